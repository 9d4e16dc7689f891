"""``fastsim_replay`` on the bundled bags: golden outputs, physics, output bags, bad inputs.

The golden outputs ``bags/golden/<name>.csv.gz`` are the replay's own CSV
(``fastsim_replay bags/<name> --params bags/<name>.params.yaml --csv``),
gzipped without a time stamp.  Regenerate them, after a deliberate change of
the physics, with::

    .venv/bin/python test/test_replay.py --write-golden

and say in the commit why they moved.
"""

from __future__ import annotations

import csv
import gzip
import io
import json
import math
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from rosbags.interfaces import QosHistory, QosReliability
from rosbags.rosbag2 import Reader, Writer
from rosbags.rosbag2.enums import StoragePlugin
from rosbags.typesys import Stores, get_typestore

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fastsim_ros import replay  # noqa: E402
from fastsim_ros.replay import batch  # noqa: E402
from fastsim_ros.contact.compiled import MaeSolver  # noqa: E402
from fastsim_ros.contact.normal import hertz_ellipse  # noqa: E402
from fastsim_ros.contact.tables import coefficient_table  # noqa: E402
from fastsim_ros.ros.params import load_params_file  # noqa: E402
from msg_adapters.cdr import read_cloud  # noqa: E402
from msg_adapters.errors import REJECTION_REASONS  # noqa: E402
from msg_adapters.patch import patch_from_cloud  # noqa: E402

BAGS = ROOT / "bags"
GOLDEN = BAGS / "golden"
NAMES = ("hertz_ramp", "semi_ellipses_spin", "flange_shift", "roller_rig", "bad_inputs",
         "mbench_a22", "transient_step", "adhesion_rig", "contaminated_rig")
TYPES = get_typestore(Stores.ROS2_JAZZY)
WRENCH, VECTOR = "geometry_msgs/msg/WrenchStamped", "geometry_msgs/msg/Vector3Stamped"
POSE, DIAG = "geometry_msgs/msg/PoseStamped", "diagnostic_msgs/msg/DiagnosticArray"
MARKERS = "visualization_msgs/msg/MarkerArray"
G, NU, MU = 8.0e10, 0.28, 0.3

# Tolerance of the golden comparison.  On one machine the replay is
# deterministic (compiled kernels, fixed input order, no clock in any
# output), so any difference at all is a change of the physics.  Across
# machines or numba/LLVM versions, float reassociation (vectorised sums in
# the kernels) moves results by about 1e-12 relative; a change of method,
# friction law, grid or table moves them by 1e-4 or more.  So: rtol 1e-9,
# plus an absolute floor of 1e-9 of the column's physical scale (mu N for
# forces, mu N x 1 cm for Mz, 1e-9 for creepages (whose float32 inputs give
# ~1e-8 of noise on a zero creepage, identical on every machine) and
# 1e-9 1/m for spin), so that a value that should be zero may differ by
# rounding.  slip_fraction is a share of cells: any change is at least
# 1/(cells in contact) > 1e-4, far above 1e-9.
RTOL = 1e-9
ATOL = {"xi": 1e-9 * 1e-3, "eta": 1e-9 * 1e-3, "phi": 1e-9, "V": 1e-9, "N": 1e-9 * MU * 6e4,
        "Fx": 1e-9 * MU * 6e4, "Fy": 1e-9 * MU * 6e4, "Mz": 1e-9 * MU * 6e4 * 0.01,
        "slip_fraction": 1e-9}


CSV_HEADER_VALUES = [k for k in replay.CSV_HEADER if k != "contact"]


# ------------------------------------------------------------------------ helpers

def run(args, capsys=None):
    """Run ``fastsim_replay`` in-process; return ``(status, stdout, stderr)``."""
    status = replay.main([str(a) for a in args])
    if capsys is None:
        return status, "", ""
    cap = capsys.readouterr()
    return status, cap.out, cap.err


def read_csv_text(text):
    """Return the rows of a replay CSV as dicts (header checked)."""
    reader = csv.reader(io.StringIO(text))
    header = next(reader)
    assert tuple(header) == replay.CSV_HEADER
    return [dict(zip(header, row)) for row in reader]


def golden_rows(name):
    """Return the golden rows of a bag."""
    with gzip.open(GOLDEN / f"{name}.csv.gz", "rt", encoding="utf-8", newline="") as f:
        return read_csv_text(f.read())


def rows_of(path, contact=None):
    """Return the rows of an output CSV (of one contact)."""
    rows = read_csv_text(Path(path).read_text(encoding="utf-8"))
    return [r for r in rows if contact is None or r["contact"] == contact]


def column(rows, name):
    """Return one column as floats (blank: NaN)."""
    return np.array([float(r[name]) if r[name] != "" else math.nan for r in rows])


def plain(msg):
    """Return a rosbags message as nested plain values (for equality)."""
    if hasattr(msg, "__dataclass_fields__"):
        return {k: plain(getattr(msg, k)) for k in msg.__dataclass_fields__}
    if isinstance(msg, np.ndarray):
        return msg.tolist()
    if isinstance(msg, (list, tuple)):
        return [plain(m) for m in msg]
    return msg


def bag_contents(path):
    """Return ``{topic: (type, [(log_ns, message), ...])}``, the connections and custom data."""
    out = {}
    with Reader(path) as reader:
        conns = {c.topic: c for c in reader.connections}
        for conn, log_ns, raw in reader.messages():
            msg = TYPES.deserialize_cdr(raw, conn.msgtype)
            out.setdefault(conn.topic, (conn.msgtype, []))[1].append((log_ns, msg))
        meta = yaml.safe_load((Path(path) / "metadata.yaml").read_text())
    return out, conns, meta["rosbag2_bagfile_information"]


def final_counts(contents, contact):
    """Return the counts of a contact in the bag's last diagnostics array."""
    _, diags = contents["/diagnostics"]
    status = next(s for s in diags[-1][1].status if s.name == f"fastsim: {contact}")
    return {kv.key: kv.value for kv in status.values}


def decoded_without_timing(contents):
    """Return decoded contents minus the wall-clock solve times of the diagnostics."""
    result = {}
    for topic, (msgtype, items) in contents.items():
        values = []
        for log_ns, msg in items:
            d = plain(msg)
            if msgtype == DIAG:
                for s in d["status"]:
                    s["values"] = [kv for kv in s["values"]
                                   if not kv["key"].startswith("solve_time")]
            values.append((log_ns, d))
        result[topic] = (msgtype, values)
    return result


# ------------------------------------------------------------------------ fixtures

@pytest.fixture(scope="module")
def replayed(tmp_path_factory):
    """Replay every bundled bag with its params file (CSV on); return the output directory."""
    out = tmp_path_factory.mktemp("replayed")
    for name in NAMES:
        status, _, _ = run([BAGS / name, "-o", out, "--params", BAGS / f"{name}.params.yaml",
                            "--csv"])
        assert status == 0, name
    return out


@pytest.fixture(scope="module")
def contents(replayed):
    """Return the decoded output bag of each bundled bag."""
    return {name: bag_contents(replayed / name) for name in NAMES}


# ------------------------------------------------------------------------ (a) golden

