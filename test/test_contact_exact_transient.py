"""The exact transient solver against CONTACT's published ``catt_to_cart`` (Cattaneo to Carter)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from fastsim_ros.contact.exact import coulomb
from fastsim_ros.contact.exact_transient import (TransientOperators, cattaneo_shift,
                                                 rolling_step)
from fastsim_ros.contact.normal import solve_normal

REFERENCE = Path(__file__).parent / "data" / "catt_to_cart_ref.csv"
# the example's input (catt_to_cart.inp, first sequence): its units (mm, N, G = 1)
NU, G, MU, FN = 0.28, 1.0, 0.4013, 0.4705
DX, XL, NX, NY, CURV = 0.25, -4.125, 34, 33, 0.002963


def _published() -> list[dict[str, str]]:
    with REFERENCE.open() as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


@pytest.fixture(scope="module")
def area():
    """Return the example's normal contact: its gap A x^2 + B y^2 under FN on its grid."""
    x0 = XL + 0.5 * DX
    x = x0 + DX * np.arange(NX)
    y = x0 + DX * np.arange(NY)
    gap = CURV * x[None, :] ** 2 + CURV * y[:, None] ** 2
    sol = solve_normal(x0, x0, DX, DX, gap, load=FN, shear_modulus=G, nu=NU)
    # the published normal solution: 621 cells in contact, approach 7.258e-2, pmax 1.834e-2
    assert int(sol.area.mask.sum()) == 621
    assert sol.approach == pytest.approx(7.258e-2, abs=1e-5)
    assert float(sol.pressure.max()) == pytest.approx(1.834e-2, abs=1e-5)
    return sol.area


@pytest.fixture(scope="module")
def sequence(area):
    """Run the published sequence: the shift, then 56 steps of one cell at its creepages."""
    ops = TransientOperators.of(area, 1, nu=NU, shear_modulus=G)
    out = []
    state = None
    for row in _published():
        c = float(row["cksi"])
        if row["kind"] == "shift":
            state = cattaneo_shift(area, c, 0.0, mu=MU, nu=NU, shear_modulus=G)
        else:
            state = rolling_step(area, ops, c, 0.0, 0.0, mu=MU, previous=state)
        out.append((row, state))
    return out


def test_forces_within_one_percent_of_mu_n_at_every_step(sequence) -> None:
    """At CONTACT's creepage of each step, Fx is its prescribed -0.657 mu N within 0.01 mu N."""
    assert len(sequence) == 57
    for row, sol in sequence:
        assert sol.fx / (MU * FN) == pytest.approx(float(row["fx_over_mu_n"]), abs=0.01), \
            row["case"]
        assert sol.fy == pytest.approx(0.0, abs=1e-9 * MU * FN)


def test_adhesion_and_slip_areas_follow_contact(area, sequence) -> None:
    """The adhesion and slip areas: CONTACT's cell counts within 1 % of the contact's cells."""
    for row, sol in sequence:
        assert abs(sol.adhesion_cells - int(row["adhesion_cells"])) <= 6, row["case"]
        assert abs(int(sol.slip.sum()) - int(row["slip_cells"])) <= 6, row["case"]
    # Cattaneo: slip in an annulus at the rim, as much in front as behind; rolling: the slip
    # area moves to the trailing edge (x < 0), the adhesion area to the leading edge
    x = area.x[None, :]
    first = sequence[0][1].slip
    last = sequence[-1][1].slip
    assert np.count_nonzero(first & (x < 0)) == np.count_nonzero(first & (x > 0))
    assert np.count_nonzero(last & (x < 0)) > 2 * np.count_nonzero(last & (x > 0))


