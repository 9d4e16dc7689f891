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
    totals (s) of the chunked path's phases, and parts of them:
    ``decompress`` (of ``read``), ``scan`` (of ``decode``: the compiled
    adapter loop), ``solver`` (of ``solve``: the compiled solves).  ``solves``: the solves as
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
class FrictionPath:
    """What online friction estimation did over one replay (``friction/estimate``).

    ``start``: the estimate's start (``friction_coefficient``); ``last`` and
    ``sigma``: the last estimate and its standard deviation; ``cycles``: the
    estimates published (one per rig cycle), ``statuses`` by status;
    ``steps``: the steps of ``mu_s`` the estimator saw (its step gate
    opened), each as ``(t, before)``: the log time since the first message
    (s) of the cycle that saw it and the estimate before it (where the
    estimate had settled); ``utilisation``: the largest of the cycles'.
    """

    start: float
    last: float = math.nan
    sigma: float = math.nan
    cycles: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    steps: list[tuple[float, float]] = field(default_factory=list)
    utilisation: float = 0.0

    def levels(self) -> list[float]:
        """Return the estimate's path: the start, where it settled before each step, the last.

        A level equal to the one before it (a step seen at the first cycle,
        before the estimate moved) is given once.
        """
        path = [self.start]
        for _, before in self.steps:
            if before != path[-1]:
                path.append(before)
        if self.cycles and self.last != path[-1]:
            path.append(self.last)
        return path

    def summary(self, where: str) -> list[str]:
        """Return the summary's lines (``where``: the friction CSV, or empty)."""
        if not self.cycles:
            return [f"  friction estimate: mu_s {self.start:g} at the start; no estimate "
                    "published (no rig cycle completed)" + (f" -> {where}" if where else "")]
        counts = ", ".join(f"{n} {s}" for s, n in self.statuses.items() if n)
        path = " -> ".join(f"{mu:.3g}" for mu in self.levels())
        steps = (f"{len(self.steps)} step{'s' if len(self.steps) != 1 else ''} of mu_s seen"
                 + (" (at " + ", ".join(f"{t:.2f}" for t, _ in self.steps) + " s)"
                    if self.steps else ""))
        lines = [f"  friction estimate: mu_s {self.start:g} at the start, {self.last:.4g} last "
                 f"(sigma {self.sigma:.3g}); {steps}; path {path}",
                 f"    {self.cycles} estimates ({counts or 'none'}), utilisation up to "
                 f"{self.utilisation:.3g}" + (f" -> {where}" if where else "")]
        return lines


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
    #: the friction estimate's path (estimation on)
    friction: FrictionPath | None = None
    #: messages the node published, by output topic (as written to the bag)
    published: dict[str, int] = field(default_factory=dict)
    #: output topics that also went to a file beside the bag: topic -> that file's path
    tabled: dict[str, str] = field(default_factory=dict)
    #: input topics the node could take but did not, as ``(topic, messages, what takes them)``
    unused: list[tuple[str, int, str]] = field(default_factory=list)
    #: the contacts' wear summary lines (wear_outputs on; records.WearSummary)
    wear: list[str] = field(default_factory=list)

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
        lines += [f"  {topic}: {n} messages not replayed; {hint}"
                  for topic, n, hint in self.unused]
        kin = self.kinematics
        dropped = {key: v for key, v in kin.items() if key not in ("wheel", "rail") and v}
        lines.append(f"  twists: {kin.get('wheel', 0)} wheelset, {kin.get('rail', 0)} rail "
                     f"used; dropped {sum(dropped.values())}"
                     + (" (" + ", ".join(f"{r} {n}" for r, n in dropped.items()) + ")"
                        if dropped else ""))
        if self.friction is not None:
            files = [p for t, p in self.tabled.items() if t.endswith("/friction/estimate")]
            lines += self.friction.summary(files[0] if files else "")
        lines += self.wear
        lines += self._outputs()
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

    def _outputs(self) -> list[str]:
        """Return the lines that say where each output topic's messages went."""
        where: dict[str, list[str]] = {}
        for topic, n in self.published.items():
            file = self.tabled.get(topic)
            key = f"the bag and {file}" if file else "the bag only"
            where.setdefault(key, []).append(f"{topic} {n}")
        keys = sorted(where, key=lambda k: k == "the bag only")  # the files first
        return [f"  published to {k}: {', '.join(where[k])}" for k in keys]
