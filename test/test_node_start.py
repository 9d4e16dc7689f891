"""Every bad start of the installed ``fastsim_node``: one line naming the parameter, exit 2.

Table-driven over :data:`fastsim_ros.ros.params.PARAMETERS`: each
parameter with a value out of its range or its choices, each kind with a
value of the wrong type, every profile parameter with a missing file and an
unreadable one, and the combinations the table cannot state alone
(``combination_distance`` above ``separation_distance``, a contact table
without its reference load or with an empty shift range, explicit contacts
in profiles mode).  The starts run two at a time (each is a process of its
own: about half a second to the refusal), once for the whole module.
"""

from __future__ import annotations

import contextlib
import gc
import signal
import subprocess
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from fastsim_ros.ros.params import PARAMETERS, ParameterSpec
from ros_harness import NODE_SCRIPT

pytestmark = pytest.mark.skipif(not NODE_SCRIPT.exists(),
                                reason="fastsim_node is not installed (run colcon build)")

PROFILES = ["-p", "patch_source:=profiles"]
#: a file that is no profile: bytes that are not text
GARBAGE = Path("/tmp") / "fastsim_test_node_start_garbage.prw"


def _value_out_of(spec: ParameterSpec) -> str | None:
    """Return a ROS argument value outside ``spec``'s range or choices (None: it has none)."""
    if spec.choices:
        return "no_such_choice"
    if spec.low is None or spec.high is None:
        return None
    if spec.kind == "integer":
        return str(int(spec.high) + 1)
    return repr(float(spec.high) * 10.0 + 1.0)


def _cases() -> list[tuple[str, str, list[str]]]:
    """Return (id, the parameter the line must name, ROS arguments) for every bad start."""
    cases = []
    for spec in PARAMETERS:
        bad = _value_out_of(spec)
        if bad is not None:
            cases.append((f"{spec.name}-range", spec.name, ["-p", f"{spec.name}:={bad}"]))
    wrong_type = {"double": "'a word'", "integer": "2.5", "bool": "'maybe'",
                  "string": "[1, 2]", "string_array": "3", "double_array": "'a word'"}
    for kind, bad in wrong_type.items():
        spec = next(s for s in PARAMETERS if s.kind == kind)
        cases.append((f"{spec.name}-type", spec.name, ["-p", f"{spec.name}:={bad}"]))
    cases.append(("wheelset_frame-empty", "wheelset_frame", ["-p", "wheelset_frame:=''"]))
    cases.append(("contacts-duplicate", "contacts", ["-p", 'contacts:=["left", "left"]']))
    cases.append(("contacts-bad-name", "contacts", ["-p", 'contacts:=["left", "9x"]']))
    # an empty list: rclpy cannot type it and leaves the parameter unset (no traceback)
    cases.append(("contacts-empty", "contacts", ["-p", "contacts:=[]"]))
    for name in ("wheel_profile", "rail_profile", "right_wheel_profile", "right_rail_profile"):
        suffix = ".prw" if "wheel" in name else ".prr"
        cases.append((f"{name}-missing", name,
                      PROFILES + ["-p", f"{name}:=/nonexistent/profile{suffix}"]))
        cases.append((f"{name}-unreadable", name,
                      PROFILES + ["-p", f"{name}:={GARBAGE.with_suffix(suffix)}"]))
    cases += [
        ("combination-above-separation", "combination_distance",
         PROFILES + ["-p", "separation_distance:=0.002", "-p", "combination_distance:=0.004"]),
        ("table-without-load", "wheel_load",
         PROFILES + ["-p", "profile_table:=true", "-p", "wheel_load:=0.0"]),
        ("table-step-not-dividing", "table_dy_step",
         PROFILES + ["-p", "profile_table:=true", "-p", "wheel_load:=1e4",
                     "-p", "table_dy_step:=0.007"]),
        ("table-empty-range", "table_dy_min",
         PROFILES + ["-p", "profile_table:=true", "-p", "wheel_load:=1e4",
                     "-p", "table_dy_min:=0.01", "-p", "table_dy_max:=-0.01"]),
        ("profiles-explicit-contacts", "contacts",
         PROFILES + ["-p", 'contacts:=["left", "right"]']),
        ("unknown-executor", "executor", ["-p", "executor:=threads"]),
        # a wear table whose breakpoints and values differ in number, or go back
        ("wear-table-lengths", "wear_function_x", ["-p", "wear_function_x:=[0.0, 1.0]"]),
        ("rcf-table-decreasing", "rcf_function_x",
         ["-p", "rcf_function_x:=[0.0, 65.0, 15.0, 175.0]"]),
    ]
    return cases


