"""``fastsim_contact wheelset``: its JSON, the sweep, the pipeline's numbers, bad input."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from fastsim_ros import cli
from fastsim_ros.geometry.wheelset import LOAD_TOLERANCE
from fastsim_ros.pipeline.profiles import ProfilePipeline
from fastsim_ros.pipeline import PipelineConfig
from msg_adapters.cdr import StampedTwist
from msg_adapters.profile_msgs import StampedPose, quaternion
from fastsim_ros.cli.wheelset import wheel_twist
from fastsim_ros.geometry.placement import Pose


def run(capsys, *argv):
    rc = cli.main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def done_when(tmp_path_factory):
    """Run the documented command: both wheels' patches and forces, the roll solved."""
    import io
    import contextlib
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        rc = cli.main(["wheelset", "--dy", "5e-3", "--yaw", "12e-3", "--load", "1e4",
                       "--speed", "2", "--json"])
    assert rc == 0
    return json.loads(out.getvalue())


def test_the_json_has_both_wheels_with_their_patches_and_track_forces(done_when):
    r = done_when
    assert {"wheels", "roll", "dz", "method"} <= r.keys()
    assert r["method"] == "mae_calibrated"
    assert [w["side"] for w in r["wheels"]] == ["left", "right"]
    keys = {"y", "z", "contact_angle", "N", "cells", "xi", "eta", "phi", "Fx", "Fy", "Mz",
            "penetration"}
    for wheel in r["wheels"]:
        assert len(wheel["force_track"]) == 3 and wheel["patches"]
        # the roll is solved so that both wheels carry 10 kN at one height
        assert wheel["force_track"][2] == pytest.approx(1e4, rel=10 * LOAD_TOLERANCE)
        for p in wheel["patches"]:
            assert keys <= p.keys()
            assert all(math.isfinite(p[k]) for k in keys)
            assert 0.0 < p["penetration"] < 1e-4 and p["cells"] >= 4
    left, right = r["wheels"]
    # shifted 5 mm to the left: the left wheel runs on its gauge corner, the right on
    # its tread; contact angles positive towards the track centre on both
    assert left["patches"][0]["y"] > 0.7 and right["patches"][0]["y"] < -0.7
    assert left["patches"][0]["contact_angle"] > 0.2 > right["patches"][0]["contact_angle"] > 0
    assert abs(r["dz"] - left["dz"]) < 1e-9 and abs(r["dz"] - right["dz"]) < 1e-9


def test_the_pipeline_given_that_roll_answers_with_the_same_numbers(done_when):
    # what the node does with a pose and a load message: the command line's numbers
    # within the documented 1e-9 (the pose's quaternion rounds roll and yaw by 1e-16,
    # which the iterative solves carry to about 4e-12 here)
    r = done_when
    config = PipelineConfig.from_values({"patch_source": "profiles", "wheel_load": 0.0})
    p = ProfilePipeline(config)
    pose = Pose(5e-3, r["dz"], 12e-3, r["roll"])
    p.on_wheel_twist(wheel_twist(pose, 2.0, 2.0 / 0.46, 0.0, 0.0))
    p.on_load(StampedTwist(0, "wheelset", (0.0, 0.0, 2e4), (0.0, 0.0, 0.0)))
    cycle = p.on_pose(StampedPose(0, "track", (0.0, 5e-3, r["dz"]),
                                  quaternion(r["roll"], 12e-3)))
    by = {o.contact: o for o in cycle.outcomes}
    for wheel in r["wheels"]:
        for patch in wheel["patches"]:
            f = by[patch["name"]].forces
            assert (f.fx, f.fy, f.mz, f.n) == pytest.approx(
                (patch["Fx"], patch["Fy"], patch["Mz"], patch["N"]), rel=1e-9)


def test_roll_given_solves_each_wheel_at_its_own_height(capsys):
    rc, out, err = run(capsys, "wheelset", "--dy", "0", "--yaw", "0", "--roll", "0", "--load",
                       "1e4", "--json")
    assert rc == 0 and err == ""
    r = json.loads(out)
    left, right = r["wheels"]
    # centred: mirror images, at one height
    assert left["dz"] == pytest.approx(right["dz"], abs=1e-12)
    assert left["patches"][0]["N"] == pytest.approx(right["patches"][0]["N"], rel=1e-9)
    assert left["force_track"][1] == pytest.approx(-right["force_track"][1], rel=1e-6)


def test_the_vertical_position_given_carries_what_it_carries(capsys):
    # 30 um below touching: each wheel carries more than at 10 kN's 16 um approach
    rc, out, err = run(capsys, "wheelset", "--dy", "0", "--yaw", "0", "--roll", "0", "--dz",
                       "-0.228e-3", "--json")
    assert rc == 0, err
    r = json.loads(out)
    assert all(1.5e4 < w["force_track"][2] < 1e5 for w in r["wheels"])


