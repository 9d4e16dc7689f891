"""The shared pipeline: library-equal wrenches, reverse running, kinematics rules, outputs."""

import math
import re

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped, Vector3Stamped, WrenchStamped
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import PointCloud2

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import samples
from fastsim_ros.contact.compiled import CalibratedMaeSolver, EquivalentEllipseSolver, MaeSolver
from fastsim_ros.contact.friction import ExponentialFriction, SlopeReduction
from fastsim_ros.contact.polach import PolachSolver
from fastsim_ros.ros.params import METHODS, ParameterError
from fastsim_ros.pipeline import Pipeline, PipelineConfig
from ros_messages import WHEEL_RADIUS as R
from ros_messages import cdr, cloud_msg, contact_normal, in_plane_area, rolling_twist, twist_msg

MS = 1_000_000
T0 = 1_700_000_000 * 1_000_000_000
LEFT = (0.0, 0.75, -R)


def egg():
    """Return two semi-ellipses joined along y = 0: asymmetric in y, symmetric in x."""
    return samples.semi_ellipses_patch(0.5, 2.0, cells=24, scale=8e-3, load=6e4)


def fore_aft_egg():
    """Return an egg-shaped patch: a leading half 7 mm long, a trailing half 4 mm long."""
    x = np.linspace(-4.5e-3, 7.5e-3, 25)
    y = np.linspace(-4.5e-3, 4.5e-3, 19)
    a = np.where(x > 0.0, 7e-3, 4e-3)
    p = np.sqrt(np.clip(1.0 - (x[None, :] / a[None, :]) ** 2 - (y[:, None] / 4e-3) ** 2,
                        0.0, None))
    return areas.GridArea(x[0], y[0], x[1] - x[0], y[1] - y[0], p).with_load(6e4)


def make(**values):
    values.setdefault("contacts", ["left"])
    return Pipeline(PipelineConfig.from_values(values))


def solve(pipe, area, *, stamp=T0 + 10 * MS, contact="left", **cloud):
    cloud.setdefault("dtype", "<f8")
    return pipe.on_patch(contact, cdr(cloud_msg(area, stamp_ns=stamp, **cloud)))


#: the library's compiled solver of each method the node offers
SOLVERS = {"mae": MaeSolver, "mae_calibrated": CalibratedMaeSolver,
           "fastsim_ellipse": EquivalentEllipseSolver, "polach": PolachSolver}
DEFAULT_METHOD = "mae_calibrated"


def solver_of(method):
    return SOLVERS[method](0.28, 8e10)


def library(method, area, xi, eta, phi, mu=0.3):
    solver = solver_of(method)
    a = in_plane_area(area)
    return solver.solve_arrays(a.pressure, a.x0, a.y0, a.dx, a.dy, xi, eta, phi, mu)


def test_every_method_is_offered():
    assert set(METHODS) == set(SOLVERS)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("xi", [2e-4, 3e-3])
def test_wrench_equals_the_library(method, xi):
    pipe = make(method=method)
    assert pipe.on_wheel_twist(cdr(rolling_twist(xi, stamp_ns=T0))) == "ok"
    out = solve(pipe, egg())
    assert out.status == "solved"
    ref = library(method, egg(), xi, 0.0, 0.0)
    assert out.creepage.xi == pytest.approx(xi, rel=1e-12)
    for got, want in ((out.forces.fx, ref.fx), (out.forces.fy, ref.fy),
                      (out.forces.mz, ref.mz), (out.forces.n, ref.n)):
        assert got == pytest.approx(want, rel=1e-9, abs=1e-9 * abs(ref.n))
    assert out.forces.fx < 0  # braked: the rail pulls the wheel back


def test_spin_from_the_contact_angle_reaches_the_solver():
    gamma = 0.3
    pipe = make()
    pipe.on_wheel_twist(cdr(twist_msg((20.0, 0, 0), (0, 20.0 / R, 0), stamp_ns=T0)))
    out = solve(pipe, egg(), normal=contact_normal(gamma, "left"))
    # phi = e_z . w / V, e_z = (0, -sin g, cos g), w = (0, omega, 0)
    phi = -(20.0 / R) * math.sin(gamma) / out.creepage.speed
    assert out.creepage.phi == pytest.approx(phi, rel=1e-9)
    c = out.creepage
    ref = library(DEFAULT_METHOD, egg(), c.xi, c.eta, c.phi)
    assert out.forces.fx == pytest.approx(ref.fx, rel=1e-9)
    assert out.forces.fy == pytest.approx(ref.fy, rel=1e-9)
    assert abs(out.forces.fx) > 100.0  # spin alone gives Fx on this asymmetric area


