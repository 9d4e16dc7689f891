"""MAE: assimilation of a non-elliptical contact area to two semi-ellipses.

Alonso & Giménez, Vehicle System Dynamics 45(4):341-357, 2007, as fixed by
docs/guide_physics.md "MAE".  Assumptions: the area's principal axes are ``x`` and
``y`` (wheel-rail contact); each of the two zones on either side of a
lateral split line behaves, in the tangential problem, like the semi-ellipse
with the same mean-square edge coordinates and the same area; the coupling
coefficients ``c12``, ``c21`` are left out of the FastSim pass (a few percent
of ``c11``; the coefficients report them).

Steps: centroid; split line ``y = y_s``; mean-square semi-axes of each zone
(eq. 6); half-ellipse coefficients from the package's tables; generalised
coefficients about the split point ``S = (x_c, y_s)`` (eq. 7, weighted by the
zones' areas) and about the reference point; per-zone flexibilities ``L1 ..
L4`` (section 3.2.2); FastSim zone by zone with the creepages at ``S``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import SplitRule, check_split_rule
from fastsim_ros.contact.coefficients import CreepCoefficients, coefficients_of_solver
from fastsim_ros.contact.equivalent import reduce_slope
from fastsim_ros.contact.fastsim import StripFlexibility, fastsim
from fastsim_ros.contact.friction import FrictionLaw
from fastsim_ros.contact.rules import face_blend, widest_position
from fastsim_ros.contact.traction import Tractions
from fastsim_ros.contact.tables import CoefficientTable

FloatArray = NDArray[np.float64]
DEFAULT_SPLIT: SplitRule = "auto"


@dataclass(frozen=True)
class Zone:
    """One zone of the split and its semi-ellipse.

    ``area`` (m^2); ``a``, ``b``: mean-square semi-axes (m, eq. 6);
    ``a_over_b``; ``a_eq``, ``b_eq``: the semi-ellipse of ratio ``a_over_b``
    and the zone's area, ``pi a_eq b_eq / 2 = area`` (m).  An empty zone has
    zero area and ``nan`` axes.
    """

    area: float
    a: float
    b: float
    a_over_b: float
    a_eq: float
    b_eq: float

    @property
    def empty(self) -> bool:
        """Whether the zone holds no cell."""
        return self.area <= 0.0


@dataclass(frozen=True)
class MaeGeometry:
    """Centroid ``(x_c, y_c)``, split line ``y_s`` (m), and the two zones (1: ``y < y_s``)."""

    x_c: float
    y_c: float
    y_s: float
    rule: SplitRule
    zone1: Zone
    zone2: Zone
    area: float

    @property
    def weights(self) -> tuple[float, float]:
        """``w_i = 2 A_i / A``."""
        return 2.0 * self.zone1.area / self.area, 2.0 * self.zone2.area / self.area


def row_extents(mask: NDArray[np.bool_]) -> tuple[NDArray[np.int_], NDArray[np.int_],
                                                  NDArray[np.int_]]:
    """Return per row: cells in contact, index of the first and of the last contact cell."""
    count = mask.sum(axis=1)
    nx = mask.shape[1]
    first = np.where(count > 0, np.argmax(mask, axis=1), 0)
    last = np.where(count > 0, nx - 1 - np.argmax(mask[:, ::-1], axis=1), -1)
    return count, first, last


def split_face(area: GridArea, rule: SplitRule = DEFAULT_SPLIT) -> int:
    """Index ``f`` of the cell face ``y = y0 + (f - 1/2) dy`` the split runs along.

    The lower face of :func:`split_blend`'s pair (the whole split where its
    ``t`` is 0).
    """
    return split_blend(area, rule)[0]


def split_blend(area: GridArea, rule: SplitRule = DEFAULT_SPLIT) -> tuple[int, float]:
    """Return ``(f, t)``: the rule's split as faces ``f``, ``f + 1`` weighted ``1 - t``, ``t``.

    ``auto`` (the default): the weighted centre of the strips with a chord
    near the longest (:func:`~fastsim_ros.contact.rules.widest_position`):
    the paper's widest strip, made a continuous function of the patch (an
    argmax over a staircase jumps between strips millimetres apart as a row
    of cells comes or goes, and a threshold between two rules jumps where
    it is crossed: docs/validation_split.md).  ``centroid``: the centroid
    (the paper's text).  Both lie between two faces in general
    (:func:`~fastsim_ros.contact.rules.face_blend`), and the MAE methods
    blend those two splits (:func:`split_geometries`).  ``widest_strip``:
    the seed's discrete rule, kept for the paper's Table 5 (it finds the
    join line of two semi-ellipses exactly), not continuous: through the
    band of strips with the longest chord (of several bands apart, the
    widest, then the one nearest the centroid, so that the mirror image of
    an area in ``y`` splits at the mirrored face; two alike at one
    distance: the centroid's), its middle face, unless the chord drops by
    over a cell at each end more on one side of the band than on the other
    (a jump: the join line of two semi-ellipses), where the split takes
    the band's face on that side; a line through the middle of a strip is
    a tie, ``t = 1/2``.
    """
    return _split(row_extents(area.mask)[0], rule)


def split_tie(area: GridArea, rule: SplitRule = DEFAULT_SPLIT) -> bool:
    """Tell whether the rule's split line runs through the middle of a strip (``t = 1/2``).

    Then the faces on either side of that strip serve alike (a patch
    symmetric in ``y`` with an odd number of strips: its centre line is no
    cell face), and the MAE methods weigh both splits alike: one of them
    alone gave an ellipse ``C~13`` of -0.03 and a yaw moment from nothing on
    a centred wheelset.
    """
    return split_blend(area, rule)[1] == 0.5


def _split(count: NDArray[np.int_], rule: SplitRule) -> tuple[int, float]:
    """Return :func:`split_blend`'s ``(f, t)`` from the strips' counts."""
    if rule == "auto":
        return face_blend(count, widest_position(count))
    ny = count.size
    total = int(count.sum())
    moment = int((count * np.arange(ny)).sum())
    yc = moment / total
    if rule == "centroid":
        return face_blend(count, yc + 0.5)
    check_split_rule(rule)
    # the band of strips sharing the longest chord (a staircase ellipse has several); of
    # several such bands apart, the widest, then the one nearest the centroid (a mirror
    # image in y splits at the mirrored face); two alike at one distance: the centroid's
    rows = np.flatnonzero(count == count.max())
    bands = np.split(rows, np.flatnonzero(np.diff(rows) > 1) + 1)
    width = max(len(b) for b in bands)
    widest = [b for b in bands if len(b) == width]
    distance = [abs(0.5 * (b[0] + b[-1]) - yc) for b in widest]
    nearest = min(distance)
    if sum(1 for d in distance if abs(d - nearest) <= 1e-9) > 1:
        return _split(count, "centroid")
    band = widest[distance.index(nearest)]
    j0, j1 = int(band[0]), int(band[-1])
    below = int(count[j0 - 1]) if j0 > 0 else 0
    above = int(count[j1 + 1]) if j1 + 1 < ny else 0
    # chords of centred shapes change by two cells at a time (one at each end)
    drop_below, drop_above = count[j0] - below, count[j0] - above
    if drop_below > drop_above + 2:
        return j0, 0.0
    if drop_above > drop_below + 2:
        return j1 + 1, 0.0
    width = j1 - j0 + 1
    if width % 2 == 0:
        return j0 + width // 2, 0.0
    middle = j0 + width // 2
    # an odd band: the face of its middle strip nearer the centroid; the centroid at the
    # strip's centre: both faces alike (the lower one given)
    if moment == middle * total:
        return middle, 0.5
    return (middle + 1 if yc > middle else middle), 0.0


def _zone(area: GridArea, rows: NDArray[np.bool_], x_c: float, y_s: float,
          lower: bool) -> Zone:
    mask = area.mask & rows[:, None]
    n = int(np.count_nonzero(mask))
    if n == 0:
        return Zone(0.0, math.nan, math.nan, math.nan, math.nan, math.nan)
    count, first, last = row_extents(mask)
    used = count > 0
    x = area.x
    lead = x[last[used]] + 0.5 * area.dx - x_c
    trail = x[first[used]] - 0.5 * area.dx - x_c
    ve_x = float(np.mean(0.5 * (lead**2 + trail**2)))
    cols = mask.any(axis=0)
    y = area.y
    if lower:
        j_out = np.argmax(mask, axis=0)[cols]
        edge = y_s - (y[j_out] - 0.5 * area.dy)
    else:
        j_out = area.ny - 1 - np.argmax(mask[::-1, :], axis=0)[cols]
        edge = y[j_out] + 0.5 * area.dy - y_s
    ve_y = float(np.mean(edge**2))
    # a semi-ellipse's mean-square edge coordinates are 2/3 of its squared semi-axes
    a, b = math.sqrt(1.5 * ve_x), math.sqrt(1.5 * ve_y)
    zone_area = n * area.cell_area
    g = a / b
    a_eq = math.sqrt(2.0 * zone_area * g / math.pi)
    return Zone(zone_area, a, b, g, a_eq, a_eq / g)


def mae_geometry(area: GridArea, rule: SplitRule = DEFAULT_SPLIT) -> MaeGeometry:
    """MAE steps 1-3: centroid, split line and the two zones' semi-ellipses."""
    return _geometry_at(area, rule, split_face(area, rule))


def _geometry_at(area: GridArea, rule: SplitRule, f: int) -> MaeGeometry:
    """Return :func:`mae_geometry` with the split along face ``f``."""
    mask = area.mask
    n = np.count_nonzero(mask)
    jj, ii = np.nonzero(mask)
    x_c = float(area.x[ii].sum() / n)
    y_c = float(area.y[jj].sum() / n)
    y_s = float(area.y0 + (f - 0.5) * area.dy)
    rows = np.arange(area.ny) < f
    return MaeGeometry(x_c, y_c, y_s, rule, _zone(area, rows, x_c, y_s, True),
                       _zone(area, ~rows, x_c, y_s, False), area.area)


def split_geometries(area: GridArea,
                     rule: SplitRule = DEFAULT_SPLIT) -> tuple[tuple[MaeGeometry, float], ...]:
    """Return the geometries of the rule's split faces with their weights (:func:`split_blend`).

    One face (weight 1), or two (``1 - t`` and ``t``): the MAE methods then
    weigh the two splits' strip stiffnesses (:func:`blended_flexibility`)
    and sweep from the weighted mean of their split lines.
    """
    f, t = _split(row_extents(area.mask)[0], rule)
    if t == 0.0:
        return ((_geometry_at(area, rule, f), 1.0),)
    return (_geometry_at(area, rule, f), 1.0 - t), (_geometry_at(area, rule, f + 1), t)


def blended_flexibility(flexibilities: list[tuple[StripFlexibility, float]]) -> StripFlexibility:
    """Return the strips' flexibilities (m/Pa) over weighted splits: stiffness ``1/L`` weighted.

    A strip's traction in adhesion is its rigid slip over ``L``: weighting
    ``1/L`` makes the full-adhesion coefficients ``C~11``, ``C~22``,
    ``C~23`` the splits' weighted mean exactly.
    """
    if len(flexibilities) == 1:
        return flexibilities[0][0]
    return StripFlexibility(*(1.0 / sum(w / getattr(f, name) for f, w in flexibilities)
                              for name in ("l1", "l2", "l3", "spin")))


def sweep_point(geometries: tuple[tuple[MaeGeometry, float], ...]) -> tuple[float, float]:
    """Return the sweep point ``S = (x_c, y_s)`` (m): the splits' weighted mean ``y_s``."""
    return (geometries[0][0].x_c, sum(w * g.y_s for g, w in geometries))


def mae_area_coefficients(area: GridArea, table: CoefficientTable, *,
                          reference: tuple[float, float] = (0.0, 0.0),
                          rule: SplitRule = DEFAULT_SPLIT) -> CreepCoefficients:
    """Return MAE's coefficients of an area (:func:`mae_coefficients` of its split).

    Where the split lies between two faces (:func:`split_blend`) the two
    splits' coefficients, weighted: continuous in the patch, and on a patch
    symmetric in ``y`` (a tie) ``C~13 = 0`` on any grid.
    """
    each = [(mae_coefficients(g, table, reference), w) for g, w in split_geometries(area, rule)]
    if len(each) == 1:
        return each[0][0]
    mean = {name: sum(w * getattr(c, name) for c, w in each)
            for name in ("C11", "C12", "C13", "C21", "C22", "C23", "C31", "C32", "C33")}
    first = each[0][0]
    return CreepCoefficients(**mean, area=first.area, reference=first.reference)


def mae_coefficients(geometry: MaeGeometry, table: CoefficientTable,
                     reference: tuple[float, float] = (0.0, 0.0)) -> CreepCoefficients:
    """MAE steps 4-5: generalised coefficients ``C~ij`` about ``reference`` (m).

    About ``S``: ``C~11 = sum w_i c11(g_i)``, ``C~22`` likewise,
    ``C~23 = sum w_i^1.5 c23(g_i)``, ``C~13 = w1^1.5 c13(g1) - w2^1.5 c13(g2)``,
    ``C~12 = w2 c12(g2) - w1 c12(g1)`` (and ``C~21``), from the mirror signs
    of docs/guide_physics.md "MAE"; then moved to ``reference`` by the rigid-slip identity.
    ``C~3j`` are not given by MAE: reported as ``nan``.
    """
    w = geometry.weights
    c = {k: 0.0 for k in ("11", "12", "13", "21", "22", "23")}
    for zone, wi, sign in ((geometry.zone1, w[0], -1.0), (geometry.zone2, w[1], 1.0)):
        if zone.empty:
            continue
        h = table.half(zone.a_over_b)
        c["11"] += wi * h["c11"]
        c["22"] += wi * h["c22"]
        c["23"] += wi**1.5 * h["c23"]
        c["12"] += sign * wi * h["c12"]
        c["21"] += sign * wi * h["c21"]
        c["13"] -= sign * wi**1.5 * h["c13"]
    root = math.sqrt(geometry.area / math.pi)
    dxp = reference[0] - geometry.x_c
    dyp = reference[1] - geometry.y_s
    c13 = c["13"] + (c["11"] * dyp - c["12"] * dxp) / root
    c23 = c["23"] + (c["21"] * dyp - c["22"] * dxp) / root
    return CreepCoefficients(C11=c["11"], C12=c["12"], C13=c13, C21=c["21"], C22=c["22"],
                             C23=c23, C31=math.nan, C32=math.nan, C33=math.nan,
                             area=geometry.area, reference=reference)


@dataclass(frozen=True)
class ZoneFlexibility:
    """Flexibilities ``L1 .. L4`` (m/Pa) of one zone (the physics guide); ``L4`` may be ``inf``."""

    l1: float
    l2: float
    l3: float
    l4: float


def zone_flexibility(zone: Zone, table: CoefficientTable,
                     shear_modulus: float) -> ZoneFlexibility:
    """Return flexibilities with which FastSim reproduces the zone's half-ellipse in adhesion.

    ``L1 = 4a/(3 G c11)``, ``L2 = 4a/(3 G c22)``,
    ``L3 = pi a^1.5/(8 G sqrt(b) c23)``, ``L4 = sqrt(a b)/(2 G c13)``, with the
    area-matched semi-axes ``a``, ``b``.
    """
    h = table.half(zone.a_over_b)
    a, b, g = zone.a_eq, zone.b_eq, shear_modulus
    l4 = math.sqrt(a * b) / (2.0 * g * h["c13"]) if h["c13"] > 0.0 else math.inf
    return ZoneFlexibility(4.0 * a / (3.0 * g * h["c11"]), 4.0 * a / (3.0 * g * h["c22"]),
                           math.pi * a**1.5 / (8.0 * g * math.sqrt(b) * h["c23"]), l4)


ZonePair = tuple[ZoneFlexibility | None, ZoneFlexibility | None]


def zone_flexibilities(geometry: MaeGeometry, table: CoefficientTable,
                       shear_modulus: float) -> ZonePair:
    """Return both zones' flexibilities (``None`` for an empty zone)."""
    z1, z2 = (None if z.empty else zone_flexibility(z, table, shear_modulus)
              for z in (geometry.zone1, geometry.zone2))
    return z1, z2


def strip_flexibility(area: GridArea, geometry: MaeGeometry,
                      zones: ZonePair) -> StripFlexibility:
    """Each strip's ``L1, L2, L3, L4`` from its zone's (:func:`zone_flexibilities`).

    The strips of an empty zone hold no cell in contact; they get an infinite
    flexibility, with which no traction builds.
    """
    lower = area.y < geometry.y_s
    out = {name: np.full(area.ny, math.inf) for name in ("l1", "l2", "l3", "l4")}
    for f, rows in zip(zones, (lower, ~lower)):
        if f is not None:
            for name in out:
                out[name][rows] = getattr(f, name)
    return StripFlexibility(out["l1"], out["l2"], out["l3"], out["l4"])


@dataclass(frozen=True, eq=False)
class MaeResult:
    """MAE + FastSim: forces (N), ``Mz`` (N m) about the reference point, and what made them."""

    fx: float
    fy: float
    mz: float
    traction: Tractions
    geometry: MaeGeometry
    flexibility: ZonePair


def mae_fastsim(area: GridArea, xi: float, eta: float, phi: float, *, bound: FloatArray,
                table: CoefficientTable, shear_modulus: float,
                reference: tuple[float, float] = (0.0, 0.0),
                rule: SplitRule = DEFAULT_SPLIT, friction: FrictionLaw | None = None,
                speed: float | None = None) -> MaeResult:
    """MAE step 7: FastSim zone by zone, creepages about ``reference`` (``phi`` in 1/m).

    ``bound``: traction bound ``g`` (Pa) on the area's cells
    (:func:`fastsim_ros.contact.fastsim.traction_bound`; with a
    slip-dependent ``friction`` law the static one, of its ``mu_s``);
    ``speed``: rolling speed ``|V|`` (m/s) for such a law; ``shear_modulus``:
    combined ``G`` (Pa); ``table``: coefficients at the material's ``nu``.
    A law's slope reduction is applied as
    :func:`~fastsim_ros.contact.equivalent.reduce_slope` says.
    """
    if friction is not None and friction.reduces_slope:
        # the modified FastSim (equivalent.reduce_slope): creepages times k, friction at the
        # rigid slip velocity, the bound of mu_s scaled to it
        red = reduce_slope(area, xi, eta, phi, friction, speed, table=table,
                           shear_modulus=shear_modulus)
        xi, eta, phi, friction, speed = red.xi, red.eta, red.phi, red.friction, None
        bound = bound * red.mu_ratio
    geometries = split_geometries(area, rule)
    pairs = [zone_flexibilities(g, table, shear_modulus) for g, _ in geometries]
    res = fastsim(area, xi, eta, phi, bound=bound,
                  flexibility=blended_flexibility([(strip_flexibility(area, g, z), w)
                                                   for (g, w), z in zip(geometries, pairs)]),
                  sweep_point=sweep_point(geometries), reference=reference,
                  friction=friction, speed=speed)
    return MaeResult(res.fx, res.fy, res.mz, res, geometries[0][0], pairs[0])


def mae_fastsim_coefficients(area: GridArea, table: CoefficientTable, *,
                             reference: tuple[float, float] = (0.0, 0.0),
                             rule: SplitRule = DEFAULT_SPLIT) -> CreepCoefficients:
    """Return the generalised coefficients of MAE + FastSim in full adhesion (no bound).

    What the pair gives at vanishing creepage, to set beside MAE's own
    coefficients (:func:`mae_coefficients`) and the exact theory's.
    """
    unbounded = np.where(area.mask, np.inf, 0.0)
    return coefficients_of_solver(
        area.area, lambda xi, eta, phi: mae_fastsim(
            area, xi, eta, phi, bound=unbounded, table=table, shear_modulus=1.0,
            reference=reference, rule=rule), reference=reference)
