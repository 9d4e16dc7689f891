"""The node's parameters: one table of names, types, defaults, ranges and descriptions.

The node declares its ROS parameters from :data:`PARAMETERS` (descriptor,
range, read-only flag), and the offline replay checks a params file against
the same table, so a value the node refuses the replay refuses too, with the
same message.  docs/guide_node.md fixes the names.
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from fastsim_ros.contact.errors import InvalidInputError
from fastsim_ros.contact.slope_reduction import SlopeReduction
from fastsim_ros.contact.wear import BURSTOW_RCF, SHEFFIELD_WEAR, PiecewiseLinear
from fastsim_ros.errors import ParameterError

#: the methods of the library the node offers (docs/guide_node.md): the paper's
#: MAE, the calibrated MAE (the default since docs/validation_wider.md shows it better
#: than the paper's on every validation area), FastSim on the equivalent ellipse and
#: Polach's closed form on it (what vehicle-dynamics codes run instead)
METHODS = ("mae", "mae_calibrated", "fastsim_ellipse", "polach")
#: friction laws (:mod:`fastsim_ros.contact.friction`): Coulomb, and the falling
#: mu(v) = mu_s ((1 - A) exp(-B v) + A) of the local slip velocity v
FRICTION_LAWS = ("constant", "exponential")
#: rolling: the steady state each cycle, or the contact's memory between cycles
ROLLING_MODES = ("steady", "transient")
#: patch sources: patch topics, or the profiles and the wheelset's pose
PATCH_SOURCES = ("topics", "profiles")
#: the contacts of profiles mode, fixed per wheel: the patch nearer the tread, then a second
PROFILE_CONTACTS = ("left", "right", "left_flange", "right_flange")
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class ParameterSpec:
    """One parameter; ``kind``: ``double``, ``integer``, ``bool``, ``string`` or an ``_array``.

    Arrays: ``string_array`` (names), ``double_array`` (a table's numbers).

    ``low``/``high``: inclusive numeric range; ``choices``: allowed strings;
    ``dynamic``: may change while the node runs (else start-up only).
    """

    name: str
    kind: str
    default: Any
    description: str
    low: float | None = None
    high: float | None = None
    choices: tuple[str, ...] = ()
    dynamic: bool = False
    empty_ok: bool = False
    #: a switch ``off``/``on``: YAML (and so ``-p name:=on`` and a params file's bare
    #: ``on``) reads those words as booleans, so true/false are taken as on/off too
    switch: bool = False

    def allowed(self) -> str:
        """Return the allowed values in words (for descriptors and error messages)."""
        if self.choices:
            return "one of " + ", ".join(self.choices)
        if self.low is not None:
            return f"in [{self.low:g}, {self.high:g}]"
        if self.kind == "string_array":
            return "a non-empty list of distinct names ([A-Za-z][A-Za-z0-9_]*)"
        if self.kind == "double_array":
            return "a list of at least 2 finite numbers"
        if self.kind == "string":
            return "a string" if self.empty_ok else "a non-empty name"
        return f"a {self.kind}"

    def check(self, value: Any) -> Any:
        """Return ``value`` converted to this parameter's type, or raise ParameterError."""
        bad = ParameterError(f"parameter {self.name!r}: {value!r} is not allowed; "
                             f"it must be {self.allowed()}")
        if self.kind == "double":
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise bad
            value = float(value)
            if not math.isfinite(value):
                raise bad
        elif self.kind == "integer":
            if isinstance(value, bool) or not isinstance(value, int):
                raise bad
        elif self.kind == "bool":
            if not isinstance(value, bool):
                raise bad
        elif self.kind == "string":
            if self.switch and isinstance(value, bool):
                value = "on" if value else "off"
            if not isinstance(value, str) or not (value or self.empty_ok):
                raise bad
        elif self.kind == "string_array":
            if (not isinstance(value, (list, tuple)) or not value
                    or not all(isinstance(v, str) and _NAME.match(v) for v in value)
                    or len(set(value)) != len(value)):
                raise bad
            value = tuple(value)
        elif self.kind == "double_array":
            # a list, a tuple, or rclpy's array.array('d') of a DOUBLE_ARRAY
            if (not isinstance(value, Sequence) or isinstance(value, (str, bytes))
                    or len(value) < 2
                    or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                               and math.isfinite(v) for v in value)):
                raise bad
            value = tuple(float(v) for v in value)
        if self.low is not None and not (self.low <= value <= self.high):  # type: ignore
            raise bad
        if self.choices and value not in self.choices:
            raise bad
        return value


