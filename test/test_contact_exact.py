"""The exact steady-rolling solver: identities of the discrete theory and Kalker's limits."""

import math

import numpy as np
import pytest

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import exact
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.traction import rigid_slip

KALKER_NU025_CIRCLE = {"C11": 4.12, "C22": 3.67, "C23": 1.47}


def notched_area() -> areas.GridArea:
    """Make an ellipse with a notch cut into its trailing half: strips of two segments."""
    e = areas.ellipse(1.0, 0.8, nx=24, ny=20)
    p = np.array(e.pressure)
    p[8:12, 6:10] = 0.0
    return e.with_pressure(p)


@pytest.mark.parametrize("make", [lambda: areas.ellipse(1.0, 0.5, nx=18, ny=16),
                                  notched_area,
                                  lambda: areas.semi_ellipses(0.5, 2.0, cells=20)])
def test_fft_solver_equals_dense_reference(make):
    ar = make()
    for cr in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.3, -0.2, 0.7)):
        fast = exact.full_adhesion(ar, *cr, nu=0.28, shear_modulus=8e10, solver="fft")
        dense = exact.full_adhesion(ar, *cr, nu=0.28, shear_modulus=8e10, solver="dense")
        scale = np.abs(dense.tau_x).max() + np.abs(dense.tau_y).max()
        np.testing.assert_allclose(fast.tau_x, dense.tau_x, atol=1e-8 * scale)
        np.testing.assert_allclose(fast.tau_y, dense.tau_y, atol=1e-8 * scale)


@pytest.mark.parametrize("g", [0.2, 1.0, 5.0])
@pytest.mark.parametrize("n", [16, 23])
def test_eta_coefficient_of_mz_equals_c23_on_every_grid(g, n):
    # With the upstream difference and w at cell centres, C32 = C23 exactly (METHOD.md 5).
    a, b = areas.semi_ellipse_axes(g)
    c = exact.creep_coefficients(areas.ellipse(a, b, nx=n, ny=n + 3), nu=0.25)
    assert c.C32 == pytest.approx(c.C23, rel=1e-8)
    assert abs(c.C12) < 1e-8 * c.C11 and abs(c.C13) < 1e-8 * c.C11


def test_circle_converges_to_kalker():
    # First-order extrapolation in the cell size (METHOD.md 5) over four grids, 40 .. 100
    # cells across; cached, so the command line's test of the same circle reuses it.
    assert exact.extrapolation_grids(100) == [40, 60, 80, 100]
    c = exact.extrapolated_coefficients("ellipse", (1.0,), nu=0.25)
    for key, published in KALKER_NU025_CIRCLE.items():
        assert getattr(c, key) == pytest.approx(published, rel=0.01), key


def test_extrapolation_is_the_first_order_fit_over_its_grids():
    c = exact.extrapolated_coefficients("semi-ellipses", (0.5, 2.0), nu=0.25, finest=20)
    grids = exact.extrapolation_grids(20)
    per = [exact.creep_coefficients(areas.semi_ellipses(0.5, 2.0, cells=n), nu=0.25)
           for n in grids]
    fit = np.polyfit([1.0 / n for n in grids], [v.C13 for v in per], 1)[1]
    assert c.C13 == fit and c.area == 1.0
    with pytest.raises(InvalidInputError, match="unknown shape"):
        exact.extrapolated_coefficients("ellipse", (1.0, 2.0), nu=0.25)


def test_mirror_in_y_flips_c13_only():
    ar = areas.semi_ellipses(0.5, 2.0, cells=24)
    c = exact.creep_coefficients(ar, nu=0.25)
    m = exact.creep_coefficients(ar.mirrored_y(), nu=0.25)
    assert abs(c.C13) > 0.05
    assert m.C13 == pytest.approx(-c.C13, rel=1e-8)
    for key in ("C11", "C22", "C23"):
        assert getattr(m, key) == pytest.approx(getattr(c, key), rel=1e-8)


def test_reference_point_moves_c13_by_rigid_slip_identity():
    ar = areas.semi_ellipses(0.2, 1.0, cells=20)
    p = (0.13, -0.21)
    o = exact.creep_coefficients(ar, nu=0.25)
    q = exact.creep_coefficients(ar, nu=0.25, reference=p)
    c = math.sqrt(ar.area / math.pi)
    assert q.C13 == pytest.approx(o.C13 + (o.C11 * p[1] - o.C12 * p[0]) / c, rel=1e-8)
    assert q.C23 == pytest.approx(o.C23 + (o.C21 * p[1] - o.C22 * p[0]) / c, rel=1e-8)
    assert q.C11 == pytest.approx(o.C11, rel=1e-10)


