"""What the studies' commands share: the robot's options and parameter set, progress, the files a command writes.

The command line (``ipir_mujoco.cli``) reads these too (``simulate``'s model options); they stand here, below
it, so that a study's declaration (:mod:`ipir_mujoco.studies.contract`) imports nothing above the studies.
Numpy-free: ``ipir-mujoco --help`` builds every parser with them.
"""

from __future__ import annotations

import argparse
from typing import Callable

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import DRIVES, FEEDFORWARDS, RobotParams, load_params

from .. import terminal

__all__ = ["add_model_options", "add_study_options", "add_variant_option", "check_input_file", "compile_first",
           "files_line", "model_params", "study_progress", "write_study_files"]


def add_model_options(parser: argparse.ArgumentParser) -> None:
    """--set, --config and --drive: the parameter set of the robot."""
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE",
                        help="set a parameter (SI units; incline in degrees); 'ipir-mujoco params' lists every "
                             "name with its meaning, unit, default and allowed range")
    parser.add_argument("--config", metavar="FILE.toml",
                        help="TOML file of parameters (top level or a [params] table); --set wins over it")
    parser.add_argument("--drive", choices=DRIVES, default=None,
                        help="what turns the crank: torque = the constant M (the paper's case, default); "
                             "motor = a DC gearmotor, M_stall (1 - omega / omega_noload); servo = that motor under "
                             "a speed controller holding omega_target (--set omega_target=RAD_S; docs/control.md); "
                             "wins over --set and the config file; a parameter only another drive uses (M, M_stall, "
                             "omega_noload, the controller's) is refused")
    parser.add_argument("--feedforward", choices=FEEDFORWARDS, default=None,
                        help="--drive servo only: the torque table the speed controller adds to its PI, from "
                             "inverse kinetostatics at omega_target: none (PI alone, default), paper (the paper's "
                             "first-order geometry, L >> r) or exact (the exact slider-crank); wins over --set")


def add_study_options(parser: argparse.ArgumentParser, command: str, set_help: str) -> None:
    """The options every study command (clutch-study, control-study, bend-study) shares: --workers, --out
    (default ./COMMAND), and --set (``set_help`` says what the study sets itself) and --config for the robot."""
    parser.add_argument("--workers", type=int, default=None, help="processes to use (default: all cores)")
    parser.add_argument("--out", metavar="DIR", default=command, help=f"results folder (default ./{command})")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE",
                        help=f"a robot parameter (SI units), {set_help}")
    parser.add_argument("--config", metavar="FILE.toml", help="TOML file of robot parameters; --set wins over it")


def add_variant_option(parser: argparse.ArgumentParser, *, many: bool, default: str | None, help: str) -> None:
    """``--variant NAME`` (``many`` False) or ``--variants A,B`` (``many`` True): the variant(s) a study runs (a
    model in an engine, ``ENGINE-MODEL[-RULE]``; ``ipir_mujoco.registry``), read as ``args.variant`` or
    ``args.variants``. The older spelling, ``--engine`` or ``--engines``, stays accepted for one release: it
    sets the same value and says so (:class:`_OlderName`: a line the command line prints on stderr once the
    command succeeded, ``args.notes``); giving both is refused by argparse (exit 2, one line)."""
    newer, older, metavar = ("--variants", "--engines", "LIST") if many else ("--variant", "--engine", "NAME")
    dest = newer[2:]
    both = parser.add_mutually_exclusive_group()
    both.add_argument(newer, dest=dest, default=default, metavar=metavar, help=help)
    both.add_argument(older, dest=dest, default=argparse.SUPPRESS, metavar=metavar, action=_OlderName,
                      newer=newer, help=f"the older name of {newer}, accepted for one release (with a note on stderr)")


class _OlderName(argparse.Action):
    """An option's older name: stores its value under the newer option's name, and in ``notes`` (a list of the
    namespace, which the command line prints on stderr, one line each, once the command succeeded) that the name
    is deprecated and which to use."""

    def __init__(self, option_strings, dest, newer: str, **kwargs):
        super().__init__(option_strings, dest, **kwargs)
        self.newer = newer

    def __call__(self, parser, namespace, values, option_string=None):
        note = f"{option_string} is deprecated and will be removed in the next release; use {self.newer}"
        namespace.notes = [*getattr(namespace, "notes", ()), note]
        setattr(namespace, self.dest, values)


