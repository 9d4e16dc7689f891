"""The pipeline's wear outputs: contact/<name>/energy and damage, the traction cloud's power."""

import math

import numpy as np
import pytest
from geometry_msgs.msg import Vector3Stamped
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import PointCloud2

from fastsim_ros.contact.wear import BURSTOW_RCF, SHEFFIELD_WEAR, t_gamma
from fastsim_ros.ros.params import METHODS, ParameterError
from fastsim_ros.pipeline import Pipeline, PipelineConfig
from msg_adapters import outputs
from ros_messages import cdr, contact_normal, in_plane_area, rolling_twist, twist_msg
from test_pipeline import MS, T0, egg, fore_aft_egg, make, solve, solver_of, turned
from ros_messages import WHEEL_RADIUS as R


def vectors(msgs, topic):
    v = deserialize_message(msgs[topic], Vector3Stamped)
    return v.header.frame_id, (v.vector.x, v.vector.y, v.vector.z)


def test_the_wear_topics_are_outputs_only_when_asked_for():
    assert not any(t.endswith(("/energy", "/damage")) for t in make().outputs())
    topics = make(wear_outputs=True, contacts=["left", "right"]).outputs()
    for c in ("left", "right"):
        for kind in ("energy", "damage"):
            assert topics[f"contact/{c}/{kind}"] == "geometry_msgs/msg/Vector3Stamped"


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("power", [False, True])
def test_energy_and_damage_of_a_solve(method, power):
    """x, y, z of both topics: T-gamma, T-gamma/A, P; wear rate, RCF damage, P / (T-gamma V)."""
    if method == "polach" and power:  # no traction field: the power is refused, not NaN
        with pytest.raises(ParameterError, match="'frictional_power': method polach refuses"):
            make(method=method, wear_outputs=True, frictional_power=power)
        return
    pipe = make(method=method, wear_outputs=True, frictional_power=power)
    pipe.on_wheel_twist(cdr(twist_msg((20.0, 0, 0), (0, 19.94 / R, 0), stamp_ns=T0)))
    out = solve(pipe, egg(), normal=contact_normal(0.2, "left"))
    msgs = dict(pipe.messages(out))
    assert "contact/left/traction" not in msgs  # the tractions kept for the power only
    f, c, p = out.forces, out.creepage, out.patch
    frame, (tg, tga, pw) = vectors(msgs, "contact/left/energy")
    assert frame == "left_contact"
    assert tg == abs(f.fx * c.xi + f.fy * c.eta + f.mz * c.phi) == t_gamma(
        f.fx, f.fy, f.mz, c.xi, c.eta, c.phi)
    assert tg > 0.0 and c.phi != 0.0
    assert tga == pytest.approx(tg / (p.cells * p.dx * p.dy), rel=1e-15)
    _, (rate, rcf, share) = vectors(msgs, "contact/left/damage")
    assert rate == SHEFFIELD_WEAR(tga) and rcf == BURSTOW_RCF(tg)
    if power:
        assert 0.0 < pw < tg * abs(c.speed)
        assert share == pytest.approx(pw / (tg * abs(c.speed)), rel=1e-12)
        assert f.dissipation * abs(c.speed) == pw
    else:
        assert math.isnan(pw) and math.isnan(share)
    # the same values as the solve gives the replay (Pipeline.wear)
    w = pipe.wear(out)
    assert (w.t_gamma, w.t_gamma_per_area, w.wear_rate, w.rcf_damage) == (tg, tga, rate, rcf)


def test_the_power_reaches_the_forces_of_the_library_solve():
    """With frictional_power the solve is the library's with tractions: forces, dissipation."""
    xi = 2e-3
    pipe = make(frictional_power=True, wear_outputs=True)
    pipe.on_wheel_twist(cdr(rolling_twist(xi, stamp_ns=T0)))
    out = solve(pipe, egg())
    a = in_plane_area(egg())
    ref = solver_of("mae_calibrated").solve_arrays(a.pressure, a.x0, a.y0, a.dx, a.dy,
                                                   out.creepage.xi, 0.0, 0.0, 0.3,
                                                   tractions=True)
    # the patch from its message: the library's numbers to the message's rounding
    assert (out.forces.fx, out.forces.fy) == pytest.approx((ref.fx, ref.fy), rel=1e-9)
    assert out.forces.dissipation == pytest.approx(ref.dissipation, rel=1e-9)
    assert ref.dissipation > 0.0
    plain = make(wear_outputs=True)
    plain.on_wheel_twist(cdr(rolling_twist(xi, stamp_ns=T0)))
    other = solve(plain, egg())
    assert (other.forces.fx, other.forces.fy) == pytest.approx((ref.fx, ref.fy), rel=1e-12)