@pytest.mark.parametrize("name", NAMES)
def test_replay_matches_golden(replayed, name):
    got, want = rows_of(replayed / f"{name}.csv"), golden_rows(name)
    assert len(got) == len(want)
    for g, w in zip(got, want):
        for key in ("stamp_ns", "contact", "method", "friction_law"):
            assert g[key] == w[key]
        for key, atol in ATOL.items():
            assert (g[key] == "") == (w[key] == ""), (key, g, w)
            if w[key] != "":
                assert float(g[key]) == pytest.approx(float(w[key]), rel=RTOL, abs=atol), \
                    (key, g["stamp_ns"], g["contact"])


# ------------------------------------------------------------------------ (a) physics

def test_hertz_ramp_linear_limit_is_kalkers_c11(replayed):
    # Fx = -G a b C11 xi in full adhesion (Kalker's linear theory, the patch's
    # Hertzian semi-axes).  FastSim on the 24 x 24 grid of this bag sits 3.8%
    # below C11 (its discretisation error along x, ~1/n); 5% is the bound.
    hz = hertz_ellipse(0.46, 0.3, 6e4, shear_modulus=G, nu=NU)
    c11 = coefficient_table(NU)("C11", hz.a / hz.b)
    for contact in ("left", "right"):
        rows = rows_of(replayed / "hertz_ramp.csv", contact)
        xi, fx, slip = column(rows, "xi"), column(rows, "Fx"), column(rows, "slip_fraction")
        linear = (xi > 1e-5) & (slip == 0.0)
        assert linear.sum() >= 5
        ratio = fx[linear] / (-G * hz.a * hz.b * c11 * xi[linear])
        assert np.all(np.abs(ratio - 1.0) < 0.05), ratio
        assert np.ptp(ratio) < 1e-3  # linear: one slope over the whole range


def test_hertz_ramp_saturates_at_mu_n_and_brakes(replayed):
    for contact in ("left", "right"):
        rows = rows_of(replayed / "hertz_ramp.csv", contact)
        xi, fx, fy, n = (column(rows, k) for k in ("xi", "Fx", "Fy", "N"))
        assert n == pytest.approx(6e4, rel=1e-5)
        # the bound: never above mu N (traction bound "given": |tau| <= mu p)
        assert np.all(np.hypot(fx, fy) <= MU * n * (1 + 1e-9))
        # braking (xi > 0) gives Fx < 0, the force grows with xi and saturates
        braking = xi > 1e-6
        assert np.all(fx[braking] < 0.0)
        assert np.all(np.diff(-fx[braking]) >= -1e-6 * MU * 6e4)
        held = xi > 0.99e-2
        assert held.sum() >= 40
        assert np.all(-fx[held] / (MU * n[held]) > 0.98)
        assert np.abs(fy).max() < 1e-6 * MU * 6e4  # no lateral creepage, no lateral force


def test_semi_ellipses_spin_gives_fx_mirrored_on_the_two_wheels(replayed):
    left = rows_of(replayed / "semi_ellipses_spin.csv", "left")
    right = rows_of(replayed / "semi_ellipses_spin.csv", "right")
    phi_l, phi_r = column(left, "phi"), column(right, "phi")
    fx_l, fx_r = column(left, "Fx"), column(right, "Fx")
    fy_l, fy_r = column(left, "Fy"), column(right, "Fy")
    assert np.abs(column(left, "xi")).max() < 1e-6 and np.abs(column(left, "eta")).max() < 1e-6
    spinning = np.abs(phi_l) > 0.05
    assert spinning.sum() > 200
    assert phi_l.min() == pytest.approx(-0.847, abs=2e-3)
    assert phi_r == pytest.approx(-phi_l, abs=1e-9)
    # spin alone gives Fx on this asymmetric area (it is ~0.2 N at phi = 0)
    assert np.all(np.abs(fx_l[spinning]) > 0.01 * MU * 6e4)
    # mirrored patch (y -> -y) under mirrored spin (phi -> -phi): Fx is the same, Fy and
    # Mz change sign.  (Opposite Fx comes with opposite spin on the same patch: below.)
    assert fx_r == pytest.approx(fx_l, rel=1e-9, abs=1e-6)
    assert fy_r == pytest.approx(-fy_l, rel=1e-9, abs=1e-6)
    # |Fx| grows with |phi| until the lateral force takes the adhesion (Fx peaks near
    # |phi| = 0.3 1/m, then falls to 0.6 of its peak at 0.85 1/m as Fy nears 0.45 mu N)
    order = np.argsort(np.abs(phi_l))
    small = order[np.abs(phi_l[order]) < 0.25]
    assert np.all(np.diff(np.abs(fx_l[small])) >= -1e-6)
    assert np.abs(fx_l[small[-1]]) > 2.5 * np.abs(fx_l[small[np.abs(phi_l[small]) > 0.05][0]])
    assert np.all(np.hypot(fx_l, fy_l) <= MU * column(left, "N") * (1 + 1e-9))


def test_spin_induced_fx_is_odd_in_phi_on_one_patch():
    # the same (left) patch of the bag, solved at +-phi: Fx changes sign
    with Reader(BAGS / "semi_ellipses_spin") as reader:
        conn = next(c for c in reader.connections if c.topic == "/contact/left/patch")
        raw = next(r for _, _, r in reader.messages([conn]))
    patch = patch_from_cloud(read_cloud(raw), max_cells=16384)
    solver = MaeSolver(NU, G)
    fx = [solver.solve_arrays(patch.pressure, patch.x0, patch.y0, patch.dx, patch.dy,
                              0.0, 0.0, phi, MU).fx for phi in (-0.4, 0.4)]
    assert abs(fx[0]) > 0.03 * MU * 6e4
    assert fx[1] == pytest.approx(-fx[0], rel=1e-9)


def test_flange_shift_two_point_contact(replayed):
    # the profile pipeline's patches (S1002 on UIC60, 20 kN per wheel, the shift to the
    # left held 0.4 s at each of ten values: treads, the left gauge corner, the flange)
    rows = rows_of(replayed / "flange_shift.csv")
    t0 = int(rows[0]["stamp_ns"])
    names = ("left", "right", "left_flange", "right_flange")
    by = {c: [r for r in rows if r["contact"] == c] for c in names}
    assert all(len(v) == 400 for v in by.values())
    t = (np.array([int(r["stamp_ns"]) for r in by["left"]]) - t0) * 1e-9
    hold = np.minimum((t / 0.4).astype(int), 9)
    n = {c: column(by[c], "N") for c in names}
    # the right wheel keeps its tread only, carrying its 20 kN throughout
    assert np.all(n["right_flange"] == 0.0)
    assert n["right"] == pytest.approx(2e4, rel=2e-3)
    # two-point contact from 4.75 to 5.05 mm (holds 3..6): the left wheel's load passes
    # from the tread to the gauge corner, their vertical parts carrying its 20 kN
    two_point = (hold >= 3) & (hold <= 6)
    assert np.all(n["left_flange"][two_point] > 0.0)
    assert np.all(n["left_flange"][~two_point] == 0.0)
    assert np.all(np.isnan(column(by["left_flange"], "xi")[~two_point]))
    shares = [float(np.mean(n["left_flange"][hold == k])) for k in (3, 4, 5, 6)]
    assert shares == sorted(shares) and shares[0] < 5e3 and shares[-1] > 15e3
    total = n["left"][two_point] + n["left_flange"][two_point]
    assert total == pytest.approx(2e4, rel=0.05)  # contact angles 0.1 and 0.3 rad
    # the flange (holds 8, 9): one patch at 1.1-1.2 rad carries 30-56 kN of normal load
    flange = hold >= 8
    assert np.all((n["left"][flange] > 3e4) & (n["left"][flange] < 6e4))
    # traction on the left (its rolling radius grows: xi < 0, Fx > 0), braking on the
    # right (xi > 0, Fx < 0), never beyond mu N
    moving = hold >= 1
    assert np.all(column(by["left"], "xi")[moving] < 0) and np.all(
        column(by["left"], "Fx")[moving] > 0)
    assert np.all(column(by["right"], "xi")[moving] > 0) and np.all(
        column(by["right"], "Fx")[moving] < 0)
    for c in ("left", "right"):
        f = np.hypot(column(by[c], "Fx"), column(by[c], "Fy"))
        assert np.all(f <= MU * n[c] * (1 + 1e-9))


