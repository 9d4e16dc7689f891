"""fastsim_node over real DDS on loopback: started from its installed script, driven by a client.

Wrenches must equal the library's for the same inputs; every bad input
(docs/guide_node.md) gives no wrench, a diagnostic naming its reason, and the next
good input is served; refused parameters leave the node running; SIGTERM
ends it cleanly.
"""

import math
import signal
import subprocess

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import PointCloud2

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import samples
from fastsim_ros.contact.compiled import CalibratedMaeSolver, EquivalentEllipseSolver, MaeSolver
from fastsim_ros.contact.friction import ConstantFriction, SlopeReduction
from fastsim_ros.contact.polach import PolachSolver
from ros_harness import (DIAGNOSTICS_PERIOD, NODE_SCRIPT, PACKAGE_ROOT, Client, NodeProcess,
                         stamp_ns)
from ros_messages import WHEEL_RADIUS as R
from ros_messages import cloud_msg, in_plane_area, rolling_twist, twist_msg

MS = 1_000_000
T0 = 1_700_000_000 * 1_000_000_000

pytestmark = pytest.mark.skipif(not NODE_SCRIPT.exists(),
                                reason="fastsim_node is not installed (run colcon build)")


def egg(scale=8e-3):
    return samples.semi_ellipses_patch(0.5, 2.0, cells=24, scale=scale, load=6e4)


def ellipse():
    return areas.ellipse(6e-3, 4e-3, nx=20, ny=20).with_load(5e4)


#: the library's compiled solver of each method the node offers; the first is the default
SOLVERS = {"mae_calibrated": CalibratedMaeSolver, "mae": MaeSolver,
           "fastsim_ellipse": EquivalentEllipseSolver, "polach": PolachSolver}
DEFAULT_METHOD = "mae_calibrated"


def library(method, area, xi, eta, phi, mu=0.3):
    solver = SOLVERS[method](0.28, 8e10)
    a = in_plane_area(area)
    return solver.solve_arrays(a.pressure, a.x0, a.y0, a.dx, a.dy, xi, eta, phi, mu)


@pytest.fixture
def run_node(tmp_path):
    """Start fastsim_node with ROS arguments and a client for its contacts; stop both after."""
    started = []

    def start(*ros_args, contacts=("left", "right")):
        proc = NodeProcess(*ros_args, log_dir=tmp_path)
        client = Client(tuple(contacts))
        started.append((proc, client))
        client.wait_connected(proc)
        return proc, client

    yield start
    for proc, client in started:
        client.close()
        proc.stop()


def exchange(client, contact, msg, rejected=None):
    """Publish a patch; once the node counted it, return the wrenches that came for it.

    ``rejected``: the reason the node must count it under (then no wrench).
    """
    outcome = client.send_patch(contact, msg)
    assert outcome == (rejected or "wrench"), f"{contact}: {outcome}, expected {rejected}"
    return [w for w in client.wrenches[contact] if stamp_ns(w) == stamp_ns(msg)]


def send_twist(client, msg, rail=False):
    client.send_twist(msg, rail=rail)  # returns once the node took it: before the patches


def force(w):
    return (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z, w.wrench.torque.z)


def assert_library_equal(w, ref):
    got = force(w)
    want = (ref.fx, ref.fy, ref.n, ref.mz)
    for g, e in zip(got, want):
        assert g == pytest.approx(e, rel=1e-9, abs=1e-9 * ref.n)


