"""MCAP (rosbag2's storage) read and written by the chunk, not by the message.

The format is the official ``mcap`` library's (https://mcap.dev/spec): the
summary comes from :mod:`mcap.reader`, the chunk records are parsed by
:mod:`mcap.records` (and, but for zstd, decompressed by
:mod:`mcap.stream_reader`), and every record written (header, schemas,
channels, chunks, message indexes, chunk indexes, metadata, statistics,
summary offsets, footer) is a :mod:`mcap.records` record.  What the library
does one message at a time is done here in bulk: the message records of a
decompressed chunk are found with one compiled pass
(:mod:`~fastsim_ros.replay.kernels`), and the records and message indexes
of the node's outputs are built from arrays.  zstd chunks are decompressed
with one context per thread, kept (the library makes one per chunk: about
a third slower on the bundled bags' 1 MiB chunks).

The replay reads an input's chunks, decompresses each once and yields its
messages in the order ``rosbags`` gives them (log time; ties by the chunk's
place in the file, then by place in the chunk) in windows of bounded size.
It writes an output whose copied inputs are the input's own chunks, byte
for byte (no second compression), beside chunks of the new messages.

Only what rosbag2 and rosbags write is needed: an indexed file (a summary
with schemas, channels and chunk indexes) with every message in a chunk.
:func:`open_indexed` returns ``None`` for anything else, and the caller
reads it with ``rosbags`` instead.
"""

from __future__ import annotations

import io
import os
import struct
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO
from zlib import crc32

import numpy as np
import zstandard
import yaml
from mcap import records as rec
from mcap.data_stream import ReadDataStream, RecordBuilder
from mcap.exceptions import McapError as LibraryError
from mcap.opcode import Opcode
from mcap.reader import SeekingReader
from mcap.stream_reader import CRCValidationError, get_chunk_data_stream
from mcap.writer import MCAP0_MAGIC
from numpy.typing import NDArray

from fastsim_ros.replay import kernels
from fastsim_ros.replay.errors import McapError

MAGIC = MCAP0_MAGIC
#: uncompressed bytes of new messages after which a chunk is written (rosbags: 1 MiB)
CHUNK_BYTES = 1 << 20
#: a message record's fixed part: opcode, record length, channel id, sequence, log and publish
#: times (MCAP's Message record, the layout of :func:`message_records`)
_MESSAGE_HEAD = struct.Struct("<BQHIQQ")
#: bytes of the footer record and the closing magic at the end of every MCAP file
_TAIL = 9 + 20 + 8
#: what a file's bytes or the library's parsers raise on a malformed file
_MALFORMED = (LibraryError, ValueError, struct.error, EOFError)


@dataclass(frozen=True)
class Schema:
    """A schema record: ``id``, type ``name``, ``encoding`` (``ros2msg``), definition."""

    id: int
    name: str
    encoding: str
    data: bytes

    def record(self) -> rec.Schema:
        """Return it as the library's record."""
        return rec.Schema(id=self.id, name=self.name, encoding=self.encoding, data=self.data)


@dataclass(frozen=True)
class Channel:
    """A channel record: ``id``, ``schema_id``, ``topic``, encoding, metadata."""

    id: int
    schema_id: int
    topic: str
    message_encoding: str
    metadata: dict[str, str]

    def record(self) -> rec.Channel:
        """Return it as the library's record."""
        return rec.Channel(id=self.id, schema_id=self.schema_id, topic=self.topic,
                           message_encoding=self.message_encoding,
                           metadata=dict(self.metadata))


