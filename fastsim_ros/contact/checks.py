"""Checks of the solvers' inputs: each check in one place, for every solver.

The numpy reference (:mod:`~fastsim_ros.contact.fastsim`,
:mod:`~fastsim_ros.contact.mae`, :mod:`~fastsim_ros.contact.equivalent`),
the exact and normal solvers and the compiled fast path
(:mod:`~fastsim_ros.contact.compiled`) refuse bad values here, with the same
messages and the exceptions of :mod:`~fastsim_ros.contact.errors`.  Only what
must run inside a compiled loop (a batch's per-item creepages and ``mu``, the
pressure scan) is repeated in :mod:`~fastsim_ros.contact.kernels`, which
reports it by status code and is turned into the same messages by
:mod:`~fastsim_ros.contact.compiled`.

Imports nothing but :mod:`~fastsim_ros.contact.errors`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from fastsim_ros.contact.errors import InvalidInputError

SplitRule = Literal["auto", "widest_strip", "centroid"]
Bound = Literal["given", "parabolic"]
#: MAE's split rules (:func:`fastsim_ros.contact.mae.split_face`)
SPLIT_RULES: tuple[SplitRule, ...] = ("auto", "widest_strip", "centroid")
#: traction bounds (:func:`fastsim_ros.contact.fastsim.traction_bound`)
BOUNDS: tuple[Bound, ...] = ("given", "parabolic")


def check_poisson_ratio(nu: float) -> float:
    """Return ``nu``; refuse a Poisson ratio outside [0, 0.5]."""
    if not (math.isfinite(nu) and 0.0 <= nu <= 0.5):
        raise InvalidInputError(f"nu must lie in [0, 0.5], got {nu}")
    return nu


def check_shear_modulus(shear_modulus: float) -> float:
    """Return ``shear_modulus`` (Pa); refuse a non-positive or non-finite one."""
    if not (math.isfinite(shear_modulus) and shear_modulus > 0.0):
        raise InvalidInputError(f"shear modulus must be positive, got {shear_modulus}")
    return shear_modulus


def check_material(nu: float, shear_modulus: float) -> None:
    """Refuse a Poisson ratio outside [0, 0.5] or a non-positive shear modulus (Pa)."""
    check_poisson_ratio(nu)
    check_shear_modulus(shear_modulus)


@dataclass(frozen=True)
class Material:
    """Combined elastic constants of two quasi-identical bodies, checked once when made.

    ``nu``: combined Poisson ratio in [0, 0.5]; ``shear_modulus``: combined
    ``G`` (Pa), ``2/G = 1/G1 + 1/G2``.
    """

    nu: float
    shear_modulus: float

    def __post_init__(self) -> None:
        check_material(self.nu, self.shear_modulus)


def check_creepages(xi: float, eta: float, phi: float) -> None:
    """Refuse non-finite creepages ``xi``, ``eta`` (1) or spin ``phi`` (1/m)."""
    for name, v in (("xi", xi), ("eta", eta), ("phi", phi)):
        if not math.isfinite(v):
            raise InvalidInputError(f"{name} must be finite")


def check_friction(mu: float) -> float:
    """Return ``mu``; refuse a friction coefficient that is not positive and finite."""
    if not (math.isfinite(mu) and mu > 0.0):
        raise InvalidInputError(f"mu must be positive, got {mu}")
    return mu


def check_bound(bound: str) -> bool:
    """Return whether the traction bound ``bound`` is the parabolic one; refuse unknown names."""
    if bound not in BOUNDS:
        raise InvalidInputError(f"unknown traction bound {bound!r}: given or parabolic")
    return bound == "parabolic"


def check_split_rule(rule: str) -> SplitRule:
    """Return ``rule``; refuse a name that is not one of :data:`SPLIT_RULES`."""
    if rule not in SPLIT_RULES:
        raise InvalidInputError(f"unknown split rule {rule!r}: auto, widest_strip or centroid")
    return rule  # type: ignore[return-value]


def check_positive(**values: float) -> None:
    """Refuse any of the named values that is not positive and finite (``a_over_b``: ``a/b``)."""
    for name, v in values.items():
        if not (math.isfinite(v) and v > 0.0):
            raise InvalidInputError(f"{name.replace('_over_', '/')} must be positive and "
                                    f"finite, got {v}")
