"""The knee factors: FastSim's creep force against the exact theory at the same creepage."""

from __future__ import annotations

import csv
import math
from functools import partial
from importlib import resources

import numpy as np
import pytest

from fastsim_ros.contact import exact
from fastsim_ros.contact import kernels as k
from fastsim_ros.contact.area import ellipse
from fastsim_ros.contact.compiled import CalibratedMaeSolver, EquivalentEllipseSolver, MaeSolver
from fastsim_ros.contact.errors import OutOfTableError
from fastsim_ros.contact.knee import KNEE_FILE, knee_factors, linear_force
from fastsim_ros.contact.samples import flange_root_patch
from fastsim_ros.estimation import ContactSample, CreepModel

G, LOAD = 8.0e10, 5.0e4


def table_rows() -> list[dict[str, str]]:
    text = resources.files("fastsim_ros.data").joinpath(KNEE_FILE).read_text("utf-8")
    return list(csv.DictReader(line for line in text.splitlines() if not line.startswith("#")))


def test_the_file_states_its_provenance_and_error():
    text = resources.files("fastsim_ros.data").joinpath(KNEE_FILE).read_text("utf-8")
    assert text.startswith("# Made by: python scripts/make_knee_table.py")
    rows = table_rows()
    # the exact force's change from 40 to 60 cells stays below a point of kappa (not its
    # error: finer grids move it further at the knee, scripts/make_knee_table.py)
    assert max(float(r["kappa_err"]) for r in rows) < 0.01
    assert {r["nu"] for r in rows} == {"0", "0.25", "0.5"}


@pytest.mark.parametrize("nu", [0.0, 0.25, 0.5])
def test_the_factor_is_the_table_at_its_nodes(nu):
    knee = knee_factors(nu)
    rows = [r for r in table_rows() if float(r["nu"]) == nu]
    for r in rows[::7]:
        share = 1.0 if r["direction"] == "xi" else 0.0
        kappa, _ = knee.factor(float(r["s"]), float(r["a_over_b"]), share)
        assert kappa == pytest.approx(float(r["kappa"]), abs=1e-12)


@pytest.mark.parametrize("aspect", [0.1, 0.6, 1.0, 2.7, 8.0])
@pytest.mark.parametrize("share", [0.0, 0.3, 1.0])
def test_one_at_rest_and_in_full_slip_continuous_between(aspect, share):
    knee = knee_factors(0.28)
    assert knee.factor(0.0, aspect, share)[0] == pytest.approx(1.0, abs=1e-12)
    # FastSim's leading-edge band fades: the factor tends to 1 far in full slip
    assert abs(knee.factor(200.0, aspect, share)[0] - 1.0) < 1e-5
    # continuous at the last node (the 1/s^2 tail joins the table)
    last = float(knee.s[-1])
    below = knee.factor(last * (1 - 1e-9), aspect, share)
    above = knee.factor(last, aspect, share)
    assert below[0] == pytest.approx(above[0], abs=1e-8)
    # and its slope (the filter's gain has no jump there, nor at an inner node)
    assert below[1] == pytest.approx(above[1], abs=1e-6)
    node = float(knee.s[20])
    left, right = knee.factor(node * (1 - 1e-9), aspect, share), knee.factor(node, aspect, share)
    assert left[1] == pytest.approx(right[1], abs=1e-6)
    # the knee: FastSim's force is low by several per cent at s = 2 on every ellipse
    assert 1.04 < knee.factor(2.0, aspect, share)[0] < 1.08
    # early partial slip: FastSim's force is high
    assert 0.93 < knee.factor(0.5, aspect, share)[0] < 0.97


@pytest.mark.parametrize("s", [0.23, 1.37, 2.04, 9.5])
def test_the_slope_is_the_factors_derivative(s):
    knee = knee_factors(0.28)
    h = 1e-7
    central = (knee.factor(s + h, 1.7, 0.6)[0] - knee.factor(s - h, 1.7, 0.6)[0]) / (2 * h)
    assert knee.factor(s, 1.7, 0.6)[1] == pytest.approx(central, rel=1e-5, abs=1e-9)


