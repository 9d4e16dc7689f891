"""``fastsim_contact``: unit mistakes are refused in one line; marked intended they are answered.

Each mistake of the table is a valid number in the wrong unit, which the
solvers answer with believable numbers: semi-axes in millimetres typed as
metres, a patch file in millimetres and megapascals, a load in kilonewtons
typed as newtons, a creepage or a friction coefficient as a percentage.  Each
is refused before any solve with exit status 2 and one line naming the value,
the unit expected and the likely mistake; with ``--allow-implausible`` the
same command is answered (or refused by a tool's hard range, which the flag
does not widen); the corrected command gives the solver's numbers.
"""

import json
from pathlib import Path

import numpy as np
import pytest

from fastsim_ros import cli
from fastsim_ros.cli import patch_files
from fastsim_ros.contact import area as areas

EXAMPLE = Path(__file__).resolve().parents[1] / "fastsim_ros" / "data" / "example_patch.csv"
ELLIPSE = ["--shape", "ellipse", "--a", "6e-3", "--b", "4e-3", "--load", "6e4"]
CREEP = ["--xi", "1e-3", "--eta", "0", "--phi", "0.1", "--mu", "0.3"]
POSE = ["wheelset", "--dy", "0", "--yaw", "0", "--roll", "0"]
A_AX, B_AX, LOAD, MU = 6e-3, 4e-3, 5e4, 0.3


def run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def replaced(argv, **flags):
    """Return the command line with the value after each named flag replaced.

    A keyword names its flag with underscores: ``shear_modulus`` is ``--shear-modulus``.
    """
    argv = list(argv)
    for name, value in flags.items():
        flag = "--" + name.replace("_", "-")
        argv[argv.index(flag) + 1] = value
    return argv


def scaled_patch(path, length=1.0, pressure=1.0):
    """Write the example patch, its coordinates times ``length``, pressures times ``pressure``."""
    ar = patch_files.read_patch(EXAMPLE)
    jj, ii = np.nonzero(ar.mask)
    rows = [f"{float(ar.x[i]) * length!r},{float(ar.y[j]) * length!r},"
            f"{float(ar.pressure[j, i]) * pressure!r}" for j, i in zip(jj, ii)]
    path.write_text("\n".join(["x,y,pressure", *rows]) + "\n")
    return path


def measured_curve(path, percent=False):
    """Write a creep curve the calibrated MAE gives at mu 0.3 (xi up to 0.02, or in percent)."""
    from fastsim_ros.contact.compiled import CalibratedMaeSolver
    ar = areas.ellipse(A_AX, B_AX, nx=20, ny=20, load=LOAD)
    solver = CalibratedMaeSolver(0.28, 8e10)
    rows = ["xi,eta,phi,Fx"]
    for xi in (float(v) for v in np.linspace(1e-3, 2e-2, 10)):
        fx = solver.solve(ar, xi, 0.0, 0.0, mu=MU).fx
        rows.append(f"{xi * (100.0 if percent else 1.0)!r},0,0,{fx!r}")
    path.write_text("\n".join(rows) + "\n")
    return path


def full_slip_curve(path):
    """Write a curve that runs to full slip (xi up to 0.2): a traction test, meant."""
    from fastsim_ros.contact.compiled import CalibratedMaeSolver
    ar = areas.ellipse(A_AX, B_AX, nx=20, ny=20, load=LOAD)
    solver = CalibratedMaeSolver(0.28, 8e10)
    rows = ["xi,eta,phi,Fx"]
    for xi in (2e-3, 5e-3, 1e-2, 2e-2, 5e-2, 0.1, 0.2):
        rows.append(f"{xi!r},0,0,{solver.solve(ar, xi, 0.0, 0.0, mu=MU).fx!r}")
    path.write_text("\n".join(rows) + "\n")
    return path


