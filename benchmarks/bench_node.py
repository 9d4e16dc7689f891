"""Benchmark fastsim_node over DDS on loopback: drops, latency, CPU, memory.

The node runs from its installed console script in its own process (its own
DDS domain, localhost only); this driver publishes, for each of ``--contacts``
contacts, a 30 x 30-cell patch at ``--rate`` Hz (pre-serialised CDR with the
stamp patched in, so the driver's own cost stays small) plus the wheelset
twist at the same rate, and collects the wrenches (raw, stamp read from the
bytes).  It prints inputs sent, wrenches received, drops, latency (patch
published -> wrench received, wall clock of this process) p50/p99/max, the
node's CPU share (from /proc), and with ``--soak MINUTES`` the node's
resident memory sampled every 10 s.  ``--profile`` first times the node's
per-message path in this process (decode + adapt + solve + encode, and an
rclpy publish) to show where the time goes; with ``--evict BYTES`` each
patch after that much other memory is read (caches as cold as a node's).
``--floor N`` drives the node and the DDS floors (dds_floor.py) in turn;
``--bound`` adds the fair floor that also solves a fixed patch and the one
that runs the node's compiled call on each patch.

    .venv/bin/python benchmarks/bench_node.py --contacts 2 4 --seconds 20
    .venv/bin/python benchmarks/bench_node.py --contacts 4 --seconds 10 --floor 3 --bound
    .venv/bin/python benchmarks/bench_node.py --profile 3000 --evict 4000000
    .venv/bin/python benchmarks/bench_node.py --contacts 4 --soak 10
    .venv/bin/python benchmarks/bench_node.py --profiles 3 --seconds 10   # profiles mode
"""

from __future__ import annotations

import argparse
import array
import gc
import os
import shlex
import signal
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("ROS_DOMAIN_ID", str(150 + os.getpid() % 50))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"

import rclpy  # noqa: E402
from rclpy.context import Context  # noqa: E402
from rclpy.experimental import EventsExecutor  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.qos import QoSProfile, ReliabilityPolicy  # noqa: E402
from rclpy.serialization import serialize_message  # noqa: E402

from geometry_msgs.msg import TwistStamped, Vector3Stamped, WrenchStamped  # noqa: E402
from sensor_msgs.msg import PointCloud2, PointField  # noqa: E402

from fastsim_ros.contact import samples  # noqa: E402
from bench_fastsim import machine  # noqa: E402  (one machine line for every benchmark)
from msg_adapters import patch as pa  # noqa: E402

NODE = ROOT / "install" / "fastsim_ros" / "lib" / "fastsim_ros" / "fastsim_node"
RADIUS = 0.46
_STAMP = struct.Struct("<iI")

#: how long a target may take to open its topics (s): a cold kernel cache compiles first
START_TIMEOUT = 180.0


def patch_cdr(k: int) -> bytearray:
    """Return the CDR of contact ``k``'s 30 x 30-cell patch (two semi-ellipses, 60 kN)."""
    area = samples.semi_ellipses_patch(0.5, 2.0, cells=30, scale=8e-3, load=6e4)
    frame = pa.frame_from_normal((0.0, 0.0, 1.0))
    pts = pa.planar_points((0.0, 0.75 - 0.5 * k, -RADIUS), frame, area.x0, area.y0, area.dx,
                           area.dy, area.ny, area.nx)
    fields, step, data = pa.cloud_bytes(pts, np.array([0.0, 0.0, 1.0]), area.pressure)
    m = PointCloud2()
    m.header.frame_id = "wheelset"
    m.height, m.width = area.pressure.shape
    m.fields = [PointField(name=n, offset=o, datatype=7, count=1) for n, o in fields]
    m.point_step, m.row_step = step, step * area.nx
    m.data = data
    m.is_dense = True
    return bytearray(serialize_message(m))


def twist_cdr(xi: float = 1e-3, speed: float = 20.0) -> bytearray:
    """Return the CDR of a wheelset twist on track with creepage ``xi``."""
    t = TwistStamped()
    t.header.frame_id = "wheelset"
    t.twist.linear.x = speed
    t.twist.angular.y = speed * (1 - xi / 2) / (1 + xi / 2) / RADIUS
    return bytearray(serialize_message(t))


def set_stamp(buf: bytearray, stamp_ns: int) -> bytes:
    """Write a header stamp into a CDR message (bytes 4..12) and return the bytes."""
    _STAMP.pack_into(buf, 4, *divmod(stamp_ns, 1_000_000_000))
    return bytes(buf)


