#!/usr/bin/env python3
"""Regenerate the package's creepage-coefficient tables with the exact solver.

For each ``a/b`` and ``nu`` the ellipse ``a b = 1/pi`` is solved in full
adhesion (unit ``xi``, ``eta``, ``phi``) on grids of ``n x n`` cells over its
bounding box; each coefficient is extrapolated to zero cell size with a
first-order fit ``C(h) = C0 + k h`` (``h = 1/n``) over the grids ``n >= 60``
(docs/guide_physics.md, "The exact solver": convergence is first order, and
the staircase noise of the boundary defeats free-order Richardson on few grids).  The error
estimate of an entry is the largest change of ``C0`` when the fit is made
over the other grid ranges listed in ``FIT_RANGES``.

Writes ``fastsim_ros/data/kalker_coefficients.csv`` (C11, C22, C23, C33 of
Kalker's linear theory), ``fastsim_ros/data/half_ellipse_coefficients.csv``
(c11 ... c23 of the upper half, docs/guide_physics.md "MAE") and the raw per-grid
values to ``docs/data/coefficient_grids.csv``.

Usage: ``python scripts/make_coefficient_tables.py [--quick]``.  The full run
takes about 20 minutes on a 2-core machine.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from fastsim_ros.contact import area as areas  # noqa: E402
from fastsim_ros.contact import exact  # noqa: E402
from fastsim_ros.contact.coefficients import coefficients_from_unit_solutions  # noqa: E402

# Kalker's 19 published ratios, points in between (in log(a/b)), and a margin
# beyond both ends: MAE's zones of real patches may measure a little outside 0.1..10.
# The ends beyond 0.05..20 (0.0125..80, added with --extend) serve the zones of flange
# contacts: patches 16 mm long and under 1 mm wide (the Manchester benchmark's flange).
A_OVER_B = (0.0125, 0.0175, 0.025, 0.035,
            0.05, 0.07, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1 / 0.9,
            1 / 0.8, 1 / 0.7, 1 / 0.6, 2.0, 2.5, 1 / 0.3, 4.0, 5.0, 1 / 0.15, 10.0, 1 / 0.07, 20.0,
            1 / 0.035, 1 / 0.025, 1 / 0.0175, 1 / 0.0125)
NUS = (0.0, 0.25, 0.5)
GRIDS = (40, 60, 80, 100, 120, 160)
MAIN_FIT = (60, 80, 100, 120, 160)
FIT_RANGES = ((40, 60, 80, 100, 120, 160), (80, 100, 120, 160), (60, 80, 100, 120))

FULL_KEYS = ("C11", "C22", "C23", "C33", "C12", "C13", "C32")
HALF_KEYS = ("c11", "c12", "c13", "c21", "c22", "c23")


def solve_grid(g: float, nu: float, n: int, shape: float = 1.0) -> dict[str, float]:
    """Full-ellipse and upper-half coefficients of one grid.

    ``shape`` stretches the cell counts: ``n * shape`` cells along x and
    ``n / shape`` along y (even), for the check on a second cell shape.
    """
    a, b = areas.semi_ellipse_axes(g)
    nx = 2 * round(n * shape / 2)
    ny = 2 * round(n / shape / 2)
    ar = areas.ellipse(a, b, nx=nx, ny=ny)
    sols = exact.unit_solutions(ar, nu=nu)
    full = coefficients_from_unit_solutions(
        ar.area, tuple((s.fx, s.fy, s.mz) for s in sols))
    c = math.sqrt(ar.area / math.pi)
    upper = (ar.y > 0.0)[:, None]
    da = ar.cell_area

    def half(s: exact.TractionSolution) -> tuple[float, float]:
        return float((s.tau_x * upper).sum() * da), float((s.tau_y * upper).sum() * da)

    (fx1, fy1), (fx2, fy2), (fx3, fy3) = (half(s) for s in sols)
    out = {k: getattr(full, k) for k in FULL_KEYS}
    # docs/guide_physics.md "MAE": Fx+ = -G ab c11 xi - G ab c12 eta + G (ab)^1.5 c13 phi,
    #                Fy+ = -G ab c21 xi - G ab c22 eta - G (ab)^1.5 c23 phi   (G = 1).
    out.update(c11=-fx1 / c**2, c12=-fx2 / c**2, c13=fx3 / c**3,
               c21=-fy1 / c**2, c22=-fy2 / c**2, c23=-fy3 / c**3)
    out["iterations"] = float(max(s.iterations for s in sols))
    return out


def extrapolate(values: dict[int, float]) -> tuple[float, float]:
    """First-order fit in ``h = 1/n``: ``(C0, error estimate)``."""
    def fit(grids: tuple[int, ...]) -> float:
        h = np.array([1.0 / n for n in grids])
        v = np.array([values[n] for n in grids])
        return float(np.polyfit(h, v, 1)[1])

    c0 = fit(MAIN_FIT)
    err = max(abs(fit(r) - c0) for r in FIT_RANGES)
    return c0, err


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="three ratios and one nu only (a smoke run, writes under /tmp)")
    parser.add_argument("--extend", action="store_true",
                        help="solve only the ratios the shipped tables lack and merge their rows "
                        "in (the shipped rows stay as they are)")
    parser.add_argument("--cell-shape-check", type=float, nargs="+", metavar="A_OVER_B",
                        help="instead of the tables: extrapolate C11, C22, C23 at these a/b on "
                        "square-box cells and on cells with 4x the cell count along x per y "
                        "(writes docs/data/cell_shape_check.csv)")
    args = parser.parse_args()
    if args.cell_shape_check:
        return cell_shape_check(args.cell_shape_check)
    ratios = (0.5, 1.0, 2.0) if args.quick else A_OVER_B
    nus = (0.25,) if args.quick else NUS
    shipped: dict[str, list[list[str]]] = {}
    if args.extend:
        for name in ("kalker_coefficients.csv", "half_ellipse_coefficients.csv"):
            shipped[name] = _rows(ROOT / "fastsim_ros" / "data" / name)
        have = {float(r[0]) for r in shipped["half_ellipse_coefficients.csv"]}
        ratios = tuple(g for g in ratios if not any(abs(g - h) <= 1e-9 * g for h in have))
    out_dir = Path("/tmp/fastsim_tables") if args.quick else ROOT / "fastsim_ros" / "data"
    raw_path = (out_dir if args.quick else ROOT / "docs" / "data") / "coefficient_grids.csv"
    out_dir.mkdir(parents=True, exist_ok=True)
    raw_path.parent.mkdir(parents=True, exist_ok=True)

    t_start = time.time()
    raw_rows: list[dict[str, float]] = []
    full_rows: list[list[str]] = []
    half_rows: list[list[str]] = []
    for nu in nus:
        for g in ratios:
            per_grid: dict[int, dict[str, float]] = {}
            for n in GRIDS:
                t = time.perf_counter()
                per_grid[n] = solve_grid(g, nu, n)
                dt = time.perf_counter() - t
                raw_rows.append({"a_over_b": g, "nu": nu, "n": n, "seconds": dt, **per_grid[n]})
            full = [f"{g:.10g}", f"{nu:g}"]
            for k in FULL_KEYS[:4]:
                c0, err = extrapolate({n: per_grid[n][k] for n in GRIDS})
                full += [f"{c0:.5f}", f"{err:.5f}"]
            half = [f"{g:.10g}", f"{nu:g}"]
            for k in HALF_KEYS:
                c0, err = extrapolate({n: per_grid[n][k] for n in GRIDS})
                half += [f"{c0:.5f}", f"{err:.5f}"]
            full_rows.append(full)
            half_rows.append(half)
            print(f"nu={nu:g} a/b={g:.4g}: C11={full[2]} C22={full[4]} C23={full[6]} "
                  f"c13={half[6]}  ({time.time() - t_start:.0f} s)", flush=True)

    if args.extend:
        full_rows = _merged(shipped["kalker_coefficients.csv"], full_rows)
        half_rows = _merged(shipped["half_ellipse_coefficients.csv"], half_rows)
    command = "python scripts/make_coefficient_tables.py" + (" --quick" if args.quick else "")
    if args.extend:
        command = ("python scripts/make_coefficient_tables.py, then --extend for a/b "
                   "0.0125..0.035 and 28.57..80")
    provenance = [
        f"# Made by: {command} (fastsim_ros exact solver, fastsim_ros/contact/exact.py)",
        "# Ellipse a b = 1/pi, full adhesion, n x n cells over the bounding box for n in "
        + " ".join(map(str, GRIDS)) + ";",
        "# coefficients normalised with the discrete area; extrapolated to zero cell size by a "
        "first-order fit C0 + k/n over n in " + " ".join(map(str, MAIN_FIT)) + ";",
        "# *_err = largest change of C0 when the fit uses n in "
        + "; ".join(" ".join(map(str, r)) for r in FIT_RANGES) + ".",
    ]
    _write(out_dir / "kalker_coefficients.csv", provenance + [
        "# Kalker's linear theory: Fx = -G ab C11 xi; Fy = -G ab C22 eta - G (ab)^1.5 C23 phi;"
        " Mz = G (ab)^1.5 C23 eta - G (ab)^2 C33 phi."],
        ["a_over_b", "nu"] + [s for k in FULL_KEYS[:4] for s in (k, k + "_err")], full_rows)
    _write(out_dir / "half_ellipse_coefficients.csv", provenance + [
        "# Upper half (y > 0) of the ellipse (docs/guide_physics.md, MAE):"
        " Fx+ = -G ab c11 xi - G ab c12 eta"
        " + G (ab)^1.5 c13 phi; Fy+ = -G ab c21 xi - G ab c22 eta - G (ab)^1.5 c23 phi."],
        ["a_over_b", "nu"] + [s for k in HALF_KEYS for s in (k, k + "_err")], half_rows)
    keys = list(raw_rows[0].keys()) if raw_rows else []
    append = args.extend and raw_path.exists()
    with open(raw_path, "a" if append else "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        if not append:
            w.writeheader()
        w.writerows(raw_rows)
    print(f"done in {time.time() - t_start:.0f} s", flush=True)
    return 0


def cell_shape_check(ratios: list[float]) -> int:
    """Converge C11, C22, C23 on two cell shapes (the exactness checks' long end)."""
    path = ROOT / "docs" / "data" / "cell_shape_check.csv"
    rows = []
    for g in ratios:
        for nu in NUS:
            for shape in (1.0, 2.0):
                per = {n: solve_grid(g, nu, n, shape) for n in GRIDS}
                row = {"a_over_b": g, "nu": nu, "cells_x_per_y": shape**2}
                for k in FULL_KEYS[:3]:
                    row[k], row[k + "_err"] = extrapolate({n: per[n][k] for n in GRIDS})
                rows.append(row)
                print(row, flush=True)
    with open(path, "w", newline="") as f:
        f.write("# Made by: python scripts/make_coefficient_tables.py --cell-shape-check "
                + " ".join(f"{g:g}" for g in ratios) + "\n")
        f.write("# cells_x_per_y = 1: n x n cells over the bounding box; 4: 2n x n/2 cells.\n")
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    return 0


def _rows(path: Path) -> list[list[str]]:
    """Return the data rows of a shipped table (comments and the column line dropped)."""
    lines = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    return [row for row in csv.reader(lines[1:])]


def _merged(old: list[list[str]], new: list[list[str]]) -> list[list[str]]:
    """Old and new rows, sorted by nu then a/b (the shipped tables' order)."""
    return sorted(old + new, key=lambda r: (float(r[1]), float(r[0])))


def _write(path: Path, header: list[str], columns: list[str], rows: list[list[str]]) -> None:
    tmp = path.with_suffix(".tmp")
    with open(tmp, "w", newline="") as f:
        for line in header:
            f.write(line + "\n")
        w = csv.writer(f)
        w.writerow(columns)
        w.writerows(rows)
    tmp.replace(path)


if __name__ == "__main__":
    sys.exit(main())
