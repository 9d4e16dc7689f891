"""Contact areas discretised on a regular grid of rectangular cells.

A :class:`GridArea` is the common currency of the exact solver, FastSim and
MAE: cell centres ``x[i]`` (rolling direction, leading edge at larger ``x``)
and ``y[j]`` (lateral), arrays indexed ``[j, i]`` so that each row is one
lateral strip marched along ``x`` (the layout of the node's organised point
clouds), and the normal pressure on each cell.  A cell is in contact where
its pressure is positive (docs/guide_physics.md "FastSim").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.checks import check_positive
from fastsim_ros.contact.errors import (EmptyContactError, GridTooLargeError,
                                        InvalidInputError, IrregularGridError)

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class GridArea:
    """A contact area on a regular grid.

    ``x0``, ``y0``: centre of cell ``[0, 0]`` (m); ``dx``, ``dy``: cell size
    (m); ``pressure``: normal pressure (Pa), shape ``(ny, nx)``, zero outside
    the contact.  Areas made for coefficients only carry a unit pressure.
    """

    x0: float
    y0: float
    dx: float
    dy: float
    pressure: FloatArray

    def __post_init__(self) -> None:
        p = np.asarray(self.pressure, dtype=float)
        if p.ndim != 2:
            raise InvalidInputError("pressure must be a 2-D array (rows = lateral strips)")
        values = (self.x0, self.y0, self.dx, self.dy)
        if not all(math.isfinite(v) for v in values) or not np.all(np.isfinite(p)):
            raise InvalidInputError("grid or pressure has NaN or infinite values")
        if self.dx <= 0.0 or self.dy <= 0.0:
            raise InvalidInputError("cell sizes must be positive")
        if np.any(p < 0.0):
            raise InvalidInputError("negative pressure")
        if not np.any(p > 0.0):
            raise EmptyContactError("no cell in contact (no positive pressure)")
        p = p.copy()
        p.setflags(write=False)
        object.__setattr__(self, "pressure", p)

    @property
    def ny(self) -> int:
        """Return the number of lateral strips (rows)."""
        return int(self.pressure.shape[0])

    @property
    def nx(self) -> int:
        """Return the number of cells along the rolling direction (columns)."""
        return int(self.pressure.shape[1])

    @property
    def x(self) -> FloatArray:
        """Cell-centre coordinates along ``x`` (m), shape ``(nx,)``."""
        return self.x0 + self.dx * np.arange(self.nx, dtype=np.float64)

    @property
    def y(self) -> FloatArray:
        """Cell-centre coordinates along ``y`` (m), shape ``(ny,)``."""
        return self.y0 + self.dy * np.arange(self.ny, dtype=np.float64)

    @property
    def mask(self) -> NDArray[np.bool_]:
        """Cells in contact (positive pressure)."""
        return self.pressure > 0.0

    @property
    def cell_area(self) -> float:
        """Area of one cell (m^2)."""
        return self.dx * self.dy

    @property
    def area(self) -> float:
        """Return the discrete contact area in m^2, cells in contact times the cell area."""
        return float(np.count_nonzero(self.mask)) * self.cell_area

    @property
    def load(self) -> float:
        """Return the normal load ``N = sum p dA`` (N)."""
        return float(self.pressure.sum()) * self.cell_area

    def with_pressure(self, pressure: FloatArray) -> GridArea:
        """Return the same grid with another pressure field."""
        return GridArea(self.x0, self.y0, self.dx, self.dy, pressure)

    def with_load(self, load: float) -> GridArea:
        """Return the same pressure shape rescaled to total load ``load`` (N)."""
        if not (math.isfinite(load) and load > 0.0):
            raise InvalidInputError("load must be positive and finite")
        return self.with_pressure(self.pressure * (load / self.load))

    def mirrored_y(self) -> GridArea:
        """Return the mirror image in ``y`` (``y -> -y``)."""
        return GridArea(self.x0, -(self.y0 + self.dy * (self.ny - 1)), self.dx, self.dy,
                        self.pressure[::-1, :])

    def shifted(self, sx: float, sy: float) -> GridArea:
        """Return the area translated by ``(sx, sy)`` (m)."""
        return GridArea(self.x0 + sx, self.y0 + sy, self.dx, self.dy, self.pressure)

    def scaled(self, k: float) -> GridArea:
        """Return the area with all lengths scaled by ``k``; pressure unchanged."""
        return GridArea(self.x0 * k, self.y0 * k, self.dx * k, self.dy * k, self.pressure)

    def cropped(self) -> GridArea:
        """Return the area on the smallest grid that holds every cell in contact."""
        rows = np.flatnonzero(self.mask.any(axis=1))
        cols = np.flatnonzero(self.mask.any(axis=0))
        j0, j1, i0, i1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
        return GridArea(self.x0 + i0 * self.dx, self.y0 + j0 * self.dy, self.dx, self.dy,
                        self.pressure[j0:j1, i0:i1])


def _cell_centres(lo: float, hi: float, n: int) -> FloatArray:
    h = (hi - lo) / n
    return lo + h * (np.arange(n, dtype=np.float64) + 0.5)


def turned_grid(pressure: FloatArray, x0: float, y0: float, dx: float,
                dy: float) -> tuple[FloatArray, float, float]:
    """Return ``(pressure, x0, y0)`` of the grid turned by 180 degrees about ``z``.

    Reverse running (docs/guide_physics.md, rolling speed ``V < 0``) is
    solved on the patch turned so that its leading edge is at ``+x``: cell
    ``[j, i]`` goes to ``[ny - 1 - j, nx - 1 - i]`` (a view, not a copy) and
    cell ``[0, 0]``'s centre to minus the old last cell's.  The spin changes
    sign with it, the forces are turned back by the caller.
    """
    p = pressure[::-1, ::-1]
    return (p, -(x0 + (p.shape[1] - 1) * dx), -(y0 + (p.shape[0] - 1) * dy))


def _centres_in(grid: tuple[float, float, float, float],
                new_grid: tuple[float, float, float, float],
                shape: tuple[int, int]) -> tuple[NDArray[np.floating], NDArray[np.floating]]:
    """Return the new grid's cell centres as fractional ``(column, row)`` indices of ``grid``."""
    x0, y0, dx, dy = new_grid
    ny, nx = shape
    ox, oy, odx, ody = grid
    return (x0 + dx * np.arange(nx) - ox) / odx, (y0 + dy * np.arange(ny) - oy) / ody


