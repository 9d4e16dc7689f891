"""MCAP (rosbag2's storage) read and written by the chunk, not by the message.

The replay reads an input's chunks, decompresses each once and finds its
message records with one compiled pass (:mod:`~fastsim_ros.replay.kernels`),
and yields them in the order ``rosbags`` gives them (log time; ties by the
chunk's place in the file, then by place in the chunk) in windows of bounded
size.  It writes an output whose copied inputs are the input's own chunks,
byte for byte (no second compression), beside chunks of the new messages,
which are built in bulk.  The MCAP format: https://mcap.dev/spec (records:
opcode u8, length u64, fields little-endian; strings and byte arrays with a
u32 length; maps with a u32 byte length).

Only what rosbag2 and rosbags write is needed: an indexed file (a summary
with schemas, channels and chunk indexes) with every message in a chunk.
:func:`open_indexed` returns ``None`` for anything else, and the caller
reads it with ``rosbags`` instead.
"""

from __future__ import annotations

import json
import os
import re
import struct
import sys
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO
from zlib import crc32

import numpy as np
import zstandard
from numpy.typing import NDArray

from fastsim_ros.replay import kernels

if sys.version_info >= (3, 14):
    from compression import zstd
else:  # the backport rosbags depends on
    from backports import zstd

MAGIC = b"\x89MCAP0\r\n"
OP_HEADER, OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK = 0x01, 0x02, 0x03, 0x04, \
    0x05, 0x06
OP_MESSAGE_INDEX, OP_CHUNK_INDEX, OP_STATISTICS, OP_METADATA = 0x07, 0x08, 0x0B, 0x0C
OP_METADATA_INDEX, OP_SUMMARY_OFFSET, OP_DATA_END = 0x0D, 0x0E, 0x0F
#: uncompressed bytes of new messages after which a chunk is written (rosbags: 1 MiB)
CHUNK_BYTES = 1 << 20

_U16, _U32, _U64 = struct.Struct("<H"), struct.Struct("<I"), struct.Struct("<Q")
_CHUNK_HEAD = struct.Struct("<QQQI")     # start, end, uncompressed size, crc


class McapError(Exception):
    """A file that does not follow the MCAP format where the replay reads it."""


@dataclass(frozen=True)
class Schema:
    """A schema record: ``id``, type ``name``, ``encoding`` (``ros2msg``), definition."""

    id: int
    name: str
    encoding: str
    data: bytes


@dataclass(frozen=True)
class Channel:
    """A channel record: ``id``, ``schema_id``, ``topic``, encoding, metadata (raw map)."""

    id: int
    schema_id: int
    topic: str
    message_encoding: str
    metadata: bytes


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


class _Fields:
    """A cursor over one record's fields."""

    __slots__ = ("data", "pos")

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.pos = 0

    def take(self, size: int) -> bytes:
        end = self.pos + size
        if end > len(self.data):
            raise McapError("a record ends inside a field")
        out = self.data[self.pos:end]
        self.pos = end
        return out

    def u16(self) -> int:
        return int(_U16.unpack(self.take(2))[0])

    def u32(self) -> int:
        return int(_U32.unpack(self.take(4))[0])

    def u64(self) -> int:
        return int(_U64.unpack(self.take(8))[0])

    def string(self) -> str:
        try:
            return self.take(self.u32()).decode("utf-8")
        except UnicodeDecodeError:
            raise McapError("a string that is not UTF-8") from None

    def sized(self) -> bytes:
        return self.take(self.u32())


def _read_record(f: BinaryIO) -> tuple[int, bytes]:
    head = f.read(9)
    if len(head) != 9:
        raise McapError("truncated record")
    op, size = head[0], int(_U64.unpack_from(head, 1)[0])
    data = f.read(size)
    if len(data) != size:
        raise McapError("truncated record")
    return op, data


# ------------------------------------------------------------------------ reading

