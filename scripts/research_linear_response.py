#!/usr/bin/env python3
"""Research: the calibrated MAE with its linear response made the exact theory's.

A prototype, not the package's method.  The default method
(:class:`fastsim_ros.contact.compiled.CalibratedMaeSolver`) gives each strip
the flexibilities ``L1 .. L4`` of its zone (``flex``, ``(4, ny)``, from
:func:`fastsim_ros.contact.kernels.mae_setup`).  In full adhesion FastSim's
force is linear in ``1/L``::

    dFx/dxi  = s1 P1                    dFy/deta = s2 P2
    dFx/dphi = s1 P1 (yp - y_s) + s4 P4  dFy/dphi = s2 P2 (x_c - xp) + s3 P3

``P1 .. P4`` the march's partial responses at the sweep point ``S = (x_c,
y_s)`` (``P4``: ``Fx`` per unit spin from the ``L4`` term, ``P3``: ``Fy``
per unit spin from the ``L3`` term), ``s_k`` a factor on every strip's
``1/L_k``.  The factors are chosen so that these four equal the exact
theory's (:func:`fastsim_ros.contact.exact.full_adhesion` at unit creepages
on the patch's own grid, about the same reference), then the method's own
march (:func:`fastsim_ros.contact.kernels.mae_sweep`) runs with the scaled
``flex``: the rigid-slip return and the strip knee factors (each strip at
``s_j = |F_lin,j| / (mu N_j)``, ``F_lin,j`` from the same scaled march)
follow the scaled stiffness.  ``xi``-``eta`` couplings (``C12``, ``C21``)
are not reachable by FastSim and are reported, not fitted.

Variants: ``linear`` (all four factors), ``translation`` (``s1``, ``s2``
only), ``no_coupling`` (``s1 .. s3``, ``L4`` as the method has it).

Cases: the tread patches of ``scripts/validate_accuracy.py`` near zero
shift (both wheels, three creepage levels), the flange root and take-over,
the spin cases, ``scripts/validate_wider.py``'s curves on a few areas, and
Hertzian ellipses (the factors' distance from 1).  Errors: the larger of
``|Fx - Fx_exact|``, ``|Fy - Fy_exact|`` in % of ``mu N`` against
:func:`fastsim_ros.contact.exact.coulomb` on the same grid.  Then the cost
of the exact linear response per patch and of cheaper estimates of it.

Findings (the run's tables, 2 cores shared): the exact stiffness fixes the
linear range of the long narrow tread patch (right wheel, -0.414 mm: 4.2% of
mu N at xi 1e-4 with the pose's spin, 0.8% scaled) but the strip knee
factors then overshoot at the knee (-0.52% to -2.7% at xi 1e-3; the wheelset's
knee level 1.9% to 3.9%): the exact theory's excess stiffness of that patch
is lost as the slip area spreads, the ellipses' knee table has none.  The
``L4`` factor is ill-conditioned (``P4`` a difference of the zones' terms:
4.5 on the take-over, whose error goes from 4.2% to 35%).  On a Hertzian
ellipse the factors are the exact solver's own grid error (``C_grid /
C_extrapolated`` to 0.003): the scaling moves an ellipse off Kalker's.
The exact linear response costs 40-290 ms a patch (three GMRES solves).

Usage: ``python scripts/research_linear_response.py
[--part all|wheelset|wider|ellipses|curve|a22|cost]``.  About 2 minutes.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from fastsim_ros.contact import area as areas  # noqa: E402
from fastsim_ros.contact import exact, samples  # noqa: E402
from fastsim_ros.contact import kernels as k  # noqa: E402
from fastsim_ros.contact.area import GridArea  # noqa: E402
from fastsim_ros.contact.compiled import CalibratedMaeSolver  # noqa: E402

import validate_accuracy as va  # noqa: E402  (the wheelset's patches and spin cases)

MU, NU, G = va.MU, va.NU, va.G
VARIANTS = ("default", "linear", "translation", "no_coupling", "faded_linear",
            "faded_translation")
_NO_FLOAT = np.empty((0, 0))
_NO_BOOL = np.empty((0, 0), dtype=np.bool_)
_NO_PARAMS = np.zeros(2)
#: a relative size of P4 below which the L4 term is left as it is (nothing to scale)
TINY = 1e-6


def exact_linear(area: GridArea, *, rtol: float = 1e-10, g: float = G,
                 reference: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """Return the exact ``3 x 3`` response: rows ``Fx, Fy, Mz``, columns ``xi, eta, phi``."""
    op = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=g)
    out = np.zeros((3, 3))
    for j, c in enumerate(((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))):
        s = exact.full_adhesion(area, *c, nu=NU, shear_modulus=g, reference=reference,
                                rtol=rtol, operator=op)
        out[:, j] = (s.fx, s.fy, s.mz)
    return out


def coarse(area: GridArea) -> GridArea:
    """Return the area on cells twice as large (pressure: the mean of each 2 x 2 block)."""
    p = area.pressure
    ny, nx = p.shape
    q = np.zeros((ny + ny % 2, nx + nx % 2))
    q[:ny, :nx] = p
    q = q.reshape(q.shape[0] // 2, 2, q.shape[1] // 2, 2).mean(axis=(1, 3))
    return GridArea(area.x0 + area.dx / 2, area.y0 + area.dy / 2, 2 * area.dx, 2 * area.dy, q)


def coarse_linear(area: GridArea) -> np.ndarray:
    """Return :func:`exact_linear` from the coarse grid, rescaled to the fine grid's area.

    Normalised coefficients carry over (the exact solver's ``C~`` are
    normalised with the discrete area): ``xi``, ``eta`` columns times
    ``A/A_c``, the spin column times ``(A/A_c)^1.5``.
    """
    c = coarse(area)
    r = area.area / c.area
    m = exact_linear(c)
    m[:, :2] *= r
    m[:, 2] *= r**1.5
    return m


class Prototype:
    """The calibrated MAE's march with each strip's ``1/L_k`` times a factor ``s_k``."""

    def __init__(self, g: float = G) -> None:
        self.g = g
        self.solver = CalibratedMaeSolver(NU, g)

    def setup(self, area: GridArea) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        s = self.solver
        p = np.ascontiguousarray(area.pressure)
        p.setflags(write=False)
        status, info, geo, env, flex, bound = k.mae_setup(
            p, area.x0, area.y0, area.dx, area.dy, 0.0, 0.0, 0.0, MU, 0.0, 0.0, s._rule, False,
            self.g, s._knots, s._polys, True, s._pair_knots, s._pair_values)
        if status != k.OK:
            raise RuntimeError(f"mae_setup status {status} ({info})")
        return p, geo, env, flex

    def sweep(self, area: GridArea, prep: tuple[Any, ...], flex: np.ndarray, xi: float,
              eta: float, phi: float, mu: float, *, knee: bool = True,
              reference: tuple[float, float] = (0.0, 0.0)) -> tuple[float, float, float]:
        fx, fy, mz, _ = self.sweep_slip(area, prep, flex, xi, eta, phi, mu, knee=knee,
                                        reference=reference)
        return fx, fy, mz

    def sweep_slip(self, area: GridArea, prep: tuple[Any, ...], flex: np.ndarray, xi: float,
                   eta: float, phi: float, mu: float, *, knee: bool = True,
                   reference: tuple[float, float] = (0.0, 0.0)
                   ) -> tuple[float, float, float, float]:
        """Return ``Fx, Fy, Mz`` and the share of the cells in contact that slip."""
        p, geo, env, _ = prep
        fx, fy, mz, nslip, ncontact = k.mae_sweep(
            p, mu, False, _NO_FLOAT, env, area.x0, area.y0, area.dx, area.dy, geo, flex, xi,
            eta, phi, reference[0], reference[1], k.LAW_CONSTANT, _NO_PARAMS, 0.0, _NO_FLOAT,
            _NO_FLOAT, _NO_BOOL, False, True, self.solver._knee if knee else k.NO_KNEE)
        return fx, fy, mz, nslip / ncontact

    def force(self, area: GridArea, prep: tuple[Any, ...], target: np.ndarray, variant: str,
              creep: tuple[float, float, float], mu: float,
              knee: bool = True) -> tuple[float, float, float]:
        """Return the variant's ``Fx, Fy, Mz``.

        ``faded_*``: the factors ``1 + (s - 1) a``, ``a`` the share of the
        cells in adhesion in the method's own (unscaled) march at these
        creepages: the exact stiffness in adhesion, the method's as the slip
        area spreads.
        """
        base = variant.removeprefix("faded_")
        s = self.factors(area, prep, target, base)
        if variant.startswith("faded_"):
            slipping = self.sweep_slip(area, prep, prep[3], *creep, mu, knee=knee)[3]
            s = 1.0 + (s - 1.0) * (1.0 - slipping)
        return self.sweep(area, prep, self.scaled(prep[3], s), *creep, mu, knee=knee)

    def partials(self, area: GridArea, prep: tuple[Any, ...]) -> tuple[float, ...]:
        """Return ``P1 .. P4`` (N per unit creepage, N m per unit spin) at ``S``."""
        geo = prep[1]
        s = (geo[k.G_XC], geo[k.G_YS])
        big = 1e20
        p1 = self.sweep(area, prep, prep[3], 1e-6, 0.0, 0.0, big, knee=False, reference=s)[0]
        p2 = self.sweep(area, prep, prep[3], 0.0, 1e-6, 0.0, big, knee=False, reference=s)[1]
        fx, fy, _ = self.sweep(area, prep, prep[3], 0.0, 0.0, 1e-5, big, knee=False,
                               reference=s)
        return p1 / 1e-6, p2 / 1e-6, fy / 1e-5, fx / 1e-5

    def factors(self, area: GridArea, prep: tuple[Any, ...], target: np.ndarray,
                variant: str) -> np.ndarray:
        """Return ``s1 .. s4`` making the march's linear response ``target``'s (about 0, 0)."""
        if variant == "default":
            return np.ones(4)
        geo = prep[1]
        p1, p2, p3, p4 = self.partials(area, prep)
        x_c, y_s = geo[k.G_XC], geo[k.G_YS]
        s1 = target[0, 0] / p1
        s2 = target[1, 1] / p2
        if variant == "translation":
            return np.array([s1, s2, 1.0, 1.0])
        # about the reference (0, 0): xi_s = xi - phi y_s, eta_s = eta + phi x_c
        s3 = (target[1, 2] - s2 * p2 * x_c) / p3
        if variant == "no_coupling":
            return np.array([s1, s2, s3, 1.0])
        need = target[0, 2] + s1 * p1 * y_s
        scale = abs(target[0, 0]) * math.sqrt(area.area)
        s4 = need / p4 if abs(p4) > TINY * scale else 1.0
        return np.array([s1, s2, s3, s4])

    def scaled(self, flex: np.ndarray, s: np.ndarray) -> np.ndarray:
        out = flex.copy()
        for kk in range(4):
            out[kk] = flex[kk] / s[kk]
        return out


def wheelset_cases() -> list[tuple[str, GridArea, tuple[float, float, float], float]]:
    """Return (label, area, creepages, load) of the wheelset's cases."""
    out = []
    for title, xi in va.LEVELS:
        short = title.split(",")[0]
        for dy in (-0.404e-3, -0.414e-3, -0.440e-3, -0.476e-3, -0.496e-3):
            for wheel, (area, creep, n) in va.patches(dy, va.axle_spin(xi)).items():
                out.append((f"tread {short} ({wheel}, {1e3 * dy:+.3f} mm)", area, creep, n))
    for dy in (-4.0e-3, -4.9e-3, -4.95e-3, -5.0e-3):
        for wheel, (area, creep, n) in va.patches(dy, va.SPEED / va.RADIUS).items():
            out.append((f"flange rolling ({wheel}, {1e3 * dy:+.3f} mm)", area, creep, n))
    for wheel in ("right", "left"):
        area, _, n = va.patches(-0.476e-3, va.axle_spin(None))[wheel]
        for creep in ((0.0, 0.0, 0.5), (0.0, 0.0, 2.0), (1e-3, 0.0, 0.5), (1e-3, 0.0, 2.0),
                      (0.0, 1e-3, 0.5), (0.0, 1e-3, 2.0)):
            out.append((f"spin {creep[0]:g}, {creep[1]:g}, {creep[2]:g} ({wheel}, -0.476 mm)",
                        area, creep, n))
    return out


