"""Friction laws as values: the friction coefficient as a function of the local slip velocity.

A law gives ``mu(v)`` (dimensionless) at the local slip velocity ``v`` (m/s,
``v = |V| |s|`` with ``V`` the rolling speed in m/s and ``s`` the local slip
per unit rolling distance, dimensionless).  Every law here is written as

    mu(v) = mu_s * ratio(v),     ratio(0) = 1,

``mu_s`` the static coefficient (what the solvers' ``mu`` argument and the
node's ``friction_coefficient`` give), so a solver applies a law to the
traction bound it already has (``g_s = mu_s p``, or the parabolic one) as
``g(v) = g_s ratio(v)``.

The solvers see a law only through:

- :attr:`FrictionLaw.code` and :attr:`FrictionLaw.params`: a small integer and
  a float array, what the compiled kernels take
  (:func:`fastsim_ros.contact.kernels.law_ratio` evaluates them);
- :meth:`FrictionLaw.ratio` and :meth:`FrictionLaw.ratio_slope` (numpy), what
  the readable reference and the exact solver take.

Adding a law is a class here and one branch in ``kernels.law_ratio``; the
solvers do not change.  FastSim evaluates ``ratio`` once per slipping cell
(:func:`fastsim_ros.contact.fastsim.slip_ratio`: no equation to solve, any
law will do); the exact solver's Newton also takes ``ratio_slope``.

A law may carry a creep-slope reduction (``reduction``,
:class:`~fastsim_ros.contact.slope_reduction.SlopeReduction`: the modified
FastSim of Spiryagin et al.): :meth:`FrictionLaw.reduced` gives the factor
``k`` on the creepages and the one friction coefficient, at the rigid slip
velocity, that a solve then runs with.  Without one, or with ``k = 1``
throughout, the solvers run as without it, bit for bit.

With ``A = 1`` or ``B = 0`` the exponential law *is* the constant one:
:class:`ExponentialFriction` then reports :data:`LAW_CONSTANT`, so every
solver runs the constant-friction path and gives its numbers bit for bit.

Imports numpy, :mod:`~fastsim_ros.contact.checks`, ``errors``, ``rules`` and
``slope_reduction`` (no SciPy).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from fastsim_ros.contact.checks import check_friction
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.rules import LAW_CONSTANT, LAW_EXPONENTIAL
from fastsim_ros.contact.slope_reduction import (SlopeReduction, rigid_slip_velocity,
                                                 total_creepage)

FloatArray = NDArray[np.float64]

__all__ = ["LAW_CONSTANT", "LAW_EXPONENTIAL", "LAW_NAMES", "FrictionLaw", "ConstantFriction",
           "ExponentialFriction", "friction_law", "resolve", "check_exponential",
           "check_speed", "SlopeReduction"]
#: the names the node, the replay and the command line use
LAW_NAMES = ("constant", "exponential")


def check_exponential(mu_s: float, limit_ratio: float, decay: float) -> None:
    """Refuse parameters of the exponential law: ``mu_s > 0``, ``0 < A <= 1``, ``B >= 0`` (s/m)."""
    check_friction(mu_s)
    if not (math.isfinite(limit_ratio) and 0.0 < limit_ratio <= 1.0):
        raise InvalidInputError(f"friction limit ratio A must lie in (0, 1], got {limit_ratio}")
    if not (math.isfinite(decay) and decay >= 0.0):
        raise InvalidInputError(f"friction decay B must be finite and >= 0 s/m, got {decay}")


def check_speed(speed: float | None) -> float:
    """Return the rolling speed ``|V|`` (m/s); refuse a missing, negative or non-finite one."""
    if speed is None:
        raise InvalidInputError("a slip-dependent friction law needs the rolling speed "
                                "(speed=|V| in m/s)")
    v = float(speed)
    if not (math.isfinite(v) and v >= 0.0):
        raise InvalidInputError(f"rolling speed |V| must be finite and >= 0 m/s, got {speed}")
    return v


@dataclass(frozen=True)
class FrictionLaw:
    """Base of the laws: ``mu(v) = mu_s ratio(v)``, ``v`` the local slip velocity (m/s).

    ``reduction``: the creep-slope reduction of a contaminated rail (None:
    the theory's full slope).
    """

    mu_s: float
    reduction: SlopeReduction | None = field(default=None, kw_only=True)

    #: the law's name (``friction_law`` of the node, the CSV and the command line)
    name = "constant"

    @property
    def code(self) -> int:
        """Return the law's number in the kernels (:data:`LAW_CONSTANT` if independent of v)."""
        return LAW_CONSTANT

    @property
    def params(self) -> FloatArray:
        """Return the kernels' parameter array of ``ratio`` (length 2: unused slots are 0)."""
        return np.zeros(2)

    @property
    def slip_dependent(self) -> bool:
        """Tell whether ``mu`` depends on the slip velocity (then the solvers need ``|V|``)."""
        return self.code != LAW_CONSTANT

    def ratio(self, v: ArrayLike) -> FloatArray:
        """Return ``mu(v)/mu_s`` at slip velocities ``v`` (m/s)."""
        return np.ones_like(np.asarray(v, dtype=np.float64))

    def ratio_slope(self, v: ArrayLike) -> FloatArray:
        """Return ``d ratio/dv`` (s/m) at slip velocities ``v`` (m/s)."""
        return np.zeros_like(np.asarray(v, dtype=np.float64))

    def mu(self, v: ArrayLike) -> FloatArray:
        """Return the friction coefficient at slip velocities ``v`` (m/s)."""
        return self.mu_s * self.ratio(v)

    @property
    def reduces_slope(self) -> bool:
        """Tell whether the law carries a slope reduction other than ``k = 1`` throughout."""
        return self.reduction is not None and not self.reduction.identity

    def reduced(self, xi: float, eta: float, phi: float, speed: float | None, *, a: float,
                b: float, c11: float, shear_modulus: float,
                load: float) -> tuple[float, float]:
        """Return ``(k, mu)``: the factor on the creepages and the solve's friction coefficient.

        ``mu`` is the law's at the rigid slip velocity ``|V| sqrt(xi^2 +
        eta^2)`` (``speed = |V|`` in m/s, needed by a slip-dependent law),
        ``k`` the reduction's factor there
        (:meth:`~fastsim_ros.contact.slope_reduction.SlopeReduction.factor`)
        on the equivalent ellipse ``a, b`` (m) with Kalker's ``c11``, the
        combined ``shear_modulus`` (Pa) and the patch's ``load`` (N).
        """
        reduction = self.reduction if self.reduction is not None else SlopeReduction()
        mu = self.mu_s
        if self.slip_dependent:
            mu = float(self.mu(rigid_slip_velocity(xi, eta, check_speed(speed))))
        k = reduction.factor(total_creepage(xi, eta, phi, a), a=a, b=b, c11=c11,
                             shear_modulus=shear_modulus, load=load, mu=mu)
        return k, mu


@dataclass(frozen=True)
class ConstantFriction(FrictionLaw):
    """Coulomb friction with one coefficient ``mu`` (the default law); ``mu > 0``."""

    def __post_init__(self) -> None:
        check_friction(self.mu_s)


@dataclass(frozen=True)
class ExponentialFriction(FrictionLaw):
    """Falling friction ``mu(v) = mu_s ((1 - A) exp(-B v) + A)``.

    ``mu_s > 0`` the static coefficient (``v = 0``), ``limit_ratio`` ``A`` in
    ``(0, 1]`` the ratio ``mu(inf)/mu_s``, ``decay`` ``B >= 0`` in s/m (the
    law's rate of decay with the slip velocity ``v`` in m/s).  ``A = 1`` or
    ``B = 0`` is constant friction ``mu_s`` (and runs as such).
    """

    limit_ratio: float = 1.0
    decay: float = 0.0
    name = "exponential"
    _params: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        check_exponential(self.mu_s, self.limit_ratio, self.decay)
        object.__setattr__(self, "_params", np.array([self.limit_ratio, self.decay]))

    @property
    def code(self) -> int:
        """:data:`LAW_EXPONENTIAL`, or :data:`LAW_CONSTANT` when ``A = 1`` or ``B = 0``."""
        if self.limit_ratio == 1.0 or self.decay == 0.0:
            return LAW_CONSTANT
        return LAW_EXPONENTIAL

    @property
    def params(self) -> FloatArray:
        """Return ``[A, B]`` (1, s/m)."""
        return self._params.copy()

    def ratio(self, v: ArrayLike) -> FloatArray:
        """Return ``(1 - A) exp(-B v) + A``; exactly 1 when the law is constant."""
        v = np.asarray(v, dtype=np.float64)
        if self.code == LAW_CONSTANT:
            return np.ones_like(v)
        a = self.limit_ratio
        return (1.0 - a) * np.exp(-self.decay * v) + a

    def ratio_slope(self, v: ArrayLike) -> FloatArray:
        """Return ``-(1 - A) B exp(-B v)`` (s/m)."""
        v = np.asarray(v, dtype=np.float64)
        if self.code == LAW_CONSTANT:
            return np.zeros_like(v)
        return -(1.0 - self.limit_ratio) * self.decay * np.exp(-self.decay * v)


def friction_law(name: str, mu_s: float, *, limit_ratio: float = 1.0,
                 decay: float = 0.0, reduction: SlopeReduction | None = None) -> FrictionLaw:
    """Return the law called ``name`` (:data:`LAW_NAMES`) with its parameters checked.

    ``reduction``: the creep-slope reduction it carries (None: none).
    """
    if name == "constant":
        return ConstantFriction(mu_s, reduction=reduction)
    if name == "exponential":
        return ExponentialFriction(mu_s, limit_ratio, decay, reduction=reduction)
    raise InvalidInputError(f"unknown friction law {name!r}: constant or exponential")


def resolve(mu: float | None, friction: FrictionLaw | None) -> FrictionLaw:
    """Return the law of a solve: ``friction``, or ``ConstantFriction(mu)`` when it is None.

    With both given, ``mu`` must be the law's ``mu_s`` (one value, never two
    that disagree silently).
    """
    if friction is None:
        if mu is None:
            raise InvalidInputError("give mu or a friction law")
        return ConstantFriction(float(mu))
    if not isinstance(friction, FrictionLaw):
        raise InvalidInputError(f"friction must be a friction law, got {friction!r}")
    if mu is not None and float(mu) != friction.mu_s:
        raise InvalidInputError(f"mu = {mu} differs from the friction law's mu_s = "
                                f"{friction.mu_s}")
    return friction
