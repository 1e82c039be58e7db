"""MuJoCo's compliant one-way clutch: the force MuJoCo applies is the clutch's definition, the run agrees
with the analytic compliant clutch, it tends to MuJoCo's own rigid ratchet, and its energy audit closes."""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.core.cycles import cycles, travel
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.run.batch import run_ratchet_batch
from ipir_mujoco.engine.controllers.compliant import CompliantClutches
from ipir_mujoco.engine.builders.model import (FRONT_CLUTCH, FRONT_SLIDE, MOTOR, REAR_CLUTCH, REAR_SLIDE, SolverSettings,
                                      build_model, dof_address, drive_control, set_closed_loop_state)
from ipir_mujoco.engine.loop.monitor import RESIDUAL_TOL
from ipir_mujoco.engine.builders.grip_model import COMPLIANT_CARRIAGE_SHARE
from ipir_mujoco.engine.modelkinds.timestep import CLUTCH_SHARE, choose_settings, clutch_rate

EPS = np.finfo(float).eps


def mujoco_run(params, t_end, timestep, **options):
    """A MuJoCo run at a given timestep, sampled at every step (a clutch force peaks between coarser samples)."""
    return simulate_mujoco(params, "unilateral", "ratchet", t_end, dt_out=timestep,
                           settings=SolverSettings(timestep=timestep), **options)

from cli_run import run_cli


def analytic_run(params, t_end):
    """The analytic compliant clutch, sampled finely enough that a sampled peak of the fastest clutch
    oscillation is within (omega dt_out)^2 / 8 < 2e-5 of the true one (dt_out <= period / 500)."""
    dt_out = min(1e-5, 2 * math.pi / clutch_rate(params) / 500)
    return analytic.simulate(params, "exact", "unilateral", t_end, dt_out=dt_out)


# --- 1. the force MuJoCo applies is k * overlap + c * speed, and nothing inside the play ----------------------------

def test_mujoco_applies_exactly_the_clutch_force_and_nothing_inside_the_play():
    """Stepping the model by hand, reading MuJoCo's own arrays before each step's integration:
    ``actuator_force`` and ``qfrc_actuator`` (what the clutch applies to the slide) against the definition,
    with the overlap computed here from the module's positions alone (its running maximum less the
    backlash), and k, c from the parameter set. Damping c = 300 N s/m makes every clutch state occur at
    step starts: engaged, clipped (the damper would pull) and, inside the play, approaching the anchor so
    fast that an always-on damper would already push. Round-off: MuJoCo forms k ctrl - k x - c v, the
    definition k (a - x) - c v: a few eps of the largest term, k max|x| (x up to ~0.4 m here)."""
    params = RobotParams(clutch_stiffness=1e6, clutch_damping=300.0, clutch_backlash=5e-4)
    k, c, delta = params.clutch_stiffness, params.clutch_damping, params.clutch_backlash
    settings = SolverSettings(timestep=1e-4)
    model = build_model(params, settings)
    data = mujoco.MjData(model)
    set_closed_loop_state(model, data, params)
    clutch = CompliantClutches(model, data, params)
    data.ctrl[model.actuator(MOTOR).id] = drive_control(params)
    mujoco.mj_forward(model, data)  # as the engine starts a run
    acts = [model.actuator(n).id for n in (REAR_CLUTCH, FRONT_CLUTCH)]
    va = [dof_address(model, n) for n in (REAR_SLIDE, FRONT_SLIDE)]
    rows = []
    for _ in range(4000):  # 0.4 s: the first stroke and the engagements of the second
        clutch.before_step()
        mujoco.mj_step(model, data)
        # what MuJoCo computed at the step's start: positions, speeds, actuator and generalized forces
        rows.append([*data.actuator_length[acts], *data.actuator_velocity[acts], *data.actuator_force[acts],
                     *data.qfrc_actuator[va], *data.qfrc_passive[va]])
    rows = np.array(rows)
    counts = {}
    for i in (0, 1):
        x, v, force, applied, passive = rows[:, i], rows[:, 2 + i], rows[:, 4 + i], rows[:, 6 + i], rows[:, 8 + i]
        overlap = np.maximum.accumulate(x) - delta - x  # x: the module's slide position at each step's start
        push = k * overlap - c * v
        engaged, clipped = (overlap > 0) & (push > 0), (overlap > 0) & (push <= 0)
        inside, eager = overlap <= 0, (overlap <= 0) & (push > 0)  # eager: an always-on damper would push
        roundoff = 4 * EPS * (k * np.abs(x).max() * 2 + c * np.abs(v))
        np.testing.assert_array_less(np.abs(force[engaged] - push[engaged]), roundoff[engaged] + 1e-300)
        assert np.all(force[clipped] == 0.0) and np.all(force[inside] == 0.0)  # exactly nothing
        # the force reaches the module's slide as it is, and no passive spring or damper hides anywhere
        np.testing.assert_array_equal(applied, force)
        assert np.all(passive == 0.0)
        counts[i] = (engaged.sum(), clipped.sum(), eager.sum())
    for i, (engaged, clipped, eager) in counts.items():
        assert engaged > 50 and clipped >= 3 and eager >= 3, (i, counts)
    # the engine's series holds these same forces, each at its sample's own state (sample n = state n)
    series = mujoco_run(params, 0.4, 1e-4).series
    for i, column in enumerate(("lambda1", "lambda2")):
        np.testing.assert_allclose(series[column][:len(rows)], rows[:, 4 + i], rtol=1e-9, atol=1e-9)


