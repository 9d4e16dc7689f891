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

#: friction-law codes of the kernels (:mod:`fastsim_ros.contact.friction`)
LAW_CONSTANT = 0
LAW_EXPONENTIAL = 1

#: the smallest share of the area a ``widest_strip`` zone may have under the
#: ``auto`` split rule (:func:`fastsim_ros.contact.mae.split_face`)
MIN_ZONE_SHARE = 0.15


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
