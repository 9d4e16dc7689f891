"""Validation of slip-dependent friction: creep curves Fx(xi) for several B.

Exact solver (Kalker's theory, slip-dependent Coulomb projection) against
FastSim on a Hertzian ellipse (Kalker's FastSim with the parabolic bound,
as ``fastsim_ellipse`` runs it on an ellipse), and against MAE + FastSim and
the equivalent ellipse on the flange-root patch
(:func:`fastsim_ros.contact.samples.flange_root_patch`), for the law
``mu(v) = mu_s ((1 - A) exp(-B v) + A)`` at rolling speed ``V``.  Also the
exact solver's grid check at one creepage near the peak (20, 30, 40 cells
across), lateral creepage and longitudinal with spin on the ellipse,
FastSim's peak on 30 to 240 cells and, at that creepage, the central strip
of the ellipse: traction over its static bound and slip velocity along
``x``, exact against FastSim (the third panel of the figure;
``docs/data/friction_strip.csv``).  Writes
``docs/figures/friction_creep_curves.png``, ``docs/data/friction_curves.csv``
and ``docs/data/friction_strip.csv`` and prints the tables of
docs/validation_friction.md.  About a minute here.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from fastsim_ros.contact import samples  # noqa: E402
from fastsim_ros.contact.area import ellipse  # noqa: E402
from fastsim_ros.contact.compiled import EquivalentEllipseSolver, MaeSolver  # noqa: E402
from fastsim_ros.contact.exact import SteadyRollingOperator, coulomb  # noqa: E402
from fastsim_ros.contact.equivalent import equivalent_fastsim  # noqa: E402
from fastsim_ros.contact.fastsim import traction_bound  # noqa: E402
from fastsim_ros.contact.friction import ConstantFriction, ExponentialFriction  # noqa: E402
from fastsim_ros.contact.tables import coefficient_table  # noqa: E402
from fastsim_ros.contact.traction import rigid_slip  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
NU, G = 0.28, 8.0e10
MU_S, A_LIMIT, SPEED = 0.4, 0.4, 20.0  # mu_s, A, |V| (m/s)
DECAYS = (0.0, 0.3, 1.0, 3.0)          # B (s/m); 0 = constant friction
XI = np.geomspace(5e-4, 0.1, 16)
EXACT_CELLS = 30
SEMI_AXES = (6e-3, 4e-3)  # the Hertzian ellipse (m), load 1e5 N
#: the grid check and the strip: B (s/m) and xi near the exact curve's peak
CHECK_DECAY, CHECK_XI = 1.0, 0.0093
CHECK_CELLS = (20, 30, 40)


def law(decay: float):
    return ConstantFriction(MU_S) if decay == 0.0 else ExponentialFriction(MU_S, A_LIMIT, decay)


def exact_curve(area, op, decay):
    return np.array([-coulomb(area, xi, 0.0, 0.0, nu=NU, shear_modulus=G, operator=op,
                              friction=law(decay), speed=SPEED).fx for xi in XI])


def fast_curve(solver, area, decay, bound):
    return np.array([-solver.solve(area, xi, 0.0, 0.0, friction=law(decay), speed=SPEED,
                                   bound=bound).fx for xi in XI])


def peak(f):
    """Peak height and creepage: three-point parabola in log xi around the largest sample."""
    k = int(np.argmax(f))
    if k == 0 or k == len(f) - 1:
        return float(f[k]), float(XI[k])
    t = np.log(XI[k - 1:k + 2])
    c = np.polyfit(t, f[k - 1:k + 2], 2)
    tm = -c[1] / (2 * c[0])
    return float(np.polyval(c, tm)), float(np.exp(tm))


def exact_strip(area, op, decay, xi):
    """Central strip of the exact solution: x/a, |tau|/(mu_s p), slip velocity (m/s)."""
    sol = coulomb(area, xi, 0.0, 0.0, nu=NU, shear_modulus=G, operator=op,
                  friction=law(decay), speed=SPEED)
    mask = area.mask
    wx, wy = rigid_slip(area, xi, 0.0, 0.0, (0.0, 0.0))
    ux, uy = op.fft_product()(sol.tau_x, sol.tau_y)  # du/dx of the tractions
    sx, sy = np.where(mask, wx - ux, 0.0), np.where(mask, wy - uy, 0.0)
    j = area.ny // 2
    cells = np.flatnonzero(mask[j])
    g = MU_S * area.pressure[j, cells]
    return (area.x[cells] / SEMI_AXES[0], np.hypot(sol.tau_x[j, cells], sol.tau_y[j, cells]) / g,
            SPEED * np.hypot(sx[j, cells], sy[j, cells]))


def fastsim_strip(area, decay, xi):
    """Central strip of Kalker's FastSim (60 cells, parabolic bound): as :func:`exact_strip`.

    The slip velocity is the one the law sees (fastsim.slip_ratio): the slip
    at the upstream cell's friction ratio, ``L1 (m - k g_s)/h``; zero in
    adhesion.
    """
    res = equivalent_fastsim(area, xi, 0.0, 0.0, table=coefficient_table(NU), shear_modulus=G,
                             friction=law(decay), speed=SPEED, bound="parabolic", cells=60)
    grid, e = res.grid, res.ellipse
    gs = traction_bound(grid, MU_S, bound="parabolic")
    c11 = coefficient_table(NU).kalker(e.a / e.b)[0]
    l1 = 8.0 * e.a / (3.0 * G * c11)
    j = grid.ny // 2
    cells = np.flatnonzero(gs[j] > 0.0)[::-1]
    tau = -res.traction.tau_x[j, cells]
    slip = res.traction.slip[j, cells]
    v = np.zeros(cells.size)
    prev, k = 0.0, 1.0
    for n, i in enumerate(cells):
        h = (0.5 if n == 0 else 1.0) * grid.dx
        if slip[n]:
            v[n] = SPEED * l1 * (prev + xi / l1 * h - k * gs[j, i]) / h
            k = tau[n] / gs[j, i]
        else:
            k = 1.0
        prev = tau[n]
    return grid.x[cells] / e.a, tau / gs[j, cells], v


def main() -> int:
    hertz = ellipse(*SEMI_AXES, nx=EXACT_CELLS, ny=EXACT_CELLS, load=1e5)
    flange = samples.flange_root_patch(cells=EXACT_CELLS)
    curves = {}
    hertz_op = SteadyRollingOperator.of(hertz, nu=NU, shear_modulus=G)
    for name, area in (("hertz", hertz), ("flange_root", flange)):
        op = (hertz_op if area is hertz
              else SteadyRollingOperator.of(area, nu=NU, shear_modulus=G))
        mun = MU_S * area.load
        for b in DECAYS:
            curves[(name, "exact", b)] = exact_curve(area, op, b) / mun
            if name == "hertz":
                curves[(name, "fastsim", b)] = fast_curve(
                    EquivalentEllipseSolver(NU, G, cells=60), area, b, "parabolic") / mun
            else:
                curves[(name, "mae", b)] = fast_curve(MaeSolver(NU, G), area, b, "given") / mun
                curves[(name, "equivalent", b)] = fast_curve(
                    EquivalentEllipseSolver(NU, G), area, b, "given") / mun
    (ROOT / "docs" / "data").mkdir(parents=True, exist_ok=True)
    with open(ROOT / "docs" / "data" / "friction_curves.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["area", "method", "B_s_per_m", "xi", "Fx_over_mu_s_N"])
        for (name, method, b), fx in curves.items():
            for xi, v in zip(XI, fx):
                w.writerow([name, method, b, f"{xi:.6g}", f"{v:.6f}"])
    # the table
    print(f"mu_s = {MU_S}, A = {A_LIMIT}, |V| = {SPEED} m/s, xi in [{XI[0]:g}, {XI[-1]:g}] "
          f"({XI.size} points), eta = phi = 0; exact on {EXACT_CELLS} cells across\n")
    print("| area | method | B (s/m) | peak Fx/(mu_s N) | at xi | max error (% of mu_s N) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for (name, method, b), fx in curves.items():
        h, x = peak(fx)
        err = "" if method == "exact" else \
            f"{100 * np.abs(fx - curves[(name, 'exact', b)]).max():.1f}"
        print(f"| {name} | {method} | {b:g} | {h:.3f} | {x:.3g} | {err} |")
    # the exact solver's grid check near the peak
    print(f"\nexact solver, B = {CHECK_DECAY:g} s/m, xi = {CHECK_XI:g}: grid check\n")
    print("| cells across | Fx/(mu_s N) | constant friction |")
    print("| --- | --- | --- |")
    for n in CHECK_CELLS:
        ar = ellipse(*SEMI_AXES, nx=n, ny=n, load=1e5)
        op = SteadyRollingOperator.of(ar, nu=NU, shear_modulus=G)
        f = [-coulomb(ar, CHECK_XI, 0.0, 0.0, nu=NU, shear_modulus=G, operator=op,
                      friction=law(b), speed=SPEED).fx / (MU_S * ar.load)
             for b in (CHECK_DECAY, 0.0)]
        print(f"| {n} | {f[0]:.4f} | {f[1]:.4f} |")
    # beyond pure xi: lateral creepage, and xi with spin, on the ellipse
    print("\nHertzian ellipse, other creepages (12 levels in [5e-4, 0.1]; xi + spin: phi = "
          "20 xi 1/m): largest error in % of mu_s N, and the peak of |F|/(mu_s N)\n")
    print("| creepage | B (s/m) | FastSim Fx error | Fy error | exact peak | FastSim peak |")
    print("| --- | --- | --- | --- | --- | --- |")
    levels = np.geomspace(XI[0], XI[-1], 12)
    fast = EquivalentEllipseSolver(NU, G, cells=60)
    for cname, creep in (("eta", lambda c: (0.0, c, 0.0)),
                         ("xi + spin", lambda c: (c, 0.0, 20.0 * c))):
        for b in (0.0, 1.0, 3.0):
            ex = np.array([[r.fx, r.fy] for r in (
                coulomb(hertz, *creep(c), nu=NU, shear_modulus=G, operator=hertz_op,
                        friction=law(b), speed=SPEED) for c in levels)])
            fa = np.array([[r.fx, r.fy] for r in (
                fast.solve(hertz, *creep(c), friction=law(b), speed=SPEED, bound="parabolic")
                for c in levels)])
            err = 100 * np.abs(fa - ex).max(axis=0) / (MU_S * hertz.load)
            pe, pf = (float(np.hypot(v[:, 0], v[:, 1]).max() / (MU_S * hertz.load))
                      for v in (ex, fa))
            print(f"| {cname} | {b:g} | {err[0]:.1f} | {err[1]:.1f} | {pe:.3f} | {pf:.3f} |")
    # FastSim's own grid convergence with the falling law (the peak on a finer xi grid)
    fine = np.geomspace(XI[0], XI[-1], 61)
    print("\nFastSim (Kalker's, parabolic bound) on n x n cells: peak Fx/(mu_s N) and its xi "
          "(61 creepages)\n")
    print("| cells across | " + " | ".join(f"B = {b:g} s/m" for b in DECAYS[1:]) + " |")
    print("| --- |" + " --- |" * (len(DECAYS) - 1))
    for n in (30, 60, 120, 240):
        solver = EquivalentEllipseSolver(NU, G, cells=n)
        cols = []
        for b in DECAYS[1:]:
            f = np.array([-solver.solve(hertz, xi, 0.0, 0.0, friction=law(b), speed=SPEED,
                                        bound="parabolic").fx for xi in fine])
            k = int(np.argmax(f))
            cols.append(f"{f[k] / (MU_S * hertz.load):.4f} at {fine[k]:.3g}")
        print(f"| {n} | " + " | ".join(cols) + " |")
    # the central strip near the peak
    strips = {"exact": exact_strip(hertz, hertz_op, CHECK_DECAY, CHECK_XI),
              "fastsim": fastsim_strip(hertz, CHECK_DECAY, CHECK_XI)}
    with open(ROOT / "docs" / "data" / "friction_strip.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["method", "x_over_a", "tau_over_mu_s_p", "slip_velocity_m_per_s"])
        for method, (xa, tg, v) in strips.items():
            for row in zip(xa, tg, v):
                w.writerow([method] + [f"{c:.6g}" for c in row])
    for method, (xa, tg, v) in strips.items():
        print(f"{method} strip: largest slip velocity {v.max():.3f} m/s, "
              f"|tau|/(mu_s p) from {tg.min():.3f} to {tg.max():.3f}")
    # the figure
    fig, axes = plt.subplots(1, 3, figsize=(17, 4.8),
                             gridspec_kw={"width_ratios": (1, 1, 0.8)})
    colours = dict(zip(DECAYS, ("k", "tab:blue", "tab:orange", "tab:red")))
    styles = {"exact": "-", "fastsim": "--", "mae": "--", "equivalent": ":"}
    marks = {"exact": "o", "fastsim": "", "mae": "", "equivalent": ""}
    titles = {"hertz": "Hertzian ellipse a = 6 mm, b = 4 mm: exact vs FastSim",
              "flange_root": "flange-root patch: exact vs MAE and equivalent ellipse"}
    for ax, name in zip(axes, ("hertz", "flange_root")):
        for (n, method, b), fx in curves.items():
            if n != name:
                continue
            label = f"{method}, B = {b:g} s/m" + (" (constant)" if b == 0 else "")
            ax.semilogx(XI, fx, styles[method], marker=marks[method], ms=3,
                        color=colours[b], label=label, lw=1.5 if method == "exact" else 1.2)
        ax.axhline(1.0, color="grey", lw=0.6)
        ax.set_title(titles[name], fontsize=10)
        ax.set_xlabel("longitudinal creepage xi")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=2, loc="lower right")
    axes[0].set_ylabel("-Fx / (mu_s N)")
    axes[1].sharey(axes[0])
    ax = axes[2]
    twin = ax.twinx()
    for method, (xa, tg, v) in strips.items():
        style = "-o" if method == "exact" else "--"
        ax.plot(xa, tg, style, color="tab:orange", ms=3, label=f"{method}: |tau|/(mu_s p)")
        twin.plot(xa, v, style, color="tab:purple", ms=3, label=f"{method}: slip velocity")
    ax.set_xlabel("x / a (leading edge on the left)")
    ax.set_ylabel("|tau| / (mu_s p)", color="tab:orange")
    twin.set_ylabel("slip velocity V |s| (m/s)", color="tab:purple")
    ax.set_ylim(0.0, 1.05)
    ax.invert_xaxis()
    ax.set_title(f"central strip, B = {CHECK_DECAY:g} s/m, xi = {CHECK_XI:g} (near the peak)",
                 fontsize=10)
    ax.grid(True, alpha=0.3)
    lines = ax.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], fontsize=7, loc="center left")
    fig.suptitle(f"Falling friction mu(v) = mu_s ((1 - A) exp(-B v) + A), mu_s = {MU_S}, "
                 f"A = {A_LIMIT}, rolling speed |V| = {SPEED} m/s", fontsize=11)
    fig.tight_layout()
    fig.savefig(ROOT / "docs" / "figures" / "friction_creep_curves.png", dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
