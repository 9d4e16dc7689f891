#!/usr/bin/env python3
"""Research: knee factors that carry the patch's own stiffness ratio (exact / calibrated MAE).

A prototype, not the package's method.  The default method
(:class:`fastsim_ros.contact.compiled.CalibratedMaeSolver`) multiplies each
strip's force by the knee factor ``kappa(s_j)`` of its own share of the
saturation ``s_j = |F_lin,j| / (mu N_j)``
(:func:`fastsim_ros.contact.kernels.strip_knee`).  On long narrow patches
with a wide end its linear response is below the exact theory's
(:func:`fastsim_ros.contact.exact.full_adhesion`):
``r_x = (dFx/dxi)_exact / (dFx/dxi)_MAE`` up to 1.09 on the tread's right
patch and 1.34 on the flange take-over.  Scaling the flexibilities by ``r``
fixes the linear range and spoils the knee
(``scripts/research_linear_response.py``).  Tried here, with the exact
``r`` (an oracle: any cheap predictor can only do worse):

* ``knee r w(s0, p)``: strip ``j``'s ``Fx`` times ``kappa_j (1 + (r_x - 1)
  w(s_j))``, its ``Fy`` times ``kappa_j (1 + (r_y - 1) w(s_j))``, ``w(s) =
  max(0, 1 - s/s0)^p``: the excess stiffness fades strip by strip as the
  strip nears its saturation, capped at the strip's bound; ``full r``:
  ``w = 1``.  The suggested method: each strip's factor carries the
  patch's stiffness ratio and fades it with the slip.
* ``added w(s0, p)``: the whole linear error added and faded by the
  patch's share of the saturation: ``F + (J_exact - J_MAE) c w(s)``, ``J``
  the ``2 x 3`` linear responses (spin's couplings included), ``c`` the
  creepages, ``s = |J_MAE c| / (mu N)``: the most any linear correction
  that fades with ``s`` can do.
* ``spin lever``: the rigid slip's ``xi`` moved by ``phi dy_l``, ``dy_l =
  ((dFx/dphi)_exact - (dFx/dphi)_MAE) / (dFx/dxi)_MAE``: the exact
  spin-to-``Fx`` coupling through the slip itself.

Then a cheap predictor of ``r_x`` from the patch's strips (the chord
profile's ``m0 m2 / m1^2``, ``m_k = sum c^(k+1)``, of the whole patch and of
MAE's zones against a semi-ellipse's), fitted by least squares through the
origin and checked leaving one family of patches out.  And, since the two
worst cases turn out not to be errors of the linear response: the patch's
equivalent ellipse's exact / method ratio at the same creepages, spin
included (an oracle of a knee table with spin), and the default on
Hertzian ellipses under ``xi`` with spin.

Cases: ``scripts/validate_accuracy.py``'s wheelset (tread at five shifts
near zero, three creepage levels; flange root and take-over; the spin cases
on both wheels; the longitudinal curve of the right tread at -0.414 mm with
the pose's spin and the take-over's creepages scaled), ``scripts/
validate_wider.py``'s areas at 40 cells (their four curves), Hertzian
ellipses a/b 0.3, 1, 3.  Errors: the larger of ``|Fx - Fx_exact|``, ``|Fy -
Fy_exact|``, % of ``mu N``, against :func:`fastsim_ros.contact.exact.coulomb`
on the same grid.

Findings (the run's tables; ``r`` exact, so they bound what a predictor
can give):

* ``r`` is 0.95-1.02 on every patch but three families: the right tread
  near zero shift (``r_x`` 1.07-1.09, ``r_y`` 1.09-1.12), the right flange
  take-over (-4.90 to -5.00 mm: 1.21-1.34, 1.23-1.44) and the crescents
  (1.02-1.03, 1.04-1.06); Hertzian ellipses 1.006-1.010 (the exact
  solver's grid error).
* ``knee r``: no fade gets both levels near zero shift within 2%.  The
  right tread's linear range goes from 2.28% to 1.60% (``w(1.5, 1)``)
  while its knee goes from 1.91% to 3.13%; ``w(1, 1)``: 1.89% and 2.57%;
  the fades that keep the knee (``w(0.5, 1)``, ``w(0.75, 2)``) leave the
  linear range at 2.14-2.15%.  The take-over (4.15%) and ``xi 1e-3, phi
  0.5`` (4.59% right, 4.40% left) do not move: their strips are past ``s =
  1`` where ``w = 0``; ``full r`` leaves them at 3.88% and 8.57%.  The
  tread's curve at ``xi 1e-4`` with the pose's spin goes from 4.18% to
  4.4-4.9%: its error is the spin's coupling ``dFx/dphi`` (the exact one
  2.2 times the method's), not ``r``.  The wider areas' worst moves by
  at most 0.15 point with ``w(1, 1)`` and the gentler fades, by up to 0.46
  with ``w(1.5, 1)``.
* ``added w(1, 2)`` (every linear term exact, faded): the tread's curve at
  small ``xi`` from 4.18% to 1.91%, the linear range 2.00%, the knee 1.91%
  (unchanged), but the take-over (4.15%; its curve 6.22% at half the pose's
  creepages, slip share 0.84) and ``xi 1e-3, phi 0.5`` (4.59%) stay, and
  the crescent whose horns trail goes from 2.75% to 15.0% (its spin
  coupling added in full at small ``s``).
* ``spin lever``: the curve at ``xi 1e-4`` to 2.47%, the take-over at
  its pose to 2.69% (9.4% at a tenth of its creepages), but the spin
  cases of the right tread to 4.9-10.7% and the take-over in full slip to
  28%: moving the rigid slip turns the full-slip force.
* the predictor misses the held-out ``r_x - 1`` by up to 0.04-0.07 on the
  right tread (0.080-0.093 exact), 0.31-0.32 on the right flange patches and
  0.21-0.24 on the wider areas (the semi-ellipses 5/1: flat chords, ``r``
  1.006): the chord profile does not carry the stiffness ratio.
* ``xi`` with spin is FastSim's knee under spin, not the patch's shape: on
  Hertzian ellipses the default is within 0.5% without spin and up to 5.3%
  off with spin's part 0.3-0.6 of ``F_lin`` at ``s`` 1-2.5 (``Fx`` low,
  ``Fy`` right: a/b 1, part 0.6, ``s`` 1.5: ``Fx`` 0.442 against 0.495 ``mu
  N``); the tread patches' equivalent ellipses are 6.2-6.4% off at ``xi
  1e-3, phi 0.5``.  The equivalent ellipse's exact / method ratio brings the
  near-elliptical left tread patch there from 4.40% to 1.54% (every left
  case within 1.6%), but the long narrow right one goes from 4.59% to
  5.70%, its knee from 1.91% to 4.25%, the take-over from 4.15% to 4.53%.

So nothing here meets the target, and no variant was implemented (no cost
measured: the ``knee r`` form would add two products per strip and the
predictor's pass over the strips).  The remaining worst errors of the
default are partial slip under spin (the take-over 4.1%, ``xi 1e-3`` with
``phi 0.5`` 4.6%): a knee factor with spin (``Fx`` and ``Fy`` apart, the
spin's part of ``F_lin`` as a dimension) is the measured lead for the
second; the take-over (two lobes, ``r`` 1.26-1.34) is reached by none.

Usage: ``python scripts/research_stiffness_knee.py
[--part all|oracle|wider|predictor|ellipse|spin_knee]``.  About 2 minutes on one
core.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from fastsim_ros.contact import area as areas  # noqa: E402
from fastsim_ros.contact import exact  # noqa: E402
from fastsim_ros.contact import kernels as k  # noqa: E402
from fastsim_ros.contact.area import GridArea  # noqa: E402
from fastsim_ros.contact.mae import row_extents  # noqa: E402

import research_linear_response as rl  # noqa: E402  (the prototype march, the cases)
import validate_accuracy as va  # noqa: E402  (the wheelset's patches)

MU, NU, G = va.MU, va.NU, va.G
Fade = Callable[[float], float]
Case = tuple[str, GridArea, tuple[float, float, float], float]


def fade(s0: float, p: float) -> Fade:
    """Return ``w(s) = max(0, 1 - s/s0)^p``."""
    return lambda s: max(0.0, 1.0 - s / s0) ** p


#: the strip-knee variants: (fade of the stiffness ratio, or None for the default)
KNEE_VARIANTS: dict[str, Fade | None] = {"default": None}
for _s0, _p in ((0.5, 1), (0.75, 2), (1.0, 1), (1.0, 2), (1.0, 3), (1.5, 1), (1.5, 2)):
    KNEE_VARIANTS[f"knee r w({_s0:g}, {_p})"] = fade(_s0, _p)
KNEE_VARIANTS["full r"] = lambda s: 1.0
#: the added linear correction's fades of the patch's s
ADDED = {"added w(1, 1)": fade(1.0, 1), "added w(1, 2)": fade(1.0, 2),
         "added w(1, 3)": fade(1.0, 3)}
VARIANTS = list(KNEE_VARIANTS) + list(ADDED) + ["spin lever"]


class Patch:
    """One patch: the prototype's set-up, the exact and the method's linear responses."""

    def __init__(self, proto: rl.Prototype, area: GridArea) -> None:
        self.area = area
        self.prep = proto.setup(area)
        self.exact = rl.exact_linear(area)[:2]
        p1, p2, p3, p4 = proto.partials(area, self.prep)
        geo = self.prep[1]
        # the march's linear response about (0, 0): creepages moved to S = (x_c, y_s)
        self.mae = np.array([[p1, 0.0, -p1 * geo[k.G_YS] + p4],
                             [0.0, p2, p2 * geo[k.G_XC] + p3]])
        self.r = (self.exact[0, 0] / p1, self.exact[1, 1] / p2)
        self.lever = (self.exact[0, 2] - self.mae[0, 2]) / p1
        self.log_aspect = math.log(geo[k.G_ELLIPSE + 2] / geo[k.G_ELLIPSE + 3])

    def strip_sums(self, creep: tuple[float, float, float], mu: float = MU) -> np.ndarray:
        """Return the march's strip sums (:func:`kernels.rolling_sweep`'s rows)."""
        p, geo, env, flex = self.prep
        a = self.area
        xi_s, eta_s = k.creepages_at_s(geo, creep[0], creep[1], creep[2], 0.0, 0.0)
        sums = np.empty((k.STRIP_SUMS, p.shape[0]))
        k.sweep(p, mu, 1.0, env, a.x0, a.y0, a.dx, a.dy, xi_s, eta_s, creep[2], flex,
                geo[k.G_XC], geo[k.G_YS], 0.0, 0.0, k.LAW_CONSTANT, rl._NO_PARAMS, 0.0,
                rl._NO_FLOAT, rl._NO_FLOAT, rl._NO_BOOL, False, True, sums)
        return sums


def knee_force(patch: Patch, sums: np.ndarray, knee: tuple[Any, ...],
               w: Fade | None) -> tuple[float, float]:
    """Return ``Fx, Fy``: each strip's force times its knee factor and the faded ratio."""
    la, sn, kap = knee
    rx, ry = patch.r
    fx = fy = 0.0
    for j in range(sums.shape[1]):
        kj, _, sj = k.strip_factor(la, sn, kap, sums[3, j], sums[4, j], sums[5, j],
                                   patch.log_aspect)
        cx = cy = kj
        if sj > 0.0:
            if w is None:
                cx = cy = k.knee_capped(kj, sums[0, j], sums[1, j], sums[5, j])
            else:
                wj = w(sj)
                cx = kj * (1.0 + (rx - 1.0) * wj)
                cy = kj * (1.0 + (ry - 1.0) * wj)
                f2 = (cx * sums[0, j]) ** 2 + (cy * sums[1, j]) ** 2
                if (cx > 1.0 or cy > 1.0) and f2 > sums[5, j] ** 2:
                    c = sums[5, j] / math.sqrt(f2)  # a strip carries at most mu N_j
                    cx, cy = cx * c, cy * c
        fx += cx * sums[0, j]
        fy += cy * sums[1, j]
    da = patch.area.cell_area
    return fx * da, fy * da


