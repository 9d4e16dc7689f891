"""The batched replay: the pipeline's rules applied to a run of messages at once.

For a run of a bag's messages (a window of them, which the replay takes
at once) the pipeline's per-message rules
(:meth:`fastsim_ros.pipeline.Pipeline.on_patch`, ``on_wheel_twist``,
``on_rail_twist``) are applied in bulk:

1. twists decoded together (those of the usual layout read straight from the
   chunks; any other through :func:`msg_adapters.cdr.read_twist`) and taken
   or dropped with the pipeline's reasons (frame, finite, not older than the
   last taken: the running maximum of the stamps before);
2. patches decoded together: each patch topic's layout is read once from a
   message (:func:`msg_adapters.cdr.read_cloud`); the messages with that
   layout (the same bytes but for the stamp, the CDR padding and the points)
   go through the node's own compiled scan and grid fit
   (:func:`~fastsim_ros.replay.kernels.scan_patches` calls
   :mod:`msg_adapters.patch_kernels`), the others, and every patch the fast
   checks do not pass, through :func:`msg_adapters.patch.patch_from_cloud`
   one by one, which gives the rejection and its words;
3. ``old_stamp`` per contact, from the running maximum of the stamps before;
4. kinematics by stamp, vectorised: the newest twist taken before the patch
   arrived (at most ``TWIST_HISTORY`` back) whose stamp is not after the
   patch's, and not more than ``max_kinematics_age`` older;
5. creepages (the rigid-body formula of docs/guide_physics.md, term for term as
   :func:`msg_adapters.kinematics.creepages`) and ``standstill``;
6. the solves in one compiled loop over the compiled solver's own per-patch
   solve (:func:`~fastsim_ros.replay.kernels.solve_mae`), patches running
   backwards turned by 180 degrees as the pipeline turns them;
7. the state the pipeline carries from patch to patch (a frame published
   when it moves, the wheelset wrench once per rig cycle, markers at most
   ``marker_rate``) in one compiled pass (:func:`~fastsim_ros.replay.kernels.advance`).

Every number goes through the floating-point operations of the pipeline, in
its order, so the outputs are the per-message path's bit for bit (the tests
compare both paths on every bundled bag).  A run may span several
diagnostics: the verdicts of its twists and patches are kept by the
message's place in the bag and counted up to each diagnostics' place
(:meth:`Batch.store`, which writes the counts, rate windows, last rejection
and solve times of each contact, and the twists' counts, back to the
pipeline), so each diagnostics array, which the pipeline builds itself,
counts what the per-message path had counted by then.  In the diagnostics
each solve's time is its run's mean (the solves run in one compiled loop).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact import kernels as contact_kernels
from fastsim_ros.contact.checks import check_bound
from fastsim_ros.contact.compiled import CalibratedMaeSolver, EquivalentEllipseSolver, MaeSolver
from fastsim_ros.contact.errors import ContactError, OutOfTableError
from fastsim_ros.contact.friction import friction_law
from fastsim_ros.ros import plausibility
from fastsim_ros.ros.params import slope_reduction_of
from fastsim_ros.pipeline import (FRAME_TOLERANCE, NO_CONTACT, SOLVE_TIME_WINDOW, SOLVED,
                                  TWIST_HISTORY, Pipeline, PipelineConfig, patch_extent)
from fastsim_ros.replay import kernels
from fastsim_ros.replay.mcap import Window
from msg_adapters.cdr import read_cloud, read_twist
from msg_adapters.errors import REJECTION_REASONS, MalformedMessageError, RejectedInput
from msg_adapters.kinematics import twist_is_finite
from msg_adapters import patch_kernels as adapter
from msg_adapters.patch import (FLOAT32, FLOAT64, GRID_TOLERANCE, MIN_CELL_SIZE,
                                MIN_CONTACT_CELLS, PATCH_FIELDS, ContactPatch, patch_from_cloud)

Ints = NDArray[np.int64]
Floats = NDArray[np.float64]
Bools = NDArray[np.bool_]

#: status codes: solved, no contact, then each rejection reason
STATUSES = (SOLVED, NO_CONTACT) + REJECTION_REASONS
CODE = {name: k for k, name in enumerate(STATUSES)}
_SOLVED, _EMPTY = CODE[SOLVED], CODE[NO_CONTACT]
_MISSING, _WRONG_FRAME, _OLD = CODE["missing_field"], CODE["wrong_frame"], CODE["old_stamp"]
#: kinds of input the batch takes (anything else: the per-message path)
KINDS = ("wheel_twist", "rail_twist", "patch")
_FIRST = np.iinfo(np.int64).min
#: the pipeline's twist counts (``kinematics_counts``) by code; taken wheel and rail twists
_TWIST_ORDER = ("wheel", "rail", "nonfinite", "wrong_frame", "old_stamp", "malformed")
_TWIST_CODE = {name: k for k, name in enumerate(_TWIST_ORDER)}
_TWIST_COUNTS = ("wheel", "rail")
#: patch layouts kept per topic (a grid that keeps changing shape: the rest one by one)
MAX_LAYOUTS = 64
#: where the adapter loop leaves the contact frame (origin, e_x, e_y, e_z) and the grid fit
#: (x0, dx, worst_x, y0, dy, worst_y)
_FRAME_SLOTS = np.array([b + k for b in (adapter.ORIGIN, adapter.E_X, adapter.E_Y, adapter.E_Z)
                         for k in range(3)])
_FIT_SLOTS = np.array([adapter.X0, adapter.DX, adapter.WORST_X, adapter.Y0, adapter.DY,
                       adapter.WORST_Y])


def supported(pipeline: Pipeline) -> bool:
    """Tell whether the batched path applies (else the per-message path replays the bag).

    Inputs the batch knows (patches and twists: not the profiles mode's),
    no traction clouds (the batched solves keep no tractions), a method it
    knows, steady rolling (transient rolling carries each contact's state
    from one patch to the next: the per-message path), no wear outputs
    (their messages and CSV columns are the per-message path's).
    """
    config = pipeline.config
    return (all(i.kind in KINDS for i in pipeline.inputs())
            and not bool(config["publish_traction"])
            and not bool(config["wear_outputs"])
            and str(config["rolling"]) == "steady"
            and str(config["method"]) in ("mae", "mae_calibrated", "fastsim_ellipse"))


# ------------------------------------------------------------------------ CDR layouts

def _align(pos: int, size: int) -> int:
    return pos + (-(pos - 4)) % size   # CDR aligns relative to the payload, after byte 4


def _u32(raw: bytes, pos: int) -> int:
    return int.from_bytes(raw[pos:pos + 4], "little")


@dataclass(frozen=True)
class Layout:
    """The layout of a topic's messages, read once from one of them.

    A message has it when it is ``length`` bytes long and its first bytes
    equal ``template`` wherever ``mask`` is set (not the stamp, not CDR
    padding).  For patches: the points start at ``data_at``; ``fast``: they
    can be scanned in bulk (little endian, one float type of ``width``
    bytes, word-aligned fields at word offsets ``cols``, a grid of
    ``height`` x ``cells`` within ``max_patch_cells``, enough data; ``row``
    and ``step`` in words); ``empty``: the same but a grid of no cells (an
    empty patch: no contact, nothing to read); otherwise the messages go
    one by one.
    """

    template: NDArray[np.uint8]
    mask: Bools
    length: int
    data_at: int
    fast: bool
    height: int = 0
    cells: int = 0
    width: int = 0
    row: int = 0
    step: int = 0
    cols: Ints = field(default_factory=lambda: np.zeros(7, dtype=np.int64))
    empty: bool = False


def cloud_layout(raw: bytes, frame_id: str, max_cells: int) -> Layout | None:
    """Return the layout of one PointCloud2 message (``None``: it does not parse)."""
    try:
        cloud = read_cloud(raw)
    except MalformedMessageError:
        return None
    if raw[:4] != b"\x00\x01\x00\x00":
        return None
    keep: list[tuple[int, int]] = []
    pos = 12                                    # after the encapsulation and the stamp
    n = _u32(raw, pos)
    keep.append((pos, pos + 4 + n))             # frame id
    pos = _align(pos + 4 + n, 4)
    keep.append((pos, pos + 12))                # height, width, field count
    count = _u32(raw, pos + 8)
    pos += 12
    for _ in range(count):
        n = _u32(raw, pos)
        keep.append((pos, pos + 4 + n))         # name
        pos = _align(pos + 4 + n, 4)
        keep.append((pos, pos + 5))             # offset, datatype
        pos = _align(pos + 5, 4)
        keep.append((pos, pos + 4))             # count
        pos += 4
    keep.append((pos, pos + 1))                 # is_bigendian
    pos = _align(pos + 1, 4)
    keep.append((pos, pos + 12))                # point_step, row_step, data length
    data_at = pos + 12
    if data_at + len(cloud.data) > len(raw):
        return None
    template = np.frombuffer(raw[:data_at], dtype=np.uint8).copy()
    mask = np.zeros(data_at, dtype=np.bool_)
    for a, b in keep:
        mask[a:b] = True
    slow = Layout(template, mask, len(raw), data_at, False)
    ny, nx = cloud.height, cloud.width
    if cloud.frame_id != frame_id or cloud.is_bigendian or not ny * nx <= max_cells:
        return slow
    specs = [cloud.fields.get(name) for name in PATCH_FIELDS]
    if any(s is None or s.datatype not in (FLOAT32, FLOAT64) or s.count != 1
           or s.datatype != specs[0].datatype for s in specs):  # type: ignore[union-attr]
        return slow
    width = 4 if specs[0].datatype == FLOAT32 else 8  # type: ignore[union-attr]
    offsets = [s.offset for s in specs]  # type: ignore[union-attr]
    if (any(o % width or o + width > cloud.point_step for o in offsets)
            or cloud.point_step % width or cloud.row_step % width):
        return slow
    if ny * nx == 0:  # patch_from_cloud checks the fields (passed, above), then: no contact
        return Layout(template, mask, len(raw), data_at, False, empty=True)
    if (cloud.row_step < nx * cloud.point_step
            or len(cloud.data) < (ny - 1) * cloud.row_step + nx * cloud.point_step):
        return slow
    return Layout(template, mask, len(raw), data_at, True, ny, nx, width,
                  cloud.row_step // width, cloud.point_step // width,
                  np.array([o // width for o in offsets], dtype=np.int64))


def twist_layout(frame_id: str) -> tuple[Layout, int]:
    """Return the layout of a little-endian TwistStamped in ``frame_id``, and its doubles' place.

    The six doubles (linear, angular) start at the returned byte.
    """
    name = frame_id.encode("utf-8") + b"\x00"
    head = b"\x00\x01\x00\x00" + bytes(8) + len(name).to_bytes(4, "little") + name
    at = _align(len(head), 8)
    mask = np.zeros(at, dtype=np.bool_)
    mask[:4] = True
    mask[12:len(head)] = True
    return Layout(np.frombuffer(head + bytes(at - len(head)), dtype=np.uint8), mask,
                  at + 48, at, True), at


def _grid_axis(first: Floats, step: Floats, worst: Floats,
               n: int) -> tuple[Floats, Floats, Ints, Bools]:
    """``msg_adapters.patch._grid_axis`` on arrays: ``(first, step, order, refused)``."""
    size = np.abs(step)
    refused = ~(size >= MIN_CELL_SIZE) | ~(worst <= GRID_TOLERANCE * size)
    back = step < 0.0
    return (np.where(back, first + step * (n - 1), first), np.where(back, -step, step),
            np.where(back, -1, 1), refused)


# ------------------------------------------------------------------------ results

@dataclass
class Patches:
    """What a run's patches gave, in arrival order (one row per patch message).

    ``index``: the message's place in its window; ``status``: an index of
    :data:`STATUSES`; ``detail``: the words of each rejection (by row);
    ``frame``: origin, ``e_x``, ``e_y``, ``e_z``; ``creep``: ``xi, eta, phi,
    V``; ``force``: ``Fx, Fy, N, Mz``; ``slip``: the share of cells on the
    traction bound.  From :func:`kernels.advance`: ``changed`` (frame
    published), ``marker``, ``cycle`` with the rig cycle's ``cycle_stamp``
    and ``cycle_wrench`` (force, torque in the wheelset frame).  ``parsed``:
    the message is a PointCloud2 (it has a stamp; it counts in the rate).
    ``solve_time``: the run's mean solve time (s) where the solver ran, NaN
    elsewhere; ``place``: the message's place in the bag (arrival order).
    """

    index: Ints
    contact: Ints
    stamp: Ints
    status: Ints
    detail: dict[int, str]
    frame: Floats
    creep: Floats
    force: Floats
    slip: Floats
    changed: Bools
    marker: Bools
    cycle: Bools
    cycle_stamp: Ints
    cycle_wrench: Floats
    parsed: Bools
    solve_time: Floats = field(default_factory=lambda: np.zeros(0))
    place: Ints = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def rows(self, r0: int, r1: int) -> Patches:
        """Return rows ``r0:r1`` (views of the arrays; the details renumbered)."""
        return Patches(
            self.index[r0:r1], self.contact[r0:r1], self.stamp[r0:r1], self.status[r0:r1],
            {i - r0: d for i, d in self.detail.items() if r0 <= i < r1},
            self.frame[r0:r1], self.creep[r0:r1], self.force[r0:r1], self.slip[r0:r1],
            self.changed[r0:r1], self.marker[r0:r1], self.cycle[r0:r1],
            self.cycle_stamp[r0:r1], self.cycle_wrench[r0:r1], self.parsed[r0:r1],
            self.solve_time[r0:r1], self.place[r0:r1])


@dataclass
class Timing:
    """Wall time (s) of the batched path's phases (the benchmark's breakdown)."""

    decode: float = 0.0
    kinematics: float = 0.0
    solve: float = 0.0
    state: float = 0.0
    #: of ``decode``, the compiled scan of the patches (the adapter loop); of ``solve``, the
    #: compiled solves
    scan: float = 0.0
    solver: float = 0.0
    solves: int = 0
    #: the solves as they were solved, when kept: :attr:`results.Profile.solves`
    inputs: list[tuple[Any, ...]] | None = None


@dataclass
class _Twists:
    """Twists taken so far (the pipeline's history): stamps, ``(v, w)``, arrival."""

    stamp: Ints = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    value: Floats = field(default_factory=lambda: np.zeros((0, 6)))
    arrival: Ints = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    dropped: int = 0     # taken earlier, out of the history kept

    def trim(self) -> None:
        extra = self.stamp.size - TWIST_HISTORY
        if extra > 0:
            self.stamp = self.stamp[extra:]
            self.value = self.value[extra:]
            self.arrival = self.arrival[extra:]
            self.dropped += extra


class _ContactState:
    """Per contact, as arrays: what :func:`kernels.advance` carries, the counters."""

    def __init__(self, n: int) -> None:
        self.last_stamp = np.zeros(n, dtype=np.int64)
        self.has_stamp = np.zeros(n, dtype=np.bool_)
        self.last_frame = np.zeros((n, 12))
        self.has_frame = np.zeros(n, dtype=np.bool_)
        self.last_marker = np.zeros(n, dtype=np.int64)
        self.has_marker = np.zeros(n, dtype=np.bool_)
        self.wrench_stamp = np.zeros(n, dtype=np.int64)
        self.wrench = np.zeros((n, 6))
        self.has_wrench = np.zeros(n, dtype=np.bool_)
        # the last wheelset wrench's stamp (kernels.advance; the int64 minimum before one)
        self.last_sum = np.array([_FIRST], dtype=np.int64)
        self.counts = np.zeros((n, len(STATUSES)), dtype=np.int64)
        self.window_inputs = np.zeros(n, dtype=np.int64)
        self.window_rejected = np.zeros(n, dtype=np.int64)
        self.window_first: list[int | None] = [None] * n
        self.window_last: list[int | None] = [None] * n
        self.last_detail: list[str | None] = [None] * n
        self.solve_times: list[list[float]] = [[] for _ in range(n)]


@dataclass
class _Group:
    """Patches of one layout scanned together: rows of the run, pressures, peak pressures."""

    rows: Ints
    pressure: Floats
    peak: Floats


# ------------------------------------------------------------------------ the batch

class Batch:
    """The pipeline's rules over runs of messages (see the module docstring).

    ``pipeline``: the configured pipeline (its parameters and diagnostics;
    :meth:`store` writes the counters back); ``channels``: input channel id
    -> ``(kind, contact index)`` (``kind`` one of :data:`KINDS`).
    """

    def __init__(self, pipeline: Pipeline, channels: dict[int, tuple[str, int]],
                 *, keep_inputs: bool = False) -> None:
        self.pipeline = pipeline
        config = pipeline.config
        self.config = config
        self.contacts = config.contacts
        self.frame_id = str(config["wheelset_frame"])
        self.max_cells = int(config["max_patch_cells"])
        self.max_age = round(float(config["max_kinematics_age"]) * 1e9)
        self.min_speed = float(config["min_rolling_speed"])
        self.allow_implausible = bool(config["allow_implausible"])
        self.rail_required = bool(config["rail_twist_required"])
        rate = float(config["marker_rate"])
        self.markers_on = bool(config["publish_markers"])
        self.marker_period = 0 if rate == 0.0 else round(1e9 / rate)
        size = max(channels, default=0) + 1
        self.kind = np.full(size, -1, dtype=np.int64)
        self.of_contact = np.zeros(size, dtype=np.int64)
        for cid, (kind, ci) in channels.items():
            self.kind[cid] = KINDS.index(kind)
            self.of_contact[cid] = ci
        self.twists = (_Twists(), _Twists())
        self.twist_layout, self.twist_doubles = twist_layout(self.frame_id)
        self.layouts: dict[int, list[Layout]] = {}
        self.state = _ContactState(len(self.contacts))
        self.timing = Timing(inputs=[] if keep_inputs else None)
        # verdicts not yet counted: twists (place in the bag, index of _TWIST_COUNTS) and
        # the runs' patches (with the first row not yet counted)
        self._twist_place = np.zeros(0, dtype=np.int64)
        self._twist_count = np.zeros(0, dtype=np.int64)
        self._pending: list[tuple[Patches, int]] = []
        # the window run last: (window, base, first message, its patches)
        self._window: tuple[Window, int, int, Patches] | None = None
        self._setup_solver()

    # ---------------------------------------------------------------- solver

    def _setup_solver(self) -> None:
        config = self.config
        nu, g = config["poisson_ratio"], config["shear_modulus"]
        self.solver: MaeSolver | EquivalentEllipseSolver = {
            "mae": MaeSolver, "mae_calibrated": CalibratedMaeSolver,
            "fastsim_ellipse": EquivalentEllipseSolver}[str(config["method"])](nu, g)
        self.mu = float(config["friction_coefficient"])
        law = friction_law(str(config["friction_law"]), self.mu,
                           limit_ratio=float(config["friction_limit_ratio"]),
                           decay=float(config["friction_decay"]),
                           reduction=slope_reduction_of(config))
        # constant friction runs as the solvers' plain mu (the pipeline passes no law)
        self.law = law if law.slip_dependent or law.reduces_slope else None
        self.reduces_slope = law.reduces_slope
        self.law_code = law.code if self.law is not None else contact_kernels.LAW_CONSTANT
        self.law_params = np.array(law.params if self.law is not None else np.zeros(2),
                                   dtype=np.float64)
        self.mu_solve = law.mu_s if self.law is not None else self.mu
        self.bound = str(config["traction_bound"])
        self.parabolic = check_bound(self.bound)

    def _solve(self, ps: Floats, grid: Floats, creep: Floats,
               speed: Floats) -> tuple[Ints, Floats]:
        """Solve ``ps[b]`` on ``grid[b]`` (x0, y0, dx, dy) at ``creep[b]`` (xi, eta, phi)."""
        n = creep.shape[0]
        status = np.zeros(n, dtype=np.int64)
        info = np.zeros(n)
        out = np.zeros((n, 6))
        s = self.solver
        x0, y0, dx, dy = (np.ascontiguousarray(grid[:, k]) for k in range(4))
        creep = np.ascontiguousarray(creep)
        if self.reduces_slope:
            # the batch kernels know no slope reduction: the solver's solve_arrays, one
            # by one (a failed item keeps status 1: _solve_error words its rejection;
            # the slip count as the fraction of one cell in contact)
            for b in range(n):
                try:
                    f = s.solve_arrays(ps[0] if ps.shape[0] == 1 else ps[b], x0[b], y0[b],
                                       dx[b], dy[b], creep[b, 0], creep[b, 1], creep[b, 2],
                                       bound=self.bound,  # type: ignore[arg-type]
                                       friction=self.law, speed=float(speed[b]))
                except ContactError:
                    status[b] = 1
                    continue
                out[b] = (f.fx, f.fy, f.mz, f.n, f.slip_fraction, 1.0)
            return status, out
        # the solver's own tables and options: what its solve_arrays hands its kernel
        if isinstance(s, MaeSolver):
            kernels.solve_mae(ps, x0, y0, dx, dy, creep, self.mu_solve, speed, s._rule,
                              self.parabolic, s.shear_modulus, s._knots, s._polys,
                              self.law_code, self.law_params, s._calibrated, s._pair_knots,
                              s._pair_values, status, info, out,
                              s._knee_for("parabolic" if self.parabolic else "given"))
        else:
            kernels.solve_equivalent(ps, x0, y0, dx, dy, creep, self.mu_solve, speed,
                                     self.parabolic, s.cells or 0, s.shear_modulus, s._knots,
                                     s._polys, self.law_code, self.law_params, status, info,
                                     out)
        return status, out

    def _solve_error(self, p: Floats, grid: Floats, creep: Floats,
                     speed: float) -> RejectedInput:
        """Return a failed solve's rejection: the solver's own error, as the pipeline words it."""
        x0, y0, dx, dy = grid.tolist()
        xi, eta, phi = creep.tolist()
        try:
            self.solver.solve_arrays(p, x0, y0, dx, dy, xi, eta, phi, self.mu,
                                     bound=self.bound,  # type: ignore[arg-type]
                                     friction=self.law, speed=speed)
        except OutOfTableError as e:
            return RejectedInput("out_of_table", str(e))
        except ContactError as e:
            return RejectedInput("nonfinite" if "finite" in str(e) else "degenerate", str(e))
        return RejectedInput("degenerate", "the solver refused the patch")

    # ---------------------------------------------------------------- a run

    def run(self, w: Window, lo: int, hi: int, base: int) -> Patches:
        """Apply the rules to messages ``lo:hi`` of a window; return their patches.

        ``base``: messages of the bag before the window (arrival order).
        The runs of a window come in order (``lo`` where the last ended):
        the first applies the rules to the rest of the window at once (one
        run of numpy and compiled loops instead of one per diagnostics) and
        the others return their rows of it.
        """
        done = self._window
        if done is None or done[0] is not w or done[1] != base or lo < done[2]:
            done = self._window = (w, base, lo, self._run(w, lo, len(w), base))
        p = done[3]
        if hi >= len(w):   # the window's last run: its buffers go with it
            self._window = None
        r0, r1 = np.searchsorted(p.index, (lo, hi), "left").tolist()
        return p if r0 == 0 and r1 == p.index.size else p.rows(r0, r1)

    def _run(self, w: Window, lo: int, hi: int, base: int) -> Patches:
        """Apply the rules to messages ``lo:hi`` of a window (see :meth:`run`)."""
        t0 = time.perf_counter()
        channel = w.channel[lo:hi]
        known = channel < self.kind.size
        kind = np.full(channel.size, -1, dtype=np.int64)
        kind[known] = self.kind[channel[known]]
        index = np.arange(lo, hi, dtype=np.int64)
        for which in (0, 1):
            self._twists(w, index[kind == which], which, base)
        at = index[kind == 2]
        contact_of = self.of_contact[w.channel[at]]
        p, groups, singles = self._decode(w, at, contact_of)
        p.place = base + at
        p.solve_time = np.full(at.size, np.nan)
        t1 = time.perf_counter()
        todo = self._kinematics(p, base)
        t2 = time.perf_counter()
        self._solve_all(p, todo, groups, singles)
        # old stamps once every patch's own verdict is known: a patch is old against the last
        # one taken (solved or empty), as the pipeline has it
        self._old_stamps(p)
        t3 = time.perf_counter()
        self._advance(p)
        self._pending.append((p, 0))
        t4 = time.perf_counter()
        self.timing.decode += t1 - t0
        self.timing.kinematics += t2 - t1
        self.timing.solve += t3 - t2
        self.timing.state += t4 - t3
        return p

    # ---------------------------------------------------------------- twists

    def _matching(self, w: Window, at: Ints, layout: Layout) -> Bools:
        """Which messages ``at`` of the window have ``layout``."""
        same = np.zeros(at.size, dtype=np.bool_)
        kernels.same_prefix(w.arrays, w.buffer[at], w.start[at], w.size[at], layout.template,
                            layout.mask, layout.length, same)
        return same

    def _stamps(self, w: Window, at: Ints) -> Ints:
        out = np.zeros(at.size, dtype=np.int64)
        kernels.stamps(w.arrays, w.buffer[at], w.start[at], out)
        return out

    def _twists(self, w: Window, at: Ints, which: int, base: int) -> None:
        n = at.size
        if n == 0:
            return
        fast = self._matching(w, at, self.twist_layout)
        stamp = np.zeros(n, dtype=np.int64)
        value = np.zeros((n, 6))
        hit = at[fast]
        stamp[fast] = self._stamps(w, hit)
        got = np.zeros((hit.size, 6))
        kernels.doubles(w.arrays, w.buffer[hit], w.start[hit], self.twist_doubles, got)
        value[fast] = got
        ok = fast & np.isfinite(value).all(axis=1)
        # each twist's verdict: an index of _TWIST_ORDER (-1: not yet decided)
        code = np.where(fast & ~ok, _TWIST_CODE["nonfinite"], -1)
        for i in np.flatnonzero(~fast).tolist():     # another layout: the pipeline's decoder
            try:
                t = read_twist(w.data(int(at[i])))
            except MalformedMessageError:
                code[i] = _TWIST_CODE["malformed"]
                continue
            if t.frame_id != self.frame_id:
                code[i] = _TWIST_CODE["wrong_frame"]
            elif not twist_is_finite(t):
                code[i] = _TWIST_CODE["nonfinite"]
            else:
                ok[i] = True
                stamp[i] = t.stamp_ns
                value[i] = t.linear + t.angular
        hist = self.twists[which]
        candidates = np.flatnonzero(ok)
        if candidates.size:
            s = stamp[candidates]
            last = hist.stamp[-1] if hist.stamp.size else _FIRST
            before = np.maximum(np.concatenate(([last], np.maximum.accumulate(s)[:-1])), last)
            old = s < before
            code[candidates[old]] = _TWIST_CODE["old_stamp"]
            taken = candidates[~old]
            hist.stamp = np.concatenate((hist.stamp, stamp[taken]))
            hist.value = np.concatenate((hist.value, value[taken]))
            hist.arrival = np.concatenate((hist.arrival, base + at[taken]))
            code[taken] = _TWIST_CODE[_TWIST_COUNTS[which]]
        counted = code >= 0
        code = code[counted]
        place = np.concatenate((self._twist_place, base + at[counted]))
        count = np.concatenate((self._twist_count, code))
        order = np.argsort(place, kind="stable")   # the wheel's and the rail's, by place
        self._twist_place, self._twist_count = place[order], count[order]

    # ---------------------------------------------------------------- patches

    def _decode(self, w: Window, at: Ints,
                contact_of: Ints) -> tuple[Patches, list[_Group], dict[int, ContactPatch]]:
        n = at.size
        p = Patches(at, contact_of, np.zeros(n, dtype=np.int64), np.full(n, -1, dtype=np.int64),
                    {}, np.zeros((n, 12)), np.full((n, 4), np.nan), np.zeros((n, 4)),
                    np.full(n, np.nan), np.zeros(n, dtype=np.bool_),
                    np.zeros(n, dtype=np.bool_), np.zeros(n, dtype=np.bool_),
                    np.zeros(n, dtype=np.int64), np.zeros((n, 6)), np.ones(n, dtype=np.bool_))
        self._grid = np.zeros((n, 4))
        groups: list[_Group] = []
        one_by_one: list[int] = []
        channel = w.channel[at]
        for cid in np.unique(channel).tolist():
            left = np.flatnonzero(channel == cid)
            known = self.layouts.setdefault(cid, [])
            k = 0
            while left.size:  # each message by the first of the topic's layouts it has
                if k == len(known):
                    if k == MAX_LAYOUTS:
                        break
                    # a layout not seen yet (the patch's grid changed): read it off the first
                    # message left, which has it
                    layout = cloud_layout(bytes(w.data(int(at[left[0]]))), self.frame_id,
                                          self.max_cells)
                    if layout is None:   # does not parse: one by one, for its words
                        one_by_one.append(int(left[0]))
                        left = left[1:]
                        continue
                    known.append(layout)
                layout = known[k]
                k += 1
                same = self._matching(w, at[left], layout)
                rows = left[same]
                left = left[~same]
                if rows.size == 0:
                    continue
                if layout.fast:
                    group, rest = self._scan(w, at, rows, layout, p)
                    groups.append(group)
                    one_by_one += rest
                elif layout.empty:
                    p.stamp[rows] = self._stamps(w, at[rows])
                    p.status[rows] = _EMPTY
                else:
                    one_by_one += rows.tolist()
            one_by_one += left.tolist()
        singles: dict[int, ContactPatch] = {}
        for i in sorted(one_by_one):
            patch = self._one(w, int(at[i]), i, p)
            if patch is not None:
                singles[i] = patch
        return p, groups, singles

    def _scan(self, w: Window, at: Ints, rows: Ints, layout: Layout,
              p: Patches) -> tuple[_Group, list[int]]:
        """Scan patches of one layout; return them and the rows left to the one-by-one path."""
        n = rows.size
        pressure = np.empty((n, layout.height, layout.cells))
        out = np.zeros((n, adapter.OUT_SIZE))
        peak = np.empty(n)
        m = at[rows]
        t0 = time.perf_counter()
        kernels.scan_patches(w.arrays, w.buffer[m], w.start[m], layout.data_at, layout.width,
                             layout.height, layout.cells, layout.row, layout.step, layout.cols,
                             pressure, out, peak)
        self.timing.scan += time.perf_counter() - t0
        p.stamp[rows] = self._stamps(w, m)
        status, cells = out[:, adapter.STATUS], out[:, adapter.CELLS]
        clean = status == adapter.OK
        p.status[rows[clean & (cells == 0)]] = _EMPTY
        # patch_from_cloud's decisions; any other outcome goes one by one for its words
        fitted = np.flatnonzero(clean & (cells >= MIN_CONTACT_CELLS))
        rest = rows[~clean | ((cells > 0) & (cells < MIN_CONTACT_CELLS))].tolist()
        if layout.height < 2 or layout.cells < 2:
            rest += rows[fitted].tolist()
            fitted = fitted[:0]
        total = out[:, adapter.P_SUM]
        frame = out[:, _FRAME_SLOTS]
        fit = out[:, _FIT_SLOTS]
        # patch_from_cloud's checks after the fit; what fails goes one by one for its words
        g = fit[fitted]
        x0, dx, x_order, x_bad = _grid_axis(g[:, 0], g[:, 1], g[:, 2], layout.cells)
        y0, dy, y_order, y_bad = _grid_axis(g[:, 3], g[:, 4], g[:, 5], layout.height)
        cell_area = dx * dy
        with np.errstate(all="ignore"):
            load = total[fitted] * cell_area
        bad = x_bad | y_bad | ~((cell_area > 0.0) & np.isfinite(load) & (load > 0.0))
        rest += rows[fitted[bad]].tolist()
        good = fitted[~bad]
        r = rows[good]
        p.status[r] = _SOLVED           # to be solved
        p.frame[r] = frame[good]
        self._grid[r] = np.stack((x0[~bad], y0[~bad], dx[~bad], dy[~bad]), axis=1)
        for j in np.flatnonzero((x_order[~bad] < 0) | (y_order[~bad] < 0)).tolist():
            i = good[j]  # rows or columns running backwards: the adapter's orientation
            pressure[i] = np.ascontiguousarray(pressure[i][::y_order[~bad][j],
                                                           ::x_order[~bad][j]])
        if good.size == n:   # every patch to solve: the array as it is (no copy)
            return _Group(r, pressure, peak), rest
        keep = np.zeros(n, dtype=np.bool_)
        keep[good] = True
        return _Group(r, pressure[keep], peak[keep]), rest

    def _one(self, w: Window, message: int, i: int, p: Patches) -> ContactPatch | None:
        """Decode patch row ``i`` as the pipeline does, one message at a time."""
        try:
            cloud = read_cloud(w.data(message))
        except MalformedMessageError as e:  # not a PointCloud2: no stamp
            p.status[i] = _MISSING
            p.detail[i] = f"missing_field: {e}"
            p.parsed[i] = False
            return None
        p.stamp[i] = cloud.stamp_ns
        if cloud.frame_id != self.frame_id:
            p.status[i] = _WRONG_FRAME
            p.detail[i] = f"wrong_frame: frame {cloud.frame_id!r}, expected {self.frame_id!r}"
            return None
        try:
            patch = patch_from_cloud(cloud, max_cells=self.max_cells)
        except RejectedInput as e:
            p.status[i] = CODE[e.reason]
            p.detail[i] = str(e)
            return None
        if patch is None:
            p.status[i] = _EMPTY
            return None
        p.status[i] = _SOLVED
        p.frame[i, 0:3] = patch.frame.origin
        p.frame[i, 3:12] = np.array(patch.frame.axes).ravel()
        self._grid[i] = (patch.x0, patch.y0, patch.dx, patch.dy)
        return patch

    def _old_stamps(self, p: Patches) -> None:
        """``old_stamp``: older than the contact's last patch taken (solved or empty) before it.

        Run after the patches' own verdicts: the old ones among them (solved
        or rejected for a later check) become ``old_stamp``, as the pipeline's
        check before the others makes them; a rejected patch does not move
        the last stamp (the pipeline's rule).  The last stamp before a patch
        is the largest of the taken ones before it (and the contact's last
        before the run): a taken patch that is old is older than that
        largest, so counting it changes nothing.
        """
        st = self.state
        parsed = p.parsed & (p.status != _WRONG_FRAME)
        for c in range(len(self.contacts)):
            mine = np.flatnonzero((p.contact == c) & parsed)
            if mine.size == 0:
                continue
            first = int(st.last_stamp[c]) if st.has_stamp[c] else _FIRST
            stamps = p.stamp[mine]
            status = p.status[mine]
            taken = (status == _SOLVED) | (status == _EMPTY)
            newest = np.maximum.accumulate(np.where(taken, stamps, _FIRST))
            before = np.maximum(np.concatenate(([first], newest[:-1])), first)
            old = stamps < before
            for i, s, last in zip(mine[old].tolist(), stamps[old].tolist(),
                                  before[old].tolist()):
                p.status[i] = _OLD
                p.detail[i] = f"old_stamp: stamp {s} ns is older than the last, {last} ns"
            last = max(first, int(newest[-1]))
            if last != _FIRST:
                st.last_stamp[c] = last
                st.has_stamp[c] = True

    # ---------------------------------------------------------------- kinematics

    def _newest_before(self, hist: _Twists, stamp: Ints,
                       arrival: Ints) -> tuple[Ints, Bools, Bools]:
        """Return per patch the newest twist's index, whether there is one, whether any came.

        The newest twist in the history as it was when the patch arrived
        whose stamp is not after the patch's; whether there is one; whether
        any twist was taken before the patch.
        """
        m = np.searchsorted(hist.arrival, arrival, "left")   # taken before the patch
        idx = np.minimum(np.searchsorted(hist.stamp, stamp, "right") - 1, m - 1)
        found = (m > 0) & (idx >= np.maximum(m - TWIST_HISTORY, 0)) & (idx >= 0)
        return np.where(found, idx, 0), found, (m + hist.dropped) > 0

    def _kinematics(self, p: Patches, base: int) -> Ints:
        """Match kinematics, compute creepages; return the rows to solve."""
        rows = np.flatnonzero(p.status == _SOLVED)
        if rows.size == 0:
            return rows
        stamp = p.stamp[rows]
        arrival = base + p.index[rows]
        wheel, rail = self.twists
        wi, w_found, w_any = self._newest_before(wheel, stamp, arrival)
        w_age = stamp - (wheel.stamp[wi] if wheel.stamp.size else 0)
        ri, r_found, _ = self._newest_before(rail, stamp, arrival)
        r_age = stamp - (rail.stamp[ri] if rail.stamp.size else 0)
        r_fresh = r_found & (r_age <= self.max_age)
        reject = np.zeros(rows.size, dtype=np.int64)
        for j in np.flatnonzero(~w_found).tolist():
            i = rows[j]
            if w_any[j]:
                p.status[i], p.detail[i] = CODE["stale_kinematics"], (
                    "stale_kinematics: every wheelset twist is newer than the patch")
            else:
                p.status[i], p.detail[i] = CODE["no_kinematics"], (
                    "no_kinematics: no wheelset twist yet")
            reject[j] = 1
        for j in np.flatnonzero(w_found & (w_age > self.max_age)).tolist():
            i = rows[j]
            p.status[i], p.detail[i] = CODE["stale_kinematics"], (
                f"stale_kinematics: newest wheelset twist is {int(w_age[j]) * 1e-9:.4g} s old")
            reject[j] = 1
        if self.rail_required:
            for j in np.flatnonzero((reject == 0) & ~r_fresh).tolist():
                i = rows[j]
                p.status[i], p.detail[i] = CODE["stale_kinematics"], (
                    "stale_kinematics: no fresh rail twist (rail_twist_required)")
                reject[j] = 1
        keep = reject == 0
        rows, wi, ri, r_fresh = rows[keep], wi[keep], ri[keep], r_fresh[keep]
        v = wheel.value[wi] if wheel.stamp.size else np.zeros((rows.size, 6))
        r = np.zeros((rows.size, 6))       # the rail at rest (track) unless fresh
        if rail.stamp.size:
            r[r_fresh] = rail.value[ri[r_fresh]]
        p.creep[rows] = _creepages(p.frame[rows], v, r)
        speed = p.creep[rows, 3]
        still = ~(np.abs(speed) >= self.min_speed)
        for i, s in zip(rows[still].tolist(), speed[still].tolist()):
            p.status[i] = CODE["standstill"]
            p.detail[i] = f"standstill: rolling speed {s:.4g} m/s"
        return rows[~still]

    # ---------------------------------------------------------------- solves

    def _solve_all(self, p: Patches, todo: Ints, groups: list[_Group],
                   singles: dict[int, ContactPatch]) -> None:
        if todo.size == 0:
            return
        where = np.zeros(p.status.size, dtype=np.bool_)
        where[todo] = True
        # one compiled call per grid shape (the patches of every layout and topic of that shape)
        shapes: dict[tuple[int, ...], list[tuple[Ints, Floats, Floats]]] = {}
        for g in groups:
            take = where[g.rows]
            if take.all():
                shapes.setdefault(g.pressure.shape[1:], []).append((g.rows, g.pressure, g.peak))
            elif take.any():
                shapes.setdefault(g.pressure.shape[1:], []).append(
                    (g.rows[take], g.pressure[take], g.peak[take]))
        for i, patch in singles.items():
            if where[i]:
                shapes.setdefault(patch.pressure.shape, []).append(
                    (np.array([i]), patch.pressure[None], np.array([patch.pressure.max()])))
        items = [pieces[0] if len(pieces) == 1 else
                 tuple(np.concatenate([piece[k] for piece in pieces]) for k in range(3))
                 for pieces in shapes.values()]
        t0 = time.perf_counter()
        solved: list[Ints] = []
        for rows, ps, peak in items:
            creep = p.creep[rows]
            grid = self._grid[rows].copy()
            xep = creep[:, :3].copy()
            back = creep[:, 3] < 0.0
            if back.any():   # the leading edge at +x: turn those patches by 180 degrees
                ps = ps.copy()
                ny, nx = ps.shape[1], ps.shape[2]
                ps[back] = ps[back][:, ::-1, ::-1]
                grid[back, 0] = -(grid[back, 0] + (nx - 1) * grid[back, 2])
                grid[back, 1] = -(grid[back, 1] + (ny - 1) * grid[back, 3])
                xep[back, 2] = -xep[back, 2]
            speed = np.abs(creep[:, 3]) if self.law is not None else np.zeros(rows.size)
            t1 = time.perf_counter()
            status, out = self._solve(np.ascontiguousarray(ps), grid, xep, speed)
            self.timing.solver += time.perf_counter() - t1
            ok = status == contact_kernels.OK
            solved.append(rows[ok])
            if self.timing.inputs is not None:
                self.timing.inputs.append((ps, grid, xep, ok))
            sign = np.where(back, -1.0, 1.0)
            fx, fy, mz, n = sign * out[:, 0], sign * out[:, 1], out[:, 2], out[:, 3]
            with np.errstate(all="ignore"):
                slip = out[:, 4] / out[:, 5]
            p.force[rows] = np.stack((fx, fy, n, mz), axis=1)
            p.slip[rows] = slip
            finite = np.isfinite(fx) & np.isfinite(fy) & np.isfinite(mz) & np.isfinite(n)
            for j in np.flatnonzero(~ok).tolist():
                e = self._solve_error(ps[j], grid[j], xep[j], float(speed[j]))
                p.status[rows[j]] = CODE[e.reason]
                p.detail[rows[j]] = str(e)
            for j in np.flatnonzero(ok & ~finite).tolist():
                p.status[rows[j]] = CODE["nonfinite"]
                p.detail[rows[j]] = "nonfinite: the solve gave a non-finite force"
            if not self.allow_implausible:
                self._implausible(p, rows, ps, grid, peak, np.flatnonzero(ok & finite))
        elapsed = time.perf_counter() - t0
        done = np.concatenate(solved)
        self.timing.solves += done.size
        if done.size:
            p.solve_time[done] = elapsed / done.size

    def _implausible(self, p: Patches, rows: Ints, ps: Floats, grid: Floats, peak: Floats,
                     solved: Ints) -> None:
        """``implausible``: the pipeline's rule (:func:`fastsim_ros.pipeline.implausible`).

        On items ``solved`` of a solve (``rows``, ``ps``, ``grid``, ``peak``:
        its patches' rows, pressures, grids and largest pressures (Pa), the
        scan's).  Its bounds tested on every row at once (the grid's span,
        the largest pressure, the creepages); the rows that fail one get the
        pipeline's own words from
        :func:`~fastsim_ros.ros.plausibility.stream_problem`.
        """
        if solved.size == 0:
            return
        table = plausibility.PLAUSIBLE
        ny, nx = ps.shape[1], ps.shape[2]
        peak = peak[solved]
        rows, grid = rows[solved], grid[solved]
        creep = p.creep[rows]
        suspect = ((nx * grid[:, 2] > table["patch_extent"].high)
                   | (ny * grid[:, 3] > table["patch_extent"].high)
                   | ~(peak >= table["peak_pressure"].low)
                   | ~(np.abs(creep[:, 0]) <= table["creepage"].high)
                   | ~(np.abs(creep[:, 1]) <= table["creepage"].high)
                   | ~(np.abs(creep[:, 2]) <= table["spin"].high))
        for j in np.flatnonzero(suspect).tolist():
            ex, ey = patch_extent(ps[solved[j]], float(grid[j, 2]), float(grid[j, 3]))
            why = plausibility.stream_problem(ex, ey, float(peak[j]), float(creep[j, 0]),
                                              float(creep[j, 1]), float(creep[j, 2]))
            if why is not None:
                p.status[rows[j]] = CODE["implausible"]
                p.detail[rows[j]] = f"implausible: {why}"

    # ---------------------------------------------------------------- state

    def _advance(self, p: Patches) -> None:
        st = self.state
        kernels.advance(p.contact, p.stamp, p.status, p.frame, p.force, FRAME_TOLERANCE,
                        self.markers_on, self.marker_period, st.last_frame, st.has_frame,
                        st.last_marker, st.has_marker, st.wrench_stamp, st.wrench,
                        st.has_wrench, st.last_sum, p.changed, p.marker, p.cycle, p.cycle_stamp,
                        p.cycle_wrench)

    def _count(self, upto: int | None) -> None:
        """Count the verdicts of the messages before place ``upto`` in the bag (None: all)."""
        twists = self._twist_place.size if upto is None else int(
            np.searchsorted(self._twist_place, upto, "left"))
        if twists:
            counts = np.bincount(self._twist_count[:twists], minlength=len(_TWIST_ORDER))
            for name, k in zip(_TWIST_ORDER, counts.tolist()):
                if k:
                    self.pipeline.kinematics_counts[name] += k
            self._twist_place = self._twist_place[twists:]
            self._twist_count = self._twist_count[twists:]
        left: list[tuple[Patches, int]] = []
        for p, r0 in self._pending:
            r1 = p.place.size if upto is None else int(np.searchsorted(p.place, upto, "left"))
            if r1 > r0:
                self._count_rows(p, r0, r1)
            if r1 < p.place.size:
                left.append((p, r1))
        self._pending = left

    def _count_rows(self, p: Patches, r0: int, r1: int) -> None:
        """Count patch rows ``r0:r1`` of a run: statuses, rate windows, rejections, solve times."""
        st = self.state
        status, contact = p.status[r0:r1], p.contact[r0:r1]
        rejected = status >= len((SOLVED, NO_CONTACT))
        parsed = p.parsed[r0:r1]
        timed = np.isfinite(p.solve_time[r0:r1])
        for c in range(len(self.contacts)):
            mine = contact == c
            st.counts[c] += np.bincount(status[mine], minlength=len(STATUSES))
            windowed = np.flatnonzero(mine & parsed)   # a PointCloud2: in the rate window
            if windowed.size:
                st.window_inputs[c] += windowed.size
                if st.window_first[c] is None:
                    st.window_first[c] = int(p.stamp[r0 + windowed[0]])
                st.window_last[c] = int(p.stamp[r0 + windowed[-1]])
                st.window_rejected[c] += int(np.count_nonzero(rejected[windowed]))
            last = np.flatnonzero(mine & rejected)
            if last.size:
                st.last_detail[c] = p.detail[r0 + int(last[-1])]
            solved = np.flatnonzero(mine & timed)
            if solved.size:
                times = st.solve_times[c]
                times += p.solve_time[r0 + solved].tolist()
                del times[:-SOLVE_TIME_WINDOW]

    # ---------------------------------------------------------------- the pipeline

    def store(self, upto: int | None = None) -> None:
        """Write the counters, rate windows, last rejections and solve times to the pipeline.

        As they stand after the messages before place ``upto`` in the bag
        (None: every message run so far).
        """
        self._count(upto)
        st = self.state
        contacts = self.pipeline._contacts
        for c, name in enumerate(self.contacts):
            stats = contacts[name].stats
            stats.counts = dict(zip(STATUSES, (int(v) for v in st.counts[c])))
            stats.window_inputs = int(st.window_inputs[c])
            stats.window_rejected = int(st.window_rejected[c])
            stats.window_first_ns = st.window_first[c]
            stats.window_last_ns = st.window_last[c]
            if st.last_detail[c] is not None:
                stats.last_detail = str(st.last_detail[c])
            times = st.solve_times[c]
            stats.solves = len(times)
            stats.solve_times[:len(times)] = times

    def reported(self) -> None:
        """Restart the rate windows: the pipeline reported, and restarted its own."""
        st = self.state
        st.window_inputs[:] = 0
        st.window_rejected[:] = 0
        st.window_first = [None] * len(self.contacts)
        st.window_last = [None] * len(self.contacts)
        for hist in self.twists:
            hist.trim()


def _creepages(frame: Floats, v: Floats, r: Floats) -> Floats:
    """:func:`msg_adapters.kinematics.creepages` on arrays, term for term: ``xi, eta, phi, V``.

    ``frame``: origin, ``e_x``, ``e_y``, ``e_z``; ``v``, ``r``: the wheel's
    and the rail's ``(v, w)`` about the wheelset origin.
    """
    p0, p1, p2 = frame[:, 0], frame[:, 1], frame[:, 2]
    ex = frame[:, 3:6].T
    ey = frame[:, 6:9].T
    ez = frame[:, 9:12].T
    v0, v1, v2, w0, w1, w2 = v.T
    vr0, vr1, vr2, wr0, wr1, wr2 = r.T
    u_w = (v0 + (w1 * p2 - w2 * p1), v1 + (w2 * p0 - w0 * p2), v2 + (w0 * p1 - w1 * p0))
    u_r = (vr0 + (wr1 * p2 - wr2 * p1), vr1 + (wr2 * p0 - wr0 * p2),
           vr2 + (wr0 * p1 - wr1 * p0))
    c = (v0 + (0.0 * p2 - w2 * p1), v1 + (w2 * p0 - w0 * p2), v2 + (w0 * p1 - 0.0 * p0))
    a = (c[0] - 0.5 * (u_w[0] + u_r[0]), c[1] - 0.5 * (u_w[1] + u_r[1]),
         c[2] - 0.5 * (u_w[2] + u_r[2]))
    speed = ex[0] * a[0] + ex[1] * a[1] + ex[2] * a[2]
    slip = (u_w[0] - u_r[0], u_w[1] - u_r[1], u_w[2] - u_r[2])
    spin = ez[0] * (w0 - wr0) + ez[1] * (w1 - wr1) + ez[2] * (w2 - wr2)
    with np.errstate(all="ignore"):
        out = np.stack((
            (ex[0] * slip[0] + ex[1] * slip[1] + ex[2] * slip[2]) / speed,
            (ey[0] * slip[0] + ey[1] * slip[1] + ey[2] * slip[2]) / speed,
            spin / speed, speed), axis=1)
    out[speed == 0.0, :3] = np.nan
    out[speed == 0.0, 3] = 0.0
    return out


def warm_up() -> None:
    """Compile (or load from numba's disk cache) the batched path's loops, every solver."""
    kernels.warm_up()
    p = np.zeros((1, 4, 4))
    p[0, 1:3, 1:3] = 1e9
    grid = np.array([[-1.5e-3, -1.5e-3, 1e-3, 1e-3]])
    creep = np.array([[1e-3, 0.0, 0.0]])
    for method in ("mae", "fastsim_ellipse"):
        b = Batch(Pipeline(PipelineConfig.from_values({"method": method, "contacts": ["a"]})),
                  {})
        b._solve(p, grid, creep, np.ones(1))
    one = np.zeros(1, dtype=np.int64)
    flags = np.zeros(1, dtype=np.bool_)
    kernels.advance(one, one, one, np.zeros((1, 12)), np.zeros((1, 4)), FRAME_TOLERANCE, True,
                    0, np.zeros((1, 12)), flags.copy(), one.copy(), flags.copy(), one.copy(),
                    np.zeros((1, 6)), flags.copy(), np.array([_FIRST], dtype=np.int64),
                    flags.copy(), flags.copy(), flags.copy(), one.copy(), np.zeros((1, 6)))
