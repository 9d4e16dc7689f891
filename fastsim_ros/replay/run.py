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
import pickle
import re
import shutil
import sys
import tempfile
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from rclpy.serialization import serialize_message

from fastsim_ros.contact.area import turned_grid
from fastsim_ros.ros.params import SPECS, ParameterError
from fastsim_ros.contact.wear import WearIndicators
from fastsim_ros.pipeline import (DIAGNOSTICS_TOPIC, FRICTION_ESTIMATE_TOPIC,
                                  MEASURED_WRENCH_TOPIC, FrictionEstimate, Outcome, Pipeline,
                                  PipelineConfig)
from fastsim_ros.pipeline.profiles import LOAD_TOPIC, POSE_TOPIC, AnyPipeline, make_pipeline
from fastsim_ros.replay import bagio, bulk, faults, heap, storage
from fastsim_ros.replay.errors import BadInput, OutputError, problem
from fastsim_ros.replay.plot import write_plot
from fastsim_ros.replay.records import (CSV_HEADER, ESTIMATE_COLUMNS, FRICTION_CSV_HEADER,
                                        WEAR_COLUMNS, Series, WearSummary, friction_row,
                                        record)
from fastsim_ros.replay.results import FrictionPath, Profile, Result
from fastsim_ros.replay.bagio import resolve

PROG = "fastsim_replay"
#: key of the checked parameters (JSON) in the output bag's custom_data
PARAMETERS_KEY = "fastsim.parameters"
#: messages between two progress-bar updates
_PROGRESS_EVERY = 256
_KINEMATICS = ("wheel_twist", "rail_twist")
#: a patch topic, resolved: its namespace (empty: the root) and contact
_PATCH_TOPIC = re.compile(r"^(.*)/contact/[^/]+/patch$")
#: how staging directories end
STAGING = ".replay-tmp"
#: the committed result, pickled, in the staging directory of a task that may run again
#: (``Task.retry``): written before its outputs are renamed into place
JOURNAL = "result.pickle"
#: where a commit with ``Task.overwrite`` moves the outputs it replaces, in its staging
#: directory: removed with it, or moved back if the commit fails
REPLACED = storage.REPLACED


@dataclass(frozen=True)
class Task:
    """One input to replay (picklable: executors send it to their workers).

    ``source``: the bag; ``name``: its NAME; ``out``: the output directory
    (either a local path or an fsspec URL: :mod:`~fastsim_ros.replay.storage`);
    ``values``: the parameters (checked again by the pipeline);
    ``contacts_from_bag``: take the contacts from the bag's patch topics
    instead of ``values`` (no ``--params``); ``namespace``: the node's
    (absolute); ``tag``: this run's mark on temporary names (so the main
    process can clean up after an interrupt).  ``path``: ``"auto"`` (an
    indexed MCAP input by the chunk, batched where the batch applies),
    ``"messages"`` (by the chunk, every message through the pipeline's
    handlers) or ``"rosbags"`` (rosbags' reader and writer, message by
    message: the reference the others are tested against).  ``retry``:
    the task may run again after its process died, even after it committed
    (a cluster): its staging directory then keeps the committed result
    (:data:`JOURNAL`) until the run's client removes it
    (:func:`remove_staging`), so that another attempt finishes that commit
    and returns that result instead of replaying again.  ``given``: the input
    as the user named it, where ``source`` is a local copy of a URL (the
    output's ``fastsim.input``).  ``overwrite``: outputs of an earlier run at
    the targets are replaced (each moved aside when its successor is
    complete and moved back if the commit fails), as is a friction CSV that
    this run does not write (estimation off): no stale one stays beside the
    new CSV.
    """

    source: Path | str
    name: str
    out: Path | str
    values: dict[str, Any]
    plot: bool = False
    write_csv: bool = False
    contacts_from_bag: bool = False
    namespace: str = "/"
    tag: str = ""
    progress: bool = False
    path: str = "auto"
    retry: bool = False
    #: the input as the user named it (a URL fetched to a local copy), for the output's metadata
    given: str = ""
    overwrite: bool = False


