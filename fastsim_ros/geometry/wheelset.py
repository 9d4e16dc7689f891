"""A wheelset on its track: both wheels' contact patches for a pose and the vertical loads.

:class:`Wheelset` places the profiles (:mod:`~fastsim_ros.geometry.placement`),
finds each wheel's interpenetration regions (:mod:`~fastsim_ros.geometry.search`),
builds a planar grid with the undeformed gap for each
(:mod:`~fastsim_ros.geometry.planar`) and solves the normal problem on it
with the package's normal solver.  The patches of one wheel belong to one
rigid wheel: they share its vertical position.

Either the vertical position is given (the pose's ``dz``) or the vertical
force on each wheel (CONTACT's "vertical force prescribed": the wheel is
lowered until the contact forces' vertical component equals the load).
That component includes the creep forces' (on a flange, inclined 60-70
degrees, a creep force of 0.3 N moves the balance by a third), so the
caller passes ``tangential``: a function that returns each patch's creep
force in the track frame.  The geometry computes no creepage itself: the
pipeline's rigid-body formula does.

Without a given roll, the roll is solved so that both wheels carry their
loads at one vertical position of the wheelset centre (a rigid wheelset);
with a given roll and loads, each wheel's vertical position is solved on
its own, as CONTACT does per side (the two then differ by what the roll
did not account for).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.checks import check_material
from fastsim_ros.geometry import normal_fast
from fastsim_ros.geometry.errors import (BalanceError, DerailmentError, NoContactError,
                                         PoseError)
from fastsim_ros.geometry.placement import (Placement, Pose, RailSide, WheelSide, place_rail,
                                            place_wheel)
from fastsim_ros.geometry.planar import PlanarGrid, grid_extent, planar_grid
from fastsim_ros.geometry.profiles import Profile
from fastsim_ros.geometry.search import A_SEP, D_COMB, D_SEP, Region, find_regions, merged

FloatArray = NDArray[np.float64]
Side = Literal["left", "right"]
SIDES: tuple[Side, Side] = ("left", "right")
Vector = tuple[float, float, float]
#: a patch's creep force (rail on wheel, track frame, N) for each patch of a wheel
TangentialForces = Callable[[Side, Sequence["WheelPatch"]], Sequence[Vector]]

#: the vertical force balance is solved to this share of the load (1 mN at 10 kN: far
#: below what the normal solver resolves; the node and the command line run the same
#: steps, so they agree to rounding whatever this is)
LOAD_TOLERANCE = 1e-7
#: the balance's bracket on the vertical position is closed at this width (m); the force
#: may step there (a cell entering the contact): then it holds to STEP_LOAD_TOLERANCE
STEP_TOLERANCE = 1e-13
STEP_LOAD_TOLERANCE = 1e-3
#: the roll is solved until the wheels' vertical positions agree to this (m)
ROLL_TOLERANCE = 1e-10
MAX_ITERATIONS = 60
#: the half-widths (rad) tried in turn for the bracket of the roll that levels both wheels'
#: loads at a given vertical position
ROLL_STEPS = (2.5e-4, 1e-3, 4e-3, 1e-2)
#: a wheel's first trial interpenetration (m, vertical) at 10 kN, scaled with load^(2/3)
TRIAL_APPROACH = 20e-6
#: a patch with fewer cells in contact is dropped (the node's adapter calls it
#: degenerate); the wheel's other patches then carry its share of the load
MIN_PATCH_CELLS = 4
#: the most patches per wheel (the contacts name two: the tread's and a second);
#: more regions are combined, nearest first
MAX_PATCHES = 2


@dataclass(frozen=True, eq=False)
class WheelPatch:
    """One solved contact patch of one wheel.

    ``grid``: the planar grid in the side frame with the undeformed gap;
    ``pressure``: normal pressure (Pa) on its cells; ``approach``: the
    rigid approach along the normal (m, the largest interpenetration of the
    undeformed surfaces); ``load``: ``N = sum p dA`` (N); ``region``: the
    interpenetration region it came from (side frame).  ``points`` and
    ``normal``: the cell centres (``(ny, nx, 3)``, m) and the plane's normal
    pointing into the wheel, in the wheelset frame of ``frame_pose``;
    ``points_track``, ``normal_track``: the same in the track frame;
    ``reference``: CONTACT's weighted reference point and ``origin``: the
    pressure centroid, both in the track frame (m).
    """

    side: Side
    grid: PlanarGrid
    pressure: FloatArray
    approach: float
    load: float
    region: Region
    points: FloatArray
    normal: FloatArray
    normal_track: FloatArray
    reference: Vector
    origin: Vector
    angle: float
    points_track: FloatArray
    frame_pose: Pose

    def cloud_arrays(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Return ``points, normal, pressure`` of the patch cloud, rows along the frame's ``y``.

        The contact frame's ``y = z x x``; on the right wheel
        the side frame's lateral axis runs the other way, so its rows are
        turned round: the node's patches all run like a rig's.
        """
        ey = np.cross(self.normal, self.points[0, -1] - self.points[0, 0])
        rows = self.points[-1, 0] - self.points[0, 0] if self.points.shape[0] > 1 else ey
        if float(np.dot(rows, ey)) < 0.0:
            return self.points[::-1], self.normal, self.pressure[::-1]
        return self.points, self.normal, self.pressure

    def in_frame(self, pose: Pose, nominal_radius: float) -> WheelPatch:
        """Return the patch with ``points`` and ``normal`` in the wheelset frame of ``pose``."""
        if pose == self.frame_pose:
            return self
        rot = pose.rotation()
        centre = np.array([0.0, pose.dy, nominal_radius + pose.dz])
        points = (self.points_track - centre) @ rot
        points.setflags(write=False)
        return replace(self, points=points, normal=rot.T @ self.normal_track, frame_pose=pose)

    @property
    def cells(self) -> int:
        """Return the cells in contact (positive pressure)."""
        return int(np.count_nonzero(self.pressure > 0.0))


