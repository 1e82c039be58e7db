"""Finite grip: a held module's locked wheels hold at most G_i = mu_wall F_ni, beyond that it skids back.

The rigid one-way model with grip (analytic/grip_model.py), the compliant one (analytic/compliant_grip.py),
the summary keys and the parameters. docs/model.md, "Finite grip", has the equations and the hand
checks these tests repeat.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from ipir_mujoco import analytic
from ipir_mujoco.analytic import ParameterError, RobotParams, kernels
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.grip_model import GripMode, GripModel
from ipir_mujoco.core.params import load_params
from ipir_mujoco.core.results import COLUMNS

RTOL = 1e-10  # the solvers' default relative tolerance
MOTOR = dict(drive="motor")
CRUISE_GRIP = dict(mu_wall=0.5, F_n1=10.0, F_n2=10.0)  # G = 5 N against ~12 N of demand at the motor's cruise
RISER_GRIP = dict(incline=90.0, mu_wall=0.3, F_n1=20.0, F_n2=20.0)  # G1 + G2 = 12 N against the robot's 19.7 N
GRIP_COLUMNS = ("slip1", "slip2", "grip_use1", "grip_use2", "skid_work", "wheels1", "wheels2")


def simulate(params, t_end=1.0, **options):
    return analytic.simulate(params, "exact", "unilateral", t_end, **options)


def _flow(energy: dict) -> float:
    """The energy put through the robot [J]: the scale of the audit's residual."""
    return max(abs(energy["motor_work_j"]), energy["friction_j"] + energy.get("skid_j", 0.0),
               abs(energy["potential_j"]), abs(energy["kinetic_j"]))


# --- unlimited grip is today's model ------------------------------------------------------------
@pytest.mark.parametrize("design,clutch", [({}, "unilateral"), (MOTOR, "unilateral"), ({}, "kinematic"),
                                           (dict(incline=30.0, **MOTOR), "unilateral"),
                                           (dict(clutch_stiffness=1e6), "unilateral")])
def test_unlimited_grip_is_todays_model_bit_for_bit(design, clutch):
    """mu_wall=unlimited (the default) runs today's code path: the same floats as the design given without
    the new fields, no grip column, and the summary's grip keys say that nothing skids."""
    today = analytic.simulate(RobotParams(**design), "exact", clutch, 0.3)
    spelled = analytic.simulate(load_params(overrides=[f"{k}={v}" for k, v in design.items()]
                                            + ["mu_wall=unlimited", "F_n1=50", "F_n2=50"]), "exact", clutch, 0.3)
    assert set(spelled.series) == set(today.series) and not set(GRIP_COLUMNS) & set(today.series)
    for column, values in today.series.items():
        assert np.array_equal(values, spelled.series[column]), column
    assert spelled.energy == today.energy and "skid_j" not in today.energy
    summary = today.summary
    assert (summary["slip1_m"], summary["slip2_m"], summary["peak_grip_use"]) == (0.0, 0.0, None)


@pytest.mark.parametrize("design", [{}, MOTOR, dict(incline=20.0, **MOTOR), dict(phi0=2.0, omega0=-3.0)])
def test_a_grip_far_above_the_demand_gives_the_unlimited_run(design):
    """G = 1e5 N, some 1e3 times the largest reaction (67 N at the paper's start-up): the finite-grip model
    (its own kernels, events and mode choice) integrates the same motion, so the runs agree to the
    integration's tolerance (rtol 1e-10 per step; 1e-8 of a column's size over a run of ~1e3 steps)."""
    unlimited = simulate(RobotParams(**design))
    gripped = simulate(RobotParams(**design, mu_wall=1.0, F_n1=1e5, F_n2=1e5))
    assert gripped.summary["slip1_m"] == gripped.summary["slip2_m"] == 0.0
    assert gripped.summary["peak_grip_use"] < 1e-3
    assert gripped.summary["mode_switches"] == unlimited.summary["mode_switches"]
    for column, values in unlimited.series.items():
        other = gripped.series[column]
        assert other.shape == values.shape, column
        scale = max(float(np.abs(values).max()), 1e-300)
        np.testing.assert_allclose(other, values, rtol=0, atol=100 * RTOL * scale, err_msg=column)
    assert np.all(gripped.series["wheels1"] >= 0) and np.all(gripped.series["wheels2"] >= 0)


