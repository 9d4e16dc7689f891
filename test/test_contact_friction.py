"""Slip-dependent friction: the laws, FastSim, MAE, the ellipse, the exact solver.

Physics asserted: A = 1 or B = 0 is constant friction bit for bit; in every
slipping cell the traction equals mu(v) p with v the slip velocity that the
traction increment implies; at full slip |F| = mu(V s) N; the creep curve
has a peak below mu_s N that moves to smaller creepage as B grows; the
compiled path equals the numpy reference.
"""

import math

import numpy as np
import pytest

from fastsim_ros.contact import samples
from fastsim_ros.contact.area import ellipse
from fastsim_ros.contact.compiled import EquivalentEllipseSolver, MaeSolver
from fastsim_ros.contact.equivalent import equivalent_fastsim
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.fastsim import (StripFlexibility, fastsim, kalker_flexibility,
                                         traction_bound)
from fastsim_ros.contact.friction import (LAW_CONSTANT, ConstantFriction, ExponentialFriction,
                                          friction_law)
from fastsim_ros.contact.mae import mae_fastsim
from fastsim_ros.contact.tables import coefficient_table

NU, G = 0.28, 8.0e10
MU = 0.4
V = 20.0  # rolling speed, m/s
A_AX, B_AX, LOAD = 6e-3, 4e-3, 1e5
FALLING = ExponentialFriction(MU, 0.4, 0.6)
CREEP = [(2e-3, 0.0, 0.0), (1e-3, -1e-3, 0.5), (4e-3, 2e-3, -1.0), (0.05, 0.0, 0.0)]


@pytest.fixture(scope="module")
def table():
    return coefficient_table(NU)


@pytest.fixture(scope="module")
def hertz():
    return ellipse(A_AX, B_AX, nx=30, ny=30, load=LOAD)


@pytest.fixture(scope="module")
def flange():
    return samples.flange_root_patch(cells=30)


def kalker_fastsim(area, table, xi, eta, phi, law, speed, bound="parabolic"):
    c11, c22, c23 = table.kalker(A_AX / B_AX)
    l1, l2, l3 = kalker_flexibility(A_AX, B_AX, c11, c22, c23, G)
    ones = np.ones(area.ny)
    flex = StripFlexibility(l1 * ones, l2 * ones, l3 * ones, l3 * ones)
    g = traction_bound(area, law.mu_s, bound=bound)
    return fastsim(area, xi, eta, phi, bound=g, flexibility=flex, friction=law,
                   speed=speed), flex, g


# ---------------------------------------------------------------- the laws


def test_exponential_law_values():
    law = ExponentialFriction(0.5, 0.3, 2.0)
    v = np.array([0.0, 0.5, 1e6])
    assert law.mu(v) == pytest.approx([0.5, 0.5 * (0.7 * math.exp(-1.0) + 0.3), 0.15])
    # slope against a central difference
    h = 1e-6
    assert law.ratio_slope(0.5) == pytest.approx(
        (law.ratio(0.5 + h) - law.ratio(0.5 - h)) / (2 * h), rel=1e-7)
    assert law.slip_dependent and not ConstantFriction(0.3).slip_dependent
    assert ExponentialFriction(0.3, 1.0, 5.0).code == LAW_CONSTANT
    assert ExponentialFriction(0.3, 0.2, 0.0).code == LAW_CONSTANT


@pytest.mark.parametrize("args, text", [
    ((0.0, 0.5, 1.0), "mu must be positive"),
    ((math.nan, 0.5, 1.0), "mu must be positive"),
    ((0.3, 0.0, 1.0), "limit ratio A"),
    ((0.3, 1.5, 1.0), "limit ratio A"),
    ((0.3, 0.5, -1.0), "decay B"),
    ((0.3, 0.5, math.inf), "decay B"),
])
def test_exponential_law_refuses(args, text):
    with pytest.raises(InvalidInputError, match=text):
        ExponentialFriction(*args)


