"""Older import paths: a module that moved or was renamed keeps its older dotted name, as the very same module;
and a package's names loaded on first use (:func:`lazy_names`).

Users' scripts import modules by the paths they had (``ipir_mujoco.engine.simulate`` from when the engine was one
folder, ``ipir_mujoco.analytic.unilateral_clutch`` before the analytic model's run loops were named ``*_run``).
:func:`keep_older_paths` registers a package's table {older dotted name: the module's name now}; one finder on
``sys.meta_path`` imports an older name as the module under its name now, so both names give one module object
(an attribute patched through either is the one the package uses) with its own ``__spec__``.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys

OLDER_PATHS: dict[str, str] = {}  # every package's table, merged


class _OlderPaths(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds an older name of :data:`OLDER_PATHS` and loads it as the module at its name now."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in OLDER_PATHS:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        module = importlib.import_module(OLDER_PATHS[spec.name])
        spec.loader_state = module.__spec__  # the import system sets the older spec on the module: kept to undo it
        return module

    def exec_module(self, module):
        module.__spec__ = module.__spec__.loader_state  # the module's own spec again (reload, python -m)


def keep_older_paths(table: dict[str, str]) -> None:
    """Make each older dotted name of ``table`` import the module named by its value (installs the finder once)."""
    OLDER_PATHS.update(table)
    if not any(isinstance(finder, _OlderPaths) for finder in sys.meta_path):
        # first: an older package path (``engine.modelkinds``) is a package now under another name, whose folder
        # the path finder would search for the older path's modules and load a second copy of each
        sys.meta_path.insert(0, _OlderPaths())


def lazy_names(package: str, table: dict[str, str]):
    """A package's ``__getattr__`` and ``__dir__`` (PEP 562) for the names of ``table`` ({name: its submodule,
    relative to ``package``}): each imported on first use and kept, so that importing the package loads none of
    them (the command line's parsers and ``--help`` load no numpy through ``ipir_mujoco`` and its ``core``)."""
    def __getattr__(name: str):
        if name in table:
            value = getattr(importlib.import_module(f"{package}.{table[name]}"), name)
            setattr(sys.modules[package], name, value)
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(table))
    return __getattr__, __dir__
