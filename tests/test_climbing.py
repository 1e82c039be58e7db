"""Climbing ability in inclined and vertical pipes: the quasi-static limit against a hand calculation, both engines
at it, the riser stall, the engines side by side uphill, downhill and in a riser, the runaway, the command line."""

from __future__ import annotations

import csv
import json
import math
import re

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from ipir_mujoco import analytic
from ipir_mujoco.core.results import REST_TIME
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.core.cycles import travel
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.cli import main
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.loop.monitor import RESIDUAL_TOL
from ipir_mujoco.studies import climbing

# MuJoCo with default options against the analytic model of the same mechanism: within 0.1 % in revolutions and
# travel (TARGET of tests/test_mujoco_accuracy.py, the horizontal case); the steady speed is travel over time and
# is held to the same 0.1 % (tests/test_clutch_study.py, the default motor's cruise)
TARGET = 1e-3
DT_OUT = 1e-3  # s: the study's output interval


# --- the restart limit against a hand calculation --------------------------------------------------------------------

def hand_required(p: RobotParams, phi: float, s: float) -> float:
    """Torque at rest [N m] that moves the robot on at crank angle phi on a slope s = sin(incline), by virtual work.

    Exact slider-crank: S = r cos phi + D, D = sqrt(L^2 - r^2 sin^2 phi), K = dS/dphi. The rod's centre is the
    mid-point of B (x1 + r cos phi) and C (x1 + S). Contraction (K < 0): module 2 stands, x1 = x2 - S moves by
    -K dphi, the rod's centre by (-K - r sin phi) / 2 dphi; expansion (K > 0): module 1 stands, x2 moves by
    K dphi, the rod's centre by (K - r sin phi) / 2 dphi. M dphi = (F_i + m_i g s) dx_i + m_rod g s dG.
    """
    r, L, sn, cs = p.r, p.L, math.sin(phi), math.cos(phi)
    D = math.sqrt(L**2 - (r * sn) ** 2)
    K = -r * sn - r**2 * sn * cs / D
    if K < 0:
        return (p.F_r1 + p.m1 * p.g * s) * -K + p.rod_mass * p.g * s * (-K - r * sn) / 2
    return (p.F_r2 + p.m2 * p.g * s) * K + p.rod_mass * p.g * s * (K - r * sn) / 2


def hand_limit(p: RobotParams, M: float) -> tuple[float, float]:
    """(s*, phi*): the required torque is a + s b in s; the drive restarts everywhere while s <= (M - a) / b."""
    def allowed(phi):
        a = hand_required(p, phi, 0.0)
        b = hand_required(p, phi, 1.0) - a
        return (M - a) / b if b > 0 else math.inf

    grid = np.linspace(0.0, 2 * math.pi, 20001)[1:-1]
    values = [allowed(x) for x in grid]
    k = int(np.argmin(values))
    best = minimize_scalar(allowed, bounds=(grid[k - 1], grid[k + 1]), method="bounded", options={"xatol": 1e-12})
    return best.fun, best.x


def test_the_largest_climbable_incline_under_0_25_n_m_is_the_hand_calculation():
    """The paper's case (constant torque 0.25 N m): the tool's restart limit is the hand calculation's.

    Both minimize smooth functions of the crank angle to ~1e-12 rad, where the minimum's value is flat: the
    values agree to roundoff (1e-9 deg leaves margin); the angles to the square root of that (1e-6 rad)."""
    params = RobotParams()
    found = climbing.restart_limit(params)
    s, phi = hand_limit(params, params.M)
    assert found["incline_deg"] == pytest.approx(math.degrees(math.asin(s)), abs=1e-9)
    assert found["phi_rad"] == pytest.approx(phi, abs=1e-6) and found["stroke"] == "expansion"
    assert 22.8 < found["incline_deg"] < 22.9  # 22.87 deg
    # the paper's model (first order, massless rod): r (F_r + m g s) <= M at phi = 90 deg, in closed form
    paper = climbing.restart_limit(params.replace(rod_mass=0.0, rod_inertia=0.0), "approx")
    closed = math.asin((params.M / params.r - params.F_r1) / (params.m1 * params.g))
    assert paper["incline_deg"] == pytest.approx(math.degrees(closed), abs=1e-9)  # 24.06 deg
    assert paper["phi_rad"] == pytest.approx(math.pi / 2, abs=1e-6)
    # the energy bound: 2 pi M per revolution against 2 r (F_r1 + F_r2 + m g s)
    mass = params.m1 + params.m2 + params.rod_mass
    bound = (math.pi * params.M / params.r - params.F_r1 - params.F_r2) / (mass * params.g)
    assert climbing.energy_bound(params)["sin"] == pytest.approx(bound, rel=1e-14)
    # the torque a vertical riser needs is the largest of the hand calculation's over a revolution
    need = climbing.torque_needed(params.replace(incline=90.0))
    grid = np.linspace(0.0, 2 * math.pi, 20001)
    assert need["torque_n_m"] == pytest.approx(max(hand_required(params, x, 1.0) for x in grid), rel=1e-7)


