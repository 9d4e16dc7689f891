"""The pipeline's compiled path gives every number of its Python path, to the bit.

:func:`fastsim_ros.pipeline.kernels.solve_cloud` replaces, for a patch that
is solved, the adapter's Python checks, the creepages, the solver's wrapper
and the wheelset wrench: a pipeline with it and one without (the Python
path alone) are fed the same messages and must give equal outcomes, field by
field, on every layout, orientation and setting the compiled path takes,
and the same rejections where it defers.
"""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from fastsim_ros.pipeline import kernels as pipeline_kernels
from fastsim_ros.contact import samples
from fastsim_ros.pipeline import Pipeline, PipelineConfig
from ros_messages import WHEEL_RADIUS as R
from ros_messages import cdr, cloud_msg, contact_normal, rolling_twist, twist_msg

MS = 1_000_000
T0 = 1_700_000_000 * 1_000_000_000


def egg():
    return samples.semi_ellipses_patch(0.5, 2.0, cells=24, scale=8e-3, load=6e4)


def python_solve(*args):
    raise AssertionError("the compiled path deferred a patch that it solves")


def pair(*, compiled_only=True, **values):
    """Return a pipeline on the compiled path and one on the Python path alone.

    ``compiled_only``: the first may not call the Python path's solve (a
    patch it defers would fail the test).
    """
    values.setdefault("contacts", ["left"])
    config = PipelineConfig.from_values(values)
    fast, slow = Pipeline(config), Pipeline(config)
    assert fast._compiled is not None
    slow._compiled = None
    if compiled_only:
        fast._solve = python_solve
    return fast, slow


def same(a, b):
    """Assert two outcomes equal field by field (floats to the bit, arrays equal)."""
    assert (a.contact, a.stamp_ns, a.status, a.detail) == (b.contact, b.stamp_ns, b.status,
                                                           b.detail)
    assert a.frame == b.frame and a.frame_changed == b.frame_changed
    assert a.creepage == b.creepage or (a.creepage is not None and all(
        math.isnan(x) and math.isnan(y) for x, y in zip(
            (a.creepage.xi, a.creepage.eta, a.creepage.phi),
            (b.creepage.xi, b.creepage.eta, b.creepage.phi))))
    if a.forces is None or b.forces is None:
        assert a.forces is b.forces
    else:  # (ContactForces compares by identity)
        for name in ("fx", "fy", "mz", "n", "slip_fraction", "tau_x", "tau_y", "slip", "grid"):
            assert getattr(a.forces, name) == getattr(b.forces, name), name
    if a.patch is None or b.patch is None:
        assert a.patch is b.patch
    else:
        for name in ("stamp_ns", "frame", "x0", "y0", "dx", "dy", "load", "cells",
                     "row_order", "column_order"):
            assert getattr(a.patch, name) == getattr(b.patch, name), name
        assert a.patch.pressure.flags.c_contiguous and b.patch.pressure.flags.c_contiguous
        assert np.array_equal(a.patch.pressure, b.patch.pressure)
    assert a.wheelset == b.wheelset and a.markers == b.markers


def feed(pipes, contact, msg):
    return [p.on_patch(contact, cdr(msg)) for p in pipes]


def twist(pipes, msg, rail=False):
    for p in pipes:
        assert (p.on_rail_twist if rail else p.on_wheel_twist)(cdr(msg)) == "ok"


CLOUDS = {
    "float32": {},
    "float64": {"dtype": "<f8"},
    "big endian": {"dtype": ">f8"},
    "fields reordered, padded": {"field_order": ["pressure", "normal_x", "normal_y",
                                                 "normal_z", "x", "y", "z"], "pad": 4},
    "rows reversed": {"reverse_rows": True},
    "columns reversed": {"reverse_columns": True},
    "both reversed": {"reverse_rows": True, "reverse_columns": True},
    "contact angle": {"normal": contact_normal(0.3), "dtype": "<f8"},
}


