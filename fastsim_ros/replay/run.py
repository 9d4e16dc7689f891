"""One input, replayed: :class:`Task` in, :class:`~fastsim_ros.replay.results.Result` out.

:func:`run_task` is what every executor runs (in this process, in a local
pool's worker, on a cluster's worker): it stages the outputs of one input
under a temporary name inside ``OUT`` and renames them at the end, so a
failed, corrupt or interrupted input leaves nothing behind.

The replay loop feeds the bag's messages to the pipeline in log-time order,
raw CDR as read, dispatching on the pipeline's own table of input topics
(:meth:`~fastsim_ros.pipeline.Pipeline.inputs`), and writes each input
message (unless it is on one of the node's output topics) and the outputs it
gave, logged at its log time.  ``/diagnostics``: one array each time the log
time passes a whole second since the first message, stamped with that
message's log time, and one at the end.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rclpy.serialization import serialize_message

from fastsim_ros.params import SPECS, ParameterError
from fastsim_ros.pipeline import DIAGNOSTICS_TOPIC, PipelineConfig, output_topics
from fastsim_ros.profile_pipeline import make_pipeline
from fastsim_ros.replay import bagio
from fastsim_ros.replay.errors import BadInput, OutputError, problem
from fastsim_ros.replay.plot import write_plot
from fastsim_ros.replay.records import CSV_HEADER, Series, record
from fastsim_ros.replay.results import Profile, Result

PROG = "fastsim_replay"
#: key of the checked parameters (JSON) in the output bag's custom_data
PARAMETERS_KEY = "fastsim.parameters"
#: messages between two progress-bar updates
_PROGRESS_EVERY = 256
_KINEMATICS = ("wheel_twist", "rail_twist")


@dataclass(frozen=True)
class Task:
    """One input to replay (picklable: executors send it to their workers).

    ``source``: the bag; ``name``: its NAME; ``out``: the output directory;
    ``values``: the parameters (checked again by the pipeline);
    ``contacts_from_bag``: take the contacts from the bag's patch topics
    instead of ``values`` (no ``--params``); ``namespace``: the node's
    (absolute); ``tag``: this run's mark on temporary names (so the main
    process can clean up after an interrupt).
    """

    source: Path
    name: str
    out: Path
    values: dict[str, Any]
    plot: bool = False
    write_csv: bool = False
    contacts_from_bag: bool = False
    namespace: str = "/"
    tag: str = ""
    progress: bool = False


def targets(out: Path, name: str, plot: bool, write_csv: bool) -> list[Path]:
    """Return the paths an input NAME writes into OUT."""
    paths = [out / name]
    if write_csv:
        paths.append(out / f"{name}.csv")
    if plot:
        paths.append(out / f"{name}.png")
    return paths


def replay_bag(source: Path, name: str, out: Path, values: dict[str, Any], *,
               plot: bool = False, write_csv: bool = False, contacts_from_bag: bool = False,
               namespace: str = "/", tag: str = "", progress: bool = True,
               profile: bool = False) -> Result:
    """Replay one input into ``out``: :func:`run_task` of the :class:`Task` of these options."""
    return run_task(Task(source, name, out, values, plot, write_csv, contacts_from_bag,
                         namespace, tag, progress), profile=profile)


def run_task(task: Task, *, profile: bool = False) -> Result:
    """Replay one input into its ``out`` (atomically); return its :class:`Result`.

    What every executor runs.  Never raises for a bad input or an
    unwritable output: ``Result.ok`` is False, ``status`` 2 (bad input) or
    1 (output or internal error) and ``error`` one line naming the file.
    KeyboardInterrupt and SystemExit propagate, after the temporary files
    are removed.  ``profile``: time each phase
    (:class:`~fastsim_ros.replay.results.Profile`, for the benchmark).
    """
    source, name, out = task.source, task.name, task.out
    result = Result(str(source), name)
    staging = out / f".{name}.{task.tag or os.getpid()}.replay-tmp"
    done = False
    try:
        staging.mkdir()
        with bagio.fast_yaml():
            _replay(task, staging, profile, result)
        for tmp in targets(staging, name, task.plot, task.write_csv):
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
        result.status, result.error = 1, f"{source}: internal error: {problem(e)}"
    finally:
        shutil.rmtree(staging, ignore_errors=True)
        if not done:
            for p in result.written:  # a partial rename: take back what this bag put there
                shutil.rmtree(p, ignore_errors=True) if os.path.isdir(p) else \
                    Path(p).unlink(missing_ok=True)
            result.written = []
    return result


def _progress(name: str, total: int, enabled: bool) -> Any:
    if not enabled or not sys.stderr.isatty():
        return None
    from tqdm import tqdm  # type: ignore[import-untyped]
    return tqdm(total=total, desc=name, unit="msg", file=sys.stderr, delay=1.0, leave=False,
                dynamic_ncols=True)


def resolve(topic: str, namespace: str = "/") -> str:
    """Return the absolute name of ``topic`` in ``namespace``, as ROS resolves it.

    An absolute name stays; a relative one is put under the namespace (a
    bag's topic names resolve in the root namespace).
    """
    if topic.startswith("/"):
        return topic
    return f"{namespace.rstrip('/')}/{topic}"


def _contact_name(name: str) -> bool:
    try:
        SPECS["contacts"].check((name,))
    except ParameterError:
        return False
    return True


def bag_contacts(topics: list[str], namespace: str) -> tuple[str, ...]:
    """Return the contacts with a ``contact/<name>/patch`` topic under ``namespace``.

    In the order of ``topics`` (the bag's connections), each once; only
    names the ``contacts`` parameter accepts.
    """
    prefix = resolve("contact/", namespace)
    found: list[str] = []
    for topic in topics:
        topic = resolve(topic)
        if topic.startswith(prefix) and topic.endswith("/patch"):
            name = topic[len(prefix):-len("/patch")]
            if name not in found and _contact_name(name):
                found.append(name)
    return tuple(found)


def _replay(task: Task, staging: Path, profile: bool, result: Result) -> None:
    start_wall = time.perf_counter()
    source, name, namespace = task.source, task.name, task.namespace
    prof = Profile() if profile else None
    result.profile = prof
    clock = time.perf_counter_ns

    reader = bagio.open_reader(source)
    try:
        if reader.message_count == 0:
            raise BadInput(f"{source}: empty bag (no messages)")
        values = task.values
        found: tuple[str, ...] = ()
        if task.contacts_from_bag:
            found = bag_contacts([conn.topic for conn in reader.connections], namespace)
            if found:
                values = dict(values, contacts=list(found))
        config = PipelineConfig.from_values(values)
        pipeline = make_pipeline(config)
        contacts = config.contacts
        result.contacts = contacts
        result.contacts_found = found
        result.namespace = namespace
        absolute = {resolve(t, namespace): msgtype for t, msgtype in output_topics(
            contacts, patches=config["patch_source"] == "profiles").items()}
        inputs = {resolve(i.topic, namespace): i for i in pipeline.inputs()}
        if not any(resolve(conn.topic) in inputs
                   and inputs[resolve(conn.topic)].kind not in _KINEMATICS
                   for conn in reader.connections):
            result.warnings.append(
                f"{source}: no patch topic "
                + (f"under {namespace} (no --params: the contacts are those with a "
                   f"{resolve('contact/<name>/patch', namespace)} topic)"
                   if task.contacts_from_bag else
                   f"of the configured contacts ({', '.join(contacts)})")
                + "; nothing solved (are --params and --namespace right?)")
        writer = bagio.open_writer(staging / name, {
            PARAMETERS_KEY: json.dumps(dict(config.values), sort_keys=True),
            "fastsim.input": str(source), "fastsim.replay": PROG})
        qos_out = bagio.qos(config["output_reliability"], int(config["qos_depth"]))
        csv_file = None
        rows = None
        if task.write_csv:
            csv_file = open(staging / f"{name}.csv", "w", newline="", encoding="utf-8")
            rows = csv.writer(csv_file, lineterminator="\n")
            rows.writerow(CSV_HEADER)
        series = {c: Series() for c in contacts}
        method, law = str(config["method"]), str(config["friction_law"])
        bar = _progress(name, reader.message_count, task.progress)
        with writer:
            copies = bagio.copy_connections(reader, writer, set(absolute))
            conns: dict[str, Any] = {}

            def put(topic: str, log_ns: int, data: Any) -> None:
                conn = conns.get(topic)
                if conn is None:
                    conn = conns[topic] = writer.add_connection(
                        topic, absolute[topic], typestore=bagio.TYPESTORE,
                        offered_qos_profiles=qos_out)
                writer.write(conn, log_ns, data)
                result.messages_out += 1

            diagnostics = resolve(DIAGNOSTICS_TOPIC, namespace)
            first: int | None = None
            last: int | None = None
            next_diag = 0
            t_read = clock()
            for conn, log_ns, raw in bagio.messages(reader, str(source)):
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
                    put(diagnostics, log_ns, serialize_message(
                        pipeline.diagnostics(log_ns)))
                    next_diag += ((log_ns - next_diag) // 1_000_000_000 + 1) * 1_000_000_000
                copy = copies.get(conn.id)
                if copy is not None:
                    t0 = clock()
                    writer.write(copy, log_ns, raw)
                    result.messages_out += 1
                    if prof is not None:
                        prof.copy.append(clock() - t0)
                source_topic = inputs.get(resolve(conn.topic))
                if source_topic is not None:
                    t0 = clock()
                    outcomes = source_topic.take(raw)
                    t1 = clock()
                    if prof is not None:
                        (prof.twist if source_topic.kind in _KINEMATICS
                         else prof.pipeline).append(t1 - t0)
                    for outcome in outcomes:
                        msgs = pipeline.messages(outcome)
                        data = [(t, m if isinstance(m, (bytes, bytearray, memoryview))
                                 else serialize_message(m)) for t, m in msgs]
                        t2 = clock()
                        for rel, payload in data:
                            put(resolve(rel, namespace), log_ns, payload)
                        if prof is not None:
                            prof.emit.append(t2 - t1)
                            prof.write.append(clock() - t2)
                            if outcome.status == "solved":
                                prof.solve_inputs.append((outcome.patch, outcome.creepage))
                        if outcome.has_wrench:
                            record(outcome, log_ns - first, rows, series[outcome.contact],
                                   method, law)
                        t1 = clock()
                t_read = clock()
            if first is None or last is None:
                raise BadInput(f"{source}: empty bag (no messages)")
            put(diagnostics, last, serialize_message(pipeline.diagnostics(last)))
            result.duration_s = (last - first) * 1e-9
        if bar is not None:
            bar.close()
        for c in contacts:
            result.counts[c] = pipeline.counts(c)
            result.solve_us[c] = pipeline.solve_time_percentiles(c)
        result.kinematics = dict(pipeline.kinematics_counts)
        if csv_file is not None:
            csv_file.close()
        if task.plot:
            plot_start = time.perf_counter()
            write_plot(staging / f"{name}.png", name, contacts, series,
                       float(config["friction_coefficient"]))
            result.plot_s = time.perf_counter() - plot_start
    finally:
        reader.close()
    result.wall_s = time.perf_counter() - start_wall
