#!/usr/bin/env python3
"""The seed paper's comparison redone: DLM (Table 1, Figures 4-5) and ASM (Table 2, Figure 6).

Writes ``docs/data/validation_seed.json``, ``docs/figures/seed_*.png`` and
``docs/validation_seed.md``: Kalker's deformation
levelling method (:mod:`fastsim_ros.contact.dlm`) and Knothe and Hung's
asymptotic strip method (:mod:`fastsim_ros.contact.asm`) beside the paper's
numbers (Tables 1 and 2 read from the printed tables, when present),
the readings of DLM that were tried and why the one in the package was kept,
ASM's collocation fit (``--fit-asm``) and its check on the rows and Poisson
ratios it was not fitted on, and the readings of Knothe and Hung's method
tried against Table 2's printed ASM columns (``scripts/asm_candidates.py``).

Usage: ``python scripts/validate_seed.py [--fit-asm] [--report-only | --candidates-only]``.
About a minute on 2 cores (``--fit-asm`` adds a few minutes).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from benchmarks.machine import machine  # noqa: E402  (the one machine line)
from fastsim_ros.contact import area as areas  # noqa: E402
from fastsim_ros.contact import asm, dlm  # noqa: E402
from fastsim_ros.contact.fastsim import sweep_integrals  # noqa: E402
from fastsim_ros.contact.seed_tables import read_table1, read_table2  # noqa: E402
import asm_candidates  # noqa: E402


DOCS = ROOT / "docs"
DATA = DOCS / "data" / "validation_seed.json"
FIG = DOCS / "figures"
#: Kalker's published table (3 digits: the reference directory beside the checkout, or where
#: ``$SHARED_REFERENCE`` says); without it, the package's own (the exact solver's, within 1%
#: of it: docs/validation.md), and the report says so
PUBLISHED = Path(os.environ.get("SHARED_REFERENCE", ROOT.parent / "shared" / "reference")
                 ) / "kalker_coefficients.csv"
PACKAGE_TABLE = ROOT / "fastsim_ros" / "data" / "kalker_coefficients.csv"
KALKER = PUBLISHED if PUBLISHED.exists() else PACKAGE_TABLE
#: the seed's Tables 1 and 2 as printed, beside Kalker's table
SEED_TABLES = PUBLISHED.parent / "seed_tables_1_2.md"
NU = 0.25
#: cells across each ellipse for DLM (its levelling and FastSim's coefficients)
DLM_CELLS = 100
#: strips across each ellipse for ASM (exact chords)
ASM_STRIPS = 60
#: the command line's default grid for ``--method asm`` (cells across the ellipse)
ASM_CLI_CELLS = 100
NAMES = ("C11", "C22", "C23")
#: the seed's Table 1: (a/b, name) -> (AMK, DLM), as printed (read from the reference file;
#: the figures below only where it is not beside the checkout)
TABLE1 = ({(r.a_over_b, n): (r.amk[i], r.dlm[i]) for r in read_table1(SEED_TABLES)
           for i, n in enumerate(NAMES)} if SEED_TABLES.exists() else
          {(0.1, "C11"): (3.31, 3.04), (1.0, "C11"): (4.12, 4.49), (10.0, "C11"): (11.7, 13.23),
           (0.1, "C22"): (2.52, 2.43), (1.0, "C22"): (3.67, 4.08), (10.0, "C22"): (12.8, 14.53),
           (0.1, "C23"): (0.473, 0.13), (1.0, "C23"): (1.47, 1.23),
           (10.0, "C23"): (14.6, 10.73)})
TABLE1_RATIOS = (0.1, 1.0, 10.0)
#: strips across each ellipse for the readings of Knothe and Hung's method tried
CANDIDATE_STRIPS = 30
#: the readings tried against Table 2's ASM columns: (label, basis, collocation fractions)
ASM_CANDIDATES: tuple[tuple[str, str, tuple[float, ...]], ...] = (
    ("quadratic, the package's fitted points", "quadratic", asm.ASM_COLLOCATION),
    ("quadratic, Gauss-Chebyshev points (n = 2)", "quadratic",
     asm_candidates.chebyshev_collocation(2)),
    ("quadratic, Gauss-Legendre points", "quadratic",
     (0.5 - 0.5 / math.sqrt(3.0), 0.5 + 0.5 / math.sqrt(3.0))),
    ("quadratic, 1/4 and 3/4", "quadratic", (0.25, 0.75)),
    ("quadratic, 1/3 and 2/3", "quadratic", (1.0 / 3.0, 2.0 / 3.0)),
    ("2-D full-adhesion shape, 2 terms, 1/4 and 3/4", "carter2", (0.25, 0.75)),
    ("2-D full-adhesion shape, 2 terms, Gauss-Chebyshev (n = 2)", "carter2",
     asm_candidates.chebyshev_collocation(2)),
    ("Hertz-like shape, 2 terms, Gauss-Chebyshev (n = 2)", "hertz2",
     asm_candidates.chebyshev_collocation(2)),
    ("2-D full-adhesion shape, 1 term, Gauss-Chebyshev (n = 1: 1/4)", "carter1",
     asm_candidates.chebyshev_collocation(1)),
    ("2-D full-adhesion shape, 1 term, 0.45", "carter1", (0.45,)),
    ("2-D full-adhesion shape, 1 term, strip middle (1/2)", "carter1", (0.5,)),
)
#: ASM's collocation is fitted on these a/b (nu = 0.25); every other row of the table checks it
ASM_FIT_RATIOS = (0.2, 0.5, 1.0, 2.0, 5.0)


def kalker() -> dict[tuple[float, float], dict[str, float]]:
    """Return Kalker's table: ``(a/b, nu) -> {C11, C22, C23}``."""
    out = {}
    with KALKER.open() as f:
        for row in csv.DictReader(line for line in f if not line.startswith("#")):
            out[(round(float(row["a_over_b"]), 6), float(row["nu"]))] = {
                k: float(row[k]) for k in NAMES}
    return out


