"""``fastsim_node``: the ROS 2 node (default name ``fastsim``), a thin front end of the pipeline.

Topics, frames and parameters: docs/guide_node.md.  The node declares every
parameter of :mod:`fastsim_ros.ros.params` with its descriptor and range,
builds one :class:`~fastsim_ros.pipeline.Pipeline` and wires topics to it:
it subscribes to every input of the pipeline's one
table (:meth:`~fastsim_ros.pipeline.Pipeline.inputs`: a topic, its type and
its handler; a new input is added there) and publishes the outcomes each
handler returns.  The hot path is lean on purpose: inputs arrive raw (CDR
bytes, decoded by :mod:`msg_adapters.cdr` with numpy views on the point
buffer, no Python message built), and every output is published as the
CDR bytes :meth:`~fastsim_ros.pipeline.Pipeline.messages` encodes.

QoS, chosen so that every peer matches: subscriptions best effort (a best
effort subscription matches reliable and best-effort publishers, and a
late patch is worth less than the next one), publishers reliable (matches
every subscriber), depth ``qos_depth``; both configurable at start.
"""

from __future__ import annotations

import contextlib
import gc
import importlib
import math
import re
import signal
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

import rclpy
from rclpy.exceptions import (InvalidParameterTypeException, InvalidParameterValueException,
                              ParameterException, ParameterUninitializedException)
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from rclpy.node import Node
from rclpy.event_handler import PublisherEventCallbacks
from rclpy.parameter import Parameter
from rclpy.publisher import Publisher
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.subscription import Subscription

from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import (FloatingPointRange, IntegerRange, ParameterDescriptor,
                                ParameterType, SetParametersResult)

from fastsim_ros.ros import params as parameters
from fastsim_ros.errors import ParameterError, StartupError

if TYPE_CHECKING:
    from fastsim_ros.pipeline import InputTopic, Outcome, PipelineConfig
    from fastsim_ros.pipeline.profiles import AnyPipeline

NODE_NAME = "fastsim"
_TYPES = {"double": ParameterType.PARAMETER_DOUBLE,
          "integer": ParameterType.PARAMETER_INTEGER,
          "bool": ParameterType.PARAMETER_BOOL,
          "string": ParameterType.PARAMETER_STRING,
          "string_array": ParameterType.PARAMETER_STRING_ARRAY,
          "double_array": ParameterType.PARAMETER_DOUBLE_ARRAY}
#: libyaml's loader where built (a params file in 0.5 ms, not 7: the check is on the start)
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
#: least time (s) between two looks at the ROS graph for patch topics no contact takes
GRAPH_PERIOD = 1.0


class ThrottledLog:
    """A warning at most once per ``period`` (s), checked before any message is built.

    rclpy's own ``throttle_duration_sec`` decides only after it has located
    its caller (``inspect`` and file-system calls, ~300 us here), for every
    message it then drops: at kHz rates a run of rejected patches would cost
    more than solving them.  Here a suppressed warning costs a clock read.
    """

    __slots__ = ("_logger", "_period", "_next", "suppressed")

    def __init__(self, logger: Any, period: float = 1.0) -> None:
        self._logger = logger
        self._period = period
        self._next = -math.inf
        self.suppressed = 0

    def due(self) -> bool:
        """Return whether a warning may go out now (then the next one waits a period)."""
        now = time.monotonic()
        if now < self._next:
            self.suppressed += 1
            return False
        self._next = now + self._period
        return True

    def warning(self, message: str) -> None:
        """Log ``message``, with how many were suppressed since the last one."""
        if self.suppressed:
            message += f" (and {self.suppressed} more in the last {self._period:g} s)"
            self.suppressed = 0
        self._logger.warning(message)


def descriptor(spec: parameters.ParameterSpec, *,
               read_only: bool | None = None) -> ParameterDescriptor:
    """Return the ROS parameter descriptor of a parameter spec.

    ``read_only``: default, the start-only parameters (``not spec.dynamic``).
    """
    d = ParameterDescriptor(type=_TYPES[spec.kind], description=spec.description,
                            additional_constraints=spec.allowed(),
                            read_only=(not spec.dynamic) if read_only is None else read_only)
    if spec.switch:  # on/off arrive as strings or as YAML's booleans: checked by the spec
        d.type, d.dynamic_typing = ParameterType.PARAMETER_NOT_SET, True
    if spec.low is not None and spec.high is not None:
        if spec.kind == "double":
            d.floating_point_range = [FloatingPointRange(
                from_value=float(spec.low), to_value=float(spec.high), step=0.0)]
        else:
            d.integer_range = [IntegerRange(from_value=int(spec.low), to_value=int(spec.high),
                                            step=1)]
    return d


