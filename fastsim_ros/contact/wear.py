"""Wear and fatigue indicators of a solve: T-gamma, frictional power, wear rate, RCF damage.

Pure physics (no ROS).  SI units: N, m, Pa, W; creepages ``xi``, ``eta``
(1) and spin ``phi`` (1/m) about the point ``Mz`` is taken about (docs/guide_physics.md,
conventions: ``Fx``, ``Fy``, ``Mz`` are the rail's on the wheel, so they
oppose the creepages and ``Fx xi + Fy eta + Mz phi <= 0``).

- **T-gamma** (N = J per metre rolled): ``T_gamma = |Fx xi + Fy eta + Mz phi|``,
  the vehicle-dynamics energy index (the power the creep forces absorb,
  ``-V (Fx xi + Fy eta + Mz phi)``, per unit rolling speed: the work per
  metre rolled, since ``int -tau . w dA = -(Fx xi + Fy eta + Mz phi)`` for
  the rigid slip ``w = (xi - phi y, eta + phi x)``).
- **T-gamma / A** (Pa = N/m^2): per unit contact area ``A`` (the cells in
  contact times the cell area), the wear function's argument.
- **Frictional dissipation** (N per metre rolled; times ``|V|``: the
  frictional power, W): ``sum -tau . s dA`` over the slip area, ``s`` the
  slip per unit rolling distance, as CONTACT's ``FRIC.POWER`` (Vollebregt &
  Kalker, CONTACT user guide; CONTACT prints it with the traction on the
  upper body, so negative).  In the exact theory it is less than
  ``T_gamma``: ``T_gamma V`` also holds the work of the stick zone's
  elastic creep (``-tau . w`` where ``s = 0``), which the elastic field
  carries out of the patch at its trailing edge instead of dissipating by
  slip; the share is ~0 in near-full adhesion and tends to 1 at full slip.  From the exact solver:
  :func:`fastsim_ros.contact.exact.slip_dissipation` (``s = w - du/dx``,
  the solver's own discrete operator); from FastSim's march:
  :mod:`~fastsim_ros.contact.slip_power` (whose spin flexibility can put it
  above ``T_gamma`` under spin).
- **Wear rate**: a piecewise-linear function of ``T_gamma / A``
  (:class:`PiecewiseLinear`); default :data:`SHEFFIELD_WEAR`, the University
  of Sheffield (USFD) wear function for R8T wheel / R260 rail steel from
  twin-disc tests (Lewis & Olofsson, "Mapping rail wear regimes and
  transitions", Wear 257 (2004) 721-729; Lewis, Dwyer-Joyce et al.,
  "Mapping railway wheel material wear mechanisms and transitions", Proc.
  IMechE F 224 (2010) 125-137; as used by Braghin, Lewis, Dwyer-Joyce &
  Bruni, "A mathematical model to predict railway wheel profile evolution
  due to wear", Wear 261 (2006) 1253-1264): ``K = 5.3`` ug/(m mm^2) for
  ``T_gamma/A < 10.4`` N/mm^2 (mild), ``55.0`` for ``10.4 <= T_gamma/A <= 77.2``
  (severe), ``61.9 T_gamma/A - 4778.7`` above (catastrophic); mass lost per
  metre rolled per unit contact area.  Here in SI: 1 ug/(m mm^2) = 1e-3
  kg/(m m^2), 1 N/mm^2 = 1e6 Pa.  As published, the catastrophic line is
  zero at 77.2 N/mm^2 (61.9 x 77.2 - 4778.7 = -0.02): just above that
  boundary it gives less than the severe regime, and exceeds it above 78.1
  N/mm^2; the table keeps the published function (its zero at
  4778.7/61.9 N/mm^2) and holds its value beyond 1000 N/mm^2.
- **RCF damage index** (damage per wheel passage, crack initiation at an
  accumulated 1): a piecewise-linear function of ``T_gamma``; default
  :data:`BURSTOW_RCF`, Burstow's whole-life rail model (Burstow,
  "A whole life rail model application and development for RSSB -
  continued development of an RCF damage parameter", AEA Technology
  report AEATR-ES-2004-880, RSSB, 2004): no damage below 15 N, ``(T_gamma -
  15) 1e-6`` up to the peak ``5e-5`` at 65 N, falling linearly to zero at
  175 N, beyond which wear removes the initiating cracks.

A table is two sequences: breakpoints ``x`` (non-decreasing; a value
repeated once is a jump, right-continuous: the value at it is the later
one's) and values ``y`` (non-negative), linear between the breakpoints and
held constant beyond the first and last.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass

from fastsim_ros.contact.errors import InvalidInputError


@dataclass(frozen=True)
class PiecewiseLinear:
    """A checked piecewise-linear table ``y(x)`` (see the module's rules); call it with ``x``.

    Raises :class:`~fastsim_ros.contact.errors.InvalidInputError` naming
    what is wrong: fewer than two breakpoints, lengths that differ, a value
    not finite, ``x`` decreasing or repeated more than once, ``y`` negative.
    """

    x: tuple[float, ...]
    y: tuple[float, ...]

    def __post_init__(self) -> None:
        x, y = self.x, self.y
        if len(x) != len(y):
            raise InvalidInputError(f"a table needs as many values as breakpoints, got {len(x)} "
                                    f"breakpoints and {len(y)} values")
        if len(x) < 2:
            raise InvalidInputError(f"a table needs at least 2 breakpoints, got {len(x)}")
        for name, seq in (("breakpoint", x), ("value", y)):
            for k, v in enumerate(seq):
                if not math.isfinite(v):
                    raise InvalidInputError(f"table {name} {k} is not finite: {v}")
        for k in range(1, len(x)):
            if x[k] < x[k - 1]:
                raise InvalidInputError(f"table breakpoints must not decrease: {x[k]:g} after "
                                        f"{x[k - 1]:g}")
            if k >= 2 and x[k] == x[k - 1] == x[k - 2]:
                raise InvalidInputError(f"table breakpoint {x[k]:g} appears more than twice "
                                        "(twice is a jump)")
        if x[0] == x[1] or x[-1] == x[-2]:
            raise InvalidInputError("a table cannot start or end with a jump")
        for k, v in enumerate(y):
            if v < 0.0:
                raise InvalidInputError(f"table value {k} is negative: {v:g}")

    @classmethod
    def of(cls, x: Sequence[float], y: Sequence[float]) -> PiecewiseLinear:
        """Return the table of breakpoints ``x`` and values ``y`` (checked)."""
        return cls(tuple(float(v) for v in x), tuple(float(v) for v in y))

    def __call__(self, v: float) -> float:
        """Return the table's value at ``v`` (NaN for NaN)."""
        if math.isnan(v):
            return math.nan
        x, y = self.x, self.y
        k = bisect_right(x, v) - 1  # the last breakpoint at or before v (a jump's second)
        if k < 0:
            return y[0]
        if k >= len(x) - 1:
            return y[-1]
        t = (v - x[k]) / (x[k + 1] - x[k])
        return y[k] + t * (y[k + 1] - y[k])


#: 1 ug/(m mm^2) in kg/(m m^2) and 1 N/mm^2 in Pa: the published wear tables' units in SI
UG_PER_M_MM2, N_PER_MM2 = 1e-3, 1e6
#: the USFD wear function (R8T/R260): T_gamma/A (Pa) -> wear rate (kg per metre rolled per
#: m^2), in SI: 5.3 and 55.0 ug/(m mm^2), the catastrophic line 61.9 T_gamma/A - 4778.7 from
#: its zero (4778.7/61.9 N/mm^2) to 1000 N/mm^2 (57121.3 ug/(m mm^2)), held beyond
SHEFFIELD_WEAR = PiecewiseLinear.of(
    (0.0, 10.4e6, 10.4e6, 77.2e6, 4778.7e6 / 61.9, 1000e6),
    (5.3e-3, 5.3e-3, 55.0e-3, 55.0e-3, 0.0, 57.1213))
#: Burstow's whole-life rail model: T_gamma (N) -> RCF damage per wheel passage
BURSTOW_RCF = PiecewiseLinear.of((0.0, 15.0, 65.0, 175.0), (0.0, 0.0, 50e-6, 0.0))


def t_gamma(fx: float, fy: float, mz: float, xi: float, eta: float, phi: float) -> float:
    """Return ``T_gamma = |Fx xi + Fy eta + Mz phi|`` (N = J per metre rolled)."""
    return abs(fx * xi + fy * eta + mz * phi)


@dataclass(frozen=True, slots=True)
class WearIndicators:
    """One solve's wear and fatigue indicators.

    ``t_gamma`` (N), ``t_gamma_per_area`` (Pa), ``wear_rate`` (kg per metre
    rolled per m^2 of contact: the wear function at ``t_gamma_per_area``),
    ``rcf_damage`` (per wheel passage: the RCF function at ``t_gamma``),
    ``frictional_power`` (W: the slip area's dissipation times ``|V|``, NaN
    where not computed) and ``slip_share`` (that over ``T_gamma |V|``, NaN
    where not computed or ``T_gamma`` is zero).
    """

    t_gamma: float
    t_gamma_per_area: float
    wear_rate: float
    rcf_damage: float
    frictional_power: float
    slip_share: float


def indicators(fx: float, fy: float, mz: float, xi: float, eta: float, phi: float,
               area: float, speed: float, dissipation: float = math.nan, *,
               wear: PiecewiseLinear = SHEFFIELD_WEAR,
               rcf: PiecewiseLinear = BURSTOW_RCF) -> WearIndicators:
    """Return the indicators of one solve: forces (N, N m), creepages (1, 1/m), ``A`` (m^2).

    ``speed``: the rolling speed (m/s; its magnitude is used);
    ``dissipation``: the slip area's dissipation per metre rolled (N), NaN
    if not computed.  A contact without area (``A = 0``) has ``T_gamma/A = 0``.
    """
    tg = t_gamma(fx, fy, mz, xi, eta, phi)
    per_area = tg / area if area > 0.0 else 0.0
    v = abs(speed)
    power = dissipation * v
    share = dissipation / tg if tg > 0.0 else math.nan
    return WearIndicators(tg, per_area, wear(per_area), rcf(tg), power, share)
