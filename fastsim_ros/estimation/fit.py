"""Batch fit of a friction law to a measured creep curve (``fastsim_contact estimate``).

The measured samples (creepages ``xi, eta`` (1), ``phi`` (1/m); forces
``Fx`` and optionally ``Fy`` (N), contact frame, signs as in
docs/guide_physics.md) on one patch are fitted by the package's solver (compiled, one batch per
evaluation) under the friction law: ``mu_s`` for constant friction, ``mu_s``,
the limit ratio ``A`` and the decay ``B`` (s/m) for the exponential law
``mu(v) = mu_s ((1 - A) exp(-B v) + A)``.  Least squares over the residuals
``(F_model - F_measured) / N`` by SciPy's trust-region reflective
Gauss-Newton (bounds: ``mu_s > 0``, ``0 < A <= 1``, ``B >= 0``), forward
differences for the Jacobian.  Standard deviations: the diagonal of
``s^2 (J^T J)^-1``, ``s^2`` the residuals' variance (n - p degrees of
freedom); a parameter the data do not determine (its column of ``J`` zero,
or ``J^T J`` singular) has none (``nan``), and the others' are those of the
rest.  The fitted curve's worst error is reported in % of
``mu_s N``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.friction import friction_law
from fastsim_ros.contact.slope_reduction import SlopeReduction
from fastsim_ros.estimation.model import ExactSolver, Solver

FloatArray = NDArray[np.float64]
#: bounds of the fitted parameters: mu_s, A (1), B (s/m)
MU_RANGE = (1e-3, 5.0)
LIMIT_RATIO_RANGE = (1e-3, 1.0)
DECAY_RANGE = (0.0, 1e4)
#: bounds of a fitted slope reduction: k0 (1); alpha_inf is in [0, 1]; beta (1) at most
K0_RANGE = (1e-3, 1.0)
BETA_MAX = 1e3
#: mu_s is not determined by samples whose largest sensitivity ``r = |dF/dmu_s| / N`` is
#: below this (the node's default ``friction_min_sensitivity``: the linear range, where the
#: exact theory's force, and so the knee-corrected model's, depends on mu only as s^2)
MIN_SENSITIVITY = 0.02


def _decay(limit_ratio: float, c: float) -> float:
    """Return the decay ``B = c / (1 - A)`` (s/m) of the fitted ``c = (1 - A) B``, in range."""
    if limit_ratio >= 1.0:
        return 0.0  # constant friction: B does not act
    return min(c / (1.0 - limit_ratio), DECAY_RANGE[1])


@dataclass(frozen=True)
class FrictionFit:
    """A fitted law: parameters, their standard deviations, the curve and its errors.

    ``law``: ``"constant"`` or ``"exponential"``; ``mu_s`` (1), ``limit_ratio``
    ``A`` (1) and ``decay`` ``B`` (s/m; 1 and 0 for constant friction);
    ``sigmas``: standard deviation of each fitted parameter (nan where
    undetermined); ``predicted``: the fitted model's forces, the measured
    shape (N); ``worst_error_percent``: ``max |F_fit - F_measured|`` in % of
    ``mu_s N``; ``rms_error_percent`` likewise; ``load`` ``N`` (N);
    ``evaluations``: model evaluations (batches); ``reduction``: the slope
    reduction of the model (fitted, with ``fit_reduction``; None: none).
    """

    law: str
    mu_s: float
    limit_ratio: float
    decay: float
    sigmas: dict[str, float]
    predicted: FloatArray
    worst_error_percent: float
    rms_error_percent: float
    load: float
    evaluations: int
    reduction: SlopeReduction | None = None


def fit_friction(solver: Solver | ExactSolver, area: GridArea, creepages: ArrayLike,
                 measured: ArrayLike,
                 *, law: str = "constant", speed: float | None = None, bound: str = "given",
                 mu0: float = 0.3, limit_ratio0: float = 0.5,
                 decay0: float = 1.0, knee: bool = False,
                 reduction: SlopeReduction | None = None,
                 max_evaluations: int = 200, fit_reduction: bool = False) -> FrictionFit:
    """Fit ``law`` to ``measured`` (``(n,)`` Fx or ``(n, 2)`` Fx, Fy in N) at ``creepages``.

    ``creepages``: ``(n, 3)`` rows ``xi, eta, phi`` (1, 1, 1/m) about the
    area's origin; ``speed``: the rolling speed ``|V|`` (m/s), required by
    the exponential law; ``mu0``, ``limit_ratio0``, ``decay0`` (s/m): the
    starting point.  ``knee``: a fast solver's forces times the knee factor
    at the fitted ``mu_s`` (:meth:`~fastsim_ros.estimation.model.CreepModel.knee_factor`,
    the node's estimator's model; not with the exact solver or the
    parabolic bound).  ``reduction``: a known creep-slope reduction the law
    carries (the modified FastSim; fast solvers only; no knee factor then).
    ``max_evaluations``: the most model evaluations (batches) of the search.
    ``fit_reduction``: fit the reduction's ``k0, alpha_inf, beta`` too (from
    ``reduction``, or from 0.8, 0.5, 1 without one; fast solvers only): the
    slope, observable in the linear range where ``mu_s`` is not.
    """
    from scipy.optimize import least_squares

    cr = np.ascontiguousarray(creepages, dtype=np.float64)
    z = np.asarray(measured, dtype=np.float64)
    if z.ndim == 1:
        z = z[:, None]
    if cr.ndim != 2 or cr.shape[1] != 3 or z.ndim != 2 or z.shape[0] != cr.shape[0] \
            or z.shape[1] not in (1, 2):
        raise InvalidInputError(f"creepages (n, 3) and measured (n,) or (n, 2) expected, got "
                                f"{cr.shape} and {np.shape(measured)}")
    exponential = law == "exponential"
    if law not in ("constant", "exponential"):
        raise InvalidInputError(f"unknown friction law {law!r}: constant or exponential")
    if exponential and speed is None:
        raise InvalidInputError("the exponential law needs the rolling speed (m/s)")
    p = (3 if exponential else 1) + (3 if fit_reduction else 0)
    n = cr.shape[0]
    if n * z.shape[1] <= p:
        raise InvalidInputError(f"{n} samples cannot determine {p} parameter(s): give more")
    load = float(area.load)
    evaluations = [0]
    corrected = None
    reduced = fit_reduction or (reduction is not None and not reduction.identity)
    if reduced and isinstance(solver, ExactSolver):
        raise InvalidInputError("the exact theory has its full slope: a slope reduction "
                                "is an option of the fast methods")
    if reduced:
        knee = False  # the modified FastSim is the model, not a corrected full-slope one
    if knee and not isinstance(solver, ExactSolver):
        from fastsim_ros.estimation.model import CreepModel
        corrected = CreepModel(solver, bound=bound)
        if not corrected.knee_corrected:
            corrected = None
    p_area = np.ascontiguousarray(area.pressure, dtype=np.float64)

    first = 3 if exponential else 1   # the reduction's parameters' index in theta

    def forces(theta: FloatArray) -> FloatArray:
        evaluations[0] += 1
        red = (SlopeReduction(float(theta[first]), float(theta[first + 1]),
                              float(theta[first + 2])) if fit_reduction else reduction)
        if exponential:
            f = friction_law("exponential", float(theta[0]), limit_ratio=float(theta[1]),
                             decay=_decay(float(theta[1]), float(theta[2])),
                             reduction=red)
        else:
            f = friction_law("constant", float(theta[0]), reduction=red)
        out = solver.solve_batch(area.pressure, area.x0, area.y0, area.dx, area.dy, cr,
                                 bound=bound, friction=f,  # type: ignore[arg-type]
                                 speed=None if speed is None else abs(speed))
        if corrected is not None:
            for row, (xi, eta, phi) in zip(out, cr):
                row[:2] *= corrected.knee_factor_of(p_area, area.x0, area.y0, area.dx,
                                                    area.dy, xi, eta, phi, 1.0,
                                                    float(theta[0]))[0]
        return out[:, :z.shape[1]]

    def residuals(theta: FloatArray) -> FloatArray:
        return ((forces(theta) - z) / load).ravel()

    # the exponential law is fitted in (mu_s, A, c = (1 - A) B): a creep curve's slip
    # velocities mostly see mu_s (1 - (1 - A) B v + ...), so the data fix c far better than
    # A and B, whose valley (1 - A) B = c is a hyperbola in (A, B) that Gauss-Newton
    # walks in dozens of steps and a straight line here (measured on the exact theory's
    # curve: 141 evaluations before)
    lo = [MU_RANGE[0]] + ([LIMIT_RATIO_RANGE[0], DECAY_RANGE[0]] if exponential else [])
    hi = [MU_RANGE[1]] + ([LIMIT_RATIO_RANGE[1], DECAY_RANGE[1]] if exponential else [])
    x0 = [mu0] + ([limit_ratio0, decay0] if exponential else [])
    x0 = [min(max(v, a), b) for v, a, b in zip(x0, lo, hi)]
    if exponential:
        if x0[1] >= 1.0:
            x0[1] = 0.5  # A = 1 is constant friction: no slope in B to start from
        x0[2] = (1.0 - x0[1]) * x0[2]
    if fit_reduction:
        lo += [K0_RANGE[0], 0.0, 0.0]
        hi += [K0_RANGE[1], 1.0, BETA_MAX]
        # k0 1 with alpha_inf 1 would start where beta does not act
        r = reduction if reduction is not None and not reduction.identity \
            else SlopeReduction(0.8, 0.5, 1.0)
        x0 += [r.k0, r.alpha_inf, min(r.beta, BETA_MAX)]
    sol = least_squares(residuals, np.array(x0, dtype=np.float64), bounds=(lo, hi),
                        method="trf", x_scale="jac", diff_step=1e-3, xtol=1e-10, ftol=1e-12,
                        gtol=1e-12, max_nfev=max_evaluations)
    theta = np.array(sol.x, dtype=np.float64)
    predicted = forces(theta)
    dof = max(z.size - p, 1)
    s2 = float(np.sum(sol.fun ** 2)) / dof
    names = (("mu_s", "limit_ratio", "decay") if exponential else ("mu_s",)) + (
        ("slope_k0", "slope_alpha_inf", "slope_beta") if fit_reduction else ())
    sigmas = {name: math.nan for name in names}
    # a parameter the forces do not depend on at all (A and B at zero rolling speed, mu_s in
    # full adhesion) has a zero column: the others' covariance is that of the rest
    jac = np.asarray(sol.jac, dtype=np.float64)
    norms = np.linalg.norm(jac, axis=0) if np.all(np.isfinite(jac)) else np.zeros(p)
    seen = np.flatnonzero(norms > 1e-12 * max(float(norms.max()), 1e-300))
    # the residuals are forces over N: mu_s's column holds each sample's sensitivity r
    if float(np.max(np.abs(jac[:, 0]), initial=0.0)) < MIN_SENSITIVITY:
        seen = seen[seen != 0]
    if seen.size and 0 in seen:
        jtj = jac[:, seen].T @ jac[:, seen]
        if np.linalg.cond(jtj) >= 1e14:
            # A and B along a valley the samples do not close (constant friction fits as
            # well as any falling law): they are undetermined, mu_s is as alone
            seen = seen[seen == 0]
    if seen.size:
        jtj = jac[:, seen].T @ jac[:, seen]
        if np.linalg.cond(jtj) < 1e14:
            cov = np.full((p, p), math.nan)
            cov[np.ix_(seen, seen)] = np.linalg.inv(jtj) * s2
            if exponential:
                # B = c / (1 - A): its variance through the map's Jacobian (nan unless both
                # A and c are determined)
                a_, c_ = float(theta[1]), float(theta[2])
                grad = (np.array([c_ / (1.0 - a_) ** 2, 1.0 / (1.0 - a_)]) if a_ < 1.0
                        else np.full(2, math.nan))   # dB/dA, dB/dc
                cov[2, 2] = float(grad @ cov[1:3, 1:3] @ grad)
            for i in range(p):
                if math.isfinite(cov[i, i]):
                    sigmas[names[i]] = math.sqrt(max(float(cov[i, i]), 0.0))
    mu_n = float(theta[0]) * load
    err = np.abs(predicted - z)
    fitted = (SlopeReduction(float(theta[first]), float(theta[first + 1]),
                             float(theta[first + 2])) if fit_reduction else reduction)
    return FrictionFit(law, float(theta[0]), float(theta[1]) if exponential else 1.0,
                       _decay(float(theta[1]), float(theta[2])) if exponential else 0.0,
                       sigmas, predicted,
                       float(err.max()) / mu_n * 100.0,
                       float(np.sqrt(np.mean(err ** 2))) / mu_n * 100.0, load, evaluations[0],
                       fitted)
