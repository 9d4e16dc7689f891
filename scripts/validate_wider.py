#!/usr/bin/env python3
"""Wider validation: exact vs the calibrated and the paper's MAE, FaStrip and the ellipse.

Writes ``docs/data/validation_wider.json``, ``docs/figures/wider_*.png`` and
``docs/validation_wider.md``.  The areas: the nine of
``scripts/validate.py`` (the Hertzian ellipse, FastSim's own floor, and the
eight non-elliptical ones), the new ones of :mod:`fastsim_ros.contact.samples`:
a long narrow patch, a crescent, an egg and normal-solver patches on a
profile gap at three lateral shifts from the tread to the flange root, and
nine areas beyond the calibrated MAE's selection (``BEYOND``: eggs,
crescents, asymmetric lobes, flat bands).  Methods: the calibrated MAE, the
paper's MAE, FaStrip, the equivalent ellipse, DLM and ASM; the calibrated MAE
also without each of its rules (the leave-one-out check).

For each area: force-creepage curves under ``xi``, ``eta``, ``phi`` and
combined (the levels of ``scripts/validate.py``) from the exact theory
(Coulomb friction, given pressure) and the four online methods on one
grid; the linear-range ``C~11, C~22, C~23`` (exact: extrapolated over four
grids, docs/guide_physics.md; the methods on 60 cells); the cost per solve; and a grid
check of the curves on a finer grid for two areas.  Besides, the selection
areas (pairs of semi-ellipses other than the validation's and two
notches: neither validation areas nor the pair-factor table's own) on which the calibrated MAE's
pair-factor rule was chosen, with the alternatives.

Usage: ``python scripts/validate_wider.py [--report-only]``.  About 15 minutes
on 2 cores (the exact Coulomb solves and the numpy reference without each rule
dominate).
"""

from __future__ import annotations

import argparse
import json
import math
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
from fastsim_ros.contact import exact, samples  # noqa: E402
from fastsim_ros.contact import mae_calibrated as calibrated_module  # noqa: E402
from fastsim_ros.contact.asm import (asm_fastsim_coefficients, asm_flexibility,  # noqa: E402
                                     fastsim_with)
from fastsim_ros.contact.dlm import dlm_coefficients, dlm_flexibility  # noqa: E402
from fastsim_ros.contact.compiled import (CalibratedMaeSolver,  # noqa: E402
                                          EquivalentEllipseSolver, MaeSolver, warm_up)
from fastsim_ros.contact.polach import PolachSolver  # noqa: E402
from fastsim_ros.contact.equivalent import equivalent_coefficients  # noqa: E402
from fastsim_ros.contact.errors import ContactError  # noqa: E402
from fastsim_ros.contact.fastrip import fastrip, fastrip_coefficients  # noqa: E402
from fastsim_ros.contact.fastsim import traction_bound  # noqa: E402
from fastsim_ros.contact.mae import (mae_coefficients, mae_fastsim_coefficients,  # noqa: E402
                                     mae_geometry)
from fastsim_ros.contact.mae_calibrated import (RULES, mae_calibrated_coefficients,  # noqa: E402
                                                mae_calibrated_fastsim)
from fastsim_ros.contact.pairs import PairFactors, pair_factors  # noqa: E402
from fastsim_ros.contact.tables import coefficient_table  # noqa: E402

import validate  # noqa: E402  (scripts/validate.py: the report's own areas)

sys.path.insert(0, str(ROOT / "benchmarks"))
import bench_fastsim as bench  # noqa: E402  (the cost ratio's patches and timing)

DOCS = ROOT / "docs"
DATA = DOCS / "data" / "validation_wider.json"
FIG = DOCS / "figures"
# the material, load and scale of scripts/validate.py, whose areas these extend
MU, G, NU, LOAD, SCALE = validate.MU, validate.G, validate.NU, validate.LOAD, validate.SCALE
#: cells across each area's bounding box for the curves (every method on the same grid)
CURVE_CELLS = 40
#: the finer grid of the curve grid check, and the areas it runs on
CHECK_CELLS = 60
CHECK_AREAS = ("ellipse 2/3 (Hertz)", "semi-ellipses 5/1")
#: exact coefficients: extrapolated over these grids; the online methods on ONLINE_CELLS
EXACT_GRIDS = (40, 60, 80, 100)
ONLINE_CELLS = 60
CURVES = {"xi": (1.0, 0.0, 0.0), "eta": (0.0, 1.0, 0.0), "phi": (0.0, 0.0, 1.0),
          "combined": (0.5, 0.5, 0.5)}
LEVELS = (0.05, 0.15, 0.3, 0.5, 0.8, 1.2, 2.0, 3.5)
METHODS = ("mae_calibrated", "mae", "fastrip", "ellipse", "polach", "dlm", "asm")
LABELS = {"mae_calibrated": "calibrated MAE", "mae": "paper's MAE", "fastrip": "FaStrip",
          "ellipse": "equivalent ellipse", "polach": "Polach", "dlm": "DLM + FastSim",
          "asm": "ASM + FastSim"}
#: the methods users would pick without the calibrated MAE
BASELINES = ("mae", "fastrip", "ellipse", "polach")
#: bar offsets of the methods in the figures
BAR = 0.13
NEW = ("long narrow", "crescent", "egg")
#: the areas beyond the calibrated MAE's selection (made after its rules were fixed,
#: never looked at while choosing them): eggs with the longer half trailing and leading,
#: crescents of other bends and widths (horns leading and trailing), asymmetric lobes, flat
#: bands.  Name -> (maker of the unit-area shape, keywords)
BEYOND: dict[str, tuple[Callable[..., areas.GridArea], dict[str, Any]]] = {
    "egg 0.6 (longer half trailing)": (samples.egg_patch, {"lead_over_trail": 0.6,
                                                           "a_over_b": 1.25}),
    "egg 1.7 (longer half leading)": (samples.egg_patch, {"lead_over_trail": 1.7,
                                                          "a_over_b": 0.8}),
    "crescent 1.5/0.4": (samples.crescent_patch, {"bend": 1.5, "a_over_b": 0.4}),
    "crescent 0.9/0.25": (samples.crescent_patch, {"bend": 0.9, "a_over_b": 0.25}),
    "crescent -1.5/0.35 (horns trailing)": (
        samples.crescent_patch, {"bend": -1.5, "a_over_b": 0.35}),
    "crescent -0.8/0.2 (horns trailing)": (
        samples.crescent_patch, {"bend": -0.8, "a_over_b": 0.2}),
    "crescent -2/0.45 (horns trailing)": (
        samples.crescent_patch, {"bend": -2.0, "a_over_b": 0.45}),
    "lobes 0.7 leading": (samples.asymmetric_lobes, {"size": 0.7, "lead": 0.45,
                                                     "overlap": 0.25, "a_over_b": (0.9, 1.1)}),
    "lobes 0.55 trailing": (samples.asymmetric_lobes, {"size": 0.55, "lead": -0.25,
                                                       "overlap": 0.2, "a_over_b": (1.2, 0.7)}),
    "flat band 0.3/5": (samples.flat_band_patch, {"a_over_b": 0.3, "exponent": 5.0}),
    "flat band 0.2/3.5": (samples.flat_band_patch, {"a_over_b": 0.2, "exponent": 3.5}),
}
#: the areas each rule of the calibrated MAE was chosen on (its fit data; the leave-one-out
#: check looks at its gain everywhere else): the report's own areas among them, the rest are
#: the selection areas of section 4 and 6
CHOSEN_ON = {"pairs": ("semi-ellipses 0.1/1", "semi-ellipses 5/1"),
             "calibration": ("notched ellipse",),
             "rigid_slip": ("truncated ellipse",),
             "bend": ("crescent", "crescent -1.5/0.35 (horns trailing)")}
#: the one area of BEYOND a rule was changed on after it was first validated (rule 4: a bend
#: whose horns trail no longer counts); the two crescents after it in BEYOND check the change
SEEN = ("crescent -1.5/0.35 (horns trailing)",)
RULE_LABELS = {"pairs": "1 pair factors", "calibration": "2 calibrated flexibilities",
               "rigid_slip": "3 rigid-slip return", "bend": "4 bent strips"}

AreaMaker = validate.AreaMaker


def area_makers(loaded: bool) -> dict[str, AreaMaker]:
    """Return the validation areas by name: ``make(cells)`` (loaded: 5e4 N on 1e-4 m^2).

    The report's eight (and its Hertzian ellipse), as ``scripts/validate.py``
    builds them, then the new ones.
    """
    load = LOAD if loaded else None
    scale = SCALE if loaded else 1.0
    out = validate.area_makers(loaded)
    out["long narrow"] = lambda n: samples.long_narrow_patch(cells=n, scale=scale, load=load)
    out["crescent"] = lambda n: samples.crescent_patch(cells=n, scale=scale, load=load)
    out["egg"] = lambda n: samples.egg_patch(cells=n, scale=scale, load=load)
    for u in samples.PROFILE_SHIFTS:
        out[f"profile gap {1e3 * u:+.1f} mm"] = (
            lambda n, u=u: samples.profile_gap_patch(u, cells=n, load=LOAD))
    for name, (make, kw) in BEYOND.items():
        out[name] = lambda n, make=make, kw=kw: make(cells=n, scale=scale, load=load, **kw)
    return out


