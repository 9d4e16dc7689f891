"""The flags, limits and checks the commands of ``fastsim_contact`` share.

Defaults are one set, the node's (:func:`node_default` reads
:data:`fastsim_ros.ros.params.PARAMETERS`).  What the command line accepts is
bounded (:data:`LIMITS`, :data:`MAX_CELLS`, :data:`MAX_STRIP_CELLS`,
:data:`MAX_EXACT_FORCE_CELLS`): every real contact lies far inside, and inside
them no intermediate quantity can overflow or underflow, and no grid or
operator outgrows memory.  Values that are valid but implausible for
wheel-rail contact in the stated unit are refused through
:mod:`fastsim_ros.ros.plausibility` unless ``--allow-implausible``.
"""

from __future__ import annotations

import argparse
import math
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

from fastsim_ros.contact.checks import check_material, check_poisson_ratio
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.slope_reduction import SlopeReduction
from fastsim_ros.errors import UsageError
from fastsim_ros.ros import plausibility
from fastsim_ros.ros.params import SPECS


def node_default(parameter: str) -> Any:
    """Return the node's default of ``parameter``: every tool's default (one set, the node's).

    The command line's material, friction, method, bound and grid defaults
    are the node's parameters' (:data:`fastsim_ros.ros.params.PARAMETERS`), read
    from there, so that the same question gets the same numbers from every tool.
    """
    return SPECS[parameter].default


#: cells across the bounding box of a shape, per method: exact coefficients are
#: extrapolated from grids up to this; FastSim's discretisation error at 60
#: cells is 0.1% on ellipses (docs/validation.md).  The calibrated MAE's
#: flexibilities make FastSim give its zones' coefficients on any grid (Kalker's
#: on an ellipse, to rounding): the grid enters through the zones' geometry
#: only, as for ``mae``, hence the same 100 cells.
DEFAULT_CELLS = {"exact": 100, "mae": 100, "mae_calibrated": 100, "fastsim": 60,
                 "dlm": 100, "asm": 100,
                 "exact_forces": 60, "mae_forces": 60, "mae_calibrated_forces": 60,
                 "fastsim_ellipse_forces": 60, "fastrip_forces": 60, "dlm_forces": 60,
                 "asm_forces": 60, "polach_forces": 60}
#: the coarsest grid of an extrapolation of the exact forces (cells across): a shape on
#: fewer than twice this is solved on its grid alone
EXACT_COARSEST = 8
#: the methods of ``coefficients`` (default ``exact``: the coefficients are the exact
#: theory's numbers) and of ``forces`` (default the node's ``method``)
COEFFICIENT_METHODS = ("exact", "mae", "mae_calibrated", "fastsim", "dlm", "asm")
FORCE_METHODS = ("mae_calibrated", "mae", "fastsim_ellipse", "exact", "fastrip", "dlm", "asm",
                 "polach")
#: the most cells along each axis of a shape's grid (``--cells``)
MAX_CELLS = 400
#: the most cells along ``x`` for the exact solver (each strip's own operator
#: block is dense: strips x cells^2 doubles)
MAX_STRIP_CELLS = MAX_CELLS
#: the most cells in contact for ``forces --method exact`` (its FFT Coulomb solver:
#: memory proportional to the cells, under 300 MB at 15,000)
MAX_EXACT_FORCE_CELLS = 20_000
#: accepted ranges (SI): (smallest, largest) magnitude
LIMITS = {
    "length": (1e-9, 1e3),        # m: --a, --b, a patch's cell sizes
    "coordinate": (0.0, 1e6),     # m: |x|, |y| of a patch's cells
    "pressure": (1e-3, 1e13),     # Pa: a loaded patch's largest pressure (forces)
    "shear_modulus": (1.0, 1e15),  # Pa
    "mu": (0.0, 100.0),           # exclusive of 0
    "creepage": (0.0, 100.0),     # |xi|, |eta|
    "spin": (0.0, 1e6),           # |phi|, 1/m
    "a_over_b": (1e-3, 1e3),      # --a-over-b
}


