"""``fastsim_contact wheelset``: a wheelset on its track, from profiles to creep forces.

docs/guide_profiles.md:
the wheelset is placed at a pose, each wheel's patches are found and their
normal problem solved (:mod:`fastsim_ros.geometry`), and the creep forces
come from the node's own pipeline in profiles mode
(:class:`~fastsim_ros.pipeline.profiles.ProfilePipeline`): the same code, the
same creepage formula, so the node answers a pose with these numbers.

The wheelset's twist is built from the flags in the wheelset frame: the
centre's velocity ``R^T (V, V_y, 0)`` and the angular velocity ``(0, W, 0) +
R^T (0, 0, yaw rate)`` (``W`` the axle spin, default ``V / R0``), the rail
at rest.  ``--load`` is the vertical load per wheel; without ``--roll`` the
roll is solved (both wheels carrying their loads at one height, or with
``--dz`` equal loads), and the answer is then the node's for the pose with
that roll.  ``--method exact`` solves the creep forces with the exact
theory instead (:mod:`fastsim_ros.contact.exact`, slow; the validation's
yardstick).
"""

from __future__ import annotations

import argparse
import csv
import math
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from fastsim_ros.cli import options
from fastsim_ros.ros import plausibility
from fastsim_ros.atomic import check_target, write_atomically
from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.compiled import ContactForces
from fastsim_ros.contact.errors import ContactError, InvalidInputError
from fastsim_ros.geometry.errors import GeometryError
from fastsim_ros.geometry.placement import Pose, rotation
from fastsim_ros.geometry.wheelset import WheelsetContact
from fastsim_ros.geometry.profiles import S1002, UIC60
from fastsim_ros.ros.params import ParameterError
from fastsim_ros.pipeline import PipelineConfig
from fastsim_ros.pipeline.profiles import ProfileCycle, ProfilePipeline, contact_name
from msg_adapters.cdr import StampedTwist
from msg_adapters.profile_msgs import StampedPose, quaternion

#: methods of ``wheelset``: the node's (compiled) and the exact theory
METHODS = ("mae_calibrated", "mae", "fastsim_ellipse", "polach", "exact")
#: the most cells a patch's grid may span on the command line (the exact solver's
#: dense operator is the limit of ``--method exact``)
MAX_PATCH_CELLS = 160_000
WHEELSET_FRAME, TRACK_FRAME = "wheelset", "track"


class ExactSolver:
    """The exact Coulomb solver with the compiled solvers' ``solve_arrays`` call."""

    def __init__(self, nu: float, shear_modulus: float) -> None:
        self.nu, self.shear_modulus = nu, shear_modulus

    def solve_arrays(self, pressure: Any, x0: float, y0: float, dx: float, dy: float,
                     xi: float, eta: float, phi: float, mu: float | None = None, *,
                     reference: tuple[float, float] = (0.0, 0.0), bound: str = "given",
                     tractions: bool = False, friction: Any = None,
                     speed: float | None = None) -> ContactForces:
        """Return the exact creep forces on the pressure grid (the given bound only)."""
        from fastsim_ros.contact import exact  # SciPy: only when asked for
        if bound != "given":
            raise InvalidInputError("the exact solver takes the pressure as given "
                                    "(--bound given)")
        area = GridArea(x0, y0, dx, dy, np.asarray(pressure, dtype=np.float64))
        sol = exact.coulomb(area, xi, eta, phi, mu=None if friction is not None else mu,
                            friction=friction, speed=speed, nu=self.nu,
                            shear_modulus=self.shear_modulus, reference=reference)
        contact = area.mask
        slip = float(np.count_nonzero(sol.slip & contact)) / max(1, int(contact.sum()))
        return ContactForces(sol.fx, sol.fy, sol.mz, area.load, slip)


