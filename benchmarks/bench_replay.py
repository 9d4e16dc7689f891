#!/usr/bin/env python3
"""Measure ``fastsim_replay``: throughput against the batch solver, where the time goes, --jobs.

Usage (from the package root)::

    .venv/bin/python benchmarks/bench_replay.py [--repeats R] [--copies K] [--bags NAME ...]
    .venv/bin/python benchmarks/bench_replay.py --scheduler [--small N]
    .venv/bin/python benchmarks/bench_replay.py --mcap-only [--rounds N] [--mcap-before REV]
    .venv/bin/python benchmarks/bench_replay.py --long [--seconds S] [--rounds N]

Prints, with the machine line:

1. per bundled bag (its ``bags/<name>.params.yaml``), best of ``R`` replays
   in this process, each a whole replay (open, read, solve, write, close):
   patch messages per second and the multiple of real time (log duration /
   wall time) of the replay (the chunked, batched path ``fastsim_replay``
   takes) and, beside it, of the per-message reference path (rosbags'
   reader and writer, one pipeline call per message: the path of inputs
   the batch replay does not take); then the batch solver's own rate on the same patches in the
   same run (``solve_batch`` of the bag's method, one call per patch shape,
   best of 3) and the replay's share of it;
2. where the batched replay's time goes (its best run): reading (chunk
   reads, decompression, finding the records), copying the input's chunks,
   decoding (twists and patches: layouts, the compiled scan and grid fit,
   stamps, old stamps), kinematics (matching by stamp, creepages), solving,
   state (frames, rig cycles, markers), encoding the outputs, writing them
   (records, chunk compression, the summary, metadata.yaml), diagnostics,
   and the rest (opening the input, the output directory, closing); shares
   of the wall time and microseconds per input message;
3. many bags: ``K`` copies of each bag that uses the default contacts,
   replayed through ``fastsim_replay.main`` with ``--jobs 1`` and
   ``--jobs 2``: patches per second and the speed-up;
4. the MCAP layer against a hand-written one, side by side in this run:
   the batched replay of each bag with the hand-written MCAP module of the
   revision ``--mcap-before`` (its ``fastsim_ros/replay/mcap.py``, loaded
   from git) and with the package's (the ``mcap`` library's records and reader), in
   alternating order, ``--rounds`` times each: median patches per second
   and the ratio (``--mcap-only``: this section alone).

With ``--long``, instead: a recording made here (``--seconds`` of one
contact at 200 Hz, 30 x 30-cell Hertzian patches in steady running's
partial slip, the default method) replayed ``--rounds`` times in this process after one
untimed replay (the kernels loaded: the wall beyond start-up), and the
command line's start-up measured apart; patches per second and the
multiple of real time of the replay as ``fastsim_replay`` runs it, the
batch solver's rate on the same patches in the same run (after a profiled
replay of each round, which keeps the solves' inputs) and the share; each
run printed (with the profiled replay's phases in us per patch, and of
``read`` the decompression, of ``decode`` the compiled adapter loop, of
``solve`` the compiled solves), then the medians.

With ``--scheduler``, instead: ``N`` small bags (generated: the first
0.5 s of ``hertz_ramp``, 200 by default) replayed by two local worker
processes of a Dask cluster started here (a scheduler and two workers, as
``fastsim_replay --scheduler`` uses them) and by ``--jobs 2`` (the local fork
pool), each after one untimed run: wall time, bags per second, the ratio,
and each executor's overhead per bag, ``(2 x wall - sum of the tasks' own
replay times) / N`` (submitting, moving the task and its result, waiting).

Nothing is written outside a temporary directory.  Timings on a shared
2-core VM drift between runs: quote the machine line and the load average.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import io
import math
import os
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.rosbag2 import Reader

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench_fastsim import machine  # noqa: E402  (one machine line for every benchmark)
from fastsim_ros import replay  # noqa: E402
from fastsim_ros.contact import compiled  # noqa: E402
from fastsim_ros.contact.compiled import CalibratedMaeSolver  # noqa: E402
from fastsim_ros.contact.compiled import EquivalentEllipseSolver, MaeSolver  # noqa: E402
from fastsim_ros.contact.friction import friction_law  # noqa: E402
from fastsim_ros.ros.params import load_params_file  # noqa: E402
from fastsim_ros.replay import batch  # noqa: E402
from msg_adapters import patch as patch_adapter  # noqa: E402

BAGS = ROOT / "bags"
NAMES = ("hertz_ramp", "semi_ellipses_spin", "flange_shift", "roller_rig", "bad_inputs")
#: bags the replay takes message by message (transient rolling's memory, friction estimation,
#: profiles mode): in section 1 beside the others, outside "all, in turn" (no batch to compare)
PER_MESSAGE = ("transient_step", "adhesion_rig", "mbench_a22")
#: bags whose params use the default contacts (left, right): one --params for all
SAME_CONTACTS = ("hertz_ramp", "semi_ellipses_spin", "bad_inputs")
PHASES = ("read", "copy", "decode", "kinematics", "solve", "state", "encode", "write",
          "diagnostics")
#: parts of phases, printed beside them in --long: (part, of phase, label)
PARTS = (("decompress", "read", "decompression"), ("scan", "decode", "adapter loop"),
         ("solver", "solve", "compiled solves"))
#: the last commit whose fastsim_ros/replay/mcap.py wrote and parsed MCAP by hand
MCAP_BEFORE = "ddc07d7"
SOLVERS = {"mae": MaeSolver, "mae_calibrated": CalibratedMaeSolver,
           "fastsim_ellipse": EquivalentEllipseSolver}


def batch_rate(solves: list[tuple[Any, ...]], values: dict[str, Any],
               repeats: int = 3) -> float:
    """Return patch solves per second of the bag's method's ``solve_batch``.

    On the same patches and creepages as the replay solved them, one call
    per patch shape, best of ``repeats``.
    """
    solver = SOLVERS[values["method"]](values["poisson_ratio"], values["shear_modulus"])
    mu = float(values["friction_coefficient"])
    law = friction_law(values["friction_law"], mu,
                       limit_ratio=float(values["friction_limit_ratio"]),
                       decay=float(values["friction_decay"]))
    groups: dict[tuple[int, ...], list[tuple[Any, ...]]] = {}
    for ps, grid, creep, solved in solves:  # Profile.solves: batches as the replay solved them
        groups.setdefault(ps.shape[1:], []).append((ps[solved], grid[solved], creep[solved]))
    batches = []
    count = 0
    for items in groups.values():
        ps = np.concatenate([i[0] for i in items])
        grid = np.concatenate([i[1] for i in items])
        batches.append((ps, *(np.ascontiguousarray(grid[:, k]) for k in range(4)),
                        np.concatenate([i[2] for i in items])))
        count += len(ps)
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        for ps, x0, y0, dx, dy, cr in batches:
            solver.solve_batch(ps, x0, y0, dx, dy, cr, mu=mu, bound=values["traction_bound"],
                               friction=law if law.slip_dependent else None,
                               speed=np.full(len(cr), 20.0))
        best = min(best, time.perf_counter() - t0)
    return count / best


def one_bag(name: str, repeats: int, out: Path, path: str,
            tag: str = "") -> tuple[Any, dict[str, Any]]:
    """Replay one bag ``repeats`` times on ``path``; return the fastest result (profiled)."""
    values = load_params_file(BAGS / f"{name}.params.yaml")
    best = None
    for k in range(repeats):
        r = replay.replay_bag(BAGS / name, f"{name}_{path}{tag}_{k}", out, values,
                              progress=False, profile=True, path=path)
        if not r.ok:
            raise SystemExit(f"replay of {name} failed: {r.error}")
        if best is None or r.wall_s < best.wall_s:
            best = r
    return best, values


def patches_of(name: str) -> int:
    """Return the bag's patch messages."""
    with Reader(BAGS / name) as reader:
        return sum(c.msgcount for c in reader.connections if c.topic.endswith("/patch"))


