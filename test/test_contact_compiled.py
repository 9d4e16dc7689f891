"""The compiled fast path (numba kernels) against the numpy reference, and its physics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import samples
from fastsim_ros.contact import kernels
from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.compiled import (ContactForces, EquivalentEllipseSolver, MaeSolver,
                                          warm_up)
from fastsim_ros.contact.equivalent import equivalent_fastsim
from fastsim_ros.contact.errors import EmptyContactError, InvalidInputError, OutOfTableError
from fastsim_ros.contact.fastsim import StripFlexibility, fastsim, traction_bound
from fastsim_ros.contact.mae import mae_fastsim, mae_geometry, zone_flexibility
from fastsim_ros.contact.tables import coefficient_table

NU, G, MU = 0.28, 8.0e10, 0.3
# agreement asked of the fast path: relative, or relative to the solve's own scale
TOL = 1e-9


# ---------------------------------------------------------------- test areas


def semi_ellipses() -> GridArea:
    """Make two semi-ellipses (a/b 0.5 below, 2 above) of 1 cm^2, Hertz-like pressure, 30 kN."""
    base = areas.semi_ellipses(0.5, 2.0, cells=40)
    a1, b1 = areas.semi_ellipse_axes(0.5)
    a2, b2 = areas.semi_ellipse_axes(2.0)
    x, y = base.x[None, :], base.y[:, None]
    rho2 = np.where(y < 0.0, (x / a1) ** 2 + (y / b1) ** 2, (x / a2) ** 2 + (y / b2) ** 2)
    # positive on every cell of the shape, including those whose centre is outside
    p = np.where(base.mask, np.sqrt(np.clip(1.0 - rho2, 0.0, None) + 1e-3), 0.0)
    return base.with_pressure(p).scaled(0.01).with_load(3e4)


def notched() -> GridArea:
    """Make an ellipse with a lateral slot (strips of two segments) and a hole near its edge."""
    ar = areas.ellipse(5e-3, 4e-3, nx=32, ny=28, load=4e4)
    p = np.array(ar.pressure)
    p[8:20, 14:17] = 0.0
    p[3:6, 20:24] = 0.0
    return ar.with_pressure(p)


def random_patch() -> GridArea:
    """Make a non-convex patch: an ellipse with random holes, a bump, random pressure, moved."""
    rng = np.random.default_rng(7)
    ar = areas.ellipse(4e-3, 5e-3, nx=26, ny=30)
    mask = ar.mask & (rng.random(ar.pressure.shape) > 0.12)
    mask[10:14, 22:26] = True
    p = mask * (0.5 + rng.random(mask.shape)) * 1e9
    return GridArea(ar.x0 + 1e-3, ar.y0 - 2e-3, ar.dx, ar.dy, p)


# name: (a function making the area, reference point (m))
AREAS = {
    "hertz_ellipse": (lambda: areas.ellipse(6e-3, 4e-3, nx=30, load=5e4), (0.0, 0.0)),
    "parabolic_ellipse": (lambda: areas.ellipse(4e-3, 6e-3, nx=24, ny=20, load=5e4,
                                                pressure="parabolic"), (1e-3, 0.0)),
    "semi_ellipses": (semi_ellipses, (0.0, 0.0)),
    "notched": (notched, (-1e-3, 2e-3)),
    # the longest chord on the edge: widest_strip leaves zone 2 empty, auto splits at the
    # centroid
    "truncated": (lambda: samples.truncated_ellipse(cells=30, scale=0.01, load=2e4),
                  (0.0, 0.0)),
    "random": (random_patch, (0.0, 0.0)),
    "odd_shifted": (lambda: areas.ellipse(3e-3, 5e-3, nx=23, ny=17, load=1e4)
                    .shifted(2e-3, -1e-3), (1.5e-3, -0.5e-3)),
}

CREEPAGES = {
    "vanishing": (1e-9, -2e-9, 0.0),
    "partial": (2e-4, 1e-4, 0.0),
    "partial_spin": (-1e-4, 3e-4, 3.0),
    "spin_only": (0.0, 0.0, 5.0),
    "full_slip": (0.3, -0.2, 40.0),
}


@pytest.fixture(scope="module")
def table():
    return coefficient_table(NU)


@pytest.fixture(scope="module")
def mae():
    warm_up()
    return MaeSolver(NU, G)


@pytest.fixture(scope="module")
def baseline():
    return EquivalentEllipseSolver(NU, G)


@pytest.fixture(scope="module", params=sorted(AREAS))
def case(request):
    make, reference = AREAS[request.param]
    ar = make()
    return request.param, ar, reference


def size(ar: GridArea) -> float:
    return math.sqrt(ar.area)


def assert_forces(mine, fx, fy, mz, length):
    """Check forces to TOL of the larger force component, Mz to that force times a length."""
    scale = max(abs(fx), abs(fy))
    assert abs(mine.fx - fx) <= TOL * scale
    assert abs(mine.fy - fy) <= TOL * scale
    assert abs(mine.mz - mz) <= TOL * max(abs(mz), scale * length)


def assert_tractions(mine, tau):
    """Check tractions to TOL of the largest one, and identical slip flags."""
    scale = max(np.abs(tau.tau_x).max(), np.abs(tau.tau_y).max())
    assert np.abs(mine.tau_x - tau.tau_x).max() <= TOL * scale
    assert np.abs(mine.tau_y - tau.tau_y).max() <= TOL * scale
    assert np.array_equal(mine.slip, tau.slip)


def reference_bound(ar: GridArea, bound: str) -> np.ndarray:
    return traction_bound(ar, MU, bound=bound)


# ---------------------------------------------------------------- MAE + FastSim


@pytest.mark.parametrize("bound", ["given", "parabolic"])
@pytest.mark.parametrize("creep", sorted(CREEPAGES))
def test_mae_equals_reference(mae, table, case, creep, bound):
    _, ar, reference = case
    xi, eta, phi = CREEPAGES[creep]
    ref = mae_fastsim(ar, xi, eta, phi, bound=reference_bound(ar, bound), table=table,
                      shear_modulus=G, reference=reference)
    mine = mae.solve(ar, xi, eta, phi, mu=MU, reference=reference, bound=bound,
                     tractions=True)
    assert_forces(mine, ref.fx, ref.fy, ref.mz, size(ar))
    assert_tractions(mine, ref.traction)
    assert mine.slip_fraction == np.count_nonzero(ref.traction.slip) / np.count_nonzero(ar.mask)
    assert mine.n == pytest.approx(ar.load, rel=1e-13)
    assert mine.grid == (ar.x0, ar.y0, ar.dx, ar.dy)
    # the arrays entry point is the same computation
    arrays = mae.solve_arrays(np.array(ar.pressure), ar.x0, ar.y0, ar.dx, ar.dy, xi, eta, phi,
                              MU, reference=reference, bound=bound)
    assert (arrays.fx, arrays.fy, arrays.mz) == (mine.fx, mine.fy, mine.mz)
    assert arrays.tau_x is None and arrays.slip is None


@pytest.mark.parametrize("rule", ["auto", "widest_strip", "centroid"])
def test_mae_geometry_and_flexibility_equal_reference(table, case, rule):
    _, ar, _ = case
    solver = MaeSolver(NU, G, rule=rule)
    ref = mae_geometry(ar, rule)
    mine = solver.geometry(ar)
    length = size(ar)
    for name in ("x_c", "y_c", "y_s"):
        assert getattr(mine, name) == pytest.approx(getattr(ref, name), abs=1e-12 * length)
    assert mine.area == pytest.approx(ref.area, rel=1e-13)
    assert mine.rule == rule
    for z_mine, z_ref in ((mine.zone1, ref.zone1), (mine.zone2, ref.zone2)):
        assert z_mine.empty == z_ref.empty
        mine_v = np.array([z_mine.area, z_mine.a, z_mine.b, z_mine.a_over_b, z_mine.a_eq,
                           z_mine.b_eq])
        ref_v = np.array([z_ref.area, z_ref.a, z_ref.b, z_ref.a_over_b, z_ref.a_eq,
                          z_ref.b_eq])
        np.testing.assert_allclose(mine_v, ref_v, rtol=1e-12)
    for f_mine, z_ref in zip(solver.flexibility(ar), (ref.zone1, ref.zone2)):
        if z_ref.empty:
            assert f_mine is None
            continue
        f_ref = zone_flexibility(z_ref, table, G)
        assert f_mine is not None
        np.testing.assert_allclose(np.array([f_mine.l1, f_mine.l2, f_mine.l3, f_mine.l4]),
                                   np.array([f_ref.l1, f_ref.l2, f_ref.l3, f_ref.l4]),
                                   rtol=1e-12)


@pytest.mark.parametrize("g1, g2", [(0.5, 2.0), (5.0, 1.0), (0.2, 0.2)])
def test_mae_on_table5_family_equals_reference(mae, table, g1, g2):
    ar = areas.semi_ellipses(g1, g2, cells=40).scaled(0.01).with_load(2e4)
    ref = mae_fastsim(ar, 1e-4, 2e-4, 2.0, bound=traction_bound(ar, MU), table=table,
                      shear_modulus=G)
    assert_forces(mae.solve(ar, 1e-4, 2e-4, 2.0, mu=MU), ref.fx, ref.fy, ref.mz, size(ar))


def test_mae_empty_zone_equals_reference(table):
    # the widest strip is the first one: zone 1 is empty under widest_strip (auto would
    # split at the centroid), its strips carry no contact
    mae = MaeSolver(NU, G, rule="widest_strip")
    ar = areas.ellipse(2e-3, 2e-3, nx=20, load=1e4)
    p = np.array(ar.pressure)
    p[:10] = 0.0
    p[10] = p[10:].max()
    ar = ar.with_pressure(p)
    geometry = mae.geometry(ar)
    assert geometry.zone1.empty and geometry.zone1.area == 0.0
    assert mae.flexibility(ar)[0] is None
    ref = mae_fastsim(ar, 1e-4, 0.0, 1.0, bound=traction_bound(ar, MU), table=table,
                      shear_modulus=G, rule="widest_strip")
    assert_forces(mae.solve(ar, 1e-4, 0.0, 1.0, mu=MU), ref.fx, ref.fy, ref.mz, size(ar))


# ---------------------------------------------------------------- equivalent ellipse


@pytest.mark.parametrize("bound", ["given", "parabolic"])
@pytest.mark.parametrize("creep", sorted(CREEPAGES))
def test_equivalent_equals_reference(baseline, table, case, creep, bound):
    _, ar, reference = case
    xi, eta, phi = CREEPAGES[creep]
    ref = equivalent_fastsim(ar, xi, eta, phi, mu=MU, table=table, shear_modulus=G,
                             reference=reference, bound=bound)
    mine = baseline.solve(ar, xi, eta, phi, mu=MU, reference=reference, bound=bound,
                          tractions=True)
    assert_forces(mine, ref.fx, ref.fy, ref.mz, size(ar))
    assert_tractions(mine, ref.traction)
    slipping = np.count_nonzero(ref.traction.slip)
    assert mine.slip_fraction == slipping / np.count_nonzero(ref.grid.mask)
    assert mine.n == pytest.approx(ar.load, rel=1e-13)
    np.testing.assert_allclose(mine.grid, (ref.grid.x0, ref.grid.y0, ref.grid.dx,
                                           ref.grid.dy), rtol=0, atol=1e-12 * size(ar))
    e, e_ref = baseline.ellipse(ar), ref.ellipse
    np.testing.assert_allclose([e.x_c, e.y_c, e.a, e.b], [e_ref.x_c, e_ref.y_c, e_ref.a,
                                                          e_ref.b], rtol=0,
                               atol=1e-12 * size(ar))


@pytest.mark.parametrize("cells", [2, 7, 31])
def test_equivalent_with_explicit_cells(table, cells):
    ar = semi_ellipses()
    ref = equivalent_fastsim(ar, 2e-4, 0.0, 1.0, mu=MU, table=table, shear_modulus=G,
                             cells=cells)
    mine = EquivalentEllipseSolver(NU, G, cells=cells).solve(ar, 2e-4, 0.0, 1.0, mu=MU)
    assert_forces(mine, ref.fx, ref.fy, ref.mz, size(ar))


# ---------------------------------------------------------------- kernels themselves


def envelopes(bound: np.ndarray) -> np.ndarray:
    """Rows ``[first, last + 1)`` of each column's positive cells (``[ny, 0)`` if none)."""
    ny, nx = bound.shape
    env = np.empty((2, nx), dtype=np.int64)
    for i in range(nx):
        rows = np.flatnonzero(bound[:, i] > 0.0)
        env[:, i] = (rows[0], rows[-1] + 1) if rows.size else (ny, 0)
    return env


