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


def test_the_default_model_is_the_published_forces(capsys, made_by_the_calibrated_mae):
    """The calibrated MAE's own forces (its knee corrected strip by strip) fit its own mu_s."""
    rc, out, err = run(capsys, *estimate(made_by_the_calibrated_mae, "--method",
                                         "mae_calibrated", "--json"))
    assert rc == 0 and err == ""
    r = json.loads(out)
    assert r["model_correction"] == "knee_strips"
    assert "fastsim_ros/contact/knee.py" in r["model_correction_note"]
    # the model made the samples: no second factor, mu_s as made
    assert abs(r["mu_static"] - MU) < max(2.0 * r["sigma_mu_static"], 0.002 * MU)
    rc, out, err = run(capsys, *estimate(made_by_the_calibrated_mae, "--method",
                                         "mae_calibrated"))
    assert rc == 0
    assert f"model correction: knee_strips: {r['model_correction_note']}" in out


def test_another_fast_model_names_the_knee_factor(capsys, made_by_the_calibrated_mae):
    """The paper's MAE carries the ellipse's knee factor on its whole force, and says so."""
    rc, out, err = run(capsys, *estimate(made_by_the_calibrated_mae, "--method", "mae",
                                         "--json"))
    assert rc == 0 and err == ""
    r = json.loads(out)
    assert r["model_correction"] == "knee_factor"
    assert "fastsim_ros/contact/knee.py" in r["model_correction_note"]


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
    from fastsim_ros.ros.params import SPECS
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


CONTACT = __import__("pathlib").Path(__file__).parent / "data" / "contact_tractcurv.csv"


def contact_measured(tmp_path, series):
    """Write the printed Fx of one series of CONTACT's tractcurv example as ``--measured``."""
    import csv
    lines = [line for line in CONTACT.read_text().splitlines() if not line.startswith("#")]
    rows = ["xi,eta,phi,Fx"] + [f"{r['cksi']},0,0,{r['fx']}" for r in csv.DictReader(lines)
                                if r["series"] == series]
    path = tmp_path / f"{series}.csv"
    path.write_text("\n".join(rows) + "\n")
    return path


EUROSPRINTER = ["--shape", "ellipse", "--a", "6.304e-3", "--b", "12.61e-3", "--load",
                "106700", "--nu", "0.28", "--shear-modulus", "8.2e10", "--speed", "10",
                "--allow-implausible", "--json"]


def test_exact_falling_law_on_contacts_coulomb_curve_answers(capsys, tmp_path):
    """The exact model under the falling law converges on every point and finds Coulomb's."""
    path = contact_measured(tmp_path, "exact_coulomb")
    rc, out, err = run(capsys, "estimate", "--measured", path, *EUROSPRINTER,
                       "--friction-law", "exponential", "--method", "exact")
    assert rc == 0, err
    res = json.loads(out)
    assert res["mu_static"] == pytest.approx(0.33, rel=0.01)
    # constant friction: A at 1 within its sigma, the fit as good as Coulomb's
    assert res["friction_limit_ratio"] > 0.99
    assert res["worst_error_percent_mu_N"] < 0.5


def test_known_slope_reduction_recovers_the_modified_fastsim_law(capsys, tmp_path):
    """With its reduction given, the modified-FastSim curve gives mu_s 0.36, A 0.38 (5%)."""
    path = contact_measured(tmp_path, "modified_fastsim")
    rc, out, err = run(capsys, "estimate", "--measured", path, *EUROSPRINTER,
                       "--friction-law", "exponential", "--method", "fastsim_ellipse",
                       "--bound", "parabolic", "--slope-k0", "0.54", "--slope-alpha-inf",
                       "0.02", "--slope-beta", "0.62")
    assert rc == 0, err
    res = json.loads(out)
    assert res["mu_static"] == pytest.approx(0.36, rel=0.05)
    assert res["friction_limit_ratio"] == pytest.approx(0.38, rel=0.05)
    assert res["worst_error_percent_mu_N"] < 2.0
    assert res["slope_reduction"] == {"k0": 0.54, "alpha_inf": 0.02, "beta": 0.62}
    # the exact theory has its full slope: the reduction is refused with it
    rc, out, err = run(capsys, "estimate", "--measured", path, *EUROSPRINTER,
                       "--method", "exact", "--slope-k0", "0.5")
    assert rc == 2 and "fast method" in err


def test_contacts_modified_fastsim_parameters_recovered(capsys, tmp_path):
    """Fitted with the law: mu_s, A, B and k0, alpha_inf, beta of CONTACT's curve within 5%."""
    path = contact_measured(tmp_path, "modified_fastsim")
    rc, out, err = run(capsys, "estimate", "--measured", path, *EUROSPRINTER,
                       "--friction-law", "exponential", "--method", "fastsim_ellipse",
                       "--bound", "parabolic", "--fit-slope-reduction")
    assert rc == 0, err
    res = json.loads(out)
    red = res["slope_reduction"]
    for got, want in ((res["mu_static"], 0.36), (res["friction_limit_ratio"], 0.38),
                      (res["friction_decay"], 0.7), (red["k0"], 0.54),
                      (red["alpha_inf"], 0.02), (red["beta"], 0.62)):
        assert got == pytest.approx(want, rel=0.05)
    assert res["worst_error_percent_mu_N"] < 2.0


def test_interface_layer_curve_says_what_it_cannot_determine(capsys, tmp_path):
    """On the interface-layer curve mu_s is within 3%, the reduction's shape left open."""
    path = contact_measured(tmp_path, "exact_interface_layer")
    rc, out, err = run(capsys, "estimate", "--measured", path, *EUROSPRINTER,
                       "--friction-law", "exponential", "--method", "fastsim_ellipse",
                       "--fit-slope-reduction")
    assert rc == 0, err
    res = json.loads(out)
    assert res["mu_static"] == pytest.approx(0.33, rel=0.03)
    assert res["worst_error_percent_mu_N"] < 2.0
    red = res["slope_reduction"]
    # k0, alpha_inf and beta trade off along the curve: not all three are pinned
    assert red["beta"] is None or red["sigma_k0"] is None or red["sigma_k0"] > 0.1
