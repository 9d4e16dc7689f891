"""FastSim's knee against the exact theory: a factor on the creep force's magnitude.

FastSim's creep force rises from zero traction at the leading edge of every
strip and is capped by ``mu p``; with the pressure as given (elliptical
across a Hertzian patch, ``bound="given"``) a thin band of adhesion stays at
the leading edge however large the creepage, so its curve reaches full slip
only slowly, while the exact theory's stick area vanishes at a finite
creepage.  Measured against :func:`fastsim_ros.contact.exact.coulomb` on
Hertzian ellipses, at the same creepage the magnitude of FastSim's force is
up to 1.6% of ``mu N`` above the exact one in the early partial slip and
up to 6.6% below it at the knee (``docs/validation_estimation.md``).

Both curves are functions of one variable on an ellipse: the creepage
normalised by its saturation value::

    s = |F_lin| / (mu_s N),

``F_lin`` the force of Kalker's linear theory (full adhesion, the force
FastSim's flexibilities reproduce: :func:`linear_force`), ``mu_s`` the static
coefficient, ``N`` the load.  FastSim's curve ``|F| / (mu N)`` against ``s``
is the same on every ellipse (its flexibilities make it so); the exact one
moves with the ellipse's ``a/b``, the creepage's direction and ``nu`` by
about a point of ``mu N`` at the knee.  So the *knee factor*::

    kappa(s, a/b, direction, nu) = |F_exact| / |F_fastsim|   at the same s

is tabulated with the exact solver (``fastsim_ros/data/fastsim_knee_factors.csv``,
made by ``scripts/make_knee_table.py``, provenance in its header) for pure
longitudinal and pure lateral creepage, and :meth:`KneeFactors.factor`
interpolates it: a cubic Hermite in ``s`` (its slope continuous), linearly
in ``log(a/b)`` (the nearest edge outside the nodes), between the two
directions by the share
``w = F_lin,x^2 / |F_lin|^2`` of the linear force along ``x``, in ``nu`` by
the quadratic through the three tabulated values.  Beyond the last node in
``s`` (full slip) ``kappa - 1`` falls as ``1/s^3``, as the deficit of
FastSim's remaining adhesion band does; ``kappa(0) = 1``.

Assumptions stated: the factor of a Hertzian ellipse serves any patch (on
MAE's patches it is taken at the equivalent ellipse's ``a/b``); Coulomb
friction (under a slip-dependent law ``s`` is taken at ``mu_s``: measured,
the exponential law of ``docs/validation_estimation.md`` moves the exact
curve's knee by 0.2 point of ``mu N`` against FastSim's); spin enters only
through ``F_lin`` (the tables hold no spin).  Measured with spin (ellipses
a/b 0.6 and 2, the flange-root patch; xi 2e-3 to 3e-3 or eta 2e-3 with phi
0.5 to 5 1/m, 20 cases): the factor lowers the error in 12, raises it in 7;
eta with spin (the two add in ``F_lin``) gains most (2.4 to 0.04% of ``mu
N``), xi across spin loses most (the flange-root patch at phi = 1 1/m: 0.8
to 4.3%; a/b 0.6 at phi = 3 1/m: 2.2 to 3.2%).  Measuring an adhesion rig's
traction (tread contact, phi of a few hundredths 1/m) is the use it is made
for; spin-dominated contacts are not.  Taking ``s`` from the translation
alone, or fading the factor with spin's share of ``F_lin``, did no better
over those cases.  The pressure as the traction
bound (``bound="given"``: Kalker's parabolic bound has another knee and is
not corrected).  Its use: the friction estimator's measurement model
(:mod:`fastsim_ros.estimation.model`), where the knee's error read as a
friction error was the estimate's largest; the published forces are the
method's own.

Validated off its own nodes: against CONTACT's published exact traction
curve (``examples/tractcurv.ref_out``, an independent solver, a/b 0.5, 24 x
24 cells here) the calibrated MAE is up to 6.5% of ``mu N`` off and 0.7%
with the factor; on a flange-root patch (not an ellipse) 2.3-4.1% and
0.3-0.7%; at a/b 0.6, ``nu`` 0.3 under oblique creepage 1.8-2.2% and
0.1-0.3% (``docs/validation_estimation.md``, ``test/test_contact_knee.py``).

Units: SI (N, m, Pa); ``s`` and ``kappa`` dimensionless.  No ROS, no SciPy.
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

FloatArray = NDArray[np.float64]

KNEE_FILE = "fastsim_knee_factors.csv"
#: the creepage directions tabulated (pure xi, pure eta)
DIRECTIONS = ("xi", "eta")


def linear_force(a: float, b: float, l1: float, l2: float, l3: float, xi: float, eta: float,
                 phi: float) -> tuple[float, float]:
    """Return ``(F_x, F_y)`` (N): Kalker's linear force with the creepages' sign.

    An ellipse of semi-axes ``a`` (along x), ``b`` (m) with Kalker's
    flexibilities ``l1, l2, l3`` (m/Pa, docs/guide_physics.md "FastSim": ``L1 = 8 a / (3 G
    C11)``, ``L2 = 8 a / (3 G C22)``, ``L3 = pi a sqrt(a/b) / (4 G C23)``)
    under ``xi``, ``eta`` (1) at its centre and spin ``phi`` (1/m):
    ``G a b (C11 xi, C22 eta) + G (ab)^1.5 C23 (0, phi)`` (Kalker's
    normalisation), written with the ``L``'s (``G a b C11 = 8 a^2 b / (3
    L1)``: FastSim's strips in adhesion, ``sum 2 a_y^2 xi / L1``; ``G (ab)^1.5
    C23 = pi a^3 b / (4 L3)``).  The creep force is minus this in full
    adhesion.
    """
    k1 = 8.0 * a * a * b / (3.0 * l1)
    k2 = 8.0 * a * a * b / (3.0 * l2)
    k3 = math.pi * a * a * a * b / (4.0 * l3)
    return k1 * xi, k2 * eta + k3 * phi


@dataclass(frozen=True, eq=False)
class KneeFactors:
    """The knee factors at one Poisson ratio (module docstring).

    ``log_aspect``: the nodes' ``log(a/b)``, ``(na,)``; ``s``: the nodes in
    ``s``, ``(ns,)`` from 0; ``kappa``: ``(2, na, ns)``, pure ``xi`` then pure
    ``eta``.
    """

    nu: float
    log_aspect: FloatArray
    s: FloatArray
    kappa: FloatArray

    def factor(self, s: float, aspect: float, share_x: float) -> tuple[float, float]:
        """Return ``(kappa, d kappa / d s)`` at ``s`` (>= 0), ``a/b`` and the share along x.

        ``share_x``: ``F_lin,x^2 / |F_lin|^2`` in ``[0, 1]``
        (:func:`interpolate`, the formula the kernels compile).
        """
        t = math.log(aspect) if aspect > 0.0 else -math.inf
        k, dk = interpolate(self.log_aspect, self.s, self.kappa, float(s), t, float(share_x))
        return float(k), float(dk)


def interpolate(log_aspect: FloatArray, s_nodes: FloatArray, kappa: FloatArray, s: float,
                t: float, share_x: float) -> tuple[float, float]:
    """Return ``(kappa, d kappa / d s)`` from the table at ``s``, ``t = log(a/b)``, ``share_x``.

    Linear in ``t`` (the nearest edge outside the nodes), the two directions
    weighed by ``share_x`` and ``1 - share_x``; in ``s`` a cubic Hermite
    between the nodes with the three-point slopes (so ``d kappa / d s``,
    the filter's slope, has no jump at a node), the last node's slope the
    tail's; beyond the last node ``kappa - 1`` falls as ``1/s^3`` (FastSim's
    leading-edge adhesion band is ``d ~ 1/s^2`` long and holds a deficit ``~
    d^1.5``).  Plain arithmetic on the arrays: compiled by
    :mod:`~fastsim_ros.contact.kernels` as it is (one formula for both paths).
    """
    na = log_aspect.shape[0]
    if not t > log_aspect[0]:
        ia, wa = 0, 0.0
    elif not t < log_aspect[na - 1]:
        ia, wa = na - 2, 1.0
    else:
        ia = 0  # log_aspect[ia] <= t < log_aspect[ia + 1] (nine nodes: a scan)
        while log_aspect[ia + 1] <= t:
            ia += 1
        wa = (t - log_aspect[ia]) / (log_aspect[ia + 1] - log_aspect[ia])
    ns = s_nodes.shape[0]
    last = s_nodes[ns - 1]
    i = ns - 1
    if s < last:
        i = 0  # s_nodes[i] <= s < s_nodes[i + 1] (a scan of a few dozen nodes)
        while s_nodes[i + 1] <= s:
            i += 1
    # the table's values (both directions and a/b weighed) at nodes i - 1 .. i + 2
    v0 = v1 = v2 = v3 = 0.0
    for q in range(4):
        j = min(max(i - 1 + q, 0), ns - 1)
        v = 0.0
        for d in range(2):
            wd = share_x if d == 0 else 1.0 - share_x
            v += wd * ((1.0 - wa) * kappa[d, ia, j] + wa * kappa[d, ia + 1, j])
        if q == 0:
            v0 = v
        elif q == 1:
            v1 = v
        elif q == 2:
            v2 = v
        else:
            v3 = v
    if i == ns - 1:
        tail = (last / s) ** 3
        return 1.0 + (v1 - 1.0) * tail, -3.0 * (v1 - 1.0) * tail / s
    h = s_nodes[i + 1] - s_nodes[i]
    secant = (v2 - v1) / h
    # the slopes at the segment's ends: three-point (non-uniform spacing), one-sided at s = 0,
    # the tail's at the last node
    if i == 0:
        m1 = secant
    else:
        hp = s_nodes[i] - s_nodes[i - 1]
        m1 = (hp * secant + h * (v1 - v0) / hp) / (hp + h)
    if i + 1 == ns - 1:
        m2 = -3.0 * (v2 - 1.0) / last
    else:
        hn = s_nodes[i + 2] - s_nodes[i + 1]
        m2 = (hn * secant + h * (v3 - v2) / hn) / (h + hn)
    u = (s - s_nodes[i]) / h
    u2 = u * u
    u3 = u2 * u
    k = ((2.0 * u3 - 3.0 * u2 + 1.0) * v1 + (u3 - 2.0 * u2 + u) * h * m1
         + (3.0 * u2 - 2.0 * u3) * v2 + (u3 - u2) * h * m2)
    dk = ((6.0 * u2 - 6.0 * u) * (v1 - v2) / h + (3.0 * u2 - 4.0 * u + 1.0) * m1
          + (3.0 * u2 - 2.0 * u) * m2)
    return k, dk


def knee_pack(factors: KneeFactors) -> FloatArray:
    """Return the table as one array for the kernels: ``na, ns``, the nodes, then ``kappa``.

    ``[na, ns, log_aspect (na), s (ns), kappa (2 * na * ns, C order)]``
    (:func:`fastsim_ros.contact.kernels.knee_arrays` unpacks it).
    """
    na = factors.log_aspect.shape[0]
    ns = factors.s.shape[0]
    return np.concatenate([np.array([na, ns], dtype=np.float64), factors.log_aspect,
                           factors.s, np.ascontiguousarray(factors.kappa).ravel()])


def _read() -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Return the file's nodes ``nu``, ``a/b``, ``s`` and ``kappa[nu, dir, a/b, s]``."""
    try:
        text = resources.files("fastsim_ros.data").joinpath(KNEE_FILE).read_text("utf-8")
    except (OSError, ModuleNotFoundError) as exc:
        raise DataError(f"cannot read the knee factors {KNEE_FILE}: {exc}") from exc
    rows = [r for r in csv.DictReader(io.StringIO(
        "\n".join(line for line in text.splitlines() if not line.startswith("#"))))]
    try:
        nus = sorted({float(r["nu"]) for r in rows})
        aspects = sorted({float(r["a_over_b"]) for r in rows})
        ss = sorted({float(r["s"]) for r in rows})
        kappa = np.full((len(nus), 2, len(aspects), len(ss)), np.nan)
        for r in rows:
            kappa[nus.index(float(r["nu"])), DIRECTIONS.index(r["direction"]),
                  aspects.index(float(r["a_over_b"])), ss.index(float(r["s"]))] = \
                float(r["kappa"])
    except (KeyError, ValueError) as exc:
        raise DataError(f"malformed knee factors {KNEE_FILE}: {exc}") from exc
    if not np.all(np.isfinite(kappa)) or len(nus) != 3 or ss[0] != 0.0:
        raise DataError(f"incomplete knee factors {KNEE_FILE}: every (nu, direction, a/b, s) "
                        "of three nu values, s from 0")
    return np.array(nus), np.array(aspects), np.array(ss), kappa


@lru_cache(maxsize=8)
def knee_factors(nu: float) -> KneeFactors:
    """Return the knee factors at Poisson ratio ``nu`` (the tables' ``0 <= nu <= 0.5``)."""
    nus, aspects, ss, kappa = _read()
    nu = float(nu)
    if not (nus[0] <= nu <= nus[-1]):
        raise OutOfTableError(f"nu = {nu} outside the knee factors' {nus[0]:g} .. {nus[-1]:g}")
    # the quadratic through the three tabulated nu (Lagrange)
    n0, n1, n2 = nus
    w = np.array([(nu - n1) * (nu - n2) / ((n0 - n1) * (n0 - n2)),
                  (nu - n0) * (nu - n2) / ((n1 - n0) * (n1 - n2)),
                  (nu - n0) * (nu - n1) / ((n2 - n0) * (n2 - n1))])
    at_nu = np.tensordot(w, kappa, axes=1)
    at_nu.setflags(write=False)
    log_aspect = np.log(aspects)
    log_aspect.setflags(write=False)
    ss.setflags(write=False)
    return KneeFactors(nu, log_aspect, ss, at_nu)