def test_results_do_not_depend_on_grid_origin_or_length_scale():
    ar = areas.ellipse(0.7, 1.1, nx=16, ny=18)
    base = exact.full_adhesion(ar, 1e-3, 2e-3, 0.5, nu=0.3, shear_modulus=8e10)
    moved = exact.full_adhesion(ar.shifted(0.3, -0.2), 1e-3, 2e-3, 0.5, nu=0.3,
                                shear_modulus=8e10, reference=(0.3, -0.2))
    assert (moved.fx, moved.fy, moved.mz) == pytest.approx((base.fx, base.fy, base.mz),
                                                           rel=1e-9)
    k = 1e-3  # metres to millimetres-sized: linear theory scales Fx ~ k^2, Fx(phi) ~ k^3
    small = exact.full_adhesion(ar.scaled(k), 1e-3, 2e-3, 0.5 / k, nu=0.3, shear_modulus=8e10)
    assert (small.fx, small.fy, small.mz) == pytest.approx(
        (base.fx * k**2, base.fy * k**2, base.mz * k**3), rel=1e-9)


def _hertz_area(load=1.0e4):
    return areas.ellipse(6e-3, 4e-3, nx=22, ny=20, load=load)


@pytest.mark.parametrize("xi, eta", [(0.05, 0.0), (0.03, -0.04), (0.0, 0.2)])
def test_full_slip_gives_mu_n_opposite_to_slip(xi, eta):
    ar = _hertz_area()
    mu = 0.3
    sol = exact.coulomb(ar, xi, eta, 0.0, mu=mu, nu=0.28, shear_modulus=8e10)
    assert np.all(sol.slip[ar.mask])
    f = np.hypot(sol.fx, sol.fy)
    assert f == pytest.approx(mu * ar.load, rel=1e-6)
    direction = np.array([xi, eta]) / math.hypot(xi, eta)
    assert np.dot([sol.fx, sol.fy], direction) / f == pytest.approx(-1.0, abs=1e-4)


def test_vanishing_creepage_gives_the_linear_theory():
    ar = _hertz_area()
    cr = (1e-7, -2e-7, 1e-5)
    sol = exact.coulomb(ar, *cr, mu=0.3, nu=0.28, shear_modulus=8e10)
    lin = exact.full_adhesion(ar, *cr, nu=0.28, shear_modulus=8e10)
    assert not np.any(sol.slip)
    assert (sol.fx, sol.fy, sol.mz) == pytest.approx((lin.fx, lin.fy, lin.mz), rel=1e-7)


def test_coulomb_tractions_obey_the_friction_law():
    ar = _hertz_area()
    mu, g = 0.3, 8e10
    sol = exact.coulomb(ar, 2e-4, 1e-4, 0.05, mu=mu, nu=0.28, shear_modulus=g)
    bound = mu * ar.pressure
    tau = np.hypot(sol.tau_x, sol.tau_y)
    assert np.all(tau <= bound * (1 + 1e-9) + 1e-9)
    # a partial-slip state: adhesion at the leading edge, slip at the trailing edge
    assert 0 < np.count_nonzero(sol.slip) < np.count_nonzero(ar.mask)
    assert np.all(tau[sol.slip] == pytest.approx(bound[sol.slip], rel=1e-9))
    # slip opposite to traction where slipping, zero where adhering
    op = exact.SteadyRollingOperator.of(ar, nu=0.28, shear_modulus=g)
    gx, gy = op.fft_product()(sol.tau_x, sol.tau_y)
    wx, wy = rigid_slip(ar, 2e-4, 1e-4, 0.05)
    sx, sy = wx - gx, wy - gy
    adh = ar.mask & ~sol.slip
    smax = np.hypot(sx, sy)[ar.mask].max()
    assert np.hypot(sx, sy)[adh].max() < 1e-6 * smax
    cos = (sx * sol.tau_x + sy * sol.tau_y)[sol.slip] / (np.hypot(sx, sy) * tau)[sol.slip]
    assert np.all(cos < -0.999)


def test_force_grows_monotonically_to_saturation():
    ar = _hertz_area()
    forces = [-exact.coulomb(ar, xi, 0.0, 0.0, mu=0.3, nu=0.28, shear_modulus=8e10).fx
              for xi in (1e-4, 5e-4, 1e-3, 2e-3, 5e-3, 2e-2)]
    mu_n = 0.3 * ar.load
    assert np.all(np.diff(forces) > 0)
    # a sliver of adhesion stays at the leading edge: mu N is approached from below
    assert np.all(np.array(forces) <= mu_n * (1 + 1e-12))
    assert forces[-1] == pytest.approx(mu_n, rel=1e-3)


@pytest.mark.parametrize("kwargs, match", [
    (dict(mu=0.0), "mu must be positive"),
    (dict(mu=float("nan")), "mu must be positive"),
    (dict(mu=0.3, nu=0.6), "nu must lie in"),
    (dict(mu=0.3, nu=-0.1), "nu must lie in"),
])
def test_bad_parameters_are_refused(kwargs, match):
    args = dict(nu=0.28, shear_modulus=8e10)
    args.update(kwargs)
    with pytest.raises(InvalidInputError, match=match):
        exact.coulomb(_hertz_area(), 1e-3, 0.0, 0.0, **args)
