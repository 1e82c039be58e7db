"""A study checks its output folder and the file it resumes before the first design, holds the folder locked
while it runs, and never says "done" beside a file it failed to write.

Resumed files are refused in one line naming them when they are another study's, or were edited or
duplicated (nothing run, nothing merged); a second run on a folder being written is refused.
"""

from __future__ import annotations

import errno
import json
import shutil

import pytest
from cli_run import run_cli

from ipir_mujoco.output import FolderLock

OPTIMIZE = ["optimize", "--vary", "L=0.1:0.3", "--objective", "max:mean_speed_m_s", "--budget", "6",
            "--variant", "analytic-approx", "--verify", "none", "--t-end", "0.2", "--workers", "1"]
SWEEP = ["sweep", "--vary", "L=0.1:0.3:4", "--variants", "analytic-approx", "--t-end", "0.2", "--workers", "1"]
SENSITIVITY = ["sensitivity", "--vary", "L=0.1:0.3", "--metric", "mean_speed_m_s", "--samples", "2",
               "--variant", "analytic-approx", "--t-end", "0.2", "--workers", "1"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """One finished optimize, sweep and sensitivity study, to copy and break (never written into)."""
    import io
    from contextlib import redirect_stderr, redirect_stdout

    from cli_run import exit_code

    root = tmp_path_factory.mktemp("studies")
    with redirect_stdout(io.StringIO()), redirect_stderr(io.StringIO()):
        for name, argv in (("opt", OPTIMIZE), ("other_seed", [*OPTIMIZE, "--seed", "7"]), ("swp", SWEEP),
                           ("other_sweep", ["sweep", "--vary", "L=0.12:0.32:4", *SWEEP[3:]]),
                           ("sen", SENSITIVITY)):
            assert exit_code([*argv, "--out", root / name]) == 0, name
    return root


def _copy(finished, name, tmp_path):
    target = tmp_path / name
    shutil.copytree(finished / name, target)
    return target


def _edit_line(path, number, edit):
    lines = path.read_text().splitlines(keepends=True)
    lines[number] = edit(lines[number])
    path.write_text("".join(lines))


def _set_cell(line: str, column: int, value: str) -> str:
    cells = line.rstrip("\n").split(",")
    cells[column] = value
    return ",".join(cells) + "\n"


CASES = {
    # another study's file (the same columns, other designs) under this study's optimize.json / sweep.json
    "optimize foreign": ("opt", OPTIMIZE, "evaluations.csv",
                         lambda f, d: shutil.copy(f / "other_seed" / "evaluations.csv", d / "evaluations.csv"),
                         "does not belong to this study"),
    "optimize tampered metric": ("opt", OPTIMIZE, "evaluations.csv",
                                 lambda f, d: _edit_line(d / "evaluations.csv", 2, lambda ln: _set_cell(ln, 3, "fast")),
                                 "mean_speed_m_s='fast' is not a number"),
    "optimize tampered design": ("opt", OPTIMIZE, "evaluations.csv",
                                 lambda f, d: _edit_line(d / "evaluations.csv", 2, lambda ln: _set_cell(ln, 1, "0.2")),
                                 "does not belong to this study"),
    "optimize out of bounds": ("opt", OPTIMIZE, "evaluations.csv",
                               lambda f, d: _edit_line(d / "evaluations.csv", 2, lambda ln: _set_cell(ln, 1, "0.9")),
                               "outside the study's 0.1..0.3"),
    "optimize duplicated": ("opt", OPTIMIZE, "evaluations.csv",
                            lambda f, d: _edit_line(d / "evaluations.csv", 3, lambda ln: ln + ln),
                            "repeats eval_id 2"),
    "sweep foreign": ("swp", SWEEP, "results.csv",
                      lambda f, d: shutil.copy(f / "other_sweep" / "results.csv", d / "results.csv"),
                      "is not this study's design 0"),
    "sweep tampered metric": ("swp", SWEEP, "results.csv",
                              lambda f, d: _edit_line(d / "results.csv", 1, lambda ln: _set_cell(ln, 3, "x")),
                              "is not a number"),
    "sweep duplicated": ("swp", SWEEP, "results.csv",
                         lambda f, d: _edit_line(d / "results.csv", 2, lambda ln: ln + ln),
                         "repeats design_id 1"),
    "sensitivity tampered": ("sen", SENSITIVITY, "evaluations.csv",
                             lambda f, d: _edit_line(d / "evaluations.csv", 1, lambda ln: _set_cell(ln, 0, "99")),
                             "eval_id 99 is past the study's 6 designs"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_a_resume_file_not_this_studys_own_is_refused_in_one_line_and_nothing_merged(capsys, finished, tmp_path,
                                                                                    case):
    name, argv, file, spoil, fragment = CASES[case]
    out = _copy(finished, name, tmp_path)
    spoil(finished, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    code, _, err = run_cli(capsys, *argv, "--out", out, "--resume")
    assert code == 2 and err.count("\n") == 1, err
    assert file in err and fragment in err, err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # nothing run, merged or rewritten


@pytest.mark.parametrize("name,argv", [("opt", OPTIMIZE), ("swp", SWEEP), ("sen", SENSITIVITY)])
def test_a_folder_another_run_is_writing_is_refused(capsys, finished, tmp_path, name, argv):
    """Two resumes of one folder at once: the second is refused while the first holds the folder (the lock is
    the one a running study takes; flock locks conflict between two opens in one process as between two
    processes)."""
    out = _copy(finished, name, tmp_path)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    held = FolderLock(out)
    try:
        code, _, err = run_cli(capsys, *argv, "--out", out, "--resume")
    finally:
        held.release()
    assert code == 2 and err.count("\n") == 1 and "is in use by another run" in err, err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    code, _, err = run_cli(capsys, *argv, "--out", out, "--resume")  # once released: resumed, all re-used
    assert code == 0, err


@pytest.mark.parametrize("argv,name", [(OPTIMIZE, "pareto.csv"), (OPTIMIZE, "optimize.json"),
                                       (SENSITIVITY, "indices.csv"), (SENSITIVITY, "sensitivity.png"),
                                       (SWEEP, "best.json")])
def test_a_name_the_study_writes_taken_by_a_folder_is_refused_before_the_first_design(capsys, tmp_path, argv, name):
    out = tmp_path / "out"
    (out / name).mkdir(parents=True)
    code, _, err = run_cli(capsys, *argv, "--out", out)
    assert code == 2 and err.count("\n") == 1 and f"{name}' is a folder" in err, err
    assert sorted(p.name for p in out.iterdir()) == [name]  # no design ran: no evaluations.csv, no results.csv


@pytest.mark.parametrize("argv,meta,figure", [(OPTIMIZE, "optimize.json", "pareto.png"),
                                              (SENSITIVITY, "sensitivity.json", "sensitivity.png")])
def test_a_failed_figure_leaves_no_status_done_and_no_cut_file(capsys, tmp_path, monkeypatch, argv, meta, figure):
    import matplotlib.figure

    def full(self, path, *args, **kwargs):
        with open(path, "wb"):  # as a full disk does: the file is created, nothing fits in it
            pass
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", full)
    out = tmp_path / "out"
    code, _, err = run_cli(capsys, *argv, "--out", out)
    assert code == 1 and "No space left on device" in err.splitlines()[-1], err
    assert json.loads((out / meta).read_text())["status"] == "running"
    assert not (out / figure).exists() and not [p for p in out.iterdir() if p.name.startswith(".")]
