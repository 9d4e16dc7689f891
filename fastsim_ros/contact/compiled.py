"""The fast path: MAE + FastSim and the equivalent-ellipse baseline, compiled.

Python API over :mod:`fastsim_ros.contact.kernels` (numba, compiled on first
use and cached on disk; :func:`warm_up` compiles, or loads, every kernel on
a tiny patch).  Results equal the numpy reference
(:func:`~fastsim_ros.contact.mae.mae_fastsim`,
:func:`~fastsim_ros.contact.equivalent.equivalent_fastsim`) to rounding.

- :class:`MaeSolver` ``(nu, shear_modulus, rule=...)``: ``solve(area, xi,
  eta, phi, mu=...)`` on a :class:`~fastsim_ros.contact.area.GridArea`,
  ``solve_arrays(pressure, x0, y0, dx, dy, ...)`` without building one (the
  node's hot path), ``solve_batch(...)`` for many patches or creepages in one
  compiled loop, and ``geometry`` / ``flexibility`` for inspection.
- :class:`CalibratedMaeSolver` ``(nu, shear_modulus, rule=...)``: the
  calibrated MAE (:mod:`~fastsim_ros.contact.mae_calibrated`), the same calls.
- :class:`EquivalentEllipseSolver` ``(nu, shear_modulus)``: the same calls.

Friction: ``mu`` (Coulomb, as always), or ``friction=`` a law of
:mod:`~fastsim_ros.contact.friction` with ``speed=`` the rolling speed
``|V|`` (m/s) that a slip-dependent law needs.  A law's slope reduction
(:mod:`~fastsim_ros.contact.slope_reduction`) runs the solve at creepages
times ``k`` with the law's coefficient at the rigid slip velocity, ``k`` on
the patch's equivalent ellipse (as
:func:`~fastsim_ros.contact.equivalent.reduce_slope`).

Units: SI throughout (m, Pa, N, N m; ``phi`` in 1/m; ``speed`` in m/s).  Bad input raises the
errors of :mod:`fastsim_ros.contact.errors` (validation runs in the kernels:
it costs one pass over the cells, not a dozen numpy calls).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from collections.abc import Callable
from typing import Any, NoReturn

import numpy as np
from numpy.typing import ArrayLike, NDArray

from fastsim_ros.contact import kernels as k
from fastsim_ros.contact import slip_power
from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import (Bound, SplitRule, check_bound, check_friction,
                                        check_shear_modulus, check_split_rule)
from fastsim_ros.contact.equivalent import EquivalentEllipse
from fastsim_ros.contact.errors import (ContactError, EmptyContactError, InvalidInputError,
                                        OutOfTableError)
from fastsim_ros.contact.friction import ExponentialFriction, FrictionLaw, check_speed, resolve
from fastsim_ros.contact.knee import knee_factors, knee_pack
from fastsim_ros.contact.mae import MaeGeometry, Zone, ZoneFlexibility
from fastsim_ros.contact.pairs import pair_factors
from fastsim_ros.contact.rules import ellipse_grid
from fastsim_ros.contact.tables import coefficient_table

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
Rule = SplitRule

_RULES = {"auto": k.RULE_AUTO, "widest_strip": k.RULE_WIDEST_STRIP,
          "centroid": k.RULE_CENTROID}
# placeholders for the kernels' traction outputs when none are wanted: one
# argument type for both cases, so one compiled specialisation
_NO_FLOAT = np.empty((0, 0))
_NO_BOOL = np.empty((0, 0), dtype=np.bool_)
# the parameters of a law that has none (constant friction)
_NO_PARAMS = np.zeros(2)


@dataclass(frozen=True, eq=False, slots=True)
class ContactForces:
    """Creep forces of one solve.

    ``fx``, ``fy`` (N) and ``mz`` (N m, about the reference point): forces
    of the rail on the wheel; ``n``: normal load ``sum p dA`` of the patch
    (N); ``slip_fraction``: share of the cells in contact on the traction
    bound.  With ``tractions=True``: ``tau_x``, ``tau_y`` (Pa) and ``slip``
    on the grid ``grid = (x0, y0, dx, dy)`` (m) (the patch's for MAE, the
    equivalent ellipse's for the baseline), else ``None``.  With them, the
    frictional dissipation of the slip area (steady rolling,
    :mod:`~fastsim_ros.contact.slip_power`): ``dissipation`` (N = J per
    metre rolled, ``sum -tau . s dA``; times ``|V|``: the frictional power,
    W) and per cell ``dissipation_density`` (N/m^2 per metre rolled, on
    ``grid``); else NaN and ``None``.
    """

    fx: float
    fy: float
    mz: float
    n: float
    slip_fraction: float
    tau_x: FloatArray | None = None
    tau_y: FloatArray | None = None
    slip: BoolArray | None = None
    grid: tuple[float, float, float, float] | None = None
    dissipation: float = math.nan
    dissipation_density: FloatArray | None = None


def _table_range(knots: FloatArray) -> str:
    return f"[{math.exp(knots[0]):.4g}, {math.exp(knots[-1]):.4g}]"


def _raise(status: int, info: float, knots: FloatArray, where: str = "") -> NoReturn:
    """Raise the exception of a kernel status code."""
    span = _table_range(knots)
    messages: dict[int, tuple[type[Exception], str]] = {
        k.E_GRID_NONFINITE: (InvalidInputError, "grid origin or cell size is NaN or infinite"),
        k.E_CELL_SIZE: (InvalidInputError, "cell sizes must be positive"),
        k.E_PRESSURE_NONFINITE: (InvalidInputError, "pressure has NaN or infinite values"),
        k.E_PRESSURE_NEGATIVE: (InvalidInputError, "negative pressure"),
        k.E_EMPTY: (EmptyContactError, "no cell in contact (no positive pressure)"),
        k.E_CREEPAGE: (InvalidInputError, "creepages xi, eta, phi must be finite"),
        k.E_MU: (InvalidInputError, "mu must be positive and finite"),
        k.E_REFERENCE: (InvalidInputError, "the reference point must be finite"),
        k.E_TABLE_ZONE1: (OutOfTableError, f"MAE zone 1 (y < y_s): a/b = {info:.4g} lies "
                          f"outside the tables' range {span}"),
        k.E_TABLE_ZONE2: (OutOfTableError, f"MAE zone 2 (y > y_s): a/b = {info:.4g} lies "
                          f"outside the tables' range {span}"),
        k.E_TABLE_ELLIPSE: (OutOfTableError, f"equivalent ellipse: a/b = {info:.4g} lies "
                            f"outside the tables' range {span}"),
        k.E_CELLS: (InvalidInputError,
                    "the equivalent ellipse needs at least 2 cells along each axis"),
    }
    error, text = messages.get(status, (ContactError, f"unknown kernel status {status}"))
    raise error(where + text)


def _readonly(a: FloatArray) -> FloatArray:
    """Return ``a`` as a read-only view (GridArea's pressure is read-only).

    numba compiles one specialisation per mutability: passing every pressure
    read-only keeps it to one (and one disk-cache entry) per kernel.  A view
    and ``setflags`` cost less than reading ``a.flags`` first.
    """
    a = a.view()
    a.setflags(write=False)
    return a


def _pressure(pressure: ArrayLike, ndim: int) -> FloatArray:
    p = np.ascontiguousarray(pressure, dtype=np.float64)
    if p.ndim != ndim:
        what = "a 2-D array (rows = lateral strips)" if ndim == 2 else \
            "a 3-D array (patch, strip, column) or one 2-D patch"
        raise InvalidInputError(f"pressure must be {what}, got shape {p.shape}")
    return _readonly(p)


_bound = check_bound


def _per_item(value: ArrayLike, size: int, name: str) -> FloatArray:
    """Return a scalar or a ``(size,)`` array as a contiguous ``(size,)`` float array."""
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0:
        return np.full(size, float(a))
    if a.shape != (size,):
        raise InvalidInputError(f"{name} must be a scalar or have shape ({size},), "
                                f"got {a.shape}")
    return np.ascontiguousarray(a)


def _law(mu: float | None, friction: FrictionLaw | None,
         speed: float | None) -> tuple[int, FloatArray, float, float]:
    """Return the kernels' ``(law code, params, mu_s, speed)`` of a solve."""
    if friction is None and mu is not None:
        # constant friction, the common case: ConstantFriction's check without building one
        # (0.65 us of a transient step's 7 us in Python)
        return k.LAW_CONSTANT, _NO_PARAMS, check_friction(float(mu)), 0.0
    law = resolve(mu, friction)
    if law.reduces_slope:  # the solvers' own calls apply it (_Solver._reducing)
        raise InvalidInputError("this call takes no slope reduction: the solvers' solve, "
                                "solve_arrays and solve_batch apply it")
    if law.slip_dependent:
        return law.code, law.params, law.mu_s, check_speed(speed)
    return law.code, _NO_PARAMS, law.mu_s, 0.0


def _batch_law(mu: ArrayLike | None, friction: FrictionLaw | None, speed: ArrayLike | None,
               size: int) -> tuple[int, FloatArray, FloatArray, FloatArray]:
    """Return the kernels' ``(law code, params, mu per item, speed per item)`` of a batch."""
    if friction is None:
        if mu is None:
            raise InvalidInputError("give mu or a friction law")
        return k.LAW_CONSTANT, _NO_PARAMS, _per_item(mu, size, "mu"), np.zeros(size)
    law = resolve(None, friction)
    mus = np.full(size, law.mu_s)
    if mu is not None and not np.array_equal(_per_item(mu, size, "mu"), mus):
        raise InvalidInputError(f"mu differs from the friction law's mu_s = {law.mu_s}")
    if not law.slip_dependent:
        return k.LAW_CONSTANT, _NO_PARAMS, mus, np.zeros(size)
    if speed is None:
        check_speed(None)
    speeds = _per_item(speed, size, "speed")  # type: ignore[arg-type]
    bad = ~(np.isfinite(speeds) & (speeds >= 0.0))
    if bad.any():
        check_speed(float(speeds[np.argmax(bad)]))
    return law.code, law.params, mus, speeds


def _batch_inputs(pressures: ArrayLike, x0: ArrayLike, y0: ArrayLike, dx: ArrayLike,
                  dy: ArrayLike,
                  creepages: ArrayLike) -> tuple[FloatArray, list[FloatArray], FloatArray]:
    ps = np.asarray(pressures, dtype=np.float64)
    if ps.ndim == 2:
        ps = ps[None]
    ps = _pressure(ps, 3)
    cr = np.ascontiguousarray(creepages, dtype=np.float64)
    if cr.ndim != 2 or cr.shape[1] != 3:
        raise InvalidInputError(f"creepages must have shape (B, 3) (xi, eta, phi), "
                                f"got {cr.shape}")
    size = cr.shape[0]
    if ps.shape[0] not in (1, size):
        raise InvalidInputError(f"{ps.shape[0]} patches for {size} creepages: give one "
                                "patch or one per creepage")
    named = ((x0, "x0"), (y0, "y0"), (dx, "dx"), (dy, "dy"))
    grid = [_per_item(v, size, name) for v, name in named]
    return ps, grid, cr


class _Solver:
    """What both solvers share: the material and the packed coefficient tables."""

    def __init__(self, nu: float, shear_modulus: float) -> None:
        check_shear_modulus(shear_modulus)
        table = coefficient_table(float(nu))  # refuses nu outside the tables
        self.nu = float(nu)
        self.shear_modulus = float(shear_modulus)
        # a private, writeable copy: the kernels' argument types stay those they were
        # compiled for (the table's own arrays are read-only)
        self._knots = np.array(table.knots, dtype=np.float64)
        self._polys = np.ascontiguousarray(np.stack([table.poly[name]
                                                     for name in k.TABLE_NAMES]))

    def _outputs(self, shape: tuple[int, int],
                 tractions: bool) -> tuple[FloatArray, FloatArray, BoolArray]:
        if not tractions:
            return _NO_FLOAT, _NO_FLOAT, _NO_BOOL
        return np.empty(shape), np.empty(shape), np.empty(shape, dtype=np.bool_)

    def solve(self, area: GridArea, xi: float, eta: float, phi: float, *,
              mu: float | None = None, reference: tuple[float, float] = (0.0, 0.0),
              bound: Bound = "given", tractions: bool = False,
              friction: FrictionLaw | None = None, speed: float | None = None) -> ContactForces:
        """Solve at creepages ``xi``, ``eta`` (1) and spin ``phi`` (1/m) about ``reference`` (m).

        ``mu``: friction coefficient; ``bound``: ``"given"`` (``g = mu p``)
        or ``"parabolic"`` (``mu N p^2 / sum(p^2 dA)``: Kalker's on a Hertzian patch);
        ``tractions``: also return the traction field.  ``friction``: a law
        (:mod:`~fastsim_ros.contact.friction`; default ``ConstantFriction(mu)``;
        ``mu``, if given too, must be its ``mu_s``; the bound is then that of
        ``mu_s`` times ``mu(v)/mu_s``); ``speed``: the rolling speed ``|V|``
        (m/s), required by a slip-dependent law.
        """
        return self._reducing(area.pressure, area.x0, area.y0, area.dx, area.dy, xi, eta,
                              phi, mu, friction, speed, reference, bound, tractions)

    def solve_arrays(self, pressure: ArrayLike, x0: float, y0: float, dx: float, dy: float,
                     xi: float, eta: float, phi: float, mu: float | None = None, *,
                     reference: tuple[float, float] = (0.0, 0.0), bound: Bound = "given",
                     tractions: bool = False, friction: FrictionLaw | None = None,
                     speed: float | None = None) -> ContactForces:
        """Solve on the pressure ``p[j, i]`` (Pa) of the grid ``x0, y0, dx, dy`` (m).

        The grid as in :class:`~fastsim_ros.contact.area.GridArea` (``(x0,
        y0)`` the centre of cell ``[0, 0]``); the rest as :meth:`solve`.
        """
        return self._reducing(_pressure(pressure, 2), x0, y0, dx, dy, xi, eta, phi, mu,
                              friction, speed, reference, bound, tractions)

    def _reducing(self, p: FloatArray, x0: float, y0: float, dx: float, dy: float, xi: float,
                  eta: float, phi: float, mu: float | None, friction: FrictionLaw | None,
                  speed: float | None, reference: tuple[float, float], bound: str,
                  tractions: bool) -> ContactForces:
        """Solve, the law's slope reduction (if any) applied: creepages times ``k``."""
        if friction is None or not friction.reduces_slope:
            return self._solve(p, x0, y0, dx, dy, xi, eta, phi, _law(mu, friction, speed),
                               reference, bound, tractions)
        law = resolve(mu, friction)
        k_factor, mu_eff = self._reduction(p, x0, y0, dx, dy, xi, eta, phi, law, speed)
        return self._solve(p, x0, y0, dx, dy, k_factor * xi, k_factor * eta, k_factor * phi,
                           (k.LAW_CONSTANT, _NO_PARAMS, mu_eff, 0.0), reference, bound,
                           tractions)

    def _reduction(self, p: FloatArray, x0: float, y0: float, dx: float, dy: float,
                   xi: float, eta: float, phi: float, law: FrictionLaw,
                   speed: float | None) -> tuple[float, float]:
        """Return ``(k, mu)`` of the modified FastSim on the patch's equivalent ellipse.

        The kernels' ellipse (:func:`~fastsim_ros.contact.kernels.equivalent_prepare`)
        and Kalker's ``C11 = 8 a / (3 L1 G)`` from its ``L1``: what
        :func:`~fastsim_ros.contact.equivalent.reduce_slope` computes in numpy.
        """
        ell = np.empty(k.ELL_SIZE)
        status, info = k.equivalent_prepare(p, float(x0), float(y0), float(dx), float(dy),
                                            self.shear_modulus, self._knots, self._polys, ell)
        if status:
            _raise(status, info, self._knots, "slope reduction: ")
        a = float(ell[k.ELL_A])
        c11 = 8.0 * a / (3.0 * float(ell[k.ELL_L1]) * self.shear_modulus)
        return law.reduced(float(xi), float(eta), float(phi), speed, a=a,
                           b=float(ell[k.ELL_B]), c11=c11, shear_modulus=self.shear_modulus,
                           load=float(ell[k.ELL_LOAD]))

    def solve_batch(self, pressures: ArrayLike, x0: ArrayLike, y0: ArrayLike, dx: ArrayLike,
                    dy: ArrayLike, creepages: ArrayLike, *, mu: ArrayLike | None = None,
                    reference: tuple[float, float] = (0.0, 0.0),
                    bound: Bound = "given", friction: FrictionLaw | None = None,
                    speed: ArrayLike | None = None) -> FloatArray:
        """Solve a batch (one compiled loop); return ``(B, 3)``: ``Fx, Fy`` (N), ``Mz`` (N m).

        ``pressures``: ``(B, ny, nx)`` (Pa), or one ``(ny, nx)`` patch for
        every creepage; ``x0 .. dy`` (m) and ``mu``: scalars or ``(B,)``;
        ``creepages``: ``(B, 3)`` rows ``xi, eta, phi`` (1, 1, 1/m) about
        ``reference`` (m).  ``friction``: one law for the batch (``mu``, if
        given too, must be its ``mu_s``); ``speed``: ``|V|`` (m/s), a scalar
        or ``(B,)``.  Item ``b`` equals ``solve_arrays`` on it.
        """
        ps, grid, cr = _batch_inputs(pressures, x0, y0, dx, dy, creepages)
        return self._batch(ps, grid, cr, mu, reference, bound, friction, speed)

    def _batch(self, ps: FloatArray, grid: list[FloatArray], cr: FloatArray,
               mu: ArrayLike | None, reference: tuple[float, float], bound: Bound,
               friction: FrictionLaw | None, speed: ArrayLike | None) -> FloatArray:
        """Solve the checked batch in the solver's compiled loop (:meth:`_batch_kernel`)."""
        reduced = self._reduce_batch(ps, grid, cr, mu, friction, speed)
        if reduced is None:
            code, prm, mus, speeds = _batch_law(mu, friction, speed, cr.shape[0])
        else:
            cr, mus = reduced
            code, prm, speeds = k.LAW_CONSTANT, _NO_PARAMS, np.zeros(cr.shape[0])
        out = np.empty((cr.shape[0], 3))
        status, index, info = self._batch_kernel(ps, grid, cr, mus, reference, bound, code,
                                                 prm, speeds, out)
        if status:
            _raise(status, info, self._knots, f"batch item {index}: ")
        return out

    def _batch_kernel(self, ps: FloatArray, grid: list[FloatArray], cr: FloatArray,
                      mus: FloatArray, reference: tuple[float, float], bound: str, code: int,
                      prm: FloatArray, speeds: FloatArray,
                      out: FloatArray) -> tuple[int, int, int]:
        """Run the solver's batch kernel into ``out``; return ``(status, item, info)``."""
        raise NotImplementedError

    def _reduce_batch(self, ps: FloatArray, grid: list[FloatArray], cr: FloatArray,
                      mu: ArrayLike | None, friction: FrictionLaw | None,
                      speed: ArrayLike | None) -> tuple[FloatArray, FloatArray] | None:
        """Return a batch's ``(creepages, mu)`` under the law's slope reduction, or None."""
        if friction is None or not friction.reduces_slope:
            return None
        law = resolve(None, friction)
        size = cr.shape[0]
        if mu is not None and not np.array_equal(_per_item(mu, size, "mu"),
                                                 np.full(size, law.mu_s)):
            raise InvalidInputError(f"mu differs from the friction law's mu_s = {law.mu_s}")
        speeds = (None if speed is None or not law.slip_dependent
                  else _per_item(speed, size, "speed"))
        scaled = np.empty_like(cr)
        mus = np.empty(size)
        for b in range(size):
            p = ps[0] if ps.shape[0] == 1 else ps[b]
            v = None if speeds is None else float(speeds[b])
            k_factor, mus[b] = self._reduction(p, grid[0][b], grid[1][b], grid[2][b],
                                               grid[3][b], cr[b, 0], cr[b, 1], cr[b, 2], law, v)
            scaled[b] = k_factor * cr[b]
        return scaled, mus

    def _solve(self, p: FloatArray, x0: float, y0: float, dx: float, dy: float, xi: float,
               eta: float, phi: float, law: tuple[int, FloatArray, float, float],
               reference: tuple[float, float], bound: str, tractions: bool) -> ContactForces:
        raise NotImplementedError

    def _forces(self, result: tuple[Any, ...], grid: tuple[float, float, float, float],
                out: tuple[FloatArray, FloatArray, BoolArray], tractions: bool,
                dissipation: Callable[[FloatArray], float] | None = None) -> ContactForces:
        """Return the solve's forces; with ``tractions`` its fields and ``dissipation``'s.

        ``dissipation(density)``: fills the cells' dissipation density and
        returns its sum (:mod:`~fastsim_ros.contact.slip_power`).
        """
        status, info, fx, fy, mz, load, nslip, ncontact = result
        if status:
            _raise(status, info, self._knots)
        if tractions:
            density = np.empty(out[0].shape)
            total = dissipation(density) if dissipation is not None else math.nan
            return ContactForces(fx, fy, mz, load, nslip / ncontact, out[0], out[1], out[2],
                                 grid, total, density if dissipation is not None else None)
        return ContactForces(fx, fy, mz, load, nslip / ncontact)


class MaeSolver(_Solver):
    """MAE + FastSim (:func:`fastsim_ros.contact.mae.mae_fastsim`), compiled.

    ``nu``: combined Poisson ratio (the tables' range); ``shear_modulus``:
    combined ``G`` (Pa); ``rule``: the split rule
    (:func:`~fastsim_ros.contact.mae.split_face`).
    """

    def __init__(self, nu: float, shear_modulus: float, *,
                 rule: Rule = "auto") -> None:
        super().__init__(nu, shear_modulus)
        self.rule: Rule = check_split_rule(rule)
        self._rule = _RULES[rule]
        self._calibrated = False
        # the pair factors (read by the calibrated method only; one argument type for both)
        self._pair_knots = np.zeros(2)
        self._pair_values = np.ones((4, 2, 2))
        # the knee factors strip by strip (the calibrated method's option), else none
        self._knee = k.NO_KNEE

    def _solve(self, p: FloatArray, x0: float, y0: float, dx: float, dy: float, xi: float,
               eta: float, phi: float, law: tuple[int, FloatArray, float, float],
               reference: tuple[float, float], bound: str, tractions: bool) -> ContactForces:
        tractions = bool(tractions)
        code, prm, mu, speed = law
        out = self._outputs(p.shape, tractions)  # type: ignore[arg-type]
        grid = (float(x0), float(y0), float(dx), float(dy))
        result = k.mae_solve(p, grid[0], grid[1], grid[2], grid[3], float(xi), float(eta),
                             float(phi), float(mu), float(reference[0]), float(reference[1]),
                             self._rule, _bound(bound), self.shear_modulus, self._knots,
                             self._polys, code, prm, speed, out[0], out[1], out[2], tractions,
                             self._calibrated, self._pair_knots, self._pair_values,
                             self._knee_for(bound))

        def dissipation(density: FloatArray) -> float:
            status, total = slip_power.mae_dissipation(
                p, grid[0], grid[1], grid[2], grid[3], float(xi), float(eta), float(phi),
                float(mu), float(reference[0]), float(reference[1]), self._rule,
                _bound(bound), self.shear_modulus, self._knots, self._polys, self._calibrated,
                self._pair_knots, self._pair_values, out[0], out[1], out[2], density)
            return float(total) if status == k.OK else math.nan
        return self._forces(result, grid, out, tractions, dissipation)

    def _knee_for(self, bound: str) -> FloatArray:
        """Return the packed knee table the solve applies (none with the parabolic bound)."""
        return self._knee if bound == "given" else k.NO_KNEE

    def _batch_kernel(self, ps: FloatArray, grid: list[FloatArray], cr: FloatArray,
                      mus: FloatArray, reference: tuple[float, float], bound: str, code: int,
                      prm: FloatArray, speeds: FloatArray,
                      out: FloatArray) -> tuple[int, int, int]:
        return k.mae_batch(ps, grid[0], grid[1], grid[2], grid[3], cr, mus,
                           float(reference[0]), float(reference[1]), self._rule,
                           _bound(bound), self.shear_modulus, self._knots, self._polys, code,
                           prm, speeds, out, self._calibrated, self._pair_knots,
                           self._pair_values, self._knee_for(bound))

    def _prepare(self, area: GridArea) -> tuple[int, float, FloatArray]:
        geo = np.empty(k.GEO_SIZE)
        env = np.empty((2, area.nx), dtype=np.int64)
        strips = np.empty((3, area.ny), dtype=np.int64)
        p = _readonly(area.pressure)
        status, info = k.mae_prepare(p, float(area.x0), float(area.y0), float(area.dx),
                                     float(area.dy), self._rule, self.shear_modulus,
                                     self._knots, self._polys, geo, env, strips,
                                     self._calibrated, self._pair_knots, self._pair_values)
        return status, info, geo

    def geometry(self, area: GridArea) -> MaeGeometry:
        """Return MAE steps 1-3 (centroid, split line, zones) as the reference's dataclass."""
        status, info, geo = self._prepare(area)
        if status not in (k.OK, k.E_TABLE_ZONE1, k.E_TABLE_ZONE2):  # no table needed here
            _raise(status, info, self._knots)
        zones = [Zone(*(float(v) for v in geo[base:base + 6]))
                 for base in (k.G_ZONE1, k.G_ZONE2)]
        return MaeGeometry(float(geo[k.G_XC]), float(geo[k.G_YC]), float(geo[k.G_YS]),
                           self.rule, zones[0], zones[1], float(geo[k.G_AREA]))

    def flexibility(self, area: GridArea) -> tuple[ZoneFlexibility | None,
                                                   ZoneFlexibility | None]:
        """Return each zone's ``L1 .. L4`` (m/Pa), ``None`` for an empty zone."""
        status, info, geo = self._prepare(area)
        if status:
            _raise(status, info, self._knots)
        return tuple(None if geo[zone] <= 0.0 else  # type: ignore[return-value]
                     ZoneFlexibility(*(float(v) for v in geo[flex:flex + 4]))
                     for zone, flex in ((k.G_ZONE1, k.G_FLEX1), (k.G_ZONE2, k.G_FLEX2)))


class CalibratedMaeSolver(MaeSolver):
    """The calibrated MAE + FastSim, compiled (:mod:`fastsim_ros.contact.mae_calibrated`).

    The paper's MAE geometry with pair factors, zone flexibilities calibrated
    on the patch's own cells and the rigid-slip return; ``nu``,
    ``shear_modulus`` (Pa) and ``rule`` as :class:`MaeSolver`, whose calls
    it has (``flexibility`` gives the calibrated ``L1 .. L4``).

    ``knee`` (default): FastSim's knee corrected strip by strip with the
    knee factors of :mod:`fastsim_ros.contact.knee`
    (:func:`~fastsim_ros.contact.mae_calibrated.strip_knee`; the given
    bound only): each strip's force times the exact theory's factor at its
    own share of the saturation.  Measured against the exact theory on the
    default wheelset's patches (``docs/validation_accuracy.md``) it halves
    the method's worst error near zero shift and through the flange.
    ``knee=False``: FastSim's own knee.
    """

    def __init__(self, nu: float, shear_modulus: float, *,
                 rule: Rule = "auto", knee: bool = True) -> None:
        super().__init__(nu, shear_modulus, rule=rule)
        pairs = pair_factors(self.nu)  # refuses nu outside the pair factors' range
        self._calibrated = True
        self.knee = bool(knee)
        if self.knee:
            self._knee = knee_pack(knee_factors(self.nu))
        # private, writeable copies (the pair factors are read-only): the kernels' argument
        # types are then the paper's MAE's, one compiled specialisation for both
        self._pair_knots = np.array(pairs.knots, dtype=np.float64)
        self._pair_values = np.array(pairs.values, dtype=np.float64, order="C")


class EquivalentEllipseSolver(_Solver):
    """Plain FastSim on the patch's equivalent ellipse (the baseline), compiled.

    :func:`fastsim_ros.contact.equivalent.equivalent_fastsim`: the ellipse
    of the patch's area, centroid and second-moment ratio, discretised on
    ``cells`` x ``cells`` cells (default: as many cells in contact as the patch), with
    Kalker's flexibilities and a Hertzian (``bound="given"``) or parabolic
    pressure of the patch's load.  ``nu``, ``shear_modulus`` (Pa) as
    :class:`MaeSolver`.
    """

    def __init__(self, nu: float, shear_modulus: float, *, cells: int | None = None) -> None:
        super().__init__(nu, shear_modulus)
        if cells is not None and not cells >= 2:
            raise InvalidInputError(f"cells must be at least 2, got {cells}")
        self.cells = None if cells is None else int(cells)

    def _solve(self, p: FloatArray, x0: float, y0: float, dx: float, dy: float, xi: float,
               eta: float, phi: float, law: tuple[int, FloatArray, float, float],
               reference: tuple[float, float], bound: str, tractions: bool) -> ContactForces:
        tractions = bool(tractions)
        code, prm, mu, speed = law
        # the kernel sizes the ellipse's grid itself (n = 0) unless tractions need arrays
        n = self.cells or (k.ellipse_cells(int(np.count_nonzero(p > 0.0))) if tractions else 0)
        out = self._outputs((n, n), tractions)
        result = k.equivalent_solve(p, float(x0), float(y0), float(dx), float(dy), float(xi),
                                    float(eta), float(phi), float(mu), float(reference[0]),
                                    float(reference[1]), _bound(bound), n,
                                    self.shear_modulus, self._knots, self._polys, code, prm,
                                    speed, out[0], out[1], out[2], tractions)
        grid = (math.nan,) * 4
        if tractions and result[0] == k.OK:
            e = self._ellipse(p, x0, y0, dx, dy)
            grid = ellipse_grid(e.a, e.b, n, e.x_c, e.y_c)  # the kernel's grid, one formula

        def dissipation(density: FloatArray) -> float:
            status, total = slip_power.equivalent_dissipation(
                p, float(x0), float(y0), float(dx), float(dy), float(xi), float(eta),
                float(phi), float(reference[0]), float(reference[1]), _bound(bound), n,
                self.shear_modulus, self._knots, self._polys, out[0], out[1], out[2], density)
            return float(total) if status == k.OK else math.nan
        return self._forces(result, grid, out, tractions,  # type: ignore[arg-type]
                            dissipation)

    def _batch_kernel(self, ps: FloatArray, grid: list[FloatArray], cr: FloatArray,
                      mus: FloatArray, reference: tuple[float, float], bound: str, code: int,
                      prm: FloatArray, speeds: FloatArray,
                      out: FloatArray) -> tuple[int, int, int]:
        return k.equivalent_batch(
            ps, grid[0], grid[1], grid[2], grid[3], cr, mus, float(reference[0]),
            float(reference[1]), _bound(bound), self.cells or 0, self.shear_modulus,
            self._knots, self._polys, code, prm, speeds, out)

    def _ellipse(self, p: FloatArray, x0: float, y0: float, dx: float,
                 dy: float) -> EquivalentEllipse:
        ell = np.empty(k.ELL_SIZE)
        status, info = k.equivalent_prepare(p, float(x0), float(y0), float(dx), float(dy),
                                            self.shear_modulus, self._knots, self._polys, ell)
        if status not in (k.OK, k.E_TABLE_ELLIPSE):  # no table needed for the ellipse
            _raise(status, info, self._knots)
        return EquivalentEllipse(*(float(v) for v in ell[k.ELL_XC:k.ELL_B + 1]))

    def ellipse(self, area: GridArea) -> EquivalentEllipse:
        """Return the area's equivalent ellipse: centre and semi-axes (m)."""
        return self._ellipse(_readonly(area.pressure), area.x0, area.y0, area.dx, area.dy)


def warm_up_case() -> tuple[GridArea, FrictionLaw,
                            tuple[MaeSolver, CalibratedMaeSolver, EquivalentEllipseSolver]]:
    """Return what the warm-ups solve: a tiny patch, a falling law and each solver.

    The kernels compile once per argument type, not per size: a 5 x 5 patch
    compiles what a rig's 30 x 30 ones run.
    """
    area = GridArea(-1.0, -1.0, 0.4, 0.4, np.array(
        [[0.0, 1.0, 2.0, 1.0, 0.0], [1.0, 2.0, 3.0, 2.0, 1.0], [1.0, 3.0, 4.0, 3.0, 1.0],
         [1.0, 2.0, 3.0, 2.0, 1.0], [0.0, 1.0, 2.0, 1.0, 0.0]]))
    return area, ExponentialFriction(0.3, 0.5, 0.5), (
        MaeSolver(0.28, 8e10), CalibratedMaeSolver(0.28, 8e10),
        EquivalentEllipseSolver(0.28, 8e10))


def warm_up() -> float:
    """Compile (or load from the disk cache) every kernel on a tiny patch; return seconds.

    Call it at start-up so that the first real solve does not pay for the
    compilation.
    """
    start = time.perf_counter()
    area, falling, solvers = warm_up_case()
    creep = np.array([[1e-3, 0.0, 0.1], [0.0, -1e-3, 0.0]])
    for solver in solvers:
        solver.solve(area, 1e-3, 0.0, 0.0, mu=0.3)
        solver.solve(area, 1e-3, 0.0, 0.0, mu=0.3, tractions=True)
        solver.solve_batch(area.pressure, area.x0, area.y0, area.dx, area.dy, creep, mu=0.3)
        solver.solve(area, 1e-3, 0.0, 0.0, friction=falling, speed=10.0)
        if isinstance(solver, MaeSolver):
            solver.geometry(area)
        else:
            solver.ellipse(area)
    return time.perf_counter() - start