def adhesion_truth():
    """Return adhesion_rig's truth (its params file's ``truth`` section) as a mu_s of t (s)."""
    truth = yaml.safe_load((BAGS / "adhesion_rig.params.yaml").read_text())
    truth = truth["truth"]["ros__parameters"]
    steps = list(zip(truth["steps_from"], truth["mu_static"]))
    spells = list(zip(truth["linear_from"], truth["linear_to"]))
    return truth, steps, spells


def test_adhesion_rig_estimates_the_exact_theorys_friction(contents):
    """The replay's friction/estimate against the truth the bag was made from.

    Issue 28's target: beyond the linear range mu within 2% of the truth
    within 0.2 s of each step and the 2-sigma band covering it at least 95%
    of the time; in the linear range the estimate moves less than 1% while
    sigma grows.  Measured by the exact theory: the method's own force at
    the knee of the curve is 3-6% of mu N off it (3-8% of mu,
    docs/validation_estimation.md), and after the wet -> dry step at 3 s the
    creepage stays at the dry knee for half a second; the estimator's model
    carries the knee factor (fastsim_ros/contact/knee.py), which brings it
    within about 1% of mu N of the exact theory there.
    """
    truth, steps, spells = adhesion_truth()
    _, msgs = contents["adhesion_rig"][0]["/friction/estimate"]
    t0 = msgs[0][1].header.stamp.sec * 10**9 + msgs[0][1].header.stamp.nanosec - 2_500_000
    t = np.array([(m.header.stamp.sec * 10**9 + m.header.stamp.nanosec - t0) * 1e-9
                  for _, m in msgs])
    mu = np.array([m.vector.x for _, m in msgs])
    sigma = np.array([m.vector.y for _, m in msgs])
    assert all(m.header.frame_id == "wheelset" for _, m in msgs) and len(msgs) == 400
    true = np.array([[m for start, m in steps if x >= start][-1] for x in t])
    linear = np.array([any(a <= x < b for a, b in spells) for x in t])
    error = np.abs(mu - true) / true
    covered = np.abs(mu - true) <= 2.0 * sigma
    assert covered[~linear].mean() >= 0.95 and covered.mean() >= 0.95
    ends = [start for start, _ in steps[1:]] + [t[-1] + 1.0]
    for (start, mu_s), end in zip(steps, ends):
        settled = (t >= start + 0.2) & (t < end) & ~linear
        assert settled.sum() > 50 and error[settled].max() < 0.02, start
    for a, b in spells:
        inside = np.nonzero((t >= a) & (t < b))[0]
        before = inside[0] - 1
        mu0 = mu[before] if before >= 0 else 0.3  # the params file's start
        assert abs(mu[inside[-1]] - mu0) < 0.01 * mu0
        assert np.all(np.diff(sigma[inside]) > 0.0)
    assert truth["solver"] == "exact" and truth["friction_law"] == "exponential"


def contaminated_truth():
    """Return contaminated_rig's truth (its params file's ``truth`` section)."""
    truth = yaml.safe_load((BAGS / "contaminated_rig.params.yaml").read_text())
    return truth["truth"]["ros__parameters"]


def stamps_s(msgs, t0):
    """Return the header stamps (s after ``t0``, ns) of ``(raw, message)`` pairs."""
    return np.array([(m.header.stamp.sec * 10**9 + m.header.stamp.nanosec - t0) * 1e-9
                     for _, m in msgs])


def test_contaminated_rig_estimates_friction_and_the_slope_reduction(contents):
    """The replay's friction/estimate and friction/slope_estimate against the bag's truth.

    The measured wrench is the modified FastSim's (the estimator's own
    model) with mu_s and k0 stepping at different times and a 250 N load
    cell; the creepage sweeps the linear range (k0 observable), the knee
    (both) and full slip (mu_s) every 0.2 s.  From 0.2 s after each step
    (and after the spell of pure rolling) to the next: mu_s within 2% and
    k0 within 5% of the truth, their 2-sigma bands covering it at least 95%
    of the time.  In pure rolling neither is observable: both hold to the
    bit while their sigmas grow.
    """
    truth = contaminated_truth()
    out = contents["contaminated_rig"][0]
    _, friction = out["/friction/estimate"]
    _, slope = out["/friction/slope_estimate"]
    assert len(friction) == len(slope) == 400
    assert all(m.header.frame_id == "wheelset" for _, m in friction + slope)
    t0 = friction[0][1].header.stamp.sec * 10**9 + friction[0][1].header.stamp.nanosec \
        - 2_500_000
    t = stamps_s(friction, t0)
    assert np.array_equal(t, stamps_s(slope, t0))
    mu, sigma = (np.array([m.vector.x for _, m in friction]),
                 np.array([m.vector.y for _, m in friction]))
    k0, sigma_k0, rho = (np.array([m.vector.x for _, m in slope]),
                         np.array([m.vector.y for _, m in slope]),
                         np.array([m.vector.z for _, m in slope]))
    true_mu = np.array([[v for a, v in zip(truth["mu_from"], truth["mu_static"]) if x >= a][-1]
                        for x in t])
    true_k0 = np.array([[v for a, v in zip(truth["k0_from"], truth["k0"]) if x >= a][-1]
                        for x in t])
    events = sorted(set(truth["mu_from"]) | set(truth["k0_from"]) | set(truth["rolling_to"]))
    settled = np.array([x >= max(e for e in events if e <= x) + 0.2 for x in t])
    assert settled.sum() >= 250
    assert np.max(np.abs(mu - true_mu)[settled] / true_mu[settled]) < 0.02
    assert np.max(np.abs(k0 - true_k0)[settled] / true_k0[settled]) < 0.05
    assert np.mean(np.abs(mu - true_mu)[settled] <= 2.0 * sigma[settled]) >= 0.95
    assert np.mean(np.abs(k0 - true_k0)[settled] <= 2.0 * sigma_k0[settled]) >= 0.95
    assert np.all(np.abs(rho) <= 1.0)
    for a, b in zip(truth["rolling_from"], truth["rolling_to"]):
        inside = np.nonzero((t >= a) & (t < b))[0]
        assert len(inside) >= 25
        assert np.all(mu[inside] == mu[inside[0]]) and np.all(k0[inside] == k0[inside[0]])
        assert np.all(np.diff(sigma[inside]) > 0.0) and np.all(np.diff(sigma_k0[inside]) > 0.0)
    assert truth["solver"] == "mae_calibrated" and truth["friction_law"] == "constant"


