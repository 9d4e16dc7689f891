"""The compiled path's constants: the configured MAE solver and friction law, as its kernel takes.

:func:`fastsim_ros.pipeline.kernels.solve_cloud` takes the solver's tables,
the traction bound and the friction law as arguments (what
:meth:`fastsim_ros.contact.compiled.MaeSolver.solve_arrays` passes);
:class:`CompiledState` holds them, built once per configuration
(:meth:`CompiledState.of`), its static coefficient renewed alone when the
friction estimate moves (:meth:`CompiledState.with_mu`).  A named tuple: the
per-patch path unpacks it in one step.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from fastsim_ros.contact import compiled
from fastsim_ros.contact.checks import check_bound
from fastsim_ros.contact.compiled import MaeSolver
from fastsim_ros.contact.friction import FrictionLaw


class CompiledState(NamedTuple):
    """The arguments of ``solve_cloud`` that stay from patch to patch, in its order."""

    #: the MAE split rule's code (the solver's)
    rule: int
    #: whether the traction bound is the parabolic one (else ``mu p`` as given)
    parabolic: bool
    #: the combined shear modulus G (Pa)
    shear_modulus: float
    #: the coefficient table's knots and polynomials (the solver's Poisson ratio)
    knots: np.ndarray
    polys: np.ndarray
    #: the friction law's code and parameters (:func:`fastsim_ros.contact.compiled._law`)
    law: int
    law_parameters: np.ndarray
    #: the static friction coefficient mu_s: the one field the friction estimate changes
    mu: float
    #: whether the law reads the local slip velocity (a law other than Coulomb's)
    slip_dependent: bool
    #: the calibrated MAE's pair factors (read by it alone)
    calibrated: bool
    pair_knots: np.ndarray
    pair_values: np.ndarray
    #: the knee factors strip by strip (the calibrated MAE under the given bound), else none
    knee: np.ndarray

    @classmethod
    def of(cls, solver: MaeSolver, bound: str, mu: float,
           law: FrictionLaw | None) -> CompiledState:
        """Return the state of ``solver`` under ``bound`` at ``mu`` (``law`` None: Coulomb)."""
        code, parameters, mu_s, _ = compiled._law(mu, law, 1.0)
        return cls(solver._rule, check_bound(bound), solver.shear_modulus, solver._knots,
                   solver._polys, code, parameters, mu_s, law is not None,
                   solver._calibrated, solver._pair_knots, solver._pair_values,
                   solver._knee_for(bound))

    def with_mu(self, mu: float) -> CompiledState:
        """Return the state with the static coefficient ``mu`` (the rest depends not on it)."""
        return self._replace(mu=mu)