PARAMETERS: tuple[ParameterSpec, ...] = (
    ParameterSpec("contacts", "string_array", ("left", "right"),
                  "names of the contacts: topics contact/<name>/patch in, "
                  "contact/<name>/wrench etc. out"),
    ParameterSpec("wheelset_frame", "string", "wheelset",
                  "frame id of the patches and twists (moves with the wheelset centre, "
                  "does not spin with the axle)"),
    ParameterSpec("shear_modulus", "double", 8.0e10, "combined shear modulus G (Pa)",
                  low=1.0e6, high=1.0e13),
    ParameterSpec("poisson_ratio", "double", 0.28, "combined Poisson ratio nu",
                  low=0.0, high=0.5),
    ParameterSpec("friction_coefficient", "double", 0.3,
                  "friction coefficient mu (the static mu_s of a slip-dependent law)",
                  low=1.0e-3, high=5.0, dynamic=True),
    ParameterSpec("method", "string", "mae_calibrated",
                  "tangential solver: mae (the paper's MAE + FastSim, Alonso & Gimenez 2007), "
                  "mae_calibrated (MAE with pair factors from the exact theory, flexibilities "
                  "calibrated on the patch's cells and slip along the rigid slip, "
                  "docs/validation_wider.md), fastsim_ellipse (FastSim on the equivalent "
                  "ellipse) or polach (Polach's closed form on the equivalent ellipse, "
                  "Polach 1999 and 2005, with polach_ka, polach_ks; forces only: no "
                  "traction, steady rolling; docs/guide_real_rails.md)",
                  choices=METHODS, dynamic=True),
    ParameterSpec("traction_bound", "string", "given",
                  "traction bound: given (mu p) or parabolic (mu N p^2 / sum(p^2 dA))",
                  choices=("given", "parabolic"), dynamic=True),
    ParameterSpec("min_rolling_speed", "double", 0.1,
                  "below this |V| (m/s) creepages are undefined: standstill, no wrench",
                  low=1.0e-6, high=100.0, dynamic=True),
    ParameterSpec("max_kinematics_age", "double", 0.05,
                  "a patch is solved with kinematics at most this old by stamp (s)",
                  low=0.0, high=10.0, dynamic=True),
    ParameterSpec("publish_traction", "bool", False,
                  "publish contact/<name>/traction (PointCloud2 of tau_x, tau_y, slip and the "
                  "frictional power density friction_power)",
                  dynamic=True),
    # --- wear and fatigue outputs (docs/guide_wear.md; fastsim_ros/contact/wear.py)
    ParameterSpec("wear_outputs", "bool", False,
                  "publish contact/<name>/energy (Vector3Stamped: x T-gamma N, y T-gamma/A Pa, "
                  "z frictional power W) and contact/<name>/damage (x wear rate kg/(m m^2), "
                  "y RCF damage per passage, z frictional power / (T-gamma |V|)) per solve, "
                  "and add their columns to the replay's CSV"),
    ParameterSpec("frictional_power", "bool", False,
                  "compute the slip area's frictional power (sum -tau . s |V| dA): the solve "
                  "keeps its tractions and sweeps them once more (steady rolling; NaN when "
                  "off or transient); publish_traction computes it too", dynamic=True),
    ParameterSpec("wear_function_x", "double_array", tuple(SHEFFIELD_WEAR.x),
                  "wear function's breakpoints in T-gamma/A (Pa; non-decreasing, a value "
                  "twice is a jump); default the University of Sheffield function for "
                  "R8T/R260 steel (10.4 and 77.2 N/mm^2)", dynamic=True),
    ParameterSpec("wear_function_y", "double_array", tuple(SHEFFIELD_WEAR.y),
                  "wear rate at each breakpoint (kg per metre rolled per m^2 of contact; "
                  "1 ug/(m mm^2) = 1e-3), linear between, held beyond the ends",
                  dynamic=True),
    ParameterSpec("rcf_function_x", "double_array", tuple(BURSTOW_RCF.x),
                  "RCF damage function's breakpoints in T-gamma (N); default Burstow's "
                  "whole-life rail model (15, 65, 175 N)", dynamic=True),
    ParameterSpec("rcf_function_y", "double_array", tuple(BURSTOW_RCF.y),
                  "RCF damage per wheel passage at each breakpoint (crack initiation at an "
                  "accumulated 1), linear between, held beyond the ends", dynamic=True),
    ParameterSpec("allow_implausible", "bool", False,
                  "accept patches and loads that wheel-rail contact does not have in SI units "
                  "(fastsim_ros/ros/plausibility.py: a patch over 0.1 m across, pressures under "
                  "1e5 Pa, |xi| or |eta| over 0.1, |phi| over 50 1/m, a wheel load outside "
                  "100 N..1 MN): a scaled rig, a full-slip test; otherwise they are rejected "
                  "as 'implausible', a likely unit mistake"),
    ParameterSpec("max_patch_cells", "integer", 16384,
                  "largest patch grid (height x width) accepted, checked before any "
                  "allocation; larger patches are rejected as too_large",
                  low=4, high=4_000_000, dynamic=True),
    ParameterSpec("rail_twist_required", "bool", False,
                  "a patch needs a fresh rail/twist (roller rigs); else a rail at rest",
                  dynamic=True),
    ParameterSpec("friction_law", "string", "constant",
                  "friction law: constant (Coulomb with friction_coefficient) or exponential "
                  "(mu(v) = mu_s ((1 - A) exp(-B v) + A), v the local slip velocity in m/s, "
                  "mu_s = friction_coefficient, A = friction_limit_ratio, B = friction_decay)",
                  choices=FRICTION_LAWS, dynamic=True),
    ParameterSpec("friction_limit_ratio", "double", 1.0,
                  "A of mu(v) = mu_s ((1 - A) exp(-B v) + A), for a slip-dependent law",
                  low=1.0e-6, high=1.0, dynamic=True),
    ParameterSpec("friction_decay", "double", 0.0,
                  "B (s/m) of mu(v) = mu_s ((1 - A) exp(-B v) + A), for a slip-dependent law",
                  low=0.0, high=1.0e4, dynamic=True),
    ParameterSpec("slope_reduction_k0", "double", 1.0,
                  "creep-slope reduction of a contaminated rail (modified FastSim, Spiryagin "
                  "et al. 2013, as CONTACT): k = k0 [alpha_inf + (1 - alpha_inf)/(1 + beta "
                  "eps)] divides the flexibilities; k0 is its value at vanishing creepage "
                  "(1 with alpha_inf 1: the theory's full slope, a clean rail; any other: "
                  "a slip-dependent law is taken at the rigid slip velocity; "
                  "docs/guide_real_rails.md)",
                  low=1.0e-3, high=1.0, dynamic=True),
    ParameterSpec("slope_reduction_alpha_inf", "double", 1.0,
                  "alpha_inf = k(inf)/k0 of the creep-slope reduction",
                  low=0.0, high=1.0, dynamic=True),
    ParameterSpec("slope_reduction_beta", "double", 0.0,
                  "beta of the creep-slope reduction: how fast k falls with Polach's eps "
                  "(the ratio of the slip to the adhesion area)",
                  low=0.0, high=1.0e6, dynamic=True),
    ParameterSpec("polach_ka", "double", 1.0,
                  "Polach's reduction factor kA of the adhesion area's stiffness (method "
                  "polach; Polach 2005; 1: Kalker's slope; kS <= kA <= 1)",
                  low=1.0e-3, high=1.0, dynamic=True),
    ParameterSpec("polach_ks", "double", 1.0,
                  "Polach's reduction factor kS of the slip area (method polach; kS <= kA)",
                  low=1.0e-3, high=1.0, dynamic=True),
    # --- online friction estimation (fastsim_ros/estimation/ekf.py)
    ParameterSpec("friction_estimation", "string", "off",
                  "estimate mu_s online from wheelset/measured_wrench (force.x, wheelset "
                  "frame) with an extended Kalman filter whose measurement model is the "
                  "solver; on: friction/estimate is published and every wrench uses the "
                  "estimate (friction_coefficient is its start)",
                  choices=("off", "on"), switch=True),
    ParameterSpec("friction_process_noise", "double", 2.0e-5,
                  "q (1/s): variance of mu_s added per second (how fast mu may change)",
                  low=0.0, high=10.0, dynamic=True),
    ParameterSpec("friction_measurement_noise", "double", 250.0,
                  "standard deviation of the measured longitudinal force (N, the load cell's)",
                  low=1.0e-6, high=1.0e9, dynamic=True),
    ParameterSpec("friction_estimate_sigma", "double", 0.1,
                  "standard deviation of mu_s at the start of the estimation",
                  low=1.0e-6, high=1.0, dynamic=True),
    ParameterSpec("friction_min_sensitivity", "double", 0.02,
                  "observability threshold on |dF/dmu_s| / N: below it (the linear range) "
                  "the estimate holds and its sigma grows", low=0.0, high=1.0, dynamic=True),
    ParameterSpec("friction_model_error", "double", 0.5,
                  "the creep model's error against the rail, one sigma, as a share of its bound "
                  "mu_s (1 - slip fraction) N (the load on the model's adhesion area): "
                  "samples the model gets wrong weigh little and sigma covers it; 0: the "
                  "model taken as exact (only the load cell's noise)",
                  low=0.0, high=10.0, dynamic=True),
    ParameterSpec("friction_estimate_slope_reduction", "bool", False,
                  "with friction_estimation on, estimate the creep-slope reduction's k0 "
                  "together with mu_s (a two-state filter; slope_reduction_alpha_inf and "
                  "_beta held; k0 is observable in the linear range, mu_s in full slip, both "
                  "at the knee): friction/slope_estimate is published and every wrench uses "
                  "the estimated k0 (slope_reduction_k0 is its start; "
                  "docs/guide_estimation.md)"),
    ParameterSpec("friction_slope_sigma", "double", 0.2,
                  "standard deviation of k0 at the start of its estimation",
                  low=1.0e-6, high=1.0, dynamic=True),
    ParameterSpec("friction_slope_process_noise", "double", 1.0e-4,
                  "q (1/s): variance of k0 added per second (how fast the rail's slope may "
                  "change)", low=0.0, high=10.0, dynamic=True),
    ParameterSpec("rolling", "string", "steady",
                  "steady (each cycle at the steady state) or transient (each contact keeps "
                  "its traction between cycles, convected by |V| dt: Kalker's non-steady "
                  "FastSim, fastsim_ros/contact/transient.py)",
                  choices=ROLLING_MODES, dynamic=True),
    ParameterSpec("transient_max_gap", "double", 0.05,
                  "transient rolling: a longer time (s) between a contact's solved patches "
                  "resets it to the steady state (its history is unknown)",
                  low=1.0e-6, high=10.0, dynamic=True),
    ParameterSpec("publish_markers", "bool", True,
                  "publish contact/markers (one creep-force arrow per contact)", dynamic=True),
    ParameterSpec("marker_scale", "double", 1.0e-5,
                  "arrow length per newton of creep force (m/N)", low=0.0, high=1.0,
                  dynamic=True),
    ParameterSpec("marker_rate", "double", 30.0,
                  "most marker arrays per second by patch stamps (0: every solve)",
                  low=0.0, high=1.0e4, dynamic=True),
    ParameterSpec("patch_reliability", "string", "best_effort",
                  "QoS reliability of the patch and twist subscriptions (best_effort "
                  "matches every publisher)", choices=("best_effort", "reliable")),
    ParameterSpec("output_reliability", "string", "reliable",
                  "QoS reliability of the publishers (reliable matches every subscriber)",
                  choices=("reliable", "best_effort")),
    ParameterSpec("executor", "string", "events",
                  "rclpy executor: events (rclpy.experimental.EventsExecutor, C++: a few us "
                  "per callback) or single_threaded (the classic Python executor)",
                  choices=("events", "single_threaded")),
    ParameterSpec("qos_depth", "integer", 10, "history depth of every subscription and "
                  "publisher", low=1, high=10000),
    ParameterSpec("diagnostics_period", "double", 1.0,
                  "seconds between /diagnostics messages", low=0.01, high=60.0),
    # --- the patch source (docs/guide_profiles.md)
    ParameterSpec("patch_source", "string", "topics",
                  "where patches come from: topics (contact/<name>/patch) or profiles "
                  "(computed each cycle from wheelset/pose, wheelset/load and the profiles; "
                  "the contacts are then left, right, left_flange, right_flange)",
                  choices=PATCH_SOURCES),
    ParameterSpec("track_frame", "string", "track",
                  "frame id of wheelset/pose (profiles mode)"),
    ParameterSpec("wheel_profile", "string", "package://fastsim_ros/data/profiles/"
                  "MBench_S1002_v3.prw",
                  "left wheel profile: SIMPACK .prw or two-column 'y z' file (profiles mode; "
                  "package://fastsim_ros/... names a file shipped with the package)"),
    ParameterSpec("rail_profile", "string", "package://fastsim_ros/data/profiles/"
                  "MBench_UIC60_v3.prr",
                  "left rail profile: SIMPACK .prr or two-column 'y z' file (profiles mode)"),
    ParameterSpec("right_wheel_profile", "string", "",
                  "right wheel profile (empty: the mirror image of the left)", empty_ok=True),
    ParameterSpec("right_rail_profile", "string", "",
                  "right rail profile (empty: the mirror image of the left)", empty_ok=True),
    ParameterSpec("profile_smoothing", "double", 0.0,
                  "smoothing wavelength L_filt of the profiles (m; 0: none)",
                  low=0.0, high=0.05),
    ParameterSpec("gauge_width", "double", 1.435,
                  "track gauge between the rails' inner faces (m)", low=0.3, high=3.0),
    ParameterSpec("gauge_height", "double", 0.014,
                  "depth below the rail top at which the gauge is measured (m)",
                  low=0.0, high=0.1),
    ParameterSpec("cant", "double", 0.0,
                  "rail inclination added to the profile's (rad, positive towards the track "
                  "centre; 0 for profiles that carry theirs)", low=-0.2, high=0.2),
    ParameterSpec("flange_back_distance", "double", 1.360,
                  "distance between the wheels' flange backs (m)", low=0.2, high=3.0),
    ParameterSpec("flange_back_position", "double", -0.070,
                  "flange back's lateral position in the wheel profile's coordinates (m)",
                  low=-0.5, high=0.5),
    ParameterSpec("nominal_radius", "double", 0.460,
                  "wheel radius at the wheel profile's origin (m)", low=0.05, high=2.0),
    ParameterSpec("cell_size", "double", 2.0e-4,
                  "cell size of the potential contact grids computed from profiles (m)",
                  low=2.0e-5, high=5.0e-3),
    ParameterSpec("separation_distance", "double", 8.0e-3,
                  "interpenetration regions of one wheel further apart than this (m) are "
                  "separate patches (CONTACT's D_SEP)", low=0.0, high=0.1),
    ParameterSpec("combination_distance", "double", 4.0e-3,
                  "regions within this (m) are combined first (CONTACT's D_COMB; at most "
                  "separation_distance)", low=0.0, high=0.1),
    ParameterSpec("wheel_load", "double", 0.0,
                  "vertical load per wheel (N) when no wheelset/load arrived; 0: the pose's "
                  "vertical position is used as given", low=0.0, high=1.0e7, dynamic=True),
    # --- the contact table of profiles mode (fastsim_ros/geometry/table.py)
    ParameterSpec("profile_table", "bool", False,
                  "profiles mode: interpolate the patches in a table over lateral shift and "
                  "yaw solved at start (or read from table_cache), at the reference load "
                  "wheel_load, instead of solving each pose (about 1 ms a pose, not 20-200)"),
    ParameterSpec("table_dy_min", "double", -0.012,
                  "contact table: smallest lateral shift (m)", low=-0.05, high=0.05),
    ParameterSpec("table_dy_max", "double", 0.012,
                  "contact table: largest lateral shift (m)", low=-0.05, high=0.05),
    ParameterSpec("table_dy_step", "double", 1.0e-4,
                  "contact table: step of the lateral shift (m; divides the range)",
                  low=1.0e-6, high=0.01),
    ParameterSpec("table_yaw_max", "double", 0.025,
                  "contact table: yaw range +-table_yaw_max (rad; 0: yaw 0 only)",
                  low=0.0, high=0.1),
    ParameterSpec("table_yaw_step", "double", 5.0e-3,
                  "contact table: step of the yaw (rad; divides 2 table_yaw_max)",
                  low=1.0e-5, high=0.1),
    ParameterSpec("table_refine", "integer", 4,
                  "contact table: times the shift intervals whose nodes differ (a contact "
                  "taking over, a contact running fast) are halved", low=0, high=8),
    ParameterSpec("table_cache", "string", "~/.cache/fastsim_ros",
                  "directory of built contact tables (keyed by profiles and parameters; "
                  "empty: build every start, keep none)", empty_ok=True),
)

