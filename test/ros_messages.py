"""Message builders shared by the adapter, pipeline, node and replay tests.

A patch is built from a :class:`~fastsim_ros.contact.area.GridArea` laid in
a contact plane: its cells at ``origin + x e_x + y e_y`` (e_x, e_y of the
plane whose normal is given), so that the test knows the exact in-plane grid
the adapter must recover.
"""

from __future__ import annotations

import math

import numpy as np
from geometry_msgs.msg import TwistStamped
from rclpy.serialization import serialize_message
from sensor_msgs.msg import PointCloud2, PointField

from fastsim_ros.contact.area import GridArea
from msg_adapters import patch as pa

WHEEL_RADIUS = 0.46
LEFT = (0.0, 0.75, -WHEEL_RADIUS)


def contact_normal(gamma: float, side: str = "left") -> tuple[float, float, float]:
    """Return the normal into the wheel at contact angle ``gamma`` (rad) on a side."""
    s = -math.sin(gamma) if side == "left" else math.sin(gamma)
    return (0.0, s, math.cos(gamma))


def cloud_msg(area: GridArea, *, origin=LEFT, normal=(0.0, 0.0, 1.0), stamp_ns=0,
              frame_id="wheelset", dtype="<f4", field_order=None, pad=0,
              reverse_rows=False, reverse_columns=False, pressure=None) -> PointCloud2:
    """Return an organised patch cloud of ``area`` (the node's input layout).

    ``field_order``: names in the order to pack (default PATCH_FIELDS);
    ``pad``: extra bytes after each point; ``reverse_*``: points run the
    other way; ``pressure``: override of the cell pressures (Pa).
    """
    frame = pa.frame_from_normal(normal)
    pts = pa.planar_points(origin, frame, area.x0, area.y0, area.dx, area.dy, area.ny,
                           area.nx)
    p = np.array(area.pressure if pressure is None else pressure, dtype=float)
    nrm = np.broadcast_to(np.asarray(frame.axes[2]), pts.shape)
    if reverse_rows:
        pts, nrm, p = pts[::-1], nrm[::-1], p[::-1]
    if reverse_columns:
        pts, nrm, p = pts[:, ::-1], nrm[:, ::-1], p[:, ::-1]
    names = list(field_order or pa.PATCH_FIELDS)
    values = {"x": pts[..., 0], "y": pts[..., 1], "z": pts[..., 2], "normal_x": nrm[..., 0],
              "normal_y": nrm[..., 1], "normal_z": nrm[..., 2], "pressure": p}
    size = np.dtype(dtype).itemsize
    step = len(names) * size + pad
    rec = np.zeros((p.shape[0], p.shape[1], step), dtype=np.uint8)
    for k, name in enumerate(names):
        column = np.ascontiguousarray(values[name], dtype=dtype)
        rec[:, :, k * size:(k + 1) * size] = column.view(np.uint8).reshape(
            p.shape[0], p.shape[1], size)
    m = PointCloud2()
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    m.header.stamp.sec, m.header.stamp.nanosec = sec, nanosec
    m.header.frame_id = frame_id
    m.height, m.width = p.shape
    code = 7 if size == 4 else 8
    m.fields = [PointField(name=name, offset=k * size, datatype=code, count=1)
                for k, name in enumerate(names)]
    m.is_bigendian = dtype.startswith(">")
    m.point_step = step
    m.row_step = step * p.shape[1]
    m.data = rec.tobytes()
    m.is_dense = True
    return m


def twist_msg(linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0), *, stamp_ns=0,
              frame_id="wheelset") -> TwistStamped:
    """Return a TwistStamped."""
    t = TwistStamped()
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    t.header.stamp.sec, t.header.stamp.nanosec = sec, nanosec
    t.header.frame_id = frame_id
    t.twist.linear.x, t.twist.linear.y, t.twist.linear.z = map(float, linear)
    t.twist.angular.x, t.twist.angular.y, t.twist.angular.z = map(float, angular)
    return t


def rolling_twist(xi: float, *, speed: float = 20.0, radius: float = WHEEL_RADIUS,
                  stamp_ns=0) -> TwistStamped:
    """Return the twist of a wheelset on track at ``speed`` (m/s) with creepage ``xi``.

    ``omega R = v0 (1 - xi/2) / (1 + xi/2)`` gives ``xi = (v0 - omega R)/V``
    with ``V = (v0 + omega R)/2``.
    """
    omega = speed * (1.0 - xi / 2.0) / (1.0 + xi / 2.0) / radius
    return twist_msg((speed, 0.0, 0.0), (0.0, omega, 0.0), stamp_ns=stamp_ns)


def cdr(msg) -> bytes:
    """Return the message's CDR bytes (as the node and the bags carry them)."""
    return serialize_message(msg)


def in_plane_area(area: GridArea) -> GridArea:
    """Return ``area`` about its pressure-weighted centroid: the contact frame's origin."""
    p = area.pressure
    xc = float((p.sum(axis=0) @ area.x) / p.sum())
    yc = float((p.sum(axis=1) @ area.y) / p.sum())
    return area.shifted(-xc, -yc)
