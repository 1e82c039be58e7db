"""Routes for the wheeled MuJoCo model (``--route``): parsing and bad input, the centreline, the closed-form fit
against hand cases, a straight route against the straight pipe, a bend that ends with a reason.

Tolerances are derived where they are used (the centreline's round-off, one output interval, the contact
geometry's round-off)."""

from __future__ import annotations

import json
import math

import pytest

from ipir_mujoco import registry
from ipir_mujoco.analytic import ParameterError, RobotParams
from ipir_mujoco.core.pipe import bend_max_length, bend_rod_clearance, bend_wheel_spread
from ipir_mujoco.core.route import read_route, route_from_tables

CRUISE = RobotParams(drive="motor", mu_wall=0.8)
BEND = [dict(kind="straight", length=0.4), dict(kind="bend", radius=1.0, angle=90.0),
        dict(kind="straight", length=0.5, incline=0.0)]


def test_a_route_file_is_read_into_its_centreline(tmp_path):
    path = tmp_path / "route.toml"
    path.write_text('[[segment]]\nkind = "straight"\nlength = 0.3\n\n[[segment]]\nkind = "bend"\nradius = 1.0\n'
                    'angle = 90\n\n[[segment]]\nkind = "straight"\nlength = 0.5\n')
    route = read_route(path)
    assert route.length == pytest.approx(0.3 + math.pi / 2 + 0.5, rel=1e-15)
    # the bend turns towards +y about a centre at (0.3, 1): it ends at (1.3, 1) heading +y, the exit at (1.3, 1.5)
    x, y, heading = route.at(route.length)
    assert (x, y, heading) == pytest.approx((1.3, 1.5, math.pi / 2), abs=1e-12)
    # a point on the arc's 45-degree radius, 0.05 m off the centreline, projects to the arc's middle
    c = math.cos(math.pi / 4)
    s = route.project(0.3 + 1.05 * c, 1.0 - 1.05 * c)
    assert s == pytest.approx(0.3 + math.pi / 4, abs=1e-12)
    assert "bend 1" in route.where(s)


@pytest.mark.parametrize("tables, word", [
    ([dict(kind="bend", radius=1.0, angle=90)], "a straight first"),
    ([dict(kind="straight", length=-1.0)], "length > 0"),
    ([dict(kind="straight", length=1.0), dict(kind="bend", radius=1.0, angle=0)], "not 0"),
    ([dict(kind="straight", length=1.0), dict(kind="bend", radius=1.0, angle=200)], "<= 180"),
    ([dict(kind="straight", length=1.0), dict(kind="bend", angle=90)], "radius"),
    ([dict(kind="straight", length=1.0, incline=95)], "incline"),
    ([dict(kind="straight", length=1.0, width=2)], "'width' is unknown"),
    ([dict(kind="elbow", length=1.0)], "kind"),
    ([], "1..100 segments"),
    # a plane tilted by 30 degrees: after a 90-degree bend the pipe runs level, not still at 30 degrees
    ([dict(kind="straight", length=1.0, incline=30), dict(kind="bend", radius=1.0, angle=90),
      dict(kind="straight", length=1.0, incline=30)], "allowed: incline = 0"),
])
def test_a_bad_route_is_refused_in_one_line(tables, word):
    with pytest.raises(ParameterError, match=word) as info:
        route_from_tables(tables, "r.toml")
    assert "\n" not in str(info.value) and "allowed" in str(info.value)