def targets(out: Any, name: str, plot: bool, write_csv: bool) -> list[Any]:
    """Return the paths (or URLs) an input NAME may write into OUT.

    The bag, with ``write_csv`` the CSV and the friction CSV (written only
    when friction estimation runs, but a target either way: an existing one
    is refused, or replaced with ``--overwrite``, so that it never stands
    beside a CSV of another run), with ``plot`` the PNG.
    """
    names = ([name] + ([f"{name}.csv", friction_csv(name)] if write_csv else [])
             + ([f"{name}.png"] if plot else []))
    return [storage.join(out, n) for n in names]


def friction_csv(name: str) -> str:
    """Return the name of an input's friction CSV (the estimate per rig cycle)."""
    return f"{name}.friction.csv"


def replay_bag(source: Path, name: str, out: Path, values: dict[str, Any], *,
               plot: bool = False, write_csv: bool = False, contacts_from_bag: bool = False,
               namespace: str = "/", tag: str = "", progress: bool = True,
               profile: bool = False, path: str = "auto") -> Result:
    """Replay one input into ``out``: :func:`run_task` of the :class:`Task` of these options."""
    return run_task(Task(source, name, out, values, plot, write_csv, contacts_from_bag,
                         namespace, tag, progress, path), profile=profile)


def run_task(task: Task, *, profile: bool = False) -> Result:
    """Replay one input into its ``out`` (atomically); return its :class:`Result`.

    What every executor runs.  Never raises for a bad input or an
    unwritable output: ``Result.ok`` is False, ``status`` 2 (bad input) or
    1 (output or internal error) and ``error`` one line naming the file.
    KeyboardInterrupt and SystemExit propagate, after the temporary files
    are removed.  ``profile``: time each phase
    (:class:`~fastsim_ros.replay.results.Profile`, for the benchmark).

    Each attempt first makes a staging directory of its own in OUT
    (``.NAME.TAG.K-ID.replay-tmp``, ``K`` its attempt number), then loads
    the kernels (:func:`warm_up`, once per process), replays into it and
    renames the outputs into place.  What an earlier attempt of the same
    run left there (a worker that died) is removed, or, if that attempt
    had committed (``Task.retry``: its :data:`JOURNAL`), its commit is
    finished and its result returned; ``Result.attempts`` counts them.
    """
    heap.keep_freed_memory()   # once per process: chunk buffers reused, not faulted in anew
    if storage.is_url(task.source) or storage.is_url(task.out):
        return _run_fetched(task, profile)
    return _run_local(task, profile)


_warm = False


def warm_up() -> None:
    """Load the compiled kernels (numba's disk cache), once per process.

    On a cluster each worker's first task does it (inside the task: a
    worker that dies meanwhile costs that task one more attempt, never the
    run); locally the main process does it before forking its pool.
    """
    global _warm
    if _warm:
        return
    from fastsim_ros.contact import compiled
    from fastsim_ros.replay import batch
    from msg_adapters import patch
    compiled.warm_up()
    faults.pause("warm-up")
    patch.warm_up()
    batch.warm_up()
    _warm = True


def staging_prefix(name: str, tag: str) -> str:
    """Return how the staging directories of an input's attempts in a run begin."""
    return f".{name}.{tag}."


def _earlier_attempts(out: Path | str, name: str, tag: str) -> list[str]:
    prefix = staging_prefix(name, tag)
    return [n for n in storage.listing(out) if n.startswith(prefix) and n.endswith(STAGING)]


def _attempt_number(staging_name: str, name: str, tag: str) -> int:
    """Return the attempt number ``K`` of a staging directory's name (0 if it has none)."""
    number = staging_name[len(staging_prefix(name, tag)):].partition("-")[0]
    return int(number) if number.isdigit() else 0


def remove_staging(out: Path | str, tag: str) -> None:
    """Remove the staging directories (and kept results) of the run ``tag`` from OUT.

    An output that an overwriting commit had moved aside and whose place is
    still empty (its process died between the two renames) is moved back
    first: a replaced output is lost only once its successor is in place.
    """
    for name in storage.listing(out):
        if name.startswith(".") and f".{tag}." in name and name.endswith(STAGING):
            if storage.is_url(out):
                storage.restore_replaced(str(out), name)
                storage.remove(str(out), name)
            else:
                _restore_replaced(Path(out), Path(out) / name)
                shutil.rmtree(Path(out) / name, ignore_errors=True)