def estimate(measured, *extra):
    return ["estimate", "--measured", measured, "--shape", "ellipse", "--a", str(A_AX),
            "--b", str(B_AX), "--load", str(LOAD), "--cells", "20",
            "--method", "mae_calibrated", *extra]


#: (id, command (``PATCH_MM_MPA`` etc. replaced by files), the words naming the value,
#: its unit, the likely mistake, what --allow-implausible gives: "answer" or the hard refusal)
MISTAKES = [
    ("forces-semi-axes-in-mm", ["forces", *replaced(ELLIPSE, a="6", b="4"), *CREEP],
     "--a 6 m", "0.0001 to 0.05 m", "millimetres typed as metres", "answer"),
    ("forces-patch-in-mm-and-MPa", ["forces", "--patch", "PATCH_MM_MPA", *CREEP],
     "extent along x 12.75 m", "0.0002 to 0.1 m", "coordinates in millimetres", "answer"),
    ("forces-patch-in-MPa", ["forces", "--patch", "PATCH_MPA", *CREEP],
     "largest pressure 1783.79 Pa", "100000 to 1e+10 Pa", "megapascals typed as pascals",
     "answer"),
    ("forces-load-in-kN", ["forces", *replaced(ELLIPSE, load="60"), *CREEP],
     "--load 60 N", "100 to 1e+06 N", "kilonewtons typed as newtons", "answer"),
    ("forces-xi-in-percent", ["forces", *ELLIPSE, *replaced(CREEP, xi="0.2")],
     "--xi 0.2 ", "magnitude at most 0.1", "a percentage typed where the fraction belongs",
     "answer"),
    ("forces-eta-in-percent", ["forces", *ELLIPSE, *replaced(CREEP, eta="-0.5")],
     "--eta -0.5 ", "magnitude at most 0.1", "a percentage typed", "answer"),
    ("forces-spin-rate", ["forces", *ELLIPSE, *replaced(CREEP, phi="120")],
     "--phi 120 1/m", "magnitude at most 50 1/m", "a spin rate (rad/s)", "answer"),
    ("forces-mu-in-percent", ["forces", *ELLIPSE, *replaced(CREEP, mu="30")],
     "--mu 30 ", "0.001 to 5", "a percentage typed where the fraction belongs", "answer"),
    ("forces-G-in-GPa", ["forces", *ELLIPSE, *CREEP, "--shear-modulus", "80"],
     "--shear-modulus 80 Pa", "1e+09 to 5e+11 Pa", "gigapascals or megapascals typed",
     "answer"),
    ("forces-load-for-tiny-semi-axes",
     ["forces", *replaced(ELLIPSE, a="6e-4", b="4e-4", load="6e5"), *CREEP],
     "the largest pressure --load 600000 N gives", "100000 to 1e+10 Pa",
     "the load and the area's size do not belong together", "answer"),
    ("wheelset-load-in-kN", [*POSE, "--load", "10"],
     "--load 10 N", "100 to 1e+06 N", "kilonewtons typed as newtons", "answer"),
    ("wheelset-mu-in-percent", [*POSE, "--load", "1e4", "--mu", "30"],
     "--mu 30 ", "0.001 to 5", "a percentage typed", "--mu: 30.0 is not allowed"),
    ("wheelset-G-in-GPa", [*POSE, "--load", "1e4", "--shear-modulus", "80"],
     "--shear-modulus 80 Pa", "1e+09 to 5e+11 Pa", "gigapascals",
     "--shear-modulus: 80.0 is not allowed"),
    ("estimate-creepages-in-percent", estimate("MEASURED_PERCENT"),
     "measured_percent.csv, line 3: xi 0.311111 ", "magnitude at most 0.1",
     "a percentage typed", "answer"),
    ("estimate-semi-axes-in-mm", replaced(estimate("MEASURED"), a="6", b="4"),
     "--a 6 m", "0.0001 to 0.05 m", "millimetres typed as metres", "answer"),
    ("estimate-load-in-kN", replaced(estimate("MEASURED"), load="50"),
     "--load 50 N", "100 to 1e+06 N", "kilonewtons typed as newtons",
     "no friction coefficient in [0.001, 5] fits"),
    ("estimate-mu-in-percent", estimate("MEASURED", "--mu", "30"),
     "--mu 30 ", "0.001 to 5", "a percentage typed", "answer"),
]


