"""``fastsim_replay --scheduler``: the replay on a real Dask cluster on localhost.

Each test's cluster is a scheduler and two worker processes started by the
test (the venv's python, this checkout on their path) and torn down after.
The outputs must equal a local ``--jobs 1`` run; a worker killed at any
moment of a task (before the run, in its warm-up, replaying, between the
renames of its outputs, after them) must leave every output present once,
complete and equal to a ``--jobs 1`` run (its task run again, the summary
saying so); a corrupt bag among good ones is reported
once; fsspec URLs work for inputs and outputs; a scheduler that cannot be
reached is one line.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from rosbags.rosbag2 import Reader

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from fastsim_ros.replay import faults  # noqa: E402
from fastsim_ros.replay.cluster import LocalProcesses  # noqa: E402
from test_replay import BAGS, DIAG, TYPES, bag_contents, decoded_without_timing  # noqa: E402

ENV = dict(os.environ, PYTHONPATH=os.pathsep.join(
    [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))


@pytest.fixture
def cluster(tmp_path):
    """Start a scheduler and two workers without nannies (a killed worker stays dead)."""
    c = LocalProcesses(tmp_path, 2, env=ENV, cwd=ROOT)
    yield c
    c.close()


def replay(*args, timeout=300):
    """Run ``fastsim_replay`` as users do; return the finished process."""
    return subprocess.run([sys.executable, "-m", "fastsim_ros.replay", *map(str, args)],
                          cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=timeout)


def same_outputs(a: Path, b: Path, names) -> None:
    for name in names:
        assert (a / f"{name}.csv").read_text() == (b / f"{name}.csv").read_text()
        assert decoded_without_timing(bag_contents(a / name)[0]) == \
            decoded_without_timing(bag_contents(b / name)[0])


def test_a_cluster_replays_as_jobs_1_and_reads_and_writes_urls(tmp_path, cluster):
    names = ("hertz_ramp", "semi_ellipses_spin", "bad_inputs")
    params = BAGS / "hertz_ramp.params.yaml"
    local = replay(*[BAGS / n for n in names], "-o", tmp_path / "local", "--csv",
                   "--params", params)
    assert local.returncode == 0, local.stderr
    remote = replay(*[BAGS / n for n in names], "-o", tmp_path / "cluster", "--csv",
                    "--params", params, "--scheduler", cluster.address)
    assert remote.returncode == 0, remote.stderr
    assert remote.stderr == ""
    same_outputs(tmp_path / "local", tmp_path / "cluster", names)
    # fsspec URLs: an input directory and a lone .mcap in, a directory URL out
    urls = replay(f"file://{BAGS / 'hertz_ramp'}", f"file://{BAGS / 'bad_inputs'}",
                  "-o", f"file://{tmp_path / 'urls'}", "--csv", "--params", params,
                  "--scheduler", cluster.address)
    assert urls.returncode == 0, urls.stderr
    assert f"-> file://{tmp_path / 'urls'}/hertz_ramp" in urls.stdout
    same_outputs(tmp_path / "local", tmp_path / "urls", ("hertz_ramp", "bad_inputs"))
    assert sorted(p.name for p in (tmp_path / "urls").iterdir()) == [
        "bad_inputs", "bad_inputs.csv", "hertz_ramp", "hertz_ramp.csv"]


def test_a_corrupt_bag_among_good_ones_is_reported_once(tmp_path, cluster):
    broken = tmp_path / "broken.mcap"
    broken.write_bytes((BAGS / "roller_rig" / "roller_rig.mcap").read_bytes()[:30_000])
    out = tmp_path / "out"
    proc = replay(BAGS / "hertz_ramp", broken, BAGS / "roller_rig", "-o", out,
                  "--scheduler", cluster.address)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"fastsim_replay: {broken}")
    assert sorted(p.name for p in out.iterdir()) == ["hertz_ramp", "roller_rig"]
    assert proc.stdout.count("messages in") == 2


# a worker killed at each moment of a task, held there by the faults hook (never a guessed
# delay): ``before`` the run starts (no task ran on it: nothing retried), in the ``warm-up``
# of its first task, in the ``replay`` (after the warm-up, the staged outputs half written),
# between the renames of its outputs (``commit``) and after them with its result not yet
# fetched (``committed``: the retry finishes that commit instead of replaying); and into
# a URL (file://) between the moves of its commit
MOMENTS = [(m, False) for m in ("before",) + faults.MOMENTS] + [("commit", True)]
RETRIED = {"before": None, "warm-up": "retried: replayed 2 times",
           "replay": "retried: replayed 2 times", "commit": "retried: 2 attempts",
           "committed": "retried: 2 attempts"}
SOURCES = ("flange_shift", "hertz_ramp", "semi_ellipses_spin")
COPIES = 4   # 12 bags


def kill_held_worker(cluster, hold: Path, proc: subprocess.Popen) -> None:
    """Wait for the worker the fault hook holds (its pid in ``hold``), then SIGKILL it.

    SIGKILL: the worker gets no clean-up of its own.  ``proc`` (the replay)
    must still run while the hook has not fired.
    """
    deadline = time.monotonic() + faults.PAUSE_S
    while not (hold / "pid").exists():
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.01)
    pid = int((hold / "pid").read_text())
    victim = next(w for w in cluster.workers if w.pid == pid)
    victim.kill()
    victim.wait(timeout=30)


def comparable(bag: Path):
    """Return a bag's messages by topic: raw CDR, the diagnostics decoded without timing."""
    raw: dict[str, list] = {}
    diagnostics: dict[str, tuple] = {}
    with Reader(bag) as reader:
        count = reader.message_count
        for conn, log_ns, data in reader.messages():
            if conn.msgtype == DIAG:
                diagnostics.setdefault(conn.topic, (DIAG, []))[1].append(
                    (log_ns, TYPES.deserialize_cdr(data, DIAG)))
            else:
                raw.setdefault(conn.topic, []).append((log_ns, bytes(data)))
    assert sum(len(v) for v in raw.values()) + sum(len(v[1]) for v in diagnostics.values()) \
        == count
    return raw, decoded_without_timing(diagnostics)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """Replay the sources with ``--jobs 1`` (no --params: contacts from the bags); keep them."""
    out = tmp_path_factory.mktemp("reference") / "out"
    proc = replay(*[BAGS / n for n in SOURCES], "-o", out, "--csv", "--jobs", "1")
    assert proc.returncode == 0, proc.stderr
    return {n: (comparable(out / n), (out / f"{n}.csv").read_text()) for n in SOURCES}


