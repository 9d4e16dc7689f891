"""Compiled kernels (numba) of FastSim, MAE and the equivalent-ellipse baseline.

The fast path of :mod:`fastsim_ros.contact.compiled`; the numpy modules
(:mod:`~fastsim_ros.contact.fastsim`, :mod:`~fastsim_ros.contact.mae`,
:mod:`~fastsim_ros.contact.equivalent`) stay the readable reference.  The
kernels repeat the reference's formulas with its order of floating-point
operations, except where noted (the order of sums; centroid and second
moments from exact integer index sums; the ellipse's pressure computed on
one quadrant and mirrored; ``sqrt(tau_x^2 + tau_y^2)`` for ``hypot`` away
from the traction bound), so the two agree to a few ulps.  No ROS import.

Conventions (docs/guide_physics.md "Conventions"): pressure ``p[j, i]`` (Pa) on a regular grid,
row ``j`` = lateral strip at ``y0 + j dy``, column ``i`` at ``x0 + i dx``
(m), leading edge at the larger ``x``; a cell is in contact where ``p > 0``.

Errors are not raised here (a raise cannot carry the typed exceptions of
:mod:`~fastsim_ros.contact.errors`): kernels return a status code (``OK``
or one of the ``E_*`` constants below) and the Python layer raises the
matching exception.  ``error_model="numpy"``: a division by zero gives
``inf``/``nan`` as in the numpy reference instead of an exception, and the
loops carry no zero-divisor checks.

Coefficient tables are passed as ``knots`` (``log a/b``, shape ``(K,)``) and
``polys`` (shape ``(len(TABLE_NAMES), 4, K - 1)``): the cubic-spline
coefficients of :class:`~fastsim_ros.contact.tables.CoefficientTable`, in the
order of :data:`TABLE_NAMES`.

Column envelopes ``env`` (``int64``, shape ``(2, nx)``): the cells of column
``i`` that can be in contact lie in rows ``env[0, i] <= j < env[1, i]``.
The sweep visits only those, so the cells around a patch cost nothing.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fastsim_ros.contact import knee, lobes, rules

#: order of the coefficients in the ``polys`` array
TABLE_NAMES = ("C11", "C22", "C23", "C33", "c11", "c12", "c13", "c21", "c22", "c23")
I_C11, I_C22, I_C23 = 0, 1, 2
I_H11, I_H13, I_H22, I_H23 = 4, 6, 8, 9

#: split rules of :func:`fastsim_ros.contact.mae.split_face`
RULE_WIDEST_STRIP, RULE_CENTROID, RULE_AUTO = 0, 1, 2

#: status codes of the kernels (``E_*``; the result slots below have other prefixes)
OK = 0
E_GRID_NONFINITE = 1      # x0, y0, dx or dy is NaN or infinite
E_CELL_SIZE = 2           # dx or dy not positive
E_PRESSURE_NONFINITE = 3  # a pressure value is NaN or infinite
E_PRESSURE_NEGATIVE = 4   # a pressure value is negative
E_EMPTY = 5               # no cell with positive pressure
E_CREEPAGE = 6            # xi, eta or phi not finite
E_MU = 7                  # mu not positive and finite
E_REFERENCE = 8           # reference point not finite
E_TABLE_ZONE1 = 9         # zone 1's a/b outside the table (info: a/b)
E_TABLE_ZONE2 = 10        # zone 2's a/b outside the table (info: a/b)
E_TABLE_ELLIPSE = 11      # the equivalent ellipse's a/b outside the table (info: a/b)
E_CELLS = 13              # fewer than 2 cells for the equivalent ellipse's grid

#: layout of the MAE geometry vector ``geo`` (see :func:`mae_prepare`)
G_XC, G_YC, G_YS, G_FACE, G_NCONTACT, G_LOAD, G_AREA = 0, 1, 2, 3, 4, 5, 6
G_ZONE1, G_ZONE2 = 7, 13    # each: area, a, b, a/b, a_eq, b_eq
G_FLEX1, G_FLEX2 = 19, 23   # each: L1, L2, L3, L4
G_ELLIPSE = 27              # the patch's equivalent ellipse x_c, y_c, a, b
GEO_SIZE = 31

#: layout of the equivalent-ellipse vector ``ell`` (see :func:`equivalent_prepare`)
ELL_XC, ELL_YC, ELL_A, ELL_B, ELL_LOAD, ELL_L1, ELL_L2, ELL_L3, ELL_NCELLS = range(9)
ELL_SIZE = 9

# |tau|^2 <= (1 - 1e-12) g^2 proves |tau| < g without a square root: the
# reference's slip test (hypot, exact to an ulp) gives the same answer there
_NO_SLIP = 1.0 - 1e-12
# within this relative distance of the bound the slip test uses hypot, as the
# reference does, so that the slip flags agree even on the bound
_ON_BOUND = 1e-12
# |tau|^2 > (1 + 1e-9) g^2 proves |tau| > g: the slip test needs no square root there
_CLEARLY_OVER = 1.0 + 1e-9


# ---------------------------------------------------------------- input checks


@njit(cache=True, error_model="numpy")
def check_grid(x0, y0, dx, dy):
    """Return the status of a grid origin ``(x0, y0)`` and cell size ``(dx, dy)`` (m)."""
    if not (math.isfinite(x0) and math.isfinite(y0) and math.isfinite(dx)
            and math.isfinite(dy)):
        return E_GRID_NONFINITE
    if not (dx > 0.0 and dy > 0.0):
        return E_CELL_SIZE
    return OK


@njit(cache=True, error_model="numpy")
def check_solve_inputs(xi, eta, phi, mu, xp, yp):
    """Return the status of the creepages (1, 1, 1/m), ``mu`` and the reference point (m)."""
    if not (math.isfinite(xi) and math.isfinite(eta) and math.isfinite(phi)):
        return E_CREEPAGE
    if not (math.isfinite(mu) and mu > 0.0):
        return E_MU
    if not (math.isfinite(xp) and math.isfinite(yp)):
        return E_REFERENCE
    return OK


@njit(cache=True, error_model="numpy")
def scan_moments(p, count):
    """Validate a pressure grid (Pa) and sum what the centroid and second moments need.

    Fills ``count[j]``, the cells in contact of strip ``j``.  Return
    ``(status, n, si, sj, sii, sjj, psum)``: cells in contact, the sums of
    their column and row indices and of the squares (exact integers), and
    the sum of ``p``.  Non-finite values are reported before negative ones,
    as :class:`~fastsim_ros.contact.area.GridArea` does.  Branch-free, so
    that the compiler vectorises it: counts per column, not sums per cell.
    """
    ny, nx = p.shape
    # one running sum per column: additions that do not wait for each other
    colsum = np.zeros(nx)
    colcount = np.zeros(nx, dtype=np.int64)
    negative = 0
    n = 0
    sj = 0
    sjj = 0
    for j in range(ny):
        c = 0
        for i in range(nx):
            v = p[j, i]
            colsum[i] += v
            pos = v > 0.0
            colcount[i] += pos
            c += pos
            negative += v < 0.0
        count[j] = c
        n += c
        sj += c * j
        sjj += c * j * j
    psum = 0.0
    si = 0
    sii = 0
    for i in range(nx):
        psum += colsum[i]
        si += i * colcount[i]
        sii += i * i * colcount[i]
    if not math.isfinite(psum):
        # NaN and inf propagate into the sums: only then look for them cell by cell
        for j in range(ny):
            for i in range(nx):
                if not math.isfinite(p[j, i]):
                    return E_PRESSURE_NONFINITE, 0, 0, 0, 0, 0, 0.0
    if negative:
        return E_PRESSURE_NEGATIVE, 0, 0, 0, 0, 0, 0.0
    if n == 0:
        return E_EMPTY, 0, 0, 0, 0, 0, 0.0
    return OK, n, si, sj, sii, sjj, psum


@njit(cache=True, error_model="numpy")
def scan_patch(p, count, first, last, env):
    """Run :func:`scan_moments`, then find the strips' extents and the column envelopes.

    Fills ``count``, ``first[j]`` and ``last[j]`` (first and last cell in
    contact of strip ``j``, 0 if none) and ``env``; returns what
    :func:`scan_moments` returns.  The extents are searched from the ends of
    each strip and column, so they cost the cells outside the contact only.
    """
    ny, nx = p.shape
    result = scan_moments(p, count)
    if result[0] != OK:
        return result
    for j in range(ny):
        f = 0
        e = 0
        if count[j] > 0:
            while not p[j, f] > 0.0:
                f += 1
            e = nx - 1
            while not p[j, e] > 0.0:
                e -= 1
        first[j] = f
        last[j] = e
    for i in range(nx):
        lo = 0
        while lo < ny and not p[lo, i] > 0.0:
            lo += 1
        hi = ny
        if lo < ny:
            while not p[hi - 1, i] > 0.0:
                hi -= 1
        else:
            lo = ny
            hi = 0
        env[0, i] = lo
        env[1, i] = hi
    return result


# ---------------------------------------------------------------- tables


@njit(cache=True, error_model="numpy")
def in_table(knots, a_over_b):
    """Whether ``a/b`` lies in the tables' range (``CoefficientTable._log_ratio``'s test)."""
    if not (math.isfinite(a_over_b) and a_over_b > 0.0):
        return False
    t = math.log(a_over_b)
    return knots[0] - 1e-12 <= t <= knots[knots.shape[0] - 1] + 1e-12


@njit(cache=True, error_model="numpy")
def spline(knots, poly, t):
    """Evaluate one coefficient's cubic at ``t = log(a/b)``; ``poly`` has shape ``(4, K - 1)``.

    The interval is ``searchsorted(knots, t) - 1`` clipped to the table, as
    :meth:`~fastsim_ros.contact.tables.CoefficientTable.__call__` picks it.
    """
    lo = 0
    hi = knots.shape[0]
    while lo < hi:  # first knot >= t (numpy's searchsorted, side="left")
        mid = (lo + hi) // 2
        if knots[mid] < t:
            lo = mid + 1
        else:
            hi = mid
    k = min(max(lo - 1, 0), knots.shape[0] - 2)
    u = t - knots[k]
    return ((poly[0, k] * u + poly[1, k]) * u + poly[2, k]) * u + poly[3, k]


@njit(cache=True, error_model="numpy")
def table_value(knots, polys, index, a_over_b):
    """Return coefficient ``TABLE_NAMES[index]`` at ``a/b`` (no range check)."""
    return spline(knots, polys[index], math.log(a_over_b))


# ---------------------------------------------------------------- flexibilities


@njit(cache=True, error_model="numpy")
def half_flexibility(a, b, c11, c13, c22, c23, shear_modulus):
    """Return MAE's ``(L1, L2, L3, L4)`` (m/Pa) of a semi-ellipse ``a``, ``b`` (m).

    ``L1 = 4a/(3 G c11)``, ``L2 = 4a/(3 G c22)``,
    ``L3 = pi a^1.5/(8 G sqrt(b) c23)``, ``L4 = sqrt(a b)/(2 G c13)``
    (``inf`` where ``c13 <= 0``); as :func:`fastsim_ros.contact.mae.zone_flexibility`.
    """
    g = shear_modulus
    l4 = math.sqrt(a * b) / (2.0 * g * c13) if c13 > 0.0 else math.inf
    return (4.0 * a / (3.0 * g * c11), 4.0 * a / (3.0 * g * c22),
            math.pi * a**1.5 / (8.0 * g * math.sqrt(b) * c23), l4)


@njit(cache=True, error_model="numpy")
def kalker_flexibility(a, b, c11, c22, c23, shear_modulus):
    """Return Kalker's ``(L1, L2, L3)`` (m/Pa) of an ellipse ``a``, ``b`` (m).

    As :func:`fastsim_ros.contact.fastsim.kalker_flexibility`.
    """
    return (8.0 * a / (3.0 * shear_modulus * c11), 8.0 * a / (3.0 * shear_modulus * c22),
            math.pi * a * math.sqrt(a / b) / (4.0 * shear_modulus * c23))


# ---------------------------------------------------------------- friction laws

#: law codes (:mod:`fastsim_ros.contact.friction`)
LAW_CONSTANT = rules.LAW_CONSTANT
LAW_EXPONENTIAL = rules.LAW_EXPONENTIAL


#: :func:`fastsim_ros.contact.rules.rigid_slip_return`,
#: :func:`~fastsim_ros.contact.rules.pair_factor` and
#: :func:`~fastsim_ros.contact.rules.chord_bend_offset`, compiled: the reference's formulas,
#: no copies
rigid_slip_return = njit(cache=True, error_model="numpy")(rules.rigid_slip_return)
pair_factor = njit(cache=True, error_model="numpy")(rules.pair_factor)
chord_bend_offset = njit(cache=True, error_model="numpy")(rules.chord_bend_offset)
widest_position = njit(cache=True, error_model="numpy")(rules.widest_position)
face_blend = njit(cache=True, error_model="numpy")(rules.face_blend)


@njit(cache=True, error_model="numpy")
def law_ratio(law, prm, v):
    """``mu(v)/mu_s`` of law ``law`` with parameters ``prm`` at slip velocity ``v`` (m/s).

    The one place the kernels know the laws' formulas (a new law: a branch
    here and its class in :mod:`~fastsim_ros.contact.friction`).  Exponential: ``prm = (A, B)``,
    ``(1 - A) exp(-B v) + A``.
    """
    if law == LAW_EXPONENTIAL:
        a = prm[0]
        return (1.0 - a) * math.exp(-prm[1] * v) + a
    return 1.0


# ---------------------------------------------------------------- the sweep

#: the previous traction state of a steady sweep: none (never read)
_NO_STATE = np.zeros((0, 0))
#: rows of :func:`rolling_sweep`'s ``strip_sums``
STRIP_SUMS = 6
#: no knee table (:func:`mae_sweep`)
NO_KNEE = np.zeros(0)
#: a packed knee table of one node (a placeholder where none is read: one type for the arrays)
_ONE_NODE_KNEE = np.array([1.0, 1.0, 0.0, 0.0, 1.0, 1.0])


@njit(cache=True, error_model="numpy")
def strip_rates(y0, dy, xi, eta, phi, flex, y_s, yp, rate_x, rate_y0, rate_yx, yr, w_x):
    """Fill each strip's constants of the march (the same for the sweep and its slope).

    ``rate_x``, ``rate_y0``, ``rate_yx`` (Pa/m, Pa/m^2 for the last): the
    constant parts of the strip's rates, grouped as the reference does;
    ``yr`` (m): the strip's ``y - yp``; ``w_x`` (1): the rigid slip per unit
    rolling distance along ``x`` (the rigid-slip return's).
    """
    for j in range(len(rate_x)):
        y = y0 + dy * j
        rate_x[j] = xi / flex[0, j] - phi * (y - y_s) / flex[3, j]
        rate_y0[j] = eta / flex[1, j]
        rate_yx[j] = phi / flex[2, j]
        yr[j] = y - yp
        w_x[j] = xi - phi * (y - y_s)


@njit(cache=True, error_model="numpy", inline="always")
def project(t_x, t_y, p_x, p_y, g, lev, law, prm, speed, step, vs, rigid, w_x, g_x, eta, phi,
            x, g_y, l1, l2):
    """Project the trial traction ``(t_x, t_y)`` (Pa) of one step on the bound ``g`` (Pa).

    The march's slip test and return for a transient path's sub-steps
    (:func:`march_path`), the same operations as the cell step of
    :func:`rolling_sweep` writes out (a call there cost the steady march 20-30
    %), so that both march alike (``test_contact_transient`` holds them to the
    same fixed point).  ``(p_x, p_y)``: the traction before the step (Pa);
    ``lev``: the particle's friction ratio on its last step (1 if it stuck;
    slip-dependent laws: the kinetic level is ``g lev``); ``step``: the
    distance rolled in the step (m), ``vs``: ``|V| / step`` (1/s);
    ``rigid``: the rigid-slip return with the rigid slip over the step (m),
    ``w_x step + g_x`` and ``(eta + phi x) step + g_y`` (``w_x``: the strip's
    rigid slip along x per metre, ``x`` (m): where the step ends, ``g_x``,
    ``g_y``: the far field's shift, m; formed only where a cell slips) and
    the strip's flexibilities ``l1``, ``l2`` (m/Pa), else the radial
    return.  Return
    ``(tau_x, tau_y, slipped, ratio)``, the ratio the particle's friction
    ratio after the step (1 where it stuck or the law is constant).
    """
    m2 = t_x * t_x + t_y * t_y
    if law == LAW_CONSTANT:
        if not m2 <= _NO_SLIP * g * g:
            # clearly over the bound: the rigid-slip return needs no |t*|
            if rigid and m2 > _CLEARLY_OVER * g * g:
                mag = g + g
            else:
                mag = math.sqrt(m2)
                if abs(mag - g) <= _ON_BOUND * g:
                    mag = math.hypot(t_x, t_y)
            if mag > g:
                done = False
                if rigid:
                    r_x, r_y, done = rigid_slip_return(p_x, p_y, w_x * step + g_x,
                                                       (eta + phi * x) * step + g_y, l1, l2, g)
                    if done:
                        return r_x, r_y, True, 1.0
                if rigid:
                    # the return declined: the radial return, with the true |t*|
                    mag = math.sqrt(m2)
                scale = g / mag
                return t_x * scale, t_y * scale, True, 1.0
        return t_x, t_y, False, 1.0
    # the kinetic level: static bound times the particle's last friction ratio
    gk = g * lev
    if not m2 <= _NO_SLIP * gk * gk:
        mag = math.sqrt(m2)
        if abs(mag - gk) <= _ON_BOUND * gk:
            mag = math.hypot(t_x, t_y)
        if mag > gk:
            # slip velocity at that level: |V| |L t*| (|t*| - gk) / (|t*| step)
            inv = 1.0 / mag
            lx = l1 * t_x
            ly = l2 * t_y
            done = False
            r_x = 0.0
            r_y = 0.0
            k = 1.0
            if rigid:
                wxh = w_x * step + g_x
                wyh = (eta + phi * x) * step + g_y
                r_x, r_y, done = rigid_slip_return(p_x, p_y, wxh, wyh, l1, l2, gk)
                if done:
                    # the slip at the kinetic level: |w h + L (tau_k - tau_p)| / h
                    s_x = wxh + l1 * (r_x - p_x)
                    s_y = wyh + l2 * (r_y - p_y)
                    k = law_ratio(law, prm, speed * math.sqrt(s_x * s_x + s_y * s_y) / step)
            if not done:
                k = law_ratio(law, prm, vs * math.sqrt(lx * lx + ly * ly) * ((mag - gk) * inv))
            r = g * k
            if r < mag:
                if done:
                    scale = r / gk
                    return r_x * scale, r_y * scale, True, k
                scale = r * inv
                return t_x * scale, t_y * scale, True, k
    return t_x, t_y, False, 1.0


@njit(cache=True, error_model="numpy", inline="always")
def march_path(t_x, t_y, lev, shape, outer, inner, j, i, nx, rolled, nsub, s, v_sub, ahead,
               per, x_rel, d_x, d_y, d_yx, w_x, g_x, g_y, eta, phi, l1, l2, law, prm, speed,
               rigid):
    """March a particle of strip ``j`` from ``x + rolled`` to one step before cell ``i``.

    :func:`rolling_sweep`'s path of a transient step: ``nsub - 1`` steps of
    ``rolled / nsub`` (m), each projected with :func:`project` on the bound
    of the cell the particle reaches (zero traction where it is off the
    contact); ``(t_x, t_y)`` (Pa) and ``lev`` (its friction ratio) where it
    starts; ``s = rolled / nsub`` (m), ``v_sub = speed / s`` (1/s), the
    cell reached after step ``m`` is ``i + int(ahead - (m + 1) per)``
    (``ahead = rolled / dx + 0.5``, ``per = s / dx``); the step's constant
    parts of the strip (Pa, Pa/m): ``d_x = rate_x s + g_x / l1``, ``d_y =
    rate_y0 s + g_y / l2``, ``d_yx = rate_yx s`` (the rates of
    :func:`strip_rates`, ``g_x``, ``g_y`` the far field's shift per step, m).
    All of them are the same for every cell of a sweep or of a strip:
    :func:`rolling_sweep` computes them once (with the rest of its per-cell
    constants: a two-cell step of the 60 x 60 semi-ellipses 66.7-68.8 ->
    62.7-63.2 us, the paper's MAE, alternating runs).  Return the
    traction and ratio before the last step (the cell's own,
    :func:`rolling_sweep`'s).  Inlined: as a call per cell it cost a 30 x
    30 step of two cells 26.8 -> 34.4 us (the paper's MAE) and 34.3 -> 46.1
    us (the calibrated one), same run; the steady march never enters it.
    """
    for m in range(nsub - 1):
        ic = min(i + int(ahead - (m + 1) * per), nx - 1)
        g_m = outer * (shape[j, ic] * inner)
        if not g_m > 0.0:
            # off the contact on its way: no traction carried on
            t_x = 0.0
            t_y = 0.0
            lev = 1.0
            continue
        x_m = x_rel + rolled - (m + 0.5) * s
        p_x = t_x
        p_y = t_y
        t_x = t_x - d_x
        t_y = t_y - (d_y + d_yx * x_m)
        t_x, t_y, _, lev = project(t_x, t_y, p_x, p_y, g_m, lev, law, prm, speed, s, v_sub,
                                   rigid, w_x, g_x, eta, phi, x_m - 0.5 * s, g_y, l1, l2)
    return t_x, t_y, lev


@njit(cache=True, error_model="numpy", inline="always")
def adhesion_step(lin, j, continues, dx, half, rate_x, rate_y0, rate_yx, x_rel, g):
    """Advance strip ``j``'s march without a bound by one cell and add it to its sums.

    ``lin`` ``(5, ny)``: the strip's traction in full adhesion at its last
    cell (``x``, ``y``, Pa), its sums over the strip's cells so far (Pa) and
    the sum of the bound ``g`` (Pa); a cell that does not continue the
    strip's segment starts from zero traction half a cell behind its front
    face.  ``rate_*`` the strip's rates (:func:`strip_rates`), ``x_rel``
    (m) the cell's ``x`` from the sweep point.  Inlined in the marches.
    """
    s_l = dx if continues else half
    if not continues:
        lin[0, j] = 0.0
        lin[1, j] = 0.0
    lin[0, j] = lin[0, j] - rate_x * s_l
    lin[1, j] = lin[1, j] - (rate_y0 + rate_yx * (x_rel + 0.5 * s_l)) * s_l
    lin[2, j] += lin[0, j]
    lin[3, j] += lin[1, j]
    lin[4, j] += g


@njit(cache=True, error_model="numpy")
def sweep(shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp, yp,
          law, prm, speed, out_x, out_y, slip, store, rigid, strip_sums=_NO_STATE):
    """March every strip from its leading edge; return ``(Fx, Fy, Mz, slipping, in contact)``.

    The steady state: :func:`rolling_sweep` with an infinite distance rolled
    (every cell's material entered the contact under the present creepages).
    """
    return rolling_sweep(shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c,
                         y_s, xp, yp, law, prm, speed, out_x, out_y, slip, store, rigid,
                         _NO_STATE, _NO_STATE, math.inf, 0.0, 0.0, 1.0, 1.0, strip_sums)


@njit(cache=True, error_model="numpy")
def rolling_sweep(shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp,
                  yp, law, prm, speed, out_x, out_y, slip, store, rigid, prev_x, prev_y,
                  rolled, shift_x, shift_y, relax_x, relax_y, strip_sums=_NO_STATE):
    """March every strip from its leading edge over one time step of rolling ``rolled`` (m).

    Kalker's non-steady FASTSIM (Kalker 1990, "Three-dimensional elastic
    bodies in rolling contact", section 5.4; :mod:`fastsim_ros.contact.transient`):
    the particle at cell centre ``x`` was at ``x + rolled`` one step ago.
    Where its distance ``d`` from its segment's front face is at most
    ``rolled`` it entered the contact during the step, with zero traction,
    and rolled ``d`` under the present creepages: its traction is the steady
    march's (``rolled = inf`` is the steady state, :func:`sweep`).
    Elsewhere its trial traction is the previous state ``prev_x``,
    ``prev_y`` (Pa, shape of ``shape``) interpolated linearly along the strip
    at ``x + rolled`` (zero at the segment's front face), marched from
    there to ``x`` in steps of at most a cell: each step subtracts the rigid
    slip over it divided by ``L`` (``phi x`` at the step's middle) and is
    projected on the bound where the particle then is with the steady
    march's own projection (:func:`project`), so that with ``rolled`` a
    whole number of cells the steady state is a fixed point of the steps.
    ``shift_x``, ``shift_y`` (m): the elastic shift of the whole patch over
    the step (:mod:`fastsim_ros.contact.transient`, the
    half-space's far field ``M dF``), added to the rigid slip of the cells
    that were in the contact before the step (zero: Kalker's local model).
    A cell that entered during the step, ``d`` (m) from the front face,
    saw the part of it since it entered: the force is taken to approach its
    new value over the step as a first-order lag of length ``relax_x``,
    ``relax_y`` (m), so the shift since entry is ``s expm1(d/l) /
    expm1(h/l)`` (``d/h`` for ``h << l``, nothing but the last ``l``
    before the step's end for ``h >> l``: the steady state).
    Slip-dependent laws: the kinetic level is the upstream
    cell's friction ratio in this sweep, as in the steady march.

    The kernel of :func:`fastsim_ros.contact.fastsim.sweep` and the
    resultants of :func:`~fastsim_ros.contact.fastsim.fastsim`.  The
    traction bound (Pa) of cell ``(j, i)`` is ``outer * (shape[j, i] *
    inner)`` (``mu p`` is ``shape = p``, ``outer = mu``, ``inner = 1``; a
    finished bound has ``outer = inner = 1``), zero outside the contact and
    only read inside the column envelopes ``env``.  ``xi``, ``eta``, ``phi``
    (1, 1, 1/m): the creepages at the sweep point ``(x_c, y_s)`` (m);
    ``flex`` (m/Pa), ``(4, ny)``: each strip's ``L1, L2, L3`` and spin
    flexibility (``L3``, or MAE's ``L4``; may be ``inf``).  ``Fx``, ``Fy``
    (N), ``Mz`` (N m) about ``(xp, yp)`` (m), cells on the bound, cells in
    contact.  With ``store`` the tractions (Pa) and slip flags are written
    to ``out_x``, ``out_y``, ``slip`` (shape of ``shape``); without it
    those are not touched (pass empty arrays).  ``law``, ``prm``: the
    friction law (:func:`law_ratio`); the bound above is then the static one
    and each cell follows :func:`fastsim_ros.contact.fastsim.slip_ratio` at
    rolling speed ``speed`` (m/s), step for step: it slips where its trial
    exceeds its kinetic level (the upstream cell's friction ratio, if that
    one slipped, times the static bound), with the ratio of the slip it has
    at that level; :data:`LAW_CONSTANT` is the constant-friction path as it
    always was.  ``rigid``: a cell over the bound slips along its slip
    (:func:`rigid_slip_return`, the reference's ``slip_rule="rigid_slip"``)
    instead of the radial return.

    ``strip_sums`` ``(6, ny)``, if given (else an empty array): per strip the
    sums over its cells of the traction ``tau_x``, ``tau_y`` (Pa), of ``x
    tau_y - y tau_x`` about ``(xp, yp)`` (Pa m), of the steady march's
    traction without a bound (the strip in full adhesion: Kalker's linear
    force of FastSim) in ``x`` and ``y`` (Pa), and of the bound ``g`` (Pa);
    times ``dx dy`` they are forces (:func:`strip_knee`).

    Like the reference, the march goes column by column with the strips side
    by side: the strips are independent, so the CPU overlaps their chains of
    dependent operations (a strip alone is a chain of square root, division
    and product per slipping cell, three times slower).
    """
    ny, nx = shape.shape
    record = strip_sums.shape[0] == STRIP_SUMS
    # the strips in full adhesion (record): the steady march's traction without a bound, and
    # the sums of it and of the bound
    lin = np.zeros((5, ny if record else 1))
    slx, sly, sgb = lin[2], lin[3], lin[4]
    da = dx * dy
    half = 0.5 * dx
    # per-strip state, constants and partial sums in one block (one allocation)
    w = np.empty((10, ny))
    tx, ty, sx, sy, sm = w[0], w[1], w[2], w[3], w[4]
    rate_x, rate_y0, rate_yx, yr, w_x = w[5], w[6], w[7], w[8], w[9]
    # the column a strip's current segment continues into (else: a new segment)
    cont = np.empty(ny, dtype=np.int64)
    # distance from the segment's front face to the last cell's centre (m), the segment's first
    # column (the previous state is interpolated between the cells up to that one)
    dist = np.zeros(ny)
    first = np.zeros(ny, dtype=np.int64)
    # slip-dependent laws: strip j's friction ratio in its last cell if that one slipped, else 1
    level = np.ones(ny)
    strip_rates(y0, dy, xi, eta, phi, flex, y_s, yp, rate_x, rate_y0, rate_yx, yr, w_x)
    sx[:] = 0.0
    sy[:] = 0.0
    sm[:] = 0.0
    cont[:] = -2
    if store:
        out_x[:, :] = 0.0
        out_y[:, :] = 0.0
        slip[:, :] = False
    nslip = 0
    ncontact = 0
    # the far field's share since entry at the front face (column 0: none) and at the n-th
    # cell of a segment (column n + 1, d = half + n dx)
    far = shift_x != 0.0 or shift_y != 0.0
    share = np.zeros((2, nx + 2 if far else 1))
    if far:
        for c in range(2):
            relax = relax_x if c == 0 else relax_y
            for n in range(nx + 1):
                d = half + n * dx
                if d >= rolled:
                    share[c, n + 1] = 1.0
                elif rolled > 50.0 * relax:
                    share[c, n + 1] = math.exp((d - rolled) / relax)
                else:
                    share[c, n + 1] = math.expm1(d / relax) / math.expm1(rolled / relax)
    # slip-dependent laws: |V| per metre of a full step and of a segment's first half step
    v_full = speed / dx
    v_half = speed / half
    # slip-dependent laws over marched paths: each cell's friction ratio in this sweep (a
    # path's start reads it)
    marched = rolled > dx and rolled < math.inf
    kinetic = law != LAW_CONSTANT and marched
    kin = np.ones((ny, nx) if kinetic else (1, 1))
    # the weights of the previous state at x + rolled, the same for every cell: cubic c0 .. c3,
    # linear u, w0 next to the front face
    f = rolled / dx if rolled < math.inf else 0.0
    k0 = int(f)
    u = f - k0
    c0 = -u * (u - 1.0) * (u - 2.0) / 6.0
    c1 = (u + 1.0) * (u - 1.0) * (u - 2.0) / 2.0
    c2 = -(u + 1.0) * u * (u - 2.0) / 2.0
    c3 = (u + 1.0) * u * (u - 1.0) / 6.0
    w0 = 1.0 - (rolled - k0 * dx) / half
    # a step longer than a cell (marched): the paths' sub-steps (march_path) and their
    # constants, the same for every cell (sweep) or strip (d_*, each cell's shift per L: one
    # division a strip)
    nsub = int(math.ceil(rolled / dx - 1e-9)) if marched else 1
    s_sub = rolled / nsub
    v_sub = speed / s_sub
    ahead = rolled / dx + 0.5
    per = s_sub / dx
    gx_sub = shift_x / nsub
    gy_sub = shift_y / nsub
    # per strip: the far field's shift over a memory cell's own step divided by L1, L2 (Pa),
    # and the sub-steps' constant parts d_x, d_y, d_yx (march_path)
    memory = rolled < math.inf
    strip = np.empty((5, ny if memory else 1))
    gl_x, gl_y, d_x, d_y, d_yx = strip[0], strip[1], strip[2], strip[3], strip[4]
    if memory:
        for j in range(ny):
            gl_x[j] = gx_sub / flex[0, j]
            gl_y[j] = gy_sub / flex[1, j]
            d_x[j] = rate_x[j] * s_sub + gl_x[j]
            d_y[j] = rate_y0[j] * s_sub + gl_y[j]
            d_yx[j] = rate_yx[j] * s_sub
    for i in range(nx - 1, -1, -1):
        x = x0 + dx * i
        x_rel = x - x_c
        xr = x - xp
        for j in range(env[0, i], env[1, i]):
            g = outer * (shape[j, i] * inner)
            if not g > 0.0:
                continue
            if record:
                # the steady march without a bound, from the segment's front face
                adhesion_step(lin, j, cont[j] == i, dx, half, rate_x[j], rate_y0[j],
                              rate_yx[j], x_rel, g)
            if cont[j] == i:
                s = dx
                t_x = tx[j]
                t_y = ty[j]
                dist[j] += dx
            else:
                # first cell of a segment: zero traction at its front face, half a step back
                s = half
                t_x = 0.0
                t_y = 0.0
                level[j] = 1.0
                dist[j] = half
                first[j] = i
            cont[j] = i - 1
            g_x = 0.0
            g_y = 0.0
            # the far field's shift over the cell's own step divided by L1, L2 (Pa)
            glx = 0.0
            gly = 0.0
            lev = level[j]
            if far and dist[j] <= rolled:
                # entered during the step: the far field's increment over this cell's march
                n = int((dist[j] - half) / dx + 0.5)
                g_x = shift_x * (share[0, n + 1] - share[0, n])
                g_y = shift_y * (share[1, n + 1] - share[1, n])
                glx = g_x / flex[0, j]
                gly = g_y / flex[1, j]
            elif dist[j] > rolled:
                g_x = gx_sub
                g_y = gy_sub
                glx = gl_x[j]
                gly = gl_y[j]
                # in the contact before the step: from the previous state at x + rolled
                s = rolled
                iu = i + k0
                if iu + 2 <= first[j] and iu >= 1 and shape[j, iu - 1] > 0.0:
                    # cubic Lagrange through the cells iu - 1 .. iu + 2 (exact for the
                    # quadratic traction of spin in adhesion: no smearing over the steps)
                    t_x = (c0 * prev_x[j, iu - 1] + c1 * prev_x[j, iu] + c2 * prev_x[j, iu + 1]
                           + c3 * prev_x[j, iu + 2])
                    t_y = (c0 * prev_y[j, iu - 1] + c1 * prev_y[j, iu] + c2 * prev_y[j, iu + 1]
                           + c3 * prev_y[j, iu + 2])
                elif iu < first[j]:
                    t_x = (1.0 - u) * prev_x[j, iu] + u * prev_x[j, iu + 1]
                    t_y = (1.0 - u) * prev_y[j, iu] + u * prev_y[j, iu + 1]
                else:
                    # between the first cell's centre and the front face (zero traction there)
                    t_x = w0 * prev_x[j, iu]
                    t_y = w0 * prev_y[j, iu]
                if marched:
                    # the particle's path from x + h, marched in steps of at most a cell, each
                    # projected on the bound where the particle is, as the steady march does
                    # (the slip's direction follows the local rigid slip, which spin turns
                    # along the path; one projection over a long step took the path's mean):
                    # with h a whole number of cells the steady state is then a fixed point
                    # of the steps exactly; the last step is the cell's own
                    s = s_sub
                    lev = 1.0
                    if kinetic:
                        # the particle's friction ratio where it starts, this sweep's there
                        start = i + int(f + 0.5)
                        if start <= first[j]:
                            lev = kin[j, start]
                    t_x, t_y, lev = march_path(
                        t_x, t_y, lev, shape, outer, inner, j, i, nx, rolled, nsub, s_sub,
                        v_sub, ahead, per, x_rel, d_x[j], d_y[j], d_yx[j], w_x[j], g_x, g_y,
                        eta, phi, flex[0, j], flex[1, j], law, prm, speed, rigid)
            # the cell's own step: project()'s projection written out (a call costs the
            # steady march 20-30 %, measured; the fixed-point test of whole-cell transient
            # steps holds the two to the same answer)
            x_mid = x_rel + 0.5 * s
            p_x = t_x
            p_y = t_y
            t_x = t_x - rate_x[j] * s - glx
            t_y = t_y - (rate_y0[j] + rate_yx[j] * x_mid) * s - gly
            over = False
            m2 = t_x * t_x + t_y * t_y
            if law == LAW_CONSTANT:
                if not m2 <= _NO_SLIP * g * g:
                    # clearly over the bound: the rigid-slip return needs no |t*|
                    if rigid and m2 > _CLEARLY_OVER * g * g:
                        mag = g + g
                    else:
                        mag = math.sqrt(m2)
                        if abs(mag - g) <= _ON_BOUND * g:
                            mag = math.hypot(t_x, t_y)
                    if mag > g:
                        done = False
                        if rigid:
                            r_x, r_y, done = rigid_slip_return(
                                p_x, p_y, w_x[j] * s + g_x, (eta + phi * x_rel) * s + g_y,
                                flex[0, j], flex[1, j], g)
                            if done:
                                t_x = r_x
                                t_y = r_y
                        if not done:
                            if rigid:
                                # the return declined: the radial return, with the true |t*|
                                mag = math.sqrt(m2)
                            scale = g / mag
                            t_x = t_x * scale
                            t_y = t_y * scale
                        over = True
                        nslip += 1
            else:
                # the kinetic level: static bound times the particle's last friction ratio
                # (the upstream cell's, or its own on a transient path)
                gk = g * lev
                if not m2 <= _NO_SLIP * gk * gk:
                    mag = math.sqrt(m2)
                    if abs(mag - gk) <= _ON_BOUND * gk:
                        mag = math.hypot(t_x, t_y)
                    if mag > gk:
                        # slip velocity at that level: |V| |L t*| (|t*| - gk) / (|t*| step)
                        inv = 1.0 / mag
                        lx = flex[0, j] * t_x
                        ly = flex[1, j] * t_y
                        vs = v_full if s == dx else (v_half if s == half else speed / s)
                        done = False
                        if rigid:
                            wxh = w_x[j] * s + g_x
                            wyh = (eta + phi * x_rel) * s + g_y
                            r_x, r_y, done = rigid_slip_return(p_x, p_y, wxh, wyh,
                                                               flex[0, j], flex[1, j], gk)
                            if done:
                                # the slip at the kinetic level: |w h + L (tau_k - tau_p)| / h
                                s_x = wxh + flex[0, j] * (r_x - p_x)
                                s_y = wyh + flex[1, j] * (r_y - p_y)
                                k = law_ratio(law, prm, speed * math.sqrt(s_x * s_x + s_y * s_y)
                                              / s)
                        if not done:
                            k = law_ratio(law, prm, vs * math.sqrt(lx * lx + ly * ly)
                                          * ((mag - gk) * inv))
                        r = g * k
                        if r < mag:
                            if done:
                                scale = r / gk
                                t_x = r_x * scale
                                t_y = r_y * scale
                            else:
                                scale = r * inv
                                t_x = t_x * scale
                                t_y = t_y * scale
                            over = True
                            nslip += 1
                            level[j] = k
                if not over:
                    level[j] = 1.0
                if kinetic:
                    kin[j, i] = level[j]
            tx[j] = t_x
            ty[j] = t_y
            sx[j] += t_x
            sy[j] += t_y
            sm[j] += xr * t_y - yr[j] * t_x
            ncontact += 1
            if store:
                out_x[j, i] = t_x
                out_y[j, i] = t_y
                slip[j, i] = over
    fx = 0.0
    fy = 0.0
    mz = 0.0
    for j in range(ny):
        fx += sx[j]
        fy += sy[j]
        mz += sm[j]
        if record:
            strip_sums[0, j] = sx[j]
            strip_sums[1, j] = sy[j]
            strip_sums[2, j] = sm[j]
            strip_sums[3, j] = slx[j]
            strip_sums[4, j] = sly[j]
            strip_sums[5, j] = sgb[j]
    return fx * da, fy * da, mz * da, nslip, ncontact


# ---------------------------------------------------------------- FastSim's knee, strip by strip


@njit(cache=True, error_model="numpy")
def knee_arrays(knee):
    """Return ``(log_aspect, s, kappa)`` of a packed knee table (:func:`knee_pack`)."""
    na = int(knee[0])
    ns = int(knee[1])
    kappa = knee[2 + na + ns:2 + na + ns + 2 * na * ns].reshape((2, na, ns))
    return knee[2:2 + na], knee[2 + na:2 + na + ns], kappa


@njit(cache=True, error_model="numpy")
def knee_capped(k, sx, sy, bound):
    """Return the factor ``k`` of a strip whose force sums ``sx``, ``sy`` at most ``bound``.

    A strip carries at most its traction bound summed (``mu N_j``): a
    factor above 1 on a strip all in slip would exceed it, so the factor is
    capped there (a strip in full slip keeps FastSim's force, ``mu N_j``,
    as the exact theory has it).
    """
    f2 = sx * sx + sy * sy
    if k > 1.0 and k * k * f2 > bound * bound:
        return bound / math.sqrt(f2)
    return k


@njit(cache=True, error_model="numpy", inline="always")
def strip_factor(log_aspect_nodes, s_nodes, kappa, lx, ly, bound, log_aspect):
    """Return ``(kappa_j, d kappa/d s, s_j)`` of a strip, not capped; ``(1, 0, 0)`` if idle.

    The strip's force in full adhesion ``(lx, ly)`` and its bound summed
    ``bound`` (any common unit) put it at ``s_j = |F_lin,j| / (mu N_j)``;
    the table (:func:`knee_arrays`) gives the factor there, at ``log(a/b)``
    = ``log_aspect`` and the share of ``x`` in the linear force.  A strip
    with no linear force or no bound has no factor.
    """
    l2 = lx * lx + ly * ly
    if l2 > 0.0 and bound > 0.0:
        s_j = math.sqrt(l2) / bound
        k, dk = knee_interpolate(log_aspect_nodes, s_nodes, kappa, s_j, log_aspect,
                                 lx * lx / l2)
        return k, dk, s_j
    return 1.0, 0.0, 0.0


@njit(cache=True, error_model="numpy", inline="always")
def factored_sums(sums, j, k, fx, fy, mz, kappa_out):
    """Return the force sums ``fx, fy, mz`` with strip ``j``'s sums times its factor ``k`` added.

    ``sums``: the strips' sums (rows ``tau_x``, ``tau_y``, the moment's);
    ``kappa_out`` ``(ny,)``, if given, receives ``k``.
    """
    if kappa_out.shape[0] == sums.shape[1]:
        kappa_out[j] = k
    return fx + k * sums[0, j], fy + k * sums[1, j], mz + k * sums[2, j]


@njit(cache=True, error_model="numpy")
def strip_knee(strip_sums, da, knee, log_aspect, out_x, out_y, store, kappa_out=NO_KNEE):
    """Return ``(Fx, Fy, Mz)`` (N, N, N m): each strip's force times its knee factor.

    :mod:`fastsim_ros.contact.knee`, applied strip by strip: strip ``j``
    with ``F_lin,j`` its force in full adhesion and ``g`` summed over it
    (``mu N_j``) is at ``s_j = |F_lin,j| / (mu N_j)``, and its force and
    moment (``strip_sums``, :func:`rolling_sweep`) are multiplied by
    ``kappa(s_j, a/b, F_lin,x^2 / |F_lin|^2)`` of the packed table ``knee``
    (:func:`knee_pack`) at ``log(a/b)`` = ``log_aspect`` (the patch's
    equivalent ellipse), capped at the strip's bound (:func:`knee_capped`).
    On an ellipse every strip is at the patch's ``s`` (FastSim's strip
    force and load both go as the chord squared) and this
    is the tabulated factor; on a patch of another shape each strip reads
    the knee at its own share of the saturation.  With ``store`` the
    strip's tractions ``out_x``, ``out_y`` (Pa) are scaled alike, so that
    they sum to the forces; ``kappa_out`` ``(ny,)``, if given, receives the
    strips' factors.
    """
    la, sn, kap = knee_arrays(knee)
    ny = strip_sums.shape[1]
    fx = 0.0
    fy = 0.0
    mz = 0.0
    for j in range(ny):
        k, _, s_j = strip_factor(la, sn, kap, strip_sums[3, j], strip_sums[4, j],
                                 strip_sums[5, j], log_aspect)
        if s_j > 0.0:
            k = knee_capped(k, strip_sums[0, j], strip_sums[1, j], strip_sums[5, j])
        fx, fy, mz = factored_sums(strip_sums, j, k, fx, fy, mz, kappa_out)
        if store and k != 1.0:
            for i in range(out_x.shape[1]):
                out_x[j, i] *= k
                out_y[j, i] *= k
    return fx * da, fy * da, mz * da


@njit(cache=True, error_model="numpy")
def tractions_knee(out_x, out_y, shape, outer, inner, env, x0, y0, dx, dy, xp, yp, yr, steady,
                   knee, log_aspect, kappa_out):
    """Return ``(Fx, Fy, Mz)`` of a transient traction field with each strip's knee factor.

    Transient rolling's new state ``out_x``, ``out_y`` (Pa; it stays as it
    is) against the steady march's ``steady`` (:func:`rolling_sweep`'s
    ``strip_sums`` at the same creepages): strip ``j`` takes the factor of
    its steady state, ``kappa_j`` at the steady ``s_j`` (:func:`strip_knee`),
    in the share its force has built up towards it, ``w_j = F_j . F_j^st /
    |F_j^st|^2`` within ``[0, 1]``: ``1 + (kappa_j - 1) w_j``.  The knee
    factor is a property of the steady saturation; a strip still building
    up its force after a step is not at its knee (taken at once, the
    factor puts the force about 5% of mu N beyond the exact transient
    theory's during a step's build-up: scripts and test_contact_transient
    measure it), and in the steady state
    ``w_j = 1`` and the forces are the steady solve's.  ``yr``: the strips'
    ``y - yp`` (m).  ``kappa_out`` as :func:`strip_knee`'s.
    """
    ny, nx = shape.shape
    sums = np.zeros((STRIP_SUMS, ny))
    for i in range(nx - 1, -1, -1):
        xr = x0 + dx * i - xp
        for j in range(env[0, i], env[1, i]):
            g = outer * (shape[j, i] * inner)
            if not g > 0.0:
                continue
            t_x = out_x[j, i]
            t_y = out_y[j, i]
            sums[0, j] += t_x
            sums[1, j] += t_y
            sums[2, j] += xr * t_y - yr[j] * t_x
    la, sn, kap = knee_arrays(knee)
    fx = 0.0
    fy = 0.0
    mz = 0.0
    for j in range(ny):
        k, _, s_j = strip_factor(la, sn, kap, steady[3, j], steady[4, j], steady[5, j],
                                 log_aspect)
        if s_j > 0.0:
            k = knee_capped(k, steady[0, j], steady[1, j], steady[5, j])
            st2 = steady[0, j] * steady[0, j] + steady[1, j] * steady[1, j]
            if st2 > 0.0:
                w = (sums[0, j] * steady[0, j] + sums[1, j] * steady[1, j]) / st2
                if w < 1.0:  # (the steady state keeps kappa itself, to the bit)
                    k = 1.0 + (k - 1.0) * max(w, 0.0)
            k = knee_capped(k, sums[0, j], sums[1, j], steady[5, j])
        fx, fy, mz = factored_sums(sums, j, k, fx, fy, mz, kappa_out)
    da = dx * dy
    return fx * da, fy * da, mz * da


# ---------------------------------------------------------------- the slope in mu_s


@njit(cache=True, error_model="numpy")
def law_ratio_slope(law, prm, v):
    """``d(mu(v)/mu_s)/dv`` (s/m) of :func:`law_ratio`: ``-(1 - A) B exp(-B v)``, or 0."""
    if law == LAW_EXPONENTIAL:
        return -(1.0 - prm[0]) * prm[1] * math.exp(-prm[1] * v)
    return 0.0


@njit(cache=True, error_model="numpy")
def rigid_slip_return_slope(px, py, dpx, dpy, wxh, wyh, l1, l2, g, dg):
    """:func:`rigid_slip_return` (its operations in order) and its derivative.

    The derivative along ``(dpx, dpy, dg)`` (the upstream traction's and the
    bound's in ``mu_s``).  Return ``(tau_x, tau_y, d tau_x, d tau_y,
    applies)``: the chain rule through ``U = L tau_p - w h``, ``V = U - g D
    U/|U|``, ``tau = g V/|V|`` (``w h`` does not depend on ``mu_s``).
    """
    ux = l1 * px - wxh
    uy = l2 * py - wyh
    n = math.sqrt(ux * ux + uy * uy)
    if not n > 0.0:
        return 0.0, 0.0, 0.0, 0.0, False
    gd = g * 0.5 * (l1 - l2) / n
    vx = ux - gd * ux
    vy = uy + gd * uy
    m = math.sqrt(vx * vx + vy * vy)
    if not m > g * 0.5 * (l1 + l2):
        return 0.0, 0.0, 0.0, 0.0, False
    r = g / m
    # the derivatives: one division per square root, the reciprocals carry the quotients'
    inv_n = 1.0 / n
    inv_m = 1.0 / m
    dux = l1 * dpx
    duy = l2 * dpy
    dn = (ux * dux + uy * duy) * inv_n
    dgd = 0.5 * (l1 - l2) * (dg - g * dn * inv_n) * inv_n
    dvx = dux - (dgd * ux + gd * dux)
    dvy = duy + (dgd * uy + gd * duy)
    dm = (vx * dvx + vy * dvy) * inv_m
    dr = (dg - r * dm) * inv_m
    return r * vx, r * vy, dr * vx + r * dvx, dr * vy + r * dvy, True


@njit(cache=True, error_model="numpy")
def sweep_mu_slope(shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s,
                   xp, yp, law, prm, speed, rigid, mu, knee=NO_KNEE, log_aspect=0.0):
    """March as the steady :func:`sweep` does, differentiating the forces in ``mu_s``.

    Return ``(Fx, Fy, Mz, dFx/dmu_s, dFy/dmu_s, slipping, in contact)``
    (N, N, N m, N, N): the first three and the counts are :func:`sweep`'s to
    the bit (the same operations in the same order; without tractions
    stored), the derivatives by forward-mode differentiation of the march
    (tangent-linear FastSim).  Every bound is ``mu_s`` times a field that
    does not depend on it (``mu p``, or the parabolic ``mu N p^2 / sum p^2
    dA``), so ``dg/dmu_s = g / mu_s``.  A cell in adhesion carries the
    derivative of its upstream neighbour's traction (``tau = tau_p - rates
    h``, the rates free of ``mu_s``); a cell on the radial return ``tau = r
    e``, ``e = t*/|t*|``, has ``d tau = dr e + (r/|t*|) (I - e e^T) d t*``;
    the rigid-slip return and the slip-dependent kinetic level (``r = g
    k(v)``, ``k`` the law's ratio at the cell's slip speed ``v``, the next
    cell's level) follow by the chain rule (:func:`rigid_slip_return_slope`,
    :func:`law_ratio_slope`).  The forces are piecewise smooth in ``mu_s``
    (a cell changing state is continuous in its traction), so this is the
    derivative everywhere but on the measure-zero set where a cell sits on
    its bound; a central difference of the solve agrees with it to 1e-11 of
    the load (test_estimation).  The steady state only (the transient
    march's state would carry a derivative of its own); ``mu``: the
    ``mu_s`` of the bound (> 0).  ``knee``, ``log_aspect``: the strips'
    knee factors (:func:`strip_knee`; :data:`NO_KNEE`: none); a strip's
    ``s_j`` goes as ``1/mu_s`` (its bound as ``mu_s``), so its factor adds
    ``-F_j (d kappa/d s) s_j / mu_s`` to the derivative.
    """
    ny, nx = shape.shape
    da = dx * dy
    half = 0.5 * dx
    inv_mu = 1.0 / mu
    record = knee.shape[0] > 0
    lin = np.zeros((5, ny if record else 1))
    slx, sly, sgb = lin[2], lin[3], lin[4]
    w = np.empty((15, ny))
    tx, ty, dtx, dty, sx, sy, sm, dsx, dsy = w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8]
    rate_x, rate_y0, rate_yx, yr, w_x, dlevel = w[9], w[10], w[11], w[12], w[13], w[14]
    level = np.ones(ny)
    cont = np.full(ny, -2, dtype=np.int64)
    strip_rates(y0, dy, xi, eta, phi, flex, y_s, yp, rate_x, rate_y0, rate_yx, yr, w_x)
    w[4:9] = 0.0  # sx, sy, sm, dsx, dsy
    dlevel[:] = 0.0
    nslip = 0
    ncontact = 0
    v_full = speed / dx
    v_half = speed / half
    for i in range(nx - 1, -1, -1):
        x = x0 + dx * i
        x_rel = x - x_c
        xr = x - xp
        for j in range(env[0, i], env[1, i]):
            g = outer * (shape[j, i] * inner)
            if not g > 0.0:
                continue
            dg = g * inv_mu
            if record:
                # the steady march without a bound, from the segment's front face
                adhesion_step(lin, j, cont[j] == i, dx, half, rate_x[j], rate_y0[j],
                              rate_yx[j], x_rel, g)
            if cont[j] == i:
                s = dx
                t_x = tx[j]
                t_y = ty[j]
                d_x = dtx[j]
                d_y = dty[j]
            else:
                s = half
                t_x = 0.0
                t_y = 0.0
                d_x = 0.0
                d_y = 0.0
                level[j] = 1.0
                dlevel[j] = 0.0
            cont[j] = i - 1
            l1 = flex[0, j]
            l2 = flex[1, j]
            x_mid = x_rel + 0.5 * s
            p_x = t_x
            p_y = t_y
            dp_x = d_x
            dp_y = d_y
            t_x = t_x - rate_x[j] * s
            t_y = t_y - (rate_y0[j] + rate_yx[j] * x_mid) * s
            over = False
            m2 = t_x * t_x + t_y * t_y
            if law == LAW_CONSTANT:
                if not m2 <= _NO_SLIP * g * g:
                    mag = math.sqrt(m2)
                    if abs(mag - g) <= _ON_BOUND * g:
                        mag = math.hypot(t_x, t_y)
                    if mag > g:
                        done = False
                        if rigid:
                            r_x, r_y, dr_x, dr_y, done = rigid_slip_return_slope(
                                p_x, p_y, dp_x, dp_y, w_x[j] * s, (eta + phi * x_rel) * s,
                                l1, l2, g, dg)
                            if done:
                                t_x = r_x
                                t_y = r_y
                                d_x = dr_x
                                d_y = dr_y
                        if not done:
                            if rigid:
                                mag = math.sqrt(m2)
                            scale = g / mag
                            inv = 1.0 / mag
                            e_x = t_x * inv
                            e_y = t_y * inv
                            dmag = e_x * d_x + e_y * d_y
                            d_x = dg * e_x + scale * (d_x - e_x * dmag)
                            d_y = dg * e_y + scale * (d_y - e_y * dmag)
                            t_x = t_x * scale
                            t_y = t_y * scale
                        over = True
                        nslip += 1
            else:
                gk = g * level[j]
                dgk = dg * level[j] + g * dlevel[j]
                if not m2 <= _NO_SLIP * gk * gk:
                    mag = math.sqrt(m2)
                    if abs(mag - gk) <= _ON_BOUND * gk:
                        mag = math.hypot(t_x, t_y)
                    if mag > gk:
                        inv = 1.0 / mag
                        lx = l1 * t_x
                        ly = l2 * t_y
                        vs = v_full if s == dx else (v_half if s == half else speed / s)
                        e_x = t_x * inv
                        e_y = t_y * inv
                        dmag = e_x * d_x + e_y * d_y
                        done = False
                        r_x = r_y = dr_x = dr_y = 0.0
                        k = 1.0
                        dv = 0.0
                        if rigid:
                            wxh = w_x[j] * s
                            wyh = (eta + phi * x_rel) * s
                            r_x, r_y, dr_x, dr_y, done = rigid_slip_return_slope(
                                p_x, p_y, dp_x, dp_y, wxh, wyh, l1, l2, gk, dgk)
                            if done:
                                s_x = wxh + l1 * (r_x - p_x)
                                s_y = wyh + l2 * (r_y - p_y)
                                sn = math.sqrt(s_x * s_x + s_y * s_y)
                                v = speed * sn / s
                                k = law_ratio(law, prm, v)
                                if sn > 0.0:
                                    dv = speed * (s_x * l1 * (dr_x - dp_x)
                                                  + s_y * l2 * (dr_y - dp_y)) / (sn * s)
                        if not done:
                            q = math.sqrt(lx * lx + ly * ly)
                            u = (mag - gk) * inv
                            v = vs * q * u
                            k = law_ratio(law, prm, v)
                            dq = (lx * l1 * d_x + ly * l2 * d_y) / q if q > 0.0 else 0.0
                            du = -(dgk - gk * dmag * inv) * inv
                            dv = vs * (dq * u + q * du)
                        dk = law_ratio_slope(law, prm, v) * dv
                        r = g * k
                        if r < mag:
                            dr = dg * k + g * dk
                            if done:
                                scale = r / gk
                                dscale = (dr - scale * dgk) / gk
                                t_x = r_x * scale
                                t_y = r_y * scale
                                d_x = dr_x * scale + r_x * dscale
                                d_y = dr_y * scale + r_y * dscale
                            else:
                                scale = r * inv
                                t_x = t_x * scale
                                t_y = t_y * scale
                                d_x = dr * e_x + scale * (d_x - e_x * dmag)
                                d_y = dr * e_y + scale * (d_y - e_y * dmag)
                            over = True
                            nslip += 1
                            level[j] = k
                            dlevel[j] = dk
                if not over:
                    level[j] = 1.0
                    dlevel[j] = 0.0
            tx[j] = t_x
            ty[j] = t_y
            dtx[j] = d_x
            dty[j] = d_y
            sx[j] += t_x
            sy[j] += t_y
            sm[j] += xr * t_y - yr[j] * t_x
            dsx[j] += d_x
            dsy[j] += d_y
            ncontact += 1
    fx = 0.0
    fy = 0.0
    mz = 0.0
    dfx = 0.0
    dfy = 0.0
    knee_la, knee_s, knee_kappa = knee_arrays(knee if record else _ONE_NODE_KNEE)
    for j in range(ny):
        if record:
            k, dk, s_j = strip_factor(knee_la, knee_s, knee_kappa, slx[j], sly[j], sgb[j],
                                      log_aspect)
            if s_j > 0.0:
                ds = -s_j * inv_mu
                dk_dmu = dk * ds
                capped = knee_capped(k, sx[j], sy[j], sgb[j])
                if capped != k:
                    # k = mu N_j / |F_j|: mu N_j goes as mu_s, |F_j| as its march says
                    k = capped
                    f2 = sx[j] * sx[j] + sy[j] * sy[j]
                    dk_dmu = k * (inv_mu - (sx[j] * dsx[j] + sy[j] * dsy[j]) / f2)
                fx += k * sx[j]
                fy += k * sy[j]
                mz += k * sm[j]
                dfx += k * dsx[j] + dk_dmu * sx[j]
                dfy += k * dsy[j] + dk_dmu * sy[j]
                continue
        fx += sx[j]
        fy += sy[j]
        mz += sm[j]
        dfx += dsx[j]
        dfy += dsy[j]
    return fx * da, fy * da, mz * da, dfx * da, dfy * da, nslip, ncontact


# ---------------------------------------------------------------- MAE geometry


@njit(cache=True, error_model="numpy")
def split_face(count, rule):
    """Index ``f`` of the cell face the MAE split runs along, from the strips' counts.

    ``count[j]``: cells in contact in strip ``j``.  The three rules of
    :func:`fastsim_ros.contact.mae.split_face`, branch for branch: the lower
    face of :func:`split_blend`'s pair.
    """
    return split_blend(count, rule)[0]


@njit(cache=True, error_model="numpy")
def split_blend(count, rule):
    """Return ``(f, t)``: the split as faces ``f`` and ``f + 1`` weighted ``1 - t``, ``t``.

    :func:`fastsim_ros.contact.mae.split_blend`: ``auto`` at the weighted
    centre of the near-longest strips (:func:`~fastsim_ros.contact.rules.widest_position`),
    ``centroid`` at the centroid, both continuous
    (:func:`~fastsim_ros.contact.rules.face_blend`); ``widest_strip`` on one
    face, or a tie's two alike (``t = 1/2``).  :func:`mae_flexibility` blends
    the two faces' strip stiffnesses.
    """
    if rule == RULE_AUTO:
        return face_blend(count, widest_position(count))
    ny = count.shape[0]
    total = 0
    moment = 0
    for j in range(ny):
        total += count[j]
        moment += count[j] * j
    yc = moment / total
    if rule == RULE_CENTROID:
        return face_blend(count, yc + 0.5)
    f, tie = _widest_strip_face(count, yc, moment, total)
    return f, 0.5 if tie else 0.0


@njit(cache=True, error_model="numpy")
def _centroid_face(count, yc, moment, total):
    """Return the face nearest the centroid row coordinate ``yc`` (within the contact), tie."""
    if moment % total == 0:   # the centroid at a strip's centre: its two faces alike
        return moment // total, True
    ny = count.shape[0]
    r0 = 0
    while count[r0] == 0:
        r0 += 1
    r1 = ny - 1
    while count[r1] == 0:
        r1 -= 1
    return min(max(round(yc + 0.5), r0), r1 + 1), False  # Python's round: half to even


@njit(cache=True, error_model="numpy")
def _widest_strip_face(count, yc, moment, total):
    """Return the face through the band of strips with the longest chord (or a jump side), tie."""
    ny = count.shape[0]
    # the band of strips sharing the longest chord (a staircase ellipse has several); of
    # several such bands apart, the widest, then the one nearest the centroid, so that a
    # mirror image in y splits at the mirrored face (the first from y0 did not); two alike
    # at one distance: the centroid's face
    longest = 0
    for j in range(ny):
        longest = max(longest, count[j])
    j0 = -1
    j1 = -1
    tie = False
    j = 0
    while j < ny:
        if count[j] != longest:
            j += 1
            continue
        k = j
        while k + 1 < ny and count[k + 1] == longest:
            k += 1
        if j0 < 0:
            j0, j1 = j, k
        else:
            wider = (k - j) - (j1 - j0)
            nearer = abs(0.5 * (j0 + j1) - yc) - abs(0.5 * (j + k) - yc)
            if wider > 0 or (wider == 0 and nearer > 1e-9):
                j0, j1, tie = j, k, False
            elif wider == 0 and abs(nearer) <= 1e-9:
                tie = True
        j = k + 1
    if tie:
        return _centroid_face(count, yc, moment, total)
    below = count[j0 - 1] if j0 > 0 else 0
    above = count[j1 + 1] if j1 + 1 < ny else 0
    # chords of centred shapes change by two cells at a time (one at each end)
    drop_below = count[j0] - below
    drop_above = count[j0] - above
    if drop_below > drop_above + 2:
        return j0, False
    if drop_above > drop_below + 2:
        return j1 + 1, False
    width = j1 - j0 + 1
    if width % 2 == 0:
        return j0 + width // 2, False
    middle = j0 + width // 2
    # an odd band: the face of its middle strip nearer the centroid; the centroid at the
    # strip's centre: both faces alike (the lower one given)
    if moment == middle * total:
        return middle, True
    return (middle + 1 if yc > middle else middle), False


@njit(cache=True, error_model="numpy")
def zone_geometry(x0, y0, dx, dy, count, first, last, env, f, x_c, y_s, lower, out):
    """Write one zone's ``area, a, b, a/b, a_eq, b_eq`` (m^2, m) to ``out[0:6]``.

    Zone 1 (``lower``) is the strips ``j < f``, zone 2 the others;
    ``count``, ``first``, ``last``: each strip's cells in contact, first and
    last of them; ``env``: the column envelopes, whose ends are the zones'
    outer edges.  Mean-square edge coordinates from cell faces, as
    :func:`fastsim_ros.contact.mae._zone`; an empty zone gets zero area and
    ``nan`` axes.
    """
    ny = count.shape[0]
    nx = env.shape[1]
    j_lo, j_hi = (0, f) if lower else (f, ny)
    n = 0
    rows = 0
    ve_x = 0.0
    for j in range(j_lo, j_hi):
        if count[j] == 0:
            continue
        n += count[j]
        lead = x0 + dx * last[j] + 0.5 * dx - x_c
        trail = x0 + dx * first[j] - 0.5 * dx - x_c
        ve_x += 0.5 * (lead**2 + trail**2)
        rows += 1
    if n == 0:
        out[0] = 0.0
        for k in range(1, 6):
            out[k] = math.nan
        return
    ve_x /= rows
    cols = 0
    ve_y = 0.0
    for i in range(nx):
        # the zone's outer cell of this longitudinal line: its lowest or highest
        if lower:
            j = env[0, i]
            if j < f:
                ve_y += (y_s - (y0 + dy * j - 0.5 * dy)) ** 2
                cols += 1
        else:
            j = env[1, i] - 1
            if j >= f:
                ve_y += (y0 + dy * j + 0.5 * dy - y_s) ** 2
                cols += 1
    ve_y /= cols
    # a semi-ellipse's mean-square edge coordinates are 2/3 of its squared semi-axes
    a = math.sqrt(1.5 * ve_x)
    b = math.sqrt(1.5 * ve_y)
    zone_area = n * (dx * dy)
    g = a / b
    a_eq = math.sqrt(2.0 * zone_area * g / math.pi)
    out[0] = zone_area
    out[1] = a
    out[2] = b
    out[3] = g
    out[4] = a_eq
    out[5] = a_eq / g


@njit(cache=True, error_model="numpy")
def ellipse_from_sums(n, si, sj, sii, sjj, x0, y0, dx, dy):
    """Return ``(x_c, y_c, a, b)`` (m) of the equivalent ellipse from :func:`scan_patch`'s sums.

    Centroid, area and ``a/b = sqrt(Ixx/Iyy)`` of the cells (each cell's own
    ``dx^2/12`` included), as
    :func:`fastsim_ros.contact.equivalent.equivalent_ellipse`.  The second
    moments come from exact integer sums, ``(n sum i^2 - (sum i)^2)/n^2``
    cells^2: no second pass and no cancellation (the products fit in 64 bits
    up to about a million cells; beyond, a float formula takes over).
    """
    x_c = x0 + dx * (si / n)
    y_c = y0 + dy * (sj / n)
    if float(n) * float(max(sii, sjj)) < 4e18:
        var_i = (n * sii - si * si) / (n * n)
        var_j = (n * sjj - sj * sj) / (n * n)
    else:
        var_i = sii / n - (si / n) ** 2
        var_j = sjj / n - (sj / n) ** 2
    ixx = dx * dx * var_i + dx**2 / 12.0
    iyy = dy * dy * var_j + dy**2 / 12.0
    g = math.sqrt(ixx / iyy)
    a = math.sqrt(n * (dx * dy) * g / math.pi)
    return x_c, y_c, a, a / g


@njit(cache=True, error_model="numpy")
def mae_prepare(p, x0, y0, dx, dy, rule, shear_modulus, knots, polys, geo, env, strips,
                calibrated, pair_knots, pair_values, shift=0):
    """MAE steps 1-3 and 6: validate, split, size the zones, look up, give ``L1 .. L4``.

    Writes ``geo`` (length :data:`GEO_SIZE`): centroid ``x_c, y_c``, split
    line ``y_s`` (m), split face index, cells in contact, load ``N = sum p
    dA`` (N), contact area (m^2), then each zone's ``area, a, b, a/b, a_eq,
    b_eq``, each zone's ``L1, L2, L3, L4`` (m/Pa; ``nan`` for an empty
    zone) and the patch's equivalent ellipse ``x_c, y_c, a, b`` (m); and the
    column envelopes ``env`` ``(2, nx)``; ``strips`` ``(3, ny)``: each
    strip's cells in contact, first and last of them (:func:`scan_patch`).
    With ``calibrated`` the ``L1 .. L4`` are the calibrated MAE's
    (:func:`calibrate`, pair factors ``pair_values`` on the nodes
    ``pair_knots``; unread otherwise).  Return ``(status, info)``; ``info`` is
    the offending ``a/b`` of a zone outside the table (the geometry is
    complete then, the flexibilities are not).  ``shift``: the split that
    many faces above the rule's lower face (1: the upper face of
    :func:`split_blend`'s pair).
    """
    status = mae_scan(p, x0, y0, dx, dy, geo, env, strips)
    if status != OK:
        return status, 0.0
    return mae_zones(p, x0, y0, dx, dy, split_face(strips[0], rule) + shift, shear_modulus,
                     knots, polys, geo, env, strips, calibrated, pair_knots, pair_values)


@njit(cache=True, error_model="numpy")
def mae_scan(p, x0, y0, dx, dy, geo, env, strips):
    """:func:`mae_prepare`'s part that does not depend on the split: check, scan, centroid.

    Fills ``env``, ``strips`` and ``geo``'s centroid, cells in contact, load,
    area and equivalent ellipse; return the status.
    """
    status = check_grid(x0, y0, dx, dy)
    if status != OK:
        return status
    count, first, last = strips[0], strips[1], strips[2]
    status, n, si, sj, sii, sjj, total = scan_patch(p, count, first, last, env)
    if status != OK:
        return status
    # the centroid from exact index sums: the reference's sum(x)/n to rounding
    geo[G_XC] = x0 + dx * (si / n)
    geo[G_YC] = y0 + dy * (sj / n)
    e_xc, e_yc, e_a, e_b = ellipse_from_sums(n, si, sj, sii, sjj, x0, y0, dx, dy)
    geo[G_NCONTACT] = n
    geo[G_LOAD] = total * (dx * dy)
    geo[G_AREA] = n * (dx * dy)
    geo[G_ELLIPSE] = e_xc
    geo[G_ELLIPSE + 1] = e_yc
    geo[G_ELLIPSE + 2] = e_a
    geo[G_ELLIPSE + 3] = e_b
    return OK


@njit(cache=True, error_model="numpy")
def mae_zones(p, x0, y0, dx, dy, f, shear_modulus, knots, polys, geo, env, strips,
              calibrated, pair_knots, pair_values):
    """:func:`mae_prepare`'s part for the split along face ``f``, on :func:`mae_scan`'s ``geo``.

    Writes the split line and face, the zones and their ``L1 .. L4``; return
    ``(status, info)`` as :func:`mae_prepare`.
    """
    count, first, last = strips[0], strips[1], strips[2]
    x_c = geo[G_XC]
    y_s = y0 + (f - 0.5) * dy
    geo[G_YS] = y_s
    geo[G_FACE] = f
    zone_geometry(x0, y0, dx, dy, count, first, last, env, f, x_c, y_s, True,
                  geo[G_ZONE1:G_ZONE1 + 6])
    zone_geometry(x0, y0, dx, dy, count, first, last, env, f, x_c, y_s, False,
                  geo[G_ZONE2:G_ZONE2 + 6])
    for k in range(8):
        geo[G_FLEX1 + k] = math.nan
    for zone, flex, code in ((G_ZONE1, G_FLEX1, E_TABLE_ZONE1),
                             (G_ZONE2, G_FLEX2, E_TABLE_ZONE2)):
        if geo[zone] <= 0.0:
            continue
        g = geo[zone + 3]
        if not in_table(knots, g):
            return code, g
        t = math.log(g)
        l1, l2, l3, l4 = half_flexibility(
            geo[zone + 4], geo[zone + 5], spline(knots, polys[I_H11], t),
            spline(knots, polys[I_H13], t), spline(knots, polys[I_H22], t),
            spline(knots, polys[I_H23], t), shear_modulus)
        geo[flex] = l1
        geo[flex + 1] = l2
        geo[flex + 2] = l3
        geo[flex + 3] = l4
    if calibrated:
        calibrate(p, x0, y0, dx, dy, strips, geo, shear_modulus, knots, polys, pair_knots,
                  pair_values)
    return OK, 0.0


@njit(cache=True, error_model="numpy")
def calibrate(p, x0, y0, dx, dy, strips, geo, shear_modulus, knots, polys, pair_knots,
              pair_values):
    """Overwrite ``geo``'s ``L1 .. L4`` with the calibrated MAE's (:func:`mae_prepare` calls it).

    :func:`fastsim_ros.contact.mae_calibrated.calibrated_flexibilities`:
    each zone's half-ellipse ``c11, c22, c23`` scaled by the pair's shared
    factor and ``c13`` times its own pair factor (:func:`pair_factor` at
    ``(log g_self, log g_other)``; 1 if the other zone is empty; as
    :func:`fastsim_ros.contact.mae_calibrated.zone_coefficients`), and the
    sweep's own integrals over the zone's cells,
    ``D1 = sum d dA``, ``D3 = sum s3 dA``, ``D4 = |sum (y - y_s) d dA|``
    (``d``: the length a cell's traction has grown over from its segment's
    front face, ``s3``: the sum of ``(x_mid - x_c) h``), so that FastSim in
    full adhesion gives those coefficients on these cells; ``c23`` with the
    bend of the zone's strips (the reference's ``offset_c23``).  Where ``D3 <= 0``
    the paper's ``L3`` (with the method's ``c23``) is kept.  ``strips``: as
    :func:`mae_prepare` leaves it.  A strip of one segment is summed
    in closed form (the midpoint sums of a linear integrand are exact: a
    cell ``m`` cells behind the front face has ``d = (m + 1/2) dx`` and
    ``s3 = ((x_lead - x_c)^2 - (x - x_c)^2)/2``); a strip of several, cell by
    cell as the sweep marches it.
    """
    ny = p.shape[0]
    x_c = geo[G_XC]
    y_s = geo[G_YS]
    f = int(geo[G_FACE])
    half = 0.5 * dx
    # per zone: D1, D3 and D4 sums (before dA)
    d1_1 = d3_1 = d4_1 = 0.0
    d1_2 = d3_2 = d4_2 = 0.0
    for j in range(ny):
        n = strips[0, j]
        if n == 0:
            continue
        i_first = strips[1, j]
        i_last = strips[2, j]
        y_rel = y0 + dy * j - y_s
        if i_last - i_first + 1 == n:
            # one segment: m = 0 .. n-1 cells behind the front face x_last + dx/2
            x_lead = x0 + dx * i_last + half - x_c
            a = x0 + dx * i_last - x_c
            sum_d = 0.5 * dx * n * n
            sum_x2 = n * a * a - a * dx * n * (n - 1) + dx * dx * (n - 1) * n * (2 * n - 1) / 6.0
            sum_s3 = 0.5 * (n * x_lead * x_lead - sum_x2)
        else:
            sum_d = 0.0
            sum_s3 = 0.0
            cd = 0.0
            cs = 0.0
            inside = False
            for i in range(i_last, i_first - 1, -1):
                if not p[j, i] > 0.0:
                    inside = False
                    continue
                s = dx if inside else half
                if not inside:
                    cd = 0.0
                    cs = 0.0
                inside = True
                cd += s
                cs += (x0 + dx * i - x_c + 0.5 * s) * s
                sum_d += cd
                sum_s3 += cs
        if j < f:
            d1_1 += sum_d
            d3_1 += sum_s3
            d4_1 += y_rel * sum_d
        else:
            d1_2 += sum_d
            d3_2 += sum_s3
            d4_2 += y_rel * sum_d
    da = dx * dy
    both = geo[G_ZONE1] > 0.0 and geo[G_ZONE2] > 0.0
    t1 = math.log(geo[G_ZONE1 + 3]) if geo[G_ZONE1] > 0.0 else 0.0
    t2 = math.log(geo[G_ZONE2 + 3]) if geo[G_ZONE2] > 0.0 else 0.0
    # the pair's coefficient shared in the lone halves' proportion (c13: each zone's own)
    s11 = s22 = s23 = 1.0
    k13_1 = k13_2 = 1.0
    if both:
        w1 = 2.0 * geo[G_ZONE1] / geo[G_AREA]
        w2 = 2.0 * geo[G_ZONE2] / geo[G_AREA]
        v1 = w1**1.5
        v2 = w2**1.5
        a11 = spline(knots, polys[I_H11], t1)
        b11 = spline(knots, polys[I_H11], t2)
        a22 = spline(knots, polys[I_H22], t1)
        b22 = spline(knots, polys[I_H22], t2)
        a23 = spline(knots, polys[I_H23], t1)
        b23 = spline(knots, polys[I_H23], t2)
        s11 = ((w1 * a11 * pair_factor(pair_knots, pair_values[0], t1, t2)
                + w2 * b11 * pair_factor(pair_knots, pair_values[0], t2, t1))
               / (w1 * a11 + w2 * b11))
        s22 = ((w1 * a22 * pair_factor(pair_knots, pair_values[1], t1, t2)
                + w2 * b22 * pair_factor(pair_knots, pair_values[1], t2, t1))
               / (w1 * a22 + w2 * b22))
        s23 = ((v1 * a23 * pair_factor(pair_knots, pair_values[2], t1, t2)
                + v2 * b23 * pair_factor(pair_knots, pair_values[2], t2, t1))
               / (v1 * a23 + v2 * b23))
        k13_1 = pair_factor(pair_knots, pair_values[3], t1, t2)
        k13_2 = pair_factor(pair_knots, pair_values[3], t2, t1)
    for z in range(2):
        zone = G_ZONE1 if z == 0 else G_ZONE2
        base = G_FLEX1 if z == 0 else G_FLEX2
        if geo[zone] <= 0.0:
            continue
        t = t1 if z == 0 else t2
        c11 = spline(knots, polys[I_H11], t) * s11
        c22 = spline(knots, polys[I_H22], t) * s22
        lone23 = spline(knots, polys[I_H23], t)
        c13 = spline(knots, polys[I_H13], t) * (k13_1 if z == 0 else k13_2)
        ab = 2.0 * geo[zone] / math.pi
        # rule 4 (the reference's offset_c23): the bend of the zone's strips
        c23 = lone23 * s23
        offset = (chord_bend_offset(strips[0], strips[1], strips[2], 0, f, dx) if z == 0
                  else chord_bend_offset(strips[0], strips[1], strips[2], f, ny, dx))
        # (a bend whose horns trail is left out: rule 4 only raises c23)
        c23 = c23 + c22 * max(offset, 0.0) / math.sqrt(ab)
        g = shear_modulus
        d1 = (d1_1 if z == 0 else d1_2) * da
        d3 = (d3_1 if z == 0 else d3_2) * da
        d4 = abs(d4_1 if z == 0 else d4_2) * da
        geo[base] = d1 / (g * ab * c11)
        geo[base + 1] = d1 / (g * ab * c22)
        if d3 > 0.0:
            geo[base + 2] = d3 / (g * ab**1.5 * c23)
        else:
            geo[base + 2] = geo[base + 2] * lone23 / c23
        geo[base + 3] = d4 / (g * ab**1.5 * c13) if c13 > 0.0 else math.inf


@njit(cache=True, error_model="numpy")
def mae_strip_flexibility(geo, flex):
    """Fill ``flex`` ``(4, ny)`` with each strip's zone ``L1, L2, L3, L4`` (m/Pa).

    Strips of an empty zone hold no cell in contact: infinite flexibility, as
    :func:`fastsim_ros.contact.mae.strip_flexibility` gives them.
    """
    f = int(geo[G_FACE])
    for j in range(flex.shape[1]):
        base = G_FLEX1 if j < f else G_FLEX2
        for k in range(4):
            v = geo[base + k]
            flex[k, j] = math.inf if math.isnan(v) else v


@njit(cache=True, error_model="numpy")
def mae_flexibility(p, x0, y0, dx, dy, rule, shear_modulus, knots, polys, geo, env, strips,
                    calibrated, pair_knots, pair_values, flex):
    """:func:`mae_prepare`, then each strip's ``L1 .. L4`` into ``flex``; return its status.

    Where the rule's split lies between two faces (:func:`split_blend`:
    ``t > 0``; a tie, the line through the middle of a strip, is ``t =
    1/2``) the two faces' strip stiffnesses ``1/L`` are weighted ``1 - t``
    and ``t`` and ``geo``'s sweep line ``y_s`` is their weighted mean
    (:func:`fastsim_ros.contact.mae.split_geometries`): the force then
    moves continuously with the split, and a patch symmetric in ``y`` has no
    yaw moment from nothing (either face alone gave an ellipse ``C~13`` of
    -0.03).
    """
    status = mae_scan(p, x0, y0, dx, dy, geo, env, strips)
    if status != OK:
        return status, 0.0
    f, t = split_blend(strips[0], rule)
    status, info = mae_zones(p, x0, y0, dx, dy, f, shear_modulus, knots, polys, geo, env,
                             strips, calibrated, pair_knots, pair_values)
    if status != OK:
        return status, info
    mae_strip_flexibility(geo, flex)
    if t == 0.0:
        return OK, 0.0
    # the other face: the same scan, its own zones
    other = geo.copy()
    status, info = mae_zones(p, x0, y0, dx, dy, f + 1, shear_modulus, knots, polys, other,
                             env, strips, calibrated, pair_knots, pair_values)
    if status != OK:
        return status, info
    upper = np.empty_like(flex)
    mae_strip_flexibility(other, upper)
    # the strips' stiffness 1/L weighted (mae.blended_flexibility): the full-adhesion
    # coefficients, linear in it, move linearly from one face's to the other's
    s = 1.0 - t
    for k in range(4):
        for j in range(flex.shape[1]):
            flex[k, j] = 1.0 / (s / flex[k, j] + t / upper[k, j])
    geo[G_YS] = s * geo[G_YS] + t * other[G_YS]
    return OK, 0.0


# ---------------------------------------------------------------- traction bounds


@njit(cache=True, error_model="numpy")
def parabolic_bound(p, dx, dy, mu, load, bound):
    """Fill ``bound`` with the parabolic ``g = mu N p^2 / sum(p^2 dA)`` (Pa) of load ``N``.

    As :func:`fastsim_ros.contact.fastsim.traction_bound` with
    ``bound="parabolic"`` (Kalker's parabolic bound on a Hertzian patch).
    """
    ny, nx = p.shape
    total = 0.0
    for j in range(ny):
        for i in range(nx):
            s = p[j, i] * p[j, i] if p[j, i] > 0.0 else 0.0
            bound[j, i] = s
            total += s
    k = mu * load / (total * dx * dy)
    for j in range(ny):
        for i in range(nx):
            bound[j, i] = k * bound[j, i]


@njit(cache=True, error_model="numpy")
def ellipse_shape(n, a, b, hertz, shape, env):
    """Fill ``shape`` ``(n, n)`` with an ellipse's pressure shape on its box; return its sum.

    The grid of :func:`fastsim_ros.contact.area.ellipse` (``n`` cells across
    ``[-a, a] x [-b, b]``, ``a``, ``b`` in m), Hertzian ``sqrt(1 - rho^2)``
    or parabolic ``1 - rho^2`` (zero outside), and its column envelopes
    ``env``.  Return ``(sum of shape, cells inside)``: the pressure of load
    ``N`` is ``shape * (N / (sum * dA))``, as ``ellipse(..., load=N)``.
    The shape is symmetric: it is computed on the quadrant nearest the grid
    origin, bit for bit as the reference, and mirrored (the reference's other
    quadrants differ by rounding; no cell comes near the edge ``rho = 1``, as
    ``(2i + 1 - n)^2 + (2j + 1 - n)^2 = n^2`` has no integer solution).
    """
    hx = (a - -a) / n
    hy = (b - -b) / n
    h = (n + 1) // 2
    u2 = np.empty(h)
    v2 = np.empty(h)
    for i in range(h):
        u2[i] = ((-a + hx * (i + 0.5)) / a) ** 2
    for j in range(h):
        v2[j] = ((-b + hy * (j + 0.5)) / b) ** 2
    total = 0.0
    inside = 0
    for j in range(h):
        jm = n - 1 - j
        wj = 1 if 2 * j + 1 == n else 2
        for i in range(h):
            r = 1.0 - (u2[i] + v2[j])
            if r > 0.0:
                s = math.sqrt(r) if hertz else r
            else:
                s = 0.0
            im = n - 1 - i
            shape[j, i] = s
            shape[j, im] = s
            shape[jm, i] = s
            shape[jm, im] = s
            # each quadrant cell stands for 4, 2 (centre line of an odd grid) or 1
            wgt = wj * (1 if 2 * i + 1 == n else 2)
            total += wgt * s
            inside += wgt if r > 0.0 else 0
    for i in range(h):
        j = 0
        while j < h and not 1.0 - (u2[i] + v2[j]) > 0.0:
            j += 1
        lo, hi = (n, 0) if j == h else (j, n - j)
        env[0, i] = lo
        env[1, i] = hi
        env[0, n - 1 - i] = lo
        env[1, n - 1 - i] = hi
    return total, inside


# ---------------------------------------------------------------- equivalent ellipse


@njit(cache=True, error_model="numpy")
def equivalent_prepare(p, x0, y0, dx, dy, shear_modulus, knots, polys, ell):
    """Validate the patch, find its equivalent ellipse and Kalker's ``L1 .. L3``.

    Writes ``ell`` (length :data:`ELL_SIZE`): ``x_c, y_c, a, b`` (m), the
    patch's load (N), ``L1, L2, L3`` (m/Pa).  Return ``(status, info)``,
    ``info`` the ellipse's ``a/b`` when outside the table (the ellipse is
    written then, the flexibilities are not).
    """
    status = check_grid(x0, y0, dx, dy)
    if status != OK:
        return status, 0.0
    count = np.empty(p.shape[0], dtype=np.int64)
    status, n, si, sj, sii, sjj, total = scan_moments(p, count)
    if status != OK:
        return status, 0.0
    x_c, y_c, a, b = ellipse_from_sums(n, si, sj, sii, sjj, x0, y0, dx, dy)
    ell[ELL_XC] = x_c
    ell[ELL_YC] = y_c
    ell[ELL_A] = a
    ell[ELL_B] = b
    ell[ELL_LOAD] = total * (dx * dy)
    ell[ELL_NCELLS] = n
    ratio = a / b
    if not in_table(knots, ratio):
        return E_TABLE_ELLIPSE, ratio
    t = math.log(ratio)
    l1, l2, l3 = kalker_flexibility(a, b, spline(knots, polys[I_C11], t),
                                    spline(knots, polys[I_C22], t),
                                    spline(knots, polys[I_C23], t), shear_modulus)
    ell[ELL_L1] = l1
    ell[ELL_L2] = l2
    ell[ELL_L3] = l3
    return OK, 0.0


#: :func:`fastsim_ros.contact.knee.linear_force` and :func:`~fastsim_ros.contact.knee.interpolate`,
#: compiled: the reference's formulas, no copies
knee_linear_force = njit(cache=True, error_model="numpy")(knee.linear_force)
knee_interpolate = njit(cache=True, error_model="numpy")(knee.interpolate)


@njit(cache=True, error_model="numpy")
def knee_factor(p, x0, y0, dx, dy, xi, eta, phi, mu, shear_modulus, knots, polys, ell,
                log_aspect, s_nodes, kappa):
    """Return ``(kappa, d kappa / d mu_s)``: the knee factor of a patch at ``mu_s = mu``.

    :meth:`fastsim_ros.estimation.model.CreepModel.knee_factor`, one call:
    the equivalent ellipse (:func:`equivalent_prepare`, into ``ell``),
    Kalker's linear force at the creepages moved to its centre (spin
    ``phi`` about the grid's origin), ``s = |F_lin| / (mu N)`` and the
    table's factor (:class:`fastsim_ros.contact.knee.KneeFactors`' arrays);
    ``(1, 0)`` where the ellipse is outside Kalker's tables or carries no
    load or force.
    """
    status, _ = equivalent_prepare(p, x0, y0, dx, dy, shear_modulus, knots, polys, ell)
    load = ell[ELL_LOAD]
    if status != OK or not load > 0.0:
        return 1.0, 0.0
    a = ell[ELL_A]
    b = ell[ELL_B]
    fx, fy = knee_linear_force(a, b, ell[ELL_L1], ell[ELL_L2], ell[ELL_L3],
                               xi - phi * ell[ELL_YC], eta + phi * ell[ELL_XC], phi)
    f2 = fx * fx + fy * fy
    if not f2 > 0.0:
        return 1.0, 0.0
    s = math.sqrt(f2) / (mu * load)
    k, dk = knee_interpolate(log_aspect, s_nodes, kappa, s, math.log(a / b), fx * fx / f2)
    return k, -dk * s / mu


@njit(cache=True, error_model="numpy")
def equivalent_sweep(ell, shape, scale, mu, env, xi, eta, phi, xp, yp, law, prm, speed,
                     out_x, out_y, slip, store):
    """Plain FastSim on the equivalent ellipse's ``n`` x ``n`` grid, bound ``mu shape scale``.

    The grid of ``ellipse(a, b, nx=n, ny=n).shifted(x_c, y_c)``; Kalker's
    flexibilities on every strip, spin flexibility ``L3``, sweep point the
    ellipse's centre.  Return as :func:`sweep`.
    """
    gx0, gy0, gdx, gdy, flex, xi_s, eta_s = ellipse_march(ell, shape.shape[0], xi, eta, phi,
                                                          xp, yp)
    return sweep(shape, mu, scale, env, gx0, gy0, gdx, gdy, xi_s, eta_s, phi, flex,
                 ell[ELL_XC], ell[ELL_YC], xp, yp, law, prm, speed, out_x, out_y, slip, store,
                 False)


@njit(cache=True, error_model="numpy")
def ellipse_bound(ell, n, parabolic):
    """Return ``(shape, env, scale)`` of the equivalent ellipse's ``n`` x ``n`` grid.

    ``shape``: Hertz's (or with ``parabolic`` Kalker's parabolic) pressure
    profile on the grid (:func:`ellipse_shape`), ``env`` its column
    envelopes, ``scale`` (Pa) the factor that makes ``shape`` the pressure
    of the ellipse's load.
    """
    shape = np.empty((n, n))
    env = np.empty((2, n), dtype=np.int64)
    a = ell[ELL_A]
    b = ell[ELL_B]
    total, _ = ellipse_shape(n, a, b, not parabolic, shape, env)
    return shape, env, ell[ELL_LOAD] / (total * ((2 * a / n) * (2 * b / n)))


@njit(cache=True, error_model="numpy")
def ellipse_march(ell, n, xi, eta, phi, xp, yp):
    """Return the equivalent ellipse's march: its grid, flexibilities, creepages at its centre.

    ``(x0, y0, dx, dy, flex, xi_s, eta_s)``: the grid of ``ellipse(a, b,
    nx=n, ny=n).shifted(x_c, y_c)`` (m), Kalker's flexibilities on every
    strip with spin flexibility ``L3`` (``(4, n)``, m/Pa), and the
    creepages about ``(xp, yp)`` (m) moved to the ellipse's centre.
    """
    x_c = ell[ELL_XC]
    y_c = ell[ELL_YC]
    gx0, gy0, gdx, gdy = ellipse_grid(ell[ELL_A], ell[ELL_B], n, x_c, y_c)
    flex = np.empty((4, n))
    for j in range(n):
        flex[0, j] = ell[ELL_L1]
        flex[1, j] = ell[ELL_L2]
        flex[2, j] = ell[ELL_L3]
        flex[3, j] = ell[ELL_L3]
    return gx0, gy0, gdx, gdy, flex, xi + phi * (yp - y_c), eta - phi * (xp - x_c)


# ---------------------------------------------------------------- whole solves


@njit(cache=True, error_model="numpy")
def creepages_at_s(geo, xi, eta, phi, xp, yp):
    """Return ``(xi_s, eta_s)``: the creepages about ``(xp, yp)`` moved to ``S = (x_c, y_s)``."""
    return xi + phi * (yp - geo[G_YS]), eta - phi * (xp - geo[G_XC])


@njit(cache=True, error_model="numpy")
def mae_sweep(p, mu, parabolic, bound, env, x0, y0, dx, dy, geo, flex, xi, eta, phi, xp, yp,
              law, prm, speed, out_x, out_y, slip, store, rigid, knee=NO_KNEE):
    """MAE step 7: FastSim with each zone's ``L``'s, creepages moved to ``S = (x_c, y_s)``.

    The bound is ``mu p``, or with ``parabolic`` the finished ``bound`` (Pa);
    ``rigid``: the calibrated method's rigid-slip return (:func:`sweep`);
    ``knee``: a packed knee table (:func:`knee_pack`) to correct FastSim's
    knee strip by strip (:func:`strip_knee`, at the patch's equivalent
    ellipse's ``a/b``; the given bound only), or :data:`NO_KNEE`.
    """
    x_c = geo[G_XC]
    y_s = geo[G_YS]
    xi_s, eta_s = creepages_at_s(geo, xi, eta, phi, xp, yp)
    if parabolic:
        return sweep(bound, 1.0, 1.0, env, x0, y0, dx, dy, xi_s, eta_s, phi, flex, x_c, y_s,
                     xp, yp, law, prm, speed, out_x, out_y, slip, store, rigid)
    if knee.shape[0] == 0:
        return sweep(p, mu, 1.0, env, x0, y0, dx, dy, xi_s, eta_s, phi, flex, x_c, y_s, xp, yp,
                     law, prm, speed, out_x, out_y, slip, store, rigid)
    sums = np.empty((STRIP_SUMS, p.shape[0]))
    _, _, _, nslip, ncontact = sweep(p, mu, 1.0, env, x0, y0, dx, dy, xi_s, eta_s, phi, flex,
                                     x_c, y_s, xp, yp, law, prm, speed, out_x, out_y, slip,
                                     store, rigid, sums)
    fx, fy, mz = strip_knee(sums, dx * dy, knee,
                            math.log(geo[G_ELLIPSE + 2] / geo[G_ELLIPSE + 3]), out_x, out_y,
                            store)
    return fx, fy, mz, nslip, ncontact


@njit(cache=True, error_model="numpy")
def mae_setup(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic, shear_modulus,
              knots, polys, calibrated, pair_knots, pair_values):
    """MAE steps 1-6 of one solve: the inputs checked, the zones, flexibilities and bound.

    Return ``(status, info, geo, env, flex, bound)``: :func:`mae_prepare`'s
    geometry and column envelopes, :func:`mae_strip_flexibility`'s strip
    flexibilities and, with ``parabolic``, the parabolic bound (Pa; else an
    empty array: the given bound ``mu p`` is applied in the sweep).  The
    arrays are only filled where ``status`` is ``OK``.
    """
    ny, nx = p.shape
    geo = np.empty(GEO_SIZE)
    env = np.empty((2, nx), dtype=np.int64)
    flex = np.empty((4, ny))
    bound = np.empty((ny, nx) if parabolic else (0, 0))
    status = check_solve_inputs(xi, eta, phi, mu, xp, yp)
    info = 0.0
    if status != OK:
        return status, info, geo, env, flex, bound
    strips = np.empty((3, ny), dtype=np.int64)
    status, info = mae_flexibility(p, x0, y0, dx, dy, rule, shear_modulus, knots, polys, geo,
                                   env, strips, calibrated, pair_knots, pair_values, flex)
    if status != OK:
        return status, info, geo, env, flex, bound
    if parabolic:
        parabolic_bound(p, dx, dy, mu, geo[G_LOAD], bound)
    return OK, 0.0, geo, env, flex, bound


strip_loads = njit(cache=True, error_model="numpy")(lobes.strip_loads)
gap_split = njit(cache=True, error_model="numpy")(lobes.gap_split)
has_inner_gap = njit(cache=True, error_model="numpy")(lobes.has_inner_gap)


@njit(cache=True, error_model="numpy")
def patch_gap(p, calibrated):
    """Return ``(m, w)`` of :func:`fastsim_ros.contact.lobes.gap_split` on ``p`` (calibrated).

    Every solve asks: a patch without a gap is answered ``(0, 1)`` before its
    strips' loads are summed.
    """
    if not calibrated or not has_inner_gap(p):
        return 0, 1.0
    q = np.empty(p.shape[0])
    strip_loads(p, q)
    return gap_split(q)


@njit(cache=True, error_model="numpy", inline="always")
def blended_forces(w, whole, fx, fy, mz):
    """Return ``(Fx, Fy, Mz)``: ``w`` of the whole patch's (``whole[2:5]``), ``1 - w`` of these."""
    return (w * whole[2] + (1.0 - w) * fx, w * whole[3] + (1.0 - w) * fy,
            w * whole[4] + (1.0 - w) * mz)


@njit(cache=True, error_model="numpy")
def blend_tractions(w, tx, ty, ts, out_x, out_y, slip):
    """Set the regions' tractions ``out_x``, ``out_y`` (Pa) to ``w`` of the whole's ``tx``, ``ty``.

    ``1 - w`` of their own; the slip flags ``slip`` are the whole's
    ``ts`` where ``w >= 1/2`` (:func:`mae_solve`).
    """
    for j in range(out_x.shape[0]):
        for i in range(out_x.shape[1]):
            out_x[j, i] = w * tx[j, i] + (1.0 - w) * out_x[j, i]
            out_y[j, i] = w * ty[j, i] + (1.0 - w) * out_y[j, i]
            if w >= 0.5:
                slip[j, i] = ts[j, i]


@njit(cache=True, error_model="numpy")
def mae_solve(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
              shear_modulus, knots, polys, law, prm, speed, out_x, out_y, slip, store,
              calibrated, pair_knots, pair_values, knee=NO_KNEE):
    """Solve MAE + FastSim on one patch: :func:`mae_solve_whole`, or its regions apart.

    The calibrated method splits a patch of separate contact regions across
    its widest gap of empty strips and blends the two parts' forces with the
    whole patch's (:mod:`fastsim_ros.contact.lobes`; the tractions alike); a
    patch without a gap, and the paper's MAE, are solved whole.  Where a
    part cannot be solved (a region outside the tables) the whole patch is.
    Arguments and return as :func:`mae_solve_whole`.
    """
    m, w = patch_gap(p, calibrated)
    if w < 1.0:
        ny, nx = p.shape
        keep = store and w > 0.0
        tx = np.empty((ny, nx) if keep else (0, 0))
        ty = np.empty((ny, nx) if keep else (0, 0))
        ts = np.empty((ny, nx) if keep else (0, 0), dtype=np.bool_)
        a = mae_solve_whole(p[:m], x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                            shear_modulus, knots, polys, law, prm, speed, out_x[:m], out_y[:m],
                            slip[:m], store, calibrated, pair_knots, pair_values, knee)
        b = mae_solve_whole(p[m:], x0, y0 + m * dy, dx, dy, xi, eta, phi, mu, xp, yp, rule,
                            parabolic, shear_modulus, knots, polys, law, prm, speed, out_x[m:],
                            out_y[m:], slip[m:], store, calibrated, pair_knots, pair_values,
                            knee)
        if a[0] == OK and b[0] == OK:
            fx, fy, mz = a[2] + b[2], a[3] + b[3], a[4] + b[4]
            n, nslip = a[5] + b[5], a[6] + b[6]
            if w > 0.0:
                c = mae_solve_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule,
                                    parabolic, shear_modulus, knots, polys, law, prm, speed,
                                    tx, ty, ts, keep, calibrated, pair_knots, pair_values,
                                    knee)
                if c[0] != OK:
                    return c
                fx, fy, mz = blended_forces(w, c, fx, fy, mz)
                n = c[5]
                if w >= 0.5:
                    nslip = c[6]
                if keep:
                    blend_tractions(w, tx, ty, ts, out_x, out_y, slip)
            return OK, 0.0, fx, fy, mz, n, nslip, a[7] + b[7]
    return mae_solve_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                           shear_modulus, knots, polys, law, prm, speed, out_x, out_y, slip,
                           store, calibrated, pair_knots, pair_values, knee)


@njit(cache=True, error_model="numpy")
def mae_solve_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                    shear_modulus, knots, polys, law, prm, speed, out_x, out_y, slip, store,
                    calibrated, pair_knots, pair_values, knee=NO_KNEE):
    """Solve MAE + FastSim on one patch, whole (:func:`fastsim_ros.contact.mae.mae_fastsim`).

    ``p`` (Pa) on the grid ``x0, y0, dx, dy`` (m); creepages ``xi``, ``eta``
    (1), ``phi`` (1/m) about ``(xp, yp)`` (m); ``parabolic``: the
    parabolic bound ``mu N p^2 / sum(p^2 dA)`` instead of ``mu p``.
    Return ``(status, info, Fx, Fy, Mz, N, slipping cells, cells in
    contact)`` (N, N, N m, N).  ``calibrated``: the calibrated MAE
    (:func:`fastsim_ros.contact.mae_calibrated.mae_calibrated_fastsim`) with
    the pair factors ``pair_values`` ``(4, n, n)`` on the nodes
    ``pair_knots`` (``log(a/b)``); else the paper's (those arrays unread).
    ``knee``: :func:`mae_sweep`'s.
    """
    status, info, geo, env, flex, bound = mae_setup(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp,
                                                    rule, parabolic, shear_modulus, knots,
                                                    polys, calibrated, pair_knots, pair_values)
    if status != OK:
        return status, info, 0.0, 0.0, 0.0, 0.0, 0, 0
    fx, fy, mz, nslip, _ = mae_sweep(p, mu, parabolic, bound, env, x0, y0, dx, dy, geo, flex,
                                     xi, eta, phi, xp, yp, law, prm, speed, out_x, out_y,
                                     slip, store, calibrated, knee)
    return OK, 0.0, fx, fy, mz, geo[G_LOAD], nslip, int(geo[G_NCONTACT])


@njit(cache=True, error_model="numpy")
def mae_solve_mu_slope(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                       shear_modulus, knots, polys, law, prm, speed, calibrated, pair_knots,
                       pair_values, knee=NO_KNEE):
    """:func:`mae_solve` (no tractions) and the forces' derivatives in ``mu_s``, one march.

    A patch of separate regions as :func:`mae_solve` splits it (the
    derivatives blended alike); else :func:`mae_solve_mu_slope_whole`.
    """
    m, w = patch_gap(p, calibrated)
    if w < 1.0:
        a = mae_solve_mu_slope_whole(p[:m], x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule,
                                     parabolic, shear_modulus, knots, polys, law, prm, speed,
                                     calibrated, pair_knots, pair_values, knee)
        b = mae_solve_mu_slope_whole(p[m:], x0, y0 + m * dy, dx, dy, xi, eta, phi, mu, xp, yp,
                                     rule, parabolic, shear_modulus, knots, polys, law, prm,
                                     speed, calibrated, pair_knots, pair_values, knee)
        if a[0] == OK and b[0] == OK:
            fx, fy, mz = a[2] + b[2], a[3] + b[3], a[4] + b[4]
            n, nslip = a[5] + b[5], a[6] + b[6]
            dfx, dfy = a[8] + b[8], a[9] + b[9]
            if w > 0.0:
                c = mae_solve_mu_slope_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule,
                                             parabolic, shear_modulus, knots, polys, law, prm,
                                             speed, calibrated, pair_knots, pair_values, knee)
                if c[0] != OK:
                    return c
                fx, fy, mz = blended_forces(w, c, fx, fy, mz)
                dfx = w * c[8] + (1.0 - w) * dfx
                dfy = w * c[9] + (1.0 - w) * dfy
                n = c[5]
                if w >= 0.5:
                    nslip = c[6]
            return OK, 0.0, fx, fy, mz, n, nslip, a[7] + b[7], dfx, dfy
    return mae_solve_mu_slope_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule,
                                    parabolic, shear_modulus, knots, polys, law, prm, speed,
                                    calibrated, pair_knots, pair_values, knee)