# --- 2. analytic and MuJoCo agree at the same finite stiffness and backlash ------------------------------------------

def agreement(params, t_end):
    """(analytic run, MuJoCo at its automatic step h, MuJoCo at h / 2, h)."""
    h = choose_settings(params, t_end, 1e-4)[0].timestep  # the engine's own step for a 1e-4 s output grid
    return analytic_run(params, t_end), mujoco_run(params, t_end, h), mujoco_run(params, t_end, h / 2), h


def assert_agree(name, reference, value, value_half, allowance=0.0):
    """MuJoCo's step is first order: its error at h is about 2 |f(h) - f(h/2)| (Richardson); allow 1.5x that,
    plus the analytic solver's (rtol 1e-10) and ``allowance`` (relative) for what no Richardson estimate sees."""
    error = abs(value - reference)
    bound = 1.5 * 2 * abs(value - value_half) + (1e-8 + allowance) * abs(reference)
    assert error <= bound, (name, value, reference, error, bound)
    return error / abs(reference)


def impact_allowance(params, h):
    """What the discrete impact adds to a peak clutch force, relative: the spring first acts at the first step
    start behind the anchor, which changes the energy the step conserves by up to (omega h)^2 / 4 of the
    impact's (peak force: half that), and the largest sampled force lies within (omega h)^2 / 8 of the turning
    point's. Neither is a smooth function of h (it depends on where within a step the contact falls), so
    Richardson cannot estimate it. omega <= clutch_rate (the bound the timestep rule uses)."""
    return 0.25 * (clutch_rate(params) * h) ** 2


@pytest.mark.parametrize("k,backlash", [(1e5, 0.0), (1e6, 0.0), (1e5, 1e-3), (1e6, 1e-3), (1e7, 1e-3)])
def test_agrees_with_the_analytic_compliant_clutch_at_the_papers_start(k, backlash):
    """The paper's case from rest, 0.4 s: the first stroke, the first engagement of each clutch (an impact at
    0.257 s with 1 mm of play) and the second stroke. Revolutions, travel and the peak clutch force agree
    within the Richardson bound of MuJoCo's first-order step; the peak also within the discrete impact's
    allowance. An impact's peak is about Q + sqrt(Q^2 + k m v0^2) (the analytic tests derive it), so its
    relative error is at most the relative error of the impact speed v0 (d log F / d log v0 <= 1), a
    smooth first-order error that the Richardson term covers. And the acceptance's figures: within 0.1 %."""
    params = RobotParams(clutch_stiffness=k, clutch_backlash=backlash)
    an, mj, half, h = agreement(params, 0.4)
    assert h <= CLUTCH_SHARE / clutch_rate(params) * (1 + 1e-12)
    errors = {
        "revolutions": assert_agree("revolutions", an.summary["revolutions"], mj.summary["revolutions"],
                                    half.summary["revolutions"]),
        "travel": assert_agree("travel", travel(an.series)[-1], travel(mj.series)[-1], travel(half.series)[-1]),
        "peak": assert_agree("peak", an.summary["peak_clutch_force_n"], mj.summary["peak_clutch_force_n"],
                             half.summary["peak_clutch_force_n"], impact_allowance(params, h)),
    }
    assert max(errors.values()) < 1e-3, errors
    assert mj.accuracy["ok"] and mj.settings["clutch_model"] == "compliant"


