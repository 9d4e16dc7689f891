#!/usr/bin/env python3
"""Write the bundled scenario bags into ``bags/`` (deterministic: same content every run).

Each bag is a rosbag2 directory (``metadata.yaml`` version 9 and one
``.mcap`` with zstd chunk compression, CDR, ``ros2msg`` schemas) with the
wheelset twist and the contact patches of docs/guide_node.md, and a
parameter file ``bags/<name>.params.yaml`` for the node ``fastsim``.  The
bad-input bag also gets ``bags/bad_inputs.expected.yaml``: the outcome of
every patch by contact, computed by reading the written bag back and
classifying each patch by the interface's rules.  ``bags/README.md`` is
written by hand and describes the scenarios.

Usage: ``python scripts/make_bags.py [--out DIR] [--only NAME ...]``.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
import shutil
import sys
import time
from typing import Any, Callable

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from fastsim_ros.contact.area import GridArea  # noqa: E402
from fastsim_ros.contact.normal import hertz_ellipse, solve_normal  # noqa: E402
from fastsim_ros.contact.samples import semi_ellipses_patch  # noqa: E402
from fastsim_ros.geometry import benchmark  # noqa: E402
from fastsim_ros.geometry.placement import rotation  # noqa: E402
from msg_adapters.profile_msgs import quaternion  # noqa: E402
from rosbags.interfaces import (  # noqa: E402
    Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime)
from rosbags.rosbag2 import Reader, Writer  # noqa: E402
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode, StoragePlugin  # noqa: E402
from rosbags.typesys import get_typestore, Stores  # noqa: E402

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
T = TYPESTORE.types
CLOUD = "sensor_msgs/msg/PointCloud2"
TWIST = "geometry_msgs/msg/TwistStamped"
POSE = "geometry_msgs/msg/PoseStamped"
WRENCH = "geometry_msgs/msg/WrenchStamped"

#: first stamp of every bag (ns since the epoch): realistic, the same every run
T0_NS = 1_700_000_000 * 10**9
FRAME = "wheelset"
G = 8.0e10
NU = 0.28
R = 0.46            # wheel radius (m)
Y_WHEEL = 0.75      # lateral position of the nominal tread contact (m)
TWIST_DT = 0.005    # 200 Hz
PATCH_DT = 0.010    # 100 Hz
PATCH_OFFSET = 0.0025  # patches lie between twists: no stamp ties, no boundary ages
FIELDS = ("x", "y", "z", "normal_x", "normal_y", "normal_z", "pressure")
REASONS = ("nonfinite", "negative_pressure", "irregular_grid", "missing_field", "wrong_frame",
           "old_stamp", "no_kinematics", "stale_kinematics", "standstill", "too_large",
           "degenerate", "out_of_table", "derailment", "implausible")
#: parameters of the node that the bad-input bag relies on
MAX_PATCH_CELLS = 4096
MAX_KINEMATICS_AGE = 0.05
MIN_ROLLING_SPEED = 0.1

QOS = [Qos(QosHistory.KEEP_LAST, 10, QosReliability.RELIABLE, QosDurability.VOLATILE,
           QosTime(0, 0), QosTime(0, 0), QosLiveliness.AUTOMATIC, QosTime(0, 0), False)]


# --------------------------------------------------------------------- messages

def stamp_ns(t: float) -> int:
    """Return the stamp (ns) of time ``t`` (s) after the bag's start, rounded to 1 us."""
    return T0_NS + int(round(t * 1e6)) * 1000


