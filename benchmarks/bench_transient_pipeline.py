"""Transient rolling through the pipeline: a rig cycle on the compiled and the Python path.

``rolling: transient`` keeps each contact's traction between cycles
(:class:`fastsim_ros.contact.transient.ContactMemory`).  Where the state is
carried over (no reset rule applies, the same grid) the pipeline solves on
its compiled path (:func:`fastsim_ros.pipeline.kernels.solve_cloud` with the
memory); the resets stay on the Python path.  Three pipelines, two contacts
(``left``, ``right``) of the 30-cell flange-root patch, the default method, a
1 kHz rig at 2 m/s (2 mm rolled a cycle), ``xi = 2e-3``: steady rolling,
transient on the compiled path, transient on the Python path alone (the
pipeline's fallback for resets and jumps); then steady and transient
(compiled) with the creepage's noise of a measured rig (``1e-3`` relative,
each cycle: the far field's fixed point follows a change of force every
cycle, where the noiseless cycles settle to one sweep), the ratio to the
noisy steady cycle.  One timed call is one cycle:
the wheelset twist and both patches as CDR bytes through the pipeline's
handlers, interleaved in rounds (``bench_fastsim.per_call``).  Prints medians
and p99 (us), the ratio to steady rolling and the machine line.  About 5 s.

    PYTHONPATH=. .venv/bin/python benchmarks/bench_transient_pipeline.py [--calls 5000]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from collections.abc import Callable

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "test"))

from bench_estimation import rig_cycle  # noqa: E402
from bench_fastsim import machine, per_call  # noqa: E402
from fastsim_ros.contact.compiled import warm_up  # noqa: E402
from fastsim_ros.pipeline import Pipeline, PipelineConfig  # noqa: E402


#: the creepage's relative noise of the noisy cycles (a measured rig's kinematics)
NOISE = 1e-3


def cycle_runner(rolling: str, *, compiled: bool = True,
                 noise: float = 0.0) -> tuple[Callable[[], None], Pipeline]:
    """Return a function that runs the next rig cycle through a pipeline, and the pipeline."""
    pipe = Pipeline(PipelineConfig.from_values({"contacts": ["left", "right"],
                                                "rolling": rolling}))
    if not compiled:
        pipe._compiled = None  # the Python path alone
    return rig_cycle(pipe, xi=2e-3, speed=2.0, noise=noise), pipe


def main() -> None:
    """Time a cycle in steady rolling and in transient rolling on both paths."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=5000)
    args = parser.parse_args()
    warm_up()
    runs = {"steady": cycle_runner("steady"), "transient, compiled": cycle_runner("transient"),
            "transient, Python path": cycle_runner("transient", compiled=False),
            "steady, noise": cycle_runner("steady", noise=NOISE),
            "transient, noise": cycle_runner("transient", noise=NOISE)}
    times = per_call({name: run for name, (run, _) in runs.items()}, args.calls)
    print(f"machine: {machine()}")
    for name, (p50, p99) in times.items():
        steady = times["steady, noise" if name.endswith("noise") else "steady"][0]
        print(f"{name:24s} median {p50:8.1f} us   p99 {p99:8.1f} us   {p50 / steady:5.2f}x steady")
    for name, (_, pipe) in runs.items():
        if name != "steady":
            resets = {k: v for k, v in pipe._memories["left"].counts.items() if v}
            print(f"{name}: resets of the left contact {resets}")


if __name__ == "__main__":
    main()