@pytest.mark.parametrize("cloud", sorted(CLOUDS))
@pytest.mark.parametrize("method", ["mae_calibrated", "mae"])
def test_solved_patches_equal_the_python_path(cloud, method):
    fast, slow = pair(method=method, contacts=["left", "right"])
    twist((fast, slow), rolling_twist(2e-3, stamp_ns=T0))
    for k, (contact, xi) in enumerate((("left", 2e-3), ("right", 2e-3), ("left", 2e-3))):
        a, b = feed((fast, slow), contact, cloud_msg(egg(), stamp_ns=T0 + (k + 1) * MS,
                                                     **CLOUDS[cloud]))
        assert a.status == "solved"
        same(a, b)
    assert fast.latest_wrench("left") == slow.latest_wrench("left")
    p50, _ = fast.solve_time_percentiles("left")
    assert p50 > 0.0


@pytest.mark.parametrize("settings", [
    {"traction_bound": "parabolic"},
    {"friction_law": "exponential", "friction_limit_ratio": 0.4, "friction_decay": 0.6},
    {"friction_coefficient": 0.15},
])
def test_settings_reach_the_compiled_solve(settings):
    fast, slow = pair(**settings)
    twist((fast, slow), rolling_twist(5e-3, stamp_ns=T0))
    a, b = feed((fast, slow), "left", cloud_msg(egg(), stamp_ns=T0 + MS, dtype="<f8"))
    assert a.status == "solved"
    same(a, b)


def test_reverse_running_and_a_moving_rail_equal_the_python_path():
    # the roller case below slides the wheel at rest on a rail at 20 m/s (xi = 2: a full-slip
    # test, which the plausibility rule takes only when marked intended)
    fast, slow = pair(contacts=["left"], allow_implausible=True)
    # reverse running, yawed and spinning: every creepage nonzero
    twist((fast, slow), twist_msg((-20.0, 0.05, 0.0), (0.01, -20.0 / R * 1.001, 0.02),
                                  stamp_ns=T0))
    msg = cloud_msg(egg(), stamp_ns=T0 + MS, dtype="<f8", normal=contact_normal(0.1))
    a, b = feed((fast, slow), "left", msg)
    assert a.status == "solved" and a.creepage.speed < 0.0
    same(a, b)
    # a roller rig: the rail moves under a wheelset at rest
    twist((fast, slow), twist_msg(stamp_ns=T0 + 2 * MS))
    twist((fast, slow), twist_msg((-20.0, 0.0, 0.0), (0.0, 0.0, 0.0), stamp_ns=T0 + 2 * MS),
          rail=True)
    a, b = feed((fast, slow), "left", cloud_msg(egg(), stamp_ns=T0 + 3 * MS))
    assert a.status == "solved"
    same(a, b)


def test_where_the_python_path_rejects_both_say_the_same():
    fast, slow = pair(contacts=["left"], max_patch_cells=10000, compiled_only=False)
    area = egg()
    bad = [cloud_msg(area, stamp_ns=T0 + MS)]  # no kinematics yet
    twist((fast, slow), rolling_twist(1e-3, stamp_ns=T0 + 2 * MS))
    stamp = T0 + 3 * MS
    nan = area.pressure.copy()
    nan[3, 3] = math.nan
    negative = area.pressure.copy()
    negative[5, 5] = -1.0
    few = np.zeros_like(area.pressure)
    few[10, 10:12] = 1e6
    for kwargs in ({"pressure": nan}, {"pressure": negative}, {"pressure": few},
                   {"pressure": np.zeros_like(area.pressure)}, {"frame_id": "base_link"}):
        bad.append(cloud_msg(area, stamp_ns=stamp, **kwargs))
        stamp += MS
    bad.append(cloud_msg(area, stamp_ns=stamp + 200 * MS))  # stale kinematics
    for msg in bad:
        a, b = feed((fast, slow), "left", msg)
        same(a, b)
    twist((fast, slow), twist_msg((1e-4, 0.0, 0.0), (0.0, 1e-4 / R, 0.0),
                                  stamp_ns=stamp + 300 * MS))
    a, b = feed((fast, slow), "left", cloud_msg(area, stamp_ns=stamp + 301 * MS))
    assert a.status == "standstill"
    same(a, b)
    assert fast.counts("left") == slow.counts("left")