def header(ns: int, frame: str = FRAME) -> Any:
    """Make a ``std_msgs/Header``."""
    return T["std_msgs/msg/Header"](
        stamp=T["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9),
        frame_id=frame)


def vec(v: Any) -> Any:
    """Make a ``geometry_msgs/Vector3``."""
    return T["geometry_msgs/msg/Vector3"](x=float(v[0]), y=float(v[1]), z=float(v[2]))


def twist_msg(ns: int, linear: Any, angular: Any) -> Any:
    """Make a ``geometry_msgs/TwistStamped`` in the wheelset frame."""
    return T[TWIST](header=header(ns),
                    twist=T["geometry_msgs/msg/Twist"](linear=vec(linear), angular=vec(angular)))


def pose_msg(ns: int, dy: float, dz: float, roll: float, yaw: float) -> Any:
    """Make a ``geometry_msgs/PoseStamped`` of the wheelset in the track frame."""
    qx, qy, qz, qw = quaternion(roll, yaw)
    return T[POSE](header=header(ns, "track"), pose=T["geometry_msgs/msg/Pose"](
        position=T["geometry_msgs/msg/Point"](x=0.0, y=float(dy), z=float(dz)),
        orientation=T["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw)))


def load_msg(ns: int, total: float, roll_moment: float = 0.0) -> Any:
    """Make a ``wheelset/load``: the total vertical load (N) and its roll moment (N m)."""
    return T[WRENCH](header=header(ns), wrench=T["geometry_msgs/msg/Wrench"](
        force=vec((0.0, 0.0, total)), torque=vec((roll_moment, 0.0, 0.0))))


def contact_axes(normal: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return ``e_x, e_y, e_z`` of a contact plane with normal ``normal`` (into the wheel)."""
    ez = np.asarray(normal, dtype=float)
    ez = ez / np.linalg.norm(ez)
    ex = np.array([1.0, 0.0, 0.0])
    ex = ex - ez * float(ez @ ex)
    ex /= np.linalg.norm(ex)
    return ex, np.cross(ez, ex), ez


def left_normal(gamma: float) -> np.ndarray:
    """Return the contact normal of the left wheel at contact angle ``gamma`` (rad)."""
    return np.array([0.0, -math.sin(gamma), math.cos(gamma)])


def right_normal(gamma: float) -> np.ndarray:
    """Return the contact normal of the right wheel at contact angle ``gamma`` (rad)."""
    return np.array([0.0, math.sin(gamma), math.cos(gamma)])


def cloud_points(area: GridArea, origin: Any, normal: Any) -> np.ndarray:
    """Return the ``(ny, nx, 7)`` float32 points of ``area`` laid on its contact plane.

    ``origin``: the contact point in the wheelset frame (the area's in-plane
    origin); ``normal``: the contact normal, pointing into the wheel.
    """
    ex, ey, ez = contact_axes(normal)
    xx, yy = np.meshgrid(area.x, area.y)
    pos = np.asarray(origin, float) + xx[..., None] * ex + yy[..., None] * ey
    pts = np.empty(area.pressure.shape + (7,), dtype=np.float32)
    pts[..., 0:3] = pos
    pts[..., 3:6] = ez
    pts[..., 6] = area.pressure
    return pts


def cloud_msg(ns: int, pts: np.ndarray, *, frame: str = FRAME,
              fields: tuple[str, ...] = FIELDS) -> Any:
    """Make an organised ``sensor_msgs/PointCloud2`` of ``(ny, nx, k)`` float32 points."""
    ny, nx, k = pts.shape
    assert k == len(fields)
    pf = T["sensor_msgs/msg/PointField"]
    return T[CLOUD](
        header=header(ns, frame), height=ny, width=nx,
        fields=[pf(name=f, offset=4 * i, datatype=pf.FLOAT32, count=1)
                for i, f in enumerate(fields)],
        is_bigendian=False, point_step=4 * k, row_step=4 * k * nx,
        data=np.frombuffer(np.ascontiguousarray(pts, dtype="<f4").tobytes(), dtype=np.uint8),
        is_dense=True)


# ------------------------------------------------------------------------ areas

def centred(area: GridArea) -> GridArea:
    """Return ``area`` translated so that its pressure-weighted centroid is at the origin."""
    w = area.pressure / area.pressure.sum()
    cx = float((w.sum(axis=0) * area.x).sum())
    cy = float((w.sum(axis=1) * area.y).sum())
    return area.shifted(-cx, -cy)


def padded(area: GridArea, nx: int, ny: int) -> GridArea:
    """Return ``area`` on an ``nx`` x ``ny`` grid (same cells, zero border added around it)."""
    px, py = nx - area.nx, ny - area.ny
    assert px >= 2 and py >= 2, (area.nx, area.ny, nx, ny)
    i0, j0 = px // 2, py // 2
    p = np.zeros((ny, nx))
    p[j0:j0 + area.ny, i0:i0 + area.nx] = area.pressure
    return GridArea(area.x0 - i0 * area.dx, area.y0 - j0 * area.dy, area.dx, area.dy, p)


def hertz_area(rx: float, ry: float, load: float, cells: int) -> GridArea:
    """Return the Hertzian ellipse of gap radii ``rx``, ``ry`` (m) under ``load`` (N).

    ``cells`` x ``cells`` cells over the ellipse's bounding box grown by 1.5
    cells each side (an empty border); the discrete load is exactly ``load``.
    """
    hz = hertz_ellipse(rx, ry, load, shear_modulus=G, nu=NU)
    hx, hy = hz.a * cells / (cells - 3), hz.b * cells / (cells - 3)
    dx, dy = 2 * hx / cells, 2 * hy / cells
    x = -hx + dx * (np.arange(cells) + 0.5)
    y = -hy + dy * (np.arange(cells) + 0.5)
    p = hz.pressure(x[None, :], y[:, None])
    return GridArea(float(x[0]), float(y[0]), dx, dy, p).with_load(load)


def normal_area(rx: float, ry_neg: float, ry_pos: float, load: float, cells: int) -> GridArea:
    """Solve the normal contact of a two-sided gap under ``load`` (N) on ``cells`` x ``cells``.

    The gap is ``x^2/(2 rx) + y^2/(2 ry)`` with ``ry = ry_neg`` for ``y < 0``
    and ``ry_pos`` for ``y > 0`` (m).  A first solve on 1.5 times the box of
    the Hertz ellipse of the flatter side finds the contact's extent; the
    second solves on that extent grown by 1.5 cells each side, so the patch
    fills its grid with an empty border.  The result is centred on its
    pressure centroid.
    """
    gap = _side_gap(rx, ry_neg, ry_pos)
    hz = hertz_ellipse(rx, max(ry_neg, ry_pos), load, shear_modulus=G, nu=NU)
    box = (-1.5 * hz.a, 1.5 * hz.a, -1.5 * hz.b, 1.5 * hz.b)
    for _ in range(2):
        dx, dy = (box[1] - box[0]) / cells, (box[3] - box[2]) / cells
        x = box[0] + dx * (np.arange(cells) + 0.5)
        y = box[2] + dy * (np.arange(cells) + 0.5)
        sol = solve_normal(float(x[0]), float(y[0]), dx, dy, gap(x[None, :], y[:, None]),
                           load=load, shear_modulus=G, nu=NU)
        if sol.touches_edge:
            raise RuntimeError("normal solve: the box is too small")
        m = sol.area.mask
        xs, ys = x[m.any(axis=0)], y[m.any(axis=1)]
        lo_x, hi_x = xs[0] - dx / 2, xs[-1] + dx / 2
        lo_y, hi_y = ys[0] - dy / 2, ys[-1] + dy / 2
        kx, ky = (hi_x - lo_x) * 1.5 / (cells - 3), (hi_y - lo_y) * 1.5 / (cells - 3)
        box = (lo_x - kx, hi_x + kx, lo_y - ky, hi_y + ky)
    return centred(sol.area)


def semi_ellipse_area() -> GridArea:
    """Return the two semi-ellipses ``a1/b1 = 0.5``, ``a2/b2 = 2`` of 1 cm^2 at 60 kN."""
    base = semi_ellipses_patch(0.5, 2.0, cells=22, scale=0.01, load=6.0e4)
    return centred(padded(base, base.nx + 2, base.ny + 2))


# ------------------------------------------------------------------------- bags

class Bag:
    """Messages of one bag, written in log-time order (ties by topic order)."""

    def __init__(self, name: str) -> None:
        """Start an empty bag called ``name``."""
        self.name = name
        self.topics: dict[str, str] = {}
        self.items: list[tuple[int, int, int, Any]] = []  # log ns, topic idx, seq, msg
        self.tags: dict[tuple[str, int], str] = {}  # (topic, seq) -> intended outcome

    def topic(self, name: str, msgtype: str) -> None:
        """Declare a topic; connections are written in declaration order."""
        self.topics[name] = msgtype

    def add(self, topic: str, log_ns: int, msg: Any, tag: str | None = None) -> None:
        """Add a message logged at ``log_ns`` (ns)."""
        idx = list(self.topics).index(topic)
        self.items.append((log_ns, idx, len(self.items), msg))
        if tag is not None:
            self.tags[(topic, len(self.items) - 1)] = tag

    def write(self, out: Path) -> Path:
        """Write ``out/<name>/`` (replacing it) and return its path."""
        path = out / self.name
        if path.exists():
            shutil.rmtree(path)
        writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
        writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        writer.set_custom_data("generator", "scripts/make_bags.py")
        names = list(self.topics)
        with writer:
            conns = [writer.add_connection(t, self.topics[t], typestore=TYPESTORE,
                                           offered_qos_profiles=QOS) for t in names]
            for log_ns, idx, _, msg in sorted(self.items, key=lambda it: it[:3]):
                writer.write(conns[idx], log_ns,
                             TYPESTORE.serialize_cdr(msg, self.topics[names[idx]]))
        with_chunk_crcs(path / f"{self.name}.mcap")
        return path


def with_chunk_crcs(file: Path) -> None:
    """Rewrite an MCAP file record for record through ``mcap``, with its chunks' CRCs.

    rosbags writes each chunk's CRC as 0 (none): a corruption inside a chunk's
    compressed data then decoded as other bytes (patches refused one by one as
    malformed) instead of failing the read as a bad file.  The schemas,
    channels (their QoS metadata), messages in file order, metadata records
    and chunking (1 MiB uncompressed, zstd) are kept; ``metadata.yaml`` names
    none of what changes.
    """
    import io
    from mcap.reader import make_reader
    from mcap.writer import CompressionType, Writer as McapWriter

    reader = make_reader(io.BytesIO(file.read_bytes()))
    header = reader.get_header()
    summary = reader.get_summary()
    assert summary is not None
    staging = file.with_name(file.name + ".crc")
    with open(staging, "wb") as f:
        out = McapWriter(f, compression=CompressionType.ZSTD, chunk_size=1 << 20)
        out.start(profile=header.profile, library=f"{header.library} + python mcap")
        schemas = {sid: out.register_schema(sc.name, sc.encoding, sc.data)
                   for sid, sc in sorted(summary.schemas.items())}
        channels = {cid: out.register_channel(ch.topic, ch.message_encoding,
                                              schemas.get(ch.schema_id, 0), ch.metadata)
                    for cid, ch in sorted(summary.channels.items())}
        for _, channel, message in reader.iter_messages(log_time_order=False):
            out.add_message(channels[channel.id], message.log_time, message.data,
                            message.publish_time, message.sequence)
        for record in reader.iter_metadata():
            out.add_metadata(record.name, record.metadata)
        out.finish()
    staging.replace(file)


def patch_times(duration: float) -> list[float]:
    """Return the patch times (s) of a bag: 100 Hz, offset from the twists."""
    return [PATCH_OFFSET + PATCH_DT * k for k in range(int(round(duration / PATCH_DT)))]


def twist_times(duration: float, start: float = 0.0) -> list[float]:
    """Return the twist times (s) from ``start`` to ``duration``: 200 Hz."""
    n0 = int(round(start / TWIST_DT))
    return [TWIST_DT * k for k in range(n0, int(round(duration / TWIST_DT)))]


def omega_for(v0: float, xi: float, radius: float) -> float:
    """Return the axle spin (rad/s) that gives creepage ``xi`` at speed ``v0`` and ``radius``."""
    return v0 * (1.0 - xi / 2.0) / (1.0 + xi / 2.0) / radius


def ramp(t: float, t0: float, t1: float, y0: float, y1: float) -> float:
    """Return the value at ``t`` of a ramp from ``y0`` at ``t0`` to ``y1`` at ``t1``, held."""
    s = min(max((t - t0) / (t1 - t0), 0.0), 1.0)
    return y0 + (y1 - y0) * s


def track_bag(name: str, contacts: list[str]) -> Bag:
    """Return a bag with the wheelset twist and the patch topics of ``contacts``."""
    bag = Bag(name)
    bag.topic("/wheelset/twist", TWIST)
    for c in contacts:
        bag.topic(f"/contact/{c}/patch", CLOUD)
    return bag


def hertz_ramp() -> tuple[Bag, dict[str, Any]]:
    """Build (a): Hertzian treads, braking creepage ramp 0 -> 1e-2 at 20 m/s."""
    dur, v0 = 4.0, 20.0
    bag = track_bag("hertz_ramp", ["left", "right"])
    area = hertz_area(R, 0.3, 6.0e4, 24)
    pts = {"left": cloud_points(area, (0.0, Y_WHEEL, -R), left_normal(0.0)),
           "right": cloud_points(area, (0.0, -Y_WHEEL, -R), right_normal(0.0))}
    for t in twist_times(dur):
        xi = ramp(t, 0.5, 3.5, 0.0, 1.0e-2)
        bag.add("/wheelset/twist", stamp_ns(t),
                twist_msg(stamp_ns(t), (v0, 0, 0), (0, omega_for(v0, xi, R), 0)))
    for t in patch_times(dur):
        for c in ("left", "right"):
            bag.add(f"/contact/{c}/patch", stamp_ns(t), cloud_msg(stamp_ns(t), pts[c]))
    return bag, {}


def semi_ellipses_spin() -> tuple[Bag, dict[str, Any]]:
    """Build (b): two semi-ellipses, contact angle ramp 0 -> 0.4 rad, xi = eta = 0."""
    dur, v0 = 4.0, 20.0
    bag = track_bag("semi_ellipses_spin", ["left", "right"])
    area = semi_ellipse_area()
    mirror = area.mirrored_y()
    for t in twist_times(dur):
        bag.add("/wheelset/twist", stamp_ns(t),
                twist_msg(stamp_ns(t), (v0, 0, 0), (0, v0 / R, 0)))
    for t in patch_times(dur):
        gamma = ramp(t, 0.5, 3.5, 0.0, 0.4)
        ns = stamp_ns(t)
        bag.add("/contact/left/patch", ns,
                cloud_msg(ns, cloud_points(area, (0.0, Y_WHEEL, -R), left_normal(gamma))))
        bag.add("/contact/right/patch", ns,
                cloud_msg(ns, cloud_points(mirror, (0.0, -Y_WHEEL, -R), right_normal(gamma))))
    return bag, {}


def _side_gap(rx: float, ry_neg: float, ry_pos: float) -> Callable[..., np.ndarray]:
    def gap(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return x**2 / (2 * rx) + y**2 / (2 * np.where(y < 0.0, ry_neg, ry_pos))
    return gap


#: flange_shift's holds: the lateral shift to the left (m), tread -> two-point -> flange
FLANGE_SHIFTS = (0.0, 2.0e-3, 4.0e-3, 4.75e-3, 4.85e-3, 4.95e-3, 5.05e-3, 6.0e-3, 6.4e-3,
                 8.0e-3)
#: its profiles-mode parameters (the geometry the patches were computed with)
FLANGE_PROFILE_PARAMS: dict[str, Any] = {
    "patch_source": "profiles", "cell_size": 4.0e-4, "separation_distance": 2.0e-3,
    "combination_distance": 1.0e-3, "shear_modulus": G, "poisson_ratio": NU, "method": "mae"}


def flange_shift() -> tuple[Bag, dict[str, Any]]:
    """Build (c): patches from the profiles, the wheelset shifted from the treads to the flange.

    The shipped S1002 wheels on UIC60 rails (the Manchester benchmark's
    placement), 20 kN per wheel, 20 m/s with the axle spinning at ``v0 /
    R0``, no yaw; ten lateral shifts to the left (:data:`FLANGE_SHIFTS`) held
    0.4 s each, each with the roll that levels both wheels under their loads.
    The patches are the profile pipeline's (0.4 mm cells; regions more than 2
    mm apart kept as separate patches): from 4.75 to 5.05 mm the left wheel
    touches its rail on the tread and on the gauge corner (``left_flange``),
    from 6.4 mm on its flange.  The bag has the pose, the load and the
    twist too, so it replays in either mode; its parameters are topics mode.
    """
    from fastsim_ros.geometry.placement import Pose
    from fastsim_ros.pipeline import PipelineConfig
    from fastsim_ros.pipeline.profiles import ProfilePipeline, contact_name
    from msg_adapters.cdr import StampedTwist

    dur, v0, hold = 4.0, 20.0, 0.4
    names = ["left", "right", "left_flange", "right_flange"]
    bag = Bag("flange_shift")
    bag.topic("/wheelset/twist", TWIST)
    bag.topic("/wheelset/load", WRENCH)
    bag.topic("/wheelset/pose", POSE)
    for c in names:
        bag.topic(f"/contact/{c}/patch", CLOUD)
    config = PipelineConfig.from_values({**FLANGE_PROFILE_PARAMS, "wheel_load": 2.0e4})
    twist = (v0, 0.0, 0.0), (0.0, v0 / R, 0.0)
    holds = []
    for dy in FLANGE_SHIFTS:
        pipeline = ProfilePipeline(config, solve_roll=True)
        wheel = StampedTwist(0, FRAME, twist[0], twist[1])
        rest = StampedTwist(0, "", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        contact = pipeline.solve(Pose(dy), wheel, rest, 0, loads=(2.0e4, 2.0e4))
        clouds: dict[str, np.ndarray] = {}
        for w in contact.wheels:
            for k, wp in enumerate(sorted(w.patches, key=lambda p: -p.region.reference[1])):
                points, normal, pressure = wp.cloud_arrays()
                pts = np.empty(pressure.shape + (7,))
                pts[..., 0:3] = points
                pts[..., 3:6] = normal
                pts[..., 6] = pressure
                clouds[contact_name(w.side, k)] = pts
        holds.append((contact.pose, clouds))
    for t in twist_times(dur):
        bag.add("/wheelset/twist", stamp_ns(t), twist_msg(stamp_ns(t), *twist))
        bag.add("/wheelset/load", stamp_ns(t), load_msg(stamp_ns(t), 4.0e4))
    empty = np.zeros((0, 0, 7))
    for t in patch_times(dur):
        pose, clouds = holds[min(int(t / hold), len(holds) - 1)]
        ns = stamp_ns(t)
        bag.add("/wheelset/pose", ns, pose_msg(ns, pose.dy, pose.dz, pose.roll, pose.yaw))
        for name in names:
            bag.add(f"/contact/{name}/patch", ns, cloud_msg(ns, clouds.get(name, empty)))
    return bag, {"contacts": names}


def roller_rig() -> tuple[Bag, dict[str, Any]]:
    """Build (d): one wheel on a roller, speed mismatch xi -5e-3 -> +5e-3 at 15 m/s."""
    dur, s_r, r_roll = 4.0, 15.0, 0.5
    bag = Bag("roller_rig")
    bag.topic("/wheelset/twist", TWIST)
    bag.topic("/rail/twist", TWIST)
    bag.topic("/contact/wheel/patch", CLOUD)
    area = hertz_area(1.0 / (1.0 / R + 1.0 / r_roll), 0.3, 5.0e4, 24)
    pts = cloud_points(area, (0.0, 0.0, -R), (0.0, 0.0, 1.0))
    omega_r = s_r / r_roll
    w_r = np.array([0.0, -omega_r, 0.0])
    v_r = np.cross(w_r, -np.array([0.0, 0.0, -(R + r_roll)]))
    for t in twist_times(dur):
        xi = ramp(t, 0.25, 3.75, -5.0e-3, 5.0e-3)
        ns = stamp_ns(t)
        bag.add("/wheelset/twist", ns, twist_msg(ns, (0, 0, 0), (0, omega_for(s_r, xi, R), 0)))
        bag.add("/rail/twist", ns, twist_msg(ns, v_r, w_r))
    for t in patch_times(dur):
        bag.add("/contact/wheel/patch", stamp_ns(t), cloud_msg(stamp_ns(t), pts))
    return bag, {"contacts": ["wheel"], "rail_twist_required": True}


def bad_inputs() -> tuple[Bag, dict[str, Any]]:
    """Build (e): good Hertzian patches on two treads interleaved with bad ones.

    See ``bags/README.md`` for the timeline; every patch is tagged with the
    outcome it is meant to have, and the tags are checked against a
    classification of the bag read back.
    """
    dur, v0, xi = 3.0, 15.0, 2.0e-3
    contacts = ["left", "right"]
    bag = track_bag("bad_inputs", contacts)
    area = hertz_area(R, 0.3, 6.0e4, 20)
    origin = {"left": (0.0, Y_WHEEL, -R), "right": (0.0, -Y_WHEEL, -R)}
    normal = {"left": left_normal(0.0), "right": right_normal(0.0)}
    good = {c: cloud_points(area, origin[c], normal[c]) for c in contacts}
    omega = omega_for(v0, xi, R)
    for t in twist_times(dur, start=0.1):
        if 1.5 <= t < 1.7 - 1e-9:  # the twist stops: stale kinematics
            continue
        ns = stamp_ns(t)
        moving = not (2.2 <= t < 2.4 - 1e-9)  # standstill
        bag.add("/wheelset/twist", ns, twist_msg(ns, (v0 if moving else 0.0, 0, 0),
                                                 (0, omega if moving else 0.0, 0)))
    times = patch_times(dur)
    kinds = ["nonfinite_p", "negative_pressure", "missing_field", "wrong_frame", "old_stamp",
             "irregular_grid", "too_large", "degenerate", "nonfinite_x", "negative_pressure",
             "missing_field", "wrong_frame", "old_stamp", "irregular_grid", "too_large",
             "degenerate", "nonfinite_n", "implausible_mm", "implausible_mpa", "implausible_mm",
             "implausible_mpa"]
    bad: dict[str, dict[int, str]] = {c: {} for c in contacts}
    for c, first in (("left", 20), ("right", 22)):  # slots from 0.2025 s, every 5th
        for i, kind in enumerate(kinds):
            bad[c][first + 5 * i] = kind
        # a wheel lifting: empty patches
        lifts = (180, 181, 182, 183, 184, 200, 201, 202, 203, 204) if c == "left" \
            else (190, 191, 205, 206)
        for slot in lifts:
            bad[c][slot] = "no_contact"
    for k, t in enumerate(times):
        for c in contacts:
            kind = bad[c].get(k, "good")
            ns = stamp_ns(t)
            topic = f"/contact/{c}/patch"
            bag.add(topic, ns, bad_patch(kind, ns, stamp_ns(times[k - 1]), good[c], area,
                                         origin[c], normal[c]), tag=kind)
    return bag, {"max_patch_cells": MAX_PATCH_CELLS}


def bad_patch(kind: str, ns: int, prev_ns: int, good: np.ndarray, area: GridArea,
              origin: Any, normal: Any) -> Any:
    """Return the patch message of ``kind`` ("good" or a bad kind) logged at ``ns``."""
    pts = good.copy()
    inside = np.argwhere(area.pressure > 0.0)
    j, i = (int(v) for v in inside[len(inside) // 2])  # a cell in contact
    if kind == "good":
        return cloud_msg(ns, pts)
    if kind == "nonfinite_p":
        pts[j, i, 6] = np.nan
    elif kind == "nonfinite_x":
        pts[j, i, 0] = np.nan
    elif kind == "nonfinite_n":
        pts[j, i, 5] = np.inf
    elif kind == "negative_pressure":
        pts[j, i, 6] = -pts[j, i, 6]
    elif kind == "missing_field":
        return cloud_msg(ns, np.ascontiguousarray(pts[..., :6]), fields=FIELDS[:6])
    elif kind == "wrong_frame":
        return cloud_msg(ns, pts, frame="base_link")
    elif kind == "old_stamp":
        return cloud_msg(prev_ns - 3_000_000, pts)  # logged at ns, stamped before the last
    elif kind == "irregular_grid":
        ex = contact_axes(normal)[0]
        pts[j, :, 0:3] += (0.3 * area.dx * ex).astype(np.float32)
    elif kind == "too_large":
        big = padded(area, 80, 80)
        pts = cloud_points(big, origin, normal)
    elif kind == "degenerate":
        p = np.zeros_like(area.pressure)
        p[j, i - 1:i + 2] = area.pressure[j, i]
        pts = cloud_points(area.with_pressure(p), origin, normal)
    elif kind == "implausible_mm":   # the positions in millimetres
        pts[..., 0:3] *= np.float32(1e3)
    elif kind == "implausible_mpa":  # the pressures in megapascals
        pts[..., 6] *= np.float32(1e-6)
    elif kind == "no_contact":
        pts[..., 6] = 0.0
    else:
        raise ValueError(kind)
    return cloud_msg(ns, pts)


# ------------------------------------------------------------ expected outcomes

def classify_bag(path: Path, params: dict[str, Any]) -> list[tuple[str, str, int]]:
    """Return ``(contact, outcome, log ns)`` of every patch of a bag, read back from disk.

    The node's rules (docs/guide_node.md), in this order: the size bound, frame, fields,
    non-finite values, negative pressure, grid regularity, stamp order, empty
    (``no_contact``), fewer than 4 cells (``degenerate``), kinematics
    (``no_kinematics``, ``stale_kinematics``), ``standstill``, a likely unit
    mistake (``implausible``); else ``served``.  Each bad patch of the bag has
    one fault only, so the order does not decide any outcome.
    """
    max_cells = int(params.get("max_patch_cells", MAX_PATCH_CELLS))
    out: list[tuple[str, str, int]] = []
    last_twist: Any = None
    last_stamp: dict[str, int] = {}
    with Reader(path) as reader:
        for conn, log_ns, raw in reader.messages():
            msg = TYPESTORE.deserialize_cdr(raw, conn.msgtype)
            if conn.topic == "/wheelset/twist":
                last_twist = msg
                continue
            contact = conn.topic.split("/")[2]
            ns = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
            outcome = _classify_patch(msg, max_cells)
            if outcome is None:
                if contact in last_stamp and ns < last_stamp[contact]:
                    outcome = "old_stamp"
                else:
                    last_stamp[contact] = ns
                    outcome = _kinematics(msg, ns, last_twist)
            out.append((contact, outcome, log_ns))
    return out


def _classify_patch(msg: Any, max_cells: int) -> str | None:
    if msg.height * msg.width > max_cells:
        return "too_large"
    if msg.header.frame_id != FRAME:
        return "wrong_frame"
    names = [f.name for f in msg.fields]
    if any(f not in names for f in FIELDS):
        return "missing_field"
    pts = np.frombuffer(msg.data.tobytes(), dtype="<f4").reshape(msg.height, msg.width, -1)
    if not np.all(np.isfinite(pts)):
        return "nonfinite"
    if np.any(pts[..., 6] < 0.0):
        return "negative_pressure"
    # regular grid: constant steps along rows and along columns
    pos = pts[..., 0:3].astype(float)
    step_x = np.diff(pos, axis=1)
    step_y = np.diff(pos, axis=0)
    tol = 1e-3 * min(np.linalg.norm(step_x[0, 0]), np.linalg.norm(step_y[0, 0]))
    if np.abs(step_x - step_x[0, 0]).max() > tol or np.abs(step_y - step_y[0, 0]).max() > tol:
        return "irregular_grid"
    return None


def _kinematics(msg: Any, ns: int, twist: Any) -> str:
    pts = np.frombuffer(msg.data.tobytes(), dtype="<f4").reshape(msg.height, msg.width, -1)
    p = pts[..., 6].astype(float)
    n_in = int(np.count_nonzero(p > 0.0))
    if n_in == 0:
        return "no_contact"
    if n_in < 4:
        return "degenerate"
    if twist is None:
        return "no_kinematics"
    t_ns = twist.header.stamp.sec * 10**9 + twist.header.stamp.nanosec
    if ns - t_ns > MAX_KINEMATICS_AGE * 1e9:
        return "stale_kinematics"
    # rolling speed on track at the pressure centroid
    w = p / p.sum()
    c = (pts[..., 0:3].astype(float) * w[..., None]).sum(axis=(0, 1))
    ez = (pts[..., 3:6].astype(float) * p[..., None]).sum(axis=(0, 1))
    ez /= np.linalg.norm(ez)
    ex = np.array([1.0, 0.0, 0.0]) - ez * ez[0]
    ex /= np.linalg.norm(ex)
    lin = np.array([twist.twist.linear.x, twist.twist.linear.y, twist.twist.linear.z])
    ang = np.array([twist.twist.angular.x, twist.twist.angular.y, twist.twist.angular.z])
    u_w = lin + np.cross(ang, c)
    cp = lin + np.cross(np.array([ang[0], 0.0, ang[2]]), c)
    speed = float(ex @ (cp - u_w / 2.0))
    if abs(speed) < MIN_ROLLING_SPEED:
        return "standstill"
    # a likely unit mistake: cells in contact over 0.1 m across (millimetres), or no
    # pressure reaching 1e5 Pa (megapascals); the bag's creepages are plausible
    rows, cols = np.nonzero(p > 0.0)
    step = (np.linalg.norm(pts[0, 1, 0:3].astype(float) - pts[0, 0, 0:3]),
            np.linalg.norm(pts[1, 0, 0:3].astype(float) - pts[0, 0, 0:3]))
    extent = max((np.ptp(cols) + 1) * step[0], (np.ptp(rows) + 1) * step[1])
    return "implausible" if extent > 0.1 or p.max() < 1e5 else "served"


def expected_counts(outcomes: list[tuple[str, str, int]]) -> dict[str, Any]:
    """Return the per-contact counts of patches, served, no_contact and each rejection."""
    res: dict[str, Any] = {}
    for contact in sorted({c for c, _, _ in outcomes}):
        got = [o for c, o, _ in outcomes if c == contact]
        res[contact] = {
            "patches": len(got),
            "served": got.count("served"),
            "no_contact": got.count("no_contact"),
            "rejected": {r: got.count(r) for r in REASONS},
        }
    return res


def mbench_a22() -> tuple[Bag, dict[str, Any]]:
    """Build the Manchester benchmark A-2.2 as a recording of a rig with profiles.

    The 21 poses of CONTACT's ``mbench_a22`` cases (shift 0..10 mm to the
    right, yaw 0..24 mrad, their roll), one every 10 ms; the wheelset twist
    at 200 Hz (2 m/s along the track, the case's axle spin, in the wheelset
    frame of the case's roll and yaw); the load, 10 kN per wheel (20 kN, no
    roll moment), with each twist.  No patches: the node or the replay in
    profiles mode computes them (params: profiles mode, the benchmark's G).
    """
    bag = Bag("mbench_a22")
    bag.topic("/wheelset/twist", TWIST)
    bag.topic("/wheelset/load", WRENCH)
    bag.topic("/wheelset/pose", POSE)
    for k, case in enumerate(benchmark.a22("left")):
        rot = rotation(case.roll, case.yaw)
        v = rot.T @ np.array([case.forward_speed, 0.0, 0.0])
        for t in (PATCH_DT * k, PATCH_DT * k + TWIST_DT):
            ns = stamp_ns(t)
            bag.add("/wheelset/twist", ns, twist_msg(ns, v, (0.0, case.axle_spin, 0.0)))
            bag.add("/wheelset/load", ns, load_msg(ns, 2.0 * benchmark.LOAD))
        ns = stamp_ns(PATCH_OFFSET + PATCH_DT * k)
        bag.add("/wheelset/pose", ns, pose_msg(ns, case.dy, 0.0, case.roll, case.yaw))
    return bag, {"contacts": ["left", "right", "left_flange", "right_flange"],
                 "patch_source": "profiles", "shear_modulus": benchmark.SHEAR_MODULUS,
                 "poisson_ratio": benchmark.POISSON, "friction_coefficient": benchmark.MU,
                 "method": "mae_calibrated", "cell_size": benchmark.CELL,
                 "wheel_load": 0.0}


def transient_step() -> tuple[Bag, dict[str, Any]]:
    """Build (g): a step in xi at 2 m/s, patches at 1 kHz, ``rolling: transient`` (MAE).

    Hertzian treads; xi 0.5e-3 -> 2e-3 at 30 ms (twists at 2 kHz, patches
    0.25 ms after a twist): each cycle rolls 2 mm of the patch, so the
    traction builds up over a few cycles.  One left patch is dropped at
    60.25 ms (the state rolls 4 mm that cycle); the right wheel lifts at
    90.25 and 91.25 ms (empty patches: its traction restarts from zero).
    """
    dur, v0, dt = 0.25, 2.0, 0.001
    bag = track_bag("transient_step", ["left", "right"])
    area = hertz_area(R, 0.3, 6.0e4, 24)
    pts = {"left": cloud_points(area, (0.0, Y_WHEEL, -R), left_normal(0.0)),
           "right": cloud_points(area, (0.0, -Y_WHEEL, -R), right_normal(0.0))}
    lifted = pts["right"].copy()
    lifted[..., 6] = 0.0
    for k in range(int(round(dur / (dt / 2)))):
        t = k * dt / 2
        xi = 0.5e-3 if t < 0.03 else 2.0e-3
        bag.add("/wheelset/twist", stamp_ns(t),
                twist_msg(stamp_ns(t), (v0, 0, 0), (0, omega_for(v0, xi, R), 0)))
    for k in range(int(round(dur / dt))):
        t = 0.00025 + k * dt
        ns = stamp_ns(t)
        if k != 60:
            bag.add("/contact/left/patch", ns, cloud_msg(ns, pts["left"]))
        bag.add("/contact/right/patch", ns, cloud_msg(ns, lifted if k in (90, 91)
                                                      else pts["right"]))
    return bag, {"rolling": "transient"}


#: adhesion_rig's truth (also in its params file, section ``truth``): the falling law's shape,
#: the static coefficient's steps (from t, mu_s: dry, wet, dry), the spells in the linear
#: range, the load cell's noise (N, one sigma) and its seed
ADHESION_LAW = {"friction_law": "exponential", "friction_limit_ratio": 0.5,
                "friction_decay": 0.5}
ADHESION_STEPS = ((0.0, 0.4), (1.5, 0.2), (3.0, 0.4))
ADHESION_LINEAR = ((0.0, 0.3), (2.2, 2.5))
ADHESION_NOISE = 250.0
ADHESION_SEED = 28


def adhesion_mu(t: float) -> float:
    """Return adhesion_rig's true static coefficient at ``t`` (s)."""
    return [mu for start, mu in ADHESION_STEPS if t >= start][-1]


def adhesion_xi(t: float) -> float:
    """Return adhesion_rig's longitudinal creepage at ``t`` (s): ramps and steps, linear spells."""
    if any(a <= t < b for a, b in ADHESION_LINEAR):
        return 1.5e-4
    if int(t * 4) % 3 == 0:  # a step to 6e-3 for a quarter second in every three
        return 6.0e-3
    return 3.0e-3 + 9.0e-3 * (t % 1.0)  # ramps 3e-3 -> 1.2e-2 in a second


def _rig(name: str, xi_of: Callable[[float], float], seed: int, noise: float,
         measure: Callable[[float, list[Any]], tuple[float, float, float]]) -> Bag:
    """Return a rig's bag: twists, patch pairs and with each pair a measured wheelset wrench.

    Two mirrored Hertzian treads (gap radii 0.46 m and 0.3 m, 50 kN each,
    20 x 20 cells) at 20 m/s for 4 s, the creepage ``xi_of(t)``; the
    measured wrench is ``measure(t, outcomes)`` (N, wheelset frame) on the
    pair's outcomes as the node converts these very messages (the
    pipeline's own conversion), plus a load cell's Gaussian noise of
    ``noise`` (N) on ``force.x``, seeded by ``seed`` (the same bag every run).
    """
    from fastsim_ros.pipeline import Pipeline, PipelineConfig

    dur, v0 = 4.0, 20.0
    bag = Bag(name)
    bag.topic("/wheelset/twist", TWIST)
    bag.topic("/wheelset/measured_wrench", WRENCH)
    for c in ("left", "right"):
        bag.topic(f"/contact/{c}/patch", CLOUD)
    area = hertz_area(R, 0.3, 5.0e4, 20)
    pts = {"left": cloud_points(area, (0.0, Y_WHEEL, -R), left_normal(0.0)),
           "right": cloud_points(area, (0.0, -Y_WHEEL, -R), right_normal(0.0))}
    converter = Pipeline(PipelineConfig.from_values(dict(BASE_PARAMS, method="mae_calibrated")))
    twists = {}
    for t in twist_times(dur):
        msg = twist_msg(stamp_ns(t), (v0, 0, 0), (0, omega_for(v0, xi_of(t), R), 0))
        twists[stamp_ns(t)] = msg
        bag.add("/wheelset/twist", stamp_ns(t), msg)
    rng = np.random.default_rng(seed)
    for t in patch_times(dur):
        ns = stamp_ns(t)
        newest = max(k for k in twists if k <= ns)
        converter.on_wheel_twist(TYPESTORE.serialize_cdr(twists[newest], TWIST))
        outcomes = []
        for c in ("left", "right"):
            cloud = cloud_msg(ns, pts[c])
            out = converter.on_patch(c, TYPESTORE.serialize_cdr(cloud, CLOUD))
            assert out.status == "solved", out.status
            outcomes.append(out)
            bag.add(f"/contact/{c}/patch", ns, cloud)
        force = measure(t, outcomes)
        w = T[WRENCH](
            header=header(ns), wrench=T["geometry_msgs/msg/Wrench"](
                force=vec((force[0] + rng.normal(0.0, noise), force[1], force[2])),
                torque=vec((0.0, 0.0, 0.0))))
        bag.add("/wheelset/measured_wrench", ns, w)
    return bag


def adhesion_rig() -> tuple[Bag, dict[str, Any]]:
    """Build (h): a wheelset on a traction rig, the measured wrench from the exact theory.

    Hertzian treads (gap radii 0.46 m and 0.3 m, 50 kN each, 20 x 20
    cells), v0 = 20 m/s, contact angle 0, 4 s: the creepage of
    :func:`adhesion_xi`, the true friction the exponential law
    :data:`ADHESION_LAW` with ``mu_s`` stepping dry -> wet -> dry
    (:data:`ADHESION_STEPS`).  With each patch pair (100 Hz) a measured
    wheelset wrench (``/wheelset/measured_wrench``, the patches' stamp,
    logged before them): the sum of the two contacts' creep forces by
    Kalker's exact theory (:func:`fastsim_ros.contact.exact.coulomb`) at the
    true law, on the patch and creepages the node converts from these very
    messages (the pipeline's own conversion), plus a load cell's Gaussian
    noise of 250 N on ``force.x`` (seeded: the same bag every run).  The
    two treads are mirror images under the same creepages: one exact solve
    serves both.  About 400 exact solves (some seconds).
    """
    from fastsim_ros.contact import exact
    from fastsim_ros.contact.friction import friction_law

    law_shape = {"limit_ratio": ADHESION_LAW["friction_limit_ratio"],
                 "decay": ADHESION_LAW["friction_decay"]}

    def measure(t: float, outcomes: list[Any]) -> tuple[float, float, float]:
        # the two treads are mirror images under the same creepages: one exact solve a cycle
        total = np.zeros(3)
        solved: list[Any] = [None]
        for out in outcomes:
            p, cr = out.patch, out.creepage
            key = (p.pressure.tobytes(), p.x0, p.y0, p.dx, p.dy, cr.xi, cr.eta, abs(cr.phi),
                   cr.speed)
            if solved[0] is None or solved[0][0] != key:
                law = friction_law(ADHESION_LAW["friction_law"], adhesion_mu(t), **law_shape)
                f = exact.coulomb(GridArea(p.x0, p.y0, p.dx, p.dy, p.pressure), cr.xi,
                                  cr.eta, cr.phi, nu=NU, shear_modulus=G, friction=law,
                                  speed=abs(cr.speed))
                solved[0] = (key, f.fx, f.fy)
            total += p.frame.to_wheelset((solved[0][1], solved[0][2], p.load))
        return float(total[0]), float(total[1]), float(total[2])
    bag = _rig("adhesion_rig", adhesion_xi, ADHESION_SEED, ADHESION_NOISE, measure)
    return bag, {"method": "mae_calibrated", **ADHESION_LAW, "friction_coefficient": 0.3,
                 "friction_estimation": "on", "friction_measurement_noise": ADHESION_NOISE,
                 "friction_estimate_sigma": 0.1}


def adhesion_truth_text() -> str:
    """Return the ``truth`` section of adhesion_rig's params file (not a node's: tests read it)."""
    lines = ["# The truth the measured wrench was made from (scripts/make_bags.py; no node of",
             "# this name: the tests read it): Kalker's exact theory under the law below, mu_s",
             "# = mu_static[i] from t = steps_from[i] s (after the first stamp), the load",
             "# cell's noise (N, one sigma) on force.x, the spells in the linear range (s).",
             "truth:", "  ros__parameters:", '    solver: "exact"']
    lines += [f"    {k}: {_yaml_value(v)}" for k, v in ADHESION_LAW.items()]
    lines += [f"    steps_from: {_yaml_value([float(a) for a, _ in ADHESION_STEPS])}",
              f"    mu_static: {_yaml_value([float(m) for _, m in ADHESION_STEPS])}",
              f"    linear_from: {_yaml_value([float(a) for a, _ in ADHESION_LINEAR])}",
              f"    linear_to: {_yaml_value([float(b) for _, b in ADHESION_LINEAR])}",
              f"    load_cell_noise: {_yaml_value(ADHESION_NOISE)}"]
    return "\n".join(lines) + "\n"


#: contaminated_rig's truth (also in its params file, section ``truth``): the modified FastSim's
#: alpha_inf and beta, the steps of mu_s and of k0 (from t, value: each steps while the other
#: holds), the spell of pure rolling (neither observable), the load cell's noise and its seed
CONTAMINATED_REDUCTION = {"slope_reduction_alpha_inf": 0.5, "slope_reduction_beta": 0.3}
CONTAMINATED_MU_STEPS = ((0.0, 0.4), (2.0, 0.25))
CONTAMINATED_K0_STEPS = ((0.0, 0.6), (1.0, 0.35), (3.0, 0.6))
CONTAMINATED_ROLLING = ((0.5, 0.8),)
CONTAMINATED_NOISE = 250.0
CONTAMINATED_SEED = 47
#: the creepage's sweep: log-uniform from XI_LOW to XI_HIGH and back in SWEEP_PERIOD s
CONTAMINATED_XI_LOW, CONTAMINATED_XI_HIGH, CONTAMINATED_SWEEP_PERIOD = 3.0e-4, 6.0e-2, 0.2


def stepped(steps: tuple[tuple[float, float], ...], t: float) -> float:
    """Return the value at ``t`` (s) of a staircase ``((from, value), ...)``."""
    return [v for start, v in steps if t >= start][-1]


def contaminated_xi(t: float) -> float:
    """Return contaminated_rig's creepage at ``t`` (s): a log sweep up and down, a rolling spell.

    From :data:`CONTAMINATED_XI_LOW` (the linear range: only k0 observable)
    to :data:`CONTAMINATED_XI_HIGH` (full slip: only mu_s) and back in
    :data:`CONTAMINATED_SWEEP_PERIOD`, through the knee (both) twice a
    sweep; 0 (pure rolling: neither) in :data:`CONTAMINATED_ROLLING`.
    """
    if any(a <= t < b for a, b in CONTAMINATED_ROLLING):
        return 0.0
    phase = (t % CONTAMINATED_SWEEP_PERIOD) / CONTAMINATED_SWEEP_PERIOD
    up = 2.0 * phase if phase < 0.5 else 2.0 * (1.0 - phase)
    return CONTAMINATED_XI_LOW * (CONTAMINATED_XI_HIGH / CONTAMINATED_XI_LOW) ** up


def contaminated_rig() -> tuple[Bag, dict[str, Any]]:
    """Build (i): a traction rig on a contaminated rail, mu_s and the slope reduction stepping.

    adhesion_rig's wheelset (Hertzian treads, 50 kN each, 20 x 20 cells,
    20 m/s, 100 Hz), 4 s, the creepage of :func:`contaminated_xi`; the
    measured wrench the modified FastSim's (the calibrated MAE under
    Coulomb's law at ``mu_s`` with the reduction ``k0``,
    :data:`CONTAMINATED_REDUCTION`'s ``alpha_inf`` and ``beta``: the
    estimator's own model, :class:`~fastsim_ros.estimation.CreepModel`
    without the knee factor) on the patches and creepages the node converts
    from these messages, ``mu_s`` and ``k0`` stepping at different times
    (:data:`CONTAMINATED_MU_STEPS`, :data:`CONTAMINATED_K0_STEPS`), plus a
    load cell's Gaussian noise of 250 N on ``force.x`` (seeded).
    """
    from fastsim_ros.contact.slope_reduction import SlopeReduction
    from fastsim_ros.estimation import ContactSample, CreepModel
    from fastsim_ros.estimation.model import solver_for

    solver = solver_for("mae_calibrated", NU, G)

    def measure(t: float, outcomes: list[Any]) -> tuple[float, float, float]:
        samples, normal = [], np.zeros(3)
        for out in outcomes:
            p, cr = out.patch, out.creepage
            samples.append(ContactSample(p.pressure, p.x0, p.y0, p.dx, p.dy, cr.xi, cr.eta,
                                         cr.phi, cr.speed,
                                         ((p.frame.axes[0][0], p.frame.axes[1][0]),)))
            normal += p.frame.to_wheelset((0.0, 0.0, p.load))
        model = CreepModel(solver, knee=False, reduction=SlopeReduction(
            stepped(CONTAMINATED_K0_STEPS, t),
            CONTAMINATED_REDUCTION["slope_reduction_alpha_inf"],
            CONTAMINATED_REDUCTION["slope_reduction_beta"]))
        fx = float(model.predict(samples, stepped(CONTAMINATED_MU_STEPS, t))[0]) + normal[0]
        return fx, 0.0, float(normal[2])
    bag = _rig("contaminated_rig", contaminated_xi, CONTAMINATED_SEED, CONTAMINATED_NOISE,
               measure)
    return bag, {"method": "mae_calibrated", "friction_coefficient": 0.3,
                 "slope_reduction_k0": 0.8, **CONTAMINATED_REDUCTION,
                 "friction_estimation": "on", "friction_estimate_slope_reduction": True,
                 "friction_measurement_noise": CONTAMINATED_NOISE,
                 "friction_estimate_sigma": 0.1, "friction_slope_sigma": 0.2}


def contaminated_truth_text() -> str:
    """Return the ``truth`` section of contaminated_rig's params file (tests read it)."""
    lines = ["# The truth the measured wrench was made from (scripts/make_bags.py; no node of",
             "# this name: the tests read it): the calibrated MAE under Coulomb's law with the",
             "# modified FastSim's reduction (alpha_inf, beta below), mu_s = mu_static[i] from",
             "# t = mu_from[i] s and k0 = k0[i] from t = k0_from[i] s (after the first stamp),",
             "# pure rolling (neither observable) in the spells, the load cell's noise (N).",
             "truth:", "  ros__parameters:", '    solver: "mae_calibrated"',
             '    friction_law: "constant"']
    lines += [f"    {k}: {_yaml_value(v)}" for k, v in CONTAMINATED_REDUCTION.items()]
    lines += [f"    mu_from: {_yaml_value([float(a) for a, _ in CONTAMINATED_MU_STEPS])}",
              f"    mu_static: {_yaml_value([float(m) for _, m in CONTAMINATED_MU_STEPS])}",
              f"    k0_from: {_yaml_value([float(a) for a, _ in CONTAMINATED_K0_STEPS])}",
              f"    k0: {_yaml_value([float(m) for _, m in CONTAMINATED_K0_STEPS])}",
              f"    rolling_from: {_yaml_value([float(a) for a, _ in CONTAMINATED_ROLLING])}",
              f"    rolling_to: {_yaml_value([float(b) for _, b in CONTAMINATED_ROLLING])}",
              f"    load_cell_noise: {_yaml_value(CONTAMINATED_NOISE)}"]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ params, main

SCENARIOS: dict[str, Callable[[], tuple[Bag, dict[str, Any]]]] = {
    "hertz_ramp": hertz_ramp,
    "semi_ellipses_spin": semi_ellipses_spin,
    "flange_shift": flange_shift,
    "roller_rig": roller_rig,
    "bad_inputs": bad_inputs,
    "mbench_a22": mbench_a22,
    "transient_step": transient_step,
    "adhesion_rig": adhesion_rig,
    "contaminated_rig": contaminated_rig,
}

BASE_PARAMS: dict[str, Any] = {
    "contacts": ["left", "right"],
    "wheelset_frame": FRAME,
    "shear_modulus": G,
    "poisson_ratio": NU,
    "friction_coefficient": 0.3,
    "method": "mae",
    "traction_bound": "given",
    "min_rolling_speed": MIN_ROLLING_SPEED,
    "max_kinematics_age": MAX_KINEMATICS_AGE,
    "publish_traction": False,
}


def _yaml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return f"{v:.1e}" if abs(v) >= 1e5 else repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, list):
        return "[" + ", ".join(_yaml_value(x) for x in v) + "]"
    return f'"{v}"'


def params_text(name: str, params: dict[str, Any]) -> str:
    """Return the ROS 2 parameter file of bag ``name`` (node ``fastsim``)."""
    lines = [f"# Node parameters for bags/{name} (made by scripts/make_bags.py)",
             "fastsim:", "  ros__parameters:"]
    lines += [f"    {k}: {_yaml_value(v)}" for k, v in params.items()]
    return "\n".join(lines) + "\n"


def expected_text(counts: dict[str, Any]) -> str:
    """Return ``bad_inputs.expected.yaml``: outcomes by contact."""
    lines = ["# Expected outcome of every patch of bags/bad_inputs by contact, computed by",
             "# scripts/make_bags.py from the bag it wrote (params: bad_inputs.params.yaml).",
             "# served: a wrench from a solve; no_contact: an empty patch, a zero wrench;",
             "# rejected/<reason>: no wrench.", "contacts:"]
    for contact, c in counts.items():
        lines += [f"  {contact}:", f"    patches: {c['patches']}", f"    served: {c['served']}",
                  f"    no_contact: {c['no_contact']}", "    rejected:"]
        lines += [f"      {r}: {n}" for r, n in c["rejected"].items()]
    return "\n".join(lines) + "\n"


def build(name: str, out: Path) -> Path:
    """Write bag ``name``, its params file and (bad inputs) its expected outcomes."""
    bag, extra = SCENARIOS[name]()
    params = dict(BASE_PARAMS, **extra)
    path = bag.write(out)
    (out / f"{name}.params.yaml").write_text(
        params_text(name, params) + (adhesion_truth_text() if name == "adhesion_rig" else
                                     contaminated_truth_text() if name == "contaminated_rig"
                                     else ""))
    if bag.tags:
        outcomes = classify_bag(path, params)
        for contact in sorted({c for c, _, _ in outcomes}):
            topic = f"/contact/{contact}/patch"
            seen = [o for c, o, _ in outcomes if c == contact]
            keys = sorted((key for key in bag.tags if key[0] == topic),
                          key=lambda key: bag.items[key[1]][:3])
            assert len(seen) == len(keys)
            for got, key in zip(seen, keys):
                want = bag.tags[key]
                want = ("nonfinite" if want.startswith("nonfinite") else
                        "implausible" if want.startswith("implausible") else want)
                if want == "good":
                    assert got in ("served", "no_kinematics", "stale_kinematics",
                                   "standstill"), got
                else:
                    assert got == want, (contact, got, want)
        (out / f"{name}.expected.yaml").write_text(expected_text(expected_counts(outcomes)))
    return path


BEGIN, END = "<!-- make_bags: begin -->", "<!-- make_bags: end -->"


def summary_text(out: Path) -> str:
    """Return the generated block of ``bags/README.md``: the bags on disk and expected outcomes."""
    lines = [BEGIN, "", "| bag | topic: messages | duration | size |", "| --- | --- | --- | --- |"]
    for name in SCENARIOS:
        path = out / name
        if not path.is_dir():
            continue
        with Reader(path) as reader:
            topics = ", ".join(f"`{c.topic}`: {c.msgcount}" for c in reader.connections)
            dur = reader.duration / 1e9
        size = sum(f.stat().st_size for f in path.iterdir())
        lines.append(f"| `{name}` | {topics} | {dur:.3f} s | {size / 1e3:.0f} kB |")
    total = sum(f.stat().st_size for f in out.rglob("*") if f.is_file() and f.name != "README.md")
    lines += ["", f"All of `bags/` but this file: {total / 1e6:.3f} MB.", ""]
    exp = out / "bad_inputs.expected.yaml"
    if exp.exists():
        counts = expected_counts(classify_bag(out / "bad_inputs", {}))
        names = list(counts)
        lines += ["Expected outcomes of `bad_inputs` (as in `bad_inputs.expected.yaml`):", "",
                  "| outcome | " + " | ".join(f"`{c}`" for c in names) + " |",
                  "| --- |" + " --- |" * len(names)]
        rows = [("patches", [counts[c]["patches"] for c in names]),
                ("served (a wrench from a solve)", [counts[c]["served"] for c in names]),
                ("`no_contact` (a zero wrench)", [counts[c]["no_contact"] for c in names])]
        rows += [(f"`rejected/{r}`", [counts[c]["rejected"][r] for c in names])
                 for r in REASONS]
        lines += [f"| {label} | " + " | ".join(str(v) for v in vals) + " |"
                  for label, vals in rows]
        lines.append("")
    return "\n".join(lines + [END])


def update_readme(out: Path) -> None:
    """Replace the generated block of ``out/README.md``, if it has one."""
    readme = out / "README.md"
    if not readme.exists():
        return
    text = readme.read_text()
    if BEGIN not in text or END not in text:
        return
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    readme.write_text(head + summary_text(out) + tail)


def main(argv: list[str] | None = None) -> int:
    """Write the bags; print each one's message count, size and build time."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "bags")
    ap.add_argument("--only", nargs="+", choices=list(SCENARIOS), default=list(SCENARIOS))
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name in args.only:
        t0 = time.perf_counter()
        path = build(name, args.out)
        size = sum(f.stat().st_size for f in path.iterdir())
        print(f"{path}: {size / 1e6:.3f} MB in {time.perf_counter() - t0:.1f} s")
    update_readme(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