def test_agrees_with_the_analytic_compliant_clutch_at_the_default_motors_cruise():
    """The default motor reaches cruise in ~1.5 s (per-revolution peaks settle to 1e-3 by the 6th
    revolution): over 2 s the revolutions, travel and every revolution's peak engagement force agree
    (1 mm of play: an impact every revolution)."""
    params = RobotParams(drive="motor", clutch_stiffness=1e6, clutch_backlash=1e-3)
    an, mj, half, h = agreement(params, 2.0)
    errors = [assert_agree("revolutions", an.summary["revolutions"], mj.summary["revolutions"],
                           half.summary["revolutions"]),
              assert_agree("travel", travel(an.series)[-1], travel(mj.series)[-1], travel(half.series)[-1])]
    peaks = [[c.peak_clutch_force_n for c in cycles(run.series)] for run in (an, mj, half)]
    assert len(peaks[0]) == len(peaks[1]) == len(peaks[2]) >= 6
    assert abs(peaks[0][-1] / peaks[0][-2] - 1) < 1e-3  # at cruise: the last two revolutions' peaks agree
    for j, (a, m, m2) in enumerate(zip(*peaks)):
        errors.append(assert_agree(f"peak of revolution {j + 1}", a, m, m2, impact_allowance(params, h)))
    assert max(errors) < 1e-3, errors


# --- 3. as k grows (no backlash) the compliant clutch tends to MuJoCo's own rigid ratchet -----------------------------

def test_tends_to_mujocos_rigid_ratchet_at_rate_one_over_k():
    """No backlash: a held module sits R/k behind its anchor and every difference from the rigid clutch is
    C/k (the analytic tests derive it): log-log slope -1. All runs share one step (2.5e-5 s: omega h <= 0.08
    up to 1e7 N/m), so the ratchet's and the springs' stepping errors, ~1e-4 of the revolutions each, are
    alike and leave the 1/k law visible down to 1e-7 of a revolution; band +-0.1 as in the analytic test
    (the O(1/k^2) share moves the slope by < 0.01). At 1e7 N/m the difference is of order R / (k 2r):
    below 1e-4 of the figures."""
    t_end, settings = 0.15, SolverSettings(timestep=2.5e-5)
    rigid = simulate_mujoco(RobotParams(), "unilateral", "ratchet", t_end, settings=settings, dt_out=1e-3)
    stiffness = np.array([1e5, 1e6, 1e7])
    differences = []
    for k in stiffness:
        run = simulate_mujoco(RobotParams(clutch_stiffness=k), "unilateral", "ratchet", t_end, settings=settings,
                              dt_out=1e-3)
        differences.append((abs(run.summary["revolutions"] - rigid.summary["revolutions"]),
                            abs(travel(run.series)[-1] - travel(rigid.series)[-1])))
    differences = np.array(differences)
    for column, name in ((0, "revolutions"), (1, "travel")):
        slope = np.polyfit(np.log10(stiffness), np.log10(differences[:, column]), 1)[0]
        assert -1.1 < slope < -0.9, (name, slope, differences[:, column])
    assert differences[-1, 0] < 1e-4 * rigid.summary["revolutions"]
    assert differences[-1, 1] < 1e-4 * travel(rigid.series)[-1]


# --- 4. the energy audit closes with the spring's energy and the damper's dissipation --------------------------------

