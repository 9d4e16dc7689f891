"""The node's wear outputs over DDS: contact/<name>/energy and damage, the tables as parameters.

The installed ``fastsim_node`` with ``wear_outputs`` and ``frictional_power``
on; each message is compared with the shared pipeline's own, run in this
process on the same message (the replay's numbers: node and replay are one
pipeline).
"""

import math

import numpy as np
import pytest
from geometry_msgs.msg import Vector3Stamped
from rclpy.serialization import deserialize_message

from fastsim_ros.contact.wear import BURSTOW_RCF
from fastsim_ros.pipeline import Pipeline, PipelineConfig
from ros_harness import NODE_SCRIPT, Client, NodeProcess, stamp_ns
from ros_messages import cdr, cloud_msg, rolling_twist
from test_node import MS, T0, egg

pytestmark = pytest.mark.skipif(not NODE_SCRIPT.exists(),
                                reason="fastsim_node is not installed (run colcon build)")


@pytest.fixture
def node(tmp_path):
    proc = NodeProcess("-p", "contacts:=[left]", "-p", "wear_outputs:=true",
                       "-p", "frictional_power:=true", log_dir=tmp_path)
    client = Client(("left",))
    energy = client.subscribe(Vector3Stamped, "contact/left/energy")
    damage = client.subscribe(Vector3Stamped, "contact/left/damage")
    try:
        client.wait_connected(proc)  # the node's wear publishers matched too
        yield proc, client, energy, damage
    finally:
        client.close()
        proc.stop()


def values(msg):
    return (msg.vector.x, msg.vector.y, msg.vector.z)


def test_the_node_publishes_the_pipelines_wear_messages(node):
    proc, client, energy, damage = node
    here = Pipeline(PipelineConfig.from_values({"contacts": ["left"], "wear_outputs": True,
                                                "frictional_power": True}))
    twist = rolling_twist(2e-3, stamp_ns=T0)
    client.send_twist(twist)
    here.on_wheel_twist(cdr(twist))
    for k in range(3):
        msg = cloud_msg(egg(), stamp_ns=T0 + (k + 1) * MS, dtype="<f8")
        assert client.send_patch("left", msg) == "wrench"
        want = dict(here.messages(here.on_patch("left", cdr(msg))))
        assert client.wait_for(lambda: len(energy) > k and len(damage) > k)
        for got, topic in ((energy[k], "contact/left/energy"),
                           (damage[k], "contact/left/damage")):
            assert stamp_ns(got) == stamp_ns(msg) and got.header.frame_id == "left_contact"
            mine = deserialize_message(want[topic], Vector3Stamped)
            assert np.array_equal(values(got), values(mine), equal_nan=True)  # to the bit
    tg, _, power = values(energy[-1])
    assert 0.0 < power < tg * 20.0  # slip dissipates part of T-gamma V (V = 20 m/s)
    rate, rcf, share = values(damage[-1])
    assert rcf == BURSTOW_RCF(tg) and 0.0 < share < 1.0 and rate > 0.0
    assert proc.proc.poll() is None


def test_a_table_set_while_running_with_whole_numbers(node):
    """``ros2 param set /fastsim rcf_function_y "[0, 0, 1, 0]"``: integers, taken as doubles."""
    proc, client, energy, damage = node
    (result,) = client.set_parameters(rcf_function_y=[0, 0, 1, 0])
    assert result.successful, result.reason
    assert list(client.get_parameter("rcf_function_y")) == [0.0, 0.0, 1.0, 0.0]
    (result,) = client.set_parameters(rcf_function_y=[0.0, 1.0])  # 2 values, 4 breakpoints
    assert not result.successful and "as many values" in result.reason
    client.send_twist(rolling_twist(2e-3, stamp_ns=T0))
    assert client.send_patch("left", cloud_msg(egg(), stamp_ns=T0 + MS, dtype="<f8")) == "wrench"
    assert client.wait_for(lambda: energy and damage)
    tg = values(energy[0])[0]
    assert 15.0 < tg < 65.0  # on the table's rising flank
    assert values(damage[0])[1] == pytest.approx((tg - 15.0) / 50.0, rel=1e-12)
    assert not math.isnan(values(damage[0])[2])
    assert proc.proc.poll() is None
