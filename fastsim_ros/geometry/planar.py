"""The planar potential contact grid of a region and the undeformed gap on it.

CONTACT's planar contact approach (DISCNS D = 2; its ``set_planar_potcon``
and ``wr_ud_planar``): the contact plane passes through the region's
reference point, its normal ``n`` turned by the contact angle from the
track's vertical (pointing into the wheel).  One difference of axes: the
grid's ``x`` is the wheelset's ``x`` projected on the plane (the node's
contact frame, so that the node's patch adapter finds a regular grid), not
the track's; the two differ by the yaw angle.  The lateral axis is ``e_s =
n x e_x`` (towards the field side).  Cells are centred at multiples of the
cell size from the reference point; the grid spans the region's
interpenetration (its ``x`` range from the contact locus, its lateral range
the arc length of the rail between the region's ends), plus one cell.

The undeformed gap at a cell centre ``G`` is measured along ``n``: the rail
(a prism along the track) is met where the line ``G + t n`` crosses its
profile, the wheel (a body of revolution) where ``|Q_xz| = r(Q_y)`` with ``Q
= R^T (G + t n - C)`` in wheel axes, found by Newton's method (quadratic,
converged to 1e-13 m).  ``gap = t_wheel - t_rail``: negative where the
undeformed bodies interpenetrate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.geometry.errors import DerailmentError
from fastsim_ros.geometry.placement import Pose, RailSide, WheelSide
from fastsim_ros.geometry.search import Region

FloatArray = NDArray[np.float64]

#: Newton's iterations for the wheel surface along the normal (converges in 3-4)
NEWTON_ITERATIONS = 12
NEWTON_TOLERANCE = 1e-13


@dataclass(frozen=True, eq=False)
class PlanarGrid:
    """A planar potential contact grid in the side frame, with the undeformed gap.

    ``origin``: the reference point (m); ``normal``, ``e_x``, ``e_s``: unit
    vectors; cell ``[j, i]`` is centred at ``origin + (x0 + i dx) e_x + (s0
    + j ds) e_s``; ``gap``: undeformed gap (m, ``(ny, nx)``, negative =
    interpenetration); ``angle``: the contact angle (rad).
    """

    origin: FloatArray
    normal: FloatArray
    e_x: FloatArray
    e_s: FloatArray
    x0: float
    s0: float
    dx: float
    ds: float
    gap: FloatArray
    angle: float

    @property
    def shape(self) -> tuple[int, int]:
        """Return ``(ny, nx)``."""
        return (int(self.gap.shape[0]), int(self.gap.shape[1]))

    def centres(self) -> FloatArray:
        """Return the cell centres ``(ny, nx, 3)`` on the plane, in the side frame (m)."""
        ny, nx = self.shape
        u = self.x0 + self.dx * np.arange(nx)
        v = self.s0 + self.ds * np.arange(ny)
        return (self.origin[None, None, :] + u[None, :, None] * self.e_x[None, None, :]
                + v[:, None, None] * self.e_s[None, None, :])


def plane_axes(angle: float, pose: Pose) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Return ``n, e_x, e_s`` of the contact plane at ``angle`` (side frame)."""
    normal = np.array([0.0, -math.sin(angle), math.cos(angle)])
    wx = pose.rotation()[:, 0]
    e_x = wx - float(np.dot(wx, normal)) * normal
    e_x /= float(np.linalg.norm(e_x))
    e_s = np.cross(normal, e_x)
    return normal, e_x, e_s


def grid_extent(region: Region, rail: RailSide, cell: float,
                margin: int = 1) -> tuple[int, int, int, int]:
    """Return the cell index ranges ``ix_lo, ix_hi, iy_lo, iy_hi`` (CONTACT's guard: a cell)."""
    x_ref, y_ref, _ = region.reference
    arc_ref = float(np.interp(y_ref, rail.y, rail.arc))
    s_lo = float(np.interp(region.y_range[0], rail.y, rail.arc)) - arc_ref
    s_hi = float(np.interp(region.y_range[1], rail.y, rail.arc)) - arc_ref
    x_lo, x_hi = region.x_range[0] - x_ref, region.x_range[1] - x_ref
    return (math.floor(x_lo / cell) - margin, math.ceil(x_hi / cell) + margin,
            math.floor(s_lo / cell) - margin, math.ceil(s_hi / cell) + margin)


