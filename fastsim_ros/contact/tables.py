"""Creepage-coefficient tables of the package, and their interpolation.

One source (docs/guide_physics.md "FastSim"): the tables shipped in ``fastsim_ros/data``,
computed by ``scripts/make_coefficient_tables.py`` with the package's exact
solver.  Kalker's ``C11, C22, C23, C33`` of full ellipses come from
``kalker_coefficients.csv``; the half-ellipse ``c11, c22, c23`` are *defined*
as ``C11/2, C22/2, C23/2`` of that same table (exact by symmetry), and only
``c12, c13, c21`` are read from ``half_ellipse_coefficients.csv``.  So plain
FastSim and MAE read one set of numbers.

Interpolation: in ``log(a/b)`` by a cubic spline (not-a-knot end conditions,
as SciPy's ``CubicSpline``, computed here with numpy alone so that the fast
path does not import SciPy; the coefficients are smooth in ``log(a/b)`` over
two decades), and in ``nu`` by a quadratic through the three
tabulated values of ``C (1 - nu)``, which removes the ``1/(1 - nu)`` of
Kalker's asymptotic formulas.  The core of the tables spans ``0.05 <= a/b
<= 20`` (a margin beyond Kalker's 0.1..10: MAE's zones of real patches may
measure a little outside it); the ends ``0.0125..0.05`` and ``20..80`` serve
the zones of flange contacts (patches 16 mm long, under 1 mm wide) and are
splines of their own, joined to the core's at 0.05 and 20 (the values
continuous there), so that extending the tables left every number inside
the core as it was.  ``0 <= nu <= 0.5``; outside, a look-up is refused
(:class:`OutOfTableError`).

Everything handed out is read-only (arrays not writeable, mappings
``MappingProxyType``): the tables are cached and shared by every solve, so
no caller can change what a later solve reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from collections.abc import Mapping
from importlib import resources
from types import MappingProxyType

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.errors import DataError, InvalidInputError, OutOfTableError

FloatArray = NDArray[np.float64]

FULL_NAMES = ("C11", "C22", "C23", "C33")
HALF_NAMES = ("c11", "c12", "c13", "c21", "c22", "c23")
#: the half-ellipse coefficients that are halves of Kalker's
HALF_FROM_FULL = {"c11": "C11", "c22": "C22", "c23": "C23"}
#: the core range of a/b: one spline; beyond it each end has its own (see the module)
CORE_RANGE = (0.05, 20.0)


def _read(name: str) -> tuple[list[str], FloatArray]:
    text = resources.files("fastsim_ros").joinpath("data", name).read_text()
    lines = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]
    header = lines[0].split(",")
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    return header, data


@dataclass(frozen=True, eq=False)
class TableData:
    """The raw tables: ``values[name]`` of shape ``(len(nus), len(a_over_b))``."""

    a_over_b: FloatArray
    nus: FloatArray
    values: Mapping[str, FloatArray]
    errors: Mapping[str, FloatArray]


@lru_cache(maxsize=1)
def table_data() -> TableData:
    """Load the shipped tables (cached; read-only arrays and mappings)."""
    values: dict[str, FloatArray] = {}
    errors: dict[str, FloatArray] = {}
    grids = []
    for fname, names in (("kalker_coefficients.csv", FULL_NAMES),
                         ("half_ellipse_coefficients.csv", HALF_NAMES)):
        header, data = _read(fname)
        g = np.unique(data[:, header.index("a_over_b")])
        nus = np.unique(data[:, header.index("nu")])
        grids.append((g, nus))
        order = np.lexsort((data[:, header.index("a_over_b")], data[:, header.index("nu")]))
        data = data[order]
        for name in names:
            values[name] = data[:, header.index(name)].reshape(nus.size, g.size)
            errors[name] = data[:, header.index(name + "_err")].reshape(nus.size, g.size)
    (g0, n0), (g1, n1) = grids
    if not (np.array_equal(g0, g1) and np.array_equal(n0, n1)):
        raise DataError("the shipped coefficient tables do not share one grid")
    for half, full in HALF_FROM_FULL.items():
        errors[half] = errors[full] / 2.0
        values[half] = values[full] / 2.0
    return TableData(_frozen(g0), _frozen(n0), _frozen_map(values), _frozen_map(errors))


def _frozen(a: FloatArray) -> FloatArray:
    """Return ``a`` made read-only (it is not copied: nobody else holds it)."""
    a.setflags(write=False)
    return a


def _frozen_map(d: dict[str, FloatArray]) -> Mapping[str, FloatArray]:
    return MappingProxyType({k: _frozen(v) for k, v in d.items()})


def not_a_knot_spline(x: FloatArray, y: FloatArray) -> FloatArray:
    """Return the coefficients ``(4, n - 1)`` of the not-a-knot cubic spline through ``(x, y)``.

    The spline of SciPy's ``CubicSpline(x, y)`` (``bc_type="not-a-knot"``),
    same equations for the slopes ``s`` (the third derivative continuous at
    the second and the last-but-one knot), solved densely (a few dozen
    knots); highest power first, in ``x - x[k]`` on interval ``k``.  Needs at
    least 4 knots.
    """
    n = x.size
    if n < 4:
        raise DataError(f"a coefficient table needs at least 4 knots, has {n}")
    dx = np.diff(x)
    slope = np.diff(y) / dx
    a = np.zeros((n, n))
    b = np.empty(n)
    i = np.arange(1, n - 1)
    a[i, i] = 2.0 * (dx[:-1] + dx[1:])
    a[i, i + 1] = dx[:-1]
    a[i, i - 1] = dx[1:]
    b[1:-1] = 3.0 * (dx[1:] * slope[:-1] + dx[:-1] * slope[1:])
    d = x[2] - x[0]
    a[0, 0] = dx[1]
    a[0, 1] = d
    b[0] = ((dx[0] + 2.0 * d) * dx[1] * slope[0] + dx[0] ** 2 * slope[1]) / d
    d = x[-1] - x[-3]
    a[-1, -1] = dx[-2]
    a[-1, -2] = d
    b[-1] = (dx[-1] ** 2 * slope[-2] + (2.0 * d + dx[-1]) * dx[-2] * slope[-1]) / d
    s = np.linalg.solve(a, b)
    t = (s[:-1] + s[1:] - 2.0 * slope) / dx
    c = np.empty((4, n - 1))
    c[0] = t / dx
    c[1] = (slope - s[:-1]) / dx - t
    c[2] = s[:-1]
    c[3] = y[:-1]
    return c


@dataclass(frozen=True, eq=False)
class CoefficientTable:
    """The coefficients at one Poisson ratio, as cubic splines in ``log(a/b)``.

    ``knots``: ``log(a/b)`` of the table; ``poly[name]``: the spline's
    coefficients, shape ``(4, len(knots) - 1)`` (highest power first, in
    ``log(a/b) - knots[k]``), the layout the compiled kernels read.
    """

    nu: float
    knots: FloatArray
    poly: Mapping[str, FloatArray]

    def __call__(self, name: str, a_over_b: float) -> float:
        """Return coefficient ``name`` (``"C11"`` ... ``"c23"``) at ``a/b``."""
        return self._at(name, self._log_ratio(a_over_b))

    def _log_ratio(self, a_over_b: float) -> float:
        """Return ``log(a/b)``; refuse a ratio outside the knots."""
        if not (math.isfinite(a_over_b) and a_over_b > 0.0):
            raise InvalidInputError(f"a/b must be positive and finite, got {a_over_b}")
        t = math.log(a_over_b)
        lo, hi = float(self.knots[0]), float(self.knots[-1])
        if not (lo - 1e-12 <= t <= hi + 1e-12):
            raise OutOfTableError(f"a/b = {a_over_b:.4g} lies outside the tables' range "
                                  f"[{math.exp(lo):g}, {math.exp(hi):g}]")
        return t

    def _at(self, name: str, t: float) -> float:
        k = min(max(int(np.searchsorted(self.knots, t)) - 1, 0), self.knots.size - 2)
        c = self.poly[name][:, k]
        u = t - self.knots[k]
        return float(((c[0] * u + c[1]) * u + c[2]) * u + c[3])

    def kalker(self, a_over_b: float) -> tuple[float, float, float]:
        """Return Kalker's ``(C11, C22, C23)`` of a full ellipse."""
        t = self._log_ratio(a_over_b)
        return self._at("C11", t), self._at("C22", t), self._at("C23", t)

    def half(self, a_over_b: float) -> dict[str, float]:
        """Return the half-ellipse ``c11 ... c23`` (docs/guide_physics.md "MAE")."""
        t = self._log_ratio(a_over_b)
        return {n: self._at(n, t) for n in HALF_NAMES}


