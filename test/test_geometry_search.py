"""Contact search against CONTACT's published A-2.2 reference points; symmetry; bad poses."""

from __future__ import annotations

import numpy as np
import pytest

from fastsim_ros.geometry import benchmark
from fastsim_ros.geometry.errors import DerailmentError, NoContactError, PoseError
from fastsim_ros.geometry.placement import Placement, Pose, place_rail, place_wheel
from fastsim_ros.geometry.planar import planar_grid
from fastsim_ros.geometry.profiles import S1002, UIC60, read_profile
from fastsim_ros.geometry.search import find_regions

CELL = 2e-4


@pytest.fixture(scope="module")
def placed():
    placement = Placement()
    return (place_rail(read_profile(UIC60), placement),
            place_wheel(read_profile(S1002), placement), placement.nominal_radius)


def _side_pose(case):
    pose = Pose(case.dy, case.dz, case.yaw, case.roll)
    return pose if case.side == "left" else pose.mirrored()


def test_benchmark_files_parse_to_21_finite_cases_per_wheel():
    for side in ("left", "right"):
        cases = benchmark.a22(side)
        assert [c.number for c in cases] == list(range(1, 22))
        assert all(benchmark.is_finite_case(c) for c in cases)
        assert all(c.side == side for c in cases)
    # CONTACT's fast methods: KPEC and ANALYN on the right wheel at poses 1, 2, 11
    fast = benchmark.a22_fast_methods()
    assert sorted((c.normal_method, benchmark.pose_number(c)) for c in fast) == [
        ("analyn", 1), ("analyn", 2), ("analyn", 11), ("kpec", 1), ("kpec", 2), ("kpec", 11)]


@pytest.mark.parametrize("side", ["left", "right"])
def test_reference_points_and_angles_match_contacts_on_all_poses(placed, side):
    # at CONTACT's own vertical position (printed to 0.1 um), the weighted reference of
    # every region and its contact angle: micrometres and 1e-4 rad, where the target
    # asks 0.5 mm and 0.01 rad
    rail, wheel, r0 = placed
    sign = 1.0 if side == "left" else -1.0
    for case in benchmark.a22(side):
        _, regions = find_regions(rail, wheel, _side_pose(case), r0, CELL)
        assert len(regions) == len(case.patches), case.number
        for region, ref in zip(sorted(regions, key=lambda r: -r.reference[1]), case.patches):
            x, y, z = region.reference
            assert x == pytest.approx(ref.reference[0], abs=0.02e-3), case.number
            assert sign * y == pytest.approx(ref.reference[1], abs=0.02e-3), case.number
            assert z == pytest.approx(ref.reference[2], abs=0.02e-3), case.number
            assert region.angle == pytest.approx(ref.angle, abs=3e-4), case.number


def test_the_planar_grid_spans_contacts_potential_area(placed):
    # CONTACT's potential contact grid of left pose 1 has 3999 cells; ours is built by
    # its rule (the interpenetration's extent plus a cell), so it has as many
    rail, wheel, r0 = placed
    case = benchmark.a22("left")[0]
    _, regions = find_regions(rail, wheel, _side_pose(case), r0, CELL)
    grid = planar_grid(regions[0], rail, wheel, _side_pose(case), r0, CELL)
    assert grid.gap.size == case.patches[0].potential_cells
    # the deepest interpenetration: CONTACT's approach within the 0.05 um its z is printed to
    assert -grid.gap.min() == pytest.approx(case.patches[0].approach, abs=0.1e-6)


def test_gap_along_the_normal_agrees_with_a_brute_force_search(placed):
    # an independent computation: march along the normal from a cell centre until the
    # point enters the wheel (radius test on the body of revolution), then bisect
    rail, wheel, r0 = placed
    case = benchmark.a22("right")[12]  # the gauge corner, contact angle 0.42 rad
    pose = _side_pose(case)
    _, regions = find_regions(rail, wheel, pose, r0, CELL)
    grid = planar_grid(regions[0], rail, wheel, pose, r0, CELL)
    centres = grid.centres()
    rot, centre = pose.rotation(), np.array([0.0, pose.dy, r0 + pose.dz])

    def inside_wheel(p):
        q = rot.T @ (p - centre)
        return np.hypot(q[0], q[2]) < np.interp(q[1], wheel.axial, wheel.radius)

    def rail_height(p):  # signed: positive where p lies above the rail (z up)
        return p[2] - np.interp(p[1], rail.y, rail.z)

    ny, nx = grid.shape
    for j, i in ((ny // 2, nx // 2), (ny // 3, nx // 4), (2 * ny // 3, 3 * nx // 4)):
        g = centres[j, i]

        def bisect(test, lo, hi):
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if not test(mid) else (lo, mid)
            return 0.5 * (lo + hi)

        t_wheel = bisect(lambda t: inside_wheel(g + t * grid.normal), -2e-3, 2e-3)
        t_rail = bisect(lambda t: rail_height(g + t * grid.normal) > 0.0, -2e-3, 2e-3)
        assert grid.gap[j, i] == pytest.approx(t_wheel - t_rail, abs=2e-9)


def test_left_and_right_are_mirror_images(placed):
    # the right wheel at a pose is the left wheel at the mirrored pose
    rail, wheel, r0 = placed
    pose = Pose(dy=-0.004, dz=-0.0002, yaw=0.01, roll=0.0004)
    _, direct = find_regions(rail, wheel, pose.mirrored(), r0, CELL)
    _, twice = find_regions(rail, wheel, pose.mirrored().mirrored().mirrored(), r0, CELL)
    assert len(direct) == len(twice)
    for a, b in zip(direct, twice):
        assert a.reference == b.reference and a.angle == b.angle


def test_a_lifted_wheel_has_no_region(placed):
    rail, wheel, r0 = placed
    _, regions = find_regions(rail, wheel, Pose(dy=0.0, dz=0.001), r0, CELL)
    assert regions == []


def test_a_pose_past_the_flange_is_a_derailment(placed):
    # 40 mm towards this rail, raised 20 mm: the flange tip rides on the rail head
    rail, wheel, r0 = placed
    with pytest.raises(DerailmentError, match="flange tip"):
        find_regions(rail, wheel, Pose(dy=0.04, dz=0.02), r0, CELL)


def test_profiles_that_never_meet_are_refused(placed):
    # rails 2 m apart under wheels 1.5 m apart: no lateral overlap at all
    _, wheel, r0 = placed
    wide = place_rail(read_profile(UIC60), Placement(gauge_width=2.0))
    with pytest.raises(NoContactError, match="do not overlap"):
        find_regions(wide, wheel, Pose(dy=0.0, dz=0.0), r0, CELL)


def test_a_wheel_shifted_far_to_the_field_side_is_off_the_rail(placed):
    rail, wheel, r0 = placed
    with pytest.raises(DerailmentError):
        find_regions(rail, wheel, Pose(dy=0.09, dz=0.0), r0, CELL)


@pytest.mark.parametrize("field, value", [("dy", float("nan")), ("yaw", 0.5),
                                          ("roll", float("inf")), ("dz", 1.0)])
def test_poses_out_of_range_are_refused(field, value):
    values = {"dy": 0.0, "dz": 0.0, "yaw": 0.0, "roll": 0.0, field: value}
    with pytest.raises(PoseError, match=field):
        Pose(**values)