@pytest.mark.parametrize("contacts", [("left",), ("left", "right"), ("a", "b", "c", "d")])
def test_wrenches_equal_the_library_for_every_method(run_node, contacts):
    names = "[" + ", ".join(f'"{c}"' for c in contacts) + "]"
    _, client = run_node("-p", f"contacts:={names}", contacts=contacts)
    xi = 1.5e-3
    send_twist(client, rolling_twist(xi, stamp_ns=T0))
    shapes = [egg(), ellipse(), egg(6e-3).mirrored_y(), egg(1e-2)]
    stamp = T0 + MS
    for method in SOLVERS:  # the default first, then each set while running
        if method != DEFAULT_METHOD:
            (result,) = client.set_parameters(method=method)
            assert result.successful, result.reason
        for k, c in enumerate(contacts):
            # treads side by side; flat normal: the centroid lies at z = -R, so xi is exact
            origin = (0.0, 0.75 - 0.5 * k, -R)
            stamp += MS
            got = exchange(client, c, cloud_msg(shapes[k], origin=origin, stamp_ns=stamp,
                                                dtype="<f8"))
            assert len(got) == 1, f"{c}: no wrench for {method}"
            assert got[0].header.frame_id == f"{c}_contact"
            assert_library_equal(got[0], library(method, shapes[k], xi, 0.0, 0.0))
    # one wheelset wrench per rig cycle: the sum once every contact had a new wrench
    client.wait_for(lambda: len(client.wheelset) >= len(SOLVERS))
    assert len(client.wheelset) == len(SOLVERS)
    assert client.wheelset[-1].header.frame_id == "wheelset"
    assert client.wheelset[-1].wrench.force.z == pytest.approx(
        sum(w[-1].wrench.force.z for w in client.wrenches.values()), rel=1e-12)


def test_a_frame_subscriber_that_joins_late_gets_the_frame_at_the_next_solve(run_node):
    """The frame is published when it changes: a viewer that joins a steady rig later got none.

    A subscription to ``contact/left/frame`` made after the first solves
    receives the (unmoved) frame at the next solve, and once only.
    """
    proc, client = run_node("-p", 'contacts:=["left"]', contacts=("left",))
    send_twist(client, rolling_twist(1e-3, stamp_ns=T0))
    for k in range(2):
        assert len(exchange(client, "left", cloud_msg(egg(), stamp_ns=T0 + (k + 1) * MS,
                                                      dtype="<f8"))) == 1
    frames = client.subscribe(PoseStamped, "contact/left/frame")
    client.wait_connected(proc)
    for k in range(2, 5):
        assert len(exchange(client, "left", cloud_msg(egg(), stamp_ns=T0 + (k + 1) * MS,
                                                      dtype="<f8"))) == 1
    assert client.wait_for(lambda: len(frames) >= 1)
    client.spin(0.2)
    assert [stamp_ns(f) for f in frames] == [T0 + 3 * MS]
    assert frames[0].header.frame_id == "wheelset"


def test_roller_rig_config(run_node):
    _, client = run_node("--params-file", str(PACKAGE_ROOT / "config" / "roller_rig.yaml"),
                         contacts=("wheel",))
    # wheel at rest in translation, spinning; roller of radius 0.7 m below it, 0.2% faster
    rr = 0.7
    omega_w, omega_r = 15.0 / R, 15.03 / rr
    origin = (0.0, 0.0, -R)
    send_twist(client, twist_msg((0, 0, 0), (0, omega_w, 0), stamp_ns=T0))
    assert exchange(client, "wheel", cloud_msg(ellipse(), origin=origin, stamp_ns=T0 + MS,
                                               dtype="<f8"), rejected="stale_kinematics") == []
    # v_r = w_r x (0 - c_r), c_r = (0, 0, -(R + rr)), w_r = (0, -omega_r, 0)
    send_twist(client, twist_msg((-omega_r * (R + rr), 0, 0), (0, -omega_r, 0),
                                 stamp_ns=T0 + 2 * MS), rail=True)
    got = exchange(client, "wheel", cloud_msg(ellipse(), origin=origin, stamp_ns=T0 + 3 * MS,
                                              dtype="<f8"))
    assert len(got) == 1
    speed = (15.0 + 15.03) / 2
    xi = (15.03 - 15.0) / speed  # the roller's surface is faster: as a braked wheel
    # roller_rig.yaml's method: the calibrated MAE
    assert_library_equal(got[0], library("mae_calibrated", ellipse(), xi, 0.0, 0.0))
    assert got[0].wrench.force.x < 0
    client.wait_for(lambda: client.diagnostic_values("wheel").get(
        "rejected/stale_kinematics") == "1", 3.0)
    assert client.diagnostic_values("wheel")["rejected/stale_kinematics"] == "1"


