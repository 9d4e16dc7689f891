"""PointCloud2 -> contact patch: layouts, the contact frame, the grid, and every rejection."""

import math

import numpy as np
import pytest
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import PointCloud2

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import samples
from msg_adapters import cdr
from msg_adapters.errors import RejectedInput
from msg_adapters.patch import patch_from_cloud
from ros_messages import cdr as to_cdr
from ros_messages import cloud_msg, contact_normal, in_plane_area

MAX = 16384


def egg():
    """Return an area with no symmetry in x or y (two semi-ellipses, Hertz-like pressure)."""
    return samples.semi_ellipses_patch(0.5, 2.0, cells=24, scale=8e-3, load=6e4)


def convert(msg, max_cells=MAX):
    return patch_from_cloud(cdr.read_cloud(to_cdr(msg)), max_cells=max_cells)


def assert_grid(patch, area, rtol=1e-6):
    """Assert that the patch carries the area's pressure on its grid, about its centroid."""
    ref = in_plane_area(area)
    scale = max(area.dx, area.dy)
    assert patch.pressure.shape == area.pressure.shape
    np.testing.assert_allclose(patch.pressure, area.pressure, rtol=rtol)
    assert patch.dx == pytest.approx(area.dx, rel=rtol)
    assert patch.dy == pytest.approx(area.dy, rel=rtol)
    assert abs(patch.x0 - ref.x0) < rtol * scale * 30
    assert abs(patch.y0 - ref.y0) < rtol * scale * 30
    assert patch.load == pytest.approx(area.load, rel=rtol)
    assert patch.cells == int(np.count_nonzero(area.mask))


@pytest.mark.parametrize("dtype", ["<f4", ">f4", "<f8", ">f8"])
@pytest.mark.parametrize("pad", [0, 4])
def test_layouts_give_the_same_patch(dtype, pad):
    area = egg()
    patch = convert(cloud_msg(area, dtype=dtype, pad=pad))
    assert_grid(patch, area, rtol=1e-5 if dtype.endswith("4") else 1e-9)


def test_fields_in_any_order():
    area = egg()
    order = ["pressure", "normal_z", "x", "normal_x", "z", "y", "normal_y"]
    assert_grid(convert(cloud_msg(area, field_order=order, dtype="<f8")), area, rtol=1e-9)


def test_mixed_field_types_are_read_per_field():
    area = egg()
    msg = cloud_msg(area, dtype="<f8")
    # make pressure float32 at its own offset after the seven doubles
    values = np.frombuffer(bytes(msg.data), dtype="<f8").reshape(area.ny, area.nx, 7)
    rec = np.zeros((area.ny, area.nx, 7 * 8 + 4), dtype=np.uint8)
    rec[..., :56] = values.view(np.uint8).reshape(area.ny, area.nx, 56)
    rec[..., 56:60] = values[..., 6].astype("<f4").view(np.uint8).reshape(area.ny, area.nx, 4)
    msg.fields[6].offset, msg.fields[6].datatype = 56, 7
    msg.point_step, msg.row_step = 60, 60 * area.nx
    msg.data = rec.tobytes()
    assert_grid(convert(msg), area, rtol=1e-6)


@pytest.mark.parametrize("rows, columns", [(True, False), (False, True), (True, True)])
def test_points_running_the_other_way_are_reordered(rows, columns):
    area = egg()
    patch = convert(cloud_msg(area, dtype="<f8", reverse_rows=rows, reverse_columns=columns))
    assert_grid(patch, area, rtol=1e-9)
    assert patch.row_order == (-1 if rows else 1)
    assert patch.column_order == (-1 if columns else 1)


