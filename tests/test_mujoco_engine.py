"""MuJoCo against the analytic model, clutches that hold, failures that are loud."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams, SimulationError
from ipir_mujoco.analytic.free_motion import simulate_free
from ipir_mujoco.core.results import Mode
from ipir_mujoco.cli import main
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.builders.model import SolverSettings

FIGURES = ("revolutions", "x1_final", "x2_final")


def at_crank_angle(run, column, phis):
    """``column`` of ``run`` resampled at crank angles ``phis`` (phi increases monotonically here)."""
    return np.interp(phis, run.series["phi"], run.series[column])


def halved(run) -> SolverSettings:
    """The settings of ``run`` with half its timestep (MuJoCo chose the timestep from the motion)."""
    return SolverSettings(timestep=run.settings["timestep"] / 2)


@pytest.fixture(scope="module")
def paper_rule_runs():
    """Analytic exact geometry, and MuJoCo locks with the paper's rule at the automatic dt and dt/2."""
    params = RobotParams()
    mj = simulate_mujoco(params, "kinematic", "lock", 1.0)
    return (analytic.simulate(params, "exact", "kinematic", 1.0), mj,
            simulate_mujoco(params, "kinematic", "lock", 1.0, settings=halved(mj)))


def test_locks_with_the_papers_rule_reproduce_the_equations(paper_rule_runs):
    exact, mj, mj_half = paper_rule_runs
    for key in FIGURES:
        reference = exact.summary[key]
        error = abs(mj.summary[key] - reference)
        # MuJoCo's step is first order: its error at dt is about 2 |f(dt) - f(dt/2)|
        # (Richardson); allow 1.5x that, plus the analytic solver's own error (rtol 1e-10).
        richardson = 2 * abs(mj.summary[key] - mj_half.summary[key])
        assert error <= 1.5 * richardson + 1e-8 * abs(reference), key
        # and the acceptance thresholds: 0.3 % on revolutions, 1 % on displacements
        assert error <= (0.003 if key == "revolutions" else 0.01) * abs(reference), key
        # halving the step moves MuJoCo toward the equations
        assert abs(mj_half.summary[key] - reference) < error, key


def test_locks_with_the_papers_rule_match_at_every_crank_angle(paper_rule_runs):
    exact, mj, _ = paper_rule_runs
    phis = np.linspace(0.0, min(exact.series["phi"][-1], mj.series["phi"][-1]), 400)[1:]
    # time to reach each crank angle: within 0.3 % of that time
    t_an, t_mj = at_crank_angle(exact, "t", phis), at_crank_angle(mj, "t", phis)
    assert np.max(np.abs(t_mj - t_an) / t_an) < 0.003
    # displacements at each crank angle: within 1 % of the distance covered by 1 s
    for column in ("x1", "x2"):
        scale = exact.summary[column + "_final"]
        difference = at_crank_angle(mj, column, phis) - at_crank_angle(exact, column, phis)
        assert np.max(np.abs(difference)) < 0.01 * scale, column
    # same mode sequence: the same number of switches
    assert abs(mj.summary["mode_switches"] - exact.summary["mode_switches"]) <= 1


def test_lock_reactions_agree_with_the_analytic_kinetostatics(paper_rule_runs):
    """The clutch reaction read from MuJoCo's constraint force is the analytic lambda, sign included."""
    exact, mj, _ = paper_rule_runs
    an, m = exact.series, mj.series
    for mode, column in ((Mode.CONTRACTION, "lambda2"), (Mode.EXPANSION, "lambda1")):
        held = (m["mode"] == mode) & (m["t"] > 0.01)
        phis = m["phi"][held]
        inside = (an["mode"] == mode)
        expected = np.interp(phis, an["phi"][inside], an[column][inside])
        # compare away from the switches, where the reaction jumps within one step
        keep = np.abs(np.sin(phis)) > 0.2
        scale = np.abs(expected[keep]).max()
        assert np.median(np.abs(m[column][held][keep] - expected[keep])) < 0.01 * scale
    assert mj.summary["min_clutch_reaction_n"] == pytest.approx(exact.summary["min_clutch_reaction_n"], rel=0.02)


