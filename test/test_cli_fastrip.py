"""``fastsim_contact forces --method fastrip``: the FaStrip baseline from the command line."""

import json

import numpy as np
import pytest

from fastsim_ros import cli
from fastsim_ros.contact import area as areas
from fastsim_ros.contact import samples
from fastsim_ros.contact.fastrip import fastrip
from fastsim_ros.contact.tables import coefficient_table

ELLIPSE = ("forces", "--shape", "ellipse", "--a", "6e-3", "--b", "4e-3", "--load", "1e4",
           "--mu", "0.3")


def run(capsys, *argv):
    rc = cli.main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def test_same_keys_as_the_other_methods_and_the_library_numbers(capsys):
    creep = ("--xi", "2e-4", "--eta", "-1e-4", "--phi", "0.05")
    rc, out, err = run(capsys, *ELLIPSE, *creep, "--method", "fastrip", "--json")
    assert rc == 0 and err == ""
    r = json.loads(out)
    rc, out, _ = run(capsys, *ELLIPSE, *creep, "--method", "mae", "--json")
    m = json.loads(out)
    keys = {"Fx", "Fy", "Mz", "N", "slip_fraction", "method", "bound", "cells"}
    assert keys <= r.keys() and keys <= m.keys()
    assert r["method"] == "fastrip" and r["bound"] == "given" and r["cells"] == [60, 60]
    ar = areas.ellipse(6e-3, 4e-3, nx=60, ny=60, load=1e4)
    lib = fastrip(ar, 2e-4, -1e-4, 0.05, mu=0.3, table=coefficient_table(0.28),
                  shear_modulus=8e10)
    assert (r["Fx"], r["Fy"], r["Mz"]) == pytest.approx((lib.fx, lib.fy, lib.mz), rel=1e-12)
    assert r["N"] == pytest.approx(1e4, rel=1e-12)
    assert 0.0 < r["slip_fraction"] < 1.0
    # partial slip: the longitudinal force opposes xi, the total stays below mu N
    assert r["Fx"] < 0 and np.hypot(r["Fx"], r["Fy"]) < 0.3 * r["N"]


def test_full_slip_gives_mu_n(capsys):
    rc, out, _ = run(capsys, *ELLIPSE, "--xi", "0.05", "--eta", "0", "--phi", "0",
                     "--method", "fastrip", "--json")
    r = json.loads(out)
    assert rc == 0
    assert r["Fx"] == pytest.approx(-0.3 * r["N"], rel=1e-9) and r["slip_fraction"] == 1.0


def test_a_patch_file(tmp_path, capsys):
    ar = samples.notched_ellipse(cells=30, scale=0.01, load=2e4)
    jj, ii = np.nonzero(ar.mask)
    rows = ["x,y,pressure"] + [f"{float(ar.x[i])!r},{float(ar.y[j])!r},"
                               f"{float(ar.pressure[j, i])!r}" for j, i in zip(jj, ii)]
    path = tmp_path / "notch.csv"
    path.write_text("\n".join(rows) + "\n")
    rc, out, err = run(capsys, "forces", "--patch", str(path), "--xi", "1e-4", "--eta", "0",
                       "--phi", "0.2", "--mu", "0.3", "--method", "fastrip", "--json")
    assert rc == 0 and err == ""
    r = json.loads(out)
    lib = fastrip(ar, 1e-4, 0.0, 0.2, mu=0.3, table=coefficient_table(0.28),
                  shear_modulus=8e10)
    assert (r["Fx"], r["Fy"], r["Mz"]) == pytest.approx((lib.fx, lib.fy, lib.mz), rel=1e-9)


@pytest.mark.parametrize("extra, words", [
    (("--bound", "parabolic"), "--bound given"),
    (("--friction-law", "exponential", "--friction-limit-ratio", "0.5", "--friction-decay",
      "1", "--speed", "10"), "constant friction"),
])
def test_refused_options_give_one_line_and_exit_2(capsys, extra, words):
    rc, out, err = run(capsys, *ELLIPSE, "--xi", "1e-4", "--eta", "0", "--phi", "0",
                       "--method", "fastrip", *extra)
    assert rc == 2 and out == ""
    assert words in err and err.count("\n") == 1
