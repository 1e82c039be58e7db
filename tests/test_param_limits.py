"""Every value the parameter table allows runs cleanly: the table's limits walked through each command.

The cases come from the table itself (:class:`ipir_mujoco.core.param_table.RobotParams`' field metadata): each
numeric field at its lowest and highest allowed value (the nearest float inside an open bound), its word for
None where it has one, and every choice of the choice fields. A limit one field allows may still be refused
for the set it makes with the others (L at its lowest is below r): that is bad input, one line, exit 2. A
run the limit makes impossible is a failure: one line with the time and the reason, exit 1. "Cleanly": one
of those, or a result, and never an internal error, a traceback, a library warning or a JSON that Python's
strict reader refuses.
"""

from __future__ import annotations

import dataclasses
import json
import math
import warnings

import pytest

from ipir_mujoco.cli import main
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.studies.sweep_files import header_for


def limit_cases() -> list[tuple[str, str]]:
    """(field, value as --set reads it) for every limit of the table."""
    cases = []
    for f in dataclasses.fields(RobotParams):
        meta = f.metadata
        if meta["kind"] == "choice":
            cases += [(f.name, choice) for choice in meta["choices"]]
            continue
        low = math.nextafter(meta["low"], math.inf) if meta["low_open"] else meta["low"]
        high = math.nextafter(meta["high"], -math.inf) if meta["high_open"] else meta["high"]
        cases += [(f.name, repr(low)), (f.name, repr(high))]
        if meta["none_word"] is not None:
            cases.append((f.name, meta["none_word"]))
    return cases


CASES = limit_cases()


def run_cli(capsys, argv):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            code = main([str(a) for a in argv])
        except SystemExit as exc:
            code = exc.code
    out, err = capsys.readouterr()
    return code, out, err, [str(w.message) for w in caught]


def assert_clean(code, out, err, caught, json_out: bool = False):
    last = err.strip().splitlines()[-1] if err.strip() else ""
    assert code in (0, 1, 2), err
    assert "internal error" not in err and "Traceback" not in err, err
    assert caught == [], caught
    if code:
        assert last.count("ipir-mujoco") == 1 and sum(ln.startswith("ipir-mujoco ") for ln in err.splitlines()) == 1
    if code == 0 and json_out:
        json.loads(out, parse_constant=lambda name: pytest.fail(f"{name} in the JSON"))


def test_the_walk_covers_every_field_of_the_table():
    names = {f.name for f in dataclasses.fields(RobotParams)}
    assert {name for name, _ in CASES} == names and len(CASES) >= 2 * len(names)


# the command line's path (--json included) in the paper's model; the exact one-way equations and MuJoCo's
# ratchet walk the table below, as the studies run them (run_design)
ENGINES = {"analytic": []}
T_END = 0.02  # s: the first steps, where a limit breaks a run
# M at +-1e6 N m: the crank's angle grows as M t^2 / (2 J) and the engines' work with the revolutions, so 0.02 s
# costs 14,771 revolutions (47 s of CPU, measured); 0.002 s still turns 149 revolutions at speeds no other
# limit reaches, a hundredth of the work (t^2)
T_END_AT = {("M", repr(1e6)): 0.002, ("M", repr(-1e6)): 0.002}


@pytest.mark.slow
@pytest.mark.parametrize("engine", list(ENGINES))
def test_every_limit_runs_cleanly_in_every_engine(capsys, tmp_path, engine):
    """simulate --json at every limit (T_END, or T_END_AT's shorter time where the limit's cost grows with it)."""
    outcomes = {0: 0, 1: 0, 2: 0}
    for name, value in CASES:
        t_end = T_END_AT.get((name, value), T_END)
        code, out, err, caught = run_cli(capsys, ["simulate", *ENGINES[engine], "--t-end", t_end, "--json",
                                                  "--set", f"{name}={value}"])
        assert_clean(code, out, err, caught, json_out=True)
        outcomes[code] += 1
    assert outcomes[0] > len(CASES) // 2  # most limits are a valid robot on their own


@pytest.mark.slow
def test_every_limit_gives_a_row_or_a_recorded_failure_in_the_studies(tmp_path):
    """The per-design task of sweep, optimize and sensitivity at every limit, in both engines: metrics or a
    recorded one-line error, never an internal error; the row goes through results.csv and is read back."""
    from ipir_mujoco.studies.sweep import run_design
    from ipir_mujoco.studies.sweep_files import ResultsFile, make_row
    from ipir_mujoco.studies.sweep_space import Axis, Study

    engines = ("analytic-unilateral", "mujoco-ratchet")
    for k, (name, value) in enumerate(CASES):
        if name in ("drive", "feedforward"):
            continue  # words: a study varies numbers (simulate walks them above)
        design = {name: None if value.isalpha() else float(value)}
        if design[name] is None:
            continue  # the default of a field with a None word: every default design
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            results = run_design(design, RobotParams(), engines, T_END_AT.get((name, value), T_END))
        for engine, metrics in results.items():
            assert "internal error" not in metrics.get("error", ""), (name, value, metrics["error"])
            assert all(v is None or isinstance(v, (int, float, str)) for v in metrics.values())
        try:
            study = Study((Axis(name, (design[name],)),), engines=engines, t_end=T_END_AT.get((name, value), T_END))
        except ParameterError as exc:  # a value no design can use with the defaults (a speed-controller parameter
            # without the servo, a clutch's damping or play without its spring): refused before the first run, as
            # each engine refuses it in its row
            # (at the field's default the run is the default design's, which no engine refuses; the study still
            # refuses an axis of a field its designs do not use, whatever its values)
            default = getattr(RobotParams(), name) == design[name]
            assert all(default or str(exc).split(": ", 1)[1] in metrics["error"] for metrics in results.values()), \
                (exc, results)
            continue
        file = ResultsFile(tmp_path / f"{k}.csv", header_for(study), resume=False)
        file.write(make_row(0, design, results, engines))
        file.close()
        again = ResultsFile(tmp_path / f"{k}.csv", header_for(study), resume=True,
                            numeric=set(header_for(study)) - {"design_id", "notes", "error"})
        again.close()
        assert again.done == {0}


@pytest.mark.slow
@pytest.mark.parametrize("argv", [
    ["sweep", "--vary", "incline=-90,90", "--vary", "F_r1=0,1e6", "--variants", "analytic-unilateral,mujoco-ratchet"],
    ["optimize", "--vary", "g=0:100", "--objective", "max:revolutions", "--budget", "3", "--verify",
     "mujoco-ratchet"],
    ["sensitivity", "--vary", "incline=-90:90", "--vary", "F_r2=0:1e6", "--metric", "revolutions", "--samples", "2"],
], ids=["sweep", "optimize", "sensitivity"])
def test_every_study_command_runs_cleanly_across_whole_ranges(capsys, tmp_path, argv):
    """Each study command to its files over ranges spanning the table's limits: a result, or one line. (Limits
    that make every run long but bounded, M = +-1e6 N m spending the analytic engines' max_switches, are walked
    per design above.)"""
    code, out, err, caught = run_cli(capsys, [*argv, "--t-end", "0.05", "--workers", "1", "--out", tmp_path / "o"])
    assert_clean(code, out, err, caught)
