"""The study contract: what a study declares, so that the command line and the validation report find it.

A study is a module of a group folder of ``ipir_mujoco/studies/`` whose source names its declaration,
``STUDY = Declaration(...)``: its name, its command-line options, its run function, the files it writes, the
report module that draws its figures and the sections of the validation report it fills.
:func:`ipir_mujoco.studies.declared` finds every such module (nothing else is edited to add one); the command
line (``ipir_mujoco.cli``) makes a subcommand of each that has options, and the report
(``ipir_mujoco.report.sections``) a section of each :class:`Section`.

A declaring module stays light: importing it loads no numpy (``ipir-mujoco --help`` imports every one); what it
runs it imports inside its run function. It never imports the report or the command line, the layers above
the studies: it names its report module (``figures``, ``Section.module``), which the layer above loads.
"""

from __future__ import annotations

import argparse
import re
from dataclasses import dataclass
from typing import Any, Callable

__all__ = ["Declaration", "Section"]

NAME = re.compile(r"^[a-z][a-z0-9]*(-[a-z0-9]+)*$")  # a command's name: lower-case words joined by '-'
MODULE = re.compile(r"^[a-z_][a-z0-9_]*$")  # a report module's name, below ipir_mujoco.report


@dataclass(frozen=True)
class Section:
    """A part of the validation report a study fills (``ipir-mujoco validate`` runs every one).

    Parameters
    ----------
    key : str
        Its key in the report's metrics.json (``sections.<key>``).
    title : str
        Its heading in the report.
    module : str
        Its report module, ``ipir_mujoco.report.<module>``: ``compute(params, quick, progress) -> dict`` (the
        metrics, JSON-ready), ``render(metrics, figures) -> blocks`` and optionally ``verdict(metrics)``
        (:class:`ipir_mujoco.report.sections.Section` says what each does).
    place : int
        Where it stands in the report: the sections are sorted by it.

    Raises
    ------
    ValueError
        A module that is not a module's name.
    """

    key: str
    title: str
    module: str
    place: int

    def __post_init__(self) -> None:
        if not MODULE.match(self.module):
            raise ValueError(f"Section module={self.module!r} is not a module's name below ipir_mujoco.report")


@dataclass(frozen=True)
class Declaration:
    """One study, as the command line and the report read it.

    Parameters
    ----------
    name : str
        Its name: its subcommand (``ipir-mujoco NAME``), lower-case words joined by ``-``.
    summary : str
        One line: what it answers (the command list of ``ipir-mujoco --help``).
    description : str
        Its command's ``--help`` text: what it runs, writes and prints.
    options : callable or None
        ``options(parser)`` adds its command-line options to its ``argparse`` parser; None: a study without a
        command (a section of the report only).
    run : callable or None
        ``run(args, figures)``: the command's work from the parsed options ``args``: every value checked before
        any work, the study run, its files written, its table printed; ``figures`` is its report module
        (``figures``), each name imported when first read (None without one). Bad input raises
        :class:`ipir_mujoco.core.errors.ParameterError`, a failed run
        :class:`ipir_mujoco.core.errors.SimulationError` (the command line makes each one line and its exit
        status). Given with ``options``, and only then.
    files : tuple of str
        The files it writes into its results folder (checked before any work, written all or nothing).
    figures : str or None
        The report module that draws its command's figures (``ipir_mujoco.report.<figures>``), or None.
    sections : tuple of Section
        The parts of the validation report it fills.

    Raises
    ------
    ValueError
        A name that is not lower-case words joined by '-', options without a run function or a run function
        without options, a figures module that is not a module's name.
    """

    name: str
    summary: str
    description: str = ""
    options: Callable[[argparse.ArgumentParser], None] | None = None
    run: Callable[[argparse.Namespace, Any], None] | None = None
    files: tuple[str, ...] = ()
    figures: str | None = None
    sections: tuple[Section, ...] = ()

    def __post_init__(self) -> None:
        if not NAME.match(self.name):
            raise ValueError(f"Declaration name={self.name!r}: allowed: lower-case words joined by '-'")
        if (self.options is None) != (self.run is None):
            raise ValueError(f"study {self.name!r}: options and run are given together (a command) or not at all")
        if self.figures is not None and not MODULE.match(self.figures):
            raise ValueError(f"study {self.name!r}: figures={self.figures!r} is not a module's name below "
                             "ipir_mujoco.report")

    @property
    def command(self) -> bool:
        """Whether it has a subcommand of its own."""
        return self.options is not None