def test_nu_outside_the_tables_is_refused():
    with pytest.raises(OutOfTableError, match="nu = 0.6"):
        knee_factors(0.6)


@pytest.mark.parametrize("mu", [0.0, -0.1, math.nan, math.inf])
def test_a_mu_the_laws_refuse_has_no_factor(mu):
    from fastsim_ros.contact.errors import InvalidInputError
    area = ellipse(6e-3, 4e-3, nx=20, ny=20, load=LOAD)
    model = CreepModel(CalibratedMaeSolver(0.28, G, knee=False))
    s = ContactSample(area.pressure, area.x0, area.y0, area.dx, area.dy, 3e-3, 0.0, 0.0, 20.0,
                      ((1.0, 0.0),))
    with pytest.raises(InvalidInputError, match="mu_s must be finite"):
        model.knee_factor(s, mu)


@pytest.mark.parametrize("aspect", [0.4, 1.0, 2.5])
def test_the_linear_force_is_fastsims_in_full_adhesion(aspect):
    """``F_lin`` on the equivalent ellipse: the force the method gives at an infinite mu."""
    a = math.sqrt(24e-6 / math.pi * aspect)
    area = ellipse(a, a / aspect, nx=40, ny=40, load=LOAD)
    solver = CalibratedMaeSolver(0.28, G, knee=False)
    ell = np.empty(k.ELL_SIZE)
    status, _ = k.equivalent_prepare(np.ascontiguousarray(area.pressure), area.x0, area.y0,
                                     area.dx, area.dy, G, solver._knots, solver._polys, ell)
    assert status == k.OK
    xi, eta, phi = 1e-4, -2e-4, 0.05
    fx, fy = linear_force(ell[k.ELL_A], ell[k.ELL_B], ell[k.ELL_L1], ell[k.ELL_L2],
                          ell[k.ELL_L3], xi, eta, phi)
    f = solver.solve(area, xi, eta, phi, mu=1e9)
    # the creep force is minus Kalker's linear one; the staircase's ellipse within 1%
    assert -f.fx == pytest.approx(fx, rel=0.01)
    assert -f.fy == pytest.approx(fy, rel=0.01)


def model_errors(solver, area, nu, xi, eta, phi, mu=0.3):
    """Return the knee-corrected and the plain model's error against the exact theory (mu N)."""
    s = ContactSample(area.pressure, area.x0, area.y0, area.dx, area.dy, xi, eta, phi, 20.0,
                      ((1.0, 0.0), (0.0, 1.0)))
    fe = exact.coulomb(area, xi, eta, phi, nu=nu, shear_modulus=G, mu=mu)
    errors = []
    for knee in (True, False):
        f = CreepModel(solver, knee=knee).predict([s], mu)
        errors.append(math.hypot(f[0] - fe.fx, f[1] - fe.fy) / (mu * s.load))
    return errors


@pytest.mark.parametrize("method", [partial(CalibratedMaeSolver, knee=False), MaeSolver,
                                    EquivalentEllipseSolver])
@pytest.mark.parametrize("xi, eta", [(2.5e-3, 1.4e-3), (3e-3, 0.0), (4e-3, 2e-3)])
def test_off_the_nodes_within_half_a_point_of_the_exact_theory(method, xi, eta):
    # a/b 0.6, nu 0.3, oblique creepage: none of them a node of the table (measured: 1.8-2.2%
    # of mu N plain, 0.1-0.3% with the factor)
    a = math.sqrt(24e-6 / math.pi * 0.6)
    area = ellipse(a, a / 0.6, nx=40, ny=40, load=LOAD)
    corrected, plain = model_errors(method(0.3, G), area, 0.3, xi, eta, 0.0)
    assert corrected < 0.005 and plain > 0.015


@pytest.mark.parametrize("xi", [1e-3, 3e-3, 5e-3])
def test_on_a_flange_root_patch(xi):
    # not an ellipse: MAE's zones, the factor at the equivalent ellipse's a/b (measured: 0.3-0.7%
    # of mu N with it, 1.9-4.1% without)
    corrected, plain = model_errors(CalibratedMaeSolver(0.28, G, knee=False),
                                    flange_root_patch(cells=30), 0.28, xi, 0.0, 0.0)
    assert corrected < 0.008 and plain > 2.0 * corrected