def test_stalled_robot_holds_with_the_statics_of_the_linkage():
    """M = 0.01 N m < F_r r at phi = pi/2: nothing moves, the forces are those of statics, the run says so.

    Crank torque balance about A with the rod along e = (C - B) / L:
    M = r T e_x, so the rod tension is T = M / (r e_x), e_x = sqrt(L^2 - r^2) / L.
    The rod pulls module 2 back with T e_x = M / r, which its lock holds; it
    pushes module 1 forward with M / r < F_r1, which static friction holds.
    Module 2 has no resistance here, so that its lock alone holds it: a clutch
    and static friction in parallel share a load in a way rigid statics leaves
    undetermined (MuJoCo's soft rows give the friction 1.4e-5 of it).
    """
    params = RobotParams(M=0.01, phi0=math.pi / 2, F_r2=0.0)
    run = simulate_mujoco(params, "unilateral", "lock", 0.3)
    s = run.series
    # at rest from the start: the run ends early, as a stall with its time and crank angle, not an error
    assert run.stall is not None and "at rest from t=0 s" in run.stall and "90.0 deg" in run.stall
    assert run.summary["stalled"] and run.t_end < 0.3
    e_x = math.sqrt(params.L**2 - params.r**2) / params.L
    # soft constraints settle to their static load within a few time constants (2e-4 s)
    assert s["rod_force"][-1] == pytest.approx(params.M / (params.r * e_x), rel=1e-5)
    assert s["lambda2"][-1] == pytest.approx(params.M / params.r, rel=1e-5)
    # module 1 stands on its static friction, its lock open: held, as in the equations' stall (both held)
    assert s["lambda1"][-1] == 0.0 and s["mode"][-1] == Mode.BOTH_LOCKED
    assert analytic.simulate(params, "exact", "unilateral", 0.3).series["mode"][-1] == Mode.BOTH_LOCKED
    # constraint compliance under 0.2 N: displacements far below a micrometre
    assert np.max(np.abs(s["x1"])) < 1e-6 and np.max(np.abs(s["x2"])) < 1e-6
    assert np.max(np.abs(s["phi"] - params.phi0)) < 1e-5


def test_energy_audit_of_the_physics_closes(paper_rule_runs):
    _, mj, mj_half = paper_rule_runs
    for run in (mj, mj_half):
        e = run.summary["energy"]
        # residual = what the soft constraints and the stepping took; the accuracy monitor
        # holds it below 1e-3 of the energy put through the robot (here the motor work) all run long
        assert abs(e["residual_j"]) < 1e-3 * e["motor_work_j"]
        assert abs(run.accuracy["residual_ratio"]) < 1e-3 and run.accuracy["ok"]
    assert abs(mj_half.summary["energy"]["residual_j"]) < abs(mj.summary["energy"]["residual_j"])


def test_free_mechanism_matches_the_equations_and_keeps_zero_momentum():
    params = RobotParams(F_r1=0.0, F_r2=0.0)
    exact = simulate_free(params, "exact", 0.5)
    mj = simulate_mujoco(params, "unilateral", "none", 0.5)
    mj_half = simulate_mujoco(params, "unilateral", "none", 0.5, settings=halved(mj))
    # No force along x acts on the robot, so its momentum stays at its initial 0.
    # What MuJoCo shows is first-order time-discretization drift: it must halve
    # with the step (0.5 +- 10 %) and stay small against the momentum scale.
    drift, drift_half = (np.max(np.abs(run.series["momentum"])) for run in (mj, mj_half))
    assert 0.45 < drift_half / drift < 0.55
    scale = (params.m1 + params.m2 + params.rod_mass) * np.max(np.abs(mj.series["v1"]))
    assert drift < 1e-3 * scale
    # x1 is a function of the crank angle alone (momentum zero from rest): compare at matching phi
    phis = np.linspace(0.0, min(exact.series["phi"][-1], mj.series["phi"][-1]), 300)
    amplitude = np.ptp(exact.series["x1"])
    difference = at_crank_angle(mj, "x1", phis) - at_crank_angle(exact, "x1", phis)
    assert np.max(np.abs(difference)) < 1e-3 * amplitude
    assert mj.summary["revolutions"] == pytest.approx(exact.summary["revolutions"], rel=0.003)