def regridded(values: FloatArray, grid: tuple[float, float, float, float],
              new_grid: tuple[float, float, float, float],
              shape: tuple[int, int]) -> FloatArray:
    """Return ``values`` on ``grid`` ``(x0, y0, dx, dy)`` (m) at the cell centres of another.

    Bilinear between the four cells around each new centre, zero outside the
    old grid (the values taken to fall to zero over half a cell beyond its
    edge cells); ``shape``: the new grid's ``(ny, nx)``.
    """
    ony, onx = values.shape
    fi, fj = _centres_in(grid, new_grid, shape)
    # pad by one zero cell on each side: zero outside the old grid
    padded = np.zeros((ony + 2, onx + 2))
    padded[1:-1, 1:-1] = values
    i = np.clip(fi + 1.0, 0.0, onx + 1.0 - 1e-9)
    j = np.clip(fj + 1.0, 0.0, ony + 1.0 - 1e-9)
    i0 = np.minimum(np.floor(i).astype(np.int64), onx)
    j0 = np.minimum(np.floor(j).astype(np.int64), ony)
    wi = (i - i0)[None, :]
    wj = (j - j0)[:, None]
    a = padded[np.ix_(j0, i0)]
    b = padded[np.ix_(j0, i0 + 1)]
    c = padded[np.ix_(j0 + 1, i0)]
    d = padded[np.ix_(j0 + 1, i0 + 1)]
    out: FloatArray = (1 - wj) * ((1 - wi) * a + wi * b) + wj * ((1 - wi) * c + wi * d)
    return out


def nearest_cells(values: NDArray[np.bool_], grid: tuple[float, float, float, float],
                  new_grid: tuple[float, float, float, float],
                  shape: tuple[int, int]) -> NDArray[np.bool_]:
    """Return flags on ``grid`` at another grid's cell centres: the nearest cell's, False outside.

    As :func:`regridded` for values that do not interpolate (a cell's slip).
    """
    ony, onx = values.shape
    fi, fj = _centres_in(grid, new_grid, shape)
    i = np.rint(fi).astype(np.int64)
    j = np.rint(fj).astype(np.int64)
    inside = ((j >= 0) & (j < ony))[:, None] & ((i >= 0) & (i < onx))[None, :]
    out: NDArray[np.bool_] = values[np.ix_(np.clip(j, 0, ony - 1), np.clip(i, 0, onx - 1))]
    return out & inside


