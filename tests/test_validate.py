"""The validation job: its numbers come from the runs, its report renders offline."""

from __future__ import annotations

import html
import json
import re
from pathlib import Path

import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.cli import main
from ipir_mujoco.studies.paper_reference import (EDGE_RESOLUTION, PAPER_CASE, REPORTED, check_paper_figures,
                                                  differences_from_paper)
from ipir_mujoco.studies.lr_study import ANGLE_FIGURES, FIGURES, thresholds
from ipir_mujoco.studies.validate import build_metrics, run_ladder, validate

# references a user of the package does not have; neither docs nor reports may point there
# (spelled in two pieces so that a grep of the repository for them finds only real references)
OUTSIDE_REFERENCES = ("shared" "/", "MODEL" ".md", "CONTRACT" ".md", "DESIGN" ".md", "../")


@pytest.fixture(scope="module")
def quick_validation():
    return validate(RobotParams(), quick=True)


@pytest.mark.slow
def test_paper_checks_at_the_papers_case(quick_validation):
    metrics, _ = quick_validation
    assert metrics["paper_case"] == {"is_paper_case": True, "differences": []}
    checks = {c["key"]: c for c in metrics["paper_checks"]}
    assert list(checks) == [f.key for f in REPORTED]
    assert all(c["reproduced"] for c in checks.values())
    # module 2 advances in whole strokes of 2r: 0.25 + 8 x 0.1 = 1.05 m, exactly the edge of "about 1.0 m"
    assert checks["x2_absolute"]["status"] == "edge" and "quantised" in checks["x2_absolute"]["note"]
    assert {k for k, c in checks.items() if c["status"] == "inside"} == set(checks) - {"x2_absolute"}
    # the identities are shown apart and never counted among the figures
    assert {i["key"] for i in metrics["identities"]} == {"S_min", "S_max"} and not {"S_min", "S_max"} & set(checks)
    answer = metrics["verdicts"][0]["answer"]
    assert answer.startswith("Yes, to the precision the paper states them: 5 of the 6 figures")
    assert "edge" in answer and "not counted" in answer


def test_every_interval_is_the_stated_number_plus_minus_half_its_precision():
    """No bound is set by hand; a value one stated precision outside the interval fails, on either side."""
    for figure in REPORTED:
        assert (figure.low, figure.high) == (figure.value - figure.precision / 2, figure.value + figure.precision / 2)
        assert figure.judge(figure.value)["status"] == "inside"
        for outside in (figure.high + figure.precision, figure.low - figure.precision):
            record = figure.judge(outside)
            assert record["status"] == "outside" and not record["reproduced"], (figure.key, outside)
            assert record["margin_precisions"] == pytest.approx(-1.0, abs=1e-9)
        # on a bound (to what a solver at rtol 1e-10 can resolve) is the edge, not a clean pass
        assert figure.judge(figure.high)["status"] == "edge"
        assert figure.judge(figure.low * (1 + 0.1 * EDGE_RESOLUTION))["status"] == "edge"
        # just beyond what the solver resolves, the value is outside
        assert figure.judge(figure.high + 10 * EDGE_RESOLUTION * max(figure.high, figure.precision))["status"] \
            == "outside"


def test_the_papers_case_is_the_default_parameter_set():
    assert differences_from_paper(RobotParams()) == []
    assert RobotParams(**PAPER_CASE) == RobotParams()
    assert differences_from_paper(RobotParams(L=0.3)) == [{"name": "L", "value": 0.3, "paper": 0.2}]
    # the rod's mass is not part of the paper's case: its model rung always drops the rod
    assert differences_from_paper(RobotParams(rod_mass=0.05)) == []