def ratios(nu: float) -> list[float]:
    """Return the table's a/b values at ``nu`` (Kalker's published range, 0.1 to 10)."""
    return sorted(g for g, n in kalker() if n == nu and 0.1 - 1e-9 <= g <= 10.0 + 1e-9)


# ----------------------------------------------------------------------------- DLM

def _ellipse(g: float, n: int) -> areas.GridArea:
    a, b = areas.semi_ellipse_axes(g)
    # Hertzian pressure: the full-slip traction of the iteration's first step
    return areas.ellipse(a, b, nx=n, ny=n, load=1.0)


def _coefficients_from_l(ar: areas.GridArea, l1: float, l2: float, l3: float) -> dict[str, float]:
    """Return FastSim's full-adhesion coefficients on ``ar`` with ``L1 .. L3`` (G = 1 Pa)."""
    x_c, _ = asm.centroid(ar)
    d, s3 = sweep_integrals(ar, x_c)
    da = ar.cell_area
    c = math.sqrt(ar.area / math.pi)
    return {"C11": float(d.sum()) * da / (l1 * c**2), "C22": float(d.sum()) * da / (l2 * c**2),
            "C23": float(s3.sum()) * da / (l3 * c**3)}


Reading = Callable[[areas.GridArea], tuple[float, float, float]]


def _readings() -> dict[str, tuple[str, Reading]]:
    """Return the readings of DLM compared (name -> (what, flexibilities of an area))."""

    def levelled(traction: str, translation: str, weighted: bool = False) -> Reading:
        def flex(ar: areas.GridArea) -> tuple[float, float, float]:
            x_c, y_c = asm.centroid(ar)
            disp = dlm.Displacements(ar, nu=NU, shear_modulus=1.0)
            mask = ar.mask
            zero = np.zeros(mask.shape)
            if traction == "adhesion":
                d, s3 = sweep_integrals(ar, x_c)
                y = ar.y[:, None] - y_c
                unit = ((d, zero), (zero, d), (np.where(mask, -y * d, 0.0), s3))
            else:
                p = np.where(mask, ar.pressure, 0.0)
                x = ar.x[None, :] - x_c
                y = ar.y[:, None] - y_c
                r = np.hypot(x, y)
                r = np.where(r > 0.0, r, 1.0)
                unit = ((p, zero), (zero, p), (-p * y / r, p * x / r))
            out = []
            for k, (tx, ty) in enumerate(unit):
                ux, uy = disp(tx, ty)
                pairs = (([ux], [tx]), ([uy], [ty]), ([ux, uy], [tx, ty]))
                us, ts = pairs[k]
                if translation == "free" and weighted:
                    # least squares weighted by the traction's magnitude
                    num = den = 0.0
                    for u, t in zip(us, ts):
                        w = np.abs(t[mask])
                        uu = u[mask] - (w * u[mask]).sum() / w.sum()
                        tt = t[mask] - (w * t[mask]).sum() / w.sum()
                        num += float((w * uu * tt).sum())
                        den += float((w * tt * tt).sum())
                    out.append(num / den)
                elif translation == "free":
                    out.append(dlm.level(us, ts, mask))
                elif translation == "none":
                    out.append(sum(float((u[mask] * t[mask]).sum()) for u, t in zip(us, ts))
                               / sum(float((t[mask] ** 2).sum()) for t in ts))
                else:  # one free translation per strip (each row) and component
                    num = den = 0.0
                    for u, t in zip(us, ts):
                        for j in range(ar.ny):
                            m = mask[j]
                            if np.count_nonzero(m) < 2:
                                continue
                            uu = u[j][m] - u[j][m].mean()
                            tt = t[j][m] - t[j][m].mean()
                            num += float((uu * tt).sum())
                            den += float((tt * tt).sum())
                    out.append(num / den)
            return out[0], out[1], out[2]
        return flex

    return {
        "package": ("adhesion traction, a free translation per component (the package's)",
                    levelled("adhesion", "free")),
        "no_translation": ("adhesion traction, no translation", levelled("adhesion", "none")),
        "strip_translation": ("adhesion traction, a free translation per strip",
                              levelled("adhesion", "strip")),
        "full_slip": ("full-slip traction (mu p along the rigid slip), a free translation "
                      "per component, not iterated", levelled("full_slip", "free")),
        "weighted": ("adhesion traction, a free translation per component, least squares "
                     "weighted by the traction", levelled("adhesion", "free", weighted=True)),
        "chord": ("adhesion traction, a free translation per component, least squares "
                  "weighted by each cell's strip length (`dlm.DLM_CHORD_FASTSIM`)", _chord),
    }


def _chord(ar: areas.GridArea) -> tuple[float, float, float]:
    """Return the flexibilities of DLM levelled with every cell weighted by its strip's length."""
    it = dlm.dlm_iteration(ar, nu=NU, shear_modulus=1.0, steps=2, weighting="chord")
    return it.l1[-1], it.l2[-1], it.l3[-1]


