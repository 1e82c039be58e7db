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
