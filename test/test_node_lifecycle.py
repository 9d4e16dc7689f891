"""fastsim_lifecycle_node over real DDS: every transition driven through lifecycle_msgs.

The managed node is started from its installed script; a client drives it
through ``/fastsim/change_state`` and reads ``/fastsim/get_state``, and checks
what is published in each state: nothing while ``unconfigured`` or
``inactive`` (inputs dropped and counted), the library's wrenches while
``active``; ``cleanup`` releases the topics, start-only parameters may change
while ``unconfigured``, a bad value fails ``configure`` with one line and
leaves the node ``unconfigured``; ``shutdown`` finalizes it and ends its process.
"""

from __future__ import annotations

import time

import pytest

from lifecycle_msgs.msg import State, Transition
from lifecycle_msgs.srv import ChangeState, GetState

from fastsim_ros.contact import area as areas
from fastsim_ros.contact.compiled import CalibratedMaeSolver
from ros_harness import LIFECYCLE_SCRIPT, Client, NodeProcess, stamp_ns
from ros_messages import WHEEL_RADIUS as R
from ros_messages import cloud_msg, in_plane_area, rolling_twist

MS = 1_000_000
T0 = 1_700_000_000 * 1_000_000_000
XI = 1.5e-3

pytestmark = pytest.mark.skipif(not LIFECYCLE_SCRIPT.exists(),
                                reason="fastsim_lifecycle_node is not installed")


class Managed:
    """The lifecycle services of the node, called from the test client."""

    def __init__(self, client: Client) -> None:
        self.client = client
        self.change = client.node.create_client(ChangeState, "/fastsim/change_state")
        self.get = client.node.create_client(GetState, "/fastsim/get_state")

    def state(self) -> int:
        """Return the node's primary state id (get_state is idempotent: resent if lost)."""
        return self.client.call(self.get, GetState.Request()).current_state.id

    def transition(self, transition: int, timeout: float = 60.0) -> bool:
        """Ask for a transition once; return whether it succeeded.

        change_state is not idempotent, so a request is never resent: a
        get_state answer first shows the node's services are up, and the
        answer to this one is awaited for as long as a configure may take.
        """
        self.state()
        assert self.change.wait_for_service(timeout_sec=20.0)
        request = ChangeState.Request()
        request.transition.id = transition
        future = self.change.call_async(request)
        assert self.client.wait_for(future.done, timeout), f"no answer to {transition}"
        return bool(future.result().success)


def ellipse():
    return areas.ellipse(6e-3, 4e-3, nx=20, ny=20).with_load(5e4)


def library(area):
    a = in_plane_area(area)
    return CalibratedMaeSolver(0.28, 8e10).solve_arrays(a.pressure, a.x0, a.y0, a.dx, a.dy,
                                                        XI, 0.0, 0.0, 0.3)


def patch(stamp):
    return cloud_msg(ellipse(), origin=(0.0, 0.75, -R), stamp_ns=stamp, dtype="<f8")


def wrenches_of(client, contact, stamp):
    return [w for w in client.wrenches[contact] if stamp_ns(w) == stamp]


def publishers_of(client, topic):
    return client.node.count_publishers(topic)


@pytest.fixture
def managed(tmp_path):
    started = []

    def start(*ros_args, contacts=("left", "right")):
        proc = NodeProcess(*ros_args, log_dir=tmp_path, script=LIFECYCLE_SCRIPT)
        client = Client(tuple(contacts))
        started.append((proc, client))
        return proc, client, Managed(client)

    yield start
    for proc, client in started:
        client.close()
        proc.stop()