@dataclass
class IndexedMcap:
    """One indexed MCAP file: its schemas, channels and chunk indexes (from the summary)."""

    path: Path
    schemas: dict[int, Schema]
    channels: dict[int, Channel]
    chunks: list[ChunkIndex]
    file: BinaryIO

    def close(self) -> None:
        """Close the file."""
        self.file.close()

    def read_chunk(self, chunk: ChunkIndex) -> tuple[bytes, bytes]:
        """Return ``(raw, records)``: the chunk's bytes in the file and its records.

        ``raw``: the chunk record and its message indexes (to copy as they
        are); ``records``: the decompressed records.
        """
        f = self.file
        f.seek(chunk.offset)
        raw = f.read(chunk.length + chunk.index_length)
        if len(raw) != chunk.length + chunk.index_length or raw[0] != OP_CHUNK:
            raise McapError(f"no chunk at byte {chunk.offset}")
        size = int(_U64.unpack_from(raw, 1)[0])
        if 9 + size != chunk.length:
            raise McapError(f"the chunk at byte {chunk.offset} is not as long as its index says")
        fields = _Fields(raw[9:9 + size])
        start, end, uncompressed, crc = _CHUNK_HEAD.unpack(fields.take(28))
        compression = fields.string()
        compressed = fields.take(fields.u64())
        records = _decompress(compressed, compression, uncompressed)
        if len(records) != uncompressed:
            raise McapError(f"chunk at byte {chunk.offset}: {len(records)} bytes "
                            f"decompressed, {uncompressed} expected")
        if crc and crc32(records) != crc:
            raise McapError(f"chunk at byte {chunk.offset}: checksum mismatch")
        return raw, records


_THREAD = threading.local()


def _zstd(data: bytes, size: int) -> bytes:
    """Decompress a zstd chunk of ``size`` bytes into one buffer of that size.

    (rosbags' decompressor grows its output block by block and joins the
    blocks: a second copy of every chunk.)  One decompression context per
    thread: a Dask worker may run tasks in several.
    """
    context = getattr(_THREAD, "zstd", None)
    if context is None:
        context = _THREAD.zstd = zstandard.ZstdDecompressor()
    out: bytes = context.decompress(data, max_output_size=size)
    return out


def _decompress(data: bytes, compression: str, size: int) -> bytes:
    from rosbags.rosbag2.storage_mcap import DECOMPRESSORS  # lz4, none: rosbags' own
    decompress = _zstd if compression == "zstd" else DECOMPRESSORS.get(compression)
    if decompress is None:
        raise McapError(f"chunk compression {compression!r} is not supported")
    try:
        out = decompress(data, size)
        return out if isinstance(out, bytes) else bytes(out)
    except Exception as e:  # the decompressors' own errors: a corrupt chunk
        raise McapError(f"a chunk does not decompress ({type(e).__name__}: {e})") from None


