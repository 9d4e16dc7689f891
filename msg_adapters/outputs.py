"""Results -> messages: wrenches, creepages, frames, traction clouds, markers, diagnostics.

Every per-patch message (``WrenchStamped``, ``Vector3Stamped``,
``PoseStamped``, the traction ``PointCloud2`` and the ``MarkerArray``) is
written straight to CDR bytes (:mod:`msg_adapters.cdr`), from a template
built once per frame id and contact where only the stamp and the numbers
change: the node publishes them raw and the replay writes them to bags as
they are.  Diagnostics (once a second) are a message object;
``rclpy.serialization.serialize_message`` turns it into bytes.  Frames
(docs/guide_node.md): a contact's wrench and creepage in
``<name>_contact``; frame, markers, traction cloud and the wheelset wrench
in the wheelset frame.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Sequence

import numpy as np
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

from msg_adapters.cdr import Template, Writer, stamped_doubles
from msg_adapters.patch import ContactFrame

#: traction cloud layout: x y z tau_x tau_y as float32, slip as uint8, the frictional power
#: density friction_power as float32 after padding, 28 bytes a point
TRACTION_DTYPE = np.dtype({"names": ["x", "y", "z", "tau_x", "tau_y", "slip", "friction_power"],
                           "formats": ["<f4", "<f4", "<f4", "<f4", "<f4", "u1", "<f4"],
                           "offsets": [0, 4, 8, 12, 16, 20, 24], "itemsize": 28})
_TRACTION_OFFSETS = (("x", 0), ("y", 4), ("z", 8), ("tau_x", 12), ("tau_y", 16), ("slip", 20),
                     ("friction_power", 24))
_UINT8, _FLOAT32 = 2, 7


def contact_frame_id(contact: str) -> str:
    """Return the frame id of a contact's wrench and creepage (``<name>_contact``)."""
    return f"{contact}_contact"


def stamp_msg(stamp_ns: int) -> Time:
    """Return ``builtin_interfaces/Time`` of a stamp in ns."""
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


def wrench_cdr(stamp_ns: int, frame_id: str, force: Sequence[float],
               torque: Sequence[float]) -> bytes:
    """Return a serialized ``geometry_msgs/WrenchStamped`` (N, N m)."""
    return stamped_doubles(stamp_ns, frame_id, (force[0], force[1], force[2],
                                                torque[0], torque[1], torque[2]))


def contact_wrench_cdr(stamp_ns: int, contact: str, fx: float, fy: float, n: float,
                       mz: float) -> bytes:
    """Return a contact's ``WrenchStamped``: ``force = (Fx, Fy, N)``, ``torque.z = Mz``."""
    return wrench_cdr(stamp_ns, contact_frame_id(contact), (fx, fy, n), (0.0, 0.0, mz))


def pose_cdr(stamp_ns: int, wheelset_frame: str, frame: ContactFrame) -> bytes:
    """Return a serialized ``PoseStamped``: the contact frame in the wheelset frame."""
    return stamped_doubles(stamp_ns, wheelset_frame, frame.origin + frame.quaternion())


def traction_cloud_cdr(stamp_ns: int, wheelset_frame: str, frame: ContactFrame,
                       tau_x: np.ndarray, tau_y: np.ndarray, slip: np.ndarray,
                       grid: tuple[float, float, float, float],
                       power: np.ndarray | None = None) -> bytes:
    """Return the solved traction as a serialized organised ``PointCloud2`` in the wheelset frame.

    One point per cell of ``grid = (x0, y0, dx, dy)`` in the contact plane
    (the patch's cells: the pipeline moves the equivalent ellipse's traction
    there from its own grid), placed at ``origin + x e_x + y e_y``; ``tau_x``,
    ``tau_y``: traction of the rail on the wheel along the contact frame's
    axes (Pa); ``slip``: 1 where the cell is on the traction bound;
    ``power``: the frictional power density ``-tau . s |V|`` (W/m^2, zero
    where the cell sticks; None: NaN, not computed).  Fields ``x y z tau_x
    tau_y`` float32, ``slip`` uint8 and ``friction_power`` float32
    (TRACTION_DTYPE).
    """
    ny, nx = tau_x.shape
    x0, y0, dx, dy = grid
    xs = x0 + dx * np.arange(nx)
    ys = y0 + dy * np.arange(ny)
    ex, ey, _ = (np.asarray(a) for a in frame.axes)
    pos = (np.asarray(frame.origin) + xs[None, :, None] * ex + ys[:, None, None] * ey)
    pts = np.zeros((ny, nx), dtype=TRACTION_DTYPE)
    pts["x"], pts["y"], pts["z"] = pos[..., 0], pos[..., 1], pos[..., 2]
    pts["tau_x"], pts["tau_y"], pts["slip"] = tau_x, tau_y, slip
    pts["friction_power"] = np.nan if power is None else power
    w = Writer()
    w.header(wheelset_frame, stamp_ns)
    w.u32(ny)
    w.u32(nx)
    w.u32(len(_TRACTION_OFFSETS))
    for name, offset in _TRACTION_OFFSETS:
        w.string(name)
        w.u32(offset)
        w.u8(_UINT8 if name == "slip" else _FLOAT32)
        w.u32(1)
    w.u8(0)  # is_bigendian
    w.u32(TRACTION_DTYPE.itemsize)
    w.u32(TRACTION_DTYPE.itemsize * nx)
    w.u32(pts.nbytes)
    w.buf += pts.tobytes()
    w.u8(1)  # is_dense
    return bytes(w.buf)