CASES = _cases()


#: a refusal takes about a second; a start still running after this long is hung
HANG_SECONDS = 60


def _start(args: list[str]) -> subprocess.CompletedProcess[str]:
    """Start the node with ``args``; a start that hangs is killed and started once more.

    A refusal is over in about a second, but one start in a full suite's worth of
    them was once seen to hang past two minutes (in CI, not reproduced in 270 starts
    here: DDS's participant set-up is the only thing a refusal waits on).  That
    hang is the middleware's, not the refusal's; it is retried once and reported
    as a warning, and a second hang fails the case with what the node had printed,
    instead of taking every other case down with it.
    """
    command = [str(NODE_SCRIPT), "--ros-args", *args]
    try:
        return subprocess.run(command, capture_output=True, text=True, timeout=HANG_SECONDS)
    except subprocess.TimeoutExpired as first:
        warnings.warn(f"start {args} hung for {HANG_SECONDS} s (stderr so far: "
                      f"{first.stderr!r}); started once more")
    try:
        return subprocess.run(command, capture_output=True, text=True, timeout=HANG_SECONDS)
    except subprocess.TimeoutExpired as second:
        stderr = second.stderr.decode() if isinstance(second.stderr, bytes) else second.stderr
        return subprocess.CompletedProcess(command, -9, "", f"hung twice: {stderr or ''}")


@pytest.fixture(scope="module")
def refusals() -> dict[str, subprocess.CompletedProcess[str]]:
    """Start the node once per case, two at a time; return each case's process."""
    for suffix in (".prw", ".prr"):
        GARBAGE.with_suffix(suffix).write_bytes(bytes(range(256)) * 8)

    def start(case: tuple[str, str, list[str]]) -> subprocess.CompletedProcess[str]:
        return _start(case[2])
    try:
        with ThreadPoolExecutor(2) as pool:
            done = list(pool.map(start, CASES))
    finally:
        for suffix in (".prw", ".prr"):
            GARBAGE.with_suffix(suffix).unlink(missing_ok=True)
    return {case[0]: proc for case, proc in zip(CASES, done)}


def test_a_bare_on_starts_the_estimator():
    # YAML reads `on` as true: the switch takes it (profiles mode too); the start then stops
    # at the next parameter's bad value, which it names alone
    done = _start([*PROFILES, "-p", "friction_estimation:=on",
                   "-p", "friction_process_noise:=-1.0"])
    assert done.returncode == 2
    assert "friction_process_noise" in done.stderr
    assert "friction_estimation'" not in done.stderr


def test_every_parameter_has_a_bad_start_here():
    named = {name for _, name, _ in CASES}
    ranged = {s.name for s in PARAMETERS if _value_out_of(s) is not None}
    # every parameter with a range or choices, and every kind, is refused at least once
    assert ranged <= named
    assert {s.kind for s in PARAMETERS} <= {s.kind for s in PARAMETERS if s.name in named}


