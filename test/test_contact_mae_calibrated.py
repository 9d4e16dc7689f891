"""The calibrated MAE: its three rules, its compiled path against the reference, its physics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import exact, samples
from fastsim_ros.contact.compiled import CalibratedMaeSolver, MaeSolver, warm_up
from fastsim_ros.contact.knee import knee_factors
from fastsim_ros.contact.errors import OutOfTableError
from fastsim_ros.contact.fastsim import traction_bound
from fastsim_ros.contact.friction import ExponentialFriction
from fastsim_ros.contact.mae import mae_coefficients, mae_geometry, row_extents, split_geometries
from fastsim_ros.contact.mae_calibrated import (_paired_coefficients, calibrated_flexibilities,
                                                mae_calibrated_coefficients,
                                                mae_calibrated_fastsim, sweep_integrals,
                                                zone_coefficients)
from fastsim_ros.contact.pairs import PAIR_NAMES, pair_factors
from fastsim_ros.contact.rules import chord_bend_offset, rigid_slip_return
from fastsim_ros.contact.tables import coefficient_table

import test_contact_compiled
from test_contact_compiled import CREEPAGES, MU, NU, G, assert_forces, assert_tractions, size

#: the compiled path's test areas, one fixture for both files (name, area, reference point)
case = test_contact_compiled.case


@pytest.fixture(scope="module")
def table():
    return coefficient_table(NU)


@pytest.fixture(scope="module")
def pairs():
    return pair_factors(NU)


@pytest.fixture(scope="module")
def solver():
    warm_up()
    return CalibratedMaeSolver(NU, G)


# ---------------------------------------------------------------- the pair factors


def test_pair_factors_are_one_for_equal_halves(pairs):
    # two equal halves are one ellipse: no correction, at the nodes and between them
    for g in (0.07, 0.1, 0.5, 1.0, 3.0, 13.0):
        for name in PAIR_NAMES:
            assert pairs.factor(name, g, g) == pytest.approx(1.0, abs=3e-3)


def test_pair_factors_say_the_short_half_carries_more(pairs):
    # the exact theory: a short half (a/b = 5) joined to a round one carries more than alone,
    # the round one less, and the effect grows with the difference
    assert pairs.factor("c23", 5.0, 1.0) > 1.15 > 1.0 > 0.9 > pairs.factor("c23", 1.0, 5.0)
    assert pairs.factor("c11", 4.0, 1.0) > pairs.factor("c11", 2.0, 1.0) > 1.0


def test_pair_factors_interpolate_in_nu_exactly_at_the_nodes():
    low, mid, high = pair_factors(0.0), pair_factors(0.25), pair_factors(0.5)
    between = pair_factors(0.28)
    v = [p.factor("c11", 4.0, 0.25) for p in (low, mid, high, between)]
    assert min(v[:3]) <= v[3] <= max(v[:3])
    with pytest.raises(OutOfTableError, match="pair factors' range"):
        pair_factors(0.6)


# ---------------------------------------------------------------- the rigid-slip return


def test_rigid_slip_return_is_radial_with_equal_flexibilities():
    px, py, l1 = 1.0e5, -2.0e4, 3e-11
    wxh, wyh = 2e-6, 5e-6
    tx, ty, ok = rigid_slip_return(px, py, wxh, wyh, l1, l1, 8e4)
    trial = np.array([px - wxh / l1, py - wyh / l1])
    assert ok
    np.testing.assert_allclose([tx, ty], 8e4 * trial / np.hypot(*trial), rtol=1e-12)


def _converged_direction(px, py, wxh, wyh, l1, l2, g):
    """Iterate ``e <- (U - g D e)/|...|`` to its fixed point: the exact rule's direction."""
    u = np.array([l1 * px - wxh, l2 * py - wyh])
    d = np.array([0.5 * (l1 - l2), -0.5 * (l1 - l2)])
    e = u / np.hypot(*u)
    for _ in range(200):
        v = u - g * d * e
        e = v / np.hypot(*v)
    return e


