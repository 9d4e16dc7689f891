"""``fastsim_contact``: one-off contact computations from the command line.

Two commands (INTERFACE.md): ``coefficients`` prints an area's generalised
creepage coefficients, ``forces`` the creep forces at given creepages.  SI
units throughout.  ``--json`` prints exactly one JSON object on stdout.  Bad
input gives one line on stderr and exit status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import exact
from fastsim_ros.contact.equivalent import equivalent_fastsim
from fastsim_ros.contact.errors import ContactError, InvalidInputError
from fastsim_ros.contact.fastsim import traction_bound
from fastsim_ros.contact.mae import (mae_coefficients, mae_fastsim, mae_fastsim_coefficients,
                                     mae_geometry)
from fastsim_ros.contact.tables import coefficient_table

EXACT_GRIDS = (0.4, 0.6, 0.8, 1.0)
#: cells across the bounding box of a shape, per method: exact coefficients are
#: extrapolated from grids up to this; FastSim's discretisation error at 60
#: cells is 0.1% on ellipses (docs/validation.md).
DEFAULT_CELLS = {"exact": 100, "mae": 100, "fastsim": 60, "exact_forces": 60,
                 "mae_forces": 60, "fastsim_ellipse_forces": 60}


class UsageError(Exception):
    """A command line that cannot be run: reported in one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
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
    if n < 4 or n > 400:
        raise argparse.ArgumentTypeError(f"--cells must lie in [4, 400], got {n}")
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
    p.add_argument("--cells", type=_cells,
                   help="cells along each axis of a shape's bounding box (a patch keeps its grid)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def build_parser() -> argparse.ArgumentParser:
    """Return the parser of the two commands and their fixed flags."""
    parser = _Parser(prog="fastsim_contact",
                     description="Creepage coefficients and creep forces of a contact area.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    co = sub.add_parser("coefficients", help="generalised creepage coefficients C~ij")
    _add_area(co, forces=False)
    co.add_argument("--method", choices=("exact", "mae", "fastsim"), default="exact",
                    help="exact solver, MAE's coefficients, or MAE + FastSim in adhesion")
    co.add_argument("--nu", type=_finite, default=0.25, help="Poisson ratio (default 0.25)")
    fo = sub.add_parser("forces", help="creep forces at given creepages")
    _add_area(fo, forces=True)
    fo.add_argument("--xi", type=_finite, required=True, help="longitudinal creepage")
    fo.add_argument("--eta", type=_finite, required=True, help="lateral creepage")
    fo.add_argument("--phi", type=_finite, required=True, help="spin creepage (1/m)")
    fo.add_argument("--mu", type=_finite, required=True, help="friction coefficient")
    fo.add_argument("--load", type=_finite, help="normal load N (N)")
    fo.add_argument("--shear-modulus", type=_finite, default=8.0e10, help="combined G (Pa)")
    fo.add_argument("--nu", type=_finite, default=0.28, help="Poisson ratio (default 0.28)")
    fo.add_argument("--method", choices=("mae", "fastsim_ellipse", "exact"), default="mae")
    fo.add_argument("--bound", choices=("given", "parabolic"), default="given",
                    help="traction bound: mu p as given, or parabolic, mu N p^2/sum(p^2 dA) "
                    "(Kalker's on a Hertzian patch)")
    return parser


def read_patch(path: Path) -> areas.GridArea:
    """Read a patch CSV (header ``x,y,pressure``; m, m, Pa) into a grid area."""
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(line for line in f if not line.lstrip().startswith("#")))
    except OSError as e:
        raise InvalidInputError(f"cannot read patch file {path}: {e.strerror}") from None
    if not rows or [c.strip() for c in rows[0]] != ["x", "y", "pressure"]:
        raise InvalidInputError(f"{path}: the header must be x,y,pressure")
    body = [r for r in rows[1:] if any(c.strip() for c in r)]
    if not body:
        raise InvalidInputError(f"{path}: no cells")
    try:
        data = np.array([[float(c) for c in r] for r in body], dtype=float)
    except ValueError:
        raise InvalidInputError(f"{path}: a value that is not a number") from None
    if data.ndim != 2 or data.shape[1] != 3:
        raise InvalidInputError(f"{path}: every row needs three values x,y,pressure")
    return areas.from_cells(data[:, 0], data[:, 1], data[:, 2])


def _shape_maker(args: argparse.Namespace) -> tuple[Callable[[int], areas.GridArea], str]:
    """Return a function of the cell count that makes the area, and its description."""
    if args.patch is not None:
        if args.shape is not None:
            raise UsageError("give either --shape or --patch, not both")
        patch = read_patch(args.patch)
        return (lambda n: patch), f"patch {args.patch}"
    if args.shape is None:
        raise UsageError("an area is needed: --shape ellipse|semi-ellipses or --patch FILE")
    g = args.a_over_b
    if args.shape == "ellipse":
        if g is None or len(g) != 1:
            raise UsageError("--shape ellipse takes one --a-over-b value")
        a, b = areas.semi_ellipse_axes(g[0])
        return (lambda n: areas.ellipse(a, b, nx=n, ny=n)), f"ellipse a/b={g[0]:g}"
    if g is None or len(g) != 2:
        raise UsageError("--shape semi-ellipses takes two --a-over-b values G1 G2")
    for v in g:
        areas.semi_ellipse_axes(v)
    return ((lambda n: areas.semi_ellipses(g[0], g[1], cells=n)),
            f"semi-ellipses a1/b1={g[0]:g}, a2/b2={g[1]:g}")


def _grid_sequence(finest: int) -> list[int]:
    return sorted({max(4, 2 * round(f * finest / 2)) for f in EXACT_GRIDS})


def coefficients(args: argparse.Namespace) -> dict[str, Any]:
    """Run ``coefficients``: a dict of the results."""
    exact.check_material(args.nu)
    make, what = _shape_maker(args)
    result: dict[str, Any]
    if args.method == "exact" and args.patch is None:
        finest = args.cells or DEFAULT_CELLS["exact"]
        grids = _grid_sequence(finest)
        per = [exact.creep_coefficients(make(n), nu=args.nu) for n in grids]
        h = np.array([1.0 / n for n in grids])
        result = {}
        for key in ("C11", "C12", "C13", "C21", "C22", "C23", "C31", "C32", "C33"):
            # first-order convergence in the cell size (METHOD.md 5)
            result[key] = float(np.polyfit(h, [getattr(c, key) for c in per], 1)[1])
        result.update(area=1.0, cells=grids, extrapolated=True)
    else:
        ar = make(args.cells or DEFAULT_CELLS[args.method])
        if args.method == "exact":
            c = exact.creep_coefficients(ar, nu=args.nu)
        elif args.method == "mae":
            c = mae_coefficients(mae_geometry(ar), coefficient_table(args.nu))
        else:
            c = mae_fastsim_coefficients(ar, coefficient_table(args.nu))
        result = {k: (None if math.isnan(v) else v) for k, v in c.as_dict().items()}
        result.update(cells=[ar.nx, ar.ny], extrapolated=False)
    result.update(method=args.method, nu=args.nu, area_description=what)
    return result


def forces(args: argparse.Namespace) -> dict[str, Any]:
    """Run ``forces``: a dict of the results."""
    exact.check_material(args.nu, args.shear_modulus)
    if not args.mu > 0.0:
        raise InvalidInputError(f"mu must be positive, got {args.mu}")
    if args.load is not None and not args.load > 0.0:
        raise InvalidInputError(f"--load must be positive, got {args.load}")
    patch = _force_area(args)
    result: dict[str, Any] = {"method": args.method, "N": patch.load, "bound": args.bound}
    if args.method == "exact":
        if args.bound == "parabolic":
            raise UsageError("--method exact takes the pressure as given (--bound given)")
        sol = exact.coulomb(patch, args.xi, args.eta, args.phi, mu=args.mu, nu=args.nu,
                            shear_modulus=args.shear_modulus)
        result.update(Fx=sol.fx, Fy=sol.fy, Mz=sol.mz, slip_fraction=float(
            np.count_nonzero(sol.slip)) / np.count_nonzero(patch.mask))
    elif args.method == "mae":
        bound = traction_bound(patch, args.mu, bound=args.bound)
        res = mae_fastsim(patch, args.xi, args.eta, args.phi, bound=bound,
                          table=coefficient_table(args.nu), shear_modulus=args.shear_modulus)
        g = res.geometry
        result.update(Fx=res.fx, Fy=res.fy, Mz=res.mz, slip_fraction=float(
            np.count_nonzero(res.traction.slip)) / np.count_nonzero(patch.mask),
            split_y=g.y_s, zones=[{"area": z.area, "a": z.a_eq, "b": z.b_eq}
                                  for z in (g.zone1, g.zone2)])
    else:
        eq = equivalent_fastsim(patch, args.xi, args.eta, args.phi, mu=args.mu,
                                table=coefficient_table(args.nu),
                                shear_modulus=args.shear_modulus, bound=args.bound)
        result.update(Fx=eq.fx, Fy=eq.fy, Mz=eq.mz, ellipse={
            "x_c": eq.ellipse.x_c, "y_c": eq.ellipse.y_c, "a": eq.ellipse.a, "b": eq.ellipse.b})
    result["cells"] = [patch.nx, patch.ny]
    return result


def _force_area(args: argparse.Namespace) -> areas.GridArea:
    """Return the loaded area: a patch file, or an ellipse with Hertzian pressure."""
    if args.patch is not None:
        if args.shape is not None:
            raise UsageError("give either --shape or --patch, not both")
        patch = read_patch(args.patch)
        return patch if args.load is None else patch.with_load(args.load)
    if args.shape != "ellipse" or args.a is None or args.b is None:
        raise UsageError("forces need --shape ellipse --a A --b B (with --load) or --patch FILE")
    if args.load is None:
        raise UsageError("--load is required with --shape ellipse --a A --b B")
    n = args.cells or DEFAULT_CELLS[args.method + "_forces"]
    return areas.ellipse(args.a, args.b, nx=n, ny=n, load=args.load)


def _print_table(command: str, result: dict[str, Any]) -> None:
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
        print(f"method {result['method']}, N = {result['N']:.6g} N")
        print(f"  Fx = {result['Fx']:.6g} N\n  Fy = {result['Fy']:.6g} N\n"
              f"  Mz = {result['Mz']:.6g} N m")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``fastsim_contact``: 0 on success, 2 on bad input."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        result = coefficients(args) if args.command == "coefficients" else forces(args)
    except (UsageError, ContactError) as e:
        print(f"fastsim_contact: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    if args.json:
        print(json.dumps(result))
    else:
        _print_table(args.command, result)
    return 0


if __name__ == "__main__":
    sys.exit(main())