def test_energy_audit_closes_with_the_clutch_spring_and_damper():
    """Motor, a 20 deg climb, damping and play: every term of the audit is at work. MuJoCo's residual
    (what the stepping and the soft loop and friction rows took, once the springs' energy and the dampers'
    dissipation are counted) stays within the accuracy monitor's tolerance all run long and at the end;
    the dissipation agrees with the analytic model's within the Richardson bound of MuJoCo's step."""
    params = RobotParams(drive="motor", incline=20.0, clutch_stiffness=1e6, clutch_damping=300.0,
                         clutch_backlash=5e-4)
    an = analytic.simulate(params, "exact", "unilateral", 0.5)
    mj = simulate_mujoco(params, "unilateral", "ratchet", 0.5)
    half = simulate_mujoco(params, "unilateral", "ratchet", 0.5, settings=SolverSettings(timestep=5e-5))
    e, s = mj.energy, mj.series
    assert abs(mj.accuracy["residual_ratio"]) < RESIDUAL_TOL and mj.accuracy["ok"]
    assert abs(e["residual_j"]) < RESIDUAL_TOL * e["motor_work_j"]
    terms = e["motor_work_j"] - e["kinetic_j"] - e["potential_j"] - e["friction_j"] - e["clutch_spring_j"]
    assert e["residual_j"] == pytest.approx(terms - e["clutch_damper_j"], abs=1e-12)
    assert e["clutch_damper_j"] > 1e-3 * e["motor_work_j"] and e["potential_j"] > 0.1 * e["motor_work_j"]
    assert s["clutch_spring_energy"].max() > 1e-4 * e["motor_work_j"]  # the springs really store energy
    np.testing.assert_allclose(s["clutch_spring_energy"], 0.5 * params.clutch_stiffness * (
        np.maximum(s["clutch_overlap1"], 0) ** 2 + np.maximum(s["clutch_overlap2"], 0) ** 2), rtol=1e-12)
    for column in ("friction_work", "clutch_damper_work"):
        assert np.all(np.diff(s[column]) >= -1e-12 * e["motor_work_j"]), column  # dissipation never shrinks
    assert_agree("damper work", an.energy["clutch_damper_j"], e["clutch_damper_j"], half.energy["clutch_damper_j"])
    # the per-revolution audit of core.cycles sees the clutch energy too
    assert mj.summary["cycle_energy_residual_j"] is not None


def test_the_monitor_counts_each_spring_as_the_step_conserves_it():
    """A stiff clutch with 5 mm of play at a coarse step (omega h = 0.16): while an impact goes on, the
    physical spring energy 1/2 k d^2 and MuJoCo's kinetic energy disagree with the work done by up to
    1/2 omega h of the impact's energy, and agree again once it is over (the semi-implicit step conserves
    1/2 m v^2 + 1/2 k d^2 + 1/2 h k d v exactly on a linear spring). Counted so, the monitor sees the
    stepping's real error, not that swing: it stays within half its tolerance where the physical form
    swings past it (the swing measured here: 2.8e-3; the monitor's figure: 3e-4)."""
    params = RobotParams(clutch_stiffness=1e7, clutch_backlash=5e-3)
    run = mujoco_run(params, 0.3, 5e-5, accuracy="warn")
    s = run.series
    physical = (s["motor_work"] - s["friction_work"] - s["clutch_damper_work"] - (s["kinetic"] - s["kinetic"][0])
                - s["potential"] - (s["clutch_spring_energy"] - s["clutch_spring_energy"][0]))
    scale = np.maximum(np.abs(s["motor_work"]), 2 * math.pi * params.M)  # the monitor's scale here
    swing = np.abs(physical / scale).max()
    assert swing > RESIDUAL_TOL and abs(run.accuracy["residual_ratio"]) < 0.5 * RESIDUAL_TOL < swing / 4
    assert abs(physical[-1] / scale[-1]) < 0.5 * RESIDUAL_TOL  # no impact under way at the end


# --- 5. what stays refused, the timestep rule, and the command line --------------------------------------------------

