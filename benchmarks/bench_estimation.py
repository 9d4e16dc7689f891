"""Online friction estimation: its cost per rig cycle beside the cycle's solves, same run.

Issue 28's target: the estimator costs at most one extra solve's time per
cycle.  Two pipelines (``fastsim_ros.pipeline.Pipeline``), two contacts
(``left``, ``right``) of the 30-cell flange-root patch, the default method,
constant friction: one with ``friction_estimation: off``, one ``on`` (fed a
measured wrench each cycle, creepage beyond the linear range so every cycle
updates, the slope ``dF/dmu_s`` from the march's own derivative), and one
``on`` whose slope is the forward difference of a second solve per contact
(the model before it had the derivative); and, on a contaminated rail
(the modified FastSim, ``k0`` 0.6, ``alpha_inf`` 0.5, ``beta`` 0.3), one
``on`` with that reduction given and one estimating ``k0`` with ``mu_s``
(``friction_estimate_slope_reduction``: the published solve and one
solve per contact for the forward difference in each state).  One timed call is one rig
cycle: the wheelset twist, (the measured wrench,) both patches, as CDR
bytes, through the pipeline's handlers.  They are interleaved in rounds
(``bench_fastsim.per_call``).  Also timed: one
``solve_arrays`` of that patch (what "one solve" costs), one call of the
kernel it wraps, as the estimator makes it, and one call of the slope
kernel.  Prints medians and
p99 (us) and the machine line.  About 10 s.

    PYTHONPATH=. .venv/bin/python benchmarks/bench_estimation.py [--calls 5000]
"""

from __future__ import annotations

import argparse
import struct
import sys
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "test"))

import numpy as np  # noqa: E402
from bench_fastsim import machine, per_call  # noqa: E402
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from ros_messages import cdr, cloud_msg, rolling_twist  # noqa: E402

from fastsim_ros.contact import samples  # noqa: E402
from fastsim_ros.contact.compiled import CalibratedMaeSolver, warm_up  # noqa: E402
from fastsim_ros.contact.friction import friction_law  # noqa: E402
from fastsim_ros.estimation import CreepModel  # noqa: E402
from fastsim_ros.pipeline import Pipeline, PipelineConfig  # noqa: E402

T0 = 1_700_000_000 * 1_000_000_000
PERIOD_NS = 1_000_000  # a 1 kHz rig
LEFT, RIGHT = (0.0, 0.75, -0.46), (0.0, -0.75, -0.46)


def wrench(force_x: float) -> bytes:
    w = WrenchStamped()
    w.header.frame_id = "wheelset"
    w.wrench.force.x = force_x
    return cdr(w)


def stamped(raw: bytes, stamp_ns: int) -> bytearray:
    """Return the CDR message ``raw`` with its header stamp set (after the 4-byte prefix)."""
    b = bytearray(raw)
    struct.pack_into("<iI", b, 4, *divmod(stamp_ns, 1_000_000_000))
    return b