def test_the_bend_lift_check_against_hand_cases():
    """The wheels' scrub per ring with 3 legs (leg 0 down, legs 1, 2 at 30 deg above the horizontal): their
    circumferential directions x cross u are (0, 1, 0) and (0, -1/2, +-sqrt(3)/2), so across a horizontal bend
    (toward y) mu P (1 + 1/2 + 1/2) = 2 mu P, across one turning up (toward z) mu P sqrt(3). With no weight, no
    drive, a bend far wider than the ring spacing (its spread and the rod's angle vanish to 1e-6 of P) and the
    scrub along z, the least-pressed leg is the one along it, leg 0: P - (2/3) sqrt(3) mu P, which lifts from
    mu = sqrt(3) / 2."""
    from ipir_mujoco.core.pipe import bend_lift_check, scrub_force

    p = RobotParams(mu_wall=0.6, F_n1=60.0, F_n2=30.0, wheel_legs=3, cornering_coefficient=None)  # rigid wheels
    P1, P2 = 60.0 / 6, 30.0 / 6
    assert scrub_force(p, 0, (1.0, 0.0), 1.0) == pytest.approx(2 * 0.6 * P1, rel=1e-12)
    assert scrub_force(p, 1, (0.0, 1.0), 1e6) == pytest.approx(math.sqrt(3) * 0.6 * P2, rel=1e-12)  # any radius
    quiet = p.replace(drive="torque", M=0.0, F_r1=0.0, F_r2=0.0, m1=1e-9, m2=1e-9)
    check = bend_lift_check(quiet, 1e6, (0.0, 1.0), [(0.0, 0.0)])
    for i, P in ((1, P1), (2, P2)):
        assert check[f"least_press{i}_n"] == pytest.approx(P - 2 / 3 * math.sqrt(3) * 0.6 * P, rel=1e-6)
    assert check["lift_predicted"] is False
    for mu, lifts in ((0.85, False), (0.88, True)):  # either side of sqrt(3) / 2 = 0.866
        assert bend_lift_check(quiet.replace(mu_wall=mu), 1e6, (0.0, 1.0), [(0.0, 0.0)])["lift_predicted"] is lifts


def test_the_wheels_side_force_in_a_bend_against_hand_cases():
    """Steer-compliant wheels (docs/model.md, "The wheels' side force"): wheel k slips at a (e_k . d), a = asin(b /
    R) a ring's slip angle, and pushes min(C |alpha_k|, mu_wall P) along e_k, C = cornering_coefficient P. While
    none slides a ring carries C a n / 2 along d (3 legs: sum (e_k . d)^2 = 1 + 1/4 + 1/4 = 3/2 across a
    horizontal bend), and the module cocks by psi = C_r a / (k_r b) (C_r = 3 C / 2, k_r = 3 P / (2 travel)), so its
    fore ring carries C_r (a + psi). Where every wheel slides, the ring's whole sideways friction (2 mu P across a
    horizontal bend), as rigid wheels at any radius."""
    from ipir_mujoco.core.pipe import bend_lift_check, ring_side_force, scrub_force

    p = RobotParams(mu_wall=0.6, F_n1=60.0, F_n2=30.0, wheel_legs=3, cornering_coefficient=10.0,
                    suspension_travel=0.004, ring_spacing=0.1)
    P1 = 60.0 / 6
    assert ring_side_force(p, 0, (1.0, 0.0), 0.01) == pytest.approx(10.0 * P1 * 0.01 * 1.5, rel=1e-12)
    assert ring_side_force(p, 0, (1.0, 0.0), -0.01) == pytest.approx(-10.0 * P1 * 0.01 * 1.5, rel=1e-12)
    # the bottom wheel (e . d = 1) slides from C alpha = mu P, alpha = 0.06; the upper two (e . d = 1/2) from 0.12
    assert ring_side_force(p, 0, (1.0, 0.0), 0.09) == pytest.approx(0.6 * P1 + 2 * 10.0 * P1 * 0.045 * 0.5, rel=1e-12)
    assert ring_side_force(p, 0, (1.0, 0.0), 0.5) == pytest.approx(2 * 0.6 * P1, rel=1e-12)
    R = 5.0
    a = math.asin(0.05 / R)
    C_r, k_r = 1.5 * 10.0 * P1, 1.5 * P1 / 0.004
    assert scrub_force(p, 0, (1.0, 0.0), R) == pytest.approx(C_r * (a + C_r * a / (k_r * 0.05)), rel=1e-12)
    assert scrub_force(p, 0, (1.0, 0.0), 0.1) == pytest.approx(2 * 0.6 * P1, rel=1e-12)
    # the side force falls as 1 / R, so a gentle bend's lift check tends to the straight pipe's
    quiet = p.replace(drive="torque", M=0.0, F_r1=0.0, F_r2=0.0, m1=1e-9, m2=1e-9)
    far = bend_lift_check(quiet, 1e3, (0.0, 1.0), [(0.0, 0.0)])
    assert far["least_press1_n"] == pytest.approx(P1, rel=1e-3) and far["lift_predicted"] is False


