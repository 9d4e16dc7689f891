"""The sample areas used by the validation and the demo."""

import numpy as np
import pytest

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import samples
from fastsim_ros.contact.mae import mae_geometry
from fastsim_ros.contact.normal import hertz_ellipse


def segments(row):
    inside = np.asarray(row, dtype=bool)
    return int(np.count_nonzero(inside[1:] & ~inside[:-1]) + inside[0])


def test_flange_root_patch_is_a_loaded_asymmetric_normal_solution():
    ar = samples.flange_root_patch(cells=40, load=5e4)
    jj, _ = np.nonzero(ar.mask)
    y = ar.y[jj]
    # the tight flange-side curvature squeezes the patch towards the tread side
    assert y.min() < -2 * y.max() < 0
    # narrower and more loaded than the Hertz patch of the tread-side curvature alone
    tread = hertz_ellipse(samples.WHEEL_RADIUS, 0.3, 5e4, shear_modulus=samples.STEEL_G,
                          nu=samples.STEEL_NU)
    assert ar.pressure.max() > tread.p0


def test_notched_ellipse_has_strips_of_two_segments_on_one_side():
    ar = samples.notched_ellipse(cells=40, scale=0.01, load=1e4)
    counts = np.array([segments(r) for r in ar.mask])
    assert counts.max() == 2
    assert np.all(counts[ar.y < 0] <= 1)
    # the notch |x| < 0.3 a, y > 0.35 b cut out of the ellipse: its share of the ellipse's
    # area by quadrature (in units of a and b)
    y = np.linspace(0.35, 1.0, 200001)
    notch = np.trapezoid(2 * np.minimum(0.3, np.sqrt(1 - y**2)), y) / np.pi
    assert ar.area == pytest.approx(1e-4 * (1 - notch), rel=0.02)


def test_two_lobes_are_one_connected_waisted_area():
    ar = samples.two_lobes(cells=60)
    width = ar.mask.sum(axis=1).astype(float)
    rows = np.flatnonzero(width)
    inner = width[rows[0]:rows[-1] + 1]
    assert np.all(inner > 0)  # connected across the waist
    k = int(np.argmin(inner[5:-5])) + 5
    assert inner[k] < 0.8 * inner[:k].max() and inner[k] < 0.8 * inner[k:].max()


@pytest.mark.parametrize("g1", [0.1, 5.0])
def test_semi_ellipses_patch_keeps_the_shape_and_its_join_line(g1):
    ar = samples.semi_ellipses_patch(g1, 1.0, cells=40, scale=0.01, load=2e4)
    shape = areas.semi_ellipses(g1, 1.0, cells=40)
    # the Hertz-like pressure is positive on every cell of the two halves, and on no other
    np.testing.assert_array_equal(ar.mask, shape.mask)
    assert ar.area == pytest.approx(1e-4, rel=0.05)
    # joined along y = 0: MAE's widest_strip split finds the join line (METHOD.md 6)
    assert mae_geometry(ar, "widest_strip").y_s == pytest.approx(0.0, abs=1e-12)
