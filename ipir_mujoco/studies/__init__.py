"""Studies that run the engines and judge them, grouped by what they are (a folder each): the validation job,
comparisons of runs, sweeps, design searches, uncertainty, the idealization atlas, climbing, the mechanism's
parts.

A study declares itself (:mod:`ipir_mujoco.studies.contract`): a module of a group folder whose source holds
``STUDY = Declaration(...)``. :func:`declared` finds every one; the command line and the validation report read
that list, so that a study is added in its own module.

The modules' older paths (``ipir_mujoco.studies.sweep``, ``ipir_mujoco.studies.atlas``, ...: the studies were one
folder) keep working: :func:`ipir_mujoco.core.older_paths.keep_older_paths` imports each as the very module at its
new place.
"""

from __future__ import annotations

import functools
import importlib
from pathlib import Path

from ipir_mujoco.core.older_paths import keep_older_paths

__all__ = ["declared"]

# each module's group folder (below studies/), where its older path ``ipir_mujoco.studies.<module>`` points
GROUPS = {
    "validation": ("validate", "ladder", "paper_reference", "cruise", "lr_study", "convergence"),
    "comparison": ("compare", "agreement", "measured", "route_compare"),
    "sweeps": ("sweep", "sweep_space", "sweep_files", "sweep_metrics", "frames"),
    "design": ("design_eval", "optimize", "sensitivity", "calibrate", "design_rules"),
    "uq": ("uncertainty", "uq_dists", "uq_stats"),
    "idealizations": ("atlas", "atlas_space", "atlas_eval", "atlas_adaptive", "atlas_surrogate", "gp"),
    "climb": ("climbing", "climb_limits", "traction"),
    "mechanism": ("clutch_study", "control_study", "bend_study"),
}
keep_older_paths({f"{__name__}.{module}": f"{__name__}.{group}.{module}"
                  for group, modules in GROUPS.items() for module in modules})

DECLARES = "\nSTUDY = Declaration("  # how a module's source declares its study (at its top level)


@functools.cache
def declared() -> tuple:
    """Every study's :class:`~ipir_mujoco.studies.contract.Declaration`, found in its module.

    Returns
    -------
    tuple of Declaration
        The ``STUDY`` of every module of the group folders (their ``__init__.py`` included) whose source declares
        one, by group folder (in :data:`GROUPS`' order, a folder it does not list after them by name) then module
        name: the command list's order. Only those modules are imported (each light: no numpy).

    Raises
    ------
    ValueError
        Two studies of one name.
    """
    found, names = [], {}
    order = list(GROUPS)
    folders = sorted((p.parent for p in Path(__file__).parent.glob("*/__init__.py")),
                     key=lambda f: (order.index(f.name) if f.name in order else len(order), f.name))
    for folder in folders:
        for file in sorted(folder.glob("*.py")):
            if DECLARES not in file.read_text(encoding="utf-8"):
                continue
            module = f"{__name__}.{folder.name}" + ("" if file.stem == "__init__" else f".{file.stem}")
            study = importlib.import_module(module).STUDY
            if study.name in names:
                raise ValueError(f"study {study.name!r} is declared twice: {names[study.name]} and {module}")
            names[study.name] = module
            found.append(study)
    return tuple(found)
