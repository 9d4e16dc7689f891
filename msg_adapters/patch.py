"""PointCloud2 -> contact patch: the contact frame, the in-plane grid, the pressure.

docs/guide_node.md: the cloud is organised, each row one lateral strip
whose points run along the rolling direction; fields ``x y z`` (cell centre
on the contact surface, m, in the wheelset frame), ``normal_x normal_y
normal_z`` (surface normal pointing into the wheel) and ``pressure`` (Pa,
zero outside the contact), float32 or float64, either byte order, in any
order and with any padding.  The contact frame: origin at the
pressure-weighted centroid, ``z`` along ``sum p n`` over the cells in
contact, ``x`` the wheelset's ``x`` projected on the contact plane, ``y = z
x x``.  Cells must form a regular grid in that plane (rows along ``x``);
their spacing is the cell size and ``N = sum p dA``.

Every check runs on the message's own numbers before the grid is used, and
the size bound before anything is allocated: a patch either converts or
raises :class:`~msg_adapters.errors.RejectedInput` with its reason key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from msg_adapters import patch_kernels as kernels
from msg_adapters.cdr import Cloud
from msg_adapters.errors import RejectedInput

FloatArray = NDArray[np.float64]

#: PointField datatype codes (sensor_msgs/PointField) the adapter reads
FLOAT32, FLOAT64 = 7, 8
PATCH_FIELDS = ("x", "y", "z", "normal_x", "normal_y", "normal_z", "pressure")
#: a cell centre may sit this share of a cell off the regular grid (float32
#: coordinates a metre from the wheelset origin carry ~1e-7 m, 1e-4 of a
#: 1 mm cell; a patch meshed on another grid is off by a large share)
GRID_TOLERANCE = 0.02
#: cells smaller than this (m) describe no wheel-rail contact (and 1e-200 m
#: cells would underflow the cell area)
MIN_CELL_SIZE = 1e-9
#: fewer cells in contact than this are `degenerate`
MIN_CONTACT_CELLS = 4


@dataclass(frozen=True, slots=True)
class ContactFrame:
    """The contact frame in the wheelset frame.

    ``origin``: (m); ``axes``: rows ``e_x, e_y, e_z`` (unit vectors).
    """

    origin: tuple[float, float, float]
    axes: tuple[tuple[float, float, float], tuple[float, float, float],
                tuple[float, float, float]]

    def quaternion(self) -> tuple[float, float, float, float]:
        """Return the frame's orientation as a unit quaternion ``(x, y, z, w)``."""
        (xx, xy, xz), (yx, yy, yz), (zx, zy, zz) = self.axes
        # rotation matrix columns are the axes: R[i][j] = axes[j][i]
        m00, m01, m02 = xx, yx, zx
        m10, m11, m12 = xy, yy, zy
        m20, m21, m22 = xz, yz, zz
        trace = m00 + m11 + m22
        if trace > 0.0:
            s = 2.0 * math.sqrt(trace + 1.0)
            q = ((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s)
        elif m00 > m11 and m00 > m22:
            s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
            q = (0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
        elif m11 > m22:
            s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
            q = ((m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s)
        else:
            s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
            q = ((m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s)
        return q

    def to_wheelset(self, v: tuple[float, float, float]) -> tuple[float, float, float]:
        """Return the contact-frame vector ``v`` in wheelset-frame components."""
        (xx, xy, xz), (yx, yy, yz), (zx, zy, zz) = self.axes
        return (v[0] * xx + v[1] * yx + v[2] * zx,
                v[0] * xy + v[1] * yy + v[2] * zy,
                v[0] * xz + v[1] * yz + v[2] * zz)


@dataclass(frozen=True, slots=True, eq=False)
class ContactPatch:
    """One converted patch: frame, in-plane grid and pressure.

    ``pressure[j, i]`` (Pa) on cells centred at ``(x0 + i dx, y0 + j dy)``
    (m) in the contact frame (rows = lateral strips, ``x`` increasing);
    ``load``: ``N = sum p dA`` (N); ``cells``: cells in contact.
    ``row_order`` and ``column_order``: +1 or -1, how rows and columns map
    to the cloud's (-1: reversed), so that results can be laid back on the
    cloud's points.
    """

    stamp_ns: int
    frame: ContactFrame
    pressure: FloatArray
    x0: float
    y0: float
    dx: float
    dy: float
    load: float
    cells: int
    row_order: int
    column_order: int


@dataclass(frozen=True, slots=True)
class _Layout:
    """Where the patch fields lie in a point: checked once per layout and reused."""

    dtype: str          # numpy dtype of every field ("" when their types differ)
    offsets: tuple[int, ...]
    widths: tuple[int, ...]
    cols: NDArray[np.int64] | None  # word offsets when the buffer can be viewed as words


_LAYOUTS: dict[tuple[Any, ...], _Layout] = {}


#: the layout of a fields dict (by identity: read_cloud hands out the same dict for the
#: same field list) with the byte order and steps it was checked with
_BY_FIELDS: dict[int, tuple[Any, bool, int, int, _Layout]] = {}


def _layout(cloud: Cloud) -> _Layout:
    """Check the patch fields; return their layout (cached: a topic keeps its layout)."""
    seen = _BY_FIELDS.get(id(cloud.fields))
    if seen is not None and seen[0] is cloud.fields and seen[1] == cloud.is_bigendian \
            and seen[2] == cloud.point_step and seen[3] == cloud.row_step:
        return seen[4]
    key = (tuple(cloud.fields.items()), cloud.is_bigendian, cloud.point_step, cloud.row_step)
    hit = _LAYOUTS.get(key)
    if hit is not None:
        if len(_BY_FIELDS) < 256:
            _BY_FIELDS[id(cloud.fields)] = (cloud.fields, cloud.is_bigendian,
                                            cloud.point_step, cloud.row_step, hit)
        return hit
    order = ">" if cloud.is_bigendian else "<"
    offsets: list[int] = []
    widths: list[int] = []
    for name in PATCH_FIELDS:
        spec = cloud.fields.get(name)
        if spec is None:
            raise RejectedInput("missing_field", f"no field {name!r}")
        if spec.datatype not in (FLOAT32, FLOAT64) or spec.count != 1:
            raise RejectedInput("missing_field", f"field {name!r} is not one float32 or "
                                f"float64 (datatype {spec.datatype}, count {spec.count})")
        size = 4 if spec.datatype == FLOAT32 else 8
        if spec.offset < 0 or spec.offset + size > cloud.point_step:
            raise RejectedInput("irregular_grid", f"field {name!r} at byte {spec.offset} "
                                f"lies outside the point_step of {cloud.point_step}")
        offsets.append(spec.offset)
        widths.append(size)
    size = widths[0]
    viewable = (all(w == size for w in widths) and not cloud.point_step % size
                and not cloud.row_step % size and not any(o % size for o in offsets))
    layout = _Layout(order + ("f4" if size == 4 else "f8") if viewable else "",
                     tuple(offsets), tuple(widths),
                     np.array([o // size for o in offsets], dtype=np.int64) if viewable
                     else None)
    if len(_LAYOUTS) < 256:
        _LAYOUTS[key] = layout
    return layout


def _words(cloud: Cloud) -> tuple[NDArray[Any], int, int, NDArray[np.int64]]:
    """Return the cloud's points as native floats ``(words, row, step, cols)``.

    Point ``(j, i)`` starts at word ``j * row + i * step`` of ``words``;
    ``cols``: word offsets of the PATCH_FIELDS.  Where every field has one
    type and all offsets and steps are multiples of its size (the usual
    layout) ``words`` is a view of the buffer (a copy only when its byte
    order is not the machine's); otherwise the fields are gathered one by
    one into a ``(ny * nx, 7)`` float64 array.
    """
    ny, nx = cloud.height, cloud.width
    layout = _layout(cloud)
    used = (ny - 1) * cloud.row_step + nx * cloud.point_step
    if cloud.row_step < nx * cloud.point_step or len(cloud.data) < used:
        raise RejectedInput("irregular_grid", f"{len(cloud.data)} bytes of data do not hold "
                            f"{ny} rows of {nx} points (point_step {cloud.point_step}, "
                            f"row_step {cloud.row_step})")
    if layout.cols is not None:
        size = layout.widths[0]
        words = np.frombuffer(cloud.data, dtype=layout.dtype, count=used // size)
        if not words.dtype.isnative:
            words = words.astype(words.dtype.newbyteorder("="))
        return words, cloud.row_step // size, cloud.point_step // size, layout.cols
    order = ">" if cloud.is_bigendian else "<"
    out = np.empty((ny, nx, 7))
    for k, (offset, width) in enumerate(zip(layout.offsets, layout.widths)):
        out[:, :, k] = np.ndarray((ny, nx), dtype=order + ("f4" if width == 4 else "f8"),
                                  buffer=cloud.data, offset=offset,
                                  strides=(cloud.row_step, cloud.point_step))
    return out.reshape(-1), 7 * nx, 7, _PLAIN_COLUMNS


_PLAIN_COLUMNS = np.arange(7, dtype=np.int64)


def words_of(cloud: Cloud) -> tuple[NDArray[Any], int, int, NDArray[np.int64]]:
    """Return the cloud's points for the adapter's loop: ``(words, row, step, cols)``.

    As the conversion reads them (see ``_words``); raises
    :class:`RejectedInput` for a layout or a buffer the conversion refuses.
    """
    return _words(cloud)


Axes = tuple[tuple[float, float, float], tuple[float, float, float],
             tuple[float, float, float]]


def contact_axes(normal: tuple[float, float, float]) -> Axes:
    """Return ``(e_x, e_y, e_z)`` of the contact frame for a normal (any length).

    ``e_z`` along the normal, ``e_x`` the wheelset's ``x`` projected on the
    contact plane, ``e_y = e_z x e_x``.  Raises ``degenerate`` for a zero
    normal or one along the wheelset's ``x``.
    """
    n0, n1, n2 = normal
    norm = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    if not norm > 0.0:
        raise RejectedInput("degenerate", "the cells' normals cancel out")
    ez = (n0 / norm, n1 / norm, n2 / norm)
    exx, exy, exz = 1.0 - ez[0] * ez[0], -ez[0] * ez[1], -ez[0] * ez[2]
    ex_norm = math.sqrt(exx * exx + exy * exy + exz * exz)
    if not ex_norm > 1e-6:
        raise RejectedInput("degenerate", "the contact normal lies along the wheelset's x")
    ex = (exx / ex_norm, exy / ex_norm, exz / ex_norm)
    ey = (ez[1] * ex[2] - ez[2] * ex[1], ez[2] * ex[0] - ez[0] * ex[2],
          ez[0] * ex[1] - ez[1] * ex[0])
    return ex, ey, ez


def _grid_axis(first: float, step: float, worst: float, n: int,
               what: str) -> tuple[float, float, int]:
    """Check one fitted grid axis; return ``(first, step, order)`` with ``step > 0``.

    ``order`` is -1 where the points run towards negative values
    (``first`` is then that of the reversed order).  A cell centre may lie
    ``GRID_TOLERANCE`` of a cell off its grid line.
    """
    if not abs(step) >= MIN_CELL_SIZE:
        raise RejectedInput("degenerate", f"cells {what} are {abs(step):.3g} m apart")
    if not worst <= GRID_TOLERANCE * abs(step):
        raise RejectedInput("irregular_grid", f"a cell centre lies {worst / abs(step):.3g} "
                            f"cells off the regular grid {what}")
    if step < 0.0:
        return first + step * (n - 1), -step, -1
    return first, step, 1


def patch_from_cloud(cloud: Cloud, *, max_cells: int) -> ContactPatch | None:
    """Convert a patch cloud; ``None`` for an empty patch (no positive pressure).

    ``max_cells``: the largest grid (``height * width``) accepted; larger is
    ``too_large``, checked before anything is read or allocated.  Raises
    :class:`RejectedInput` with its reason key (docs/guide_node.md) otherwise.
    """
    ny, nx = cloud.height, cloud.width
    if ny * nx > max_cells:
        raise RejectedInput("too_large", f"{ny} x {nx} cells exceed max_patch_cells = "
                            f"{max_cells}")
    if ny * nx == 0:
        _layout(cloud)
        if len(cloud.data):
            # a grid of no cells that carries points is malformed, not a lifted wheel: a
            # width of 0 over a whole patch's data was published as a zero wrench
            raise RejectedInput("irregular_grid", f"{len(cloud.data)} bytes of data for a "
                                f"grid of {ny} x {nx} points")
        return None
    words, row, step, cols = _words(cloud)
    pressure = np.empty((ny, nx))
    out = np.empty(kernels.OUT_SIZE)
    kernels.adapt(words, ny, nx, row, step, cols, pressure, out)
    (status, cells_, total, low, o0, o1, o2, ex0, ex1, ex2, ey0, ey1, ey2, ez0, ez1, ez2,
     fx0, fdx, worst_x, fy0, fdy, worst_y) = out.tolist()
    cells = int(cells_)
    if status == kernels.NONFINITE:
        raise RejectedInput("nonfinite", "NaN or infinite values in the patch")
    if status == kernels.NEGATIVE:
        raise RejectedInput("negative_pressure", f"pressure down to {low:.4g} Pa")
    if status == kernels.TOO_HIGH:
        raise RejectedInput("too_large", f"pressure up to {float(pressure.max()):.4g} Pa, "
                            f"above {kernels.MAX_PRESSURE:g} Pa")
    if cells == 0:
        return None
    if cells < MIN_CONTACT_CELLS or ny < 2 or nx < 2:
        raise RejectedInput("degenerate", f"{cells} cells in contact on a {ny} x {nx} grid "
                            f"(at least {MIN_CONTACT_CELLS} on a grid of 2 x 2 or more)")
    # origin: the pressure-weighted centroid; e_z along sum p n (contact_axes's checks)
    if status == kernels.ZERO_NORMAL:
        raise RejectedInput("degenerate", "the cells' normals cancel out")
    if status == kernels.NORMAL_ALONG_X:
        raise RejectedInput("degenerate", "the contact normal lies along the wheelset's x")
    # each checks the whole grid: x must not vary across strips, nor y along them
    x0, dx, column_order = _grid_axis(fx0, fdx, worst_x, nx, "along a strip")
    y0, dy, row_order = _grid_axis(fy0, fdy, worst_y, ny, "across the strips")
    cell_area = dx * dy
    load = total * cell_area
    if not (cell_area > 0.0 and math.isfinite(load) and load > 0.0):
        raise RejectedInput("degenerate", f"cell area {cell_area:.3g} m^2, load {load:.3g} N")
    if row_order < 0 or column_order < 0:
        pressure = np.ascontiguousarray(pressure[::row_order, ::column_order])
    frame = ContactFrame((o0, o1, o2), ((ex0, ex1, ex2), (ey0, ey1, ey2), (ez0, ez1, ez2)))
    return ContactPatch(cloud.stamp_ns, frame, pressure, x0, y0, dx, dy, load, cells,
                        row_order, column_order)


def warm_up() -> None:
    """Compile (or load from numba's disk cache) the adapter's loop for both float widths.

    Each width read-only too: the usual layout's words are a view of the
    message's buffer (read-only, its own numba specialisation), a copy
    (another byte order, gathered fields) is writeable.
    """
    for width in (np.float32, np.float64):
        for writeable in (False, True):
            words = np.zeros(4 * 7, dtype=width)
            words.setflags(write=writeable)
            kernels.adapt(words, 2, 2, 14, 7, _PLAIN_COLUMNS, np.empty((2, 2)),
                          np.empty(kernels.OUT_SIZE))


def planar_points(origin: tuple[float, float, float], axes: ContactFrame | None, x0: float,
                  y0: float, dx: float, dy: float, ny: int, nx: int) -> FloatArray:
    """Return cell centres ``(ny, nx, 3)`` of a grid in a contact plane, in the wheelset frame.

    ``axes``: a frame whose ``e_x, e_y`` span the plane (its origin is
    ignored; ``origin`` places cell ``(x, y) = (0, 0)``).  The inverse of
    the in-plane coordinates :func:`patch_from_cloud` derives.
    """
    (ex, ey, _) = (np.asarray(a, dtype=np.float64) for a in
                   (axes.axes if axes is not None else ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0),
                                                        (0.0, 0.0, 1.0))))
    xs = x0 + dx * np.arange(nx)
    ys = y0 + dy * np.arange(ny)
    return (np.asarray(origin, dtype=np.float64) + xs[None, :, None] * ex
            + ys[:, None, None] * ey)


def frame_from_normal(normal: tuple[float, float, float]) -> ContactFrame:
    """Return the contact frame for a ``normal`` (origin at 0)."""
    return ContactFrame((0.0, 0.0, 0.0), contact_axes(normal))


def cloud_bytes(points: FloatArray, normals: FloatArray, pressure: FloatArray, *,
                dtype: str = "<f4") -> tuple[list[tuple[str, int]], int, bytes]:
    """Return ``(fields, point_step, data)`` of a patch cloud in the node's input layout.

    ``points``, ``normals``: ``(ny, nx, 3)`` (a normal may be given once,
    shape ``(3,)``); ``pressure``: ``(ny, nx)`` (Pa); fields ``x y z
    normal_x normal_y normal_z pressure`` packed in that order with
    ``dtype`` (``<f4``, ``>f8``, ...).  ``fields``: ``(name, offset)``.
    """
    ny, nx = pressure.shape
    size = np.dtype(dtype).itemsize
    rec = np.empty((ny, nx, 7), dtype=dtype)
    rec[..., 0:3] = points
    rec[..., 3:6] = np.broadcast_to(normals, (ny, nx, 3))
    rec[..., 6] = pressure
    return [(name, k * size) for k, name in enumerate(PATCH_FIELDS)], 7 * size, rec.tobytes()
