"""The pipeline with ``rolling: transient``: each contact's memory, its rules, its diagnostics."""

import numpy as np
import pytest

from fastsim_ros.contact import area as areas
from fastsim_ros.contact.compiled import CalibratedMaeSolver
from fastsim_ros.contact.transient import ContactMemory, TransientSolver
from fastsim_ros.ros.params import ParameterError
from fastsim_ros.pipeline import Pipeline, PipelineConfig
from ros_messages import cdr, cloud_msg, in_plane_area, rolling_twist

MS = 1_000_000
T0 = 1_700_000_000 * 1_000_000_000
SPEED = 2.0  # m/s; at 1 kHz a cycle rolls 2 mm of the 12 mm patch
XI0, XI1 = 5e-4, 2e-3


def patch():
    """Return a Hertzian ellipse a = 6 mm, b = 4 mm, 30 x 20 cells, 40 kN."""
    return areas.ellipse(6e-3, 4e-3, nx=30, ny=20, load=4e4)


def make(**values):
    values.setdefault("contacts", ["left"])
    return Pipeline(PipelineConfig.from_values(values))


def cycle(pipe, stamp, xi, **cloud):
    """Feed one 1 kHz cycle: the twist, then the patch with the same stamp."""
    assert pipe.on_wheel_twist(cdr(rolling_twist(xi, speed=SPEED, stamp_ns=stamp))) == "ok"
    return pipe.on_patch("left", cdr(cloud_msg(patch(), stamp_ns=stamp, dtype="<f8",
                                               **cloud)))


def test_creepage_step_builds_up_over_a_contact_length() -> None:
    """A step in xi at 1 kHz, 2 m/s: the force rises over ~one contact length to the steady one."""
    steady = make()
    transient = make(rolling="transient")
    fx = []
    for n in range(12):
        stamp = T0 + n * MS
        xi = XI0 if n < 2 else XI1
        s = cycle(steady, stamp, xi)
        t = cycle(transient, stamp, xi)
        assert s.status == t.status == "solved"
        fx.append((s.forces.fx, t.forces.fx))
    # before the step: the steady state (start, then a carried steady state)
    assert fx[0][1] == fx[0][0]
    assert fx[1][1] == pytest.approx(fx[1][0], rel=1e-9)
    # after it: early and too large in steady rolling, rising in transient rolling
    assert abs(fx[0][0]) < abs(fx[2][1]) < 0.85 * abs(fx[2][0])
    rising = [abs(t) for _, t in fx[2:]]
    assert all(b >= a * (1.0 - 1e-9) for a, b in zip(rising, rising[1:]))
    # after 2 mm x 9 cycles (18 mm > 12 mm): the steady answer; the local model has it
    # exactly once the patch is renewed, the half-space's far field (the patch's shift as
    # the force builds up, transient.far_field) decays over its relaxation length (~1.8 a)
    assert fx[-1][1] == pytest.approx(fx[-1][0], rel=1e-3)


def test_the_pipeline_state_is_the_librarys() -> None:
    """Wrench for wrench the pipeline's transient answers are ContactMemory's on the patch."""
    pipe = make(rolling="transient")
    memory = ContactMemory(TransientSolver(CalibratedMaeSolver(0.28, 8e10)), max_gap=0.05)
    a = in_plane_area(patch())
    for n in range(6):
        stamp = T0 + n * MS
        xi = XI0 if n < 2 else XI1
        out = cycle(pipe, stamp, xi)
        ref, _ = memory.solve(stamp, out.creepage.speed, a.pressure, a.x0, a.y0, a.dx, a.dy,
                              out.creepage.xi, out.creepage.eta, out.creepage.phi, 0.3)
        assert out.forces.fx == pytest.approx(ref.fx, rel=1e-9, abs=1e-6)
        assert out.forces.tau_x is None  # no tractions unless publish_traction


def test_reset_rules_in_diagnostics() -> None:
    """A stamp gap resets to the steady state; a lifted wheel restarts from zero traction."""
    pipe = make(rolling="transient", transient_max_gap=0.01)
    steady = make()
    cycle(pipe, T0, XI0)
    cycle(pipe, T0 + MS, XI1)
    # 20 ms later: beyond the gap, the steady answer at once
    gap = cycle(pipe, T0 + 21 * MS, XI1)
    assert gap.forces.fx == cycle(steady, T0 + 21 * MS, XI1).forces.fx
    # the wheel lifts for a cycle, then touches down: the traction builds up again
    empty = np.zeros_like(patch().pressure)
    assert cycle(pipe, T0 + 22 * MS, XI1, pressure=empty).status == "no_contact"
    down = cycle(pipe, T0 + 23 * MS, XI1)
    assert 0.0 < down.forces.fx / gap.forces.fx < 0.6
    values = dict(pipe.report("left").values)
    assert values["rolling"] == "transient"
    assert values["transient/start"] == "1"
    assert values["transient/stamp_gap"] == "1"
    assert values["transient/lost_contact"] == "1"
    assert dict(steady.report("left").values)["rolling"] == "steady"