def bad_inputs():
    """Return (reason, patch message builder) for every bad input the node rejects."""
    area = egg()

    def values(msg):
        return np.frombuffer(bytes(msg.data), dtype="<f8").reshape(area.ny, area.nx, 7).copy()

    def nonfinite(stamp):
        msg = cloud_msg(area, stamp_ns=stamp, dtype="<f8")
        v = values(msg)
        v[4, 4, 6] = math.nan
        msg.data = v.tobytes()
        return msg

    def negative(stamp):
        p = area.pressure.copy()
        p[3, 3] = -1.0
        return cloud_msg(area, stamp_ns=stamp, pressure=p)

    def irregular(stamp):
        msg = cloud_msg(area, stamp_ns=stamp, dtype="<f8")
        v = values(msg)
        v[6, :, 0] += 0.4 * area.dx
        msg.data = v.tobytes()
        return msg

    def missing(stamp):
        msg = cloud_msg(area, stamp_ns=stamp)
        msg.fields = [f for f in msg.fields if f.name != "normal_z"]
        return msg

    def huge(stamp):  # 130 x 130 cells, above max_patch_cells = 10000
        p = np.zeros((130, 130))
        p[60:70, 60:70] = 1e9
        return cloud_msg(areas.GridArea(0.0, 0.0, 1e-3, 1e-3, p), stamp_ns=stamp)

    def stray(stamp):
        msg = cloud_msg(area, stamp_ns=stamp, dtype="<f8")
        v = values(msg)
        v[0, 0, 0] += 100.0
        msg.data = v.tobytes()
        return msg

    def degenerate(stamp):
        p = np.zeros_like(area.pressure)
        p[5, 5:8] = 1e9
        return cloud_msg(area, stamp_ns=stamp, pressure=p)

    def out_of_table(stamp):  # 2 x 401 cells: MAE zones of a/b about 200, beyond the tables
        strip = areas.GridArea(-200e-3, -0.5e-3, 1e-3, 1e-3, np.ones((2, 401)) * 1e9)
        return cloud_msg(strip, stamp_ns=stamp)

    def tiny(stamp):
        return cloud_msg(area.scaled(1e-200), origin=(0.0, 0.0, 0.0), stamp_ns=stamp,
                         dtype="<f8")

    def in_mm(stamp):  # positions in millimetres: a patch 12 m across
        return cloud_msg(area.scaled(1e3), origin=(0.0, 750.0, -460.0), stamp_ns=stamp,
                         dtype="<f8")

    def in_mpa(stamp):  # pressures in megapascals
        return cloud_msg(area, stamp_ns=stamp, pressure=area.pressure * 1e-6)

    return [("nonfinite", nonfinite), ("negative_pressure", negative),
            ("irregular_grid", irregular), ("irregular_grid", stray),
            ("missing_field", missing),
            ("wrong_frame", lambda s: cloud_msg(area, stamp_ns=s, frame_id="base_link")),
            ("too_large", huge), ("degenerate", degenerate), ("degenerate", tiny),
            ("out_of_table", out_of_table), ("implausible", in_mm), ("implausible", in_mpa)]


