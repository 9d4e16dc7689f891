#!/usr/bin/env python3
"""Time the exact solver: CONTACT's perfc cases and finer grids, FFT Coulomb against dense.

Coulomb friction (partial slip) on a Hertzian ellipse, CONTACT's performance
test ``test_table`` (perfc_test, ``src/test_table.f90``): G = 82 GPa, nu =
0.28, mu = 0.3, N = 82 kN, the circle a = b = 9 mm (a/b = 1), one
creepage of its table (magnitude 1.1, angle 30 degrees, spin 0.5, undone
from its scaling as CONTACT does: ``xi = 1.1 mu cos(30) c/rho``, ``phi =
0.5 mu/rho``, ``c = sqrt(a b)``, ``rho`` the Hertz radius of N), on
CONTACT's grids: 15 x 15, 25 x 25, 35 x 35 cells of potential contact, the
ellipse across ``N - 4`` of them (its scale ``N/(N - 4)``).  Then the same
case on ellipses 60, 100 and 140 cells across (15,400 cells in contact).
The median and largest of ``--runs`` calls of ``exact.coulomb`` (one call
from a user: the operator built in every call), the FFT solver and the
dense reference alternately where the dense one fits (at most
``exact.MAX_DENSE_COULOMB_CELLS`` cells; one run above 5,000 cells), both
with one BLAS thread; Newton / GMRES iterations and FFT products (FFT
solver) or Gauss-Seidel sweeps (dense); their tractions' largest
difference; and, from one more call in a child process of its own, the
largest memory traced during the call (``tracemalloc``: numpy's arrays
included) and the child's peak resident set (the interpreter and its
libraries included; the resident set after the imports is shown for scale).

Then a sample of CONTACT's whole table (its 3,220 cases: five ellipses, four
spins, seven angles, 23 magnitudes; every ``--table-stride``-th case, the
operator built once per ellipse as CONTACT keeps its influence coefficients)
on the three perfc grids, for a per-case mean against CONTACT's published
ms per case (``perfc_test/get_times.ref_out``: 2016, one thread; its time
includes the normal problem, which is analytic here).  Then full adhesion
(three unit creepages) on n x n ellipses.

Usage: ``PYTHONPATH=. .venv/bin/python benchmarks/bench_exact.py`` (about
four minutes); ``--perfc``, ``--grids``, ``--runs``, ``--table-stride``,
``--table-solvers``, ``--adhesion-grids``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_fastsim import machine  # noqa: E402

from fastsim_ros.contact import area as areas  # noqa: E402
from fastsim_ros.contact import exact  # noqa: E402
from fastsim_ros.contact.partial_slip import one_blas_thread  # noqa: E402

# CONTACT's test_table (src/test_table.f90), in SI units
G, NU, MU, LOAD = 82e9, 0.28, 0.3, 82e3
SEMI_AXES = {0.2: 4e-3, 0.5: 6e-3, 1.0: 9e-3, 2.0: 12e-3, 5.0: 20e-3}  # a (m) by a/b
SPINS = (0.0, 0.5, 1.0, 2.0)
ANGLES = (-math.pi / 2, -math.pi / 3, -math.pi / 6, 0.0, math.pi / 6, math.pi / 3, math.pi / 2)
MAGNITUDES = (0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.7, 0.9, 1.1, 1.4, 1.7, 2.0, 2.5, 3.0, 3.5, 4.0,
              5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 12.0)
#: the timed case of the table: a/b, creepage magnitude, angle, spin
CASE = (1.0, 1.1, math.pi / 6, 0.5)
#: CONTACT's published ms per case, one thread (get_times.ref_out: table_NxN, test_clib_seqNN)
CONTACT_MS = {15: (4.0, 3.6), 25: (28.0, 28.0), 35: (134.0, 133.0)}


def hertz_rho(a: float, b: float) -> float:
    """Return CONTACT's effective radius ``rho`` (m) of the Hertz ellipse ``a``, ``b``.

    m_hertz.f90 (hzcalc3d, semi-axes given): ``rho = 4 pi c^3 E* sqrt(g)/(3 N E(k))``,
    ``c = sqrt(a b)``, ``g`` the smaller over the larger axis, ``E`` the complete
    elliptic integral of the second kind of modulus ``k = sqrt(1 - g^2)``.
    """
    import scipy.special
    g = min(a, b) / max(a, b)
    c = math.sqrt(a * b)
    return (4 * math.pi * c**3 * G / (1 - NU) * math.sqrt(g)
            / (3 * LOAD * float(scipy.special.ellipe(1 - g * g))))


def table_case(cells: int, a_over_b: float, magnitude: float, angle: float,
               spin: float) -> tuple[areas.GridArea, tuple[float, float, float]]:
    """Return the area (the ellipse ``cells`` across) and creepages of a table case."""
    a = SEMI_AXES[a_over_b]
    b = a / a_over_b
    rho = hertz_rho(a, b)
    c = math.sqrt(a * b)
    area = areas.ellipse(a, b, nx=cells, ny=cells, load=LOAD)
    return area, (magnitude * MU * math.cos(angle) * c / rho,
                  magnitude * MU * math.sin(angle) * c / rho, MU * spin / rho)


def peak_rss() -> float:
    """Return the peak resident set (MB): VmHWM, the high-water mark of this process's memory.

    (``getrusage``'s ``ru_maxrss`` would not do: a child starts with its parent's.)
    """
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return math.nan


def child(cells: int, solver: str) -> None:
    """Trace one call of ``solver`` on the ellipse ``cells`` across; print JSON (MB)."""
    rss0 = peak_rss()
    area, creep = table_case(cells, *CASE)
    with one_blas_thread():
        tracemalloc.start()
        exact.coulomb(area, *creep, mu=MU, nu=NU, shear_modulus=G, solver=solver)
        traced = tracemalloc.get_traced_memory()[1] / 2**20
        tracemalloc.stop()
    print(json.dumps({"traced": traced, "rss0": rss0, "rss": peak_rss()}))


def memory(cells: int, solver: str) -> dict[str, float]:
    """Run :func:`child` in a process of its own: its memory is that call's alone."""
    done = subprocess.run([sys.executable, __file__, "--child", str(cells), solver],
                          capture_output=True, text=True, check=True,
                          env={**os.environ, "PYTHONPATH": str(Path(__file__).parents[1])})
    result: dict[str, float] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def coulomb_table(label: str, grids: list[tuple[int, int]], runs: int) -> None:
    """Time both solvers alternately on each grid, then trace each in a child process.

    ``grids``: (the size shown, cells across the ellipse).
    """
    print(f"\n{label}")
    print(f"{'grid':>8} {'cells':>6} {'solver':>6} {'median s':>9} {'max s':>8} "
          f"{'iterations':>22} {'traced MB':>9} {'peak RSS MB':>11} {'slip':>5} "
          f"{'|tau-dense|':>11}")
    for shown, cells in grids:
        area, creep = table_case(cells, *CASE)
        mask = area.mask
        n = int(np.count_nonzero(mask))
        solvers = ["fft"] + (["dense"] if n <= exact.MAX_DENSE_COULOMB_CELLS else [])
        times: dict[str, list[float]] = {solver: [] for solver in solvers}
        sols = {}
        with one_blas_thread():
            for _ in range(runs if n < 5000 else 1):
                for solver in solvers:  # alternately: a load that comes and goes hits both
                    start = time.perf_counter()
                    sols[solver] = exact.coulomb(area, *creep, mu=MU, nu=NU, shear_modulus=G,
                                                 solver=solver)
                    times[solver].append(time.perf_counter() - start)
        rss0 = 0.0
        for solver in solvers:
            sol = sols[solver]
            mem = memory(cells, solver)
            rss0 = mem["rss0"]
            its = (f"N {sol.iterations} K {sol.krylov} P {sol.products}" if solver == "fft"
                   else f"{sol.iterations} sweeps")
            diff = "-"
            if solver == "fft" and "dense" in sols:
                d = sols["dense"]
                diff = (max(np.abs(sol.tau_x - d.tau_x).max(), np.abs(sol.tau_y - d.tau_y).max())
                        / (MU * float(area.pressure.max())))
                diff = f"{diff:.1e}"
            print(f"{shown:>4}x{shown:<3} {n:>6} {solver:>6} {np.median(times[solver]):9.4f} "
                  f"{max(times[solver]):8.4f} {its:>22} {mem['traced']:9.1f} {mem['rss']:11.0f} "
                  f"{float(sol.slip[mask].mean()):5.2f} {diff:>11}")
        if "dense" in times:
            ratio = np.median(times["dense"]) / np.median(times["fft"])
            print(f"{'':>8} dense/fft {ratio:.1f}x (medians of {len(times['fft'])} alternating "
                  f"calls); resident set after the imports {rss0:.0f} MB")