@dataclass(frozen=True, eq=False)
class WheelContact:
    """One wheel's contact: its patches (tread first), vertical position and forces.

    ``dz``: the wheelset centre's vertical position at which it was solved
    (m); ``normal_force``: the sum of the patches' normal forces in the
    track frame (N); ``tangential``: the creep forces the balance included.
    """

    side: Side
    patches: tuple[WheelPatch, ...]
    dz: float
    normal_force: Vector
    tangential: tuple[Vector, ...] = field(default=())

    @property
    def vertical_force(self) -> float:
        """Return the vertical force of the rail on the wheel (N), creep forces included."""
        return self.normal_force[2] + sum(t[2] for t in self.tangential)


@dataclass(frozen=True, eq=False)
class WheelsetContact:
    """Both wheels' contacts at one pose (``roll`` and ``dz`` as solved or given)."""

    pose: Pose
    wheels: tuple[WheelContact, WheelContact]


class Wheelset:
    """Profiles, placement and material of a wheelset on its track (or rig).

    ``wheel``, ``rail``: the left side's profiles (canonical form); the
    right side's are their mirror images unless ``right_wheel`` /
    ``right_rail`` are given (also in canonical form: ``y`` to the field
    side).  ``cell``: the potential contact grid's cell size (m);
    ``shear_modulus`` (Pa) and ``poisson_ratio``: combined material.
    """

    def __init__(self, wheel: Profile, rail: Profile, placement: Placement | None = None, *,
                 right_wheel: Profile | None = None, right_rail: Profile | None = None,
                 cell: float = 2e-4, shear_modulus: float = 8.0e10,
                 poisson_ratio: float = 0.28, a_sep: float = A_SEP, d_sep: float = D_SEP,
                 d_comb: float = D_COMB) -> None:
        check_material(poisson_ratio, shear_modulus)
        if not (math.isfinite(cell) and 2e-5 <= cell <= 5e-3):
            raise PoseError(f"cell size must lie in [2e-5, 5e-3] m, got {cell!r}")
        self.placement = placement or Placement()
        self.cell = float(cell)
        self.shear_modulus = float(shear_modulus)
        self.poisson_ratio = float(poisson_ratio)
        self.separation = (a_sep, d_sep, d_comb)
        #: the right side is the left's mirror image (a contact table solves one wheel)
        self.symmetric = right_wheel is None and right_rail is None
        self.rails: dict[Side, RailSide] = {
            "left": place_rail(rail, self.placement),
            "right": place_rail(right_rail or rail, self.placement)}
        self.wheels: dict[Side, WheelSide] = {
            "left": place_wheel(wheel, self.placement),
            "right": place_wheel(right_wheel or wheel, self.placement)}
        self._normal = normal_fast.NormalSolver(shear_modulus=self.shear_modulus,
                                                nu=self.poisson_ratio)

    # ------------------------------------------------------------------ one wheel

    def side_pose(self, side: Side, pose: Pose) -> Pose:
        """Return the pose in the side's frame (the right side's is mirrored in ``y``)."""
        return pose if side == "left" else pose.mirrored()

    def regions(self, side: Side, pose: Pose) -> list[Region]:
        """Return the interpenetration regions of one wheel at a pose (side frame)."""
        a_sep, d_sep, d_comb = self.separation
        _, regions = find_regions(self.rails[side], self.wheels[side], self.side_pose(side, pose),
                                  self.placement.nominal_radius, self.cell, a_sep=a_sep,
                                  d_sep=d_sep, d_comb=d_comb)
        while len(regions) > MAX_PATCHES:
            gaps = [regions[k + 1].y_range[0] - regions[k].y_range[1]
                    for k in range(len(regions) - 1)]
            k = int(np.argmin(gaps))
            both = merged(regions[k], regions[k + 1])
            z = float(np.interp(both.reference[1], self.rails[side].y, self.rails[side].z))
            regions[k:k + 2] = [replace(both, reference=(both.reference[0], both.reference[1], z))]
        return regions

    def vertical_gap(self, side: Side, pose: Pose) -> float:
        """Return the smallest vertical gap between the wheel's locus and the rail (m)."""
        from fastsim_ros.geometry.search import vertical_gap
        locus = vertical_gap(self.rails[side], self.wheels[side], self.side_pose(side, pose),
                             self.placement.nominal_radius, self.cell)
        return float(np.min(locus.gap))

    def patches(self, side: Side, pose: Pose) -> tuple[WheelPatch, ...]:
        """Return one wheel's solved patches at a given pose (vertical position given)."""
        sp = self.side_pose(side, pose)
        out = []
        for region in self.regions(side, pose):
            patch = self._patch(side, pose, sp, region)
            if patch.cells >= MIN_PATCH_CELLS:
                out.append(patch)
        return tuple(out)

    def _patch(self, side: Side, pose: Pose, sp: Pose, region: Region) -> WheelPatch:
        rail, wheel = self.rails[side], self.wheels[side]
        r0 = self.placement.nominal_radius
        extent = grid_extent(region, rail, self.cell)
        for _ in range(8):
            grid = planar_grid(region, rail, wheel, sp, r0, self.cell, extent)
            approach = -float(grid.gap.min())
            pressure = self._normal.solve(grid.gap + approach, approach, grid.dx, grid.ds)
            grow = _edges_in_contact(pressure)
            if not any(grow):
                break
            lo_x, hi_x, lo_s, hi_s = extent
            extent = (lo_x - 2 * grow[0], hi_x + 2 * grow[1], lo_s - 2 * grow[2],
                      hi_s + 2 * grow[3])
        load = float(pressure.sum()) * grid.dx * grid.ds
        grid, pressure = _cropped(grid, pressure)
        return self._placed(side, pose, grid, pressure, approach, load, region)

    def _placed(self, side: Side, pose: Pose, grid: PlanarGrid, pressure: FloatArray,
                approach: float, load: float, region: Region) -> WheelPatch:
        """Express a side-frame patch in the track and wheelset frames."""
        mirror = np.array([1.0, 1.0 if side == "left" else -1.0, 1.0])
        # the patch lies in the contact plane moved by the approach onto the undeformed
        # wheel at its deepest point: Kalker's rigid slip compares the rail's surface point
        # with the wheel's one approach deeper (CONTACT's point Q, ``wr_creep_cref``), and
        # with the patch in this plane the pipeline's creepages at the pressure centroid
        # give CONTACT's planar rigid slip field (a rolling radius off by the approach,
        # 20 um, would move xi by 4e-5: 200 N of Fx on a tread)
        centres_t = (grid.centres() - approach * grid.normal[None, None, :]) * mirror
        normal_t = grid.normal * mirror
        rot = pose.rotation()
        centre = np.array([0.0, pose.dy, self.placement.nominal_radius + pose.dz])
        points_w = (centres_t - centre) @ rot
        normal_w = rot.T @ normal_t
        ref = np.asarray(region.reference) * mirror
        total = float(pressure.sum())
        if total > 0.0:
            origin = tuple(float(v) for v in np.tensordot(pressure, centres_t, axes=2) / total)
        else:
            origin = tuple(float(v) for v in ref)
        points_w.setflags(write=False)
        centres_t.setflags(write=False)
        return WheelPatch(side, grid, pressure, approach, load, region, points_w, normal_w,
                          normal_t, (float(ref[0]), float(ref[1]), float(ref[2])),
                          (origin[0], origin[1], origin[2]), grid.angle, centres_t, pose)

    def wheel_at(self, side: Side, pose: Pose,
                 tangential: TangentialForces | None = None) -> WheelContact:
        """Return one wheel's contact with the vertical position given by the pose."""
        patches = self.patches(side, pose)
        forces = tuple(tangential(side, patches)) if (tangential and patches) else ()
        return WheelContact(side, patches, pose.dz, _normal_force(patches), forces)

    def lifted(self, side: Side, pose: Pose) -> WheelContact:
        """Return a wheel that carries no load: no patches, no force (a lifted wheel)."""
        return WheelContact(side, (), pose.dz, (0.0, 0.0, 0.0))

    def wheel_loaded(self, side: Side, pose: Pose, load: float,
                     tangential: TangentialForces | None = None) -> WheelContact:
        """Return one wheel's contact where its vertical force is ``load`` (N).

        The wheelset centre's vertical position is varied (the pose's
        ``dz`` is the start); roll, yaw and shift stay.  The force grows
        like ``approach^1.5`` (Hertz), so the secant runs on ``F^(2/3)``.
        """
        if not (math.isfinite(load) and 0.0 < load <= 1e7):
            raise PoseError(f"the vertical load must lie in (0, 1e7] N, got {load!r}")
        gap = self.vertical_gap(side, pose)
        dz_touch = pose.dz - gap
        target = load ** (2.0 / 3.0)
        trial = TRIAL_APPROACH * (load / 1e4) ** (2.0 / 3.0)
        points = [(dz_touch, -target)]
        dz = dz_touch - trial
        best: WheelContact | None = None
        for _ in range(MAX_ITERATIONS):
            contact = self.wheel_at(side, replace(pose, dz=dz), tangential)
            force = contact.vertical_force
            if best is None or abs(force - load) < abs(best.vertical_force - load):
                best = contact
            if abs(force - load) <= LOAD_TOLERANCE * load:
                return contact
            phi = math.copysign(abs(force) ** (2.0 / 3.0), force) - target
            points.append((dz, phi))
            dz = _next_position(points, dz_touch)
            if _bracket_width(points) <= STEP_TOLERANCE:
                # the force steps over the load here (a cell of the grid entering or
                # leaving the contact): the nearest side of the step is the balance
                break
        if best is None:  # pragma: no cover - MAX_ITERATIONS > 0
            raise BalanceError("no vertical position found")
        if abs(best.vertical_force - load) <= STEP_LOAD_TOLERANCE * load:
            return best
        raise BalanceError(f"the {side} wheel's vertical balance did not converge: "
                           f"{best.vertical_force:.6g} N for a load of {load:.6g} N")

    # ------------------------------------------------------------------ both wheels

    def solve(self, pose: Pose, *, loads: tuple[float, float] | None = None,
              solve_roll: bool = False,
              tangential: TangentialForces | None = None) -> WheelsetContact:
        """Return both wheels' contacts.

        ``loads``: the vertical load on the left and right wheel (N), or
        ``None`` for the pose's vertical position.  ``solve_roll``: vary the
        roll so that both wheels carry their loads at one vertical position
        (with ``loads``) or carry equal loads (without).
        """
        if loads is None and not solve_roll:
            return WheelsetContact(pose, (self.wheel_at("left", pose, tangential),
                                          self.wheel_at("right", pose, tangential)))
        if loads is not None and not solve_roll:
            if loads[0] <= 0.0 and loads[1] <= 0.0:  # nothing presses the wheels down
                return WheelsetContact(pose, (self.lifted("left", pose),
                                              self.lifted("right", pose)))
            left = (self.wheel_loaded("left", pose, loads[0], tangential) if loads[0] > 0.0
                    else None)
            right = (self.wheel_loaded("right", pose, loads[1], tangential) if loads[1] > 0.0
                     else None)
            heights = [w.dz for w in (left, right) if w is not None]
            frame = replace(pose, dz=sum(heights) / len(heights))
            return self._one_frame(frame, left or self.lifted("left", frame),
                                   right or self.lifted("right", frame))
        return self._solve_roll(pose, loads, tangential)

    def _one_frame(self, pose: Pose, left: WheelContact, right: WheelContact) -> WheelsetContact:
        """Both wheels' patches in the one wheelset frame of ``pose``.

        With the roll given, each wheel carries its load at its own height
        (CONTACT's half-wheelset cases); the frame's origin is the mean, so
        each wheel's patches lie where its own solve put them, expressed
        from there (their heights differ by what the roll did not balance,
        micrometres for a roll near the equilibrium).
        """
        r0 = self.placement.nominal_radius
        wheels = tuple(replace(w, patches=tuple(p.in_frame(pose, r0) for p in w.patches))
                       for w in (left, right))
        return WheelsetContact(pose, (wheels[0], wheels[1]))

    def _solve_roll(self, pose: Pose, loads: tuple[float, float] | None,
                    tangential: TangentialForces | None) -> WheelsetContact:
        half_track = self.placement.wheel_offset
        roll = pose.roll
        if loads is not None:
            # both wheels at one centre height: the root of m(roll) = dz_L - dz_R.  A roll
            # d raises the left wheel by y_L d (m' = -2 y_L) on treads; on a flange the
            # wheel also slides sideways, so secant steps, kept in a bracket once found
            # (Illinois), take it from the first geometric step on
            best: tuple[float, WheelContact, WheelContact, Pose] | None = None
            tried: list[tuple[float, float]] = []
            for _ in range(MAX_ITERATIONS):
                _check_roll(roll)
                p = replace(pose, roll=roll)
                left = self.wheel_loaded("left", p, loads[0], tangential)
                right = self.wheel_loaded("right", p, loads[1], tangential)
                mismatch = left.dz - right.dz
                if best is None or abs(mismatch) < abs(best[0]):
                    best = (mismatch, left, right, p)
                if abs(mismatch) <= ROLL_TOLERANCE:
                    break
                tried.append((roll, mismatch))
                following = _next_roll(tried, half_track)
                if following is None:  # the bracket closed on a step of the mismatch
                    break
                roll = following
            if best is None or abs(best[0]) > 1e3 * ROLL_TOLERANCE:
                raise BalanceError("the roll that levels both wheels was not found")
            _, left, right, p = best
            return self._one_frame(replace(p, dz=0.5 * (left.dz + right.dz)), left, right)
        # vertical position given: the roll that makes both wheels' vertical forces equal.
        # Their difference falls as the roll lowers one wheel and raises the other, and is
        # zero, not a root, over the rolls where both wheels are off the rails: a wheelset
        # held above them is lifted (no patches, not an error) at the roll it was given
        f_0 = self._load_difference(pose, tangential)
        if f_0 == 0.0:
            return self.solve(pose, tangential=tangential)
        # the bracket grows from a quarter of a milliradian (the levelling roll of a shifted
        # wheelset is a fraction of one): a roll of 10 mrad at once sank a wheel by 7.5 mm,
        # past the rail's profile (a derailment) or into a patch of 100,000 cells
        bracket = None
        derailed = [False, False]
        for step in ROLL_STEPS:
            for side, end in enumerate((roll + step, roll - step)):
                if derailed[side]:
                    continue
                try:
                    f_end = self._load_difference(replace(pose, roll=end), tangential)
                except DerailmentError:
                    derailed[side] = True  # the root lies nearer, if on this side
                    continue
                if f_end == 0.0:  # both wheels off the rails there: lifted at that roll
                    return self.solve(replace(pose, roll=end), tangential=tangential)
                if f_end * f_0 < 0.0:
                    bracket = (roll, f_0, end, f_end)
                    break
            if bracket is not None:
                break
        if bracket is None:
            raise NoContactError(f"no roll within +-{1e3 * ROLL_STEPS[-1]:g} mrad gives both "
                                 f"wheels equal loads")
        lo, f_lo, hi, f_hi = bracket
        for _ in range(MAX_ITERATIONS):
            mid = hi - f_hi * (hi - lo) / (f_hi - f_lo)
            f_mid = self._load_difference(replace(pose, roll=mid), tangential)
            if f_mid == 0.0:
                hi = mid
                break
            if abs(hi - lo) < 1e-12:
                break
            if f_mid * f_hi < 0.0:
                lo, f_lo = hi, f_hi
            else:
                f_lo *= 0.5  # Illinois: keep the bracket shrinking on both sides
            hi, f_hi = mid, f_mid
        return self.solve(replace(pose, roll=hi), tangential=tangential)

    def _load_difference(self, pose: Pose, tangential: TangentialForces | None) -> float:
        left = self.wheel_at("left", pose, tangential)
        right = self.wheel_at("right", pose, tangential)
        return left.vertical_force - right.vertical_force


