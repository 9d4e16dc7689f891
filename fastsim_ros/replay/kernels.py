"""Compiled loops of the batched replay (numba): passes over chunks and patches.

The decisions stay in Python (:mod:`~fastsim_ros.replay.batch`); these
loops only walk bytes and sum.  The patch scan runs the node's adapter
loop (:func:`msg_adapters.patch_kernels.adapt`) on each patch of a chunk,
without its per-point finiteness test where every word of the patch is
finite (:func:`all_finite`), so a patch gives the same numbers here as in
the node.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fastsim_ros.contact import kernels as contact
from msg_adapters import patch_kernels

_OP_MESSAGE = 0x05


@njit(cache=True)
def _u64(buf, pos):
    v = np.uint64(0)
    for k in range(8):
        v |= np.uint64(buf[pos + k]) << np.uint64(8 * k)
    return v


@njit(cache=True)
def count_messages(buf):
    """Walk the records of a decompressed chunk; return ``(status, message records)``.

    ``status`` 1 when a record overruns the chunk or a message record is
    shorter than its fixed fields.
    """
    n = buf.size
    pos = np.int64(0)
    count = 0
    while pos < n:
        if pos + 9 > n:
            return 1, count
        size = _u64(buf, pos + 1)
        if size > np.uint64(n - pos - 9):
            return 1, count
        if buf[pos] == _OP_MESSAGE:
            if size < np.uint64(22):
                return 1, count
            count += 1
        pos += 9 + np.int64(size)
    return 0, count


@njit(cache=True)
def fill_messages(buf, channel, log_time, start, size):
    """Fill each message record's channel, log time (ns), data start and size (bytes)."""
    n = buf.size
    pos = np.int64(0)
    k = 0
    while pos < n:
        length = np.int64(_u64(buf, pos + 1))
        if buf[pos] == _OP_MESSAGE:
            channel[k] = np.int64(buf[pos + 9]) | (np.int64(buf[pos + 10]) << 8)
            log_time[k] = np.int64(_u64(buf, pos + 15))
            start[k] = pos + 9 + 22
            size[k] = length - 22
            k += 1
        pos += 9 + length


@njit(cache=True)
def same_prefix(bufs, which, start, size, template, mask, length, out):
    """Mark the messages of the template's layout.

    Message ``i`` is ``bufs[which[i]][start[i]:start[i] + size[i]]``;
    ``out[i]``: it is ``length`` bytes long and its first bytes equal
    ``template`` wherever ``mask`` is set (the stamp and CDR padding are not
    compared).
    """
    m = template.size
    for i in range(start.size):
        if size[i] != length:
            out[i] = False
            continue
        buf = bufs[which[i]]
        s = start[i]
        same = True
        for j in range(m):
            if mask[j] and buf[s + j] != template[j]:
                same = False
                break
        out[i] = same


@njit(cache=True)
def stamps(bufs, which, start, out):
    """Read each message's header stamp (CDR little endian: int32 sec, uint32 nanosec) (ns)."""
    for i in range(start.size):
        buf = bufs[which[i]]
        s = start[i] + 4
        sec = np.int64(0)
        for k in range(4):
            sec |= np.int64(buf[s + k]) << (8 * k)
        if sec >= 1 << 31:
            sec -= 1 << 32
        nsec = np.int64(0)
        for k in range(4):
            nsec |= np.int64(buf[s + 4 + k]) << (8 * k)
        out[i] = sec * 1_000_000_000 + nsec


@njit(cache=True)
def doubles(bufs, which, start, at, out):
    """Read ``out.shape[1]`` little-endian doubles ``at`` bytes into each message."""
    for i in range(start.size):
        buf = bufs[which[i]]
        s = start[i] + at
        out[i] = buf[s:s + 8 * out.shape[1]].view(np.float64)


