"""Wheel and rail profiles: read, clean, and put in one canonical form.

The canonical form is CONTACT's (user guide, "Inputs regarding wheel and
rail profiles"): lateral ``y`` positive towards the field side (a right-side
profile), ``z`` positive downwards, here in metres, the points ordered by
increasing ``y``.  A wheel profile's ``z`` is then the radial offset from the
nominal rolling circle (larger ``z``: larger radius, the flange), a rail's
the depth below its highest point.

Formats:

- SIMPACK ``.prw`` (wheel) and ``.prr`` (rail): the file's own processing
  options are applied in SIMPACK's order (minimum point distance, shift,
  rotation, bounds, mirroring, inversion of the order, length unit
  ``units.len.f`` = user units per metre); smoothing options are not
  applied (``smooth`` below is the package's).
- Any other extension: two numbers per line, ``y z``, separated by blanks,
  a comma or a semicolon; ``#``, ``%`` and ``!`` start comments and one
  header line of words is skipped.  The length unit is taken from the size,
  as CONTACT checks it: a profile 5 to 500 units long (summed chord length)
  is in millimetres, 0.005 to 0.5 in metres; anything else is refused.

Orientation (as CONTACT's MIRROR_Z auto-detection): a rail whose ends lie
above its top, or a wheel whose flange points up, has its ``z`` mirrored; a
wheel whose flange lies at positive ``y`` has its ``y`` mirrored (the
flange is on the track-centre side).  A rail's lateral direction cannot be
told from its shape: two-column rail files must give ``y`` towards the
field side.

Cleaning (as CONTACT's curation, except that nothing is repaired): repeated
points are dropped; a profile with NaN, fewer than :data:`MIN_POINTS`
points, a loop (two segments crossing), a zig-zag (two successive turns of
the direction sharper than :data:`ZIGZAG_ANGLE`) or a ``y`` that runs back
(an overhang, which no vertical view can see) is refused with one line
naming the file and the point.

The surface between the points is a monotone piecewise-cubic (PCHIP) curve
in the chord length, which never overshoots the data, sampled densely
(:data:`DENSE_STEP`) for the contact search.  Optional smoothing
(``smooth`` = L_filt > 0, m) is CONTACT's weighted smoothing spline with
second-order penalty, ``lambda = (L_filt / 2 pi)^4``: wavelengths shorter
than ``L_filt`` are damped, longer ones kept (Vollebregt 2022).
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.geometry.errors import ProfileError

FloatArray = NDArray[np.float64]
Kind = Literal["wheel", "rail"]

#: fewer points than this cannot describe a wheel or rail surface
MIN_POINTS = 10
#: at most this many distinct points (measured profiles have hundreds to a few thousand):
#: the loop check and the smoothing's matrices grow with the square of the count, and a
#: 400,000-point file (8.5 MB, under MAX_FILE_BYTES) took 6 GB and never finished
MAX_POINTS = 10_000
#: ... and with smoothing (its spline is solved densely: 4,000 points take some 0.4 GB)
MAX_SMOOTHED_POINTS = 4_000
#: a zig-zag: two successive direction changes sharper than this (rad; CONTACT's ZIGTHRS)
ZIGZAG_ANGLE = 5.0 * math.pi / 6.0
#: summed chord length of a profile, in its own unit: millimetres or metres (CONTACT: 5..500 mm)
MIN_LENGTH_MM, MAX_LENGTH_MM = 5.0, 500.0
#: spacing (m) of the dense samples of the surface used by the contact search
DENSE_STEP = 1e-5
#: the largest file read (bytes): a profile has hundreds of points, not millions
MAX_FILE_BYTES = 16 * 1024 * 1024
#: package-relative profile names: ``package://fastsim_ros/data/profiles/...``
PACKAGE_PREFIX = "package://fastsim_ros/"
PACKAGE_ROOT = Path(__file__).resolve().parents[1]
#: the Manchester benchmark profiles shipped with the package
S1002 = PACKAGE_PREFIX + "data/profiles/MBench_S1002_v3.prw"
UIC60 = PACKAGE_PREFIX + "data/profiles/MBench_UIC60_v3.prr"
#: bare names a user types for the shipped profiles (the Manchester benchmark's are the
#: standard S1002 wheel and UIC60 rail), looked up when no such file exists where named
SHIPPED_NAMES = {"s1002.prw": S1002, "uic60.prr": UIC60,
                 "mbench_s1002_v3.prw": S1002, "mbench_uic60_v3.prr": UIC60}


@dataclass(frozen=True, eq=False)
class Profile:
    """A cleaned profile in canonical form (see the module docstring).

    ``y``, ``z``: the points (m), ``y`` increasing towards the field side,
    ``z`` downwards; ``dense_y``, ``dense_z``, ``dense_slope``: the surface
    sampled every :data:`DENSE_STEP` of chord length, with ``dz/dy`` there;
    ``mirrored_y``, ``mirrored_z``: what the orientation check changed.
    """

    kind: Kind
    source: str
    y: FloatArray
    z: FloatArray
    dense_y: FloatArray = field(repr=False)
    dense_z: FloatArray = field(repr=False)
    dense_slope: FloatArray = field(repr=False)
    mirrored_y: bool = False
    mirrored_z: bool = False
    smooth: float = 0.0

    def z_at(self, y: FloatArray | float) -> FloatArray:
        """Return ``z`` (m, down) of the surface at lateral positions ``y`` (m); NaN outside."""
        return np.asarray(np.interp(y, self.dense_y, self.dense_z, left=math.nan,
                                    right=math.nan), dtype=np.float64)

    def slope_at(self, y: FloatArray | float) -> FloatArray:
        """Return ``dz/dy`` of the surface at ``y`` (m); NaN outside."""
        return np.asarray(np.interp(y, self.dense_y, self.dense_slope, left=math.nan,
                                    right=math.nan), dtype=np.float64)


_VARIABLE = re.compile(r"\$(\w+|\{[^}]*\})")


def expand_path(text: str) -> Path:
    """Return a path with ``~`` and environment variables (``$HOME``, ``${RIG}``) expanded.

    ROS parameters are not expanded by ROS itself, and a rig's parameter file
    names its files as a shell would.  A variable that is not set raises
    :class:`ValueError` naming it (a directory literally named ``$RIG`` is
    never what was meant).
    """
    for match in _VARIABLE.finditer(text):
        name = match.group(1).strip("{}")
        if name not in os.environ:
            raise ValueError(f"{text}: the environment variable {name} is not set")
    return Path(os.path.expandvars(text)).expanduser()


def resolve_path(name: str | Path) -> Path:
    """Return the file a profile name points to (``package://fastsim_ros/...`` or a path).

    A bare name of a shipped profile (:data:`SHIPPED_NAMES`, any case) that is
    not a file in the working directory names the shipped file.
    """
    text = str(name)
    if text.startswith(PACKAGE_PREFIX):
        return PACKAGE_ROOT / text[len(PACKAGE_PREFIX):]
    try:
        path = expand_path(text)
    except ValueError as e:
        raise ProfileError(str(e)) from None
    # a bare file name that is not a file here: one of the shipped profiles by its name
    # (``S1002.prw``, ``UIC60.prr``), so that a first start needs no path into the package
    shipped = SHIPPED_NAMES.get(text.lower()) if path.name == text else None
    if shipped is not None and not path.exists():
        return resolve_path(shipped)
    return path


def read_profile(name: str | Path, *, kind: Kind | None = None,
                 smooth: float = 0.0) -> Profile:
    """Read, clean and orient a profile file; raise :class:`ProfileError` naming the problem.

    ``kind``: ``"wheel"`` or ``"rail"``; taken from the extension for
    ``.prw``/``.prr`` (a different ``kind`` is refused), required otherwise.
    ``smooth``: CONTACT's smoothing wavelength L_filt (m), 0 for none.
    """
    path = resolve_path(name)
    label = str(name)
    suffix = path.suffix.lower()
    file_kind: Kind | None = ("wheel" if suffix == ".prw" else "rail" if suffix == ".prr"
                              else None)
    if kind is None:
        kind = file_kind
    if kind not in ("wheel", "rail"):
        raise ProfileError(f"{label}: say whether it is a wheel or a rail profile "
                           "(.prw/.prr, or kind='wheel'|'rail')")
    if file_kind is not None and file_kind != kind:
        raise ProfileError(f"{label}: a {suffix} file is a {file_kind} profile, not a {kind} one")
    if not (math.isfinite(smooth) and smooth >= 0.0):
        raise ProfileError(f"{label}: smoothing wavelength must be >= 0 m, got {smooth}")
    text = _read_text(path, label)
    if file_kind is not None:
        y, z, index, header_kind = _parse_simpack(text, label)
        if header_kind is not None and header_kind != kind:
            raise ProfileError(f"{label}: its header says it is a {header_kind} profile")
    else:
        y, z, index = _parse_columns(text, label)
        y, z = _to_metres(y, z, label)
    return _canonical(kind, label, y, z, index, smooth)


def profile_from_points(kind: Kind, y: FloatArray, z: FloatArray, *, source: str = "<points>",
                        smooth: float = 0.0) -> Profile:
    """Clean and orient points already in metres (``y``, ``z`` as in canonical form)."""
    y = np.asarray(y, dtype=np.float64).ravel()
    z = np.asarray(z, dtype=np.float64).ravel()
    if y.shape != z.shape:
        raise ProfileError(f"{source}: y and z have different lengths")
    return _canonical(kind, source, y, z, np.arange(1, y.size + 1), smooth)


# --------------------------------------------------------------------------- reading

def _read_text(path: Path, label: str) -> str:
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ProfileError(f"{label}: {size} bytes, more than a profile file can be "
                               f"({MAX_FILE_BYTES})")
        raw = path.read_bytes()
    except ProfileError:
        raise
    except OSError as e:
        raise ProfileError(f"{label}: cannot read it ({e.strerror or e})") from None
    if b"\0" in raw:
        raise ProfileError(f"{label}: not a text file (a NUL byte)")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        # a profile written on a Windows machine: a comment's degree sign or umlaut in
        # Windows-1252 / Latin-1 (the numbers are ASCII either way)
        return raw.decode("latin-1")


_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?"
_KEY_VALUE = re.compile(r"^\s*([A-Za-z][\w.]*)\s*=\s*(.*?)\s*$")


def _number(token: str) -> float:
    return float(token.replace("d", "e").replace("D", "e"))


def _parse_simpack(text: str, label: str) -> tuple[FloatArray, FloatArray, NDArray[np.int64],
                                                   Kind | None]:
    """Points and processing options of a SIMPACK profile; the options applied."""
    options: dict[str, str] = {}
    points: list[tuple[float, float]] = []
    in_points = False
    saw_points = False
    section = ""
    for lineno, line in enumerate(text.splitlines(), start=1):
        body = line.split("!", 1)[0].strip()
        if not body:
            continue
        low = body.lower()
        if low.endswith(".begin") and low != "point.begin":
            section = low[:-len(".begin")]
            continue
        if low.endswith(".end") and low != "point.end":
            section = ""
            continue
        if low == "point.begin":
            in_points, saw_points = True, True
            continue
        if low == "point.end":
            in_points = False
            continue
        if in_points:
            tokens = body.replace(",", " ").split()
            if len(tokens) < 2 or len(tokens) > 3:
                raise ProfileError(f"{label}: line {lineno}: expected 'y z [weight]', got "
                                   f"{body[:40]!r}")
            try:
                yv, zv = _number(tokens[0]), _number(tokens[1])
            except ValueError:
                raise ProfileError(f"{label}: line {lineno}: not a number: {body[:40]!r}") \
                    from None
            points.append((yv, zv))
            continue
        match = _KEY_VALUE.match(body)
        if match:
            key = match.group(1).lower()
            # the header's `type` (0 rail, 1 wheel) is not the spline's data-file type
            options[f"header.{key}" if section == "header" else key] = \
                match.group(2).strip().strip("'\"")
    if not saw_points:
        raise ProfileError(f"{label}: no 'point.begin' ... 'point.end' block (not a SIMPACK "
                           "profile)")
    if not points:
        raise ProfileError(f"{label}: no points")
    header_kind: Kind | None = None
    if "header.type" in options:
        code = options["header.type"].split()[0]
        header_kind = "rail" if code == "0" else "wheel" if code == "1" else None

    def opt(key: str, default: float) -> float:
        if key not in options:
            return default
        try:
            value = _number(options[key].split()[0])
        except (ValueError, IndexError):
            raise ProfileError(f"{label}: option {key} = {options[key]!r} is not a number") \
                from None
        if not math.isfinite(value):
            raise ProfileError(f"{label}: option {key} is not finite")
        return value

    data = np.asarray(points, dtype=np.float64)
    y, z = data[:, 0].copy(), data[:, 1].copy()
    index = np.arange(1, y.size + 1)
    # SIMPACK's processing order (the numbers of its option comments)
    min_dist = opt("point.dist.min", 0.0)
    if min_dist > 0.0:
        keep = [0]
        for i in range(1, y.size):
            if math.hypot(y[i] - y[keep[-1]], z[i] - z[keep[-1]]) >= min_dist:
                keep.append(i)
        y, z, index = y[keep], z[keep], index[keep]
    y = y + opt("shift.y", 0.0)
    z = z + opt("shift.z", 0.0)
    angle_unit = opt("units.ang.f", 1.0)
    if angle_unit <= 0.0:
        raise ProfileError(f"{label}: units.ang.f must be positive")
    angle = opt("rotate", 0.0) / angle_unit
    if angle != 0.0:
        c, s = math.cos(angle), math.sin(angle)
        y, z = c * y - s * z, s * y + c * z
    for axis, values in (("y", y), ("z", z)):
        lo, hi = opt(f"bound.{axis}.min", 1.0), opt(f"bound.{axis}.max", 0.0)
        if lo < hi:  # SIMPACK: min > max disables the bound
            keep_mask = (values >= lo) & (values <= hi)
            y, z, index = y[keep_mask], z[keep_mask], index[keep_mask]
            values = y if axis == "y" else z
    if opt("mirror.y", 0.0) == 1.0:
        y = -y
    if opt("mirror.z", 0.0) == 1.0:
        z = -z
    if opt("inversion", 0.0) == 1.0:
        y, z, index = y[::-1], z[::-1], index[::-1]
    length_unit = opt("units.len.f", 1000.0)
    if length_unit <= 0.0:
        raise ProfileError(f"{label}: units.len.f must be positive")
    return y / length_unit, z / length_unit, index, header_kind


def _parse_columns(text: str, label: str) -> tuple[FloatArray, FloatArray, NDArray[np.int64]]:
    """Two-column ``y z`` text: comments, one header line of words, any separator."""
    rows: list[tuple[float, float]] = []
    header_seen = False
    number = re.compile(rf"^{_NUMBER}$")
    for lineno, line in enumerate(text.splitlines(), start=1):
        body = re.split(r"[#%!]", line, maxsplit=1)[0].strip()
        if not body:
            continue
        tokens = [t for t in re.split(r"[\s,;]+", body) if t]
        if not all(number.match(t) for t in tokens):
            if not rows and not header_seen:
                header_seen = True
                continue
            raise ProfileError(f"{label}: line {lineno}: not two numbers: {body[:40]!r}")
        if len(tokens) != 2:
            raise ProfileError(f"{label}: line {lineno}: expected two numbers 'y z', got "
                               f"{len(tokens)}")
        rows.append((_number(tokens[0]), _number(tokens[1])))
    if not rows:
        raise ProfileError(f"{label}: no points")
    data = np.asarray(rows, dtype=np.float64)
    return data[:, 0].copy(), data[:, 1].copy(), np.arange(1, len(rows) + 1)


def _chord_length(y: FloatArray, z: FloatArray) -> float:
    return float(np.sum(np.hypot(np.diff(y), np.diff(z))))


def _to_metres(y: FloatArray, z: FloatArray, label: str) -> tuple[FloatArray, FloatArray]:
    if not (np.all(np.isfinite(y)) and np.all(np.isfinite(z))) or y.size < MIN_POINTS:
        return y, z  # refused, with the point named, by _canonical
    length = _chord_length(y, z)
    if MIN_LENGTH_MM <= length <= MAX_LENGTH_MM:
        return y * 1e-3, z * 1e-3
    if MIN_LENGTH_MM * 1e-3 <= length <= MAX_LENGTH_MM * 1e-3:
        return y, z
    raise ProfileError(f"{label}: the profile is {length:.4g} units long: neither 5..500 mm "
                       "nor 0.005..0.5 m")


# --------------------------------------------------------------------------- cleaning

def _point(label: str, index: NDArray[np.int64], y: FloatArray, z: FloatArray, i: int) -> str:
    return f"{label}: point {int(index[i])} (y = {y[i] * 1e3:.4f} mm, z = {z[i] * 1e3:.4f} mm)"


def _canonical(kind: Kind, label: str, y: FloatArray, z: FloatArray, index: NDArray[np.int64],
               smooth: float) -> Profile:
    bad = ~(np.isfinite(y) & np.isfinite(z))
    if bad.any():
        i = int(np.argmax(bad))
        raise ProfileError(f"{label}: point {int(index[i])} is not finite")
    # repeated points carry no surface (CONTACT drops them too)
    keep = np.ones(y.size, dtype=bool)
    keep[1:] = (np.diff(y) != 0.0) | (np.diff(z) != 0.0)
    y, z, index = y[keep], z[keep], index[keep]
    if y.size < MIN_POINTS:
        raise ProfileError(f"{label}: {y.size} distinct points, at least {MIN_POINTS} needed")
    most = MAX_SMOOTHED_POINTS if smooth > 0.0 else MAX_POINTS
    if y.size > most:
        raise ProfileError(f"{label}: {y.size} distinct points, at most {most} taken"
                           f"{' with smoothing' if smooth > 0.0 else ''} (resample it: a "
                           "profile has hundreds to a few thousand)")
    length = _chord_length(y, z)
    if not MIN_LENGTH_MM * 1e-3 <= length <= MAX_LENGTH_MM * 1e-3:
        raise ProfileError(f"{label}: the profile is {length * 1e3:.4g} mm long, outside "
                           f"{MIN_LENGTH_MM:g}..{MAX_LENGTH_MM:g} mm (wrong length unit?)")
    _check_zigzag(label, index, y, z)
    _check_loops(label, index, y, z)
    if y[-1] < y[0]:
        y, z, index = y[::-1].copy(), z[::-1].copy(), index[::-1].copy()
    mirrored_y = mirrored_z = False
    z_ends = 0.5 * (z[0] + z[-1])
    if kind == "rail":
        # the ends of a rail head lie below its top: with z down they are the largest z
        if float(z.max()) - z_ends > z_ends - float(z.min()):
            z, mirrored_z = -z, True
    else:
        # the flange tip is the wheel's largest radius: with z down, the largest z
        mid = float(np.median(z))
        if mid - float(z.min()) > float(z.max()) - mid:
            z, mirrored_z = -z, True
        # ... and lies on the track-centre side, at negative y
        if y[int(np.argmax(z))] > 0.5 * (y[0] + y[-1]):
            y, z, index = -y[::-1].copy(), z[::-1].copy(), index[::-1].copy()
            mirrored_y = True
    back = np.diff(y) < 0.0
    if back.any():
        i = int(np.argmax(back)) + 1
        raise ProfileError(f"{_point(label, index, y, z, i)}: the profile runs back in y (an "
                           "overhang no vertical view can see); it must be monotone")
    if smooth > 0.0:
        y, z = _smoothed(y, z, smooth)
        back = np.diff(y) < 0.0
        if back.any():
            i = int(np.argmax(back)) + 1
            raise ProfileError(f"{_point(label, index, y, z, i)}: smoothing made the profile "
                               "run back in y; use a shorter wavelength")
    dense_y, dense_z, slope = _dense(y, z)
    for arr in (y, z, dense_y, dense_z, slope):
        arr.setflags(write=False)
    return Profile(kind, label, y, z, dense_y, dense_z, slope, mirrored_y, mirrored_z,
                   float(smooth))


def _check_zigzag(label: str, index: NDArray[np.int64], y: FloatArray, z: FloatArray) -> None:
    angle = np.arctan2(np.diff(z), np.diff(y))
    turn = np.abs((np.diff(angle) + math.pi) % (2.0 * math.pi) - math.pi)
    sharp = turn > ZIGZAG_ANGLE
    zig = sharp[:-1] & sharp[1:]
    if zig.any():
        i = int(np.argmax(zig)) + 1
        raise ProfileError(f"{_point(label, index, y, z, i)}: a zig-zag (the direction turns "
                           f"back twice by more than {math.degrees(ZIGZAG_ANGLE):.0f} degrees)")


def _check_loops(label: str, index: NDArray[np.int64], y: FloatArray, z: FloatArray) -> None:
    """Refuse two non-adjacent segments that cross (a loop)."""
    p0 = np.stack([y[:-1], z[:-1]], axis=1)
    d = np.diff(np.stack([y, z], axis=1), axis=0)
    n = p0.shape[0]

    def cross(a: FloatArray, b: FloatArray) -> FloatArray:
        return np.asarray(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0])

    for start in range(0, n, 256):
        i = np.arange(start, min(n, start + 256))[:, None]
        j = np.arange(n)[None, :]
        pi, di, pj, dj = p0[i], d[i], p0[j], d[j]
        denom = cross(di, dj)
        rel = pj - pi
        with np.errstate(divide="ignore", invalid="ignore"):
            t = cross(rel, dj) / denom
            u = cross(rel, di) / denom
        hit = (j > i + 1) & (denom != 0.0) & (t > 0.0) & (t < 1.0) & (u > 0.0) & (u < 1.0)
        if hit.any():
            a, b = np.argwhere(hit)[0]
            k = int(i[a, 0])
            m = int(j[0, b])
            raise ProfileError(f"{_point(label, index, y, z, k + 1)}: a loop (the segment "
                               f"after it crosses the one after point {int(index[m])})")


def _pchip_slopes(t: FloatArray, f: FloatArray) -> FloatArray:
    """Fritsch-Carlson slopes: a monotone piecewise cubic never overshoots its data."""
    h = np.diff(t)
    delta = np.diff(f) / h
    m = np.zeros_like(f)
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    same = delta[:-1] * delta[1:] > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        harmonic = (w1 + w2) / (w1 / delta[:-1] + w2 / delta[1:])
    m[1:-1] = np.where(same, harmonic, 0.0)
    # end slopes: the one-sided three-point formula, limited as Fritsch-Carlson do
    for end, (h0, h1, d0, d1) in ((0, (h[0], h[1], delta[0], delta[1])),
                                  (-1, (h[-1], h[-2], delta[-1], delta[-2]))):
        s = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1)
        if s * d0 <= 0.0:
            s = 0.0
        elif d0 * d1 <= 0.0 and abs(s) > 3.0 * abs(d0):
            s = 3.0 * d0
        m[end] = s
    return m


def _hermite(t: FloatArray, f: FloatArray, m: FloatArray,
             tq: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Value and derivative of the cubic Hermite interpolant at ``tq``."""
    k = np.clip(np.searchsorted(t, tq, side="right") - 1, 0, t.size - 2)
    h = t[k + 1] - t[k]
    s = (tq - t[k]) / h
    h00 = (1 + 2 * s) * (1 - s) ** 2
    h10 = s * (1 - s) ** 2
    h01 = s * s * (3 - 2 * s)
    h11 = s * s * (s - 1)
    value = h00 * f[k] + h10 * h * m[k] + h01 * f[k + 1] + h11 * h * m[k + 1]
    d00 = 6 * s * s - 6 * s
    d10 = 3 * s * s - 4 * s + 1
    d01 = -d00
    d11 = 3 * s * s - 2 * s
    deriv = (d00 * f[k] + d01 * f[k + 1]) / h + d10 * m[k] + d11 * m[k + 1]
    return value, deriv


def _dense(y: FloatArray, z: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Sample the monotone cubic through the points every DENSE_STEP of chord length."""
    t = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(y), np.diff(z)))])
    n = max(2, int(math.ceil(t[-1] / DENSE_STEP)) + 1)
    tq = np.linspace(0.0, t[-1], n)
    yq, dy = _hermite(t, y, _pchip_slopes(t, y), tq)
    zq, dz = _hermite(t, z, _pchip_slopes(t, z), tq)
    # a vertical piece (dy = 0) has no slope in y; cap it at 89.99 degrees
    slope = dz / np.maximum(dy, abs(dz) * 1e-4 + 1e-300)
    return yq, zq, slope


def _smoothed(y: FloatArray, z: FloatArray, wavelength: float) -> tuple[FloatArray, FloatArray]:
    """Smooth as CONTACT's weighted smoothing spline (2nd-order penalty) on the chord length."""
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(y), np.diff(z)))])
    n = s.size
    w = np.empty(n)
    w[1:-1] = 0.5 * (s[2:] - s[:-2])
    w[0], w[-1] = s[1] - s[0], s[-1] - s[-2]
    lam = (wavelength / (2.0 * math.pi)) ** 4
    # second differences on the non-uniform parameter: f'' at interior points
    h = np.diff(s)
    d2 = np.zeros((n - 2, n))
    rows = np.arange(n - 2)
    d2[rows, rows] = 2.0 / (h[:-1] * (h[:-1] + h[1:]))
    d2[rows, rows + 1] = -2.0 / (h[:-1] * h[1:])
    d2[rows, rows + 2] = 2.0 / (h[1:] * (h[:-1] + h[1:]))
    a = np.diag(w) + lam * d2.T @ (w[1:-1, None] * d2)
    return (np.asarray(np.linalg.solve(a, w * y), dtype=np.float64),
            np.asarray(np.linalg.solve(a, w * z), dtype=np.float64))
