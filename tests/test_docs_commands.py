"""Every command the documentation shows runs, and prints what the documentation quotes.

The commands come from README.md, docs/*.md, mjcf/README.md, the route files' headers and the modules'
docstrings (tests/docs_commands.py says how they are found and shortened). They run as a user types them,
in a scratch folder, through the installed ``ipir-mujoco`` and this interpreter as ``python`` (one code block
after another on each pytest-xdist worker; in one process, two blocks at a time): a command of plain words in a
child forked by a process that has the libraries imported (tests/command_zygote.py), the others by bash. Each
must exit 0 with no traceback, a synopsis must match its ``--help``, quoted output must be printed. Running them
takes minutes: those tests are marked slow; the extraction itself is checked fast.
"""

from __future__ import annotations

import argparse
import ast
import functools
import os
import re
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import docs_commands as dc  # noqa: E402

from cli_run import SHELL_TIMEOUT_S as TIMEOUT_S, forked_entry, run_command, run_shell  # noqa: E402

GROUPS = dc.all_commands()
SHARED = {ran for _documented, ran, _reader in dc.SHARED_RUNS}
COMMANDS = [command for group in GROUPS.values() for command in group]


@functools.lru_cache(maxsize=1)
def _subcommands() -> dict[str, argparse.ArgumentParser]:
    from ipir_mujoco.cli import build_parser

    parser = build_parser()
    return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices


def needs_arguments(command: dc.Command) -> bool:
    """A command named, not shown: an inline ``ipir-mujoco NAME`` or ``python -m MODULE`` with no arguments
    in running text or a heading ('## `ipir-mujoco sweep`', '`ipir-mujoco clutch-study`: the engagement
    loads ...'), or a bare subcommand that cannot run without arguments. The test runs its --help (the
    command's examples and synopsis, shown in code blocks, are run and checked where they stand)."""
    words = command.text.split()
    if command.inline and not command.screen and (
            (words[0] == "ipir-mujoco" and len(words) <= 2) or (words[0].startswith("python") and len(words) == 3
                                                                and words[1] == "-m")):
        return True
    if words[0] != "ipir-mujoco" or len(words) != 2 or words[1] not in _subcommands():
        return False
    return any(a.required or not a.option_strings for a in _subcommands()[words[1]]._actions
               if a.dest != "help")


run = run_command


@functools.lru_cache(maxsize=None)
def help_text(prog: tuple[str, ...]) -> tuple[int, str]:
    """(exit status, text) of ``PROG --help``. For ``ipir-mujoco [SUBCOMMAND]`` the parser's own help, read in
    this process: the text the command prints for --help, character for character (argparse prints
    format_help(); test_in_process_help_is_what_the_command_prints holds it for each), without a
    process of 0.3 s for each of them on each worker; other programs run."""
    if prog[0] == "ipir-mujoco" and (len(prog) == 1 or prog[1] in _subcommands()):
        from ipir_mujoco.cli import build_parser

        return 0, (build_parser() if len(prog) == 1 else _subcommands()[prog[1]]).format_help()
    done = run(" ".join(prog) + " --help", dc.ROOT)
    return done.returncode, done.stdout + done.stderr


def test_in_process_help_is_what_the_command_prints(capsys):
    """help_text's in-process help is what the command's entry point (``main``, which the ``ipir-mujoco`` script
    calls) prints for ``[SUBCOMMAND] --help``, exit status 0, for each subcommand."""
    from cli_run import run_cli

    for name in ("", *_subcommands()):
        prog = ("ipir-mujoco", name) if name else ("ipir-mujoco",)
        code, out, err = run_cli(capsys, *prog[1:], "--help")
        assert (code, out + err) == help_text(prog), prog


