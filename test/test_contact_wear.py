"""Wear and fatigue indicators: T-gamma, the wear and RCF tables, the slip area's frictional power.

The frictional power is checked against CONTACT's ``FRIC.POWER`` of its
published traction curve (``docs/data/contact_tractcurv_power.csv``:
``examples/tractcurv.ref_out``, the Coulomb series) and against this
package's exact solver, whose dissipation is ``-tau . (w - du/dx)`` on the
slip cells with its own discrete operator.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import exact
from fastsim_ros.contact.compiled import (CalibratedMaeSolver, EquivalentEllipseSolver,
                                          MaeSolver)
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.traction import rigid_slip
from fastsim_ros.contact.wear import (BURSTOW_RCF, SHEFFIELD_WEAR, PiecewiseLinear,
                                      indicators, t_gamma)

ROOT = Path(__file__).resolve().parents[1]
# CONTACT's case (tractcurv.inp): Hertzian a, b (m), load (N), G (Pa), nu, mu, V (m/s)
A, B, LOAD, G, NU, MU, V = 6.304e-3, 12.61e-3, 106700.0, 8.2e10, 0.28, 0.33, 10.0


def contact_power() -> dict[int, tuple[float, float, float]]:
    """Return CONTACT's cases as ``case -> (xi, Fx (N), FRIC.POWER (W, as printed))``."""
    rows = {}
    for line in (ROOT / "docs" / "data" / "contact_tractcurv_power.csv").read_text().splitlines():
        if line[:1].isdigit():
            case, cksi, fx, _, power = line.split(",")
            rows[int(case)] = (float(cksi), float(fx), float(power))
    return rows


# ------------------------------------------------------------------------ T-gamma


@pytest.mark.parametrize("solver", [MaeSolver, CalibratedMaeSolver])
@pytest.mark.parametrize("creep", [(1e-3, 0.0, 0.0), (0.0, 1e-3, 0.0), (5e-4, -8e-4, 2.0),
                                   (2e-3, 1e-3, -3.0)])
def test_t_gamma_is_the_creep_forces_work_per_metre(solver, creep):
    """T-gamma = |Fx xi + Fy eta + Mz phi| = |sum tau . w dA| of the solve's own traction field.

    ``Mz`` about the reference point and the spin about the same point:
    ``int tau . w dA = Fx xi + Fy eta + Mz phi`` exactly for the rigid slip
    ``w = (xi - phi (y - yp), eta + phi (x - xp))`` (docs/guide_physics.md, conventions), so the
    index from the forces is the work of the tractions, to rounding.
    """
    area = areas.semi_ellipses(0.6, 1.6, cells=30).scaled(6e-3).with_load(7e4)
    ref = (1.3e-3, -0.8e-3)
    f = solver(NU, G).solve(area, *creep, mu=0.3, reference=ref, tractions=True)
    wx, wy = rigid_slip(area, *creep, ref)
    work = float((f.tau_x * wx + f.tau_y * wy).sum() * area.cell_area)
    tg = t_gamma(f.fx, f.fy, f.mz, *creep)
    assert tg == abs(f.fx * creep[0] + f.fy * creep[1] + f.mz * creep[2])
    assert tg == pytest.approx(abs(work), rel=1e-12)
    assert work < 0.0  # the creep forces oppose the creepages: energy is absorbed


# ------------------------------------------------------------------------ the tables


def test_sheffield_wear_function_at_and_between_its_breakpoints():
    """K = 5.3 below 10.4 N/mm^2, 55 up to 77.2, 61.9 x - 4778.7 above (ug/(m mm^2)), in SI."""
    mpa, k = 1e6, 1e-3  # 1 N/mm^2 in Pa, 1 ug/(m mm^2) in kg/(m m^2)
    w = SHEFFIELD_WEAR
    assert w(0.0) == pytest.approx(5.3 * k)
    assert w(5.0 * mpa) == pytest.approx(5.3 * k)
    assert w(math.nextafter(10.4 * mpa, 0.0)) == pytest.approx(5.3 * k)
    assert w(10.4 * mpa) == pytest.approx(55.0 * k)  # the severe regime from 10.4 on
    assert w(40.0 * mpa) == pytest.approx(55.0 * k)
    assert w(77.2 * mpa) == pytest.approx(55.0 * k)  # ... up to 77.2 included
    for tga in (80.0, 100.0, 250.0, 1000.0):  # the catastrophic line
        assert w(tga * mpa) == pytest.approx((61.9 * tga - 4778.7) * k, rel=1e-12)
    assert w(5000.0 * mpa) == w(1000.0 * mpa)  # held beyond the last breakpoint
    assert math.isnan(w(math.nan))


