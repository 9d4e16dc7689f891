"""Normal contact: the Hertz ellipse and the discrete Polonsky-Keer solver against it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, special

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.errors import ConvergenceError, EmptyContactError, InvalidInputError
from fastsim_ros.contact.normal import (
    HertzContact, NormalSolution, ellipsoid_gap, hertz_ellipse, solve_normal)

# Wheel on rail: steel (combined G, nu), wheel radius 0.46 m along x, a
# transverse relative radius of 0.3 m, 50 kN: semi-axes of about 5 mm.
STEEL = {"shear_modulus": 8e10, "nu": 0.28}
WHEEL_RAIL = (0.46, 0.3, 5e4)


def e_star(shear_modulus: float, nu: float) -> float:
    return shear_modulus / (1.0 - nu)


# ---------------------------------------------------------------- Hertz


@pytest.mark.parametrize("radius, load, material", [
    (0.46, 5e4, STEEL),
    (0.01, 1.0, {"shear_modulus": 1.0, "nu": 0.0}),
    (2.0, 3e5, {"shear_modulus": 2.6e10, "nu": 0.5}),
])
def test_hertz_circle_closed_form(radius, load, material):
    h = hertz_ellipse(radius, radius, load, **material)
    a = (3.0 * load * radius / (4.0 * e_star(**material))) ** (1.0 / 3.0)
    assert h.a == pytest.approx(a, rel=1e-13)
    assert h.b == pytest.approx(a, rel=1e-13)
    assert h.p0 == pytest.approx(3.0 * load / (2.0 * math.pi * a**2), rel=1e-13)
    assert h.approach == pytest.approx(a**2 / radius, rel=1e-13)
    assert h.load == pytest.approx(load, rel=1e-13)


@pytest.mark.parametrize("rx, ry", [(0.46, 0.3), (1.0, 4.0), (4.0, 1.0), (0.3, 0.3 * 25.0),
                                    (1.0, 1.0 + 1e-7)])
def test_hertz_ellipse_classical_relations(rx, ry):
    """Johnson sec. 4.2 with scipy's ellipk/ellipe, independent of the Carlson form used."""
    load = 5e4
    h = hertz_ellipse(rx, ry, load, **STEEL)
    es = e_star(**STEEL)
    # primed: along the larger radius (the longer semi-axis)
    r_major, a_major, b_minor = (rx, h.a, h.b) if rx >= ry else (ry, h.b, h.a)
    assert a_major >= b_minor
    m = 1.0 - (b_minor / a_major) ** 2
    k, e = special.ellipk(m), special.ellipe(m)
    b_over_a = max(rx, ry) / min(rx, ry)  # ratio of the gap's curvatures B/A
    assert h.load == pytest.approx(load, rel=1e-12)
    assert h.approach == pytest.approx(h.p0 * b_minor * k / es, rel=1e-12)
    if m > 1e-4:  # ellipk - ellipe cancels below; the near-circle case is checked next
        assert ((a_major / b_minor) ** 2 * e - k) / (k - e) == pytest.approx(b_over_a, rel=1e-9)
        a3 = 3.0 * load * r_major * (k - e) / (math.pi * es * m)
        assert a_major**3 == pytest.approx(a3, rel=1e-9)
    else:
        # B/A = 1 + 3m/4 + O(m^2) near the circle; the axes tend to the circle's
        circle = hertz_ellipse(rx, rx, load, **STEEL)
        assert m == pytest.approx(4.0 / 3.0 * (b_over_a - 1.0), rel=1e-3)
        assert h.a == pytest.approx(circle.a, rel=1e-6)
    # orientation: the contact is longer along the larger radius
    assert (h.a > h.b) == (rx > ry)


def hertz_displacement(h: HertzContact, x0: float, y0: float, es: float) -> float:
    """Integrate the normal displacement (m) of the Hertz pressure at ``(x0, y0)``.

    ``u = 1/(pi E*) int p/|r - r0| dA``; in polar coordinates about the field
    point the radial integral of ``p0 sqrt(c0 + c1 s - c2 s^2)`` is a circle
    segment's area, which leaves one quadrature over the direction.
    """
    def radial(theta: float) -> float:
        c, s = math.cos(theta), math.sin(theta)
        c2 = c**2 / h.a**2 + s**2 / h.b**2
        c1 = -2.0 * (x0 * c / h.a**2 + y0 * s / h.b**2)
        c0 = 1.0 - x0**2 / h.a**2 - y0**2 / h.b**2
        disc = c1**2 + 4.0 * c2 * c0
        if disc <= 0.0:
            return 0.0
        mid, half = c1 / (2.0 * c2), math.sqrt(disc) / (2.0 * c2)
        lo = max(0.0, mid - half) - mid
        if lo >= half:
            return 0.0

        def f(u: float) -> float:
            v = min(max(u / half, -1.0), 1.0)  # rounding can step just past the end
            return 0.5 * half**2 * (v * math.sqrt(1.0 - v**2) + math.asin(v))

        return math.sqrt(c2) * (f(half) - f(lo))

    total, _ = integrate.quad(radial, 0.0, 2.0 * math.pi, limit=400, epsabs=0.0, epsrel=1e-11)
    return h.p0 * total / (math.pi * es)