def turned(area):
    """Return the area turned by 180 degrees about z (x, y -> -x, -y)."""
    return areas.GridArea(-(area.x0 + (area.nx - 1) * area.dx),
                          -(area.y0 + (area.ny - 1) * area.dy), area.dx, area.dy,
                          area.pressure[::-1, ::-1])


@pytest.mark.parametrize("method", METHODS)
def test_reverse_running_solves_the_turned_patch_and_opposes_the_slip(method):
    # backing up at 20 m/s, braked (|omega R| < |v0|), with spin from a contact angle
    v0, omega_r, gamma = -20.0, -19.96, 0.2
    pipe = make(method=method)
    pipe.on_wheel_twist(cdr(twist_msg((v0, 0, 0), (0, omega_r / R, 0), stamp_ns=T0)))
    out = solve(pipe, fore_aft_egg(), normal=contact_normal(gamma, "left"))
    c = out.creepage
    assert c.speed < 0 and c.xi > 0
    # solve on the turned cells with (xi, eta, -phi); report (-Fx', -Fy', Mz')
    a = in_plane_area(fore_aft_egg())
    solver = solver_of(method)
    t = turned(a)
    ref = solver.solve_arrays(t.pressure, t.x0, t.y0, t.dx, t.dy, c.xi, c.eta, -c.phi, 0.3)
    assert out.forces.fx == pytest.approx(-ref.fx, rel=1e-9)
    assert out.forces.fy == pytest.approx(-ref.fy, rel=1e-9)
    assert out.forces.mz == pytest.approx(ref.mz, rel=1e-9)
    # the wheel slides towards -x relative to the rail: the rail pushes it towards +x
    slip_x = v0 - omega_r
    assert slip_x < 0 and out.forces.fx > 0
    # and the leading edge is the other one: on a patch with a long front and a
    # short back, running backwards is not the forward solve negated
    fwd = make(method=method)
    fwd.on_wheel_twist(cdr(twist_msg((-v0, 0, 0), (0, -omega_r / R, 0), stamp_ns=T0)))
    forward = solve(fwd, fore_aft_egg(), normal=contact_normal(gamma, "left"))
    assert forward.forces.fx < 0
    if method != "fastsim_ellipse":  # the equivalent ellipse is symmetric whatever the patch
        assert abs(forward.forces.fx + out.forces.fx) > 1e-3 * abs(out.forces.fx)


def test_reverse_running_traction_integrates_to_the_force():
    pipe = make(publish_traction=True)
    pipe.on_wheel_twist(cdr(twist_msg((-20.0, 0, 0), (0, -19.96 / R, 0), stamp_ns=T0)))
    out = solve(pipe, fore_aft_egg(), normal=contact_normal(0.2, "left"))
    f = out.forces
    assert out.creepage.speed < 0
    cell = out.patch.dx * out.patch.dy
    assert float(f.tau_x.sum()) * cell == pytest.approx(f.fx, rel=1e-12)
    assert float(f.tau_y.sum()) * cell == pytest.approx(f.fy, rel=1e-12)
    # the traction lies on the patch's own cells, in the patch's own orientation
    x = f.grid[0] + f.grid[2] * np.arange(f.tau_x.shape[1])
    y = f.grid[1] + f.grid[3] * np.arange(f.tau_x.shape[0])
    mz = float((x[None, :] * f.tau_y - y[:, None] * f.tau_x).sum()) * cell
    assert mz == pytest.approx(f.mz, rel=1e-9)
    assert np.all((f.tau_x != 0) <= (out.patch.pressure > 0))


