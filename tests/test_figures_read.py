"""The report's and the studies' figures read right (tests/figure_checks.py): legend entries drawn, axes with
units and without raw keys, no text over data; and each figure's own fault fixed. Built from small
synthetic records in the shape the studies write, so that these tests take a second."""

from __future__ import annotations

import copy

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
    # as the ladder's table calls it, the rung before (the paper's locks, pulling) against the one-way clutches:
    # their cost is a difference, the relative one undefined against 0 N
    assert ladder_change(-1371.2, 0.0, None, "min_clutch_reaction_n") == "-1371 N"
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
    # every value inside its panel (a -20 % label ran into the panel's edge), no band in the legend that does not
    # show (the engines agree to 0.02 %: a band a tenth of a pixel wide)
    figure_checks.assert_reads_right(fig)
    bars = [p for p in fig.axes[0].patches if p.get_height() == pytest.approx(0.6)]
    assert len(bars) == 4 and all("numerical error" in ax.get_title() for ax in fig.axes)
    assert [t.get_text() for t in fig.axes[2].texts].count("n/a") == 1
    assert all("too narrow to draw" in ax.get_title() for ax in fig.axes)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert not any("numerical error" in label for label in labels)
    # a numerical error wide enough to see is drawn as a band and keyed in the legend
    wide = copy.deepcopy(metrics)
    wide["ladder"][3]["summary"]["revolutions"] *= 1.02  # MuJoCo 2 % off the equations
    fig = overview_figure(wide)
    figure_checks.assert_reads_right(fig)
    assert "too narrow" not in fig.axes[0].get_title()
    assert any("numerical error" in t.get_text() for t in fig.legends[0].get_texts())


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


def _atlas_result(atlas, cost, mujoco: bool) -> dict:
    """An atlas result in run_atlas's shape for one idealization and metric: the equations' dense sample of
    ``cost(parameter values) -> signed cost`` and their surrogate, and (``mujoco``) a few MuJoCo designs with a
    surrogate on top; safe shares and the 1-D crossing as the atlas states them."""
    from ipir_mujoco.studies.atlas import unit_sobol
    from ipir_mujoco.studies.atlas_surrogate import CostSurrogate

    (name,), (metric,), (t,) = atlas.idealizations, atlas.metrics, atlas.thresholds
    U = unit_sobol(32, len(atlas.axes), 0)
    c = cost(atlas.values(U))
    equations = CostSurrogate(t).update(U, c)
    result = {"_surrogates": {(name, "equations"): {metric: equations}},
              "_measured": {(name, "equations"): (U, [{"cost": {metric: v}} for v in c])},
              "_candidates": unit_sobol(256, len(atlas.axes), 7)}
    share = float(np.mean(np.abs(c) < t))
    entry = {"measured_by": "equations", "by_threshold": [
        {"threshold": t, "safe_fraction": share, "safe_fraction_interval": [share - 0.08, min(1.0, share + 0.08)]}]}
    if len(atlas.axes) == 1:
        x = np.sort(atlas.values(U)[:, 0])
        cross = float(x[np.argmin(np.abs(np.abs(cost(x[:, None])) - t))])
        entry["by_threshold"][0]["crossings_interval"] = {atlas.names[0]: [[cross, cross * 0.999, cross * 1.001]]}
    if mujoco:
        Um = unit_sobol(8, len(atlas.axes), 3)
        cm = cost(atlas.values(Um)) * 1.01
        result["_surrogates"][(name, "mujoco")] = {metric: CostSurrogate(t, equations).update(Um, cm)}
        result["_measured"][(name, "mujoco")] = (Um, [{"cost": {metric: v}} for v in cm])
        entry = {"measured_by": "mujoco", "by_threshold": [
            {"threshold": t, "safe_fraction": share, "safe_fraction_interval": [share - 0.02, share + 0.02]}],
            "equations": entry}
    result["idealizations"] = {name: {metric: entry}}
    return result


