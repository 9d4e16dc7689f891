"""The physics core: wheel-rail creep forces with FastSim, MAE and Kalker's exact theory.

The public names below can be taken from here (``from fastsim_ros.contact
import MaeSolver``) without knowing the module that holds them.  They are
loaded on first use (PEP 562), so that importing the package, or its fast
path :mod:`fastsim_ros.contact.compiled`, pulls in neither SciPy nor the
exact solver.  README "The physics core" says which module may import which.
"""

from __future__ import annotations

import importlib
from typing import Any

#: public name -> the module (of this package) that defines it
_HOME = {
    # errors
    "ContactError": "errors", "InvalidInputError": "errors", "EmptyContactError": "errors",
    "IrregularGridError": "errors", "GridTooLargeError": "errors",
    "OutOfTableError": "errors", "ConvergenceError": "errors", "DataError": "errors",
    # checked inputs
    "Material": "checks", "check_material": "checks",
    # areas and results
    "GridArea": "area", "ellipse": "area", "semi_ellipses": "area",
    "semi_ellipse_axes": "area", "from_cells": "area",
    "CreepCoefficients": "coefficients", "Tractions": "traction",
    "coefficient_table": "tables",
    # the fast path the node runs
    "MaeSolver": "compiled", "EquivalentEllipseSolver": "compiled",
    "ContactForces": "compiled", "warm_up": "compiled",
    # contaminated rails: the modified FastSim's slope reduction, Polach's closed form
    "SlopeReduction": "slope_reduction", "PolachSolver": "polach",
    # the numpy reference
    "traction_bound": "fastsim",  # (fastsim() itself: the submodule takes the name)
    "mae_geometry": "mae", "mae_coefficients": "mae", "mae_fastsim": "mae",
    "mae_fastsim_coefficients": "mae",
    "equivalent_fastsim": "equivalent", "equivalent_coefficients": "equivalent",
    # FaStrip (fastrip() itself: the submodule takes the name)
    "fastrip_coefficients": "fastrip",
    # the exact theory and the normal problem (SciPy)
    "SteadyRollingOperator": "exact", "full_adhesion": "exact", "coulomb": "exact",
    "creep_coefficients": "exact", "unit_solutions": "exact",
    "solve_normal": "normal", "hertz_ellipse": "normal",
}

__all__ = sorted(_HOME)


def __getattr__(name: str) -> Any:
    """Load a public name from its module on first use."""
    try:
        module = _HOME[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """List the public names with the module's own."""
    return sorted(set(globals()) | set(__all__))
