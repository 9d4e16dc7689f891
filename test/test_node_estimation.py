"""fastsim_node with friction_estimation on, over DDS: the in-process pipeline's estimates.

A client sends each rig cycle's twist and measured wheelset wrench, waits
until the node counted both, then the patch; the node's ``friction/estimate``
and wrenches must equal those of an in-process :class:`~fastsim_ros.pipeline.
Pipeline` fed the same messages in the same order (the replay's code), and
the estimate must move towards the friction the measurement came from.
"""

import numpy as np
import pytest
from geometry_msgs.msg import Vector3Stamped, WrenchStamped

from fastsim_ros.contact import area as areas
from fastsim_ros.pipeline import Pipeline, PipelineConfig
from ros_harness import NODE_SCRIPT, Client, NodeProcess, stamp_ns
from ros_messages import cdr, cloud_msg, rolling_twist

T0 = 1_700_000_000 * 1_000_000_000
PERIOD = 5_000_000  # ns

pytestmark = pytest.mark.skipif(not NODE_SCRIPT.exists(),
                                reason="fastsim_node is not installed (run colcon build)")


def wrench_msg(force_x, stamp):
    w = WrenchStamped()
    w.header.stamp.sec, w.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
    w.header.frame_id = "wheelset"
    w.wrench.force.x = float(force_x)
    return w


def test_node_estimates_as_the_pipeline_does(tmp_path):
    values = {"contacts": ["left"], "friction_estimation": "on", "friction_coefficient": 0.2,
              "friction_measurement_noise": 250.0, "friction_estimate_sigma": 0.15}
    # 'on' quoted: a bare on is YAML's true, and the parameter is a string
    proc = NodeProcess("-p", 'contacts:=["left"]', "-p", "friction_estimation:=on",
                       "-p", "friction_coefficient:=0.2",
                       "-p", "friction_measurement_noise:=250.0",
                       "-p", "friction_estimate_sigma:=0.15", log_dir=tmp_path)
    client = Client(("left",))
    try:
        measured = client.publisher(WrenchStamped, "wheelset/measured_wrench")
        estimates = client.subscribe(Vector3Stamped, "friction/estimate")
        client.wait_connected(proc)
        reference = Pipeline(PipelineConfig.from_values(values))
        truth = Pipeline(PipelineConfig.from_values({"contacts": ["left"],
                                                     "friction_coefficient": 0.35}))
        hertz = areas.ellipse(6e-3, 4e-3, nx=20, ny=20, load=5e4)
        rng = np.random.default_rng(11)
        expected = []
        for k, xi in enumerate(rng.uniform(2.5e-3, 8e-3, 12)):
            stamp = T0 + k * PERIOD
            twist = rolling_twist(float(xi), stamp_ns=stamp)
            patch = cloud_msg(hertz, stamp_ns=stamp, dtype="<f8")
            truth.on_wheel_twist(cdr(twist))
            fx = truth.on_patch("left", cdr(patch)).wheelset.force[0] + rng.normal(0.0, 250.0)
            wrench = wrench_msg(fx, stamp)
            client.send_twist(twist)
            measured.publish(wrench)
            assert client.wait_for(lambda k=k: int(client.diagnostic_values("left").get(
                "friction_estimation/measured", "0")) >= k + 1)
            assert client.send_patch("left", patch) == "wrench"
            reference.on_wheel_twist(cdr(twist))
            reference.on_measured_wrench(cdr(wrench))
            out = reference.on_patch("left", cdr(patch))
            expected.append((stamp, out.friction.mu, out.friction.sigma,
                             out.friction.utilisation, out.forces.fx))
        assert client.wait_for(lambda: len(estimates) >= len(expected))
        got = {stamp_ns(m): (m.vector.x, m.vector.y, m.vector.z) for m in estimates}
        fxs = {stamp_ns(w): w.wrench.force.x for w in client.wrenches["left"]}
        for stamp, mu, sigma, utilisation, fx in expected:
            assert got[stamp] == pytest.approx((mu, sigma, utilisation), rel=1e-12)
            assert fxs[stamp] == pytest.approx(fx, rel=1e-12)
        assert estimates[-1].header.frame_id == "wheelset"
        # from 0.2 towards the measurement's 0.35
        assert abs(expected[-1][1] - 0.35) < 0.02 * 0.35
    finally:
        client.close()
        proc.stop()