@dataclass(frozen=True)
class ChunkIndex:
    """A chunk index record: where a chunk is, its times, sizes and message indexes."""

    start_time: int
    end_time: int
    offset: int
    length: int
    index_offsets: dict[int, int]
    index_length: int
    compression: str
    compressed_size: int
    uncompressed_size: int

    @staticmethod
    def of(r: rec.ChunkIndex) -> ChunkIndex:
        """Return the library's chunk index record in this form."""
        return ChunkIndex(int(r.message_start_time), int(r.message_end_time),
                          int(r.chunk_start_offset), int(r.chunk_length),
                          {int(c): int(o) for c, o in r.message_index_offsets.items()},
                          int(r.message_index_length), str(r.compression),
                          int(r.compressed_size), int(r.uncompressed_size))

    def record(self) -> rec.ChunkIndex:
        """Return it as the library's record."""
        return rec.ChunkIndex(
            message_start_time=self.start_time, message_end_time=self.end_time,
            chunk_start_offset=self.offset, chunk_length=self.length,
            message_index_offsets=dict(self.index_offsets),
            message_index_length=self.index_length, compression=self.compression,
            compressed_size=self.compressed_size, uncompressed_size=self.uncompressed_size)


def metadata_map(entries: dict[str, str]) -> dict[str, str]:
    """Return a channel's metadata (an MCAP ``map<string, string>``)."""
    return dict(entries)


# ------------------------------------------------------------------------ reading

_THREAD = threading.local()


def _zstd(data: bytes, size: int) -> bytes:
    """Decompress a zstd chunk of ``size`` bytes into one buffer of that size.

    One decompression context per thread (a Dask worker may run tasks in
    several), kept between chunks.
    """
    context = getattr(_THREAD, "zstd", None)
    if context is None:
        context = _THREAD.zstd = zstandard.ZstdDecompressor()
    out: bytes = context.decompress(data, max_output_size=size)
    return out


#: chunk compressions the library decompresses ("": none)
_COMPRESSIONS = ("", "zstd", "lz4")


def _chunk_records(chunk: rec.Chunk, offset: int) -> bytes:
    """Return the decompressed records of a chunk, its size and checksum checked."""
    if chunk.compression not in _COMPRESSIONS:
        raise McapError(f"chunk compression {chunk.compression!r} is not supported")
    try:
        if chunk.compression == "zstd":
            records = _zstd(chunk.data, chunk.uncompressed_size)
            if chunk.uncompressed_crc and crc32(records) != chunk.uncompressed_crc:
                raise CRCValidationError(chunk.uncompressed_crc, crc32(records), chunk)
        else:
            stream, size = get_chunk_data_stream(chunk, validate_crc=True)
            records = stream.read(size)   # the stream's own buffer (read whole: no copy)
    except CRCValidationError:
        raise McapError(f"chunk at byte {offset}: checksum mismatch") from None
    except Exception as e:  # the decompressors' own errors: a corrupt chunk
        raise McapError(f"a chunk does not decompress ({type(e).__name__}: {e})") from None
    if len(records) != chunk.uncompressed_size:
        raise McapError(f"chunk at byte {offset}: {len(records)} bytes "
                        f"decompressed, {chunk.uncompressed_size} expected")
    return records


