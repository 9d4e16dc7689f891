"""The creep-slope reduction of contaminated rails (modified FastSim) in every fast method.

CONTACT's published modified-FastSim curve of the Eurosprinter case
(test/data/contact_tractcurv.csv, from CONTACT's examples/tractcurv.ref_out,
Apache-2.0, E. Vollebregt) is the yardstick; no reduction is today's numbers
to the bit.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from fastsim_ros.contact.area import GridArea, ellipse
from fastsim_ros.contact.asm import asm_fastsim
from fastsim_ros.contact.compiled import (CalibratedMaeSolver, EquivalentEllipseSolver,
                                          MaeSolver)
from fastsim_ros.contact.equivalent import equivalent_fastsim, reduce_slope
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.fastsim import traction_bound
from fastsim_ros.contact.friction import ConstantFriction, ExponentialFriction, friction_law
from fastsim_ros.contact.mae import mae_fastsim
from fastsim_ros.contact.slope_reduction import SlopeReduction, total_creepage
from fastsim_ros.contact.tables import coefficient_table

DATA = Path(__file__).parent / "data" / "contact_tractcurv.csv"
# the Eurosprinter case of CONTACT's tractcurv example
A, B, LOAD, NU, G, SPEED = 6.304e-3, 12.61e-3, 106700.0, 0.28, 8.2e10, 10.0
EUROSPRINTER = SlopeReduction(0.54, 0.02, 0.62)
POLACH_LAW = ExponentialFriction(0.36, 0.38, 0.7, reduction=EUROSPRINTER)
SOLVERS = {"fastsim_ellipse": EquivalentEllipseSolver, "mae": MaeSolver,
           "mae_calibrated": CalibratedMaeSolver}


def contact_series(name: str) -> list[tuple[float, float]]:
    """Return ``(cksi, |Fx|)`` (1, N) of one of CONTACT's series."""
    lines = [line for line in DATA.read_text().splitlines() if not line.startswith("#")]
    return [(float(row["cksi"]), abs(float(row["fx"]))) for row in csv.DictReader(lines)
            if row["series"] == name]


@pytest.fixture(scope="module")
def patch() -> GridArea:
    return ellipse(A, B, nx=60, ny=60, load=LOAD)


def skewed_patch() -> GridArea:
    """Make a non-elliptical patch (a pear: wider at one side), Hertz-like pressure."""
    n = 40
    x = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    y = x.copy()
    xx, yy = np.meshgrid(x, y)
    half = 0.7 + 0.25 * yy
    inside = (xx / half) ** 2 + yy ** 2 < 1.0
    p = np.where(inside, np.sqrt(np.clip(1.0 - (xx / half) ** 2 - yy ** 2, 0.0, None)), 0.0)
    area = GridArea(-7e-3 + 0.5 * 14e-3 / n, -7e-3 + 0.5 * 14e-3 / n, 14e-3 / n, 14e-3 / n,
                    p * 1e9)
    return area.with_load(80e3)


@pytest.mark.parametrize("method", sorted(SOLVERS))
def test_contact_modified_fastsim_curve_within_two_percent(patch: GridArea, method: str) -> None:
    """Every printed point of CONTACT's modified-FastSim curve within 2% of mu_s N."""
    solver = SOLVERS[method](NU, G)
    worst = 0.0
    for cksi, fx in contact_series("modified_fastsim"):
        ours = abs(solver.solve(patch, cksi, 0.0, 0.0, friction=POLACH_LAW, speed=SPEED,
                                bound="parabolic").fx)
        worst = max(worst, abs(ours - fx) / (0.36 * LOAD))
    # the gap is that of plain FastSim to CONTACT's (Kalker's L1 against CONTACT's
    # blended flexibilities): 1.2% on the Coulomb series
    assert worst < 0.02


def test_plain_fastsim_gap_is_the_reduced_one(patch: GridArea) -> None:
    """The same method without reduction is as close to CONTACT's plain FastSim curve."""
    solver = EquivalentEllipseSolver(NU, G)
    worst = max(abs(abs(solver.solve(patch, cksi, 0.0, 0.0, mu=0.33, bound="parabolic").fx)
                    - fx) / (0.33 * LOAD) for cksi, fx in contact_series("fastsim_coulomb"))
    assert 0.005 < worst < 0.015


@pytest.mark.parametrize("reduction", [SlopeReduction(), SlopeReduction(1.0, 1.0, 0.62),
                                       SlopeReduction(1.0, 0.3, 0.0)])
