"""The replay on a Dask distributed cluster: ``fastsim_replay ... --scheduler ADDRESS``.

One more executor (:mod:`~fastsim_ros.replay.executors`): each input is one
task, :func:`~fastsim_ros.replay.run.run_task` run on a worker (which must
have this package installed and, for local paths, see the same files as the
client: a shared file system, or fsspec URLs).  The task stages and commits
its own outputs, so what the cluster adds is only where it runs:

- no broadcast to the workers, which one dead worker would break: each
  worker loads the compiled kernels in its first task
  (:func:`~fastsim_ros.replay.run.warm_up`, once per process);
- a worker that dies at any moment of a task (its warm-up, the replay, the
  renames of its outputs, after them with its result not yet fetched): the
  scheduler runs the task again on another worker (Dask's own rescheduling
  of a lost worker's tasks, and of the results it held); the new attempt
  removes what the dead one left in OUT, or finishes its commit and
  returns its result if it had committed (``Task.retry``), and counts
  itself (``Result.attempts``, in the summary);
- a bad bag is a result with its one-line error, not a failed task: it is
  reported once and never retried;
- a task whose workers kept dying (Dask's ``allowed-failures``): reported
  as a failed input;
- the scheduler lost: :class:`ClusterError` (one line); outputs already
  committed stay (each was renamed into place whole).
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import subprocess
import sys
import time
from collections.abc import Iterator, Sequence
from concurrent.futures import CancelledError
from dataclasses import replace
from pathlib import Path
from typing import Any

from fastsim_ros.replay.errors import ClusterError, problem
from fastsim_ros.replay.results import Result
from fastsim_ros.replay.run import Task, run_task, warm_up

#: seconds to wait for the scheduler when connecting (``FASTSIM_DASK_CONNECT_TIMEOUT``: a
#: slow network may need more, a test of an unreachable address less)
CONNECT_TIMEOUT = 10.0


def connect_timeout() -> float:
    """Return the seconds to wait for the scheduler: the environment's, else the default."""
    text = os.environ.get("FASTSIM_DASK_CONNECT_TIMEOUT", "")
    try:
        value = float(text)
    except ValueError:
        return CONNECT_TIMEOUT
    return value if math.isfinite(value) and value > 0.0 else CONNECT_TIMEOUT


#: Dask settings (environment variables) for a cluster that replays bags: no statistical
#: profiler on the workers (it samples the task's stack every 10 ms) and no work stealing
#: (tasks of similar cost; the scheduler's bookkeeping of it costs CPU per task); together
#: about 1.4 ms less CPU per task on this machine (bench_replay.py --scheduler)
LEAN = {"DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED": "False",
        "DASK_DISTRIBUTED__SCHEDULER__WORK_STEALING": "False"}


def warm_worker() -> str:
    """Load the compiled kernels (numba's disk cache), once per process: :func:`warm_up`."""
    warm_up()
    return "ok"