@pytest.mark.parametrize("engine", ["analytic", "mujoco"])
def test_at_the_restart_limit_both_engines_hold_or_move_on_as_statics_says(engine):
    """From rest at the hardest crank angle, 0.05 deg above the limit the robot stays at rest, 0.05 deg below it
    moves on. The margin leaves the drive g cos(incline) b 8.7e-4 rad ~ 4e-4 N m (1.8e-3 of M) short or spare,
    far above the engines' statics errors (1e-7 of the weight; tests/test_mujoco_engine.py and
    tests/test_motor_gravity.py)."""
    limit = climbing.restart_limit(RobotParams())
    for margin, held in ((0.05, True), (-0.05, False)):
        params = RobotParams(incline=limit["incline_deg"] + margin, phi0=limit["phi_rad"])
        run = (analytic.simulate(params, "exact", "unilateral", 0.3, dt_out=DT_OUT) if engine == "analytic" else
               simulate_mujoco(params, "unilateral", "ratchet", 0.3, dt_out=DT_OUT))
        turned = run.series["phi"][-1] - params.phi0
        if held:
            # MuJoCo's soft rows take up the load in the first 0.03 s, turning the crank by 3.9e-5 rad
            assert run.stall is not None and abs(turned) < 1e-4, (margin, run.stall, turned)
        else:  # ~0.1 rad/s^2 of spare acceleration: 5e-3 rad in 0.3 s
            assert run.stall is None and turned > 2e-3, (margin, turned)


# --- a vertical riser under the default motor --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def riser_runs():
    """The default motor in a vertical pipe, both exact models, to steady state (10 s cap) or a stall."""
    params = RobotParams(drive="motor", incline=90.0)
    return params, {"analytic": analytic.simulate(params, "exact", "unilateral", 10.0, dt_out=DT_OUT,
                                                  until_steady=True),
                    "mujoco": simulate_mujoco(params, "unilateral", "ratchet", 10.0, dt_out=DT_OUT, until_steady=True)}


def test_the_default_motor_stalls_in_a_vertical_pipe_in_both_engines_at_the_same_place(riser_runs):
    params, runs = riser_runs
    found = {name: climbing.run_metrics(run) for name, run in runs.items()}
    an, mj = found["analytic"], found["mujoco"]
    assert an["stalled"] and mj["stalled"]
    # each says why, in one line, in the same words (core.summary.stall_reason): only the figures differ
    assert "cannot move the linkage against the resistances and gravity" in an["stall_reason"]
    assert re.sub(r"[0-9.]+", "#", an["stall_reason"]) == re.sub(r"[0-9.]+", "#", mj["stall_reason"])
    # and each run ends REST_TIME after its robot came to rest (MuJoCo at its next 0.05 s check)
    for name, run in runs.items():
        assert REST_TIME - 1e-9 <= run.t_end - found[name]["stall_t_s"] <= REST_TIME + 0.05 + 1e-9, name
    # where: the crank angle is revolutions x 2 pi, held to TARGET; when: MuJoCo reads rest at its 1 ms samples
    # (one dt_out late at most), plus TARGET of the time for its trajectory
    assert mj["stall_phi_rad"] == pytest.approx(an["stall_phi_rad"], rel=TARGET)
    assert abs(mj["stall_t_s"] - an["stall_t_s"]) <= DT_OUT + TARGET * an["stall_t_s"]
    # why, from statics: the torque needed at rest exceeds M_stall there, and first did so earlier in the turn,
    # which the crank passed on its kinetic energy; a revolution needs up to 0.562 N m
    phi = an["stall_phi_rad"]
    assert climbing.required_torque(params, phi) > params.M_stall
    ahead = np.linspace(0.0, phi, 2001)
    assert climbing.required_torque(params, ahead)[0] < params.M_stall < climbing.required_torque(params, ahead).max()
    assert climbing.torque_needed(params)["torque_n_m"] > params.M_stall
    # at rest both clutches hold what statics says (a hold pulling module 1 back is its static resistance's);
    # MuJoCo at its own crank angle, its soft rows settled to 1e-7 of the weight (tests/test_mujoco_engine.py)
    weight = (params.m1 + params.m2 + params.rod_mass) * params.g
    for name, tolerance in (("analytic", 1e-9), ("mujoco", 1e-6)):
        lambda1, lambda2, *_ = OneDofDynamics(params, "exact").stalled_reactions(found[name]["stall_phi_rad"])
        assert found[name]["lambda1_at_rest_n"] == pytest.approx(float(lambda1), abs=tolerance * weight), name
        assert found[name]["lambda2_at_rest_n"] == pytest.approx(float(lambda2), abs=tolerance * weight), name
        assert found[name]["lambda2_at_rest_n"] > weight  # module 2's clutch carries the whole robot and more