def test_the_closed_form_fits_against_hand_cases():
    """Numbers chosen so that the square roots are exact: a station b = 0.3 m off the module's middle, wheel
    centres on circles of 0.5 m (outer: R + D/2 - R_w) and 0.34 m (inner: R - D/2 + R_w), so 0.4 m and
    0.16 m from the tangent along the station's line: 0.24 m apart where a straight pipe holds them
    D - 2 R_w = 0.16 m apart."""
    assert bend_wheel_spread(0.3, 0.01, 0.42, 0.18) == pytest.approx(0.08, abs=1e-15)
    assert bend_wheel_spread(0.0, 0.01, 0.42, 0.18) == pytest.approx(0.0, abs=1e-15)  # on the radius: D
    # a rectangle 0.1 m wide with its inner side on the inner wall's tangent (0.05 m from the centre, a bend of
    # 0.15 m in a 0.2 m pipe) reaches the outer wall (0.25 m) at a half-length sqrt(0.25^2 - 0.15^2) = 0.2 m
    assert bend_max_length(0.1, 0.15, 0.2) == pytest.approx(0.4, abs=1e-15)
    with pytest.raises(ParameterError, match="radius"):
        bend_wheel_spread(0.025, 0.015, 0.07, 0.16)
    # a rod of 0.6 m as a chord of a 0.5 m centreline: its middle 0.4 m from the centre, where the inner wall of a
    # 0.2 m pipe is; a rod 0.01 m thick crosses it by that much
    assert bend_rod_clearance(0.6, 0.01, 0.5, 0.2) == pytest.approx(-0.01, abs=1e-15)
    assert bend_rod_clearance(1.2, 0.0, 0.5, 0.2) == -math.inf  # longer than the centreline's diameter


@pytest.mark.slow
def test_a_straight_route_runs_as_the_straight_pipe_and_ends_at_its_end():
    """Box walls in place of the planes: the same contacts (capsule against a face at the same distance and
    normal), so the motion is the plane model's to round-off (1e-9 of the travel is far above round-off,
    far below the monitor's 1e-3); a route shorter than the run ends where the plane model's rear module
    crossed its length, to one output interval."""
    dt_out, t_end, length = 1e-3, 1.0, 0.35
    plain = registry.run("mujoco-wheels", CRUISE, t_end, dt_out=dt_out, timestep=1e-4)
    long = registry.run("mujoco-wheels", CRUISE, t_end, dt_out=dt_out, timestep=1e-4,
                        route=route_from_tables([dict(kind="straight", length=0.35), dict(kind="straight", length=4.65)]))
    for key in ("x1_final", "x2_final", "revolutions"):
        assert long.summary[key] == pytest.approx(plain.summary[key], rel=1e-9)
    s = long.summary
    # the robot's centre, midway between A (x1) and C (x2 + the gap S at the start), reached 0.35 m when the plane
    # model's did, to one output interval
    series = plain.series
    centre = 0.5 * (series["x1"] + series["x2"] + series["S"][0])
    crossed = series["t"][centre >= 0.35][0]
    assert crossed - dt_out <= s["route_piece_times_s"][1] <= crossed + 1e-12
    assert s["route_done"] is False and s["route_time_s"] is None and "t_end" in s["route_stop"]
    assert s["route_s_m"] == pytest.approx(plain.series["x1"].max(), rel=1e-9)  # the rear module, along x
    short = registry.run("mujoco-wheels", CRUISE, t_end, dt_out=dt_out, timestep=1e-4,
                         route=route_from_tables([dict(kind="straight", length=length)]))
    s = short.summary
    crossed = plain.series["t"][plain.series["x1"] >= length][0]
    assert s["route_done"] is True and "end" in s["route_stop"]
    assert crossed - dt_out <= s["route_time_s"] <= crossed + 1e-12
    assert short.t_end < t_end