def _qos(reliability: str, depth: int) -> QoSProfile:
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth,
                      reliability=(ReliabilityPolicy.BEST_EFFORT if reliability == "best_effort"
                                   else ReliabilityPolicy.RELIABLE))


#: the parameters declared as doubles, and as lists of doubles
_DOUBLES = frozenset(spec.name for spec in parameters.PARAMETERS if spec.kind == "double")
_DOUBLE_ARRAYS = frozenset(spec.name for spec in parameters.PARAMETERS
                           if spec.kind == "double_array")


def _as_declared(given: Parameter) -> Parameter:
    """Return ``given`` as double(s) if whole numbers were given for a double (array) parameter."""
    if given.name in _DOUBLES and given.type_ == Parameter.Type.INTEGER:
        return Parameter(given.name, Parameter.Type.DOUBLE, float(given.value))
    if given.name in _DOUBLE_ARRAYS and given.type_ == Parameter.Type.INTEGER_ARRAY:
        return Parameter(given.name, Parameter.Type.DOUBLE_ARRAY,
                         [float(v) for v in given.value])
    return given


class _FrontEnd:
    """The wiring the plain and the managed node share (a mixin of an rclpy node).

    Three steps, which the plain node takes in its constructor and the
    managed node in its transitions: :meth:`_declare` (every parameter with
    its descriptor), :meth:`_configure` (check the values, warm the kernels,
    build the pipeline: profiles read and placed, a contact table loaded or
    built) and :meth:`_open` (publishers, subscriptions, the diagnostics
    timer); :meth:`_close` undoes :meth:`_open`.  While ``_active`` is
    false every input is dropped and counted, and nothing is published.
    """

    pipeline: AnyPipeline
    _active: bool = True
    _dropped_inactive: int = 0
    _contacts_given: bool = False
    _warm: float = 0.0
    _diagnostics: Publisher | None = None
    _timer: Any = None
    #: patch topics with publishers and no contact: topic -> (contact name, publishers)
    _unheard: dict[str, tuple[str, int]]
    #: the unheard topics already logged (once per topic)
    _unheard_logged: set[str]
    _graph_next: float = -math.inf

    def finished(self) -> bool:
        """Return whether the node is done and its process should end (never, here)."""
        return False

    def _apply_descriptor(self, parameter: Parameter, descriptor: Any = None,
                          check_read_only: bool = True) -> SetParametersResult:
        """Check a value against its descriptor as rclpy does, completing a wrong type's reason.

        rclpy refuses a value of another type before any callback of ours
        runs, with "Wrong parameter type, expected ... got ..." alone;
        every refusal names the parameter and its range (docs/guide_node.md).
        The reason keeps rclpy's words first (rclpy maps them to its type
        exception) and adds the parameter's name and what it takes.
        """
        result: SetParametersResult = super()._apply_descriptor(  # type: ignore[misc]
            parameter, descriptor, check_read_only)
        spec = parameters.SPECS.get(parameter.name)
        if (not result.successful and spec is not None
                and result.reason.startswith("Wrong parameter type")):
            result.reason = (f"{result.reason} for parameter {parameter.name!r}: it must be "
                             f"{spec.allowed()}")
        return result

    # --- the three steps --------------------------------------------------------------
    def _declare(self, *, start_only_read_only: bool = True) -> None:
        """Declare every parameter; ``contacts`` defaults to the profiles' four in that mode.

        ``start_only_read_only``: start-only parameters get a read-only
        descriptor (the plain node; a managed node re-reads them at each
        ``configure`` and refuses their change while configured instead).
        """
        node: Node = self  # type: ignore[assignment]
        # given at launch (a ROS argument or a params file): then checked as given
        overrides = getattr(node, "_parameter_overrides", {})
        self._contacts_given = "contacts" in overrides
        # a whole number for a double (`-p friction_coefficient:=1`, `ros2 param set ... 1`)
        # is that double: rclpy types the value by its spelling and refused it
        for name, given in list(overrides.items()):
            overrides[name] = _as_declared(given)
        node.add_pre_set_parameters_callback(
            lambda given: [_as_declared(p) for p in given])
        source_spec = parameters.SPECS["patch_source"]
        try:
            source = node.declare_parameter(
                source_spec.name, source_spec.default,
                descriptor(source_spec, read_only=start_only_read_only)).value
        except (InvalidParameterValueException, InvalidParameterTypeException,
                ParameterException) as e:
            raise StartupError(_parameter_problem(e, source_spec)) from None
        spec = source_spec
        try:
            for spec in parameters.PARAMETERS:
                if spec is source_spec:
                    continue
                default: Any = spec.default
                if spec.name == "contacts":
                    # in profiles mode the contacts are fixed per wheel, so
                    # they are the default there and any other value is refused
                    default = list(parameters.PROFILE_CONTACTS if source == "profiles"
                                   else spec.default)
                elif spec.kind in ("string_array", "double_array"):
                    default = list(spec.default)
                node.declare_parameter(spec.name, default, descriptor(
                    spec, read_only=start_only_read_only and not spec.dynamic))
        except (InvalidParameterValueException, InvalidParameterTypeException,
                ParameterException) as e:
            raise StartupError(_parameter_problem(e, spec)) from None

    def _warn_unmatched(self, argv: Sequence[str] | None) -> None:
        """Log what of the launch's parameters no parameter of the node takes; start anyway.

        rclpy ignores an override no parameter is declared for (a typo such
        as ``-p friction_coeficient:=0.4``), and a params file's section that
        matches no node name never reaches the node (``fastsim_node:`` for a
        node named ``fastsim``): both are found by the rule the replay refuses
        them with (:func:`fastsim_ros.ros.params.unmatched`), on the overrides
        the node was given and on the ``--params-file`` files of ``argv``
        (its ROS arguments; None: only the overrides).
        """
        node: Node = self  # type: ignore[assignment]
        fqn = node.get_fully_qualified_name()
        log = node.get_logger()
        found: list[str] = []
        named: set[str] = set()
        for path in parameters.ros_params_files(argv or ()):
            try:  # rcl has parsed it already: a file it refused never gets here
                content = yaml.load(Path(path).read_text(encoding="utf-8"), Loader=_YAML_LOADER)
            except (OSError, UnicodeDecodeError, yaml.YAMLError):
                continue
            for finding in parameters.unmatched(fqn, content):
                named.add(finding.name)
                found.append(f"{path}: {finding}")
        overrides = getattr(node, "_parameter_overrides", {})
        found += [str(f) for f in parameters.unmatched(fqn, overrides=overrides)
                  if f.name not in named]
        for line in found:
            log.warning(f"not used: {line}")

    def _configure(self, log: Callable[[str], None]) -> PipelineConfig:
        """Check the declared values, warm the kernels and build the pipeline."""
        node: Node = self  # type: ignore[assignment]
        values = {}
        spec = parameters.PARAMETERS[0]
        try:
            for spec in parameters.PARAMETERS:
                try:
                    value = node.get_parameter(spec.name).value
                except ParameterUninitializedException:
                    # an empty list at launch (`contacts:=[]`): rclpy cannot type it and
                    # leaves the parameter unset; refused as the empty list it was
                    value = [] if spec.kind.endswith("_array") else None
                values[spec.name] = spec.check(value)
            if not self._contacts_given:
                # the mode's own contacts (profiles: fixed per wheel), not a declared default
                del values["contacts"]
            checked = parameters.checked(values)
        except ParameterError as e:
            raise StartupError(str(e)) from None
        # the solver's modules (numba and its kernels, about half a second) load once the
        # parameters are known good: a start refused for them ends without
        import fastsim_ros.numba_quietly  # noqa: F401  (first: numba without its coverage hook)
        from fastsim_ros.contact import compiled
        from fastsim_ros.pipeline import PipelineConfig
        from fastsim_ros.pipeline import kernels as pipeline_kernels
        from fastsim_ros.pipeline.profiles import make_pipeline
        from msg_adapters import patch as patch_adapter
        config = PipelineConfig(checked)
        try:  # profiles mode reads and places its profiles here (and builds its table)
            pipeline = make_pipeline(config, log=log)
        except ParameterError as e:  # a profile file or placement: one line
            raise StartupError(str(e)) from None
        # the kernels loaded (compiled, on a cold cache: tens of seconds) after the profiles
        # are read, so that a missing or unreadable profile is told at once; a table build
        # loads what it uses as it goes
        warm = compiled.warm_up()
        start = time.perf_counter()
        patch_adapter.warm_up()
        pipeline_kernels.warm_up()
        self._warm = warm + time.perf_counter() - start
        self.pipeline = pipeline
        return config

    def _open(self) -> None:
        """Create the publishers, the subscriptions and the diagnostics timer."""
        from fastsim_ros.pipeline import DIAGNOSTICS_TOPIC, ProfilePipeline
        node: Node = self  # type: ignore[assignment]
        config = self.pipeline.config
        depth = int(config["qos_depth"])
        qos_in = _qos(config["patch_reliability"], depth)
        qos_out = _qos(config["output_reliability"], depth)
        # every topic by its name as configured: the diagnostics report how many
        # peers each has matched (publishers of an input, subscribers of an output)
        self._pubs: dict[str, Publisher] = {}
        self._subs: dict[str, Subscription] = {}
        # the outputs somebody subscribes to, kept by DDS's matched events: only
        # those are encoded and published (a message to nobody is work for nothing)
        self._wanted: set[str] = set()
        # one throttle per contact: a contact that keeps failing must not hide another's
        # rejections behind its own "(and N more)"
        self._rejections = {c: ThrottledLog(node.get_logger()) for c in config.contacts}
        # what exists now (modules, kernels, the pipeline) lives as long as the node: out
        # of the cyclic collector's sight, so that its passes stay short at kHz rates.  The
        # full pass (30-50 ms) runs here, before any topic exists: a client may start
        # sending as soon as the topics match, and at 1 kHz a patch topic's queue
        # (qos_depth) holds 10 ms
        gc.collect()
        gc.freeze()
        # the pipeline's one table of outputs (profiles mode's has the patches too, so
        # that a recording replays in either mode); /diagnostics has its own publisher
        for topic, msgtype in self.pipeline.outputs().items():
            if topic != DIAGNOSTICS_TOPIC:
                self._pubs[topic] = node.create_publisher(
                    message_type(msgtype), topic, qos_out,
                    event_callbacks=PublisherEventCallbacks(matched=self._matched(topic)))
        self._diagnostics = node.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC, qos_out)
        # the pipeline's one table of inputs: each topic raw to its handler
        for entry in self.pipeline.inputs():
            self._subs[entry.topic] = node.create_subscription(
                message_type(entry.msgtype), entry.topic, self._input_callback(entry), qos_in,
                raw=True)
        self._unheard = {}
        self._unheard_logged = getattr(self, "_unheard_logged", set())
        self._graph_next = -math.inf
        self._timer = node.create_timer(float(config["diagnostics_period"]),
                                        self._publish_diagnostics)
        source = (f"patches from the profiles {config['wheel_profile']} on "
                  f"{config['rail_profile']} at each wheelset/pose"
                  if isinstance(self.pipeline, ProfilePipeline)
                  else "patches from contact/<name>/patch")
        node.get_logger().info(
            f"{source}; solving {', '.join(config.contacts)} with {config['method']} "
            f"(mu {config['friction_coefficient']:g}, bound {config['traction_bound']}); "
            f"kernels ready in {self._warm:.2f} s")

    def _close(self) -> None:
        """Destroy what :meth:`_open` created (a managed node's cleanup and shutdown)."""
        node: Node = self  # type: ignore[assignment]
        for sub in getattr(self, "_subs", {}).values():
            node.destroy_subscription(sub)
        for pub in getattr(self, "_pubs", {}).values():
            node.destroy_publisher(pub)
        if self._diagnostics is not None:
            node.destroy_publisher(self._diagnostics)
            self._diagnostics = None
        if self._timer is not None:
            node.destroy_timer(self._timer)
            self._timer = None
        self._subs, self._pubs, self._wanted = {}, {}, set()

    # --- what the open node does -------------------------------------------------------
    def connections(self) -> dict[str, list[tuple[str, str]]]:
        """Return each contact's matched peers as diagnostic key-values.

        ``publishers/<topic>`` for the contact's patch and the twists,
        ``subscribers/<topic>`` for its outputs and the shared ones: the
        counts DDS matched on the node's side, which a client cannot see
        from its own (a message sent before both sides matched is lost).
        """
        from fastsim_ros.pipeline import MARKERS_TOPIC
        shared = [(f"publishers/{t}", str(s.get_publisher_count()))
                  for t, s in self._subs.items() if not t.startswith("contact/")]
        shared += [(f"subscribers/{t}", str(p.get_subscription_count()))
                   for t, p in self._pubs.items() if not t.startswith("contact/")
                   or t == MARKERS_TOPIC]
        if self._dropped_inactive:
            shared.append(("dropped/inactive", str(self._dropped_inactive)))
        out: dict[str, list[tuple[str, str]]] = {}
        for c in self.pipeline.config.contacts:
            own = f"contact/{c}/"
            out[c] = [(f"publishers/{t}", str(s.get_publisher_count()))
                      for t, s in self._subs.items() if t.startswith(own)]
            out[c] += [(f"subscribers/{t}", str(p.get_subscription_count()))
                       for t, p in self._pubs.items() if t.startswith(own)]
            out[c] += shared
        return out

    def _matched(self, topic: str) -> Callable[[Any], None]:
        """Return the matched-event callback of an output topic's publisher.

        A contact's frame topic that gains a subscriber has the frame
        published at the contact's next solve, moved or not (a viewer
        started after the node on a steady rig got none).
        """
        frame_of = next((c for c in self.pipeline.config.contacts
                         if topic == f"contact/{c}/frame"), None)

        def matched(status: Any) -> None:
            if status.current_count > 0:
                self._wanted.add(topic)
            else:
                self._wanted.discard(topic)
            # (a managed node between cleanup and configure has no pipeline)
            if (frame_of is not None and status.current_count_change > 0
                    and hasattr(self, "pipeline")):
                self.pipeline.republish_frame(frame_of)
        return matched

    def _input_callback(self, spec: InputTopic) -> Callable[[bytes], None]:
        """Return the subscription callback of an input: its handler, then the outputs."""
        node: Node = self  # type: ignore[assignment]
        # inputs without outcomes (twists, the measured wrench): the verdict, logged if a drop
        check, what = spec.check, spec.topic
        if spec.kind in ("wheel_twist", "rail_twist"):
            check = (self.pipeline.on_wheel_twist if spec.kind == "wheel_twist"
                     else self.pipeline.on_rail_twist)
            what = "wheelset twist" if spec.kind == "wheel_twist" else "rail twist"
        if check is not None:
            on = check
            log = ThrottledLog(node.get_logger())

            def screened(raw: bytes) -> None:
                if not self._active:
                    self._dropped_inactive += 1
                    return
                verdict = on(raw)
                if verdict != "ok" and log.due():
                    log.warning(f"{what} dropped: {verdict}")
            return screened
        take, publish = spec.take, self._publish

        def callback(raw: bytes) -> None:
            if not self._active:
                self._dropped_inactive += 1
                return
            for outcome in take(raw):
                publish(outcome)
        return callback

    def _publish(self, outcome: Outcome) -> None:
        """Publish an outcome's messages (CDR bytes), or log why there are none."""
        if not outcome.has_wrench:
            log = self._rejections.get(outcome.contact)
            if log is None:   # an outcome of no configured contact (a pose's): its own
                node: Node = self  # type: ignore[assignment]
                log = self._rejections[outcome.contact] = ThrottledLog(node.get_logger())
            if log.due():
                log.warning(f"{outcome.contact}: patch rejected, "
                            f"{outcome.status}: {outcome.detail}")
            return
        pubs = self._pubs
        try:
            for topic, data in self.pipeline.messages(outcome, self._wanted):
                pubs[topic].publish(data)
        except _rclpy.RCLError:
            self._raise_unless_shut_down()

    def _raise_unless_shut_down(self) -> None:
        """Re-raise an rcl call's error, unless a signal shut the context down under it.

        SIGINT or SIGTERM shuts the context down from the signal handler, between
        two statements of a callback: the callback's next publish or peer count
        then fails ("publisher's context is invalid") and rclpy's executor would
        log the error with its traceback as FATAL before ``main`` ends the spin.
        That error is the shutdown's, not a fault: the message is dropped, as it
        would have been a moment later.
        """
        node: Node = self  # type: ignore[assignment]
        if node.context.ok():
            raise

    def unheard_values(self) -> list[tuple[str, str]]:
        """Return the patch topics with publishers that no contact takes, as key-values.

        ``unsubscribed/<topic>`` (relative to the node's namespace, as
        ``publishers/<topic>``): the publishers' count and the parameter
        that would take them (``contacts``).  A look at the ROS graph at
        most every :data:`GRAPH_PERIOD` (the diagnostics timer's, off the
        hot path); each such topic is logged once.  Topics mode only: in
        profiles mode the node publishes the patches itself.
        """
        from fastsim_ros.pipeline import ProfilePipeline
        node: Node = self  # type: ignore[assignment]
        if isinstance(self.pipeline, ProfilePipeline):
            return []
        now = time.monotonic()
        if now >= self._graph_next:
            self._graph_next = now + GRAPH_PERIOD
            self._unheard = self._find_unheard()
            for topic, (name, _) in self._unheard.items():
                if topic not in self._unheard_logged:
                    self._unheard_logged.add(topic)
                    node.get_logger().warning(
                        f"{topic} has publishers and no contact takes it: add {name!r} to "
                        f"parameter 'contacts' to solve its patches")
        skip = len(node.get_namespace().rstrip("/")) + 1
        return [(f"unsubscribed/{topic[skip:]}", f"{count} publisher(s); add {name!r} to "
                 "parameter 'contacts' to take it")
                for topic, (name, count) in sorted(self._unheard.items())]

    def _find_unheard(self) -> dict[str, tuple[str, int]]:
        """Return the graph's ``contact/<name>/patch`` topics with publishers and no contact."""
        node: Node = self  # type: ignore[assignment]
        namespace = node.get_namespace().rstrip("/")
        pattern = re.compile(re.escape(namespace) + r"/contact/([^/]+)/patch")
        contacts = set(self.pipeline.config.contacts)
        found = {}
        for topic, _ in node.get_topic_names_and_types():
            match = pattern.fullmatch(topic)
            if match is not None and match.group(1) not in contacts:
                count = node.count_publishers(topic)
                if count:
                    found[topic] = (match.group(1), count)
        return found

    def _publish_diagnostics(self) -> None:
        if not self._active or self._diagnostics is None:
            return
        node: Node = self  # type: ignore[assignment]
        try:  # the peer counts and the graph are rcl calls too: a signal may end them
            extra = self.connections()
            unheard = self.unheard_values()
            for c in self.pipeline.config.contacts:
                extra[c] = extra.get(c, []) + unheard
            # CDR written directly: the message's ~80 Python objects cost more than the rest
            self._diagnostics.publish(self.pipeline.diagnostics_cdr(
                node.get_clock().now().nanoseconds, extra))
        except _rclpy.RCLError:
            self._raise_unless_shut_down()

    def _set_running(self, changes: list[Parameter]) -> SetParametersResult:
        """Check and apply parameter changes to the running pipeline."""
        node: Node = self  # type: ignore[assignment]
        values = {}
        for p in changes:
            spec = parameters.SPECS.get(p.name)
            if spec is None:
                return SetParametersResult(successful=False,
                                           reason=f"unknown parameter {p.name!r}")
            if not spec.dynamic:
                return SetParametersResult(successful=False, reason=(
                    f"parameter {p.name!r} is set at start only"))
            try:
                values[p.name] = spec.check(p.value)
            except ParameterError as e:
                return SetParametersResult(successful=False, reason=str(e))
        try:
            self.pipeline.update(values)
        except ParameterError as e:
            return SetParametersResult(successful=False, reason=str(e))
        node.get_logger().info("parameters set: " + ", ".join(
            f"{k} = {v!r}" for k, v in values.items()))
        return SetParametersResult(successful=True)