@pytest.mark.parametrize("eta, phi, bound", [(2e-3, 2.0, 0.005), (0.0, 1.0, 0.01),
                                             (0.0, 3.0, 0.035)])
def test_with_spin_within_the_measured_bounds(eta, phi, bound):
    """The tables hold no spin (the module states the limit measured over 20 cases).

    Lateral creepage with spin (both in ``F_lin``'s lateral part) gains most
    (2.3 to 0.1% of mu N here); xi across spin is the weak case (3 1/m: 3.2%
    with the factor, 2.2% without): each within the error measured for it.
    """
    a = math.sqrt(24e-6 / math.pi * 0.6)
    area = ellipse(a, a / 0.6, nx=40, ny=40, load=LOAD)
    xi = 0.0 if eta else 3e-3
    corrected, _ = model_errors(CalibratedMaeSolver(0.3, G, knee=False), area, 0.3, xi, eta, phi)
    assert corrected < bound


def test_the_parabolic_bound_is_not_corrected():
    model = CreepModel(CalibratedMaeSolver(0.28, G, knee=False), bound="parabolic")
    area = ellipse(6e-3, 4e-3, nx=20, ny=20, load=LOAD)
    s = ContactSample(area.pressure, area.x0, area.y0, area.dx, area.dy, 4e-3, 0.0, 0.0, 20.0,
                      ((1.0, 0.0),))
    assert not model.knee_corrected and model.knee_factor(s, 0.3) == (1.0, 0.0)


def test_reverse_running_turns_the_spins_share():
    # V < 0: the solver takes the patch turned by 180 degrees and the spin negated, so the
    # spin's part of F_lin changes sign against the creepage's: another s
    area = flange_root_patch(cells=30)
    model = CreepModel(CalibratedMaeSolver(0.28, G, knee=False))
    forward, reverse = (model.knee_factor(ContactSample(
        area.pressure, area.x0, area.y0, area.dx, area.dy, 0.0, 2e-3, 2.0, v, ((1.0, 0.0),)),
        0.3) for v in (20.0, -20.0))
    assert forward != reverse
    # the reverse one is the forward factor of the patch turned by 180 degrees, spin negated
    p = area.pressure[::-1, ::-1]
    turned = model.knee_factor(ContactSample(
        p, -(area.x0 + (p.shape[1] - 1) * area.dx), -(area.y0 + (p.shape[0] - 1) * area.dy),
        area.dx, area.dy, 0.0, 2e-3, -2.0, 20.0, ((1.0, 0.0),)), 0.3)
    assert reverse == turned
    plain = [model.knee_factor(ContactSample(
        area.pressure, area.x0, area.y0, area.dx, area.dy, 2e-3, 0.0, 0.0, v, ((1.0, 0.0),)),
        0.3)[0] for v in (20.0, -20.0)]
    assert plain[0] == pytest.approx(plain[1], rel=1e-9)  # no spin: the same s either way


@pytest.mark.parametrize("xi, eta, phi, speed", [(3e-3, 0.0, 0.0, 20.0),
                                                 (1e-3, -2e-3, 1.5, 20.0),
                                                 (2e-3, 1e-3, -0.7, -15.0)])
