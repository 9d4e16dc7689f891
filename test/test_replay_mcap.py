"""MCAP by the chunk (:mod:`fastsim_ros.replay.mcap`).

Windows in rosbags' order with bounded memory, files rosbags reads back,
corrupt chunks refused.
"""

from __future__ import annotations

import io
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
import zstandard
from mcap.data_stream import ReadDataStream
from rosbags.rosbag2 import Reader

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fastsim_ros import replay  # noqa: E402
from fastsim_ros.replay import bagio, mcap  # noqa: E402

BAGS = ROOT / "bags"
NAMES = ("hertz_ramp", "semi_ellipses_spin", "flange_shift", "roller_rig", "bad_inputs")


def rosbags_order(path):
    """Return ``(topic, log_ns, data)`` of every message as rosbags reads them."""
    with bagio.fast_yaml(), Reader(path) as reader:
        return [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]


def window_order(path, **limits):
    """Return the same from :func:`mcap.windows`, and the windows' buffer counts."""
    indexed = mcap.open_indexed(path)
    got, held = [], []
    try:
        for w in mcap.windows(indexed, lambda *args: None, **limits):
            held.append(len(w.buffers))
            got += [(indexed.channels[int(c)].topic, int(t), bytes(w.data(i)))
                    for i, (c, t) in enumerate(zip(w.channel, w.log_time))]
    finally:
        indexed.close()
    return got, held


@pytest.mark.parametrize("name", NAMES)
def test_windows_give_rosbags_order_and_hold_one_chunk_at_a_time(name):
    path = BAGS / name / f"{name}.mcap"
    want = rosbags_order(path)
    small, held = window_order(path, max_messages=7, max_bytes=1)
    assert small == want
    # the chunks follow one another in time: one held at a time when the window is small
    # (two where a tie in log time spans the boundary)
    assert max(held) <= 2 and np.mean(held) < 1.5
    whole, held = window_order(path)
    assert whole == want and len(held) == 1     # a bundled bag is one window by default


def _string(text):
    data = text.encode() + b"\x00"
    return b"\x00\x01\x00\x00" + len(data).to_bytes(4, "little") + data


def _writer(path):
    """Return a writer of ``path`` with two String channels, ids 1 and 2 (/chatter1, 2)."""
    text, _ = bagio.TYPESTORE.generate_msgdef("std_msgs/msg/String", ros_version=2)
    w = mcap.McapWriter(path)
    w.add_schema(mcap.Schema(1, "std_msgs/msg/String", "ros2msg", text.encode()))
    for cid in (1, 2):
        w.add_channel(mcap.Channel(cid, 1, f"/chatter{cid}", "cdr", mcap.metadata_map(
            {"offered_qos_profiles": ""})))
    return w


def _write(path, records, monkeypatch, chunk_bytes):
    """Write ``(channel, log_ns, text)`` records in this order, chunks of ``chunk_bytes``."""
    monkeypatch.setattr(mcap, "CHUNK_BYTES", chunk_bytes)
    w = _writer(path)
    for cid, t, s in records:
        w.write(cid, t, _string(s))
    w.close("")


def test_overlapping_chunks_and_ties_come_out_as_rosbags_orders_them(tmp_path, monkeypatch):
    rng = np.random.default_rng(7)
    times = rng.integers(0, 40, size=300) * 1000      # out of order, many ties
    records = [(1 + k % 2, int(t), f"m{k}") for k, t in enumerate(times)]
    path = tmp_path / "overlap.mcap"
    _write(path, records, monkeypatch, 300)
    want = rosbags_order(path)
    assert len(want) == 300 and len(mcap.open_indexed(path).chunks) > 20
    for limits in ({"max_messages": 5, "max_bytes": 1}, {"max_messages": 64}, {}):
        got, _ = window_order(path, **limits)
        assert got == want, limits


def test_a_file_the_writer_makes_reads_back_with_its_counts(tmp_path, monkeypatch):
    records = [(1, 10 * k, f"a{k}") for k in range(50)] + [(2, 5 * k, f"b{k}")
                                                           for k in range(30)]
    path = tmp_path / "out.mcap"
    _write(path, records, monkeypatch, 256)
    with Reader(path) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
        assert counts == {"/chatter1": 50, "/chatter2": 30}
        got = [(c.topic, t) for c, t, _ in reader.messages()]
    assert got == sorted(got, key=lambda m: m[1]) and len(got) == 80


def test_metadata_yaml_round_trips():
    data = {"rosbag2_bagfile_information": {
        "version": 9, "relative_file_paths": ["x.mcap"], "duration": {"nanoseconds": 5},
        "topics_with_message_count": [{"topic_metadata": {
            "name": "/contact/left/wrench", "offered_qos_profiles": [{"depth": 10}],
            "type_description_hash": "RIHS01_ab"}, "message_count": 3}],
        "custom_data": {"fastsim.parameters": '{"a": [1, 2], "b": "c: d"}'},
        "compression_format": "", "files": [], "ros_distro": "rosbags", "none": None,
        "flag": False, "nested": [[1, 2], [], {}]}}
    assert yaml.safe_load(mcap.dump_yaml(data)) == data


