"""Compiled loops of the patch adapter (numba): two passes over a cloud's points.

:mod:`msg_adapters.patch` keeps every check and decision; these loops only
sum and measure, where twenty numpy calls on a 30 x 30 cloud cost about
50 us and one pass a few.  ``words`` is the cloud's buffer as native floats
(float32 or float64), point ``(j, i)`` starting at word ``j * row + i *
step``; ``cols`` the word offsets of ``x y z normal_x normal_y normal_z
pressure`` in a point.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: statuses of :func:`scan_points`
OK, NONFINITE, NEGATIVE = 0, 1, 2


@njit(cache=True)
def scan_points(words, ny, nx, row, step, cols, pressure, xyz):
    """Copy pressure (Pa) and positions (m) out of the cloud; sum what the frame needs.

    Fills ``pressure[j, i]`` and ``xyz[j, i, :]`` (float64).  Returns
    ``(status, cells, p_sum, p_min, s)`` with ``cells`` the points of
    positive pressure and ``s`` the six sums ``sum p x, sum p y, sum p z,
    sum p n_x, sum p n_y, sum p n_z`` (zero-pressure points add nothing).
    """
    s = np.zeros(6)
    cells = 0
    p_sum = 0.0
    p_min = math.inf
    status = OK
    for j in range(ny):
        for i in range(nx):
            base = j * row + i * step
            p = float(words[base + cols[6]])
            x = float(words[base + cols[0]])
            y = float(words[base + cols[1]])
            z = float(words[base + cols[2]])
            n0 = float(words[base + cols[3]])
            n1 = float(words[base + cols[4]])
            n2 = float(words[base + cols[5]])
            if not (math.isfinite(p) and math.isfinite(x) and math.isfinite(y)
                    and math.isfinite(z) and math.isfinite(n0) and math.isfinite(n1)
                    and math.isfinite(n2)):
                status = NONFINITE
            pressure[j, i] = p
            xyz[j, i, 0] = x
            xyz[j, i, 1] = y
            xyz[j, i, 2] = z
            if p < p_min:
                p_min = p
            if p > 0.0:
                cells += 1
                p_sum += p
                s[0] += p * x
                s[1] += p * y
                s[2] += p * z
                s[3] += p * n0
                s[4] += p * n1
                s[5] += p * n2
    if status == OK and p_min < 0.0:
        status = NEGATIVE
    return status, cells, p_sum, p_min, s


@njit(cache=True)
def fit_grid(xyz, origin, ex, ey):
    """Fit ``x = x0 + i dx`` and ``y = y0 + j dy`` to the in-plane coordinates of every point.

    In-plane coordinates ``x = (r - origin) . e_x``, ``y = (r - origin) .
    e_y`` (m).  The step along each axis is the mean over the other index of
    (last - first)/(n - 1), the offset the mean residual; returns ``(x0,
    dx, worst_x, y0, dy, worst_y)`` with ``worst_*`` the largest distance
    (m) of a point from its fitted grid line (the grid is regular when both
    are a small share of the steps; ``dx`` or ``dy`` < 0 when the points run
    towards negative coordinates).
    """
    ny, nx = xyz.shape[0], xyz.shape[1]
    xl = np.empty((ny, nx))
    yl = np.empty((ny, nx))
    sx = 0.0
    sy = 0.0
    for j in range(ny):
        for i in range(nx):
            d0 = xyz[j, i, 0] - origin[0]
            d1 = xyz[j, i, 1] - origin[1]
            d2 = xyz[j, i, 2] - origin[2]
            u = d0 * ex[0] + d1 * ex[1] + d2 * ex[2]
            v = d0 * ey[0] + d1 * ey[1] + d2 * ey[2]
            xl[j, i] = u
            yl[j, i] = v
            sx += u
            sy += v
    span_x = 0.0
    for j in range(ny):
        span_x += xl[j, nx - 1] - xl[j, 0]
    span_y = 0.0
    for i in range(nx):
        span_y += yl[ny - 1, i] - yl[0, i]
    dx = span_x / (ny * (nx - 1))
    dy = span_y / (nx * (ny - 1))
    n = ny * nx
    x0 = sx / n - dx * 0.5 * (nx - 1)
    y0 = sy / n - dy * 0.5 * (ny - 1)
    worst_x = 0.0
    worst_y = 0.0
    for j in range(ny):
        for i in range(nx):
            ox = abs(xl[j, i] - (x0 + i * dx))
            oy = abs(yl[j, i] - (y0 + j * dy))
            if ox > worst_x:
                worst_x = ox
            if oy > worst_y:
                worst_y = oy
    return x0, dx, worst_x, y0, dy, worst_y
