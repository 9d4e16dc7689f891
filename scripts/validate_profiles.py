#!/usr/bin/env python3
"""Patches from profiles against CONTACT's Manchester benchmark A-2.2: validation_profiles.md.

For both wheels and the 21 poses of A-2.2 (S1002 on UIC60 1:40, shift 0..10
mm with yaw 0..24 mrad, the poses' roll and axle spin as CONTACT's .inp
files give them, 10 kN per wheel, V = 2 m/s, mu = 0.3, G = 82 GPa, nu =
0.28, 0.2 mm cells) the package's profile path
(:mod:`fastsim_ros.cli.wheelset`, the node's own pipeline) is run with the
exact solver, the calibrated MAE (the default), the paper's MAE and the
equivalent ellipse, each with its own vertical load balance, and compared
with CONTACT's published exact results (``fastsim_ros/data/mbench``) and,
on its three poses, with CONTACT's fast methods KPEC + FASTSIM and ANALYN +
FASTSIM.

What is compared, and how (the conventions of
:mod:`fastsim_ros.geometry.benchmark`):

- contact position and angle: CONTACT's reference point (its weighted
  centre, which the package computes too: ``reference`` in the JSON) and
  contact angle, where CONTACT has one region;
- N: the normal force of each patch;
- creepages: at CONTACT's point Q (the reference moved by the approach
  onto the wheel) in CONTACT's axes (``x`` along the track), from the
  pipeline's rigid-body formula; the package's own creepages are taken at
  its patch's pressure centroid with ``x`` along the wheelset, so they
  differ from these by the spin times the offset;
- forces: each wheel's total force of the rail on the wheel in the track
  frame, against CONTACT's, in per cent of mu N (N: CONTACT's).

Usage: ``python scripts/validate_profiles.py [--report-only] [--methods ...]``.
The full run takes about 15 minutes on 2 cores (the exact solver dominates);
``--report-only`` rewrites the report from docs/data/validation_profiles.json;
``--methods`` runs those methods and keeps the others' runs from that file
(the fast methods after a change of theirs, without the exact solver's
quarter of an hour).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from benchmarks.machine import machine  # noqa: E402  (the one machine line)
from fastsim_ros import cli  # noqa: E402
from fastsim_ros.cli.wheelset import result_of, solve_pose, wheel_twist  # noqa: E402
from fastsim_ros.geometry import benchmark  # noqa: E402
from fastsim_ros.geometry.placement import rotation  # noqa: E402
from msg_adapters.kinematics import creepages  # noqa: E402
from msg_adapters.patch import ContactFrame  # noqa: E402

DOCS = ROOT / "docs"
DATA = DOCS / "data" / "validation_profiles.json"
FIG = DOCS / "figures"
REPORT = DOCS / "validation_profiles.md"
METHODS = ("exact", "mae_calibrated", "mae", "fastsim_ellipse", "polach")
DEFAULT = "mae_calibrated"
LABEL = {"exact": "exact", "mae_calibrated": "calibrated MAE", "mae": "paper's MAE",
         "fastsim_ellipse": "equiv. ellipse", "polach": "Polach", "kpec": "CONTACT KPEC+FASTSIM",
         "analyn": "CONTACT ANALYN+FASTSIM"}
TARGET = {"position": 0.5e-3, "angle": 0.01, "n": 0.01, "creepage": 0.02, "creepage_abs": 1e-5,
          "exact": 5.0, "default": 10.0}


def pose_args(case: benchmark.CaseResult, method: str) -> argparse.Namespace:
    """Return the ``fastsim_contact wheelset`` arguments of an A-2.2 wheel-pose."""
    return cli.build_parser().parse_args([
        "wheelset", "--dy", repr(case.dy), "--yaw", repr(case.yaw), "--roll", repr(case.roll),
        "--load", repr(benchmark.LOAD), "--speed", repr(case.forward_speed),
        "--axle-spin", repr(case.axle_spin), "--mu", repr(benchmark.MU),
        "--shear-modulus", repr(benchmark.SHEAR_MODULUS), "--nu", repr(benchmark.POISSON),
        "--cell", repr(benchmark.CELL), "--method", method])


def solve_case(case: benchmark.CaseResult, method: str) -> dict[str, Any]:
    """One wheel of one pose: the package's numbers in the benchmark's terms."""
    args = pose_args(case, method)
    start = time.perf_counter()
    cycle, pipeline = solve_pose(args, case.dy, case.yaw)
    seconds = time.perf_counter() - start
    result = result_of(cycle, pipeline, method)
    assert cycle.contact is not None
    pose = cycle.contact.pose
    rot = rotation(pose.roll, pose.yaw)
    centre = np.array([0.0, pose.dy, pipeline.wheelset.placement.nominal_radius + pose.dz])
    twist = wheel_twist(pose, case.forward_speed, case.axle_spin, 0.0, 0.0)
    wheel = next(w for w in result["wheels"] if w["side"] == case.side)
    geometry = next(w for w in cycle.contact.wheels if w.side == case.side)
    ordered = sorted(geometry.patches, key=lambda p: -p.region.reference[1])
    patches = []
    for p, wp in zip(wheel["patches"], ordered):
        # CONTACT's point Q and axes: x along the track, z the plane's normal
        normal_t = np.asarray(wp.normal_track)
        q_t = np.asarray(wp.reference) - wp.approach * normal_t
        ex_t = np.array([1.0, 0.0, 0.0]) - normal_t[0] * normal_t
        ex_t /= np.linalg.norm(ex_t)
        axes_w = tuple(tuple(float(v) for v in rot.T @ a)
                       for a in (ex_t, np.cross(normal_t, ex_t), normal_t))
        q_w = rot.T @ (q_t - centre)
        creep = creepages(ContactFrame((float(q_w[0]), float(q_w[1]), float(q_w[2])),
                                       axes_w), twist)  # type: ignore[arg-type]
        patches.append({**p, "cxi": creep.xi, "ceta": creep.eta, "cphi": creep.phi,
                        "cV": creep.speed, "region_y": list(wp.region.y_range)})
    return {"side": case.side, "case": case.number, "method": method, "seconds": seconds,
            "force_track": wheel["force_track"], "dz": wheel["dz"], "patches": patches,
            "pressure": _pressure_picture(ordered) if method == "exact" else []}


def _pressure_picture(patches: list[Any]) -> list[dict[str, Any]]:
    """Return the patches' pressure on their planar grids (for the figure), in MPa."""
    out = []
    for wp in patches:
        g = wp.grid
        out.append({"x0": g.x0, "s0": g.s0, "dx": g.dx, "ds": g.ds,
                    "p": np.round(wp.pressure / 1e6, 2).tolist()})
    return out


