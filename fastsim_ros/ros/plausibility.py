"""Plausible values of wheel-rail contact: one table, shared by the command line, node and replay.

A value in the wrong unit is often still a valid number: semi-axes in
millimetres typed as metres (``--a 6``), a load in kilonewtons typed as
newtons (``--load 10``), a creepage or a friction coefficient as a
percentage (``--xi 0.2`` meant as 0.2 %, ``--mu 30``).  Each solver answers
those with believable numbers.  :data:`PLAUSIBILITY` holds, for each
quantity, the range a wheel-rail contact has in the SI unit the interface
states, and the mistake a value outside it most likely is;
:func:`check` refuses a value outside its range in one line that names the
value, the expected unit, the likely mistake and how to accept the value
when it is meant (a scaled rig, a full-slip test).

These are plausibility bounds, not validity bounds: inside the hard limits
of each tool (``fastsim_ros.cli.LIMITS``, the node's parameter ranges) a
solver answers any value, and ``allow=True`` (the command line's
``--allow-implausible``) accepts it.  The friction coefficient's range is
the node's parameter range (:data:`fastsim_ros.ros.params.PARAMETERS`), read
from there so that there is one source.

Pure Python (no ROS, no numpy): callers compute a patch's extent and peak
pressure and pass the numbers.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.ros.params import SPECS

#: how the command line accepts an implausible value; the node and the replay pass theirs
OVERRIDE_FLAG = "--allow-implausible"
#: how the node and the replay accept one (their parameter)
OVERRIDE_PARAMETER = "parameter allow_implausible: true"


class ImplausibleValueError(InvalidInputError):
    """A value that is valid but implausible for wheel-rail contact in its stated unit."""


@dataclass(frozen=True)
class Plausible:
    """The plausible range of one quantity of wheel-rail contact, in its SI unit.

    ``low``/``high``: inclusive bounds; with ``magnitude`` they bound
    ``|value|`` and a ``low`` of 0 bounds nothing.  ``below``/``above``: the
    mistake a value under ``low`` or over ``high`` most likely is, in words.
    ``why``: where the bounds come from.
    """

    name: str
    quantity: str
    unit: str
    low: float
    high: float
    below: str
    above: str
    why: str
    magnitude: bool = False

    def contains(self, value: float) -> bool:
        """Return whether ``value`` (its magnitude, with ``magnitude``) lies in the range."""
        v = abs(value) if self.magnitude else value
        return self.low <= v <= self.high

    def expected(self) -> str:
        """Return the range in words, with its unit (``0.0001 to 0.05 m``, ``|.| <= 0.1``)."""
        unit = f" {self.unit}" if self.unit else ""
        if self.magnitude and self.low == 0.0:
            return f"magnitude at most {self.high:g}{unit}"
        return f"{self.low:g} to {self.high:g}{unit}"


def _node_range(parameter: str) -> tuple[float, float]:
    """Return a node parameter's range (:data:`fastsim_ros.ros.params.PARAMETERS`)."""
    spec = SPECS[parameter]
    if spec.low is None or spec.high is None:
        raise LookupError(f"parameter {parameter!r} has no numeric range")
    return float(spec.low), float(spec.high)


_FRICTION = _node_range("friction_coefficient")

#: the plausible ranges (SI units), one entry per quantity
PLAUSIBILITY: tuple[Plausible, ...] = (
    Plausible(
        "semi_axis", "contact semi-axis", "m", 1.0e-4, 5.0e-2,
        below="metres converted again as if they were millimetres",
        above="millimetres typed as metres",
        why="Hertzian semi-axes of wheel-rail contact are 2-10 mm on full-size wheels and "
        "about 0.3 mm on a 1:10 scaled rig at 100 N; 50 mm exceeds a conformal worn "
        "tread's patch"),
    Plausible(
        "patch_extent", "patch extent (the cells in contact, along x or y)", "m",
        2.0e-4, 0.1,
        below="metres converted again as if they were millimetres",
        above="coordinates in millimetres where metres belong",
        why="twice the semi-axis bounds: the patch's cells in contact span the area's "
        "diameter"),
    Plausible(
        "peak_pressure", "largest contact pressure", "Pa", 1.0e5, 1.0e10,
        below="megapascals typed as pascals (1000 MPa is 1e9 Pa)",
        above="pascals converted twice, or a load far too large for the patch",
        why="Hertzian peak pressures of wheel-rail contact are 0.3-2 GPa, above 0.1 GPa "
        "even at 100 N on a scaled rig, and plastic flow caps real ones near 4 GPa; "
        "1e5 Pa leaves three decades below, 1e10 Pa a factor 2.5 above"),
    Plausible(
        "wheel_load", "normal load per wheel", "N", 100.0, 1.0e6,
        below="kilonewtons typed as newtons",
        above="a vehicle's or axle's load given for one wheel, or newtons typed for "
        "kilonewtons twice",
        why="scaled roller rigs carry a few hundred newtons per wheel; heavy haul (40 t "
        "axles) about 200 kN static and some 600 kN under a wheel flat's impact"),
    Plausible(
        "creepage", "longitudinal or lateral creepage (xi, eta)", "", 0.0, 0.1,
        below="",
        above="a percentage typed where the fraction belongs (0.2 % is 0.002)",
        why="creep forces saturate near |xi| = 2 pi mu p0 / (G C11), about 0.006 at mu 0.3 "
        "and p0 1 GPa; running and curving stay below a few hundredths; 0.1 is ten times "
        "saturation (a full-slip test is accepted when marked intended)",
        magnitude=True),
    Plausible(
        "spin", "spin creepage (phi)", "1/m", 0.0, 50.0,
        below="",
        above="a spin rate (rad/s) not divided by the rolling speed",
        why="spin is about sin(contact angle) / wheel radius: at most 3 1/m on full-size "
        "wheels (flange contact, 70 degrees, R 0.3 m), about 10 1/m on a 1:5 and 20 1/m "
        "on a 1:10 scaled rig; 50 1/m is a wheel of 19 mm radius",
        magnitude=True),
    Plausible(
        "friction_coefficient", "friction coefficient", "", *_FRICTION,
        below="a fraction divided by 100 as if it were a percentage",
        above="a percentage typed where the fraction belongs (30 % is 0.3)",
        why="the node's parameter range friction_coefficient (fastsim_ros.ros.params); "
        "wheel-rail friction is 0.05-0.6"),
    Plausible(
        "shear_modulus", "combined shear modulus", "Pa", 1.0e9, 5.0e11,
        below="gigapascals or megapascals typed as pascals (80 GPa is 8e10 Pa)",
        above="a modulus converted to pascals twice",
        why="steel is 8e10 Pa; 1e9 Pa admits polymer rollers of scaled rigs, 5e11 Pa "
        "tungsten carbide"),
)

