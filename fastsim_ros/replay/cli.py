"""The command line of ``fastsim_replay``: flags, checks before any work, summaries, status."""

from __future__ import annotations

import argparse
import os
import re
import signal
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from fastsim_ros.ros.params import ParameterError, defaults, load_params_file
from fastsim_ros.pipeline import PipelineConfig
from fastsim_ros.pipeline.profiles import table_of, wheelset_of
from fastsim_ros.replay.bagio import input_name
from fastsim_ros.replay.executors import Executor, InProcess, LocalPool
from fastsim_ros.replay import storage
from fastsim_ros.replay.cluster import ClusterError, scheduler_address
from fastsim_ros.replay.errors import problem
from fastsim_ros.replay.run import PROG, Task, remove_staging, targets, warm_up


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> Any:  # one line, exit 2 (argparse prints usage too)
        self.exit(2, f"{self.prog}: error: {message}\n")


def parser() -> argparse.ArgumentParser:
    """Return the command-line parser."""
    p = _Parser(prog=PROG, allow_abbrev=False,
                description="Replay rosbag2 bags (directories or .mcap files) through the "
                            "fastsim node's pipeline; write bags with the creep forces.")
    p.add_argument("inputs", nargs="+", metavar="IN", type=_location,
                   help="a rosbag2 directory or a single .mcap file (a path or an fsspec URL)")
    p.add_argument("-o", "--output", required=True, type=_location, metavar="OUT",
                   help="output directory, made if missing (a path or an fsspec URL)")
    p.add_argument("--params", type=Path, metavar="FILE",
                   help="the node's ROS 2 parameter file (default: every default, and the "
                        "contacts those with a patch topic in the bag)")
    p.add_argument("--namespace", type=namespace, default="/", metavar="NS",
                   help="the node's namespace: patches on NS/contact/<name>/patch, outputs "
                        "under NS (default /; a bag's relative topic names are in /)")
    p.add_argument("--plot", action="store_true", help="write OUT/NAME.png")
    p.add_argument("--csv", action="store_true",
                   help="write OUT/NAME.csv, one row per wrench (and with friction estimation "
                        "OUT/NAME.friction.csv, one row per estimate)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace the outputs of an earlier run (each once its successor is "
                        "complete; a failed run leaves them as they were)")
    p.add_argument("--jobs", type=_jobs, default=1, metavar="N",
                   help="replay the inputs on N worker processes (default 1)")
    p.add_argument("--scheduler", metavar="ADDRESS", type=scheduler_address,
                   help="replay each input as a task on the Dask distributed cluster of this "
                        "scheduler (e.g. tcp://10.0.0.5:8786) instead of on this machine")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar (it shows only on a terminal anyway)")
    return p


_TOKEN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def namespace(text: str) -> str:
    """Return a ROS namespace made absolute (``rig1`` -> ``/rig1``); refuse a malformed one.

    Tokens of letters, digits and underscores, not starting with a digit,
    separated by single slashes (ROS 2 name rules; one trailing slash is
    dropped); ``/`` is the root.
    """
    name = text if text.startswith("/") else "/" + text
    if len(name) > 1 and name.endswith("/") and not name.endswith("//"):
        name = name[:-1]  # /rig1/ as a shell completes a directory-like name: /rig1
    if name == "/":
        return name
    tokens = name[1:].split("/")
    if not all(_TOKEN.match(t) for t in tokens):
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a ROS namespace (tokens of letters, digits and underscores, "
            "not starting with a digit, separated by single slashes)")
    return name


def _location(text: str) -> Path | str:
    """Return a local path as a Path, an fsspec URL (``protocol://...``) as it is."""
    return text if storage.is_url(text) else Path(text)


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


