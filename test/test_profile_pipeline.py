"""The pipeline in profiles mode: poses and loads in, patches and wrenches out, bad poses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fastsim_ros.geometry.placement import rotation
from fastsim_ros.geometry.wheelset import LOAD_TOLERANCE
from fastsim_ros.ros.params import PROFILE_CONTACTS, ParameterError
from fastsim_ros.pipeline import Pipeline, PipelineConfig
from fastsim_ros.pipeline.profiles import BALANCE_TOLERANCE, ProfilePipeline
from msg_adapters.cdr import StampedTwist
from msg_adapters.errors import RejectedInput
from msg_adapters.profile_msgs import StampedPose, quaternion

MS = 1_000_000
SPEED, R0 = 2.0, 0.46


def _config(**over):
    values = {"patch_source": "profiles", "wheel_load": 1e4, "shear_modulus": 82e9,
              "poisson_ratio": 0.28, **over}
    return PipelineConfig.from_values(values)


def _twist(stamp, *, roll=0.0, yaw=0.0, speed=SPEED, spin=None):
    rot = rotation(roll, yaw)
    v = rot.T @ np.array([speed, 0.0, 0.0])
    w = (0.0, speed / R0 if spin is None else spin, 0.0)
    return StampedTwist(stamp, "wheelset", tuple(float(c) for c in v), w)


def _pose(stamp, dy, yaw=0.0, roll=0.0, dz=0.0, frame="track"):
    return StampedPose(stamp, frame, (0.0, dy, dz), quaternion(roll, yaw))


def _vertical_force(outcome, pose_roll=0.0, pose_yaw=0.0):
    f = outcome.forces
    w = outcome.frame.to_wheelset((f.fx, f.fy, f.n))
    return float((rotation(pose_roll, pose_yaw) @ np.asarray(w))[2])


@pytest.fixture(scope="module")
def served():
    """One pose, 10 kN per wheel from the parameter, shifted 3 mm right and yawed."""
    p = ProfilePipeline(_config())
    p.on_wheel_twist(_twist(0, roll=-2e-4, yaw=-7.2e-3))
    cycle = p.on_pose(_pose(1 * MS, -3e-3, yaw=-7.2e-3, roll=-2e-4))
    return p, cycle


def test_a_pose_gives_every_contact_a_wrench_and_the_loads_balance(served):
    p, cycle = served
    by = {o.contact: o for o in cycle.outcomes}
    assert tuple(by) == PROFILE_CONTACTS
    assert by["left"].status == by["right"].status == "solved"
    # one patch per wheel here: the second names publish zero wrenches
    assert by["left_flange"].status == by["right_flange"].status == "no_contact"
    # the rig cycle is complete once: one wheelset wrench, from the last contact
    wrenches = [o.wheelset for o in cycle.outcomes if o.wheelset is not None]
    assert len(wrenches) == 1
    # this roll is not the loads' equilibrium: each wheel carries its load at its own
    # height (CONTACT's half wheelsets), micrometres apart, and both are expressed in the
    # frame at their mean height; the loads hold to the creep force that difference makes
    for side in ("left", "right"):
        assert _vertical_force(by[side], -2e-4, -7.2e-3) == pytest.approx(1e4, rel=1e-4)


def test_on_a_centred_pose_each_wheel_carries_its_load_exactly():
    # symmetric: both wheels at one height, the balance holds to its tolerance
    p = ProfilePipeline(_config())
    p.on_wheel_twist(_twist(0))
    cycle = p.on_pose(_pose(1 * MS, 0.0))
    by = {o.contact: o for o in cycle.outcomes}
    for side in ("left", "right"):
        assert _vertical_force(by[side]) == pytest.approx(1e4, rel=10 * LOAD_TOLERANCE)
    wrench = next(o.wheelset for o in cycle.outcomes if o.wheelset is not None)
    assert wrench.force[2] == pytest.approx(2e4, rel=10 * LOAD_TOLERANCE)
    # mirror symmetry: equal normal loads, lateral forces opposite
    assert by["left"].forces.n == pytest.approx(by["right"].forces.n, rel=1e-9)
    # the wheelset shifted right rides on the right flange's side: lateral force to the left
    assert by["right"].frame.origin[1] < 0.0 < by["left"].frame.origin[1]


def test_the_patches_replayed_as_topics_give_the_same_wrenches(served):
    # what the node publishes on contact/<name>/patch, fed to a topics-mode pipeline
    p, cycle = served
    topics = Pipeline(PipelineConfig.from_values({
        "contacts": list(PROFILE_CONTACTS), "shear_modulus": 82e9, "poisson_ratio": 0.28}))
    topics.on_wheel_twist(_twist(0, roll=-2e-4, yaw=-7.2e-3))
    for (name, cloud), outcome in zip(cycle.patches, cycle.outcomes):
        again = topics.on_patch(name, cloud)
        assert again.status == outcome.status
        if outcome.forces is not None:
            assert again.forces is not None
            assert (again.forces.fx, again.forces.fy, again.forces.mz, again.forces.n) == \
                (outcome.forces.fx, outcome.forces.fy, outcome.forces.mz, outcome.forces.n)
            assert again.creepage == outcome.creepage


def test_a_load_message_splits_by_its_roll_moment():
    p = ProfilePipeline(_config(wheel_load=0.0))
    b = p.wheelset.placement.wheel_offset
    # 26 kN with a roll moment putting 16 kN on the left wheel, 10 kN on the right
    assert p.on_load(StampedTwist(0, "wheelset", (0.0, 0.0, 26e3), (6e3 * b, 0.0, 0.0))) == "ok"
    p.on_wheel_twist(_twist(0))
    cycle = p.on_pose(_pose(1 * MS, 0.0))
    by = {o.contact: o for o in cycle.outcomes}
    assert cycle.loads == pytest.approx((16e3, 10e3))
    assert _vertical_force(by["left"]) == pytest.approx(16e3, rel=10 * LOAD_TOLERANCE)
    assert _vertical_force(by["right"]) == pytest.approx(10e3, rel=10 * LOAD_TOLERANCE)


def test_a_load_all_on_one_wheel_lifts_the_other():
    p = ProfilePipeline(_config(wheel_load=0.0))
    b = p.wheelset.placement.wheel_offset
    assert p.on_load(StampedTwist(0, "wheelset", (0.0, 0.0, 1e4), (1e4 * b, 0.0, 0.0))) == "ok"
    p.on_wheel_twist(_twist(0))
    by = {o.contact: o for o in p.on_pose(_pose(1 * MS, 0.0)).outcomes}
    assert by["right"].status == "no_contact" and by["left"].status == "solved"
    assert _vertical_force(by["left"]) == pytest.approx(1e4, rel=10 * LOAD_TOLERANCE)


@pytest.mark.parametrize("load, why", [
    (StampedTwist(0, "other", (0.0, 0.0, 2e4), (0.0, 0.0, 0.0)), "wrong_frame"),
    (StampedTwist(0, "wheelset", (0.0, 0.0, -2e4), (0.0, 0.0, 0.0)), "out_of_range"),
    (StampedTwist(0, "wheelset", (0.0, 0.0, 2e4), (2e5, 0.0, 0.0)), "out_of_range"),
    (StampedTwist(0, "wheelset", (0.0, 0.0, 1e13), (0.0, 0.0, 0.0)), "out_of_range"),
    (StampedTwist(0, "wheelset", (0.0, 0.0, math.nan), (0.0, 0.0, 0.0)), "nonfinite"),
])
def test_bad_loads_are_not_taken(load, why):
    p = ProfilePipeline(_config(wheel_load=0.0))
    assert p.on_load(load) == why
    assert p.wheel_loads(1 * MS) is None
    assert p.pose_counts[why] == 1
    (taken,) = [i for i in p.inputs() if i.kind == "load"]
    assert taken.check is not None  # the node logs the verdict


def test_a_stale_load_is_rejected_not_replaced():
    """Once a load has arrived, a pose without a fresh one is stale_kinematics.

    Replacing it with wheel_load (or, at 0, the pose's height: zero wrenches
    as if the wheelset were lifted) would hide the lost load cell.
    """
    p = ProfilePipeline(_config(wheel_load=1e4))
    p.on_wheel_twist(_twist(0))
    assert p.on_load(StampedTwist(0, "wheelset", (0.0, 0.0, 1.6e4), (0.0, 0.0, 0.0))) == "ok"
    assert p.wheel_loads(1 * MS) == (8e3, 8e3)
    late = 1 * MS + round(p.config["max_kinematics_age"] * 1e9) + MS
    with pytest.raises(RejectedInput, match="older than the pose"):
        p.wheel_loads(late)
    p.on_wheel_twist(_twist(late))
    cycle = p.on_pose(_pose(late, 0.0))
    assert {o.status for o in cycle.outcomes} == {"stale_kinematics"}


def test_without_a_load_the_pose_height_is_used_and_a_lifted_pair_has_no_contact():
    p = ProfilePipeline(_config(wheel_load=0.0))
    p.on_wheel_twist(_twist(0))
    cycle = p.on_pose(_pose(1 * MS, 0.0, dz=1e-3))  # 1 mm above the rails
    assert [o.status for o in cycle.outcomes] == ["no_contact"] * 4
    assert all(o.has_wrench for o in cycle.outcomes)
    # lowered 20 um below touching: the interpenetration carries a load
    cycle = p.on_pose(_pose(2 * MS, 0.0, dz=-0.218e-3))
    by = {o.contact: o for o in cycle.outcomes}
    assert by["left"].status == "solved" and 1e3 < by["left"].forces.n < 1e5


def _reasons(cycle):
    return {o.status for o in cycle.outcomes}


def test_bad_poses_are_dropped_for_every_contact_and_the_next_one_served():
    p = ProfilePipeline(_config())
    assert _reasons(p.on_pose(_pose(1 * MS, 0.0))) == {"no_kinematics"}
    p.on_wheel_twist(_twist(2 * MS))
    assert _reasons(p.on_pose(_pose(3 * MS, 0.0, frame="map"))) == {"wrong_frame"}
    assert _reasons(p.on_pose(StampedPose(4 * MS, "track", (0.0, math.nan, 0.0),
                                          (0.0, 0.0, 0.0, 1.0)))) == {"nonfinite"}
    assert _reasons(p.on_pose(_pose(200 * MS, 0.0))) == {"stale_kinematics"}
    assert _reasons(p.on_pose(_pose(100 * MS, 0.0))) == {"old_stamp"}
    p.on_wheel_twist(_twist(201 * MS))
    # 45 mm to the right: the right flange has climbed its rail
    assert _reasons(p.on_pose(_pose(202 * MS, -0.045))) == {"derailment"}
    p.on_wheel_twist(_twist(203 * MS, speed=0.0, spin=0.0))
    assert _reasons(p.on_pose(_pose(204 * MS, 0.0))) == {"standstill"}
    p.on_wheel_twist(_twist(205 * MS))
    good = p.on_pose(_pose(206 * MS, 0.0))
    assert {o.contact: o.status for o in good.outcomes}["left"] == "solved"
    report = dict(p.pipeline.report("left").values)
    for reason in ("no_kinematics", "wrong_frame", "nonfinite", "stale_kinematics",
                   "old_stamp", "derailment", "standstill"):
        assert report[f"rejected/{reason}"] == "1", reason


def test_a_missing_profile_is_a_parameter_error_naming_the_file(tmp_path):
    with pytest.raises(ParameterError, match="nothere.prw: cannot read"):
        ProfilePipeline(_config(wheel_profile=str(tmp_path / "nothere.prw")))


def test_profiles_mode_fixes_the_contacts():
    assert PipelineConfig.from_values({"patch_source": "profiles"}).contacts == PROFILE_CONTACTS
    with pytest.raises(ParameterError, match="fixed"):
        PipelineConfig.from_values({"patch_source": "profiles", "contacts": ["front"]})


# ---------------------------------------------------------------------------- the contact table

#: a small table: dy -4..4 mm by 0.5 mm, yaw -10..10 mrad by 5 mrad (85 nodes, the treads)
TABLE = {"profile_table": True, "table_dy_min": -4e-3, "table_dy_max": 4e-3,
         "table_dy_step": 5e-4, "table_yaw_max": 1e-2, "table_yaw_step": 5e-3}


@pytest.fixture(scope="module")
def table_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("tables")


@pytest.fixture(scope="module")
def tabled(table_cache):
    return ProfilePipeline(_config(**TABLE, table_cache=str(table_cache)))


def test_the_table_refuses_a_wheel_load_of_zero_at_run_time(tabled):
    """The table needs a load: wheel_load 0 is refused at run time as at start.

    Taken, it would send poses to the per-pose solve at their own height
    (328 kN on a pose outside the table).
    """
    with pytest.raises(ParameterError, match="wheel_load"):
        tabled.update({"wheel_load": 0.0})
    assert tabled.config["wheel_load"] > 0.0


def _serve(p, stamp, dy, yaw, **twist):
    p.on_wheel_twist(_twist(stamp, yaw=yaw, **twist))
    return p.on_pose(_pose(stamp, dy, yaw=yaw))


@pytest.mark.parametrize("dy, yaw", [(1.3e-3, 2.1e-3), (-2.7e-3, -6.4e-3), (3.05e-3, 8e-3)])
def test_the_table_balances_each_wheels_load_with_the_creep_forces(tabled, dy, yaw):
    cycle = _serve(tabled, 10 * MS, dy, yaw)
    assert cycle.contact is not None
    roll = cycle.contact.roll
    by = {o.contact: o for o in cycle.outcomes}
    for side in ("left", "right"):
        assert by[side].status == "solved"
        # the published wrenches' vertical sum, creep forces included, is the wheel's load
        assert _vertical_force(by[side], roll, yaw) == pytest.approx(1e4, rel=BALANCE_TOLERANCE)


@pytest.mark.parametrize("dy, yaw", [(1.3e-3, 2.1e-3), (-2.7e-3, -6.4e-3), (2.25e-3, 0.0)])
def test_the_table_between_nodes_is_the_per_pose_solve_within_a_percent(tabled, dy, yaw):
    # the table at its levelled roll against the per-pose solve at that roll: Fx, Fy within
    # 1% of mu N on the treads (docs/validation_table.md measures the whole range)
    cycle = _serve(tabled, 20 * MS, dy, yaw)
    exact = ProfilePipeline(_config())
    exact.on_wheel_twist(_twist(20 * MS, yaw=yaw))
    ref = exact.on_pose(_pose(20 * MS, dy, yaw=yaw, roll=cycle.contact.roll))
    for a, b in zip(cycle.outcomes, ref.outcomes):
        assert a.status == b.status
        if b.forces is not None:
            mu_n = 0.3 * b.forces.n
            assert a.forces.fx == pytest.approx(b.forces.fx, abs=0.01 * mu_n)
            assert a.forces.fy == pytest.approx(b.forces.fy, abs=0.01 * mu_n)
            assert a.forces.n == pytest.approx(b.forces.n, rel=2e-3)


def test_the_table_patches_replayed_as_topics_give_the_same_wrenches(tabled):
    cycle = _serve(tabled, 30 * MS, -1.1e-3, 3.3e-3)
    topics = Pipeline(PipelineConfig.from_values({
        "contacts": list(PROFILE_CONTACTS), "shear_modulus": 82e9, "poisson_ratio": 0.28}))
    topics.on_wheel_twist(_twist(30 * MS, yaw=3.3e-3))
    for (name, cloud), outcome in zip(cycle.patches, cycle.outcomes):
        again = topics.on_patch(name, cloud)
        assert again.status == outcome.status
        if outcome.forces is not None:
            # the table's solve took its patch as it made it; the adapter finds the same
            # frame and grid in the cloud to rounding (1e-16 m), so the forces to 1e-9
            for key in ("fx", "fy", "mz", "n"):
                assert getattr(again.forces, key) == pytest.approx(
                    getattr(outcome.forces, key), rel=1e-9, abs=1e-9), key
            assert again.creepage.xi == pytest.approx(outcome.creepage.xi, rel=1e-9,
                                                      abs=1e-15)


def test_a_load_message_scales_the_table_patches_like_hertz(tabled):
    reference = _serve(tabled, 38 * MS, 0.7e-3, 1e-3)
    tabled.on_load(StampedTwist(39 * MS, "wheelset", (0.0, 0.0, 1.6e4), (0.0, 0.0, 0.0)))
    cycle = _serve(tabled, 40 * MS, 0.7e-3, 1e-3)
    assert cycle.loads == (8e3, 8e3)
    by = {o.contact: o for o in cycle.outcomes}
    vertical = _vertical_force(by["left"], cycle.contact.roll, 1e-3)
    assert vertical == pytest.approx(8e3, rel=BALANCE_TOLERANCE)
    # the normal force ~ s^3 (the creep forces' vertical share, 1% here, scales alike)
    for k in range(2):
        ratio = (cycle.contact.scales[k] / reference.contact.scales[k]) ** 3
        assert ratio == pytest.approx(0.8, rel=2e-3)
    # all on the left wheel: the right one is lifted, its contact publishes no wrench
    b = tabled.wheelset.placement.wheel_offset
    tabled.on_load(StampedTwist(41 * MS, "wheelset", (0.0, 0.0, 1e4), (1e4 * b, 0.0, 0.0)))
    lifted = _serve(tabled, 42 * MS, 0.7e-3, 1e-3)
    assert lifted.loads == pytest.approx((1e4, 0.0))
    status = {o.contact: o.status for o in lifted.outcomes}
    assert status["right"] == "no_contact" and status["left"] == "solved"


def test_poses_outside_the_table_are_counted_out_of_table(tabled):
    assert _reasons(_serve(tabled, 50 * MS, 4.5e-3, 0.0)) == {"out_of_table"}
    assert _reasons(_serve(tabled, 51 * MS, 0.0, 0.011)) == {"out_of_table"}
    good = _serve(tabled, 52 * MS, 0.0, 0.0)
    assert {o.contact: o.status for o in good.outcomes}["left"] == "solved"
    report = dict(tabled.pipeline.report("right_flange").values)
    assert int(report["rejected/out_of_table"]) >= 2


def test_a_second_pipeline_reads_the_cached_table(tabled, table_cache, monkeypatch):
    from fastsim_ros.geometry.table import ContactTable

    def no_build(*args, **kwargs):
        raise AssertionError("the table was built again")
    monkeypatch.setattr(ContactTable, "build", no_build)
    again = ProfilePipeline(_config(**TABLE, table_cache=str(table_cache)))
    for n, m in zip(again.table.nodes, tabled.table.nodes, strict=True):
        assert n.roll == m.roll
        for side in range(2):
            for p, q in zip(n.patches[side], m.patches[side], strict=True):
                np.testing.assert_array_equal(p.pressure, q.pressure)
                np.testing.assert_array_equal(p.origin, q.origin)
    served = _serve(again, 60 * MS, 1.7e-3, -2e-3)
    assert {o.contact: o.status for o in served.outcomes}["left"] == "solved"


def test_the_table_cache_expands_environment_variables(tabled, table_cache, monkeypatch):
    """``table_cache: $RIG_TABLES`` names the directory the variable holds (no literal '$')."""
    from fastsim_ros.geometry.table import ContactTable

    def no_build(*args, **kwargs):
        raise AssertionError("the table was built again")
    monkeypatch.setattr(ContactTable, "build", no_build)
    monkeypatch.setenv("FASTSIM_TEST_TABLES", str(table_cache))
    again = ProfilePipeline(_config(**TABLE, table_cache="$FASTSIM_TEST_TABLES"))
    assert again.table.nodes[0].roll == tabled.table.nodes[0].roll
    monkeypatch.delenv("FASTSIM_TEST_TABLES")
    with pytest.raises(ParameterError,
                       match="'table_cache'.*FASTSIM_TEST_TABLES is not set"):
        ProfilePipeline(_config(**TABLE, table_cache="${FASTSIM_TEST_TABLES}/x"))


def test_the_table_needs_a_reference_load(table_cache):
    with pytest.raises(ParameterError, match="wheel_load"):
        ProfilePipeline(_config(**TABLE, wheel_load=0.0, table_cache=str(table_cache)))
    with pytest.raises(ParameterError, match="divide"):
        ProfilePipeline(_config(**{**TABLE, "table_dy_step": 3e-3},
                                table_cache=str(table_cache)))


def test_a_wheel_load_in_kilonewtons_is_rejected_unless_allowed():
    """``wheel_load`` 10 (kN typed as N) and a ``wheelset/load`` of 20 N: likely unit mistakes.

    The pose is dropped for every contact, named ``implausible`` with the
    value and the parameter that accepts it; ``allow_implausible`` solves it;
    a lifted wheelset (no load) is no mistake.
    """
    p = ProfilePipeline(_config(wheel_load=10.0))
    p.on_wheel_twist(_twist(0))
    cycle = p.on_pose(_pose(1 * MS, 0.0))
    assert _reasons(cycle) == {"implausible"}
    assert all(o.detail.startswith("parameter wheel_load 10 N is implausible for wheel-rail "
                                   "contact") and "kilonewtons typed as newtons" in o.detail
               and o.detail.endswith("give parameter allow_implausible: true")
               for o in cycle.outcomes)
    allowed = ProfilePipeline(_config(wheel_load=10.0, allow_implausible=True))
    allowed.on_wheel_twist(_twist(0))
    assert "implausible" not in _reasons(allowed.on_pose(_pose(1 * MS, 0.0)))
    assert p.on_load(StampedTwist(2 * MS, "wheelset", (0.0, 0.0, 20.0), (0.0, 0.0, 0.0))) == "ok"
    p.on_wheel_twist(_twist(2 * MS))
    cycle = p.on_pose(_pose(3 * MS, 0.0))
    assert _reasons(cycle) == {"implausible"}
    assert cycle.outcomes[0].detail.startswith("wheelset/load: half its force.z 10 N")
    assert p.on_load(StampedTwist(4 * MS, "wheelset", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))) == "ok"
    p.on_wheel_twist(_twist(4 * MS))
    assert _reasons(p.on_pose(_pose(5 * MS, 0.0))) == {"no_contact"}
