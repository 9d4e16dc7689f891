"""The replay's chunked, batched path gives the per-message replay's outputs, bit for bit.

``fastsim_replay`` replays an indexed MCAP bag by the chunk and applies the
pipeline's rules to runs of messages at once (:mod:`fastsim_ros.replay.batch`);
rosbags' reader and writer with one pipeline call per message are the
reference (``path="rosbags"``).  Both must write the same messages on the same
topics in the same order with the same values (CSV text equal byte for byte,
every topic's messages decoded equal, the diagnostics but their wall-clock
solve times), on the bundled bags and on a recording made to go through every
branch: reverse running, a rail twist, float64, padded and reversed point
layouts, layout changes (and back), empty grids, big-endian data, every rejection, twists of every
kind, each method, bound and friction law, markers at every solve.
"""

from __future__ import annotations

import math
import struct
import sys
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag2 import Reader, Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode, StoragePlugin

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from fastsim_ros import replay  # noqa: E402
from fastsim_ros.contact import samples  # noqa: E402
from fastsim_ros.contact.area import ellipse  # noqa: E402
from fastsim_ros.ros.params import checked, load_params_file  # noqa: E402
from fastsim_ros.pipeline import InputTopic, Pipeline, PipelineConfig  # noqa: E402
from fastsim_ros.replay import batch, encode  # noqa: E402
from msg_adapters import outputs  # noqa: E402
from msg_adapters.cdr import stamped_doubles  # noqa: E402
from msg_adapters.patch import ContactFrame  # noqa: E402
from ros_messages import (WHEEL_RADIUS, cdr, cloud_msg, contact_normal,  # noqa: E402
                          rolling_twist, twist_msg)
from test_replay import BAGS, NAMES, TYPES, decoded_without_timing  # noqa: E402

T0 = 1_700_000_000 * 10**9
MS = 10**6


def replayed(source, out, values, path, **options):
    """Replay ``source`` on ``path``; return (CSV text, decoded contents, result)."""
    name = Path(source).name
    out.mkdir(parents=True, exist_ok=True)
    r = replay.replay_bag(Path(source), name, out, values, write_csv=True, progress=False,
                          path=path, **options)
    assert r.ok, r.error
    return (out / f"{name}.csv").read_text(), contents_of(out / name), r


def contents_of(path):
    """Return every topic's messages decoded, without the diagnostics' solve times.

    Bytes where they do not decode (the malformed inputs, copied).
    """
    out = {}
    with Reader(path) as reader:
        for conn, log_ns, raw in reader.messages():
            try:
                msg = TYPES.deserialize_cdr(raw, conn.msgtype)
            except Exception:
                msg = bytes(raw)
            out.setdefault(conn.topic, (conn.msgtype, []))[1].append((log_ns, msg))
    return decoded_without_timing(out)


def assert_same(a, b):
    """Assert two replays wrote the same outputs and counted the same."""
    csv_a, bag_a, res_a = a
    csv_b, bag_b, res_b = b
    assert csv_a == csv_b
    assert sorted(bag_a) == sorted(bag_b)
    for topic in bag_a:  # (repr: a NaN copied from the input equals itself)
        assert repr(bag_a[topic]) == repr(bag_b[topic]), topic
    assert res_a.counts == res_b.counts and res_a.kinematics == res_b.kinematics
    assert (res_a.messages_in, res_a.messages_out) == (res_b.messages_in, res_b.messages_out)


@pytest.mark.parametrize("name", NAMES)
def test_every_path_replays_a_bundled_bag_the_same(tmp_path, name):
    values = load_params_file(BAGS / f"{name}.params.yaml")
    reference = replayed(BAGS / name, tmp_path / "rosbags", values, "rosbags")
    by_chunk = replayed(BAGS / name, tmp_path / "messages", values, "messages")
    batched = replayed(BAGS / name, tmp_path / "auto", values, "auto")
    assert_same(by_chunk, reference)
    assert_same(batched, reference)
    # a recording of patches solves hundreds; mbench_a22 (profiles mode) its 21 poses' two treads
    least = 42 if values.get("patch_source") == "profiles" else 400
    assert sum(reference[2].counts[c]["solved"] for c in reference[2].contacts) >= least