def error(f: tuple[float, float], e: tuple[float, float], n: float) -> float:
    return 100.0 * max(abs(f[0] - e[0]), abs(f[1] - e[1])) / (MU * n)


def part_wheelset(proto: Prototype) -> None:
    print("## Wheelset patches: error, % of mu N (exact.coulomb, same grid)\n")
    print("| case | s1 | s2 | s3 | s4 | " + " | ".join(VARIANTS) + " |")
    print("| --- | --- | --- | --- | --- | " + " | ".join("---" for _ in VARIANTS) + " |")
    cache: dict[int, Any] = {}
    worst: dict[str, dict[str, float]] = {}
    for label, area, creep, n in wheelset_cases():
        key = hash(area.pressure.tobytes()) ^ hash((area.x0, area.y0, area.dx, area.dy))
        if key not in cache:
            prep = proto.setup(area)
            target = exact_linear(area)
            cache[key] = (prep, target, {"linear": proto.factors(area, prep, target[:2],
                                                                 "linear")})
        prep, target, facs = cache[key]
        ex = exact.coulomb(area, *creep, mu=MU, nu=NU, shear_modulus=G)
        ref = proto.solver.solve(area, *creep, mu=MU)
        errs = []
        for v in VARIANTS:
            fx, fy, _ = proto.force(area, prep, target[:2], v, creep, MU)
            if v == "default":
                assert abs(fx - ref.fx) + abs(fy - ref.fy) < 1e-6 * MU * n, "not the default"
            errs.append(error((fx, fy), (ex.fx, ex.fy), n))
        group = label.split(" (")[0]
        g = worst.setdefault(group, {v: 0.0 for v in VARIANTS})
        for v, e in zip(VARIANTS, errs):
            g[v] = max(g[v], e)
        s = facs["linear"]
        print(f"| {label} | {s[0]:.3f} | {s[1]:.3f} | {s[2]:.3f} | {s[3]:.3f} | "
              + " | ".join(f"{e:.2f}" for e in errs) + " |", flush=True)
    print("\n### Worst per group\n")
    print("| group | " + " | ".join(VARIANTS) + " |")
    print("| --- | " + " | ".join("---" for _ in VARIANTS) + " |")
    for group, g in worst.items():
        print(f"| {group} | " + " | ".join(f"{g[v]:.2f}" for v in VARIANTS) + " |")
    c12 = max(abs(t[0, 1] / t[0, 0]) for _, t, _ in cache.values())
    c21 = max(abs(t[1, 0] / t[1, 1]) for _, t, _ in cache.values())
    print(f"\nCouplings the march cannot carry (exact, largest over the {len(cache)} patches): "
          f"|dFx/deta| / |dFx/dxi| {c12:.4f}, |dFy/dxi| / |dFy/deta| {c21:.4f}")