def add_parser(sub: Any, finite: Any) -> None:
    """Add ``wheelset`` to the subcommands of ``fastsim_contact``."""
    p = sub.add_parser("wheelset", help="a wheelset on its track: patches and creep forces "
                       "from wheel and rail profiles")
    g = p.add_argument_group("profiles (default: the Manchester benchmark's S1002 on UIC60)")
    g.add_argument("--wheel", default=S1002, help="wheel profile (.prw or two-column y z)")
    g.add_argument("--rail", default=UIC60, help="rail profile (.prr or two-column y z)")
    g.add_argument("--right-wheel", default="", help="right wheel profile (default: mirror)")
    g.add_argument("--right-rail", default="", help="right rail profile (default: mirror)")
    g.add_argument("--smooth", type=finite, default=options.node_default("profile_smoothing"),
                   help="profile smoothing wavelength L_filt (m, 0: none; default %(default)g)")
    q = p.add_argument_group("pose and load")
    q.add_argument("--dy", type=finite, help="lateral shift (m, positive left)")
    q.add_argument("--yaw", type=finite, help="yaw angle (rad, about z)")
    q.add_argument("--roll", type=finite, help="roll angle (rad, about x; default: solved)")
    v = q.add_mutually_exclusive_group(required=True)
    v.add_argument("--load", type=finite, help="vertical load per wheel (N)")
    v.add_argument("--dz", type=finite, help="vertical position of the wheelset centre (m)")
    k = p.add_argument_group("kinematics (the rail at rest)")
    k.add_argument("--speed", type=finite, default=2.0, help="forward speed (m/s, default 2)")
    k.add_argument("--axle-spin", type=finite,
                   help="axle angular velocity about +y (rad/s; default V/R0)")
    k.add_argument("--lateral-speed", type=finite, default=0.0, help="lateral speed (m/s)")
    k.add_argument("--yaw-rate", type=finite, default=0.0, help="yaw rate (rad/s)")
    m = p.add_argument_group("material and solver")
    m.add_argument("--mu", type=finite, default=options.node_default("friction_coefficient"),
                   help="friction coefficient (default %(default)g, the node's)")
    options.add_material(m, finite)
    m.add_argument("--method", choices=METHODS, default=options.node_default("method"),
                   help="creep force method: the node's methods or exact; default "
                   "%(default)s, the node's")
    m.add_argument("--bound", choices=("given", "parabolic"),
                   default=options.node_default("traction_bound"),
                   help="traction bound of the fast methods (default %(default)s, the node's)")
    m.add_argument("--cell", type=finite, default=options.node_default("cell_size"),
                   help="cell size of the potential contact grid (m, default %(default)g, "
                   "the node's cell_size)")
    options.add_allow_implausible(m, ("wheel_load", "friction_coefficient", "shear_modulus"))
    t = p.add_argument_group("placement (default: the Manchester benchmark, the node's)")
    t.add_argument("--gauge-width", type=finite, default=options.node_default("gauge_width"),
                   help="track gauge (m, default %(default)g)")
    t.add_argument("--gauge-height", type=finite, default=options.node_default("gauge_height"),
                   help="gauge measuring depth below the rail top (m, default %(default)g)")
    t.add_argument("--cant", type=finite, default=options.node_default("cant"),
                   help="rail inclination added to the profile's (rad, default %(default)g)")
    t.add_argument("--flange-back-distance", type=finite,
                   default=options.node_default("flange_back_distance"),
                   help="(m, default %(default)g)")
    t.add_argument("--flange-back-position", type=finite,
                   default=options.node_default("flange_back_position"),
                   help="flange back in wheel profile coordinates (m, default %(default)g)")
    t.add_argument("--nominal-radius", type=finite, default=options.node_default("nominal_radius"),
                   help="(m, default %(default)g)")
    s = p.add_argument_group("sweep (instead of one pose)")
    s.add_argument("--sweep-dy", type=finite, nargs=3, metavar=("Y0", "Y1", "STEP"),
                   help="lateral shifts from Y0 to Y1 by STEP (m)")
    s.add_argument("--sweep-yaw", type=finite, nargs=2, metavar=("P0", "P1"),
                   help="yaw from P0 at Y0 to P1 at Y1, linearly (rad)")
    s.add_argument("-o", "--output", type=Path, help="the sweep's CSV")
    s.add_argument("--plot", type=Path, help="the sweep's figure (PNG)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def check_plausible(args: argparse.Namespace) -> None:
    """Refuse ``--load``, ``--mu`` or ``--shear-modulus`` implausible for wheel-rail contact.

    Before any pose is solved (:mod:`fastsim_ros.ros.plausibility`); the node's
    parameter ranges still bound what ``--allow-implausible`` accepts.
    """
    if args.load is not None and math.isfinite(args.load) and args.load > 0.0:
        # a load that is no load at all is refused by its own check, naming its range
        plausibility.check("wheel_load", args.load, what="--load",
                           allow=args.allow_implausible)
    options.check_plausible_material(args)


def _config(args: argparse.Namespace) -> PipelineConfig:
    values = {
        "patch_source": "profiles", "wheelset_frame": WHEELSET_FRAME, "track_frame": TRACK_FRAME,
        "wheel_profile": str(args.wheel), "rail_profile": str(args.rail),
        "right_wheel_profile": str(args.right_wheel), "right_rail_profile": str(args.right_rail),
        "profile_smoothing": args.smooth, "gauge_width": args.gauge_width,
        "gauge_height": args.gauge_height, "cant": args.cant,
        "flange_back_distance": args.flange_back_distance,
        "flange_back_position": args.flange_back_position,
        "nominal_radius": args.nominal_radius, "cell_size": args.cell,
        "shear_modulus": args.shear_modulus, "poisson_ratio": args.nu,
        "friction_coefficient": args.mu,
        "method": "mae" if args.method == "exact" else args.method,
        "traction_bound": args.bound, "max_patch_cells": MAX_PATCH_CELLS,
        "publish_markers": False, "allow_implausible": bool(args.allow_implausible),
    }
    try:
        return PipelineConfig.from_values(values)
    except ParameterError as e:
        raise _flag_error(e) from None


#: the node's parameter behind each flag of this command: its errors name the flag
FLAG_OF_PARAMETER = {
    "wheel_profile": "--wheel", "rail_profile": "--rail", "right_wheel_profile": "--right-wheel",
    "right_rail_profile": "--right-rail", "profile_smoothing": "--smooth",
    "gauge_width": "--gauge-width", "gauge_height": "--gauge-height", "cant": "--cant",
    "flange_back_distance": "--flange-back-distance",
    "flange_back_position": "--flange-back-position", "nominal_radius": "--nominal-radius",
    "cell_size": "--cell", "shear_modulus": "--shear-modulus", "poisson_ratio": "--nu",
    "friction_coefficient": "--mu", "method": "--method", "traction_bound": "--bound",
}


def _flag_error(error: ParameterError) -> InvalidInputError:
    """Return a parameter's error as this command's, naming the flag the user gave."""
    text = re.sub(r"parameter '(\w+)'",
                  lambda m: FLAG_OF_PARAMETER.get(m.group(1), m.group(0)), str(error))
    return InvalidInputError(text)


def wheel_twist(pose: Pose, speed: float, axle_spin: float, lateral_speed: float,
                yaw_rate: float) -> StampedTwist:
    """Return the wheelset twist in the wheelset frame (stamp 0) for track-frame rates."""
    rot = rotation(pose.roll, pose.yaw)
    v = rot.T @ np.array([speed, lateral_speed, 0.0])
    w = np.array([0.0, axle_spin, 0.0]) + rot.T @ np.array([0.0, 0.0, yaw_rate])
    return StampedTwist(0, WHEELSET_FRAME, (float(v[0]), float(v[1]), float(v[2])),
                        (float(w[0]), float(w[1]), float(w[2])))


def solve_pose(args: argparse.Namespace, dy: float,
               yaw: float) -> tuple[ProfileCycle, ProfilePipeline]:
    """Solve one pose as the node would; the pose's roll solved first when not given."""
    config = _config(args)
    solver = ExactSolver(args.nu, args.shear_modulus) if args.method == "exact" else None
    axle_spin = (args.speed / args.nominal_radius if args.axle_spin is None
                 else args.axle_spin)
    dz = 0.0 if args.dz is None else args.dz
    roll = args.roll
    try:
        if roll is None:
            # the roll first (both wheels carrying their loads at one height), then the
            # pose with that roll as the node would solve it
            scout = ProfilePipeline(config, solve_roll=True, solver=solver)
            cycle = _cycle(scout, Pose(dy, dz, yaw, 0.0), args, axle_spin)
            if cycle.contact is None:
                _refused(cycle)
            assert isinstance(cycle.contact, WheelsetContact)   # never a table here
            roll = cycle.contact.pose.roll
            dz = cycle.contact.pose.dz
        pipeline = ProfilePipeline(config, solver=solver)
        cycle = _cycle(pipeline, Pose(dy, dz, yaw, roll), args, axle_spin)
    except ParameterError as e:
        raise _flag_error(e) from None
    if cycle.contact is None:
        _refused(cycle)
    return cycle, pipeline


def _cycle(pipeline: ProfilePipeline, pose: Pose, args: argparse.Namespace,
           axle_spin: float) -> ProfileCycle:
    pipeline.on_wheel_twist(wheel_twist(pose, args.speed, axle_spin, args.lateral_speed,
                                        args.yaw_rate))
    if args.load is not None:
        if not (math.isfinite(args.load) and 0.0 < args.load <= 1e7):
            raise InvalidInputError(f"--load must lie in (0, 1e7] N, got {args.load}")
        pipeline.on_load(StampedTwist(0, WHEELSET_FRAME, (0.0, 0.0, 2.0 * args.load),
                                      (0.0, 0.0, 0.0)))
    msg = StampedPose(0, TRACK_FRAME, (0.0, pose.dy, pose.dz), quaternion(pose.roll, pose.yaw))
    return pipeline.on_pose(msg)


def _refused(cycle: ProfileCycle) -> None:
    first = cycle.outcomes[0]
    raise GeometryError(f"{first.status}: {first.detail}")


def result_of(cycle: ProfileCycle, pipeline: ProfilePipeline, method: str) -> dict[str, Any]:
    """Return the JSON object (docs/guide_cli.md) for one solved pose."""
    contact = cycle.contact
    assert isinstance(contact, WheelsetContact)   # the command line solves each pose
    pose = contact.pose
    rot = pose.rotation()
    centre = np.array([0.0, pose.dy, pipeline.wheelset.placement.nominal_radius + pose.dz])
    outcomes = {o.contact: o for o in cycle.outcomes}
    wheels = []
    for wheel in contact.wheels:
        patches = []
        total = np.zeros(3)
        ordered = sorted(wheel.patches, key=lambda p: -p.region.reference[1])
        for index, wp in enumerate(ordered):
            name = contact_name(wheel.side, index)
            o = outcomes[name]
            if o.forces is None or o.frame is None or o.creepage is None:
                raise GeometryError(f"{name}: {o.status}: {o.detail}")
            f = o.forces
            origin = centre + rot @ np.asarray(o.frame.origin)
            force = rot @ np.asarray(o.frame.to_wheelset((f.fx, f.fy, f.n)))
            total += force
            patches.append({
                "name": name, "x": float(origin[0]), "y": float(origin[1]),
                "z": float(origin[2]), "contact_angle": wp.angle, "N": f.n,
                "cells": wp.cells, "xi": o.creepage.xi, "eta": o.creepage.eta,
                "phi": o.creepage.phi, "V": o.creepage.speed, "Fx": f.fx, "Fy": f.fy,
                "Mz": f.mz, "penetration": wp.approach, "slip_fraction": f.slip_fraction,
                "reference": list(wp.reference), "force_track": [float(v) for v in force]})
        wheels.append({"side": wheel.side, "force_track": [float(v) for v in total],
                       "dz": wheel.dz, "patches": patches})
    return {"wheels": wheels, "roll": pose.roll, "dz": pose.dz, "dy": pose.dy, "yaw": pose.yaw,
            "method": method, "loads": list(cycle.loads) if cycle.loads else None}


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Run ``wheelset``: one pose, or a sweep written to ``-o``."""
    if not (args.cell > 0.0):
        raise InvalidInputError(f"--cell must be positive, got {args.cell}")
    check_plausible(args)
    if args.sweep_dy is None:
        if args.dy is None or args.yaw is None:
            raise InvalidInputError("give --dy and --yaw (or --sweep-dy)")
        if args.output is not None or args.plot is not None:
            raise InvalidInputError("-o and --plot belong to --sweep-dy")
        if args.sweep_yaw is not None:
            raise InvalidInputError("--sweep-yaw belongs to --sweep-dy")
        cycle, pipeline = solve_pose(args, args.dy, args.yaw)
        return result_of(cycle, pipeline, args.method)
    if args.dy is not None:
        raise InvalidInputError("give either --dy or --sweep-dy, not both")
    if args.yaw is not None and args.sweep_yaw is not None:
        raise InvalidInputError("give either --yaw or --sweep-yaw, not both")
    return sweep(args)


# --------------------------------------------------------------------- the sweep

SWEEP_COLUMNS = ("dy", "yaw", "roll", "dz", "side", "name", "status", "x", "y", "z",
                 "contact_angle", "N", "cells", "xi", "eta", "phi", "Fx", "Fy", "Mz",
                 "penetration", "wheel_Fx", "wheel_Fy", "wheel_Fz")


def sweep_poses(args: argparse.Namespace) -> list[tuple[float, float]]:
    """Return the sweep's ``(dy, yaw)`` poses."""
    y0, y1, step = args.sweep_dy
    if not (step > 0.0) or y1 < y0:
        raise InvalidInputError("--sweep-dy needs Y0 <= Y1 and STEP > 0")
    count = (y1 - y0) / step   # a float: inf for an absurd range, compared, never converted
    if not count < 10_000:
        raise InvalidInputError(f"--sweep-dy gives {count + 1:.4g} poses, at most 10000")
    n = int(math.floor(count + 1e-9)) + 1
    dys = [y0 + k * step for k in range(n)]
    if args.sweep_yaw is not None:
        p0, p1 = args.sweep_yaw
        span = (y1 - y0) or 1.0
        yaws = [p0 + (p1 - p0) * (dy - y0) / span for dy in dys]
    else:
        yaws = [0.0 if args.yaw is None else args.yaw] * n
    return list(zip(dys, yaws))


def sweep(args: argparse.Namespace) -> dict[str, Any]:
    """Solve every pose of the sweep, write the CSV (and the figure) atomically."""
    if args.output is None:
        raise InvalidInputError("--sweep-dy needs -o OUT.csv")
    poses = sweep_poses(args)
    # the outputs' places checked before the poses are solved (minutes), not after
    for target in (args.output, args.plot):
        if target is not None:
            check_target(target)
    rows: list[dict[str, Any]] = []
    results: list[dict[str, Any] | None] = []
    for dy, yaw in poses:
        try:
            cycle, pipeline = solve_pose(args, dy, yaw)
            result = result_of(cycle, pipeline, args.method)
        except GeometryError as e:
            rows.append({"dy": dy, "yaw": yaw, "status": str(e)})
            results.append(None)
            continue
        results.append(result)
        for wheel in result["wheels"]:
            fx, fy, fz = wheel["force_track"]
            if not wheel["patches"]:
                rows.append({"dy": dy, "yaw": yaw, "roll": result["roll"], "dz": wheel["dz"],
                             "side": wheel["side"], "status": "lifted", "wheel_Fx": fx,
                             "wheel_Fy": fy, "wheel_Fz": fz})
            for patch in wheel["patches"]:
                rows.append({"dy": dy, "yaw": yaw, "roll": result["roll"], "dz": wheel["dz"],
                             "side": wheel["side"], "status": "ok", "wheel_Fx": fx,
                             "wheel_Fy": fy, "wheel_Fz": fz,
                             **{k: patch[k] for k in SWEEP_COLUMNS if k in patch}})
    write_atomically(args.output, lambda f: _write_csv(f, rows))
    if args.plot is not None:
        from fastsim_ros.geometry.sweep_plot import plot_sweep
        plot_sweep(args, poses, results, args.plot)
    solved = sum(1 for r in results if r is not None)
    return {"sweep": str(args.output), "poses": len(poses), "solved": solved,
            "refused": len(poses) - solved, "plot": str(args.plot) if args.plot else None,
            "method": args.method}


def _write_csv(f: Any, rows: Sequence[dict[str, Any]]) -> None:
    w = csv.DictWriter(f, fieldnames=SWEEP_COLUMNS, extrasaction="ignore")
    w.writeheader()
    for row in rows:
        w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items()})