def planar_grid(region: Region, rail: RailSide, wheel: WheelSide, pose: Pose,
                nominal_radius: float, cell: float,
                extent: tuple[int, int, int, int] | None = None) -> PlanarGrid:
    """Return the region's planar grid and the undeformed gap on it (side frame, m).

    ``extent``: cell index ranges (:func:`grid_extent` by default), given
    when a solution showed the contact reaching the grid's edge.
    """
    ix_lo, ix_hi, iy_lo, iy_hi = grid_extent(region, rail, cell) if extent is None else extent
    normal, e_x, e_s = plane_axes(region.angle, pose)
    origin = np.asarray(region.reference, dtype=np.float64)
    shape = (iy_hi - iy_lo + 1, ix_hi - ix_lo + 1)
    grid = PlanarGrid(origin, normal, e_x, e_s, ix_lo * cell, iy_lo * cell, cell, cell,
                      np.zeros(shape), region.angle)
    points = grid.centres()
    t_rail = _rail_distance(points, normal, rail, region.angle)
    t_wheel = _wheel_distance(points, normal, t_rail, wheel, pose, nominal_radius)
    gap = t_wheel - t_rail
    gap.setflags(write=False)
    return PlanarGrid(origin, normal, e_x, e_s, grid.x0, grid.s0, cell, cell, gap, region.angle)


def _rail_distance(points: FloatArray, normal: FloatArray, rail: RailSide,
                   angle: float) -> FloatArray:
    """Distance along ``normal`` from each point to the rail surface (m)."""
    c, s = math.cos(angle), math.sin(angle)
    # coordinates in the plane's (lateral, normal) axes within the y-z plane
    sigma_rail = rail.y * c + rail.z * s
    nu_rail = -rail.y * s + rail.z * c
    sigma = points[..., 1] * c + points[..., 2] * s
    nu = -points[..., 1] * s + points[..., 2] * c
    lo, hi = float(sigma.min()), float(sigma.max())
    k_lo = int(np.searchsorted(np.maximum.accumulate(sigma_rail), lo)) - 2
    k_hi = int(np.searchsorted(np.maximum.accumulate(sigma_rail), hi)) + 2
    k_lo, k_hi = max(0, k_lo), min(sigma_rail.size, k_hi)
    part_sigma = sigma_rail[k_lo:k_hi]
    if part_sigma.size < 2 or np.any(np.diff(part_sigma) <= 0.0):
        raise DerailmentError(f"the rail surface folds back under the contact plane inclined "
                              f"at {math.degrees(angle):.1f} degrees")
    if lo < part_sigma[0] or hi > part_sigma[-1]:
        raise DerailmentError("the contact plane reaches beyond the rail profile")
    return np.interp(sigma, part_sigma, nu_rail[k_lo:k_hi]) - nu


def _wheel_distance(points: FloatArray, normal: FloatArray, start: FloatArray,
                    wheel: WheelSide, pose: Pose, nominal_radius: float) -> FloatArray:
    """Distance along ``normal`` from each point to the wheel surface (m), by Newton."""
    r = pose.rotation()
    centre = np.array([0.0, pose.dy, nominal_radius + pose.dz])
    m = r.T @ normal
    base = (points - centre) @ r  # R^T (G - C), rows are points
    t = start.copy()
    a_lo, a_hi = float(wheel.axial[0]), float(wheel.axial[-1])
    for _ in range(NEWTON_ITERATIONS):
        q = base + t[..., None] * m
        rho = np.hypot(q[..., 0], q[..., 2])
        a = q[..., 1]
        if float(a.min()) < a_lo or float(a.max()) > a_hi:
            raise DerailmentError("the contact plane reaches beyond the wheel profile")
        f = rho - np.interp(a, wheel.axial, wheel.radius)
        slope = np.interp(a, wheel.axial, wheel.slope)
        df = (q[..., 0] * m[0] + q[..., 2] * m[2]) / rho - slope * m[1]
        step = f / df
        t = t - step
        if float(np.abs(step).max()) < NEWTON_TOLERANCE:
            break
    return t
