"""Transient rolling with the fast methods: Kalker's non-steady FASTSIM.

The steady methods answer each cycle as if the rolling had reached its
steady state.  After a step in creepage the traction needs about one contact
length of rolling to build up; at 1 kHz and 2 m/s a cycle rolls 2 mm of a
10-15 mm patch.  Here each contact keeps its surface traction on its cells
between cycles (Kalker 1990, "Three-dimensional elastic bodies in rolling
contact", section 5.4, non-steady FASTSIM; Alonso & Gimenez, Vehicle System
Dynamics 46, 2008, for the MAE patches):

- over a time step ``dt`` the material moves through the contact by the
  distance rolled ``h = |V| dt`` (m): the traction of the previous step is
  convected by ``h`` along each strip (semi-Lagrangian: interpolated at
  ``x + h``, new material entering at the leading edge with zero traction);
- the rigid slip over the step divided by the flexibility ``L`` (Kalker's
  ``L1 .. L3`` on the equivalent ellipse, MAE's per-strip ``L1 .. L4``, the
  calibrated MAE's) is added, and the sum is projected on the traction bound
  ``mu p`` (slip-dependent friction and the rigid-slip return as in the
  steady sweep): :func:`fastsim_ros.contact.kernels.rolling_sweep`.

Two additions to Kalker's local model, each for a failure measured against
the exact transient solver (``docs/validation_transient.md``):

- **the half-space's far field** (:func:`far_field`): FastSim's displacement
  is local, ``u = L tau``, so a rigid shift meets the stiffness ``sum dA /
  L``, about twice Mindlin's (:func:`mindlin_compliance`), and a creepage
  step built up twice as fast as the exact one.  With ``u = L tau + M F``
  (``F`` the patch's total force, ``M`` making a uniform shift Mindlin's) the
  patch shifts as its force changes; steady rolling does not see it (``F``
  constant).  The step's own ``F`` is a fixed point, solved by Broyden's
  secant method with its Jacobian carried from step to step in the state
  (:func:`elastic_sweep`; one sweep in the steady state).  Assumed: the far
  field is uniform over the patch (its first moment only: no torsion term),
  and the force changes over a step as a first-order lag of the relaxation
  length (for the material that entered during the step), and a long step
  whose force changes is taken as sub-steps (:func:`elastic_steps`);
- **paths marched**: a particle's way from ``x + h`` is marched cell by
  cell, each cell of it projected on the bound where the particle is with
  the steady march's projection (the slip's direction follows the local
  rigid slip, which spin turns along the path; one projection over a long
  step took the path's mean).  Every cell of the path is tested, with the
  calibrated MAE's rigid-slip return and the falling law's kinetic level,
  so that steps of whole cells keep the steady state as their fixed point
  exactly (a path marched only when its end slipped, with the radial
  return, had the calibrated MAE's fixed point under spin up to 4 points
  of mu N off its steady answer).

Material that entered during the step (within ``h`` of its segment's front
face) rolled under the present creepages only: it has the steady march's
traction.  So the steady FastSim is the limit ``h`` >= the patch length
(exactly), and with ``h`` a whole number of cells it is the exact fixed
point of repeated steps (the semi-Lagrangian shift is then a shift by whole
cells and the path's march is the steady march's); other ``h`` converge to
it within the interpolation's smoothing.

State rules (:class:`ContactMemory`, stated in :data:`RESET_REASONS`):

- ``start``: the first patch; the rig was rolling before the node listened:
  the steady state is the best estimate;
- ``stamp_gap``: more than ``max_gap`` (s) since the last solved patch, or
  since the last empty one (a dropped stream, a standstill): the history is
  unknown, steady state;
- ``lost_contact``: the previous patch was empty (a lifted wheel), at most
  ``max_gap`` before: the new contact starts from zero traction (its
  material has no history);
- ``patch_jump``: the load-bearing area changed by more than ``jump_tolerance``
  (relative) or its pressure centroid moved by more than ``jump_tolerance``
  times the patch's half length in one step, in the frame the patches' contact
  frames are given in (a new contact, e.g. a flange): zero traction;
- ``resampled`` (not a reset): another grid (cell size, origin, shape): the
  previous traction is interpolated bilinearly onto the new cell centres in
  the contact plane, zero outside the previous contact;
- ``reversed``: the rolling direction changed sign: steady state.

Units: SI (m, Pa, N, s; ``phi`` in 1/m).  No ROS, no SciPy.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from fastsim_ros.contact import kernels as k
from fastsim_ros.contact.area import regridded
from fastsim_ros.contact.checks import check_bound
from fastsim_ros.contact.compiled import (ContactForces, EquivalentEllipseSolver, MaeSolver,
                                          _law, _pressure, _raise, warm_up_case)
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.friction import FrictionLaw

FloatArray = NDArray[np.float64]
#: a contact frame: origin (m), unit vectors e_x, e_y, in a frame the patches share
Frame = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]

#: why a contact's state was reset (or resampled), the keys of the diagnostics' counts
RESET_REASONS = ("start", "stamp_gap", "lost_contact", "patch_jump", "resampled", "reversed")
#: resets after which the step is the steady state (history unknown, contact rolling)
STEADY_RESETS = ("start", "stamp_gap", "reversed")


@njit(cache=True, error_model="numpy")
def elliptic_ke(m):
    """Return the complete elliptic integrals ``K(m)``, ``E(m)`` of parameter ``m = e^2`` < 1.

    By the arithmetic-geometric mean (Abramowitz & Stegun 17.6): ``K = pi /
    (2 a_n)``, ``E = K (1 - sum_n 2^(n-1) c_n^2)``; quadratic convergence,
    a few iterations to machine precision.
    """
    a = 1.0
    b = math.sqrt(1.0 - m)
    total = 0.5 * m      # 2^-1 c_0^2, c_0^2 = m
    power = 0.5
    for _ in range(40):
        c = 0.5 * (a - b)
        a, b = 0.5 * (a + b), math.sqrt(a * b)
        power *= 2.0
        total += power * c * c
        if abs(c) <= 1e-16 * a:
            break
    k_m = math.pi / (2.0 * a)
    return k_m, k_m * (1.0 - total)


@njit(cache=True, error_model="numpy")
def mindlin_compliance(a, b, nu, shear_modulus):
    """Return the tangential compliances ``(c_x, c_y)`` (m/N) of an elliptical contact in stick.

    Mindlin (1949), Johnson "Contact Mechanics" (1985) section 7.2: a rigid
    shift ``delta`` of two elastically (quasi-)identical bodies in full
    adhesion on the ellipse of semi-axes ``a`` (along x) and ``b`` (m)
    takes the force ``delta / c``, with ``a1`` the major semi-axis and
    ``e^2 = 1 - (minor/major)^2``,

        c_major = (K(e) - nu B(e)) / (pi G a1),  c_minor = (K(e) - nu D(e)) / (pi G a1),

    ``D = (K - E)/e^2``, ``B = (E - (1 - e^2) K)/e^2`` (both ``pi/4`` on a
    circle: ``c = (2 - nu)/(4 G a)``).  Checked against the exact Cattaneo
    shift of :mod:`~fastsim_ros.contact.exact_transient` (``test_contact_transient``).
    """
    major = max(a, b)
    m = 1.0 - (min(a, b) / major) ** 2
    k_m, e_m = elliptic_ke(m)
    if m < 1e-8:
        big_d = 0.25 * math.pi
        big_b = 0.25 * math.pi
    else:
        big_d = (k_m - e_m) / m
        big_b = (e_m - (1.0 - m) * k_m) / m
    scale = 1.0 / (math.pi * shear_modulus * major)
    c_major = (k_m - nu * big_b) * scale
    c_minor = (k_m - nu * big_d) * scale
    if a >= b:
        return c_major, c_minor
    return c_minor, c_major


@njit(cache=True, error_model="numpy")
def far_field(shape, env, flex, dx, dy, a, b, nu, shear_modulus):
    """Return ``(M_x, M_y, K_x, K_y, l_x, l_y, length)``: the far field of a patch.

    The far field makes a uniform shift Mindlin's.

    FastSim's displacement is local, ``u = L tau``: a uniform shift
    ``delta`` of the patch in stick takes ``K_L delta``, ``K_L = sum dA / L``
    (N/m; about ``(3 pi / 8) C11 G a`` on a circle, twice Mindlin's ``4 G a
    / (2 - nu)``).  The half-space's displacement is not local: a traction
    field displaces the whole patch.  Its first moment is kept by ``u = L
    tau + M F`` (``F`` the patch's total force, ``M`` in m/N): a uniform
    shift then takes ``delta / (1/K_L + M)``, Mindlin's ``delta / c`` for
    ``M = c - 1/K_L`` (zero where the local model is already as compliant).
    Steady rolling does not see ``M`` (``F`` constant: no slip from it);
    transient rolling does (the shift of the patch as the force builds up).
    ``shape``: the bound's shape (positive in contact), ``a``, ``b`` (m):
    the ellipse Mindlin's compliance is taken on.  Also returns the
    relaxation lengths ``(l_x, l_y)`` (m): the linear steady force per unit
    creepage over the shift stiffness, ``c sum dA d / L`` (``d`` a cell's
    distance from its strip's front face), the distance a first-order lag
    with Mindlin's initial slope needs to reach the steady force (about
    ``1.8 a`` on a circle), and the patch's length along x (m), its
    longest strip segment.
    """
    ny, nx = shape.shape
    k_x = 0.0
    k_y = 0.0
    c11 = 0.0
    c22 = 0.0
    da = dx * dy
    length = 0.0
    front = np.zeros(ny)
    inside = np.zeros(ny, dtype=np.bool_)
    cells = np.zeros(ny)
    moment = np.zeros(ny)
    for i in range(nx - 1, -1, -1):
        for j in range(ny):
            if j < env[0, i] or j >= env[1, i] or not shape[j, i] > 0.0:
                inside[j] = False
                continue
            d = front[j] + dx if inside[j] else 0.5 * dx
            front[j] = d
            inside[j] = True
            length = max(length, d + 0.5 * dx)
            cells[j] += 1.0
            moment[j] += d
    # per strip: its cells in contact and their distances' sum (one division a strip)
    for j in range(ny):
        if cells[j] > 0.0:
            k_x += da * cells[j] / flex[0, j]
            k_y += da * cells[j] / flex[1, j]
            c11 += da * moment[j] / flex[0, j]
            c22 += da * moment[j] / flex[1, j]
    c_x, c_y = mindlin_compliance(a, b, nu, shear_modulus)
    if not k_x > 0.0 or not k_y > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0
    m_x = max(c_x - 1.0 / k_x, 0.0)
    m_y = max(c_y - 1.0 / k_y, 0.0)
    return m_x, m_y, k_x, k_y, c_x * c11, c_y * c22, length


#: the far field's fixed point is solved to this fraction of the step's change of force (1)
FAR_FIELD_TOLERANCE = 1e-3
#: ... or to this fraction of the traction bound's total, whichever is larger (1): the force's
#: error then stays below a millionth of mu N (a relative tolerance alone refined changes
#: of a millionth of mu N, the interpolation's drift of a step of 1.3 cells or creepage
#: noise, over five sweeps a step)
FAR_FIELD_FLOOR = 1e-6
#: a change of force below this fraction of the traction bound's total is none (1)
FAR_FIELD_STEADY = 1e-12
#: at most this many secant steps (each a sweep) for the far field's fixed point
FAR_FIELD_STEPS = 4


@njit(cache=True, error_model="numpy")
def elastic_sweep(shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp,
                  yp, law, prm, speed, out_x, out_y, slip, rigid, prev_x, prev_y, rolled,
                  m_x, m_y, k_x, k_y, l_x, l_y, length, f_old_x, f_old_y, bound_total,
                  slope, fade=1.0):
    """One time step with the far field: :func:`kernels.rolling_sweep` at its fixed point.

    The patch's shift over the step is ``s = M (F - F_old)`` (m per
    direction, :func:`far_field`), ``F`` the step's own force: ``g(s) = s -
    M (F(s) - F_old) = 0`` is solved by secant steps from ``s = 0`` (``F`` is
    monotone in ``s``: memory cells in stick lose ``s / L`` each, those in
    slip stay on the bound) by Broyden's method in ``(s_x, s_y)``: the
    second point the root of the plane ``F = F0 - J s``, ``J`` (N/m, 2 x
    2: ``dF_x/ds_x, dF_x/ds_y, dF_y/ds_x, dF_y/ds_y``, negated) in ``slope``
    (4 floats, in and out: the last Broyden estimate, carried from step to
    step with the contact's state; unknown (NaN) or out of range: ``K``,
    diagonal, as if every memory cell stuck).  Slipping cells turn with the
    shift too, and the directions couple: on the bench's patch (88% slip)
    ``J`` is a third of ``K`` with cross terms of 15%, so a first point
    from ``K`` was 0.6 of the root, per direction, a sweep or two more a
    step.  In the steady state ``F = F_old``: one sweep, ``s = 0``.  A
    cell that entered during the step saw the shift since it entered
    (:func:`kernels.rolling_sweep`): a lag of length ``l (1 - h /
    length)``, so that a step ``h`` of the patch's
    ``length`` or more is the steady state (no material saw the old force);
    ``fade`` (1) scales that lag further (:func:`elastic_steps`' sub-steps).
    Returns as :func:`kernels.rolling_sweep`; the last
    sweep's tractions stored.
    """
    fx, fy, mz, nslip, ncontact = k.rolling_sweep(
        shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp, yp, law,
        prm, speed, out_x, out_y, slip, True, rigid, prev_x, prev_y, rolled, 0.0, 0.0, 1.0, 1.0)
    return _settle(shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp,
                   yp, law, prm, speed, out_x, out_y, slip, rigid, prev_x, prev_y, rolled, m_x,
                   m_y, k_x, k_y, l_x, l_y, length, f_old_x, f_old_y, bound_total, slope, fade,
                   fx, fy, mz, nslip, ncontact)


@njit(cache=True, error_model="numpy")
def _settle(shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp, yp,
            law, prm, speed, out_x, out_y, slip, rigid, prev_x, prev_y, rolled, m_x, m_y, k_x,
            k_y, l_x, l_y, length, f_old_x, f_old_y, bound_total, slope, fade, fx, fy, mz,
            nslip, ncontact):
    """:func:`elastic_sweep` from its first sweep (no shift), whose answer is given.

    Arguments as :func:`elastic_sweep`'s, then that sweep's return.
    """
    if (m_x == 0.0 and m_y == 0.0) or not rolled < length:
        return fx, fy, mz, nslip, ncontact
    # the lag completes within the step as the step nears the patch's length: a step over
    # the whole patch leaves no material that saw the old force (the steady state, exactly)
    taper = (1.0 - rolled / length) * fade
    r_x = l_x * taper
    r_y = l_y * taper
    change = abs(fx - f_old_x) + abs(fy - f_old_y)
    if change <= FAR_FIELD_STEADY * bound_total:
        return fx, fy, mz, nslip, ncontact
    tol = max(FAR_FIELD_TOLERANCE * change, FAR_FIELD_FLOOR * bound_total)
    s0x = 0.0
    s0y = 0.0
    g0x = -m_x * (fx - f_old_x)
    g0y = -m_y * (fy - f_old_y)
    # g's Jacobian A = I + M J (F ~ F0 - J s): from the carried J, else every memory cell in
    # stick (J = K, diagonal); Broyden's updates from the points swept
    j_xx, j_xy, j_yx, j_yy = slope[0], slope[1], slope[2], slope[3]
    if not (j_xx >= 0.0 and j_xx <= k_x and j_yy >= 0.0 and j_yy <= k_y
            and abs(j_xy) <= k_x and abs(j_yx) <= k_y):
        j_xx, j_xy, j_yx, j_yy = k_x, 0.0, 0.0, k_y
    a11 = 1.0 + m_x * j_xx
    a12 = m_x * j_xy
    a21 = m_y * j_yx
    a22 = 1.0 + m_y * j_yy
    s1x, s1y = _newton(a11, a12, a21, a22, s0x, s0y, g0x, g0y)
    for _ in range(FAR_FIELD_STEPS):
        fx, fy, mz, nslip, ncontact = k.rolling_sweep(
            shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp, yp,
            law, prm, speed, out_x, out_y, slip, True, rigid, prev_x, prev_y, rolled, s1x,
            s1y, r_x, r_y)
        g1x = s1x - m_x * (fx - f_old_x)
        g1y = s1y - m_y * (fy - f_old_y)
        # Broyden: A += (dg - A ds) ds^T / |ds|^2
        d_x = s1x - s0x
        d_y = s1y - s0y
        nd = d_x * d_x + d_y * d_y
        if nd > 0.0:
            r_1 = (g1x - g0x) - (a11 * d_x + a12 * d_y)
            r_2 = (g1y - g0y) - (a21 * d_x + a22 * d_y)
            a11 += r_1 * d_x / nd
            a12 += r_1 * d_y / nd
            a21 += r_2 * d_x / nd
            a22 += r_2 * d_y / nd
            # the next step's first guess, J = M^-1 (A - I), where the far field acts (a
            # direction without it keeps K's row: a NaN there would void the whole guess)
            slope[0], slope[1] = ((a11 - 1.0) / m_x, a12 / m_x) if m_x > 0.0 else (k_x, 0.0)
            slope[2], slope[3] = (a21 / m_y, (a22 - 1.0) / m_y) if m_y > 0.0 else (0.0, k_y)
        if abs(g1x) * k_x <= tol and abs(g1y) * k_y <= tol:
            break
        s0x, s0y, g0x, g0y = s1x, s1y, g1x, g1y
        s1x, s1y = _newton(a11, a12, a21, a22, s1x, s1y, g1x, g1y)
    return fx, fy, mz, nslip, ncontact


@njit(cache=True, error_model="numpy", inline="always")
def _newton(a11, a12, a21, a22, s_x, s_y, g_x, g_y):
    """Return ``s - A^-1 g``: the root of the line through ``(s, g)`` with Jacobian ``A``.

    A singular ``A`` (a degenerate Broyden update) takes its diagonal alone.
    """
    det = a11 * a22 - a12 * a21
    if abs(det) > 1e-6 * abs(a11 * a22) and det != 0.0:
        return (s_x - (a22 * g_x - a12 * g_y) / det, s_y - (a11 * g_y - a21 * g_x) / det)
    return s_x - (g_x / a11 if a11 != 0.0 else 0.0), s_y - (g_y / a22 if a22 != 0.0 else 0.0)


#: with the far field, a step longer than this share of the patch's length is taken in equal
#: sub-steps no longer than it (1) where the force changes: the lag over one long step
#: overshot the same model's build-up in small steps
SUBSTEP = 0.125
#: ... where the force changes by more than this share of the bound's total over the whole
#: step taken at once (1): the lag's error was about 1.5 % of the change (a point of mu N
#: for a change of 66 points), so steadier steps are taken whole, at one sweep's cost
SUBSTEP_CHANGE = 0.02
#: the sub-steps' lag fades to none from this share of the patch's length to the whole (1)
FADE_START = 0.5


@njit(cache=True, error_model="numpy")
def elastic_steps(shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp,
                  yp, law, prm, speed, out_x, out_y, slip, rigid, prev_x, prev_y, rolled,
                  far_shape, a, b, nu, shear_modulus, with_far_field, f_old_x, f_old_y,
                  bound_total, slope):
    """Roll ``rolled`` (m) as :func:`elastic_sweep` does, in sub-steps where it is long.

    With ``with_far_field`` the far field is :func:`far_field`'s of
    ``far_shape`` (positive in contact) on the ellipse ``a``, ``b`` (m),
    Poisson ratio ``nu`` and ``shear_modulus`` (Pa), taken only when the
    first sweep's force differs from ``f_old`` (N): a step whose force does
    not change (the steady state) is that sweep alone, and the far field's
    scan of the patch (1.2 us of a 30 x 30 step) is not made.

    The far field's force is taken to change as a first-order lag within a
    step (:func:`elastic_sweep`); over a step of half the patch's length the
    build-up after a creepage step overshot the one of the same model in
    small steps by a point of mu N (``docs/validation_transient.md``), the
    model's own error in time.  So with the far field a step between
    :data:`SUBSTEP` times the patch's ``length`` and the whole length, whose
    force taken at once changes by more than :data:`SUBSTEP_CHANGE` of the
    bound's total ``bound_total`` (N), is taken again as equal sub-steps no
    longer than that, each from the last one's tractions and force (a step
    of the whole length or more is the steady state in one sweep; a steady
    step is one sweep whatever its length).  Two joins keep the answer
    continuous (a jump of 8% of mu N at ``h = length`` and a larger creepage
    step answered with a smaller force were measured without them):

    - in the step's length: the sub-steps' far field (its compliance ``M``
      and lag) fades linearly to none between :data:`FADE_START` times the
      patch's length and the whole length, where one step is the steady
      state (sub-steps of Kalker's local model over the whole length are
      that steady state too); shorter steps (the validated ones, ``V dt <=
      a`` on the circle) are as they were;
    - in the change of force: between one and two times
      :data:`SUBSTEP_CHANGE` the answer (forces and tractions) goes linearly
      from the whole step's to the sub-steps'.

    Other arguments and return as :func:`elastic_sweep`; the sub-steps start from
    the Jacobian ``slope`` came with (the whole step's sweeps are discarded
    with it), so that a step of ``h`` taken in full sub-steps is two of
    ``h/2`` so taken to the bit.
    """
    j_xx, j_xy, j_yx, j_yy = slope[0], slope[1], slope[2], slope[3]
    fx, fy, mz, nslip, ncontact = k.rolling_sweep(
        shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp, yp, law,
        prm, speed, out_x, out_y, slip, True, rigid, prev_x, prev_y, rolled, 0.0, 0.0, 1.0, 1.0)
    if (not with_far_field or not rolled < math.inf
            or abs(fx - f_old_x) + abs(fy - f_old_y) <= FAR_FIELD_STEADY * bound_total):
        # no far field, the steady state, or no change of force: no shift (elastic_sweep
        # alone, as its own tests hold it)
        return fx, fy, mz, nslip, ncontact
    m_x, m_y, k_x, k_y, l_x, l_y, length = far_field(far_shape, env, flex, dx, dy, a, b, nu,
                                                     shear_modulus)
    fx, fy, mz, nslip, ncontact = _settle(
        shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp, yp,
        law, prm, speed, out_x, out_y, slip, rigid, prev_x, prev_y, rolled, m_x, m_y, k_x,
        k_y, l_x, l_y, length, f_old_x, f_old_y, bound_total, slope, 1.0, fx, fy, mz, nslip,
        ncontact)
    if (m_x == 0.0 and m_y == 0.0) or not rolled < length:
        return fx, fy, mz, nslip, ncontact
    nsub = max(1, int(math.ceil(rolled / (SUBSTEP * length) - 1e-9)))
    limit = SUBSTEP_CHANGE * bound_total
    change = abs(fx - f_old_x) + abs(fy - f_old_y)
    if nsub == 1 or not change > limit:
        return fx, fy, mz, nslip, ncontact
    # the force changes over a long step: again from the start, in sub-steps
    slope[0], slope[1], slope[2], slope[3] = j_xx, j_xy, j_yx, j_yy
    weight = min(1.0, (change - limit) / limit)
    whole_x = out_x.copy()
    whole_y = out_y.copy()
    whole_slip = slip.copy()
    whole = (fx, fy, mz)
    whole_nslip = nslip
    fade = (length - rolled) / ((1.0 - FADE_START) * length)
    fade = 1.0 if fade > 1.0 - 1e-9 else fade   # up to FADE_START: 1, exactly
    h = rolled / nsub
    state_x = prev_x
    state_y = prev_y
    for n in range(nsub):
        if n > 0:
            state_x = out_x.copy()
            state_y = out_y.copy()
        fx, fy, mz, nslip, ncontact = elastic_sweep(
            shape, outer, inner, env, x0, y0, dx, dy, xi, eta, phi, flex, x_c, y_s, xp, yp,
            law, prm, speed, out_x, out_y, slip, rigid, state_x, state_y, h, m_x * fade,
            m_y * fade, k_x, k_y, l_x, l_y, length, f_old_x, f_old_y, bound_total, slope, fade)
        f_old_x = fx
        f_old_y = fy
    if weight < 1.0:
        # a convex combination of two admissible tractions is admissible (|tau| <= g)
        keep = 1.0 - weight
        ny, nx = out_x.shape
        for j in range(ny):
            for i in range(nx):
                out_x[j, i] = weight * out_x[j, i] + keep * whole_x[j, i]
                out_y[j, i] = weight * out_y[j, i] + keep * whole_y[j, i]
        if weight < 0.5:
            slip[:, :] = whole_slip
            nslip = whole_nslip
        fx = weight * fx + keep * whole[0]
        fy = weight * fy + keep * whole[1]
        mz = weight * mz + keep * whole[2]
    return fx, fy, mz, nslip, ncontact


@njit(cache=True, error_model="numpy")
def mae_rolling_solve(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                      shear_modulus, knots, polys, law, prm, speed, out_x, out_y, slip,
                      calibrated, pair_knots, pair_values, prev_x, prev_y, rolled, geo, nu,
                      with_far_field, f_old_x, f_old_y, slope, knee=k.NO_KNEE,
                      kappa_out=k.NO_KNEE):
    """One time step of MAE + FastSim: :func:`mae_rolling_solve_whole`, or its regions apart.

    A patch of separate contact regions is split as the steady solve splits
    it (:func:`fastsim_ros.contact.kernels.mae_solve`,
    :mod:`fastsim_ros.contact.lobes`), each region rolled from its own rows of
    the state, with its own far field from its own previous force (its rows
    of the state summed; the far field's Jacobian is guessed afresh, and
    ``slope`` is left NaN), and blended with the whole patch's step by the
    same weight: the forces, the new state and the strips' factors alike
    (in the blend the published tractions, the state times the factors, then
    sum to the forces to a few parts in 1e5).  So the steady state of a
    patch of separate regions is the steady solve's (in the blend, with the
    far field, within 0.2% of ``mu N``: the far field acts on the blended
    state, whose fixed point is not quite the blend of the two steady
    ones).  ``geo`` holds the whole patch's measures (area, centroid,
    equivalent ellipse) either way.  Where a region cannot be solved the
    whole patch is.  Arguments and return as :func:`mae_rolling_solve_whole`.
    """
    m, w = k.patch_gap(p, calibrated)
    if w < 1.0:
        ny, nx = p.shape
        da = dx * dy
        keep = w > 0.0
        tx = np.empty((ny, nx) if keep else (0, 0))
        ty = np.empty((ny, nx) if keep else (0, 0))
        ts = np.empty((ny, nx) if keep else (0, 0), dtype=np.bool_)
        tk = np.ones(kappa_out.shape[0] if keep else 0)
        parts = np.zeros((2, 8))
        status = k.OK
        for z in range(2):
            lo = 0 if z == 0 else m
            hi = m if z == 0 else ny
            fo_x = 0.0
            fo_y = 0.0
            for j in range(lo, hi):
                for i in range(nx):
                    fo_x += prev_x[j, i]
                    fo_y += prev_y[j, i]
            band_slope = np.full(4, math.nan)
            band_geo = np.empty(k.GEO_SIZE)
            r = mae_rolling_solve_whole(
                p[lo:hi], x0, y0 + lo * dy, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                shear_modulus, knots, polys, law, prm, speed, out_x[lo:hi], out_y[lo:hi],
                slip[lo:hi], calibrated, pair_knots, pair_values, prev_x[lo:hi], prev_y[lo:hi],
                rolled, band_geo, nu, with_far_field, fo_x * da, fo_y * da, band_slope, knee,
                kappa_out[lo:hi])
            if r[0] != k.OK:
                status = r[0]
                break
            parts[z, 0], parts[z, 1], parts[z, 2], parts[z, 3] = r[2], r[3], r[4], r[5]
            parts[z, 4], parts[z, 5], parts[z, 6], parts[z, 7] = r[6], r[7], r[8], r[9]
        if status == k.OK:
            fx, fy, mz = parts[0, 0] + parts[1, 0], parts[0, 1] + parts[1, 1], \
                parts[0, 2] + parts[1, 2]
            n = parts[0, 3] + parts[1, 3]
            nslip = int(parts[0, 4] + parts[1, 4])
            ncontact = int(parts[0, 5] + parts[1, 5])
            own_x, own_y = parts[0, 6] + parts[1, 6], parts[0, 7] + parts[1, 7]
            if keep:
                c = mae_rolling_solve_whole(
                    p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                    shear_modulus, knots, polys, law, prm, speed, tx, ty, ts, calibrated,
                    pair_knots, pair_values, prev_x, prev_y, rolled, geo, nu, with_far_field,
                    f_old_x, f_old_y, slope, knee, tk)
                if c[0] != k.OK:
                    return c
                fx, fy, mz = k.blended_forces(w, c, fx, fy, mz)
                n = c[5]
                own_x = w * c[8] + (1.0 - w) * own_x
                own_y = w * c[9] + (1.0 - w) * own_y
                if w >= 0.5:
                    nslip = c[6]
                k.blend_tractions(w, tx, ty, ts, out_x, out_y, slip)
                if kappa_out.shape[0] == ny:
                    for j in range(ny):
                        kappa_out[j] = w * tk[j] + (1.0 - w) * kappa_out[j]
            else:
                env = np.empty((2, nx), dtype=np.int64)
                strips = np.empty((3, ny), dtype=np.int64)
                k.mae_scan(p, x0, y0, dx, dy, geo, env, strips)
            slope[:] = math.nan
            return k.OK, 0.0, fx, fy, mz, n, nslip, ncontact, own_x, own_y
    return mae_rolling_solve_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule,
                                   parabolic, shear_modulus, knots, polys, law, prm, speed,
                                   out_x, out_y, slip, calibrated, pair_knots, pair_values,
                                   prev_x, prev_y, rolled, geo, nu, with_far_field, f_old_x,
                                   f_old_y, slope, knee, kappa_out)


@njit(cache=True, error_model="numpy")
def mae_rolling_solve_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                            shear_modulus, knots, polys, law, prm, speed, out_x, out_y, slip,
                            calibrated, pair_knots, pair_values, prev_x, prev_y, rolled, geo,
                            nu, with_far_field, f_old_x, f_old_y, slope, knee=k.NO_KNEE,
                            kappa_out=k.NO_KNEE):
    """One time step of MAE + FastSim on the patch whole, rolling ``rolled`` (m) from the state.

    As :func:`fastsim_ros.contact.kernels.mae_solve` (same arguments and
    return, then FastSim's own ``Fx``, ``Fy``: the state's force, which
    the far field compares with the next step's) with the previous
    tractions (Pa, the patch's grid) and the new
    ones written to ``out_x``, ``out_y`` (always stored: the next state);
    ``geo`` receives the MAE geometry (:data:`~kernels.GEO_SIZE`).  With
    ``with_far_field`` the patch's shift (:func:`far_field`, Mindlin's on the
    equivalent ellipse, Poisson ratio ``nu``) from the previous force
    ``f_old_x``, ``f_old_y`` (N); ``slope`` (4 floats, N/m, in and out): the
    far field's Jacobian carried with the state (:func:`elastic_sweep`).
    ``knee``: the returned forces carry each strip's knee factor in the
    share its force has built up towards its steady state
    (:func:`~fastsim_ros.contact.kernels.tractions_knee`, against one
    steady march at the step's creepages; the state, the far field's forces
    and ``out_x``, ``out_y`` stay FastSim's own), so that a steady state
    gives :func:`mae_solve`'s;
    ``kappa_out`` ``(ny,)``, if given, receives the strips' factors (1
    without ``knee``): the published tractions are ``out_x`` times them.
    """
    status = k.check_solve_inputs(xi, eta, phi, mu, xp, yp)
    if status != k.OK:
        return status, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0, 0.0, 0.0
    ny, nx = p.shape
    env = np.empty((2, nx), dtype=np.int64)
    strips = np.empty((3, ny), dtype=np.int64)
    flex = np.empty((4, ny))
    status, info = k.mae_flexibility(p, x0, y0, dx, dy, rule, shear_modulus, knots, polys,
                                     geo, env, strips, calibrated, pair_knots, pair_values,
                                     flex)
    if status != k.OK:
        return status, info, 0.0, 0.0, 0.0, 0.0, 0, 0, 0.0, 0.0
    # MAE step 7: creepages moved to S = (x_c, y_s) (kernels.mae_sweep)
    x_c = geo[k.G_XC]
    y_s = geo[k.G_YS]
    xi_s = xi + phi * (yp - y_s)
    eta_s = eta - phi * (xp - x_c)
    # the traction bound: mu p as given (shape p, outer mu), or the finished parabolic one
    shape, outer = p, mu
    if parabolic:
        shape = np.empty((ny, nx))
        k.parabolic_bound(p, dx, dy, mu, geo[k.G_LOAD], shape)
        outer = 1.0
    fx, fy, mz, nslip, _ = elastic_steps(
        shape, outer, 1.0, env, x0, y0, dx, dy, xi_s, eta_s, phi, flex, x_c, y_s, xp, yp,
        law, prm, speed, out_x, out_y, slip, calibrated, prev_x, prev_y, rolled, p,
        geo[k.G_ELLIPSE + 2], geo[k.G_ELLIPSE + 3], nu, shear_modulus, with_far_field, f_old_x,
        f_old_y, mu * geo[k.G_LOAD], slope)
    own_x, own_y = fx, fy
    if kappa_out.shape[0] == ny:
        kappa_out[:] = 1.0
    if knee.shape[0] > 0 and not parabolic:
        # the steady march at these creepages: each strip's knee factor and its steady force
        steady = np.empty((k.STRIP_SUMS, ny))
        empty = np.empty((0, 0))
        k.sweep(shape, outer, 1.0, env, x0, y0, dx, dy, xi_s, eta_s, phi, flex, x_c, y_s, xp,
                yp, law, prm, speed, empty, empty, np.empty((0, 0), dtype=np.bool_), False,
                calibrated, steady)
        yr = np.empty(ny)
        for j in range(ny):
            yr[j] = y0 + dy * j - yp
        fx, fy, mz = k.tractions_knee(out_x, out_y, shape, outer, 1.0, env, x0, y0, dx, dy,
                                      xp, yp, yr, steady, knee,
                                      math.log(geo[k.G_ELLIPSE + 2] / geo[k.G_ELLIPSE + 3]),
                                      kappa_out)
    return k.OK, 0.0, fx, fy, mz, geo[k.G_LOAD], nslip, int(geo[k.G_NCONTACT]), own_x, own_y


@njit(cache=True, error_model="numpy")
def longest_segment(p, dx):
    """Return the length (m) of the longest run of cells in contact along a strip of ``p``."""
    ny, nx = p.shape
    longest = 0
    for j in range(ny):
        run = 0
        for i in range(nx):
            run = run + 1 if p[j, i] > 0.0 else 0
            longest = max(longest, run)
    return longest * dx


@njit(cache=True, error_model="numpy")
def ellipse_rolling_solve(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, parabolic, n,
                          shear_modulus, knots, polys, law, prm, speed, out_x, out_y, slip,
                          prev_x, prev_y, rolled, ell, nu, with_far_field, f_old_x, f_old_y,
                          slope):
    """One time step of FastSim on the patch's equivalent ellipse (``n`` x ``n`` cells).

    As :func:`fastsim_ros.contact.kernels.equivalent_solve` with the state
    on the ellipse's grid (``prev_x``, ``prev_y`` in, ``out_x``, ``out_y``
    out, Pa); ``ell`` receives the ellipse (:data:`~kernels.ELL_SIZE`); the
    far field as :func:`mae_rolling_solve`, on the ellipse itself.
    """
    status = k.check_solve_inputs(xi, eta, phi, mu, xp, yp)
    if status != k.OK:
        return status, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0
    status, info = k.equivalent_prepare(p, x0, y0, dx, dy, shear_modulus, knots, polys, ell)
    if status != k.OK:
        return status, info, 0.0, 0.0, 0.0, 0.0, 0, 0
    shape, env, scale = k.ellipse_bound(ell, n, parabolic)
    a = ell[k.ELL_A]
    b = ell[k.ELL_B]
    x_c = ell[k.ELL_XC]
    y_c = ell[k.ELL_YC]
    gx0, gy0, gdx, gdy, flex, xi_s, eta_s = k.ellipse_march(ell, n, xi, eta, phi, xp, yp)
    if rolled >= longest_segment(p, dx):
        # a step over the whole patch is the steady state (the rule of every method): the
        # ellipse's own grid is longer than the patch (its area is the staircase's), and a
        # step between the two lengths would keep a memory the patch does not have
        rolled = math.inf
    fx, fy, mz, nslip, ncontact = elastic_steps(
        shape, mu, scale, env, gx0, gy0, gdx, gdy, xi_s, eta_s, phi, flex, x_c, y_c, xp, yp,
        law, prm, speed, out_x, out_y, slip, False, prev_x, prev_y, rolled, shape, a, b, nu,
        shear_modulus, with_far_field, f_old_x, f_old_y, mu * ell[k.ELL_LOAD], slope)
    return k.OK, 0.0, fx, fy, mz, ell[k.ELL_LOAD], nslip, ncontact


@dataclass(frozen=True, eq=False)
class TractionState:
    """A contact's surface traction (Pa) on its grid ``(x0, y0, dx, dy)`` (m), ``(ny, nx)``.

    ``area``: the patch's cells in contact
    times the cell area (m^2), ``centroid``: its pressure centroid (m) and
    ``half_length``: half its extent along ``x`` (m), for the jump rule;
    ``force``: its total ``(Fx, Fy)`` (N), the far field's previous force;
    ``far_slope``: the far field's Jacobian ``-dF/ds`` (N/m, 2 x 2 by rows,
    NaN: none yet), the next step's first guess (:func:`elastic_sweep`).
    """

    tau_x: FloatArray
    tau_y: FloatArray
    grid: tuple[float, float, float, float]
    area: float
    centroid: tuple[float, float]
    half_length: float
    force: tuple[float, float] = (0.0, 0.0)
    far_slope: tuple[float, float, float, float] = (math.nan,) * 4

    def resampled(self, grid: tuple[float, float, float, float],
                  shape: tuple[int, int]) -> tuple[FloatArray, FloatArray]:
        """Return the tractions interpolated bilinearly on another grid (zero outside this one)."""
        return (regridded(self.tau_x, self.grid, grid, shape),
                regridded(self.tau_y, self.grid, grid, shape))


_new_object = object.__new__


def _made(tau_x: FloatArray, tau_y: FloatArray, grid: tuple[float, float, float, float],
          area: float, centroid: tuple[float, float], half_length: float,
          force: tuple[float, float],
          far_slope: tuple[float, float, float, float]) -> TractionState:
    """Return ``TractionState(...)`` of these fields, made as :meth:`TransientSolver.step` needs.

    A frozen dataclass's ``__init__`` sets each field through
    ``object.__setattr__``: 1.1 us for these eight, a twentieth of a 30 x
    30 step; filling the instance's ``__dict__`` costs 0.35 us and leaves it
    as frozen (``test_contact_transient`` holds the two alike, field by field).
    """
    state: TractionState = _new_object(TractionState)
    fields = state.__dict__
    fields["tau_x"] = tau_x
    fields["tau_y"] = tau_y
    fields["grid"] = grid
    fields["area"] = area
    fields["centroid"] = centroid
    fields["half_length"] = half_length
    fields["force"] = force
    fields["far_slope"] = far_slope
    return state


def mae_state(tau_x: FloatArray, tau_y: FloatArray, grid: tuple[float, float, float, float],
              geo: FloatArray, force: tuple[float, float],
              far_slope: tuple[float, float, float, float]) -> TractionState:
    """Return the state a MAE step leaves: its tractions, with the measures of the jump rule.

    ``geo``: the step's MAE geometry (:data:`~kernels.GEO_SIZE`): the
    patch's area, centroid and half length (its equivalent ellipse's ``a``)
    for :class:`ContactMemory`; ``force`` (N) and ``far_slope`` as
    :class:`TractionState`'s: the pipeline's compiled path
    (``pipeline.Pipeline``) builds its state here, as
    :meth:`TransientSolver.step` does from :func:`_mae_measures`.
    """
    return _made(tau_x, tau_y, grid, *_mae_measures(geo), force, far_slope)


def _mae_measures(geo: FloatArray) -> tuple[float, tuple[float, float], float]:
    """Return the patch's area, centroid and half length (m^2, m, m) from a MAE geometry."""
    g = geo.tolist()
    return g[k.G_AREA], (g[k.G_XC], g[k.G_YC]), g[k.G_ELLIPSE + 2]


