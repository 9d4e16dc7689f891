"""The plausibility table of wheel-rail contact: its ranges, one-line refusals and override."""

import subprocess
import sys
from pathlib import Path

import pytest

from fastsim_ros.ros import plausibility
from fastsim_ros.contact.errors import ContactError, InvalidInputError
from fastsim_ros.ros.params import SPECS
from fastsim_ros.ros.plausibility import (PLAUSIBILITY, PLAUSIBLE, ImplausibleValueError, check,
                                          check_patch, message)

ROOT = Path(__file__).resolve().parents[1]


def test_one_entry_per_quantity_with_an_si_unit_and_a_mistake():
    assert [p.name for p in PLAUSIBILITY] == list(PLAUSIBLE)
    assert set(PLAUSIBLE) == {"semi_axis", "patch_extent", "peak_pressure", "wheel_load",
                              "creepage", "spin", "friction_coefficient", "shear_modulus"}
    for p in PLAUSIBILITY:
        assert 0.0 <= p.low < p.high, p.name
        assert p.unit in ("m", "Pa", "N", "1/m", ""), p.name
        assert p.above and p.why, p.name
        # a lower bound that bounds something names its mistake too
        assert p.below or (p.magnitude and p.low == 0.0), p.name
    with pytest.raises(TypeError):
        PLAUSIBLE["spin"] = PLAUSIBLE["creepage"]  # the shared table is read-only


@pytest.mark.parametrize("name, low, high", [
    ("semi_axis", 1e-4, 5e-2), ("patch_extent", 2e-4, 0.1), ("peak_pressure", 1e5, 1e10),
    ("wheel_load", 100.0, 1e6), ("creepage", 0.0, 0.1), ("spin", 0.0, 50.0),
    ("shear_modulus", 1e9, 5e11)])
def test_the_bounds(name, low, high):
    assert (PLAUSIBLE[name].low, PLAUSIBLE[name].high) == (low, high)


def test_friction_is_the_nodes_parameter_range():
    spec = SPECS["friction_coefficient"]
    p = PLAUSIBLE["friction_coefficient"]
    assert (p.low, p.high) == (spec.low, spec.high) == (1e-3, 5.0)


def test_steel_and_the_nodes_defaults_are_plausible():
    for name, parameter in (("friction_coefficient", "friction_coefficient"),
                            ("shear_modulus", "shear_modulus")):
        check(name, SPECS[parameter].default)


# value, the words the line names: its quantity's unit and the likely mistake
REFUSED = [
    ("semi_axis", 6.0, " m ", "millimetres typed as metres"),
    ("semi_axis", 6e-6, " m ", "metres converted again as if they were millimetres"),
    ("patch_extent", 12.0, " m ", "coordinates in millimetres"),
    ("peak_pressure", 1500.0, " Pa ", "megapascals typed as pascals"),
    ("peak_pressure", 2e11, " Pa ", "pascals converted twice"),
    ("wheel_load", 10.0, " N ", "kilonewtons typed as newtons"),
    ("wheel_load", 5e6, " N ", "a vehicle's or axle's load"),
    ("creepage", 0.2, "magnitude at most 0.1", "a percentage typed"),
    ("creepage", -0.2, "magnitude at most 0.1", "a percentage typed"),
    ("spin", -200.0, " 1/m ", "a spin rate (rad/s) not divided by the rolling speed"),
    ("friction_coefficient", 30.0, "0.001 to 5", "a percentage typed"),
    ("friction_coefficient", 3e-4, "0.001 to 5", "a fraction divided by 100"),
    ("shear_modulus", 80.0, " Pa ", "gigapascals or megapascals typed as pascals"),
    ("shear_modulus", 8e13, " Pa ", "a modulus converted to pascals twice"),
]


@pytest.mark.parametrize("name, value, unit, mistake", REFUSED)
def test_a_value_outside_is_refused_in_one_line_naming_it(name, value, unit, mistake):
    with pytest.raises(ImplausibleValueError) as caught:
        check(name, value, what="--flag")
    text = str(caught.value)
    assert "\n" not in text
    assert text.startswith(f"--flag {value:g}")
    assert unit in text and f"likely {mistake}" in text
    assert text.endswith("if intended, give --allow-implausible")
    # the same value, marked intended, is accepted
    check(name, value, allow=True)


@pytest.mark.parametrize("name, value", [
    ("semi_axis", 6e-3), ("semi_axis", 1e-4), ("semi_axis", 5e-2), ("patch_extent", 0.012),
    ("peak_pressure", 1.2e9), ("wheel_load", 100.0), ("wheel_load", 1e6), ("wheel_load", 5e4),
    ("creepage", -0.1), ("creepage", 0.0), ("spin", -50.0), ("spin", 2.0),
    ("friction_coefficient", 0.3), ("shear_modulus", 8e10)])
def test_a_value_inside_is_accepted(name, value):
    check(name, value)


def test_the_error_is_the_cores_bad_input():
    # the command line's exit 2 and the node's rejection count catch it as they are
    assert issubclass(ImplausibleValueError, InvalidInputError)
    assert issubclass(ImplausibleValueError, ContactError)


def test_the_caller_names_its_override_and_the_mistake():
    text = message("wheel_load", 10.0, what="parameter 'wheel_load'",
                   override="allow_implausible:=true")
    assert text.startswith("parameter 'wheel_load' 10 N is implausible")
    assert text.endswith("if intended, give allow_implausible:=true")
    text = message("peak_pressure", 2e4, mistake="the load and the area do not belong together")
    assert text.startswith("largest contact pressure 20000 Pa") and "likely the load" in text


@pytest.mark.parametrize("extent_x, extent_y, peak, words", [
    (12.0, 8.0, 1.2e9, "p.csv: extent along x 12 m"),       # coordinates in mm
    (0.012, 0.2, 1.2e9, "p.csv: extent along y 0.2 m"),
    (0.012, 0.008, 1200.0, "p.csv: largest pressure 1200 Pa"),   # pressure in MPa
])
def test_a_patch_in_other_units_is_refused(extent_x, extent_y, peak, words):
    with pytest.raises(ImplausibleValueError, match=words):
        check_patch(extent_x, extent_y, peak, what="p.csv")
    check_patch(extent_x, extent_y, peak, what="p.csv", allow=True)


def test_a_patch_in_metres_and_pascals_is_plausible_and_a_load_leaves_its_pressure():
    check_patch(0.012, 0.008, 1.2e9)
    check_patch(0.012, 0.008, None)   # a load rescales the pressure: not checked


def test_pure_python_without_ros_or_numpy():
    code = ("import sys, fastsim_ros.ros.plausibility; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in "
            "('rclpy', 'numpy', 'scipy', 'numba')))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_the_module_exports_its_api():
    assert set(plausibility.__all__) >= {"PLAUSIBILITY", "PLAUSIBLE", "check", "check_patch",
                                         "ImplausibleValueError"}