@pytest.mark.slow
def test_a_design_that_is_not_the_papers_is_not_judged_by_the_papers_figures():
    """validate --set L=0.3: the report says so and never calls L/r = 6 the paper's."""
    from ipir_mujoco.report.validation import build_blocks, to_markdown

    params = RobotParams(L=0.3)
    rungs = run_ladder(params, 0.3, 1e-3, 1e-10, 1e-12, lambda _m: None)  # a short ladder: fast, same logic
    rows = [{"ratio": x, "divergence": {k: 0.2 / x**2 for k in FIGURES + ANGLE_FIGURES}} for x in (1.5, 3, 6)]
    study = {"ratios": [1.5, 3, 6], "rows": rows, "thresholds": thresholds(rows)}
    convergence = {"mujoco": [], "equations": [], "mujoco_default_error": 1e-4, "equations_default_error": 1e-10}
    settings = {"t_end_s": 0.3, "quick": True, "dt_out_s": 1e-3, "rtol": 1e-10, "atol": 1e-12,
                "mujoco": {"timestep": 1e-4, "integrator": "implicitfast", "constraint_time_constant": 2e-4,
                           "solimp": [0.99, 0.999, 0.001]}}
    metrics = build_metrics(params, rungs, settings, study, convergence)
    assert metrics["paper_case"]["is_paper_case"] is False and metrics["paper_checks"] == []
    assert metrics["verdicts"][0]["answer"].startswith("Not checked: this is not the paper's case (L = 0.3 m "
                                                       "(paper: 0.2 m))")
    costs = metrics["verdicts"][2]["answer"]
    assert "this design's L/r = 6 (the paper's case has 4)" in costs and "the paper's L/r" not in costs
    study["rows"] = []  # the report's L/r table is not under test here
    text = to_markdown(build_blocks(metrics, {name: f"figures/{name}" for name in (
        "mechanism.png", "robot.gif", "fig2_crank.png", "fig3_modules.png", "fig4_gap.png", "lr_study.png",
        "clutch_reactions.png", "pull_per_stroke.png")}))
    assert "## Not the paper's case" in text and "The paper's figures, reproduced" not in text
    assert "the paper's L/r" not in text and "at the paper's case" not in text


def test_a_wrong_model_fails_the_paper_checks():
    """The checks can fail: double the torque and the paper's figures are no longer reproduced."""
    run = analytic.simulate(RobotParams(M=0.5), "approx")
    failed = {c["key"] for c in check_paper_figures(run) if not c["reproduced"]}
    assert {"revolutions", "peak_speed", "first_contraction_end_s"} <= failed


@pytest.mark.slow
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
    # the report states the idealization's cost: (first order - exact) / |exact|
    cost = (paper["revolutions"] - exact["revolutions"]) / exact["revolutions"]
    assert metrics["ladder"][1]["cost_vs_previous"]["revolutions"] == pytest.approx(cost, abs=1e-8)
    assert f"{100 * cost:+.2f} %" in metrics["verdicts"][2]["answer"]
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


@pytest.mark.slow
def test_lr_divergence_is_recomputed_from_independent_runs(quick_validation):
    metrics, _ = quick_validation
    row = metrics["lr_study"]["rows"][2]
    params = RobotParams(rod_mass=0.0, rod_inertia=0.0, L=row["L"])
    first = analytic.simulate(params, "approx").summary["revolutions"]
    exact = analytic.simulate(params, "exact").summary["revolutions"]
    # the same equations and tolerance: only the output grid differs, which leaves the end state alone
    assert row["divergence"]["revolutions"] == pytest.approx((first - exact) / exact, abs=1e-8)


@pytest.mark.slow
def test_lr_study_measures_mujoco_against_the_equations_of_the_same_linkage(quick_validation):
    """MuJoCo needs a rod with mass; set beside the massless exact equations it read the rod's own effect
    (-0.4 % in revolutions at the paper's case) as MuJoCo's disagreement. It is measured against the exact
    equations with the same rod."""
    for row in quick_validation[0]["lr_study"]["rows"]:
        with_rod = analytic.simulate(RobotParams(L=row["L"]), "exact", "kinematic", dt_out=1e-3).summary
        assert row["exact_with_rod"]["revolutions"] == pytest.approx(with_rod["revolutions"], rel=1e-9)
        expected = (row["mujoco"]["revolutions"] - with_rod["revolutions"]) / with_rod["revolutions"]
        assert row["mujoco_vs_exact"]["revolutions"] == pytest.approx(expected, rel=1e-6)
        # MuJoCo's accuracy monitor keeps revolutions within 0.1 % of the converged mechanism (engine/loop/monitor.py)
        assert abs(row["mujoco_vs_exact"]["revolutions"]) <= 1e-3


