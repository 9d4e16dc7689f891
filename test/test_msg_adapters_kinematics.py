"""Creepages from twists: the general rigid-body form (docs/guide_physics.md) on a rig's cases."""

import math

import pytest

from msg_adapters.cdr import StampedTwist, read_twist
from msg_adapters.errors import MalformedMessageError
from msg_adapters.kinematics import creepages
from msg_adapters.patch import ContactFrame, frame_from_normal
from ros_messages import WHEEL_RADIUS as R
from ros_messages import cdr, contact_normal, twist_msg


def frame_at(origin, normal=(0.0, 0.0, 1.0)):
    axes = frame_from_normal(normal).axes
    return ContactFrame(origin, axes)


def twist(linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)):
    return StampedTwist(0, "wheelset", tuple(map(float, linear)), tuple(map(float, angular)))


LEFT = (0.0, 0.75, -R)
RIGHT = (0.0, -0.75, -R)


@pytest.mark.parametrize("origin", [LEFT, RIGHT])
def test_pure_rolling_on_track_has_no_creepage(origin):
    v0 = 25.0
    c = creepages(frame_at(origin), twist((v0, 0, 0), (0, v0 / R, 0)))
    assert c.speed == pytest.approx(v0)
    assert (c.xi, c.eta, c.phi) == pytest.approx((0.0, 0.0, 0.0), abs=1e-15)


def test_braked_wheel_has_positive_xi():
    # xi = (v0 - omega R)/V with V = (v0 + omega R)/2
    v0, omega_r = 20.0, 19.9
    c = creepages(frame_at(LEFT), twist((v0, 0, 0), (0, omega_r / R, 0)))
    assert c.speed == pytest.approx((v0 + omega_r) / 2)
    assert c.xi == pytest.approx((v0 - omega_r) / ((v0 + omega_r) / 2), rel=1e-12)
    assert c.xi > 0


@pytest.mark.parametrize("yaw", [1e-3, -2e-3, 5e-3])
def test_yawed_wheelset_has_eta_minus_yaw(yaw):
    # the wheelset yawed by +yaw about z runs along the track: in its own frame
    # the centre moves at v0 (cos yaw, -sin yaw, 0); rolling without slip along x
    v0 = 30.0
    v = (v0 * math.cos(yaw), -v0 * math.sin(yaw), 0.0)
    for origin in (LEFT, RIGHT):
        c = creepages(frame_at(origin), twist(v, (0, v[0] / R, 0)))
        assert c.eta == pytest.approx(-math.tan(yaw), rel=1e-12)
        assert c.eta == pytest.approx(-yaw, rel=1e-4)  # small angles
        assert c.xi == pytest.approx(0.0, abs=1e-15)


def test_wheel_on_a_roller_gives_the_speed_mismatch():
    # wheel centre at rest, spinning at omega_w; roller of radius Rr below it,
    # centre c_r = (0, y, -(R + Rr)), turning at w_r = (0, -omega_r, 0):
    # v_r = w_r x (0 - c_r) (docs/guide_node.md)
    rr, y = 0.7, 0.0
    omega_w = 15.0 / R
    omega_r = 15.03 / rr
    w_r = (0.0, -omega_r, 0.0)
    c_r = (0.0, y, -(R + rr))
    v_r = (w_r[1] * (-c_r[2]) - w_r[2] * (-c_r[1]), w_r[2] * (-c_r[0]) - w_r[0] * (-c_r[2]),
           w_r[0] * (-c_r[1]) - w_r[1] * (-c_r[0]))
    c = creepages(frame_at((0.0, y, -R)), twist((0, 0, 0), (0, omega_w, 0)),
                  twist(v_r, w_r))
    wheel_speed, roller_speed = omega_w * R, omega_r * rr
    assert c.speed == pytest.approx((wheel_speed + roller_speed) / 2, rel=1e-12)
    # the roller surface runs faster than the wheel's: as a braked wheel, xi > 0
    assert c.xi == pytest.approx((roller_speed - wheel_speed) / c.speed, rel=1e-9)
    assert c.xi > 0
    assert c.eta == pytest.approx(0.0, abs=1e-15) and c.phi == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("gamma", [0.05, 0.3, 0.6])
