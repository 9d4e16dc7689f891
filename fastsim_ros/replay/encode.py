"""The node's per-patch output messages as CDR, many at a time.

Each message kind of a contact has one layout (its frame id is fixed), so a
template row is made once with the node's own encoders
(:func:`msg_adapters.cdr.stamped_doubles`; for markers
``rclpy.serialization`` of :func:`msg_adapters.outputs.force_marker`) and
the stamps and values are written into copies of it.  The values come from
the same arithmetic as the node's (term for term), so the messages decode
to the node's (the tests compare them field by field).
"""

from __future__ import annotations

import struct

import numpy as np
from numpy.typing import NDArray

from msg_adapters import outputs
from msg_adapters.cdr import stamped_doubles
from msg_adapters.patch import ContactFrame

Floats = NDArray[np.float64]
Ints = NDArray[np.int64]
Rows = NDArray[np.uint8]


def _fill_stamps(rows: Rows, stamps: Ints, at: int) -> None:
    """Write ``builtin_interfaces/Time`` (int32 sec, uint32 nanosec) of each stamp (ns)."""
    sec, nanosec = np.divmod(stamps.astype(np.int64), 1_000_000_000)
    rows[:, at:at + 4] = sec.astype("<i4").view(np.uint8).reshape(-1, 4)
    rows[:, at + 4:at + 8] = nanosec.astype("<u4").view(np.uint8).reshape(-1, 4)


class Stamped:
    """A header (stamp, ``frame_id``) and ``count`` doubles.

    ``WrenchStamped`` (6), ``Vector3Stamped`` (3), ``PoseStamped`` (7:
    position, quaternion ``x y z w``).
    """

    def __init__(self, frame_id: str, count: int) -> None:
        template = stamped_doubles(0, frame_id, (0.0,) * count)
        self.template = np.frombuffer(template, dtype=np.uint8)
        self.doubles = len(template) - 8 * count
        self.count = count

    def encode(self, stamps: Ints, values: Floats) -> Rows:
        """Return one message per row: ``(k, length)`` bytes."""
        rows = np.repeat(self.template[None], stamps.size, axis=0)
        _fill_stamps(rows, stamps, 4)
        rows[:, self.doubles:] = np.ascontiguousarray(values, dtype="<f8").view(
            np.uint8).reshape(stamps.size, 8 * self.count)
        return rows


_SEC, _NANOSEC = 0x2B3C4D5E, 987_654_321
#: a frame and forces whose arrow has six distinct, unmistakable coordinates
_ORIGIN = (1.2345678901234567e-150, 2.3456789012345678e-150, 3.4567890123456789e-150)
_AXES = ((0.6, 0.0, 0.8), (0.0, 1.0, 0.0), (-0.8, 0.0, 0.6))
_FORCE = (1.0e-140, 3.0e-140)


