"""The installed package: data files reachable, the two models independent."""

from __future__ import annotations

import ast
from pathlib import Path

import analytic
from ipir_mujoco.resources import mjcf_dir


def test_mjcf_folder_is_reachable():
    assert (mjcf_dir() / "README.md").is_file()


def test_analytic_never_imports_mujoco_or_ipir_mujoco():
    """The cross-check is worthless if the analytic side borrows the physics side's code."""
    for path in Path(analytic.__file__).parent.glob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names = [node.module or ""]
            for name in names:
                assert not name.split(".")[0] in ("mujoco", "ipir_mujoco"), f"{path.name} imports {name}"


def test_the_mujoco_side_never_runs_the_analytic_equations():
    """Engine, model, clutches and batch may share the parameter set, the result container and the
    errors with analytic/, nothing that computes dynamics."""
    import ipir_mujoco

    allowed = {"analytic.params", "analytic.results", "analytic.errors"}
    folder = Path(ipir_mujoco.__file__).parent
    for name in ("engine.py", "model.py", "clutches.py", "sweep_batch.py", "sweep_metrics.py", "resources.py"):
        tree = ast.parse((folder / name).read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").startswith("analytic"):
                assert node.module in allowed, f"{name} imports {node.module}"
            if isinstance(node, ast.Import):
                assert not any(a.name == "analytic" or a.name.startswith("analytic.") and a.name not in allowed
                               for a in node.names), f"{name} imports analytic"
