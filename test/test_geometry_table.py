"""The contact table: levelled roll, nodes, mirror, blending, Hertz scaling, range, files."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from fastsim_ros.geometry import benchmark
from fastsim_ros.geometry.errors import DerailmentError
from fastsim_ros.geometry.placement import Pose
from fastsim_ros.geometry.profiles import read_profile
from fastsim_ros.geometry.table import (MATCH_DISTANCE, BlendPlan, ContactTable, TableError,
                                        TableGrid, TableNode, TablePatch, TableRangeError,
                                        blend, cached_table, levelled_roll, solve_node, table_key)
from fastsim_ros.geometry.wheelset import Wheelset

DATA = benchmark.DATA.parent / "profiles"
LOAD = 1e4


@pytest.fixture(scope="module")
def wheelset():
    wheel = read_profile(DATA / "MBench_S1002_v3.prw", kind="wheel")
    rail = read_profile(DATA / "MBench_UIC60_v3.prr", kind="rail")
    return Wheelset(wheel, rail, shear_modulus=82e9, poisson_ratio=0.28)


@pytest.fixture(scope="module")
def grid():
    return TableGrid.regular(-2e-3, 2e-3, 1e-3, 5e-3, 5e-3)


@pytest.fixture(scope="module")
def table(wheelset, grid):
    return ContactTable.build(wheelset, grid, LOAD)


def _centroid(patch: TablePatch) -> np.ndarray:
    points, _, pressure = patch.cloud_arrays()
    return np.tensordot(pressure, points, axes=2) / pressure.sum()


# ---------------------------------------------------------------------------- the roll


@pytest.mark.parametrize("case", benchmark.a22("left"), ids=lambda c: f"pose{c.number}")
def test_levelled_roll_is_the_benchmark_roll(wheelset, case):
    # CONTACT's A-2.2 roll is solved under the loads; the rigid wheels' levelled roll differs
    # by the elastic approaches' difference: micro-radians on the treads (poses 1-13), up to
    # 0.2 mrad once a flange carries one wheel (its approach there is far smaller)
    roll, dz = levelled_roll(wheelset, case.dy, case.yaw)
    tolerance = 1e-5 if case.number <= 13 else 2e-4
    assert roll == pytest.approx(case.roll, abs=tolerance)
    pose = Pose(dy=case.dy, dz=dz, yaw=case.yaw, roll=roll)
    # both rigid wheels touch at that height
    assert wheelset.vertical_gap("left", pose) == pytest.approx(0.0, abs=1e-9)
    assert wheelset.vertical_gap("right", pose) == pytest.approx(0.0, abs=1e-9)


def test_levelled_roll_is_odd_in_the_pose(wheelset):
    roll, dz = levelled_roll(wheelset, 3e-3, 4e-3)
    mirrored, dz_m = levelled_roll(wheelset, -3e-3, -4e-3)
    assert mirrored == pytest.approx(-roll, abs=1e-12)
    assert dz_m == pytest.approx(dz, abs=1e-12)


# ---------------------------------------------------------------------------- nodes


def test_a_node_holds_the_wheels_loaded_at_the_levelled_roll(wheelset, table, grid):
    i, j = 3, 2   # dy = 1 mm, yaw = 5 mrad
    dy, yaw = grid.dys[i], grid.yaws[j]
    node = table.node(i, j)
    roll, dz = levelled_roll(wheelset, dy, yaw)
    assert node.roll == roll
    for k, side in enumerate(("left", "right")):
        wheel = wheelset.wheel_loaded(side, Pose(dy=dy, dz=dz, yaw=yaw, roll=roll), LOAD)
        (solved,) = wheel.patches
        (held,) = node.patches[k]
        points, normal, pressure = held.cloud_arrays()
        # the same cells in the same places (the table turns the right wheel's rows round)
        assert held.load == pytest.approx(solved.load, rel=1e-9)
        assert held.cells == solved.cells
        centroid = np.tensordot(solved.pressure, solved.points, axes=2) / solved.pressure.sum()
        np.testing.assert_allclose(_centroid(held), centroid, atol=1e-12)
        np.testing.assert_allclose(normal, solved.normal, atol=1e-12)
        # the vertical balance held at the reference load (no creep forces in a node)
        assert held.vertical_normal_force(Pose(dy=dy, yaw=yaw, roll=roll).rotation()) \
            == pytest.approx(LOAD, rel=1e-6)


def test_the_mirror_equals_the_right_wheel_solved(wheelset, grid, table):
    # the same profiles given for the right side: no mirror, both wheels solved
    asymmetric = Wheelset(read_profile(DATA / "MBench_S1002_v3.prw", kind="wheel"),
                          read_profile(DATA / "MBench_UIC60_v3.prr", kind="rail"),
                          right_wheel=read_profile(DATA / "MBench_S1002_v3.prw", kind="wheel"),
                          right_rail=read_profile(DATA / "MBench_UIC60_v3.prr", kind="rail"),
                          shear_modulus=82e9, poisson_ratio=0.28)
    assert wheelset.symmetric and not asymmetric.symmetric and grid.symmetric
    node = solve_node(asymmetric, LOAD, grid.dys[1], grid.yaws[0])
    mirrored = table.node(1, 0).patches[1]
    assert len(node.patches[1]) == len(mirrored) == 1
    direct, twin = node.patches[1][0], mirrored[0]
    np.testing.assert_allclose(twin.origin, direct.origin, atol=1e-12)
    np.testing.assert_allclose(twin.normal, direct.normal, atol=1e-12)
    assert twin.pressure.shape == direct.pressure.shape
    np.testing.assert_allclose(twin.pressure, direct.pressure, rtol=1e-8,
                               atol=1e-8 * direct.pressure.max())


# ---------------------------------------------------------------------------- lookups


def test_on_a_node_the_lookup_is_the_node(table, grid):
    hit = table.lookup(grid.dys[2], grid.yaws[1])
    node = table.node(2, 1)
    assert hit.roll == node.roll
    for k, side in enumerate(("left", "right")):
        assert [p is q for p, q in zip(hit.patches(side), node.patches[k])] == [True]


def test_between_nodes_load_roll_and_position_are_the_weighted_means(table, grid):
    dy, yaw = 0.25 * grid.dys[2] + 0.75 * grid.dys[3], grid.yaws[1]
    hit = table.lookup(dy, yaw)
    a, b = table.node(2, 1), table.node(3, 1)
    assert hit.roll == pytest.approx(0.25 * a.roll + 0.75 * b.roll, abs=1e-15)
    for k, side in enumerate(("left", "right")):
        (patch,) = hit.patches(side)
        pa, pb = a.patches[k][0], b.patches[k][0]
        assert patch.load == pytest.approx(0.25 * pa.load + 0.75 * pb.load, rel=1e-12)
        origin = 0.25 * pa.origin + 0.75 * pb.origin
        np.testing.assert_allclose(patch.origin, origin, atol=1e-15)
        # the resampled field is trimmed to the blended cells, its centroid on the origin
        assert patch.cells == round(0.25 * pa.cells + 0.75 * pb.cells)
        np.testing.assert_allclose(_centroid(patch), origin, atol=1e-12)
        load = patch.pressure.sum() * patch.da * patch.db
        assert load == pytest.approx(patch.load, rel=1e-12)
        # the patch lies in the adapter's contact frame (x the wheelset's x projected)
        ex = np.array([1.0, 0.0, 0.0]) - patch.normal[0] * patch.normal
        np.testing.assert_allclose(patch.u, ex / np.linalg.norm(ex), atol=1e-12)
        np.testing.assert_allclose(np.cross(patch.normal, patch.u), patch.v, atol=1e-12)


def test_the_blend_tends_to_the_node_as_the_pose_nears_it(table, grid):
    node = table.node(2, 1).patches[0][0]
    other = table.node(3, 1).patches[0][0]
    errors = []
    for t in (0.3, 0.1, 0.01):
        dy = (1.0 - t) * grid.dys[2] + t * grid.dys[3]
        (patch,) = table.lookup(dy, grid.yaws[1]).patches("left")
        errors.append(float(np.linalg.norm(patch.origin - node.origin)))
        assert patch.cells == round((1.0 - t) * node.cells + t * other.cells)
        assert patch.load == pytest.approx((1.0 - t) * node.load + t * other.load, rel=1e-12)
        # the shape: the weighted sum of the fields, so the peak pressure near the weighted
        # peaks (the members' peaks lie near, not on, one another)
        peak = (1.0 - t) * node.pressure.max() + t * other.pressure.max()
        assert patch.pressure.max() == pytest.approx(peak, rel=0.1)
    # the origin runs along the line between the nodes' (the tread contact runs 10.6 mm here)
    distance = float(np.linalg.norm(other.origin - node.origin))
    assert errors == pytest.approx([0.3 * distance, 0.1 * distance, 0.01 * distance], rel=1e-9)


def test_hertz_scaling_of_a_patch(table):
    patch = table.node(2, 1).patches[0][0]
    for s in (0.8, 1.25):
        scaled = patch.scaled(s)
        assert scaled.load == pytest.approx(s ** 3 * patch.load, rel=1e-12)
        assert scaled.cells == round(s ** 2 * patch.cells)
        np.testing.assert_allclose(_centroid(scaled), patch.origin, atol=1e-12)
        # the peak pressure grows like s (Hertz: p0 = 3N / (2 pi a b)), within the
        # resampling's smoothing of the peak (a cell of 0.2 mm on a 6 mm patch)
        assert scaled.pressure.max() / patch.pressure.max() == pytest.approx(s, rel=0.02)
        # the contact's length along x grows like s
        length = np.ptp(np.flatnonzero(scaled.pressure.any(axis=0))) * scaled.da
        length0 = np.ptp(np.flatnonzero(patch.pressure.any(axis=0))) * patch.da
        assert length / length0 == pytest.approx(s, abs=2 * patch.da / length0)


def test_a_patch_at_some_nodes_only_fades_in(table):
    patch = table.node(2, 1).patches[0][0]
    faded = blend([(1.0, patch)], fade=0.25)
    assert faded.load == pytest.approx(0.25 * patch.load, rel=1e-12)
    assert faded.cells == round(0.25 * patch.cells)
    np.testing.assert_allclose(_centroid(faded), patch.origin, atol=1e-12)
    # in a lookup: a second patch far away on one of two nodes joins with that node's weight
    far = replace(patch, origin=patch.origin + np.array([0.0, 3 * MATCH_DISTANCE, 0.0]))
    a, b = table.node(2, 1), table.node(3, 1)
    nodes = list(table.nodes)
    nodes[3 * len(table.grid.yaws) + 1] = TableNode(b.roll, b.dz, (b.patches[0] + (far,),
                                                                   b.patches[1]))
    edited = ContactTable(table.grid, table.load, nodes)
    hit = edited.lookup(0.5 * (table.grid.dys[2] + table.grid.dys[3]), table.grid.yaws[1])
    plans = hit.groups[0]
    assert len(plans) == 2
    faded_plan = next(p for p in plans if p.fade < 1.0)
    assert faded_plan.fade == pytest.approx(0.5)
    assert faded_plan.load == pytest.approx(0.5 * far.load, rel=1e-12)
    assert isinstance(faded_plan, BlendPlan) and a.patches[0][0] is not None


def test_poses_outside_the_table_are_refused(table, grid):
    with pytest.raises(TableRangeError, match="dy"):
        table.lookup(grid.dys[-1] + 1e-4, 0.0)
    with pytest.raises(TableRangeError, match="yaw"):
        table.lookup(0.0, grid.yaws[-1] + 1e-4)
    table.lookup(grid.dys[-1], grid.yaws[0])   # the edges are in


def test_a_pose_next_to_a_derailed_node_is_a_derailment(table):
    nodes = list(table.nodes)
    nodes[0] = TableNode(0.0, 0.0, ((), ()), derailed=True)
    edited = ContactTable(table.grid, table.load, nodes)
    with pytest.raises(DerailmentError, match="derails"):
        edited.lookup(0.5 * (table.grid.dys[0] + table.grid.dys[1]), table.grid.yaws[0])
    edited.lookup(table.grid.dys[2], table.grid.yaws[0])   # elsewhere served


@pytest.mark.parametrize("args, why", [((-2e-3, 2e-3, 3e-3, 0.0, 1e-3), "divide"),
                                       ((2e-3, -2e-3, 1e-3, 0.0, 1e-3), "range"),
                                       ((-2e-3, 2e-3, 0.0, 0.0, 1e-3), "range"),
                                       ((-2e-3, 2e-3, 1e-3, 5e-3, 3e-3), "divide")])
def test_bad_grids_are_refused(args, why):
    with pytest.raises(TableError, match=why):
        TableGrid.regular(*args)


def test_a_table_needs_a_load(wheelset, grid):
    with pytest.raises(TableError, match="load"):
        ContactTable.build(wheelset, grid, 0.0)


# ---------------------------------------------------------------------------- files


def test_save_and_read_round_trip(table, wheelset, grid, tmp_path):
    key = table_key(wheelset, grid, LOAD)
    path = tmp_path / "t.npz"
    table.save(path, key)
    back = ContactTable.read(path, key)
    assert back.grid == table.grid and back.load == table.load
    for n, m in zip(table.nodes, back.nodes):
        assert (n.roll, n.dz, n.derailed) == (m.roll, m.dz, m.derailed)
        for side in range(2):
            for p, q in zip(n.patches[side], m.patches[side], strict=True):
                np.testing.assert_array_equal(p.pressure, q.pressure)
                np.testing.assert_array_equal(p.origin, q.origin)
                assert (p.a0, p.b0, p.da, p.db, p.load, p.cells) == \
                    (q.a0, q.b0, q.da, q.db, q.load, q.cells)
    with pytest.raises(TableError, match="other profiles"):
        ContactTable.read(path, "0" * 32)
    (tmp_path / "junk.npz").write_bytes(b"not a table")
    with pytest.raises(TableError, match="not a contact table"):
        ContactTable.read(tmp_path / "junk.npz")
    assert [p.name for p in tmp_path.iterdir()] in (["t.npz", "junk.npz"],
                                                    ["junk.npz", "t.npz"])


def test_a_damaged_table_file_is_a_table_error(table, wheelset, grid, tmp_path):
    """Empty, truncated, bit-flipped, a plain array, NaN pressures: TableError, never another.

    The cache then rebuilds (cached_table catches TableError), where an
    EOFError, BadZipFile, TypeError or ValueError would end the node's start
    with a traceback and fail the lifecycle node's configure without a word.
    """
    key = table_key(wheelset, grid, LOAD)
    good = tmp_path / "t.npz"
    table.save(good, key)
    data = good.read_bytes()
    flipped = bytearray(data)
    flipped[len(data) // 2] ^= 0xFF
    damaged = {"empty.npz": b"", "truncated.npz": data[:len(data) // 3],
               "flipped.npz": bytes(flipped), "tail.npz": data[:-40]}
    for name, content in damaged.items():
        (tmp_path / name).write_bytes(content)
    np.save(tmp_path / "array.npy", np.zeros(3))
    (tmp_path / "array.npy").rename(tmp_path / "array.npz")
    with np.load(good) as f:
        arrays = {k: f[k] for k in f.files}
    arrays["pressure"] = arrays["pressure"].copy()
    arrays["pressure"][0] = np.nan
    np.savez(tmp_path / "nan.npz", **arrays)
    for name in (*damaged, "array.npz", "nan.npz"):
        try:
            ContactTable.read(tmp_path / name, key)
        except TableError as e:
            assert "not a contact table" in str(e) or "other profiles" in str(e), name
        else:
            assert name == "flipped.npz"  # a flip inside a pressure may still read


def test_the_key_follows_every_input(wheelset, grid):
    key = table_key(wheelset, grid, LOAD)
    assert table_key(wheelset, grid, 2 * LOAD) != key
    assert table_key(wheelset, TableGrid.regular(-2e-3, 2e-3, 5e-4, 5e-3, 5e-3), LOAD) != key
    other = Wheelset(read_profile(DATA / "MBench_S1002_v3.prw", kind="wheel"),
                     read_profile(DATA / "MBench_UIC60_v3.prr", kind="rail"),
                     shear_modulus=82e9, poisson_ratio=0.28, cell=2.5e-4)
    assert table_key(other, grid, LOAD) != key
    same = Wheelset(read_profile(DATA / "MBench_S1002_v3.prw", kind="wheel"),
                    read_profile(DATA / "MBench_UIC60_v3.prr", kind="rail"),
                    shear_modulus=82e9, poisson_ratio=0.28)
    assert table_key(same, grid, LOAD) == key


def test_the_cache_builds_once_then_reads(wheelset, tmp_path, monkeypatch):
    small = TableGrid.regular(-1e-3, 1e-3, 1e-3, 0.0, 1e-3)
    messages: list[str] = []
    first = cached_table(wheelset, small, LOAD, tmp_path, log=messages.append)
    assert any("solving 3 nodes" in m for m in messages)
    (path,) = tmp_path.glob("contact_table_*.npz")

    def no_build(*args, **kwargs):
        raise AssertionError("rebuilt a cached table")
    monkeypatch.setattr(ContactTable, "build", no_build)
    again = cached_table(wheelset, small, LOAD, tmp_path)
    np.testing.assert_array_equal(again.nodes[1].patches[0][0].pressure,
                                  first.nodes[1].patches[0][0].pressure)


def test_a_build_in_worker_processes_equals_one_in_process(wheelset):
    small = TableGrid.regular(-4e-3, 4e-3, 1e-3, 0.0, 1e-3)   # 9 nodes: two chunks
    serial = ContactTable.build(wheelset, small, LOAD)
    parallel = ContactTable.build(wheelset, small, LOAD, workers=2)
    for n, m in zip(serial.nodes, parallel.nodes):
        assert n.roll == m.roll
        for side in range(2):
            for p, q in zip(n.patches[side], m.patches[side], strict=True):
                np.testing.assert_array_equal(p.pressure, q.pressure)


def test_refinement_halves_the_steps_where_a_flange_takes_over(wheelset):
    # -6.4..-6.0 mm: the right wheel's gauge corner gives way to its flange between -6.3 and
    # -6.25 mm (the levelled roll runs from -1.5 to -0.76 mrad there, the contact angle from
    # 1.2 to 0.55 rad, N by 15 kN over 0.02 mm); no mirror on this grid: both wheels
    # solved, refined four times (the default)
    grid = TableGrid((-6.4e-3, -6.3e-3, -6.2e-3, -6.1e-3, -6.0e-3), (0.0,))
    coarse = ContactTable.build(wheelset, grid, LOAD)
    fine = ContactTable.build(wheelset, grid, LOAD, refine=4)
    steps = np.diff(fine.grid.dys)
    finest = np.flatnonzero(steps < 0.1e-3 / 16 * 1.001)
    assert finest.size and all(-6.3e-3 - 1e-12 <= fine.grid.dys[k] < -6.2e-3 for k in finest)
    for i, d in enumerate(grid.dys):   # the base nodes as they were
        assert fine.node(fine.grid.dys.index(d), 0).roll == coarse.node(i, 0).roll

    def right_force(lookup_or_node):
        """Return the right wheel's normal forces' sum (wheelset frame, N)."""
        if isinstance(lookup_or_node, TableNode):
            patches = lookup_or_node.patches[1]
        else:
            patches = lookup_or_node.patches("right")
        return sum((p.load * p.normal for p in patches), np.zeros(3))

    # in the transition, against the wheel solved there: the refined table is far closer
    for dy in (-6.29e-3, -6.27e-3, -6.26e-3):
        exact = right_force(solve_node(wheelset, LOAD, dy, 0.0))
        err_fine = np.linalg.norm(right_force(fine.lookup(dy, 0.0)) - exact)
        err_coarse = np.linalg.norm(right_force(coarse.lookup(dy, 0.0)) - exact)
        assert err_fine < 0.25 * err_coarse
        assert err_fine < 0.05 * np.linalg.norm(exact)


def test_refinement_keeps_the_grid_symmetric_for_the_mirror(wheelset):
    grid = TableGrid.regular(-6.4e-3, 6.4e-3, 0.4e-3, 0.0, 1e-3)
    table = ContactTable.build(wheelset, grid, LOAD, refine=2)
    assert table.grid.symmetric and len(table.grid.dys) > len(grid.dys)
    k = next(i for i, d in enumerate(table.grid.dys) if d not in grid.dys)
    mirror = table.grid.dys.index(min(table.grid.dys, key=lambda d: abs(d + table.grid.dys[k])))
    left, right = table.node(k, 0).patches[0], table.node(mirror, 0).patches[1]
    assert len(left) == len(right)
    for p, q in zip(left, right):
        np.testing.assert_allclose(q.origin, p.origin * np.array([1.0, -1.0, 1.0]), atol=1e-12)


@pytest.fixture(scope="module")
def flange_table(wheelset):
    """Return a table over the right flange's take-over, refined.

    Shifts -6.4..-6.0 mm by 0.1 mm at yaws 10 and 15 mrad (no mirror on
    this grid: both wheels solved).
    """
    grid = TableGrid((-6.4e-3, -6.3e-3, -6.2e-3, -6.1e-3, -6.0e-3), (10e-3, 15e-3))
    return ContactTable.build(wheelset, grid, LOAD, refine=4)


def _normal_force(patches):
    return sum((p.load * p.normal for p in patches), np.zeros(3))


def test_yaw_columns_are_aligned_on_the_flanges_take_over(wheelset, flange_table):
    # the right flange takes over at -6.222 mm at 10 mrad and -6.181 mm at 15 mrad; at 12.5
    # mrad, around its own take-over (interpolated: -6.2015 mm), the two columns are read at
    # the same distance from their own take-overs: the wheel's normal force (its size and
    # direction, 0.55 rad on the gauge corner, 1.2 on the flange) comes out far closer to
    # the wheel solved there than when both are read at the pose's own shift (both tables
    # without the yaw-refined window, which holds 12.5 mrad as a column of its own)
    (e10,), (e15,) = flange_table.events
    assert e10 == pytest.approx(-6.222e-3, abs=0.01e-3)
    assert e15 == pytest.approx(-6.181e-3, abs=0.01e-3)
    aligned = ContactTable(flange_table.grid, flange_table.load, flange_table.nodes)
    plain = ContactTable(flange_table.grid, flange_table.load, flange_table.nodes)
    plain.events = [[], []]

    aligned_err, plain_err = [], []
    for dy in np.linspace(-6.26e-3, -6.14e-3, 13):
        exact = _normal_force(solve_node(wheelset, LOAD, float(dy), 12.5e-3).patches[1])
        for t, errs in ((aligned, aligned_err), (plain, plain_err)):
            got = _normal_force(t.lookup(float(dy), 12.5e-3).patches("right"))
            errs.append(float(np.linalg.norm(got - exact) / np.linalg.norm(exact)))
    assert max(aligned_err) < 0.5 * max(plain_err)
    assert np.mean(aligned_err) < 0.5 * np.mean(plain_err)


def test_yaw_is_refined_around_the_flanges_take_over(wheelset, flange_table):
    # the flange's take-over is an event of both columns (the contact angle turns by 0.6
    # rad): the shifts within 40 um of both take-overs are solved at 11.25, 12.5 and 13.75
    # mrad too, each such column with its own take-over between its neighbours'; the
    # gauge corner's patches elsewhere are not refined in yaw
    assert all(t > 0.5 for turns in flange_table.turns for t in turns)
    (window,) = flange_table.refined[0]
    (e10,), (e15,) = flange_table.events
    lo, hi = min(e10, e15) - 40e-6, max(e10, e15) + 40e-6   # every shift in 40 um of both
    dys = np.asarray(window.grid.dys)
    step = float(np.diff(flange_table.grid.dys).min())   # the grid's finest: 6.25 um
    assert step == pytest.approx(0.1e-3 / 16, rel=1e-9)
    np.testing.assert_allclose(np.diff(dys), step, rtol=1e-9)
    assert lo <= dys[0] < lo + step and hi - step < dys[-1] <= hi
    assert window.grid.yaws == pytest.approx((10e-3, 11.25e-3, 12.5e-3, 13.75e-3, 15e-3),
                                             abs=1e-15)
    # each column's take-over between its neighbours', the end columns' as the grid's
    takeovers = [e for (e,) in window.events]
    assert takeovers == sorted(takeovers)
    assert takeovers[0] == pytest.approx(e10, abs=step) and takeovers[-1] == pytest.approx(
        e15, abs=step)
    # the window's columns are nodes solved there, both wheels, at their own levelled roll
    node = window.node(3, 2)
    solved = solve_node(wheelset, LOAD, window.grid.dys[3], 12.5e-3)
    assert node.roll == solved.roll
    for k in range(2):
        for p, q in zip(node.patches[k], solved.patches[k], strict=True):
            np.testing.assert_array_equal(p.pressure, q.pressure)
    # a pose in the window takes the window's table; outside it, the grid's
    assert flange_table.window(-6.2e-3, 11.9e-3) is window
    assert flange_table.window(-6.3e-3, 11.9e-3) is None
    assert flange_table.window(-6.2e-3, 15.0e-3) is window   # its end column: the grid's
    # between the window's columns the wheel's normal force is closer to the wheel solved at
    # the pose than the grid's alone gives (10-40 um either side of the take-over)
    grid_only = ContactTable(flange_table.grid, flange_table.load, flange_table.nodes)
    errs: dict[str, list[float]] = {"window": [], "grid": []}
    for yaw, dy in ((11.9e-3, -6.236e-3), (11.9e-3, -6.186e-3), (13.1e-3, -6.225e-3),
                    (13.1e-3, -6.168e-3)):
        exact = _normal_force(solve_node(wheelset, LOAD, dy, yaw).patches[1])
        for name, t in (("window", flange_table), ("grid", grid_only)):
            got = _normal_force(t.lookup(dy, yaw).patches("right"))
            errs[name].append(float(np.linalg.norm(got - exact) / np.linalg.norm(exact)))
    assert np.mean(errs["window"]) < 0.5 * np.mean(errs["grid"])


def test_a_table_with_windows_round_trips_and_an_older_version_is_rebuilt(
        wheelset, flange_table, tmp_path, monkeypatch):
    from fastsim_ros.geometry import table as table_module
    path = tmp_path / "t.npz"
    flange_table.save(path, "k")
    back = ContactTable.read(path, "k")
    (window,) = flange_table.refined[0]
    (again,) = back.refined[0]
    assert again.grid == window.grid and again.events == window.events
    for n, m in zip(window.nodes, again.nodes, strict=True):
        assert n.roll == m.roll
        for side in range(2):
            for p, q in zip(n.patches[side], m.patches[side], strict=True):
                np.testing.assert_array_equal(p.pressure, q.pressure)
    # a file of the previous layout (no windows) is refused by its version, not misread
    with np.load(path) as f:
        old = {k: f[k] for k in f.files if k not in ("windows", "window_yaws")}
    old["version"] = np.array(table_module.TABLE_VERSION - 1)
    np.savez(tmp_path / "old.npz", **old)
    with pytest.raises(TableError, match="version"):
        ContactTable.read(tmp_path / "old.npz", "k")


def test_windows_built_in_worker_processes_equal_those_built_in_process(
        wheelset, flange_table):
    serial = flange_table   # built in this process
    grid = TableGrid((-6.4e-3, -6.3e-3, -6.2e-3, -6.1e-3, -6.0e-3), (10e-3, 15e-3))
    parallel = ContactTable.build(wheelset, grid, LOAD, refine=4, workers=2)
    assert serial.grid == parallel.grid and serial.refined and parallel.refined
    for a, b in zip(serial.refined[0], parallel.refined[0], strict=True):
        assert a.grid == b.grid
        for n, m in zip(a.nodes, b.nodes, strict=True):
            assert n.roll == m.roll
            for side in range(2):
                for p, q in zip(n.patches[side], m.patches[side], strict=True):
                    np.testing.assert_array_equal(p.pressure, q.pressure)


def test_build_progress_logs_the_time_left_of_each_pass(monkeypatch):
    from fastsim_ros.geometry import table as table_module
    clock = iter([0.0, 10.0, 20.0, 20.0, 25.0, 30.0])
    monkeypatch.setattr(table_module.time, "monotonic", lambda: next(clock))
    lines = []
    progress = table_module.BuildProgress(lines.append, period=5.0)  # starts its clock at 0
    progress(100, 400)   # 10 s for 100 of 400: 30 s left
    progress(400, 400)   # the end of the pass is always logged: 0 s left
    progress(5, 50)      # a refinement pass: its own clock from 20 s (too early to log)
    progress(10, 50)     # 5 s for 10 of 50 in this pass: 20 s left
    assert lines == ["contact table: 100 of 400 nodes solved (25%), about 30 s left in this pass",
                     "contact table: 400 of 400 nodes solved (100%), about 0 s left in this pass",
                     "contact table: 10 of 50 nodes solved (20%), about 20 s left in this pass"]