def table_sample(grids: list[int], stride: int, solvers: list[str]) -> None:
    """Time every ``stride``-th case of CONTACT's table: mean time per case against CONTACT's."""
    cases = [(g, m, a, s) for g in SEMI_AXES for s in SPINS for a in ANGLES for m in MAGNITUDES]
    picked = cases[::stride]
    print(f"\nCONTACT's table (3,220 cases), every {stride}th: {len(picked)} cases per grid; "
          "the operator built once per ellipse; ms per case")
    print(f"{'grid':>8} {'solver':>6} {'mean ms':>8} {'median ms':>9} {'max ms':>8} "
          f"{'CONTACT ms (table, clib)':>25}")
    for n in grids:
        for solver in solvers:
            times = []
            ops: dict[float, exact.SteadyRollingOperator] = {}
            with one_blas_thread():
                for g, m, a, s in picked:
                    area, creep = table_case(n - 4, g, m, a, s)
                    start = time.perf_counter()
                    if g not in ops:
                        ops[g] = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=G)
                    exact.coulomb(area, *creep, mu=MU, nu=NU, shear_modulus=G, operator=ops[g],
                                  solver=solver)
                    times.append(time.perf_counter() - start)
            t = 1e3 * np.array(times)
            published = CONTACT_MS.get(n)
            pub = f"{published[0]:.1f}, {published[1]:.1f}" if published else "-"
            print(f"{n:>4}x{n:<3} {solver:>6} {t.mean():8.2f} {np.median(t):9.2f} "
                  f"{t.max():8.1f} {pub:>25}")


