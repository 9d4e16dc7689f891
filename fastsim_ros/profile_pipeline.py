"""The pipeline in profiles mode: wheelset poses (and loads) in, patches and creep forces out.

INTERFACE.md ("Patches from wheel and rail profiles"): a rig knows its
profiles and measures the wheelset's pose and loads.  :class:`ProfilePipeline`
wraps the :class:`~fastsim_ros.pipeline.Pipeline` of the patch topics: for
each ``wheelset/pose`` it places the wheelset
(:class:`~fastsim_ros.geometry.wheelset.Wheelset`), finds both wheels'
patches and solves their normal problem, balancing each wheel's vertical
load with the creep forces the wrapped pipeline computes (its rigid-body
creepages, its solver: there is no second formula), then hands every patch
to the wrapped pipeline exactly as if it had arrived on
``contact/<name>/patch``.  The patches are returned for publishing on those
topics, so a recording replays in either mode.

Contacts are fixed per wheel: ``left``/``right`` for the patch nearer the
tread, ``left_flange``/``right_flange`` for a second one; a name with no
patch this cycle gets an empty patch, i.e. a zero wrench (``no_contact``).
A pose the geometry cannot serve (past the flange, off the rail head,
profiles that do not meet) is dropped for every contact as ``derailment``;
missing or stale kinematics as in topics mode.  Like the wrapped pipeline it
reads no clock: stamps come from the messages.

Loads: the newest ``wheelset/load`` not after the pose and at most
``max_kinematics_age`` older (``force.z`` the total, ``torque.x`` the roll
moment: the left wheel carries ``(F + M/b)/2`` with ``b`` the wheel
profile's lateral offset); else ``wheel_load`` per wheel; else (``0``) the
pose's vertical position as given.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Container, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from fastsim_ros.contact.errors import ContactError
from fastsim_ros.geometry.errors import DerailmentError, GeometryError, NoContactError
from fastsim_ros.geometry.placement import Placement, Pose
from fastsim_ros.geometry.profiles import read_profile
from fastsim_ros.geometry.wheelset import (SIDES, Side, Vector, WheelPatch, Wheelset,
                                           WheelsetContact)
from fastsim_ros.params import PROFILE_CONTACTS, SPECS, ParameterError
from fastsim_ros.pipeline import (RAIL_TWIST_TOPIC, WHEEL_TWIST_TOPIC, InputTopic, Outcome,
                                  Pipeline, PipelineConfig, output_topics, patch_topic)
from msg_adapters.cdr import Cloud, StampedTwist
from msg_adapters.errors import MalformedMessageError, RejectedInput
from msg_adapters.patch import MIN_CONTACT_CELLS, patch_from_cloud
from msg_adapters.profile_msgs import (StampedPose, cloud_cdr, patch_cloud, read_load,
                                       read_pose)

POSE_TOPIC, LOAD_TOPIC = "wheelset/pose", "wheelset/load"
#: loads kept for matching pose stamps
LOAD_HISTORY = 1024


def contact_name(side: Side, index: int) -> str:
    """Return the contact name of a wheel's patch: 0 the tread's, 1 a second one."""
    return side if index == 0 else f"{side}_flange"


def placement_of(values: Any) -> Placement:
    """Return the placement from checked parameters (or any mapping of its names)."""
    return Placement(gauge_width=float(values["gauge_width"]),
                     gauge_height=float(values["gauge_height"]),
                     cant=float(values["cant"]),
                     flange_back_distance=float(values["flange_back_distance"]),
                     flange_back_position=float(values["flange_back_position"]),
                     nominal_radius=float(values["nominal_radius"]))


def wheelset_of(config: PipelineConfig) -> Wheelset:
    """Read the profiles and place them; a bad file or value raises ParameterError (one line)."""
    smooth = float(config["profile_smoothing"])
    try:
        wheel = read_profile(config["wheel_profile"], kind="wheel", smooth=smooth)
        rail = read_profile(config["rail_profile"], kind="rail", smooth=smooth)
        right_wheel = (read_profile(config["right_wheel_profile"], kind="wheel", smooth=smooth)
                       if config["right_wheel_profile"] else None)
        right_rail = (read_profile(config["right_rail_profile"], kind="rail", smooth=smooth)
                      if config["right_rail_profile"] else None)
        d_sep, d_comb = float(config["separation_distance"]), float(config["combination_distance"])
        if d_comb > d_sep:
            raise ParameterError(f"parameter 'combination_distance' ({d_comb:g} m) must be at "
                                 f"most separation_distance ({d_sep:g} m)")
        return Wheelset(wheel, rail, placement_of(config.values), right_wheel=right_wheel,
                        right_rail=right_rail, cell=float(config["cell_size"]),
                        shear_modulus=float(config["shear_modulus"]),
                        poisson_ratio=float(config["poisson_ratio"]), d_sep=d_sep,
                        d_comb=d_comb)
    except ContactError as e:
        raise ParameterError(str(e)) from None


@dataclass(frozen=True, eq=False)
class ProfileCycle:
    """What one pose gave.

    ``patches``: ``(name, cloud)`` for all four names, in order; ``outcomes``:
    the wrapped pipeline's, one per contact; ``contact``: the geometry
    (``None`` when the pose was dropped); ``loads``: the wheel loads used.
    """

    stamp_ns: int
    patches: tuple[tuple[str, Cloud], ...]
    outcomes: tuple[Outcome, ...]
    contact: WheelsetContact | None
    loads: tuple[float, float] | None


class ProfilePipeline:
    """Poses + loads + twists -> patches -> the pipeline's outputs (INTERFACE.md)."""

    def __init__(self, config: PipelineConfig, *, solve_roll: bool = False,
                 solver: Any = None) -> None:
        if config["patch_source"] != "profiles":
            raise ParameterError("a ProfilePipeline needs patch_source: profiles")
        self.pipeline = Pipeline(config, solver=solver)
        self.wheelset = wheelset_of(config)
        self.solve_roll = solve_roll
        self._loads: deque[StampedTwist] = deque(maxlen=LOAD_HISTORY)
        self._last_pose_ns: int | None = None
        self._clouds: dict[str, Cloud] = {}
        self.pose_counts = {"pose": 0, "load": 0, "malformed": 0, "wrong_frame": 0,
                            "nonfinite": 0, "old_stamp": 0}

    @property
    def config(self) -> PipelineConfig:
        """Return the wrapped pipeline's configuration."""
        return self.pipeline.config

    # --- the wrapped pipeline's face, for the node and the replay

    @property
    def kinematics_counts(self) -> dict[str, int]:
        """Return the twists' counts and the poses and loads dropped (``pose_<reason>``).

        The poses and loads taken are in :attr:`pose_counts`.
        """
        dropped = {f"pose_{k}": v for k, v in self.pose_counts.items()
                   if k not in ("pose", "load") and v}
        return {**self.pipeline.kinematics_counts, **dropped}

    def counts(self, contact: str) -> dict[str, int]:
        """Return a contact's cumulative counts by status."""
        return self.pipeline.counts(contact)

    def solve_time_percentiles(self, contact: str) -> tuple[float, float]:
        """Return a contact's solve-time p50 and p99 (us)."""
        return self.pipeline.solve_time_percentiles(contact)

    def diagnostics(self, stamp_ns: int,
                    extra: Mapping[str, Sequence[tuple[str, str]]] | None = None) -> Any:
        """Return the wrapped pipeline's ``DiagnosticArray``, the poses' counts added.

        ``extra``: more key-values per contact (the node's matched peers).
        """
        counts = tuple((f"poses/{k}", str(v)) for k, v in self.pose_counts.items())
        merged = {c: tuple((extra or {}).get(c, ())) + counts for c in self.config.contacts}
        return self.pipeline.diagnostics(stamp_ns, merged)

    def outputs(self) -> dict[str, str]:
        """Return every topic profiles mode publishes: the pipeline's and the patches."""
        return output_topics(self.config.contacts, patches=True)

    def inputs(self) -> tuple[InputTopic, ...]:
        """Return the input topics of profiles mode: the twists, the pose and the load."""
        def kinematics(on: Any) -> Any:
            def take(raw: bytes | memoryview) -> tuple[Outcome, ...]:
                on(raw)
                return ()
            return take

        def pose(raw: bytes | memoryview) -> tuple[Outcome, ...]:
            return self.on_pose(raw).outcomes

        twist = "geometry_msgs/msg/TwistStamped"
        return (InputTopic(WHEEL_TWIST_TOPIC, twist, "wheel_twist", None,
                           kinematics(self.on_wheel_twist)),
                InputTopic(RAIL_TWIST_TOPIC, twist, "rail_twist", None,
                           kinematics(self.on_rail_twist)),
                InputTopic(LOAD_TOPIC, "geometry_msgs/msg/WrenchStamped", "load", None,
                           kinematics(self.on_load)),
                InputTopic(POSE_TOPIC, "geometry_msgs/msg/PoseStamped", "pose", None, pose))

    def messages(self, outcome: Outcome,
                 wanted: Container[str] | None = None) -> list[tuple[str, Any]]:
        """Return the ``(topic, message)`` pairs of an outcome: its patch, then the pipeline's.

        The patch (CDR bytes) goes out with every outcome of the pose it
        came from, solved or refused by the solver; a pose dropped whole has
        no patches.  ``wanted``: if given, only these topics are encoded.
        """
        cloud = self._clouds.get(outcome.contact)
        head: list[tuple[str, Any]] = []
        topic = patch_topic(outcome.contact)
        if (cloud is not None and cloud.stamp_ns == outcome.stamp_ns
                and (wanted is None or topic in wanted)):
            head.append((topic, cloud_cdr(cloud)))
        return head + self.pipeline.messages(outcome, wanted)

    def update(self, changes: dict[str, Any]) -> None:
        """Apply changes of parameters that may change while running (the rest are refused)."""
        for name, value in changes.items():
            spec = SPECS.get(name)
            if spec is not None and not spec.dynamic and value != self.config[name]:
                raise ParameterError(f"parameter {name!r} is set at start only")
        self.pipeline.update(changes)

    # ------------------------------------------------------------------ inputs

    def on_wheel_twist(self, twist: StampedTwist | bytes | memoryview) -> str:
        """Take a wheelset twist (see :meth:`Pipeline.on_wheel_twist`)."""
        return self.pipeline.on_wheel_twist(twist)

    def on_rail_twist(self, twist: StampedTwist | bytes | memoryview) -> str:
        """Take a rail twist (see :meth:`Pipeline.on_rail_twist`)."""
        return self.pipeline.on_rail_twist(twist)

    def on_load(self, load: StampedTwist | bytes | memoryview) -> str:
        """Take a ``wheelset/load`` (``linear`` the force, ``angular`` the torque): "ok" or why."""
        if not isinstance(load, StampedTwist):
            try:
                load = read_load(load)
            except MalformedMessageError:
                self.pose_counts["malformed"] += 1
                return "malformed"
        if load.frame_id != self.config["wheelset_frame"]:
            reason = "wrong_frame"
        elif not all(math.isfinite(v) for v in load.linear + load.angular) \
                or min(self.split_load(load.linear[2], load.angular[0])) < 0.0:
            reason = "nonfinite"  # a negative share cannot press a wheel onto its rail
        elif self._loads and load.stamp_ns < self._loads[-1].stamp_ns:
            reason = "old_stamp"
        else:
            self._loads.append(load)
            self.pose_counts["load"] += 1
            return "ok"
        self.pose_counts[reason] += 1
        return reason

    def wheel_loads(self, stamp_ns: int) -> tuple[float, float] | None:
        """Return the per-wheel loads (N) for a pose stamped ``stamp_ns``, or ``None``.

        A share of zero lifts that wheel (no patches, a zero wrench).
        """
        max_age = round(float(self.config["max_kinematics_age"]) * 1e9)
        for load in reversed(self._loads):
            if load.stamp_ns <= stamp_ns:
                if stamp_ns - load.stamp_ns <= max_age:
                    return self.split_load(load.linear[2], load.angular[0])
                break
        per_wheel = float(self.config["wheel_load"])
        return (per_wheel, per_wheel) if per_wheel > 0.0 else None

    def split_load(self, total: float, roll_moment: float) -> tuple[float, float]:
        """Return the left and right wheels' shares of a load ``total`` (N), moment ``M`` (N m)."""
        b = self.wheelset.placement.wheel_offset
        return (0.5 * (total + roll_moment / b), 0.5 * (total - roll_moment / b))

    # ------------------------------------------------------------------ a cycle

    def on_pose(self, pose: StampedPose | bytes | memoryview) -> ProfileCycle:
        """Compute both wheels' patches for one pose and solve them (one rig cycle)."""
        if not isinstance(pose, StampedPose):
            try:
                pose = read_pose(pose)
            except MalformedMessageError as e:
                self.pose_counts["malformed"] += 1
                return self._dropped(-1, "missing_field", f"not a PoseStamped: {e}")
        stamp = pose.stamp_ns
        if pose.frame_id != self.config["track_frame"]:
            self.pose_counts["wrong_frame"] += 1
            return self._dropped(stamp, "wrong_frame", f"pose frame {pose.frame_id!r}, "
                                 f"expected {self.config['track_frame']!r}")
        if not pose.is_finite():
            self.pose_counts["nonfinite"] += 1
            return self._dropped(stamp, "nonfinite", "NaN or infinite values in the pose")
        if self._last_pose_ns is not None and stamp < self._last_pose_ns:
            self.pose_counts["old_stamp"] += 1
            return self._dropped(stamp, "old_stamp", f"pose stamp {stamp} ns is older than "
                                 f"the last, {self._last_pose_ns} ns")
        self._last_pose_ns = stamp
        self.pose_counts["pose"] += 1
        try:
            roll, yaw = pose.roll_yaw()
            wheelset_pose = Pose(dy=pose.position[1], dz=pose.position[2], yaw=yaw, roll=roll)
        except (MalformedMessageError, GeometryError) as e:
            return self._dropped(stamp, "nonfinite", str(e))
        try:
            wheel, rail = self.pipeline.kinematics(stamp)
        except RejectedInput as e:
            return self._dropped(stamp, e.reason, e.detail)
        loads = self.wheel_loads(stamp)
        try:
            contact = self.solve(wheelset_pose, wheel, rail, stamp, loads=loads)
        except RejectedInput as e:
            return self._dropped(stamp, e.reason, e.detail)
        except (DerailmentError, NoContactError) as e:
            return self._dropped(stamp, "derailment", str(e))
        except ContactError as e:
            return self._dropped(stamp, "degenerate", str(e))
        patches = self.clouds(contact, stamp)
        self._clouds = dict(patches)
        outcomes = tuple(self.pipeline.on_patch(name, cloud) for name, cloud in patches)
        return ProfileCycle(stamp, patches, outcomes, contact, loads)

    def solve(self, pose: Pose, wheel: StampedTwist, rail: StampedTwist, stamp_ns: int, *,
              loads: tuple[float, float] | None) -> WheelsetContact:
        """Return both wheels' contacts at a pose under the twists (creep forces balanced)."""
        frame = self.config["wheelset_frame"]
        max_cells = int(self.config["max_patch_cells"])

        def creep_forces(side: Side, patches: Sequence[WheelPatch]) -> list[Vector]:
            rot = pose.rotation()
            out: list[Vector] = []
            for wp in patches:
                cloud = patch_cloud(stamp_ns, frame, *wp.cloud_arrays())
                try:
                    patch = patch_from_cloud(cloud, max_cells=max_cells)
                    if patch is None:
                        raise RejectedInput("degenerate", "an empty patch")
                    try:
                        _, f = self.pipeline.solve_patch(patch, wheel, rail)
                    except RejectedInput as e:
                        if e.reason in ("standstill", "too_large", "nonfinite"):
                            raise
                        # a patch the method refuses (an MAE zone beyond its tables, a
                        # sliver at a trial position): the balance takes FastSim on its
                        # equivalent ellipse, so that it stays continuous; on_patch then
                        # solves, or refuses, the final patch with the configured method
                        _, f = self.pipeline.solve_patch(patch, wheel, rail,
                                                         method="fastsim_ellipse")
                except RejectedInput as e:
                    if e.reason in ("standstill", "too_large", "nonfinite"):
                        raise
                    out.append((0.0, 0.0, 0.0))
                    continue
                f_w = patch.frame.to_wheelset((f.fx, f.fy, 0.0))
                f_t = rot @ np.asarray(f_w)
                out.append((float(f_t[0]), float(f_t[1]), float(f_t[2])))
            return out

        return self.wheelset.solve(pose, loads=loads, solve_roll=self.solve_roll,
                                   tangential=creep_forces)

    def clouds(self, contact: WheelsetContact, stamp_ns: int) -> tuple[tuple[str, Cloud], ...]:
        """Return the patch cloud of each of the four contacts (empty without such a patch)."""
        frame = self.config["wheelset_frame"]
        by_name: dict[str, Cloud] = {}
        for wheel in contact.wheels:
            for index, wp in enumerate(_tread_first(wheel.patches)):
                by_name[contact_name(wheel.side, index)] = patch_cloud(
                    stamp_ns, frame, *wp.cloud_arrays())
        empty = np.zeros((0, 0))
        return tuple((name, by_name.get(name) or patch_cloud(stamp_ns, frame, np.zeros((0, 0, 3)),
                                                             np.zeros(3), empty))
                     for name in PROFILE_CONTACTS)

    def _dropped(self, stamp: int, reason: str, detail: str) -> ProfileCycle:
        outcomes = tuple(self.pipeline.reject(name, stamp, reason, detail)
                         for name in PROFILE_CONTACTS)
        return ProfileCycle(stamp, (), outcomes, None, None)


#: either pipeline: what the node and the replay drive (inputs, outputs, messages, counts)
AnyPipeline = Pipeline | ProfilePipeline


def make_pipeline(config: PipelineConfig) -> AnyPipeline:
    """Return the pipeline of the configured patch source (the node's and the replay's)."""
    if config["patch_source"] == "profiles":
        return ProfilePipeline(config)
    return Pipeline(config)


def _tread_first(patches: Sequence[WheelPatch]) -> list[WheelPatch]:
    """Order a wheel's patches: nearest the tread (the field side, larger side-frame y) first."""
    return sorted(patches, key=lambda p: -p.region.reference[1])


__all__ = ["LOAD_TOPIC", "POSE_TOPIC", "ProfileCycle", "ProfilePipeline", "SIDES",
           "contact_name", "make_pipeline", "placement_of", "wheelset_of", "MIN_CONTACT_CELLS"]