def _check_roll(roll: float) -> None:
    if not abs(roll) <= 0.2:
        raise NoContactError(f"the roll that levels both wheels ran away ({roll:.4g} rad)")


def _normal_force(patches: Sequence[WheelPatch]) -> Vector:
    f = np.zeros(3)
    for p in patches:
        f += p.load * p.normal_track
    return (float(f[0]), float(f[1]), float(f[2]))


def _cropped(grid: PlanarGrid, pressure: FloatArray) -> tuple[PlanarGrid, FloatArray]:
    """Return the grid and pressure cut to the cells in contact and one empty cell around.

    The potential contact area is about three times the contact; the patch
    the node publishes and solves needs only the contact (and keeps an
    empty border, as the bundled bags' patches do).
    """
    rows = np.flatnonzero(pressure.any(axis=1))
    cols = np.flatnonzero(pressure.any(axis=0))
    if rows.size == 0:
        return grid, pressure
    j0, j1 = max(0, int(rows[0]) - 1), min(pressure.shape[0], int(rows[-1]) + 2)
    i0, i1 = max(0, int(cols[0]) - 1), min(pressure.shape[1], int(cols[-1]) + 2)
    gap = grid.gap[j0:j1, i0:i1]
    gap.setflags(write=False)
    cut = replace(grid, x0=grid.x0 + i0 * grid.dx, s0=grid.s0 + j0 * grid.ds, gap=gap)
    return cut, np.ascontiguousarray(pressure[j0:j1, i0:i1])


