#!/usr/bin/env python3
"""Research: the spin's longitudinal slip in FastSim's adhesion, and the coupling dFx/dphi.

A prototype, not the package's method.  In FastSim a strip's traction grows
through its adhesion zone at ``d tau_x / dx = -(xi/L1 - phi (y - y_s)/Ls)``:
Kalker's FastSim takes ``Ls = L3``, the calibrated MAE (the default,
:mod:`fastsim_ros.contact.mae_calibrated`) takes each zone's ``L4``, set so
that the zone carries its half-ellipse's ``c13``.  Either way the spin's
longitudinal slip ``-phi y`` is stiffer than a longitudinal creepage of the
same size by ``L1/Ls`` (1.23 to 1.58 for the default on ellipses of a/b 0.5
to 2), so under ``xi`` with spin the strips' ``Fx`` changes sign short of the
rigid slip's pole ``y = xi/phi``.  The exact theory's strips have a ratio
too: under unit spin a strip at ``y`` carries ``-r_s y`` times its force
under unit ``xi`` (full adhesion), ``r_s`` nearly the same on every strip,
a function of ``a/b`` alone, 1 in the limit of strip theory (``a/b -> 0``).

Variants of the default (the numpy reference, strip knee factors on):

* ``L4`` (the default);
* ``pole``: ``Ls = L1 / r_s(a/b)`` in each zone (``r_s`` at the zone's
  ``a/b``, measured here on Hertzian ellipses with the exact solver): the
  spin's longitudinal slip acts on each strip as the exact theory's
  strips do; the zones' ``c13`` are then FastSim's, not the tables';
* ``pole+C13``: ``pole`` about a point moved along ``y`` by the same
  amount in both zones, so that the patch's ``dFx/dphi`` in full adhesion
  is the default's again.

Then why neither ``L4`` nor ``pole`` carries the coupling ``dFx/dphi`` of a
tread patch: the exact theory's ``dFx/dphi`` is the first moment about the
reference of its own strips' stiffness under ``xi`` (``-sum_j y_j
K_j``, ``K_j`` a strip's ``Fx`` per unit ``xi``, full adhesion), and that
distribution over the strips is not FastSim's (chord squared) nor any one
power of the chord.

Cases: Hertzian ellipses (a/b 0.5, 1, 2, 40 cells) under ``xi`` with spin
at 0.3 to 1 of the translational force's share, ``s`` 0.6 to 5 of the
saturation; the tread patches of ``scripts/validate_accuracy.py`` (its spin
cases at -0.476 mm and its three creepage levels at -0.404, -0.440 and
-0.496 mm); CONTACT's Manchester A-2.2 poses (the package's patches, 0.2 mm
cells).  Errors: the larger of ``|Fx - Fx_exact|``, ``|Fy - Fy_exact|`` in %
of ``mu N`` against :func:`fastsim_ros.contact.exact.coulomb` on the same
grid.

Findings (the run's tables): ``pole`` takes the worst error on the
ellipses from 7.4, 6.0 and 4.1% of mu N (a/b 0.5, 1, 2) to 2.2, 2.6 and
2.3%, and the left tread patch under ``xi`` 1e-3 with spin 0.5 from 4.4 to
1.5%; but it makes the patch's ``dFx/dphi`` FastSim's first moment, which
on A-2.2's centred pose is 0.09 of the exact one (pose 1: 0.7 -> 4.4% of mu
N), and the left tread under pure spin goes from 1.7 to 3.2%.  ``pole+C13``
keeps the coupling and loses the knee of the tread's right patch (1.9 ->
3.4%) and A-2.2 pose 2 (2.2 -> 2.4%).  The coupling: the exact ``dFx/dphi``
is the first moment of the exact strips' ``K_j`` within 1-3% on every
patch where it is large (A-2.2 poses 1, 2 and 11, the tread's right
patch), and that moment from ``K_j`` proportional to the chord to the power
1, 1.5 or 2 (FastSim's) is 0.97-2.1, 0.43-1.35 and -0.02-0.70 of it: the
share of each strip in the patch's stiffness is the half-space's, which the
strips' own chords do not give.  Nor does the half-space's share alone make
the method: FastSim with the exact strips' stiffness (``L1_j``, ``L2_j`` so
that every strip carries its exact full-adhesion force; an oracle costing
the exact linear solves) takes the right tread's linear range from 2.3 to
1.3% of mu N (spin as ``pole``) but the left's from 0.4 to 2.7%, leaves
``xi`` 1e-3 with spin 0.5 at 4.2-6.5%, and A-2.2's worst at 2.4%.  On the
left patch at ``xi`` 4e-4 FastSim's own error (without the knee factors)
grows with the exact strips' stiffness from 5.0 to 6.2% of mu N, and the
strip knee factors, tabulated on ellipses with FastSim's strips, take out
about the same 3.6 points as before: the knee belongs to the strips'
stiffness it was tabulated with.  The tread's worst case, ``xi`` 1e-3 with
spin 0.5 on the right patch (4.6%, all in ``Fy``), is the spin's lateral
force shared over the strips: with each strip's ``L3`` set so that it
carries the exact strip's lateral force under spin in full adhesion (an
oracle), it is 2.2%, and with ``pole`` too every spin case of the tread is
within 2.5%; the exact strips' lateral force under spin is 0.58 to 1.87
times the default's over the right patch's strips of 2.6-6.2 mm chord.

Usage: ``python scripts/research_spin_pole.py
[--part all|ratio|ellipses|wheelset|a22|coupling|strips|spin_strips]``.
About 2 minutes.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Iterator
import contextlib
from contextlib import contextmanager
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from fastsim_ros.cli.wheelset import solve_pose  # noqa: E402
from fastsim_ros.contact import exact, samples  # noqa: E402
from fastsim_ros.contact import mae_calibrated as mc  # noqa: E402
from fastsim_ros.contact.area import GridArea  # noqa: E402
from fastsim_ros.contact.fastsim import StripFlexibility, sweep_integrals  # noqa: E402
from fastsim_ros.contact.fastsim import traction_bound  # noqa: E402
from fastsim_ros.contact.knee import knee_factors  # noqa: E402
from fastsim_ros.contact.mae import MaeGeometry, ZonePair  # noqa: E402
from fastsim_ros.contact.pairs import pair_factors  # noqa: E402
from fastsim_ros.contact.tables import coefficient_table  # noqa: E402
from fastsim_ros.geometry import benchmark as bm  # noqa: E402

import validate_accuracy as va  # noqa: E402  (the wheelset's patches and spin cases)
import validate_profiles as vp  # noqa: E402  (A-2.2's poses as the wheelset command's)
from research_linear_response import run_parts  # noqa: E402

MU, NU, G = va.MU, va.NU, va.G
assert (bm.MU, bm.POISSON) == (MU, NU), "A-2.2's friction and nu are the wheelset's"
LOAD = 1.0e4
VARIANTS = ("L4", "pole", "pole+C13")
ASPECTS = (0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0)
TABLE, PAIRS, KNEE = coefficient_table(NU), pair_factors(NU), knee_factors(NU)
_RATIO: list[np.ndarray] = []
#: the default method's strip flexibilities (every variant starts from them)
_DEFAULT_FLEXIBILITY = mc.strip_flexibility


def ellipse(aspect: float, cells: int = 40) -> GridArea:
    """Return a Hertzian ellipse of ``a/b = aspect`` (area 2e-5 m^2) on ``cells`` x ``cells``."""
    return samples.semi_ellipses_patch(aspect, aspect, cells=cells, scale=0.008, load=LOAD)


def spin_ratio(area: GridArea) -> tuple[float, float, float]:
    """Return the exact strips' ``r_s``: mean, least and largest over ``0.2 b < |y| < 0.8 b``."""
    op = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=G)
    by_xi = exact.full_adhesion(area, 1e-6, 0.0, 0.0, nu=NU, shear_modulus=G, operator=op)
    by_phi = exact.full_adhesion(area, 0.0, 0.0, 1e-3, nu=NU, shear_modulus=G, operator=op)
    kx, kp = by_xi.tau_x.sum(axis=1) / 1e-6, by_phi.tau_x.sum(axis=1) / 1e-3
    y = area.y
    b = float(np.abs(y[area.mask.any(axis=1)]).max())
    mid = (np.abs(y) > 0.2 * b) & (np.abs(y) < 0.8 * b)
    r = -kp[mid] / (y[mid] * kx[mid])
    return float(r.mean()), float(r.min()), float(r.max())