def dlm_part() -> dict[str, Any]:
    """Return DLM's Table 1 under each reading, its curve over a/b and the levelling's picture."""
    out: dict[str, Any] = {"table1": {}, "curve": {}, "grid": {}}
    readings = _readings()
    for key, (what, flex) in readings.items():
        rows = {}
        for g in TABLE1_RATIOS:
            ar = _ellipse(g, DLM_CELLS)
            rows[str(g)] = _coefficients_from_l(ar, *flex(ar))
        out["table1"][key] = {"what": what, "rows": rows}
    # the package's own path (dlm_coefficients: FastSim with the levelled L in full adhesion)
    out["package_cli"] = {}
    for g in TABLE1_RATIOS:
        c = dlm.dlm_coefficients(_ellipse(g, DLM_CELLS), nu=NU)
        out["package_cli"][str(g)] = {k: getattr(c, k) for k in NAMES}
    # grid convergence of the package's reading, and of the chord-weighted one
    out["chord_grid"] = {}
    for n in (40, 60, 100, 160):
        out["grid"][str(n)] = {str(g): {k: getattr(dlm.dlm_coefficients(_ellipse(g, n), nu=NU),
                                                   k) for k in NAMES}
                               for g in TABLE1_RATIOS}
        out["chord_grid"][str(n)] = {
            str(g): {k: getattr(dlm.DLM_CHORD_FASTSIM.coefficients(_ellipse(g, n), nu=NU), k)
                     for k in NAMES} for g in TABLE1_RATIOS}
    for g in ratios(NU):
        c = dlm.dlm_coefficients(_ellipse(g, 60), nu=NU)
        out["curve"][str(g)] = {k: getattr(c, k) for k in NAMES}
    # the iteration and the levelled displacement along the middle strip of the circle
    ar = _ellipse(1.0, DLM_CELLS)
    it = dlm.dlm_iteration(ar, nu=NU, shear_modulus=1.0, steps=3)
    out["iteration"] = {"L1": list(it.l1), "L2": list(it.l2), "L3": list(it.l3)}
    x_c, _ = asm.centroid(ar)
    d, _ = sweep_integrals(ar, x_c)
    disp = dlm.Displacements(ar, nu=NU, shear_modulus=1.0)
    ux, _ = disp(np.where(ar.mask, d, 0.0), np.zeros(ar.mask.shape))
    lev = dlm.level([ux], [d], ar.mask)
    j = ar.ny // 2
    m = ar.mask[j]
    offset = float((ux[ar.mask] - lev * d[ar.mask]).mean())
    out["levelling"] = {"x": ar.x[m].tolist(), "u": ux[j][m].tolist(),
                        "L_tau_plus_c": (lev * d[j][m] + offset).tolist(), "L1": lev}
    return out


# ----------------------------------------------------------------------------- ASM

def asm_errors(collocation: tuple[float, float], gs: tuple[float, ...] | list[float],
               nu: float) -> np.ndarray:
    """Return ASM's relative errors against Kalker's at ``gs`` and ``nu`` (rows: a/b)."""
    table = kalker()
    out = []
    for g in gs:
        c = asm.ellipse_coefficients(g, nu=nu, strips=ASM_STRIPS, collocation=collocation)
        k = table[(round(g, 6), nu)]
        out.append([getattr(c, n) / k[n] - 1.0 for n in NAMES])
    return np.array(out)


def fit_asm() -> dict[str, Any]:
    """Fit ASM's two collocation fractions on ASM_FIT_RATIOS (least squares, nu = 0.25)."""
    from scipy.optimize import minimize

    def rms(p: np.ndarray) -> float:
        if not 0.0 < p[0] < p[1] < 1.0:
            return 10.0
        return float(np.sqrt((asm_errors((p[0], p[1]), ASM_FIT_RATIOS, NU) ** 2).mean()))

    best = None
    for start in ((0.2, 0.8), (0.1, 0.7), (0.15, 0.9), (0.05, 0.5)):
        r = minimize(rms, np.array(start), method="Nelder-Mead",
                     options={"xatol": 1e-5, "fatol": 1e-8})
        if best is None or r.fun < best.fun:
            best = r
    assert best is not None
    return {"collocation": [float(best.x[0]), float(best.x[1])], "rms": float(best.fun),
            "fit_ratios": list(ASM_FIT_RATIOS), "nu": NU, "strips": ASM_STRIPS}


def asm_part() -> dict[str, Any]:
    """Return ASM's Table 2 (nu = 0.25) and its check at nu = 0 and 0.5, with the cost."""
    out: dict[str, Any] = {"collocation": list(asm.ASM_COLLOCATION), "rows": {}}
    for nu in (0.25, 0.0, 0.5):
        rows = {}
        for g in ratios(nu):
            t0 = time.perf_counter()
            c = asm.ellipse_coefficients(g, nu=nu, strips=ASM_STRIPS)
            rows[str(g)] = {**{k: getattr(c, k) for k in NAMES},
                            "seconds": time.perf_counter() - t0}
        out["rows"][str(nu)] = rows
    # what `fastsim_contact coefficients --shape ellipse --a-over-b G --method asm --nu 0.25`
    # prints (its default grid: ASM_CLI_CELLS cells across the ellipse, ASM + FastSim)
    out["cli"] = {}
    for g in ratios(NU):
        a, b = areas.semi_ellipse_axes(g)
        ar = areas.ellipse(a, b, nx=ASM_CLI_CELLS, ny=ASM_CLI_CELLS)
        c = asm.asm_fastsim_coefficients(ar, nu=NU)
        out["cli"][str(g)] = {k: getattr(c, k) for k in NAMES}
    # the strips' traction against the exact one along the circle's middle strip
    from fastsim_ros.contact import exact
    a, b = areas.semi_ellipse_axes(1.0)
    ar = areas.ellipse(a, b, nx=80, ny=80)
    sol = exact.full_adhesion(ar, 1.0, 0.0, 0.0, nu=NU, shear_modulus=1.0)
    strips = asm.area_strips(ar)
    mat, _, _ = asm.influence_matrix(strips, nu=NU)
    npts = mat.shape[0] // 2
    coef = np.linalg.solve(mat, np.concatenate([np.ones(npts), np.zeros(npts)]))
    j = ar.ny // 2
    k = int(np.flatnonzero(np.isclose(strips.y, ar.y[j]))[0])
    xs = np.linspace(strips.x_t[k], strips.x_l[k], 81)
    s = (strips.x_l[k] - xs) / (strips.x_l[k] - strips.x_t[k])
    m = ar.mask[j]
    out["traction"] = {"x_exact": ar.x[m].tolist(), "tau_exact": sol.tau_x[j][m].tolist(),
                       "x_asm": xs.tolist(),
                       "tau_asm": (coef[4 * k] * s + coef[4 * k + 1] * s * s).tolist(),
                       "collocation_x": [float(strips.x_l[k] - f * (strips.x_l[k]
                                                                    - strips.x_t[k]))
                                         for f in asm.ASM_COLLOCATION]}
    return out