@pytest.mark.parametrize("speed", [20.0, -20.0], ids=["forward", "reverse"])
@pytest.mark.parametrize("rolling", ["steady", "transient"])
@pytest.mark.parametrize("shape, share", [("hertz", 0.015), ("fore_aft_egg", 0.03)])
def test_the_equivalent_ellipse_traction_lies_on_the_patch_cells(speed, rolling, shape, share):
    """The traction cloud is on the patch cells, the ellipse's own grid moved there.

    The equivalent ellipse solves on an n x n grid of its own; the cloud
    takes the patch's grid and shape, zero traction and no slip off its
    cells in contact, and sums to the solve's force within what the move
    loses: on a Hertzian patch (the ellipse is the patch) the interpolation
    at the edge cells, 0.7% measured; on the egg the ellipse's traction
    outside the egg as well, 1-2.2% measured.
    """
    area = (areas.ellipse(6e-3, 4e-3, nx=24, ny=18).with_load(6e4) if shape == "hertz"
            else fore_aft_egg())
    pipe = make(method="fastsim_ellipse", publish_traction=True, rolling=rolling)
    pipe.on_wheel_twist(cdr(twist_msg((speed, 0, 0), (0, speed * 0.999 / R, 0),
                                      stamp_ns=T0)))
    out = solve(pipe, area, normal=contact_normal(0.2, "left"))
    f, patch = out.forces, out.patch
    assert (out.creepage.speed < 0) == (speed < 0)
    assert f.grid == (patch.x0, patch.y0, patch.dx, patch.dy)
    assert f.tau_x.shape == f.tau_y.shape == f.slip.shape == patch.pressure.shape
    off = ~(patch.pressure > 0)
    assert not f.tau_x[off].any() and not f.tau_y[off].any() and not f.slip[off].any()
    assert f.slip.any()
    cell = patch.dx * patch.dy
    assert float(f.tau_x.sum()) * cell == pytest.approx(f.fx, rel=share)
    assert float(f.tau_y.sum()) * cell == pytest.approx(f.fy, rel=share)
    msgs = dict(pipe.messages(out))
    cloud = deserialize_message(msgs["contact/left/traction"], PointCloud2)
    assert (cloud.height, cloud.width) == patch.pressure.shape


def test_reverse_running_on_a_symmetric_patch_mirrors_the_forward_force():
    area = areas.ellipse(6e-3, 4e-3, nx=24, ny=24).with_load(6e4)
    forces = []
    for sign in (1.0, -1.0):
        pipe = make()
        pipe.on_wheel_twist(cdr(twist_msg((sign * 20.0, 0, 0), (0, sign * 19.98 / R, 0),
                                          stamp_ns=T0)))
        forces.append(solve(pipe, area).forces)
    assert forces[1].fx == pytest.approx(-forces[0].fx, rel=1e-9)
    assert forces[0].fx < 0 < forces[1].fx


def test_kinematics_matching_by_stamp():
    pipe = make(max_kinematics_age=0.05)
    assert solve(pipe, egg(), stamp=T0).status == "no_kinematics"
    pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0 + 100 * MS)))
    # a twist newer than the patch is never used for it
    assert solve(pipe, egg(), stamp=T0 + 90 * MS).status == "stale_kinematics"
    assert solve(pipe, egg(), stamp=T0 + 140 * MS).status == "solved"
    assert solve(pipe, egg(), stamp=T0 + 150 * MS).status == "solved"  # exactly max age
    assert solve(pipe, egg(), stamp=T0 + 151 * MS).status == "stale_kinematics"
    # the newest twist not after the patch is the one used
    pipe.on_wheel_twist(cdr(rolling_twist(2e-3, stamp_ns=T0 + 160 * MS)))
    pipe.on_wheel_twist(cdr(rolling_twist(4e-3, stamp_ns=T0 + 180 * MS)))
    out = solve(pipe, egg(), stamp=T0 + 170 * MS)
    assert out.creepage.xi == pytest.approx(2e-3, rel=1e-9)
    counts = pipe.counts("left")
    assert counts["no_kinematics"] == 1 and counts["stale_kinematics"] == 2
    assert counts["solved"] == 3


def test_twists_that_are_dropped():
    pipe = make()
    assert pipe.on_wheel_twist(cdr(twist_msg((math.nan, 0, 0), stamp_ns=T0))) == "nonfinite"
    assert pipe.on_wheel_twist(cdr(twist_msg(stamp_ns=T0, frame_id="map"))) == "wrong_frame"
    assert pipe.on_wheel_twist(cdr(rolling_twist(0.0, stamp_ns=T0 + 5 * MS))) == "ok"
    assert pipe.on_wheel_twist(cdr(rolling_twist(0.0, stamp_ns=T0))) == "old_stamp"
    assert pipe.on_wheel_twist(b"\x00\x01\x00\x00\x01") == "malformed"


def test_rail_twist_required():
    pipe = make(rail_twist_required=True)
    pipe.on_wheel_twist(cdr(twist_msg((0, 0, 0), (0, 15.0 / R, 0), stamp_ns=T0)))
    assert solve(pipe, egg()).status == "stale_kinematics"
    # a roller of radius 0.7 m turning at -omega_r below the wheel: v_r = w_r x (0 - c_r)
    rr, omega_r = 0.7, 15.0 / 0.7
    pipe.on_rail_twist(cdr(twist_msg((-omega_r * (R + rr), 0, 0), (0, -omega_r, 0),
                                     stamp_ns=T0 + 5 * MS)))
    out = solve(pipe, egg(), stamp=T0 + 20 * MS, origin=(0.0, 0.0, -R))
    assert out.status == "solved"
    assert out.creepage.speed == pytest.approx(15.0, rel=1e-6)
    assert out.creepage.xi == pytest.approx(0.0, abs=1e-9)


