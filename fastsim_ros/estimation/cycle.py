"""The online estimator's cycle: a rig cycle's solved contacts and measured force, one update.

The pipeline hands over, once per rig cycle, each contact's published solve
(patch, creepages, forces at the ``mu_s`` in force) and the slope its march
gave; :meth:`FrictionCycle.update` takes the measured wheelset force of that
cycle (:meth:`FrictionCycle.measurement`: the kinematics' rules of age and
order) and updates the filter (:mod:`fastsim_ros.estimation.ekf`) with the
measurement model of :mod:`fastsim_ros.estimation.model`.  The pipeline then
solves with the estimate.  No ROS, no pipeline state: the counts of what each
cycle did are kept here (:attr:`FrictionCycle.counts`, the diagnostics').
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from typing import Any

from fastsim_ros.contact.compiled import ContactForces
from fastsim_ros.contact.errors import ContactError
from fastsim_ros.contact.slope_reduction import SlopeReduction
from fastsim_ros.estimation.ekf import FrictionEkf, FrictionSlopeEkf
from fastsim_ros.estimation.model import ContactSample, CreepModel, model_error
from msg_adapters.kinematics import Creepage
from msg_adapters.patch import ContactPatch

#: a measured creep force (N) beyond this times the highest mu_s the estimator admits times the
#: cycle's load is a fault of the measurement, not a rail: the update is skipped (implausible)
IMPLAUSIBLE_FORCE = 1.0

#: a contact's published solve: the patch as converted, its creepages and forces
ContactSolve = tuple[ContactPatch, Creepage, ContactForces]


def _sample(patch: ContactPatch, creep: Creepage) -> ContactSample:
    """Return the measurement model's sample of one solve (its wheelset-x projection)."""
    return ContactSample(patch.pressure, patch.x0, patch.y0, patch.dx, patch.dy, creep.xi,
                         creep.eta, creep.phi, creep.speed,
                         ((patch.frame.axes[0][0], patch.frame.axes[1][0]),))


