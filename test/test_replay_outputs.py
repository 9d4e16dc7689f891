"""``fastsim_replay``: what it shows of what it computed, what it did not take, --overwrite.

- friction estimation (``bags/adhesion_rig``): the summary gives the
  estimate's path, ``OUT/NAME.friction.csv`` holds the ``friction/estimate``
  messages of the output bag, the plot bounds each wrench with the mu it was
  solved with;
- every output topic is named in the summary with its count and where it went;
- input topics no configured contact takes are named with the parameter
  that would take them (``bags/flange_shift`` with ``config/fastsim.yaml``);
- ``--overwrite`` replaces an earlier run's outputs, and only once the new
  ones are complete: a failed, refused or interrupted run leaves them.
"""

from __future__ import annotations

import contextlib
import csv
import io
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag2 import Reader

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from fastsim_ros import replay  # noqa: E402
from fastsim_ros.replay import batch, faults, plot, run as replay_run  # noqa: E402
from test_replay import (BAGS, adhesion_truth, bag_contents,  # noqa: E402
                         decoded_without_timing, final_counts, rows_of)

ADHESION = ("adhesion_rig", BAGS / "adhesion_rig.params.yaml")
FRICTION_HEADER = ["stamp_ns", "mu", "sigma", "utilisation", "status"]
STATUSES = ("updated", "unobservable", "implausible", "no_measurement")


def stamp(msg):
    """Return the header's time of a message (ns)."""
    return msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec


def friction_rows(path):
    """Return a friction CSV's rows as dicts (header checked)."""
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        assert next(reader) == FRICTION_HEADER
        return [dict(zip(FRICTION_HEADER, row)) for row in reader]


def quiet_run(args):
    """Run ``fastsim_replay`` in this process; return ``(status, stdout, stderr)``."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = replay.main([str(a) for a in args])
    return status, out.getvalue(), err.getvalue()


class Plots:
    """What :func:`write_plot` was given, by input name (the replay's own call, then drawn)."""

    def __init__(self):
        self.calls = {}
        self.original = replay_run.write_plot

    def __call__(self, path, name, contacts, series, mu, law="constant", estimates=None):
        self.calls[name] = dict(contacts=contacts, series=series, mu=mu, law=law,
                                estimates=estimates)
        self.original(path, name, contacts, series, mu, law, estimates)


@pytest.fixture(scope="module")
def adhesion(tmp_path_factory):
    """Replay adhesion_rig (estimation on) and hertz_ramp (off), each with its params file."""
    out = tmp_path_factory.mktemp("adhesion") / "out"
    plots = Plots()
    stdout = ""
    with pytest.MonkeyPatch.context() as m:
        m.setattr(replay_run, "write_plot", plots)
        for name in ("adhesion_rig", "hertz_ramp"):
            status, got, err = quiet_run([BAGS / name, "-o", out, "--params",
                                          BAGS / f"{name}.params.yaml", "--csv", "--plot"])
            assert status == 0 and err == "", err
            stdout += got
    topics, _, _ = bag_contents(out / "adhesion_rig")
    return out, stdout, topics, plots


def _summary(stdout, name):
    """Return the summary of one input (its lines, from its first)."""
    lines = stdout.splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith(f"{name}: "))
    end = next((k for k in range(start + 1, len(lines)) if not lines[k].startswith(" ")),
               len(lines))
    return "\n".join(lines[start:end])


# ------------------------------------------------------------------------ friction estimation