def variant_forces(proto: rl.Prototype, patch: Patch, creep: tuple[float, float, float],
                   n: float) -> dict[str, tuple[float, float]]:
    """Return every variant's ``Fx, Fy`` (N) at the creepages."""
    knee = k.knee_arrays(proto.solver._knee)
    sums = patch.strip_sums(creep)
    out = {v: knee_force(patch, sums, knee, w) for v, w in KNEE_VARIANTS.items()}
    c = np.array(creep)
    s = float(np.hypot(*(patch.mae @ c))) / (MU * n)
    d = (patch.exact - patch.mae) @ c
    base = out["default"]
    for v, w in ADDED.items():
        out[v] = (base[0] + d[0] * w(s), base[1] + d[1] * w(s))
    moved = (creep[0] + patch.lever * creep[2], creep[1], creep[2])
    out["spin lever"] = knee_force(patch, patch.strip_sums(moved), knee, None)
    return out


def error(f: tuple[float, float], e: tuple[float, float], n: float) -> float:
    return 100.0 * max(abs(f[0] - e[0]), abs(f[1] - e[1])) / (MU * n)


def oracle_cases() -> Iterator[Case]:
    """Yield (group, area, creepages, load): the wheelset's cases and the two curves."""
    for label, area, creep, n in rl.wheelset_cases():
        wheel = "right" if "right" in label else "left"
        yield f"{label.split(' (')[0]} ({wheel})", area, creep, n
    tread = va.patches(-0.414e-3, va.axle_spin(None))["right"]
    area, creep, n = tread
    for x in (1e-4, 2e-4, 4e-4, 6e-4, 1e-3, 1.5e-3, 3e-3):
        yield f"tread curve (right, -0.414 mm), xi {x:.1e}", area, (x, creep[1], creep[2]), n
    area, creep, n = va.patches(-4.95e-3, va.SPEED / va.RADIUS)["right"]
    for f in (0.1, 0.25, 0.5, 1.0, 2.0, 10.0):
        yield (f"take-over curve (right, -4.950 mm), creepages x {f:g}", area,
               tuple(f * c for c in creep), n)  # type: ignore[misc]