def compute(methods: tuple[str, ...], cases: tuple[int, ...]) -> dict[str, Any]:
    results: dict[str, Any] = {"machine": machine(), "runs": []}
    for side in ("left", "right"):
        for case in benchmark.a22(side):
            if case.number not in cases:
                continue
            for method in methods:
                try:
                    run = solve_case(case, method)
                except Exception as e:  # report it, do not hide a pose
                    run = {"side": side, "case": case.number, "method": method,
                           "error": f"{type(e).__name__}: {e}"}
                results["runs"].append(run)
                msg = run.get("error") or f"{run['seconds']:.1f} s"
                print(f"{side} {case.number:2d} {method:16s} {msg}", flush=True)
    return results


# ----------------------------------------------------------------------------- report

def _run(results: dict[str, Any], side: str, case: int, method: str) -> dict[str, Any] | None:
    for r in results["runs"]:
        if r["side"] == side and r["case"] == case and r["method"] == method:
            return r if "error" not in r else None
    return None


def _error(run: dict[str, Any] | None, ref: benchmark.CaseResult) -> float:
    """Largest error of the wheel's track force, % of mu N (N: CONTACT's)."""
    if run is None:
        return math.nan
    mu_n = benchmark.MU * sum(p.n for p in ref.patches)
    return 100.0 * max(abs(a - b) for a, b in zip(run["force_track"][:2], ref.force_track[:2])) \
        / mu_n