def ratio_table() -> np.ndarray:
    """Return ``r_s`` at :data:`ASPECTS` (40-cell ellipses), computed once."""
    if not _RATIO:
        _RATIO.append(np.array([spin_ratio(ellipse(g))[0] for g in ASPECTS]))
    return _RATIO[0]


def r_s(aspect: float) -> float:
    """Return ``r_s`` at ``a/b = aspect``, interpolated in ``log(a/b)``."""
    return float(np.interp(math.log(aspect), np.log(ASPECTS), ratio_table()))


def pole_flexibility(variant: str, area: GridArea, geometry: MaeGeometry,
                     zones: ZonePair) -> StripFlexibility:
    """Return the default's strip flexibilities with ``Ls`` of ``variant``."""
    flex = _DEFAULT_FLEXIBILITY(area, geometry, zones)
    if variant == "L4":
        return flex
    lower = area.y < geometry.y_s
    y_rel = area.y - geometry.y_s
    ratio = np.zeros(area.ny)
    l1 = np.full(area.ny, math.inf)
    d, _ = sweep_integrals(area, geometry.x_c)
    target = pole = stiffness = 0.0
    for zone, z, rows in ((geometry.zone1, zones[0], lower), (geometry.zone2, zones[1], ~lower)):
        if z is None:
            continue
        cells = area.mask & rows[:, None]
        moment = float((y_rel[:, None] * d)[cells].sum()) * area.cell_area
        r = r_s(zone.a_over_b)
        target += moment / z.l4 if math.isfinite(z.l4) else 0.0
        pole += r * moment / z.l1
        stiffness += float(d[cells].sum()) * area.cell_area / z.l1
        ratio[rows] = r
        l1[rows] = z.l1
    # pole+C13: rate_x = (xi - r phi (y - y_s) + k phi) / L1, k so that sum over the zones
    # of the spin's Fx in full adhesion is the default's
    shift = (pole - target) / stiffness if variant == "pole+C13" and stiffness > 0 else 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        spin = l1 * y_rel / (ratio * y_rel - shift)
    spin = np.where(np.isfinite(flex.l1) & np.isfinite(spin), spin, flex.spin)
    return StripFlexibility(flex.l1, flex.l2, flex.l3, spin)


