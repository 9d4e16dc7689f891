"""A solved patch against the plausible values of wheel-rail contact: a likely unit mistake.

:func:`implausible` applies :func:`fastsim_ros.ros.plausibility.stream_problem`
(the table the node, the replay and the command line share) to a patch's
extent, pressure and creepages; the replay's batch applies the same rule
through :func:`patch_extent`.  Skipped with ``allow_implausible``.
"""

from __future__ import annotations

import numpy as np

from fastsim_ros.ros.plausibility import PLAUSIBLE, stream_problem
from msg_adapters.kinematics import Creepage


def patch_extent(pressure: np.ndarray, dx: float, dy: float) -> tuple[float, float]:
    """Return a patch's span (m) along x and y: its grid's, or its cells in contact's if over.

    The grid's span bounds the contact's, so the cells in contact are looked
    at only where the grid spans more than a plausible patch.
    """
    ny, nx = pressure.shape
    high = PLAUSIBLE["patch_extent"].high
    if nx * dx <= high and ny * dy <= high:
        return nx * dx, ny * dy
    rows, cols = np.nonzero(pressure > 0.0)
    if cols.size == 0:
        return 0.0, 0.0
    return (float(np.ptp(cols)) + 1.0) * dx, (float(np.ptp(rows)) + 1.0) * dy


def implausible(pressure: np.ndarray, dx: float, dy: float, load: float, cells: int,
                creep: Creepage) -> str | None:
    """Return why a solved patch is a likely unit mistake (one line), or None.

    :func:`fastsim_ros.ros.stream_problem` on the patch's extent,
    its mean pressure (its largest where the mean is under the table's
    bound) and its creepages: the replay's batch applies the same rule.
    """
    ex, ey = patch_extent(pressure, dx, dy)
    p = load / (cells * dx * dy) if cells > 0 else 0.0
    if not p >= PLAUSIBLE["peak_pressure"].low:
        p = float(pressure.max())
    return stream_problem(ex, ey, p, creep.xi, creep.eta, creep.phi)
