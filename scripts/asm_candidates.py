"""Readings of Knothe and Hung's strip method tried against the seed's Table 2 (exploration).

A strip collocation more general than :mod:`fastsim_ros.contact.asm`: in each
strip (along the rolling direction, exact chords of an ellipse) either
traction component is a sum of basis functions of ``s = (x_l - x)/h`` (0 at
the leading edge, 1 at the trailing edge), constant across the strip's width;
full adhesion ``du/dx = w`` is imposed at given fractions ``s`` on the strip's
centre line.  ``du/dx`` is a central difference of the displacement, whose
integral along every strip is taken by tanh-sinh quadrature on either side of
the field point (it copes with the ``1/sqrt(1 - s)`` of the 2-D full-adhesion
shape at the trailing edge and with the kernels' logarithm on the point's own
strip).  With the quadratic basis it equals the package's ASM (checked by
:func:`self_check`).  Used by ``scripts/validate_seed.py``; numpy only.
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

from fastsim_ros.contact.asm import Strips, ellipse_strips
from fastsim_ros.contact.coefficients import (UNIT_CREEPAGES, CreepCoefficients,
                                              coefficients_from_unit_solutions)
from fastsim_ros.contact.influence import line_influence

FloatArray = np.ndarray
#: a basis function of ``(s, 1 - s)`` (1 - s passed apart: it is the singular end's distance)
Basis = Callable[[FloatArray, FloatArray], FloatArray]

BASES: dict[str, list[Basis]] = {
    # the package's ASM: tau = A1 s + A2 s^2
    "quadratic": [lambda s, m: s, lambda s, m: s * s],
    # the 2-D full-adhesion (Carter) shape, exact per strip for a slip linear in x
    "carter2": [lambda s, m: np.sqrt(s / m), lambda s, m: s * np.sqrt(s / m)],
    # its first term alone (exact per strip for a slip constant along it)
    "carter1": [lambda s, m: np.sqrt(s / m)],
    # a Hertz-like shape, zero at both ends
    "hertz2": [lambda s, m: np.sqrt(s * m), lambda s, m: s * np.sqrt(s * m)],
}


def _tanh_sinh(n: int = 60) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Nodes ``t`` on (0, 1), weights, and ``1 - t`` computed without cancellation."""
    step = 6.0 / n
    k = np.arange(-n, n + 1) * step
    u = 0.5 * math.pi * np.sinh(k)
    t = 0.5 * (1.0 + np.tanh(u))
    w = 0.25 * step * math.pi * np.cosh(k) / np.cosh(u) ** 2
    tm = 1.0 / (1.0 + np.exp(2.0 * u))
    ok = (t > 0.0) & (tm > 0.0) & (w > 1e-300)
    return t[ok], w[ok], tm[ok]


_TS = _tanh_sinh()


def _displacements(xp: FloatArray, yp: FloatArray, strips: Strips, basis: Sequence[Basis],
                   nu: float) -> list[list[FloatArray]]:
    """``[basis][xx, yy, xy]`` displacement kernels (points x strips) of unit basis tractions."""
    h = (strips.x_l - strips.x_t)[None, :]
    xl = strips.x_l[None, :]
    x = xp[:, None]
    y_lo = yp[:, None] - (strips.y + 0.5 * strips.dy)[None, :]
    y_hi = yp[:, None] - (strips.y - 0.5 * strips.dy)[None, :]
    split = np.clip((xl - x) / h, 0.0, 1.0)
    out = [[np.zeros(y_lo.shape) for _ in range(3)] for _ in basis]
    t, w, tm = _TS
    for part, (lo, hi) in enumerate(((np.zeros_like(split), split),
                                     (split, np.ones_like(split)))):
        length = hi - lo
        for tq, wq, tmq in zip(t, w, tm):
            s = lo + length * tq
            m = ((1.0 - split) + split * tmq if part == 0
                 else np.where(length > 0.0, length * tmq, 1.0))
            kxx, kyy, kxy = line_influence(x - (xl - h * s), y_lo, y_hi, shear_modulus=1.0,
                                           nu=nu)
            jac = wq * length * h
            for b, f in enumerate(basis):
                fv = f(s, m) * jac
                out[b][0] += kxx * fv
                out[b][1] += kyy * fv
                out[b][2] += kxy * fv
    return out


