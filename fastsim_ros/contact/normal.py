"""Normal contact of two quasi-identical elastic half-spaces, discretised on a grid.

Assumptions (as in Kalker 1990 and CONTACT): two quasi-identical elastic
half-spaces (combined shear modulus ``G``, Poisson ratio ``nu``), so the
normal problem does not depend on the tangential one; frictionless normal
contact; uniform pressure on the rectangular cells of a regular grid; the
normal displacement difference from the closed-form rectangle influence
coefficients (:mod:`fastsim_ros.contact.influence`).  A point force ``P``
gives ``u_z = (1 - nu)/(pi G) P/rho``, i.e. ``P/(pi E* rho)`` with the
combined contact modulus ``E* = G/(1 - nu)`` of Hertz theory.

The discrete problem: find the pressure ``p >= 0`` (Pa) on the cells such
that the deformed gap ``h = h0 - delta + u_z(p)`` (m) is ``>= 0`` with
``p h = 0`` on every cell (complementarity), ``h0`` the undeformed gap and
``delta`` the rigid approach.  Either the load ``N = sum p dA`` or ``delta``
is given.  It is the minimum of the convex energy ``1/2 p.K p + p.(h0 -
delta)`` over ``p >= 0`` (``K`` the symmetric positive definite influence
matrix), which the conjugate-gradient algorithm of Polonsky & Keer (Wear
231, 1999, pp. 206-219) solves with products ``K p`` by FFT (``K`` is a
convolution on the regular grid).  For a given load, ``delta`` is the
multiplier of the load constraint and the algorithm removes the mean gap on
the contact set; for a given approach the same projected CG runs without
the load constraint.

The classical Hertz solution of an ellipsoidal gap (:func:`hertz_ellipse`)
is the reference the discrete solver is checked against.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.fft
import scipy.optimize
import scipy.special
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.errors import ConvergenceError, EmptyContactError, InvalidInputError
from fastsim_ros.contact.checks import check_material, check_positive
from fastsim_ros.contact.influence import influence_kernel

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class HertzContact:
    """Hertz solution of an ellipsoidal gap.

    ``a``, ``b``: semi-axes of the contact ellipse along ``x`` and ``y`` (m);
    ``p0``: maximum pressure (Pa), at the centre; ``approach``: rigid
    approach ``delta`` of the two bodies (m).  The pressure is
    ``p0 sqrt(1 - x^2/a^2 - y^2/b^2)`` inside the ellipse.
    """

    a: float
    b: float
    p0: float
    approach: float

    @property
    def load(self) -> float:
        """Return the normal load ``N = 2/3 pi a b p0`` (N)."""
        return 2.0 / 3.0 * math.pi * self.a * self.b * self.p0

    def pressure(self, x: FloatArray, y: FloatArray) -> FloatArray:
        """Return the Hertz pressure at points ``(x, y)`` (m) in Pa, zero outside the ellipse."""
        rho2 = (np.asarray(x) / self.a) ** 2 + (np.asarray(y) / self.b) ** 2
        return self.p0 * np.sqrt(np.clip(1.0 - rho2, 0.0, None))


@dataclass(frozen=True, eq=False)
class NormalSolution:
    """Solution of the discrete normal contact problem.

    ``area``: the grid with the contact pressure (a :class:`GridArea`, ready
    for the tangential solvers); ``pressure``: the same pressure (Pa), shape
    ``(ny, nx)``; ``approach``: rigid approach ``delta`` (m); ``load``:
    ``N = sum p dA`` (N); ``gap``: deformed gap ``h0 - delta + u_z`` (m),
    zero (to the tolerance) on the contact cells; ``iterations``: CG
    iterations.
    """

    area: GridArea
    pressure: FloatArray
    approach: float
    load: float
    gap: FloatArray
    iterations: int

    @property
    def touches_edge(self) -> bool:
        """Whether a cell on the grid's boundary is in contact (the grid may be too small)."""
        m = self.area.mask
        return bool(m[0].any() or m[-1].any() or m[:, 0].any() or m[:, -1].any())


def ellipsoid_gap(x: FloatArray, y: FloatArray, rx: float, ry: float) -> FloatArray:
    """Undeformed gap ``h0 = x^2/(2 rx) + y^2/(2 ry)`` (m) on a grid, shape ``(ny, nx)``.

    ``x`` (shape ``(nx,)``) and ``y`` (``(ny,)``) are the cell centres (m),
    e.g. ``GridArea.x`` and ``GridArea.y``; ``rx``, ``ry`` the principal
    relative radii of curvature (m) along ``x`` and ``y``.
    """
    check_positive(rx=rx, ry=ry)
    xa = np.asarray(x, dtype=float).ravel()
    ya = np.asarray(y, dtype=float).ravel()
    return xa[None, :] ** 2 / (2.0 * rx) + ya[:, None] ** 2 / (2.0 * ry)