def test_law_by_name():
    assert friction_law("constant", 0.3) == ConstantFriction(0.3)
    assert friction_law("exponential", 0.3, limit_ratio=0.5, decay=1.0) == \
        ExponentialFriction(0.3, 0.5, 1.0)
    with pytest.raises(InvalidInputError, match="unknown friction law"):
        friction_law("polach", 0.3)


# ---------------------------------------------------------------- reduction to constant


@pytest.mark.parametrize("law", [ExponentialFriction(MU, 1.0, 0.8),
                                 ExponentialFriction(MU, 0.3, 0.0), ConstantFriction(MU)])
@pytest.mark.parametrize("creep", CREEP)
def test_constant_limits_give_todays_numbers(law, creep, table, hertz, flange):
    g = traction_bound(flange, MU)
    old = mae_fastsim(flange, *creep, bound=g, table=table, shear_modulus=G)
    new = mae_fastsim(flange, *creep, bound=g, table=table, shear_modulus=G, friction=law,
                      speed=V)
    assert (new.fx, new.fy, new.mz) == (old.fx, old.fy, old.mz)
    old_e = equivalent_fastsim(flange, *creep, mu=MU, table=table, shear_modulus=G)
    new_e = equivalent_fastsim(flange, *creep, table=table, shear_modulus=G, friction=law,
                               speed=V)
    assert (new_e.fx, new_e.fy, new_e.mz) == (old_e.fx, old_e.fy, old_e.mz)
    for solver in (MaeSolver(NU, G), EquivalentEllipseSolver(NU, G)):
        for area in (hertz, flange):
            for bound in ("given", "parabolic"):
                a = solver.solve(area, *creep, mu=MU, bound=bound)
                b = solver.solve(area, *creep, friction=law, speed=V, bound=bound)
                assert (a.fx, a.fy, a.mz) == (b.fx, b.fy, b.mz)
                assert a.slip_fraction == b.slip_fraction
        batch = np.array([creep, creep])
        a = solver.solve_batch(flange.pressure, flange.x0, flange.y0, flange.dx, flange.dy,
                               batch, mu=MU)
        b = solver.solve_batch(flange.pressure, flange.x0, flange.y0, flange.dx, flange.dy,
                               batch, friction=law, speed=V)
        assert np.array_equal(a, b)


# ---------------------------------------------------------------- consistency per cell


@pytest.mark.parametrize("creep", [(2e-3, 0.0, 0.0), (1e-3, 1.5e-3, 0.0), (0.02, -0.01, 0.0)])
def test_slipping_cells_satisfy_the_law(creep, table, hertz):
    """|tau| = mu(v) p in each slipping cell, v = V |s_k| the slip at the upstream cell's ratio.

    Trial t* = tau_prev - (w/L) h; kinetic level k g_s (k: the upstream
    cell's |tau|/g_s if it slipped, else 1); s_k = w + L (k g_s t*/|t*| -
    tau_prev)/h (fastsim.slip_ratio).  A slipping cell lies on mu(V |s_k|)
    p along t*; an adhering one is the trial itself (s = 0), within its
    level or with friction at its level's slip above the trial.
    """
    res, flex, g = kalker_fastsim(hertz, table, *creep, FALLING, V)
    xi, eta, _ = creep
    w = np.array([xi, eta])
    checked = 0
    for j in range(hertz.ny):
        lj = np.array([flex.l1[j], flex.l2[j]])
        prev = np.zeros(2)
        first = True
        k = 1.0
        for i in range(hertz.nx - 1, -1, -1):
            if not g[j, i] > 0.0:
                prev, first, k = np.zeros(2), True, 1.0
                continue
            h = 0.5 * hertz.dx if first else hertz.dx
            tau = np.array([res.tau_x[j, i], res.tau_y[j, i]])
            trial = prev - w / lj * h
            m = np.hypot(*trial)
            s_k = w + lj * (k * g[j, i] * trial / m - prev) / h
            mu_k = FALLING.mu(V * np.hypot(*s_k))
            if res.slip[j, i]:
                assert m > k * g[j, i]
                assert np.hypot(*tau) == pytest.approx(mu_k / MU * g[j, i], rel=1e-12)
                assert np.abs(tau / np.hypot(*tau) - trial / m).max() <= 1e-12
                # the slip opposes the traction
                assert float(s_k @ tau) < 0.0
                k = np.hypot(*tau) / g[j, i]
                checked += 1
            else:
                assert np.abs(tau - trial).max() <= 1e-9 * g[j, i]
                assert m <= k * g[j, i] or mu_k / MU * g[j, i] >= m
                k = 1.0
            prev, first = tau, False
    assert checked > 10


