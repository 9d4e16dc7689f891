"""A contact table: the wheelset's patches precomputed over lateral shift and yaw.

The per-pose path (:class:`~fastsim_ros.geometry.wheelset.Wheelset`) solves
the contact search and the non-Hertzian normal problem for every pose: 20 to
200 ms, far beyond a 1 kHz loop (the target: a pose at most 1 ms median).
A rig's wheelset moves over a few millimetres and milliradians, so the
patches are solved once on a grid of nodes ``(dy, yaw)`` and interpolated:
what multibody codes do with their contact tables (CONTACT's own module 1
solves each case afresh; the table trades that for speed, and
``docs/validation_table.md`` measures the price against both).

Assumptions, each stated because the interpolation rests on it:

1. **Kinematic roll.**  At each node the roll is the one at which both
   rigid wheels touch their rails at one height of the wheelset centre
   (:func:`levelled_roll`); the elastic approaches of the two wheels differ
   by micrometres under unequal loads, which moves the roll by about
   ``1e-5`` rad (a loaded solve's).
2. **Hertz similarity in the load.**  Each node's patches are solved at a
   reference wheel load ``L0``; at a load ``L`` a patch is scaled by
   ``s = (L/L0)^(1/3)`` in its plane, its pressure by ``s`` and its normal
   force by ``s^3`` (exact for a Hertzian contact, close for the
   non-Hertzian ones of a worn tread: the report measures it), about its
   pressure centroid, which stays where the node put it.  With two patches
   on one wheel both scale alike: their shares of the load are the node's.
3. **Blending between nodes.**  A patch at a pose between nodes is the
   weighted blend (bilinear weights in ``dy`` and yaw) of the nodes' matching
   patches: origin (pressure centroid), normal and load blended linearly, the
   pressure field the weighted sum of the members' fields each centred on its
   own centroid (shape interpolation), resampled bilinearly on the blended
   contact plane and trimmed to the blended number of cells in contact.  A
   patch present at only some of the nodes fades in with their weights (a
   flange contact that starts between two nodes grows from zero load).
4. **Events aligned in yaw, the flange's refined in yaw.**  The shift at
   which a flange or gauge corner takes over moves with the yaw; between two
   yaw nodes each column is read at the pose's distance from its own
   take-over (interpolated between the columns), so that the two columns
   blend the same contact.  In the shift the nodes are refined by bisection
   where neighbours differ.  Around a flange's take-over (an event of both
   columns turning the contact angle by 0.5 rad or more: the flange's 0.6-0.7,
   not the gauge corner's 0.4) the yaw is refined too: the
   shifts within 40 um of both columns' take-overs are solved at yaws that
   halve the interval twice (1.25 mrad), a window with a table of its own
   (aligned in the same way between its columns) that the lookup takes for
   the poses in it; at the window's edges, 40 um from the take-overs, the
   grid's blend and the window's differ by what the grid's errs there.
5. **Mirror symmetry.**  With the right wheel and rail the mirror images of
   the left ones and a grid symmetric about ``dy = 0`` and ``yaw = 0``, the
   right wheel's patches at ``(dy, yaw)`` are the left wheel's at ``(-dy,
   -yaw)`` mirrored in ``y``; only the left wheel is solved.

The vertical balance with the creep forces (CONTACT's "vertical force
prescribed") is solved at run time by the caller on the scale ``s^3``
(:meth:`ContactTable.lookup` returns the blended patches at ``s = 1``;
:meth:`TablePatch.scaled` scales them).  Poses outside the grid raise
:class:`TableRangeError` (the node counts ``out_of_table``); a pose next to a
node where the wheel derailed raises
:class:`~fastsim_ros.geometry.errors.DerailmentError`.
"""

from __future__ import annotations

import bisect
import hashlib
import math
import os
import tempfile
import time
import zipfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numba
import numpy as np
from numpy.typing import NDArray

from fastsim_ros.geometry.errors import (DerailmentError, GeometryError, NoContactError,
                                         TableError, TableRangeError)
from fastsim_ros.geometry.placement import Pose
from fastsim_ros.geometry.wheelset import (MAX_PATCHES, MIN_PATCH_CELLS, SIDES, Side,
                                           WheelPatch, Wheelset)

FloatArray = NDArray[np.float64]

#: bump when the stored layout or the physics of a node changes: old files are rebuilt
TABLE_VERSION = 3
#: patches of neighbouring nodes are the same contact if their pressure centroids lie
#: within this distance (m) and their normals within this angle (rad).  On S1002/UIC60 the
#: tread contact runs 10.6 mm for a 1 mm shift near the centre, while the patches of one
#: wheel lie at least D_SEP (8 mm) apart at their edges and their contact angles differ by
#: 0.4 rad or more (tread 0.01-0.03, gauge corner 0.4-0.5, flange 1.1-1.2 rad)
MATCH_DISTANCE = 12e-3
MATCH_ANGLE = 0.3
#: neighbouring shifts whose nodes differ more than this are refined by bisection (up to
#: ``refine`` times): the contact angle (rad), the centroid (m), the patch load (share).
#: A gauge corner or flange contact taking over between two nodes, or
#: the tread contact running across the wheel near the centre (10 mm per mm of shift), is
#: then blended over a sixteenth of a step instead of a whole one
REFINE_ANGLE = 0.05
REFINE_DISTANCE = 0.5e-3
REFINE_LOAD = 0.1
#: a looked-at interval is halved again unless the half-and-half blend of its ends is its
#: midpoint node: centroid within this (m), load, cells and RMS extents within this share
REFINE_MIDPOINT = 0.1e-3
REFINE_SHAPE = 0.05
#: jumps of one yaw column this close (m) are one event; events of neighbouring yaw columns
#: this close (m) are the same event (the flange takes over 0.2 mm further out at 25 mrad
#: than at 0)
EVENT_CLUSTER = 0.05e-3
EVENT_MATCH = 0.5e-3
#: yaw refinement around a flange's take-over (assumption 4): an event paired between two
#: yaw columns whose contact angle turns by at least YAW_EVENT_TURN (rad: the flange's
#: 0.6-0.7, not the gauge corner's 0.4) gets the shifts within YAW_WINDOW (m) of both
#: columns' events solved at the yaws halving the interval YAW_REFINE times (5 mrad -> 1.25)
YAW_REFINE = 2
YAW_WINDOW = 40e-6
YAW_EVENT_TURN = 0.5
#: a pose this close to a node (in units of the step) takes that node alone
NODE_SNAP = 1e-9
#: the roll that levels both rigid wheels is solved to this height difference (m)
ROLL_TOLERANCE = 1e-10
ROLL_ITERATIONS = 60


# ---------------------------------------------------------------------------- the roll


