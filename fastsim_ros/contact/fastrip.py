"""FaStrip on a grid area: strip theory made three-dimensional by Kalker's linear theory.

FaStrip (Sichani, Enblom and Berg, "An alternative to FASTSIM for tangential
solution of the wheel-rail contact", Vehicle System Dynamics 54(6), 2016) is
the baseline a user would pick instead of FastSim: each lateral strip of the
patch is solved in closed form as a two-dimensional rolling contact (Carter's
solution, as in Kalker's 1967 strip theory), and the strips' elastic constant
is taken from Kalker's linear theory so that the three-dimensional creep
coefficients come out right.  On a non-elliptical patch every strip segment
is treated with its own local half-length (the non-elliptical FaStrip of
Sichani et al. that ANALYN feeds).

Provenance.  The paper's text could not be retrieved here (the search tool
holds no copy of it, nor of the ANALYN-FaStrip papers), so the equation
numbers of the paper are not quoted: each equation below is stated with its
derivation, and every one of them is pinned by an exactness test
(``test/test_contact_fastrip.py``).  Where this reading had to choose, the
choice and its reason are given.

Per strip segment ``j`` (cells of one row in contact without a gap):

(F1) local geometry: half-length ``a_j`` and centre ``x_j`` from the
     segment's cell faces, strip load per unit width ``P_j = sum p dx``
     (N/m), and the semi-elliptic strip pressure of that load,
     ``p_j(s) = p0_j sqrt(1 - s^2)``, ``p0_j = 2 P_j/(pi a_j)``, ``s = (x -
     x_j)/a_j``.  On a Hertzian patch this is the given pressure exactly
     (``1 - x^2/a^2 - y^2/b^2 = (1 - y^2/b^2)(1 - x^2/a_y^2)``).  Assumption of
     strip theory: the strip is a plane-strain rolling contact with a
     Hertzian pressure along it; FaStrip's traction bound is therefore
     ``mu p_j``, not the given pressure cell by cell (``bound="given"`` is
     the only bound it takes).
(F2) Carter's partial-slip solution in the strip, stick zone at the leading
     edge ``2 nu_j - 1 <= s <= 1`` (half-length ``k = 1 - nu_j``, centre
     ``nu_j``): ``|tau| = mu p0_j (sqrt(1 - s^2) - sqrt(k^2 - (s - nu_j)^2))``
     there and ``|tau| = mu p0_j sqrt(1 - s^2)`` in the slip zone behind it;
     the strip's force is ``mu P_j (1 - k^2)`` up to ``nu_j = 1``, ``mu P_j``
     beyond.  In the stick zone the difference is evaluated as
     ``2 nu sqrt(1 - s) / (sqrt(1 + s) + sqrt(1 + s - 2 nu))`` in effect
     (below ``nu = 1e-8`` by its first-order term ``nu sqrt((1-s)/(1+s))``,
     whose cell integrals are closed-form), so that vanishing creepage and
     ``mu -> infinity`` lose no digits.
(F3) the three-dimensional elastic constant: the strip's normalised creepage
     vector is ``nu_j = q_j / mu`` with
     ``q_x = a_j^2 (xi_c/L1 - phi (y_j - y_c)/L3) / P_j``,
     ``q_y = a_j^2 (eta_c/L2 + phi (x_j - x_c)/L3) / P_j``,
     ``L1..L3`` Kalker's flexibilities (docs/guide_physics.md "FastSim") of the patch's
     equivalent ellipse (:func:`~fastsim_ros.contact.equivalent.equivalent_ellipse`:
     area, centroid ``(x_c, y_c)``, second-moment ratio; Kalker's C from the
     package's tables), creepages moved to the centroid by the rigid-slip
     identity: every creepage that is constant along the strip.  Why: at
     vanishing creepage (F2) gives the strip force ``2 mu P_j nu_j = 2 a_j^2
     xi/L1``, which is FastSim's strip force in full adhesion; on an ellipse,
     summed over strips, that is Kalker's ``G a b C11 xi`` (and C22).
     Choice: Kalker's 1967 strip theory takes the strip's constant from plane
     strain (its known 25% error on round patches); FaStrip's point is to
     take it from the linear theory, and FastSim's L's are the one set of
     constants that do so strip by strip.
(F3b) the spin within the strip (the lateral rigid slip ``phi (x - x_j)``,
     which varies along it) is not strip theory's: FaStrip takes it from the
     simplified theory, FastSim's adhesion traction ``tau_y = -(phi/L3)
     (a_j^2 - (x - x_j)^2)/2``, so that the strips' lateral force under spin
     is FastSim's and, on an ellipse, Kalker's C23.  Choice, by evidence: the
     alternative of strip theory alone (the spin as the constant lateral
     creepage of the same full-adhesion force, Carter's law for it) was
     measured against the exact theory on the Hertzian ellipse a/b = 2/3
     (24 cells): 13.5% of mu N under pure spin, against 1.8% with (F3b);
     plane strain's answer to a creepage linear along the strip is the
     semi-elliptic traction, which saturates a whole strip at once, the
     spin error Kalker reported for strip theory.
(F4) the sum: Carter's traction (F2) opposes ``q_j`` (the vector form of
     Carter's solution, one direction per strip), (F3b) is added to it, and
     where the sum exceeds the bound ``mu p_j`` the cell slips, on the bound,
     in the simplified theory's direction (the strip marched from its
     leading edge, the trial traction ``tau_prev - (xi_c/L1 - phi (y -
     y_c)/L3, eta_c/L2 + phi (x - x_c)/L3) h``).  Without spin this is
     Carter's solution exactly; a pure creepage tends to ``mu N``.  Choice:
     strip theory has no direction field for the slip zone under spin; the
     simplified theory's is the one that goes with (F3b).

Discretisation: each cell's traction is the mean of (F2) and of (F3b) over the
cell (the stick/slip boundary may cut a cell), and the bound the mean of
``mu p_j``, so a strip's force in adhesion and in full slip is the closed
form whatever the cell size; a cell is reported as slipping when its centre
lies in Carter's slip zone or its traction is on the bound by (F4).  Strips of
several segments (a notch): each segment is a strip of its own, restarting at
its own leading edge.  Units: SI (m, Pa, N, N m; ``phi`` in 1/m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import (check_bound, check_creepages, check_friction,
                                        check_shear_modulus)
from fastsim_ros.contact.coefficients import CreepCoefficients, coefficients_of_solver
from fastsim_ros.contact.equivalent import EquivalentEllipse, equivalent_ellipse
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.fastsim import kalker_flexibility
from fastsim_ros.contact.tables import CoefficientTable
from fastsim_ros.contact.traction import Tractions, resultants

FloatArray = NDArray[np.float64]

#: below this normalised creepage (F2) is evaluated by its first-order term
SMALL_NU = 1e-8


@dataclass(frozen=True, eq=False)
class StripSegments:
    """The strip segments of an area: row ``j``, first and one-past-last column, per segment."""

    row: NDArray[np.int_]
    start: NDArray[np.int_]
    stop: NDArray[np.int_]


def strip_segments(area: GridArea) -> StripSegments:
    """Return every run of cells in contact along each row (the strips FaStrip solves)."""
    m = area.mask
    pad = np.zeros((m.shape[0], 1), dtype=bool)
    edges = np.diff(np.hstack([pad, m, pad]).astype(np.int8), axis=1)
    rs, starts = np.nonzero(edges == 1)
    re, stops = np.nonzero(edges == -1)
    # np.nonzero walks row-major: runs come in the same order in both
    if not np.array_equal(rs, re):
        raise InvalidInputError("inconsistent strip segments")  # cannot happen
    return StripSegments(rs, starts, stops)


@dataclass(frozen=True)
class FastripFlexibility:
    """Kalker's ``L1, L2, L3`` (m/Pa) of the patch's equivalent ellipse."""

    l1: float
    l2: float
    l3: float


@dataclass(frozen=True, eq=False)
class FastripResult:
    """Forces (N), ``Mz`` (N m) about the reference point, the ellipse, its L's and the field."""

    fx: float
    fy: float
    mz: float
    ellipse: EquivalentEllipse
    flexibility: FastripFlexibility
    traction: Tractions


