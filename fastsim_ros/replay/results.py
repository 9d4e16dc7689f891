"""What the replay of one input gives: :class:`Result` (and its summary) and :class:`Profile`."""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass, field
from typing import Any

from msg_adapters.errors import REJECTION_REASONS


@dataclass
class Profile:
    """Per-message wall times (ns) of one replay, by phase (see ``benchmarks/bench_replay.py``).

    ``read``: the reader's next message (decompression, record parsing),
    ``copy``: writing the input message, ``pipeline``: the pipeline call
    (decode, adapt, kinematics, solve) of patches, ``twist``: of twists,
    ``emit``: building and serializing the output messages of a patch,
    ``write``: writing them (the per-message path).  ``phases``: the
    totals (s) of the chunked path's phases.  ``solves``: the solves as
    they were solved, to time the solver alone on the same inputs, in
    batches ``(pressure (k, ny, nx) Pa, grid (k, 4): x0, y0, dx, dy (m),
    creepages (k, 3): xi, eta, phi, solved (k,) bool)`` (kept as the
    replay had them: only the ``solved`` items count).
    """

    read: array = field(default_factory=lambda: array("q"))
    copy: array = field(default_factory=lambda: array("q"))
    pipeline: array = field(default_factory=lambda: array("q"))
    twist: array = field(default_factory=lambda: array("q"))
    emit: array = field(default_factory=lambda: array("q"))
    write: array = field(default_factory=lambda: array("q"))
    phases: dict[str, float] = field(default_factory=dict)
    solves: list[tuple[Any, ...]] = field(default_factory=list)


@dataclass
class Result:
    """What the replay of one input gave (picklable: it crosses process pools and clusters)."""

    source: str
    name: str
    ok: bool = False
    status: int = 0
    error: str = ""
    warnings: list[str] = field(default_factory=list)
    messages_in: int = 0
    messages_out: int = 0
    duration_s: float = 0.0
    wall_s: float = 0.0
    plot_s: float = 0.0
    contacts: tuple[str, ...] = ()
    contacts_found: tuple[str, ...] = ()
    namespace: str = "/"
    counts: dict[str, dict[str, int]] = field(default_factory=dict)
    solve_us: dict[str, tuple[float, float]] = field(default_factory=dict)
    kinematics: dict[str, int] = field(default_factory=dict)
    written: list[str] = field(default_factory=list)
    attempts: int = 1
    resumed: bool = False
    profile: Profile | None = None

    @property
    def speed(self) -> float:
        """Return the replay speed as a multiple of real time (log duration / wall time).

        The wall time of the replay itself (read, solve, write the bag and
        the CSV), without drawing the plot.
        """
        wall = self.wall_s - self.plot_s
        return self.duration_s / wall if wall > 0 else math.inf

    def summary(self) -> str:
        """Return the readable summary of this bag (stdout)."""
        where = self.written[0] if self.written else "-"
        lines = [f"{self.name}: {self.messages_in} messages in ({self.duration_s:.3f} s of "
                 f"log), {self.messages_out} written -> {where}"]
        if self.contacts_found:
            lines.append(f"  contacts found in the bag (no --params): "
                         f"{', '.join(self.contacts_found)}"
                         + (f"; namespace {self.namespace}" if self.namespace != "/" else ""))
        elif self.namespace != "/":
            lines.append(f"  namespace {self.namespace}")
        for c in self.contacts:
            k = self.counts[c]
            patches = sum(k.values())
            rejected = {r: k[r] for r in REJECTION_REASONS if k[r]}
            p50, p99 = self.solve_us.get(c, (math.nan, math.nan))
            lines.append(
                f"  {c}: {patches} patches, {k['solved'] + k['no_contact']} wrenches "
                f"({k['solved']} solved, {k['no_contact']} no_contact), rejected "
                f"{sum(rejected.values())}"
                + (" (" + ", ".join(f"{r} {n}" for r, n in rejected.items()) + ")"
                   if rejected else "")
                + (f"; solve p50 {p50:.1f} us, p99 {p99:.1f} us" if math.isfinite(p50)
                   else "; nothing solved"))
        kin = self.kinematics
        dropped = {key: v for key, v in kin.items() if key not in ("wheel", "rail") and v}
        lines.append(f"  twists: {kin.get('wheel', 0)} wheelset, {kin.get('rail', 0)} rail "
                     f"used; dropped {sum(dropped.values())}"
                     + (" (" + ", ".join(f"{r} {n}" for r, n in dropped.items()) + ")"
                        if dropped else ""))
        lines.append(f"  replay: {self.wall_s - self.plot_s:.2f} s, {self.speed:.1f}x real time"
                     + (f"; plot {self.plot_s:.2f} s" if self.plot_s else ""))
        if self.attempts > 1 and self.resumed:
            lines.append(f"  retried: {self.attempts} attempts (a worker died after writing "
                         "the outputs, before its result came back: its commit finished, "
                         "nothing replayed again)")
        elif self.attempts > 1:
            lines.append(f"  retried: replayed {self.attempts} times (a worker died while "
                         "replaying it; what it left was removed)")
        lines += [f"  wrote {p}" for p in self.written[1:]]
        return "\n".join(lines)