def test_every_bad_input_is_rejected_and_the_next_good_one_served(run_node):
    proc, client = run_node("-p", "max_patch_cells:=10000", contacts=("left",))
    # before any twist: no kinematics
    assert exchange(client, "left", cloud_msg(egg(), stamp_ns=T0 - MS),
                    rejected="no_kinematics") == []
    send_twist(client, rolling_twist(1e-3, stamp_ns=T0))
    stamp = T0 + MS
    expected = {"no_kinematics": 1}
    for reason, build in bad_inputs():
        stamp += MS
        assert exchange(client, "left", build(stamp), rejected=reason) == [], reason
        expected[reason] = expected.get(reason, 0) + 1
        stamp += MS
        good = exchange(client, "left", cloud_msg(egg(), stamp_ns=stamp, dtype="<f8"))
        assert len(good) == 1, f"no wrench after {reason}"
    # a stamp older than the last one
    assert exchange(client, "left", cloud_msg(egg(), stamp_ns=stamp - MS // 2),
                    rejected="old_stamp") == []
    expected["old_stamp"] = 1
    # kinematics too old by stamp, then standstill
    stamp += 60 * MS
    assert exchange(client, "left", cloud_msg(egg(), stamp_ns=stamp),
                    rejected="stale_kinematics") == []
    expected["stale_kinematics"] = 1
    send_twist(client, twist_msg((0.01, 0, 0), (0, 0.01 / R, 0), stamp_ns=stamp + MS))
    stamp += 2 * MS
    assert exchange(client, "left", cloud_msg(egg(), stamp_ns=stamp),
                    rejected="standstill") == []
    expected["standstill"] = 1
    # an empty patch is no rejection: a zero wrench, counted as no_contact
    stamp += MS
    zero = exchange(client, "left", cloud_msg(egg(), stamp_ns=stamp,
                                              pressure=np.zeros_like(egg().pressure)))
    assert len(zero) == 1 and force(zero[0]) == (0.0, 0.0, 0.0, 0.0)

    def counted():
        values = client.diagnostic_values("left")
        return values and values["no_contact"] == "1" and all(
            values[f"rejected/{r}"] == str(n) for r, n in expected.items())
    if not client.wait_for(counted, 4.0):
        values = client.diagnostic_values("left") or {}
        wrong = {r: (n, values.get(f"rejected/{r}")) for r, n in expected.items()
                 if values.get(f"rejected/{r}") != str(n)}
        pytest.fail(f"rejection counts (expected, seen) differ: {wrong}; no_contact"
                    f" {values.get('no_contact')}; all: {values}")
    values = client.diagnostic_values("left")
    assert values["solved"] == str(len(bad_inputs()))
    # the log names the first rejection at once (later ones within a second are summed)
    assert "left: patch rejected, no_kinematics" in proc.output()


def test_throttled_log_builds_no_message_while_suppressed():
    from fastsim_ros.ros.node import ThrottledLog

    class Logger:
        def __init__(self):
            self.lines = []

        def warning(self, message):
            self.lines.append(message)

    logger = Logger()
    log = ThrottledLog(logger, period=3600.0)
    assert log.due()
    log.warning("first")
    assert not any(log.due() for _ in range(5))
    assert logger.lines == ["first"] and log.suppressed == 5
    log = ThrottledLog(logger, period=0.0)  # every call due: nothing suppressed to report
    assert log.due() and log.due()
    log.warning("second")
    assert logger.lines[-1] == "second"
    log.suppressed = 2
    log.warning("third")
    assert logger.lines[-1] == "third (and 2 more in the last 0 s)" and log.suppressed == 0


def test_a_slope_reduction_set_while_running_gives_the_librarys_reduced_wrench(run_node):
    """Set at run time, the reduction's parameters give the library's reduced solve."""
    _, client = run_node(contacts=("left",))
    xi = 1.5e-3
    send_twist(client, rolling_twist(xi, stamp_ns=T0))
    results = client.set_parameters(slope_reduction_k0=0.54, slope_reduction_alpha_inf=0.02,
                                    slope_reduction_beta=0.62)
    assert all(r.successful for r in results), [r.reason for r in results]
    (w,) = exchange(client, "left", cloud_msg(egg(), origin=(0.0, 0.75, -R), stamp_ns=T0 + MS,
                                              dtype="<f8"))
    a = in_plane_area(egg())
    law = ConstantFriction(0.3, reduction=SlopeReduction(0.54, 0.02, 0.62))
    ref = CalibratedMaeSolver(0.28, 8e10).solve_arrays(a.pressure, a.x0, a.y0, a.dx, a.dy,
                                                       xi, 0.0, 0.0, friction=law)
    assert_library_equal(w, ref)
    assert abs(ref.fx) < 0.8 * abs(library(DEFAULT_METHOD, egg(), xi, 0.0, 0.0).fx)
    # Polach's method takes no slope reduction: refused, the node keeps its method
    (result,) = client.set_parameters(method="polach")
    assert not result.successful and "polach" in result.reason
    assert client.get_parameter("method") == DEFAULT_METHOD


def test_refused_parameter_keeps_the_node_and_its_value(run_node):
    proc, client = run_node(contacts=("left",))
    (result,) = client.set_parameters(friction_coefficient=-0.2)
    assert not result.successful
    assert "friction_coefficient" in result.reason and "0.001" in result.reason  # the range
    (result,) = client.set_parameters(method="exact_please")
    assert not result.successful and "method" in result.reason
    (result,) = client.set_parameters(poisson_ratio=0.3)
    assert not result.successful  # the material is set at start only
    assert client.get_parameter("friction_coefficient") == 0.3
    assert proc.proc.poll() is None
    # and it still serves, with the friction it kept: saturated at 0.3 N
    send_twist(client, rolling_twist(3e-2, stamp_ns=T0))
    (w,) = exchange(client, "left", cloud_msg(egg(), stamp_ns=T0 + MS, dtype="<f8"))
    fx, fy, n, _ = force(w)
    assert math.hypot(fx, fy) == pytest.approx(0.3 * n, rel=0.03)
    (result,) = client.set_parameters(friction_coefficient=0.4)
    assert result.successful
    (w,) = exchange(client, "left", cloud_msg(egg(), stamp_ns=T0 + 2 * MS, dtype="<f8"))
    fx, fy, n, _ = force(w)
    assert math.hypot(fx, fy) == pytest.approx(0.4 * n, rel=0.03)


def test_a_whole_number_for_a_double_parameter_is_that_double(run_node):
    """``-p friction_coefficient:=1`` and ``ros2 param set ... 1``: rclpy types by spelling.

    An integer for a parameter declared double was refused at start ("expecting
    type 'DOUBLE'", exit 2) and at run time ("Wrong parameter type").
    """
    proc, client = run_node("-p", "contacts:=[left]", "-p", "friction_coefficient:=1",
                            contacts=("left",))
    value = client.get_parameter("friction_coefficient")
    assert value == 1.0 and isinstance(value, float)
    (result,) = client.set_parameters(friction_coefficient=2)
    assert result.successful, result.reason
    value = client.get_parameter("friction_coefficient")
    assert value == 2.0 and isinstance(value, float)
    (result,) = client.set_parameters(friction_coefficient=9)  # out of range: still refused
    assert not result.successful and "friction_coefficient" in result.reason
    (result,) = client.set_parameters(method=3)  # no double: the type is still checked
    assert not result.successful
    assert proc.proc.poll() is None


def test_diagnostics_report_the_peers_each_topic_matched(run_node):
    """What a client cannot see from its side: the node's own matches, per topic."""
    _, client = run_node(contacts=("left",))  # the node serves left and right
    left, right = client.diagnostic_values("left"), client.diagnostic_values("right")
    assert left["publishers/contact/left/patch"] == "1"
    assert right["publishers/contact/right/patch"] == "0"
    assert "publishers/contact/right/patch" not in left  # each status its own contact's
    assert left["subscribers/contact/left/wrench"] == "1"
    assert left["subscribers/contact/left/creepage"] == "0"
    for status in (left, right):  # the shared topics in every status
        assert status["publishers/wheelset/twist"] == "1"
        assert status["publishers/rail/twist"] == "1"
        assert status["subscribers/wheelset/wrench"] == "1"
        assert status["subscribers/contact/markers"] == "0"


def warnings_of(proc, text):
    """Return the node's warning lines that contain ``text``."""
    return [line for line in proc.output().splitlines() if "WARN" in line and text in line]


def test_an_unknown_parameter_is_a_warning_naming_the_nearest_and_the_node_starts(run_node):
    """An override no parameter is declared for (rclpy ignores it): a warning, and it starts."""
    proc, client = run_node("-p", "friction_coeficient:=0.4", contacts=("left",))
    lines = warnings_of(proc, "friction_coeficient")
    assert len(lines) == 1, proc.output()
    assert ("unknown parameter 'friction_coeficient'; did you mean 'friction_coefficient'?"
            in lines[0])
    assert client.get_parameter("friction_coefficient") == 0.3
    assert proc.proc.poll() is None


def test_a_params_file_for_another_node_name_is_a_warning_and_the_node_starts(
        run_node, tmp_path):
    """A section keyed ``fastsim_node`` never reaches the node ``fastsim``: the node says so."""
    path = tmp_path / "p.yaml"
    path.write_text("fastsim_node:\n  ros__parameters:\n    friction_coefficient: 0.4\n")
    proc, client = run_node("--params-file", str(path), contacts=("left",))
    lines = warnings_of(proc, "fastsim_node")
    assert len(lines) == 1, proc.output()
    assert (f"{path}: section 'fastsim_node' is for another node: this node's section is "
            "'fastsim' or a wildcard such as '/**'") in lines[0]
    assert client.get_parameter("friction_coefficient") == 0.3
    assert proc.proc.poll() is None


def test_diagnostics_say_which_counts_are_this_period_and_which_since_start(run_node):
    """The status message counts the last period, ``rejected`` and its reasons since start."""
    _, client = run_node(contacts=("left",))
    for k in range(2):  # no twist yet: each rejected
        assert exchange(client, "left", cloud_msg(egg(), stamp_ns=T0 + k * MS),
                        rejected="no_kinematics") == []
    statuses = [status for array in client.diagnostics for status in array.status
                if status.name == "fastsim: left"]
    periods = []
    for status in statuses:
        values = {kv.key: kv.value for kv in status.values}
        assert values["since_start"].startswith("wrenches, solved, no_contact, rejected, "
                                                "rejected/*"), values
        periods.append((int(values["this_period/patches"]),
                        int(values["this_period/rejected"])))
        if values["this_period/rejected"] != "0":
            n, m = values["this_period/rejected"], values["this_period/patches"]
            assert status.message.startswith(f"{n} of {m} patches rejected this period; "
                                             "last: "), status.message
    # the periods add up to the counts since start
    assert tuple(map(sum, zip(*periods))) == (2, 2)
    last = client.diagnostic_values("left")
    assert last["rejected"] == "2" and last["rejected/no_kinematics"] == "2"


def test_publishers_on_a_patch_topic_of_no_contact_are_named_in_diagnostics(run_node):
    """A patch topic the node does not take: its publishers named, with the parameter."""
    proc, client = run_node(contacts=("left",))  # the node serves left and right
    flange = client.node.create_publisher(PointCloud2, "contact/left_flange/patch", client.qos)
    key = "unsubscribed/contact/left_flange/patch"
    assert client.wait_for(lambda: key in client.diagnostic_values("left")), (
        client.diagnostic_values("left"))
    for contact in ("left", "right"):
        assert client.diagnostic_values(contact)[key] == (
            "1 publisher(s); add 'left_flange' to parameter 'contacts' to take it")
    assert not any(k.startswith("unsubscribed/contact/left/")
                   for k in client.diagnostic_values("left"))
    # logged once for the topic, however many looks at the graph find it: the node's
    # diagnostics count its time, a look at most every GRAPH_PERIOD
    from fastsim_ros.ros.node import GRAPH_PERIOD
    seen, periods = len(client.diagnostics), 2 * math.ceil(GRAPH_PERIOD / DIAGNOSTICS_PERIOD)
    assert client.wait_for(lambda: len(client.diagnostics) >= seen + periods, 30.0)
    assert key in client.diagnostic_values("left")
    lines = warnings_of(proc, "/contact/left_flange/patch")
    assert len(lines) == 1, proc.output()
    assert "add 'left_flange' to parameter 'contacts'" in lines[0]
    # gone with its publisher
    client.node.destroy_publisher(flange)
    assert client.wait_for(lambda: key not in client.diagnostic_values("left"))


def test_sigterm_and_sigint_end_cleanly(tmp_path):
    for sig in (signal.SIGTERM, signal.SIGINT):
        proc = NodeProcess("--params-file", str(PACKAGE_ROOT / "config" / "fastsim.yaml"),
                           log_dir=tmp_path)
        client = Client(("left",), name="probe")
        try:
            client.wait_connected(proc)
        finally:
            client.close()
        assert proc.stop(sig) == 0
        out = proc.output()
        assert "Traceback" not in out and "solving left, right with mae_calibrated " in out


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT, signal.SIGTERM, signal.SIGINT],
                         ids=["SIGTERM", "SIGINT", "SIGTERM-again", "SIGINT-again"])
