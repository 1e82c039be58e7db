"""The study contract (ipir_mujoco/studies/contract.py): what a study declares, and that the command line and the
validation report read exactly the declared list."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from ipir_mujoco.cli import TOOLS, build_parser
from ipir_mujoco.studies import declared
from ipir_mujoco.studies.contract import Declaration, Section

REPORT = Path(__file__).resolve().parent.parent / "ipir_mujoco" / "report"


def _subcommands() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices


def test_the_command_line_has_one_subcommand_per_declared_study_and_per_tool():
    studies = [s.name for s in declared() if s.command]
    tools = [t.__name__.rsplit(".", 1)[-1] for t in TOOLS]
    assert len(set(studies)) == len(studies) and not set(studies) & set(tools)
    assert list(_subcommands()) == tools + studies  # the tools first, then the studies in declared() order
    assert {"sweep", "climb", "atlas", "uncertainty", "design-check"} <= set(studies)


def test_the_report_reads_the_declared_sections_in_their_place_order():
    from ipir_mujoco.report.sections import SECTIONS

    declared_sections = sorted((s for study in declared() for s in study.sections), key=lambda s: s.place)
    assert [s.key for s in SECTIONS] == [s.key for s in declared_sections]
    assert len({s.key for s in declared_sections}) == len(declared_sections)
    assert len({s.place for s in declared_sections}) == len(declared_sections)  # no tie left to file order
    for section, read in zip(declared_sections, SECTIONS):
        assert read.title == section.title and read.compute.__module__ == f"ipir_mujoco.report.{section.module}"


def test_every_declared_report_module_is_a_file_of_the_report():
    named = {s.figures for s in declared() if s.figures} | {x.module for s in declared() for x in s.sections}
    assert named and sorted(m for m in named if not (REPORT / f"{m}.py").is_file()) == []


def test_every_study_with_a_command_names_its_files_or_writes_none():
    """A study's files are written into its --out folder: a study that names files has --out."""
    commands = _subcommands()
    for study in declared():
        if study.files:
            dests = {a.dest for a in commands[study.name]._actions}
            assert "out" in dests, study.name


@pytest.mark.parametrize("fields, word", [
    ({"name": "Bad_Name", "summary": "s"}, "lower-case words"),
    ({"name": "ok", "summary": "s", "options": lambda parser: None}, "together"),
    ({"name": "ok", "summary": "s", "run": lambda args, figures: None}, "together"),
    ({"name": "ok", "summary": "s", "figures": "report.x"}, "module's name"),
])
def test_a_bad_declaration_is_refused_where_it_is_made(fields, word):
    with pytest.raises(ValueError, match=word):
        Declaration(**fields)
    with pytest.raises(ValueError, match="module's name"):
        Section("k", "title", "../x", 1)


# --- one word per meaning: --variant / --variants, the older --engine / --engines for one release ---------------

OLDER_NAMES = [("calibrate", "--variant", "--engine", "analytic-exact", ["--data", "run.csv"]),
               ("optimize", "--variant", "--engine", "analytic-exact", []),
               ("sensitivity", "--variant", "--engine", "analytic-exact", []),
               ("uncertainty", "--variant", "--engine", "analytic-exact", []),
               ("sweep", "--variants", "--engines", "analytic-approx,analytic-exact", []),
               ("climb", "--variants", "--engines", "analytic-approx,analytic-exact", [])]


@pytest.mark.parametrize("command, newer, older, value, extra", OLDER_NAMES, ids=[o[0] for o in OLDER_NAMES])
def test_the_older_option_name_sets_the_variant_and_notes_it(command, newer, older, value, extra):
    parser = build_parser()
    new = parser.parse_args([command, newer, value, *extra])
    old = parser.parse_args([command, older, value, *extra])
    assert getattr(new, newer[2:]) == getattr(old, newer[2:]) == value
    assert getattr(new, "notes", []) == []
    assert old.notes == [f"{older} is deprecated and will be removed in the next release; use {newer}"]
    with pytest.raises(SystemExit) as refused:  # both spellings: argparse's one line, exit 2
        parser.parse_args([command, newer, value, older, value, *extra])
    assert refused.value.code == 2


def test_a_sweep_under_the_older_name_runs_the_same_and_says_so_in_one_line(capsys, tmp_path):
    from ipir_mujoco.cli import main

    common = ["sweep", "--vary", "L=0.1,0.2", "--t-end", "0.05", "--workers", "1"]
    assert main([*common, "--variants", "analytic-approx", "--out", str(tmp_path / "new")]) == 0
    assert "note" not in capsys.readouterr().err
    assert main([*common, "--engines", "analytic-approx", "--out", str(tmp_path / "old")]) == 0
    notes = [line for line in capsys.readouterr().err.splitlines() if "note" in line]
    assert notes == ["ipir-mujoco sweep: note: --engines is deprecated and will be removed in the next release; "
                     "use --variants"]
    assert (tmp_path / "new" / "results.csv").read_bytes() == (tmp_path / "old" / "results.csv").read_bytes()


def test_a_failure_under_the_older_name_stays_one_line(capsys, tmp_path):
    """The note comes once the command succeeded: bad input under --engine is the contract's one line, exit 2."""
    from ipir_mujoco.cli import main

    assert main(["optimize", "--engine", "nan", "--vary", "m1=0.5:1", "--objective", "max:steady_speed_m_s",
                 "--out", str(tmp_path / "o")]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and "variant 'nan' is unknown" in lines[0] and "deprecated" not in lines[0]


# a study's command with the least it needs to start its work: each refuses a declared file's name taken by a folder
STARTS = {"sweep": ["--vary", "L=0.1,0.2"], "optimize": ["--vary", "L=0.1:0.3", "--objective", "max:revolutions"],
          "sensitivity": ["--vary", "L=0.1:0.3", "--metric", "revolutions"], "atlas": ["--vary", "L=0.1:0.3"],
          "clutch-study": ["--quick"], "climb": [], "control-study": ["--quick"]}


@pytest.mark.parametrize("name", sorted(STARTS))
def test_a_study_checks_the_files_its_declaration_names_before_any_work(name, tmp_path, capsys):
    """Every file a study's declaration names is checked before the work (a folder already of that name: exit 2,
    one line naming it, nothing written)."""
    from ipir_mujoco.cli import main

    study = next(s for s in declared() if s.name == name)
    assert study.files
    for file in study.files:
        out = tmp_path / file.replace(".", "_")
        (out / file).mkdir(parents=True)
        code = main([name, *STARTS[name], "--out", str(out)])
        err = capsys.readouterr().err
        assert code == 2 and file in err and err.count("\n") == 1, (file, err)
        assert sorted(p.name for p in out.iterdir()) == [file]


def test_the_studies_that_check_their_files_in_their_own_module_check_the_declared_ones():
    """sweep, atlas, optimize and sensitivity run from Python as well (run_sweep, run_atlas, ...), so their own module
    checks its files; the list is the declaration's (a light module cannot import theirs)."""
    from ipir_mujoco.studies.design import optimize, sensitivity
    from ipir_mujoco.studies.idealizations import atlas
    from ipir_mujoco.studies.sweeps import sweep

    studies = {s.name: s for s in declared()}
    for name, module in (("sweep", sweep), ("atlas", atlas), ("optimize", optimize), ("sensitivity", sensitivity)):
        assert tuple(module.OUTPUT_FILES) == studies[name].files, name