def test_the_papers_model_wrongly_climbs_the_riser_under_the_default_motor():
    """First order, massless rod: its requirement r (F_r + m g) = 0.5405 N m peaks lower and its crank carries
    over it, so it climbs where both exact models stall."""
    run = analytic.simulate(RobotParams(drive="motor", incline=90.0), "approx", "kinematic", 10.0, dt_out=DT_OUT,
                            until_steady=True)
    assert run.stall is None and run.summary["steady"] and 0.1 < run.summary["steady_speed_m_s"] < 0.12


# --- the engines side by side: 30 deg, a riser with a stronger motor, 20 deg downhill ----------------------------------

def at_common_time(runs):
    """Revolutions and travel [m] of each run at the end of the shorter one (linear between samples)."""
    t = min(run.series["t"][-1] for run in runs)
    return [((np.interp(t, r.series["t"], r.series["phi"]) - r.series["phi"][0]) / (2 * math.pi),
             np.interp(t, r.series["t"], travel(r.series)) - travel(r.series)[0]) for r in runs]


CASES = {  # the default motor at 30 deg; at 90 deg the smallest motor that restarts anywhere (0.5621 N m rounded
    # up to 0.57); at -20 deg the default resistances cannot hold the robot (see the runaway below): F_r = 5 N can
    "30 deg": RobotParams(drive="motor", incline=30.0),
    "90 deg, M_stall 0.57 N m": RobotParams(drive="motor", incline=90.0, M_stall=0.57),
    "-20 deg, F_r 5 N": RobotParams(drive="motor", incline=-20.0, F_r1=5.0, F_r2=5.0),
}


@pytest.fixture(scope="module")
def side_by_side():
    return {name: (analytic.simulate(p, "exact", "unilateral", 10.0, dt_out=DT_OUT, until_steady=True),
                   simulate_mujoco(p, "unilateral", "ratchet", 10.0, dt_out=DT_OUT, until_steady=True))
            for name, p in CASES.items()}


@pytest.mark.parametrize("case", list(CASES))
def test_analytic_and_mujoco_agree_on_a_slope_as_in_a_horizontal_pipe(side_by_side, case):
    an, mj = side_by_side[case]
    assert an.summary["steady"] and mj.summary["steady"] and an.stall is None and mj.stall is None
    (rev_an, moved_an), (rev_mj, moved_mj) = at_common_time((an, mj))
    assert abs(rev_mj / rev_an - 1) < TARGET and abs(moved_mj / moved_an - 1) < TARGET
    assert abs(mj.summary["steady_speed_m_s"] / an.summary["steady_speed_m_s"] - 1) < TARGET
    assert mj.accuracy["ok"]


def test_the_study_gives_no_peak_reaction_for_mujocos_rigid_clutches(side_by_side):
    """A rigid MuJoCo clutch engages through a soft constraint that overshoots by an amount set by the step, and
    read every DT_OUT its peak is whichever step a sample hits: the same run read at every step gives another
    peak. The study leaves MuJoCo's out (the equations give the rigid clutch's) and keeps its mean reaction."""
    an, mj = side_by_side["90 deg, M_stall 0.57 N m"]
    every_step = simulate_mujoco(CASES["90 deg, M_stall 0.57 N m"], "unilateral", "ratchet", 10.0,
                                 dt_out=mj.settings["timestep"], until_steady=True)
    assert mj.settings["timestep"] < DT_OUT
    assert abs(every_step.summary["peak_clutch_force_n"] / mj.summary["peak_clutch_force_n"] - 1) > 0.1
    kept = climbing.run_metrics(mj)
    assert kept["peak_clutch_force_n"] is None and kept["mean_clutch_force_n"] > 0
    assert climbing.run_metrics(an)["peak_clutch_force_n"] == an.summary["peak_clutch_force_n"]


