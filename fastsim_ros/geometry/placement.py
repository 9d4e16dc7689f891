"""Placement of the rail and the wheel, and the wheelset pose, in one side's frame.

Frames (all right-handed but the mirrored side frame, see below; SI units):

- the track frame ``T``: REP-103, ``x`` along the track, ``y`` left, ``z``
  up, origin on the track centre line in the plane resting on the rails;
- the wheelset frame ``W``: origin at the axle centre, turned by the
  wheelset's roll and yaw (``R = Rx(roll) Rz(yaw)``: rolled about ``x``,
  then yawed about the new ``z``, CONTACT's order), not by the axle's spin;
- a side frame ``S``: ``x`` forward, ``y`` towards that side's field side,
  ``z`` up.  For the left side ``S = T``; for the right side ``S`` is ``T``
  mirrored in ``y`` (a left-handed copy), so that one computation serves
  both sides: the geometry and the normal problem are mirror-symmetric,
  and the patches are mirrored back before anything else sees them.

Rail placement (CONTACT's gauge-point computation, user guide "Track and
roller geometry"): the canonical profile (``y`` to the field side, ``z``
down) is turned by the cant (positive: the rail head inclined towards the
track centre; zero for the Manchester profiles, which carry their 1:40
inclination), shifted up so that its highest point lies in the track plane
``z = 0``, and sideways so that its inner-most point within
``gauge_height`` below the top lies at ``y = gauge_width / 2``.

Wheel placement: the wheel profile's origin lies at lateral distance
``flange_back_distance / 2 - flange_back_position`` from the wheelset
centre and at the nominal radius below the axle (no tape-circle offset):
a profile point ``(y_c, z_c)`` is the circle of radius ``R0 + z_c`` at axial
position ``y_w0 + y_c``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.geometry.errors import PlacementError, PoseError
from fastsim_ros.geometry.profiles import Profile

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Placement:
    """Track and wheelset dimensions (m, rad); defaults: the Manchester benchmark.

    ``cant``: the rail's installation angle (rad, positive towards the track
    centre), 0 for profiles that carry their inclination.
    """

    gauge_width: float = 1.435
    gauge_height: float = 0.014
    cant: float = 0.0
    flange_back_distance: float = 1.360
    flange_back_position: float = -0.070
    nominal_radius: float = 0.460

    def __post_init__(self) -> None:
        ranges = {"gauge_width": (0.3, 3.0), "gauge_height": (0.0, 0.1),
                  "cant": (-0.2, 0.2), "flange_back_distance": (0.2, 3.0),
                  "flange_back_position": (-0.5, 0.5), "nominal_radius": (0.05, 2.0)}
        for name, (lo, hi) in ranges.items():
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value)
                    and lo <= value <= hi):
                raise PlacementError(f"{name} must lie in [{lo:g}, {hi:g}], got {value!r}")

    @property
    def wheel_offset(self) -> float:
        """Return the wheel profile origin's lateral distance from the wheelset centre (m)."""
        return 0.5 * self.flange_back_distance - self.flange_back_position


@dataclass(frozen=True, eq=False)
class RailSide:
    """A placed rail in its side frame: the surface ``z(y)`` (m, up), densely sampled.

    ``y``: increasing lateral positions (m, towards the field side); ``z``:
    height (m); ``angle``: surface inclination ``atan(dz/dy)`` (rad,
    positive leaning towards the track centre); ``arc``: arc length (m).
    ``origin``: where the profile origin lies ``(y, z)`` (m).
    """

    y: FloatArray
    z: FloatArray
    angle: FloatArray
    arc: FloatArray
    origin: tuple[float, float]


@dataclass(frozen=True, eq=False)
class WheelSide:
    """A placed wheel profile: circles of radius ``radius`` at axial positions ``axial`` (m).

    ``axial`` increases towards the field side; ``slope`` = ``dr/da``;
    ``flange_tip``: the axial position of the largest radius.
    """

    axial: FloatArray
    radius: FloatArray
    slope: FloatArray
    flange_tip: float


