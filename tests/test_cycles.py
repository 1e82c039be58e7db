"""Per-revolution figures and the steady-state test, on synthetic runs with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ipir_mujoco.core.cycles import cycle_boundaries, cycle_summary, cycles, steady_index
from ipir_mujoco.core.steady_watch import SteadyWatch


def settling_run(t_end=6.0, n=60001, tau=0.5, omega_ss=20.0, per_rev=0.05):
    """A crank settling exponentially to omega_ss; the robot advances per_rev per revolution.

    phi = omega_ss (t - tau (1 - exp(-t / tau))): revolutions end where phi = 2 pi k. Energies:
    the motor does 1 J per revolution plus the kinetic energy 1/2 omega^2 * 1e-3 gained; friction
    takes 1 J per revolution, so every revolution's audit closes exactly.
    """
    t = np.linspace(0.0, t_end, n)
    phi = omega_ss * (t - tau * (1 - np.exp(-t / tau)))
    omega = omega_ss * (1 - np.exp(-t / tau))
    x = per_rev * phi / (2 * math.pi)
    kinetic = 0.5e-3 * omega**2
    return {"t": t, "phi": phi, "x1": x, "x2": x, "motor_work": phi / (2 * math.pi) + kinetic,
            "friction_work": phi / (2 * math.pi), "kinetic": kinetic, "potential": 0 * t,
            "lambda1": np.sin(phi) ** 2 * 7.0, "lambda2": 0 * t}


def test_boundaries_fall_where_the_crank_completes_each_turn():
    run = settling_run()
    ends, _ = cycle_boundaries(run["t"], run["phi"])
    # phi(t) is known: the boundary times solve phi = 2 pi k; linear interpolation between samples
    # 1e-4 s apart errs by at most phi'' dt^2 / (8 phi') < 1e-8 s here
    for k, te in enumerate(ends, start=1):
        phi_at = 20.0 * (te - 0.5 * (1 - math.exp(-te / 0.5)))
        assert phi_at == pytest.approx(2 * math.pi * k, abs=1e-6)


def test_a_rocking_crank_counts_a_revolution_once():
    t = np.linspace(0, 3, 3001)
    phi = 2 * math.pi * t / 2 - 0.5 * np.sin(6 * math.pi * t)  # turns 1.5 revolutions, rocking back on the way
    ends, _ = cycle_boundaries(t, phi)
    assert ends.size == 1


def test_cycle_figures_and_audit_close_exactly():
    found = cycles(settling_run())
    assert len(found) > 10
    for c in found:
        assert c.distance_m == pytest.approx(0.05, rel=1e-9)
        assert c.motor_work_j - c.kinetic_change_j == pytest.approx(1.0, rel=1e-9)
        assert abs(c.residual_j) < 1e-9
        assert c.peak_clutch_force_n == pytest.approx(7.0, rel=1e-3)


def test_steady_state_is_found_when_the_speed_has_settled_and_not_before():
    run = settling_run()
    s = cycle_summary(run, tol=1e-4, n=3)
    assert s["steady"]
    # the per-revolution speed deficit decays like exp(-t / tau): a spread of 1e-4 over three
    # revolutions of ~0.31 s needs roughly exp(-t/0.5) * (exp(0.94/0.5) - 1) ~ 1e-4: t ~ 5.5 s
    assert 4.5 < s["t_steady_s"] < 6.0
    assert s["steady_speed_m_s"] == pytest.approx(20.0 / (2 * math.pi) * 0.05, rel=1e-3)
    assert s["distance_per_rev_m"] == pytest.approx(0.05, rel=1e-9)
    assert s["efficiency"] == pytest.approx(1.0, rel=2e-3)  # friction / (friction + small kinetic gain)
    assert s["energy_per_metre_j_m"] == pytest.approx(1 / 0.05, rel=2e-3)
    assert not cycle_summary(settling_run(t_end=3.0, n=30001))["steady"]


def test_the_watch_agrees_with_the_after_the_fact_test():
    run = settling_run()
    position = 0.5 * (run["x1"] + run["x2"])
    watch = SteadyWatch(run["phi"][0])
    for start in range(0, run["t"].size, 997):  # arbitrary chunks, as an engine feeds them
        sl = slice(start, start + 997)
        watch.update(run["t"][sl], run["phi"][sl], position[sl])
    assert watch.steady_at == pytest.approx(cycle_summary(run)["t_steady_s"], abs=1e-9)


def test_steady_index_needs_positive_speed_and_a_full_window():
    assert steady_index([0.0, 0.0, 0.0]) is None
    assert steady_index([1.0, 1.0]) is None
    assert steady_index([0.5, 1.0, 1.00002, 1.000021], tol=1e-4, n=3) == 3


def test_a_slow_settling_is_steady_only_when_little_drift_remains():
    """Per-revolution speeds approaching 1 m/s geometrically, 1/60 of the gap closed a revolution (a heavy
    flywheel): three successive speeds agree to 1e-4 while the speed is still 3e-3 short, so the spread alone
    would call that steady. Extrapolating the last two changes (geometric: exact here) keeps the steady
    window's mean within the spread (<= tol) plus the remaining drift (<= tol) of the final speed."""
    tol, n = 1e-4, 3
    u = 1.0 - np.exp(-np.arange(1200) / 60.0)
    spread_only = next(k for k in range(n - 1, u.size) if u[k] - u[k - n + 1] <= tol * u[k - n + 1:k + 1].mean())
    assert 1.0 - u[spread_only] > 2e-3  # what the spread alone accepted
    k = steady_index(u, tol, n)
    assert k is not None and 1.0 - u[k - n + 1:k + 1].mean() <= 2 * tol
    assert 1.0 - u[k - 1] > tol  # and not much later than needed: a revolution earlier, more than tol was left