WIDER_CELLS = 40
WIDER_LEVELS = (0.05, 0.15, 0.3, 0.5, 0.8, 1.2, 2.0, 3.5)
WIDER_CURVES = {"xi": (1.0, 0.0, 0.0), "eta": (0.0, 1.0, 0.0), "phi": (0.0, 0.0, 1.0),
                "combined": (0.5, 0.5, 0.5)}


def wider_makers() -> dict[str, Any]:
    scale, load = 0.01, 5.0e4
    a, b = areas.semi_ellipse_axes(2.0 / 3.0)
    out = {
        "ellipse 2/3 (Hertz)": lambda n: areas.ellipse(a * scale, b * scale, nx=n, ny=n,
                                                       load=load),
        "long narrow": lambda n: samples.long_narrow_patch(cells=n, scale=scale, load=load),
        "crescent": lambda n: samples.crescent_patch(cells=n, scale=scale, load=load),
        "egg": lambda n: samples.egg_patch(cells=n, scale=scale, load=load),
        "flange root": lambda n: samples.flange_root_patch(cells=n, load=load),
        "semi-ellipses 5/1": lambda n: samples.semi_ellipses_patch(5.0, 1.0, cells=n,
                                                                   scale=scale, load=load),
        "truncated ellipse": lambda n: samples.truncated_ellipse(cells=n, scale=scale,
                                                                 load=load),
        "crescent -1.5/0.35 (horns trailing)": lambda n: samples.crescent_patch(
            cells=n, scale=scale, load=load, bend=-1.5, a_over_b=0.35),
    }
    for u in (-4.0e-3, 1.5e-3, 4.5e-3):
        out[f"profile gap {1e3 * u:+.1f} mm"] = (
            lambda n, u=u: samples.profile_gap_patch(u, cells=n, load=load))
    return out