def slip_runs(flags):
    """Count the separate runs of slipping cells in a strip's flags."""
    f = np.concatenate([[False], flags])
    return int(np.count_nonzero(f[1:] & ~f[:-1]))


@pytest.mark.parametrize("decay", [0.3, 1.0, 3.0, 10.0])
@pytest.mark.parametrize("xi", [2e-3, 5e-3, 9.3e-3, 2e-2])
def test_slip_zones_stay_whole_and_slip_velocities_bounded(decay, xi, table, hertz):
    """Pure xi on an ellipse: the strips stick and slip as with constant friction, in one piece.

    The rule's reason (fastsim.slip_ratio): with the cell's own traction
    change in its slip, the first slipping cell dropped to near A g_s with a
    slip ten times the rigid one and the strip alternated stick and slip.
    Here no strip has more separate slip zones than with constant friction
    (a strip's first cell may slip on the staircase edge), and the slip at
    the frozen ratio stays below the constant-friction FastSim's largest
    slip, xi + 2 L1 g_0/a on the ellipse.
    """
    law = ExponentialFriction(MU, 0.4, decay)
    res, flex, g = kalker_fastsim(hertz, table, xi, 0.0, 0.0, law, V)
    const, _, _ = kalker_fastsim(hertz, table, xi, 0.0, 0.0, ConstantFriction(MU), V)
    g0 = float(g.max())
    s_max = xi + 2.0 * flex.l1[0] * g0 / A_AX
    checked = 0
    for j in range(hertz.ny):
        cells = np.flatnonzero(g[j] > 0.0)[::-1]  # leading edge first
        flags = res.slip[j, cells]
        assert slip_runs(flags) <= max(1, slip_runs(const.slip[j, cells])), f"strip {j}"
        tau = -res.tau_x[j, cells]
        # the slip at the upstream cell's level, per cell: L (m - k g_s)/h
        prev, k = 0.0, 1.0
        for n, i in enumerate(cells):
            h = 0.5 * hertz.dx if n == 0 else hertz.dx
            m = prev + xi / flex.l1[j] * h
            if flags[n]:
                assert flex.l1[j] * (m - k * g[j, i]) / h <= s_max
                k = tau[n] / g[j, i]
                checked += 1
            else:
                k = 1.0
            prev = tau[n]
    assert checked > 0


# ---------------------------------------------------------------- compiled = reference


@pytest.mark.parametrize("creep", CREEP)
@pytest.mark.parametrize("bound", ["given", "parabolic"])
def test_compiled_equals_reference(creep, bound, table, flange):
    g = traction_bound(flange, MU, bound=bound)
    ref = mae_fastsim(flange, *creep, bound=g, table=table, shear_modulus=G, friction=FALLING,
                      speed=V)
    got = MaeSolver(NU, G).solve(flange, *creep, friction=FALLING, speed=V, bound=bound,
                                 tractions=True)
    n = flange.load
    assert abs(got.fx - ref.fx) <= 1e-12 * MU * n and abs(got.fy - ref.fy) <= 1e-12 * MU * n
    assert np.abs(got.tau_x - ref.traction.tau_x).max() <= 1e-12 * g.max()
    assert np.array_equal(got.slip, ref.traction.slip)
    ref_e = equivalent_fastsim(flange, *creep, table=table, shear_modulus=G, friction=FALLING,
                               speed=V, bound=bound)
    got_e = EquivalentEllipseSolver(NU, G).solve(flange, *creep, friction=FALLING, speed=V,
                                                 bound=bound)
    assert abs(got_e.fx - ref_e.fx) <= 1e-12 * MU * n
    assert abs(got_e.fy - ref_e.fy) <= 1e-12 * MU * n
    # a batch item equals the single solve, with per-item speeds
    out = MaeSolver(NU, G).solve_batch(flange.pressure, flange.x0, flange.y0, flange.dx,
                                       flange.dy, np.array([creep, creep]), friction=FALLING,
                                       speed=np.array([V, 2 * V]), bound=bound)
    assert out[0, 0] == got.fx
    twice = MaeSolver(NU, G).solve(flange, *creep, friction=FALLING, speed=2 * V, bound=bound)
    assert out[1, 0] == twice.fx