def test_efficiency_counts_the_lift_as_useful(side_by_side):
    """Rigid clutches lose nothing: at the steady state (resistance work + potential energy) / (motor work less
    the kinetic energy in transit) is 1, to the energy audit's residual (analytic: its solver error, 1e-6 of
    the flow; MuJoCo: each cumulative residual within RESIDUAL_TOL of the motor work so far, so the window's
    within 2 RESIDUAL_TOL of the whole run's, over the window's): the summary's efficiency says so at every
    incline, where resistance work / motor work alone would read (F_r1 + F_r2) / (F_r1 + F_r2 + m g
    sin(incline)) uphill and exceed 1 downhill. The window's ends are settled to 1e-4 in speed, not equal: the
    kinetic energy it gains would read as a loss of kinetic / put_in (up to ~1e-3) were it not taken off."""
    for case, runs in side_by_side.items():
        p = CASES[case]
        share = (p.F_r1 + p.F_r2) / (p.F_r1 + p.F_r2 + (p.m1 + p.m2 + p.rod_mass) * p.g * math.sin(math.radians(p.incline)))
        for run in runs:
            t0, t1, steady = climbing.steady_window(run)
            motor, kinetic, lifted, friction = (np.diff(np.interp([t0, t1], run.series["t"], run.series[c]))[0]
                                                for c in ("motor_work", "kinetic", "potential", "friction_work"))
            bound = 1e-6 if run.engine == "analytic" else 2 * RESIDUAL_TOL * run.series["motor_work"][-1] / motor
            assert steady and abs(run.summary["efficiency"] - 1) < bound, (case, run.engine)
            if p.incline > 0:  # the resistances' share alone is far from 1 on a climb
                assert friction / motor == pytest.approx(share, abs=bound + abs(kinetic) / motor), (case, run.engine)
                assert share < 0.9


def test_twenty_degrees_downhill_the_default_resistances_let_the_robot_run_away_in_both_engines():
    """sin(20 deg) g = 3.36 m/s^2 > (F_r1 + F_r2) / m = 0.995 m/s^2: no steady state; both engines agree on the
    revolutions and travel of the runaway within TARGET."""
    params = RobotParams(drive="motor", incline=-20.0)
    assert params.g * math.sin(math.radians(20.0)) * (params.m1 + params.m2 + params.rod_mass) > params.F_r1 + params.F_r2
    an = analytic.simulate(params, "exact", "unilateral", 2.0, dt_out=DT_OUT)
    mj = simulate_mujoco(params, "unilateral", "ratchet", 2.0, dt_out=DT_OUT)
    (rev_an, moved_an), (rev_mj, moved_mj) = at_common_time((an, mj))
    assert abs(rev_mj / rev_an - 1) < TARGET and abs(moved_mj / moved_an - 1) < TARGET
    assert not an.summary["steady"] and not mj.summary["steady"] and an.stall is None and mj.stall is None


# --- downhill runaway --------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("engine", ["analytic", "mujoco"])
def test_a_downhill_runaway_is_simulated_to_its_end(engine):
    """-60 deg, F_r = 0.1 N: gravity (8.5 m/s^2) pulls both modules faster than the linkage moves them, no clutch
    holds, and the robot's momentum grows as Newton says, dp/dt = m a_g - F_r1 - F_r2 (the crank's motion is
    internal). A wall-time budget turns a hang into a SimulationError naming it."""
    params = RobotParams(drive="motor", incline=-60.0, F_r1=0.1, F_r2=0.1)
    if engine == "analytic":
        run = analytic.simulate(params, "exact", "unilateral", 3.0, dt_out=DT_OUT, wall_budget_s=120.0)
        mass = OneDofDynamics(params, "exact").mass_terms(run.series["phi"])
        momentum = mass.m11 * run.series["v1"] + mass.m12 * run.series["omega"]
        tolerance = 1e-6  # every term a state or a function of states, within ~rtol
    else:
        run = simulate_mujoco(params, "unilateral", "ratchet", 3.0, dt_out=DT_OUT, wall_budget_s=120.0)
        momentum = run.series["momentum"]
        tolerance = TARGET  # a soft constraint's leak of the free acceleration, 1e-4, and the step's error
    s = run.series
    assert run.t_end == pytest.approx(3.0) and run.stall is None and not run.summary["steady"]
    late = s["t"] >= 1.0  # after the start-up both modules slide all the time
    assert s["v1"][late].min() > 1.0 and s["v2"][late].min() > 1.0
    assert s["lambda1"][late].max() == 0.0 and s["lambda2"][late].max() == 0.0
    mass = params.m1 + params.m2 + params.rod_mass
    a_g = -params.g * math.sin(math.radians(params.incline))
    rate = (np.interp(3.0, s["t"], momentum) - np.interp(1.0, s["t"], momentum)) / 2.0
    assert rate == pytest.approx(mass * a_g - params.F_r1 - params.F_r2, rel=tolerance)


