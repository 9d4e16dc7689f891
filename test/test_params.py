"""The parameter table, the parameter files in config/ and bags/, and their checks."""

import pytest

from fastsim_ros.ros import params
from fastsim_ros.ros.params import SPECS, ParameterError, load_params_file
from ros_harness import PACKAGE_ROOT

CONFIG = PACKAGE_ROOT / "config"
# the documented defaults; method: the calibrated MAE, the default since the validation
# report (docs/validation_wider.md) shows it better than the paper's MAE on every area
DOCUMENTED_DEFAULTS = {
    "contacts": ("left", "right"), "wheelset_frame": "wheelset", "shear_modulus": 8.0e10,
    "poisson_ratio": 0.28, "friction_coefficient": 0.3, "method": "mae_calibrated",
    "traction_bound": "given", "min_rolling_speed": 0.1, "max_kinematics_age": 0.05,
    "publish_traction": False, "rail_twist_required": False, "friction_law": "constant",
    "friction_limit_ratio": 1.0, "friction_decay": 0.0,
}


def test_defaults_are_interface_md():
    d = params.defaults()
    for name, value in DOCUMENTED_DEFAULTS.items():
        assert d[name] == value, name
    assert d["max_patch_cells"] >= 30 * 30


def test_config_fastsim_yaml_lists_every_parameter_at_its_default():
    values = load_params_file(CONFIG / "fastsim.yaml")
    assert values == params.defaults()
    text = (CONFIG / "fastsim.yaml").read_text()
    for spec in params.PARAMETERS:
        assert f"    {spec.name}:" in text, spec.name


def test_roller_rig_yaml():
    values = load_params_file(CONFIG / "roller_rig.yaml")
    assert values["contacts"] == ("wheel",)
    assert values["rail_twist_required"] is True
    assert values["method"] == "mae_calibrated"


def test_methods_and_the_default():
    assert params.METHODS == ("mae", "mae_calibrated", "fastsim_ellipse", "polach")
    spec = params.SPECS["method"]
    assert spec.default == "mae_calibrated" and spec.dynamic
    for method in params.METHODS:
        assert spec.check(method) == method
        assert method in spec.description  # the descriptor names every method
    assert "docs/validation_wider.md" in spec.description
    assert spec.allowed() == "one of mae, mae_calibrated, fastsim_ellipse, polach"
    # the config lists them with the default
    text = (CONFIG / "fastsim.yaml").read_text()
    assert "one of mae, mae_calibrated, fastsim_ellipse, polach" in text
    assert '    method: "mae_calibrated"' in text


@pytest.mark.parametrize("path", sorted((PACKAGE_ROOT / "bags").glob("*.params.yaml")))
def test_bag_parameter_files_load(path):
    # the bags' golden outputs are their method's: each file names it explicitly (the
    # paper's MAE, but mbench_a22: the default method of the benchmark's report, and
    # adhesion_rig: the friction estimator's model, validated in docs/validation_estimation.md,
    # and contaminated_rig: the modified FastSim its measured wrench was made with)
    load_params_file(path)
    assert '    method: "mae"' in path.read_text() or (
        path.name in ("mbench_a22.params.yaml", "adhesion_rig.params.yaml",
                      "contaminated_rig.params.yaml")
        and '    method: "mae_calibrated"' in path.read_text())


@pytest.mark.parametrize("name, value", [
    ("friction_coefficient", 0.0), ("friction_coefficient", float("nan")),
    ("poisson_ratio", 0.51), ("method", "exact"), ("method", "calibrated"),
    ("method", "MAE_calibrated"), ("traction_bound", "hertz"),
    ("contacts", []), ("contacts", ["left", "left"]), ("contacts", ["1st"]),
    ("max_patch_cells", 2), ("max_patch_cells", 1.5), ("publish_traction", "yes"),
    ("friction_limit_ratio", 0.0), ("friction_decay", -1.0), ("shear_modulus", "8e10"),
    ("friction_limit_ratio", 1.01), ("friction_limit_ratio", float("nan")),
    ("friction_decay", float("inf")), ("friction_law", "polach"), ("friction_law", ""),
])
def test_bad_values_name_the_parameter_and_the_range(name, value):
    spec = params.SPECS[name]
    with pytest.raises(ParameterError, match=f"parameter '{name}'.*must be") as info:
        spec.check(value)
    assert spec.allowed() in str(info.value)


