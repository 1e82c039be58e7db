"""The analytic engines along a route: today's straight-pipe model on a straight route (a constant grade too), the
energy audit closing along bends in any plane, a vertical leg against a hand calculation, the route's summary keys
and stops, the scrub hook's booking, the registry and the command line."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.route import read_route, route_from_tables

MOTOR = dict(drive="motor")
ANALYTIC_KEYS = {"route_done", "route_time_s", "route_s_m", "route_length_m", "route_stop", "route_piece_times_s"}
# bends in three planes (one oblique), two meeting with no straight between, a straight shorter than the rings'
# spacing, a tight bend: every regime of a module's pose
WINDING = route_from_tables([dict(kind="straight", length=0.5), dict(kind="bend", radius=0.6, angle=40.0, plane=37.0),
                             dict(kind="bend", radius=0.45, angle=-30.0, plane=120.0),
                             dict(kind="straight", length=0.06), dict(kind="bend", radius=0.3, angle=50.0, plane=-70.0),
                             dict(kind="straight", length=0.4)])


def straight(length: float, incline: float = 0.0):
    return route_from_tables([dict(kind="straight", length=length, incline=incline)])


@pytest.mark.parametrize("variant, params", [
    ("analytic-exact", RobotParams(**MOTOR)),
    ("analytic-unilateral", RobotParams(**MOTOR)),
    ("analytic-unilateral", RobotParams(mu_wall=0.3, F_n1=10.0, F_n2=10.0, **MOTOR)),  # both modules skid
    ("analytic-unilateral", RobotParams(incline=30.0, **MOTOR)),  # a constant grade: today's incline model
    ("analytic-unilateral", RobotParams(incline=90.0, M_stall=1.0, mu_wall=0.5, F_n1=30.0, F_n2=30.0, **MOTOR)),
])
def test_a_straight_route_runs_as_todays_straight_pipe(variant, params):
    """The route's equations in a straight pipe are today's exact-geometry model: travel, turns, skids and the energy
    agree to 1e-8 (each run holds rtol = 1e-10 per step; the two integrate different states, the gap S(phi) against
    the loop closed by Newton's method, so they differ by the integration error accumulated over the run's few
    thousand steps, ~1e-11 of the travel measured; any modelling difference is of order (L / R)^2, 2e-4 at R/D 50)
    and the clutches switch as often."""
    route = straight(5.0, params.incline)
    along = registry.run(variant, params, 1.5, route=route, dt_out=1e-3)
    plain = registry.run(variant, params, 1.5, dt_out=1e-3)
    a, b = along.summary, plain.summary
    assert a["mode_switches"] == b["mode_switches"]
    for key in ("x1_final", "x2_final", "revolutions", "slip1_m", "slip2_m"):
        assert a[key] == pytest.approx(b[key], rel=1e-8, abs=1e-11), key
    for key in ("motor_work_j", "kinetic_j", "friction_j", "potential_j"):
        assert a["energy"][key] == pytest.approx(b["energy"][key], rel=1e-8, abs=1e-10), key
    assert along.params.incline == params.incline and a["route_done"] is False


@pytest.mark.parametrize("variant, params, route", [
    ("analytic-unilateral", RobotParams(mu_wall=0.8, **MOTOR), read_route("mjcf/bend90.toml")),
    ("analytic-exact", RobotParams(**MOTOR), WINDING),
    ("analytic-unilateral", RobotParams(mu_wall=0.5, F_n1=30.0, F_n2=30.0, M_stall=1.5, **MOTOR), WINDING),  # skids
    ("analytic-unilateral", RobotParams(mu_wall=0.5, F_n1=50.0, F_n2=50.0, M_stall=1.0, **MOTOR),  # skids 0.13 m
     route_from_tables([dict(kind="straight", length=0.4), dict(kind="bend", radius=0.25, angle=90.0, plane=90.0),
                        dict(kind="straight", length=0.3)])),
])
def test_the_energy_audit_closes_along_a_route(variant, params, route):
    """Motor work = kinetic + potential + friction + skid + scrub work + residual with the residual within the
    solver's tolerance: rtol = 1e-10 per step, at worst 1e-6 of the energy put through over the run's ~1e4 steps
    if every step's error added up (measured: a few 1e-9). Along the bends in three planes (the rings crossing
    joints between pieces in different planes and across a short straight, where a discontinuous frame would
    show as a jump of the crank pin's speed: 1e-4 of the energy before the frame was made continuous), and a tight
    bend turning up into a riser on finite grip."""
    run = registry.run(variant, params, 30.0, route=route, dt_out=1e-3)
    s = run.summary
    assert s["route_done"], s["route_stop"]
    assert abs(s["accuracy"]["residual_ratio"]) < 1e-6
    # the wheels' scrub (route_scrub's closed form) where they have a finite grip: every one of these routes has a
    # bend tight enough for a wheel to slide (R <= 0.8 m: the fore ring, cocked, slips at about (1 + c travel / b)
    # b / R >= 0.11 rad, beyond mu_wall / c <= 0.1 rad); with unlimited grip the equations' rails carry the side
    # force without any
    assert (run.energy["scrub_j"] > 0.0) == (params.mu_wall is not None)


def test_a_vertical_leg_lifts_the_robot_as_a_hand_calculation_says():
    """Level, a bend turning up (plane 90) and a vertical straight: at the route's end both modules are in the
    riser, where each module's point is on the centreline, its height R + (s - s_riser), and the crank pin B sits
    r cos(phi) above A (module 1's axis is vertical, its left horizontal): the potential energy gained is
    g (m1 z_A + m2 z_C + m_rod (z_B + z_C) / 2) from 0 at the start, the robot's weight lifted."""
    p = RobotParams(M_stall=1.0, mu_wall=0.8, **MOTOR)
    R = 0.4
    route = route_from_tables([dict(kind="straight", length=0.4), dict(kind="bend", radius=R, angle=90.0, plane=90.0),
                               dict(kind="straight", length=0.6)])
    run = registry.run("analytic-unilateral", p, 60.0, route=route, dt_out=1e-3)
    s, series = run.summary, run.series
    assert s["route_done"], s["route_stop"]
    riser = route.pieces[2].s0
    z_A = R + (series["x1"][-1] - riser)
    z_C = R + (series["x2"][-1] + series["S"][0] - riser)
    z_B = z_A + p.r * math.cos(series["phi"][-1])
    lifted = p.g * (p.m1 * z_A + p.m2 * z_C + p.rod_mass * 0.5 * (z_B + z_C))
    assert series["potential"][-1] == pytest.approx(lifted, rel=1e-12)
    assert run.energy["potential_j"] == pytest.approx(lifted, rel=1e-12)


def test_a_route_run_reports_the_route_keys_mujocos_do_and_ends_where_module_1_reaches_the_end():
    """The summary's route keys are those of MuJoCo's route watch that the equations can give (the rest, the wheels'
    fit and their contact with the wall, are MuJoCo's); the run ends where module 1's A reaches the route's end,
    located as an event: where today's straight-pipe run crosses it, to its sampling (the crossing interpolated
    between samples 1e-4 s apart, v below 2 m/s: 1e-4 s); the robot's centre reaches each piece's start when
    today's does."""
    from ipir_mujoco.engine.modelkinds.route_watch import RouteWatch

    watch = RouteWatch.__new__(RouteWatch)
    watch.stop, watch.route, watch.s_max, watch.done_at, watch.prediction = "x", straight(1.0), 0.0, None, {}
    watch.lost, watch.off_time, watch.module_off_time, watch.reach, watch.mark_times = None, 0.0, 0.0, 0.0, []
    assert ANALYTIC_KEYS <= set(watch.record(1.0, None))
    params = RobotParams(**MOTOR)
    route = route_from_tables([dict(kind="straight", length=0.4), dict(kind="straight", length=0.5)])
    run = registry.run("analytic-unilateral", params, 10.0, route=route, dt_out=1e-4)
    plain = registry.run("analytic-unilateral", params, run.t_end + 0.1, dt_out=1e-4)
    s, series = run.summary, plain.series
    assert ANALYTIC_KEYS == {k for k in s if k.startswith("route_")}
    assert s["route_done"] is True and s["route_s_m"] == pytest.approx(0.9, abs=1e-12)
    assert run.t_end == s["route_time_s"]
    assert s["route_time_s"] == pytest.approx(np.interp(0.9, series["x1"], series["t"]), abs=1e-4)
    centre = np.maximum.accumulate(0.5 * (series["x1"] + series["x2"] + series["S"][0]))
    assert s["route_piece_times_s"][0] == 0.0
    assert s["route_piece_times_s"][1] == pytest.approx(np.interp(0.4, centre, series["t"]), abs=1e-4)


def test_a_robot_that_gets_nowhere_stops_with_the_reason():
    """A riser with a grip of a fifth of the weight: the robot slides back and gets no further; the run stops after
    the route's window (PROGRESS_S) with the reason in one line, long before its cap. A constant torque too weak to
    lift it: a stall, said so."""
    from ipir_mujoco.core.route import PROGRESS_S

    riser = straight(1.0, 90.0)
    run = registry.run("analytic-unilateral", RobotParams(mu_wall=0.05, **MOTOR), 30.0, route=riser, dt_out=1e-3)
    s = run.summary
    assert s["route_done"] is False and s["route_stop"].startswith("stalled: less than 10 mm of progress")
    assert "\n" not in s["route_stop"] and PROGRESS_S <= run.t_end < PROGRESS_S + 1.0
    run = registry.run("analytic-unilateral", RobotParams(M=0.05), 30.0, route=riser, dt_out=1e-3)
    assert run.summary["route_stop"].startswith("stalled: at rest") and run.stall is not None


def test_the_scrub_hook_is_booked_as_its_own_term(tmp_path):
    """A scrub of 0.3 N on each moving module (route_kernels.scrub_force patched, in a process running the kernels
    as Python): the audit books 0.3 N times the modules' travel as scrub_j, the residual still closes, and the
    motion is that of a robot whose resistances are 0.3 N higher (to the solver's tolerance)."""
    code = (
        "import json\n"
        "from ipir_mujoco import registry\n"
        "from ipir_mujoco.analytic import route_kernels\n"
        "from ipir_mujoco.core.params import RobotParams\n"
        "from ipir_mujoco.core.route import route_from_tables\n"
        "route_kernels.scrub_force = lambda p, module, s, v: 0.3\n"
        "route = route_from_tables([dict(kind='straight', length=0.3), dict(kind='bend', radius=0.5, angle=30.0,"
        " plane=45.0), dict(kind='straight', length=0.3)])\n"
        "scrub = registry.run('analytic-unilateral', RobotParams(drive='motor'), 0.5, route=route, dt_out=1e-3)\n"
        "route_kernels.scrub_force = lambda p, module, s, v: 0.0\n"
        "higher = registry.run('analytic-unilateral', RobotParams(drive='motor', F_r1=1.3, F_r2=1.3), 0.5,"
        " route=route, dt_out=1e-3)\n"
        "print(json.dumps([scrub.summary, higher.summary]))\n")
    env = {**os.environ, "IPIR_MUJOCO_JIT": "0"}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    scrub, higher = json.loads(done.stdout)
    travel = scrub["x1_final"] + scrub["x2_final"]
    assert scrub["energy"]["scrub_j"] == pytest.approx(0.3 * travel, rel=1e-9)
    assert abs(scrub["accuracy"]["residual_ratio"]) < 1e-6  # as the audit along a route above
    assert scrub["x1_final"] == pytest.approx(higher["x1_final"], rel=1e-8)
    assert scrub["energy"]["friction_j"] + scrub["energy"]["scrub_j"] == pytest.approx(higher["energy"]["friction_j"],
                                                                                     rel=1e-8)


def test_what_runs_along_a_route_and_what_is_refused_in_one_line():
    bend = read_route("mjcf/bend90.toml")
    assert {v for v in registry.ROUTE_VARIANTS} == {"analytic-exact", "analytic-unilateral", "mujoco-wheels"}
    for name in ("analytic-approx", "analytic-approx-unilateral"):
        with pytest.raises(ParameterError, match="analytic-exact, analytic-unilateral"):
            registry.run(name, RobotParams(), 0.1, route=bend)
    for params, options, word in ((RobotParams(clutch_stiffness=1e5), {}, "clutch_stiffness"),
                                  (RobotParams(drive="servo"), {}, "servo"),
                                  (RobotParams(**MOTOR), {"until_steady": True}, "until-steady"),
                                  (RobotParams(incline=10.0), {}, "incline"),
                                  (RobotParams(pipe_diameter=2.0), {}, "pipe_diameter")):
        with pytest.raises(ParameterError, match=word) as caught:
            registry.run("analytic-unilateral", params, 0.1, route=bend, **options)
        assert "\n" not in str(caught.value)
    with pytest.raises(ParameterError, match="route"):
        registry.run("analytic-unilateral", RobotParams(), 0.1, route="mjcf/bend90.toml")


def test_simulate_takes_a_route_on_the_equations(capsys):
    from cli_run import run_cli

    code, out, err = run_cli(capsys, "simulate", "--route", "mjcf/bend90.toml", "--drive", "motor", "--json")
    assert code == 0 and err == ""
    record = json.loads(out)
    s = record["summary"]
    assert (record["engine"], record["geometry"], record["clutch"]) == ("analytic", "exact", "kinematic")
    assert s["route_done"] is True and ANALYTIC_KEYS <= set(s) and s["energy"]["scrub_j"] == 0.0
    code, out, err = run_cli(capsys, "simulate", "--clutch", "unilateral", "--drive", "motor", "--route",
                             "mjcf/bend90.toml", "--t-end", "0.3")
    assert code == 0 and "m along the route" in out and "route NOT done: " in out and "closed-form" not in out
    code, out, err = run_cli(capsys, "simulate", "--geometry", "approx", "--route", "mjcf/bend90.toml")
    assert code == 2 and "analytic-approx" in err and "--geometry exact" in err and len(err.strip().splitlines()) == 1