def _edges_in_contact(pressure: FloatArray) -> tuple[int, int, int, int]:
    """Which grid edges carry pressure: ``(x low, x high, s low, s high)`` as 0/1."""
    return (int(bool(np.any(pressure[:, 0] > 0.0))), int(bool(np.any(pressure[:, -1] > 0.0))),
            int(bool(np.any(pressure[0, :] > 0.0))), int(bool(np.any(pressure[-1, :] > 0.0))))


def _next_roll(tried: list[tuple[float, float]], half_track: float) -> float | None:
    """Return the next roll (rad) for the levelling, or ``None`` once the bracket closed.

    ``tried``: ``(roll, dz_left - dz_right)``.  The first step is the
    geometric one; then secants, kept inside the bracket once the mismatch
    changed sign (bisection where a secant leaves it).
    """
    roll, m = tried[-1]
    if len(tried) == 1:
        return roll + m / (2.0 * half_track)
    pos = [(r, f) for r, f in tried if f > 0.0]
    neg = [(r, f) for r, f in tried if f < 0.0]
    (r1, f1), (r2, f2) = tried[-2], tried[-1]
    guess = r2 - f2 * (r2 - r1) / (f2 - f1) if f2 != f1 else r2 + m / (2.0 * half_track)
    if pos and neg:
        # the mismatch falls as the roll grows: the root lies between the largest
        # roll still positive and the smallest negative one
        lo = max(r for r, _ in pos)
        hi = min(r for r, _ in neg)
        lo, hi = min(lo, hi), max(lo, hi)
        if hi - lo <= 1e-13:
            return None
        if not lo < guess < hi:
            guess = 0.5 * (lo + hi)
    return guess


