"""Run ``fastsim_node`` from its installed console script and talk to it over DDS.

Every test run gets its own DDS domain (``ROS_DOMAIN_ID`` from the process id)
limited to this machine (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``), set
before any context is initialised, so parallel runs and other ROS graphs
never see each other.  The test side uses its own rclpy context.

Nothing here waits for a time to pass: every wait is on a condition.  A DDS
message sent before its topic matched on *both* sides is lost (the writer
sends to the readers it matched; a reader drops data of a writer it has not
matched yet), and the two sides match independently.  So
:meth:`Client.wait_connected` waits until every topic the client publishes
or reads has matched on the client's side (its own counts) and on the
node's side (the ``publishers/<topic>`` and ``subscribers/<topic>`` counts
the node reports in ``/diagnostics``); and :meth:`Client.send_twist` and
:meth:`Client.send_patch` return once the node's diagnostics count the
message handled, so that a patch never overtakes the twist it needs (two
topics carry no order between them).
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import TwistStamped, WrenchStamped
from rcl_interfaces.srv import GetParameters, SetParameters
from sensor_msgs.msg import PointCloud2

PACKAGE_ROOT = Path(__file__).resolve().parents[1]
NODE_SCRIPT = PACKAGE_ROOT / "install" / "fastsim_ros" / "lib" / "fastsim_ros" / "fastsim_node"
LIFECYCLE_SCRIPT = NODE_SCRIPT.with_name("fastsim_lifecycle_node")
DOMAIN_ID = str(1 + os.getpid() % 200)
os.environ["ROS_DOMAIN_ID"] = DOMAIN_ID
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
#: the node's diagnostics period in tests (s): how quickly its counts are seen
DIAGNOSTICS_PERIOD = 0.05
#: every twist count of the node's diagnostics (taken, or dropped by reason)
TWIST_KEYS = ("twists/wheel", "twists/rail", "twists/nonfinite", "twists/wrong_frame",
              "twists/old_stamp", "twists/malformed")


def stamp_ns(msg) -> int:
    """Return a message's header stamp in ns."""
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


class NodeProcess:
    """``fastsim_node`` in a subprocess, with its output collected.

    ``diagnostics_period`` is passed last (it overrides a params file), so
    that the client sees the node's counts within a fraction of a second.
    """

    def __init__(self, *ros_args: str, log_dir: Path,
                 diagnostics_period: float = DIAGNOSTICS_PERIOD,
                 script: Path = NODE_SCRIPT) -> None:
        self.log = log_dir / "node.log"
        self._out = open(self.log, "w")
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        self.proc = subprocess.Popen(
            [str(script), "--ros-args", *ros_args,
             "-p", f"diagnostics_period:={diagnostics_period}"],
            stdout=self._out, stderr=subprocess.STDOUT, env=env)

    def output(self) -> str:
        """Return what the node printed so far."""
        if not self._out.closed:
            self._out.flush()
        return self.log.read_text()

    def stop(self, sig: int = signal.SIGTERM, timeout: float = 10.0) -> int:
        """Send ``sig`` and return the exit status."""
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            return self.proc.wait(timeout)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()
            self._out.close()


def _relative(topic: str) -> str:
    """Return a topic of the root namespace as the node names it (no leading slash)."""
    return topic[1:] if topic.startswith("/") else topic