@pytest.mark.parametrize("law", ["constant", "exponential"])
def test_no_reduction_is_todays_numbers_to_the_bit(reduction: SlopeReduction, law: str) -> None:
    """With k = 1 at every creepage every solver's forces are bit for bit those without."""
    area = skewed_patch()
    plain = friction_law(law, 0.3, limit_ratio=0.4, decay=0.6)
    reduced = friction_law(law, 0.3, limit_ratio=0.4, decay=0.6, reduction=reduction)
    creep = np.array([[1e-3, -2e-4, 0.3], [4e-3, 1e-3, -1.0], [2e-2, 0.0, 0.0]])
    for cls in SOLVERS.values():
        solver = cls(NU, G)
        for xi, eta, phi in creep:
            a = solver.solve(area, xi, eta, phi, friction=plain, speed=SPEED, tractions=True)
            b = solver.solve(area, xi, eta, phi, friction=reduced, speed=SPEED, tractions=True)
            assert (a.fx, a.fy, a.mz, a.slip_fraction) == (b.fx, b.fy, b.mz, b.slip_fraction)
            assert np.array_equal(a.tau_x, b.tau_x) and np.array_equal(a.tau_y, b.tau_y)
        batch = [solver.solve_batch(area.pressure, area.x0, area.y0, area.dx, area.dy, creep,
                                    friction=f, speed=SPEED) for f in (plain, reduced)]
        assert np.array_equal(batch[0], batch[1])
    table = coefficient_table(NU)
    for f_a, f_b in ((plain, reduced),):
        e1 = equivalent_fastsim(area, 1e-3, 2e-4, 0.5, friction=f_a, speed=SPEED, table=table,
                                shear_modulus=G)
        e2 = equivalent_fastsim(area, 1e-3, 2e-4, 0.5, friction=f_b, speed=SPEED, table=table,
                                shear_modulus=G)
        assert (e1.fx, e1.fy, e1.mz) == (e2.fx, e2.fy, e2.mz)
        g = traction_bound(area, 0.3)
        m1 = mae_fastsim(area, 1e-3, 2e-4, 0.5, bound=g, table=table, shear_modulus=G,
                         friction=f_a, speed=SPEED)
        m2 = mae_fastsim(area, 1e-3, 2e-4, 0.5, bound=g, table=table, shear_modulus=G,
                         friction=f_b, speed=SPEED)
        assert (m1.fx, m1.fy, m1.mz) == (m2.fx, m2.fy, m2.mz)


def test_compiled_equals_numpy_reference_under_reduction() -> None:
    """The compiled solvers apply the reduction as the numpy references do (to rounding)."""
    area = skewed_patch()
    table = coefficient_table(NU)
    law = ExponentialFriction(0.3, 0.4, 0.6, reduction=SlopeReduction(0.5, 0.1, 0.8))
    for xi, eta, phi in ((1e-3, -2e-4, 0.3), (4e-3, 1e-3, -1.0), (3e-2, 0.0, 0.0)):
        ref = equivalent_fastsim(area, xi, eta, phi, friction=law, speed=SPEED, table=table,
                                 shear_modulus=G)
        got = EquivalentEllipseSolver(NU, G).solve(area, xi, eta, phi, friction=law,
                                                   speed=SPEED)
        assert got.fx == pytest.approx(ref.fx, rel=1e-9, abs=1e-6)
        assert got.fy == pytest.approx(ref.fy, rel=1e-9, abs=1e-6)
        ref_m = mae_fastsim(area, xi, eta, phi, bound=traction_bound(area, 0.3), table=table,
                            shear_modulus=G, friction=law, speed=SPEED)
        got_m = MaeSolver(NU, G).solve(area, xi, eta, phi, friction=law, speed=SPEED)
        assert got_m.fx == pytest.approx(ref_m.fx, rel=1e-9, abs=1e-6)
        assert got_m.mz == pytest.approx(ref_m.mz, rel=1e-9, abs=1e-9)


def test_batch_equals_single_solves_under_reduction() -> None:
    area = skewed_patch()
    law = ExponentialFriction(0.3, 0.4, 0.6, reduction=SlopeReduction(0.5, 0.1, 0.8))
    creep = np.array([[1e-3, -2e-4, 0.3], [4e-3, 1e-3, -1.0], [3e-2, 0.0, 0.0]])
    speeds = np.array([5.0, 10.0, 20.0])
    for cls in SOLVERS.values():
        solver = cls(NU, G)
        batch = solver.solve_batch(area.pressure, area.x0, area.y0, area.dx, area.dy, creep,
                                   friction=law, speed=speeds)
        for row, (xi, eta, phi), v in zip(batch, creep, speeds):
            one = solver.solve(area, xi, eta, phi, friction=law, speed=v)
            assert tuple(row) == (one.fx, one.fy, one.mz)


def test_initial_slope_is_k0_of_the_theorys(patch: GridArea) -> None:
    """At vanishing creepage the force is the full-slope force at k0 xi: the slope is k0's."""
    solver = EquivalentEllipseSolver(NU, G)
    xi = 1e-6
    reduced = solver.solve(patch, xi, 0.0, 0.0, friction=POLACH_LAW, speed=SPEED).fx
    full = solver.solve(patch, xi, 0.0, 0.0, mu=0.36).fx
    assert reduced / full == pytest.approx(0.54, rel=1e-3)
    # full slip (Kalker's parabolic bound, as CONTACT's case): the force is mu at the
    # rigid slip velocity times N, although k xi is only 4e-3 there
    xi = 0.25
    big = abs(solver.solve(patch, xi, 0.0, 0.0, friction=POLACH_LAW, speed=SPEED,
                           bound="parabolic").fx)
    mu_rigid = float(POLACH_LAW.mu(SPEED * xi))
    assert big == pytest.approx(mu_rigid * LOAD, rel=1e-3)


