"""``fastsim_contact forces``'s wear and fatigue keys (docs/guide_wear.md)."""

import json

import pytest

from fastsim_ros import cli
from fastsim_ros.contact.wear import BURSTOW_RCF, SHEFFIELD_WEAR

#: CONTACT's tractcurv case (docs/data/contact_tractcurv_power.csv), case 5: xi = 1.6e-3
CONTACT = ("--shape", "ellipse", "--a", "6.304e-3", "--b", "12.61e-3", "--load", "106700",
           "--nu", "0.28", "--shear-modulus", "8.2e10", "--mu", "0.33", "--xi", "1.6e-3",
           "--eta", "0", "--phi", "0")
CONTACT_POWER = 419.6  # W, FRIC.POWER as printed (negated: the traction on the wheel)


def forces(capsys, *argv):
    assert cli.main(["forces", *argv, "--json"]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    return json.loads(out)


@pytest.mark.parametrize("method, bound, within", [
    ("exact", "given", 0.004), ("mae_calibrated", "parabolic", 0.06),
    ("mae", "parabolic", 0.06), ("fastsim_ellipse", "parabolic", 0.06)])
def test_forces_json_carries_t_gamma_wear_rcf_and_the_frictional_power(
        capsys, method, bound, within):
    """Every key from the result's own forces; the power against CONTACT's FRIC.POWER.

    Measured at xi = 1.6e-3 (the knee): the exact solver (44 x 44 cells)
    419.3 W, 0.07% under CONTACT's 419.6 W; the fast methods (parabolic
    bound, 60 x 60) 5.6% under.
    """
    cells = ["--cells", "44"] if method == "exact" else []
    f = forces(capsys, *CONTACT, "--method", method, "--bound", bound, "--speed", "10",
               *cells)
    tg = abs(f["Fx"] * 1.6e-3 + f["Fy"] * 0.0 + f["Mz"] * 0.0)
    assert f["T_gamma"] == tg
    area = f["T_gamma"] / f["T_gamma_per_area"]
    assert area == pytest.approx(3.14159 * 6.304e-3 * 12.61e-3, rel=0.03)  # the cells' area
    assert f["wear_rate"] == SHEFFIELD_WEAR(f["T_gamma_per_area"])
    assert f["rcf_damage"] == BURSTOW_RCF(f["T_gamma"])
    assert f["frictional_power"] == pytest.approx(f["frictional_dissipation"] * 10.0,
                                                  rel=1e-15)
    assert f["slip_share"] == pytest.approx(f["frictional_dissipation"] / f["T_gamma"],
                                            rel=1e-15)
    assert f["frictional_power"] == pytest.approx(CONTACT_POWER, rel=within)
    assert f["frictional_power"] < CONTACT_POWER


def test_without_speed_no_power_but_the_dissipation_per_metre(capsys):
    f = forces(capsys, *CONTACT, "--method", "mae_calibrated", "--bound", "parabolic")
    assert f["frictional_power"] is None
    assert f["frictional_dissipation"] == pytest.approx(CONTACT_POWER / 10.0, rel=0.06)


def test_a_method_without_slip_velocities_gives_null(capsys):
    f = forces(capsys, *CONTACT, "--method", "dlm", "--speed", "10")
    assert f["frictional_power"] is None and f["slip_share"] is None
    assert f["T_gamma"] == abs(f["Fx"] * 1.6e-3)


def test_the_readable_table_names_the_units(capsys):
    assert cli.main(["forces", *CONTACT, "--speed", "10"]) == 0
    out = capsys.readouterr()[0]
    assert "T_gamma = " in out and " N\n" in out
    assert "frictional_power = " in out and " W" in out
    assert "wear_rate = " in out and "kg/(m m^2)" in out