def _terminate(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def main(argv: Sequence[str] | None = None) -> int:
    """Run the replay; return the exit status (see the package docstring)."""
    args = parser().parse_args(argv)
    out: Path | str = args.output
    values = defaults()
    if args.params is not None:
        try:
            values = load_params_file(args.params, namespace=args.namespace)
            if values["patch_source"] == "profiles":  # its profiles read before any work
                config = PipelineConfig.from_values(values)
                wheelset = wheelset_of(config)
                if values["profile_table"]:
                    # the contact table built (or read) once here, into its cache, so that
                    # the tasks only read it: a pool does not build it N times over
                    table_of(config, wheelset,
                             log=lambda m: print(f"{PROG}: {m}", file=sys.stderr, flush=True))
        except ParameterError as e:
            return _fail(f"{args.params}: {e}" if str(args.params) not in str(e) else str(e))
    if args.scheduler is not None and args.jobs != 1:
        return _fail("--jobs is for this machine, --scheduler for a cluster: give one")
    names: dict[str, Path | str] = {}
    # every file each input writes in OUT (NAME, NAME.csv, NAME.friction.csv, NAME.png): an
    # input named x.csv replayed with --csv beside one named x would write x.csv twice
    written: dict[str, Path | str] = {}
    for src in args.inputs:
        name = input_name(src)
        if not name or name.startswith("."):
            return _fail(f"{src}: cannot name an output after it")
        if name in names:
            return _fail(f"{src}: same name {name!r} as {names[name]}; outputs would clash")
        names[name] = src
        for target in targets("", name, args.plot, args.csv):
            other = written.setdefault(str(target), src)
            if other is not src:
                return _fail(f"{src}: its output {target} would also be {other}'s; outputs "
                             "would clash")
    try:
        if storage.is_file(out):
            return _fail(f"{out}: exists and is not a directory")
        for name in names:
            for target in targets(out, name, args.plot, args.csv):
                if not args.overwrite and storage.exists(target):
                    return _fail(f"{target}: exists already; not overwritten (--overwrite "
                                 "replaces it)")
        made = not storage.exists(out)
        storage.makedirs(out)
    except (OSError, ValueError, ImportError) as e:
        print(f"{PROG}: {out}: cannot make the output directory: {problem(e)}",
              file=sys.stderr)
        return 1
    tag = f"{os.getpid()}"
    jobs = min(args.jobs, len(names))
    tasks = [Task(src, name, out, values, plot=args.plot, write_csv=args.csv,
                  contacts_from_bag=args.params is None, namespace=args.namespace, tag=tag,
                  progress=not args.no_progress and jobs == 1 and args.scheduler is None,
                  overwrite=args.overwrite)
             for name, src in names.items()]
    previous = signal.signal(signal.SIGTERM, _terminate)
    status = 0
    executor: Executor | None = None
    try:
        if args.scheduler is not None:
            from fastsim_ros.replay.cluster import Cluster
            executor = Cluster(args.scheduler, progress=not args.no_progress)
        else:
            warm_up()  # load the kernels once (forked workers inherit them)
            executor = InProcess() if jobs == 1 else LocalPool(jobs)
        for r in executor.results(tasks):
            for w in r.warnings:
                print(f"{PROG}: warning: {w}", file=sys.stderr)
            if r.ok:
                print(r.summary(), flush=True)
            else:
                print(f"{PROG}: {r.error}", file=sys.stderr, flush=True)
                status = max(status, r.status)
        remove_staging(out, tag)  # every result in: what a cluster's attempts kept
    except KeyboardInterrupt:
        if executor is not None:
            executor.stop()
            executor = None
        remove_staging(out, tag)
        print(f"{PROG}: interrupted; nothing left of the unfinished inputs", file=sys.stderr)
        return 130
    except ClusterError as e:
        executor = None  # nothing to close: the scheduler is gone
        if made and not storage.is_url(out) and not os.listdir(out):
            os.rmdir(out)  # never reached: nothing of this run is left
        print(f"{PROG}: {e}; the outputs already written stay", file=sys.stderr, flush=True)
        return 1
    finally:
        if executor is not None:
            executor.close()
        signal.signal(signal.SIGTERM, previous)
    return status