def _half_disc(s: FloatArray) -> FloatArray:
    """Return ``A1(s) = int sqrt(1 - s^2) ds`` (from 0), ``s`` clipped to [-1, 1]."""
    s = np.clip(s, -1.0, 1.0)
    return 0.5 * (s * np.sqrt(1.0 - s * s) + np.arcsin(s))


def _disc(s: FloatArray, centre: FloatArray, radius: FloatArray) -> FloatArray:
    """Return ``int sqrt(r^2 - (s - c)^2) ds`` (from ``c``), clipped to the disc."""
    r = np.maximum(radius, 1e-300)
    u = np.clip((s - centre) / r, -1.0, 1.0)
    return 0.5 * r * r * (u * np.sqrt(1.0 - u * u) + np.arcsin(u))


def _adhesion_shape(s: FloatArray) -> FloatArray:
    """Return ``H(s) = sqrt(1 - s^2) + asin(s)``, the integral of ``sqrt((1-s)/(1+s))``."""
    s = np.clip(s, -1.0, 1.0)
    return np.sqrt(1.0 - s * s) + np.arcsin(s)


def _combine(area: GridArea, carter: FloatArray, ux: FloatArray, uy: FloatArray,
             spin: FloatArray, bound: FloatArray, xi_c: float, eta_c: float, phi: float,
             centroid: tuple[float, float],
             flex: FastripFlexibility) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
    """Return ``tau_x``, ``tau_y`` (Pa) and the slip flags: Carter's part plus spin's (F4).

    ``carter``: each cell's mean traction magnitude of the strip's Carter
    solution (F2), opposing ``(ux, uy)``; ``spin``: the cell's mean lateral
    traction of the spin within the strip (F3b); ``bound``: the cell's mean
    ``mu p_j``.  Where the sum exceeds the bound the cell slips, on the bound,
    in the simplified theory's direction: each strip marched from its
    leading edge, the trial traction ``tau_prev - (xi_c/L1 - phi (y -
    y_c)/L3, eta_c/L2 + phi (x - x_c)/L3) h`` (first step ``h = dx/2``, then
    ``dx``; ``phi x`` at the middle of the step, docs/guide_physics.md "FastSim").
    """
    x_c, y_c = centroid
    ny, nx = carter.shape
    dx = area.dx
    inside_all = area.mask
    rate_x = xi_c / flex.l1 - phi * (area.y - y_c) / flex.l3
    tx = np.zeros(ny)
    ty = np.zeros(ny)
    out_x = np.zeros((ny, nx))
    out_y = np.zeros((ny, nx))
    slip = np.zeros((ny, nx), dtype=bool)
    prev_in = np.zeros(ny, dtype=bool)
    for i in range(nx - 1, -1, -1):
        inside = inside_all[:, i]
        step = np.where(prev_in, dx, 0.5 * dx)
        x_mid = area.x[i] - x_c + 0.5 * step
        cand_x = -carter[:, i] * ux[:, i]
        cand_y = -carter[:, i] * uy[:, i] + spin[:, i]
        over = np.hypot(cand_x, cand_y) > bound[:, i] * (1.0 + 1e-9)
        trial_x = tx - rate_x * step
        trial_y = ty - (eta_c / flex.l2 + phi * x_mid / flex.l3) * step
        norm = np.hypot(trial_x, trial_y)
        ok = norm > 0.0
        safe = np.where(ok, norm, 1.0)
        cn = np.maximum(np.hypot(cand_x, cand_y), 1e-300)
        dir_x = np.where(ok, trial_x / safe, cand_x / cn)
        dir_y = np.where(ok, trial_y / safe, cand_y / cn)
        tx = np.where(inside, np.where(over, bound[:, i] * dir_x, cand_x), 0.0)
        ty = np.where(inside, np.where(over, bound[:, i] * dir_y, cand_y), 0.0)
        out_x[:, i] = tx
        out_y[:, i] = ty
        slip[:, i] = over & inside
        prev_in = inside
    return out_x, out_y, slip