def test_roller_rig_is_served_with_its_rail_twist(replayed):
    rows = rows_of(replayed / "roller_rig.csv", "wheel")
    assert len(rows) == 400
    xi, fx, v = column(rows, "xi"), column(rows, "Fx"), column(rows, "V")
    assert np.all(np.isfinite(xi))
    assert v == pytest.approx(15.0, rel=0.01)  # the roller's surface speed, not 0 (no rail)
    assert xi.min() == pytest.approx(-5e-3, rel=1e-3) and xi.max() == pytest.approx(5e-3,
                                                                                    rel=1e-3)
    moving = np.abs(xi) > 1e-5
    assert np.all(np.sign(fx[moving]) == -np.sign(xi[moving]))
    assert np.abs(fx[np.abs(xi) < 1e-7]).max() < 1.0  # passes zero at xi = 0


def test_roller_rig_without_its_params_takes_its_contact_from_the_bag(tmp_path, capsys):
    status, out, err = run([BAGS / "roller_rig", "-o", tmp_path, "--csv"], capsys)
    assert status == 0 and err == ""
    assert "contacts found in the bag (no --params): wheel\n" in out
    assert "wheel: 400 patches, 400 wrenches (400 solved" in out
    meta = yaml.safe_load((tmp_path / "roller_rig" / "metadata.yaml").read_text())
    stored = json.loads(meta["rosbag2_bagfile_information"]["custom_data"][replay.PARAMETERS_KEY])
    assert stored["contacts"] == ["wheel"] and stored["method"] == "mae_calibrated"
    # the rail twist is used when fresh (rail_twist_required only makes it compulsory)
    assert column(rows_of(tmp_path / "roller_rig.csv"), "V") == pytest.approx(15.0, rel=0.01)


def test_roller_rig_with_other_contacts_solves_nothing_and_warns(tmp_path, capsys):
    params = tmp_path / "params.yaml"
    params.write_text("fastsim:\n  ros__parameters:\n    contacts: [left, right]\n")
    status, out, err = run([BAGS / "roller_rig", "-o", tmp_path / "out", "--params", params],
                           capsys)
    assert status == 0
    assert "no patch topic of the configured contacts (left, right)" in err
    assert "left: 0 patches" in out


# ------------------------------------------------------------------------ namespaces

def _namespaced_copy(source, target, renames):
    """Write ``source`` again with its topics renamed (``renames``: old -> new name)."""
    with Reader(source) as reader, \
            Writer(target, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conns = {c.id: writer.add_connection(renames.get(c.topic, c.topic), c.msgtype,
                                             typestore=TYPES,
                                             offered_qos_profiles=c.ext.offered_qos_profiles)
                 for c in reader.connections}
        for conn, log_ns, raw in reader.messages():
            writer.write(conns[conn.id], log_ns, raw)


def _first_message_body(data: bytes) -> int:
    """Return the file offset of the first message record's body in an uncompressed chunk."""
    from mcap.reader import make_reader
    chunk = make_reader(io.BytesIO(bytes(data))).get_summary().chunk_indexes[0]
    assert chunk.compression == ""
    at = chunk.chunk_start_offset + 1 + 8 + 8 + 8 + 8 + 4   # opcode, length, times, size, crc
    at += 4 + int.from_bytes(data[at:at + 4], "little") + 8  # compression string, records size
    while data[at] != 0x05:                                  # schema and channel records
        at += 1 + 8 + int.from_bytes(data[at + 1:at + 9], "little")
    return at + 1 + 8


@pytest.mark.parametrize("offset, value, match", [
    (0, (74).to_bytes(2, "little"), "a message on channel 74, which the file does not define"),
    (6, (1).to_bytes(8, "little"), "a message logged outside the chunk's time range")])
def test_a_corrupt_chunk_without_crcs_is_a_bad_input(tmp_path, capsys, offset, value, match):
    """A chunk that decodes but names another channel or time: one line, exit 2, nothing left.

    rosbags writes no chunk CRCs: such a corruption decodes.  A message on a
    channel the file does not define ended the replay with an internal error
    (exit 1); a log time moved out of its chunk was replayed as an old stamp.
    """
    bag = tmp_path / "plain"
    _namespaced_copy(BAGS / "hertz_ramp", bag, {})  # uncompressed chunks, CRC 0
    f = bag / "plain.mcap"
    data = bytearray(f.read_bytes())
    at = _first_message_body(data) + offset         # channel id u16, sequence u32, log time
    data[at:at + len(value)] = value
    f.write_bytes(bytes(data))
    out = tmp_path / "out"
    status, stdout, err = run([bag, "-o", out], capsys)
    assert status == 2
    (line,) = err.splitlines()
    assert "plain" in line and match in line
    assert not any(out.iterdir()) if out.exists() else True


@pytest.fixture(scope="module")
def rig1_front(tmp_path_factory):
    """hertz_ramp's left wheel recorded under /rig1 as contact ``front`` (twists relative)."""
    path = tmp_path_factory.mktemp("rig1") / "rig1_front"
    _namespaced_copy(BAGS / "hertz_ramp", path, {
        "/contact/left/patch": "/rig1/contact/front/patch",
        "/contact/right/patch": "/contact/right/patch",  # outside the namespace: copied only
        "/wheelset/twist": "rig1/wheelset/twist"})        # relative: in the root namespace
    return path


def test_namespaced_recording_with_a_front_contact_replays_without_params(tmp_path, capsys,
                                                                          rig1_front):
    out = tmp_path / "out"
    status, stdout, err = run([rig1_front, "-o", out, "--namespace", "/rig1", "--csv"], capsys)
    assert status == 0 and err == ""
    assert "contacts found in the bag (no --params): front; namespace /rig1\n" in stdout
    assert "front: 400 patches, 400 wrenches (400 solved" in stdout
    assert "twists: 800 wheelset" in stdout
    topics, _, meta = bag_contents(out / "rig1_front")
    for topic in ("/rig1/contact/front/wrench", "/rig1/contact/front/creepage",
                  "/rig1/wheelset/wrench"):
        assert len(topics[topic][1]) == 400, topic
    assert topics["/rig1/contact/front/wrench"][1][0][1].header.frame_id == "front_contact"
    assert "/rig1/contact/markers" in topics and "/diagnostics" in topics
    assert not any(t.startswith("/contact/") and not t.endswith("/patch") for t in topics)
    assert len(topics["/contact/right/patch"][1]) == 400  # copied, not solved
    stored = json.loads(meta["custom_data"][replay.PARAMETERS_KEY])
    assert stored["contacts"] == ["front"]
    # the same physics as hertz_ramp's left wheel replayed with its own name, defaults
    params = tmp_path / "left.yaml"
    params.write_text("fastsim:\n  ros__parameters:\n    contacts: [left]\n")
    assert run([BAGS / "hertz_ramp", "-o", tmp_path / "plain", "--csv",
                "--params", params])[0] == 0
    got, want = rows_of(out / "rig1_front.csv"), rows_of(tmp_path / "plain" / "hertz_ramp.csv")
    assert len(got) == len(want) == 400
    for g, w in zip(got, want):
        assert g["contact"] == "front" and w["contact"] == "left"
        assert [g[k] for k in CSV_HEADER_VALUES] == [w[k] for k in CSV_HEADER_VALUES]


def test_namespaced_recording_in_the_root_namespace(tmp_path, capsys, rig1_front):
    # in /, the one patch topic is /contact/right/patch; the twists are under /rig1
    status, out, err = run([rig1_front, "-o", tmp_path], capsys)
    assert status == 0 and err == ""
    assert "contacts found in the bag (no --params): right\n" in out
    assert "right: 400 patches, 0 wrenches (0 solved, 0 no_contact), rejected 400 " \
        "(no_kinematics 400)" in out


def test_namespace_without_patch_topics_warns(tmp_path, capsys):
    status, out, err = run([BAGS / "hertz_ramp", "-o", tmp_path, "--namespace", "rig2"], capsys)
    assert status == 0
    assert "no patch topic under /rig2 (no --params: the contacts are those with a " \
        "/rig2/contact/<name>/patch topic)" in err
    # where the bag's patch topics are, for the flag that replays them
    assert "the bag's patch topics are under / (--namespace /)" in err
    assert "left: 0 patches" in out
    assert "nan" not in out  # a contact with nothing solved has no solve times


def test_a_namespaced_recording_replayed_without_its_namespace_names_it(tmp_path, capsys):
    bag = tmp_path / "rig1_only"
    _namespaced_copy(BAGS / "hertz_ramp", bag, {
        "/contact/left/patch": "/rig1/contact/left/patch",
        "/contact/right/patch": "/rig1/contact/right/patch",
        "/wheelset/twist": "/rig1/wheelset/twist"})
    status, out, err = run([bag, "-o", tmp_path / "out"], capsys)
    assert status == 0
    assert "nothing solved (are --params and --namespace right?); the bag's patch topics " \
        "are under /rig1 (--namespace /rig1)" in err


@pytest.mark.parametrize("text, resolved", [("rig1", "/rig1"), ("/rig1", "/rig1"), ("/", "/"),
                                            ("/a/b_2", "/a/b_2"), ("_x", "/_x")])
def test_namespace_flag_is_made_absolute(text, resolved):
    assert replay.parser().parse_args(["in", "-o", "out", "--namespace", text]).namespace \
        == resolved


def test_topics_resolve_as_ros_resolves_them():
    assert replay.resolve("contact/left/patch") == "/contact/left/patch"
    assert replay.resolve("contact/left/patch", "/rig1") == "/rig1/contact/left/patch"
    assert replay.resolve("/diagnostics", "/rig1") == "/diagnostics"
    assert replay.bag_contacts(["/rig1/contact/front/patch", "rig1/contact/rear/patch",
                                "/contact/left/patch", "/rig1/contact/a/b/patch",
                                "/rig1/contact/9x/patch", "/rig1/contact/front/patch"],
                               "/rig1") == ("front", "rear")


# ------------------------------------------------------------------------ (b) bad inputs

def test_bad_inputs_rejections_by_reason(contents, replayed):
    expected = yaml.safe_load((BAGS / "bad_inputs.expected.yaml").read_text())["contacts"]
    topics, _, _ = contents["bad_inputs"]
    for contact, want in expected.items():
        counts = final_counts(topics, contact)
        assert int(counts["solved"]) == want["served"]
        assert int(counts["no_contact"]) == want["no_contact"]
        for reason in REJECTION_REASONS:
            assert int(counts[f"rejected/{reason}"]) == want["rejected"][reason], reason
        # a wrench for each served or empty patch, none for a rejected one
        _, wrenches = topics[f"/contact/{contact}/wrench"]
        assert len(wrenches) == want["served"] + want["no_contact"]
        assert len(topics[f"/contact/{contact}/creepage"][1]) == want["served"]
        stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for _, m in wrenches]
        assert stamps == sorted(set(stamps))  # no wrench for the old_stamp patches
        forces = np.array([[m.wrench.force.x, m.wrench.force.y, m.wrench.force.z,
                            m.wrench.torque.z] for _, m in wrenches])
        assert np.all(np.isfinite(forces))
        assert len(rows_of(replayed / "bad_inputs.csv", contact)) == len(wrenches)


