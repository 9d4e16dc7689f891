"""Kalker's steady rolling with Coulomb friction on large grids: semismooth Newton, FFTs, GMRES.

The discrete problem is the one :func:`fastsim_ros.contact.exact.coulomb`
states (and its dense reference solves strip by strip): on every cell in
contact, with ``s = w - B tau`` the slip (``B`` the
:class:`~fastsim_ros.contact.rolling.SteadyRollingOperator`, ``w`` the rigid
slip) and ``g`` the traction bound,

    |tau| <= g;   s = 0 where |tau| < g;   s = -lambda tau, lambda >= 0, where |tau| = g.

Written as the fixed point ``F(tau) = tau - P_g(tau - c s(tau)) = 0`` (``P_g``
the projection onto the disc of radius ``g``, ``c > 0`` a scalar that makes
``c B`` of unit diagonal; Alart and Curnier's form), ``F`` is semismooth and
is solved by Newton's method for the whole area at once:

- the Jacobian ``J = I - Pi (I + c B)`` (``Pi`` the projection's derivative,
  the identity on sticking cells, ``g/|z| (I - z z^T/|z|^2)`` on slipping
  ones) is never formed: GMRES multiplies by it with one FFT product
  (:class:`~fastsim_ros.contact.rolling.FFTProduct`) and per-cell 2 x 2 work;
- GMRES is preconditioned on the right by the exact inverse of ``J``'s own
  block on each lateral strip (strips longer than :data:`SEGMENT_CELLS` cut
  into segments): within a strip lies the upstream difference of steady
  rolling, the strongest coupling, and no ``x``-``y`` coupling of ``B``; the
  strips' mutual influence is left to GMRES.  Strips of one size are
  inverted together (batched LAPACK);
- Newton starts from the full-adhesion tractions projected onto the discs
  (one GMRES solve: the Newton step with every cell sticking), solves each
  step to a relative residual of ``min(0.1, |F|/(mu p_max))`` (inexact
  Newton: superlinear near the solution, cheap far from it), and takes the
  step in full unless the residual grows, then halves it (at most
  :data:`MAX_HALVINGS` times) below the largest residual of the last
  :data:`NONMONOTONE_MEMORY` iterations (Grippo, Lampariello and Lucidi's
  non-monotone line search: a full step that moves many cells between the
  slip and stick areas may raise ``|F|`` for one iteration).

A slip-dependent law makes the disc's radius ``g = g_s ratio(V |s|)`` depend
on the unknowns; on a slipping cell the Jacobian then gains ``- (z/|z|) g_s
ratio'(V |s|) V (s/|s|)^T ds/dtau`` with ``ds/dtau = -B``, carried in the
products and in the strip blocks alike.

Where Newton alone does not converge under a steeply falling law,
:func:`solve_continued` reaches the solution by continuation in the rolling
speed (the law's argument is ``|V| |s|``).

Cost per Newton iteration: a few FFT products of the ``2ny x 2nx`` grid per
GMRES iteration, and the strip blocks' inverses (``(2 m)^3`` per strip of
``m`` cells).  Memory: the grid's spectra, the Krylov basis and the blocks,
all proportional to the cells (no dense operator).

Imports numpy, :mod:`~fastsim_ros.contact.errors`, ``friction`` and ``rolling``.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import ParamSpec, TypeVar

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import ThreadpoolController

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.errors import ConvergenceError
from fastsim_ros.contact.friction import FrictionLaw
from fastsim_ros.contact.rolling import SteadyRollingOperator
from fastsim_ros.contact.traction import rigid_slip

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.intp]
P = ParamSpec("P")
R = TypeVar("R")

#: the longest strip segment of the preconditioner (cells): its blocks hold
#: ``4 SEGMENT_CELLS`` numbers a cell at most
SEGMENT_CELLS = 160
#: Newton iterations before :class:`ConvergenceError`
MAX_NEWTON = 200
#: Newton iterations of one solve under a slip-dependent law before continuation
#: (:func:`solve_continued`) takes over; a converging solve takes under 30
CONTINUATION_AFTER = 40
#: continuation: the smallest share of the rolling speed it starts from, and the least
#: growth factor of the share per step before it gives up
CONTINUATION_START = 2.0 ** -12
CONTINUATION_MIN_GROWTH = 1.05
#: step halvings of the line search before the step is taken anyway
MAX_HALVINGS = 5
#: iterations whose largest residual a step must not exceed (non-monotone search)
NONMONOTONE_MEMORY = 5
#: GMRES: restart length and most iterations per Newton step
KRYLOV_RESTART = 60
KRYLOV_MAX = 400
#: GMRES iterations of a Newton step beyond which the next step refactors every strip
#: segment (otherwise only those whose cells changed between slip and stick)
REBUILD_AFTER = 30


_BLAS: list[ThreadpoolController] = []


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the block with one BLAS thread, the former number restored after.

    The exact solvers' dense blocks are small (tens to hundreds of rows): a
    second BLAS thread gains little on them, and on a busy machine its
    spinning makes a solve many times slower (measured: 25x, 60 x 60 cells,
    the other core loaded).  The BLAS libraries are those loaded when this
    is first used (numpy's and, once :mod:`scipy.linalg` is imported, SciPy's).
    """
    if not _BLAS:
        _BLAS.append(ThreadpoolController())
    with _BLAS[0].limit(limits=1, user_api="blas"):
        yield