def _creep_ok(mine: float, theirs: float) -> bool:
    return abs(mine - theirs) <= max(TARGET["creepage"] * abs(theirs), TARGET["creepage_abs"])


def report(results: dict[str, Any]) -> str:
    lines: list[str] = []
    add = lines.append
    add("# Patches from profiles: the Manchester benchmark A-2.2 against CONTACT")
    add("")
    add("Made by `python scripts/validate_profiles.py` (data: "
        "`docs/data/validation_profiles.json`); machine: " + results["machine"] + ".")
    add("")
    add("S1002 on UIC60 1:40, 10 kN per wheel, V = 2 m/s, mu = 0.3, G = 82 GPa, nu = 0.28, "
        "0.2 mm cells, the 21 poses of A-2.2 (shift 0..10 mm, yaw 0..24 mrad, roll and axle "
        "spin as in CONTACT's `.inp` files); CONTACT's published outputs "
        "(`mbench_a22_left/right.ref_out`, its exact solver, and `mbench_a22_kpec.ref_out`, "
        "its fast methods) are the reference.  The package's numbers come from the node's "
        "own pipeline in profiles mode (`fastsim_contact wheelset`), each method with its "
        "own vertical load balance.  Conventions: `fastsim_ros/geometry/benchmark.py`; what "
        "is compared: this script's docstring.")
    add("")
    sides = {s: benchmark.a22(s) for s in ("left", "right")}
    # ---- targets
    pos_err, ang_err, n_err, cr_miss, worst = [], [], [], [], {m: (0.0, "") for m in METHODS}
    for side, cases in sides.items():
        for ref in cases:
            ex = _run(results, side, ref.number, "exact")
            for m in METHODS:
                e = _error(_run(results, side, ref.number, m), ref)
                if math.isfinite(e) and e > worst[m][0]:
                    worst[m] = (e, f"{side} {ref.number}")
            if ex is None:
                continue
            one = len(ref.patches) == 1 and len(ex["patches"]) == 1
            for mine, theirs in zip(ex["patches"], ref.patches):
                if one:
                    pos_err.append(max(abs(mine["reference"][1] - theirs.reference[1]),
                                       abs(mine["reference"][2] - theirs.reference[2])))
                    ang_err.append(abs(mine["contact_angle"] - theirs.angle))
                n_err.append(abs(mine["N"] - theirs.n) / theirs.n)
                for k, ck in (("cxi", "xi"), ("ceta", "eta"), ("cphi", "phi")):
                    if not _creep_ok(mine[k], getattr(theirs, ck)):
                        cr_miss.append(f"{side} {ref.number} {ck}")
    add("## Targets")
    add("")
    add("| what | target | measured | met |")
    add("| --- | --- | --- | --- |")
    if pos_err:
        add(f"| contact position (one-region poses) | 0.5 mm | largest {max(pos_err) * 1e3:.3f} mm"
            f" | {'yes' if max(pos_err) <= TARGET['position'] else 'no'} |")
        add(f"| contact angle (one-region poses) | 0.01 rad | largest {max(ang_err):.4f} rad | "
            f"{'yes' if max(ang_err) <= TARGET['angle'] else 'no'} |")
    if n_err:
        add(f"| N (exact run) | 1% | largest {100 * max(n_err):.2f}% | "
            f"{'yes' if max(n_err) <= TARGET['n'] else 'no'} |")
    add(f"| creepages at CONTACT's point (exact run) | 2% or 1e-5 | {len(cr_miss)} of "
        f"{3 * len(n_err)} outside | {'yes' if not cr_miss else 'no'} |")
    add(f"| exact forces, track frame | 5% of mu N | worst {worst['exact'][0]:.1f}% "
        f"({worst['exact'][1]}) | {'yes' if worst['exact'][0] <= TARGET['exact'] else 'no'} |")
    add(f"| default method (calibrated MAE) | 10% of mu N | worst {worst[DEFAULT][0]:.1f}% "
        f"({worst[DEFAULT][1]}) | {'yes' if worst[DEFAULT][0] <= TARGET['default'] else 'no'} |")
    if cr_miss:
        add("")
        add("Creepages outside the target: " + ", ".join(cr_miss) + ".")
    add("")
    add("Worst track-force error per method (% of mu N over both wheels and 21 poses): "
        + "; ".join(f"{LABEL[m]} {worst[m][0]:.1f} ({worst[m][1]})" for m in METHODS) + ".")
    add("")
    # ---- fast methods of CONTACT
    add("## Against CONTACT's fast methods (right wheel, its three poses)")
    add("")
    add("Error of the right wheel's track force against CONTACT's exact result, % of mu N "
        "(largest of Fx, Fy):")
    add("")
    add("| pose | " + " | ".join(LABEL[m] for m in ("kpec", "analyn") + METHODS) + " |")
    add("| --- " * (3 + len(METHODS)) + "|")
    fast = benchmark.a22_fast_methods()
    right = {c.number: c for c in sides["right"]}
    closer = True
    for number in (1, 2, 11):
        ref = right[number]
        row = [f"{number} (dy {-ref.dy * 1e3:.1f} mm)"]
        theirs = []
        for kind in ("kpec", "analyn"):
            c = next((f for f in fast if f.normal_method == kind
                      and benchmark.pose_number(f) == number), None)
            if c is None:
                row.append("-")
                continue
            mu_n = benchmark.MU * sum(p.n for p in ref.patches)
            e = 100.0 * max(abs(a - b) for a, b in zip(c.force_track[:2], ref.force_track[:2])) \
                / mu_n
            theirs.append(e)
            row.append(f"{e:.1f}")
        for m in METHODS:
            e = _error(_run(results, "right", number, m), ref)
            row.append(f"{e:.1f}")
            if m == DEFAULT and theirs and not e < min(theirs):
                closer = False
        add("| " + " | ".join(row) + " |")
    add("")
    add(f"The default method {'is' if closer else 'is not'} closer to CONTACT's exact results "
        "than both of CONTACT's fast methods on all three poses.")
    add("")
    # ---- per pose tables
    for side, cases in sides.items():
        add(f"## {side.capitalize()} wheel, pose by pose")
        add("")
        add("Reference point and angle (package / CONTACT), N, and the track force of the rail "
            "on the wheel (kN).")
        add("")
        add("| pose | y (mm) | z (mm) | angle (rad) | N (kN) | Fx, Fy exact | Fx, Fy "
            "cal. MAE | Fx, Fy CONTACT | err exact / cal. / MAE / ellipse (% mu N) |")
        add("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        for ref in cases:
            ex = _run(results, side, ref.number, "exact")
            de = _run(results, side, ref.number, DEFAULT)
            cells = [f"{ref.number} ({-ref.dy * 1e3:.1f})"]
            if ex is None:
                cells += ["-"] * 4
            else:
                cells.append(" ; ".join(f"{p['reference'][1] * 1e3:.2f}/{t.reference[1] * 1e3:.2f}"
                                        for p, t in zip(ex["patches"], ref.patches)))
                cells.append(" ; ".join(
                    f"{p['reference'][2] * 1e3:.3f}/{t.reference[2] * 1e3:.3f}"
                    for p, t in zip(ex["patches"], ref.patches)))
                cells.append(" ; ".join(f"{p['contact_angle']:.4f}/{t.angle:.4f}"
                                        for p, t in zip(ex["patches"], ref.patches)))
                cells.append(" ; ".join(f"{p['N'] / 1e3:.3f}/{t.n / 1e3:.3f}"
                                        for p, t in zip(ex["patches"], ref.patches)))
            for run in (ex, de):
                cells.append("-" if run is None else ", ".join(
                    f"{v / 1e3:.3f}" for v in run["force_track"][:2]))
            cells.append(f"{ref.force_track[0] / 1e3:.3f}, {ref.force_track[1] / 1e3:.3f}")
            cells.append(" / ".join(f"{_error(_run(results, side, ref.number, m), ref):.1f}"
                                    for m in METHODS))
            add("| " + " | ".join(cells) + " |")
        add("")
        add("Creepages at CONTACT's point Q in its axes, exact run (package / CONTACT):")
        add("")
        add("| pose | xi | eta | phi (1/m) | V (m/s) |")
        add("| --- | --- | --- | --- | --- |")
        for ref in cases:
            ex = _run(results, side, ref.number, "exact")
            if ex is None:
                continue
            add(f"| {ref.number} | " + " | ".join(
                " ; ".join(f"{p[k]:.4g}/{getattr(t, ck):.4g}"
                           for p, t in zip(ex["patches"], ref.patches))
                for k, ck in (("cxi", "xi"), ("ceta", "eta"), ("cphi", "phi"), ("cV", "speed")))
                + " |")
        add("")
    add("## Figures")
    add("")
    add("![forces against the shift](figures/profiles_forces.png)")
    add("")
    add("![patches](figures/profiles_patches.png)")
    add("")
    return "\n".join(lines) + "\n"


def figures(results: dict[str, Any]) -> None:
    FIG.mkdir(parents=True, exist_ok=True)
    sides = {s: benchmark.a22(s) for s in ("left", "right")}
    fig, axes = plt.subplots(2, 2, figsize=(12, 8), sharex=True)
    styles = {"exact": "-o", "mae_calibrated": "-s", "mae": "--", "fastsim_ellipse": ":",
              "polach": "-."}
    for col, side in enumerate(("left", "right")):
        cases = sides[side]
        shift = [-c.dy * 1e3 for c in cases]
        for row, k in enumerate((0, 1)):
            ax = axes[row][col]
            ax.plot(shift, [c.force_track[k] / 1e3 for c in cases], "k-", lw=2.5, alpha=0.4,
                    label="CONTACT exact")
            for m in METHODS:
                vals = []
                for c in cases:
                    r = _run(results, side, c.number, m)
                    vals.append(r["force_track"][k] / 1e3 if r else math.nan)
                ax.plot(shift, vals, styles[m], ms=3, label=LABEL[m])
            ax.set_title(f"{side} wheel, F{'xy'[k]} of the rail on the wheel (track frame)")
            ax.set_ylabel("kN")
            if row == 1:
                ax.set_xlabel("lateral shift to the right, Y_WS (mm)")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(FIG / "profiles_forces.png", dpi=100)
    plt.close(fig)
    picks = [("left", 1), ("left", 14), ("right", 2), ("right", 11), ("right", 13),
             ("right", 14)]
    fig, axes = plt.subplots(2, 3, figsize=(13, 7))
    for ax, (side, number) in zip(axes.ravel(), picks):
        run = _run(results, side, number, "exact")
        if run is None:
            continue
        for pic in run["pressure"]:
            p = np.asarray(pic["p"])
            ny, nx = p.shape
            x = (pic["x0"] + pic["dx"] * np.arange(nx)) * 1e3
            s = (pic["s0"] + pic["ds"] * np.arange(ny)) * 1e3
            ax.contourf(x, s, np.where(p > 0, p, np.nan), levels=12)
            ax.contour(x, s, (p > 0).astype(float), levels=[0.5], colors="k", linewidths=0.8)
        ax.set_title(f"{side} wheel, pose {number}: pressure (MPa)", fontsize=9)
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("s, along the plane (mm)")
        ax.set_aspect("equal", adjustable="datalim")
    fig.tight_layout()
    fig.savefig(FIG / "profiles_patches.png", dpi=100)
    plt.close(fig)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--report-only", action="store_true")
    parser.add_argument("--methods", nargs="+", choices=METHODS, default=list(METHODS))
    parser.add_argument("--cases", nargs="+", type=int, default=list(range(1, 22)),
                        help="poses to run (1..21; a partial run for checking the script)")
    args = parser.parse_args()
    if args.report_only:
        results = json.loads(DATA.read_text())
    else:
        results = compute(tuple(args.methods), tuple(args.cases))
        if set(args.methods) != set(METHODS) and DATA.exists():
            # a run of some methods: the others' runs stay as the data file has them
            kept = [r for r in json.loads(DATA.read_text())["runs"]
                    if r["method"] not in args.methods]
            results["runs"] = kept + results["runs"]
        DATA.parent.mkdir(parents=True, exist_ok=True)
        DATA.write_text(json.dumps(results))
    figures(results)
    REPORT.write_text(report(results))
    print(f"wrote {REPORT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