@njit(cache=True, error_model="numpy")
def mae_solve_mu_slope_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                             shear_modulus, knots, polys, law, prm, speed, calibrated,
                             pair_knots, pair_values, knee=NO_KNEE):
    """:func:`mae_solve_whole` (no tractions) and the forces' derivatives in ``mu_s``, one march.

    Return ``(status, info, Fx, Fy, Mz, N, slipping cells, cells in
    contact, dFx/dmu_s, dFy/dmu_s)``: the first eight :func:`mae_solve`'s
    to the bit, the derivatives (N) :func:`sweep_mu_slope`'s; the arguments
    as :func:`mae_solve`'s (``knee`` with the given bound only).  The
    zones, flexibilities and the point ``S`` do not depend on ``mu_s``.
    """
    status, info, geo, env, flex, bound = mae_setup(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp,
                                                    rule, parabolic, shear_modulus, knots,
                                                    polys, calibrated, pair_knots, pair_values)
    if status != OK:
        return status, info, 0.0, 0.0, 0.0, 0.0, 0, 0, 0.0, 0.0
    xi_s, eta_s = creepages_at_s(geo, xi, eta, phi, xp, yp)
    x_c = geo[G_XC]
    y_s = geo[G_YS]
    # as mae_sweep: the finished bound (outer = inner = 1), or mu p applied in the march
    if parabolic:
        fx, fy, mz, dfx, dfy, nslip, _ = sweep_mu_slope(
            bound, 1.0, 1.0, env, x0, y0, dx, dy, xi_s, eta_s, phi, flex, x_c, y_s, xp, yp,
            law, prm, speed, calibrated, mu)
    else:
        fx, fy, mz, dfx, dfy, nslip, _ = sweep_mu_slope(
            p, mu, 1.0, env, x0, y0, dx, dy, xi_s, eta_s, phi, flex, x_c, y_s, xp, yp, law,
            prm, speed, calibrated, mu, knee,
            math.log(geo[G_ELLIPSE + 2] / geo[G_ELLIPSE + 3]) if knee.shape[0] > 0 else 0.0)
    return OK, 0.0, fx, fy, mz, geo[G_LOAD], nslip, int(geo[G_NCONTACT]), dfx, dfy