def test_the_compiled_factor_is_the_references(xi, eta, phi, speed):
    """The kernel (one call per contact per cycle) against the numpy modules composed."""
    from fastsim_ros.contact.equivalent import equivalent_ellipse
    from fastsim_ros.contact.fastsim import kalker_flexibility
    from fastsim_ros.contact.tables import coefficient_table

    area = flange_root_patch(cells=30)
    mu, nu = 0.3, 0.28
    model = CreepModel(CalibratedMaeSolver(nu, G, knee=False))
    sample = ContactSample(area.pressure, area.x0, area.y0, area.dx, area.dy, xi, eta, phi,
                           speed, ((1.0, 0.0),))
    kappa, dkappa = model.knee_factor(sample, mu)
    # the reference: the patch as the solver takes it (turned for V < 0), numpy's ellipse
    ar, spin = area, phi
    if speed < 0.0:
        from fastsim_ros.contact.area import GridArea
        p = area.pressure[::-1, ::-1]
        ar = GridArea(-(area.x0 + (p.shape[1] - 1) * area.dx),
                      -(area.y0 + (p.shape[0] - 1) * area.dy), area.dx, area.dy, p)
        spin = -phi
    e = equivalent_ellipse(ar)
    table = coefficient_table(nu)
    ls = kalker_flexibility(e.a, e.b, *table.kalker(e.a / e.b), G)
    fx, fy = linear_force(e.a, e.b, *ls, xi - spin * e.y_c, eta + spin * e.x_c, spin)
    s = math.hypot(fx, fy) / (mu * float(ar.pressure.sum()) * ar.dx * ar.dy)
    ref, dref = knee_factors(nu).factor(s, e.a / e.b, fx * fx / (fx * fx + fy * fy))
    assert kappa == pytest.approx(ref, rel=1e-9)
    assert dkappa == pytest.approx(-dref * s / mu, rel=1e-6)


# ---------------------------------------------------------------- strip by strip


def wheelset_patch(wheel: str, xi: float | None = None):
    """Return a tread patch of the default wheelset near zero shift, its creepages and load.

    S1002 on UIC60 1:40, 10 kN, 2 m/s, at -0.414 mm: the left patch nearly an
    ellipse, the right one 15 mm long and 3 mm wide with a wide end; ``xi``
    sets the axle spin (default: the longitudinal creepage the sweep of
    ``docs/validation_accuracy.md`` has, 4e-4 on the right wheel).
    """
    from fastsim_ros import cli
    from fastsim_ros.cli import wheelset as cli_wheelset
    from fastsim_ros.contact.area import GridArea
    spin = 4.3438 if xi is None else 2.0 * (1.0 - xi / 2.0) / (1.0 + xi / 2.0) / 0.46
    args = cli.build_parser().parse_args(["wheelset", "--dy", "-0.000414", "--yaw", "0",
                                          "--load", "1e4", "--axle-spin", repr(spin)])
    cycle, _ = cli_wheelset.solve_pose(args, -0.414e-3, 0.0)
    o = next(o for o in cycle.outcomes if o.contact == wheel)
    p = o.patch
    return (GridArea(p.x0, p.y0, p.dx, p.dy, np.array(p.pressure)),
            (o.creepage.xi, o.creepage.eta, o.creepage.phi), o.forces.n)


def test_strip_knee_compiled_is_the_reference():
    from fastsim_ros.contact.fastsim import traction_bound
    from fastsim_ros.contact.mae_calibrated import mae_calibrated_fastsim
    from fastsim_ros.contact.pairs import pair_factors
    from fastsim_ros.contact.tables import coefficient_table
    area = flange_root_patch(cells=30)
    mu, nu = 0.3, 0.28
    solver = CalibratedMaeSolver(nu, G)
    for xi, eta, phi in ((1.5e-3, 0.0, 0.0), (1e-3, 5e-4, 2.0), (0.0, 1e-3, -1.0)):
        mine = solver.solve(area, xi, eta, phi, mu=mu, tractions=True)
        ref = mae_calibrated_fastsim(area, xi, eta, phi, bound=traction_bound(area, mu),
                                     table=coefficient_table(nu), pairs=pair_factors(nu),
                                     shear_modulus=G, knee=knee_factors(nu))
        scale = mu * area.load
        for a, b in ((mine.fx, ref.fx), (mine.fy, ref.fy)):
            assert a == pytest.approx(b, abs=1e-12 * scale)
        assert mine.mz == pytest.approx(ref.mz, abs=1e-12 * scale * 0.01)
        np.testing.assert_allclose(mine.tau_x, ref.traction.tau_x, rtol=0,
                                   atol=1e-10 * area.pressure.max())
        # the tractions carry the factors: they sum to the forces
        assert mine.tau_x.sum() * area.dx * area.dy == pytest.approx(mine.fx, rel=1e-12)
        batch = solver.solve_batch(area.pressure, area.x0, area.y0, area.dx, area.dy,
                                   np.array([[xi, eta, phi]]), mu=mu)
        assert tuple(batch[0]) == (mine.fx, mine.fy, mine.mz)