#: visualization_msgs/Marker's type ARROW and actions ADD, DELETE
_ARROW, _ADD, _DELETE = 0, 0, 2
#: the arrow's shaft diameter, head diameter and head length (m), and its colour (RGBA)
ARROW_SCALE = (0.004, 0.008, 0.01)
ARROW_COLOR = (0.9, 0.2, 0.1, 1.0)
_MARKERS: dict[tuple[str, int, str, bool], Template] = {}


def _marker_template(wheelset_frame: str, index: int, contact: str, add: bool) -> Template:
    """Return the template of a ``MarkerArray`` holding one arrow (or its deletion)."""
    w = Writer()
    w.u32(1)  # markers: one
    stamp_at = w.header(wheelset_frame)
    w.string("creep_force")  # ns
    w.i32(index)
    w.i32(_ARROW)
    w.i32(_ADD if add else _DELETE)
    w.doubles(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)  # pose: at the origin, not turned
    w.doubles(*(ARROW_SCALE if add else (0.0, 0.0, 0.0)))
    w.f32(*(ARROW_COLOR if add else (0.0, 0.0, 0.0, 0.0)))
    w.i32(0)  # lifetime: forever
    w.u32(0)
    w.u8(0)  # frame_locked
    w.u32(2 if add else 0)  # points: from the contact origin to the arrow's tip
    values_at = w.doubles(*([0.0] * 6)) if add else 0
    w.u32(0)  # colors
    w.string("")  # texture_resource
    w.header("")  # texture (sensor_msgs/CompressedImage): header, format, data
    w.string("")
    w.u32(0)
    w.u32(0)  # uv_coordinates
    w.string(contact)  # text
    w.string("")  # mesh_resource
    w.string("")  # mesh_file: filename, data
    w.u32(0)
    w.u8(0)  # mesh_use_embedded_materials
    return Template(w.buf, stamp_at, values_at, 6 if add else 0)


def force_marker_cdr(stamp_ns: int, wheelset_frame: str, index: int, contact: str,
                     frame: ContactFrame | None, fx: float, fy: float, scale: float) -> bytes:
    """Return a serialized ``MarkerArray``: an arrow from the contact origin along the creep force.

    ``scale`` m/N; marker ``id`` = ``index``, namespace ``creep_force``, text
    the contact's name.  Without a frame (no contact) the arrow of that
    contact is deleted.
    """
    key = (wheelset_frame, index, contact, frame is not None)
    template = _MARKERS.get(key)
    if template is None:
        template = _marker_template(*key)
        if len(_MARKERS) < 512:
            _MARKERS[key] = template
    if frame is None:
        return template.encode(stamp_ns)
    tip = frame.to_wheelset((fx * scale, fy * scale, 0.0))
    o = frame.origin
    return template.encode(stamp_ns, o[0], o[1], o[2], o[0] + tip[0], o[1] + tip[1],
                           o[2] + tip[2])


def diagnostic_array(stamp_ns: int, statuses: Iterable[tuple[str, int, str,
                                                             Sequence[tuple[str, str]]]],
                     hardware_id: str = "fastsim") -> DiagnosticArray:
    """Return a ``DiagnosticArray`` of ``(name, level, message, key-values)`` statuses."""
    msg = DiagnosticArray()
    msg.header.stamp = stamp_msg(stamp_ns)
    msg.status = [DiagnosticStatus(level=bytes([level]), name=name, message=message,
                                   hardware_id=hardware_id,
                                   values=[KeyValue(key=k, value=v) for k, v in values])
                  for name, level, message, values in statuses]
    return msg


_PAD = (b"", b"\x00\x00\x00", b"\x00\x00", b"\x00")   # by length % 4: to the next 4
_U32 = struct.Struct("<I").pack


def diagnostic_array_cdr(stamp_ns: int, statuses: Iterable[tuple[str, int, str,
                                                                 Sequence[tuple[str, str]]]],
                         hardware_id: str = "fastsim") -> bytes:
    """Return :func:`diagnostic_array`'s message as CDR bytes, written directly.

    The message ``rclpy.serialization.serialize_message`` gives (it
    deserialises to the same fields; rclpy leaves the padding bytes as they
    were, these are zero), without building its Python objects: some 80
    key-values a period, most of the diagnostics' cost.
    """
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    statuses = list(statuses)
    # encapsulation, stamp, frame_id "" (length 1, NUL), padding, the statuses' count
    parts = [b"\x00\x01\x00\x00", struct.pack("<iII", sec, nanosec, 1), b"\x00\x00\x00\x00",
             _U32(len(statuses))]
    size = 20          # bytes so far after the encapsulation header, for CDR's alignment
    hardware = hardware_id.encode("utf-8") + b"\x00"

    def string(raw: bytes) -> None:
        nonlocal size
        pad = _PAD[size % 4]
        parts.append(pad + _U32(len(raw)) + raw)
        size += len(pad) + 4 + len(raw)

    for name, level, message, values in statuses:
        parts.append(bytes((level,)))
        size += 1
        string(name.encode("utf-8") + b"\x00")
        string(message.encode("utf-8") + b"\x00")
        string(hardware)
        pad = _PAD[size % 4]
        parts.append(pad + _U32(len(values)))
        size += len(pad) + 4
        for key, value in values:
            string(key.encode("utf-8") + b"\x00")
            string(value.encode("utf-8") + b"\x00")
    return b"".join(parts)
