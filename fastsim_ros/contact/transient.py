"""Transient rolling with the fast methods: Kalker's non-steady FASTSIM.

The steady methods answer each cycle as if the rolling had reached its
steady state.  After a step in creepage the traction needs about one contact
length of rolling to build up; at 1 kHz and 2 m/s a cycle rolls 2 mm of a
10-15 mm patch.  Here each contact keeps its surface traction on its cells
between cycles (Kalker 1990, "Three-dimensional elastic bodies in rolling
contact", section 5.4, non-steady FASTSIM; Alonso & Gimenez, Vehicle System
Dynamics 46, 2008, for the MAE patches):

- over a time step ``dt`` the material moves through the contact by the
  distance rolled ``h = |V| dt`` (m): the traction of the previous step is
  convected by ``h`` along each strip (semi-Lagrangian: interpolated at
  ``x + h``, new material entering at the leading edge with zero traction);
- the rigid slip over the step divided by the flexibility ``L`` (Kalker's
  ``L1 .. L3`` on the equivalent ellipse, MAE's per-strip ``L1 .. L4``, the
  calibrated MAE's) is added, and the sum is projected on the traction bound
  ``mu p`` (slip-dependent friction and the rigid-slip return as in the
  steady sweep): :func:`fastsim_ros.contact.kernels.rolling_sweep`.

Material that entered during the step (within ``h`` of its segment's front
face) rolled under the present creepages only: it has the steady march's
traction.  So the steady FastSim is the limit ``h`` >= the patch length
(exactly), and with ``h = dx`` it is the exact fixed point of repeated steps
(the semi-Lagrangian shift is then a shift by one cell); other ``h`` converge
to it within the interpolation's smoothing.

State rules (:class:`ContactMemory`, stated in :data:`RESET_REASONS`):

- ``start``: the first patch; the rig was rolling before the node listened:
  the steady state is the best estimate;
- ``stamp_gap``: more than ``max_gap`` (s) since the last solved patch (a
  dropped stream, a standstill): the history is unknown, steady state;
- ``lost_contact``: the previous patch was empty (a lifted wheel): the new
  contact starts from zero traction (its material has no history);
- ``patch_jump``: the load-bearing area changed by more than ``jump_tolerance``
  (relative) or its centroid moved by more than ``jump_tolerance`` times the
  patch's half length in one step (a new contact, e.g. a flange): zero traction;
- ``resampled`` (not a reset): another grid (cell size, origin, shape): the
  previous traction is interpolated bilinearly onto the new cell centres in
  the contact plane, zero outside the previous contact;
- ``reversed``: the rolling direction changed sign: steady state.

Units: SI (m, Pa, N, s; ``phi`` in 1/m).  No ROS, no SciPy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from fastsim_ros.contact import kernels as k
from fastsim_ros.contact.checks import check_bound
from fastsim_ros.contact.compiled import (ContactForces, EquivalentEllipseSolver, MaeSolver,
                                          _law, _pressure, _raise)
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.friction import FrictionLaw

FloatArray = NDArray[np.float64]

#: why a contact's state was reset (or resampled), the keys of the diagnostics' counts
RESET_REASONS = ("start", "stamp_gap", "lost_contact", "patch_jump", "resampled", "reversed")
#: resets after which the step is the steady state (history unknown, contact rolling)
STEADY_RESETS = ("start", "stamp_gap", "reversed")


@njit(cache=True, error_model="numpy")
def mae_rolling_solve(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                      shear_modulus, knots, polys, law, prm, speed, out_x, out_y, slip,
                      calibrated, pair_knots, pair_values, prev_x, prev_y, rolled, geo):
    """One time step of MAE + FastSim, rolling ``rolled`` (m) from the state ``prev_x, prev_y``.

    As :func:`fastsim_ros.contact.kernels.mae_solve` (same arguments and
    return) with the previous tractions (Pa, the patch's grid) and the new
    ones written to ``out_x``, ``out_y`` (always stored: the next state);
    ``geo`` receives the MAE geometry (:data:`~kernels.GEO_SIZE`).
    """
    status = k.check_solve_inputs(xi, eta, phi, mu, xp, yp)
    if status != k.OK:
        return status, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0
    ny, nx = p.shape
    env = np.empty((2, nx), dtype=np.int64)
    strips = np.empty((3, ny), dtype=np.int64)
    status, info = k.mae_prepare(p, x0, y0, dx, dy, rule, shear_modulus, knots, polys, geo,
                                 env, strips, calibrated, pair_knots, pair_values)
    if status != k.OK:
        return status, info, 0.0, 0.0, 0.0, 0.0, 0, 0
    flex = np.empty((4, ny))
    k.mae_strip_flexibility(geo, flex)
    # MAE step 7: creepages moved to S = (x_c, y_s) (kernels.mae_sweep)
    x_c = geo[k.G_XC]
    y_s = geo[k.G_YS]
    xi_s = xi + phi * (yp - y_s)
    eta_s = eta - phi * (xp - x_c)
    if parabolic:
        bound = np.empty((ny, nx))
        k.parabolic_bound(p, dx, dy, mu, geo[k.G_LOAD], bound)
        fx, fy, mz, nslip, _ = k.rolling_sweep(
            bound, 1.0, 1.0, env, x0, y0, dx, dy, xi_s, eta_s, phi, flex, x_c, y_s, xp, yp,
            law, prm, speed, out_x, out_y, slip, True, calibrated, prev_x, prev_y, rolled)
    else:
        fx, fy, mz, nslip, _ = k.rolling_sweep(
            p, mu, 1.0, env, x0, y0, dx, dy, xi_s, eta_s, phi, flex, x_c, y_s, xp, yp,
            law, prm, speed, out_x, out_y, slip, True, calibrated, prev_x, prev_y, rolled)
    return k.OK, 0.0, fx, fy, mz, geo[k.G_LOAD], nslip, int(geo[k.G_NCONTACT])


@njit(cache=True, error_model="numpy")
def ellipse_rolling_solve(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, parabolic, n,
                          shear_modulus, knots, polys, law, prm, speed, out_x, out_y, slip,
                          prev_x, prev_y, rolled, ell):
    """One time step of FastSim on the patch's equivalent ellipse (``n`` x ``n`` cells).

    As :func:`fastsim_ros.contact.kernels.equivalent_solve` with the state
    on the ellipse's grid (``prev_x``, ``prev_y`` in, ``out_x``, ``out_y``
    out, Pa); ``ell`` receives the ellipse (:data:`~kernels.ELL_SIZE`).
    """
    status = k.check_solve_inputs(xi, eta, phi, mu, xp, yp)
    if status != k.OK:
        return status, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0
    status, info = k.equivalent_prepare(p, x0, y0, dx, dy, shear_modulus, knots, polys, ell)
    if status != k.OK:
        return status, info, 0.0, 0.0, 0.0, 0.0, 0, 0
    shape = np.empty((n, n))
    env = np.empty((2, n), dtype=np.int64)
    a = ell[k.ELL_A]
    b = ell[k.ELL_B]
    x_c = ell[k.ELL_XC]
    y_c = ell[k.ELL_YC]
    total, _ = k.ellipse_shape(n, a, b, not parabolic, shape, env)
    scale = ell[k.ELL_LOAD] / (total * ((2 * a / n) * (2 * b / n)))
    gx0, gy0, gdx, gdy = k.ellipse_grid(a, b, n, x_c, y_c)
    flex = np.empty((4, n))
    for j in range(n):
        flex[0, j] = ell[k.ELL_L1]
        flex[1, j] = ell[k.ELL_L2]
        flex[2, j] = ell[k.ELL_L3]
        flex[3, j] = ell[k.ELL_L3]
    xi_s = xi + phi * (yp - y_c)
    eta_s = eta - phi * (xp - x_c)
    fx, fy, mz, nslip, ncontact = k.rolling_sweep(
        shape, mu, scale, env, gx0, gy0, gdx, gdy, xi_s, eta_s, phi, flex, x_c, y_c, xp, yp,
        law, prm, speed, out_x, out_y, slip, True, False, prev_x, prev_y, rolled)
    return k.OK, 0.0, fx, fy, mz, ell[k.ELL_LOAD], nslip, ncontact


@dataclass(frozen=True, eq=False)
class TractionState:
    """A contact's surface traction (Pa) on its grid ``(x0, y0, dx, dy)`` (m), ``(ny, nx)``.

    ``load``: the patch's normal load (N), ``area``: its cells in contact
    times the cell area (m^2), ``centroid``: its pressure centroid (m) and
    ``half_length``: half its extent along ``x`` (m), for the jump rule.
    """

    tau_x: FloatArray
    tau_y: FloatArray
    grid: tuple[float, float, float, float]
    area: float
    centroid: tuple[float, float]
    half_length: float

    def resampled(self, grid: tuple[float, float, float, float],
                  shape: tuple[int, int]) -> tuple[FloatArray, FloatArray]:
        """Return the tractions interpolated bilinearly on another grid (zero outside this one)."""
        x0, y0, dx, dy = grid
        ny, nx = shape
        ox, oy, odx, ody = self.grid
        ony, onx = self.tau_x.shape
        # fractional indices of the new cell centres in the old grid
        fi = (x0 + dx * np.arange(nx) - ox) / odx
        fj = (y0 + dy * np.arange(ny) - oy) / ody
        out = []
        for tau in (self.tau_x, self.tau_y):
            # pad by one zero cell on each side: zero traction outside the old grid
            padded = np.zeros((ony + 2, onx + 2))
            padded[1:-1, 1:-1] = tau
            i = np.clip(fi + 1.0, 0.0, onx + 1.0 - 1e-9)
            j = np.clip(fj + 1.0, 0.0, ony + 1.0 - 1e-9)
            i0 = np.minimum(np.floor(i).astype(np.int64), onx)
            j0 = np.minimum(np.floor(j).astype(np.int64), ony)
            wi = (i - i0)[None, :]
            wj = (j - j0)[:, None]
            a = padded[np.ix_(j0, i0)]
            b = padded[np.ix_(j0, i0 + 1)]
            c = padded[np.ix_(j0 + 1, i0)]
            d = padded[np.ix_(j0 + 1, i0 + 1)]
            out.append((1 - wj) * ((1 - wi) * a + wi * b) + wj * ((1 - wi) * c + wi * d))
        return out[0], out[1]


class TransientSolver:
    """Non-steady FastSim on a compiled solver's patches (MAE, calibrated MAE, ellipse).

    ``solver``: a :class:`~fastsim_ros.contact.compiled.MaeSolver` (or
    :class:`~fastsim_ros.contact.compiled.CalibratedMaeSolver`) or an
    :class:`~fastsim_ros.contact.compiled.EquivalentEllipseSolver`; its
    material, tables and options are used.
    """

    def __init__(self, solver: MaeSolver | EquivalentEllipseSolver) -> None:
        self.solver = solver
        #: whether the last step interpolated its state onto another grid
        self.resampled = False

    def step(self, state: TractionState | None, pressure: ArrayLike, x0: float, y0: float,
             dx: float, dy: float, xi: float, eta: float, phi: float, rolled: float,
             mu: float | None = None, *, reference: tuple[float, float] = (0.0, 0.0),
             bound: str = "given", friction: FrictionLaw | None = None,
             speed: float | None = None) -> tuple[ContactForces, TractionState]:
        """Roll ``rolled`` (m, ``inf``: the steady state) from ``state`` (``None``: zero traction).

        The patch, creepages (1, 1, 1/m about ``reference``, m), ``mu``,
        ``bound``, ``friction`` and ``speed`` (m/s) as the solver's
        ``solve_arrays``; the state is resampled when the grid differs.
        Return the forces (with the tractions) and the new state.
        """
        if not rolled >= 0.0:
            raise InvalidInputError(f"the distance rolled must be >= 0, got {rolled}")
        p = _pressure(pressure, 2)
        code, prm, mu_s, v = _law(mu, friction, speed)
        s = self.solver
        parabolic = check_bound(bound)
        xp, yp = float(reference[0]), float(reference[1])
        if isinstance(s, MaeSolver):
            grid = (float(x0), float(y0), float(dx), float(dy))
            shape = p.shape
            prev = self._previous(state, grid, shape)
            out = (np.empty(shape), np.empty(shape), np.empty(shape, dtype=np.bool_))
            geo = np.empty(k.GEO_SIZE)
            result = mae_rolling_solve(
                p, grid[0], grid[1], grid[2], grid[3], float(xi), float(eta), float(phi),
                float(mu_s), xp, yp, s._rule, parabolic, s.shear_modulus, s._knots, s._polys,
                code, prm, v, out[0], out[1], out[2], s._calibrated, s._pair_knots,
                s._pair_values, prev[0], prev[1], float(rolled), geo)
            # the patch's area, centroid and half length, for ContactMemory's jump rule
            measures = (float(geo[k.G_AREA]), (float(geo[k.G_XC]), float(geo[k.G_YC])),
                        float(geo[k.G_ELLIPSE + 2]))
        else:
            n = s.cells or k.ellipse_cells(int(np.count_nonzero(p > 0.0)))
            ell = np.empty(k.ELL_SIZE)
            status, info = k.equivalent_prepare(p, float(x0), float(y0), float(dx), float(dy),
                                                s.shear_modulus, s._knots, s._polys, ell)
            if status:
                _raise(status, info, s._knots)
            grid = k.ellipse_grid(ell[k.ELL_A], ell[k.ELL_B], n, ell[k.ELL_XC], ell[k.ELL_YC])
            shape = (n, n)
            prev = self._previous(state, grid, shape)
            out = (np.empty(shape), np.empty(shape), np.empty(shape, dtype=np.bool_))
            result = ellipse_rolling_solve(
                p, float(x0), float(y0), float(dx), float(dy), float(xi), float(eta),
                float(phi), float(mu_s), xp, yp, parabolic, n, s.shear_modulus, s._knots,
                s._polys, code, prm, v, out[0], out[1], out[2], prev[0], prev[1],
                float(rolled), ell)
            # the equivalent ellipse has the patch's area and centroid
            measures = (math.pi * float(ell[k.ELL_A] * ell[k.ELL_B]),
                        (float(ell[k.ELL_XC]), float(ell[k.ELL_YC])), float(ell[k.ELL_A]))
        forces = s._forces(result, grid, out, True)
        return forces, TractionState(out[0], out[1], grid, *measures)

    def _previous(self, state: TractionState | None, grid: tuple[float, float, float, float],
                  shape: tuple[int, ...]) -> tuple[FloatArray, FloatArray]:
        self.resampled = False
        if state is None:
            return np.zeros(shape), np.zeros(shape)
        if state.grid == grid and state.tau_x.shape == shape:
            return state.tau_x, state.tau_y
        self.resampled = True
        return state.resampled(grid, (shape[0], shape[1]))


class ContactMemory:
    """One contact's state between cycles and the rules that reset it (module docstring).

    ``max_gap`` (s): a longer time between solved patches resets to the
    steady state; ``jump_tolerance`` (1): the relative change of area, or
    the centroid's move in half lengths, beyond which the patch is a new
    contact.  ``counts``: how often each of :data:`RESET_REASONS` applied.
    """

    def __init__(self, solver: TransientSolver, *, max_gap: float = 0.05,
                 jump_tolerance: float = 0.3) -> None:
        if not max_gap > 0.0 or not jump_tolerance > 0.0:
            raise InvalidInputError("max_gap and jump_tolerance must be positive")
        self.solver = solver
        self.max_gap = float(max_gap)
        self.jump_tolerance = float(jump_tolerance)
        self.state: TractionState | None = None
        self.stamp_ns: int | None = None
        self.direction = 0.0
        self.lost = False
        self.lost_ns: int | None = None
        self.counts = dict.fromkeys(RESET_REASONS, 0)

    def lose_contact(self, stamp_ns: int) -> None:
        """Record an empty patch stamped ``stamp_ns``: the next contact starts from zero."""
        self.state = None
        self.lost = True
        self.lost_ns = int(stamp_ns)

    def _rule(self, stamp_ns: int, speed: float) -> str | None:
        """Return the reset that applies before the solve (the jump is found after it)."""
        if self.lost and self.lost_ns is not None and stamp_ns >= self.lost_ns and (
                stamp_ns - self.lost_ns) * 1e-9 <= self.max_gap:
            return "lost_contact"
        if self.stamp_ns is None or self.state is None:
            return "start"
        if (stamp_ns - self.stamp_ns) * 1e-9 > self.max_gap or stamp_ns < self.stamp_ns:
            return "stamp_gap"
        if math.copysign(1.0, speed) != self.direction:
            return "reversed"
        return None

    def _jumped(self, old: TractionState, new: TractionState) -> bool:
        """Whether the patch's area or centroid moved beyond the tolerance in one step."""
        tol = self.jump_tolerance
        moved = math.hypot(new.centroid[0] - old.centroid[0], new.centroid[1] - old.centroid[1])
        return abs(new.area - old.area) > tol * old.area or moved > tol * old.half_length

    def solve(self, stamp_ns: int, speed: float, pressure: ArrayLike, x0: float, y0: float,
              dx: float, dy: float, xi: float, eta: float, phi: float, mu: float | None = None,
              *, reference: tuple[float, float] = (0.0, 0.0), bound: str = "given",
              friction: FrictionLaw | None = None) -> tuple[ContactForces, str | None]:
        """Solve the patch stamped ``stamp_ns`` (ns) at rolling speed ``speed`` (m/s, signed).

        The distance rolled since the last solved patch is ``|V| dt``
        (``dt`` from the stamps: the state's rules depend on the messages
        only, so a replay gives the node's answers).  Return the forces and
        the reset reason that applied (``None``: the state carried over).
        """
        p = _pressure(pressure, 2)
        reason = self._rule(stamp_ns, speed)
        state = self.state
        if reason in STEADY_RESETS:
            rolled, state = math.inf, None
        else:
            # a new contact appeared at the last empty patch (zero traction then), a jumped
            # one at the last solve: it has rolled since with the present creepages
            since = self.lost_ns if reason == "lost_contact" else self.stamp_ns
            assert since is not None
            rolled = abs(speed) * max(stamp_ns - since, 0) * 1e-9
            if reason is not None:
                state = None
        args = (p, x0, y0, dx, dy, xi, eta, phi, rolled, mu)
        kw = {"reference": reference, "bound": bound, "friction": friction, "speed": abs(speed)}
        forces, new = self.solver.step(state, *args, **kw)  # type: ignore[arg-type]
        if reason is None and state is not None and self._jumped(state, new):
            # another contact than the last one: its material has no history
            reason = "patch_jump"
            forces, new = self.solver.step(None, *args, **kw)  # type: ignore[arg-type]
        elif reason is None and self.solver.resampled:
            reason = "resampled"
        self.state = new
        if reason is not None:
            self.counts[reason] += 1
        self.stamp_ns = int(stamp_ns)
        self.direction = math.copysign(1.0, speed)
        self.lost = False
        return forces, reason