def levelled_roll(wheelset: Wheelset, dy: float, yaw: float, *, start: float = 0.0
                  ) -> tuple[float, float]:
    """Return ``(roll, dz)``: the roll at which both rigid wheels touch at one height.

    ``g(roll) = gap_left - gap_right`` (vertical gaps at ``dz = 0``) grows
    like ``2 b roll`` (``b`` the wheel's lateral offset) on treads; a flange
    contact bends it.  Secant steps from the geometric first step, kept in a
    bracket once one is found (Illinois).  ``dz = -gap``: the wheelset
    lowered until both wheels touch.  Raises
    :class:`~fastsim_ros.geometry.errors.NoContactError` if no roll within
    0.1 rad levels them.
    """
    b = wheelset.placement.wheel_offset

    def mismatch(roll: float) -> tuple[float, float]:
        pose = Pose(dy=dy, yaw=yaw, roll=roll)
        left = wheelset.vertical_gap("left", pose)
        right = wheelset.vertical_gap("right", pose)
        return left - right, left

    r0 = start
    g0, gap0 = mismatch(r0)
    if abs(g0) <= ROLL_TOLERANCE:
        return r0, -gap0
    r1 = r0 - g0 / (2.0 * b)
    bracket: tuple[float, float] | None = None   # the last point on the other side of the root
    for _ in range(ROLL_ITERATIONS):
        if not abs(r1) <= 0.1:
            raise NoContactError(f"no roll within 0.1 rad levels both wheels at dy={dy:.6g} m, "
                                 f"yaw={yaw:.6g} rad")
        g1, gap1 = mismatch(r1)
        if abs(g1) <= ROLL_TOLERANCE:
            return r1, -gap1
        if bracket is None and g0 * g1 < 0.0:
            bracket = (r0, g0)
        if bracket is None:
            # secant outside a bracket: a flange bends g(roll), but it stays monotone
            r_next = r1 - g1 * (r1 - r0) / (g1 - g0) if g1 != g0 else r1 - g1 / (2.0 * b)
        else:
            # Illinois: regula falsi on the bracket, the end kept twice running halved
            ra, ga = bracket
            if g1 * g0 < 0.0 and (r0, g0) != bracket:
                ra, ga = r0, g0
            elif (r0, g0) != bracket:
                ga *= 0.5
            bracket = (ra, ga)
            if abs(r1 - ra) <= 1e-15:
                return r1, -gap1
            r_next = r1 - g1 * (r1 - ra) / (g1 - ga)
        r0, g0 = r1, g1
        r1 = r_next
    raise NoContactError(f"the levelling roll did not converge at dy={dy:.6g} m, "
                         f"yaw={yaw:.6g} rad")


# ---------------------------------------------------------------------------- patches


@dataclass(frozen=True, eq=False)
class TablePatch:
    """One patch of one wheel at a node, in the wheelset frame (m, Pa, N).

    ``origin``: the pressure centroid; ``normal``: the contact plane's unit
    normal pointing into the wheel; ``u``, ``v``: the grid's in-plane unit
    axes; cell ``(j, i)`` lies at ``origin + (a0 + i da) u + (b0 + j db) v``
    with ``pressure[j, i]``; ``load``: ``sum p da db``; ``approach``: the
    rigid approach of the normal solve (m).
    """

    origin: FloatArray
    normal: FloatArray
    u: FloatArray
    v: FloatArray
    a0: float
    b0: float
    da: float
    db: float
    pressure: FloatArray
    load: float
    approach: float
    cells: int = -1
    axes: tuple[tuple[float, ...], tuple[float, ...]] = ((), ())

    def __post_init__(self) -> None:
        if self.cells < 0:
            object.__setattr__(self, "cells", int(np.count_nonzero(self.pressure > 0.0)))
        # the axes as plain floats: the blend's arithmetic on them runs per pose, and numpy's
        # per-call cost on 3-vectors would be most of it
        object.__setattr__(self, "axes", (tuple(float(c) for c in self.u),
                                          tuple(float(c) for c in self.v)))

    @classmethod
    def of(cls, patch: WheelPatch) -> TablePatch:
        """Return a solved wheel patch (its ``points`` in the wheelset frame) as a table patch."""
        pts, p = patch.points, patch.pressure
        ny, nx = p.shape
        normal = np.asarray(patch.normal, dtype=float)
        normal = normal / np.linalg.norm(normal)
        # the planar grid runs along the wheelset's x projected on the contact plane (the
        # adapter's contact frame): the table keeps that, so its patches need no resampling
        u = _in_plane((1.0, 0.0, 0.0), normal)
        if nx > 1:
            along = pts[0, 1] - pts[0, 0]
            if abs(float(along @ u)) < (1.0 - 1e-9) * float(np.linalg.norm(along)):
                raise TableError("a patch grid not along the wheelset's x projected on its "
                                 "plane")
        v = _cross(normal, u)
        if ny > 1 and float(np.dot(pts[1, 0] - pts[0, 0], v)) < 0.0:
            # rows that run against n x u (the right wheel's side frame): turn them round,
            # so that every table patch is right-handed (u, v, normal)
            pts, p = pts[::-1], p[::-1]
        total = float(p.sum())
        origin = np.tensordot(p, pts, axes=2) / total
        rel = pts[0, 0] - origin
        return cls(origin, normal, u, v, float(rel @ u), float(rel @ v), float(patch.grid.dx),
                   float(patch.grid.ds), np.ascontiguousarray(p, dtype=float),
                   float(patch.load), float(patch.approach))

    def mirrored(self) -> TablePatch:
        """Return the patch mirrored in the wheelset's ``y`` (the other wheel's)."""
        m = np.array([1.0, -1.0, 1.0])
        # the mirror turns the frame left-handed: v is turned round with the rows, so the
        # grid stays right-handed (cell j of the mirror is row nb-1-j of the original)
        nb = self.pressure.shape[0]
        return replace(self, origin=self.origin * m, normal=self.normal * m, u=self.u * m,
                       v=-(self.v * m), b0=-(self.b0 + (nb - 1) * self.db),
                       pressure=np.ascontiguousarray(self.pressure[::-1]))

    def scaled(self, s: float) -> TablePatch:
        """Return the patch under Hertz similarity: sizes times ``s``, pressure times ``s``."""
        if s == 1.0:
            return self
        return blend([(1.0, self)], scale=s)

    def cloud_arrays(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Return ``points, normal, pressure`` of the patch cloud (wheelset frame).

        Rows run along the contact frame's ``y = z x x`` with ``x`` the
        wheelset's ``x`` projected on the plane (the adapter's frame), so a
        patch of either wheel reads like a rig's.
        """
        ny, nx = self.pressure.shape
        a = self.a0 + self.da * np.arange(nx)
        b = self.b0 + self.db * np.arange(ny)
        points = (self.origin + a[None, :, None] * self.u) + b[:, None, None] * self.v
        return points, self.normal, self.pressure

    def vertical_normal_force(self, rotation: FloatArray) -> float:
        """Return the normal force's vertical component in the track frame (N)."""
        return self.load * float((rotation @ self.normal)[2])


def _in_plane(vector: tuple[float, float, float] | FloatArray, normal: FloatArray) -> FloatArray:
    """Return ``vector`` projected on the plane of ``normal``, normalised."""
    w = np.asarray(vector, dtype=float)
    w = w - float(w @ normal) * normal
    return w / np.linalg.norm(w)


@numba.njit(cache=True, nogil=True)
def _gather(out: FloatArray, x0: float, s0: float, h: float, pressure: FloatArray, a0: float,
            b0: float, da: float, db: float, m00: float, m01: float, m10: float, m11: float,
            factor: float) -> None:  # pragma: no cover - compiled
    """Add ``factor`` times a member's pressure, bilinearly sampled, to ``out``.

    Output cell ``(j, i)`` lies at ``(x0 + i h, s0 + j h)`` in the blended
    frame; ``m`` maps those coordinates to the member's ``(a, b)`` (its own
    grid coordinates about its centroid, divided by the scale).
    """
    ns, nx = out.shape
    nb, na = pressure.shape
    for j in range(ns):
        s = s0 + j * h
        for i in range(nx):
            x = x0 + i * h
            fa = (m00 * x + m01 * s - a0) / da
            fb = (m10 * x + m11 * s - b0) / db
            ia = int(math.floor(fa))
            ib = int(math.floor(fb))
            if ia < -1 or ib < -1 or ia >= na or ib >= nb:
                continue
            ta = fa - ia
            tb = fb - ib
            acc = 0.0
            if ib >= 0:
                if ia >= 0:
                    acc += (1.0 - ta) * (1.0 - tb) * pressure[ib, ia]
                if ia + 1 < na:
                    acc += ta * (1.0 - tb) * pressure[ib, ia + 1]
            if ib + 1 < nb:
                if ia >= 0:
                    acc += (1.0 - ta) * tb * pressure[ib + 1, ia]
                if ia + 1 < na:
                    acc += ta * tb * pressure[ib + 1, ia + 1]
            out[j, i] += factor * acc


