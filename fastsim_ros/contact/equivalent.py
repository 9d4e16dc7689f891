"""The equivalent-ellipse baseline: plain FastSim on an ellipse standing in for the patch.

What a user without MAE would do: replace the patch by the ellipse with its
area and with ``a/b`` from its second moments about the centroid
(``a/b = sqrt(Ixx/Iyy)``, exact for an ellipse), centred on the centroid,
and run Kalker's FastSim on that ellipse with Kalker's flexibilities and a
bound for the same load: Hertzian (``bound="given"``, the ellipse's own
pressure, since the patch's cannot be carried over to another area) or
Kalker's parabolic one (``"parabolic"``).  The patch's shape beyond its second moments is lost:
that is what MAE is measured against.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fastsim_ros.contact.area import GridArea, ellipse
from fastsim_ros.contact.coefficients import CreepCoefficients, coefficients_of_solver
from fastsim_ros.contact.fastsim import (StripFlexibility, fastsim, kalker_flexibility,
                                         traction_bound)
from fastsim_ros.contact.friction import ConstantFriction, FrictionLaw, resolve
from fastsim_ros.contact.rules import ellipse_cells
from fastsim_ros.contact.traction import Tractions
from fastsim_ros.contact.tables import CoefficientTable


@dataclass(frozen=True)
class EquivalentEllipse:
    """Centre ``(x_c, y_c)`` and semi-axes ``a`` (along x), ``b`` (m)."""

    x_c: float
    y_c: float
    a: float
    b: float


def equivalent_ellipse(area: GridArea) -> EquivalentEllipse:
    """Return the ellipse of the area's size, centroid and second-moment ratio."""
    mask = area.mask
    jj, ii = np.nonzero(mask)
    x = area.x[ii]
    y = area.y[jj]
    x_c, y_c = float(x.mean()), float(y.mean())
    # second moments of the cells, each cell's own dx^2/12 included
    ixx = float(np.mean((x - x_c) ** 2)) + area.dx**2 / 12.0
    iyy = float(np.mean((y - y_c) ** 2)) + area.dy**2 / 12.0
    g = math.sqrt(ixx / iyy)
    a = math.sqrt(area.area * g / math.pi)
    return EquivalentEllipse(x_c, y_c, a, a / g)


@dataclass(frozen=True)
class ReducedProblem:
    """A solve with a slope reduction, as the solver runs it.

    ``xi, eta`` (1), ``phi`` (1/m): the creepages times ``k``; ``friction``:
    constant friction at the law's coefficient at the rigid slip velocity;
    ``mu_ratio``: that coefficient over the law's ``mu_s`` (what scales a
    traction bound computed with ``mu_s``); ``k``: the factor (1).
    """

    xi: float
    eta: float
    phi: float
    friction: FrictionLaw
    mu_ratio: float
    k: float


def reduce_slope(area: GridArea, xi: float, eta: float, phi: float, law: FrictionLaw,
                 speed: float | None, *, table: CoefficientTable,
                 shear_modulus: float) -> ReducedProblem:
    """Return the problem a solve runs under ``law``'s slope reduction on ``area``.

    The modified FastSim of Spiryagin et al.
    (:mod:`~fastsim_ros.contact.slope_reduction`): ``k`` on the area's
    equivalent ellipse with Kalker's ``C11`` at its ``a/b`` (``table``), the
    area's load, ``shear_modulus`` (Pa); ``speed``: ``|V|`` (m/s).
    """
    e = equivalent_ellipse(area)
    c11 = table.kalker(e.a / e.b)[0]
    k, mu = law.reduced(xi, eta, phi, speed, a=e.a, b=e.b, c11=c11,
                        shear_modulus=shear_modulus, load=area.load)
    return ReducedProblem(k * xi, k * eta, k * phi, ConstantFriction(mu), mu / law.mu_s, k)


@dataclass(frozen=True, eq=False)
class EquivalentResult:
    """Forces (N), ``Mz`` (N m) about the reference point, the ellipse and its solve."""

    fx: float
    fy: float
    mz: float
    ellipse: EquivalentEllipse
    grid: GridArea
    traction: Tractions


def equivalent_fastsim(area: GridArea, xi: float, eta: float, phi: float, *,
                       mu: float | None = None, table: CoefficientTable, shear_modulus: float,
                       reference: tuple[float, float] = (0.0, 0.0), bound: str = "given",
                       cells: int | None = None, friction: FrictionLaw | None = None,
                       speed: float | None = None) -> EquivalentResult:
    """Plain FastSim on the area's equivalent ellipse, load ``N`` of the area.

    The ellipse is discretised on ``cells`` x ``cells`` cells over its bounding
    box (default: as many cells in contact as the area has, :func:`ellipse_cells`).
    ``friction``: the law (default ``ConstantFriction(mu)``; ``mu``, if also
    given, must be its ``mu_s``; its slope reduction, if any, applied by
    :func:`reduce_slope`); ``speed``: ``|V|`` (m/s) for a slip-dependent law.
    """
    law = resolve(mu, friction)
    if law.reduces_slope:
        red = reduce_slope(area, xi, eta, phi, law, speed, table=table,
                           shear_modulus=shear_modulus)
        xi, eta, phi, law, speed = red.xi, red.eta, red.phi, red.friction, None
    e = equivalent_ellipse(area)
    n = cells or ellipse_cells(int(np.count_nonzero(area.mask)))
    grid = ellipse(e.a, e.b, nx=n, ny=n, load=area.load).shifted(e.x_c, e.y_c)
    g = traction_bound(grid, law.mu_s, bound=bound)
    c11, c22, c23 = table.kalker(e.a / e.b)
    l1, l2, l3 = kalker_flexibility(e.a, e.b, c11, c22, c23, shear_modulus)
    ones = np.ones(grid.ny)
    flex = StripFlexibility(l1 * ones, l2 * ones, l3 * ones, l3 * ones)
    res = fastsim(grid, xi, eta, phi, bound=g, flexibility=flex, sweep_point=(e.x_c, e.y_c),
                  reference=reference, friction=law, speed=speed)
    return EquivalentResult(res.fx, res.fy, res.mz, e, grid, res)


def equivalent_coefficients(area: GridArea, table: CoefficientTable, *,
                            reference: tuple[float, float] = (0.0, 0.0)) -> CreepCoefficients:
    """Return the generalised coefficients of equivalent-ellipse FastSim in full adhesion.

    Normalised with the area's own discrete area, as the exact theory's are.
    """
    unit_load = area.with_load(1.0)
    # a friction coefficient so large that no cell reaches the bound: full adhesion
    return coefficients_of_solver(
        area.area, lambda xi, eta, phi: equivalent_fastsim(
            unit_load, xi, eta, phi, mu=1e300, table=table, shear_modulus=1.0,
            reference=reference), reference=reference)
