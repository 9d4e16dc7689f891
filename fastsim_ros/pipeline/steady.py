"""The pipeline the node and the replay share: kinematics and patches in, creep forces out.

:class:`Pipeline` holds the checked configuration, the compiled solver and
the latest kinematics; :meth:`Pipeline.on_patch` turns one patch (a decoded
:class:`~msg_adapters.cdr.Cloud`) into an :class:`Outcome`: the solved
contact (frame, creepages, forces) and, once per rig cycle, the wheelset
wrench, or a rejection with its reason key.  It never reads
a clock for anything it outputs: stamps come from the messages, so a replay
is deterministic (only the solve-time statistics use ``perf_counter``).
No ``rclpy.node`` here: the node and ``fastsim_replay`` are thin front ends.
A patch that is solved takes the compiled path
(:func:`fastsim_ros.pipeline.kernels.solve_cloud`: the adapter's loop, the
creepages, the MAE solve and the wheelset wrench in one call, equal to the
bit to the Python path, which decides every rejection); its solve time is
that call's.

Physics (docs/guide_physics.md, its conventions and creepages): the solvers roll towards
``+x``; when the rolling speed ``V`` is negative (reverse running) the patch
is turned by 180 degrees about the contact normal (``x, y -> -x, -y``), solved
with ``(xi, eta, -phi)``, and ``(-Fx', -Fy', Mz')`` is reported in the
unchanged contact frame, so the creep force always opposes the slip.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable, Collection, Container, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from fastsim_ros.ros import params as parameters
from fastsim_ros.ros.params import slope_reduction_of
from fastsim_ros.pipeline import kernels as fast
from fastsim_ros.pipeline.plausibility import implausible
from fastsim_ros.pipeline.compiled_state import CompiledState
from fastsim_ros.pipeline.outcomes import (NO_CONTACT, SINCE_START, SINCE_START_KEY, SOLVED,
                                           ContactReport, ContactStats, FrictionEstimate,
                                           Outcome, Solved, WheelsetWrench, new_creepage,
                                           new_estimate, new_forces, new_frame, new_outcome,
                                           new_patch)
from fastsim_ros.pipeline.topics import (FRICTION_ESTIMATE_TOPIC, MARKERS_TOPIC,
                                         MEASURED_WRENCH_TOPIC, RAIL_TWIST_TOPIC,
                                         SLOPE_ESTIMATE_TOPIC, WHEEL_TWIST_TOPIC,
                                         WHEELSET_WRENCH_TOPIC, InputHandler, InputTopic,
                                         output_topics, patch_topic)
from fastsim_ros.contact.area import nearest_cells, regridded, turned_grid
from fastsim_ros.contact.compiled import (CalibratedMaeSolver, ContactForces,
                                          EquivalentEllipseSolver, MaeSolver)
from fastsim_ros.contact.errors import ContactError, OutOfTableError
from fastsim_ros.contact.polach import PolachSolver
from fastsim_ros.contact.friction import FrictionLaw, friction_law
from fastsim_ros.errors import ParameterError
from fastsim_ros.contact.slope_reduction import SlopeReduction
from fastsim_ros.estimation import CreepModel, FrictionEkf
from fastsim_ros.estimation.cycle import FrictionCycle
from fastsim_ros.estimation.ekf import FrictionSlopeEkf
from fastsim_ros.contact import kernels as contact_kernels
from fastsim_ros.contact.transient import (RESET_REASONS, ContactMemory, TransientSolver,
                                           mae_state)
from fastsim_ros.contact.wear import PiecewiseLinear, WearIndicators, indicators
from msg_adapters import outputs as out
from msg_adapters import patch_kernels
from msg_adapters.cdr import (Cloud, CloudReader, StampedTwist, read_twist, stamped_doubles,
                              stamped_doubles_template)
from msg_adapters.errors import REJECTION_REASONS, MalformedMessageError, RejectedInput
from msg_adapters.kinematics import REST, Creepage, creepages, twist_is_finite
from msg_adapters.patch import ContactFrame, ContactPatch, patch_from_cloud, words_of

#: twists kept for matching patch stamps (at 1 kHz: 1 s of history)
TWIST_HISTORY = 1024
#: a frame "changes" (and is published again) when its origin moves by more
#: than this (m) or an axis turns by more than this (rad, small angles)
FRAME_TOLERANCE = 1e-6


def _on_patch_cells(f: ContactForces, patch: ContactPatch) -> ContactForces:
    """Return ``f`` with its tractions moved from the solver's own grid to the patch's cells.

    The equivalent ellipse solves on an ``n`` x ``n`` grid of its own
    ellipse; the traction cloud is the patch's cells' (docs/guide_node.md
    "Outputs"): bilinear (:func:`~fastsim_ros.contact.area.regridded`), the
    slip flag the nearest cell's, both zero outside the patch's cells in
    contact.  The forces stay the solve's: the cloud's sum of ``tau dA``
    falls short of them by what the move loses, the edge cells'
    interpolation (0.7% on a Hertzian patch of 24 x 18 cells, 2% on 13 x 9)
    and, where the ellipse is not the patch, its traction outside the
    patch (1-2.2% on the tests' egg).
    """
    if f.tau_x is None or f.tau_y is None or f.slip is None or f.grid is None:
        return f
    grid = (patch.x0, patch.y0, patch.dx, patch.dy)
    shape = (patch.pressure.shape[0], patch.pressure.shape[1])
    inside = patch.pressure > 0.0
    # the dissipation density moves as the tractions do (its sum stays the solve's)
    density = (None if f.dissipation_density is None else
               np.where(inside, regridded(f.dissipation_density, f.grid, grid, shape), 0.0))
    return ContactForces(f.fx, f.fy, f.mz, f.n, f.slip_fraction,
                         np.where(inside, regridded(f.tau_x, f.grid, grid, shape), 0.0),
                         np.where(inside, regridded(f.tau_y, f.grid, grid, shape), 0.0),
                         nearest_cells(f.slip, f.grid, grid, shape) & inside, grid,
                         f.dissipation, density)


@dataclass(frozen=True)
class PipelineConfig:
    """The checked parameters (see :mod:`fastsim_ros.ros.params`)."""

    values: Mapping[str, Any]

    @classmethod
    def from_values(cls, values: Mapping[str, Any]) -> PipelineConfig:
        """Check ``values`` (missing names take their defaults); raise ParameterError."""
        return cls(parameters.checked(values))

    def __getitem__(self, name: str) -> Any:
        return self.values[name]

    @property
    def contacts(self) -> tuple[str, ...]:
        """Return the configured contact names."""
        return tuple(self.values["contacts"])


class _ContactState:
    __slots__ = ("last_stamp_ns", "last_frame", "last_marker_ns", "wrench",
                 "stats", "reader", "frame_out", "result", "solved", "slope")

    def __init__(self) -> None:
        self.reader = CloudReader()  # the topic's header parsed once
        # the compiled path's outputs, read right after each call
        self.frame_out = np.empty(patch_kernels.OUT_SIZE)
        self.result = np.empty(fast.RESULT_SIZE)
        self.last_stamp_ns: int | None = None
        self.last_frame: ContactFrame | None = None
        self.last_marker_ns: int | None = None
        # the latest wrench in the wheelset frame: (stamp, force, torque)
        self.wrench: tuple[int, tuple[float, float, float], tuple[float, float, float]] | None
        self.wrench = None
        self.stats = ContactStats()
        # the latest solve (friction estimation's measurement model): patch, creepages, forces
        self.solved: tuple[ContactPatch, Creepage, ContactForces] | None = None
        # that solve's dFx/dmu_s, dFy/dmu_s (N, contact frame) where its march gave them
        self.slope: tuple[float, float] | None = None


class _ContactTopics:
    """A contact's output topics (relative names), built once."""

    __slots__ = ("wrench", "creepage", "frame", "traction", "wrench_cdr", "energy", "damage",
                 "vector_cdr")

    def __init__(self, contact: str) -> None:
        base = f"contact/{contact}/"
        self.wrench, self.creepage = base + "wrench", base + "creepage"
        self.frame, self.traction = base + "frame", base + "traction"
        self.energy, self.damage = base + "energy", base + "damage"
        # the contact's WrenchStamped, (Fx, Fy, N) and (0, 0, Mz): only numbers change
        self.wrench_cdr = stamped_doubles_template(out.contact_frame_id(contact), 6).encode
        # its Vector3Stamped (the creepage and the wear topics)
        self.vector_cdr = stamped_doubles_template(out.contact_frame_id(contact), 3).encode


class _Every:
    """Every topic: what :meth:`Pipeline.messages` encodes when not told otherwise."""

    def __contains__(self, topic: object) -> bool:
        return True


_EVERY = _Every()


#: pipeline_kernels.solve_cloud's memory in steady rolling
_STEADY_MEMORY = np.zeros(fast.MEMORY_SIZE)


def _frame_moved(a: ContactFrame | None, b: ContactFrame) -> bool:
    if a is None:
        return True
    if a.origin == b.origin and a.axes == b.axes:  # the usual case on a steady rig
        return False
    moved = max(abs(u - v) for u, v in zip(a.origin, b.origin))
    turned = max(abs(u - v) for ea, eb in zip(a.axes, b.axes) for u, v in zip(ea, eb))
    return moved > FRAME_TOLERANCE or turned > FRAME_TOLERANCE


def _newest_before(history: deque[StampedTwist], stamp_ns: int) -> StampedTwist | None:
    for twist in reversed(history):
        if twist.stamp_ns <= stamp_ns:
            return twist
    return None


class Pipeline:
    """Patches + kinematics -> creep forces, with the node's rules.

    Build it from a :class:`PipelineConfig`; feed it :meth:`on_wheel_twist`,
    :meth:`on_rail_twist` and :meth:`on_patch` in arrival (log-time) order;
    :meth:`update` changes the parameters that may change while running.
    """

    def __init__(self, config: PipelineConfig, *, solver: Any = None) -> None:
        self.config = config
        # a solver with MaeSolver's solve_arrays, used instead of the method's (the
        # command line's exact solver on patches from profiles)
        self._override = solver
        nu, g = config["poisson_ratio"], config["shear_modulus"]
        # one solver per method of parameters.METHODS (CalibratedMaeSolver is a MaeSolver)
        self._solvers: dict[str, MaeSolver | EquivalentEllipseSolver | PolachSolver] = {
            "mae": MaeSolver(nu, g), "mae_calibrated": CalibratedMaeSolver(nu, g),
            "fastsim_ellipse": EquivalentEllipseSolver(nu, g)}
        self._wheel: deque[StampedTwist] = deque(maxlen=TWIST_HISTORY)
        self._rail: deque[StampedTwist] = deque(maxlen=TWIST_HISTORY)
        # the twists last given to the compiled path, as its arrays (v, w)
        self._twist_arrays: dict[str, tuple[StampedTwist, np.ndarray]] = {}
        self._contacts = {name: _ContactState() for name in config.contacts}
        # transient rolling: each contact's traction between cycles (contact/transient.py)
        self._memories: dict[str, ContactMemory] = {}
        self._memory_key: tuple[Any, ...] | None = None
        # transient rolling's reset counts per contact, shared by its successive memories (a
        # method or rolling change starts a new memory; the counts carry on)
        self._reset_counts: dict[str, dict[str, int]] = {}
        # the last wheelset wrench's stamp (ns): a sum needs every contact's wrench newer
        self._last_sum_ns: int | None = None
        self._topics = {name: _ContactTopics(name) for name in config.contacts}
        self.kinematics_counts = {"wheel": 0, "rail": 0, "nonfinite": 0, "wrong_frame": 0,
                                  "old_stamp": 0, "malformed": 0}
        # online friction estimation (None: off); the measured wrenches (stamp, force)
        self._ekf: FrictionEkf | FrictionSlopeEkf | None = None
        self._friction = FrictionCycle(TWIST_HISTORY)
        # measured wrenches dropped, by reason (the twists' reasons)
        self.wrench_counts = {"nonfinite": 0, "wrong_frame": 0, "old_stamp": 0, "malformed": 0}
        self.estimation_counts = self._friction.counts
        self._apply(config)

    def _apply(self, config: PipelineConfig, changed: Collection[str] = ()) -> None:
        """Take ``config``; ``changed``: the parameters set at run time (:meth:`update`)."""
        self.config = config
        if config["method"] == "polach":  # kA, kS may change while running
            nu, g = config["poisson_ratio"], config["shear_modulus"]
            self._solvers["polach"] = PolachSolver(nu, g, k_a=float(config["polach_ka"]),
                                                   k_s=float(config["polach_ks"]))
        self._solver = self._override or self._solvers[config["method"]]
        self._bound = config["traction_bound"]
        self._frame_id = config["wheelset_frame"]
        self._max_cells = int(config["max_patch_cells"])
        self._max_age_ns = round(config["max_kinematics_age"] * 1e9)
        self._min_speed = float(config["min_rolling_speed"])
        self._rail_required = bool(config["rail_twist_required"])
        self._allow_implausible = bool(config["allow_implausible"])
        # the tractions are kept for the cloud, or for the frictional power (a sweep more)
        self._publish_tractions = bool(config["publish_traction"])
        self._tractions = self._publish_tractions or bool(config["frictional_power"])
        self._wear = bool(config["wear_outputs"])
        self._wear_function = PiecewiseLinear.of(config["wear_function_x"],
                                                 config["wear_function_y"])
        self._rcf_function = PiecewiseLinear.of(config["rcf_function_x"],
                                                config["rcf_function_y"])
        rate = float(config["marker_rate"])
        self._markers = bool(config["publish_markers"])
        self._marker_period_ns = 0 if rate == 0.0 else round(1e9 / rate)
        self._apply_estimation(config, changed)
        self._model_error_share = float(config["friction_model_error"])
        # the estimator's measurement model: the configured solver, law shape and bound
        # and the model of the (mu_s, k0) estimate's: its reduction's alpha_inf and beta too
        self._reduced_model = (self._solver, str(config["friction_law"]),
                               float(config["friction_limit_ratio"]),
                               float(config["friction_decay"]), str(self._bound),
                               float(config["slope_reduction_alpha_inf"]),
                               float(config["slope_reduction_beta"]))
        self._creep_model = CreepModel(self._solver,  # type: ignore[arg-type]
                                       str(config["friction_law"]),
                                       float(config["friction_limit_ratio"]),
                                       float(config["friction_decay"]), str(self._bound),
                                       reduction=self._reduction(config))
        mu = self._ekf.mu if self._ekf is not None else float(config["friction_coefficient"])
        self._use_mu(mu, config)

    def _use_mu(self, mu: float, config: PipelineConfig) -> None:
        """Solve with the static coefficient ``mu`` (the parameter's, or the estimate)."""
        self._mu = mu
        # None: constant friction (Coulomb's law, speed unused); else the law, run at |V|
        law = friction_law(str(config["friction_law"]), self._mu,
                           limit_ratio=float(config["friction_limit_ratio"]),
                           decay=float(config["friction_decay"]),
                           reduction=self._reduction(config))
        self._law: FrictionLaw | None = (law if law.slip_dependent or law.reduces_slope
                                         else None)
        # the compiled path (pipeline_kernels.solve_cloud): the MAE methods without
        # tractions; the solver's arguments as its solve_arrays passes them
        self._compiled: CompiledState | None = None
        solver = self._solver
        self._transient = config["rolling"] == "transient" and self._override is None
        # a new method or rolling: the contacts' memories start afresh; a new gap rule
        # applies to them from the next patch (their state and counts carry on)
        key = (self._transient, config["method"])
        if key != self._memory_key:
            self._memories = {}
            self._memory_key = key
        for memory in self._memories.values():
            memory.max_gap = float(config["transient_max_gap"])
        # the compiled path knows no slope reduction: the solver's solve_arrays applies it
        if isinstance(solver, MaeSolver) and not self._tractions and not law.reduces_slope:
            self._compiled = CompiledState.of(solver, self._bound, self._mu, self._law)

    def _reduction(self, config: PipelineConfig) -> SlopeReduction | None:
        """Return the creep-slope reduction in force: the parameters', ``k0`` the estimate's.

        With ``friction_estimate_slope_reduction`` the estimated ``k0`` with
        the configured ``alpha_inf`` and ``beta`` (None where that is no
        reduction), else :func:`~fastsim_ros.ros.params.slope_reduction_of`.
        """
        ekf = self._ekf
        if not isinstance(ekf, FrictionSlopeEkf):
            return slope_reduction_of(config)
        reduction = SlopeReduction(ekf.k0, float(config["slope_reduction_alpha_inf"]),
                                   float(config["slope_reduction_beta"]))
        return None if reduction.identity else reduction

    def _apply_estimation(self, config: PipelineConfig, changed: Collection[str] = ()) -> None:
        """Start the friction estimator (estimation on), or retune the running one.

        At run time ``friction_coefficient``, set (to any value, the one it
        had too), restarts the estimate from it, and ``friction_estimate_sigma``
        sets the estimate's uncertainty to it (an operator's new prior: the
        rail was cleaned, the estimate is not to be trusted); the other
        settings change how the estimate moves from then on.
        """
        if config["friction_estimation"] != "on":
            self._ekf = None
            return
        q, r = float(config["friction_process_noise"]), float(config["friction_measurement_noise"])
        gate = float(config["friction_min_sensitivity"])
        mu, sigma = float(config["friction_coefficient"]), float(config["friction_estimate_sigma"])
        spec = parameters.SPECS["friction_coefficient"]
        assert spec.low is not None and spec.high is not None
        if config["friction_estimate_slope_reduction"]:
            k0, sigma_k0 = (float(config["slope_reduction_k0"]),
                            float(config["friction_slope_sigma"]))
            q_k0 = float(config["friction_slope_process_noise"])
            ekf = self._ekf
            if not isinstance(ekf, FrictionSlopeEkf):
                k0_spec = parameters.SPECS["slope_reduction_k0"]
                assert k0_spec.low is not None and k0_spec.high is not None
                self._ekf = FrictionSlopeEkf(
                    mu, k0, sigma, sigma_k0, process_noise=q, process_noise_k0=q_k0,
                    measurement_noise=r, min_sensitivity=gate,
                    mu_bounds=(spec.low, spec.high), k0_bounds=(k0_spec.low, k0_spec.high))
                return
            ekf.process_noise, ekf.process_noise_k0, ekf.measurement_noise = q, q_k0, r
            ekf.min_sensitivity = gate
            if any(n in changed for n in ("friction_coefficient", "friction_estimate_sigma",
                                          "slope_reduction_k0", "friction_slope_sigma")):
                ekf.restart(sigma, mu if "friction_coefficient" in changed else None,
                            sigma_k0=sigma_k0,
                            k0=k0 if "slope_reduction_k0" in changed else None)
            return
        if self._ekf is None:
            # the estimate ranges over the parameter's own range: a friction_coefficient
            # the node takes is never clamped unseen (the filter's default was 0.01 to 2)
            self._ekf = FrictionEkf(mu, sigma, process_noise=q, measurement_noise=r,
                                    min_sensitivity=gate, mu_bounds=(spec.low, spec.high))
            return
        self._ekf.process_noise, self._ekf.measurement_noise = q, r
        self._ekf.min_sensitivity = gate
        if "friction_coefficient" in changed or "friction_estimate_sigma" in changed:
            self._ekf.restart(sigma, mu if "friction_coefficient" in changed else None)

    def update(self, changes: Mapping[str, Any]) -> None:
        """Apply new values of parameters (checked; the material and contacts stay)."""
        values = dict(self.config.values)
        values.update(changes)
        config = PipelineConfig.from_values(values)
        for name in ("contacts", "wheelset_frame", "shear_modulus", "poisson_ratio",
                     "friction_estimation", "friction_estimate_slope_reduction"):
            if config[name] != self.config[name]:
                raise ParameterError(f"parameter {name!r} is set at start only")
        self._apply(config, tuple(changes))

    def outputs(self) -> dict[str, str]:
        """Return every topic the pipeline publishes (relative, but /diagnostics) with its type."""
        topics = output_topics(self.config.contacts, wear=self._wear)
        if self._ekf is not None:
            topics[FRICTION_ESTIMATE_TOPIC] = "geometry_msgs/msg/Vector3Stamped"
        if isinstance(self._ekf, FrictionSlopeEkf):
            topics[SLOPE_ESTIMATE_TOPIC] = "geometry_msgs/msg/Vector3Stamped"
        return topics

    def inputs(self) -> tuple[InputTopic, ...]:
        """Return every input topic the pipeline takes, with its handler, in this order.

        The one table of inputs: a new input (a topic and its ``on_*``
        method) is added here, and the replay dispatches on it.
        """
        def kinematics(on: Callable[[bytes | memoryview], str]) -> InputHandler:
            def take(raw: bytes | memoryview) -> tuple[Outcome, ...]:
                on(raw)  # counted in kinematics_counts; no outcome
                return ()
            return take

        def patch(contact: str) -> InputHandler:
            def take(raw: bytes | memoryview) -> tuple[Outcome, ...]:
                return (self.on_patch(contact, raw),)
            return take

        twist = "geometry_msgs/msg/TwistStamped"
        measured = ((InputTopic(MEASURED_WRENCH_TOPIC, "geometry_msgs/msg/WrenchStamped",
                                "measured_wrench", None, kinematics(self.on_measured_wrench),
                                self.on_measured_wrench),)
                    if self._ekf is not None else ())
        return ((InputTopic(WHEEL_TWIST_TOPIC, twist, "wheel_twist", None,
                            kinematics(self.on_wheel_twist)),
                 InputTopic(RAIL_TWIST_TOPIC, twist, "rail_twist", None,
                            kinematics(self.on_rail_twist)))
                + measured
                + tuple(InputTopic(patch_topic(c), "sensor_msgs/msg/PointCloud2", "patch", c,
                                   patch(c)) for c in self.config.contacts))

    # ---------------------------------------------------------------- kinematics

    def _screened(self, message: StampedTwist | bytes | memoryview, last_ns: int | None
                  ) -> StampedTwist | str:
        """Return a twist or wrench (one CDR layout) screened, or why it is dropped.

        The kinematics' rules. Dropped: malformed, another frame than the
        wheelset's, non-finite, or a stamp older than ``last_ns`` (the last taken).
        """
        if not isinstance(message, StampedTwist):
            try:
                message = read_twist(message)
            except MalformedMessageError:
                return "malformed"
        if message.frame_id != self._frame_id:
            return "wrong_frame"
        if not twist_is_finite(message):
            return "nonfinite"
        if last_ns is not None and message.stamp_ns < last_ns:
            return "old_stamp"
        return message

    def _twist(self, history: deque[StampedTwist], twist: StampedTwist | bytes | memoryview,
               what: str) -> str:
        taken = self._screened(twist, history[-1].stamp_ns if history else None)
        if isinstance(taken, str):
            self.kinematics_counts[taken] += 1
            return taken
        history.append(taken)
        self.kinematics_counts[what] += 1
        return "ok"

    def on_wheel_twist(self, twist: StampedTwist | bytes | memoryview) -> str:
        """Take a wheelset twist (decoded or CDR); return ``"ok"`` or why it was dropped."""
        return self._twist(self._wheel, twist, "wheel")

    def on_rail_twist(self, twist: StampedTwist | bytes | memoryview) -> str:
        """Take a rail twist (roller, moving rail); return ``"ok"`` or why it was dropped."""
        return self._twist(self._rail, twist, "rail")

    def on_measured_wrench(self, wrench: StampedTwist | bytes | memoryview) -> str:
        """Take a measured wheelset wrench (``WrenchStamped``, CDR or decoded as a twist).

        The rig's measured force of the rails on the wheelset in the wheelset
        frame (``linear`` = force, N).  Dropped (counted in
        ``estimation_counts["dropped"]``) as a twist is: malformed, another
        frame, non-finite, older than the last.
        """
        measured = self._friction.measured
        taken = self._screened(wrench, measured[-1][0] if measured else None)
        if isinstance(taken, str):
            self.estimation_counts["dropped"] += 1
            self.wrench_counts[taken] += 1
            return taken
        f = taken.linear
        self._friction.add(taken.stamp_ns, (f[0], f[1], f[2]))
        return "ok"

    def _estimate(self, cycle: WheelsetWrench) -> FrictionEstimate:
        """Update the friction estimate with the cycle's measured force.x; use it from now on.

        The measurement and the filter's update are the estimator's cycle
        (:meth:`fastsim_ros.estimation.cycle.FrictionCycle.update`, given each
        contact's published solve and its march's slope); the estimate's
        ``mu_s`` (and ``k0``) is what the next patches are solved with.
        """
        ekf = self._ekf
        assert ekf is not None
        mu = self._mu
        status, utilisation = self._friction.update(
            ekf, cycle.stamp_ns, mu,
            [(state.solved, state.slope) for state in self._contacts.values()],
            self._max_age_ns, self._creep_model, self._model_error_share,
            self._reduced_model)
        if isinstance(ekf, FrictionSlopeEkf):
            reduction = self._law.reduction if self._law is not None else None
            if ekf.mu != mu or (reduction.k0 if reduction is not None else 1.0) != ekf.k0:
                self._use_mu(ekf.mu, self.config)  # the law and the compiled path anew
            return new_estimate(cycle.stamp_ns, ekf.mu, ekf.sigma, utilisation, status,
                                ekf.k0, ekf.sigma_k0, ekf.correlation)
        if ekf.mu != mu:  # as _use_mu, which gives the same law and state, for less
            self._mu = ekf.mu
            if self._law is not None:
                self._law = friction_law(str(self.config["friction_law"]), self._mu,
                                         limit_ratio=float(self.config["friction_limit_ratio"]),
                                         decay=float(self.config["friction_decay"]),
                                         reduction=self._reduction(self.config))
            if self._compiled is not None:  # only its mu_s depends on mu
                self._compiled = self._compiled.with_mu(self._mu)
        return new_estimate(cycle.stamp_ns, ekf.mu, ekf.sigma, utilisation, status)

    def kinematics(self, stamp_ns: int) -> tuple[StampedTwist, StampedTwist]:
        """Return the wheel and rail twists a patch stamped ``stamp_ns`` is solved with.

        Raises :class:`RejectedInput` (``no_kinematics``, ``stale_kinematics``).
        """
        return self._kinematics(stamp_ns)

    def _kinematics(self, stamp_ns: int) -> tuple[StampedTwist, StampedTwist]:
        wheel = _newest_before(self._wheel, stamp_ns)
        if wheel is None:
            if not self._wheel:
                raise RejectedInput("no_kinematics", "no wheelset twist yet")
            raise RejectedInput("stale_kinematics", "every wheelset twist is newer than "
                                "the patch")
        if stamp_ns - wheel.stamp_ns > self._max_age_ns:
            raise RejectedInput("stale_kinematics", f"newest wheelset twist is "
                                f"{(stamp_ns - wheel.stamp_ns) * 1e-9:.4g} s old")
        rail = _newest_before(self._rail, stamp_ns)
        if rail is not None and stamp_ns - rail.stamp_ns > self._max_age_ns:
            rail = None
        if rail is None:
            if self._rail_required:
                raise RejectedInput("stale_kinematics", "no fresh rail twist "
                                    "(rail_twist_required)")
            rail = REST
        return wheel, rail

    # ---------------------------------------------------------------- patches

    def on_patch(self, contact: str, cloud: Cloud | bytes | memoryview, *,
                 given: Solved | None = None) -> Outcome:
        """Solve one patch (decoded or CDR) of ``contact`` with the kinematics it matches.

        ``given``: the patch as converted, its creepages, forces and solve
        time (s), from :meth:`solve_patch` on this cloud's patch with this
        stamp's kinematics (profiles mode's load balance solved it already):
        then the stamp and frame are checked and the rest taken as given.
        """
        state = self._contacts[contact]
        stats = state.stats
        if not isinstance(cloud, Cloud):
            try:
                cloud = state.reader.read(cloud)
            except MalformedMessageError as e:  # not a PointCloud2: its fields are missing
                stats.counts["missing_field"] += 1
                stats.last_detail = f"missing_field: {e}"
                return Outcome(contact, -1, "missing_field", str(e))
        stamp = cloud.stamp_ns
        stats.window_inputs += 1
        if stats.window_first_ns is None:
            stats.window_first_ns = stamp
        stats.window_last_ns = stamp
        try:
            if cloud.frame_id != self._frame_id:
                raise RejectedInput("wrong_frame", f"frame {cloud.frame_id!r}, expected "
                                    f"{self._frame_id!r}")
            if state.last_stamp_ns is not None and stamp < state.last_stamp_ns:
                raise RejectedInput("old_stamp", f"stamp {stamp} ns is older than the last, "
                                    f"{state.last_stamp_ns} ns")
            done = None
            state.slope = None
            if given is not None:
                patch, creep, forces, seconds = given
                stats.add_solve_time(seconds)
            else:
                done = (self._solve_compiled(cloud, state, self._memory(contact))
                        if self._compiled is not None else None)
                if done is None:  # the Python path: it gives the reason of a rejection
                    converted = patch_from_cloud(cloud, max_cells=self._max_cells)
                    if converted is None:
                        return self._no_contact(contact, state, stamp)
                    patch = converted
                    wheel, rail = self._kinematics(stamp)
                    creep = creepages(patch.frame, wheel, rail)
                    if not abs(creep.speed) >= self._min_speed:
                        raise RejectedInput("standstill",
                                            f"rolling speed {creep.speed:.4g} m/s")
                    forces = self._solve(patch, creep, stats, self._memory(contact))
            if done is None:
                f_ws = patch.frame.to_wheelset((forces.fx, forces.fy, forces.n))
                m_ws = patch.frame.to_wheelset((0.0, 0.0, forces.mz))
                o = patch.frame.origin
                torque = (o[1] * f_ws[2] - o[2] * f_ws[1] + m_ws[0],
                          o[2] * f_ws[0] - o[0] * f_ws[2] + m_ws[1],
                          o[0] * f_ws[1] - o[1] * f_ws[0] + m_ws[2])
            else:
                patch, creep, forces, f_ws, torque = done
            if not self._allow_implausible:
                why = implausible(patch.pressure, patch.dx, patch.dy, patch.load, patch.cells,
                                  creep)
                if why is not None:
                    raise RejectedInput("implausible", why)
        except RejectedInput as e:
            stats.counts[e.reason] += 1
            stats.window_rejected += 1
            stats.last_detail = str(e)
            return Outcome(contact, stamp, e.reason, e.detail)
        # the last stamp is the last patch taken (a rejected one, a NaN stamped an hour ahead,
        # made every later patch of the contact old)
        state.last_stamp_ns = stamp
        stats.counts[SOLVED] += 1
        changed = _frame_moved(state.last_frame, patch.frame)
        if changed:
            state.last_frame = patch.frame
        state.solved = (patch, creep, forces)
        wheelset = self._add_wrench(state, stamp, f_ws, torque)
        friction = (self._estimate(wheelset) if wheelset is not None and self._ekf is not None
                    else None)
        return new_outcome(contact, stamp, SOLVED, "", patch.frame, changed, creep, forces,
                           patch, wheelset, self._markers_due(state, stamp), friction)

    def _twist_array(self, what: str, twist: StampedTwist) -> np.ndarray:
        """Return a twist's ``(v, w)`` as an array (built once per twist)."""
        last = self._twist_arrays.get(what)
        if last is not None and last[0] is twist:
            return last[1]
        values = np.array(twist.linear + twist.angular, dtype=np.float64)
        self._twist_arrays[what] = (twist, values)
        return values

    def _solve_compiled(self, cloud: Cloud, state: _ContactState,
                        memory: ContactMemory | None = None) -> tuple[
            ContactPatch, Creepage, ContactForces, tuple[float, float, float],
            tuple[float, float, float]] | None:
        """Solve a patch on the compiled path; None where the Python path must decide.

        Returns the patch, its creepages and forces, and its wrench in the
        wheelset frame (force, torque about the origin), each to the bit as
        the Python path gives them.  None for an input the Python path may
        reject (or find without contact): it then runs from the start.
        ``memory``: transient rolling's state, solved from here where it is
        carried over (no reset rule, the same grid); a reset, a resample or
        a jump is the Python path's (ContactMemory.solve), a few cycles in a run.
        """
        ny, nx = cloud.height, cloud.width
        if not 0 < ny * nx <= self._max_cells:
            return None
        mem: np.ndarray = _STEADY_MEMORY
        state_arrays: tuple[np.ndarray, ...] = fast.NO_STATE
        if memory is not None:
            carried = memory.carried(cloud.stamp_ns)
            if carried is None:
                return None
            previous, dt_ns = carried
            # in the order of pipeline_kernels.MEM_*
            mem = np.array((1.0, *previous.grid, dt_ns, memory.direction, *previous.force,
                            float(memory.solver.far_field), memory.solver.solver.nu,
                            *previous.far_slope))
            state_arrays = (previous.tau_x, previous.tau_y, np.empty((ny, nx)),
                            np.empty((ny, nx)), np.empty((ny, nx), dtype=np.bool_),
                            np.empty(contact_kernels.GEO_SIZE))
        try:
            words, row, step, cols = words_of(cloud)
            wheel, rail = self._kinematics(cloud.stamp_ns)
        except RejectedInput:
            return None
        assert self._compiled is not None
        (rule, parabolic, shear_modulus, knots, polys, law, prm, mu, slip_dependent,
         calibrated, pair_knots, pair_values, knee) = self._compiled
        pressure = np.empty((ny, nx))
        frame_out, result = state.frame_out, state.result
        prev_x, prev_y, out_x, out_y, out_slip, out_geo = state_arrays
        start = time.perf_counter()
        status = fast.solve_cloud(
            words, ny, nx, row, step, cols, pressure, frame_out,
            self._twist_array("wheel", wheel), self._twist_array("rail", rail),
            self._min_speed, rule, parabolic, shear_modulus, knots, polys, law, prm, mu,
            slip_dependent, calibrated, pair_knots, pair_values,
            self._ekf is not None and memory is None, result, mem, prev_x, prev_y, out_x,
            out_y, out_slip, out_geo, knee)
        elapsed = time.perf_counter() - start
        if status != fast.SOLVED:
            return None
        if memory is not None:  # ContactMemory.solve's state, kept unless the patch jumped
            _, _, tau_x, tau_y, _, geo = state_arrays
            sign = -1.0 if result[fast.SPEED] < 0.0 else 1.0  # the forces of the turned patch
            j_xx, j_xy, j_yx, j_yy = mem[fast.MEM_FAR_SLOPE:fast.MEM_FAR_SLOPE + 4].tolist()
            new = mae_state(tau_x, tau_y, previous.grid, geo,
                            (sign * float(result[fast.STATE_FX]),
                             sign * float(result[fast.STATE_FY])),
                            (j_xx, j_xy, j_yx, j_yy))
            (o0, o1, o2, ex0, ex1, ex2, ey0, ey1, ey2) = frame_out[
                patch_kernels.ORIGIN:patch_kernels.E_Y + 3].tolist()
            if not memory.take(cloud.stamp_ns, float(result[fast.SPEED]), new,
                               ((o0, o1, o2), (ex0, ex1, ex2), (ey0, ey1, ey2))):
                return None
        if self._ekf is not None and memory is None:  # estimation's slope, the same march
            state.slope = (float(result[fast.DFX_DMU]), float(result[fast.DFY_DMU]))
        # the adapter's loop and the solve, timed together on this path
        state.stats.add_solve_time(elapsed)
        (o0, o1, o2, ex0, ex1, ex2, ey0, ey1, ey2, ez0, ez1, ez2) = frame_out[
            patch_kernels.ORIGIN:patch_kernels.E_Z + 3].tolist()
        (x0, y0, dx, dy, load, cells, row_order, column_order, xi, eta, phi, speed, fx, fy,
         mz, n, slip_fraction, f0, f1, f2, t0, t1, t2) = result[:fast.DFX_DMU].tolist()
        frame = new_frame((o0, o1, o2), ((ex0, ex1, ex2), (ey0, ey1, ey2), (ez0, ez1, ez2)))
        patch = new_patch(cloud.stamp_ns, frame, pressure, x0, y0, dx, dy, load, int(cells),
                          int(row_order), int(column_order))
        return (patch, new_creepage(xi, eta, phi, speed),
                new_forces(fx, fy, mz, n, slip_fraction, None, None, None, None), (f0, f1, f2),
                (t0, t1, t2))

    def solve_patch(self, patch: ContactPatch, wheel: StampedTwist,
                    rail: StampedTwist = REST, *, method: str | None = None,
                    timing: list[float] | None = None) -> tuple[Creepage, ContactForces]:
        """Return the creepages and creep forces of one converted patch under given twists.

        The rules of :meth:`on_patch` (standstill, the solver's refusals as
        :class:`RejectedInput`), without its stamps, counts or outputs: the
        profiles patch source balances a wheel's vertical load with it.
        ``method``: another of the pipeline's methods than the configured one.
        """
        creep = creepages(patch.frame, wheel, rail)
        if not abs(creep.speed) >= self._min_speed:
            raise RejectedInput("standstill", f"rolling speed {creep.speed:.4g} m/s")
        if method is None or method == self.config["method"]:
            stats = ContactStats()
            forces = self._solve(patch, creep, stats)
            if timing is not None:
                timing.append(float(stats.solve_times[0]))
            return creep, forces
        configured, self._solver = self._solver, self._solvers[method]
        try:
            return creep, self._solve(patch, creep, ContactStats())
        finally:
            self._solver = configured

    def reject(self, contact: str, stamp_ns: int, reason: str, detail: str) -> Outcome:
        """Count an input of ``contact`` dropped upstream of its patch (profiles mode)."""
        stats = self._contacts[contact].stats
        stats.window_inputs += 1
        if stats.window_first_ns is None:
            stats.window_first_ns = stamp_ns
        stats.window_last_ns = stamp_ns
        stats.counts[reason] += 1
        stats.window_rejected += 1
        stats.last_detail = f"{reason}: {detail}"
        return Outcome(contact, stamp_ns, reason, detail)

    def _memory(self, contact: str) -> ContactMemory | None:
        """Return the contact's transient state (None when rolling is steady)."""
        if not self._transient:
            return None
        memory = self._memories.get(contact)
        if memory is None:
            # the parameters refuse transient rolling with Polach's closed form
            assert not isinstance(self._solver, PolachSolver)
            memory = ContactMemory(TransientSolver(self._solver),
                                   max_gap=float(self.config["transient_max_gap"]))
            # the contact's counts, cumulative as every other count
            memory.counts = self._reset_counts.setdefault(contact, memory.counts)
            self._memories[contact] = memory
        return memory

    def _no_contact(self, contact: str, state: _ContactState, stamp: int) -> Outcome:
        state.last_stamp_ns = stamp
        state.stats.counts[NO_CONTACT] += 1
        state.solved = None
        memory = self._memory(contact)
        if memory is not None:  # a lifted wheel: the next contact starts from zero traction
            memory.lose_contact(stamp)
        wheelset = self._add_wrench(state, stamp, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        friction = (self._estimate(wheelset) if wheelset is not None and self._ekf is not None
                    else None)
        return Outcome(contact, stamp, NO_CONTACT, "no cell with positive pressure",
                       wheelset=wheelset, markers=self._markers_due(state, stamp),
                       friction=friction)

    def _solve(self, patch: ContactPatch, creep: Creepage, stats: ContactStats,
               memory: ContactMemory | None = None) -> ContactForces:
        p, x0, y0, dx, dy = patch.pressure, patch.x0, patch.y0, patch.dx, patch.dy
        xi, eta, phi = creep.xi, creep.eta, creep.phi
        reverse = creep.speed < 0.0
        if reverse:  # turn the patch by 180 degrees about z: the leading edge at +x
            p, x0, y0 = turned_grid(p, x0, y0, dx, dy)
            phi = -phi
        start = time.perf_counter()
        try:
            if memory is None:
                f = self._solver.solve_arrays(p, x0, y0, dx, dy, xi, eta, phi, self._mu,
                                              bound=self._bound, tractions=self._tractions,
                                              friction=self._law, speed=abs(creep.speed))
            else:
                # transient: the distance rolled from the stamps, the rules of ContactMemory
                f, _ = memory.solve(patch.stamp_ns, creep.speed, p, x0, y0, dx, dy, xi, eta,
                                    phi, None if self._law else self._mu, bound=self._bound,
                                    friction=self._law, frame=(patch.frame.origin,
                                                               *patch.frame.axes[:2]))
                if not self._tractions:
                    f = ContactForces(f.fx, f.fy, f.mz, f.n, f.slip_fraction)
        except OutOfTableError as e:
            raise RejectedInput("out_of_table", str(e)) from None
        except ContactError as e:  # inputs the adapters passed but the solver refuses
            raise RejectedInput("nonfinite" if "finite" in str(e) else "degenerate",
                                str(e)) from None
        stats.add_solve_time(time.perf_counter() - start)
        if reverse:
            tau_x = tau_y = slip = density = None
            if f.tau_x is not None and f.tau_y is not None and f.slip is not None:
                tau_x, tau_y, slip = -f.tau_x[::-1, ::-1], -f.tau_y[::-1, ::-1], \
                    f.slip[::-1, ::-1]
            if f.dissipation_density is not None:  # a scalar field: turned, not negated
                density = f.dissipation_density[::-1, ::-1]
            grid = None
            if f.grid is not None:  # the turned grid's cell [0, 0] is the original's last
                gx0, gy0, gdx, gdy = f.grid
                n_y, n_x = (tau_x.shape if tau_x is not None else (1, 1))
                grid = (-(gx0 + (n_x - 1) * gdx), -(gy0 + (n_y - 1) * gdy), gdx, gdy)
            f = ContactForces(-f.fx, -f.fy, f.mz, f.n, f.slip_fraction, tau_x, tau_y, slip,
                              grid, f.dissipation, density)
        if not self._publish_tractions and f.tau_x is not None:
            # kept for the frictional power alone: its sum is taken, the fields go
            f = ContactForces(f.fx, f.fy, f.mz, f.n, f.slip_fraction,
                              dissipation=f.dissipation)
        if f.grid is not None and isinstance(self._solver, EquivalentEllipseSolver):
            f = _on_patch_cells(f, patch)
        isfinite = math.isfinite
        if not (isfinite(f.fx) and isfinite(f.fy) and isfinite(f.mz) and isfinite(f.n)):
            raise RejectedInput("nonfinite", "the solve gave a non-finite force")
        return f

    def _add_wrench(self, state: _ContactState, stamp: int, force: tuple[float, float, float],
                    torque: tuple[float, float, float]) -> WheelsetWrench | None:
        """Keep the contact's wrench; return the wheelset wrench if it completes a rig cycle.

        The node's rule, by the stamps: every contact has a wrench newer
        than those of the last sum, i.e. stamped after the last sum's stamp
        (the newest of its wrenches).  After a rejected patch of the contact
        that arrives first, one sum pairs the other contact's wrench of the
        previous cycle and the next cycle is whole again (a flag per contact
        would pair them so for good).
        :func:`fastsim_ros.replay.kernels.advance` is the replay's copy of
        this rule.
        """
        state.wrench = (stamp, force, torque)
        newest, last = stamp, self._last_sum_ns
        states = self._contacts.values()
        for s in states:
            w = s.wrench
            if w is None or (last is not None and w[0] <= last):
                return None  # some contact has no wrench newer than the last sum
            if w[0] > newest:
                newest = w[0]
        self._last_sum_ns = newest
        # summed contact by contact, in the contacts' order
        fx = fy = fz = tx = ty = tz = 0.0
        for s in states:
            assert s.wrench is not None
            _, (f0, f1, f2), (t0, t1, t2) = s.wrench
            fx += f0
            fy += f1
            fz += f2
            tx += t0
            ty += t1
            tz += t2
        return WheelsetWrench(newest, (fx, fy, fz), (tx, ty, tz))

    def _markers_due(self, state: _ContactState, stamp: int) -> bool:
        if not self._markers:
            return False
        last = state.last_marker_ns
        if last is not None and 0 <= stamp - last < self._marker_period_ns:
            return False
        state.last_marker_ns = stamp
        return True

    # ---------------------------------------------------------------- messages

    def messages(self, outcome: Outcome,
                 wanted: Container[str] | None = None) -> list[tuple[str, Any]]:
        """Return the ``(topic, message)`` pairs to publish for an outcome, in order.

        Each as CDR bytes (docs/guide_node.md): the contact's wrench and
        creepage, its frame when it moved, its traction cloud when asked
        for, its energy and damage (``wear_outputs``, :meth:`wear`), its
        marker when due, and the wheelset wrench when the rig cycle is
        complete.  ``wanted``: if given, only these topics are encoded
        (the node's topics that have subscribers).
        """
        if not outcome.has_wrench:
            return []
        c, stamp, frame_id = outcome.contact, outcome.stamp_ns, self._frame_id
        topics = self._topics[c]
        f = outcome.forces
        msgs: list[tuple[str, Any]] = []
        if wanted is None:
            wanted = _EVERY
        topic = topics.wrench
        if f is None or outcome.frame is None or outcome.creepage is None:
            if topic in wanted:
                msgs.append((topic, out.contact_wrench_cdr(stamp, c, 0.0, 0.0, 0.0, 0.0)))
            if self._wear:  # no contact: no energy, no wear, no damage
                if topics.energy in wanted:
                    msgs.append((topics.energy, topics.vector_cdr(stamp, 0.0, 0.0, 0.0)))
                if topics.damage in wanted:
                    msgs.append((topics.damage, topics.vector_cdr(stamp, 0.0, 0.0,
                                                                  math.nan)))
        else:
            if topic in wanted:  # (out.contact_wrench_cdr, from the contact's template)
                msgs.append((topic, topics.wrench_cdr(stamp, f.fx, f.fy, f.n, 0.0, 0.0, f.mz)))
            topic = topics.creepage
            if topic in wanted:  # (xi, eta, phi) in the contact's Vector3Stamped
                cr = outcome.creepage
                msgs.append((topic, topics.vector_cdr(stamp, cr.xi, cr.eta, cr.phi)))
            topic = topics.frame
            if outcome.frame_changed and topic in wanted:
                msgs.append((topic, out.pose_cdr(stamp, frame_id, outcome.frame)))
            topic = topics.traction
            if (self._publish_tractions and f.tau_x is not None and f.tau_y is not None
                    and f.slip is not None and f.grid is not None and topic in wanted):
                v = abs(outcome.creepage.speed)
                power = (None if f.dissipation_density is None
                         else f.dissipation_density * v)
                msgs.append((topic, out.traction_cloud_cdr(
                    stamp, frame_id, outcome.frame, f.tau_x, f.tau_y, f.slip, f.grid, power)))
            if self._wear:
                ind = self.wear(outcome)
                if ind is not None:
                    if topics.energy in wanted:
                        msgs.append((topics.energy, topics.vector_cdr(
                            stamp, ind.t_gamma, ind.t_gamma_per_area, ind.frictional_power)))
                    if topics.damage in wanted:
                        msgs.append((topics.damage, topics.vector_cdr(
                            stamp, ind.wear_rate, ind.rcf_damage, ind.slip_share)))
        if outcome.markers and MARKERS_TOPIC in wanted:
            index = self.config.contacts.index(c)
            fx, fy = (f.fx, f.fy) if f is not None else (0.0, 0.0)
            msgs.append((MARKERS_TOPIC, out.force_marker_cdr(
                stamp, frame_id, index, c, outcome.frame, fx, fy,
                float(self.config["marker_scale"]))))
        w = outcome.wheelset
        if w is not None and WHEELSET_WRENCH_TOPIC in wanted:
            msgs.append((WHEELSET_WRENCH_TOPIC, out.wrench_cdr(w.stamp_ns, frame_id, w.force,
                                                               w.torque)))
        e = outcome.friction
        if e is not None and FRICTION_ESTIMATE_TOPIC in wanted:
            msgs.append((FRICTION_ESTIMATE_TOPIC, stamped_doubles(
                e.stamp_ns, frame_id, (e.mu, e.sigma, e.utilisation))))
        if e is not None and SLOPE_ESTIMATE_TOPIC in wanted and not math.isnan(e.k0):
            msgs.append((SLOPE_ESTIMATE_TOPIC, stamped_doubles(
                e.stamp_ns, frame_id, (e.k0, e.sigma_k0, e.correlation))))
        return msgs

    def wear(self, outcome: Outcome) -> WearIndicators | None:
        """Return a solved outcome's wear and fatigue indicators (None without a solve).

        :func:`fastsim_ros.contact.wear.indicators` with the configured
        tables; ``A`` the patch's cells in contact times the cell area; the
        frictional power where the solve computed its dissipation (parameter
        ``frictional_power`` or ``publish_traction``, steady rolling), else NaN.
        """
        f, cr, p = outcome.forces, outcome.creepage, outcome.patch
        if f is None or cr is None or p is None:
            return None
        return indicators(f.fx, f.fy, f.mz, cr.xi, cr.eta, cr.phi, p.cells * p.dx * p.dy,
                          cr.speed, f.dissipation, wear=self._wear_function,
                          rcf=self._rcf_function)

    def diagnostics(self, stamp_ns: int,
                    extra: Mapping[str, Sequence[tuple[str, str]]] | None = None) -> Any:
        """Return the ``DiagnosticArray`` at ``stamp_ns``: one status per contact.

        Each carries the twist counts too (``twists/<what>``: taken for the
        wheel and the rail, dropped by reason), the kinematics being shared,
        then the key-values ``extra[contact]`` if given (the node's connections).
        """
        return out.diagnostic_array(stamp_ns, self._statuses(stamp_ns, extra))

    def _statuses(self, stamp_ns: int, extra: Mapping[str, Sequence[tuple[str, str]]] | None
                  ) -> list[tuple[str, int, str, Sequence[tuple[str, str]]]]:
        """Return the diagnostics' statuses (each contact's report starts a new rate window)."""
        twists = tuple((f"twists/{key}", str(v)) for key, v in self.kinematics_counts.items())
        if self._ekf is not None:  # the estimator's state, shared by the contacts
            slope = ((("friction_estimation/k0", f"{self._ekf.k0:.6g}"),
                      ("friction_estimation/sigma_k0", f"{self._ekf.sigma_k0:.3g}"))
                     if isinstance(self._ekf, FrictionSlopeEkf) else ())
            twists += (("friction_estimation/mu", f"{self._ekf.mu:.6g}"),
                       ("friction_estimation/sigma", f"{self._ekf.sigma:.3g}")) + slope + tuple(
                (f"friction_estimation/{key}", str(v))
                for key, v in self.estimation_counts.items()) + tuple(
                (f"measured_wrench/{key}", str(v)) for key, v in self.wrench_counts.items())
        statuses: list[tuple[str, int, str, Sequence[tuple[str, str]]]] = []
        for c in self.config.contacts:
            r = self.report(c)
            more = tuple(extra.get(c, ())) if extra is not None else ()
            statuses.append((r.name, r.level, r.message, r.values + twists + more))
        return statuses

    def diagnostics_cdr(self, stamp_ns: int,
                        extra: Mapping[str, Sequence[tuple[str, str]]] | None = None) -> bytes:
        """Return :meth:`diagnostics`' message as CDR bytes, written without its objects."""
        return out.diagnostic_array_cdr(stamp_ns, self._statuses(stamp_ns, extra))

    # ---------------------------------------------------------------- diagnostics

    def latest_wrench(self, contact: str) -> tuple[int, tuple[float, float, float],
                                                   tuple[float, float, float]] | None:
        """Return the contact's latest wrench in the wheelset frame ``(stamp, F, M)``."""
        return self._contacts[contact].wrench

    def solve_time_percentiles(self, contact: str) -> tuple[float, float]:
        """Return the p50 and p99 (us) of the contact's last solves (NaN before any)."""
        return self._contacts[contact].stats.percentiles_us()

    def counts(self, contact: str) -> dict[str, int]:
        """Return a copy of the contact's cumulative counts by status."""
        return dict(self._contacts[contact].stats.counts)

    def republish_frame(self, contact: str) -> None:
        """Have the contact's next solve publish its frame, moved or not.

        The frame is published when it changes, to whoever
        subscribes then: on a steady rig a subscriber that joins later (a
        viewer started after the node) never got one.  The node calls this
        when the frame's topic gains a subscriber.
        """
        self._contacts[contact].last_frame = None

    def report(self, contact: str) -> ContactReport:
        """Return the contact's diagnostics and start a new rate window."""
        stats = self._contacts[contact].stats
        p50, p99 = stats.percentiles_us()
        rate = 0.0
        first, last = stats.window_first_ns, stats.window_last_ns
        if first is not None and last is not None and last > first:
            rate = (stats.window_inputs - 1) / ((last - first) * 1e-9)
        rejected = sum(stats.counts[r] for r in REJECTION_REASONS)
        values: list[tuple[str, str]] = [
            ("method", self.config["method"]),
            ("friction_law", self.config["friction_law"]),
            ("friction_coefficient", f"{self._mu:g}"),
            ("friction_limit_ratio", f"{self.config['friction_limit_ratio']:g}"),
            ("friction_decay", f"{self.config['friction_decay']:g}"),
            ("slope_reduction", "k0 {:g}, alpha_inf {:g}, beta {:g}".format(
                self.config["slope_reduction_k0"], self.config["slope_reduction_alpha_inf"],
                self.config["slope_reduction_beta"])),
            ("traction_bound", self._bound),
            ("solve_time_p50_us", f"{p50:.1f}"),
            ("solve_time_p99_us", f"{p99:.1f}"),
            ("input_rate_hz", f"{rate:.1f}"),
            ("wrenches", str(stats.counts[SOLVED] + stats.counts[NO_CONTACT])),
            ("solved", str(stats.counts[SOLVED])),
            ("no_contact", str(stats.counts[NO_CONTACT])),
            ("rejected", str(rejected)),
        ]
        values += [(f"rejected/{r}", str(stats.counts[r])) for r in REJECTION_REASONS]
        values.append(("rolling", str(self.config["rolling"])))
        if self._transient:  # why the contact's traction state was reset (transient.py)
            counts = self._reset_counts.get(contact, {})
            values += [(f"transient/{r}", str(counts.get(r, 0))) for r in RESET_REASONS]
        # the counts above are since the start; these and the message, of the last period
        values += [("this_period/patches", str(stats.window_inputs)),
                   ("this_period/rejected", str(stats.window_rejected)),
                   (SINCE_START_KEY, SINCE_START)]
        level, message = 0, "ok"
        if stats.window_inputs == 0:
            level, message = 1, "no patch in the last period"
        elif stats.window_rejected:
            level, message = 1, (f"{stats.window_rejected} of {stats.window_inputs} patches "
                                 f"rejected this period; last: {stats.last_detail}")
        stats.window_inputs = stats.window_rejected = 0
        stats.window_first_ns = stats.window_last_ns = None
        return ContactReport(f"fastsim: {contact}", level, message, tuple(values))