def test_tractions_and_the_equivalent_ellipse_stay_on_the_python_path():
    for values in ({"publish_traction": True}, {"method": "fastsim_ellipse"}):
        pipe = Pipeline(PipelineConfig.from_values({"contacts": ["left"], **values}))
        assert pipe._compiled is None
    pipe = Pipeline(PipelineConfig.from_values({"contacts": ["left"]}))
    pipe.update({"publish_traction": True})
    assert pipe._compiled is None
    pipe.update({"publish_traction": False, "method": "mae"})
    assert pipe._compiled is not None


def test_warm_up_compiles_every_words_type():
    from fastsim_ros.contact import transient
    pipeline_kernels.warm_up()
    assert len(pipeline_kernels.solve_cloud.signatures) >= 4
    # transient rolling's resets run its Python path: compiled at start-up, not at the
    # first transient patch (seconds, cold)
    assert transient.mae_rolling_solve.signatures and transient.ellipse_rolling_solve.signatures


def test_the_fast_builders_make_the_dataclasses_own_instances():
    import dataclasses

    from fastsim_ros.pipeline import outcomes
    from fastsim_ros.contact.compiled import ContactForces
    from msg_adapters.kinematics import Creepage
    from msg_adapters.patch import ContactFrame, ContactPatch

    frame = ContactFrame((0.0, 0.75, -R), ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))
    pressure = np.ones((2, 2))
    cases = [(outcomes.new_frame, ContactFrame, (frame.origin, frame.axes)),
             (outcomes.new_patch, ContactPatch,
              (T0, frame, pressure, -1e-3, -2e-3, 1e-3, 2e-3, 6e4, 4, 1, -1)),
             (outcomes.new_creepage, Creepage, (1e-3, -2e-3, 0.1, 20.0)),
             (outcomes.new_forces, ContactForces,
              (-1e3, 2e2, 3.0, 6e4, 0.25, None, None, None, None)),
             (outcomes.new_outcome, outcomes.Outcome,
              ("left", T0, "solved", "", frame, True, None, None, None, None, False))]
    for build, cls, values in cases:
        built, reference = build(*values), cls(*values)
        assert type(built) is cls
        for f in dataclasses.fields(cls):
            assert getattr(built, f.name) is getattr(reference, f.name), f.name
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(built, dataclasses.fields(cls)[0].name, None)
    assert outcomes.new_frame(*cases[0][2]) == frame  # frozen dataclasses compare by value