def part_oracle(proto: rl.Prototype) -> None:
    print("## Wheelset: worst error per group, % of mu N (r, J exact: an oracle)\n")
    print("| group | r_x, r_y | " + " | ".join(VARIANTS) + " |")
    print("| --- | --- | " + " | ".join("---" for _ in VARIANTS) + " |")
    cache: dict[int, Patch] = {}
    worst: dict[str, dict[str, float]] = {}
    ratio: dict[str, str] = {}
    order: list[str] = []
    for group, area, creep, n in oracle_cases():
        key = hash(area.pressure.tobytes()) ^ hash((area.x0, area.y0, area.dx, area.dy))
        if key not in cache:
            cache[key] = Patch(proto, area)
        patch = cache[key]
        ex = exact.coulomb(area, *creep, mu=MU, nu=NU, shear_modulus=G)
        f = variant_forces(proto, patch, creep, n)
        ref = proto.solver.solve(area, *creep, mu=MU)
        assert abs(f["default"][0] - ref.fx) + abs(f["default"][1] - ref.fy) < 1e-6 * MU * n
        if group not in worst:
            order.append(group)
            worst[group] = {v: 0.0 for v in VARIANTS}
            ratio[group] = ""
        for v in VARIANTS:
            worst[group][v] = max(worst[group][v], error(f[v], (ex.fx, ex.fy), n))
        if patch.r[0] >= float(ratio[group].split(",")[0] or 0.0):
            ratio[group] = f"{patch.r[0]:.3f}, {patch.r[1]:.3f}"
    for group in order:
        print(f"| {group} | {ratio[group]} | "
              + " | ".join(f"{worst[group][v]:.2f}" for v in VARIANTS) + " |", flush=True)


