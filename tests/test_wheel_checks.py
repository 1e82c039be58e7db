"""The round-pipe robot's rings under the linkage's loads (core.wheel_checks): closed forms, no simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ipir_mujoco.core import wheel_checks as W
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.pipe import SCRUB_FLOOR, leg_direction, sprung_mass

GRIP = RobotParams(mu_wall=0.5, F_n1=30.0, F_n2=40.0, g=0.0)  # weightless: the wheels' friction alone


def test_a_ring_holds_a_load_inside_its_wheels_friction_zonotope_and_nothing_while_it_skids():
    """With 3 legs at 120 deg each facet of the zonotope is normal to a leg: along leg j the wheels hold
    mu P sum_k |e_k . u_j| = mu P (0 + 2 sin 120 deg) = sqrt(3) mu P; a load a hair inside it holds, a hair
    outside does not, whatever its direction (the legs' directions and the directions between them)."""
    P = GRIP.F_n1 / 6
    edge = math.sqrt(3) * GRIP.mu_wall * P
    assert W.side_holds(GRIP, 0) == pytest.approx(np.full(3, edge), rel=1e-12)
    u, _ = W.leg_frames(3)
    for j in range(3):
        along = edge * u[j]
        assert W.held(GRIP, 0, along * (1 - 1e-9)) and not W.held(GRIP, 0, along * (1 + 1e-9))
    # the facets' normals are +-u_j, 60 deg apart; half-way between two of them (across the crank's plane, +y, between
    # leg 1 at +30 deg and the opposite of leg 2 at -30 deg) the zonotope reaches edge / cos 30 deg
    corner = edge / math.cos(math.radians(30)) * np.array([1.0, 0.0])
    assert W.held(GRIP, 0, corner * (1 - 1e-9)) and not W.held(GRIP, 0, corner * (1 + 1e-9))
    # Coulomb's cone: with the share g of the grip used along the pipe, sqrt(1 - g^2) of it is left across
    assert W.held(GRIP, 0, 0.599 * edge * u[0], grip_use=0.8) and not W.held(GRIP, 0, 0.601 * edge * u[0], grip_use=0.8)
    assert not W.held(GRIP, 0, 1e-9 * u[0], grip_use=1.0)  # skidding: nothing across
    assert W.held(GRIP.replace(mu_wall=None), 0, 1e6 * u[0], grip_use=1.0)  # unlimited grip never skids


def test_ring_loads_carry_the_linkage_force_and_the_motors_couple():
    """Module 1's rings take its force across the pipe half each and the motor's reaction -T about z as a couple
    (moment about A of the two rings' loads = -T); module 2's rings half of its force each."""
    p = RobotParams(ring_spacing=0.12)
    side1, side2, T = np.array([-3.0, 1.0]), np.array([2.5, -4.0]), np.array([0.7, -0.2])
    loads = W.ring_loads(p, side1, side2, T, vertical1=np.array([0.4, 0.0]), vertical2=-1.0)
    aft, fore = loads["1aft"], loads["1fore"]
    assert aft[:, 0] + fore[:, 0] == pytest.approx(side1, rel=1e-12)
    assert 0.5 * p.ring_spacing * (fore[:, 0] - aft[:, 0]) == pytest.approx(-T, rel=1e-12)
    assert aft[:, 1] + fore[:, 1] == pytest.approx([0.4, 0.0], abs=1e-15)
    assert loads["2aft"] == pytest.approx(loads["2fore"]) and loads["2aft"][:, 0] == pytest.approx(side2 / 2)
    assert loads["2aft"][:, 1] == pytest.approx([-0.5, -0.5])


def test_a_leg_lifts_where_the_springs_load_along_it_reaches_a_quarter_of_the_press():
    """Beyond the wheels' friction the springs carry the load: leg j's press is P + (2 / n) F . u_j, 0 where
    F . u_j = -F_n / 4, whatever n (3 and 5 legs), with the module skidding (no friction across); the check says
    a lift from LIFT_SHARE of the preload on, where the run counts a wheel off its wall."""
    for n in (3, 5):
        p = GRIP.replace(wheel_legs=float(n))
        u = np.array(leg_direction(0, n)[1:])
        for scale, lifts in ((1 - 1e-9, True), (1 - W.LIFT_SHARE * (1 + 1e-9), False),
                             (1 - W.LIFT_SHARE * (1 - 1e-9), True)):
            load = -scale * p.F_n1 / 4 * u
            loads = {"1aft": load[None, :], "1fore": np.zeros((1, 2)), "2aft": np.zeros((1, 2)),
                     "2fore": np.zeros((1, 2))}
            result = W.check(p, loads, grip_use=(1.0, 1.0))
            assert result["least_press1_n"] == pytest.approx(p.F_n1 / (2 * n) * (1 - scale), abs=1e-9)
            assert result["lift_predicted"] is lifts
            # one sample: no path on the springs; a lift is a slide all the same (its wheel rides off the wall
            # with its ring, the suspension's whole travel across the pipe)
            assert result["slid1_m"] == 0.0 and result["scrub_predicted"] is lifts
    # the same load within the wheels' grip (the module rolls): the ring does not move, no leg lifts
    load = -0.9 * GRIP.F_n1 / 4 * np.array(leg_direction(0, 3)[1:])
    assert np.abs(load @ W.leg_frames(3)[0].T).max() > W.side_holds(GRIP, 0).max()  # beyond the grip: it slides
    held = GRIP.replace(mu_wall=2.0)
    loads = {"1aft": load[None, :], "1fore": np.zeros((1, 2)), "2aft": np.zeros((1, 2)), "2fore": np.zeros((1, 2))}
    assert W.check(held, loads)["least_press1_n"] == pytest.approx(held.F_n1 / 6, rel=1e-12)


def test_the_weight_stays_on_the_springs_and_lifts_the_upper_legs_at_F_n():
    """With leg 0 down the upper legs (30 deg above the horizontal) lift where the sprung weight reaches F_n
    (3 legs), friction or none: the robot starts at rest sagged on its springs."""
    p = RobotParams(mu_wall=1.0, F_n1=20.0, F_n2=20.0)
    zero = {key: np.zeros((1, 2)) for key in ("1aft", "1fore", "2aft", "2fore")}
    W_sprung = sprung_mass(p, 0) * p.g
    least = W.check(p, zero)["least_press1_n"]
    assert least == pytest.approx(p.F_n1 / 6 - W_sprung / 6, rel=1e-12)
    heavy = p.replace(m1=1.01 * p.F_n1 / (p.g * sprung_mass(p, 0) / p.m1))
    assert W.check(heavy, zero)["lift_predicted"] is True


def test_a_ring_on_its_springs_follows_a_load_as_a_mass_on_springs():
    """Undamped: a load held from rest moves the ring to twice its static place at half a period and back; a load
    held for a tenth of a period moves it by about (omega t)^2 / 2 of its static place, far less; while the wheels
    hold the ring stays where it is."""
    steps = 2000
    step = 2 * math.pi / 1000  # a period per 1000 samples
    load = np.zeros((steps, 2))
    load[:, 0] = 1.0
    place = W.ring_response(load, np.zeros(steps, dtype=bool), step)
    assert place[:, 0].max() == pytest.approx(2.0, rel=1e-6) and place[500, 0] == pytest.approx(2.0, rel=1e-6)
    assert place[1000, 0] == pytest.approx(0.0, abs=1e-9)
    short = np.zeros((steps, 2))
    short[:100, 0] = 1.0  # a tenth of a period
    peak = W.ring_response(short, np.zeros(steps, dtype=bool), step)[:, 0].max()
    assert peak == pytest.approx(2 * math.sin(math.pi * 0.1), rel=1e-6)  # 0.618 of the static 1, not 2
    hold = np.zeros(steps, dtype=bool)
    hold[:250] = True
    assert np.all(W.ring_response(load, hold, step)[:251, 0] == 0.0)


def test_the_wheels_friction_at_the_wall_pitches_a_module_with_its_weight_across():
    """mu (D / 2) W / s on each ring, along the weight, at the whole grip; none with unlimited grip."""
    p = RobotParams(mu_wall=0.6, ring_spacing=0.08, m1=2.0)
    W_sprung = sprung_mass(p, 0) * p.g
    assert W.pitch_couple(p, 0) == pytest.approx([0.0, -0.6 * 0.08 * W_sprung / 0.08], rel=1e-12)
    assert not W.pitch_couple(p.replace(mu_wall=None), 0).any()


def test_the_predicted_slide_is_the_path_the_springs_place_the_ring_on():
    """A skidding module whose ring load swings from +F to -F across the pipe and back slides 2 x 2 x 2F / (n k)."""
    p = RobotParams(mu_wall=0.5, g=0.0)
    k = p.F_n1 / 6 / p.suspension_travel
    F = 0.5 * p.F_n1 / 6
    swing = np.array([[F, 0.0], [-F, 0.0], [F, 0.0]])
    loads = {"1aft": swing, "1fore": np.zeros((3, 2)), "2aft": np.zeros((3, 2)), "2fore": np.zeros((3, 2))}
    result = W.check(p, loads, grip_use=(np.ones(3), np.zeros(3)))
    assert result["slid1_m"] == pytest.approx(2 * 2 * F * 2 / (3 * k), rel=1e-12)
    assert result["scrub_predicted"] is (result["slid1_m"] >= SCRUB_FLOOR)
    assert result["slid2_m"] == 0.0


def test_the_rings_motion_in_closed_form_is_the_step_by_step_recurrence():
    """ring_response sums each sliding stretch in closed form; stepped sample by sample (each interval turns
    (place - load, velocity / omega) by -omega dt; at rest where the wheels hold) it is the same to round-off,
    over random loads and holds."""
    def stepped(spring, grip, step):
        c, s = math.cos(step), math.sin(step)
        out, x, v = np.empty_like(spring), [0.0, 0.0], [0.0, 0.0]
        for j, (load, hold) in enumerate(zip(spring.tolist(), grip.tolist())):
            out[j] = x
            if hold:
                v = [0.0, 0.0]
                continue
            for a in (0, 1):
                y = x[a] - load[a]
                x[a], v[a] = load[a] + y * c + v[a] * s, v[a] * c - y * s
        return out

    rng = np.random.default_rng(7)
    for share in (0.0, 0.2, 0.6, 1.0):
        spring = rng.normal(size=(2000, 2))
        grip = rng.random(2000) < share
        assert np.abs(W.ring_response(spring, grip, 0.05) - stepped(spring, grip, 0.05)).max() < 1e-12


def test_the_constant_press_measures_say_the_wheels_grip_as_mujoco_has_it():
    """The atlas's constant-press pair notes the wheeled run's grip (mu_wall x measured press) against the
    slides' mu_wall F_n; the validation report's sentence on the wheeled rung says the press and grip too."""
    from ipir_mujoco.studies.atlas_space import IDEALIZATIONS, measure
    from ipir_mujoco.studies.validate import _press

    params = RobotParams(mu_wall=0.5, F_n1=30.0, F_n2=40.0)
    out = measure(IDEALIZATIONS["constant-press"].mujoco, params, ("revolutions",), 0.05, False)
    assert out["error"] == "" and "mujoco-wheels: grip " in out["note"]
    assert "against mu_wall F_n 15 / 20 N" in out["note"]
    summary = {"press1_n": 30.2, "press2_n": 40.1, "wheel_off_s": 0.0, "grip1_n": 15.1, "grip2_n": 20.05}
    assert _press(summary) == ("the wheels pressed 30.2 / 40.1 N on the mean, a wheel off its wall 0 s, a grip of "
                               "15.1 / 20.05 N (mu_wall x press)")
    assert "grip" not in _press({**summary, "grip1_n": None})


def one_ring(spring, still, omega, dt, damping, walls=None):
    """rings_motion for one ring (the other still, no heading): (place, slid)."""
    count = len(spring)
    places, slid = W.rings_motion([spring, np.zeros((count, 2))], [still, np.ones(count, dtype=bool)],
                                  [np.broadcast_to(damping, (count,)), np.zeros(count)], omega, dt, 0.0, walls)
    return places[0], slid[0]


@pytest.mark.parametrize("zeta", [0.1, 0.7, 3.0])
def test_a_rolling_rings_creep_is_a_damped_mass_on_springs(zeta):
    """A ring with damping 2 zeta omega from rest under a load held: the textbook step response (under- and
    overdamped), to round-off; with no damping it is ring_response's undamped motion; a still sample keeps it."""
    omega, dt, steps = 70.0, 1e-3, 400
    load = np.zeros((steps, 2))
    load[:, 1] = -2.0
    place, slid = one_ring(load, np.zeros(steps, dtype=bool), omega, dt, 2 * zeta * omega)
    t = dt * np.arange(steps)
    h = zeta * omega
    if zeta < 1:
        wd = omega * math.sqrt(1 - zeta ** 2)
        step = 1 - np.exp(-h * t) * (np.cos(wd * t) + h / wd * np.sin(wd * t))
    else:
        l1, l2 = -h + omega * math.sqrt(zeta ** 2 - 1), -h - omega * math.sqrt(zeta ** 2 - 1)
        step = 1 - (l2 * np.exp(l1 * t) - l1 * np.exp(l2 * t)) / (l2 - l1)
    assert np.abs(place[:, 1] - (-2.0) * step).max() < 1e-12 and not place[:, 0].any() and not slid.any()
    rng = np.random.default_rng(5)
    spring, still = rng.normal(size=(300, 2)), rng.random(300) < 0.3
    free, slides = one_ring(spring, still, omega, dt, 0.0)
    assert np.abs(free - W.ring_response(spring, still, omega * dt)).max() < 1e-12 and (slides == ~still).all()


def test_a_creeping_ring_slides_where_its_wheels_side_force_would_pass_their_friction():
    """Heavily damped (a slow roll), as the ring gathers speed under a load applied at once the damper takes most
    of it (its force damping x the place's speed / omega^2); beyond the wheels' friction they slide, their
    friction (less than the damper's force) against the ring's way, so the ring runs ahead of the damped one until
    the damper's force falls back within the friction. With no end to the friction (walls None) it never slides."""
    omega, dt, steps = 70.0, 1e-4, 2000
    load = np.zeros((steps, 2))
    load[:, 0] = 8.0
    walls = W.wheel_walls(GRIP, 0)  # along y 2 mu P = 5 N at the preload (legs at -90, 30, 150 deg), below 8 N
    damped, never = one_ring(load, np.zeros(steps, dtype=bool), omega, dt, 6 * omega)
    place, slid = one_ring(load, np.zeros(steps, dtype=bool), omega, dt, 6 * omega, walls)
    assert not never.any() and slid.any() and not slid[-1]
    assert place[50, 0] > damped[50, 0] and place[-1, 0] < 8.0


def test_a_rolling_module_yawed_by_a_couple_steers_both_rings_the_way_its_nose_points():
    """A couple +-F on the aft and fore rings of a rolling module: it yaws on its springs by psi = (d_fore - d_aft)
    / s, and its wheels, rolling along its axis, push both rings the way the nose points, C_r psi each, so at
    rest on its springs the rings carry X_aft = F_aft + sigma (F_fore - F_aft), X_fore = F_fore + sigma (F_fore -
    F_aft), sigma = C_r / (k_r s) = cornering_coefficient suspension_travel / ring_spacing: the fore ring carries
    (1 + 2 sigma) F, 1.8 F at the defaults."""
    p = GRIP
    sigma = p.cornering_coefficient * p.suspension_travel / p.ring_spacing
    steps, F = 6000, 1.0
    aft, fore = np.zeros((steps, 2)), np.zeros((steps, 2))
    aft[:, 0], fore[:, 0] = F, -F
    still = np.zeros(steps, dtype=bool)
    damping = np.full(steps, 150.0)  # about critical at omega = 70 rad/s
    places, slid = W.rings_motion([aft, fore], [still, still], [damping, damping], 70.0, 1e-3, sigma)
    assert places[0][-1, 0] == pytest.approx(F - 2 * sigma * F, rel=1e-6)
    assert places[1][-1, 0] == pytest.approx(-F - 2 * sigma * F, rel=1e-6) and sigma == pytest.approx(0.4)
    assert not slid[0].any() and not slid[1].any()
    # the check at rest (dt None) puts the same on the springs: module 1 rolling, its fore ring's leg at +30 deg
    # (u . y = cos 30 deg) loses (2 / 3) (1 + 2 sigma) F cos 30 deg of its preload
    loads = {"1aft": aft[:1], "1fore": fore[:1], "2aft": np.zeros((1, 2)), "2fore": np.zeros((1, 2))}
    static = W.check(p, loads, rolling=(True, False))
    assert static["least_press1_n"] == pytest.approx(
        p.F_n1 / 6 - 2 / 3 * (1 + 2 * sigma) * F * math.cos(math.radians(30)), rel=1e-12)


def test_a_rolling_modules_steer_compliant_wheels_let_its_ring_roll_across_to_its_springs():
    """A load across the pipe inside the wheels' friction: a standing module's wheels hold it (no press change);
    rolling at 0.5 m/s its steer-compliant wheels creep (a damped ring), its springs take the load, so its
    least-pressed leg loses (2 / n) F of press, without a slide; rigid wheels hold it rolling too."""
    p = GRIP
    P = p.F_n1 / 6
    F = 0.9 * math.sqrt(3) * p.mu_wall * P  # along leg 0's opposite: inside the zonotope
    steps = 4000
    loads = {k: np.zeros((steps, 2)) for k in ("1aft", "1fore", "2aft", "2fore")}
    loads["1aft"][:, 1] = loads["1fore"][:, 1] = F  # up on both rings, against leg 0 (down): no yaw
    rolls = (np.ones(steps, dtype=bool), np.zeros(steps, dtype=bool))
    speed = (np.full(steps, 0.5), np.zeros(steps))
    standing = W.check(p, loads, dt=1e-3)
    rolling = W.check(p, loads, rolling=rolls, dt=1e-3, speed=speed)
    rigid = W.check(p.replace(cornering_coefficient=None), loads, rolling=rolls, dt=1e-3, speed=speed)
    assert standing["least_press1_n"] == pytest.approx(P, rel=1e-12) == rigid["least_press1_n"]
    assert rolling["least_press1_n"] == pytest.approx(P - 2 / 3 * F, rel=1e-3)  # settled on its springs
    assert rolling["slid1_m"] == 0.0 and not rolling["scrub_predicted"]


def test_a_rolling_modules_wheel_that_cannot_turn_its_hub_skids_and_scrubs():
    """A wheel turns on the wall only while its friction mu_wall N can turn its hub against its share of the
    rolling resistance, F_r / (2 n) (the hub's frictionloss): weightless, every leg at its preload P = F_n / 6, so
    a rolling module's wheels skid from F_r = 6 mu_wall P on (a hair either side here), and the check says a
    scrub with no slide on the springs and no lift; a standing module's wheels need not turn."""
    p = GRIP
    P = p.F_n1 / 6
    zero = {key: np.zeros((1, 2)) for key in ("1aft", "1fore", "2aft", "2fore")}
    for factor, stuck in ((1 - 1e-9, False), (1 + 1e-9, True)):
        q = p.replace(F_r1=factor * 6 * p.mu_wall * P)
        rolling = W.check(q, zero, rolling=(True, False))
        assert rolling["stuck1"] is stuck and rolling["scrub_predicted"] is stuck and not rolling["stuck2"]
        assert rolling["slid1_m"] == 0.0 and not rolling["lift_predicted"]
        standing = W.check(q, zero)
        assert not standing["stuck1"] and not standing["scrub_predicted"]
    assert not W.check(p.replace(mu_wall=None, F_r1=5.0), zero, rolling=(True, True))["stuck1"]  # unlimited grip


def test_a_rolling_modules_stuck_wheels_skid_at_the_wall_and_pitch_it():
    """A heavy module's upper wheels press least: where their friction mu N cannot turn their hubs against F_r /
    (2 n) and the lower wheel's can, the two upper wheels of each ring skid along the pipe, mu N_up each at the wall
    D / 2 out along legs at 30 and 150 deg (u_z = 1/2 each): the rings carry 2 mu (D / 2) N_up / s along z, down on
    the aft ring (a friction against the way, at the top); nothing with unlimited grip or with every wheel turning."""
    p = RobotParams(mu_wall=0.5, m1=1.0, F_n1=12.0, ring_spacing=0.1)
    N_up, N_down = W.leg_presses(p, 0, W.weight_load(p, 0))[[1, 0]]
    stuck = p.replace(F_r1=6 * p.mu_wall * 0.5 * (N_up + N_down))  # between the two: the upper wheels stick
    assert N_up < N_down
    expected = 2 * p.mu_wall * 0.5 * p.pipe_diameter * N_up / p.ring_spacing
    assert W.stuck_couple(stuck, 0) == pytest.approx([0.0, expected], abs=1e-12 * expected)
    assert not W.stuck_couple(p.replace(F_r1=6 * p.mu_wall * 0.99 * N_up), 0).any()  # all turn
    assert not W.stuck_couple(stuck.replace(mu_wall=None), 0).any()
    zero = {key: np.zeros((1, 2)) for key in ("1aft", "1fore", "2aft", "2fore")}
    rigid = stuck.replace(cornering_coefficient=None)  # held by its wheels' friction: the couple moves nothing
    assert W.check(rigid, zero, rolling=(True, False))["least_press1_n"] == pytest.approx(N_up, rel=1e-12)
    # steer-compliant wheels rolling: the rings creep onto their springs, -+e on aft and fore, and the heading steers
    # both by sigma (X_fore - X_aft) = 2 sigma e up: the aft ring carries -(1 - 2 sigma) e, its upper legs losing
    # (2 / n) u_z of it
    sigma = stuck.cornering_coefficient * stuck.suspension_travel / stuck.ring_spacing
    rolling = W.check(stuck, zero, rolling=(True, False))
    assert rolling["least_press1_n"] == pytest.approx(N_up - 2 / 3 * (1 - 2 * sigma) * expected * 0.5, rel=1e-9)
