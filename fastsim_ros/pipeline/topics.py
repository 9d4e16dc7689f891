"""The pipelines' topics: their names, the output table and the input table's entries.

The names are relative (but ``/diagnostics``): a front end resolves them in
its namespace.  :func:`output_topics` is the one table of outputs with their
message types; :meth:`Pipeline.outputs` gives a configured pipeline's, from
which the node creates its publishers and the replay its channels.
:class:`InputTopic` is an entry of :meth:`Pipeline.inputs`, the table of
inputs with their handlers.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from fastsim_ros.pipeline.outcomes import Outcome


def patch_topic(contact: str) -> str:
    """Return the (relative) patch topic of a contact."""
    return f"contact/{contact}/patch"


WHEEL_TWIST_TOPIC, RAIL_TWIST_TOPIC = "wheelset/twist", "rail/twist"
WHEELSET_WRENCH_TOPIC, MARKERS_TOPIC = "wheelset/wrench", "contact/markers"
DIAGNOSTICS_TOPIC = "/diagnostics"
#: online friction estimation (parameter friction_estimation): the measured wrench in, the
#: estimate out (Vector3Stamped: x = mu_s, y = its standard deviation, z = adhesion utilisation)
MEASURED_WRENCH_TOPIC, FRICTION_ESTIMATE_TOPIC = "wheelset/measured_wrench", "friction/estimate"
#: the creep-slope reduction's estimate (friction_estimate_slope_reduction): Vector3Stamped, x =
#: k0, y = its standard deviation, z = the correlation of the mu_s and k0 estimates' errors
SLOPE_ESTIMATE_TOPIC = "friction/slope_estimate"
#: output topics of a contact: relative name -> message type
CONTACT_OUTPUTS = {"wrench": "geometry_msgs/msg/WrenchStamped",
                   "creepage": "geometry_msgs/msg/Vector3Stamped",
                   "frame": "geometry_msgs/msg/PoseStamped",
                   "traction": "sensor_msgs/msg/PointCloud2"}


#: a contact's wear and fatigue topics (parameter wear_outputs; docs/guide_wear.md):
#: energy = (T-gamma N, T-gamma/A Pa, frictional power W), damage = (wear rate kg/(m m^2),
#: RCF damage per passage, frictional power / (T-gamma ``|V|``))
WEAR_OUTPUTS = {"energy": "geometry_msgs/msg/Vector3Stamped",
                "damage": "geometry_msgs/msg/Vector3Stamped"}


def output_topics(contacts: tuple[str, ...], *, patches: bool = False,
                  wear: bool = False) -> dict[str, str]:
    """Return every output topic (relative, but /diagnostics) with its message type.

    ``patches``: the patches are outputs too (profiles mode computes them);
    ``wear``: the wear and fatigue topics too (:data:`WEAR_OUTPUTS`).
    """
    kinds = {**CONTACT_OUTPUTS, **WEAR_OUTPUTS} if wear else CONTACT_OUTPUTS
    topics = {f"contact/{c}/{kind}": msgtype for c in contacts
              for kind, msgtype in kinds.items()}
    if patches:
        topics.update({patch_topic(c): "sensor_msgs/msg/PointCloud2" for c in contacts})
    topics[WHEELSET_WRENCH_TOPIC] = "geometry_msgs/msg/WrenchStamped"
    topics[MARKERS_TOPIC] = "visualization_msgs/msg/MarkerArray"
    topics[DIAGNOSTICS_TOPIC] = "diagnostic_msgs/msg/DiagnosticArray"
    return topics


#: a handler of one input message (CDR bytes): the outcomes it gave (none for kinematics)
InputHandler = Callable[[bytes | memoryview], tuple[Outcome, ...]]


@dataclass(frozen=True)
class InputTopic:
    """One input topic of the pipeline and its handler (front ends dispatch on these).

    ``topic``: relative name; ``msgtype``: its ROS type; ``kind``:
    ``"patch"`` (of ``contact``), ``"wheel_twist"`` or ``"rail_twist"``;
    ``take``: the pipeline's handler of one message (CDR bytes), returning
    the outcomes it gave (none for kinematics); ``check``: for an input
    without outcomes (the measured wrench), the same handler returning
    ``"ok"`` or why the message was dropped (a front end logs it).
    """

    topic: str
    msgtype: str
    kind: str
    contact: str | None
    take: InputHandler
    check: Callable[[bytes | memoryview], str] | None = None