SPECS: dict[str, ParameterSpec] = {spec.name: spec for spec in PARAMETERS}


def defaults() -> dict[str, Any]:
    """Return every parameter at its default."""
    return {spec.name: spec.default for spec in PARAMETERS}


def reduces_slope(values: Any) -> bool:
    """Tell whether the parameters ask for a creep-slope reduction other than ``k = 1``."""
    return not (values["slope_reduction_k0"] == 1.0
                and (values["slope_reduction_alpha_inf"] == 1.0
                     or values["slope_reduction_beta"] == 0.0))


def slope_reduction_of(values: Any) -> SlopeReduction | None:
    """Return the creep-slope reduction the parameters ask for (None: ``k = 1``).

    ``values``: anything indexed by parameter name (a dict, the pipeline's config).
    """
    if not reduces_slope(values):
        return None
    return SlopeReduction(float(values["slope_reduction_k0"]),
                          float(values["slope_reduction_alpha_inf"]),
                          float(values["slope_reduction_beta"]))


def checked(values: Mapping[str, Any]) -> dict[str, Any]:
    """Return the defaults updated with ``values``, each checked; raise ParameterError."""
    out = defaults()
    for name, value in values.items():
        spec = SPECS.get(name)
        if spec is None:
            raise ParameterError(f"unknown parameter {name!r}")
        out[name] = spec.check(value)
    if out["rolling"] == "transient" and reduces_slope(out):
        raise ParameterError("the creep-slope reduction (slope_reduction_k0 < 1, or "
                             "slope_reduction_alpha_inf < 1 with slope_reduction_beta > 0) "
                             "applies to steady rolling only: set rolling steady, or k0 1 "
                             "and alpha_inf 1")
    if out["friction_estimate_slope_reduction"]:
        for name, bad, why in (("method", out["method"] == "polach",
                                "Polach's slope is reduced by polach_ka and polach_ks"),
                               ("rolling", out["rolling"] == "transient",
                                "the creep-slope reduction applies to steady rolling only")):
            if bad:
                raise ParameterError("parameter 'friction_estimate_slope_reduction': the "
                                     f"estimate of k0 refuses {name} {out[name]!r}: {why}")
    if out["method"] == "polach":
        if out["polach_ks"] > out["polach_ka"]:
            raise ParameterError("parameters 'polach_ka', 'polach_ks': Polach's factors need "
                                 f"kS <= kA, got kA {out['polach_ka']:g}, kS "
                                 f"{out['polach_ks']:g}")
        for name, bad, why in (("publish_traction", out["publish_traction"] is True,
                                "its closed form has no traction field"),
                               ("frictional_power", out["frictional_power"] is True,
                                "its closed form has no traction field to integrate the "
                                "slip's power over (T-gamma and the wear outputs need none)"),
                               ("rolling", out["rolling"] == "transient",
                                "its closed form is steady rolling"),
                               ("slope_reduction_k0", reduces_slope(out),
                                "its slope is reduced by polach_ka and polach_ks")):
            if bad:
                raise ParameterError(f"parameter {name!r}: method polach refuses "
                                     f"{out[name]!r}: {why}")
    if out["patch_source"] == "profiles":
        if "contacts" in values and tuple(out["contacts"]) != PROFILE_CONTACTS:
            raise ParameterError("parameter 'contacts': in profiles mode the contacts are "
                                 "fixed: " + ", ".join(PROFILE_CONTACTS))
        out["contacts"] = PROFILE_CONTACTS
    for table in ("wear_function", "rcf_function"):
        try:
            PiecewiseLinear.of(out[f"{table}_x"], out[f"{table}_y"])
        except InvalidInputError as e:
            raise ParameterError(f"parameters '{table}_x' and '{table}_y': {e}") from None
    return out


