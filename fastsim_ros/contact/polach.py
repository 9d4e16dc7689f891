"""Polach's method: closed-form creep forces on the patch's equivalent ellipse.

The method vehicle-dynamics codes (Simpack, Gensys, Open Rails) run in
place of FastSim.  Sources:

- O. Polach, "A fast wheel-rail forces calculation computer code", Vehicle
  System Dynamics 33 (suppl.), 1999, 728-739: the creep force of an
  ellipse with Hertzian pressure from the gradient ``eps`` of the
  tangential stress in the adhesion area, and the spin's lateral force;
- O. Polach, "Creep forces in simulations of traction vehicles running on
  adhesion limit", Wear 258, 2005, 992-1000: the reduction factors ``kA``
  (the adhesion area's stiffness) and ``kS`` (the slip area's), and the
  falling friction ``mu = mu_s [(1 - A) exp(-B w) + A]`` at the slip
  velocity ``w`` (m/s).

On an ellipse of semi-axes ``a`` (along the rolling direction), ``b`` (m),
load ``Q`` (N), combined shear modulus ``G`` (Pa), Kalker's coefficients
``c11, c22, c23`` at its ``a/b`` and Poisson ratio, creepages ``sx, sy`` (1)
and spin ``psi`` (1/m) at its centre:

    sy_C = sy + psi a   if |sy + psi a| > |sy|,   else sy          (Polach 1999)
    s_C  = sqrt(sx^2 + sy_C^2)
    C    = 3/8 G/a sqrt((c11 sx/s_C)^2 + (c22 sy_C/s_C)^2)           (N/m^3)
    eps  = 2/3 C pi a^2 b s_C / (Q mu)
    F    = 2 Q mu / pi [kA eps / (1 + (kA eps)^2) + arctan(kS eps)]  (Polach 2005)
    (Fx, Fy) = -F (sx, sy) / s_C

and the spin's lateral force (Polach 1999)

    eps_M = 8/3 G b sqrt(a b) c23 s_C / (Q mu (1 + 6.3 (1 - exp(-a/b))))
    delta = (eps_M^2 - 1) / (eps_M^2 + 1)
    K_M   = |eps_M| (delta^3/3 - delta^2/2 + 1/6) - 1/3 sqrt((1 - delta^2)^3)
    Fy_S  = 9/16 a Q mu K_M (1 + 6.3 (1 - exp(-a/b))) psi / s_C,

``K_M <= 0`` (``-2/3 |eps_M|`` for small ``eps_M``, 0 for large), so that
with the creep force's sign (opposing the creepage) ``Fy`` gains ``Fy_S``
as written: in the linear range ``Fx = -G a b c11 sx``, ``Fy = -G a b c22
sy - G (ab)^1.5 c23 psi``, Kalker's linear theory (times ``kA + kS`` over
2 in the creepage terms: Polach's reduced initial slope), and at large
creepage ``|F| -> mu Q``.  Polach gives no spin moment: ``Mz`` is the
forces' moment about the reference point only (0 about the ellipse's
centre).

``mu`` is the friction law's coefficient at the rigid slip velocity ``w =
|V| sqrt(sx^2 + sy^2)`` (m/s), as Polach takes it.  The slip share
reported is Kalker's simplified theory on a strip with the parabolic bound:
the slip zone's share ``min(1, eps / 2)`` of the length.

Imports numpy, :mod:`~fastsim_ros.contact.checks`, ``compiled`` (its
equivalent-ellipse kernel and error words), ``errors``, ``friction`` and
``tables``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from fastsim_ros.contact import kernels as k
from fastsim_ros.contact.checks import Bound, check_bound
from fastsim_ros.contact.compiled import ContactForces, _per_item, _raise, _readonly, _Solver
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.friction import FrictionLaw, check_speed, resolve
from fastsim_ros.contact.slope_reduction import rigid_slip_velocity
from fastsim_ros.contact.tables import coefficient_table

FloatArray = NDArray[np.float64]

__all__ = ["PolachSolver", "polach_forces", "PolachForces"]


def check_reduction_factors(k_a: float, k_s: float) -> None:
    """Refuse Polach's factors outside ``0 < kS <= kA <= 1``."""
    if not (math.isfinite(k_a) and math.isfinite(k_s) and 0.0 < k_s <= k_a <= 1.0):
        raise InvalidInputError(f"Polach's reduction factors must satisfy 0 < kS <= kA <= 1, "
                                f"got kA = {k_a}, kS = {k_s}")


