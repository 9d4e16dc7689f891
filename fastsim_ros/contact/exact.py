"""Kalker's exact theory of steady rolling, discretised by boundary elements.

Assumptions (as in Kalker 1990 and CONTACT): two quasi-identical elastic
half-spaces (combined ``G``, ``nu``), so the normal problem does not depend on
the tangential one; steady state; uniform tractions on the rectangular cells
of a regular grid; the displacement difference from the closed-form rectangle
influence coefficients (:mod:`fastsim_ros.contact.influence`).

The slip per unit rolling distance of the wheel relative to the rail is
``s = w - du/dx`` (material flows from larger to smaller ``x``), with the rigid
slip ``w = (xi - phi y, eta + phi x)``.  It is discretised at cell centres
with the *upstream* difference ``du/dx ~ (u(x + dx) - u(x))/dx``; the upstream
point may lie outside the area, where the displacement is still the elastic
field of the tractions inside.  With that difference the coefficient of
``eta`` in ``Mz`` equals ``C23`` on every grid (docs/guide_physics.md "The exact solver").

Tractions ``tau`` are those of the rail on the wheel.  ``tau -> du/dx`` is
the :class:`~fastsim_ros.contact.rolling.SteadyRollingOperator`, a
convolution on the regular grid: products go through FFTs, never through a
matrix.  Full adhesion (``s = 0`` everywhere) is one linear system ``B tau =
w``, solved by GMRES (a dense direct solve is kept as the reference).
Coulomb friction (``|tau| <= mu p``; ``s = 0`` where ``|tau| < mu p``; ``s``
opposite to ``tau`` where ``|tau| = mu p``) is solved by semismooth Newton on
the whole area with FFT products (:mod:`~fastsim_ros.contact.partial_slip`,
the default, up to :data:`MAX_COULOMB_CELLS` cells in contact); the
reference, for small grids, is block Gauss-Seidel over the lateral strips
with the dense operator, each strip's own nonlinear problem solved exactly by
semismooth Newton.  With a slip-dependent law
(:mod:`~fastsim_ros.contact.friction`) the bound is ``mu(v) p`` with ``v =
|V| |s|`` the cell's own slip velocity: the projection's radius depends on
the unknowns, and both Newtons carry that dependence in their Jacobians.

``SteadyRollingOperator`` and ``StripBlock`` are :mod:`~fastsim_ros.contact.rolling`'s,
taken from here as before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import numpy as np
import scipy.linalg
import scipy.sparse.linalg
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea, ellipse, semi_ellipse_axes, semi_ellipses
from fastsim_ros.contact.checks import (check_creepages, check_friction, check_material,
                                        check_poisson_ratio)
from fastsim_ros.contact.coefficients import (UNIT_CREEPAGES, CreepCoefficients,
                                              coefficients_from_unit_solutions)
from fastsim_ros.contact.errors import (ConvergenceError, GridTooLargeError,
                                        InvalidInputError)
from fastsim_ros.contact.friction import FrictionLaw, check_speed, resolve
from fastsim_ros.contact.partial_slip import on_one_blas_thread, solve_area
from fastsim_ros.contact.rolling import SteadyRollingOperator, StripBlock
from fastsim_ros.contact.traction import Tractions, resultants, rigid_slip

__all__ = ["SteadyRollingOperator", "StripBlock", "TractionSolution", "full_adhesion",
           "coulomb", "unit_solutions", "creep_coefficients", "extrapolation_grids",
           "extrapolated_coefficients", "EXTRAPOLATION_GRIDS", "MAX_COULOMB_CELLS",
           "MAX_DENSE_COULOMB_CELLS", "slip_dissipation"]

FloatArray = NDArray[np.float64]
SolverKind = Literal["fft", "dense"]
ShapeName = Literal["ellipse", "semi-ellipses"]


class _StripPreconditioner:
    """Exact inverse of each lateral strip's own block of the operator.

    Within a strip (``dj = 0``) the operator holds the upstream difference,
    the strongest coupling of steady rolling, and no ``x``-``y`` coupling
    (``K_xy`` vanishes on ``dj = 0``); the strips' mutual influence is left to
    GMRES.  This cuts the iterations several-fold on fine grids.
    """

    def __init__(self, op: SteadyRollingOperator) -> None:
        self.n = int(np.count_nonzero(op.area.mask))
        self.blocks = []
        # strips of one pattern share their block arrays: factor each once
        factored: dict[bytes, tuple[object, object]] = {}
        for idx, bxx, byy, pattern in op.strip_blocks():
            if pattern not in factored:
                factored[pattern] = (scipy.linalg.lu_factor(bxx), scipy.linalg.lu_factor(byy))
            self.blocks.append((idx, *factored[pattern]))

    def solve(self, v: FloatArray) -> FloatArray:
        out = np.empty_like(v)
        n = self.n
        for idx, lux, luy in self.blocks:
            out[idx] = scipy.linalg.lu_solve(lux, v[idx], check_finite=False)
            out[n + idx] = scipy.linalg.lu_solve(luy, v[n + idx], check_finite=False)
        return out

    def as_operator(self) -> scipy.sparse.linalg.LinearOperator:
        return scipy.sparse.linalg.LinearOperator((2 * self.n, 2 * self.n), matvec=self.solve,
                                                  dtype=float)


@dataclass(frozen=True, eq=False)
class TractionSolution(Tractions):
    """Tractions of one exact solve (:class:`Tractions`), its area and solver iterations.

    ``slip`` is all false in full adhesion; ``iterations``: GMRES iterations
    (full adhesion), Newton iterations (Coulomb, the FFT solver, on the
    finest grid) or Gauss-Seidel sweeps (Coulomb, the dense reference);
    ``krylov``: the FFT Coulomb solver's GMRES iterations in all (finest
    grid); ``products``: its FFT products with the operator (finest grid).
    """

    area: GridArea
    iterations: int
    krylov: int = 0
    products: int = 0


def _operator(operator: SteadyRollingOperator | None, area: GridArea, nu: float,
              shear_modulus: float) -> SteadyRollingOperator:
    """Return ``operator`` once checked against the area and material, else build it."""
    if operator is None:
        return SteadyRollingOperator.of(area, nu=nu, shear_modulus=shear_modulus)
    check_material(nu, shear_modulus)
    operator.check_matches(area, nu, shear_modulus)
    return operator


@on_one_blas_thread
def full_adhesion(area: GridArea, xi: float, eta: float, phi: float, *, nu: float,
                  shear_modulus: float, reference: tuple[float, float] = (0.0, 0.0),
                  solver: SolverKind = "fft", rtol: float = 1e-10,
                  operator: SteadyRollingOperator | None = None) -> TractionSolution:
    """Tractions in full adhesion (``mu`` infinite) for creepages about ``reference``.

    ``xi``, ``eta`` dimensionless, ``phi`` in 1/m; ``shear_modulus`` combined
    ``G`` (Pa).  ``solver="fft"``: GMRES with FFT products; ``"dense"``: LU of
    the dense operator (the reference, for a few thousand cells at most).
    ``operator``: the area's :class:`SteadyRollingOperator` for this
    material, if already built (checked against the area and the material).
    """
    check_creepages(xi, eta, phi)
    op = _operator(operator, area, nu, shear_modulus)
    wx, wy = rigid_slip(area, xi, eta, phi, reference)
    mask = area.mask
    n = int(np.count_nonzero(mask))
    rhs = np.concatenate([wx[mask], wy[mask]])
    iterations = 0
    if solver == "dense":
        tau = scipy.linalg.solve(op.dense(), rhs)
    elif solver == "fft":
        product = op.fft_product()
        tx = np.zeros(mask.shape)
        ty = np.zeros(mask.shape)

        def matvec(v: FloatArray) -> FloatArray:
            tx[mask] = v[:n]
            ty[mask] = v[n:]
            gx, gy = product(tx, ty)
            return np.concatenate([gx[mask], gy[mask]])

        lin = scipy.sparse.linalg.LinearOperator((2 * n, 2 * n), matvec=matvec, dtype=float)
        precond = _StripPreconditioner(op).as_operator()
        counter = [0]

        def count(_: object) -> None:
            counter[0] += 1

        if not np.any(rhs):
            tau = np.zeros(2 * n)
        else:
            tau, info = scipy.sparse.linalg.gmres(lin, rhs, rtol=rtol, atol=0.0, restart=200,
                                                  maxiter=50, M=precond, callback=count,
                                                  callback_type="pr_norm")
            if info != 0:
                raise ConvergenceError(f"GMRES did not converge ({counter[0]} iterations)")
        iterations = counter[0]
    else:
        raise InvalidInputError(f"unknown solver {solver!r}")
    tau_x = np.zeros(mask.shape)
    tau_y = np.zeros(mask.shape)
    tau_x[mask] = tau[:n]
    tau_y[mask] = tau[n:]
    fx, fy, mz = resultants(area, tau_x, tau_y, reference)
    return TractionSolution(tau_x, tau_y, np.zeros(mask.shape, dtype=bool), fx, fy, mz, area,
                            iterations)


def _project(z: FloatArray, bound: FloatArray) -> tuple[FloatArray, NDArray[np.bool_]]:
    """Project the rows of ``z`` (m, 2) onto discs of radius ``bound``; flag the clipped ones."""
    norm = np.hypot(z[:, 0], z[:, 1])
    out = norm > bound
    pz = z.copy()
    pz[out] *= (bound[out] / norm[out])[:, None]
    return pz, out


def _strip_coulomb(q: FloatArray, bp: FloatArray, bound: FloatArray, c: float,
                   tau0: FloatArray, tol: float, max_newton: int = 50,
                   law: FrictionLaw | None = None,
                   speed: float = 0.0) -> tuple[FloatArray, NDArray[np.bool_]]:
    """Coulomb friction on one strip, the other strips' tractions frozen.

    Slip ``s = q + Bp tau`` (``q``, ``tau`` of shape (m, 2); ``Bp`` the strip's
    own block, interleaved x/y, ``2m x 2m``).  The friction law is the
    fixed point ``tau = P(tau - c s)`` with ``P`` the projection onto the disc
    ``|tau| <= g`` (``c > 0`` any scalar): inside the disc it says ``s = 0``,
    on its rim that ``s`` is opposite to ``tau``.  Solved by semismooth Newton,
    ``J = I - Pi (I - c Bp)`` with ``Pi`` the projection's derivative, and a
    backtracking line search on ``|F|``.

    A slip-dependent ``law``: ``bound`` is the static one (``mu_s p``) and the
    disc's radius is ``bound ratio(speed |s|)`` (``speed`` = ``|V|``, m/s), a
    function of the unknowns; on a clipped cell ``P = g z/|z|`` then also
    moves with ``g``: ``J`` gains ``- (z/|z|) g_s ratio'(v) V (s/|s|)^T Bp``.
    """
    m = q.shape[0]
    eye = np.eye(2 * m)
    az = eye - c * bp
    tau = tau0.copy()
    radius = bound

    def residual(t: FloatArray) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
        nonlocal radius
        z = (az @ t.ravel()).reshape(m, 2) - c * q
        if law is not None:
            slip = q + (bp @ t.ravel()).reshape(m, 2)
            radius = bound * law.ratio(speed * np.hypot(slip[:, 0], slip[:, 1]))
        pz, out = _project(z, radius)
        return t - pz, z, out

    f, z, out = residual(tau)
    fnorm = float(np.abs(f).max())
    for _ in range(max_newton):
        if fnorm <= tol:
            break
        # Pi: identity where z lies in the disc, g/|z| (I - zz^T/|z|^2) where clipped.
        pi = np.zeros((m, 2, 2))
        pi[~out] = np.eye(2)
        zo = z[out]
        nz = np.hypot(zo[:, 0], zo[:, 1])
        zh = zo / nz[:, None]
        pi[out] = (radius[out] / nz)[:, None, None] * (np.eye(2) - zh[:, :, None] * zh[:, None, :])
        big_pi = np.zeros((2 * m, 2 * m))
        for a in range(2):
            for b in range(2):
                big_pi[a::2, b::2] = np.diag(pi[:, a, b])
        jac = eye - big_pi @ az
        if law is not None and out.any():
            # d radius_i / d s_i = g_s ratio'(V |s_i|) V s_i/|s_i|; ds = Bp dtau
            slip = q + (bp @ tau.ravel()).reshape(m, 2)
            ns = np.hypot(slip[:, 0], slip[:, 1])
            safe = np.where(ns > 0.0, ns, 1.0)
            dg = np.where(ns > 0.0, bound * law.ratio_slope(speed * ns) * speed / safe, 0.0)
            dir_z = np.zeros((m, 2))
            dir_z[out] = zh
            # rows of cell i: dir_z_i (dg_i s_i^T) Bp[2i:2i+2, :]
            row = (slip * dg[:, None])
            ds_row = row[:, 0:1] * bp[0::2] + row[:, 1:2] * bp[1::2]  # (m, 2m)
            big = np.zeros((2 * m, 2 * m))
            big[0::2] = dir_z[:, 0:1] * ds_row
            big[1::2] = dir_z[:, 1:2] * ds_row
            jac = jac - big
        step = np.linalg.solve(jac, -f.ravel()).reshape(m, 2)
        alpha = 1.0
        while True:
            trial = tau + alpha * step
            f_t, z_t, out_t = residual(trial)
            fn_t = float(np.abs(f_t).max())
            if fn_t < fnorm or alpha < 1e-4:
                break
            alpha *= 0.5
        tau, f, z, out, fnorm = trial, f_t, z_t, out_t, fn_t
    # a clipped z is slip; the projection of the converged fixed point is the traction
    return _project(z, radius)[0] if fnorm <= tol else tau, out


@on_one_blas_thread
def coulomb(area: GridArea, xi: float, eta: float, phi: float, *, mu: float | None = None,
            nu: float, shear_modulus: float, reference: tuple[float, float] = (0.0, 0.0),
            tol: float = 1e-9, max_sweeps: int = 500,
            operator: SteadyRollingOperator | None = None, friction: FrictionLaw | None = None,
            speed: float | None = None, solver: SolverKind = "fft",
            start: FloatArray | None = None) -> TractionSolution:
    """Tractions with Coulomb friction ``|tau| <= mu p``, ``p`` the area's pressure (Pa).

    ``friction``: a law (default ``ConstantFriction(mu)``; ``mu``, if given
    too, must be its ``mu_s``): the bound is ``mu(v) p`` with ``v = |V| |s|``
    the local slip velocity (m/s), ``speed`` = ``|V|`` (m/s, required by a
    slip-dependent law), ``s`` the slip per unit rolling distance.

    Creepages about ``reference`` (``phi`` in 1/m); ``shear_modulus`` the
    combined ``G`` (Pa).  ``operator``: the area's
    :class:`SteadyRollingOperator` for this material, if already built: a
    sweep of creepages on one area should pass it (the FFT solver keeps its
    spectra, strip blocks and coarse grids on it); without it the FFT solver
    builds one for the smallest grid holding the cells in contact
    (:meth:`GridArea.cropped`: a potential-contact grid's empty margin costs
    nothing), the results on ``area``'s grid all the same.

    ``solver="fft"`` (default): semismooth Newton on the whole area, GMRES
    with FFT products and strip-block preconditioning, started from the
    grid of twice the cell size (:mod:`~fastsim_ros.contact.partial_slip`),
    or from ``start`` (Pa, ``(m, 2)``: the tractions of the cells in contact
    in the mask's order, e.g. a nearby problem's solution, to the same
    tolerance);
    memory proportional to the cells, at most :data:`MAX_COULOMB_CELLS` cells
    in contact.  ``"dense"``: the reference, block Gauss-Seidel over the
    lateral strips with the dense operator (at most
    :data:`MAX_DENSE_COULOMB_CELLS` cells), each strip's nonlinear problem
    solved exactly (:func:`_strip_coulomb`); the strips' mutual influence is
    weak enough for the sweep to contract (a march along ``x`` instead, cell
    by cell, diverges: the far upstream terms of the difference kernel
    amplify); at most ``max_sweeps`` sweeps.  Both solve the same discrete
    problem and stop when the largest traction error (the Newton residual
    ``|tau - P(tau - c s)|``; the Gauss-Seidel sweep's largest change) is
    below ``tol * mu * max(p)``.  The cell count is checked before anything
    of the solver is allocated (:class:`GridTooLargeError`).  Both run with
    one BLAS thread (:func:`~fastsim_ros.contact.partial_slip.one_blas_thread`),
    as does :func:`full_adhesion`.
    """
    law = resolve(mu, friction)
    if law.reduces_slope:
        raise InvalidInputError("the exact theory has its full slope: a slope reduction is "
                                "an option of the fast methods")
    mu = check_friction(law.mu_s)
    slip_law = law if law.slip_dependent else None
    v_roll = check_speed(speed) if slip_law is not None else 0.0
    check_creepages(xi, eta, phi)
    mask = area.mask
    n = int(np.count_nonzero(mask))
    if solver == "fft":
        _check_cells(n, MAX_COULOMB_CELLS, "the FFT Coulomb solver")
        # the FFTs span the grid: without an operator, solve on the smallest grid that holds
        # the cells in contact (their order, row by row, is the same on both grids)
        op = _operator(operator, area if operator is not None else area.cropped(), nu,
                       shear_modulus)
        if start is not None and np.shape(start) != (n, 2):
            raise InvalidInputError(f"start tractions of shape {np.shape(start)}, the area has "
                                    f"{n} cells in contact")
        try:
            res = solve_area(op, (xi, eta, phi), reference, mu_s=mu, tol=tol, law=slip_law,
                             speed=v_roll, start=None if start is None
                             else np.array(start, dtype=np.float64))
        except ConvergenceError:
            # the whole-area Newton can cycle between slip areas (measured: the long narrow
            # validation patch at half the saturating eta, scripts/validate_wider.py); the
            # dense reference's strip-by-strip sweeps converge there, within their cell limit
            if n > MAX_DENSE_COULOMB_CELLS:
                raise
            return coulomb(area, xi, eta, phi, nu=nu, shear_modulus=shear_modulus,
                           reference=reference, tol=tol, max_sweeps=max_sweeps, friction=law,
                           speed=speed, solver="dense")
        return _solution(area, res.tau, res.slip, reference, res.newton, res.krylov,
                         res.products)
    if solver != "dense":
        raise InvalidInputError(f"unknown solver {solver!r}: fft or dense")
    _check_cells(n, MAX_DENSE_COULOMB_CELLS, "the dense Coulomb solver")
    op = _operator(operator, area, nu, shear_modulus)
    # rows of B's transpose are contiguous: the update of all slips by one
    # strip's traction change reads them.
    bt = np.ascontiguousarray(op.dense().T)
    wx, wy = rigid_slip(area, xi, eta, phi, reference)
    bound = mu * area.pressure[mask]
    d_x, d_y = op.diagonal
    c = 1.0 / math.sqrt(d_x * d_y)
    tau = np.zeros((n, 2))
    s = np.concatenate([wx[mask], wy[mask]])
    strips = []
    # each strip's block, negated (positive diagonal) and x/y interleaved; shared
    # by strips of one pattern
    interleaved: dict[bytes, FloatArray] = {}
    for idx, bxx, byy, pattern in op.strip_blocks():
        if pattern not in interleaved:
            bp = np.zeros((2 * idx.size, 2 * idx.size))
            bp[0::2, 0::2] = -bxx
            bp[1::2, 1::2] = -byy
            interleaved[pattern] = bp
        strips.append((idx, interleaved[pattern]))
    scale = mu * float(area.pressure.max())
    slip = np.zeros(n, dtype=bool)
    for sweep in range(1, max_sweeps + 1):
        change = 0.0
        for idx, bp in strips:
            old = tau[idx]
            s_strip = np.stack([s[idx], s[n + idx]], axis=1)
            q = s_strip - (bp @ old.ravel()).reshape(-1, 2)
            new, slip[idx] = _strip_coulomb(q, bp, bound[idx], c, old, 1e-3 * tol * scale,
                                            law=slip_law, speed=v_roll)
            delta = new - old
            change = max(change, float(np.abs(delta).max()))
            s -= delta[:, 0] @ bt[idx] + delta[:, 1] @ bt[n + idx]
            tau[idx] = new
        if change <= tol * scale:
            break
    else:
        raise ConvergenceError(f"Coulomb solver did not converge in {max_sweeps} sweeps")
    return _solution(area, tau, slip, reference, sweep)


#: the most cells in contact of the FFT Coulomb solver (CONTACT's default limit is 20,000)
MAX_COULOMB_CELLS = 20_000
#: the most cells in contact of the dense reference (its operator: 8 (2n)^2 bytes, 0.5 GB)
MAX_DENSE_COULOMB_CELLS = 4_000


def _check_cells(n: int, limit: int, what: str) -> None:
    if n > limit:
        raise GridTooLargeError(f"{what} takes at most {limit:,} cells in contact, got {n:,}")


def _solution(area: GridArea, tau: FloatArray, slip: NDArray[np.bool_],
              reference: tuple[float, float], iterations: int, krylov: int = 0,
              products: int = 0) -> TractionSolution:
    """Return the solution on the grid from the cells' tractions ``tau`` (m, 2)."""
    mask = area.mask
    tau_x = np.zeros(mask.shape)
    tau_y = np.zeros(mask.shape)
    slip_map = np.zeros(mask.shape, dtype=bool)
    tau_x[mask] = tau[:, 0]
    tau_y[mask] = tau[:, 1]
    slip_map[mask] = slip
    fx, fy, mz = resultants(area, tau_x, tau_y, reference)
    return TractionSolution(tau_x, tau_y, slip_map, fx, fy, mz, area, iterations, krylov,
                            products)


def unit_solutions(area: GridArea, *, nu: float, reference: tuple[float, float] = (0.0, 0.0),
                   solver: SolverKind = "fft") -> tuple[TractionSolution, ...]:
    """Full-adhesion solutions for unit ``xi``, unit ``eta`` and unit ``phi`` (G = 1 Pa)."""
    op = SteadyRollingOperator.of(area, nu=nu, shear_modulus=1.0)
    return tuple(full_adhesion(area, *cr, nu=nu, shear_modulus=1.0, reference=reference,
                               solver=solver, operator=op)
                 for cr in UNIT_CREEPAGES)


def creep_coefficients(area: GridArea, *, nu: float,
                       reference: tuple[float, float] = (0.0, 0.0),
                       solver: SolverKind = "fft") -> CreepCoefficients:
    """Generalised coefficients ``C~ij`` of an area from the exact theory on its grid.

    Normalised with the discrete area (cells times cell area), which removes
    most of the staircase noise of the boundary (docs/guide_physics.md "The exact solver").
    """
    sols = unit_solutions(area, nu=nu, reference=reference, solver=solver)
    return coefficients_from_unit_solutions(
        area.area, tuple((s.fx, s.fy, s.mz) for s in sols), reference=reference)


#: the grids of an extrapolation, as fractions of the finest (docs/guide_physics.md: at least four)
EXTRAPOLATION_GRIDS = (0.4, 0.6, 0.8, 1.0)


def extrapolation_grids(finest: int) -> list[int]:
    """Return the even cell counts of an extrapolation up to ``finest`` cells across.

    None above ``finest`` (an odd count is not rounded up to the next even
    one: ``--cells 7`` solves on at most 6); fewer than two for ``finest`` below
    6, where no line can be fitted: :func:`extrapolated_coefficients` then
    refuses.
    """
    top = finest - finest % 2
    return sorted({min(top, max(4, 2 * round(f * finest / 2))) for f in EXTRAPOLATION_GRIDS})


def extrapolated_coefficients(shape: ShapeName, ratios: tuple[float, ...], *, nu: float,
                              finest: int = 100) -> CreepCoefficients:
    """Return the exact coefficients of a unit-area shape extrapolated to zero cell size.

    ``shape``: ``"ellipse"`` (``ratios = (a/b,)``) or ``"semi-ellipses"``
    (``ratios = (a1/b1, a2/b2)``), area 1 m^2, about the centre (the join
    line's middle); solved on :func:`extrapolation_grids` ``(finest)`` cells
    across and fitted by ``C(h) = C0 + k h`` in the cell size ``h = 1/n``
    (first-order convergence, docs/guide_physics.md); ``area`` is 1.  Cached: the
    extrapolation takes seconds and its result is immutable.
    """
    # one cache key however the call spells its arguments
    return _extrapolated(str(shape), tuple(float(g) for g in ratios), float(nu), int(finest))


@lru_cache(maxsize=32)
def _extrapolated(shape: str, ratios: tuple[float, ...], nu: float,
                  finest: int) -> CreepCoefficients:
    check_poisson_ratio(nu)
    if shape == "ellipse" and len(ratios) == 1:
        a, b = semi_ellipse_axes(ratios[0])

        def make(n: int) -> GridArea:
            return ellipse(a, b, nx=n, ny=n)
    elif shape == "semi-ellipses" and len(ratios) == 2:
        semi_ellipse_axes(ratios[0])
        semi_ellipse_axes(ratios[1])

        def make(n: int) -> GridArea:
            return semi_ellipses(ratios[0], ratios[1], cells=n)
    else:
        raise InvalidInputError(f"unknown shape {shape!r} with a/b {ratios}: an ellipse takes "
                                "one ratio, semi-ellipses two")
    grids = extrapolation_grids(finest)
    if len(grids) < 2:
        # one grid fits no line: numpy's rank-deficient fit gave half the coefficients
        raise InvalidInputError(f"an extrapolation needs two grids at least: {finest} cells "
                                "across give one (6 or more do)")
    per = [creep_coefficients(make(n), nu=nu) for n in grids]
    h = np.array([1.0 / n for n in grids])
    fit = {key: float(np.polyfit(h, [getattr(c, key) for c in per], 1)[1])
           for key in ("C11", "C12", "C13", "C21", "C22", "C23", "C31", "C32", "C33")}
    return CreepCoefficients(fit["C11"], fit["C12"], fit["C13"], fit["C21"], fit["C22"],
                             fit["C23"], fit["C31"], fit["C32"], fit["C33"], area=1.0)


def slip_dissipation(area: GridArea, solution: Tractions, xi: float, eta: float, phi: float,
                     *, nu: float, shear_modulus: float,
                     reference: tuple[float, float] = (0.0, 0.0),
                     operator: SteadyRollingOperator | None = None
                     ) -> tuple[float, FloatArray]:
    """Return the exact solve's slip dissipation per metre rolled (N) and its density (N/m^2).

    ``s = w - du/dx`` with ``du/dx`` the solver's own discrete operator
    (:class:`~fastsim_ros.contact.rolling.SteadyRollingOperator`, upstream
    difference) applied to the solution's tractions, ``w`` the rigid slip
    about ``reference``; ``-tau . s`` on the slip cells (zero where they
    stick, as CONTACT sets it), summed times the cell area.  Times ``|V|``:
    the frictional power (W) and its density (W/m^2).  ``operator``: the
    area's own (:func:`coulomb`'s), else one is built.
    """
    op = operator if operator is not None else SteadyRollingOperator.of(
        area, nu=nu, shear_modulus=shear_modulus)
    dux, duy = op.fft_product()(solution.tau_x, solution.tau_y)
    wx, wy = rigid_slip(area, xi, eta, phi, reference)
    density = np.where(solution.slip, -(solution.tau_x * (wx - dux)
                                        + solution.tau_y * (wy - duy)), 0.0)
    return float(density.sum() * area.cell_area), density
