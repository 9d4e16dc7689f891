"""Run ``fastsim_node`` with a timeline of what its main thread does (``bench_node.py --trace``).

    python benchmarks/node_trace.py OUT.npz [CHECKOUT] --ros-args ...

The node of this checkout's sources (or of ``CHECKOUT``'s), run as its
console script runs it (``fastsim_ros.ros.node.main``), with four kinds of
event recorded on ``time.perf_counter`` (CLOCK_MONOTONIC, the clock of
every process on the machine, so the driver's send and receive times line
up with them):

- ``callback``: each subscription callback (start, end, the input's header
  stamp and its contact's index; twists have contact -1);
- ``diagnostics``: each run of the diagnostics timer's callback;
- ``gc``: each collection of the cyclic garbage collector (``gc.callbacks``:
  start, stop, generation);
- ``spin``: each ``executor.spin_once`` call of the node's loop (entry,
  return): the executor's wake-ups;
- ``on_patch``: each ``Pipeline.on_patch`` inside a patch's callback (the
  pipeline's handler, without the encoding and the publishes).

The events go into preallocated ``array`` buffers (no object the collector
tracks is made per event) and are written to ``OUT.npz`` when the node
exits (SIGTERM).  The recording costs about a microsecond per event.
"""

from __future__ import annotations

import array
import gc
import importlib
import importlib.util
import sys
import time
from pathlib import Path
from typing import Any, Callable

KINDS = ("callback", "diagnostics", "gc", "spin", "on_patch")


class Timeline:
    """Events as parallel arrays: kind, start, end (s), stamp (ns), contact or generation."""

    def __init__(self) -> None:
        self.kind = array.array("b")
        self.start = array.array("d")
        self.end = array.array("d")
        self.stamp = array.array("q")
        self.extra = array.array("q")

    def add(self, kind: int, start: float, end: float, stamp: int, extra: int) -> None:
        self.kind.append(kind)
        self.start.append(start)
        self.end.append(end)
        self.stamp.append(stamp)
        self.extra.append(extra)

    def save(self, path: str) -> None:
        import numpy as np
        np.savez(path, kind=np.frombuffer(self.kind, dtype=np.int8),
                 start=np.frombuffer(self.start), end=np.frombuffer(self.end),
                 stamp=np.frombuffer(self.stamp, dtype=np.int64),
                 extra=np.frombuffer(self.extra, dtype=np.int64))


def install(timeline: Timeline, node_module: Any) -> None:
    """Wrap the node's callbacks, diagnostics, executor and the collector to record events."""
    clock = time.perf_counter
    add = timeline.add
    front = node_module._FrontEnd
    input_callback = front._input_callback

    def traced_input(self: Any, spec: Any) -> Callable[[bytes], None]:
        callback = input_callback(self, spec)
        contacts = list(self.pipeline.config.contacts)
        contact = contacts.index(spec.contact) if getattr(spec, "contact", None) in contacts \
            else -1

        def traced(raw: bytes) -> None:
            t0 = clock()
            callback(raw)
            t1 = clock()
            add(0, t0, t1, int.from_bytes(raw[4:8], "little", signed=True) * 1_000_000_000
                + int.from_bytes(raw[8:12], "little"), contact)
        return traced
    front._input_callback = traced_input

    diagnostics = front._publish_diagnostics

    def traced_diagnostics(self: Any) -> None:
        t0 = clock()
        diagnostics(self)
        add(1, t0, clock(), 0, 0)
    front._publish_diagnostics = traced_diagnostics

    started = [0.0]

    def on_gc(phase: str, info: dict[str, int]) -> None:
        if phase == "start":
            started[0] = clock()
        else:
            add(2, started[0], clock(), 0, info["generation"])
    gc.callbacks.append(on_gc)

    make_executor = node_module.make_executor

    class Spinning:
        """The executor, its ``spin_once`` timed."""

        def __init__(self, executor: Any) -> None:
            self._executor = executor

        def spin_once(self, timeout_sec: float | None = None) -> None:
            t0 = clock()
            try:
                self._executor.spin_once(timeout_sec=timeout_sec)
            finally:
                add(3, t0, clock(), 0, 0)

        def __getattr__(self, name: str) -> Any:
            return getattr(self._executor, name)

    node_module.make_executor = lambda kind: Spinning(make_executor(kind))

    from fastsim_ros.pipeline import Pipeline
    on_patch = Pipeline.on_patch

    def traced_on_patch(self: Any, contact: str, cloud: Any, **kwargs: Any) -> Any:
        t0 = clock()
        outcome = on_patch(self, contact, cloud, **kwargs)
        add(4, t0, clock(), 0, 0)
        return outcome
    Pipeline.on_patch = traced_on_patch  # type: ignore[method-assign]


def main() -> int:
    """Run the node with the timeline; write it on exit."""
    out = sys.argv.pop(1)
    if len(sys.argv) > 1 and not sys.argv[1].startswith("-"):
        sys.path.insert(0, str(Path(sys.argv.pop(1)).resolve()))
    else:
        sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    # the node module where the checkout has it (fastsim_ros/ros/, or the package's top
    # level in a checkout from before the front ends had their package)
    node = importlib.import_module("fastsim_ros.ros.node" if importlib.util.find_spec(
        "fastsim_ros.ros") else "fastsim_ros.node")
    timeline = Timeline()
    install(timeline, node)
    try:
        return node.main()
    finally:
        timeline.save(out)


if __name__ == "__main__":
    sys.exit(main())