@pytest.mark.slow
def test_a_bend_route_ends_or_stops_with_a_reason_and_the_summary_says_which(capsys, tmp_path):
    """A tight bend (R/D 2, 30 degrees) at mu_wall 0.8: the closed form says a wheel lifts there (the wheels'
    sideways scrub as the modules turn), and MuJoCo's wheels are indeed off their walls for a while; the run
    either reaches the end or stops with one line, and the summary (JSON, and the lines printed without --json)
    says which."""
    from cli_run import run_cli

    path = tmp_path / "bend.toml"
    path.write_text('[[segment]]\nkind = "straight"\nlength = 0.35\n[[segment]]\nkind = "bend"\nradius = 0.32\n'
                    'angle = 30\n[[segment]]\nkind = "straight"\nlength = 0.05\n')
    argv = ("simulate", "--engine", "mujoco", "--mujoco-model", "wheels", "--drive", "motor", "--set", "mu_wall=0.8",
            "--route", path, "--timestep", "5e-5", "--dt-out", "1e-3", "--t-end", "3")
    code, out, err = run_cli(capsys, *argv, "--json")
    assert code == 0 and err == ""
    s = json.loads(out)["summary"]
    assert isinstance(s["route_done"], bool) and s["route_stop"] and "\n" not in s["route_stop"]
    if s["route_done"]:
        assert s["route_time_s"] > 0 and s["route_s_m"] >= s["route_length_m"]
        # the travel is read along the route: the rear module's A from its start (0) to the route's end, to one
        # sample's step of the run's end (its last samples' speed, below 1.2 m/s, times the 1e-3 s interval)
        assert s["x1_final"] == pytest.approx(s["route_s_m"], abs=1.2e-3)
    else:
        assert s["route_time_s"] is None and s["route_s_m"] < s["route_length_m"]
    # the closed form for a module tangent to the bend: its legs reach the spread (83 % of the preload left), but
    # a rolling module's wheels scrub sideways as it turns (mu_wall P per wheel across the pipe: 13.3 N per ring
    # at F_n 50 N), which with the straight pipe's loads lifts a leg; the summary's check knows it
    bend = s["route_fit"]["bends"][0]
    assert bend["wall_press_share"] > 0.8 and not bend["wheels_keep_wall"]
    assert bend["scrub_n"] == pytest.approx([0.8 * 50 / 3] * 2, rel=1e-12)
    assert "may leave the wall in bend 1" in s["route_fit"]["predicted"]
    # the summary's check takes the run's own loads with the bend's (docs/model.md, "Along a route"): a leg below
    # LIFT_SHARE of its preload F_n / 6, as MuJoCo's wheels are off their walls
    from ipir_mujoco.core.wheel_checks import LIFT_SHARE

    floor = LIFT_SHARE * 50 / 6
    assert s["lift_predicted"] is True and min(s["least_press1_n"], s["least_press2_n"]) < floor
    assert s["route_wheel_off_s"] > 0 and s["wheel_off_s"] > 0
    from ipir_mujoco.cli.simulate import route_lines  # what simulate prints without --json

    printed = "\n".join(route_lines(s))
    assert ("route done in" in printed) == s["route_done"] and "closed-form fit" in printed
    # and printed without --json: the same lines from a 0.2 s run of the same route (the 3 s run above is what
    # the summary's checks need; the printed lines are there from a route run's first stroke)
    code, out, err = run_cli(capsys, *argv[:-1], "0.2")
    assert code == 0 and "module 1 (rear) moved" in out and "m along the route" in out


@pytest.mark.slow
def test_a_robot_that_makes_no_progress_or_slides_out_stops_with_the_reason(monkeypatch):
    """A horizontal pipe with a grip of half the rolling resistance (mu_wall 0.01: 0.5 N against F_r = 1 N): the
    held module cannot hold the other's resistance, the crank turns and the robot gets nowhere; the run stops
    after the watch's window (shortened here to keep the test fast) with the reason in one line. A riser with a
    grip of a quarter of the weight: the robot slides down and out of the pipe behind the route's start."""
    from ipir_mujoco.engine.modelkinds import route_watch

    monkeypatch.setattr(route_watch, "PROGRESS_S", 0.3)
    route = route_from_tables([dict(kind="straight", length=1.0)])
    run = registry.run("mujoco-wheels", RobotParams(drive="motor", mu_wall=0.01), 2.0, dt_out=1e-3, timestep=5e-5,
                       route=route, accuracy="warn")
    s = run.summary
    assert s["route_done"] is False and s["route_stop"].startswith("stalled") and "crank turned" in s["route_stop"]
    assert "\n" not in s["route_stop"] and run.t_end < 1.0 and s["route_s_m"] < 0.1
    riser = route_from_tables([dict(kind="straight", length=1.0, incline=90.0)])
    run = registry.run("mujoco-wheels", RobotParams(drive="motor", mu_wall=0.05), 2.0, dt_out=1e-3, timestep=5e-5,
                       route=riser, accuracy="warn")
    s = run.summary
    assert s["route_done"] is False and s["route_stop"].startswith("slid back out of the pipe")
    assert run.params.incline == 90.0 and run.series["x1"][-1] < -route_watch.BACK_OUT + 1e-12


