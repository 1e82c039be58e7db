"""Sections of the validation report beyond its core (the paper, the ladder, L/r, clutch forces).

Each :class:`Section` is a study that ``validate`` runs and a part of the
report it draws: ``compute`` returns a JSON-ready dict stored in
``metrics.json`` under ``sections.<key>``; ``render`` writes the section's
figures into the report's figures folder and returns its blocks
(:mod:`ipir_mujoco.report.document`); ``verdict``, if given, adds a
{question, answer, evidence, short, key} to the report's opening verdicts (``short``: the verdict in a few
words, ``key``: its key figure with its unit, '' if none; the summary table shows both).
:data:`SECTIONS` lists them in report order, read from the studies' declarations
(:func:`ipir_mujoco.studies.declared`: each study names its sections and their report modules here, which
define ``compute``, ``render`` and ``verdict``); ``ipir-mujoco validate`` runs them all.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ipir_mujoco.core.params import RobotParams

from ..studies import declared

Progress = Callable[[str], None]


@dataclass(frozen=True)
class Section:
    key: str  # metrics.json: sections.<key>
    title: str
    compute: Callable[[RobotParams, bool, Progress], dict]  # (params, quick, progress) -> metrics
    render: Callable[[dict, Path], list]  # (metrics, figures folder) -> blocks; Image paths "figures/NAME"
    verdict: Callable[[dict], dict | None] | None = None


def _sections() -> tuple[Section, ...]:
    """Every study's sections (:class:`ipir_mujoco.studies.contract.Section`), by their place, with their report
    module's functions."""
    declared_sections = sorted((s for study in declared() for s in study.sections), key=lambda s: s.place)
    found = []
    for s in declared_sections:
        module = importlib.import_module(f"{__package__}.{s.module}")
        found.append(Section(s.key, s.title, module.compute, module.render, getattr(module, "verdict", None)))
    return tuple(found)


SECTIONS: tuple[Section, ...] = _sections()