@numba.njit(cache=True, nogil=True)
def _finish(field: FloatArray, cells: int, load: float, h: float, x0: float,
            s0: float) -> tuple[int, int, int, int, float, float]:  # pragma: no cover - compiled
    """Keep the ``cells`` largest values, scale the rest to ``load``; return the crop and centroid.

    Returns ``(j0, j1, i0, i1, cx, cs)``: the rows and columns in contact
    with one empty cell around, and the centroid ``(x, s)`` of the kept
    field (m, in the field's coordinates).
    """
    ns, nx = field.shape
    flat = field.ravel()
    positive = 0
    for k in range(flat.size):
        if flat[k] > 0.0:
            positive += 1
        else:
            flat[k] = 0.0
    if positive > cells:
        cut = np.partition(flat, flat.size - cells)[flat.size - cells]
        above = 0
        for k in range(flat.size):
            if flat[k] > cut:
                above += 1
        ties = cells - above   # values equal to the cut that are kept: the first ones
        for k in range(flat.size):
            if flat[k] < cut:
                flat[k] = 0.0
            elif flat[k] == cut:
                if ties > 0:
                    ties -= 1
                else:
                    flat[k] = 0.0
    total = 0.0
    mx = 0.0
    ms = 0.0
    j0, j1, i0, i1 = ns, -1, nx, -1
    for j in range(ns):
        for i in range(nx):
            v = field[j, i]
            if v > 0.0:
                total += v
                mx += v * (x0 + i * h)
                ms += v * (s0 + j * h)
                j0 = min(j0, j)
                j1 = max(j1, j)
                i0 = min(i0, i)
                i1 = max(i1, i)
    if total <= 0.0:
        return 0, 0, 0, 0, 0.0, 0.0
    scale = load / (total * h * h)
    for j in range(ns):
        for i in range(nx):
            field[j, i] *= scale
    return (max(0, j0 - 1), min(ns, j1 + 2), max(0, i0 - 1), min(nx, i1 + 2), mx / total,
            ms / total)


class BlendPlan:
    """Matching patches ready to blend at any load scale (assumptions 2 and 3).

    ``members``: ``(weight, patch)`` with weights summing to one; ``fade``:
    the share of the nodes that have this patch (the blended load and cells
    are multiplied by it).  What does not depend on the scale (the blended
    frame, each member's map onto it, the bounds) is done once, so that the
    vertical balance's steps cost the resampling only.
    """

    def __init__(self, members: Sequence[tuple[float, TablePatch]], fade: float = 1.0) -> None:
        self.members = tuple(members)
        self.fade = fade
        if len(members) == 1:
            only = members[0][1]
            origin, normal, u, v = only.origin, only.normal, only.u, only.v
        else:
            origin = np.zeros(3)
            normal = np.zeros(3)
            for w, p in members:
                origin += w * p.origin
                normal += w * p.normal
            normal /= math.sqrt(float(normal @ normal))
            # u: the wheelset's x projected on the plane, v = normal x u
            n0 = float(normal[0])
            u = np.array([1.0 - n0 * n0, -n0 * float(normal[1]), -n0 * float(normal[2])])
            u /= math.sqrt(float(u @ u))
            v = _cross(normal, u)
        self.origin, self.normal, self.u, self.v = origin, normal, u, v
        self.h = min(min(p.da, p.db) for _, p in members)
        self.load = fade * sum(w * p.load for w, p in members)
        self.cells = fade * sum(w * p.cells for w, p in members)
        self.approach = sum(w * p.approach for w, p in members)
        u0, u1, u2 = float(u[0]), float(u[1]), float(u[2])
        v0, v1, v2 = float(v[0]), float(v[1]), float(v[2])
        self.maps = []
        lo_x = lo_s = math.inf
        hi_x = hi_s = -math.inf
        for w, p in members:
            # the member's (a, b) onto the blend's (x, s) at scale 1
            (pu0, pu1, pu2), (pv0, pv1, pv2) = p.axes
            f00 = pu0 * u0 + pu1 * u1 + pu2 * u2
            f01 = pv0 * u0 + pv1 * u1 + pv2 * u2
            f10 = pu0 * v0 + pu1 * v1 + pu2 * v2
            f11 = pv0 * v0 + pv1 * v1 + pv2 * v2
            nb, na = p.pressure.shape
            a1, b1 = p.a0 + (na - 1) * p.da, p.b0 + (nb - 1) * p.db
            # the extremes of a linear map on a box lie at its corners
            xa, xb = sorted((f00 * p.a0, f00 * a1))
            xc, xd = sorted((f01 * p.b0, f01 * b1))
            sa, sb = sorted((f10 * p.a0, f10 * a1))
            sc, sd = sorted((f11 * p.b0, f11 * b1))
            lo_x, hi_x = min(lo_x, xa + xc), max(hi_x, xb + xd)
            lo_s, hi_s = min(lo_s, sa + sc), max(hi_s, sb + sd)
            det = f00 * f11 - f01 * f10
            self.maps.append((w, p, f11 / det, -f01 / det, -f10 / det, f00 / det))
        self.bounds = (lo_x, hi_x, lo_s, hi_s)

    @property
    def single(self) -> TablePatch | None:
        """Return the one node patch this plan is, or ``None`` (a blend or a fade)."""
        return self.members[0][1] if len(self.members) == 1 and self.fade == 1.0 else None

    def at(self, scale: float = 1.0) -> TablePatch:
        """Return the blended patch at the Hertz scale ``s``.

        Its load is ``fade s^3 sum w L``, its cells ``round(fade s^2 sum w
        cells)`` (the largest of the resampled field: bilinear resampling
        spreads an edge by a cell), its pressure centroid exactly the blended
        origin, its grid along the adapter's contact frame.
        """
        single = self.single
        if scale == 1.0 and single is not None:
            return single   # on a node: the node's own patch
        h = self.h
        lo_x, hi_x, lo_s, hi_s = (scale * b for b in self.bounds)
        x0 = math.floor(lo_x / h) * h - h
        s0 = math.floor(lo_s / h) * h - h
        nx = int(math.ceil((hi_x - x0) / h)) + 2
        ns = int(math.ceil((hi_s - s0) / h)) + 2
        field = np.zeros((ns, nx))
        for w, p, m00, m01, m10, m11 in self.maps:
            _gather(field, x0, s0, h, p.pressure, p.a0, p.b0, p.da, p.db, m00 / scale,
                    m01 / scale, m10 / scale, m11 / scale, w * scale)
        load = self.load * scale ** 3
        cells = max(1, round(self.cells * scale ** 2))
        j0, j1, i0, i1, cx, cs = _finish(field, cells, load, h, x0, s0)
        if j1 <= j0:
            raise TableError("a blended patch came out empty")
        cropped = np.ascontiguousarray(field[j0:j1, i0:i1])
        # the grid shifted so that the kept field's centroid is the blended origin
        return TablePatch(self.origin, self.normal, self.u, self.v, x0 + i0 * h - cx,
                          s0 + j0 * h - cs, h, h, cropped, load, scale ** 2 * self.approach)

    def vertical_normal_force(self, rotation: FloatArray) -> float:
        """Return the blend's normal force's vertical component at scale 1, track frame (N)."""
        return self.load * float((rotation @ self.normal)[2])