def test_only_the_wheeled_model_and_the_exact_equations_take_a_route(capsys, tmp_path):
    from cli_run import run_cli

    good = tmp_path / "r.toml"
    good.write_text('[[segment]]\nkind = "straight"\nlength = 1\n')
    bad = tmp_path / "bad.toml"
    bad.write_text('[[segment]]\nkind = "bend"\nradius = 1\nangle = 90\n')
    tight = tmp_path / "tight.toml"
    tight.write_text('[[segment]]\nkind = "straight"\nlength = 1\n[[segment]]\nkind = "bend"\nradius = 0.05\n'
                     'angle = 90\n')
    short = tmp_path / "short.toml"
    short.write_text('[[segment]]\nkind = "straight"\nlength = 0.1\n[[segment]]\nkind = "bend"\nradius = 1\n'
                     'angle = 90\n')
    wheels = ("--engine", "mujoco", "--mujoco-model", "wheels")
    for argv, word in ((("--engine", "mujoco", "--route", good), "--mujoco-model wheels"),
                       (("--geometry", "approx", "--route", good), "--geometry exact"),
                       ((*wheels, "--route", bad), "a straight first"),
                       ((*wheels, "--route", tight), "radius > pipe_diameter / 2"),
                       ((*wheels, "--route", tmp_path / "none.toml"), "does not exist"),
                       ((*wheels, "--route", good, "--until-steady", "--drive", "motor"), "--until-steady"),
                       ((*wheels, "--route", good, "--set", "incline=10"), "incline"),
                       ((*wheels, "--route", short), "length >= 0.315 m")):  # L + r + ring_spacing / 2 + R
        code, out, err = run_cli(capsys, "simulate", *argv)
        assert code == 2 and word in err and len(err.strip().splitlines()) == 1, (argv, err)
    with pytest.raises(ParameterError, match="wheeled"):
        registry.run("mujoco-ratchet", CRUISE, 0.1, route=route_from_tables(BEND))


def test_the_viewer_builds_the_route_walls():
    """The interactive viewer's robot (no screen needed to build and step it) carries the route's walls."""
    from ipir_mujoco.cli.view import ViewedRobot
    from ipir_mujoco.engine.builders.model import SolverSettings

    robot = ViewedRobot(CRUISE, model="wheels", route=route_from_tables(BEND), settings=SolverSettings(timestep=1e-4))
    names = {robot.model.geom(i).name for i in range(robot.model.ngeom)}
    assert {"pipe_straight1", "pipe_bend1", "pipe_straight2"} <= names  # the round pipe's pieces along the route
    assert sum(1 for n in names if n.startswith(("pipe_straight", "pipe_bend"))) == 3  # and no straight pipe
    robot.step(200)