# ------------------------------------------------------------------------ a varied bag

def _twist_be(stamp_ns, linear, angular, frame="wheelset"):
    """Return a TwistStamped in big-endian CDR (the node reads either byte order)."""
    sec, nanosec = divmod(stamp_ns, 10**9)
    name = frame.encode() + b"\x00"
    body = struct.pack(">iII", sec, nanosec, len(name)) + name
    body += b"\x00" * (-len(body) % 8)
    return b"\x00\x00\x00\x00" + body + struct.pack(">6d", *linear, *angular)


def _empty(cloud):
    """Return ``cloud`` as a grid of no cells (an empty patch: no contact)."""
    cloud.height, cloud.width, cloud.row_step, cloud.data = 0, 0, 0, b""
    return cloud


def varied_bag(path):
    """Write a 2 s two-contact recording that takes every branch of the batched path."""
    hertz = ellipse(6e-3, 4e-3, nx=24, load=6e4)
    egg = samples.semi_ellipses_patch(0.5, 2.0, cells=24, scale=8e-3, load=5e4)
    wide = ellipse(7e-3, 3e-3, nx=32, ny=20, load=4e4)
    three = np.zeros_like(hertz.pressure)
    three[11, 11:14] = 1e6   # 3 cells in contact: degenerate
    msgs = []  # (topic, log_ns, cdr bytes)
    for k in range(400):  # wheelset twists at 200 Hz
        t = T0 + k * 5 * MS
        if k < 150:
            tw = cdr(rolling_twist(2e-3 * k / 150, stamp_ns=t))
        elif k < 170:    # standstill
            tw = cdr(twist_msg(stamp_ns=t))
        elif k < 190:    # a gap: stale kinematics
            continue
        else:            # reverse running: the leading edge at -x
            omega = -20.0 * (1 - 1e-3) / (1 + 1e-3) / WHEEL_RADIUS
            tw = cdr(twist_msg((-20.0, 0.3, 0.0), (0.0, omega, 0.02), stamp_ns=t))
        if k == 60:
            tw = cdr(twist_msg((20.0, 0, 0), (0, 43.0, 0), stamp_ns=t, frame_id="base_link"))
        elif k == 61:
            tw = cdr(twist_msg((math.nan, 0, 0), (0, 43.0, 0), stamp_ns=t))
        elif k == 62:
            tw = cdr(rolling_twist(1e-3, stamp_ns=t - 20 * MS))          # old stamp
        elif k == 63:
            tw = _twist_be(t, (20.0, 0.0, 0.0), (0.0, 43.4, 0.0))        # big endian
        elif k == 64:
            tw = cdr(rolling_twist(1e-3, stamp_ns=t))[:30]               # malformed
        msgs.append(("/wheelset/twist", t, tw))
        if k % 4 == 1:   # a moving rail, sometimes
            msgs.append(("/rail/twist", t + MS, cdr(twist_msg(
                (0.01 * math.sin(k), 0.0, 0.0), (0.0, 0.0, 1e-3), stamp_ns=t + MS))))
    for k in range(200):  # patches at 100 Hz
        t = T0 + 2_500_000 + k * 10 * MS
        gamma = 0.05 + 0.2 * k / 200
        left = dict(origin=(0.0, 0.75, -WHEEL_RADIUS), normal=contact_normal(gamma, "left"))
        right = dict(origin=(0.0, -0.75, -WHEEL_RADIUS), normal=contact_normal(gamma, "right"))
        if k < 100:
            lp = cloud_msg(hertz, stamp_ns=t, **left)
        else:            # a layout change: float64, another grid
            lp = cloud_msg(wide, stamp_ns=t, dtype="<f8", **left)
        rp = cloud_msg(egg, stamp_ns=t, pad=4, reverse_rows=True, reverse_columns=True, **right)
        lraw, rraw = cdr(lp), cdr(rp)
        if k == 20:
            lraw = cdr(cloud_msg(hertz, stamp_ns=t, dtype=">f4", **left))        # big endian
        elif k == 21:
            lraw = cdr(cloud_msg(hertz, stamp_ns=t, frame_id="base_link", **left))
        elif k == 22:
            lraw = cdr(cloud_msg(hertz, stamp_ns=t - 25 * MS, **left))           # old stamp
        elif k == 23:
            bad = hertz.pressure.copy()
            bad[12, 12] = math.nan
            lraw = cdr(cloud_msg(hertz, stamp_ns=t, pressure=bad, **left))
        elif k == 24:
            lraw = cdr(cloud_msg(hertz, stamp_ns=t, pressure=0 * hertz.pressure, **left))
        elif k == 25:
            lraw = cdr(cloud_msg(hertz, stamp_ns=t, pressure=three, **left))     # degenerate
        elif k == 26:
            lraw = lraw[:60]                                                   # malformed
        elif k == 29:   # a pressure beyond any material's: too_large
            huge = hertz.pressure.copy()
            huge[12, 12] = 1e30
            lraw = cdr(cloud_msg(hertz, stamp_ns=t, pressure=huge, **left))
        elif k == 28:   # a NaN stamped an hour ahead: rejected, and no later patch old for it
            bad = hertz.pressure.copy()
            bad[12, 12] = math.nan
            lraw = cdr(cloud_msg(hertz, stamp_ns=t + 3600 * 10**9, pressure=bad, **left))
        elif k == 27:
            bad = egg.pressure.copy()
            bad[5, 5] = -1.0
            rraw = cdr(cloud_msg(egg, stamp_ns=t, pad=4, pressure=bad, **right))
        elif k in (40, 41):
            rraw = cdr(cloud_msg(egg, stamp_ns=t, pad=4, pressure=0 * egg.pressure, **right))
        elif k in (30, 31, 35):
            lraw = cdr(_empty(cloud_msg(hertz, stamp_ns=t, **left)))     # a grid of no cells
        elif k in (150, 152):   # another layout for a moment, then the first one again
            rraw = cdr(cloud_msg(egg, stamp_ns=t, **right))
        msgs.append(("/contact/left/patch", t, lraw))
        msgs.append(("/contact/right/patch", t, rraw))
    msgs.sort(key=lambda m: m[1])
    types = {"/wheelset/twist": "geometry_msgs/msg/TwistStamped",
             "/rail/twist": "geometry_msgs/msg/TwistStamped",
             "/contact/left/patch": "sensor_msgs/msg/PointCloud2",
             "/contact/right/patch": "sensor_msgs/msg/PointCloud2"}
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with writer:
        conns = {t: writer.add_connection(t, m, typestore=TYPES) for t, m in types.items()}
        for topic, t, raw in msgs:
            writer.write(conns[topic], t, raw)
    return path


