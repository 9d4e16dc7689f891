"""``fastsim_replay``: replay recorded bags offline through the node's pipeline.

Usage (INTERFACE.md, "The offline replay fastsim_replay")::

    fastsim_replay IN [IN ...] -o OUT [--params FILE] [--plot] [--csv] [--jobs N]

Each ``IN`` (a rosbag2 directory, or a single ``.mcap``) named ``NAME`` (the
directory's name, or the file's without ``.mcap``) gives:

- ``OUT/NAME/``: a rosbag2 bag (version 9, MCAP, zstd chunk compression)
  with the input's topics copied (an input message on one of the node's
  output topics is not copied) and the node's outputs on the node's topic
  names, each logged at the log time of the patch that gave it:
  ``/contact/<name>/wrench``, ``creepage``, ``frame`` (and ``traction``
  when asked for), ``/wheelset/wrench``, ``/contact/markers`` and
  ``/diagnostics`` (one array each time the log time passes a whole second
  since the first message, stamped with that message's log time, and one
  at the end).  Output connections offer the node's publisher QoS
  (``output_reliability``, keep last ``qos_depth``: reliable, 10 by
  default).  The metadata's ``custom_data`` holds ``fastsim.parameters``
  (JSON of every checked parameter, defaults filled), ``fastsim.input``
  (the input's path) and ``fastsim.replay`` (this program).
- with ``--plot``, ``OUT/NAME.png``: per contact, Fx and Fy against time
  (with +-mu N dashed) and against the creepage that varies most on that
  contact (``phi`` counted as ``phi * 5 mm``, a typical semi-axis, when
  comparing spreads).
- with ``--csv``, ``OUT/NAME.csv``: one row per wrench, header
  :data:`CSV_HEADER`; floats in Python's shortest round-trip form.  A
  ``no_contact`` row (an empty patch, zero wrench) has ``N, Fx, Fy, Mz`` =
  0 and ``xi, eta, phi, V, slip_fraction`` blank (undefined: no contact).

Messages are fed to :class:`~fastsim_ros.pipeline.Pipeline` in the bag's
log-time order, raw CDR as read.  Without ``--params`` every parameter has
its default.  Everything is written under a temporary name inside ``OUT``
and renamed at the end; on failure, Ctrl-C or SIGTERM nothing is left of
an unfinished input (inputs already done, whose summaries were printed, stay).
A progress bar (tqdm, on stderr) appears when stderr is a terminal, ``--jobs``
is 1 and a bag takes more than a second.

Exit status: 0 all done; 2 bad flags, a bad params file, two inputs with the
same NAME or a target that exists (all before any work), or a bad, corrupt,
truncated or empty input (the others are still done); 1 an output that could
not be written or an internal error; 130 interrupted.  Every problem is one
line on stderr naming the file.
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import csv
import json
import math
import multiprocessing
import os
import shutil
import signal
import sys
import time
from array import array
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from rclpy.serialization import serialize_message
from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness,
                                QosReliability, QosTime)
from rosbags.rosbag2 import Reader, Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode, StoragePlugin
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from fastsim_ros.params import ParameterError, defaults, load_params_file
from fastsim_ros.pipeline import (DIAGNOSTICS_TOPIC, RAIL_TWIST_TOPIC, WHEEL_TWIST_TOPIC,
                                  Outcome, Pipeline, PipelineConfig, output_topics,
                                  patch_topic)
from msg_adapters.errors import REJECTION_REASONS

PROG = "fastsim_replay"
CSV_HEADER = ("stamp_ns", "contact", "xi", "eta", "phi", "V", "N", "Fx", "Fy", "Mz",
              "slip_fraction", "method", "friction_law")
#: key of the checked parameters (JSON) in the output bag's custom_data
PARAMETERS_KEY = "fastsim.parameters"
#: messages between two progress-bar updates
_PROGRESS_EVERY = 256
#: points kept per contact for the plot (decimated by 2 each time it fills)
_PLOT_POINTS = 100_000
#: semi-axis (m) that puts phi on the scale of xi and eta when picking the plot's abscissa
_PHI_SCALE = 5e-3
_TYPESTORE = get_typestore(Stores.ROS2_JAZZY)


class BadInput(Exception):
    """An input that cannot be replayed: corrupt, truncated, empty, not a bag."""


class OutputError(Exception):
    """An output that cannot be written (disk full, permissions, a target that appeared)."""


# ------------------------------------------------------------------------ fast YAML

class _LibYaml:
    """Stand-in for ruamel's ``YAML(typ='safe')`` inside rosbags, on PyYAML's libyaml.

    Without ruamel's C extension (not a dependency here) rosbags spends
    about 12 ms per output connection and 0.1-0.2 s per bag dumping and
    loading its small YAML documents (QoS profiles, ``metadata.yaml``):
    more than replaying a 4 s bag.  Same documents, parsed by the same
    readers (the tests open every output with the unpatched rosbags reader).
    """

    _LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    _DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.default_flow_style: bool | None = False

    def load(self, text: Any) -> Any:
        """Load one document; raise ruamel's YAMLError as rosbags expects."""
        from ruamel.yaml.error import YAMLError
        try:
            return yaml.load(text, Loader=self._LOADER)
        except yaml.YAMLError as e:
            raise YAMLError(" ".join(str(e).split())) from None

    def dump(self, data: Any, stream: Any) -> None:
        """Dump one document to ``stream``."""
        yaml.dump(data, stream, Dumper=self._DUMPER, default_flow_style=self.default_flow_style,
                  width=1 << 30)