def warm_up() -> None:
    """Compile (or load from numba's disk cache) the blend's kernels on a tiny field."""
    field = np.zeros((3, 3))
    pressure = np.ones((2, 2))
    _gather(field, -2e-4, -2e-4, 2e-4, pressure, -1e-4, -1e-4, 2e-4, 2e-4, 1.0, 0.0, 0.0, 1.0,
            1.0)
    _finish(field, 2, 1.0, 2e-4, -2e-4, -2e-4)


def blend(members: Sequence[tuple[float, TablePatch]], *, scale: float = 1.0,
          fade: float = 1.0) -> TablePatch:
    """Return the blend of matching patches at the scale ``s`` (see :class:`BlendPlan`)."""
    return BlendPlan(members, fade).at(scale)


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """Return ``a x b`` of two 3-vectors (numpy's cross costs 20 us on these)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def match(groups: list[list[tuple[float, TablePatch]]], weight: float,
          patches: Sequence[TablePatch]) -> None:
    """Add one node's patches to the groups of matching patches (assumption 3).

    Each patch joins the nearest group (distance over MATCH_DISTANCE plus
    angle over MATCH_ANGLE) within both limits that has no patch of this
    node yet, else starts a group.
    """
    taken: set[int] = set()
    for p in patches:
        best, best_cost = -1, math.inf
        for k, g in enumerate(groups):
            if k in taken:
                continue
            ref = g[0][1]
            d = float(np.linalg.norm(p.origin - ref.origin))
            angle = math.acos(max(-1.0, min(1.0, float(p.normal @ ref.normal))))
            cost = d / MATCH_DISTANCE + angle / MATCH_ANGLE
            if d <= MATCH_DISTANCE and angle <= MATCH_ANGLE and cost < best_cost:
                best, best_cost = k, cost
        if best < 0:
            groups.append([(weight, p)])
            taken.add(len(groups) - 1)
        else:
            groups[best].append((weight, p))
            taken.add(best)


# ---------------------------------------------------------------------------- the table


@dataclass(frozen=True)
class TableGrid:
    """The nodes: lateral shifts ``dys`` (m) and yaws ``yaws`` (rad), both increasing."""

    dys: tuple[float, ...]
    yaws: tuple[float, ...]

    @classmethod
    def regular(cls, dy_min: float, dy_max: float, dy_step: float, yaw_max: float,
                yaw_step: float) -> TableGrid:
        """Return the grid ``dy_min..dy_max`` by ``dy_step``, yaws ``-yaw_max..yaw_max``.

        A step that does not divide its range is refused: the nodes must
        fall on the range's ends (and on zero, for the mirror).
        """
        def axis(lo: float, hi: float, step: float, name: str) -> tuple[float, ...]:
            if not (math.isfinite(lo) and math.isfinite(hi) and math.isfinite(step)
                    and step > 0.0 and hi >= lo):
                raise TableError(f"table {name}: a range lo <= hi and a step > 0, got "
                                 f"{lo!r}..{hi!r} by {step!r}")
            n = (hi - lo) / step
            if abs(n - round(n)) > 1e-6 or round(n) > 2000:
                raise TableError(f"table {name}: the step {step:g} must divide the range "
                                 f"{lo:g}..{hi:g} (at most 2000 steps)")
            k = np.arange(round(n) + 1)
            return tuple(float(v) for v in lo + k * (hi - lo) / max(round(n), 1))

        dys = axis(dy_min, dy_max, dy_step, "dy")
        yaws = axis(-yaw_max, yaw_max, yaw_step, "yaw") if yaw_max > 0.0 else (0.0,)
        return cls(dys, yaws)

    @property
    def symmetric(self) -> bool:
        """Return whether the grid is its own mirror image (``-dy``, ``-yaw`` are nodes)."""
        return (np.allclose(self.dys, [-d for d in reversed(self.dys)], rtol=0.0, atol=1e-12)
                and np.allclose(self.yaws, [-y for y in reversed(self.yaws)], rtol=0.0,
                                atol=1e-12))

    def nodes(self) -> list[tuple[float, float]]:
        """Return every node ``(dy, yaw)``, yaw fastest."""
        return [(d, y) for d in self.dys for y in self.yaws]


def _axis_weights(nodes: tuple[float, ...], value: float, name: str) -> list[tuple[int, float]]:
    """Return the linear weights of ``value`` on increasing ``nodes`` (refined: not uniform)."""
    if len(nodes) == 1:
        if abs(value - nodes[0]) > 1e-12:
            raise TableRangeError(f"{name} {value:.6g} outside the table (only {nodes[0]:g})")
        return [(0, 1.0)]
    lo, hi = nodes[0], nodes[-1]
    snap = NODE_SNAP * (hi - lo) / (len(nodes) - 1)
    if not lo - snap <= value <= hi + snap:
        raise TableRangeError(f"{name} {value:.6g} outside the table's {lo:.6g}..{hi:.6g}")
    k = min(max(bisect.bisect_right(nodes, value) - 1, 0), len(nodes) - 2)
    t = (value - nodes[k]) / (nodes[k + 1] - nodes[k])
    if t <= NODE_SNAP:
        return [(k, 1.0)]
    if t >= 1.0 - NODE_SNAP:
        return [(k + 1, 1.0)]
    return [(k, 1.0 - t), (k + 1, t)]


def _event_pairs(a: list[float], b: list[float]) -> list[tuple[float, float]]:
    """Return the events of two yaw columns that are one event (nearest, within EVENT_MATCH).

    In order along the shift: a gauge corner taking over at one yaw and not at
    the next is left out, the flange's take-over at both is paired.
    """
    out = []
    i = k = 0
    while i < len(a) and k < len(b):
        if abs(a[i] - b[k]) <= EVENT_MATCH:
            out.append((a[i], b[k]))
            i += 1
            k += 1
        elif a[i] < b[k]:
            i += 1
        else:
            k += 1
    return out


def _contact_angles(node: TableNode) -> tuple[float, float]:
    """Return each wheel's contact angle (rad, from the wheelset's z), weighed by load."""
    out = []
    for patches in node.patches:
        load = sum(p.load for p in patches)
        out.append(sum(p.load * math.atan2(abs(float(p.normal[1])), float(p.normal[2]))
                       for p in patches) / load if load > 0.0 else 0.0)
    return out[0], out[1]


def _event_turn(column: Sequence[TableNode], first: int, last: int) -> float:
    """Return how far a column's contact angle turns across the nodes ``first`` to ``last``.

    The larger of the two wheels' load-weighted contact angles' changes (rad):
    a flange taking over from the gauge corner turns it by 0.6-0.7 rad, a
    gauge corner from the tread by about 0.4.
    """
    a, b = _contact_angles(column[first]), _contact_angles(column[last])
    return max(abs(b[0] - a[0]), abs(b[1] - a[1]))


def _pairs(a: TableNode, b: TableNode) -> list[tuple[TablePatch, TablePatch]] | None:
    """Return the matching patch pairs of two nodes (both wheels), or ``None`` if any is unmatched.

    ``None`` too if one node derailed and not the other; two derailed nodes
    have no pairs.  (While a table with the mirror is built, only the left
    wheel is there: the mirrored insertions cover the right.)
    """
    if a.derailed or b.derailed:
        return [] if a.derailed == b.derailed else None
    pairs = []
    for side in range(2):
        if len(a.patches[side]) != len(b.patches[side]):
            return None
        groups: list[list[tuple[float, TablePatch]]] = []
        match(groups, 0.5, a.patches[side])
        match(groups, 0.5, b.patches[side])
        for g in groups:
            if len(g) != 2:
                return None
            pairs.append((g[0][1], g[1][1]))
    return pairs


def _differ(a: TableNode, b: TableNode) -> bool:
    """Return whether two neighbouring nodes differ enough to look between them.

    Other patches, or a pair whose contact angles differ by more than
    REFINE_ANGLE, centroids by more than REFINE_DISTANCE or loads by more
    than REFINE_LOAD of the larger.
    """
    pairs = _pairs(a, b)
    if pairs is None:
        return True
    for p, q in pairs:
        angle = math.acos(max(-1.0, min(1.0, float(p.normal @ q.normal))))
        if (angle > REFINE_ANGLE or float(np.linalg.norm(p.origin - q.origin)) > REFINE_DISTANCE
                or abs(p.load - q.load) > REFINE_LOAD * max(p.load, q.load)):
            return True
    return False


def _shape(p: TablePatch) -> tuple[float, float, float]:
    """Return the cells and the RMS extents along ``u`` and ``v`` about the centroid (m)."""
    nb, na = p.pressure.shape
    a = p.a0 + p.da * np.arange(na)
    b = p.b0 + p.db * np.arange(nb)
    total = float(p.pressure.sum())
    ma = float(p.pressure.sum(axis=0) @ (a * a)) / total
    mb = float(p.pressure.sum(axis=1) @ (b * b)) / total
    return float(p.cells), math.sqrt(max(ma, 0.0)), math.sqrt(max(mb, 0.0))


def _blends_well(a: TableNode, b: TableNode, mid: TableNode) -> bool:
    """Return whether the half-and-half blend of ``a`` and ``b`` is the node ``mid`` between them.

    The blend's centroid within REFINE_MIDPOINT of the midpoint node's, its
    load, cells and RMS extents within REFINE_SHAPE of them, the same patches.
    """
    pairs = _pairs(a, b)
    if pairs is None or _pairs(a, mid) is None:
        return False
    mids = [q for _, q in _pairs(a, mid) or []]
    for (p, q), m in zip(pairs, mids):
        half = BlendPlan([(0.5, p), (0.5, q)])
        if float(np.linalg.norm(half.origin - m.origin)) > REFINE_MIDPOINT:
            return False
        if abs(half.load - m.load) > REFINE_SHAPE * m.load:
            return False
        for x, y in zip(_shape(half.at(1.0 + 1e-12)), _shape(m)):
            if abs(x - y) > REFINE_SHAPE * abs(y):
                return False
    return True


@dataclass(frozen=True, eq=False)
class TableNode:
    """One node: its roll (rad), its loaded height (m, the left wheel's) and both wheels' patches.

    ``derailed``: the wheelset cannot stand there (no roll levels it, a
    wheel past its flange): poses next to it are refused.
    """

    roll: float
    dz: float
    patches: tuple[tuple[TablePatch, ...], tuple[TablePatch, ...]]
    derailed: bool = False


@dataclass(frozen=True, eq=False)
class TableLookup:
    """A pose from the table: the roll (rad) and each wheel's contacts (tread first)."""

    roll: float
    groups: tuple[tuple[BlendPlan, ...], tuple[BlendPlan, ...]]

    def patches(self, side: Side, scale: float = 1.0) -> list[TablePatch]:
        """Return one wheel's patches at the load scale ``s`` (assumptions 2 and 3)."""
        return [g.at(scale) for g in self.groups[SIDES.index(side)]]

    def vertical_normal_force(self, side: Side, rotation: FloatArray) -> float:
        """Return the wheel's normal forces' vertical sum in the track frame at ``s = 1`` (N).

        The blend's load and normal without its resampling, so the vertical
        balance's first scale comes without a solve.
        """
        return sum(g.vertical_normal_force(rotation) for g in self.groups[SIDES.index(side)])


def solve_node(wheelset: Wheelset, load: float, dy: float, yaw: float,
               sides: Sequence[Side] = SIDES) -> TableNode:
    """Solve one node: the levelling roll, then each wheel at the reference ``load`` (N)."""
    try:
        roll, dz = levelled_roll(wheelset, dy, yaw)
        pose = Pose(dy=dy, dz=dz, yaw=yaw, roll=roll)
        out: list[tuple[TablePatch, ...]] = [(), ()]
        for side in sides:
            wheel = wheelset.wheel_loaded(side, pose, load)
            patches = sorted(wheel.patches, key=lambda p: -p.region.reference[1])
            # each patch in the wheelset frame of its own loaded height (the rigid approach
            # lowers the wheelset by 15-40 um, which moves the rolling radius, hence xi)
            out[SIDES.index(side)] = tuple(TablePatch.of(p) for p in patches)
            dz = wheel.dz if side == "left" else dz
        return TableNode(roll, dz, (out[0], out[1]))
    except GeometryError:
        return TableNode(0.0, 0.0, ((), ()), derailed=True)


def _solve_nodes(args: tuple[Wheelset, float, list[tuple[float, float]], tuple[Side, ...]]
                 ) -> list[TableNode]:
    wheelset, load, nodes, sides = args
    return [solve_node(wheelset, load, dy, yaw, sides) for dy, yaw in nodes]


def _solve_in_children(wheelset: Wheelset, load: float,
                       chunks: list[list[tuple[float, float]]], sides: tuple[Side, ...],
                       workers: int, progress: Callable[[int, int], None] | None
                       ) -> list[TableNode]:
    """Solve the chunks in ``workers`` child interpreters (``python -m ...table_worker``).

    Not multiprocessing: its spawn re-imports the caller's main module (a
    script without a main guard would start again in each child) and its
    fork would copy a node's DDS threads half-alive.  Each child takes every
    ``workers``-th chunk (the flange's costly nodes spread over all) as one
    pickle on its stdin and answers one pickle on its stdout; a child that
    fails has its chunks solved here.
    """
    import pickle
    import subprocess
    import sys

    total = sum(len(c) for c in chunks)
    shares = [list(range(w, len(chunks), workers)) for w in range(workers)]
    env = dict(os.environ)
    # the child finds this package where this process found it
    root = str(Path(__file__).resolve().parents[2])
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [root, env.get("PYTHONPATH", "")]))
    children = []
    for share in shares:
        proc = subprocess.Popen([sys.executable, "-m", "fastsim_ros.geometry.table_worker"],
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, env=env)
        assert proc.stdin is not None
        proc.stdin.write(pickle.dumps((wheelset, load, [chunks[k] for k in share], sides)))
        proc.stdin.close()
        children.append((share, proc))
    results: dict[int, list[TableNode]] = {}
    done = 0
    for share, proc in children:
        assert proc.stdout is not None
        raw = proc.stdout.read()
        status = proc.wait()
        try:
            parts = pickle.loads(raw) if status == 0 else None
        except (pickle.UnpicklingError, EOFError, ValueError):
            parts = None
        if parts is None or len(parts) != len(share):
            parts = [_solve_nodes((wheelset, load, chunks[k], sides)) for k in share]
        for k, part in zip(share, parts):
            results[k] = part
            done += len(part)
        if progress:
            progress(done, total)
    return [node for k in range(len(chunks)) for node in results[k]]


