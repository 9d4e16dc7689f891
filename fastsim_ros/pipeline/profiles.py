"""The pipeline in profiles mode: wheelset poses (and loads) in, patches and creep forces out.

docs/guide_profiles.md: a rig knows its
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

With ``profile_table`` the patches come from a contact table
(:mod:`~fastsim_ros.geometry.table`) solved over lateral shift and yaw at the
reference load ``wheel_load`` when the pipeline starts (or read from
``table_cache``): each pose then costs a lookup, a blend and the vertical
balance with the creep forces on the Hertz-similar scale of the patches,
about a millisecond instead of 20-200.  The pose's roll and height are not
used then: the table's roll is the one at which both rigid wheels touch, the
height follows from the loads.  A pose outside the table is dropped as
``out_of_table``.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Container, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal, Protocol

import numpy as np

from fastsim_ros.ros import plausibility
from fastsim_ros.contact.errors import ContactError
from fastsim_ros.geometry.errors import DerailmentError, GeometryError, NoContactError
from fastsim_ros.geometry.placement import Placement, Pose, rotation
from fastsim_ros.geometry.profiles import Profile, expand_path, read_profile
from fastsim_ros.geometry.table import (ContactTable, TableError, TableGrid, TablePatch,
                                        TableRangeError, cached_table)
from fastsim_ros.geometry.table import warm_up as table_warm_up
from fastsim_ros.geometry.wheelset import (SIDES, Side, Vector, WheelPatch, Wheelset,
                                           WheelsetContact)
from fastsim_ros.ros.params import PROFILE_CONTACTS, SPECS, ParameterError
from fastsim_ros.pipeline.outcomes import Outcome, Solved
from fastsim_ros.pipeline.steady import Pipeline, PipelineConfig
from fastsim_ros.pipeline.topics import (RAIL_TWIST_TOPIC, WHEEL_TWIST_TOPIC, InputTopic,
                                         output_topics, patch_topic)
from msg_adapters.cdr import Cloud, StampedTwist
from msg_adapters.errors import MalformedMessageError, RejectedInput
from msg_adapters.patch import (MIN_CONTACT_CELLS, ContactFrame, ContactPatch, contact_axes,
                                patch_from_cloud)
from msg_adapters.profile_msgs import (StampedPose, cloud_cdr, patch_cloud, read_load,
                                       read_pose)

POSE_TOPIC, LOAD_TOPIC = "wheelset/pose", "wheelset/load"
#: loads kept for matching pose stamps
LOAD_HISTORY = 1024
#: the largest wheel load taken (N): wheel_load's own range, and the wheelset solve's
MAX_WHEEL_LOAD = 1.0e7
#: the table's vertical balance with the creep forces: to this share of the load (1 N at
#: 10 kN: the creep forces then err by 1e-4 of themselves, twenty times below the table's
#: median interpolation error, docs/validation_table.md), in at most BALANCE_ITERATIONS
#: secant steps on the scale s^3; where the patch's cells step (a cell more or less at a
#: new scale) it may stop at ACCEPT_BALANCE
BALANCE_TOLERANCE = 1e-4
ACCEPT_BALANCE = 1e-3
BALANCE_ITERATIONS = 12


class CloudSource(Protocol):
    """A solved patch that gives its cloud: ``points, normal, pressure`` (wheelset frame)."""

    def cloud_arrays(self) -> tuple[Any, Any, Any]:
        """Return the cell centres (m), the normal and the pressure (Pa)."""


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


def table_grid_of(config: PipelineConfig) -> TableGrid:
    """Return the contact table's grid from the ``table_*`` parameters (ParameterError if bad)."""
    dy_min, dy_max = float(config["table_dy_min"]), float(config["table_dy_max"])
    if dy_min > dy_max:
        raise ParameterError(f"parameters 'table_dy_min' ({dy_min:g} m) and 'table_dy_max' "
                             f"({dy_max:g} m): the smallest shift must not exceed the largest")
    try:
        return TableGrid.regular(dy_min, dy_max, float(config["table_dy_step"]),
                                 float(config["table_yaw_max"]), float(config["table_yaw_step"]))
    except TableError as e:
        raise ParameterError("contact table parameters 'table_dy_min', 'table_dy_max', "
                             f"'table_dy_step', 'table_yaw_max', 'table_yaw_step': {e}") from None


