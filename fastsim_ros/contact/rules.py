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

#: the ``auto`` split's band of near-longest strips (:func:`widest_position`): the strips
#: whose chord is within this share of the longest, or within WIDEST_BAND_CELLS cells
WIDEST_BAND_SHARE = 0.05
WIDEST_BAND_CELLS = 2.0
#: a split within this fraction of a cell of a face (or of a strip's middle) is taken there
SPLIT_SNAP = 1e-9


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
    With ``U = L tau_p - w h`` and ``L = lbar + D`` (``lbar = (L1 + L2)/2``,
    ``D = diag(dl, -dl)``, ``dl = (L1 - L2)/2``) the traction's direction
    ``e`` solves ``e ~ U - g L e``, in which the isotropic part ``g lbar e``
    drops out: ``e ~ U - g D e``, a contraction of factor about ``dl/lbar``.
    One step of it from ``e0 = U/|U|`` gives ``e = V/|V|``, ``V = U - g D
    e0``: exact in full sliding (``|U| >> g dl``) and where ``L1 = L2`` (then
    it is FastSim's radial return), elsewhere within 1.7% of ``g`` of the
    converged direction for ``L2/L1`` in 0.7..1.4 (measured on 20,000
    random cells at each of 0.7, 0.8, 1.25, 1.4: 1.6, 0.6, 0.6, 1.4%); a
    zone's ``L2/L1 = c11/c22`` lies in 0.86..1.38 at ``nu = 0.28`` (steel),
    in 0.74..1.97 at ``nu = 0.5``, where the step is within 5.7% of ``g``
    (at 1.97); on the 15 areas of
    docs/validation_wider.md the force-creepage curves move by at most 0.6
    points of mu N against the converged return, at the cost of two square
    roots.  The cell slips by this rule where ``|V| > g lbar`` (with ``L1 =
    L2``: where the adhesion trial exceeds the bound); elsewhere (MAE's
    spin flexibilities made the trial slip where ``L1, L2`` and the rigid
    slip would not) the third value is ``False`` and the caller keeps the
    radial return.  Why not the radial return: it puts the traction along
    the trial ``tau_p - (rates) h``, whose spin terms use ``L3``, ``L4``: with
    MAE's unequal flexibilities the force in sliding is then off the rigid
    slip's direction (docs/validation_wider.md: the paper's MAE's Fx under
    spin on a truncated ellipse, 18.6% of mu N).
    """
    ux = l1 * px - wxh
    uy = l2 * py - wyh
    n = math.sqrt(ux * ux + uy * uy)
    if not n > 0.0:
        return 0.0, 0.0, False
    gd = g * 0.5 * (l1 - l2) / n
    vx = ux - gd * ux
    vy = uy + gd * uy
    m = math.sqrt(vx * vx + vy * vy)
    if not m > g * 0.5 * (l1 + l2):
        return 0.0, 0.0, False
    r = g / m
    return r * vx, r * vy, True


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


def chord_bend_offset(count: Any, first: Any, last: Any, j_lo: int, j_hi: int,
                      dx: float) -> float:
    """Return the strip offset (m) of the calibrated MAE's rule 4 for strips ``j_lo .. j_hi-1``.

    ``count[j]``, ``first[j]``, ``last[j]``: strip ``j``'s cells in contact
    and the indices of its first and last such cell (a strip with ``count
    = 0`` is skipped); ``dx``: the cell length (m).  Each strip ``k`` has
    its chord's centre ``m_k`` and half-length ``l_k`` (the faces of its
    outermost cells).  Spin about the centroid acts on a strip centred off
    it as a lateral creepage; the exact theory tells two kinds of offset
    apart (docs/validation_wider.md, section 6):

    - offsets proportional to the chord, ``m = m0 + s l`` (an egg: two half
      ellipses of different lengths; any shape sheared in proportion to its
      chords): the exact lateral force of a strip is then proportional to
      its length (measured: within 7% rms on eight eggs, 80 cells), so the
      offsets average to the centroid and do nothing (the exact C~23 about
      the centroid of an egg is its straightened shape's within 1.2%);
    - a bend, ``m = m0 - B l^2`` (a crescent: strips moved by a function of
      ``y`` whatever their length, the short ones most): the exact theory
      weighs the offsets nearly alike per strip (with the elastic coupling
      of the bent strips), as rule 4 first found on the crescent.

    So the centres are fitted by least squares, each strip counted once,
    with ``m = alpha + beta l + kappa l^2``, and the offset is the bend's
    part alone, ``kappa (mean(l^2) - sum(l^3)/sum(l))``: the mean centre,
    each strip once, of ``kappa l^2`` less its centroid (strips weighed by
    their length).  On a crescent (centres exactly quadratic in the chord)
    that is the mean strip centre less the centroid, the first form of the
    rule; on an egg, a straight zone, or too few distinct chords to tell a
    bend (``< 3``, or a singular fit) it is zero.  Signed (negative: the
    horns trail); rule 4 counts it where it is positive.
    """
    n = 0
    s_l = 0.0
    s_l2 = 0.0
    s_l3 = 0.0
    for j in range(j_lo, j_hi):
        if count[j] > 0:
            half = 0.5 * dx * (last[j] - first[j] + 1)
            n += 1
            s_l += half
            s_l2 += half * half
            s_l3 += half * half * half
    if n < 3:
        return 0.0
    mean_l = s_l / n
    mean_u2 = 0.0
    for j in range(j_lo, j_hi):
        if count[j] > 0:
            u = 0.5 * dx * (last[j] - first[j] + 1) - mean_l
            mean_u2 += u * u
    mean_u2 /= n
    # centred regressors u = l - mean(l) and q = u^2 - mean(u^2): kappa is q's coefficient
    s_uu = s_uq = s_qq = s_um = s_qm = 0.0
    for j in range(j_lo, j_hi):
        if count[j] > 0:
            u = 0.5 * dx * (last[j] - first[j] + 1) - mean_l
            q = u * u - mean_u2
            m = 0.5 * dx * (first[j] + last[j])
            s_uu += u * u
            s_uq += u * q
            s_qq += q * q
            s_um += u * m
            s_qm += q * m
    det = s_uu * s_qq - s_uq * s_uq
    if not det > 1e-9 * s_uu * s_qq:
        return 0.0
    kappa = (s_uu * s_qm - s_uq * s_um) / det
    return kappa * (s_l2 / n - s_l3 / s_l)


def widest_position(count: Any) -> float:
    """Return the ``auto`` rule's split line in face units ``u`` (``y = y0 + (u - 1/2) dy``).

    ``count[j]``: strip ``j``'s cells in contact.  MAE's split runs along the
    widest strip (the join line of two semi-ellipses, the centre line of an
    ellipse); on a grid the longest chord is a staircase, and a flat-topped
    chord profile (a conformal tread patch) has its longest strip anywhere
    along the top, so an argmax jumps as a row of cells comes or goes.  Here
    every strip whose chord reaches into the band ``[longest - w, longest]``
    (``w`` the larger of :data:`WIDEST_BAND_SHARE` of the longest chord and
    :data:`WIDEST_BAND_CELLS` cells) weighs in by how far it reaches, and the
    split is their weighted centre: a continuous function of the chords, at
    the band's middle on a patch symmetric in ``y`` (``C~13 = 0``), near the
    join line where one half is wider than the other, and inside the patch
    where its longest chord is a cut edge (an ellipse cut near its centre
    line: the zones then stay the two halves' shapes, not one empty zone).
    """
    n = len(count)
    longest = 0
    for j in range(n):
        longest = max(longest, count[j])
    floor = longest - max(WIDEST_BAND_CELLS, WIDEST_BAND_SHARE * longest)
    weight = 0.0
    moment = 0.0
    for j in range(n):
        w = count[j] - floor
        if w > 0.0:
            weight += w
            moment += w * (j + 0.5)
    return moment / weight


def face_blend(count: Any, u: float) -> tuple[int, float]:
    """Return ``(f, t)``: a split at ``u`` as faces ``f``, ``f + 1`` weighted ``1 - t``, ``t``.

    A split between two cell faces has no zones of whole strips; the MAE
    methods solve it as the two faces' splits with their strips' stiffness
    ``1/L`` weighted ``1 - t`` and ``t`` (the full-adhesion coefficients,
    linear in ``1/L``, move linearly between the two faces'), so that the
    force moves continuously with ``u``.  ``u`` is held within the faces of
    the strips in contact; within :data:`SPLIT_SNAP` of a face it is that
    face (``t = 0``), of a strip's middle exactly the middle (``t = 1/2``:
    a patch symmetric in ``y`` then gets both faces alike).
    """
    n = len(count)
    r0 = 0
    while r0 < n - 1 and count[r0] == 0:
        r0 += 1
    r1 = n - 1
    while r1 > 0 and count[r1] == 0:
        r1 -= 1
    u = min(max(u, float(r0)), float(r1 + 1))
    f = int(math.floor(u))
    t = u - f
    if t <= SPLIT_SNAP:
        return f, 0.0
    if t >= 1.0 - SPLIT_SNAP:
        return f + 1, 0.0
    if abs(t - 0.5) <= SPLIT_SNAP:
        return f, 0.5
    return f, t
