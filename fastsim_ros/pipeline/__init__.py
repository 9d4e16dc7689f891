"""The pipelines the node and the replay share: kinematics and patches (or poses) in, forces out.

:class:`Pipeline` (:mod:`fastsim_ros.pipeline.steady`) turns patches into
creep forces; :class:`ProfilePipeline` (:mod:`fastsim_ros.pipeline.profiles`)
makes the patches from wheel and rail profiles and the wheelset's pose,
then runs a :class:`Pipeline`.  The compiled per-patch path is
:mod:`fastsim_ros.pipeline.kernels`.  No ROS import: the node and
``fastsim_replay`` are thin front ends of these.
"""

from fastsim_ros.pipeline.profiles import (LOAD_TOPIC, MIN_CONTACT_CELLS, POSE_TOPIC, SIDES,
                                           ProfileCycle, ProfilePipeline, TableContact,
                                           contact_name, make_pipeline, placement_of,
                                           table_grid_of, table_of, wheelset_of)
from fastsim_ros.pipeline.steady import (CONTACT_OUTPUTS, DIAGNOSTICS_TOPIC, FRAME_TOLERANCE,
                                         FRICTION_ESTIMATE_TOPIC, IMPLAUSIBLE_FORCE,
                                         MARKERS_TOPIC, MEASURED_WRENCH_TOPIC, NO_CONTACT,
                                         RAIL_TWIST_TOPIC, SINCE_START, SINCE_START_KEY,
                                         SLOPE_ESTIMATE_TOPIC, SOLVE_TIME_WINDOW, SOLVED,
                                         TWIST_HISTORY, WEAR_OUTPUTS, WHEEL_TWIST_TOPIC,
                                         WHEELSET_WRENCH_TOPIC, ContactReport, ContactStats,
                                         FrictionEstimate, InputHandler, InputTopic, Outcome,
                                         Pipeline, PipelineConfig, Solved, WheelsetWrench,
                                         implausible, output_topics, patch_extent, patch_topic)

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
