"""The validation job: its numbers come from the runs, its report renders offline."""

from __future__ import annotations

import html
import json
import re

import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.cli import main
from ipir_mujoco.studies.paper_reference import REPORTED, check_paper_figures
from ipir_mujoco.studies.lr_study import ANGLE_FIGURES, FIGURES, thresholds
from ipir_mujoco.studies.validate import validate


@pytest.fixture(scope="module")
def quick_validation():
    return validate(RobotParams(), quick=True)


def test_paper_checks_all_pass_for_the_papers_model(quick_validation):
    metrics, _ = quick_validation
    assert [c["key"] for c in metrics["paper_checks"]] == [f.key for f in REPORTED]
    assert all(c["reproduced"] for c in metrics["paper_checks"])
    assert metrics["verdicts"][0]["answer"].startswith("Yes: 8 of 8")


def test_a_wrong_model_fails_the_paper_checks():
    """The checks can fail: double the torque and the paper's figures are no longer reproduced."""
    run = analytic.simulate(RobotParams(M=0.5), "approx")
    failed = {c["key"] for c in check_paper_figures(run) if not c["reproduced"]}
    assert {"revolutions", "peak_speed", "first_contraction_end_s"} <= failed


def test_verdict_numbers_are_recomputed_from_independent_runs(quick_validation):
    metrics, _ = quick_validation
    base = RobotParams(rod_mass=0.0, rod_inertia=0.0)
    paper = analytic.simulate(base, "approx").summary
    exact = analytic.simulate(base, "exact").summary
    expected = (exact["revolutions"] - paper["revolutions"]) / paper["revolutions"]
    stated = metrics["ladder"][1]["change_vs_previous"]["revolutions"]
    # same solver and tolerance (rtol 1e-10): only the output grid differs, which
    # does not touch the end state, so the two agree to a few rtol
    assert stated == pytest.approx(expected, abs=1e-8)
    assert f"{100 * expected:+.2f} %" in metrics["verdicts"][2]["answer"]
    # the largest pull of a lock: min over locked samples, which include every switch instant
    assert metrics["clutch_pull"]["min_reaction_n"] == pytest.approx(paper["min_clutch_reaction_n"], rel=1e-8)
    assert f"{-paper['min_clutch_reaction_n']:.0f} N" in metrics["verdicts"][2]["answer"]


def test_lr_thresholds_bracket_the_true_crossing():
    """Synthetic divergence c / ratio^2: it crosses a level at ratio sqrt(c / level) exactly."""
    ratios = np.geomspace(1.05, 20, 9)
    c = 0.2
    rows = [{"ratio": x, "divergence": {k: c / x**2 for k in FIGURES + ANGLE_FIGURES}} for x in ratios]
    found = thresholds(rows)["revolutions"]
    for key, level in (("1%", 0.01), ("5%", 0.05)):
        lo, hi = found[key]["between"]
        assert lo < np.sqrt(c / level) <= hi
        assert hi / lo == pytest.approx(ratios[1] / ratios[0])  # the bracket is one grid step: the resolution
    tiny = [{"ratio": x, "divergence": {k: 1e-4 for k in FIGURES + ANGLE_FIGURES}} for x in ratios]
    assert thresholds(tiny)["x1_final"]["1%"] == {"below_sweep": True, "smallest_ratio": ratios[0]}
    huge = [{"ratio": x, "divergence": {k: 0.5 for k in FIGURES + ANGLE_FIGURES}} for x in ratios]
    assert thresholds(huge)["x1_final"]["5%"] == {"whole_sweep": True, "largest_ratio": ratios[-1]}


def test_lr_divergence_is_recomputed_from_independent_runs(quick_validation):
    metrics, _ = quick_validation
    row = metrics["lr_study"]["rows"][2]
    params = RobotParams(rod_mass=0.0, rod_inertia=0.0, L=row["L"])
    first = analytic.simulate(params, "approx").summary["revolutions"]
    exact = analytic.simulate(params, "exact").summary["revolutions"]
    # the same equations and tolerance: only the output grid differs, which leaves the end state alone
    assert row["divergence"]["revolutions"] == pytest.approx((first - exact) / exact, abs=1e-8)


def test_pull_fraction_grows_with_crank_speed(quick_validation):
    metrics, _ = quick_validation
    strokes = [s for s in metrics["clutch_pull"]["per_stroke"] if s["t_end"] < 0.9]
    assert strokes[0]["pull_fraction"] < strokes[-1]["pull_fraction"]
    assert all(0 < s["pull_fraction"] < 1 for s in strokes)
    assert metrics["verdicts"][3]["answer"].startswith("Yes")


def test_validate_writes_a_self_contained_report(tmp_path, capsys):
    out = tmp_path / "report"
    assert main(["validate", "--quick", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "[6/6]" in captured.err  # progress shown
    page = (out / "index.html").read_text()
    assert "<script" not in page and "http://" not in page and "https://" not in page
    # Fig. 2, 3, 4, clutch reactions, pull per stroke, the L/r study
    assert page.count('src="data:image/png;base64,') == 6
    markdown = (out / "report.md").read_text()
    for name in re.findall(r"\]\((figures/[^)]+)\)", markdown):
        assert (out / name).is_file()
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["schema_version"] == 1 and len(metrics["ladder"]) == 6
    for verdict in metrics["verdicts"]:
        assert html.escape(verdict["question"]) in page


def test_validate_bad_parameter_exits_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "report"
    assert main(["validate", "--quick", "--out", str(out), "--set", "L=0.01"]) == 2
    assert "L=0.01" in capsys.readouterr().err and not out.exists()