@pytest.fixture
def files(tmp_path):
    return {"PATCH_MM_MPA": scaled_patch(tmp_path / "mm_mpa.csv", 1e3, 1e-6),
            "PATCH_MPA": scaled_patch(tmp_path / "mpa.csv", 1.0, 1e-6),
            "MEASURED": measured_curve(tmp_path / "measured.csv"),
            "MEASURED_PERCENT": measured_curve(tmp_path / "measured_percent.csv", True)}


def command(argv, files):
    return [str(files.get(a, a)) for a in argv]


@pytest.mark.parametrize("argv, what, unit, mistake, allowed",
                         [m[1:] for m in MISTAKES], ids=[m[0] for m in MISTAKES])
def test_a_unit_mistake_is_one_line_and_exit_2(capsys, files, argv, what, unit, mistake,
                                               allowed):
    rc, out, err = run(capsys, *command(argv, files))
    assert rc == 2 and out == "", err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    line = lines[0]
    assert line.startswith("fastsim_contact: error: ") and "Traceback" not in err
    assert what in line, line
    assert f"expected {unit}" in line, line
    assert f"likely {mistake}" in line, line
    assert line.endswith("if intended, give --allow-implausible"), line


@pytest.mark.parametrize("argv, allowed", [(m[1], m[5]) for m in MISTAKES],
                         ids=[m[0] for m in MISTAKES])
def test_marked_intended_the_value_is_taken(capsys, files, argv, allowed):
    rc, out, err = run(capsys, *command(argv, files), "--allow-implausible", "--json")
    if allowed == "answer":
        assert rc == 0 and err == "", err
        assert json.loads(out)
    else:
        # a tool's hard range (the node's parameter ranges, the fit's mu range) still holds,
        # or the fit says the value makes no sense of the samples
        assert rc == 2 and out == "" and allowed in err, err
        assert "implausible" not in err


def test_the_issues_mistakes_gave_believable_numbers_when_marked_intended(capsys, files):
    """What the mistakes gave unchecked: saturated or tiny forces that look like answers."""
    rc, out, _ = run(capsys, "forces", *replaced(ELLIPSE, a="6", b="4"), "--xi", "0.01",
                     "--eta", "0", "--phi", "0", "--mu", "0.3", "--allow-implausible", "--json")
    assert rc == 0 and json.loads(out)["Fx"] == pytest.approx(-0.3 * 6e4, rel=1e-6)
    rc, out, _ = run(capsys, "forces", "--patch", files["PATCH_MM_MPA"], *CREEP,
                     "--allow-implausible", "--json")
    # the millimetres' areas and the megapascals cancel in N: a believable 50 kN
    assert rc == 0 and json.loads(out)["N"] == pytest.approx(5e4, rel=1e-9)


def test_right_uses_give_the_solvers_numbers(capsys, files):
    """The mistakes corrected: the compiled solver's numbers (the default, the node's method)."""
    from fastsim_ros.contact.compiled import CalibratedMaeSolver
    solver = CalibratedMaeSolver(0.28, 8e10)
    f = json.loads(run(capsys, "forces", *ELLIPSE, *CREEP, "--json")[1])
    ref = solver.solve(areas.ellipse(6e-3, 4e-3, nx=60, ny=60, load=6e4), 1e-3, 0.0, 0.1,
                       mu=0.3)
    assert (f["Fx"], f["Fy"], f["Mz"]) == (ref.fx, ref.fy, ref.mz)
    assert f["N"] == pytest.approx(6e4, rel=1e-12)
    f = json.loads(run(capsys, "forces", "--patch", EXAMPLE, *CREEP, "--json")[1])
    ref = solver.solve(patch_files.read_patch(EXAMPLE), 1e-3, 0.0, 0.1, mu=0.3)
    assert (f["Fx"], f["Fy"], f["Mz"]) == (ref.fx, ref.fy, ref.mz)
    assert f["N"] == pytest.approx(5e4, rel=1e-9)
    # the file in metres and pascals, written back from the scaled one: the same numbers
    g = json.loads(run(capsys, "forces", "--patch", scaled_patch(
        files["PATCH_MPA"].with_name("m_pa.csv")), *CREEP, "--json")[1])
    assert (g["Fx"], g["Fy"], g["Mz"]) == (f["Fx"], f["Fy"], f["Mz"])