def test_unmodelled_combinations_are_refused_with_one_line():
    compliant = RobotParams(clutch_stiffness=1e6)
    for implementation in ("lock", "none"):
        with pytest.raises(ParameterError, match=f"clutch_stiffness=1000000.0 N/m with the MuJoCo "
                                                 f"'{implementation}' clutch: only the ratchet"):
            simulate_mujoco(compliant, "unilateral", implementation, 0.01)
    with pytest.raises(ParameterError, match="--clutch kinematic with the ratchet"):
        simulate_mujoco(compliant, "kinematic", "ratchet", 0.01)
    for name in ("clutch_damping", "clutch_backlash"):
        with pytest.raises(ParameterError, match=f"{name}=0.001 needs a finite clutch_stiffness"):
            simulate_mujoco(RobotParams(**{name: 1e-3}), "unilateral", "ratchet", 0.01)
    refused, kept = run_ratchet_batch([compliant, RobotParams()], 0.01, dt_out=1e-3, nthread=1)
    assert "batched runs have rigid ratchets only" in refused["error"] and "\n" not in refused["error"]
    assert "error" not in kept


def test_the_timestep_resolves_the_clutch_spring():
    """dt <= 0.1 sqrt(min(m1, m2) / k): 63 steps per period of the fastest clutch oscillation; a stiffness
    that would need less than 1e-6 s is refused up front, naming the value and the largest allowed here."""
    for k, m2 in ((1e7, 1.0), (1e8, 0.25), (1e5, 1.0)):
        params = RobotParams(clutch_stiffness=k, m2=m2)
        settings, why = choose_settings(params, 0.5, 1e-4)
        assert why["clutch_s"] == pytest.approx(0.1 * math.sqrt(min(params.m1, m2) / k))
        assert settings.timestep <= why["clutch_s"] * (1 + 1e-12) and settings.timestep <= why["default_s"]
    with pytest.raises(ParameterError, match=r"clutch_stiffness=1e\+11 N/m: MuJoCo would need a timestep of "
                                             r"3.2e-07 s .*\(a stiffness up to 1e\+10 N/m here"):
        choose_settings(RobotParams(clutch_stiffness=1e11), 0.5, 1e-4)


def test_on_finite_grip_the_timestep_resolves_the_skidding_carriage_at_its_own_share():
    """With finite grip the spring also rings on the carriage (1e-3 of its module's mass): dt <= 0.3 / omega_s,
    omega_s = sqrt(k (1/m + 1/m_c)), which is 6.7 times inside the explicit spring's stability (omega_s dt < 2)
    and looser than the module's own 0.1 / omega_c would be on it; the refusal names the stiffness that fits."""
    for k, m2 in ((1e6, 1.0), (1e5, 0.25), (1e4, 1.0)):
        params = RobotParams(clutch_stiffness=k, m2=m2, mu_wall=0.5)
        lightest = min(params.m1, m2)
        omega_s = math.sqrt(k * (1 / lightest + 1 / (COMPLIANT_CARRIAGE_SHARE * lightest)))
        settings, why = choose_settings(params, 0.5, 1e-4)
        assert why["clutch_s"] == pytest.approx(min(0.1 * math.sqrt(lightest / k), 0.3 / omega_s))
        assert omega_s * settings.timestep <= 0.3 * (1 + 1e-12) < 2
    with pytest.raises(ParameterError, match=r"clutch_stiffness=1e\+09 N/m: .*on the skidding carriage.*"
                                             r"\(a stiffness up to 8.99e\+07 N/m here"):
        choose_settings(RobotParams(clutch_stiffness=1e9, mu_wall=0.5), 0.5, 1e-4)



def test_cli_runs_the_compliant_clutch_in_mujoco(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, "simulate", "--engine", "mujoco", "--clutch", "unilateral", "--t-end", "0.1",
                             "--set", "clutch_stiffness=1e6", "--set", "clutch_backlash=1e-3", "--json")
    assert code == 0 and err == ""
    record = json.loads(out)
    assert record["settings"]["clutch_model"] == "compliant" and record["settings"]["mujoco_clutch"] == "ratchet"
    assert {"clutch_spring_j", "clutch_damper_j"} <= set(record["summary"]["energy"])
    for argv, fragment in ((["--mujoco-clutch", "lock", "--set", "clutch_stiffness=1e6"], "'lock' clutch"),
                           (["--set", "clutch_stiffness=1e12"], "clutch_stiffness=1e+12")):
        code, out, err = run_cli(capsys, "simulate", "--engine", "mujoco", "--clutch", "unilateral", *argv)
        assert code == 2 and out == "" and err.count("\n") == 1 and fragment in err, err
    assert list(tmp_path.iterdir()) == []
