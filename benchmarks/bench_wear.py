"""Time what the wear outputs add to a patch; print medians and p99, variants side by side.

Run from the package root (``benchmarks/README.md``)::

    PYTHONPATH=. .venv/bin/python benchmarks/bench_wear.py [--calls 3000]

One pipeline per variant, the same patch message (a 30 x 30 Hertzian patch
with spin, partial slip) and wheelset twist, ``Pipeline.on_patch`` then
``Pipeline.messages`` timed together per call (``time.perf_counter_ns``),
the variants interleaved call by call so that the machine's load falls on
all alike:

- ``off``: the defaults (the compiled path, no wear topics),
- ``wear_outputs``: T-gamma, T-gamma/A, the wear and RCF tables and the two
  ``Vector3Stamped`` messages (the compiled path still),
- ``wear_outputs + frictional_power``: the solve keeps its tractions (the
  Python path) and sweeps them once more for the slip's dissipation,

for each method; then the library alone: ``solve_arrays`` without
tractions, with tractions (which now include the dissipation sweep) and the
dissipation sweep alone (``slip_power.mae_dissipation``), on the same
patch.  The machine is printed with the figures: quote it with them.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import slip_power
from fastsim_ros.contact.compiled import CalibratedMaeSolver, MaeSolver, warm_up
from fastsim_ros.machine import machine
from fastsim_ros.pipeline import Pipeline, PipelineConfig
from fastsim_ros.pipeline.kernels import warm_up as warm_pipeline

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))
from ros_messages import cdr, cloud_msg, rolling_twist  # noqa: E402

NU, G, MU = 0.28, 8.0e10, 0.3
T0 = 1_700_000_000 * 1_000_000_000


def stats(ns: list[int]) -> str:
    us = np.asarray(ns) * 1e-3
    return f"{np.median(us):7.1f} / {np.percentile(us, 99):7.1f}"


def pipeline_variants(method: str, calls: int) -> None:
    area = areas.ellipse(6e-3, 5e-3, nx=30, ny=30, load=5e4)
    patch = cdr(cloud_msg(area, stamp_ns=T0 + 1_000_000, dtype="<f8"))
    twist = cdr(rolling_twist(1.5e-3, stamp_ns=T0))
    variants = {"off": {}, "wear_outputs": {"wear_outputs": True},
                "wear_outputs + frictional_power": {"wear_outputs": True,
                                                    "frictional_power": True}}
    pipes = {}
    for name, extra in variants.items():
        pipe = Pipeline(PipelineConfig.from_values({"contacts": ["left"], "method": method,
                                                    "publish_markers": False, **extra}))
        pipe.on_wheel_twist(twist)
        pipes[name] = pipe
    times: dict[str, list[int]] = {name: [] for name in variants}
    for k in range(calls + 200):
        for name, pipe in pipes.items():
            pipe._contacts["left"].last_stamp_ns = None  # the same stamp each call
            start = time.perf_counter_ns()
            out = pipe.on_patch("left", patch)
            pipe.messages(out)
            if k >= 200:
                times[name].append(time.perf_counter_ns() - start)
    print(f"  {method}: on_patch + messages (us), median / p99")
    for name, ns in times.items():
        print(f"    {name:34s} {stats(ns)}")


def library(calls: int) -> None:
    area = areas.ellipse(6e-3, 5e-3, nx=30, ny=30, load=5e4)
    creep = (1.5e-3, 3e-4, 1.0)
    for solver in (MaeSolver(NU, G), CalibratedMaeSolver(NU, G)):
        p = area.pressure
        f = solver.solve_arrays(p, area.x0, area.y0, area.dx, area.dy, *creep, MU,
                                tractions=True)
        density = np.empty(p.shape)

        def sweep() -> None:
            slip_power.mae_dissipation(p, area.x0, area.y0, area.dx, area.dy, *creep, MU,
                                       0.0, 0.0, solver._rule, False, solver.shear_modulus,
                                       solver._knots, solver._polys, solver._calibrated,
                                       solver._pair_knots, solver._pair_values, f.tau_x,
                                       f.tau_y, f.slip, density)

        cases: dict[str, Callable[[], object]] = {
            "solve_arrays": lambda: solver.solve_arrays(p, area.x0, area.y0, area.dx, area.dy,
                                                        *creep, MU),
            "solve_arrays, tractions + power": lambda: solver.solve_arrays(
                p, area.x0, area.y0, area.dx, area.dy, *creep, MU, tractions=True),
            "the dissipation sweep alone": sweep}
        times: dict[str, list[int]] = {name: [] for name in cases}
        for k in range(calls + 200):
            for name, call in cases.items():
                start = time.perf_counter_ns()
                call()
                if k >= 200:
                    times[name].append(time.perf_counter_ns() - start)
        print(f"  {type(solver).__name__} 30 x 30 (us), median / p99")
        for name, ns in times.items():
            print(f"    {name:34s} {stats(ns)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=3000)
    args = parser.parse_args()
    warm_up()
    warm_pipeline()
    print(machine())
    print("the pipeline, one patch per call, variants interleaved:")
    for method in ("mae_calibrated", "mae", "fastsim_ellipse"):
        pipeline_variants(method, args.calls)
    print("the library:")
    library(args.calls)


if __name__ == "__main__":
    main()
