"""The measurement model of friction estimation: the package's solver as a function of mu_s.

A :class:`ContactSample` is one contact of one rig cycle as the pipeline
solved it: the patch's pressure grid, its creepages and rolling speed, and
the projection of its creep force ``(Fx, Fy)`` (contact frame, N) onto the
measured components (a rig's load cells: the wheelset frame's ``x``, say).
A :class:`CreepModel` holds the solver and the friction law's shape (name,
limit ratio ``A``, decay ``B`` in s/m); :meth:`CreepModel.predict` gives the
measured components' model values (N) at a static coefficient ``mu_s``.

Reverse running (rolling speed ``V < 0``) is solved as the pipeline solves
it (INTERFACE.md "Creepages"): the patch turned by 180 degrees about ``z``,
spin negated, ``(-Fx', -Fy')`` reported, so the model's forces are the
published ones bit for bit.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.compiled import (CalibratedMaeSolver, EquivalentEllipseSolver,
                                          MaeSolver)
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.friction import FrictionLaw, friction_law

FloatArray = NDArray[np.float64]
Solver = MaeSolver | EquivalentEllipseSolver
#: the solvers the estimators may use as their measurement model
METHODS = ("mae_calibrated", "mae", "fastsim_ellipse")


def solver_for(method: str, nu: float, shear_modulus: float) -> Solver:
    """Return the compiled solver of ``method`` (:data:`METHODS`); ``shear_modulus`` in Pa."""
    if method == "mae_calibrated":
        return CalibratedMaeSolver(nu, shear_modulus)
    if method == "mae":
        return MaeSolver(nu, shear_modulus)
    if method == "fastsim_ellipse":
        return EquivalentEllipseSolver(nu, shear_modulus)
    raise InvalidInputError(f"unknown method {method!r}: one of {', '.join(METHODS)}")


class ExactSolver:
    """Kalker's exact theory (:func:`fastsim_ros.contact.exact.coulomb`) with the batch call.

    ``solve_batch`` as the compiled solvers' (one patch, ``(B, 3)``
    creepages; ``bound`` must be ``"given"``): the batch fit's reference
    model (about 10 ms a solve at 20 x 20 cells), never the node's.  ``nu``,
    ``shear_modulus`` (Pa).
    """

    def __init__(self, nu: float, shear_modulus: float) -> None:
        self.nu, self.shear_modulus = float(nu), float(shear_modulus)

    def solve_batch(self, pressure: FloatArray, x0: float, y0: float, dx: float, dy: float,
                    creepages: FloatArray, *, bound: str = "given",
                    friction: FrictionLaw | None = None,
                    speed: float | None = None) -> FloatArray:
        """Return ``(B, 3)``: ``Fx, Fy`` (N), ``Mz`` (N m) at each row ``xi, eta, phi``."""
        from fastsim_ros.contact import exact
        from fastsim_ros.contact.area import GridArea

        if bound != "given":
            raise InvalidInputError("the exact solver takes the pressure as given "
                                    "(bound given)")
        area = GridArea(float(x0), float(y0), float(dx), float(dy), np.asarray(pressure))
        out = np.empty((len(creepages), 3))
        for k, (xi, eta, phi) in enumerate(np.asarray(creepages, dtype=np.float64)):
            sol = exact.coulomb(area, float(xi), float(eta), float(phi), nu=self.nu,
                                shear_modulus=self.shear_modulus, friction=friction,
                                speed=speed)
            out[k] = sol.fx, sol.fy, sol.mz
        return out


@dataclass(frozen=True, eq=False)
class ContactSample:
    """One contact of one cycle: grid, creepages, speed and the force's projection.

    ``pressure[j, i]`` (Pa) on the grid ``x0, y0, dx, dy`` (m, cell ``[0, 0]``'s
    centre and the cell sizes, contact frame); ``xi``, ``eta`` (1), ``phi``
    (1/m); ``speed``: the signed rolling speed ``V`` (m/s); ``projection``:
    ``(m, 2)``, the measured components as ``projection @ (Fx, Fy)``.
    """

    pressure: FloatArray
    x0: float
    y0: float
    dx: float
    dy: float
    xi: float
    eta: float
    phi: float
    speed: float
    projection: FloatArray | tuple[tuple[float, float], ...]

    @property
    def load(self) -> float:
        """Return the normal load ``sum p dA`` (N)."""
        return float(self.pressure.sum()) * self.dx * self.dy


@dataclass(frozen=True)
class CreepModel:
    """The solver under a friction law of fixed shape; ``mu_s`` is what is estimated.

    ``law``: ``"constant"`` or ``"exponential"``; ``limit_ratio`` ``A`` in
    ``(0, 1]`` and ``decay`` ``B`` (s/m) of ``mu(v) = mu_s ((1 - A) exp(-B v)
    + A)``; ``bound``: the traction bound (``"given"`` or ``"parabolic"``).
    """

    solver: Solver
    law: str = "constant"
    limit_ratio: float = 1.0
    decay: float = 0.0
    bound: str = "given"

    def friction(self, mu_s: float, limit_ratio: float | None = None,
                 decay: float | None = None) -> FrictionLaw:
        """Return the law at static coefficient ``mu_s`` (``A``, ``B``: the shape's by default)."""
        return friction_law(self.law, float(mu_s),
                            limit_ratio=self.limit_ratio if limit_ratio is None else limit_ratio,
                            decay=self.decay if decay is None else decay)

    def contact_forces(self, sample: ContactSample, mu_s: float) -> tuple[float, float]:
        """Return the creep forces ``(Fx, Fy)`` (N, contact frame) of one sample at ``mu_s``."""
        p, x0, y0, phi = sample.pressure, sample.x0, sample.y0, sample.phi
        reverse = sample.speed < 0.0
        if reverse:  # as Pipeline._solve: the leading edge at +x
            p = p[::-1, ::-1]
            x0 = -(x0 + (p.shape[1] - 1) * sample.dx)
            y0 = -(y0 + (p.shape[0] - 1) * sample.dy)
            phi = -phi
        law = self.friction(mu_s)
        f = self.solver.solve_arrays(p, x0, y0, sample.dx, sample.dy, sample.xi, sample.eta,
                                     phi, bound=self.bound,  # type: ignore[arg-type]
                                     friction=law, speed=abs(sample.speed))
        return (-f.fx, -f.fy) if reverse else (f.fx, f.fy)

    def predict(self, samples: Sequence[ContactSample], mu_s: float) -> FloatArray:
        """Return the measured components' model values (N): ``sum projection @ (Fx, Fy)``."""
        if not samples:
            raise InvalidInputError("no contact sample to predict")
        total = [0.0] * len(samples[0].projection)
        for s in samples:
            fx, fy = self.contact_forces(s, mu_s)
            for i, (px, py) in enumerate(s.projection):
                total[i] += float(px) * fx + float(py) * fy
        return np.array(total)
