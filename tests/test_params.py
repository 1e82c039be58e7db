"""The parameter set: defaults, validation, TOML and overrides."""

from __future__ import annotations

import math
import re
from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ipir_mujoco.analytic import ParameterError, RobotParams, load_params
from ipir_mujoco.core.params import PARAMETER_NAMES, describe_parameters, parse_overrides, read_toml

CONTRACT_NAMES = ("m1 m2 r L J_A F_r1 F_r2 M rod_mass rod_inertia phi0 omega0 drive M_stall omega_noload "
                  "clutch_stiffness clutch_damping clutch_backlash incline g mu_wall F_n1 F_n2 pipe_diameter wheel_radius "
                  "wheel_legs suspension_travel ring_spacing cornering_coefficient omega_target speed_dip feedforward control_rate speed_kp speed_ki").split()


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
    ("m1", -1.0, "m1=-1.0 is out of range; allowed: 0 < m1 <= 10000 kg"),
    ("m2", 0.0, "0 < m2"),
    ("J_A", 0.0, "0 < J_A"),
    ("r", -0.05, "0 < r"),
    ("F_r1", -0.1, "0 <= F_r1"),
    ("rod_mass", -0.01, "0 <= rod_mass"),
    ("rod_inertia", -1e-6, "0 <= rod_inertia"),
    ("omega0", 1e300, "omega0=1e+300 is out of range; allowed: -10000 <= omega0 <= 10000 rad/s"),
    ("incline", 91.0, "-90 <= incline <= 90 deg"),
    ("drive", "wheel", "drive='wheel' is unknown; allowed: torque, motor, servo"),
    ("clutch_stiffness", -1.0, "0 < clutch_stiffness <= 1e+12 N/m, or 'rigid'"),
    ("clutch_backlash", 0.03, "clutch_backlash <= r / 2 = 0.025 m"),
    ("M", math.nan, "M=nan is not finite"),
    ("L", math.inf, "L=inf is not finite"),
    ("L", 0.04, "L=0.04 m with r=0.05 m"),
    ("L", 0.05, "allowed: L > r"),
])
def test_out_of_range_values_name_the_value_and_the_allowed_range(name, value, fragment):
    with pytest.raises(ParameterError, match="^.*" + re.escape(fragment)):
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


@pytest.mark.parametrize("value", [np.int64(2), np.float32(2.0), np.array(2.0), Fraction(2, 1), Decimal("2")])
def test_any_real_number_type_is_a_number(value):
    p = RobotParams(m2=value)
    assert p.m2 == 2.0 and type(p.m2) is float


@pytest.mark.parametrize("value", [True, 1 + 0j, "2", [2.0], np.array([2.0])])
def test_things_that_are_not_real_numbers_are_refused_by_name(value):
    with pytest.raises(ParameterError, match="m2=.* is not a number; allowed: 0 < m2"):
        RobotParams(m2=value)


def test_an_unknown_keyword_is_a_parameter_error_naming_it():
    with pytest.raises(ParameterError, match="unknown parameter 'mass'"):
        RobotParams(mass=1)
    with pytest.raises(ParameterError, match="unknown parameter 'mass'"):
        RobotParams().replace(mass=1)


def test_optional_fields_take_their_word_on_the_command_line_and_in_toml(tmp_path):
    assert parse_overrides(["clutch_stiffness=rigid", "rod_inertia=uniform"]) == \
        {"clutch_stiffness": None, "rod_inertia": None}
    path = tmp_path / "c.toml"
    path.write_text('clutch_stiffness = "rigid"\ndrive = "motor"\n')
    p = load_params(path)
    assert p.rigid_clutches and p.drive == "motor"


def test_every_parameter_is_described_with_meaning_unit_default_and_range():
    rows = describe_parameters()
    assert [r["name"] for r in rows] == list(PARAMETER_NAMES)
    for row in rows:
        assert row["meaning"] and row["units"] and row["allowed"], row
        default = getattr(RobotParams(), row["name"])
        assert row["default"] == default or (default is None and row["default"] is None)
    # the described range is the one enforced: a value just outside each finite bound is refused
    for row in rows:
        meta = RobotParams.__dataclass_fields__[row["name"]].metadata
        if meta["kind"] != "number" or row["name"] in ("clutch_backlash", "L", "r"):
            continue
        with pytest.raises(ParameterError, match=row["name"]):
            RobotParams(**{row["name"]: meta["high"] * 1.01 + 1e-9})


