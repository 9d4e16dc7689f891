"""Recursive estimation of the static friction coefficient: an extended Kalman filter.

State: ``mu_s`` (dimensionless), a random walk ``d mu_s = w``, ``E[w^2] =
q dt`` (``q``, :attr:`FrictionEkf.process_noise`, in 1/s: how fast ``mu_s``
may change).  Measurement: ``z = h(mu_s) + b + v``, ``h`` the package's
solver summed over the cycle's contacts and projected on the measured
components (:class:`~fastsim_ros.estimation.model.CreepModel`), ``v`` the
load cell's noise of standard deviation :attr:`FrictionEkf.measurement_noise`
(N, white), ``b`` the model's own error against the rail (N, of scale ``s``
given with each measurement, see below: not white).  The slope ``H =
dh/dmu_s`` is the model's own derivative where it has one (the MAE
solvers: the march differentiated, one march per contact), else a forward
difference with the step ``relative_step * mu_s``: one solve per contact
beyond the one at the prior (which the caller may pass: the published
forces are that solve).

Observability.  With constant friction FastSim's forces are homogeneous,
``F(mu, c) = mu F(1, c/mu)``, so ``dF/dmu = (F - c . dF/dc)/mu``: zero in
full adhesion (``F`` linear in the creepages ``c``), ``F/mu = N``-sized in
full slip.  The dimensionless sensitivity::

    r = |H| / N     (N the cycle's total normal load)

measures it: with ``F = mu N f(s)``, ``s`` the creepage over its saturation
value, ``r = f - s f'``: about ``s^2/3`` for ``f = s - s^2/3 + s^3/27``
(small ``s``: the linear range) and 1 in full slip.  Below
:attr:`FrictionEkf.min_sensitivity` the update is skipped (the step says
why): the estimate holds exactly and its variance grows by ``q dt`` per
cycle (bounded by :attr:`FrictionEkf.sigma_max`), instead of a gain
``K ~ 1/H`` that would turn load-cell noise into a drifting ``mu``.  Above
it the gain weighs the information (below); the estimate is kept in
:attr:`FrictionEkf.mu_bounds`.

The model's error.  The fast method is not the exact theory: against it
(docs/validation_estimation.md) the creep force is off by up to some 6% of
``mu N`` at the knee of the curve, and that error is systematic (the same
creepage gives the same error, cycle after cycle), not noise: a filter that
took it for noise would average it down, report a sigma far too small, and
read a force error ``db`` as a friction error ``db / H``, largest where the
slope ``H`` is small.  Its scale ``s`` (N, one sigma) comes with each
measurement (:func:`~fastsim_ros.estimation.model.model_error`: the traction
bound times the load on the model's adhesion area, a share of it), and the
filter carries two parts of its uncertainty: ``P`` the variance from noise
(averages down, grows by ``q dt``) and ``c`` a bound on the error from the
model (mu units; any correlation and sign between cycles: it never averages
down below the samples' own).  The reported ``sigma = sqrt(P + c^2)``.  In
``mu`` units a cycle implies the correction ``d = H.y / |H|^2`` (``y = z -
h(mu)`` the innovation) with noise ``n' = sigma_v / |H|`` and model error
``s' = s / |H|``; an update with the scalar gain ``g = K H`` gives

    mu+ = mu + g d,   P+ = (1 - g)^2 P + g^2 n'^2,   c+ = (1 - g) c + g s'

(the bound by the triangle inequality: the old error and the new sample's
may add), and ``g`` minimises ``P+ + c+^2``:

    g = (P + c (c - s')) / (P + n'^2 + (c - s')^2),   clipped to [0, 1].

With ``s = 0`` and ``c = 0`` this is the Kalman gain ``P H^2 / (P H^2 +
sigma_v^2)`` and the Joseph-form variance.  Repeated cycles at one operating
point average the noise (``g -> P / (P + n'^2)``) while ``c`` settles on
that point's ``s'``; a cycle whose model error is smaller than the
estimate's (``s' < c``) pulls it harder; one whose error is larger (``s' >
c + P / c``: the knee, partial slip, where ``H`` is small) moves it little
or not at all.  So the estimate leans on the samples the model gets right
(full slip) and its sigma states what the model can be trusted to.

Steps of mu (dry -> wet rail).  A random walk slow enough for a quiet
estimate follows a step only slowly; so an innovation beyond
:attr:`FrictionEkf.step_gate` standard deviations of its noise plus the
model's bounds (``|d| > gate sqrt(P + n'^2) + 2 (c + s')``) is taken as a
change of the rail: the
variance grows by the square of the step it implies, ``d^2``, before the
gain is computed, so the estimate jumps to the new level within a cycle and
then averages the noise down again; the sample's model error is then the
model's at the new level (``model_error_at(mu + d)``).  The gate adds the
model error's bounds (:data:`MODEL_BOUND_SIGMAS` times ``c`` and ``s'``:
an error the model may make is no evidence of a step) to ``gate`` standard
deviations of the noise.  With a 4-sigma gate, noise alone opens
it once in some 16,000 cycles.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from fastsim_ros.contact.errors import InvalidInputError

FloatArray = NDArray[np.float64]

#: why an update was or was not made (:attr:`EkfStep.status`)
UPDATED, UNOBSERVABLE = "updated", "unobservable"
#: the model's error is at most this many of its scales s (the bound taken as two sigma)
MODEL_BOUND_SIGMAS = 2.0
#: a sensitivity r at or below this is none, even with min_sensitivity 0: dividing by a
#: slope of zero (full adhesion, no contact) gave an infinite correction (1)
NO_SENSITIVITY = 1e-12


class EkfStep(NamedTuple):
    """One update: prior and posterior ``mu_s`` and sigma, slope, sensitivity, innovation.

    ``slope``: ``H = dh/dmu_s`` (N per unit mu, per measured component);
    ``sensitivity``: ``r = |H| / N``; ``innovation``: ``z - h(mu_prior)``
    (N); ``status``: :data:`UPDATED` or :data:`UNOBSERVABLE` (update skipped);
    ``step_seen``: the innovation opened the step gate; ``gain``: ``g = K H``
    (0 when skipped); ``model_bound``: ``c`` after the update (mu units).
    A named tuple: one per rig cycle, it must cost little.
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
    gain: float = 0.0
    model_bound: float = 0.0


