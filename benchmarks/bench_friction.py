"""Compiled MAE + FastSim, one 30x30 patch: falling friction against constant, same run.

the target: a solve with a slip-dependent law costs at most 2x one with
constant friction.  Times one ``MaeSolver.solve_arrays`` call (the node's
hot path) on the flange-root patch (30 cells across), constant friction
``mu = 0.4`` against the exponential law ``mu_s = 0.4``, ``A = 0.4``, ``B =
0.6`` s/m at ``|V| = 20`` m/s, at a creepage where about half the cells slip
(``xi = 3e-3``, ``phi = 0.1`` 1/m) and at full slip (``xi = 0.05``); the
equivalent-ellipse baseline likewise.  The calls of the two laws are
interleaved in rounds (``bench_fastsim.per_call``), so a drifting machine
slows both alike.  Prints medians and p99 (us), their ratio and the machine
line of every benchmark.  About 10 s.

    PYTHONPATH=. .venv/bin/python benchmarks/bench_friction.py [--calls 20000]

Figures measured here, with their machine line: benchmarks/README.md
("bench_friction.py"); about 1.3x at half slip, 1.5x at full slip.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_fastsim import machine, per_call  # noqa: E402

from fastsim_ros.contact import samples  # noqa: E402
from fastsim_ros.contact.compiled import EquivalentEllipseSolver, MaeSolver, warm_up  # noqa: E402
from fastsim_ros.contact.friction import ExponentialFriction  # noqa: E402

LAW = ExponentialFriction(0.4, 0.4, 0.6)
SPEED = 20.0
CREEP = ((3e-3, 0.0, 0.1), (0.05, 0.0, 0.1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--calls", type=int, default=20000, help="timed calls per figure")
    args = parser.parse_args()
    warm_up()
    area = samples.flange_root_patch(cells=30)
    p, x0, y0, dx, dy = area.pressure, area.x0, area.y0, area.dx, area.dy
    print(f"machine: {machine()}")
    print(f"patch: flange root, {p.shape[1]}x{p.shape[0]} cells "
          f"({np.count_nonzero(p > 0)} in contact); law: exponential mu_s = {LAW.mu_s}, "
          f"A = {LAW.limit_ratio}, B = {LAW.decay} s/m, |V| = {SPEED} m/s")
    print("| solver | xi | slip fraction | constant median / p99 (us) | "
          "exponential median / p99 (us) | ratio of medians |")
    print("| --- | --- | --- | --- | --- | --- |")
    for name, solver in (("mae", MaeSolver(0.28, 8e10)),
                         ("equivalent", EquivalentEllipseSolver(0.28, 8e10))):
        for creep in CREEP:
            fns = {
                "constant": lambda c=creep: solver.solve_arrays(p, x0, y0, dx, dy, *c, 0.4),
                "exponential": lambda c=creep: solver.solve_arrays(
                    p, x0, y0, dx, dy, *c, friction=LAW, speed=SPEED),
            }
            t = per_call(fns, args.calls)
            sf = solver.solve_arrays(p, x0, y0, dx, dy, *creep, friction=LAW,
                                     speed=SPEED).slip_fraction
            c, f = t["constant"], t["exponential"]
            print(f"| {name} | {creep[0]:g} | {sf:.2f} | {c[0]:.1f} / {c[1]:.1f} | "
                  f"{f[0]:.1f} / {f[1]:.1f} | {f[0] / c[0]:.2f} |")
    print(f"machine: {machine()}")


if __name__ == "__main__":
    main()