def test_a_speed_that_keeps_drifting_is_never_steady():
    """A constant torque accelerates the robot for ever: a speed rising 1e-5 of itself every revolution has
    three revolutions agreeing to 2e-5 < 1e-4, but no steady state; one rising a thousandth of the tolerance
    per revolution is settled for any purpose of that tolerance."""
    k = np.arange(200)
    assert steady_index(1.0 + 1e-5 * k, 1e-4, 3) is None
    assert steady_index(1.0 + 1e-8 * k, 1e-4, 3) == 2


def test_a_run_ending_on_a_revolution_keeps_it_after_a_csv_round_trip(tmp_path):
    """12 significant digits move phi by a few 1e-12 revolutions: the last revolution must still count."""
    from ipir_mujoco.analytic import RobotParams, simulate
    from ipir_mujoco.core.results import read_csv

    run = simulate(RobotParams(drive="motor"), "exact", "unilateral", 10.0, dt_out=1e-3, until_steady=True)
    run.write_csv(tmp_path / "ts.csv")
    back = read_csv(tmp_path / "ts.csv")
    assert cycle_summary(back)["cycles"] == cycle_summary(run.series)["cycles"] >= 3
    assert cycle_summary(back)["steady"]


def test_a_revolution_of_no_duration_does_not_hang_the_watch():
    """Two turns ending at one instant (a crank angle that jumps at a repeated time, as a mode switch's twin
    samples would if they disagreed): the second turn has no duration and so no speed, but it must end
    (it used to be sought again and again, for ever)."""
    watch = SteadyWatch(0.0)
    watch.update([0.0, 1.0, 1.0], [0.0, 1.0, 20.0], [0.0, 0.1, 0.2])
    assert watch.turns == math.floor(20.0 / (2 * math.pi)) == 3
    assert len(watch.speeds) == 1  # only the first turn took time


@pytest.mark.parametrize("geometry, clutch, extra", [("exact", "kinematic", {}), ("exact", "unilateral", {}),
                                                     ("exact", "unilateral", {"clutch_stiffness": 1e5})])
def test_efficiency_counts_kinetic_energy_released_as_put_in(geometry, clutch, extra):
    """A crank started at 60 rad/s under a tiny torque: it coasts down, and the kinetic energy it releases,
    not the motor, pays most of the resistance work. Counted as loss-free input (as potential energy released
    downhill is) the figure is resistance work / (motor work + kinetic energy released) and at most 1, to the
    audit's residual (solver error, far below 1e-6 of the energies); resistance work / motor work would read
    3 to 7 here."""
    from ipir_mujoco.analytic import RobotParams, simulate

    run = simulate(RobotParams(omega0=60.0, M=0.01, **extra), geometry, clutch, 0.3, dt_out=1e-3)
    e, s = run.energy, run.summary
    assert e["kinetic_j"] < -0.2 and e["friction_j"] > 2 * e["motor_work_j"] > 0  # the case: coasting
    assert not s["steady"]  # so the figure is over the whole run
    expected = e["friction_j"] / (e["motor_work_j"] - e["kinetic_j"] - min(e.get("clutch_spring_j", 0.0), 0.0))
    assert s["efficiency"] == pytest.approx(expected, rel=1e-9)
    assert s["efficiency"] <= 1.0 + 1e-6


def test_a_motor_driven_past_its_no_load_speed_absorbs_energy_it_does_not_put_in():
    """A motor at twice its no-load speed brakes the crank: its work is negative (energy absorbed, a loss),
    so the input is the kinetic energy released alone, and the figure stays at most 1 (it used to be None
    here, and resistance work / (negative motor work + kinetic energy released) would exceed 1)."""
    from ipir_mujoco.analytic import RobotParams, simulate
    from ipir_mujoco.core.cycles import efficiency

    assert efficiency(-1.0, 2.0, kinetic_j=-3.0) == pytest.approx(2.0 / 3.0)
    assert efficiency(-1.0, 0.0) is None  # nothing put in
    run = simulate(RobotParams(drive="motor", omega0=60.0), "exact", "unilateral", 0.1, dt_out=1e-3)
    e = run.energy
    assert e["motor_work_j"] < 0 < e["friction_j"] and e["kinetic_j"] < 0
    assert run.summary["efficiency"] == pytest.approx(e["friction_j"] / -e["kinetic_j"], rel=1e-9)
    assert run.summary["efficiency"] <= 1.0 + 1e-6



def test_a_flywheel_robots_steady_speed_is_its_final_speed_within_the_tolerance():
    """The default motor with a crank inertia of 0.05 kg m^2 (50x the paper's) settles with a time constant
    of some 70 revolutions. Its steady speed must be the speed it keeps: within 2 steady_tol (the window's
    spread plus the drift left, each <= tol) of the mean over the last three revolutions of a run three
    times as long. Three agreeing revolutions alone stopped it 6.6e-4 short."""
    from ipir_mujoco.analytic import RobotParams, simulate

    params = RobotParams(drive="motor", J_A=0.05)
    run = simulate(params, "exact", "unilateral", 200.0, dt_out=1e-2, until_steady=True)
    s = run.summary
    assert s["steady"]
    longer = cycles(simulate(params, "exact", "unilateral", 3 * s["t_steady_s"], dt_out=1e-2).series)
    final = sum(c.distance_m for c in longer[-3:]) / sum(c.period_s for c in longer[-3:])
    assert abs(s["steady_speed_m_s"] / final - 1) <= 2 * 1e-4
