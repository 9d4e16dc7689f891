"""Per-wrench and per-estimate records: the CSV rows and the plot's samples (bounded memory).

The CSV (``--csv``): one row per wrench, header :data:`CSV_HEADER`, floats
in Python's shortest round-trip form; a ``no_contact`` row (an empty patch,
zero wrench) has ``N, Fx, Fy, Mz`` = 0 and ``xi, eta, phi, V,
slip_fraction`` blank (undefined: no contact).

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

from fastsim_ros.pipeline import FrictionEstimate, Outcome

CSV_HEADER = ("stamp_ns", "contact", "xi", "eta", "phi", "V", "N", "Fx", "Fy", "Mz",
              "slip_fraction", "method", "friction_law")
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


def record(outcome: Outcome, t_ns: int, rows: Any, series: Series | None, method: str,
           law: str, mu: float) -> None:
    """Add a wrench's CSV row (when ``rows`` is a csv writer) and plot sample (to ``series``).

    ``mu``: the static coefficient the wrench was solved with (the plot's bound).
    """
    f, cr = outcome.forces, outcome.creepage
    if f is None or cr is None:  # no contact: a zero wrench, creepages undefined
        if rows is not None:
            rows.writerow((outcome.stamp_ns, outcome.contact, "", "", "", "", 0.0, 0.0, 0.0,
                           0.0, "", method, law))
        if series is not None:
            series.add(t_ns * 1e-9, math.nan, math.nan, math.nan, 0.0, 0.0, 0.0, mu)
        return
    if rows is not None:
        rows.writerow((outcome.stamp_ns, outcome.contact, cr.xi, cr.eta, cr.phi, cr.speed,
                       f.n, f.fx, f.fy, f.mz, f.slip_fraction, method, law))
    if series is not None:
        series.add(t_ns * 1e-9, cr.xi, cr.eta, cr.phi, f.fx, f.fy, f.n, mu)


def friction_row(estimate: FrictionEstimate) -> tuple[Any, ...]:
    """Return the friction CSV's row of one estimate (:data:`FRICTION_CSV_HEADER`)."""
    return (estimate.stamp_ns, estimate.mu, estimate.sigma, estimate.utilisation,
            estimate.status)