@njit(cache=True)
def scan_patches(bufs, which, start, data_at, width, ny, nx, row, step, cols, pressure, out,
                 peak):
    """Run the node's patch adapter loop on every patch of one layout.

    Patch ``i``'s points start ``data_at`` bytes into its message
    (``bufs[which[i]][start[i]:]``) as native floats of ``width`` bytes (4:
    float32, 8: float64), point ``(j, k)`` at word ``j * row + k * step``,
    the patch fields at word offsets ``cols``.  Fills ``pressure[i]`` (Pa)
    and ``out[i]`` as :func:`msg_adapters.patch_kernels.adapt` does (its
    status, cells, sums, contact frame and grid fit, by its indices): a
    patch whose words are all finite goes through the node's loop without
    its per-point finiteness test (``checked=False``), any other through the
    node's loop with it, so a patch gives the node's numbers.  ``peak[i]``: the largest of
    ``pressure[i]`` (Pa) where the points are finite (the plausibility
    bound's peak pressure; NaN in, anything out).
    """
    words = (ny - 1) * row + nx * step
    nbytes = words * width
    for i in range(start.size):
        buf = bufs[which[i]]
        s = start[i] + data_at
        if width == 4:
            peak[i] = _adapt_patch(buf[s:s + nbytes].view(np.float32), words, ny, nx, row,
                                   step, cols, pressure[i], out[i])
        else:
            peak[i] = _adapt_patch(buf[s:s + nbytes].view(np.float64), words, ny, nx, row,
                                   step, cols, pressure[i], out[i])


@njit(cache=True, inline="always")
def _adapt_patch(words, n, ny, nx, row, step, cols, pressure, out):
    """Run the node's adapter loop on one patch's ``n`` words; return its largest pressure (Pa).

    Without the per-point finiteness test where every word is finite
    (:func:`all_finite`); otherwise the node's loop with it (the status then
    says why, and the largest pressure is NaN where one is).
    """
    if all_finite(words, n):
        return patch_kernels.adapt(words, ny, nx, row, step, cols, pressure, out, False)
    patch_kernels.adapt(words, ny, nx, row, step, cols, pressure, out)
    return pressure.max()


@njit(cache=True)
def all_finite(words, n):
    """Tell whether the first ``n`` words are all finite (one pass the compiler vectorises).

    The words of a patch's points, padding included: when they are all
    finite so is every field of every point; otherwise (a NaN in padding as
    much as in a field) the caller runs the node's own per-point test.
    """
    ok = True
    for k in range(n):
        ok &= abs(words[k]) < math.inf
    return ok


@njit(cache=True)
def solve_mae(ps, x0, y0, dx, dy, creep, mu, speed, rule, parabolic, shear_modulus, knots,
              polys, law, prm, calibrated, pair_knots, pair_values, status, info, out,
              knee=contact.NO_KNEE):
    """Solve each item with the compiled MAE solve the node calls (one per item).

    As :func:`fastsim_ros.contact.kernels.mae_batch`, but every item is
    solved whatever the others gave, and its load and slip counts are kept:
    ``status[b]``, ``info[b]`` and ``out[b]`` = ``Fx, Fy, Mz, N, slipping
    cells, cells in contact`` of :func:`~fastsim_ros.contact.kernels.mae_solve`
    on item ``b`` (``creep[b]``: ``xi, eta, phi``; ``speed[b]``: ``|V|``;
    ``knee``: the solver's, :func:`~fastsim_ros.contact.kernels.mae_sweep`).
    """
    empty_f = np.empty((0, 0))
    empty_b = np.empty((0, 0), dtype=np.bool_)
    for b in range(creep.shape[0]):
        r = contact.mae_solve(ps[b], x0[b], y0[b], dx[b], dy[b], creep[b, 0], creep[b, 1],
                              creep[b, 2], mu, 0.0, 0.0, rule, parabolic, shear_modulus, knots,
                              polys, law, prm, speed[b], empty_f, empty_f, empty_b, False,
                              calibrated, pair_knots, pair_values, knee)
        status[b] = r[0]
        info[b] = r[1]
        out[b, 0] = r[2]
        out[b, 1] = r[3]
        out[b, 2] = r[4]
        out[b, 3] = r[5]
        out[b, 4] = r[6]
        out[b, 5] = r[7]