def on_one_blas_thread(solve: Callable[P, R]) -> Callable[P, R]:
    """Run every call of ``solve`` with one BLAS thread (:func:`one_blas_thread`)."""
    @functools.wraps(solve)
    def run(*args: P.args, **kwargs: P.kwargs) -> R:
        with one_blas_thread():
            return solve(*args, **kwargs)
    return run


@dataclass(frozen=True)
class PartialSlip:
    """A converged partial-slip solve.

    ``tau`` (m, 2): tractions on the cells in contact (Pa); ``slip`` (m,):
    the cells on their bound; ``newton``: Newton iterations (the initial
    full-adhesion step included); ``krylov``: GMRES iterations in all;
    ``products``: FFT products with the operator in all.
    """

    tau: FloatArray
    slip: BoolArray
    newton: int
    krylov: int
    products: int


class _Blocks:
    """Each strip segment's own block of ``A = I + c B`` (x/y interleaved), grouped by size.

    Shared by all segments of one cell pattern; built once per operator and
    scale ``c`` (:func:`strip_system`).
    """

    def __init__(self, op: SteadyRollingOperator, c: float) -> None:
        by_size: dict[int, tuple[list[IntArray], list[int], dict[bytes, int],
                                 list[FloatArray]]] = {}
        for idx, bxx, byy, pattern in op.segment_blocks(SEGMENT_CELLS):
            m = idx.size
            cells, which, known, patterns = by_size.setdefault(m, ([], [], {}, []))
            if pattern not in known:
                a = np.zeros((2 * m, 2 * m))
                # I + c B (z = tau - c s = (I + c B) tau - c w); B = du/dx has -D < 0 on
                # its diagonal, c B about -1
                a[0::2, 0::2] = c * bxx
                a[1::2, 1::2] = c * byy
                a[np.diag_indices(2 * m)] += 1.0
                known[pattern] = len(patterns)
                patterns.append(a)
            cells.append(idx)
            which.append(known[pattern])
        self.groups = [(np.array(cells), np.array(which), np.array(patterns))
                       for cells, which, _, patterns in by_size.values()]


def strip_system(op: SteadyRollingOperator, c: float) -> _Blocks:
    """Return the operator's strip blocks of ``I + c B`` (cached on the operator per ``c``)."""
    cache: dict[float, _Blocks] = op.__dict__.setdefault("_partial_slip_blocks", {})
    if c not in cache:
        cache.clear()
        cache[c] = _Blocks(op, c)
    return cache[c]