@pytest.mark.slow
def test_pull_fraction_grows_with_crank_speed(quick_validation):
    metrics, _ = quick_validation
    strokes = [s for s in metrics["clutch_pull"]["per_stroke"] if s["t_end"] < 0.9]
    assert strokes[0]["pull_fraction"] < strokes[-1]["pull_fraction"]
    assert all(0 < s["pull_fraction"] < 1 for s in strokes)
    assert metrics["verdicts"][3]["answer"].startswith("Yes")
    # the last stroke is cut short by the end of the run: marked, and the only one so marked
    assert [s["complete"] for s in metrics["clutch_pull"]["per_stroke"]][-1] is False
    assert all(s["complete"] for s in metrics["clutch_pull"]["per_stroke"][:-1])


@pytest.mark.slow
def test_validate_writes_a_self_contained_report(shared_command):
    """The README's first command as its test runs it (``ipir-mujoco validate --quick``, one run for both:
    tests/docs_commands.py's SHARED_RUNS): a report in ./report."""
    from ipir_mujoco.video import RenderUnavailable, gl_backend

    done = shared_command("ipir-mujoco validate --quick")
    assert done.returncode == 0, done.stderr[-2000:]
    out = done.folder / "report"
    assert "[7/7]" in done.stderr  # progress shown
    page = (out / "index.html").read_text()
    markdown = (out / "report.md").read_text()
    assert "<script" not in page and "http://" not in page and "https://" not in page
    for text in (page, markdown, (out / "metrics.json").read_text()):
        assert not [ref for ref in OUTSIDE_REFERENCES if ref in text]
    # the documents it names are where the report says they are on this machine (installed with the package)
    from ipir_mujoco.resources import shipped

    for doc in ("docs/model.md", "mjcf/README.md"):
        assert f"{doc} as {shipped(doc)}" in markdown and Path(shipped(doc)).is_file()
    # the mechanism diagram, Fig. 2, 3, 4, clutch reactions, pull per stroke, the L/r study; one figure per section
    from ipir_mujoco.report.sections import SECTIONS

    # the core figures, the opening picture (idealization_costs.png) and one per section
    assert page.count('src="data:image/png;base64,') == 7 + 1 + len(SECTIONS)
    try:
        gl_backend()
        has_gl = True
    except RenderUnavailable:
        has_gl = False
    assert page.count('src="data:image/gif;base64,') == (1 if has_gl else 0)
    assert ("No animation:" in page) is not has_gl
    for name in re.findall(r"\]\((figures/[^)]+)\)", markdown):
        assert (out / name).is_file()
    # tables name figures in words with units, not by their code names
    assert "module 1 (rear) travel [m]" in markdown and "| x1_final" not in markdown
    assert "first_contraction_end_s" not in markdown
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["schema_version"] == 2 and len(metrics["ladder"]) == 7
    for verdict in metrics["verdicts"]:
        assert html.escape(verdict["question"]) in page
    # parameters left to a rule are shown by the rule's word
    assert "| clutch_stiffness | rigid | N/m |" in markdown and "(uniform rod" in markdown
    # the real-clutch section: its numbers, both engines at both operating points, its verdict and figure
    section = metrics["sections"]["clutch_engagement"]
    assert {(r["point"], r["clutch_stiffness_n_m"], r["clutch_backlash_m"]) for r in section["study"]["rows"]} == {
        (point, p["clutch_stiffness"], p["clutch_backlash"]) for point in ("cruise", "startup")
        for p in section["realistic"]}
    assert all("error" not in r[e] for r in section["study"]["rows"] for e in ("analytic", "mujoco"))
    clutch_verdict = next(v for v in metrics["verdicts"] if v["evidence"] == "sections.clutch_engagement")
    sprag = next(r for r in section["study"]["rows"] if r["point"] == "startup" and r["clutch_backlash_m"] == 0)
    assert f"{sprag['analytic']['peak_clutch_force_n']:.3g} N" in clutch_verdict["answer"]
    assert markdown.index("## Energy audit") < markdown.index("## Real clutches: engagement loads") < markdown.index(
        "## Numerical convergence")
    assert "](figures/clutch_engagement.png)" in markdown
    # under a real motor: every rung at its steady state, MuJoCo within the cross-check tolerance, a verdict
    cruise = metrics["sections"]["cruise"]
    assert len(cruise["rungs"]) == 6 and all(r["steady"] for r in cruise["rungs"])
    assert all(c["within"] for c in cruise["cross_checks"])
    assert any(v["evidence"] == "sections.cruise" for v in metrics["verdicts"])
    assert markdown.index("## Energy audit") < markdown.index("## Under a real motor") < markdown.index(
        "## Numerical convergence")
    assert "](figures/cruise_histories.png)" in markdown
    # the vertical riser: the default motor stalls in both exact models, the paper's model says it climbs; the
    # smallest motor that restarts anywhere (the torque needed at rest, rounded up to 0.01 N m) climbs in both
    riser = metrics["sections"]["vertical_riser"]
    assert all(riser["default"][e]["stalled"] for e in ("analytic-unilateral", "mujoco-ratchet"))
    assert riser["default"]["analytic-approx"]["steady"] and not riser["default"]["analytic-approx"]["stalled"]
    assert riser["need"]["torque_n_m"] > riser["motor"]["M_stall_n_m"]
    assert 0 <= riser["stronger_n_m"] - riser["need"]["torque_n_m"] < 0.01
    speeds = [riser["strong"][e]["steady_speed_m_s"] for e in ("analytic-unilateral", "mujoco-ratchet")]
    assert abs(speeds[1] / speeds[0] - 1) < 1e-3  # TARGET of tests/test_mujoco_accuracy.py
    riser_verdict = next(v for v in metrics["verdicts"] if v["evidence"] == "sections.vertical_riser")
    assert riser_verdict["answer"].startswith("No, not with the motor of M_stall 0.5 N m")
    assert f"{riser['need']['torque_n_m']:.4g} N m" in riser_verdict["answer"]
    assert markdown.index("## Real clutches: engagement loads") < markdown.index("## Vertical riser") < markdown.index(
        "## Numerical convergence")
    assert "](figures/climbing_ability.png)" in markdown and "**It stalls.**" in markdown