@pytest.fixture(scope="module")
def varied(tmp_path_factory):
    return varied_bag(tmp_path_factory.mktemp("varied") / "varied")


VARIANTS = {
    "defaults": {},
    "mae_parabolic_exponential_markers": {
        "method": "mae", "traction_bound": "parabolic", "friction_law": "exponential",
        "friction_limit_ratio": 0.5, "friction_decay": 0.2, "marker_rate": 0.0},
    "ellipse_rail_required": {"method": "fastsim_ellipse", "rail_twist_required": True,
                              "max_kinematics_age": 0.02, "publish_markers": False},
    "small_grids_only": {"max_patch_cells": 620, "friction_coefficient": 0.15},
    "traction_clouds": {"publish_traction": True},
    "calibrated_falling_slope_reduced": {
        "friction_law": "exponential", "friction_limit_ratio": 0.4, "friction_decay": 0.6,
        "slope_reduction_k0": 0.5, "slope_reduction_alpha_inf": 0.1,
        "slope_reduction_beta": 0.8},
    "polach": {"method": "polach", "polach_ka": 0.5, "polach_ks": 0.2},
}


@pytest.mark.parametrize("variant", VARIANTS)
def test_batched_path_equals_the_per_message_path_on_every_branch(tmp_path, varied, variant):
    values = checked(dict(VARIANTS[variant], contacts=["left", "right"]))
    reference = replayed(varied, tmp_path / "rosbags", values, "rosbags")
    batched = replayed(varied, tmp_path / "auto", values, "auto")
    assert_same(batched, reference)
    counts, kinematics = reference[2].counts, reference[2].kinematics
    # the recording does take the branches it was made for
    assert counts["left"]["solved"] > 50 and counts["right"]["solved"] > 50
    assert all(kinematics[k] for k in ("wrong_frame", "nonfinite", "old_stamp", "malformed"))
    for reason in ("wrong_frame", "old_stamp", "nonfinite", "degenerate", "missing_field",
                   "standstill", "stale_kinematics"):
        assert counts["left"][reason] >= 1, reason
    assert counts["right"]["negative_pressure"] == 1 and counts["right"]["no_contact"] == 2
    assert counts["left"]["no_contact"] >= 3    # the grids of no cells
    assert counts["left"]["old_stamp"] == 1 and counts["left"]["nonfinite"] >= 2
    # the wheelset wrench is one cycle's, the contacts' wrenches of its own stamp, after the
    # rejections of the contact that arrives first too (they paired left k with right k - 1)

    def stamp(m):   # a decoded message as plain dicts
        return m["header"]["stamp"]["sec"] * 10**9 + m["header"]["stamp"]["nanosec"]
    wrenches = {c: {stamp(m) for _, m in reference[1][f"/contact/{c}/wrench"][1]}
                for c in ("left", "right")}
    sums = reference[1]["/wheelset/wrench"][1]
    assert len(sums) > 50
    # a sum with the other contact's wrench of the cycle before: at most once per rejection
    # (a flag per contact made every later sum so, after the first rejected left patch)
    mixed = [stamp(m) for _, m in sums
             if not (stamp(m) in wrenches["left"] and stamp(m) in wrenches["right"])]
    rejected = sum(n for c in ("left", "right") for reason, n in counts[c].items()
                   if reason not in ("solved", "no_contact"))
    assert len(mixed) <= min(rejected, 12), mixed
    if variant == "small_grids_only":
        assert counts["left"]["too_large"] == 100 + 1   # the 20 x 32 patches, 1e30 Pa
    else:
        assert counts["left"]["too_large"] == 1         # 1e30 Pa
    rows = [line.split(",") for line in reference[0].splitlines()[1:]]
    assert any(float(r[5]) < 0 for r in rows if r[5])   # running backwards: V < 0