class _Preconditioner:
    """The exact inverse of the Jacobian's block on each strip segment, kept up to date.

    With ``A = I + c B`` restricted to the segment the block is ``I - Pi A``,
    less, for a slip-dependent law, ``zh dg^T (I - A)/c`` on the slipping
    cells (``(I - A)/c = -B = ds/dtau``).  :meth:`update` refactors only the
    segments in which a cell changed between slip and stick since their
    last factorisation (``everything=True``: all): near the solution few
    do, and a slipping cell's ``Pi`` drifts slowly.
    """

    def __init__(self, blocks: _Blocks) -> None:
        self.groups = blocks.groups
        self.inverses = [np.empty((cells.shape[0], 2 * cells.shape[1], 2 * cells.shape[1]))
                         for cells, _, _ in self.groups]
        self.states = [np.zeros(cells.shape, dtype=np.int8) - 1 for cells, _, _ in self.groups]

    def update(self, pi: FloatArray, c: float, slope: tuple[FloatArray, FloatArray] | None,
               out: BoolArray, everything: bool) -> int:
        """Refactor the segments whose slip cells changed (or all); return how many."""
        done = 0
        for (cells, which, patterns), inv, state in zip(self.groups, self.inverses,
                                                        self.states):
            now = out[cells].astype(np.int8)
            rows = (np.arange(cells.shape[0]) if everything
                    else np.flatnonzero((now != state).any(axis=1)))
            if rows.size == 0:
                continue
            inv[rows] = self._inverse(cells[rows], patterns[which[rows]], pi, c, slope)
            state[rows] = now[rows]
            done += rows.size
        return done

    @staticmethod
    def _inverse(cells: IntArray, blocks: FloatArray, pi: FloatArray, c: float,
                 slope: tuple[FloatArray, FloatArray] | None) -> FloatArray:
        k, m = cells.shape
        a4 = blocks.reshape(k, m, 2, 2 * m)
        p = pi[cells]  # (k, m, 2, 2)
        j4 = -(p[:, :, :, 0, None] * a4[:, :, None, 0, :]
               + p[:, :, :, 1, None] * a4[:, :, None, 1, :])
        if slope is not None:
            zh, dg = slope
            # d radius = dg . ds, ds = -B dtau; within the segment -B = (I - A)/c
            bs = -a4
            bs[:, np.arange(m), 0, 2 * np.arange(m)] += 1.0
            bs[:, np.arange(m), 1, 2 * np.arange(m) + 1] += 1.0
            row = (dg[cells][:, :, 0, None] * bs[:, :, 0, :]
                   + dg[cells][:, :, 1, None] * bs[:, :, 1, :]) / c
            j4 -= zh[cells][:, :, :, None] * row[:, :, None, :]
        jac = j4.reshape(k, 2 * m, 2 * m)
        jac[:, np.arange(2 * m), np.arange(2 * m)] += 1.0
        try:
            return np.asarray(np.linalg.inv(jac), dtype=np.float64)
        except np.linalg.LinAlgError:
            # a singular segment block (never seen): leave those segments unpreconditioned
            return np.broadcast_to(np.eye(2 * m), jac.shape).copy()

    def __call__(self, r: FloatArray) -> FloatArray:
        out = np.empty_like(r)
        for (cells, _, _), inv in zip(self.groups, self.inverses):
            k, m = cells.shape
            out[cells] = np.matmul(inv, r[cells].reshape(k, 2 * m, 1)).reshape(k, m, 2)
        return out


