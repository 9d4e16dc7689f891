"""The output encoders: every CDR template decodes (rclpy) to the message it stands for."""

import math

import numpy as np
import pytest
from geometry_msgs.msg import Point, PoseStamped, Vector3Stamped, WrenchStamped
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import PointCloud2
from visualization_msgs.msg import Marker, MarkerArray

from msg_adapters import cdr, outputs
from msg_adapters.patch import ContactFrame, contact_axes

#: frame ids of every length modulo 8: the header's string moves what follows it
FRAMES = ["", "w", "ws", "left_contact", "wheelset", "wheel_1", "rig1/wheelset_frame",
          "r\u00e4d"]
STAMPS = [0, 1, 1_700_000_000_123_456_789, -5, 2**31 * 1_000_000_000 - 1]


def stamp_of(msg):
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


@pytest.mark.parametrize("frame_id", FRAMES)
@pytest.mark.parametrize("stamp", STAMPS)
def test_stamped_doubles_decode_to_the_messages(frame_id, stamp):
    values = (1.5, -2.0, 3e5, 0.0, -0.0, math.pi)
    w = deserialize_message(cdr.stamped_doubles(stamp, frame_id, values), WrenchStamped)
    assert stamp_of(w) == stamp and w.header.frame_id == frame_id
    assert (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z, w.wrench.torque.x,
            w.wrench.torque.y, w.wrench.torque.z) == values
    v = deserialize_message(cdr.stamped_doubles(stamp, frame_id, (1e-3, 2e-3, -0.5)),
                            Vector3Stamped)
    assert (v.vector.x, v.vector.y, v.vector.z) == (1e-3, 2e-3, -0.5)
    pose = deserialize_message(cdr.stamped_doubles(stamp, frame_id, tuple(range(7))),
                               PoseStamped)
    assert (pose.pose.position.x, pose.pose.orientation.w) == (0.0, 6.0)
    # what rclpy writes, byte for byte but for the padding (uninitialised there)
    ref = WrenchStamped()
    ref.header.frame_id = frame_id
    assert len(cdr.stamped_doubles(0, frame_id, (0.0,) * 6)) == len(serialize_message(ref))


def test_a_template_returns_copies():
    first = cdr.stamped_doubles(1, "left_contact", (1.0, 2.0, 3.0))
    second = cdr.stamped_doubles(2, "left_contact", (4.0, 5.0, 6.0))
    assert deserialize_message(first, Vector3Stamped).vector.x == 1.0
    assert deserialize_message(second, Vector3Stamped).vector.x == 4.0


def reference_marker(stamp, wheelset_frame, index, contact, frame, fx, fy, scale):
    """Return the marker as rclpy builds it (what the encoder must stand for)."""
    m = Marker()
    m.header.stamp.sec, m.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
    m.header.frame_id = wheelset_frame
    m.ns, m.id, m.text = "creep_force", index, contact
    if frame is None:
        m.action = Marker.DELETE
        return m
    m.type, m.action = Marker.ARROW, Marker.ADD
    tip = frame.to_wheelset((fx * scale, fy * scale, 0.0))
    o = frame.origin
    m.points = [Point(x=o[0], y=o[1], z=o[2]),
                Point(x=o[0] + tip[0], y=o[1] + tip[1], z=o[2] + tip[2])]
    m.pose.orientation.w = 1.0
    m.scale.x, m.scale.y, m.scale.z = outputs.ARROW_SCALE
    m.color.r, m.color.g, m.color.b, m.color.a = outputs.ARROW_COLOR
    return m


