"""``fastsim_contact coefficients`` and ``forces``: one contact area's coefficients and forces.

``forces --method mae_calibrated`` (the default: the calibrated MAE, better than
the paper's MAE on every area of docs/validation_wider.md), ``mae`` (the paper's)
and ``fastsim_ellipse`` run the compiled solvers of
:mod:`fastsim_ros.contact.compiled`, the code the node runs; ``exact`` runs
the exact theory (:mod:`fastsim_ros.contact.exact`); ``fastrip`` the numpy
FaStrip baseline (:mod:`fastsim_ros.contact.fastrip`, no compiled path);
``dlm`` and ``asm`` the seed paper's older ways to FastSim's flexibilities
(:mod:`~fastsim_ros.contact.dlm`, :mod:`~fastsim_ros.contact.asm`, numpy).
The area is a shape (``--shape``) or a patch file (``--patch``,
:func:`fastsim_ros.cli.patch_files.read_patch`).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from fastsim_ros.cli.options import (COEFFICIENT_METHODS, DEFAULT_CELLS, EXACT_COARSEST,
                                     FORCE_METHODS, LIMITS, MAX_EXACT_FORCE_CELLS,
                                     MAX_STRIP_CELLS, add_allow_implausible, add_area,
                                     add_material, add_poisson_ratio, add_slope_reduction,
                                     check_finite_result, check_material_flags,
                                     check_plausible_creepages, check_plausible_material,
                                     check_speed, finite, in_range, node_default,
                                     slope_reduction)
from fastsim_ros.cli.patch_files import read_patch
from fastsim_ros.contact import area as areas
from fastsim_ros.contact import wear
from fastsim_ros.contact.checks import BOUNDS, check_friction
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.friction import ConstantFriction, ExponentialFriction, FrictionLaw
from fastsim_ros.errors import UsageError
from fastsim_ros.ros import plausibility


def add_parsers(sub: Any) -> None:
    """Add ``coefficients`` and ``forces`` to the subcommands of ``fastsim_contact``."""
    co = sub.add_parser("coefficients", help="generalised creepage coefficients C~ij")
    add_area(co, forces=False)
    co.add_argument("--method", choices=COEFFICIENT_METHODS, default="exact",
                    help="exact solver (default: the coefficients are the exact theory's "
                    "numbers), MAE's coefficients, the calibrated MAE's "
                    "(its FastSim in full adhesion), MAE + FastSim in full adhesion, or the "
                    "seed's DLM or ASM (FastSim with their flexibilities, full adhesion)")
    add_poisson_ratio(co, finite)
    fo = sub.add_parser("forces", help="creep forces at given creepages")
    add_area(fo, forces=True)
    fo.add_argument("--xi", type=finite, required=True, help="longitudinal creepage")
    fo.add_argument("--eta", type=finite, required=True, help="lateral creepage")
    fo.add_argument("--phi", type=finite, required=True, help="spin creepage (1/m)")
    fo.add_argument("--mu", type=finite, required=True,
                    help="friction coefficient (the static mu_s of a slip-dependent law)")
    fo.add_argument("--friction-law", choices=("constant", "exponential"),
                    default=node_default("friction_law"),
                    help="constant (Coulomb) or exponential: mu(v) = mu_s ((1 - A) exp(-B v) "
                    "+ A), v the local slip velocity (m/s); default %(default)s, the node's")
    fo.add_argument("--friction-limit-ratio", type=finite, metavar="A",
                    help="A in (0, 1] of the exponential law")
    fo.add_argument("--friction-decay", type=finite, metavar="B",
                    help="B >= 0 (s/m) of the exponential law")
    fo.add_argument("--speed", type=finite, metavar="V",
                    help="rolling speed V (m/s; its magnitude is used)")
    add_slope_reduction(fo, finite)
    fo.add_argument("--load", type=finite, help="normal load N (N)")
    add_material(fo, finite)
    fo.add_argument("--method", choices=FORCE_METHODS, default=node_default("method"),
                    help="mae_calibrated (the calibrated MAE), mae (the paper's MAE), "
                    "fastsim_ellipse, exact, fastrip, dlm, asm or polach (Polach's closed "
                    "form on the equivalent ellipse); default %(default)s, the node's")
    fo.add_argument("--polach-ka", type=finite, metavar="KA",
                    default=node_default("polach_ka"),
                    help="Polach's kA in (0, 1] (method polach); default %(default)s")
    fo.add_argument("--polach-ks", type=finite, metavar="KS",
                    default=node_default("polach_ks"),
                    help="Polach's kS in (0, kA] (method polach); default %(default)s")
    fo.add_argument("--bound", choices=BOUNDS, default=node_default("traction_bound"),
                    help="traction bound: mu p as given, or parabolic, mu N p^2/sum(p^2 dA) "
                    "(Kalker's on a Hertzian patch); default %(default)s, the node's")
    add_allow_implausible(fo)


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


def check_exact_grid(area: areas.GridArea, *, forces: bool,
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
        in_range("a/b", v, "a_over_b")
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

    check_material_flags(args.nu)
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
            check_exact_grid(ar, forces=False)
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
    check_finite_result(result, COEFFICIENT_KEYS)
    result.update(method=args.method, nu=args.nu, area_description=what)
    return result


# ---------------------------------------------------------------- forces


#: the keys every ``forces`` result has, whatever the method
FORCE_KEYS = ("Fx", "Fy", "Mz", "N", "slip_fraction")


def forces(args: argparse.Namespace) -> dict[str, Any]:
    """Run ``forces``: a dict of the results (the same keys for every method, and extras)."""
    check_material_flags(args.nu, args.shear_modulus)
    check_friction(args.mu)
    in_range("mu", args.mu, "mu", open_low=True)
    in_range("xi", args.xi, "creepage", magnitude=True)
    in_range("eta", args.eta, "creepage", magnitude=True)
    in_range("phi", args.phi, "spin", " 1/m", magnitude=True)
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
    patch = force_area(args)
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
        check_exact_grid(patch, forces=True)
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
        if args.method == "mae_calibrated":
            # separate contact regions (fastsim_ros.contact.lobes): where the solve split the
            # patch and the whole patch's weight; the split and zones above are the whole patch's
            from fastsim_ros.contact.kernels import patch_gap
            m, w = patch_gap(np.ascontiguousarray(patch.pressure, dtype=np.float64), True)
            result.update(regions={"apart_at_y": float(patch.y0 + (m - 0.5) * patch.dy),
                                   "whole_weight": float(w)} if w < 1.0 else None)
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
    check_finite_result(result, FORCE_KEYS)
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
            check_speed(args.speed)
        return ConstantFriction(args.mu, reduction=slope_reduction(args))
    missing = [flag for flag, v in given.items() if v is None]
    if missing:
        raise UsageError(f"--friction-law exponential requires {', '.join(missing)}")
    a, b = args.friction_limit_ratio, args.friction_decay
    if not 0.0 < a <= 1.0:
        raise InvalidInputError(f"--friction-limit-ratio must lie in (0, 1], got {a:g}")
    if not 0.0 <= b <= 1e4:
        raise InvalidInputError(f"--friction-decay must lie in [0, 1e4] s/m, got {b:g}")
    check_speed(args.speed)
    return ExponentialFriction(args.mu, a, b, reduction=slope_reduction(args))


def force_area(args: argparse.Namespace) -> areas.GridArea:
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
    in_range("--a", args.a, "length", " m")
    in_range("--b", args.b, "length", " m")
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


def print_coefficients(result: dict[str, Any]) -> None:
    """Print a ``coefficients`` result: the area, the grid, then the rows of C~ij it gives."""
    print(f"{result['area_description']}, nu = {result['nu']:g}, method {result['method']}"
          + (f", extrapolated from grids {result['cells']}" if result.get("extrapolated")
             else f", grid {result['cells'][0]} x {result['cells'][1]}"))
    print(f"area A = {result['area']:.6g} m^2; about the area's origin")
    for row in ("1", "2", "3"):
        values = [(f"C{row}{col}", result[f"C{row}{col}"]) for col in "123"]
        if all(v is not None for _, v in values):
            print("  " + "  ".join(f"{k} = {v:9.4f}" for k, v in values))


#: units of the ``forces`` result's numbers in the readable table (the rest: none)
FORCE_UNITS = {"N": "N", "Fx": "N", "Fy": "N", "Mz": "N m", "split_y": "m", "speed": "m/s",
               "apart_at_y": "m",
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
