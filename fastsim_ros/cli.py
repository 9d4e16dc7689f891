"""``fastsim_contact``: one-off contact computations from the command line.

Three commands: ``coefficients`` prints an area's generalised
creepage coefficients, ``forces`` the creep forces at given creepages,
``wheelset`` a wheelset's patches and creep forces from wheel and rail profiles
(:mod:`fastsim_ros.cli_wheelset`), and ``estimate`` fits the friction law to
measured creep forces (:mod:`fastsim_ros.cli_estimate`).  SI
units throughout.  ``--json`` prints exactly one JSON object on stdout.  Bad
input gives one line on stderr and exit status 2, never a traceback, and no
non-finite number is ever printed as a result.

``forces --method mae_calibrated`` (the default: the calibrated MAE, better than
the paper's MAE on every area of docs/validation_wider.md), ``mae`` (the paper's)
and ``fastsim_ellipse`` run the compiled solvers of
:mod:`fastsim_ros.contact.compiled`, the code the node runs; ``exact`` runs
the exact theory (:mod:`fastsim_ros.contact.exact`); ``fastrip`` the numpy
FaStrip baseline (:mod:`fastsim_ros.contact.fastrip`, no compiled path);
``dlm`` and ``asm`` the seed paper's older ways to FastSim's flexibilities
(:mod:`~fastsim_ros.contact.dlm`, :mod:`~fastsim_ros.contact.asm`, numpy).

Defaults are one set, the node's (:func:`node_default` reads
:data:`fastsim_ros.params.PARAMETERS`): method (``coefficients``: ``exact``,
the exact theory's numbers), Poisson ratio, shear modulus, friction law,
bound; each ``--help`` shows them.  Values that are valid but implausible
for wheel-rail contact in the stated unit (semi-axes, patch extent and
pressure, load, creepages, friction, shear modulus:
:data:`fastsim_ros.plausibility.PLAUSIBILITY`) are refused before any solve,
in one line naming the likely unit mistake, unless ``--allow-implausible``.

What the command line accepts is bounded (:data:`LIMITS`, :data:`MAX_PATCH_CELLS`,
:data:`MAX_STRIP_CELLS`, :data:`MAX_EXACT_FORCE_CELLS`): every real contact lies
far inside, and inside them no intermediate quantity can overflow or underflow,
and no grid or operator outgrows memory; each bound is checked before the
arrays it limits are allocated.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import re
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from fastsim_ros import plausibility
from fastsim_ros.contact import area as areas
from fastsim_ros.contact import wear
from fastsim_ros.contact.checks import (BOUNDS, check_friction, check_material,
                                        check_poisson_ratio)
from fastsim_ros.contact.errors import ContactError, InvalidInputError
from fastsim_ros.errors import UsageError
from fastsim_ros.contact.friction import ConstantFriction, ExponentialFriction, FrictionLaw
from fastsim_ros.contact.slope_reduction import SlopeReduction
from fastsim_ros.params import SPECS


def node_default(parameter: str) -> Any:
    """Return the node's default of ``parameter``: every tool's default (one set, the node's).

    The command line's material, friction, method, bound and grid defaults
    are the node's parameters' (:data:`fastsim_ros.params.PARAMETERS`), read
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
#: the most cells the grid of a patch file may span (its cells' bounding box at
#: their spacing): 400 x 400, the largest ``--cells`` grid
MAX_PATCH_CELLS = MAX_CELLS * MAX_CELLS
#: the most cells along ``x`` for the exact solver (each strip's own operator
#: block is dense: strips x cells^2 doubles)
MAX_STRIP_CELLS = MAX_CELLS
#: the most cells in contact for ``forces --method exact`` (its FFT Coulomb solver:
#: memory proportional to the cells, under 300 MB at 15,000)
MAX_EXACT_FORCE_CELLS = 20_000
#: the largest patch file read (bytes): far more than MAX_PATCH_CELLS rows need
MAX_PATCH_BYTES = 64 * 2**20
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


class _Parser(argparse.ArgumentParser):
    """No prefix abbreviations (``--a`` is not ``--a-over-b``); errors raise UsageError."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


def _finite(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return v


def _cells(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if n < 4 or n > MAX_CELLS:
        raise argparse.ArgumentTypeError(f"--cells must lie in [4, {MAX_CELLS}], got {n}")
    return n


def _add_area(p: argparse.ArgumentParser, *, forces: bool) -> None:
    g = p.add_argument_group("area (one of --shape or --patch)")
    g.add_argument("--shape", choices=("ellipse", "semi-ellipses"))
    g.add_argument("--a-over-b", type=_finite, nargs="+", metavar="G",
                   help="a/b of the ellipse, or G1 G2 of the two semi-ellipses")
    if forces:
        g.add_argument("--a", type=_finite, help="semi-axis along x (m)")
        g.add_argument("--b", type=_finite, help="semi-axis along y (m)")
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
    p.add_argument("--cells", type=_cells,
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


def build_parser() -> argparse.ArgumentParser:
    """Return the parser of the two commands and their fixed flags."""
    parser = _Parser(prog="fastsim_contact",
                     description="Creepage coefficients and creep forces of a contact area.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    co = sub.add_parser("coefficients", help="generalised creepage coefficients C~ij")
    _add_area(co, forces=False)
    co.add_argument("--method", choices=COEFFICIENT_METHODS, default="exact",
                    help="exact solver (default: the coefficients are the exact theory's "
                    "numbers), MAE's coefficients, the calibrated MAE's "
                    "(its FastSim in full adhesion), MAE + FastSim in full adhesion, or the "
                    "seed's DLM or ASM (FastSim with their flexibilities, full adhesion)")
    add_poisson_ratio(co, _finite)
    fo = sub.add_parser("forces", help="creep forces at given creepages")
    _add_area(fo, forces=True)
    fo.add_argument("--xi", type=_finite, required=True, help="longitudinal creepage")
    fo.add_argument("--eta", type=_finite, required=True, help="lateral creepage")
    fo.add_argument("--phi", type=_finite, required=True, help="spin creepage (1/m)")
    fo.add_argument("--mu", type=_finite, required=True,
                    help="friction coefficient (the static mu_s of a slip-dependent law)")
    fo.add_argument("--friction-law", choices=("constant", "exponential"),
                    default=node_default("friction_law"),
                    help="constant (Coulomb) or exponential: mu(v) = mu_s ((1 - A) exp(-B v) "
                    "+ A), v the local slip velocity (m/s); default %(default)s, the node's")
    fo.add_argument("--friction-limit-ratio", type=_finite, metavar="A",
                    help="A in (0, 1] of the exponential law")
    fo.add_argument("--friction-decay", type=_finite, metavar="B",
                    help="B >= 0 (s/m) of the exponential law")
    fo.add_argument("--speed", type=_finite, metavar="V",
                    help="rolling speed V (m/s; its magnitude is used)")
    add_slope_reduction(fo, _finite)
    fo.add_argument("--load", type=_finite, help="normal load N (N)")
    add_material(fo, _finite)
    fo.add_argument("--method", choices=FORCE_METHODS, default=node_default("method"),
                    help="mae_calibrated (the calibrated MAE), mae (the paper's MAE), "
                    "fastsim_ellipse, exact, fastrip, dlm, asm or polach (Polach's closed "
                    "form on the equivalent ellipse); default %(default)s, the node's")
    fo.add_argument("--polach-ka", type=_finite, metavar="KA",
                    default=node_default("polach_ka"),
                    help="Polach's kA in (0, 1] (method polach); default %(default)s")
    fo.add_argument("--polach-ks", type=_finite, metavar="KS",
                    default=node_default("polach_ks"),
                    help="Polach's kS in (0, kA] (method polach); default %(default)s")
    fo.add_argument("--bound", choices=BOUNDS, default=node_default("traction_bound"),
                    help="traction bound: mu p as given, or parabolic, mu N p^2/sum(p^2 dA) "
                    "(Kalker's on a Hertzian patch); default %(default)s, the node's")
    add_allow_implausible(fo)
    from fastsim_ros import cli_wheelset  # the wheelset command lives in its own module
    cli_wheelset.add_parser(sub, _finite)
    from fastsim_ros import cli_estimate  # the friction fit lives in its own module too
    cli_estimate.add_parser(sub, _finite)
    return parser


# ---------------------------------------------------------------- patch files


def _patch_lines(path: Path, what: str = "patch file") -> list[str]:
    """Return the lines of a text file: at most MAX_PATCH_BYTES, UTF-8 (a BOM is dropped).

    ``what`` names the file in the errors (``patch file``, ``measured file``).
    """
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_PATCH_BYTES + 1)
    except OSError as e:
        raise InvalidInputError(f"cannot read {what} {path}: {e.strerror}") from None
    if len(raw) > MAX_PATCH_BYTES:
        raise InvalidInputError(f"{path}: larger than {MAX_PATCH_BYTES // 2**20} MiB, more "
                                f"than a {what} may be")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise InvalidInputError(f"{path}: not UTF-8 text (byte 0x{raw[e.start]:02x} at "
                                f"offset {e.start})") from None
    if "\x00" in text:
        raise InvalidInputError(f"{path}: a NUL byte: not a text file")
    return text.splitlines()


def _rows(path: Path, lines: list[str]) -> Iterator[tuple[int, list[str]]]:
    """Yield ``(line number, fields)`` of the non-blank, non-comment lines."""
    # comment lines become blank ones, so that the reader's line numbers stay the file's
    reader = csv.reader("" if ln.lstrip().startswith("#") else ln for ln in lines)
    try:
        for fields in reader:
            if any(c.strip() for c in fields):
                yield reader.line_num, fields
    except csv.Error as e:
        raise InvalidInputError(f"{path}, line {reader.line_num}: {e}") from None


def _value(path: Path, line: int, name: str, text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        shown = text.strip()[:30] or "an empty field"
        raise InvalidInputError(f"{path}, line {line}: {name} is not a number: "
                                f"{shown!r}") from None
    if not math.isfinite(v):
        raise InvalidInputError(f"{path}, line {line}: NaN or infinite {name} {text.strip()!r}")
    return v


def read_patch(path: Path, *, max_cells: int = MAX_PATCH_CELLS) -> areas.GridArea:
    """Read a patch CSV (header ``x,y,pressure``; m, m, Pa) into a grid area.

    Refused (:class:`InvalidInputError`, one line naming the file, the line
    and the problem): a file that cannot be read, is larger than
    :data:`MAX_PATCH_BYTES` or is not UTF-8 text (a UTF-8 BOM is fine), a
    wrong header, a row without exactly three values, a value that is not a
    finite number, a negative pressure, a coordinate beyond
    ``LIMITS["coordinate"]``, cells off one regular grid, and cells whose grid
    would span more than ``max_cells`` cells (checked before it is allocated).
    """
    rows = _rows(path, _patch_lines(path))
    first = next(rows, None)
    if first is None:
        raise InvalidInputError(f"{path}: empty (no header x,y,pressure)")
    if [c.strip() for c in first[1]] != ["x", "y", "pressure"]:
        shown = ",".join(first[1])[:40]
        raise InvalidInputError(f"{path}, line {first[0]}: the header must be x,y,pressure, "
                                f"not {shown!r}")
    values: list[tuple[float, float, float]] = []
    coordinate_max = LIMITS["coordinate"][1]
    for line, fields in rows:
        if len(fields) != 3:
            kind = "a short row" if len(fields) < 3 else "a long row"
            raise InvalidInputError(f"{path}, line {line}: {kind}: {len(fields)} values where "
                                    "x,y,pressure needs 3")
        x, y, p = (_value(path, line, name, text)
                   for name, text in zip(("x", "y", "pressure"), fields))
        if p < 0.0:
            raise InvalidInputError(f"{path}, line {line}: negative pressure {p:g} Pa")
        if max(abs(x), abs(y)) > coordinate_max:
            raise InvalidInputError(f"{path}, line {line}: coordinate ({x:g}, {y:g}) m beyond "
                                    f"the {coordinate_max:g} m the command line accepts")
        values.append((x, y, p))
        if len(values) > max_cells:
            raise InvalidInputError(f"{path}: more than {max_cells:,} cells")
    if not values:
        raise InvalidInputError(f"{path}: no cells")
    data = np.array(values)
    try:
        patch = areas.from_cells(data[:, 0], data[:, 1], data[:, 2], max_cells=max_cells)
    except ContactError as e:
        raise type(e)(f"{path}: {e}") from None
    lo, hi = LIMITS["length"]
    if not (lo <= patch.dx <= hi and lo <= patch.dy <= hi):
        raise InvalidInputError(f"{path}: cells of {patch.dx:.4g} m x {patch.dy:.4g} m: cell "
                                f"sizes must lie in [{lo:g}, {hi:g}] m")
    return patch


# ---------------------------------------------------------------- checks


def _in_range(name: str, value: float, key: str, unit: str = "", *,
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


def _check_material(nu: float, shear_modulus: float | None = None) -> None:
    """Run the library's material checks, then the command line's range of ``G``."""
    if shear_modulus is None:
        check_poisson_ratio(nu)
        return
    check_material(nu, shear_modulus)
    _in_range("--shear-modulus", shear_modulus, "shear_modulus", " Pa")


def contact_extent(area: areas.GridArea) -> tuple[float, float]:
    """Return the span (m) of the area's cells in contact along x and y, cell size included."""
    rows, cols = np.nonzero(area.mask)
    if cols.size == 0:
        return 0.0, 0.0
    return (float(np.ptp(cols)) + 1.0) * area.dx, (float(np.ptp(rows)) + 1.0) * area.dy


def check_plausible_area(args: argparse.Namespace, area: areas.GridArea) -> None:
    """Refuse an area or load implausible for wheel-rail contact (:mod:`plausibility`).

    A patch file: its extent, and its largest pressure unless ``--load``
    rescales them; an ellipse: ``--a`` and ``--b``; then ``--load`` and the
    largest pressure it gives.  Skipped with ``--allow-implausible``.
    """
    allow = args.allow_implausible
    if allow:
        return
    if args.patch is not None:
        extent_x, extent_y = contact_extent(area)
        plausibility.check_patch(extent_x, extent_y,
                                 None if args.load is not None else float(area.pressure.max()),
                                 what=str(args.patch))
    else:
        plausibility.check("semi_axis", args.a, what="--a")
        plausibility.check("semi_axis", args.b, what="--b")
    if args.load is not None:
        plausibility.check("wheel_load", args.load, what="--load")
        plausibility.check("peak_pressure", float(area.pressure.max()),
                           what=f"the largest pressure --load {args.load:g} N gives",
                           mistake="the load and the area's size do not belong together "
                           "(one of them in another unit)")


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


def _check_exact_grid(area: areas.GridArea, *, forces: bool,
                      command: str = "forces --method exact") -> None:
    """Refuse a grid the exact solver cannot take; ``command`` names the one refused."""
    if area.nx > MAX_STRIP_CELLS:
        raise InvalidInputError(f"the exact solver takes at most {MAX_STRIP_CELLS} cells along "
                                f"x (its strips' operator blocks are dense), got {area.nx}")
    n = int(np.count_nonzero(area.mask))
    if forces and n > MAX_EXACT_FORCE_CELLS:
        raise InvalidInputError(
            f"{command} takes at most {MAX_EXACT_FORCE_CELLS:,} cells in contact, "
            f"got {n:,}: use fewer --cells or a coarser patch")


def _finite_result(result: dict[str, Any], keys: Sequence[str]) -> None:
    """Refuse to print a result with a non-finite number (a last guard: the limits prevent it)."""
    for key in keys:
        v = result.get(key)
        if isinstance(v, float) and not math.isfinite(v):
            raise InvalidInputError(f"the solve gave a non-finite {key}: the inputs are beyond "
                                    "what the solver can represent")


def _or_none(v: float) -> float | None:
    return v if math.isfinite(v) else None


# ---------------------------------------------------------------- coefficients


def _patch_alone(args: argparse.Namespace) -> None:
    """Refuse the flags of a shape beside ``--patch`` (one or the other was not meant)."""
    given = [flag for flag, value in (("--shape", args.shape),
                                      ("--a-over-b", getattr(args, "a_over_b", None)),
                                      ("--a", getattr(args, "a", None)),
                                      ("--b", getattr(args, "b", None))) if value is not None]
    if given:
        raise UsageError(f"give either --patch or the shape's flags ({', '.join(given)}), "
                         "not both")
    if getattr(args, "cells", None) is not None:
        # it was ignored without a word: a patch file's grid is its own
        raise UsageError("--cells sets a shape's grid; a --patch file keeps its own cells")


def _shape_maker(args: argparse.Namespace) -> tuple[Callable[[int], areas.GridArea], str]:
    """Return a function of the cell count that makes the area, and its description."""
    if args.patch is not None:
        _patch_alone(args)
        patch = read_patch(args.patch)
        return (lambda n: patch), f"patch {args.patch}"
    if args.shape is None:
        raise UsageError("an area is needed: --shape ellipse|semi-ellipses or --patch FILE")
    g = args.a_over_b
    if args.shape == "ellipse":
        if g is None or len(g) != 1:
            raise UsageError("--shape ellipse takes one --a-over-b value")
    elif g is None or len(g) != 2:
        raise UsageError("--shape semi-ellipses takes two --a-over-b values G1 G2")
    for v in g:
        areas.semi_ellipse_axes(v)  # refuses a/b <= 0 with the library's message
        _in_range("a/b", v, "a_over_b")
    if args.shape == "ellipse":
        a, b = areas.semi_ellipse_axes(g[0])
        return (lambda n: areas.ellipse(a, b, nx=n, ny=n)), f"ellipse a/b={g[0]:g}"
    return ((lambda n: areas.semi_ellipses(g[0], g[1], cells=n)),
            f"semi-ellipses a1/b1={g[0]:g}, a2/b2={g[1]:g}")


COEFFICIENT_KEYS = ("C11", "C12", "C13", "C21", "C22", "C23", "C31", "C32", "C33", "area")


def coefficients(args: argparse.Namespace) -> dict[str, Any]:
    """Run ``coefficients``: a dict of the results."""
    from fastsim_ros.contact import exact
    from fastsim_ros.contact.mae import mae_area_coefficients, mae_fastsim_coefficients
    from fastsim_ros.contact.mae_calibrated import mae_calibrated_coefficients
    from fastsim_ros.contact.pairs import pair_factors
    from fastsim_ros.contact.tables import coefficient_table

    _check_material(args.nu)
    make, what = _shape_maker(args)
    result: dict[str, Any]
    if args.method == "exact" and args.patch is None:
        finest = args.cells or DEFAULT_CELLS["exact"]
        # first-order extrapolation to zero cell size (docs/guide_physics.md "The exact solver")
        ext = exact.extrapolated_coefficients(args.shape, tuple(args.a_over_b), nu=args.nu,
                                              finest=finest)
        result = dict(ext.as_dict())
        result.update(cells=exact.extrapolation_grids(finest), extrapolated=True)
    else:
        ar = make(args.cells or DEFAULT_CELLS[args.method])
        if args.method == "exact":
            _check_exact_grid(ar, forces=False)
            c = exact.creep_coefficients(ar, nu=args.nu)
        elif args.method == "mae":
            c = mae_area_coefficients(ar, coefficient_table(args.nu))
        elif args.method == "mae_calibrated":
            # full adhesion, about the area's origin (as every method here)
            c = mae_calibrated_coefficients(ar, coefficient_table(args.nu),
                                            pair_factors(args.nu))
        elif args.method in ("dlm", "asm"):
            from fastsim_ros.contact.asm import asm_fastsim_coefficients
            from fastsim_ros.contact.dlm import dlm_coefficients
            seed = dlm_coefficients if args.method == "dlm" else asm_fastsim_coefficients
            c = seed(ar, nu=args.nu)
        else:
            c = mae_fastsim_coefficients(ar, coefficient_table(args.nu))
        # MAE gives no C~3j: reported as null
        result = {k: (None if math.isnan(v) else v) for k, v in c.as_dict().items()}
        result.update(cells=[ar.nx, ar.ny], extrapolated=False)
    _finite_result(result, COEFFICIENT_KEYS)
    result.update(method=args.method, nu=args.nu, area_description=what)
    return result


# ---------------------------------------------------------------- forces


#: the keys every ``forces`` result has, whatever the method
FORCE_KEYS = ("Fx", "Fy", "Mz", "N", "slip_fraction")


def forces(args: argparse.Namespace) -> dict[str, Any]:
    """Run ``forces``: a dict of the results (the same keys for every method, and extras)."""
    _check_material(args.nu, args.shear_modulus)
    check_friction(args.mu)
    _in_range("mu", args.mu, "mu", open_low=True)
    _in_range("xi", args.xi, "creepage", magnitude=True)
    _in_range("eta", args.eta, "creepage", magnitude=True)
    _in_range("phi", args.phi, "spin", " 1/m", magnitude=True)
    if args.load is not None and not args.load > 0.0:
        raise InvalidInputError(f"--load must be positive, got {args.load:g}")
    if args.method == "exact" and args.bound == "parabolic":
        raise UsageError("--method exact takes the pressure as given (--bound given)")
    if args.method == "fastrip" and args.bound == "parabolic":
        raise UsageError("--method fastrip takes the strips' Hertzian pressure of the given "
                         "load (--bound given)")
    law = _friction(args)
    if args.method == "exact" and law.reduces_slope:
        raise UsageError("--method exact is Kalker's exact theory, its slope in full: the "
                         "--slope-* reduction is an option of the fast methods")
    if args.method == "fastrip" and law.slip_dependent and not law.reduces_slope:
        raise UsageError("--method fastrip takes constant friction (--friction-law constant), "
                         "or a law with a --slope-* reduction (taken at the rigid slip)")
    patch = _force_area(args)
    # before any solve: a unit mistake is refused, not answered with believable numbers
    check_plausible_area(args, patch)
    check_plausible_material(args)
    check_plausible_creepages(args.xi, args.eta, args.phi, allow=args.allow_implausible,
                              where="--")
    result: dict[str, Any] = {"method": args.method, "N": patch.load, "bound": args.bound,
                              "friction_law": law.name}
    if isinstance(law, ExponentialFriction):
        result.update(friction_limit_ratio=law.limit_ratio, friction_decay=law.decay,
                      speed=args.speed)
    if law.reduction is not None:
        result.update(slope_reduction={"k0": law.reduction.k0,
                                       "alpha_inf": law.reduction.alpha_inf,
                                       "beta": law.reduction.beta})
    creepages = (args.xi, args.eta, args.phi)
    speed = None if args.speed is None else abs(args.speed)
    cells = [patch.nx, patch.ny]
    # the slip area's dissipation per metre rolled (N), where the method gives it
    dissipation = math.nan
    if args.method == "exact":
        from fastsim_ros.contact import exact
        _check_exact_grid(patch, forces=True)
        sol = exact.coulomb(patch, *creepages, nu=args.nu, shear_modulus=args.shear_modulus,
                            friction=law, speed=speed)
        fx, fy, mz = sol.fx, sol.fy, sol.mz
        n = patch.nx
        if args.patch is None and n >= 2 * EXACT_COARSEST:
            # the exact forces converge in the cell at first order (the rigid slip taken at
            # a cell's end, the upstream difference: the physics guide): on 60 cells an ellipse's
            # Fy under spin is 1.7% off its limit, so a shape's forces are extrapolated
            # from n/2 and n cells, F = (n F_n - m F_m) / (n - m)
            m = n // 2
            coarse = exact.coulomb(areas.ellipse(args.a, args.b, nx=m, ny=m, load=args.load),
                                   *creepages, nu=args.nu, shear_modulus=args.shear_modulus,
                                   friction=law, speed=speed)
            fx, fy, mz = ((n * f - m * c) / (n - m) for f, c in
                          ((sol.fx, coarse.fx), (sol.fy, coarse.fy), (sol.mz, coarse.mz)))
            cells = [m, n]
            result.update(extrapolated=True)
        result.update(Fx=fx, Fy=fy, Mz=mz, slip_fraction=float(
            np.count_nonzero(sol.slip)) / np.count_nonzero(patch.mask))
        # on the finest grid (the forces above may be extrapolated)
        dissipation = exact.slip_dissipation(patch, sol, *creepages, nu=args.nu,
                                             shear_modulus=args.shear_modulus)[0]
    elif args.method in ("mae", "mae_calibrated"):
        from fastsim_ros.contact.compiled import CalibratedMaeSolver, MaeSolver
        solver = CalibratedMaeSolver if args.method == "mae_calibrated" else MaeSolver
        mae = solver(args.nu, args.shear_modulus)
        res = mae.solve(patch, *creepages, bound=args.bound, friction=law, speed=speed,
                        tractions=True)
        dissipation = res.dissipation
        g = mae.geometry(patch)
        result.update(Fx=res.fx, Fy=res.fy, Mz=res.mz, slip_fraction=res.slip_fraction,
                      split_y=g.y_s,
                      # an empty zone (a one-sided split) has no semi-ellipse: null axes
                      zones=[{"area": z.area, "a": _or_none(z.a_eq), "b": _or_none(z.b_eq)}
                             for z in (g.zone1, g.zone2)])
    elif args.method in ("dlm", "asm"):
        from fastsim_ros.contact.asm import asm_fastsim
        from fastsim_ros.contact.dlm import dlm_fastsim
        seed = dlm_fastsim if args.method == "dlm" else asm_fastsim
        fs = seed(patch, *creepages, mu=args.mu, nu=args.nu, shear_modulus=args.shear_modulus,
                  bound=args.bound, friction=law, speed=speed)
        result.update(Fx=fs.fx, Fy=fs.fy, Mz=fs.mz, slip_fraction=float(
            np.count_nonzero(fs.slip)) / np.count_nonzero(patch.mask))
    elif args.method == "fastrip":
        from fastsim_ros.contact.fastrip import fastrip
        from fastsim_ros.contact.tables import coefficient_table
        table = coefficient_table(args.nu)
        fr_creep, fr_mu = creepages, args.mu
        if law.reduces_slope:  # the modified FastSim's k and mu (equivalent.reduce_slope)
            from fastsim_ros.contact.equivalent import reduce_slope
            red = reduce_slope(patch, *creepages, law, speed, table=table,
                               shear_modulus=args.shear_modulus)
            fr_creep, fr_mu = (red.xi, red.eta, red.phi), red.friction.mu_s
        fr = fastrip(patch, *fr_creep, mu=fr_mu, table=table, shear_modulus=args.shear_modulus)
        e = fr.ellipse
        result.update(Fx=fr.fx, Fy=fr.fy, Mz=fr.mz, slip_fraction=float(
            np.count_nonzero(fr.traction.slip)) / np.count_nonzero(patch.mask),
            ellipse={"x_c": e.x_c, "y_c": e.y_c, "a": e.a, "b": e.b})
    elif args.method == "polach":
        from fastsim_ros.contact.compiled import EquivalentEllipseSolver
        from fastsim_ros.contact.polach import PolachSolver
        if law.reduces_slope:
            raise UsageError("--method polach reduces its slope with --polach-ka and "
                             "--polach-ks, not --slope-*")
        pol = PolachSolver(args.nu, args.shear_modulus, k_a=args.polach_ka, k_s=args.polach_ks)
        res = pol.solve(patch, *creepages, bound=args.bound, friction=law, speed=speed)
        e = EquivalentEllipseSolver(args.nu, args.shear_modulus).ellipse(patch)
        result.update(Fx=res.fx, Fy=res.fy, Mz=res.mz, slip_fraction=res.slip_fraction,
                      polach_ka=args.polach_ka, polach_ks=args.polach_ks,
                      ellipse={"x_c": e.x_c, "y_c": e.y_c, "a": e.a, "b": e.b})
    else:
        from fastsim_ros.contact.compiled import EquivalentEllipseSolver
        eq = EquivalentEllipseSolver(args.nu, args.shear_modulus)
        res = eq.solve(patch, *creepages, bound=args.bound, friction=law, speed=speed,
                       tractions=True)
        dissipation = res.dissipation
        e = eq.ellipse(patch)
        result.update(Fx=res.fx, Fy=res.fy, Mz=res.mz, slip_fraction=res.slip_fraction,
                      ellipse={"x_c": e.x_c, "y_c": e.y_c, "a": e.a, "b": e.b})
    _finite_result(result, FORCE_KEYS)
    result.update(_wear(result, creepages, patch, dissipation, speed))
    result["cells"] = cells
    return result


def _wear(result: dict[str, Any], creepages: tuple[float, float, float],
          patch: areas.GridArea, dissipation: float, speed: float | None) -> dict[str, Any]:
    """Return the wear and fatigue keys of a ``forces`` result (docs/guide_wear.md).

    ``T_gamma`` (N), ``T_gamma_per_area`` (Pa), ``wear_rate`` (kg per metre
    rolled per m^2, the USFD function), ``rcf_damage`` (per passage,
    Burstow's), ``frictional_dissipation`` (N = J per metre rolled: the
    slip area's; null where the method does not give it: dlm, asm,
    fastrip), ``slip_share`` (that over ``T_gamma``) and
    ``frictional_power`` (W, that times ``|V|``: null without ``--speed``).
    """
    area = float(np.count_nonzero(patch.mask)) * patch.cell_area
    w = wear.indicators(result["Fx"], result["Fy"], result["Mz"], *creepages, area,
                        1.0, dissipation)
    return {"T_gamma": w.t_gamma, "T_gamma_per_area": w.t_gamma_per_area,
            "wear_rate": w.wear_rate, "rcf_damage": w.rcf_damage,
            "frictional_dissipation": _or_none(dissipation),
            "slip_share": _or_none(w.slip_share),
            "frictional_power": (_or_none(dissipation * speed) if speed is not None
                                 else None)}


def _friction(args: argparse.Namespace) -> FrictionLaw:
    """Return the friction law of ``forces``, its flags checked (each named when refused)."""
    given = {"--friction-limit-ratio": args.friction_limit_ratio,
             "--friction-decay": args.friction_decay, "--speed": args.speed}
    if args.friction_law == "constant":
        extra = [flag for flag in ("--friction-limit-ratio", "--friction-decay")
                 if given[flag] is not None]
        if extra:
            raise UsageError(f"{' and '.join(extra)} only apply to --friction-law exponential")
        if args.speed is not None:
            _speed(args.speed)
        return ConstantFriction(args.mu, reduction=slope_reduction(args))
    missing = [flag for flag, v in given.items() if v is None]
    if missing:
        raise UsageError(f"--friction-law exponential requires {', '.join(missing)}")
    a, b = args.friction_limit_ratio, args.friction_decay
    if not 0.0 < a <= 1.0:
        raise InvalidInputError(f"--friction-limit-ratio must lie in (0, 1], got {a:g}")
    if not 0.0 <= b <= 1e4:
        raise InvalidInputError(f"--friction-decay must lie in [0, 1e4] s/m, got {b:g}")
    _speed(args.speed)
    return ExponentialFriction(args.mu, a, b, reduction=slope_reduction(args))


def _speed(v: float) -> None:
    if not abs(v) <= 1e4:
        raise InvalidInputError(f"--speed must be at most 1e4 m/s in magnitude, got {v:g}")


def _force_area(args: argparse.Namespace) -> areas.GridArea:
    """Return the loaded area: a patch file, or an ellipse with Hertzian pressure.

    The largest pressure is checked against ``LIMITS["pressure"]`` before a
    load scales it (so that an absurd ``--load`` is named, not its overflow).
    """
    lo, hi = LIMITS["pressure"]
    if args.patch is not None:
        _patch_alone(args)
        patch = read_patch(args.patch)
        if args.load is None:
            p_max = float(patch.pressure.max())
            if not lo <= p_max <= hi:
                raise InvalidInputError(f"{args.patch}: largest pressure {p_max:.3g} Pa; "
                                        f"pressures must lie in [{lo:g}, {hi:g}] Pa (or "
                                        "rescale them with --load)")
            return patch
        _check_load(args.load, patch)
        return patch.with_load(args.load)
    if args.shape != "ellipse" or args.a is None or args.b is None:
        raise UsageError("forces need --shape ellipse --a A --b B (with --load) or --patch FILE")
    if getattr(args, "a_over_b", None) is not None:
        # it was dropped without a word: the semi-axes give the ratio
        raise UsageError("--a-over-b is for coefficients: forces take the semi-axes --a and --b")
    if args.load is None:
        raise UsageError("--load is required with --shape ellipse --a A --b B")
    _in_range("--a", args.a, "length", " m")
    _in_range("--b", args.b, "length", " m")
    n = args.cells or DEFAULT_CELLS[args.method + "_forces"]
    _check_load(args.load, areas.ellipse(args.a, args.b, nx=n, ny=n, load=1.0))
    return areas.ellipse(args.a, args.b, nx=n, ny=n, load=args.load)


def _check_load(load: float, unit: areas.GridArea) -> None:
    """Refuse a load that would put the largest pressure of ``unit`` outside the limits."""
    lo, hi = LIMITS["pressure"]
    peak = float(unit.pressure.max()) * (load / unit.load)  # floats: inf, not an error
    if not lo <= peak <= hi:
        # an overflowing peak is told as above the limit (no non-finite number printed)
        told = f"of {peak:.3g} Pa" if math.isfinite(peak) else f"above {hi:g} Pa"
        raise InvalidInputError(f"--load {load:g} N gives a largest pressure {told}; "
                                f"pressures must lie in [{lo:g}, {hi:g}] Pa")


# ---------------------------------------------------------------- output


def _print_table(command: str, result: dict[str, Any]) -> None:
    if command == "wheelset":
        from fastsim_ros import cli_wheelset
        cli_wheelset.print_table(result)
        return
    if command == "estimate":
        from fastsim_ros import cli_estimate
        cli_estimate.print_table(result)
        return
    if command == "coefficients":
        print(f"{result['area_description']}, nu = {result['nu']:g}, method {result['method']}"
              + (f", extrapolated from grids {result['cells']}" if result.get("extrapolated")
                 else f", grid {result['cells'][0]} x {result['cells'][1]}"))
        print(f"area A = {result['area']:.6g} m^2; about the area's origin")
        for row in ("1", "2", "3"):
            values = [(f"C{row}{col}", result[f"C{row}{col}"]) for col in "123"]
            if all(v is not None for _, v in values):
                print("  " + "  ".join(f"{k} = {v:9.4f}" for k, v in values))
    else:
        print_forces(result)


#: units of the ``forces`` result's numbers in the readable table (the rest: none)
FORCE_UNITS = {"N": "N", "Fx": "N", "Fy": "N", "Mz": "N m", "split_y": "m", "speed": "m/s",
               "friction_decay": "s/m", "area": "m^2", "a": "m", "b": "m", "x_c": "m",
               "y_c": "m", "T_gamma": "N", "T_gamma_per_area": "Pa",
               "wear_rate": "kg/(m m^2)", "frictional_dissipation": "J/m",
               "frictional_power": "W"}


def _text(key: str, value: Any) -> str:
    """Return one value of a result as the readable table shows it, with its unit."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        unit = FORCE_UNITS.get(key)
        return f"{value:.6g}" + (f" {unit}" if unit else "")
    if isinstance(value, dict):
        return ", ".join(f"{k} {_text(k, v)}" for k, v in value.items())
    if isinstance(value, list):
        if key == "cells":
            return " x ".join(str(v) for v in value)
        return "; ".join(f"[{_text(key, v)}]" for v in value)
    return str(value)


def print_forces(result: dict[str, Any]) -> None:
    """Print every field of a ``forces`` result, one ``key = value`` line each (JSON's keys)."""
    first = [k for k in ("method", "N", "Fx", "Fy", "Mz", "slip_fraction") if k in result]
    for key in first + [k for k in result if k not in first]:
        text = _text(key, result[key])
        if key == "cells" and result.get("extrapolated"):
            # the exact forces on a shape: the two grids of the extrapolation, cells across
            text = " and ".join(str(n) for n in result[key]) + " across (extrapolated)"
        print(f"  {key} = {text}")


def _run(argv: Sequence[str] | None) -> tuple[argparse.Namespace, dict[str, Any]]:
    args = build_parser().parse_args(argv)
    with np.errstate(all="ignore"):
        if args.command == "wheelset":
            from fastsim_ros import cli_wheelset
            return args, cli_wheelset.run(args)
        if args.command == "estimate":
            from fastsim_ros import cli_estimate
            return args, cli_estimate.run(args)
        result = coefficients(args) if args.command == "coefficients" else forces(args)
    return args, result


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``fastsim_contact``: 0 on success, 2 on bad input, 1 on an internal error."""
    try:
        # a warning is never the answer: the checks and the finite-result guard are
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            args, result = _run(argv)
        text = json.dumps(result, allow_nan=False) if args.json else None
    except (UsageError, ContactError) as e:
        print(f"fastsim_contact: error: {e}", file=sys.stderr)
        return 2
    except SystemExit as e:  # --help
        return int(e.code or 0)
    except KeyboardInterrupt:
        return 130
    except MemoryError:
        print("fastsim_contact: error: out of memory", file=sys.stderr)
        return 2
    except Exception as e:  # a bug, not bad input: still one line, no traceback
        print(f"fastsim_contact: internal error: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    try:
        if text is not None:
            print(text)
        else:
            _print_table(args.command, result)
        sys.stdout.flush()
    except BrokenPipeError:  # e.g. piped into head
        _quiet_stdout()
        return 0
    except OSError as e:  # a full disk, a closed descriptor: one line, not a traceback
        _quiet_stdout()
        print(f"fastsim_contact: error: cannot write the answer: {e.strerror or e}",
              file=sys.stderr)
        return 1
    return 0


def _quiet_stdout() -> None:
    """Point stdout at the null device: the interpreter's last flush at exit fails again."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):
        pass


if __name__ == "__main__":
    # ``python -m fastsim_ros.cli``: run the package's module, not this copy of it named
    # __main__, whose UsageError the subcommands' modules (which import fastsim_ros.cli)
    # would not raise: their usage errors were internal errors, exit 1
    from fastsim_ros.cli import main as _main
    sys.exit(_main())
