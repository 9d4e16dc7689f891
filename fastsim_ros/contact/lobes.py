"""Patches of separate contact regions: split across the widest gap of empty strips, blended.

A wheel in two-point contact (tread and flange root, the flange take-over)
presses on the rail in two regions some millimetres apart across the
rail, and a contact search that gives one patch per wheel puts both on one
grid, with empty strips (rows of constant ``y``) between them.  MAE reads
a patch as two semi-ellipses meeting on a split line: on two regions it
takes each region for half an ellipse cut at that line, and its linear
response is far off (measured on S1002/UIC60 at the take-over, -4.95 mm:
``dFx/dxi`` 20% low, the spin's ``dFx/dphi`` of the wrong sign, Fy 4.2% of
``mu N`` off the exact theory).  Each region is a patch of its own: solved
apart, the regions' forces are the exact theory's within 0.8% of ``mu N``
through the take-over, and the exact theory on the regions apart is within
0.2% of the exact theory on the whole grid (the half-space couples regions
8 mm apart only weakly).  Regions that touch are coupled strongly: solved apart, two
lobes joined by a thin neck are up to 0.9% of ``mu N`` further from the exact
theory than whole, so a neck is not a gap.

The rule, continuous as a gap opens: the widest gap (empty strips between
contact strips, measured between the two sides' edges relative to the
narrower side's width, :func:`gap_split`) splits the patch into the strips
below it and the rest, and the forces are ``w F_whole + (1 - w) (F_below +
F_rest)`` with the whole patch's weight ``w = 1 - smoothstep(t /
GAP_APART)``, ``t`` the gap in widths of the narrower side.  A patch
without an empty strip between contact strips is solved whole, as MAE
solves it (to the bit); regions at least ``GAP_APART`` times the narrower
one's width apart are solved apart; as a gap closes the weight moves to
the whole patch (regions that touch have ``t`` near 0).

Assumptions stated: one split (a third region stays with its side); the
regions do not load each other (the half-space's coupling across the gap is
left out); ``GAP_APART`` is a choice, not a fit (the take-over's regions,
tens of strips apart, are beyond it; closing the gap of ``samples.two_regions``
in 2 um steps, the forces move within 0.3% of ``mu N`` of the exact ones).
Plain arithmetic on arrays: the kernels compile it as it is (one formula for
both paths).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

#: the gap, in widths of the narrower region, from which the regions are solved apart
GAP_APART = 2.0


def strip_loads(p: NDArray[np.float64], out: NDArray[np.float64]) -> None:
    """Fill ``out`` ``(ny,)`` with each strip's sum of its positive pressures (Pa)."""
    ny, nx = p.shape
    for j in range(ny):
        s = 0.0
        for i in range(nx):
            v = p[j, i]
            if v > 0.0:
                s += v
        out[j] = s


def has_inner_gap(p: NDArray[np.float64]) -> bool:
    """Return whether a strip without contact (no ``p > 0``, Pa) lies between strips with it.

    :func:`gap_split`'s condition for a split, found from each strip's first
    cell in contact without summing the patch: the common patch, one region,
    is told apart at a fraction of :func:`strip_loads`' cost.
    """
    ny, nx = p.shape
    seen = False
    empty_since = False
    for j in range(ny):
        contact = False
        for i in range(nx):
            if p[j, i] > 0.0:
                contact = True
                break
        if contact:
            if empty_since:
                return True
            seen = True
        elif seen:
            empty_since = True
    return False


def gap_split(q: NDArray[np.float64]) -> tuple[int, float]:
    """Return ``(m, w)``: the first empty strip of the widest gap, the whole patch's weight.

    ``q``: the strips' loads (:func:`strip_loads`).  Each side of a gap is
    measured by its load's moments across the strips: its centre ``c`` and
    half-width ``b = sqrt(5 var)`` (a Hertzian region's strip loads go as
    ``1 - (y/b)^2``, of variance ``b^2 / 5``; ``var`` with each strip's own
    width, ``1/12``), both continuous in the pressures, so the gap between
    the sides' edges ``g = c_2 - c_1 - b_1 - b_2`` moves continuously as a
    region's edge strips fill or empty; ``t = g / (2 min(b_1, b_2))`` (the
    narrower side's width), and the widest gap is the largest ``t``.  ``w
    = 1`` (and ``m = 0``) where no empty strip lies between contact strips:
    the patch is solved whole.
    """
    ny = q.shape[0]
    first = 0
    while first < ny and not q[first] > 0.0:
        first += 1
    last = ny - 1
    while last > first and not q[last] > 0.0:
        last -= 1
    best = -math.inf
    m = 0
    j = first + 1
    while j < last:
        if q[j] > 0.0:
            j += 1
            continue
        lo = j
        while not q[j] > 0.0:
            j += 1
        # strips first .. lo - 1 below the gap, j .. last above it (the ends may hold gaps too):
        # each side's centre and half-width (strips)
        c1 = b1 = c2 = b2 = 0.0
        for side in range(2):
            s0 = s1 = s2 = 0.0
            for k in range(first, lo) if side == 0 else range(j, last + 1):
                s0 += q[k]
                s1 += q[k] * k
                s2 += q[k] * k * k
            c = s1 / s0
            b = math.sqrt(5.0 * (max(s2 / s0 - c * c, 0.0) + 1.0 / 12.0))
            if side == 0:
                c1, b1 = c, b
            else:
                c2, b2 = c, b
        t = (c2 - c1 - b1 - b2) / (2.0 * min(b1, b2))
        if t > best:
            best = t
            m = lo
    if m == 0:
        return 0, 1.0
    t = min(max(best / GAP_APART, 0.0), 1.0)
    return m, 1.0 - t * t * (3.0 - 2.0 * t)