# --- the default motor's cruise on 5 N of grip ---------------------------------------------------
@pytest.fixture(scope="module")
def cruise():
    return simulate(RobotParams(**MOTOR, **CRUISE_GRIP), 30.0, until_steady=True)


def test_cruise_on_little_grip_skids_and_the_reaction_never_exceeds_the_grip(cruise):
    s, summary = cruise.series, cruise.summary
    G = 0.5 * 10.0
    assert summary["steady"] and summary["slip1_m"] > 1e-3 and summary["slip2_m"] > 1e-3
    assert summary["peak_grip_use"] == 1.0
    for i in (1, 2):
        lam, wheels, v = s[f"lambda{i}"], s[f"wheels{i}"], s[f"v{i}"]
        ground = lam + s[f"resistance{i}"]
        # a standing module holds within [-F_r, G]; its reaction reaches G at the skid event, which is located to
        # ~4 eps in time: beyond G by no more than that times its rate (~1e-12 of G)
        assert lam.max() <= G * (1 + 1e-9)
        held = wheels == 0
        assert np.all(ground[held] <= G * (1 + 1e-9)) and np.all(ground[held] >= -1.0 * (1 + 1e-9))
        skid = wheels == -1
        assert skid.any() and np.all(lam[skid] == G) and np.all(ground[skid] == G)  # exactly the grip, no F_r
        # moving back; 0 where a skid starts or stops (a roundoff of the event's state: ~1e-15 m/s)
        assert np.all(v[skid] <= 1e-12) and v[skid].min() < -1e-3
        assert np.all(s[f"grip_use{i}"][skid] == 1.0)
        assert np.all(np.diff(s[f"slip{i}"]) >= -1e-15)  # a skid segment's samples telescope; roundoff only
    # with little grip a module seldom stands: one rolls forward while the other skids back
    both = (s["wheels1"] == 1) & (s["wheels2"] == -1) | (s["wheels1"] == -1) & (s["wheels2"] == 1)
    assert both.any()


def test_a_skidding_module_feels_exactly_its_grip(cruise):
    """Where both modules move (one rolls, one skids: two degrees of freedom), the x1-row of Lagrange's
    equations gives the external force along the pipe from the motion alone: M11 a1 + M12 alpha + M12' omega^2
    = g1 + g2 (horizontal), which must be -F_r1 + G2 or G1 - F_r2. Roundoff: ~1e-12 of m r omega^2 terms."""
    s = cruise.series
    p = cruise.params
    dyn = OneDofDynamics(p, "exact")
    mt = dyn.mass_terms(s["phi"])
    lhs = mt.m11 * s["a1"] + mt.m12 * s["alpha"] + mt.dm12 * s["omega"] ** 2
    G = 5.0
    for w1, w2, force in ((1, -1, -p.F_r1 + G), (-1, 1, G - p.F_r2)):
        rows = (s["wheels1"] == w1) & (s["wheels2"] == w2)
        assert rows.sum() > 100
        scale = mt.m11[rows] * p.r * s["omega"][rows] ** 2 + G
        np.testing.assert_array_less(np.abs(lhs[rows] - force), 1e-9 * scale)


def test_the_cruise_energy_audit_closes_with_the_skid_work(cruise):
    e = cruise.energy
    assert e["skid_j"] > 0.01 * e["motor_work_j"]  # the skids cost energy
    assert cruise.series["skid_work"][-1] == pytest.approx(5.0 * (cruise.series["slip1"][-1]
                                                                  + cruise.series["slip2"][-1]), rel=1e-12)
    # rtol 1e-10 per step over ~1e4 steps and ~40 events: the existing audits' 1e-6 of the energy put through,
    # here observed at ~2e-10
    assert abs(e["residual_j"]) < 1e-8 * _flow(e)
    summary = cruise.summary
    assert summary["cycle_energy_residual_j"] < 1e-8 * _flow(e)
    unlimited = simulate(RobotParams(**MOTOR), 30.0, until_steady=True).summary
    # skidding loses stroke: the robot is slower and less efficient than on unlimited grip
    assert summary["steady_speed_m_s"] < unlimited["steady_speed_m_s"]
    assert summary["efficiency"] < unlimited["efficiency"]