@contextmanager
def _fast_yaml() -> Iterator[None]:
    """Let rosbags' reader and writer use :class:`_LibYaml` for the duration."""
    import rosbags.rosbag2.metadata as m
    import rosbags.rosbag2.reader as r
    import rosbags.rosbag2.writer as w
    saved = [(mod, getattr(mod, "YAML")) for mod in (m, r, w)]
    for mod, _ in saved:
        setattr(mod, "YAML", _LibYaml)
    try:
        yield
    finally:
        for mod, original in saved:
            setattr(mod, "YAML", original)


# ------------------------------------------------------------------------ inputs

def input_name(path: Path) -> str:
    """Return the NAME of an input: the directory's name, or the file's without ``.mcap``."""
    p = Path(os.path.abspath(path))
    return p.stem if p.suffix == ".mcap" and not p.is_dir() else p.name


def targets(out: Path, name: str, plot: bool, write_csv: bool) -> list[Path]:
    """Return the paths an input NAME writes into OUT."""
    paths = [out / name]
    if write_csv:
        paths.append(out / f"{name}.csv")
    if plot:
        paths.append(out / f"{name}.png")
    return paths


def _problem(e: BaseException) -> str:
    text = " ".join(str(e).split()) or type(e).__name__
    return text if isinstance(e, (BadInput, OutputError)) else f"{type(e).__name__}: {text}"


def _qos(reliability: str, depth: int) -> list[Qos]:
    rel = QosReliability.BEST_EFFORT if reliability == "best_effort" else QosReliability.RELIABLE
    return [Qos(QosHistory.KEEP_LAST, depth, rel, QosDurability.VOLATILE, QosTime(0, 0),
                QosTime(0, 0), QosLiveliness.AUTOMATIC, QosTime(0, 0), False)]


def _definition(conn: Any) -> tuple[str, str]:
    """Return ``(msgdef, rihs01)`` of an input connection, to copy it as it is."""
    msgdef, digest = conn.msgdef.data, conn.digest
    if msgdef and digest:
        return msgdef, digest
    if conn.msgtype in _TYPESTORE.fielddefs:
        text, _ = _TYPESTORE.generate_msgdef(conn.msgtype, ros_version=2)
        return text, _TYPESTORE.hash_rihs01(conn.msgtype)
    try:  # a type of its own: hash the definition the bag carries
        store = get_typestore(Stores.EMPTY)
        store.register(get_types_from_msg(msgdef, conn.msgtype))
        return msgdef, store.hash_rihs01(conn.msgtype)
    except Exception as e:
        raise BadInput(f"topic {conn.topic}: no usable definition of type {conn.msgtype} "
                       f"({_problem(e)})") from None


