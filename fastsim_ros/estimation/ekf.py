"""Recursive estimation of the static friction coefficient: an extended Kalman filter.

State: ``mu_s`` (dimensionless), a random walk ``d mu_s = w``, ``E[w^2] =
q dt`` (``q``, :attr:`FrictionEkf.process_noise`, in 1/s: how fast ``mu_s``
may change).  Measurement: ``z = h(mu_s) + v``, ``h`` the package's solver
summed over the cycle's contacts and projected on the measured components
(:class:`~fastsim_ros.estimation.model.CreepModel`), ``v`` the load cell's
noise of standard deviation :attr:`FrictionEkf.measurement_noise` (N).
The slope ``H = dh/dmu_s`` is a forward difference with the step
``relative_step * mu_s``: one solve per contact beyond the one at the prior
(which the caller may pass: the published forces are that solve).

Observability.  With constant friction FastSim's forces are homogeneous,
``F(mu, c) = mu F(1, c/mu)``, so ``dF/dmu = (F - c . dF/dc)/mu``: zero in
full adhesion (``F`` linear in the creepages ``c``), ``F/mu = N``-sized in
full slip.  The dimensionless sensitivity

    r = |H| / N     (N the cycle's total normal load)

measures it: with ``F = mu N f(s)``, ``s`` the creepage over its saturation
value, ``r = f - s f'``: about ``s^2/3`` for ``f = s - s^2/3 + s^3/27``
(small ``s``: the linear range) and 1 in full slip.  Below
:attr:`FrictionEkf.min_sensitivity` the update is skipped (the step says
why): the estimate holds exactly and its variance grows by ``q dt`` per
cycle (bounded by :attr:`FrictionEkf.sigma_max`), instead of a gain
``K ~ 1/H`` that would turn load-cell noise into a drifting ``mu``.  Above
it the Kalman gain weighs the information as usual; the estimate is kept in
:attr:`FrictionEkf.mu_bounds`.

Steps of mu (dry -> wet rail).  A random walk slow enough for a quiet
estimate follows a step only slowly; so an innovation beyond
:attr:`FrictionEkf.step_gate` standard deviations of its prediction (``|z -
h| > gate sqrt(S)``, ``S = H P H + R``) is taken as a change of the rail:
the variance grows by the square of the step it implies, ``(|z - h| /
|H|)^2``, before the gain is computed, so the estimate jumps to the new
level within a cycle and then averages the noise down again.  With a 4-sigma
gate, noise alone opens it once in some 16,000 cycles.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from fastsim_ros.contact.errors import InvalidInputError

FloatArray = NDArray[np.float64]

#: why an update was or was not made (:attr:`EkfStep.status`)
UPDATED, UNOBSERVABLE = "updated", "unobservable"


@dataclass(frozen=True)
class EkfStep:
    """One update: prior and posterior ``mu_s`` and sigma, slope, sensitivity, innovation.

    ``slope``: ``H = dh/dmu_s`` (N per unit mu, per measured component);
    ``sensitivity``: ``r = |H| / N``; ``innovation``: ``z - h(mu_prior)``
    (N); ``status``: :data:`UPDATED` or :data:`UNOBSERVABLE` (update skipped);
    ``step_seen``: the innovation opened the step gate.
    """

    status: str
    mu_prior: float
    sigma_prior: float
    mu: float
    sigma: float
    slope: tuple[float, ...]
    sensitivity: float
    innovation: tuple[float, ...]
    step_seen: bool = False


def _floats(values: ArrayLike) -> tuple[float, ...]:
    """Return a scalar or a 1-D sequence of numbers as a tuple of floats."""
    if isinstance(values, (list, tuple)):
        return tuple(float(v) for v in values)
    return tuple(np.asarray(values, dtype=np.float64).ravel().tolist())


def _positive(name: str, value: float, *, zero_ok: bool = False) -> float:
    v = float(value)
    if not (math.isfinite(v) and (v >= 0.0 if zero_ok else v > 0.0)):
        raise InvalidInputError(f"{name} must be finite and {'>=' if zero_ok else '>'} 0, "
                                f"got {value}")
    return v


class FrictionEkf:
    """Extended Kalman filter on ``mu_s``; see the module's docstring for the model.

    ``mu``: initial estimate; ``sigma``: its standard deviation;
    ``process_noise``: ``q`` (1/s), the variance of ``mu_s`` added per second;
    ``measurement_noise``: standard deviation of each measured component (N);
    ``min_sensitivity``: the observability threshold on ``r``;
    ``mu_bounds``: the estimate is clamped to it; ``sigma_max``: the largest
    standard deviation (what "nothing known" means); ``relative_step``: the
    forward difference's step relative to ``mu_s``; ``step_gate``: the
    innovation (in its standard deviations) taken as a step of mu (``inf``:
    never).
    """

    def __init__(self, mu: float, sigma: float, *, process_noise: float,
                 measurement_noise: float, min_sensitivity: float = 0.02,
                 mu_bounds: tuple[float, float] = (0.01, 2.0), sigma_max: float = 1.0,
                 relative_step: float = 0.01, step_gate: float = 4.0) -> None:
        lo, hi = (float(v) for v in mu_bounds)
        if not (0.0 < lo < hi and math.isfinite(hi)):
            raise InvalidInputError(f"mu_bounds must satisfy 0 < low < high, got {mu_bounds}")
        self.mu_bounds = (lo, hi)
        self.mu = min(max(_positive("mu", mu), lo), hi)
        self.sigma_max = _positive("sigma_max", sigma_max)
        self.variance = min(_positive("sigma", sigma), self.sigma_max) ** 2
        self.process_noise = _positive("process_noise", process_noise, zero_ok=True)
        self.measurement_noise = _positive("measurement_noise", measurement_noise)
        self.min_sensitivity = _positive("min_sensitivity", min_sensitivity, zero_ok=True)
        self.relative_step = _positive("relative_step", relative_step)
        self.step_gate = _positive("step_gate", step_gate) if step_gate != math.inf \
            else math.inf
        self.updates = 0
        self.skipped = 0
        self.steps = 0

    @property
    def sigma(self) -> float:
        """Return the standard deviation of the estimate."""
        return math.sqrt(self.variance)

    def predict(self, dt: float) -> None:
        """Advance by ``dt`` seconds: the variance grows by ``q dt`` (up to ``sigma_max^2``)."""
        dt = _positive("dt", dt, zero_ok=True)
        self.variance = min(self.variance + self.process_noise * dt, self.sigma_max ** 2)

    def update(self, measured: ArrayLike, model: Callable[[float], ArrayLike], load: float,
               predicted: ArrayLike | None = None) -> EkfStep:
        """Take one measurement ``measured`` (N, ``(m,)``) of the model ``model(mu_s)`` (N).

        ``load``: the cycle's total normal load (N, for the sensitivity);
        ``predicted``: ``model(self.mu)`` if already known (saves a solve).
        """
        z = _floats(measured)
        load = _positive("load", load)
        if not all(math.isfinite(v) for v in z):
            raise InvalidInputError("measured forces must be finite")
        mu0, var0 = self.mu, self.variance
        sigma0 = math.sqrt(var0)
        h0 = _floats(model(mu0) if predicted is None else predicted)
        if len(h0) != len(z):
            raise InvalidInputError(f"model gives {len(h0)} components, measured {len(z)}")
        step = self.relative_step * mu0
        if mu0 + step > self.mu_bounds[1]:
            step = -step  # stay inside the range the solver is asked about
        h1 = _floats(model(mu0 + step))
        slope = tuple((b - a) / step for a, b in zip(h0, h1))
        innovation = tuple(a - b for a, b in zip(z, h0))
        h2 = math.fsum(v * v for v in slope)
        sensitivity = math.sqrt(h2) / load
        if not sensitivity >= self.min_sensitivity:
            self.skipped += 1
            return EkfStep(UNOBSERVABLE, mu0, sigma0, mu0, sigma0, slope, sensitivity,
                           innovation)
        r = self.measurement_noise ** 2
        hv = math.fsum(a * b for a, b in zip(slope, innovation))
        # the innovation's size in its predicted standard deviations (along H)
        nis = hv * hv / h2 / (var0 * h2 + r)
        step_seen = nis > self.step_gate ** 2
        if step_seen:  # the rail changed: what the innovation implies of mu is unknown
            var0 = min(var0 + hv * hv / (h2 * h2), self.sigma_max ** 2)
            self.steps += 1
        # scalar state, isotropic R = r I: S = P H H^T + r I, so S^-1 H = H / (P |H|^2 + r)
        # (Sherman-Morrison) and K = P H / (P |H|^2 + r); Joseph form for the variance
        denominator = var0 * h2 + r
        kh = var0 * h2 / denominator
        mu = mu0 + var0 * hv / denominator
        self.variance = (1.0 - kh) ** 2 * var0 + r * var0 * var0 * h2 / denominator ** 2
        self.mu = min(max(mu, self.mu_bounds[0]), self.mu_bounds[1])
        self.updates += 1
        return EkfStep(UPDATED, mu0, sigma0, self.mu, self.sigma, slope, sensitivity,
                       innovation, step_seen)
