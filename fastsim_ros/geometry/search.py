"""Contact search: where the undeformed wheel and rail interpenetrate, and each region's reference.

The method is CONTACT's planar approach with the contact locus (user guide
"Identification of contact patches", DISCNS D = 2, "wgt-wgt-2"), in a side
frame (:mod:`~fastsim_ros.geometry.placement`):

1. The contact locus: on each circle of the wheel (a point ``(a, r)`` of
   its profile) the point where the wheel's surface normal has no
   component along the track: only there can the wheel touch a rail that
   does not change along the track.  With the wheel's outward normal
   ``(sin t, -r'(a), -cos t)`` at angle ``t`` from its lowest point (wheel
   axes), the condition ``e_x . R n = 0`` is ``R00 sin t - R02 cos t = R01
   r'``, solved in closed form.  A yawed wheelset has its locus off ``x =
   0``: on the flange by millimetres (Wang/Vollebregt's contact locus).
2. The vertical gap between the locus and the rail, ``g(y) = z_w(y) -
   z_r(y)``, on a uniform lateral grid (0.3 of the cell size, CONTACT's
   ``fac_dyds``); each run of ``g < 0`` is an interpenetration region.
3. Each region's reference: the centre of the interpenetration area
   weighted by the square of the local depth, the depth along ``x`` taken
   as ``g(y) + (x - x_lc)^2 / (2 R0)`` (CONTACT's ``compute_wgt_center_1d``:
   the weight of a lateral station is ``16/15 pen^2 sqrt(2 R0 pen)``), and
   the contact angle as the mean of the rail's inclination with the same
   weights; the point is put on the rail surface at that ``y``.
4. Regions whose bounding boxes lie within ``d_comb`` and then ``d_sep`` of
   each other, with contact angles within ``a_sep``, are combined into one
   patch (CONTACT combines within ``d_sep`` too but attenuates the
   cross-influence of parts further apart than ``d_comb``; here they are
   one elastic patch); separate regions within ``d_turn`` have their angles
   turned towards their weighted mean (CONTACT's ``turn_cpatch_refangle``).

Assumptions stated: the rail does not vary along the track (prismatic); the
wheel is a body of revolution; the view is vertical in the track frame, so
the locus and the rail must be single-valued in ``y`` there (a profile that
folds back in that view is trimmed to its longest single-valued part).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.geometry.errors import DerailmentError, NoContactError
from fastsim_ros.geometry.placement import Pose, RailSide, WheelSide

FloatArray = NDArray[np.float64]

#: CONTACT's defaults of A-2.2: angle and distances for combining regions (rad, m)
A_SEP, D_SEP, D_COMB = 0.5 * math.pi, 8e-3, 4e-3
#: the lateral step of the vertical gap function, as a share of the cell size
VIEW_STEP_SHARE = 0.3
#: a region this close (m) to the end of a profile has left the part that is described
EDGE_MARGIN = 0.2e-3
#: a wheel touching within this distance (m) of its flange tip rides on the tip's rounding
#: (contact angle under about 10 degrees on S1002): the flange has climbed the rail.  The
#: Manchester benchmark's steepest flange contacts lie 10 mm or more from the tip.
FLANGE_TIP_MARGIN = 2e-3


@dataclass(frozen=True)
class Locus:
    """The wheel's contact locus and the rail on one lateral grid (side frame, m, rad).

    ``y``: uniform lateral positions; ``wheel_z``, ``wheel_x``: height and
    longitudinal position of the locus; ``rail_z``: rail height;
    ``rail_angle``: rail inclination; ``gap``: ``wheel_z - rail_z``
    (``inf`` where either surface is missing); ``wheel_axial``: the wheel
    profile's axial position there.
    """

    y: FloatArray
    wheel_z: FloatArray
    wheel_x: FloatArray
    wheel_axial: FloatArray
    rail_z: FloatArray
    rail_angle: FloatArray
    gap: FloatArray


@dataclass(frozen=True)
class Region:
    """One interpenetration region (or several combined) in the side frame (m, rad).

    ``reference``: ``(x, y, z)`` of CONTACT's weighted reference point (on
    the rail); ``angle``: the contact angle there; ``x_range``, ``y_range``,
    ``z_range``: the extent of the interpenetration (``z`` at the ``y``
    ends, on the rail); ``weight``: the total weight (for combining);
    ``depth``: the largest vertical interpenetration (m);
    ``deepest_axial``: the wheel profile's axial position at the deepest
    point.
    """

    reference: tuple[float, float, float]
    angle: float
    x_range: tuple[float, float]
    y_range: tuple[float, float]
    z_range: tuple[float, float]
    weight: float
    depth: float
    deepest_axial: float


def wheel_locus(wheel: WheelSide, pose: Pose, nominal_radius: float) -> FloatArray:
    """Return the locus points ``(n, 4)``: ``x, y, z`` (side frame) and the axial position.

    ``pose`` is the wheelset's pose in this side's frame.
    """
    r = pose.rotation()
    a_coef, b_coef = r[0, 0], -r[0, 2]
    rho = math.hypot(a_coef, b_coef)
    beta = math.atan2(b_coef, a_coef)
    d = r[0, 1] * wheel.slope
    theta = np.arcsin(np.clip(d / rho, -1.0, 1.0)) - beta
    q = np.stack([wheel.radius * np.sin(theta), wheel.axial, -wheel.radius * np.cos(theta)])
    centre = np.array([0.0, pose.dy, nominal_radius + pose.dz])
    p = centre[:, None] + r @ q
    return np.stack([p[0], p[1], p[2], wheel.axial], axis=1)


def _single_valued(points: FloatArray) -> FloatArray:
    """Keep the longest run of strictly increasing ``y`` (the part a vertical view sees)."""
    up = np.diff(points[:, 1]) > 0.0
    if up.all():
        return points
    best_start, best_len, start = 0, 0, 0
    for i, ok in enumerate(np.append(up, False)):
        if not ok:
            if i + 1 - start > best_len:
                best_start, best_len = start, i + 1 - start
            start = i + 1
    return points[best_start:best_start + best_len]


def vertical_gap(rail: RailSide, wheel: WheelSide, pose: Pose, nominal_radius: float,
                 cell: float) -> Locus:
    """Return the locus and the rail on one uniform lateral grid (CONTACT's 1-d gap function)."""
    locus = _single_valued(wheel_locus(wheel, pose, nominal_radius))
    lo = max(float(rail.y[0]), float(locus[0, 1]))
    hi = min(float(rail.y[-1]), float(locus[-1, 1]))
    if not hi > lo:
        raise NoContactError(f"the wheel and the rail do not overlap laterally (wheel locus "
                             f"{locus[0, 1]:.4f}..{locus[-1, 1]:.4f} m, rail "
                             f"{rail.y[0]:.4f}..{rail.y[-1]:.4f} m)")
    step = VIEW_STEP_SHARE * cell
    n = int(math.floor((hi - lo) / step)) + 1
    y = lo + step * np.arange(n)
    wheel_z = np.interp(y, locus[:, 1], locus[:, 2])
    wheel_x = np.interp(y, locus[:, 1], locus[:, 0])
    wheel_axial = np.interp(y, locus[:, 1], locus[:, 3])
    rail_z = np.interp(y, rail.y, rail.z)
    rail_angle = np.interp(y, rail.y, rail.angle)
    return Locus(np.asarray(y, dtype=np.float64), wheel_z, wheel_x, wheel_axial, rail_z,
                 rail_angle, wheel_z - rail_z)


def _region(locus: Locus, i0: int, i1: int, curvature: float) -> Region:
    """Return the reference and extent of the run ``i0..i1`` (inclusive) of ``gap < 0``."""
    sl = slice(i0, i1 + 1)
    pen = -locus.gap[sl]
    # CONTACT: the depth along x is pen - a t^2 with a = 1/(2 R0); the weight
    # of a station, int (pen - a t^2)^2 dt over |t| < t0 = sqrt(pen/a), is 16/15 pen^2 t0
    t0 = np.sqrt(pen / curvature)
    w = np.maximum(1e-30, 16.0 / 15.0 * pen * pen * t0)
    total = float(w.sum())
    x_ref = float(np.dot(w, locus.wheel_x[sl]) / total)
    y_ref = float(np.dot(w, locus.y[sl]) / total)
    angle = float(np.dot(w, locus.rail_angle[sl]) / total)
    y, g = locus.y, locus.gap

    def crossing(inside: int, outside: int) -> float:
        if outside < 0 or outside >= y.size or not math.isfinite(g[outside]):
            return float(y[inside])
        return float(y[inside] - g[inside] * (y[outside] - y[inside]) / (g[outside] - g[inside]))

    y_sta, y_end = crossing(i0, i0 - 1), crossing(i1, i1 + 1)
    z_sta = float(np.interp(y_sta, locus.y, locus.rail_z))
    z_end = float(np.interp(y_end, locus.y, locus.rail_z))
    x_lc = locus.wheel_x[sl]
    deepest = int(np.argmax(pen))
    return Region(reference=(x_ref, y_ref, float(np.interp(y_ref, locus.y, locus.rail_z))),
                  angle=angle,
                  x_range=(float((x_lc - t0).min()), float((x_lc + t0).max())),
                  y_range=(y_sta, y_end), z_range=(z_sta, z_end),
                  weight=total * float(y[1] - y[0]) if y.size > 1 else total,
                  depth=float(pen[deepest]),
                  deepest_axial=float(locus.wheel_axial[i0 + deepest]))


def _box_distance(a: Region, b: Region) -> float:
    """Return the distance of the regions' bounding boxes (m; CONTACT's ``cpatch_distance``)."""
    dx = max(0.0, a.x_range[0] - b.x_range[1], b.x_range[0] - a.x_range[1])
    if a.y_range[0] > b.y_range[1]:
        dy, dz = a.y_range[0] - b.y_range[1], a.z_range[0] - b.z_range[1]
    elif b.y_range[0] > a.y_range[1]:
        dy, dz = b.y_range[0] - a.y_range[1], b.z_range[0] - a.z_range[1]
    else:
        dy = dz = 0.0
    return math.sqrt(dx * dx + dy * dy + dz * dz)


def merged(a: Region, b: Region) -> Region:
    """Return two regions combined into one (weighted reference, union of extents)."""
    wa, wb = a.weight, b.weight
    total = wa + wb

    def mean(u: float, v: float) -> float:
        return (u * wa + v * wb) / total

    ref = (mean(a.reference[0], b.reference[0]), mean(a.reference[1], b.reference[1]),
           math.nan)
    first, last = (a, b) if a.y_range[0] <= b.y_range[0] else (b, a)
    y_end, z_end = ((a.y_range[1], a.z_range[1]) if a.y_range[1] >= b.y_range[1]
                    else (b.y_range[1], b.z_range[1]))
    deep = a if a.depth >= b.depth else b
    return Region(reference=ref, angle=mean(a.angle, b.angle),
                  x_range=(min(a.x_range[0], b.x_range[0]), max(a.x_range[1], b.x_range[1])),
                  y_range=(first.y_range[0], y_end), z_range=(first.z_range[0], z_end),
                  weight=total, depth=deep.depth, deepest_axial=deep.deepest_axial)


def combine(regions: list[Region], *, a_sep: float = A_SEP, d_sep: float = D_SEP,
            d_comb: float = D_COMB, d_turn: float | None = None) -> list[Region]:
    """Combine regions close together (two passes: ``d_comb``, then ``d_sep``); turn the rest.

    The result is sorted by increasing ``y`` (from the track centre to the
    field side).  The merged reference's ``z`` is NaN: callers put it back
    on the rail (:func:`find_regions`).
    """
    out = list(regions)
    for limit in (d_comb, d_sep):
        i = 0
        while i < len(out):
            j = i + 1
            while j < len(out):
                if (abs(out[i].angle - out[j].angle) <= a_sep
                        and _box_distance(out[i], out[j]) <= limit):
                    out[i] = merged(out[i], out.pop(j))
                else:
                    j += 1
            i += 1
    out.sort(key=lambda r: r.reference[1])
    turn = 2.0 * d_sep - d_comb if d_turn is None else d_turn
    if turn > d_sep and len(out) > 1:
        angles = [r.angle for r in out]
        for k in range(len(out) - 1):
            lo, hi = out[k], out[k + 1]
            dist = math.hypot(hi.y_range[0] - lo.y_range[1], hi.z_range[0] - lo.z_range[1])
            if abs(angles[k] - angles[k + 1]) > a_sep or not d_sep <= dist <= turn:
                continue
            comb = (angles[k] * lo.weight + angles[k + 1] * hi.weight) / (lo.weight + hi.weight)
            fac = (turn - dist) / (turn - d_sep)
            out[k] = _with_angle(out[k], out[k].angle + fac * (comb - angles[k]))
            out[k + 1] = _with_angle(out[k + 1], out[k + 1].angle + fac * (comb - angles[k + 1]))
    return out


def _with_angle(r: Region, angle: float) -> Region:
    return Region(r.reference, angle, r.x_range, r.y_range, r.z_range, r.weight, r.depth,
                  r.deepest_axial)


def find_regions(rail: RailSide, wheel: WheelSide, pose: Pose, nominal_radius: float,
                 cell: float, *, a_sep: float = A_SEP, d_sep: float = D_SEP,
                 d_comb: float = D_COMB) -> tuple[Locus, list[Region]]:
    """Return the gap function and the (combined) interpenetration regions of one side.

    An empty list: the wheel does not touch this rail (a lifted wheel).
    Raises :class:`DerailmentError` when a region reaches the flange's back
    (the flange tip has passed the rail) or the end of either profile.
    """
    locus = vertical_gap(rail, wheel, pose, nominal_radius, cell)
    inside = locus.gap < 0.0
    regions: list[Region] = []
    if inside.any():
        edges = np.flatnonzero(np.diff(np.concatenate([[0], inside.astype(np.int8), [0]])))
        curvature = 0.5 / nominal_radius
        for i0, i1 in zip(edges[0::2], edges[1::2] - 1):
            region = _region(locus, int(i0), int(i1), curvature)
            _check_inside(region, rail, wheel, locus)
            regions.append(region)
    combined = combine(regions, a_sep=a_sep, d_sep=d_sep, d_comb=d_comb)
    placed = []
    for r in combined:
        z = float(np.interp(r.reference[1], rail.y, rail.z))
        placed.append(Region((r.reference[0], r.reference[1], z), r.angle, r.x_range, r.y_range,
                             r.z_range, r.weight, r.depth, r.deepest_axial))
    return locus, placed


def _check_inside(region: Region, rail: RailSide, wheel: WheelSide, locus: Locus) -> None:
    """Refuse a region beyond the flange tip or at the end of a profile (derailment)."""
    if region.deepest_axial <= wheel.flange_tip + FLANGE_TIP_MARGIN:
        distance = (region.deepest_axial - wheel.flange_tip) * 1e3
        raise DerailmentError(f"the wheel touches {distance:.2f} mm from its flange tip: the "
                              "flange has climbed the rail")
    lo_y, hi_y = float(locus.y[0]), float(locus.y[-1])
    if region.y_range[0] <= lo_y + EDGE_MARGIN or region.y_range[1] >= hi_y - EDGE_MARGIN:
        centre_side = region.y_range[0] <= lo_y + EDGE_MARGIN
        where = region.y_range[0] if centre_side else region.y_range[1]
        side = "track-centre" if centre_side else "field"
        raise DerailmentError(f"the contact reaches the {side} end of the profiles at "
                              f"y = {where:.4f} m")