def adhesion(grids: list[int], runs: int) -> None:
    """Time the three unit creepages, sticking everywhere, on ellipses ``grids`` cells across."""
    print("\nfull adhesion, unit xi, eta, phi (one operator), nu = 0.25; seconds")
    print(f"{'grid':>8} {'cells':>6} {'median':>8} {'max':>8}")
    a, b = areas.semi_ellipse_axes(1.0)
    for n in grids:
        ar = areas.ellipse(a, b, nx=n, ny=n)
        times = []
        with one_blas_thread():
            for _ in range(runs):
                start = time.perf_counter()
                exact.unit_solutions(ar, nu=0.25)
                times.append(time.perf_counter() - start)
        print(f"{n:>4}x{n:<3} {np.count_nonzero(ar.mask):>6} {np.median(times):8.3f} "
              f"{max(times):8.3f}")


def main() -> int:
    """Run the tables (or, with ``--child``, trace one call)."""
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        child(int(sys.argv[2]), sys.argv[3])
        return 0
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--perfc", type=int, nargs="*", default=[15, 25, 35])
    parser.add_argument("--grids", type=int, nargs="*", default=[60, 100, 140])
    parser.add_argument("--table-stride", type=int, default=11)
    parser.add_argument("--table-solvers", nargs="*", default=["fft"],
                        choices=["fft", "dense"])
    parser.add_argument("--adhesion-grids", type=int, nargs="*", default=[30, 60, 100])
    args = parser.parse_args()
    print(f"machine: {machine()}; one BLAS thread")
    a_over_b, magnitude, angle, spin = CASE
    print(f"Coulomb friction, CONTACT's test_table case a/b = {a_over_b:g} (a = b = 9 mm), "
          f"creepage {magnitude:g} at {math.degrees(angle):.0f} deg, spin {spin:g}: "
          f"xi, eta, phi = {', '.join(f'{v:.4g}' for v in table_case(10, *CASE)[1])}; "
          "N 82 kN, mu 0.3, G 82 GPa, nu 0.28")
    coulomb_table("CONTACT's perfc grids (potential contact N x N, the ellipse N - 4 across)",
                  [(n, n - 4) for n in args.perfc], args.runs)
    coulomb_table("finer grids (the ellipse N across)", [(n, n) for n in args.grids], args.runs)
    if args.table_stride > 0 and args.perfc:
        table_sample(args.perfc, args.table_stride, args.table_solvers)
    if args.adhesion_grids:
        adhesion(args.adhesion_grids, 3)
    return 0


if __name__ == "__main__":
    sys.exit(main())
