"""The Manchester contact benchmark, case A-2.2, as CONTACT publishes it.

CONTACT's examples ``mbench_a22_left``, ``mbench_a22_right`` (21 poses each,
its exact solver) and ``mbench_a22_kpec`` (the right wheel at three poses
with its fast methods KPEC + FASTSIM and ANALYN + FASTSIM, and its exact
solver again) ship in ``fastsim_ros/data/mbench/`` (Apache License 2.0,
github.com/eve70a/CONTACT; Shackleton & Iwnicki, Vehicle System Dynamics 46
(2008) 129-149).  This module reads their ``.ref_out`` files and converts
every quantity to this package's conventions:

- CONTACT's track frame has ``y`` to the right and ``z`` down; ours (REP-103)
  ``y`` left and ``z`` up: ``y = -y_C``, ``z = -z_C``, yaw ``= -YAW_C``,
  roll ``= ROLL_C``, axle spin about ``+y`` ``= -VPITCH_C``;
- CONTACT prints forces *on the rail*; ours are of the rail *on the wheel*:
  ``F_track = (-FX_C, FY_C, FZ_C)`` in our axes;
- its contact angle ``DELTCP`` is positive towards the track centre on the
  left rail and negative on the right one; ours is positive towards the
  centre on both;
- its creepages (body 1 the rail) have ``xi = -CKSI``, ``eta = CETA``,
  ``phi = CPHI`` (1/mm -> 1/m) in our contact axes (``x`` forward, ``y =
  z x x``, ``z`` into the wheel); patch forces ``Fx = -FX``, ``Fy = FS``,
  ``Mz = MN`` (N mm -> N m), about CONTACT's reference point;
- lengths are converted from mm to m.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "data" / "mbench"
#: A-2.2's conditions (CONTACT's .inp files)
SPEED, MU, SHEAR_MODULUS, POISSON, CELL, LOAD = 2.0, 0.3, 82e9, 0.28, 2e-4, 1e4


@dataclass(frozen=True)
class PatchResult:
    """One contact patch of CONTACT's output, in this package's conventions (SI)."""

    reference: tuple[float, float, float]   # XCP, YCP, ZCP in our track frame (m)
    angle: float                            # contact angle, positive towards the centre
    speed: float                            # VELOC (m/s)
    xi: float
    eta: float
    phi: float                              # 1/m
    n: float                                # FN (N)
    fx: float                               # of the rail on the wheel, contact axes (N)
    fy: float
    mz: float                               # N m, about the reference point
    approach: float                         # m
    p_max: float                            # Pa
    cells: int                              # NCON
    potential_cells: int                    # NPOT


@dataclass(frozen=True)
class CaseResult:
    """One case (a wheel at a pose) of CONTACT's output, in this package's conventions."""

    number: int
    side: str                               # "left" | "right"
    dy: float                               # m, positive left
    dz: float                               # m, positive up
    roll: float
    yaw: float
    forward_speed: float                    # m/s
    axle_spin: float                        # rad/s about +y
    force_track: tuple[float, float, float]  # of the rail on the wheel (N)
    patches: tuple[PatchResult, ...]
    normal_method: str                      # "exact", "kpec", "analyn"


_HEADER = re.compile(r"^[A-Z][A-Z0-9_()./]*$")


def _value_blocks(lines: list[str]) -> list[dict[str, float]]:
    """Every header line of names followed by a line of numbers, as a dict per block."""
    blocks: list[dict[str, float]] = []
    for i, line in enumerate(lines[:-1]):
        names = line.split()
        if not names or not all(_HEADER.match(n) for n in names):
            continue
        values = lines[i + 1].split()
        if len(values) != len(names):
            continue
        try:
            numbers = [float(v) for v in values]
        except ValueError:
            continue
        blocks.append(dict(zip(names, numbers)))
    return blocks


def _merge(blocks: list[dict[str, float]]) -> dict[str, float]:
    merged: dict[str, float] = {}
    for b in blocks:
        merged.update(b)
    return merged


def read_inputs(name: str) -> list[tuple[float, ...]]:
    """Every case's ``S, Y, FZ, ROLL, YAW, PITCH, VS, VY, VZ, VROLL, VYAW, VPITCH`` of an ``.inp``.

    The ``.ref_out`` prints the pose with 3-4 digits (a roll of -1.126E-02
    rad is 7 um at the wheel); the inputs carry them all.
    """
    rows: list[tuple[float, ...]] = []
    pending: list[float] = []
    for line in (DATA / f"{name}.inp").read_text().splitlines():
        if "S, Y, FZ, ROLL, YAW, PITCH" in line.replace("  ", " "):
            pending = [float(v) for v in line.split()[:6]]
        elif "VS,VY,VZ, VROLL,VYAW,VPITCH" in line.replace(" ", "").replace(
                "VS,VY,VZ,VROLL,VYAW,VPITCH", "VS,VY,VZ, VROLL,VYAW,VPITCH"):
            rows.append(tuple(pending + [float(v) for v in line.split()[:6]]))
    return rows


def read_ref_out(name: str) -> list[CaseResult]:
    """Read a shipped ``.ref_out`` (``mbench_a22_left`` etc.); poses from its ``.inp``."""
    inputs = read_inputs(name)
    text = (DATA / f"{name}.ref_out").read_text()
    chunks = re.split(r"^\s*Case\s+(\d+)\s*$", text, flags=re.MULTILINE)
    cases: list[CaseResult] = []
    state: dict[str, float] = {}
    bound = "0"
    for number, body in zip(chunks[1::2], chunks[2::2]):
        side_match = re.search(r"WHEEL-RAIL CONTACT, (LEFT|RIGHT) WHEEL", body)
        if side_match is None:
            continue
        side = side_match.group(1).lower()
        bound_match = re.search(r"BOUND\s+(\d)", body)
        if bound_match:
            bound = bound_match.group(1)
        parts = re.split(r"-----\s*DATA FOR CONTACT PATCH\s+\d+\s*-----", body)
        head = _merge(_value_blocks(parts[0].splitlines()))
        state.update(head)  # positions and speeds are printed only when they change
        sgn = 1.0 if side == "left" else -1.0
        patches = []
        for part in parts[1:]:
            v = _merge(_value_blocks(part.splitlines()))
            patches.append(PatchResult(
                reference=(v["XCP(TR)"] * 1e-3, -v["YCP(TR)"] * 1e-3, -v["ZCP(TR)"] * 1e-3),
                angle=sgn * v["DELTCP(TR)"], speed=v["VELOC"] * 1e-3,
                xi=-v["CKSI"], eta=v["CETA"], phi=v["CPHI"] * 1e3,
                n=v["FN"], fx=-v["FX"], fy=v["FS"], mz=v["MN"] * 1e-3,
                approach=v["APPROACH"] * 1e-3, p_max=v["PMAX"] * 1e6,
                cells=int(v["NCON"]), potential_cells=int(v["NPOT"])))
        given = inputs[int(number) - 1]
        cases.append(CaseResult(
            number=int(number), side=side, dy=-given[1] * 1e-3, dz=-state["Z_WS"] * 1e-3,
            roll=given[3], yaw=-given[4], forward_speed=given[6] * 1e-3,
            axle_spin=-given[11],
            force_track=(-state["FX(TR)"], state["FY(TR)"], state["FZ(TR)"]),
            patches=tuple(patches),
            normal_method={"0": "exact", "5": "kpec", "6": "analyn"}.get(bound, bound)))
    return cases


def a22(side: str) -> list[CaseResult]:
    """Return CONTACT's 21 exact results of A-2.2 for the ``"left"`` or ``"right"`` wheel."""
    if side not in ("left", "right"):
        raise ValueError(f"side must be 'left' or 'right', got {side!r}")
    return read_ref_out(f"mbench_a22_{side}")


def a22_fast_methods() -> list[CaseResult]:
    """Return CONTACT's KPEC and ANALYN (+ FASTSIM) results of A-2.2 (right wheel, 3 poses)."""
    return [c for c in read_ref_out("mbench_a22_kpec") if c.normal_method != "exact"]


def pose_number(case: CaseResult) -> int:
    """Return the A-2.2 pose (1..21) of a case: the shift in 0.5 mm steps."""
    return int(round(abs(case.dy) / 0.5e-3)) + 1


def is_finite_case(case: CaseResult) -> bool:
    """Return whether every number of a case is finite (a parse check)."""
    values = [case.dy, case.dz, case.roll, case.yaw, *case.force_track]
    for p in case.patches:
        values += [*p.reference, p.angle, p.xi, p.eta, p.phi, p.n, p.fx, p.fy, p.mz]
    return all(math.isfinite(v) for v in values)