@pytest.mark.parametrize("l2_over_l1", [0.7, 0.9, 1.2, 1.4])
def test_rigid_slip_return_is_near_the_converged_rule(l2_over_l1):
    rng = np.random.default_rng(5)
    g, l1 = 1.0, 1.0
    l2 = l1 * l2_over_l1
    worst = 0.0
    for _ in range(500):
        px, py = 0.7 * rng.standard_normal(2)
        wxh, wyh = rng.standard_normal(2) * rng.uniform(0.05, 3.0)
        tx, ty, ok = rigid_slip_return(px, py, wxh, wyh, l1, l2, g)
        if ok:
            assert math.hypot(tx, ty) == pytest.approx(g, rel=1e-12)
            e = _converged_direction(px, py, wxh, wyh, l1, l2, g)
            worst = max(worst, math.hypot(tx - g * e[0], ty - g * e[1]))
            # the converged direction is opposite to the slip s h = w h + L (tau - tau_p)
            sx, sy = wxh + l1 * (g * e[0] - px), wyh + l2 * (g * e[1] - py)
            assert sx * e[1] - sy * e[0] == pytest.approx(0.0, abs=1e-9 * math.hypot(sx, sy))
            assert sx * e[0] + sy * e[1] < 0.0
    # rules.rigid_slip_return's docstring: within 1.7% of g for L2/L1 in 0.7..1.4
    assert worst <= 0.017 * g


@pytest.mark.parametrize("l2_over_l1", [0.3, 1.7, 6.0])
def test_rigid_slip_return_in_full_sliding_opposes_the_rigid_slip(l2_over_l1):
    # |w h| >> L g: the traction is opposite to the rigid slip, whatever the flexibilities, up
    # to the elastic part L tau_p of the slip (here 5e-5 of w h)
    l1, g = 2e-11, 9e4
    w = np.array([1e-2, -2.5e-2])
    tx, ty, ok = rigid_slip_return(-3e4, 6e4, *w, l1, l1 * l2_over_l1, g)
    assert ok
    np.testing.assert_allclose([tx, ty], -g * w / np.hypot(*w), rtol=0.0, atol=2e-4 * g)


def test_rigid_slip_return_declines_inside_the_bound():
    assert rigid_slip_return(1e4, 0.0, 1e-8, 0.0, 1e-11, 2e-11, 1e5)[2] is False


# ---------------------------------------------------------------- the calibration


def _zone_sums(ar, table, pairs):
    """Return the method's zone coefficients summed as MAE's eq. 7: C~11, C~22, C~23 about S.

    With the split between two faces (a tie: an odd number of strips on a
    shape symmetric in ``y``), the weighted mean over them (the method
    weighs their strips' stiffness).
    """
    sums = []
    for geo, weight in split_geometries(ar):
        (w1, w2), (c1, c2) = geo.weights, zone_coefficients(ar, geo, table, pairs)
        sums.append((weight * (w1 * c1["c11"] + w2 * c2["c11"]),
                     weight * (w1 * c1["c22"] + w2 * c2["c22"]),
                     weight * (w1**1.5 * c1["c23"] + w2**1.5 * c2["c23"])))
    return tuple(sum(v) for v in zip(*sums))


@pytest.mark.parametrize("cells", [12, 20, 41])
def test_fastsim_gives_the_zone_coefficients_on_any_grid(table, pairs, cells):
    # the paper's flexibilities reproduce a zone's coefficients on the continuous
    # semi-ellipse only (+2% at 30 cells, docs/guide_physics.md); calibrated on the cells, FastSim
    # gives them on any grid (an ellipse centred on x = 0: C~23 about S is about the origin)
    ar = areas.ellipse(6e-3, 4e-3, nx=cells, ny=cells + 3)
    c = mae_calibrated_coefficients(ar, table, pairs)
    for name, value in zip(("C11", "C22", "C23"), _zone_sums(ar, table, pairs)):
        assert getattr(c, name) == pytest.approx(value, rel=1e-9)


@pytest.mark.parametrize("cells", [12, 20, 40])
def test_ellipse_gives_maes_own_coefficients(table, pairs, cells):
    # an even number of strips: two equal zones, pair factor 1, MAE's (Kalker's) C exactly
    ar = areas.ellipse(6e-3, 4e-3, nx=cells, ny=cells + 4)
    c = mae_calibrated_coefficients(ar, table, pairs)
    own = mae_coefficients(mae_geometry(ar), table)
    for name in ("C11", "C22", "C23"):
        assert getattr(c, name) == pytest.approx(getattr(own, name), rel=1e-9)
    assert abs(c.C13) <= 1e-9 * c.C11


def test_notch_behind_a_gap_keeps_the_zone_coefficients(table, pairs):
    # FastSim restarts behind the notch; the calibrated flexibilities make up for it, so the
    # method's C~11 is its zones' sum (the paper's MAE + FastSim is 9% under MAE's own here)
    ar = samples.notched_ellipse(cells=40)
    c = mae_calibrated_coefficients(ar, table, pairs)
    assert c.C11 == pytest.approx(_zone_sums(ar, table, pairs)[0], rel=1e-9)
    paper = MaeSolver(NU, 1.0).solve(ar, 1e-12, 0.0, 0.0, mu=1e3).fx / (-ar.area / math.pi * 1e-12)
    assert paper < 0.93 * c.C11


