"""Node replay: a player publishes a bundled bag to the node, a recorder keeps the wrenches.

They must equal the offline replay's (``fastsim_replay``) wrench for wrench:
the node and the replay share one pipeline, and stamps come from the
messages, so the same inputs in the same order give the same numbers.  Two
topics carry no order between them over DDS, so the player sends every
twist of the bag first and waits until the node's diagnostics count them
all, then the patches at real time: each patch is solved with the newest
twist stamped at or before it, which is the one the offline replay used as
long as no twist is logged after a patch it is stamped before (checked).
Nothing is lost on the way: every topic matched on both sides before the
first message, and the node runs with reliable subscriptions deep enough
to hold a whole bag (a test of equal numbers, not of speed).
"""

import time

import pytest
from geometry_msgs.msg import WrenchStamped
from rclpy.serialization import deserialize_message
from rosbags.rosbag2 import Reader
from sensor_msgs.msg import PointCloud2

from fastsim_ros import replay
from fastsim_ros.ros.params import load_params_file
from fastsim_ros.pipeline import TWIST_HISTORY
from msg_adapters.cdr import read_cloud, read_twist
from ros_harness import NODE_SCRIPT, PACKAGE_ROOT, Client, NodeProcess, stamp_ns

BAGS = PACKAGE_ROOT / "bags"
SPEED = 1.0
#: the node's queues: deeper than a bag's messages on any topic
DEPTH = 1000

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


@pytest.mark.parametrize("bag", ["hertz_ramp", "roller_rig", "flange_shift", "transient_step"])
def test_node_fed_by_a_player_equals_the_offline_replay(bag, tmp_path):
    want = offline_wrenches(bag, tmp_path / "offline")
    with Reader(BAGS / bag) as reader:
        # topics mode: the twists and the patches (flange_shift also carries the poses and
        # loads its patches were computed from, for profiles mode: not this node's inputs)
        messages = [(conn.topic, t_ns, bytes(raw)) for conn, t_ns, raw in reader.messages()
                    if conn.topic.endswith(("/twist", "/patch"))]
    twists = [m for m in messages if m[0].endswith("/twist")]
    patches = [m for m in messages if m[0].endswith("/patch")]
    assert len(twists) + len(patches) == len(messages)
    # twists first gives each patch the twist the offline replay gave it: no twist is
    # logged after a patch it is stamped at or before
    newest_patch = -1
    for topic, _, raw in messages:
        if topic.endswith("/patch"):
            newest_patch = max(newest_patch, read_cloud(raw).stamp_ns)
        else:
            assert read_twist(raw).stamp_ns > newest_patch, topic
    for topic in {m[0] for m in twists}:
        assert sum(m[0] == topic for m in twists) <= TWIST_HISTORY  # the node keeps them all
    contacts = load_params_file(BAGS / f"{bag}.params.yaml")["contacts"]
    proc = NodeProcess("--params-file", str(BAGS / f"{bag}.params.yaml"),
                       "-p", "patch_reliability:=reliable", "-p", f"qos_depth:={DEPTH}",
                       log_dir=tmp_path)
    client = Client(tuple(contacts), name="player")
    try:
        pubs = {f"/{topic}": pub for topic, pub in (("wheelset/twist", client.twist),
                                                    ("rail/twist", client.rail))}
        pubs.update({f"/contact/{c}/patch": p for c, p in client.patch.items()})
        for topic in {m[0] for m in messages} - pubs.keys():
            pubs[topic] = client.publisher(PointCloud2, topic)
        client.wait_connected(proc)
        for topic, _, raw in twists:
            pubs[topic].publish(raw)
        client.wait_twists_handled(len(twists))
        start, first = time.monotonic(), patches[0][1]
        for topic, t_ns, raw in patches:
            due = start + (t_ns - first) * 1e-9 / SPEED
            while time.monotonic() < due:
                client.executor.spin_once(timeout_sec=max(0.0, due - time.monotonic()))
            pubs[topic].publish(raw)

        def recorded():
            return sum(len(v) for v in client.wrenches.values())
        client.wait_for(lambda: recorded() >= len(want), 20.0)
        got = {(c, stamp_ns(w)): force(w) for c, ws in client.wrenches.items() for w in ws}
    finally:
        client.close()
        assert proc.stop() == 0
    assert len(want) > 300
    assert got.keys() == want.keys()
    for key, f in want.items():
        assert got[key] == pytest.approx(f, rel=1e-12, abs=1e-9), key