def table_of(config: PipelineConfig, wheelset: Wheelset,
             log: Callable[[str], None] | None = None) -> ContactTable:
    """Return the contact table of a configuration: read from ``table_cache`` or built there.

    Its reference load is ``wheel_load``, which must be positive.
    """
    load = float(config["wheel_load"])
    if load <= 0.0:
        raise ParameterError("parameter 'wheel_load': profile_table needs the reference wheel "
                             "load (N) > 0")
    cache = str(config["table_cache"])
    try:
        directory = expand_path(cache) if cache else None
    except ValueError as e:
        raise ParameterError(f"parameter 'table_cache': {e}") from None
    return cached_table(wheelset, table_grid_of(config), load, directory,
                        refine=int(config["table_refine"]), log=log)


def table_contact_patch(patch: TablePatch, stamp_ns: int, *, max_cells: int) -> ContactPatch:
    """Return a table patch as the adapter makes it of its cloud (to rounding), cloud skipped.

    The table's patches lie in the adapter's contact frame (``x`` the
    wheelset's projected) with their pressure centroid at the origin, so the
    frame and grid are the table's own; the adapter's bounds still apply.
    """
    ny, nx = patch.pressure.shape
    if ny * nx > max_cells:
        raise RejectedInput("too_large", f"{ny} x {nx} cells exceed max_patch_cells = "
                            f"{max_cells}")
    if patch.cells < MIN_CONTACT_CELLS:
        raise RejectedInput("degenerate", f"{patch.cells} cells in contact")
    o, n = patch.origin, patch.normal
    frame = ContactFrame((float(o[0]), float(o[1]), float(o[2])),
                         contact_axes((float(n[0]), float(n[1]), float(n[2]))))
    return ContactPatch(stamp_ns, frame, patch.pressure, patch.a0, patch.b0, patch.da, patch.db,
                        patch.load, patch.cells, 1, 1)


def wheelset_of(config: PipelineConfig) -> Wheelset:
    """Read the profiles and place them; a bad file or value raises ParameterError (one line)."""
    smooth = float(config["profile_smoothing"])

    def profile(name: str, kind: Literal["wheel", "rail"]) -> Profile | None:
        if not config[name]:
            return None
        try:
            return read_profile(config[name], kind=kind, smooth=smooth)
        except ContactError as e:  # the file's problem, under the parameter that named it
            raise ParameterError(f"parameter {name!r}: {e}") from None

    wheel, rail = profile("wheel_profile", "wheel"), profile("rail_profile", "rail")
    right_wheel = profile("right_wheel_profile", "wheel")
    right_rail = profile("right_rail_profile", "rail")
    if wheel is None or rail is None:
        raise ParameterError("parameters 'wheel_profile' and 'rail_profile' must name files")
    try:
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
    contact: WheelsetContact | TableContact | None
    loads: tuple[float, float] | None


@dataclass(frozen=True, eq=False)
class TableContact:
    """Both wheels' patches from the contact table at one pose.

    ``roll``: the table's (rad); ``patches``: left then right wheel, tread
    first, each at its wheel's load; ``scales``: the Hertz scale ``s`` of
    each wheel's patches (``nan`` for a lifted wheel); ``vertical``: each
    wheel's vertical force (N, normal and creep forces) where the balance
    stopped.
    """

    roll: float
    patches: tuple[tuple[TablePatch, ...], tuple[TablePatch, ...]]
    scales: tuple[float, float]
    vertical: tuple[float, float]