def _saturation(ar: areas.GridArea) -> tuple[float, float, float]:
    """Creepages that would saturate the linear theory (C ~ 4.5, 4, 1.5), as validate.py."""
    c = math.sqrt(ar.area / math.pi)
    n_load = ar.load
    return (MU * n_load / (G * c**2 * 4.5), MU * n_load / (G * c**2 * 4.0),
            MU * n_load / (G * c**3 * 1.5))


def curves_on(ar: areas.GridArea) -> dict[str, Any]:
    """Return the curves of exact and the three methods on ``ar``, with each solve's cost."""
    t = coefficient_table(NU)
    mae = MaeSolver(NU, G)
    calibrated = CalibratedMaeSolver(NU, G)
    ell = EquivalentEllipseSolver(NU, G)
    pol = PolachSolver(NU, G)
    sat = _saturation(ar)
    op = exact.SteadyRollingOperator.of(ar, nu=NU, shear_modulus=G)
    entry: dict[str, Any] = {"N": ar.load, "sat": sat, "cells": [ar.nx, ar.ny],
                             "in_contact": int(np.count_nonzero(ar.mask))}
    # the seed's methods: their flexibilities once per area (the cost of a new patch)
    t0 = time.perf_counter()
    flex_dlm = dlm_flexibility(ar, nu=NU, shear_modulus=G)
    t1 = time.perf_counter()
    flex_asm = asm_flexibility(ar, nu=NU, shear_modulus=G)
    entry["prep"] = {"dlm": t1 - t0, "asm": time.perf_counter() - t1}
    bound = traction_bound(ar, MU)
    cost: dict[str, list[float]] = {m: [] for m in ("exact",) + METHODS}
    for curve, direction in CURVES.items():
        pts = []
        for s in LEVELS:
            cr = tuple(s * d * k for d, k in zip(direction, sat))
            point: dict[str, Any] = {"level": s, "creepage": cr}
            t0 = time.perf_counter()
            ex = exact.coulomb(ar, *cr, mu=MU, nu=NU, shear_modulus=G, operator=op)
            cost["exact"].append(time.perf_counter() - t0)
            point["exact"] = [ex.fx, ex.fy, ex.mz]
            solvers: dict[str, Callable[[], Any]] = {
                "mae_calibrated": lambda cr=cr: calibrated.solve(ar, *cr, mu=MU),
                "mae": lambda cr=cr: mae.solve(ar, *cr, mu=MU),
                "fastrip": lambda cr=cr: fastrip(ar, *cr, mu=MU, table=t, shear_modulus=G),
                "ellipse": lambda cr=cr: ell.solve(ar, *cr, mu=MU),
                "polach": lambda cr=cr: pol.solve(ar, *cr, mu=MU),
                "dlm": lambda cr=cr: fastsim_with(ar, flex_dlm, *cr, bound=bound),
                "asm": lambda cr=cr: fastsim_with(ar, flex_asm, *cr, bound=bound)}
            for m, solve in solvers.items():
                try:
                    # an untimed call first: the exact solve just before trashes the caches,
                    # and the method called first would pay for it
                    solve()
                    t0 = time.perf_counter()
                    r = solve()
                    cost[m].append(time.perf_counter() - t0)
                    point[m] = [r.fx, r.fy, r.mz]
                except ContactError as e:
                    point[m] = None
                    point[m + "_error"] = str(e)
            pts.append(point)
        entry[curve] = pts
    entry["cost"] = {m: float(np.median(v)) if v else None for m, v in cost.items()}
    return entry


def _extrapolated(make: AreaMaker) -> dict[str, float]:
    per = [exact.creep_coefficients(make(n), nu=NU) for n in EXACT_GRIDS]
    h = [1.0 / n for n in EXACT_GRIDS]
    out = {}
    for k in ("C11", "C22", "C23", "C13"):
        vals = [getattr(c, k) for c in per]
        out[k] = float(np.polyfit(h, vals, 1)[1])
        out[k + "_err"] = abs(float(np.polyfit(h[1:], vals[1:], 1)[1]) - out[k])
    return out


def polach_coefficients(ar: areas.GridArea, tab: Any) -> Any:
    """Return Polach's coefficients: his forces at vanishing creepage (Kalker's C, kA = kS = 1).

    Full adhesion by a friction coefficient far above any force the unit
    creepages make (``G`` = 1 Pa on a unit area); Polach has no spin moment,
    so only ``C11``, ``C22``, ``C23``, ``C13`` are read.
    """
    from fastsim_ros.contact.coefficients import coefficients_of_solver
    pol = PolachSolver(NU, 1.0)
    return coefficients_of_solver(ar.area, lambda xi, eta, phi: pol.solve(
        ar, xi, eta, phi, mu=1e9))


def coefficients_of(make: AreaMaker) -> dict[str, Any]:
    """Return the linear-range coefficients about each area's origin: exact and the methods."""
    t = coefficient_table(NU)
    pairs = pair_factors(NU)
    ar = make(ONLINE_CELLS)
    out: dict[str, Any] = {"exact": _extrapolated(make)}
    calibrated: Callable[[Any, Any], Any] = (
        lambda a, tab: mae_calibrated_coefficients(a, tab, pairs))
    # MAE's own coefficients (the physics guide, eq. 7 with the zones' semi-ellipses, no FastSim):
    # what the calibrated method's rules 2 and 3 leave as they are
    own: Callable[[Any, Any], Any] = lambda a, tab: mae_coefficients(mae_geometry(a), tab)
    for m, f in (("mae_calibrated", calibrated), ("mae", mae_fastsim_coefficients),
                 ("fastrip", fastrip_coefficients), ("ellipse", equivalent_coefficients),
                 ("mae_own", own), ("dlm", lambda a, tab: dlm_coefficients(a, nu=NU)),
                 ("asm", lambda a, tab: asm_fastsim_coefficients(a, nu=NU)),
                 ("polach", polach_coefficients)):
        try:
            c = f(ar, t)
            out[m] = {k: getattr(c, k) for k in ("C11", "C22", "C23", "C13")}
        except ContactError as e:
            out[m] = None
            out[m + "_error"] = str(e)
    # the calibrated MAE without each of its rules (the leave-one-out check)
    for rule in RULES:
        c = mae_calibrated_coefficients(ar, t, pairs, without=(rule,))
        out["without_" + rule] = {k: getattr(c, k) for k in ("C11", "C22", "C23", "C13")}
    return out


def selection_makers() -> dict[str, AreaMaker]:
    """Return the areas the calibrated MAE's pair-factor rule was chosen on (fit data, loaded).

    Semi-ellipse pairs at nodes of the pair-factor table (made from their
    full-adhesion solutions) and two notches other than the validation's;
    none of them is a validation area.
    """
    out: dict[str, AreaMaker] = {}
    for g1, g2 in ((4.0, 0.7), (7.0, 1.3), (0.13, 1.3), (2.5, 0.4)):
        out[f"pair {g1:g}/{g2:g}"] = (lambda n, g1=g1, g2=g2: samples.semi_ellipses_patch(
            g1, g2, cells=n, scale=SCALE, load=LOAD))
    for ratio, half_width, depth in ((1.5, 0.2, 0.3), (1.2, 0.45, 0.1)):
        out[f"notch {ratio:g}/{half_width:g}/{depth:g}"] = (
            lambda n, r=ratio, w=half_width, d=depth: samples.notched_ellipse(
                cells=n, scale=SCALE, load=LOAD, a_over_b=r, half_width=w, depth=d))
    return out


#: the pair-factor rules compared on the selection areas (numpy reference)
SHARES = {"shared": "shared factor (the method)", "zone": "each half its own factor",
          "none": "no pair factor"}


def selection_on(ar: areas.GridArea) -> dict[str, Any]:
    """Return exact curves on a selection area and the calibrated MAE's under each rule."""
    entry = curves_on(ar)
    t = coefficient_table(NU)
    ones = PairFactors(NU, np.log(np.array([0.05, 20.0])), np.ones((4, 2, 2)))
    bound = traction_bound(ar, MU)
    for rule in SHARES:
        for curve in CURVES:
            for p in entry[curve]:
                r = mae_calibrated_fastsim(
                    ar, *p["creepage"], bound=bound, table=t,
                    pairs=ones if rule == "none" else pair_factors(NU), shear_modulus=G,
                    share="zone" if rule == "zone" else "shared")
                p["rule_" + rule] = [r.fx, r.fy, r.mz]
    return entry


def ablation_on(entry: dict[str, Any], ar: areas.GridArea) -> None:
    """Add to ``entry``'s curve points the calibrated MAE without each rule (numpy reference)."""
    t = coefficient_table(NU)
    pairs = pair_factors(NU)
    bound = traction_bound(ar, MU)
    for rule in RULES:
        for curve in CURVES:
            for p in entry[curve]:
                r = mae_calibrated_fastsim(ar, *p["creepage"], bound=bound, table=t,
                                           pairs=pairs, shear_modulus=G, without=(rule,))
                p["without_" + rule] = [r.fx, r.fy, r.mz]