def test_an_integer_is_a_double():
    assert params.SPECS["friction_coefficient"].check(1) == 1.0


@pytest.mark.parametrize("text, match", [
    ("fastsim:\n  ros__parameters:\n    friction_coefficient: -1.0\n", "friction_coefficient"),
    ("fastsim:\n  ros__parameters:\n    no_such: 1\n", "unknown parameter 'no_such'"),
    ("other_node:\n  ros__parameters:\n    method: mae\n", "no section for node"),
    ("fastsim: [1, 2\n", "cannot read"),
    ("fastsim:\n  ros__parameters:\n    contacts: [\"left\", \"right\"\n    method: mae\n",
     r"cannot read parameters: line 4, column 5: expected ',' or '\]'"),
    ("fastsim:\n\tros__parameters: 1\n", "line 2, column 1: found character"),
    ("- just a list\n", "not a ROS 2 parameter file"),
])
def test_bad_parameter_files(tmp_path, text, match):
    path = tmp_path / "p.yaml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=match) as info:
        load_params_file(path)
    assert str(path) in str(info.value)
    assert "\n" not in str(info.value)  # one line on stderr


def test_wildcard_section_and_node_section(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("/**:\n  ros__parameters:\n    friction_coefficient: 0.2\n"
                    "    method: fastsim_ellipse\n"
                    "fastsim:\n  ros__parameters:\n    friction_coefficient: 0.4\n")
    values = load_params_file(path)
    assert values["friction_coefficient"] == 0.4 and values["method"] == "fastsim_ellipse"


@pytest.mark.parametrize("key, namespace, taken", [
    ("/rig1/fastsim", "/rig1", True), ("/**/fastsim", "/rig1", True),
    ("/**/fastsim", "/", True), ("/*/fastsim", "/rig1", True), ("/rig1/*", "/rig1", True),
    ("/rig1/fast*", "/rig1", True), ("fastsim", "/rig1", True), ("/fastsim", "/rig1", True),
    ("/rig2/fastsim", "/rig1", False), ("/*/fastsim", "/", False),
    ("/**/other", "/rig1", False), ("/rig1/fastsim", "/", False),
])
def test_a_section_is_taken_where_ros_would_give_it_to_the_node(
        tmp_path, key, namespace, taken):
    """Node keys as ROS matches them against the node's name in its namespace."""
    path = tmp_path / "p.yaml"
    path.write_text(f"{key}:\n  ros__parameters:\n    friction_coefficient: 0.4\n")
    if taken:
        assert load_params_file(path, namespace=namespace)["friction_coefficient"] == 0.4
    else:
        with pytest.raises(ParameterError, match="no section for node"):
            load_params_file(path, namespace=namespace)


def test_the_nodes_own_section_wins_over_wildcards_and_ros_parameters_pass(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text("/rig1/fastsim:\n  ros__parameters:\n    friction_coefficient: 0.4\n"
                    "/**:\n  ros__parameters:\n    use_sim_time: true\n"
                    "    friction_coefficient: 0.2\n    method: mae\n")
    values = load_params_file(path, namespace="/rig1")
    assert values["friction_coefficient"] == 0.4 and values["method"] == "mae"
    assert "use_sim_time" not in values  # rclpy's own: accepted, of no use to the replay


def test_friction_laws_and_their_parameters_are_dynamic():
    assert params.FRICTION_LAWS == ("constant", "exponential")
    for name in ("friction_law", "friction_limit_ratio", "friction_decay"):
        assert params.SPECS[name].dynamic
    assert params.SPECS["friction_law"].check("exponential") == "exponential"


@pytest.mark.parametrize("given, taken", [(True, "on"), (False, "off"), ("on", "on"),
                                          ("off", "off")])
def test_a_switch_takes_yamls_booleans_for_on_and_off(given, taken):
    # `-p friction_estimation:=on` and a params file's bare `on` arrive as YAML's true
    assert SPECS["friction_estimation"].check(given) == taken


def test_a_switch_refuses_other_words():
    with pytest.raises(ParameterError, match="friction_estimation"):
        SPECS["friction_estimation"].check("yes please")


def _file(*sections: str) -> dict:
    """Return a parsed params file of sections ``key`` or ``key=name,name`` (values 1)."""
    out = {}
    for section in sections:
        key, _, names = section.partition("=")
        out[key] = {"ros__parameters": {n: 1 for n in names.split(",") if n}}
    return out


@pytest.mark.parametrize("fqn, content, overrides, found", [
    # a typo: the nearest parameter named
    ("/fastsim", None, ["friction_coeficient"],
     ["unknown parameter 'friction_coeficient'; did you mean 'friction_coefficient'?"]),
    ("/fastsim", None, ["frobnicate"], ["unknown parameter 'frobnicate'"]),
    # rclpy's own parameters and the node's are known
    ("/fastsim", None, ["use_sim_time", "qos_overrides./x.publisher.depth", "method"], []),
    # the node's section under another node's name (the executable's): no section is the node's
    ("/fastsim", _file("fastsim_node=friction_coefficient"), [],
     ["section 'fastsim_node' is for another node: this node's section is 'fastsim' "
      "or a wildcard such as '/**'"]),
    # beside the node's own: a near name is a typo, another node's section is not ours
    ("/fastsim", _file("fastsim=method", "fastsim_lifecycle_node=method",
                       "robot_state_publisher=robot_description"), [],
     ["section 'fastsim_lifecycle_node' is for another node: this node's section is "
      "'fastsim' or a wildcard such as '/**'"]),
    ("/fastsim", _file("/fastsimm=method", "/**=use_sim_time"), [],
     ["section '/fastsimm' is for another node: this node's section is 'fastsim' "
      "or a wildcard such as '/**'"]),
    # wildcards match (their unknown names are found too); /* is one token
    ("/fastsim", _file("/**=friction_coeficient"), [],
     ["unknown parameter 'friction_coeficient' in section '/**'; did you mean "
      "'friction_coefficient'?"]),
    ("/rig1/fastsim", _file("/rig1/**=method", "/*/fastsim=methd"), [],
     ["unknown parameter 'methd' in section '/*/fastsim'; did you mean 'method'?"]),
    ("/fastsim", _file("/*/fastsim=method"), [],
     ["section '/*/fastsim' is for another node: this node's section is 'fastsim' "
      "or a wildcard such as '/**'"]),
    # namespaced: rcl gives a key without a namespace to the root's node only
    ("/rig1/fastsim", _file("fastsim=method"), [],
     ["section 'fastsim' is for another node: this node's section is '/rig1/fastsim' "
      "or a wildcard such as '/**'"]),
    ("/rig1/fastsim", _file("/rig1/fastsim=method", "/rig2/fastsim=method"), [], []),
    ("/rig1/fastsim", _file("rig1/fastsim=method"), [], []),
    # each name once, where first found: the file before the overrides
    ("/fastsim", _file("fastsim=mu,method"), ["mu", "friction_coeficient"],
     ["unknown parameter 'mu' in section 'fastsim'",
      "unknown parameter 'friction_coeficient'; did you mean 'friction_coefficient'?"]),
    # nested maps are dotted names, as rcl flattens them
    ("/fastsim", {"fastsim": {"ros__parameters": {"friction": {"coefficient": 0.3}}}}, [],
     ["unknown parameter 'friction.coefficient' in section 'fastsim'; did you mean "
      "'friction_coefficient'?"]),
])
def test_unmatched_finds_other_nodes_sections_and_unknown_names(fqn, content, overrides, found):
    assert [str(f) for f in params.unmatched(fqn, content, overrides)] == found


def test_unmatched_takes_the_replays_own_keys_too():
    content = _file("fastsim=method")
    assert params.unmatched("/rig1/fastsim", content, also=("fastsim", "/fastsim")) == []


@pytest.mark.parametrize("argv, files", [
    (["node", "--ros-args", "--params-file", "a.yaml", "-p", "x:=1"], ["a.yaml"]),
    (["node", "--params-file", "no.yaml", "--ros-args", "-r", "__ns:=/r",
      "--params-file", "a.yaml", "--", "--params-file", "no.yaml",
      "--ros-args", "--params-file", "b.yaml"], ["a.yaml", "b.yaml"]),
    # a flag's value is no flag
    (["node", "--ros-args", "-p", "--params-file", "-p", "y:=2"], []),
    (["node"], []),
])
def test_ros_params_files(argv, files):
    assert params.ros_params_files(argv) == files


@pytest.mark.parametrize("text, line", [
    ("fastsim_node:\n  ros__parameters:\n    friction_coefficient: 0.4\n",
     "no section for node '/fastsim': section 'fastsim_node' is for another node: this "
     "node's section is 'fastsim' or a wildcard such as '/**'"),
    ("fastsim:\n  ros__parameters:\n    friction_coeficient: 0.4\n",
     "unknown parameter 'friction_coeficient' in section 'fastsim'; did you mean "
     "'friction_coefficient'?"),
    ("fastsim:\n  ros__parameters:\n    method: mae\nfastsim_node:\n  ros__parameters:\n"
     "    friction_coefficient: 0.4\n",
     "section 'fastsim_node' is for another node: this node's section is 'fastsim' or a "
     "wildcard such as '/**'"),
])
def test_the_replay_refuses_what_the_node_warns_of_in_one_line_exit_2(tmp_path, capsys,
                                                                      text, line):
    from fastsim_ros.replay import cli

    path = tmp_path / "p.yaml"
    path.write_text(text)
    with pytest.raises(ParameterError) as info:
        load_params_file(path)
    assert str(info.value) == f"{path}: {line}"
    assert cli.main([str(tmp_path / "in.mcap"), "-o", str(tmp_path / "out"),
                     "--params", str(path)]) == 2
    err = capsys.readouterr().err
    assert err == f"fastsim_replay: {path}: {line}\n"
    assert not (tmp_path / "out").exists()


def test_slope_reduction_parameters():
    """No reduction by default; k0 < 1 is one; transient rolling refuses it."""
    assert params.slope_reduction_of(params.defaults()) is None
    values = params.checked({"slope_reduction_k0": 0.54, "slope_reduction_alpha_inf": 0.02,
                             "slope_reduction_beta": 0.62})
    r = params.slope_reduction_of(values)
    assert (r.k0, r.alpha_inf, r.beta) == (0.54, 0.02, 0.62)
    # alpha_inf < 1 without beta is no reduction (k = k0 = 1 throughout)
    assert params.slope_reduction_of(params.checked({"slope_reduction_alpha_inf": 0.3})) is None
    for name, bad in (("slope_reduction_k0", 0.0), ("slope_reduction_k0", 1.2),
                      ("slope_reduction_alpha_inf", -0.1), ("slope_reduction_beta", -1.0)):
        with pytest.raises(ParameterError, match=name):
            params.checked({name: bad})
    with pytest.raises(ParameterError, match="steady rolling only"):
        params.checked({"slope_reduction_k0": 0.5, "rolling": "transient"})
    for name in ("slope_reduction_k0", "slope_reduction_alpha_inf", "slope_reduction_beta"):
        assert SPECS[name].dynamic


def test_polach_parameters():
    """Polach's kS <= kA; the method refuses tractions, transient rolling, a slope reduction."""
    assert params.checked({"method": "polach", "polach_ka": 0.3, "polach_ks": 0.1})
    with pytest.raises(ParameterError, match="kS <= kA"):
        params.checked({"method": "polach", "polach_ka": 0.1, "polach_ks": 0.3})
    for extra in ({"publish_traction": True}, {"rolling": "transient"},
                  {"slope_reduction_k0": 0.5}):
        with pytest.raises(ParameterError, match="method polach refuses"):
            params.checked({"method": "polach", **extra})
