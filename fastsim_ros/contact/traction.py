"""Tangential traction fields on a grid area: the rigid slip that drives them, their resultants.

Shared by the exact solver and FastSim, so that both report forces the same
way: tractions of the rail on the wheel (Pa) at the cell centres, ``Fx``,
``Fy`` (N) and ``Mz`` (N m) about a reference point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class Tractions:
    """A traction field and its resultants.

    ``tau_x``, ``tau_y``: tractions of the rail on the wheel (Pa), shape
    ``(ny, nx)``, zero outside the contact; ``slip``: cells that slip (on the
    traction bound); ``fx``, ``fy`` (N) and ``mz`` (N m) about the reference
    point.
    """

    tau_x: FloatArray
    tau_y: FloatArray
    slip: NDArray[np.bool_]
    fx: float
    fy: float
    mz: float


def rigid_slip(area: GridArea, xi: float, eta: float, phi: float,
               reference: tuple[float, float] = (0.0, 0.0)) -> tuple[FloatArray, FloatArray]:
    """Return the rigid slip ``(w_x, w_y)`` at the cell centres, creepages about ``reference`` (m).

    ``w_x = xi - phi (y - y_P)``, ``w_y = eta + phi (x - x_P)`` (docs/guide_physics.md).
    """
    x = area.x[None, :] - reference[0]
    y = area.y[:, None] - reference[1]
    shape = area.pressure.shape
    return (np.broadcast_to(xi - phi * y, shape).astype(float),
            np.broadcast_to(eta + phi * x, shape).astype(float))


def resultants(area: GridArea, tau_x: FloatArray, tau_y: FloatArray,
               reference: tuple[float, float] = (0.0, 0.0)) -> tuple[float, float, float]:
    """Return ``(Fx, Fy, Mz)`` of a traction field on ``area``, ``Mz`` about ``reference``."""
    x = area.x[None, :] - reference[0]
    y = area.y[:, None] - reference[1]
    da = area.cell_area
    return (float(tau_x.sum() * da), float(tau_y.sum() * da),
            float((x * tau_y - y * tau_x).sum() * da))