@dataclass(frozen=True)
class PolachForces:
    """Polach's forces at the ellipse's centre: ``fx``, ``fy`` (N); ``slip_fraction`` (1)."""

    fx: float
    fy: float
    slip_fraction: float


def polach_forces(a: float, b: float, load: float, c11: float, c22: float, c23: float,
                  shear_modulus: float, mu: float, sx: float, sy: float, psi: float, *,
                  k_a: float = 1.0, k_s: float = 1.0) -> PolachForces:
    """Return Polach's creep forces (module docstring) at the ellipse's centre.

    ``a, b`` (m), ``load`` (N), ``c11, c22, c23`` Kalker's coefficients,
    ``shear_modulus`` (Pa), ``mu`` the friction coefficient, creepages
    ``sx, sy`` (1) and spin ``psi`` (1/m) at the centre; ``k_a``, ``k_s``
    Polach's reduction factors (1: Kalker's full slope).
    """
    sy_c = sy + psi * a
    if abs(sy_c) <= abs(sy):
        sy_c = sy
    s_c = math.hypot(sx, sy_c)
    if s_c == 0.0 or load <= 0.0:
        return PolachForces(0.0, 0.0, 0.0)
    stiffness = 0.375 * shear_modulus / a * math.hypot(c11 * sx / s_c, c22 * sy_c / s_c)
    eps = 2.0 / 3.0 * stiffness * math.pi * a * a * b * s_c / (load * mu)
    ka_eps = k_a * eps
    force = 2.0 * load * mu / math.pi * (ka_eps / (1.0 + ka_eps * ka_eps)
                                         + math.atan(k_s * eps))
    fx = -force * sx / s_c
    fy = -force * sy / s_c
    if psi != 0.0:
        shape = 1.0 + 6.3 * (1.0 - math.exp(-a / b))
        eps_m = (8.0 / 3.0 * shear_modulus * b * math.sqrt(a * b) * c23 * s_c
                 / (load * mu * shape))
        e2 = eps_m * eps_m
        delta = (e2 - 1.0) / (e2 + 1.0)
        k_m = (abs(eps_m) * (delta ** 3 / 3.0 - delta * delta / 2.0 + 1.0 / 6.0)
               - math.sqrt(max(1.0 - delta * delta, 0.0) ** 3) / 3.0)
        fy += 9.0 / 16.0 * a * load * mu * k_m * shape * psi / s_c
    return PolachForces(fx, fy, min(1.0, 0.5 * eps))