#: the areas rule 4's second form was chosen on (an egg whose longer half trails
#: is 26% high in C~23 with the first form); none of them is a validation area
BEND_SELECTION: dict[str, tuple[Callable[..., areas.GridArea], dict[str, Any]]] = {
    **{f"egg {r:g}": (samples.egg_patch, {"lead_over_trail": r}) for r in (0.5, 0.7, 1.4, 2.5)},
    **{f"egg {r:g} a/b {g:g}": (samples.egg_patch, {"lead_over_trail": r, "a_over_b": g})
       for r, g in ((0.6, 0.6), (2.0, 0.6), (1.5, 1.6), (0.6, 1.6))},
    **{f"crescent {b:g}/{g:g}": (samples.crescent_patch, {"bend": b, "a_over_b": g})
       for b, g in ((0.6, 0.3), (2.0, 0.3), (1.2, 0.2), (1.2, 0.5), (0.8, 0.15), (-1.0, 0.3))},
    **{f"lobes {s:g}/{ld:g}/{o:g}/{ab[0]:g},{ab[1]:g}": (
        samples.asymmetric_lobes, {"size": s, "lead": ld, "overlap": o, "a_over_b": ab})
       for s, ld, o, ab in ((0.6, 0.3, 0.2, (1.0, 1.0)), (0.5, -0.4, 0.3, (0.7, 1.2)),
                            (0.8, 0.6, 0.15, (1.3, 0.8)), (0.4, 0.0, 0.3, (0.5, 1.5)))},
    **{f"band {g:g}/{e:g}": (samples.flat_band_patch, {"a_over_b": g, "exponent": e})
       for g, e in ((0.25, 4.0), (0.15, 6.0), (0.4, 3.0), (0.5, 8.0))},
}


def _first_form_offset(area: areas.GridArea, geometry: Any, zone: Any, rows: Any,
                       c: dict[str, float]) -> dict[str, float]:
    """Rule 4's first form: every strip offset counted, each strip once."""
    count, first, last = calibrated_module.row_extents(area.mask & rows[:, None])
    used = count > 0
    centres = 0.5 * (area.x[first[used]] + area.x[last[used]])
    out = dict(c)
    shifted = c["c23"] + c["c22"] * (float(centres.mean()) - geometry.x_c) / math.sqrt(
        2.0 * zone.area / math.pi)
    # (the first form kept at least a quarter of the zone's c23)
    out["c23"] = max(shifted, 0.25 * c["c23"])
    return out


def bend_selection() -> dict[str, Any]:
    """Return exact and the calibrated MAE's C~11..C~23 on BEND_SELECTION (rule 4's forms)."""
    t = coefficient_table(NU)
    pairs = pair_factors(NU)
    out: dict[str, Any] = {}
    for name, (make, kw) in BEND_SELECTION.items():
        def shape(n: int, make: Any = make, kw: Any = kw) -> areas.GridArea:
            return make(cells=n, **kw)
        ar = shape(ONLINE_CELLS)
        row: dict[str, Any] = {"exact": _extrapolated(shape)}
        keys = ("C11", "C22", "C23")
        c = mae_calibrated_coefficients(ar, t, pairs)
        row["chord"] = {k: getattr(c, k) for k in keys}
        c = mae_calibrated_coefficients(ar, t, pairs, without=("bend",))
        row["none"] = {k: getattr(c, k) for k in keys}
        kept = calibrated_module.offset_c23
        calibrated_module.offset_c23 = _first_form_offset  # type: ignore[assignment]
        try:
            c = mae_calibrated_coefficients(ar, t, pairs)
        finally:
            calibrated_module.offset_c23 = kept  # type: ignore[assignment]
        row["first"] = {k: getattr(c, k) for k in keys}
        c = mae_fastsim_coefficients(ar, t)
        row["mae"] = {k: getattr(c, k) for k in keys}
        out[name] = row
    return out


#: the grids of the coefficient grid check (the calibrated MAE's C~11, C~22, C~23 where missed)
COEF_CHECK_GRIDS = (40, 60, 100, 160)


def coefficient_grid_check(names: list[str]) -> dict[str, Any]:
    """Return the calibrated MAE's coefficients of the named areas on COEF_CHECK_GRIDS cells.

    A normal-solver patch is solved again on each grid (its contact area changes with the
    grid), an analytic shape is the same shape on a finer staircase.
    """
    t = coefficient_table(NU)
    pairs = pair_factors(NU)
    unit = area_makers(False)
    out: dict[str, Any] = {}
    for name in names:
        rows = {}
        for n in COEF_CHECK_GRIDS:
            ar = unit[name](n)
            c = mae_calibrated_coefficients(ar, t, pairs)
            rows[str(n)] = {"strips": int(np.count_nonzero(ar.mask.any(axis=1))),
                            **{k: getattr(c, k) for k in ("C11", "C22", "C23")}}
        out[name] = rows
    return out


def cost_ratio(calls: int = 3000) -> dict[str, Any]:
    """Time the calibrated and the paper's MAE side by side on 30x30 patches.

    ``benchmarks/bench_fastsim.py``'s patches (two semi-ellipses 0.5/2 of 1 cm^2 and a
    Hertzian 6 x 4 mm ellipse, 50 kN), creepages and interleaved timing (``per_call``);
    medians in seconds.
    """
    cal, mae = CalibratedMaeSolver(bench.NU, bench.G), MaeSolver(bench.NU, bench.G)
    out: dict[str, Any] = {}
    for name, make in (("semi-ellipses 30x30", bench.semi_ellipses),
                       ("ellipse 30x30", bench.ellipse)):
        ar = make(30)
        t = bench.per_call({
            "mae_calibrated": lambda: cal.solve(ar, *bench.CREEP, mu=bench.MU),
            "mae": lambda: mae.solve(ar, *bench.CREEP, mu=bench.MU)}, calls)
        out[name] = {m: 1e-6 * median for m, (median, _) in t.items()}
    return out


def compute() -> dict[str, Any]:
    """Run every part; return what the JSON holds."""
    warm_up()
    res: dict[str, Any] = {"machine": machine(), "curve_cells": CURVE_CELLS,
                           "check_cells": CHECK_CELLS, "exact_grids": EXACT_GRIDS,
                           "online_cells": ONLINE_CELLS, "mu": MU, "G": G, "nu": NU,
                           "load": LOAD, "areas": {}, "grid_check": {}}
    loaded, unit = area_makers(True), area_makers(False)
    start = time.time()
    for name, make in loaded.items():
        t0 = time.time()
        ar = make(CURVE_CELLS)
        entry = curves_on(ar)
        ablation_on(entry, ar)
        entry["coefficients"] = coefficients_of(unit[name])
        res["areas"][name] = entry
        print(f"{name}: {time.time() - t0:.0f} s", flush=True)
    for name in CHECK_AREAS:
        t0 = time.time()
        res["grid_check"][name] = curves_on(loaded[name](CHECK_CELLS))
        print(f"grid check {name}: {time.time() - t0:.0f} s", flush=True)
    res["cost_ratio"] = cost_ratio()
    res["selection"] = {}
    for name, make in selection_makers().items():
        t0 = time.time()
        res["selection"][name] = selection_on(make(CURVE_CELLS))
        print(f"selection {name}: {time.time() - t0:.0f} s", flush=True)
    t0 = time.time()
    res["bend_selection"] = bend_selection()
    print(f"bend selection: {time.time() - t0:.0f} s", flush=True)
    res["seconds"] = time.time() - start
    return res


# ----------------------------------------------------------------------------- report

def curve_error(entry: dict[str, Any], curve: str, method: str) -> float | None:
    """Return the largest |F_method - F_exact| / (mu N) over a curve where |F_exact| > 5% mu N."""
    mu_n = MU * entry["N"]
    worst = 0.0
    for p in entry[curve]:
        if p[method] is None:
            return None
        for idx in (0, 1):
            fe, fm = p["exact"][idx], p[method][idx]
            if abs(fe) > 0.05 * mu_n:
                worst = max(worst, abs(fm - fe) / mu_n)
    return worst


def worst_error(entry: dict[str, Any], method: str) -> tuple[float | None, str]:
    """Return the worst curve error of a method on an area and the curve it occurs on."""
    errs = {c: curve_error(entry, c, method) for c in CURVES}
    if any(v is None for v in errs.values()):
        return None, "-"
    curve = max(errs, key=lambda c: errs[c] or 0.0)
    return errs[curve], curve


def _f(v: float | None, fmt: str = "{:.1f}") -> str:
    return "n/a" if v is None else fmt.format(v)


def _fname(name: str) -> str:
    return ("wider_curves_" + name.replace(" ", "_").replace("/", "-").replace("+", "p")
            .replace(".", "_").replace("(", "").replace(")", "") + ".png")