class ProfilePipeline:
    """Poses + loads + twists -> patches -> the pipeline's outputs."""

    def __init__(self, config: PipelineConfig, *, solve_roll: bool = False,
                 solver: Any = None, log: Callable[[str], None] | None = None) -> None:
        if config["patch_source"] != "profiles":
            raise ParameterError("a ProfilePipeline needs patch_source: profiles")
        self.pipeline = Pipeline(config, solver=solver)
        self.wheelset = wheelset_of(config)
        self.table = table_of(config, self.wheelset, log) if config["profile_table"] else None
        #: the configured method's solves of the table patches in this pose's balance
        self._solved: dict[int, Solved] = {}
        #: each wheel's creep forces' vertical sum per unit s^3 at its last balance (N)
        self._creep_share: dict[str, float] = {"left": 0.0, "right": 0.0}
        if self.table is not None:
            table_warm_up()   # the blend's kernels compiled or loaded before the first pose
        self.solve_roll = solve_roll
        self._loads: deque[StampedTwist] = deque(maxlen=LOAD_HISTORY)
        self._last_pose_ns: int | None = None
        self._clouds: dict[str, Cloud] = {}
        self.pose_counts = {"pose": 0, "load": 0, "malformed": 0, "wrong_frame": 0,
                            "nonfinite": 0, "out_of_range": 0, "old_stamp": 0}

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

    def republish_frame(self, contact: str) -> None:
        """Have the contact's next solve publish its frame (:meth:`Pipeline.republish_frame`)."""
        self.pipeline.republish_frame(contact)

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

    def diagnostics_cdr(self, stamp_ns: int,
                        extra: Mapping[str, Sequence[tuple[str, str]]] | None = None) -> bytes:
        """Return :meth:`diagnostics`' message as CDR bytes, written without its objects."""
        counts = tuple((f"poses/{k}", str(v)) for k, v in self.pose_counts.items())
        merged = {c: tuple((extra or {}).get(c, ())) + counts for c in self.config.contacts}
        return self.pipeline.diagnostics_cdr(stamp_ns, merged)

    def outputs(self) -> dict[str, str]:
        """Return every topic profiles mode publishes: the pipeline's and the patches."""
        return {**self.pipeline.outputs(), **output_topics(self.config.contacts, patches=True)}

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
        # friction estimation on: the measured wheelset wrench, taken as in topics mode
        measured = tuple(i for i in self.pipeline.inputs() if i.kind == "measured_wrench")
        return (InputTopic(WHEEL_TWIST_TOPIC, twist, "wheel_twist", None,
                           kinematics(self.on_wheel_twist)),
                InputTopic(RAIL_TWIST_TOPIC, twist, "rail_twist", None,
                           kinematics(self.on_rail_twist)),
                InputTopic(LOAD_TOPIC, "geometry_msgs/msg/WrenchStamped", "load", None,
                           kinematics(self.on_load), self.on_load)) + measured + (
                InputTopic(POSE_TOPIC, "geometry_msgs/msg/PoseStamped", "pose", None, pose),)

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
        if self.table is not None and "wheel_load" in changes and \
                not float(changes["wheel_load"]) > 0.0:
            raise ParameterError("parameter 'wheel_load': profile_table needs the wheel load "
                                 "(N) > 0 (a pose's height is not the table's)")
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
        elif not all(math.isfinite(v) for v in load.linear + load.angular):
            reason = "nonfinite"
        elif not all(0.0 <= share <= MAX_WHEEL_LOAD
                     for share in self.split_load(load.linear[2], load.angular[0])):
            # a negative share cannot press a wheel onto its rail; beyond wheel_load's own
            # range a table patch scaled by Hertz grew past any memory before its size check
            reason = "out_of_range"
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

        A share of zero lifts that wheel (no patches, a zero wrench).  The
        load follows the kinematics' rules: the newest ``wheelset/load`` not
        after the pose and at most ``max_kinematics_age`` before it;
        ``wheel_load`` (0: the pose's height) only until a load has arrived.
        Once one has, a pose without a fresh one is rejected
        (``stale_kinematics``: the rig's load is not known, and another would
        give other forces).
        """
        max_age = round(float(self.config["max_kinematics_age"]) * 1e9)
        for load in reversed(self._loads):
            if load.stamp_ns <= stamp_ns:
                if stamp_ns - load.stamp_ns <= max_age:
                    self._check_plausible(0.5 * load.linear[2], "wheelset/load: half its force.z")
                    return self.split_load(load.linear[2], load.angular[0])
                raise RejectedInput("stale_kinematics", f"the last wheelset/load is "
                                    f"{(stamp_ns - load.stamp_ns) * 1e-6:.3g} ms older than "
                                    "the pose")
        if self._loads:
            raise RejectedInput("stale_kinematics", "no wheelset/load at or before the pose")
        per_wheel = float(self.config["wheel_load"])
        self._check_plausible(per_wheel, "parameter wheel_load")
        return (per_wheel, per_wheel) if per_wheel > 0.0 else None

    def _check_plausible(self, per_wheel: float, what: str) -> None:
        """Reject a load per wheel (N) a wheel-rail contact does not have (a unit mistake).

        A wheelset's mean load per wheel, not one wheel's share: a share passes
        through nothing as a wheel lifts, and zero (no load given, or the
        wheelset lifted) is no mistake.  Unless ``allow_implausible``.
        """
        if (per_wheel > 0.0 and not self.config["allow_implausible"]
                and not plausibility.PLAUSIBLE["wheel_load"].contains(per_wheel)):
            raise RejectedInput("implausible", plausibility.message(
                "wheel_load", per_wheel, what=what, override=plausibility.OVERRIDE_PARAMETER))

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
        try:
            loads = self.wheel_loads(stamp)
        except RejectedInput as e:
            return self._dropped(stamp, e.reason, e.detail)
        if self.table is not None and loads is None:  # (wheel_load 0 is refused with a table)
            return self._dropped(stamp, "no_kinematics", "the contact table needs a wheel "
                                 "load: no wheelset/load and wheel_load is 0")
        contact: WheelsetContact | TableContact
        solved: dict[str, Solved | None] = {}
        try:
            if self.table is not None and loads is not None:
                self._solved.clear()
                contact = self.table_solve(wheelset_pose.dy, wheelset_pose.yaw, wheel, rail,
                                           stamp, loads=loads)
                patches = self.clouds_of(zip(SIDES, contact.patches), stamp)
                solved = {contact_name(side, k): self._solved.get(id(tp))
                          for side, wheel_patches in zip(SIDES, contact.patches)
                          for k, tp in enumerate(wheel_patches)}
            else:
                contact = self.solve(wheelset_pose, wheel, rail, stamp, loads=loads)
                patches = self.clouds(contact, stamp)
        except RejectedInput as e:
            return self._dropped(stamp, e.reason, e.detail)
        except TableRangeError as e:
            return self._dropped(stamp, "out_of_table", str(e))
        except (DerailmentError, NoContactError) as e:
            return self._dropped(stamp, "derailment", str(e))
        except ContactError as e:
            return self._dropped(stamp, "degenerate", str(e))
        self._clouds = dict(patches)
        if self.table is not None and loads is not None and self.config["rolling"] == "steady":
            # the balance's last step solved these very patches with the configured method:
            # the pipeline takes those solves (the clouds carry the same patches, to rounding).
            # Transient rolling solves them again with each contact's memory (the balance
            # took the steady creep forces' vertical share: a few N of a wheel's load)
            outcomes = tuple(self.pipeline.on_patch(name, cloud, given=solved.get(name))
                             for name, cloud in patches)
        else:
            outcomes = tuple(self.pipeline.on_patch(name, cloud) for name, cloud in patches)
        return ProfileCycle(stamp, patches, outcomes, contact, loads)

    def solve(self, pose: Pose, wheel: StampedTwist, rail: StampedTwist, stamp_ns: int, *,
              loads: tuple[float, float] | None) -> WheelsetContact:
        """Return both wheels' contacts at a pose under the twists (creep forces balanced)."""
        creep_forces = self.creep_forces(pose.rotation(), wheel, rail, stamp_ns)
        return self.wheelset.solve(pose, loads=loads, solve_roll=self.solve_roll,
                                   tangential=creep_forces)

    def table_solve(self, dy: float, yaw: float, wheel: StampedTwist, rail: StampedTwist,
                    stamp_ns: int, *, loads: tuple[float, float]) -> TableContact:
        """Return both wheels' patches from the contact table, each wheel's load balanced.

        A wheel's vertical force is ``u A + T(u)``: ``A`` its patches'
        normal forces' vertical sum at the reference load, ``u = s^3`` the
        Hertz scale's cube, ``T`` the creep forces' vertical sum on the
        patches at that scale (the configured method, as in the per-pose
        balance).  Secant steps on ``u`` from ``u = L/A``.
        """
        assert self.table is not None
        lookup = self.table.lookup(dy, yaw)
        rot = rotation(lookup.roll, yaw)
        creep_forces = self.creep_forces(rot, wheel, rail, stamp_ns)
        sides: list[tuple[TablePatch, ...]] = []
        scales: list[float] = []
        vertical: list[float] = []
        for side, load in zip(SIDES, loads):
            area = lookup.vertical_normal_force(side, rot)
            if load <= 0.0 or area <= 0.0:
                sides.append(())
                scales.append(math.nan)
                vertical.append(0.0)
                continue
            tried: list[tuple[float, float, tuple[TablePatch, ...]]] = []
            # the first step takes the creep forces' vertical share of the wheel's last pose
            # (a rig's poses follow one another closely): one solve is then enough mostly
            u = load / (area + self._creep_share[side])
            for _ in range(BALANCE_ITERATIONS):
                patches = tuple(lookup.patches(side, u ** (1.0 / 3.0)))
                force = u * area + sum(f[2] for f in creep_forces(side, patches))
                tried.append((u, force - load, patches))
                if abs(force - load) <= BALANCE_TOLERANCE * load:
                    break
                if len(tried) == 1:
                    # the creep forces scale about like the load (mu N once sliding):
                    # T(u) ~ T0 u / u0 makes the second step land within the tolerance
                    u = load / (area + (force - u * area) / u)
                else:
                    (u0, r0, _), (u1, r1, _) = tried[-2], tried[-1]
                    u = u1 - r1 * (u1 - u0) / (r1 - r0) if r1 != r0 else u1 - r1 / area
                if not u > 0.0:
                    break
            u, residual, patches = min(tried, key=lambda t: abs(t[1]))
            if abs(residual) > ACCEPT_BALANCE * load:
                raise RejectedInput("degenerate", f"the {side} wheel's vertical balance from "
                                    f"the contact table did not converge ({residual:.3g} N)")
            share = (load + residual - u * area) / u
            self._creep_share[side] = share if math.isfinite(share) else 0.0
            sides.append(patches)
            scales.append(u ** (1.0 / 3.0))
            vertical.append(load + residual)
        return TableContact(lookup.roll, (sides[0], sides[1]), (scales[0], scales[1]),
                            (vertical[0], vertical[1]))

    def creep_forces(self, rot: Any, wheel: StampedTwist, rail: StampedTwist,
                     stamp_ns: int) -> Callable[[Side, Sequence[CloudSource]], list[Vector]]:
        """Return a function: each patch's creep force (N, track frame) under the twists.

        ``rot``: the wheelset's axes in the track frame.  A patch the method
        refuses is solved by FastSim on its equivalent ellipse (see below);
        standstill, a too large patch and non-finite values are raised.
        """
        frame = self.config["wheelset_frame"]
        max_cells = int(self.config["max_patch_cells"])

        def creep_forces(side: Side, patches: Sequence[CloudSource]) -> list[Vector]:
            out: list[Vector] = []
            for wp in patches:
                try:
                    patch: ContactPatch | None
                    if isinstance(wp, TablePatch):
                        patch = table_contact_patch(wp, stamp_ns, max_cells=max_cells)
                    else:
                        patch = patch_from_cloud(patch_cloud(stamp_ns, frame, *wp.cloud_arrays()),
                                                 max_cells=max_cells)
                    if patch is None:
                        raise RejectedInput("degenerate", "an empty patch")
                    try:
                        timing: list[float] = []
                        creep, f = self.pipeline.solve_patch(patch, wheel, rail, timing=timing)
                        if isinstance(wp, TablePatch):
                            self._solved[id(wp)] = (patch, creep, f, timing[0])
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

        return creep_forces

    def clouds(self, contact: WheelsetContact, stamp_ns: int) -> tuple[tuple[str, Cloud], ...]:
        """Return the patch cloud of each of the four contacts (empty without such a patch)."""
        return self.clouds_of(((w.side, _tread_first(w.patches)) for w in contact.wheels),
                              stamp_ns)

    def clouds_of(self, wheels: Any, stamp_ns: int) -> tuple[tuple[str, Cloud], ...]:
        """Return the four contacts' clouds from ``(side, patches tread first)`` per wheel."""
        frame = self.config["wheelset_frame"]
        by_name: dict[str, Cloud] = {}
        for side, patches in wheels:
            for index, wp in enumerate(patches):
                by_name[contact_name(side, index)] = patch_cloud(
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


def make_pipeline(config: PipelineConfig, *,
                  log: Callable[[str], None] | None = None) -> AnyPipeline:
    """Return the pipeline of the configured patch source (the node's and the replay's).

    ``log``: where a contact table's build is announced (profiles mode).
    """
    if config["patch_source"] == "profiles":
        return ProfilePipeline(config, log=log)
    return Pipeline(config)


def _tread_first(patches: Sequence[WheelPatch]) -> list[WheelPatch]:
    """Order a wheel's patches: nearest the tread (the field side, larger side-frame y) first."""
    return sorted(patches, key=lambda p: -p.region.reference[1])


__all__ = ["LOAD_TOPIC", "POSE_TOPIC", "ProfileCycle", "ProfilePipeline", "SIDES",
           "TableContact", "table_grid_of", "table_of",
           "contact_name", "make_pipeline", "placement_of", "wheelset_of", "MIN_CONTACT_CELLS"]
