"""``ipir-mujoco design-check``: the round-pipe robot's closed-form design rules (studies.design.design_rules)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cli_run import run_cli
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.pipe import bend_wheel_spread, sprung_mass
from ipir_mujoco.studies.design.design_rules import design_rules, linkage_samples, tightest_bend

KEYS = {"name", "value", "limit", "margin", "unit", "holds", "why"}


def rules(params, route=None) -> dict:
    return {r["name"]: r for r in design_rules(params, route)["rules"]}


def test_design_check_prints_every_rule_and_exits_0_whatever_the_verdicts(capsys):
    code, out, err = run_cli(capsys, "design-check", "--json", "--drive", "motor", "--set", "M_stall=2",
                             "--set", "F_n1=20", "--set", "F_n2=20", "--set", "mu_wall=0.5")
    assert code == 0 and err == ""
    result = json.loads(out)
    assert set(result) == {"rules", "holds"} and result["holds"] is False
    assert all(set(r) == KEYS for r in result["rules"])
    by_name = {r["name"]: r for r in result["rules"]}
    # a 2 N m motor through a 0.05 m crank pushes a held module with about 40 N against a grip of 0.5 x 20 N
    assert by_name["stall_push_1"]["holds"] is False and by_name["stall_push_1"]["limit"] == pytest.approx(10.0)
    assert by_name["lift_at_stall"]["holds"] is False  # it skids: nothing but its springs holds across the pipe
    assert all(r["holds"] is (r["margin"] is None or r["margin"] >= 0) for r in result["rules"])
    code, out, _ = run_cli(capsys, "design-check")  # the text table, the same rules
    assert code == 0 and all(name in out for name in by_name if name != "lift_at_speed")


def test_a_side_load_where_the_wheels_hold_nothing_is_null_in_the_json(capsys):
    """A module heavier than its press sags until its upper legs press nothing: along them its wheels hold
    nothing across the pipe, so the sideways grip rule's ratio has no bound: inf in Python, null in the JSON (as
    a summary's side_use), and the rule does not hold."""
    code, out, err = run_cli(capsys, "design-check", "--json", "--drive", "motor", "--set", "m1=3",
                             "--set", "F_n1=20", "--set", "mu_wall=0.8")
    assert code == 0 and err == ""
    side = {r["name"]: r for r in json.loads(out)["rules"]}["side_grip_at_stall"]
    assert side["value"] is None and side["margin"] is None and side["holds"] is False
    params = RobotParams(drive="motor", m1=3.0, F_n1=20.0, mu_wall=0.8)
    assert {r["name"]: r for r in design_rules(params)["rules"]}["side_grip_at_stall"]["value"] == math.inf


@pytest.mark.parametrize("argv,word", [(("--set", "wheel_radius=0.05"), "wheel_radius"),
                                       (("--set", "suspension_travel=0.02"), "suspension_travel"),
                                       (("--route", "no-such-route.toml"), "--route")])
def test_design_check_refuses_bad_input_in_one_line(capsys, argv, word):
    code, out, err = run_cli(capsys, "design-check", *argv)
    assert code == 2 and out == "" and word in err and len(err.strip().splitlines()) == 1


