"""The exact steady-rolling solver: identities of the discrete theory and Kalker's limits."""

import math

import numpy as np
import pytest
import scipy.special

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import exact, normal, partial_slip
from fastsim_ros.contact.errors import ConvergenceError, GridTooLargeError, InvalidInputError
from fastsim_ros.contact.friction import ExponentialFriction
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
    # With the upstream difference and w at cell centres, C32 = C23 exactly (the physics guide).
    a, b = areas.semi_ellipse_axes(g)
    c = exact.creep_coefficients(areas.ellipse(a, b, nx=n, ny=n + 3), nu=0.25)
    assert c.C32 == pytest.approx(c.C23, rel=1e-8)
    assert abs(c.C12) < 1e-8 * c.C11 and abs(c.C13) < 1e-8 * c.C11


def test_circle_converges_to_kalker():
    # First-order extrapolation in the cell size (docs/guide_physics.md) over four grids, 40 .. 100
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


#: the Coulomb solvers: the FFT one (default) and the dense reference pass the same tests
SOLVERS = ["fft", "dense"]


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("xi, eta", [(0.05, 0.0), (0.03, -0.04), (0.0, 0.2)])
def test_full_slip_gives_mu_n_opposite_to_slip(xi, eta, solver):
    ar = _hertz_area()
    mu = 0.3
    sol = exact.coulomb(ar, xi, eta, 0.0, mu=mu, nu=0.28, shear_modulus=8e10, solver=solver)
    assert np.all(sol.slip[ar.mask])
    f = np.hypot(sol.fx, sol.fy)
    assert f == pytest.approx(mu * ar.load, rel=1e-6)
    direction = np.array([xi, eta]) / math.hypot(xi, eta)
    assert np.dot([sol.fx, sol.fy], direction) / f == pytest.approx(-1.0, abs=1e-4)


@pytest.mark.parametrize("solver", SOLVERS)
def test_vanishing_creepage_gives_the_linear_theory(solver):
    ar = _hertz_area()
    cr = (1e-7, -2e-7, 1e-5)
    sol = exact.coulomb(ar, *cr, mu=0.3, nu=0.28, shear_modulus=8e10, solver=solver)
    lin = exact.full_adhesion(ar, *cr, nu=0.28, shear_modulus=8e10)
    assert not np.any(sol.slip)
    assert (sol.fx, sol.fy, sol.mz) == pytest.approx((lin.fx, lin.fy, lin.mz), rel=1e-7)


@pytest.mark.parametrize("solver", SOLVERS)
def test_coulomb_tractions_obey_the_friction_law(solver):
    ar = _hertz_area()
    mu, g = 0.3, 8e10
    sol = exact.coulomb(ar, 2e-4, 1e-4, 0.05, mu=mu, nu=0.28, shear_modulus=g, solver=solver)
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


