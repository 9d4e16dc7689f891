#!/usr/bin/env python3
"""Tabulate the elastic interaction of two joined semi-ellipses with the exact solver.

MAE (docs/guide_physics.md "MAE") gives each zone the coefficients of a lone half ellipse:
the two halves of a joined pair are taken as independent.  They are not: in
the exact theory the traction on one half is changed by the other half's
(the half-space couples them), and on the 5/1 semi-ellipses the sum of
independent halves is 26% low in C~23 (docs/validation_wider.md).  This
script measures, for the family of ``area.semi_ellipses(g_lower, g_upper)``
(two semi-ellipses joined along ``y = 0``, ``a_i b_i = 1/pi``), each half's
share of the exact full-adhesion forces, in the half-ellipse normalisation
of docs/guide_physics.md "MAE" (upper half: ``Fx+ = -G ab c11 xi + G (ab)^1.5 c13 phi``,
``Fy+ = -G ab c22 eta - G (ab)^1.5 c23 phi``, ``ab = 1/pi``; the lower half
mirrored), and writes it as the *pair factor*

    k_ij(g_self, g_other, nu) = c_ij of the half g_self joined to g_other
                                / c_ij of the lone half g_self (the package's tables)

for ``ij`` in 11, 22, 23, 13.  ``k = 1`` on the diagonal by symmetry (the
pair is then one ellipse): the script writes 1 there, and solves three
diagonal pairs to check how far the extrapolated ratio is from it (the
error of the extrapolation and of the tables together).

Grids: ``cells`` cells across the wider half along ``x`` and about as many
along ``y`` (``area.semi_ellipses``), n in GRIDS; each pair coefficient is
extrapolated to zero cell size by a first-order fit ``C0 + k/n`` over all
of them (docs/guide_physics.md), the error estimate being the change of ``C0`` when
the coarsest grid is left out; ``k_err`` is that error over the lone half's
coefficient.

The nodes in ``a/b`` are chosen off the validation's semi-ellipses (0.1, 0.5,
1, 2, 5): the method's fit data and its validation data are different areas.

Writes ``fastsim_ros/data/semi_ellipse_pair_factors.csv``.
Usage: ``python scripts/make_pair_tables.py [--quick] [--jobs N]``; the full
run takes about 20 minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from fastsim_ros.contact import area as areas  # noqa: E402
from fastsim_ros.contact import exact  # noqa: E402
from fastsim_ros.contact.tables import coefficient_table  # noqa: E402

#: a/b of the table's nodes (log-spaced, off the validation's 0.1, 0.5, 1, 2, 5)
NODES = (0.07, 0.13, 0.18, 0.25, 0.32, 0.4, 0.62, 0.8, 1.25, 1.6, 2.5, 3.2, 4.0, 6.3, 9.0, 13.0)
NUS = (0.0, 0.25, 0.5)
GRIDS = (40, 60, 80, 100)
KEYS = ("c11", "c22", "c23", "c13")
#: diagonal pairs solved as a check of k = 1 (the pair is then one ellipse)
DIAGONAL_CHECK = (0.25, 1.25, 4.0)
OUT = ROOT / "fastsim_ros" / "data" / "semi_ellipse_pair_factors.csv"


def halves(g_lower: float, g_upper: float, nu: float, n: int) -> dict[str, float]:
    """Both halves' coefficients (the physics guide normalisation) of one pair on ``n`` cells."""
    ar = areas.semi_ellipses(g_lower, g_upper, cells=n)
    sols = exact.unit_solutions(ar, nu=nu)
    c = math.sqrt(ar.area / math.pi)
    upper = (ar.y > 0.0)[:, None]
    da = ar.cell_area
    out: dict[str, float] = {}
    for side, sel, sign in (("upper", upper, 1.0), ("lower", ~upper, -1.0)):
        fx1 = float((sols[0].tau_x * sel).sum() * da)
        fy2 = float((sols[1].tau_y * sel).sum() * da)
        fx3 = float((sols[2].tau_x * sel).sum() * da)
        fy3 = float((sols[2].tau_y * sel).sum() * da)
        # the lower half is the mirror image: its c13 term has the opposite sign
        out.update({f"{side}_c11": -fx1 / c**2, f"{side}_c22": -fy2 / c**2,
                    f"{side}_c23": -fy3 / c**3, f"{side}_c13": sign * fx3 / c**3})
    return out


def extrapolate(values: list[float]) -> tuple[float, float]:
    """``C0`` of ``C0 + k/n`` over GRIDS, and its change without the coarsest grid."""
    h = np.array([1.0 / n for n in GRIDS])
    v = np.array(values)
    c0 = float(np.polyfit(h, v, 1)[1])
    return c0, abs(float(np.polyfit(h[1:], v[1:], 1)[1]) - c0)