@contextlib.contextmanager
def _destroyed_on_failure(node: Node) -> Iterator[None]:
    """Destroy ``node`` when its construction fails (a refused start), then re-raise.

    The constructor that raises never returns the node to :func:`_run`,
    which destroys only what it was given: the half-built node's entities
    (its rcl node, parameter services, publishers) were left to the garbage
    collector, after the context's shutdown or at the interpreter's exit,
    while the middleware's threads wound down.
    """
    try:
        yield
    except BaseException:
        with contextlib.suppress(Exception):
            node.destroy_node()
        raise


class FastsimNode(_FrontEnd, Node):
    """Creep forces for every contact patch received.

    ``argv``: the process's arguments, whose ``--params-file`` files are
    checked for sections and names the node does not take (a warning).
    """

    def __init__(self, *, argv: Sequence[str] | None = None, **kwargs: Any) -> None:
        super().__init__(NODE_NAME, **kwargs)
        with _destroyed_on_failure(self):
            self._declare()
            self._warn_unmatched(argv)
            self._configure(log=self.get_logger().info)
            self._open()
            self.add_on_set_parameters_callback(self._set_running)


class FastsimLifecycleNode(_FrontEnd, LifecycleNode):
    """The node as a ROS 2 managed (lifecycle) node: ``fastsim_lifecycle_node``.

    Transitions (``lifecycle_msgs``' services ``~/change_state``, ``~/get_state``):

    - ``configure``: check the parameters, warm the kernels, read and place
      the profiles and load or build the contact table (its progress logged
      with the time left); a bad value fails the transition with one line
      naming the parameter, and the node stays ``unconfigured``;
    - ``activate``: create the publishers and subscriptions (the first
      time) and serve; ``deactivate``: publish nothing, every input dropped
      and counted (``dropped/inactive`` in the diagnostics once active again);
    - ``cleanup`` and ``shutdown``: release the topics and the pipeline.

    Start-only parameters may change while ``unconfigured`` (the next
    ``configure`` reads them); the dynamic ones at any time.  ``finalized``
    ends the process (:meth:`finished`).  ``argv``: as :class:`FastsimNode`'s.
    """

    def __init__(self, *, argv: Sequence[str] | None = None, **kwargs: Any) -> None:
        super().__init__(NODE_NAME, **kwargs)
        self._active = False
        self._configured = False
        self._subs, self._pubs, self._wanted = {}, {}, set()
        with _destroyed_on_failure(self):
            self._declare(start_only_read_only=False)
            self._warn_unmatched(argv)
            self.add_on_set_parameters_callback(self._on_set_parameters)
        name = self.get_fully_qualified_name()
        self.get_logger().info(
            f"managed node {name} unconfigured: configure, then activate it through "
            f"{name}/change_state (lifecycle_msgs); shutdown ends the process")

    def finished(self) -> bool:
        """Return whether the node is ``finalized`` (after ``shutdown``): the process ends."""
        label: str = self._state_machine.current_state[1]  # (id, label), as rclpy reads it
        return label == "finalized"

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Check the parameters and build the pipeline (profiles, contact table)."""
        try:
            self._configure(log=self.get_logger().info)
        except StartupError as e:
            self.get_logger().error(f"configure failed: {e}")
            return TransitionCallbackReturn.FAILURE
        self._configured = True
        self.get_logger().info(f"configured in {self._warm:.2f} s of kernel warm-up")
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Open the topics (the first time after configure) and serve."""
        if not self._subs:
            self._open()
        if self._dropped_inactive:
            self.get_logger().info(f"{self._dropped_inactive} inputs dropped while inactive")
        self._active = True
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Stop publishing; inputs are dropped and counted until the next activate."""
        self._active = False
        return super().on_deactivate(state)

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Release the topics and the pipeline (back to ``unconfigured``)."""
        self._release()
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Release everything (``finalized`` follows)."""
        self._release()
        return TransitionCallbackReturn.SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Release everything after an error in a transition; back to ``unconfigured``."""
        self._release()
        return TransitionCallbackReturn.SUCCESS

    def destroy_node(self) -> None:
        """Destroy the node and its lifecycle state machine, which holds the rcl node.

        rclpy 7.1's ``LifecycleNode.destroy_node`` leaves the state machine
        to the garbage collector, and the rcl node (in the graph, its
        middleware entities) with it: measured, the node stayed in its
        context's graph after ``destroy_node`` until the state machine went.
        """
        super().destroy_node()
        machine = getattr(self, "_state_machine", None)
        if machine is not None:
            machine.destroy_when_not_in_use()

    def _release(self) -> None:
        self._active = False
        self._close()
        self._configured = False
        self._dropped_inactive = 0
        if hasattr(self, "pipeline"):
            del self.pipeline

    def _on_set_parameters(self, changes: list[Parameter]) -> SetParametersResult:
        if self._configured:
            return self._set_running(changes)
        for p in changes:  # unconfigured: each value checked now, used at configure
            spec = parameters.SPECS.get(p.name)
            if spec is None:
                return SetParametersResult(successful=False,
                                           reason=f"unknown parameter {p.name!r}")
            try:
                spec.check(p.value)
            except ParameterError as e:
                return SetParametersResult(successful=False, reason=str(e))
            if p.name == "contacts":
                self._contacts_given = True
        return SetParametersResult(successful=True)