@pytest.mark.parametrize("rx, ry", [(0.46, 0.3), (1.0, 4.0), (4.0, 1.0)])
def test_hertz_ellipse_closes_gap(rx, ry):
    """The Hertz pressure's displacement closes the gap exactly inside the ellipse and not outside.

    Deformed gap ``h0 - delta + u`` from an independent quadrature of the
    Boussinesq kernel: zero inside, positive outside.
    """
    h = hertz_ellipse(rx, ry, 5e4, **STEEL)
    es = e_star(**STEEL)
    inside = [(0.0, 0.0), (0.5, 0.0), (0.0, -0.7), (0.4, 0.6), (-0.9, 0.1)]
    for sx, sy in inside:
        x, y = sx * h.a, sy * h.b
        h0 = float(ellipsoid_gap(np.array([x]), np.array([y]), rx, ry)[0, 0])
        gap = h0 - h.approach + hertz_displacement(h, x, y, es)
        assert abs(gap) <= 1e-8 * h.approach
    for sx, sy in [(1.2, 0.0), (0.0, -1.5), (1.0, 1.0)]:
        x, y = sx * h.a, sy * h.b
        h0 = float(ellipsoid_gap(np.array([x]), np.array([y]), rx, ry)[0, 0])
        assert h0 - h.approach + hertz_displacement(h, x, y, es) > 1e-3 * h.approach


# ---------------------------------------------------------------- discrete solver


def grid_case(rx: float, ry: float, load: float, material: dict[str, float], nx: int,
              ny: int, box: float = 1.3):
    """Hertz reference and the grid over ``box`` times its semi-axes, with the gap."""
    h = hertz_ellipse(rx, ry, load, **material)
    dx, dy = 2.0 * box * h.a / nx, 2.0 * box * h.b / ny
    x = -box * h.a + dx * (np.arange(nx) + 0.5)
    y = -box * h.b + dy * (np.arange(ny) + 0.5)
    return h, (float(x[0]), float(y[0]), dx, dy, ellipsoid_gap(x, y, rx, ry))


def fitted_ellipse(sol: NormalSolution, level: float = 0.3) -> tuple[float, float, float]:
    """Return ``(a, b, p0)`` of a least-squares fit ``p^2 = p0^2 (1 - x^2/a^2 - y^2/b^2)``.

    Hertz's ``p^2`` is quadratic in ``x`` and ``y``; cells below ``level``
    times the peak (the steep rim, one cell from the edge) are left out.
    """
    xx, yy = np.meshgrid(sol.area.x, sol.area.y)
    p = sol.pressure
    sel = p > level * p.max()
    lhs = np.column_stack([np.ones(np.count_nonzero(sel)), xx[sel] ** 2, yy[sel] ** 2])
    c, *_ = np.linalg.lstsq(lhs, p[sel] ** 2, rcond=None)
    return math.sqrt(-c[0] / c[1]), math.sqrt(-c[0] / c[2]), math.sqrt(c[0])


CASES = {
    "circle": (0.46, 0.46, 5e4, STEEL, 101, 101),
    "wheel-rail": (*WHEEL_RAIL, STEEL, 101, 101),
    "ry/rx=4": (0.1, 0.4, 2e4, STEEL, 81, 121),
    "rx/ry=3.5, near-square cells": (1.0, 1.0 / 3.5, 1.0, {"shear_modulus": 1.0, "nu": 0.3},
                                     220, 100),
}