def test_a_lifted_wheelset_has_no_patches_and_no_force(capsys):
    rc, out, err = run(capsys, "wheelset", "--dy", "0", "--yaw", "0", "--roll", "0", "--dz",
                       "1e-3", "--json")
    assert rc == 0, err
    r = json.loads(out)
    assert all(w["patches"] == [] and w["force_track"] == [0.0, 0.0, 0.0] for w in r["wheels"])


@pytest.mark.parametrize("dz", ["1e-2", "2e-3"])
def test_a_wheelset_held_above_the_rails_with_its_roll_free_is_lifted(capsys, dz):
    """The roll to be solved at a height where no wheel touches: lifted, not an error.

    The levelling of both wheels' loads found them equal (zero) at both ends
    of its bracket and divided by their difference (an internal error, exit
    1), or, with one end touching, returned that end unsolved (10 mrad, one
    wheel 5 mm into its rail at 33 MN).
    """
    rc, out, err = run(capsys, "wheelset", "--dy", "0", "--yaw", "0", "--dz", dz, "--json")
    assert rc == 0, err
    r = json.loads(out)
    assert r["roll"] == 0.0
    assert all(w["patches"] == [] and w["force_track"] == [0.0, 0.0, 0.0] for w in r["wheels"])


def test_the_roll_at_a_given_height_levels_both_wheels(capsys):
    """A shifted wheelset at a given height: the roll found gives both wheels one vertical force.

    The bracket grows from a quarter of a milliradian: at once 10 mrad wide it
    sank a wheel 7.5 mm, past the rail profile (refused as a derailment).
    """
    rc, out, err = run(capsys, "wheelset", "--dy", "5e-3", "--yaw", "0", "--dz", "-1e-4",
                       "--json")
    assert rc == 0, err
    r = json.loads(out)
    left, right = r["wheels"]
    assert left["patches"] and right["patches"]
    assert left["force_track"][2] == pytest.approx(right["force_track"][2], rel=1e-4)
    assert 0.0 < r["roll"] < 1e-3


def test_the_exact_method_runs_on_the_same_patches(capsys):
    rc, out, err = run(capsys, "wheelset", "--dy", "0", "--yaw", "0", "--roll", "0", "--load",
                       "1e4", "--method", "exact", "--mu", "0.3", "--json")
    assert rc == 0, err
    r = json.loads(out)
    assert r["method"] == "exact"
    # a centred wheelset on its treads at rolling without longitudinal creepage at R0
    for w in r["wheels"]:
        assert abs(w["force_track"][0]) < 0.1 * 0.3 * 1e4


def test_a_sweep_writes_its_csv_and_figure(tmp_path, capsys):
    out_csv, out_png = tmp_path / "sweep.csv", tmp_path / "sweep.png"
    rc, out, err = run(capsys, "wheelset", "--sweep-dy", "0", "4e-3", "2e-3", "--sweep-yaw",
                       "0", "9.6e-3", "--load", "1e4", "--method", "fastsim_ellipse",
                       "-o", str(out_csv), "--plot", str(out_png), "--json")
    assert rc == 0, err
    summary = json.loads(out)
    assert summary["poses"] == 3 and summary["solved"] == 3
    rows = list(csv.DictReader(out_csv.open()))
    assert {r["dy"] for r in rows} == {"0.0", "0.002", "0.004"}
    assert {r["side"] for r in rows} == {"left", "right"}
    yaws = sorted({float(r["yaw"]) for r in rows})
    assert yaws == pytest.approx([0.0, 4.8e-3, 9.6e-3])
    assert all(float(r["wheel_Fz"]) == pytest.approx(1e4, rel=1e-5) for r in rows)
    assert out_png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sweep.csv", "sweep.png"]
    # written as any new file is (mkstemp's 0600 kept: others could not read the results)
    import os
    umask = os.umask(0)
    os.umask(umask)
    for path in (out_csv, out_png):
        assert path.stat().st_mode & 0o777 == 0o666 & ~umask


def test_the_table_output_names_both_wheels(capsys):
    rc, out, err = run(capsys, "wheelset", "--dy", "2e-3", "--yaw", "0", "--load", "1e4",
                       "--method", "fastsim_ellipse")
    assert rc == 0 and err == ""
    assert "left wheel" in out and "right wheel" in out and "Fz = 10000.0 N" in out