def _parameter_problem(error: Exception, spec: parameters.ParameterSpec) -> str:
    """Return a start-up parameter error as one line naming the parameter and its range."""
    if isinstance(error, ParameterError):
        return str(error)
    return (f"parameter {spec.name!r}: {str(error).splitlines()[0]}; it must be "
            f"{spec.allowed()}")


def message_type(name: str) -> Any:
    """Return the message class of a type name such as ``geometry_msgs/msg/TwistStamped``."""
    package, _, cls = name.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), cls)


def make_executor(kind: str) -> Executor:
    """Return the executor ``kind`` names (``events`` or ``single_threaded``).

    The events executor (C++, rclpy.experimental) costs a few microseconds per
    callback where the Python executor rebuilds its wait set each time: at
    several kHz of patches that is the difference between keeping up or not
    (benchmarks/bench_node.py).
    """
    if kind == "events":
        return EventsExecutor()
    return SingleThreadedExecutor()


def main(args: Sequence[str] | None = None) -> int:
    """Run the node until SIGINT or SIGTERM; return the exit status (2: bad parameters)."""
    return _run(FastsimNode, "fastsim_node", args)


def main_lifecycle(args: Sequence[str] | None = None) -> int:
    """Run the managed node (unconfigured until told) until ``finalized``, SIGINT or SIGTERM."""
    return _run(FastsimLifecycleNode, "fastsim_lifecycle_node", args)