def test_config_file_that_is_not_utf8_or_is_a_folder_is_refused_in_one_line(tmp_path):
    path = tmp_path / "latin.toml"
    path.write_bytes("L = 0.3 # longueur \xe9\n".encode("latin-1"))
    with pytest.raises(ParameterError, match="is not UTF-8 text"):
        load_params(path)
    with pytest.raises(ParameterError, match="is a folder"):
        load_params(tmp_path)


# (parameter, a value other than its default, a drive that does not use it, the drives the message names)
IDLE = [("M_stall", 0.3, "torque", ("motor", "servo")), ("omega_noload", 40.0, "torque", ("motor", "servo")),
        ("M", 0.3, "motor", ("torque",)), ("M", 0.3, "servo", ("torque",)),
        ("omega_target", 5.0, "motor", ("servo",)), ("speed_kp", 0.1, "torque", ("servo",))]


@pytest.mark.parametrize("name, value, drive, users", IDLE)
def test_a_parameter_the_drive_does_not_use_is_refused_by_every_interface(tmp_path, capsys, name, value, drive,
                                                                            users):
    """`--set M_stall=0.3` under the paper's constant torque once ran the constant torque and said nothing: every
    interface (the command line's --set, a TOML file, the Python run, a sweep varying it) refuses it in one line
    naming the drives that use it, before any work; with such a drive it runs."""
    from cli_run import run_cli

    from ipir_mujoco import run
    from ipir_mujoco.studies.sweep_space import Study, parse_vary

    def said(text: str) -> bool:
        return (f"{name}" in text and " or ".join(f"drive={d}" for d in users) + " uses" in text
                and f"the drive here is '{drive}'" in text and f"--drive {users[0]}" in text)

    config = tmp_path / "p.toml"
    config.write_text(f'drive = "{drive}"\n{name} = {value}\n')
    for argv in (["--drive", drive, "--set", f"{name}={value}"], ["--config", str(config)]):
        code, out, err = run_cli(capsys, "simulate", "--t-end", "0.01", *argv)
        assert code == 2 and out == "" and err.count("\n") == 1 and said(err), err
    for variant in ("analytic-approx", "mujoco-ratchet"):
        with pytest.raises(ParameterError) as refused:
            run(variant, RobotParams(drive=drive, **{name: value}), 0.01)
        assert said(str(refused.value))
    with pytest.raises(ParameterError) as refused:
        Study((parse_vary(f"{name}={value},{2 * value}"),), RobotParams(drive=drive))
    assert said(str(refused.value)) and f"{name} (varied)" in str(refused.value)
    code, _, err = run_cli(capsys, "simulate", "--t-end", "0.01", "--drive", users[0], "--set", f"{name}={value}")
    assert code == 0, err


def test_naming_the_drive_returns_what_it_does_not_use_to_the_defaults():
    """replace(drive=...) (the studies' motor and torque cases of one design) drops every drive's parameter the
    named drive does not act through: a run would refuse it. What it uses, or what is given, stays."""
    defaults = RobotParams()
    same = RobotParams(M=0.3, M_stall=0.8).replace(drive="torque")  # the torque case of a design given both
    assert (same.M, same.M_stall) == (0.3, defaults.M_stall)
    motor = RobotParams(M=0.3).replace(drive="motor")
    assert (motor.drive, motor.M) == ("motor", defaults.M)
    torque = RobotParams(drive="servo", M_stall=0.9, omega_target=5.0).replace(drive="torque")
    assert (torque.M_stall, torque.omega_target) == (defaults.M_stall, defaults.omega_target)
    kept = RobotParams(drive="servo", M_stall=0.9, omega_target=5.0).replace(drive="motor")
    assert (kept.M_stall, kept.omega_target) == (0.9, defaults.omega_target)
    assert RobotParams(M=0.3).replace(drive="motor", M=0.4).M == 0.4  # given: kept, and refused by a run
