"""ASM, Knothe and Hung's asymptotic strip method (the seed's Table 2): pieces and physics."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import samples
from fastsim_ros.contact.asm import (MAX_STRIPS, Strips, area_strips, asm_coefficients,
                                     asm_fastsim, asm_fastsim_coefficients, centroid,
                                     ellipse_coefficients, influence_matrix)
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.influence import (_rectangle_integrals, line_influence,
                                           point_load_displacement)

NU = 0.25
#: Kalker's published coefficients at nu = 0.25 (his table E.3, 3 digits)
KALKER = {0.5: (3.62, 3.01, 0.929), 1.0: (4.12, 3.67, 1.47), 2.0: (5.10, 4.90, 2.62)}


def test_line_influence_is_the_integral_of_the_point_load_kernels():
    # over the field-minus-source offsets y in [-0.8, 0.3] at x: trapezoidal quadrature
    y = np.linspace(-0.8, 0.3, 400001)
    for x in (0.05, -0.4, 1.3):
        kernels = point_load_displacement(np.full(y.shape, x), y, shear_modulus=2.0, nu=NU)
        got = line_influence(np.array(x), np.array(-0.8), np.array(0.3), shear_modulus=2.0,
                             nu=NU)
        for k, g in zip(kernels[:3], got):
            assert float(g) == pytest.approx(np.trapezoid(k, y), rel=1e-6, abs=1e-12)


def test_strip_slope_of_a_linear_traction_equals_the_rectangle_influence_derivative():
    # one strip, traction s = (x_l - x)/h: ASM's du_x/dx at a point against a finite
    # difference of the displacement of the same traction on 4000 thin rectangles
    strips = Strips(np.array([0.0]), np.array([0.2]), np.array([-1.0]), np.array([1.0]))
    a, xp, yp = influence_matrix(strips, nu=NU, collocation=(0.35, 0.7))
    n = 4000
    xs = -1.0 + (np.arange(n) + 0.5) * 2.0 / n
    f = (1.0 - xs) / 2.0

    def u(x, y):
        i_xx, i_yy, _ = _rectangle_integrals(xs - x, 0.0 - y, 2.0 / n, 0.2)
        return float(((i_xx + (1.0 - NU) * i_yy) / math.pi * f).sum())

    for k in range(2):
        e = 1e-4
        slope = (u(xp[k] + e, yp[k]) - u(xp[k] - e, yp[k])) / (2 * e)
        assert a[k, 0] == pytest.approx(slope, rel=2e-3)


@pytest.mark.parametrize("g", sorted(KALKER))
def test_ellipses_within_two_percent_of_kalker(g):
    c = ellipse_coefficients(g, nu=NU, strips=60)
    for got, want in zip((c.C11, c.C22, c.C23), KALKER[g]):
        assert got == pytest.approx(want, rel=0.02)
    assert c.C13 == pytest.approx(0.0, abs=1e-9)
    assert c.C21 == pytest.approx(0.0, abs=1e-9)


def test_strips_of_a_notched_area_are_its_row_segments():
    ar = samples.notched_ellipse(cells=30)
    s = area_strips(ar)
    per_row = np.array([np.count_nonzero(np.isclose(s.y, y)) for y in ar.y])
    edges = np.diff(np.pad(ar.mask.astype(int), ((0, 0), (1, 1))), axis=1)
    np.testing.assert_array_equal(per_row, (edges == 1).sum(axis=1))
    assert per_row.max() == 2
    assert float(((s.x_l - s.x_t) * s.dy).sum()) == pytest.approx(ar.area, rel=1e-12)


def test_fastsim_with_asm_flexibilities_gives_asms_coefficients():
    ar = samples.egg_patch(cells=40)
    ref = centroid(ar)
    own = asm_coefficients(ar, nu=NU, reference=ref)
    fs = asm_fastsim_coefficients(ar, nu=NU, reference=ref)
    for key in ("C11", "C22", "C23"):
        assert getattr(fs, key) == pytest.approx(getattr(own, key), rel=1e-9)


def test_asm_fastsim_saturates_at_mu_n():
    ar = samples.crescent_patch(cells=30, scale=0.01, load=3e4)
    sol = asm_fastsim(ar, 0.0, 0.5, 0.0, mu=0.3, nu=0.28, shear_modulus=8e10)
    assert sol.fy == pytest.approx(-0.3 * ar.load, rel=1e-9)


def test_too_many_strips_are_refused_before_the_system_is_built():
    n = MAX_STRIPS + 1
    strips = Strips(np.arange(n, dtype=float), np.ones(n), np.zeros(n), np.ones(n))
    with pytest.raises(InvalidInputError, match="at most 800 strips"):
        influence_matrix(strips, nu=NU)
    with pytest.raises(InvalidInputError, match="collocation"):
        influence_matrix(Strips(*(np.ones(1),) * 2, np.zeros(1), np.ones(1)), nu=NU,
                         collocation=(0.7, 0.2))
    with pytest.raises(InvalidInputError):
        asm_coefficients(areas.ellipse(1.0, 1.0, nx=8, ny=8), nu=0.7)


SEED_TABLES = Path(__file__).resolve().parents[1].parent / "shared" / "reference" / \
    "seed_tables_1_2.md"


def test_table2_reading_maps_its_amk_columns_onto_kalkers_table():
    # the printed labels of the two blocks are swapped: the AMK columns are Kalker's at a/b = g
    # (first block) and 1/g (second), to the 3-digit rounding, but for the one misprint
    if not SEED_TABLES.exists():
        pytest.skip("the published reference tables are not beside this checkout")
    from fastsim_ros.contact.seed_tables import read_table2
    published = {}
    for line in (SEED_TABLES.parent / "kalker_coefficients.csv").read_text().splitlines():
        cells = line.split(",")
        if not line.startswith("#") and cells[0] != "a_over_b" and float(cells[1]) == 0.25:
            published[round(float(cells[0]), 6)] = tuple(float(c) for c in cells[2:5])
    rows = read_table2(SEED_TABLES)
    assert {round(r.a_over_b, 6) for r in rows} == set(published)
    for r in rows:
        for name, printed, kalker in zip(("C11", "C22", "C23"), r.amk,
                                         published[round(r.a_over_b, 6)]):
            if (r.block, r.g, name) == ("b<a", 0.8, "C23"):
                assert printed == 1.15 and kalker == 1.25
                continue
            assert printed == pytest.approx(kalker, abs=0.0051), (r, name)


def _table2_rows() -> list:
    if not SEED_TABLES.exists():
        return [None]
    from fastsim_ros.contact.seed_tables import read_table2
    return read_table2(SEED_TABLES)


def _meets_issue_target(name: str, got: float, printed: float) -> bool:
    # the target: within 2%; C23 within 3% or 0.02
    err = abs(got / printed - 1.0)
    return err <= 0.02 if name != "C23" else (err <= 0.03 or abs(got - printed) <= 0.02)


@pytest.mark.xfail(strict=True, reason="the printed ASM columns are not reproduced: Knothe "
                   "and Hung's ansatz and placement are not established (docs/"
                   "validation_seed.md, section 2, the readings tried)")
@pytest.mark.parametrize("row", _table2_rows(),
                         ids=lambda r: "absent" if r is None else f"{r.block}-g{r.g:g}")
def test_table2_asm_columns_as_printed(row):
    # each row of Table 2 (a/b mapped as the reference file states) at the package's ASM, as
    # `fastsim_contact coefficients --shape ellipse --method asm --nu 0.25` reports it
    if row is None:
        pytest.skip("the published reference tables are not beside this checkout")
    c = ellipse_coefficients(row.a_over_b, nu=NU, strips=60)
    misses = [(name, got, printed) for name, got, printed in
              zip(("C11", "C22", "C23"), (c.C11, c.C22, c.C23), row.asm)
              if not _meets_issue_target(name, got, printed)]
    assert not misses