# ------------------------------------------------------------------------ results

@dataclass
class Profile:
    """Per-message wall times (ns) of one replay, by phase (see ``benchmarks/bench_replay.py``).

    ``read``: the reader's next message (decompression, record parsing),
    ``copy``: writing the input message, ``pipeline``: the pipeline call
    (decode, adapt, kinematics, solve) of patches, ``twist``: of twists,
    ``emit``: building and serializing the output messages of a patch,
    ``write``: writing them.  ``solve_inputs``: ``(patch, creepage)`` of
    every solved patch, to time the solver alone on the same inputs.
    """

    read: array = field(default_factory=lambda: array("q"))
    copy: array = field(default_factory=lambda: array("q"))
    pipeline: array = field(default_factory=lambda: array("q"))
    twist: array = field(default_factory=lambda: array("q"))
    emit: array = field(default_factory=lambda: array("q"))
    write: array = field(default_factory=lambda: array("q"))
    solve_inputs: list[tuple[Any, Any]] = field(default_factory=list)


@dataclass
class Result:
    """What the replay of one input gave (picklable: it crosses the process pool)."""

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
    counts: dict[str, dict[str, int]] = field(default_factory=dict)
    solve_us: dict[str, tuple[float, float]] = field(default_factory=dict)
    kinematics: dict[str, int] = field(default_factory=dict)
    written: list[str] = field(default_factory=list)
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
                + f"; solve p50 {p50:.1f} us, p99 {p99:.1f} us")
        kin = self.kinematics
        dropped = {key: v for key, v in kin.items() if key not in ("wheel", "rail") and v}
        lines.append(f"  twists: {kin.get('wheel', 0)} wheelset, {kin.get('rail', 0)} rail "
                     f"used; dropped {sum(dropped.values())}"
                     + (" (" + ", ".join(f"{r} {n}" for r, n in dropped.items()) + ")"
                        if dropped else ""))
        lines.append(f"  replay: {self.wall_s - self.plot_s:.2f} s, {self.speed:.1f}x real time"
                     + (f"; plot {self.plot_s:.2f} s" if self.plot_s else ""))
        lines += [f"  wrote {p}" for p in self.written[1:]]
        return "\n".join(lines)


# ------------------------------------------------------------------------ plot data

class _Series:
    """Per-contact samples for the plot, decimated by 2 whenever full (bounded memory)."""

    __slots__ = ("stride", "seen", "cols")

    def __init__(self) -> None:
        self.stride = 1
        self.seen = 0
        self.cols: tuple[array, ...] = tuple(array("d") for _ in range(7))

    def add(self, *values: float) -> None:
        """Add ``t, xi, eta, phi, Fx, Fy, N``."""
        self.seen += 1
        if (self.seen - 1) % self.stride:
            return
        for col, v in zip(self.cols, values):
            col.append(v)
        if len(self.cols[0]) >= _PLOT_POINTS:
            self.cols = tuple(array("d", col[::2]) for col in self.cols)
            self.stride *= 2