def _gmres(matvec: Callable[[FloatArray], FloatArray],
           precondition: Callable[[FloatArray], FloatArray], b: FloatArray,
           rtol: float) -> tuple[FloatArray, int]:
    """Solve ``A x = b`` by restarted GMRES, preconditioned on the right; return x, iterations.

    Stops at ``|b - A x| <= rtol |b|`` (the true residual: right
    preconditioning leaves it unscaled) or after :data:`KRYLOV_MAX` iterations.
    """
    shape = b.shape
    bv = b.ravel()
    bnorm = float(np.linalg.norm(bv))
    x = np.zeros_like(bv)
    if bnorm == 0.0:
        return x.reshape(shape), 0
    target = rtol * bnorm
    r = bv.copy()
    beta = bnorm
    total = 0
    size = KRYLOV_RESTART
    # only the Krylov basis is kept: x = M (V y) at the end of a cycle costs one more
    # preconditioner product and saves as much memory again
    v = np.empty((size + 1, bv.size))
    while True:
        h = np.zeros((size + 1, size))
        cs = np.zeros(size)
        sn = np.zeros(size)
        g = np.zeros(size + 1)
        g[0] = beta
        v[0] = r / beta
        k = 0
        while k < size and total < KRYLOV_MAX and abs(g[k]) > target:
            w = matvec(precondition(v[k].reshape(shape))).ravel()
            # classical Gram-Schmidt twice: as stable as modified, in matrix products
            hk = v[: k + 1] @ w
            w -= hk @ v[: k + 1]
            h2 = v[: k + 1] @ w
            w -= h2 @ v[: k + 1]
            h[: k + 1, k] = hk + h2
            h[k + 1, k] = float(np.linalg.norm(w))
            if h[k + 1, k] > 0.0:
                v[k + 1] = w / h[k + 1, k]
            for i in range(k):
                t = cs[i] * h[i, k] + sn[i] * h[i + 1, k]
                h[i + 1, k] = -sn[i] * h[i, k] + cs[i] * h[i + 1, k]
                h[i, k] = t
            rho = math.hypot(h[k, k], h[k + 1, k])
            cs[k], sn[k] = (h[k, k] / rho, h[k + 1, k] / rho) if rho > 0.0 else (1.0, 0.0)
            h[k, k] = rho
            h[k + 1, k] = 0.0
            g[k + 1] = -sn[k] * g[k]
            g[k] = cs[k] * g[k]
            k += 1
            total += 1
        if k == 0:
            return x.reshape(shape), total
        y = np.linalg.solve(np.triu(h[:k, :k]), g[:k])
        x += precondition((y @ v[:k]).reshape(shape)).ravel()
        r = bv - matvec(x.reshape(shape)).ravel()
        beta = float(np.linalg.norm(r))
        # done, out of iterations, or the estimate met but round-off keeps the true
        # residual above it (a restart would not help)
        if beta <= target or total >= KRYLOV_MAX or abs(g[k]) <= target and beta < 2 * target:
            return x.reshape(shape), total


