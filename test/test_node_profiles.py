"""fastsim_node in profiles mode over real DDS: poses in, the command line's wrenches out.

The node is started from its installed script with ``config/profiles_track.yaml``
(the Manchester benchmark's S1002 on UIC60, 10 kN per wheel); a client
publishes twists and poses and reads the four contacts' wrenches.  They must
equal ``fastsim_contact wheelset --json`` for the same pose within 1e-9
(docs/guide_node.md); a lifted wheelset gives zero wrenches; a pose past the flange
is counted as a derailment and the next pose is served; a missing or bad
profile stops the node at start with one line and exit 2.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import subprocess

import numpy as np
import pytest

from fastsim_ros import cli
from fastsim_ros.geometry.placement import rotation
from geometry_msgs.msg import PoseStamped, TwistStamped
from msg_adapters.profile_msgs import quaternion
from ros_harness import NODE_SCRIPT, PACKAGE_ROOT, Client, NodeProcess
from sensor_msgs.msg import PointCloud2

CONFIG = PACKAGE_ROOT / "config" / "profiles_track.yaml"
CONTACTS = ("left", "right", "left_flange", "right_flange")
T0 = 1_700_000_000
SPEED, R0 = 2.0, 0.46

pytestmark = pytest.mark.skipif(not NODE_SCRIPT.exists(),
                                reason="fastsim_node is not installed (run colcon build)")


@pytest.fixture
def node(tmp_path):
    """Start the node in profiles mode (extra ROS arguments) and a client; stop both after."""
    started = []

    def start(*ros_args):
        proc = NodeProcess("--params-file", str(CONFIG), *ros_args, log_dir=tmp_path)
        client = Client(CONTACTS, patches=False)
        pose = client.publisher(PoseStamped, "wheelset/pose")
        patches = client.subscribe(PointCloud2, "contact/left/patch")
        started.append((proc, client))
        client.wait_connected(proc)
        return proc, client, pose, patches

    yield start
    for proc, client in started:
        client.close()
        proc.stop()


def _twist(sec, roll, yaw):
    v = rotation(roll, yaw).T @ np.array([SPEED, 0.0, 0.0])
    msg = TwistStamped()
    msg.header.frame_id = "wheelset"
    msg.header.stamp.sec = sec
    msg.twist.linear.x, msg.twist.linear.y, msg.twist.linear.z = (float(c) for c in v)
    msg.twist.angular.y = SPEED / R0
    return msg


def _pose(sec, dy, dz, roll, yaw):
    msg = PoseStamped()
    msg.header.frame_id = "track"
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, 2_500_000
    msg.pose.position.y, msg.pose.position.z = dy, dz
    q = msg.pose.orientation
    q.x, q.y, q.z, q.w = quaternion(roll, yaw)
    return msg


def _cli(*argv):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli.main(["wheelset", *argv, "--json"]) == 0
    return json.loads(out.getvalue())


def test_a_pose_gives_the_command_lines_wrenches(node):
    expected = _cli("--dy", "5e-3", "--yaw", "12e-3", "--load", "1e4", "--speed", "2",
                    "--shear-modulus", "8.2e10")
    roll, dz = expected["roll"], expected["dz"]
    _, client, pose, patches = node()
    client.send_twist(_twist(T0, roll, 12e-3))
    got = client.send_pose(pose, _pose(T0, 5e-3, dz, roll, 12e-3), CONTACTS)
    names = set()
    for wheel in expected["wheels"]:
        for p in wheel["patches"]:
            names.add(p["name"])
            (w,) = got[p["name"]]
            f = w.wrench
            assert (f.force.x, f.force.y, f.force.z, f.torque.z) == pytest.approx(
                (p["Fx"], p["Fy"], p["N"], p["Mz"]), rel=1e-9), p["name"]
            assert w.header.frame_id == f"{p['name']}_contact"
    # the names without a patch this cycle publish zero wrenches
    for name in set(CONTACTS) - names:
        (w,) = got[name]
        assert (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z) == (0.0, 0.0, 0.0)
    # the patch went out too, on the contact's patch topic, in the wheelset frame
    assert client.wait_for(lambda: any(m.header.stamp.sec == T0 for m in patches))
    cloud = next(m for m in patches if m.header.stamp.sec == T0)
    assert cloud.header.frame_id == "wheelset" and cloud.height * cloud.width >= 4


def test_the_first_start_needs_neither_contacts_nor_profile_paths(tmp_path):
    # profiles mode as a new user starts it: no params file, the
    # shipped profiles by their bare names, the contacts the mode's own four by default
    expected = _cli("--wheel", "S1002.prw", "--rail", "UIC60.prr", "--dy", "5e-3",
                    "--yaw", "12e-3", "--load", "1e4", "--speed", "2")
    roll, dz = expected["roll"], expected["dz"]
    proc = NodeProcess("-p", "patch_source:=profiles", "-p", "wheel_profile:=S1002.prw",
                       "-p", "rail_profile:=UIC60.prr", "-p", "wheel_load:=1e4",
                       log_dir=tmp_path)
    client = Client(CONTACTS, patches=False)
    try:
        pose = client.publisher(PoseStamped, "wheelset/pose")
        client.wait_connected(proc)
        client.send_twist(_twist(T0, roll, 12e-3))
        got = client.send_pose(pose, _pose(T0, 5e-3, dz, roll, 12e-3), CONTACTS)
    finally:
        client.close()
        assert proc.stop() == 0
    sides = set()
    for wheel in expected["wheels"]:
        sides.add(wheel["side"])
        for p in wheel["patches"]:
            (w,) = got[p["name"]]
            f = w.wrench
            assert (f.force.x, f.force.y, f.force.z, f.torque.z) == pytest.approx(
                (p["Fx"], p["Fy"], p["N"], p["Mz"]), rel=1e-9), p["name"]
    assert sides == {"left", "right"} and all(len(got[c]) == 1 for c in CONTACTS)
    assert got["left"][0].wrench.force.z > 0 and got["right"][0].wrench.force.z > 0


def test_a_lifted_wheelset_publishes_zero_wrenches(node):
    # no load: the pose's height as given, 1 mm above the rails
    _, client, pose, _ = node("-p", "wheel_load:=0.0")
    client.send_twist(_twist(T0, 0.0, 0.0))
    got = client.send_pose(pose, _pose(T0, 0.0, 1e-3, 0.0, 0.0), CONTACTS)
    for name in CONTACTS:
        (w,) = got[name]
        assert (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z) == (0.0, 0.0, 0.0)
    assert client.diagnostic_values("left")["no_contact"] == "1"


def test_a_pose_past_the_flange_is_counted_and_the_next_one_served(node):
    _, client, pose, _ = node()
    client.send_twist(_twist(T0, 0.0, 0.0))
    # 45 mm to the right with the roll given: the right flange has climbed its rail
    got = client.send_pose(pose, _pose(T0, -0.045, 0.0, 0.0, 0.0), CONTACTS)
    assert all(ws == [] for ws in got.values())
    for name in CONTACTS:
        assert client.diagnostic_values(name)["rejected/derailment"] == "1"
    client.send_twist(_twist(T0 + 1, 0.0, 0.0))
    got = client.send_pose(pose, _pose(T0 + 1, 0.0, 0.0, 0.0, 0.0), CONTACTS)
    assert len(got["left"]) == 1 and len(got["right"]) == 1
    assert got["left"][0].wrench.force.z == pytest.approx(9997, rel=2e-3)


@pytest.mark.parametrize("profile, match", [
    ("/nonexistent/wheel.prw", "wheel.prw: cannot read"),
    ("LOOPED", "loop"),
], ids=["missing", "looped"])
def test_a_bad_profile_stops_the_node_at_start(tmp_path, profile, match):
    if profile == "LOOPED":
        t = np.linspace(0.0, 2 * math.pi, 40)
        path = tmp_path / "looped.txt"
        path.write_text("\n".join(f"{10 * math.cos(3 * a):.6f} {10 * math.sin(2 * a):.6f}"
                                  for a in t))
        profile = str(path)
    done = subprocess.run([str(NODE_SCRIPT), "--ros-args", "--params-file", str(CONFIG),
                           "-p", f"wheel_profile:={profile}"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and match in lines[0], done.stderr


def test_a_recorded_rig_replays_to_the_node_as_offline(node, tmp_path):
    # bags/mbench_a22 (poses, loads, twists: no patches) played to the node in profiles
    # mode equals fastsim_replay's output wrench for wrench: one pipeline, stamps from
    # the messages.  The twists and loads go first (two topics carry no order between
    # them), then each pose, waiting for the node to have served it.
    from rclpy.serialization import deserialize_message
    from rosbags.rosbag2 import Reader

    from fastsim_ros import replay
    from geometry_msgs.msg import WrenchStamped

    bags = PACKAGE_ROOT / "bags"
    params = bags / "mbench_a22.params.yaml"
    out = tmp_path / "offline"
    assert replay.main([str(bags / "mbench_a22"), "-o", str(out), "--params", str(params),
                        "--no-progress"]) == 0
    want = {}
    with Reader(out / "mbench_a22") as reader:
        for conn, _, raw in reader.messages():
            parts = conn.topic.split("/")
            if len(parts) == 4 and parts[1] == "contact" and parts[3] == "wrench":
                w = deserialize_message(raw, WrenchStamped)
                want[(parts[2], w.header.stamp.sec, w.header.stamp.nanosec)] = w.wrench
    with Reader(bags / "mbench_a22") as reader:
        messages = [(conn.topic, bytes(raw)) for conn, _, raw in reader.messages()]
    proc = NodeProcess("--params-file", str(params), "-p", "patch_reliability:=reliable",
                       "-p", "qos_depth:=1000", log_dir=tmp_path)
    client = Client(CONTACTS, name="player", patches=False)
    try:
        pose = client.publisher(PoseStamped, "wheelset/pose")
        load = client.publisher(WrenchStamped, "wheelset/load")
        client.wait_connected(proc)
        twists = [raw for topic, raw in messages if topic == "/wheelset/twist"]
        loads = [raw for topic, raw in messages if topic == "/wheelset/load"]
        for raw in twists:
            client.twist.publish(raw)
        for raw in loads:
            load.publish(raw)
        client.wait_twists_handled(len(twists))
        assert client.wait_for(lambda: int(client.node_values().get("poses/load", "0"))
                               >= len(loads), 20.0)
        for topic, raw in messages:
            if topic == "/wheelset/pose":
                client.send_pose(pose, deserialize_message(raw, PoseStamped), CONTACTS)
        got = {(c, w.header.stamp.sec, w.header.stamp.nanosec): w.wrench
               for c, ws in client.wrenches.items() for w in ws}
    finally:
        client.close()
        assert proc.stop() == 0
    assert len(want) == 4 * 21 and got.keys() == want.keys()
    for key, w in want.items():
        g = got[key]
        assert (g.force.x, g.force.y, g.force.z, g.torque.z) == pytest.approx(
            (w.force.x, w.force.y, w.force.z, w.torque.z), rel=1e-12, abs=1e-9), key


def test_the_node_with_the_contact_table_gives_the_pipelines_wrenches(node, tmp_path):
    # a small table (shift -2..2 mm by 1 mm, yaw 0), built by the node at start into a cache
    # of this test's own; the same pipeline in this process reads it from there
    from fastsim_ros.ros.params import load_params_file
    from fastsim_ros.pipeline import PipelineConfig
    from fastsim_ros.pipeline.profiles import ProfilePipeline
    from msg_adapters.cdr import StampedTwist
    from msg_adapters.profile_msgs import StampedPose

    table = {"profile_table": True, "table_dy_min": -2e-3, "table_dy_max": 2e-3,
             "table_dy_step": 1e-3, "table_yaw_max": 0.0, "table_refine": 0,
             "table_cache": str(tmp_path / "tables")}
    args = [a for k, v in table.items()
            for a in ("-p", f"{k}:={str(v).lower() if isinstance(v, bool) else v}")]
    _, client, pose, _ = node(*args)
    client.send_twist(_twist(T0, 0.0, 0.0))
    got = client.send_pose(pose, _pose(T0, 0.6e-3, 0.0, 0.0, 0.0), CONTACTS)
    assert list((tmp_path / "tables").glob("contact_table_*.npz"))
    here = ProfilePipeline(PipelineConfig.from_values({**load_params_file(CONFIG), **table}))
    v = rotation(0.0, 0.0).T @ np.array([SPEED, 0.0, 0.0])
    here.on_wheel_twist(StampedTwist(T0 * 1_000_000_000, "wheelset", tuple(float(c) for c in v),
                                     (0.0, SPEED / R0, 0.0)))
    cycle = here.on_pose(StampedPose(T0 * 1_000_000_000 + 2_500_000, "track",
                                     (0.0, 0.6e-3, 0.0), quaternion(0.0, 0.0)))
    for outcome in cycle.outcomes:
        (w,) = got[outcome.contact]
        if outcome.forces is None:
            assert outcome.status == "no_contact"
            assert (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z) == (0.0, 0.0, 0.0)
            continue
        f = outcome.forces
        assert (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z, w.wrench.torque.z) == \
            pytest.approx((f.fx, f.fy, f.n, f.mz), rel=1e-9), outcome.contact
    # outside the table: counted, nothing published; the next pose inside served
    client.send_twist(_twist(T0 + 1, 0.0, 0.0))
    got = client.send_pose(pose, _pose(T0 + 1, 3e-3, 0.0, 0.0, 0.0), CONTACTS)
    assert all(ws == [] for ws in got.values())
    assert client.diagnostic_values("left")["rejected/out_of_table"] == "1"
    client.send_twist(_twist(T0 + 2, 0.0, 0.0))
    got = client.send_pose(pose, _pose(T0 + 2, -1.5e-3, 0.0, 0.0, 0.0), CONTACTS)
    assert len(got["left"]) == 1 and len(got["right"]) == 1
