"""Results -> messages: wrenches, creepages, frames, traction clouds, markers, diagnostics.

The per-patch messages (``WrenchStamped``, ``Vector3Stamped``,
``PoseStamped``) are written straight to CDR bytes (:mod:`msg_adapters.cdr`):
the node publishes them raw and the replay writes them to bags as they are.
The occasional ones (traction cloud, markers, diagnostics) are message
objects; ``rclpy.serialization.serialize_message`` turns them into bytes.
Frames (INTERFACE.md "Outputs"): a contact's wrench and creepage in
``<name>_contact``; frame, markers, traction cloud and the wheelset wrench in
the wheelset frame.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point
from sensor_msgs.msg import PointCloud2, PointField
from visualization_msgs.msg import Marker, MarkerArray

from msg_adapters.cdr import stamped_doubles
from msg_adapters.kinematics import Creepage
from msg_adapters.patch import ContactFrame

#: traction cloud layout: x y z tau_x tau_y as float32, slip as uint8, padded to 24 bytes
TRACTION_DTYPE = np.dtype({"names": ["x", "y", "z", "tau_x", "tau_y", "slip"],
                           "formats": ["<f4", "<f4", "<f4", "<f4", "<f4", "u1"],
                           "offsets": [0, 4, 8, 12, 16, 20], "itemsize": 24})
_TRACTION_OFFSETS = (("x", 0), ("y", 4), ("z", 8), ("tau_x", 12), ("tau_y", 16), ("slip", 20))
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


def creepage_cdr(stamp_ns: int, contact: str, creepage: Creepage) -> bytes:
    """Return a serialized ``geometry_msgs/Vector3Stamped`` ``(xi, eta, phi)``."""
    return stamped_doubles(stamp_ns, contact_frame_id(contact),
                           (creepage.xi, creepage.eta, creepage.phi))


def pose_cdr(stamp_ns: int, wheelset_frame: str, frame: ContactFrame) -> bytes:
    """Return a serialized ``PoseStamped``: the contact frame in the wheelset frame."""
    return stamped_doubles(stamp_ns, wheelset_frame, frame.origin + frame.quaternion())


def traction_cloud(stamp_ns: int, wheelset_frame: str, frame: ContactFrame,
                   tau_x: np.ndarray, tau_y: np.ndarray, slip: np.ndarray,
                   grid: tuple[float, float, float, float]) -> PointCloud2:
    """Return the solved traction as an organised ``PointCloud2`` in the wheelset frame.

    One point per cell of the solve's grid (``grid = (x0, y0, dx, dy)`` in
    the contact plane), placed at ``origin + x e_x + y e_y``; ``tau_x``,
    ``tau_y``: traction of the rail on the wheel along the contact frame's
    axes (Pa); ``slip``: 1 where the cell is on the traction bound.
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
    msg = PointCloud2()
    msg.header.stamp = stamp_msg(stamp_ns)
    msg.header.frame_id = wheelset_frame
    msg.height, msg.width = ny, nx
    msg.fields = [PointField(name=name, offset=offset,
                             datatype=_UINT8 if name == "slip" else _FLOAT32, count=1)
                  for name, offset in _TRACTION_OFFSETS]
    msg.is_bigendian = False
    msg.point_step = TRACTION_DTYPE.itemsize
    msg.row_step = TRACTION_DTYPE.itemsize * nx
    msg.data = pts.tobytes()
    msg.is_dense = True
    return msg


def force_marker(stamp_ns: int, wheelset_frame: str, index: int, contact: str,
                 frame: ContactFrame | None, fx: float, fy: float, scale: float) -> Marker:
    """Return an arrow from the contact origin along the creep force (``scale`` m/N).

    Without a frame (no contact) the arrow of that contact is deleted.
    """
    m = Marker()
    m.header.stamp = stamp_msg(stamp_ns)
    m.header.frame_id = wheelset_frame
    m.ns = "creep_force"
    m.id = index
    m.text = contact
    if frame is None:
        m.action = Marker.DELETE
        return m
    m.type = Marker.ARROW
    m.action = Marker.ADD
    tip = frame.to_wheelset((fx * scale, fy * scale, 0.0))
    o = frame.origin
    m.points = [Point(x=o[0], y=o[1], z=o[2]),
                Point(x=o[0] + tip[0], y=o[1] + tip[1], z=o[2] + tip[2])]
    m.pose.orientation.w = 1.0
    m.scale.x, m.scale.y, m.scale.z = 0.004, 0.008, 0.01  # shaft, head diameter and length
    m.color.r, m.color.g, m.color.b, m.color.a = 0.9, 0.2, 0.1, 1.0
    return m


def marker_array(markers: Iterable[Marker]) -> MarkerArray:
    """Return a ``MarkerArray`` of the markers."""
    return MarkerArray(markers=list(markers))


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