#: seconds a finished node still serves before its process ends: the answer to the
#: transition that finished it is sent, but DDS delivers it (and a reliable writer's
#: resends) only while the node exists; a client then sees the new state too
FINISHED_GRACE = 0.5


def _run(make: Callable[..., Node], program: str, args: Sequence[str] | None) -> int:
    """Build a node, spin it until a signal or it finished, always destroy it and shut down."""
    # SIGINT: rclpy's handler (installed by init) shuts the context down, then calls the
    # handler it found, Python's, which raises KeyboardInterrupt wherever the main thread
    # is: inside a callback, rclpy's executor logs it as FATAL with a traceback.  While
    # spinning the shut-down context alone ends the loop, so Python's handler is quiet
    # there; before (a cold kernel compile, a table build) it still interrupts.
    spinning, interrupted = [False], [False]

    def on_sigint(signum: int, frame: Any) -> None:
        if not spinning[0]:
            interrupted[0] = True
            raise KeyboardInterrupt
    previous = signal.signal(signal.SIGINT, on_sigint)
    try:
        return _run_node(make, program, args, spinning, interrupted)
    finally:
        signal.signal(signal.SIGINT, previous)


def _run_node(make: Callable[..., Node], program: str, args: Sequence[str] | None,
              spinning: list[bool], interrupted: list[bool]) -> int:
    """:func:`_run` with Python's SIGINT handler in place.

    ``spinning``: set while spinning; ``interrupted``: set by a SIGINT
    before (the handler raised KeyboardInterrupt).
    """
    try:
        rclpy.init(args=list(args) if args is not None else None)
    except _rclpy.RCLError as e:  # malformed --ros-args: rcl says why
        print(f"{program}: {str(e).splitlines()[0]}", file=sys.stderr)
        return 2
    node: Node | None = None
    executor: Executor | None = None
    status = 0
    try:
        node = make(argv=list(args) if args is not None else sys.argv)
        kind = node.get_parameter("executor").value  # checked at configure, else events
        executor = make_executor(kind if kind in ("events", "single_threaded") else "events")
        executor.add_node(node)
        # the executor too out of the collector's sight (the rest was frozen before the
        # topics opened, so this pass is short)
        gc.collect()
        gc.freeze()
        # spin_once in a loop, not spin(): the events executor's spin() neither
        # runs Python timers nor returns on SIGTERM in this rclpy; spin_once
        # raises ExternalShutdownException once the signal shut the context down
        spinning[0] = True
        finished = node.finished if isinstance(node, _FrontEnd) else (lambda: False)
        while rclpy.ok() and not finished():
            executor.spin_once(timeout_sec=0.25)
        if rclpy.ok():
            node.get_logger().info("finalized: exiting")
            end = time.monotonic() + FINISHED_GRACE
            while rclpy.ok() and time.monotonic() < end:
                executor.spin_once(timeout_sec=max(0.0, end - time.monotonic()))
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except ImportError:
        # the KeyboardInterrupt of a SIGINT while a C extension loads (numba's, imported
        # once the parameters are checked) surfaces as that extension's ImportError
        if not interrupted[0]:
            raise
    except _rclpy.RCLError:
        if rclpy.ok():  # not a signal arriving while the node was being built
            raise
    except StartupError as e:
        print(f"{program}: {e}", file=sys.stderr)
        status = 2
    finally:
        if executor is not None:
            # the node's entities out of the executor, and it shut down, before they go:
            # the events executor aborts the process ("Destroying callback manager with
            # callbacks remaining", exit -6) when a SIGTERM just after start-up leaves it
            # to the garbage collector with the node's callbacks still registered
            # (test_node.py: test_sigterm_and_sigint_end_cleanly)
            if node is not None:
                with contextlib.suppress(Exception):
                    executor.remove_node(node)
            with contextlib.suppress(Exception):
                executor.shutdown()
        if node is not None:
            node.destroy_node()
        del executor
        rclpy.try_shutdown()
    return status


if __name__ == "__main__":
    sys.exit(main())