def rig_cycle(pipe: Pipeline, *, xi: float = 4e-3, speed: float = 20.0,
              measured: bool = False, cycles: int = 100_000,
              noise: float = 0.0) -> Callable[[], None]:
    """Return a function that runs the next 1 kHz rig cycle through ``pipe``.

    The wheelset twist (creepage ``xi`` at ``speed`` m/s; with ``noise``
    the creepage times ``1 + noise n``, ``n`` standard normal, from a pool
    of 97 twists in turn: a measured rig's kinematics), with ``measured``
    a measured wrench, and both contacts' 30-cell flange-root patches, as
    CDR bytes with the cycle's stamp (``bytes``, as the node gets them: the
    patch topics' header parsed once); at most ``cycles`` cycles with ``measured``.
    """
    area = samples.flange_root_patch(cells=30)
    noisy = [cdr(rolling_twist(xi * (1.0 + noise * n), speed=speed))
             for n in np.random.default_rng(0).standard_normal(97)] if noise else []
    twist = cdr(rolling_twist(xi, speed=speed))
    left = cdr(cloud_msg(area, origin=LEFT, dtype="<f8"))
    right = cdr(cloud_msg(area, origin=RIGHT, dtype="<f8"))
    stamp = [T0]
    # the measured wrenches stamped before the timing: the cycle with estimation on times
    # the pipeline's work on one more message, not the bench's making of it
    force = wrench(-2.0e4)
    forces = iter([bytes(stamped(force, T0 + k * PERIOD_NS)) for k in range(1, cycles + 1)]
                  if measured else ())

    def run() -> None:
        stamp[0] += PERIOD_NS
        t = stamp[0]
        # bytes, as rclpy hands a raw subscription's message to the node
        pipe.on_wheel_twist(bytes(stamped(noisy[t // PERIOD_NS % 97] if noise else twist, t)))
        if measured:
            pipe.on_measured_wrench(next(forces))
        pipe.on_patch("left", bytes(stamped(left, t)))
        pipe.on_patch("right", bytes(stamped(right, t)))
    return run


#: a contaminated rail's slope reduction (modified FastSim)
REDUCED = {"slope_reduction_k0": 0.6, "slope_reduction_alpha_inf": 0.5,
           "slope_reduction_beta": 0.3}


def cycle_runner(estimation: str, differenced: bool = False, cycles: int = 100_000,
                 **extra: object):
    """Return a function that runs the next rig cycle through a pipeline, and the pipeline.

    ``differenced``: the estimator's slope a forward difference (a second
    solve per contact), beside the march's own derivative; ``extra``: more
    parameters.
    """
    pipe = Pipeline(PipelineConfig.from_values(
        {"contacts": ["left", "right"], "friction_estimation": estimation, **extra}))
    if differenced:
        object.__setattr__(pipe._creep_model, "_marched_slope", False)
    return rig_cycle(pipe, measured=estimation == "on", cycles=cycles), pipe


def main() -> None:
    """Time the cycles with estimation off and on, and one solve."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=5000)
    args = parser.parse_args()
    warm_up()
    cycles = args.calls + 200  # per_call's warm-up and timed calls
    off, _ = cycle_runner("off")
    on, pipe_on = cycle_runner("on", cycles=cycles)
    differenced, _ = cycle_runner("on", differenced=True, cycles=cycles)
    reduced, _ = cycle_runner("on", cycles=cycles, **REDUCED)
    with_k0, pipe_k0 = cycle_runner("on", cycles=cycles, **REDUCED,
                                    friction_estimate_slope_reduction=True)
    area = samples.flange_root_patch(cells=30)
    solver = CalibratedMaeSolver(0.28, 8e10)

    def solve() -> None:
        solver.solve_arrays(area.pressure, area.x0, area.y0, area.dx, area.dy, 4e-3, 0.0, 0.0,
                            0.3)
    direct = CreepModel(solver)._kernel  # type: ignore[attr-defined]
    march = CreepModel(solver)._kernel  # type: ignore[attr-defined]
    law = CreepModel._kernel_law(friction_law("constant", 0.3))

    def kernel() -> None:
        direct(area.pressure, area.x0, area.y0, area.dx, area.dy, 4e-3, 0.0, 0.0, law, 20.0)

    def slope() -> None:
        march(area.pressure, area.x0, area.y0, area.dx, area.dy, 4e-3, 0.0, 0.0, law, 20.0,
              True)
    times = per_call({"cycle, estimation off": off, "cycle, estimation on": on,
                      "on, slopes differenced": differenced,
                      "on, reduction given": reduced, "on, k0 estimated too": with_k0,
                      "one solve_arrays": solve,
                      "one kernel call": kernel, "one slope kernel call": slope}, args.calls)
    print(f"machine: {machine()}")
    for name, (p50, p99) in times.items():
        print(f"{name:24s} median {p50:8.1f} us   p99 {p99:8.1f} us")
    for name in ("cycle, estimation on", "on, slopes differenced"):
        extra = times[name][0] - times["cycle, estimation off"][0]
        print(f"estimator per cycle ({name}; difference of medians): {extra:.1f} us = "
              f"{extra / times['one solve_arrays'][0]:.2f} solves")
    extra = times["on, k0 estimated too"][0] - times["on, reduction given"][0]
    print(f"k0 estimated beside the reduction given (difference of medians): {extra:.1f} us = "
          f"{extra / times['one solve_arrays'][0]:.2f} solves")
    for name, pipe in (("mu_s", pipe_on), ("mu_s and k0", pipe_k0)):
        print(f"{name}: updates {pipe.estimation_counts['updated']}, "
              f"unobservable {pipe.estimation_counts['unobservable']}")


if __name__ == "__main__":
    main()