def test_right_uses_of_wheelset_and_estimate_are_answered(capsys, files):
    rc, out, err = run(capsys, *POSE, "--load", "1e4", "--json")
    assert rc == 0 and err == ""
    assert all(w["force_track"][2] == pytest.approx(1e4, rel=1e-3)
               for w in json.loads(out)["wheels"])
    rc, out, err = run(capsys, *command(estimate("MEASURED", "--json"), files))
    assert rc == 0 and err == ""
    assert json.loads(out)["mu_static"] == pytest.approx(MU, rel=0.05)


def test_a_full_slip_test_is_taken_when_marked_intended(capsys, tmp_path):
    path = full_slip_curve(tmp_path / "traction.csv")
    rc, out, err = run(capsys, *estimate(path, "--json"))
    assert rc == 2 and "traction.csv, line 8: xi 0.2 " in err
    rc, out, err = run(capsys, *estimate(path, "--allow-implausible", "--json"))
    assert rc == 0 and err == ""
    assert json.loads(out)["mu_static"] == pytest.approx(MU, rel=0.05)


@pytest.mark.parametrize("argv", [
    ["forces", *ELLIPSE, *CREEP],
    ["forces", "--patch", EXAMPLE, *CREEP],
    [*POSE, "--load", "1e4"],
])
def test_the_bounds_are_inclusive_and_the_flag_changes_no_right_answer(capsys, argv):
    plain = run(capsys, *argv, "--json")
    marked = run(capsys, *argv, "--allow-implausible", "--json")
    assert plain[0] == 0 and plain == marked


@pytest.mark.parametrize("values", [
    {"load": "100"}, {"a": "5e-2", "b": "5e-2", "load": "1e6"}, {"a": "1e-4", "b": "1e-4",
                                                                 "load": "100"},
    {"xi": "0.1"}, {"eta": "-0.1"}, {"phi": "50"}, {"mu": "5"}, {"mu": "0.001"},
    {"shear_modulus": "1e9"}, {"shear_modulus": "5e11"}])
def test_values_on_the_bounds_are_plausible(capsys, values):
    argv = replaced(["forces", *ELLIPSE, *CREEP, "--shear-modulus", "8e10"], **values)
    rc, out, err = run(capsys, *argv, "--json")
    assert rc == 0 and err == "", err


def test_coefficients_are_scale_free_and_take_no_such_check(capsys):
    # a unit area (semi-axes 0.56 m) is what coefficients are: nothing to refuse
    rc, out, err = run(capsys, "coefficients", "--shape", "ellipse", "--a-over-b", "1",
                       "--method", "mae", "--json")
    assert rc == 0 and err == ""
    rc, out, err = run(capsys, "coefficients", "--shape", "ellipse", "--a-over-b", "1",
                       "--allow-implausible")
    assert rc == 2 and "unrecognized arguments: --allow-implausible" in err


@pytest.mark.parametrize("command", ["forces", "estimate", "wheelset"])
def test_the_flag_and_the_bounds_are_in_the_help(capsys, command):
    rc, out, _ = run(capsys, command, "--help")
    assert rc == 0
    text = " ".join(out.split())
    assert "--allow-implausible" in text and "normal load per wheel 100 to 1e+06 N" in text
