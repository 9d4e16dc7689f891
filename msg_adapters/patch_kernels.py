"""The compiled loop of the patch adapter (numba): three passes over a cloud's points, one call.

:mod:`msg_adapters.patch` keeps every check and decision; this loop only
sums and measures, where twenty numpy calls on a 30 x 30 cloud cost about
50 us and one call a few (one call: numba's dispatch costs a microsecond or
two per call).  ``words`` is the cloud's buffer as native floats
(float32 or float64), point ``(j, i)`` starting at word ``j * row + i *
step``; ``cols`` the word offsets of ``x y z normal_x normal_y normal_z
pressure`` in a point.
"""

from __future__ import annotations

import math

from numba import njit

#: statuses of :func:`adapt`: the points, then the contact frame
OK, NONFINITE, NEGATIVE, ZERO_NORMAL, NORMAL_ALONG_X, TOO_HIGH = 0, 1, 2, 3, 4, 5
#: the largest pressure a patch may carry (Pa): a thousand times any steel's yield, as
#: ``fastsim_contact``'s limit (a 1e30 Pa cell gave a wrench of 7.6e25 N)
MAX_PRESSURE = 1e13
#: what :func:`adapt` writes into its ``out`` array, by index
(STATUS, CELLS, P_SUM, P_MIN, ORIGIN, E_X, E_Y, E_Z, X0, DX, WORST_X, Y0, DY,
 WORST_Y) = (0, 1, 2, 3, 4, 7, 10, 13, 16, 17, 18, 19, 20, 21)
OUT_SIZE = 22


