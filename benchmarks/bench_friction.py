"""Compiled MAE + FastSim, one 30x30 patch: falling friction against constant, same run.

TARGETS.md: a solve with a slip-dependent law costs at most 2x one with
constant friction.  Times one ``MaeSolver.solve_arrays`` call (the node's
hot path) on the flange-root patch (30 cells across) at a creepage where
about half the cells slip, and at full slip; prints medians and p99 (us)
and the machine.  About 10 s.
"""

from __future__ import annotations

import platform
import time

import numpy as np

from fastsim_ros.contact import samples
from fastsim_ros.contact.compiled import MaeSolver, warm_up
from fastsim_ros.contact.friction import ExponentialFriction


def times(fn, reps=20000):
    out = np.empty(reps)
    for k in range(reps):
        t = time.perf_counter()
        fn()
        out[k] = time.perf_counter() - t
    return np.median(out) * 1e6, np.percentile(out, 99) * 1e6


def main() -> None:
    warm_up()
    area = samples.flange_root_patch(cells=30)
    p, x0, y0, dx, dy = area.pressure, area.x0, area.y0, area.dx, area.dy
    solver = MaeSolver(0.28, 8e10)
    law = ExponentialFriction(0.4, 0.4, 0.6)
    print(f"machine: {platform.machine()} {platform.processor() or ''} "
          f"{platform.python_implementation()} {platform.python_version()}, "
          f"patch {p.shape[1]}x{p.shape[0]} cells ({np.count_nonzero(p > 0)} in contact)")
    for xi in (3e-3, 0.05):
        const = times(lambda: solver.solve_arrays(p, x0, y0, dx, dy, xi, 0.0, 0.1, 0.4))
        fall = times(lambda: solver.solve_arrays(p, x0, y0, dx, dy, xi, 0.0, 0.1,
                                                 friction=law, speed=20.0))
        sf = solver.solve_arrays(p, x0, y0, dx, dy, xi, 0.0, 0.1, friction=law,
                                 speed=20.0).slip_fraction
        print(f"xi = {xi:g} (slip fraction {sf:.2f}): constant median {const[0]:.1f} us "
              f"p99 {const[1]:.1f} us | exponential median {fall[0]:.1f} us p99 "
              f"{fall[1]:.1f} us | ratio {fall[0] / const[0]:.2f}")


if __name__ == "__main__":
    main()