class ContactTable:
    """The wheelset's patches on a grid of ``(dy, yaw)`` at a reference wheel load."""

    def __init__(self, grid: TableGrid, load: float, nodes: Sequence[TableNode],
                 refined: dict[int, list[ContactTable]] | None = None) -> None:
        if len(nodes) != len(grid.dys) * len(grid.yaws):
            raise TableError("the table's nodes do not fill its grid")
        self.grid = grid
        self.load = float(load)
        self.nodes = tuple(nodes)
        # each yaw column's events: where its contact jumps (a flange or gauge corner taking
        # over), i.e. where the refinement went down to its finest step and the nodes still
        # differ; the jumps within EVENT_CLUSTER of one another are one event, at their mean
        # (``turns``: how far the contact angle turns across it, _event_turn)
        dys = np.asarray(grid.dys)
        finest = 1.5 * float(np.diff(dys).min()) if dys.size > 1 else 0.0
        self.events: list[list[float]] = []
        self.turns: list[list[float]] = []
        for j in range(len(grid.yaws)):
            column = [self.nodes[i * len(grid.yaws) + j] for i in range(len(grid.dys))]
            jumps = [i for i in range(len(column) - 1)
                     if grid.dys[i + 1] - grid.dys[i] < finest
                     and _differ(column[i], column[i + 1])]
            clusters: list[list[int]] = []
            for i in jumps:
                if clusters and (0.5 * (grid.dys[i] + grid.dys[i + 1])
                                 - 0.5 * (grid.dys[clusters[-1][-1]]
                                          + grid.dys[clusters[-1][-1] + 1])) < EVENT_CLUSTER:
                    clusters[-1].append(i)
                else:
                    clusters.append([i])
            self.events.append([sum(0.5 * (grid.dys[i] + grid.dys[i + 1]) for i in c) / len(c)
                                for c in clusters])
            self.turns.append([_event_turn(column, c[0], c[-1] + 1) for c in clusters])
        #: yaw interval j -> the tables of its windows (assumption 4): around a flange's
        #: take-over, shifts at the finest step solved at yaws between columns j and j + 1
        self.refined: dict[int, list[ContactTable]] = dict(refined or {})

    def weights(self, dy: float, yaw: float) -> list[tuple[int, int, float]]:
        """Return the weights ``(i_dy, i_yaw, w)`` of a pose's nodes, largest first.

        Bilinear, but aligned on the events in yaw (assumption 3): where both
        yaw columns have the same number of events (say a flange taking over,
        at a shift that moves with the yaw), the pose's shift is placed on
        each column at the same distance from its events as from the events
        interpolated at the pose's yaw (piecewise linear between them), so
        that both columns give the contact the pose has, not one each.
        """
        for_yaw = _axis_weights(self.grid.yaws, yaw, "yaw")
        _axis_weights(self.grid.dys, dy, "dy")   # the range check on the shift itself
        knots = (_event_pairs(self.events[for_yaw[0][0]], self.events[for_yaw[1][0]])
                 if len(for_yaw) == 2 else [])
        if knots:
            (j0, w0), (j1, w1) = for_yaw
            ends = (self.grid.dys[0], self.grid.dys[-1])
            e0 = [ends[0], *(a for a, _ in knots), ends[1]]
            e1 = [ends[0], *(b for _, b in knots), ends[1]]
            at = [w0 * a + w1 * b for a, b in zip(e0, e1)]
            k = min(max(bisect.bisect_right(at, dy) - 1, 0), len(at) - 2)
            t = (dy - at[k]) / (at[k + 1] - at[k]) if at[k + 1] > at[k] else 0.0
            shifted = [(j0, w0, e0[k] + t * (e0[k + 1] - e0[k])),
                       (j1, w1, e1[k] + t * (e1[k + 1] - e1[k]))]
        else:
            shifted = [(j, wj, dy) for j, wj in for_yaw]
        out: list[tuple[int, int, float]] = []
        for j, wj, d in shifted:
            for i, wi in _axis_weights(self.grid.dys, d, "dy"):
                if wi * wj > 0.0:
                    out.append((i, j, wi * wj))
        out.sort(key=lambda t: -t[2])
        return out

    @classmethod
    def build(cls, wheelset: Wheelset, grid: TableGrid, load: float, *, workers: int = 1,
              refine: int = 0,
              progress: Callable[[int, int], None] | None = None) -> ContactTable:
        """Solve every node (in ``workers`` processes); the mirror halves the work (assumption 5).

        ``load``: the reference wheel load (N).  ``refine``: times the shift
        intervals whose nodes are inconsistent (:func:`_consistent`, any yaw)
        are halved; the inserted shifts are solved at every yaw (the grid
        stays a tensor grid, and symmetric: ``-dy`` with ``dy``).
        ``progress(done, total)`` is called as chunks finish.
        """
        if not (math.isfinite(load) and load > 0.0):
            raise TableError(f"a contact table needs a reference wheel load > 0 N, got {load!r}")
        mirror = wheelset.symmetric and grid.symmetric
        sides: tuple[Side, ...] = ("left",) if mirror else SIDES
        # nodes by integer keys (picometres, picoradians): a shift and its mirror image, or
        # a midpoint reached from both sides, are one node whatever the float rounding
        solved: dict[tuple[int, int], TableNode] = {}

        def key(d: float, y: float) -> tuple[int, int]:
            return round(d * 1e12), round(y * 1e12)

        def solve(nodes: list[tuple[float, float]]) -> None:
            chunks = [nodes[k:k + 8] for k in range(0, len(nodes), 8)]
            if workers > 1 and len(chunks) > 1:
                done = _solve_in_children(wheelset, load, chunks, sides, workers, progress)
            else:
                done = []
                for c in chunks:
                    done.extend(_solve_nodes((wheelset, load, c, sides)))
                    if progress:
                        progress(len(done), len(nodes))
            solved.update((key(d, y), n) for (d, y), n in zip(nodes, done))

        dys = {round(d * 1e12): d for d in grid.dys}
        solve([(d, y) for d in grid.dys for y in grid.yaws])
        # intervals to look into: first those whose ends differ; then the halves of those
        # whose midpoint the blend of the ends misses
        ordered = sorted(dys.values())
        looking = [(d0, d1) for d0, d1 in zip(ordered[:-1], ordered[1:])
                   if any(_differ(solved[key(d0, y)], solved[key(d1, y)]) for y in grid.yaws)]
        for _ in range(refine):
            inserted: dict[int, float] = {}
            for d0, d1 in looking:
                mid = 0.5 * (d0 + d1)
                for d in ((mid, -mid) if mirror else (mid,)):
                    if round(d * 1e12) not in dys:
                        inserted.setdefault(round(d * 1e12), d)
            if not inserted:
                break
            solve([(d, y) for d in sorted(inserted.values()) for y in grid.yaws])
            dys.update(inserted)
            following = []
            for d0, d1 in looking:
                mid = 0.5 * (d0 + d1)
                if not all(_blends_well(solved[key(d0, y)], solved[key(d1, y)],
                                        solved[key(mid, y)]) for y in grid.yaws):
                    following += [(d0, mid), (mid, d1)]
            if mirror:   # the mirror images of the intervals kept, once
                mirrored = [(-d1, -d0) for d0, d1 in following]
                seen = {(round(d0 * 1e12), round(d1 * 1e12)) for d0, d1 in following}
                following += [(d0, d1) for d0, d1 in mirrored
                              if (round(d0 * 1e12), round(d1 * 1e12)) not in seen]
            looking = following
        grid = TableGrid(tuple(sorted(dys.values())), grid.yaws)

        def assembled(d: float, y: float) -> TableNode:
            node = solved[key(d, y)]
            if mirror:
                twin = solved[key(-d, -y)]
                right = tuple(p.mirrored() for p in twin.patches[0])
                node = TableNode(node.roll, node.dz, (node.patches[0], right),
                                 node.derailed or twin.derailed)
            return node

        table = cls(grid, load, [assembled(d, y) for d in grid.dys for y in grid.yaws])
        if refine <= 0 or YAW_REFINE <= 0:
            return table
        # assumption 4: around a flange's take-over, yaws between the columns (the window's
        # own nodes; with the mirror, the mirrored window's too: the right wheel's patches)
        windows = table.yaw_windows()
        wanted: dict[tuple[int, int], tuple[float, float]] = {}
        for _, window_dys, window_yaws in windows:
            for d in window_dys:
                for y in window_yaws:
                    for dd, yy in (((d, y), (-d, -y)) if mirror else ((d, y),)):
                        if key(dd, yy) not in solved:
                            wanted.setdefault(key(dd, yy), (dd, yy))
        if wanted:
            solve([wanted[k] for k in sorted(wanted)])
        for j, window_dys, window_yaws in windows:
            table.refined.setdefault(j, []).append(
                cls(TableGrid(window_dys, window_yaws), load,
                    [assembled(d, y) for d in window_dys for y in window_yaws]))
        return table

    def node(self, i_dy: int, i_yaw: int) -> TableNode:
        """Return the node at grid indices ``(i_dy, i_yaw)``."""
        return self.nodes[i_dy * len(self.grid.yaws) + i_yaw]

    def window(self, dy: float, yaw: float) -> ContactTable | None:
        """Return the yaw-refined window's table that holds ``(dy, yaw)``, or ``None``."""
        if not self.refined:
            return None
        yaws = self.grid.yaws
        j = min(max(bisect.bisect_right(yaws, yaw) - 1, 0), len(yaws) - 2)
        for table in self.refined.get(j, ()):
            if (table.grid.dys[0] <= dy <= table.grid.dys[-1]
                    and yaws[j] <= yaw <= yaws[j + 1]):
                return table
        return None

    def yaw_windows(self) -> list[tuple[int, tuple[float, ...], tuple[float, ...]]]:
        """Return the windows to refine in yaw: ``(j, dys, yaws)`` (assumption 4).

        For each yaw interval ``j`` and each event paired between its columns
        that turns the contact angle by YAW_EVENT_TURN or more (a flange
        taking over): the shifts at the grid's finest step within YAW_WINDOW of
        both columns' events (every one, not only the grid's: between the two
        columns' take-overs the grid's refinement may have stopped at a
        coarser step) and the yaws that halve the interval YAW_REFINE times,
        its end columns included.
        """
        out: list[tuple[int, tuple[float, ...], tuple[float, ...]]] = []
        yaws, dys = self.grid.yaws, self.grid.dys
        if len(dys) < 2:
            return out
        step = float(np.diff(np.asarray(dys)).min())
        parts = 2 ** YAW_REFINE
        for j in range(len(yaws) - 1):
            for a, b in _event_pairs(self.events[j], self.events[j + 1]):
                turn = min(self.turns[j][self.events[j].index(a)],
                           self.turns[j + 1][self.events[j + 1].index(b)])
                if turn < YAW_EVENT_TURN:
                    continue
                # on the lattice of the finest step from the grid's first shift (the grid's
                # own shifts are on it; on a symmetric grid it is symmetric: the mirror's
                # windows are these, mirrored)
                lo, hi = min(a, b) - YAW_WINDOW, max(a, b) + YAW_WINDOW
                k0 = max(int(math.ceil((lo - dys[0]) / step - 1e-6)), 0)
                k1 = min(int(math.floor((hi - dys[0]) / step + 1e-6)),
                         int(round((dys[-1] - dys[0]) / step)))
                if k1 <= k0:
                    continue
                # rounded to picometres (the nodes' keys): a window and its mirror image are
                # then exact negatives of one another
                window_dys = tuple(round((dys[0] + k * step) * 1e12) / 1e12
                                   for k in range(k0, k1 + 1))
                window_yaws = tuple(yaws[j] + k * (yaws[j + 1] - yaws[j]) / parts
                                    for k in range(parts + 1))
                out.append((j, window_dys, window_yaws))
        return out

    def lookup(self, dy: float, yaw: float) -> TableLookup:
        """Return the roll and both wheels' blended patches at ``(dy, yaw)`` (reference load).

        Each patch comes with its fade (its nodes' share of the weight).  A
        pose in a yaw-refined window (:attr:`refined`) is that window's
        table's lookup.  Raises :class:`TableRangeError` outside the grid and
        :class:`~fastsim_ros.geometry.errors.DerailmentError` next to a
        derailed node.
        """
        window = self.window(dy, yaw)
        if window is not None:
            return window.lookup(dy, yaw)
        weights = self.weights(dy, yaw)
        nodes = [(w, self.node(i, j)) for i, j, w in weights]
        if any(n.derailed for _, n in nodes):
            raise DerailmentError(f"the wheelset derails near dy={dy:.6g} m, yaw={yaw:.6g} rad "
                                  "(a table node)")
        roll = sum(w * n.roll for w, n in nodes)
        sides = []
        for k in range(2):
            groups: list[list[tuple[float, TablePatch]]] = []
            for w, n in nodes:
                match(groups, w, n.patches[k])
            kept: list[tuple[BlendPlan, float]] = []
            for g in groups:
                fade = sum(w for w, _ in g)
                plan = BlendPlan(tuple((w / fade, p) for w, p in g), fade)
                if plan.cells < MIN_PATCH_CELLS:
                    continue   # a contact fading in below the smallest patch
                kept.append((plan, abs(float(plan.origin[1]))))
            kept.sort(key=lambda t: -t[0].load)
            kept = kept[:MAX_PATCHES]
            # tread first: the field side, the larger |y| in the wheelset frame
            kept.sort(key=lambda t: -t[1])
            sides.append(tuple(t[0] for t in kept))
        return TableLookup(roll, (sides[0], sides[1]))

    # ------------------------------------------------------------------ files

    def save(self, path: Path, key: str) -> None:
        """Write the table to ``path`` (``.npz``) atomically, with its ``key``."""
        # the windows' nodes follow the grid's; a window's node that is one of the grid's (its
        # end columns' shifts on the grid) is stored as a reference to it
        index = {(round(d * 1e12), round(y * 1e12)): i * len(self.grid.yaws) + j
                 for i, d in enumerate(self.grid.dys) for j, y in enumerate(self.grid.yaws)}
        windows: list[tuple[int, int, int]] = []
        window_axes: list[float] = []
        refs: list[int] = []
        stored = list(self.nodes)
        for j in sorted(self.refined):
            for sub in self.refined[j]:
                windows.append((j, len(sub.grid.dys), len(sub.grid.yaws)))
                window_axes.extend(sub.grid.dys)
                window_axes.extend(sub.grid.yaws)
                for i, d in enumerate(sub.grid.dys):
                    for c, y in enumerate(sub.grid.yaws):
                        k = index.get((round(d * 1e12), round(y * 1e12)), -1)
                        refs.append(k)
                        if k < 0:
                            stored.append(sub.node(i, c))
        meta, floats, pressure = [], [], []
        offset = 0
        for k, node in enumerate(stored):
            for side in range(2):
                for p in node.patches[side]:
                    nb, na = p.pressure.shape
                    meta.append((k, side, nb, na, offset))
                    offset += nb * na
                    floats.append(np.concatenate([p.origin, p.normal, p.u, p.v,
                                                  [p.a0, p.b0, p.da, p.db, p.load, p.approach]]))
                    pressure.append(p.pressure.ravel())
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".part.npz")
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez(f, version=np.array(TABLE_VERSION), key=np.array(key),
                         dys=np.array(self.grid.dys), yaws=np.array(self.grid.yaws),
                         load=np.array(self.load),
                         nodes=np.array([(n.roll, n.dz, float(n.derailed)) for n in stored]),
                         windows=np.array(windows, dtype=np.int64).reshape(-1, 3),
                         window_axes=np.array(window_axes, dtype=float),
                         window_refs=np.array(refs, dtype=np.int64),
                         meta=np.array(meta, dtype=np.int64).reshape(-1, 5),
                         floats=np.array(floats, dtype=float).reshape(-1, 18),
                         pressure=np.concatenate(pressure) if pressure else np.zeros(0))
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise

    @classmethod
    def read(cls, path: Path, key: str | None = None) -> ContactTable:
        """Read a table written by :meth:`save`; a wrong version or ``key`` raises TableError.

        So does any file that is not such a table: empty, truncated, damaged
        (the zip's or the arrays' own errors), or with values no build gives
        (non-finite, a negative pressure, records that do not fit together).
        """
        try:
            return cls._read(path, key)
        except TableError:
            raise
        except (OSError, EOFError, zipfile.BadZipFile, KeyError, ValueError, TypeError,
                IndexError, AttributeError) as e:
            raise TableError(f"{path}: not a contact table ({type(e).__name__}: {e})") from None

    @classmethod
    def _read(cls, path: Path, key: str | None) -> ContactTable:
        try:
            with np.load(path, allow_pickle=False) as f:
                if int(f["version"]) != TABLE_VERSION:
                    raise TableError(f"{path}: table version {int(f['version'])}, "
                                     f"expected {TABLE_VERSION}")
                if key is not None and str(f["key"]) != key:
                    raise TableError(f"{path}: made for other profiles or parameters")
                grid = TableGrid(tuple(float(v) for v in f["dys"]),
                                 tuple(float(v) for v in f["yaws"]))
                load = float(f["load"])
                node_rows, meta = f["nodes"], f["meta"]
                floats, pressure = f["floats"], f["pressure"]
                windows, axes, refs = f["windows"], f["window_axes"], f["window_refs"]
        except (OSError, KeyError, ValueError) as e:
            raise TableError(f"{path}: not a contact table ({e})") from None
        if not (np.all(np.isfinite(floats)) and np.all(np.isfinite(pressure))
                and np.all(np.isfinite(node_rows)) and (pressure.size == 0
                                                        or float(pressure.min()) >= 0.0)):
            raise TableError(f"{path}: not a contact table (non-finite values or a negative "
                             "pressure)")
        patches: list[tuple[list[TablePatch], list[TablePatch]]] = [
            ([], []) for _ in range(len(node_rows))]
        for (k, side, nb, na, off), fl in zip(meta, floats):
            p = np.array(pressure[off:off + nb * na]).reshape(nb, na)
            patches[k][side].append(TablePatch(fl[0:3].copy(), fl[3:6].copy(), fl[6:9].copy(),
                                               fl[9:12].copy(), float(fl[12]), float(fl[13]),
                                               float(fl[14]), float(fl[15]), p, float(fl[16]),
                                               float(fl[17])))
        nodes = [TableNode(float(r), float(z), (tuple(ps[0]), tuple(ps[1])), bool(d))
                 for (r, z, d), ps in zip(node_rows, patches)]
        n_grid = len(grid.dys) * len(grid.yaws)
        table = cls(grid, load, nodes[:n_grid])
        k, a, r = n_grid, 0, 0
        for j, n_dys, n_yaws in (tuple(int(v) for v in w) for w in windows):
            window_dys = tuple(float(v) for v in axes[a:a + n_dys])
            window_yaws = tuple(float(v) for v in axes[a + n_dys:a + n_dys + n_yaws])
            a += n_dys + n_yaws
            sub = []
            for ref in refs[r:r + n_dys * n_yaws]:
                if ref >= 0:
                    sub.append(table.nodes[int(ref)])
                else:
                    sub.append(nodes[k])
                    k += 1
            r += n_dys * n_yaws
            table.refined.setdefault(j, []).append(
                cls(TableGrid(window_dys, window_yaws), load, sub))
        if k != len(nodes) or r != len(refs):
            raise TableError(f"{path}: not a contact table (its windows do not fill it)")
        return table