@pytest.mark.parametrize("moment, url", MOMENTS)
def test_a_worker_killed_at_any_moment_loses_nothing(tmp_path, reference, moment, url):
    hold = tmp_path / "hold"
    hold.mkdir()
    logs = tmp_path / "logs"
    logs.mkdir()
    # both workers may be held; the first to reach the moment is, the other goes on
    env = ENV if moment == "before" else dict(ENV, **{faults.ENV: f"{moment}:{hold}"})
    cluster = LocalProcesses(logs, 2, env=env, cwd=ROOT)
    try:
        src = tmp_path / "in"
        src.mkdir()
        names = [f"{n}-{k}" for k in range(COPIES) for n in SOURCES]
        for name in names:
            (src / name).symlink_to(BAGS / name.rsplit("-", 1)[0], target_is_directory=True)
        out = tmp_path / "out"
        if moment == "before":
            cluster.workers[0].kill()
            cluster.workers[0].wait(timeout=30)
        proc = subprocess.Popen(
            [sys.executable, "-m", "fastsim_ros.replay", *(str(src / n) for n in names), "-o",
             f"file://{out}" if url else str(out), "--csv", "--scheduler", cluster.address],
            cwd=ROOT, env=ENV,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            if moment != "before":
                kill_held_worker(cluster, hold, proc)
            stdout, stderr = proc.communicate(timeout=120)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
    finally:
        cluster.close()
    assert proc.returncode == 0, stderr
    assert stderr == ""
    # every output once, nothing else left (no staging directory, no kept result)
    assert sorted(p.name for p in out.iterdir()) == sorted(names + [f"{n}.csv" for n in names])
    for name in names:
        bag, csv = reference[name.rsplit("-", 1)[0]]
        assert (out / f"{name}.csv").read_text() == csv, name
        assert comparable(out / name) == bag, name
    assert stdout.count(f"-> {'file://' if url else ''}{out}/") == len(names)
    if RETRIED[moment] is None:
        assert "retried" not in stdout
    else:
        assert stdout.count("retried:") == 1 and stdout.count(RETRIED[moment]) == 1, stdout


def test_a_lost_scheduler_is_one_line_and_the_written_outputs_stay(tmp_path, cluster):
    src = tmp_path / "in"
    src.mkdir()
    for k in range(10):
        (src / f"f{k}").symlink_to(BAGS / "flange_shift", target_is_directory=True)
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "fastsim_ros.replay", *sorted(map(str, src.iterdir())), "-o",
         str(out), "--csv", "--scheduler", cluster.address], cwd=ROOT, env=ENV,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not (out.is_dir() and any(p.name.endswith(".csv") for p in out.iterdir())):
        assert time.monotonic() < deadline and proc.poll() is None
        time.sleep(0.005)
    cluster.procs[0].send_signal(signal.SIGKILL)   # the scheduler
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 1
    assert stderr.count("\n") == 1 and "Traceback" not in stderr
    assert f"lost the Dask scheduler at {cluster.address}" in stderr
    assert "the outputs already written stay" in stderr
    # what was committed is whole (a worker still running may commit a bag after)
    done = [p for p in out.iterdir() if not p.name.startswith(".") and p.is_dir()]
    assert done
    for bag in done:
        if (out / f"{bag.name}.csv").exists():
            with Reader(bag) as reader:
                assert sum(1 for _ in reader.messages()) == reader.message_count > 4000