class Client:
    """A test node: publishes twists and patches, collects wrenches and diagnostics.

    Every publisher and subscription is made through :meth:`publisher` and
    :meth:`subscribe` (reliable, depth 1000: nothing a test sends or awaits
    is pushed out of a history), so that :meth:`wait_connected` knows them all.
    """

    def __init__(self, contacts: tuple[str, ...], name: str = "test_client", *,
                 patches: bool = True) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = Node(name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        self._publishers: list[tuple[str, Any]] = []
        self._subscriptions: list[tuple[str, Any]] = []
        self.twist = self.publisher(TwistStamped, "wheelset/twist")
        self.rail = self.publisher(TwistStamped, "rail/twist")
        # patches: this client publishes them (topics mode); profiles mode computes them
        self.patch = ({c: self.publisher(PointCloud2, f"contact/{c}/patch") for c in contacts}
                      if patches else {})
        self.wrenches: dict[str, list[WrenchStamped]] = {
            c: self.subscribe(WrenchStamped, f"contact/{c}/wrench") for c in contacts}
        self.wheelset: list[WrenchStamped] = self.subscribe(WrenchStamped, "wheelset/wrench")
        self.diagnostics: list[DiagnosticArray] = self.subscribe(DiagnosticArray,
                                                                 "/diagnostics")
        self.set_client = self.node.create_client(SetParameters, "/fastsim/set_parameters")
        self.get_client = self.node.create_client(GetParameters, "/fastsim/get_parameters")
        self._twists_sent = 0
        self._patches_sent = {c: 0 for c in contacts}

    def publisher(self, msgtype: Any, topic: str) -> Any:
        """Return a publisher on ``topic`` that :meth:`wait_connected` waits for."""
        pub = self.node.create_publisher(msgtype, topic, self.qos)
        self._publishers.append((_relative(topic), pub))
        return pub

    def subscribe(self, msgtype: Any, topic: str) -> list[Any]:
        """Subscribe to ``topic``; return the list its messages are appended to."""
        received: list[Any] = []
        sub = self.node.create_subscription(msgtype, topic, received.append, self.qos)
        self._subscriptions.append((_relative(topic), sub))
        return received

    def spin(self, seconds: float) -> None:
        """Process callbacks for ``seconds`` (for benchmarks and demos, not for waiting)."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.01)

    def wait_for(self, condition: Callable[[], Any], timeout: float = 10.0) -> bool:
        """Spin until ``condition()`` holds; return whether it did."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if condition():
                return True
            self.executor.spin_once(timeout_sec=0.01)
        return bool(condition())

    # ------------------------------------------------------------ the node's view

    def node_values(self) -> dict[str, str]:
        """Return the key-values of every status of the latest diagnostics, merged.

        The keys of the statuses are the same, or per contact (its counts
        are read through :meth:`diagnostic_values`); connections are keyed by topic.
        """
        if not self.diagnostics:
            return {}
        return {kv.key: kv.value for status in self.diagnostics[-1].status
                for kv in status.values}

    def diagnostic_values(self, contact: str) -> dict[str, str]:
        """Return the key-values of the latest status of ``fastsim: <contact>``."""
        for array in reversed(self.diagnostics):
            for status in array.status:
                if status.name == f"fastsim: {contact}":
                    return {kv.key: kv.value for kv in status.values}
        return {}

    def _unmatched(self) -> list[str]:
        """Return what has not matched yet on either side (empty: all has)."""
        missing = [f"our publisher of {t}" for t, p in self._publishers
                   if p.get_subscription_count() < 1]
        missing += [f"our subscription to {t}" for t, s in self._subscriptions
                    if s.get_publisher_count() < 1]
        if not self.diagnostics:
            return missing + ["no /diagnostics received"]
        seen = self.node_values()
        for kind, mine in (("publishers", self._publishers),
                           ("subscribers", self._subscriptions)):
            for topic in {t for t, _ in mine if t != "diagnostics"}:
                ours = sum(t == topic for t, _ in mine)
                if int(seen.get(f"{kind}/{topic}", "0")) < ours:
                    missing.append(f"the node's {kind} of {topic}: "
                                   f"{seen.get(f'{kind}/{topic}')} (ours {ours})")
        return missing

    def wait_connected(self, proc: NodeProcess, timeout: float = 30.0) -> None:
        """Wait until every topic of this client matched on both sides (see the module)."""
        def ready() -> bool:
            if proc.proc.poll() is not None:
                raise AssertionError("fastsim_node exited:\n" + proc.output())
            return not self._unmatched()
        assert self.wait_for(ready, timeout), (
            f"fastsim_node did not connect: {self._unmatched()}\n" + proc.output())

    def _twists_handled(self) -> int:
        values = self.node_values()
        return sum(int(values.get(key, "0")) for key in TWIST_KEYS)

    def wait_twists_handled(self, count: int, timeout: float = 10.0) -> None:
        """Wait until the node's diagnostics count ``count`` twists (taken or dropped)."""
        assert self.wait_for(lambda: self._twists_handled() >= count, timeout), (
            f"the node handled {self._twists_handled()} of {count} twists")

    def send_twist(self, msg: TwistStamped, rail: bool = False) -> None:
        """Publish a twist and return once the node has handled it."""
        (self.rail if rail else self.twist).publish(msg)
        self._twists_sent += 1
        self.wait_twists_handled(self._twists_sent)

    def _patch_counts(self, contact: str) -> dict[str, int]:
        values = self.diagnostic_values(contact)
        return {k: int(v) for k, v in values.items()
                if k in ("wrenches", "rejected") or k.startswith("rejected/")}

    def send_patch(self, contact: str, msg: PointCloud2, timeout: float = 10.0) -> str:
        """Publish a patch; once the node counted it, return ``"wrench"`` or its rejection.

        A rejection is the reason key whose count went up.  With a wrench,
        this also waits until the wrench (same stamp) has arrived.
        """
        before = self._patch_counts(contact)  # holds the patches before: each was awaited
        self.patch[contact].publish(msg)
        self._patches_sent[contact] += 1
        sent = self._patches_sent[contact]

        def handled() -> bool:
            now = self._patch_counts(contact)
            return now.get("wrenches", 0) + now.get("rejected", 0) >= sent
        assert self.wait_for(handled, timeout), f"{contact}: the node did not count patch {sent}"
        after = self._patch_counts(contact)
        if after["wrenches"] > before.get("wrenches", 0):
            stamp = stamp_ns(msg)
            assert self.wait_for(lambda: any(stamp_ns(w) == stamp
                                             for w in self.wrenches[contact]), timeout), (
                f"{contact}: the node counted a wrench that did not arrive")
            return "wrench"
        grown = [k[len("rejected/"):] for k, v in after.items()
                 if k.startswith("rejected/") and v > before.get(k, 0)]
        assert len(grown) == 1, f"{contact}: counts before {before}, after {after}"
        return grown[0]

    def poses_handled(self) -> int:
        """Return how many poses the node has counted (taken, or dropped by reason)."""
        values = self.node_values()
        return sum(int(values.get(f"poses/{k}", "0"))
                   for k in ("pose", "malformed", "wrong_frame", "nonfinite", "old_stamp"))

    def send_pose(self, publisher: Any, msg: Any, contacts: tuple[str, ...],
                  timeout: float = 60.0) -> dict[str, list[WrenchStamped]]:
        """Publish a pose (profiles mode); once the node counted it, return its wrenches.

        Waits for the count, then for a wrench of the pose's stamp on every
        contact of ``contacts`` that the node served (a pose dropped whole has none).
        """
        before = self.poses_handled()
        publisher.publish(msg)
        assert self.wait_for(lambda: self.poses_handled() > before, timeout), (
            f"the node did not count the pose (it counted {self.poses_handled()})")
        stamp = stamp_ns(msg)
        # the diagnostics that counted the pose count its wrenches too: wait for them all
        counted = {c: int(self.diagnostic_values(c).get("wrenches", "0")) for c in contacts}
        assert self.wait_for(lambda: all(len(self.wrenches[c]) >= counted[c]
                                         for c in contacts), timeout), (
            f"wrenches counted {counted}, arrived "
            f"{ {c: len(self.wrenches[c]) for c in contacts} }")
        return {c: [w for w in self.wrenches[c] if stamp_ns(w) == stamp] for c in contacts}

    def call(self, client: Any, request: Any, timeout: float = 20.0) -> Any:
        """Call a service of the node (an idempotent one) and return the response.

        ``wait_for_service`` sees the match on this side only: a request
        sent before the node's side matched is lost, so a call unanswered
        for a while is sent again (the parameter services are idempotent).
        """
        assert client.wait_for_service(timeout_sec=timeout), client.service_name
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            future = client.call_async(request)
            if self.wait_for(future.done, min(2.0, end - time.monotonic())):
                return future.result()
            client.remove_pending_request(future)
        raise AssertionError(f"no answer from {client.service_name} in {timeout} s")

    def set_parameters(self, **values):
        """Call the node's set_parameters; return the results."""
        req = SetParameters.Request()
        req.parameters = [Parameter(k, value=v).to_parameter_msg() for k, v in values.items()]
        return self.call(self.set_client, req).results

    def get_parameter(self, name: str):
        """Return the node's current value of a parameter."""
        response = self.call(self.get_client, GetParameters.Request(names=[name]))
        return Parameter.from_parameter_msg(rcl_param(name, response.values[0])).value

    def close(self) -> None:
        """Destroy the node and shut the context down."""
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.shutdown(context=self.context)


def rcl_param(name, value):
    """Return an ``rcl_interfaces/Parameter`` message of a name and a ParameterValue."""
    from rcl_interfaces.msg import Parameter as ParameterMsg
    return ParameterMsg(name=name, value=value)