def many_bags(copies: int, jobs: int, out: Path) -> tuple[float, int, float]:
    """Replay ``copies`` of each default-contact bag with ``--jobs``.

    Return the wall time (s), the number of patches and the log duration (s).
    """
    links = out / f"in{jobs}"
    links.mkdir()
    inputs = []
    patches = 0
    log_s = 0.0
    for name in SAME_CONTACTS:
        with Reader(BAGS / name) as reader:
            dur = reader.duration * 1e-9
        for k in range(copies):
            link = links / f"{name}_{k}"
            link.symlink_to(BAGS / name, target_is_directory=True)
            inputs.append(str(link))
            patches += patches_of(name)
            log_s += dur
    args = inputs + ["-o", str(out / f"out{jobs}"), "--jobs", str(jobs), "--no-progress",
                     "--params", str(BAGS / "hertz_ramp.params.yaml")]
    with contextlib.redirect_stdout(io.StringIO()):
        t0 = time.perf_counter()
        status = replay.main(args)
        wall = time.perf_counter() - t0
    if status != 0:
        raise SystemExit(f"--jobs {jobs} replay failed with status {status}")
    return wall, patches, log_s


def mcap_module(rev: str) -> Any:
    """Return ``fastsim_ros/replay/mcap.py`` of git revision ``rev`` as a module."""
    text = subprocess.run(["git", "-C", str(ROOT), "show", f"{rev}:fastsim_ros/replay/mcap.py"],
                          check=True, capture_output=True, text=True).stdout
    name = "fastsim_ros.replay.mcap_before"
    spec = importlib.util.spec_from_loader(name, loader=None)
    assert spec is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module      # dataclasses look their module up
    exec(compile(text, f"{rev}:fastsim_ros/replay/mcap.py", "exec"), module.__dict__)
    return module