def test_factor_formula_and_constant_reduction() -> None:
    """The factor is k0 [alpha + (1 - alpha)/(1 + beta eps)], eps = G pi a b k0 C11 w/(4 mu N)."""
    r = SlopeReduction(0.54, 0.02, 0.62)
    c11 = coefficient_table(NU).kalker(A / B)[0]
    w = 3e-3
    eps = G * math.pi * A * B * 0.54 * c11 * w / (4.0 * 0.3 * LOAD)
    k = r.factor(w, a=A, b=B, c11=c11, shear_modulus=G, load=LOAD, mu=0.3)
    assert k == pytest.approx(0.54 * (0.02 + 0.98 / (1.0 + 0.62 * eps)), rel=1e-14)
    # alpha_inf = 1: the slope is k0's at every creepage
    assert SlopeReduction(0.4, 1.0, 5.0).factor(w, a=A, b=B, c11=c11, shear_modulus=G,
                                                load=LOAD, mu=0.3) == 0.4
    # spin adds phi a to eta unless it lessens |eta|
    assert total_creepage(0.0, 1e-3, 0.1, 0.01) == pytest.approx(2e-3)
    assert total_creepage(0.0, 1e-3, -0.1, 0.01) == pytest.approx(1e-3)


def test_reduce_slope_runs_constant_friction_at_rigid_slip() -> None:
    area = skewed_patch()
    law = ExponentialFriction(0.3, 0.4, 0.6, reduction=SlopeReduction(0.5, 0.1, 0.8))
    red = reduce_slope(area, 3e-3, 4e-3, 0.0, law, 10.0, table=coefficient_table(NU),
                       shear_modulus=G)
    mu = 0.3 * (0.6 * math.exp(-0.6 * 10.0 * 5e-3) + 0.4)
    assert isinstance(red.friction, ConstantFriction)
    assert red.friction.mu_s == pytest.approx(mu, rel=1e-14)
    assert 0.05 < red.k < 0.5
    assert (red.xi, red.eta) == (red.k * 3e-3, red.k * 4e-3)


def test_numpy_seed_methods_apply_the_reduction() -> None:
    """ASM + FastSim with a reduction: the force at vanishing creepage is k0 of the full one."""
    area = skewed_patch()
    law = ConstantFriction(0.3, reduction=SlopeReduction(0.5, 0.1, 0.8))
    red = asm_fastsim(area, 1e-7, 0.0, 0.0, mu=0.3, nu=NU, shear_modulus=G, friction=law)
    full = asm_fastsim(area, 1e-7, 0.0, 0.0, mu=0.3, nu=NU, shear_modulus=G)
    assert red.fx / full.fx == pytest.approx(0.5, rel=1e-3)


@pytest.mark.parametrize("args", [(0.0, 0.5, 1.0), (1.2, 0.5, 1.0), (0.5, -0.1, 1.0),
                                  (0.5, 1.1, 1.0), (0.5, 0.5, -1.0), (0.5, 0.5, math.nan),
                                  (math.inf, 0.5, 1.0)])
def test_bad_reduction_refused(args: tuple[float, float, float]) -> None:
    with pytest.raises(InvalidInputError):
        SlopeReduction(*args)


def test_slip_dependent_reduced_law_needs_speed(patch: GridArea) -> None:
    with pytest.raises(InvalidInputError, match="speed"):
        EquivalentEllipseSolver(NU, G).solve(patch, 1e-3, 0.0, 0.0, friction=POLACH_LAW)


def test_paths_that_cannot_apply_a_reduction_refuse_it(patch: GridArea) -> None:
    """The exact theory, FastSim's bare sweep and the transient step never drop it silently."""
    from fastsim_ros.contact import exact
    from fastsim_ros.contact.fastsim import StripFlexibility, fastsim
    from fastsim_ros.contact.transient import TransientSolver
    small = ellipse(A, B, nx=12, ny=12, load=LOAD)
    with pytest.raises(InvalidInputError, match="full slope"):
        exact.coulomb(small, 1e-3, 0.0, 0.0, nu=NU, shear_modulus=G, friction=POLACH_LAW,
                      speed=SPEED)
    ones = np.ones(small.ny)
    with pytest.raises(InvalidInputError, match="slope reduction"):
        fastsim(small, 1e-3, 0.0, 0.0, bound=traction_bound(small, 0.36),
                flexibility=StripFlexibility(ones, ones, ones, ones), friction=POLACH_LAW,
                speed=SPEED)
    step = TransientSolver(CalibratedMaeSolver(NU, G))
    with pytest.raises(InvalidInputError, match="slope reduction"):
        step.step(None, small.pressure, small.x0, small.y0, small.dx, small.dy, 1e-3, 0.0,
                  0.0, 1e-3, friction=POLACH_LAW, speed=SPEED)