def test_standstill_and_min_rolling_speed():
    pipe = make(min_rolling_speed=0.1)
    pipe.on_wheel_twist(cdr(twist_msg((0.05, 0, 0), (0, 0.05 / R, 0), stamp_ns=T0)))
    assert solve(pipe, egg()).status == "standstill"
    pipe.on_wheel_twist(cdr(twist_msg((0.5, 0, 0), (0, 0.5 / R, 0), stamp_ns=T0 + 20 * MS)))
    assert solve(pipe, egg(), stamp=T0 + 30 * MS).status == "solved"


def test_patch_rejections_then_the_next_good_patch_is_served():
    pipe = make()
    pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0)))
    assert solve(pipe, egg(), frame_id="map").status == "wrong_frame"
    assert solve(pipe, egg(), stamp=T0 + 20 * MS).status == "solved"
    assert solve(pipe, egg(), stamp=T0 + 15 * MS).status == "old_stamp"
    assert pipe.on_patch("left", b"garbage!").status == "missing_field"
    p = egg().pressure.copy()
    p[3, 3] = -5.0
    assert solve(pipe, egg(), stamp=T0 + 25 * MS, pressure=p).status == "negative_pressure"
    assert solve(pipe, egg(), stamp=T0 + 30 * MS).status == "solved"


def _in_mm(area):
    """Return ``area`` with its coordinates in millimetres where metres belong."""
    return areas.GridArea(area.x0 * 1e3, area.y0 * 1e3, area.dx * 1e3, area.dy * 1e3,
                          area.pressure)


@pytest.mark.parametrize("case, cloud, twist, words", [
    ("coordinates in mm", dict(area=_in_mm(egg())), rolling_twist(1e-3, stamp_ns=T0),
     r"patch extent along x 12\.7662 m is implausible for wheel-rail contact: .* likely "
     "coordinates in millimetres where metres belong; if intended, give parameter "
     "allow_implausible: true"),
    ("pressures in MPa", dict(pressure=egg().pressure * 1e-6),
     rolling_twist(1e-3, stamp_ns=T0),
     "largest pressure 1397.59 Pa is implausible for wheel-rail contact: .* likely "
     r"megapascals typed as pascals \(1000 MPa is 1e9 Pa\); if intended, give parameter "
     "allow_implausible: true"),
    ("a percentage as a creepage", {}, rolling_twist(0.2, stamp_ns=T0),
     "xi 0.2 is implausible for wheel-rail contact: .* likely a percentage typed where the "
     r"fraction belongs \(0.2 % is 0.002\); if intended, give parameter allow_implausible: "
     "true"),
])
def test_a_likely_unit_mistake_is_rejected_unless_allowed(case, cloud, twist, words):
    """Patches and creepages wheel-rail contact does not have in SI units: no wrench.

    The same inputs with ``allow_implausible`` are solved (a scaled rig, a
    full-slip test), as every plausible patch is.
    """
    area = cloud.pop("area", egg())
    for allow in (False, True):
        pipe = make(allow_implausible=allow)
        pipe.on_wheel_twist(cdr(twist))
        out = solve(pipe, area, **cloud)
        if allow:
            assert out.status == "solved" and math.isfinite(out.forces.fx), case
            continue
        assert out.status == "implausible", case
        assert re.fullmatch(words, out.detail), out.detail
        assert pipe.messages(out) == []
        assert pipe.counts("left")["implausible"] == 1
        # the next good patch, with a plausible twist, is served
        pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0 + 15 * MS)))
        assert solve(pipe, egg(), stamp=T0 + 20 * MS).status == "solved"


@pytest.mark.parametrize("method", ["mae", "mae_calibrated"])
def test_out_of_table_patch(method):
    # a strip 401 cells long and 2 wide: MAE zones of a/b about 200, beyond the tables' 80
    area = areas.GridArea(-200e-3, -0.5e-3, 1e-3, 1e-3, np.ones((2, 401)) * 1e9)
    pipe = make(method=method)
    pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0)))
    out = solve(pipe, area)
    assert out.status == "out_of_table"
    assert pipe.messages(out) == []