def part_wider(proto: rl.Prototype) -> None:
    print("\n## validate_wider.py areas (40 cells): worst curve error, % of mu N "
          "(points with |F_exact| > 5% of mu N)\n")
    print("| area | r_x, r_y | " + " | ".join(VARIANTS) + " |")
    print("| --- | --- | " + " | ".join("---" for _ in VARIANTS) + " |")
    for name, make in rl.wider_makers().items():
        ar = make(rl.WIDER_CELLS)
        op = exact.SteadyRollingOperator.of(ar, nu=NU, shear_modulus=G)
        patch = Patch(proto, ar)
        sat = rl.saturation(ar)
        mun = MU * ar.load
        worst = {v: 0.0 for v in VARIANTS}
        for direction in rl.WIDER_CURVES.values():
            for lev in rl.WIDER_LEVELS:
                cr = tuple(lev * d * s for d, s in zip(direction, sat))
                ex = exact.coulomb(ar, *cr, mu=MU, nu=NU, shear_modulus=G, operator=op)
                f = variant_forces(proto, patch, cr, ar.load)  # type: ignore[arg-type]
                for v in VARIANTS:
                    e = 0.0
                    for fm, fe in zip(f[v], (ex.fx, ex.fy)):
                        if abs(fe) > 0.05 * mun:
                            e = max(e, 100.0 * abs(fm - fe) / mun)
                    worst[v] = max(worst[v], e)
        print(f"| {name} | {patch.r[0]:.3f}, {patch.r[1]:.3f} | "
              + " | ".join(f"{worst[v]:.2f}" for v in VARIANTS) + " |", flush=True)


