"""Non-steady FastSim (Kalker's transient FASTSIM) on the fast methods' patches."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import kernels
from fastsim_ros.contact.compiled import CalibratedMaeSolver, EquivalentEllipseSolver, MaeSolver
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.fastsim import sweep_integrals
from fastsim_ros.contact.friction import ExponentialFriction
from fastsim_ros.contact.transient import ContactMemory, TransientSolver

NU, G, MU = 0.28, 8.0e10, 0.3
SOLVERS = (MaeSolver, CalibratedMaeSolver, EquivalentEllipseSolver)
# creepages (xi, eta, phi in 1/m): longitudinal, combined with spin, near saturation
CREEPAGES = ((1e-3, 0.0, 0.0), (1e-3, 2e-3, 0.5), (3e-3, -1e-3, 2.0))


@pytest.fixture(scope="module")
def patch() -> areas.GridArea:
    """Return a Hertzian ellipse, a = 6 mm, b = 4 mm, 40 x 30 cells, 40 kN."""
    return areas.ellipse(6e-3, 4e-3, nx=40, ny=30, load=4e4)


def _step(t: TransientSolver, state, ar, creep, rolled, **kw):
    return t.step(state, ar.pressure, ar.x0, ar.y0, ar.dx, ar.dy, *creep, rolled, **kw)


@pytest.mark.parametrize("solver_cls", SOLVERS)
@pytest.mark.parametrize("creep", CREEPAGES)
def test_steady_limit_when_rolling_past_the_patch(solver_cls, creep, patch) -> None:
    """Rolling more than the patch length in one step gives the steady answer exactly."""
    solver = solver_cls(NU, G)
    steady = solver.solve(patch, *creep, mu=MU, tractions=True)
    # from an arbitrary previous state: all of it has left the contact
    rng = np.random.default_rng(3)
    t = TransientSolver(solver)
    _, state = _step(t, None, patch, creep, 0.3 * patch.dx, mu=MU)
    noisy = type(state)(state.tau_x + rng.normal(0, 1e8, state.tau_x.shape), state.tau_y,
                        state.grid, state.area, state.centroid, state.half_length)
    f, _ = _step(t, noisy, patch, creep, 2.1 * 6e-3, mu=MU)
    assert (f.fx, f.fy, f.mz, f.slip_fraction) == (steady.fx, steady.fy, steady.mz,
                                                   steady.slip_fraction)
    np.testing.assert_array_equal(f.tau_x, steady.tau_x)
    np.testing.assert_array_equal(f.slip, steady.slip)


def test_steady_limit_with_slip_dependent_friction(patch) -> None:
    """The steady limit holds with a falling friction law (its slip velocities included)."""
    law = ExponentialFriction(0.4, 0.4, 0.6)
    solver = CalibratedMaeSolver(NU, G)
    steady = solver.solve(patch, 4e-3, 1e-3, 1.0, friction=law, speed=10.0)
    f, _ = _step(TransientSolver(solver), None, patch, (4e-3, 1e-3, 1.0), math.inf,
                 friction=law, speed=10.0)
    assert (f.fx, f.fy, f.mz) == (steady.fx, steady.fy, steady.mz)


@pytest.mark.parametrize("solver_cls", SOLVERS)
def test_steps_of_one_cell_reach_the_steady_state_exactly(solver_cls, patch) -> None:
    """Steps of ``V dt = dx`` from zero traction: the steady answer after one patch length."""
    solver = solver_cls(NU, G)
    t = TransientSolver(solver)
    creep = CREEPAGES[2]
    steady = solver.solve(patch, *creep, mu=MU, tractions=True)
    state = None
    h = patch.dx
    if solver_cls is EquivalentEllipseSolver:
        # the ellipse's own grid: its cell length is the step
        _, state = _step(t, None, patch, creep, 0.0, mu=MU)
        h = state.grid[2]
        state = None
    fx = []
    for _ in range(patch.nx + 30):
        f, state = _step(t, state, patch, creep, h, mu=MU)
        fx.append(f.fx)
    np.testing.assert_allclose(f.tau_x, steady.tau_x, rtol=0,
                               atol=1e-9 * np.abs(steady.tau_x).max())
    assert f.fx == pytest.approx(steady.fx, rel=1e-12)
    assert f.fy == pytest.approx(steady.fy, rel=1e-12)
    # the build-up: far from steady after a cell, steady within 1 % after a contact length
    assert abs(fx[0]) < 0.5 * abs(steady.fx)
    assert fx[int(2 * 6e-3 / h)] == pytest.approx(steady.fx, rel=0.01)


def test_fractional_steps_converge_to_the_refined_steady_state() -> None:
    """Steps of ``dx/2``: the fixed point lies nearer the steady answer of the finer grid.

    The steady march's step is the cell (its error is first order in ``dx``
    under spin in partial slip); the fixed point of steps ``h < dx`` marches
    the material with ``h``, so it lies between the steady answers at ``dx``
    and ``dx/2``, nearer the latter.
    """
    solver = MaeSolver(NU, G)
    t = TransientSolver(solver)
    creep = CREEPAGES[2]
    coarse = areas.ellipse(6e-3, 4e-3, nx=40, ny=30, load=4e4)
    fine = areas.ellipse(6e-3, 4e-3, nx=80, ny=30, load=4e4)
    s_coarse = solver.solve(coarse, *creep, mu=MU)
    s_fine = solver.solve(fine, *creep, mu=MU)
    state = None
    for _ in range(110):
        f, state = _step(t, state, coarse, creep, 0.5 * coarse.dx, mu=MU)
    for name in ("fx", "fy", "mz"):
        a, b, c = getattr(f, name), getattr(s_coarse, name), getattr(s_fine, name)
        assert abs(a - c) < 0.25 * abs(b - c) + 1e-3 * MU * 4e4, name
    # no spin: tractions linear along x in adhesion, the fixed point is the steady state
    s_xi = solver.solve(coarse, 1e-3, 0.0, 0.0, mu=MU)
    state = None
    for _ in range(110):
        f, state = _step(t, state, coarse, (1e-3, 0.0, 0.0), 0.5 * coarse.dx, mu=MU)
    assert f.fx == pytest.approx(s_xi.fx, rel=1e-3)


def test_build_up_in_adhesion_follows_kalkers_transient(patch) -> None:
    """A step in ``xi`` in full adhesion: ``Fx(s) = -xi dA sum_j (1/L1_j) sum_i min(d_ij, s)``.

    Kalker's transient FASTSIM in adhesion: a particle's traction grows with
    the distance it has rolled since it entered, ``min(d, s)`` after rolling
    ``s`` from zero traction (``d``: its distance from the leading edge).
    """
    solver = MaeSolver(NU, G)
    t = TransientSolver(solver)
    xi = 2e-5
    status, _, geo = solver._prepare(patch)
    assert status == kernels.OK
    flex = np.empty((4, patch.ny))
    kernels.mae_strip_flexibility(geo, flex)
    d, _ = sweep_integrals(patch, float(geo[kernels.G_XC]))
    mask = patch.mask
    state = None
    rolled = 0.0
    h = 0.7e-3  # not a multiple of the cell (0.3 mm)
    for _ in range(12):
        f, state = _step(t, state, patch, (xi, 0.0, 0.0), h, mu=MU)
        rolled += h
        expected = -xi * patch.cell_area * float(
            (np.where(mask, np.minimum(d, rolled), 0.0) / flex[0][:, None]).sum())
        assert f.slip_fraction == 0.0
        # the cubic interpolation of the convection is exact on either side of the kink
        # d = s, not across it (one cell of the profile min(d, s)): 1e-4 of Fx there
        assert f.fx == pytest.approx(expected, rel=3e-4)


def test_memory_rules(patch) -> None:
    """Start and stamp gap: steady; carried state: transient; lost contact and jump: from zero."""
    solver = MaeSolver(NU, G)
    mem = ContactMemory(TransientSolver(solver), max_gap=0.01)
    speed, dt_ns = 2.0, 1_000_000  # 2 m/s, 1 kHz: 2 mm per cycle
    a, b = (1e-3, 0.0, 0.0), (2e-3, 0.0, 0.0)
    args = (patch.pressure, patch.x0, patch.y0, patch.dx, patch.dy)
    steady_a = solver.solve(patch, *a, mu=MU)
    steady_b = solver.solve(patch, *b, mu=MU)
    f, reason = mem.solve(0, speed, *args, *a, MU)
    assert reason == "start" and f.fx == steady_a.fx
    f, reason = mem.solve(dt_ns, speed, *args, *a, MU)
    assert reason is None and f.fx == pytest.approx(steady_a.fx, rel=1e-12)
    # a creepage step: after one cycle (2 mm of a 12 mm patch) between the two steady answers
    f, reason = mem.solve(2 * dt_ns, speed, *args, *b, MU)
    assert reason is None
    assert abs(steady_a.fx) < abs(f.fx) < abs(steady_b.fx)
    # a stamp gap: steady at the new creepages
    f, reason = mem.solve(2 * dt_ns + 20_000_000, speed, *args, *b, MU)
    assert reason == "stamp_gap" and f.fx == steady_b.fx
    # a lost contact: the new one starts from zero traction and has rolled one cycle
    mem.lose_contact(2 * dt_ns + 21_000_000)
    f, reason = mem.solve(2 * dt_ns + 22_000_000, speed, *args, *b, MU)
    assert reason == "lost_contact" and 0.0 < f.fx / steady_b.fx < 0.6
    # the patch moved by a cell: resampled, the traction carried (no drop)
    before = f.fx
    f, reason = mem.solve(2 * dt_ns + 23_000_000, speed, patch.pressure, patch.x0 + patch.dx,
                          patch.y0, patch.dx, patch.dy, *b, MU)
    assert reason == "resampled" and abs(f.fx) > abs(before)
    # a jump: half the patch gone
    p = np.array(patch.pressure)
    p[: patch.ny // 2] = 0.0
    f, reason = mem.solve(2 * dt_ns + 24_000_000, speed, p, patch.x0 + patch.dx, patch.y0,
                          patch.dx, patch.dy, *b, MU)
    assert reason == "patch_jump"
    f, reason = mem.solve(2 * dt_ns + 25_000_000, -speed, p, patch.x0 + patch.dx, patch.y0,
                          patch.dx, patch.dy, *b, MU)
    assert reason == "reversed"
    assert mem.counts == {"start": 1, "stamp_gap": 1, "lost_contact": 1, "patch_jump": 1,
                          "resampled": 1, "reversed": 1}


def test_refuses_negative_distance(patch) -> None:
    """A negative distance rolled is refused."""
    with pytest.raises(InvalidInputError):
        _step(TransientSolver(MaeSolver(NU, G)), None, patch, CREEPAGES[0], -1e-3, mu=MU)