#: :func:`fastsim_ros.contact.rules.ellipse_cells` and
#: :func:`~fastsim_ros.contact.rules.ellipse_grid`, compiled: the reference's formulas, no copies
ellipse_cells = njit(cache=True, error_model="numpy")(rules.ellipse_cells)
ellipse_grid = njit(cache=True, error_model="numpy")(rules.ellipse_grid)


@njit(cache=True, error_model="numpy")
def equivalent_solve(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, parabolic, n,
                     shear_modulus, knots, polys, law, prm, speed, out_x, out_y, slip, store):
    """Solve plain FastSim on the patch's equivalent ellipse (:func:`equivalent_fastsim`).

    ``n``: cells across the ellipse's box along each axis (``n >= 2``);
    ``parabolic``: Kalker's parabolic pressure on the ellipse, else
    Hertzian.  Return ``(status, info, Fx, Fy, Mz, N, slipping cells, cells
    in contact of the ellipse grid)``; the tractions, if stored, are on that
    grid.
    """
    status = check_solve_inputs(xi, eta, phi, mu, xp, yp)
    if status != OK:
        return status, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0
    ell = np.empty(ELL_SIZE)
    status, info = equivalent_prepare(p, x0, y0, dx, dy, shear_modulus, knots, polys, ell)
    if status != OK:
        return status, info, 0.0, 0.0, 0.0, 0.0, 0, 0
    if n <= 0:
        n = ellipse_cells(ell[ELL_NCELLS])
    if n < 2:
        return E_CELLS, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0
    shape, env, scale = ellipse_bound(ell, n, parabolic)
    fx, fy, mz, nslip, ncontact = equivalent_sweep(ell, shape, scale, mu, env, xi, eta, phi,
                                                   xp, yp, law, prm, speed, out_x, out_y,
                                                   slip, store)
    return OK, 0.0, fx, fy, mz, ell[ELL_LOAD], nslip, ncontact