def scheduler_address(text: str) -> str:
    """Return a Dask scheduler address checked as Dask parses it (argparse's type).

    ``tcp://host:port`` (or ``host:port``), ``tls://``, ``ws://``, ...: a
    host and a port.  An address Dask cannot parse is refused here, before
    a client is made (a client that fails to start is closed by its
    finaliser 20 s later, with a traceback); ``inproc://`` names a scheduler
    inside another process's memory, never reachable from this one.
    """
    from distributed.comm.addressing import parse_address, parse_host_port
    try:
        scheme, location = parse_address(text)
        if scheme == "inproc":
            raise ValueError("an inproc:// scheduler lives in its own process only")
        parse_host_port(location)
    except ValueError as e:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a Dask scheduler address (tcp://host:port): {e}") from None
    return text


class Cluster:
    """Tasks on the Dask distributed scheduler at ``address`` (``tcp://host:8786``, ...)."""

    def __init__(self, address: str, *, progress: bool = False) -> None:
        from distributed import Client
        # the client's own reconnection attempts log tracebacks: a lost or unreachable
        # scheduler is one line of ours instead
        logging.getLogger("distributed").setLevel(logging.CRITICAL)
        self.address = address
        self.progress = progress
        self.futures: list[Any] = []
        try:
            self.client = Client(address, timeout=f"{connect_timeout()}s",
                                 set_as_default=False)
        except (OSError, TimeoutError, ValueError) as e:
            raise ClusterError(f"cannot reach the Dask scheduler at {address}: "
                               f"{problem(e)}") from None

    def results(self, tasks: Sequence[Task]) -> Iterator[Result]:
        """Submit every task; yield the results in the tasks' order."""
        from distributed import as_completed
        client = self.client
        # each attempt keeps its committed result until the end of the run (the command
        # line removes it): a worker lost with the result not yet fetched costs no replay
        tasks = [replace(t, retry=True) for t in tasks]
        # all the tasks in one message (client.map, not a submit each) and the results
        # fetched by the batch as they complete (not a round trip each): on a small cluster
        # the client and the scheduler share the cores with the workers, a few ms per bag
        keys = [f"fastsim-replay-{t.tag}-{t.name}" for t in tasks]
        self.futures = client.map(run_task, tasks, key=keys, pure=False)
        place = {f.key: k for k, f in enumerate(self.futures)}
        bar = self._bar(len(tasks))
        done: dict[int, Result] = {}
        first = 0   # the first task whose result is not yet given out
        for batch in as_completed(self.futures, loop=client.loop).batches():
            finished = [f for f in batch if f.status == "finished"]
            try:
                got = dict(zip((f.key for f in finished), client.gather(finished)))
            except Exception:   # each on its own below, for its own error
                got = {}
            for future in batch:
                k = place[future.key]
                done[k] = got[future.key] if future.key in got else self._result(tasks[k], future)
            while first in done:
                if bar is not None:
                    bar.update(1)
                yield done.pop(first)
                first += 1
        if bar is not None:
            bar.close()

    def _result(self, task: Task, future: Any) -> Result:
        """Return a task's result, or the failed input's, from its future alone."""
        from distributed import KilledWorker
        from distributed.comm import CommClosedError
        try:
            result: Result = future.result()
        except KilledWorker as e:   # its workers kept dying: give up on this input
            result = Result(str(task.source), task.name, status=1,
                            error=f"{task.source}: the workers replaying it died "
                                  f"({problem(e)})")
        except ImportError as e:   # the worker has not this package (or not all of it)
            result = Result(str(task.source), task.name, status=1,
                            error=f"{task.source}: the workers of {self.address} cannot "
                                  f"load the package: {problem(e)}")
        except Exception as e:
            lost = (CancelledError, OSError, CommClosedError)
            if self.client.status != "running" or isinstance(e, lost):
                raise ClusterError(f"lost the Dask scheduler at {self.address} "
                                   f"({type(e).__name__})") from None
            result = Result(str(task.source), task.name, status=1,
                            error=f"{task.source}: internal error on a worker: "
                                  f"{problem(e)}")
        return result

    def _bar(self, total: int) -> Any:
        if not self.progress or not sys.stderr.isatty():
            return None
        from tqdm import tqdm  # type: ignore[import-untyped]
        return tqdm(total=total, desc="bags", unit="bag", file=sys.stderr, leave=False,
                    dynamic_ncols=True)

    def stop(self) -> None:
        """Cancel the tasks not done, then disconnect.

        A task already running finishes or is dropped by its worker; the
        command line removes its staging directory.
        """
        try:
            self.client.cancel(self.futures, force=True)
        finally:
            self.close()

    def close(self) -> None:
        """Disconnect from the scheduler."""
        try:
            self.client.close(timeout=5)
        except Exception:
            pass


def _scheduler_address(file: Path) -> str | None:
    """Return the address a Dask scheduler file gives, or None while it is missing or partial."""
    try:
        address = json.loads(file.read_text())["address"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return address if isinstance(address, str) and address else None


class LocalProcesses:
    """A Dask scheduler and ``workers`` worker processes on this machine (tests, benchmarks).

    Started with this interpreter and ``env`` (this package on their path;
    :data:`LEAN` added where ``env`` does not set those variables),
    logs in ``directory``; ``nanny=False``: a killed worker stays dead.
    ``address`` once they are up; :meth:`close` ends them.
    """

    def __init__(self, directory: Path, workers: int = 2, *, env: dict[str, str] | None = None,
                 cwd: Path | None = None, nanny: bool = False, timeout: float = 60.0) -> None:
        self.directory = directory
        self.env = dict(os.environ if env is None else env)
        for key, value in LEAN.items():   # unless the caller's environment says otherwise
            self.env.setdefault(key, value)
        self.cwd = cwd
        self.procs: list[subprocess.Popen[bytes]] = []
        self.workers: list[subprocess.Popen[bytes]] = []
        file = directory / "scheduler.json"
        try:
            self.procs.append(self._start("distributed.cli.dask_scheduler", "--host",
                                          "127.0.0.1", "--port", "0", "--no-dashboard",
                                          "--scheduler-file", str(file)))
            deadline = time.monotonic() + timeout
            # the scheduler writes its file in place, not atomically: it can be seen empty or
            # half-written, so it is read until it holds the address
            address = _scheduler_address(file)
            while address is None:
                if time.monotonic() > deadline or self.procs[0].poll() is not None:
                    raise ClusterError("the local Dask scheduler did not start")
                time.sleep(0.05)
                address = _scheduler_address(file)
            self.address: str = address
            for k in range(workers):
                self.workers.append(self._start(
                    "distributed.cli.dask_worker", self.address, "--nthreads", "1",
                    "--no-dashboard", "--name", f"w{k}", *(() if nanny else ("--no-nanny",))))
            self.procs += self.workers
            from distributed import Client
            with Client(self.address, timeout=f"{timeout}s", set_as_default=False) as client:
                client.wait_for_workers(workers, timeout=timeout)
        except BaseException:
            self.close()
            raise

    def _start(self, module: str, *args: str) -> subprocess.Popen[bytes]:
        log = open(self.directory / f"{module.rsplit('.', 1)[-1]}-{len(self.procs)}.log", "wb")
        return subprocess.Popen([sys.executable, "-m", module, *args], cwd=self.cwd,
                                env=self.env, stdout=log, stderr=subprocess.STDOUT)

    def close(self) -> None:
        """End the workers, then (once they are gone) the scheduler.

        Not all at once: a worker whose scheduler goes away while it closes
        can hang in its own close (Dask's ``Worker.close`` cancelled) until
        it is killed.
        """
        workers = [p for p in self.procs if p in self.workers]
        for group in (workers, [p for p in self.procs if p not in workers]):
            for p in group:
                if p.poll() is None:
                    p.terminate()
            for p in group:
                try:
                    p.wait(timeout=15)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait(timeout=15)
