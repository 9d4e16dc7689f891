#!/usr/bin/env python3
"""Measure ``fastsim_replay``: throughput, --jobs scaling, and where the time goes.

Usage (from the package root)::

    .venv/bin/python benchmarks/bench_replay.py [--repeats R] [--copies K] [--bags NAME ...]

Prints, with the machine line:

1. per bundled bag (its ``bags/<name>.params.yaml``), best of ``R`` replays
   in this process: patch messages per second and the multiple of real time
   (log duration / wall time) of a whole replay (open, read, solve, write,
   close); beside it the batch solver's own rate on the same patches
   (``MaeSolver.solve_batch``, one call per patch shape);
2. the breakdown of one replay's wall time into reading (the reader's next
   message: MCAP chunk decompression and record parsing), copying the input
   message to the output, the pipeline (CDR decode, patch adaptation,
   kinematics, solve), of which the solve alone (``solve_arrays`` re-timed
   on the same patches and creepages), building and serializing the output
   messages, writing them, and the rest (opening, connections, diagnostics,
   closing), with per-message medians and p99;
3. many bags (``K`` copies of each bag that uses the default contacts,
   replayed through ``fastsim_replay.main`` with ``--jobs 1`` and
   ``--jobs 2``): patches per second and the speed-up.

Nothing is written outside a temporary directory.  Timings on a shared
2-core VM drift between runs: quote the machine line and the load average.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from rosbags.rosbag2 import Reader

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench_fastsim import machine  # noqa: E402  (one machine line for every benchmark)
from fastsim_ros import replay  # noqa: E402
from fastsim_ros.contact import compiled  # noqa: E402
from fastsim_ros.contact.compiled import MaeSolver  # noqa: E402
from fastsim_ros.params import load_params_file  # noqa: E402

BAGS = ROOT / "bags"
NAMES = ("hertz_ramp", "semi_ellipses_spin", "flange_shift", "roller_rig", "bad_inputs")
#: bags whose params use the default contacts (left, right): one --params for all
SAME_CONTACTS = ("hertz_ramp", "semi_ellipses_spin", "bad_inputs")
PHASES = ("read", "copy", "pipeline", "emit", "write")


def _us(values_ns) -> tuple[float, float]:
    a = np.frombuffer(values_ns, dtype=np.int64) / 1e3 if len(values_ns) else np.zeros(1)
    return float(np.median(a)), float(np.percentile(a, 99))


def _sum_s(values_ns) -> float:
    return float(np.frombuffer(values_ns, dtype=np.int64).sum()) * 1e-9 if len(values_ns) \
        else 0.0


def solve_times(inputs, mu: float) -> np.ndarray:
    """Return the wall time (s) of ``solve_arrays`` on each ``(patch, creepage)``."""
    solver = MaeSolver(0.28, 8.0e10)
    out = np.empty(len(inputs))
    clock = time.perf_counter_ns
    for k, (p, c) in enumerate(inputs):
        t0 = clock()
        solver.solve_arrays(p.pressure, p.x0, p.y0, p.dx, p.dy, c.xi, c.eta, c.phi, mu)
        out[k] = (clock() - t0) * 1e-9
    return out


def batch_rate(inputs, mu: float, repeats: int = 3) -> float:
    """Return patch solves per second of ``MaeSolver.solve_batch`` on the same patches."""
    solver = MaeSolver(0.28, 8.0e10)
    groups: dict[tuple[int, int], list] = {}
    for p, c in inputs:
        groups.setdefault(p.pressure.shape, []).append((p, c))
    batches = []
    for items in groups.values():
        batches.append((np.stack([p.pressure for p, _ in items]),
                        np.array([p.x0 for p, _ in items]), np.array([p.y0 for p, _ in items]),
                        np.array([p.dx for p, _ in items]), np.array([p.dy for p, _ in items]),
                        np.array([[c.xi, c.eta, c.phi] for _, c in items])))
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        for ps, x0, y0, dx, dy, cr in batches:
            solver.solve_batch(ps, x0, y0, dx, dy, cr, mu=mu)
        best = min(best, time.perf_counter() - t0)
    return len(inputs) / best


def one_bag(name: str, repeats: int, out: Path):
    """Replay one bag ``repeats`` times; return the best result (profiled)."""
    values = load_params_file(BAGS / f"{name}.params.yaml")
    best = None
    for k in range(repeats):
        r = replay.replay_bag(BAGS / name, f"{name}_{k}", out, values, progress=False,
                              profile=True)
        if not r.ok:
            raise SystemExit(f"replay of {name} failed: {r.error}")
        if best is None or r.wall_s < best.wall_s:
            best = r
    return best, values


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
            n = sum(c.msgcount for c in reader.connections if c.topic.endswith("/patch"))
            dur = reader.duration * 1e-9
        for k in range(copies):
            link = links / f"{name}_{k}"
            link.symlink_to(BAGS / name, target_is_directory=True)
            inputs.append(str(link))
            patches += n
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


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    ap.add_argument("--repeats", type=int, default=3, help="replays per bag (best is kept)")
    ap.add_argument("--copies", type=int, default=4,
                    help="copies of each default-contact bag in the many-bags run")
    ap.add_argument("--bags", nargs="+", default=list(NAMES), choices=NAMES)
    args = ap.parse_args(argv)
    print(f"machine: {machine()}")
    warm = compiled.warm_up()
    source = "from the disk cache" if warm < 5.0 else "compiled: the cache was cold"
    print(f"kernels ready in {warm:.2f} s ({source})\n")

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        results = {name: one_bag(name, args.repeats, out) for name in args.bags}

        print(f"1. one bag at a time (best of {args.repeats}; whole replay: open to close)")
        print(f"{'bag':20s} {'msgs':>5s} {'patches':>7s} {'wall s':>7s} {'patch/s':>8s} "
              f"{'x real':>7s} {'batch solve/s':>13s}")
        total_wall = total_log = 0.0
        for name, (r, values) in results.items():
            p = r.profile
            n_patch = len(p.pipeline)
            mu = float(values["friction_coefficient"])
            rate = batch_rate(p.solve_inputs, mu) if p.solve_inputs else float("nan")
            total_wall += r.wall_s
            total_log += r.duration_s
            print(f"{name:20s} {r.messages_in:5d} {n_patch:7d} {r.wall_s:7.3f} "
                  f"{n_patch / r.wall_s:8.0f} {r.speed:7.1f} {rate:13.0f}")
        print(f"{'all five, in turn':20s} {'':5s} {'':7s} {total_wall:7.3f} {'':8s} "
              f"{total_log / total_wall:7.1f}\n")

        print("2. where the time goes (the best replay of each bag): share of wall time; "
              "per message median / p99 (us)")
        header = "".join(f" {k:>15s}" for k in PHASES + ("solve", "rest"))
        print(f"{'bag':20s}{header}   overhead/msg")
        for name, (r, values) in results.items():
            p = r.profile
            solves = solve_times(p.solve_inputs, float(values["friction_coefficient"]))
            sums = {k: _sum_s(getattr(p, k)) for k in PHASES}
            sums["pipeline"] += _sum_s(p.twist)
            solve_s = float(solves.sum())
            rest = r.wall_s - sum(sums.values())
            shares = {k: v / r.wall_s for k, v in sums.items()}
            cells = []
            for k in PHASES:
                share = shares[k] - (solve_s / r.wall_s if k == "pipeline" else 0.0)
                cells.append(f" {100 * share:14.0f}%")
            cells.append(f" {100 * solve_s / r.wall_s:14.0f}%")
            cells.append(f" {100 * rest / r.wall_s:14.0f}%")
            overhead = (r.wall_s - solve_s) / r.messages_in * 1e6
            print(f"{name:20s}{''.join(cells)}   {overhead:8.1f} us")
            per = [_us(getattr(p, k)) for k in PHASES]
            s50, s99 = (float(np.median(solves)) * 1e6, float(np.percentile(solves, 99)) * 1e6) \
                if solves.size else (float("nan"), float("nan"))
            print(f"{'  per msg us':20s}" + "".join(f" {a:7.1f} / {b:5.0f}" for a, b in per)
                  + f" {s50:7.1f} / {s99:5.0f}")
        print("  (pipeline = pipeline calls of patches and twists minus the solve; per msg of"
              " pipeline, emit, write: per patch; read, copy: per input message;\n"
              "   overhead/msg = (wall - solve) / input messages, everything but the solve)\n")

        print(f"3. many bags: {args.copies} copies each of {', '.join(SAME_CONTACTS)} "
              f"(one --params), fastsim_replay --jobs N")
        walls = {}
        for jobs in (1, 2):
            wall, patches, log_s = many_bags(args.copies, jobs, out)
            walls[jobs] = wall
            print(f"  --jobs {jobs}: {3 * args.copies} bags, {patches} patches in {wall:.2f} s: "
                  f"{patches / wall:.0f} patches/s, {log_s / wall:.1f}x real time")
        print(f"  speed-up --jobs 2 / --jobs 1: {walls[1] / walls[2]:.2f}x")
    print(f"\nmachine: {machine()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