@dataclass
class IndexedMcap:
    """One indexed MCAP file: its schemas, channels and chunk indexes (from the summary)."""

    path: Path
    schemas: dict[int, Schema]
    channels: dict[int, Channel]
    chunks: list[ChunkIndex]
    file: BinaryIO
    #: by channel id, whether the file defines it (:meth:`channel_table`)
    known: NDArray[np.bool_] | None = None
    #: wall time (s) spent decompressing chunks (:meth:`read_chunk`)
    decompress_s: float = 0.0

    def close(self) -> None:
        """Close the file."""
        self.file.close()

    def channel_table(self) -> NDArray[np.bool_]:
        """Return, by channel id, whether the file defines that channel (made once)."""
        if self.known is None:
            self.known = np.zeros(max(self.channels, default=-1) + 1, dtype=np.bool_)
            self.known[np.fromiter(self.channels, dtype=np.int64,
                                   count=len(self.channels))] = True
        return self.known

    def read_chunk(self, chunk: ChunkIndex) -> tuple[bytes, bytes]:
        """Return ``(raw, records)``: the chunk's bytes in the file and its records.

        ``raw``: the chunk record and its message indexes (to copy as they
        are); ``records``: the decompressed records.
        """
        f = self.file
        f.seek(chunk.offset)
        raw = f.read(chunk.length + chunk.index_length)
        if len(raw) != chunk.length + chunk.index_length or raw[0] != Opcode.CHUNK:
            raise McapError(f"no chunk at byte {chunk.offset}")
        size = int.from_bytes(raw[1:9], "little")
        if 9 + size != chunk.length:
            raise McapError(f"the chunk at byte {chunk.offset} is not as long as its index says")
        stream = ReadDataStream(io.BytesIO(raw))
        stream.read(9)
        try:
            record = rec.Chunk.read(stream)
        except _MALFORMED:
            record = None
        if record is None or stream.count > chunk.length:
            raise McapError(f"the chunk at byte {chunk.offset} ends inside a field")
        t0 = time.perf_counter()
        records = _chunk_records(record, chunk.offset)
        self.decompress_s += time.perf_counter() - t0
        return raw, records


def open_indexed(path: Path) -> IndexedMcap | None:
    """Open an MCAP file through its summary; ``None`` without one (read it another way).

    Raises :class:`McapError` for a file that is not MCAP or whose summary
    is malformed.
    """
    f = open(path, "rb")
    try:
        size = os.fstat(f.fileno()).st_size
        if f.read(8) != MAGIC:
            raise McapError("not an MCAP file (magic)")
        if size < 8 + 9 + _TAIL:
            raise McapError("too short for an MCAP file")
        f.seek(size - 8)
        if f.read(8) != MAGIC:
            raise McapError("no MCAP footer")
        f.seek(0)
        try:
            summary = SeekingReader(f, record_size_limit=size).get_summary()
        except _MALFORMED as e:
            raise McapError(f"malformed summary ({type(e).__name__}: {e})") from None
        if summary is None:
            f.close()
            return None
        schemas = {int(s.id): Schema(int(s.id), str(s.name), str(s.encoding), bytes(s.data))
                   for s in summary.schemas.values()}
        channels = {int(c.id): Channel(int(c.id), int(c.schema_id), str(c.topic),
                                       str(c.message_encoding), dict(c.metadata))
                    for c in summary.channels.values()}
        chunks = [ChunkIndex.of(c) for c in summary.chunk_indexes]
        for c in chunks:
            if not 8 <= c.offset or c.offset + c.length + c.index_length > size - _TAIL:
                raise McapError(f"a chunk index points outside the data (byte {c.offset})")
        if not chunks and not channels:
            f.close()
            return None
        return IndexedMcap(Path(path), schemas, channels, chunks, f)
    except BaseException:
        f.close()
        raise


@dataclass
class Window:
    """Messages of loaded chunks, in the order rosbags reads them (log time, file, record).

    ``buffers[k]``: decompressed records of chunk ``k`` of this window;
    per message ``channel``, ``log_time`` (ns), ``buffer`` (``k``),
    ``start`` and ``size`` of its data in that buffer.
    """

    buffers: list[bytes]
    channel: NDArray[np.int64]
    log_time: NDArray[np.int64]
    buffer: NDArray[np.int64]
    start: NDArray[np.int64]
    size: NDArray[np.int64]

    def __len__(self) -> int:
        return int(self.channel.size)

    @property
    def arrays(self) -> Any:
        """Return the buffers as uint8 arrays in a numba list (for the compiled loops)."""
        cached = getattr(self, "_arrays", None)
        if cached is None:
            from numba.typed import List
            cached = List([np.frombuffer(b, dtype=np.uint8) for b in self.buffers])
            self._arrays = cached
        return cached

    def data(self, i: int) -> memoryview:
        """Return the serialized bytes of message ``i`` (a view of its chunk's records)."""
        s = int(self.start[i])
        return memoryview(self.buffers[int(self.buffer[i])])[s:s + int(self.size[i])]


