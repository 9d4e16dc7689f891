"""Per-wrench and per-estimate records: the CSV rows and the plot's samples (bounded memory).

The CSV (``--csv``): one row per wrench, header :data:`CSV_HEADER`, floats
in Python's shortest round-trip form; a ``no_contact`` row (an empty patch,
zero wrench) has ``N, Fx, Fy, Mz`` = 0 and ``xi, eta, phi, V,
slip_fraction`` blank (undefined: no contact).

With ``wear_outputs`` on, each row also has :data:`WEAR_COLUMNS`: the
``contact/<name>/energy`` and ``damage`` messages' values (``T_gamma``
N, ``T_gamma_per_area`` Pa, ``frictional_power`` W (NaN where not
computed), ``wear_rate`` kg/(m m^2), ``rcf_damage`` per passage,
``slip_share``); a ``no_contact`` row has them 0 (the share blank).

The friction CSV (``--csv`` with ``friction_estimation: on``): one row per
``friction/estimate`` message, header :data:`FRICTION_CSV_HEADER`: the
estimate's stamp (the rig cycle's: the newest of its wrenches), ``mu`` (the
estimated static coefficient ``mu_s``, what the next cycle's wrenches use),
``sigma`` (its standard deviation), ``utilisation`` (the wheelset's: the
cycle's creep forces over the friction available, ``sum |(Fx, Fy)| / (mu
sum N)`` over the contacts, at the ``mu`` they were solved with: the
previous row's ``mu``, the ``friction_coefficient`` before the first) and
``status`` (``updated``, ``unobservable``, ``implausible`` or
``no_measurement``): the message's ``x``, ``y``, ``z`` and the status the
message does not carry.
"""

from __future__ import annotations

import math
from array import array
from typing import Any

from collections.abc import Callable
from dataclasses import dataclass

from fastsim_ros.contact.wear import WearIndicators
from fastsim_ros.pipeline import FrictionEstimate, Outcome

CSV_HEADER = ("stamp_ns", "contact", "xi", "eta", "phi", "V", "N", "Fx", "Fy", "Mz",
              "slip_fraction", "method", "friction_law")
#: the CSV's columns of the wear and fatigue indicators (wear_outputs on)
WEAR_COLUMNS = ("T_gamma", "T_gamma_per_area", "frictional_power", "wear_rate", "rcf_damage",
                "slip_share")
FRICTION_CSV_HEADER = ("stamp_ns", "mu", "sigma", "utilisation", "status")
#: points kept per series for the plot (decimated by 2 each time it fills)
PLOT_POINTS = 100_000
#: a contact's plot samples: t (s), xi, eta, phi, Fx, Fy, N and the mu_s in force
WRENCH_COLUMNS = 8
#: the estimate's plot samples: t (s), mu_s, sigma, utilisation
ESTIMATE_COLUMNS = 4


class Series:
    """Samples for the plot, ``columns`` values each, decimated by 2 whenever full."""

    __slots__ = ("stride", "seen", "cols")

    def __init__(self, columns: int = WRENCH_COLUMNS) -> None:
        self.stride = 1
        self.seen = 0
        self.cols: tuple[array, ...] = tuple(array("d") for _ in range(columns))

    def add(self, *values: float) -> None:
        """Add one sample (a contact's: ``t, xi, eta, phi, Fx, Fy, N, mu``)."""
        self.seen += 1
        if (self.seen - 1) % self.stride:
            return
        for col, v in zip(self.cols, values):
            col.append(v)
        if len(self.cols[0]) >= PLOT_POINTS:
            self.cols = tuple(array("d", col[::2]) for col in self.cols)
            self.stride *= 2


