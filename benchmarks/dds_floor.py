"""The DDS floor: a relay that answers each raw patch with a fixed wrench (rclpy + Fast DDS only).

What ``fastsim_node`` cannot go below on this stack: the same topics, QoS,
executor and process shape as the node (subscriptions best effort, the
wrench publishers reliable, depth 10; rclpy's events executor in a
``spin_once`` loop; the twist taken too), but no work: each patch's stamp
is copied into a pre-serialised ``WrenchStamped`` of that contact, which is
published as bytes.  ``bench_node.py --floor`` drives it alternately with
the node and prints node/floor ratios.

``--fair``: the fair floor.  Each patch is answered with the messages the
node publishes per patch when they have subscribers (docs/guide_node.md's
outputs): the contact's ``WrenchStamped`` and its ``Vector3Stamped``
creepage, and once per rig cycle (every contact answered a patch of a
newer stamp than the last sum's, the node's rule) the ``wheelset/wrench``;
each pre-serialised, stamp copied in, published as bytes.  The floor
without the flag, the one-message floor, publishes the wrench alone.

``--solve``: the relay also runs the node's MAE solve (``MaeSolver.solve_arrays``)
on one fixed, already converted 30 x 30-cell patch for every patch it
answers: the least any node that solves each patch costs on this stack
(``bench_node.py --floor N --bound`` drives it beside the node and the floor).

    .venv/bin/python benchmarks/dds_floor.py --contacts c0 c1 c2 c3
"""

from __future__ import annotations

import argparse
import struct
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import serialize_message

from geometry_msgs.msg import TwistStamped, Vector3Stamped, WrenchStamped
from sensor_msgs.msg import PointCloud2

#: a header stamp (int32 sec, uint32 nanosec) sits at bytes 4..12 of a little-endian
#: CDR message: right after the encapsulation header, first in std_msgs/Header
STAMP = slice(4, 12)
_STAMP = struct.Struct("<iI")
#: before any stamp (ns): older than every stamp
_NONE = -(1 << 62)


class Floor(Node):
    """Answer ``contact/<name>/patch`` with a fixed ``contact/<name>/wrench``, stamp copied."""

    def __init__(self, contacts: Sequence[str], depth: int = 10,
                 solve: Callable[[bytes], object] | None = None, fair: bool = False) -> None:
        super().__init__("fastsim_floor")
        self._solve = solve
        qos_in = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth,
                            reliability=ReliabilityPolicy.BEST_EFFORT)
        qos_out = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth,
                             reliability=ReliabilityPolicy.RELIABLE)
        self.create_subscription(TwistStamped, "wheelset/twist", self._on_twist, qos_in,
                                 raw=True)
        cycle = None
        if fair:
            total = WrenchStamped()
            total.header.frame_id = "wheelset"
            total.wrench.force.x = -1000.0 * len(contacts)
            total.wrench.force.z = 60000.0 * len(contacts)
            # the rig cycle's state: per contact the newest stamp answered, the last sum's
            cycle = _Cycle(len(contacts), bytearray(serialize_message(total)),
                           self.create_publisher(WrenchStamped, "wheelset/wrench", qos_out))
        for k, name in enumerate(contacts):
            wrench = WrenchStamped()
            wrench.header.frame_id = f"{name}_contact"
            wrench.wrench.force.x, wrench.wrench.force.z = -1000.0, 60000.0
            pub = self.create_publisher(WrenchStamped, f"contact/{name}/wrench", qos_out)
            if cycle is None:
                answer = self._answer(pub, bytearray(serialize_message(wrench)), solve)
            else:
                creepage = Vector3Stamped()
                creepage.header.frame_id = f"{name}_contact"
                creepage.vector.x = 1e-3
                answer = self._answer_fair(
                    k, pub, bytearray(serialize_message(wrench)),
                    self.create_publisher(Vector3Stamped, f"contact/{name}/creepage", qos_out),
                    bytearray(serialize_message(creepage)), cycle, solve)
            self.create_subscription(PointCloud2, f"contact/{name}/patch", answer, qos_in,
                                     raw=True)

    def _on_twist(self, raw: bytes) -> None:
        pass

    @staticmethod
    def _answer(pub, wrench: bytearray,
                solve: Callable[[bytes], object] | None) -> Callable[[bytes], None]:
        if solve is None:
            def callback(raw: bytes) -> None:
                wrench[STAMP] = raw[STAMP]
                pub.publish(bytes(wrench))
            return callback

        def solving(raw: bytes) -> None:
            solve(raw)
            wrench[STAMP] = raw[STAMP]
            pub.publish(bytes(wrench))
        return solving

    @staticmethod
    def _answer_fair(k: int, pub, wrench: bytearray, creepage_pub, creepage: bytearray,
                     cycle: "_Cycle",
                     solve: Callable[[bytes], object] | None) -> Callable[[bytes], None]:
        newest, total = cycle.newest, cycle.total

        def callback(raw: bytes) -> None:
            if solve is not None:
                solve(raw)
            stamp = raw[STAMP]
            wrench[STAMP] = stamp
            pub.publish(bytes(wrench))
            creepage[STAMP] = stamp
            creepage_pub.publish(bytes(creepage))
            # the rig cycle (the pipeline's rule): every contact newer than the last sum
            sec, nanosec = _STAMP.unpack(stamp)
            newest[k] = sec * 1_000_000_000 + nanosec
            last = cycle.last_sum
            if min(newest) > last:
                cycle.last_sum = max(newest)
                total[STAMP] = _STAMP.pack(*divmod(cycle.last_sum, 1_000_000_000))
                cycle.pub.publish(bytes(total))
        return callback