def _write_plot(path: Path, name: str, contacts: tuple[str, ...],
                series: dict[str, _Series], mu: float) -> None:
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    rows = max(1, len(contacts))
    fig = Figure(figsize=(11, 3.2 * rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, 2, squeeze=False)
    fig.suptitle(f"{name}: creep forces of the rail on the wheel (mu = {mu:g})")
    for row, c in enumerate(contacts):
        t, xi, eta, phi, fx, fy, n = (np.asarray(col) for col in series[c].cols)
        left, right = axes[row]
        left.set_title(f"{c}: against time")
        right.set_title(f"{c}: against creepage")
        if t.size == 0:
            for ax in (left, right):
                ax.text(0.5, 0.5, "no wrench", ha="center", va="center",
                        transform=ax.transAxes)
            continue
        left.plot(t, fx * 1e-3, ".", ms=2, label="Fx")
        left.plot(t, fy * 1e-3, ".", ms=2, label="Fy")
        left.plot(t, mu * n * 1e-3, "k--", lw=0.8, label="+-mu N")
        left.plot(t, -mu * n * 1e-3, "k--", lw=0.8)
        left.set_xlabel("time since the first message (s)")
        left.set_ylabel("force (kN)")
        left.legend(loc="best", fontsize="small")
        solved = np.isfinite(xi)
        spreads = [float(np.ptp(v[solved])) if solved.any() else 0.0
                   for v in (xi, eta, phi * _PHI_SCALE)]
        k = int(np.argmax(spreads))
        label = ("xi", "eta", "phi (1/m)")[k]
        x = (xi, eta, phi)[k]
        right.plot(x[solved], fx[solved] * 1e-3, ".", ms=2, label="Fx")
        right.plot(x[solved], fy[solved] * 1e-3, ".", ms=2, label="Fy")
        right.axhline(0.0, color="0.6", lw=0.6)
        right.set_xlabel(label)
        right.set_ylabel("force (kN)")
        right.legend(loc="best", fontsize="small")
        for ax in (left, right):
            ax.grid(True, lw=0.3)
    fig.savefig(str(path), dpi=110, format="png")


# ------------------------------------------------------------------------ one bag

def _messages(reader: Reader, source: str) -> Iterator[tuple[Any, int, bytes]]:
    """Yield the reader's messages; turn any reading problem into :class:`BadInput`."""
    it = reader.messages()
    while True:
        try:
            item = next(it)
        except StopIteration:
            return
        except Exception as e:
            raise BadInput(f"{source}: unreadable: {_problem(e)}") from None
        yield item


def _progress(name: str, total: int, enabled: bool) -> Any:
    if not enabled or not sys.stderr.isatty():
        return None
    from tqdm import tqdm  # type: ignore[import-untyped]
    return tqdm(total=total, desc=name, unit="msg", file=sys.stderr, delay=1.0, leave=False,
                dynamic_ncols=True)


def replay_bag(source: Path, name: str, out: Path, values: dict[str, Any], *,
               plot: bool = False, write_csv: bool = False, tag: str = "",
               progress: bool = True, profile: bool = False) -> Result:
    """Replay one input into ``out`` (atomically); return its :class:`Result`.

    Never raises for a bad input or an unwritable output: ``Result.ok`` is
    False, ``status`` 2 (bad input) or 1 (output or internal error) and
    ``error`` one line naming the file.  KeyboardInterrupt and SystemExit
    propagate, after the temporary files are removed.
    """
    result = Result(str(source), name)
    staging = out / f".{name}.{tag or os.getpid()}.replay-tmp"
    done = False
    try:
        staging.mkdir()
        with _fast_yaml():
            _replay(source, name, staging, values, plot, write_csv, progress, profile, result)
        for tmp in [staging / name] + ([staging / f"{name}.csv"] if write_csv else []) + \
                ([staging / f"{name}.png"] if plot else []):
            final = out / tmp.name
            if os.path.lexists(final):
                raise OutputError(f"{final}: appeared while replaying; not overwritten")
            os.rename(tmp, final)
            result.written.append(str(final))
        done = True
        result.ok = True
    except BadInput as e:
        result.status, result.error = 2, str(e)
    except OutputError as e:
        result.status, result.error = 1, str(e)
    except OSError as e:
        result.status, result.error = 1, f"{e.filename or out}: cannot write: {e.strerror or e}"
    except Exception as e:  # a bug: still one line, and the other inputs go on
        result.status, result.error = 1, f"{source}: internal error: {_problem(e)}"
    finally:
        shutil.rmtree(staging, ignore_errors=True)
        if not done:
            for p in result.written:  # a partial rename: take back what this bag put there
                shutil.rmtree(p, ignore_errors=True) if os.path.isdir(p) else \
                    Path(p).unlink(missing_ok=True)
            result.written = []
    return result


def _open_reader(source: Path) -> Reader:
    if not os.path.lexists(source):
        raise BadInput(f"{source}: no such file or directory")
    if not source.is_dir() and source.suffix != ".mcap":
        raise BadInput(f"{source}: not a rosbag2 directory or an .mcap file")
    try:
        reader = Reader(source)
        reader.open()
    except Exception as e:
        raise BadInput(f"{source}: not a readable bag: {_problem(e)}") from None
    return reader


def _replay(source: Path, name: str, staging: Path, values: dict[str, Any], plot: bool,
            write_csv: bool, progress: bool, profile: bool, result: Result) -> None:
    start_wall = time.perf_counter()
    config = PipelineConfig.from_values(values)
    pipeline = Pipeline(config)
    contacts = config.contacts
    result.contacts = contacts
    prof = Profile() if profile else None
    result.profile = prof
    clock = time.perf_counter_ns

    reader = _open_reader(source)
    try:
        if reader.message_count == 0:
            raise BadInput(f"{source}: empty bag (no messages)")
        outputs = output_topics(contacts)
        absolute = {("/" + t if not t.startswith("/") else t): msgtype
                    for t, msgtype in outputs.items()}
        patches = {"/" + patch_topic(c): c for c in contacts}
        if not any(conn.topic in patches for conn in reader.connections):
            result.warnings.append(
                f"{source}: no patch topic of the configured contacts "
                f"({', '.join(contacts)}); nothing solved (is --params right?)")
        writer = Writer(staging / name, version=9, storage_plugin=StoragePlugin.MCAP)
        writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        writer.set_custom_data(PARAMETERS_KEY, json.dumps(dict(config.values), sort_keys=True))
        writer.set_custom_data("fastsim.input", str(source))
        writer.set_custom_data("fastsim.replay", PROG)
        qos_out = _qos(config["output_reliability"], int(config["qos_depth"]))
        csv_file = None
        rows = None
        if write_csv:
            csv_file = open(staging / f"{name}.csv", "w", newline="", encoding="utf-8")
            rows = csv.writer(csv_file, lineterminator="\n")
            rows.writerow(CSV_HEADER)
        series = {c: _Series() for c in contacts}
        method, law = str(config["method"]), str(config["friction_law"])
        bar = _progress(name, reader.message_count, progress)
        with writer:
            copies = {}
            for conn in reader.connections:
                if conn.topic in absolute:
                    continue
                msgdef, digest = _definition(conn)
                ext = conn.ext
                copies[conn.id] = writer.add_connection(
                    conn.topic, conn.msgtype, msgdef=msgdef, rihs01=digest,
                    serialization_format=getattr(ext, "serialization_format", "cdr"),
                    offered_qos_profiles=getattr(ext, "offered_qos_profiles", ()))
            conns: dict[str, Any] = {}

            def put(topic: str, log_ns: int, data: Any) -> None:
                conn = conns.get(topic)
                if conn is None:
                    conn = conns[topic] = writer.add_connection(
                        topic, absolute[topic], typestore=_TYPESTORE,
                        offered_qos_profiles=qos_out)
                writer.write(conn, log_ns, data)
                result.messages_out += 1

            first: int | None = None
            last: int | None = None
            next_diag = 0
            t_read = clock()
            for conn, log_ns, raw in _messages(reader, str(source)):
                if prof is not None:
                    now = clock()
                    prof.read.append(now - t_read)
                if first is None:
                    first = log_ns
                    next_diag = first + 1_000_000_000
                last = log_ns
                result.messages_in += 1
                if bar is not None and result.messages_in % _PROGRESS_EVERY == 0:
                    bar.update(_PROGRESS_EVERY)
                if log_ns >= next_diag:
                    put(DIAGNOSTICS_TOPIC, log_ns, serialize_message(
                        pipeline.diagnostics(log_ns)))
                    next_diag += ((log_ns - next_diag) // 1_000_000_000 + 1) * 1_000_000_000
                copy = copies.get(conn.id)
                if copy is not None:
                    t0 = clock()
                    writer.write(copy, log_ns, raw)
                    result.messages_out += 1
                    if prof is not None:
                        prof.copy.append(clock() - t0)
                topic = conn.topic
                contact = patches.get(topic)
                if contact is not None:
                    t0 = clock()
                    outcome = pipeline.on_patch(contact, raw)
                    t1 = clock()
                    msgs = pipeline.messages(outcome)
                    data = [(t, m if isinstance(m, (bytes, bytearray, memoryview))
                             else serialize_message(m)) for t, m in msgs]
                    t2 = clock()
                    for rel, payload in data:
                        put(rel if rel.startswith("/") else "/" + rel, log_ns, payload)
                    if prof is not None:
                        prof.pipeline.append(t1 - t0)
                        prof.emit.append(t2 - t1)
                        prof.write.append(clock() - t2)
                        if outcome.status == "solved":
                            prof.solve_inputs.append((outcome.patch, outcome.creepage))
                    if outcome.has_wrench:
                        _record(outcome, log_ns - first, rows, series[contact], method, law)
                elif topic == "/" + WHEEL_TWIST_TOPIC:
                    t0 = clock()
                    pipeline.on_wheel_twist(raw)
                    if prof is not None:
                        prof.twist.append(clock() - t0)
                elif topic == "/" + RAIL_TWIST_TOPIC:
                    t0 = clock()
                    pipeline.on_rail_twist(raw)
                    if prof is not None:
                        prof.twist.append(clock() - t0)
                t_read = clock()
            if first is None or last is None:
                raise BadInput(f"{source}: empty bag (no messages)")
            put(DIAGNOSTICS_TOPIC, last, serialize_message(pipeline.diagnostics(last)))
            result.duration_s = (last - first) * 1e-9
        if bar is not None:
            bar.close()
        for c in contacts:
            result.counts[c] = pipeline.counts(c)
            result.solve_us[c] = pipeline.solve_time_percentiles(c)
        result.kinematics = dict(pipeline.kinematics_counts)
        if csv_file is not None:
            csv_file.close()
        if plot:
            plot_start = time.perf_counter()
            _write_plot(staging / f"{name}.png", name, contacts, series,
                        float(config["friction_coefficient"]))
            result.plot_s = time.perf_counter() - plot_start
    finally:
        reader.close()
    result.wall_s = time.perf_counter() - start_wall


def _record(outcome: Outcome, t_ns: int, rows: Any, series: _Series, method: str,
            law: str) -> None:
    f, cr = outcome.forces, outcome.creepage
    if f is None or cr is None:  # no contact: a zero wrench, creepages undefined
        if rows is not None:
            rows.writerow((outcome.stamp_ns, outcome.contact, "", "", "", "", 0.0, 0.0, 0.0,
                           0.0, "", method, law))
        series.add(t_ns * 1e-9, math.nan, math.nan, math.nan, 0.0, 0.0, 0.0)
        return
    if rows is not None:
        rows.writerow((outcome.stamp_ns, outcome.contact, cr.xi, cr.eta, cr.phi, cr.speed,
                       f.n, f.fx, f.fy, f.mz, f.slip_fraction, method, law))
    series.add(t_ns * 1e-9, cr.xi, cr.eta, cr.phi, f.fx, f.fy, f.n)


# ------------------------------------------------------------------------ command line

class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> Any:  # one line, exit 2 (argparse prints usage too)
        self.exit(2, f"{self.prog}: error: {message}\n")


def parser() -> argparse.ArgumentParser:
    """Return the command-line parser."""
    p = _Parser(prog=PROG, allow_abbrev=False,
                description="Replay rosbag2 bags (directories or .mcap files) through the "
                            "fastsim node's pipeline; write bags with the creep forces.")
    p.add_argument("inputs", nargs="+", metavar="IN", type=Path,
                   help="a rosbag2 directory or a single .mcap file")
    p.add_argument("-o", "--output", required=True, type=Path, metavar="OUT",
                   help="output directory (made if missing)")
    p.add_argument("--params", type=Path, metavar="FILE",
                   help="the node's ROS 2 parameter file (default: every default)")
    p.add_argument("--plot", action="store_true", help="write OUT/NAME.png")
    p.add_argument("--csv", action="store_true", help="write OUT/NAME.csv, one row per wrench")
    p.add_argument("--jobs", type=_jobs, default=1, metavar="N",
                   help="replay the inputs on N worker processes (default 1)")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar (it shows only on a terminal anyway)")
    return p


def _jobs(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 1 <= n <= 256:
        raise argparse.ArgumentTypeError(f"{n} is outside [1, 256]")
    return n


def _fail(message: str) -> int:
    print(f"{PROG}: {message}", file=sys.stderr)
    return 2


def _worker_signals() -> None:
    """Let a worker ignore Ctrl-C and die of SIGTERM: the main process stops it and cleans up."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _terminate(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def main(argv: Sequence[str] | None = None) -> int:
    """Run the replay; return the exit status (see the module docstring)."""
    args = parser().parse_args(argv)
    out: Path = args.output
    values = defaults()
    if args.params is not None:
        try:
            values = load_params_file(args.params)
        except ParameterError as e:
            return _fail(str(e))
    names: dict[str, Path] = {}
    for src in args.inputs:
        name = input_name(src)
        if not name or name.startswith("."):
            return _fail(f"{src}: cannot name an output after it")
        if name in names:
            return _fail(f"{src}: same name {name!r} as {names[name]}; outputs would clash")
        names[name] = src
    if os.path.lexists(out) and not out.is_dir():
        return _fail(f"{out}: exists and is not a directory")
    for name in names:
        for target in targets(out, name, args.plot, args.csv):
            if os.path.lexists(target):
                return _fail(f"{target}: exists already; not overwritten")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        print(f"{PROG}: {out}: cannot make the output directory: {e.strerror or e}",
              file=sys.stderr)
        return 1
    tag = f"{os.getpid()}"
    previous = signal.signal(signal.SIGTERM, _terminate)
    jobs = min(args.jobs, len(names))
    status = 0
    kwargs = dict(plot=args.plot, write_csv=args.csv, tag=tag,
                  progress=not args.no_progress and jobs == 1)
    pool: cf.ProcessPoolExecutor | None = None
    try:
        from fastsim_ros.contact import compiled
        from msg_adapters import patch as patch_adapter
        compiled.warm_up()  # load the kernels once (the forked workers inherit them)
        patch_adapter.warm_up()
        if jobs == 1:
            results: Iterator[Result] = (replay_bag(src, name, out, values, **kwargs)
                                         for name, src in names.items())
        else:
            pool = cf.ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("fork"),
                                          initializer=_worker_signals)
            futures = [pool.submit(replay_bag, src, name, out, values, **kwargs)
                       for name, src in names.items()]
            results = (f.result() for f in futures)
        for r in results:
            for w in r.warnings:
                print(f"{PROG}: warning: {w}", file=sys.stderr)
            if r.ok:
                print(r.summary(), flush=True)
            else:
                print(f"{PROG}: {r.error}", file=sys.stderr, flush=True)
                status = max(status, r.status)
    except KeyboardInterrupt:
        _stop(pool)
        pool = None
        _clean(out, tag)
        print(f"{PROG}: interrupted; nothing left of the unfinished inputs", file=sys.stderr)
        return 130
    finally:
        if pool is not None:
            pool.shutdown(wait=True)
        signal.signal(signal.SIGTERM, previous)
    return status


def _stop(pool: cf.ProcessPoolExecutor | None) -> None:
    """Stop the workers at once (they ignore SIGINT: the main process cleans up)."""
    if pool is None:
        return
    processes = list(getattr(pool, "_processes", {}).values())
    for proc in processes:
        proc.terminate()
    for proc in processes:
        proc.join(timeout=5)
        if proc.is_alive():
            proc.kill()
            proc.join(timeout=5)
    pool.shutdown(wait=False, cancel_futures=True)


def _clean(out: Path, tag: str) -> None:
    """Remove this run's temporary directories from OUT."""
    try:
        entries = list(out.iterdir())
    except OSError:
        return
    for p in entries:
        if p.name.startswith(".") and p.name.endswith(f".{tag}.replay-tmp"):
            shutil.rmtree(p, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