def hertz_ellipse(rx: float, ry: float, load: float, *, shear_modulus: float,
                  nu: float) -> HertzContact:
    """Hertz contact of the gap ``x^2/(2 rx) + y^2/(2 ry)`` under ``load`` (N).

    ``rx``, ``ry``: principal relative radii (m) along ``x`` and ``y``;
    ``shear_modulus``: combined ``G`` (Pa); ``E* = G/(1 - nu)``.

    Johnson, Contact Mechanics (1985), sec. 4.2 (with the displacement of
    the ellipsoidal pressure, ch. 3): write the gap ``A x'^2 + B y'^2``
    with ``A <= B`` (``x'`` along the larger radius ``R' = 1/(2A)``), so the
    semi-axes are ``a' >= b'``, ``e^2 = 1 - b'^2/a'^2`` and ``K``, ``E`` the
    complete elliptic integrals of parameter ``m = e^2``.  The pressure
    ``p0 sqrt(1 - x'^2/a'^2 - y'^2/b'^2)`` displaces the surfaces by
    ``(L - M x'^2 - N y'^2)`` inside the ellipse, with

        L = p0 b' K/E*,   M = p0 b'/(E* e^2 a'^2) (K - E),
        N = p0 b'/(E* e^2 a'^2) ((a'^2/b'^2) E - K),

    and contact requires ``delta = L``, ``A = M``, ``B = N``; with
    ``p0 = 3 N_load/(2 pi a' b')`` this gives

        B/A = ((a'/b')^2 E - K)/(K - E),                (eccentricity)
        a'^3 = 3 N_load R' (K - E)/(pi E* e^2),        delta = p0 b' K/E*.

    The differences ``K - E`` and ``E/(1 - m) - K`` cancel as ``e -> 0`` (the
    near-circular contacts of wheel and rail); they are evaluated exactly in
    Carlson's form, ``K - E = m R_D(0, 1-m, 1)/3`` and ``E/(1-m) - K = m
    R_D(0, 1, 1-m)/3`` (DLMF 19.25.1), so ``B/A = R_D(0, 1, k)/R_D(0, k, 1)``
    with ``k = 1 - m = (b'/a')^2``, solved for ``k`` with ``brentq``, and
    ``a'^3 = N_load R' R_D(0, k, 1)/(pi E*)``.  ``K`` is ``ellipkm1(k)``,
    accurate also for slender ellipses (``m -> 1``).  For ``rx = ry = R``:
    ``a = b = (3 N_load R/(4 E*))^(1/3)``, ``p0 = 3 N_load/(2 pi a^2)``,
    ``delta = a^2/R``.
    """
    check_positive(rx=rx, ry=ry, load=load)
    check_material(nu, shear_modulus)
    e_star = shear_modulus / (1.0 - nu)
    r_major, r_minor = max(rx, ry), min(rx, ry)
    ratio = r_major / r_minor  # B/A >= 1
    k = 1.0 if ratio == 1.0 else _squared_axis_ratio(ratio)
    rd = float(scipy.special.elliprd(0.0, k, 1.0))
    a_major = (load * r_major * rd / (math.pi * e_star)) ** (1.0 / 3.0)
    b_minor = a_major * math.sqrt(k)
    p0 = 3.0 * load / (2.0 * math.pi * a_major * b_minor)
    approach = p0 * b_minor * float(scipy.special.ellipkm1(k)) / e_star
    if rx >= ry:
        return HertzContact(a_major, b_minor, p0, approach)
    return HertzContact(b_minor, a_major, p0, approach)


def _squared_axis_ratio(ratio: float) -> float:
    """Return ``k = (b'/a')^2`` in ``(0, 1)`` of the Hertz ellipse with curvature ratio ``B/A``.

    Solves ``ln R_D(0, 1, k) - ln R_D(0, k, 1) = ln ratio`` in ``s = ln k``:
    the left side decreases from ``+inf`` (``k -> 0``) to 0 (``k = 1``).
    Johnson's approximation ``b'/a' ~ (A/B)^(2/3)`` starts the bracket.
    """
    target = math.log(ratio)

    def f(s: float) -> float:
        k = math.exp(s)
        return math.log(float(scipy.special.elliprd(0.0, 1.0, k))
                        / float(scipy.special.elliprd(0.0, k, 1.0))) - target

    lo = -2.0 * (4.0 / 3.0) * target - 1.0
    while f(lo) <= 0.0:
        lo *= 2.0
        if lo < -1400.0:  # k below the smallest double: no ellipse to speak of
            raise InvalidInputError(f"radii ratio {ratio:g} too large for a Hertz ellipse")
    return math.exp(float(scipy.optimize.brentq(f, lo, 0.0, xtol=1e-15, rtol=1e-15)))