Flexibility = Callable[[GridArea, MaeGeometry, ZonePair], StripFlexibility]


@contextmanager
def flexibility_of(flexibility: Flexibility) -> Iterator[None]:
    """Solve the default method with its strips' flexibilities from ``flexibility``."""
    mc.strip_flexibility = flexibility
    try:
        with np.errstate(divide="ignore"):  # strips out of contact: 1/L summed to 0
            yield
    finally:
        mc.strip_flexibility = _DEFAULT_FLEXIBILITY


def variant_of(name: str) -> contextlib.AbstractContextManager[None]:
    """Solve with the default method's ``Ls`` replaced by ``name``'s (:func:`pole_flexibility`)."""
    return flexibility_of(lambda area, g, z: pole_flexibility(name, area, g, z))


def zone_ratios(area: GridArea, geometry: MaeGeometry) -> np.ndarray:
    """Return each strip's ``r_s``: its zone's (1 for a strip of an empty zone)."""
    lower = area.y < geometry.y_s
    ratio = np.ones(area.ny)
    for zone, rows in ((geometry.zone1, lower), (geometry.zone2, ~lower)):
        if not zone.empty:
            ratio[rows] = r_s(zone.a_over_b)
    return ratio


def solve(area: GridArea, creep: tuple[float, float, float],
          shear_modulus: float) -> tuple[float, float]:
    """Return the default's (numpy reference, strip knee factors) ``Fx, Fy`` (N)."""
    r = mc.mae_calibrated_fastsim(area, *creep, bound=traction_bound(area, MU), table=TABLE,
                                  pairs=PAIRS, shear_modulus=shear_modulus, knee=KNEE)
    return r.fx, r.fy