def test_contact_angle_gives_spin_of_opposite_sign_on_the_two_wheels(gamma):
    # phi = e_z . w / V with e_z = (0, -+sin g, cos g) on the left/right wheel and
    # w = (0, omega, 0): phi = -+omega sin(g) / V.  With pure rolling omega R = V.
    v0 = 20.0
    omega = v0 / R
    left = creepages(frame_at(LEFT, contact_normal(gamma, "left")), twist((v0, 0, 0),
                                                                          (0, omega, 0)))
    right = creepages(frame_at(RIGHT, contact_normal(gamma, "right")), twist((v0, 0, 0),
                                                                             (0, omega, 0)))
    assert left.phi == pytest.approx(-omega * math.sin(gamma) / left.speed, rel=1e-12)
    assert right.phi == pytest.approx(omega * math.sin(gamma) / right.speed, rel=1e-12)
    assert abs(left.phi) == pytest.approx(math.sin(gamma) / R, rel=1e-12)


def test_yaw_rate_gives_spin_on_a_flat_contact():
    c = creepages(frame_at(LEFT), twist((20.0, 0, 0), (0, 20.0 / R, 0.4)))
    # e_z . w = 0.4 rad/s; the yaw rate also moves the contact point (c includes w_z x p)
    assert c.phi == pytest.approx(0.4 / c.speed, rel=1e-12)


def test_reverse_running_has_negative_speed_and_the_same_creepage_sign_for_braking():
    # backing up at 20 m/s with a braked wheel: |omega R| < |v0|
    v0, omega_r = -20.0, -19.9
    c = creepages(frame_at(LEFT), twist((v0, 0, 0), (0, omega_r / R, 0)))
    assert c.speed == pytest.approx((v0 + omega_r) / 2)
    assert c.speed < 0
    # the slip u_w - u_r = v0 - omega R = -0.1 m/s; xi = slip / V > 0, as when braking forwards
    assert c.xi == pytest.approx(-0.1 / c.speed, rel=1e-9)
    assert c.xi > 0


def test_standstill_has_zero_speed_and_no_finite_creepage():
    c = creepages(frame_at(LEFT), twist())
    assert c.speed == 0.0
    assert math.isnan(c.xi)


def test_twist_cdr_round_trip():
    msg = twist_msg((1.0, -2.0, 3.5), (0.1, 43.2, -0.2), stamp_ns=1_700_000_001_000_000_007,
                    frame_id="wheelset")
    t = read_twist(cdr(msg))
    assert t.stamp_ns == 1_700_000_001_000_000_007
    assert t.frame_id == "wheelset"
    assert t.linear == (1.0, -2.0, 3.5) and t.angular == (0.1, 43.2, -0.2)


@pytest.mark.parametrize("frame_id", ["", "w", "wheelset", "rig1/wheelset", "ab", "abcd",
                                      "abcdefg", "abcdefgh", "r\u00e4der"])
def test_twist_fast_path_reads_as_the_general_reader(frame_id):
    # bytes take read_twist's two-unpack path, a memoryview the general reader:
    # every alignment of the doubles after the frame id must give the same twist
    msg = twist_msg((1.0, -2.0, 3.5), (0.1, 43.2, -0.2), stamp_ns=1_700_000_001_000_000_007,
                    frame_id=frame_id)
    raw = cdr(msg)
    fast, general = read_twist(raw), read_twist(memoryview(raw))
    assert fast == general == read_twist(bytearray(raw))
    assert fast.frame_id == frame_id and fast.stamp_ns == 1_700_000_001_000_000_007
    assert fast.linear == (1.0, -2.0, 3.5) and fast.angular == (0.1, 43.2, -0.2)


def test_twist_fast_path_refuses_what_the_general_reader_refuses():
    raw = cdr(twist_msg((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), frame_id="wheelset"))
    with pytest.raises(MalformedMessageError, match="truncated"):
        read_twist(raw[:-1])
    bad = bytearray(raw)
    bad[16] = 0xFF  # the frame id's first byte: not UTF-8
    with pytest.raises(MalformedMessageError, match="UTF-8"):
        read_twist(bytes(bad))