def _restore_replaced(out: Path, staging: Path) -> None:
    """Move the outputs a commit set aside in ``staging`` back where nothing took their place."""
    aside = staging / REPLACED
    for old in storage.listing(aside):
        if not os.path.lexists(out / old):
            try:
                os.rename(aside / old, out / old)
            except OSError:
                pass


def _set_aside(final: Path, staging: Path) -> bool:
    """Move an existing output ``final`` into ``staging``'s :data:`REPLACED`; tell if it was."""
    if not os.path.lexists(final):
        return False
    (staging / REPLACED).mkdir(exist_ok=True)
    os.rename(final, staging / REPLACED / final.name)
    return True


def _finish_commit(task: Task, out: Path, earlier: Path, attempt: int) -> Result:
    """Finish the commit of an attempt that died after writing its journal; return its result.

    Its outputs were complete when it wrote the journal: those still in its
    staging directory are renamed into place now (with ``Task.overwrite``
    the outputs they replace, and a friction CSV not written, set aside).
    """
    result: Result = pickle.loads((earlier / JOURNAL).read_bytes())
    written = {Path(p).name for p in result.written}
    for final in map(Path, targets(out, task.name, task.plot, task.write_csv)):
        staged = earlier / final.name
        if final.name in written and os.path.lexists(staged):
            if task.overwrite:
                _set_aside(final, earlier)
            if not os.path.lexists(final):
                os.rename(staged, final)
        elif final.name not in written and task.overwrite:
            _set_aside(final, earlier)
    result.attempts, result.resumed = attempt, True
    return result


def _run_local(task: Task, profile: bool) -> Result:
    source, name, out = task.source, task.name, Path(task.out)
    result = Result(str(source), name)
    tag = task.tag or str(os.getpid())
    earlier = _earlier_attempts(out, name, tag)   # of workers that died replaying this input
    attempt = 1 + max((_attempt_number(n, name, tag) for n in earlier), default=0)
    result.attempts = attempt
    staging = out / f"{staging_prefix(name, tag)}{attempt}-{uuid.uuid4().hex[:12]}{STAGING}"
    done = False
    moved: list[Path] = []
    aside: list[Path] = []
    try:
        staging.mkdir()   # this attempt's mark, first: an attempt that dies from here counts
        committed = [n for n in earlier if (out / n / JOURNAL).is_file()]
        if committed:
            result = _finish_commit(task, out, out / committed[0], attempt)
            done = True
            return result
        for leftover in earlier:
            shutil.rmtree(out / leftover, ignore_errors=True)
        warm_up()
        with bagio.fast_yaml():
            _replay(task, staging, profile, result)
        staged = targets(staging, name, task.plot, task.write_csv)
        finals = [out / tmp.name for tmp in staged]
        if not task.overwrite:
            for final in finals:
                if os.path.lexists(final):
                    raise OutputError(f"{final}: appeared while replaying; not overwritten")
        result.ok = True
        result.written = [str(f) for tmp, f in zip(staged, finals) if os.path.lexists(tmp)]
        if task.retry:   # the result, before any output is in place (renamed whole)
            journal = staging / f"{JOURNAL}.tmp"
            journal.write_bytes(pickle.dumps(result))
            os.rename(journal, staging / JOURNAL)
        for tmp, final in zip(staged, finals):
            if task.overwrite and _set_aside(final, staging):
                aside.append(final)
                faults.pause(faults.REPLACE)
            if os.path.lexists(tmp):
                os.rename(tmp, final)
                moved.append(final)
            if task.retry:
                faults.pause("commit")
        done = True
        if task.retry:
            faults.pause("committed")
    except BadInput as e:
        # one line naming the file: a problem found below the file's level
        # (a topic's definition) names only what it saw
        error = str(e)
        result.status = 2
        result.error = error if error.startswith(str(source)) else f"{source}: {error}"
    except OutputError as e:
        result.status, result.error = 1, str(e)
    except OSError as e:
        result.status, result.error = 1, f"{e.filename or out}: cannot write: {e.strerror or e}"
    except Exception as e:  # a bug: still one line, and the other inputs go on
        result.status, result.error = 1, f"{source}: internal error: {problem(e)}"
    finally:
        if not done:
            result.ok = False
            for p in moved:  # a partial rename: take back what this bag put there
                shutil.rmtree(p, ignore_errors=True) if p.is_dir() else p.unlink(missing_ok=True)
            for p in aside:  # and put back what it replaced (before its staging goes)
                if not os.path.lexists(p):
                    os.rename(staging / REPLACED / p.name, p)
            result.written = []
        if not (done and task.retry):   # a committed result stays for another attempt
            shutil.rmtree(staging, ignore_errors=True)
    return result