def strip_coefficients(strips: Strips, basis: Sequence[Basis], collocation: Sequence[float],
                       *, nu: float, area: float) -> CreepCoefficients:
    """Return the strip collocation's coefficients (about the origin, area ``area``)."""
    h = strips.x_l - strips.x_t
    xp = np.concatenate([strips.x_l - s * h for s in collocation])
    yp = np.concatenate([strips.y] * len(collocation))
    d = 1e-6 * float(h.max())
    up = _displacements(xp + d, yp, strips, basis, nu)
    um = _displacements(xp - d, yp, strips, basis, nu)
    nb, npts = len(basis), xp.size
    a = np.zeros((2 * npts, 2 * nb * strips.y.size))
    for b in range(nb):
        dxx, dyy, dxy = ((up[b][k] - um[b][k]) / (2.0 * d) for k in range(3))
        a[:npts, b::2 * nb] = dxx
        a[:npts, nb + b::2 * nb] = dxy
        a[npts:, b::2 * nb] = dxy
        a[npts:, nb + b::2 * nb] = dyy
    rhs = np.array([np.concatenate([xi - phi * yp, eta + phi * xp])
                    for xi, eta, phi in UNIT_CREEPAGES]).T
    coef = np.linalg.solve(a, rhs)
    t, w, tm = _TS
    m0 = [h * float((w * f(t, tm)).sum()) for f in basis]
    m1 = [h * (strips.x_l * float((w * f(t, tm)).sum()) - h * float((w * f(t, tm) * t).sum()))
          for f in basis]
    unit = []
    for k in range(coef.shape[1]):
        c = coef[:, k]
        fx = sum(strips.dy * c[b::2 * nb] * m0[b] for b in range(nb))
        fy = sum(strips.dy * c[nb + b::2 * nb] * m0[b] for b in range(nb))
        x_fy = sum(strips.dy * c[nb + b::2 * nb] * m1[b] for b in range(nb))
        mz = x_fy - strips.y * fx
        unit.append((float(np.sum(fx)), float(np.sum(fy)), float(np.sum(mz))))
    return coefficients_from_unit_solutions(area, tuple(unit))


def ellipse_coefficients(a_over_b: float, basis: str, collocation: Sequence[float], *,
                         nu: float, strips: int) -> CreepCoefficients:
    """Return the coefficients of an ellipse of area 1 (``strips`` strips, exact chords)."""
    b = 1.0 / math.sqrt(math.pi * a_over_b)
    return strip_coefficients(ellipse_strips(a_over_b * b, b, strips), BASES[basis],
                              collocation, nu=nu, area=1.0)


def chebyshev_collocation(n: int) -> tuple[float, ...]:
    """Gauss-Chebyshev collocation fractions for a traction ``~ sqrt(s/(1-s)) poly(s)``.

    The points of the quadrature rule for the weight ``sqrt((1-t)/(1+t))``
    (Erdogan and Gupta's for singular integral equations, one bounded end):
    ``t_j = cos((2j - 1) pi/(2n + 1))``, ``s = (1 - t)/2``.
    """
    return tuple((1.0 - math.cos((2 * j - 1) * math.pi / (2 * n + 1))) / 2.0
                 for j in range(1, n + 1))


def self_check(nu: float = 0.25) -> float:
    """Return the largest relative difference from the package's ASM (quadratic basis)."""
    from fastsim_ros.contact import asm
    worst = 0.0
    for g in (0.5, 1.0, 2.0):
        ours = ellipse_coefficients(g, "quadratic", asm.ASM_COLLOCATION, nu=nu, strips=20)
        pkg = asm.ellipse_coefficients(g, nu=nu, strips=20)
        for k in ("C11", "C22", "C23"):
            worst = max(worst, abs(getattr(ours, k) / getattr(pkg, k) - 1.0))
    return worst
