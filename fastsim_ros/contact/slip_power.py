"""The frictional dissipation of FastSim's steady march, from the tractions it produced.

FastSim's elastic model (Kalker's simplified theory, docs/guide_physics.md): the
surface displacement is ``u = L tau`` per strip.  A cell's step from its
upstream neighbour's traction ``tau_up`` (``h = dx``, or ``dx/2`` from a
segment's front face, zero traction there) forms the trial traction ``t* =
tau_up - (w_L / L) h`` (the march's rates,
:func:`fastsim_ros.contact.kernels.strip_rates`: the spin term with the
spin flexibility, ``phi x`` at the step's middle).  Where the cell slips,
its slip per unit rolling distance is the one its method's projection
uses, the slip a slip-dependent friction law of the march reads:

- the radial return (the paper's MAE, the equivalent ellipse): ``s = L (tau
  - t*) / h``, the traction the cell could not hold, released as
  displacement (``L`` the strip's ``L1``, ``L2``);
- the rigid-slip return (the calibrated MAE): ``s = (w h + L (tau -
  tau_up)) / h``, ``w = (xi - phi (y - y_s), eta + phi (x - x_c))`` the
  rigid slip at the cell.

Zero where the cell sticks.  The dissipation per unit rolling distance and
area is ``-tau . s`` (J/m^2 per metre rolled; times ``|V|``: the frictional
power density, W/m^2), summed over the slip area as CONTACT's
``FRIC.POWER`` (Vollebregt, CONTACT user guide, "frictional power": ``V
int tau . s dA`` over the slip area, printed with the traction on the upper
body, hence negative there).

Without spin both slips are the same and the sum stays below T-gamma (the
rest is the elastic energy the march carries out of the patch).  Under
spin the march's spin term uses the spin flexibility (``L3``, MAE's
``L4``), not ``L1``, ``L2``: its displacement is not one elastic field, so
the radial return's dissipation may exceed T-gamma (the paper's MAE on
semi-ellipses under pure spin: up to 1.2 T-gamma) and the rigid-slip
return's falls short of the exact theory's (docs/guide_wear.md).

The trial is re-formed from the stored tractions with the march's own
operations (steady rolling: every cell's material entered under the present
creepages).  Compiled (numba); called by
:class:`fastsim_ros.contact.compiled.MaeSolver` and the equivalent
ellipse's solver when tractions are asked for: one pass over the cells
after the solve, plus the MAE set-up again (the solve does not return it).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fastsim_ros.contact import kernels as k


@njit(cache=True, error_model="numpy")
def march_dissipation(inside, tau_x, tau_y, slip, x0, y0, dx, dy, xi_s, eta_s, phi, flex,
                      x_c, y_s, rigid, density):
    """Fill ``density`` (N/m^2 per metre rolled) with each cell's ``-tau . s``; return the sum (N).

    ``inside`` (bool, ``(ny, nx)``): the cells the march visited (bound
    positive); ``tau_x``, ``tau_y`` (Pa) and ``slip``: the march's results on
    the grid ``x0, y0, dx, dy`` (m); ``xi_s``, ``eta_s`` (1), ``phi`` (1/m):
    the creepages at the sweep point ``(x_c, y_s)`` (m); ``flex`` (m/Pa,
    ``(4, ny)``): the strips' ``L1, L2, L3`` and spin flexibility;
    ``rigid``: the rigid-slip return's slip, else the radial return's (the
    module's).  The sum is ``sum -tau . s dA``: the dissipation per metre
    rolled (N = J/m).
    """
    ny, nx = inside.shape
    half = 0.5 * dx
    total = 0.0
    for j in range(ny):
        y = y0 + dy * j
        # the march's constant rates of strip j (strip_rates)
        rate_x = xi_s / flex[0, j] - phi * (y - y_s) / flex[3, j]
        rate_y0 = eta_s / flex[1, j]
        rate_yx = phi / flex[2, j]
        upstream = False
        for i in range(nx - 1, -1, -1):
            if not inside[j, i]:
                upstream = False
                density[j, i] = 0.0
                continue
            if upstream:
                h = dx
                p_x = tau_x[j, i + 1]
                p_y = tau_y[j, i + 1]
            else:
                h = half
                p_x = 0.0
                p_y = 0.0
            upstream = True
            d = 0.0
            if slip[j, i]:
                x_rel = x0 + dx * i - x_c
                if rigid:
                    # the rigid-slip return's slip: (w h + L (tau - tau_up)) / h
                    s_x = ((xi_s - phi * (y - y_s)) * h
                           + flex[0, j] * (tau_x[j, i] - p_x)) / h
                    s_y = ((eta_s + phi * x_rel) * h + flex[1, j] * (tau_y[j, i] - p_y)) / h
                else:
                    x_mid = x_rel + 0.5 * h
                    t_x = p_x - rate_x * h
                    t_y = p_y - (rate_y0 + rate_yx * x_mid) * h
                    s_x = flex[0, j] * (tau_x[j, i] - t_x) / h
                    s_y = flex[1, j] * (tau_y[j, i] - t_y) / h
                d = -(tau_x[j, i] * s_x + tau_y[j, i] * s_y)
            density[j, i] = d
            total += d
    return total * (dx * dy)


@njit(cache=True, error_model="numpy")
def mae_dissipation(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                    shear_modulus, knots, polys, calibrated, pair_knots, pair_values, tau_x,
                    tau_y, slip, density):
    """:func:`march_dissipation` of a solve of :func:`fastsim_ros.contact.kernels.mae_solve`.

    The arguments as that solve's (its tractions ``tau_x``, ``tau_y``,
    ``slip``); returns ``(status, dissipation per metre rolled (N))``.  A
    patch the solve splits into its regions (:mod:`fastsim_ros.contact.lobes`)
    is marched region by region with each region's flexibilities, blended
    with the whole patch's march by the solve's weight.
    """
    m, w = k.patch_gap(p, calibrated)
    if w < 1.0:
        ny, nx = p.shape
        a = mae_dissipation_whole(p[:m], x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule,
                                  parabolic, shear_modulus, knots, polys, calibrated,
                                  pair_knots, pair_values, tau_x[:m], tau_y[:m], slip[:m],
                                  density[:m])
        b = mae_dissipation_whole(p[m:], x0, y0 + m * dy, dx, dy, xi, eta, phi, mu, xp, yp,
                                  rule, parabolic, shear_modulus, knots, polys, calibrated,
                                  pair_knots, pair_values, tau_x[m:], tau_y[m:], slip[m:],
                                  density[m:])
        if a[0] == k.OK and b[0] == k.OK:
            total = a[1] + b[1]
            if w > 0.0:
                apart = density.copy()
                c = mae_dissipation_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule,
                                          parabolic, shear_modulus, knots, polys, calibrated,
                                          pair_knots, pair_values, tau_x, tau_y, slip, density)
                if c[0] != k.OK:
                    return c
                for j in range(ny):
                    for i in range(nx):
                        density[j, i] = w * density[j, i] + (1.0 - w) * apart[j, i]
                total = w * c[1] + (1.0 - w) * total
            return k.OK, total
    return mae_dissipation_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                                 shear_modulus, knots, polys, calibrated, pair_knots,
                                 pair_values, tau_x, tau_y, slip, density)


@njit(cache=True, error_model="numpy")
def mae_dissipation_whole(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp, rule, parabolic,
                          shear_modulus, knots, polys, calibrated, pair_knots, pair_values,
                          tau_x, tau_y, slip, density):
    """:func:`mae_dissipation` on the patch whole (:func:`~.kernels.mae_setup`)."""
    status, _, geo, _, flex, _ = k.mae_setup(p, x0, y0, dx, dy, xi, eta, phi, mu, xp, yp,
                                             rule, parabolic, shear_modulus, knots, polys,
                                             calibrated, pair_knots, pair_values)
    if status != k.OK:
        return status, 0.0
    xi_s, eta_s = k.creepages_at_s(geo, xi, eta, phi, xp, yp)
    return k.OK, march_dissipation(p > 0.0, tau_x, tau_y, slip, x0, y0, dx, dy, xi_s, eta_s,
                                   phi, flex, geo[k.G_XC], geo[k.G_YS], calibrated, density)


@njit(cache=True, error_model="numpy")
def equivalent_dissipation(p, x0, y0, dx, dy, xi, eta, phi, xp, yp, parabolic, n,
                           shear_modulus, knots, polys, tau_x, tau_y, slip, density):
    """:func:`march_dissipation` of an equivalent-ellipse solve (``kernels.equivalent_solve``).

    On the equivalent ellipse's ``n`` x ``n`` grid (the solve's tractions);
    returns ``(status, dissipation per metre rolled (N))``.
    """
    ell = np.empty(k.ELL_SIZE)
    status, _ = k.equivalent_prepare(p, x0, y0, dx, dy, shear_modulus, knots, polys, ell)
    if status != k.OK:
        return status, 0.0
    shape, _, _ = k.ellipse_bound(ell, n, parabolic)
    gx0, gy0, gdx, gdy, flex, xi_s, eta_s = k.ellipse_march(ell, n, xi, eta, phi, xp, yp)
    return k.OK, march_dissipation(shape > 0.0, tau_x, tau_y, slip, gx0, gy0, gdx, gdy, xi_s,
                                   eta_s, phi, flex, ell[k.ELL_XC], ell[k.ELL_YC], False,
                                   density)
