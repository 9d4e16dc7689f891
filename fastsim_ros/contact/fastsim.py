"""Kalker's simplified theory (FASTSIM) on a grid area.

Assumption of the simplified theory: the surface displacement is proportional
to the local traction, ``u_i = L_i tau_i``; in the steady state a particle's
traction then grows, while it adheres, by the rigid slip times ``1/L`` per
unit rolling distance, and is capped by the traction bound ``g = mu p``
where it slips (Kalker 1982; docs/guide_physics.md "FastSim").

The sweep here is general enough for plain FastSim and for MAE: each strip
``j`` has its own flexibilities, and the slip increments per unit rolling
distance are

    d tau_x = -(xi/L1_j - phi (y_j - y_s)/Ls_j)             (spin via Ls)
    d tau_y = -(eta/L2_j + phi (x - x_c)/L3_j)

with ``Ls = L3`` and ``(x_c, y_s)`` the reference point in plain FastSim,
and ``Ls = L4`` about the split point ``S`` in MAE (docs/guide_physics.md "MAE").

Discretisation (pinned by docs/guide_physics.md "FastSim"): a cell is in contact where its
pressure is positive; each segment of a strip starts from zero traction at the
front face of its first cell; tractions live at cell centres, so the first
step is ``dx/2`` and every later one ``dx``; ``phi x`` is taken at the middle
of each step.

Slip rule of a cell over the bound: ``radial`` (Kalker's: the adhesion
trial scaled back onto the bound) or ``rigid_slip`` (the traction opposite
to the cell's slip with FastSim's compliance and the rigid slip,
:func:`~fastsim_ros.contact.rules.rigid_slip_return`; the second MAE
method's, :mod:`~fastsim_ros.contact.mae_calibrated`).

Slip-dependent friction (:mod:`~fastsim_ros.contact.friction`, bound
``g(v) = g_s ratio(v)``, ``g_s = mu_s p`` the static bound): see
:func:`slip_ratio` for the rule each slipping cell follows (its slip taken at
the friction ratio of its upstream neighbour).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import check_bound, check_creepages, check_friction
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.friction import FrictionLaw, check_speed
from fastsim_ros.contact.rules import rigid_slip_return
from fastsim_ros.contact.traction import Tractions, resultants

FloatArray = NDArray[np.float64]
SlipRule = Literal["radial", "rigid_slip"]
SLIP_RULES: tuple[SlipRule, ...] = ("radial", "rigid_slip")
#: a rigid-slip return in the reference sweep: traction (Pa), applies, rigid slip w h (m)
_Returned = tuple[float, float, bool, float, float]


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


def slip_ratio(m: FloatArray, level: FloatArray, q: FloatArray,
               law: FrictionLaw) -> FloatArray:
    """Return the friction ratio of cells whose trial traction exceeds their kinetic level.

    The FastSim step of a cell under a slip-dependent law (bound ``g(v) =
    g_s ratio(v)``, ``g_s`` the static bound): the trial (adhesion) traction
    ``t* = tau_prev - (w / L) h`` (``h`` the step, m; ``w`` the rigid slip per
    unit rolling distance), ``m = |t*|``.  The cell's *kinetic level* is
    ``k g_s``, ``k`` the friction ratio of its upstream neighbour if that one
    slipped, else 1 (static friction; also at a segment's first cell).  With
    ``m > k g_s`` the cell slips at the friction ratio frozen over the step:
    radial return onto ``k g_s``, whose slip per unit rolling distance
    follows from the traction increment, ``s = w + L (tau_k - tau_prev)/h =
    L (tau_k - t*)/h`` (componentwise ``L = (L1, L2)``), ``|s| = (m - k g_s)
    |L t*| / (m h)``, so the slip velocity is::

        v = |V| |s| = q (m - k g_s),    q = |V| |L t*| / (m h)  (m/(s Pa)),

    and the cell's ratio is ``ratio(v)``, its traction ``r t*/m`` with ``r =
    g_s ratio(v)`` where ``r < m``; where ``r >= m`` (possible only within
    the static bound, ``m <= g_s``: the slip at the frozen ratio is so small
    that friction recovers beyond the trial) the cell adheres.  ``m``,
    ``level`` (``k g_s``, Pa), ``q``: arrays of the cells with ``m > level``.

    Why the ratio is frozen over the step, and not solved for with the
    cell's own slip (``r = g_s ratio(q (m - r))``, the implicit step):
    FastSim's ``u = L tau`` is a contact-scale flexibility (calibrated on
    the full-adhesion creep forces), and through ``s = L (tau - t*)/h`` it
    gives a cell's slip a compliance ``L/h`` towards the cell's own traction
    change.  With a falling law the implicit step's gain ``q g_s |ratio'|
    ~ |V| g_s L B (1 - A) / h`` then exceeds 1 (2.7 at the centre of a
    Hertzian ellipse of 60 cells at ``mu_s = 0.4``, ``A = 0.4``, ``B = 1``
    s/m, ``V = 20`` m/s, and it grows as the grid is refined): the only root
    is a drop of the traction towards ``A g_s`` with a slip ten times the
    rigid slip in the first slipping cell, after which the strip re-adheres
    and slips again, cell by cell; in the continuous simplified theory, too,
    ``tau = g_s ratio(|V| s)`` with ``s = w - L dtau/dt`` makes the slip run
    away from its quasi-static value along the strip.  The half-space the
    exact theory solves has a local compliance instead: the slip of a cell
    changes by ``D_x`` per pascal of its own traction (the steady-rolling
    operator's self-coefficient, ``0.57/G``, independent of the cell size),
    15 to 30 times less than ``L/h`` on these grids, and the same gain is
    0.07 (``B = 1``): there the slip grows continuously from zero at the
    stick-slip boundary.  So the cell-scale traction change that the
    ratio's own change between neighbouring cells causes is left out of the
    slip (the half-space would answer it with ``D_x``, not ``L/h``): what
    remains is FastSim's slip with the friction level of the upstream cell,
    which tends to the quasi-static slip ``s = w - L (g_s ratio)'`` with
    ``ratio`` held locally constant as the cells shrink.  One evaluation of
    the law per slipping cell, no root to choose; ``A = 1`` or ``B = 0``
    never comes here (constant friction runs its own path).
    """
    return law.ratio(q * (m - level))


def sweep(bound: FloatArray, x: FloatArray, dx: float, xi: FloatArray | float,
          eta: FloatArray | float, phi: float, flex: StripFlexibility, y_rel: FloatArray,
          x_c: float, *, friction: FrictionLaw | None = None, speed: float | None = None,
          slip_rule: SlipRule = "radial") -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
    """March every strip from its leading edge; the readable reference of the kernel.

    ``bound``: ``g`` (Pa), ``(ny, nx)``, zero outside the contact (with a
    slip-dependent ``friction`` law: the static bound ``g_s``, at ``v =
    0``); ``x``: cell-centre ``x`` (m); ``xi``, ``eta``: creepages at the
    sweep's reference point (scalars or one per strip); ``y_rel``: ``y_j -
    y_s`` (m); ``speed``: the rolling speed ``|V|`` (m/s), needed by a
    slip-dependent law (each slipping cell then follows
    :func:`slip_ratio`).  ``slip_rule``: how a cell over the bound is put
    on it (module docstring; with ``rigid_slip`` and a slip-dependent law
    the return at the kinetic level gives the direction and the slip, the
    law at that slip the magnitude).  Returns ``tau_x``, ``tau_y`` (Pa) and
    the slip flags.  Vectorised over the strips, marched over the columns.
    """
    if slip_rule not in SLIP_RULES:
        raise ValueError(f"slip_rule must be one of {SLIP_RULES}, got {slip_rule!r}")
    rigid = slip_rule == "rigid_slip"
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
    # the rigid slip per unit rolling distance, x part (the y part varies along the strip)
    w_x = np.asarray(xi) - phi * y_rel
    w_y0 = np.asarray(eta) * np.ones(ny)
    prev_in = np.zeros(ny, dtype=bool)
    prev_slip = np.zeros(ny, dtype=bool)
    # each strip's friction ratio in its last cell (read only where that cell slipped)
    ratio = np.ones(ny)

    def returned_to(jj: int | np.integer, level: float) -> _Returned:
        # strip jj's rigid-slip return onto ``level`` (Pa) in the column being marched, and
        # its rigid slip over the step (m), taken where the traction lives: the cell's centre
        h = step[jj]
        wxh = w_x[jj] * h
        wyh = (w_y0[jj] + phi * (x[i] - x_c)) * h
        rx, ry, ok = rigid_slip_return(px[jj], py[jj], wxh, wyh, flex.l1[jj], flex.l2[jj], level)
        return rx, ry, ok, wxh, wyh

    for i in range(nx - 1, -1, -1):
        g = bound[:, i]
        inside = g > 0.0
        # first cell of a segment: half a step from its front face
        step = np.where(prev_in, dx, 0.5 * dx)
        x_mid = x[i] - x_c + 0.5 * step
        # the traction one step upstream (zero at a segment's front face)
        px = np.where(inside & prev_in, tx, 0.0)
        py = np.where(inside & prev_in, ty, 0.0)
        tx = np.where(inside, px - rate_x * step, 0.0)
        ty = np.where(inside, py - (rate_y0 + rate_yx * x_mid) * step, 0.0)
        mag = np.hypot(tx, ty)
        if law is None:
            over = mag > g
            if rigid:
                for jj in np.flatnonzero(over):
                    rx, ry, ok, _, _ = returned_to(jj, g[jj])
                    if ok:
                        # on the bound already: the scale below leaves it there
                        tx[jj], ty[jj], mag[jj] = rx, ry, g[jj]
        else:
            # kinetic level: the upstream cell's friction ratio if it slipped, else static
            level = g * np.where(prev_slip, ratio, 1.0)
            over = mag > level
            if over.any():
                idx = np.flatnonzero(over)
                m = mag[idx]
                # |L t*| / m: the slip per unit of the traction cut back (componentwise L1, L2)
                lx = flex.l1[idx] * tx[idx]
                ly = flex.l2[idx] * ty[idx]
                q = v_roll / step[idx] * np.sqrt(lx * lx + ly * ly) / m
                k = slip_ratio(m, level[idx], q, law)
                returned = []
                if rigid:
                    for n_, jj in enumerate(idx):
                        lv = level[jj]
                        rx, ry, ok, wxh, wyh = returned_to(jj, lv)
                        if ok:
                            # the slip at the kinetic level, |V| |w h + L (tau_k - tau_p)| / h
                            sx = wxh + flex.l1[jj] * (rx - px[jj])
                            sy = wyh + flex.l2[jj] * (ry - py[jj])
                            k[n_] = law.ratio(np.asarray(v_roll * math.hypot(sx, sy)
                                                         / step[jj]))
                            returned.append((n_, jj, rx, ry, lv))
                r = g[idx] * k
                slides = r < m
                for n_, jj, rx, ry, lv in returned:
                    if slides[n_]:
                        # the return's direction; the scale below sets |tau| = g k
                        tx[jj], ty[jj], mag[jj] = rx, ry, lv
                g = g.copy()
                g[idx] = r
                ratio[idx] = k
                over[idx[~slides]] = False
        scale = np.where(over, g / np.where(over, mag, 1.0), 1.0)
        tx = tx * scale
        ty = ty * scale
        out_x[:, i] = tx
        out_y[:, i] = ty
        slip[:, i] = over & inside
        prev_in = inside
        prev_slip = over & inside
    return out_x, out_y, slip


def sweep_integrals(area: GridArea, x_c: float) -> tuple[FloatArray, FloatArray]:
    """Return per cell ``d`` (m) and ``s3`` (m^2) of FastSim's adhesion march.

    ``d``: the length over which the cell's traction has grown since its
    segment's front face (half a cell, then a cell per step); ``s3``: the
    sum of ``(x_mid - x_c) h`` over the same steps, ``x_mid`` each step's
    middle.  FastSim's full-adhesion traction is ``tau_x = -(xi/L1) d``,
    ``tau_y = -(eta/L2) d - (phi/L3) s3`` (plus MAE's spin term ``phi (y -
    y_s) d / L4`` in ``tau_x``).  Zero outside the contact.  The calibrated
    MAE's rule 2 and the seed's DLM and ASM build their flexibilities on them.
    """
    mask = area.mask
    ny, nx = mask.shape
    d = np.zeros((ny, nx))
    s3 = np.zeros((ny, nx))
    cd = np.zeros(ny)
    cs = np.zeros(ny)
    prev = np.zeros(ny, dtype=bool)
    for i in range(nx - 1, -1, -1):
        inside = mask[:, i]
        step = np.where(prev, area.dx, 0.5 * area.dx)
        x_mid = area.x[i] - x_c + 0.5 * step
        cd = np.where(inside, np.where(prev, cd, 0.0) + step, 0.0)
        cs = np.where(inside, np.where(prev, cs, 0.0) + x_mid * step, 0.0)
        d[:, i] = cd
        s3[:, i] = cs
        prev = inside
    return d, s3


def fastsim(area: GridArea, xi: float, eta: float, phi: float, *, bound: FloatArray,
            flexibility: StripFlexibility, sweep_point: tuple[float, float] = (0.0, 0.0),
            reference: tuple[float, float] = (0.0, 0.0), friction: FrictionLaw | None = None,
            speed: float | None = None, slip_rule: SlipRule = "radial") -> Tractions:
    """Solve FastSim on ``area``, creepages ``xi``, ``eta``, ``phi`` (1/m) about ``reference``.

    ``sweep_point`` ``(x_c, y_s)`` is the point the strips' rates refer to
    (the reference point itself in plain FastSim, MAE's ``S``); creepages are
    moved to it by the rigid-slip identity.  ``Mz`` is about ``reference``.
    ``bound`` is the static bound ``g_s`` (Pa) of a slip-dependent
    ``friction`` law (whose ``mu_s`` made it); ``speed``: ``|V|`` (m/s);
    ``slip_rule``: :func:`sweep`'s.  A law's slope reduction is the
    methods' to apply (their creepages times ``k``): it is refused here.
    """
    check_creepages(xi, eta, phi)
    if friction is not None and friction.reduces_slope:
        raise InvalidInputError("FastSim's sweep takes the flexibilities as given: a slope "
                                "reduction is applied by the methods (equivalent.reduce_slope)")
    xc, ys = sweep_point
    xp, yp = reference
    xi_s = xi + phi * (yp - ys)
    eta_s = eta - phi * (xp - xc)
    tx, ty, slip = sweep(bound, area.x, area.dx, xi_s, eta_s, phi, flexibility,
                         area.y - ys, xc, friction=friction, speed=speed, slip_rule=slip_rule)
    return Tractions(tx, ty, slip, *resultants(area, tx, ty, reference))