def test_a_signal_while_publishing_ends_without_a_traceback(tmp_path, sig):
    # a stream of patches and a 100 Hz /diagnostics: the signal lands inside a callback.
    # Before the fix 8 of 10 such stops printed rclpy's FATAL "Exception in 'subscriptions'
    # callback" with a traceback (SIGTERM: the publish after the context's shutdown;
    # SIGINT: KeyboardInterrupt raised mid-callback)
    proc = NodeProcess("-p", 'contacts:=["left"]', log_dir=tmp_path, diagnostics_period=0.01)
    client = Client(("left",), name="probe")
    area = samples.flange_root_patch(cells=20)
    try:
        client.wait_connected(proc)
        t0 = 1_700_000_000 * 1_000_000_000
        for i in range(400):
            stamp = t0 + i * 1_000_000
            client.twist.publish(rolling_twist(4e-3, stamp_ns=stamp))
            client.patch["left"].publish(cloud_msg(area, stamp_ns=stamp, dtype="<f8"))
            if i % 5 == 0:
                client.executor.spin_once(timeout_sec=0.0)
            if i == 300:
                proc.proc.send_signal(sig)
        assert client.wrenches["left"], "the node answered none of the patches"
    finally:
        client.close()
        try:  # the one signal ends it (a second SIGINT is a user's "now")
            proc.proc.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            pass
        status = proc.stop(signal.SIGKILL)
    out = proc.output()
    assert status == 0, out
    for mark in ("Traceback", "FATAL", "Error occurred", "Exception in"):
        assert mark not in out, out


