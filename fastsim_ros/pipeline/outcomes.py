"""What the pipelines give: outcomes of a patch, wheelset wrenches, friction estimates, counts.

Frozen, slotted dataclasses the front ends read (and the replay records);
:func:`fast_builder` makes the constructors the compiled path uses, which set
each slot directly (:data:`new_frame`, :data:`new_patch`, ...: half the
dataclasses' own ``__init__`` time, for the five results built per patch).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import MISSING, dataclass, field, fields
from typing import Any

import numpy as np

from fastsim_ros.contact.compiled import ContactForces
from msg_adapters.errors import REJECTION_REASONS
from msg_adapters.kinematics import Creepage
from msg_adapters.patch import ContactFrame, ContactPatch

#: solve times kept per contact for the percentiles of the diagnostics
SOLVE_TIME_WINDOW = 1000
SOLVED, NO_CONTACT = "solved", "no_contact"
#: a patch solved already: as converted, its creepages, forces and solve time (s)
Solved = tuple[ContactPatch, Creepage, ContactForces, float]


@dataclass(frozen=True, slots=True)
class WheelsetWrench:
    """Sum of the contacts' wrenches in the wheelset frame about its origin (N, N m)."""

    stamp_ns: int
    force: tuple[float, float, float]
    torque: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class FrictionEstimate:
    """The friction estimate after a rig cycle (``friction/estimate``).

    ``mu``: the estimated static coefficient ``mu_s`` (what the next cycle's
    wrenches use); ``sigma``: its standard deviation; ``utilisation``: the
    cycle's creep forces over the friction available, ``sum |(Fx, Fy)| /
    (mu sum N)`` at the mu they were solved with; ``status``: ``updated``,
    ``unobservable`` (the linear range, or no contact: held, sigma grown),
    ``implausible`` (the measured creep force beyond the friction any rail
    gives the cycle's load: held,
    :data:`~fastsim_ros.estimation.cycle.IMPLAUSIBLE_FORCE`) or
    ``no_measurement`` (no fresh ``wheelset/measured_wrench``: held).
    With the slope reduction estimated (``friction_estimate_slope_reduction``):
    ``k0`` its estimate, ``sigma_k0`` its standard deviation, ``correlation``
    that of the two estimates' errors (else NaN).
    """

    stamp_ns: int
    mu: float
    sigma: float
    utilisation: float
    status: str
    k0: float = math.nan
    sigma_k0: float = math.nan
    correlation: float = math.nan


@dataclass(frozen=True, slots=True, eq=False)
class Outcome:
    """What one patch gave.

    ``status``: ``"solved"``, ``"no_contact"`` (zero wrench) or a rejection
    reason of :data:`~msg_adapters.errors.REJECTION_REASONS` (no wrench);
    ``detail``: words for the log.  When solved: the contact ``frame`` (and
    whether it moved since it was last published), ``creepage``, ``forces``
    (``fx, fy`` (N), ``mz`` (N m) about the contact origin, ``n`` (N)) and
    the ``patch``.  ``wheelset``: the wheelset wrench when this patch
    completed a rig cycle; ``markers``: whether markers are due;
    ``friction``: the friction estimate after that cycle (estimation on).
    """

    contact: str
    stamp_ns: int
    status: str
    detail: str = ""
    frame: ContactFrame | None = None
    frame_changed: bool = False
    creepage: Creepage | None = None
    forces: ContactForces | None = None
    patch: ContactPatch | None = None
    wheelset: WheelsetWrench | None = None
    markers: bool = False
    friction: FrictionEstimate | None = None

    @property
    def has_wrench(self) -> bool:
        """Return whether a wrench is published for this patch (solved or no contact)."""
        return self.status in (SOLVED, NO_CONTACT)


#: the diagnostics key that names the keys counting since the start (a managed node: since
#: its last configure), beside this_period/* and the status message (the last period)
SINCE_START_KEY = "since_start"
SINCE_START = "wrenches, solved, no_contact, rejected, rejected/*, twists/*, dropped/inactive"


@dataclass
class ContactStats:
    """Counters and solve times of one contact (cumulative since start)."""

    counts: dict[str, int] = field(default_factory=lambda: {
        key: 0 for key in (SOLVED, NO_CONTACT) + REJECTION_REASONS})
    solve_times: np.ndarray = field(default_factory=lambda: np.zeros(SOLVE_TIME_WINDOW))
    solves: int = 0
    window_inputs: int = 0
    window_rejected: int = 0
    window_first_ns: int | None = None
    window_last_ns: int | None = None
    last_detail: str = ""

    def add_solve_time(self, seconds: float) -> None:
        """Record one solve's wall time (s)."""
        self.solve_times[self.solves % SOLVE_TIME_WINDOW] = seconds
        self.solves += 1

    def percentiles_us(self) -> tuple[float, float]:
        """Return the p50 and p99 of the recent solve times (us); NaN before any."""
        filled = self.solve_times[:min(self.solves, SOLVE_TIME_WINDOW)]
        if filled.size == 0:
            return math.nan, math.nan
        p50, p99 = np.percentile(filled, (50.0, 99.0))
        return float(p50) * 1e6, float(p99) * 1e6


@dataclass(frozen=True)
class ContactReport:
    """One contact's diagnostics: level (0 OK, 1 WARN, 2 ERROR), message, key-values."""

    name: str
    level: int
    message: str
    values: tuple[tuple[str, str], ...]


def fast_builder(cls: type) -> Callable[..., Any]:
    """Return a constructor of a frozen, slotted dataclass taking every field in order.

    The dataclass's own ``__init__`` sets each field through
    ``object.__setattr__`` (what ``frozen`` costs); this one calls each slot's
    setter directly: half the time, for the five results built per patch on
    the compiled path.  Plain defaults (no factories), no ``__post_init__``
    (none of them has one); the instance equals the ``__init__``'s (test_pipeline_kernels.py).
    """
    names = [f.name for f in fields(cls)]
    assert list(getattr(cls, "__slots__")) == names and not hasattr(cls, "__post_init__")
    # a field with a plain default may be left out (Outcome.friction: only when estimating)
    defaults = {f.name: f.default for f in fields(cls) if f.default is not MISSING}
    args = ", ".join(f"{n}=default_{n}" if n in defaults else n for n in names)
    body = "".join(f"    set_{n}(o, {n})\n" for n in names)
    scope: dict[str, Any] = {"new": object.__new__, "cls": cls}
    scope.update({f"default_{n}": v for n, v in defaults.items()})
    scope.update({f"set_{n}": getattr(cls, n).__set__ for n in names})
    exec(f"def build({args}):\n    o = new(cls)\n{body}    return o\n", scope)
    build: Callable[..., Any] = scope["build"]
    return build


new_frame = fast_builder(ContactFrame)
new_patch = fast_builder(ContactPatch)
new_creepage = fast_builder(Creepage)
new_forces = fast_builder(ContactForces)
new_outcome = fast_builder(Outcome)
new_estimate = fast_builder(FrictionEstimate)