# Polach's closed form has no traction field (the parameters refuse the power with it)
@pytest.mark.parametrize("method", [m for m in METHODS if m != "polach"])
def test_reverse_running_dissipates_what_the_turned_patch_does(method):
    """Backing up: the power of the patch turned by 180 degrees, its density turned with it."""
    pipe = make(method=method, frictional_power=True, publish_traction=True)
    pipe.on_wheel_twist(cdr(twist_msg((-20.0, 0, 0), (0, -19.9 / R, 0), stamp_ns=T0)))
    out = solve(pipe, fore_aft_egg(), normal=contact_normal(0.2, "left"))
    c = out.creepage
    assert c.speed < 0.0
    t = turned(in_plane_area(fore_aft_egg()))
    ref = solver_of(method).solve_arrays(t.pressure, t.x0, t.y0, t.dx, t.dy, c.xi, c.eta,
                                         -c.phi, 0.3, tractions=True)
    assert out.forces.dissipation == pytest.approx(ref.dissipation, rel=1e-9)
    assert ref.dissipation > 0.0
    density = out.forces.dissipation_density
    if method != "fastsim_ellipse":  # on the patch's own cells: the turned density
        assert np.allclose(density, ref.dissipation_density[::-1, ::-1], rtol=1e-9,
                           atol=1e-9 * density.max())
    msgs = dict(pipe.messages(out))
    cloud = deserialize_message(msgs["contact/left/traction"], PointCloud2)
    pts = np.frombuffer(bytes(cloud.data), dtype=outputs.TRACTION_DTYPE)
    power = pts["friction_power"].reshape(cloud.height, cloud.width).astype(float)
    assert np.allclose(power, density * abs(c.speed), rtol=1e-6, atol=0.0)
    p = out.patch
    total = power.sum() * p.dx * p.dy
    if method == "fastsim_ellipse":  # moved from the ellipse's grid: the move loses a little
        assert total == pytest.approx(out.forces.dissipation * abs(c.speed), rel=0.05)
    else:
        assert total == pytest.approx(out.forces.dissipation * abs(c.speed), rel=1e-6)
    if method != "fastsim_ellipse":  # the slip cells carry it all (the cloud's slip flag)
        assert (power[pts["slip"].reshape(power.shape) == 0] == 0.0).all()


def test_the_traction_cloud_without_the_power_carries_nan_not_zero():
    """Transient rolling has no steady march to take the power from: NaN in the cloud."""
    pipe = make(publish_traction=True, rolling="transient")
    pipe.on_wheel_twist(cdr(rolling_twist(2e-3, stamp_ns=T0)))
    out = solve(pipe, egg())
    assert math.isnan(out.forces.dissipation)
    cloud = deserialize_message(dict(pipe.messages(out))["contact/left/traction"], PointCloud2)
    pts = np.frombuffer(bytes(cloud.data), dtype=outputs.TRACTION_DTYPE)
    assert np.isnan(pts["friction_power"]).all()


def test_no_contact_publishes_no_energy():
    pipe = make(wear_outputs=True)
    out = solve(pipe, egg(), pressure=np.zeros_like(egg().pressure))
    assert out.status == "no_contact"
    msgs = dict(pipe.messages(out))
    assert vectors(msgs, "contact/left/energy")[1] == (0.0, 0.0, 0.0)
    rate, rcf, share = vectors(msgs, "contact/left/damage")[1]
    assert (rate, rcf) == (0.0, 0.0) and math.isnan(share)


def test_the_tables_are_parameters_checked_and_changed_while_running():
    pipe = make(wear_outputs=True)
    pipe.on_wheel_twist(cdr(rolling_twist(3e-3, stamp_ns=T0)))
    out = solve(pipe, egg())
    pipe.update({"rcf_function_x": [0.0, 1000.0], "rcf_function_y": [0.0, 1.0]})
    out2 = solve(pipe, egg(), stamp=T0 + 11 * MS)
    w = pipe.wear(out2)
    assert w.rcf_damage == pytest.approx(w.t_gamma / 1000.0, rel=1e-12)
    assert pipe.wear(out).rcf_damage == w.rcf_damage  # the table in force when asked
    with pytest.raises(ParameterError, match="rcf_function_x.*as many values"):
        pipe.update({"rcf_function_x": [0.0, 10.0, 20.0]})
    with pytest.raises(ParameterError, match="must not decrease"):
        PipelineConfig.from_values({"wear_function_x": [0.0, 2.0, 1.0],
                                    "wear_function_y": [1.0, 1.0, 1.0]})
    with pytest.raises(ParameterError, match="wear_function_y"):
        Pipeline(PipelineConfig.from_values({"wear_function_y": "fast"}))
