"""Rectangle influence coefficients against quadrature and the point-force solution."""

import numpy as np
import pytest
from scipy import integrate

from fastsim_ros.contact.influence import influence_kernel, point_load_displacement

G = 8.0e10
NU = 0.28


def _quadrature(xc, yc, hx, hy, component):
    """Integrate the point-force kernel over the rectangle, split at the field point.

    Splitting puts the ``1/rho`` singularity of the self-influence on the
    corners of the pieces, where adaptive quadrature copes with it.
    """
    xs = sorted({xc - hx / 2, xc + hx / 2} | ({0.0} if abs(xc) < hx / 2 else set()))
    ys = sorted({yc - hy / 2, yc + hy / 2} | ({0.0} if abs(yc) < hy / 2 else set()))
    total = 0.0
    for x1, x2 in zip(xs[:-1], xs[1:]):
        for y1, y2 in zip(ys[:-1], ys[1:]):
            def f(y, x):
                return point_load_displacement(np.array(x), np.array(y), shear_modulus=G,
                                               nu=NU)[component]
            val, _ = integrate.dblquad(f, x1, x2, y1, y2, epsabs=0.0, epsrel=1e-10)
            total += val
    return total


@pytest.mark.parametrize("di, dj", [(0, 0), (1, 0), (0, 1), (2, -3), (-1, 1)])
@pytest.mark.parametrize("component", [0, 1, 2, 3])
def test_rectangle_coefficients_equal_quadrature(di, dj, component):
    hx, hy = 1.3e-3, 0.7e-3
    k = influence_kernel(hx, hy, 3, 3, shear_modulus=G, nu=NU)
    closed = (k.xx, k.yy, k.xy, k.zz)[component][dj + 3, di + 3]
    # the source cell lies at minus the offset from the field point
    quad = _quadrature(-di * hx, -dj * hy, hx, hy, component)
    assert closed == pytest.approx(quad, rel=1e-7, abs=1e-9 * abs(k.xx[3, 3]))


def test_self_influence_is_positive_and_largest():
    # Without the absolute values in the corner primitives the self term is zero.
    k = influence_kernel(1.0, 2.0, 4, 4, shear_modulus=1.0, nu=0.3)
    for c in (k.xx, k.yy, k.zz):
        assert c[4, 4] > 0.0
        assert c[4, 4] == c.max()
    assert k.xy[4, 4] == 0.0


@pytest.mark.parametrize("nu", [0.0, 0.25, 0.5])
def test_far_field_approaches_point_force(nu):
    h = 1.0e-3
    m = 40
    k = influence_kernel(h, h, m, m, shear_modulus=G, nu=nu)
    di, dj = 31, -23
    x, y = -di * h, -dj * h
    point = point_load_displacement(np.array(x), np.array(y), shear_modulus=G, nu=nu)
    cells = (k.xx, k.yy, k.xy, k.zz)
    for c, p in zip(cells, point):
        # a uniform traction differs from a point force by O((h/rho)^2)
        assert c[dj + m, di + m] == pytest.approx(float(p) * h * h, rel=2e-3, abs=1e-6 * h / G)


def test_symmetries_of_the_kernel():
    k = influence_kernel(1.0, 0.5, 5, 4, shear_modulus=1.0, nu=0.25)
    np.testing.assert_allclose(k.xx, k.xx[::-1, ::-1])
    np.testing.assert_allclose(k.xx, k.xx[:, ::-1])
    np.testing.assert_allclose(k.xy, -k.xy[:, ::-1], atol=1e-15)
    np.testing.assert_allclose(k.xy, k.xy[::-1, ::-1], atol=1e-15)
