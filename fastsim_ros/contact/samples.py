"""Sample non-elliptical contact areas for validation, demos and tests.

Each sample is defined analytically (or by the normal problem on an analytic
gap), so it can be gridded at any resolution: the exact solver's values are
extrapolated over several grids, the online methods are judged on one.

- two semi-ellipses joined along ``y = 0`` (the paper's Table 5 family);
- an ellipse with a notch cut into one side (strips of two segments);
- two overlapping lobes of different size (a waisted, two-lobed area);
- an ellipse truncated just beyond its centre line (a patch cut off where a
  profile region ends): its longest chord lies on its edge;
- a wide end: two semi-ellipses sharing their join chord, the upper one
  flatter and possibly cut to a few rows (a conformal tread patch whose
  longest chord lies near one end);
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


def notched_ellipse(*, cells: int, scale: float = 1.0, load: float | None = None,
                    a_over_b: float = 0.8, half_width: float = 0.3,
                    depth: float = 0.35) -> GridArea:
    """Ellipse ``a/b = 0.8`` of area ``scale^2`` with a notch in its ``y > 0`` side.

    The notch removes ``|x| < 0.3 a``, ``y > 0.35 b``: strips there have two
    segments, and the area is asymmetric in ``y``.  ``a_over_b``,
    ``half_width`` (of ``a``) and ``depth`` (of ``b``) make other notched
    ellipses (the calibrated MAE's selection areas).
    """
    a, b = semi_ellipse_axes(a_over_b)
    x, y, dx, dy = _grid((-a, a), (-b, b), cells)
    xx, yy = x[None, :], y[:, None]
    p = _hertz_like(xx, yy, a, b) * ~((np.abs(xx) < half_width * a) & (yy > depth * b))
    return _finish(x, y, dx, dy, p, scale, load)


def two_lobes(*, cells: int, scale: float = 1.0, load: float | None = None) -> GridArea:
    """Two overlapping elliptical lobes of different size, joined by a waist."""
    lobes = ((0.0, -0.30, 0.50, 0.42), (0.06, 0.36, 0.32, 0.30))  # x_c, y_c, a, b
    x, y, dx, dy = _grid((-0.52, 0.52), (-0.74, 0.68), cells)
    xx, yy = x[None, :], y[:, None]
    # a Hertz-like peak that grows with the lobe's size
    p = np.maximum.reduce([a * _hertz_like(xx - xc, yy - yc, a, b) for xc, yc, a, b in lobes])
    return _finish(x, y, dx, dy, p, scale, load)


def two_regions(gap: float, *, cell: float = 2.5e-4, load: float = 2.0e4) -> GridArea:
    """Make two Hertzian ellipses side by side across ``y``, their edges ``gap`` (m) apart.

    A tread region (``a = 3 mm``, ``b = 2.5 mm``) and a smaller flange-root
    region (``a = 2 mm``, ``b = 1.25 mm``), as a wheel's two-point contact
    gives on one grid of square cells ``cell`` (m); ``gap`` (m; 0: the
    regions touch, down to -1 mm: they overlap and merge into one patch
    with a waist), the first region's centre on a strip, the second's
    wherever the gap puts it (its edge strips carry what the ellipse gives
    them: a gap closing in small steps fills a strip gradually); Hertz-like
    pressure per region in proportion to its size, ``load`` (N) in all.
    """
    if not gap >= -1e-3:
        raise InvalidInputError(f"gap must be at least -1 mm, got {gap}")
    (a1, b1), (a2, b2) = (3e-3, 2.5e-3), (2e-3, 1.25e-3)
    nx = 2 * math.ceil(a1 / cell) + 2
    centre2 = b1 + gap + b2
    below = math.ceil(b1 / cell) + 1
    ny = below + math.ceil((centre2 + b2) / cell) + 2
    x = cell * (np.arange(nx) - (nx - 1) / 2.0)
    y = cell * (np.arange(ny) - below)
    xx, yy = x[None, :], y[:, None]
    p = np.maximum(a1 * _hertz_like(xx, yy, a1, b1), a2 * _hertz_like(xx, yy - centre2, a2, b2))
    return GridArea(float(x[0]), float(y[0]), cell, cell, p).with_load(load)


def asymmetric_lobes(*, cells: int, scale: float = 1.0, load: float | None = None,
                     size: float = 0.6, lead: float = 0.3, overlap: float = 0.2,
                     a_over_b: tuple[float, float] = (1.0, 1.0)) -> GridArea:
    """Make two overlapping elliptical lobes side by side, the second smaller and leading.

    Lobe 1 (``y < 0``) has semi-axes ``a1 = a_over_b[0] b1``, ``b1 = 1``;
    lobe 2 (``y > 0``) is ``size`` times as large (``b2 = size``, ``a2 =
    a_over_b[1] b2``), its centre ``lead a1`` ahead of lobe 1's along ``x``
    and laterally where the lobes overlap by ``overlap b1`` (a two-point
    contact about to merge: asymmetric in ``x`` and in ``y``); Hertz-like
    pressure per lobe growing with its size; area ``scale^2``.
    """
    for name, v in (("size", size), ("overlap", overlap)):
        if not (math.isfinite(v) and v > 0.0):
            raise InvalidInputError(f"{name} must be positive, got {v}")
    a1, b1 = a_over_b[0], 1.0
    a2, b2 = a_over_b[1] * size, size
    lobes = ((0.0, 0.0, a1, b1), (lead * a1, b1 + b2 - overlap * b1, a2, b2))
    box = ((min(xc - a for xc, _, a, _ in lobes), max(xc + a for xc, _, a, _ in lobes)),
           (-b1, lobes[1][1] + b2))

    def pressure(cells_: int) -> tuple[np.ndarray, np.ndarray, float, float, np.ndarray]:
        x, y, dx, dy = _grid(box[0], box[1], cells_)
        xx, yy = x[None, :], y[:, None]
        return x, y, dx, dy, np.maximum.reduce(
            [b * _hertz_like(xx - xc, yy - yc, a, b) for xc, yc, a, b in lobes])

    # area scale^2: the shape's own area, on a fine grid whatever ``cells`` (one shape)
    *_, dx_f, dy_f, p_f = pressure(400)
    k = scale / math.sqrt(float(np.count_nonzero(p_f > 0.0)) * dx_f * dy_f)
    x, y, dx, dy, p = pressure(cells)
    return _finish(x, y, dx, dy, p, k, load)


def truncated_ellipse(*, cells: int, scale: float = 1.0, load: float | None = None,
                      cut: float = 0.1) -> GridArea:
    """Ellipse ``a/b = 1.5`` (``a b = scale^2/pi``) without the part beyond ``y = cut * b``."""
    a, b = semi_ellipse_axes(1.5)
    x, y, dx, dy = _grid((-a, a), (-b, b), cells)
    xx, yy = x[None, :], y[:, None]
    p = _hertz_like(xx, yy, a, b) * (yy <= cut * b)
    return _finish(x, y, dx, dy, p, scale, load).cropped()


def wide_end(*, a: float, b_lower: float, b_upper: float, cell: float, load: float,
             rows_above: int | None = None) -> GridArea:
    """Return semi-ellipses ``(a, b_lower)`` below and ``(a, b_upper)`` above ``y = 0`` (m).

    Square cells of ``cell`` (m), the join line on a cell face; above it
    ``rows_above`` rows (default: the upper half's, at least one), so a
    sweep of ``rows_above`` trims the smaller zone row by row.  Hertz-like
    pressure per half, scaled to ``load`` (N).
    """
    if rows_above is None:
        rows_above = max(1, int(np.ceil(b_upper / cell)))
    x = -a + cell * (np.arange(int(round(2 * a / cell))) + 0.5)
    y = cell * (np.arange(-int(np.ceil(b_lower / cell)), rows_above) + 0.5)
    xx, yy = np.meshgrid(x, y)
    b = np.where(yy < 0.0, b_lower, b_upper)
    p = np.sqrt(np.clip(1.0 - (xx / a) ** 2 - (yy / b) ** 2, 0.0, None))
    return GridArea(float(x[0]), float(y[0]), cell, cell, p * load / (p.sum() * cell * cell))


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


# ----------------------------------------------------------------------------- wider validation

def long_narrow_patch(*, cells: int, scale: float = 1.0, load: float | None = None,
                      a_over_b: float = 6.0) -> GridArea:
    """Make a long narrow patch: the superellipse ``|x/a|^4 + |y/b|^4 < 1``, ``a/b = a_over_b``.

    Area ``scale^2`` (the superellipse's area is ``4 a b Gamma(5/4)^2 /
    Gamma(3/2)``); squarer than an ellipse, as where a narrow running band
    is cut off laterally; pressure ``p0 sqrt(1 - |x/a|^4 - |y/b|^4)``.
    """
    if not a_over_b > 5.0:
        raise InvalidInputError(f"a long narrow patch has a/b > 5, got {a_over_b}")
    unit = 4.0 * math.gamma(1.25) ** 2 / math.gamma(1.5)  # area of a = b = 1
    b = math.sqrt(1.0 / (unit * a_over_b))
    a = a_over_b * b
    x, y, dx, dy = _grid((-a, a), (-b, b), cells)
    r4 = (x[None, :] / a) ** 4 + (y[:, None] / b) ** 4
    p = np.sqrt(np.clip(1.0 - r4, 0.0, None))
    return _finish(x, y, dx, dy, p, scale, load)


def flat_band_patch(*, cells: int, scale: float = 1.0, load: float | None = None,
                    a_over_b: float = 0.25, exponent: float = 4.0) -> GridArea:
    """Make a flat band: the superellipse ``|x/a|^n + |y/b|^n < 1`` wide across the rail.

    A conformal contact (a worn wheel on a worn rail) spreads laterally into
    a band, short along the rolling direction and flat-ended: ``a/b =
    a_over_b`` (below 1), ``n = exponent`` (2 is an ellipse; larger is
    squarer), area ``scale^2``, pressure ``p0 sqrt(1 - |x/a|^n - |y/b|^n)``.
    """
    if not (math.isfinite(a_over_b) and 0.0 < a_over_b < 1.0):
        raise InvalidInputError(f"a flat band has 0 < a/b < 1, got {a_over_b}")
    if not (math.isfinite(exponent) and exponent > 2.0):
        raise InvalidInputError(f"a flat band's exponent is above 2, got {exponent}")
    # area of |x|^n + |y|^n < 1: 4 Gamma(1 + 1/n)^2 / Gamma(1 + 2/n)
    unit = 4.0 * math.gamma(1.0 + 1.0 / exponent) ** 2 / math.gamma(1.0 + 2.0 / exponent)
    b = math.sqrt(1.0 / (unit * a_over_b))
    a = a_over_b * b
    x, y, dx, dy = _grid((-a, a), (-b, b), cells)
    rn = np.abs(x[None, :] / a) ** exponent + np.abs(y[:, None] / b) ** exponent
    p = np.sqrt(np.clip(1.0 - rn, 0.0, None))
    return _finish(x, y, dx, dy, p, scale, load)


def crescent_patch(*, cells: int, scale: float = 1.0, load: float | None = None,
                   bend: float = 1.2, a_over_b: float = 0.3) -> GridArea:
    """Make a crescent: a hollow-worn tread's patch, an ellipse bent along its lateral axis.

    The ellipse ``a/b = a_over_b`` (area ``scale^2``) with each strip moved
    along ``x`` by ``bend a (y/b)^2``: the horns lead the middle by ``bend
    a`` (a patch on a hollow tread, whose contact runs ahead towards both of
    the hollow's shoulders); Hertz-like pressure in the bent coordinates.  A
    negative ``bend`` makes the horns trail.
    """
    if not math.isfinite(bend):
        raise InvalidInputError(f"bend must be finite, got {bend}")
    a, b = semi_ellipse_axes(a_over_b)
    x, y, dx, dy = _grid((-a + min(bend, 0.0) * a, a + max(bend, 0.0) * a), (-b, b), cells)
    xx, yy = x[None, :], y[:, None]
    p = _hertz_like(xx - bend * a * (yy / b) ** 2, yy, a, b)
    return _finish(x, y, dx, dy, p, scale, load).cropped()


def egg_patch(*, cells: int, scale: float = 1.0, load: float | None = None,
              lead_over_trail: float = 1.8, a_over_b: float = 1.0) -> GridArea:
    """Make an egg: the leading half (``x > 0``) ``lead_over_trail`` times the trailing one.

    Two half ellipses joined along ``x = 0``, semi-axes ``a_l`` (leading),
    ``a_t`` (trailing) and ``b``, ``a_l = lead_over_trail a_t``, ``(a_l +
    a_t)/(2 b) = a_over_b``, area ``scale^2``; Hertz-like pressure per half,
    equal on the join.  Asymmetric in ``x`` only: symmetric in ``y``.
    ``lead_over_trail < 1``: the longer half trails.
    """
    for name, v in (("lead_over_trail", lead_over_trail), ("a_over_b", a_over_b)):
        if not (math.isfinite(v) and v > 0.0):
            raise InvalidInputError(f"{name} must be positive, got {v}")
    # area pi (a_l + a_t) b / 2 = 1 with a_l + a_t = 2 b a_over_b
    b = 1.0 / math.sqrt(math.pi * a_over_b)
    a_t = 2.0 * b * a_over_b / (1.0 + lead_over_trail)
    a_l = lead_over_trail * a_t
    x, y, dx, dy = _grid((-a_t, a_l), (-b, b), cells)
    xx, yy = x[None, :], y[:, None]
    p = np.where(xx > 0.0, _hertz_like(xx, yy, a_l, b), _hertz_like(xx, yy, a_t, b))
    return _finish(x, y, dx, dy, p, scale, load)


#: the profile-gap sample: lateral relative curvature (1/m) on the tread and at the flange
#: root, and the width (m) of the transition between them (from s = 0 to s = WIDTH)
PROFILE_TREAD_CURVATURE = 1.0 / 0.3
PROFILE_ROOT_CURVATURE = 1.0 / 0.03
PROFILE_TRANSITION = 6.0e-3


def _profile_height(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the lateral profile gap ``h(s)`` (m) of the profile-gap sample and ``h'(s)``."""
    k0, k1, w = PROFILE_TREAD_CURVATURE, PROFILE_ROOT_CURVATURE, PROFILE_TRANSITION
    t = np.asarray(s, dtype=float) / w
    # q'' = smoothstep(t): 0 before the transition, 3t^2 - 2t^3 in it, 1 after
    tc = np.clip(t, 0.0, 1.0)
    q = np.where(t < 0.0, 0.0, np.where(t <= 1.0, tc**4 / 4 - tc**5 / 10,
                                        0.15 + 0.5 * (t - 1.0) + 0.5 * (t - 1.0) ** 2))
    dq = np.where(t < 0.0, 0.0, np.where(t <= 1.0, tc**3 - tc**4 / 2, 0.5 + (t - 1.0)))
    return k0 * s**2 / 2 + (k1 - k0) * w**2 * q, k0 * s + (k1 - k0) * w * dq


def profile_gap(x: np.ndarray, y: np.ndarray, shift: float) -> np.ndarray:
    """Return the undeformed gap (m) at ``(x, y)`` (m) of a contact at lateral shift ``shift``.

    A wheel profile whose lateral relative curvature rises smoothly from the
    tread's (0.3 m radius, ``s < 0``) to the flange root's (0.03 m, ``s >
    6 mm``): ``h''(s)`` is a smoothstep between them.  At a lateral shift
    ``u`` the contact's centre is where the profile touches, ``s = u``; the
    gap is ``h(u + y) - h(u) - h'(u) y`` (the contact plane tangent there)
    plus the wheel radius along ``x``.
    """
    h_y, _ = _profile_height(shift + y)
    h_u, dh_u = _profile_height(np.asarray(shift, dtype=float))
    return x**2 / (2.0 * WHEEL_RADIUS) + (h_y - h_u - dh_u * y)


#: lateral shifts (m) from the tread to the flange root used by the validation
PROFILE_SHIFTS = (-4.0e-3, 1.5e-3, 4.5e-3)


def profile_gap_patch(shift: float, *, cells: int, load: float = 5.0e4) -> GridArea:
    """Solve the normal contact of :func:`profile_gap` at ``shift`` (m) under ``load`` (N).

    Steel on steel, the exact normal solver on ``cells`` x ``cells`` cells
    over a box of 18 mm x 13 mm (more of it on the tread side, ``y < 0``),
    cropped to the cells in contact.
    """
    if not (math.isfinite(shift) and abs(shift) <= 2.0e-2):
        raise InvalidInputError(f"shift must lie within 20 mm of the profile's origin, "
                                f"got {shift}")
    x, y, dx, dy = _grid((-9.0e-3, 9.0e-3), (-7.0e-3, 6.0e-3), cells)
    gap = profile_gap(x[None, :], y[:, None], shift)
    sol = solve_normal(float(x[0]), float(y[0]), dx, dy, gap, load=load,
                       shear_modulus=STEEL_G, nu=STEEL_NU)
    if sol.touches_edge:
        raise InvalidInputError(f"the profile-gap box is too small for a load of {load:g} N "
                                f"at shift {shift:g} m")
    return sol.area.cropped()
