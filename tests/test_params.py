"""The parameter set: defaults, validation, TOML and overrides."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from ipir_mujoco.analytic import ParameterError, RobotParams, load_params
from ipir_mujoco.analytic.params import PARAMETER_NAMES, parse_overrides, read_toml

CONTRACT_NAMES = "m1 m2 r L J_A F_r1 F_r2 M rod_mass rod_inertia phi0 omega0".split()


def test_contract_names_and_the_papers_defaults():
    assert list(PARAMETER_NAMES) == CONTRACT_NAMES
    p = RobotParams()
    assert (p.m1, p.m2, p.r, p.L, p.J_A, p.F_r1, p.F_r2, p.M) == (1.0, 1.0, 0.05, 0.2, 0.001, 1.0, 1.0, 0.25)
    assert (p.phi0, p.omega0) == (0.0, 0.0)
    assert p.rod_mass > 0
    assert p.rod_inertia_value == pytest.approx(p.rod_mass * p.L**2 / 12)


def test_default_rod_inertia_follows_the_rod_and_an_explicit_one_is_kept():
    assert RobotParams().replace(L=0.3).rod_inertia_value == pytest.approx(0.01 * 0.09 / 12)
    assert RobotParams(rod_inertia=2e-4).replace(L=0.3).rod_inertia_value == 2e-4
    assert RobotParams().as_dict()["rod_inertia"] == RobotParams().rod_inertia_value


@pytest.mark.parametrize("name,value,fragment", [
    ("m1", -1.0, "m1=-1.0 is out of range; allowed: m1 > 0"),
    ("m2", 0.0, "m2 > 0"),
    ("J_A", 0.0, "J_A > 0"),
    ("r", -0.05, "r > 0"),
    ("F_r1", -0.1, "F_r1 >= 0"),
    ("rod_mass", -0.01, "rod_mass >= 0"),
    ("rod_inertia", -1e-6, "rod_inertia >= 0"),
    ("M", math.nan, "M=nan is not finite"),
    ("L", math.inf, "L=inf is not finite"),
    ("L", 0.04, "L=0.04 m with r=0.05 m"),
    ("L", 0.05, "allowed: L > r"),
])
def test_out_of_range_values_name_the_value_and_the_allowed_range(name, value, fragment):
    with pytest.raises(ParameterError, match="^.*" + fragment.replace("(", r"\(").replace(")", r"\)")):
        RobotParams(**{name: value})


def test_parameter_error_is_a_value_error():
    assert issubclass(ParameterError, ValueError)


@given(st.sampled_from(["m1", "m2", "r", "J_A"]), st.floats(max_value=0.0, allow_nan=False))
def test_no_non_positive_mass_length_or_inertia_is_accepted(name, value):
    with pytest.raises(ParameterError, match=name):
        RobotParams(**{name: value})


def test_overrides_parse_and_reject_unknown_or_malformed_items():
    assert parse_overrides(["L=0.3", " m2 = 2"]) == {"L": 0.3, "m2": 2.0}
    with pytest.raises(ParameterError, match="unknown parameter 'foo'; known parameters: m1 m2"):
        parse_overrides(["foo=1"])
    with pytest.raises(ParameterError, match="expected NAME=VALUE"):
        parse_overrides(["L0.3"])
    with pytest.raises(ParameterError, match="L='abc' is not a number"):
        parse_overrides(["L=abc"])


def test_toml_top_level_and_params_table_and_override_precedence(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text("m1 = 2\n[params]\nL = 0.3\nM = 0.5\n")
    assert read_toml(path) == {"m1": 2.0, "L": 0.3, "M": 0.5}
    p = load_params(path, ["M=0.4"])
    assert (p.m1, p.L, p.M, p.m2) == (2.0, 0.3, 0.4, 1.0)


@pytest.mark.parametrize("text,fragment", [
    ("L = [0.3\n", "is not valid TOML"),
    ("Length = 0.3\n", "unknown parameter 'Length'"),
    ("L = 'long'\n", "L='long' is not a number"),
    ("params = 3\n", "'params' must be a table"),
])
def test_bad_toml_files_are_refused_with_the_file_named(tmp_path, text, fragment):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=fragment) as info:
        load_params(path)
    assert "bad.toml" in str(info.value)


def test_missing_config_file_is_bad_input(tmp_path):
    with pytest.raises(ParameterError, match="does not exist"):
        load_params(tmp_path / "nope.toml")