@pytest.mark.parametrize("unbounded", [False, True])
@pytest.mark.parametrize("creep", ["partial_spin", "full_slip"])
def test_sweep_equals_reference_fastsim(case, creep, unbounded):
    # per-strip flexibilities all different, an infinite spin flexibility on some strips
    _, ar, reference = case
    rng = np.random.default_rng(3)
    ny = ar.ny
    l1, l2, l3 = (1e-11 * (0.5 + rng.random(ny)) for _ in range(3))
    spin = np.where(rng.random(ny) < 0.3, np.inf, 1e-11 * (1.0 + rng.random(ny)))
    flex = StripFlexibility(l1, l2, l3, spin)
    bound = np.where(ar.mask, np.inf, 0.0) if unbounded else traction_bound(ar, MU)
    point = (ar.x0 + 0.4 * ar.dx * ar.nx, ar.y0 + 0.6 * ar.dy * ar.ny)
    xi, eta, phi = CREEPAGES[creep]
    ref = fastsim(ar, xi, eta, phi, bound=bound, flexibility=flex, sweep_point=point,
                  reference=reference)
    xi_s = xi + phi * (reference[1] - point[1])
    eta_s = eta - phi * (reference[0] - point[0])
    out = np.empty((3,) + bound.shape)
    slip = np.empty(bound.shape, dtype=bool)
    fx, fy, mz, nslip, ncontact = kernels.sweep(
        bound, 1.0, 1.0, envelopes(bound), ar.x0, ar.y0, ar.dx, ar.dy, xi_s, eta_s, phi,
        np.array([flex.l1, flex.l2, flex.l3, flex.spin]), point[0], point[1], reference[0],
        reference[1], kernels.LAW_CONSTANT, np.zeros(2), 0.0, out[0], out[1], slip, True, False)
    assert_forces(ContactForces(fx, fy, mz, 0.0, 0.0), ref.fx, ref.fy, ref.mz, size(ar))
    scale = max(np.abs(ref.tau_x).max(), np.abs(ref.tau_y).max())
    assert np.abs(out[0] - ref.tau_x).max() <= TOL * scale
    assert np.abs(out[1] - ref.tau_y).max() <= TOL * scale
    assert np.array_equal(slip, ref.slip) and nslip == np.count_nonzero(ref.slip)
    assert ncontact == np.count_nonzero(ar.mask)