# argparse reads a token that starts with "-" as a flag unless it looks like a
# negative number, and its test knows neither exponents nor inf/nan: "-1e-4"
# would be "expected one argument".  This one knows every float Python reads.
_NEGATIVE_NUMBER = re.compile(
    r"^-(\d[\d_]*\.?[\d_]*|\.\d[\d_]*)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


class Parser(argparse.ArgumentParser):
    """No prefix abbreviations (``--a`` is not ``--a-over-b``); errors raise UsageError."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


def finite(text: str) -> float:
    """Return the finite number ``text`` (an argparse type: a bad one is a usage error)."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return v


def cell_count(text: str) -> int:
    """Return ``--cells``: a whole number in [4, :data:`MAX_CELLS`]."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if n < 4 or n > MAX_CELLS:
        raise argparse.ArgumentTypeError(f"--cells must lie in [4, {MAX_CELLS}], got {n}")
    return n


def add_area(p: argparse.ArgumentParser, *, forces: bool) -> None:
    """Add the area flags (``--shape``, ``--a-over-b``, ``--patch``, ``--cells``, ``--json``).

    ``forces``: also ``--a`` and ``--b``, the semi-axes of a loaded ellipse.
    """
    g = p.add_argument_group("area (one of --shape or --patch)")
    g.add_argument("--shape", choices=("ellipse", "semi-ellipses"))
    g.add_argument("--a-over-b", type=finite, nargs="+", metavar="G",
                   help="a/b of the ellipse, or G1 G2 of the two semi-ellipses")
    if forces:
        g.add_argument("--a", type=finite, help="semi-axis along x (m)")
        g.add_argument("--b", type=finite, help="semi-axis along y (m)")
    g.add_argument("--patch", type=Path, help="CSV with header x,y,pressure (m, m, Pa)")
    if forces:
        cells = (f"default {DEFAULT_CELLS['mae_calibrated_forces']} for every method (exact on "
                 "a shape: extrapolated from N/2 and N cells)")
    else:
        by_count: dict[int, list[str]] = {}
        for method in COEFFICIENT_METHODS:
            by_count.setdefault(DEFAULT_CELLS[method], []).append(method)
        cells = "default " + ", ".join(f"{n} ({', '.join(ms)})" for n, ms in by_count.items())
        cells += "; exact on a shape: the finest grid of its extrapolation"
    p.add_argument("--cells", type=cell_count,
                   help="cells along each axis of a shape's bounding box (a patch keeps its "
                   f"grid); {cells}")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def add_material(p: Any, finite: Callable[[str], float]) -> None:
    """Add ``--shear-modulus`` and ``--nu`` with the node's defaults, shown in the help."""
    p.add_argument("--shear-modulus", type=finite, default=node_default("shear_modulus"),
                   help="combined shear modulus G (Pa; default %(default)g, the node's)")
    add_poisson_ratio(p, finite)


def add_poisson_ratio(p: Any, finite: Callable[[str], float]) -> None:
    """Add ``--nu`` with the node's default (steel), shown in the help."""
    p.add_argument("--nu", type=finite, default=node_default("poisson_ratio"),
                   help="Poisson ratio (default %(default)g, steel, the node's; Kalker's "
                   "published tables are at 0.25: ask for it)")


def add_slope_reduction(p: Any, finite: Callable[[str], float]) -> None:
    """Add ``--slope-k0``, ``--slope-alpha-inf``, ``--slope-beta`` (the node's defaults)."""
    p.add_argument("--slope-k0", type=finite, metavar="K0",
                   default=node_default("slope_reduction_k0"),
                   help="creep-slope reduction of a contaminated rail (modified FastSim, "
                   "Spiryagin et al.; docs/guide_real_rails.md): k0 in (0, 1], the slope's "
                   "share at vanishing creepage; default %(default)s (with alpha_inf 1: the "
                   "theory's full slope)")
    p.add_argument("--slope-alpha-inf", type=finite, metavar="ALPHA",
                   default=node_default("slope_reduction_alpha_inf"),
                   help="alpha_inf in [0, 1]: k(inf)/k0 of the reduction; default %(default)s")
    p.add_argument("--slope-beta", type=finite, metavar="BETA",
                   default=node_default("slope_reduction_beta"),
                   help="beta >= 0: how fast k falls with the slip area; default %(default)s")


def slope_reduction(args: argparse.Namespace) -> SlopeReduction | None:
    """Return the reduction of ``--slope-*`` (None: ``k = 1``), each flag checked."""
    for flag, spec in (("--slope-k0", "slope_reduction_k0"),
                       ("--slope-alpha-inf", "slope_reduction_alpha_inf"),
                       ("--slope-beta", "slope_reduction_beta")):
        value = getattr(args, flag[2:].replace("-", "_"))
        lo, hi = SPECS[spec].low, SPECS[spec].high
        if not lo <= value <= hi:  # type: ignore[operator]
            raise InvalidInputError(f"{flag} must lie in [{lo:g}, {hi:g}], got {value:g}")
    reduction = SlopeReduction(args.slope_k0, args.slope_alpha_inf, args.slope_beta)
    return None if reduction.identity else reduction


def add_allow_implausible(p: Any, quantities: Sequence[str] | None = None) -> None:
    """Add ``--allow-implausible``: accept values outside :data:`plausibility.PLAUSIBILITY`.

    ``quantities``: the table's names the command checks (its help lists their
    ranges); None: all.
    """
    ranges = "; ".join(f"{q.quantity} {q.expected()}" for q in plausibility.PLAUSIBILITY
                       if quantities is None or q.name in quantities)
    p.add_argument(plausibility.OVERRIDE_FLAG, action="store_true",
                   help="accept a value outside the plausible range of wheel-rail contact "
                   "(a scaled rig, a full-slip test); without it such a value is refused "
                   f"as a likely unit mistake. Plausible: {ranges}")


def in_range(name: str, value: float, key: str, unit: str = "", *,
             magnitude: bool = False, open_low: bool = False) -> None:
    """Refuse ``value`` (or its magnitude) outside ``LIMITS[key]``, naming ``name``."""
    lo, hi = LIMITS[key]
    if magnitude:
        if not abs(value) <= hi:
            raise InvalidInputError(f"|{name}| must be at most {hi:g}{unit}, got {value:g}")
        return
    if not ((value > lo if open_low else value >= lo) and value <= hi):
        left = "(" if open_low else "["
        raise InvalidInputError(f"{name} must lie in {left}{lo:g}, {hi:g}]{unit}, got {value:g}")


def check_material_flags(nu: float, shear_modulus: float | None = None) -> None:
    """Run the library's material checks, then the command line's range of ``G``."""
    if shear_modulus is None:
        check_poisson_ratio(nu)
        return
    check_material(nu, shear_modulus)
    in_range("--shear-modulus", shear_modulus, "shear_modulus", " Pa")


def check_plausible_material(args: argparse.Namespace) -> None:
    """Refuse ``--mu`` or ``--shear-modulus`` implausible for wheel-rail contact."""
    allow = args.allow_implausible
    plausibility.check("friction_coefficient", args.mu, what="--mu", allow=allow)
    plausibility.check("shear_modulus", args.shear_modulus, what="--shear-modulus", allow=allow)


def check_plausible_creepages(xi: float, eta: float, phi: float, *, allow: bool,
                              where: str = "") -> None:
    """Refuse creepages implausible for wheel-rail contact; ``where`` prefixes their names."""
    for name, quantity, value in (("xi", "creepage", xi), ("eta", "creepage", eta),
                                  ("phi", "spin", phi)):
        plausibility.check(quantity, value, what=f"{where}{name}", allow=allow)


def check_finite_result(result: dict[str, Any], keys: Sequence[str]) -> None:
    """Refuse to print a result with a non-finite number (a last guard: the limits prevent it)."""
    for key in keys:
        v = result.get(key)
        if isinstance(v, float) and not math.isfinite(v):
            raise InvalidInputError(f"the solve gave a non-finite {key}: the inputs are beyond "
                                    "what the solver can represent")


def check_speed(v: float) -> None:
    """Refuse a rolling speed ``--speed`` beyond 1e4 m/s in magnitude."""
    if not abs(v) <= 1e4:
        raise InvalidInputError(f"--speed must be at most 1e4 m/s in magnitude, got {v:g}")