def test_the_summary_shows_the_estimates_path(adhesion):
    out, stdout, topics, _ = adhesion
    text = _summary(stdout, "adhesion_rig")
    msgs = [m for _, m in topics["/friction/estimate"][1]]
    last = msgs[-1].vector
    assert (f"friction estimate: mu_s 0.3 at the start, {last.x:.4g} last "
            f"(sigma {last.y:.3g})") in text
    # the path: where the estimate settled before each step it saw, then the last; the
    # truth is 0.4 from the start, 0.2 from 1.5 s, 0.4 from 3 s (the params file's truth)
    _, steps, _ = adhesion_truth()
    path = re.search(r"; path ([-> 0-9.]+)\n", text + "\n").group(1).split(" -> ")
    assert float(path[0]) == 0.3
    assert [float(v) for v in path[1:]] == pytest.approx([m for _, m in steps], rel=0.02)
    seen = re.search(r"(\d+) steps of mu_s seen \(at ([0-9., ]+) s\)", text)
    times = [float(t) for t in seen.group(2).split(", ")]
    assert int(seen.group(1)) == len(times) == 2
    assert times == pytest.approx([start for start, _ in steps[1:]], abs=0.05)
    # the estimates by status: the estimator's own counts in the bag's last diagnostics
    counts = final_counts(topics, "left")
    listed = re.search(r"(\d+) estimates \(([^)]*)\)", text)
    assert int(listed.group(1)) == len(msgs) == 400
    by_status = dict((s, int(n)) for n, s in (p.split(" ") for p in listed.group(2).split(", ")))
    assert by_status == {s: int(counts[f"friction_estimation/{s}"]) for s in STATUSES
                         if int(counts[f"friction_estimation/{s}"])}
    assert int(counts["friction_estimation/steps"]) == 2
    assert "-> adhesion_rig.friction.csv" in text
    assert f"wrote {out / 'adhesion_rig.friction.csv'}" in text


def test_the_friction_csv_is_the_estimate_messages_of_the_output_bag(adhesion):
    out, _, topics, _ = adhesion
    rows = friction_rows(out / "adhesion_rig.friction.csv")
    msgs = topics["/friction/estimate"][1]
    assert len(rows) == len(msgs) == 400
    for r, (_, m) in zip(rows, msgs):
        assert int(r["stamp_ns"]) == stamp(m)
        assert (float(r["mu"]), float(r["sigma"]), float(r["utilisation"])) == \
            (m.vector.x, m.vector.y, m.vector.z)
        assert r["status"] in STATUSES
    # the utilisation is the wheelset's: sum |(Fx, Fy)| / (mu sum N) over the contacts'
    # wrenches of the cycle, at the mu they were solved with (the row before's)
    wrenches = {c: {stamp(m): m.wrench.force for _, m in topics[f"/contact/{c}/wrench"][1]}
                for c in ("left", "right")}
    for k in (0, 100, 399):
        mu = 0.3 if k == 0 else float(rows[k - 1]["mu"])
        cycle = int(rows[k]["stamp_ns"])
        forces = [wrenches[c][cycle] for c in ("left", "right")]
        used = sum(np.hypot(f.x, f.y) for f in forces) / (mu * sum(f.z for f in forces))
        assert float(rows[k]["utilisation"]) == pytest.approx(used, rel=1e-12)


def test_estimation_off_writes_no_friction_csv(adhesion):
    out, stdout, _, _ = adhesion
    assert not (out / "hertz_ramp.friction.csv").exists()
    text = _summary(stdout, "hertz_ramp")
    assert "friction" not in text
    assert sorted(p.name for p in out.iterdir()) == sorted(
        ["adhesion_rig", "adhesion_rig.csv", "adhesion_rig.friction.csv", "adhesion_rig.png",
         "hertz_ramp", "hertz_ramp.csv", "hertz_ramp.png"])


def test_the_plot_bounds_each_wrench_with_the_mu_it_was_solved_with(adhesion):
    out, _, _, plots = adhesion
    for name in ("adhesion_rig", "hertz_ramp"):
        png = (out / f"{name}.png").read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    call = plots.calls["adhesion_rig"]
    rows = friction_rows(out / "adhesion_rig.friction.csv")
    estimated = [float(r["mu"]) for r in rows]
    # each cycle's wrenches at the estimate of the cycle before (0.3, the start, first)
    for c in ("left", "right"):
        mu = list(call["series"][c].cols[7])
        assert mu == [0.3] + estimated[:-1], c
    # the estimate's own row: mu, sigma, utilisation of each cycle
    t, mu, sigma, used = (list(col) for col in call["estimates"].cols)
    assert (mu, sigma, used) == (estimated, [float(r["sigma"]) for r in rows],
                                 [float(r["utilisation"]) for r in rows])
    assert plot.title("adhesion_rig", call["mu"], call["law"], call["estimates"]) == (
        f"adhesion_rig: creep forces of the rail on the wheel (+-mu_s N, mu_s estimated "
        f"online: 0.3 at the start, {estimated[-1]:.3g} last)")
    # without estimation (the batched path): the given mu throughout, and the title says so
    call = plots.calls["hertz_ramp"]
    assert call["estimates"] is None
    assert set(call["series"]["left"].cols[7]) == {0.3} and len(call["series"]["left"].cols[7]) \
        == 400
    assert plot.title("hertz_ramp", call["mu"], call["law"], None) == \
        "hertz_ramp: creep forces of the rail on the wheel (+-mu N, mu = 0.3 given)"