def _yaml_problem(error: Exception) -> str:
    """Return a file error as one line: YAML's where and what, without its quoted snippet."""
    if isinstance(error, yaml.MarkedYAMLError) and error.problem_mark is not None:
        mark = error.problem_mark
        return f"line {mark.line + 1}, column {mark.column + 1}: {error.problem}"
    return " ".join(str(error).split())


#: parameters rclpy declares on every node: a node's file may set them, the replay has no use
#: for them (its time is the messages' stamps)
ROS_NODE_PARAMETERS = ("use_sim_time", "start_type_description_service", "qos_overrides")


def _node_key_pattern(key: str) -> re.Pattern[str]:
    """Return the regular expression of a parameter file's node key, as rcl matches it.

    A key without a leading ``/`` is taken from the root; ``/**`` stands for
    any number of namespace tokens (none included) and the node, ``*`` for one
    token or a part of one (ROS 2's parameter file wildcards).
    """
    tokens = ("/" + key.lstrip("/")).split("/")[1:]
    parts = []
    for k, token in enumerate(tokens):
        if token == "**":
            parts.append("(?:/[^/]+)*" if k < len(tokens) - 1 else "(?:/[^/]+)+")
        else:
            parts.append("/" + ".*".join("[^/]*".join(re.escape(p) for p in q.split("*"))
                                         for q in [token]))
    return re.compile("".join(parts))