# --- a vertical riser on too little grip -------------------------------------------------------
def test_a_riser_with_the_drive_off_slides_back_at_the_hand_computed_rate():
    """Drive off (M = 0) at a dead centre: the crank has no torque to turn it (K = M12 = 0 there), so both
    modules skid together, a = (G1 + G2) / (m1 + m2 + m_rod) - g exactly; x = a t^2 / 2, which DOP853
    integrates exactly (a polynomial of degree 2), to roundoff."""
    p = RobotParams(M=0.0, **RISER_GRIP)
    run = simulate(p, 1.0)
    s = run.series
    mass = p.m1 + p.m2 + p.rod_mass
    a = (6.0 + 6.0) / mass - p.g
    assert np.all(s["wheels1"] == -1) and np.all(s["wheels2"] == -1)
    t = s["t"]
    for i in (1, 2):
        np.testing.assert_allclose(s[f"x{i}"], 0.5 * a * t**2, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(s[f"a{i}"], a, rtol=1e-12)
        assert run.summary[f"slip{i}_m"] == pytest.approx(-0.5 * a, rel=1e-12)
    e = run.energy
    assert e["skid_j"] == pytest.approx(12.0 * (-0.5 * a), rel=1e-12)  # G1 slip1 + G2 slip2, each slip -a/2
    assert e["potential_j"] == pytest.approx(mass * p.g * 0.5 * a, rel=1e-12)
    assert abs(e["residual_j"]) < 1e-12 * _flow(e)


def test_a_riser_with_a_motor_that_turns_still_slides_back():
    """M_stall = 1 N m turns the crank in a riser (0.56 N m is needed at rest), but G1 + G2 = 12 N holds less
    than the robot's weight, 19.7 N: it starts with both modules skidding at the hand-computed rate and
    slides back, each module's stroke unable to make up what it loses."""
    p = RobotParams(**MOTOR, M_stall=1.0, **RISER_GRIP)
    run = simulate(p, 1.0)
    s, summary = run.series, run.summary
    a = 12.0 / (p.m1 + p.m2 + p.rod_mass) - p.g
    assert (s["wheels1"][0], s["wheels2"][0]) == (-1, -1)
    assert s["a1"][0] == pytest.approx(a, rel=1e-12) and s["a2"][0] == pytest.approx(a, rel=1e-12)
    assert summary["revolutions"] > 1  # the crank turns
    assert summary["x1_final"] < -1.0 and summary["x2_final"] < -1.0
    assert summary["slip1_m"] > 1.0 and summary["slip2_m"] > 1.0 and summary["peak_grip_use"] == 1.0
    assert abs(run.energy["residual_j"]) < 1e-8 * _flow(run.energy)


def _riser_holds(p: RobotParams) -> tuple[float, float]:
    """The ground forces (R1, R2) [N] that hold the robot at rest in a riser at phi = pi/2, by hand: there
    K = -r and the rod is vertical on the pipe axis' side (D = S), so module 2 carries its weight, the rod's
    and the linkage's push M / r; module 1 the rest of the robot's weight."""
    R2 = p.M / p.r + (p.m2 + p.rod_mass) * p.g
    return (p.m1 + p.m2 + p.rod_mass) * p.g - R2, R2


@pytest.mark.parametrize("factors,moves", [((1.001, 1.001), (0, 0)), ((1.001, 0.999), (0, -1)),
                                           ((0.999, 1.001), (-1, 0)), ((0.999, 0.999), (-1, -1))])
def test_a_module_at_rest_holds_exactly_while_its_whole_ground_force_is_within_its_grip(factors, moves):
    """At rest in a riser a module needs a grip of its share of the weight (and of the linkage's push): with
    0.1 % more on both the robot stands for good; with 0.1 % less on one, that one skids back (and only it).
    The held condition is on the whole ground force R_i <= G_i: a condition on R_i + F_ri (1 N more) or a
    two-sided static resistance (1 N less) would put these thresholds 1 N (7-20 %) elsewhere."""
    base = RobotParams(incline=90.0, M=0.25, phi0=math.pi / 2)
    holds = _riser_holds(base)
    p = base.replace(mu_wall=1.0, F_n1=holds[0] * factors[0], F_n2=holds[1] * factors[1])
    run = simulate(p, 0.2)
    s = run.series
    if moves == (0, 0):
        assert run.stall is not None and np.all(s["x1"] == 0) and np.all(s["x2"] == 0)
        np.testing.assert_allclose([s["lambda1"][0], s["lambda2"][0]], holds, rtol=1e-12)
        return
    assert run.stall is None
    for i, state in enumerate(moves):
        assert s[f"wheels{i + 1}"][0] == state
        assert (run.summary[f"slip{i + 1}_m"] > 0) == (state == -1)


@pytest.mark.parametrize("G2,states", [(0.5, (0, -1)), (2.0, (1, 0))])
def test_at_a_dead_centre_at_rest_the_next_order_decides(G2, states):
    """From rest at phi = 0 (K = 0) every single-hold mode starts with zero module acceleration; the gap then
    shrinks (K' < 0). Module 1 rolls forward against F_r1 = 1 N while module 2 holds, if its grip can take
    that 1 N; with G2 = 0.5 N it cannot, and module 2 skids back while module 1 stands on its resistance
    (pushed forward by 0.5 N < F_r1)."""
    p = RobotParams(mu_wall=0.5, F_n1=100.0, F_n2=2 * G2)
    s = simulate(p, 0.05).series
    assert (s["wheels1"][0], s["wheels2"][0]) == states
    first = np.arange(np.flatnonzero(s["mode"] != s["mode"][0])[0])  # the first mode's samples
    assert first.size > 10
    if states == (0, -1):
        assert np.all(s["x1"][first] == 0.0) and s["x2"][first[-1]] < 0 and np.all(s["lambda2"][first] == G2)
    else:
        assert np.all(s["x2"][first] == 0.0) and s["x1"][first[-1]] > 0


def test_a_skidding_module_can_go_straight_to_rolling_forward():
    """The paper's torque on 10 N of grip: after start-up the modules hardly ever stand; a module that stops
    skidding, pushed forward by more than its F_r, rolls on at once. At each such switch standing would need
    a ground force below -F_r (the hold's lower limit): checked with the model's own accelerations."""
    p = RobotParams(mu_wall=0.5, F_n1=20.0, F_n2=20.0)
    run = simulate(p, 1.0)
    s = run.series
    model = GripModel(p, "exact")
    found = 0
    for i in (0, 1):
        w = s[f"wheels{i + 1}"]
        for j in np.flatnonzero((w[:-1] == -1) & (w[1:] == 1)):
            found += 1
            other = int(s["wheels2" if i == 0 else "wheels1"][j + 1])
            held = next(m for m in GripMode if m.states == ((0, other) if i == 0 else (other, 0)))
            R = model.motion(float(s["phi"][j + 1]), float(s["omega"][j + 1]), float(s["v1"][j + 1]), held)
            assert R["R1" if i == 0 else "R2"] < -(p.F_r1 if i == 0 else p.F_r2)
            assert s[f"a{i + 1}"][j + 1] >= 0
    assert found >= 4
    assert run.summary["mode_switches"] > 20  # the kinematics stay 'both moving': the states change


# --- the equations of the skid modes, against a symbolic derivation --------------------------------
ph, w, al, vv, a1s = sp.symbols("phi omega alpha v a1", real=True)


def _lagrange_rows(p: RobotParams, g1, g2):
    """Lagrange's two rows in (x1, phi) for the exact linkage with its rod, ground forces g1, g2 [N] (+
    forward) on the modules and the drive's constant torque, from the bodies' positions (sympy)."""
    r, L = p.r, p.L
    S = r * sp.cos(ph) + sp.sqrt(L**2 - r**2 * sp.sin(ph) ** 2)
    Gx, Gy = (r * sp.cos(ph) + S) / 2, r * sp.sin(ph) / 2
    beta = sp.asin(-r * sp.sin(ph) / L)
    T = (p.m1 * vv**2 + p.m2 * (vv + sp.diff(S, ph) * w) ** 2 + p.J_A * w**2
         + p.rod_mass * ((vv + sp.diff(Gx, ph) * w) ** 2 + (sp.diff(Gy, ph) * w) ** 2)
         + p.rod_inertia_value * (sp.diff(beta, ph) * w) ** 2) / 2
    a_g = -p.g * math.sin(math.radians(p.incline))
    # generalized forces: virtual work g1 dx1 + g2 (dx1 + S' dphi) + M dphi + gravity on every mass
    Q1 = g1 + g2 + a_g * (p.m1 + p.m2 + p.rod_mass)
    Q2 = g2 * sp.diff(S, ph) + p.M + a_g * (p.m2 * sp.diff(S, ph) + p.rod_mass * sp.diff(Gx, ph))
    rows = []
    for q_dot, Q in ((vv, Q1), (w, Q2)):
        d_dt = sp.diff(T, q_dot, vv) * a1s + sp.diff(T, q_dot, w) * al + sp.diff(T, q_dot, ph) * w
        rows.append(d_dt - (sp.diff(T, ph) if q_dot is w else 0) - Q)
    return rows, sp.diff(S, ph)


@pytest.mark.parametrize("mode", [GripMode.REAR_SKIDS, GripMode.FRONT_SKIDS, GripMode.REAR_SKIDS_FRONT_ROLLS,
                                  GripMode.FRONT_SKIDS_REAR_ROLLS, GripMode.BOTH_SKID])
@pytest.mark.slow
def test_skid_mode_accelerations_and_holds_match_symbolic_lagrange(mode):
    """Each skid mode's alpha, a1, a2 and standing module's ground force, against Lagrange's equations
    solved with a skidding module's force +G_i, a rolling one's -F_ri and a standing one's hold unknown
    (with a1 = 0 or a2 = 0 as its constraint). Roundoff: ~1e-12 of the terms' size."""
    p = RobotParams(m1=1.3, m2=0.7, F_r1=0.8, F_r2=1.9, rod_mass=0.2, incline=35.0, M=0.4, mu_wall=0.7,
                    F_n1=9.0, F_n2=14.0)
    G = p.grip
    model = GripModel(p, "exact")
    R = sp.Symbol("R", real=True)
    forces = [G[i] if s == -1 else (-(p.F_r1, p.F_r2)[i] if s == 1 else R) for i, s in enumerate(mode.states)]
    rows, K = _lagrange_rows(p, *forces)
    rng = np.random.default_rng(int(mode))
    for phi, omega, v1 in zip(rng.uniform(-3, 9, 8), rng.uniform(-20, 30, 8), rng.uniform(-2, 2, 8)):
        values = {ph: phi, w: omega}
        if mode.states[0] == 0:
            unknowns, values[vv] = (al, R), 0.0
            equations = [row.subs(a1s, 0) for row in rows]
        elif mode.states[1] == 0:
            unknowns, values[vv] = (al, R), float(-K.subs(ph, phi) * omega)
            # module 2 stands: a2 = a1 + K alpha + K' omega^2 = 0
            equations = [row.subs(a1s, -K * al - sp.diff(K, ph) * w**2) for row in rows]
        else:
            unknowns, values[vv] = (al, a1s), v1
            equations = rows
        solved = sp.solve([e.subs(values) for e in equations], unknowns, dict=True)[0]
        m = model.motion(float(phi), float(omega), float(values[vv]), mode)
        size = p.M / p.J_A + p.r * omega**2 + 100.0
        assert float(m["alpha"]) == pytest.approx(float(solved[al]), rel=1e-10, abs=1e-10 * size / p.r)
        if R in unknowns:
            held = "R1" if mode.states[0] == 0 else "R2"
            assert float(m[held]) == pytest.approx(float(solved[R]), rel=1e-10, abs=1e-10 * size)
        else:
            assert float(m["a1"]) == pytest.approx(float(solved[a1s]), rel=1e-10, abs=1e-10 * size)


def test_the_grip_kernels_events_are_the_models_events():
    """The compiled guards (kernels.grip_guard) and the Python events of every integrated mode agree."""
    p = RobotParams(**MOTOR, incline=25.0, mu_wall=0.4, F_n1=12.0, F_n2=30.0, m2=0.6)
    model = GripModel(p, "exact")
    rng = np.random.default_rng(5)
    for mode in GripMode:
        if mode == GripMode.BOTH_LOCKED:
            continue
        for phi, omega, v1 in zip(rng.uniform(-3, 9, 10), rng.uniform(-10, 40, 10), rng.uniform(-1, 1, 10)):
            y = np.array([phi, omega, 0.0, 0.0, v1, 0.0])
            kernel, kmode, constants = model.kernel_call(mode)
            values = np.empty((2, 1))
            kernels.guard_table(kernel, kmode, 2, constants, np.zeros(1), y[None, :], values)
            reference = [float(e(0.0, y)) for e, _ in model.events(mode)]
            np.testing.assert_allclose(values[:, 0], reference, rtol=1e-12, atol=1e-12 * (1 + abs(omega)))


# --- input -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("values,fragment", [
    (dict(mu_wall=-0.1), "mu_wall=-0.1 is out of range; allowed: 0 <= mu_wall <= 10, or 'unlimited'"),
    (dict(mu_wall=math.nan), "mu_wall=nan is not finite"),
    (dict(mu_wall="slippery"), "mu_wall='slippery' is not a number"),
    (dict(mu_wall=0.5, F_n1=0.0), "F_n1=0.0 N with mu_wall=0.5: a finite grip needs the wheels pressed on; "
                                  "allowed: 0 < F_n1 <= 1e+06 N"),
    (dict(mu_wall=0.5, F_n2=-3.0), "F_n2=-3.0 is out of range; allowed: 0 <= F_n2 <= 1e+06 N, and F_n2 > 0"),
    (dict(F_n1=math.nan), "F_n1=nan is not finite"),
])
def test_bad_grip_input_is_refused_with_one_line(values, fragment):
    with pytest.raises(ParameterError) as caught:
        RobotParams(**values)
    message = str(caught.value)
    assert fragment in message and "\n" not in message


