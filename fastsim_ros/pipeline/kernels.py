"""The pipeline's compiled path of one patch: adapter, creepages, MAE solve, wheelset wrench.

:meth:`fastsim_ros.pipeline.Pipeline.on_patch` runs, for a patch that is
not rejected, the adapter's loop (:func:`msg_adapters.patch_kernels.adapt`),
a dozen Python checks and dataclasses, the creepages
(:func:`msg_adapters.kinematics.creepages`, plain floats) and the solver's
Python wrapper around :func:`fastsim_ros.contact.kernels.mae_solve`: about
15 us of interpreter per patch around ~14 us of compiled work, which a
loaded 2-core machine inflates about threefold (benchmarks/bench_node.py).
:func:`solve_cloud` does the same in one call, with the same operations in
the same order, so that every number is the Python path's to the bit
(test/test_pipeline_kernels.py).  It decides nothing that could reject a
patch: where the Python path would reject (or return no contact) it
returns :data:`DEFER`, and the pipeline runs that path, which then gives the
reason.  Python keeps the stamps, counts, frames and outputs.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fastsim_ros.contact import kernels as contact
from fastsim_ros.contact import transient
from msg_adapters import patch_kernels as adapter
from msg_adapters.patch import GRID_TOLERANCE, MIN_CELL_SIZE, MIN_CONTACT_CELLS

#: what :func:`solve_cloud` returns: solved, or the Python path must decide
SOLVED, DEFER = 0, 1
#: the indices of :func:`solve_cloud`'s ``result`` (the frame stays in the adapter's ``out``)
(X0, Y0, DX, DY, LOAD, CELLS, ROW_ORDER, COLUMN_ORDER, XI, ETA, PHI, SPEED, FX, FY, MZ, N,
 SLIP_FRACTION, FORCE_WS, TORQUE_WS, DFX_DMU, DFY_DMU, STATE_FX, STATE_FY) = (
    0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 20, 23, 24, 25, 26)
RESULT_SIZE = 27
#: the indices of :func:`solve_cloud`'s ``memory`` (transient rolling's carried state):
#: on (1) or steady (0), the state's grid (turned as the patch is when rolling towards -x),
#: the time since the last solved patch (ns), the last rolling direction (+-1), the last
#: force (N, turned), the far field on (1) or off (0), the Poisson ratio, the far field's
#: Jacobian (N/m, 2 x 2 by rows, in and out: the new state's, written back)
(MEM_ON, MEM_GRID, MEM_DT_NS, MEM_DIRECTION, MEM_FORCE, MEM_FAR_FIELD, MEM_NU,
 MEM_FAR_SLOPE) = (0, 1, 5, 6, 7, 9, 10, 11)
MEMORY_SIZE = 15


@njit(cache=True, inline="always")
def _grid_axis(first, step, worst, n, result, at):
    """:func:`msg_adapters.patch._grid_axis` without its rejections: False where it rejects."""
    if not abs(step) >= MIN_CELL_SIZE:
        return False
    if not worst <= GRID_TOLERANCE * abs(step):
        return False
    if step < 0.0:
        result[at] = first + step * (n - 1)
        result[at + 2] = -step
        return True
    result[at] = first
    result[at + 2] = step
    return True


@njit(cache=True)
def solve_cloud(words, ny, nx, row, step, cols, pressure, frame, wheel, rail, min_speed, rule,
                parabolic, shear_modulus, knots, polys, law, prm, mu, slip_dependent,
                calibrated, pair_knots, pair_values, slope, result, memory, prev_x, prev_y,
                out_x, out_y, slip, geo, knee=contact.NO_KNEE):
    """Convert one patch cloud, derive its creepages, solve it (MAE + FastSim); no tractions.

    ``words .. cols``: the cloud's points as :func:`msg_adapters.patch._words`
    gives them; ``pressure`` (``(ny, nx)``, float64) receives the patch's
    pressure (Pa) in the grid's order and ``frame`` (the adapter's ``out``)
    its contact frame; ``wheel``, ``rail``: the twists ``(v, w)`` (m/s,
    rad/s, 6 floats each); ``min_speed`` (m/s); the rest: the solver's
    arguments as :meth:`fastsim_ros.contact.compiled.MaeSolver.solve_arrays`
    passes them (``slip_dependent``: the law reads ``|V|``).  Returns
    :data:`SOLVED` with ``result`` filled (indices above: the grid, load,
    cells, row and column order, the creepages and rolling speed, the
    forces and slip fraction, and the wrench in the wheelset frame about
    its origin), or :data:`DEFER` where the Python path decides.  ``slope``:
    also ``dFx/dmu_s``, ``dFy/dmu_s`` (N, contact frame; friction
    estimation's slope) from the same march
    (:func:`fastsim_ros.contact.kernels.mae_solve_mu_slope`, the forces
    to the bit); else those slots are NaN.

    Transient rolling (``memory[MEM_ON]`` 1): the contact's state carried
    over, as :meth:`fastsim_ros.contact.transient.ContactMemory.solve` does
    when none of its reset rules applies: the tractions ``prev_x``,
    ``prev_y`` (Pa) on the grid ``memory[MEM_GRID:MEM_GRID + 4]``, rolled
    ``|V| dt`` (:func:`fastsim_ros.contact.transient.mae_rolling_solve`, the
    same arguments as :meth:`~fastsim_ros.contact.transient.TransientSolver.step`
    passes); the new state in ``out_x``, ``out_y``, ``slip``, the MAE
    geometry in ``geo``.  A reversal or another grid (a resample) is
    :data:`DEFER`: the Python path applies that rule.
    """
    adapter.adapt(words, ny, nx, row, step, cols, pressure, frame)
    cells = int(frame[adapter.CELLS])
    if frame[adapter.STATUS] != adapter.OK or cells < MIN_CONTACT_CELLS or ny < 2 or nx < 2:
        return DEFER
    if not _grid_axis(frame[adapter.X0], frame[adapter.DX], frame[adapter.WORST_X], nx,
                      result, X0):
        return DEFER
    if not _grid_axis(frame[adapter.Y0], frame[adapter.DY], frame[adapter.WORST_Y], ny,
                      result, Y0):
        return DEFER
    column_order = 1 if frame[adapter.DX] > 0.0 else -1
    row_order = 1 if frame[adapter.DY] > 0.0 else -1
    x0, y0, dx, dy = result[X0], result[Y0], result[DX], result[DY]
    cell_area = dx * dy
    load = frame[adapter.P_SUM] * cell_area
    if not (cell_area > 0.0 and math.isfinite(load) and load > 0.0):
        return DEFER
    if row_order < 0 or column_order < 0:  # as np.ascontiguousarray(p[::rows, ::columns])
        flipped = pressure.copy()
        for j in range(ny):
            jj = j if row_order > 0 else ny - 1 - j
            for i in range(nx):
                pressure[j, i] = flipped[jj, i if column_order > 0 else nx - 1 - i]
    # the creepages: msg_adapters.kinematics.creepages, the same operations in order
    p0, p1, p2 = frame[adapter.ORIGIN], frame[adapter.ORIGIN + 1], frame[adapter.ORIGIN + 2]
    ex0, ex1, ex2 = frame[adapter.E_X], frame[adapter.E_X + 1], frame[adapter.E_X + 2]
    ey0, ey1, ey2 = frame[adapter.E_Y], frame[adapter.E_Y + 1], frame[adapter.E_Y + 2]
    ez0, ez1, ez2 = frame[adapter.E_Z], frame[adapter.E_Z + 1], frame[adapter.E_Z + 2]
    v0, v1, v2, w0, w1, w2 = wheel[0], wheel[1], wheel[2], wheel[3], wheel[4], wheel[5]
    u_w0 = v0 + (w1 * p2 - w2 * p1)
    u_w1 = v1 + (w2 * p0 - w0 * p2)
    u_w2 = v2 + (w0 * p1 - w1 * p0)
    r0, r1, r2 = rail[3], rail[4], rail[5]
    u_r0 = rail[0] + (r1 * p2 - r2 * p1)
    u_r1 = rail[1] + (r2 * p0 - r0 * p2)
    u_r2 = rail[2] + (r0 * p1 - r1 * p0)
    c0 = v0 + (0.0 * p2 - w2 * p1)
    c1 = v1 + (w2 * p0 - w0 * p2)
    c2 = v2 + (w0 * p1 - 0.0 * p0)
    speed = (ex0 * (c0 - 0.5 * (u_w0 + u_r0)) + ex1 * (c1 - 0.5 * (u_w1 + u_r1))
             + ex2 * (c2 - 0.5 * (u_w2 + u_r2)))
    s0, s1, s2 = u_w0 - u_r0, u_w1 - u_r1, u_w2 - u_r2
    spin = ez0 * (w0 - r0) + ez1 * (w1 - r1) + ez2 * (w2 - r2)
    if speed == 0.0 or not abs(speed) >= min_speed:
        return DEFER
    xi = (ex0 * s0 + ex1 * s1 + ex2 * s2) / speed
    eta = (ey0 * s0 + ey1 * s1 + ey2 * s2) / speed
    phi = spin / speed
    # the solve: Pipeline._solve, a patch turned by 180 degrees when rolling towards -x
    p = pressure
    sx0, sy0, sphi = x0, y0, phi
    reverse = speed < 0.0
    if reverse:
        p = np.empty((ny, nx))
        for j in range(ny):
            for i in range(nx):
                p[j, i] = pressure[ny - 1 - j, nx - 1 - i]
        sx0 = -(x0 + (nx - 1) * dx)
        sy0 = -(y0 + (ny - 1) * dy)
        sphi = -phi
    no_float = np.empty((0, 0))
    no_bool = np.empty((0, 0), dtype=np.bool_)
    dfx = dfy = math.nan
    if memory[MEM_ON] != 0.0:
        if math.copysign(1.0, speed) != memory[MEM_DIRECTION]:
            return DEFER  # reversed: the steady state, the Python path's rule
        if prev_x.shape[0] != ny or prev_x.shape[1] != nx or memory[MEM_GRID] != sx0 or (
                memory[MEM_GRID + 1] != sy0 or memory[MEM_GRID + 2] != dx
                or memory[MEM_GRID + 3] != dy):
            return DEFER  # another grid: the state resampled, in Python
        rolled = abs(speed) * memory[MEM_DT_NS] * 1e-9
        v = abs(speed) if slip_dependent else 0.0
        far = memory[MEM_FAR_FIELD] != 0.0
        far_slope = memory[MEM_FAR_SLOPE:MEM_FAR_SLOPE + 4].copy()
        t = transient.mae_rolling_solve(
            p, sx0, sy0, dx, dy, xi, eta, sphi, mu, 0.0, 0.0, rule, parabolic, shear_modulus,
            knots, polys, law, prm, v, out_x, out_y, slip, calibrated, pair_knots, pair_values,
            prev_x, prev_y, rolled, geo, memory[MEM_NU], far, memory[MEM_FORCE],
            memory[MEM_FORCE + 1], far_slope, knee)
        memory[MEM_FAR_SLOPE:MEM_FAR_SLOPE + 4] = far_slope
        r = (t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7])
        own_x, own_y = t[8], t[9]
    elif slope:
        q = contact.mae_solve_mu_slope(p, sx0, sy0, dx, dy, xi, eta, sphi, mu, 0.0, 0.0, rule,
                                       parabolic, shear_modulus, knots, polys, law, prm,
                                       abs(speed) if slip_dependent else 0.0, calibrated,
                                       pair_knots, pair_values, knee)
        r = (q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7])
        dfx, dfy = q[8], q[9]
        own_x, own_y = q[2], q[3]
    else:
        r = contact.mae_solve(p, sx0, sy0, dx, dy, xi, eta, sphi, mu, 0.0, 0.0, rule, parabolic,
                              shear_modulus, knots, polys, law, prm,
                              abs(speed) if slip_dependent else 0.0, no_float, no_float,
                              no_bool, False, calibrated, pair_knots, pair_values, knee)
        own_x, own_y = r[2], r[3]
    if r[0] != contact.OK:
        return DEFER
    fx, fy, mz, n = r[2], r[3], r[4], r[5]
    if reverse:
        fx, fy = -fx, -fy
        dfx, dfy = -dfx, -dfy
        own_x, own_y = -own_x, -own_y
    # transient rolling's state keeps FastSim's own force (the far field's)
    result[STATE_FX], result[STATE_FY] = own_x, own_y
    result[DFX_DMU], result[DFY_DMU] = dfx, dfy
    if not (math.isfinite(fx) and math.isfinite(fy) and math.isfinite(mz)
            and math.isfinite(n)):
        return DEFER
    result[LOAD] = load
    result[CELLS] = cells
    result[ROW_ORDER] = row_order
    result[COLUMN_ORDER] = column_order
    result[XI], result[ETA], result[PHI], result[SPEED] = xi, eta, phi, speed
    result[FX], result[FY], result[MZ], result[N] = fx, fy, mz, n
    result[SLIP_FRACTION] = r[6] / r[7]
    # the wrench in the wheelset frame about its origin (ContactFrame.to_wheelset, in order)
    f0 = fx * ex0 + fy * ey0 + n * ez0
    f1 = fx * ex1 + fy * ey1 + n * ez1
    f2 = fx * ex2 + fy * ey2 + n * ez2
    m0 = 0.0 * ex0 + 0.0 * ey0 + mz * ez0
    m1 = 0.0 * ex1 + 0.0 * ey1 + mz * ez1
    m2 = 0.0 * ex2 + 0.0 * ey2 + mz * ez2
    result[FORCE_WS], result[FORCE_WS + 1], result[FORCE_WS + 2] = f0, f1, f2
    result[TORQUE_WS] = p1 * f2 - p2 * f1 + m0
    result[TORQUE_WS + 1] = p2 * f0 - p0 * f2 + m1
    result[TORQUE_WS + 2] = p0 * f1 - p1 * f0 + m2
    return SOLVED


#: ``prev_x .. geo`` of :func:`solve_cloud` in steady rolling (not read)
NO_STATE = (np.empty((0, 0)), np.empty((0, 0)), np.empty((0, 0)), np.empty((0, 0)),
            np.empty((0, 0), dtype=np.bool_), np.empty(contact.GEO_SIZE))


def warm_up() -> None:
    """Compile (or load from numba's disk cache) :func:`solve_cloud` for every words type.

    The patch's points as float32 or float64, read-only (a view of the
    message's buffer) or writeable (a copy): one specialisation each, as the
    adapter's :func:`msg_adapters.patch.warm_up`.  Also transient rolling's
    Python path (its resets), :func:`fastsim_ros.contact.transient.warm_up`.
    """
    transient.warm_up()
    from fastsim_ros.contact.compiled import CalibratedMaeSolver
    solver = CalibratedMaeSolver(0.28, 8e10)
    cols = np.arange(7, dtype=np.int64)
    for width in (np.float32, np.float64):
        for writeable in (False, True):
            words = np.zeros(4 * 7, dtype=width)
            words.setflags(write=writeable)
            solve_cloud(words, 2, 2, 14, 7, cols, np.empty((2, 2)),
                        np.empty(adapter.OUT_SIZE), np.zeros(6), np.zeros(6), 0.0,
                        solver._rule, False, solver.shear_modulus, solver._knots,
                        solver._polys, contact.LAW_CONSTANT, np.zeros(2), 0.3, False, True,
                        solver._pair_knots, solver._pair_values, writeable,
                        np.empty(RESULT_SIZE), np.zeros(MEMORY_SIZE), *NO_STATE, solver._knee)
