"""``fastsim_contact estimate`` names the correction its model applies to the method's force."""

import json

import numpy as np
import pytest

from fastsim_ros import cli
from fastsim_ros.contact import area as areas

A_AX, B_AX, LOAD, MU = 6e-3, 4e-3, 5e4, 0.35


def run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def made_by_the_calibrated_mae(tmp_path_factory):
    """Write the forces ``forces --method mae_calibrated`` gives at mu 0.35 (uncorrected)."""
    from fastsim_ros.contact.compiled import CalibratedMaeSolver
    ar = areas.ellipse(A_AX, B_AX, nx=20, ny=20, load=LOAD)
    solver = CalibratedMaeSolver(0.28, 8e10)
    rows = ["xi,eta,phi,Fx"]
    for xi in (float(v) for v in np.linspace(1e-3, 2e-2, 10)):
        rows.append(f"{xi!r},0,0,{solver.solve(ar, xi, 0.0, 0.0, mu=MU).fx!r}")
    path = tmp_path_factory.mktemp("estimate") / "measured.csv"
    path.write_text("\n".join(rows) + "\n")
    return path


def estimate(path, *extra):
    return ["estimate", "--measured", path, "--shape", "ellipse", "--a", str(A_AX), "--b",
            str(B_AX), "--load", str(LOAD), "--cells", "20", *extra]


def test_a_fast_model_names_the_knee_factor_that_moves_mu(capsys, made_by_the_calibrated_mae):
    """The method's own forces fit another mu_s: the knee factor says why, in JSON and text."""
    rc, out, err = run(capsys, *estimate(made_by_the_calibrated_mae, "--method",
                                         "mae_calibrated", "--json"))
    assert rc == 0 and err == ""
    r = json.loads(out)
    assert r["model_correction"] == "knee_factor"
    assert "fastsim_ros/contact/knee.py" in r["model_correction_note"]
    # the knee factor's share: mu_s off by more than its sigma, within the knee error
    assert abs(r["mu_static"] - MU) > max(r["sigma_mu_static"], 0.005 * MU)
    assert abs(r["mu_static"] - MU) < 0.06 * MU
    rc, out, err = run(capsys, *estimate(made_by_the_calibrated_mae, "--method",
                                         "mae_calibrated"))
    assert rc == 0
    assert f"model correction: knee_factor: {r['model_correction_note']}" in out


@pytest.mark.parametrize("extra, note", [
    ((), "the exact theory's forces, uncorrected"),   # the default model: exact
    (("--method", "mae_calibrated", "--bound", "parabolic"),
     "tabulated for --bound given only")])
def test_no_correction_is_named_none(capsys, made_by_the_calibrated_mae, extra, note):
    rc, out, err = run(capsys, *estimate(made_by_the_calibrated_mae, *extra, "--json"))
    assert rc == 0 and err == ""
    r = json.loads(out)
    assert r["model_correction"] == "none" and note in r["model_correction_note"]
    assert r["method"] == (extra[1] if extra else "exact")


def test_the_defaults_are_the_nodes_and_shown_in_the_help(capsys):
    from fastsim_ros.params import SPECS
    args = cli.build_parser().parse_args(estimate("m.csv"))
    assert args.mu == SPECS["friction_coefficient"].default
    assert args.nu == SPECS["poisson_ratio"].default
    assert args.shear_modulus == SPECS["shear_modulus"].default
    assert args.bound == SPECS["traction_bound"].default
    assert args.method == "exact"
    rc, out, _ = run(capsys, "estimate", "--help")
    text = " ".join(out.split())
    for shown in ("default 0.3", "default 0.28", "default 8e+10", "exact (default"):
        assert shown in text, shown