def test_burstow_rcf_function_at_and_between_its_breakpoints():
    """No damage below 15 N, (T-gamma - 15) 1e-6 up to 65 N, falling to zero at 175 N."""
    r = BURSTOW_RCF
    for tg, want in ((0.0, 0.0), (10.0, 0.0), (15.0, 0.0), (20.0, 5e-6), (40.0, 25e-6),
                     (65.0, 50e-6), (120.0, 25e-6), (175.0, 0.0), (400.0, 0.0)):
        assert r(tg) == pytest.approx(want, abs=1e-18), tg
    for tg in np.linspace(15.0, 65.0, 11):
        assert r(tg) == pytest.approx((tg - 15.0) * 1e-6, abs=1e-18)


def test_a_table_interpolates_and_holds_its_ends():
    t = PiecewiseLinear.of((1.0, 2.0, 2.0, 4.0), (1.0, 3.0, 10.0, 0.0))
    assert (t(0.0), t(1.0), t(1.5), t(2.0), t(3.0), t(4.0), t(9.0)) == (
        1.0, 1.0, 2.0, 10.0, 5.0, 0.0, 0.0)
    assert t(math.nextafter(2.0, 0.0)) == pytest.approx(3.0)


@pytest.mark.parametrize("x, y, words", [
    ((0.0,), (1.0,), "at least 2"),
    ((0.0, 1.0), (1.0,), "as many values"),
    ((0.0, math.inf), (1.0, 1.0), "not finite"),
    ((0.0, 1.0), (1.0, math.nan), "not finite"),
    ((0.0, 2.0, 1.0), (1.0, 1.0, 1.0), "must not decrease"),
    ((0.0, 1.0, 1.0, 1.0, 2.0), (0.0, 1.0, 2.0, 3.0, 4.0), "more than twice"),
    ((0.0, 0.0, 1.0), (0.0, 1.0, 2.0), "start or end with a jump"),
    ((0.0, 1.0), (1.0, -0.5), "negative"),
])
def test_a_bad_table_is_refused_with_its_reason(x, y, words):
    with pytest.raises(InvalidInputError, match=words):
        PiecewiseLinear.of(x, y)


def test_indicators_follow_the_tables():
    """T-gamma/A picks the wear regime, T-gamma the RCF damage; the power is dissipation x V."""
    w = indicators(-20000.0, 0.0, 0.0, 2e-3, 0.0, 0.0, area=2e-6, speed=-12.0, dissipation=30.0)
    assert w.t_gamma == pytest.approx(40.0)
    assert w.t_gamma_per_area == pytest.approx(20e6)  # 20 N/mm^2: severe
    assert w.wear_rate == pytest.approx(55e-3)
    assert w.rcf_damage == pytest.approx(25e-6)
    assert w.frictional_power == pytest.approx(360.0)  # |V| = 12 m/s
    assert w.slip_share == pytest.approx(0.75)
    none = indicators(-20000.0, 0.0, 0.0, 2e-3, 0.0, 0.0, area=2e-6, speed=12.0)
    assert math.isnan(none.frictional_power) and math.isnan(none.slip_share)
    own = indicators(-20000.0, 0.0, 0.0, 2e-3, 0.0, 0.0, area=2e-6, speed=12.0,
                     wear=PiecewiseLinear.of((0.0, 40e6), (0.0, 1.0)),
                     rcf=PiecewiseLinear.of((0.0, 80.0), (0.0, 1.0)))
    assert (own.wear_rate, own.rcf_damage) == pytest.approx((0.5, 0.5))


# ------------------------------------------------------------------------ frictional power

#: CONTACT's cases checked: the linear range, the knee, saturation, full slip
CASES = (2, 4, 6, 8, 10, 20, 30)


@pytest.fixture(scope="module")
def contact_area():
    # CONTACT's element size (0.2889 x 0.6304 mm): 44 x 40 cells across the ellipse
    return areas.ellipse(A, B, nx=44, ny=40, load=LOAD)


@pytest.fixture(scope="module")
def exact_powers(contact_area):
    op = exact.SteadyRollingOperator.of(contact_area, nu=NU, shear_modulus=G)
    rows = contact_power()
    out = {}
    for case in CASES:
        xi = rows[case][0]
        sol = exact.coulomb(contact_area, xi, 0.0, 0.0, mu=MU, nu=NU, shear_modulus=G,
                            operator=op)
        d, density = exact.slip_dissipation(contact_area, sol, xi, 0.0, 0.0, nu=NU,
                                            shear_modulus=G, operator=op)
        out[case] = (sol, d, density)
    return out


