"""The measurement model of friction estimation: the package's solver as a function of mu_s.

A :class:`ContactSample` is one contact of one rig cycle as the pipeline
solved it: the patch's pressure grid, its creepages and rolling speed, and
the projection of its creep force ``(Fx, Fy)`` (contact frame, N) onto the
measured components (a rig's load cells: the wheelset frame's ``x``, say).
A :class:`CreepModel` holds the solver and the friction law's shape (name,
limit ratio ``A``, decay ``B`` in s/m); :meth:`CreepModel.predict` gives the
measured components' model values (N) at a static coefficient ``mu_s``.

The model's error (:func:`model_error`): where the fast method and the
exact theory differ.  Both bound the traction by ``mu p``; in the model's
slip area both are at the bound along the slip (the same force, up to the
slip's direction and, under a falling law, its speed), so the difference
lives in the model's adhesion area, where FastSim's traction rises from zero
at the leading edge while the exact one is already near the bound.  It is
at most ``mu_s`` times the load on that area, about ``(1 - k) N`` (``k`` the
slip fraction, the share of cells on the bound: the adhesion area is the
leading edge, where the pressure is below average, so this over-states the
load a little).  :data:`MODEL_ERROR_SHARE` of that bound is taken as the
error's standard deviation (the bound as two sigma): ``s = 0.5 mu_s (1 - k)
N`` per contact, the contacts' added (the same sign at worst).  Measured
(Hertzian 6 x 4 mm ellipse under xi, under eta, the 20-cell flange-root
patch under xi, ``mae_calibrated`` against :func:`fastsim_ros.contact.exact.
coulomb`, mu = 0.4 under the exponential law A = B = 0.5 at 20 m/s): the
error is 0.10-0.21 of ``mu (1 - k) N`` from ``k`` = 0.64 to full slip (the
knee's 5.9% of mu N at k = 0.67, 1% at k = 0.92), below 0.05 of it in
partial slip (``k`` < 0.55), so the 0.5 is an honest bound.  In full slip
``s`` vanishes and the load cell's noise is left.

The knee (:mod:`fastsim_ros.contact.knee`): FastSim's force against the
exact theory's is off by a function of the normalised creepage (1.6% of
``mu N`` above it in early partial slip, up to 6.6% below it at the knee of
the curve, the same on every ellipse to a point).  With ``knee`` (the
default) the model's force is the method's times the tabulated knee factor
``kappa(s)``, ``s = |F_lin| / (mu_s N)`` on the patch's equivalent ellipse,
and its slope in ``mu_s`` is that product's (``d kappa / d mu_s = -(s /
mu_s) d kappa / d s``): the estimate reads the exact theory's friction from
a force at the knee, where the method's own force read as friction was 3-8%
off.  Not with the parabolic bound (another knee, not tabulated) nor where
the equivalent ellipse is outside Kalker's tables (factor 1).

Reverse running (rolling speed ``V < 0``) is solved as the pipeline solves
it (docs/guide_physics.md): the patch turned by 180 degrees about ``z``,
spin negated, ``(-Fx', -Fy')`` reported, so the model's forces are the
published ones bit for bit.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact import kernels
from fastsim_ros.contact.area import turned_grid
from fastsim_ros.contact.checks import check_bound
from fastsim_ros.contact.compiled import (CalibratedMaeSolver, EquivalentEllipseSolver,
                                          MaeSolver, _raise)
from fastsim_ros.contact.compiled import _law as _kernel_law
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.friction import FrictionLaw, check_speed, friction_law
from fastsim_ros.contact.knee import knee_factors
from fastsim_ros.contact.polach import PolachSolver
from fastsim_ros.contact.slope_reduction import SlopeReduction

FloatArray = NDArray[np.float64]
Solver = MaeSolver | EquivalentEllipseSolver | PolachSolver
#: the solvers the estimators may use as their measurement model
METHODS = ("mae_calibrated", "mae", "fastsim_ellipse", "polach")
#: the model error's standard deviation as a share of its bound mu_s (1 - k) N (the bound as
#: two sigma; the module's docstring)
MODEL_ERROR_SHARE = 0.5


def _positive_mu(mu_s: float) -> float:
    """Return ``mu_s``; refuse one the friction laws refuse (not finite and > 0)."""
    if not (mu_s > 0.0 and math.isfinite(mu_s)):
        raise InvalidInputError(f"mu_s must be finite and > 0, got {mu_s}")
    return mu_s


def model_error(mu_s: float, adhesion_load: float, share: float = MODEL_ERROR_SHARE) -> float:
    """Return ``s = share mu_s sum (1 - k) N |projection|`` (N): the model error's scale.

    ``adhesion_load``: ``sum_c (1 - k_c) N_c |e_c|`` over the cycle's
    contacts (``k_c`` the slip fraction, ``N_c`` the load, ``|e_c|`` the
    length of the contact's projection row on the measured component);
    ``share`` 0: the model taken as exact.
    """
    return float(share) * float(mu_s) * float(adhesion_load)


def solver_for(method: str, nu: float, shear_modulus: float) -> Solver:
    """Return the compiled solver of ``method`` (:data:`METHODS`); ``shear_modulus`` in Pa."""
    if method == "mae_calibrated":
        return CalibratedMaeSolver(nu, shear_modulus)
    if method == "mae":
        return MaeSolver(nu, shear_modulus)
    if method == "fastsim_ellipse":
        return EquivalentEllipseSolver(nu, shear_modulus)
    if method == "polach":
        return PolachSolver(nu, shear_modulus)
    raise InvalidInputError(f"unknown method {method!r}: one of {', '.join(METHODS)}")


class ExactSolver:
    """Kalker's exact theory (:func:`fastsim_ros.contact.exact.coulomb`) with the batch call.

    ``solve_batch`` as the compiled solvers' (one patch, ``(B, 3)``
    creepages; ``bound`` must be ``"given"``): the batch fit's reference
    model (about 10 ms a solve at 20 x 20 cells), never the node's.  ``nu``,
    ``shear_modulus`` (Pa).
    """

    def __init__(self, nu: float, shear_modulus: float) -> None:
        self.nu, self.shear_modulus = float(nu), float(shear_modulus)
        # the last area's steady-rolling operator (its FFT spectra, strip blocks and coarse
        # grids): a fit solves one patch under many creepages and laws
        self._operator: tuple[bytes, Any, Any] | None = None
        # the last solution's tractions at each creepage on that area (Pa, (m, 2))
        self._starts: dict[tuple[float, float, float], FloatArray] = {}

    def _area(self, pressure: FloatArray, x0: float, y0: float, dx: float,
              dy: float) -> tuple[Any, Any]:
        """Return the smallest area holding the contact and its operator, kept between calls."""
        from fastsim_ros.contact.area import GridArea
        from fastsim_ros.contact.rolling import SteadyRollingOperator

        p = np.ascontiguousarray(pressure, dtype=np.float64)
        key = np.array([x0, y0, dx, dy, *p.shape]).tobytes() + p.tobytes()
        if self._operator is None or self._operator[0] != key:
            area = GridArea(float(x0), float(y0), float(dx), float(dy), p).cropped()
            self._operator = (key, area, SteadyRollingOperator.of(
                area, nu=self.nu, shear_modulus=self.shear_modulus))
            self._starts = {}
        return self._operator[1], self._operator[2]

    def solve_batch(self, pressure: FloatArray, x0: float, y0: float, dx: float, dy: float,
                    creepages: FloatArray, *, bound: str = "given",
                    friction: FrictionLaw | None = None,
                    speed: float | None = None) -> FloatArray:
        """Return ``(B, 3)``: ``Fx, Fy`` (N), ``Mz`` (N m) at each row ``xi, eta, phi``."""
        from fastsim_ros.contact import exact

        if bound != "given":
            raise InvalidInputError("the exact solver takes the pressure as given "
                                    "(bound given)")
        # the cropped grid's cells keep their coordinates: the creepages' reference point
        # and the forces are those of the given grid
        area, operator = self._area(pressure, x0, y0, dx, dy)
        starts = self._starts
        mask = area.mask
        out = np.empty((len(creepages), 3))
        for k, (xi, eta, phi) in enumerate(np.asarray(creepages, dtype=np.float64)):
            # a fit evaluates the same creepages under nearby laws: each solve starts from
            # the last one's tractions at its creepages (Newton's few last steps, not the
            # coarse grid's solve and the whole way)
            key = (float(xi), float(eta), float(phi))
            sol = exact.coulomb(area, *key, nu=self.nu, shear_modulus=self.shear_modulus,
                                friction=friction, speed=speed, operator=operator,
                                start=starts.get(key))
            starts[key] = np.stack([sol.tau_x[mask], sol.tau_y[mask]], axis=1)
            out[k] = sol.fx, sol.fy, sol.mz
        return out


class ContactSample(NamedTuple):
    """One contact of one cycle: grid, creepages, speed and the force's projection.

    ``pressure[j, i]`` (Pa) on the grid ``x0, y0, dx, dy`` (m, cell ``[0, 0]``'s
    centre and the cell sizes, contact frame); ``xi``, ``eta`` (1), ``phi``
    (1/m); ``speed``: the signed rolling speed ``V`` (m/s); ``projection``:
    ``(m, 2)``, the measured components as ``projection @ (Fx, Fy)``.  A
    named tuple: made per contact per rig cycle, it must cost little.
    """

    pressure: FloatArray
    x0: float
    y0: float
    dx: float
    dy: float
    xi: float
    eta: float
    phi: float
    speed: float
    projection: FloatArray | tuple[tuple[float, float], ...]

    @property
    def load(self) -> float:
        """Return the normal load ``sum p dA`` (N)."""
        return float(self.pressure.sum()) * self.dx * self.dy


def _mae_kernel(solver: Solver, bound: str) -> Callable[..., tuple[float, ...]] | None:
    """Return ``solve(p, x0, y0, dx, dy, xi, eta, phi, law, speed, slope)`` for MAE.

    ``(Fx, Fy, k, dFx/dmu_s, dFy/dmu_s)``: the forces from the compiled
    kernel :meth:`MaeSolver.solve_arrays` calls, with the same arguments
    (bit for bit its forces), without the wrapping the estimator pays per
    solve (argument checks, the result object); with ``slope`` the march's
    own derivatives from the same march
    (:func:`fastsim_ros.contact.kernels.mae_solve_mu_slope`, the EKF's
    slope), else zeros.  None for the other solvers.
    """
    if not isinstance(solver, MaeSolver):
        return None
    parabolic = check_bound(bound)
    rule, shear, knots, polys = solver._rule, solver.shear_modulus, solver._knots, solver._polys
    calibrated, pair_knots, pair_values = (solver._calibrated, solver._pair_knots,
                                           solver._pair_values)
    knee = solver._knee_for(bound)
    no_float, no_bool = np.empty((0, 0)), np.empty((0, 0), dtype=np.bool_)

    def solve(p: FloatArray, x0: float, y0: float, dx: float, dy: float, xi: float,
              eta: float, phi: float, law: tuple[int, FloatArray, float, bool],
              speed: float, slope: bool = False) -> tuple[float, ...]:
        code, prm, mu, slip_dependent = law
        if not p.flags.c_contiguous:
            p = np.ascontiguousarray(p)
        v = check_speed(speed) if slip_dependent else 0.0
        if slope:
            r = kernels.mae_solve_mu_slope(p, x0, y0, dx, dy, xi, eta, phi, mu, 0.0, 0.0, rule,
                                           parabolic, shear, knots, polys, code, prm, v,
                                           calibrated, pair_knots, pair_values, knee)
            d_x, d_y = r[8], r[9]
        else:
            r = kernels.mae_solve(p, x0, y0, dx, dy, xi, eta, phi, mu, 0.0, 0.0, rule,
                                  parabolic, shear, knots, polys, code, prm, v, no_float,
                                  no_float, no_bool, False, calibrated, pair_knots, pair_values,
                                  knee)
            d_x = d_y = 0.0
        if r[0]:
            _raise(r[0], r[1], knots)
        return r[2], r[3], r[6] / r[7], d_x, d_y
    return solve


@dataclass(frozen=True)
class CreepModel:
    """The solver under a friction law of fixed shape; ``mu_s`` is what is estimated.

    ``law``: ``"constant"`` or ``"exponential"``; ``limit_ratio`` ``A`` in
    ``(0, 1]`` and ``decay`` ``B`` (s/m) of ``mu(v) = mu_s ((1 - A) exp(-B v)
    + A)``; ``bound``: the traction bound (``"given"`` or ``"parabolic"``);
    ``knee``: the method's force times the knee factor (module docstring;
    with the given bound only).
    """

    solver: Solver
    law: str = "constant"
    limit_ratio: float = 1.0
    decay: float = 0.0
    bound: str = "given"
    knee: bool = True
    reduction: SlopeReduction | None = field(default=None, kw_only=True)

    def friction(self, mu_s: float, limit_ratio: float | None = None,
                 decay: float | None = None) -> FrictionLaw:
        """Return the law at static coefficient ``mu_s`` (``A``, ``B``: the shape's by default)."""
        return friction_law(self.law, float(mu_s),
                            limit_ratio=self.limit_ratio if limit_ratio is None else limit_ratio,
                            decay=self.decay if decay is None else decay,
                            reduction=self.reduction)

    def __post_init__(self) -> None:
        """Check the bound; keep the compiled MAE kernel's call (None: the solver's own).

        Under a slope reduction the solver's own call applies it (the kernel
        knows none) and the knee factor, a correction of the full-slope
        method toward the exact theory, is off: the modified FastSim is the model.
        """
        check_bound(self.bound)
        reduced = self.reduction is not None and not self.reduction.identity
        if reduced or isinstance(self.solver, PolachSolver):  # Polach's: no FastSim knee
            object.__setattr__(self, "knee", False)
        object.__setattr__(self, "_kernel", None if reduced
                           else _mae_kernel(self.solver, self.bound))
        # the march's own slope (the MAE kernels); False: the EKF's forward difference
        object.__setattr__(self, "_marched_slope", self._kernel is not None)  # type: ignore
        # the law's kernel arguments but mu_s (its code and A, B do not depend on mu_s)
        object.__setattr__(self, "_law_template", self._kernel_law(friction_law(
            self.law, 1.0, limit_ratio=self.limit_ratio, decay=self.decay)))
        # the ellipse's factor on the whole force, unless the solver corrects its knee strip by
        # strip itself (one correction, the published forces')
        object.__setattr__(self, "_knee", knee_factors(self.solver.nu)
                           if self.knee and not check_bound(self.bound)
                           and not getattr(self.solver, "knee", False) else None)
        object.__setattr__(self, "_ell", np.empty(kernels.ELL_SIZE))

    @property
    def knee_corrected(self) -> bool:
        """Whether the model's forces carry the knee factor (``knee`` and the given bound)."""
        return self._knee is not None  # type: ignore[attr-defined]

    def knee_factor(self, sample: ContactSample, mu_s: float) -> tuple[float, float]:
        """Return ``(kappa, d kappa / d mu_s)`` of one sample at ``mu_s``; ``(1, 0)`` without.

        ``kappa(s)`` at ``s = |F_lin| / (mu_s N)``, ``F_lin`` Kalker's linear
        force on the patch's equivalent ellipse at the creepages moved to
        its centre, as the solver takes the patch (reversed when ``V <
        0``: the spin's share of ``F_lin`` turns with the rolling direction).
        """
        return self.knee_factor_of(sample.pressure, sample.x0, sample.y0, sample.dx,
                                   sample.dy, sample.xi, sample.eta, sample.phi, sample.speed,
                                   mu_s)

    def knee_factor_of(self, p: FloatArray, x0: float, y0: float, dx: float, dy: float,
                       xi: float, eta: float, phi: float, speed: float,
                       mu_s: float) -> tuple[float, float]:
        """:meth:`knee_factor` of a sample's fields (the node's cycle: no sample made)."""
        if self._knee is None:  # type: ignore[attr-defined]
            return 1.0, 0.0
        if speed < 0.0:  # as _solve
            p, x0, y0 = turned_grid(p, x0, y0, dx, dy)
            phi = -phi
        return self._knee_as_solved(p, x0, y0, dx, dy, xi, eta, phi, mu_s)

    def _knee_as_solved(self, p: FloatArray, x0: float, y0: float, dx: float, dy: float,
                        xi: float, eta: float, phi: float,
                        mu_s: float) -> tuple[float, float]:
        """:meth:`knee_factor_of` on the patch as the solver takes it (turned if ``V < 0``)."""
        knee = self._knee  # type: ignore[attr-defined]
        if knee is None:
            return 1.0, 0.0
        _positive_mu(mu_s)  # s = |F_lin| / (mu_s N): a mu the laws refuse has none
        if not p.flags.c_contiguous:
            p = np.ascontiguousarray(p)
        s = self.solver
        return kernels.knee_factor(  # type: ignore[no-any-return]
            p, float(x0), float(y0), float(dx), float(dy), float(xi), float(eta), float(phi),
            float(mu_s), s.shear_modulus, s._knots, s._polys,
            self._ell,  # type: ignore[attr-defined]
            knee.log_aspect, knee.s, knee.kappa)

    def contact_forces(self, sample: ContactSample, mu_s: float) -> tuple[float, float]:
        """Return the creep forces ``(Fx, Fy)`` (N, contact frame) of one sample at ``mu_s``."""
        return self._solve(sample, mu_s)[:2]

    def _solve(self, sample: ContactSample, mu_s: float,
               law: FrictionLaw | None = None,
               kernel_law: tuple[int, FloatArray, float, bool] | None = None,
               slope: bool = False) -> tuple[float, float, float]:
        """Return ``(Fx, Fy, slip fraction)`` of one sample at ``mu_s`` (``law``: its law).

        ``kernel_law``: the law's kernel arguments (:meth:`_kernel_law`), if known;
        ``slope``: ``(dFx/dmu_s, dFy/dmu_s)`` (N) instead of the forces (MAE only).
        """
        p, x0, y0, phi = sample.pressure, sample.x0, sample.y0, sample.phi
        reverse = sample.speed < 0.0
        if reverse:  # as Pipeline._solve: the leading edge at +x
            p, x0, y0 = turned_grid(p, x0, y0, sample.dx, sample.dy)
            phi = -phi
        kernel = self._kernel  # type: ignore[attr-defined]
        if kernel is not None:  # the kernel solve_arrays calls, without its wrapping
            if kernel_law is None:
                kernel_law = self._kernel_law(self.friction(mu_s) if law is None else law)
            fx, fy, k, dfx, dfy = kernel(p, x0, y0, sample.dx, sample.dy, sample.xi,
                                         sample.eta, phi, kernel_law, abs(sample.speed), slope)
            # the factor of the patch as turned above, not turned again
            kappa, dkappa = self._knee_as_solved(p, x0, y0, sample.dx, sample.dy, sample.xi,
                                                 sample.eta, phi, mu_s)
            if slope:  # d(kappa F)/dmu_s = kappa dF/dmu_s + F dkappa/dmu_s
                fx, fy = kappa * dfx + dkappa * fx, kappa * dfy + dkappa * fy
            else:
                fx, fy = kappa * fx, kappa * fy
        else:
            law = self.friction(mu_s) if law is None else law
            f = self.solver.solve_arrays(p, x0, y0, sample.dx, sample.dy, sample.xi,
                                         sample.eta, phi,
                                         bound=self.bound,  # type: ignore[arg-type]
                                         friction=law, speed=abs(sample.speed))
            kappa = self._knee_as_solved(p, x0, y0, sample.dx, sample.dy, sample.xi,
                                         sample.eta, phi, mu_s)[0]
            fx, fy, k = kappa * f.fx, kappa * f.fy, f.slip_fraction
        return (-fx, -fy, k) if reverse else (fx, fy, k)

    @property
    def has_slope(self) -> bool:
        """Whether :meth:`slope` is the march's own derivative (MAE solvers), not a difference."""
        return bool(self._marched_slope)  # type: ignore[attr-defined]

    def slope(self, samples: Sequence[ContactSample], mu_s: float) -> FloatArray:
        """Return ``d/dmu_s`` of :meth:`predict` (N): the march's derivative (:attr:`has_slope`).

        The steady sweep differentiated (tangent-linear FastSim,
        :func:`fastsim_ros.contact.kernels.sweep_mu_slope`): one march per
        contact, where a forward difference needs a second solve.
        """
        if not self.has_slope:
            raise InvalidInputError("the slope in mu_s is the MAE solvers' only")
        if not samples:
            raise InvalidInputError("no contact sample to differentiate")
        code, prm, _, slip_dependent = self._law_template  # type: ignore[attr-defined]
        kernel_law = (code, prm, float(_positive_mu(mu_s)), slip_dependent)
        total = [0.0] * len(samples[0].projection)
        for s in samples:
            dfx, dfy, _ = self._solve(s, mu_s, None, kernel_law, slope=True)
            for i, (px, py) in enumerate(s.projection):
                total[i] += float(px) * dfx + float(py) * dfy
        return np.array(total)

    def predict(self, samples: Sequence[ContactSample], mu_s: float) -> FloatArray:
        """Return the measured components' model values (N): ``sum projection @ (Fx, Fy)``."""
        return self.predict_with_error(samples, mu_s, 0.0)[0]

    def predict_with_error(self, samples: Sequence[ContactSample], mu_s: float,
                           share: float = MODEL_ERROR_SHARE) -> tuple[FloatArray, float]:
        """Return :meth:`predict`'s values and the model error's scale (N) there."""
        if not samples:
            raise InvalidInputError("no contact sample to predict")
        total = [0.0] * len(samples[0].projection)
        adhesion = 0.0
        if self._kernel is not None:  # type: ignore[attr-defined]
            # the kernel's law arguments at mu_s, as _kernel_law(self.friction(mu_s)) gives
            code, prm, _, slip_dependent = self._law_template  # type: ignore[attr-defined]
            law = None
            kernel_law = (code, prm, float(_positive_mu(mu_s)), slip_dependent)
        else:
            law, kernel_law = self.friction(mu_s), None
        for s in samples:
            fx, fy, k = self._solve(s, mu_s, law, kernel_law)
            weight = 0.0
            for i, (px, py) in enumerate(s.projection):
                total[i] += float(px) * fx + float(py) * fy
                weight = max(weight, math.hypot(px, py))
            if share:
                adhesion += (1.0 - k) * s.load * weight
        return np.array(total), model_error(mu_s, adhesion, share)

    @staticmethod
    def _kernel_law(law: FrictionLaw) -> tuple[int, FloatArray, float, bool]:
        """Return the kernel's ``(law code, params, mu_s, slip dependent)`` of ``law``."""
        code, prm, mu, _ = _kernel_law(None, law, 1.0)
        return code, prm, mu, law.slip_dependent
