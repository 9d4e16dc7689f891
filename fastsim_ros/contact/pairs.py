"""Pair factors: the elastic interaction of two joined semi-ellipses, from the exact theory.

MAE's zones are sized as lone half ellipses; two halves joined along their
cut carry, in the exact theory, other shares of the force than two lone
halves would: the half-space couples them (a short half ``a/b = 5`` joined
to a round one ``a/b = 1`` carries more than when alone, the round one
less, and the pair's ``C~23`` is 26% above MAE's sum).  The *pair factor*
``k_ij(g_self, g_other, nu)`` is the ratio of the half ``g_self``'s
coefficient ``c_ij`` when joined to the half ``g_other`` (the family of
:func:`~fastsim_ros.contact.area.semi_ellipses`: equal half areas, ``a_i
b_i = 1/pi``) to its lone value, for ``ij`` in 11, 22, 23, 13; it is 1 on
the diagonal (the pair is then one ellipse).

Data: ``fastsim_ros/data/semi_ellipse_pair_factors.csv``, made by
``scripts/make_pair_tables.py`` with the package's exact solver (every entry
with an error estimate, provenance in the file's header).  Interpolation:
bilinear in ``(log g_self, log g_other)`` (:func:`~fastsim_ros.contact.rules.pair_factor`,
the one formula the kernels compile too), the nearest edge value outside
the nodes; in ``nu`` by the quadratic through the three tabulated values.

Assumption stated: a patch's two MAE zones are coupled as the equal-area
pair of the same ``a/b`` would be, whatever their areas.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.errors import DataError, OutOfTableError
from fastsim_ros.contact.rules import pair_factor

FloatArray = NDArray[np.float64]

#: the coefficients a pair factor is tabulated for, in the kernels' order
PAIR_NAMES = ("c11", "c22", "c23", "c13")
_FILE = "semi_ellipse_pair_factors.csv"


@dataclass(frozen=True, eq=False)
class PairFactors:
    """The pair factors at one Poisson ratio.

    ``knots``: ``log(a/b)`` of the nodes; ``values``: ``(4, n, n)``, the
    factors of :data:`PAIR_NAMES` at ``(g_self, g_other)`` nodes (read-only).
    """

    nu: float
    knots: FloatArray
    values: FloatArray

    def factor(self, name: str, g_self: float, g_other: float) -> float:
        """Return ``k_name`` of the half ``a/b = g_self`` joined to the half ``g_other``."""
        return float(pair_factor(self.knots, self.values[PAIR_NAMES.index(name)],
                                 math.log(g_self), math.log(g_other)))

    def factors(self, g_self: float, g_other: float) -> dict[str, float]:
        """Return every factor of :data:`PAIR_NAMES` at ``(g_self, g_other)``."""
        return {name: self.factor(name, g_self, g_other) for name in PAIR_NAMES}


@lru_cache(maxsize=1)
def _data() -> tuple[FloatArray, FloatArray, FloatArray]:
    """Nodes ``a/b``, Poisson ratios, and the factors ``(nu, 4, n, n)`` of the shipped file."""
    text = resources.files("fastsim_ros").joinpath("data", _FILE).read_text()
    rows = list(csv.DictReader(line for line in io.StringIO(text) if not line.startswith("#")))
    if not rows:
        raise DataError(f"{_FILE} holds no rows")
    nodes = np.array(sorted({float(r["g_self"]) for r in rows}))
    nus = np.array(sorted({float(r["nu"]) for r in rows}))
    values = np.full((nus.size, len(PAIR_NAMES), nodes.size, nodes.size), np.nan)
    for r in rows:
        a = int(np.searchsorted(nus, float(r["nu"])))
        i = int(np.searchsorted(nodes, float(r["g_self"])))
        j = int(np.searchsorted(nodes, float(r["g_other"])))
        for q, name in enumerate(PAIR_NAMES):
            values[a, q, i, j] = float(r["k" + name[1:]])
    if not np.all(np.isfinite(values)) or np.any(values <= 0.0):
        raise DataError(f"{_FILE} is incomplete or holds a factor <= 0")
    return nodes, nus, values


@lru_cache(maxsize=16)
def pair_factors(nu: float) -> PairFactors:
    """Return the pair factors at Poisson ratio ``nu`` (cached per ``nu``; read-only)."""
    nodes, nus, values = _data()
    if not (math.isfinite(nu) and nus[0] <= nu <= nus[-1]):
        raise OutOfTableError(f"nu = {nu} lies outside the pair factors' range "
                              f"[{nus[0]:g}, {nus[-1]:g}]")
    # Lagrange weights of the quadratic through the tabulated nus; exact at each of them
    weights = np.array([np.prod([(nu - nus[m]) / (nus[q] - nus[m])
                                 for m in range(nus.size) if m != q])
                        for q in range(nus.size)])
    at_nu = np.ascontiguousarray(np.tensordot(weights, values, axes=1))
    knots = np.log(nodes)
    knots.setflags(write=False)
    at_nu.setflags(write=False)
    return PairFactors(float(nu), knots, at_nu)