def test_empty_patch_gives_a_zero_wrench_without_kinematics():
    pipe = make()
    out = solve(pipe, egg(), pressure=np.zeros_like(egg().pressure))
    assert out.status == "no_contact"
    topics = [t for t, _ in pipe.messages(out)]
    assert topics[0] == "contact/left/wrench"
    w = deserialize_message(pipe.messages(out)[0][1], WrenchStamped)
    assert (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z) == (0.0, 0.0, 0.0)
    assert pipe.counts("left")["no_contact"] == 1


def test_messages_of_a_solve():
    pipe = make(publish_traction=True)
    pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0)))
    out = solve(pipe, egg(), stamp=T0 + 7 * MS)
    msgs = dict(pipe.messages(out))
    w = deserialize_message(msgs["contact/left/wrench"], WrenchStamped)
    assert w.header.frame_id == "left_contact"
    assert w.header.stamp.sec * 10**9 + w.header.stamp.nanosec == T0 + 7 * MS
    assert (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z, w.wrench.torque.z) == (
        out.forces.fx, out.forces.fy, out.forces.n, out.forces.mz)
    v = deserialize_message(msgs["contact/left/creepage"], Vector3Stamped)
    assert (v.vector.x, v.vector.y, v.vector.z) == (out.creepage.xi, out.creepage.eta,
                                                    out.creepage.phi)
    pose = deserialize_message(msgs["contact/left/frame"], PoseStamped)
    assert pose.header.frame_id == "wheelset"
    assert (pose.pose.position.x, pose.pose.position.y,
            pose.pose.position.z) == pytest.approx(out.frame.origin)
    cloud = deserialize_message(msgs["contact/left/traction"], PointCloud2)
    tau = np.frombuffer(bytes(cloud.data), dtype=np.dtype(
        {"names": ["tau_x"], "formats": ["<f4"], "offsets": [12],
         "itemsize": cloud.point_step}))
    # the traction integrates to the force
    assert float(tau["tau_x"].astype(float).sum()) * out.patch.dx * out.patch.dy == \
        pytest.approx(out.forces.fx, rel=1e-5)
    assert "contact/markers" in msgs and "wheelset/wrench" in msgs
    # the same frame again is not republished
    again = solve(pipe, egg(), stamp=T0 + 17 * MS)
    assert "contact/left/frame" not in dict(pipe.messages(again))


def test_a_frame_asked_for_again_is_published_at_the_next_solve_once():
    # the node asks when the frame's topic gains a subscriber (a viewer joining late)
    pipe = make()
    pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0)))
    published = []
    for k in range(5):
        if k == 3:
            pipe.republish_frame("left")
        out = solve(pipe, egg(), stamp=T0 + (k + 1) * MS)
        published.append("contact/left/frame" in dict(pipe.messages(out)))
    assert published == [True, False, False, True, False]


def test_messages_only_for_the_topics_wanted():
    # the node encodes only what somebody subscribes to; without a choice, everything
    pipe = make(contacts=["left", "right"])
    pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0)))
    left = solve(pipe, egg(), stamp=T0 + 7 * MS)
    right = solve(pipe, egg().mirrored_y(), contact="right", stamp=T0 + 8 * MS,
                  origin=(0.0, -0.75, -R))
    every = [t for t, _ in pipe.messages(right)]
    assert every == ["contact/right/wrench", "contact/right/creepage", "contact/right/frame",
                     "contact/markers", "wheelset/wrench"]
    wanted = {"contact/right/creepage", "wheelset/wrench", "contact/left/wrench"}
    assert [t for t, _ in pipe.messages(right, wanted)] == ["contact/right/creepage",
                                                            "wheelset/wrench"]
    assert dict(pipe.messages(right, wanted))["wheelset/wrench"] == \
        dict(pipe.messages(right))["wheelset/wrench"]
    assert [t for t, _ in pipe.messages(left, wanted)] == ["contact/left/wrench"]
    assert pipe.messages(left, set()) == []


