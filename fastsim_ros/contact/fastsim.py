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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import check_bound, check_creepages, check_friction
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


def sweep(bound: FloatArray, x: FloatArray, dx: float, xi: FloatArray | float,
          eta: FloatArray | float, phi: float, flex: StripFlexibility, y_rel: FloatArray,
          x_c: float) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
    """March every strip from its leading edge; the readable reference of the kernel.

    ``bound``: ``g`` (Pa), ``(ny, nx)``, zero outside the contact; ``x``:
    cell-centre ``x`` (m); ``xi``, ``eta``: creepages at the sweep's
    reference point (scalars or one per strip); ``y_rel``: ``y_j - y_s`` (m).
    Returns ``tau_x``, ``tau_y`` (Pa) and the slip flags.  Vectorised over
    the strips, marched over the columns.
    """
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
        scale = np.where(over, g / np.where(over, mag, 1.0), 1.0)
        tx = tx * scale
        ty = ty * scale
        out_x[:, i] = tx
        out_y[:, i] = ty
        slip[:, i] = over & inside
        prev_in = inside
    return out_x, out_y, slip


def fastsim(area: GridArea, xi: float, eta: float, phi: float, *, bound: FloatArray,
            flexibility: StripFlexibility, sweep_point: tuple[float, float] = (0.0, 0.0),
            reference: tuple[float, float] = (0.0, 0.0)) -> Tractions:
    """Solve FastSim on ``area``, creepages ``xi``, ``eta``, ``phi`` (1/m) about ``reference``.

    ``sweep_point`` ``(x_c, y_s)`` is the point the strips' rates refer to
    (the reference point itself in plain FastSim, MAE's ``S``); creepages are
    moved to it by the rigid-slip identity.  ``Mz`` is about ``reference``.
    """
    check_creepages(xi, eta, phi)
    xc, ys = sweep_point
    xp, yp = reference
    xi_s = xi + phi * (yp - ys)
    eta_s = eta - phi * (xp - xc)
    tx, ty, slip = sweep(bound, area.x, area.dx, xi_s, eta_s, phi, flexibility,
                         area.y - ys, xc)
    return Tractions(tx, ty, slip, *resultants(area, tx, ty, reference))