class TransientSolver:
    """Non-steady FastSim on a compiled solver's patches (MAE, calibrated MAE, ellipse).

    ``solver``: a :class:`~fastsim_ros.contact.compiled.MaeSolver` (or
    :class:`~fastsim_ros.contact.compiled.CalibratedMaeSolver`) or an
    :class:`~fastsim_ros.contact.compiled.EquivalentEllipseSolver`; its
    material, tables and options are used.  ``far_field``: the patch's
    elastic shift (:func:`far_field`: after a creepage step the force builds
    up at the half-space's shift stiffness, not FastSim's, twice as stiff);
    ``False``: Kalker's local non-steady FASTSIM.
    """

    def __init__(self, solver: MaeSolver | EquivalentEllipseSolver, *,
                 far_field: bool = True) -> None:
        self.solver = solver
        self.far_field = bool(far_field)
        #: whether the last step interpolated its state onto another grid
        self.resampled = False

    def step(self, state: TractionState | None, pressure: ArrayLike, x0: float, y0: float,
             dx: float, dy: float, xi: float, eta: float, phi: float, rolled: float,
             mu: float | None = None, *, reference: tuple[float, float] = (0.0, 0.0),
             bound: str = "given", friction: FrictionLaw | None = None,
             speed: float | None = None) -> tuple[ContactForces, TractionState]:
        """Roll ``rolled`` (m, ``inf``: the steady state) from ``state`` (``None``: zero traction).

        The patch, creepages (1, 1, 1/m about ``reference``, m), ``mu``,
        ``bound``, ``friction`` and ``speed`` (m/s) as the solver's
        ``solve_arrays``; the state is resampled when the grid differs.
        Return the forces (with the tractions) and the new state.
        """
        if not rolled >= 0.0:
            raise InvalidInputError(f"the distance rolled must be >= 0, got {rolled}")
        p = _pressure(pressure, 2)
        code, prm, mu_s, v = _law(mu, friction, speed)
        s = self.solver
        parabolic = check_bound(bound)
        xp, yp = float(reference[0]), float(reference[1])
        f_old = state.force if state is not None else (0.0, 0.0)
        slope = np.array(state.far_slope if state is not None else (math.nan,) * 4)
        kappa: FloatArray | None = None
        if isinstance(s, MaeSolver):
            grid = (float(x0), float(y0), float(dx), float(dy))
            shape = p.shape
            prev = self._previous(state, grid, shape)
            out = (np.empty(shape), np.empty(shape), np.empty(shape, dtype=np.bool_))
            geo = np.empty(k.GEO_SIZE)
            kappa = np.ones(shape[0])
            result = mae_rolling_solve(
                p, grid[0], grid[1], grid[2], grid[3], float(xi), float(eta), float(phi),
                float(mu_s), xp, yp, s._rule, parabolic, s.shear_modulus, s._knots, s._polys,
                code, prm, v, out[0], out[1], out[2], s._calibrated, s._pair_knots,
                s._pair_values, prev[0], prev[1], float(rolled), geo, s.nu, self.far_field,
                f_old[0], f_old[1], slope, s._knee_for("parabolic" if parabolic else "given"),
                kappa)
            measures = _mae_measures(geo)
        else:
            n = s.cells or k.ellipse_cells(int(np.count_nonzero(p > 0.0)))
            ell = np.empty(k.ELL_SIZE)
            status, info = k.equivalent_prepare(p, float(x0), float(y0), float(dx), float(dy),
                                                s.shear_modulus, s._knots, s._polys, ell)
            if status:
                _raise(status, info, s._knots)
            grid = k.ellipse_grid(ell[k.ELL_A], ell[k.ELL_B], n, ell[k.ELL_XC], ell[k.ELL_YC])
            shape = (n, n)
            prev = self._previous(state, grid, shape)
            out = (np.empty(shape), np.empty(shape), np.empty(shape, dtype=np.bool_))
            result = ellipse_rolling_solve(
                p, float(x0), float(y0), float(dx), float(dy), float(xi), float(eta),
                float(phi), float(mu_s), xp, yp, parabolic, n, s.shear_modulus, s._knots,
                s._polys, code, prm, v, out[0], out[1], out[2], prev[0], prev[1],
                float(rolled), ell, s.nu, self.far_field, f_old[0], f_old[1], slope)
            # the equivalent ellipse has the patch's area and centroid
            measures = (math.pi * float(ell[k.ELL_A] * ell[k.ELL_B]),
                        (float(ell[k.ELL_XC]), float(ell[k.ELL_YC])), float(ell[k.ELL_A]))
        # the published tractions carry the strips' knee factors, the state FastSim's own
        published = out if kappa is None else (out[0] * kappa[:, None],
                                               out[1] * kappa[:, None], out[2])
        forces = s._forces(result[:8], grid, published, True)
        j = slope.tolist()
        # the state keeps FastSim's own force (the far field's; MAE's knee factors are the
        # published forces' only)
        own = (result[8], result[9]) if len(result) > 8 else (result[2], result[3])
        return forces, _made(out[0], out[1], grid, *measures,
                             (float(own[0]), float(own[1])), (j[0], j[1], j[2], j[3]))

    def _previous(self, state: TractionState | None, grid: tuple[float, float, float, float],
                  shape: tuple[int, ...]) -> tuple[FloatArray, FloatArray]:
        self.resampled = False
        if state is None:
            return np.zeros(shape), np.zeros(shape)
        if state.grid == grid and state.tau_x.shape == shape:
            return state.tau_x, state.tau_y
        self.resampled = True
        return state.resampled(grid, (shape[0], shape[1]))