@pytest.mark.parametrize("params,clutch,fragment", [
    (RobotParams(mu_wall=0.5), "kinematic", "mu_wall=0.5 with clutch='kinematic'"),
])
def test_the_analytic_engine_refuses_what_it_would_ignore(params, clutch, fragment):
    with pytest.raises(ParameterError, match=fragment) as caught:
        analytic.simulate(params, "exact", clutch, 0.1)
    assert "\n" not in str(caught.value)


def test_the_press_is_settable_with_unlimited_grip_and_moves_nothing_there():
    """F_n1, F_n2 are the wheeled MuJoCo model's leg preload whatever mu_wall is, so they are taken with
    unlimited grip too; the analytic model's unlimited grip holds any force, so they change none of its figures."""
    plain = analytic.simulate(RobotParams(), "exact", "unilateral", 0.1)
    pressed = analytic.simulate(RobotParams(F_n1=30.0, F_n2=80.0), "exact", "unilateral", 0.1)
    for key in ("x1_final", "x2_final", "revolutions"):
        assert pressed.summary[key] == plain.summary[key]


def test_engines_without_grip_columns_summarize():
    """A run without the grip columns (as MuJoCo's today) still has the keys: nothing skids, no ratio."""
    run = simulate(RobotParams(), 0.1)
    series = {c: run.series[c] for c in COLUMNS}
    from ipir_mujoco.core.results import summarize
    summary = summarize(series, run.energy)
    assert (summary["slip1_m"], summary["slip2_m"], summary["peak_grip_use"]) == (0.0, 0.0, None)