def test_the_stall_push_weight_and_climb_rules_by_hand():
    p = RobotParams(drive="motor", M_stall=0.8, mu_wall=0.4, F_n1=60.0, F_n2=30.0, incline=20.0, m2=2.0)
    r = rules(p)
    K = np.abs(linkage_samples(p)["K"]).max()
    # the crank near its quarter turn: |dS/dphi| = r |sin phi| (1 + r cos phi / sqrt(L^2 - r^2 sin^2 phi)), its
    # largest r (1 + (r / L)^2 / 2 + ...) off the quarter turn: 3 % above r at r / L = 1 / 4
    assert p.r < K < p.r * (1 + (p.r / p.L) ** 2)
    down = p.g * math.sin(math.radians(20.0))
    assert r["stall_push_1"]["value"] == pytest.approx(0.8 / K + p.m1 * down, rel=1e-12)
    assert r["stall_push_2"]["value"] == pytest.approx(0.8 / K + p.m2 * down, rel=1e-12)
    assert r["stall_push_2"]["limit"] == pytest.approx(0.4 * 30.0) and r["stall_push_2"]["holds"] is False
    # three legs, leg 0 down: the upper legs (30 deg up) lift where the sprung weight across reaches F_n
    weight = sprung_mass(p, 0) * p.g * math.cos(math.radians(20.0))
    assert r["weight_press_1"]["value"] == pytest.approx(weight, rel=1e-12)
    assert r["weight_press_1"]["limit"] == pytest.approx(60.0, rel=1e-12)
    work = 2 * p.r * (p.F_r1 + p.F_r2 + (p.m1 + p.m2 + p.rod_mass) * down)
    assert r["climb_energy"]["value"] == pytest.approx(work, rel=1e-12)
    assert r["climb_energy"]["limit"] == pytest.approx(2 * math.pi * 0.8, rel=1e-12)
    assert "lift_at_speed" in r and "lift_at_speed" not in rules(RobotParams())  # a constant torque: no top speed


def test_unlimited_grip_holds_a_2_N_m_motor_on_20_N_and_finite_grip_does_not():
    """The default robot on its default (unlimited) grip: the wheels' sideways friction carries the motor's couple
    and the rod's side force at stall (no leg lifts); at mu_wall 1 a held module skids (40 N of push against 20 N
    of grip) and its springs alone cannot carry the couple M_stall / ring_spacing = 20 N per ring."""
    strong = RobotParams(drive="motor", M_stall=2.0, F_n1=20.0, F_n2=20.0)
    assert rules(strong)["lift_at_stall"]["holds"] is True
    assert rules(strong.replace(mu_wall=1.0))["lift_at_stall"]["holds"] is False


def test_the_tightest_bend_grows_with_the_ring_spacing_as_its_square():
    """The wheels' spread off a ring's plane is about b^2 D / (2 R^2) (b = ring_spacing / 2, R >> D): at the
    tightest bend it equals the springs' reach 2 travel, so R ~ b sqrt(D / (4 travel)) there, in proportion to b."""
    p = RobotParams(L=0.1, r=0.03)  # a short rod: the wheels bind before the rod does
    radii = [tightest_bend(p.replace(ring_spacing=s)) for s in (0.2, 0.4)]
    for s, R in zip((0.2, 0.4), radii):
        assert bend_wheel_spread(s / 2, p.wheel_radius, R, p.pipe_diameter) == pytest.approx(
            2 * p.suspension_travel, rel=1e-6)
    assert radii[1] / radii[0] == pytest.approx(2.0, rel=0.05)


def test_a_route_puts_its_bends_into_the_bend_rules(capsys):
    """With mjcf/bend90.toml (one bend of R/D 5): tightest_bend is judged against R/D 5, and bend_scrub is the
    bend's own lift check (core.pipe.bend_lift_check), which the wheels' scrub at mu_wall 0.8 fails and at 0.3
    does not (mjcf/README.md, "Routes": the robot stalls in a tight bend at 0.8 and passes at 0.3)."""
    from ipir_mujoco.core.pipe import bend_lift_check
    from ipir_mujoco.core.route import read_route
    from ipir_mujoco.engine.builders.route_walls import bend_loads
    from ipir_mujoco.resources import mjcf_dir

    path = mjcf_dir() / "bend90.toml"
    route = read_route(path)
    for mu, holds in ((0.3, True), (0.8, False)):
        p = RobotParams(mu_wall=mu)
        r = rules(p, route)
        assert r["tightest_bend"]["limit"] == pytest.approx(route.bends[0].radius / p.pipe_diameter)
        check = bend_lift_check(p, route.bends[0].radius, *bend_loads(route, route.bends[0], p.g))
        assert r["bend_scrub"]["value"] == pytest.approx(min(check["least_press1_n"], check["least_press2_n"]))
        assert r["bend_scrub"]["holds"] is holds
    code, out, _ = run_cli(capsys, "design-check", "--route", str(path), "--set", "mu_wall=0.3")
    assert code == 0 and out.strip().endswith("every rule holds")