@pytest.mark.parametrize("argv, match", [
    (["--dy", "0", "--yaw", "0", "--load", "1e4", "--dz", "0"], "not allowed with"),
    (["--yaw", "0", "--load", "1e4"], "give --dy and --yaw"),
    (["--dy", "0", "--yaw", "0"], "one of the arguments --load --dz is required"),
    (["--dy", "0", "--yaw", "0", "--load", "-5"], r"--load must lie in \(0, 1e7\]"),
    (["--dy", "nan", "--yaw", "0", "--load", "1e4"], "not a finite number"),
    (["--dy", "-0.045", "--yaw", "0", "--roll", "0", "--load", "1e4"], "derailment"),
    (["--dy", "0", "--yaw", "0", "--load", "1e4", "--cell", "0"], "cell"),
    (["--dy", "0", "--yaw", "0", "--load", "1e4", "--wheel", "/nonexistent/w.prw"],
     "^fastsim_contact: error: --wheel: /nonexistent/w.prw: cannot read"),
    (["--dy", "0", "--yaw", "0", "--load", "1e4", "--rail", ""], "--rail: '' is not allowed"),
    (["--dy", "0", "--yaw", "0", "--load", "1e4", "--gauge-width", "9"],
     r"--gauge-width: 9.0 is not allowed; it must be in \[0.3, 3\]"),
    (["--dy", "0", "--yaw", "0", "--load", "1e4", "-o", "x.csv"], "-o and --plot belong"),
    (["--sweep-dy", "0", "1e300", "1e-300", "--load", "1e4", "-o", "x.csv"],
     "--sweep-dy gives inf poses, at most 10000"),
    (["--sweep-dy", "-1e308", "1e308", "1e307", "--load", "1e4", "-o", "x.csv"],
     "--sweep-dy gives inf poses"),
    (["--sweep-dy", "0", "2e-3", "1e-3", "--dy", "0", "--load", "1e4", "-o", "x.csv"],
     "either --dy or --sweep-dy"),
    (["--dy", "0", "--yaw", "0", "--sweep-yaw", "0", "1e-3", "--load", "1e4"],
     "--sweep-yaw belongs to --sweep-dy"),
], ids=["load-and-dz", "no-dy", "no-load", "negative-load", "nan", "derailment", "cell",
        "missing-file", "empty-rail", "gauge", "stray-output", "huge-sweep", "inf-sweep",
        "dy-and-sweep", "stray-sweep-yaw"])
def test_bad_input_is_one_line_and_exit_2(capsys, argv, match):
    rc, out, err = run(capsys, "wheelset", *argv)
    assert rc == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("fastsim_contact: error:")
    assert __import__("re").search(match, err), err


def test_a_looped_profile_file_is_refused_naming_it(tmp_path, capsys):
    t = np.linspace(0.0, 2 * np.pi, 40)
    path = tmp_path / "loop.txt"
    path.write_text("\n".join(f"{10 * math.cos(3 * a):.6f} {10 * math.sin(2 * a):.6f}"
                              for a in t))
    rc, out, err = run(capsys, "wheelset", "--dy", "0", "--yaw", "0", "--load", "1e4",
                       "--rail", str(path))
    assert rc == 2 and "loop.txt" in err and err.count("\n") == 1


@pytest.mark.parametrize("method", ["mae_calibrated", "mae", "fastsim_ellipse"])
def test_a_centred_wheelset_gets_mirrored_forces_on_its_two_wheels(capsys, method):
    """At dy = 0, yaw 0 the wheels' patches are mirror images: so are their forces.

    MAE split the left tread's patch at another strip than the right's (two
    bands of strips shared the longest chord): Fx -137 N left, +217 N right
    with ``mae``, a yaw moment from nothing.
    """
    rc, out, err = run(capsys, "wheelset", "--dy", "0", "--yaw", "0", "--load", "1e5",
                       "--method", method, "--json")
    assert rc == 0, err
    left, right = (w["patches"] for w in json.loads(out)["wheels"])
    assert len(left) == len(right) >= 1
    for p, q in zip(left, right):
        scale = 0.3 * p["N"]
        assert abs(p["N"] - q["N"]) < 1e-3 * p["N"]
        assert abs(p["Fx"] - q["Fx"]) < 2e-3 * scale, (p["Fx"], q["Fx"])
        assert abs(p["Fy"] + q["Fy"]) < 2e-3 * scale, (p["Fy"], q["Fy"])
        assert abs(p["Mz"] + q["Mz"]) < 2e-3 * scale * 0.01


@pytest.mark.parametrize("bad", ["csv", "plot"])
def test_a_sweep_target_that_cannot_be_written_is_refused_before_the_poses(tmp_path, capsys,
                                                                           monkeypatch, bad):
    """A directory given as -o or --plot: one line, exit 2, before any pose is solved.

    It was found after the sweep (minutes on a real one) as an internal error,
    exit 1, and a bad --plot left the CSV written.
    """
    from fastsim_ros.cli import wheelset as cli_wheelset
    (tmp_path / "adir.csv").mkdir()
    (tmp_path / "adir.png").mkdir()

    def no_pose(*args, **kwargs):
        raise AssertionError("a pose was solved")
    monkeypatch.setattr(cli_wheelset, "solve_pose", no_pose)
    out_csv = tmp_path / ("adir.csv" if bad == "csv" else "sweep.csv")
    out_png = tmp_path / ("adir.png" if bad == "plot" else "sweep.png")
    rc, out, err = run(capsys, "wheelset", "--sweep-dy", "0", "4e-3", "2e-3", "--load", "1e4",
                       "-o", str(out_csv), "--plot", str(out_png))
    assert rc == 2 and out == "" and err.count("\n") == 1
    assert "is a directory" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["adir.csv", "adir.png"]
