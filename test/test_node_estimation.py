"""fastsim_node with friction_estimation on, over DDS: the in-process pipeline's estimates.

A client sends each rig cycle's twist and measured wheelset wrench, waits
until the node counted both, then the patch; the node's ``friction/estimate``
and wrenches must equal those of an in-process :class:`~fastsim_ros.pipeline.
Pipeline` fed the same messages in the same order (the replay's code), and
the estimate must move towards the friction the measurement came from.
The bags ``adhesion_rig`` (the exact theory's forces) and
``contaminated_rig`` (the modified FastSim's, mu_s and the slope
reduction's k0 estimated together) played to the node: its estimates and
wrenches equal the offline replay's, and on contaminated_rig meet the
truth's targets.
"""

import numpy as np
import pytest
import yaml
from geometry_msgs.msg import Vector3Stamped, WrenchStamped
from rclpy.serialization import deserialize_message
from rosbags.rosbag2 import Reader

from fastsim_ros import replay
from fastsim_ros.contact import area as areas
from fastsim_ros.pipeline import TWIST_HISTORY, Pipeline, PipelineConfig
from ros_harness import NODE_SCRIPT, PACKAGE_ROOT, Client, NodeProcess, stamp_ns
from ros_messages import cdr, cloud_msg, rolling_twist

T0 = 1_700_000_000 * 1_000_000_000
PERIOD = 5_000_000  # ns
BAGS = PACKAGE_ROOT / "bags"

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


def offline_estimates(out, name="adhesion_rig", topic="/friction/estimate"):
    """Return {stamp: topic's (x, y, z)} and {(contact, stamp): Fx} of the replay of ``name``."""
    assert replay.main([str(BAGS / name), "-o", str(out), "--params",
                        str(BAGS / f"{name}.params.yaml"), "--no-progress"]) == 0
    estimates, fx = {}, {}
    with Reader(out / name) as reader:
        for conn, _, raw in reader.messages():
            if conn.topic == topic:
                m = deserialize_message(raw, Vector3Stamped)
                estimates[stamp_ns(m)] = (m.vector.x, m.vector.y, m.vector.z)
            elif conn.topic.startswith("/contact/") and conn.topic.endswith("/wrench"):
                w = deserialize_message(raw, WrenchStamped)
                fx[(conn.topic.split("/")[2], stamp_ns(w))] = w.wrench.force.x
    return estimates, fx