def test_the_bend_study_writes_its_table_and_figure_and_refuses_bad_ratios(capsys, tmp_path):
    """From a study record (the shape run_study gives): the CSV's columns, the table's rows and the figure's
    points, each the record's numbers over the analytic prediction; bad R/D values are refused in one line."""
    import csv

    from cli_run import run_cli
    from matplotlib.figure import Figure

    from ipir_mujoco.cli.bend_study import COLUMNS, format_table, write_csv
    from ipir_mujoco.report.bend_figure import bend_figure

    def passage(time_s, energy_j, keeps):
        return {"time_s": time_s, "energy_j": energy_j, "passed": True, "route_stop": "reached the route's end",
                "route_wheel_off_s": 0.0, "route_module_off_s": 0.0, "route_arm_reach": 0.5, "residual_ratio": 1e-4,
                "skid_j": 0.0, "predicted": "passes" if keeps else "a wheel leaves the wall", "wheels_keep_wall": keeps}

    rows = [{"R_over_D": r, "radius_m": 0.16 * r, "window_m": w, "bend": passage(tb, eb, r > 2),
             "straight": passage(ts, es, True), "analytic": {"time_s": ta, "energy_j": ea},
             "equations": {"time_s": qt, "energy_j": qe, "scrub_j": 0.1, "route_stop": "reached the route's end"},
             "equations_straight": {"time_s": ta, "energy_j": ea},
             "mujoco_vs_equations": {"time_s": tb / qt - 1, "energy_j": eb / qe - 1, "outcome": "miss"}}
            for r, w, tb, eb, ts, es, ta, ea, qt, qe in ((2.0, 0.7, 1.2, 0.9, 1.3, 1.4, 1.32, 1.41, 1.25, 1.0),
                                                         (5.0, 1.46, 2.74, 2.91, 2.73, 2.91, 2.735, 2.913, 2.75, 2.9))]
    study = {"rows": rows, "reference": {"steady_speed_m_s": 0.53, "energy_per_metre_j_m": 2.0},
             "settings": {"params": RobotParams(mu_wall=0.8).as_dict()}}
    write_csv(tmp_path / "s.csv", study)
    with open(tmp_path / "s.csv") as f:
        read = list(csv.DictReader(f))
    assert tuple(read[0]) == COLUMNS and float(read[1]["bend_time_s"]) == 2.74
    assert float(read[1]["equations_time_s"]) == 2.75
    assert float(read[0]["mujoco_vs_equations_time"]) == pytest.approx(1.2 / 1.25 - 1, rel=1e-12)
    table = format_table(study)
    assert "2.74 / 2.73 / 2.735" in table and "2.75 / 2.735, 2.9 / 2.913" in table
    assert "-4.00 %, -10.00 %: miss" in table and read[0]["mujoco_vs_equations"] == "miss"
    fig = bend_figure(study)
    assert isinstance(fig, Figure)
    bend = [a for ax in fig.axes for a in ax.get_lines() if a.get_gid() == "bend:time"][0]
    assert list(bend.get_ydata()) == pytest.approx([1.2 / 1.32, 2.74 / 2.735], rel=1e-12)
    equations = [a for ax in fig.axes for a in ax.get_lines() if a.get_gid() == "equations:energy"][0]
    assert list(equations.get_ydata()) == pytest.approx([1.0 / 1.41, 2.9 / 2.913], rel=1e-12)
    for argv, word in ((("--ratios", "0.4"), "--ratios"), (("--ratios", "1,abc"), "--ratios"),
                       (("--planes", "200"), "--planes"),
                       (("--set", "pipe_diameter=0.05"), "pipe_diameter")):  # refused before any run or progress
        code, out, err = run_cli(capsys, "bend-study", *argv, "--out", tmp_path / "o")
        assert code == 2 and word in err and len(err.strip().splitlines()) == 1, (argv, err)
    assert not (tmp_path / "o").exists()


def test_the_automatic_step_knows_a_route_with_bends():
    """A route with a bend steps at a quarter of the rows' shortest time constant (the wheels' sideways scrub in a
    bend converges only there: mjcf/README.md), a straight route and the straight pipe at half of it."""
    from ipir_mujoco.engine.builders.wheels_model import ROW_TIMES

    tau = ROW_TIMES.shortest()
    bend = route_from_tables(BEND, "bend.toml")
    straight = route_from_tables([dict(kind="straight", length=1.0)], "straight.toml")
    assert registry.timestep("mujoco-wheels", CRUISE, 1.0, 1e-3, route=bend) == pytest.approx(tau / 4, rel=1e-12)
    for route in (straight, None):
        assert registry.timestep("mujoco-wheels", CRUISE, 1.0, 1e-3, route=route) == pytest.approx(tau / 2, rel=1e-12)


def test_a_stall_line_names_a_module_cocked_in_its_pipe():
    """A module turned 10 deg about z off a straight pipe's axis is cocked (beyond COCKED_DEG); one turned 2 deg,
    or the robot as it starts, is not."""
    import mujoco

    from ipir_mujoco.engine.builders.wheels_model import build_wheels_model, set_wheels_state
    from ipir_mujoco.engine.modelkinds.route_watch import COCKED_DEG, RouteWatch

    route = route_from_tables([dict(kind="straight", length=1.0)], "straight.toml")
    model = build_wheels_model(CRUISE, route=route)
    data = mujoco.MjData(model)
    set_wheels_state(model, data, CRUISE)
    watch = RouteWatch(route, model, None, {"bends": [], "predicted": ""}, 1e-3)
    assert watch.cocked(data.qpos, (0.0, 0.25)) is None
    adr = model.jnt_qposadr[model.joint("rear_tilt").id]
    for degrees, words in ((10.0, "module 1 cocked 10 deg off the pipe's axis"), (2.0, None)):
        assert (degrees > COCKED_DEG) == (words is not None)
        half = math.radians(degrees) / 2
        data.qpos[adr:adr + 4] = [math.cos(half), 0.0, 0.0, math.sin(half)]
        assert watch.cocked(data.qpos, (0.0, 0.25)) == words