#: the prefix of rclpy's QoS override parameters (``qos_overrides./topic.publisher.depth``)
QOS_OVERRIDES = "qos_overrides."
#: every name a parameter of the node has (the table's and rclpy's own)
KNOWN_NAMES: tuple[str, ...] = tuple(SPECS) + ROS_NODE_PARAMETERS


def section_matches(key: str, node_fqn: str, also: Iterable[str] = ()) -> bool:
    """Return whether a parameter file's section ``key`` is for the node ``node_fqn``.

    As rcl matches it (:func:`_node_key_pattern`), or ``key`` is one of ``also``.
    """
    return key in also or bool(_node_key_pattern(key).fullmatch(node_fqn))


@dataclass(frozen=True)
class Unmatched:
    """A params file's section or a parameter name that no parameter of the node takes.

    ``kind``: ``"section"``, a section for another node (``hint``: the key of
    this node's section), or ``"parameter"``, a name no parameter has
    (``hint``: the nearest parameter's name, empty if none is near);
    ``section``: the section a parameter is in (empty: an override).
    ``str()`` is one line.
    """

    kind: str
    name: str
    hint: str
    section: str = ""

    def __str__(self) -> str:
        if self.kind == "section":
            return (f"section {self.name!r} is for another node: this node's section is "
                    f"{self.hint!r} or a wildcard such as '/**'")
        where = f" in section {self.section!r}" if self.section else ""
        near = f"; did you mean {self.hint!r}?" if self.hint else ""
        return f"unknown parameter {self.name!r}{where}{near}"