def mcap_layers(names: list[str], rounds: int, out: Path, rev: str) -> None:
    """Print section 4: the batched replay with the MCAP module of ``rev`` and today's."""
    from fastsim_ros.replay import bulk
    now = bulk.mcap
    layers = {f"before ({rev}, by hand)": mcap_module(rev), "now (mcap library)": now}
    rates: dict[str, dict[str, list[float]]] = {k: {n: [] for n in names} for k in layers}
    walls: dict[str, list[float]] = {k: [] for k in layers}
    print(f"4. the MCAP layer: median of {rounds} alternating replays of each bag, "
          f"patches/s (whole replay, batched path)")
    try:
        for k in range(rounds):
            order = list(layers) if k % 2 == 0 else list(layers)[::-1]
            for layer in order:
                bulk.mcap = layers[layer]   # type: ignore[assignment]
                total = 0.0
                for name in names:
                    values = load_params_file(BAGS / f"{name}.params.yaml")
                    r = replay.replay_bag(BAGS / name, f"{name}_mcap{k}_{order.index(layer)}",
                                          out, values, progress=False, path="auto")
                    if not r.ok:
                        raise SystemExit(f"replay of {name} ({layer}) failed: {r.error}")
                    rates[layer][name].append(patches_of(name) / r.wall_s)
                    total += r.wall_s
                walls[layer].append(total)
    finally:
        bulk.mcap = now
    patches = sum(patches_of(n) for n in names)
    heads = list(layers)
    print(f"{'bag':20s} {heads[0]:>26s} {heads[1]:>20s} {'now/before':>10s}")
    for name in names + ["all, in turn"]:
        if name in rates[heads[0]]:
            a, b = (float(np.median(rates[h][name])) for h in heads)
        else:
            a, b = (patches / float(np.median(walls[h])) for h in heads)
        print(f"{name:20s} {a:26.0f} {b:20.0f} {b / a:10.2f}")
    print(f"  (ranges, all in turn: before {patches / max(walls[heads[0]]):.0f}-"
          f"{patches / min(walls[heads[0]]):.0f}, now {patches / max(walls[heads[1]]):.0f}-"
          f"{patches / min(walls[heads[1]]):.0f} patches/s)")


