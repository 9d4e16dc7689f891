"""Polach's method (Polach 1999, 2005) on the equivalent ellipse: its limits and its gap."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from fastsim_ros.contact.area import ellipse
from fastsim_ros.contact.errors import EmptyContactError, InvalidInputError
from fastsim_ros.contact.friction import ConstantFriction, ExponentialFriction
from fastsim_ros.contact.polach import PolachSolver, polach_forces
from fastsim_ros.contact.slope_reduction import SlopeReduction
from fastsim_ros.contact.tables import coefficient_table

DATA = Path(__file__).parent / "data" / "contact_tractcurv.csv"
A, B, LOAD, NU, G = 6.304e-3, 12.61e-3, 106700.0, 0.28, 8.2e10
C11, C22, C23 = coefficient_table(NU).kalker(A / B)


def forces(sx: float, sy: float, psi: float, mu: float = 0.3, **kw: float) -> tuple[float,
                                                                                    float]:
    f = polach_forces(A, B, LOAD, C11, C22, C23, G, mu, sx, sy, psi, **kw)
    return f.fx, f.fy


def test_linear_limits_are_kalkers() -> None:
    """Small creepage: Kalker's linear theory, C11, C22 and C23 (the spin's lateral force)."""
    fx, _ = forces(1e-8, 0.0, 0.0)
    assert fx == pytest.approx(-G * A * B * C11 * 1e-8, rel=1e-6)
    _, fy = forces(0.0, 1e-8, 0.0)
    assert fy == pytest.approx(-G * A * B * C22 * 1e-8, rel=1e-6)
    _, fy = forces(0.0, 0.0, 1e-6)
    assert fy == pytest.approx(-G * (A * B) ** 1.5 * C23 * 1e-6, rel=1e-5)


def test_reduction_factors_scale_the_initial_slope() -> None:
    """Polach 2005: the initial slope is (kA + kS)/2 of Kalker's; saturation is mu N still."""
    fx, _ = forces(1e-8, 0.0, 0.0, k_a=0.3, k_s=0.1)
    assert fx == pytest.approx(-0.2 * G * A * B * C11 * 1e-8, rel=1e-6)
    fx, _ = forces(50.0, 0.0, 0.0, k_a=0.3, k_s=0.1)
    # 2/pi (kA e/(1 + kA^2 e^2) + arctan(kS e)) -> 1 as eps grows
    assert -fx / (0.3 * LOAD) == pytest.approx(1.0, abs=2e-3)


def test_full_slip_is_mu_n_along_the_creepage() -> None:
    fx, fy = forces(0.6, 0.8, 0.0)
    assert math.hypot(fx, fy) == pytest.approx(0.3 * LOAD, rel=1e-3)
    assert fx / fy == pytest.approx(0.6 / 0.8, rel=1e-12)


def test_large_pure_spin_lateral_force_vanishes() -> None:
    """K_M -> 0: a spin pole at the centre in full slip gives no net lateral force."""
    _, small = forces(0.0, 0.0, 1e-3)
    _, mid = forces(0.0, 0.0, 2.0)
    _, big = forces(0.0, 0.0, 5e4)
    assert small < 0.0 and mid < 0.0
    assert abs(big) < 0.01 * abs(mid)


def contact_series(name: str) -> list[tuple[float, float]]:
    lines = [line for line in DATA.read_text().splitlines() if not line.startswith("#")]
    return [(float(r["cksi"]), abs(float(r["fx"]))) for r in csv.DictReader(lines)
            if r["series"] == name]


def test_contact_exact_curve_gap_is_at_the_knee() -> None:
    """Against CONTACT's exact Coulomb curve: within 6.5% of mu N, worst at the knee."""
    solver = PolachSolver(NU, G)
    area = ellipse(A, B, nx=60, ny=60, load=LOAD)
    errors = [(cksi, (abs(solver.solve(area, cksi, 0.0, 0.0, mu=0.33).fx) - fx) / (0.33 * LOAD))
              for cksi, fx in contact_series("exact_coulomb")]
    worst = max(errors, key=lambda e: abs(e[1]))
    assert 0.03 < abs(worst[1]) < 0.065
    assert 0.002 <= worst[0] <= 0.004   # the knee of this case (saturation near 0.0035)
    assert all(abs(e) < 1e-3 for c, e in errors if c >= 0.02)   # full slip: mu N both


def test_solver_on_a_patch_moves_to_the_centre_and_takes_the_law() -> None:
    area = ellipse(A, B, nx=40, ny=40, load=LOAD).shifted(2e-3, -1e-3)
    solver = PolachSolver(NU, G)
    f = solver.solve(area, 1e-3, 2e-4, 0.5, mu=0.3)
    # the creepages about the origin moved to the centre (2e-3, -1e-3): xi - phi y_c, ...
    e = solver.solve(ellipse(A, B, nx=40, ny=40, load=LOAD), 1e-3 + 0.5 * 1e-3,
                     2e-4 + 0.5 * 2e-3, 0.5, mu=0.3)
    assert (f.fx, f.fy) == pytest.approx((e.fx, e.fy), rel=1e-9)
    assert f.mz == pytest.approx(2e-3 * f.fy + 1e-3 * f.fx, rel=1e-12)
    law = ExponentialFriction(0.36, 0.38, 0.7)
    falling = solver.solve(area, 0.2, 0.0, 0.0, friction=law, speed=10.0)
    assert -falling.fx == pytest.approx(float(law.mu(10.0 * 0.2)) * LOAD, rel=2e-3)


def test_batch_equals_single_solves() -> None:
    area = ellipse(A, B, nx=30, ny=30, load=LOAD)
    solver = PolachSolver(NU, G, k_a=0.5, k_s=0.2)
    creep = np.array([[1e-3, 0.0, 0.0], [2e-3, -1e-3, 0.4], [0.05, 0.01, -1.0]])
    batch = solver.solve_batch(area.pressure, area.x0, area.y0, area.dx, area.dy, creep,
                               mu=0.3)
    for row, c in zip(batch, creep):
        one = solver.solve(area, *c, mu=0.3)
        assert tuple(row) == (one.fx, one.fy, one.mz)


def test_refusals() -> None:
    area = ellipse(A, B, nx=20, ny=20, load=LOAD)
    with pytest.raises(InvalidInputError, match="kS <= kA"):
        PolachSolver(NU, G, k_a=0.1, k_s=0.3)
    with pytest.raises(InvalidInputError, match="no traction field"):
        PolachSolver(NU, G).solve(area, 1e-3, 0.0, 0.0, mu=0.3, tractions=True)
    with pytest.raises(InvalidInputError, match="kA, kS"):
        PolachSolver(NU, G).solve(area, 1e-3, 0.0, 0.0, friction=ConstantFriction(
            0.3, reduction=SlopeReduction(0.5, 0.1, 1.0)))
    with pytest.raises(InvalidInputError, match="finite"):
        PolachSolver(NU, G).solve(area, math.nan, 0.0, 0.0, mu=0.3)
    with pytest.raises(EmptyContactError):
        PolachSolver(NU, G).solve_arrays(np.zeros((4, 4)), 0.0, 0.0, 1e-3, 1e-3, 1e-3, 0.0,
                                         0.0, 0.3)