def errors(cases: list[tuple[GridArea, tuple[float, float, float], float]], *,
           shear_modulus: float = G) -> dict[str, list[float]]:
    """Return, per variant, each case's error in % of mu N; a case: area, creepages, N."""
    exacts = [exact.coulomb(a, *c, mu=MU, nu=NU, shear_modulus=shear_modulus)
              for a, c, _ in cases]
    out: dict[str, list[float]] = {}
    for v in VARIANTS:
        with variant_of(v):
            out[v] = [100 * max(abs(f - e) for f, e in
                                zip(solve(a, c, shear_modulus), (ex.fx, ex.fy))) / (MU * n)
                      for (a, c, n), ex in zip(cases, exacts)]
    return out


def row(label: str, errs: dict[str, list[float]]) -> str:
    """Return a table row: each variant's worst of ``errs``."""
    return f"| {label} | " + " | ".join(f"{max(errs[v]):.2f}" for v in VARIANTS) + " |"


def header(first: str, names: tuple[str, ...] = VARIANTS) -> None:
    """Print a table's header: ``first``, then ``names`` (the variants)."""
    print(f"| {first} | " + " | ".join(names) + " |")
    print("| --- | " + " | ".join("---" for _ in names) + " |")


def part_ratio() -> None:
    """Print r_s on ellipses beside the default's L1/L4."""
    print("\n## The exact strips' spin-to-xi ratio r_s, and the default's L1/L4 (ellipses)\n")
    print("| a/b | r_s, 40 cells (least, largest) | r_s, 64 cells | default's L1/L4 |")
    print("| --- | --- | --- | --- |")
    for g, r in zip(ASPECTS, ratio_table()):
        area = ellipse(g)
        fine = spin_ratio(ellipse(g, 64))[0]
        lo, hi = spin_ratio(area)[1:]
        geometry = mc.split_geometries(area, mc.DEFAULT_SPLIT)[0][0]
        z1, _ = mc.calibrated_flexibilities(area, geometry, TABLE, PAIRS, G)
        print(f"| {g} | {r:.3f} ({lo:.3f}, {hi:.3f}) | {fine:.3f} | "
              f"{z1.l1 / z1.l4 if z1 is not None else math.nan:.3f} |", flush=True)


def part_ellipses() -> None:
    """Print the variants' worst errors on ellipses under xi with spin."""
    print("\n## Hertzian ellipses under xi with spin: worst error, % of mu N\n")
    header("a/b (s 0.6-5, spin's share 0.3-1)")
    for g in (0.5, 1.0, 2.0):
        area = ellipse(g)
        op = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=G)
        kx = exact.full_adhesion(area, 1e-6, 0, 0, nu=NU, shear_modulus=G, operator=op).fx / 1e-6
        ky = exact.full_adhesion(area, 0, 0, 1e-3, nu=NU, shear_modulus=G, operator=op).fy / 1e-3
        cases = [(area, (s * MU * LOAD / abs(kx), 0.0, share * s * MU * LOAD / abs(ky)), LOAD)
                 for s in (0.6, 1.0, 1.5, 2.5, 5.0) for share in (0.3, 0.6, 1.0)]
        print(row(str(g), errors(cases)), flush=True)


def part_wheelset() -> None:
    """Print the variants' worst errors on the wheelset's tread patches."""
    print("\n## The default wheelset's tread patches: worst error, % of mu N\n")
    header("cases")
    for wheel in ("right", "left"):
        area, _, n = va.patches(-0.476e-3, va.axle_spin(None))[wheel]
        for creep in ((0.0, 0.0, 0.5), (1e-3, 0.0, 0.5), (0.0, 1e-3, 0.5)):
            print(row(f"{wheel}, -0.476 mm, {creep}", errors([(area, creep, n)])), flush=True)
    for level, xi in va.LEVELS:
        for wheel in ("right", "left"):
            cases = []
            for dy in (-0.404e-3, -0.440e-3, -0.496e-3):
                area, creep, n = va.patches(dy, va.axle_spin(xi))[wheel]
                cases.append((area, creep, n))
            print(row(f"{wheel}, {level}, three shifts", errors(cases)), flush=True)


