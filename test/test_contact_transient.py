"""Non-steady FastSim (Kalker's transient FASTSIM) on the fast methods' patches."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import kernels
from fastsim_ros.contact.compiled import CalibratedMaeSolver, EquivalentEllipseSolver, MaeSolver
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.fastsim import sweep_integrals
from fastsim_ros.contact.friction import ExponentialFriction
from fastsim_ros.contact.exact import coulomb
from fastsim_ros.contact.exact_transient import (TransientOperators, cattaneo_shift,
                                                 rolling_step)
from fastsim_ros.contact.transient import (ContactMemory, TransientSolver, elliptic_ke,
                                           mindlin_compliance)

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
    """Kalker's local model, steps of ``V dt = dx`` from zero: steady after one patch length."""
    solver = solver_cls(NU, G)
    t = TransientSolver(solver, far_field=False)
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
    t = TransientSolver(solver, far_field=False)
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
    t = TransientSolver(solver, far_field=False)
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


def test_elliptic_integrals_against_published_values() -> None:
    """``K(m)``, ``E(m)`` by the AGM against Abramowitz & Stegun's Table 17.1 (m = 0.5, 0.9)."""
    assert elliptic_ke(0.0) == pytest.approx((math.pi / 2, math.pi / 2), rel=1e-15)
    assert elliptic_ke(0.5) == pytest.approx((1.8540746773013719, 1.3506438810476755),
                                             rel=1e-14)
    assert elliptic_ke(0.9) == pytest.approx((2.5780921133481731, 1.1047747327040733),
                                             rel=1e-14)


@pytest.mark.parametrize("a_over_b", [0.2, 1.0, 5.0])
def test_mindlin_compliance_is_the_exact_shift_in_adhesion(a_over_b: float) -> None:
    """Mindlin's compliance of an ellipse against the exact Cattaneo shift in full stick.

    The exact solver on 40 x 40 cells (uniform tractions on cells miss a
    little of the edge singularity of the adhesive traction: 0.3 %).
    """
    a, b = 6e-3 * math.sqrt(a_over_b), 6e-3 / math.sqrt(a_over_b)
    ar = areas.ellipse(a, b, nx=40, ny=40, load=4e4)
    c_x, c_y = mindlin_compliance(a, b, NU, G)
    delta = 1e-9
    k_x = abs(cattaneo_shift(ar, delta, 0.0, mu=1e3, nu=NU, shear_modulus=G).fx) / delta
    k_y = abs(cattaneo_shift(ar, 0.0, delta, mu=1e3, nu=NU, shear_modulus=G).fy) / delta
    assert k_x * c_x == pytest.approx(1.0, abs=0.005)
    assert k_y * c_y == pytest.approx(1.0, abs=0.005)
    if a_over_b == 1.0:
        assert c_x == pytest.approx((2 - NU) / (4 * G * a), rel=1e-12)


@pytest.mark.parametrize("solver_cls", SOLVERS)
def test_the_first_step_from_zero_takes_mindlins_stiffness(solver_cls, patch) -> None:
    """A small creepage step, rolled a tenth of a cell: the force is Mindlin's shift's.

    The particles in the contact are shifted by ``xi h``: the far field
    gives the patch the half-space's stiffness ``1 / c`` (the local model
    twice as stiff).
    """
    solver = solver_cls(NU, G)
    xi, h = 1e-5, 0.1 * patch.dx
    f, _ = _step(TransientSolver(solver), None, patch, (xi, 0.0, 0.0), h, mu=MU)
    local, _ = _step(TransientSolver(solver, far_field=False), None, patch, (xi, 0.0, 0.0), h,
                     mu=MU)
    c_x, _ = mindlin_compliance(6e-3, 4e-3, NU, G)
    mindlin = -xi * h / c_x
    # the material entered during the step (a twentieth of the patch) shifts less
    assert f.fx == pytest.approx(mindlin, rel=0.05)
    assert local.fx / mindlin > 1.8