@dataclass
class _Loaded:
    order: int                  # the chunk's place in the file
    records: bytes
    channel: NDArray[np.int64]
    log_time: NDArray[np.int64]
    start: NDArray[np.int64]
    size: NDArray[np.int64]
    taken: int = 0              # messages already given out (a prefix, in log-time order)


Arrays = tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]


def scan_records(records: bytes) -> Arrays:
    """Return ``channel, log_time, start, size`` of the message records of a chunk.

    Stably sorted by log time (as rosbags sorts a chunk).  Raises
    :class:`McapError` when a record overruns the chunk.
    """
    buf = np.frombuffer(records, dtype=np.uint8)
    status, count = kernels.count_messages(buf)
    if status:
        raise McapError("a record overruns its chunk")
    channel = np.empty(count, dtype=np.int64)
    log_time = np.empty(count, dtype=np.int64)
    start = np.empty(count, dtype=np.int64)
    size = np.empty(count, dtype=np.int64)
    kernels.fill_messages(buf, channel, log_time, start, size)
    if count and np.any(log_time[1:] < log_time[:-1]):
        order = np.argsort(log_time, kind="stable")
        channel, log_time, start, size = channel[order], log_time[order], start[order], \
            size[order]
    return channel, log_time, start, size


def _check_chunk(mcap: IndexedMcap, chunk: ChunkIndex, arrays: Arrays) -> None:
    """Refuse a chunk whose messages name no channel of the file or lie outside its times.

    A file without chunk CRCs (rosbags writes none) decodes a corruption inside
    a chunk's compressed data as other bytes: a record on channel 74 of a file
    with six ended the replay with an internal error (exit 1), a log time
    moved out of the chunk's range was replayed as an old stamp.  Both are
    the file's fault: a bad input.
    """
    channel, log_time = arrays[0], arrays[1]
    if not channel.size:
        return
    known = mcap.channel_table()
    unknown = (channel < 0) | (channel >= known.size)
    unknown[~unknown] = ~known[channel[~unknown]]
    if unknown.any():
        bad = int(channel[unknown][0])
        raise McapError(f"chunk at byte {chunk.offset}: a message on channel {bad}, which "
                        f"the file does not define (a corrupt chunk)")
    if int(log_time.min()) < chunk.start_time or int(log_time.max()) > chunk.end_time:
        raise McapError(f"chunk at byte {chunk.offset}: a message logged outside the "
                        f"chunk's time range (a corrupt chunk)")