def test_a_forked_command_does_what_the_same_command_does_in_a_new_process(tmp_path):
    """run_command's forked child gives what bash's new process gives: exit status, standard output, standard error
    (a run, a refusal, a python script's warning and traceback, a module run with -m), and leaves shell syntax to
    bash."""
    (tmp_path / "boom.py").write_text("import warnings\nwarnings.warn('careful')\nprint('out')\nraise KeyError(3)\n")
    for text in ("ipir-mujoco simulate --t-end 0.05 --set M=0.3", "ipir-mujoco simulate --set m1=-1",
                 "python boom.py", "python -m ipir_mujoco.report.diagram robot.png"):
        assert forked_entry(text) is not None, text
        forked, new = run_command(text, tmp_path), run_shell(text, tmp_path)
        wall = dc.WALL.sub  # the run's wall time, the one figure that may differ
        assert (forked.returncode, wall("", forked.stdout)) == (new.returncode, wall("", new.stdout)), text
        # a traceback names the frames that ran: the forked child's own (command_zygote, runpy) are extra
        assert [line for line in forked.stderr.splitlines() if not line.startswith("  ")][-3:] == \
            [line for line in new.stderr.splitlines() if not line.startswith("  ")][-3:], text
    for text in ("ipir-mujoco params | head -3", "python bench/x.py > out.txt", "A=1 ipir-mujoco params"):
        assert forked_entry(text) is None, text


def help_of(prog) -> str:
    """A program's --help text ('' if it has none)."""
    code, text = help_text(tuple(prog))
    return text if code == 0 else ""


def scratch(folder: Path) -> Path:
    """A folder as the repository's root looks to a user: mjcf/ and docs/ copied (commands write there),
    bench/ and tests/ linked (the benchmarks import the tests' designs)."""
    folder.mkdir(parents=True)
    for name in ("mjcf", "docs"):
        shutil.copytree(dc.ROOT / name, folder / name)
    for name in ("bench", "tests"):
        (folder / name).symlink_to(dc.ROOT / name)
    return folder


def run_group(commands: list[dc.Command], folder: Path, shared=None) -> dict[int, dict]:
    """What each command did; a command alone in its group whose output other tests read too
    (:data:`docs_commands.SHARED_RUNS`) is ``shared(text)``'s one run."""
    out = {}
    quoting = any(command.output for command in commands)  # a printed figure may depend on a grid's points
    for command in commands:
        if command.synopsis or needs_arguments(command):
            prog = dc.program(command.text)
            code, text = help_text(tuple(prog))
            out[id(command)] = dict(ran=" ".join(prog) + " --help", how="synopsis", code=code, stdout=text,
                                    stderr="")
            continue
        missing = dc.missing_inputs(command.text, folder)
        if missing:  # an example's own data: the command's --help, and the synopsis check
            prog = dc.program(command.text)
            code, text = help_text(tuple(prog))
            out[id(command)] = dict(ran=" ".join(prog) + " --help", how=f"needs {', '.join(missing)}", code=code,
                                    stdout=text, stderr="")
            continue
        ran, how = dc.shortened(command.text, help_of, grids=not quoting)
        if "mujoco.viewer" in command.text:  # MuJoCo's own viewer needs a screen: load the file it opens
            path = command.text.split("--mjcf", 1)[1].split()[0]
            ran, how = f"python -c 'import mujoco; mujoco.MjModel.from_xml_path(\"{path}\")'", "loads the model"
        started = time.monotonic()
        try:
            done = shared(ran) if shared is not None and len(commands) == 1 and ran in SHARED else \
                run(ran, folder)
        except subprocess.TimeoutExpired as exc:  # this command's failure, not the others'
            out[id(command)] = dict(ran=ran, how=how, code=None, stdout=exc.stdout or "",
                                    stderr=f"timed out after {TIMEOUT_S} s", seconds=TIMEOUT_S)
            continue
        out[id(command)] = dict(ran=ran, how=how, code=done.returncode, stdout=done.stdout, stderr=done.stderr,
                                seconds=time.monotonic() - started)
    return out