def report(res: dict[str, Any]) -> None:
    """Write docs/validation_wider.md and the figures from the results."""
    FIG.mkdir(parents=True, exist_ok=True)
    d = res["areas"]
    lines: list[str] = []
    add = lines.append
    add("# Wider validation: the calibrated MAE, the paper's MAE, FaStrip, the equivalent"
        " ellipse, DLM and ASM against the exact theory\n")
    add("Generated by `python scripts/validate_wider.py` (results cached in"
        " `docs/data/validation_wider.json`; `--report-only` rewrites this page from them)."
        " Every number here was computed by the package on "
        f"{res['machine']}; the whole run took {res['seconds'] / 60:.1f} min.\n")
    add("Methods: the exact theory (Kalker's, boundary elements, Coulomb friction with the"
        " given pressure); the calibrated MAE (`compiled.CalibratedMaeSolver`, the second MAE"
        " method, `fastsim_ros/contact/mae_calibrated.py`: section 0); the paper's MAE +"
        " FastSim (`compiled.MaeSolver`, default `auto` split, given bound); FaStrip"
        " (`fastsim_ros.contact.fastrip`, Sichani, Enblom and Berg 2016, strip form with each"
        " strip's own half-length); the equivalent-ellipse"
        " FastSim (`compiled.EquivalentEllipseSolver`, given bound); the seed paper's older"
        " ways to FastSim's flexibilities on any area, DLM (Kalker's deformation levelling"
        " method, `fastsim_ros.contact.dlm`) and ASM (Knothe and Hung's asymptotic strip"
        " method, FastSim calibrated to its coefficients, `fastsim_ros.contact.asm`), both"
        " with Kalker's FastSim (radial return, given bound; `docs/validation_seed.md` sets"
        " them beside the paper's Tables 1 and 2). Steel (G ="
        f" {G:.3g} Pa, nu = {NU}), mu = {MU}, N = {LOAD:.3g} N; analytic shapes scaled to"
        " 1e-4 m^2, flange root and profile gap from the normal solver.\n")
    add("FaStrip's provenance: the paper's text (and that of the non-elliptical"
        " ANALYN-FaStrip papers) could not be retrieved when it was implemented, so"
        " `fastrip.py` is a reconstruction from strip theory and the paper's stated idea"
        " (Carter's solution per strip, the strips' constant from Kalker's linear theory),"
        " with each equation and choice stated in its docstring and pinned by tests; the"
        " paper's own accuracy claim could not be checked. Its spin treatment (FastSim's"
        " adhesion traction for the spin within each strip, added to Carter's solution for"
        " the creepages, FastSim's direction where the sum reaches the bound) is this"
        " reading's; a first reading (the spin as a constant equivalent lateral creepage"
        " under Carter's law) was 13.5% of mu N off under pure spin on the Hertzian ellipse"
        " (24 cells) and was dropped for it (1.8%).\n")
    _targets(add, res)
    # ------------------------------------------------------------------ summary table
    add("## 1. Worst-case curve errors\n")
    add(f"Largest |F_method - F_exact| over the four curves (xi, eta, phi, combined; eight"
        f" levels each, multiples of the creepage that would saturate the linear theory) and"
        f" over Fx and Fy, where the exact component exceeds 5% of mu N, in % of mu N (the"
        f" curve where it occurs in brackets). Every method and the exact theory on the same"
        f" grid: {CURVE_CELLS} cells across each area's bounding box.\n")
    add("| area | cells in contact | " + " | ".join(LABELS[m] for m in METHODS) + " |")
    add("| --- | --- | " + " | ".join("---" for _ in METHODS) + " |")
    overall = {m: (0.0, "") for m in METHODS}
    for name, e in d.items():
        row = []
        for m in METHODS:
            w, c = worst_error(e, m)
            row.append(f"{_f(None if w is None else 100 * w)} ({c})")
            if w is not None and w > overall[m][0]:
                overall[m] = (w, name)
        add(f"| {name} | {e['in_contact']} | " + " | ".join(row) + " |")
    add("")
    add("Worst case over all areas: " + "; ".join(
        f"{LABELS[m]} {100 * overall[m][0]:.1f} ({overall[m][1]})" for m in METHODS) + ".\n")
    non_ell = [n for n in d if not n.startswith("ellipse")]
    for m in METHODS:
        miss = [n for n in non_ell if (worst_error(d[n], m)[0] or 0.0) > 0.10]
        misses = f"; misses: {', '.join(miss)}" if miss else ""
        add(f"- {LABELS[m]}: within 10% of mu N on {len(non_ell) - len(miss)} of"
            f" {len(non_ell)} non-elliptical areas{misses}.")
    add("")
    add("Per curve (in % of mu N; Fx and Fy together):\n")
    add("| area | curve | " + " | ".join(LABELS[m] for m in METHODS) + " |")
    add("| --- | --- | " + " | ".join("---" for _ in METHODS) + " |")
    for name, e in d.items():
        for c in CURVES:
            add(f"| {name} | {c} | " + " | ".join(
                _f(None if curve_error(e, c, m) is None else 100 * (curve_error(e, c, m) or 0))
                for m in METHODS) + " |")
    add("")
    fig, ax = plt.subplots(figsize=(12, 4))
    names = list(d)
    xs = np.arange(len(names))
    for k, m in enumerate(METHODS):
        vals = [100 * (worst_error(d[n], m)[0] or 0.0) for n in names]
        ax.bar(xs + BAR * (k - 0.5 * (len(METHODS) - 1)), vals, BAR, label=LABELS[m])
    ax.axhline(10, color="k", lw=0.8, ls="--", label="target 10% of mu N")
    ax.set_xticks(xs, names, rotation=30, ha="right", fontsize=7)
    ax.set_ylabel("worst curve error (% of mu N)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(FIG / "wider_worst.png", dpi=100)
    plt.close(fig)
    add("![worst-case curve errors](figures/wider_worst.png)\n")
    # ------------------------------------------------------------------ grid check
    add("### Grid check\n")
    add(f"The curves above are on {CURVE_CELLS} cells. On {res['check_cells']} cells (exact"
        " and methods re-solved on the finer grid) the worst-case errors are:\n")
    add("| area | cells | " + " | ".join(LABELS[m] for m in METHODS) + " |")
    add("| --- | --- | " + " | ".join("---" for _ in METHODS) + " |")
    for name, e in res["grid_check"].items():
        for label, ent in ((CURVE_CELLS, d[name]), (res["check_cells"], e)):
            add(f"| {name} | {label} | " + " | ".join(
                f"{_f(100 * (worst_error(ent, m)[0] or 0.0))} ({worst_error(ent, m)[1]})"
                for m in METHODS) + " |")
    add("")
    shifts = [abs((worst_error(e, m)[0] or 0) - (worst_error(d[n], m)[0] or 0))
              for n, e in res["grid_check"].items() for m in METHODS]
    add(f"The worst-case errors move by at most {100 * max(shifts):.1f} points of mu N"
        f" between {CURVE_CELLS} and {res['check_cells']} cells: {CURVE_CELLS} cells, the grid"
        " of `scripts/validate.py`'s curves, is converged enough to rank the methods, and"
        " keeps the exact Coulomb solves (the cost of this run) to a few tenths of a second"
        " each.\n")
    # ------------------------------------------------------------------ coefficients
    add("## 2. Linear-range coefficients\n")
    add(f"nu = {NU}, about each area's origin. Exact: full adhesion extrapolated to zero cell"
        f" size over n = {EXACT_GRIDS} (fit C0 + k/n; error = change without the"
        f" coarsest grid). Methods at vanishing creepage on {ONLINE_CELLS} cells: MAE +"
        " FastSim, FaStrip and equivalent-ellipse FastSim. Deviation from exact in %; C13 (a"
        " coupling that crosses zero) in % of C11.\n")
    add("| area | exact C11 | C22 | C23 | C13 | method | dC11 | dC22 | dC23 | dC13/C11 |")
    add("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    worst_coef = {m: (0.0, "", "") for m in METHODS}
    for name, e in d.items():
        co = e["coefficients"]
        ex = co["exact"]
        for k, m in enumerate(METHODS):
            head = (f"| {name} | {ex['C11']:.3f} | {ex['C22']:.3f} | {ex['C23']:.3f} |"
                    f" {ex['C13']:.3f} |" if k == 0 else "| | | | | |")
            c = co.get(m)
            if c is None:
                add(head + f" {LABELS[m]} | n/a | n/a | n/a | n/a |")
                continue
            devs = {key: c[key] / ex[key] - 1 for key in ("C11", "C22", "C23")}
            for key, v in devs.items():
                if abs(v) > abs(worst_coef[m][0]):
                    worst_coef[m] = (v, name, key)
            add(head + f" {LABELS[m]} | " + " | ".join(f"{100 * devs[key]:+.1f}"
                                                       for key in ("C11", "C22", "C23"))
                + f" | {100 * (c['C13'] - ex['C13']) / ex['C11']:+.1f} |")
    add("")
    add("Largest coefficient error (C11, C22, C23): " + "; ".join(
        f"{LABELS[m]} {100 * worst_coef[m][0]:+.1f}% ({worst_coef[m][2]}, {worst_coef[m][1]})"
        for m in METHODS) + ".")
    ext = max(((e["coefficients"]["exact"][k + "_err"] / e["coefficients"]["exact"][k], n, k)
               for n, e in d.items() for k in ("C11", "C22", "C23")))
    add(f"Largest error estimate of the exact extrapolation: {100 * ext[0]:.2f}% ({ext[2]},"
        f" {ext[1]}); coefficient errors smaller than that are not resolved there.\n")
    fig, axs = plt.subplots(1, 3, figsize=(14, 4))
    for ax, key in zip(axs, ("C11", "C22", "C23")):
        for k, m in enumerate(METHODS):
            vals = [100 * (d[n]["coefficients"][m][key] / d[n]["coefficients"]["exact"][key]
                           - 1) if d[n]["coefficients"][m] else 0.0 for n in names]
            ax.bar(xs + BAR * (k - 0.5 * (len(METHODS) - 1)), vals, BAR, label=LABELS[m])
        ax.axhspan(-5, 5, color="0.92")
        ax.set_xticks(xs, names, rotation=40, ha="right", fontsize=6)
        ax.set_title(f"{key}: deviation from exact (%)")
    axs[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(FIG / "wider_coefficients.png", dpi=100)
    plt.close(fig)
    add("![coefficient errors](figures/wider_coefficients.png)\n")
    # ------------------------------------------------------------------ cost
    add("## 3. Cost per solve\n")
    add(f"Median wall time of one solve over the area's 32 curve points, {CURVE_CELLS}-cell"
        f" grid, on {res['machine']} (shared with other jobs: indicative, not a benchmark;"
        " `benchmarks/` measures speed; each the second of two calls, the first after the exact"
        " solve paying for its caches). The two MAEs and the equivalent ellipse: the compiled path"
        " called from Python; FaStrip: numpy (no compiled path yet); exact: the Coulomb"
        " solver, the operator built once per area.\n")
    add("| area | cells in contact | exact (s) | " + " | ".join(
        f"{LABELS[m]} (us)" for m in METHODS) + " |")
    add("| --- | --- | --- | " + " | ".join("---" for _ in METHODS) + " |")
    for name, e in d.items():
        cst = e["cost"]
        add(f"| {name} | {e['in_contact']} | {cst['exact']:.3f} | " + " | ".join(
            _f(None if cst[m] is None else 1e6 * cst[m], "{:.0f}") for m in METHODS) + " |")
    med = {m: float(np.median([e["cost"][m] for e in d.values() if e["cost"][m]]))
           for m in ("exact",) + METHODS}
    add(f"\nMedian over the areas: exact {med['exact']:.3f} s, " + ", ".join(
        f"{LABELS[m]} {1e6 * med[m]:.0f} us" for m in METHODS) + ".\n")
    prep = {k: [e["prep"][k] for e in d.values() if "prep" in e] for k in ("dlm", "asm")}
    if prep["dlm"]:
        add("DLM + FastSim and ASM + FastSim are numpy (no compiled path): each solve is the"
            " numpy FastSim sweep with the area's flexibilities, which are found once per area"
            " (the cost of a new patch): DLM's levelling (three FFT convolutions of the"
            " influence coefficients) median"
            f" {1e3 * float(np.median(prep['dlm'])):.0f} ms (largest"
            f" {1e3 * max(prep['dlm']):.0f} ms), ASM's linear system of four unknowns per strip"
            f" median {1e3 * float(np.median(prep['asm'])):.0f} ms (largest"
            f" {1e3 * max(prep['asm']):.0f} ms), on the {CURVE_CELLS}-cell grids.\n")
    # ------------------------------------------------------------------ causes
    add("## 4. Where the paper's MAE falls short, and what the calibrated MAE does there\n")
    _causes(add, d)
    _selection(add, res)
    # ------------------------------------------------------- beyond the selection
    _beyond(add, res)
    # ------------------------------------------------------------------ curves figures
    add("## 5. Curves of the new areas\n")
    for name in [n for n in d if n in NEW or n.startswith("profile gap") or n in BEYOND]:
        _curve_figure(name, d[name])
        add(f"![{name}](figures/{_fname(name)})\n")
    (DOCS / "validation_wider.md").write_text("\n".join(lines) + "\n")


def _c_tolerance(exact_value: float) -> float:
    """Return the coefficient target: 5% of the exact value, or 0.05 where that is near zero."""
    return max(0.05 * abs(exact_value), 0.05)


def _c_error(e: dict[str, Any], m: str, key: str) -> float:
    """Return a method's coefficient error in units of the target's tolerance (1 = at it)."""
    co = e["coefficients"]
    return float((co[m][key] - co["exact"][key]) / _c_tolerance(co["exact"][key]))


def _c_text(e: dict[str, Any], m: str, key: str) -> str:
    """Return a coefficient's error as the target reads it: % of exact, or absolute near zero."""
    co = e["coefficients"]
    ex = co["exact"][key]
    if abs(ex) >= 1.0:
        return f"{100 * (co[m][key] / ex - 1):+.1f}%"
    return f"{co[m][key] - ex:+.3f} (of {ex:.3f})"


def _curve_excess(e: dict[str, Any], m: str, base: str) -> tuple[float, str]:
    """Return the largest excess (points of mu N) of ``m``'s curve error over ``base``'s."""
    return max(((100 * ((curve_error(e, c, m) or 0.0) - (curve_error(e, c, base) or 0.0)), c)
                for c in CURVES))


def _beyond(add: Callable[[str], None], res: dict[str, Any]) -> None:
    """Write section 6: the calibrated MAE on areas outside its selection."""
    d = res["areas"]
    m = "mae_calibrated"
    add("## 6. The calibrated MAE beyond its selection\n")
    fresh = [n for n in BEYOND if n not in SEEN]
    add(f"{len(BEYOND)} areas made after the calibrated MAE's rules were fixed (`BEYOND` in"
        " the script): eggs with the longer half trailing and leading, crescents of other"
        " bends and widths (horns leading and trailing), two lobes side by side of unequal"
        " size, one leading or trailing, and two flat bands (superellipses wide across the"
        " rail). Nine were made with rule 4's second form in its first version (every bend"
        " counted); on one of them, " + ", ".join(SEEN) + ", that version met the linear"
        " C~23 but missed the curve under spin (10.8% of mu N, 2.6 points worse than the"
        " paper's MAE; `mae_calibrated.offset_c23` says why), so rule 4 was changed to count"
        " a bend only where its horns lead, and two more crescents with trailing horns were"
        " made after the change to check it: that one area is the change's fit data, the"
        f" other {len(fresh)} were never looked at while choosing any rule. Targets"
        ": curves within 10% of mu N where the exact force exceeds 5%"
        " of mu N; C~23 within 5% of exact, or 0.05 where it is near zero (below 1); no curve"
        " worse than the paper's MAE's by more than 1 point of mu N.\n")
    add("| area | worst curve, calibrated / paper's MAE | largest excess over the paper's MAE"
        " (points, curve) | C~11 | C~22 | C~23 | C~23, paper's MAE + FastSim |")
    add("| --- | --- | --- | --- | --- | --- | --- |")
    miss_curve, miss_c23, miss_excess = [], [], []
    for n in BEYOND:
        e = d[n]
        w, c = worst_error(e, m)
        wm, cm = worst_error(e, "mae")
        ex, cx = _curve_excess(e, m, "mae")
        if (w or 0.0) > 0.10:
            miss_curve.append(n)
        if abs(_c_error(e, m, "C23")) > 1.0:
            miss_c23.append(n)
        if ex > 1.0:
            miss_excess.append(n)
        add(f"| {n} | {100 * (w or 0):.1f} ({c}) / {100 * (wm or 0):.1f} ({cm}) |"
            f" {ex:+.1f} ({cx}) | {_c_text(e, m, 'C11')} | {_c_text(e, m, 'C22')} |"
            f" {_c_text(e, m, 'C23')} | {_c_text(e, 'mae', 'C23')} |")
    add("")
    every = f"met on all {len(BEYOND)}."
    add("- curves within 10% of mu N: "
        + (every if not miss_curve else "missed on " + ", ".join(miss_curve) + "."))
    add("- C~23 within 5% (0.05 near zero): "
        + (every if not miss_c23 else "missed on " + ", ".join(miss_c23) + "."))
    add("- no curve worse than the paper's MAE by more than 1 point: "
        + (every if not miss_excess else "missed on " + ", ".join(miss_excess)
           + "."))
    add("")
    # ------------------------------------------------------------- leave one out
    add("### Each rule on the areas it was not chosen on\n")
    add("The calibrated MAE without one rule at a time (the numpy reference, `without=` in"
        " `mae_calibrated.py`; without rule 2 the zones get the paper's flexibilities of"
        " their semi-ellipses with the method's coefficients, without rule 3 FastSim's radial"
        " return), on every validation area. Each rule's gain: the worst curve error without"
        " it less that with it (points of mu N; positive: the rule helps), and the same for"
        " the C~23 error (in % of exact or, near zero, points of 0.01). The areas a rule was"
        " chosen on are left out of its count (its fit data: "
        + "; ".join(f"rule {RULE_LABELS[r]}: {', '.join(CHOSEN_ON[r])}" for r in RULES)
        + "; besides, the selection areas of section 4 and of rule 4's second form"
        " below).\n")
    add("| rule | areas (not chosen on) | helps (> 0.5 point) | hurts (< -0.5 point) |"
        " largest harm (curve) | largest gain (curve) | C~23: helps by over 1 point |"
        " C~23: hurts by over 1 point |")
    add("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in RULES:
        others = [n for n in d if n not in CHOSEN_ON[r]]
        gains = {}
        c23 = {}
        for n in others:
            if "without_" + r not in d[n]["xi"][0]:
                continue
            w_with = worst_error(d[n], m)[0] or 0.0
            w_without = worst_error(d[n], "without_" + r)[0] or 0.0
            gains[n] = 100 * (w_without - w_with)
            co = d[n]["coefficients"]
            if "without_" + r in co:
                tol = _c_tolerance(co["exact"]["C23"])
                c23[n] = 5 * (abs(co["without_" + r]["C23"] - co["exact"]["C23"])
                              - abs(co[m]["C23"] - co["exact"]["C23"])) / tol
        if not gains:
            continue
        harm = min(gains.items(), key=lambda kv: kv[1])
        gain = max(gains.items(), key=lambda kv: kv[1])
        c23_hurt = [n for n, v in c23.items() if v < -1.0]
        c23_help = [n for n, v in c23.items() if v > 1.0]
        add(f"| {RULE_LABELS[r]} | {len(gains)} | {sum(v > 0.5 for v in gains.values())} |"
            f" {sum(v < -0.5 for v in gains.values())} | {harm[1]:+.1f} ({harm[0]}) |"
            f" {gain[1]:+.1f} ({gain[0]}) | "
            + (", ".join(f"{n} {c23[n]:+.1f}" for n in c23_help) if c23_help else "none")
            + " | "
            + (", ".join(f"{n} {c23[n]:+.1f}" for n in c23_hurt) if c23_hurt else "none")
            + " |")
    add("")
    add("How to read it. Rule 3 (the rigid-slip return) is general: it helps the curves"
        " nearly everywhere and hurts none. Rule 2 (calibrated flexibilities) helps curves and"
        " C~23 on most areas and hurts no curve; where it costs C~23 it removes FastSim's"
        " discretisation error that happened to offset MAE's own. Rule 1 (pair factors) was"
        " chosen for joined semi-ellipses, MAE's own model shape, and its gain is there"
        " (section 4, and the semi-ellipses' C~23 above); beyond them it moves the curves"
        " little, costs a few points on the truncated ellipse and the lobes' C~23, and"
        " pushes no area out of a target: it stays, not shown general beyond pairs. Rule 4"
        " (a bend whose horns lead) moves no curve and raises C~23 where the horns lead; on"
        " lobes side by side its fit reads the waist as a bend and lifts C~23 a few points"
        " too far: general for crescents, not for lobes. With all four, the curves are"
        " within 10% of mu N on every area and better than the paper's MAE's on every"
        " area, so the default stays the calibrated MAE (section 0).\n")
    add("Per area (worst curve error in % of mu N: the calibrated MAE, then without each"
        " rule; a rule's own fit areas in italics):\n")
    add("| area | calibrated MAE | " + " | ".join(f"without {RULE_LABELS[r]}" for r in RULES)
        + " |")
    add("| --- | --- | " + " | ".join("---" for _ in RULES) + " |")
    for n, e in d.items():
        if "without_pairs" not in e["xi"][0]:
            continue
        cells = []
        for r in RULES:
            v = f"{100 * (worst_error(e, 'without_' + r)[0] or 0.0):.1f}"
            cells.append(f"*{v}*" if n in CHOSEN_ON[r] else v)
        add(f"| {n} | {100 * (worst_error(e, m)[0] or 0.0):.1f} | " + " | ".join(cells) + " |")
    add("")
    _bend_selection_report(add, res)


def _bend_selection_report(add: Callable[[str], None], res: dict[str, Any]) -> None:
    """Write the selection of rule 4's second form (fit data)."""
    sel = res.get("bend_selection")
    if not sel:
        return
    add("### Rule 4's second form: how it was chosen\n")
    add("Issue 22 found the first form of rule 4 (every strip's offset from the centroid"
        " counted, each strip once) 26% high in C~23 on an egg whose longer half trails, where"
        " the paper's MAE is within 3%. On the exact theory: the lateral force of a strip"
        " under a lateral creepage is proportional to the strip's length (within 7% rms on"
        " eight eggs and six crescents, 80 cells), so offsets that grow in proportion to the"
        " chord (an egg: the long strips lead or trail) average out at the centroid, while a"
        " bend (strips moved by a function of y whatever their length, the short ones most: a"
        " crescent) is felt as the first form counts it. The second form fits the strips'"
        " centres as `alpha + beta l + kappa l^2` (`l` the half-chord) and counts the `kappa`"
        " part only (`rules.chord_bend_offset`): exactly the first form on a crescent, zero on"
        " an egg; no parameter fitted. It was chosen on these areas (fit data, none a"
        " validation area; C~23 deviation from exact about each area's origin, % or,"
        " near zero, absolute). A bend whose horns trail (a negative offset) is not counted:"
        " it would lower the zone's `c23` and with it raise its spin flexibility, which gets"
        " the linear C~23 right but halves the lateral force under moderate spin (section 6,"
        " crescent -1.5/0.35); the selection's crescent -1/0.3 shows what that costs in the"
        " linear range.\n")
    add("| selection area | exact C~23 | second form (the method) | first form | no rule 4 |"
        " paper's MAE + FastSim |")
    add("| --- | --- | --- | --- | --- | --- |")
    forms = ("chord", "first", "none", "mae")
    worst: dict[str, tuple[float, str]] = {k: (0.0, "") for k in forms}
    for n, row in sel.items():
        ex = row["exact"]["C23"]
        cells = []
        for k in ("chord", "first", "none", "mae"):
            err = (row[k]["C23"] - ex) / _c_tolerance(ex)
            if abs(err) > abs(worst[k][0]):
                worst[k] = (err, n)
            cells.append(f"{100 * (row[k]['C23'] / ex - 1):+.1f}%" if abs(ex) >= 1.0
                         else f"{row[k]['C23'] - ex:+.3f}")
        add(f"| {n} | {ex:.3f} | " + " | ".join(cells) + " |")
    add("")
    add("Worst, in units of the target's tolerance (1: at 5% or 0.05): " + "; ".join(
        f"{lab} {abs(worst[k][0]):.2f} ({worst[k][1]})" for k, lab in (
            ("chord", "second form"), ("first", "first form"), ("none", "no rule 4"),
            ("mae", "paper's MAE + FastSim"))) + ". The second form misses on "
        + ", ".join(n for n, row in sel.items()
                    if abs(row["chord"]["C23"] - row["exact"]["C23"])
                    > _c_tolerance(row["exact"]["C23"]))
        + ": on the crescents whose horns trail by choice (above); elsewhere the first form and"
        " no rule 4 miss as well, and the cause is the zones' likening to semi-ellipses (MAE's"
        " own coefficients: a strongly bent crescent, a square band, lobes with a narrow"
        " waist), not the strips' offsets.\n")


def _coefficient_misses(d: dict[str, Any]) -> list[str]:
    """Return the areas where the calibrated MAE's C~11, C~22 or C~23 is over 5% off exact."""
    return sorted(n for n in d if any(abs(_c_error(d[n], "mae_calibrated", k)) > 1.0
                                      for k in ("C11", "C22", "C23")))


def _coef_dev(e: dict[str, Any], m: str, key: str) -> float:
    co = e["coefficients"]
    return float(co[m][key] / co["exact"][key] - 1)


def _targets(add: Callable[[str], None], res: dict[str, Any]) -> None:
    """Write section 0: the calibrated MAE's rules and the targets, met or missed."""
    d = res["areas"]
    m = "mae_calibrated"
    add("## 0. The calibrated MAE and its targets\n")
    add("The paper's MAE stays as it is (`mae`); the calibrated MAE keeps its"
        " steps 1-3 (centroid, split, each zone likened to a semi-ellipse) and changes what"
        " the validation below shows off, each by a rule from the exact theory"
        " (`fastsim_ros/contact/mae_calibrated.py` states each with its evidence):\n")
    add("1. **Joined halves interact** (pair factors): the zones' `c11, c22, c23` are scaled"
        " so that their MAE sum is the exact coefficient of the pair of semi-ellipses they are"
        " likened to, from `fastsim_ros/data/semi_ellipse_pair_factors.csv` (made by"
        " `scripts/make_pair_tables.py` with the exact solver, every entry with an error"
        " estimate, on pairs other than the validation's); the factor is shared by both zones"
        " (section 4, *Selection*, shows why).")
    add("2. **FastSim gives the zones' coefficients on the real cells** (calibrated"
        " flexibilities): each zone's L1..L4 come from FastSim's own adhesion integrals over"
        " that zone's cells (with the restart behind a gap and the flat edges as they are),"
        " so that in full adhesion FastSim gives exactly the zones' coefficients on any grid.")
    add("3. **A slipping cell slips along its slip** (the rigid-slip return): its traction is"
        " opposite to its slip with FastSim's compliance and the rigid slip at the cell,"
        " where FastSim's radial return sends it along the trial traction, which MAE's unequal"
        " flexibilities turn off the slip's direction.")
    add("4. **A bent zone's strips are offset** (crescent): spin about the centroid acts on a"
        " strip centred off it as a lateral creepage, which adds `c22 offset/sqrt(A')` to the"
        " zone's `c23`; `offset` is the bend's part of the strips' mean centre less the"
        " centroid (the strips' centres fitted as `alpha + beta l + kappa l^2` in the"
        " half-chord `l`, the `kappa` part counted: a crescent's offsets count, an egg's,"
        " proportional to the chord, do not; no parameter fitted). The first form (every"
        " offset counted) was 26% high in C~23 on an egg whose longer half trails;"
        " section 6 shows the selection of the second form and the rules' check beyond their"
        " selection.\n")
    non_ell = [n for n in d if not n.startswith("ellipse")]
    worst = {k: max(((worst_error(d[n], k)[0] or 0.0, n) for n in d)) for k in METHODS}
    curve_miss = [(n, 100 * (worst_error(d[n], m)[0] or 0.0)) for n in d
                  if (worst_error(d[n], m)[0] or 0.0) > 0.10]
    coef_miss = [(n, key, 100 * _coef_dev(d[n], m, key)) for n in d
                 for key in ("C11", "C22", "C23") if abs(_c_error(d[n], m, key)) > 1.0]
    worse = max((100 * ((worst_error(d[n], m)[0] or 0.0) - (worst_error(d[n], "mae")[0] or 0.0)),
                 n) for n in d)
    hertz = "ellipse 2/3 (Hertz)"
    hertz_worse = max((100 * ((curve_error(d[hertz], c, m) or 0.0)
                              - (curve_error(d[hertz], c, "mae") or 0.0)), c) for c in CURVES)
    worst_coef = max(((abs(_c_error(d[n], m, key)), n, key) for n in d
                      for key in ("C11", "C22", "C23")))
    add("| target | measured | |")
    add("| --- | --- | --- |")
    add(f"| force-creepage curves within 10% of mu N where the exact force exceeds 5% of mu N,"
        f" every area | worst {100 * worst[m][0]:.1f}% ({worst[m][1]}) |"
        f" {'met' if not curve_miss else 'missed on ' + ', '.join(n for n, _ in curve_miss)} |")
    add(f"| linear-range C~11, C~22, C~23 within 5% of exact (0.05 where below 1), every area"
        " | worst"
        f" {_c_text(d[worst_coef[1]], m, worst_coef[2])} ({worst_coef[2]},"
        f" {worst_coef[1]}) | " + ("met" if not coef_miss else "missed: " + "; ".join(
            f"{n} {key} {_c_text(d[n], m, key)}" for n, key, _ in coef_miss)) + " |")
    add("| better than the paper's MAE, FaStrip and the equivalent ellipse on the worst case |"
        + " " + ", ".join(f"{LABELS[k]} {100 * worst[k][0]:.1f}" for k in METHODS) + " | "
        + ("met" if all(worst[m][0] < worst[k][0] for k in METHODS if k != m) else "missed")
        + " |")
    add(f"| never worse than the paper's MAE by more than 1 point on any area | largest"
        f" excess {worse[0]:+.1f} points ({worse[1]}) | {'met' if worse[0] <= 1.0 else 'missed'}"
        " |")
    add(f"| on the Hertzian ellipse no worse than Kalker's FastSim (the paper's MAE there) by"
        f" more than 1 point on any curve | largest excess {hertz_worse[0]:+.1f} points"
        f" ({hertz_worse[1]}) | {'met' if hertz_worse[0] <= 1.0 else 'missed'} |")
    cr = res.get("cost_ratio") or {}
    ratios = {n: v["mae_calibrated"] / v["mae"] for n, v in cr.items()}
    add("| one 30x30 solve at most 1.5x the paper's MAE (`solve` from Python, interleaved,"
        " medians; `benchmarks/bench_fastsim.py` measures more) | " + ", ".join(
            f"{n} {1e6 * cr[n]['mae_calibrated']:.1f} / {1e6 * cr[n]['mae']:.1f} us ="
            f" {r:.2f}x" for n, r in ratios.items()) + " | "
        + ("met" if ratios and max(ratios.values()) <= 1.5 else "missed") + " |\n")
    if coef_miss:
        add("Where the coefficient target is missed: " + _coef_miss_why(d, coef_miss) + "\n")
        check = res.get("coefficient_grid_check") or {}
        if check:
            add("The calibrated MAE's coefficients of these areas on other grids (deviation from"
                " the exact extrapolation, %; strips in contact in brackets):\n")
            add("| area | " + " | ".join(f"{n} cells" for n in COEF_CHECK_GRIDS) + " |")
            add("| --- | " + " | ".join("---" for _ in COEF_CHECK_GRIDS) + " |")
            for name, rows in check.items():
                ex = d[name]["coefficients"]["exact"]
                add(f"| {name} | " + " | ".join(
                    ", ".join(f"{k} {100 * (rows[str(n)][k] / ex[k] - 1):+.1f}"
                              for k in ("C11", "C22", "C23")) + f" ({rows[str(n)]['strips']})"
                    for n in COEF_CHECK_GRIDS) + " |")
            add("\nOn an analytic shape the method's coefficients do not move with the grid"
                " (rule 2 makes them the zones' own); a normal-solver patch is solved anew on each"
                " grid, and with it its contact area, so its coefficients move by a few % from"
                " grid to grid: where that spread straddles the target, the miss on "
                f"{ONLINE_CELLS} cells is not resolved.\n")
    better = [n for n in d if (worst_error(d[n], m)[0] or 0.0) < (worst_error(d[n], "mae")[0]
                                                                  or 0.0)]
    add(f"**Default.** The calibrated MAE's worst curve error is smaller than the paper's MAE's"
        f" on {len(better)} of {len(d)} areas"
        + (" (every one)" if len(better) == len(d) else
           f" (not on {', '.join(n for n in d if n not in better)})")
        + ", and smaller than every other method's worst case over all areas: so"
        + (" `mae_calibrated` is the default of the node and of `fastsim_contact forces` and"
           " `wheelset` (a method becomes the default when this report shows it better than"
           " the paper's MAE on every area)." if len(better) == len(d)
           else " the default stays `mae`.")
        + " The table that decides it (worst curve error per area, % of mu N):\n")
    add("| area | " + " | ".join(LABELS[k] for k in METHODS) + " |")
    add("| --- | " + " | ".join("---" for _ in METHODS) + " |")
    for n in d:
        add(f"| {n} | " + " | ".join(
            f"{100 * (worst_error(d[n], k)[0] or 0.0):.1f}" for k in METHODS) + " |")
    add("| **worst** | " + " | ".join(f"**{100 * worst[k][0]:.1f}**" for k in METHODS) + " |")
    add("")
    del non_ell


def _coef_miss_why(d: dict[str, Any], misses: list[tuple[str, str, float]]) -> str:
    """Explain each coefficient miss with the paper's MAE's own coefficients there."""
    parts = []
    for n in sorted({n for n, _, _ in misses}):
        keys = [key for mn, key, _ in misses if mn == n]
        text = (f"{n}: " + ", ".join(
            f"{key} {_c_text(d[n], 'mae_calibrated', key)} (MAE's own coefficients, eq. 7 of"
            f" its zones' semi-ellipses, {_c_text(d[n], 'mae_own', key)}; the paper's MAE +"
            f" FastSim on {ONLINE_CELLS} cells {_c_text(d[n], 'mae', key)})" for key in keys))
        parts.append(text)
    return ("; ".join(parts) + ". The calibrated method gives in full adhesion exactly its"
            " zones' coefficients, MAE's own with the pair factors and the strips' bend"
            " (rule 2 removes FastSim's discretisation error, which in the paper's MAE + FastSim"
            " happens to offset part of MAE's own), so where MAE's likening of a zone to a"
            " semi-ellipse is off, so is the method: zones long along x (a/b about 5 to 6: the"
            " flat-sided superellipse, and the profile-gap patch near the flange root, 9 strips"
            " across on the curves' grid), strongly bent crescents (C~22 with C~23), lobes"
            " whose waist makes a zone of two unlike parts. On the crescents whose horns trail"
            " rule 4 is left out by choice (section 6: it would get C~23 right and the curve"
            " under spin wrong), so C~23 is MAE's own there, too high by 0.1 to 0.3 (the"
            " paper's MAE + FastSim higher still), while every curve stays within 10% of mu N."
            " The errors have both signs and several causes: no one factor removes them.")


def _selection(add: Callable[[str], None], res: dict[str, Any]) -> None:
    """Write the selection areas: the pair-factor rules compared on fit data."""
    sel = res.get("selection")
    if not sel:
        return
    add("### Selection: how the pair factor is shared\n")
    add("The pair factors fix the pair's coefficients; how the zones share them was chosen on"
        " areas that are neither validation areas nor the table's own (pairs of semi-ellipses"
        " and two notches; `selection_makers` in the script), with the exact curves on each"
        " (worst curve error, % of mu N, the calibrated MAE's numpy reference under each"
        " rule; the paper's MAE beside):\n")
    add("| selection area | " + " | ".join(SHARES.values()) + " | paper's MAE |")
    add("| --- | " + " | ".join("---" for _ in SHARES) + " | --- |")
    for n, e in sel.items():
        add(f"| {n} | " + " | ".join(
            f"{100 * max(curve_error(e, c, 'rule_' + r) or 0.0 for c in CURVES):.1f}"
            for r in SHARES) + f" | {100 * (worst_error(e, 'mae')[0] or 0.0):.1f} |")
    add("")
    add("Each half's own factor gets the linear range as right as the shared one, but it makes"
        " one zone stiffer and the other softer, so that one saturates early and the other"
        " late; the shared factor keeps the paper's balance of the zones. On the deep wide"
        " notch (1.2/0.45/0.1) every rule, and the paper's MAE, misses 10%: the notch reaches"
        " the split line, so one zone is two separate pieces, which no semi-ellipse is (a"
        " limit of MAE's assimilation, not of the rules).\n")


def _pc(v: float) -> str:
    return f"{100 * v:+.1f}%"


def _causes(add: Callable[[str], None], d: dict[str, Any]) -> None:
    """Write the three causes of the paper's MAE's errors with the numbers that show them."""
    def dev(name: str, m: str, key: str) -> float:
        co = d[name]["coefficients"]
        return float(co[m][key] / co["exact"][key] - 1)

    def worst(name: str, m: str) -> str:
        w, c = worst_error(d[name], m)
        return f"{_f(None if w is None else 100 * w)} ({c})"

    floor = worst("ellipse 2/3 (Hertz)", "mae")
    add("Worst curve errors below are in % of mu N, the curve in brackets. FastSim's own"
        f" floor, on the Hertzian ellipse, is {floor} for MAE (which is Kalker's FastSim"
        f" there) and {worst('ellipse 2/3 (Hertz)', 'fastrip')} for FaStrip.\n")
    add("1. **Two joined semi-ellipses interact elastically**: MAE sums independent halves."
        f" C~23 is {_pc(dev('semi-ellipses 5/1', 'mae', 'C23'))} on the 5/1 semi-ellipses and"
        f" {_pc(dev('semi-ellipses 0.1/1', 'mae', 'C23'))} on the 0.1/1 ones (FaStrip"
        f" {_pc(dev('semi-ellipses 5/1', 'fastrip', 'C23'))} and"
        f" {_pc(dev('semi-ellipses 0.1/1', 'fastrip', 'C23'))}, the equivalent ellipse"
        f" {_pc(dev('semi-ellipses 5/1', 'ellipse', 'C23'))} and"
        f" {_pc(dev('semi-ellipses 0.1/1', 'ellipse', 'C23'))}). On the new areas whose"
        " halves differ: the egg (halves along x, which MAE's split along y does not see)"
        f" C~23 {_pc(dev('egg', 'mae', 'C23'))}, the profile-gap patch in the"
        f" transition C~23 {_pc(dev(f'profile gap {1e3 * samples.PROFILE_SHIFTS[1]:+.1f} mm', 'mae', 'C23'))}."  # noqa: E501
        f" Worst curves on the 5/1 semi-ellipses: MAE {worst('semi-ellipses 5/1', 'mae')},"
        f" FaStrip {worst('semi-ellipses 5/1', 'fastrip')}, ellipse"
        f" {worst('semi-ellipses 5/1', 'ellipse')}. *Calibrated MAE* (rule 1, pair factors):"
        f" C~23 {_pc(dev('semi-ellipses 5/1', 'mae_calibrated', 'C23'))} and"
        f" {_pc(dev('semi-ellipses 0.1/1', 'mae_calibrated', 'C23'))}, worst curves"
        f" {worst('semi-ellipses 5/1', 'mae_calibrated')} and"
        f" {worst('semi-ellipses 0.1/1', 'mae_calibrated')}.")
    add("2. **FastSim restarts behind a gap in a strip**: on the notched ellipse MAE's C~11 is"
        f" {_pc(dev('notched ellipse', 'mae', 'C11'))} and its worst curve error"
        f" {worst('notched ellipse', 'mae')}; FaStrip restarts each strip segment too (C~11"
        f" {_pc(dev('notched ellipse', 'fastrip', 'C11'))}, worst"
        f" {worst('notched ellipse', 'fastrip')}), the equivalent ellipse has no gap at all"
        f" (C~11 {_pc(dev('notched ellipse', 'ellipse', 'C11'))}, worst"
        f" {worst('notched ellipse', 'ellipse')}). None of the new areas has a gap in a"
        " strip: this cause is shown by the notch alone. *Calibrated MAE* (rule 2, the"
        " flexibilities calibrated on the cells with the restart as it is: FastSim then"
        " gives MAE's own coefficients of the zones whatever the gaps): C~11"
        f" {_pc(dev('notched ellipse', 'mae_calibrated', 'C11'))}, worst"
        f" {worst('notched ellipse', 'mae_calibrated')}.")
    add("3. **A zone with a flat edge is no semi-ellipse**: the truncated ellipse gives MAE"
        f" {worst('truncated ellipse', 'mae')} (FaStrip {worst('truncated ellipse', 'fastrip')},"
        f" equivalent ellipse {worst('truncated ellipse', 'ellipse')}); the long narrow"
        " superellipse, flat-sided along its whole length, gives MAE"
        f" {worst('long narrow', 'mae')} with C~23 {_pc(dev('long narrow', 'mae', 'C23'))}"
        f" (FaStrip {worst('long narrow', 'fastrip')}, C~23"
        f" {_pc(dev('long narrow', 'fastrip', 'C23'))}; ellipse"
        f" {worst('long narrow', 'ellipse')}). The evidence says the truncated ellipse's"
        " shortfall is not the zone's shape: MAE's coefficients there are within"
        f" {100 * max(abs(dev('truncated ellipse', 'mae', k)) for k in ('C11', 'C22', 'C23')):.1f}%"  # noqa: E501
        " of exact, and its force under spin misses the exact's full-sliding limit because"
        " FastSim's radial return sends the traction along the trial, off the slip, with"
        " MAE's unequal flexibilities. *Calibrated MAE* (rule 3, the rigid-slip return):"
        f" truncated ellipse {worst('truncated ellipse', 'mae_calibrated')}, long narrow"
        f" {worst('long narrow', 'mae_calibrated')} with C~23"
        f" {_pc(dev('long narrow', 'mae_calibrated', 'C23'))} (section 0).\n")
    add("On the normal-solver patches from tread to flange root the worst curve errors are,"
        " for MAE / FaStrip / the equivalent ellipse: " + "; ".join(
            f"{n[len('profile gap '):]}: {worst(n, 'mae')} / {worst(n, 'fastrip')} /"
            f" {worst(n, 'ellipse')}" for n in d if n.startswith("profile gap"))
        + ".\n")
    add("Beyond the three causes: the **crescent** (strips offset along x, bent by the hollow"
        " tread) is a fourth shortfall, of both strip-wise methods alike: MAE's C~23 is"
        f" {_pc(dev('crescent', 'mae', 'C23'))} and FaStrip's"
        f" {_pc(dev('crescent', 'fastrip', 'C23'))} (the equivalent ellipse"
        f" {_pc(dev('crescent', 'ellipse', 'C23'))}); worst curves MAE"
        f" {worst('crescent', 'mae')}, FaStrip {worst('crescent', 'fastrip')}, ellipse"
        f" {worst('crescent', 'ellipse')}. The cause: spin about the centroid acts on a strip"
        " centred off it as a lateral creepage, and the exact theory carries a lateral"
        " creepage on each strip of an ellipse alike, where FastSim's parabola weights the"
        " long middle strips (which trail here). *Calibrated MAE* (rule 4, the strips'"
        f" offsets): C~23 {_pc(dev('crescent', 'mae_calibrated', 'C23'))}, worst"
        f" {worst('crescent', 'mae_calibrated')}.\n")
    fr = {n: worst_error(d[n], 'fastrip')[0] or 0.0 for n in d}
    spin_worst = sum(1 for n in d if worst_error(d[n], 'fastrip')[1] in ('phi', 'combined'))
    best = {c: sum(1 for n in d if curve_error(d[n], c, "fastrip") is not None
                   and all((curve_error(d[n], c, "fastrip") or 0.0)
                           <= (curve_error(d[n], c, m) or 0.0) for m in BASELINES))
            for c in ("xi", "eta")}
    add(f"FaStrip (as reconstructed here) has the smallest error of the three baselines (the"
        f" paper's MAE, FaStrip, the equivalent ellipse) under pure xi"
        f" on {best['xi']} and under pure eta on {best['eta']} of {len(d)} areas, but its"
        f" worst curve is under spin or combined creepage on {spin_worst}"
        f" of {len(d)} areas (up to {100 * max(fr.values()):.1f}% of mu N).\n")


def _curve_figure(name: str, e: dict[str, Any]) -> None:
    fig, axs = plt.subplots(1, 4, figsize=(15, 3.3))
    mu_n = MU * e["N"]
    for ax, curve in zip(axs, CURVES):
        lv = [p["level"] for p in e[curve]]
        for m, style, label in (("exact", "k-", "exact"), ("mae_calibrated", "C1D-", "calibrated"),
                                ("mae", "C0o--", "MAE"),
                                ("fastrip", "C2^-.", "FaStrip"),
                                ("ellipse", "C3s:", "ellipse"),
                                ("dlm", "C4v:", "DLM"), ("asm", "C5<:", "ASM")):
            for idx, comp in ((0, "Fx"), (1, "Fy")):
                if max(abs(p["exact"][idx]) for p in e[curve]) < 0.02 * mu_n:
                    continue
                if any(p[m] is None for p in e[curve]):
                    continue
                ax.plot(lv, [p[m][idx] / mu_n for p in e[curve]], style, ms=3,
                        alpha=1.0 if idx == 0 else 0.6, label=f"{label} {comp}")
        ax.set(xscale="log", title=f"{name}: {curve}", xlabel="creepage / saturation")
        ax.axhline(0, color="0.8", lw=0.5)
    axs[0].set_ylabel("force / (mu N)")
    axs[-1].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(FIG / _fname(name), dpi=100)
    plt.close(fig)


def main() -> int:
    """Run the wider validation (or only rewrite the report) and write its outputs."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--report-only", action="store_true")
    args = parser.parse_args()
    if args.report_only:
        res = json.loads(DATA.read_text())
        unit = area_makers(False)
        for name, entry in res["areas"].items():
            co = entry["coefficients"]
            if "polach" not in co:  # a run before Polach's coefficients were computed
                c = polach_coefficients(unit[name](ONLINE_CELLS), None)
                co["polach"] = {k: getattr(c, k) for k in ("C11", "C22", "C23", "C13")}
        if "cost_ratio" not in res:
            warm_up()
            res["cost_ratio"] = cost_ratio()
    else:
        res = compute()
    # the grid check of the coefficients the target misses (cheap: the method's only)
    missed = _coefficient_misses(res["areas"])
    if sorted(res.get("coefficient_grid_check") or {}) != missed:
        res["coefficient_grid_check"] = coefficient_grid_check(missed)
    DATA.parent.mkdir(parents=True, exist_ok=True)
    DATA.write_text(json.dumps(res, indent=1))
    report(res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
