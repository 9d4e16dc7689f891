"""Kalker's exact theory of transient rolling: the Cattaneo shift and rolling in time steps.

The reference of the non-steady fast methods (:mod:`~fastsim_ros.contact.transient`).
Assumptions as :mod:`~fastsim_ros.contact.exact` (quasi-identical
half-spaces, uniform tractions on the rectangular cells, Coulomb friction).
Over a time step in which the bodies roll ``q`` (m) the slip *distance* of
the wheel relative to the rail at a cell centre ``x`` is (Kalker 1990,
"Three-dimensional elastic bodies in rolling contact", section 2.3, the
transient form of the slip; CONTACT's user guide, "transient rolling")

    S(x) = W(x) + u(x, t) - u(x + q, t - dt),

``W`` the rigid slip over the step (``w q`` for rolling at creepages ``w =
(xi - phi y, eta + phi x)``; a rigid shift for the Cattaneo problem, which
is the same with ``q = 0``), ``u = A tau`` the displacement difference of
the present tractions and ``u(x + q, t - dt)`` the previous one where the
particle now at ``x`` was: the previous tractions' field, convected by the
distance rolled.  With ``q`` a whole number ``m`` of cells the convection is
a shift of the influence kernel by ``m`` cells (no interpolation), so the
problem is again ``S = W_eff - T tau`` on the cells in contact with a
convolution ``T = -A`` and ``W_eff = W - A_m tau_prev`` (``A_m`` the kernel
``K(d + m e_x)``): the same complementarity problem as steady rolling,
solved by the same semismooth Newton with FFT products
(:func:`fastsim_ros.contact.partial_slip.solve`).  Steady rolling is its
fixed point (``tau = tau_prev``: ``S/q = w - (u(x + q) - u(x))/q``, the
upstream difference of :mod:`~fastsim_ros.contact.rolling` when ``q = dx``).

Units: SI or any consistent set (CONTACT's examples use mm, N and ``G = 1``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import check_friction, check_material
from fastsim_ros.contact.errors import ConvergenceError, InvalidInputError
from fastsim_ros.contact.influence import influence_kernel
from fastsim_ros.contact.partial_slip import on_one_blas_thread, solve
from fastsim_ros.contact.rolling import SteadyRollingOperator
from fastsim_ros.contact.traction import resultants, rigid_slip

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class TransientSolution:
    """One time step: tractions ``tau_x``, ``tau_y`` (Pa), slip flags, slip distances (m).

    ``slip_x``, ``slip_y``: ``S`` over the step (zero where sticking);
    ``fx``, ``fy`` (N), ``mz`` (N m, about the reference point);
    ``iterations``: Newton iterations.
    """

    tau_x: FloatArray
    tau_y: FloatArray
    slip: NDArray[np.bool_]
    slip_x: FloatArray
    slip_y: FloatArray
    fx: float
    fy: float
    mz: float
    iterations: int

    @property
    def adhesion_cells(self) -> int:
        """Cells in contact that stick."""
        return int(np.count_nonzero((self.tau_x != 0.0) | (self.tau_y != 0.0))
                   - np.count_nonzero(self.slip))


@dataclass(frozen=True, eq=False)
class TransientOperators:
    """The two convolutions of a time step rolling ``cells`` cells on ``area``'s grid.

    ``present``: ``tau -> -A tau`` (the unknown's, in the form of a
    :class:`~fastsim_ros.contact.rolling.SteadyRollingOperator`, whose
    solvers it then serves); ``previous``: ``tau -> A_m tau``, the previous
    tractions' displacement at ``x + m dx``.
    """

    present: SteadyRollingOperator
    previous: SteadyRollingOperator
    cells: int

    @classmethod
    def of(cls, area: GridArea, cells: int, *, nu: float,
           shear_modulus: float) -> TransientOperators:
        """Build them; ``cells`` >= 0 (0: the shift problem), ``shear_modulus`` the combined G."""
        check_material(nu, shear_modulus)
        if cells < 0:
            raise InvalidInputError(f"cells rolled must be >= 0, got {cells}")
        m = int(cells)
        nx = area.nx
        n = nx - 1 + m
        k = influence_kernel(area.dx, area.dy, n, area.ny - 1, shear_modulus=shear_modulus,
                             nu=nu)
        # column of offset d is d + n: offsets -(nx-1)..nx-1, and shifted by m cells
        now = slice(m, m + 2 * nx - 1)
        then = slice(2 * m, 2 * m + 2 * nx - 1)
        present = SteadyRollingOperator(area, nu, shear_modulus, -k.xx[:, now], -k.yy[:, now],
                                        -k.xy[:, now])
        previous = SteadyRollingOperator(area, nu, shear_modulus, k.xx[:, then],
                                         k.yy[:, then], k.xy[:, then])
        return cls(present, previous, m)


@on_one_blas_thread
def transient_step(area: GridArea, operators: TransientOperators, shift: tuple[FloatArray,
                   FloatArray], mu: float, previous: TransientSolution | None = None, *,
                   reference: tuple[float, float] = (0.0, 0.0),
                   tol: float = 1e-9) -> TransientSolution:
    """Solve one time step with the rigid slip ``shift`` (m, per cell, ``(ny, nx)`` each).

    ``previous``: the last step's solution (``None``: zero tractions, the
    bodies pressed together without tangential load); ``mu``: Coulomb's
    coefficient, bound ``mu p``.  Converged to ``tol`` of ``mu max p``.
    """
    check_friction(mu)
    mask = area.mask
    wx, wy = shift
    w = np.stack([wx[mask], wy[mask]], axis=1)
    start = None
    if previous is not None:
        ux, uy = operators.previous.fft_product()(previous.tau_x, previous.tau_y)
        w = w - np.stack([ux[mask], uy[mask]], axis=1)
        start = np.stack([previous.tau_x[mask], previous.tau_y[mask]], axis=1)
    bound = mu * area.pressure[mask]
    scale = mu * float(area.pressure.max())
    try:
        res = solve(operators.present, w, bound, tol=tol, scale=scale, start=start)
    except ConvergenceError:
        if start is None:
            raise
        # the semismooth Newton started from the previous tractions can cycle between two
        # slip patterns (seen under eta on a/b = 0.5 and on 40 x 40 cells); started from
        # full adhesion, as the steady solver always is, it converges
        res = solve(operators.present, w, bound, tol=tol, scale=scale)
    tx = np.zeros(mask.shape)
    ty = np.zeros(mask.shape)
    tx[mask] = res.tau[:, 0]
    ty[mask] = res.tau[:, 1]
    s = w - operators.present.fft_product().on_cells(res.tau)
    sx = np.zeros(mask.shape)
    sy = np.zeros(mask.shape)
    slip = np.zeros(mask.shape, dtype=bool)
    slip[mask] = res.slip
    sx[mask] = np.where(res.slip, s[:, 0], 0.0)
    sy[mask] = np.where(res.slip, s[:, 1], 0.0)
    fx, fy, mz = resultants(area, tx, ty, reference)
    return TransientSolution(tx, ty, slip, sx, sy, fx, fy, mz, res.newton)


def cattaneo_shift(area: GridArea, shift_x: float, shift_y: float, *, mu: float, nu: float,
                   shear_modulus: float,
                   previous: TransientSolution | None = None) -> TransientSolution:
    """Solve the shift (Cattaneo) problem: the bodies, pressed together, shifted (m)."""
    ops = TransientOperators.of(area, 0, nu=nu, shear_modulus=shear_modulus)
    shape = area.mask.shape
    return transient_step(area, ops, (np.full(shape, float(shift_x)),
                                      np.full(shape, float(shift_y))), mu, previous)


def rolling_step(area: GridArea, operators: TransientOperators, xi: float, eta: float,
                 phi: float, *, mu: float, previous: TransientSolution | None,
                 reference: tuple[float, float] = (0.0, 0.0)) -> TransientSolution:
    """Roll ``operators.cells`` cells at creepages ``xi``, ``eta`` (1), ``phi`` (1/m).

    The rigid slip over the step is the creepages' ``w`` (at the cell
    centres, about ``reference``) times the distance rolled ``m dx``.
    """
    q = operators.cells * area.dx
    wx, wy = rigid_slip(area, xi, eta, phi, reference)
    return transient_step(area, operators, (wx * q, wy * q), mu, previous,
                          reference=reference)
