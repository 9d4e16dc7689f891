"""Creepage-coefficient tables of the package, and their interpolation.

One source (METHOD.md section 2): the tables shipped in ``fastsim_ros/data``,
computed by ``scripts/make_coefficient_tables.py`` with the package's exact
solver.  Kalker's ``C11, C22, C23, C33`` of full ellipses come from
``kalker_coefficients.csv``; the half-ellipse ``c11, c22, c23`` are *defined*
as ``C11/2, C22/2, C23/2`` of that same table (exact by symmetry), and only
``c12, c13, c21`` are read from ``half_ellipse_coefficients.csv``.  So plain
FastSim and MAE read one set of numbers.

Interpolation: in ``log(a/b)`` by a cubic spline (the coefficients are smooth
in it over two decades), and in ``nu`` by a quadratic through the three
tabulated values of ``C (1 - nu)``, which removes the ``1/(1 - nu)`` of
Kalker's asymptotic formulas.  The tables span ``0.05 <= a/b <= 20`` (a
margin beyond Kalker's 0.1..10: MAE's zones of real patches may measure a
little outside it) and ``0 <= nu <= 0.5``; outside, a look-up is refused
(:class:`OutOfTableError`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from fastsim_ros.contact.errors import InvalidInputError, OutOfTableError

FloatArray = NDArray[np.float64]

FULL_NAMES = ("C11", "C22", "C23", "C33")
HALF_NAMES = ("c11", "c12", "c13", "c21", "c22", "c23")
#: the half-ellipse coefficients that are halves of Kalker's
HALF_FROM_FULL = {"c11": "C11", "c22": "C22", "c23": "C23"}


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
    values: dict[str, FloatArray]
    errors: dict[str, FloatArray]


@lru_cache(maxsize=1)
def table_data() -> TableData:
    """Load the shipped tables (cached)."""
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
        raise RuntimeError("the shipped coefficient tables do not share one grid")
    for half, full in HALF_FROM_FULL.items():
        errors[half] = errors[full] / 2.0
        values[half] = values[full] / 2.0
    return TableData(g0, n0, values, errors)


@dataclass(frozen=True, eq=False)
class CoefficientTable:
    """The coefficients at one Poisson ratio, as cubic splines in ``log(a/b)``.

    ``knots``: ``log(a/b)`` of the table; ``poly[name]``: the spline's
    coefficients, shape ``(4, len(knots) - 1)`` (highest power first, in
    ``log(a/b) - knots[k]``), the layout the compiled kernels read.
    """

    nu: float
    knots: FloatArray
    poly: dict[str, FloatArray]

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
        """Return the half-ellipse ``c11 ... c23`` (METHOD.md section 3.4)."""
        t = self._log_ratio(a_over_b)
        return {n: self._at(n, t) for n in HALF_NAMES}


@lru_cache(maxsize=16)
def coefficient_table(nu: float) -> CoefficientTable:
    """Return the tables interpolated to Poisson ratio ``nu`` (cached per ``nu``)."""
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
    for name, v in data.values.items():
        at_nu = (weights @ (v * (1.0 - nodes)[:, None])) / (1.0 - nu)
        poly[name] = np.ascontiguousarray(CubicSpline(knots, at_nu).c)
    return CoefficientTable(float(nu), knots, poly)
