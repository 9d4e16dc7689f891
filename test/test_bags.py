"""The bundled bags: readable, small, reproducible, with patches of the node's input layout."""

from dataclasses import fields, is_dataclass
import importlib.util
import io
from pathlib import Path
import zlib

from mcap.records import Chunk
from mcap.stream_reader import StreamReader
import numpy as np
import pytest
from rosbags.interfaces import QosReliability
from rosbags.rosbag2 import Reader
import yaml
import zstandard

ROOT = Path(__file__).resolve().parents[1]
BAGS = ROOT / "bags"
CLOUD = "sensor_msgs/msg/PointCloud2"
TWIST = "geometry_msgs/msg/TwistStamped"
POSE = "geometry_msgs/msg/PoseStamped"
WRENCH = "geometry_msgs/msg/WrenchStamped"
FIELDS = ["x", "y", "z", "normal_x", "normal_y", "normal_z", "pressure"]

#: topic -> (type, message count) of each bundled bag
EXPECTED = {
    "hertz_ramp": {"/wheelset/twist": (TWIST, 800), "/contact/left/patch": (CLOUD, 400),
                   "/contact/right/patch": (CLOUD, 400)},
    "semi_ellipses_spin": {"/wheelset/twist": (TWIST, 800), "/contact/left/patch": (CLOUD, 400),
                           "/contact/right/patch": (CLOUD, 400)},
    "flange_shift": {"/wheelset/twist": (TWIST, 800), "/wheelset/load": (WRENCH, 800),
                     "/wheelset/pose": (POSE, 400), "/contact/left/patch": (CLOUD, 400),
                     "/contact/right/patch": (CLOUD, 400),
                     "/contact/left_flange/patch": (CLOUD, 400),
                     "/contact/right_flange/patch": (CLOUD, 400)},
    "roller_rig": {"/wheelset/twist": (TWIST, 800), "/rail/twist": (TWIST, 800),
                   "/contact/wheel/patch": (CLOUD, 400)},
    "bad_inputs": {"/wheelset/twist": (TWIST, 540), "/contact/left/patch": (CLOUD, 300),
                   "/contact/right/patch": (CLOUD, 300)},
    "mbench_a22": {"/wheelset/twist": (TWIST, 42), "/wheelset/load": (WRENCH, 42),
                   "/wheelset/pose": (POSE, 21)},
    "adhesion_rig": {"/wheelset/twist": (TWIST, 800), "/wheelset/measured_wrench": (WRENCH, 400),
                     "/contact/left/patch": (CLOUD, 400), "/contact/right/patch": (CLOUD, 400)},
    "contaminated_rig": {"/wheelset/twist": (TWIST, 800),
                         "/wheelset/measured_wrench": (WRENCH, 400),
                         "/contact/left/patch": (CLOUD, 400),
                         "/contact/right/patch": (CLOUD, 400)},
}
#: made from hundreds of exact solves (seconds): shipped, never rebuilt by the tests
SLOW = ("adhesion_rig",)