def ellipse(a: float, b: float, *, nx: int, ny: int | None = None,
            load: float | None = None, pressure: str = "hertz") -> GridArea:
    """Make an ellipse with semi-axes ``a`` (along x) and ``b`` (m) on ``nx`` x ``ny`` cells.

    The grid spans the bounding box ``[-a, a] x [-b, b]``.  Without ``load``
    the pressure is 1 Pa on every cell inside (coefficients only).  With a
    load (N), ``pressure="hertz"`` gives ``p0 sqrt(1 - x^2/a^2 - y^2/b^2)``
    and ``"parabolic"`` Kalker's ``1 - x^2/a^2 - y^2/b^2`` profile, both
    rescaled so that the discrete sum equals the load.
    """
    check_positive(a=a, b=b)
    ny = nx if ny is None else ny
    _check_cells(nx, ny)
    x = _cell_centres(-a, a, nx)
    y = _cell_centres(-b, b, ny)
    rho2 = (x[None, :] / a) ** 2 + (y[:, None] / b) ** 2
    inside = rho2 < 1.0
    if load is None:
        p = inside.astype(float)
    elif pressure == "hertz":
        p = np.sqrt(np.clip(1.0 - rho2, 0.0, None)) * inside
    elif pressure == "parabolic":
        p = np.clip(1.0 - rho2, 0.0, None) * inside
    else:
        raise InvalidInputError(f"unknown pressure profile {pressure!r}")
    area = GridArea(float(x[0]), float(y[0]), 2 * a / nx, 2 * b / ny, p)
    return area if load is None else area.with_load(load)


def semi_ellipse_axes(a_over_b: float) -> tuple[float, float]:
    """Semi-axes ``(a, b)`` (m) of the ellipse with ratio ``a/b`` and ``a b = 1/pi`` (area 1)."""
    check_positive(a_over_b=a_over_b)
    return math.sqrt(a_over_b / math.pi), 1.0 / math.sqrt(a_over_b * math.pi)


def semi_ellipses(g1: float, g2: float, *, cells: int) -> GridArea:
    """Make two semi-ellipses joined along ``y = 0`` (the paper's Table 5 family), unit pressure.

    Zone 1 (``y < 0``) is the lower half of the ellipse ``a1/b1 = g1``, zone 2
    (``y > 0``) the upper half of ``a2/b2 = g2``, with ``a_i b_i = 1/pi`` so the
    total area is 1 m^2.  The grid has ``cells`` cells along ``x`` across the
    wider half and about ``cells`` along ``y``, with a cell face on the join
    line.
    """
    a1, b1 = semi_ellipse_axes(g1)
    a2, b2 = semi_ellipse_axes(g2)
    _check_cells(cells, cells)
    amax = max(a1, a2)
    x = _cell_centres(-amax, amax, cells)
    dy = (b1 + b2) / cells
    n1 = max(1, math.ceil(b1 / dy - 1e-9))
    n2 = max(1, math.ceil(b2 / dy - 1e-9))
    y = dy * (np.arange(n1 + n2) - n1 + 0.5)
    xx, yy = x[None, :], y[:, None]
    inside = np.where(yy < 0.0, (xx / a1) ** 2 + (yy / b1) ** 2 < 1.0,
                      (xx / a2) ** 2 + (yy / b2) ** 2 < 1.0)
    return GridArea(float(x[0]), float(y[0]), 2 * amax / cells, dy, inside.astype(float))


def from_cells(x: FloatArray, y: FloatArray, pressure: FloatArray, *,
               rtol: float = 1e-6, max_cells: int | None = None) -> GridArea:
    """Make a grid area from scattered cell centres ``(x, y)`` (m) and their pressure (Pa).

    The centres must lie on one regular grid (any subset of it; absent cells
    are outside the contact).  Raises :class:`IrregularGridError` otherwise.
    ``max_cells``: the most cells the grid spanned by the centres may have;
    a larger one (a stray cell far from the others) raises
    :class:`GridTooLargeError` before anything of the grid's size is allocated.
    """
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    p = np.asarray(pressure, dtype=float).ravel()
    if not (x.size == y.size == p.size) or x.size == 0:
        raise InvalidInputError("x, y and pressure must have the same, non-zero length")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y)) and np.all(np.isfinite(p))):
        raise InvalidInputError("NaN or infinite value in the cells")
    if np.any(p < 0.0):
        raise InvalidInputError("negative pressure")
    ux, dx = _spacing(x, "x", rtol)
    uy, dy = _spacing(y, "y", rtol)
    for name, h, u in (("x", dx, ux), ("y", dy, uy)):
        if not (math.isfinite(h) and h > 0.0):
            # coordinates so close that their gaps underflow (1e-303 m apart): no grid
            raise IrregularGridError(f"no cell size along {name} can be found: the {name} "
                                     f"coordinates span {float(u[-1] - u[0]):.3g} m")
    # the grid's size from the spacing alone: no index array yet, nothing allocated
    nx = _span_cells(ux, dx)
    ny = _span_cells(uy, dy)
    limit = _INDEX_LIMIT if max_cells is None else min(int(max_cells), _INDEX_LIMIT)
    if nx * ny > limit:
        raise GridTooLargeError(
            f"the cells span a grid of {nx:.4g} x {ny:.4g} cells of {dx:.4g} m x {dy:.4g} m, "
            f"more than the {limit:,} allowed (a stray cell far from the others?)")
    dx, dy = _fitted_spacing(ux, dx), _fitted_spacing(uy, dy)
    ix = _grid_index(x, ux, dx, "x", rtol)
    iy = _grid_index(y, uy, dy, "y", rtol)
    grid = np.zeros((iy.max() + 1, ix.max() + 1))
    if np.unique(iy * grid.shape[1] + ix).size != ix.size:
        raise IrregularGridError("two cells share one grid position")
    grid[iy, ix] = p
    return GridArea(float(ux[0]), float(uy[0]), dx, dy, grid)