@pytest.mark.parametrize("name", kernels.TABLE_NAMES)
def test_spline_equals_table(table, name):
    index = kernels.TABLE_NAMES.index(name)
    polys = np.stack([table.poly[n] for n in kernels.TABLE_NAMES])
    ratios = np.concatenate([np.exp(table.knots), np.geomspace(0.1, 10.0, 37)])
    for g in ratios:
        assert kernels.table_value(table.knots, polys, index, g) == pytest.approx(
            table(name, g), rel=1e-13, abs=1e-15)


# ---------------------------------------------------------------- batches


@pytest.mark.parametrize("bound", ["given", "parabolic"])
@pytest.mark.parametrize("solver_type", [MaeSolver, EquivalentEllipseSolver])
def test_batch_equals_one_by_one(solver_type, bound):
    solver = solver_type(NU, G)
    rng = np.random.default_rng(11)
    base = semi_ellipses()
    size_b = 9
    # different patches (pressure and load), a repeated one, different grids and mu
    ps = np.array([base.pressure * (0.5 + rng.random(base.pressure.shape)) for _ in
                   range(size_b)])
    ps[4] = ps[3]
    x0 = base.x0 + 1e-4 * rng.standard_normal(size_b)
    x0[4] = x0[3]
    dx = base.dx * (1.0 + 0.1 * rng.random(size_b))
    dx[4] = dx[3]
    mu = np.full(size_b, MU)
    mu[6] = 0.5
    creep = np.column_stack([1e-4 * rng.standard_normal(size_b),
                             1e-4 * rng.standard_normal(size_b), rng.standard_normal(size_b)])
    out = solver.solve_batch(ps, x0, base.y0, dx, base.dy, creep, mu=mu,
                             reference=(1e-4, 0.0), bound=bound)
    assert out.shape == (size_b, 3)
    for b in range(size_b):
        one = solver.solve_arrays(ps[b], x0[b], base.y0, dx[b], base.dy, *creep[b], mu[b],
                                  reference=(1e-4, 0.0), bound=bound)
        assert tuple(out[b]) == (one.fx, one.fy, one.mz)