class Markers:
    """The ``MarkerArray`` of one contact's creep-force arrow (or its deletion).

    Templates from the node's own encoder
    (:func:`msg_adapters.outputs.force_marker_cdr`): where the stamp and the
    arrow's two points lie is found by encoding unmistakable values.
    """

    def __init__(self, frame_id: str, index: int, contact: str, scale: float) -> None:
        self.scale = scale
        stamp = _SEC * 1_000_000_000 + _NANOSEC
        frame = ContactFrame(_ORIGIN, _AXES)
        fx, fy = _FORCE[0] / scale, _FORCE[1] / scale
        tip = frame.to_wheelset((fx * scale, fy * scale, 0.0))
        points = _ORIGIN + tuple(o + t for o, t in zip(_ORIGIN, tip))
        self.arrow, self.arrow_at = self._template(outputs.force_marker_cdr(
            stamp, frame_id, index, contact, frame, fx, fy, scale), points)
        self.delete, self.delete_at = self._template(outputs.force_marker_cdr(
            stamp, frame_id, index, contact, None, 0.0, 0.0, scale), ())

    @staticmethod
    def _template(data: bytes, points: tuple[float, ...]) -> tuple[Rows, list[int]]:
        marks = [struct.pack("<iI", _SEC, _NANOSEC)] + [struct.pack("<d", v) for v in points]
        found = []
        for m in marks:
            at = data.find(m)
            if at < 0 or data.find(m, at + 1) >= 0:
                raise RuntimeError("cannot find the marker's fields in its CDR")
            found.append(at)
        return np.frombuffer(data, dtype=np.uint8), found

    def arrows(self, stamps: Ints, frame: Floats, fx: Floats, fy: Floats) -> Rows:
        """Return the arrows of forces ``fx, fy`` (N) at frames (origin, ``e_x .. e_z``).

        Each from the origin to ``origin + scale (Fx e_x + Fy e_y)``.
        """
        rows = np.repeat(self.arrow[None], stamps.size, axis=0)
        _fill_stamps(rows, stamps, self.arrow_at[0])
        a, b = fx * self.scale, fy * self.scale
        o = frame[:, 0:3]
        # ContactFrame.to_wheelset((a, b, 0.0)), term for term
        tip = [a * frame[:, 3 + k] + b * frame[:, 6 + k] + 0.0 * frame[:, 9 + k]
               for k in range(3)]
        values = (o[:, 0], o[:, 1], o[:, 2], o[:, 0] + tip[0], o[:, 1] + tip[1], o[:, 2] + tip[2])
        for at, v in zip(self.arrow_at[1:], values):
            rows[:, at:at + 8] = np.ascontiguousarray(v, dtype="<f8").view(
                np.uint8).reshape(-1, 8)
        return rows

    def deletions(self, stamps: Ints) -> Rows:
        """Return the deletions of the arrow (no contact)."""
        rows = np.repeat(self.delete[None], stamps.size, axis=0)
        _fill_stamps(rows, stamps, self.delete_at[0])
        return rows


def quaternions(frame: Floats) -> Floats:
    """Return the frames' orientations as quaternions ``(k, 4)``: ``x, y, z, w``.

    :meth:`msg_adapters.patch.ContactFrame.quaternion` on arrays (rows:
    origin, ``e_x``, ``e_y``, ``e_z``), branch for branch.
    """
    xx, xy, xz = frame[:, 3], frame[:, 4], frame[:, 5]
    yx, yy, yz = frame[:, 6], frame[:, 7], frame[:, 8]
    zx, zy, zz = frame[:, 9], frame[:, 10], frame[:, 11]
    m00, m01, m02 = xx, yx, zx
    m10, m11, m12 = xy, yy, zy
    m20, m21, m22 = xz, yz, zz
    trace = m00 + m11 + m22
    q = np.empty((frame.shape[0], 4))
    first = trace > 0.0
    second = ~first & (m00 > m11) & (m00 > m22)
    third = ~first & ~second & (m11 > m22)
    fourth = ~(first | second | third)
    with np.errstate(all="ignore"):
        s = 2.0 * np.sqrt(trace + 1.0)
        q[first] = np.stack(((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s,
                             0.25 * s), axis=1)[first]
        s = 2.0 * np.sqrt(1.0 + m00 - m11 - m22)
        q[second] = np.stack((0.25 * s, (m01 + m10) / s, (m02 + m20) / s,
                              (m21 - m12) / s), axis=1)[second]
        s = 2.0 * np.sqrt(1.0 + m11 - m00 - m22)
        q[third] = np.stack(((m01 + m10) / s, 0.25 * s, (m12 + m21) / s,
                             (m02 - m20) / s), axis=1)[third]
        s = 2.0 * np.sqrt(1.0 + m22 - m00 - m11)
        q[fourth] = np.stack(((m02 + m20) / s, (m12 + m21) / s, 0.25 * s,
                              (m10 - m01) / s), axis=1)[fourth]
    return q