def test_atlas_figures_name_things_in_words_with_units_and_show_their_keys():
    """atlas_1d.png, atlas_map.png and atlas_safe.png: the varied parameters with their units (L [m], m2 [kg]),
    no code names (first-order-kinematics, travel_m, |cost|), a colour bar in plain numbers (it read '2x10^1'),
    the boundary's legend entry visible (white on the white legend), no share written over an error bar's cap,
    no legend entry for a measure not drawn."""
    from ipir_mujoco.core.params import RobotParams
    from ipir_mujoco.report.atlas_plots import figure_1d, figure_map, safe_figure
    from ipir_mujoco.studies.atlas import Atlas
    from ipir_mujoco.studies.sweep_space import Axis

    line = Atlas((Axis("L", (), 0.06, 0.5),), RobotParams(), idealizations=("first-order-kinematics",),
                 metrics=("travel_m",), budget=0)
    result = _atlas_result(line, lambda v: 0.26 * (0.05 / v[:, 0]) ** 1.9, mujoco=False)
    fig = figure_1d(result, line)
    figure_checks.assert_reads_right(fig)
    assert fig.axes[0].get_xlabel() == "L [m]"
    plane = Atlas((Axis("L", (), 0.08, 0.4), Axis("m2", (), 0.3, 3.0)), RobotParams(),
                  idealizations=("locking-clutches",), metrics=("revolutions",), thresholds=(0.15,), budget=16)
    result = _atlas_result(plane, lambda v: 0.09 + 0.12 * (v[:, 1] - 1.0) ** 2 + 0.02 * v[:, 0], mujoco=True)
    fig = figure_map(result, plane)
    figure_checks.assert_reads_right(fig)
    assert (fig.axes[0].get_xlabel(), fig.axes[0].get_ylabel()) == ("L [m]", "m2 [kg]")
    for idealizations, axes in ((result["idealizations"], plane.axes),
                                (_atlas_result(line, lambda v: 0.01 + 0 * v[:, 0], False)["idealizations"],
                                 line.axes)):
        fig = safe_figure(idealizations, axes)
        figure_checks.assert_reads_right(fig)
    # a share of 100 % with its interval at the panel's edge: written right of it, inside the figure
    full = {"massless-rod": {"revolutions": {"measured_by": "equations", "by_threshold": [
        {"threshold": 0.01, "safe_fraction": 1.0, "safe_fraction_interval": [0.97, 1.0]},
        {"threshold": 0.05, "safe_fraction": 0.991, "safe_fraction_interval": [0.96, 0.999]}]}}}
    figure_checks.assert_reads_right(safe_figure(full, line.axes))


def _climb_study(brackets: dict) -> dict:
    """A climb study in climb_study's shape under the motor: two engines over 0-90 deg, stalling above 77 deg,
    with their steady-climb brackets ``brackets`` {engine: [climbs, stalls]}."""
    rows = []
    for incline in (0.0, 30.0, 60.0, 75.0, 80.0, 90.0):
        stalled = incline > 77.6
        metrics = {"stalled": stalled, "steady_speed_m_s": None if stalled else 0.53 - 0.0055 * incline,
                   "peak_clutch_force_n": 12.0 + 0.4 * incline, "mean_clutch_force_n": 1.7 + 0.2 * incline}
        rows.append({"incline_deg": incline, "engines": {"analytic-unilateral": dict(metrics),
                                                         "mujoco-ratchet": dict(metrics, peak_clutch_force_n=None)}})
    return {"drive": "motor", "engines": ["analytic-unilateral", "mujoco-ratchet"], "rows": rows, "t_end_s": 12.0,
            "restart": {"incline_deg": 61.44}, "steady_climb": {
                e: {"incline_deg": b[0], "bracket": b} for e, b in brackets.items()}}