def print_table(result: dict[str, Any]) -> None:
    """Print one pose's result (or a sweep's summary) for a reader."""
    if "sweep" in result:
        print(f"{result['poses']} poses ({result['solved']} solved, {result['refused']} "
              f"refused), method {result['method']}: {result['sweep']}"
              + (f", figure {result['plot']}" if result["plot"] else ""))
        return
    print(f"pose dy = {result['dy'] * 1e3:.3f} mm, yaw = {result['yaw'] * 1e3:.3f} mrad, "
          f"roll = {result['roll'] * 1e3:.4f} mrad, dz = {result['dz'] * 1e3:.4f} mm; "
          f"method {result['method']}")
    for wheel in result["wheels"]:
        fx, fy, fz = wheel["force_track"]
        print(f"{wheel['side']} wheel: force on the wheel (track frame) Fx = {fx:.1f} N, "
              f"Fy = {fy:.1f} N, Fz = {fz:.1f} N")
        if not wheel["patches"]:
            print("  no contact (the wheel is lifted)")
        for p in wheel["patches"]:
            print(f"  {p['name']}: y = {p['y'] * 1e3:.3f} mm, z = {p['z'] * 1e3:.3f} mm, "
                  f"angle = {p['contact_angle']:.4f} rad, N = {p['N']:.1f} N, "
                  f"{p['cells']} cells, pen = {p['penetration'] * 1e6:.2f} um")
            print(f"    xi = {p['xi']:.4g}, eta = {p['eta']:.4g}, phi = {p['phi']:.4g} 1/m; "
                  f"Fx = {p['Fx']:.1f} N, Fy = {p['Fy']:.1f} N, Mz = {p['Mz']:.3f} N m")


__all__ = ["ExactSolver", "METHODS", "add_parser", "print_table", "result_of", "run",
           "solve_pose", "sweep", "wheel_twist", "ContactError"]
