"""Run ``fastsim_node`` from its installed console script and talk to it over DDS.

Every test run gets its own DDS domain (``ROS_DOMAIN_ID`` from the process id)
limited to this machine (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``), set
before any context is initialised, so parallel runs and other ROS graphs
never see each other.  The test side uses its own rclpy context.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

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
DOMAIN_ID = str(1 + os.getpid() % 200)
os.environ["ROS_DOMAIN_ID"] = DOMAIN_ID
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"


def stamp_ns(msg) -> int:
    """Return a message's header stamp in ns."""
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


class NodeProcess:
    """``fastsim_node`` in a subprocess, with its output collected."""

    def __init__(self, *ros_args: str, log_dir: Path) -> None:
        self.log = log_dir / "node.log"
        self._out = open(self.log, "w")
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        self.proc = subprocess.Popen([str(NODE_SCRIPT), "--ros-args", *ros_args],
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


class Client:
    """A test node: publishes twists and patches, collects wrenches and diagnostics."""

    def __init__(self, contacts: tuple[str, ...], name: str = "test_client") -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = Node(name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        reliable = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
        self.wrenches: dict[str, list[WrenchStamped]] = {c: [] for c in contacts}
        self.wheelset: list[WrenchStamped] = []
        self.diagnostics: list[DiagnosticArray] = []
        self.twist = self.node.create_publisher(TwistStamped, "wheelset/twist", reliable)
        self.rail = self.node.create_publisher(TwistStamped, "rail/twist", reliable)
        self.patch = {c: self.node.create_publisher(PointCloud2, f"contact/{c}/patch", reliable)
                      for c in contacts}
        for c in contacts:
            self.node.create_subscription(WrenchStamped, f"contact/{c}/wrench",
                                          self.wrenches[c].append, reliable)
        self.node.create_subscription(WrenchStamped, "wheelset/wrench", self.wheelset.append,
                                      reliable)
        self.node.create_subscription(DiagnosticArray, "/diagnostics",
                                      self.diagnostics.append, reliable)
        self.set_client = self.node.create_client(SetParameters, "/fastsim/set_parameters")
        self.get_client = self.node.create_client(GetParameters, "/fastsim/get_parameters")

    def spin(self, seconds: float) -> None:
        """Process callbacks for ``seconds``."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.01)

    def wait_for(self, condition, timeout: float = 10.0) -> bool:
        """Spin until ``condition()`` holds; return whether it did."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if condition():
                return True
            self.executor.spin_once(timeout_sec=0.01)
        return bool(condition())

    def wait_connected(self, proc: NodeProcess, timeout: float = 20.0) -> None:
        """Wait until the node's subscriptions and publishers matched ours."""
        def ready():
            if proc.proc.poll() is not None:
                raise AssertionError("fastsim_node exited:\n" + proc.output())
            subs = all(p.get_subscription_count() > 0 for p in self.patch.values())
            return subs and self.twist.get_subscription_count() > 0 and all(
                self.node.count_publishers(f"/contact/{c}/wrench") > 0 for c in self.patch)
        assert self.wait_for(ready, timeout), "fastsim_node did not connect:\n" + \
            proc.output()
        self.spin(0.2)

    def set_parameters(self, **values):
        """Call the node's set_parameters; return the results."""
        assert self.set_client.wait_for_service(timeout_sec=10.0)
        req = SetParameters.Request()
        req.parameters = [Parameter(k, value=v).to_parameter_msg() for k, v in values.items()]
        future = self.set_client.call_async(req)
        assert self.wait_for(future.done, 10.0)
        return future.result().results

    def get_parameter(self, name: str):
        """Return the node's current value of a parameter."""
        assert self.get_client.wait_for_service(timeout_sec=10.0)
        future = self.get_client.call_async(GetParameters.Request(names=[name]))
        assert self.wait_for(future.done, 10.0)
        return Parameter.from_parameter_msg(
            rcl_param(name, future.result().values[0])).value

    def diagnostic_values(self, contact: str) -> dict[str, str]:
        """Return the key-values of the latest status of ``fastsim: <contact>``."""
        for array in reversed(self.diagnostics):
            for status in array.status:
                if status.name == f"fastsim: {contact}":
                    return {kv.key: kv.value for kv in status.values}
        return {}

    def close(self) -> None:
        """Destroy the node and shut the context down."""
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.shutdown(context=self.context)


def rcl_param(name, value):
    """Return an ``rcl_interfaces/Parameter`` message of a name and a ParameterValue."""
    from rcl_interfaces.msg import Parameter as ParameterMsg
    return ParameterMsg(name=name, value=value)
