"""MuJoCo's finite grip: the wheels hold up to G_i and skid at G_i by construction (MuJoCo's own rows say
so), unlimited grip is today's model, and the two engines agree where the grip binds.

Tolerances are the monitor's (0.1 % of the motion), MuJoCo's own discretization error measured here
against half its step, and the carriage's inertia (grip_model.CARRIAGE_SHARE of its module's), each said
where it is used.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.core.cycles import _at, cycle_boundaries
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.run.batch import run_ratchet_batch
from ipir_mujoco.engine.clutches import clutch_controller
from ipir_mujoco.engine.builders.grip_model import BODY_MASS, CARRIAGE_SHARE, CARRIAGES, ROLLS, SKIDS
from ipir_mujoco.engine.builders.model import (MOTOR, SLIDES, SolverSettings, build_model, dof_address, drive_control,
                                      set_closed_loop_state)
from ipir_mujoco.engine.loop.monitor import EXCURSION_PER_R, RESIDUAL_TOL

CRUISE = RobotParams(drive="motor", mu_wall=0.5, F_n1=10.0, F_n2=10.0)  # 5 N of grip against ~12 N of demand
RISER = RobotParams(drive="motor", M_stall=1.0, incline=90.0, mu_wall=0.3, F_n1=20.0, F_n2=20.0)  # too little grip
LIMIT = (int(mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT), int(mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON))
FRICTION = (int(mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF), int(mujoco.mjtConstraint.mjCNSTR_FRICTION_TENDON))


def mujoco_run(params, t_end, **options):
    return simulate_mujoco(params, "unilateral", "ratchet", t_end, **{"dt_out": 1e-3, **options})


def skid_per_rev(run, first: int, last: int) -> list[float]:
    """Each module's skid [m] per revolution over the crank's whole revolutions first..last (0 = the first)."""
    s = run.series
    ends, _ = cycle_boundaries(s["t"], s["phi"])
    edges = np.concatenate([[s["t"][0]], ends])[[first, last]]
    return [float(np.diff(_at(s["t"], s[f"slip{k}"], edges))[0]) / (last - first) for k in (1, 2)]


# --- the model ---------------------------------------------------------------------------------------------------

def stepped_by_hand(p: RobotParams, dt: float):
    """(model, data, clutch controller, the carriages' dof addresses) of the ratchet model at its closed-loop
    start with the drive set, ready for mj_step by hand."""
    model = build_model(p, SolverSettings(timestep=dt), ratchet=True)
    data = mujoco.MjData(model)
    set_closed_loop_state(model, data, p)
    clutch = clutch_controller(model, data, p, "ratchet")
    data.ctrl[model.actuator(MOTOR).id] = drive_control(p)
    mujoco.mj_forward(model, data)
    return model, data, clutch, [dof_address(model, n) for n in SKIDS]


def test_unlimited_grip_builds_todays_model_and_finite_grip_adds_only_the_carriages():
    plain, grip = build_model(RobotParams(), ratchet=True), build_model(CRUISE, ratchet=True)
    assert (plain.nbody, plain.njnt, plain.ntendon) == (grip.nbody - 2, grip.njnt - 2, grip.ntendon - 2) == (5, 4, 0)
    p = CRUISE
    for i, (slide, skid, roll, body) in enumerate(zip(SLIDES, SKIDS, ROLLS, CARRIAGES)):
        mass = (p.m1, p.m2)[i]
        j, t = grip.joint(skid), grip.tendon(roll)
        assert grip.dof_frictionloss[j.dofadr[0]] == p.grip[i] == 5.0  # the grip: Coulomb friction mu_wall F_ni
        assert grip.dof_armature[j.dofadr[0]] == pytest.approx(CARRIAGE_SHARE * mass, rel=1e-15)
        assert grip.body(body).mass[0] == BODY_MASS  # no weight to speak of: the carriage's inertia is armature
        assert grip.tendon_frictionloss[t.id] == (p.F_r1, p.F_r2)[i]  # rolling resistance on the roll
        assert grip.dof_frictionloss[dof_address(grip, slide)] == 0.0 and not grip.jnt_limited[grip.joint(slide).id]
        assert grip.jnt_limited[j.id] and grip.tendon_limited[t.id]  # the wall's and the clutch's one-way limits
        # the rows scale their softness with the module slide's inverse weight, not the light carriage's
        weight = grip.dof_invweight0[dof_address(grip, slide)]
        assert grip.dof_invweight0[j.dofadr[0]] == weight == grip.tendon_invweight0[t.id]


def test_what_has_no_grip_refuses_a_finite_one_with_one_line():
    for implementation in ("lock", "none"):
        with pytest.raises(ParameterError, match="only the ratchet is modelled on wheels of finite grip") as info:
            simulate_mujoco(CRUISE, "unilateral", implementation, 0.1)
        assert "\n" not in str(info.value)
    # the press is settable with unlimited grip (the wheeled model's leg preload) and moves nothing on the slides
    pressed, plain = (simulate_mujoco(p, "unilateral", "ratchet", 0.1) for p in (RobotParams(F_n1=20.0), RobotParams()))
    assert pressed.summary["x1_final"] == plain.summary["x1_final"]
    outcome, = run_ratchet_batch([CRUISE], 0.1)
    assert "batched runs have unlimited grip only" in outcome["error"] and "\n" not in outcome["error"]


# --- MuJoCo's own rows: the hold is capped at the grip, a skid is at the grip --------------------------------------

def test_mujocos_rows_hold_up_to_the_grip_and_skid_at_it():
    """Stepping the cruise by hand (2.5 s, both modules skid every revolution) and reading MuJoCo's rows after
    each step. The hold on module i is the roll tendon's rows (clutch limit + rolling friction); the carriage
    carries it to the wall through its friction row (<= G_i by MuJoCo's bound) and its forward limit, so the
    hold may exceed G_i only by the carriage's inertia force m_c |a_c| (a_c its acceleration over the step);
    round-off of forces of ~10 N: 1e-9 N. While the carriage moves back the friction row sits at G_i
    exactly; at rest it creeps below 1e-6 m/s (the package's rest speed; measured 2.5e-7 m/s at most)."""
    p, dt = CRUISE, 1e-4
    model, data, clutch, c_dof = stepped_by_hand(p, dt)
    rolls = [model.tendon(n).id for n in ROLLS]
    m_c = model.dof_armature[c_dof]
    skidding = [[], []]
    for _ in range(25000):
        v_before = data.qvel[c_dof].copy()
        clutch.before_step()
        mujoco.mj_step(model, data)
        kinds, ids, force = data.efc_type.astype(int), data.efc_id, data.efc_force
        for k in (0, 1):
            hold = sum(f for kind, i, f in zip(kinds, ids, force) if kind in (FRICTION[1], LIMIT[1]) and i == rolls[k])
            grip = sum(f for kind, i, f in zip(kinds, ids, force) if kind == FRICTION[0] and i == c_dof[k])
            v_c = data.qvel[c_dof[k]]
            a_c = (v_c - v_before[k]) / dt
            assert hold <= p.grip[k] + m_c[k] * abs(a_c) + 1e-9
            assert grip <= p.grip[k]
            if v_c < -1e-4:  # skidding (well above the soft friction's creep)
                skidding[k].append(grip)
            elif v_c > -1e-9 and v_c < 1e-9:
                assert grip < p.grip[k]  # standing: the row holds within its bound
    for k in (0, 1):
        assert len(skidding[k]) > 1000  # both modules skid for much of the run
        assert np.all(np.array(skidding[k]) == p.grip[k])


def test_a_held_module_creeps_far_below_what_the_comparison_resolves():
    """At the cruise on 20 N of grip (the equations' demand peaks at 12.1 N, MuJoCo's soft engagement at
    17.6 N: every hold stands), the carriages' backward travel while their modules stand, per revolution over
    the last three revolutions: the soft friction's creep. The skid per revolution is compared to ~1e-3 of
    ~1e-3 m below, so creep must stay far under 1e-6 m per revolution; 1e-8 m is asserted (measured 2.0e-9 m
    and 1.6e-9 m, over 142 and 124 standing samples of 1 ms)."""
    run = mujoco_run(RobotParams(drive="motor", mu_wall=0.5, F_n1=40.0, F_n2=40.0), 10.0, until_steady=True)
    s = run.series
    assert run.summary["steady"] and run.summary["peak_grip_use"] < 1.0
    ends, _ = cycle_boundaries(s["t"], s["phi"])
    inside = (s["t"] >= ends[-4]) & (s["t"] <= ends[-1])
    for k in (1, 2):
        standing = (s[f"wheels{k}"][1:] == 0) & (s[f"wheels{k}"][:-1] == 0) & inside[1:]
        assert standing.sum() > 100
        creep = np.diff(s[f"slip{k}"])[standing].sum() / 3
        assert 0 <= creep < 1e-8


# --- unlimited grip, and a grip far above the demand --------------------------------------------------------------

@pytest.mark.parametrize("base", [{}, {"drive": "motor", "incline": 30.0}])
def test_a_grip_far_above_the_demand_gives_the_unlimited_results(base):
    """10 kN of grip against at most 67 N of demand: the carriages never skid, and the run equals the
    unlimited one within MuJoCo's own accuracy, the monitor's 0.1 % target (measured: 2e-7)."""
    unlimited = mujoco_run(RobotParams(**base), 1.0)
    far = mujoco_run(RobotParams(**base, mu_wall=1.0, F_n1=1e4, F_n2=1e4), 1.0)
    for key in ("revolutions", "x1_final", "x2_final"):
        assert far.summary[key] == pytest.approx(unlimited.summary[key], rel=1e-3)
    assert far.summary["mode_switches"] == unlimited.summary["mode_switches"]
    assert far.summary["slip1_m"] < 1e-6 and far.summary["slip2_m"] < 1e-6  # creep only, no skid
    assert unlimited.summary["slip1_m"] == 0.0 and unlimited.summary["peak_grip_use"] is None


# --- the two engines where the grip binds -------------------------------------------------------------------------

@pytest.fixture(scope="module")
def cruise():
    analytic = registry.run("analytic-unilateral", CRUISE, 10.0, dt_out=1e-3, until_steady=True)
    mujoco_ = registry.run("mujoco-ratchet", CRUISE, 10.0, dt_out=1e-3, until_steady=True)
    return analytic, mujoco_


def test_engines_agree_on_the_steady_speed_where_the_grip_binds(cruise):
    """Both skid (2-3 cm to the steady state) and settle to one speed within 0.5 % (measured 1.5e-4)."""
    analytic, mujoco_ = cruise
    for run in cruise:
        assert run.summary["steady"] and run.summary["slip1_m"] > 0.01 and run.summary["slip2_m"] > 0.01
        assert run.summary["peak_grip_use"] == pytest.approx(1.0, abs=1e-2)  # a skid is at the grip
    assert mujoco_.summary["steady_speed_m_s"] == pytest.approx(analytic.summary["steady_speed_m_s"], rel=5e-3)


def test_engines_agree_on_the_skid_per_revolution(cruise):
    """The skid per revolution over the last three revolutions MuJoCo ran (the same crank revolutions in both
    runs). A skid integrates the demand's excess over the grip, so MuJoCo's first-order step error on it is
    larger than on the motion: it is measured here against the same run at half the step, and its
    Richardson estimate E = 2 |s(dt) - s(dt/2)| (first order) bounds MuJoCo's own error, allowed 1.5 E; on
    top, the carriage adds CARRIAGE_SHARE of its module's mass to a skidding module (a bias of at most that
    share, measured -0.85 x it), and a skid is part of its module's travel, which the monitor holds to 0.1 %
    (RESIDUAL_TOL) of the distance per revolution: MuJoCo's error that does not shrink with the step. Measured at
    the step the skid check keeps (5e-5 s): -6.0e-4 and -1.9e-3 of 1.04 and 0.66 mm (E = 2.8e-4 and 5.5e-4;
    module 2's -2.2e-3 at half the step: that part does not converge, 1.3e-6 m per revolution against the 5e-5 m
    allowed); at 1e-4 s with a carriage of 1e-3, -5.7e-3 and -4.3e-3."""
    analytic, mujoco_ = cruise
    last = mujoco_.summary["cycles"]
    half = mujoco_run(CRUISE, mujoco_.t_end, settings=SolverSettings(timestep=mujoco_.settings["timestep"] / 2))
    reference = skid_per_rev(analytic, last - 3, last)
    at_dt, at_half = skid_per_rev(mujoco_, last - 3, last), skid_per_rev(half, last - 3, last)
    for s_an, s_mj, s_half in zip(reference, at_dt, at_half):
        richardson = 2 * abs(s_mj - s_half)
        assert s_an > 5e-4 and richardson < 0.02 * s_an  # a skid of its own and a step that resolves it
        travel = RESIDUAL_TOL * mujoco_.summary["distance_per_rev_m"]
        assert abs(s_mj - s_an) <= 1.5 * richardson + CARRIAGE_SHARE * s_an + travel


def test_engines_agree_on_the_travel_sliding_back_down_a_riser():
    """6 N of grip per module against the whole robot's 19.7 N weight: the robot slides back although its motor
    turns the crank. Travel within 2 % (measured 8e-4: the carriages' inertia, 1e-3 of the modules', slows
    the slide as much)."""
    analytic = registry.run("analytic-unilateral", RISER, 1.0, dt_out=1e-3)
    mujoco_ = registry.run("mujoco-ratchet", RISER, 1.0, dt_out=1e-3)
    for run in (analytic, mujoco_):
        assert run.summary["x1_final"] < -1.0 and run.summary["x2_final"] < -1.0 and run.summary["revolutions"] > 1
    for key in ("x1_final", "x2_final", "slip1_m", "slip2_m"):
        assert mujoco_.summary[key] == pytest.approx(analytic.summary[key], rel=2e-2)


def test_a_riser_without_drive_slides_at_the_hand_calculated_acceleration():
    """Drive off, 6 N of grip per module: both skid, a = (G1 + G2 - (m1 + m2 + m_rod) g) / (m1 + m2 + m_rod +
    m_c1 + m_c2). The first run carries the carriages' inertia (its share of the modules', which has no weight:
    -3.8381 m/s^2), and MuJoCo's semi-implicit step gives x_n = a dt^2 n (n + 1) / 2, t/dt = n: a relative error
    dt / t = 1e-4 at 1 s. The summary's rigid limit has neither: a = -3.8398 m/s^2, the equations' law, within
    its own error bar."""
    p = RobotParams(M=0.0, incline=90.0, mu_wall=0.3, F_n1=20.0, F_n2=20.0)
    run = mujoco_run(p, 1.0)
    mass = p.m1 + p.m2 + p.rod_mass
    t = run.series["t"][-1]
    share = run.settings["carriage_share"]
    a_first = (sum(p.grip) - mass * p.g) / (mass + share * (p.m1 + p.m2))
    for k in (1, 2):
        assert run.series[f"x{k}"][-1] == pytest.approx(0.5 * a_first * t * t, rel=2e-4)
    assert run.summary["slip1_m"] == pytest.approx(-0.5 * a_first * t * t, rel=2e-4)
    a_rigid = (sum(p.grip) - mass * p.g) / mass
    for key in ("x1_final", "x2_final"):
        assert abs(run.summary[key] - 0.5 * a_rigid * t * t) <= run.summary["figure_errors"][key]
        assert run.accuracy["figures_accepted"][key]


def test_a_riser_at_rest_stands_on_just_enough_grip_and_skids_on_a_little_less():
    """docs/model.md's hand check: at phi = pi/2 in a riser under M = 0.25 N m statics loads module 2 with
    M/r + (m2 + m_rod) g = 14.908 N and module 1 with m1 g - M/r = 4.81 N. 0.1 % more grip on both: a stall
    within a skid of the soft start (< 1e-7 m); 0.1 % less on module 2 only: module 2 skids, as in the
    equations (within 1 %: a skid of 0.5 mm)."""
    R1, R2 = 9.81 - 5.0, 5.0 + 1.01 * 9.81
    hold = RobotParams(incline=90.0, phi0=math.pi / 2, mu_wall=0.5, F_n1=1.001 * R1 / 0.5, F_n2=1.001 * R2 / 0.5)
    stood = mujoco_run(hold, 0.3)
    assert stood.stall is not None and stood.summary["slip1_m"] < 1e-7 and stood.summary["slip2_m"] < 1e-7
    assert stood.series["lambda2"][-1] == pytest.approx(R2, rel=1e-6)
    weak = RobotParams(incline=90.0, phi0=math.pi / 2, mu_wall=0.5, F_n1=1.001 * R1 / 0.5, F_n2=0.999 * R2 / 0.5)
    skid, reference = mujoco_run(weak, 0.3), registry.run("analytic-unilateral", weak, 0.3, dt_out=1e-3)
    assert skid.stall is None and skid.summary["slip1_m"] < 1e-7
    assert skid.summary["slip2_m"] == pytest.approx(reference.summary["slip2_m"], rel=1e-2)


# --- the energy audit and the accuracy monitor --------------------------------------------------------------------

def test_the_energy_audit_closes_with_the_skid_work(cruise):
    """skid_j is the carriages' friction rows' work; it is G_i times the carriages' travel up to what the
    rows do below G_i: their creep, and the engagement and release of each skid within the rows' time constant
    (8 steps, a soft term the rigid limit extrapolates away; measured 8e-5 of skid_j). The audit books it, so it
    must lie within the monitor's tolerance of it; with skid_j the residual is within the tolerance, and without
    it the audit would miss 6 % of the motor's work."""
    _, run = cruise
    e, s = run.energy, run.series
    assert e["skid_j"] == pytest.approx(sum(G * s[f"slip{k}"][-1] for k, G in enumerate(CRUISE.grip, 1)),
                                        rel=RESIDUAL_TOL)
    assert abs(e["residual_j"]) < RESIDUAL_TOL * e["motor_work_j"]
    assert abs(e["residual_j"] + e["skid_j"]) > 50 * RESIDUAL_TOL * e["motor_work_j"]
    assert e["motor_work_j"] == pytest.approx(e["kinetic_j"] + e["potential_j"] + e["friction_j"] + e["skid_j"]
                                              + e["residual_j"], rel=1e-12)


def test_the_excursion_figure_measures_the_clutchs_give_not_a_skid():
    """Down a riser the modules skid back 2 m: the excursion figure (how far a one-way limit gave) stays
    at the clutches' and the wall's give, far below the monitor's 2e-4 r (measured 4e-11 m)."""
    run = mujoco_run(RISER, 1.0)
    assert run.summary["slip1_m"] > 1.0
    assert run.accuracy["excursion_m"] < 1e-3 * EXCURSION_PER_R * RISER.r


def test_a_grip_below_the_rolling_resistance_still_never_drags_a_module_forward():
    """G = 0.5 N < F_r = 1 N: a module rolling forward pulls its carriage forward with F_r, more than the grip;
    the wall's one-way limit holds the carriage (slip never decreases). The run's step is set by the motion (its
    automatic step is halved once by the monitor), so the rigid limit comes from a finer run: its skids within
    0.5 % of the equations' (1 s, 0.6 m per module), each figure within its error bar."""
    p = RobotParams(mu_wall=0.05, F_n1=10.0, F_n2=10.0)
    run = mujoco_run(p, 1.0)
    reference = registry.run("analytic-unilateral", p, 1.0, dt_out=1e-3)
    for k in (1, 2):
        assert np.all(np.diff(run.series[f"slip{k}"]) >= 0.0)
        assert run.summary[f"slip{k}_m"] == pytest.approx(reference.summary[f"slip{k}_m"], rel=5e-3)
    assert run.accuracy["rigid_limit"] == "extrapolated" and run.accuracy["ok"]
    for key, error in run.summary["figure_errors"].items():
        assert abs(run.summary[key] - reference.summary[key]) <= error, key


# --- compliant clutches on finite grip ----------------------------------------------------------------------------

COMPLIANT = RobotParams(drive="motor", clutch_stiffness=1e6, mu_wall=0.5, F_n1=10.0, F_n2=10.0)


@pytest.mark.slow
def test_a_compliant_clutchs_force_is_capped_by_the_grip_and_its_anchor_slides():
    """Stepping the default motor with an undamped 1e6 N/m clutch on 5 N of grip (0.6 s, at the automatic
    step): the clutch actuator acts on the roll tendon, so what it applies, MuJoCo's actuator_force (no damper:
    no implicit part), reaches the wall through the carriage: it exceeds G_i only by the carriage's inertia
    force m_c |a_c| (round-off of forces of ~10 N: 1e-9 N; measured 3e-10 N), and the carriage's friction row
    sits at G_i exactly while it slides back, carrying the anchor (slip > 0)."""
    p = COMPLIANT
    settings = simulate_mujoco(p, "unilateral", "ratchet", 1e-3, dt_out=1e-3).settings
    dt = settings["timestep"]
    model, data, clutch, c_dof = stepped_by_hand(p, dt)
    # read as Python numbers once: the loop below runs 190,000 steps
    acts, dofs = [int(a) for a in clutch.act], [int(d) for d in c_dof]
    m_c, grips = [float(model.dof_armature[d]) for d in dofs], [float(g) for g in p.grip]
    qvel, force = data.qvel, data.actuator_force  # views of data's fixed-size arrays
    sliding = [0, 0]
    for _ in range(round(0.6 / dt)):
        v_before = [float(qvel[d]) for d in dofs]
        clutch.before_step()
        mujoco.mj_step(model, data)
        # the friction rows are the nf rows after the ne equality rows (MuJoCo orders efc rows by type)
        rows = slice(data.ne, data.ne + data.nf)
        friction = list(zip(data.efc_type[rows].tolist(), data.efc_id[rows].tolist(), data.efc_force[rows].tolist()))
        for k in (0, 1):
            a_c = (float(qvel[dofs[k]]) - v_before[k]) / dt
            assert force[acts[k]] <= grips[k] + m_c[k] * abs(a_c) + 1e-9
            carriage = [f for kind, row_id, f in friction if kind == FRICTION[0] and row_id == dofs[k]]
            assert len(carriage) <= 1  # the carriage's one friction row (its sum below is that row's force, exactly)
            grip = sum(carriage)
            assert grip <= grips[k]
            if qvel[dofs[k]] < -1e-4:
                assert grip == grips[k]
                sliding[k] += 1
    assert min(sliding) > 1000 and min(clutch.lowest) < -1e-3  # both anchors slid back by millimetres


def test_compliant_clutches_on_finite_grip_close_the_energy_audit():
    """Spring, damper, rolling resistance and skid work together close the audit within the monitor's
    tolerance (measured 5e-6 of the motor's work), and the skid work is G_i times the anchors' slide."""
    p = RobotParams(drive="motor", clutch_stiffness=1e6, clutch_damping=300.0, clutch_backlash=5e-4, mu_wall=0.5,
                    F_n1=10.0, F_n2=10.0)
    run = mujoco_run(p, 0.5)
    e, s = run.energy, run.series
    assert run.summary["slip1_m"] > 1e-3 and run.summary["slip2_m"] > 1e-3
    assert abs(e["residual_j"]) < RESIDUAL_TOL * e["motor_work_j"]
    assert e["skid_j"] == pytest.approx(sum(G * s[f"slip{k}"][-1] for k, G in enumerate(p.grip, 1)), rel=1e-6)
    assert {"clutch_spring_j", "clutch_damper_j", "skid_j"} <= set(e)


def test_a_compliant_clutch_far_below_its_grip_runs_as_without_grip():
    """10 kN of grip: the carriages never slide; the run equals the compliant one on unlimited grip within
    MuJoCo's accuracy target, 0.1 % (the timestep differs: the carriage's rule, timestep.clutch_step)."""
    base = dict(drive="motor", clutch_stiffness=1e5, clutch_damping=20.0)
    unlimited = mujoco_run(RobotParams(**base), 0.5)
    far = mujoco_run(RobotParams(**base, mu_wall=1.0, F_n1=1e4, F_n2=1e4), 0.5)
    assert far.settings["timestep"] < unlimited.settings["timestep"]
    for key in ("revolutions", "x1_final", "x2_final"):
        assert far.summary[key] == pytest.approx(unlimited.summary[key], rel=1e-3)
    assert far.summary["slip1_m"] < 1e-6 and far.summary["slip2_m"] < 1e-6


def test_compliant_grip_agrees_with_the_analytic_engine_where_it_has_it():
    """Once the analytic engine models compliant clutches on finite grip (on main; this branch's refuses):
    the default motor, 1e6 N/m undamped, 5 N of grip, 1 s. Revolutions within the monitor's 0.1 %; skids
    within 1 % (the analytic run on main: MuJoCo -7e-4 and -6e-4 of its 7.41 and 13.0 mm; the carriage's
    share alone may take 1e-3, and a skid's first-order step error is of the order of the rigid one's at
    1e-4 s, measured 5e-3 at the cruise)."""
    try:
        reference = registry.run("analytic-unilateral", COMPLIANT, 1.0, dt_out=1e-3)
    except ParameterError as exc:
        pytest.skip(f"the analytic engine here: {exc}")
    run = mujoco_run(COMPLIANT, 1.0)
    assert run.summary["revolutions"] == pytest.approx(reference.summary["revolutions"], rel=1e-3)
    for k in (1, 2):
        assert run.summary[f"slip{k}_m"] == pytest.approx(reference.summary[f"slip{k}_m"], rel=1e-2)