def test_traction_clouds_take_the_per_message_path():
    on = Pipeline(PipelineConfig.from_values({"publish_traction": True}))
    off = Pipeline(PipelineConfig.from_values({}))
    assert not batch.supported(on) and batch.supported(off)


def test_an_input_the_batch_does_not_know_takes_the_per_message_path(monkeypatch):
    pipeline = Pipeline(PipelineConfig.from_values({}))
    extra = InputTopic("wheelset/pose", "geometry_msgs/msg/PoseStamped", "pose", None,
                       lambda raw: ())
    monkeypatch.setattr(pipeline, "inputs", lambda: (extra,))
    assert not batch.supported(pipeline)


# ------------------------------------------------------------------------ encoders

def _frames(n, seed=3):
    """Random right-handed frames covering the four branches of the quaternion."""
    rng = np.random.default_rng(seed)
    out = np.zeros((n, 12))
    for k in range(n):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        q *= np.sign(np.linalg.det(q))
        if k % 4 == 1:      # trace < 0, m00 largest: a half turn about x
            q = np.diag([1.0, -1.0, -1.0]) @ q if k % 8 == 1 else np.diag([1.0, -1.0, -1.0])
        elif k % 4 == 2:
            q = np.diag([-1.0, 1.0, -1.0])
        elif k % 4 == 3:
            q = np.diag([-1.0, -1.0, 1.0])
        out[k, 0:3] = rng.normal(size=3)
        out[k, 3:12] = q.T.ravel()   # rows e_x, e_y, e_z
    return out