def solve(op: SteadyRollingOperator, w: FloatArray, bound: FloatArray, *, tol: float,
          scale: float, law: FrictionLaw | None = None, speed: float = 0.0,
          start: FloatArray | None = None, max_newton: int = MAX_NEWTON) -> PartialSlip:
    """Solve the partial-slip problem on ``op``'s cells in contact.

    ``w`` (m, 2): the rigid slip at the cells; ``bound`` (m,): the static
    traction bound ``mu_s p`` (Pa); ``law``: a slip-dependent law (``None``:
    constant friction), with ``speed`` = ``|V|`` (m/s).  Converged when the
    largest residual ``|tau - P(tau - c s)|`` (a traction) is at most ``tol
    scale`` (``scale`` in Pa, ``mu max p`` for the callers).  Raises
    :class:`ConvergenceError` after ``max_newton`` iterations.
    """
    product = op.fft_product()
    d_x, d_y = op.diagonal
    c = 1.0 / math.sqrt(d_x * d_y)
    blocks = strip_system(op, c)
    n = w.shape[0]
    eye = np.broadcast_to(np.eye(2), (n, 2, 2))
    counts = {"products": 0, "krylov": 0}

    def bmul(t: FloatArray) -> FloatArray:
        counts["products"] += 1
        return product.on_cells(t)

    def state(t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray,
                                      BoolArray, FloatArray]:
        """``F``, ``z``, ``|z|``, the radius, the clipped cells and the slip at ``t``."""
        s = w - bmul(t)
        z = t - c * s
        nz = np.hypot(z[:, 0], z[:, 1])
        radius = bound if law is None else bound * law.ratio(speed * np.hypot(s[:, 0], s[:, 1]))
        out = nz > radius
        pz = z.copy()
        pz[out] *= (radius[out] / nz[out])[:, None]
        return t - pz, z, nz, radius, out, s

    precondition = _Preconditioner(blocks)
    last = [-1]

    def newton_step(t: FloatArray, f: FloatArray, pi: FloatArray,
                    slope: tuple[FloatArray, FloatArray] | None, rtol: float,
                    out: BoolArray) -> FloatArray:
        precondition.update(pi, c, slope, out, last[0] < 0 or last[0] > REBUILD_AFTER)

        def jmul(d: FloatArray) -> FloatArray:
            ds = -bmul(d)
            jd = d - np.einsum("nab,nb->na", pi, d - c * ds)
            if slope is not None:
                zh, dg = slope
                jd -= zh * np.einsum("na,na->n", dg, ds)[:, None]
            return jd

        step, its = _gmres(jmul, precondition, -f, rtol)
        last[0] = its
        counts["krylov"] += its
        return step

    # Newton's first step: every cell sticking (Pi = I) from tau = 0 is the full-adhesion
    # solve; its tractions projected onto the discs start the iteration.
    if start is None:
        # (at tau = 0 the sticking residual tau - z is c w)
        tau = newton_step(np.zeros((n, 2)), c * w, np.array(eye), None, 1e-3,
                          np.zeros(n, dtype=bool))
    else:
        tau = start
    f, z, nz, radius, out, s = state(tau)
    tau = tau - f  # the projection P(z), a point inside every disc
    f, z, nz, radius, out, s = state(tau)
    fmax = float(np.abs(f).max())
    merit = float(np.linalg.norm(f))
    history = [merit]
    newton = 1
    while fmax > tol * scale:
        if newton >= max_newton:
            raise ConvergenceError(f"the partial-slip Newton did not converge in {max_newton} "
                                   f"iterations (residual {fmax / scale:.2e} of mu p_max)")
        newton += 1
        pi = np.array(eye)
        zh = z[out] / nz[out][:, None]
        pi[out] = (radius[out] / nz[out])[:, None, None] * (
            eye[out] - zh[:, :, None] * zh[:, None, :])
        slope = None
        if law is not None and out.any():
            ns = np.hypot(s[:, 0], s[:, 1])
            safe = np.where(ns > 0.0, ns, 1.0)
            dgs = np.where(ns > 0.0, bound * law.ratio_slope(speed * ns) * speed / safe, 0.0)
            dir_z = np.zeros((n, 2))
            dir_z[out] = zh
            slope = (dir_z, np.where(out[:, None], s * dgs[:, None], 0.0))
        step = newton_step(tau, f, pi, slope, min(0.1, max(fmax / scale, 1e-3 * tol)), out)
        ceiling = max(history[-NONMONOTONE_MEMORY:])
        alpha = 1.0
        for _ in range(MAX_HALVINGS + 1):
            trial = tau + alpha * step
            f_t, z_t, nz_t, radius_t, out_t, s_t = state(trial)
            merit_t = float(np.linalg.norm(f_t))
            if merit_t < ceiling:
                break
            alpha *= 0.5
        tau, f, z, nz, radius, out, s = trial, f_t, z_t, nz_t, radius_t, out_t, s_t
        fmax = float(np.abs(f).max())
        history.append(merit_t)
    # at the fixed point the traction is the projection: exactly on the bound where clipped
    return PartialSlip(tau - f, out, newton, counts["krylov"], counts["products"])


def solve_continued(op: SteadyRollingOperator, w: FloatArray, bound: FloatArray, *,
                    tol: float, scale: float, law: FrictionLaw | None = None,
                    speed: float = 0.0, start: FloatArray | None = None) -> PartialSlip:
    """:func:`solve`, by continuation in the rolling speed where Newton alone does not converge.

    A steeply falling law (the exponential one with ``B |V|`` of thousands:
    friction halving within a millimetre per second of slip) makes the
    radius of a slipping cell's disc swing with its slip from one Newton
    iterate to the next, and the full-step Newton cycles between slip
    areas.  The law enters only through ``ratio(|V| |s|)``: solved at the
    speed ``t |V|``, ``t`` rising geometrically from
    :data:`CONTINUATION_START` (nearly constant friction) to 1, each solve
    starts within its Newton's reach of the next one's solution.  A step
    that fails is retried with the square root of its growth factor (down to
    :data:`CONTINUATION_MIN_GROWTH`, then :class:`ConvergenceError`).
    """
    if law is None or speed == 0.0:
        return solve(op, w, bound, tol=tol, scale=scale, start=start)
    try:
        return solve(op, w, bound, tol=tol, scale=scale, law=law, speed=speed, start=start,
                     max_newton=CONTINUATION_AFTER)
    except ConvergenceError:
        pass
    share = CONTINUATION_START
    res = solve(op, w, bound, tol=tol, scale=scale, law=law, speed=share * speed, start=start)
    growth = 2.0
    while share < 1.0:
        nxt = min(1.0, share * growth)
        try:
            res = solve(op, w, bound, tol=tol, scale=scale, law=law, speed=nxt * speed,
                        start=res.tau, max_newton=CONTINUATION_AFTER)
        except ConvergenceError:
            growth = math.sqrt(growth)
            if growth < CONTINUATION_MIN_GROWTH:
                raise ConvergenceError(
                    "the partial-slip Newton did not converge under the slip-dependent law, "
                    f"even by continuation in the rolling speed (stalled at {share:.3g} of "
                    "|V|)") from None
            continue
        share = nxt
        growth = min(2.0 * growth, 2.0)
    return res