@pytest.mark.parametrize("solver_cls", SOLVERS)
def test_the_far_field_keeps_the_steady_state_and_reaches_it(solver_cls, patch) -> None:
    """From the steady state, steps of a cell stay on it; from zero, they converge to it."""
    solver = solver_cls(NU, G)
    t = TransientSolver(solver)
    creep = CREEPAGES[1]
    steady = solver.solve(patch, *creep, mu=MU)
    state = None
    _, state = _step(t, None, patch, creep, math.inf, mu=MU)
    h = state.grid[2]
    for _ in range(3):
        f, state = _step(t, state, patch, creep, h, mu=MU)
        assert (f.fx, f.fy) == pytest.approx((steady.fx, steady.fy), rel=1e-12)
    state = None
    for _ in range(int(6 * 6e-3 / h)):
        f, state = _step(t, state, patch, creep, h, mu=MU)
    assert (f.fx, f.fy) == pytest.approx((steady.fx, steady.fy), rel=2e-3)


def test_spin_in_slip_reaches_the_steady_state_with_long_steps() -> None:
    """Steps of ten cells under spin in slip: the fixed point is the steady answer.

    The traction's direction follows the local rigid slip along a particle's
    path; projected once over a long step it took the path's mean direction
    (a fixed point of twice the steady Fy before the path was marched cell
    by cell).
    """
    ar = areas.ellipse(6e-3, 6e-3, nx=20, ny=20, load=4e4)
    solver = EquivalentEllipseSolver(NU, G)
    t = TransientSolver(solver)
    steady = solver.solve(ar, 0.0, 0.0, 3.0, mu=MU)
    state = None
    for _ in range(8):
        f, state = _step(t, state, ar, (0.0, 0.0, 3.0), 10 * ar.dx, mu=MU)
    assert f.fy == pytest.approx(steady.fy, rel=1e-3)


@pytest.mark.parametrize("solver_cls", SOLVERS)
@pytest.mark.parametrize("cells", [3, 5])
@pytest.mark.parametrize("law", [None, ExponentialFriction(0.3, 0.4, 0.6)])
def test_steps_of_whole_cells_reach_the_steady_state_under_spin(solver_cls, cells, law,
                                                                patch) -> None:
    """Steps of several cells under spin near saturation: the fixed point is the steady answer.

    A particle's path from ``x + h`` is marched cell by cell with the steady
    march's own projection (the calibrated MAE's rigid-slip return, the
    falling law's kinetic level from where the particle starts), and every
    cell of the path is tested, not only the last: so with ``h`` a whole
    number of cells the steady state is a fixed point of the steps.  A path
    marched only where its end is over the bound, with the radial return,
    puts the calibrated MAE's fixed point under spin 1-4 points of mu N off
    its steady answer (-0.3515 against -0.3910 on a/b = 2 at ten cells a
    step).
    """
    solver = solver_cls(NU, G)
    creep = CREEPAGES[2]
    kw = {"mu": MU} if law is None else {"friction": law, "speed": 3.0}
    steady = solver.solve(patch, *creep, **kw)
    t = TransientSolver(solver)
    _, state = _step(t, None, patch, creep, 0.0, **kw)
    h = cells * state.grid[2]           # the solver's own cells (the equivalent ellipse's grid)
    state = None
    for _ in range(int(8 * 12e-3 / h)):
        f, state = _step(t, state, patch, creep, h, **kw)
    scale = MU * patch.pressure.sum() * patch.dx * patch.dy
    for name in ("fx", "fy", "mz"):
        a, b = getattr(f, name), getattr(steady, name)
        assert abs(a - b) <= 1e-6 * scale * (6e-3 if name == "mz" else 1.0), name


@pytest.mark.parametrize("kind, knee", [
    ("xi", False), ("phi", False), ("phi", True),
    pytest.param("xi", True, marks=pytest.mark.xfail(strict=True, reason=(
        "FastSim's non-steady march builds the force up faster than the exact transient "
        "theory: 4-6% of mu N ahead of it over the first patch length after a step in xi "
        "(measured, either knee); FastSim's own knee (knee=False) is as far behind in the "
        "steady state (592 N), which hid it; with the knee factors the steady error is "
        "112 N and the build-up's 564 N shows")))])