def test_quaternions_are_the_frames_own_bit_for_bit():
    frames = _frames(64)
    got = encode.quaternions(frames)
    for f, q in zip(frames, got):
        frame = ContactFrame(tuple(f[0:3]), (tuple(f[3:6]), tuple(f[6:9]), tuple(f[9:12])))
        assert tuple(q) == frame.quaternion()


def test_stamped_messages_equal_the_node_encoders():
    stamps = np.array([T0 + 17, T0 + 10**9 + 5, -3 * 10**9 + 7])
    values = np.arange(18, dtype=float).reshape(3, 6) * math.pi
    rows = encode.Stamped("left_contact", 6).encode(stamps, values)
    for s, v, row in zip(stamps.tolist(), values, rows):
        assert row.tobytes() == stamped_doubles(s, "left_contact", tuple(v))


def test_markers_equal_the_node_markers():
    frames = _frames(8)
    stamps = T0 + np.arange(8) * 7 * MS
    fx, fy = np.linspace(-9e3, 9e3, 8), np.linspace(3e3, -1e3, 8)
    m = encode.Markers("wheelset", 1, "right", 1e-5)
    for k, row in enumerate(m.arrows(stamps, frames, fx, fy)):
        f = frames[k]
        frame = ContactFrame(tuple(f[0:3]), (tuple(f[3:6]), tuple(f[6:9]), tuple(f[9:12])))
        assert row.tobytes() == outputs.force_marker_cdr(int(stamps[k]), "wheelset", 1, "right",
                                                         frame, fx[k], fy[k], 1e-5)
    for k, row in enumerate(m.deletions(stamps)):
        assert row.tobytes() == outputs.force_marker_cdr(int(stamps[k]), "wheelset", 1, "right",
                                                         None, 0.0, 0.0, 1e-5)


@pytest.mark.parametrize("window", [97, 1000])
def test_windows_that_end_mid_second_count_the_diagnostics_as_the_per_message_path(
        tmp_path, monkeypatch, varied, window):
    # a window's first run takes the rules to its end at once and each diagnostics counts the
    # verdicts before its place: with windows that end anywhere between two diagnostics (and
    # runs that carry rows not yet counted into the next window) the diagnostics, outputs and
    # counts are still the per-message path's
    from fastsim_ros.replay import bulk
    values = checked(dict(contacts=["left", "right"]))
    reference = replayed(varied, tmp_path / "rosbags", values, "rosbags")
    monkeypatch.setattr(bulk, "WINDOW", window)
    batched = replayed(varied, tmp_path / "auto", values, "auto")
    assert_same(batched, reference)
    diagnostics = reference[1]["/diagnostics"][1]
    assert len(diagnostics) >= 2       # one inside the recording, the last at its end