# ---------------------------------------------------------------- full slip and the peak


def test_full_slip_force_is_mu_of_the_slip_velocity(table, hertz, flange):
    xi = 0.5  # rigid slip 0.5: v = V * 0.5 = 10 m/s
    mu_full = float(FALLING.mu(V * xi))
    res, _, _ = kalker_fastsim(hertz, table, xi, 0.0, 0.0, FALLING, V)
    assert -res.fx == pytest.approx(mu_full * LOAD, rel=2e-3)
    for solver in (MaeSolver(NU, G), EquivalentEllipseSolver(NU, G)):
        for area in (hertz, flange):
            f = solver.solve(area, xi, 0.0, 0.0, friction=FALLING, speed=V)
            assert -f.fx == pytest.approx(mu_full * area.load, rel=2e-3)
            assert f.slip_fraction == 1.0
    # lateral, too
    f = MaeSolver(NU, G).solve(flange, 0.0, -xi, 0.0, friction=FALLING, speed=V)
    assert f.fy == pytest.approx(mu_full * flange.load, rel=2e-3)


def test_peak_below_mu_s_moves_to_smaller_creepage(table, hertz):
    xis = np.geomspace(2e-4, 0.1, 60)
    peaks = []
    for decay in (0.2, 0.6, 2.0):
        law = ExponentialFriction(MU, 0.4, decay)
        f = np.array([-kalker_fastsim(hertz, table, xi, 0.0, 0.0, law, V)[0].fx for xi in xis])
        k = int(np.argmax(f))
        assert 0 < k < xis.size - 1, "an interior maximum"
        assert f[k] < MU * LOAD
        assert f[-1] < 0.9 * f[k], "the curve falls after its peak"
        peaks.append((xis[k], f[k]))
    assert peaks[0][0] > peaks[1][0] > peaks[2][0]
    assert peaks[0][1] > peaks[1][1] > peaks[2][1]


@pytest.mark.parametrize("decay", [1.0, 3.0])
def test_fastsim_peak_converges_with_the_grid(decay, hertz):
    """The falling-friction peak does not drift as the cells shrink (fastsim.slip_ratio).

    The implicit per-cell step's gain grew as 1/h: its peak at B = 1 fell
    from 0.852 to 0.768 to 0.726 mu_s N on 30, 60, 120 cells.
    """
    law = ExponentialFriction(MU, 0.4, decay)
    xis = np.geomspace(5e-3, 2e-2, 15)
    peaks = []
    for cells in (60, 120):
        solver = EquivalentEllipseSolver(NU, G, cells=cells)
        peaks.append(max(-solver.solve(hertz, xi, 0.0, 0.0, friction=law, speed=V,
                                       bound="parabolic").fx for xi in xis))
    assert abs(peaks[0] - peaks[1]) <= 3e-3 * MU * LOAD


def test_solvers_refuse_bad_friction_arguments(flange):
    solver = MaeSolver(NU, G)
    with pytest.raises(InvalidInputError, match="rolling speed"):
        solver.solve(flange, 1e-3, 0.0, 0.0, friction=FALLING)
    with pytest.raises(InvalidInputError, match="rolling speed"):
        solver.solve(flange, 1e-3, 0.0, 0.0, friction=FALLING, speed=-1.0)
    with pytest.raises(InvalidInputError, match="differs"):
        solver.solve(flange, 1e-3, 0.0, 0.0, mu=0.3, friction=FALLING, speed=V)
    with pytest.raises(InvalidInputError, match="give mu"):
        solver.solve(flange, 1e-3, 0.0, 0.0)
    with pytest.raises(InvalidInputError, match="rolling speed"):
        solver.solve_batch(flange.pressure, flange.x0, flange.y0, flange.dx, flange.dy,
                           np.zeros((2, 3)), friction=FALLING, speed=[1.0, math.nan])
    # constant friction needs no speed (today's calls)
    solver.solve(flange, 1e-3, 0.0, 0.0, mu=MU)