@pytest.mark.parametrize("case", CASES.values(), ids=CASES.keys())
def test_given_load_matches_hertz(case):
    rx, ry, load, material, nx, ny = case
    h, (x0, y0, dx, dy, gap) = grid_case(rx, ry, load, material, nx, ny)
    sol = solve_normal(x0, y0, dx, dy, gap, load=load, **material)
    # the Hertz ellipse, its peak pressure and the approach within 0.3 % (brief: 1 %)
    a, b, p0 = fitted_ellipse(sol)
    assert a == pytest.approx(h.a, rel=3e-3)
    assert b == pytest.approx(h.b, rel=3e-3)
    assert p0 == pytest.approx(h.p0, rel=3e-3)
    assert sol.pressure.max() == pytest.approx(h.p0, rel=3e-3)
    assert sol.approach == pytest.approx(h.approach, rel=3e-3)
    # the contact cells reach the Hertz ellipse to within one cell
    xx, yy = np.meshgrid(sol.area.x, sol.area.y)
    contact = sol.area.mask
    assert np.max(np.abs(xx[contact])) == pytest.approx(h.a, abs=dx)
    assert np.max(np.abs(yy[contact])) == pytest.approx(h.b, abs=dy)
    assert sol.area.area == pytest.approx(math.pi * h.a * h.b, rel=0.015)
    # pointwise: the collocated pressure follows Hertz's away from the rim
    core = h.pressure(xx, yy) > 0.3 * h.p0
    assert np.max(np.abs(sol.pressure - h.pressure(xx, yy))[core]) <= 5e-3 * h.p0
    # equilibrium and the contact conditions
    assert sol.load == pytest.approx(load, rel=1e-12)
    assert sol.area.load == pytest.approx(load, rel=1e-12)
    assert np.all(sol.pressure >= 0.0)
    assert np.all(sol.gap >= -1e-8 * sol.approach)
    assert np.max(np.abs(sol.gap[contact])) <= 1e-8 * sol.approach
    assert not sol.touches_edge
    assert isinstance(sol.area, GridArea)
    assert (sol.area.x0, sol.area.y0, sol.area.dx, sol.area.dy) == (x0, y0, dx, dy)


@pytest.mark.parametrize("case", [CASES["wheel-rail"], CASES["ry/rx=4"]],
                         ids=["wheel-rail", "ry/rx=4"])
def test_given_approach_reproduces_given_load(case):
    rx, ry, load, material, nx, ny = case
    h, (x0, y0, dx, dy, gap) = grid_case(rx, ry, load, material, nx, ny)
    by_load = solve_normal(x0, y0, dx, dy, gap, load=load, **material)
    by_approach = solve_normal(x0, y0, dx, dy, gap, approach=by_load.approach, **material)
    assert by_approach.approach == by_load.approach
    assert by_approach.load == pytest.approx(load, rel=1e-8)
    assert np.max(np.abs(by_approach.pressure - by_load.pressure)) <= 1e-7 * h.p0
    assert np.array_equal(by_approach.area.mask, by_load.area.mask)
    assert np.all(by_approach.gap >= -1e-8 * by_approach.approach)
    # Hertz's approach gives Hertz's load (N ~ delta^1.5: 0.3 % in delta is 0.45 % in N)
    at_hertz = solve_normal(x0, y0, dx, dy, gap, approach=h.approach, **material)
    assert at_hertz.load == pytest.approx(load, rel=5e-3)


def test_off_centre_gap_moves_the_contact():
    """A gap moved by whole cells gives the same pressure, moved by as many cells."""
    rx, ry, load = WHEEL_RAIL
    h, (x0, y0, dx, dy, _) = grid_case(rx, ry, load, STEEL, 60, 60, box=2.0)
    ni, nj = 7, -4
    x = x0 + dx * np.arange(60)
    y = y0 + dy * np.arange(60)
    centred = solve_normal(x0, y0, dx, dy, ellipsoid_gap(x, y, rx, ry), load=load, **STEEL)
    moved = solve_normal(x0, y0, dx, dy, ellipsoid_gap(x - ni * dx, y - nj * dy, rx, ry),
                         load=load, **STEEL)
    assert np.allclose(np.roll(centred.pressure, (nj, ni), axis=(0, 1)), moved.pressure,
                       rtol=0.0, atol=1e-7 * h.p0)
    assert moved.approach == pytest.approx(centred.approach, rel=1e-9)


def test_grid_too_small_is_flagged():
    rx, ry, load = WHEEL_RAIL
    h, (x0, y0, dx, dy, gap) = grid_case(rx, ry, load, STEEL, 40, 40, box=0.8)
    sol = solve_normal(x0, y0, dx, dy, gap, load=load, **STEEL)
    assert sol.touches_edge
    # the contact is confined to the grid: a stiffer contact, higher approach
    assert sol.approach > h.approach