def _names(params: Mapping[Any, Any], prefix: str = "") -> Iterator[str]:
    """Yield a section's parameter names, nested maps as rcl flattens them (``a.b``)."""
    for key, value in params.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            yield from _names(value, name + ".")
        else:
            yield name


def _known(name: str) -> bool:
    return name in SPECS or name in ROS_NODE_PARAMETERS or name.startswith(QOS_OVERRIDES)


def _near_node_name(key: str, node_name: str) -> bool:
    """Return whether a section key names a node close to ``node_name`` (a typo of it).

    ``fastsim_node`` or ``fastsim_lifecycle_node`` (the executable's name),
    ``fastsimm``; not ``node_name`` itself (a section for a node of that name
    in another namespace, as a file for several rigs has) nor a wildcard.
    """
    last = key.rstrip("/").rsplit("/", 1)[-1]
    if not last or "*" in last or last == node_name:
        return False
    return (last.startswith(node_name)
            or bool(difflib.get_close_matches(last, [node_name], n=1, cutoff=0.8)))


def unmatched(node_fqn: str, content: Any = None, overrides: Iterable[str] = (), *,
              also: Sequence[str] = ()) -> list[Unmatched]:
    """Return what of a params file and of overrides the node ``node_fqn`` does not take.

    ``content``: a parsed ROS 2 parameter file (``<node>: ros__parameters:
    {...}``) or None; ``overrides``: parameter names given otherwise (``-p``;
    a dict's keys); ``also``: section keys taken besides those rcl matches
    with ``node_fqn`` (:func:`section_matches`).  Found, in the file's order:

    - a section for no node of this name, when no section is the node's (the
      file is another node's) or when its key names a node near the node's
      name (``fastsim_node`` for ``fastsim``); a section of a node with
      another name beside the node's own (a file several nodes share) is
      that node's business, not a finding;
    - a parameter name, in a section of the node or among ``overrides``,
      that no parameter has (nor rclpy's own, :data:`ROS_NODE_PARAMETERS`,
      ``qos_overrides.*``), with the nearest parameter's name: each name
      once, where it is first found (the file before the overrides).

    The replay refuses a file with findings; the node warns and starts
    (rclpy ignores a value no parameter is declared for).
    """
    node_name = node_fqn.rsplit("/", 1)[-1]
    namespace = node_fqn[:-len(node_name)].rstrip("/")
    hint = f"{namespace}/{node_name}" if namespace else node_name
    found: list[Unmatched] = []
    named: set[str] = set()

    def unknown(names: Iterable[str], section: str) -> None:
        for name in names:
            if name in named or _known(name):
                continue
            named.add(name)
            near = difflib.get_close_matches(name, KNOWN_NAMES, n=1, cutoff=0.6)
            found.append(Unmatched("parameter", name, near[0] if near else "", section))

    sections = ({k: v for k, v in content.items() if isinstance(k, str)}
                if isinstance(content, Mapping) else {})
    mine = {k for k in sections if section_matches(k, node_fqn, also)}
    for key, section in sections.items():
        if key in mine:
            params = section.get("ros__parameters") if isinstance(section, Mapping) else None
            if isinstance(params, Mapping):
                unknown(_names(params), key)
        elif not mine or _near_node_name(key, node_name):
            found.append(Unmatched("section", key, hint))
    unknown(overrides, "")
    return found