def fastrip_flexibility(area: GridArea, table: CoefficientTable,
                        shear_modulus: float) -> tuple[EquivalentEllipse, FastripFlexibility]:
    """Return the equivalent ellipse of the area and its Kalker flexibilities (F3)."""
    check_shear_modulus(shear_modulus)
    e = equivalent_ellipse(area)
    c11, c22, c23 = table.kalker(e.a / e.b)
    l1, l2, l3 = kalker_flexibility(e.a, e.b, c11, c22, c23, shear_modulus)
    return e, FastripFlexibility(l1, l2, l3)


def fastrip(area: GridArea, xi: float, eta: float, phi: float, *, mu: float,
            table: CoefficientTable, shear_modulus: float,
            reference: tuple[float, float] = (0.0, 0.0), bound: str = "given") -> FastripResult:
    """Solve FaStrip on ``area`` at ``xi``, ``eta`` (1) and ``phi`` (1/m) about ``reference`` (m).

    ``mu``: Coulomb's friction coefficient; ``table``: the coefficient tables
    at the material's Poisson ratio; ``shear_modulus``: combined ``G`` (Pa).
    ``bound`` must be ``"given"`` (F1: the strip's own Hertzian pressure of
    the given load); ``"parabolic"`` is refused.  ``Mz`` is about ``reference``.
    """
    check_creepages(xi, eta, phi)
    mu = check_friction(mu)
    if check_bound(bound):
        raise InvalidInputError("FaStrip takes the strips' Hertzian pressure of the given load "
                                "(bound 'given'), not the parabolic bound")
    ell, flex = fastrip_flexibility(area, table, shear_modulus)
    x_c, y_c = ell.x_c, ell.y_c
    xp, yp = reference
    # creepages at the centroid (the rigid-slip identity, docs/guide_physics.md "MAE")
    xi_c = xi + phi * (yp - y_c)
    eta_c = eta - phi * (xp - x_c)
    seg = strip_segments(area)
    dx = area.dx
    x = area.x
    p = area.pressure
    half = 0.5 * (seg.stop - seg.start) * dx                      # a_j
    centre = 0.5 * (x[seg.start] + x[seg.stop - 1])               # x_j
    csum = np.hstack([np.zeros((area.ny, 1)), np.cumsum(p, axis=1)])
    load = (csum[seg.row, seg.stop] - csum[seg.row, seg.start]) * dx   # P_j (N/m)
    p0 = 2.0 * load / (math.pi * half)
    y_j = area.y[seg.row]
    # (F3): the strips' normalised creepages times mu
    qx = half**2 * (xi_c / flex.l1 - phi * (y_j - y_c) / flex.l3) / load
    qy = half**2 * (eta_c / flex.l2 + phi * (centre - x_c) / flex.l3) / load
    qn = np.hypot(qx, qy)
    nu = qn / mu
    # every cell in contact, with its segment
    counts = seg.stop - seg.start
    k_seg = np.repeat(np.arange(seg.row.size), counts)
    offsets = np.arange(k_seg.size) - np.repeat(np.cumsum(counts) - counts, counts)
    cols = seg.start[k_seg] + offsets
    rows = seg.row[k_seg]
    a_k, x_k, nu_k = half[k_seg], centre[k_seg], nu[k_seg]
    s_lo = np.clip((x[cols] - 0.5 * dx - x_k) / a_k, -1.0, 1.0)
    s_hi = np.clip((x[cols] + 0.5 * dx - x_k) / a_k, -1.0, 1.0)
    t = np.minimum(2.0 * nu_k - 1.0, 1.0)                         # stick/slip boundary
    # slip part of each cell: mu p0 int sqrt(1 - s^2) over [s_lo, min(s_hi, t)]
    slip_hi = np.minimum(s_hi, t)
    slip_int = np.where(slip_hi > s_lo, _half_disc(slip_hi) - _half_disc(s_lo), 0.0)
    # stick part: over [max(s_lo, t), s_hi], in units of p0 (mu nu = |q| in the small branch)
    st_lo = np.maximum(s_lo, t)
    has_stick = s_hi > st_lo
    k_rad = 1.0 - nu_k
    with np.errstate(over="ignore", invalid="ignore"):  # only read where nu > SMALL_NU
        exact_part = mu * ((_half_disc(s_hi) - _half_disc(st_lo))
                           - (_disc(s_hi, nu_k, k_rad) - _disc(st_lo, nu_k, k_rad)))
    small_part = qn[k_seg] * (_adhesion_shape(s_hi) - _adhesion_shape(st_lo))
    stick_int = np.where(has_stick, np.where(nu_k > SMALL_NU, exact_part, small_part), 0.0)
    scale = p0[k_seg] * a_k / dx                                  # mean over the cell
    stick_mag = np.maximum(stick_int, 0.0) * scale
    slip_mag = mu * slip_int * scale
    # (F3b): the spin within each strip, FastSim's adhesion traction, cell means:
    # tau_y = -(phi/L3) (a_j^2 - (x - x_j)^2)/2
    u_lo = x[cols] - 0.5 * dx - x_k
    u_hi = x[cols] + 0.5 * dx - x_k
    lo_c = np.maximum(u_lo, -a_k)
    hi_c = np.minimum(u_hi, a_k)
    spin_mean = -(phi / flex.l3) * 0.5 * (a_k**2 * (hi_c - lo_c)
                                          - (hi_c**3 - lo_c**3) / 3.0) / dx
    bound_mean = mu * p0[k_seg] * (_half_disc(s_hi) - _half_disc(s_lo)) * a_k / dx
    with np.errstate(invalid="ignore", divide="ignore"):
        ux = np.where(qn > 0.0, qx / np.where(qn > 0.0, qn, 1.0), 0.0)[k_seg]
        uy = np.where(qn > 0.0, qy / np.where(qn > 0.0, qn, 1.0), 0.0)[k_seg]
    grids = [np.zeros(p.shape) for _ in range(5)]
    for g2, v in zip(grids, (stick_mag + slip_mag, ux, uy, spin_mean, bound_mean)):
        g2[rows, cols] = v
    tau_x, tau_y, slip = _combine(area, grids[0], grids[1], grids[2], grids[3], grids[4],
                                  xi_c, eta_c, phi, (x_c, y_c), flex)
    s_mid = (x[cols] - x_k) / a_k
    slip[rows, cols] |= s_mid < t
    fx, fy, mz = resultants(area, tau_x, tau_y, reference)
    return FastripResult(fx, fy, mz, ell, flex, Tractions(tau_x, tau_y, slip, fx, fy, mz))


def fastrip_coefficients(area: GridArea, table: CoefficientTable, *,
                         reference: tuple[float, float] = (0.0, 0.0)) -> CreepCoefficients:
    """Return FaStrip's generalised coefficients at vanishing creepage (full adhesion).

    Normalised with the area's own discrete area, as the exact theory's are.
    """
    unit_load = area.with_load(1.0)
    # so large a friction coefficient that no strip has a slip zone: full adhesion
    return coefficients_of_solver(
        area.area, lambda xi, eta, phi: fastrip(
            unit_load, xi, eta, phi, mu=1e300, table=table, shear_modulus=1.0,
            reference=reference), reference=reference)
