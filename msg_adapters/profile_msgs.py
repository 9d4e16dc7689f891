"""Messages of the profiles patch source: poses and loads in, patch clouds out.

docs/guide_profiles.md: ``wheelset/pose`` is
a ``geometry_msgs/PoseStamped`` in the track frame (the wheelset frame's
origin and orientation), ``wheelset/load`` a ``geometry_msgs/WrenchStamped``
in the wheelset frame (``force.z`` the total vertical load, ``torque.x`` the
roll moment that splits it between the wheels); the computed patches go out
on ``contact/<name>/patch`` as ``sensor_msgs/PointCloud2`` in the layout the
patch adapter reads (float64, so that a recording replays to the same
numbers).  Pure conversions, no node state.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from msg_adapters.cdr import Cloud, PointFieldSpec, StampedTwist, read_twist
from msg_adapters.errors import MalformedMessageError
from msg_adapters.patch import FLOAT64, PATCH_FIELDS

FloatArray = NDArray[np.float64]

_POSE = {"<": struct.Struct("<7d"), ">": struct.Struct(">7d")}


@dataclass(frozen=True, slots=True)
class StampedPose:
    """A ``geometry_msgs/PoseStamped``: stamp (ns), frame, position (m), quaternion ``x y z w``."""

    stamp_ns: int
    frame_id: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]

    def is_finite(self) -> bool:
        """Return whether every number is finite."""
        return all(math.isfinite(v) for v in self.position + self.orientation)

    def roll_yaw(self) -> tuple[float, float]:
        """Return ``(roll, yaw)`` (rad) of ``R = Rx(roll) Rz(yaw)`` (a pitch is ignored).

        The quaternion is normalised first; a zero one raises
        :class:`MalformedMessageError`.
        """
        x, y, z, w = self.orientation
        # scaled by its largest component first: a finite quaternion of 1e300 squared to inf
        # (its norm then made it zero: a 90 degree yaw served as none)
        big = max(abs(x), abs(y), abs(z), abs(w))
        if not big > 0.0:
            raise MalformedMessageError("a zero quaternion")
        x, y, z, w = x / big, y / big, z / big, w / big
        norm = math.sqrt(x * x + y * y + z * z + w * w)
        x, y, z, w = x / norm, y / norm, z / norm, w / norm
        r00 = 1.0 - 2.0 * (y * y + z * z)
        r01 = 2.0 * (x * y - z * w)
        r12 = 2.0 * (y * z - x * w)
        r22 = 1.0 - 2.0 * (x * x + y * y)
        # R = Rx(phi) Rz(psi): R01 = -sin(psi), R00 = cos(psi), R12 = -sin(phi), R22 = cos(phi)
        return math.atan2(-r12, r22), math.atan2(-r01, r00)


def quaternion(roll: float, yaw: float) -> tuple[float, float, float, float]:
    """Return the unit quaternion ``x y z w`` of ``Rx(roll) Rz(yaw)``."""
    cr, sr = math.cos(0.5 * roll), math.sin(0.5 * roll)
    cy, sy = math.cos(0.5 * yaw), math.sin(0.5 * yaw)
    # q = qx(roll) * qz(yaw)
    return (sr * cy, -sr * sy, cr * sy, cr * cy)


def read_pose(buf: bytes | memoryview) -> StampedPose:
    """Decode a serialized ``geometry_msgs/PoseStamped``."""
    view = memoryview(buf).cast("B") if memoryview(buf).format != "B" else memoryview(buf)
    if len(view) < 4:
        raise MalformedMessageError("shorter than the CDR encapsulation header")
    if view[0] != 0 or view[1] > 1:
        raise MalformedMessageError("not plain CDR")
    order = "<" if view[1] == 1 else ">"
    body = view[4:]
    if len(body) < 12:
        raise MalformedMessageError("truncated")
    sec, nanosec, size = struct.unpack_from(order + "iII", body, 0)
    pos = 12 + size
    if size > len(body) - 12:
        raise MalformedMessageError("truncated")
    try:
        frame = bytes(body[12:12 + max(0, size - 1)]).decode("utf-8")
    except UnicodeDecodeError:
        raise MalformedMessageError("a string that is not UTF-8") from None
    pos += -pos % 8
    if pos + 56 > len(body):
        raise MalformedMessageError("truncated")
    v = _POSE[order].unpack_from(body, pos)
    return StampedPose(int(sec) * 1_000_000_000 + int(nanosec), frame, (v[0], v[1], v[2]),
                       (v[3], v[4], v[5], v[6]))


def read_load(buf: bytes | memoryview) -> StampedTwist:
    """Decode a serialized ``geometry_msgs/WrenchStamped`` (the layout of a TwistStamped).

    ``linear`` is the force (N), ``angular`` the torque (N m).
    """
    return read_twist(buf)


_FIELDS = {name: PointFieldSpec(8 * k, FLOAT64, 1) for k, name in enumerate(PATCH_FIELDS)}


def patch_cloud(stamp_ns: int, frame_id: str, points: FloatArray, normal: FloatArray,
                pressure: FloatArray) -> Cloud:
    """Return a patch as a decoded cloud (float64, little endian) for the pipeline.

    ``points``: ``(ny, nx, 3)`` cell centres (m); ``normal``: ``(3,)`` or
    ``(ny, nx, 3)``; ``pressure``: ``(ny, nx)`` (Pa).  An empty ``pressure``
    (``0 x 0``) is an empty patch: no contact.
    """
    ny, nx = pressure.shape
    rec = np.empty((ny, nx, 7), dtype="<f8")
    if ny * nx:
        rec[..., 0:3] = points
        rec[..., 3:6] = np.broadcast_to(normal, (ny, nx, 3))
        rec[..., 6] = pressure
    data = memoryview(rec.tobytes())
    return Cloud(stamp_ns, frame_id, ny, nx, _FIELDS, False, 56, 56 * nx, data)


def cloud_cdr(cloud: Cloud) -> bytes:
    """Serialize a cloud as a ``sensor_msgs/PointCloud2`` (little endian, ``is_dense`` true)."""
    sec, nanosec = divmod(int(cloud.stamp_ns), 1_000_000_000)
    out = bytearray(b"\x00\x01\x00\x00")

    def align(n: int) -> None:
        out.extend(b"\x00" * (-(len(out) - 4) % n))

    def string(text: str) -> None:
        raw = text.encode("utf-8") + b"\x00"
        align(4)
        out.extend(struct.pack("<I", len(raw)))
        out.extend(raw)

    out.extend(struct.pack("<iI", sec, nanosec))
    string(cloud.frame_id)
    align(4)
    out.extend(struct.pack("<III", cloud.height, cloud.width, len(cloud.fields)))
    for name, spec in cloud.fields.items():
        string(name)
        align(4)
        out.extend(struct.pack("<IBxxxI", spec.offset, spec.datatype, spec.count))
    out.extend(struct.pack("<?", cloud.is_bigendian))
    align(4)
    out.extend(struct.pack("<II", cloud.point_step, cloud.row_step))
    data = bytes(cloud.data)
    out.extend(struct.pack("<I", len(data)))
    out.extend(data)
    out.extend(struct.pack("<?", True))
    return bytes(out)
