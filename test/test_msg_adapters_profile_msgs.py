"""Poses, loads and patch clouds of the profiles mode against rclpy's own serialization."""

from __future__ import annotations

import math

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from fastsim_ros.geometry.placement import rotation
from geometry_msgs.msg import PoseStamped, WrenchStamped
from msg_adapters.cdr import read_cloud
from msg_adapters.errors import MalformedMessageError
from msg_adapters.patch import patch_from_cloud
from msg_adapters.profile_msgs import (StampedPose, cloud_cdr, patch_cloud, quaternion, read_load,
                                       read_pose)
from sensor_msgs.msg import PointCloud2


def _pose_msg(stamp_ns, frame, position, q):
    msg = PoseStamped()
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    msg.header.frame_id = frame
    msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = position
    (msg.pose.orientation.x, msg.pose.orientation.y, msg.pose.orientation.z,
     msg.pose.orientation.w) = q
    return msg


@pytest.mark.parametrize("frame", ["track", "", "a_much_longer_frame_name_x"])
def test_read_pose_equals_rclpy(frame):
    q = quaternion(0.0123, -0.0456)
    msg = _pose_msg(1_234_567_890_123, frame, (0.1, -0.004, 0.0002), q)
    pose = read_pose(serialize_message(msg))
    assert pose.stamp_ns == 1_234_567_890_123
    assert pose.frame_id == frame
    assert pose.position == (0.1, -0.004, 0.0002)
    assert pose.orientation == q


@pytest.mark.parametrize("roll, yaw", [(0.0, 0.0), (0.0123, -0.0456), (-0.2, 0.15)])
def test_quaternion_is_rx_rz_and_back(roll, yaw):
    x, y, z, w = quaternion(roll, yaw)
    # the rotation matrix of the quaternion equals Rx(roll) Rz(yaw)
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    assert np.allclose(r, rotation(roll, yaw), atol=1e-15)
    pose = read_pose(serialize_message(_pose_msg(0, "track", (0.0, 0.0, 0.0), (x, y, z, w))))
    back_roll, back_yaw = pose.roll_yaw()
    assert back_roll == pytest.approx(roll, abs=1e-15)
    assert back_yaw == pytest.approx(yaw, abs=1e-15)


def test_an_unnormalised_quaternion_gives_the_same_angles():
    x, y, z, w = quaternion(0.01, 0.02)
    pose = read_pose(serialize_message(_pose_msg(0, "track", (0, 0, 0), (3 * x, 3 * y, 3 * z,
                                                                         3 * w))))
    assert pose.roll_yaw() == pytest.approx((0.01, 0.02), abs=1e-15)


@pytest.mark.parametrize("scale", [1e-300, 1e300, 1.7e308])
def test_a_huge_or_tiny_quaternion_gives_its_angles(scale):
    """Normalised without overflow: 1e300 (0, 0, 1, 1) is a 90 degree yaw, not none."""
    pose = StampedPose(0, "track", (0.0, 0.0, 0.0), (0.0, 0.0, scale, scale))
    assert pose.roll_yaw() == pytest.approx((0.0, math.pi / 2), abs=1e-12)


def test_a_zero_quaternion_and_truncated_bytes_are_malformed():
    pose = read_pose(serialize_message(_pose_msg(0, "track", (0, 0, 0), (0, 0, 0, 0))))
    with pytest.raises(MalformedMessageError, match="zero quaternion"):
        pose.roll_yaw()
    raw = serialize_message(_pose_msg(0, "track", (0, 0, 0), (0, 0, 0, 1)))
    with pytest.raises(MalformedMessageError, match="truncated"):
        read_pose(raw[:30])


def test_read_load_equals_rclpy():
    msg = WrenchStamped()
    msg.header.frame_id = "wheelset"
    msg.header.stamp.sec = 7
    msg.wrench.force.z = 20000.0
    msg.wrench.torque.x = 300.0
    load = read_load(serialize_message(msg))
    assert load.stamp_ns == 7_000_000_000 and load.frame_id == "wheelset"
    assert load.linear == (0.0, 0.0, 20000.0) and load.angular == (300.0, 0.0, 0.0)


def test_patch_cloud_bytes_decode_in_rclpy_and_back_to_the_same_patch():
    rng = np.random.default_rng(5)
    ny, nx = 7, 9
    xs = 0.2e-3 * np.arange(nx)
    ys = 0.2e-3 * np.arange(ny)
    points = np.zeros((ny, nx, 3))
    points[..., 0] = xs[None, :] + 0.001
    points[..., 1] = ys[:, None] + 0.75
    points[..., 2] = -0.0001
    pressure = np.where(rng.random((ny, nx)) > 0.3, rng.random((ny, nx)) * 1e9, 0.0)
    cloud = patch_cloud(123_000_000_456, "wheelset", points, np.array([0.0, 0.0, 1.0]),
                        pressure)
    raw = cloud_cdr(cloud)
    msg = deserialize_message(raw, PointCloud2)
    assert (msg.height, msg.width, msg.point_step, msg.row_step) == (ny, nx, 56, 56 * nx)
    names = ["x", "y", "z", "normal_x", "normal_y", "normal_z", "pressure"]
    assert [f.name for f in msg.fields] == names
    assert msg.header.frame_id == "wheelset"
    assert msg.header.stamp.sec == 123 and msg.header.stamp.nanosec == 456
    data = np.frombuffer(bytes(msg.data), dtype="<f8").reshape(ny, nx, 7)
    assert np.array_equal(data[..., 6], pressure)
    assert np.array_equal(data[..., 0:3], points)
    # the wire form and the in-memory cloud convert to the same patch, bit for bit
    a = patch_from_cloud(read_cloud(raw), max_cells=10_000)
    b = patch_from_cloud(cloud, max_cells=10_000)
    assert a is not None and b is not None
    assert a.frame == b.frame and np.array_equal(a.pressure, b.pressure)
    assert (a.x0, a.y0, a.dx, a.dy, a.load) == (b.x0, b.y0, b.dx, b.dy, b.load)


def test_an_empty_patch_cloud_is_no_contact():
    cloud = patch_cloud(0, "wheelset", np.zeros((0, 0, 3)), np.zeros(3), np.zeros((0, 0)))
    assert patch_from_cloud(read_cloud(cloud_cdr(cloud)), max_cells=16) is None
    assert math.isfinite(len(cloud_cdr(cloud)))