def _floats(values: ArrayLike) -> tuple[float, ...]:
    """Return a scalar or a 1-D sequence of numbers as a tuple of floats."""
    if isinstance(values, (list, tuple)):
        if len(values) == 1:
            return (float(values[0]),)
        return tuple(float(v) for v in values)
    return tuple(np.asarray(values, dtype=np.float64).ravel().tolist())


def _positive(name: str, value: float, *, zero_ok: bool = False) -> float:
    v = float(value)
    if not (math.isfinite(v) and (v >= 0.0 if zero_ok else v > 0.0)):
        raise InvalidInputError(f"{name} must be finite and {'>=' if zero_ok else '>'} 0, "
                                f"got {value}")
    return v


class _Tuning:
    """The tuning both filters share, checked, and their counts of updates, skips and steps."""

    def __init__(self, measurement_noise: float, min_sensitivity: float, relative_step: float,
                 step_gate: float) -> None:
        self.measurement_noise = _positive("measurement_noise", measurement_noise)
        self.min_sensitivity = _positive("min_sensitivity", min_sensitivity, zero_ok=True)
        self.relative_step = _positive("relative_step", relative_step)
        self.step_gate = (_positive("step_gate", step_gate) if step_gate != math.inf
                          else math.inf)
        self.updates = 0
        self.skipped = 0
        self.steps = 0


