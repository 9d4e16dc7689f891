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
    # joined along y = 0: MAE's widest_strip split finds the join line (docs/guide_physics.md)
    assert mae_geometry(ar, "widest_strip").y_s == pytest.approx(0.0, abs=1e-12)


def extents(ar):
    """Return the cell-face extents ``(x_min, x_max, y_min, y_max)`` of the cells in contact."""
    jj, ii = np.nonzero(ar.mask)
    return (ar.x[ii].min() - ar.dx / 2, ar.x[ii].max() + ar.dx / 2,
            ar.y[jj].min() - ar.dy / 2, ar.y[jj].max() + ar.dy / 2)


def test_long_narrow_patch_is_long_narrow_and_not_an_ellipse():
    ar = samples.long_narrow_patch(cells=40, scale=0.01, load=5e4)
    x0, x1, y0, y1 = extents(ar)
    assert (x1 - x0) / (y1 - y0) > 5.0
    assert ar.area == pytest.approx(1e-4, rel=0.03)
    # squarer than the ellipse of its extents: 18% more area (superellipse of order 4)
    assert ar.area / (np.pi * (x1 - x0) * (y1 - y0) / 4) == pytest.approx(1.18, rel=0.03)
    assert ar.load == pytest.approx(5e4)
    with pytest.raises(samples.InvalidInputError):
        samples.long_narrow_patch(cells=20, a_over_b=4.0)


def test_crescent_is_bent_symmetric_and_not_convex():
    ar = samples.crescent_patch(cells=40, scale=0.01, load=5e4)
    np.testing.assert_array_equal(ar.mask, ar.mask[::-1, :])  # symmetric in y
    rows = np.flatnonzero(ar.mask.any(axis=1))
    centre = np.array([ar.x[np.flatnonzero(ar.mask[j])].mean() for j in rows])
    y = ar.y[rows]
    # the strips' centres lie on a parabola in y: the horns lead the middle
    mid = centre[np.argmin(np.abs(y))]
    a, b = (0.01 * v for v in areas.semi_ellipse_axes(0.3))
    assert centre[0] - mid == pytest.approx(1.2 * a * (y[0] / b) ** 2, rel=0.1)
    assert np.corrcoef(y**2, centre)[0, 1] > 0.99
    # not convex: the point halfway between the horns' tips lies outside the patch
    tip = ar.x[np.flatnonzero(ar.mask[rows[0]])].mean()
    i = int(np.argmin(np.abs(ar.x - tip)))
    j = int(np.argmin(np.abs(ar.y)))
    assert not ar.mask[j, i]
    assert ar.area == pytest.approx(1e-4, rel=0.03)


def test_egg_is_asymmetric_in_x_only():
    ratio = 1.8
    ar = samples.egg_patch(cells=40, scale=0.01, load=5e4, lead_over_trail=ratio)
    x0, x1, _, _ = extents(ar)
    assert x1 / -x0 == pytest.approx(ratio, rel=0.05)
    np.testing.assert_allclose(ar.pressure, ar.pressure[::-1, :], rtol=1e-12, atol=0)
    jj, ii = np.nonzero(ar.mask)
    w = ar.pressure[jj, ii]
    assert np.average(ar.x[ii], weights=w) > 0.1 * x1  # the load leans forward
    assert ar.area == pytest.approx(1e-4, rel=0.03)


def test_profile_gap_patches_run_from_the_tread_to_the_flange_root():
    patches = [samples.profile_gap_patch(u, cells=40) for u in samples.PROFILE_SHIFTS]
    # on the tread the patch is Hertz's of the tread's curvatures
    tread = hertz_ellipse(samples.WHEEL_RADIUS, 1.0 / samples.PROFILE_TREAD_CURVATURE, 5e4,
                          shear_modulus=samples.STEEL_G, nu=samples.STEEL_NU)
    x0, x1, y0, y1 = extents(patches[0])
    assert patches[0].pressure.max() == pytest.approx(tread.p0, rel=0.03)
    assert (y1 - y0) / 2 == pytest.approx(tread.b, abs=2 * patches[0].dy)
    assert (x1 - x0) / 2 == pytest.approx(tread.a, abs=2 * patches[0].dx)
    # towards the flange root: narrower, longer, more loaded
    widths = [extents(p)[3] - extents(p)[2] for p in patches]
    lengths = [extents(p)[1] - extents(p)[0] for p in patches]
    peaks = [p.pressure.max() for p in patches]
    assert widths[0] > widths[1] > widths[2]
    assert lengths[0] < lengths[1] < lengths[2]
    assert peaks[0] < peaks[1] < peaks[2]
    # in the transition the patch reaches further onto the softer tread side
    _, _, y0, y1 = extents(patches[1])
    assert -y0 > 1.5 * y1
    for p in patches:
        assert p.load == pytest.approx(5e4, rel=1e-6)


