"""The engagement-load study: its rows agree between engines, tend to the rigid clutch, follow the physics of
an engagement (a finite limit without play, an impact ~ sqrt(k) with it), its figure holds the rows, and its
command line refuses bad input in one line."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.core.results import Mode
from ipir_mujoco.engine.modelkinds.timestep import clutch_rate
from ipir_mujoco.report.clutch_section import study_figure
from ipir_mujoco.studies.clutch_study import OperatingPoint, run_study

import figure_checks
from cli_run import run_cli

# the paper's start-up up to the first engagement of each clutch (the rear one at 0.245 s, with 1 mm of play
# at 0.257 s): the same case the analytic tests derive the engagement laws on
FIRST = {"first": OperatingPoint("first", "the first engagements of the paper's start-up", "torque", 0.3, False)}
STIFFNESS = (1e5, 1e6, 1e7)


@pytest.fixture(scope="module")
def first_engagements():
    return run_study(RobotParams(), designs=[(k, b) for k in STIFFNESS for b in (0.0, 1e-3)], points=("first",),
                     points_table=FIRST, workers=2)


@pytest.fixture(scope="module")
def cruise():
    # the design tests/test_mujoco_compliant.py holds at cruise over 2 s
    return run_study(RobotParams(), designs=[(1e6, 1e-3)], points=("cruise",), workers=2)


def rows(study, backlash):
    return sorted((r for r in study["rows"] if r["clutch_backlash_m"] == backlash),
                  key=lambda r: r["clutch_stiffness_n_m"])


@pytest.mark.slow
def test_rows_agree_between_the_engines(first_engagements, cruise):
    """The tolerance tests/test_mujoco_compliant.py derives and holds at these stiffnesses (1e5..1e7 N/m, 0 and
    1 mm of play, the paper's start and the default motor's cruise, MuJoCo at its automatic step): revolutions,
    travel and peak clutch force within 0.1 % (there within 1.5 x MuJoCo's Richardson estimate plus the
    discrete impact's (omega h)^2 / 4 for a peak, all of which came out below 1e-3). Distance per revolution
    and the steady speed are travel over revolutions and over time."""
    checked = 0
    for study, keys in ((first_engagements, ("revolutions", "distance_per_rev_m", "peak_clutch_force_n")),
                        (cruise, ("revolutions", "distance_per_rev_m", "peak_clutch_force_n", "steady_speed_m_s"))):
        for row in study["rows"]:
            an, mj = row["analytic"], row["mujoco"]
            assert "error" not in an and "error" not in mj, row
            for key in keys:
                assert abs(row["divergence"][key]) < 1e-3, (row["point"], row["clutch_stiffness_n_m"], key,
                                                            row["divergence"][key])
                assert row["divergence"][key] == pytest.approx((mj[key] - an[key]) / abs(an[key]))
                checked += 1
            # the peak as sampled: exact in the analytic model (no damping), within (omega h)^2 / 4 in MuJoCo
            rate = clutch_rate(RobotParams(clutch_stiffness=row["clutch_stiffness_n_m"]))
            assert an["peak_sampling_bound"] == 0.0
            assert mj["peak_sampling_bound"] == pytest.approx((rate * mj["timestep_s"]) ** 2 / 4)
            assert mj["dt_out_s"] == mj["timestep_s"] <= 0.1 / rate * (1 + 1e-12)  # every step sampled
    assert checked == 6 * 3 + 4
    row = cruise["rows"][0]
    for engine in ("analytic", "mujoco"):
        assert row[engine]["energy_per_metre_j_m"] > 0 and row[engine]["steady_speed_m_s"] > 0


def test_a_damped_analytic_peak_does_not_depend_on_the_output_grid():
    """With clutch damping the analytic run locates each force maximum on its dense output (a bounded Brent
    search to sqrt(eps) t), so the study's bound is (omega_c sqrt(eps) t_end)^2, not the grid's
    (omega_c dt_out)^2 / 8 (2e-5 on the study's grid here); a grid 2.5 x coarser, which would read a sampled
    peak up to 1.25e-4 low, reads the same peak within that bound."""
    from ipir_mujoco.studies.clutch_study import Task, design, run_task

    base, point = RobotParams(clutch_damping=30.0), FIRST["first"]
    metrics = run_task(base, point, Task("first", "analytic", 1e5, 0.0))
    params = design(base, point, 1e5, 0.0)
    bound = (clutch_rate(params) * math.sqrt(np.finfo(float).eps) * point.t_end) ** 2
    assert metrics["peak_sampling_bound"] == pytest.approx(bound) and bound < 1e-11
    coarse = analytic.simulate(params, "exact", "unilateral", point.t_end, dt_out=1e-4).series
    peak = max(coarse["lambda1"].max(), coarse["lambda2"].max())
    assert metrics["dt_out_s"] < 1e-4 / 2.5 * (1 + 1e-12)
    assert peak == pytest.approx(metrics["peak_clutch_force_n"], rel=bound, abs=0)


@pytest.mark.slow
def test_the_rigid_limit_is_approached_at_rate_one_over_k(first_engagements):
    """No play: each engine's revolutions differ from its own rigid clutch's (MuJoCo: its ratchet at the same
    step, so the stepping errors cancel) as C/k, the regular perturbation tests/test_compliant_clutch.py and
    tests/test_mujoco_compliant.py derive: log-log slope -1 within their band +-0.1. And the two engines'
    differences are the same law: within 1 % of each other at every stiffness (the ratchet and the compliant
    runs share each step's error only to O(h); 1 % of ~1e-4 rev is far below it)."""
    study = first_engagements
    rigid_an = study["rigid"]["first"]["analytic"]
    rigid_mj = {m["timestep_s"]: m for m in study["rigid"]["first"]["mujoco_by_timestep"]}
    gaps = {"analytic": [], "mujoco": []}
    for row in rows(study, 0.0):
        gaps["analytic"].append(row["analytic"]["revolutions"] - rigid_an["revolutions"])
        gaps["mujoco"].append(row["mujoco"]["revolutions"] - rigid_mj[row["mujoco"]["timestep_s"]]["revolutions"])
    for engine, gap in gaps.items():
        slope = np.polyfit(np.log10(STIFFNESS), np.log10(np.abs(gap)), 1)[0]
        assert -1.1 < slope < -0.9, (engine, slope, gap)
    np.testing.assert_allclose(gaps["mujoco"], gaps["analytic"], rtol=1e-2)


def impact_shares(study, engine):
    """Per stiffness: (peak force F, load Q at the engagement, the engagement record) of the 1 mm runs.

    Q = -m_eff a at the last sample inside the play (what pushed the module back), m_eff = M11 - M12^2 / M22
    (module 1 with the crank free), as in tests/test_compliant_clutch.py."""
    dyn = OneDofDynamics(RobotParams(), "exact")
    out = []
    for row in rows(study, 1e-3):
        run = row[engine]
        hit = run["engagement"]
        assert hit["module"] == 1 and hit["speed_m_s"] > 0.1  # the rear clutch's first impact, a real one
        mt = dyn.mass_terms(hit["phi_rad"])
        m_eff = mt.m11 - mt.m12**2 / mt.m22
        out.append((run["peak_clutch_force_n"], -m_eff * hit["accel_m_s2"], m_eff, hit))
    return out


@pytest.mark.parametrize("engine", ["analytic", "mujoco"])
@pytest.mark.slow
def test_with_play_the_peak_force_is_an_impact_growing_as_sqrt_k(first_engagements, engine):
    """A mass m_eff pressed by a load Q onto a spring at speed v0 peaks at F = Q + sqrt(Q^2 + k m_eff v0^2):
    finite, and its log-log slope in k is 0.5 (1 - Q / (F - Q)), rising to 1/2 as the impact dominates. The
    fitted slope over the grid lies between the local slopes at its ends (each from that run's own F and Q),
    +-0.01 for v0, which the earlier history changes by ~1 % between stiffnesses. The law itself holds to the
    crank's turn during the compression, omega pi/2 sqrt(m_eff / k) (Q and m_eff are held fixed in it), plus,
    for MuJoCo, the step's (omega_c h)^2 / 4 and its sampled engagement state (one step, h a / v0 < 2 %)."""
    found = impact_shares(first_engagements, engine)
    for (force, load, m_eff, hit), row in zip(found, rows(first_engagements, 1e-3)):
        k, v0 = row["clutch_stiffness_n_m"], hit["speed_m_s"]
        assert math.isfinite(force) and force > 2 * load > 0
        predicted = load + math.sqrt(load**2 + k * m_eff * v0**2)
        turned = abs(hit["omega_rad_s"]) * 0.5 * math.pi * math.sqrt(m_eff / k)
        step = 0.0 if engine == "analytic" else (
            row[engine]["peak_sampling_bound"] + abs(hit["accel_m_s2"]) * row[engine]["timestep_s"] / v0)
        assert force == pytest.approx(predicted, rel=turned + step), (k, force, predicted)
    local = [0.5 * (1 - load / (force - load)) for force, load, _, _ in found]
    slope = np.polyfit(np.log10(STIFFNESS), np.log10([f for f, _, _, _ in found]), 1)[0]
    assert min(local) - 0.01 < slope < max(local) + 0.01, (slope, local)
    assert local[-1] > 0.45  # and at 1e7 N/m the impact dominates: nearly sqrt(k)


@pytest.mark.parametrize("engine", ["analytic", "mujoco"])
@pytest.mark.slow
def test_without_play_the_peak_force_tends_to_twice_the_rigid_jump(first_engagements, engine):
    """No play: where the rigid clutch's reaction jumps from 0 to R_jump, the spring takes a suddenly applied load
    R_jump - F_r1 and an undamped spring peaks at twice that, 2 (R_jump - F_r1), for every k; it falls short by the
    load's change during the half period pi sqrt(m / k), a deficit ~ k^-1/2 (tests/test_compliant_clutch.py:
    band +-0.1 on the slope for the next, ~1/k, term). MuJoCo's sampled peak adds at most (omega_c h)^2 / 4 of
    the peak (0.2 N at 1e7 N/m against a deficit of 2.4 N: 0.02 on the slope), inside the band."""
    rigid = analytic.simulate(RobotParams(), "exact", "unilateral", 0.3).series
    first_hold = np.flatnonzero(rigid["mode"] == int(Mode.EXPANSION))[0]
    limit = 2 * (rigid["lambda1"][first_hold] - RobotParams().F_r1)
    deficits = np.array([limit - row[engine]["peak_clutch_force_n"] for row in rows(first_engagements, 0.0)])
    assert np.all(deficits > 0)
    slope = np.polyfit(np.log10(STIFFNESS), np.log10(deficits), 1)[0]
    assert -0.6 < slope < -0.4, (slope, deficits)
    # the study's own scaling record: a force that saturates, against ~1/2 with play
    scaling = {(s["clutch_backlash_m"], s["engine"]): s for s in first_engagements["scaling"]}
    assert scaling[(0.0, engine)]["slope_stiff"] < 0.1 < 0.45 < scaling[(1e-3, engine)]["slope_stiff"]


@pytest.mark.slow
def test_the_analytic_peak_force_is_a_sample_whatever_the_output_grid():
    """Without damping the clutch force k d peaks where the module turns (d' = -v), which ends a segment: the
    peak is sampled exactly on any output grid. With damping it peaks between the turning points; the run
    samples each maximum (located on the dense output), so it too is the same on any grid, to roundoff, and
    within the study's bound (omega_c dt)^2 / 8 = 2e-5 on its grid (a 500th of the fastest clutch period)."""
    def peak(params, dt_out):
        return analytic.simulate(params, "exact", "unilateral", 0.3, dt_out=dt_out).summary["peak_clutch_force_n"]

    params = RobotParams(clutch_stiffness=1e6, clutch_backlash=1e-3)
    assert peak(params, 1e-3) == pytest.approx(peak(params, 2e-6), rel=1e-12)
    damped = params.replace(clutch_damping=100.0)
    grid = 2 * math.pi / clutch_rate(damped) / 500
    fine = peak(damped, grid / 20)
    assert peak(damped, 1e-3) == pytest.approx(fine, rel=1e-9)  # a coarse grid used to miss it by 1e-4 and more
    assert peak(damped, grid) == pytest.approx(fine, rel=(clutch_rate(damped) * grid) ** 2 / 8)


@pytest.mark.slow
def test_the_figure_draws_the_rows_of_both_engines_and_the_rigid_limit(first_engagements, cruise):
    fig = study_figure(first_engagements)
    (ax,) = fig.axes
    lines = {line.get_gid(): line for line in ax.get_lines() if line.get_gid()}
    for backlash in (0.0, 1e-3):
        for engine in ("analytic", "mujoco"):
            line = lines[f"{engine}:{backlash!r}"]
            np.testing.assert_array_equal(line.get_xdata(), STIFFNESS)
            np.testing.assert_array_equal(line.get_ydata(), [r[engine]["peak_clutch_force_n"]
                                                             for r in rows(first_engagements, backlash)])
        assert lines[f"analytic:{backlash!r}"].get_linestyle() == "-"
        assert lines[f"mujoco:{backlash!r}"].get_marker() == "o"
    for engine in ("analytic", "mujoco"):
        marker = lines[f"rigid:{engine}"]
        assert marker.get_xdata()[0] > max(STIFFNESS)  # right of the axis break
        assert marker.get_ydata()[0] == first_engagements["rigid"]["first"][engine]["peak_clutch_force_n"]
    assert ax.get_xscale() == ax.get_yscale() == "log" and "[N/m]" in ax.get_xlabel() and "[N]" in ax.get_ylabel()
    # at cruise both rigid models run under the motor: both markers, at their own peak forces
    (ax,) = study_figure(cruise).axes
    markers = {line.get_gid(): line for line in ax.get_lines() if line.get_gid()}
    for engine in ("analytic", "mujoco"):
        assert markers[f"rigid:{engine}"].get_ydata()[0] == cruise["rigid"]["cruise"][engine]["peak_clutch_force_n"]
    assert not any("rigid analytic" in text.get_text() for text in ax.texts)


@pytest.mark.slow
def test_the_figure_reads_right_its_legend_lists_only_what_is_drawn(first_engagements, cruise):
    """Every legend entry has a drawn artist of its look and every mark drawn an entry, axes have units, no
    note lies over data: on the full grid with marked designs, and where a backlash has one design only (its
    colour keyed by its marker, not a line: an orange marker used to have no entry)."""
    highlight = [{"name": "sprag", "clutch_stiffness": 1e6, "clutch_backlash": 0.0}]
    fig = study_figure(first_engagements, highlight)
    figure_checks.assert_reads_right(fig)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "backlash 1 mm" in labels and "realistic clutches" in labels
    assert any(t.get_text() == "sprag (no play)" for t in fig.axes[0].texts)
    # the cruise study: one design (1e6 N/m, 1 mm): no curve, so its colour keyed by a marker, no analytic line
    fig = study_figure(cruise)
    figure_checks.assert_reads_right(fig)
    legend = fig.legends[0]
    keys = {t.get_text(): h for t, h in zip(legend.get_texts(), legend.legend_handles)}
    assert keys["backlash 1 mm"].get_marker() == "o" and keys["backlash 1 mm"].get_linestyle() == "None"
    assert "analytic compliant clutch (lines)" not in keys and "MuJoCo compliant ratchet (markers)" in keys



@pytest.mark.slow
def test_the_command_writes_its_files_and_prints_the_table(capsys, tmp_path):
    out = tmp_path / "study"
    code, stdout, stderr = run_cli(capsys, "clutch-study", "--stiffness", "1e5", "--backlash", "0,1e-3",
                                   "--points", "startup", "--out", str(out))
    assert code == 0
    assert all(line.startswith("clutch-study: ") for line in stderr.splitlines()) and "[6/6]" in stderr
    assert "peak force [N]" in stdout and "lost/stroke [mm]" in stdout and "the paper's start-up" in stdout
    with open(out / "clutch_study.csv", newline="") as handle:
        table = list(csv.DictReader(handle))
    assert [(r["clutch"], float(r["clutch_backlash_m"])) for r in table] == [
        ("compliant", 0.0), ("compliant", 1e-3), ("rigid", 0.0)]
    study = json.loads((out / "clutch_study.json").read_text())
    for record, row in zip(table, study["rows"]):
        for engine in ("analytic", "mujoco"):
            assert float(record[f"{engine}:peak_clutch_force_n"]) == row[engine]["peak_clutch_force_n"]
    assert table[2]["clutch_stiffness_n_m"] == "inf" and float(table[2]["mujoco:peak_clutch_force_n"]) > 0
    assert (out / "clutch_study.png").stat().st_size > 10_000


@pytest.mark.parametrize("argv,fragment", [
    (["--stiffness", "-1"], "clutch_stiffness=-1.0"),
    (["--stiffness", "nan"], "clutch_stiffness=nan"),
    (["--stiffness", "1e11"], "clutch_stiffness=1e+11 N/m"),
    (["--stiffness", "1e3:1e7"], "--stiffness '1e3:1e7' is malformed"),
    (["--stiffness", "1e3:1e7:0"], "--stiffness N=0"),
    (["--backlash", "0.03"], "clutch_backlash=0.03"),
    (["--backlash=-1e-3"], "clutch_backlash=-0.001"),
    (["--points", "cruise,walk"], "unknown operating point walk"),
    (["--set", "clutch_stiffness=1e6"], "--stiffness"),
    (["--set", "drive=motor"], "drive='motor'"),
    (["--workers", "0"], "workers=0"),
])
def test_bad_input_exits_2_with_one_line_naming_the_value(capsys, tmp_path, argv, fragment):
    out = tmp_path / "study"
    code, stdout, stderr = run_cli(capsys, "clutch-study", "--quick", "--out", str(out), *argv)
    assert code == 2 and stdout == "" and stderr.count("\n") == 1 and fragment in stderr, stderr
    assert not out.exists() and list(tmp_path.iterdir()) == []

