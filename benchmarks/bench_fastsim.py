"""Time the compiled MAE + FastSim and equivalent-ellipse paths; print medians and p99.

Run from the package root (``benchmarks/README.md``)::

    PYTHONPATH=. .venv/bin/python benchmarks/bench_fastsim.py [--calls 2000] [--batch 2000]

For each grid (10x10 ... 60x60 cells) and each patch (two semi-ellipses with
a Hertz-like pressure, a wheel-rail sized non-elliptical patch; and a Hertzian
ellipse), one call at a time from Python (``time.perf_counter_ns`` around
each call, after a warm-up; the three compiled calls interleaved in blocks):

- ``MaeSolver.solve`` (the full API: a ``GridArea`` in, ``ContactForces`` out),
- ``MaeSolver.solve_arrays`` (the node's hot path: arrays in),
- the MAE geometry and table look-ups alone (kernel ``mae_prepare`` called
  in a compiled loop, so without the call overhead) and their share of the
  whole compiled solve (``mae_solve`` in the same loop),
- the numpy reference ``mae_fastsim`` (with its traction bound; fewer calls),
- ``EquivalentEllipseSolver.solve`` (the baseline, same patch),
- ``CalibratedMaeSolver.solve`` (the second MAE method, same patch; the
  target is at most 1.5x ``MaeSolver.solve``),
- ``TransientSolver.step`` on the calibrated MAE (transient rolling: the
  traction carried from the last step, which rolled two cells; the
  target is at most 1.5x the steady ``CalibratedMaeSolver.solve``),
- the same step on the 30 x 30 patches at several distances rolled ``V
  dt`` (half a cell to 4.3 cells), with the creepages unchanged and with
  a rig's noise on them (the far field's fixed point then follows a change
  of force every step), over the steady ``solve_arrays``,

the cost of the slope reduction of contaminated rails and of Polach's method
(:func:`real_rails_table`; ``--real-rails-only`` runs it alone), then the
batched throughput (patch solves per second, one core) of
``solve_batch`` on distinct patches and on one patch under many creepages.
The machine (platform, CPU, cores, load average) is printed with the figures:
quote it with them.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit

from fastsim_ros.contact import area as areas
from fastsim_ros.contact import kernels
from fastsim_ros.contact.area import GridArea
from fastsim_ros.contact.compiled import (CalibratedMaeSolver, EquivalentEllipseSolver,
                                          MaeSolver, warm_up)
from fastsim_ros.contact.fastsim import traction_bound
from fastsim_ros.contact.friction import ExponentialFriction, SlopeReduction
from fastsim_ros.contact.mae import mae_fastsim
from fastsim_ros.contact.polach import PolachSolver
from fastsim_ros.contact.tables import coefficient_table
from fastsim_ros.contact.transient import TransientSolver
from machine import machine  # noqa: E402  (the one machine line of every benchmark)

NU, G, MU, LOAD = 0.28, 8.0e10, 0.3, 5.0e4
# wheel-rail creepages in partial slip with spin (saturation near 5e-3 here)
CREEP = (1.0e-3, 5.0e-4, 1.0)
GRIDS = (10, 20, 30, 45, 60)


def semi_ellipses(cells: int) -> GridArea:
    """Make two semi-ellipses (a/b = 0.5 and 2) of 1 cm^2, Hertz-like pressure, ``LOAD`` (N)."""
    base = areas.semi_ellipses(0.5, 2.0, cells=cells)
    a1, b1 = areas.semi_ellipse_axes(0.5)
    a2, b2 = areas.semi_ellipse_axes(2.0)
    x, y = base.x[None, :], base.y[:, None]
    rho2 = np.where(y < 0.0, (x / a1) ** 2 + (y / b1) ** 2, (x / a2) ** 2 + (y / b2) ** 2)
    p = np.where(base.mask, np.sqrt(np.clip(1.0 - rho2, 0.0, None) + 1e-3), 0.0)
    return base.with_pressure(p).scaled(0.01).with_load(LOAD)


def ellipse(cells: int) -> GridArea:
    """Make a Hertzian ellipse of 6 mm x 4 mm under ``LOAD`` (N)."""
    return areas.ellipse(6e-3, 4e-3, nx=cells, load=LOAD)


def per_call(fns: dict[str, Callable[[], Any]], calls: int,
             rounds: int = 20) -> dict[str, tuple[float, float]]:
    """Return the median and p99 (us) of ``calls`` timed calls of each function.

    The calls go in ``rounds`` interleaved blocks (a block of each function,
    then the next round), so that a machine whose speed drifts during the
    run (a shared VM) affects every function alike.
    """
    clock = time.perf_counter_ns
    times = {name: np.empty(calls) for name in fns}
    block = max(1, calls // rounds)
    for fn in fns.values():
        for _ in range(min(200, calls)):
            fn()
    for start in range(0, calls, block):
        stop = min(calls, start + block)
        for name, fn in fns.items():
            t = times[name]
            for n in range(start, stop):
                t0 = clock()
                fn()
                t[n] = clock() - t0
    return {name: (float(np.median(t)) / 1e3, float(np.percentile(t, 99)) / 1e3)
            for name, t in times.items()}


@njit
def _loop_prepare(reps, p, x0, y0, dx, dy, shear_modulus, knots, polys):
    geo = np.empty(kernels.GEO_SIZE)
    env = np.empty((2, p.shape[1]), dtype=np.int64)
    strips = np.empty((3, p.shape[0]), dtype=np.int64)
    for _ in range(reps):
        kernels.mae_prepare(p, x0, y0, dx, dy, kernels.RULE_WIDEST_STRIP, shear_modulus,
                            knots, polys, geo, env, strips, False, np.zeros(2),
                            np.ones((4, 2, 2)))
    return geo[0]


@njit
def _loop_solve(reps, p, x0, y0, dx, dy, shear_modulus, knots, polys, xi, eta, phi, mu):
    none_f = np.empty((0, 0))
    none_b = np.empty((0, 0), dtype=np.bool_)
    fx = 0.0
    for _ in range(reps):
        fx += kernels.mae_solve(p, x0, y0, dx, dy, xi, eta, phi, mu, 0.0, 0.0,
                                kernels.RULE_WIDEST_STRIP, False, shear_modulus, knots, polys,
                                kernels.LAW_CONSTANT, np.zeros(2), 0.0, none_f, none_f, none_b,
                                False, False, np.zeros(2), np.ones((4, 2, 2)))[2]
    return fx


def in_kernel(fn: Callable[..., Any], *args: Any, reps: int = 200) -> float:
    """Return the best time (us) per iteration of a compiled loop: no call overhead."""
    fn(1, *args)
    best = math.inf
    for _ in range(15):
        t0 = time.perf_counter_ns()
        fn(reps, *args)
        best = min(best, (time.perf_counter_ns() - t0) / reps)
    return best / 1e3


def throughput(fn: Callable[[], Any], size: int) -> float:
    """Return patch solves per second of a batch call of ``size`` items (median of 5)."""
    fn()
    runs = []
    for _ in range(5):
        t0 = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - t0)
    return size / float(np.median(runs))


#: the distances rolled a step of the transient table, in cells
TRANSIENT_STEPS = (0.5, 1.0, 1.3, 2.0, 4.3)
#: the creepages' relative noise of its second column (a measured rig's kinematics)
TRANSIENT_NOISE = 1e-3


def transient_table(calls: int, cells: int = 30) -> None:
    """Print a transient step's cost over the steady solve at several ``V dt``, one run.

    ``TransientSolver(CalibratedMaeSolver).step`` on the 30 x 30 patches,
    from the state its own steps settled in, with the bench's creepages
    unchanged (a whole number of cells is then the steady state's fixed
    point: one sweep) and with each creepage times ``1 + 1e-3 n`` (``n``
    standard normal, fresh every call: a rig's measured kinematics, whose
    change of force the far field's fixed point follows), interleaved with
    the steady ``CalibratedMaeSolver.solve_arrays`` of the same patch.
    """
    calibrated = CalibratedMaeSolver(NU, G)
    transient = TransientSolver(calibrated)
    xi, eta, phi = CREEP
    rng = np.random.default_rng(0)
    print(f"transient rolling: TransientSolver(CalibratedMaeSolver).step over the steady "
          f"solve_arrays,\n{cells}x{cells} patches, V dt in cells; constant: the creepages "
          f"unchanged; noise: each times 1 + {TRANSIENT_NOISE:g} n (n standard normal)\n")
    head = (f"{'patch':<14}{'V dt':>6}  {'steady':>13}  {'constant':>13}{'ratio':>7}"
            f"  {'noise':>13}{'ratio':>7}")
    print(head)
    print("-" * len(head))
    for name, make in (("semi-ellipses", semi_ellipses), ("ellipse", ellipse)):
        ar = make(cells)
        p = np.array(ar.pressure)
        grid = (ar.x0, ar.y0, ar.dx, ar.dy)
        for steps in TRANSIENT_STEPS:
            rolled = steps * ar.dx
            settled = transient.step(None, p, *grid, xi, eta, phi, math.inf, MU)[1]
            for _ in range(100):
                settled = transient.step(settled, p, *grid, xi, eta, phi, rolled, MU)[1]
            state = [settled, settled]

            def constant() -> None:
                state[0] = transient.step(state[0], p, *grid, xi, eta, phi, rolled, MU)[1]

            def noise() -> None:
                k = 1.0 + TRANSIENT_NOISE * rng.standard_normal(3)
                state[1] = transient.step(state[1], p, *grid, k[0] * xi, k[1] * eta,
                                          k[2] * phi, rolled, MU)[1]
            t = per_call({"steady": lambda: calibrated.solve_arrays(p, *grid, xi, eta, phi, MU),
                          "constant": constant, "noise": noise}, calls)
            base = t["steady"][0]
            print(f"{name:<14}{steps:>6g}  {t['steady'][0]:>6.1f} /{t['steady'][1]:>5.1f}  "
                  f"{t['constant'][0]:>6.1f} /{t['constant'][1]:>5.1f}"
                  f"{t['constant'][0] / base:>7.2f}  {t['noise'][0]:>6.1f} /{t['noise'][1]:>5.1f}"
                  f"{t['noise'][0] / base:>7.2f}")
    print("\ntimes in us, median / p99; ratio: the median over the steady median "
          "(the target: 1.5).\n")


def real_rails_table(calls: int, grids: list[int]) -> None:
    """Print the cost of a solve with and without the slope reduction, and Polach's, one run.

    ``solve_arrays`` of the calibrated MAE and of the equivalent ellipse at
    Coulomb's ``mu`` (today's call), then under the falling law with the
    Eurosprinter's slope reduction (k0 0.54, alpha_inf 0.02, beta 0.62; mu_s
    0.36, A 0.38, B 0.7 s/m, 10 m/s: the modified FastSim, its extra cost the
    equivalent ellipse and the factor ``k``), and ``PolachSolver.solve_arrays``
    (Polach's closed form with kA 0.3, kS 0.1) on the same patch, interleaved.
    """
    law = ExponentialFriction(0.36, 0.38, 0.7, reduction=SlopeReduction(0.54, 0.02, 0.62))
    falling = ExponentialFriction(0.36, 0.38, 0.7)
    calibrated = CalibratedMaeSolver(NU, G)
    baseline = EquivalentEllipseSolver(NU, G)
    polach = PolachSolver(NU, G, k_a=0.3, k_s=0.1)
    xi, eta, phi = CREEP
    print("real rails: solve_arrays with Coulomb's mu, under the falling law alone, and under "
          "the falling law with the slope reduction; Polach's closed form\n")
    head = (f"{'patch':<14}{'grid':>6}  {'cal mu':>13}  {'cal law':>13}  {'cal reduced':>13}"
            f"{'ratio':>7}  {'eq mu':>13}  {'eq reduced':>13}{'ratio':>7}  {'polach':>13}")
    print(head)
    print("-" * len(head))
    for name, make in (("semi-ellipses", semi_ellipses), ("ellipse", ellipse)):
        for n in grids:
            ar = make(n)
            p = np.array(ar.pressure)
            grid = (ar.x0, ar.y0, ar.dx, ar.dy)
            t = per_call({
                "cal": lambda: calibrated.solve_arrays(p, *grid, xi, eta, phi, 0.36),
                "cal_law": lambda: calibrated.solve_arrays(p, *grid, xi, eta, phi,
                                                           friction=falling, speed=10.0),
                "cal_red": lambda: calibrated.solve_arrays(p, *grid, xi, eta, phi,
                                                           friction=law, speed=10.0),
                "eq": lambda: baseline.solve_arrays(p, *grid, xi, eta, phi, 0.36),
                "eq_red": lambda: baseline.solve_arrays(p, *grid, xi, eta, phi, friction=law,
                                                        speed=10.0),
                "polach": lambda: polach.solve_arrays(p, *grid, xi, eta, phi, friction=falling,
                                                      speed=10.0)}, calls)

            def cell(key: str) -> str:
                return f"{t[key][0]:>6.1f} /{t[key][1]:>5.1f}"
            print(f"{name:<14}{n:>6}  {cell('cal')}  {cell('cal_law')}  {cell('cal_red')}"
                  f"{t['cal_red'][0] / t['cal'][0]:>7.2f}  {cell('eq')}  {cell('eq_red')}"
                  f"{t['eq_red'][0] / t['eq'][0]:>7.2f}  {cell('polach')}")
    print("\ntimes in us, median / p99; ratio: the reduced median over Coulomb's.\n")


def main() -> None:
    """Run the benchmark and print its tables."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--calls", type=int, default=2000, help="timed calls per figure")
    parser.add_argument("--reference-calls", type=int, default=30,
                        help="timed calls of the numpy reference")
    parser.add_argument("--batch", type=int, default=2000, help="items per batch")
    parser.add_argument("--grids", type=int, nargs="+", default=list(GRIDS))
    parser.add_argument("--real-rails-only", action="store_true",
                        help="only the table of the slope reduction and Polach's method")
    args = parser.parse_args()
    if args.real_rails_only:
        print(f"machine: {machine()}")
        print(f"warm-up (compile or load the cached kernels): {warm_up():.2f} s")
        real_rails_table(args.calls, args.grids)
        return

    print(f"machine: {machine()}")
    print(f"warm-up (compile or load the cached kernels): {warm_up():.2f} s")
    print(f"creepages xi, eta, phi = {CREEP} (phi in 1/m), mu = {MU}, N = {LOAD:g} N, "
          f"G = {G:g} Pa, nu = {NU}; times in us, median / p99 over {args.calls} calls\n")
    mae = MaeSolver(NU, G)
    calibrated = CalibratedMaeSolver(NU, G)
    own_knee = CalibratedMaeSolver(NU, G, knee=False)
    baseline = EquivalentEllipseSolver(NU, G)
    transient = TransientSolver(calibrated)
    local = TransientSolver(calibrated, far_field=False)
    table = coefficient_table(NU)
    knots, polys = mae._knots, mae._polys
    rng = np.random.default_rng(0)
    xi, eta, phi = CREEP

    head = (f"{'patch':<14}{'grid':>6}{'cells':>6}{'slip':>6}  {'solve':>13}  "
            f"{'solve_arrays':>13}  {'geometry':>8}{'share':>7}  {'numpy ref':>10}  "
            f"{'equivalent':>13}{'eq/mae':>7}  {'calibrated':>13}{'cal/mae':>8}"
            f"  {'transient':>13}{'tr/cal':>7}  {'local':>6}{'lo/cal':>7}  {'stepping':>13}"
            f"{'st/cal':>7}  {'own knee':>13}{'cal/own':>8}")
    print(head)
    print("-" * len(head))
    rates = []
    for name, make in (("semi-ellipses", semi_ellipses), ("ellipse", ellipse)):
        for n in args.grids:
            ar = make(n)
            p = np.array(ar.pressure)
            grid = (ar.x0, ar.y0, ar.dx, ar.dy)
            res = mae.solve(ar, xi, eta, phi, mu=MU)
            state = [transient.step(None, p, *grid, xi, eta, phi, 2 * ar.dx, MU)[1]]
            state_local = [local.step(None, p, *grid, xi, eta, phi, 2 * ar.dx, MU)[1]]
            state_steps = [state[0], 0]

            def step() -> None:
                state[0] = transient.step(state[0], p, *grid, xi, eta, phi, 2 * ar.dx, MU)[1]

            def step_local() -> None:
                state_local[0] = local.step(state_local[0], p, *grid, xi, eta, phi, 2 * ar.dx,
                                            MU)[1]

            def stepping() -> None:
                # a creepage step every cycle (between the creepages and half of them): the
                # far field's secant every time, the worst case
                k = 1.0 if state_steps[1] % 2 else 0.5
                state_steps[1] += 1
                state_steps[0] = transient.step(state_steps[0], p, *grid, k * xi, k * eta,
                                                k * phi, 2 * ar.dx, MU)[1]
            t = per_call({
                "solve": lambda: mae.solve(ar, xi, eta, phi, mu=MU),
                "arrays": lambda: mae.solve_arrays(p, *grid, xi, eta, phi, MU),
                "equivalent": lambda: baseline.solve(ar, xi, eta, phi, mu=MU),
                "calibrated": lambda: calibrated.solve(ar, xi, eta, phi, mu=MU),
                "own_knee": lambda: own_knee.solve(ar, xi, eta, phi, mu=MU),
                "transient": step, "local": step_local, "stepping": stepping}, args.calls)
            t_solve, t_arrays, t_eq = t["solve"], t["arrays"], t["equivalent"]
            t_cal, t_tr = t["calibrated"], t["transient"]
            kargs = (ar.pressure, *grid, G, knots, polys)
            t_geo = in_kernel(_loop_prepare, *kargs)
            t_whole = in_kernel(_loop_solve, *kargs, xi, eta, phi, MU)
            bound = traction_bound(ar, MU)
            t_ref = per_call({"ref": lambda: mae_fastsim(
                ar, xi, eta, phi, bound=bound, table=table, shear_modulus=G)},
                args.reference_calls, rounds=1)["ref"]
            print(f"{name:<14}{f'{ar.nx}x{ar.ny}':>6}{np.count_nonzero(ar.mask):>6}"
                  f"{100 * res.slip_fraction:>5.0f}%  {t_solve[0]:>6.1f} /{t_solve[1]:>5.1f}  "
                  f"{t_arrays[0]:>6.1f} /{t_arrays[1]:>5.1f}  {t_geo:>8.2f}"
                  f"{100 * t_geo / t_whole:>6.0f}%  {t_ref[0]:>10.0f}  "
                  f"{t_eq[0]:>6.1f} /{t_eq[1]:>5.1f}{t_eq[0] / t_solve[0]:>7.2f}  "
                  f"{t_cal[0]:>6.1f} /{t_cal[1]:>5.1f}{t_cal[0] / t_solve[0]:>8.2f}"
                  f"  {t_tr[0]:>6.1f} /{t_tr[1]:>5.1f}{t_tr[0] / t_cal[0]:>7.2f}"
                  f"  {t['local'][0]:>6.1f}{t['local'][0] / t_cal[0]:>7.2f}"
                  f"  {t['stepping'][0]:>6.1f} /{t['stepping'][1]:>5.1f}"
                  f"{t['stepping'][0] / t_cal[0]:>7.2f}"
                  f"  {t['own_knee'][0]:>6.1f} /{t['own_knee'][1]:>5.1f}"
                  f"{t_cal[0] / t['own_knee'][0]:>8.2f}")
            # batches: distinct patches (load and a fore-aft tilt of the pressure vary
            # smoothly from patch to patch, as from a normal solver) and creepages
            b = args.batch
            tilt = np.linspace(-1.0, 1.0, ar.nx)[None, None, :]
            ps = p[None] * ((0.8 + 0.4 * rng.random((b, 1, 1)))
                            * (1.0 + 0.3 * (rng.random((b, 1, 1)) - 0.5) * tilt))
            creep = np.column_stack([xi * (0.5 + rng.random(b)), eta * (0.5 + rng.random(b)),
                                     phi * (0.5 + rng.random(b))])
            rates.append((name, f"{ar.nx}x{ar.ny}", [
                throughput(lambda: s.solve_batch(pp, *grid, creep, mu=MU), b)
                for s in (mae, baseline, calibrated) for pp in (ps, p)]))
    print("\ngeometry: MAE geometry + table look-ups alone (kernel mae_prepare, in a compiled "
          "loop);\nshare: of the whole compiled MAE solve (mae_solve, same loop); numpy ref: "
          "mae_fastsim,\nmedian of fewer calls; eq/mae: median of EquivalentEllipseSolver.solve "
          "over MaeSolver.solve;\ncalibrated: CalibratedMaeSolver.solve, cal/mae its median over "
          "MaeSolver.solve's;\ntransient: TransientSolver(CalibratedMaeSolver).step rolling 2 "
          "cells from the last state\n(the same creepages: the steady state, one sweep), "
          "tr/cal its median over CalibratedMaeSolver.solve's;\nlocal: the same without the "
          "far field (Kalker's local model); stepping: the far field\nwith a creepage step "
          "every call (its secant every time); own knee: CalibratedMaeSolver(knee=False).solve "
          "(FastSim's own knee),\ncal/own: the default's median over it (the cost of the "
          "strips' knee factors).\n")
    transient_table(args.calls)
    real_rails_table(args.calls, args.grids)
    print(f"batched throughput, patch solves per second on one core (batches of {args.batch})")
    head = (f"{'patch':<14}{'grid':>6}  {'MAE distinct':>13}{'MAE 1 patch':>13}"
            f"{'eq distinct':>13}{'eq 1 patch':>13}{'cal distinct':>13}{'cal 1 patch':>13}")
    print(head)
    print("-" * len(head))
    for name, size, r in rates:
        print(f"{name:<14}{size:>6}  " + "".join(f"{v:>13,.0f}" for v in r))
    print("\ndistinct: B different patches (load and pressure tilt vary) and creepages; "
          "1 patch: one patch\nunder B creepages (its geometry, look-ups and bound are "
          "computed once).")


if __name__ == "__main__":
    main()
