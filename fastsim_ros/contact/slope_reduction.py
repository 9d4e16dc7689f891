"""The reduced creep slope of contaminated rails: the modified FastSim's factor ``k``.

Measured adhesion curves on wet, leafy or oily rails rise far less steeply
than Kalker's theory: their initial slope is a fraction of the theory's,
and the fraction falls as the slip area grows.  The modified FastSim of
Spiryagin et al. (Spiryagin, Polach, Cole, "Creep force modelling for rail
traction vehicles based on the Fastsim algorithm", Vehicle System Dynamics
51(11), 2013), as built into CONTACT (E. Vollebregt, user guide, section
"Flexibilities of the simplified theory", equation ``k_modif_fs``),
divides the flexibilities by

    k = k0 [alpha_inf + (1 - alpha_inf) / (1 + beta eps)],

    eps = G pi a b k0 C11 w / (4 mu N),       w = sqrt(xi^2 + nu_phi^2),

``k0`` in (0, 1] the reduction at vanishing creepage, ``alpha_inf`` in
[0, 1] the ratio ``k(inf)/k0``, ``beta >= 0`` how fast ``k`` falls with
``eps`` (Polach's gradient of the tangential stress at the leading edge:
the ratio of the slip to the adhesion area); ``a, b`` (m) the semi-axes of
the patch's equivalent ellipse, ``C11`` Kalker's coefficient at its ``a/b``,
``G`` (Pa) the combined shear modulus, ``N`` (N) the load, ``mu`` the
friction coefficient at the rigid slip velocity, ``nu_phi = eta + phi a``
(unless that is smaller than ``|eta|``: then ``eta``), the total creepage
of Spiryagin et al. as CONTACT's ``fastsim_params`` computes it.

Dividing every flexibility by ``k`` is multiplying the creepages by ``k``:
FastSim's slip ``s = w - (L/k) dp/dx`` is ``k s = k w - L dp/dx``, the same
tractions.  That is how every fast method here applies it: its own solve,
at creepages ``k (xi, eta, phi)``.  As in CONTACT's modified FastSim and in
Polach's method, a slip-dependent friction law is then evaluated once, at
the rigid slip velocity ``|V| sqrt(xi^2 + eta^2)`` (m/s), and the solve
runs with that constant coefficient.

``k0 = 1`` with ``alpha_inf = 1`` (or ``beta = 0``) is no reduction: the
solvers then run their path without a reduction, bit for bit.

Imports :mod:`~fastsim_ros.contact.errors` only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fastsim_ros.contact.errors import InvalidInputError

__all__ = ["SlopeReduction", "check_slope_reduction", "total_creepage", "rigid_slip_velocity"]


def check_slope_reduction(k0: float, alpha_inf: float, beta: float) -> None:
    """Refuse parameters outside ``0 < k0 <= 1``, ``0 <= alpha_inf <= 1``, ``0 <= beta <= 1e6``."""
    if not (math.isfinite(k0) and 0.0 < k0 <= 1.0):
        raise InvalidInputError(f"slope reduction k0 must lie in (0, 1], got {k0}")
    if not (math.isfinite(alpha_inf) and 0.0 <= alpha_inf <= 1.0):
        raise InvalidInputError(f"slope reduction alpha_inf must lie in [0, 1], got {alpha_inf}")
    if not (math.isfinite(beta) and 0.0 <= beta <= 1e6):
        raise InvalidInputError(f"slope reduction beta must lie in [0, 1e6], got {beta}")


def total_creepage(xi: float, eta: float, phi: float, a: float) -> float:
    """Return Spiryagin's total creepage ``sqrt(xi^2 + nu_phi^2)``, ``nu_phi = eta + phi a``.

    ``phi`` (1/m) times the ellipse's longitudinal semi-axis ``a`` (m) is the
    lateral creepage the spin adds; where it would lessen ``|eta|``, ``eta``
    alone is taken (CONTACT's ``fastsim_params``).
    """
    nu_phi = eta + phi * a
    if abs(nu_phi) < abs(eta):
        nu_phi = eta
    return math.sqrt(xi * xi + nu_phi * nu_phi)


def rigid_slip_velocity(xi: float, eta: float, speed: float) -> float:
    """Return the rigid slip velocity ``|V| sqrt(xi^2 + eta^2)`` (m/s), ``speed = |V|`` (m/s)."""
    return speed * math.sqrt(xi * xi + eta * eta)


@dataclass(frozen=True)
class SlopeReduction:
    """The modified FastSim's slope reduction ``k0, alpha_inf, beta`` (all dimensionless)."""

    k0: float = 1.0
    alpha_inf: float = 1.0
    beta: float = 0.0

    def __post_init__(self) -> None:
        check_slope_reduction(self.k0, self.alpha_inf, self.beta)

    @property
    def identity(self) -> bool:
        """Tell whether ``k`` is 1 at every creepage (``k0 = 1`` and no fall with ``eps``)."""
        return self.k0 == 1.0 and (self.alpha_inf == 1.0 or self.beta == 0.0)

    def epsilon(self, creepage: float, *, a: float, b: float, c11: float,
                shear_modulus: float, load: float, mu: float) -> float:
        """Return ``eps = G pi a b k0 C11 w / (4 mu N)`` at total creepage ``w`` (1)."""
        return (shear_modulus * math.pi * a * b * self.k0 * c11 * creepage
                / (4.0 * mu * load))

    def factor(self, creepage: float, *, a: float, b: float, c11: float,
               shear_modulus: float, load: float, mu: float) -> float:
        """Return ``k = k0 [alpha_inf + (1 - alpha_inf) / (1 + beta eps)]`` (1).

        ``creepage``: the total creepage :func:`total_creepage` (1); ``a, b``
        (m), ``c11`` (1): the equivalent ellipse and its Kalker coefficient;
        ``shear_modulus`` (Pa), ``load`` (N) and ``mu`` at the rigid slip.
        """
        if self.identity:
            return self.k0
        eps = self.epsilon(creepage, a=a, b=b, c11=c11, shear_modulus=shear_modulus,
                           load=load, mu=mu)
        return self.k0 * (self.alpha_inf + (1.0 - self.alpha_inf) / (1.0 + self.beta * eps))
