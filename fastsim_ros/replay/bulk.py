"""The replay of an indexed MCAP bag, by the chunk: the path ``fastsim_replay`` takes.

The input is read chunk by chunk (:func:`~fastsim_ros.replay.mcap.windows`:
log-time order, memory bounded by the chunks that overlap in time); its
chunks are copied to the output as they are (the input's messages, with
their channels, schemas and message indexes: no second compression), except
a chunk holding messages on one of the node's output topics, whose other
messages are copied one by one.  The messages of a window go at once
through :class:`~fastsim_ros.replay.batch.Batch` (the pipeline's rules in
bulk), each diagnostics array of the window counts the verdicts before its
place (:meth:`~fastsim_ros.replay.batch.Batch.store`), and the window's
outputs and diagnostics are encoded and written in bulk, in the order the
per-message replay writes them; where the batch does not apply (inputs it
does not know, traction clouds) each message goes through the pipeline's
own handler (:meth:`~fastsim_ros.pipeline.Pipeline.inputs`).  Either way the messages,
their order and their values are those of the per-message replay.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from rclpy.serialization import serialize_message
from rosbags.rosbag2.metadata import dump_qos_v9

from fastsim_ros.pipeline import (DIAGNOSTICS_TOPIC, MARKERS_TOPIC, WHEELSET_WRENCH_TOPIC,
                                  Outcome, Pipeline)
from fastsim_ros.pipeline.profiles import AnyPipeline
from fastsim_ros.replay import bagio, batch, encode, faults, kernels, mcap
from fastsim_ros.replay.bagio import resolve
from fastsim_ros.replay.errors import BadInput, McapError
from fastsim_ros.replay.results import Result

Ints = NDArray[np.int64]
#: messages per window read at a time (each window's chunks stay in memory)
WINDOW = 8192
#: order of a patch's outputs (Pipeline.messages), the diagnostics before them
_DIAG, _WRENCH, _CREEPAGE, _FRAME, _MARKER, _WHEELSET = -1, 0, 1, 2, 4, 5


def open_indexed(source: Path, reader: Any) -> mcap.IndexedMcap | None:
    """Return the input's one MCAP file opened by its index, or ``None``.

    ``None`` (rosbags reads it) for several files, per-message or file
    compression, no summary, no chunk index or no message indexes.
    """
    storage = reader.storage
    files: list[Any] = getattr(storage, "storages", [storage])
    if len(files) != 1 or not isinstance(files[0], mcap_reader_type()):
        return None
    if getattr(reader, "compression_mode", None):
        return None
    try:
        indexed = mcap.open_indexed(Path(getattr(files[0], "path")))
    except (McapError, OSError) as e:
        raise BadInput(f"{source}: unreadable: {e}") from None
    if indexed is not None and not (indexed.chunks
                                    and all(c.index_offsets for c in indexed.chunks)):
        # no chunk index (an unchunked file, or one written without indexes: its messages
        # are still there), or a chunk without message indexes: rosbags reads it
        indexed.close()
        return None
    return indexed


def mcap_reader_type() -> type:
    """Return rosbags' MCAP storage reader class."""
    from rosbags.rosbag2.storage_mcap import McapReader
    return McapReader


