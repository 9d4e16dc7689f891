"""Profiles: reading SIMPACK and two-column files, orientation, cleaning, smoothing."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fastsim_ros.geometry.errors import PlacementError, ProfileError
from fastsim_ros.geometry.placement import Placement, place_rail, place_wheel
from fastsim_ros.geometry.profiles import (PACKAGE_ROOT, S1002, UIC60, expand_path,
                                           profile_from_points, read_profile)


@pytest.fixture(scope="module")
def wheel():
    return read_profile(S1002)


@pytest.fixture(scope="module")
def rail():
    return read_profile(UIC60)


def test_shipped_wheel_is_in_canonical_form(wheel):
    # CONTACT's canonical form: y to the field side, z down; S1002's flange tip lies
    # 28 mm below the tape circle, about 55 mm to the track-centre side of it
    assert wheel.kind == "wheel"
    assert np.all(np.diff(wheel.y) > 0.0)
    tip = int(np.argmax(wheel.z))
    assert wheel.z[tip] == pytest.approx(0.028, abs=0.1e-3)
    assert wheel.y[tip] == pytest.approx(-0.0549, abs=0.5e-3)
    assert not wheel.mirrored_y and not wheel.mirrored_z
    # the tread rises towards the field side (conicity): z < 0 there
    assert wheel.z[-1] < 0.0 < wheel.z[0]


def test_shipped_rail_is_in_canonical_form(rail):
    assert rail.kind == "rail"
    assert np.all(np.diff(rail.y) >= 0.0)
    top = int(np.argmax(-rail.z))
    assert abs(rail.z[top]) < 1e-6  # the highest point is the origin's height
    assert rail.z[0] > 0.03 and rail.z[-1] > 0.03  # the head's sides lie below its top


def test_dense_samples_follow_the_points(wheel):
    # the monotone cubic passes through every point and never overshoots
    assert np.allclose(wheel.z_at(wheel.y), wheel.z, atol=1e-12)
    assert wheel.dense_z.max() <= wheel.z.max() + 1e-12
    assert np.all(np.diff(wheel.dense_y) >= 0.0)


def _write_columns(path: Path, y, z, *, scale: float = 1e3, header: str = "y z") -> Path:
    path.write_text(header + "\n" + "\n".join(f"{a * scale:.9g}, {b * scale:.9g}"
                                              for a, b in zip(y, z)) + "\n")
    return path


@pytest.mark.parametrize("scale", [1e3, 1.0], ids=["millimetres", "metres"])
def test_two_column_file_in_either_unit_gives_the_simpack_profile(tmp_path, wheel, scale):
    path = _write_columns(tmp_path / "wheel.csv", wheel.y, wheel.z, scale=scale)
    other = read_profile(path, kind="wheel")
    assert np.allclose(other.y, wheel.y, atol=1e-12)
    assert np.allclose(other.z, wheel.z, atol=1e-12)


def test_a_wheel_given_flange_right_and_z_up_is_turned_to_canonical(tmp_path, wheel):
    # the same wheel mirrored in y and z, listed from the other end
    path = _write_columns(tmp_path / "turned.txt", -wheel.y[::-1], -wheel.z[::-1])
    other = read_profile(path, kind="wheel")
    assert other.mirrored_y and other.mirrored_z
    assert np.allclose(other.y, wheel.y, atol=1e-12)
    assert np.allclose(other.z, wheel.z, atol=1e-12)


def test_a_rail_given_z_up_is_turned(tmp_path, rail):
    path = _write_columns(tmp_path / "rail.txt", rail.y, -rail.z)
    other = read_profile(path, kind="rail")
    assert other.mirrored_z
    assert np.allclose(other.z, rail.z, atol=1e-12)


def _arc(n: int = 60) -> tuple[np.ndarray, np.ndarray]:
    y = np.linspace(-0.03, 0.03, n)
    return y, 0.3 - np.sqrt(0.3**2 - y**2)


@pytest.mark.parametrize("content, match", [
    ("", "no points"),
    ("y z\n1 2\n", r"1 distinct points, at least 10"),
    ("y z\n" + "\n".join(f"{k} nan" for k in range(20)), "line 2: not two numbers"),
    ("y z\n1 2 3\n", "expected two numbers"),
    ("y z\n1 2\nfoo bar\n", "line 3: not two numbers"),
    ("y z\n" + "\n".join(f"{k * 1e3} 0" for k in range(20)), r"neither 5\.\.500 mm"),
], ids=["empty", "too-few", "nan", "three-columns", "words", "units"])
def test_bad_two_column_files_are_refused_with_the_file_named(tmp_path, content, match):
    path = tmp_path / "bad.txt"
    path.write_text(content)
    with pytest.raises(ProfileError, match=match) as info:
        read_profile(path, kind="rail")
    assert str(path) in str(info.value)


def test_a_loop_is_refused_naming_the_point(tmp_path):
    y, z = _arc()
    y, z = list(y), list(z)
    # a small loop in the middle: the profile runs forward, back across itself, on
    y[30:30] = [y[30] + 0.002, y[30] + 0.001, y[30] + 0.0015]
    z[30:30] = [z[30], z[30] + 0.001, z[30] - 0.001]
    path = _write_columns(tmp_path / "loop.txt", y, z)
    with pytest.raises(ProfileError, match=r"loop.txt: point \d+ .*a loop"):
        read_profile(path, kind="rail")


def test_a_zigzag_is_refused_naming_the_point(tmp_path):
    y, z = _arc()
    y, z = list(y), list(z)
    # CONTACT's stitching pattern: a point repeated with a small offset backwards
    y.insert(31, y[30] - 1e-4)
    z.insert(31, z[30])
    y.insert(32, y[30] + 2e-5)
    z.insert(32, z[30])
    path = _write_columns(tmp_path / "zig.txt", y, z)
    with pytest.raises(ProfileError, match=r"zig.txt: point 3[12] .*zig-zag"):
        read_profile(path, kind="rail")


def test_nan_points_are_refused_naming_the_point():
    y, z = _arc()
    z = z.copy()
    z[7] = math.nan
    with pytest.raises(ProfileError, match="point 8 is not finite"):
        profile_from_points("rail", y, z)


def test_an_overhang_is_refused_naming_the_point(tmp_path):
    # a gauge face that turns past the vertical (smoothly: no zig-zag, no loop) and
    # runs back in y: an undercut no vertical view can see
    t = np.radians(np.linspace(-60.0, 110.0, 60))
    y, z = 0.01 * np.sin(t), 0.01 * (1.0 - np.cos(t))
    path = _write_columns(tmp_path / "overhang.txt", y, z)
    with pytest.raises(ProfileError, match=r"overhang.txt: point 5\d .*runs back in y"):
        read_profile(path, kind="rail")


@pytest.mark.parametrize("name, content, kind, match", [
    ("missing.prr", None, None, "cannot read"),
    ("w.prw", "header.begin\n type = 0\nheader.end\npoint.begin\n1 2\npoint.end\n", None,
     "header says it is a rail"),
    ("w.prw", "header.begin\nheader.end\n", None, "no 'point.begin'"),
    ("x.txt", "1 2\n", None, "say whether it is a wheel or a rail"),
    ("r.prr", "point.begin\n1 2\npoint.end\n", "wheel", "a .prr file is a rail profile"),
], ids=["missing", "header", "no-points", "no-kind", "kind-mismatch"])
def test_bad_simpack_files_are_refused(tmp_path, name, content, kind, match):
    path = tmp_path / name
    if content is not None:
        path.write_text(content)
    with pytest.raises(ProfileError, match=match):
        read_profile(path, kind=kind)


def test_bytes_that_are_not_text_are_refused(tmp_path):
    path = tmp_path / "bin.prr"
    path.write_bytes(b"\xff\xfe\x00\x81" * 100)
    with pytest.raises(ProfileError, match="bin.prr: not a text file"):
        read_profile(path)


def test_a_latin_1_comment_reads_as_the_same_profile(tmp_path):
    # a SIMPACK file edited on a Windows machine: a degree sign in Windows-1252 / Latin-1
    shipped = PACKAGE_ROOT / "data/profiles/MBench_S1002_v3.prw"
    raw = shipped.read_bytes()
    path = tmp_path / "s1002_latin1.prw"
    path.write_bytes(b"! inclination 1:40, 1.43\xb0, M\xfcller\n" + raw)
    with pytest.raises(UnicodeDecodeError):
        path.read_bytes().decode("utf-8")
    edited, original = read_profile(path), read_profile(shipped)
    assert np.array_equal(edited.dense_y, original.dense_y)
    assert np.array_equal(edited.dense_z, original.dense_z)


@pytest.mark.parametrize("text, expected", [
    ("$FASTSIM_TEST_RIG/w.prw", "/rigs/one/w.prw"),
    ("${FASTSIM_TEST_RIG}/w.prw", "/rigs/one/w.prw"),
    ("~/w.prw", None),
])
def test_paths_expand_the_home_and_environment_variables(monkeypatch, text, expected):
    monkeypatch.setenv("FASTSIM_TEST_RIG", "/rigs/one")
    path = expand_path(text)
    assert str(path) == (expected or str(Path.home() / "w.prw"))


def test_an_unset_variable_in_a_path_is_refused_naming_it(monkeypatch):
    monkeypatch.delenv("FASTSIM_TEST_UNSET", raising=False)
    with pytest.raises(ProfileError, match="FASTSIM_TEST_UNSET is not set"):
        read_profile("$FASTSIM_TEST_UNSET/w.prw")


def test_smoothing_damps_short_wavelengths_and_keeps_the_shape():
    rng = np.random.default_rng(3)
    y, z = _arc(400)
    noisy = z + 5e-6 * rng.standard_normal(z.size)
    # a rail head of radius 300 mm (z down) with 5 um of measurement noise
    rough = profile_from_points("rail", y, noisy)
    smooth = profile_from_points("rail", y, noisy, smooth=2e-3)
    truth = z
    err_rough = float(np.std(rough.z_at(y[5:-5]) - truth[5:-5]))
    err_smooth = float(np.std(smooth.z_at(y[5:-5]) - truth[5:-5]))
    assert err_smooth < 0.4 * err_rough
    # the 300 mm arc (a wavelength far above 2 mm) is kept
    assert abs(smooth.z_at(0.0) - truth[y.size // 2]) < 3e-6


def test_rail_placement_puts_the_gauge_point_at_half_the_gauge(rail):
    placement = Placement()
    placed = place_rail(rail, placement)
    assert placed.z.max() == pytest.approx(0.0, abs=1e-12)
    within = placed.z >= -placement.gauge_height
    inner = np.arange(placed.y.size) <= int(np.argmax(placed.z))
    assert placed.y[within & inner].min() == pytest.approx(0.5 * placement.gauge_width,
                                                           abs=1e-6)
    # CONTACT places the Manchester rail's origin 760.53 mm from the track centre
    assert placed.origin[0] == pytest.approx(0.76053, abs=2e-5)


def test_wheel_placement_puts_the_profile_origin_at_the_nominal_radius(wheel):
    placed = place_wheel(wheel, Placement())
    i = int(np.argmin(np.abs(wheel.dense_y)))
    assert placed.axial[i] == pytest.approx(0.75, abs=2e-5)
    assert placed.radius[i] == pytest.approx(0.46, abs=1e-6)
    assert placed.flange_tip == pytest.approx(0.75 - 0.0549, abs=0.5e-3)


@pytest.mark.parametrize("field, value", [("gauge_width", 0.1), ("nominal_radius", math.nan),
                                          ("cant", 0.5), ("flange_back_position", 2.0)])
def test_placement_out_of_range_is_refused(field, value):
    with pytest.raises(PlacementError, match=field):
        Placement(**{field: value})


def test_profiles_of_the_wrong_kind_are_refused(wheel, rail):
    with pytest.raises(PlacementError, match="not a rail"):
        place_rail(wheel, Placement())
    with pytest.raises(PlacementError, match="not a wheel"):
        place_wheel(rail, Placement())


@pytest.mark.parametrize("name, shipped", [("S1002.prw", "MBench_S1002_v3.prw"),
                                           ("uic60.prr", "MBench_UIC60_v3.prr")])
def test_a_bare_name_of_a_shipped_profile_reads_the_shipped_file(tmp_path, monkeypatch,
                                                                 name, shipped):
    from fastsim_ros.geometry.profiles import PACKAGE_ROOT, resolve_path
    monkeypatch.chdir(tmp_path)
    assert resolve_path(name) == PACKAGE_ROOT / "data" / "profiles" / shipped
    # a file of that name where the user is wins, and a path is never looked up elsewhere
    (tmp_path / name).write_text("0 0\n")
    assert resolve_path(name) == Path(name)
    assert resolve_path("sub/" + name) == Path("sub/" + name)


@pytest.mark.parametrize("smooth, points", [(0.0, 10_001), (2e-3, 4_001)])
def test_more_points_than_a_profile_has_are_one_line(tmp_path, smooth, points):
    """A file under the size limit with 10,000+ points: refused at once, not hours of loops.

    The loop check grows with the square of the count and the smoothing spline
    is dense: 400,000 points (8.5 MB) took 6 GB and never finished, 20,000
    smoothed ones ended in a MemoryError.
    """
    y = np.linspace(-0.07, 0.07, points)
    z = 1e-3 * np.cos(y / 0.07 * math.pi)
    path = tmp_path / "dense.txt"
    path.write_text("".join(f"{a * 1e3:.9f} {b * 1e3:.9f}\n" for a, b in zip(y, z)))
    with pytest.raises(ProfileError, match="at most"):
        read_profile(path, kind="rail", smooth=smooth)
