"""Profiles mode with ``rolling: transient``: each wheel's contacts keep their memory."""

from __future__ import annotations

import numpy as np
import pytest

from fastsim_ros.geometry.placement import rotation
from fastsim_ros.pipeline import PipelineConfig
from fastsim_ros.pipeline.profiles import ProfilePipeline
from msg_adapters.cdr import StampedTwist
from msg_adapters.profile_msgs import StampedPose, quaternion

MS = 1_000_000
SPEED, R0 = 2.0, 0.46   # m/s, m: at 1 kHz a cycle rolls 2 mm of a ~12 mm patch
#: a tiny table on the treads: 5 shifts at yaw 0
TABLE = {"profile_table": True, "table_dy_min": -1e-3, "table_dy_max": 1e-3,
         "table_dy_step": 5e-4, "table_yaw_max": 0.0, "table_yaw_step": 5e-3}


def _pipeline(**over):
    values = {"patch_source": "profiles", "wheel_load": 1e4, "shear_modulus": 82e9,
              "poisson_ratio": 0.28, **over}
    return ProfilePipeline(PipelineConfig.from_values(values))


def _cycle(p, stamp, xi):
    """One 1 kHz cycle at a longitudinal creepage ``xi`` (the axle spun faster)."""
    v = rotation(0.0, 0.0).T @ np.array([SPEED, 0.0, 0.0])
    p.on_wheel_twist(StampedTwist(stamp, "wheelset", tuple(float(c) for c in v),
                                  (0.0, SPEED * (1.0 + xi) / R0, 0.0)))
    cycle = p.on_pose(StampedPose(stamp, "track", (0.0, 0.4e-3, 0.0), quaternion(0.0, 0.0)))
    return {o.contact: o for o in cycle.outcomes}


@pytest.mark.parametrize("table", [False, True], ids=["per_pose", "table"])
def test_a_creepage_step_builds_up_on_the_profiles_patches(table, tmp_path) -> None:
    """A step in xi: steady answers jump, transient ones rise over a contact length to them."""
    over = {**TABLE, "table_cache": str(tmp_path)} if table else {}
    steady = _pipeline(**over)
    transient = _pipeline(rolling="transient", **over)
    fx = []
    for n in range(14):
        xi = 2e-5 if n < 2 else 1e-4  # below a half of mu N: the build-up is elastic
        s = _cycle(steady, n * MS, xi)["left"]
        t = _cycle(transient, n * MS, xi)["left"]
        assert s.status == t.status == "solved"
        fx.append((s.forces.fx, t.forces.fx))
    # before the step: the steady state (the first patch starts there, the next carries it)
    assert fx[0][1] == pytest.approx(fx[0][0], rel=1e-9)
    assert fx[1][1] == pytest.approx(fx[1][0], rel=1e-3)
    # the cycle after the step (2 mm of a ~4 mm semi-axis rolled) covers a part of the
    # change only (the wheel's rolling radius gives a base creepage: the step is 20 % of it)
    covered = (fx[2][1] - fx[1][0]) / (fx[2][0] - fx[1][0])
    assert 0.1 < covered < 0.8
    rising = [abs(t) for _, t in fx[2:]]
    assert all(b >= a * (1.0 - 1e-6) for a, b in zip(rising, rising[1:]))
    assert fx[-1][1] == pytest.approx(fx[-1][0], rel=5e-3)