def _run_fetched(task: Task, profile: bool) -> Result:
    """Replay an input or into an output that is a URL, through local copies.

    Into a URL, as into a local OUT: the attempt's staging directory at the
    URL is marked first, an earlier attempt's journalled commit is finished
    rather than replayed again (:func:`~fastsim_ros.replay.storage.commit`).
    """
    tag = task.tag or str(os.getpid())
    attempt, name = 1, ""
    if storage.is_url(task.out):
        out = str(task.out)
        earlier = _earlier_attempts(out, task.name, tag)
        attempt = 1 + max((_attempt_number(n, task.name, tag) for n in earlier), default=0)
        name = f"{staging_prefix(task.name, tag)}{attempt}-{uuid.uuid4().hex[:12]}{STAGING}"
        try:
            storage.mark(out, name)   # this attempt's mark, first
            committed = [n for n in earlier if storage.exists(f"{out.rstrip('/')}/{n}/{JOURNAL}")]
            if committed:
                result: Result = pickle.loads(storage.finish_commit(out, committed[0], JOURNAL))
                result.attempts, result.resumed = attempt, True
                return result
        except Exception as e:
            result = Result(str(task.source), task.name, status=1, attempts=attempt)
            result.error = f"{out}: cannot write: {problem(e)}"
            return result
        for leftover in earlier:
            storage.remove(out, leftover)
    with tempfile.TemporaryDirectory(prefix="fastsim-replay-") as tmp:
        local = Path(tmp)
        source: Path | str = task.source
        if storage.is_url(task.source):
            try:
                source = storage.fetch(str(task.source), local / "in")
            except Exception as e:
                if name:
                    storage.remove(str(task.out), name)
                result = Result(str(task.source), task.name, status=2)
                result.error = f"{task.source}: cannot fetch: {problem(e)}"
                return result
        if not storage.is_url(task.out):
            result = _run_local(replace(task, source=source, given=str(task.source)), profile)
            result.source = str(task.source)
            result.error = result.error.replace(str(source), str(task.source))
            return result
        staged = local / "out"
        staged.mkdir()
        result = _run_local(replace(task, source=source, out=staged, retry=False,
                                    given=str(task.source)), profile)
        result.source = str(task.source)
        result.error = result.error.replace(str(source), str(task.source))
        result.attempts = attempt
        if not result.ok:
            storage.remove(out, name)
            return result
        names = [Path(p).name for p in result.written]
        result.written = [f"{out.rstrip('/')}/{n}" for n in names]
        try:
            old = ([storage.basename(str(t))
                    for t in targets(out, task.name, task.plot, task.write_csv)]
                   if task.overwrite else None)
            storage.commit(staged, names, out, name,
                           journal=(JOURNAL, pickle.dumps(result)) if task.retry else None,
                           replace=old)
        except OSError as e:
            storage.remove(out, name)
            result.ok, result.status, result.written = False, 1, []
            result.error = f"{out}: cannot write: {problem(e)}"
        else:
            if task.retry:
                faults.pause("committed")
        return result