# ---------------------------------------------------------------- batches


@njit(cache=True, error_model="numpy")
def _same_patch(b, pb, prev_pb, x0, y0, dx, dy):
    """Whether item ``b`` has the patch and grid of item ``b - 1`` (its setup can be reused)."""
    return (b > 0 and pb == prev_pb and x0[b] == x0[b - 1] and y0[b] == y0[b - 1]
            and dx[b] == dx[b - 1] and dy[b] == dy[b - 1])


@njit(cache=True, error_model="numpy")
def mae_batch(ps, x0, y0, dx, dy, creep, mu, xp, yp, rule, parabolic, shear_modulus,
              knots, polys, law, prm, speed, out, calibrated, pair_knots, pair_values,
              knee=NO_KNEE):
    """MAE + FastSim on a batch; write ``Fx, Fy, Mz`` (N, N, N m) of item ``b`` to ``out[b]``.

    ``ps`` ``(P, ny, nx)`` (Pa) with ``P`` = batch size, or ``P = 1`` for one
    patch under every creepage; ``x0 .. dy`` (m), ``mu``: ``(B,)``; ``creep``
    ``(B, 3)``: ``xi, eta, phi`` (1, 1, 1/m) about ``(xp, yp)`` (m); ``law``,
    ``prm``: one friction law, ``speed`` ``(B,)``: ``|V|`` (m/s).  The
    geometry, look-ups and bound are redone only when the patch (or, for the
    parabolic bound, ``mu``) changes from one item to the next.  Return
    ``(status, index of the failing item, info)``; stops at the first error.
    ``calibrated``, ``pair_knots``, ``pair_values``, ``knee``: as :func:`mae_solve`.
    """
    nb = creep.shape[0]
    ny, nx = ps.shape[1], ps.shape[2]
    geo = np.empty(GEO_SIZE)
    env = np.empty((2, nx), dtype=np.int64)
    strips = np.empty((3, ny), dtype=np.int64)
    bound = np.empty((ny, nx))
    flex = np.empty((4, ny))
    empty_f = np.empty((0, 0))
    empty_b = np.empty((0, 0), dtype=np.bool_)
    prev_pb = -1
    whole = 1.0
    for b in range(nb):
        pb = b if ps.shape[0] > 1 else 0
        xi, eta, phi = creep[b, 0], creep[b, 1], creep[b, 2]
        status = check_solve_inputs(xi, eta, phi, mu[b], xp, yp)
        if status != OK:
            return status, b, 0.0
        p = ps[pb]
        same = _same_patch(b, pb, prev_pb, x0, y0, dx, dy)
        if not same:
            _, whole = patch_gap(p, calibrated)
        if whole < 1.0:  # separate regions: mae_solve splits the patch (no setup to reuse)
            r = mae_solve(p, x0[b], y0[b], dx[b], dy[b], xi, eta, phi, mu[b], xp, yp, rule,
                          parabolic, shear_modulus, knots, polys, law, prm, speed[b], empty_f,
                          empty_f, empty_b, False, calibrated, pair_knots, pair_values, knee)
            if r[0] != OK:
                return r[0], b, r[1]
            out[b, 0] = r[2]
            out[b, 1] = r[3]
            out[b, 2] = r[4]
            prev_pb = -1  # the next item sets its patch up afresh
            continue
        if not same:
            status, info = mae_flexibility(p, x0[b], y0[b], dx[b], dy[b], rule, shear_modulus,
                                           knots, polys, geo, env, strips, calibrated,
                                           pair_knots, pair_values, flex)
            if status != OK:
                return status, b, info
        if parabolic and not (same and mu[b] == mu[b - 1]):
            parabolic_bound(p, dx[b], dy[b], mu[b], geo[G_LOAD], bound)
        prev_pb = pb
        fx, fy, mz, _, _ = mae_sweep(p, mu[b], parabolic, bound, env, x0[b], y0[b], dx[b],
                                     dy[b], geo, flex, xi, eta, phi, xp, yp, law, prm,
                                     speed[b], empty_f, empty_f, empty_b, False, calibrated,
                                     knee)
        out[b, 0] = fx
        out[b, 1] = fy
        out[b, 2] = mz
    return OK, -1, 0.0