def candidates_part() -> dict[str, Any]:
    """Return each reading of Table 2's ASM tried: its C11, C22, C23 on every printed row."""
    if not SEED_TABLES.exists():
        return {}
    out: dict[str, Any] = {"strips": CANDIDATE_STRIPS, "self_check": asm_candidates.self_check(),
                           "readings": []}
    for label, basis, col in ASM_CANDIDATES:
        t0 = time.perf_counter()
        rows = {}
        for r in read_table2(SEED_TABLES):
            c = asm_candidates.ellipse_coefficients(r.a_over_b, basis, col, nu=NU,
                                                    strips=CANDIDATE_STRIPS)
            rows[str(r.a_over_b)] = {n: getattr(c, n) for n in NAMES}
        out["readings"].append({"label": label, "basis": basis, "collocation": list(col),
                                "rows": rows, "seconds": time.perf_counter() - t0})
        print(f"candidate {label}: {time.perf_counter() - t0:.1f} s", flush=True)
    return out


def _meets(n: str, got: float, printed: float) -> bool:
    """Return whether ``got`` meets the target against a printed ASM value."""
    e = abs(got / printed - 1.0)
    return e <= 0.02 if n != "C23" else (e <= 0.03 or abs(got - printed) <= 0.02)


# ----------------------------------------------------------------------------- report

def _pct(v: float) -> str:
    return f"{100 * v:+.1f}%"


def _cli_spread(a: dict[str, Any]) -> float:
    """Return the largest relative difference between ASM's command-line and strip values."""
    rows = a["rows"]["0.25"]
    return max(abs(v[n] / rows[g][n] - 1.0) for g, v in a.get("cli", {}).items() for n in NAMES)


def _report_candidates(add: Callable[[str], None], cand: dict[str, Any],
                       printed: list[Any]) -> None:
    """Add the readings of Knothe and Hung's method tried, against the printed ASM columns."""
    if not cand:
        add("(The readings tried were not computed in this run.)\n")
        return
    add("**The readings of Knothe and Hung's method tried** (`scripts/asm_candidates.py`:"
        " the same strips, kernels and full-adhesion condition as the package's ASM, with"
        " another traction shape along each strip or other collocation fractions `s`,"
        f" measured from the leading edge; {cand['strips']} strips, nu = {NU}; with the"
        " quadratic shape it is the package's ASM to"
        f" {100 * cand['self_check']:.3f}%). Deviations from the printed ASM columns, all 19"
        " rows; `s/(1-s)` shapes are singular at the trailing edge like the 2-D (Carter)"
        " full-adhesion traction:\n")
    add("| reading | collocation s | max dev C11 | max dev C22 | max dev C23 | rows within"
        " target | rms |")
    add("| --- | --- | --- | --- | --- | --- | --- |")

    def devs(entry: dict[str, Any]) -> np.ndarray:
        return np.array([[entry["rows"][str(r.a_over_b)][n] / r.asm[i] - 1.0
                          for i, n in enumerate(NAMES)] for r in printed])

    def signed_max(col: np.ndarray) -> str:
        return _pct(float(col[np.argmax(np.abs(col))]))

    for entry in cand["readings"]:
        e = devs(entry)
        ok = sum(all(_meets(n, entry["rows"][str(r.a_over_b)][n], r.asm[i])
                     for i, n in enumerate(NAMES)) for r in printed)
        ok_12 = sum(all(_meets(n, entry["rows"][str(r.a_over_b)][n], r.asm[i])
                        for i, n in enumerate(NAMES[:2])) for r in printed)
        add(f"| {entry['label']} | {', '.join(f'{c:.4f}' for c in entry['collocation'])} | "
            + " | ".join(signed_max(e[:, i]) for i in range(3))
            + f" | {ok} (C11 and C22: {ok_12}) | {100 * float(np.sqrt((e ** 2).mean())):.1f}% |")
    add("")
    show = [x for x in cand["readings"] if x["basis"] == "carter1" and x["collocation"] == [0.45]
            or x["label"].startswith("quadratic, Gauss-Chebyshev")
            or x["label"].startswith("2-D full-adhesion shape, 2 terms, 1/4")]
    add("Row by row, three of them (deviation from the printed ASM column; the one-term shape"
        " cannot carry a slip varying along a strip, so its C23 means nothing):\n")
    add("| a/b | " + " | ".join(f"{x['label']}: {n}" for x in show for n in NAMES) + " |")
    add("| --- | " + " | ".join("---" for _ in show for _ in NAMES) + " |")
    for r in printed:
        add(f"| {r.a_over_b:.4g} | " + " | ".join(
            _pct(x["rows"][str(r.a_over_b)][n] / r.asm[i] - 1.0)
            for x in show for i, n in enumerate(NAMES)) + " |")
    add("")
    one = next((x for x in cand["readings"] if x["basis"] == "carter1"
                and x["collocation"] == [0.45]), None)
    one_ok = (sum(all(_meets(n, one["rows"][str(r.a_over_b)][n], r.asm[i])
                      for i, n in enumerate(NAMES[:2])) for r in printed) if one else 0)
    one_max = (max(abs(one["rows"][str(r.a_over_b)][n] / r.asm[i] - 1.0) for r in printed
                   for i, n in enumerate(NAMES[:2])) if one else math.nan)
    add("**What this shows.** (1) Every reading whose strip traction can carry the 2-D"
        " full-adhesion solution (the 2-D shape with two terms, at any fractions tried)"
        " converges on Kalker's AMK column, not on the printed ASM: on a slender strip a"
        " good approximation is the exact theory, and the printed ASM sits 0-8% below it."
        " The 2-D shape's quadrature is not converged at a/b = 10 (its C11 there is above"
        " Kalker's by much more than anywhere else): that row is indicative only. (2) The"
        " quadratic shape at the Gauss-Chebyshev points of the 2-D shape's weight (a"
        " placement defined by its own rule, not fitted) is the nearest of the natural"
        " placements, and it lies beside the least-squares fit of two points to the printed"
        " column (s = 0.097, 0.667, rms 3.5%: an earlier exploration); but it"
        " misses C11 and C22 by up to 4% and C23 by 17% at a/b = 0.1. (3) The one-term"
        " 2-D shape collocated once per strip, near the strip's middle, follows the printed"
        " C11 and C22 closely (the trend, exact at a/b = 0.1 and increasingly below Kalker"
        " towards a/b = 10, is the printed one); at s = 0.45 C11 and C22 are within"
        f" {100 * one_max:.2f}% on every row (within 2% on {one_ok} of {len(printed)}), but"
        " s = 0.45 is a value read off this table, not a rule, and the one"
        " term gives no spin coefficient: a second term for the lateral traction brings C23"
        " back to Kalker's. (4) No reading gives the printed C23 = 0.55 at a/b = 0.1 (16%"
        " above Kalker's 0.473): every reading with the exact kernels gives 0.45-0.48 there,"
        " where the strips are short and the 2-D limit is exact; the printed value must"
        " come from something in Knothe and Hung's scheme that is not in these readings"
        " (the kernels' treatment, the lateral interpolation across strips, or the mesh)."
        " Further readings (exploration, 2026-12-03, not in the data above): piecewise-linear"
        " tractions on 2 to 6 elements per strip collocated at the elements' middles (rms"
        " 7-23%), least squares over ten points per strip instead of collocation (rms 6-60%),"
        " a one-term longitudinal with a two-term lateral shape (rms 4-14%, C23 at a/b = 0.1"
        " 0.47 again), the Poisson coupling left out (C23 at a/b = 0.1 0.34): none nearer."
        " Knothe and Hung's own ansatz and placement are therefore not established: the"
        " package keeps its fitted points (`ASM_COLLOCATION`), which reproduce Kalker's"
        " coefficients (AMK) within 2% for 0.1 <= a/b <= 3.3 (within 4.1% at 5 and 10),"
        " and the printed ASM columns are not reproduced.\n")


