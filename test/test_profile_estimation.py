"""Profiles mode with ``friction_estimation: on``: the measured wheelset wrench in, mu out."""

from __future__ import annotations

import numpy as np
import pytest

from fastsim_ros.pipeline import FRICTION_ESTIMATE_TOPIC, MEASURED_WRENCH_TOPIC, PipelineConfig
from fastsim_ros.pipeline.profiles import ProfilePipeline
from msg_adapters.cdr import StampedTwist
from msg_adapters.profile_msgs import StampedPose, quaternion

MS = 1_000_000
SPEED, R0 = 2.0, 0.46   # m/s, m
MU_TRUE, MU_PRIOR = 0.25, 0.35


def _pipeline(**over):
    values = {"patch_source": "profiles", "wheel_load": 1e4, "shear_modulus": 82e9,
              "poisson_ratio": 0.28, **over}
    return ProfilePipeline(PipelineConfig.from_values(values))


def _cycle(p, stamp, xi, measured=None):
    """One cycle: the twist (the axle driven at ``xi``), a measured wrench if given, the pose."""
    p.on_wheel_twist(StampedTwist(stamp, "wheelset", (SPEED, 0.0, 0.0),
                                  (0.0, SPEED * (1.0 + xi) / R0, 0.0)))
    if measured is not None:
        p.pipeline.on_measured_wrench(StampedTwist(stamp, "wheelset", measured, (0.0, 0.0, 0.0)))
    return p.on_pose(StampedPose(stamp, "track", (0.0, 0.0, 0.0), quaternion(0.0, 0.0)))


def test_profiles_mode_takes_the_measured_wrench_and_publishes_the_estimate() -> None:
    p = _pipeline(friction_estimation="on")
    assert MEASURED_WRENCH_TOPIC in {i.topic for i in p.inputs()}
    assert FRICTION_ESTIMATE_TOPIC in p.outputs()
    assert MEASURED_WRENCH_TOPIC not in {i.topic for i in _pipeline().inputs()}


def test_the_estimate_finds_the_rigs_friction_from_its_traction() -> None:
    """A rig at mu 0.25 driven beyond the knee; the node starts from 0.35 and finds 0.25.

    The measured wrench is the wheelset wrench of the same model at the true
    mu (the estimator alone, no model error), with a load cell's noise.
    """
    rig = _pipeline(friction_coefficient=MU_TRUE)
    node = _pipeline(friction_coefficient=MU_PRIOR, friction_estimation="on",
                     friction_measurement_noise=20.0)
    rng = np.random.default_rng(3)
    estimates = []
    for n in range(25):
        stamp = (n + 1) * MS
        xi = 1.5e-2  # well beyond the knee: the force is about mu N, the slope dF/dmu about N
        truth = next(o.wheelset for o in _cycle(rig, stamp, xi).outcomes
                     if o.wheelset is not None)
        force = tuple(float(f) for f in np.asarray(truth.force) + rng.normal(0.0, 20.0, 3))
        cycle = _cycle(node, stamp, xi, measured=force)
        friction = [o.friction for o in cycle.outcomes if o.friction is not None]
        assert len(friction) == 1  # once per rig cycle, with the wheelset wrench
        estimates.append(friction[0])
    last = estimates[-1]
    assert last.mu == pytest.approx(MU_TRUE, rel=0.01)
    assert abs(last.mu - MU_TRUE) < 2.0 * last.sigma + 1e-3 * MU_TRUE
    assert estimates[0].mu < MU_PRIOR  # it moved at the first measured cycle
    # the next cycle's published wrenches use the estimate: the rig's within 1 % of mu N
    stamp = 30 * MS
    truth = next(o.wheelset for o in _cycle(rig, stamp, xi).outcomes if o.wheelset is not None)
    served = next(o.wheelset for o in _cycle(node, stamp, xi).outcomes
                  if o.wheelset is not None)
    assert served.force[0] == pytest.approx(truth.force[0], abs=0.01 * MU_TRUE * 2e4)