#: grid cells beyond which indices would not fit the integers numpy casts them to
_INDEX_LIMIT = 2**40


#: how far (in cells) a cell centre may lie off the regular grid through all of them
GRID_TOLERANCE = 0.01


def _spacing(v: FloatArray, name: str, rtol: float) -> tuple[FloatArray, float]:
    """Return the sorted distinct coordinates ``v`` and the grid spacing along them.

    The spacing is the most common gap between neighbouring coordinates (a
    stray point must not make a fine phantom grid).
    """
    u = np.unique(v)
    if u.size == 1:
        raise IrregularGridError(f"a single {name} coordinate: the cell size along {name} "
                                 "cannot be inferred")
    gaps = np.diff(u)
    tol = rtol * float(u[-1] - u[0])
    candidates = np.unique(np.round(gaps / max(tol, 1e-300)))
    counts = [np.count_nonzero(np.abs(gaps - c * tol) <= tol) for c in candidates]
    h = float(np.median(gaps[np.abs(gaps - candidates[int(np.argmax(counts))] * tol) <= tol]))
    return u, h


def _fitted_spacing(u: FloatArray, h: float) -> float:
    """Return the spacing of the grid through all the coordinates ``u`` (least squares).

    Coordinates written with a few digits (1.7143e-4 for 1.7142857e-4 m)
    have gaps that are each off, their median by as much, and the error of
    a spacing taken from one gap grows along the row (2e-6 m at the 70th
    cell of such a file, which was refused as irregular); the fit's does not.
    Called once the grid's size is known to be bounded.
    """
    k = np.rint((u - u[0]) / h)
    dk = k - k.mean()
    den = float(dk @ dk)
    fitted = float(dk @ (u - u.mean())) / den if den > 0.0 else h
    return fitted if math.isfinite(fitted) and fitted > 0.0 else h


def _span_cells(u: FloatArray, h: float) -> float:
    """Return the cells along one axis of the grid spacing ``h`` through the coordinates ``u``.

    A float, so that an absurd span (``inf`` included) compares with a
    bound instead of overflowing an integer.
    """
    n = float(u[-1] - u[0]) / h
    return math.floor(n + 0.5) + 1.0 if math.isfinite(n) else math.inf


def _grid_index(v: FloatArray, u: FloatArray, h: float, name: str,
                rtol: float) -> NDArray[np.int_]:
    """Integer grid indices of coordinates ``v`` on the spacing ``h`` from ``u[0]``.

    Every coordinate must lie on a multiple of the spacing, to within
    :data:`GRID_TOLERANCE` of a cell.
    """
    tol = rtol * float(u[-1] - u[0])
    k = (v - u[0]) / h
    idx = np.rint(k).astype(int)
    # the grid's own origin (the fit's, from all the coordinates): the first one's rounding
    # is not every coordinate's offset
    offset = float(np.mean((u - u[0]) / h - np.rint((u - u[0]) / h)))
    # off the grid by more than a hundredth of a cell (and the span's tolerance): irregular;
    # coordinates written to the micrometre are a few thousandths of a 0.2 mm cell off
    if np.max(np.abs(k - idx - offset)) * h > max(10 * tol, GRID_TOLERANCE * h):
        raise IrregularGridError(f"{name} coordinates are not on a regular grid "
                                 f"(spacing {h:.6g} m)")
    return idx


def _check_cells(nx: int, ny: int) -> None:
    if nx < 2 or ny < 2:
        raise InvalidInputError("a grid needs at least 2 cells along each axis")