class _Cycle:
    """The fair floor's rig cycle: each contact's newest stamp (ns), the last sum's, the sum."""

    def __init__(self, n: int, total: bytearray, pub) -> None:
        self.newest = [_NONE] * n
        self.last_sum = _NONE
        self.total = total
        self.pub = pub


def fixed_solve() -> Callable[[bytes], object]:
    """Return a call of the default solve (mae_calibrated) on a fixed 30 x 30-cell patch."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from fastsim_ros.contact import compiled, samples
    compiled.warm_up()
    area = samples.semi_ellipses_patch(0.5, 2.0, cells=30, scale=8e-3, load=6e4)
    solver = compiled.CalibratedMaeSolver(0.28, 8.0e10)  # the default method
    pressure = np.ascontiguousarray(area.pressure, dtype=np.float64)

    def solve(raw: bytes) -> object:
        return solver.solve_arrays(pressure, area.x0, area.y0, area.dx, area.dy, 1e-3, 0.0,
                                   0.0, 0.3, bound="given", tractions=False, friction=None,
                                   speed=20.0)
    return solve


def compiled_path() -> Callable[[bytes], object]:
    """Return the node's one compiled call on each received patch, with nothing around it.

    ``fastsim_ros.pipeline.kernels.solve_cloud`` (the adapter's loop over
    the patch's own points, the creepages, the default method's solve, the
    wheelset wrench) with the node's constant arguments, on a view of the
    received CDR's points (the layout read from the first patch): what a
    node whose whole per-patch path were one compiled call from the bytes
    would cost, less the encoding (the fair floor's templates) and the
    kinematics (a fixed rolling twist, creepage 1e-3 at 20 m/s).
    """
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from fastsim_ros.contact import compiled
    from fastsim_ros.pipeline import Pipeline, PipelineConfig
    from fastsim_ros.pipeline import kernels as fast
    from msg_adapters import cdr
    from msg_adapters import patch as patch_adapter
    from msg_adapters import patch_kernels
    compiled.warm_up()
    patch_adapter.warm_up()
    fast.warm_up()
    # the node's configuration of the compiled call (its defaults)
    pipe = Pipeline(PipelineConfig.from_values({"contacts": ["c"], "publish_markers": False}))
    state = pipe._compiled
    assert state is not None
    speed, xi, radius = 20.0, 1e-3, 0.46
    wheel = np.array([speed, 0.0, 0.0, 0.0, speed * (1 - xi / 2) / (1 + xi / 2) / radius, 0.0])
    rail = np.zeros(6)
    frame = np.empty(patch_kernels.OUT_SIZE)
    result = np.empty(fast.RESULT_SIZE)
    memory = np.zeros(fast.MEMORY_SIZE)  # steady rolling
    min_speed = float(pipe.config["min_rolling_speed"])
    layout: list[tuple[int, np.dtype, int, int, int, int, int, np.ndarray, np.ndarray]] = []

    def solve(raw: bytes) -> object:
        if not layout:  # the topic's layout, read once
            cloud = cdr.CloudReader().read(raw)
            words, row, step, cols = patch_adapter._words(cloud)
            # where the points start in the message (the view's address in the buffer's)
            start = (np.frombuffer(cloud.data, dtype=np.uint8).ctypes.data
                     - np.frombuffer(raw, dtype=np.uint8).ctypes.data)
            layout.append((start, words.dtype, words.size, cloud.height, cloud.width, row,
                           step, cols, np.empty((cloud.height, cloud.width))))
        start, dtype, count, ny, nx, row, step, cols, pressure = layout[0]
        words = np.frombuffer(raw, dtype=dtype, count=count, offset=start)
        return fast.solve_cloud(
            words, ny, nx, row, step, cols, pressure, frame, wheel, rail, min_speed, state.rule,
            state.parabolic, state.shear_modulus, state.knots, state.polys, state.law,
            state.law_parameters, state.mu, state.slip_dependent, state.calibrated,
            state.pair_knots, state.pair_values, False, result, memory, *fast.NO_STATE,
            state.knee)
    return solve


def main(argv: Sequence[str] | None = None) -> int:
    """Relay until SIGINT or SIGTERM."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--contacts", nargs="+", default=["left", "right"])
    parser.add_argument("--depth", type=int, default=10, help="QoS depth (the node's qos_depth)")
    parser.add_argument("--fair", action="store_true",
                        help="publish the node's messages: wrench and creepage per patch, the "
                        "wheelset wrench per rig cycle (the fair floor)")
    parser.add_argument("--solve", action="store_true",
                        help="also run the node's solve on a fixed patch for every patch")
    parser.add_argument("--compiled", action="store_true",
                        help="instead: the node's one compiled call (adapter loop and solve) "
                        "on each received patch")
    args, ros_args = parser.parse_known_args(argv)
    rclpy.init(args=[sys.argv[0], *ros_args])  # its signal handlers end spin_once
    node = None
    try:
        solve = (compiled_path() if args.compiled else fixed_solve() if args.solve
                 else None)
        node = Floor(args.contacts, args.depth, solve, fair=args.fair)
        executor = EventsExecutor()
        executor.add_node(node)
        while rclpy.ok():  # as the node: spin_once, which returns on SIGTERM
            executor.spin_once(timeout_sec=0.25)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