def saturation(ar: GridArea) -> tuple[float, float, float]:
    """validate_wider.py's creepages that would saturate the linear theory."""
    c = math.sqrt(ar.area / math.pi)
    return (MU * ar.load / (G * c**2 * 4.5), MU * ar.load / (G * c**2 * 4.0),
            MU * ar.load / (G * c**3 * 1.5))


def part_wider(proto: Prototype) -> None:
    print("\n## validate_wider.py areas (40 cells): worst curve error, % of mu N "
          "(points with |F_exact| > 5% mu N, as that script)\n")
    print("| area | s1 | s2 | s3 | s4 | " + " | ".join(
        f"{v}: worst (curve)" for v in VARIANTS) + " |")
    print("| --- | --- | --- | --- | --- | " + " | ".join("---" for _ in VARIANTS) + " |")
    for name, make in wider_makers().items():
        ar = make(WIDER_CELLS)
        op = exact.SteadyRollingOperator.of(ar, nu=NU, shear_modulus=G)
        prep = proto.setup(ar)
        target = exact_linear(ar)
        facs = {"linear": proto.factors(ar, prep, target[:2], "linear")}
        sat = saturation(ar)
        mun = MU * ar.load
        worst = {v: (0.0, "") for v in VARIANTS}
        for curve, direction in WIDER_CURVES.items():
            for lev in WIDER_LEVELS:
                cr = tuple(lev * d * s for d, s in zip(direction, sat))
                ex = exact.coulomb(ar, *cr, mu=MU, nu=NU, shear_modulus=G, operator=op)
                for v in VARIANTS:
                    fx, fy, _ = proto.force(ar, prep, target[:2], v, cr, MU)
                    e = 0.0
                    for fm, fe in ((fx, ex.fx), (fy, ex.fy)):
                        if abs(fe) > 0.05 * mun:
                            e = max(e, 100.0 * abs(fm - fe) / mun)
                    if e > worst[v][0]:
                        worst[v] = (e, f"{curve} {lev:g}")
        s = facs["linear"]
        print(f"| {name} | {s[0]:.3f} | {s[1]:.3f} | {s[2]:.3f} | {s[3]:.3f} | "
              + " | ".join(f"{worst[v][0]:.2f} ({worst[v][1]})" for v in VARIANTS) + " |",
              flush=True)