def test_ellipsoid_gap_layout():
    x = np.array([-1.0, 0.0, 2.0])
    y = np.array([0.5, -3.0])
    h0 = ellipsoid_gap(x, y, 2.0, 4.0)
    assert h0.shape == (2, 3)
    assert h0[1, 2] == pytest.approx(2.0**2 / 4.0 + 3.0**2 / 8.0)
    assert h0[0, 1] == pytest.approx(0.5**2 / 8.0)


# ---------------------------------------------------------------- bad input

GRID = (-1e-3, -1e-3, 1e-4, 1e-4)


def small_gap() -> np.ndarray:
    x = GRID[0] + GRID[2] * np.arange(21)
    return ellipsoid_gap(x, x, 0.46, 0.3)


def with_nan() -> np.ndarray:
    g = small_gap()
    g[3, 4] = np.nan
    return g


def with_inf() -> np.ndarray:
    g = small_gap()
    g[0, 0] = np.inf
    return g


@pytest.mark.parametrize("gap, kwargs, match", [
    (with_nan(), {"load": 1e3}, "NaN or infinite"),
    (with_inf(), {"load": 1e3}, "NaN or infinite"),
    (small_gap(), {"load": 0.0}, "load must be positive"),
    (small_gap(), {"load": -5.0}, "load must be positive"),
    (small_gap(), {"load": math.nan}, "load must be positive"),
    (small_gap(), {"approach": math.inf}, "approach must be finite"),
    (small_gap(), {}, "exactly one of load and approach"),
    (small_gap(), {"load": 1e3, "approach": 1e-6}, "exactly one of load and approach"),
    (small_gap(), {"load": 1e3, "nu": 0.6}, r"nu must lie in \[0, 0.5\]"),
    (small_gap(), {"load": 1e3, "nu": -0.1}, r"nu must lie in \[0, 0.5\]"),
    (small_gap(), {"load": 1e3, "nu": math.nan}, r"nu must lie in \[0, 0.5\]"),
    (small_gap(), {"load": 1e3, "shear_modulus": 0.0}, "shear modulus must be positive"),
    (small_gap(), {"load": 1e3, "shear_modulus": -8e10}, "shear modulus must be positive"),
    (small_gap()[0], {"load": 1e3}, "2-D array"),
    (small_gap(), {"load": 1e3, "tol": 0.0}, "tol must be positive"),
])
def test_bad_input_raises(gap, kwargs, match):
    kw = {**STEEL, **kwargs}
    with pytest.raises(InvalidInputError, match=match):
        solve_normal(*GRID, gap, **kw)


@pytest.mark.parametrize("grid, match", [
    ((-1e-3, -1e-3, 0.0, 1e-4), "dx must be positive"),
    ((-1e-3, -1e-3, 1e-4, -1e-4), "dy must be positive"),
    ((math.nan, -1e-3, 1e-4, 1e-4), "x0 and y0 must be finite"),
])
def test_bad_grid_raises(grid, match):
    with pytest.raises(InvalidInputError, match=match):
        solve_normal(*grid, small_gap(), load=1e3, **STEEL)


def test_approach_that_closes_no_gap_raises():
    g = small_gap() + 1e-6
    with pytest.raises(EmptyContactError, match="closes no cell's gap"):
        solve_normal(*GRID, g, approach=1e-6, **STEEL)


@pytest.mark.parametrize("args, kwargs, match", [
    ((0.0, 0.3, 5e4), STEEL, "rx must be positive"),
    ((0.46, math.inf, 5e4), STEEL, "ry must be positive"),
    ((0.46, 0.3, 0.0), STEEL, "load must be positive"),
    ((0.46, 0.3, math.nan), STEEL, "load must be positive"),
    ((0.46, 0.3, 5e4), {"shear_modulus": 8e10, "nu": 0.51}, r"nu must lie in \[0, 0.5\]"),
    ((0.46, 0.3, 5e4), {"shear_modulus": -1.0, "nu": 0.28}, "shear modulus must be positive"),
])
def test_hertz_bad_input_raises(args, kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        hertz_ellipse(*args, **kwargs)


@pytest.mark.parametrize("kwargs", [{"load": 1e3}, {"approach": 1e-5}])
def test_too_few_iterations_raise_convergence_error(kwargs):
    with pytest.raises(ConvergenceError, match="did not converge in 2 iterations"):
        solve_normal(*GRID, small_gap(), max_iter=2, **STEEL, **kwargs)