def test_step_response_follows_the_exact_transient_solver(kind: str, knee: bool) -> None:
    """A creepage step at V dt / a = 0.3: within the steady error plus 2 % of mu N."""
    a, n, load = 6e-3, 20, 4e4
    ar = areas.ellipse(a, a, nx=n, ny=n, load=load)
    creep = (1.5e-3, 0.0, 0.0) if kind == "xi" else (0.0, 0.0, 3.0)
    key = "fx" if kind == "xi" else "fy"
    ops = TransientOperators.of(ar, 1, nu=NU, shear_modulus=G)
    exact, state = [], None
    for _ in range(2 * n):
        state = rolling_step(ar, ops, *creep, mu=MU, previous=state)
        exact.append(getattr(state, key))
    exact_steady = getattr(coulomb(ar, *creep, mu=MU, nu=NU, shear_modulus=G), key)
    solver = CalibratedMaeSolver(NU, G, knee=knee)
    steady_error = abs(getattr(solver.solve(ar, *creep, mu=MU), key) - exact_steady)
    t = TransientSolver(solver)
    tstate = None
    for step in range(2 * n // 3):
        f, tstate = _step(t, tstate, ar, creep, 3 * ar.dx, mu=MU)
        gap = abs(getattr(f, key) - exact[3 * step + 2])
        assert gap <= steady_error + 0.02 * MU * load, step


@pytest.mark.parametrize("solver_cls", SOLVERS)
def test_a_long_step_is_the_build_up_of_short_ones(solver_cls) -> None:
    """A creepage step rolled half the patch's length at once follows the same in small steps.

    The far field's force changes as a lag within a step; over one step of
    half the patch (``V dt = a``) that overshot the build-up of steps of
    ``a/10`` by a point of mu N (after ``a``: -0.661 against -0.650 of mu N
    under ``eta`` on the circle).  Such a step is taken as sub-steps of at
    most an eighth of the patch (:data:`transient.SUBSTEP`) where its force
    changes (:data:`transient.SUBSTEP_CHANGE`).
    """
    a, n, load = 6e-3, 40, 4e4
    ar = areas.ellipse(a, a, nx=n, ny=n, load=load)
    solver = solver_cls(NU, G)
    creep = (0.0, 1.5e-3, 0.0)
    t = TransientSolver(solver)
    long_steps, state = [], None
    for _ in range(3):
        f, state = _step(t, state, ar, creep, a, mu=MU)
        long_steps.append(f.fy)
    short_steps, state = [], None
    for k in range(30):
        f, state = _step(t, state, ar, creep, a / 10, mu=MU)
        if k % 10 == 9:
            short_steps.append(f.fy)
    np.testing.assert_allclose(long_steps, short_steps, rtol=0, atol=2e-3 * MU * load)
    # the sub-steps are steps: one of a equals two of a / 2 from the same state
    _, start = _step(t, None, ar, creep, 0.3 * a, mu=MU)
    once, _ = _step(t, start, ar, creep, a, mu=MU)
    _, mid = _step(t, start, ar, creep, a / 2, mu=MU)
    twice, _ = _step(t, mid, ar, creep, a / 2, mu=MU)
    assert (once.fx, once.fy, once.mz) == (twice.fx, twice.fy, twice.mz)


@pytest.mark.parametrize("solver_cls", SOLVERS)
def test_a_step_just_past_the_patch_length_is_steady_for_every_method(solver_cls):
    """``V dt`` a hair over the patch's 12 mm: the steady answer, from any state.

    The equivalent ellipse kept a memory up to its own grid's length (12.08
    mm on 30 x 30 cells: its area is the staircase's), 19% of mu N off the
    steady answer.
    """
    patch = areas.ellipse(6e-3, 4e-3, nx=30, ny=30, load=6e4)
    solver = solver_cls(NU, G)
    length = patch.dx * patch.nx
    _, state = _step(TransientSolver(solver), None, patch, (-2e-3, 1e-3, -1.0), 0.5 * patch.dx,
                     mu=MU)
    creep = (1e-3, 0.0, 0.5)
    steady = solver.solve(patch, *creep, mu=MU)
    f, _ = _step(TransientSolver(solver), state, patch, creep, 1.0001 * length, mu=MU)
    assert (f.fx, f.fy, f.mz) == (steady.fx, steady.fy, steady.mz)


@pytest.mark.parametrize("solver_cls", SOLVERS)
def test_the_far_fields_answer_is_continuous_in_the_step_and_the_creepage(solver_cls, patch):
    """One step ``h`` after a creepage step: monotone in ``h`` and in the creepage step.

    The steady state at the patch's length is reached continuously.
    Sub-steps of a long step kept their far field's lag however near ``h``
    came to the length: 0.815 of the steady force at ``0.999 L``, 1.0 at
    ``L``; and a creepage step large enough to be sub-stepped was answered
    with a smaller force than a slightly smaller one (+57 N at ``0.9 L``).
    """
    solver = solver_cls(NU, G)
    t = TransientSolver(solver)
    length = patch.dx * patch.nx
    _, rest = _step(t, None, patch, (0.0, 0.0, 0.0), math.inf, mu=MU)
    steady = solver.solve(patch, 1e-3, 0.0, 0.0, mu=MU).fx
    share = [_step(t, rest, patch, (1e-3, 0.0, 0.0), frac * length, mu=MU)[0].fx / steady
             for frac in (0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99, 0.999, 1.0)]
    assert all(b >= a - 1e-9 for a, b in zip(share, share[1:])), share
    assert share[-1] == 1.0 and share[-1] - share[-2] < 0.01 * MU * patch.load / abs(steady)
    forces = [_step(t, rest, patch, (xi, 0.0, 0.0), 0.9 * length, mu=MU)[0].fx
              for xi in np.linspace(2e-5, 8e-5, 25)]
    assert all(b < a for a, b in zip(forces, forces[1:])), np.diff(forces)


@pytest.mark.parametrize("solver_cls", SOLVERS)
def test_the_carried_far_field_jacobian_changes_the_path_not_the_answer(solver_cls, patch):
    """The far field's Jacobian carried with the state is a first guess, not a model.

    A rig's creepages change a little every cycle (noise): the far field's
    fixed point follows a change of force every step, and its Broyden
    Jacobian, carried from step to step, estimates ``-dF/ds`` of the patch
    (positive on the diagonal).  The step from the same state with the Jacobian forgotten
    (NaN: the stick stiffness ``K``) is the same fixed point, within the
    solve's tolerance (1e-3 of the change of force, or 1e-6 of mu N).
    """
    t = TransientSolver(solver_cls(NU, G))
    creep = np.array((1e-3, 5e-4, 0.5))
    rolled = 2.3 * patch.dx
    _, state = _step(t, None, patch, creep, math.inf, mu=MU)
    rng = np.random.default_rng(5)
    for _ in range(6):
        _, state = _step(t, state, patch, creep * (1 + 1e-2 * rng.standard_normal(3)),
                         rolled, mu=MU)
    assert all(math.isfinite(v) for v in state.far_slope)
    j_xx, j_xy, j_yx, j_yy = state.far_slope
    assert j_xx > 0.0 and j_yy > 0.0
    bound = MU * 4e4
    for _ in range(3):
        step_creep = creep * (1 + 1e-2 * rng.standard_normal(3))
        carried, new = _step(t, state, patch, step_creep, rolled, mu=MU)
        forgotten, _ = _step(t, dataclasses.replace(state, far_slope=(math.nan,) * 4), patch,
                             step_creep, rolled, mu=MU)
        change = abs(carried.fx - state.force[0]) + abs(carried.fy - state.force[1])
        tol = max(1e-3 * change, 1e-6 * bound)
        # the two answers are each within tol of the fixed point (times the far field's
        # share of the stiffness, below 1)
        assert abs(carried.fx - forgotten.fx) <= 2 * tol
        assert abs(carried.fy - forgotten.fy) <= 2 * tol
        state = new


@pytest.mark.parametrize("solver_cls", SOLVERS)
def test_a_steps_state_is_the_dataclass_it_names(solver_cls, patch) -> None:
    """The state a step returns (made without the dataclass's ``__init__``) is one, frozen.

    Every field is set, equal to the one the step computed and to a state
    built field by field the usual way; it cannot be assigned to.
    """
    t = TransientSolver(solver_cls(NU, G))
    _, state = _step(t, None, patch, (1e-3, 5e-4, 0.5), 1.5 * patch.dx, mu=MU)
    names = [f.name for f in dataclasses.fields(state)]
    assert sorted(vars(state)) == sorted(names)
    built = type(state)(**{name: getattr(state, name) for name in names})
    for name in names:
        mine, theirs = getattr(state, name), getattr(built, name)
        if isinstance(mine, np.ndarray):
            assert mine is theirs
        else:
            assert mine == theirs and type(mine) is type(theirs), name
    assert all(type(v) is float for v in (*state.grid, state.area, *state.centroid,
                                          state.half_length, *state.force, *state.far_slope))
    with pytest.raises(dataclasses.FrozenInstanceError):
        state.force = (0.0, 0.0)  # type: ignore[misc]
    replaced = dataclasses.replace(state, force=(1.0, 2.0))
    assert replaced.force == (1.0, 2.0) and replaced.grid == state.grid