def report(res: dict[str, Any]) -> None:
    """Write docs/validation_seed.md and the figures from ``res``."""
    FIG.mkdir(parents=True, exist_ok=True)
    lines: list[str] = []
    add = lines.append
    k = kalker()
    d = res["dlm"]
    a = res["asm"]
    add("# The seed paper's comparison: DLM and ASM beside Tables 1 and 2\n")
    add("Generated by `python scripts/validate_seed.py` (results in"
        " `docs/data/validation_seed.json`; `--report-only` rewrites this page from them,"
        " `--candidates-only` recomputes only the readings of ASM tried, `--fit-asm` refits"
        " ASM's collocation). Every number here was computed by the package"
        f" on {res['machine']}; the run took {res['seconds']:.0f} s.\n")
    published = res.get("kalker") == "published"
    add("Kalker's coefficients: " + (
        "his published table E.3 (3 digits)."
        if published else "the package's own table (`fastsim_ros/data/kalker_coefficients"
        ".csv`, the exact solver's; the published one was not beside the checkout).") + "\n")
    add("Before proposing MAE, Alonso & Giménez (VSD 45(4), 2007) compare the ways FastSim's"
        " flexibilities were found on non-elliptical areas: Kalker's deformation levelling"
        " method (DLM: their Table 1, Figures 4 and 5) and Knothe and Hung's asymptotic strip"
        " method (ASM: Table 2, Figure 6); Kalker's variational method is what the package's"
        " exact solver goes beyond. The paper's text itself was not at hand: the methods are"
        " built from the published descriptions of them, and where a"
        " choice was open it was settled by the evidence below. The paper's figures could not"
        " be seen either: Figures 4 to 6 below redraw what the tables compare (each method's"
        " coefficients over a/b against Kalker's) and what each method does (DLM's levelling,"
        " ASM's strip traction), from the package.\n")
    # --------------------------------------------------------------- Table 1
    add("## 1. DLM (Table 1)\n")
    add("`fastsim_ros/contact/dlm.py`. The simplified theory says `u = L tau`; the exact theory"
        " gives the displacement of a traction through the Boussinesq-Cerruti influence"
        " coefficients (eq. 4; the package's closed-form rectangle coefficients, FFT"
        " convolution); DLM takes the `L` that levels the two by least squares (eq. 5), for the"
        " traction of the simplified theory, starting from the full-slip traction and"
        " iterating until `L` stops changing. The package's reading: one `L` per creepage"
        " (`L1` from `u_x` under unit `xi`, `L2` from `u_y` under unit `eta`, `L3` from both"
        " components under unit spin about the centroid), a free rigid translation per"
        " displacement component, FastSim's adhesion traction on the area's cells. Its"
        " coefficients are FastSim's in full adhesion with those `L` (`fastsim_contact"
        " coefficients --method dlm`, here on"
        f" {DLM_CELLS} x {DLM_CELLS} cells, nu = {NU}).\n")
    add("The seed's Table 1 prints two numbers per entry. The first of each pair is Kalker's"
        " exact coefficient for nu = 0.25 (his table E.3: 3.31, 4.12, 11.7; ...), so the"
        " header's order looks swapped and DLM's values are the second numbers; they are"
        " what is compared here.\n")
    add("| a/b | | Table 1 (Kalker, DLM) | package DLM | vs Table 1's DLM | Kalker |")
    add("| --- | --- | --- | --- | --- | --- |")
    pk = d["package_cli"]
    for g in TABLE1_RATIOS:
        for n in NAMES:
            first, second = TABLE1[(g, n)]
            v = pk[str(g)][n]
            add(f"| {g:g} | {n} | {first:g}, {second:g} | {v:.3f} | {_pct(v / second - 1)} |"
                f" {k[(round(g, 6), NU)][n]:g} |")
    add("")
    misses = [(g, n, pk[str(g)][n] / TABLE1[(g, n)][1] - 1) for g in TABLE1_RATIOS
              for n in ("C11", "C22") if abs(pk[str(g)][n] / TABLE1[(g, n)][1] - 1) > 0.03]
    add("Target: C11 and C22 within 3% of Table 1's DLM. "
        + ("Met." if not misses else "Met at a/b = 1 and 10; missed at " + ", ".join(
            f"a/b = {g:g} {n} {_pct(e)}" for g, n, e in misses) + "."))
    add("")
    add("**The readings tried** (the formulation was settled by these; each row's"
        " coefficients from its `L` by FastSim's full-adhesion integrals on the same cells,"
        " deviation from Table 1's DLM):\n")
    add("| reading | " + " | ".join(f"a/b {g:g} {n}" for g in TABLE1_RATIOS for n in NAMES)
        + " |")
    add("| --- | " + " | ".join("---" for _ in range(9)) + " |")
    for key, entry in d["table1"].items():
        add(f"| {entry['what']} | " + " | ".join(
            _pct(entry["rows"][str(g)][n] / TABLE1[(g, n)][1] - 1) for g in TABLE1_RATIOS
            for n in NAMES) + " |")
    add("")
    add("Without the translation `L` is the mean displacement's and every C11 and C22 comes"
        " out 35 to 67% below Table 1's; a translation per strip (the slip is `du/dx`, blind to"
        " a displacement constant along a strip) overshoots at a/b = 0.1 and 1; the full-slip"
        " traction alone (the iteration's first step) falls 20 to 50% short at a/b = 0.1 and"
        " 1;"
        " weighting the least squares by the traction fits a/b = 0.1's C11 but is 25-40% high"
        " at a/b = 1 and 10. Of the readings tried, the package's was the only"
        " one within 2% of C11 and C22 at a/b = 1 and 10 (the chord-weighted one is new: see"
        " below). The"
        " iteration from the full-slip traction converges after one step, because the"
        " simplified theory's adhesion traction of a unit creepage has a shape that does not"
        " depend on `L` (on the circle, `L1` from the full-slip traction is "
        f"{d['iteration']['L1'][0] / d['iteration']['L1'][-1]:.3f} times the converged one,"
        " then exactly it).\n")
    add("**Where Table 1 is not reproduced, and the likely reason.** At a/b = 0.1 the"
        " package's reading gives C11 and C22 6-9% below Table 1's ("
        + ", ".join(f"{n} {_pct(pk['0.1'][n] / TABLE1[(0.1, n)][1] - 1)}"
                    for n in ("C11", "C22"))
        + "). The grid is not the cause (the package's values move by "
        + f"{_grid_spread(d, 0.1):.1f}% between 40 and 160 cells; an exploration with square"
        " cells, 4 to 20 along x, moved them by up to 6%, downwards); neither is nu (an"
        " exploration over nu = 0..0.5: no single nu fits the three ratios). What is left is"
        " what the published description of the method does not fix: the weights of its least"
        " squares (and the paper's mesh, which amounts to weights). Table 1's a/b = 0.1 values"
        " lie between the unweighted levelling and the one weighted by the local traction (the"
        " table above), which weighs each strip's trailing part, where the traction is large,"
        " too much at a/b = 1 and 10. Weighting every cell by the length of its strip (the"
        " strip's mean adhesion traction is proportional to it) does what the table asks at"
        " all three ratios: "
        + ", ".join(f"a/b = {g:g}: " + ", ".join(
            f"{n} {_pct(d['table1']['chord']['rows'][str(g)][n] / TABLE1[(g, n)][1] - 1)}"
            for n in NAMES) for g in TABLE1_RATIOS)
        + ". It is grid-converged (the table below) and better than the package's reading on"
        " eight of the nine entries, but it was found by trying weights against Table 1 (the"
        " strip length to the powers 0, 1 and 2 and the strip-uniform and pressure weights were"
        " tried; the powers 0 and 2 give -8.9% and +6.9% on C11 at a/b = 0.1), not read from"
        " the paper's definition, which was not at hand. So it is a named option"
        " (`dlm.DLM_CHORD_FASTSIM`, `weighting=\"chord\"`), not the default: the command line's"
        " `--method dlm` stays the unweighted levelling, and the choice is left to whoever"
        " can read the paper's eq. 5. C23 is not a target: the levelling of the spin traction"
        " mixes its two components, whose displacements the nu coupling ties together, and"
        " Table 1's C23 (0.13, 1.23, 10.73) is matched at a/b = 1 (+3%) and 0.1 (+9%) but"
        f" not at a/b = 10 ({_pct(pk['10.0']['C23'] / TABLE1[(10.0, 'C23')][1] - 1)}; the"
        " chord-weighted reading"
        f" {_pct(d['table1']['chord']['rows']['10.0']['C23'] / TABLE1[(10.0, 'C23')][1] - 1)}),"
        " where no reading tried comes near it (the per-strip translation gives +4%, at the"
        " cost of C11 and C22). Levelling the spin traction's lateral component alone gives"
        " C23 -12%, -13%, +55% at a/b = 0.1, 1, 10, its longitudinal component alone +9%,"
        " +6%, +149% (exploration, 2026-12-03, 60 and 100 cells alike): the miss at a/b = 10"
        " is not the mixing of the two components either.\n")
    add("Grid check of the package's DLM (C11, C22, C23 on n x n cells):\n")
    add("| a/b | " + " | ".join(f"{n} cells" for n in d["grid"]) + " |")
    add("| --- | " + " | ".join("---" for _ in d["grid"]) + " |")
    for g in TABLE1_RATIOS:
        add(f"| {g:g} | " + " | ".join(
            ", ".join(f"{d['grid'][n][str(g)][c]:.3f}" for c in NAMES) for n in d["grid"])
            + " |")
    add("")
    if d.get("chord_grid"):
        add("The same for the chord-weighted levelling:\n")
        add("| a/b | " + " | ".join(f"{n} cells" for n in d["chord_grid"]) + " |")
        add("| --- | " + " | ".join("---" for _ in d["chord_grid"]) + " |")
        for g in TABLE1_RATIOS:
            add(f"| {g:g} | " + " | ".join(
                ", ".join(f"{d['chord_grid'][n][str(g)][c]:.3f}" for c in NAMES)
                for n in d["chord_grid"]) + " |")
        add("")
    _figure_coefficients("seed_fig4_dlm.png", "DLM (package) against Kalker, nu = 0.25",
                         {float(g): v for g, v in d["curve"].items()}, NU,
                         marks={(g, n): TABLE1[(g, n)][1] for g in TABLE1_RATIOS
                                for n in NAMES})
    add("![Figure 4: DLM's coefficients against Kalker's](figures/seed_fig4_dlm.png)\n")
    add("*Figure 4.* DLM's C11, C22, C23 over a/b (60 cells) against Kalker's (lines), with"
        " Table 1's DLM values (crosses).\n")
    _figure_levelling(d)
    add("![Figure 5: the levelling](figures/seed_fig5_levelling.png)\n")
    add("*Figure 5.* What DLM levels, on the circle under unit `xi`: the exact displacement"
        " `u_x` of FastSim's adhesion traction along the middle strip, and `L1 tau_x + c`"
        " with the levelled `L1` (left); `L1, L2, L3` over the iteration's steps, from the"
        " full-slip traction (step 0), relative to the converged values (right).\n")
    # --------------------------------------------------------------- Table 2
    add("## 2. ASM (Table 2)\n")
    col = a["collocation"]
    add("`fastsim_ros/contact/asm.py`. Strips along the rolling direction (the grid's rows; a"
        " row with a gap gives one strip per segment); in each strip the traction is"
        " quadratic in the distance from the strip's leading edge and vanishes there, for"
        " each component: four coefficients per strip, constant across its width; full"
        " adhesion (`du/dx = w`, the displacement difference of all strips' tractions) at two"
        " points on each strip's centre line, which gives four equations per strip. The"
        " kernels are integrated across a strip's width in closed form and along it by parts"
        " and Gauss-Legendre. The two points are placed to minimise the error on ellipses:"
        f" at {col[0]:.4f} and {col[1]:.4f} of the strip's length from its leading edge,"
        f" fitted (least squares of the relative errors of C11, C22, C23) on a/b ="
        f" {', '.join(f'{g:g}' for g in ASM_FIT_RATIOS)} at nu = {NU} with {ASM_STRIPS}"
        " strips"
        + (f" (rms {100 * res['asm_fit']['rms']:.2f}%)" if res.get("asm_fit") else "")
        + "; every other row, and nu = 0 and 0.5, check it.\n")
    rows = a["rows"]["0.25"]
    by_ratio = {round(float(g), 6): v for g, v in (a.get("cli") or rows).items()}
    if SEED_TABLES.exists():
        printed = read_table2(SEED_TABLES)
        add("Table 2 as printed, both columns: the"
            " paper's ASM and Kalker's asymptotic method (AMK). **Mapping:** the printed"
            " labels of the two blocks are swapped; the first block (`b<a`, g = 0.1..0.9) is"
            " at a/b = g, the second (`b>a`, g = 1..0.1) at a/b = 1/g (`a` along the rolling"
            " direction). So a row g of the first block is `fastsim_contact coefficients"
            " --shape ellipse --a-over-b g --method asm --nu 0.25`, a row g of the second"
            " `--a-over-b 1/g`; the reading (`fastsim_ros/contact/seed_tables.py`) is pinned"
            " by a test: so mapped, the AMK columns are Kalker's published table to the"
            " rounding, but for the misprint C23 = 1.15 at 0.8 (Kalker: 1.25). The package"
            " column is what that command prints"
            + (f" (ASM + FastSim on its default {ASM_CLI_CELLS} x {ASM_CLI_CELLS} cells; the"
               f" exact-chord {ASM_STRIPS}-strip values of Figure 6 are within"
               f" {100 * _cli_spread(a):.1f}% of it)"
               if a.get("cli") else f" ({ASM_STRIPS} strips, exact chords)")
            + "; deviations are from the printed ASM column (fit rows in bold).\n")
        add("| a/b (block, g) | " + " | ".join(f"{n} ASM | package | dev | {n} AMK"
                                               for n in NAMES) + " |")
        add("| --- | " + " | ".join("--- | --- | --- | ---" for _ in NAMES) + " |")
        worst = {n: (0.0, 0.0) for n in NAMES}
        within = 0
        for r in printed:
            v = by_ratio[round(r.a_over_b, 6)]
            fit = any(abs(r.a_over_b - f) < 1e-6 for f in ASM_FIT_RATIOS)
            cells = []
            ok = True
            for n, t_asm, t_amk in zip(NAMES, r.asm, r.amk):
                e = v[n] / t_asm - 1
                if abs(e) > abs(worst[n][1]):
                    worst[n] = (r.a_over_b, e)
                ok = ok and _meets(n, v[n], t_asm)
                cells.append(f"{t_asm:g} | {v[n]:.3f} | {_pct(e)} | {t_amk:g}")
            within += ok
            label = f"{r.a_over_b:.4g} ({r.block}, {r.g:g})"
            add(f"| {'**' + label + '**' if fit else label} | " + " | ".join(cells) + " |")
        add("")
        add("Target: the printed ASM columns within 2% (C23 within 3%"
            f" or 0.02). {within} of {len(printed)} rows meet it; the worst deviations are "
            + ", ".join(f"{n} {_pct(e)} (a/b = {g:.3g})" for n, (g, e) in worst.items())
            + ". **Not reproduced.**\n")
        _report_candidates(add, res.get("candidates") or {}, printed)
    else:
        add("(The printed tables are not beside this checkout: Table 2 as"
            " printed is not shown.)\n")
    _figure_coefficients("seed_fig6_asm.png", "ASM against Kalker, nu = 0.25",
                         {float(g): v for g, v in rows.items()}, NU, marks={})
    _figure_traction(a)
    add("![Figure 6: ASM's coefficients against Kalker's](figures/seed_fig6_asm.png)\n")
    add("![Figure 6b: ASM's strip traction](figures/seed_fig6_traction.png)\n")
    add("*Figure 6.* ASM's C11, C22, C23 over a/b against Kalker's (top); ASM's quadratic"
        " traction on the circle's middle strip under unit `xi` against the exact"
        " full-adhesion traction on 80 cells, with the collocation points (bottom).\n")
    cost = [v["seconds"] for v in rows.values()]
    add("## 3. Cost\n")
    add(f"ASM's coefficients of an ellipse ({ASM_STRIPS} strips): median"
        f" {1e3 * float(np.median(cost)):.0f} ms (a dense system of {4 * ASM_STRIPS}"
        " unknowns). DLM's flexibilities and the FastSim methods' cost per solve on the"
        " validation areas are in `docs/validation_wider.md`, section 3.\n")
    (DOCS / "validation_seed.md").write_text("\n".join(lines) + "\n")