def open_indexed(path: Path) -> IndexedMcap | None:
    """Open an MCAP file through its summary; ``None`` without one (read it another way).

    Raises :class:`McapError` for a file that is not MCAP or whose summary
    is malformed.
    """
    f = open(path, "rb")
    try:
        if f.read(8) != MAGIC:
            raise McapError("not an MCAP file (magic)")
        size = os.fstat(f.fileno()).st_size
        if size < 8 + 9 + 29 + 8:
            raise McapError("too short for an MCAP file")
        f.seek(size - 37)
        footer = f.read(37)
        if footer[-8:] != MAGIC or footer[0] != OP_FOOTER:
            raise McapError("no MCAP footer")
        summary_start = int(_U64.unpack_from(footer, 9)[0])
        if summary_start == 0:
            f.close()
            return None
        if not 8 < summary_start < size - 37:
            raise McapError("summary offset outside the file")
        f.seek(summary_start)
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        chunks: list[ChunkIndex] = []
        while f.tell() < size - 37:
            op, data = _read_record(f)
            r = _Fields(data)
            if op == OP_SCHEMA:
                sid = r.u16()
                schemas[sid] = Schema(sid, r.string(), r.string(), r.sized())
            elif op == OP_CHANNEL:
                cid = r.u16()
                channels[cid] = Channel(cid, r.u16(), r.string(), r.string(), r.sized())
            elif op == OP_CHUNK_INDEX:
                start, end, offset, length = (r.u64() for _ in range(4))
                index = r.sized()
                if len(index) % 10:
                    raise McapError("malformed chunk index")
                offsets = {int(c): int(o) for c, o in struct.iter_unpack("<HQ", index)}
                chunks.append(ChunkIndex(start, end, offset, length, offsets, r.u64(),
                                         r.string(), r.u64(), r.u64()))
            elif op in (OP_SUMMARY_OFFSET, OP_FOOTER):
                break
        for c in chunks:
            if not 8 <= c.offset < summary_start or c.offset + c.length > summary_start:
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
    while True:
        loaded = [c for c in loaded if c.taken < c.log_time.size]
        horizon = mcap.chunks[order[nxt]].start_time if nxt < len(order) else None
        pending = sum(c.log_time.size - c.taken for c in loaded)
        held = sum(len(c.records) for c in loaded)
        if horizon is not None and (not loaded or _pending_min(loaded) >= horizon
                                    or (pending < max_messages and held < max_bytes)):
            k = order[nxt]
            nxt += 1
            raw, records = mcap.read_chunk(mcap.chunks[k])
            arrays = scan_records(records)
            on_chunk(k, raw, records, arrays)
            loaded.append(_Loaded(mcap.chunks[k].offset, records, *arrays))
            loaded.sort(key=lambda c: c.order)
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


def _pending_min(loaded: list[_Loaded]) -> int:
    return min(int(c.log_time[c.taken]) for c in loaded)


def _flat(loaded: list[_Loaded], which: NDArray[np.int64],
          place: NDArray[np.int64]) -> NDArray[np.int64]:
    base = np.cumsum([0] + [c.log_time.size for c in loaded])[:-1]
    return np.asarray(base, dtype=np.int64)[which] + place


# ------------------------------------------------------------------------ writing

def _string(text: str) -> bytes:
    data = text.encode("utf-8")
    return _U32.pack(len(data)) + data


def _record(op: int, body: bytes) -> bytes:
    return bytes((op,)) + _U64.pack(len(body)) + body


def schema_record(schema: Schema) -> bytes:
    """Return the bytes of a schema record."""
    return _record(OP_SCHEMA, _U16.pack(schema.id) + _string(schema.name)
                   + _string(schema.encoding) + _U32.pack(len(schema.data)) + schema.data)


def channel_record(channel: Channel) -> bytes:
    """Return the bytes of a channel record."""
    return _record(OP_CHANNEL, _U16.pack(channel.id) + _U16.pack(channel.schema_id)
                   + _string(channel.topic) + _string(channel.message_encoding)
                   + _U32.pack(len(channel.metadata)) + channel.metadata)


def metadata_map(entries: dict[str, str]) -> bytes:
    """Return an MCAP ``map<string, string>`` body (without its byte length)."""
    return b"".join(_string(k) + _string(v) for k, v in entries.items())


@dataclass
class _Pending:
    """New message records not yet in a chunk."""

    parts: list[bytes] = field(default_factory=list)
    size: int = 0
    start: int = (1 << 63) - 1
    end: int = 0
    # per channel: (log time, offset in the chunk) arrays
    index: dict[int, list[tuple[NDArray[np.int64], NDArray[np.int64]]]] = field(
        default_factory=dict)