# --- compliant clutches: the force is capped by the grip, the anchor slides ------------------------
@pytest.mark.parametrize("damping", [0.0, 50.0])
def test_a_compliant_clutchs_force_is_capped_by_the_grip_and_the_audit_closes(damping):
    """The motor's cruise on 5 N of grip with 1e6 N/m clutches: a clutch pushes with at most G (beyond it by the
    switch's hysteresis, 1e-10 of G or 2 k * 1 pm = 2e-6 N), exactly G while its anchor slides; the anchors' slides
    are the slips; the audit closes with the spring, the damper (its slide share closed-form) and the skid work."""
    p = RobotParams(**MOTOR, clutch_stiffness=1e6, clutch_damping=damping, **CRUISE_GRIP)
    run = simulate(p, 2.0)
    s, summary = run.series, run.summary
    G = 5.0
    assert summary["slip1_m"] > 1e-3 and summary["slip2_m"] > 1e-3
    hysteresis = max(1e-10 * G, 2 * 1e6 * 1e-12)  # [N] 2e-6 N here: a grip use of 1 + 4e-7 at the slide's start
    # and the force's roundoff: k times a few ulp of the positions (the overlap is a difference of them)
    roundoff = 1e6 * 4 * np.spacing(max(np.abs(s["x1"]).max(), np.abs(s["x2"]).max()))
    assert 1.0 <= summary["peak_grip_use"] <= 1.0 + (hysteresis + roundoff) / G
    for i in (1, 2):
        lam, sliding = s[f"lambda{i}"], s[f"wheels{i}"] == -1
        assert lam.max() <= G + hysteresis + roundoff
        assert sliding.any() and np.all(lam[sliding] == G)
        # the anchor (x + d) only goes back while sliding, and what it slides is the slip
        anchor = s[f"x{i}"] + s[f"clutch_overlap{i}"]
        assert np.all(np.diff(anchor)[sliding[1:]] <= 1e-15)
    e = run.energy
    assert e["skid_j"] == pytest.approx(G * (summary["slip1_m"] + summary["slip2_m"]), rel=1e-12)
    if damping:
        assert e["clutch_damper_j"] > 1e-6  # the damper works, while engaged and while sliding
    # rtol 1e-10 per step over ~1e4 steps and ~100 switches, as the compliant model's own audits (1e-7 there)
    assert abs(e["residual_j"]) < 1e-8 * _flow(e)
    assert summary["cycle_energy_residual_j"] < 1e-8 * _flow(e)


