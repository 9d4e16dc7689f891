"""The discrete steady-rolling operator of a grid: tractions to the slip they cause.

Kalker's steady rolling on a regular grid (uniform tractions on rectangular
cells, quasi-identical bodies, :mod:`~fastsim_ros.contact.influence`): the
slip per unit rolling distance is ``s = w - du/dx`` with ``du/dx`` the
*upstream* difference ``(u(x + dx) - u(x))/dx`` of the displacement
difference at the cell centres.  ``tau -> du/dx`` is a convolution on the
grid (the kernel depends on the offset between cells only), so it is kept as
its kernel, never as a matrix: a product costs two real FFTs of the grid
padded to at least ``2 n - 1`` cells per axis (no wrap-around), memory
proportional to the grid.  The dense matrix of the cells in contact and each
lateral strip's own block are built on demand, for the direct reference
solves and for the strip-block preconditioners.

Imports numpy, SciPy (its FFTs), :mod:`~fastsim_ros.contact.area`,
``checks``, ``errors`` and ``influence``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple

import numpy as np
import scipy.fft
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import check_material
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.influence import influence_kernel

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


@dataclass(frozen=True, eq=False)
class SteadyRollingOperator:
    """The discrete operator ``tau -> du/dx`` (upstream difference) of a grid.

    ``kernel_*[dj, di]`` hold ``(K(d + e_x) - K(d))/dx`` for offsets
    ``di in [-(nx-1), nx-1]``, ``dj in [-(ny-1), ny-1]`` (field minus source),
    ``K`` the rectangle influence coefficients.  Units 1/Pa.
    """

    area: GridArea
    nu: float
    shear_modulus: float
    kernel_xx: FloatArray
    kernel_yy: FloatArray
    kernel_xy: FloatArray

    @classmethod
    def of(cls, area: GridArea, *, nu: float, shear_modulus: float) -> SteadyRollingOperator:
        """Build the operator of ``area``'s grid; ``shear_modulus``: combined ``G`` (Pa)."""
        check_material(nu, shear_modulus)
        nx, ny = area.nx, area.ny
        k = influence_kernel(area.dx, area.dy, nx, ny - 1, shear_modulus=shear_modulus, nu=nu)

        def diff(c: FloatArray) -> FloatArray:
            # columns are di = -nx..nx; d + e_x for di in [-(nx-1), nx-1] is columns 2..2nx
            return (c[:, 2:] - c[:, 1:-1]) / area.dx

        return cls(area, nu, shear_modulus, diff(k.xx), diff(k.yy), diff(k.xy))

    @property
    def diagonal(self) -> tuple[float, float]:
        """``(D_x, D_y)``: minus the self-coefficients, ``> 0`` (1/Pa)."""
        cy, cx = self.area.ny - 1, self.area.nx - 1
        return -float(self.kernel_xx[cy, cx]), -float(self.kernel_yy[cy, cx])

    def dense(self) -> FloatArray:
        """Return the operator restricted to the contact cells, ``[[Bxx, Bxy], [Bxy, Byy]]``."""
        jj, ii = np.nonzero(self.area.mask)
        dj = jj[:, None] - jj[None, :] + self.area.ny - 1
        di = ii[:, None] - ii[None, :] + self.area.nx - 1
        bxx = self.kernel_xx[dj, di]
        byy = self.kernel_yy[dj, di]
        bxy = self.kernel_xy[dj, di]
        return np.block([[bxx, bxy], [bxy, byy]])

    def strip_blocks(self) -> list[StripBlock]:
        """Return each lateral strip's own block of the operator, strip by strip.

        Per strip with cells in contact (:class:`StripBlock`): their indices
        among the contact cells (row-major, as :meth:`dense` orders them), the
        ``xx`` and ``yy`` blocks between them (``K_xy`` vanishes within a
        strip, ``dj = 0``), and the strip's pattern of cells (bytes), which
        strips of one pattern share along with their block arrays.
        """
        return self.segment_blocks(None)

    def segment_blocks(self, longest: int | None) -> list[StripBlock]:
        """Return the strips' own blocks with no strip longer than ``longest`` cells.

        A strip with more cells in contact than ``longest`` is cut into
        consecutive segments of nearly equal length (``None``: whole strips,
        :meth:`strip_blocks`), so that the blocks' memory stays proportional
        to the cells in contact (at most ``4 longest`` numbers a cell).
        """
        mask = self.area.mask
        flat = np.cumsum(mask.ravel()).reshape(mask.shape) - 1
        row_x = self.kernel_xx[self.area.ny - 1]
        row_y = self.kernel_yy[self.area.ny - 1]
        cache: dict[bytes, tuple[FloatArray, FloatArray]] = {}
        blocks = []
        for j in range(self.area.ny):
            row = np.flatnonzero(mask[j])
            if row.size == 0:
                continue
            parts = 1 if longest is None else -(-row.size // longest)
            for cols in np.array_split(row, parts):
                key = (cols - cols[0]).tobytes()
                if key not in cache:
                    d = cols[:, None] - cols[None, :] + self.area.nx - 1
                    cache[key] = (row_x[d], row_y[d])
                blocks.append(StripBlock(flat[j, cols], *cache[key], key))
        return blocks

    def check_matches(self, area: GridArea, nu: float, shear_modulus: float) -> None:
        """Refuse to serve ``area`` and the material if this operator was built for others."""
        mine = self.area
        if mine is not area and not (
                (mine.nx, mine.ny, mine.dx, mine.dy) == (area.nx, area.ny, area.dx, area.dy)
                and np.array_equal(mine.mask, area.mask)):
            raise InvalidInputError("the operator was built for another grid or set of cells "
                                    "in contact than the area's")
        if (self.nu, self.shear_modulus) != (nu, shear_modulus):
            raise InvalidInputError(f"the operator was built for nu = {self.nu}, G = "
                                    f"{self.shear_modulus} Pa, not nu = {nu}, G = "
                                    f"{shear_modulus} Pa")

    def fft_product(self) -> FFTProduct:
        """FFT-based product with tractions on the whole grid (built once per operator)."""
        return self._product

    @cached_property
    def _product(self) -> FFTProduct:
        return FFTProduct(self)


class StripBlock(NamedTuple):
    """One lateral strip's own block of the operator (:meth:`SteadyRollingOperator.strip_blocks`).

    ``idx``: the strip's cells among the contact cells; ``xx``, ``yy``: the
    blocks (1/Pa); ``pattern``: the strip's cells relative to its first (the
    key under which strips of one pattern share ``xx`` and ``yy``).
    """

    idx: IntArray
    xx: FloatArray
    yy: FloatArray
    pattern: bytes


class FFTProduct:
    """The operator's product through FFTs: the kernel's spectrum on a padded grid.

    The Toeplitz operator is embedded in a circulant one on ``Ly`` x ``Lx``
    points, ``L >= 2 n - 1`` per axis and chosen for a fast FFT (offset ``d``
    at index ``d mod L``): the circular convolution of the zero-padded
    tractions then equals the linear one on the first ``ny`` x ``nx`` points.
    One thread: the grids here are small, and the machine is shared.
    """

    def __init__(self, op: SteadyRollingOperator) -> None:
        ny, nx = op.area.ny, op.area.nx
        self.ny, self.nx = ny, nx
        self.shape = (scipy.fft.next_fast_len(2 * ny - 1),
                      scipy.fft.next_fast_len(2 * nx - 1, real=True))
        rows = np.mod(np.arange(-(ny - 1), ny), self.shape[0])
        cols = np.mod(np.arange(-(nx - 1), nx), self.shape[1])
        spectra = []
        for kernel in (op.kernel_xx, op.kernel_xy, op.kernel_yy):
            c = np.zeros(self.shape)
            c[np.ix_(rows, cols)] = kernel
            spectra.append(scipy.fft.rfft2(c, workers=1))
        self.fxx, self.fxy, self.fyy = spectra
        mask = op.area.mask
        self.cells = np.nonzero(mask)
        self._grid = np.zeros((2, ny, nx))

    def __call__(self, tx: FloatArray, ty: FloatArray) -> tuple[FloatArray, FloatArray]:
        """``(du_x/dx, du_y/dx)`` on the grid for tractions ``tx``, ``ty`` (ny, nx)."""
        g = self._grid_product(np.stack([tx, ty]))
        return g[0, : self.ny, : self.nx], g[1, : self.ny, : self.nx]

    def on_cells(self, tau: FloatArray) -> FloatArray:
        """``du/dx`` (m, 2) on the cells in contact for their tractions ``tau`` (m, 2)."""
        jj, ii = self.cells
        self._grid[:, jj, ii] = tau.T
        g = self._grid_product(self._grid)
        return np.ascontiguousarray(g[:, jj, ii].T)

    def _grid_product(self, t: FloatArray) -> FloatArray:
        f = scipy.fft.rfft2(t, s=self.shape, workers=1)
        out = np.empty_like(f)
        np.multiply(self.fxx, f[0], out=out[0])
        out[0] += self.fxy * f[1]
        np.multiply(self.fxy, f[0], out=out[1])
        out[1] += self.fyy * f[1]
        return scipy.fft.irfft2(out, s=self.shape, workers=1)