@pytest.mark.parametrize("settings", [
    {}, {"method": "mae"}, {"traction_bound": "parabolic"},
    {"friction_law": "exponential", "friction_limit_ratio": 0.4, "friction_decay": 0.6},
])
def test_transient_rolling_equals_the_python_path_cycle_for_cycle(settings):
    """``rolling: transient``: every outcome and the carried state to the bit, every rule met.

    The compiled path solves the cycles that carry the state over; the
    start, a creepage step, a stamp gap, reverse running (a reversal, then
    carried in the turned frame), a lifted wheel and its touch-down, the
    patch on another grid (a resample) and a jump (half the patch gone,
    then back) go to the Python path, whose ContactMemory rules decide.
    """
    fast, slow = pair(rolling="transient", compiled_only=False, **settings)
    python_solves = []
    solve = fast._solve

    def counted(*args, **kwargs):
        python_solves.append(args[0].stamp_ns)
        return solve(*args, **kwargs)
    fast._solve = counted
    area = egg()
    half = area.pressure.copy()
    half[:, : area.nx // 2] = 0.0
    moved = dataclasses.replace(area, dx=area.dx * 1.05)  # cells 5% longer: another grid
    # (ms, xi, speed, the patch's keywords, area); 2 m/s at 1 kHz: 2 mm a cycle
    plan = [(0, 5e-4, 2.0, {}, area), (1, 5e-4, 2.0, {}, area)]
    plan += [(n, 2e-3, 2.0, {}, area) for n in range(2, 8)]
    plan += [(100, 2e-3, 2.0, {}, area), (101, 1e-3, 2.0, {}, area)]  # a gap
    plan += [(n, 1e-3, -2.0, {}, area) for n in range(102, 106)]  # reversed, carried
    plan += [(106, 1e-3, -2.0, {"pressure": np.zeros_like(area.pressure)}, area)]
    plan += [(n, 1e-3, -2.0, {}, area) for n in range(107, 110)]  # lifted, down again
    plan += [(n, 1e-3, -2.0, {}, moved) for n in range(110, 113)]  # resampled, carried
    plan += [(113, 1e-3, -2.0, {"pressure": half}, moved), (114, 1e-3, -2.0, {}, moved)]
    carried = 0
    for ms, xi, speed, keywords, grid in plan:
        stamp = T0 + ms * MS
        twist((fast, slow), rolling_twist(xi, speed=speed, stamp_ns=stamp))
        before = len(python_solves)
        a, b = feed((fast, slow), "left", cloud_msg(grid, stamp_ns=stamp, dtype="<f8",
                                                    **keywords))
        same(a, b)
        carried += len(python_solves) == before and a.status == "solved"
        m, n = fast._memories["left"], slow._memories["left"]
        assert (m.state is None) == (n.state is None) and m.counts == n.counts
        if m.state is not None:
            assert np.array_equal(m.state.tau_x, n.state.tau_x)
            assert np.array_equal(m.state.tau_y, n.state.tau_y)
            assert (m.state.grid, m.state.area, m.state.centroid, m.state.half_length,
                    m.state.force) == (n.state.grid, n.state.area, n.state.centroid,
                                       n.state.half_length, n.state.force)
            # the far field's Jacobian, carried too (NaN: none yet)
            assert np.array_equal(m.state.far_slope, n.state.far_slope, equal_nan=True)
            assert (m.stamp_ns, m.direction, m.lost) == (n.stamp_ns, n.direction, n.lost)
    counts = fast._memories["left"].counts
    assert counts["start"] == 1 and counts["stamp_gap"] == 1 and counts["reversed"] == 1
    assert counts["lost_contact"] == 1 and counts["resampled"] == 1
    assert counts["patch_jump"] == 2  # half the patch gone, then back
    # the Python path solved the resets (a jump after the compiled solve had found it)
    assert [(s - T0) // MS for s in python_solves] == [0, 100, 102, 107, 110, 113, 114]
    assert carried == len(plan) - 1 - 7


@pytest.mark.parametrize("bag", ["bad_inputs", "flange_shift", "hertz_ramp", "roller_rig",
                                 "semi_ellipses_spin", "transient_step"])
def test_transient_rolling_on_the_bundled_bags_equals_the_python_path(bag):
    """Every bundled bag with ``rolling: transient``: the same outcomes on both paths.

    Their bad inputs, stamp gaps, lifted wheels, jumps and resamples
    included (bad_inputs, flange_shift and semi_ellipses_spin meet each of
    these rules); the memories' reset counts equal too.
    """
    from pathlib import Path

    from rosbags.highlevel import AnyReader

    from fastsim_ros.ros.params import load_params_file
    bags = Path(__file__).resolve().parent.parent / "bags"
    values = load_params_file(bags / f"{bag}.params.yaml")
    values["rolling"] = "transient"
    fast, slow = (Pipeline(PipelineConfig.from_values(values)) for _ in range(2))
    assert fast._compiled is not None
    slow._compiled = None
    handlers = [{i.topic: i.take for i in p.inputs()} for p in (fast, slow)]
    outcomes = 0
    with AnyReader([bags / bag]) as reader:
        for connection, _, raw in reader.messages():
            topic = connection.topic.lstrip("/")
            if topic not in handlers[0]:
                continue
            a, b = (h[topic](bytes(raw)) for h in handlers)
            assert len(a) == len(b)
            for x, y in zip(a, b):
                same(x, y)
                outcomes += 1
    assert outcomes > 0
    for contact in fast.config.contacts:
        if contact in fast._memories:
            assert fast._memories[contact].counts == slow._memories[contact].counts


def test_the_kernel_cache_is_keyed_on_every_compiled_source():
    """The cache is keyed on every compiled source: numba checks only a kernel's own file.

    ``transient.py``'s kernels are compiled into ``pipeline_kernels.solve_cloud``;
    with ``transient.py`` left out of the key, a changed transient step loaded
    the pipeline's old machine code from the cache (the compiled path then
    disagreed with the library by 0.7 N in a development tree).  Every module
    with compiled functions must be in the key, and so must every package
    module they import whole or take constants (upper-case names) from.
    """
    import re

    import fastsim_ros
    root = Path(fastsim_ros.__file__).resolve().parent
    keyed = {(root / name).resolve() for name in fastsim_ros._KERNEL_SOURCES}
    files = [*root.rglob("*.py"), *(root.parent / "msg_adapters").glob("*.py")]
    compiled = [f for f in files if re.search(r"@njit|= njit\(", f.read_text())]
    assert compiled
    for f in compiled:
        assert f.resolve() in keyed, f
        for pkg, names in re.findall(
                r"^\s*from ((?:fastsim_ros|msg_adapters)[\w.]*) import \(?([^)\n]*)",
                f.read_text(), flags=re.M):
            base = root.parent.joinpath(*pkg.split("."))
            for name in (n.split(" as ")[0].strip() for n in names.split(",")):
                if not name:
                    continue
                module = base / f"{name}.py"
                if module.exists():  # a module imported whole
                    assert module.resolve() in keyed, (f, module)
                elif name.isupper():  # a constant, frozen into the kernels
                    assert base.with_suffix(".py").resolve() in keyed, (f, pkg, name)


def test_the_keyed_cache_holds_when_numba_was_imported_first(tmp_path):
    """A script that imports numba before the package still caches under the sources' key.

    numba reads ``NUMBA_CACHE_DIR`` when it is imported: a benchmark that
    imported numba first kept numba's default, ``__pycache__`` keyed on each
    file's own time stamp, and ``transient.py``'s solves loaded machine code
    compiled against an older ``kernels.rolling_sweep`` (a doubled force in
    ``rolling_sweep`` left ``mae_rolling_solve``'s answer as it was).  Only
    the cache's directory is set: what the script set in code stays.
    """
    import os
    import subprocess
    import sys

    probe = ("import os, numba, numba.core.config as c, fastsim_ros; "
             "from fastsim_ros.contact import transient; "
             "print(c.CACHE_DIR); print(os.environ['NUMBA_CACHE_DIR']); "
             "print(transient.mae_rolling_solve._cache._cache_path)")
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "FASTSIM_ROS_NUMBA_CACHE_DIR")}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    env["PYTHONPATH"] = os.pathsep.join([str(Path(__file__).resolve().parents[1]),
                                         env.get("PYTHONPATH", "")])
    done = subprocess.run([sys.executable, "-c", probe], env=env, cwd=str(tmp_path),
                          capture_output=True, text=True, timeout=120, check=True)
    numba_dir, chosen, cache_path = done.stdout.split()
    assert chosen.startswith(str(tmp_path))
    assert numba_dir == chosen
    assert cache_path.startswith(chosen)
    # and what the script set in code stays set (a reload of numba's settings reset it)
    probe = ("import numba; numba.config.DISABLE_JIT = True; import fastsim_ros; "
             "from fastsim_ros.contact import transient; "
             "print(numba.config.DISABLE_JIT, type(transient.elastic_sweep).__name__)")
    done = subprocess.run([sys.executable, "-c", probe], env=env, cwd=str(tmp_path),
                          capture_output=True, text=True, timeout=120, check=True)
    assert done.stdout.split() == ["True", "function"]
