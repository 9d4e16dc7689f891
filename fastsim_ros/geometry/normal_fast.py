"""The normal problem on a planar potential contact grid, with numpy's FFT (no SciPy).

The same discrete problem and the same algorithm as
:func:`fastsim_ros.contact.normal.solve_normal` in approach mode (Polonsky
& Keer's projected conjugate gradients; Kalker's half-space influence
coefficients of uniform pressure on rectangles, quasi-identical bodies):
find ``p >= 0`` with the deformed gap ``h0 - delta + K p >= 0`` and ``p h =
0``.  What serves the profile path, which solves many grids of a few
shapes: the influence spectra are cached by grid shape and cell size; the
zero padding that makes the FFT's convolution linear goes to the next
length with factors 2, 3 and 5 only (pocketfft is twice as fast there as on
``2 n`` = 2 x 17 x 3); ``K p`` is updated with ``K t`` after a step that
changed no cell's state (the CG step is linear there) and recomputed after
any other step and every tenth; the FFTs are numpy's, so the path the node
runs does not import SciPy.
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.errors import ConvergenceError, InvalidInputError
from fastsim_ros.contact.influence import influence_kernel

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: relative pressure change of one iteration at which the solve stops
TOLERANCE = 1e-10
MAX_ITERATIONS = 2000
#: influence spectra kept (grid shapes recur from one pose to the next)
CACHE_SIZE = 64
#: ``K p`` is recomputed at least every this many iterations (rounding of the update)
REFRESH = 10


def fft_length(n: int) -> int:
    """Return the smallest length ``>= n`` whose only prime factors are 2, 3 and 5."""
    while True:
        m = n
        for f in (2, 3, 5):
            while m % f == 0:
                m //= f
        if m == 1:
            return n
        n += 1


class NormalSolver:
    """Polonsky-Keer CG for a given approach, with cached influence spectra."""

    def __init__(self, *, shear_modulus: float, nu: float) -> None:
        self.shear_modulus = float(shear_modulus)
        self.nu = float(nu)
        self._spectra: OrderedDict[tuple[int, int, float, float], ComplexArray] = OrderedDict()

    def _spectrum(self, ny: int, nx: int, dx: float, dy: float) -> ComplexArray:
        key = (ny, nx, dx, dy)
        hit = self._spectra.get(key)
        if hit is not None:
            self._spectra.move_to_end(key)
            return hit
        zz = influence_kernel(dx, dy, nx - 1, ny - 1, shear_modulus=self.shear_modulus,
                              nu=self.nu).zz
        # offset d (field minus source) at index d mod L, L >= 2n - 1: a linear
        # convolution on the first ny x nx entries of the padded grid
        shape = (fft_length(2 * ny - 1), fft_length(2 * nx - 1))
        c = np.zeros(shape)
        cy, cx = ny - 1, nx - 1
        c[np.ix_(np.arange(-cy, cy + 1) % shape[0], np.arange(-cx, cx + 1) % shape[1])] = zz
        spectrum = np.fft.rfft2(c)
        self._spectra[key] = spectrum
        if len(self._spectra) > CACHE_SIZE:
            self._spectra.popitem(last=False)
        return spectrum

    def solve(self, gap: FloatArray, approach: float, dx: float, dy: float) -> FloatArray:
        """Return the pressure (Pa) for the undeformed ``gap`` (m, ``>= 0``) and ``approach`` (m).

        The contact closes where ``gap < approach``; ``gap`` has ``ny x nx``
        cells of ``dx`` x ``dy`` (m).
        """
        h0 = np.asarray(gap, dtype=np.float64)
        if h0.ndim != 2 or min(h0.shape) < 2:
            raise InvalidInputError(f"gap must be a grid of at least 2 x 2 cells, got {h0.shape}")
        if not (math.isfinite(approach) and approach > 0.0 and np.all(np.isfinite(h0))):
            raise InvalidInputError("the gap and the approach must be finite, the approach > 0")
        ny, nx = h0.shape
        spectrum = self._spectrum(ny, nx, float(dx), float(dy))
        shape = (fft_length(2 * ny - 1), fft_length(2 * nx - 1))

        def product(p: FloatArray) -> FloatArray:
            u = np.fft.irfft2(spectrum * np.fft.rfft2(p, s=shape), s=shape)
            return np.asarray(u[:ny, :nx])

        d = np.maximum(approach - h0, 0.0)
        if not np.any(d > 0.0):
            return np.zeros_like(h0)
        kd = product(d)
        p = d * (float(np.sum(d * d)) / float(np.sum(d * kd)))
        u = product(p)
        t = np.zeros_like(h0)
        g_old = 1.0
        conjugate = False
        for it in range(1, MAX_ITERATIONS + 1):
            contact = p > 0.0
            g = u + h0 - approach
            g_norm = float(np.sum(g[contact] ** 2))
            beta = g_norm / g_old if conjugate else 0.0
            t = np.where(contact, g + beta * t, 0.0)
            g_old = g_norm
            r = product(t)
            curvature = float(np.sum(r[contact] * t[contact]))
            if g_norm == 0.0 or curvature <= 0.0:
                return p
            tau = float(np.sum(g[contact] * t[contact])) / curvature
            p_old = p
            trial = np.where(contact, p - tau * t, 0.0)
            clipped = bool((trial < 0.0).any())
            p = np.maximum(trial, 0.0)
            overlap = (p == 0.0) & (g < 0.0)
            conjugate = not bool(overlap.any())
            p[overlap] -= tau * g[overlap]
            s = float(p.sum())
            if not math.isfinite(s):
                raise ConvergenceError("the normal solver broke down")
            change = float(np.sum(np.abs(p - p_old)))
            if conjugate and not clipped and it % REFRESH:
                u = u - tau * r  # no cell changed state: p moved by -tau t exactly
            else:
                u = product(p)
            if s > 0.0 and change <= TOLERANCE * s:
                return p
        raise ConvergenceError(f"the normal solver did not converge in {MAX_ITERATIONS} "
                               "iterations")