class FrictionEkf(_Tuning):
    """Extended Kalman filter on ``mu_s``; see the module's docstring for the model.

    ``mu``: initial estimate; ``sigma``: its standard deviation;
    ``process_noise``: ``q`` (1/s), the variance of ``mu_s`` added per second;
    ``measurement_noise``: standard deviation of each measured component (N);
    ``min_sensitivity``: the observability threshold on ``r``;
    ``mu_bounds``: the estimate is clamped to it; ``sigma_max``: the largest
    standard deviation (what "nothing known" means); ``relative_step``: the
    forward difference's step relative to ``mu_s``; ``step_gate``: the
    innovation (in its standard deviations) taken as a step of mu (``inf``:
    never).  :attr:`variance` is the noise part ``P`` of the estimate's
    variance, :attr:`model_bound` the model part's bound ``c``.
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
        self.model_bound = 0.0
        self.process_noise = _positive("process_noise", process_noise, zero_ok=True)
        super().__init__(measurement_noise, min_sensitivity, relative_step, step_gate)

    def restart(self, sigma: float, mu: float | None = None) -> None:
        """Start again from ``mu`` (None: the estimate as it is) with standard deviation ``sigma``.

        An operator's new prior (a run-time ``friction_coefficient`` or
        ``friction_estimate_sigma``): the noise part is ``sigma^2`` (at most
        ``sigma_max^2``), the model's bound is dropped, the counts stay.
        """
        lo, hi = self.mu_bounds
        if mu is not None:
            self.mu = min(max(_positive("mu", mu), lo), hi)
        self.variance = min(_positive("sigma", sigma), self.sigma_max) ** 2
        self.model_bound = 0.0

    @property
    def sigma(self) -> float:
        """Return the standard deviation of the estimate, ``sqrt(P + c^2)``."""
        return math.sqrt(self.variance + self.model_bound * self.model_bound)

    def predict(self, dt: float) -> None:
        """Advance by ``dt`` seconds: ``P`` grows by ``q dt`` (the total up to ``sigma_max^2``)."""
        if not (dt >= 0.0 and math.isfinite(dt)):
            dt = _positive("dt", dt, zero_ok=True)  # raises
        self.variance = min(self.variance + self.process_noise * dt,
                            max(self.sigma_max ** 2 - self.model_bound ** 2, 0.0))

    def update(self, measured: ArrayLike, model: Callable[[float], ArrayLike], load: float,
               predicted: ArrayLike | None = None, model_error: float = 0.0,
               model_error_at: Callable[[float], float] | None = None,
               slope_at: Callable[[float], ArrayLike] | None = None) -> EkfStep:
        """Take one measurement ``measured`` (N, ``(m,)``) of the model ``model(mu_s)`` (N).

        ``load``: the cycle's total normal load (N, for the sensitivity);
        ``predicted``: ``model(self.mu)`` if already known (saves a solve);
        ``model_error``: ``s``, the scale (N, one sigma, each component) of
        the model's error at the prior (0: the model taken as exact);
        ``model_error_at``: ``s`` at another ``mu_s``, asked once when a
        step of mu is seen (the sample's error is the model's at the new
        level, ``mu + d``, not at the prior's: a wet prior in full slip
        knows nothing of a dry rail's knee);
        ``slope_at``: ``dh/dmu_s`` (N) at a ``mu_s``, if the model knows it
        (:meth:`~fastsim_ros.estimation.model.CreepModel.slope`: one march
        per contact, in place of the forward difference's second solve).
        """
        z = _floats(measured)
        if not (load > 0.0 and math.isfinite(load)):
            load = _positive("load", load)
        if not (model_error >= 0.0 and math.isfinite(model_error)):
            model_error = _positive("model_error", model_error, zero_ok=True)
        s = float(model_error)
        for v in z:
            if not math.isfinite(v):
                raise InvalidInputError("measured forces must be finite")
        mu0 = self.mu
        h0 = _floats(model(mu0) if predicted is None else predicted)
        if len(h0) != len(z):
            raise InvalidInputError(f"model gives {len(h0)} components, measured {len(z)}")
        slope: tuple[float, ...]
        if slope_at is not None:
            slope = _floats(slope_at(mu0))
            if len(slope) != len(z):
                raise InvalidInputError(f"slope gives {len(slope)} components, "
                                        f"measured {len(z)}")
        else:
            step = self.relative_step * mu0
            if mu0 + step > self.mu_bounds[1]:
                step = -step  # stay inside the range the solver is asked about
            h1 = _floats(model(mu0 + step))
            slope = tuple((b - a) / step for a, b in zip(h0, h1))
        innovation: tuple[float, ...]
        if len(z) == 1:  # one measured component (the node's force.x): no sums to make
            innovation = (z[0] - h0[0],)
            h2 = slope[0] * slope[0]
            hv = slope[0] * innovation[0]
        else:
            innovation = tuple(a - b for a, b in zip(z, h0))
            h2 = math.fsum(v * v for v in slope)
            hv = math.fsum(a * b for a, b in zip(slope, innovation))
        return self._correct(h2, hv, load, s, model_error_at, slope, innovation)

    def update_scalar(self, measured: float, predicted: float, slope: float, load: float,
                      model_error: float = 0.0,
                      model_error_at: Callable[[float], float] | None = None) -> EkfStep:
        """Take one measured component whose model value and slope at the prior are known.

        The node's cycle (one component, ``force.x``; the published solve is
        the model at the prior and its march gave the slope): :meth:`update`
        with ``predicted`` and ``slope_at`` given, to the bit, without its
        sequences.  ``measured``, ``predicted`` (N), ``slope`` (N per unit
        mu), ``load`` (N), ``model_error`` (N) and ``model_error_at`` as
        :meth:`update`'s.
        """
        z, h0, h = float(measured), float(predicted), float(slope)
        if not (load > 0.0 and math.isfinite(load)):
            load = _positive("load", load)
        if not (model_error >= 0.0 and math.isfinite(model_error)):
            model_error = _positive("model_error", model_error, zero_ok=True)
        if not math.isfinite(z):
            raise InvalidInputError("measured forces must be finite")
        y = z - h0
        return self._correct(h * h, h * y, load, float(model_error), model_error_at, (h,),
                             (y,))

    def _correct(self, h2: float, hv: float, load: float, s: float,
                 model_error_at: Callable[[float], float] | None, slope: tuple[float, ...],
                 innovation: tuple[float, ...]) -> EkfStep:
        """Apply the update of ``|H|^2 = h2``, ``H.y = hv`` (the module's docstring)."""
        mu0, var0, c0 = self.mu, self.variance, self.model_bound
        sigma0 = math.sqrt(var0 + c0 * c0)
        sensitivity = math.sqrt(h2) / load
        # a zero slope is never information, whatever the threshold (0 is a legal one)
        if not (sensitivity >= self.min_sensitivity and sensitivity > NO_SENSITIVITY):
            self.skipped += 1
            return EkfStep(UNOBSERVABLE, mu0, sigma0, mu0, sigma0, slope, sensitivity,
                           innovation, model_bound=c0)
        # in mu units: the implied correction, its noise variance and the model's error
        d = hv / h2
        noise = self.measurement_noise ** 2 / h2
        bias = s / math.sqrt(h2)
        # beyond what the noise (gate sigmas) and the model's error (its bounds) explain
        step_seen = abs(d) > (self.step_gate * math.sqrt(var0 + noise)
                              + MODEL_BOUND_SIGMAS * (c0 + bias))
        if step_seen:  # the rail changed: what the innovation implies of mu is unknown
            var0 = min(var0 + d * d, self.sigma_max ** 2)
            self.steps += 1
            if model_error_at is not None:
                level = min(max(mu0 + d, self.mu_bounds[0]), self.mu_bounds[1])
                bias = _positive("model_error", model_error_at(level), zero_ok=True) \
                    / math.sqrt(h2)
        # the gain that minimises P+ + c+^2 (the module's docstring), in [0, 1]
        g = (var0 + c0 * (c0 - bias)) / (var0 + noise + (c0 - bias) ** 2)
        g = min(max(g, 0.0), 1.0)
        self.variance = (1.0 - g) ** 2 * var0 + g * g * noise
        self.model_bound = min((1.0 - g) * c0 + g * bias, self.sigma_max)
        self.mu = min(max(mu0 + g * d, self.mu_bounds[0]), self.mu_bounds[1])
        self.updates += 1
        return EkfStep(UPDATED, mu0, sigma0, self.mu, self.sigma, slope, sensitivity,
                       innovation, step_seen, g, self.model_bound)


class SlopeEkfStep(NamedTuple):
    """One update of :class:`FrictionSlopeEkf`: status, estimates, sigmas, sensitivities.

    ``status``: :data:`UPDATED` (one state or both moved) or
    :data:`UNOBSERVABLE` (neither: held); ``mu``, ``k0`` and their sigmas
    after the update; ``sensitivity_mu`` ``|dh/dmu_s| / N`` and
    ``sensitivity_k0`` ``|dh/dk0| / N``; ``updated``: which states moved
    (``"mu"``, ``"k0"``, ``"mu+k0"`` or ``""``); ``step_seen``: the step
    gate opened; ``innovation`` (N).
    """

    status: str
    mu: float
    k0: float
    sigma_mu: float
    sigma_k0: float
    sensitivity_mu: float
    sensitivity_k0: float
    updated: str
    step_seen: bool
    innovation: float


class FrictionSlopeEkf(_Tuning):
    """Extended Kalman filter on ``(mu_s, k0)``: friction and the creep-slope reduction.

    State ``x = (mu_s, k0)``: the static coefficient and the modified
    FastSim's slope reduction at vanishing creepage
    (:class:`~fastsim_ros.contact.slope_reduction.SlopeReduction`, its
    ``alpha_inf`` and ``beta`` held at configured values), each a random
    walk (``q_mu``, ``q_k0`` in 1/s).  Measurement: ``z = h(mu_s, k0) + v``,
    ``h`` the solver under that reduction, ``v`` the load cell's noise
    (:attr:`measurement_noise`, N, white).  ``H = (dh/dmu_s, dh/dk0)`` by
    forward differences (one solve per contact each, beyond the one at the
    prior).

    Observability.  In the linear range FastSim's force is ``k C w``: it
    fixes ``k0`` (``dh/dk0 = h / k0``, sizeable) and not ``mu_s``
    (``dh/dmu_s ~ 0``); in full slip it is ``mu N``: ``mu_s`` and not
    ``k0`` (``dh/dk0 = 0``: every cell on the bound); at the knee both
    (one component a cycle: the two are told apart as the creepage moves
    along the curve).  A state whose sensitivity ``|H_i| / N`` is below
    :attr:`min_sensitivity` is frozen for the cycle: its gain is zero (the
    Schmidt-Kalman "consider" update: its uncertainty still enters the
    innovation's variance ``S = H P H^T + R`` and the Joseph-form
    covariance, ``P+ = (I - K H) P (I - K H)^T + K R K^T``, holds for that
    gain), so a state the cycle does not inform never drifts with the
    noise, and its variance grows by ``q dt`` per cycle.  Neither
    observable: no update at all, the estimates hold to the bit.

    Steps.  An innovation beyond :attr:`step_gate` sigmas of ``sqrt(S)``
    is a change of the rail: each observable state's variance grows by the
    square of the step it alone would explain, ``(y / H_i)^2`` (at most
    ``sigma_max^2``), before the gain: the next cycles, at other creepages,
    tell which state it was.
    """

    def __init__(self, mu: float, k0: float, sigma_mu: float, sigma_k0: float, *,
                 process_noise: float, process_noise_k0: float, measurement_noise: float,
                 min_sensitivity: float = 0.02, mu_bounds: tuple[float, float] = (0.01, 2.0),
                 k0_bounds: tuple[float, float] = (0.02, 1.0), sigma_max: float = 1.0,
                 relative_step: float = 0.01, step_gate: float = 4.0) -> None:
        for name, (lo, hi) in (("mu_bounds", mu_bounds), ("k0_bounds", k0_bounds)):
            if not (0.0 < lo < hi and math.isfinite(hi)):
                raise InvalidInputError(f"{name} must satisfy 0 < low < high, got {(lo, hi)}")
        self.mu_bounds = (float(mu_bounds[0]), float(mu_bounds[1]))
        self.k0_bounds = (float(k0_bounds[0]), float(k0_bounds[1]))
        self.sigma_max = _positive("sigma_max", sigma_max)
        self.x = np.array([min(max(_positive("mu", mu), self.mu_bounds[0]), self.mu_bounds[1]),
                           min(max(_positive("k0", k0), self.k0_bounds[0]),
                               self.k0_bounds[1])])
        self.P = np.diag([min(_positive("sigma_mu", sigma_mu), self.sigma_max) ** 2,
                          min(_positive("sigma_k0", sigma_k0), self.sigma_max) ** 2])
        self.process_noise = _positive("process_noise", process_noise, zero_ok=True)
        self.process_noise_k0 = _positive("process_noise_k0", process_noise_k0, zero_ok=True)
        super().__init__(measurement_noise, min_sensitivity, relative_step, step_gate)

    @property
    def mu(self) -> float:
        """Return the estimate of ``mu_s``."""
        return float(self.x[0])

    @property
    def k0(self) -> float:
        """Return the estimate of ``k0``."""
        return float(self.x[1])

    @property
    def sigma(self) -> float:
        """Return the standard deviation of ``mu_s``."""
        return math.sqrt(self.P[0, 0])

    @property
    def sigma_k0(self) -> float:
        """Return the standard deviation of ``k0``."""
        return math.sqrt(self.P[1, 1])

    @property
    def correlation(self) -> float:
        """Return the correlation coefficient of the two estimates' errors (1)."""
        d = math.sqrt(self.P[0, 0] * self.P[1, 1])
        return float(self.P[0, 1] / d) if d > 0.0 else 0.0

    def restart(self, sigma: float, mu: float | None = None, *, sigma_k0: float | None = None,
                k0: float | None = None) -> None:
        """Start again from ``mu``, ``k0`` (None: as they are) with the sigmas given.

        ``sigma_k0`` None: ``k0``'s variance stays; the correlation is dropped.
        """
        if mu is not None:
            self.x[0] = min(max(_positive("mu", mu), self.mu_bounds[0]), self.mu_bounds[1])
        if k0 is not None:
            self.x[1] = min(max(_positive("k0", k0), self.k0_bounds[0]), self.k0_bounds[1])
        var_k0 = self.P[1, 1] if sigma_k0 is None else \
            min(_positive("sigma_k0", sigma_k0), self.sigma_max) ** 2
        self.P = np.diag([min(_positive("sigma", sigma), self.sigma_max) ** 2, var_k0])

    def predict(self, dt: float) -> None:
        """Advance by ``dt`` s: each variance grows by its ``q dt`` (up to ``sigma_max^2``)."""
        if not (dt >= 0.0 and math.isfinite(dt)):
            dt = _positive("dt", dt, zero_ok=True)  # raises
        top = self.sigma_max ** 2
        self.P[0, 0] = min(self.P[0, 0] + self.process_noise * dt, top)
        self.P[1, 1] = min(self.P[1, 1] + self.process_noise_k0 * dt, top)

    def update(self, measured: float, model: Callable[[float, float], float],
               load: float, predicted: float | None = None) -> SlopeEkfStep:
        """Take one measured component ``measured`` (N) of ``model(mu_s, k0)`` (N).

        ``load``: the cycle's total normal load (N, for the sensitivities);
        ``predicted``: ``model(mu, k0)`` at the prior if known (saves a solve).
        """
        z = float(measured)
        if not math.isfinite(z):
            raise InvalidInputError("measured forces must be finite")
        if not (load > 0.0 and math.isfinite(load)):
            load = _positive("load", load)
        mu0, k00 = self.mu, self.k0
        h0 = float(model(mu0, k00) if predicted is None else predicted)
        step_mu = self.relative_step * mu0
        if mu0 + step_mu > self.mu_bounds[1]:
            step_mu = -step_mu
        step_k0 = self.relative_step * k00
        if k00 + step_k0 > self.k0_bounds[1]:
            step_k0 = -step_k0  # k0 <= 1: stay inside the range the solver takes
        h = np.array([(float(model(mu0 + step_mu, k00)) - h0) / step_mu,
                      (float(model(mu0, k00 + step_k0)) - h0) / step_k0])
        return self._correct(z - h0, h, load)

    def _correct(self, y: float, h: FloatArray, load: float) -> SlopeEkfStep:
        """Apply the consider update of innovation ``y`` (N), slope ``h`` (class docstring)."""
        r_mu, r_k0 = abs(h[0]) / load, abs(h[1]) / load
        observable = np.array([r_mu >= self.min_sensitivity and r_mu > NO_SENSITIVITY,
                               r_k0 >= self.min_sensitivity and r_k0 > NO_SENSITIVITY])
        if not observable.any():
            self.skipped += 1
            return SlopeEkfStep(UNOBSERVABLE, self.mu, self.k0, self.sigma, self.sigma_k0,
                                r_mu, r_k0, "", False, y)
        noise = self.measurement_noise ** 2
        P = self.P
        s = float(h @ P @ h) + noise
        step_seen = abs(y) > self.step_gate * math.sqrt(s)
        if step_seen:  # the rail changed: each observable state may carry the step
            top = self.sigma_max ** 2
            for i in (0, 1):
                if observable[i]:
                    P[i, i] = min(P[i, i] + (y / h[i]) ** 2, top)
            s = float(h @ P @ h) + noise
            self.steps += 1
        gain = np.where(observable, (P @ h) / s, 0.0)
        a = np.eye(2) - np.outer(gain, h)
        self.P = a @ P @ a.T + noise * np.outer(gain, gain)
        self.P = 0.5 * (self.P + self.P.T)
        x = self.x + gain * y
        self.x = np.array([min(max(x[0], self.mu_bounds[0]), self.mu_bounds[1]),
                           min(max(x[1], self.k0_bounds[0]), self.k0_bounds[1])])
        self.updates += 1
        which = "+".join(n for n, o in zip(("mu", "k0"), observable) if o)
        return SlopeEkfStep(UPDATED, self.mu, self.k0, self.sigma, self.sigma_k0, r_mu, r_k0,
                            which, step_seen, y)