def test_sweep_integrals_of_one_strip():
    # one strip of 4 cells: d = h/2, 3h/2, 5h/2, 7h/2 from the front face
    p = np.zeros((1, 6))
    p[0, 1:5] = 1.0
    ar = areas.GridArea(0.0, 0.0, 0.5, 1.0, p)
    d, s3 = sweep_integrals(ar, x_c=1.25)
    np.testing.assert_allclose(d[0], [0.0, 1.75, 1.25, 0.75, 0.25, 0.0])
    # s3 = sum (x_mid - x_c) h with x_mid each step's middle: ((x_lead - x_c)^2 - (x - x_c)^2)/2
    x_lead = 2.25
    expected = [((x_lead - 1.25) ** 2 - (x - 1.25) ** 2) / 2 for x in ar.x]
    np.testing.assert_allclose(s3[0, 1:5], expected[1:5], atol=1e-15)


# ---------------------------------------------------------------- compiled = reference


@pytest.mark.parametrize("bound", ["given", "parabolic"])
@pytest.mark.parametrize("creep", sorted(CREEPAGES))
def test_compiled_equals_reference(solver, table, pairs, case, creep, bound):
    _, ar, reference = case
    xi, eta, phi = CREEPAGES[creep]
    ref = mae_calibrated_fastsim(ar, xi, eta, phi, bound=traction_bound(ar, MU, bound=bound),
                                 table=table, pairs=pairs, shear_modulus=G,
                                 reference=reference,
                                 knee=knee_factors(NU) if bound == "given" else None)
    mine = solver.solve(ar, xi, eta, phi, mu=MU, reference=reference, bound=bound,
                        tractions=True)
    assert_forces(mine, ref.fx, ref.fy, ref.mz, size(ar))
    assert_tractions(mine, ref.traction)
    arrays = solver.solve_arrays(np.array(ar.pressure), ar.x0, ar.y0, ar.dx, ar.dy, xi, eta,
                                 phi, MU, reference=reference, bound=bound)
    assert (arrays.fx, arrays.fy, arrays.mz) == (mine.fx, mine.fy, mine.mz)


@pytest.mark.parametrize("creep", ["partial_spin", "full_slip", "partial"])
def test_compiled_equals_reference_with_falling_friction(solver, table, pairs, case, creep):
    _, ar, reference = case
    law = ExponentialFriction(0.4, 0.4, 1.0)
    xi, eta, phi = CREEPAGES[creep]
    ref = mae_calibrated_fastsim(ar, xi, eta, phi, bound=traction_bound(ar, law.mu_s),
                                 table=table, pairs=pairs, shear_modulus=G,
                                 reference=reference, friction=law, speed=20.0,
                                 knee=knee_factors(NU))
    mine = solver.solve(ar, xi, eta, phi, friction=law, speed=20.0, reference=reference,
                        tractions=True)
    assert_forces(mine, ref.fx, ref.fy, ref.mz, size(ar))
    assert_tractions(mine, ref.traction)


def test_compiled_flexibilities_equal_reference(solver, table, pairs, case):
    _, ar, _ = case
    geo = mae_geometry(ar)
    ref = calibrated_flexibilities(ar, geo, table, pairs, G)
    mine = solver.flexibility(ar)
    for r, m in zip(ref, mine):
        assert (r is None) == (m is None)
        if r is not None:
            for name in ("l1", "l2", "l3", "l4"):
                assert getattr(m, name) == pytest.approx(getattr(r, name), rel=1e-11)


def test_batch_equals_one_by_one(solver):
    ar = samples.semi_ellipses_patch(5.0, 1.0, cells=30, scale=0.01, load=3e4)
    creep = np.column_stack([np.linspace(-2e-3, 2e-3, 7), np.linspace(1e-3, -1e-3, 7),
                             np.linspace(-3.0, 3.0, 7)])
    out = solver.solve_batch(ar.pressure, ar.x0, ar.y0, ar.dx, ar.dy, creep, mu=MU)
    for row, c in zip(out, creep):
        one = solver.solve(ar, *c, mu=MU)
        assert tuple(row) == (one.fx, one.fy, one.mz)


# ---------------------------------------------------------------- physics