def test_summary_reports_rejections(tmp_path, capsys):
    status, out, _ = run([BAGS / "bad_inputs", "-o", tmp_path, "--params",
                          BAGS / "bad_inputs.params.yaml"], capsys)
    assert status == 0
    assert "bad_inputs: 1140 messages in" in out
    assert ("left: 300 patches, 234 wrenches (224 solved, 10 no_contact), rejected 66 "
            "(nonfinite 3, negative_pressure 2, irregular_grid 2, missing_field 2, "
            "wrong_frame 2, old_stamp 2, no_kinematics 10, stale_kinematics 15, "
            "standstill 20, too_large 2, degenerate 2, implausible 4)") in out
    assert "x real time" in out and "solve p50" in out


# ------------------------------------------------------------------------ (d) output bags

@pytest.mark.parametrize("name", NAMES)
def test_output_bag_opens_with_types_and_counts(contents, name):
    topics, conns, meta = contents[name]
    params = load_params_file(BAGS / f"{name}.params.yaml")
    stored = json.loads(meta["custom_data"][replay.PARAMETERS_KEY])
    assert stored == json.loads(json.dumps(params))
    assert meta["version"] == 9 and meta["storage_identifier"] == "mcap"
    # the inputs, copied with their types and counts
    with Reader(BAGS / name) as reader:
        for conn in reader.connections:
            msgtype, items = topics[conn.topic]
            assert msgtype == conn.msgtype and len(items) == conn.msgcount
    types = replay.output_topics(tuple(params["contacts"]))
    for contact in params["contacts"]:
        counts = final_counts(topics, contact)
        solved, empty = int(counts["solved"]), int(counts["no_contact"])
        assert topics[f"/contact/{contact}/wrench"][0] == WRENCH
        assert len(topics[f"/contact/{contact}/wrench"][1]) == solved + empty
        if solved:
            assert topics[f"/contact/{contact}/creepage"][0] == VECTOR
            assert len(topics[f"/contact/{contact}/creepage"][1]) == solved
            assert topics[f"/contact/{contact}/frame"][0] == POSE
            assert 1 <= len(topics[f"/contact/{contact}/frame"][1]) <= solved
        assert f"/contact/{contact}/traction" not in topics  # publish_traction: false
    for topic, (msgtype, _) in topics.items():
        rel = topic if topic == "/diagnostics" else topic[1:]
        if rel in types:
            assert types[rel] == msgtype
            # what the node offers: reliable, keep last 10
            qos = conns[topic].ext.offered_qos_profiles[0]
            assert qos.reliability == QosReliability.RELIABLE
            assert qos.history == QosHistory.KEEP_LAST and qos.depth == 10
    assert topics["/contact/markers"][0] == MARKERS
    assert topics["/wheelset/wrench"][0] == WRENCH
    # diagnostics each whole second of log time, and one at the end
    duration = meta["duration"]["nanoseconds"] * 1e-9
    assert len(topics["/diagnostics"][1]) == math.floor(duration) + 1
    # every output is logged at its patch's log time = its header stamp here
    for _, m in topics[f"/contact/{params['contacts'][0]}/wrench"][1][:5]:
        assert m.header.frame_id == f"{params['contacts'][0]}_contact"