@pytest.mark.parametrize("solver", SOLVERS)
def test_force_grows_monotonically_to_saturation(solver):
    ar = _hertz_area()
    forces = [-exact.coulomb(ar, xi, 0.0, 0.0, mu=0.3, nu=0.28, shear_modulus=8e10,
                             solver=solver).fx
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
@pytest.mark.parametrize("solver", SOLVERS)
def test_bad_parameters_are_refused(kwargs, match, solver):
    args = dict(nu=0.28, shear_modulus=8e10, solver=solver)
    args.update(kwargs)
    with pytest.raises(InvalidInputError, match=match):
        exact.coulomb(_hertz_area(), 1e-3, 0.0, 0.0, **args)


# ------------------------------------------------------------ the FFT Coulomb solver


def _notched_hertz():
    e = areas.ellipse(6e-3, 4e-3, nx=30, ny=26, load=2e4)
    p = np.array(e.pressure)
    p[10:15, 8:13] = 0.0  # a notch in the trailing half: strips of two segments
    return e.with_pressure(p)


#: areas on which the FFT solver's tractions are compared with the dense reference's:
#: 30 x 26 cells and more start from a coarse grid (partial_slip.COARSEST_CELLS)
COMPARED_AREAS = {
    "hertz 22x20": _hertz_area,
    "hertz 34x34": lambda: areas.ellipse(6e-3, 4e-3, nx=34, ny=34, load=1e4),
    "notched hertz": _notched_hertz,
    "semi-ellipses (flat bound)": lambda: areas.semi_ellipses(0.5, 2.0, cells=24).scaled(
        1e-2).with_load(3e4),
    "hertz 30x12, strips cut into segments": lambda: areas.ellipse(
        8e-3, 3e-3, nx=30, ny=12, load=1e4),
}
#: creepages (xi, eta, phi in 1/m), from the linear range to full slip, spin included
COMPARED_CREEPAGES = [(2e-4, 1e-4, 0.05), (-6e-4, 3e-4, 0.0), (0.0, 0.0, 1.5),
                      (1e-4, -2e-4, -0.8), (0.02, 0.01, 0.3)]


@pytest.mark.parametrize("name", sorted(COMPARED_AREAS))
def test_fft_coulomb_equals_dense_reference(name, monkeypatch):
    # Both solve one discrete problem to 1e-9 of mu p_max: their tractions agree to
    # round-off of that order (measured at most 6e-10 of mu p_max).
    if "segments" in name:
        # the preconditioner of strips longer than SEGMENT_CELLS (160): on 30 cells, at 7
        monkeypatch.setattr(partial_slip, "SEGMENT_CELLS", 7)
    ar = COMPARED_AREAS[name]()
    op = exact.SteadyRollingOperator.of(ar, nu=0.28, shear_modulus=8e10)
    mu = 0.3
    scale = mu * ar.pressure.max()
    for cr in COMPARED_CREEPAGES:
        fft = exact.coulomb(ar, *cr, mu=mu, nu=0.28, shear_modulus=8e10, operator=op)
        dense = exact.coulomb(ar, *cr, mu=mu, nu=0.28, shear_modulus=8e10, operator=op,
                              solver="dense")
        np.testing.assert_allclose(fft.tau_x, dense.tau_x, rtol=0, atol=1e-8 * scale)
        np.testing.assert_allclose(fft.tau_y, dense.tau_y, rtol=0, atol=1e-8 * scale)
        # a cell exactly on the slip/stick border may fall either way at round-off
        assert np.count_nonzero(fft.slip != dense.slip) <= 1
        mu_n = mu * ar.load
        assert (fft.fx, fft.fy) == pytest.approx((dense.fx, dense.fy), abs=1e-8 * mu_n)
        assert fft.mz == pytest.approx(dense.mz, abs=1e-8 * mu_n * ar.dx * ar.nx)
        assert fft.iterations >= 1 and fft.products > fft.krylov > 0


def test_fft_coulomb_equals_dense_reference_with_falling_friction():
    # measured at most 1e-9 of mu_s p_max apart
    ar = _hertz_area()
    op = exact.SteadyRollingOperator.of(ar, nu=0.28, shear_modulus=8e10)
    law = ExponentialFriction(0.3, 0.4, 0.6)
    scale = 0.3 * ar.pressure.max()
    for cr in COMPARED_CREEPAGES:
        fft, dense = (exact.coulomb(ar, *cr, friction=law, speed=20.0, nu=0.28,
                                    shear_modulus=8e10, operator=op, solver=solver)
                      for solver in SOLVERS)
        np.testing.assert_allclose(fft.tau_x, dense.tau_x, rtol=0, atol=1e-8 * scale)
        np.testing.assert_allclose(fft.tau_y, dense.tau_y, rtol=0, atol=1e-8 * scale)
        assert np.count_nonzero(fft.slip != dense.slip) <= 1


def test_coarse_grid_keeps_the_pressure_and_the_cells():
    ar = _notched_hertz()
    coarse = partial_slip.coarsened(ar)
    assert (coarse.dx, coarse.dy) == (2 * ar.dx, 2 * ar.dy)
    assert coarse.load == pytest.approx(ar.load, rel=1e-12)
    # every fine cell in contact lies in a coarse cell in contact
    up = np.repeat(np.repeat(coarse.mask, 2, axis=0), 2, axis=1)[: ar.ny, : ar.nx]
    assert np.all(up[ar.mask])
    assert coarse.x[0] == pytest.approx(ar.x[0] + 0.5 * ar.dx)


def test_the_cell_bounds_are_checked_before_anything_is_built(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the operator was built")

    big = areas.ellipse(6e-3, 6e-3, nx=170, ny=170, load=1e4)  # 22,700 cells
    assert np.count_nonzero(big.mask) > exact.MAX_COULOMB_CELLS
    mid = areas.ellipse(6e-3, 6e-3, nx=80, ny=80, load=1e4)  # 5,000 cells
    assert np.count_nonzero(mid.mask) > exact.MAX_DENSE_COULOMB_CELLS
    monkeypatch.setattr(exact.SteadyRollingOperator, "of", refuse)
    with pytest.raises(GridTooLargeError, match="at most 20,000 cells in contact"):
        exact.coulomb(big, 1e-3, 0.0, 0.0, mu=0.3, nu=0.28, shear_modulus=8e10)
    with pytest.raises(GridTooLargeError, match="dense Coulomb solver takes at most 4,000"):
        exact.coulomb(mid, 1e-3, 0.0, 0.0, mu=0.3, nu=0.28, shear_modulus=8e10,
                      solver="dense")
    with pytest.raises(InvalidInputError, match="unknown solver"):
        exact.coulomb(_hertz_area(), 1e-3, 0.0, 0.0, mu=0.3, nu=0.28, shear_modulus=8e10,
                      solver="gauss")


# ------------------------------------------- CONTACT's published exact results
#
# CONTACT (Vollebregt and Kalker; github.com/eve70a/CONTACT, Apache License 2.0), the
# same discrete theory (uniform tractions on rectangular cells, steady rolling with the
# difference over one cell, dq = dx), with its pressure from its own normal solver: here
# from ours on the same grid (the same cells come into contact).

#: examples/tractcurv.inp, first series (original Kalker theory, Coulomb friction):
#: Eurosprinter wheel, a/b = 0.5, A = 0.8e-3 1/mm, 106.7 kN, mu 0.33, G 82 GPa, nu 0.28,
#: 48 x 44 cells over 1.1 times the Hertz ellipse; xi and Fx (N) of tractcurv.ref_out
TRACTCURV = [(1e-5, -247.0), (4e-4, -9112.0), (8e-4, -1.670e4), (1.2e-3, -2.282e4),
             (1.6e-3, -2.757e4), (2.0e-3, -3.104e4), (2.4e-3, -3.333e4), (2.8e-3, -3.462e4),
             (3.2e-3, -3.513e4), (3.6e-3, -3.518e4), (4.0e-3, -3.518e4), (4.4e-3, -3.519e4),
             (4.8e-3, -3.519e4), (5.2e-3, -3.520e4), (5.6e-3, -3.520e4), (6e-3, -3.520e4),
             (8e-3, -3.520e4), (1e-2, -3.521e4), (2e-2, -3.521e4), (3e-2, -3.521e4),
             (4e-2, -3.521e4), (5e-2, -3.521e4), (0.075, -3.521e4), (0.1, -3.521e4),
             (0.125, -3.521e4), (0.15, -3.521e4), (0.175, -3.521e4), (0.2, -3.521e4),
             (0.225, -3.521e4), (0.25, -3.521e4)]


def _curvature_ratio(b_over_a):
    """``B/A`` of the Hertz ellipse with semi-axes ratio ``b/a <= 1`` (normal.hertz_ellipse)."""
    k = b_over_a ** 2
    return float(scipy.special.elliprd(0.0, 1.0, k) / scipy.special.elliprd(0.0, k, 1.0))


def _contact_grid(mx, my, dx, dy, a1, b1, load):
    """Return CONTACT's centred ``mx`` x ``my`` grid, pressure from the gap ``A x^2 + B y^2``."""
    x0, y0 = -(mx - 1) / 2 * dx, -(my - 1) / 2 * dy
    x = x0 + dx * np.arange(mx)
    y = y0 + dy * np.arange(my)
    gap = a1 * x[None, :] ** 2 + b1 * y[:, None] ** 2
    return normal.solve_normal(x0, y0, dx, dy, gap, load=load, shear_modulus=8.2e10,
                               nu=0.28).area


@pytest.fixture(scope="module")
def tractcurv_area():
    a1 = 0.8e-3 * 1e3  # 1/m; a/b = 0.5: the curvature across (y) is A1 over the ratio
    b1 = a1 / _curvature_ratio(0.5)
    h = normal.hertz_ellipse(1 / (2 * a1), 1 / (2 * b1), 106.7e3, shear_modulus=8.2e10,
                             nu=0.28)
    ar = _contact_grid(48, 44, 2.2 * h.a / 48, 2.2 * h.b / 44, a1, b1, 106.7e3)
    assert np.count_nonzero(ar.mask) == 1384  # CONTACT's NCON
    return ar, exact.SteadyRollingOperator.of(ar, nu=0.28, shear_modulus=8.2e10)


@pytest.mark.parametrize("solver", SOLVERS)
def test_contact_published_creep_curve(solver, tractcurv_area):
    ar, op = tractcurv_area
    # the dense reference on every other point (it takes a second a point)
    points = TRACTCURV if solver == "fft" else TRACTCURV[::2]
    for xi, published in points:
        sol = exact.coulomb(ar, xi, 0.0, 0.0, mu=0.33, nu=0.28, shear_modulus=8.2e10,
                            operator=op, solver=solver)
        assert sol.fx == pytest.approx(published, rel=0.006), xi


@pytest.mark.parametrize("solver", SOLVERS)
def test_contact_published_spin_case(solver):
    """Compare with CONTACT's examples/fastsim.inp, case 1: lateral creepage and spin.

    Hertz ellipse a = 8 mm, b = 4 mm, 82 kN, mu 0.3, 44 x 44 cells over 1.1 times the
    ellipse (dx = 0.4 mm, dy = 0.2 mm), eta = -6.25e-4, phi = 0.625 1/m; published
    (fastsim.ref_out): Fy = -1.494e4 N, Mz = -4.821e4 N mm, 920 of 1276 cells slipping.
    CONTACT evaluates the spin's rigid slip at ``x + dq/6`` (its FACPHI, 1/6 by default,
    m_sdis.f90), this solver at the cell centre: the creepages about ``x_P = -dq/6`` pose
    CONTACT's discrete problem (without it Fy is 2.4% smaller).
    """
    k = 0.5 ** 2
    # the major axis a along x: a^3 = N R_x R_D(0, k, 1)/(pi E*) (normal.hertz_ellipse)
    e_star = 8.2e10 / (1 - 0.28)
    r_x = math.pi * e_star * 8e-3 ** 3 / (82e3 * float(scipy.special.elliprd(0.0, k, 1.0)))
    a1 = 1 / (2 * r_x)
    ar = _contact_grid(44, 44, 0.4e-3, 0.2e-3, a1, a1 * _curvature_ratio(0.5), 82e3)
    assert np.count_nonzero(ar.mask) == 1276  # CONTACT's NCON
    x_p = -0.4e-3 / 6
    sol = exact.coulomb(ar, 0.0, -6.25e-4, 0.625, mu=0.3, nu=0.28, shear_modulus=8.2e10,
                        reference=(x_p, 0.0), solver=solver)
    assert sol.fy == pytest.approx(-1.494e4, rel=0.004)
    assert sol.mz + x_p * sol.fy == pytest.approx(-48.21, rel=0.004)
    assert abs(sol.fx) < 1e-9 * abs(sol.fy)
    assert abs(np.count_nonzero(sol.slip) - 920) <= 3


def test_the_fft_solver_crops_the_empty_margin_and_answers_on_the_callers_grid():
    ar = _hertz_area()
    wide = areas.GridArea(ar.x0 - 7 * ar.dx, ar.y0 - 3 * ar.dy, ar.dx, ar.dy,
                          np.pad(ar.pressure, ((3, 5), (7, 2))))
    cr = (2e-4, 1e-4, 0.05)
    tight = exact.coulomb(ar, *cr, mu=0.3, nu=0.28, shear_modulus=8e10)
    padded = exact.coulomb(wide, *cr, mu=0.3, nu=0.28, shear_modulus=8e10)
    assert padded.tau_x.shape == wide.pressure.shape and padded.area is wide
    # the same problem (the grids' origins differ by round-off)
    scale = 0.3 * ar.pressure.max()
    np.testing.assert_allclose(padded.tau_x[3:-5, 7:-2], tight.tau_x, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(padded.tau_y[3:-5, 7:-2], tight.tau_y, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(padded.slip[3:-5, 7:-2], tight.slip)
    assert not padded.tau_x[:3].any() and not padded.slip[-5:].any()
    assert (padded.fx, padded.fy, padded.mz) == pytest.approx((tight.fx, tight.fy, tight.mz),
                                                              rel=1e-12)


@pytest.mark.parametrize("law", [None, ExponentialFriction(0.3, 0.4, 0.6)])
def test_a_warm_start_solves_the_same_problem_in_fewer_newton_steps(law):
    """``start``: a nearby problem's tractions (a fit's last evaluation) start Newton.

    The answer is the problem's, to the solver's tolerance, whatever the start.
    """
    ar = areas.ellipse(6e-3, 4e-3, nx=30, load=5e4)
    kw = dict(nu=0.28, shear_modulus=8e10, speed=20.0)
    kw.update(friction=law) if law is not None else kw.update(mu=0.3)
    near = dict(kw, friction=ExponentialFriction(0.3003, 0.4, 0.6)) if law is not None \
        else dict(kw, mu=0.3003)
    prior = exact.coulomb(ar, 3e-3, 0.0, 0.5, **near)
    start = np.stack([prior.tau_x[ar.mask], prior.tau_y[ar.mask]], axis=1)
    cold = exact.coulomb(ar, 3e-3, 0.0, 0.5, **kw)
    warm = exact.coulomb(ar, 3e-3, 0.0, 0.5, start=start, **kw)
    scale = 0.3 * float(ar.pressure.max())
    assert np.abs(warm.tau_x - cold.tau_x).max() < 1e-6 * scale
    assert np.abs(warm.tau_y - cold.tau_y).max() < 1e-6 * scale
    assert warm.fx == pytest.approx(cold.fx, rel=1e-7)
    assert warm.iterations < cold.iterations
    with pytest.raises(InvalidInputError, match="start tractions"):
        exact.coulomb(ar, 3e-3, 0.0, 0.5, start=start[1:], **kw)


def test_a_steeply_falling_law_converges_by_continuation_in_the_speed():
    """Continuation in |V| solves a steeply falling law, and the solution obeys it.

    Friction halving within 0.7 mm/s of slip (B = 1000 s/m at 10 m/s) on
    CONTACT's Eurosprinter ellipse.
    """
    ar = areas.ellipse(6.304e-3, 12.61e-3, nx=60, ny=60, load=106700.0)
    law = ExponentialFriction(0.37, 0.9, 1000.0)
    g = 8.2e10
    # Newton from the coarse grid's tractions alone runs out of its 200 iterations here
    sol = exact.coulomb(ar, 4e-4, 0.0, 0.0, nu=0.28, shear_modulus=g, friction=law,
                        speed=10.0)
    op = exact.SteadyRollingOperator.of(ar, nu=0.28, shear_modulus=g)
    gx, gy = op.fft_product()(sol.tau_x, sol.tau_y)
    wx, wy = rigid_slip(ar, 4e-4, 0.0, 0.0)
    speed_slip = 10.0 * np.hypot(wx - gx, wy - gy)
    bound = 0.37 * ar.pressure * law.ratio(speed_slip)
    tau = np.hypot(sol.tau_x, sol.tau_y)
    assert np.all(tau[ar.mask] <= bound[ar.mask] * (1 + 1e-3) + 1e-3 * 0.37 * ar.pressure.max())
    assert 0 < np.count_nonzero(sol.slip) < np.count_nonzero(ar.mask)
    assert np.allclose(tau[sol.slip], bound[sol.slip], rtol=1e-3,
                       atol=1e-3 * 0.37 * ar.pressure.max())


def test_where_the_whole_area_newton_cycles_the_dense_reference_answers():
    """The long narrow validation patch at half the saturating eta: the FFT Newton cycles.

    ``coulomb`` then solves with the dense reference (within its cell limit),
    so the caller gets the answer, not a ConvergenceError.
    """
    from fastsim_ros.contact import samples
    mu, g, nu, load = 0.3, samples.STEEL_G, samples.STEEL_NU, 5.0e4
    ar = samples.long_narrow_patch(cells=40, scale=0.01, load=load)
    eta = 0.5 * mu * load / (g * (ar.area / math.pi) * 4.0)
    op = exact.SteadyRollingOperator.of(ar, nu=nu, shear_modulus=g)
    with pytest.raises(ConvergenceError, match="did not converge"):
        partial_slip.solve_area(op, (0.0, eta, 0.0), (0.0, 0.0), mu_s=mu, tol=1e-9)
    sol = exact.coulomb(ar, 0.0, eta, 0.0, mu=mu, nu=nu, shear_modulus=g, operator=op)
    dense = exact.coulomb(ar, 0.0, eta, 0.0, mu=mu, nu=nu, shear_modulus=g, solver="dense")
    assert (sol.fx, sol.fy, sol.mz) == (dense.fx, dense.fy, dense.mz)
    # partial slip, opposing eta, the bound held
    assert -mu * load < sol.fy < 0.0
    assert 0 < np.count_nonzero(sol.slip) < np.count_nonzero(ar.mask)
    bound = mu * ar.pressure
    assert np.all(np.hypot(sol.tau_x, sol.tau_y) <= bound * (1 + 1e-6) + 1e-6 * bound.max())
