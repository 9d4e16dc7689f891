"""Calibrated MAE: the paper's assimilation, with three rules from the exact theory.

The second MAE method (the paper's method, docs/guide_physics.md "MAE", stays as
:mod:`~fastsim_ros.contact.mae` implements it).  It keeps MAE's steps 1-3
(centroid, split, each zone likened to a semi-ellipse) and changes three
things and adds one, each where the validation against the exact solver
showed the paper's method off and why (docs/validation_wider.md):

1. **Joined halves interact** (pair factors).  The zones' half-ellipse
   coefficients ``c11, c22, c23`` are scaled so that their MAE sum is the
   pair's exact coefficient, from the pair factors of the zones'
   semi-ellipses (:mod:`~fastsim_ros.contact.pairs`, tabulated with the
   exact solver on pairs other than the validation's; :func:`zone_coefficients`);
   1 for two equal halves, so an ellipse is Kalker's.
2. **FastSim reproduces the zones' coefficients on the real cells**
   (calibrated flexibilities).  The paper's ``L = 4a/(3 G c11)`` makes
   FastSim reproduce a zone's coefficients only if the zone *is* a
   semi-ellipse.  Behind a gap in a strip (a notch) FastSim restarts from
   zero traction and a zone with a flat edge holds other strip lengths, so
   the paper's flexibilities give 9% less ``C~11`` on the notched ellipse
   than MAE's own coefficients.  Here each zone's flexibilities come from
   the sweep's own integrals over that zone's cells, with FastSim's
   discretisation (first step half a cell, ``phi x`` at each step's
   middle): ``D1 = sum d dA``, ``d`` the distance a cell's traction has
   grown over from its segment's front face; ``D3 = sum s3 dA``, ``s3`` the
   sum of ``(x_mid - x_c) h`` over those steps; ``D4 = |sum (y - y_s) d dA|``.
   In full adhesion zone ``i`` then carries ``Fx = -(xi/L1) D1``, and
   ``L1 = D1 / (G A' c11)``, ``L2 = D1 / (G A' c22)``, ``L3 = D3 / (G A'^1.5
   c23)``, ``L4 = D4 / (G A'^1.5 c13)`` (``A' = 2 A_i / pi``, the pair-factored
   ``c``) make FastSim give exactly MAE's generalised coefficients, on any
   grid; on a semi-ellipse (continuous) they are the paper's.  Where a
   zone's ``D3 <= 0`` (its strips all behind the centroid) the paper's
   ``L3`` is kept.
3. **A slipping cell slips along its slip** (the rigid-slip return,
   :func:`~fastsim_ros.contact.rules.rigid_slip_return`): FastSim's radial
   return puts a slipping cell's traction along ``w/L``, not along the slip;
   with MAE's unequal ``L1``, ``L2``, ``L3``, ``L4`` that turns the force in
   sliding off the rigid slip's direction (the paper's MAE: 18.6% of mu N
   off under spin on the truncated ellipse, the exact force's full-sliding
   limit missed by 40%).  Here the traction is opposite to the cell's slip
   with ``u = L tau`` (``L1``, ``L2``) and the true rigid slip at the step's
   middle.

4. **A bent zone's strips are offset** (rule 4, :func:`offset_c23`): spin
   about the centroid acts on a strip centred off it as a lateral creepage,
   which adds to the zone's ``c23`` where the strips are bent (the paper's
   MAE is 31% low in C~23 on the crescent of a hollow tread); offsets in
   proportion to the chord (an egg) do nothing.

Assumptions (besides MAE's): FastSim's local flexibility, one set per zone;
the zones couple as the equal-area pair of their ``a/b`` would; the
couplings ``c12``, ``c21`` are left out, as in the paper.
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import SplitRule
from fastsim_ros.contact.coefficients import CreepCoefficients, coefficients_of_solver
from fastsim_ros.contact.equivalent import equivalent_ellipse, reduce_slope
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.fastsim import StripFlexibility, fastsim, sweep_integrals
from fastsim_ros.contact.friction import FrictionLaw
from fastsim_ros.contact.knee import KneeFactors, interpolate
from fastsim_ros.contact.lobes import gap_split, strip_loads
from fastsim_ros.contact.mae import (DEFAULT_SPLIT, MaeGeometry, MaeResult, Zone,
                                     ZoneFlexibility, ZonePair, blended_flexibility,
                                     row_extents, split_geometries,
                                     strip_flexibility, sweep_point, zone_flexibility)
from fastsim_ros.contact.pairs import PAIR_NAMES, PairFactors
from fastsim_ros.contact.rules import chord_bend_offset
from fastsim_ros.contact.tables import CoefficientTable
from fastsim_ros.contact.traction import Tractions, resultants

FloatArray = NDArray[np.float64]


PairShare = Literal["shared", "zone"]
#: the calibrated MAE's four rules by name (``without=`` leaves some out: the validation's
#: leave-one-out check of each rule; the compiled path has every rule)
RULES = ("pairs", "calibration", "rigid_slip", "bend")


def _check_without(without: tuple[str, ...]) -> None:
    for name in without:
        if name not in RULES:
            raise ValueError(f"unknown rule {name!r}: the rules are {RULES}")


def zone_coefficients(area: GridArea, geometry: MaeGeometry, table: CoefficientTable,
                      pairs: PairFactors, *, share: PairShare = "shared",
                      without: tuple[str, ...] = ()) -> tuple[dict[str, float] | None,
                                                              dict[str, float] | None]:
    """Return each zone's ``c11, c22, c23, c13``: pair interaction (rule 1), strip offsets (4).

    The pair factors give each half's share of the joined pair's force; their
    sum over the zones, ``C~q = sum w_i^p c_q(g_i) k_q(g_i, g_j)`` (``p`` =
    1 for 11, 22, 1.5 for 23, MAE's eq. 7 weights), is the pair's exact
    coefficient, and it is shared by the zones in the proportion of the lone
    halves: ``c_q,i = c_q(g_i) K_q`` with ``K_q = C~q / sum w_i^p c_q(g_i)``.
    Why not each half its own factor: that gets the linear range as right,
    but it makes one zone stiffer and the other softer, so one saturates too
    early and the other too late: on the pairs 4/0.7 and 7/1.3 (the
    selection areas of ``scripts/validate_wider.py``, not validation areas)
    the worst curve error was 12.1 and 17.0% of mu N with each half's own
    factor, 3.9 and 6.2% with the shared one, 7.8 and 7.3% without any.
    ``c13``, a difference of the zones' terms, takes each zone's own factor.
    ``share="zone"``: each half its own factor (the alternative, kept for
    the validation's comparison; the compiled path has the shared rule
    only).  Then :func:`offset_c23` (rule 4).  ``None`` for an empty zone;
    with the other zone empty the lone (pair) values stand.  ``without``:
    rules left out (``"pairs"``: every factor 1; ``"bend"``: no rule 4).
    """
    if share not in ("shared", "zone"):
        raise ValueError(f"share must be 'shared' or 'zone', got {share!r}")
    _check_without(without)
    if "pairs" in without:
        pairs = PairFactors(pairs.nu, np.log(np.array([0.05, 20.0])),
                            np.ones((len(PAIR_NAMES), 2, 2)))
    paired = _paired_coefficients(geometry, table, pairs, share)
    if "bend" in without:
        return paired
    lower = area.y < geometry.y_s
    c1, c2 = (None if c is None else offset_c23(area, geometry, zone, rows, c)
              for c, zone, rows in zip(paired, (geometry.zone1, geometry.zone2),
                                       (lower, ~lower)))
    return c1, c2


def _paired_coefficients(
        geometry: MaeGeometry, table: CoefficientTable, pairs: PairFactors,
        share: PairShare) -> tuple[dict[str, float] | None, dict[str, float] | None]:
    """Return the zones' coefficients with rule 1 of :func:`zone_coefficients` only."""
    zones = (geometry.zone1, geometry.zone2)
    if zones[0].empty or zones[1].empty:
        return tuple(None if z.empty else {n: table.half(z.a_over_b)[n] for n in PAIR_NAMES}
                     for z in zones)  # type: ignore[return-value]
    w = geometry.weights
    lone = [table.half(z.a_over_b) for z in zones]
    k = [pairs.factors(zones[0].a_over_b, zones[1].a_over_b),
         pairs.factors(zones[1].a_over_b, zones[0].a_over_b)]
    if share == "zone":
        return tuple({n: lone[i][n] * k[i][n] for n in PAIR_NAMES}  # type: ignore[return-value]
                     for i in range(2))
    out = [{"c13": lone[i]["c13"] * k[i]["c13"]} for i in range(2)]
    for name, power in (("c11", 1.0), ("c22", 1.0), ("c23", 1.5)):
        alone = sum(w[i] ** power * lone[i][name] for i in range(2))
        joined = sum(w[i] ** power * lone[i][name] * k[i][name] for i in range(2))
        for i in range(2):
            out[i][name] = lone[i][name] * (joined / alone)
    return out[0], out[1]


def offset_c23(area: GridArea, geometry: MaeGeometry, zone: Zone, rows: NDArray[np.bool_],
               c: dict[str, float]) -> dict[str, float]:
    """Return the zone's coefficients with ``c23`` for the bend of its strips (rule 4).

    MAE likens a zone to a semi-ellipse whose strips are centred on ``x_c``.
    A crescent's are not (a hollow tread bends the patch: its horns lead):
    spin about ``S`` then also acts on strip ``j`` as a lateral creepage
    ``phi (x_j - x_c)``, ``x_j`` the strip's centre, and the lateral force
    of that creepage adds to the zone's ``c23``: ``c23 -> c23 + c22
    offset/sqrt(A')`` (``A' = 2 A_i/pi``), ``offset`` the bend's part of
    the strips' mean centre less the centroid
    (:func:`~fastsim_ros.contact.rules.chord_bend_offset`: centres that
    move in proportion to the chord, as an egg's, do not count, the exact
    theory shows them doing nothing), where it is positive (the horns
    lead).  For a straight zone (every ellipse and semi-ellipse) nothing
    changes.

    Evidence (docs/validation_wider.md, section 6): the first form (every
    offset counted, each strip once) took the crescent's C~23 from -12.4%
    to -1.7% but put eggs whose longer half trails up to 0.16 above the
    exact value (C~23 0.91); counting the bend alone brings the eggs within
    0.04 and keeps the crescents (no parameter fitted).  Why a bend whose
    horns trail is left out: the rule acts through the zone's spin
    flexibility (rule 2 calibrates ``L3`` to ``c23``), and lowering ``c23``
    by a third or more makes ``L3`` so large that the spin's lateral traction
    builds too slowly along every strip: on a crescent whose horns trail
    (bend -1.5, a/b 0.35) its C~23 came right (within 0.03 of exact) but the
    lateral force under spin halved at moderate spin (10.8% of mu N off,
    5.7% without the rule; the paper's MAE 8.3%), while raising ``c23`` (the
    horns leading) left every curve as it was (within 0.3 point of mu N on
    the six crescents) and the linear range right.  The lateral force of a
    trailing bend is a redistribution over the strips, which one flexibility
    per zone cannot carry: this rule does not try.
    """
    count, first, last = row_extents(area.mask & rows[:, None])
    offset = chord_bend_offset(count, first, last, 0, area.ny, area.dx)
    out = dict(c)
    out["c23"] = c["c23"] + c["c22"] * max(offset, 0.0) / math.sqrt(2.0 * zone.area / math.pi)
    return out


def calibrated_zone_flexibility(area: GridArea, geometry: MaeGeometry, zone: Zone,
                                lower: bool, c: dict[str, float], table: CoefficientTable,
                                shear_modulus: float, d: FloatArray,
                                s3: FloatArray) -> ZoneFlexibility:
    """Return the zone's ``L1 .. L4`` (m/Pa): FastSim then gives ``c`` on its cells (rule 2)."""
    rows = (area.y < geometry.y_s) if lower else ~(area.y < geometry.y_s)
    cells = area.mask & rows[:, None]
    da = area.cell_area
    d1 = float(d[cells].sum()) * da
    d3 = float(s3[cells].sum()) * da
    d4 = abs(float(((area.y - geometry.y_s)[:, None] * d)[cells].sum())) * da
    ab = 2.0 * zone.area / math.pi
    g = shear_modulus
    if d3 > 0.0:
        l3 = d3 / (g * ab**1.5 * c["c23"])
    else:
        # no calibration possible: the semi-ellipse's (the paper's) formula, with the factored c23
        l3 = zone_flexibility(zone, table, g).l3 * table.half(zone.a_over_b)["c23"] / c["c23"]
    l4 = d4 / (g * ab**1.5 * c["c13"]) if c["c13"] > 0.0 else math.inf
    return ZoneFlexibility(d1 / (g * ab * c["c11"]), d1 / (g * ab * c["c22"]), l3, l4)


def paper_zone_flexibility(zone: Zone, c: dict[str, float],
                           shear_modulus: float) -> ZoneFlexibility:
    """Return the paper's ``L1 .. L4`` of the zone's semi-ellipse for coefficients ``c``.

    :func:`~fastsim_ros.contact.mae.zone_flexibility`'s formulas with the
    method's (pair-factored, bent) ``c`` in place of the table's: rule 2 left
    out (the leave-one-out check).
    """
    a, b, g = zone.a_eq, zone.b_eq, shear_modulus
    l4 = math.sqrt(a * b) / (2.0 * g * c["c13"]) if c["c13"] > 0.0 else math.inf
    return ZoneFlexibility(4.0 * a / (3.0 * g * c["c11"]), 4.0 * a / (3.0 * g * c["c22"]),
                           math.pi * a**1.5 / (8.0 * g * math.sqrt(b) * c["c23"]), l4)


def calibrated_flexibilities(area: GridArea, geometry: MaeGeometry, table: CoefficientTable,
                             pairs: PairFactors, shear_modulus: float, *,
                             share: PairShare = "shared",
                             without: tuple[str, ...] = ()) -> ZonePair:
    """Return both zones' calibrated flexibilities (``None`` for an empty zone).

    ``without``: rules left out (:func:`zone_coefficients`'; ``"calibration"``:
    the paper's flexibilities of the zones' semi-ellipses, :func:`paper_zone_flexibility`).
    """
    c1, c2 = zone_coefficients(area, geometry, table, pairs, share=share, without=without)
    if "calibration" in without:
        return tuple(None if c is None else paper_zone_flexibility(z, c, shear_modulus)
                     for c, z in zip((c1, c2), (geometry.zone1, geometry.zone2))
                     )  # type: ignore[return-value]
    d, s3 = sweep_integrals(area, geometry.x_c)
    z1 = None if c1 is None else calibrated_zone_flexibility(
        area, geometry, geometry.zone1, True, c1, table, shear_modulus, d, s3)
    z2 = None if c2 is None else calibrated_zone_flexibility(
        area, geometry, geometry.zone2, False, c2, table, shear_modulus, d, s3)
    return z1, z2


def mae_calibrated_fastsim(area: GridArea, xi: float, eta: float, phi: float, *,
                           bound: FloatArray, table: CoefficientTable, pairs: PairFactors,
                           shear_modulus: float, reference: tuple[float, float] = (0.0, 0.0),
                           rule: SplitRule = DEFAULT_SPLIT, friction: FrictionLaw | None = None,
                           speed: float | None = None, share: PairShare = "shared",
                           without: tuple[str, ...] = (),
                           knee: KneeFactors | None = None) -> MaeResult:
    """Solve the calibrated MAE + FastSim; arguments as :func:`.mae.mae_fastsim`.

    ``pairs``: the pair factors at the table's ``nu``
    (:func:`~fastsim_ros.contact.pairs.pair_factors`); ``share``:
    :func:`zone_coefficients`'; ``without``: rules left out (:data:`RULES`;
    ``"rigid_slip"``: FastSim's radial return); ``knee``: FastSim's knee
    corrected strip by strip with these factors (:func:`strip_knee`).
    """
    if friction is not None and friction.reduces_slope:
        # the modified FastSim (equivalent.reduce_slope), as in mae.mae_fastsim
        red = reduce_slope(area, xi, eta, phi, friction, speed, table=table,
                           shear_modulus=shear_modulus)
        xi, eta, phi, friction, speed = red.xi, red.eta, red.phi, red.friction, None
        bound = bound * red.mu_ratio
    q = np.empty(area.ny)
    strip_loads(area.pressure, q)
    m, w = gap_split(q)
    if w < 1.0:  # separate contact regions (fastsim_ros.contact.lobes)
        try:
            parts = [_whole(GridArea(area.x0, area.y0 + lo * area.dy, area.dx, area.dy,
                                     area.pressure[lo:hi]), xi, eta, phi,
                            bound=bound[lo:hi], table=table, pairs=pairs,
                            shear_modulus=shear_modulus, reference=reference, rule=rule,
                            friction=friction, speed=speed, share=share, without=without,
                            knee=knee)
                     for lo, hi in ((0, m), (m, area.ny))]
        except InvalidInputError:  # a region the tables do not hold: the patch whole
            parts = []
        if parts:
            return _blend(area, parts, w, xi, eta, phi, bound=bound, table=table, pairs=pairs,
                          shear_modulus=shear_modulus, reference=reference, rule=rule,
                          friction=friction, speed=speed, share=share, without=without,
                          knee=knee)
    return _whole(area, xi, eta, phi, bound=bound, table=table, pairs=pairs,
                  shear_modulus=shear_modulus, reference=reference, rule=rule,
                  friction=friction, speed=speed, share=share, without=without, knee=knee)


def _blend(area: GridArea, parts: list[MaeResult], w: float, xi: float, eta: float,
           phi: float, **options: Any) -> MaeResult:
    """Return the regions' solves ``parts`` (stacked along ``y``) blended with the whole's.

    ``w``: the whole patch's weight (:func:`fastsim_ros.contact.lobes.gap_split`).
    """
    tau_x = np.concatenate([r.traction.tau_x for r in parts])
    tau_y = np.concatenate([r.traction.tau_y for r in parts])
    slip = np.concatenate([r.traction.slip for r in parts])
    fx, fy, mz = (sum(r.fx for r in parts), sum(r.fy for r in parts),
                  sum(r.mz for r in parts))
    first = parts[0]
    if w > 0.0:
        whole = _whole(area, xi, eta, phi, **options)
        t = whole.traction
        fx = w * whole.fx + (1.0 - w) * fx
        fy = w * whole.fy + (1.0 - w) * fy
        mz = w * whole.mz + (1.0 - w) * mz
        tau_x = w * t.tau_x + (1.0 - w) * tau_x
        tau_y = w * t.tau_y + (1.0 - w) * tau_y
        if w >= 0.5:
            slip = t.slip
            first = whole
    return MaeResult(fx, fy, mz, Tractions(tau_x, tau_y, slip, fx, fy, mz), first.geometry,
                     first.flexibility)


def _whole(area: GridArea, xi: float, eta: float, phi: float, *,
           bound: FloatArray, table: CoefficientTable, pairs: PairFactors,
           shear_modulus: float, reference: tuple[float, float], rule: SplitRule,
           friction: FrictionLaw | None, speed: float | None, share: PairShare,
           without: tuple[str, ...], knee: KneeFactors | None) -> MaeResult:
    """:func:`mae_calibrated_fastsim` on the patch whole (its slope reduction applied)."""
    geometries = split_geometries(area, rule)
    zone_pairs = [calibrated_flexibilities(area, g, table, pairs, shear_modulus, share=share,
                                           without=without) for g, _ in geometries]
    flex: StripFlexibility = blended_flexibility([(strip_flexibility(area, g, z), w)
                                                  for (g, w), z in zip(geometries, zone_pairs)])
    res = fastsim(area, xi, eta, phi, bound=bound, flexibility=flex,
                  sweep_point=sweep_point(geometries), reference=reference,
                  friction=friction, speed=speed,
                  slip_rule="radial" if "rigid_slip" in without else "rigid_slip")
    if knee is not None:
        full_adhesion = fastsim(area, xi, eta, phi, bound=np.where(area.mask, np.inf, 0.0),
                                flexibility=flex, sweep_point=sweep_point(geometries),
                                reference=reference)
        res = strip_knee(area, res, full_adhesion, bound, knee, reference)
    return MaeResult(res.fx, res.fy, res.mz, res, geometries[0][0], zone_pairs[0])


def strip_knee(area: GridArea, solved: Tractions, full_adhesion: Tractions, bound: FloatArray,
               knee: KneeFactors, reference: tuple[float, float]) -> Tractions:
    """Return ``solved`` with each strip's tractions times its knee factor.

    :mod:`~fastsim_ros.contact.knee` strip by strip: strip ``j`` (a row of
    cells along the rolling direction) carries in full adhesion the force
    ``F_lin,j`` (``full_adhesion``: the same march without a bound) and
    the bound ``mu N_j`` (``bound`` summed), so it stands at ``s_j =
    |F_lin,j| / (mu N_j)`` of its saturation; its tractions are multiplied by
    ``kappa(s_j)`` at the patch's equivalent ellipse's ``a/b`` and the
    share ``F_lin,x^2 / |F_lin|^2``, capped so that no strip carries more
    than its bound (a strip in full slip keeps ``mu N_j``).  On an ellipse every strip stands at
    the patch's ``s`` (FastSim's strip force in adhesion and the strip's
    load both go as its chord squared) and the factor is the tabulated one;
    on another shape (a long narrow tread patch, a flange root) each strip
    reads the knee at its own ``s_j``: measured against the exact theory,
    that halves the default method's worst error near zero shift and
    through the flange (``docs/validation_accuracy.md``).  Assumptions: the
    ellipse's knee serves every strip (the strips of an ellipse are at one
    ``s``); the tables hold no spin (spin enters through ``F_lin,j``).
    The compiled path: :func:`fastsim_ros.contact.kernels.strip_knee`.
    """
    ellipse = equivalent_ellipse(area)
    log_aspect = math.log(ellipse.a / ellipse.b)
    lin_x = full_adhesion.tau_x.sum(axis=1)
    lin_y = full_adhesion.tau_y.sum(axis=1)
    bound_sum = np.where(area.mask, bound, 0.0).sum(axis=1)
    own_x = solved.tau_x.sum(axis=1)
    own_y = solved.tau_y.sum(axis=1)
    kappa = np.ones(area.ny)
    for j in range(area.ny):
        l2 = lin_x[j] ** 2 + lin_y[j] ** 2
        if l2 > 0.0 and bound_sum[j] > 0.0:
            kappa[j] = interpolate(knee.log_aspect, knee.s, knee.kappa,
                                   math.sqrt(l2) / bound_sum[j], log_aspect,
                                   lin_x[j] ** 2 / l2)[0]
            # a strip carries at most its bound summed (mu N_j): in full slip FastSim's force
            f2 = own_x[j] ** 2 + own_y[j] ** 2
            if kappa[j] > 1.0 and kappa[j] ** 2 * f2 > bound_sum[j] ** 2:
                kappa[j] = bound_sum[j] / math.sqrt(f2)
    tx = solved.tau_x * kappa[:, None]
    ty = solved.tau_y * kappa[:, None]
    return Tractions(tx, ty, solved.slip, *resultants(area, tx, ty, reference))


def mae_calibrated_coefficients(area: GridArea, table: CoefficientTable, pairs: PairFactors, *,
                                reference: tuple[float, float] = (0.0, 0.0),
                                rule: SplitRule = DEFAULT_SPLIT,
                                without: tuple[str, ...] = ()) -> CreepCoefficients:
    """Return the calibrated method's generalised coefficients in full adhesion (no bound)."""
    unbounded = np.where(area.mask, np.inf, 0.0)
    return coefficients_of_solver(
        area.area, lambda xi, eta, phi: mae_calibrated_fastsim(
            area, xi, eta, phi, bound=unbounded, table=table, pairs=pairs, shear_modulus=1.0,
            reference=reference, rule=rule, without=without), reference=reference)