def _bracket_width(points: list[tuple[float, float]]) -> float:
    """Return the width of the bracket the balance keeps (``inf`` before there is one)."""
    below = [z for z, f in points if f < 0.0]
    above = [z for z, f in points if f > 0.0]
    if not below or not above:
        return math.inf
    return abs(min(below) - max(above))


def _next_position(points: list[tuple[float, float]], dz_touch: float) -> float:
    """Return the next vertical position: a safeguarded secant on ``F^(2/3) - L^(2/3)``.

    ``phi`` falls as the wheel is lowered (``dz`` falls); the root is kept
    bracketed between the lowest ``dz`` with ``phi < 0``... and the highest
    with ``phi > 0`` once both exist.
    """
    below = [(z, f) for z, f in points if f < 0.0]
    above = [(z, f) for z, f in points if f > 0.0]
    (z1, f1), (z2, f2) = points[-2], points[-1]
    guess = z2 - f2 * (z2 - z1) / (f2 - f1) if f2 != f1 else z2
    if below and above:
        # bracket: the highest dz with too much force, the lowest with too little
        z_hi_f = max(above, key=lambda p: p[0])[0]   # overloaded wheels are lower: dz smaller
        z_lo_f = min(below, key=lambda p: p[0])[0]
        lo, hi = min(z_hi_f, z_lo_f), max(z_hi_f, z_lo_f)
        if not lo < guess < hi:
            guess = 0.5 * (lo + hi)
    elif not above:
        # not yet loaded enough: go at least as deep again
        depth = dz_touch - z2
        guess = min(guess, z2 - max(depth, 1e-7))
    return guess