def _progress(name: str, total: int, enabled: bool) -> Any:
    if not enabled or not sys.stderr.isatty():
        return None
    from tqdm import tqdm  # type: ignore[import-untyped]
    return tqdm(total=total, desc=name, unit="msg", file=sys.stderr, delay=1.0, leave=False,
                dynamic_ncols=True)


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
    source, name, namespace = Path(task.source), task.name, task.namespace
    prof = Profile() if profile else None
    result.profile = prof

    reader = bagio.open_reader(source)
    csv_file = friction_file = None
    try:
        # metadata.yaml's count is another writer's word: 0 for a file that holds messages
        # is possible, so a zero is checked by reading the first message
        if reader.message_count == 0 and next(iter(reader.messages()), None) is None:
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
                + "; nothing solved (are --params and --namespace right?)"
                + _namespaces_hint(reader.connections, namespace))
        custom = {PARAMETERS_KEY: json.dumps(dict(config.values), sort_keys=True),
                  "fastsim.input": task.given or str(source), "fastsim.replay": PROG}
        estimating = FRICTION_ESTIMATE_TOPIC in pipeline.outputs()
        inner = pipeline if isinstance(pipeline, Pipeline) else pipeline.pipeline
        wearing = bool(config["wear_outputs"])
        rows = friction_rows = None
        if task.write_csv:
            csv_file = open(staging / f"{name}.csv", "w", newline="", encoding="utf-8")
            rows = csv.writer(csv_file, lineterminator="\n")
            rows.writerow(CSV_HEADER + (WEAR_COLUMNS if wearing else ()))
            if estimating:
                friction_file = open(staging / friction_csv(name), "w", newline="",
                                     encoding="utf-8")
                friction_rows = csv.writer(friction_file, lineterminator="\n")
                friction_rows.writerow(FRICTION_CSV_HEADER)
        series = {c: Series() for c in contacts} if task.plot else None
        mu = float(config["friction_coefficient"])
        out = _Outputs(pipeline, rows, series, str(config["method"]),
                       str(config["friction_law"]), mu=mu, friction_rows=friction_rows,
                       estimates=Series(ESTIMATE_COLUMNS) if task.plot and estimating else None,
                       path=FrictionPath(mu) if estimating else None,
                       wear=inner.wear if wearing else None)
        bar = _progress(name, reader.message_count, task.progress)
        indexed = bulk.open_indexed(source, reader) if task.path != "rosbags" else None
        if indexed is not None:
            try:
                first, last = _replay_indexed(task, indexed, reader, staging, pipeline, custom,
                                              out, bar, prof, result)
            finally:
                indexed.close()
        else:
            first, last = _replay_messages(task, reader, staging, pipeline, custom, out, bar,
                                           prof, result)
        result.duration_s = (last - first) * 1e-9
        if bar is not None:
            bar.close()
        for c in contacts:
            result.counts[c] = pipeline.counts(c)
            result.solve_us[c] = pipeline.solve_time_percentiles(c)
        result.kinematics = dict(pipeline.kinematics_counts)
        result.friction = out.path
        result.wear = [out.wear_summary[c].line(c) for c in contacts if c in out.wear_summary]
        result.unused = unused_topics(reader.connections, out.seen, pipeline, namespace)
        if task.write_csv:
            result.tabled = {resolve(f"contact/{c}/{kind}", namespace): f"{name}.csv"
                             for c in contacts for kind in ("wrench", "creepage")
                             + (("energy", "damage") if wearing else ())}
            if estimating:
                result.tabled[resolve(FRICTION_ESTIMATE_TOPIC, namespace)] = friction_csv(name)
        for f in (csv_file, friction_file):
            if f is not None:
                f.close()
        if task.plot and series is not None:
            plot_start = time.perf_counter()
            write_plot(staging / f"{name}.png", name, contacts, series, mu,
                       str(config["friction_law"]), out.estimates)
            result.plot_s = time.perf_counter() - plot_start
    finally:
        for f in (csv_file, friction_file):
            if f is not None:
                f.close()
        reader.close()
    result.wall_s = time.perf_counter() - start_wall