def test_a_stall_says_what_unlimited_grip_does_only_with_the_robot_in_a_bend():
    """RouteWatch.in_bend: a bend lying between the rear wheels (A less ring_reach) and the front wheels (C plus it)
    on bend90.toml's layout (a 0.4 m straight, a bend of 0.8 m radius and 90 deg, 0.3 m straight): the stall line
    adds what unlimited grip does there only then, and only with unlimited grip."""
    from ipir_mujoco.engine.builders.wheels_model import build_wheels_model
    from ipir_mujoco.engine.modelkinds.route_watch import RouteWatch

    route = route_from_tables([dict(kind="straight", length=0.4), dict(kind="bend", radius=0.8, angle=90.0),
                               dict(kind="straight", length=0.3)], "bend90.toml")
    bend_end = 0.4 + 0.8 * math.pi / 2
    model = build_wheels_model(CRUISE, route=route)
    watch = RouteWatch(route, model, None, {"bends": [], "predicted": ""}, 1e-3, unlimited_grip=True, ring_reach=0.06)
    assert not watch.in_bend(0.0, 0.33)  # the front wheels 0.39 m along: still in the first straight
    assert watch.in_bend(0.0, 0.35)  # 0.41 m: in the bend
    assert watch.in_bend(bend_end + 0.05, bend_end + 0.3)  # the rear wheels 0.01 m before the bend's end
    assert not watch.in_bend(bend_end + 0.07, bend_end + 0.3)  # all of the robot past it


def test_a_route_of_long_bends_builds_one_piece_per_bend():
    """40 half turns of 100 m radius, in alternating planes: the round pipe builds each bend as one piece, whatever
    its radius or plane (nothing about the walls grows with a bend's size)."""
    from ipir_mujoco.engine.builders.wheels_model import build_wheels_model

    tables = [dict(kind="straight", length=0.5)] + [dict(kind="bend", radius=100.0, angle=(-1) ** k * 180.0,
                                                          plane=90.0 * (k % 2)) for k in range(40)]
    route = route_from_tables(tables, "r.toml")
    model = build_wheels_model(CRUISE, route=route)
    assert sum(1 for g in range(model.ngeom) if model.geom(g).name.startswith("pipe_bend")) == 40


def test_a_bend_faster_than_its_twin_says_why_with_the_runs_numbers():
    """The bend study's note: a bend more than TWIN_SLACK faster than its straight twin is explained by its
    wheels' time off the wall, or (all wheels on it) by the passage's timing ripple; a slower one has no note."""
    from ipir_mujoco.studies.bend_study import TWIN_SLACK, twin_note

    twin = {"time_s": 1.0}
    off = {"time_s": 0.9, "route_wheel_off_s": 0.92, "route_module_off_s": 0.13}
    assert "10.0 % faster" in twin_note(off, twin) and "off their walls 0.920 s" in twin_note(off, twin)
    assert "timing ripple" in twin_note({"time_s": 0.99, "route_wheel_off_s": 0.0}, twin)
    assert twin_note({"time_s": 1.0 - 0.5 * TWIN_SLACK, "route_wheel_off_s": 1.0}, twin) is None
    assert twin_note({"time_s": None}, twin) is None


def test_the_wall_budget_covers_building_the_model():
    """A budget no build can meet (1 ns: compiling any model takes far longer) ends the run before its first
    step, saying so in one line."""
    from ipir_mujoco.core.errors import SimulationError

    with pytest.raises(SimulationError, match="while building its model") as info:
        registry.run("mujoco-wheels", CRUISE, 1.0, route=route_from_tables(BEND), wall_budget_s=1e-9)
    assert "\n" not in str(info.value)
