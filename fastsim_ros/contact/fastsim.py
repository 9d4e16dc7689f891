"""Kalker's simplified theory (FASTSIM) on a grid area.

Assumption of the simplified theory: the surface displacement is proportional
to the local traction, ``u_i = L_i tau_i``; in the steady state a particle's
traction then grows, while it adheres, by the rigid slip times ``1/L`` per
unit rolling distance, and is capped by the traction bound ``g = mu p``
where it slips (Kalker 1982; METHOD.md section 2).

The sweep here is general enough for plain FastSim and for MAE: each strip
``j`` has its own flexibilities, and the slip increments per unit rolling
distance are

    d tau_x = -(xi/L1_j - phi (y_j - y_s)/Ls_j)             (spin via Ls)
    d tau_y = -(eta/L2_j + phi (x - x_c)/L3_j)

with ``Ls = L3`` and ``(x_c, y_s)`` the reference point in plain FastSim,
and ``Ls = L4`` about the split point ``S`` in MAE (METHOD.md section 3.7).

Discretisation (pinned by METHOD.md section 2): a cell is in contact where its
pressure is positive; each segment of a strip starts from zero traction at the
front face of its first cell; tractions live at cell centres, so the first
step is ``dx/2`` and every later one ``dx``; ``phi x`` is taken at the middle
of each step.

Slip-dependent friction (:mod:`~fastsim_ros.contact.friction`, bound
``g(v) = g_s ratio(v)``, ``g_s = mu_s p`` the static bound): see
:func:`slipping_bound` for the scalar equation each slipping cell solves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact import rules
from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import check_bound, check_creepages, check_friction
from fastsim_ros.contact.friction import FrictionLaw, check_speed
from fastsim_ros.contact.traction import Tractions, resultants

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class StripFlexibility:
    """Flexibilities of each strip (m/Pa), shape ``(ny,)``; ``spin`` is L3 or MAE's L4.

    ``spin`` may be ``inf`` (no spin term in ``tau_x``, e.g. ``c13 = 0``).
    """

    l1: FloatArray
    l2: FloatArray
    l3: FloatArray
    spin: FloatArray


def kalker_flexibility(a: float, b: float, c11: float, c22: float, c23: float,
                       shear_modulus: float) -> tuple[float, float, float]:
    """Kalker's ``(L1, L2, L3)`` (m/Pa) of an ellipse: FastSim = linear theory in adhesion.

    ``L1 = 8a/(3 G C11)``, ``L2 = 8a/(3 G C22)``, ``L3 = pi a sqrt(a/b)/(4 G C23)``.
    """
    return (8.0 * a / (3.0 * shear_modulus * c11), 8.0 * a / (3.0 * shear_modulus * c22),
            math.pi * a * math.sqrt(a / b) / (4.0 * shear_modulus * c23))


def traction_bound(area: GridArea, mu: float, *, bound: str = "given") -> FloatArray:
    """Return the traction bound ``g`` (Pa) on the area's cells.

    ``bound="given"``: ``mu p`` with the area's pressure.  ``"parabolic"``:
    ``mu N p^2 / sum(p^2 dA)``, the same load with the pressure squared.  On a
    Hertzian patch, ``p0 sqrt(1 - x^2/a^2 - y^2/b^2)``, that is exactly
    Kalker's parabolic ``2N/(pi a b) (1 - x^2/a^2 - y^2/b^2)``, the profile
    that makes FastSim's saturation curve agree with the exact theory; on a
    non-Hertzian patch it keeps every cell in contact and the shape of the
    given pressure.
    """
    check_friction(mu)
    p = np.asarray(area.pressure)
    if not check_bound(bound):
        return mu * p
    p2 = p * p
    return mu * area.load * p2 / (float(p2.sum()) * area.cell_area)


#: Newton's stopping rule in :func:`slipping_bound` (shared with the kernels): a step
#: below ``NEWTON_TOL * g_s``, at most ``NEWTON_MAX`` steps
NEWTON_TOL, NEWTON_MAX = rules.NEWTON_TOL, rules.NEWTON_MAX


def slipping_bound(m: FloatArray, gs: FloatArray, q: FloatArray,
                   law: FrictionLaw) -> FloatArray:
    """Return the traction magnitude ``r`` (Pa) of slipping cells under a slip-dependent law.

    The FastSim step of a cell: the trial (adhesion) traction ``t* = tau_prev
    - (w / L) h`` (``h`` the step, m; ``w`` the rigid slip per unit rolling
    distance) exceeds the static bound, ``m = |t*| > g_s``.  The cell slips:
    ``tau = r t*/m`` (radial return, as with constant friction), and its
    local slip per unit rolling distance follows from the traction increment,
    ``s = w + L (tau - tau_prev)/h = L (tau - t*)/h`` (componentwise, ``L =
    (L1, L2)``; zero in adhesion), so ``|s| = (m - r) |L t*| / (m h)`` and the
    slip velocity is ``v = |V| |s| = q (m - r)`` with ``q = |V| |L t*|/(m h)``
    (m/(s Pa)).  The bound and the slip must agree:

        F(r) = r - g_s ratio(q (m - r)) = 0,    0 <= r <= m.

    ``F(0) = -g_s ratio(q m) < 0`` and ``F(m) = m - g_s > 0``, so a root lies
    in ``(0, m)``.  It is unique when ``ratio`` is convex in ``v`` (constant
    and exponential laws): then ``F`` is concave in ``r``, and a concave
    function that is negative at 0 and positive at ``m`` crosses zero once
    (on ``(r1, m]`` it lies above the chord from ``(r1, 0)`` to ``(m,
    F(m))``).  For a non-increasing law, ``F`` is also negative at ``r0 =
    g_s ratio(q m)``; Newton from there climbs monotonically to the root
    (``F`` concave: each tangent lies above ``F``, and ``F' > 0`` left of the
    root), kept inside the bracket ``[r0, m]`` (a bisection step where a
    Newton step would leave it).  It stops after a step below
    :data:`NEWTON_TOL` ``* g_s`` (at most :data:`NEWTON_MAX` steps; 2-4 are
    usual).  ``m``, ``gs`` (Pa), ``q`` (m/(s Pa)): arrays of the slipping
    cells.

    A cell within the static bound (``m <= g_s``) may, with a falling law,
    have two slipping roots besides adhesion (``F`` concave, ``F(m) <= 0``):
    see :func:`kinetic_bound` for which one is taken and when.
    """
    lo = gs * law.ratio(q * m)
    hi = m.copy()
    r = lo.copy()
    active = np.ones(m.shape, dtype=bool)
    for _ in range(NEWTON_MAX):
        if not active.any():
            break
        v = q * (m - r)
        f = r - gs * law.ratio(v)
        df = 1.0 + gs * q * law.ratio_slope(v)
        lo = np.where(active & (f <= 0.0), r, lo)
        hi = np.where(active & (f >= 0.0), r, hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            cand = np.where(df > 0.0, r - f / df, np.inf)
        outside = ~((cand > lo) & (cand < hi))
        cand = np.where(outside, 0.5 * (lo + hi), cand)
        cand = np.where(f == 0.0, r, cand)
        done = np.abs(cand - r) <= NEWTON_TOL * gs
        r = np.where(active, cand, r)
        active &= ~done
    return r


def kinetic_bound(m: FloatArray, gs: FloatArray, q: FloatArray,
                  law: FrictionLaw) -> FloatArray:
    """Return ``r`` (Pa) of cells within the static bound that keep slipping; ``nan``: adhesion.

    Applied to a cell (``m = |t*| <= g_s``) whose predecessor in its strip
    slipped: kinetic friction keeps it slipping if ``F(r) = r - g_s ratio(q
    (m - r))`` (:func:`slipping_bound`) has a root in ``(0, m)``.  ``F`` is
    concave with ``F(m) <= 0``, so it has none or two; the one taken is the
    smaller, ``r1``, where ``F`` rises through zero (``F' > 0``: the same
    branch as the unique root above the static bound, the root continuous in
    ``m`` across ``g_s``; on a smooth slip zone it gives ``|s|`` near the
    rigid slip, as the continuous theory).  Newton from ``r0 = g_s ratio(q
    m)`` (``F(r0) <= 0``) climbs to ``r1``; it has none if a step reaches
    ``m`` or ``F' <= 0`` first (``F`` stays negative: the cell adheres).
    Without this hysteresis a slip zone would alternate cell by cell between
    adhesion and slip, each new slip a jump from ``mu_s`` to kinetic friction
    over one cell, whose slip velocity grows as the cell shrinks.
    """
    r = gs * law.ratio(q * m)
    out = np.full(m.shape, np.nan)
    active = np.ones(m.shape, dtype=bool)
    for _ in range(NEWTON_MAX):
        if not active.any():
            break
        v = q * (m - r)
        f = r - gs * law.ratio(v)
        df = 1.0 + gs * q * law.ratio_slope(v)
        found = active & (f >= 0.0)
        out = np.where(found, r, out)
        active &= ~found
        with np.errstate(divide="ignore", invalid="ignore"):
            cand = np.where(df > 0.0, r - f / df, np.inf)
        active &= cand < m
        done = active & (np.abs(cand - r) <= NEWTON_TOL * gs)
        out = np.where(done, cand, out)
        active &= ~done
        r = np.where(active, cand, r)
    return out


def sweep(bound: FloatArray, x: FloatArray, dx: float, xi: FloatArray | float,
          eta: FloatArray | float, phi: float, flex: StripFlexibility, y_rel: FloatArray,
          x_c: float, *, friction: FrictionLaw | None = None,
          speed: float | None = None) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
    """March every strip from its leading edge; the readable reference of the kernel.

    ``bound``: ``g`` (Pa), ``(ny, nx)``, zero outside the contact (with a
    slip-dependent ``friction`` law: the static bound ``g_s``, at ``v =
    0``); ``x``: cell-centre ``x`` (m); ``xi``, ``eta``: creepages at the
    sweep's reference point (scalars or one per strip); ``y_rel``: ``y_j -
    y_s`` (m); ``speed``: the rolling speed ``|V|`` (m/s), needed by a
    slip-dependent law (each slipping cell then solves
    :func:`slipping_bound`).  Returns ``tau_x``, ``tau_y`` (Pa) and the slip
    flags.  Vectorised over the strips, marched over the columns.
    """
    law = friction if friction is not None and friction.slip_dependent else None
    v_roll = check_speed(speed) if law is not None else 0.0
    ny, nx = bound.shape
    tx = np.zeros(ny)
    ty = np.zeros(ny)
    out_x = np.zeros((ny, nx))
    out_y = np.zeros((ny, nx))
    slip = np.zeros((ny, nx), dtype=bool)
    # constant part of each strip's rates (1/m * Pa... per metre rolled): Pa/m
    rate_x = np.asarray(xi) / flex.l1 - phi * y_rel / flex.spin
    rate_y0 = np.asarray(eta) / flex.l2
    rate_yx = phi / flex.l3
    prev_in = np.zeros(ny, dtype=bool)
    prev_slip = np.zeros(ny, dtype=bool)
    for i in range(nx - 1, -1, -1):
        g = bound[:, i]
        inside = g > 0.0
        # first cell of a segment: half a step from its front face
        step = np.where(prev_in, dx, 0.5 * dx)
        x_mid = x[i] - x_c + 0.5 * step
        tx = np.where(inside, tx - rate_x * step, 0.0)
        ty = np.where(inside, ty - (rate_y0 + rate_yx * x_mid) * step, 0.0)
        mag = np.hypot(tx, ty)
        over = mag > g
        if law is not None and over.any():
            m = mag[over]
            # |L t*| / m: the slip per unit of the traction cut back (componentwise L1, L2)
            lt = np.hypot(flex.l1[over] * tx[over], flex.l2[over] * ty[over])
            q = v_roll * lt / (m * step[over])
            g = g.copy()
            g[over] = slipping_bound(m, g[over], q, law)
        if law is not None:
            keep = inside & ~over & prev_slip & prev_in & (mag > 0.0)
            if keep.any():
                m = mag[keep]
                lt = np.hypot(flex.l1[keep] * tx[keep], flex.l2[keep] * ty[keep])
                r = kinetic_bound(m, g[keep], v_roll * lt / (m * step[keep]), law)
                sliding = np.zeros(ny, dtype=bool)
                sliding[keep] = ~np.isnan(r)
                if sliding.any():
                    g = g.copy()
                    g[sliding] = r[~np.isnan(r)]
                    over = over | sliding
        scale = np.where(over, g / np.where(over, mag, 1.0), 1.0)
        tx = tx * scale
        ty = ty * scale
        out_x[:, i] = tx
        out_y[:, i] = ty
        slip[:, i] = over & inside
        prev_in = inside
        prev_slip = over & inside
    return out_x, out_y, slip


def fastsim(area: GridArea, xi: float, eta: float, phi: float, *, bound: FloatArray,
            flexibility: StripFlexibility, sweep_point: tuple[float, float] = (0.0, 0.0),
            reference: tuple[float, float] = (0.0, 0.0), friction: FrictionLaw | None = None,
            speed: float | None = None) -> Tractions:
    """Solve FastSim on ``area``, creepages ``xi``, ``eta``, ``phi`` (1/m) about ``reference``.

    ``sweep_point`` ``(x_c, y_s)`` is the point the strips' rates refer to
    (the reference point itself in plain FastSim, MAE's ``S``); creepages are
    moved to it by the rigid-slip identity.  ``Mz`` is about ``reference``.
    ``bound`` is the static bound ``g_s`` (Pa) of a slip-dependent
    ``friction`` law (whose ``mu_s`` made it); ``speed``: ``|V|`` (m/s).
    """
    check_creepages(xi, eta, phi)
    xc, ys = sweep_point
    xp, yp = reference
    xi_s = xi + phi * (yp - ys)
    eta_s = eta - phi * (xp - xc)
    tx, ty, slip = sweep(bound, area.x, area.dx, xi_s, eta_s, phi, flexibility,
                         area.y - ys, xc, friction=friction, speed=speed)
    return Tractions(tx, ty, slip, *resultants(area, tx, ty, reference))