def test_a_corrupt_chunk_is_a_bad_input_and_leaves_nothing(tmp_path, capsys):
    bag = tmp_path / "in" / "broken"
    shutil.copytree(BAGS / "hertz_ramp", bag)
    (bag / "hertz_ramp.mcap").rename(bag / "broken.mcap")
    meta = bag / "metadata.yaml"
    meta.write_text(meta.read_text().replace("hertz_ramp.mcap", "broken.mcap"))
    indexed = mcap.open_indexed(bag / "broken.mcap")
    chunk = indexed.chunks[5]
    indexed.close()
    data = bytearray((bag / "broken.mcap").read_bytes())
    middle = chunk.offset + chunk.length // 2
    data[middle:middle + 64] = bytes(64)   # zeros in the middle of the compressed data
    (bag / "broken.mcap").write_bytes(bytes(data))
    out = tmp_path / "out"
    status = replay.main([str(bag), str(BAGS / "roller_rig"), "-o", str(out), "--csv"])
    err = capsys.readouterr().err
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"fastsim_replay: {bag}: unreadable")
    assert sorted(p.name for p in out.iterdir()) == ["roller_rig", "roller_rig.csv"]


def test_message_indexes_of_single_and_bulk_writes_point_at_their_records(tmp_path,
                                                                          monkeypatch):
    """Every message index entry names a message record of its channel and log time.

    One message at a time (``write``, the per-message replay) and in bulk
    (``write_records``, the batched one) into the same chunks and channels,
    in runs that alternate: each record indexed once, in file order.
    """
    from mcap.records import Chunk, Message, MessageIndex
    from mcap.stream_reader import StreamReader
    monkeypatch.setattr(mcap, "CHUNK_BYTES", 700)
    path = tmp_path / "mixed.mcap"
    w = _writer(path)
    written = []
    t = 0
    for run in range(12):
        if run % 3 == 2:  # a bulk run: fixed-size payloads, both channels
            payloads = np.frombuffer(b"".join(_string(f"bulk{run}{k:02d}") for k in range(6)),
                                     dtype=np.uint8).reshape(6, -1)
            ch = np.array([1, 2, 1, 1, 2, 2], dtype=np.int64)
            times = np.arange(t, t + 6, dtype=np.int64)
            records = mcap.message_records(ch, times, payloads)
            offsets = np.arange(6, dtype=np.int64) * records.shape[1]
            w.write_records(records.tobytes(), ch, times, offsets)
            written += [(int(c), int(s), payloads[k].tobytes()) for k, (c, s) in
                        enumerate(zip(ch, times))]
            t += 6
        else:
            for k in range(5):
                cid = 1 + (run + k) % 2
                data = _string(f"one{run}-{k}")
                w.write(cid, t, data)
                written.append((cid, t, data))
                t += 1
    w.close("")
    indexed = []
    chunks = 0
    last_chunk = None
    for record in StreamReader(str(path), emit_chunks=True, validate_crcs=True).records:
        if isinstance(record, Chunk):
            chunks += 1
            last_chunk = record
        elif isinstance(record, MessageIndex):
            assert last_chunk is not None
            data = zstandard.ZstdDecompressor().decompress(
                last_chunk.data, max_output_size=last_chunk.uncompressed_size)
            for log_time, offset in record.records:
                # opcode, length, then the Message record's fields
                assert data[offset] == 0x05
                length = int.from_bytes(data[offset + 1:offset + 9], "little")
                msg = Message.read(ReadDataStream(io.BytesIO(
                    data[offset + 9:offset + 9 + length])), length)
                assert (msg.channel_id, msg.log_time) == (record.channel_id, log_time)
                indexed.append((msg.channel_id, msg.log_time, bytes(msg.data)))
    assert chunks > 3
    assert sorted(indexed, key=lambda m: m[1]) == written
    got, _ = window_order(path)
    assert [(int(topic[-1]), t, d) for topic, t, d in got] == written


def test_the_compiled_message_records_are_the_librarys_bytes():
    # the batched writer's records, written in place at their offsets, against the array
    # builder and the mcap library's own Message record
    from mcap.records import Message
    from fastsim_ros.replay import kernels
    payloads = np.arange(5 * 13, dtype=np.uint8).reshape(5, 13)
    times = np.array([0, 1, 2**40 + 3, 2**62 + 5, 1_700_000_000_123_456_789], dtype=np.int64)
    offsets = np.array([3, 3 + 44 + 7, 3 + 2 * 44 + 7, 3 + 3 * 44 + 9, 3 + 4 * 44 + 9])
    out = np.full(offsets[-1] + 44 + 2, 0xAB, dtype=np.uint8)
    kernels.message_records(out, offsets, 0x1234, times, payloads)
    built = mcap.message_records(np.full(5, 0x1234, dtype=np.int64), times, payloads)
    for k, o in enumerate(offsets.tolist()):
        record = out[o:o + 44].tobytes()
        assert record == built[k].tobytes()
        msg = Message(channel_id=0x1234, sequence=0, log_time=int(times[k]),
                      publish_time=int(times[k]), data=payloads[k].tobytes())
        stream = mcap.RecordBuilder()
        msg.write(stream)
        assert record == stream.end()
    gaps = np.ones(out.size, dtype=np.bool_)
    for o in offsets.tolist():
        gaps[o:o + 44] = False
    assert (out[gaps] == 0xAB).all()      # nothing written between the records