def test_climbing_figure_keys_its_limit_as_drawn_with_the_bracket_climb_prints():
    """The steady-climb limit: black dotted in the legend was drawn as blue and orange dashes; it said 77.5 deg
    where ``climb`` prints 77.56-77.62 deg. Engines with one bracket share one black dotted line; an engine with
    its own bracket gets a line in its colour."""
    from ipir_mujoco.core.params import RobotParams
    from ipir_mujoco.report.climb_figure import climb_figure

    params = RobotParams(drive="motor")
    same = _climb_study({"analytic-unilateral": [77.5627, 77.6186], "mujoco-ratchet": [77.5627, 77.6186]})
    fig = climb_figure(same, params)
    figure_checks.assert_reads_right(fig)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("77.56-77.62 deg (analytic one-way clutches, MuJoCo ratchet)" in label for label in labels), labels
    limits = [line for line in fig.axes[0].lines if (line.get_gid() or "").startswith("steady-limit")]
    assert len(limits) == 1 and limits[0].get_color() == "black" and limits[0].get_xdata()[0] == 77.5627
    apart = _climb_study({"analytic-unilateral": [77.5627, 77.6186], "mujoco-ratchet": [77.2, 77.3]})
    fig = climb_figure(apart, params)
    figure_checks.assert_reads_right(fig)
    limits = [line for line in fig.axes[0].lines if (line.get_gid() or "").startswith("steady-limit")]
    assert sorted(line.get_color() for line in limits) == ["tab:blue", "tab:orange"]


def test_speed_control_figure_shows_the_promise_apart_and_keys_the_target():
    """speed_control.png: the paper's promise lay hidden under the delivered curves (its deviations are a tenth of
    theirs), the black zero line was not in the legend, the controllers read 'pi+paper', 'pi+exact'."""
    from ipir_mujoco.report.control_section import EXACT, MUJOCO, PROMISE, RUNS, speed_figure

    phi = np.linspace(0.0, 2 * np.pi, 400)
    runs = []
    for controller, variant in RUNS:
        size = {PROMISE: 0.0003}.get(variant, 0.002 if controller != "pi" else 0.004)
        runs.append({"controller": controller, "variant": variant,
                     "trace": {"phi_rad": phi.tolist(), "omega_rad_s": (10 * (1 + size * np.sin(2 * phi))).tolist()}})
    fig = speed_figure({"speed_rad_s": 10.0, "runs": runs})
    figure_checks.assert_reads_right(fig)
    texts = [t.get_text() for t in figure_checks._shown_texts(fig)]
    assert not [t for t in texts if "pi+" in t], texts
    (ax,) = fig.axes
    series = [line for line in ax.lines if len(line.get_xdata()) > 2]
    (promise,) = [line for line in series if "paper's geometry" in line.get_label()]
    assert promise.get_linewidth() >= 5 * max(line.get_linewidth() for line in series if line is not promise)
    assert promise.get_zorder() < min(line.get_zorder() for line in series if line is not promise)
    assert any(t.startswith("target") for t in texts)
    assert {EXACT, MUJOCO} <= {r["variant"] for r in runs}