# --- the command line ----------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("argv,fragment", [
    (["simulate", "--set", "incline=91"], "incline=91"), (["simulate", "--set", "incline=nan"], "incline=nan"),
    (["simulate", "--engine", "mujoco", "--set", "incline=-90.5"], "incline=-90.5"),
    (["climb", "--inclines", "0,95"], "incline=95.0"), (["climb", "--inclines", "nan"], "incline=nan"),
    (["climb", "--inclines=-100:0:3"], "incline=-100.0"), (["climb", "--set", "incline=10"], "--inclines"),
    (["climb", "--variants", "mujoco"], "mujoco"), (["climb", "--tolerance", "0"], "--tolerance"),
])
def test_an_incline_outside_plus_minus_90_deg_or_nan_exits_2_in_one_line(argv, fragment, capsys, tmp_path):
    assert main(argv + (["--out", str(tmp_path / "x")] if argv[0] == "climb" else [])) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err and "allowed" in err
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_climb_command_writes_its_study_and_figure(capsys, tmp_path):
    """A constant torque (no bisection: it has no steady state): the restart limit printed is the tool's, a
    stall is a row, and the figure holds the rows' numbers."""
    from ipir_mujoco.report.climb_figure import climb_figure

    out = tmp_path / "climb"
    assert main(["climb", "--inclines", "0,45", "--t-end", "0.5", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert f"up to {climbing.restart_limit(RobotParams())['incline_deg']:.2f} deg" in text
    study = json.loads((out / "climb.json").read_text())
    assert study["steady_climb"] == {} and [r["incline_deg"] for r in study["rows"]] == [0.0, 45.0]
    rows = list(csv.DictReader((out / "climb.csv").open()))
    for engine in climbing.ENGINES:
        # above the energy bound (44 deg) no constant torque of 0.25 N m keeps going: a stall, in both engines
        assert rows[0][f"{engine}:stalled"] == "0" and rows[1][f"{engine}:stalled"] == "1"
        assert float(rows[0][f"{engine}:mean_speed_m_s"]) == pytest.approx(study["rows"][0]["engines"][engine]
                                                                          ["mean_speed_m_s"], rel=1e-12)
    assert (out / "climb.png").stat().st_size > 0
    fig = climb_figure(study, RobotParams())
    lines = {line.get_gid(): line for ax in fig.axes for line in ax.get_lines() if line.get_gid()}
    for engine in climbing.ENGINES:
        x, y = lines[f"speed:{engine}"].get_data()
        assert list(x) == [0.0, 45.0] and y[0] == study["rows"][0]["engines"][engine]["mean_speed_m_s"]
        assert np.isnan(y[1]) and list(lines[f"stalled:{engine}"].get_data()[0]) == [45.0]
    assert lines["restart"].get_xdata()[0] == pytest.approx(study["restart"]["incline_deg"])


@pytest.mark.slow
def test_the_sweep_preset_over_the_incline_runs_end_to_end(capsys, tmp_path):
    """sweep --vary incline=... --drive motor --until-steady with the default engines (MuJoCo batched): every
    design runs, the riser stalls in both, and the steady speeds agree within TARGET."""
    out = tmp_path / "sweep"
    assert main(["sweep", "--vary", "incline=0,45,90", "--drive", "motor", "--until-steady", "--out", str(out)]) == 0
    assert "3 designs, 0 failed, 1 stalled" in capsys.readouterr().out
    rows = list(csv.DictReader((out / "results.csv").open()))
    for row in rows[:2]:
        assert row["mujoco-ratchet:steady"] == row["analytic-unilateral:steady"] == "1"
        assert abs(float(row["divergence:analytic-unilateral:steady_speed_m_s"])) < TARGET
    assert rows[2]["mujoco-ratchet:stalled"] == rows[2]["analytic-unilateral:stalled"] == "1"
    assert (out / "sweep_lines.png").is_file()