def part_ellipses(proto: Prototype) -> None:
    print("\n## Hertzian ellipses: the factors (1 = unchanged) on the grid, and against "
          "Kalker's extrapolated coefficients\n")
    print("| a/b | cells | s1 | s2 | s3 | s4 | exact on the grid / extrapolated: C11, C22, C23 |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for g in (0.3, 1.0, 2.0 / 3.0, 3.0):
        a, b = areas.semi_ellipse_axes(g)
        for n in (20, 40):
            ar = areas.ellipse(a * 0.01, b * 0.01, nx=n, ny=n, load=5.0e4)
            prep = proto.setup(ar)
            target = exact_linear(ar)
            s = proto.factors(ar, prep, target[:2], "linear")
            grid = exact.creep_coefficients(ar, nu=NU)
            ext = exact.extrapolated_coefficients("ellipse", (g,), nu=NU, finest=60)
            print(f"| {g:.3g} | {n} | {s[0]:.3f} | {s[1]:.3f} | {s[2]:.3f} | {s[3]:.3f} | "
                  f"{grid.C11 / ext.C11:.3f}, {grid.C22 / ext.C22:.3f}, "
                  f"{grid.C23 / ext.C23:.3f} |", flush=True)


def part_curve(proto: Prototype) -> None:
    """Print the signed Fx, Fy errors along the creepage on the patches the fit fails on.

    The tread: ``xi`` alone varied (the pose's ``eta``, ``phi`` kept, as the
    axle spin of ``scripts/validate_accuracy.py`` does); the take-over: the
    pose's creepages times a factor.
    """
    curve_variants = VARIANTS
    print("\n## Along the curve: (F - F_exact) / (mu N), % (signed; x then y)\n")
    print("| patch | creepages | F_exact / (mu N) | " + " | ".join(curve_variants)
          + " | default, FastSim's knee | linear, FastSim's knee |")
    print("| --- | --- | --- | " + " | ".join("---" for _ in curve_variants) + " | --- | --- |")
    for label, dy, spin, wheel in (("tread", -0.414e-3, va.axle_spin(None), "right"),
                                   ("take-over", -4.95e-3, va.SPEED / va.RADIUS, "right")):
        area, creep, n = va.patches(dy, spin)[wheel]
        prep = proto.setup(area)
        target = exact_linear(area)
        mun = MU * n
        if label == "tread":
            points = [(x, creep[1], creep[2]) for x in
                      (1e-4, 2e-4, 3e-4, 4e-4, 6e-4, 8e-4, 1e-3, 1.5e-3, 2e-3, 3e-3, 5e-3, 1e-2)]
        else:
            points = [tuple(f * c for c in creep) for f in (0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 10.0)]
        for cr in points:
            ex = exact.coulomb(area, *cr, mu=MU, nu=NU, shear_modulus=G)
            cells = []
            for v, knee in [(v, True) for v in curve_variants] + [("default", False),
                                                                  ("linear", False)]:
                fx, fy, _ = proto.force(area, prep, target[:2], v, cr, MU, knee=knee)
                cells.append(f"{100 * (fx - ex.fx) / mun:+.2f}, {100 * (fy - ex.fy) / mun:+.2f}")
            print(f"| {label} ({wheel}, {1e3 * dy:+.3f} mm) | {cr[0]:.2e}, {cr[1]:.1e}, "
                  f"{cr[2]:.3f} | {ex.fx / mun:+.3f}, {ex.fy / mun:+.3f} | "
                  + " | ".join(cells) + " |", flush=True)


def part_a22() -> None:
    """Solve the Manchester A-2.2 poses of CONTACT (the package's patches, exact on them)."""
    import validate_profiles as vp  # A-2.2's poses as the wheelset command's
    from fastsim_ros.cli.wheelset import solve_pose
    from fastsim_ros.geometry import benchmark as bm
    proto = Prototype(bm.SHEAR_MODULUS)
    print("\n## Manchester A-2.2 poses (package's patches, 0.2 mm cells): error, % of mu N\n")
    print("| wheel, pose (dy mm, yaw mrad) | patch | s1 | s2 | s3 | s4 | "
          + " | ".join(VARIANTS) + " |")
    print("| --- | --- | --- | --- | --- | --- | " + " | ".join("---" for _ in VARIANTS) + " |")
    worst = {v: 0.0 for v in VARIANTS}
    for side in ("right", "left"):
        for case in bm.a22(side):
            cycle, _ = solve_pose(vp.pose_args(case, vp.DEFAULT), case.dy, case.yaw)
            for o in cycle.outcomes:
                if o.patch is None or o.creepage is None or o.forces is None:
                    continue
                if not o.contact.startswith(side):
                    continue
                pp = o.patch
                area = GridArea(pp.x0, pp.y0, pp.dx, pp.dy, np.array(pp.pressure))
                creep = (o.creepage.xi, o.creepage.eta, o.creepage.phi)
                n = o.forces.n
                prep = proto.setup(area)
                target = exact_linear(area, g=bm.SHEAR_MODULUS)
                ex = exact.coulomb(area, *creep, mu=bm.MU, nu=bm.POISSON,
                                   shear_modulus=bm.SHEAR_MODULUS)
                errs = []
                for v in VARIANTS:
                    fx, fy, _ = proto.force(area, prep, target[:2], v, creep, bm.MU)
                    errs.append(error((fx, fy), (ex.fx, ex.fy), n))
                    worst[v] = max(worst[v], errs[-1])
                s = proto.factors(area, prep, target[:2], "linear")
                print(f"| {side} {case.number} ({1e3 * case.dy:.1f}, {1e3 * case.yaw:.0f}) | "
                      f"{o.contact} | {s[0]:.3f} | {s[1]:.3f} | {s[2]:.3f} | {s[3]:.3f} | "
                      + " | ".join(f"{e:.2f}" for e in errs) + " |", flush=True)
    print("| worst | | | | | | " + " | ".join(f"{worst[v]:.2f}" for v in VARIANTS) + " |")


def dense_linear(area: GridArea) -> np.ndarray:
    """Return :func:`exact_linear`'s ``Fx, Fy`` rows by one dense LU and three right sides."""
    import scipy.linalg
    from fastsim_ros.contact.traction import resultants, rigid_slip
    op = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=G)
    mask = area.mask
    n = int(np.count_nonzero(mask))
    rhs = []
    for c in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)):
        wx, wy = rigid_slip(area, *c, (0.0, 0.0))
        rhs.append(np.concatenate([wx[mask], wy[mask]]))
    tau = scipy.linalg.lu_solve(scipy.linalg.lu_factor(op.dense()), np.array(rhs).T)
    out = np.zeros((2, 3))
    for j in range(3):
        tx = np.zeros(mask.shape)
        ty = np.zeros(mask.shape)
        tx[mask] = tau[:n, j]
        ty[mask] = tau[n:, j]
        out[:, j] = resultants(area, tx, ty, (0.0, 0.0))[:2]
    return out