@pytest.mark.parametrize("name", ["adhesion_rig", "hertz_ramp"])
def test_the_summary_names_every_output_topic_with_its_count_and_place(adhesion, name):
    out, stdout, _, _ = adhesion
    text = _summary(stdout, name)
    topics, _, _ = bag_contents(out / name)
    with Reader(BAGS / name) as reader:
        inputs = {c.topic for c in reader.connections}
    places = {}
    for line in text.splitlines():
        m = re.match(r"  published to (the bag and (\S+)|the bag only): (.*)$", line)
        if m:
            for item in m.group(3).split(", "):
                topic, n = item.split(" ")
                places[topic] = (m.group(2), int(n))
    outputs = {t: len(items) for t, (_, items) in topics.items() if t not in inputs}
    assert {t: n for t, (_, n) in places.items()} == outputs
    for topic, (file, _) in places.items():
        if topic.endswith(("/wrench", "/creepage")) and topic.startswith("/contact/"):
            assert file == f"{name}.csv"
        elif topic == "/friction/estimate":
            assert file == f"{name}.friction.csv"
        else:
            assert file is None, topic
    assert ("/friction/estimate" in places) == (name == "adhesion_rig")


# ------------------------------------------------------------------------ jobs 2 and clusters

def test_jobs_2_shows_the_same_estimate(adhesion, tmp_path):
    out, stdout, _, _ = adhesion
    (tmp_path / "in").mkdir()
    copy = tmp_path / "in" / "copy"
    copy.symlink_to(BAGS / "adhesion_rig", target_is_directory=True)
    status, got, err = quiet_run([BAGS / "adhesion_rig", copy, "-o", tmp_path / "out",
                                  "--params", ADHESION[1], "--csv", "--jobs", "2"])
    assert status == 0 and err == ""

    def estimate_lines(text, name):
        return [line.replace(name, "NAME")
                for line in _summary(text, name).splitlines() if "estimate" in line]
    want = estimate_lines(stdout, "adhesion_rig")
    assert len(want) == 3
    for name in ("adhesion_rig", "copy"):
        assert (tmp_path / "out" / f"{name}.friction.csv").read_text() == \
            (out / "adhesion_rig.friction.csv").read_text()
        assert estimate_lines(got, name) == want


def test_a_result_with_its_estimate_survives_pickling(tmp_path):
    import pickle
    result = replay.replay_bag(BAGS / "adhesion_rig", "adhesion_rig", tmp_path,
                               _params_of(ADHESION[1]), write_csv=True, progress=False)
    assert result.ok, result.error
    copy = pickle.loads(pickle.dumps(result))
    assert copy.summary() == result.summary()
    assert copy.friction == result.friction and copy.friction.cycles == 400


# ------------------------------------------------------------------------ topics not taken

def _bag_counts(name):
    with Reader(BAGS / name) as reader:
        counts = {}
        for conn, _, _ in reader.messages():
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
    return counts