@njit(cache=True)
def adapt(words, ny, nx, row, step, cols, pressure, out, checked=True):
    """Copy the pressure (Pa) out of the cloud, derive the contact frame, fit the grid.

    Fills ``pressure[j, i]`` (float64) and ``out`` (float64, OUT_SIZE), by
    the indices above: ``STATUS`` (OK, NONFINITE, NEGATIVE, TOO_HIGH (a
    pressure above :data:`MAX_PRESSURE`); after the
    frame, ZERO_NORMAL or NORMAL_ALONG_X), ``CELLS`` (points of positive
    pressure), ``P_SUM``, ``P_MIN``; when the points are finite,
    non-negative, some in contact, on a grid of 2 x 2 or more: the frame
    (``ORIGIN`` the pressure-weighted centroid, ``E_Z`` along ``sum p n``,
    ``E_X`` the wheelset's ``x`` projected on the contact plane, ``E_Y =
    E_Z x E_X``), then the grid fit ``x = x0 + i dx``, ``y = y0 + j dy`` of
    the in-plane coordinates ``x = (r - origin) . e_x``, ``y = (r -
    origin) . e_y`` (m): each step the mean over the other index of (last -
    first)/(n - 1), each offset the mean residual, ``WORST_*`` the largest
    distance (m) of a point from its grid line.  ``patch.py`` decides what
    the numbers mean.  ``checked=False``: every word is known finite (the
    replay tests a whole patch's words at once), and the per-point test is
    skipped; the numbers are the same.  Returns the largest pressure (Pa).
    """
    cells = 0
    p_sum = 0.0
    p_min = math.inf
    p_max = -math.inf
    status = OK
    s0 = s1 = s2 = s3 = s4 = s5 = 0.0
    # the field offsets in locals: read once, not at every point (pressure, written
    # in the loop, might alias cols for all the compiler knows)
    c0, c1, c2, c3, c4, c5, c6 = cols[0], cols[1], cols[2], cols[3], cols[4], cols[5], cols[6]
    for j in range(ny):
        for i in range(nx):
            base = j * row + i * step
            p = float(words[base + c6])
            x = float(words[base + c0])
            y = float(words[base + c1])
            z = float(words[base + c2])
            n0 = float(words[base + c3])
            n1 = float(words[base + c4])
            n2 = float(words[base + c5])
            if checked and not (math.isfinite(p) and math.isfinite(x) and math.isfinite(y)
                                and math.isfinite(z) and math.isfinite(n0)
                                and math.isfinite(n1) and math.isfinite(n2)):
                status = NONFINITE
            pressure[j, i] = p
            if p < p_min:
                p_min = p
            if p > p_max:
                p_max = p
            if p > 0.0:
                cells += 1
                p_sum += p
                s0 += p * x
                s1 += p * y
                s2 += p * z
                s3 += p * n0
                s4 += p * n1
                s5 += p * n2
    if status == OK and p_min < 0.0:
        status = NEGATIVE
    if status == OK and p_max > MAX_PRESSURE:
        status = TOO_HIGH
    out[STATUS] = status
    out[CELLS] = cells
    out[P_SUM] = p_sum
    out[P_MIN] = p_min
    if status != OK or cells == 0:
        return p_max
    o0, o1, o2 = s0 / p_sum, s1 / p_sum, s2 / p_sum
    out[ORIGIN], out[ORIGIN + 1], out[ORIGIN + 2] = o0, o1, o2
    # the contact frame (patch.contact_axes, the same operations)
    norm = math.sqrt(s3 * s3 + s4 * s4 + s5 * s5)
    if not norm > 0.0:
        out[STATUS] = ZERO_NORMAL
        return p_max
    z0, z1, z2 = s3 / norm, s4 / norm, s5 / norm
    exx, exy, exz = 1.0 - z0 * z0, -z0 * z1, -z0 * z2
    ex_norm = math.sqrt(exx * exx + exy * exy + exz * exz)
    if not ex_norm > 1e-6:
        out[STATUS] = NORMAL_ALONG_X
        return p_max
    x0_, x1_, x2_ = exx / ex_norm, exy / ex_norm, exz / ex_norm
    y0_, y1_, y2_ = z1 * x2_ - z2 * x1_, z2 * x0_ - z0 * x2_, z0 * x1_ - z1 * x0_
    out[E_X], out[E_X + 1], out[E_X + 2] = x0_, x1_, x2_
    out[E_Y], out[E_Y + 1], out[E_Y + 2] = y0_, y1_, y2_
    out[E_Z], out[E_Z + 1], out[E_Z + 2] = z0, z1, z2
    if ny < 2 or nx < 2:
        return p_max
    # the grid's steps from the spans between the first and last points of each
    # strip (x) and of each column (y), summed in index order
    span_x = 0.0
    for j in range(ny):
        first = j * row
        last = first + (nx - 1) * step
        span_x += _along(words, last, c0, c1, c2, o0, o1, o2, x0_, x1_, x2_) - _along(
            words, first, c0, c1, c2, o0, o1, o2, x0_, x1_, x2_)
    span_y = 0.0
    for i in range(nx):
        first = i * step
        last = first + (ny - 1) * row
        span_y += _along(words, last, c0, c1, c2, o0, o1, o2, y0_, y1_, y2_) - _along(
            words, first, c0, c1, c2, o0, o1, o2, y0_, y1_, y2_)
    dx = span_x / (ny * (nx - 1))
    dy = span_y / (nx * (ny - 1))
    # one pass for the offsets (the mean residuals) and the worst residuals: the
    # residual x - (x0 + i dx) of a point is (x - i dx) - x0, so the extremes of
    # x - i dx and the mean give the worst
    sx = 0.0
    sy = 0.0
    rx_low = ry_low = math.inf
    rx_high = ry_high = -math.inf
    for j in range(ny):
        for i in range(nx):
            base = j * row + i * step
            d0 = float(words[base + c0]) - o0
            d1 = float(words[base + c1]) - o1
            d2 = float(words[base + c2]) - o2
            u = d0 * x0_ + d1 * x1_ + d2 * x2_
            v = d0 * y0_ + d1 * y1_ + d2 * y2_
            sx += u
            sy += v
            ru = u - i * dx
            rv = v - j * dy
            rx_low = min(rx_low, ru)
            rx_high = max(rx_high, ru)
            ry_low = min(ry_low, rv)
            ry_high = max(ry_high, rv)
    n = ny * nx
    gx0 = sx / n - dx * 0.5 * (nx - 1)
    gy0 = sy / n - dy * 0.5 * (ny - 1)
    out[X0], out[DX], out[WORST_X] = gx0, dx, max(rx_high - gx0, gx0 - rx_low)
    out[Y0], out[DY], out[WORST_Y] = gy0, dy, max(ry_high - gy0, gy0 - ry_low)
    return p_max


@njit(cache=True, inline="always")
def _along(words, base, c0, c1, c2, o0, o1, o2, a0, a1, a2):
    """Return ``(r - origin) . a`` of the point at word ``base`` (m)."""
    return ((float(words[base + c0]) - o0) * a0 + (float(words[base + c1]) - o1) * a1
            + (float(words[base + c2]) - o2) * a2)