def test_wheelset_wrench_sums_the_contacts_once_per_cycle():
    pipe = make(contacts=["left", "right"])
    pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0)))
    gamma = 0.1
    left = solve(pipe, egg(), origin=(0.0, 0.75, -R), normal=contact_normal(gamma, "left"))
    assert left.wheelset is None
    right = solve(pipe, egg().mirrored_y(), contact="right", stamp=T0 + 11 * MS,
                  origin=(0.0, -0.75, -R), normal=contact_normal(gamma, "right"))
    ws = right.wheelset
    assert ws is not None and ws.stamp_ns == T0 + 11 * MS
    force = np.zeros(3)
    torque = np.zeros(3)
    for out in (left, right):
        axes = np.array(out.frame.axes)  # rows e_x, e_y, e_z
        f = axes.T @ [out.forces.fx, out.forces.fy, out.forces.n]
        force += f
        torque += np.cross(out.frame.origin, f) + axes.T @ [0.0, 0.0, out.forces.mz]
    np.testing.assert_allclose(ws.force, force, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(ws.torque, torque, rtol=1e-12, atol=1e-9)
    # a second left patch alone does not complete a cycle
    assert solve(pipe, egg(), stamp=T0 + 20 * MS).wheelset is None


@pytest.mark.parametrize("failing", ["left", "right"])
def test_the_wheelset_wrench_stays_one_cycles_after_a_rejected_patch(failing):
    """A NaN patch in one cycle: the sums are each cycle's own two wrenches again at once.

    The contacts arrive left, then right, each cycle.  With a flag per
    contact, one rejected left patch paired every later sum with the right
    wrench of the cycle before (stamped with the left one's), for good.  By
    the stamps (every contact's wrench newer than those of the
    last sum) that pairing is made once, in the cycle after the rejection.
    """
    pipe = make(contacts=["left", "right"])
    gamma = 0.1
    where = {"left": dict(origin=(0.0, 0.75, -R), normal=contact_normal(gamma, "left")),
             "right": dict(origin=(0.0, -0.75, -R), normal=contact_normal(gamma, "right"))}
    sums = []
    for k in range(8):
        t = T0 + k * MS
        # another creepage each cycle: each cycle's wrenches are its own
        pipe.on_wheel_twist(cdr(rolling_twist(1e-3 * (1 + k), stamp_ns=t)))
        wrench = {}
        for contact in ("left", "right"):
            area = egg() if contact == "left" else egg().mirrored_y()
            pressure = area.pressure.copy()
            if k == 2 and contact == failing:
                pressure[5, 5] = math.nan
            out = solve(pipe, area, stamp=t, contact=contact, pressure=pressure,
                        **where[contact])
            if out.status == "solved":
                axes = np.array(out.frame.axes)
                wrench[contact] = axes.T @ [out.forces.fx, out.forces.fy, out.forces.n]
            if out.wheelset is not None:
                sums.append((k, out.wheelset, dict(wrench)))
    assert [k for k, _, _ in sums] == [0, 1, 3, 4, 5, 6, 7]
    for k, ws, wrench in sums:
        assert ws.stamp_ns == T0 + k * MS
        if failing == "left" and k == 3:   # left 3 with the right wrench of cycle 2, once
            continue
        np.testing.assert_allclose(ws.force, wrench["left"] + wrench["right"], rtol=1e-12,
                                   atol=1e-6)


def test_a_rejected_patch_stamped_ahead_does_not_make_later_ones_old():
    """A NaN stamped an hour ahead is rejected; the contact's next patch is served.

    The rejected patch's stamp was kept as the contact's last: every later
    patch was ``old_stamp`` until a restart.
    """
    pipe = make()
    pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0)))
    bad = egg().pressure.copy()
    bad[5, 5] = math.nan
    ahead = solve(pipe, egg(), stamp=T0 + 3600 * 10**9, pressure=bad)
    assert ahead.status == "nonfinite"
    assert solve(pipe, egg(), stamp=T0 + 10 * MS).status == "solved"
    assert solve(pipe, egg(), stamp=T0 + 5 * MS).status == "old_stamp"   # older than taken