def test_batch_of_creepages_on_one_patch(mae, baseline):
    ar = semi_ellipses()
    creep = np.column_stack([np.geomspace(1e-6, 1e-2, 12), np.zeros(12), np.linspace(0, 5, 12)])
    for solver in (mae, baseline):
        out = solver.solve_batch(ar.pressure, ar.x0, ar.y0, ar.dx, ar.dy, creep, mu=MU)
        one = [solver.solve(ar, *c, mu=MU) for c in creep]
        np.testing.assert_array_equal(out, [(r.fx, r.fy, r.mz) for r in one])
    assert mae.solve_batch(ar.pressure, ar.x0, ar.y0, ar.dx, ar.dy, np.empty((0, 3)),
                           mu=MU).shape == (0, 3)


# ---------------------------------------------------------------- physics


@pytest.mark.parametrize("bound", ["given", "parabolic"])
@pytest.mark.parametrize("solver_type", [MaeSolver, EquivalentEllipseSolver])
def test_full_slip_gives_mu_n(case, solver_type, bound):
    # along x only: MAE's zones have their own L1/L2, so a skew creepage would turn the
    # tractions of the two zones by different angles (|F| a little under mu N)
    _, ar, _ = case
    r = solver_type(NU, G).solve(ar, -2.0, 0.0, 0.0, mu=MU, bound=bound)
    assert r.fx == pytest.approx(MU * ar.load, rel=1e-9) and r.fy == 0.0
    # both bounds keep every cell in contact
    assert r.slip_fraction == 1.0


