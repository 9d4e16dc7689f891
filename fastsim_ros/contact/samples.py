"""Sample non-elliptical contact areas for validation, demos and tests.

Each sample is defined analytically (or by the normal problem on an analytic
gap), so it can be gridded at any resolution: the exact solver's values are
extrapolated over several grids, the online methods are judged on one.

- two semi-ellipses joined along ``y = 0`` (the paper's Table 5 family);
- an ellipse with a notch cut into one side (strips of two segments);
- two overlapping lobes of different size (a waisted, two-lobed area);
- an ellipse truncated just beyond its centre line (a patch cut off where a
  profile region ends): its longest chord lies on its edge;
- a flange-root patch: the normal contact of a gap whose lateral curvature
  is ten times larger on the flange side (``y > 0``) than on the tread side,
  as where a wheel's flange root runs against the rail's gauge corner.

Pressures of the analytic shapes are Hertz-like, ``p0 sqrt(1 - r^2)`` per
part, scaled to the requested load.
"""

from __future__ import annotations

import math

import numpy as np

from fastsim_ros.contact.area import GridArea, semi_ellipse_axes, semi_ellipses
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.normal import solve_normal

#: wheel-rail values used by the samples (Pa, -, m)
STEEL_G = 8.0e10
STEEL_NU = 0.28
WHEEL_RADIUS = 0.46


def _grid(xlim: tuple[float, float], ylim: tuple[float, float],
          cells: int) -> tuple[np.ndarray, np.ndarray, float, float]:
    dx = (xlim[1] - xlim[0]) / cells
    dy = (ylim[1] - ylim[0]) / cells
    x = xlim[0] + dx * (np.arange(cells) + 0.5)
    y = ylim[0] + dy * (np.arange(cells) + 0.5)
    return x, y, dx, dy


def _hertz_like(x: np.ndarray, y: np.ndarray, a: float, b: float) -> np.ndarray:
    return np.sqrt(np.clip(1.0 - (x / a) ** 2 - (y / b) ** 2, 0.0, None))


def _finish(x: np.ndarray, y: np.ndarray, dx: float, dy: float, p: np.ndarray,
            scale: float, load: float | None) -> GridArea:
    ar = GridArea(float(x[0]) * scale, float(y[0]) * scale, dx * scale, dy * scale, p)
    return ar.with_load(load) if load is not None else ar.with_pressure(
        (p > 0).astype(float))


def semi_ellipses_patch(g1: float, g2: float, *, cells: int, scale: float = 1.0,
                        load: float | None = None) -> GridArea:
    """Two semi-ellipses (``a_i b_i = scale^2/pi``), Hertz-like pressure per half with a load."""
    base = semi_ellipses(g1, g2, cells=cells)
    if load is None:
        return base.scaled(scale)
    (a1, b1), (a2, b2) = semi_ellipse_axes(g1), semi_ellipse_axes(g2)
    y = base.y[:, None]
    p = np.where(y < 0, _hertz_like(base.x[None, :], y, a1, b1),
                 _hertz_like(base.x[None, :], y, a2, b2)) * base.mask
    return base.with_pressure(p).scaled(scale).with_load(load)


def notched_ellipse(*, cells: int, scale: float = 1.0, load: float | None = None) -> GridArea:
    """Ellipse ``a/b = 0.8`` of area ``scale^2`` with a notch in its ``y > 0`` side.

    The notch removes ``|x| < 0.3 a``, ``y > 0.35 b``: strips there have two
    segments, and the area is asymmetric in ``y``.
    """
    a, b = semi_ellipse_axes(0.8)
    x, y, dx, dy = _grid((-a, a), (-b, b), cells)
    xx, yy = x[None, :], y[:, None]
    p = _hertz_like(xx, yy, a, b) * ~((np.abs(xx) < 0.3 * a) & (yy > 0.35 * b))
    return _finish(x, y, dx, dy, p, scale, load)


def two_lobes(*, cells: int, scale: float = 1.0, load: float | None = None) -> GridArea:
    """Two overlapping elliptical lobes of different size, joined by a waist."""
    lobes = ((0.0, -0.30, 0.50, 0.42), (0.06, 0.36, 0.32, 0.30))  # x_c, y_c, a, b
    x, y, dx, dy = _grid((-0.52, 0.52), (-0.74, 0.68), cells)
    xx, yy = x[None, :], y[:, None]
    # a Hertz-like peak that grows with the lobe's size
    p = np.maximum.reduce([a * _hertz_like(xx - xc, yy - yc, a, b) for xc, yc, a, b in lobes])
    return _finish(x, y, dx, dy, p, scale, load)


def truncated_ellipse(*, cells: int, scale: float = 1.0, load: float | None = None,
                      cut: float = 0.1) -> GridArea:
    """Ellipse ``a/b = 1.5`` (``a b = scale^2/pi``) without the part beyond ``y = cut * b``."""
    a, b = semi_ellipse_axes(1.5)
    x, y, dx, dy = _grid((-a, a), (-b, b), cells)
    xx, yy = x[None, :], y[:, None]
    p = _hertz_like(xx, yy, a, b) * (yy <= cut * b)
    return _finish(x, y, dx, dy, p, scale, load).cropped()


def flange_root_gap(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Return the undeformed gap (m) at ``(x, y)`` (m) of the flange-root sample.

    The wheel radius along ``x``; laterally 0.3 m of relative radius on the
    tread side (``y < 0``) and 0.03 m on the flange side.
    """
    ry = np.where(y < 0.0, 0.3, 0.03)
    return x**2 / (2.0 * WHEEL_RADIUS) + y**2 / (2.0 * ry)


def flange_root_patch(*, cells: int, load: float = 5.0e4) -> GridArea:
    """Solve the normal contact of :func:`flange_root_gap` under ``load`` (N), steel on steel.

    Solved by the exact normal solver on ``cells`` x ``cells`` cells over a
    box that holds the contact, then cropped to the cells in contact.
    """
    x, y, dx, dy = _grid((-7.5e-3, 7.5e-3), (-6.5e-3, 3.0e-3), cells)
    gap = flange_root_gap(x[None, :], y[:, None])
    sol = solve_normal(float(x[0]), float(y[0]), dx, dy, gap, load=load,
                       shear_modulus=STEEL_G, nu=STEEL_NU)
    if sol.touches_edge:
        raise InvalidInputError(f"the flange-root box is too small for a load of {load:g} N")
    return sol.area.cropped()


def unit_scale(area: GridArea) -> float:
    """Length scale ``sqrt(A/pi)`` of an area (m)."""
    return math.sqrt(area.area / math.pi)