#: the table by quantity name
PLAUSIBLE: Mapping[str, Plausible] = MappingProxyType({p.name: p for p in PLAUSIBILITY})


def message(name: str, value: float, *, what: str | None = None,
            override: str = OVERRIDE_FLAG, mistake: str | None = None) -> str:
    """Return the one-line refusal of ``value`` of quantity ``name`` (no check made).

    ``what`` names the value as the user gave it (a flag, a file and line, a
    parameter); ``override`` says how to accept the value when it is meant;
    ``mistake`` replaces the table's likely mistake where the caller knows
    better (a pressure that follows from a load and semi-axes).
    """
    p = PLAUSIBLE[name]
    unit = f" {p.unit}" if p.unit else ""
    v = abs(value) if p.magnitude else value
    if mistake is None:
        mistake = p.below if v < p.low else p.above
    return (f"{what or p.quantity} {value:g}{unit} is implausible for wheel-rail contact: "
            f"{p.quantity} expected {p.expected()}; likely {mistake}; "
            f"if intended, give {override}")


def check(name: str, value: float, *, allow: bool = False, what: str | None = None,
          override: str = OVERRIDE_FLAG, mistake: str | None = None) -> None:
    """Refuse ``value`` of quantity ``name`` outside its plausible range (unless ``allow``).

    Raise :class:`ImplausibleValueError` with :func:`message`'s one line.
    ``name`` is a key of :data:`PLAUSIBLE`; units are the table's (SI).
    """
    if allow or PLAUSIBLE[name].contains(value):
        return
    raise ImplausibleValueError(message(name, value, what=what, override=override,
                                        mistake=mistake))


def check_patch(extent_x: float, extent_y: float, peak_pressure: float | None, *,
                allow: bool = False, what: str = "patch",
                override: str = OVERRIDE_FLAG) -> None:
    """Refuse a patch whose extent (m) or largest pressure (Pa) suggests another unit.

    ``extent_x``, ``extent_y``: the span of the cells in contact, cell size
    included (m); ``peak_pressure``: the largest pressure (Pa), or None when
    it does not matter (a load rescales the pressures).
    """
    if allow:
        return
    for axis, extent in (("x", extent_x), ("y", extent_y)):
        check("patch_extent", extent, what=f"{what}: extent along {axis}", override=override)
    if peak_pressure is not None:
        check("peak_pressure", peak_pressure, what=f"{what}: largest pressure",
              override=override)


#: :func:`stream_problem`'s bounds, read once
_EXTENT_HIGH = PLAUSIBLE["patch_extent"].high
_PRESSURE_LOW = PLAUSIBLE["peak_pressure"].low
_CREEPAGE, _SPIN = PLAUSIBLE["creepage"], PLAUSIBLE["spin"]


def stream_problem(extent_x: float, extent_y: float, pressure: float, xi: float, eta: float,
                   phi: float, *, override: str = OVERRIDE_PARAMETER) -> str | None:
    """Return why a solved patch of a stream is implausible (one line), or None.

    The unit mistakes a patch topic or a recording can carry: coordinates in
    millimetres (an extent, m, over the table's), pressures in megapascals
    (``pressure``: the largest, Pa, under the table's; a value at or above
    the bound, such as the mean pressure, clears it), and creepages or spin
    beyond the table's.  The lower extent bound and the load are not
    applied: a patch that starts or ends (a flange just touching, a wheel
    lifting) is small and light, and right.  The node and the replay
    reject such a patch as ``implausible`` (no wrench published).
    """
    # each test once, its message built only where it fails (a sound stream at kHz rates
    # passes them all)
    high = _EXTENT_HIGH
    if extent_x > high:
        return message("patch_extent", extent_x, what="patch extent along x",
                       override=override)
    if extent_y > high:
        return message("patch_extent", extent_y, what="patch extent along y",
                       override=override)
    if pressure < _PRESSURE_LOW:
        return message("peak_pressure", pressure, what="largest pressure", override=override)
    if not _CREEPAGE.contains(xi):
        return message("creepage", xi, what="xi", override=override)
    if not _CREEPAGE.contains(eta):
        return message("creepage", eta, what="eta", override=override)
    if not _SPIN.contains(phi):
        return message("spin", phi, what="phi", override=override)
    return None


__all__ = ["ImplausibleValueError", "OVERRIDE_FLAG", "OVERRIDE_PARAMETER", "PLAUSIBILITY",
           "PLAUSIBLE", "Plausible", "check", "check_patch", "message", "stream_problem"]