def long_bag(out: Path, seconds: float, rate: float = 200.0, cells: int = 30) -> Path:
    """Write a recording of one contact: ``seconds`` at ``rate`` Hz, ``cells`` x ``cells``.

    The wheelset twist and the patch at ``rate`` each, the patch half a
    period after the twist; a Hertzian tread patch (60 kN) at 20 m/s under
    a braking creepage of steady running, ``1e-3 (1 + 0.5 sin(2 pi t / 10
    s))`` (partial slip throughout); the default method.  The messages are
    serialised once and their stamps patched in.
    Returns the bag's directory (its params file beside it).
    """
    sys.path.insert(0, str(ROOT / "scripts"))
    import make_bags as mb
    from rosbags.rosbag2 import Writer
    from rosbags.rosbag2.enums import CompressionFormat, CompressionMode, StoragePlugin
    name = f"long_{seconds:g}s"
    path = out / name
    area = mb.hertz_area(mb.R, 0.3, 6.0e4, cells)
    cloud = bytearray(mb.TYPESTORE.serialize_cdr(
        mb.cloud_msg(0, mb.cloud_points(area, (0.0, mb.Y_WHEEL, -mb.R), mb.left_normal(0.0))),
        mb.CLOUD))
    v0, dt = 20.0, 1.0 / rate
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with writer:
        twist_conn = writer.add_connection("/wheelset/twist", mb.TWIST, typestore=mb.TYPESTORE,
                                           offered_qos_profiles=mb.QOS)
        patch_conn = writer.add_connection("/contact/left/patch", mb.CLOUD,
                                           typestore=mb.TYPESTORE, offered_qos_profiles=mb.QOS)
        for k in range(int(round(seconds * rate))):
            t = k * dt
            xi = 1.0e-3 * (1.0 + 0.5 * math.sin(2.0 * math.pi * t / 10.0))
            ns = mb.stamp_ns(t)
            writer.write(twist_conn, ns, mb.TYPESTORE.serialize_cdr(
                mb.twist_msg(ns, (v0, 0, 0), (0, mb.omega_for(v0, xi, mb.R), 0)), mb.TWIST))
            ns = mb.stamp_ns(t + dt / 2)
            cloud[4:12] = struct.pack("<iI", *divmod(ns, 1_000_000_000))
            writer.write(patch_conn, ns, bytes(cloud))
    params = dict(mb.BASE_PARAMS, contacts=["left"], method="mae_calibrated")
    (out / f"{name}.params.yaml").write_text(mb.params_text(name, params))
    return path