def test_wrench_messages_equal_the_csv(contents, replayed):
    topics, _, _ = contents["hertz_ramp"]
    rows = rows_of(replayed / "hertz_ramp.csv", "left")
    wrenches = topics["/contact/left/wrench"][1]
    for (log_ns, m), r in zip(wrenches, rows):
        assert log_ns == int(r["stamp_ns"])
        assert (m.wrench.force.x, m.wrench.force.y, m.wrench.force.z, m.wrench.torque.z) == \
            (float(r["Fx"]), float(r["Fy"]), float(r["N"]), float(r["Mz"]))


def test_no_contact_rows_are_zero_wrench_and_blank_creepage(replayed):
    rows = [r for r in rows_of(replayed / "bad_inputs.csv") if r["N"] == "0.0"]
    assert len(rows) == 14
    for r in rows:
        assert (r["Fx"], r["Fy"], r["Mz"]) == ("0.0", "0.0", "0.0")
        assert r["xi"] == r["eta"] == r["phi"] == r["V"] == r["slip_fraction"] == ""


def test_lone_mcap_replays_like_its_directory(tmp_path, replayed):
    status, _, _ = run([BAGS / "hertz_ramp" / "hertz_ramp.mcap", "-o", tmp_path, "--csv",
                        "--params", BAGS / "hertz_ramp.params.yaml"])
    assert status == 0
    assert (tmp_path / "hertz_ramp.csv").read_text() == (replayed / "hertz_ramp.csv").read_text()
    got, _, _ = bag_contents(tmp_path / "hertz_ramp")
    want, _, _ = bag_contents(replayed / "hertz_ramp")
    assert decoded_without_timing(got) == decoded_without_timing(want)


