"""DLM: Kalker's deformation levelling method for FastSim's flexibilities on any area.

One of the ways, before MAE, to give FastSim flexibilities on a
non-elliptical area (the seed paper, Alonso & Giménez 2007, section 2, eqs. 4
and 5, Table 1, Figures 4 and 5).  The simplified theory says ``u = L tau``;
the exact theory gives the displacement of a traction through the
Boussinesq-Cerruti influence coefficients (eq. 4, here the closed-form
rectangle coefficients of :mod:`~fastsim_ros.contact.influence`, the
displacement difference of quasi-identical bodies).  DLM takes the
flexibility that levels the two, by least squares over the contact (eq. 5),
for the traction of the simplified theory itself, starting from the
full-slip traction and iterating until ``L`` no longer changes.

The formulation (the paper's text was not at hand; settled by the evidence
of docs/validation_seed.md, where it is compared with other readings):

- one flexibility per creepage: ``L1`` levels ``u_x`` against the traction
  of unit ``xi``, ``L2`` ``u_y`` against that of unit ``eta``, ``L3`` both
  components against that of unit spin (Kalker's FastSim uses ``L3`` in both
  spin terms);
- each displacement component may differ from ``L tau`` by a rigid
  translation, which a displacement field is only defined up to (without it
  ``L`` is the mean displacement's and C11 comes out half of Kalker's);
- the traction: FastSim's adhesion traction of the unit creepage on the
  area's cells (``tau_x = d``, ``tau_y = d``; spin about the centroid,
  ``(y d, -s3)``, ``d`` and ``s3`` FastSim's own sweep integrals), whose
  shape does not depend on ``L``: the iteration from the full-slip traction
  (``mu p`` along the rigid slip) is therefore converged after its first
  step (:func:`dlm_iteration` records it).

This reproduces the seed's Table 1 (its second numbers) at a/b = 1 and 10
within 2% on C11 and C22; at a/b = 0.1 it is 6 to 9% off, and C23 is not
reproduced at a/b = 10 (docs/validation_seed.md says by how much and why).

DLM + FastSim (:func:`dlm_fastsim`): Kalker's FastSim with DLM's ``L1, L2,
L3`` on the area's cells, sweep about the centroid.  numpy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.asm import (CalibratedFlexibility, FlexibilityMethod, centroid,
                                     strip_runs)
from fastsim_ros.contact.checks import check_material
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.fastsim import sweep_integrals
from fastsim_ros.contact.influence import influence_kernel

FloatArray = NDArray[np.float64]


class Displacements:
    """The displacement difference ``(u_x, u_y)`` (m) of tractions on a grid (Cerruti, eq. 4).

    Linear convolution of the rectangle influence coefficients by FFT on a
    ``2 ny`` x ``2 nx`` grid (numpy's FFT: no SciPy on this path).
    """

    def __init__(self, area: GridArea, *, nu: float, shear_modulus: float) -> None:
        ny, nx = area.ny, area.nx
        k = influence_kernel(area.dx, area.dy, nx - 1, ny - 1, shear_modulus=shear_modulus,
                             nu=nu)
        self.shape = (2 * ny, 2 * nx)
        self.ny, self.nx = ny, nx
        self.fxx, self.fyy, self.fxy = (self._spectrum(c) for c in (k.xx, k.yy, k.xy))

    def _spectrum(self, kernel: FloatArray) -> NDArray[np.complex128]:
        ny, nx = self.ny, self.nx
        c = np.zeros(self.shape)
        # offset d at index d mod 2n: the product is the linear convolution on the first block
        rows = np.r_[np.arange(ny), np.arange(ny + 1, 2 * ny)]
        cols = np.r_[np.arange(nx), np.arange(nx + 1, 2 * nx)]
        c[np.ix_(rows, cols)] = np.roll(np.roll(kernel, -(ny - 1), axis=0), -(nx - 1), axis=1)
        return np.fft.rfft2(c)

    def __call__(self, tau_x: FloatArray, tau_y: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Return ``(u_x, u_y)`` on the grid for tractions ``tau_x``, ``tau_y`` (Pa)."""
        fx = np.fft.rfft2(tau_x, s=self.shape)
        fy = np.fft.rfft2(tau_y, s=self.shape)
        ux = np.fft.irfft2(self.fxx * fx + self.fxy * fy, s=self.shape)
        uy = np.fft.irfft2(self.fxy * fx + self.fyy * fy, s=self.shape)
        return ux[: self.ny, : self.nx], uy[: self.ny, : self.nx]


def level(displacements: list[FloatArray], tractions: list[FloatArray],
          mask: NDArray[np.bool_], weight: FloatArray | None = None) -> float:
    """Return the ``L`` (m/Pa) that levels ``u ~ L tau + c`` by least squares over ``mask``.

    One ``L`` for the listed components, a free translation ``c`` per
    component: ``L = sum cov(u, tau) / sum var(tau)`` over the cells (each
    cell weighted by ``weight`` if given, else equally); ``nan`` where the
    traction is uniform (a rigid translation itself: nothing to level, as
    the full-slip traction of a uniform pressure).
    """
    w = np.ones(int(np.count_nonzero(mask))) if weight is None else weight[mask]
    num = den = 0.0
    for u, t in zip(displacements, tractions):
        uu = u[mask] - float((w * u[mask]).sum()) / float(w.sum())
        tt = t[mask] - float((w * t[mask]).sum()) / float(w.sum())
        num += float((w * uu * tt).sum())
        den += float((w * tt * tt).sum())
    return num / den if den > 0.0 else math.nan


#: the levelling's weights: ``area`` (every cell alike: the least squares over the area, the
#: package's reading) or ``chord`` (every cell by the length of its strip, the run of cells
#: along ``x`` it belongs to; exploration: docs/validation_seed.md, section 1)
WEIGHTINGS = ("area", "chord")


def strip_chords(area: GridArea) -> FloatArray:
    """Return, on every cell in contact, the length of its strip (its run along ``x``, m)."""
    out = np.zeros(area.mask.shape)
    for j, i0, i1 in zip(*strip_runs(area.mask)):
        out[j, i0:i1] = (i1 - i0) * area.dx
    return out


def _weights(area: GridArea, weighting: str) -> FloatArray | None:
    if weighting == "area":
        return None
    if weighting == "chord":
        return strip_chords(area)
    raise ValueError(f"weighting must be one of {WEIGHTINGS}, got {weighting!r}")


@dataclass(frozen=True)
class DlmIteration:
    """The levelled ``L1, L2, L3`` (m/Pa) after each step, from the full-slip traction on."""

    l1: tuple[float, ...]
    l2: tuple[float, ...]
    l3: tuple[float, ...]


def _unit_tractions(area: GridArea, x_c: float, y_c: float,
                    full_slip: bool) -> tuple[tuple[FloatArray, FloatArray], ...]:
    """Return the tractions (shape only) of unit xi, eta and spin about the centroid."""
    mask = area.mask
    zero = np.zeros(mask.shape)
    x = area.x[None, :] - x_c
    y = area.y[:, None] - y_c
    if full_slip:
        # mu p along the rigid slip (its magnitude cancels in the levelling)
        p = np.where(mask, area.pressure, 0.0)
        r = np.hypot(x, y)
        r = np.where(r > 0.0, r, 1.0)
        return (p, zero), (zero, p), (-p * y / r, p * x / r)
    d, s3 = sweep_integrals(area, x_c)
    d = np.where(mask, d, 0.0)
    # FastSim's adhesion traction of unit creepage, up to -1/L (which the levelling drops)
    return (d, zero), (zero, d), (np.where(mask, -y * d, 0.0), np.where(mask, s3, 0.0))


def dlm_iteration(area: GridArea, *, nu: float, shear_modulus: float,
                  steps: int = 3, weighting: str = "area") -> DlmIteration:
    """Return the levelled flexibilities after each of ``steps`` steps from the full slip.

    Step 0 levels the full-slip traction; every later step the adhesion
    traction of the simplified theory with the previous ``L``, whose shape
    does not depend on ``L``: so step 1 is the converged value.
    ``weighting``: one of :data:`WEIGHTINGS`.
    """
    check_material(nu, shear_modulus)
    weight = _weights(area, weighting)
    x_c, y_c = centroid(area)
    disp = Displacements(area, nu=nu, shear_modulus=shear_modulus)
    mask = area.mask
    hist: list[list[float]] = [[], [], []]
    for step in range(steps):
        unit = _unit_tractions(area, x_c, y_c, full_slip=step == 0)
        for k, (tx, ty) in enumerate(unit):
            ux, uy = disp(tx, ty)
            if k == 0:
                lk = level([ux], [tx], mask, weight)
            elif k == 1:
                lk = level([uy], [ty], mask, weight)
            else:
                lk = level([ux, uy], [tx, ty], mask, weight)
            hist[k].append(lk)
    return DlmIteration(tuple(hist[0]), tuple(hist[1]), tuple(hist[2]))


def dlm_flexibility(area: GridArea, *, nu: float, shear_modulus: float,
                    weighting: str = "area") -> CalibratedFlexibility:
    """Return DLM's converged ``L1, L2, L3`` (m/Pa) of ``area``, sweep point its centroid.

    ``weighting``: one of :data:`WEIGHTINGS` (``area``, the package's reading).
    """
    it = dlm_iteration(area, nu=nu, shear_modulus=shear_modulus, steps=2, weighting=weighting)
    x_c, y_c = centroid(area)
    for l_k in (it.l1[-1], it.l2[-1], it.l3[-1]):
        if not (math.isfinite(l_k) and l_k > 0.0):
            # a patch too thin to level (one loaded cell, a single column or row): the
            # area's fault, told as such (a plain ValueError was the CLI's internal error)
            raise InvalidInputError("DLM's levelling gave no positive flexibility: the patch "
                                    "is too thin for it (one cell or one line of cells)")
    return CalibratedFlexibility(it.l1[-1], it.l2[-1], it.l3[-1], x_c, y_c)


def dlm_chord_flexibility(area: GridArea, *, nu: float,
                          shear_modulus: float) -> CalibratedFlexibility:
    """Return DLM's ``L1, L2, L3`` levelled with every cell weighted by its strip's length."""
    return dlm_flexibility(area, nu=nu, shear_modulus=shear_modulus, weighting="chord")


#: DLM + FastSim
DLM_FASTSIM = FlexibilityMethod(dlm_flexibility)
#: DLM + FastSim with the chord-weighted levelling (a named option: docs/validation_seed.md)
DLM_CHORD_FASTSIM = FlexibilityMethod(dlm_chord_flexibility)
#: DLM + FastSim: solve (forces in N, ``Mz`` about ``reference``; ``flexibility``: the result
#: of :func:`dlm_flexibility`, to reuse over many creepages)
dlm_fastsim = DLM_FASTSIM.solve
#: DLM + FastSim's generalised coefficients in full adhesion about ``reference``
dlm_coefficients = DLM_FASTSIM.coefficients
