"""``fastsim_contact estimate``: fit a friction law to a measured creep curve.

``--measured FILE.csv`` (header ``xi,eta,phi,Fx`` or ``xi,eta,phi,Fx,Fy``;
creepages in 1, 1, 1/m about the area's origin, forces of the rail on the
wheel in N, signs as in docs/guide_physics.md) on the area of ``forces``
(``--shape ellipse --a --b --load`` or ``--patch FILE``, ``--nu``, ``--shear-modulus``,
``--bound``, ``--cells``): the batch fit of
:func:`fastsim_ros.estimation.fit.fit_friction` with the solver of
``--method`` under ``--friction-law``
(``constant``: ``mu_s``; ``exponential``: ``mu_s``, ``A``, ``B``, with
``--speed`` the rolling speed in m/s).  ``--mu``, ``--friction-limit-ratio``
and ``--friction-decay`` give the starting point.  ``--json`` prints
``mu_s``, the law's parameters, their standard deviations (null where the
data do not determine them) and the fitted curve's worst and rms errors in
% of ``mu_s N``, and ``model_correction`` (``knee_strips``, ``knee_factor`` or ``none``,
with ``model_correction_note`` in words, also in the readable table): the
correction the fit's model applies to the method's force.  Bad files and
flags: one line on stderr, exit status 2 (the checks and messages of
:mod:`fastsim_ros.cli`); so are values implausible for wheel-rail contact
(:mod:`fastsim_ros.ros.plausibility`: the area, ``--load``, ``--mu``,
``--shear-modulus`` and the measured creepages) unless
``--allow-implausible``.  Material, friction and bound default to the
node's parameters.

The default model is Kalker's exact theory (``--method exact``, as for
``coefficients``: a fitted ``mu_s`` is the exact theory's number): an offline
fit is where the reference belongs; it recovers ``mu_s``, ``A`` and ``B``
(seconds for a constant law, tens of seconds for the exponential one on a
dozen samples at the default 60 x 60 cells).  ``--method mae_calibrated``
(the node's estimator's model: the method's force times the knee factor,
:mod:`fastsim_ros.contact.knee`) fits in a second: on the exact theory's
curves ``mu_s`` within 1% and the curve within 1.5% of ``mu N``; ``A`` and
``B`` apart are not determined as well (their product nearly is).  Without
the knee factor a fast method's knee error (up to 6% of ``mu N``) went
into the fitted law: ``mu_s`` 14% high under the exponential law.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np

from fastsim_ros.cli import options
from fastsim_ros.cli.patch import check_exact_grid, check_plausible_area, force_area
from fastsim_ros.cli.patch_files import csv_rows, number, text_lines
from fastsim_ros.contact.checks import BOUNDS
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.errors import UsageError

#: the most samples a measured file may hold
MAX_SAMPLES = 100_000
#: the solvers the fit may use (compiled batches: one call per model evaluation)
#: the most model evaluations of a fit; of the exact model's exponential fit, that starts
#: from the fast model's: least-squares steps (each takes 1 + 3 batches, the 3 its
#: finite differences; a batch of 30 samples 1-3 s at 60 x 60 cells)
MAX_EVALUATIONS = 200
MAX_EXACT_EXPONENTIAL_EVALUATIONS = 3
METHODS = ("exact", "mae_calibrated", "mae", "fastsim_ellipse", "polach")
#: the most samples ``--method exact`` takes (about 10 ms a solve at 20 x 20 cells, a few
#: dozen evaluations of the curve)
MAX_EXACT_SAMPLES = 200
HEADERS = (["xi", "eta", "phi", "Fx"], ["xi", "eta", "phi", "Fx", "Fy"])


def add_parser(sub: Any, finite: Any) -> None:
    """Add ``estimate`` to the subcommands of ``fastsim_contact``."""
    p = sub.add_parser("estimate", help="fit the friction law to measured creep forces")
    options.add_area(p, forces=True)
    p.add_argument("--measured", type=Path, required=True,
                   help="CSV with header xi,eta,phi,Fx[,Fy] (1, 1, 1/m, N, N)")
    p.add_argument("--friction-law", choices=("constant", "exponential"), default="constant",
                   help="constant (fit mu_s) or exponential (fit mu_s, A, B of mu(v) = "
                   "mu_s ((1 - A) exp(-B v) + A))")
    p.add_argument("--mu", type=finite, default=options.node_default("friction_coefficient"),
                   help="starting mu_s (default %(default)g, the node's friction_coefficient)")
    # the fit's starting point of A and B, not the node's (A = 1 would leave B unseen)
    p.add_argument("--friction-limit-ratio", type=finite, default=0.5, metavar="A",
                   help="starting A of the exponential law (default %(default)g)")
    p.add_argument("--friction-decay", type=finite, default=1.0, metavar="B",
                   help="starting B (s/m) of the exponential law (default %(default)g)")
    p.add_argument("--speed", type=finite, metavar="V",
                   help="rolling speed V (m/s; its magnitude is used), for the exponential law")
    p.add_argument("--load", type=finite, help="normal load N (N)")
    options.add_slope_reduction(p, finite)
    p.add_argument("--fit-slope-reduction", action="store_true",
                   help="fit the slope reduction k0, alpha_inf, beta with the law (from "
                   "--slope-*, or from 0.8, 0.5, 1 when those are no reduction; a fast "
                   "method): a contaminated rail's reduced slope")
    options.add_material(p, finite)
    p.add_argument("--method", choices=METHODS, default="exact",
                   help="the measurement model: exact (default: Kalker's exact theory, the "
                   "reference, as for coefficients; seconds to a minute), mae_calibrated "
                   "(the node's method times the knee factor, the node's estimator's "
                   "model; fast), mae or fastsim_ellipse (times the knee factor too), or "
                   "polach (Polach's closed form, kA = kS = 1)")
    p.add_argument("--bound", choices=BOUNDS, default=options.node_default("traction_bound"),
                   help="traction bound: mu p as given, or parabolic; default %(default)s, "
                   "the node's")
    options.add_allow_implausible(p)


def read_measured(path: Path, *,
                  allow_implausible: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Read the measured samples: ``(n, 3)`` creepages and ``(n, 1 or 2)`` forces (N).

    Refused (:class:`InvalidInputError`, one line naming the file and the
    line): what :func:`fastsim_ros.cli.patch_files.read_patch` refuses of a text file,
    a header other than :data:`HEADERS`, a row of the wrong length, a value
    that is not a finite number, a creepage beyond the command line's limits,
    more than :data:`MAX_SAMPLES` rows, no row; and, unless
    ``allow_implausible``, a creepage implausible for wheel-rail contact
    (:mod:`fastsim_ros.ros.plausibility`: a percentage typed as a fraction).
    """
    rows = csv_rows(path, text_lines(path, "measured file"))
    first = next(rows, None)
    if first is None:
        raise InvalidInputError(f"{path}: empty (no header xi,eta,phi,Fx[,Fy])")
    header = [c.strip() for c in first[1]]
    if header not in HEADERS:
        shown = ",".join(first[1])[:40]
        raise InvalidInputError(f"{path}, line {first[0]}: the header must be xi,eta,phi,Fx "
                                f"or xi,eta,phi,Fx,Fy, not {shown!r}")
    width = len(header)
    values: list[list[float]] = []
    creep_max, spin_max = options.LIMITS["creepage"][1], options.LIMITS["spin"][1]
    for line, fields in rows:
        if len(fields) != width:
            raise InvalidInputError(f"{path}, line {line}: {len(fields)} values where "
                                    f"{','.join(header)} needs {width}")
        row = [number(path, line, name, text) for name, text in zip(header, fields)]
        if max(abs(row[0]), abs(row[1])) > creep_max or abs(row[2]) > spin_max:
            raise InvalidInputError(f"{path}, line {line}: creepages beyond the command line's "
                                    f"limits (|xi|, |eta| <= {creep_max:g}, |phi| <= "
                                    f"{spin_max:g} 1/m)")
        if max(abs(v) for v in row[3:]) > 1e12:
            raise InvalidInputError(f"{path}, line {line}: a force beyond 1e12 N")
        options.check_plausible_creepages(row[0], row[1], row[2], allow=allow_implausible,
                                          where=f"{path}, line {line}: ")
        values.append(row)
        if len(values) > MAX_SAMPLES:
            raise InvalidInputError(f"{path}: more than {MAX_SAMPLES:,} samples")
    if not values:
        raise InvalidInputError(f"{path}: no samples")
    data = np.array(values)
    return np.ascontiguousarray(data[:, :3]), np.ascontiguousarray(data[:, 3:])


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Run ``estimate``: a dict of the results."""
    from fastsim_ros.estimation.fit import MU_RANGE, fit_friction
    from fastsim_ros.estimation.model import solver_for

    options.check_material_flags(args.nu, args.shear_modulus)
    options.in_range("--mu", args.mu, "mu", open_low=True)
    options.check_plausible_material(args)
    if args.load is not None and not args.load > 0.0:
        raise InvalidInputError(f"--load must be positive, got {args.load:g}")
    exponential = args.friction_law == "exponential"
    if exponential:
        if args.speed is None:
            raise UsageError("--friction-law exponential requires --speed")
        options.check_speed(args.speed)
        if not 0.0 < args.friction_limit_ratio <= 1.0:
            raise InvalidInputError("--friction-limit-ratio must lie in (0, 1], got "
                                    f"{args.friction_limit_ratio:g}")
        if not 0.0 <= args.friction_decay <= 1e4:
            raise InvalidInputError("--friction-decay must lie in [0, 1e4] s/m, got "
                                    f"{args.friction_decay:g}")
    reduction = options.slope_reduction(args)
    if (reduction is not None or args.fit_slope_reduction) and args.method == "exact":
        raise UsageError("--method exact is Kalker's exact theory, its slope in full: "
                         "the --slope-* reduction needs a fast method")
    creepages, measured = read_measured(args.measured,
                                        allow_implausible=args.allow_implausible)
    patch = force_area(args)
    check_plausible_area(args, patch)   # before any solve
    solver: Any
    if args.method == "exact":
        from fastsim_ros.estimation.model import ExactSolver
        if args.bound != "given":
            raise UsageError("--method exact (the default) takes the pressure as given "
                             "(--bound given); --bound parabolic needs a fast method")
        if creepages.shape[0] > MAX_EXACT_SAMPLES:
            raise InvalidInputError(f"--method exact (the default) takes at most "
                                    f"{MAX_EXACT_SAMPLES} samples, got {creepages.shape[0]}: "
                                    "give fewer, or --method mae_calibrated")
        check_exact_grid(patch, forces=True,
                         command="estimate's exact model (the default)")
        solver = ExactSolver(args.nu, args.shear_modulus)
    else:
        solver = solver_for(args.method, args.nu, args.shear_modulus)
    correction, note = model_correction(args.method, args.bound, solver)
    if reduction is not None or args.fit_slope_reduction:
        correction, note = "none", (f"{args.method} under the slope reduction (the modified "
                                    "FastSim of Spiryagin et al.), uncorrected")
    # a fast method as the node's estimator takes it: times the knee factor
    start = (args.mu, args.friction_limit_ratio, args.friction_decay)
    evaluations = MAX_EVALUATIONS
    if args.method == "exact" and exponential:
        # the exact model costs seconds a batch: the fast model (the node's, the calibrated
        # MAE times the knee factor) finds the law's valley, the exact one finishes from
        # there in a few evaluations
        seed = fit_friction(solver_for("mae_calibrated", args.nu, args.shear_modulus),
                            patch, creepages, measured, law="exponential", speed=args.speed,
                            bound=args.bound, mu0=args.mu,
                            limit_ratio0=args.friction_limit_ratio,
                            decay0=args.friction_decay, knee=True)
        start = (seed.mu_s, min(seed.limit_ratio, 0.999), seed.decay)
        evaluations = MAX_EXACT_EXPONENTIAL_EVALUATIONS
    fit = fit_friction(solver, patch, creepages, measured, law=args.friction_law,
                       speed=args.speed, bound=args.bound, mu0=start[0],
                       limit_ratio0=start[1], decay0=start[2],
                       knee=args.method != "exact", reduction=reduction,
                       max_evaluations=evaluations, fit_reduction=args.fit_slope_reduction)

    def finite_or_none(v: float) -> float | None:
        return v if math.isfinite(v) else None

    if not math.isfinite(fit.sigmas["mu_s"]):
        # the fit's mu_s would be its starting value (--mu): not an answer
        raise InvalidInputError(
            f"{args.measured}: the samples do not determine mu_s (their forces do not depend "
            "on it: the linear range, full adhesion, or no force); give samples nearer "
            "saturation")
    if any(abs(fit.mu_s - b) <= 1e-6 * b for b in MU_RANGE):
        raise InvalidInputError(
            f"{args.measured}: no friction coefficient in [{MU_RANGE[0]:g}, {MU_RANGE[1]:g}] "
            f"fits the samples (best {fit.mu_s:.4g}, worst error "
            f"{fit.worst_error_percent:.3g}% of mu N): are the forces' sign (opposing the "
            "creepage), units (N) and --load those of the patch?")

    def determined(name: str, value: float) -> float | None:
        # an undetermined parameter stays at its starting value: not an answer either
        return value if math.isfinite(fit.sigmas[name]) else None

    result: dict[str, Any] = {
        "mu_static": fit.mu_s, "friction_law": fit.law, "method": args.method,
        "model_correction": correction, "model_correction_note": note,
        "N": fit.load, "samples": int(creepages.shape[0]),
        "components": ["Fx", "Fy"][:measured.shape[1]],
        "sigma_mu_static": finite_or_none(fit.sigmas["mu_s"]),
        "worst_error_percent_mu_N": fit.worst_error_percent,
        "rms_error_percent_mu_N": fit.rms_error_percent, "evaluations": fit.evaluations}
    if args.fit_slope_reduction and fit.reduction is not None:
        r = fit.reduction
        result.update(slope_reduction={
            "k0": determined("slope_k0", r.k0),
            "alpha_inf": determined("slope_alpha_inf", r.alpha_inf),
            "beta": determined("slope_beta", r.beta),
            "sigma_k0": finite_or_none(fit.sigmas["slope_k0"]),
            "sigma_alpha_inf": finite_or_none(fit.sigmas["slope_alpha_inf"]),
            "sigma_beta": finite_or_none(fit.sigmas["slope_beta"]), "fitted": True})
    elif reduction is not None:
        result.update(slope_reduction={"k0": reduction.k0, "alpha_inf": reduction.alpha_inf,
                                       "beta": reduction.beta})
    if exponential:
        result.update(friction_limit_ratio=determined("limit_ratio", fit.limit_ratio),
                      friction_decay=determined("decay", fit.decay),
                      sigma_friction_limit_ratio=finite_or_none(fit.sigmas["limit_ratio"]),
                      sigma_friction_decay=finite_or_none(fit.sigmas["decay"]),
                      speed=abs(args.speed))
    options.check_finite_result(result, ("mu_static", "worst_error_percent_mu_N",
                                "rms_error_percent_mu_N"))
    return result


def model_correction(method: str, bound: str, solver: Any) -> tuple[str, str]:
    """Return the correction the fit's model applies to the method's force, and why, in words.

    ``("knee_strips", ...)`` for the calibrated MAE under the given bound
    (its own strip-by-strip knee factors: the published forces),
    ``("knee_factor", ...)`` for another fast method under the given bound (the
    node's estimator's model, :class:`~fastsim_ros.estimation.model.CreepModel`),
    ``("none", ...)`` otherwise: a fitted ``mu_s`` differs from the one that
    made forces with the method alone by the knee factor's share.
    """
    if method == "exact":
        return "none", "the exact theory's forces, uncorrected"
    if bound == "given" and getattr(solver, "knee", False):
        return "knee_strips", (
            f"{method}'s forces as the node publishes them: FastSim's knee corrected strip by "
            "strip with the knee factors of fastsim_ros/contact/knee.py; no factor added")
    from fastsim_ros.estimation.model import CreepModel
    if not CreepModel(solver, bound=bound).knee_corrected:
        return "none", (f"{method}'s forces, uncorrected (the knee factor is tabulated for "
                        "--bound given only)")
    return "knee_factor", (
        f"{method}'s force times the knee factor (fastsim_ros/contact/knee.py): "
        "|F_exact| / |F_FastSim| at the same normalised creepage, as the node's estimator; "
        f"forces {method} made alone are fitted with a mu_s a few per cent off (the knee "
        "error, up to 6% of mu N)")


def print_table(result: dict[str, Any]) -> None:
    """Print the fit readably."""
    def pm(v: float | None, s: float | None) -> str:
        if v is None:
            return "undetermined by the samples"
        return f"{v:.5g} +- {s:.2g}" if s is not None else f"{v:.5g} (undetermined)"

    print(f"method {result['method']}, friction {result['friction_law']}, N = "
          f"{result['N']:.6g} N, {result['samples']} samples of "
          f"{', '.join(result['components'])}")
    print(f"  mu_s = {pm(result['mu_static'], result['sigma_mu_static'])}")
    print(f"  model correction: {result['model_correction']}: "
          f"{result['model_correction_note']}")
    if result["friction_law"] == "exponential":
        print(f"  A = {pm(result['friction_limit_ratio'], result['sigma_friction_limit_ratio'])}")
        unit = " s/m" if result["friction_decay"] is not None else ""
        print(f"  B = {pm(result['friction_decay'], result['sigma_friction_decay'])}{unit}")
    red = result.get("slope_reduction")
    if red is not None and red.get("fitted"):
        for key in ("k0", "alpha_inf", "beta"):
            print(f"  slope reduction {key} = {pm(red[key], red['sigma_' + key])}")
    elif red is not None:
        print(f"  slope reduction (given): k0 {red['k0']:g}, alpha_inf {red['alpha_inf']:g}, "
              f"beta {red['beta']:g}")
    print(f"  fitted curve: worst error {result['worst_error_percent_mu_N']:.3g}% of mu N, "
          f"rms {result['rms_error_percent_mu_N']:.3g}%")