class _NormalProduct:
    """``u_z = K p`` on a grid by FFT: circular embedding on a ``2ny`` x ``2nx`` grid."""

    def __init__(self, dx: float, dy: float, ny: int, nx: int, *, shear_modulus: float,
                 nu: float) -> None:
        zz = influence_kernel(dx, dy, nx - 1, ny - 1, shear_modulus=shear_modulus, nu=nu).zz
        self.shape = (2 * ny, 2 * nx)
        self.ny, self.nx = ny, nx
        # offset d (field minus source) lives at index d mod 2n; the zero row and
        # column at index n keep the product a linear (not circular) convolution on
        # the first ny x nx entries.
        c = np.zeros(self.shape)
        cy, cx = ny - 1, nx - 1
        c[:ny, :nx] = zz[cy:, cx:]
        c[:ny, nx + 1:] = zz[cy:, :cx]
        c[ny + 1:, :nx] = zz[:cy, cx:]
        c[ny + 1:, nx + 1:] = zz[:cy, :cx]
        self.spectrum = scipy.fft.rfft2(c, workers=-1)

    def __call__(self, p: FloatArray) -> FloatArray:
        """Return the normal displacement difference (m) of the pressure ``p`` (Pa, ny x nx)."""
        fp = scipy.fft.rfft2(p, s=self.shape, workers=-1)
        u = scipy.fft.irfft2(self.spectrum * fp, s=self.shape, workers=-1)
        return np.asarray(u[: self.ny, : self.nx])


def solve_normal(x0: float, y0: float, dx: float, dy: float, gap: FloatArray, *,
                 load: float | None = None, approach: float | None = None,
                 shear_modulus: float, nu: float, tol: float = 1e-10,
                 max_iter: int = 2000) -> NormalSolution:
    """Pressure of the normal contact of the undeformed gap ``gap`` under a load or an approach.

    The grid: centre of cell ``[0, 0]`` at ``(x0, y0)`` (m), cells ``dx`` x
    ``dy`` (m); ``gap[j, i]`` is the undeformed gap ``h0`` (m, positive =
    separated) at the cell centres, rows along ``y``.  Give exactly one of
    ``load`` (N, ``> 0``) or ``approach`` (m, the rigid approach ``delta``).
    ``shear_modulus`` is the combined ``G`` (Pa), ``nu`` the combined Poisson
    ratio.  Iterates until the pressure change of one iteration,
    ``sum |p_new - p_old| / sum p_new``, is below ``tol``; raises
    :class:`ConvergenceError` after ``max_iter`` iterations.
    """
    h0 = np.asarray(gap, dtype=float)
    _check_grid(x0, y0, dx, dy, h0)
    check_material(nu, shear_modulus)
    if not (math.isfinite(tol) and tol > 0.0):
        raise InvalidInputError(f"tol must be positive, got {tol}")
    if max_iter < 1:
        raise InvalidInputError(f"max_iter must be at least 1, got {max_iter}")
    if (load is None) == (approach is None):
        raise InvalidInputError("give exactly one of load and approach")
    product = _NormalProduct(dx, dy, h0.shape[0], h0.shape[1], shear_modulus=shear_modulus,
                             nu=nu)
    if load is not None:
        check_positive(load=load)
        p, iterations = _given_load(product, h0, load / (dx * dy), tol, max_iter)
    else:
        assert approach is not None
        if not math.isfinite(approach):
            raise InvalidInputError(f"approach must be finite, got {approach}")
        if not np.any(h0 < approach):
            raise EmptyContactError(f"approach {approach:g} m closes no cell's gap "
                                    f"(smallest gap {float(h0.min()):g} m)")
        p, iterations = _given_approach(product, h0, approach, tol, max_iter)
    u = product(p)
    contact = p > 0.0
    # delta: the rigid shift that closes the gap on the contact set (exactly the
    # given one in approach mode, the load constraint's multiplier otherwise).
    delta = float(np.mean(h0[contact] + u[contact])) if approach is None else float(approach)
    area = GridArea(float(x0), float(y0), float(dx), float(dy), p)
    return NormalSolution(area=area, pressure=area.pressure, approach=delta, load=area.load,
                          gap=h0 - delta + u, iterations=iterations)


