"""The report's and the studies' figures read right (tests/figure_checks.py): legend entries drawn, axes with
units and without raw keys, no text over data; and each figure's own fault fixed. Built from small
synthetic records in the shape the studies write, so that these tests take a second."""

from __future__ import annotations

import numpy as np
import pytest

import figure_checks
from ipir_mujoco.report import cruise_section


def _cruise_metrics(same: bool = True) -> dict:
    """Rungs as cruise_study writes them: the three equation rungs on one curve, the locks on it too, the
    one-way rungs on another, the one-way rungs running longer (they settle later)."""
    rungs = []
    for name, t_end, level in ((cruise_section.PAPER, 1.75, 0.43), (cruise_section.EXACT, 1.75, 0.43),
                               (cruise_section.ROD, 1.75, 0.43), (cruise_section.LOCKS, 1.75, 0.43),
                               (cruise_section.ONE_WAY, 2.2, 0.53), (cruise_section.RATCHET, 2.2, 0.53)):
        t = np.linspace(0.0, t_end, 400)
        ends = np.linspace(0.35, t_end, 8)
        rungs.append({"name": name, "steady": True, "steady_speed_m_s": level,
                      "history": {"t": t.tolist(), "omega": (30 * level * (1 + 0.2 * np.sin(40 * t))).tolist(),
                                  "speed": (level * (1 + 0.5 * np.sin(40 * t))).tolist()},
                      "revolutions_end": {"t": ends.tolist(), "speed": (level * (1 - np.exp(-5 * ends))).tolist()}})
    return {"rungs": rungs, "params": {"omega_noload": 30.0}}


def test_cruise_histories_show_every_series_on_one_time_axis():
    fig = cruise_section.history_figure(_cruise_metrics())
    assert not figure_checks.undrawn_legend_entries(fig)
    assert not figure_checks.bad_axis_labels(fig)
    assert not figure_checks.texts_over_data(fig)
    assert "[s]" in fig.axes[-1].get_xlabel()
    # one time axis: the three panels span the same times (panel (c) used to start at its first revolution)
    assert len({ax.get_xlim() for ax in fig.axes}) == 1 and fig.axes[0].get_xlim()[0] == 0.0
    # a series drawn over an identical one is thinner, so the one under it shows as a rim
    for ax in fig.axes:
        lines = [line for line in ax.lines if len(line.get_xdata()) > 2]
        for i, upper in enumerate(lines):
            for lower in lines[:i]:
                if np.array_equal(lower.get_xdata(), upper.get_xdata()) and \
                        np.allclose(lower.get_ydata(), upper.get_ydata()):
                    assert upper.get_linewidth() < lower.get_linewidth(), (lower.get_label(), upper.get_label())


def _grip_metrics() -> dict:
    """The finite-grip section's record: per case the unlimited-grip runs and the finite-grip rows (the
    cruise runs to their steady states, each as long as it needs)."""
    from ipir_mujoco.report.grip_section import ONE_WAY, PAPER

    def run(travel, t_end, speed, peak=12.0, slip=0.0):
        return {"travel_m": travel, "t_end_s": t_end, "steady_speed_m_s": speed, "peak_clutch_force_n": peak,
                "slip_m": slip}
    cases = {}
    for key, drive in (("startup", "torque"), ("cruise", "motor")):
        rows = [{"mu": mu, "press_n": press, "grip_n": mu * press,
                 ONE_WAY: run(1.3 - 0.1 * (mu == 0.1), 2.6 + (mu == 0.1), 0.53 - 0.01 * (mu == 0.1), slip=0.01)}
                for mu in (0.1, 0.5) for press in (50.0,)]
        cases[key] = {"drive": drive, "unlimited": {PAPER: run(1.2, 2.4, 0.43, 77.0), ONE_WAY: run(1.25, 2.5, 0.533)},
                      "rows": rows}
    return {"quick": True, "mu": [0.1, 0.5], "press_n": [50.0], "cases": cases,
            "riser": {"mu": 0.5, "needed_n": [41.4, 41.4], "press_n": {"drive_off": [19.6, 19.9]}}}


@pytest.mark.slow
def test_finite_grip_figure_labels_its_log_axis_and_its_table_says_each_runs_time(tmp_path):
    from ipir_mujoco.report import grip_section
    from ipir_mujoco.report.document import Table

    metrics = _grip_metrics()
    fig = grip_section.grip_figure(metrics)
    assert not figure_checks.undrawn_legend_entries(fig)
    assert not figure_checks.bad_axis_labels(fig)
    assert not figure_checks.texts_over_data(fig)
    for ax in fig.axes:
        fig.canvas.draw()
        shown = [t.get_text() for t in ax.get_xticklabels() if t.get_text() and
                 ax.get_xlim()[0] <= t.get_position()[0] <= ax.get_xlim()[1]]
        assert len(shown) >= 2, shown  # a log axis over 5-25 N used to show one label ("10^1")
        assert "mu_wall" not in ax.get_xlabel() and "F_n" not in ax.get_xlabel()
    # the table: the speed is the figure to compare; a travel comes with the time it took
    (table,) = [b for b in grip_section.render(metrics, tmp_path) if isinstance(b, Table)][1:]
    travel = table.header.index("travel [m] in the run's time [s]")
    assert table.rows[0][travel] == "1.250 in 2.50 s" and table.rows[1][travel] == "1.200 in 3.60 s"
    assert table.header.index("speed [m/s] (steady, or mean over 1 s)") < travel