def a22_patches() -> Iterator[tuple[str, GridArea, tuple[float, float, float], float]]:
    """Yield CONTACT's A-2.2 wheel-poses: label, the package's patch, creepages, N."""
    for side in ("right", "left"):
        for case in bm.a22(side):
            cycle, _ = solve_pose(vp.pose_args(case, vp.DEFAULT), case.dy, case.yaw)
            for o in cycle.outcomes:
                if (o.patch is None or o.creepage is None or o.forces is None
                        or not o.contact.startswith(side)):
                    continue
                p = o.patch
                yield (f"{side} {case.number}", GridArea(p.x0, p.y0, p.dx, p.dy,
                                                         np.array(p.pressure)),
                       (o.creepage.xi, o.creepage.eta, o.creepage.phi), o.forces.n)


def part_a22() -> None:
    """Print the variants' errors on A-2.2's wheel-poses and the worst."""
    print("\n## Manchester A-2.2 (42 wheel-poses, against the exact theory on the same patch)\n")
    header("wheel-pose")
    worst = {v: (0.0, "") for v in VARIANTS}
    for label, area, creep, n in a22_patches():
        errs = errors([(area, creep, n)], shear_modulus=bm.SHEAR_MODULUS)
        for v in VARIANTS:
            if errs[v][0] > worst[v][0]:
                worst[v] = (errs[v][0], label)
        if label.split()[1] in ("1", "2", "3", "11"):
            print(row(label, errs), flush=True)
    print("| worst (where) | " + " | ".join(f"{e:.2f} ({w})" for e, w in worst.values()) + " |")


def part_coupling() -> None:
    """Print the exact dFx/dphi against the strips' moments and the variants'."""
    print("\n## The exact dFx/dphi against the first moment of the strips' stiffness\n")
    print("| patch | exact dFx/dphi (N m) | over -sum y K_j (exact K_j) | over the moment of "
          "K_j ~ chord^1, ^1.5, ^2 | " + ", ".join(VARIANTS) + " over exact |")
    print("| --- | --- | --- | --- | --- |")
    cases = [(label, area) for label, area, _, _ in a22_patches()
             if label.split()[1] in ("1", "2", "3", "11")]
    cases += [(f"tread {w}, -0.476 mm", va.patches(-0.476e-3, va.axle_spin(None))[w][0])
              for w in ("right", "left")]
    for label, area in cases:
        op = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=G)
        by_xi = exact.full_adhesion(area, 1e-7, 0, 0, nu=NU, shear_modulus=G, operator=op)
        by_phi = exact.full_adhesion(area, 0, 0, 1e-5, nu=NU, shear_modulus=G, operator=op)
        k = by_xi.tau_x.sum(axis=1) * area.cell_area / 1e-7
        coupling = by_phi.fx / 1e-5
        chord = area.mask.sum(axis=1) * area.dx
        powers = []
        for p in (1.0, 1.5, 2.0):
            kp = chord**p * k.sum() / (chord**p).sum()
            powers.append(f"{-(area.y * kp).sum() / coupling:.2f}")
        methods = []
        for v in VARIANTS:
            with variant_of(v):
                f = mc.mae_calibrated_fastsim(area, 0.0, 0.0, 1e-5,
                                              bound=np.where(area.mask, np.inf, 0.0),
                                              table=TABLE, pairs=PAIRS, shear_modulus=G)
            methods.append(f"{f.fx / 1e-5 / coupling:.2f}")
        print(f"| {label} | {coupling:+.3e} | {coupling / -(area.y * k).sum():.3f} | "
              + ", ".join(powers) + " | " + ", ".join(methods) + " |", flush=True)