def test_update_friction_and_method_while_running():
    pipe = make()
    pipe.on_wheel_twist(cdr(rolling_twist(2e-2, stamp_ns=T0)))
    saturated = solve(pipe, egg(), stamp=T0 + 1 * MS).forces
    assert math.hypot(saturated.fx, saturated.fy) == pytest.approx(0.3 * saturated.n, rel=0.05)
    pipe.update({"friction_coefficient": 0.4, "method": "fastsim_ellipse"})
    after = solve(pipe, egg(), stamp=T0 + 2 * MS).forces
    assert math.hypot(after.fx, after.fy) == pytest.approx(0.4 * after.n, rel=0.05)
    # every method may be chosen while running: the wrench is then that method's, the
    # diagnostics name it; the paper's MAE and the calibrated one differ here
    xi = 2e-3
    pipe.on_wheel_twist(cdr(rolling_twist(xi, stamp_ns=T0 + 3 * MS)))
    fx = {}
    for k, method in enumerate(("mae", "mae_calibrated", "fastsim_ellipse")):
        pipe.update({"method": method})
        got = solve(pipe, egg(), stamp=T0 + (4 + k) * MS)
        ref = library(method, egg(), got.creepage.xi, got.creepage.eta, got.creepage.phi,
                      mu=0.4)
        assert got.forces.fx == pytest.approx(ref.fx, rel=1e-9)
        assert got.forces.fy == pytest.approx(ref.fy, abs=1e-9 * ref.n)
        assert dict(out_values(pipe))["method"] == method
        fx[method] = got.forces.fx
    assert abs(fx["mae_calibrated"] - fx["mae"]) > 1e-3 * abs(fx["mae"])
    with pytest.raises(ParameterError, match="start only"):
        pipe.update({"poisson_ratio": 0.3})
    with pytest.raises(ParameterError, match="friction_coefficient"):
        pipe.update({"friction_coefficient": -1.0})
    assert pipe.config["friction_coefficient"] == 0.4


def test_diagnostics_name_every_reason():
    pipe = make(contacts=["left", "right"])
    solve(pipe, egg())  # no kinematics yet
    diag = pipe.diagnostics(T0)
    names = [s.name for s in diag.status]
    assert names == ["fastsim: left", "fastsim: right"]  # one status per contact
    values = {kv.key: kv.value for kv in diag.status[0].values}
    assert values["rejected/no_kinematics"] == "1"
    assert values["method"] == DEFAULT_METHOD and values["friction_law"] == "constant"
    for key in ("solve_time_p50_us", "solve_time_p99_us", "input_rate_hz", "no_contact",
                "rejected/too_large", "rejected/out_of_table", "rejected/standstill"):
        assert key in values
    assert diag.status[0].level == b"\x01"
    assert values["twists/wheel"] == "0"


@pytest.mark.parametrize("speed", [20.0, -20.0])
def test_falling_friction_reaches_the_solver_at_the_rolling_speed(speed):
    """The pipeline runs the law at |V| from the kinematics; reverse running too."""
    from fastsim_ros.contact.friction import ExponentialFriction
    law = {"friction_law": "exponential", "friction_limit_ratio": 0.4, "friction_decay": 0.6}
    pipe = make(**law)
    xi = 2e-2
    assert pipe.on_wheel_twist(cdr(rolling_twist(xi, speed=speed, stamp_ns=T0))) == "ok"
    out = solve(pipe, egg())
    assert out.status == "solved" and out.creepage.speed * speed > 0.0
    a = in_plane_area(egg())
    solver = solver_of(DEFAULT_METHOD)
    if speed > 0:
        ref = solver.solve_arrays(a.pressure, a.x0, a.y0, a.dx, a.dy, out.creepage.xi,
                                  out.creepage.eta, out.creepage.phi,
                                  friction=ExponentialFriction(0.3, 0.4, 0.6),
                                  speed=out.creepage.speed)
        assert out.forces.fx == pytest.approx(ref.fx, rel=1e-9)
    # the falling law gives less than constant friction at this creepage, same sign
    const = make()
    const.on_wheel_twist(cdr(rolling_twist(xi, speed=speed, stamp_ns=T0)))
    c = solve(const, egg()).forces
    assert 0.0 < out.forces.fx / c.fx < 0.97
    values = dict(out_values(pipe))
    assert values["friction_law"] == "exponential" and values["friction_decay"] == "0.6"
    # the law may change while running, and constant friction is today's again
    pipe.update({"friction_law": "constant"})
    again = solve(pipe, egg(), stamp=T0 + 20 * MS).forces
    assert again.fx == c.fx
    with pytest.raises(ParameterError, match="friction_limit_ratio"):
        pipe.update({"friction_limit_ratio": 1.5})
    with pytest.raises(ParameterError, match="friction_decay"):
        pipe.update({"friction_decay": -0.1})
    with pytest.raises(ParameterError, match="friction_law"):
        pipe.update({"friction_law": "polach"})


def out_values(pipe):
    status = pipe.diagnostics(T0 + 30 * MS)
    return [(kv.key, kv.value) for kv in status.status[0].values]