def table_key(wheelset: Wheelset, grid: TableGrid, load: float, refine: int = 0) -> str:
    """Return a digest of everything a table's nodes depend on (``grid``: before refining)."""
    h = hashlib.sha256()
    h.update(f"v{TABLE_VERSION};{grid.dys!r};{grid.yaws!r};{load!r};r{refine};"
             f"y{YAW_REFINE},{YAW_WINDOW!r},{YAW_EVENT_TURN!r};{wheelset.cell!r};"
             f"{wheelset.shear_modulus!r};{wheelset.poisson_ratio!r};{wheelset.separation!r};"
             f"{wheelset.placement!r}".encode())
    for side in SIDES:
        rail, wheel = wheelset.rails[side], wheelset.wheels[side]
        for a in (rail.y, rail.z, wheel.axial, wheel.radius):
            h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    return h.hexdigest()[:32]


class BuildProgress:
    """``progress(done, total)`` of a table build as log lines with the time left.

    A line at most every ``period`` seconds (and at the end of each pass),
    the time left extrapolated from the pass's own rate: the refinement's
    passes solve fewer, costlier nodes (the flange's), so each pass starts
    its own clock.
    """

    def __init__(self, log: Callable[[str], None], period: float = 5.0) -> None:
        self._log = log
        self._period = period
        self._start = time.monotonic()
        self._last = self._start  # the last line logged
        self._called = self._start  # the last call: where a new pass's clock starts
        self._total: int | None = None

    def __call__(self, done: int, total: int) -> None:
        """Log the share of the pass done and the estimate of the time left."""
        now = time.monotonic()
        if self._total is not None and total != self._total:  # the next pass began
            self._start = self._last = self._called
        self._total, self._called = total, now
        if done < total and now - self._last < self._period:
            return
        self._last = now
        elapsed = now - self._start
        left = elapsed * (total - done) / max(done, 1)
        share = 100.0 * done / max(total, 1)
        self._log(f"contact table: {done} of {total} nodes solved ({share:.0f}%), "
                  f"about {left:.0f} s left in this pass")


