#!/usr/bin/env python3
"""Speed of the profiles patch source: one wheelset pose, both wheels, and its parts.

For a few poses of the Manchester benchmark (S1002 on UIC60, 10 kN per
wheel, 0.2 mm cells unless ``--cell``) it times, interleaved in one run:

- ``pose (loads)``: :meth:`ProfilePipeline.on_pose` with the wheel loads
  given, what the node runs per cycle: contact search, planar grids, the
  normal problem, the vertical balance with the creep forces (the default
  method) and the four contacts' solves;
- ``pose (height)``: the same with the vertical position given (one pass);
- the parts of one pass: ``search`` (both wheels' contact locus and
  regions), ``grids`` (planar grids and their undeformed gap), ``normal``
  (the normal problem on each grid), ``tangential`` (the creep forces of
  each patch, the default method).

Prints medians and p99 (ms) with the machine.  Usage:
``python benchmarks/bench_geometry.py [--repeat N] [--cell H]``.

``--table POSES``: instead, the contact table's path
(``config/profiles_track_table.yaml``, the table read from its cache or
built): ``pose (table)``, :meth:`ProfilePipeline.on_pose` on ``POSES``
poses drawn over the range of A-2.2 (shift -10..10 mm, yaw within 24 mrad,
10 kN per wheel, the twist of A-2.2), each its own (no two poses alike, so
every one blends between nodes; ``--windows``: drawn inside the table's
yaw-refined windows around the flanges' take-overs instead); ``table lookup`` (the nodes' weights,
matching and blend plans, no resampling); and beside them, on a few of those
poses, ``pose (per pose)`` (the same pipeline without the table).
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from fastsim_ros.geometry import benchmark  # noqa: E402
from fastsim_ros.geometry.placement import Pose  # noqa: E402
from fastsim_ros.geometry.planar import planar_grid  # noqa: E402
from machine import machine  # noqa: E402  (the one machine line of every benchmark)
from fastsim_ros.pipeline import PipelineConfig  # noqa: E402
from fastsim_ros.pipeline.profiles import ProfilePipeline  # noqa: E402
from fastsim_ros.cli.wheelset import wheel_twist  # noqa: E402
from msg_adapters.patch import patch_from_cloud  # noqa: E402
from msg_adapters.profile_msgs import StampedPose, patch_cloud, quaternion  # noqa: E402

#: A-2.2 poses: centred on the treads, 5 mm (the right gauge corner), 7 mm (the flange)
POSES = (1, 11, 15)


def timed(fn: Callable[[], object], repeat: int) -> np.ndarray:
    out = np.empty(repeat)
    for k in range(repeat):
        t = time.perf_counter()
        fn()
        out[k] = time.perf_counter() - t
    return out * 1e3


def table_rows(poses: int, per_pose: int, windows: bool = False) -> None:
    """Time the table's path on ``poses`` poses and the per-pose path on ``per_pose`` of them.

    ``windows``: the poses drawn inside the table's yaw-refined windows (a
    rig dwelling at a flange's take-over) instead of over A-2.2's range.
    """
    from fastsim_ros.ros.params import load_params_file
    from msg_adapters.cdr import StampedTwist

    values = load_params_file(ROOT / "config" / "profiles_track_table.yaml")
    start = time.perf_counter()
    tabled = ProfilePipeline(PipelineConfig.from_values(values), log=print)
    print(f"table ready in {time.perf_counter() - start:.2f} s "
          f"({len(tabled.table.nodes) if tabled.table else 0} nodes)")
    solved = ProfilePipeline(PipelineConfig.from_values({**values, "profile_table": False}))
    rng = np.random.default_rng(7)
    dys = rng.uniform(-10e-3, 10e-3, poses)
    yaws = -2.4 * dys * rng.uniform(0.5, 1.0, poses)   # yaws as much as 2.4 mrad/mm
    if windows:
        assert tabled.table is not None
        boxes = [w.grid for v in tabled.table.refined.values() for w in v]
        print(f"poses inside the {len(boxes)} yaw-refined windows")
        pick = rng.integers(0, len(boxes), poses)
        dys = np.array([rng.uniform(boxes[k].dys[0], boxes[k].dys[-1]) for k in pick])
        yaws = np.array([rng.uniform(boxes[k].yaws[0], boxes[k].yaws[-1]) for k in pick])
    stamp = [0]

    def cycle(p: ProfilePipeline, dy: float, yaw: float) -> str:
        stamp[0] += 1
        pose = Pose(dy, 0.0, yaw, 0.0)
        twist = wheel_twist(pose, 2.0, 2.0 / 0.46, 0.0, 0.0)
        p.on_wheel_twist(StampedTwist(stamp[0], twist.frame_id, twist.linear, twist.angular))
        out = p.on_pose(StampedPose(stamp[0], "track", (0.0, dy, 0.0), quaternion(0.0, yaw)))
        return out.outcomes[0].status

    cycle(tabled, 0.0, 0.0)
    cycle(solved, 0.0, 0.0)
    statuses: dict[str, int] = {}
    table_t, lookup_t, solved_t = [], [], []
    every = max(1, poses // max(per_pose, 1))
    for k, (dy, yaw) in enumerate(zip(dys, yaws)):
        t0 = time.perf_counter()
        status = cycle(tabled, float(dy), float(yaw))
        t1 = time.perf_counter()
        statuses[status] = statuses.get(status, 0) + 1
        assert tabled.table is not None
        tabled.table.lookup(float(dy), float(yaw))
        t2 = time.perf_counter()
        table_t.append(t1 - t0)
        lookup_t.append(t2 - t1)
        if per_pose and k % every == 0:
            t3 = time.perf_counter()
            cycle(solved, float(dy), float(yaw))
            solved_t.append(time.perf_counter() - t3)
    print(f"{'what':>18s} {'poses':>6s} {'median':>9s} {'p99':>9s} {'max':>9s}  (ms)")
    for name, t in (("pose (table)", table_t), ("table lookup", lookup_t),
                    ("pose (per pose)", solved_t)):
        if t:
            a = np.array(t) * 1e3
            print(f"{name:>18s} {a.size:6d} {np.median(a):9.3f} {np.percentile(a, 99):9.3f} "
                  f"{a.max():9.3f}")
    print("left wheel's status over the table's poses: "
          + ", ".join(f"{k} {v}" for k, v in sorted(statuses.items())))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20)
    parser.add_argument("--cell", type=float, default=2e-4)
    parser.add_argument("--table", type=int, default=0, metavar="POSES",
                        help="time the contact table's path on POSES poses instead")
    parser.add_argument("--windows", action="store_true",
                        help="with --table: the poses inside the yaw-refined windows")
    parser.add_argument("--per-pose", type=int, default=20, metavar="N",
                        help="with --table: N of the poses also solved without the table")
    args = parser.parse_args()
    if args.table:
        print(f"machine: {machine()}")
        table_rows(args.table, args.per_pose, args.windows)
        return 0
    print(f"machine: {machine()}; cell {args.cell * 1e3:g} mm; {args.repeat} repeats, "
          "interleaved; times in ms")
    print(f"{'pose':>18s} {'what':>16s} {'median':>9s} {'p99':>9s}")
    for number in POSES:
        case = benchmark.a22("right")[number - 1]
        values = {"patch_source": "profiles", "shear_modulus": benchmark.SHEAR_MODULUS,
                  "poisson_ratio": benchmark.POISSON, "cell_size": args.cell}
        loaded = ProfilePipeline(PipelineConfig.from_values({**values, "wheel_load": 1e4}))
        height = ProfilePipeline(PipelineConfig.from_values({**values, "wheel_load": 0.0}))
        pose = Pose(case.dy, case.dz, case.yaw, case.roll)
        twist = wheel_twist(pose, case.forward_speed, case.axle_spin, 0.0, 0.0)
        msg = StampedPose(0, "track", (0.0, pose.dy, pose.dz), quaternion(pose.roll, pose.yaw))
        stamp = [0]

        def cycle(p: ProfilePipeline) -> None:
            stamp[0] += 1
            p.on_wheel_twist(twist.__class__(stamp[0], twist.frame_id, twist.linear,
                                             twist.angular))
            out = p.on_pose(msg.__class__(stamp[0], msg.frame_id, msg.position,
                                          msg.orientation))
            assert out.contact is not None, out.outcomes[0].detail

        cycle(loaded)  # warm: numba, caches
        cycle(height)
        ws = height.wheelset
        regions = {s: ws.regions(s, pose) for s in ("left", "right")}
        r0 = ws.placement.nominal_radius
        grids = [planar_grid(r, ws.rails[s], ws.wheels[s], ws.side_pose(s, pose), r0, ws.cell)
                 for s in ("left", "right") for r in regions[s]]
        patches = [p for s in ("left", "right") for p in ws.patches(s, pose)]
        clouds = [patch_cloud(0, "wheelset", p.points, p.normal, p.pressure) for p in patches]
        converted = [patch_from_cloud(c, max_cells=100_000) for c in clouds]

        parts: dict[str, Callable[[], object]] = {
            "pose (loads)": lambda: cycle(loaded),
            "pose (height)": lambda: cycle(height),
            "search": lambda: [ws.regions(s, pose) for s in ("left", "right")],
            "grids": lambda: [planar_grid(r, ws.rails[s], ws.wheels[s], ws.side_pose(s, pose),
                                          r0, ws.cell)
                              for s in ("left", "right") for r in regions[s]],
            "normal": lambda: [ws._normal.solve(g.gap - g.gap.min(), -float(g.gap.min()),
                                                g.dx, g.ds) for g in grids],
            "tangential": lambda: [height.pipeline.solve_patch(c, twist) for c in converted
                                   if c is not None],
        }
        samples: dict[str, list[np.ndarray]] = {k: [] for k in parts}
        for _ in range(args.repeat):
            for name, fn in parts.items():
                samples[name].append(timed(fn, 1))
        label = f"A-2.2 {number} ({-case.dy * 1e3:.1f} mm)"
        for name, runs in samples.items():
            t = np.concatenate(runs)
            print(f"{label:>18s} {name:>16s} {np.median(t):9.2f} {np.percentile(t, 99):9.2f}")
        cells = sum(g.gap.size for g in grids)
        print(f"{label:>18s} {'grids':>16s} {len(grids)} grid(s), {cells} cells")
    return 0


if __name__ == "__main__":
    sys.exit(main())