def test_the_ladder_shows_a_change_through_zero_in_its_unit_and_flags_an_inaccurate_rung():
    from ipir_mujoco.report.validation import accuracy_flag, ladder_change, monitor_verdict

    # a reaction from -1371 N (a pull) to 0: not '+100.00 %'
    assert ladder_change(0.0, -1371.2, 1.0, "min_clutch_reaction_n") == "+1371 N"
    assert ladder_change(5.0, -2.0, -3.5, "x1_final") == "+7 m"
    assert ladder_change(8.289, 8.3223, -0.004, "revolutions") == "-0.40 %"
    assert ladder_change(8.3, None, None, "revolutions") == ""
    accuracy = {"residual_ratio": 3.78e-3, "tolerances": {"residual_ratio": 1e-3, "loop_gap_m": 5e-5}, "mode": "warn",
                "ok": False, "violations": [{"figure": "residual_ratio", "t_s": 0.819, "value": 1.04e-3,
                                             "tolerance": 1e-3}], "loop_gap_m": 1.4e-5}
    flag = accuracy_flag("wheels in contact", accuracy)
    assert flag.startswith("wheels in contact: residual_ratio 3.8e-03 against the tolerance 0.001 (first above it "
                           "at t = 0.819 s)") and "loop_gap_m" not in flag
    assert monitor_verdict(accuracy) == "ABOVE: residual_ratio (see below)"
    assert accuracy_flag("MuJoCo ratchet", {**accuracy, "ok": True, "violations": []}) == ""
    assert monitor_verdict({"residual_ratio": 1e-9}) == ""  # the equations: no monitor


def _optimize_folder(tmp_path, infeasible: bool):
    """evaluations.csv and pareto.csv of a one-objective search (min M_stall with steady speed >= 0.5 m/s)
    as run_optimize writes them, with or without infeasible designs."""
    from ipir_mujoco.core.params import RobotParams
    from ipir_mujoco.studies.optimize import Problem, parse_constraint, parse_objective
    from ipir_mujoco.studies.sweep_space import parse_vary

    problem = Problem((parse_vary("M_stall=0.1:1"),), (parse_objective("min:M_stall"),),
                      (parse_constraint("steady_speed_m_s>=0.5"),), RobotParams(drive="motor"), verify=None,
                      t_end=10.0, until_steady=True, budget=20)
    stall = np.linspace(0.32 if not infeasible else 0.1, 1.0, 12)
    speed = 0.5 + 0.28 * (stall - 0.316)
    header = "eval_id,M_stall,steady_speed_m_s,notes,error\n"
    rows = [f"{i},{m:.6g},{v:.6g},," for i, (m, v) in enumerate(zip(stall, speed))]
    (tmp_path / "evaluations.csv").write_text(header + "\n".join(rows) + "\n")
    best = int(np.argmin(np.where(speed >= 0.5, stall, np.inf)))
    (tmp_path / "pareto.csv").write_text(header + rows[best] + "\n")
    return problem


def test_pareto_figure_names_its_axes_in_words_with_units_and_lists_only_what_it_drew(tmp_path):
    from ipir_mujoco.report.optimize_plots import pareto_figure

    for infeasible in (False, True):
        fig = pareto_figure(tmp_path, _optimize_folder(tmp_path, infeasible))
        assert not figure_checks.undrawn_legend_entries(fig)
        assert not figure_checks.bad_axis_labels(fig)
        assert not figure_checks.texts_over_data(fig)
        labels = [t.get_text() for t in fig.legends[0].get_texts()]
        assert any(label.startswith("infeasible") for label in labels) is infeasible, labels
        assert fig.axes[0].get_ylabel() == "steady forward speed [m/s]" and fig.axes[0].get_xlabel() == "M_stall [N m]"
        assert "constraint: steady forward speed >= 0.5" in labels