def part_cost(proto: Prototype) -> None:
    print("\n## Cost of the exact linear response per patch (median of 3, one core)\n")
    print("| patch | cells in contact | operator build, ms | 3 solves rtol 1e-10, ms | "
          "3 solves rtol 1e-4, ms | worst factor change at 1e-4 | coarse grid (2x cells), "
          "ms | worst factor change coarse | dense LU, 3 right sides, ms | "
          "calibrated MAE solve, us |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    cases = []
    for dy, wheel in ((-0.414e-3, "right"), (-0.414e-3, "left"), (-4.95e-3, "right"),
                      (-4.0e-3, "right")):
        area, creep, _ = va.patches(dy, va.axle_spin(None))[wheel]
        cases.append((f"{wheel} {1e3 * dy:+.3f} mm", area, creep))
    for name in ("long narrow", "crescent"):
        ar = wider_makers()[name](40)
        cases.append((f"{name} (40 cells)", ar, (1e-4, 0.0, 0.0)))
    for label, area, creep in cases:
        t_op, t_fine, t_loose, t_coarse, t_dense = [], [], [], [], []
        for _ in range(3):
            t0 = time.perf_counter()
            op = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=G)
            t1 = time.perf_counter()
            for c in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)):
                exact.full_adhesion(area, *c, nu=NU, shear_modulus=G, operator=op)
            t_op.append(t1 - t0)
            t_fine.append(time.perf_counter() - t1)
            t0 = time.perf_counter()
            loose = exact_linear(area, rtol=1e-4)
            t_loose.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            rough = coarse_linear(area)
            t_coarse.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            dense_linear(area)
            t_dense.append(time.perf_counter() - t0)
        fine = exact_linear(area)
        prep = proto.setup(area)
        s_fine = proto.factors(area, prep, fine[:2], "linear")
        s_loose = proto.factors(area, prep, loose[:2], "linear")
        s_rough = proto.factors(area, prep, rough[:2], "linear")
        proto.solver.solve(area, *creep, mu=MU)
        t0 = time.perf_counter()
        for _ in range(200):
            proto.solver.solve(area, *creep, mu=MU)
        t_fast = (time.perf_counter() - t0) / 200
        print(f"| {label} | {int(np.count_nonzero(area.mask))} | "
              f"{1e3 * np.median(t_op):.1f} | {1e3 * np.median(t_fine):.1f} | "
              f"{1e3 * np.median(t_loose):.1f} | "
              f"{np.max(np.abs(s_loose / s_fine - 1)):.2e} | "
              f"{1e3 * np.median(t_coarse):.1f} | {np.max(np.abs(s_rough / s_fine - 1)):.3f} "
              f"(s {', '.join(f'{v:.3f}' for v in s_rough)} vs "
              f"{', '.join(f'{v:.3f}' for v in s_fine)}) | {1e3 * np.median(t_dense):.1f} | "
              f"{1e6 * t_fast:.0f} |", flush=True)


def run_parts(description: str, parts: dict[str, Callable[[], None]]) -> int:
    """Run the ``--part`` chosen (``all``: every part, in order); print the run's time."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--part", default="all", choices=("all", *parts))
    args = parser.parse_args()
    start = time.perf_counter()
    for name, part in parts.items():
        if args.part in ("all", name):
            part()
    print(f"\nThe run took {time.perf_counter() - start:.0f} s.")
    return 0


def main() -> int:
    proto = Prototype()
    return run_parts(__doc__.splitlines()[0], {
        "wheelset": lambda: part_wheelset(proto), "wider": lambda: part_wider(proto),
        "ellipses": lambda: part_ellipses(proto), "curve": lambda: part_curve(proto),
        "a22": part_a22, "cost": lambda: part_cost(proto)})


if __name__ == "__main__":
    sys.exit(main())