@njit(cache=True)
def solve_equivalent(ps, x0, y0, dx, dy, creep, mu, speed, parabolic, cells, shear_modulus,
                     knots, polys, law, prm, status, info, out):
    """:func:`solve_mae` for the equivalent-ellipse FastSim (``cells``: 0 for its default)."""
    empty_f = np.empty((0, 0))
    empty_b = np.empty((0, 0), dtype=np.bool_)
    for b in range(creep.shape[0]):
        r = contact.equivalent_solve(ps[b], x0[b], y0[b], dx[b], dy[b], creep[b, 0],
                                     creep[b, 1], creep[b, 2], mu, 0.0, 0.0, parabolic, cells,
                                     shear_modulus, knots, polys, law, prm, speed[b], empty_f,
                                     empty_f, empty_b, False)
        status[b] = r[0]
        info[b] = r[1]
        out[b, 0] = r[2]
        out[b, 1] = r[3]
        out[b, 2] = r[4]
        out[b, 3] = r[5]
        out[b, 4] = r[6]
        out[b, 5] = r[7]


#: statuses of :func:`advance` (the rest are rejections: no wrench)
SOLVED, NO_CONTACT = 0, 1


@njit(cache=True)
def advance(contact_of, stamp, status, frame, force, tolerance, markers_on, period,
            last_frame, has_frame, last_marker, has_marker, wrench_stamp, wrench, has_wrench,
            last_sum, changed, marker, cycle, cycle_stamp, cycle_wrench):
    """Walk the patches in order with the pipeline's per-contact rules that carry state.

    Per patch ``i`` of contact ``contact_of[i]`` with ``status[i]``
    (:data:`SOLVED`, :data:`NO_CONTACT`, else rejected): whether its frame
    moved since the contact's last published frame (``changed``, origin or
    an axis by more than ``tolerance``), whether a marker is due
    (``marker``: none within ``period`` ns of stamps), and whether it
    completes a rig cycle (``cycle``: the pipeline's rule,
    :meth:`fastsim_ros.pipeline.Pipeline._add_wrench`: every contact has a
    wrench stamped after the last sum; then ``cycle_stamp`` the newest and
    ``cycle_wrench`` the sum of force and torque in the wheelset frame, in
    the contacts' order).  ``has_wrench[c]``: contact ``c`` has a wrench;
    ``last_sum[0]``: the last sum's stamp (the int64 minimum before the
    first).  ``force[i]``:
    ``Fx, Fy, N, Mz`` in the contact frame ``frame[i]`` (origin, ``e_x``,
    ``e_y``, ``e_z``).  The arithmetic is the pipeline's, term for term.
    The state arrays (per contact) are read and updated.
    """
    nc = has_wrench.size
    for i in range(contact_of.size):
        c = contact_of[i]
        s = status[i]
        changed[i] = False
        marker[i] = False
        cycle[i] = False
        if s != SOLVED and s != NO_CONTACT:
            continue
        f = frame[i]
        if s == SOLVED:
            moved = True
            if has_frame[c]:
                m = 0.0
                for k in range(3):
                    d = abs(last_frame[c, k] - f[k])
                    if d > m:
                        m = d
                t = 0.0
                for k in range(3, 12):
                    d = abs(last_frame[c, k] - f[k])
                    if d > t:
                        t = d
                moved = m > tolerance or t > tolerance
            if moved:
                for k in range(12):
                    last_frame[c, k] = f[k]
                has_frame[c] = True
            changed[i] = moved
            fx, fy, n, mz = force[i, 0], force[i, 1], force[i, 2], force[i, 3]
            # ContactFrame.to_wheelset: rows e_x, e_y, e_z
            w0 = fx * f[3] + fy * f[6] + n * f[9]
            w1 = fx * f[4] + fy * f[7] + n * f[10]
            w2 = fx * f[5] + fy * f[8] + n * f[11]
            m0 = 0.0 * f[3] + 0.0 * f[6] + mz * f[9]
            m1 = 0.0 * f[4] + 0.0 * f[7] + mz * f[10]
            m2 = 0.0 * f[5] + 0.0 * f[8] + mz * f[11]
            wrench[c, 0] = w0
            wrench[c, 1] = w1
            wrench[c, 2] = w2
            wrench[c, 3] = f[1] * w2 - f[2] * w1 + m0
            wrench[c, 4] = f[2] * w0 - f[0] * w2 + m1
            wrench[c, 5] = f[0] * w1 - f[1] * w0 + m2
        else:
            for k in range(6):
                wrench[c, k] = 0.0
        wrench_stamp[c] = stamp[i]
        has_wrench[c] = True
        complete = True
        lo = stamp[i]
        hi = stamp[i]
        for k in range(nc):
            if not has_wrench[k]:
                complete = False
            else:
                lo = min(lo, wrench_stamp[k])
                hi = max(hi, wrench_stamp[k])
        if complete and lo > last_sum[0]:
            for k in range(6):
                cycle_wrench[i, k] = 0.0
            for k in range(nc):
                for j in range(3):
                    cycle_wrench[i, j] += wrench[k, j]
                    cycle_wrench[i, 3 + j] += wrench[k, 3 + j]
            last_sum[0] = hi
            cycle[i] = True
            cycle_stamp[i] = hi
        if markers_on:
            due = True
            if has_marker[c]:
                age = stamp[i] - last_marker[c]
                if 0 <= age < period:
                    due = False
            if due:
                last_marker[c] = stamp[i]
                has_marker[c] = True
            marker[i] = due