def model_params(args: argparse.Namespace) -> RobotParams:
    """The parameter set a command's options describe: defaults, --config, --set, then --drive and
    --feedforward (refused in one line with a drive other than servo)."""
    drive = getattr(args, "drive", None)
    # --drive as the last --set, not a replace(): a drive's parameters given with another drive are refused by
    # the run (core.drive_fields.refuse_idle_parameters), where replace() would quietly reset them
    params = load_params(args.config, [*args.overrides, *([f"drive={drive}"] if drive is not None else [])])
    feedforward = getattr(args, "feedforward", None)
    if feedforward is not None:
        if params.drive != "servo":
            raise ParameterError(f"--feedforward {feedforward} applies only to --drive servo (the drive here is "
                                 f"{params.drive!r}); allowed: --drive servo, or leave --feedforward out")
        params = params.replace(feedforward=feedforward)
    return params


def check_input_file(option: str, path: str) -> None:
    """A file the user names exists and is a file (not a folder), or a one-line ParameterError."""
    from pathlib import Path

    if not str(path).strip():  # Path('') is '.', the current folder
        raise ParameterError(f"{option} {path!r} names no file; give a file")
    target = Path(path)
    if target.is_dir():
        raise ParameterError(f"{option} {path!r} is a folder; give a file")
    if not target.exists():
        raise ParameterError(f"{option} {path!r} does not exist")
    if not target.is_file():  # /dev/zero, a pipe: read for ever
        raise ParameterError(f"{option} {path!r} is not a regular file (a device or pipe); give a file")


def compile_first(engines=None) -> None:
    """Before a long command's work: the analytic kernels compiled now, in this process, where numba's cache
    does not hold them yet (once per machine: 12-40 s, said at once on stderr and every second while it lasts,
    :mod:`ipir_mujoco.analytic.accel`), so that the command says so within a second or two of its start rather
    than after its imports and first runs, and a pool's workers load them rather than each compiling them.
    ``engines``: the variants the command runs (None: the analytic engines among them); nothing without one."""
    from ipir_mujoco import registry

    if engines is not None and all(registry.variant(e).is_mujoco for e in engines):
        return
    from ipir_mujoco.analytic import accel, compile_kernels

    if accel.compilation_pending():
        compile_kernels()


def study_progress(command: str) -> Callable[[str], None]:
    """A study's progress on stderr, one line per message, prefixed with the command's name; a message that is
    a status (:class:`ipir_mujoco.core.options.Status`: "still running") as the status line (in place on a
    terminal, every 5 s in a log). ``live``: the study's heartbeats may beat every second."""
    from ipir_mujoco.core.options import Status

    def progress(message: str) -> None:
        terminal.say(f"{command}: {message}", status=isinstance(message, Status))
    progress.live = True
    return progress


def files_line(out, *names) -> str:
    """'OUT/a.csv, OUT/b.json, ...': every file a command wrote with its folder (``names`` relative to ``out``;
    a path already holding its folder, a figure's as the study returned it, as it is)."""
    from pathlib import Path

    return ", ".join(str(n) if Path(n).parent != Path(".") else str(Path(out) / n) for n in names)


def write_study_files(out, files: tuple[str, str, str], study: dict, write_csv, write_figure, table: str,
                      counted: str) -> None:
    """A study command's ending: ``files`` (CSV, JSON, figure) written into ``out`` all or nothing
    (``write_csv(path, study)``, the study as JSON, ``write_figure(path)``), then the ``table`` and one line
    '``counted`` in S s; results: ...' on stdout."""
    from pathlib import Path

    from ipir_mujoco.core.results import write_json

    from ..output import staged_output

    with staged_output(out) as staging:
        write_csv(staging / files[0], study)
        write_json(staging / files[1], study)
        write_figure(staging / files[2])
    print(table)
    print(f"{counted} in {study['wall_s']:.1f} s; results: " + ", ".join(str(Path(out) / f) for f in files))