class FrictionCycle:
    """The measured wheelset forces and the estimator's update of each rig cycle.

    ``history``: how many measured forces are kept for matching cycle
    stamps.  :attr:`counts`: measured wrenches taken and dropped, and each
    cycle's status (``updated``, ``unobservable``, ``implausible``,
    ``no_measurement``) and the filter's steps seen.
    """

    def __init__(self, history: int) -> None:
        #: the measured forces (stamp ns, force N in the wheelset frame), oldest first
        self.measured: deque[tuple[int, tuple[float, float, float]]] = deque(maxlen=history)
        self._used_ns: int | None = None
        self._last_cycle_ns: int | None = None
        self.counts = {"measured": 0, "dropped": 0, "updated": 0, "unobservable": 0,
                       "implausible": 0, "no_measurement": 0, "steps": 0}

    def add(self, stamp_ns: int, force: tuple[float, float, float]) -> None:
        """Keep a measured wheelset force (N, wheelset frame) stamped ``stamp_ns``."""
        self.measured.append((stamp_ns, force))
        self.counts["measured"] += 1

    def measurement(self, stamp_ns: int, max_age_ns: int) -> tuple[float, float, float] | None:
        """Return the measured force of the cycle stamped ``stamp_ns``, by the kinematics' rules.

        The newest measured wrench not after the cycle and at most
        ``max_age_ns`` before it, and not used by an earlier cycle.
        """
        for stamp, force in reversed(self.measured):
            if stamp <= stamp_ns:
                if stamp_ns - stamp > max_age_ns or (
                        self._used_ns is not None and stamp <= self._used_ns):
                    return None
                self._used_ns = stamp
                return force
        return None

    def update(self, ekf: FrictionEkf | FrictionSlopeEkf, stamp_ns: int, mu: float,
               contacts: Sequence[tuple[ContactSolve | None, tuple[float, float] | None]],
               max_age_ns: int, model: CreepModel, share: float,
               reduced: tuple[Any, str, float, float, str, float, float]
               ) -> tuple[str, float]:
        """Update the estimate with the cycle's measured force.x; return the status, utilisation.

        ``contacts``: each contact's latest solve at ``mu`` (None: none) and
        the slope ``(dFx, dFy)/dmu_s`` its march gave (None: not marched).
        Measurement model (:mod:`fastsim_ros.estimation`): the wheelset
        frame's ``x`` component of the contacts' wrenches, ``sum_c e_x,c[0]
        Fx_c + e_y,c[0] Fy_c + e_z,c[0] N_c``, the creep forces solved at
        ``mu_s`` (the published ones are those at the prior; the slope is the
        march's derivative where every contact's march gave it, else one
        march more per contact; with the equivalent ellipse a forward
        difference, one more solve per contact).  ``model``: the measurement
        model, ``share`` its error's share (parameter friction_model_error);
        ``reduced``: the solver, law name, limit ratio, decay, bound, and the
        reduction's ``alpha_inf`` and ``beta`` (the estimate of ``(mu_s, k0)``).
        The utilisation is the cycle's ``sum |(Fx, Fy)| / (mu sum N)``.
        """
        if self._last_cycle_ns is not None and stamp_ns > self._last_cycle_ns:
            ekf.predict((stamp_ns - self._last_cycle_ns) * 1e-9)
        self._last_cycle_ns = stamp_ns
        solved: list[ContactSolve] = []
        normal_x = predicted = load = used = adhesion = slope = 0.0
        marched = True  # every contact's slope came with its solve
        slopes: list[tuple[float, float]] = []
        for taken, contact_slope in contacts:
            if taken is None:
                continue
            patch, _, f = taken
            ex, ey, ez = patch.frame.axes
            if contact_slope is None:
                marched = False
            else:
                slope += ex[0] * contact_slope[0] + ey[0] * contact_slope[1]
                slopes.append(contact_slope)
            solved.append(taken)
            normal_x += ez[0] * f.n
            predicted += ex[0] * f.fx + ey[0] * f.fy
            load += f.n
            used += math.hypot(f.fx, f.fy)
            adhesion += (1.0 - f.slip_fraction) * f.n * math.hypot(ex[0], ey[0])
        utilisation = used / (mu * load) if load > 0.0 else 0.0
        measured = self.measurement(stamp_ns, max_age_ns)
        status = "no_measurement"
        if measured is None:
            pass
        elif not (solved and load > 0.0):
            status = "unobservable"  # no contact (a lifted wheelset): no force depends on mu
        elif abs(measured[0] - normal_x) > (
                IMPLAUSIBLE_FORCE * ekf.mu_bounds[1] * load + 10.0 * ekf.measurement_noise):
            # more creep force than the highest friction the filter admits gives the load
            # (plus ten of the load cell's sigmas): a fault of the measurement, which as a
            # step of mu would drive the estimate to its bound and every wrench with it
            status = "implausible"
        elif isinstance(ekf, FrictionSlopeEkf):
            status = self._update_with_slope(ekf, solved, measured[0] - normal_x, load, reduced)
        else:
            # the model's samples only where a solve beyond the published one is asked
            # for (a step of mu seen, a slope the march did not give): most cycles none
            built: list[list[ContactSample]] = []

            def samples() -> list[ContactSample]:
                if not built:
                    built.append([_sample(p, c) for p, c, _ in solved])
                return built[0]
            try:
                if marched and model.has_slope and ekf.mu == mu:
                    # the node's cycle: the model and its slope at the prior are the
                    # published solve's (update, to the bit, without its sequences), times
                    # the knee factor where the model carries it (CreepModel.knee_factor)
                    if model.knee_corrected:
                        predicted, slope = knee_corrected(model, solved, slopes, mu)
                    step = ekf.update_scalar(
                        measured[0] - normal_x, predicted, slope, load,
                        model_error(mu, adhesion, share),
                        lambda m: model.predict_with_error(samples(), m, share)[1])
                else:  # a slope the march did not give, or an estimate off the published mu
                    if model.knee_corrected:  # the published forces times their factors
                        predicted = knee_corrected(model, solved, None, mu)[0]
                    step = ekf.update((measured[0] - normal_x,),
                                      lambda m: model.predict(samples(), m), load, (predicted,),
                                      model_error(mu, adhesion, share),
                                      lambda m: model.predict_with_error(samples(), m, share)[1],
                                      (lambda m: model.slope(samples(), m)) if model.has_slope
                                      else None)
                status = step.status
                self.counts["steps"] += int(step.step_seen)
            except ContactError:  # the solver refused the perturbed mu: hold
                status = "unobservable"
        self.counts[status] += 1
        return status, utilisation

    def _update_with_slope(self, ekf: FrictionSlopeEkf, solved: list[ContactSolve],
                           measured: float, load: float,
                           reduced: tuple[Any, str, float, float, str, float, float]) -> str:
        """Update ``(mu_s, k0)`` with the cycle's measured creep force ``measured`` (N, x).

        The model: the configured solver under the law at ``mu_s`` with the
        reduction ``SlopeReduction(k0, alpha_inf, beta)`` (the modified
        FastSim, no knee factor), the contacts' forces projected on the
        wheelset's ``x`` (:meth:`CreepModel.predict`).  The model at the prior
        is the published forces (solved under that very law and reduction);
        the forward difference in each state is one solve per contact more.
        Returns the cycle's status.
        """
        samples = [_sample(p, c) for p, c, _ in solved]
        solver, name, limit_ratio, decay, bound, alpha_inf, beta = reduced

        def model(mu_s: float, k0: float) -> float:
            reduction = SlopeReduction(k0, alpha_inf, beta)
            creep = CreepModel(solver, name, limit_ratio, decay, bound, knee=False,
                               reduction=None if reduction.identity else reduction)
            return float(creep.predict(samples, mu_s)[0])
        predicted = math.fsum(p.frame.axes[0][0] * f.fx + p.frame.axes[1][0] * f.fy
                              for p, _, f in solved)
        try:
            step = ekf.update(measured, model, load, predicted)
        except ContactError:  # the solver refused a perturbed state: hold
            return "unobservable"
        self.counts["steps"] += int(step.step_seen)
        return step.status


def knee_corrected(model: CreepModel, solved: Sequence[ContactSolve],
                   slopes: Sequence[tuple[float, float]] | None,
                   mu: float) -> tuple[float, float]:
    """Return the model's value and slope at ``mu`` from the published solves and marches.

    Per contact ``kappa F`` and ``kappa dF/dmu_s + F dkappa/dmu_s``
    (:meth:`CreepModel.knee_factor`), projected on the wheelset's ``x``:
    :meth:`CreepModel.predict` and :meth:`CreepModel.slope` without a
    solve (the published forces and the march's slope are theirs);
    ``slopes`` None: the value alone (slope 0).
    """
    predicted = slope = 0.0
    for k, (p, c, f) in enumerate(solved):
        kappa, dkappa = model.knee_factor_of(p.pressure, p.x0, p.y0, p.dx, p.dy, c.xi,
                                             c.eta, c.phi, c.speed, mu)
        ex, ey, _ = p.frame.axes
        force = ex[0] * f.fx + ey[0] * f.fy
        predicted += kappa * force
        if slopes is not None:
            dfx, dfy = slopes[k]
            slope += kappa * (ex[0] * dfx + ey[0] * dfy) + dkappa * force
    return predicted, slope