#: grid sequencing: a grid starts from the tractions of the grid of twice its cells'
#: size when that one has at least this many cells in contact
COARSEST_CELLS = 100


def coarsened(area: GridArea) -> GridArea:
    """Return the area on cells twice as large: each the mean pressure of its 2 x 2 cells."""
    ny, nx = area.ny, area.nx
    p = np.zeros((ny + ny % 2, nx + nx % 2))
    p[:ny, :nx] = area.pressure
    blocks = p.reshape(p.shape[0] // 2, 2, p.shape[1] // 2, 2).mean(axis=(1, 3))
    return GridArea(area.x0 + 0.5 * area.dx, area.y0 + 0.5 * area.dy, 2 * area.dx, 2 * area.dy,
                    blocks)


def solve_area(op: SteadyRollingOperator, creepages: tuple[float, float, float],
               reference: tuple[float, float], *, mu_s: float, tol: float,
               law: FrictionLaw | None = None, speed: float = 0.0,
               start: FloatArray | None = None) -> PartialSlip:
    """Solve the partial-slip problem of ``op``'s area, bound ``mu_s p``, by grid sequencing.

    The area on cells twice as large (:func:`coarsened`), while it keeps at
    least :data:`COARSEST_CELLS` cells in contact, is solved first (to
    ``1e-3`` of ``mu p_max``) and its tractions, each coarse cell's on its
    fine cells, start Newton here: the slip and stick areas are then right
    but for a band of cells along their border, and Newton needs a few
    iterations whatever the grid (from the full-adhesion start it needs more
    the finer the grid, as the border moves a few cells per iteration).
    ``start`` (Pa, ``(m, 2)``, the cells in contact in the mask's order): the
    tractions of a nearby problem (a fit's previous evaluation) to start
    Newton from instead; the coarse grid is then skipped.
    """
    area = op.area
    mask = area.mask
    cache: dict[str, SteadyRollingOperator] = op.__dict__.setdefault("_partial_slip_coarse", {})
    if start is None and "op" not in cache:
        coarse = coarsened(area)
        if np.count_nonzero(coarse.mask) >= COARSEST_CELLS:
            cache["op"] = SteadyRollingOperator.of(coarse, nu=op.nu,
                                                   shear_modulus=op.shear_modulus)
    if start is None and "op" in cache:
        rough = solve_area(cache["op"], creepages, reference, mu_s=mu_s, tol=max(tol, 1e-3),
                           law=law, speed=speed)
        cop = cache["op"]
        grid = np.zeros((2, cop.area.ny, cop.area.nx))
        grid[:, cop.area.mask] = rough.tau.T
        fine = grid.repeat(2, axis=1).repeat(2, axis=2)[:, : area.ny, : area.nx]
        start = np.ascontiguousarray(fine[:, mask].T)
    wx, wy = rigid_slip(area, *creepages, reference)
    w = np.stack([wx[mask], wy[mask]], axis=1)
    bound = mu_s * area.pressure[mask]
    return solve_continued(op, w, bound, tol=tol, scale=mu_s * float(area.pressure.max()),
                           law=law, speed=speed, start=start)