def test_ratchet_never_lets_a_module_back_over_six_seconds():
    """A weaker motor (M = 0.06 N m) keeps speeds moderate for 6 s (27 revolutions)."""
    run = simulate_mujoco(RobotParams(M=0.06), "unilateral", "ratchet", 6.0, dt_out=1e-3)
    s = run.series
    assert s["t"][-1] == pytest.approx(6.0) and run.summary["revolutions"] > 20
    # the monitor's excursion is checked before every step; the samples can only see less of it
    tolerance = run.accuracy["tolerances"]["excursion_m"]
    assert run.accuracy["excursion_m"] <= tolerance
    for column in ("x1", "x2"):
        backward = np.maximum.accumulate(s[column]) - s[column]
        assert backward.max() <= run.accuracy["excursion_m"], column
    assert min(s["lambda1"].min(), s["lambda2"].min()) >= 0.0
    assert run.summary["min_clutch_reaction_n"] >= 0.0


def test_ratchet_and_unilateral_locks_are_the_same_physics():
    """Two implementations of a one-way clutch: limits raised each step, and locks that let go."""
    params = RobotParams()
    ratchet = simulate_mujoco(params, "unilateral", "ratchet", 1.0)
    locks = simulate_mujoco(params, "unilateral", "lock", 1.0)
    for key in FIGURES:
        # both engage within a step of each other: differences of order dt in time
        assert locks.summary[key] == pytest.approx(ratchet.summary[key], rel=1e-3), key
    # one-way clutches change the motion: fewer revolutions than the paper's rule
    assert ratchet.summary["revolutions"] < 0.95 * analytic.simulate(params, "exact").summary["revolutions"]


def test_instability_fails_loudly_with_time_and_reason(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    coarse = SolverSettings(timestep=5e-3)
    # the accuracy monitor stops this run first; recording it instead lets MuJoCo's own failure show
    with pytest.raises(SimulationError, match=r"unstable after t=\d"):
        simulate_mujoco(RobotParams(M=50.0), "kinematic", "lock", 1.0, dt_out=5e-3, settings=coarse, accuracy="warn")
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT left in the user's folder


def test_cli_mujoco_json_and_exit_statuses(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--engine", "mujoco", "--json", "--t-end", "0.3"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert (record["engine"], record["geometry"], record["clutch"]) == ("mujoco", "exact", "kinematic")
    assert record["summary"]["revolutions"] > 0.5
    bad_mjcf = tmp_path / "bad.xml"
    bad_mjcf.write_text("<mujoco><worldbody>")
    for argv, fragment in ((["--geometry", "approx"], "--geometry approx"), (["--set", "rod_mass=0"], "rod_mass=0"),
                           (["--set", "L=0.05"], "L=0.05"), (["--mjcf", str(tmp_path / "no.xml")], "no.xml"),
                           (["--mjcf", str(bad_mjcf)], "bad.xml"),
                           (["--timestep", "3e-5", "--dt-out", "1e-4"], "dt_out")):
        assert main(["simulate", "--engine", "mujoco", *argv]) == 2, argv
        err = capsys.readouterr().err
        assert fragment in err and err.count("\n") == 1, argv
    code = main(["simulate", "--engine", "mujoco", "--set", "M=50", "--timestep", "5e-3", "--dt-out", "5e-3",
                 "--accuracy", "warn"])
    assert code == 1 and "unstable after t=" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.xml"]