def test_plot_is_written(tmp_path):
    status, _, _ = run([BAGS / "flange_shift", "-o", tmp_path, "--plot", "--params",
                        BAGS / "flange_shift.params.yaml"])
    assert status == 0
    png = (tmp_path / "flange_shift.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["flange_shift", "flange_shift.png"]


def test_jobs_2_equals_jobs_1(tmp_path):
    inputs = [BAGS / n for n in ("hertz_ramp", "semi_ellipses_spin", "bad_inputs")]
    for jobs in (1, 2):
        assert run(inputs + ["-o", tmp_path / f"j{jobs}", "--csv", "--jobs", jobs])[0] == 0
    for path in inputs:
        a, b = tmp_path / "j1", tmp_path / "j2"
        assert (a / f"{path.name}.csv").read_text() == (b / f"{path.name}.csv").read_text()
        assert decoded_without_timing(bag_contents(a / path.name)[0]) == \
            decoded_without_timing(bag_contents(b / path.name)[0])


# ------------------------------------------------------------------------ (e) bad inputs

def _bad_inputs(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    truncated = src / "truncated"
    shutil.copytree(BAGS / "hertz_ramp", truncated)
    (truncated / "hertz_ramp.mcap").rename(truncated / "truncated.mcap")
    meta = (truncated / "metadata.yaml").read_text().replace("hertz_ramp.mcap",
                                                             "truncated.mcap")
    (truncated / "metadata.yaml").write_text(meta)
    mcap = truncated / "truncated.mcap"
    data = mcap.read_bytes()
    mcap.write_bytes(data[:len(data) // 2])
    lone = src / "cut.mcap"
    lone.write_bytes((BAGS / "roller_rig" / "roller_rig.mcap").read_bytes()[:30_000])
    garbage = src / "garbage.mcap"
    garbage.write_bytes(bytes(range(256)) * 40)
    empty_file = src / "nothing.mcap"
    empty_file.write_bytes(b"")
    not_a_bag = src / "notabag"
    not_a_bag.mkdir()
    (not_a_bag / "notes.txt").write_text("hello")
    empty_bag = src / "emptybag"
    with Writer(empty_bag, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        w.add_connection("/wheelset/twist", "geometry_msgs/msg/TwistStamped", typestore=TYPES)
    return [truncated, lone, garbage, empty_file, not_a_bag, empty_bag, src / "missing"]


def test_bad_inputs_exit_2_and_leave_nothing_while_a_good_one_completes(tmp_path, capsys):
    bad = _bad_inputs(tmp_path)
    out = tmp_path / "out"
    status, stdout, err = run(bad[:3] + [BAGS / "hertz_ramp"] + bad[3:] +
                              ["-o", out, "--csv", "--plot"], capsys)
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == len(bad)
    for path, line in zip(bad, lines):
        assert line.startswith(f"fastsim_replay: {path}"), line
    assert "Traceback" not in err
    assert "empty bag" in lines[5] and "no such file" in lines[6]
    assert sorted(p.name for p in out.iterdir()) == ["hertz_ramp", "hertz_ramp.csv",
                                                     "hertz_ramp.png"]
    assert "hertz_ramp: 1600 messages in" in stdout


def test_a_topic_without_a_usable_definition_is_one_line_naming_the_bag(tmp_path, capsys):
    """A custom type whose definition the bag garbles: exit 2, the bag's path on its line.

    The problem is found at a topic, below the file's level; its line names
    the bag as well as the topic and the type, so that among several inputs
    the one that failed is known.
    """
    bag = tmp_path / "custom"
    with Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        c = w.add_connection("/weird", "my_pkg/msg/Foo", msgdef="this is not a definition",
                             rihs01="RIHS01_" + "0" * 64)
        w.write(c, 1, bytes(8))
    # as a writer that knows no hash leaves it: the definition is then all there is
    meta = bag / "metadata.yaml"
    meta.write_text(re.sub(r"type_description_hash:\s*RIHS01_0+", 'type_description_hash: ""',
                           meta.read_text()))
    out = tmp_path / "out"
    status, stdout, err = run([bag, BAGS / "hertz_ramp", "-o", out], capsys)
    assert status == 2
    line = err.strip().splitlines()[-1]
    assert line.startswith(f"fastsim_replay: {bag}: topic /weird: no usable definition of "
                           "type my_pkg/msg/Foo"), line
    assert "Traceback" not in err
    assert sorted(p.name for p in out.iterdir()) == ["hertz_ramp"]


def test_truncated_bag_from_the_console_script(tmp_path):
    truncated = _bad_inputs(tmp_path)[0]
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "fastsim_ros.replay", str(truncated), "-o",
                           str(out)], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and str(truncated) in proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    assert list(out.iterdir()) == []


@pytest.mark.parametrize("where", ["batch", "message"])
def test_interrupt_leaves_nothing(tmp_path, monkeypatch, capsys, where):
    # Ctrl-C in the middle of the first bag: in the batched replay (at its second
    # diagnostics, its window's rules run, its outputs not yet written), or in one
    # message's pipeline call (the per-message path: traction clouds on)
    calls = {"n": 0}
    owner, name, at = ((batch.Batch, "store", 2) if where == "batch"
                       else (replay.Pipeline, "on_patch", 300))
    original = getattr(owner, name)

    def interrupted(*args):
        calls["n"] += 1
        if calls["n"] == at:
            raise KeyboardInterrupt
        return original(*args)

    monkeypatch.setattr(owner, name, interrupted)
    params = tmp_path / "params.yaml"
    params.write_text("fastsim:\n  ros__parameters:\n    publish_traction: "
                      f"{'false' if where == 'batch' else 'true'}\n")
    out = tmp_path / "out"
    status, _, err = run([BAGS / "hertz_ramp", BAGS / "semi_ellipses_spin", "-o", out, "--csv",
                          "--plot", "--params", params], capsys)
    assert status == 130 and "interrupted" in err
    assert calls["n"] == at
    assert list(out.iterdir()) == []


def test_sigterm_with_jobs_2_stops_the_workers_and_leaves_no_partial_output(tmp_path):
    src = tmp_path / "in"
    src.mkdir()
    for k in range(6):
        (src / f"f{k}").symlink_to(BAGS / "flange_shift", target_is_directory=True)
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "fastsim_ros.replay", *sorted(map(str, src.iterdir())), "-o",
         str(out), "--jobs", "2", "--csv", "--params", str(BAGS / "flange_shift.params.yaml")],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not (out.is_dir() and any(p.name.endswith(".replay-tmp") for p in out.iterdir())):
        assert time.monotonic() < deadline and proc.poll() is None
        time.sleep(0.02)
    proc.send_signal(signal.SIGTERM)
    # the workers die with the main process: nothing keeps the pipes open
    stdout, stderr = proc.communicate(timeout=30)
    assert proc.returncode == 130 and "interrupted" in stderr and "Traceback" not in stderr
    left = sorted(p.name for p in out.iterdir())
    done = [line.split(":")[0] for line in stdout.splitlines() if "messages in" in line]
    # every input whose summary was printed is there; an input may also have been
    # finished (renamed) just before the signal, its summary not yet printed: then
    # it must be complete too.  Nothing partial: no temporary names, no bag
    # without its CSV, every bag readable to its last message.
    bags = [n for n in left if not n.endswith(".csv")]
    assert set(done) <= set(bags)
    assert left == sorted(bags + [f"{n}.csv" for n in bags])
    for name in bags:
        with Reader(out / name) as reader:
            assert sum(1 for _ in reader.messages()) == reader.message_count > 4000
    time.sleep(1.0)  # no orphan still writing
    assert sorted(p.name for p in out.iterdir()) == left


# ------------------------------------------------------------------------ before any work

def test_duplicate_name_exits_before_work(tmp_path, capsys):
    other = tmp_path / "elsewhere" / "hertz_ramp"
    shutil.copytree(BAGS / "hertz_ramp", other)
    out = tmp_path / "out"
    status, _, err = run([BAGS / "hertz_ramp", other, "-o", out], capsys)
    assert status == 2 and "same name 'hertz_ramp'" in err and err.count("\n") == 1
    assert not out.exists()


@pytest.mark.parametrize("existing, flags", [("hertz_ramp", []), ("hertz_ramp.csv", ["--csv"]),
                                             ("hertz_ramp.png", ["--plot"])])
def test_existing_target_exits_before_work(tmp_path, capsys, existing, flags):
    target = tmp_path / existing
    target.write_text("keep me")
    status, _, err = run([BAGS / "roller_rig", BAGS / "hertz_ramp", "-o", tmp_path] + flags,
                         capsys)
    assert status == 2 and f"{target}: exists already" in err and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == [existing]
    assert target.read_text() == "keep me"


@pytest.mark.parametrize("args, message", [
    (["--jobs", "0"], "argument --jobs: 0 is outside"),
    (["--jobs", "two"], "argument --jobs: 'two' is not a whole number"),
    (["--par", "x.yaml"], "unrecognized arguments: --par"),
    (["--bogus"], "unrecognized arguments: --bogus"),
    (["-o"], "argument -o/--output: expected one argument"),
    (["--namespace", "rig 1"], "argument --namespace: 'rig 1' is not a ROS namespace"),
    (["--namespace", "/rig1//"], "argument --namespace: '/rig1//' is not a ROS namespace"),
    (["--namespace", "//rig1"], "argument --namespace: '//rig1' is not a ROS namespace"),
])
def test_bad_flags_one_line_exit_2(tmp_path, capsys, args, message):
    with pytest.raises(SystemExit) as e:
        replay.main([str(BAGS / "hertz_ramp"), "-o", str(tmp_path / "out")] + args)
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err
    assert not (tmp_path / "out").exists()


def test_no_input_or_no_output_is_a_usage_error(capsys):
    for args in ([], ["-o", "somewhere"], [str(BAGS / "hertz_ramp")]):
        with pytest.raises(SystemExit, match="2"):
            replay.main(args)
        assert capsys.readouterr().err.count("\n") == 1


def test_bad_params_file_exits_before_work(tmp_path, capsys):
    params = tmp_path / "bad.yaml"
    params.write_text("fastsim:\n  ros__parameters:\n    friction_coefficient: -1.0\n")
    status, _, err = run([BAGS / "hertz_ramp", "-o", tmp_path / "out", "--params", params],
                         capsys)
    assert status == 2 and err.count("\n") == 1
    assert str(params) in err and "friction_coefficient" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("text, words", [
    ("fastsim:\n  ros__parameters:\n    friction_coeficient: 0.4\n",
     "unknown parameter 'friction_coeficient' in section 'fastsim'; did you mean "
     "'friction_coefficient'?"),
    ("fastsim_node:\n  ros__parameters:\n    friction_coefficient: 0.4\n",
     "no section for node '/fastsim': section 'fastsim_node' is for another node: this "
     "node's section is 'fastsim' or a wildcard such as '/**'"),
], ids=["typo", "another node's section"])
def test_a_params_file_the_node_would_not_take_exits_before_work(tmp_path, capsys, text,
                                                                 words):
    """A typo or a section for another node name: what the node warns of, the replay refuses."""
    params = tmp_path / "p.yaml"
    params.write_text(text)
    status, _, err = run([BAGS / "hertz_ramp", "-o", tmp_path / "out", "--params", params],
                         capsys)
    assert status == 2 and err.count("\n") == 1
    assert f"{params}: {words}" in err, err
    assert not (tmp_path / "out").exists()


# ------------------------------------------------------------------------ golden files

def write_golden(names=NAMES) -> None:
    """Regenerate ``bags/golden/<name>.csv.gz`` from the replay's own CSV output."""
    import tempfile
    GOLDEN.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            status = replay.main([str(BAGS / name), "-o", tmp, "--csv", "--params",
                                  str(BAGS / f"{name}.params.yaml")])
            if status != 0:
                raise SystemExit(f"replay of {name} failed")
            data = (Path(tmp) / f"{name}.csv").read_bytes()
            with open(GOLDEN / f"{name}.csv.gz", "wb") as f:
                with gzip.GzipFile(filename="", mode="wb", fileobj=f, mtime=0) as z:
                    z.write(data)
            print(f"wrote {GOLDEN / name}.csv.gz ({len(data)} bytes of CSV)")


if __name__ == "__main__":
    if sys.argv[1:2] != ["--write-golden"] or not set(sys.argv[2:]) <= set(NAMES):
        raise SystemExit("usage: python test/test_replay.py --write-golden [NAME ...]")
    write_golden(tuple(sys.argv[2:]) or NAMES)


# ------------------------------------------------------------------ inputs of other writers

def _short_copy(source, target, *, relative=False, wrench_input=False, compression=None,
                seconds=0.5):
    """Write the first ``seconds`` of ``source`` again; options as another writer's bag.

    ``relative``: every topic without its leading slash (resolved in the root
    namespace); ``wrench_input``: a recorded ``contact/left/wrench`` beside each
    left patch (an output topic: never copied); ``compression``: rosbags'
    per-message zstd compression (read message by message, not by the chunk).
    """
    from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
    name = (lambda t: t.lstrip("/")) if relative else (lambda t: t)
    writer = Writer(target, version=9, storage_plugin=StoragePlugin.MCAP)
    if compression == "message":
        writer.set_compression(CompressionMode.MESSAGE, CompressionFormat.ZSTD)
    wrench_type = TYPES.types["geometry_msgs/msg/WrenchStamped"]
    with Reader(source) as reader, writer:
        conns = {c.id: writer.add_connection(name(c.topic), c.msgtype, typestore=TYPES,
                                             offered_qos_profiles=c.ext.offered_qos_profiles)
                 for c in reader.connections}
        recorded = writer.add_connection(name("/contact/left/wrench"), wrench_type.__msgtype__,
                                         typestore=TYPES) if wrench_input else None
        t0 = None
        for conn, log_ns, raw in reader.messages():
            t0 = log_ns if t0 is None else t0
            if log_ns - t0 > seconds * 1e9:
                break
            writer.write(conns[conn.id], log_ns, raw)
            if recorded is not None and conn.topic == "/contact/left/patch":
                msg = TYPES.deserialize_cdr(bytes(raw), conn.msgtype)
                w = wrench_type(header=msg.header, wrench=TYPES.types[
                    "geometry_msgs/msg/Wrench"](force=TYPES.types["geometry_msgs/msg/Vector3"](
                        1.0, 2.0, 3.0), torque=TYPES.types["geometry_msgs/msg/Vector3"](
                        4.0, 5.0, 6.0)))
                writer.write(recorded, log_ns, TYPES.serialize_cdr(w, wrench_type.__msgtype__))


@pytest.mark.parametrize("compression", [None, "message"], ids=["chunks", "per-message"])
def test_a_recorded_output_topic_with_a_relative_name_is_not_copied(
        tmp_path, capsys, compression):
    """``contact/left/wrench`` in a bag is ``/contact/left/wrench``: an output, not copied.

    The per-message path compared the bag's name as written (it copied the
    recorded wrenches beside the node's: 100 on the topic instead of 50).
    """
    bag = tmp_path / "relative"
    _short_copy(BAGS / "hertz_ramp", bag, relative=True, wrench_input=True,
                compression=compression)
    status, out, err = run([bag, "-o", tmp_path / "out"], capsys)
    assert status == 0, err
    topics, _, _ = bag_contents(tmp_path / "out" / "relative")
    assert "contact/left/wrench" not in topics
    wrenches = topics["/contact/left/wrench"][1]
    assert len(wrenches) == 50
    assert all(m.wrench.force.z > 1e3 for _, m in wrenches)  # the node's: N, not the 3.0
    assert len(topics["contact/left/patch"][1]) == 50          # inputs copied as named


@pytest.mark.parametrize("variant", ["no_chunk_index", "unchunked"])
def test_a_valid_mcap_without_chunk_indexes_replays(tmp_path, capsys, variant):
    """An MCAP file with its messages but no chunk index (another writer's options).

    It was refused as "empty bag (no messages)": the indexed path found no
    chunk to read.  rosbags reads such a file message by message.
    """
    from mcap.reader import make_reader
    from mcap.writer import IndexType, Writer as McapWriter
    options = ({"index_types": IndexType.NONE} if variant == "no_chunk_index"
               else {"use_chunking": False})
    source = next((BAGS / "hertz_ramp").glob("*.mcap"))
    target = tmp_path / f"{variant}.mcap"
    with open(source, "rb") as f, open(target, "wb") as g:
        writer = McapWriter(g, **options)
        writer.start(profile="ros2", library="another writer")
        schemas, channels, t0 = {}, {}, None
        for schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
            t0 = message.log_time if t0 is None else t0
            if message.log_time - t0 > 5e8:
                break
            if schema.id not in schemas:
                schemas[schema.id] = writer.register_schema(schema.name, schema.encoding,
                                                            schema.data)
            if channel.id not in channels:
                channels[channel.id] = writer.register_channel(
                    channel.topic, channel.message_encoding, schemas[schema.id],
                    channel.metadata)
            writer.add_message(channels[channel.id], message.log_time, message.data,
                               message.publish_time, message.sequence)
        writer.finish()
    status, out, err = run([target, "-o", tmp_path / "out"], capsys)
    assert status == 0, err
    assert "left: 50 patches, 50 wrenches (50 solved" in out
    topics, _, _ = bag_contents(tmp_path / "out" / variant)
    assert len(topics["/contact/left/wrench"][1]) == 50


def test_inputs_whose_outputs_clash_are_refused_before_any_work(tmp_path, capsys):
    """``x`` with ``--csv`` writes ``x.csv``; an input named ``x.csv`` would write it too."""
    (tmp_path / "in").mkdir()
    for name in ("x", "x.csv"):
        _short_copy(BAGS / "hertz_ramp", tmp_path / "in" / name, seconds=0.05)
    out = tmp_path / "out"
    status, stdout, err = run([tmp_path / "in" / "x", tmp_path / "in" / "x.csv", "-o", out,
                               "--csv"], capsys)
    assert status == 2 and stdout == ""
    (line,) = err.splitlines()
    assert "x.csv" in line and "would clash" in line
    assert not out.exists()


def test_a_url_input_is_named_by_its_url_and_a_url_out_that_is_a_file_is_refused(
        tmp_path, capsys):
    bag = tmp_path / "short"
    _short_copy(BAGS / "hertz_ramp", bag, seconds=0.05)
    status, _, err = run([f"file://{bag}", "-o", tmp_path / "out"], capsys)
    assert status == 0, err
    _, _, meta = bag_contents(tmp_path / "out" / "short")
    assert meta["custom_data"]["fastsim.input"] == f"file://{bag}"  # not the local copy
    (tmp_path / "a_file").write_text("")
    status, stdout, err = run([bag, "-o", f"file://{tmp_path / 'a_file'}"], capsys)
    assert status == 2 and "exists and is not a directory" in err and err.count("\n") == 1


@pytest.mark.parametrize("address", ["notanaddress", "", "inproc://x", "tcp://host"])
def test_a_malformed_scheduler_address_is_one_line_exit_2_at_once(tmp_path, capsys, address):
    started = time.monotonic()
    with pytest.raises(SystemExit) as info:
        replay.main([str(BAGS / "hertz_ramp"), "-o", str(tmp_path / "out"), "--scheduler",
                     address])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a Dask scheduler address" in err
    assert time.monotonic() - started < 10.0   # no client left to time out
    assert not (tmp_path / "out").exists()


def test_a_namespace_with_a_trailing_slash_is_that_namespace(tmp_path, capsys, rig1_front):
    status, out, err = run([rig1_front, "-o", tmp_path / "out", "--namespace", "/rig1/"],
                           capsys)
    assert status == 0 and err == ""
    assert "contacts found in the bag (no --params): front; namespace /rig1\n" in out