@dataclass
class _Outputs:
    """Where a wrench's and an estimate's CSV rows and plot samples go (each may be off).

    ``mu``: the static coefficient in force (the wrenches of a cycle are
    solved with the estimate of the cycle before); ``path``: the estimate's
    path (estimation on); ``seen``: the input messages by channel or
    connection id (the replay counts them).
    """

    pipeline: AnyPipeline
    rows: Any
    series: dict[str, Series] | None
    method: str
    law: str
    first: int = 0
    mu: float = 0.0
    friction_rows: Any = None
    estimates: Series | None = None
    path: FrictionPath | None = None
    seen: dict[str, int] = field(default_factory=dict)
    #: the pipeline's wear indicators of an outcome (wear_outputs on), their summary
    wear: Callable[[Outcome], WearIndicators | None] | None = None
    wear_summary: dict[str, WearSummary] = field(default_factory=dict)

    def outcome(self, outcome: Any, log_ns: int) -> None:
        """Record one outcome's wrench and friction estimate (the per-message paths)."""
        if outcome.has_wrench:
            record(outcome, log_ns - self.first, self.rows,
                   None if self.series is None else self.series[outcome.contact],
                   self.method, self.law, self.mu, self.wear, self.wear_summary)
        if outcome.friction is not None:
            self.estimate(outcome.friction, log_ns)

    def estimate(self, e: FrictionEstimate, log_ns: int) -> None:
        """Record a rig cycle's friction estimate; its mu is in force from now on."""
        t = (log_ns - self.first) * 1e-9
        path = self.path
        if path is not None:
            steps = _estimation_counts(self.pipeline)["steps"]
            if steps > len(path.steps):   # this cycle's update saw a step of mu_s
                path.steps.append((t, self.mu))
            path.cycles += 1
            path.statuses[e.status] = path.statuses.get(e.status, 0) + 1
            path.last, path.sigma = e.mu, e.sigma
            path.utilisation = max(path.utilisation, e.utilisation)
        if self.friction_rows is not None:
            self.friction_rows.writerow(friction_row(e))
        if self.estimates is not None:
            self.estimates.add(t, e.mu, e.sigma, e.utilisation)
        self.mu = e.mu


def _estimation_counts(pipeline: AnyPipeline) -> dict[str, int]:
    """Return the friction estimator's counts (``steps``: the steps of mu_s it saw)."""
    inner = pipeline if isinstance(pipeline, Pipeline) else pipeline.pipeline
    return inner.estimation_counts


def unused_topics(connections: Any, seen: dict[str, int], pipeline: AnyPipeline,
                  namespace: str) -> list[tuple[str, int, str]]:
    """Return the bag's topics the node could take but this replay did not, and what takes them.

    ``(topic, messages, hint)`` in the bag's order, ``seen``: the messages
    read by resolved topic.  Patch topics of contacts not configured (the
    ``contacts`` parameter takes them), or under another namespace; the
    measured wrench with friction estimation off; poses and loads with
    patches from topics.  Only copied to the output bag.
    """
    inputs = {resolve(i.topic, namespace): i for i in pipeline.inputs()}
    outputs = {resolve(t, namespace) for t in pipeline.outputs()}
    from_topics = any(i.kind == "patch" for i in inputs.values())
    prefix, ns = resolve("contact/", namespace), resolve(namespace)
    found: dict[str, str] = {}
    for conn in connections:
        topic = resolve(conn.topic)
        if topic in inputs or topic in outputs or topic in found:
            continue
        hint = ""
        m = _PATCH_TOPIC.match(topic)
        if m is not None and from_topics:
            if topic.startswith(prefix):
                contact = topic[len(prefix):-len("/patch")]
                hint = (f"add {contact!r} to the 'contacts' parameter" if _contact_name(contact)
                        else f"{contact!r} is not a name the 'contacts' parameter takes")
            else:
                other = m.group(1) or "/"
                hint = f"outside the namespace {ns} (--namespace {other} replays it)"
        elif topic == resolve(MEASURED_WRENCH_TOPIC, namespace):
            hint = "set 'friction_estimation' to on to estimate mu_s from it"
        elif from_topics and topic in (resolve(POSE_TOPIC, namespace),
                                       resolve(LOAD_TOPIC, namespace)):
            hint = "set 'patch_source' to profiles to compute the patches from them"
        if hint:
            found[topic] = hint
    return [(topic, seen.get(topic, 0), hint) for topic, hint in found.items()]