@dataclass
class WearSummary:
    """A contact's wear and fatigue indicators over a replay (the summary's line).

    Sums and largest values over its solved patches (``solves``);
    ``powered``: those with a frictional power (``frictional_power`` or
    ``publish_traction`` on, steady rolling).
    """

    solves: int = 0
    t_gamma: float = 0.0
    t_gamma_max: float = 0.0
    wear_rate: float = 0.0
    wear_rate_max: float = 0.0
    rcf_damage: float = 0.0
    rcf_damage_max: float = 0.0
    powered: int = 0
    power: float = 0.0
    slip_share: float = 0.0

    def add(self, w: WearIndicators) -> None:
        """Add one solve's indicators."""
        self.solves += 1
        self.t_gamma += w.t_gamma
        self.t_gamma_max = max(self.t_gamma_max, w.t_gamma)
        self.wear_rate += w.wear_rate
        self.wear_rate_max = max(self.wear_rate_max, w.wear_rate)
        self.rcf_damage += w.rcf_damage
        self.rcf_damage_max = max(self.rcf_damage_max, w.rcf_damage)
        if math.isfinite(w.frictional_power):
            self.powered += 1
            self.power += w.frictional_power
            if math.isfinite(w.slip_share):
                self.slip_share += w.slip_share

    def line(self, contact: str) -> str:
        """Return the summary's line of the contact."""
        n = max(self.solves, 1)
        text = (f"  {contact} wear: T-gamma mean {self.t_gamma / n:.4g} N, max "
                f"{self.t_gamma_max:.4g} N; wear rate mean {self.wear_rate / n:.4g}, max "
                f"{self.wear_rate_max:.4g} kg/(m m^2); RCF damage mean "
                f"{self.rcf_damage / n:.4g}, max {self.rcf_damage_max:.4g} per passage")
        if self.powered:
            text += (f"; frictional power mean {self.power / self.powered:.4g} W "
                     f"({self.slip_share / self.powered:.3g} of T-gamma V)")
        else:
            text += "; frictional power not computed (parameter frictional_power)"
        return text


def record(outcome: Outcome, t_ns: int, rows: Any, series: Series | None, method: str,
           law: str, mu: float,
           wear: Callable[[Outcome], WearIndicators | None] | None = None,
           summary: dict[str, WearSummary] | None = None) -> None:
    """Add a wrench's CSV row (when ``rows`` is a csv writer) and plot sample (to ``series``).

    ``mu``: the static coefficient the wrench was solved with (the plot's bound);
    ``wear``: the pipeline's indicators of an outcome (wear_outputs on: the
    row gets :data:`WEAR_COLUMNS`, and ``summary`` the contact's solve).
    """
    f, cr = outcome.forces, outcome.creepage
    if f is None or cr is None:  # no contact: a zero wrench, creepages undefined
        if rows is not None:
            rows.writerow((outcome.stamp_ns, outcome.contact, "", "", "", "", 0.0, 0.0, 0.0,
                           0.0, "", method, law) + ((0.0, 0.0, 0.0, 0.0, 0.0, "")
                                                    if wear is not None else ()))
        if series is not None:
            series.add(t_ns * 1e-9, math.nan, math.nan, math.nan, 0.0, 0.0, 0.0, mu)
        return
    extra: tuple[Any, ...] = ()
    if wear is not None:
        w = wear(outcome)
        if w is not None:
            extra = (w.t_gamma, w.t_gamma_per_area, w.frictional_power, w.wear_rate,
                     w.rcf_damage, w.slip_share)
            if summary is not None:
                summary.setdefault(outcome.contact, WearSummary()).add(w)
    if rows is not None:
        rows.writerow((outcome.stamp_ns, outcome.contact, cr.xi, cr.eta, cr.phi, cr.speed,
                       f.n, f.fx, f.fy, f.mz, f.slip_fraction, method, law) + extra)
    if series is not None:
        series.add(t_ns * 1e-9, cr.xi, cr.eta, cr.phi, f.fx, f.fy, f.n, mu)


def friction_row(estimate: FrictionEstimate) -> tuple[Any, ...]:
    """Return the friction CSV's row of one estimate (:data:`FRICTION_CSV_HEADER`)."""
    return (estimate.stamp_ns, estimate.mu, estimate.sigma, estimate.utilisation,
            estimate.status)
