"""No silent traps: required shear modulus, checked operators, read-only shared tables."""

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import exact
from fastsim_ros.contact.errors import ContactError, InvalidInputError
from fastsim_ros.contact.tables import coefficient_table, not_a_knot_spline, table_data


def test_shear_modulus_is_required():
    ar = areas.ellipse(1.0, 0.5, nx=8)
    with pytest.raises(TypeError, match="shear_modulus"):
        exact.SteadyRollingOperator.of(ar, nu=0.28)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="shear_modulus"):
        exact.full_adhesion(ar, 1e-3, 0.0, 0.0, nu=0.28)  # type: ignore[call-arg]


@pytest.mark.parametrize("solve", [
    lambda ar, op: exact.full_adhesion(ar, 1e-3, 0.0, 0.0, nu=0.28, shear_modulus=8e10,
                                       operator=op),
    lambda ar, op: exact.coulomb(ar.with_load(1e4), 1e-3, 0.0, 0.0, mu=0.3, nu=0.28,
                                 shear_modulus=8e10, operator=op)])
def test_a_passed_operator_is_checked_against_area_and_material(solve):
    ar = areas.ellipse(6e-3, 4e-3, nx=10, load=1e4)
    good = exact.SteadyRollingOperator.of(ar, nu=0.28, shear_modulus=8e10)
    solve(ar, good)  # its own area: fine
    solve(ar.with_pressure(np.asarray(ar.pressure) * 2.0), good)  # same cells: fine
    other_cells = areas.ellipse(6e-3, 4e-3, nx=10, pressure="parabolic", load=1e4)
    other_grid = areas.ellipse(6e-3, 4e-3, nx=12, load=1e4)
    wrong = {"material": exact.SteadyRollingOperator.of(ar, nu=0.3, shear_modulus=8e10),
             "modulus": exact.SteadyRollingOperator.of(ar, nu=0.28, shear_modulus=1.0),
             "grid": exact.SteadyRollingOperator.of(other_grid, nu=0.28, shear_modulus=8e10)}
    for op in wrong.values():
        with pytest.raises(InvalidInputError, match="operator was built for"):
            solve(ar, op)
    if not np.array_equal(other_cells.mask, ar.mask):
        with pytest.raises(InvalidInputError, match="operator was built for"):
            solve(other_cells, good)


def test_full_adhesion_checks_its_creepages():
    ar = areas.ellipse(1.0, 0.5, nx=8)
    with pytest.raises(InvalidInputError, match="xi must be finite"):
        exact.full_adhesion(ar, float("nan"), 0.0, 0.0, nu=0.28, shear_modulus=1.0)


def test_shared_tables_are_read_only():
    data = table_data()
    table = coefficient_table(0.28)
    for a in (data.a_over_b, data.nus, *data.values.values(), *data.errors.values(),
              table.knots, *table.poly.values()):
        with pytest.raises(ValueError, match="read-only"):
            a[..., 0] = 0.0
    for mapping in (data.values, data.errors, table.poly):
        with pytest.raises(TypeError):
            mapping["C11"] = np.zeros(3)  # type: ignore[index]


def test_splines_equal_scipys_not_a_knot_splines_to_rounding():
    data = table_data()
    knots = np.log(data.a_over_b)
    for v in data.values.values():
        for row in v:
            ours = not_a_knot_spline(knots, row)
            theirs = CubicSpline(knots, row).c
            # relative to each interval's largest coefficient (all-zero rows: exactly)
            scale = np.abs(theirs).max(axis=0)
            assert np.all(np.abs(ours - theirs) <= 1e-13 * scale)


def test_package_errors_only():
    # every error of the core derives from ContactError (a RuntimeError only as ConvergenceError)
    import fastsim_ros.contact.errors as errors
    for name in dir(errors):
        obj = getattr(errors, name)
        if isinstance(obj, type) and issubclass(obj, Exception):
            assert issubclass(obj, ContactError)