@pytest.mark.parametrize("solver_type", [MaeSolver, EquivalentEllipseSolver])
def test_vanishing_creepage_is_linear(case, solver_type):
    _, ar, reference = case
    solver = solver_type(NU, G)
    small = solver.solve(ar, 1e-10, 2e-10, 1e-7, mu=MU, reference=reference)
    double = solver.solve(ar, 2e-10, 4e-10, 2e-7, mu=MU, reference=reference)
    assert small.slip_fraction == 0.0 and double.slip_fraction == 0.0
    for one, two in ((small.fx, double.fx), (small.fy, double.fy), (small.mz, double.mz)):
        assert two == pytest.approx(2.0 * one, rel=1e-9)


def test_vanishing_creepage_gives_kalker_on_ellipse(mae, baseline, table):
    # FastSim with the pinned discretisation is within 0.1% of Kalker at 60x60 (the physics guide)
    a, b = 6e-3, 4e-3
    ar = areas.ellipse(a, b, nx=60, load=5e4)
    c11, c22, _ = table.kalker(a / b)
    for solver in (mae, baseline):
        rx = solver.solve(ar, 1e-9, 0.0, 0.0, mu=MU)
        ry = solver.solve(ar, 0.0, 1e-9, 0.0, mu=MU)
        assert -rx.fx / (G * a * b * c11 * 1e-9) == pytest.approx(1.0, abs=2e-3)
        assert -ry.fy / (G * a * b * c22 * 1e-9) == pytest.approx(1.0, abs=2e-3)
        assert abs(rx.fy) <= 1e-9 * abs(rx.fx)


# ---------------------------------------------------------------- bad inputs


def good_arrays():
    ar = areas.ellipse(3e-3, 3e-3, nx=10, load=1e4)
    return np.array(ar.pressure), ar.x0, ar.y0, ar.dx, ar.dy