@pytest.mark.parametrize("path", ["auto", "rosbags"])
def test_patch_topics_of_contacts_not_configured_are_named(tmp_path, path):
    counts = _bag_counts("flange_shift")
    values = _params_of(ROOT / "config" / "fastsim.yaml")
    result = replay.replay_bag(BAGS / "flange_shift", "flange_shift", tmp_path, values,
                               progress=False, path=path)
    assert result.ok, result.error
    text = result.summary()
    for contact in ("left_flange", "right_flange"):
        topic = f"/contact/{contact}/patch"
        assert counts[topic] == 400
        assert (f"  {topic}: {counts[topic]} messages not replayed; add {contact!r} to the "
                "'contacts' parameter") in text.splitlines()
    # the poses and loads of the profiles recording: patch_source would take them
    for topic in ("/wheelset/pose", "/wheelset/load"):
        assert (f"  {topic}: {counts[topic]} messages not replayed; set 'patch_source' to "
                "profiles to compute the patches from them") in text.splitlines()
    assert [t for t, _, _ in result.unused] == [
        "/wheelset/load", "/wheelset/pose", "/contact/left_flange/patch",
        "/contact/right_flange/patch"]
    # the contacts the parameter lists are replayed as usual
    assert "  left: 400 patches, 400 wrenches" in text and "  right: 400 patches" in text


def _params_of(path):
    from fastsim_ros.ros.params import load_params_file
    return load_params_file(path)


def test_from_the_command_line_the_dropped_topics_are_in_the_summary(tmp_path, capsys):
    status = replay.main([str(BAGS / "flange_shift"), "-o", str(tmp_path), "--params",
                          str(ROOT / "config" / "fastsim.yaml"), "--csv"])
    cap = capsys.readouterr()
    assert status == 0 and cap.err == ""
    assert ("/contact/left_flange/patch: 400 messages not replayed; add 'left_flange' to "
            "the 'contacts' parameter") in cap.out
    assert ("/contact/right_flange/patch: 400 messages not replayed; add 'right_flange' to "
            "the 'contacts' parameter") in cap.out
    # with its own params file (all four contacts) nothing of the patches is left out
    status = replay.main([str(BAGS / "flange_shift"), "-o", str(tmp_path / "all"), "--params",
                          str(BAGS / "flange_shift.params.yaml")])
    cap = capsys.readouterr()
    assert status == 0 and "patch: " not in cap.out and "'contacts'" not in cap.out


def test_the_measured_wrench_without_estimation_is_named(tmp_path, capsys):
    params = tmp_path / "off.yaml"
    params.write_text("fastsim:\n  ros__parameters:\n    friction_estimation: \"off\"\n")
    status = replay.main([str(BAGS / "adhesion_rig"), "-o", str(tmp_path / "out"), "--params",
                          str(params), "--csv"])
    cap = capsys.readouterr()
    assert status == 0
    assert ("  /wheelset/measured_wrench: 400 messages not replayed; set "
            "'friction_estimation' to on to estimate mu_s from it") in cap.out.splitlines()
    assert not (tmp_path / "out" / "adhesion_rig.friction.csv").exists()


def test_a_patch_topic_under_another_namespace_is_named_with_its_flag(tmp_path, capsys):
    from test_replay import _namespaced_copy
    bag = tmp_path / "two_rigs"
    _namespaced_copy(BAGS / "hertz_ramp", bag, {"/contact/right/patch":
                                                "/rig2/contact/right/patch"})
    status = replay.main([str(bag), "-o", str(tmp_path / "out")])
    cap = capsys.readouterr()
    assert status == 0
    assert "contacts found in the bag (no --params): left\n" in cap.out
    assert ("  /rig2/contact/right/patch: 400 messages not replayed; outside the namespace / "
            "(--namespace /rig2 replays it)") in cap.out.splitlines()


# ------------------------------------------------------------------------ --overwrite

def _snapshot(out):
    """Return every file under ``out`` with its bytes (names relative to ``out``)."""
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file()}


@pytest.fixture
def earlier(tmp_path):
    """Return an OUT holding hertz_ramp's outputs of an earlier run, marked as that run's."""
    out = tmp_path / "out"
    status, _, err = quiet_run([BAGS / "hertz_ramp", "-o", out, "--csv", "--plot"])
    assert status == 0, err
    (out / "hertz_ramp" / "earlier.txt").write_text("of the earlier run")
    with open(out / "hertz_ramp.csv", "a", encoding="utf-8") as f:
        f.write("# the earlier run\n")
    return out