def test_rolling_reaches_the_steady_state(area, sequence) -> None:
    """Rolling on at the last creepage: the state tends to the steady rolling solution.

    Steady rolling (the upstream difference over one cell) is the fixed point of
    steps of one cell; after CONTACT's two diameters the memory of the shift is
    down to 1e-4 of mu N, and it decays geometrically (about 7 % a cell rolled).
    """
    row, state = sequence[-1]
    cksi = float(row["cksi"])
    steady = coulomb(area, cksi, 0.0, 0.0, mu=MU, nu=NU, shear_modulus=G)
    assert state.fx == pytest.approx(steady.fx, abs=1e-3 * MU * FN)
    ops = TransientOperators.of(area, 1, nu=NU, shear_modulus=G)
    gaps = []
    for _ in range(80):
        state = rolling_step(area, ops, cksi, 0.0, 0.0, mu=MU, previous=state)
        gaps.append(abs(state.fx - steady.fx))
    assert all(b < a for a, b in zip(gaps[::10], gaps[10::10]))
    assert gaps[-1] < 1e-6 * MU * FN
    np.testing.assert_array_equal(state.slip, steady.slip)


def test_cattaneo_example_as_published() -> None:
    """The ``cattaneo`` example of CONTACT (Kalker 1990, 5.2.1.1): a ball shifted in stick.

    Polyethylene on polyethylene (G = 200 N/mm^2, nu = 0.42, mu = 0.4), the
    gap 0.01 (x^2 + y^2) (mm) under FN = 9.1954 N on 19 x 19 cells of
    0.13333 mm, shifted until Fx = -0.875 mu FN.  ``cattaneo.ref_out``
    publishes: 177 cells in contact, approach 1.998e-2 mm, pmax 4.393
    N/mm^2; the shift 8.155e-3 mm with 45 cells in adhesion and 132 in
    slip; dFx/dshift = -67.6 (1/mm, Fx in mu FN).  The shift is found here by
    bisection on the force, as CONTACT's Newton on the prescribed force.
    """
    nu, g, mu, fn, dx, xl, n = 0.42, 200.0, 0.4, 9.1954, 0.13333, -1.26667, 19
    x0 = xl + 0.5 * dx
    x = x0 + dx * np.arange(n)
    normal = solve_normal(x0, x0, dx, dx, 0.01 * x[None, :] ** 2 + 0.01 * x[:, None] ** 2,
                          load=fn, shear_modulus=g, nu=nu)
    assert int(normal.area.mask.sum()) == 177
    assert normal.approach == pytest.approx(1.998e-2, abs=1e-5)
    assert float(normal.pressure.max()) == pytest.approx(4.393, abs=1e-3)

    def force(shift: float) -> float:
        return cattaneo_shift(normal.area, shift, 0.0, mu=mu, nu=nu, shear_modulus=g).fx / (
            mu * fn)

    lo, hi = 0.0, 0.02
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if force(mid) > -0.875 else (lo, mid)
    shift = 0.5 * (lo + hi)
    sol = cattaneo_shift(normal.area, shift, 0.0, mu=mu, nu=nu, shear_modulus=g)
    assert shift == pytest.approx(8.155e-3, abs=1e-6)
    assert sol.adhesion_cells == 45
    assert int(sol.slip.sum()) == 132
    slope = (force(shift + 1e-6) - force(shift - 1e-6)) / 2e-6
    assert slope == pytest.approx(-67.6, rel=0.01)


def test_a_step_whose_newton_cycles_from_the_last_state_still_converges() -> None:
    """An eta step on an ellipse a/b = 0.5: Newton from the previous tractions cycles at step 5.

    The step restarts from full adhesion then (``transient_step``); the
    answer rises monotonically to the steady one (Newton from the last state
    alone raises ConvergenceError at the fifth step).
    """
    from fastsim_ros.contact import area as areas
    nu, g, mu, load = 0.28, 8e10, 0.3, 4e4
    ar = areas.ellipse(3e-3, 6e-3, nx=20, ny=20, load=load)
    ops = TransientOperators.of(ar, 1, nu=nu, shear_modulus=g)
    state, fy = None, []
    for _ in range(12):
        state = rolling_step(ar, ops, 0.0, 1.5e-3, 0.0, mu=mu, previous=state)
        fy.append(state.fy)
    assert all(b < a for a, b in zip(fy, fy[1:]))
    steady = coulomb(ar, 0.0, 1.5e-3, 0.0, mu=mu, nu=nu, shear_modulus=g)
    assert abs(fy[-1]) < abs(steady.fy) * 1.01