def chord_flatness(count: np.ndarray, dx: float) -> float:
    """Return ``m0 m2 / m1^2`` of the chords (``m_k = sum c^(k+1)``) over an ellipse's, less 1.

    An ellipse's (and a semi-ellipse's) chord profile gives ``27 pi^2 / 256``;
    a profile with a wide end and a long narrow neck gives more.
    """
    c = count[count > 0] * dx
    if c.size == 0:
        return 0.0
    m0, m1, m2 = c.sum(), (c**2).sum(), (c**3).sum()
    return float(m0 * m2 / m1**2 / (27.0 * math.pi**2 / 256.0) - 1.0)


def features(patch: Patch) -> np.ndarray:
    """Return the predictor's features: the patch's and its MAE zones' chord flatness."""
    area = patch.area
    geo = patch.prep[1]
    lower = area.y < geo[k.G_YS]
    whole = chord_flatness(row_extents(area.mask)[0], area.dx)
    zones = []
    weights = []
    for rows in (lower, ~lower):
        count = row_extents(area.mask & rows[:, None])[0]
        zones.append(chord_flatness(count, area.dx))
        weights.append(float(count.sum()))
    zone = sum(w * z for w, z in zip(weights, zones)) / sum(weights)
    return np.array([whole, zone, max(zones)])


def part_predictor(proto: rl.Prototype) -> None:
    print("\n## A cheap predictor of r_x from the chords (least squares, one family left out)\n")
    families: dict[str, list[Patch]] = {"tread left": [], "tread right": [],
                                        "flange left": [], "flange right": [],
                                        "wider": [], "ellipses": []}
    seen: set[int] = set()
    for dy in (-0.404e-3, -0.414e-3, -0.440e-3, -0.476e-3, -0.496e-3, -4.0e-3, -4.9e-3,
               -4.95e-3, -5.0e-3):
        for wheel, (area, _, _) in va.patches(dy, va.axle_spin(None)).items():
            key = hash(area.pressure.tobytes())
            if key in seen:
                continue
            seen.add(key)
            fam = ("flange " if dy < -1e-3 else "tread ") + wheel
            families[fam].append(Patch(proto, area))
    for name, make in rl.wider_makers().items():
        families["wider"].append(Patch(proto, make(rl.WIDER_CELLS)))
    for g in (0.3, 1.0, 3.0):
        a, b = areas.semi_ellipse_axes(g)
        families["ellipses"].append(Patch(proto, areas.ellipse(a * 0.01, b * 0.01, nx=40,
                                                               ny=40, load=5.0e4)))
    names = ("patch flatness", "zones' flatness (area-weighted)", "zones' flatness (larger)")
    x = {f: np.array([features(p) for p in ps]) for f, ps in families.items()}
    y = {f: np.array([p.r[0] - 1.0 for p in ps]) for f, ps in families.items()}
    print("| feature | fitted slope (all) | held-out family: r_x - 1 exact (range) | "
          "predicted (range) | worst held-out error of r_x |")
    print("| --- | --- | --- | --- | --- |")
    for i, label in enumerate(names):
        xa = np.concatenate([x[f][:, i] for f in families])
        ya = np.concatenate([y[f] for f in families])
        slope = float(xa @ ya / (xa @ xa))
        for held in families:
            xt = np.concatenate([x[f][:, i] for f in families if f != held])
            yt = np.concatenate([y[f] for f in families if f != held])
            sl = float(xt @ yt / (xt @ xt))
            pred = sl * x[held][:, i]
            print(f"| {label} | {slope:.3f} | {held}: {y[held].min():+.3f} .. "
                  f"{y[held].max():+.3f} | {pred.min():+.3f} .. {pred.max():+.3f} | "
                  f"{np.max(np.abs(pred - y[held])):.3f} |", flush=True)