def test_every_transition_publishes_what_its_state_allows(managed):
    proc, client, node = managed()
    assert node.state() == State.PRIMARY_STATE_UNCONFIGURED
    # unconfigured: the node has no topics at all
    assert publishers_of(client, "/contact/left/wrench") == 0
    assert publishers_of(client, "/diagnostics") == 0

    assert node.transition(Transition.TRANSITION_CONFIGURE)
    assert node.state() == State.PRIMARY_STATE_INACTIVE
    # configured, not active: the pipeline is built, still nothing published
    client.spin(0.3)
    assert publishers_of(client, "/contact/left/wrench") == 0
    assert client.diagnostics == []

    assert node.transition(Transition.TRANSITION_ACTIVATE)
    assert node.state() == State.PRIMARY_STATE_ACTIVE
    client.wait_connected(proc)
    client.send_twist(rolling_twist(XI, stamp_ns=T0))
    stamp = T0 + MS
    assert client.send_patch("left", patch(stamp)) == "wrench"
    (w,) = wrenches_of(client, "left", stamp)
    ref = library(ellipse())
    assert (w.wrench.force.x, w.wrench.force.y, w.wrench.force.z) == pytest.approx(
        (ref.fx, ref.fy, ref.n), rel=1e-9)

    # inactive: inputs are dropped and counted, nothing goes out, not even diagnostics
    assert node.transition(Transition.TRANSITION_DEACTIVATE)
    assert node.state() == State.PRIMARY_STATE_INACTIVE
    # diagnostics already in flight arrive: wait for a quiet half second (a loaded
    # machine delivers them late; a fixed 0.3 s once let one arrive after it)
    seen = -1
    for _ in range(20):
        if len(client.diagnostics) == seen:
            break
        seen = len(client.diagnostics)
        client.spin(0.5)
    dropped_stamp = T0 + 2 * MS
    client.twist.publish(rolling_twist(XI, stamp_ns=dropped_stamp))
    client.patch["left"].publish(patch(dropped_stamp))
    client.spin(0.5)
    assert len(client.diagnostics) == seen
    assert wrenches_of(client, "left", dropped_stamp) == []

    # active again: the drops are counted, and the next input is served
    assert node.transition(Transition.TRANSITION_ACTIVATE)
    assert client.wait_for(lambda: client.diagnostic_values("left").get(
        "dropped/inactive") == "2"), client.diagnostic_values("left")
    assert wrenches_of(client, "left", dropped_stamp) == []
    client.send_twist(rolling_twist(XI, stamp_ns=T0 + 3 * MS))
    assert client.send_patch("left", patch(T0 + 4 * MS)) == "wrench"

    # cleanup releases every topic; a start-only parameter may change while unconfigured
    assert node.transition(Transition.TRANSITION_DEACTIVATE)
    assert node.transition(Transition.TRANSITION_CLEANUP)
    assert node.state() == State.PRIMARY_STATE_UNCONFIGURED
    assert client.wait_for(lambda: publishers_of(client, "/contact/left/wrench") == 0)
    (result,) = client.set_parameters(contacts=["wheel"])
    assert result.successful, result.reason
    assert node.transition(Transition.TRANSITION_CONFIGURE)
    assert node.transition(Transition.TRANSITION_ACTIVATE)
    assert client.wait_for(lambda: publishers_of(client, "/contact/wheel/wrench") == 1)
    assert publishers_of(client, "/contact/left/wrench") == 0
    # configured: a start-only parameter is refused, a dynamic one taken
    (result,) = client.set_parameters(contacts=["left"])
    assert not result.successful and "start only" in result.reason
    (result,) = client.set_parameters(friction_coefficient=0.4)
    assert result.successful, result.reason

    # shutdown finalizes the node, and its process ends
    assert node.transition(Transition.TRANSITION_ACTIVE_SHUTDOWN)
    assert client.wait_for(lambda: publishers_of(client, "/contact/wheel/wrench") == 0)
    assert proc.proc.wait(timeout=30.0) == 0, proc.output()


def test_a_bad_value_fails_configure_and_the_node_stays_unconfigured(managed):
    proc, client, node = managed("-p", "patch_source:=profiles",
                                 "-p", "wheel_profile:=/nonexistent/wheel.prw",
                                 contacts=("left", "right", "left_flange", "right_flange"))
    assert not node.transition(Transition.TRANSITION_CONFIGURE)
    assert node.state() == State.PRIMARY_STATE_UNCONFIGURED
    deadline = time.monotonic() + 10.0
    while "configure failed" not in proc.output() and time.monotonic() < deadline:
        client.spin(0.1)
    failed = [line for line in proc.output().splitlines() if "configure failed" in line]
    assert len(failed) == 1 and "'wheel_profile'" in failed[0], proc.output()
    # mended while unconfigured: the shipped profile by its bare name, then it configures
    (result,) = client.set_parameters(wheel_profile="S1002.prw")
    assert result.successful, result.reason
    assert node.transition(Transition.TRANSITION_CONFIGURE)
    assert node.state() == State.PRIMARY_STATE_INACTIVE
    assert proc.proc.poll() is None


def test_the_managed_node_says_it_started_and_exits_0_after_shutdown(managed):
    """A start line in the log; ``shutdown`` from ``unconfigured`` ends the process, exit 0.

    The launch's parameters are checked as the plain node's: a typo is a
    warning naming the nearest parameter, and the node starts.
    """
    proc, client, node = managed("-p", "friction_coeficient:=0.4")
    assert node.state() == State.PRIMARY_STATE_UNCONFIGURED  # answered: it has started
    out = proc.output()
    assert ("managed node /fastsim unconfigured: configure, then activate it through "
            "/fastsim/change_state (lifecycle_msgs); shutdown ends the process") in out, out
    assert ("unknown parameter 'friction_coeficient'; did you mean 'friction_coefficient'?"
            in out), out
    assert node.transition(Transition.TRANSITION_UNCONFIGURED_SHUTDOWN)
    assert proc.proc.wait(timeout=30.0) == 0, proc.output()
    out = proc.output()
    assert "finalized: exiting" in out
    for mark in ("Traceback", "FATAL", "ERROR"):
        assert mark not in out, out
