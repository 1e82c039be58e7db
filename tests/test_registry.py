"""The engine registry: one name per model variant, one run() for every engine, and nothing around it."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import ipir_mujoco
from ipir_mujoco import analytic, registry
from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.engine import simulate_mujoco

SHORT = 0.05  # s: long enough to cross the first dead centre's mode switch at the paper's torque


@pytest.mark.parametrize("name", registry.NAMES)
def test_every_variant_runs_as_its_name_says(name):
    v = registry.variant(name)
    run = registry.run(name, RobotParams(), SHORT, dt_out=1e-3)
    assert (run.engine, run.geometry, run.clutch) == (v.engine, v.geometry, v.rule)
    if v.is_mujoco:
        assert run.settings["mujoco_clutch"] == v.clutch
    assert run.t_end == pytest.approx(SHORT)


def test_a_variant_runs_bit_for_bit_as_its_engine_called_directly():
    """The registry adds no arithmetic: its runs are the engines' own."""
    params = RobotParams(drive="motor")
    pairs = ((registry.run("analytic-approx", params, 0.3), analytic.simulate(params, "approx", "kinematic", 0.3)),
             (registry.run("mujoco-lock-unilateral", params, 0.3, dt_out=1e-3),
              simulate_mujoco(params, "unilateral", "lock", 0.3, dt_out=1e-3)))
    for ours, theirs in pairs:
        assert ours.series.keys() == theirs.series.keys()
        assert all(np.array_equal(ours.series[c], theirs.series[c]) for c in ours.series)


def test_aliases_name_the_same_variants_and_unknown_names_are_one_line():
    assert registry.variant("analytic-exact-unilateral") is registry.variant("analytic-unilateral")
    assert registry.variant("mujoco-lock-kinematic").name == "mujoco-lock"
    for alias, name in registry.ALIASES.items():
        assert registry.variant(alias) is registry.VARIANTS[name]
    with pytest.raises(ParameterError, match=r"^variant 'mujoco-slides' is unknown \(a model in an engine, "
                                             r"ENGINE-MODEL\[-RULE\]\); allowed: analytic-approx, "):
        registry.variant("mujoco-slides")


@pytest.mark.parametrize("flags,name", [
    (("analytic", None, "kinematic", None), "analytic-approx"),
    (("analytic", "exact", "kinematic", None), "analytic-exact"),
    (("analytic", "approx", "unilateral", None), "analytic-approx-unilateral"),
    (("analytic", "exact", "unilateral", None), "analytic-unilateral"),
    (("mujoco", None, "kinematic", None), "mujoco-lock"),
    (("mujoco", "exact", "unilateral", None), "mujoco-ratchet"),
    (("mujoco", None, "unilateral", "lock"), "mujoco-lock-unilateral"),
])
def test_the_command_lines_flags_name_one_variant_each(flags, name):
    assert registry.from_flags(*flags).name == name


@pytest.mark.parametrize("flags,fragment", [
    (("mujoco", "approx", "kinematic", None), "--geometry approx with --engine mujoco"),
    (("mujoco", None, "kinematic", "ratchet"), "--clutch kinematic with the ratchet"),
    (("analytic", None, "kinematic", "lock"), "--mujoco-clutch lock applies only to --engine mujoco"),
])
def test_flags_that_name_no_variant_are_refused(flags, fragment):
    with pytest.raises(ParameterError, match=fragment):
        registry.from_flags(*flags)


@pytest.mark.parametrize("name,option,value", [
    ("mujoco-ratchet", "max_switches", 10), ("mujoco-ratchet", "rtol", 1e-8),
    ("analytic-approx", "timestep", 1e-4), ("analytic-unilateral", "accuracy", "warn"),
])
def test_an_option_the_engine_does_not_take_is_refused_by_name(name, option, value):
    with pytest.raises(ParameterError, match=f"^{option} .* applies only to the "):
        registry.run(name, RobotParams(), SHORT, **{option: value})


