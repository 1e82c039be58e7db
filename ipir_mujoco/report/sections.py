"""Sections of the validation report beyond its core (the paper, the ladder, L/r, clutch forces).

Each :class:`Section` is a study that ``validate`` runs and a part of the
report it draws: ``compute`` returns a JSON-ready dict stored in
``metrics.json`` under ``sections.<key>``; ``render`` writes the section's
figures into the report's figures folder and returns its blocks
(:mod:`ipir_mujoco.report.document`); ``verdict``, if given, adds a
{question, answer, evidence, short, key} to the report's opening verdicts (``short``: the verdict in a few
words, ``key``: its key figure with its unit, '' if none; the summary table shows both).
:data:`SECTIONS` lists them in report order; ``ipir-mujoco validate`` runs
them all.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ipir_mujoco.core.params import RobotParams

from . import atlas_section, clutch_section, control_section, cruise_section, grip_section, riser_section

Progress = Callable[[str], None]


@dataclass(frozen=True)
class Section:
    key: str  # metrics.json: sections.<key>
    title: str
    compute: Callable[[RobotParams, bool, Progress], dict]  # (params, quick, progress) -> metrics
    render: Callable[[dict, Path], list]  # (metrics, figures folder) -> blocks; Image paths "figures/NAME"
    verdict: Callable[[dict], dict | None] | None = None


SECTIONS: tuple[Section, ...] = (
    Section("clutch_engagement", "Real clutches: engagement loads", clutch_section.compute, clutch_section.render,
            clutch_section.verdict),
    Section("cruise", "Under a real motor", cruise_section.compute, cruise_section.render, cruise_section.verdict),
    Section("vertical_riser", "Vertical riser", riser_section.compute, riser_section.render, riser_section.verdict),
    Section("finite_grip", "Finite grip", grip_section.compute, grip_section.render, grip_section.verdict),
    Section("speed_control", "Speed control", control_section.compute, control_section.render,
            control_section.verdict),
    Section("model_holds", "Where the paper's model holds", atlas_section.compute, atlas_section.render,
            atlas_section.verdict),
)