@pytest.mark.parametrize("xi", [2e-4, 8e-4, 1.5e-3, 3e-3])
def test_strip_knee_on_an_ellipse_is_the_tabulated_factor(xi):
    """Every strip of an ellipse stands at the patch's ``s``: the factor is the table's."""
    a = math.sqrt(24e-6 / math.pi * 0.6)
    area = ellipse(a, a / 0.6, nx=40, ny=40, load=LOAD)
    plain = CalibratedMaeSolver(0.3, G, knee=False).solve(area, xi, 0.0, 0.0, mu=0.3)
    strips = CalibratedMaeSolver(0.3, G).solve(area, xi, 0.0, 0.0, mu=0.3)
    kappa, _ = CreepModel(CalibratedMaeSolver(0.3, G, knee=False)).knee_factor_of(
        area.pressure, area.x0, area.y0, area.dx, area.dy, xi, 0.0, 0.0, 2.0, 0.3)
    # the grid's strips stand at slightly different s (their discrete chords): 0.2 point
    assert abs(strips.fx - kappa * plain.fx) < 0.002 * 0.3 * LOAD


def test_strip_knee_keeps_the_linear_theory_and_full_slip():
    area = flange_root_patch(cells=30)
    plain = CalibratedMaeSolver(0.28, G, knee=False)
    strips = CalibratedMaeSolver(0.28, G)
    for creep in ((1e-11, 0.0, 0.0), (0.0, 1e-11, 1e-9)):
        a, b = plain.solve(area, *creep, mu=0.3), strips.solve(area, *creep, mu=0.3)
        assert (b.fx, b.fy) == pytest.approx((a.fx, a.fy), rel=1e-6)
    a, b = plain.solve(area, 0.05, 0.0, 0.0, mu=0.3), strips.solve(area, 0.05, 0.0, 0.0, mu=0.3)
    assert abs(b.fx - a.fx) < 1e-4 * 0.3 * area.load
    # the parabolic bound has another knee: not corrected
    a = plain.solve(area, 1.5e-3, 0.0, 0.0, mu=0.3, bound="parabolic")
    b = strips.solve(area, 1.5e-3, 0.0, 0.0, mu=0.3, bound="parabolic")
    assert (a.fx, a.fy, a.mz) == (b.fx, b.fy, b.mz)


@pytest.mark.parametrize("wheel, xi, plain_above, strips_below", [
    # the left patch nearly an ellipse: FastSim's knee is its whole error (measured 5.1% of
    # mu N plain, 0.5% strip by strip)
    ("left", None, 0.045, 0.01),
    ("left", 1.5e-3, 0.045, 0.01),
    # the right patch, long and narrow: its translational response 8% low in every fast method
    # (docs/validation_accuracy.md) and its knee not the ellipse's (measured 3.8% and 0.8%
    # plain, 2.1% and 0.8% strip by strip)
    ("right", None, 0.035, 0.025),
    ("right", 1.5e-3, 0.0, 0.01),
])
def test_strip_knee_against_the_exact_theory_on_tread_patches(wheel, xi, plain_above,
                                                              strips_below):
    area, creep, n = wheelset_patch(wheel, xi)
    ex = exact.coulomb(area, *creep, mu=0.3, nu=0.28, shear_modulus=G)
    errors = []
    for solver in (CalibratedMaeSolver(0.28, G, knee=False), CalibratedMaeSolver(0.28, G)):
        f = solver.solve(area, *creep, mu=0.3)
        errors.append(max(abs(f.fx - ex.fx), abs(f.fy - ex.fy)) / (0.3 * n))
    assert errors[0] > plain_above and errors[1] < strips_below