class McapWriter:
    """Write an MCAP file: copied chunks as they are, new messages in zstd chunks.

    ``add_schema`` and ``add_channel`` before the messages that use them;
    :meth:`copy_chunk` (a chunk of an input, with its message indexes,
    byte for byte), :meth:`write` (one message) and :meth:`write_records`
    (message records built in bulk); :meth:`close` writes the summary
    (schemas, channels, chunk indexes, statistics, the rosbag2 metadata)
    and the footer.
    """

    def __init__(self, path: Path, *, library: str = "fastsim_replay") -> None:
        self.path = path
        self.file: BinaryIO = open(path, "xb")
        self.file.write(MAGIC + _record(OP_HEADER, _string("ros2") + _string(library)))
        self.schemas: dict[int, Schema] = {}
        self.channels: dict[int, Channel] = {}
        self.chunks: list[ChunkIndex] = []
        self.counts: dict[int, int] = {}
        self.start = (1 << 63) - 1
        self.end = 0
        self._pending = _Pending()
        self._sequence = 0

    def add_schema(self, schema: Schema) -> None:
        """Declare a schema (its id unique in the file)."""
        self.schemas[schema.id] = schema
        self.file.write(schema_record(schema))

    def add_channel(self, channel: Channel) -> None:
        """Declare a channel (its id unique in the file, its schema declared)."""
        self.channels[channel.id] = channel
        self.counts.setdefault(channel.id, 0)
        self.file.write(channel_record(channel))

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
        """Add one message (log time ns) to the pending chunk."""
        head = struct.pack("<BQHIQQ", OP_MESSAGE, 22 + len(data), channel, 0, log_time,
                           log_time)
        self.write_records(head + bytes(data), np.array([channel], dtype=np.int64),
                           np.array([log_time], dtype=np.int64),
                           np.array([0], dtype=np.int64))

    def write_records(self, records: bytes, channel: NDArray[np.int64],
                      log_time: NDArray[np.int64], offset: NDArray[np.int64]) -> None:
        """Add message records built in bulk.

        ``records``: their bytes; per record its ``channel``, ``log_time``
        (ns) and ``offset`` in ``records``.
        """
        if not channel.size:
            return
        p = self._pending
        base = p.size
        p.parts.append(records)
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
        compressed = zstd.compress(records)
        body = (_CHUNK_HEAD.pack(p.start, p.end, len(records), 0) + _string("zstd")
                + _U64.pack(len(compressed)) + compressed)
        offset = self.file.tell()
        self.file.write(_record(OP_CHUNK, body))
        length = self.file.tell() - offset
        index_offsets = {}
        for c, pieces in sorted(p.index.items()):
            times = np.concatenate([t for t, _ in pieces])
            offsets = np.concatenate([o for _, o in pieces])
            pairs = np.empty((times.size, 2), dtype="<u8")
            pairs[:, 0] = times
            pairs[:, 1] = offsets
            index_offsets[c] = self.file.tell()
            self.file.write(_record(OP_MESSAGE_INDEX, _U16.pack(c) + _U32.pack(pairs.nbytes)
                                    + pairs.tobytes()))
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
        body = _string("serialized_metadata") + _string(rosbag2_metadata)
        f.write(_record(OP_METADATA, _string("rosbag2") + _U32.pack(len(body)) + body))
        metadata_end = f.tell()
        f.write(_record(OP_DATA_END, _U32.pack(0)))
        summary_start = f.tell()
        for schema in self.schemas.values():
            f.write(schema_record(schema))
        channel_start = f.tell()
        for channel in self.channels.values():
            f.write(channel_record(channel))
        chunk_start = f.tell()
        for c in self.chunks:
            offsets = b"".join(_U16.pack(k) + _U64.pack(o) for k, o in c.index_offsets.items())
            f.write(_record(OP_CHUNK_INDEX, struct.pack("<QQQQ", c.start_time, c.end_time,
                                                        c.offset, c.length)
                            + _U32.pack(len(offsets)) + offsets + _U64.pack(c.index_length)
                            + _string(c.compression)
                            + _U64.pack(c.compressed_size) + _U64.pack(c.uncompressed_size)))
        metadata_index_start = f.tell()
        f.write(_record(OP_METADATA_INDEX, _U64.pack(metadata_start)
                        + _U64.pack(metadata_end - metadata_start) + _string("rosbag2")))
        statistics_start = f.tell()
        counts = b"".join(_U16.pack(c) + _U64.pack(n) for c, n in sorted(self.counts.items()))
        total = sum(self.counts.values())
        f.write(_record(OP_STATISTICS, struct.pack(
            "<QHIIIIQQ", total, len(self.schemas), len(self.channels), 0, 1, len(self.chunks),
            self.start if total else 0, self.end if total else 0)
            + _U32.pack(len(counts)) + counts))
        offsets_start = f.tell()
        for op, start, end in ((OP_SCHEMA, summary_start, channel_start),
                               (OP_CHANNEL, channel_start, chunk_start),
                               (OP_CHUNK_INDEX, chunk_start, metadata_index_start),
                               (OP_METADATA_INDEX, metadata_index_start, statistics_start),
                               (OP_STATISTICS, statistics_start, offsets_start)):
            if end > start:
                f.write(_record(OP_SUMMARY_OFFSET, bytes((op,)) + _U64.pack(start)
                                + _U64.pack(end - start)))
        f.write(_record(OP_FOOTER, _U64.pack(summary_start) + _U64.pack(offsets_start)
                        + _U32.pack(0)) + MAGIC)
        f.close()

    def abort(self) -> None:
        """Close the file as it is (the caller removes it)."""
        self.file.close()