def windows(mcap: IndexedMcap, on_chunk: Any, max_messages: int = 8192,
            max_bytes: int = 32 << 20) -> Iterator[Window]:
    """Yield every message in log-time order, in windows of at most ``max_messages``.

    Chunks are read in order of their first log time, until the window holds
    ``max_messages`` messages or ``max_bytes`` of decompressed chunks (or a
    chunk must be read because the next message could come from it), and let
    go once their messages are given out: memory is bounded by those limits
    and the chunks that overlap in time, not by the file.
    ``on_chunk(index, raw, records, arrays)`` is called once per chunk as it
    is read (the writer copies it; ``arrays``: :func:`scan_records`'s).
    Ties in log time go to the chunk earlier in the file, then to the earlier
    record, as ``rosbags`` orders them.
    """
    order = sorted(range(len(mcap.chunks)),
                   key=lambda k: (mcap.chunks[k].start_time, mcap.chunks[k].offset))
    loaded: list[_Loaded] = []
    nxt = 0
    pending = held = 0     # messages not given out, bytes of records, of the loaded chunks
    while True:
        horizon = mcap.chunks[order[nxt]].start_time if nxt < len(order) else None
        if horizon is not None and (not loaded or (pending < max_messages and held < max_bytes)
                                    or _pending_min(loaded) >= horizon):
            k = order[nxt]
            nxt += 1
            raw, records = mcap.read_chunk(mcap.chunks[k])
            arrays = scan_records(records)
            _check_chunk(mcap, mcap.chunks[k], arrays)
            on_chunk(k, raw, records, arrays)
            if arrays[0].size:   # (a chunk of no messages gives nothing out)
                loaded.append(_Loaded(mcap.chunks[k].offset, records, *arrays))
                loaded.sort(key=lambda c: c.order)
                pending += arrays[0].size
                held += len(records)
            continue
        if not loaded:
            return
        # give out what precedes the next chunk's first message (strictly: a tie may
        # belong to that chunk, if it comes earlier in the file), at most max_messages
        counts = [c.log_time.size - c.taken if horizon is None else
                  int(np.searchsorted(c.log_time[c.taken:], horizon, "left")) for c in loaded]
        times = np.concatenate([c.log_time[c.taken:c.taken + n] for c, n in zip(loaded, counts)])
        which = np.concatenate([np.full(n, b, dtype=np.int64) for b, n in enumerate(counts)])
        place = np.concatenate([np.arange(c.taken, c.taken + n, dtype=np.int64)
                                for c, n in zip(loaded, counts)])
        if len(loaded) > 1 and times.size > 1 and np.any(np.diff(times) < 0):
            merged = np.lexsort((place, which, times))[:max_messages]
        else:  # one chunk, or chunks one after the other in time: already in order
            merged = np.arange(min(times.size, max_messages))
        which, place = which[merged], place[merged]
        for b, c in enumerate(loaded):  # each chunk gives out a prefix of its messages
            c.taken += int(np.count_nonzero(which == b))
        flat = _flat(loaded, which, place)
        yield Window([c.records for c in loaded],
                     np.concatenate([c.channel for c in loaded])[flat], times[merged], which,
                     np.concatenate([c.start for c in loaded])[flat],
                     np.concatenate([c.size for c in loaded])[flat])
        loaded = [c for c in loaded if c.taken < c.log_time.size]
        pending = sum(c.log_time.size - c.taken for c in loaded)
        held = sum(len(c.records) for c in loaded)


def _pending_min(loaded: list[_Loaded]) -> int:
    return min(int(c.log_time[c.taken]) for c in loaded)


def _flat(loaded: list[_Loaded], which: NDArray[np.int64],
          place: NDArray[np.int64]) -> NDArray[np.int64]:
    base = np.cumsum([0] + [c.log_time.size for c in loaded])[:-1]
    return np.asarray(base, dtype=np.int64)[which] + place


# ------------------------------------------------------------------------ writing

class _MessageIndex(rec.MessageIndex):
    """A message index record whose ``(log time, offset)`` entries are one array."""

    def __init__(self, channel_id: int, entries: NDArray[Any]) -> None:
        super().__init__(channel_id=channel_id, records=[])
        self.entries = entries       # (k, 2) little-endian u64

    def write(self, stream: RecordBuilder) -> None:
        """Write the record, its entries in one piece (the library's: one by one)."""
        stream.start_record(Opcode.MESSAGE_INDEX)
        stream.write2(self.channel_id)
        stream.write4(self.entries.nbytes)
        stream.write(self.entries.tobytes())
        stream.finish_record()


@dataclass
class _Pending:
    """New message records not yet in a chunk."""

    parts: list[bytes | memoryview] = field(default_factory=list)
    size: int = 0
    start: int = (1 << 63) - 1
    end: int = 0
    # per channel: (log time, offset in the chunk) arrays, or lists of single messages' (the
    # per-message path: a run of them appended to the channel's last lists, in file order)
    index: dict[int, list[tuple[NDArray[np.int64] | list[int],
                                NDArray[np.int64] | list[int]]]] = field(default_factory=dict)


