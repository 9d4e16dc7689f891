"""Generalised creepage coefficients: the result type every method reports them in.

docs/guide_physics.md "Conventions" (paper eq. 3).  The exact solver, MAE's own
coefficients, MAE + FastSim and the equivalent ellipse all fill a
:class:`CreepCoefficients`, directly or from their forces at the unit
creepages (:func:`coefficients_from_unit_solutions`, or
:func:`coefficients_of_solver` which makes those solves).  Imports nothing of the
package: it sits below every solver.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol


@dataclass(frozen=True)
class CreepCoefficients:
    """Generalised creepage coefficients of an area (docs/guide_physics.md, paper eq. 3).

    ``Fx = -G (A/pi) C11 xi - G (A/pi) C12 eta - G (A/pi)^1.5 C13 phi``,
    ``Fy = -G (A/pi) C21 xi - G (A/pi) C22 eta - G (A/pi)^1.5 C23 phi``,
    ``Mz = G (A/pi)^1.5 C31 xi + G (A/pi)^1.5 C32 eta - G (A/pi)^2 C33 phi``
    (Kalker's signs: ``C32 = C23`` on an ellipse), about ``reference`` (m).
    ``area`` is ``A`` (m^2), the discrete area of the cells in contact.
    """

    C11: float
    C12: float
    C13: float
    C21: float
    C22: float
    C23: float
    C31: float
    C32: float
    C33: float
    area: float
    reference: tuple[float, float] = (0.0, 0.0)

    def as_dict(self) -> dict[str, float]:
        """Return the coefficients and the area by name."""
        names = ("C11", "C12", "C13", "C21", "C22", "C23", "C31", "C32", "C33", "area")
        return {k: getattr(self, k) for k in names}


#: unit xi, eta and phi (1/m): the creepages whose forces define the coefficients
UNIT_CREEPAGES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def coefficients_from_unit_solutions(
    area: float, unit: tuple[tuple[float, float, float], ...], *, shear_modulus: float = 1.0,
    reference: tuple[float, float] = (0.0, 0.0)
) -> CreepCoefficients:
    """Coefficients from ``(Fx, Fy, Mz)`` at unit ``xi``, unit ``eta`` and unit ``phi``.

    ``area``: ``A`` (m^2); ``shear_modulus``: the ``G`` (Pa) the unit
    solutions were computed with (1 Pa by convention).
    """
    c = math.sqrt(area / math.pi)
    g = shear_modulus
    (fx1, fy1, mz1), (fx2, fy2, mz2), (fx3, fy3, mz3) = unit
    return CreepCoefficients(
        C11=-fx1 / (g * c**2), C12=-fx2 / (g * c**2), C13=-fx3 / (g * c**3),
        C21=-fy1 / (g * c**2), C22=-fy2 / (g * c**2), C23=-fy3 / (g * c**3),
        C31=mz1 / (g * c**3), C32=mz2 / (g * c**3), C33=-mz3 / (g * c**4),
        area=area, reference=reference)


class Forces(Protocol):
    """What :func:`coefficients_of_solver`'s solve returns: ``fx``, ``fy`` (N), ``mz`` (N m)."""

    @property
    def fx(self) -> float: ...

    @property
    def fy(self) -> float: ...

    @property
    def mz(self) -> float: ...


def coefficients_of_solver(area: float, solve: Callable[[float, float, float], Forces], *,
                           reference: tuple[float, float] = (0.0, 0.0)) -> CreepCoefficients:
    """Return a method's coefficients from its solves at :data:`UNIT_CREEPAGES` (G = 1 Pa).

    ``solve(xi, eta, phi)``: the method in full adhesion with ``G = 1`` Pa
    and creepages about ``reference`` (m); ``area``: ``A`` (m^2).
    """
    unit = tuple(solve(*cr) for cr in UNIT_CREEPAGES)
    return coefficients_from_unit_solutions(area, tuple((r.fx, r.fy, r.mz) for r in unit),
                                            reference=reference)