def message_records(channel: NDArray[np.int64], log_time: NDArray[np.int64],
                    payloads: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Return message records of fixed-size payloads ``(k, L)`` as a ``(k, 31 + L)`` array."""
    k, size = payloads.shape
    out = np.empty((k, 31 + size), dtype=np.uint8)
    out[:, 0] = OP_MESSAGE
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


_PLAIN_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_.]*$")


def dump_yaml(data: Any) -> str:
    """Return ``data`` (dicts, lists, strings, integers, booleans, None) as block YAML.

    Strings are double-quoted in JSON's escapes (valid YAML): rosbag2's and
    rosbags' readers take it as they take rosbags' own ``metadata.yaml``.
    A few lines of Python: PyYAML's representer (Python even with libyaml)
    took longer than replaying a small bag.
    """
    lines: list[str] = []
    _emit(data, 0, lines)
    return "\n".join(lines) + "\n"


def _scalar(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    return json.dumps(str(value))


def _key(key: Any) -> str:
    return key if isinstance(key, str) and _PLAIN_KEY.match(key) else json.dumps(str(key))


def _emit(data: Any, indent: int, lines: list[str], first: str | None = None) -> None:
    """Add ``data`` at ``indent``; ``first``: the prefix of its first line (a list's dash)."""
    pad = " " * indent
    if isinstance(data, dict) and data:
        for k, (key, value) in enumerate(data.items()):
            head = (first if k == 0 and first is not None else pad) + _key(key) + ":"
            if isinstance(value, (dict, list)) and value:
                lines.append(head)
                _emit(value, indent + 2 if isinstance(value, dict) else indent, lines)
            else:
                lines.append(f"{head} {_inline(value)}")
    elif isinstance(data, list) and data:
        for k, value in enumerate(data):
            dash = (first if k == 0 and first is not None else pad) + "- "
            if isinstance(value, (dict, list)) and value:
                _emit(value, indent + 2, lines, dash)
            else:
                lines.append(dash + _inline(value))
    else:
        lines.append((first if first is not None else pad) + _inline(data))


def _inline(value: Any) -> str:
    if isinstance(value, dict):
        return "{}"
    if isinstance(value, list):
        return "[]"
    return _scalar(value)


def read_map(data: bytes) -> dict[str, str]:
    """Return the entries of an MCAP ``map<string, string>`` body."""
    r = _Fields(data)
    out = {}
    while r.pos < len(data):
        key = r.string()
        out[key] = r.string()
    return out