class McapWriter:
    """Write an MCAP file: copied chunks as they are, new messages in zstd chunks.

    ``add_schema`` and ``add_channel`` before the messages that use them;
    :meth:`copy_chunk` (a chunk of an input, with its message indexes,
    byte for byte), :meth:`write` (one message) and :meth:`write_records`
    (message records built in bulk); :meth:`close` writes the summary
    (schemas, channels, chunk indexes, statistics, the rosbag2 metadata)
    and the footer.  Every record is the ``mcap`` library's.
    """

    def __init__(self, path: Path, *, library: str = "fastsim_replay") -> None:
        self.path = path
        self.file: BinaryIO = open(path, "xb")
        self._builder = RecordBuilder()
        self.file.write(MAGIC)
        self._put(rec.Header(profile="ros2", library=library))
        self.schemas: dict[int, Schema] = {}
        self.channels: dict[int, Channel] = {}
        self.chunks: list[ChunkIndex] = []
        self.counts: dict[int, int] = {}
        self.start = (1 << 63) - 1
        self.end = 0
        self._pending = _Pending()

    def _put(self, record: rec.McapRecord) -> int:
        """Write one record at the end of the file; return its length (bytes)."""
        record.write(self._builder)
        data = self._builder.end()
        self.file.write(data)
        return len(data)

    def add_schema(self, schema: Schema) -> None:
        """Declare a schema (its id unique in the file)."""
        self.schemas[schema.id] = schema
        self._put(schema.record())

    def add_channel(self, channel: Channel) -> None:
        """Declare a channel (its id unique in the file, its schema declared)."""
        self.channels[channel.id] = channel
        self.counts.setdefault(channel.id, 0)
        self._put(channel.record())

    def copy_chunk(self, chunk: ChunkIndex, raw: bytes, counts: dict[int, int]) -> None:
        """Copy an input's chunk record and its message indexes (``raw``) as they are.

        ``counts``: messages per channel in the chunk (its channels are declared).
        """
        self._flush_if(CHUNK_BYTES)
        offset = self.file.tell()
        self.file.write(raw)
        shift = offset - chunk.offset
        self.chunks.append(ChunkIndex(
            chunk.start_time, chunk.end_time, offset, chunk.length,
            {c: o + shift for c, o in chunk.index_offsets.items()}, chunk.index_length,
            chunk.compression, chunk.compressed_size, chunk.uncompressed_size))
        for c, n in counts.items():
            self.counts[c] += n
        if any(counts.values()):
            self.start = min(self.start, chunk.start_time)
            self.end = max(self.end, chunk.end_time)

    def write(self, channel: int, log_time: int, data: bytes | bytearray | memoryview) -> None:
        """Add one message (log time ns) to the pending chunk.

        The record :func:`message_records` builds for one (the bytes
        :class:`mcap.records.Message` writes), without the arrays of the bulk
        path: the per-message replay writes every output this way, and the
        arrays cost it some 10 us a message.
        """
        raw = bytes(data)
        p = self._pending
        offset = p.size
        p.parts.append(_MESSAGE_HEAD.pack(Opcode.MESSAGE, 22 + len(raw), channel, 0, log_time,
                                          log_time))
        p.parts.append(raw)
        p.size += 31 + len(raw)
        if log_time < p.start:
            p.start = log_time
        if log_time > p.end:
            p.end = log_time
        pieces = p.index.setdefault(channel, [])
        if pieces and isinstance(pieces[-1][0], list):
            pieces[-1][0].append(log_time)  # type: ignore[union-attr]
            pieces[-1][1].append(offset)  # type: ignore[union-attr]
        else:
            pieces.append(([log_time], [offset]))
        self.counts[channel] += 1
        self.start = min(self.start, p.start)
        self.end = max(self.end, p.end)
        self._flush_if(CHUNK_BYTES)

    def write_records(self, records: bytes | NDArray[np.uint8], channel: NDArray[np.int64],
                      log_time: NDArray[np.int64], offset: NDArray[np.int64]) -> None:
        """Add message records built in bulk.

        ``records``: their bytes (or a uint8 array of them, kept as it is
        until the chunk is written); per record its ``channel``,
        ``log_time`` (ns) and ``offset`` in ``records``.
        """
        if not channel.size:
            return
        p = self._pending
        base = p.size
        p.parts.append(records if isinstance(records, bytes) else records.data)
        p.size += len(records)
        p.start = min(p.start, int(log_time.min()))
        p.end = max(p.end, int(log_time.max()))
        for c in np.unique(channel).tolist():
            mine = channel == c
            p.index.setdefault(c, []).append((log_time[mine], offset[mine] + base))
            self.counts[c] += int(np.count_nonzero(mine))
        self.start = min(self.start, p.start)
        self.end = max(self.end, p.end)
        self._flush_if(CHUNK_BYTES)

    def _flush_if(self, limit: int) -> None:
        p = self._pending
        if p.size == 0 or (p.size < limit and limit > 0):
            return
        records = b"".join(p.parts)
        compressed = zstandard.compress(records)
        offset = self.file.tell()
        length = self._put(rec.Chunk(
            compression="zstd", data=compressed, message_start_time=p.start,
            message_end_time=p.end, uncompressed_crc=crc32(records),
            uncompressed_size=len(records)))
        index_offsets = {}
        for c, pieces in sorted(p.index.items()):
            entries = np.empty((sum(len(t) for t, _ in pieces), 2), dtype="<u8")
            entries[:, 0] = np.concatenate([np.asarray(t, dtype=np.int64) for t, _ in pieces])
            entries[:, 1] = np.concatenate([np.asarray(o, dtype=np.int64) for _, o in pieces])
            index_offsets[c] = self.file.tell()
            self._put(_MessageIndex(c, entries))
        self.chunks.append(ChunkIndex(p.start, p.end, offset, length, index_offsets,
                                      self.file.tell() - offset - length, "zstd",
                                      len(compressed), len(records)))
        self._pending = _Pending()

    def close(self, rosbag2_metadata: str) -> None:
        """Write the last chunk, the summary and the footer; close the file.

        ``rosbag2_metadata``: the YAML of ``rosbag2_bagfile_information``
        (rosbag2 keeps it in a metadata record named ``rosbag2``).
        """
        self._flush_if(0)
        f = self.file
        metadata_start = f.tell()
        metadata_length = self._put(rec.Metadata(
            name="rosbag2", metadata={"serialized_metadata": rosbag2_metadata}))
        self._put(rec.DataEnd(data_section_crc=0))
        summary_start = f.tell()
        total = sum(self.counts.values())
        groups: list[tuple[int, list[rec.McapRecord]]] = [
            (Opcode.SCHEMA, [s.record() for s in self.schemas.values()]),
            (Opcode.CHANNEL, [c.record() for c in self.channels.values()]),
            (Opcode.CHUNK_INDEX, [c.record() for c in self.chunks]),
            (Opcode.METADATA_INDEX, [rec.MetadataIndex(
                offset=metadata_start, length=metadata_length, name="rosbag2")]),
            (Opcode.STATISTICS, [rec.Statistics(
                message_count=total, schema_count=len(self.schemas),
                channel_count=len(self.channels), attachment_count=0, metadata_count=1,
                chunk_count=len(self.chunks),
                message_start_time=self.start if total else 0,
                message_end_time=self.end if total else 0,
                channel_message_counts=dict(sorted(self.counts.items())))]),
        ]
        summary = RecordBuilder()
        offsets: list[rec.McapRecord] = []
        for opcode, records in groups:
            group_start = summary.count
            for r in records:
                r.write(summary)
            if summary.count > group_start:
                offsets.append(rec.SummaryOffset(group_opcode=opcode,
                                                 group_start=summary_start + group_start,
                                                 group_length=summary.count - group_start))
        offsets_start = summary_start + summary.count
        for r in offsets:
            r.write(summary)
        data = summary.end()
        f.write(data)
        # the summary's checksum covers the footer's fields before it (as the library's)
        footer_crc = crc32(struct.pack("<BQQQ", Opcode.FOOTER, 20, summary_start,
                                       offsets_start), crc32(data))
        self._put(rec.Footer(summary_start=summary_start, summary_offset_start=offsets_start,
                             summary_crc=footer_crc))
        f.write(MAGIC)
        f.close()

    def abort(self) -> None:
        """Close the file as it is (the caller removes it)."""
        self.file.close()