def test_the_installed_node_keeps_its_own_kernel_cache(tmp_path):
    """A node started from this (checkout) process caches the installed kernels in its own place.

    Importing ``fastsim_ros`` here exported this tree's NUMBA_CACHE_DIR; a child
    importing the install tree must choose its own (keyed on its own kernel
    sources), not compile the installed kernels afresh under the checkout's
    digest whenever the checkout's sources differ; a directory the user set
    is kept.
    """
    import os
    import sys

    import fastsim_ros  # noqa: F401  (this process has chosen its directory)
    probe = [sys.executable, "-c", "import os, fastsim_ros; "
             "print(fastsim_ros.__file__); print(os.environ['NUMBA_CACHE_DIR'])"]
    own = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "FASTSIM_ROS_NUMBA_CACHE_DIR")}

    def child(env):
        done = subprocess.run(probe, env=env, cwd="/", capture_output=True, text=True,
                              timeout=60, check=True)
        return done.stdout.split()

    alone = child(own)
    assert alone[0].startswith(str(PACKAGE_ROOT / "install"))  # the installed package
    assert child(dict(os.environ)) == alone
    chosen = str(tmp_path / "mine")
    assert child(dict(own, NUMBA_CACHE_DIR=chosen))[1] == chosen


@pytest.mark.parametrize("args, name", [
    (["-p", "friction_coefficient:=-1.0"], "friction_coefficient"),
    (["-p", "method:=exact_please"], "method"),
    (["-p", "poisson_ratio:=0.7"], "poisson_ratio"),
    (["-p", "contacts:=[\"left\", \"left\"]"], "contacts"),
])
def test_bad_start_parameters_exit_2_with_one_line(args, name):
    done = subprocess.run([str(NODE_SCRIPT), "--ros-args", *args], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and name in lines[0], done.stderr