def test_every_step_samples_mujoco_at_the_timestep_it_chooses():
    params = RobotParams()
    step = registry.timestep("mujoco-ratchet", params, SHORT, 1e-3)
    run = registry.run("mujoco-ratchet", params, SHORT, dt_out=1e-3, every_step=True)
    assert run.settings["timestep"] == step and run.settings["dt_out"] == step
    assert np.allclose(np.diff(run.series["t"]), step)
    assert registry.timestep("analytic-unilateral", params, SHORT, 1e-3) is None


def test_only_the_ratchet_runs_batched():
    assert [n for n in registry.NAMES if registry.batched(n)] == ["mujoco-ratchet"]
    with pytest.raises(ParameterError, match="has no batched runs"):
        registry.run_batch("mujoco-lock", [RobotParams()], SHORT, 1e-3)


# what runs an engine: the engines' own entry points
ENGINE_CALLS = {"simulate_mujoco", "simulate", "simulate_unilateral", "simulate_kinematic", "simulate_compliant",
                "run_ratchet_batch"}
# modules outside the registry that may step an engine themselves: the interactive viewer steps MuJoCo's own loop
# between frames, which a finished run does not give
STEPS_ITS_OWN = {"cli/view.py"}


def test_studies_cli_and_report_reach_the_engines_only_through_the_registry():
    package = Path(ipir_mujoco.__file__).resolve().parent
    found = {}
    for path in sorted(package.rglob("*.py")):
        relative = path.relative_to(package).as_posix()
        if relative.startswith(("engine/", "analytic/")) or relative == "registry.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call):
                called = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
                if called in ENGINE_CALLS and not (called == "simulate" and isinstance(node.func, ast.Name)):
                    found.setdefault(relative, []).append(called)
            if isinstance(node, ast.ImportFrom) and node.module and node.module.endswith("engine.stepper"):
                found.setdefault(relative, []).append("engine.stepper")
    assert set(found) <= STEPS_ITS_OWN, found


def test_the_public_surface_is_importable_from_the_package_and_documented_in_sections(tmp_path):
    """``from ipir_mujoco import run, RobotParams, RunResult, ParameterError, SimulationError, VARIANTS``: the
    names a script needs, listed in ``__all__``, each with numpydoc sections; importing them loads no engine."""
    import inspect
    import subprocess
    import sys

    from ipir_mujoco import ParameterError as PE, RobotParams as RP, RunResult, SimulationError, VARIANTS, run
    from ipir_mujoco.engine.kinds import ModelKind

    assert run is registry.run and VARIANTS is registry.VARIANTS and RP is RobotParams and PE is ParameterError
    assert set(ipir_mujoco.__all__) >= {"run", "RobotParams", "RunResult", "ParameterError", "SimulationError",
                                        "VARIANTS"}
    sections = {run: ("Parameters", "Returns", "Raises"), RP: ("Parameters", "Raises"),
                RunResult: ("Parameters", "Attributes"), PE: ("Parameters",), SimulationError: ("Parameters",),
                ModelKind.check: ("Parameters", "Returns", "Raises"), ModelKind: ("Attributes",)}
    for thing, wanted in sections.items():
        doc = inspect.cleandoc(thing.__doc__)
        for section in wanted:
            assert f"\n{section}\n{'-' * len(section)}\n" in doc, (thing, section)
    assert all(f"\n    {f} : " in RP.__doc__ for f in ("m1", "mu_wall", "speed_ki"))  # every field, from its metadata
    # of the engine only the model kinds' declarations (the registry reads their variants): engine/kinds/base.py and
    # each kind's __init__.py, whose methods import the rest when called
    code = ("import sys, ipir_mujoco; from ipir_mujoco.engine.kinds import KINDS; "
            "declared = {'ipir_mujoco.engine', 'ipir_mujoco.engine.kinds', 'ipir_mujoco.engine.kinds.base'} | "
            "{type(k).__module__ for k in KINDS.values()}; "
            "print(sorted(m for m in sys.modules if m in ('mujoco', 'scipy') or m.startswith('ipir_mujoco.engine') "
            "and m not in declared))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                            cwd=tmp_path).stdout
    assert loaded.strip() == "[]"