def test_tilted_patch_frame():
    # a flange-root contact: normal tilted by 0.5 rad towards the track centre
    area = egg()
    gamma = 0.5
    normal = contact_normal(gamma, "left")
    origin = (0.01, 0.72, -0.45)
    patch = convert(cloud_msg(area, origin=origin, normal=normal, dtype="<f8"))
    ex, ey, ez = (np.array(a) for a in patch.frame.axes)
    np.testing.assert_allclose(ez, normal, atol=1e-12)
    np.testing.assert_allclose(ex, [1.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(ey, np.cross(ez, ex), atol=1e-12)
    assert ey[1] == pytest.approx(math.cos(gamma)) and ey[2] == pytest.approx(math.sin(gamma))
    # origin: the pressure-weighted centroid, in the wheelset frame
    ref = in_plane_area(area)
    shift = np.array([area.x0 - ref.x0, area.y0 - ref.y0])
    np.testing.assert_allclose(patch.frame.origin, np.array(origin) + shift[0] * ex
                               + shift[1] * ey, atol=1e-12)
    assert_grid(patch, area, rtol=1e-9)


def test_frame_x_is_the_wheelset_x_projected():
    # a normal with a forward tilt: e_x stays in the plane spanned by x and the normal
    area = areas.ellipse(6e-3, 4e-3, nx=20, ny=20).with_load(5e4)
    normal = (math.sin(0.1), 0.0, math.cos(0.1))
    patch = convert(cloud_msg(area, normal=normal, dtype="<f8"))
    ex, _, ez = (np.array(a) for a in patch.frame.axes)
    assert ex @ ez == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(ex, [math.cos(0.1), 0.0, -math.sin(0.1)], atol=1e-12)
    quat = patch.frame.quaternion()
    assert sum(q * q for q in quat) == pytest.approx(1.0)


def test_empty_patch_is_no_contact():
    area = egg()
    assert convert(cloud_msg(area, pressure=np.zeros_like(area.pressure))) is None
    empty = PointCloud2()
    empty.fields = cloud_msg(area).fields
    empty.point_step = 28
    empty.header.frame_id = "wheelset"
    assert patch_from_cloud(cdr.read_cloud(to_cdr(empty)), max_cells=MAX) is None


@pytest.mark.parametrize("emptied", ["width", "height"])
def test_a_grid_of_no_points_over_a_patchs_data_is_irregular_not_empty(emptied):
    """A zero width (or height) with the points still there is malformed, not a lifted wheel.

    The grid's size alone must not make it an empty patch: that would
    publish a zero wrench for a message that carries a whole loaded patch.
    """
    msg = cloud_msg(egg(), dtype="<f8")
    setattr(msg, emptied, 0)
    if emptied == "width":
        msg.row_step = 0
    error = rejected(msg, "irregular_grid")
    assert f"{len(bytes(msg.data))} bytes" in str(error)


def rejected(msg, reason, max_cells=MAX):
    with pytest.raises(RejectedInput) as info:
        convert(msg, max_cells)
    assert info.value.reason == reason
    return info.value


@pytest.mark.parametrize("field", ["x", "normal_y", "pressure"])
@pytest.mark.parametrize("value", [math.nan, math.inf])
def test_nonfinite(field, value):
    area = egg()
    msg = cloud_msg(area, dtype="<f8")
    values = np.frombuffer(bytes(msg.data), dtype="<f8").reshape(area.ny, area.nx, 7).copy()
    values[3, 4, ["x", "y", "z", "normal_x", "normal_y", "normal_z",
                  "pressure"].index(field)] = value
    msg.data = values.tobytes()
    rejected(msg, "nonfinite")


def test_negative_pressure():
    area = egg()
    p = area.pressure.copy()
    p[0, 0] = -1.0
    rejected(cloud_msg(area, pressure=p), "negative_pressure")


def test_missing_and_unreadable_fields():
    area = egg()
    msg = cloud_msg(area)
    msg.fields = [f for f in msg.fields if f.name != "pressure"]
    assert "pressure" in str(rejected(msg, "missing_field"))
    msg = cloud_msg(area)
    msg.fields[6].datatype = 2  # uint8
    rejected(msg, "missing_field")


def test_irregular_grid():
    area = egg()
    msg = cloud_msg(area, dtype="<f8")
    values = np.frombuffer(bytes(msg.data), dtype="<f8").reshape(area.ny, area.nx, 7).copy()
    values[5, :, 0] += 0.3 * area.dx  # one strip shifted by 0.3 cell along x
    msg.data = values.tobytes()
    rejected(msg, "irregular_grid")
    values[5, :, 0] -= 0.3 * area.dx
    values[:, 7, 1] += 0.25 * area.dy  # one column bent sideways
    msg.data = values.tobytes()
    rejected(msg, "irregular_grid")


def test_stray_point_far_away_is_irregular():
    area = egg()
    msg = cloud_msg(area, dtype="<f8")
    values = np.frombuffer(bytes(msg.data), dtype="<f8").reshape(area.ny, area.nx, 7).copy()
    values[0, 0, 0] += 100.0
    msg.data = values.tobytes()
    rejected(msg, "irregular_grid")


def test_truncated_data_is_irregular():
    area = egg()
    msg = cloud_msg(area)
    msg.data = bytes(msg.data)[:-28]
    rejected(msg, "irregular_grid")


def test_huge_grid_refused_before_reading():
    # 1e6 x 1e6 points declared, no data: refused on the header alone
    msg = cloud_msg(egg())
    msg.height, msg.width = 1_000_000, 1_000_000
    msg.data = b""
    rejected(msg, "too_large")
    rejected(cloud_msg(egg()), "too_large", max_cells=24 * 24 - 1)


@pytest.mark.parametrize("case", ["three_cells", "one_row", "coincident", "tiny"])
def test_degenerate(case):
    area = egg()
    if case == "three_cells":
        p = np.zeros_like(area.pressure)
        p[5, 5:8] = 1e9
        msg = cloud_msg(area, pressure=p)
    elif case == "one_row":
        strip = areas.GridArea(0.0, 0.0, 1e-3, 1e-3, np.ones((1, 10)))
        msg = cloud_msg(strip)
    elif case == "coincident":
        msg = cloud_msg(area.scaled(0.0) if False else area, dtype="<f8")
        values = np.frombuffer(bytes(msg.data), dtype="<f8").reshape(area.ny, area.nx, 7)
        values = values.copy()
        values[..., 0:3] = (0.0, 0.75, -0.46)
        msg.data = values.tobytes()
    else:  # coordinates of 1e-200 m
        msg = cloud_msg(area.scaled(1e-200), origin=(0.0, 0.0, 0.0), dtype="<f8")
    rejected(msg, "degenerate")


def test_round_trip_of_the_cdr_view():
    # what the adapter reads is what rclpy serialised
    area = egg()
    msg = cloud_msg(area, stamp_ns=1_700_000_000_123_456_789)
    view = cdr.read_cloud(to_cdr(msg))
    back = deserialize_message(to_cdr(msg), PointCloud2)
    assert view.stamp_ns == 1_700_000_000_123_456_789
    assert view.frame_id == back.header.frame_id == "wheelset"
    assert (view.height, view.width) == (back.height, back.width)
    assert bytes(view.data) == bytes(back.data)
    assert {n: (f.offset, f.datatype, f.count) for n, f in view.fields.items()} == {
        f.name: (f.offset, f.datatype, f.count) for f in back.fields}


def test_a_topic_reader_parses_the_header_once_and_anything_new_afresh():
    reader = cdr.CloudReader()
    area = egg()
    first = to_cdr(cloud_msg(area, stamp_ns=5))
    assert reader.read(first) == cdr.read_cloud(first)
    # the same header, a new stamp and new points: the last parse, the new numbers
    p = area.pressure * 2.0
    again = to_cdr(cloud_msg(area, stamp_ns=1_700_000_000_000_000_001, pressure=p))
    got = reader.read(again)
    assert got == cdr.read_cloud(again)
    assert got.stamp_ns == 1_700_000_000_000_000_001
    assert patch_from_cloud(got, max_cells=MAX).load == pytest.approx(2.0 * area.load, rel=1e-5)
    # another frame id, another size, another byte order: each parsed as it comes
    for msg in (cloud_msg(area, stamp_ns=6, frame_id="base"),
                cloud_msg(areas.ellipse(6e-3, 4e-3, nx=9, ny=7).with_load(5e4), stamp_ns=7),
                cloud_msg(area, stamp_ns=8, dtype=">f8")):
        raw = to_cdr(msg)
        assert reader.read(raw) == cdr.read_cloud(raw)
    # cut short behind the same header: not read from the last parse
    reader.read(first)
    with pytest.raises(cdr.MalformedMessageError, match="truncated"):
        reader.read(first[:-40])