def long_main(seconds: float, rounds: int) -> int:
    """Print the long recording's replay: rate, x real time, the batch solver's, the share."""
    print(f"machine: {machine()}")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        t0 = time.perf_counter()
        bag = long_bag(out, seconds)
        print(f"recording: {seconds:g} s, one contact, 200 Hz, 30 x 30 cells, written in "
              f"{time.perf_counter() - t0:.1f} s")
        params = out / f"{bag.name}.params.yaml"
        # start-up: the command line from process start on a recording of one twist and patch;
        # the installed one, as users run it (its kernels cached by setup_env.sh; this
        # tree's modules run as `python -m` have a cache of their own, cold after a new venv)
        short = long_bag(out / "short", 1.0 / 200.0)
        installed = ROOT / "install" / "fastsim_ros" / "lib" / "fastsim_ros" / "fastsim_replay"
        program = ([str(installed)] if installed.exists()
                   else [sys.executable, "-m", "fastsim_ros.replay"])
        cmd = [*program, str(short), "-o", str(out / "s"), "--params", str(params),
               "--no-progress", "--overwrite"]
        starts = []
        for _ in range(3):
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, cwd=ROOT, capture_output=True)
            starts.append(time.perf_counter() - t0)
        print(f"start-up ({Path(program[-1]).name} on a one-patch recording, 3 runs): median "
              f"{np.median(starts):.2f} s ({', '.join(f'{s:.2f}' for s in starts)})")
        warm = compiled.warm_up()
        patch_adapter.warm_up()
        batch.warm_up()
        print(f"kernels ready in {warm:.2f} s")
        values = load_params_file(params)
        replay.replay_bag(bag, "warm", out, values, progress=False)
        n_patch = int(round(seconds * 200))
        rows = []
        for k in range(rounds):
            # the replay as fastsim_replay runs it, then a profiled one (its phases, and its
            # solves for the batch solver: it keeps every solve's inputs, 86 MB of pressures for
            # the 60 s recording, which costs it some 5% of its wall)
            r = replay.replay_bag(bag, f"run{k}", out, values, progress=False)
            prof = replay.replay_bag(bag, f"prof{k}", out, values, progress=False, profile=True)
            if not (r.ok and prof.ok):
                raise SystemExit(f"replay failed: {r.error or prof.error}")
            rate = batch_rate(prof.profile.solves, values)
            rows.append((n_patch / r.wall_s, r.duration_s / r.wall_s, rate))
            phases = prof.profile.phases
            parts = {of: f" ({label} {phases.get(part, 0.0) / n_patch * 1e6:.1f})"
                     for part, of, label in PARTS}
            share = 100 * n_patch / r.wall_s / rate
            print(f"  run {k}: wall {r.wall_s:.3f} s (profiled {prof.wall_s:.3f} s), "
                  f"{n_patch / r.wall_s:8.0f} patches/s, {r.duration_s / r.wall_s:6.1f}x real "
                  f"time; batch solver {rate:8.0f}/s; share {share:5.1f}%"
                  f"; us/patch (profiled): " + ", ".join(
                      f"{key} {phases.get(key, 0.0) / n_patch * 1e6:.1f}{parts.get(key, '')}"
                      for key in PHASES))
            for f in [*out.glob(f"run{k}*"), *out.glob(f"prof{k}*")]:
                if f.is_dir():
                    import shutil
                    shutil.rmtree(f)
        med = np.median(np.array(rows), axis=0)
        share = 100 * np.median([a / c for a, _, c in rows])
        print(f"median of {rounds}: {med[0]:.0f} patches/s, {med[1]:.1f}x real time beyond "
              f"start-up, batch solver {med[2]:.0f}/s, share {share:.1f}% (range "
              f"{100 * min(a / c for a, _, c in rows):.1f}-"
              f"{100 * max(a / c for a, _, c in rows):.1f}%)")
    print(f"machine: {machine()}")
    return 0


def _spin(n: int) -> int:
    total = 0
    for k in range(n):
        total += k
    return total