@pytest.mark.slow
def test_report_is_complete_without_opengl(quick_validation, tmp_path, monkeypatch):
    """Where no headless OpenGL exists the report still builds, and says why it has no animation."""
    from ipir_mujoco import video
    from ipir_mujoco.report.validation import build_blocks, to_markdown, write_animation

    def missing():
        raise video.RenderUnavailable("rendering needs a headless OpenGL library and none was found: install EGL")

    monkeypatch.setattr(video, "gl_backend", missing)
    metrics, rungs = quick_validation
    note, _ = write_animation(rungs[-1], tmp_path / "robot.gif", quick=True)
    assert note.startswith("rendering needs a headless OpenGL library") and not (tmp_path / "robot.gif").exists()
    figures = {name: f"figures/{name}" for name in ("mechanism.png", "fig2_crank.png", "fig3_modules.png",
                                                    "fig4_gap.png", "lr_study.png", "clutch_reactions.png",
                                                    "pull_per_stroke.png")}
    text = to_markdown(build_blocks(metrics, figures, note))  # raises KeyError if it wanted the missing GIF
    assert "(No animation: rendering needs a headless OpenGL library" in text and "robot.gif" not in text
    assert text.count("](figures/") == 7


def test_validate_bad_parameter_exits_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "report"
    assert main(["validate", "--quick", "--out", str(out), "--set", "L=0.01"]) == 2
    assert "L=0.01" in capsys.readouterr().err and not out.exists()