@pytest.mark.parametrize("case, name, args", CASES, ids=[c[0] for c in CASES])
def test_a_bad_start_is_one_line_naming_the_parameter_exit_2(refusals, case, name, args):
    done = refusals[case]
    assert done.returncode == 2, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("fastsim_node: ") and name in lines[0], lines[0]
    assert "Traceback" not in done.stderr and done.stdout == ""


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_while_the_node_is_importing_ends_it_with_exit_0(signum):
    """A stop a third of a second after the start (the node's module still importing).

    The console script imported the node's module (rclpy, numpy, numba: about
    half a second) before any handler of the node's was in place: a SIGINT
    printed a KeyboardInterrupt traceback (or rclpy's "C extension isn't
    present"), a SIGTERM killed the process (-15).  ``fastsim_ros.ros.entry``
    imports it with quiet handlers in place.
    """
    proc = subprocess.Popen([str(NODE_SCRIPT), "--ros-args", "-p", "contacts:=[left]"],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    time.sleep(0.3)
    proc.send_signal(signum)
    out, _ = proc.communicate(timeout=HANG_SECONDS)
    assert proc.returncode == 0, out
    assert not any(w in out for w in ("Traceback", "Error", "error", "Fatal")), out


@contextlib.contextmanager
def in_process(*ros_args: str, collector: bool = True):
    """Yield ``(context, nodes)``: an rclpy context of this process's own, shut down after.

    In a DDS domain of its own, without rclpy's signal handlers (pytest keeps
    its own); ``ros_args``: the nodes' ROS arguments; every node put in
    ``nodes`` is destroyed at the end; ``collector=False`` holds the garbage
    collector off meanwhile (a node that lingers then stays where it is).
    """
    import rclpy
    from rclpy.context import Context
    from rclpy.signals import SignalHandlerOptions

    context = Context()
    rclpy.init(args=["--ros-args", *ros_args] if ros_args else [], context=context,
               domain_id=int(time.time()) % 100 + 110,
               signal_handler_options=SignalHandlerOptions.NO)
    nodes: list = []
    if not collector:
        gc.disable()
    try:
        yield context, nodes
    finally:
        gc.enable()
        for node in nodes:
            node.destroy_node()
        rclpy.try_shutdown(context=context)


@pytest.mark.parametrize("managed", [False, True], ids=["node", "lifecycle"])
def test_a_refused_construction_destroys_its_half_built_node(managed):
    """A constructor that refuses its parameters destroys the node it had made.

    ``_run`` destroys only a node it was given; the refused one never
    reached it, so its entities lived as long as the exception's traceback
    or a reference cycle did, up to the garbage collector's pass after the
    context's shutdown.  With the collector held off and the exception
    held, the refused node is no longer in its context's graph as soon as
    the constructor raised.  The lifecycle node's own ``destroy_node``
    releases its state machine too (rclpy's left it, and the rcl node it
    holds, to the collector: measured, the old code fails here).
    """
    import rclpy

    from fastsim_ros.ros.node import FastsimLifecycleNode, FastsimNode, StartupError

    with in_process("-p", "wheelset_frame:=[1, 2]", "-p", "executor:=threads",
                    collector=False) as (context, nodes):
        with pytest.raises(StartupError, match="wheelset_frame") as refused:
            (FastsimLifecycleNode if managed else FastsimNode)(context=context)
        probe = rclpy.create_node("fastsim_test_probe", context=context)
        nodes.append(probe)
        assert probe.get_node_names() == ["fastsim_test_probe"]
        assert refused.tb is not None  # the traceback (and its frames) still held


def test_a_destroyed_lifecycle_node_leaves_the_graph_at_once():
    """``destroy_node`` of the managed node takes its rcl node out of the graph then and there.

    ``_run`` destroys the node, then shuts the context down: with rclpy's
    ``LifecycleNode.destroy_node`` alone the rcl node, held by the state
    machine, outlived the context's shutdown until the collector came.
    """
    import rclpy

    from fastsim_ros.ros.node import FastsimLifecycleNode

    with in_process(collector=False) as (context, nodes):
        node = FastsimLifecycleNode(context=context)
        probe = rclpy.create_node("fastsim_test_probe", context=context)
        nodes.append(probe)
        assert sorted(probe.get_node_names()) == ["fastsim", "fastsim_test_probe"]
        node.destroy_node()
        assert probe.get_node_names() == ["fastsim_test_probe"]


def test_a_value_of_the_wrong_type_at_run_time_names_the_parameter_and_its_range():
    """A bad value is refused naming the parameter and the allowed range.

    rclpy refuses a value of another type before the node's callbacks see
    it, with "Wrong parameter type ..." alone; the node's reason goes on with
    the parameter's name and what it takes (rclpy's words first: it maps them
    to its type exception).  An out-of-range value names both already.
    """
    from rclpy.parameter import Parameter

    from fastsim_ros.ros.node import FastsimLifecycleNode

    with in_process() as (context, nodes):
        node = FastsimLifecycleNode(context=context)
        nodes.append(node)
        for name, value in (("friction_coefficient", "abc"), ("method", 3),
                            ("publish_traction", 1.5)):
            result, = node.set_parameters([Parameter(name, value=value)])
            assert not result.successful
            assert result.reason.startswith("Wrong parameter type"), result.reason
            assert f"for parameter {name!r}: it must be " in result.reason, result.reason
        result, = node.set_parameters([Parameter("friction_coefficient", value="abc")])
        assert result.reason.endswith("in [0.001, 5]")
        assert node.get_parameter("friction_coefficient").value == 0.3
