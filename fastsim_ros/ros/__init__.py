"""The ROS front ends and the tables they check their input against.

:mod:`~fastsim_ros.ros.node` holds ``fastsim_node`` and its lifecycle
variant (rclpy), :mod:`~fastsim_ros.ros.entry` their console scripts;
:mod:`~fastsim_ros.ros.params` declares the node's parameters and
:mod:`~fastsim_ros.ros.plausibility` the plausible values of wheel-rail
contact, tables the command lines, the pipelines and the replay check
against too.  Importing this package imports no ROS module: only
:mod:`~fastsim_ros.ros.node` does.
"""
