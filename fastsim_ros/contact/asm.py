"""ASM: Knothe and Hung's asymptotic strip method for the creep coefficients of any area.

One of the ways, before MAE, to give FastSim flexibilities on a
non-elliptical area (the seed paper, Alonso & Giménez 2007, section 2 and
Table 2; Knothe and Le The Hung): solve the linear (full-adhesion) rolling
problem approximately, strip by strip, and take the creep coefficients from
it.  As the package reads the method from its published descriptions:

- the area is cut into strips along the rolling direction (the grid's rows;
  a row with a gap holds one strip per segment), each of its own width;
- in each strip the traction is quadratic in the distance from the strip's
  leading edge and vanishes there, ``tau = A1 s + A2 s^2`` (``s = (x_l -
  x)/(x_l - x_t)``), for each of ``tau_x``, ``tau_y``: four coefficients per
  strip, constant across its width;
- full adhesion is imposed at two points per strip on its centre line, at
  ``s = ASM_COLLOCATION`` (fractions of its length from the leading edge):
  ``du/dx = w`` for both components, the displacement difference of the
  Boussinesq-Cerruti half-spaces (as the exact theory's, docs/guide_physics.md) of all
  strips' tractions; four equations per strip, one dense linear system;
- the two points are placed to minimise the error on ellipses (against
  Kalker's coefficients, nu = 0.25; ``scripts/validate_seed.py`` fits them on
  a/b = 0.2, 0.5, 1, 2, 5 and checks every other entry of his table and nu
  = 0 and 0.5, docs/validation_seed.md).

What this does not reproduce: the seed's Table 2 prints ASM's own
coefficients, 0-8% below Kalker's; these points give Kalker's (within 2% for
0.1 <= a/b <= 3.3, 4% at 5 and 10), not the printed ASM.  Knothe and Hung's
own ansatz and collocation could not be established (their text was not at
hand): of the readings tried in ``scripts/asm_candidates.py`` (quadratic,
2-D full-adhesion and Hertz-like strip tractions, natural and Gauss-Chebyshev
placements) none reproduces the printed columns within 2%, and none gives
the printed C23 at a/b = 0.1 (docs/validation_seed.md, section 2).  So the
fitted points stay the default: they make ASM an accurate strip method.

``du_i/dx`` of a strip's traction ``f(x')`` at ``(x, y)``, integrated by
parts along the strip (``f(x_l) = 0``): ``M_ij(x - x_t) f(x_t) + int M_ij(x
- x') f'(x') dx'``, ``M`` the kernels integrated across the strip's width
in closed form (:func:`~fastsim_ros.contact.influence.line_influence`); the
remaining integral by Gauss-Legendre on either side of ``x' = x`` with
``x' = x +- (.) t^2`` (the kernels' logarithmic singularity at the point's
own strip is then smooth in ``t``).

ASM + FastSim (:func:`asm_fastsim`): Kalker's FastSim with one ``L1, L2,
L3`` on the area, calibrated on its cells so that in full adhesion it gives
ASM's ``C~11, C~22, C~23`` about the centroid (the calibrated MAE's rule 2
for one zone); the couplings ``C~12``, ``C~13``, ``C~21`` are left out, as
in FastSim.  numpy only (no compiled path): a solve costs a dense system of
``4 x strips``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.checks import check_material
from fastsim_ros.contact.coefficients import (UNIT_CREEPAGES, CreepCoefficients,
                                              coefficients_from_unit_solutions,
                                              coefficients_of_solver)
from fastsim_ros.contact.equivalent import reduce_slope
from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.fastsim import (StripFlexibility, fastsim, sweep_integrals,
                                         traction_bound)
from fastsim_ros.contact.friction import FrictionLaw
from fastsim_ros.contact.influence import line_influence
from fastsim_ros.contact.tables import coefficient_table
from fastsim_ros.contact.traction import Tractions

FloatArray = NDArray[np.float64]

#: the two collocation points of a strip, as fractions of its length from the leading edge,
#: fitted by ``scripts/validate_seed.py --fit-asm`` (least squares of the relative errors of
#: C11, C22, C23 against Kalker's published table at nu = 0.25, a/b = 0.2, 0.5, 1, 2, 5;
#: 60 strips; rms 1.3%)
ASM_COLLOCATION = (0.0883, 0.6923)
#: Gauss-Legendre points on each side of a collocation point's own position along a strip
QUADRATURE_POINTS = 16
#: the most strips (segments of rows) ASM solves: its dense system has 4 unknowns per strip
#: (800 strips: a 3200 x 3200 system and about 0.2 GB of kernel arrays), checked before
#: anything of that size is allocated
MAX_STRIPS = 800


@dataclass(frozen=True)
class Strips:
    """The strips (segments of the grid's rows): centre ``y``, width ``dy``, ends ``x_t < x_l``.

    Arrays of one value per strip (m).
    """

    y: FloatArray
    dy: FloatArray
    x_t: FloatArray
    x_l: FloatArray


Runs = tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.intp]]


def strip_runs(mask: NDArray[np.bool_]) -> Runs:
    """Return each run of cells in contact along a row: its row, first and one-past-last column.

    Row-major, as :func:`numpy.nonzero` walks (so the starts and ends pair up).
    """
    edges = np.diff(np.pad(mask.astype(np.int8), ((0, 0), (1, 1))), axis=1)
    rows, starts = np.nonzero(edges == 1)
    _, ends = np.nonzero(edges == -1)
    return rows, starts, ends


def area_strips(area: GridArea) -> Strips:
    """Return the strips of ``area``: each run of cells in contact along a row, face to face."""
    rows, starts, ends = strip_runs(area.mask)
    x0 = area.x0 - 0.5 * area.dx
    return Strips(area.y[rows], np.full(rows.size, area.dy),
                  (x0 + area.dx * starts).astype(np.float64),
                  (x0 + area.dx * ends).astype(np.float64))


def ellipse_strips(a: float, b: float, strips: int) -> Strips:
    """Return ``strips`` strips of equal width across an ellipse, chords exact (m)."""
    dy = 2.0 * b / strips
    y = -b + dy * (np.arange(strips, dtype=np.float64) + 0.5)
    half = a * np.sqrt(np.clip(1.0 - (y / b) ** 2, 0.0, None))
    return Strips(y, np.full(strips, dy), -half, half)


def influence_matrix(strips: Strips, *, nu: float,
                     collocation: tuple[float, float] = ASM_COLLOCATION,
                     shear_modulus: float = 1.0) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Return ASM's system ``A c = w`` and its collocation points ``(x, y)`` (m).

    Unknowns per strip ``k``: ``c[4k:4k+4] = (A1x, A2x, A1y, A2y)`` (Pa);
    rows: ``du_x/dx`` at every point, then ``du_y/dx`` (points ``p = m S +
    k``, ``m`` the collocation index, ``S`` the number of strips).
    """
    s1, s2 = collocation
    if strips.y.size > MAX_STRIPS:
        raise InvalidInputError(f"ASM takes at most {MAX_STRIPS} strips (row segments), the "
                                f"area has {strips.y.size}")
    if not 0.0 <= s1 < s2 <= 1.0:
        raise InvalidInputError(f"collocation fractions must satisfy 0 <= s1 < s2 <= 1, got "
                                f"{collocation}")
    y, dy, x_t, x_l = strips.y, strips.dy, strips.x_t, strips.x_l
    h = x_l - x_t
    xp = np.concatenate([x_l - s * h for s in collocation])[:, None]
    yp = np.concatenate([y, y])[:, None]
    y_lo = yp - (y + 0.5 * dy)[None, :]
    y_hi = yp - (y - 0.5 * dy)[None, :]
    xt, xl, hh = x_t[None, :], x_l[None, :], h[None, :]
    g = shear_modulus

    def kernels(x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        return line_influence(x, y_lo, y_hi, shear_modulus=g, nu=nu)

    # the trailing end's term, f(x_t) = 1 for both bases s and s^2
    bxx, byy, bxy = kernels(xp - xt)
    npts, ns = xp.shape[0], y.size
    acc = {k: np.zeros((npts, ns)) for k in ("xx1", "xx2", "yy1", "yy2", "xy1", "xy2")}
    t, w = np.polynomial.legendre.leggauss(QUADRATURE_POINTS)
    t, w = 0.5 * (t + 1.0), 0.5 * w
    split = np.clip(xp, xt, xl)
    for end in (xt, xl):
        length = np.abs(end - split)
        for tq, wq in zip(t, w):
            xq = split + (end - split) * tq * tq
            weight = wq * 2.0 * length * tq
            kxx, kyy, kxy = kernels(xp - xq)
            # f' of the bases s = (x_l - x)/h and s^2
            d1 = -weight / hh
            d2 = -2.0 * (xl - xq) / (hh * hh) * weight
            acc["xx1"] += kxx * d1
            acc["xx2"] += kxx * d2
            acc["yy1"] += kyy * d1
            acc["yy2"] += kyy * d2
            acc["xy1"] += kxy * d1
            acc["xy2"] += kxy * d2
    a = np.zeros((2 * npts, 4 * ns))
    a[:npts, 0::4] = bxx + acc["xx1"]
    a[:npts, 1::4] = bxx + acc["xx2"]
    a[:npts, 2::4] = bxy + acc["xy1"]
    a[:npts, 3::4] = bxy + acc["xy2"]
    a[npts:, 0::4] = bxy + acc["xy1"]
    a[npts:, 1::4] = bxy + acc["xy2"]
    a[npts:, 2::4] = byy + acc["yy1"]
    a[npts:, 3::4] = byy + acc["yy2"]
    return a, xp[:, 0], yp[:, 0]


def unit_forces(strips: Strips, *, nu: float, reference: tuple[float, float] = (0.0, 0.0),
                collocation: tuple[float, float] = ASM_COLLOCATION
                ) -> tuple[tuple[float, float, float], ...]:
    """Return ASM's ``(Fx, Fy, Mz)`` (G = 1 Pa) at unit ``xi``, ``eta`` and ``phi`` (1/m).

    Creepages and ``Mz`` about ``reference`` (m).
    """
    a, xp, yp = influence_matrix(strips, nu=nu, collocation=collocation)
    rhs = np.array([np.concatenate([xi - phi * (yp - reference[1]),
                                    eta + phi * (xp - reference[0])])
                    for xi, eta, phi in UNIT_CREEPAGES]).T
    coef = np.linalg.solve(a, rhs)
    h = strips.x_l - strips.x_t
    # integrals over a strip of s and s^2, and of x s and x s^2 (x = x_l - h s)
    i1, i2 = 0.5 * h, h / 3.0
    m1 = h * (0.5 * strips.x_l - h / 3.0)
    m2 = h * (strips.x_l / 3.0 - 0.25 * h)
    out = []
    for k in range(coef.shape[1]):
        c = coef[:, k]
        fx = strips.dy * (c[0::4] * i1 + c[1::4] * i2)
        fy = strips.dy * (c[2::4] * i1 + c[3::4] * i2)
        x_fy = strips.dy * (c[2::4] * m1 + c[3::4] * m2)
        mz = x_fy - reference[0] * fy - (strips.y - reference[1]) * fx
        out.append((float(fx.sum()), float(fy.sum()), float(mz.sum())))
    return tuple(out)


def asm_coefficients(area: GridArea, *, nu: float,
                     reference: tuple[float, float] = (0.0, 0.0),
                     collocation: tuple[float, float] = ASM_COLLOCATION) -> CreepCoefficients:
    """Return ASM's generalised coefficients of ``area`` about ``reference`` (m).

    Normalised with the area of the strips (the cells in contact).
    """
    check_material(nu, 1.0)
    return coefficients_from_unit_solutions(
        area.area, unit_forces(area_strips(area), nu=nu, reference=reference,
                               collocation=collocation), reference=reference)


def ellipse_coefficients(a_over_b: float, *, nu: float, strips: int = 60,
                         collocation: tuple[float, float] = ASM_COLLOCATION
                         ) -> CreepCoefficients:
    """Return ASM's coefficients of an ellipse (exact chords, ``strips`` strips, area 1)."""
    check_material(nu, 1.0)
    if not (math.isfinite(a_over_b) and a_over_b > 0.0):
        raise InvalidInputError(f"a/b must be positive, got {a_over_b}")
    b = 1.0 / math.sqrt(math.pi * a_over_b)
    return coefficients_from_unit_solutions(
        1.0, unit_forces(ellipse_strips(a_over_b * b, b, strips), nu=nu,
                         collocation=collocation))


@dataclass(frozen=True)
class CalibratedFlexibility:
    """One ``L1, L2, L3`` (m/Pa) for the whole area and the sweep point ``(x_c, y_c)`` (m)."""

    l1: float
    l2: float
    l3: float
    x_c: float
    y_c: float

    def strips(self, area: GridArea) -> StripFlexibility:
        """Return the flexibilities of every strip (Kalker's FastSim: spin via ``L3``)."""
        ones = np.ones(area.ny)
        return StripFlexibility(self.l1 * ones, self.l2 * ones, self.l3 * ones,
                                self.l3 * ones)


def centroid(area: GridArea) -> tuple[float, float]:
    """Return the centroid of the cells in contact (m)."""
    jj, ii = np.nonzero(area.mask)
    return float(area.x[ii].mean()), float(area.y[jj].mean())


def calibrated_flexibility(area: GridArea, c11: float, c22: float, c23: float,
                           shear_modulus: float) -> CalibratedFlexibility:
    """Return the ``L1, L2, L3`` with which FastSim gives ``C~11, C~22, C~23`` on ``area``.

    The coefficients about the centroid; FastSim's full-adhesion traction is
    ``tau_x = -(xi/L1) d``, ``tau_y = -(eta/L2) d - (phi/L3) s3``, so ``L1 =
    D1/(G (A/pi) C~11)``, ``L2 = D1/(G (A/pi) C~22)``, ``L3 = D3/(G
    (A/pi)^1.5 C~23)`` with ``D1 = sum d dA``, ``D3 = sum s3 dA``.
    """
    x_c, y_c = centroid(area)
    d, s3 = sweep_integrals(area, x_c)
    da = area.cell_area
    d1 = float(d.sum()) * da
    d3 = float(s3.sum()) * da
    ab = area.area / math.pi
    g = shear_modulus
    if not (c11 > 0.0 and c22 > 0.0 and c23 > 0.0 and d3 > 0.0):
        raise InvalidInputError("the area's coefficients give no positive flexibility "
                                f"(C11 {c11:g}, C22 {c22:g}, C23 {c23:g})")
    return CalibratedFlexibility(d1 / (g * ab * c11), d1 / (g * ab * c22),
                                 d3 / (g * ab**1.5 * c23), x_c, y_c)


def asm_flexibility(area: GridArea, *, nu: float, shear_modulus: float,
                    collocation: tuple[float, float] = ASM_COLLOCATION
                    ) -> CalibratedFlexibility:
    """Return FastSim's flexibilities that reproduce ASM's coefficients on ``area``."""
    c = asm_coefficients(area, nu=nu, reference=centroid(area), collocation=collocation)
    return calibrated_flexibility(area, c.C11, c.C22, c.C23, shear_modulus)


def fastsim_with(area: GridArea, flex: CalibratedFlexibility, xi: float, eta: float,
                 phi: float, *, bound: FloatArray, reference: tuple[float, float] = (0.0, 0.0),
                 friction: FrictionLaw | None = None, speed: float | None = None) -> Tractions:
    """Solve FastSim on ``area`` with ``flex`` (radial return), creepages about ``reference``."""
    return fastsim(area, xi, eta, phi, bound=bound, flexibility=flex.strips(area),
                   sweep_point=(flex.x_c, flex.y_c), reference=reference, friction=friction,
                   speed=speed)


class FlexibilityOf(Protocol):
    """A method's flexibilities of an area: ``(area, *, nu, shear_modulus) -> L1, L2, L3``."""

    def __call__(self, area: GridArea, *, nu: float,
                 shear_modulus: float) -> CalibratedFlexibility: ...


@dataclass(frozen=True)
class FlexibilityMethod:
    """FastSim with one ``L1, L2, L3`` on the area, from ``flexibility_of`` (ASM's, DLM's).

    The loop ASM + FastSim and DLM + FastSim share: :meth:`solve` under the
    traction bound, :meth:`coefficients` in full adhesion.
    """

    flexibility_of: FlexibilityOf

    def solve(self, area: GridArea, xi: float, eta: float, phi: float, *, mu: float,
              nu: float, shear_modulus: float, reference: tuple[float, float] = (0.0, 0.0),
              bound: str = "given", friction: FrictionLaw | None = None,
              speed: float | None = None,
              flexibility: CalibratedFlexibility | None = None) -> Tractions:
        """Solve FastSim (forces in N, ``Mz`` about ``reference``); ``phi`` in 1/m.

        ``flexibility``: ``flexibility_of``'s result for this area and
        material, to reuse over many creepages.  A law's slope reduction is
        applied as :func:`~fastsim_ros.contact.equivalent.reduce_slope` says.
        """
        if friction is not None and friction.reduces_slope:
            # the modified FastSim (equivalent.reduce_slope): creepages times k, constant
            # friction at the rigid slip velocity
            red = reduce_slope(area, xi, eta, phi, friction, speed,
                               table=coefficient_table(nu), shear_modulus=shear_modulus)
            xi, eta, phi, friction, speed = red.xi, red.eta, red.phi, red.friction, None
            mu = friction.mu_s
        flex = flexibility or self.flexibility_of(area, nu=nu, shear_modulus=shear_modulus)
        return fastsim_with(area, flex, xi, eta, phi,
                            bound=traction_bound(area, mu, bound=bound), reference=reference,
                            friction=friction, speed=speed)

    def coefficients(self, area: GridArea, *, nu: float,
                     reference: tuple[float, float] = (0.0, 0.0)) -> CreepCoefficients:
        """Return the generalised coefficients in full adhesion about ``reference`` (m).

        Unit creepages, no traction bound, normalised with the area of the
        cells in contact.
        """
        flex = self.flexibility_of(area, nu=nu, shear_modulus=1.0)
        unbounded = np.where(area.mask, np.inf, 0.0)
        return coefficients_of_solver(
            area.area, lambda xi, eta, phi: fastsim_with(area, flex, xi, eta, phi,
                                                         bound=unbounded, reference=reference),
            reference=reference)


#: ASM + FastSim
ASM_FASTSIM = FlexibilityMethod(asm_flexibility)
#: ASM + FastSim: solve (forces in N, ``Mz`` about ``reference``; ``flexibility``: the result
#: of :func:`asm_flexibility`, to reuse over many creepages: it costs ASM's linear system)
asm_fastsim = ASM_FASTSIM.solve
#: ASM + FastSim's coefficients in full adhesion (ASM's own ``C~11, C~22, C~23``)
asm_fastsim_coefficients = ASM_FASTSIM.coefficients