@pytest.mark.slow
def test_a_section_adds_its_metrics_verdict_and_blocks_to_the_report(quick_validation, tmp_path):
    """The registry the further studies (motor, incline, clutch compliance) plug into."""
    import copy

    from ipir_mujoco.report.document import Image, Paragraph
    from ipir_mujoco.report.plots import new_figure
    from ipir_mujoco.report.sections import Section
    from ipir_mujoco.report.validation import write_report
    from ipir_mujoco.studies.validate import run_sections

    def render(result, figures_dir):
        fig, (ax,) = new_figure(1)
        ax.plot([0, 1], [0, result["twice_L_m"]])
        fig.savefig(figures_dir / "toy.png")
        return [Paragraph(f"twice L is {result['twice_L_m']:g} m"), Image("figures/toy.png", "toy figure")]

    toy = Section("toy", "toy study", lambda params, quick, progress: {"twice_L_m": 2 * params.L}, render,
                  lambda result: {"question": "Is L positive?", "answer": "Yes", "evidence": "sections.toy",
                                  "short": "Yes", "key": f"L = {result['twice_L_m'] / 2:g} m"})
    metrics, rungs = copy.deepcopy(quick_validation)
    seen = []
    run_sections(metrics, RobotParams(L=0.3), True, seen.append, (toy,))
    assert metrics["sections"]["toy"] == {"twice_L_m": 0.6} and metrics["verdicts"][-1]["question"] == "Is L positive?"
    assert seen[0] == "toy study ..." and seen[-1].startswith("toy study: done")
    write_report(tmp_path, metrics, rungs, (toy,))
    markdown = (tmp_path / "report.md").read_text()
    # the section sits after the core sections and before the numerical evidence
    assert markdown.index("## Energy audit") < markdown.index("twice L is 0.6 m") < markdown.index("## Numerical convergence")
    assert "](figures/toy.png)" in markdown and "**Is L positive?** Yes" in markdown


@pytest.mark.slow
def test_convergence_evidence_covers_the_envelope_corners(quick_validation):
    """--quick checks the lightest rod and the shortest L/r with the automatic settings: each within the
    envelope's 0.1 % target of the analytic one-way model (the full validate runs every corner)."""
    from ipir_mujoco.studies.convergence import SMOKE_CASES

    envelope = quick_validation[0]["convergence"]["envelope"]
    assert [r["case"] for r in envelope["rows"]] == list(SMOKE_CASES)
    for row in envelope["rows"]:
        assert max(abs(row["error"]["revolutions"]), abs(row["error"]["travel"])) < envelope["tolerance"] == 1e-3
    assert envelope["worst_error"] == max(max(abs(r["error"]["revolutions"]), abs(r["error"]["travel"]))
                                          for r in envelope["rows"])


@pytest.mark.slow
def test_the_timestep_halving_starts_from_each_clutchs_own_automatic_step(quick_validation):
    """The engine chooses 5e-5 s for the locks and 1e-4 s for the ratchet at the paper's case; the halving
    study measured both clutches from 1e-4 s, so the 'halving MuJoCo's timestep from its default' figure
    was the locks' change from a step they never use, and no step below the locks' own was tried."""
    metrics = quick_validation[0]
    conv = metrics["convergence"]
    used = {run["timestep"] for run in metrics["settings"]["mujoco_runs"].values()}
    assert set(conv["mujoco_auto_timestep"].values()) == used
    worst = 0.0
    for clutch, step in conv["mujoco_auto_timestep"].items():
        rows = [r for r in conv["mujoco"] if r["clutch"] == clutch]
        assert any(r["timestep"] == pytest.approx(step / 2) for r in rows)  # half its own step was tried
        kept = [r for r in rows if r["timestep"] <= step * (1 + 1e-9)]
        for r in kept:  # each clutch against the equations of its own mechanism, within the accuracy
            # monitor's calibration at the automatic step or finer (0.1 % in revolutions, engine/loop/monitor.py)
            assert abs(r["vs_analytic"]["revolutions"]) < 1e-3
        worst = max([worst] + [abs(a[k] - b[k]) / abs(b[k]) for a in kept for b in kept
                               for k in ("revolutions", "x1_final", "x2_final")])
    assert conv["mujoco_default_error"] == pytest.approx(worst, rel=1e-12)