def _generator():
    spec = importlib.util.spec_from_file_location("make_bags", ROOT / "scripts" / "make_bags.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


MB = _generator()


def _plain(msg):
    """Return a message as nested tuples (arrays as dtype and bytes) for equality."""
    if is_dataclass(msg):
        return tuple((f.name, _plain(getattr(msg, f.name))) for f in fields(msg))
    if isinstance(msg, np.ndarray):
        return (str(msg.dtype), msg.tobytes())
    if isinstance(msg, (list, tuple)):
        return tuple(_plain(m) for m in msg)
    return msg


def _messages(path):
    with Reader(path) as reader:
        return [(conn.topic, ns, MB.TYPESTORE.deserialize_cdr(raw, conn.msgtype))
                for conn, ns, raw in reader.messages()]


@pytest.fixture(scope="module")
def decoded():
    return {name: _messages(BAGS / name) for name in EXPECTED}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_bag_opens_with_topics_types_counts(name, decoded):
    path = BAGS / name
    assert sorted(p.name for p in path.iterdir()) == sorted(["metadata.yaml", f"{name}.mcap"])
    with Reader(path) as reader:
        got = {c.topic: (c.msgtype, c.msgcount) for c in reader.connections}
        assert reader.message_count == sum(n for _, n in EXPECTED[name].values())
    assert got == EXPECTED[name]
    counts = {}
    for topic, _, _ in decoded[name]:
        counts[topic] = counts.get(topic, 0) + 1
    assert counts == {t: n for t, (_, n) in EXPECTED[name].items()}
    # log times never go back (the replay feeds them in this order)
    stamps = [ns for _, ns, _ in decoded[name]]
    assert stamps == sorted(stamps) and 0 <= stamps[0] - MB.T0_NS < 10**7


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_metadata_version_and_qos(name):
    meta = yaml.safe_load((BAGS / name / "metadata.yaml").read_text())
    info = meta["rosbag2_bagfile_information"]
    assert info["version"] == 9 and info["storage_identifier"] == "mcap"
    for entry in info["topics_with_message_count"]:
        qos = entry["topic_metadata"]["offered_qos_profiles"]
        assert len(qos) == 1
        assert qos[0]["reliability"] == "reliable" and qos[0]["history"] == "keep_last"
        assert qos[0]["durability"] == "volatile" and qos[0]["depth"] == 10
    with Reader(BAGS / name) as reader:
        for conn in reader.connections:
            (qos,) = conn.ext.offered_qos_profiles
            assert qos.reliability == QosReliability.RELIABLE


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_every_chunk_carries_its_crc(name):
    """Each chunk has its CRC: rosbags writes 0 (none), ``make_bags.with_chunk_crcs`` adds them.

    Without, a corruption inside a chunk's compressed data decoded as other
    bytes in 15 of 60 places tried on hertz_ramp (patches refused one by one,
    or read as other numbers) instead of failing the read as a bad file.
    """
    raw = (BAGS / name / f"{name}.mcap").read_bytes()
    chunks = [r for r in StreamReader(io.BytesIO(raw), emit_chunks=True).records
              if isinstance(r, Chunk)]
    assert chunks
    for chunk in chunks:
        assert chunk.uncompressed_crc != 0
        assert chunk.uncompressed_crc == zlib.crc32(
            zstandard.ZstdDecompressor().decompress(
                chunk.data, max_output_size=chunk.uncompressed_size))


def test_total_size_under_10_mb():
    total = sum(f.stat().st_size for f in BAGS.rglob("*") if f.is_file())
    assert total <= 10 * 1024 * 1024


def _assert_same(made, shipped, where=""):
    """Assert two decoded messages equal to the rounding of the machine that made them.

    The bags made from profiles run the normal solver and the load balance:
    numpy's SIMD kernels (AVX-512 on one machine of this kind, AVX2 on
    another) sum in another order, so a rebuilt bag may differ from the
    shipped one in the last bits (seen: dz by 1e-18 m, 440 of 3600 messages
    of flange_shift between an Intel and an AMD machine; the same machine
    rebuilds it bit for bit).  Floats: 1e-9 relative; the float32 patch
    clouds: 4 float32 ulps of the field's largest value.
    """
    if is_dataclass(made):
        assert type(made) is type(shipped), where
        if hasattr(made, "fields") and hasattr(made, "data") and hasattr(made, "point_step"):
            a = np.frombuffer(made.data.tobytes(), dtype="<f4")
            b = np.frombuffer(shipped.data.tobytes(), dtype="<f4")
            assert a.shape == b.shape, where
            scale = float(np.abs(b).max()) if b.size else 0.0
            np.testing.assert_allclose(a, b, rtol=0.0, atol=4 * np.finfo(np.float32).eps * scale,
                                       err_msg=where)
            for f in fields(made):
                if f.name != "data":
                    _assert_same(getattr(made, f.name), getattr(shipped, f.name),
                                 f"{where}.{f.name}")
            return
        for f in fields(made):
            _assert_same(getattr(made, f.name), getattr(shipped, f.name), f"{where}.{f.name}")
    elif isinstance(made, np.ndarray):
        assert made.dtype == shipped.dtype and made.shape == shipped.shape, where
        if made.dtype.kind == "f":
            np.testing.assert_allclose(made, shipped, rtol=1e-9, err_msg=where)
        else:
            assert made.tobytes() == shipped.tobytes(), where
    elif isinstance(made, (list, tuple)):
        assert len(made) == len(shipped), where
        for k, (a, b) in enumerate(zip(made, shipped)):
            _assert_same(a, b, f"{where}[{k}]")
    elif isinstance(made, float):
        assert made == pytest.approx(shipped, rel=1e-9, abs=1e-15), where
    else:
        assert made == shipped, where


def test_generator_rebuilds_the_same_bags(tmp_path, decoded):
    assert MB.main(["--out", str(tmp_path), "--only",
                    *(n for n in MB.SCENARIOS if n not in SLOW)]) == 0
    for name in (n for n in EXPECTED if n not in SLOW):
        again = _messages(tmp_path / name)
        assert len(again) == len(decoded[name])
        for (t1, ns1, m1), (t2, ns2, m2) in zip(again, decoded[name]):
            assert (t1, ns1) == (t2, ns2)
            _assert_same(m1, m2, f"{name} {t1} {ns1}")
        for extra in (f"{name}.params.yaml", f"{name}.expected.yaml"):
            if (BAGS / extra).exists():
                assert (tmp_path / extra).read_text() == (BAGS / extra).read_text()


def _points(msg):
    return np.frombuffer(msg.data.tobytes(), dtype="<f4").reshape(msg.height, msg.width, -1)


def _check_layout(msg):
    assert msg.header.frame_id == "wheelset"
    assert [f.name for f in msg.fields] == FIELDS
    assert [(f.offset, f.datatype, f.count) for f in msg.fields] == \
        [(4 * i, 7, 1) for i in range(7)]
    assert msg.point_step == 28 and msg.row_step == 28 * msg.width
    assert not msg.is_bigendian and msg.is_dense
    pts = _points(msg)
    assert np.all(np.isfinite(pts))
    p = pts[..., 6]
    assert np.all(p >= 0.0)
    n = pts[..., 3:6].astype(float)
    assert np.allclose(np.linalg.norm(n, axis=2), 1.0, atol=1e-6)
    if p.max() > 0.0:
        assert not (p[0].any() or p[-1].any() or p[:, 0].any() or p[:, -1].any())
    # organised: points run along +x in a row, rows step along the in-plane y = e_z x e_x
    pos = pts[..., 0:3].astype(float)
    ex, ey = np.diff(pos, axis=1), np.diff(pos, axis=0)
    assert np.all(ex[..., 0] > 0.0)
    ez = n[0, 0]
    assert np.allclose(ey / np.linalg.norm(ey, axis=2, keepdims=True),
                       np.cross(ez, [1.0, 0.0, 0.0]), atol=2e-3)
    assert np.allclose(ex, ex[0, 0], atol=1e-3 * np.linalg.norm(ex[0, 0]))
    assert np.allclose(ey, ey[0, 0], atol=1e-3 * np.linalg.norm(ey[0, 0]))
    return p


#: the bags of hand-made patches (20 to 30 cells a side); flange_shift's come from profiles
SYNTHETIC = ("hertz_ramp", "semi_ellipses_spin", "roller_rig", "adhesion_rig",
             "contaminated_rig")


@pytest.mark.parametrize("name", [n for n in sorted(EXPECTED)
                                  if n not in ("bad_inputs", "mbench_a22")])
def test_patches_follow_the_layout(name, decoded):
    loads = []
    for topic, ns, msg in decoded[name]:
        assert msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec == ns
        if topic.endswith(("/twist", "/load", "/measured_wrench")):
            assert msg.header.frame_id == "wheelset"
            continue
        if topic.endswith("/pose"):
            assert msg.header.frame_id == "track"
            continue
        if msg.height * msg.width == 0:  # an empty patch: no contact on that name
            loads.append(0.0)
            continue
        if name in SYNTHETIC:
            assert 20 <= msg.height <= 30 and 20 <= msg.width <= 30
        p = _check_layout(msg)
        dx = np.linalg.norm(_points(msg)[0, -1, :3] - _points(msg)[0, 0, :3]) / (msg.width - 1)
        dy = np.linalg.norm(_points(msg)[-1, 0, :3] - _points(msg)[0, 0, :3]) / (msg.height - 1)
        loads.append(float(p.sum()) * dx * dy)
    loads = np.array(loads)
    low = 1.0e4 if name in SYNTHETIC else 1.0e3  # profiles: a gauge-corner patch starting
    assert np.all((loads == 0.0) | ((loads > low) & (loads < 1.0e5)))
    assert np.count_nonzero(loads) > (0.5 if name in SYNTHETIC else 0.4) * loads.size


def test_bad_inputs_expected_outcomes():
    expected = yaml.safe_load((BAGS / "bad_inputs.expected.yaml").read_text())["contacts"]
    params = yaml.safe_load((BAGS / "bad_inputs.params.yaml").read_text())
    params = params["fastsim"]["ros__parameters"]
    assert params["max_patch_cells"] == 4096
    outcomes = MB.classify_bag(BAGS / "bad_inputs", params)
    assert MB.expected_counts(outcomes) == expected
    for contact, c in expected.items():
        assert c["patches"] == c["served"] + c["no_contact"] + sum(c["rejected"].values())
        assert c["served"] > c["patches"] // 2
        assert c["no_contact"] >= 2
        for reason, n in c["rejected"].items():
            # out_of_table and derailment (profiles mode) have no bad patch of their own
            assert n >= (0 if reason in ("out_of_table", "derailment") else 2), (contact, reason)


def test_bad_inputs_good_patches_and_old_stamps(decoded):
    last = {}
    old = 0
    for topic, ns, msg in decoded["bad_inputs"]:
        stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
        if topic.endswith("/twist"):
            assert stamp == ns
            continue
        if topic in last and stamp < last[topic]:
            old += 1  # an old_stamp patch: logged in turn, stamped before the one before it
        else:
            assert stamp == ns
        last[topic] = ns
        if msg.height * msg.width <= 4096 and msg.header.frame_id == "wheelset" \
                and len(msg.fields) == 7 and np.all(np.isfinite(_points(msg))) \
                and np.all(_points(msg)[..., 6] >= 0):
            pts = _points(msg)
            assert pts.shape[:2] == (20, 20)
    assert old == 4


def test_ros_deserializes_the_bags(decoded):
    from rclpy.serialization import deserialize_message
    from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
    from sensor_msgs.msg import PointCloud2
    classes = {CLOUD: PointCloud2, TWIST: TwistStamped, POSE: PoseStamped,
               WRENCH: WrenchStamped}
    for name in EXPECTED:
        seen = set()
        with Reader(BAGS / name) as reader:
            for conn, _, raw in reader.messages():
                if conn.topic in seen:
                    continue
                seen.add(conn.topic)
                ros = deserialize_message(bytes(raw), classes[conn.msgtype])
                ours = MB.TYPESTORE.deserialize_cdr(raw, conn.msgtype)
                assert ros.header.frame_id == ours.header.frame_id
                assert ros.header.stamp.nanosec == ours.header.stamp.nanosec
                if conn.msgtype == CLOUD:
                    assert bytes(ros.data) == ours.data.tobytes()
                    assert [f.name for f in ros.fields] == [f.name for f in ours.fields]
                elif conn.msgtype == TWIST:
                    assert ros.twist.angular.y == ours.twist.angular.y
                elif conn.msgtype == POSE:
                    assert ros.pose.orientation.w == ours.pose.orientation.w
                    assert ros.pose.position.y == ours.pose.position.y
                else:
                    assert ros.wrench.force.z == ours.wrench.force.z
        assert seen == set(EXPECTED[name])