def test_rolling_parameter_is_checked() -> None:
    """Only steady and transient are allowed."""
    with pytest.raises(ParameterError, match="rolling"):
        make(rolling="unsteady")


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("speed", [SPEED, -SPEED])
def test_a_patch_that_moves_is_a_jump_and_one_that_creeps_is_not(compiled, speed) -> None:
    """The jump rule measures the centroid's move in the wheelset frame.

    The same patch, its contact frame's origin (its pressure centroid) moved
    5 mm across the wheel in one cycle (more than 0.3 of its 6 mm half
    length): another contact, zero traction, the build-up again; moved 0.5
    mm: the same contact, the state carried.  In the patch's own frame the
    centroid never moves (the frame's origin is the centroid), so the rule
    must not be measured there; both paths alike, either rolling direction.
    """
    pipe = make(rolling="transient")
    if not compiled:
        pipe._compiled = None  # the Python path alone
    x, y, z = (0.0, 0.75, -0.46)

    def at(n, dy):
        stamp = T0 + n * MS
        twist = rolling_twist(XI1, speed=speed, stamp_ns=stamp)
        assert pipe.on_wheel_twist(cdr(twist)) == "ok"
        return pipe.on_patch("left", cdr(cloud_msg(patch(), origin=(x, y + dy, z),
                                                   stamp_ns=stamp, dtype="<f8")))

    out = [at(n, 0.0) for n in range(12)]  # the steady state of XI1
    settled = out[-1].forces.fx
    creep = at(12, 5e-4)
    assert creep.forces.fx == pytest.approx(settled, rel=1e-3)
    jumped = at(13, 5.5e-3)
    assert 0.0 < jumped.forces.fx / settled < 0.6  # rebuilt from zero traction over 2 mm
    values = dict(pipe.report("left").values)
    assert values["transient/patch_jump"] == "1"
    again = [at(n, 5.5e-3).forces.fx for n in range(14, 26)]
    assert again[-1] == pytest.approx(settled, rel=1e-3)


def test_the_reset_keys_are_there_from_the_start_and_survive_a_new_gap_rule() -> None:
    """/diagnostics lists every transient/<reason> from the start (0 before any patch).

    A run-time transient_max_gap applies to the running memory from the next
    patch: its state and counts carry on (the memories are not dropped, the
    keys stay and the counts go on).  An empty patch followed by
    nothing for longer than the gap is a stamp gap (the history is unknown),
    not a start.
    """
    pipe = make(rolling="transient", transient_max_gap=0.01)
    values = dict(pipe.report("left").values)
    assert all(values[f"transient/{r}"] == "0" for r in
               ("start", "stamp_gap", "lost_contact", "patch_jump", "resampled", "reversed"))
    cycle(pipe, T0, XI1)
    carried = cycle(pipe, T0 + MS, XI1)
    pipe.update({"transient_max_gap": 0.05})
    assert dict(pipe.report("left").values)["transient/start"] == "1"
    # 20 ms later: within the new gap, the state carried over
    later = cycle(pipe, T0 + 21 * MS, XI1)
    assert dict(pipe.report("left").values)["transient/stamp_gap"] == "0"
    assert later.forces.fx == pytest.approx(carried.forces.fx, rel=0.05)
    empty = np.zeros_like(patch().pressure)
    assert cycle(pipe, T0 + 22 * MS, XI1, pressure=empty).status == "no_contact"
    steady = make()
    back = cycle(pipe, T0 + 122 * MS, XI1)  # 100 ms after the empty patch
    values = dict(pipe.report("left").values)
    assert values["transient/stamp_gap"] == "1" and values["transient/lost_contact"] == "0"
    assert values["transient/start"] == "1"
    assert back.forces.fx == cycle(steady, T0 + 122 * MS, XI1).forces.fx


def test_the_reset_counts_are_cumulative_across_a_method_change() -> None:
    """A run-time method (or rolling) change starts the memories afresh, the counts carry on."""
    pipe = make(rolling="transient", transient_max_gap=0.01)
    cycle(pipe, T0, XI1)
    cycle(pipe, T0 + 30 * MS, XI1)  # a gap
    pipe.update({"method": "mae"})
    values = dict(pipe.report("left").values)
    assert (values["transient/start"], values["transient/stamp_gap"]) == ("1", "1")
    cycle(pipe, T0 + 31 * MS, XI1)  # the new method's memory: a start
    values = dict(pipe.report("left").values)
    assert (values["transient/start"], values["transient/stamp_gap"]) == ("2", "1")
