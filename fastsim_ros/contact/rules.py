"""Constants and small formulas the numpy reference and the compiled kernels share: one source.

Plain Python on floats and ints: the reference modules call these functions
as they are, :mod:`~fastsim_ros.contact.kernels` compiles the same functions
with numba (numba's ``round`` of a float rounds half to even, as Python's).
Imports nothing of the package.

numba's disk cache keys a compiled kernel on its own file's time stamp only:
after changing this file during development, clear the cache (or touch
``kernels.py``) so that kernels compiled with the old values are not reused.
"""

from __future__ import annotations

import math
from typing import Any

#: friction-law codes of the kernels (:mod:`fastsim_ros.contact.friction`)
LAW_CONSTANT = 0
LAW_EXPONENTIAL = 1

#: the smallest share of the area a ``widest_strip`` zone may have under the
#: ``auto`` split rule (:func:`fastsim_ros.contact.mae.split_face`)
MIN_ZONE_SHARE = 0.15

#: the calibrated MAE's rule 4 keeps at least this share of a zone's ``c23``
#: (a zone bent far backwards; :func:`fastsim_ros.contact.mae_calibrated.offset_c23`)
MIN_OFFSET_C23_SHARE = 0.25


def ellipse_cells(cells_in_contact: float) -> int:
    """Return the cells across the ellipse's box giving as many cells in contact as the patch.

    An ellipse covers ``pi/4`` of its bounding box, so ``n = sqrt(4 N/pi)``
    (rounded half to even, at least 2): the equivalent-ellipse baseline then
    sweeps as many cells as MAE does, at the same resolution, and neither is
    cheaper or finer than the other.
    """
    return max(2, round(math.sqrt(4.0 * cells_in_contact / math.pi)))


def ellipse_grid(a: float, b: float, n: int, x_c: float,
                 y_c: float) -> tuple[float, float, float, float]:
    """Return ``(x0, y0, dx, dy)`` (m) of the ``n`` x ``n`` grid of an ellipse at ``(x_c, y_c)``.

    The grid of ``area.ellipse(a, b, nx=n, ny=n).shifted(x_c, y_c)``: ``n``
    cells across ``[-a, a] x [-b, b]``, ``(x0, y0)`` the centre of the first
    cell, with the same floating-point operations.
    """
    return (-a + (a - -a) / n * 0.5 + x_c, -b + (b - -b) / n * 0.5 + y_c, 2 * a / n, 2 * b / n)


def rigid_slip_return(px: float, py: float, wxh: float, wyh: float, l1: float, l2: float,
                      g: float) -> tuple[float, float, bool]:
    """Return a slipping cell's traction, opposite to its slip, and whether the rule applies.

    Kalker's simplified theory with ``u = L tau`` componentwise (``L = (L1,
    L2)``, m/Pa): over a step ``h`` (m) the slip of a cell is ``s h = w h +
    L (tau - tau_p)`` (``w``: the rigid slip per unit rolling distance at
    the cell's centre, where its traction lives, ``w h = (wxh, wyh)`` in m:
    taken at the step's middle, as the adhesion trial takes it, it would
    turn the sliding traction by half a cell's rotation of the slip, 3
    degrees a cell near a spin pole on 30 cells; ``tau_p`` = ``(px, py)``
    the traction one step upstream, Pa), and Coulomb's law puts a slipping
    cell on the bound ``g`` (Pa) opposite to its slip, ``tau = -g s/|s|``.
    With ``t' = tau_p - w h / L`` that is ``t' = (g + lam / L) tau / g``
    for some ``lam >= 0``: ``tau_k = g t'_k / (g + lam / L_k)``, ``lam``
    the root of ``sum (t'_k / (g + lam / L_k))^2 = 1``, a decreasing convex
    function of ``lam`` (Newton from the isotropic lower bound ``(|t'| - g)
    min(L)`` converges monotonically).  With ``L1 = L2`` this is FastSim's
    radial return of the adhesion trial; with unequal ``L`` (and MAE's spin
    flexibilities, which the adhesion trial uses) radial return sends the
    traction along ``w / L`` rather than ``w``, and in full sliding the
    force off the rigid slip's direction (docs/validation_wider.md: the
    paper's MAE's Fx under spin on a truncated ellipse, 18.6% of mu N).
    Where ``|t'| <= g`` (the spin flexibilities made the trial slip where
    the rigid slip with ``L1, L2`` would not) the third value is ``False``
    and the caller keeps the radial return.
    """
    ttx = px - wxh / l1
    tty = py - wyh / l2
    tm = math.sqrt(ttx * ttx + tty * tty)
    if not tm > g:
        return 0.0, 0.0, False
    m1 = 1.0 / l1
    m2 = 1.0 / l2
    lam = (tm - g) / max(m1, m2)
    d1 = g + lam * m1
    d2 = g + lam * m2
    for _ in range(60):
        f = (ttx / d1) ** 2 + (tty / d2) ** 2 - 1.0
        if not f > 1e-14:
            break
        df = -2.0 * (ttx * ttx * m1 / (d1 * d1 * d1) + tty * tty * m2 / (d2 * d2 * d2))
        lam = lam - f / df
        d1 = g + lam * m1
        d2 = g + lam * m2
    ex = ttx / d1
    ey = tty / d2
    n = math.sqrt(ex * ex + ey * ey)
    return g * ex / n, g * ey / n, True


def pair_factor(knots: Any, values: Any, t_self: float, t_other: float) -> float:
    """Interpolate a pair-factor table at ``(log g_self, log g_other)``, exactly 1 where they meet.

    ``knots``: the table's ``log(a/b)`` nodes (increasing); ``values[i, j]``
    the factor at ``(knots[i], knots[j])``.  Linear on the triangles that
    split each cell of the node grid along its ``(i, j) - (i+1, j+1)``
    diagonal: on the line ``g_self = g_other`` only diagonal nodes take part,
    so two equal halves get the factor 1 of the table's diagonal between
    the nodes too (bilinear interpolation would mix in off-diagonal nodes:
    1.034 at ``a/b = 6`` on both sides).  Outside the nodes the nearest edge
    value is taken (the factor held constant beyond the table; the zones'
    own coefficients still come from the half-ellipse tables).
    """
    n = len(knots)
    ti = min(max(t_self, knots[0]), knots[n - 1])
    tj = min(max(t_other, knots[0]), knots[n - 1])
    i = 0
    while i < n - 2 and ti > knots[i + 1]:
        i += 1
    j = 0
    while j < n - 2 and tj > knots[j + 1]:
        j += 1
    u = (ti - knots[i]) / (knots[i + 1] - knots[i])
    v = (tj - knots[j]) / (knots[j + 1] - knots[j])
    if u >= v:
        return (1.0 - u) * values[i, j] + (u - v) * values[i + 1, j] + v * values[i + 1, j + 1]
    return (1.0 - v) * values[i, j] + (v - u) * values[i, j + 1] + u * values[i + 1, j + 1]