def test_without_overwrite_an_existing_output_is_still_refused(earlier):
    before = _snapshot(earlier)
    status, stdout, err = quiet_run([BAGS / "hertz_ramp", "-o", earlier, "--csv"])
    assert status == 2 and stdout == ""
    assert err == (f"fastsim_replay: {earlier / 'hertz_ramp'}: exists already; not "
                   "overwritten (--overwrite replaces it)\n")
    assert _snapshot(earlier) == before


def test_overwrite_replaces_the_earlier_outputs(earlier, tmp_path):
    # a friction CSV of an earlier run with estimation: not written now, so replaced too
    (earlier / "hertz_ramp.friction.csv").write_text("stale\n")
    status, stdout, err = quiet_run([BAGS / "hertz_ramp", "-o", earlier, "--csv", "--plot",
                                     "--overwrite"])
    assert status == 0 and err == ""
    status, _, _ = quiet_run([BAGS / "hertz_ramp", "-o", tmp_path / "fresh", "--csv"])
    assert status == 0
    assert sorted(p.name for p in earlier.iterdir()) == ["hertz_ramp", "hertz_ramp.csv",
                                                         "hertz_ramp.png"]
    assert (earlier / "hertz_ramp.csv").read_text() == \
        (tmp_path / "fresh" / "hertz_ramp.csv").read_text()
    assert not (earlier / "hertz_ramp" / "earlier.txt").exists()   # the whole bag replaced
    assert sorted(p.name for p in (earlier / "hertz_ramp").iterdir()) == [
        "hertz_ramp.mcap", "metadata.yaml"]
    assert len(rows_of(earlier / "hertz_ramp.csv")) == 800


def test_a_friction_csv_alone_is_a_target_too(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "hertz_ramp.friction.csv").write_text("keep me")
    status, _, err = quiet_run([BAGS / "hertz_ramp", "-o", out, "--csv"])
    assert status == 2 and f"{out / 'hertz_ramp.friction.csv'}: exists already" in err
    assert (out / "hertz_ramp.friction.csv").read_text() == "keep me"
    assert sorted(p.name for p in out.iterdir()) == ["hertz_ramp.friction.csv"]