def _grid_spread(d: dict[str, Any], g: float) -> float:
    vals = [d["grid"][n][str(g)]["C11"] for n in d["grid"]]
    return 100 * (max(vals) - min(vals)) / float(np.mean(vals))


def _figure_coefficients(name: str, title: str, values: dict[float, dict[str, float]],
                         nu: float, *, marks: dict[tuple[float, str], float]) -> None:
    k = kalker()
    gs = sorted(values)
    fig, axs = plt.subplots(1, 3, figsize=(13, 3.6))
    for ax, n in zip(axs, NAMES):
        ax.plot(gs, [k[(round(g, 6), nu)][n] for g in gs], "k-", label="Kalker")
        ax.plot(gs, [values[g][n] for g in gs], "C0o--", ms=4, label="package")
        for (g, nn), v in marks.items():
            if nn == n:
                ax.plot([g], [v], "C3x", ms=9, mew=2, label="Table 1" if g == 0.1 else None)
        ax.set(xscale="log", yscale="log", xlabel="a/b", title=f"{n}")
    axs[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(FIG / name, dpi=100)
    plt.close(fig)


def _figure_levelling(d: dict[str, Any]) -> None:
    lev = d["levelling"]
    it = d["iteration"]
    fig, axs = plt.subplots(1, 2, figsize=(11, 3.6))
    axs[0].plot(lev["x"], lev["u"], "k-", label="exact u_x of FastSim's traction")
    axs[0].plot(lev["x"], lev["L_tau_plus_c"], "C0--", label="L1 tau_x + c (levelled)")
    axs[0].set(xlabel="x (m, unit-area circle)", ylabel="u_x (m, per unit G and xi)")
    axs[0].legend(fontsize=8)
    for key, style in (("L1", "C0o-"), ("L2", "C1s-"), ("L3", "C2^-")):
        axs[1].plot(range(len(it[key])), [v / it[key][-1] for v in it[key]], style, label=key)
    axs[1].set(xlabel="step (0: full-slip traction)", ylabel="L / converged L")
    axs[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(FIG / "seed_fig5_levelling.png", dpi=100)
    plt.close(fig)


def _figure_traction(a: dict[str, Any]) -> None:
    t = a["traction"]
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    ax.plot(t["x_exact"], t["tau_exact"], "k.-", ms=3, label="exact, 80 cells")
    ax.plot(t["x_asm"], t["tau_asm"], "C0-", label="ASM (quadratic)")
    for x in t["collocation_x"]:
        ax.axvline(x, color="C3", lw=0.8, ls=":")
    ax.set(xlabel="x (m, unit-area circle; rolling towards +x)",
           ylabel="tau_x (Pa per unit G and xi)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(FIG / "seed_fig6_traction.png", dpi=100)
    plt.close(fig)


def main() -> int:
    """Run the seed comparison (or only rewrite the report) and write its outputs."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--report-only", action="store_true")
    parser.add_argument("--candidates-only", action="store_true",
                        help="recompute only the readings of ASM tried (the rest from the JSON)")
    parser.add_argument("--fit-asm", action="store_true",
                        help="refit ASM's collocation (then set asm.ASM_COLLOCATION to it)")
    args = parser.parse_args()
    if args.report_only:
        res = json.loads(DATA.read_text())
    elif args.candidates_only:
        res = json.loads(DATA.read_text())
        res["candidates"] = candidates_part()
        DATA.write_text(json.dumps(res, indent=1))
    else:
        start = time.time()
        old = json.loads(DATA.read_text()) if DATA.exists() else {}
        res = {"machine": machine(),
               "kalker": "published" if KALKER == PUBLISHED else "package"}
        if args.fit_asm:
            res["asm_fit"] = fit_asm()
            print(f"ASM collocation fit: {res['asm_fit']}", flush=True)
        elif "asm_fit" in old:
            res["asm_fit"] = old["asm_fit"]
        res["dlm"] = dlm_part()
        res["asm"] = asm_part()
        res["candidates"] = candidates_part()
        res["seconds"] = time.time() - start
        DATA.parent.mkdir(parents=True, exist_ok=True)
        DATA.write_text(json.dumps(res, indent=1))
    report(res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