def parallel_capacity(n: int = 2_000_000, rounds: int = 3) -> float:
    """Return how much faster two forked processes run a pure-Python loop than one in turn.

    Best of ``rounds``: what the machine (2 cores shared with other work)
    gives two processes at the moment, the ceiling of ``--jobs 2``'s speed-up.
    """
    import multiprocessing
    best = 0.0
    with multiprocessing.get_context("fork").Pool(2) as pool:
        pool.map(_spin, [10, 10])
        for _ in range(rounds):
            t0 = time.perf_counter()
            _spin(n)
            _spin(n)
            serial = time.perf_counter() - t0
            t0 = time.perf_counter()
            pool.map(_spin, [n, n], chunksize=1)
            best = max(best, serial / (time.perf_counter() - t0))
    return best


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("--repeats", type=int, default=5, help="replays per bag (best is kept)")
    ap.add_argument("--copies", type=int, default=4,
                    help="copies of each default-contact bag in the many-bags run")
    ap.add_argument("--bags", nargs="+", default=list(NAMES + PER_MESSAGE),
                    choices=NAMES + PER_MESSAGE)
    ap.add_argument("--scheduler", action="store_true",
                    help="small bags on a local Dask cluster (two workers) against --jobs 2")
    ap.add_argument("--small", type=int, default=200, help="small bags for --scheduler")
    ap.add_argument("--rounds", type=int, default=3,
                    help="alternating timed runs of each executor (--scheduler, the many bags, "
                    "the MCAP layers: at least 5 there)")
    ap.add_argument("--mcap-only", action="store_true",
                    help="section 4 alone: the MCAP module of --mcap-before against today's")
    ap.add_argument("--mcap-before", default=MCAP_BEFORE,
                    help="git revision of the hand-written MCAP module (default %(default)s)")
    ap.add_argument("--long", action="store_true",
                    help="instead: a long one-contact recording (--seconds) made and replayed")
    ap.add_argument("--seconds", type=float, default=60.0, help="the long recording's length")
    args = ap.parse_args(argv)
    if args.long:
        return long_main(args.seconds, args.rounds)
    if args.scheduler:
        return cluster_main(args.small, args.rounds)
    print(f"machine: {machine()}")
    warm = compiled.warm_up()
    patch_adapter.warm_up()
    batch.warm_up()
    source = "from the disk cache" if warm < 5.0 else "compiled: the cache was cold"
    print(f"kernels ready in {warm:.2f} s ({source})\n")

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        mcap_rounds = max(5, args.rounds)
        if args.mcap_only:
            for name in args.bags:  # one untimed replay each: first-call costs out of the figures
                one_bag(name, 1, out, "auto", "_warm")
            mcap_layers(list(args.bags), mcap_rounds, out, args.mcap_before)
            print(f"\nmachine: {machine()}")
            return 0
        for name in args.bags:  # one untimed replay each: first-call costs out of the figures
            one_bag(name, 1, out, "auto", "_warm")
        results = {name: one_bag(name, args.repeats, out, "auto") for name in args.bags}
        reference = {name: one_bag(name, max(1, args.repeats // 2), out, "rosbags")[0]
                     for name in args.bags}

        print(f"1. one bag at a time (best of {args.repeats}; whole replay: open to close)")
        print(f"{'bag':20s} {'patches':>7s} {'wall ms':>8s} {'patch/s':>8s} {'x real':>7s} "
              f"{'per-msg x real':>14s} {'batch solve/s':>13s} {'share':>6s}")
        totals = {"wall": 0.0, "log": 0.0, "patches": 0, "solve_s": 0.0}
        for name, (r, values) in results.items():
            n_patch = patches_of(name)
            solves = r.profile.solves
            if not solves:  # message by message: no batch of its solves to compare with
                print(f"{name:20s} {n_patch:7d} {r.wall_s * 1e3:8.1f} "
                      f"{n_patch / r.wall_s:8.0f} {r.speed:7.1f} "
                      f"{reference[name].speed:14.1f} {'-':>13s} {'-':>6s}")
                continue
            rate = batch_rate(solves, values)
            totals["wall"] += r.wall_s
            totals["log"] += r.duration_s
            totals["patches"] += n_patch
            totals["solve_s"] += n_patch / rate
            print(f"{name:20s} {n_patch:7d} {r.wall_s * 1e3:8.1f} {n_patch / r.wall_s:8.0f} "
                  f"{r.speed:7.1f} {reference[name].speed:14.1f} {rate:13.0f} "
                  f"{100 * n_patch / r.wall_s / rate:5.1f}%")
        if not totals["patches"]:
            totals["wall"] = totals["solve_s"] = math.nan
        all_rate = totals["patches"] / totals["wall"]
        solver_rate = totals["patches"] / totals["solve_s"]
        print(f"{'all, in turn':20s} {totals['patches']:7d} {totals['wall'] * 1e3:8.1f} "
              f"{all_rate:8.0f} {totals['log'] / totals['wall']:7.1f} {'':14s} "
              f"{solver_rate:13.0f} {100 * all_rate / solver_rate:5.1f}%\n")

        print("2. where the batched replay's time goes (its best run): share of wall time; "
              "us per input message")
        print(f"{'bag':20s}" + "".join(f" {k[:6]:>7s}" for k in PHASES + ("rest",)))
        for name, (r, _) in results.items():
            phases = r.profile.phases
            known = [phases.get(k, 0.0) for k in PHASES]
            rest = r.wall_s - sum(known) - phases.get("csv", 0.0)
            shares = known + [rest]
            print(f"{name:20s}" + "".join(f" {100 * v / r.wall_s:6.0f}%" for v in shares))
            per = [v / r.messages_in * 1e6 for v in shares]
            print(f"{'  us/msg':20s}" + "".join(f" {v:7.2f}" for v in per))
        print("  (read: chunk reads, decompression, record scan; copy: the input's chunks as "
              "they are;\n   decode: twists, patch layouts, compiled scan and fit; write: "
              "records, compression, summary, metadata)\n")

        print(f"3. many bags: {args.copies} copies each of {', '.join(SAME_CONTACTS)} "
              f"(one --params), fastsim_replay --jobs N")
        walls: dict[int, list[float]] = {1: [], 2: []}
        for k in range(args.rounds):   # alternating, best of the rounds
            for jobs in (1, 2):
                run = out / f"many{k}"
                run.mkdir(exist_ok=True)
                wall, patches, log_s = many_bags(args.copies, jobs, run)
                walls[jobs].append(wall)
        for jobs in (1, 2):
            wall = min(walls[jobs])
            print(f"  --jobs {jobs}: {3 * args.copies} bags, {patches} patches in {wall:.2f} s "
                  f"(best of {args.rounds}; median {sorted(walls[jobs])[args.rounds // 2]:.2f}"
                  f" s): {patches / wall:.0f} patches/s, {log_s / wall:.1f}x real time")
        print(f"  speed-up --jobs 2 / --jobs 1: {min(walls[1]) / min(walls[2]):.2f}x (best of "
              f"each); the machine's own, two processes of pure Python against one in turn: "
              f"{parallel_capacity():.2f}x\n")
        mcap_layers(list(args.bags), mcap_rounds, out, args.mcap_before)
    print(f"\nmachine: {machine()}")
    return 0


def small_bag(path: Path, seconds: float = 0.5) -> None:
    """Write the first ``seconds`` of hertz_ramp as a bag (MCAP, zstd chunks)."""
    from rosbags.rosbag2 import Writer
    from rosbags.rosbag2.enums import CompressionFormat, CompressionMode, StoragePlugin
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with Reader(BAGS / "hertz_ramp") as reader, writer:
        conns = {c.id: writer.add_connection(c.topic, c.msgtype, msgdef=c.msgdef.data,
                                             rihs01=c.digest,
                                             offered_qos_profiles=c.ext.offered_qos_profiles)
                 for c in reader.connections}
        end = reader.start_time + round(seconds * 1e9)
        for conn, t, raw in reader.messages(stop=end):
            writer.write(conns[conn.id], t, raw)


def timed(executor: Any, tasks: list[Any]) -> tuple[float, float]:
    """Run the tasks; return the wall time and the sum of the tasks' own replay times (s)."""
    t0 = time.perf_counter()
    results = list(executor.results(tasks))
    wall = time.perf_counter() - t0
    bad = [r.error for r in results if not r.ok]
    if bad:
        raise SystemExit(f"replay failed: {bad[0]}")
    return wall, sum(r.wall_s for r in results)


def cpu_seconds(pids: dict[str, Any]) -> dict[str, float]:
    """Return the CPU time (s) so far of the scheduler, the workers and this process (client)."""
    import resource

    def of(pid: int) -> float:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    me = resource.getrusage(resource.RUSAGE_SELF)
    return {"scheduler": of(pids["scheduler"]),
            "workers": sum(of(p) for p in pids["workers"]),
            "client": me.ru_utime + me.ru_stime}


def cluster_main(count: int, rounds: int = 3) -> int:
    """Run the ``--scheduler`` benchmark: a local cluster of two workers against ``--jobs 2``."""
    from fastsim_ros.replay.cluster import Cluster, LocalProcesses, warm_worker
    from fastsim_ros.replay.executors import LocalPool
    from fastsim_ros.replay.run import Task
    print(f"machine: {machine()}")
    warm_worker()
    values = load_params_file(BAGS / "hertz_ramp.params.yaml")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        small_bag(out / "small")
        (out / "in").mkdir()
        for k in range(count):
            (out / "in" / f"b{k:04d}").symlink_to(out / "small", target_is_directory=True)
        with Reader(out / "small") as reader:
            log_s = reader.duration * 1e-9
            messages = reader.message_count

        def tasks(run: str) -> list[Any]:
            target = out / run
            target.mkdir()
            return [Task(out / "in" / f"b{k:04d}", f"b{k:04d}", target, values, tag=run)
                    for k in range(count)]

        print(f"{count} bags of {log_s:.3f} s, {messages} messages each; {rounds} rounds, "
              "the executors alternating (best and median of the rounds)\n")
        cluster = LocalProcesses(out, 2, env=env, cwd=ROOT)
        pids = {"scheduler": cluster.procs[0].pid,
                "workers": [w.pid for w in cluster.workers]}
        try:
            makers = {"--jobs 2": lambda: LocalPool(2),
                      "--scheduler, 2 workers": lambda: Cluster(cluster.address)}
            runs: dict[str, list[tuple[float, float, dict[str, float]]]] = {m: [] for m in makers}
            for label, make in makers.items():   # one untimed run each
                executor = make()
                try:
                    timed(executor, tasks(f"{label[2:6]}-warm"))
                finally:
                    executor.close()
            for k in range(rounds):
                for label, make in makers.items():
                    executor = make()
                    before = cpu_seconds(pids)
                    try:
                        wall, inside = timed(executor, tasks(f"{label[2:6]}-{k}"))
                    finally:
                        executor.close()
                    after = cpu_seconds(pids)
                    runs[label].append((wall, inside, {w: after[w] - before[w] for w in after}))
        finally:
            cluster.close()
        for label, got in runs.items():
            walls = sorted(w for w, _, _ in got)
            wall, inside, cpu = min(got, key=lambda r: r[0])
            line = (f"{label:24s} {wall:6.2f} s (median {walls[len(walls) // 2]:.2f}): "
                    f"{count / wall:6.1f} bags/s, {count * log_s / wall:7.1f}x real time; "
                    f"overhead per bag {(2 * wall - inside) / count * 1e3:6.2f} ms "
                    f"(the tasks themselves {inside / count * 1e3:.2f} ms each)")
            if label.startswith("--scheduler"):
                line += ("\n" + " " * 25 + "CPU per bag: "
                         + ", ".join(f"{w} {v / count * 1e3:.2f} ms" for w, v in cpu.items()))
            print(line)
        best = {label: min(w for w, _, _ in got) for label, got in runs.items()}
        median = {label: sorted(w for w, _, _ in got)[len(got) // 2]
                  for label, got in runs.items()}
        jobs, dask = "--jobs 2", "--scheduler, 2 workers"
        print(f"\ntwo Dask workers / --jobs 2 throughput: {best[jobs] / best[dask]:.2f}x "
              f"(best of each), {median[jobs] / median[dask]:.2f}x (medians)")
    print(f"\nmachine: {machine()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