def _replay_indexed(task: Task, indexed: Any, reader: Any, staging: Path, pipeline: AnyPipeline,
                    custom: dict[str, str], out: _Outputs, bar: Any, prof: Profile | None,
                    result: Result) -> tuple[int, int]:
    """Replay an indexed MCAP input by the chunk (:mod:`~fastsim_ros.replay.bulk`)."""
    replay = bulk.IndexedReplay(Path(task.source), indexed, reader, staging / task.name, pipeline,
                                task.namespace, custom, result,
                                keep_inputs=prof is not None,
                                batched=task.path != "messages")
    try:
        first, last = replay.run(out, None if bar is None else bar.update)
        replay.close()
    except BaseException:
        replay.abort()
        raise
    for cid, n in replay.seen.items():
        topic = resolve(indexed.channels[cid].topic)
        out.seen[topic] = out.seen.get(topic, 0) + n
    result.published = {topic: replay.writer.counts[cid]
                        for topic, cid in replay.out_channels.items()}
    if prof is not None:
        prof.phases = dict(replay.phases)
        if replay.batch is not None:
            t = replay.batch.timing
            prof.phases.update(decode=t.decode, kinematics=t.kinematics, solve=t.solve,
                               state=t.state, scan=t.scan, solver=t.solver)
            prof.solves = t.inputs or []
        prof.phases["decompress"] = indexed.decompress_s
    return first, last


def _replay_messages(task: Task, reader: Any, staging: Path, pipeline: AnyPipeline,
                     custom: dict[str, str], out: _Outputs, bar: Any, prof: Profile | None,
                     result: Result) -> tuple[int, int]:
    """Replay any input message by message with rosbags (the reference path)."""
    source, namespace, config = task.source, task.namespace, pipeline.config
    clock = time.perf_counter_ns
    absolute = {resolve(t, namespace): msgtype for t, msgtype in pipeline.outputs().items()}
    inputs = {resolve(i.topic, namespace): i for i in pipeline.inputs()}
    writer = bagio.open_writer(staging / task.name, custom)
    qos_out = bagio.qos(config["output_reliability"], int(config["qos_depth"]))
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
            result.published[topic] = result.published.get(topic, 0) + 1

        diagnostics = resolve(DIAGNOSTICS_TOPIC, namespace)
        first: int | None = None
        last: int | None = None
        next_diag = 0
        seen: dict[int, int] = {}
        t_read = clock()
        for conn, log_ns, raw in bagio.messages(reader, str(source)):
            if prof is not None:
                now = clock()
                prof.read.append(now - t_read)
            seen[conn.id] = seen.get(conn.id, 0) + 1
            if first is None:
                first = out.first = log_ns
                next_diag = first + 1_000_000_000
            last = log_ns
            result.messages_in += 1
            if bar is not None and result.messages_in % _PROGRESS_EVERY == 0:
                bar.update(_PROGRESS_EVERY)
            if log_ns >= next_diag:
                put(diagnostics, log_ns, serialize_message(pipeline.diagnostics(log_ns)))
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
                        if outcome.status == "solved" and outcome.patch is not None \
                                and outcome.creepage is not None:
                            prof.solves.append(_solve_input(outcome))
                    out.outcome(outcome, log_ns)
                    t1 = clock()
            t_read = clock()
        if first is None or last is None:
            raise BadInput(f"{source}: empty bag (no messages)")
        put(diagnostics, last, serialize_message(pipeline.diagnostics(last)))
    for conn in reader.connections:
        topic = resolve(conn.topic)
        out.seen[topic] = out.seen.get(topic, 0) + seen.get(conn.id, 0)
    return first, last


def _solve_input(outcome: Any) -> tuple[Any, ...]:
    """Return a solved patch as it was solved: a batch of one (:attr:`Profile.solves`)."""
    patch, creep = outcome.patch, outcome.creepage
    p, x0, y0, phi = patch.pressure, patch.x0, patch.y0, creep.phi
    if creep.speed < 0.0:  # turned by 180 degrees, as the pipeline solves it
        p, x0, y0 = turned_grid(p, x0, y0, patch.dx, patch.dy)
        phi = -phi
    return (p[None], np.array([[x0, y0, patch.dx, patch.dy]]),
            np.array([[creep.xi, creep.eta, phi]]), np.ones(1, dtype=np.bool_))


def _namespaces_hint(connections: Any, namespace: str) -> str:
    """Name the namespaces under which the bag does have patch topics (for the warning)."""
    found = sorted({m.group(1) or "/" for conn in connections
                    if (m := _PATCH_TOPIC.match(resolve(conn.topic))) is not None}
                   - {resolve(namespace)})
    if not found:
        return ""
    return "; the bag's patch topics are under " + ", ".join(
        f"{ns} (--namespace {ns})" for ns in found)