def test_an_unreachable_scheduler_is_one_line(tmp_path, monkeypatch):
    monkeypatch.setitem(ENV, "FASTSIM_DASK_CONNECT_TIMEOUT", "2")   # not the default 10 s
    started = time.monotonic()
    proc = replay(BAGS / "hertz_ramp", "-o", tmp_path / "out", "--scheduler",
                  "tcp://127.0.0.1:9", timeout=120)
    assert time.monotonic() - started < 9.0
    assert proc.returncode == 1
    assert proc.stderr.count("\n") == 1
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_jobs_and_scheduler_together_are_refused(tmp_path):
    proc = replay(BAGS / "hertz_ramp", "-o", tmp_path / "out", "--jobs", "2", "--scheduler",
                  "tcp://127.0.0.1:9")
    assert proc.returncode == 2 and "give one" in proc.stderr
    assert not (tmp_path / "out").exists()


def _estimate_lines(stdout: str) -> list[str]:
    return [line for line in stdout.splitlines() if "estimate" in line]


@pytest.mark.parametrize("url", [False, True])
def test_an_overwrite_on_a_cluster_shows_the_estimate_and_survives_a_killed_worker(
        tmp_path, url):
    """adhesion_rig over an earlier output, the worker killed with that output set aside.

    The task runs again and finishes the commit it journalled: the new
    outputs (bag, CSV, friction CSV) in place, the earlier ones gone, the
    summary with the friction estimate as a local run gives it.
    """
    params = BAGS / "adhesion_rig.params.yaml"
    local = replay(BAGS / "adhesion_rig", "-o", tmp_path / "local", "--csv", "--params", params)
    assert local.returncode == 0, local.stderr
    out = tmp_path / "out"
    out.mkdir()
    (out / "adhesion_rig").mkdir()
    (out / "adhesion_rig" / "earlier.txt").write_text("of the earlier run")
    (out / "adhesion_rig.csv").write_text("earlier\n")
    (out / "adhesion_rig.friction.csv").write_text("earlier\n")
    refused = replay(BAGS / "adhesion_rig", "-o", out, "--csv", "--params", params)
    assert refused.returncode == 2 and "exists already" in refused.stderr
    hold = tmp_path / "hold"
    hold.mkdir()
    logs = tmp_path / "logs"
    logs.mkdir()
    # an overwrite into a URL sets the earlier outputs aside inside its commit (no moment)
    moment = "commit" if url else faults.REPLACE
    cluster = LocalProcesses(logs, 2, env=dict(ENV, **{faults.ENV: f"{moment}:{hold}"}),
                             cwd=ROOT)
    try:
        proc = subprocess.Popen(
            [sys.executable, "-m", "fastsim_ros.replay", str(BAGS / "adhesion_rig"), "-o",
             f"file://{out}" if url else str(out), "--csv", "--params", str(params),
             "--overwrite", "--scheduler", cluster.address],
            cwd=ROOT, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            kill_held_worker(cluster, hold, proc)
            stdout, stderr = proc.communicate(timeout=300)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
    finally:
        cluster.close()
    assert proc.returncode == 0, stderr
    assert stderr == ""
    assert sorted(p.name for p in out.iterdir()) == [
        "adhesion_rig", "adhesion_rig.csv", "adhesion_rig.friction.csv"]
    assert not (out / "adhesion_rig" / "earlier.txt").exists()
    for name in ("adhesion_rig.csv", "adhesion_rig.friction.csv"):
        assert (out / name).read_text() == (tmp_path / "local" / name).read_text()
    assert comparable(out / "adhesion_rig") == comparable(tmp_path / "local" / "adhesion_rig")
    assert _estimate_lines(stdout) == _estimate_lines(local.stdout) != []
    assert "retried: 2 attempts" in stdout


def test_a_scheduler_file_is_read_only_once_it_holds_the_address(tmp_path):
    """The scheduler writes its file in place: empty or half-written, it gives no address yet."""
    from fastsim_ros.replay.cluster import _scheduler_address
    file = tmp_path / "scheduler.json"
    assert _scheduler_address(file) is None
    for partial in ("", '{"type": "Scheduler", "add', '{"type": "Scheduler"}'):
        file.write_text(partial)
        assert _scheduler_address(file) is None
    file.write_text('{"type": "Scheduler", "address": "tcp://127.0.0.1:40123"}')
    assert _scheduler_address(file) == "tcp://127.0.0.1:40123"
