"""The figure of a ``fastsim_contact wheelset --sweep-dy``: patches on the profiles, forces.

Four panels: both rail profiles with each pose's patches drawn as their
lateral extent on the rail (one line per patch, offset per pose, the
wheel profile at the first pose); the wheels' lateral and vertical forces
against the shift; the contact angle; the contact position on the rail.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np


def plot_sweep(args: argparse.Namespace, poses: Sequence[tuple[float, float]],
               results: Sequence[dict[str, Any] | None], path: Path) -> None:
    """Write the sweep's figure to ``path`` (PNG), atomically."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from fastsim_ros.atomic import write_atomically
    from fastsim_ros.geometry.placement import Placement, place_rail
    from fastsim_ros.geometry.profiles import read_profile

    placement = Placement(args.gauge_width, args.gauge_height, args.cant,
                          args.flange_back_distance, args.flange_back_position,
                          args.nominal_radius)
    rail = place_rail(read_profile(args.rail, kind="rail"), placement)
    fig, axes = plt.subplots(2, 2, figsize=(12, 8))
    (ax_prof, ax_force), (ax_angle, ax_pos) = axes
    colours = {"left": "tab:blue", "right": "tab:red"}
    for side, sign in (("left", 1.0), ("right", -1.0)):
        ax_prof.plot(sign * rail.y * 1e3, rail.z * 1e3, color=colours[side], lw=1.0,
                     label=f"{side} rail")
    span = max(1, len(poses) - 1)
    for k, ((dy, _), result) in enumerate(zip(poses, results)):
        if result is None:
            continue
        for wheel in result["wheels"]:
            for patch in wheel["patches"]:
                y = patch["y"] * 1e3
                z = patch["z"] * 1e3 + 2.0 + 8.0 * k / span
                ax_prof.plot([y], [z], "o", ms=3, color=colours[wheel["side"]])
    ax_prof.set_xlabel("y, track frame (mm)")
    ax_prof.set_ylabel("z (mm); patches above the rail, one row per pose")
    ax_prof.set_title("contact positions on the rails")
    ax_prof.legend(fontsize=8)
    for side in ("left", "right"):
        dys, fy, fz, ang, pos = [], [], [], [], []
        for (dy, _), result in zip(poses, results):
            if result is None:
                continue
            wheel = next(w for w in result["wheels"] if w["side"] == side)
            for patch in wheel["patches"]:
                dys.append(dy * 1e3)
                ang.append(patch["contact_angle"])
                pos.append(patch["y"] * 1e3)
            w_dy = dy * 1e3
            fy.append((w_dy, wheel["force_track"][1]))
            fz.append((w_dy, wheel["force_track"][2]))
        if fy:
            a = np.asarray(fy)
            b = np.asarray(fz)
            ax_force.plot(a[:, 0], a[:, 1] / 1e3, "-o", ms=3, color=colours[side],
                          label=f"{side} Fy")
            ax_force.plot(b[:, 0], b[:, 1] / 1e3, "--", color=colours[side],
                          label=f"{side} Fz")
        ax_angle.plot(dys, ang, "o", ms=3, color=colours[side], label=side)
        ax_pos.plot(dys, pos, "o", ms=3, color=colours[side], label=side)
    ax_force.set_xlabel("lateral shift dy (mm)")
    ax_force.set_ylabel("force of the rail on the wheel (kN)")
    ax_force.legend(fontsize=8)
    ax_angle.set_xlabel("lateral shift dy (mm)")
    ax_angle.set_ylabel("contact angle (rad)")
    ax_pos.set_xlabel("lateral shift dy (mm)")
    ax_pos.set_ylabel("contact position y, track frame (mm)")
    for ax in (ax_angle, ax_pos):
        ax.legend(fontsize=8)
    fig.suptitle(f"wheelset sweep, method {args.method}")
    fig.tight_layout()
    write_atomically(Path(path), lambda f: fig.savefig(f, format="png", dpi=110), binary=True)
    plt.close(fig)