@njit(cache=True)
def message_records(out, offsets, channel, log_time, payloads):
    """Write one MCAP message record per payload row into ``out`` at ``offsets[i]``.

    The bytes :class:`mcap.records.Message` writes (and
    :func:`fastsim_ros.replay.mcap.message_records` builds): opcode 0x05,
    the record's length ``22 + L`` (u64), ``channel`` (u16), sequence 0
    (u32), ``log_time[i]`` (ns, u64) as log and publish time, then the
    ``L`` bytes of ``payloads[i]``.
    """
    size = payloads.shape[1]
    length = np.uint64(22 + size)
    for i in range(payloads.shape[0]):
        o = offsets[i]
        out[o] = _OP_MESSAGE
        for k in range(8):
            out[o + 1 + k] = np.uint8((length >> np.uint64(8 * k)) & np.uint64(0xFF))
        out[o + 9] = np.uint8(channel & 0xFF)
        out[o + 10] = np.uint8((channel >> 8) & 0xFF)
        for k in range(4):
            out[o + 11 + k] = 0
        t = np.uint64(log_time[i])
        for k in range(8):
            byte = np.uint8((t >> np.uint64(8 * k)) & np.uint64(0xFF))
            out[o + 15 + k] = byte
            out[o + 23 + k] = byte
        for j in range(size):
            out[o + 31 + j] = payloads[i, j]


def warm_up() -> None:
    """Compile (or load from numba's disk cache) the loops on tiny inputs."""
    from numba.typed import List
    buf = np.frombuffer(bytes(512), dtype=np.uint8)  # read-only, as chunks are
    count_messages(buf)
    one = np.zeros(1, dtype=np.int64)
    fill_messages(buf[:0], one, one, one, one)
    bufs = List([buf])
    flags = np.zeros(1, dtype=np.bool_)
    same_prefix(bufs, one, one, one, np.zeros(4, dtype=np.uint8), flags.copy(), 4, flags)
    stamps(bufs, one, one, one.copy())
    doubles(bufs, one, one, 0, np.zeros((1, 6)))
    cols = np.arange(7, dtype=np.int64)
    for width in (4, 8):
        scan_patches(bufs, one, one, 0, width, 2, 2, 14, 7, cols, np.empty((1, 2, 2)),
                     np.zeros((1, patch_kernels.OUT_SIZE)), np.zeros(1))
    message_records(np.zeros(64, dtype=np.uint8), one, 3, one, np.zeros((1, 8), dtype=np.uint8))