def cached_table(wheelset: Wheelset, grid: TableGrid, load: float, cache_dir: Path | None, *,
                 refine: int = 0, workers: int | None = None,
                 log: Callable[[str], None] | None = None) -> ContactTable:
    """Return the table from ``cache_dir`` if built for these inputs, else build and keep it.

    ``workers``: processes for a build (default: the machine's cores when
    there are at least 200 nodes).
    """
    key = table_key(wheelset, grid, load, refine)
    path = cache_dir / f"contact_table_{key}.npz" if cache_dir is not None else None
    if path is not None and path.exists():
        try:
            return ContactTable.read(path, key)
        except TableError as e:
            if log:
                log(f"contact table: rebuilding, {e}")
    n = len(grid.dys) * len(grid.yaws)
    if workers is None:
        workers = min(os.cpu_count() or 1, 8) if n >= 200 else 1
    if log:
        log(f"contact table: solving {n} nodes ({len(grid.dys)} shifts x {len(grid.yaws)} yaws) "
            f"in {workers} process(es); cached in {path}" if path else "")
    table = ContactTable.build(wheelset, grid, load, workers=workers, refine=refine,
                               progress=BuildProgress(log) if log else None)
    if log and refine:
        windows = [w for v in table.refined.values() for w in v]
        inner = sum(len(w.nodes) for w in windows)
        log(f"contact table: {len(table.grid.dys) - len(grid.dys)} shifts added where "
            f"neighbouring nodes differed ({len(table.nodes)} nodes in all), {inner} nodes "
            f"in {len(windows)} windows refined in yaw around the flanges' take-overs")
    if path is not None:
        try:
            table.save(path, key)
        except OSError as e:
            if log:
                log(f"contact table: not cached ({e})")
    return table


__all__ = ["BuildProgress", "ContactTable", "MATCH_ANGLE", "MATCH_DISTANCE", "TABLE_VERSION",
           "TableError", "TableGrid", "TableLookup", "TableNode", "TablePatch", "TableRangeError",
           "blend", "cached_table", "levelled_roll", "match", "solve_node", "table_key", "warm_up",
           "BlendPlan"]
