"""The replay's MCAP through the official ``mcap`` library.

Its output read back by the library with every CRC checked, the summary's
CRC as the library's writer computes it, and malformed files refused as
:class:`~fastsim_ros.replay.McapError` (never the library's or
Python's own exceptions).
"""

from __future__ import annotations

import struct
import sys
import zlib
from pathlib import Path

import pytest
from mcap.reader import make_reader
from rosbags.rosbag2 import Reader

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fastsim_ros import replay  # noqa: E402
from fastsim_ros.replay import bagio, mcap  # noqa: E402
from fastsim_ros.replay.errors import McapError  # noqa: E402

BAGS = ROOT / "bags"


def test_replay_output_reads_back_through_the_library_with_crcs(tmp_path, capsys):
    assert replay.main([str(BAGS / "flange_shift"), "-o", str(tmp_path / "out")]) == 0
    capsys.readouterr()
    path = tmp_path / "out" / "flange_shift" / "flange_shift.mcap"
    with bagio.fast_yaml(), Reader(path.parent) as reader:
        want = [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]
    with open(path, "rb") as f:
        lib = make_reader(f, validate_crcs=True)
        summary = lib.get_summary()
        got = [(ch.topic, m.log_time, bytes(m.data)) for _, ch, m in lib.iter_messages()]
        assert summary is not None and summary.statistics is not None
        assert summary.statistics.message_count == len(want)
    assert got == want and len(got) > 6000
    data = path.read_bytes()
    footer = data[-37:-8]
    summary_start, offsets_start, crc = struct.unpack_from("<QQI", footer, 9)
    assert crc == zlib.crc32(data[summary_start:-8 - 4])


def _copy(tmp_path, name="roller_rig"):
    path = tmp_path / f"{name}.mcap"
    path.write_bytes((BAGS / name / f"{name}.mcap").read_bytes())
    return path


def test_a_chunk_whose_records_fail_their_crc_is_refused(tmp_path, capsys):
    # the bundled bags (rosbags) leave the CRC 0; the replay's own chunks carry one
    assert replay.main([str(BAGS / "roller_rig"), "-o", str(tmp_path / "out")]) == 0
    capsys.readouterr()
    path = tmp_path / "out" / "roller_rig" / "roller_rig.mcap"
    data = bytearray(path.read_bytes())
    indexed = mcap.open_indexed(path)
    crcs = [(c.offset + 9 + 24, struct.unpack_from("<I", data, c.offset + 9 + 24)[0])
            for c in indexed.chunks]   # each chunk's uncompressed CRC
    indexed.close()
    at, crc = next((at, crc) for at, crc in crcs if crc)
    struct.pack_into("<I", data, at, crc ^ 1)
    path.write_bytes(bytes(data))
    indexed = mcap.open_indexed(path)
    try:
        with pytest.raises(McapError, match="checksum mismatch"):
            for _ in mcap.windows(indexed, lambda *args: None):
                pass
    finally:
        indexed.close()


def test_a_summary_record_longer_than_the_file_is_refused(tmp_path):
    path = _copy(tmp_path)
    data = bytearray(path.read_bytes())
    summary_start = struct.unpack_from("<Q", data, len(data) - 37 + 9)[0]
    struct.pack_into("<Q", data, summary_start + 1, 10 ** 12)
    path.write_bytes(bytes(data))
    with pytest.raises(McapError, match="malformed summary"):
        mcap.open_indexed(path)


@pytest.mark.parametrize("content", [b"", b"\x89MCAP0\r\n", bytes(range(256)) * 4])
def test_not_mcap_is_refused(tmp_path, content):
    path = tmp_path / "x.mcap"
    path.write_bytes(content)
    with pytest.raises(McapError):
        mcap.open_indexed(path)