@pytest.mark.parametrize("solver_type", [MaeSolver, EquivalentEllipseSolver])
@pytest.mark.parametrize("change, error, match", [
    ({"cell": math.nan}, InvalidInputError, "NaN or infinite"),
    ({"cell": math.inf}, InvalidInputError, "NaN or infinite"),
    ({"cell": -1.0}, InvalidInputError, "negative pressure"),
    ({"zero": True}, EmptyContactError, "no cell in contact"),
    ({"dx": 0.0}, InvalidInputError, "cell sizes must be positive"),
    ({"x0": math.nan}, InvalidInputError, "grid origin or cell size"),
    ({"xi": math.nan}, InvalidInputError, "creepages .* must be finite"),
    ({"phi": math.inf}, InvalidInputError, "creepages .* must be finite"),
    ({"mu": 0.0}, InvalidInputError, "mu must be positive"),
    ({"mu": math.nan}, InvalidInputError, "mu must be positive"),
    ({"reference": (math.nan, 0.0)}, InvalidInputError, "reference point"),
    ({"bound": "hertz"}, InvalidInputError, "unknown traction bound"),
    ({"flat": True}, InvalidInputError, "2-D array"),
])
def test_bad_input_is_refused(solver_type, change, error, match):
    p, x0, y0, dx, dy = good_arrays()
    if "cell" in change:
        p[5, 5] = change["cell"]
    if change.get("zero"):
        p[:] = 0.0
    if change.get("flat"):
        p = p.ravel()
    args = {"x0": x0, "y0": y0, "dx": dx, "dy": dy, "xi": 1e-3, "eta": 0.0, "phi": 0.0,
            "mu": MU}
    args.update({k: v for k, v in change.items() if k in args})
    kwargs = {k: v for k, v in change.items() if k in ("reference", "bound")}
    with pytest.raises(error, match=match):
        solver_type(NU, G).solve_arrays(p, args["x0"], args["y0"], args["dx"], args["dy"],
                                        args["xi"], args["eta"], args["phi"], args["mu"],
                                        **kwargs)


def test_zone_outside_the_table_is_refused(table):
    # a long thin strip pair: each zone is one strip, a/b = 100, far beyond the tables
    thin = GridArea(0.0, 0.0, 1e-4, 1e-4, np.ones((2, 200)))
    with pytest.raises(OutOfTableError, match="outside the tables' range"):
        mae_fastsim(thin, 1e-3, 0.0, 0.0, bound=traction_bound(thin, MU), table=table,
                    shear_modulus=G)
    with pytest.raises(OutOfTableError, match=r"MAE zone 1 \(y < y_s\): a/b = 100 lies"):
        MaeSolver(NU, G).solve(thin, 1e-3, 0.0, 0.0, mu=MU)
    with pytest.raises(OutOfTableError, match="equivalent ellipse: a/b = "):
        EquivalentEllipseSolver(NU, G).solve(thin, 1e-3, 0.0, 0.0, mu=MU)
    # the geometry alone needs no table
    assert MaeSolver(NU, G).geometry(thin).zone1.a_over_b == pytest.approx(100.0)


def test_bad_solver_settings_are_refused():
    with pytest.raises(OutOfTableError, match="nu = 0.7"):
        MaeSolver(0.7, G)
    with pytest.raises(InvalidInputError, match="shear modulus must be positive"):
        EquivalentEllipseSolver(NU, -1.0)
    with pytest.raises(InvalidInputError, match="unknown split rule"):
        MaeSolver(NU, G, rule="middle")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="cells must be at least 2"):
        EquivalentEllipseSolver(NU, G, cells=1)
    # a one-cell patch still has an equivalent ellipse: the smallest grid, 2 x 2 cells
    single = GridArea(0.0, 0.0, 1e-3, 1e-3, np.ones((1, 1)))
    r = EquivalentEllipseSolver(NU, G).solve(single, 1.0, 0.0, 0.0, mu=MU)
    assert r.fx == pytest.approx(-MU * single.load, rel=1e-9)


@pytest.mark.parametrize("solver_type", [MaeSolver, EquivalentEllipseSolver])
def test_bad_batch_is_refused_with_its_item(solver_type):
    p, x0, y0, dx, dy = good_arrays()
    solver = solver_type(NU, G)
    ps = np.array([p] * 5)
    ps[3, 2, 2] = -5.0
    creep = np.zeros((5, 3))
    with pytest.raises(InvalidInputError, match="batch item 3: negative pressure"):
        solver.solve_batch(ps, x0, y0, dx, dy, creep, mu=MU)
    creep[2, 1] = math.nan
    with pytest.raises(InvalidInputError, match="batch item 2: creepages"):
        solver.solve_batch(p, x0, y0, dx, dy, creep, mu=MU)
    with pytest.raises(InvalidInputError, match=r"shape \(B, 3\)"):
        solver.solve_batch(p, x0, y0, dx, dy, np.zeros((5, 2)), mu=MU)
    with pytest.raises(InvalidInputError, match="2 patches for 5 creepages"):
        solver.solve_batch(ps[:2], x0, y0, dx, dy, np.zeros((5, 3)), mu=MU)
    with pytest.raises(InvalidInputError, match=r"mu must be a scalar or have shape \(5,\)"):
        solver.solve_batch(ps, x0, y0, dx, dy, np.zeros((5, 3)), mu=np.ones(3))
