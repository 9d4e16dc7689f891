"""Node replay: a player publishes a bundled bag to the node, a recorder keeps the wrenches.

They must equal the offline replay's (``fastsim_replay``) wrench for wrench:
the node and the replay share one pipeline, and stamps come from the
messages, so the same inputs in the same order give the same numbers.  The
player publishes at real time in log-time order, except that twists go out
``TWIST_LEAD`` early: different topics carry no order between them over DDS,
and a twist that arrived after its patch would change the kinematics that
patch is solved with; an early twist changes nothing, since a patch only
uses twists stamped at or before it.
"""

import gc
import time

import pytest
from geometry_msgs.msg import WrenchStamped
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from rosbags.rosbag2 import Reader
from sensor_msgs.msg import PointCloud2

from fastsim_ros import replay
from fastsim_ros.params import load_params_file
from ros_harness import NODE_SCRIPT, PACKAGE_ROOT, Client, NodeProcess, stamp_ns

BAGS = PACKAGE_ROOT / "bags"
SPEED = 1.0
TWIST_LEAD = 50_000_000  # ns of log time

pytestmark = pytest.mark.skipif(not NODE_SCRIPT.exists(),
                                reason="fastsim_node is not installed (run colcon build)")


def offline_wrenches(bag, out):
    """Return {(contact, stamp): (Fx, Fy, N, Mz)} of fastsim_replay's output bag."""
    assert replay.main([str(BAGS / bag), "-o", str(out), "--params",
                        str(BAGS / f"{bag}.params.yaml"), "--no-progress"]) == 0
    found = {}
    with Reader(out / bag) as reader:
        for conn, _, raw in reader.messages():
            parts = conn.topic.split("/")
            if len(parts) == 4 and parts[1] == "contact" and parts[3] == "wrench":
                w = deserialize_message(raw, WrenchStamped)
                found[(parts[2], stamp_ns(w))] = force(w)
    return found


def force(w):
    return (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z, w.wrench.torque.z)


@pytest.mark.parametrize("bag", ["hertz_ramp", "roller_rig", "flange_shift"])
def test_node_fed_by_a_player_equals_the_offline_replay(bag, tmp_path):
    want = offline_wrenches(bag, tmp_path / "offline")
    contacts = load_params_file(BAGS / f"{bag}.params.yaml")["contacts"]
    proc = NodeProcess("--params-file", str(BAGS / f"{bag}.params.yaml"), log_dir=tmp_path)
    client = Client(tuple(contacts), name="player")
    # a full pass of the cyclic collector over a whole test session's objects
    # stalls this process for tens of ms: the player would then send a burst
    # (the node's best-effort queue keeps 10 per topic) and the recorder fall
    # behind the node's reliable keep-last-10 writers.  None while playing.
    gc.collect()
    gc.disable()
    try:
        client.wait_connected(proc)
        qos = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
        pubs = {}
        with Reader(BAGS / bag) as reader:
            for conn in reader.connections:
                if conn.topic == "/wheelset/twist":
                    pubs[conn.topic] = client.twist
                elif conn.topic == "/rail/twist":
                    pubs[conn.topic] = client.rail
                else:
                    pubs[conn.topic] = client.node.create_publisher(PointCloud2, conn.topic,
                                                                    qos)
            client.spin(0.5)
            schedule = sorted(((t_ns - TWIST_LEAD if conn.topic.endswith("/twist") else t_ns,
                                k, conn, bytes(raw))
                               for k, (conn, t_ns, raw) in enumerate(reader.messages())),
                              key=lambda item: item[:2])
            start, first = time.monotonic(), schedule[0][0]
            for t_ns, _, conn, raw in schedule:
                due = start + (t_ns - first) * 1e-9 / SPEED
                while time.monotonic() < due:
                    client.executor.spin_once(timeout_sec=max(0.0, due - time.monotonic()))
                pubs[conn.topic].publish(raw)

        def recorded():
            return sum(len(v) for v in client.wrenches.values())
        client.wait_for(lambda: recorded() >= len(want), 10.0)
        got = {(c, stamp_ns(w)): force(w) for c, ws in client.wrenches.items() for w in ws}
    finally:
        gc.enable()
        client.close()
        assert proc.stop() == 0
    assert len(want) > 300
    assert got.keys() == want.keys()
    for key, f in want.items():
        assert got[key] == pytest.approx(f, rel=1e-12, abs=1e-9), key