@pytest.mark.parametrize("make", [
    lambda: samples.truncated_ellipse(cells=30, scale=0.01, load=2e4),
    lambda: samples.semi_ellipses_patch(5.0, 1.0, cells=30, scale=0.01, load=3e4),
    lambda: samples.crescent_patch(cells=30, scale=0.01, load=3e4),
], ids=["truncated", "semi_5_1", "crescent"])
def test_full_sliding_force_follows_the_rigid_slip(solver, make):
    # at creepages far beyond saturation every cell slides opposite to its rigid slip:
    # F = -mu sum p w/|w| dA (spin about the origin, with some lateral creepage)
    ar = make()
    xi, eta, phi = 0.0, 0.05, 400.0
    x, y = ar.x[None, :], ar.y[:, None]
    wx, wy = xi - phi * y, eta + phi * x
    wn = np.hypot(wx, wy)
    p = np.asarray(ar.pressure)
    fx = -MU * float((p * wx / wn).sum()) * ar.cell_area
    fy = -MU * float((p * wy / wn).sum()) * ar.cell_area
    mine = solver.solve(ar, xi, eta, phi, mu=MU)
    paper = MaeSolver(NU, G).solve(ar, xi, eta, phi, mu=MU)
    scale = MU * ar.load
    assert abs(mine.fx - fx) < 0.01 * scale and abs(mine.fy - fy) < 0.01 * scale
    # the paper's radial return misses the direction where the zones' L differ
    assert abs(paper.fx - fx) + abs(paper.fy - fy) > abs(mine.fx - fx) + abs(mine.fy - fy)


def test_full_slip_along_x_gives_mu_n(solver, case):
    _, ar, _ = case
    r = solver.solve(ar, -2.0, 0.0, 0.0, mu=MU)
    assert r.fx == pytest.approx(MU * ar.load, rel=1e-9) and abs(r.fy) <= 1e-9 * r.fx
    assert r.slip_fraction == 1.0


def test_semi_ellipses_5_1_coefficients_near_exact(table, pairs):
    # the validation area the pair factors were made for, not fitted on (nodes 4 and 7, 0.7
    # and 1.3): the paper's MAE is 26% low in C~23 here, the calibrated method within 5%
    exact_c = exact.extrapolated_coefficients("semi-ellipses", (5.0, 1.0), nu=NU, finest=60)
    c = mae_calibrated_coefficients(areas.semi_ellipses(5.0, 1.0, cells=60), table, pairs)
    for name in ("C11", "C22", "C23"):
        assert getattr(c, name) == pytest.approx(getattr(exact_c, name), rel=0.05)


# ---------------------------------------------------------------- rule 4: bent zones


