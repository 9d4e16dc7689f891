"""Influence coefficients of uniform surface tractions on rectangles of an elastic half-space.

Two quasi-identical half-spaces in contact (combined shear modulus ``G`` with
``2/G = 1/G1 + 1/G2``, combined Poisson ratio ``nu``): the normal and the
tangential problems decouple and only the *difference* of the two bodies'
surface displacements matters.  For a point force ``Q`` at the origin of the
surface, summing Boussinesq's and Cerruti's solutions for both bodies gives
(Johnson, Contact Mechanics, eqs. 3.19 and 3.86a, with ``rho = |(x, y)|``)

    u_x = Q_x/(pi G) [(1 - nu)/rho + nu x^2/rho^3] + Q_y/(pi G) nu x y/rho^3
    u_y = Q_x/(pi G) nu x y/rho^3 + Q_y/(pi G) [(1 - nu)/rho + nu y^2/rho^3]
    u_z = Q_z/(pi G) (1 - nu)/rho

(the normal-tangential coupling terms cancel between quasi-identical bodies).
A uniform traction on a rectangle integrates these kernels in closed form
(Kalker 1990, ch. 5; CONTACT's ``m_inflcf``); the corner primitives below need
absolute values, without which a cell's influence on itself comes out zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def _x_asinh_y_over_abs_x(x: FloatArray, y: FloatArray) -> FloatArray:
    """``x asinh(y/|x|)``, continued by its limit 0 on ``x = 0``."""
    ax = np.abs(x)
    safe = np.where(ax > 0.0, ax, 1.0)
    return np.where(ax > 0.0, x * np.arcsinh(y / safe), 0.0)


def _rectangle_integrals(
    xc: FloatArray, yc: FloatArray, hx: float, hy: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Integrals of ``x^2/rho^3``, ``y^2/rho^3`` and ``x y/rho^3`` over a rectangle.

    The rectangle has its centre at ``(xc, yc)`` relative to the field point and
    sides ``hx``, ``hy`` (m).  Primitives ``F`` with ``d2F/dxdy`` equal to the
    kernel: ``y asinh(x/|y|)``, ``x asinh(y/|x|)`` and ``-rho``.  Returns
    ``(I_xx, I_yy, I_xy)`` in m.
    """
    i_xx = np.zeros(np.broadcast(xc, yc).shape)
    i_yy = np.zeros_like(i_xx)
    i_xy = np.zeros_like(i_xx)
    for sx in (-0.5, 0.5):
        for sy in (-0.5, 0.5):
            x = xc + sx * hx
            y = yc + sy * hy
            sign = 1.0 if sx * sy > 0 else -1.0
            i_xx += sign * _x_asinh_y_over_abs_x(y, x)
            i_yy += sign * _x_asinh_y_over_abs_x(x, y)
            i_xy -= sign * np.hypot(x, y)
    return i_xx, i_yy, i_xy


@dataclass(frozen=True)
class InfluenceKernel:
    """Influence of a unit uniform traction on one cell, for every cell offset.

    ``xx[dj, di]`` is the difference of the bodies' ``u_x`` at a field cell due
    to a unit ``tau_x`` (1 Pa) on a source cell ``di`` cells behind it in ``x``
    and ``dj`` in ``y`` (field index minus source index), stored for
    ``di in [-mx, mx]`` and ``dj in [-my, my]`` at array index ``[dj + my,
    di + mx]``.  Units m/Pa.  ``xy`` couples ``tau_y`` to ``u_x`` (and
    ``tau_x`` to ``u_y``); ``zz`` is the normal one.
    """

    hx: float
    hy: float
    mx: int
    my: int
    xx: FloatArray
    yy: FloatArray
    xy: FloatArray
    zz: FloatArray


def influence_kernel(
    hx: float, hy: float, mx: int, my: int, *, shear_modulus: float, nu: float
) -> InfluenceKernel:
    """Influence coefficients of a grid of ``hx`` x ``hy`` cells (m), offsets up to ``mx``, ``my``.

    ``shear_modulus`` is the combined ``G`` (Pa), ``nu`` the combined Poisson ratio.
    """
    di = np.arange(-mx, mx + 1, dtype=float)
    dj = np.arange(-my, my + 1, dtype=float)
    # The source lies at minus the offset from the field point.
    xc = -di[None, :] * hx
    yc = -dj[:, None] * hy
    i_xx, i_yy, i_xy = _rectangle_integrals(xc, yc, hx, hy)
    scale = 1.0 / (np.pi * shear_modulus)
    return InfluenceKernel(
        hx=hx,
        hy=hy,
        mx=mx,
        my=my,
        xx=scale * (i_xx + (1.0 - nu) * i_yy),
        yy=scale * ((1.0 - nu) * i_xx + i_yy),
        xy=scale * nu * i_xy,
        zz=scale * (1.0 - nu) * (i_xx + i_yy),
    )


def point_load_displacement(
    x: FloatArray, y: FloatArray, *, shear_modulus: float, nu: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Boussinesq-Cerruti point-force kernels ``(xx, yy, xy, zz)`` at ``(x, y)`` (m/N)."""
    rho = np.hypot(x, y)
    scale = 1.0 / (np.pi * shear_modulus)
    return (
        scale * ((1.0 - nu) / rho + nu * x**2 / rho**3),
        scale * ((1.0 - nu) / rho + nu * y**2 / rho**3),
        scale * nu * x * y / rho**3,
        scale * (1.0 - nu) / rho,
    )


def line_influence(
    x: FloatArray, y_lo: FloatArray, y_hi: FloatArray, *, shear_modulus: float, nu: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Integrals of the point-force kernels over a lateral segment: ``(xx, yy, xy)`` (1/Pa).

    The kernels of :func:`point_load_displacement` at ``(x, y)`` integrated
    over ``y`` from ``y_lo`` to ``y_hi`` (field minus source, m), in closed
    form: ``int 1/rho dy = asinh(y/|x|)``, ``int x^2/rho^3 dy = y/rho``,
    ``int y^2/rho^3 dy = asinh(y/|x|) - y/rho``, ``int x y/rho^3 dy =
    -x/rho``.  The displacement difference of a line load of 1 N/m along
    ``x`` on that segment, per unit length: a strip's traction integrated
    across its width.  ``x = 0`` with ``y_lo < 0 < y_hi`` (the field point
    on the segment) is the kernels' logarithmic singularity: do not ask for
    it; ``x = 0`` elsewhere is taken as its limit.
    """
    ax = np.abs(x)
    safe = np.where(ax > 0.0, ax, 1.0)

    def primitives(y: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        rho = np.hypot(x, y)
        r = np.where(rho > 0.0, rho, 1.0)
        # asinh(y/|x|) at x -> 0 (y != 0): sign(y) log(2|y|/|x|); the |x| cancels between the
        # two ends of a segment that does not hold y = 0
        a = np.where(ax > 0.0, np.arcsinh(y / safe),
                     np.sign(y) * np.log(2.0 * np.maximum(np.abs(y), 1e-300)))
        return a, np.where(rho > 0.0, y / r, 0.0), np.where(rho > 0.0, -x / r, 0.0)

    a_hi, b_hi, c_hi = primitives(np.asarray(y_hi, dtype=float))
    a_lo, b_lo, c_lo = primitives(np.asarray(y_lo, dtype=float))
    a, b, c = a_hi - a_lo, b_hi - b_lo, c_hi - c_lo
    scale = 1.0 / (np.pi * shear_modulus)
    return scale * ((1.0 - nu) * a + nu * b), scale * (a - nu * b), scale * nu * c