def cpu_seconds(pid: int) -> float:
    """Return user + system CPU seconds of a process."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def thread_cpu_seconds(pid: int) -> dict[str, float]:
    """Return user + system CPU seconds of a process's threads, summed by thread name.

    Threads of one name (Fast DDS's receive threads, say) are summed; the
    main thread is named after the process.
    """
    out: dict[str, float] = {}
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            text = (task / "stat").read_text()
        except OSError:  # the thread ended meanwhile
            continue
        name = text[text.index("(") + 1:text.rindex(")")]
        fields = text.rsplit(")", 1)[1].split()
        if task.name == str(pid):
            name = "main"
        out[name] = out.get(name, 0.0) + (int(fields[11]) + int(fields[12])) / os.sysconf(
            "SC_CLK_TCK")
    return out


def rss_mib(pid: int) -> float:
    """Return a process's resident memory (MiB)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def profile(calls: int, evict: int = 0) -> None:
    """Time the node's per-message path in this process, step by step.

    ``evict``: bytes of other memory read before each patch (what the DDS
    threads, the driver and the rest of a machine do to the caches between
    two of a node's callbacks); 0: every patch runs with warm caches.
    """
    from fastsim_ros.pipeline import Pipeline, PipelineConfig
    from msg_adapters import cdr
    from fastsim_ros.contact import compiled
    compiled.warm_up()
    pipe = Pipeline(PipelineConfig.from_values({"contacts": ["left"],
                                                "publish_markers": False}))
    patch = patch_cdr(0)
    twist = twist_cdr()
    pipe.on_wheel_twist(set_stamp(twist, 1))
    steps: dict[str, list[float]] = {"decode (CDR view)": [], "adapt (frame, grid)": [],
                                     "whole on_patch": [], "messages (encode)": []}
    other = np.ones(max(1, evict // 8))
    for i in range(calls):
        raw = set_stamp(patch, 1 + i)
        if evict:
            other.sum()
        t0 = time.perf_counter()
        c = cdr.read_cloud(raw)
        t1 = time.perf_counter()
        pa.patch_from_cloud(c, max_cells=16384)
        t2 = time.perf_counter()
        out = pipe.on_patch("left", raw)
        t3 = time.perf_counter()
        pipe.messages(out)
        t4 = time.perf_counter()
        for key, dt in zip(steps, (t1 - t0, t2 - t1, t3 - t2, t4 - t3)):
            steps[key].append(dt * 1e6)
    p50, p99 = pipe.solve_time_percentiles("left")
    print(f"per-message path, {calls} calls (us), {evict} bytes read between patches: "
          "median / p99")
    for key, v in steps.items():
        print(f"  {key:22s} {statistics.median(v):7.1f} / {np.percentile(v, 99):7.1f}")
    # the pipeline's solve times: on its compiled path, the one call (adapter loop + solve)
    print(f"  {'solve (compiled call)':22s} {p50:7.1f} / {p99:7.1f}")
    ctx = Context()
    rclpy.init(context=ctx)
    node = Node("bench_publish", context=ctx)
    pub = node.create_publisher(WrenchStamped, "bench/wrench", 10)
    data = pipe.messages(out)[0][1]
    msg = WrenchStamped()
    for label, item in (("publish(bytes)", data), ("publish(WrenchStamped)", msg)):
        times = []
        for _ in range(calls):
            t0 = time.perf_counter()
            pub.publish(item)
            times.append((time.perf_counter() - t0) * 1e6)
        print(f"  {label:22s} {statistics.median(times):7.1f} / {np.percentile(times, 99):7.1f}")
    node.destroy_node()
    rclpy.shutdown(context=ctx)


def driver(name: str) -> tuple[Context, Node, Any]:
    """Return a context, a node and an events executor spinning it, for the driver side.

    The driver runs the events executor too: a Python executor here would add
    its own ~50 us per wrench callback to the latencies measured.
    """
    ctx = Context()
    rclpy.init(context=ctx)
    node = Node(name, context=ctx)
    ex = EventsExecutor(context=ctx)
    ex.add_node(node)
    return ctx, node, ex


def startup(trials: int) -> None:
    """Time fastsim_node from process start to its first wrench (kernels cached)."""
    ctx, node, ex = driver("bench_startup")
    qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    got: list[float] = []
    node.create_subscription(WrenchStamped, "contact/left/wrench",
                             lambda raw: got.append(time.perf_counter()), qos, raw=True)
    patch_pub = node.create_publisher(PointCloud2, "contact/left/patch", qos)
    twist_pub = node.create_publisher(TwistStamped, "wheelset/twist", qos)
    patch, twist = patch_cdr(0), twist_cdr()
    times = []
    for _ in range(trials):
        got.clear()
        start = time.perf_counter()
        proc = subprocess.Popen([str(NODE)], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        stamp = 1_700_000_000 * 1_000_000_000
        while not got and time.perf_counter() - start < 30:
            stamp += 10_000_000
            twist_pub.publish(set_stamp(twist, stamp - 1000))
            patch_pub.publish(set_stamp(patch, stamp))
            ex.spin_once(timeout_sec=0.01)
        times.append(got[0] - start if got else float("nan"))
        proc.send_signal(signal.SIGTERM)
        proc.wait(10)
        for _ in range(20):
            ex.spin_once(timeout_sec=0.01)
    node.destroy_node()
    rclpy.shutdown(context=ctx)
    print(f"start-up to first wrench over {trials} starts (s): median "
          f"{statistics.median(times):.2f}, max {max(times):.2f} "
          f"({', '.join(f'{t:.2f}' for t in times)})")


#: ["--native"] (environment BENCH_NATIVE=1): py-spy samples C and C++ frames too, pausing
#: the target at each sample (it then drops most patches: shares, not rates)
NATIVE: list[str] = ["--native"] if os.environ.get("BENCH_NATIVE") else []
FLOOR = Path(__file__).resolve().parent / "dds_floor.py"
TRACE = Path(__file__).resolve().parent / "node_trace.py"
#: the checkout whose node runs as the target "baseline" (--baseline)
BASELINE = ROOT


def target_command(target: str, names: list[str], executor: str,
                   node_args: list[str], trace: str | None = None) -> list[str]:
    """Return the command line of the node or of the floor relay serving ``names``.

    ``trace``: the node (or the baseline) runs through ``node_trace.py``,
    which writes its main thread's timeline to that file on exit.
    """
    params = ["--ros-args", "-p", f"executor:={executor}", "-p",
              "contacts:=[" + ",".join(f'"{n}"' for n in names) + "]", *node_args]
    if trace is not None and target in ("node", "baseline"):
        checkout = [str(BASELINE)] if target == "baseline" else []
        return [sys.executable, str(TRACE), trace, *checkout, *params]
    if target == "floor":
        return [sys.executable, str(FLOOR), "--contacts", *names]
    if target == "fair floor":
        return [sys.executable, str(FLOOR), "--fair", "--contacts", *names]
    if target == "floor+solve":
        return [sys.executable, str(FLOOR), "--fair", "--solve", "--contacts", *names]
    if target == "floor+compiled":
        return [sys.executable, str(FLOOR), "--fair", "--compiled", "--contacts", *names]
    if target == "baseline":  # the node of another checkout's sources (BASELINE)
        # its node module where that checkout has it (fastsim_ros/ros/, or the package's top
        # level in a checkout from before the front ends had their package)
        return [sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv.pop(1)); "
                "import importlib, importlib.util as u; sys.exit(importlib.import_module("
                "'fastsim_ros.ros.node' if u.find_spec('fastsim_ros.ros') else "
                "'fastsim_ros.node').main())", str(BASELINE),
                "--ros-args", "-p", f"executor:={executor}", "-p",
                "contacts:=[" + ",".join(f'"{n}"' for n in names) + "]", *node_args]
    return [str(NODE), "--ros-args", "-p", f"executor:={executor}", "-p",
            "contacts:=[" + ",".join(f'"{n}"' for n in names) + "]", *node_args]


def run(contacts: int, rate: float, seconds: float, soak: float, executor: str,
        node_args: list[str], target: str = "node",
        py_spy: str | None = None, trace: bool = False,
        wrench_only: bool = False) -> dict[str, float]:
    """Drive the node (or the floor) with ``contacts`` contacts at ``rate`` Hz each.

    Prints the figures and returns them: ``received`` (share of the patches
    answered, %), ``p50``, ``p99`` (latency, ms), ``cpu`` (the target's share
    of one core, %), ``late`` (times the driver re-anchored).  ``py_spy``: a
    file to which py-spy (``pip install py-spy``) writes the target's
    sampled stacks over the run (collapsed, the flame graph format).
    ``trace``: the node runs through ``node_trace.py`` and the latencies'
    outliers are attributed (:func:`attribute`).  The driver subscribes to
    each contact's creepage and to ``wheelset/wrench`` too (what a rig
    takes; the node publishes only what has subscribers), unless
    ``wrench_only``.
    """
    names = [f"c{k}" for k in range(contacts)]
    trace_file = None
    if trace and target in ("node", "baseline"):
        trace_file = tempfile.NamedTemporaryFile(suffix=".npz", delete=False).name
    proc = subprocess.Popen(target_command(target, names, executor, node_args, trace_file),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    ctx, node, ex = driver("bench_driver")
    qos = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
    sent: dict[tuple[int, int], float] = {}
    latency: list[float] = []
    received = [0] * contacts
    # every patch answered: contact, stamp (ns), sent, received (perf_counter s)
    answered = (array.array("q"), array.array("q"), array.array("d"), array.array("d"))
    others = [0, 0]   # creepages, wheelset wrenches received

    def on_wrench(k: int):
        def callback(raw: bytes) -> None:
            now = time.perf_counter()
            sec, nanosec = _STAMP.unpack_from(raw, 4)
            stamp = sec * 1_000_000_000 + nanosec
            t = sent.pop((k, stamp), None)
            if t is not None:
                latency.append(now - t)
                received[k] += 1
                answered[0].append(k)
                answered[1].append(stamp)
                answered[2].append(t)
                answered[3].append(now)
        return callback

    def on_other(which: int):
        def callback(raw: bytes) -> None:
            others[which] += 1
        return callback

    driver_gc = Gc()
    gc.callbacks.append(driver_gc)

    pubs = [node.create_publisher(PointCloud2, f"contact/{n}/patch", qos) for n in names]
    twist_pub = node.create_publisher(TwistStamped, "wheelset/twist", qos)
    subs = [node.create_subscription(WrenchStamped, f"contact/{n}/wrench", on_wrench(k), qos,
                                     raw=True) for k, n in enumerate(names)]
    if not wrench_only:
        subs += [node.create_subscription(Vector3Stamped, f"contact/{n}/creepage",
                                          on_other(0), qos, raw=True) for n in names]
        subs.append(node.create_subscription(WrenchStamped, "wheelset/wrench", on_other(1),
                                             qos, raw=True))
    patches = [patch_cdr(k) for k in range(contacts)]
    twist = twist_cdr()
    start = time.monotonic()
    # matched on this side; the far side's readers are given the 0.5 s below (a lost
    # first patch would count as one drop in ~10^4)
    # the wrenches' publishers (the one-message floor publishes no creepage)
    while not (all(p.get_subscription_count() for p in pubs + [twist_pub])
               and all(s.get_publisher_count() for s in subs[:contacts])):
        ex.spin_once(timeout_sec=0.05)
        # a cold kernel cache compiles for a minute or more before the first topic opens
        # (measured: a fresh clone whose cache was filled elsewhere gave up at 30 s)
        if time.monotonic() - start > START_TIMEOUT or proc.poll() is not None:
            status = proc.poll()
            # stop it before giving up: a target left running kept its DDS domain busy
            # (a test run that drew the same domain later saw its /diagnostics publisher)
            proc.terminate()
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
            raise SystemExit(f"the {target} did not come up within {START_TIMEOUT:g} s "
                             f"(exit status {status}); a cold kernel cache compiles "
                             "first: scripts/setup_env.sh fills it")
    for _ in range(50):
        ex.spin_once(timeout_sec=0.01)
    duration = soak * 60.0 if soak else seconds
    period = 1.0 / rate
    rss = [(0.0, rss_mib(proc.pid))]
    spy = None
    if py_spy:
        duration_s = soak * 60.0 if soak else seconds
        # native frames need the process paused at each sample (no --nonblocking)
        sampling = NATIVE or ["--nonblocking"]
        spy = subprocess.Popen([str(Path(sys.executable).parent / "py-spy"), "record",
                                "--pid", str(proc.pid), "--rate", "250", *sampling,
                                "--format", "raw", "--duration", str(int(duration_s)),
                                "--output", py_spy],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    threads0 = thread_cpu_seconds(proc.pid)
    # the driver's own collections paused the wrenches' callbacks by up to 12 ms (measured
    # with --trace), for the node and the floors alike: none while it drives
    gc.collect()
    gc.freeze()
    gc.disable()
    cpu0, wall0 = cpu_seconds(proc.pid), time.perf_counter()
    t_next = wall0
    stamp = 1_700_000_000 * 1_000_000_000
    inputs = 0
    late = 0
    last_rss = wall0
    while True:
        now = time.perf_counter()
        if now - wall0 >= duration:
            break
        if now >= t_next:
            stamp += round(period * 1e9)
            twist_pub.publish(set_stamp(twist, stamp - 1000))
            for k, p in enumerate(pubs):
                sent[(k, stamp)] = time.perf_counter()
                p.publish(set_stamp(patches[k], stamp))
                inputs += 1
            t_next += period
            if now - t_next > 10 * period:  # the driver itself fell behind: re-anchor
                late += 1
                t_next = now + period
        ex.spin_once(timeout_sec=max(0.0, min(t_next - time.perf_counter(), period)))
        if soak and now - last_rss >= 10.0:
            last_rss = now
            rss.append((now - wall0, rss_mib(proc.pid)))
    wall = time.perf_counter() - wall0
    cpu = cpu_seconds(proc.pid) - cpu0
    threads = thread_cpu_seconds(proc.pid)
    drain = time.perf_counter()
    while time.perf_counter() - drain < 1.0:
        ex.spin_once(timeout_sec=0.01)
    gc.enable()
    gc.unfreeze()
    rss.append((time.perf_counter() - wall0, rss_mib(proc.pid)))
    if spy is not None:
        spy.wait(30)
    proc.send_signal(signal.SIGTERM)
    status = proc.wait(10)
    node.destroy_node()
    rclpy.shutdown(context=ctx)
    gc.callbacks.remove(driver_gc)
    got = sum(received)
    lat = np.array(latency) * 1e3 if latency else np.array([np.nan])
    extra = " ".join([target, executor, *node_args]) if target == "node" else target
    figures = {"received": 100.0 * got / inputs, "p50": float(np.median(lat)),
               "p99": float(np.percentile(lat, 99)), "cpu": 100.0 * cpu / wall,
               "late": float(late)}
    # per thread (% of one core): the main thread runs the executor and every callback
    shares = sorted(((100.0 * (t - threads0.get(name, 0.0)) / wall, name)
                     for name, t in threads.items()), reverse=True)
    figures["main"] = next((v for v, name in shares if name == "main"), 0.0)
    print(f"{extra}: {contacts} contacts x {rate:g} Hz for {wall:.1f} s: sent {inputs}, "
          f"wrenches {got}, dropped {inputs - got} ({100.0 * (inputs - got) / inputs:.2f}%), "
          f"latency p50 {figures['p50']:.3f} ms, p99 {figures['p99']:.3f} ms, "
          f"max {lat.max():.3f} ms; {target} CPU {figures['cpu']:.0f}% of one core; "
          f"driver re-anchored {late} times; exit {status}", flush=True)
    busy = [f"{name} {v:.1f}" for v, name in shares if v >= 0.5]
    print("  threads (% of a core): " + ", ".join(busy), flush=True)
    if not wrench_only:
        print(f"  also received: {others[0]} creepages, {others[1]} wheelset wrenches",
              flush=True)
    if trace_file is not None:
        figures.update(attribute(np.load(trace_file), answered, driver_gc, wall0,
                                 wall0 + duration))
        os.unlink(trace_file)
    if soak:
        first = rss[1][1] if len(rss) > 2 else rss[0][1]
        samples_text = ", ".join(f"{t:.0f}: {m:.1f}" for t, m in rss)
        print(f"  {target} RSS (MiB) over time (s): {samples_text}")
        print(f"  growth after the first 10 s: {100.0 * (rss[-1][1] - first) / first:+.1f}%")
    return figures


class Gc:
    """A ``gc.callbacks`` entry recording the driver's own collections (start, end: s)."""

    def __init__(self) -> None:
        self.start = array.array("d")
        self.end = array.array("d")
        self._t0 = 0.0

    def __call__(self, phase: str, info: dict[str, int]) -> None:
        if phase == "start":
            self._t0 = time.perf_counter()
        else:
            self.start.append(self._t0)
            self.end.append(time.perf_counter())


def _busy_before(start: np.ndarray, end: np.ndarray) -> Any:
    """Return ``F(t)``: the time (s) spent inside the intervals before ``t`` (sorted, disjoint)."""
    order = np.argsort(start)
    s, length = start[order], (end - start)[order]
    before = np.concatenate(([0.0], np.cumsum(length)))

    def busy(t: np.ndarray) -> np.ndarray:
        j = np.searchsorted(s, t, "right") - 1
        inside = np.clip(t - s[np.maximum(j, 0)], 0.0, length[np.maximum(j, 0)]) \
            if s.size else np.zeros_like(t)
        return np.where(j >= 0, before[np.maximum(j, 0)] + inside, 0.0)
    return busy


#: the parts of a patch's latency (:func:`attribute`), in the order printed
PARTS = ("wait: wake-up, transport in", "wait: other callbacks", "wait: diagnostics",
         "garbage collection", "handler", "return: transport out, driver")


def attribute(trace: Any, answered: tuple[Any, ...], driver_gc: Gc, t_first: float,
              t_last: float) -> dict[str, float]:
    """Split each answered patch's latency into parts from the node's timeline; print the tail.

    Per patch (sent at ``ts``, its callback run from ``cs`` to ``ce`` in the
    node, its wrench received at ``tr``; one clock, CLOCK_MONOTONIC):
    ``ts..cs`` is the wait, split into the node's other callbacks, its
    diagnostics timer, its garbage collections and the rest (no Python of the
    node running: DDS's transport and the executor's wake-up, take and
    dispatch); ``cs..ce`` the handler (its collections apart); ``ce..tr``
    the return (the wrench's way back and the driver's own collections).
    The patches at or above the p99 latency are each given the part that
    exceeds its median over all patches the most: the count by part says
    what makes p99.  Prints the node's events (collections by generation,
    diagnostics runs, executor wake-ups) and returns the tail's shares.
    """
    names = ("kind", "start", "end", "stamp", "extra")
    kind, start, end, stamp, extra = (trace[key] for key in names)
    k, st = np.frombuffer(answered[0], dtype=np.int64), np.frombuffer(answered[1], dtype=np.int64)
    ts, tr = np.frombuffer(answered[2]), np.frombuffer(answered[3])
    if ts.size == 0:
        return {}
    cb = kind == 0
    key = stamp[cb] * 64 + extra[cb]
    order = np.argsort(key)
    where = np.searchsorted(key[order], st * 64 + k)
    where = np.minimum(where, order.size - 1)
    found = key[order][where] == st * 64 + k
    ts, tr = ts[found], tr[found]
    cs, ce = start[cb][order][where][found], end[cb][order][where][found]
    callbacks = _busy_before(start[cb], end[cb])
    diagnostics = _busy_before(start[kind == 1], end[kind == 1])
    collections = _busy_before(start[kind == 2], end[kind == 2])
    g_wait = collections(cs) - collections(ts)
    g_run = collections(ce) - collections(cs)
    # callbacks before this one that were still running when the patch was sent count
    c_wait = callbacks(cs) - callbacks(ts)
    d_wait = diagnostics(cs) - diagnostics(ts)
    wait = cs - ts
    parts = np.stack((np.maximum(wait - c_wait - d_wait, 0.0),
                      np.maximum(c_wait - g_wait, 0.0), d_wait, g_wait + g_run,
                      (ce - cs) - g_run, tr - ce), axis=1) * 1e3
    latency = (tr - ts) * 1e3
    p99 = np.percentile(latency, 99)
    tail = latency >= p99
    median = np.median(parts, axis=0)
    cause = np.argmax(parts[tail] - median, axis=1)
    counts = np.bincount(cause, minlength=len(PARTS))
    d_gc = _busy_before(np.frombuffer(driver_gc.start), np.frombuffer(driver_gc.end))
    driver = (d_gc(tr) - d_gc(ce)) * 1e3
    print(f"  latency's parts (ms), {found.sum()} patches matched to the node's callbacks of "
          f"{found.size}; the tail: {tail.sum()} patches at or above p99 {p99:.3f} ms:")
    print(f"    {'part':34s} {'median':>8s} {'p99':>8s} {'tail mean':>9s} {'tail cause':>10s}")
    for j, name in enumerate(PARTS):
        print(f"    {name:34s} {median[j]:8.3f} {np.percentile(parts[:, j], 99):8.3f} "
              f"{parts[tail, j].mean():9.3f} {counts[j]:10d}")
    print(f"    (driver's own collections in the return: tail mean {driver[tail].mean():.3f} "
          f"ms, {np.count_nonzero(driver[tail] > 0)} of the tail)")
    span = t_last - t_first
    inside = (start >= t_first) & (start <= t_last)
    for g in range(3):
        sel = inside & (kind == 2) & (extra == g)
        d = (end[sel] - start[sel]) * 1e6
        if d.size:
            print(f"    gc generation {g}: {d.size / span:6.1f}/s, {np.median(d):7.1f} us "
                  f"median, {d.max():8.1f} us max")
        else:
            print(f"    gc generation {g}: none")
    sel = inside & (kind == 1)
    d = (end[sel] - start[sel]) * 1e6
    if d.size:
        print(f"    diagnostics: {d.size / span:.2f}/s, {np.median(d):.0f} us median, "
              f"{d.max():.0f} us max")
    sel = inside & (kind == 3)
    print(f"    executor spin_once: {sel.sum() / span:.0f}/s; callbacks "
          f"{np.count_nonzero(inside & cb) / span:.0f}/s")
    sel = inside & (kind == 4)
    if sel.any():   # the pipeline's handler inside the patches' callbacks
        d = (end[sel] - start[sel]) * 1e6
        whole = (ce - cs) * 1e6
        print(f"    Pipeline.on_patch: {np.median(d):.0f} us median, p99 "
              f"{np.percentile(d, 99):.0f} us; the patch callbacks around it "
              f"{np.median(whole):.0f} us median")
    share = counts / max(1, tail.sum())
    return {f"tail {name}": float(100 * share[j]) for j, name in enumerate(PARTS)}


def against_floor(contacts: int, rate: float, seconds: float, rounds: int, executor: str,
                  node_args: list[str], bound: bool = False, trace: bool = False,
                  wrench_only: bool = False) -> None:
    """Run the node and the floors alternately ``rounds`` times; print medians and ratios.

    The targets (4 x 1 kHz): received share within 0.2 points of the
    one-message floor's, p99 at most 2x its and under 1 ms, CPU at most
    1.5x the fair floor's (``dds_floor.py --fair``: the node's messages,
    pre-serialised).  ``bound``: the fair floor that also solves a fixed
    patch per patch with the default method (``dds_floor.py --fair
    --solve``) runs in the rotation too: what the solve alone adds, the
    least a node that solves each patch and publishes its messages costs;
    and the fair floor with the node's one compiled call on each received
    patch (``--fair --compiled``: adapter loop and solve, nothing around it).
    ``trace``: the node's runs attribute their tail.
    """
    targets: tuple[str, ...] = ("node", "floor", "fair floor")
    if bound:
        targets += ("floor+solve", "floor+compiled")
    if BASELINE != ROOT:
        targets += ("baseline",)
    runs: dict[str, list[dict[str, float]]] = {t: [] for t in targets}
    for r in range(rounds):
        # rotate which goes first, so that a drift of the machine weighs on all
        order = targets[r % len(targets):] + targets[:r % len(targets)]
        for target in order:
            runs[target].append(run(contacts, rate, seconds, 0.0, executor, node_args,
                                    target, trace=trace, wrench_only=wrench_only))
    keys = ("received", "p50", "p99", "cpu", "main")
    med = {t: {k: statistics.median(f[k] for f in runs[t]) for k in keys} for t in runs}
    n, f, fair = med["node"], med["floor"], med["fair floor"]
    print(f"medians of {rounds} alternating runs, {contacts} contacts x {rate:g} Hz, "
          f"{seconds:g} s each:")
    for t in targets:
        m = med[t]
        print(f"  {t:11s} received {m['received']:.2f}%, latency p50 {m['p50']:.3f} ms, "
              f"p99 {m['p99']:.3f} ms, CPU {m['cpu']:.0f}% of one core "
              f"(main thread {m['main']:.0f}%)")
        spread = {k: (min(r[k] for r in runs[t]), max(r[k] for r in runs[t])) for k in keys}
        print(f"  {'':11s} runs: received {spread['received'][0]:.2f}-"
              f"{spread['received'][1]:.2f}%, p99 {spread['p99'][0]:.3f}-"
              f"{spread['p99'][1]:.3f} ms, CPU {spread['cpu'][0]:.0f}-{spread['cpu'][1]:.0f}%")
    print(f"  node/floor: received {n['received'] - f['received']:+.2f} points (target >= "
          f"-0.2), p99 {n['p99'] / f['p99']:.2f}x (target <= 2, and under 1 ms: "
          f"{n['p99']:.3f} ms); node/fair floor: CPU {n['cpu'] / fair['cpu']:.2f}x "
          f"(target <= 1.5); fair/one-message floor: CPU {fair['cpu'] / f['cpu']:.2f}x, p99 "
          f"{fair['p99'] / f['p99']:.2f}x", flush=True)
    if "baseline" in med:
        b = med["baseline"]
        print(f"  baseline/floor: received {b['received'] - f['received']:+.2f} points, "
              f"p99 {b['p99'] / f['p99']:.2f}x ({b['p99']:.3f} ms); baseline/fair floor: CPU "
              f"{b['cpu'] / fair['cpu']:.2f}x", flush=True)
    if bound:
        b = med["floor+solve"]
        print(f"  floor+solve (the fair floor solving each patch)/floor: received "
              f"{b['received'] - f['received']:+.2f} points, p99 {b['p99'] / f['p99']:.2f}x; "
              f"/fair floor: CPU {b['cpu'] / fair['cpu']:.2f}x", flush=True)
        b = med["floor+compiled"]
        print(f"  floor+compiled (the fair floor with the node's compiled call on each patch)"
              f"/floor: received {b['received'] - f['received']:+.2f} points, p99 "
              f"{b['p99'] / f['p99']:.2f}x; /fair floor: CPU {b['cpu'] / fair['cpu']:.2f}x",
              flush=True)


def main() -> None:
    """Run the benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--contacts", type=int, nargs="*", default=[2, 4],
                        help="contact counts to drive (none: only --startup / --profile)")
    parser.add_argument("--rate", type=float, default=1000.0, help="patches per second each")
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--soak", type=float, default=0.0, metavar="MINUTES")
    parser.add_argument("--executors", nargs="+", default=["events"],
                        choices=["events", "single_threaded"],
                        help="the node's executor parameter; several: side by side")
    parser.add_argument("--node-args", default="", metavar="ARGS",
                        help="more --ros-args for the node, e.g. --node-args='-p qos_depth:=50'")
    parser.add_argument("--startup", type=int, default=0, metavar="TRIALS",
                        help="first time start-up to the first wrench, TRIALS times")
    parser.add_argument("--profile", type=int, default=0, metavar="CALLS",
                        help="first time the per-message path in-process")
    parser.add_argument("--evict", type=int, default=0, metavar="BYTES",
                        help="with --profile: read BYTES of other memory before each patch "
                        "(caches as cold as a node's between callbacks)")
    parser.add_argument("--bound", action="store_true",
                        help="with --floor: the fair floor that also solves a fixed patch "
                        "(dds_floor.py --fair --solve) and the one with the node's compiled "
                        "call (--fair --compiled) in the rotation too")
    parser.add_argument("--baseline", default=None, metavar="CHECKOUT",
                        help="with --floor: the node of another checkout's sources (a "
                        "worktree of main, say) in the rotation too, as 'baseline'")
    parser.add_argument("--trace", action="store_true",
                        help="run the node through node_trace.py and attribute the latency's "
                        "tail (its callbacks, garbage collections, diagnostics, wake-ups)")
    parser.add_argument("--wrench-only", action="store_true",
                        help="the driver takes the contacts' wrenches alone (not the creepages "
                        "and the wheelset wrench): the node then publishes the wrench alone")
    parser.add_argument("--target", choices=("node", "floor", "fair floor", "floor+solve",
                                             "floor+compiled",
                                             "baseline"),
                        default="node",
                        help="what the single runs drive: the node or the DDS floor")
    parser.add_argument("--py-spy", default=None, metavar="FILE",
                        help="record the target with py-spy (collapsed stacks to FILE)")
    parser.add_argument("--floor", type=int, default=0, metavar="ROUNDS",
                        help="drive the node and the DDS floor (dds_floor.py) alternately, "
                        "ROUNDS times each, and print node/floor ratios of the medians")
    parser.add_argument("--profiles", type=int, default=0, metavar="ROUNDS",
                        help="the node in profiles mode (one wheelset, poses and twists at "
                        "--rate) and in topics mode (two patches a cycle) alternately, ROUNDS "
                        "times each (bench_profiles_node.py)")
    args = parser.parse_args()
    if args.baseline:
        global BASELINE
        BASELINE = Path(args.baseline).resolve()
    print(f"machine: {machine()}")
    if args.profiles:
        import bench_profiles_node
        bench_profiles_node.side_by_side(sys.modules[__name__], args.rate, args.seconds,
                                         args.profiles, shlex.split(args.node_args))
        return
    if not NODE.exists():
        raise SystemExit(f"{NODE} is missing: run scripts/setup_env.sh")
    if args.startup:
        startup(args.startup)
    if args.profile:
        profile(args.profile, args.evict)
    for n in args.contacts:
        for executor in args.executors:
            if args.floor:
                against_floor(n, args.rate, args.seconds, args.floor, executor,
                              shlex.split(args.node_args), args.bound, args.trace,
                              args.wrench_only)
            else:
                run(n, args.rate, args.seconds, args.soak, executor,
                    shlex.split(args.node_args), args.target, args.py_spy, args.trace,
                    args.wrench_only)


if __name__ == "__main__":
    main()