def message_records(channel: NDArray[np.int64], log_time: NDArray[np.int64],
                    payloads: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Return message records of fixed-size payloads ``(k, L)`` as a ``(k, 31 + L)`` array.

    The bytes :class:`mcap.records.Message` writes (sequence 0, publish time
    = log time), built for all ``k`` at once.
    """
    k, size = payloads.shape
    out = np.empty((k, 31 + size), dtype=np.uint8)
    out[:, 0] = Opcode.MESSAGE
    out[:, 1:9] = np.full(k, 22 + size, dtype="<u8").view(np.uint8).reshape(k, 8)
    out[:, 9:11] = channel.astype("<u2").view(np.uint8).reshape(k, 2)
    out[:, 11:15] = 0
    stamps = log_time.astype("<u8").view(np.uint8).reshape(k, 8)
    out[:, 15:23] = stamps
    out[:, 23:31] = stamps
    out[:, 31:] = payloads
    return out


def bag_metadata(path_name: str, channels: list[tuple[Channel, str, list[Any], str]],
                 counts: dict[int, int], start: int, end: int,
                 custom_data: dict[str, str]) -> dict[str, Any]:
    """Return rosbag2's ``metadata.yaml`` (version 9) of an MCAP file, as rosbags writes it.

    ``channels``: ``(channel, message type, offered QoS dicts, type hash)``.
    """
    total = sum(counts.values())
    duration = max(0, end - start) if total else 0
    first = start if total else (1 << 63) - 1
    return {"rosbag2_bagfile_information": {
        "version": 9,
        "storage_identifier": "mcap",
        "relative_file_paths": [path_name],
        "duration": {"nanoseconds": duration},
        "starting_time": {"nanoseconds_since_epoch": first},
        "message_count": total,
        "topics_with_message_count": [
            {"topic_metadata": {"name": c.topic, "type": msgtype,
                                "serialization_format": c.message_encoding,
                                "offered_qos_profiles": qos,
                                "type_description_hash": digest},
             "message_count": counts.get(c.id, 0)}
            for c, msgtype, qos, digest in channels],
        "compression_format": "",
        "compression_mode": "",
        "files": [{"path": path_name, "starting_time": {"nanoseconds_since_epoch": first},
                   "duration": {"nanoseconds": duration}, "message_count": total}],
        "custom_data": custom_data or None,
        "ros_distro": "rosbags",
    }}


class _BlockDumper(yaml.CSafeDumper):
    """PyYAML's safe dumper on libyaml's emitter, writing every repeated node out.

    rosbag2's ``metadata.yaml`` has no anchors: the QoS profiles a writer
    shares between topics are printed in full at each topic.
    """

    def ignore_aliases(self, data: Any) -> bool:
        """Write a node shared by several parents in full at each (no ``&id``/``*id``)."""
        return True


def dump_yaml(data: Any) -> str:
    """Return ``data`` (dicts, lists, strings, integers, booleans, None) as block YAML.

    PyYAML's safe representer on libyaml's C emitter (about 0.2 ms for a
    bag's ``metadata.yaml``), keys in the dict's order, every nested
    collection in block style, no aliases: rosbag2's and rosbags' readers
    take it as they take rosbags' own ``metadata.yaml``.
    """
    return str(yaml.dump(data, Dumper=_BlockDumper, sort_keys=False,
                         default_flow_style=False, allow_unicode=True, width=1 << 30))
