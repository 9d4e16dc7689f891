"""Where the tasks run: the one seam between the command line and the replay of one input.

An executor takes the :class:`~fastsim_ros.replay.run.Task` of every input
and yields their :class:`~fastsim_ros.replay.results.Result` in the tasks'
order; each task runs :func:`~fastsim_ros.replay.run.run_task`, which
stages and commits its own outputs, so an executor only moves tasks and
results.  ``stop()`` ends the work at once (Ctrl-C, SIGTERM): the command
line then removes what unfinished tasks left.

- :class:`InProcess`: one task after the other in this process (``--jobs 1``);
- :class:`LocalPool`: ``N`` forked worker processes (``--jobs N``): they
  inherit the compiled kernels loaded before the fork.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import signal
from collections.abc import Iterator, Sequence
from typing import Protocol

from fastsim_ros.replay.results import Result
from fastsim_ros.replay.run import Task, run_task


class Executor(Protocol):
    """Runs tasks somewhere; yields their results in the tasks' order."""

    def results(self, tasks: Sequence[Task]) -> Iterator[Result]:
        """Run every task; yield each result (in the tasks' order) as it is known."""
        ...

    def stop(self) -> None:
        """Stop every running task at once (the caller cleans up their temporary files)."""
        ...

    def close(self) -> None:
        """Release the executor's resources after the last result."""
        ...


class _Base:
    def stop(self) -> None:
        """Nothing runs outside this process."""

    def close(self) -> None:
        """Nothing to release."""


class InProcess(_Base):
    """One task after the other, in this process."""

    def results(self, tasks: Sequence[Task]) -> Iterator[Result]:
        """Run the tasks in turn; yield each result."""
        return (run_task(task) for task in tasks)


def _worker_signals() -> None:
    """Let a worker ignore Ctrl-C and die of SIGTERM: the main process stops it and cleans up."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


class LocalPool(_Base):
    """``jobs`` forked worker processes on this machine."""

    def __init__(self, jobs: int) -> None:
        self._pool = cf.ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("fork"),
                                            initializer=_worker_signals)

    def results(self, tasks: Sequence[Task]) -> Iterator[Result]:
        """Submit every task; yield the results in the tasks' order."""
        futures = [self._pool.submit(run_task, task) for task in tasks]
        return (f.result() for f in futures)

    def stop(self) -> None:
        """Stop the workers at once (they ignore SIGINT: the main process cleans up)."""
        processes = list(getattr(self._pool, "_processes", {}).values())
        for proc in processes:
            proc.terminate()
        for proc in processes:
            proc.join(timeout=5)
            if proc.is_alive():
                proc.kill()
                proc.join(timeout=5)
        self._pool.shutdown(wait=False, cancel_futures=True)

    def close(self) -> None:
        """Wait for the workers to exit."""
        self._pool.shutdown(wait=True)