def _scan_cases():
    """Return ``(name, cdr bytes)`` of patch clouds that take every branch of the adapter loop."""
    hertz = ellipse(6e-3, 4e-3, nx=24, load=6e4)
    egg = samples.semi_ellipses_patch(0.5, 2.0, cells=24, scale=8e-3, load=5e4)
    left = dict(origin=(0.0, 0.75, -WHEEL_RADIUS), normal=contact_normal(0.1, "left"))
    rng = np.random.default_rng(7)
    order = ("pressure", "normal_z", "x", "normal_x", "y", "normal_y", "z")
    cases = [("float32", cdr(cloud_msg(hertz, **left))),
             ("float64", cdr(cloud_msg(hertz, dtype="<f8", **left))),
             ("padded reversed", cdr(cloud_msg(egg, pad=4, reverse_rows=True,
                                               reverse_columns=True, **left))),
             ("field order", cdr(cloud_msg(egg, field_order=order, **left)))]
    noisy = hertz.pressure * (1.0 + 1e-3 * rng.standard_normal(hertz.pressure.shape))
    cases.append(("noisy", cdr(cloud_msg(hertz, pressure=np.maximum(noisy, 0.0), **left))))
    for name, cell, value in (("nan", (12, 12), math.nan), ("inf outside", (0, 0), math.inf),
                              ("negative", (5, 5), -1.0), ("too high", (12, 12), 1e30),
                              ("negative zero", (0, 1), -0.0)):
        p = hertz.pressure.copy()
        p[cell] = value
        cases.append((name, cdr(cloud_msg(hertz, pressure=p, **left))))
    cases.append(("no contact", cdr(cloud_msg(hertz, pressure=0 * hertz.pressure, **left))))
    along_x = cloud_msg(hertz)                   # the normal's z named its x
    for f in along_x.fields:
        f.name = {"normal_x": "normal_z", "normal_z": "normal_x"}.get(f.name, f.name)
    cases.append(("along x", cdr(along_x)))
    one_row = cloud_msg(hertz, **left)          # the middle strip alone
    one_row.height = 1
    one_row.data = one_row.data[12 * one_row.row_step:13 * one_row.row_step]
    cases.append(("one row", cdr(one_row)))
    # NaN in a point's padding: no field is touched, the node's loop decides
    padded = cloud_msg(egg, pad=4, **left)
    raw = bytearray(cdr(padded))
    end = batch.cloud_layout(bytes(raw), "wheelset", 10_000).data_at + len(padded.data)
    raw[end - 4:end] = struct.pack("<f", math.nan)   # the last point's padding
    cases.append(("nan padding", bytes(raw)))
    return cases


def test_the_scan_gives_the_node_adapter_loop_bit_for_bit():
    # the batched scan's loop for finite words (all_finite, adapt_finite) against the node's
    # own patch_kernels.adapt, patch by patch: pressures and every number of its out array,
    # and the largest pressure of each patch the loop passes
    from numba.typed import List
    from fastsim_ros.replay import kernels
    from msg_adapters import patch_kernels
    seen = set()
    for name, raw in _scan_cases():
        layout = batch.cloud_layout(raw, "wheelset", 10_000)
        assert layout is not None and layout.fast, name
        buf = np.frombuffer(raw, dtype=np.uint8)
        one = np.zeros(1, dtype=np.int64)
        pressure = np.full((1, layout.height, layout.cells), -7.0)
        out = np.full((1, patch_kernels.OUT_SIZE), -7.0)
        peak = np.full(1, -7.0)
        kernels.scan_patches(List([buf]), one, one, layout.data_at, layout.width,
                             layout.height, layout.cells, layout.row, layout.step, layout.cols,
                             pressure, out, peak)
        count = (layout.height - 1) * layout.row + layout.cells * layout.step
        words = buf[layout.data_at:layout.data_at + count * layout.width].view(
            np.float32 if layout.width == 4 else np.float64)
        want_p = np.full((layout.height, layout.cells), -7.0)
        want = np.full(patch_kernels.OUT_SIZE, -7.0)
        patch_kernels.adapt(words, layout.height, layout.cells, layout.row, layout.step,
                            layout.cols, want_p, want)
        assert out[0].tobytes() == want.tobytes(), name
        assert pressure[0].tobytes() == want_p.tobytes(), name
        if want[patch_kernels.STATUS] == patch_kernels.OK:   # the plausibility bound's peak
            assert peak[0] == want_p.max(), name
        seen.add((int(want[patch_kernels.STATUS]), bool(kernels.all_finite(words, count))))
    # every status of the loop, on both of its branches where they can be
    ok, nonfinite = patch_kernels.OK, patch_kernels.NONFINITE
    assert {(ok, True), (ok, False), (nonfinite, False), (patch_kernels.NEGATIVE, True),
            (patch_kernels.TOO_HIGH, True), (patch_kernels.NORMAL_ALONG_X, True)} <= seen