def test_a_bad_input_with_overwrite_leaves_the_earlier_outputs(earlier, tmp_path):
    before = _snapshot(earlier)
    bad = tmp_path / "bad" / "hertz_ramp"
    bad.mkdir(parents=True)
    shutil.copy(BAGS / "hertz_ramp" / "metadata.yaml", bad)
    data = (BAGS / "hertz_ramp" / "hertz_ramp.mcap").read_bytes()
    (bad / "hertz_ramp.mcap").write_bytes(data[:len(data) // 2])
    status, _, err = quiet_run([bad, "-o", earlier, "--csv", "--plot", "--overwrite"])
    assert status == 2 and str(bad) in err and err.count("\n") == 1
    assert _snapshot(earlier) == before
    assert sorted(p.name for p in earlier.iterdir()) == ["hertz_ramp", "hertz_ramp.csv",
                                                         "hertz_ramp.png"]


@pytest.mark.parametrize("failing", ["hertz_ramp.csv", "hertz_ramp.png"])
def test_a_commit_that_fails_midway_puts_the_earlier_outputs_back(earlier, monkeypatch,
                                                                  failing):
    """The bag (and the CSV) renamed into place, then a rename fails: all as it was."""
    before = _snapshot(earlier)
    rename = os.rename

    def failing_rename(src, dst, *args, **kwargs):
        if Path(dst) == earlier / failing and ".replay-tmp" in str(src) \
                and ".replaced" not in str(src):
            raise OSError(28, "No space left on device", str(dst))
        return rename(src, dst, *args, **kwargs)

    monkeypatch.setattr(replay_run.os, "rename", failing_rename)
    status, _, err = quiet_run([BAGS / "hertz_ramp", "-o", earlier, "--csv", "--plot",
                                "--overwrite"])
    assert status == 1 and "No space left on device" in err
    assert _snapshot(earlier) == before
    assert sorted(p.name for p in earlier.iterdir()) == ["hertz_ramp", "hertz_ramp.csv",
                                                         "hertz_ramp.png"]


def test_an_interrupted_overwrite_leaves_the_earlier_outputs(earlier, monkeypatch):
    before = _snapshot(earlier)
    calls = {"n": 0}
    original = batch.Batch.store

    def interrupted(*args):   # Ctrl-C at the batched replay's second diagnostics
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt
        return original(*args)

    monkeypatch.setattr(batch.Batch, "store", interrupted)
    status, _, err = quiet_run([BAGS / "hertz_ramp", "-o", earlier, "--csv", "--plot",
                                "--overwrite"])
    assert status == 130 and "interrupted" in err
    assert _snapshot(earlier) == before


def test_sigterm_between_setting_aside_and_renaming_puts_the_earlier_output_back(
        earlier, tmp_path):
    before = _snapshot(earlier)
    hold = tmp_path / "hold"
    hold.mkdir()
    env = dict(os.environ, **{faults.ENV: f"{faults.REPLACE}:{hold}"})
    proc = subprocess.Popen([sys.executable, "-m", "fastsim_ros.replay",
                             str(BAGS / "hertz_ramp"), "-o", str(earlier), "--csv", "--plot",
                             "--overwrite"], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + faults.PAUSE_S
        while not (hold / "pid").exists():
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.01)
        # held with the earlier bag moved aside, the new one not yet in its place
        assert not (earlier / "hertz_ramp").exists()
        proc.send_signal(signal.SIGTERM)
        _, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 130 and "interrupted" in stderr and "Traceback" not in stderr
    assert _snapshot(earlier) == before
    assert sorted(p.name for p in earlier.iterdir()) == ["hertz_ramp", "hertz_ramp.csv",
                                                         "hertz_ramp.png"]


def test_overwrite_into_a_url(earlier, tmp_path):
    status, _, err = quiet_run([BAGS / "hertz_ramp", "-o", f"file://{earlier}", "--csv",
                                "--overwrite"])
    assert status == 0, err
    assert sorted(p.name for p in earlier.iterdir()) == ["hertz_ramp", "hertz_ramp.csv",
                                                         "hertz_ramp.png"]
    assert not (earlier / "hertz_ramp" / "earlier.txt").exists()
    assert "# the earlier run" not in (earlier / "hertz_ramp.csv").read_text()
    status, _, _ = quiet_run([BAGS / "hertz_ramp", "-o", tmp_path / "fresh", "--csv"])
    assert status == 0
    assert (earlier / "hertz_ramp.csv").read_text() == \
        (tmp_path / "fresh" / "hertz_ramp.csv").read_text()
    assert decoded_without_timing(bag_contents(earlier / "hertz_ramp")[0]) == \
        decoded_without_timing(bag_contents(tmp_path / "fresh" / "hertz_ramp")[0])


@pytest.mark.parametrize("steps, last, cycles, path", [
    ([], 0.3, 5, [0.3]),                                  # held: the start is the path
    ([(0.01, 0.3), (1.5, 0.4), (3.0, 0.2)], 0.4, 9, [0.3, 0.4, 0.2, 0.4]),
    ([(1.5, 0.4)], 0.2, 9, [0.3, 0.4, 0.2]),
])
def test_the_path_is_the_start_the_level_before_each_step_and_the_last(steps, last, cycles,
                                                                       path):
    from fastsim_ros.replay.results import FrictionPath
    f = FrictionPath(0.3, last, 0.01, cycles, {"updated": cycles}, steps, 0.9)
    assert f.levels() == path
    assert f.summary("x.friction.csv")[0].endswith(
        "; path " + " -> ".join(f"{mu:.3g}" for mu in path))


def test_an_estimation_without_a_cycle_says_so():
    from fastsim_ros.replay.results import FrictionPath
    (line,) = FrictionPath(0.3).summary("x.friction.csv")
    assert line == ("  friction estimate: mu_s 0.3 at the start; no estimate published (no rig "
                    "cycle completed) -> x.friction.csv")