def _given_load(product: _NormalProduct, h0: FloatArray, total: float, tol: float,
                max_iter: int) -> tuple[FloatArray, int]:
    """Polonsky & Keer's CG for ``sum p = total`` (Pa; the load over the cell area).

    Steps of the paper (sec. 3): on the contact set ``Ic = {p > 0}`` the gap
    ``g = K p + h0`` minus its mean over ``Ic`` (the mean is ``delta``) is
    the energy gradient; the search direction ``t`` is conjugate (``beta =
    G/G_old``) unless the previous step had to switch on cells outside
    ``Ic`` that overlapped (``p = 0``, ``g < 0``), which restarts steepest
    descent; the step ``tau`` is the exact line minimum with the mean of
    ``K t`` over ``Ic`` removed (the load constraint); after the step the
    pressure is clipped at zero, overlapping free cells get ``-tau g``, and
    the sum is rescaled to the load.
    """
    p = np.full(h0.shape, total / h0.size)
    t = np.zeros(h0.shape)
    g_old = 1.0
    conjugate = False
    for it in range(1, max_iter + 1):
        contact = p > 0.0
        g = product(p) + h0
        g -= np.mean(g[contact])
        g_norm = float(np.sum(g[contact] ** 2))
        beta = g_norm / g_old if conjugate else 0.0
        t = np.where(contact, g + beta * t, 0.0)
        g_old = g_norm
        r = product(t)
        r -= np.mean(r[contact])
        curvature = float(np.sum(r[contact] * t[contact]))
        if g_norm == 0.0 or curvature <= 0.0:
            return p, it  # exact solution (zero gradient on the contact set)
        tau = float(np.sum(g[contact] * t[contact])) / curvature
        p_old = p
        p = np.where(contact, p - tau * t, 0.0)
        p = np.maximum(p, 0.0)
        overlap = (p == 0.0) & (g < 0.0)
        conjugate = not bool(overlap.any())
        p[overlap] -= tau * g[overlap]
        s = float(p.sum())
        if not (math.isfinite(s) and s > 0.0):
            raise ConvergenceError(f"normal solver broke down at iteration {it}")
        p *= total / s
        if float(np.sum(np.abs(p - p_old))) <= tol * total:
            return p, it
    raise ConvergenceError(f"normal solver (given load) did not converge in {max_iter} "
                           "iterations")


def _given_approach(product: _NormalProduct, h0: FloatArray, delta: float, tol: float,
                    max_iter: int) -> tuple[FloatArray, int]:
    """Projected CG of Polonsky & Keer without the load constraint: ``h = K p + h0 - delta``.

    The energy ``1/2 p.K p + p.(h0 - delta)`` has the gradient ``g = K p +
    h0 - delta``, the deformed gap itself, so no mean is removed and the
    pressure is not rescaled.  It starts from the interference ``(delta -
    h0)+`` scaled to the energy minimum along it.
    """
    d = np.maximum(delta - h0, 0.0)
    p = d * (float(np.sum(d * d)) / float(np.sum(d * product(d))))
    t = np.zeros(h0.shape)
    g_old = 1.0
    conjugate = False
    for it in range(1, max_iter + 1):
        contact = p > 0.0
        g = product(p) + h0 - delta
        g_norm = float(np.sum(g[contact] ** 2))
        beta = g_norm / g_old if conjugate else 0.0
        t = np.where(contact, g + beta * t, 0.0)
        g_old = g_norm
        r = product(t)
        curvature = float(np.sum(r[contact] * t[contact]))
        if g_norm == 0.0 or curvature <= 0.0:
            if np.any(p > 0.0):
                return p, it
            raise ConvergenceError(f"normal solver broke down at iteration {it}")
        tau = float(np.sum(g[contact] * t[contact])) / curvature
        p_old = p
        p = np.maximum(np.where(contact, p - tau * t, 0.0), 0.0)
        overlap = (p == 0.0) & (g < 0.0)
        conjugate = not bool(overlap.any())
        p[overlap] -= tau * g[overlap]
        s = float(p.sum())
        if not math.isfinite(s):
            raise ConvergenceError(f"normal solver broke down at iteration {it}")
        if s > 0.0 and float(np.sum(np.abs(p - p_old))) <= tol * s:
            return p, it
    raise ConvergenceError(f"normal solver (given approach) did not converge in {max_iter} "
                           "iterations")


def _check_grid(x0: float, y0: float, dx: float, dy: float, h0: FloatArray) -> None:
    if not all(math.isfinite(v) for v in (x0, y0)):
        raise InvalidInputError("x0 and y0 must be finite")
    check_positive(dx=dx, dy=dy)
    if h0.ndim != 2 or h0.shape[0] < 2 or h0.shape[1] < 2:
        raise InvalidInputError(f"gap must be a 2-D array of at least 2 x 2 cells, got shape "
                                f"{h0.shape}")
    if not np.all(np.isfinite(h0)):
        raise InvalidInputError("gap has NaN or infinite values")