@pytest.mark.parametrize("wheelset_frame", FRAMES)
@pytest.mark.parametrize("contact", ["left", "wheel", "left_flange"])
@pytest.mark.parametrize("lifted", [False, True])
def test_force_marker_decodes_to_the_arrow(wheelset_frame, contact, lifted):
    frame = None if lifted else ContactFrame((0.01, 0.75, -0.46),
                                             contact_axes((0.0, -0.1, 1.0)))
    args = (1_700_000_000_000_000_007, wheelset_frame, 3, contact, frame, -1500.0, 250.0,
            1e-5)
    got = deserialize_message(outputs.force_marker_cdr(*args), MarkerArray)
    # as on the wire (the colour is float32 there)
    want = deserialize_message(serialize_message(MarkerArray(markers=[reference_marker(*args)])),
                               MarkerArray)
    assert got == want


def test_traction_cloud_decodes_to_the_cells():
    frame = ContactFrame((0.0, 0.75, -0.46), contact_axes((0.0, -0.2, 1.0)))
    rng = np.random.default_rng(1)
    tau_x, tau_y = rng.normal(size=(2, 3, 4)) * 1e6
    slip = rng.random((3, 4)) > 0.5
    data = outputs.traction_cloud_cdr(5, "wheelset", frame, tau_x, tau_y, slip,
                                      (-1e-3, -2e-3, 1e-3, 2e-3))
    cloud = deserialize_message(data, PointCloud2)
    assert (cloud.height, cloud.width, cloud.header.frame_id) == (3, 4, "wheelset")
    assert [(f.name, f.offset, f.datatype, f.count) for f in cloud.fields] == [
        ("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1), ("tau_x", 12, 7, 1),
        ("tau_y", 16, 7, 1), ("slip", 20, 2, 1), ("friction_power", 24, 7, 1)]
    pts = np.frombuffer(bytes(cloud.data), dtype=outputs.TRACTION_DTYPE).reshape(3, 4)
    assert np.array_equal(pts["tau_x"], tau_x.astype(np.float32))
    assert np.array_equal(pts["slip"], slip.astype(np.uint8))
    # cell (j, i) at origin + x e_x + y e_y
    ex, ey, _ = (np.array(a) for a in frame.axes)
    want = np.array(frame.origin) + (-1e-3 + 3e-3) * ex + (-2e-3 + 2 * 2e-3) * ey
    got = np.array([pts["x"][2, 3], pts["y"][2, 3], pts["z"][2, 3]], dtype=float)
    assert got == pytest.approx(want, abs=1e-7)
    assert cloud.point_step == 28 and cloud.row_step == 112 and cloud.is_dense
    # no frictional power given: NaN (not computed), not a zero that reads as no slip
    assert np.isnan(pts["friction_power"]).all()
    power = rng.random((3, 4)) * 1e8
    pts = np.frombuffer(bytes(deserialize_message(outputs.traction_cloud_cdr(
        5, "wheelset", frame, tau_x, tau_y, slip, (-1e-3, -2e-3, 1e-3, 2e-3), power),
        PointCloud2).data), dtype=outputs.TRACTION_DTYPE).reshape(3, 4)
    assert np.array_equal(pts["friction_power"], power.astype(np.float32))


#: statuses whose strings end at every byte offset modulo 4 (CDR aligns each length to 4)
STATUSES = [("fastsim: left", 1, "2 of 5 patches rejected this period; last: r\u00e4d",
             [("method", "mae_calibrated"), ("a", ""), ("bb", "1"), ("ccc", "22"),
              ("dddd", "333")]),
            ("", 2, "", []),
            ("fastsim: right", 0, "ok", [(f"k{i}", "v" * i) for i in range(9)])]


@pytest.mark.parametrize("stamp", STAMPS)
@pytest.mark.parametrize("count", [0, 1, 3])
def test_diagnostic_array_cdr_decodes_to_the_diagnostic_array(stamp, count):
    from diagnostic_msgs.msg import DiagnosticArray
    statuses = STATUSES[:count]
    got = deserialize_message(outputs.diagnostic_array_cdr(stamp, statuses), DiagnosticArray)
    want = outputs.diagnostic_array(stamp, statuses)
    assert got == want
    # the same bytes but for CDR's padding, which rclpy leaves as it was
    assert len(outputs.diagnostic_array_cdr(stamp, statuses)) == len(serialize_message(want))