def solve_pair(job: tuple[float, float, float]) -> tuple[float, float, float, dict[str, float],
                                                         float]:
    """Extrapolated coefficients of both halves of the pair ``(g_lower, g_upper)`` at ``nu``."""
    g_lower, g_upper, nu = job
    t0 = time.perf_counter()
    per = [halves(g_lower, g_upper, nu, n) for n in GRIDS]
    res: dict[str, float] = {}
    for k in per[0]:
        res[k], res[k + "_err"] = extrapolate([p[k] for p in per])
    return g_lower, g_upper, nu, res, time.perf_counter() - t0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="three nodes, nu = 0.25, written under /tmp (a smoke run)")
    parser.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    args = parser.parse_args()
    nodes = (0.25, 1.25, 4.0) if args.quick else NODES
    nus = (0.25,) if args.quick else NUS
    out = Path("/tmp/fastsim_pairs.csv") if args.quick else OUT
    jobs = [(g1, g2, nu) for nu in nus for i, g1 in enumerate(nodes) for g2 in nodes[i + 1:]]
    jobs += [(g, g, nu) for nu in nus for g in DIAGONAL_CHECK if g in nodes]
    start = time.time()
    found: dict[tuple[float, float, float], dict[str, float]] = {}
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        for g1, g2, nu, res, dt in pool.map(solve_pair, jobs):
            found[(g1, g2, nu)] = res
            print(f"nu={nu:g} lower {g1:g} upper {g2:g}: upper c23 {res['upper_c23']:.4f} "
                  f"lower c23 {res['lower_c23']:.4f} ({dt:.0f} s, {time.time() - start:.0f} s)",
                  flush=True)
    rows: list[list[str]] = []
    worst_diag = 0.0
    for nu in nus:
        table = coefficient_table(nu)
        for g_self in nodes:
            lone = table.half(g_self)
            for g_other in nodes:
                row = [f"{g_self:g}", f"{g_other:g}", f"{nu:g}"]
                if g_self == g_other:
                    # k = 1 by symmetry; the solved diagonal pairs are the check of it
                    row += ["1", "0"] * len(KEYS)
                    if (g_self, g_self, nu) in found:
                        res = found[(g_self, g_self, nu)]
                        for k in KEYS:
                            worst_diag = max(worst_diag, abs(res[f"upper_{k}"] / lone[k] - 1.0))
                else:
                    # the upper half of (lower=g_other, upper=g_self), or the lower of the mirror
                    if (g_other, g_self, nu) in found:
                        res, side = found[(g_other, g_self, nu)], "upper"
                    else:
                        res, side = found[(g_self, g_other, nu)], "lower"
                    for k in KEYS:
                        kv = res[f"{side}_{k}"] / lone[k]
                        row += [f"{kv:.5f}", f"{res[f'{side}_{k}_err'] / lone[k]:.5f}"]
                rows.append(row)
    command = "python scripts/make_pair_tables.py" + (" --quick" if args.quick else "")
    header = [
        f"# Made by: {command} (fastsim_ros exact solver, fastsim_ros/contact/exact.py)",
        "# Two semi-ellipses joined along y = 0 (area.semi_ellipses, a_i b_i = 1/pi), full"
        " adhesion, about the join line's middle; n x ~n cells, n in "
        + " ".join(map(str, GRIDS)) + ", extrapolated by C0 + k/n;",
        "# k_ij = c_ij of the half a/b = g_self joined to the half g_other / c_ij of the lone"
        " half (fastsim_ros/data tables); *_err: change of C0 without the coarsest grid,"
        " over the lone half's c_ij.",
        "# Diagonal check (k = 1 by symmetry) at a/b "
        + ", ".join(f"{g:g}" for g in DIAGONAL_CHECK) + ":"
        f" largest |k - 1| = {worst_diag:.4f} (the extrapolation's and the tables' error);"
        " every diagonal entry is set to 1.",
    ]
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".tmp")
    with open(tmp, "w", newline="") as f:
        for line in header:
            f.write(line + "\n")
        w = csv.writer(f)
        names = [s for k in KEYS for s in (f"k{k[1:]}", f"k{k[1:]}_err")]
        w.writerow(["g_self", "g_other", "nu"] + names)
        w.writerows(rows)
    tmp.replace(out)
    print(f"wrote {out} in {time.time() - start:.0f} s; diagonal |k - 1| <= {worst_diag:.4f}",
          flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