@pytest.mark.parametrize("ratio", [0.6, 1.7])
def test_eggs_of_other_proportions_keep_their_area_and_halves(ratio):
    ar = samples.egg_patch(cells=60, scale=0.01, load=5e4, lead_over_trail=ratio,
                           a_over_b=1.25)
    x0, x1, y0, y1 = extents(ar)
    assert x1 / -x0 == pytest.approx(ratio, rel=0.05)
    assert (x1 - x0) / (y1 - y0) == pytest.approx(1.25, rel=0.05)
    assert ar.area == pytest.approx(1e-4, rel=0.03)
    # the default proportions are the report's egg, bit for bit
    np.testing.assert_array_equal(samples.egg_patch(cells=30).pressure,
                                  samples.egg_patch(cells=30, a_over_b=1.0).pressure)


def test_crescents_bend_either_way():
    lead = samples.crescent_patch(cells=40, bend=1.5, a_over_b=0.4)
    trail = samples.crescent_patch(cells=40, bend=-1.5, a_over_b=0.4)
    # the horns trailing: the mirror image in x of the horns leading
    np.testing.assert_array_equal(trail.mask, lead.mask[:, ::-1])
    assert lead.area == pytest.approx(1.0, rel=0.03)
    np.testing.assert_array_equal(samples.crescent_patch(cells=30).pressure,
                                  samples.crescent_patch(cells=30, a_over_b=0.3).pressure)


def test_flat_band_is_wide_and_squarer_than_an_ellipse():
    ar = samples.flat_band_patch(cells=60, scale=0.01, load=5e4, a_over_b=0.25, exponent=4.0)
    x0, x1, y0, y1 = extents(ar)
    assert (x1 - x0) / (y1 - y0) == pytest.approx(0.25, rel=0.05)
    assert ar.area == pytest.approx(1e-4, rel=0.03)
    assert ar.area / (np.pi * (x1 - x0) * (y1 - y0) / 4) == pytest.approx(1.18, rel=0.03)
    with pytest.raises(samples.InvalidInputError):
        samples.flat_band_patch(cells=20, a_over_b=1.5)
    with pytest.raises(samples.InvalidInputError):
        samples.flat_band_patch(cells=20, exponent=2.0)


def test_asymmetric_lobes_are_one_waisted_area_asymmetric_both_ways():
    ar = samples.asymmetric_lobes(cells=60, scale=0.01, load=5e4, size=0.6, lead=0.4)
    assert ar.area == pytest.approx(1e-4, rel=0.03)
    # one connected area: a flood fill from one cell reaches every cell in contact
    seen = np.zeros_like(ar.mask)
    stack = [tuple(int(v) for v in np.argwhere(ar.mask)[0])]
    while stack:
        j, i = stack.pop()
        if 0 <= j < ar.ny and 0 <= i < ar.nx and ar.mask[j, i] and not seen[j, i]:
            seen[j, i] = True
            stack += [(j + 1, i), (j - 1, i), (j, i + 1), (j, i - 1)]
    np.testing.assert_array_equal(seen, ar.mask)
    counts = ar.mask.sum(axis=1)
    rows = np.flatnonzero(counts)
    # a waist: the chords shrink and grow again between the lobes
    inner = counts[rows[0]:rows[-1] + 1]
    k = int(np.argmin(inner[len(inner) // 4: 3 * len(inner) // 4])) + len(inner) // 4
    assert inner[k] < inner[:k].max() and inner[k] < inner[k:].max()
    jj, ii = np.nonzero(ar.mask)
    assert ar.x[ii][ar.y[jj] > ar.y[jj].mean()].mean() > ar.x[ii].mean()  # the small one leads
    with pytest.raises(samples.InvalidInputError):
        samples.asymmetric_lobes(cells=20, size=-1.0)