WARM_PATH_PROBE = """
import numba
from fastsim_ros.pipeline import kernels as pipeline_kernels
from fastsim_ros.contact import compiled, kernels, samples, slip_power
from fastsim_ros.ros.params import METHODS
from fastsim_ros.pipeline import Pipeline, PipelineConfig
from msg_adapters import patch, patch_kernels
from ros_messages import cdr, cloud_msg, rolling_twist

compiled.warm_up()
patch.warm_up()
pipeline_kernels.warm_up()


def signatures():
    return {(mod.__name__, name): len(f.signatures)
            for mod in (kernels, patch_kernels, pipeline_kernels, slip_power)
            for name, f in vars(mod).items() if isinstance(f, numba.core.registry.CPUDispatcher)}


before = signatures()
area = samples.semi_ellipses_patch(0.5, 2.0, cells=12, scale=8e-3, load=6e4)
for method in METHODS:
    # Polach's closed form has no traction field (the parameters refuse it)
    for traction, power in (((False, False),) if method == "polach"
                            else ((False, False), (True, False), (False, True))):
        pipe = Pipeline(PipelineConfig.from_values({"contacts": ["left"], "method": method,
                                                    "publish_traction": traction,
                                                    "frictional_power": power}))
        pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=0)))
        for k, dtype in enumerate(("<f4", "<f8", ">f8")):
            out = pipe.on_patch("left", cdr(cloud_msg(area, stamp_ns=k + 1, dtype=dtype)))
            assert out.status == "solved", out.status
print(sorted(key for key, n in signatures().items() if n != before.get(key)))
"""


def test_the_warm_ups_cover_the_hot_path():
    # numba compiles one specialisation per argument type: after the warm-ups the
    # node runs at start, its per-patch path (every method, both float widths, a
    # buffer view or a copy, with or without tractions) compiles nothing more, so
    # a node on a fresh cache never compiles at its first patch (seconds under load)
    import os
    import subprocess
    import sys
    from pathlib import Path
    here = Path(__file__).resolve().parent
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(here.parent), str(here), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-c", WARM_PATH_PROBE], cwd=here.parent, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[-2] == "[]", done.stdout


def test_a_pressure_beyond_any_material_is_too_large():
    """1e30 Pa on one cell: rejected as ``too_large`` (a wrench of 7.6e25 N was published)."""
    pipe = make()
    pipe.on_wheel_twist(cdr(rolling_twist(1e-3, stamp_ns=T0)))
    huge = egg().pressure.copy()
    huge[5, 5] = 1e30
    out = solve(pipe, egg(), stamp=T0 + 1 * MS, pressure=huge)
    assert out.status == "too_large" and "1e+30 Pa" in out.detail
    assert solve(pipe, egg(), stamp=T0 + 2 * MS).status == "solved"


def test_a_slope_reduction_runs_the_librarys_reduced_solve():
    """The node's wrench under a slope reduction is the library's reduced solve; k = 1 is not."""
    reduced = {"friction_law": "exponential", "friction_coefficient": 0.36,
               "friction_limit_ratio": 0.38, "friction_decay": 0.7, "slope_reduction_k0": 0.54,
               "slope_reduction_alpha_inf": 0.02, "slope_reduction_beta": 0.62}
    for method in ("mae_calibrated", "fastsim_ellipse"):
        pipe = make(method=method, **reduced)
        assert pipe.on_wheel_twist(cdr(rolling_twist(3e-3, stamp_ns=T0))) == "ok"
        out = solve(pipe, egg())
        assert out.status == "solved"
        a = in_plane_area(egg())
        law = ExponentialFriction(0.36, 0.38, 0.7, reduction=SlopeReduction(0.54, 0.02, 0.62))
        ref = solver_of(method).solve_arrays(a.pressure, a.x0, a.y0, a.dx, a.dy,
                                             out.creepage.xi, out.creepage.eta,
                                             out.creepage.phi, friction=law,
                                             speed=abs(out.creepage.speed))
        assert out.forces.fx == pytest.approx(ref.fx, rel=1e-9)
        full = library(method, egg(), out.creepage.xi, out.creepage.eta, out.creepage.phi,
                       mu=0.36)
        assert abs(out.forces.fx) < 0.8 * abs(full.fx)   # the reduced slope, k well below 1
        # set back to no reduction while running: the plain falling law's numbers again
        pipe.update({"slope_reduction_k0": 1.0, "slope_reduction_alpha_inf": 1.0})
        again = solve(pipe, egg(), stamp=T0 + 20 * MS)
        plain = solver_of(method).solve_arrays(a.pressure, a.x0, a.y0, a.dx, a.dy,
                                               again.creepage.xi, again.creepage.eta,
                                               again.creepage.phi, friction=ExponentialFriction(
                                                   0.36, 0.38, 0.7),
                                               speed=abs(again.creepage.speed))
        assert again.forces.fx == pytest.approx(plain.fx, rel=1e-12)