def _pieces(a_over_b: FloatArray) -> list[tuple[int, int]]:
    """Return the knot index ranges ``(first, last)`` of the splines: the ends, the core."""
    lo = int(np.argmin(np.abs(a_over_b - CORE_RANGE[0])))
    hi = int(np.argmin(np.abs(a_over_b - CORE_RANGE[1])))
    pieces = [(lo, hi)]
    if lo > 0:
        pieces.insert(0, (0, lo))
    if hi < a_over_b.size - 1:
        pieces.append((hi, a_over_b.size - 1))
    return pieces


@lru_cache(maxsize=16)
def coefficient_table(nu: float) -> CoefficientTable:
    """Return the tables interpolated to Poisson ratio ``nu`` (cached per ``nu``; read-only)."""
    data = table_data()
    if not (math.isfinite(nu) and data.nus[0] <= nu <= data.nus[-1]):
        raise OutOfTableError(f"nu = {nu} lies outside the tables' range "
                              f"[{data.nus[0]:g}, {data.nus[-1]:g}]")
    knots = np.log(data.a_over_b)
    # Lagrange weights of a quadratic in nu through the tabulated nus, applied
    # to C (1 - nu); exact at the tabulated values.
    nodes = data.nus
    weights = np.array([np.prod([(nu - nodes[m]) / (nodes[k] - nodes[m])
                                 for m in range(nodes.size) if m != k])
                        for k in range(nodes.size)])
    poly = {}
    pieces = _pieces(data.a_over_b)
    for name, v in data.values.items():
        splines = []
        for a, b in pieces:  # each piece as its own table (the core's numbers unchanged)
            part = v[:, a:b + 1]
            at_nu = (weights @ (part * (1.0 - nodes)[:, None])) / (1.0 - nu)
            splines.append(not_a_knot_spline(knots[a:b + 1], at_nu))
        poly[name] = np.ascontiguousarray(np.concatenate(splines, axis=1))
    return CoefficientTable(float(nu), _frozen(knots), _frozen_map(poly))
