"""Compliant one-way clutches (stiffness, damping, backlash): the limit of the rigid clutch, the energy
audit, the travel the backlash costs, the engagement force, and bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ipir_mujoco import analytic
from ipir_mujoco.analytic import ParameterError, RobotParams, SimulationError
from ipir_mujoco.core.cycles import cycles
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.core.results import Mode

from cli_run import run_cli


def compliant(params, t_end, **options):
    return analytic.simulate(params, "exact", "unilateral", t_end, **options)


def travel(summary):
    return 0.5 * (summary["x1_final"] + summary["x2_final"])


@pytest.mark.slow
def test_converges_to_the_rigid_one_way_clutch_at_rate_one_over_k():
    """With no backlash a module meets its clutch at zero speed (the rigid model's velocity reaches zero
    continuously: no impact). The compliant model is then a regular perturbation of the rigid one in
    1/k: a held module sits R/k behind its anchor, the clutch oscillation a load step starts has a
    force amplitude of order R but a displacement of order R/k, the spring stores R^2 / 2k. So every
    error is C/k: log-log slope -1. Band +-0.1: the O(1/k^2) share, measured 34 % at k = 1e4 (the
    error falls 13.4x from 1e4 to 1e5, not 10x), is 3.4 % at 1e5 and moves the slope over two decades
    by < 0.01; the rest covers the phase of the undamped clutch oscillation at t_end (also ~1/k)."""
    t_end = 0.15  # the first stroke and the start of the second
    rigid = analytic.simulate(RobotParams(), "exact", "unilateral", t_end).summary
    stiffness = np.array([1e5, 1e6, 1e7])
    errors = []
    for k in stiffness:
        s = compliant(RobotParams(clutch_stiffness=k), t_end).summary
        errors.append((abs(s["revolutions"] - rigid["revolutions"]), abs(travel(s) - travel(rigid))))
    errors = np.array(errors)
    for column, name in ((0, "revolutions"), (1, "travel")):
        slope = np.polyfit(np.log10(stiffness), np.log10(errors[:, column]), 1)[0]
        assert -1.1 < slope < -0.9, (name, slope, errors[:, column])
    # and the limit itself: at 1e7 N/m the relative error is of order R / (k 2r) ~ 40 N / (1e7 N/m 0.1 m)
    assert errors[-1, 0] < 1e-4 * rigid["revolutions"] and errors[-1, 1] < 1e-4 * travel(rigid)


@pytest.fixture(scope="module")
def damped_run():
    """Damping and backlash: every clutch state (tracking, free, engaged, clipped) occurs."""
    params = RobotParams(clutch_stiffness=1e6, clutch_damping=50.0, clutch_backlash=5e-4)
    return compliant(params, 0.5, dt_out=1e-5)  # fine samples for the momentum balance


def test_the_mode_says_held_exactly_where_a_clutch_pushes_in_both_engines():
    """With compliant clutches a module counts as held only while its clutch pushes (docs/model.md, Modes).
    Uphill with the play open at the start, module 1 stands on its resistance while module 2 slides back
    into its play for 11 ms: neither clutch pushes, so the mode is 3, not 2 (rear held). Read against each
    engine's own clutch forces at every sample: a module labelled unheld has a clutch force of exactly 0;
    one whose clutch pushes by more than 1e-6 N (far above the engagement hysteresis, k x 1 pm = 1e-6 N
    here, where a force starts from 0) is labelled held."""
    from ipir_mujoco.engine import simulate_mujoco

    p = RobotParams(M=0.4, incline=25, clutch_stiffness=1e6, clutch_damping=20, clutch_backlash=5e-4, phi0=0.7)
    runs = (compliant(p, 0.06, dt_out=1e-4), simulate_mujoco(p, "unilateral", "ratchet", 0.06, dt_out=1e-4))
    for run in runs:
        s = run.series
        mode = s["mode"].astype(int)
        held = (np.isin(mode, [Mode.EXPANSION, Mode.BOTH_LOCKED]), np.isin(mode, [Mode.CONTRACTION, Mode.BOTH_LOCKED]))
        for i, force in enumerate((s["lambda1"], s["lambda2"])):
            assert np.all(force[~held[i]] == 0.0), (run.engine, i)
            assert np.all(held[i][force > 1e-6]), (run.engine, i)
        start = s["t"] < 0.011
        assert np.all(mode[start] == Mode.BOTH_MOVING) and s["v2"][start][-1] < 0, run.engine
        assert np.any(mode == Mode.CONTRACTION), run.engine  # module 2's clutch takes the load in the end


def test_energy_audit_closes_with_the_clutch_spring_and_damper(damped_run):
    e, s = damped_run.energy, damped_run.series
    # the audit's terms are integrated states (rtol 1e-10) summed over ~1e3 steps and ~1e2 events:
    # 1e-7 of the motor work is far above that sum and far below any term that matters
    assert abs(e["residual_j"]) < 1e-7 * e["motor_work_j"]
    assert e["clutch_damper_j"] > 1e-4 * e["motor_work_j"]  # the damper is really at work
    assert s["clutch_spring_energy"].max() > 1e-6 * e["motor_work_j"]  # and the spring
    for column in ("friction_work", "clutch_damper_work", "motor_work"):
        assert np.all(np.diff(s[column]) >= -1e-12), column  # cumulative dissipation never shrinks
    residual = damped_run.summary["cycle_energy_residual_j"]
    assert residual is not None and residual < 1e-7 * e["motor_work_j"]


def test_energy_audit_closes_with_gravity_and_the_motor():
    run = compliant(RobotParams(clutch_stiffness=1e5, drive="motor", incline=20.0), 0.5)
    e = run.energy
    assert e["potential_j"] > 0.01 * e["motor_work_j"]  # climbing: gravity takes a real share
    assert abs(e["residual_j"]) < 1e-7 * e["motor_work_j"]


def test_clutch_force_is_the_spring_and_damper_and_only_pushes(damped_run):
    s, p = damped_run.series, damped_run.params
    k, c = p.clutch_stiffness, p.clutch_damping
    for i, (lam, d, v) in enumerate((("lambda1", "clutch_overlap1", "v1"), ("lambda2", "clutch_overlap2", "v2"))):
        force, overlap, speed = s[lam], s[d], s[v]
        assert force.min() >= 0  # never pulls
        pushing = force > 0
        assert pushing.any() and np.all(overlap[pushing] > 0)  # only beyond the backlash
        # where it pushes it is k d - c v (the samples are the regime's own formula: round-off only)
        np.testing.assert_allclose(force[pushing], k * overlap[pushing] - c * speed[pushing],
                                   rtol=1e-9, atol=1e-9 * k * p.r)
        # the resistance is Coulomb: |friction| <= F_r, and -F_r sign(v) while sliding
        F = (p.F_r1, p.F_r2)[i]
        friction = s[f"resistance{i + 1}"]
        assert np.all(np.abs(friction) <= F * (1 + 1e-9))
        sliding = np.abs(speed) > 1e-6
        np.testing.assert_allclose(friction[sliding], -F * np.sign(speed[sliding]))
    # a module can move backward a little now: by its backlash plus the spring's compression
    assert s["v1"].min() < -1e-3 and s["v2"].min() < -1e-3
    lost = np.maximum.accumulate(s["x1"]) - s["x1"]
    assert lost.max() > p.clutch_backlash and lost.max() < p.clutch_backlash + s["lambda1"].max() / k * 1.01


def test_the_reported_forces_are_the_rate_of_change_of_momentum(damped_run):
    """Along the pipe only the clutch forces, the resistances (a stuck module's too: the force its
    friction must give, solved with the accelerations) and gravity act on the robot, so their impulse
    is the change of its momentum p = M11 v1 + M12 omega: an independent check of those forces, which
    the energy audit cannot give (a stuck module's force does no work). Tolerance: the trapezoid
    rule's error, dt^2 / 12 |F''| over the time the clutches ring: at dt = 1e-5 s, with |F''| ~
    (k / m) 100 N = 1e8 N/s^2 for ~0.05 s, about 4e-5 N s."""
    s, p = damped_run.series, damped_run.params
    mt = OneDofDynamics(p, "exact").mass_terms(s["phi"])
    momentum = mt.m11 * s["v1"] + mt.m12 * s["omega"]
    force = s["lambda1"] + s["lambda2"] + s["resistance1"] + s["resistance2"]  # horizontal pipe: no gravity
    impulse = np.concatenate([[0.0], np.cumsum(0.5 * (force[1:] + force[:-1]) * np.diff(s["t"]))])
    assert np.abs(momentum - momentum[0] - impulse).max() < 1e-4
    assert np.ptp(momentum) > 1.0  # against a momentum that changes by 1.9 N s


@pytest.mark.parametrize("F_r2,engagements", [(2.0, 1), (1.0, 2)])
def test_backlash_costs_its_play_at_every_engagement_at_low_speed(F_r2, engagements):
    """Slow crank (a motor with a 4 rad/s no-load speed). In expansion the rod pushes the rear module
    back and the front one forward with a force P; in contraction it pulls them together. A module
    pushed back slides back through its play delta before its clutch holds, and the gap the crank
    sets is then shared: the other module advances delta less. So each engagement costs delta of
    travel, and each module advances 2r - engagements * delta per revolution. With F_r1 = 1 N <
    F_r2 = 2 N only the rear clutch engages (in contraction the rear module slides on before the
    front one can be pulled back): one engagement per revolution. With F_r1 = F_r2 both thresholds
    are reached together and the force that accelerates the advancing module tips the held one back:
    both clutches engage, two per revolution. Tolerance: a module held by its clutch spring and
    friction comes to rest anywhere |k d - P| <= F_r, an uncertainty of 2 F_r / k per engagement in
    each run; the loss is a difference of two runs: 4 F_r engagements / k (4..8 um)."""
    base = dict(drive="motor", M_stall=0.5, omega_noload=4.0, F_r2=F_r2, clutch_stiffness=1e6)
    per_rev = {}
    for delta in (0.0, 1e-3, 2e-3):
        found = cycles(compliant(RobotParams(clutch_backlash=delta, **base), 3.8, dt_out=1e-3).series)
        assert len(found) == 2
        per_rev[delta] = np.array([c.distance_m for c in found])
    tolerance = 4 * 1.0 * engagements / base["clutch_stiffness"]
    for delta in (1e-3, 2e-3):
        np.testing.assert_allclose(per_rev[0.0] - per_rev[delta], engagements * delta, atol=tolerance)
    np.testing.assert_allclose(per_rev[0.0], 2 * 0.05, atol=tolerance)  # and without play: the stroke 2r


def test_without_backlash_the_peak_force_tends_to_twice_the_rigid_jump():
    """No backlash, no damping: where the rigid clutch's reaction jumps from 0 to R_jump (at zero
    speed, no impact), the compliant module slides back against its friction and the spring takes a
    suddenly applied load R_jump - F_r1: an undamped spring then peaks at twice the static force,
    2 (R_jump - F_r1), finite for every k. It falls short by the load's change during the half period
    pi sqrt(m/k): the deficit scales as k^-1/2. Band +-0.1 on the slope: the next term (~1/k, as in
    the convergence test) shifts the two-decade slope by < 0.04 (the deficit ratio from 1e5 to 1e6 is
    2.7 instead of sqrt(10))."""
    t_end = 0.3  # the first engagement of the rear clutch is at 0.245 s
    rigid = analytic.simulate(RobotParams(), "exact", "unilateral", t_end).series
    first_hold = np.flatnonzero(rigid["mode"] == int(Mode.EXPANSION))[0]
    limit = 2 * (rigid["lambda1"][first_hold] - RobotParams().F_r1)
    stiffness = np.array([1e5, 1e6, 1e7])
    deficits = np.array([limit - compliant(RobotParams(clutch_stiffness=k), t_end).series["lambda1"].max()
                         for k in stiffness])
    assert np.all(deficits > 0)  # below the limit at every stiffness
    slope = np.polyfit(np.log10(stiffness), np.log10(deficits), 1)[0]
    assert -0.6 < slope < -0.4, (slope, deficits)


@pytest.mark.parametrize("damping, backlash", [(30.0, 0.0), (300.0, 0.0), (300.0, 1e-4)])
@pytest.mark.slow
def test_a_damped_clutchs_peak_force_does_not_depend_on_the_output_grid(damping, backlash):
    """With damping the clutch force k d - c v peaks between the module's turning points, so between
    samples: on the 1e-4 s grid it read 1.2e-3 low at 1e7 N/m and 300 N s/m ((omega_c dt_out)^2 / 8 with
    omega_c = 3.2e3 rad/s), 1.3e-5 low at 30 N s/m. The run samples each maximum, located on the dense output
    to sqrt(eps) of the time, so the peak is the same on a 1e-4 s and a 1e-6 s grid to roundoff."""
    params = RobotParams(clutch_stiffness=1e7, clutch_damping=damping, clutch_backlash=backlash)
    peaks = []
    for dt_out in (1e-4, 1e-6):
        s = compliant(params, 0.3, dt_out=dt_out).series
        peaks.append(max(s["lambda1"].max(), s["lambda2"].max()))
    assert peaks[0] == pytest.approx(peaks[1], rel=1e-9)


@pytest.mark.slow
def test_with_backlash_the_peak_force_is_an_impact_growing_as_sqrt_k():
    """With play the module crosses it and hits its clutch at a speed v0 that k does not change. A mass
    m_eff pressed by a load Q hitting a spring at v0 compresses it to k d_max = Q + sqrt(Q^2 + k m_eff v0^2):
    ~ v0 sqrt(k m_eff) for a stiff clutch. m_eff = M11 - M12^2 / M22 (module 1 with the crank free),
    Q = -m_eff a1 (what drove it back) at the moment of impact. Tolerance: the formula holds Q and
    m_eff fixed during the compression, while the crank turns omega * pi/2 sqrt(m_eff / k) radians;
    both change by about that fraction."""
    params = dict(clutch_backlash=1e-3)
    dyn = OneDofDynamics(RobotParams(), "exact")
    peaks, share = {}, []
    for k in (1e6, 1e7, 1e8):
        s = compliant(RobotParams(clutch_stiffness=k, **params), 0.3, dt_out=1e-6).series
        peak = int(np.argmax(s["lambda1"]))
        hit = np.flatnonzero(s["clutch_overlap1"][:peak] <= 0)[-1]  # the last sample inside the play
        mt = dyn.mass_terms(s["phi"][hit])
        m_eff = mt.m11 - mt.m12**2 / mt.m22
        v0, load = -s["v1"][hit], -m_eff * s["a1"][hit]
        predicted = load + math.sqrt(load**2 + k * m_eff * v0**2)
        turned = abs(s["omega"][hit]) * 0.5 * math.pi * math.sqrt(m_eff / k)
        assert s["lambda1"][peak] == pytest.approx(predicted, rel=turned), k
        assert math.isfinite(s["lambda1"][peak]) and v0 > 0.1  # a real impact, at the same speed for every k
        peaks[k] = s["lambda1"][peak]
        share.append(load / peaks[k])
    slope = np.polyfit(np.log10(list(peaks)), np.log10(list(peaks.values())), 1)[0]
    # k d_max = Q + sqrt(Q^2 + k m v0^2) has log-slope 1/2 (1 - Q / (k d_max)) in k: between its values at
    # the ends, less 0.01 for v0, which varies by 1 % between runs (earlier history differs by O(1/k))
    assert 0.5 * (1 - max(share)) - 0.01 < slope < 0.5 * (1 - min(share)) + 0.01, (slope, share)


finite = dict(allow_nan=False, allow_infinity=False)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(m1=st.floats(0.2, 5, **finite), m2=st.floats(0.2, 5, **finite), ratio=st.floats(1.2, 12, **finite),
       F_r1=st.floats(0, 4, **finite), F_r2=st.floats(0, 4, **finite), M=st.floats(0, 0.6, **finite),
       phi0=st.floats(0, 2 * math.pi, **finite), omega0=st.floats(-10, 10, **finite),
       log_k=st.floats(3, 7.5, **finite), damping=st.sampled_from([0.0, 30.0]),
       backlash=st.floats(0, 0.025, **finite), drive=st.sampled_from(["torque", "motor"]),
       incline=st.floats(-90, 90, **finite), geometry=st.sampled_from(["approx", "exact"]))
@pytest.mark.slow
def test_properties_over_a_wide_range_of_designs(m1, m2, ratio, F_r1, F_r2, M, phi0, omega0, log_k, damping, backlash,
                                                 drive, incline, geometry):
    torque = dict(M=M) if drive == "torque" else {}  # M is the constant torque's (refused with the motor)
    params = RobotParams(m1=m1, m2=m2, L=0.05 * ratio, F_r1=F_r1, F_r2=F_r2, phi0=phi0, omega0=omega0,
                         clutch_stiffness=10**log_k, clutch_damping=damping, clutch_backlash=backlash, drive=drive,
                         incline=incline, **torque)
    run = analytic.simulate(params, geometry, "unilateral", 0.2, dt_out=1e-3)
    s, e = run.series, run.energy
    assert s["lambda1"].min() >= 0 and s["lambda2"].min() >= 0
    assert np.all(np.abs(s["resistance1"]) <= F_r1 * (1 + 1e-9) + 1e-12)
    assert np.all(np.abs(s["resistance2"]) <= F_r2 * (1 + 1e-9) + 1e-12)
    # the energy that flows: work of the drive, of gravity, against friction, or the initial kinetic energy
    flow = max(abs(e["motor_work_j"]), abs(e["potential_j"]), e["friction_j"], s["kinetic"][0], 1e-9)
    assert abs(e["residual_j"]) <= 1e-6 * flow  # rtol 1e-10 over up to ~1e4 steps and events


@pytest.mark.parametrize("k", [1e3, 1e5])  # the revolution event lands a hair past / short of the whole turn
def test_runs_to_the_steady_state_and_stops_on_a_revolution_boundary(k):
    seen = []
    run = compliant(RobotParams(clutch_stiffness=k, drive="motor"), 10.0, until_steady=True, steady_cycles=3,
                    progress=seen.append, dt_out=1e-3)
    s = run.summary
    assert s["steady"] and run.series["t"][-1] == pytest.approx(s["t_steady_s"], abs=1e-12)
    assert s["revolutions"] == pytest.approx(round(s["revolutions"]), abs=1e-9)  # ends on a boundary
    assert run.settings["steady_tol"] == 1e-4 and run.settings["steady_cycles"] == 3
    assert s["steady_speed_m_s"] > 0 and s["energy_per_metre_j_m"] > 0
    assert seen == sorted(seen) and seen[-1] == run.series["t"][-1] and len(seen) >= run.series["t"][-1] / 0.2


def test_a_torque_too_small_stalls_for_good():
    run = compliant(RobotParams(clutch_stiffness=1e6, M=0.02, omega0=6.0), 1.0)
    assert run.stall is not None and run.summary["stalled"]
    s = run.series
    rest = s["t"] > 0.6  # it coasts to rest within 0.52 s
    assert np.ptp(s["x1"][rest]) == 0 and np.ptp(s["x2"][rest]) == 0 and np.all(s["omega"][rest] == 0)
    # at rest the mode says which clutches push (a module standing in its play on its resistance is not held)
    push1, push2 = s["lambda1"][rest] > 0, s["lambda2"][rest] > 0
    expected = np.where(push1 & push2, Mode.BOTH_LOCKED, np.where(push2, Mode.CONTRACTION,
                                                                  np.where(push1, Mode.EXPANSION, Mode.BOTH_MOVING)))
    assert np.all(s["mode"][rest] == expected) and np.all(push2)
    assert abs(run.energy["residual_j"]) < 1e-7 * run.energy["friction_j"]


def test_work_budgets_are_simulation_errors():
    params = RobotParams(clutch_stiffness=1e6)
    with pytest.raises(SimulationError, match="max_switches=3"):
        compliant(params, 1.0, max_switches=3)
    with pytest.raises(SimulationError, match="wall_budget_s=1e-06"):
        compliant(params, 1.0, wall_budget_s=1e-6)


def test_unmodelled_combinations_are_refused():
    with pytest.raises(ParameterError, match="clutch_stiffness=1000000.0 N/m with clutch='kinematic'"):
        analytic.simulate(RobotParams(clutch_stiffness=1e6), "exact", "kinematic")
    for name in ("clutch_damping", "clutch_backlash"):
        with pytest.raises(ParameterError, match=f"{name}=0.001 needs a finite clutch_stiffness"):
            analytic.simulate(RobotParams(**{name: 1e-3}), "exact", "unilateral")



@pytest.mark.parametrize("settings,fragment", [
    (["clutch_stiffness=-1"], "clutch_stiffness=-1.0"),
    (["clutch_stiffness=0"], "clutch_stiffness=0"),
    (["clutch_stiffness=nan"], "clutch_stiffness=nan"),
    (["clutch_damping=-5", "clutch_stiffness=1e6"], "clutch_damping=-5.0"),
    (["clutch_backlash=0.03", "clutch_stiffness=1e6"], "clutch_backlash=0.03"),
    (["clutch_backlash=nan", "clutch_stiffness=1e6"], "clutch_backlash=nan"),
    (["clutch_damping=5"], "clutch_damping=5.0 needs a finite clutch_stiffness"),
])
def test_bad_clutch_input_exits_2_with_one_line_naming_the_value(capsys, settings, fragment):
    argv = ["simulate", "--clutch", "unilateral", "--geometry", "exact"]
    for item in settings:
        argv += ["--set", item]
    code, out, err = run_cli(capsys, *argv)
    assert code == 2 and out == "" and err.count("\n") == 1 and fragment in err, err


def test_cli_refuses_the_kinematic_rule_with_a_compliant_clutch(capsys):
    code, _, err = run_cli(capsys, "simulate", "--set", "clutch_stiffness=1e6")
    assert code == 2 and err.count("\n") == 1 and "clutch='kinematic'" in err


def test_cli_runs_the_compliant_clutch(capsys):
    code, out, err = run_cli(capsys, "simulate", "--clutch", "unilateral", "--geometry", "exact", "--t-end", "0.1",
                             "--set", "clutch_stiffness=1e6", "--json")
    assert code == 0 and err == ""
    record = json.loads(out)
    assert record["clutch"] == "unilateral" and record["settings"]["clutch_model"] == "compliant"
    assert record["params"]["clutch_stiffness"] == 1e6
    energy = record["summary"]["energy"]
    assert {"clutch_spring_j", "clutch_damper_j", "potential_j"} <= set(energy)
    assert abs(energy["residual_j"]) < 1e-7 * energy["motor_work_j"]


def test_a_dead_centre_at_rest_with_the_drive_off_is_decided_by_friction_not_assumed_at_rest():
    """A riser, drive off (M = 0), at a dead centre from rest: nothing turns the crank, but gravity pulls both
    modules back, which friction (F_r = 1 N each) cannot hold; the clutches must catch them. The robot sinks
    until its springs carry the weight (mg/k ~ 1e-5 m at 1e6 N/m) and friction never exceeds F_r."""
    p = RobotParams(M=0.0, incline=90.0, clutch_stiffness=1e6)
    run = compliant(p, 0.1)
    s = run.series
    assert np.abs(s["resistance1"]).max() <= p.F_r1 * (1 + 1e-9)
    assert np.abs(s["resistance2"]).max() <= p.F_r2 * (1 + 1e-9)
    weight = (p.m1 + p.m2 + p.rod_mass) * p.g
    assert s["x1"][-1] < 0 and s["lambda1"][-1] + s["lambda2"][-1] >= weight - p.F_r1 - p.F_r2 - 1e-6