class PolachSolver(_Solver):
    """Polach's method on the patch's equivalent ellipse, with the fast solvers' calls.

    ``nu``: combined Poisson ratio (the tables' range); ``shear_modulus``:
    combined ``G`` (Pa); ``k_a``, ``k_s``: Polach's reduction factors ``0 <
    kS <= kA <= 1`` (1, 1: Kalker's slope, a clean rail).  The ellipse is the
    equivalent-ellipse method's (the patch's area, centroid and second-moment
    ratio), its load the patch's.  ``bound`` is accepted for the common call
    and does not act: Polach's closed form is that of a Hertzian ellipse.
    No traction field (``tractions=True`` is refused).  ``friction``: the
    law, taken at the rigid slip velocity (``speed = |V|`` in m/s for a
    slip-dependent one); a law's slope reduction is refused (Polach's own
    is ``k_a``, ``k_s``).  The calls are those of
    :class:`~fastsim_ros.contact.compiled.MaeSolver`; a batch is solved item
    by item.
    """

    def __init__(self, nu: float, shear_modulus: float, *, k_a: float = 1.0,
                 k_s: float = 1.0) -> None:
        super().__init__(nu, shear_modulus)
        check_reduction_factors(k_a, k_s)
        self.table = coefficient_table(float(nu))
        self.k_a, self.k_s = float(k_a), float(k_s)

    def _reducing(self, p: FloatArray, x0: float, y0: float, dx: float, dy: float, xi: float,
                  eta: float, phi: float, mu: float | None, friction: FrictionLaw | None,
                  speed: float | None, reference: tuple[float, float], bound: str,
                  tractions: bool) -> ContactForces:
        """Solve one patch (Polach's closed form, no slope reduction but his own)."""
        if tractions:
            raise InvalidInputError("Polach's method gives forces only, no traction field")
        check_bound(bound)
        law = resolve(mu, friction)
        if law.reduces_slope:
            raise InvalidInputError("Polach's method reduces its slope with its own kA, kS: "
                                    "a friction law's slope reduction is for the FastSim "
                                    "methods")
        for name, v in (("xi", xi), ("eta", eta), ("phi", phi)):
            if not math.isfinite(float(v)):
                raise InvalidInputError("creepages xi, eta, phi must be finite")
        ell = np.empty(k.ELL_SIZE)
        status, info = k.equivalent_prepare(p, float(x0), float(y0), float(dx), float(dy),
                                            self.shear_modulus, self._knots, self._polys, ell)
        if status:
            _raise(status, info, self._knots)
        x_c, y_c = float(ell[k.ELL_XC]), float(ell[k.ELL_YC])
        a, b, load = float(ell[k.ELL_A]), float(ell[k.ELL_B]), float(ell[k.ELL_LOAD])
        # the creepages at the ellipse's centre (rigid slip of the spin about the reference)
        xr, yr = float(reference[0]), float(reference[1])
        sx = float(xi) - float(phi) * (y_c - yr)
        sy = float(eta) + float(phi) * (x_c - xr)
        mu_eff = law.mu_s
        if law.slip_dependent:
            mu_eff = float(law.mu(rigid_slip_velocity(sx, sy, check_speed(speed))))
        c11, c22, c23 = self.table.kalker(a / b)
        f = polach_forces(a, b, load, c11, c22, c23, self.shear_modulus, mu_eff, sx, sy,
                          float(phi), k_a=self.k_a, k_s=self.k_s)
        # Polach's forces act at the centre, with no spin moment of their own
        mz = (x_c - xr) * f.fy - (y_c - yr) * f.fx
        return ContactForces(f.fx, f.fy, mz, load, f.slip_fraction)

    def _batch(self, ps: FloatArray, grid: list[FloatArray], cr: FloatArray,
               mu: ArrayLike | None, reference: tuple[float, float], bound: Bound,
               friction: FrictionLaw | None, speed: ArrayLike | None) -> FloatArray:
        """Solve the checked batch item by item (a closed form each: no compiled loop)."""
        size = cr.shape[0]
        mus = None if mu is None else _per_item(mu, size, "mu")
        speeds = None if speed is None else _per_item(speed, size, "speed")
        out = np.empty((size, 3))
        for i in range(size):
            f = self._reducing(_readonly(ps[0] if ps.shape[0] == 1 else ps[i]),
                               grid[0][i], grid[1][i], grid[2][i], grid[3][i],
                               cr[i, 0], cr[i, 1], cr[i, 2],
                               None if mus is None else float(mus[i]), friction,
                               None if speeds is None else float(speeds[i]), reference,
                               bound, False)
            out[i] = f.fx, f.fy, f.mz
        return out