def feed_node(tmp_path, name, topics, finish=None):
    """Play the bag ``name`` to a node over DDS; return its estimates, its Fx and its output.

    Twists and measured wrenches first (counted), then the patches a cycle
    at a time, each cycle waited for on every topic of ``topics``.  Return
    ``({topic: {stamp: (x, y, z)}}, {(contact, stamp): Fx}, the node's
    output)``; ``finish(client, publishers)`` runs before the node stops.
    """
    with Reader(BAGS / name) as reader:
        messages = [(conn.topic, bytes(raw)) for conn, _, raw in reader.messages()]
    first = [m for m in messages if m[0].endswith(("/twist", "/measured_wrench"))]
    patches = [m for m in messages if m[0].endswith("/patch")]
    assert len(first) + len(patches) == len(messages) and len(first) <= 2 * TWIST_HISTORY
    wrenches = sum(m[0].endswith("/measured_wrench") for m in first)
    proc = NodeProcess("--params-file", str(BAGS / f"{name}.params.yaml"),
                       "-p", "patch_reliability:=reliable", "-p", "qos_depth:=1000",
                       log_dir=tmp_path)
    client = Client(("left", "right"), name="player")
    try:
        pubs = {"/wheelset/twist": client.twist,
                "/wheelset/measured_wrench": client.publisher(WrenchStamped,
                                                              "wheelset/measured_wrench")}
        pubs.update({f"/contact/{c}/patch": p for c, p in client.patch.items()})
        received = {topic: client.subscribe(Vector3Stamped, topic) for topic in topics}
        client.wait_connected(proc)
        for topic, raw in first:
            pubs[topic].publish(raw)
        client.wait_twists_handled(len(first) - wrenches)
        assert client.wait_for(lambda: int(client.diagnostic_values("left").get(
            "friction_estimation/measured", "0")) >= wrenches, 20.0)
        for k in range(0, len(patches), 2):  # a cycle at a time: both patches, then its estimate
            for topic, raw in patches[k:k + 2]:
                pubs[topic].publish(raw)
            assert client.wait_for(
                lambda k=k: all(len(got) >= k // 2 + 1 for got in received.values()), 10.0)
        got = {topic: {stamp_ns(m): (m.vector.x, m.vector.y, m.vector.z) for m in ms}
               for topic, ms in received.items()}
        got_fx = {(c, stamp_ns(w)): w.wrench.force.x for c, ws in client.wrenches.items()
                  for w in ws}
        if finish is not None:
            finish(client, pubs, got)
    finally:
        client.close()
        assert proc.stop() == 0
    return got, got_fx, proc.output()


def test_node_fed_adhesion_rig_estimates_as_the_replay_does(tmp_path):
    """The bag over DDS: its estimates and forces as the replay's; a stray wrench dropped."""
    want, want_fx = offline_estimates(tmp_path / "offline")

    def wrong_frame(client, pubs, got):
        # a measured wrench in another frame: dropped, counted by its reason, logged
        bad = WrenchStamped()
        bad.header.frame_id = "base_link"
        bad.header.stamp.sec = 2_000_000_000
        pubs["/wheelset/measured_wrench"].publish(bad)
        assert client.wait_for(lambda: client.diagnostic_values("left").get(
            "measured_wrench/wrong_frame") == "1", 20.0)
    got, got_fx, output = feed_node(tmp_path, "adhesion_rig", ["friction/estimate"],
                                    wrong_frame)
    got = got["friction/estimate"]
    assert "wheelset/measured_wrench dropped: wrong_frame" in output
    assert len(want) == 400 and got.keys() == want.keys()
    for stamp, value in want.items():
        assert got[stamp] == pytest.approx(value, rel=1e-12), stamp
    assert got_fx.keys() == want_fx.keys()
    for key, value in want_fx.items():
        assert got_fx[key] == pytest.approx(value, rel=1e-12), key


def test_node_fed_contaminated_rig_estimates_mu_and_k0_as_the_replay_does(tmp_path):
    """contaminated_rig over DDS: friction/estimate and friction/slope_estimate as the replay's.

    The node's estimates of mu_s and k0 equal the replay's to 1e-12 at every
    cycle, and meet the bag's targets: from 0.2 s after each step to the
    next, mu_s within 2% and k0 within 5% of the truth, 2 sigma covering it
    at least 95% of the time.
    """
    want_mu, want_fx = offline_estimates(tmp_path / "offline", "contaminated_rig")
    want_k0, _ = offline_estimates(tmp_path / "offline_k0", "contaminated_rig",
                                   "/friction/slope_estimate")

    def k0_diagnosed(client, pubs, got):
        last = got["friction/slope_estimate"]
        last_k0 = last[max(last)][0]
        assert client.wait_for(lambda: client.diagnostic_values("left").get(
            "friction_estimation/k0") == f"{last_k0:.6g}", 20.0)
    got, got_fx, _ = feed_node(tmp_path, "contaminated_rig",
                               ["friction/estimate", "friction/slope_estimate"], k0_diagnosed)
    got_mu, got_k0 = got["friction/estimate"], got["friction/slope_estimate"]
    assert len(want_mu) == len(want_k0) == 400
    assert got_mu.keys() == want_mu.keys() and got_k0.keys() == want_k0.keys()
    for stamp in want_mu:
        assert got_mu[stamp] == pytest.approx(want_mu[stamp], rel=1e-12), stamp
        assert got_k0[stamp] == pytest.approx(want_k0[stamp], rel=1e-12), stamp
    assert got_fx.keys() == want_fx.keys()
    for key, value in want_fx.items():
        assert got_fx[key] == pytest.approx(value, rel=1e-12), key
    # the targets, on the node's own estimates
    truth = yaml.safe_load((BAGS / "contaminated_rig.params.yaml").read_text())
    truth = truth["truth"]["ros__parameters"]
    stamps = sorted(got_mu)
    t = (np.array(stamps) - stamps[0] + 2_500_000) * 1e-9
    events = sorted(set(truth["mu_from"]) | set(truth["k0_from"]) | set(truth["rolling_to"]))
    settled = [x >= max(e for e in events if e <= x) + 0.2 for x in t]
    errors = {"mu": [], "k0": []}
    covered = {"mu": [], "k0": []}
    for x, stamp, ok in zip(t, stamps, settled):
        if not ok:
            continue
        for key, got, values in (("mu", got_mu, truth["mu_static"]),
                                 ("k0", got_k0, truth["k0"])):
            true = [v for a, v in zip(truth[f"{key}_from"], values) if x >= a][-1]
            est, sigma, _ = got[stamp]
            errors[key].append(abs(est - true) / true)
            covered[key].append(abs(est - true) <= 2.0 * sigma)
    assert len(errors["mu"]) >= 250
    assert max(errors["mu"]) < 0.02 and max(errors["k0"]) < 0.05
    assert np.mean(covered["mu"]) >= 0.95 and np.mean(covered["k0"]) >= 0.95