def test_exact_frictional_power_is_contacts(exact_powers):
    """The exact solver's V sum -tau . s dA against CONTACT's FRIC.POWER: within 0.35% per point.

    Measured: -0.33% at xi = 4e-4 (the linear range), within 0.1% from the
    knee on; CONTACT prints the power with the traction on the wheel,
    hence the sign.
    """
    rows = contact_power()
    for case in CASES:
        xi, fx, power = rows[case]
        _, d, _ = exact_powers[case]
        assert d * V == pytest.approx(-power, rel=3.5e-3), (case, d * V, power)


def test_exact_frictional_power_is_below_t_gamma_v(exact_powers):
    """Slip dissipates less than T-gamma V: the stick zone's elastic creep is not slip.

    The gap is the work carried out of the patch by the elastic field at
    the trailing edge: 18% of T-gamma V at xi = 4e-4 (CONTACT: 29.7 of 36.3
    W slip), a few tens of watts that no longer grow once the whole patch
    slips, so the share tends to 1.
    """
    rows = contact_power()
    shares = []
    for case in CASES:
        xi = rows[case][0]
        sol, d, density = exact_powers[case]
        tg = t_gamma(sol.fx, sol.fy, sol.mz, xi, 0.0, 0.0)
        assert 0.0 < d < tg
        assert (density >= -1e-6 * density.max()).all()  # dissipated, cell by cell
        assert np.count_nonzero(density[~sol.slip]) == 0  # nothing where it sticks
        shares.append(d / tg)
    assert all(b > a for a, b in zip(shares, shares[1:]))
    assert shares[0] < 0.85 and shares[-1] > 0.999


@pytest.mark.parametrize("solver", [MaeSolver, CalibratedMaeSolver, EquivalentEllipseSolver])
def test_fastsim_frictional_power_against_contact(solver):
    """The march's power (parabolic bound, Kalker's; 60 x 60 cells) against CONTACT's FRIC.POWER.

    Measured low by 3.3% in the linear range (xi = 4e-4: 28.7 W against
    29.7 W), by at most 5.7% at the knee (xi = 2e-3) and 1.2% at
    saturation (xi = 3.6e-3), under 0.1% beyond, every method alike:
    FastSim's slip zone grows from the trailing edge as the exact one
    does, a little later.  The sum of the density is the total.
    """
    worst = 0.06
    rows = contact_power()
    area = areas.ellipse(A, B, nx=60, ny=60, load=LOAD)
    s = solver(NU, G)
    for case in CASES:
        xi, _, power = rows[case]
        f = s.solve(area, xi, 0.0, 0.0, mu=MU, bound="parabolic", tractions=True)
        assert f.dissipation_density is not None
        assert f.dissipation == pytest.approx(float(f.dissipation_density.sum())
                                              * float(np.prod(f.grid[2:])), rel=1e-12)
        err = (f.dissipation * V + power) / -power
        assert err < 0.0 and -err < (worst if xi < 3.6e-3 else 0.015), (case, err)
        assert f.dissipation < t_gamma(f.fx, f.fy, f.mz, xi, 0.0, 0.0)


def test_no_slip_no_dissipation_and_full_slip_dissipates_t_gamma():
    """In near-full adhesion nothing slips; at full slip the dissipation tends to T-gamma."""
    area = areas.ellipse(A, B, nx=40, ny=40, load=LOAD)
    s = CalibratedMaeSolver(NU, G)
    f = s.solve(area, 1e-7, 0.0, 0.0, mu=MU, tractions=True)
    assert f.dissipation == 0.0
    f = s.solve(area, 0.05, 0.0, 0.0, mu=MU, tractions=True)
    assert f.dissipation / t_gamma(f.fx, f.fy, f.mz, 0.05, 0.0, 0.0) > 0.99


def test_no_tractions_no_dissipation():
    """Without tractions the solve does no extra sweep: the dissipation is NaN (not computed)."""
    area = areas.ellipse(A, B, nx=20, ny=20, load=LOAD)
    f = MaeSolver(NU, G).solve(area, 1e-3, 0.0, 0.0, mu=MU)
    assert math.isnan(f.dissipation) and f.dissipation_density is None
