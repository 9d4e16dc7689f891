"""``bench_node.py --profiles``: the node in profiles mode over DDS, beside topics mode.

the target: the node in profiles mode, one wheelset, poses and twists at 1
kHz: no drop, at most one core.  The node runs from its installed console
script with ``config/profiles_track_table.yaml`` (the contact table, read
from its cache: ``scripts/validate_table.py`` or a first start builds it) in
its own DDS domain; this driver publishes ``wheelset/twist`` and
``wheelset/pose`` at ``rate`` Hz (pre-serialised CDR, stamp patched in), the
pose swaying over the treads (lateral shift 3 mm and yaw 4 mrad in
amplitude, 0.5 Hz and 0.3 Hz, so that no two poses are alike and the
table blends between nodes every cycle), and takes both wheels' wrenches
raw.  A pose is answered when its left wheel's wrench arrives: latency is
pose published -> that wrench received.  Then, in the same run, the node in
topics mode with two 30 x 30-cell patches per cycle (``bench_node.run``),
the load of a rig whose patches come from elsewhere.
"""

from __future__ import annotations

import math
import signal
import subprocess
import time
from pathlib import Path
from typing import Any

import numpy as np
from rclpy.qos import QoSProfile, ReliabilityPolicy

from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
from rclpy.serialization import serialize_message

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "profiles_track_table.yaml"


def pose_cdr(dy: float, yaw: float) -> bytearray:
    """Return the CDR of a ``wheelset/pose`` in the track frame (shift ``dy``, yaw ``yaw``)."""
    m = PoseStamped()
    m.header.frame_id = "track"
    m.pose.position.y = dy
    m.pose.orientation.z = math.sin(0.5 * yaw)
    m.pose.orientation.w = math.cos(0.5 * yaw)
    return bytearray(serialize_message(m))


def run_profiles(bench: Any, rate: float, seconds: float,
                 node_args: list[str]) -> dict[str, float]:
    """Drive the node in profiles mode at ``rate`` poses per second; print and return figures.

    ``bench``: the ``bench_node`` module (its driver, stamps, CPU reading).
    """
    proc = subprocess.Popen([str(bench.NODE), "--ros-args", "--params-file", str(CONFIG),
                             *node_args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    ctx, node, ex = bench.driver("bench_profiles")
    qos = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
    sent: dict[int, float] = {}
    latency: list[float] = []
    answered = [0, 0]

    def on_wrench(k: int) -> Any:
        def callback(raw: bytes) -> None:
            now = time.perf_counter()
            sec, nanosec = bench._STAMP.unpack_from(raw, 4)
            stamp = sec * 1_000_000_000 + nanosec
            answered[k] += 1
            if k == 0:
                t = sent.pop(stamp, None)
                if t is not None:
                    latency.append(now - t)
        return callback

    pose_pub = node.create_publisher(PoseStamped, "wheelset/pose", qos)
    twist_pub = node.create_publisher(TwistStamped, "wheelset/twist", qos)
    subs = [node.create_subscription(WrenchStamped, f"contact/{side}/wrench", on_wrench(k), qos,
                                     raw=True) for k, side in enumerate(("left", "right"))]
    # poses precomputed (the driver's own cost stays out of the node's figures)
    period = 1.0 / rate
    n = int(seconds * rate) + 1
    t = np.arange(n) * period
    dys = 3e-3 * np.sin(2 * math.pi * 0.5 * t)
    yaws = 4e-3 * np.sin(2 * math.pi * 0.3 * t + 0.4)
    poses = [pose_cdr(float(d), float(y)) for d, y in zip(dys, yaws)]
    twist = bench.twist_cdr(xi=0.0, speed=2.0)
    start = time.monotonic()
    while not (pose_pub.get_subscription_count() and twist_pub.get_subscription_count()
               and all(s.get_publisher_count() for s in subs)):
        ex.spin_once(timeout_sec=0.05)
        if time.monotonic() - start > 120 or proc.poll() is not None:
            raise SystemExit("the node in profiles mode did not come up (is the table "
                             "cached? scripts/validate_table.py builds it)")
    for _ in range(50):
        ex.spin_once(timeout_sec=0.01)
    cpu0, wall0 = bench.cpu_seconds(proc.pid), time.perf_counter()
    t_next = wall0
    stamp = 1_700_000_000 * 1_000_000_000
    inputs = late = 0
    while inputs < n:
        now = time.perf_counter()
        if now >= t_next:
            stamp += round(period * 1e9)
            twist_pub.publish(bench.set_stamp(twist, stamp - 1000))
            sent[stamp] = time.perf_counter()
            pose_pub.publish(bench.set_stamp(poses[inputs], stamp))
            inputs += 1
            t_next += period
            if now - t_next > 10 * period:
                late += 1
                t_next = now + period
        ex.spin_once(timeout_sec=max(0.0, min(t_next - time.perf_counter(), period)))
    wall = time.perf_counter() - wall0
    cpu = bench.cpu_seconds(proc.pid) - cpu0
    drain = time.perf_counter()
    while time.perf_counter() - drain < 1.0:
        ex.spin_once(timeout_sec=0.01)
    proc.send_signal(signal.SIGTERM)
    status = proc.wait(10)
    node.destroy_node()
    import rclpy
    rclpy.shutdown(context=ctx)
    lat = np.array(latency) * 1e3 if latency else np.array([np.nan])
    figures = {"received": 100.0 * answered[0] / inputs, "p50": float(np.median(lat)),
               "p99": float(np.percentile(lat, 99)), "cpu": 100.0 * cpu / wall,
               "late": float(late)}
    print(f"profiles (table): 1 wheelset x {rate:g} Hz poses for {wall:.1f} s: sent {inputs} "
          f"poses, answered {answered[0]} left / {answered[1]} right "
          f"({100.0 - figures['received']:.2f}% dropped), latency p50 {figures['p50']:.3f} ms, "
          f"p99 {figures['p99']:.3f} ms, max {lat.max():.3f} ms; node CPU "
          f"{figures['cpu']:.0f}% of one core; driver re-anchored {late} times; exit {status}",
          flush=True)
    return figures


def side_by_side(bench: Any, rate: float, seconds: float, rounds: int,
                 node_args: list[str]) -> None:
    """Profiles mode and topics mode (two patches a cycle) alternately; print the medians."""
    import statistics
    runs: dict[str, list[dict[str, float]]] = {"profiles": [], "topics": []}
    for r in range(rounds):
        order = ("profiles", "topics") if r % 2 == 0 else ("topics", "profiles")
        for mode in order:
            if mode == "profiles":
                runs[mode].append(run_profiles(bench, rate, seconds, node_args))
            else:
                runs[mode].append(bench.run(2, rate, seconds, 0.0, "events", node_args))
    print(f"medians of {rounds} alternating runs, {rate:g} Hz, {seconds:g} s each:")
    for mode, figs in runs.items():
        med = {k: statistics.median(f[k] for f in figs) for k in ("received", "p50", "p99",
                                                                  "cpu")}
        print(f"  {mode:8s} received {med['received']:.2f}%, latency p50 {med['p50']:.3f} ms, "
              f"p99 {med['p99']:.3f} ms, CPU {med['cpu']:.0f}% of one core", flush=True)
    print("  the target, profiles mode: no drop, at most one core (100%)")