def ros_params_files(argv: Sequence[str]) -> list[str]:
    """Return the ``--params-file`` paths among the ROS arguments of ``argv``, in order.

    ROS arguments are those after ``--ros-args`` up to ``--`` (there may be
    several such blocks); the flags that take a value skip it, so that a
    value is never read as a flag.
    """
    with_value = {"-p", "--param", "-r", "--remap", "--params-file", "--log-level",
                  "--log-config-file", "--log-file-name", "-e", "--enclave"}
    files: list[str] = []
    inside = False
    k = 0
    while k < len(argv):
        arg = argv[k]
        if arg == "--ros-args":
            inside = True
        elif arg == "--":
            inside = False
        elif inside and arg in with_value and k + 1 < len(argv):
            if arg == "--params-file":
                files.append(argv[k + 1])
            k += 1
        k += 1
    return files


def load_params_file(path: Path, node_name: str = "fastsim",
                     namespace: str = "/") -> dict[str, Any]:
    """Read a ROS 2 parameter file (``<node>: ros__parameters: ...``) and check it.

    The sections taken are those whose key names the node as ROS matches
    it, ``namespace/node_name`` (``/rig1/fastsim``, ``/**``, ``/**/fastsim``,
    ``/*/fastsim``), and ``fastsim`` or ``/fastsim`` in any namespace (a
    rig's file written for the node at the root replays under its
    namespace as well); sections with a wildcard first, then the node's own,
    each in the file's order (a later one wins).  rclpy's own parameters
    (:data:`ROS_NODE_PARAMETERS`, e.g. ``use_sim_time``) are accepted and
    not used.  What :func:`unmatched` finds (a section for another node's
    name, a parameter name no parameter has) is refused, as is a bad value:
    raises ParameterError, one line naming the file.
    """
    try:
        text = Path(path).read_text(encoding="utf-8")
        data = yaml.safe_load(text)
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as e:
        raise ParameterError(f"{path}: cannot read parameters: {_yaml_problem(e)}") from None
    if not isinstance(data, dict):
        raise ParameterError(f"{path}: not a ROS 2 parameter file")
    fqn = f"{namespace.rstrip('/')}/{node_name}"
    own = (node_name, "/" + node_name)
    keys = [k for k in data if isinstance(k, str) and section_matches(k, fqn, own)]
    keys.sort(key=lambda k: "*" not in k)   # stable: the file's order within each kind
    found = unmatched(fqn, data, also=own)
    if not keys:
        why = ("; ".join(str(f) for f in found) if found
               else f"({node_name!r}, {fqn!r} or a wildcard such as '/**')")
        raise ParameterError(f"{path}: no section for node {fqn!r}: {why}")
    values: dict[str, Any] = {}
    for key in keys:
        section = data[key]
        params = section.get("ros__parameters") if isinstance(section, dict) else None
        if not isinstance(params, dict):
            raise ParameterError(f"{path}: section {key!r} has no ros__parameters")
        values.update(params)
    if found:
        raise ParameterError(f"{path}: " + "; ".join(str(f) for f in found))
    for name in ROS_NODE_PARAMETERS:
        values.pop(name, None)
    try:
        return checked(values)
    except ParameterError as e:
        raise ParameterError(f"{path}: {e}") from None