def test_sensitivity_figure_labels_units_and_says_why_s1_exceeds_st():
    from ipir_mujoco.report.optimize_plots import indices_figure

    indices = [{"metric": "energy_per_metre_j_m", "parameter": "F_r1", "S1": 0.522, "S1_conf": 0.18, "ST": 0.473,
                "ST_conf": 0.156},
               {"metric": "energy_per_metre_j_m", "parameter": "F_r2", "S1": 0.501, "S1_conf": 0.244, "ST": 0.499,
                "ST_conf": 0.129},
               {"metric": "energy_per_metre_j_m", "parameter": "L", "S1": 0.0, "S1_conf": 0.0, "ST": 0.0,
                "ST_conf": 0.0}]
    fig = indices_figure(indices, ["energy_per_metre_j_m"])
    assert not figure_checks.undrawn_legend_entries(fig)
    assert not figure_checks.bad_axis_labels(fig)
    assert not figure_checks.texts_over_data(fig)
    (ax,) = fig.axes
    assert ax.get_ylabel() == "Sobol index [-]" and "energy per metre [J/m]" in ax.get_title()
    # F_r1's S1 is 0.05 above its ST (shown); F_r2's 0.002 (not visible on the bars: not commented)
    assert "S1 > ST for F_r1: within the 95 % intervals" in ax.get_title()
    agreeing = [dict(i, S1=min(i["S1"], i["ST"])) for i in indices]
    assert "S1 > ST" not in indices_figure(agreeing, ["energy_per_metre_j_m"]).axes[0].get_title()


def _report_metrics() -> dict:
    """A metrics record's ladder (the first second) and cruise section, as validate writes them."""
    ladder = {"paper model": (8.435, 0.8959, 0.8), "exact geometry": (8.322, 0.8770, 0.8),
              "with rod mass": (8.289, 0.8682, 0.8), "MuJoCo, paper's rule": (8.290, 0.8683, 0.79995),
              "one-way clutches": (7.587, 0.9907, 0.8964), "MuJoCo ratchet": (7.589, 0.9907, 0.8966),
              "wheels in contact": (7.475, 1.0048, 0.9053)}
    cruise = {"paper model": 0.4270, "exact geometry": 0.4255, "with rod mass": 0.4256,
              "MuJoCo, paper's rule": 0.42561, "one-way clutches": 0.5326, "MuJoCo ratchet": 0.53265}
    return {"ladder": [{"name": n, "summary": {"revolutions": r, "x1_final": x1, "x2_final": x2}}
                       for n, (r, x1, x2) in ladder.items()],
            "sections": {"cruise": {"rungs": [{"name": n, "steady_speed_m_s": v} for n, v in cruise.items()]}}}


def test_the_report_opens_with_each_idealizations_cost_beside_the_numerical_error():
    from ipir_mujoco.report.overview import idealization_costs, overview_figure

    metrics = _report_metrics()
    data = idealization_costs(metrics)
    costs = dict(data["costs"])
    # the paper's first-order geometry against the exact one: (8.435 - 8.322) / 8.322
    assert costs["first-order geometry"]["revolutions"] == pytest.approx(8.435 / 8.322 - 1, rel=1e-12)
    assert costs["locks that pull (not one-way)"]["cruise"] == pytest.approx(0.4256 / 0.5326 - 1, rel=1e-12)
    assert "cruise" not in costs["slides (not wheels on the wall)"]  # no wheeled cruise: n/a, not 0
    # the band: the engines' worst disagreement on one linkage
    assert data["error"]["revolutions"] == pytest.approx(max(8.290 / 8.289 - 1, 7.589 / 7.587 - 1), rel=1e-12)
    fig = overview_figure(metrics)
    assert not figure_checks.undrawn_legend_entries(fig)
    assert not figure_checks.bad_axis_labels(fig)
    assert not figure_checks.texts_over_data(fig)
    bars = [p for p in fig.axes[0].patches if p.get_height() == pytest.approx(0.6)]
    assert len(bars) == 4 and all("numerical error" in ax.get_title() for ax in fig.axes)
    assert [t.get_text() for t in fig.axes[2].texts].count("n/a") == 1


def test_verdicts_stay_short_and_their_detail_opens_their_section():
    from ipir_mujoco.report.document import Heading, Paragraph
    from ipir_mujoco.report.overview import VERDICT_WORDS, place_moved, short_verdict, verdict_blocks

    long = ("Under a gearmotor the paper's model cruises at 0.427 m/s where the robot does 0.533 m/s. "
            + "Its locks stop each module instead of letting it coast, " * 8 + "so it is slow. The end.")
    text, cut = short_verdict(long)
    assert cut and text == "Under a gearmotor the paper's model cruises at 0.427 m/s where the robot does 0.533 m/s."
    one = "Yes, to the precision the paper states them: " + "5 of 6 figures land in their intervals, " * 10 + "ok."
    assert short_verdict(one) == ("Yes, to the precision the paper states them.", True)
    verdicts = [{"question": "Q1?", "answer": long, "section": "Under a real motor"},
                {"question": "Q2?", "answer": "Yes.", "section": "Energy audit"}]
    blocks, moved = verdict_blocks(verdicts)
    assert all(len(b.text.split()) <= VERDICT_WORDS + 12 for b in blocks if isinstance(b, Paragraph))
    assert blocks[1].text.endswith('(More in "Under a real motor".)') and list(moved) == ["Under a real motor"]
    placed = place_moved([Heading("Under a real motor"), Paragraph("table")], moved)
    assert placed[1].text == f"**Q1?** {long}" and placed[2].text == "table"