@pytest.fixture(scope="module")
def results(tmp_path_factory, shared_command):
    """group name -> {id(command): what it did}. Each group of commands runs once, in its own scratch folder. In
    one process all groups run at once, two at a time (the machine's cores); under pytest-xdist each group runs
    where its tests are sent (tests/conftest.py keeps a group on one worker; the other workers run the rest of the
    suite)."""
    base = tmp_path_factory.mktemp("docs")
    done: dict[str, dict] = {}

    def of(group: str) -> dict:
        if group not in done:
            if os.environ.get("PYTEST_XDIST_WORKER"):
                done[group] = run_group(GROUPS[group], scratch(base / f"g{len(done)}"), shared_command)
            else:
                with ThreadPoolExecutor(max_workers=2) as pool:
                    jobs = {name: pool.submit(run_group, commands, scratch(base / f"g{i}"), shared_command)
                            for i, (name, commands) in enumerate(GROUPS.items())}
                    done.update({name: job.result() for name, job in jobs.items()})
        return done[group]
    return of


def test_the_docs_show_commands_of_every_kind():
    """The extraction finds what the pages show: if it found nothing the slow test would pass vacuously."""
    texts = [c.text for c in COMMANDS]
    assert len(COMMANDS) >= 80
    assert sum(c.synopsis for c in COMMANDS) >= 20
    assert sum(bool(c.output) for c in COMMANDS) >= 5
    # every benchmark shows its usage, and every subcommand is shown somewhere
    for bench in sorted((dc.ROOT / "bench").glob("*.py")):
        assert any(f"bench/{bench.name}" in t for t in texts), bench.name
    for name in _subcommands():
        assert any(t.startswith(f"ipir-mujoco {name}") for t in texts), name
    # a continued line is one command; quoted output stays with its command
    simulate = next(c for c in COMMANDS if c.text == "ipir-mujoco simulate" and c.output)
    assert simulate.output[0].startswith("analytic engine")


def test_every_benchmark_has_a_smoke_mode():
    """Each bench declares --smoke (read from its source: running 20 interpreters is the slow test's job,
    which runs each bench with it) and says so in its usage."""
    for bench in sorted((dc.ROOT / "bench").glob("*.py")):
        source = bench.read_text()
        assert '"--smoke"' in source, bench.name  # the option in its code (argparse or by hand)
        assert "--smoke" in (ast.get_docstring(ast.parse(source)) or ""), bench.name


@pytest.mark.slow
# the id's first word is the command's group (tests/conftest.py runs each group's tests on one worker)
@pytest.mark.parametrize("command", COMMANDS, ids=[f"{c.group} {c.source} {c.text[:60]}" for c in COMMANDS])
def test_documented_command(command, results):
    got = results(command.group)[id(command)]
    where = f"{command.source}: {got['ran']}"
    if command.screen and "mujoco.viewer" not in command.text and got["how"] != "synopsis":
        # without a screen the viewer refuses: one line naming what is missing, exit 2
        assert got["code"] == 2, where
        assert len(got["stderr"].strip().splitlines()) == 1 and "screen" in got["stderr"], where
        return
    assert got["code"] == 0, f"{where}\nexit {got['code']}\n{got['stderr'][-2000:]}"
    assert "Traceback" not in got["stderr"], f"{where}\n{got['stderr'][-2000:]}"
    if got["how"] == "synopsis":
        missing = [o for o in dc.options_shown(command.text) if o not in got["stdout"]]
        assert not missing, f"{where}: the synopsis shows {missing}, which --help does not list"
    elif command.output and not got["how"]:  # run as written: what it prints must hold the quoted lines
        missing = dc.missing_output(command.output, got["stdout"])
        assert not missing, f"{where}: quoted but not printed:\n" + "\n".join(missing) + \
            "\n--- printed:\n" + got["stdout"][-3000:]