class ContactMemory:
    """One contact's state between cycles and the rules that reset it (module docstring).

    ``max_gap`` (s): a longer time between solved patches resets to the
    steady state; ``jump_tolerance`` (1): the relative change of area, or
    the centroid's move in half lengths, beyond which the patch is a new
    contact.  ``counts``: how often each of :data:`RESET_REASONS` applied.
    """

    def __init__(self, solver: TransientSolver, *, max_gap: float = 0.05,
                 jump_tolerance: float = 0.3) -> None:
        if not max_gap > 0.0 or not jump_tolerance > 0.0:
            raise InvalidInputError("max_gap and jump_tolerance must be positive")
        self.solver = solver
        self.max_gap = float(max_gap)
        self.jump_tolerance = float(jump_tolerance)
        self.state: TractionState | None = None
        # the state's pressure centroid in the frame the patches' frames are given in (m)
        self.position: tuple[float, float, float] | None = None
        self.stamp_ns: int | None = None
        self.direction = 0.0
        self.lost = False
        self.lost_ns: int | None = None
        self.counts = dict.fromkeys(RESET_REASONS, 0)

    def lose_contact(self, stamp_ns: int) -> None:
        """Record an empty patch stamped ``stamp_ns``: the next contact starts from zero."""
        self.state = None
        self.lost = True
        self.lost_ns = int(stamp_ns)

    def _rule(self, stamp_ns: int, speed: float) -> str | None:
        """Return the reset that applies before the solve (the jump is found after it)."""
        if self.lost and self.lost_ns is not None:
            if stamp_ns >= self.lost_ns and (stamp_ns - self.lost_ns) * 1e-9 <= self.max_gap:
                return "lost_contact"
            return "stamp_gap"  # an empty patch, then nothing for longer than the gap
        if self.stamp_ns is None or self.state is None:
            return "start"
        if (stamp_ns - self.stamp_ns) * 1e-9 > self.max_gap or stamp_ns < self.stamp_ns:
            return "stamp_gap"
        if math.copysign(1.0, speed) != self.direction:
            return "reversed"
        return None

    def carried(self, stamp_ns: int) -> tuple[TractionState, int] | None:
        """Return the state and the time since it (ns) if a patch stamped ``stamp_ns`` carries it.

        What :meth:`solve` does when no reset applies; ``None`` where a rule
        other than a reversal (which needs the patch's speed) applies.  A
        compiled caller solves from it (``|V| dt`` rolled) and hands the new
        state to :meth:`take`.
        """
        state, last = self.state, self.stamp_ns
        if self.lost or state is None or last is None or stamp_ns < last or (
                stamp_ns - last) * 1e-9 > self.max_gap:
            return None
        return state, stamp_ns - last

    def take(self, stamp_ns: int, speed: float, new: TractionState,
             frame: Frame | None = None) -> bool:
        """Keep ``new``, solved from :meth:`carried`'s state; False (nothing kept) if it jumped.

        A jump (another contact than the last) restarts from zero traction:
        the caller then solves with :meth:`solve`, which finds the jump itself.
        ``frame``: the patch's contact frame, as :meth:`solve` takes it.
        """
        assert self.state is not None
        position = self._position(new, speed, frame)
        if self._jumped(self.state, new, position):
            return False
        self._commit(stamp_ns, speed, new, None, position)
        return True

    def _commit(self, stamp_ns: int, speed: float, new: TractionState,
                reason: str | None, position: tuple[float, float, float] | None) -> None:
        self.state = new
        self.position = position
        if reason is not None:
            self.counts[reason] += 1
        self.stamp_ns = int(stamp_ns)
        self.direction = math.copysign(1.0, speed)
        self.lost = False

    @staticmethod
    def _position(state: TractionState, speed: float,
                  frame: Frame | None) -> tuple[float, float, float] | None:
        """Return the state's pressure centroid in the frame ``frame`` is given in (m).

        The solver's grid is the contact frame's, turned by 180 degrees about
        ``z`` in reverse running (``speed`` < 0): ``(x, y) -> (-x, -y)``.
        """
        if frame is None:
            return None
        origin, e_x, e_y = frame
        turn = -1.0 if speed < 0.0 else 1.0
        c_x, c_y = turn * state.centroid[0], turn * state.centroid[1]
        return (origin[0] + c_x * e_x[0] + c_y * e_y[0], origin[1] + c_x * e_x[1] + c_y * e_y[1],
                origin[2] + c_x * e_x[2] + c_y * e_y[2])

    def _jumped(self, old: TractionState, new: TractionState,
                position: tuple[float, float, float] | None = None) -> bool:
        """Whether the patch's area or centroid moved beyond the tolerance in one step.

        The centroid's move is measured where the patches' frames are given
        (the wheelset frame: a contact frame's origin moves with its patch,
        so in it a patch that moved keeps its centroid), else in the grid.
        """
        tol = self.jump_tolerance
        if position is not None and self.position is not None:
            moved = math.dist(position, self.position)
        else:
            moved = math.hypot(new.centroid[0] - old.centroid[0],
                               new.centroid[1] - old.centroid[1])
        return abs(new.area - old.area) > tol * old.area or moved > tol * old.half_length

    def solve(self, stamp_ns: int, speed: float, pressure: ArrayLike, x0: float, y0: float,
              dx: float, dy: float, xi: float, eta: float, phi: float, mu: float | None = None,
              *, reference: tuple[float, float] = (0.0, 0.0), bound: str = "given",
              friction: FrictionLaw | None = None,
              frame: Frame | None = None) -> tuple[ContactForces, str | None]:
        """Solve the patch stamped ``stamp_ns`` (ns) at rolling speed ``speed`` (m/s, signed).

        The distance rolled since the last solved patch is ``|V| dt``
        (``dt`` from the stamps: the state's rules depend on the messages
        only, so a replay gives the node's answers).  Return the forces and
        the reset reason that applied (``None``: the state carried over).
        ``frame``: the patch's contact frame ``(origin, e_x, e_y)`` in a frame
        the patches share (the wheelset's; m, unit vectors), for the jump
        rule; ``None``: the grids share one frame.
        """
        p = _pressure(pressure, 2)
        reason = self._rule(stamp_ns, speed)
        state = self.state
        if reason in STEADY_RESETS:
            rolled, state = math.inf, None
        else:
            # a new contact appeared at the last empty patch (zero traction then), a jumped
            # one at the last solve: it has rolled since with the present creepages
            since = self.lost_ns if reason == "lost_contact" else self.stamp_ns
            assert since is not None
            rolled = abs(speed) * max(stamp_ns - since, 0) * 1e-9
            if reason is not None:
                state = None
        args = (p, x0, y0, dx, dy, xi, eta, phi, rolled, mu)
        kw = {"reference": reference, "bound": bound, "friction": friction, "speed": abs(speed)}
        forces, new = self.solver.step(state, *args, **kw)  # type: ignore[arg-type]
        position = self._position(new, speed, frame)
        if reason is None and state is not None and self._jumped(state, new, position):
            # another contact than the last one: its material has no history
            reason = "patch_jump"
            forces, new = self.solver.step(None, *args, **kw)  # type: ignore[arg-type]
            position = self._position(new, speed, frame)
        elif reason is None and self.solver.resampled:
            reason = "resampled"
        self._commit(stamp_ns, speed, new, reason, position)
        return forces, reason


def warm_up() -> float:
    """Compile (or load from the disk cache) the transient kernels on a tiny patch; return s.

    :func:`fastsim_ros.contact.compiled.warm_up` for transient rolling: the
    steady start and a carried step of each solver, constant and falling
    friction, so that a node's first transient patch does not pay for the
    compilation (seconds, cold).
    """
    start = time.perf_counter()
    area, falling, solvers = warm_up_case()
    p, grid = area.pressure, (area.x0, area.y0, area.dx, area.dy)
    for solver in solvers:
        stepper = TransientSolver(solver)
        _, state = stepper.step(None, p, *grid, 1e-3, 0.0, 0.1, math.inf, 0.3)
        stepper.step(state, p, *grid, 2e-3, 0.0, 0.1, 0.4, 0.3)
        stepper.step(state, p, *grid, 2e-3, 0.0, 0.1, 0.4, friction=falling, speed=10.0)
    return time.perf_counter() - start