@contextmanager
def exact_strips(area: GridArea, shear_modulus: float, *, spin: str) -> Iterator[None]:
    """Solve with each strip's ``L1``, ``L2`` from the exact strips' stiffness on ``area``.

    ``L1_j = D_j / K_j`` (``D_j`` the strip's sweep integral ``sum d dA``,
    ``K_j`` its ``-Fx`` per unit ``xi`` in the exact theory's full adhesion;
    ``L2_j`` alike under ``eta``), so that FastSim's strips carry the exact
    strips' forces in full adhesion; ``spin``: ``"L4"`` keeps the zones'
    ``Ls``, ``"pole"`` takes ``Ls = L1_j / r_s``.  An oracle: it costs the
    exact linear solves of the patch.
    """
    op = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=shear_modulus)
    k = [-getattr(exact.full_adhesion(area, *c, nu=NU, shear_modulus=shear_modulus,
                                      operator=op), t).sum(axis=1) * area.cell_area / 1e-7
         for c, t in (((1e-7, 0.0, 0.0), "tau_x"), ((0.0, 1e-7, 0.0), "tau_y"))]

    def flexibility(part: GridArea, geometry: MaeGeometry, zones: ZonePair) -> StripFlexibility:
        flex = _DEFAULT_FLEXIBILITY(part, geometry, zones)
        if part.ny != area.ny:  # a region of a split patch: left as the default has it
            return flex
        d, _ = sweep_integrals(part, geometry.x_c)
        dj = (d * part.mask).sum(axis=1) * part.cell_area
        with np.errstate(divide="ignore", invalid="ignore"):
            l1, l2 = (np.where((kk > 0) & (dj > 0), dj / kk, math.inf) for kk in k)
        if spin == "L4":
            return StripFlexibility(l1, l2, flex.l3, flex.spin)
        return StripFlexibility(l1, l2, flex.l3, l1 / zone_ratios(part, geometry))

    with flexibility_of(flexibility):
        yield


def part_strips() -> None:
    """Print the default against FastSim with the exact strips' stiffness (an oracle)."""
    print("\n## FastSim with the exact strips' stiffness (L1_j, L2_j; the strip knee factors "
          "as the default's): worst error, % of mu N\n")
    header("case", ("default", "exact strips, L4", "exact strips, pole"))

    def three(area: GridArea, creep: tuple[float, float, float], n: float,
              g: float) -> list[float]:
        ex = exact.coulomb(area, *creep, mu=MU, nu=NU, shear_modulus=g)
        out = []
        for spin in (None, "L4", "pole"):
            if spin is None:
                fx, fy = solve(area, creep, g)
            else:
                with exact_strips(area, g, spin=spin):
                    fx, fy = solve(area, creep, g)
            out.append(100 * max(abs(fx - ex.fx), abs(fy - ex.fy)) / (MU * n))
        return out

    def line(label: str, errs: list[float]) -> None:
        print(f"| {label} | " + " | ".join(f"{e:.2f}" for e in errs) + " |", flush=True)

    for wheel in ("right", "left"):
        area, _, n = va.patches(-0.476e-3, va.axle_spin(None))[wheel]
        for creep in ((0.0, 0.0, 0.5), (1e-3, 0.0, 0.5)):
            line(f"{wheel}, -0.476 mm, {creep}", three(area, creep, n, G))
    for level, xi in va.LEVELS[:2]:
        for wheel in ("right", "left"):
            worst = np.zeros(3)
            for dy in (-0.404e-3, -0.440e-3, -0.496e-3):
                area, creep, n = va.patches(dy, va.axle_spin(xi))[wheel]
                worst = np.maximum(worst, three(area, creep, n, G))
            line(f"{wheel}, {level}, three shifts", list(worst))
    worst, where = np.zeros(3), [""] * 3
    for label, area, creep, n in a22_patches():
        errs = three(area, creep, n, bm.SHEAR_MODULUS)
        for i, e in enumerate(errs):
            if e > worst[i]:
                worst[i], where[i] = e, label
    print("| A-2.2, worst (where) | " + " | ".join(f"{e:.2f} ({w})" for e, w in zip(worst, where))
          + " |")


