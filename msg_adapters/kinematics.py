"""Twists -> creepages: the general rigid-body form (docs/guide_physics.md).

Wheel twist ``(v, w)`` and rail twist ``(v_r, w_r)``, both about the
wheelset frame's origin and relative to the ground; contact origin ``p`` and
axes ``e_x, e_y, e_z`` in the wheelset frame.  Then

- material velocities at ``p``: wheel ``u_w = v + w x p``, rail ``u_r = v_r + w_r x p``;
- the contact point, fixed in the non-spinning wheelset frame, moves at
  ``c = v + (w_x, 0, w_z) x p``;
- rolling speed ``V = e_x . (c - (u_w + u_r)/2)`` (signed);
- ``xi = e_x . (u_w - u_r)/V``, ``eta = e_y . (u_w - u_r)/V``,
  ``phi = e_z . (w - w_r)/V`` (1/m).

On track (rail at rest, axle spin ``omega`` about ``y``, wheel radius
``R``): ``V = (v0 + omega R)/2``, ``xi = (v0 - omega R)/V``, a braked wheel
has ``xi > 0``.  Plain floats: this runs once per patch, where numpy's
per-call overhead on 3-vectors would cost more than the arithmetic.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from msg_adapters.cdr import StampedTwist
from msg_adapters.patch import ContactFrame

Vec = tuple[float, float, float]

#: the rail at rest: track
REST = StampedTwist(0, "", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


@dataclass(frozen=True, slots=True)
class Creepage:
    """Creepages of one contact: ``xi``, ``eta`` (1), ``phi`` (1/m), rolling speed (m/s)."""

    xi: float
    eta: float
    phi: float
    speed: float


def _cross(a: Vec, b: Vec) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a: Vec, b: Vec) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def twist_is_finite(twist: StampedTwist) -> bool:
    """Return whether every component of the twist is finite."""
    (a, b, c), (d, e, f) = twist.linear, twist.angular
    # a sum is not finite where a term is not (or it overflows: finite terms
    # beyond 1e307, no twist's), and one check is cheaper than six
    return math.isfinite(a + b + c + d + e + f) or all(
        math.isfinite(v) for v in (a, b, c, d, e, f))


def creepages(frame: ContactFrame, wheel: StampedTwist,
              rail: StampedTwist = REST) -> Creepage:
    """Return the creepages of the contact ``frame`` under the two twists.

    Where ``V = 0`` the creepages are not finite: callers compare ``speed``
    with their ``min_rolling_speed`` first.
    """
    p = frame.origin
    ex, ey, ez = frame.axes
    v, w = wheel.linear, wheel.angular
    wx_p = _cross(w, p)
    u_w = (v[0] + wx_p[0], v[1] + wx_p[1], v[2] + wx_p[2])
    wr_p = _cross(rail.angular, p)
    vr = rail.linear
    u_r = (vr[0] + wr_p[0], vr[1] + wr_p[1], vr[2] + wr_p[2])
    c_p = _cross((w[0], 0.0, w[2]), p)
    c = (v[0] + c_p[0], v[1] + c_p[1], v[2] + c_p[2])
    speed = _dot(ex, (c[0] - 0.5 * (u_w[0] + u_r[0]), c[1] - 0.5 * (u_w[1] + u_r[1]),
                      c[2] - 0.5 * (u_w[2] + u_r[2])))
    slip = (u_w[0] - u_r[0], u_w[1] - u_r[1], u_w[2] - u_r[2])
    wr = rail.angular
    spin = _dot(ez, (w[0] - wr[0], w[1] - wr[1], w[2] - wr[2]))
    if speed == 0.0:
        return Creepage(math.nan, math.nan, math.nan, 0.0)
    return Creepage(_dot(ex, slip) / speed, _dot(ey, slip) / speed, spin / speed, speed)
