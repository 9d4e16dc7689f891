#!/usr/bin/env python3
"""Tabulate FastSim's knee against the exact theory: the knee factors.

For Hertzian ellipses (``a/b`` at the nodes :data:`ASPECTS`, area 24 mm^2,
50 kN, G = 80 GPa, Coulomb friction mu = 0.3) under pure ``xi`` and pure
``eta`` at each normalised creepage ``s = |F_lin| / (mu N)`` of :data:`S`
(``F_lin`` Kalker's linear force, :func:`fastsim_ros.contact.knee.linear_force`,
on the patch's equivalent ellipse as the estimator computes it), at ``nu``
0, 0.25 and 0.5: the exact force (:func:`fastsim_ros.contact.exact.coulomb`)
and the calibrated MAE's (the default method; on an ellipse every fast
method is Kalker's FastSim), and their ratio

    kappa = |F_exact| / |F_fastsim|   (1 at s = 0).

Grids: ``CELLS`` x ``CELLS``; the exact force is also solved on
``COARSE`` x ``COARSE`` cells and the change of kappa is written
(``kappa_err``; the fast force is the same on both grids to 0.1%: FastSim's
curve in ``s`` does not depend on the grid).  That change is not the
table's error: the exact force converges slowly and not monotonically in
the cell, and where 40 and 60 cells agree finer grids still move it
(measured at nu 0.25, a/b 1, pure xi: kappa at s = 1, 1.5, 2 is 0.9925,
1.0443, 1.0613 on 60 cells, 0.9886, 1.0411, 1.0599 on 100 and 0.9868,
1.0398, 1.0592 on 158, where ``kappa_err`` says 0.00002 at s = 1.5): the
table is about half a point of kappa above the converged one at the knee
(a 130-cell table, 4 s a solve, would take two hours).  Writes
``fastsim_ros/data/fastsim_knee_factors.csv`` (provenance in its header).
Usage: ``python scripts/make_knee_table.py``: about five minutes on one core.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from fastsim_ros.contact import exact  # noqa: E402
from fastsim_ros.contact import kernels as k  # noqa: E402
from fastsim_ros.contact.area import ellipse  # noqa: E402
from fastsim_ros.contact.compiled import CalibratedMaeSolver  # noqa: E402
from fastsim_ros.contact.knee import DIRECTIONS, KNEE_FILE, linear_force  # noqa: E402

G, LOAD, MU, AREA = 8.0e10, 5.0e4, 0.3, 24e-6
NUS = (0.0, 0.25, 0.5)
ASPECTS = (0.2, 0.3, 0.45, 0.7, 1.0, 1.4, 2.2, 3.3, 5.0)
S = tuple(round(0.1 * i, 2) for i in range(31)) + (3.25, 3.5, 4.0, 5.0, 6.0, 8.0)
CELLS, COARSE = 60, 40
OUT = Path(__file__).resolve().parent.parent / "fastsim_ros" / "data" / KNEE_FILE


def unit_linear(solver: CalibratedMaeSolver, ar, direction: str) -> float:
    """Return |F_lin| (N) per unit creepage along ``direction`` (the area's equivalent ellipse)."""
    ell = np.empty(k.ELL_SIZE)
    status, _ = k.equivalent_prepare(np.ascontiguousarray(ar.pressure), ar.x0, ar.y0, ar.dx,
                                     ar.dy, G, solver._knots, solver._polys, ell)
    assert status == k.OK, status
    xi, eta = (1.0, 0.0) if direction == "xi" else (0.0, 1.0)
    fx, fy = linear_force(ell[k.ELL_A], ell[k.ELL_B], ell[k.ELL_L1], ell[k.ELL_L2],
                          ell[k.ELL_L3], xi, eta, 0.0)
    return math.hypot(fx, fy)


def kappa(nu: float, aspect: float, direction: str, cells: int) -> list[float]:
    """Return kappa at each node of :data:`S` on a ``cells`` x ``cells`` grid."""
    a = math.sqrt(AREA / math.pi * aspect)
    ar = ellipse(a, a / aspect, nx=cells, ny=cells, load=LOAD)
    solver = CalibratedMaeSolver(nu, G)
    unit = unit_linear(solver, ar, direction)
    out = []
    for s in S:
        if s == 0.0:
            out.append(1.0)
            continue
        c = s * MU * LOAD / unit
        xi, eta = (c, 0.0) if direction == "xi" else (0.0, c)
        fe = exact.coulomb(ar, xi, eta, 0.0, nu=nu, shear_modulus=G, mu=MU)
        ff = solver.solve(ar, xi, eta, 0.0, mu=MU)
        out.append(math.hypot(fe.fx, fe.fy) / math.hypot(ff.fx, ff.fy))
    return out


def main() -> None:
    """Solve every node and write the table."""
    start = time.time()
    rows = []
    worst = 0.0
    for nu in NUS:
        for aspect in ASPECTS:
            for direction in DIRECTIONS:
                fine = kappa(nu, aspect, direction, CELLS)
                coarse = kappa(nu, aspect, direction, COARSE)
                for s, kf, kc in zip(S, fine, coarse):
                    rows.append((nu, aspect, direction, s, kf, abs(kf - kc)))
                    worst = max(worst, abs(kf - kc))
            print(f"nu {nu} a/b {aspect}: {time.time() - start:.0f} s", file=sys.stderr)
    header = [
        "# Made by: python scripts/make_knee_table.py (fastsim_ros exact solver, "
        "fastsim_ros/contact/exact.py; fast: the calibrated MAE, fastsim_ros/contact/compiled.py)",
        f"# Hertzian ellipses, area {AREA * 1e6:g} mm^2, {LOAD:g} N, G {G:g} Pa, Coulomb "
        f"mu {MU}, {CELLS} x {CELLS} cells; pure xi or pure eta at s = |F_lin| / (mu N) "
        "(F_lin: fastsim_ros/contact/knee.py linear_force on the equivalent ellipse);",
        "# kappa = |F_exact| / |F_fastsim| at the same creepage; kappa_err: its change with "
        f"the exact force on {COARSE} x {COARSE} cells (largest {worst:.4f}), not its error: "
        "finer grids lower kappa at the knee by about 0.005 more (scripts/make_knee_table.py).",
        "nu,a_over_b,direction,s,kappa,kappa_err"]
    lines = header + [f"{nu:g},{aspect:g},{d},{s:g},{kf:.5f},{err:.5f}"
                      for nu, aspect, d, s, kf, err in rows]
    OUT.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {OUT} ({len(rows)} rows, {time.time() - start:.0f} s)", file=sys.stderr)


if __name__ == "__main__":
    main()