def test_a_relative_difference_that_rounds_to_zero_is_printed_without_a_sign():
    """The riser section printed the paper's rule on the exact linkage as '(-0.000 %)': a sign that is
    round-off's, not the robot's. Differences that do not round to zero keep theirs."""
    from ipir_mujoco.labels import signed_percent
    from ipir_mujoco.report.riser_section import _relative

    assert signed_percent(-1e-9, 3) == "0.000 %" and signed_percent(1e-9, 2) == "0.00 %"
    assert signed_percent(1.3e-4, 3) == "+0.013 %" and signed_percent(-0.05, 2) == "-5.00 %"
    assert _relative(0.16341, 0.16341 * (1 - 1e-9)) == "0.000 %"
    # the animation's overlay printed a held module's round-off speed as '-0.00 m/s'
    from ipir_mujoco.labels import fixed

    assert fixed(-1e-4, 2) == "0.00" and fixed(-0.006, 2) == "-0.01" and fixed(3.14159, 1) == "3.1"


@pytest.mark.slow
def test_the_report_opens_with_a_summary_table_that_links_each_verdict_to_its_section(quick_validation):
    """One row per verdict (question, verdict, key figure, where), before the verdicts' paragraphs; each link
    goes to a heading the report has (in HTML, to that heading's id)."""
    from ipir_mujoco.report.document import Heading, Link, Table, anchor, to_html
    from ipir_mujoco.report.validation import build_blocks

    metrics, _ = quick_validation
    # every verdict states its own short form and key figure (nothing read back out of its prose)
    assert all(v["short"] and isinstance(v["key"], str) for v in metrics["verdicts"])
    assert all(v["key"] for v in metrics["verdicts"] if not v["short"].startswith("not checked"))
    figures = {name: f"figures/{name}" for name in ("mechanism.png", "fig2_crank.png", "fig3_modules.png",
                                                    "fig4_gap.png", "lr_study.png", "clutch_reactions.png",
                                                    "pull_per_stroke.png")}
    blocks = build_blocks(metrics, figures, "no animation here")
    headings = [b.text for b in blocks if isinstance(b, Heading)]
    assert headings.index("Summary") < headings.index("Verdicts")
    summary = next(b for b in blocks if isinstance(b, Table) and list(b.header)[:2] == ["question", "verdict"])
    assert len(summary.rows) == len(metrics["verdicts"])
    links = [row[3] for row in summary.rows]
    assert all(isinstance(link, Link) and link.heading in headings for link in links)
    page = to_html([Heading(links[0].heading), Table(["where"], [[links[0]]])], Path("."))
    assert f'id="{anchor(links[0].heading)}"' in page and f'href="#{anchor(links[0].heading)}"' in page


def test_the_lr_crossing_is_the_atlas_root_finding_on_the_atlas_pair_of_runs():
    """The report's 'off by more than 1 % below L/r = X' is narrowed past the grid's bracket by the atlas's own
    k-section, and the atlas's pair of runs for first-order-kinematics (measured here as the atlas measures a
    design) puts the cost on either side of 1 % at the narrowed bracket's ends: the report and ``atlas --vary L``
    state one crossing."""
    from ipir_mujoco.studies.atlas_space import IDEALIZATIONS, measure
    from ipir_mujoco.studies.lr_study import CROSSING_TOL, refine_threshold

    params = RobotParams()
    found = refine_threshold(params.replace(rod_mass=0.0, rod_inertia=0.0), "revolutions", 0.01, [4.09, 5.13],
                             1.0, 1e-3)
    low, high = found["crossing_interval"]
    assert 4.09 < low < found["crossing"] < high < 5.13 and high - low <= CROSSING_TOL
    pair = IDEALIZATIONS["first-order-kinematics"].equations
    costs = [measure(pair, params.replace(L=x * params.r), ("revolutions",), 1.0, False)["cost"]["revolutions"]
             for x in (low, high)]
    assert costs[0] > 0.01 > costs[1], costs
    assert found["crossing_L_m"] == pytest.approx(found["crossing"] * params.r)
