"""Just enough CDR (XCDR1, the ROS 2 wire format) for the node's hot messages.

The node subscribes to patches and twists raw and publishes its wrenches
as bytes: a PointCloud2 of 30 x 30 cells costs rclpy about as much to turn
into a Python message as the MAE solve itself, while its point buffer is one
contiguous block that numpy can view in place.  The replay reads the same
bytes from bags.  Layouts follow the ``.msg`` definitions of
``std_msgs/Header``, ``sensor_msgs/PointCloud2``, ``sensor_msgs/PointField``
and ``geometry_msgs`` (Twist, Wrench, Vector3, Pose): primitives aligned to
their size relative to the end of the 4-byte encapsulation header, strings
as ``uint32`` length (NUL included) + bytes + NUL, sequences as ``uint32``
count + elements.  Tests compare every encoder and decoder with
``rclpy.serialization``.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Any

from msg_adapters.errors import MalformedMessageError

#: encapsulation headers: CDR big endian, CDR little endian
_CDR_BE = b"\x00\x00\x00\x00"
_CDR_LE = b"\x00\x01\x00\x00"

_U32 = {"<": struct.Struct("<I"), ">": struct.Struct(">I")}
_I32U32 = {"<": struct.Struct("<iI"), ">": struct.Struct(">iI")}
_FIELD_TAIL = {"<": struct.Struct("<IBxxxI"), ">": struct.Struct(">IBxxxI")}
_SIX_DOUBLES = {"<": struct.Struct("<6d"), ">": struct.Struct(">6d")}
_PC2_STEPS = {"<": struct.Struct("<?xxxII"), ">": struct.Struct(">?xxxII")}


@dataclass(frozen=True, slots=True)
class PointFieldSpec:
    """One ``sensor_msgs/PointField``: byte offset in a point, datatype code, count."""

    offset: int
    datatype: int
    count: int


@dataclass(frozen=True, slots=True)
class Cloud:
    """A ``sensor_msgs/PointCloud2`` with its point buffer as a memoryview (no copy).

    ``stamp_ns``: header stamp (ns since the epoch of the stamp's clock);
    ``fields``: by name.  The point of row ``j``, column ``i`` starts at
    byte ``j * row_step + i * point_step`` of ``data``.
    """

    stamp_ns: int
    frame_id: str
    height: int
    width: int
    fields: dict[str, PointFieldSpec]
    is_bigendian: bool
    point_step: int
    row_step: int
    data: memoryview


@dataclass(frozen=True, slots=True)
class StampedTwist:
    """A ``geometry_msgs/TwistStamped``: stamp (ns), frame, linear (m/s), angular (rad/s)."""

    stamp_ns: int
    frame_id: str
    linear: tuple[float, float, float]
    angular: tuple[float, float, float]


class _Reader:
    """A cursor over one CDR buffer."""

    __slots__ = ("buf", "pos", "end", "order")

    def __init__(self, buf: bytes | memoryview) -> None:
        view = memoryview(buf)
        if view.format != "B" or view.ndim != 1:
            view = view.cast("B")
        if len(view) < 4:
            raise MalformedMessageError("shorter than the CDR encapsulation header")
        kind = view[1]
        if view[0] != 0 or kind > 1:
            raise MalformedMessageError(f"not plain CDR (encapsulation {bytes(view[:2]).hex()})")
        self.order = "<" if kind == 1 else ">"
        self.buf = view[4:]
        self.pos = 0
        self.end = len(self.buf)

    def _take(self, size: int, align: int) -> int:
        pos = self.pos + (-self.pos % align)
        if pos + size > self.end:
            raise MalformedMessageError("truncated")
        self.pos = pos + size
        return pos

    def u32(self) -> int:
        value: int = _U32[self.order].unpack_from(self.buf, self._take(4, 4))[0]
        return value

    def stamp_ns(self) -> int:
        sec, nanosec = _I32U32[self.order].unpack_from(self.buf, self._take(8, 4))
        return int(sec) * 1_000_000_000 + int(nanosec)

    def string(self) -> str:
        size = self.u32()
        if size == 0:  # some writers send no NUL for an empty string
            return ""
        start = self._take(size, 1)
        raw = bytes(self.buf[start:start + size - 1])
        try:
            return raw.decode("utf-8")
        except UnicodeDecodeError:
            raise MalformedMessageError("a string that is not UTF-8") from None

    def doubles6(self) -> tuple[float, ...]:
        values: tuple[float, ...] = _SIX_DOUBLES[self.order].unpack_from(
            self.buf, self._take(48, 8))
        return values


_FIELDS_CACHE: dict[bytes, tuple[dict[str, PointFieldSpec], int]] = {}


def _read_fields(r: _Reader, count: int) -> dict[str, PointFieldSpec]:
    """Read ``count`` PointFields; the same bytes give the same (cached) dict."""
    start = r.pos
    # a patch topic sends the same field list every time: key the parse on its
    # bytes (the first 32 bytes per field cover the usual names and layout)
    probe = bytes(r.buf[start:start + 32 * count])
    hit = _FIELDS_CACHE.get(probe)
    if hit is not None and start + hit[1] <= r.end:
        r.pos = start + hit[1]
        return hit[0]
    fields: dict[str, PointFieldSpec] = {}
    tail = _FIELD_TAIL[r.order]
    for _ in range(count):
        name = r.string()
        offset, datatype, n = tail.unpack_from(r.buf, r._take(12, 4))
        fields[name] = PointFieldSpec(int(offset), int(datatype), int(n))
    length = r.pos - start
    if length <= len(probe) and len(_FIELDS_CACHE) < 64:
        _FIELDS_CACHE[bytes(r.buf[start:start + 32 * count])] = (fields, length)
    return fields


def read_cloud(buf: bytes | memoryview) -> Cloud:
    """Decode a serialized ``sensor_msgs/PointCloud2``; the points stay in ``buf``.

    The returned ``fields`` dict may be shared between calls: do not change it.
    """
    return _read_cloud(buf)[0]


def _read_cloud(buf: bytes | memoryview) -> tuple[Cloud, int]:
    """Return the cloud and where its points start in ``buf`` (bytes)."""
    r = _Reader(buf)
    stamp = r.stamp_ns()
    frame = r.string()
    height = r.u32()
    width = r.u32()
    count = r.u32()
    if count > 64:
        raise MalformedMessageError(f"{count} point fields")
    fields = _read_fields(r, count)
    bigendian, point_step, row_step = _PC2_STEPS[r.order].unpack_from(r.buf, r._take(12, 1))
    size = r.u32()
    start = r._take(size, 1)
    return Cloud(stamp, frame, int(height), int(width), fields, bool(bigendian),
                 int(point_step), int(row_step), r.buf[start:start + size]), 4 + start


class CloudReader:
    """:func:`read_cloud` for one topic: the header parsed once while it stays the same.

    A topic's patches differ in their stamp and their points only: when the
    bytes between the stamp and the points (frame id, sizes, fields, steps,
    the data's length) equal the last message's, the cloud is rebuilt from
    the last parse with the new stamp and data (a comparison of ~200 bytes
    instead of a parse).  Anything else is parsed afresh.
    """

    __slots__ = ("_key", "_start", "_cloud")

    def __init__(self) -> None:
        self._key = b""
        self._start = 0
        self._cloud: Cloud | None = None

    def read(self, buf: bytes | memoryview) -> Cloud:
        """Decode a serialized ``sensor_msgs/PointCloud2`` (as :func:`read_cloud`)."""
        last, start = self._cloud, self._start
        if last is not None and len(buf) >= start + len(last.data) \
                and buf[:4] == self._key[:4] and buf[12:start] == self._key[4:]:
            sec, nanosec = _I32U32[">" if buf[1] == 0 else "<"].unpack_from(buf, 4)
            view = memoryview(buf)
            return Cloud(int(sec) * 1_000_000_000 + int(nanosec), last.frame_id, last.height,
                         last.width, last.fields, last.is_bigendian, last.point_step,
                         last.row_step, view[start:start + len(last.data)])
        cloud, start = _read_cloud(buf)
        if isinstance(buf, bytes):  # (a memoryview's slices would compare otherwise)
            self._key = buf[:4] + buf[12:start]
            self._start = start
            self._cloud = cloud
        return cloud


_TWIST_HEAD = struct.Struct("<4xiII")


def read_twist(buf: bytes | memoryview) -> StampedTwist:
    """Decode a serialized ``geometry_msgs/TwistStamped`` (also a ``WrenchStamped``: one layout).

    Little-endian CDR with a NUL-terminated frame id (what every ROS 2
    writer sends) is read with two unpacks; anything else by the general
    reader, which names what is wrong.
    """
    if isinstance(buf, (bytes, bytearray)) and len(buf) >= 16 and buf[:4] == _CDR_LE:
        sec, nanosec, size = _TWIST_HEAD.unpack_from(buf)
        # the six doubles start 8-aligned after the string (offsets from byte 4)
        start = 16 + size + (-(12 + size) % 8)
        if size > 0 and start + 48 <= len(buf) and buf[15 + size] == 0:
            try:
                frame = buf[16:15 + size].decode("utf-8")
            except UnicodeDecodeError:
                raise MalformedMessageError("a string that is not UTF-8") from None
            v = _SIX_DOUBLES["<"].unpack_from(buf, start)
            return StampedTwist(sec * 1_000_000_000 + nanosec, frame, (v[0], v[1], v[2]),
                                (v[3], v[4], v[5]))
    r = _Reader(buf)
    stamp = r.stamp_ns()
    frame = r.string()
    v = r.doubles6()
    return StampedTwist(stamp, frame, (v[0], v[1], v[2]), (v[3], v[4], v[5]))


class Writer:
    """A little-endian CDR buffer being written, for building message templates.

    Primitives are aligned to their size relative to the payload (after the
    encapsulation header); the ``f64``, ``stamp`` and ``doubles`` writers
    return where their bytes start, so that a :class:`Template` can patch
    them later.
    """

    __slots__ = ("buf",)

    def __init__(self) -> None:
        self.buf = bytearray(_CDR_LE)

    def _align(self, size: int) -> None:
        self.buf += b"\x00" * (-(len(self.buf) - 4) % size)

    def _put(self, fmt: str, size: int, *values: Any) -> int:
        self._align(size)
        at = len(self.buf)
        self.buf += struct.pack("<" + fmt, *values)
        return at

    def u8(self, value: int) -> None:
        """Write a uint8 (or a bool)."""
        self.buf.append(value)

    def i32(self, value: int) -> None:
        """Write an int32."""
        self._put("i", 4, value)

    def u32(self, value: int) -> None:
        """Write a uint32 (also a sequence's length)."""
        self._put("I", 4, value)

    def f32(self, *values: float) -> None:
        """Write float32s."""
        self._put(f"{len(values)}f", 4, *values)

    def doubles(self, *values: float) -> int:
        """Write float64s; return where the first starts."""
        return self._put(f"{len(values)}d", 8, *values)

    def string(self, text: str) -> None:
        """Write a string: uint32 length (NUL included), the UTF-8 bytes, NUL."""
        raw = text.encode("utf-8") + b"\x00"
        self.u32(len(raw))
        self.buf += raw

    def stamp(self, stamp_ns: int = 0) -> int:
        """Write a ``builtin_interfaces/Time``; return where it starts."""
        sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
        return self._put("iI", 4, sec, nanosec)

    def header(self, frame_id: str, stamp_ns: int = 0) -> int:
        """Write a ``std_msgs/Header``; return where its stamp starts."""
        at = self.stamp(stamp_ns)
        self.string(frame_id)
        return at


class Template:
    """A serialized message whose stamp and one run of doubles change from message to message.

    Built once (by a :class:`Writer`) for what stays (frame ids, names,
    layout); :meth:`encode` packs the stamp and the values into the one
    buffer it keeps and returns a copy: no message object, no allocation
    but the returned bytes.
    """

    __slots__ = ("_buf", "_stamp_at", "_values_at", "_pack")

    def __init__(self, buf: bytearray, stamp_at: int, values_at: int, count: int) -> None:
        self._buf = buf
        self._stamp_at = stamp_at
        self._values_at = values_at
        self._pack = struct.Struct(f"<{count}d").pack_into

    def encode(self, stamp_ns: int, *values: float) -> bytes:
        """Return the message with ``stamp_ns`` and ``values`` in place."""
        buf = self._buf
        _STAMP_LE.pack_into(buf, self._stamp_at, *divmod(stamp_ns, 1_000_000_000))
        self._pack(buf, self._values_at, *values)
        return bytes(buf)


_STAMP_LE = struct.Struct("<iI")
_STAMPED: dict[tuple[str, int], Template] = {}


def stamped_doubles_template(frame_id: str, count: int) -> Template:
    """Return the template of a header and ``count`` doubles (as :func:`stamped_doubles`)."""
    w = Writer()
    stamp_at = w.header(frame_id)
    return Template(w.buf, stamp_at, w.doubles(*([0.0] * count)), count)


def stamped_doubles(stamp_ns: int, frame_id: str, values: tuple[float, ...]) -> bytes:
    """Serialize a header followed by doubles.

    That is the layout of ``WrenchStamped`` (6 doubles), ``Vector3Stamped``
    (3), ``PointStamped`` (3) and ``PoseStamped`` (7: position, then the
    orientation quaternion ``x, y, z, w``).  The template of each frame id
    and count is built once (a few hundred kept).
    """
    key = (frame_id, len(values))
    template = _STAMPED.get(key)
    if template is None:
        template = stamped_doubles_template(frame_id, len(values))
        if len(_STAMPED) < 512:
            _STAMPED[key] = template
    return template.encode(stamp_ns, *values)