def test_uncertainty_figure_names_metrics_and_events_in_words():
    """uncertainty.png: its axes and titles read 'energy_per_metre_j_m', 'P(metric <= x)', its events
    'skid_m>0.05', its legends 'analytic-unilateral'; now words with units, legends below the data."""
    from ipir_mujoco.report.uncertainty_figure import uncertainty_figure
    from ipir_mujoco.studies.uncertainty import event_words, key_words

    rng = np.random.default_rng(0)
    rows = [{"sample": i, "analytic-unilateral:energy_per_metre_j_m": float(v),
             "mujoco-ratchet:energy_per_metre_j_m": float(v) if i < 10 else None}
            for i, v in enumerate(rng.normal(2.0, 0.14, 200))]
    entry = {"mean": 2.0, "mean_interval": [1.98, 2.02], "std": 0.14, "std_interval": [0.13, 0.16],
             "quantiles": {"5": 1.77, "50": 2.0, "95": 2.23}, "quantile_intervals": {"5": [1.7, 1.8], "50": [1.97, 2.02],
                                                                                   "95": [2.2, 2.29]},
             "estimator": "multi-fidelity", "variance_reduction": 19.5, "correlation": 0.99999, "mujoco_samples": 10}
    events = {"slides-back": {"probability": 0.04, "interval": [0.0, 0.47], "resolved": False,
                              "equations_mc": {"interval": [0.017, 0.077]}},
              "skid_m>0.05": {"probability": 1.0, "interval": [0.6, 1.0], "resolved": True}}
    result = {"study": {"engine": "analytic-unilateral", "mujoco_engine": "mujoco-ratchet",
                        "dists": ["F_r1=normal:1:0.1", "F_r2=normal:1:0.1"], "samples": 200, "mujoco_samples": 10},
              "rows": rows, "metrics": {"energy_per_metre_j_m": entry}, "events": events}
    words = {"metrics": {"energy_per_metre_j_m": key_words("energy_per_metre_j_m")},
             "events": {e: event_words(e) for e in events},
             "engines": {"analytic-unilateral": "analytic one-way clutches", "mujoco-ratchet": "MuJoCo ratchet"}}
    fig = uncertainty_figure(result, words)
    figure_checks.assert_reads_right(fig)
    assert fig.axes[0].get_xlabel() == "energy per metre [J/m]"
    assert [t.get_text() for t in fig.axes[2].get_yticklabels()] == ["slides back (travel < 0 m)",
                                                                     "larger backward skid > 0.05 m"]
    assert not [t for t in figure_checks._shown_texts(fig) if "P(metric" in t.get_text()]


def test_calibration_figure_gives_each_estimate_to_its_intervals_digits_with_its_unit():
    """calibration.png's title read 'F_r1 = 1.301 [1.2996, 1.3025], F_r2 = 0.79834 [0.79546, 0.80122]': 4 and 5
    digits, no units. Each estimate now to the decimals its interval's half-width needs (two significant digits),
    value and bounds alike, in its unit."""
    from ipir_mujoco.report.calibration_figure import calibration_figure, estimate_text
    from ipir_mujoco.studies.measured import Measured

    assert estimate_text(1.30102, [1.29957, 1.30247], "N") == "1.3010 N [1.2996, 1.3025]"
    assert estimate_text(0.79834, [0.795457, 0.801224], "N") == "0.7983 N [0.7955, 0.8012]"
    assert estimate_text(0.01, [-0.0188555, 0.0388555], "kg m^2") == "0.010 kg m^2 [-0.019, 0.039]"
    t = np.linspace(0.0, 1.0, 120)
    model = {"x1": 0.9 * t**2, "phi": 46 * t**2}
    rng = np.random.default_rng(1)
    measured = Measured("noisy.csv", t, {c: v + rng.normal(0, 0.01 * v.max(), t.size) for c, v in model.items()})
    result = {"engine": "analytic-unilateral", "data": "noisy.csv", "model": model, "not_identifiable": [],
              "residuals": {c: (model[c] - measured.columns[c]) / (0.01 * model[c].max()) for c in model},
              "noise": {c: 0.01 * model[c].max() for c in model}, "residual_rms": {c: 0.01 * model[c].max() for c in model},
              "estimates": {"F_r1": {"value": 1.30102, "interval": [1.29957, 1.30247]},
                            "F_r2": {"value": 0.79834, "interval": [0.795457, 0.801224]}}}
    fig = calibration_figure(result, measured)
    figure_checks.assert_reads_right(fig)
    assert "F_r1 = 1.3010 N [1.2996, 1.3025], F_r2 = 0.7983 N [0.7955, 0.8012]" in fig.get_suptitle()
