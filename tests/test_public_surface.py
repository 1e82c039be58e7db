"""The public Python surface: ``from ipir_mujoco import ...`` and the registry's ``__all__``. ``run`` takes its
options by name, typed, each documented; every public callable documents every parameter in a numpydoc
Parameters section (and what it returns and raises); the package is marked typed (PEP 561)."""

from __future__ import annotations

import inspect
import re
import tomllib
from pathlib import Path

import pytest

import ipir_mujoco
from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterTypeError
from ipir_mujoco.core.params import RobotParams

ROOT = Path(__file__).resolve().parent.parent


def public_callables() -> dict[str, object]:
    """{dotted name: object} of every callable the package's and the registry's ``__all__`` name."""
    found = {f"ipir_mujoco.{n}": getattr(ipir_mujoco, n) for n in ipir_mujoco.__all__}
    found |= {f"ipir_mujoco.registry.{n}": getattr(registry, n) for n in registry.__all__}
    return {name: obj for name, obj in found.items() if callable(obj)}


def sections(obj) -> dict[str, str]:
    """{heading: its text} of a numpydoc docstring."""
    doc = "\n" + inspect.cleandoc(obj.__doc__ or "") + "\n"
    parts = re.split(r"\n(\w[\w ]*)\n-+\n", doc)
    return dict(zip(parts[1::2], parts[2::2]))


def documented(obj) -> set[str]:
    """The names a Parameters section documents: each unindented line's names before ' : ' (``a, b : float``)."""
    text = sections(obj).get("Parameters", "")
    return {name.strip().lstrip("*") for line in text.splitlines() if line and not line[0].isspace()
            for name in line.split(" : ")[0].split(",")}


def parameters(obj) -> list[str]:
    """The parameters of ``obj``'s signature (a class's: its constructor's), ``self`` left out; [] for an
    exception class, whose message is its one argument (documented as such where it has a Parameters section)."""
    if isinstance(obj, type) and issubclass(obj, BaseException):
        return []
    return [p for p in inspect.signature(obj).parameters if p != "self"]


def test_every_public_parameter_is_documented():
    names = public_callables()
    missing = {name: [p for p in parameters(obj) if p not in documented(obj)] for name, obj in names.items()}
    assert {name: gaps for name, gaps in missing.items() if gaps} == {}
    counted = sum(len(parameters(obj)) for obj in {id(o): o for o in names.values()}.values())
    # the surface this holds: run, RobotParams, RunResult, the errors, Variant, variant, timestep, feedforward_table
    assert len({id(o) for o in names.values()}) >= 9 and counted >= 80


def test_every_public_function_says_what_it_returns_and_raises():
    for name, obj in public_callables().items():
        if inspect.isfunction(obj):
            assert {"Parameters", "Returns", "Raises"} <= set(sections(obj)), name


def test_run_takes_its_options_by_name_each_typed_and_every_one_known():
    signature = inspect.signature(registry.run)
    keyword = [p for p in signature.parameters.values() if p.kind is inspect.Parameter.KEYWORD_ONLY]
    assert [p.name for p in keyword] == list(registry.OPTIONS)  # one list: the engines' option names are run's
    assert all(p.default is None and p.annotation is not inspect.Parameter.empty for p in keyword)
    assert not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in signature.parameters.values())
    # a misspelt option is bad input in one line (a ParameterError, and a TypeError as Python's own would be)
    with pytest.raises(ParameterTypeError, match="option dt_outt=0.001 is unknown to analytic-approx; allowed: dt_out"):
        registry.run("analytic-approx", RobotParams(), 0.01, dt_outt=1e-3)


def test_an_option_given_as_none_is_the_engines_default():
    """None is "not given": the same run as without the option (the analytic engine, bit for bit)."""
    plain = registry.run("analytic-approx", RobotParams(), 0.05, dt_out=1e-3)
    nones = registry.run("analytic-approx", RobotParams(), 0.05, dt_out=1e-3, rtol=None, until_steady=None,
                         settings=None, every_step=None)
    assert all((plain.series[c] == nones.series[c]).all() for c in plain.series)


def test_the_package_is_marked_typed_and_ships_the_marker():
    assert (ROOT / "ipir_mujoco" / "py.typed").is_file()
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    assert "py.typed" in data["ipir_mujoco"]
