"""The pipelines the node and the replay share: kinematics and patches (or poses) in, forces out.

:class:`Pipeline` (:mod:`fastsim_ros.pipeline.steady`) turns patches into
creep forces; :class:`ProfilePipeline` (:mod:`fastsim_ros.pipeline.profiles`)
makes the patches from wheel and rail profiles and the wheelset's pose,
then runs a :class:`Pipeline`.  Their topics and the output table are
:mod:`fastsim_ros.pipeline.topics`, what they give
:mod:`fastsim_ros.pipeline.outcomes`; the compiled per-patch path is
:mod:`fastsim_ros.pipeline.kernels`, its constants
:mod:`fastsim_ros.pipeline.compiled_state`; the screen of a solved patch
against the plausible values :mod:`fastsim_ros.pipeline.plausibility`; the
friction estimator's cycle :mod:`fastsim_ros.estimation.cycle`.  No ROS import: the node and
``fastsim_replay`` are thin front ends of these.
"""

from fastsim_ros.estimation.cycle import IMPLAUSIBLE_FORCE
from fastsim_ros.pipeline.outcomes import (NO_CONTACT, SINCE_START, SINCE_START_KEY, SOLVED,
                                           SOLVE_TIME_WINDOW, ContactReport, ContactStats,
                                           FrictionEstimate, Outcome, Solved, WheelsetWrench)
from fastsim_ros.pipeline.profiles import (LOAD_TOPIC, MIN_CONTACT_CELLS, POSE_TOPIC, SIDES,
                                           ProfileCycle, ProfilePipeline, TableContact,
                                           contact_name, make_pipeline, placement_of,
                                           table_grid_of, table_of, wheelset_of)
from fastsim_ros.pipeline.plausibility import implausible, patch_extent
from fastsim_ros.pipeline.steady import FRAME_TOLERANCE, TWIST_HISTORY, Pipeline, PipelineConfig
from fastsim_ros.pipeline.topics import (CONTACT_OUTPUTS, DIAGNOSTICS_TOPIC,
                                         FRICTION_ESTIMATE_TOPIC, MARKERS_TOPIC,
                                         MEASURED_WRENCH_TOPIC, RAIL_TWIST_TOPIC,
                                         SLOPE_ESTIMATE_TOPIC, WEAR_OUTPUTS, WHEEL_TWIST_TOPIC,
                                         WHEELSET_WRENCH_TOPIC, InputHandler, InputTopic,
                                         output_topics, patch_topic)

__all__ = [
    "CONTACT_OUTPUTS", "DIAGNOSTICS_TOPIC", "FRAME_TOLERANCE", "FRICTION_ESTIMATE_TOPIC",
    "IMPLAUSIBLE_FORCE", "LOAD_TOPIC", "MARKERS_TOPIC", "MEASURED_WRENCH_TOPIC",
    "MIN_CONTACT_CELLS", "NO_CONTACT", "POSE_TOPIC", "RAIL_TWIST_TOPIC", "SIDES", "SINCE_START",
    "SINCE_START_KEY", "SLOPE_ESTIMATE_TOPIC", "SOLVED", "SOLVE_TIME_WINDOW", "TWIST_HISTORY",
    "WEAR_OUTPUTS", "WHEELSET_WRENCH_TOPIC", "WHEEL_TWIST_TOPIC", "ContactReport",
    "ContactStats", "FrictionEstimate", "InputHandler", "InputTopic", "Outcome", "Pipeline",
    "PipelineConfig", "ProfileCycle", "ProfilePipeline", "Solved", "TableContact",
    "WheelsetWrench", "contact_name", "implausible", "make_pipeline", "output_topics",
    "patch_extent", "patch_topic", "placement_of", "table_grid_of", "table_of", "wheelset_of",
]