# ---------------------------------------------------------------- the exact solver


@pytest.fixture(scope="module", params=["fft", "dense"])
def exact_setup(request):
    """Return the area, its operator and the Coulomb solver (both pass every test)."""
    from fastsim_ros.contact.exact import SteadyRollingOperator
    area = ellipse(A_AX, B_AX, nx=20, ny=20, load=LOAD)
    return area, SteadyRollingOperator.of(area, nu=NU, shear_modulus=G), request.param


def exact(setup, xi, eta, phi, **kw):
    from fastsim_ros.contact.exact import coulomb
    area, op, solver = setup
    return coulomb(area, xi, eta, phi, nu=NU, shear_modulus=G, operator=op, solver=solver,
                   **kw)


@pytest.mark.parametrize("law", [ExponentialFriction(MU, 1.0, 0.8),
                                 ExponentialFriction(MU, 0.3, 0.0)])
def test_exact_constant_limits_give_todays_numbers(law, exact_setup):
    for creep in [(2e-3, 0.0, 0.0), (1e-3, -1e-3, 0.5)]:
        old = exact(exact_setup, *creep, mu=MU)
        new = exact(exact_setup, *creep, friction=law, speed=V)
        assert (new.fx, new.fy, new.mz) == (old.fx, old.fy, old.mz)
        assert np.array_equal(new.tau_x, old.tau_x)


def test_exact_slipping_cells_satisfy_the_law(exact_setup):
    """|tau| = mu(V |s|) p on the slip area, s = w - du/dx the exact slip; s = 0 elsewhere."""
    from fastsim_ros.contact.traction import rigid_slip
    area, op, _ = exact_setup
    res = exact(exact_setup, 3e-3, 1e-3, 0.0, friction=FALLING, speed=V)
    mask = area.mask
    wx, wy = rigid_slip(area, 3e-3, 1e-3, 0.0, (0.0, 0.0))
    tau = np.concatenate([res.tau_x[mask], res.tau_y[mask]])
    s = np.concatenate([wx[mask], wy[mask]]) - op.dense() @ tau
    n = int(mask.sum())
    sx, sy = s[:n], s[n:]
    slip = res.slip[mask]
    mag = np.hypot(res.tau_x[mask], res.tau_y[mask])
    bound = FALLING.mu(V * np.hypot(sx, sy)) * area.pressure[mask]
    assert slip.sum() > 20
    assert np.abs(mag[slip] - bound[slip]).max() <= 1e-6 * MU * area.pressure.max()
    assert (res.tau_x[mask][slip] * sx[slip] + res.tau_y[mask][slip] * sy[slip] < 0).all()
    assert np.hypot(sx, sy)[~slip].max() <= 1e-6 * 3e-3


def test_exact_full_slip_and_peak(exact_setup):
    area, _, _ = exact_setup
    xi = 0.5
    full = exact(exact_setup, xi, 0.0, 0.0, friction=FALLING, speed=V)
    assert -full.fx == pytest.approx(float(FALLING.mu(V * xi)) * area.load, rel=2e-3)
    xis = np.geomspace(2e-3, 0.2, 12)
    peaks = []
    for decay in (0.1, 3.0):
        law = ExponentialFriction(MU, 0.4, decay)
        f = np.array([-exact(exact_setup, x, 0.0, 0.0, friction=law, speed=V).fx for x in xis])
        k = int(np.argmax(f))
        assert 0 < k < xis.size - 1 and f[k] < MU * area.load and f[-1] < 0.95 * f[k]
        peaks.append((xis[k], f[k]))
    assert peaks[0][0] > peaks[1][0] and peaks[0][1] > peaks[1][1]