def test_a_compliant_riser_on_little_grip_slides_at_the_hand_computed_rate():
    """Drive off at a dead centre in a riser: both modules go back, each clutch's spring charges to G / k and
    its anchor slides (c = 0: at once). From then on the module meets its grip G_i through the clutch and its
    own Coulomb resistance F_ri (the compliant model's, either way): a = (G1 + G2 + F_r1 + F_r2) / m - g, to
    roundoff. The rigid model's skidding module meets G_i alone (locked wheels do not roll)."""
    p = RobotParams(M=0.0, clutch_stiffness=1e6, **RISER_GRIP)
    s = simulate(p, 0.5).series
    both = (s["wheels1"] == -1) & (s["wheels2"] == -1)
    assert both[-1] and both.sum() > 1000
    a = (12.0 + p.F_r1 + p.F_r2) / (p.m1 + p.m2 + p.rod_mass) - p.g
    np.testing.assert_allclose(s["a1"][both], a, rtol=1e-9)
    np.testing.assert_allclose(s["a2"][both], a, rtol=1e-9)
    np.testing.assert_array_equal(s["lambda1"][both], 6.0)


def test_a_stiff_compliant_clutch_on_finite_grip_approaches_the_rigid_model():
    """k = 1e8 N/m, the motor's cruise on 5 N of grip: the compliant clutch's module meets G + F_r while its
    anchor slides, so the run approaches the rigid model with a grip of G + F_r = 6 N: the travel to 2e-4
    (the compliant model's departure from rigid at this stiffness, ~k^-1/2, 1e-3 at 1e6 N/m) and the slips to
    2 %; the rigid model with 5 N slips 80 % more."""
    compliant = simulate(RobotParams(**MOTOR, clutch_stiffness=1e8, **CRUISE_GRIP), 2.0, dt_out=1e-3).summary
    same = simulate(RobotParams(**MOTOR, mu_wall=0.5, F_n1=12.0, F_n2=12.0), 2.0, dt_out=1e-3).summary
    less = simulate(RobotParams(**MOTOR, **CRUISE_GRIP), 2.0, dt_out=1e-3).summary
    for key in ("x1_final", "x2_final"):
        assert compliant[key] == pytest.approx(same[key], rel=5e-4)
    for key in ("slip1_m", "slip2_m"):
        assert compliant[key] == pytest.approx(same[key], rel=0.02)
        assert less[key] > 1.5 * compliant[key]


