"""Per-wrench records: the CSV rows and the plot's samples (bounded memory).

The CSV (``--csv``): one row per wrench, header :data:`CSV_HEADER`, floats
in Python's shortest round-trip form; a ``no_contact`` row (an empty patch,
zero wrench) has ``N, Fx, Fy, Mz`` = 0 and ``xi, eta, phi, V,
slip_fraction`` blank (undefined: no contact).
"""

from __future__ import annotations

import math
from array import array
from typing import Any

from fastsim_ros.pipeline import Outcome

CSV_HEADER = ("stamp_ns", "contact", "xi", "eta", "phi", "V", "N", "Fx", "Fy", "Mz",
              "slip_fraction", "method", "friction_law")
#: points kept per contact for the plot (decimated by 2 each time it fills)
PLOT_POINTS = 100_000


class Series:
    """Per-contact samples for the plot, decimated by 2 whenever full (bounded memory)."""

    __slots__ = ("stride", "seen", "cols")

    def __init__(self) -> None:
        self.stride = 1
        self.seen = 0
        self.cols: tuple[array, ...] = tuple(array("d") for _ in range(7))

    def add(self, *values: float) -> None:
        """Add ``t, xi, eta, phi, Fx, Fy, N``."""
        self.seen += 1
        if (self.seen - 1) % self.stride:
            return
        for col, v in zip(self.cols, values):
            col.append(v)
        if len(self.cols[0]) >= PLOT_POINTS:
            self.cols = tuple(array("d", col[::2]) for col in self.cols)
            self.stride *= 2


def record(outcome: Outcome, t_ns: int, rows: Any, series: Series | None, method: str,
           law: str) -> None:
    """Add a wrench's CSV row (when ``rows`` is a csv writer) and plot sample (to ``series``)."""
    f, cr = outcome.forces, outcome.creepage
    if f is None or cr is None:  # no contact: a zero wrench, creepages undefined
        if rows is not None:
            rows.writerow((outcome.stamp_ns, outcome.contact, "", "", "", "", 0.0, 0.0, 0.0,
                           0.0, "", method, law))
        if series is not None:
            series.add(t_ns * 1e-9, math.nan, math.nan, math.nan, 0.0, 0.0, 0.0)
        return
    if rows is not None:
        rows.writerow((outcome.stamp_ns, outcome.contact, cr.xi, cr.eta, cr.phi, cr.speed,
                       f.n, f.fx, f.fy, f.mz, f.slip_fraction, method, law))
    if series is not None:
        series.add(t_ns * 1e-9, cr.xi, cr.eta, cr.phi, f.fx, f.fy, f.n)
