"""Validation of slip-dependent friction (issue 13): creep curves Fx(xi) for several B.

Exact solver (Kalker's theory, slip-dependent Coulomb projection) against
FastSim on a Hertzian ellipse (Kalker's FastSim with the parabolic bound,
as ``fastsim_ellipse`` runs it on an ellipse), and against MAE + FastSim and
the equivalent ellipse on the flange-root patch
(:func:`fastsim_ros.contact.samples.flange_root_patch`), for the law
``mu(v) = mu_s ((1 - A) exp(-B v) + A)`` at rolling speed ``V``.  Writes
``docs/figures/friction_creep_curves.png`` and
``docs/data/friction_curves.csv`` and prints the table of
docs/validation.md ("Slip-dependent friction").  About a minute here.
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
from fastsim_ros.contact.friction import ConstantFriction, ExponentialFriction  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
NU, G = 0.28, 8.0e10
MU_S, A_LIMIT, SPEED = 0.4, 0.4, 20.0  # mu_s, A, |V| (m/s)
DECAYS = (0.0, 0.3, 1.0, 3.0)          # B (s/m); 0 = constant friction
XI = np.geomspace(5e-4, 0.1, 16)
EXACT_CELLS = 30


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


def main() -> int:
    hertz = ellipse(6e-3, 4e-3, nx=EXACT_CELLS, ny=EXACT_CELLS, load=1e5)
    flange = samples.flange_root_patch(cells=EXACT_CELLS)
    curves = {}
    for name, area in (("hertz", hertz), ("flange_root", flange)):
        op = SteadyRollingOperator.of(area, nu=NU, shear_modulus=G)
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
    # the figure
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8), sharey=True)
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
    fig.suptitle(f"Falling friction mu(v) = mu_s ((1 - A) exp(-B v) + A), mu_s = {MU_S}, "
                 f"A = {A_LIMIT}, rolling speed |V| = {SPEED} m/s", fontsize=11)
    fig.tight_layout()
    fig.savefig(ROOT / "docs" / "figures" / "friction_creep_curves.png", dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