def place_rail(profile: Profile, placement: Placement) -> RailSide:
    """Place a rail profile in a side frame (CONTACT's gauge-point computation)."""
    if profile.kind != "rail":
        raise PlacementError(f"{profile.source} is a {profile.kind} profile, not a rail")
    c, s = math.cos(placement.cant), math.sin(placement.cant)
    yc, zc = profile.dense_y, -profile.dense_z  # z up
    # cant: a rotation by +cant about x turns the head's normal towards -y, the centre
    y = c * yc - s * zc
    z = s * yc + c * zc
    top = int(np.argmax(z))
    z_shift = -float(z[top])
    # the gauge point: the inner-most point within gauge_height below the top,
    # on the inner (track-centre) side of the top (CONTACT: find_gauge_meas_pt)
    inner = np.arange(top + 1)
    within = inner[z[inner] + z_shift >= -placement.gauge_height]
    if within.size == 0:
        raise PlacementError(f"{profile.source}: no rail surface within the gauge height")
    first = int(within[0])
    if first > 0 and z[first - 1] + z_shift < -placement.gauge_height:
        # the face crosses the gauge height between two samples: interpolate
        z0, z1 = z[first - 1] + z_shift, z[first] + z_shift
        f = (-placement.gauge_height - z0) / (z1 - z0)
        y_cross = float(y[first - 1] + f * (y[first] - y[first - 1]))
        y_gauge = min(y_cross, float(y[within].min()))
    else:
        y_gauge = float(y[within].min())
    y_shift = 0.5 * placement.gauge_width - y_gauge
    ys, zs = y + y_shift, z + z_shift
    if np.any(np.diff(ys) < 0.0):
        raise PlacementError(f"{profile.source}: the canted rail runs back in y (cant too large)")
    angle = np.arctan(np.gradient(zs, ys, edge_order=1))
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(ys), np.diff(zs)))])
    return RailSide(_frozen(ys), _frozen(zs), _frozen(angle), _frozen(arc), (y_shift, z_shift))


def place_wheel(profile: Profile, placement: Placement) -> WheelSide:
    """Place a wheel profile on its axle (CONTACT's wheel marker, no tape circle)."""
    if profile.kind != "wheel":
        raise PlacementError(f"{profile.source} is a {profile.kind} profile, not a wheel")
    axial = placement.wheel_offset + profile.dense_y
    radius = placement.nominal_radius + profile.dense_z
    if float(radius.min()) <= 0.1 * placement.nominal_radius:
        raise PlacementError(f"{profile.source}: the profile reaches the axle at the "
                             f"nominal radius {placement.nominal_radius} m")
    tip = float(axial[int(np.argmax(radius))])
    return WheelSide(_frozen(axial), _frozen(radius.copy()), _frozen(profile.dense_slope.copy()),
                     tip)


def _frozen(a: FloatArray) -> FloatArray:
    b = np.ascontiguousarray(a, dtype=np.float64)
    b.setflags(write=False)
    return b


# --------------------------------------------------------------------------- pose

#: a pose is refused beyond these (m, rad): a wheelset on its track, not flying
MAX_SHIFT, MAX_ANGLE = 0.1, 0.2


@dataclass(frozen=True)
class Pose:
    """A wheelset pose in the track frame.

    Lateral shift ``dy`` (m, positive left), vertical position ``dz`` (m,
    positive up, 0 with the axle at the nominal radius above the track
    plane), ``yaw`` about ``z`` and ``roll`` about ``x`` (rad).
    """

    dy: float
    dz: float = 0.0
    yaw: float = 0.0
    roll: float = 0.0

    def __post_init__(self) -> None:
        for name, limit in (("dy", MAX_SHIFT), ("dz", MAX_SHIFT), ("yaw", MAX_ANGLE),
                            ("roll", MAX_ANGLE)):
            value = getattr(self, name)
            if not (math.isfinite(value) and abs(value) <= limit):
                raise PoseError(f"{name} must be finite and within +-{limit:g}, got {value!r}")

    def rotation(self) -> FloatArray:
        """Return ``R = Rx(roll) Rz(yaw)``: wheelset axes (columns) in the track frame."""
        return rotation(self.roll, self.yaw)

    def mirrored(self) -> Pose:
        """Return the pose seen in the frame mirrored in ``y`` (the right side's frame)."""
        return Pose(-self.dy, self.dz, -self.yaw, -self.roll)


def rotation(roll: float, yaw: float) -> FloatArray:
    """Return ``Rx(roll) Rz(yaw)`` (rad)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cy, sy = math.cos(yaw), math.sin(yaw)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    return rx @ rz
