#!/usr/bin/env python3
"""Time the exact solver: full adhesion (FFT + GMRES) and Coulomb friction; print medians."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_fastsim import machine  # noqa: E402

from fastsim_ros.contact import area as areas  # noqa: E402
from fastsim_ros.contact import exact  # noqa: E402


def timed(fn, runs: int) -> tuple[float, float]:
    """Median and p99 (seconds) of ``runs`` calls of ``fn``."""
    t = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        t.append(time.perf_counter() - start)
    return float(np.median(t)), float(np.percentile(t, 99))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--adhesion-grids", type=int, nargs="+", default=[30, 60, 100])
    parser.add_argument("--coulomb-grids", type=int, nargs="+", default=[30, 60])
    args = parser.parse_args()
    print(f"machine: {machine()}")
    a, b = areas.semi_ellipse_axes(1.0)
    print("full adhesion, unit xi, eta, phi (one operator), nu = 0.25; seconds")
    print(f"{'grid':>8} {'cells':>6} {'median':>8} {'p99':>8}")
    for n in args.adhesion_grids:
        ar = areas.ellipse(a, b, nx=n, ny=n)
        med, p99 = timed(lambda: exact.unit_solutions(ar, nu=0.25), args.runs)
        print(f"{n:>4}x{n:<3} {np.count_nonzero(ar.mask):>6} {med:8.3f} {p99:8.3f}")
    print("Coulomb friction, Hertzian ellipse 6 x 4 mm, 10 kN, mu 0.3, G 8e10 Pa, nu 0.28,"
          " xi 2e-4, eta 1e-4, phi 0.05 1/m (partial slip); seconds")
    print(f"{'grid':>8} {'cells':>6} {'median':>8} {'p99':>8} {'slip':>6}")
    for n in args.coulomb_grids:
        ar = areas.ellipse(6e-3, 4e-3, nx=n, ny=n, load=1e4)
        sol = exact.coulomb(ar, 2e-4, 1e-4, 0.05, mu=0.3, nu=0.28, shear_modulus=8e10)
        med, p99 = timed(lambda: exact.coulomb(ar, 2e-4, 1e-4, 0.05, mu=0.3, nu=0.28,
                                               shear_modulus=8e10), args.runs)
        print(f"{n:>4}x{n:<3} {np.count_nonzero(ar.mask):>6} {med:8.3f} {p99:8.3f} "
              f"{sol.slip[ar.mask].mean():6.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