@njit(cache=True, error_model="numpy")
def equivalent_batch(ps, x0, y0, dx, dy, creep, mu, xp, yp, parabolic, n, shear_modulus,
                     knots, polys, law, prm, speed, out):
    """Equivalent-ellipse FastSim on a batch; the layout and return of :func:`mae_batch`.

    ``n``: cells across each ellipse's box (``<= 0``: :func:`ellipse_cells` of
    each patch's cells in contact).
    """
    nb = creep.shape[0]
    ny, nx = ps.shape[1], ps.shape[2]
    if 0 < n < 2:
        return E_CELLS, 0, 0.0
    nmax = n if n > 0 else max(ellipse_cells(ny * nx), 2)
    ell = np.empty(ELL_SIZE)
    shape_all = np.empty((nmax, nmax))
    env_all = np.empty((2, nmax), dtype=np.int64)
    shape = shape_all
    env = env_all
    empty_f = np.empty((0, 0))
    empty_b = np.empty((0, 0), dtype=np.bool_)
    scale = 0.0
    prev_pb = -1
    for b in range(nb):
        pb = b if ps.shape[0] > 1 else 0
        xi, eta, phi = creep[b, 0], creep[b, 1], creep[b, 2]
        status = check_solve_inputs(xi, eta, phi, mu[b], xp, yp)
        if status != OK:
            return status, b, 0.0
        if not _same_patch(b, pb, prev_pb, x0, y0, dx, dy):
            status, info = equivalent_prepare(ps[pb], x0[b], y0[b], dx[b], dy[b],
                                              shear_modulus, knots, polys, ell)
            if status != OK:
                return status, b, info
            nb_cells = n if n > 0 else ellipse_cells(ell[ELL_NCELLS])
            shape = shape_all[:nb_cells, :nb_cells]
            env = env_all[:, :nb_cells]
            a = ell[ELL_A]
            bb = ell[ELL_B]
            total, _ = ellipse_shape(nb_cells, a, bb, not parabolic, shape, env)
            scale = ell[ELL_LOAD] / (total * ((2 * a / nb_cells) * (2 * bb / nb_cells)))
        prev_pb = pb
        fx, fy, mz, _, _ = equivalent_sweep(ell, shape, scale, mu[b], env, xi, eta, phi, xp,
                                            yp, law, prm, speed[b], empty_f, empty_f, empty_b,
                                            False)
        out[b, 0] = fx
        out[b, 1] = fy
        out[b, 2] = mz
    return OK, -1, 0.0