def part_ellipse(proto: rl.Prototype) -> None:
    print("\n## The equivalent ellipse's exact / method ratio, spin included (an oracle)\n")
    print("Each wheelset case's patch against its equivalent ellipse (the method's own, same "
          "load, 30 x 30 cells, the creepages about its centre): the default's error there, "
          "and the patch's default force times the ellipse's ratio ``F_exact / F_method`` "
          "per component (or plus their difference). % of mu N.\n")
    print("| group (wheel) | default | default on the ellipse | times the ellipse's ratio | "
          "plus the ellipse's difference |")
    print("| --- | --- | --- | --- | --- |")
    worst: dict[str, list[float]] = {}
    for group, area, creep, n in oracle_cases():
        if "curve" in group:
            continue
        geo = Patch(proto, area).prep[1]
        xe, ye, a, b = (geo[k.G_ELLIPSE + i] for i in range(4))
        ce = (creep[0] - creep[2] * ye, creep[1] + creep[2] * xe, creep[2])
        ell = areas.ellipse(a, b, nx=30, ny=30, load=n)
        ee = exact.coulomb(ell, *ce, mu=MU, nu=NU, shear_modulus=G)
        de = proto.solver.solve(ell, *ce, mu=MU)
        ex = exact.coulomb(area, *creep, mu=MU, nu=NU, shear_modulus=G)
        d = proto.solver.solve(area, *creep, mu=MU)
        small = 1e-9 * n
        ratio = (d.fx * (ee.fx / de.fx if abs(de.fx) > small else 1.0),
                 d.fy * (ee.fy / de.fy if abs(de.fy) > small else 1.0))
        added = (d.fx + ee.fx - de.fx, d.fy + ee.fy - de.fy)
        row = worst.setdefault(group, [0.0] * 4)
        for i, (f, e) in enumerate((((d.fx, d.fy), (ex.fx, ex.fy)),
                                    ((de.fx, de.fy), (ee.fx, ee.fy)),
                                    (ratio, (ex.fx, ex.fy)), (added, (ex.fx, ex.fy)))):
            row[i] = max(row[i], error(f, e, n))
    for group, row in worst.items():
        print(f"| {group} | " + " | ".join(f"{v:.2f}" for v in row) + " |", flush=True)


def part_spin_knee(proto: rl.Prototype) -> None:
    print("\n## The default on Hertzian ellipses under xi with spin: error, % of mu N\n")
    print("``xi`` and ``phi`` (about the centre) set so that the linear force is at ``s = "
          "|F_lin| / (mu N)`` with the spin's part ``F_lin,phi / |F_lin|`` (lateral); "
          "30 x 30 cells, N 10 kN, semi-axes ``sqrt(ab)`` 3 mm.\n")
    levels = (0.3, 0.6, 1.0, 1.5, 2.5)
    print("| a/b | spin's part | " + " | ".join(f"s {v:g}" for v in levels) + " |")
    print("| --- | --- | " + " | ".join("---" for _ in levels) + " |")
    n = 1.0e4
    for g in (0.3, 1.0, 3.0):
        a, b = areas.semi_ellipse_axes(g)
        scale = 3e-3 / math.sqrt(a * b)
        ell = areas.ellipse(a * scale, b * scale, nx=30, ny=30, load=n)
        op = exact.SteadyRollingOperator.of(ell, nu=NU, shear_modulus=G)
        patch = Patch(proto, ell)
        jx, jy = patch.mae[0, 0], patch.mae[1, 2]
        for part in (0.0, 0.3, 0.6, 0.9):
            cells = []
            for lev in levels:
                f = lev * MU * n
                cr = (f * math.sqrt(1.0 - part**2) / jx, 0.0, f * part / jy)
                ex = exact.coulomb(ell, *cr, mu=MU, nu=NU, shear_modulus=G, operator=op)
                d = proto.solver.solve(ell, *cr, mu=MU)
                cells.append(f"{error((d.fx, d.fy), (ex.fx, ex.fy), n):.2f}")
            print(f"| {g:g} | {part:g} | " + " | ".join(cells) + " |", flush=True)


def main() -> int:
    proto = rl.Prototype()
    return rl.run_parts(__doc__.splitlines()[0], {
        "oracle": lambda: part_oracle(proto), "wider": lambda: part_wider(proto),
        "predictor": lambda: part_predictor(proto), "ellipse": lambda: part_ellipse(proto),
        "spin_knee": lambda: part_spin_knee(proto)})


if __name__ == "__main__":
    sys.exit(main())