@contextmanager
def exact_spin_strips(area: GridArea, shear_modulus: float, *, pole: bool) -> Iterator[None]:
    """Solve with each strip's ``L3`` from the exact strips' lateral force under spin.

    In full adhesion FastSim's strip ``j`` carries, under unit spin about
    the reference, ``Fy_j = -(x_c/L2_j) D_j - S3_j/L3_j`` (spin about ``S``
    plus the lateral creepage ``phi x_c`` it adds there; ``D_j``, ``S3_j``
    the strip's sweep integrals); ``L3_j`` is set so that this is the exact
    strip's (where that gives a positive ``L3_j``; elsewhere the zone's).
    ``pole``: also ``Ls = L1 / r_s``.  An oracle: it costs the exact
    linear solve of the patch.
    """
    by_phi = exact.full_adhesion(area, 0.0, 0.0, 1e-5, nu=NU, shear_modulus=shear_modulus)
    fy = by_phi.tau_y.sum(axis=1) * area.cell_area / 1e-5

    def flexibility(part: GridArea, geometry: MaeGeometry, zones: ZonePair) -> StripFlexibility:
        flex = _DEFAULT_FLEXIBILITY(part, geometry, zones)
        if part.ny != area.ny:  # a region of a split patch: left as the default has it
            return flex
        d, s3 = sweep_integrals(part, geometry.x_c)
        dj = (d * part.mask).sum(axis=1) * part.cell_area
        s3j = (s3 * part.mask).sum(axis=1) * part.cell_area
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = (-fy - geometry.x_c * dj / flex.l2) / s3j
            l3 = np.where(np.isfinite(inv) & (inv > 0) & part.mask.any(axis=1), 1.0 / inv,
                          flex.l3)
        spin = flex.l1 / zone_ratios(part, geometry) if pole else flex.spin
        return StripFlexibility(flex.l1, flex.l2, l3, spin)

    with flexibility_of(flexibility):
        yield


def part_spin_strips() -> None:
    """Print the tread's spin cases with the exact strips' lateral force under spin."""
    print("\n## The exact strips' lateral force under spin (L3_j, an oracle): error, % of mu N"
          " (Fx, Fy)\n")
    header("case", ("default", "exact strips' L3", "and pole"))
    shares = []
    for wheel in ("right", "left"):
        area, _, n = va.patches(-0.476e-3, va.axle_spin(None))[wheel]
        for creep in ((0.0, 0.0, 0.5), (1e-3, 0.0, 0.5), (0.0, 1e-3, 0.5), (1e-3, 0.0, 2.0)):
            ex = exact.coulomb(area, *creep, mu=MU, nu=NU, shear_modulus=G)
            cells = []
            for pole in (None, False, True):
                if pole is None:
                    fx, fy = solve(area, creep, G)
                else:
                    with exact_spin_strips(area, G, pole=pole):
                        fx, fy = solve(area, creep, G)
                cells.append(f"{100 * (fx - ex.fx) / (MU * n):+.2f}, "
                             f"{100 * (fy - ex.fy) / (MU * n):+.2f}")
            print(f"| {wheel}, {creep} | " + " | ".join(cells) + " |", flush=True)
        by_phi = exact.full_adhesion(area, 0.0, 0.0, 1e-5, nu=NU, shear_modulus=G)
        lin = mc.mae_calibrated_fastsim(area, 0.0, 0.0, 1e-5,
                                        bound=np.where(area.mask, np.inf, 0.0), table=TABLE,
                                        pairs=PAIRS, shear_modulus=G)
        chord = area.mask.sum(axis=1) * area.dx
        inner = chord > 2.5e-3  # strips away from the patch's thin ends
        share = by_phi.tau_y.sum(axis=1)[inner] / lin.traction.tau_y.sum(axis=1)[inner]
        shares.append(f"{wheel} patch: the exact strips' lateral force under unit spin over "
                      f"the default's, strips of chord {1e3 * chord[inner].min():.1f}-"
                      f"{1e3 * chord[inner].max():.1f} mm: {share.min():.2f} to "
                      f"{share.max():.2f}")
    print("\n" + "\n".join(shares))


def main() -> int:
    """Run the ``--part`` chosen (``all``: every part, in order); print the run's time."""
    return run_parts(__doc__.splitlines()[0], {
        "ratio": part_ratio, "ellipses": part_ellipses, "wheelset": part_wheelset,
        "a22": part_a22, "coupling": part_coupling, "strips": part_strips,
        "spin_strips": part_spin_strips})


if __name__ == "__main__":
    sys.exit(main())
