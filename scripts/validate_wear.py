"""Validate the frictional power: CONTACT's FRIC.POWER, the exact solver, the fast methods.

Run from the package root::

    PYTHONPATH=. .venv/bin/python scripts/validate_wear.py

Prints two Markdown tables (docs/guide_wear.md quotes them):

1. CONTACT's published traction curve (``docs/data/contact_tractcurv_power.csv``,
   ``examples/tractcurv.ref_out``, the Coulomb series: Hertzian a = 6.304 mm,
   b = 12.61 mm, N = 106.7 kN, mu = 0.33, V = 10 m/s): per point CONTACT's
   frictional power, the exact solver's (44 x 40 cells, CONTACT's element
   size) and its gap, T-gamma V and the share that slips, and the fast
   methods' (parabolic bound, 60 x 60 cells) gap to CONTACT.
2. A non-elliptical patch (two semi-ellipses, a/b 0.5 and 2, 40 x 41 cells,
   80 kN, mu = 0.3, the pressure as the bound): the exact solver's
   dissipation per metre rolled and share against each fast method's, under
   creepage, spin and both.
"""

from __future__ import annotations

from pathlib import Path

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import exact
from fastsim_ros.contact.compiled import (CalibratedMaeSolver, EquivalentEllipseSolver,
                                          MaeSolver)
from fastsim_ros.contact.wear import t_gamma

ROOT = Path(__file__).resolve().parents[1]
A, B, LOAD, G, NU, MU, V = 6.304e-3, 12.61e-3, 106700.0, 8.2e10, 0.28, 0.33, 10.0
FAST = (("mae_calibrated", CalibratedMaeSolver), ("mae", MaeSolver),
        ("fastsim_ellipse", EquivalentEllipseSolver))


def contact_rows() -> list[tuple[int, float, float]]:
    rows = []
    for line in (ROOT / "docs" / "data" / "contact_tractcurv_power.csv").read_text().splitlines():
        if line[:1].isdigit():
            case, cksi, _, _, power = line.split(",")
            rows.append((int(case), float(cksi), -float(power)))
    return rows


def contact_table() -> None:
    area = areas.ellipse(A, B, nx=44, ny=40, load=LOAD)
    fine = areas.ellipse(A, B, nx=60, ny=60, load=LOAD)
    op = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=G)
    solvers = [(name, cls(NU, G)) for name, cls in FAST]
    print("| case | xi | CONTACT P (W) | exact P (W) | gap | T-gamma V (W) | P / T-gamma V | "
          + " | ".join(f"{name} gap" for name, _ in solvers) + " |")
    print("|" + " ---: |" * (7 + len(solvers)))
    for case, xi, power in contact_rows():
        sol = exact.coulomb(area, xi, 0.0, 0.0, mu=MU, nu=NU, shear_modulus=G, operator=op)
        d, _ = exact.slip_dissipation(area, sol, xi, 0.0, 0.0, nu=NU, shear_modulus=G,
                                      operator=op)
        tgv = t_gamma(sol.fx, sol.fy, sol.mz, xi, 0.0, 0.0) * V
        gaps = []
        for _, s in solvers:
            f = s.solve(fine, xi, 0.0, 0.0, mu=MU, bound="parabolic", tractions=True)
            gaps.append(f"{(f.dissipation * V - power) / power * 100:+.1f}%")
        print(f"| {case} | {xi:.4g} | {power:.4g} | {d * V:.4g} | "
              f"{(d * V - power) / power * 100:+.2f}% | {tgv:.4g} | {d * V / tgv:.3f} | "
              + " | ".join(gaps) + " |")


def patch_table() -> None:
    g, mu = 8e10, 0.3
    area = areas.semi_ellipses(0.5, 2.0, cells=40).scaled(6e-3).with_load(8e4)
    op = exact.SteadyRollingOperator.of(area, nu=NU, shear_modulus=g)
    solvers = [(name, cls(NU, g)) for name, cls in FAST]
    print("| xi | eta | phi (1/m) | exact D (J/m) | exact D / T-gamma | "
          + " | ".join(f"{name} D (gap), D / T-gamma" for name, _ in solvers) + " |")
    print("|" + " ---: |" * (5 + len(solvers)))
    for xi, eta, phi in ((1e-3, 0.0, 0.0), (0.0, 1e-3, 0.0), (5e-4, 5e-4, 1.0),
                         (0.0, 0.0, 5.0), (3e-3, 1e-3, 2.0), (2e-2, 0.0, 0.0)):
        sol = exact.coulomb(area, xi, eta, phi, mu=mu, nu=NU, shear_modulus=g, operator=op)
        d, _ = exact.slip_dissipation(area, sol, xi, eta, phi, nu=NU, shear_modulus=g,
                                      operator=op)
        cells = []
        for _, s in solvers:
            f = s.solve(area, xi, eta, phi, mu=mu, tractions=True)
            tg = t_gamma(f.fx, f.fy, f.mz, xi, eta, phi)
            cells.append(f"{f.dissipation:.4g} ({(f.dissipation - d) / d * 100:+.0f}%), "
                         f"{f.dissipation / tg:.2f}")
        tg = t_gamma(sol.fx, sol.fy, sol.mz, xi, eta, phi)
        print(f"| {xi:g} | {eta:g} | {phi:g} | {d:.4g} | {d / tg:.3f} | " + " | ".join(cells)
              + " |")


def main() -> None:
    contact_table()
    print()
    patch_table()


if __name__ == "__main__":
    main()