class IndexedReplay:
    """One indexed input replayed into one output bag (see the module docstring)."""

    def __init__(self, source: Path, indexed: mcap.IndexedMcap, reader: Any, out_dir: Path,
                 pipeline: AnyPipeline, namespace: str, custom_data: dict[str, str],
                 result: Result, *, keep_inputs: bool = False, batched: bool = True) -> None:
        self.source = source
        self.mcap = indexed
        self.pipeline = pipeline
        self.config = pipeline.config
        self.namespace = namespace
        self.result = result
        self.custom_data = custom_data
        contacts = self.config.contacts
        self.output_types = {resolve(t, namespace): m for t, m in pipeline.outputs().items()}
        self.frame_id = str(self.config["wheelset_frame"])
        out_dir.mkdir()
        self.out_dir = out_dir
        self.writer = mcap.McapWriter(out_dir / f"{out_dir.name}.mcap")
        self.phases: dict[str, float] = {"read": 0.0, "copy": 0.0, "encode": 0.0,
                                         "write": 0.0, "diagnostics": 0.0, "csv": 0.0}
        #: the input's messages read, by channel id
        self.seen: dict[int, int] = {}
        # the input's channels: copied with their ids and schemas, but those on output topics
        self.skip = {cid for cid, ch in indexed.channels.items()
                     if resolve(ch.topic) in self.output_types}
        self.meta: list[tuple[mcap.Channel, str, list[Any], str]] = []
        connections = {(c.topic, c.msgtype): c for c in reader.connections}
        used_schemas = {ch.schema_id for cid, ch in indexed.channels.items()
                        if cid not in self.skip}
        for sid in sorted(used_schemas):
            if sid in indexed.schemas:
                self.writer.add_schema(indexed.schemas[sid])
        for cid, ch in sorted(indexed.channels.items()):
            if cid in self.skip:
                continue
            self.writer.add_channel(ch)
            schema = indexed.schemas.get(ch.schema_id)
            msgtype = schema.name if schema is not None else ""
            conn = connections.get((ch.topic, msgtype))
            qos = dump_qos_v9(list(getattr(conn.ext, "offered_qos_profiles", ())) if conn
                              else [])
            digest = bagio.definition(conn)[1] if conn is not None else ""
            self.meta.append((ch, msgtype, qos, digest))
        self.next_schema = max(indexed.schemas, default=0) + 1
        self.next_channel = max(indexed.channels, default=0) + 1
        self.out_schemas: dict[str, int] = {}
        self.out_channels: dict[str, int] = {}
        self.qos_out = bagio.qos(self.config["output_reliability"], int(self.config["qos_depth"]))
        self.qos_text: str | None = None
        self.qos_dicts: list[Any] = []
        # the inputs the pipeline takes, by channel
        inputs = {resolve(i.topic, namespace): i for i in pipeline.inputs()}
        self.handlers = {cid: inputs[resolve(ch.topic)] for cid, ch in indexed.channels.items()
                         if resolve(ch.topic) in inputs}
        self.batch: batch.Batch | None = None
        if batched and isinstance(pipeline, Pipeline) and batch.supported(pipeline):
            self.batch = batch.Batch(pipeline, {
                cid: (i.kind, contacts.index(i.contact) if i.contact is not None else 0)
                for cid, i in self.handlers.items()}, keep_inputs=keep_inputs)
            scale = float(self.config["marker_scale"])
            self.encoders = {c: (encode.Stamped(f"{c}_contact", 6),
                                 encode.Stamped(f"{c}_contact", 3),
                                 encode.Stamped(self.frame_id, 7),
                                 encode.Markers(self.frame_id, k, c, scale))
                             for k, c in enumerate(contacts)}
            self.wheelset_encoder = encode.Stamped(self.frame_id, 6)

    # ---------------------------------------------------------------- channels

    def channel(self, topic: str) -> int:
        """Return the output channel of an output topic, declared on first use."""
        cid = self.out_channels.get(topic)
        if cid is not None:
            return cid
        msgtype = self.output_types[topic]
        sid = self.out_schemas.get(msgtype)
        if sid is None:
            sid = self.out_schemas[msgtype] = self.next_schema
            self.next_schema += 1
            text, _ = bagio.standard_definition(msgtype)
            self.writer.add_schema(mcap.Schema(sid, msgtype, "ros2msg", text.encode("utf-8")))
        cid = self.out_channels[topic] = self.next_channel
        self.next_channel += 1
        if self.qos_text is None:
            self.qos_dicts = dump_qos_v9(self.qos_out)
            self.qos_text = mcap.dump_yaml(self.qos_dicts).strip()
        channel = mcap.Channel(cid, sid, topic, "cdr", mcap.metadata_map(
            {"offered_qos_profiles": self.qos_text}))
        self.writer.add_channel(channel)
        self.meta.append((channel, msgtype, self.qos_dicts,
                          bagio.standard_definition(msgtype)[1]))
        return cid

    # ---------------------------------------------------------------- copies

    def _copy(self, k: int, raw: bytes, records: bytes, arrays: mcap.Arrays) -> None:
        t0 = time.perf_counter()
        channel, log_time, start, size = arrays
        chunk = self.mcap.chunks[k]
        counts = np.bincount(channel, minlength=1)
        for c in np.flatnonzero(counts).tolist():
            self.seen[c] = self.seen.get(c, 0) + int(counts[c])
        if not self.skip or not np.isin(channel, list(self.skip)).any():
            self.writer.copy_chunk(chunk, raw, {c: int(counts[c]) for c in
                                                np.flatnonzero(counts).tolist()})
            self.result.messages_out += int(channel.size)
        else:  # messages on an output topic are not copied: the others one by one
            for c, t, s, n in zip(channel.tolist(), log_time.tolist(), start.tolist(),
                                  size.tolist()):
                if c not in self.skip and c in self.writer.channels:
                    self.writer.write(c, t, records[s:s + n])
                    self.result.messages_out += 1
        self.phases["copy"] += time.perf_counter() - t0

    # ---------------------------------------------------------------- the replay

    def run(self, out: Any, progress: Callable[[int], None] | None) -> tuple[int, int]:
        """Replay every message; return the first and last log times (ns).

        ``out``: where each wrench's CSV row and plot sample go (``rows``, a
        csv writer or None; ``series``, per contact, or None; ``method``,
        ``law``, ``mu`` (the static coefficient in force); ``first`` is set;
        ``outcome(outcome, log_ns)`` records one, and its friction estimate).
        """
        first: int | None = None
        last = 0
        next_diag = 0
        base = 0
        self.out = out
        diagnostics = resolve(DIAGNOSTICS_TOPIC, self.namespace)
        t_read = time.perf_counter()
        try:
            for w in mcap.windows(self.mcap, self._copy, WINDOW):
                self.phases["read"] += time.perf_counter() - t_read
                log = w.log_time
                n = len(w)
                if first is None:
                    first = out.first = int(log[0])
                    next_diag = first + 1_000_000_000
                # the batch: the window's rules at once, its outputs (and diagnostics) at once
                p = self.batch.run(w, 0, n, base) if self.batch is not None else None
                diags: list[tuple[int, int, bytes]] = []
                lo = 0
                while lo < n:
                    j = lo + int(np.searchsorted(log[lo:], next_diag, "left"))
                    if j > lo and p is None:
                        self._messages(w, lo, j, base)
                    if j < n:
                        stamp = int(log[j])
                        if p is None:
                            self._diagnostics(diagnostics, stamp, base + j)
                        else:
                            diags.append((j, stamp, self._diagnostics_cdr(stamp, base + j)))
                        next_diag += ((stamp - next_diag) // 1_000_000_000 + 1) * 1_000_000_000
                    lo = j
                if p is not None:
                    self._outputs(w, p, diags, diagnostics)
                base += n
                last = int(log[-1])
                self.result.messages_in += n
                if base == n:   # the first window replayed, its outputs half written
                    faults.pause("replay")
                if progress is not None:
                    progress(n)
                t_read = time.perf_counter()
        except McapError as e:
            raise BadInput(f"{self.source}: unreadable: {e}") from None
        if first is None:
            raise BadInput(f"{self.source}: empty bag (no messages)")
        t0 = time.perf_counter()
        if self.batch is not None:
            self.batch.store()
        self.writer.write(self.channel(diagnostics), last, self.pipeline.diagnostics_cdr(last))
        self.result.messages_out += 1
        self.phases["diagnostics"] += time.perf_counter() - t0
        return first, last

    def close(self) -> None:
        """Finish the output bag: the MCAP summary, then ``metadata.yaml``."""
        t0 = time.perf_counter()
        w = self.writer
        info = mcap.bag_metadata(w.path.name, self.meta, w.counts, w.start, w.end,
                                 self.custom_data)
        inner = mcap.dump_yaml(info["rosbag2_bagfile_information"])
        w.close(inner.strip())
        path = self.out_dir / "metadata.yaml"
        tmp = path.with_suffix(".yaml.tmp")
        tmp.write_text("rosbag2_bagfile_information:\n"
                       + "".join("  " + line + "\n" for line in inner.splitlines()),
                       encoding="utf-8")
        tmp.replace(path)
        self.phases["write"] += time.perf_counter() - t0

    def abort(self) -> None:
        """Close the output file as it is (the caller removes the staging directory)."""
        self.writer.abort()

    # ---------------------------------------------------------------- messages

    def _diagnostics(self, topic: str, stamp: int, place: int) -> None:
        """Write the diagnostics array at ``stamp``: counts of the messages before ``place``."""
        t0 = time.perf_counter()
        data = self.pipeline.diagnostics_cdr(stamp)
        self.writer.write(self.channel(topic), stamp, data)
        self.result.messages_out += 1
        self.phases["diagnostics"] += time.perf_counter() - t0

    def _diagnostics_cdr(self, stamp: int, place: int) -> bytes:
        """Return the diagnostics array at ``stamp``: counts of the messages before ``place``.

        The window's rules have run (:meth:`batch.Batch.run`); the counts
        are those of its messages before ``place`` (:meth:`batch.Batch.store`).
        """
        assert self.batch is not None
        t0 = time.perf_counter()
        self.batch.store(place)
        data = self.pipeline.diagnostics_cdr(stamp)
        self.batch.reported()
        self.phases["diagnostics"] += time.perf_counter() - t0
        return data

    def _messages(self, w: mcap.Window, lo: int, hi: int, base: int) -> None:
        for i in range(lo, hi):  # the pipeline's own handlers, one message at a time
            handler = self.handlers.get(int(w.channel[i]))
            if handler is None:
                continue
            log_ns = int(w.log_time[i])
            for outcome in handler.take(w.data(i)):
                self._emit(outcome, log_ns)

    def _emit(self, outcome: Outcome, log_ns: int) -> None:
        for rel, m in self.pipeline.messages(outcome):
            data = bytes(m) if isinstance(m, (bytearray, memoryview)) else \
                m if isinstance(m, bytes) else serialize_message(m)
            self.writer.write(self.channel(resolve(rel, self.namespace)), log_ns, data)
            self.result.messages_out += 1
        self.out.outcome(outcome, log_ns)

    def _outputs(self, w: mcap.Window, p: batch.Patches, diags: list[tuple[int, int, bytes]],
                 diagnostics: str) -> None:
        """Encode and write a window's outputs and its diagnostics arrays, in the replay's order.

        ``p``: the window's patches; ``diags``: ``(message, stamp, CDR)`` of
        each diagnostics array, which comes before the outputs of that
        message's patch (the per-message replay writes each when the first
        message of its second arrives).  The output channels are declared in
        the order the per-message replay first uses them.
        """
        t0 = time.perf_counter()
        solved = p.status == 0
        wrench = solved | (p.status == 1)
        log = w.log_time[p.index]
        # each diagnostics array before the patch rows from its message on
        at = np.searchsorted(p.index, np.array([j for j, _, _ in diags], dtype=np.int64), "left")
        markers = resolve(MARKERS_TOPIC, self.namespace)
        kinds: list[tuple[int, Ints, Any, str]] = []   # (kind, rows, encode(rows), topic)
        for k, c in enumerate(self.config.contacts):
            mine = p.contact == k
            force_enc, creep_enc, pose_enc, marker_enc = self.encoders[c]
            base_topic = resolve(f"contact/{c}/", self.namespace)
            kinds.append((_WRENCH, np.flatnonzero(mine & wrench),
                          lambda rows, e=force_enc: e.encode(p.stamp[rows], _wrenches(p, rows)),
                          base_topic + "wrench"))
            kinds.append((_CREEPAGE, np.flatnonzero(mine & solved),
                          lambda rows, e=creep_enc: e.encode(p.stamp[rows], p.creep[rows, :3]),
                          base_topic + "creepage"))
            kinds.append((_FRAME, np.flatnonzero(mine & solved & p.changed),
                          lambda rows, e=pose_enc: e.encode(p.stamp[rows], np.concatenate(
                              (p.frame[rows, :3], encode.quaternions(p.frame[rows])), axis=1)),
                          base_topic + "frame"))
            kinds.append((_MARKER, np.flatnonzero(mine & solved & p.marker),
                          lambda rows, e=marker_enc: e.arrows(p.stamp[rows], p.frame[rows],
                                                              p.force[rows, 0],
                                                              p.force[rows, 1]), markers))
            kinds.append((_MARKER, np.flatnonzero(mine & ~solved & wrench & p.marker),
                          lambda rows, e=marker_enc: e.deletions(p.stamp[rows]), markers))
        kinds.append((_WHEELSET, np.flatnonzero(p.cycle),
                      lambda rows: self.wheelset_encoder.encode(p.cycle_stamp[rows],
                                                                p.cycle_wrench[rows]),
                      resolve(WHEELSET_WRENCH_TOPIC, self.namespace)))
        self._declare([(rows, topic) for _, rows, _, topic in kinds], at, diagnostics)
        parts: list[tuple[Ints, Ints, NDArray[np.uint8], int]] = []  # keys, log times, rows, ch
        for kind, rows, make, topic in kinds:
            if rows.size:
                parts.append((rows * 8 + kind, log[rows], make(rows), self.channel(topic)))
        for r, (_, stamp, data) in zip(at.tolist(), diags):
            parts.append((np.array([r * 8 + _DIAG]), np.array([stamp]),
                          np.frombuffer(data, dtype=np.uint8)[None], self.channel(diagnostics)))
        t1 = time.perf_counter()
        self.phases["encode"] += t1 - t0
        if parts:
            self._write(parts)
        self.phases["write"] += time.perf_counter() - t1
        if self.out.rows is not None or self.out.series is not None:
            t2 = time.perf_counter()
            self._records(p, wrench, log)
            self.phases["csv"] += time.perf_counter() - t2

    def _declare(self, topics: list[tuple[Ints, str]], at: Ints, diagnostics: str) -> None:
        """Declare the output channels a window uses first, in the per-message replay's order.

        ``topics``: the rows of each kind of output in the order the replay
        takes them for one patch run; ``at``: the row each diagnostics array
        comes before.  A run between two diagnostics declares its topics in
        that order, then the diagnostics' (the replay runs its patches from
        one diagnostics to the next).
        """
        first: list[tuple[int, int, str]] = []   # (run, order, topic)
        for order, (rows, topic) in enumerate(topics):
            if rows.size and topic not in self.out_channels:
                run = int(np.searchsorted(at, rows[0], "right"))
                first.append((2 * run, order, topic))
        if at.size and diagnostics not in self.out_channels:
            first.append((1, 0, diagnostics))
        for _, _, topic in sorted(first):
            self.channel(topic)

    def _records(self, p: batch.Patches, wrench: NDArray[np.bool_], log: Ints) -> None:
        """Add the CSV row and plot sample of each wrench, in order (records.record's).

        The batch runs without friction estimation (its inputs do not include
        the measured wrench: :func:`batch.supported`), so ``out.mu``, the
        given coefficient, is every wrench's.
        """
        out = self.out
        idx = np.flatnonzero(wrench)
        if idx.size == 0:
            return
        contacts = self.config.contacts
        solved = (p.status[idx] == 0).tolist()
        stamp = p.stamp[idx].tolist()
        name = [contacts[c] for c in p.contact[idx].tolist()]
        cr = p.creep[idx].tolist()
        f = p.force[idx].tolist()
        slip = p.slip[idx].tolist()
        method, law, mu = out.method, out.law, out.mu
        if out.rows is not None:
            out.rows.writerows(
                (s, c, q[0], q[1], q[2], q[3], g[2], g[0], g[1], g[3], sl, method, law) if ok
                else (s, c, "", "", "", "", 0.0, 0.0, 0.0, 0.0, "", method, law)
                for ok, s, c, q, g, sl in zip(solved, stamp, name, cr, f, slip))
        if out.series is not None:
            t = ((log[idx] - out.first) * 1e-9).tolist()
            nan = float("nan")
            for ok, c, tt, q, g in zip(solved, name, t, cr, f):
                if ok:
                    out.series[c].add(tt, q[0], q[1], q[2], g[0], g[1], g[2], mu)
                else:
                    out.series[c].add(tt, nan, nan, nan, 0.0, 0.0, 0.0, mu)

    def _write(self, parts: list[Any]) -> None:
        """Write message records of ``(keys, log times, payloads (k, L), channel)`` by key."""
        keys = np.concatenate([k for k, _, _, _ in parts])
        order = np.argsort(keys, kind="stable")
        sizes = np.concatenate([np.full(r.shape[0], r.shape[1] + 31, dtype=np.int64)
                                for _, _, r, _ in parts])
        offsets = np.zeros(keys.size, dtype=np.int64)
        offsets[order] = np.concatenate(([0], np.cumsum(sizes[order])[:-1]))
        out = np.empty(int(sizes.sum()), dtype=np.uint8)
        channels = np.empty(keys.size, dtype=np.int64)
        times = np.empty(keys.size, dtype=np.int64)
        at = 0
        for _, log, payloads, cid in parts:
            k = log.size
            kernels.message_records(out, offsets[at:at + k], cid, log, payloads)
            channels[at:at + k] = cid
            times[at:at + k] = log
            at += k
        self.writer.write_records(out, channels[order], times[order], offsets[order])
        self.result.messages_out += int(keys.size)


def _wrenches(p: batch.Patches, rows: Ints) -> NDArray[np.float64]:
    """Return the wrench ``Fx, Fy, N, 0, 0, Mz`` of each row (zero where not solved)."""
    values = np.zeros((rows.size, 6))
    values[:, 0] = p.force[rows, 0]
    values[:, 1] = p.force[rows, 1]
    values[:, 2] = p.force[rows, 2]
    values[:, 5] = p.force[rows, 3]
    values[p.status[rows] != 0] = 0.0
    return values