def test_a_torque_profile_runs_the_same_grip_model_through_solve_ivp():
    """A torque profile is a Python function, so the run goes through solve_ivp with the model's Python
    right-hand sides and events (not the kernels): the paper's constant torque given as a profile is the same
    motion, to the integrations' tolerance (two DOP853 runs at rtol 1e-10 whose roundoff differs)."""
    p = RobotParams(mu_wall=0.5, F_n1=20.0, F_n2=20.0)
    kernels_run = simulate(p, 0.5)
    profile_run = simulate(p, 0.5, torque=lambda t, phi, omega: 0.25 + 0.0 * np.asarray(phi))
    for key in ("slip1_m", "slip2_m", "x1_final", "x2_final", "revolutions", "mode_switches"):
        assert profile_run.summary[key] == pytest.approx(kernels_run.summary[key], rel=1e-8), key
    assert profile_run.energy["skid_j"] == pytest.approx(kernels_run.energy["skid_j"], rel=1e-8)


# --- designs a random sweep of finite-grip runs found hard (each chattered before its fix) -----------
def test_a_module_that_rolls_forward_for_less_than_a_step_is_resolved():
    """A riser on little grip: module 1 stops skidding, its linkage pushes it forward by a little more than
    F_r1 (so it rolls, a1 = +0.065 m/s^2), and a jerk of ~1e4 m/s^3 stops it again within ~1e-5 s, in the
    first part of a 6.6 ms step. Its speed starts at exactly 0 (reading +tiny), so the solver sees the stop
    as a crossing in that step, not at the segment's start (which repeated the same zero-length segment)."""
    p = RobotParams(m1=0.6204592467906616, m2=0.539658123574452, r=0.02023469650136134, L=0.04913762703896226,
                    F_r1=0.06229382548662421, F_r2=2.9631457558603325, incline=90.0, phi0=-0.15462136217968414,
                    mu_wall=0.3, F_n1=28.973961968853825, F_n2=15.566737085413308, drive="motor",
                    M_stall=0.9594150146671183, omega_noload=25.372657670021205)
    run = simulate(p, 0.5, dt_out=1e-3)
    assert run.summary["slip1_m"] > 0.01
    assert abs(run.energy["residual_j"]) < 1e-8 * _flow(run.energy)


@pytest.mark.parametrize("damping", [0.0, 20.0])
def test_compliant_clutches_on_no_grip_push_with_nothing(damping):
    """mu_wall = 0: a compliant clutch's anchor slides as soon as it engages (its force would exceed G = 0 by the
    hysteresis, 2e-6 N at 1e6 N/m) and, when the anchor stops, its spring has relaxed to nothing: the clutch
    releases (it is not engaged with a pulling damper, which clipped and re-engaged at once, for ever)."""
    p = RobotParams(drive="motor", clutch_stiffness=1e6, clutch_damping=damping, mu_wall=0.0)
    run = simulate(p, 0.3, dt_out=1e-3)
    s = run.series
    roundoff = 1e6 * 4 * np.spacing(max(np.abs(s["x1"]).max(), np.abs(s["x2"]).max()))  # k times a few ulp
    assert s["lambda1"].max() <= 2e-6 + roundoff and s["lambda2"].max() <= 2e-6 + roundoff
    assert run.summary["peak_grip_use"] == 1.0 and run.energy["skid_j"] == 0.0
    assert abs(run.energy["residual_j"]) < 1e-8 * _flow(run.energy)