def _strips(halves, centres_twice):
    # strips of 2 l cells whose centre is at centres_twice / 2 cells: count, first, last
    n = np.array([2 * h for h in halves])
    first = np.array([(c - (2 * h - 1)) // 2 for h, c in zip(halves, centres_twice)])
    return n, first, first + n - 1


def test_bend_offset_of_centres_quadratic_in_the_chord_is_the_mean_shift():
    # a crescent's strips: centre = A - B l^2 (the short ones lead); the offset is the mean
    # strip centre (each strip once) less the centroid (strips weighed by their length)
    halves = [2, 3, 4, 5, 6, 5, 4, 3, 2]
    centres_twice = [2 * (60 - h * h) - 1 for h in halves]
    count, first, last = _strips(halves, centres_twice)
    dx = 1e-4
    m = 0.5 * dx * (first + last)
    half = 0.5 * dx * count
    expected = m.mean() - (m * half).sum() / half.sum()
    got = chord_bend_offset(count, first, last, 0, len(halves), dx)
    assert expected > 0.0
    assert got == pytest.approx(expected, rel=1e-9)


def test_bend_offset_of_centres_proportional_to_the_chord_is_zero():
    # an egg's strips: centre = m0 + s l (the long ones lead): no bend, no offset, although
    # the mean strip centre is off the centroid
    halves = [2, 3, 4, 5, 6, 5, 4, 3, 2]
    centres_twice = [2 * (10 + 2 * h) - 1 for h in halves]
    count, first, last = _strips(halves, centres_twice)
    dx = 1e-4
    m = 0.5 * dx * (first + last)
    assert abs(m.mean() - (m * count).sum() / count.sum()) > 0.5 * dx
    assert abs(chord_bend_offset(count, first, last, 0, len(halves), dx)) < 1e-12 * dx


def test_bend_offset_needs_three_chords():
    count, first, last = _strips([3, 4, 3, 4], [9, 11, 13, 15])
    assert chord_bend_offset(count, first, last, 0, 4, 1e-3) == 0.0


def test_bent_strips_add_c22_times_the_bend_offset(table, pairs):
    # an ellipse whose strips are shifted by whole cells (the horns lead): each zone's c23
    # grows by c22 offset / sqrt(A'), offset the bend of its strips (positive here)
    base = areas.ellipse(4e-3, 6e-3, nx=30, ny=30)
    shift = np.rint(6.0 * ((base.y - base.y.mean()) / 6e-3) ** 2).astype(int)
    p = np.zeros((base.ny, base.nx + 8))
    for j, k in enumerate(shift):
        p[j, k:k + base.nx] = base.pressure[j]
    ar = areas.GridArea(base.x0, base.y0, base.dx, base.dy, p)
    geo = mae_geometry(ar)
    lower = ar.y < geo.y_s
    plain = _paired_coefficients(geo, table, pairs, "shared")  # rule 1 alone
    bent = zone_coefficients(ar, geo, table, pairs)
    for zone, rows, c0, c in zip((geo.zone1, geo.zone2), (lower, ~lower), plain, bent):
        count, first, last = row_extents(ar.mask & rows[:, None])
        offset = chord_bend_offset(count, first, last, 0, ar.ny, ar.dx)
        assert offset > 0.25 * ar.dx
        expected = c0["c23"] + c0["c22"] * offset / math.sqrt(2.0 * zone.area / math.pi)
        assert c["c23"] == pytest.approx(expected, rel=1e-9)
        assert c["c11"] == c0["c11"] and c["c22"] == c0["c22"]


def test_straight_zones_are_not_offset(table, pairs):
    # an ellipse moved along x: every strip centred on the centroid, c23 untouched
    ar = areas.ellipse(5e-3, 3e-3, nx=30, ny=24).shifted(2e-3, 0.0)
    geo = mae_geometry(ar)
    for zone, c in zip((geo.zone1, geo.zone2), zone_coefficients(ar, geo, table, pairs)):
        assert c["c23"] == pytest.approx(table.half(zone.a_over_b)["c23"], rel=1e-9)


def test_crescent_c23_near_exact(table, pairs):
    # the paper's MAE + FastSim is 31% low in C~23 on this crescent, MAE's own geometry 12%
    # low; with the strips' offsets the calibrated method is within 5% (no parameter fitted)
    grids = (24, 36, 48, 60)
    per = [exact.creep_coefficients(samples.crescent_patch(cells=n), nu=NU).C23 for n in grids]
    c23_exact = float(np.polyfit([1.0 / n for n in grids], per, 1)[1])
    c = mae_calibrated_coefficients(samples.crescent_patch(cells=60), table, pairs)
    assert c.C23 == pytest.approx(c23_exact, rel=0.05)


def test_egg_with_the_longer_half_trailing_c23_near_exact(table, pairs):
    # C~23 about the join of the halves is small here (0.41): the first form of rule 4 (every
    # strip offset counted) put it 0.11 high; the bend alone keeps it within 0.05
    grids = (24, 36, 48, 60)
    per = [exact.creep_coefficients(samples.egg_patch(cells=n, lead_over_trail=0.5),
                                    nu=NU).C23 for n in grids]
    c23_exact = float(np.polyfit([1.0 / n for n in grids], per, 1)[1])
    c = mae_calibrated_coefficients(samples.egg_patch(cells=60, lead_over_trail=0.5), table,
                                    pairs)
    assert c.C23 == pytest.approx(c23_exact, abs=0.05)


def test_a_bend_whose_horns_trail_leaves_c23_alone(table, pairs, solver):
    # the mirror image in x of a horns-leading crescent: its bend offset is negative, and
    # rule 4 only raises c23 (a lower c23 would halve the lateral force under spin)
    ar = samples.crescent_patch(cells=40, bend=-1.5, a_over_b=0.35)
    geo = mae_geometry(ar)
    lower = ar.y < geo.y_s
    for rows in (lower, ~lower):
        count, first, last = row_extents(ar.mask & rows[:, None])
        assert chord_bend_offset(count, first, last, 0, ar.ny, ar.dx) < -0.03 * math.sqrt(
            ar.area)
    assert zone_coefficients(ar, geo, table, pairs) == _paired_coefficients(
        geo, table, pairs, "shared")
    loaded = samples.crescent_patch(cells=40, scale=0.01, load=3e4, bend=-1.5, a_over_b=0.35)
    bound = traction_bound(loaded, MU)
    for creep in ((0.0, 0.0, 2.0), (1e-4, 2e-4, 0.5)):
        ref = mae_calibrated_fastsim(loaded, *creep, bound=bound, table=table, pairs=pairs,
                                     shear_modulus=G, knee=knee_factors(NU))
        res = solver.solve(loaded, *creep, mu=MU)
        assert_forces(res, ref.fx, ref.fy, ref.mz, size(loaded))
