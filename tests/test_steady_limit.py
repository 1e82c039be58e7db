"""The steady figures against the periodic limit each engine converges to.

A run to its steady state stops once the last revolutions' mean speeds agree within ``STEADY_TOL`` (1e-4)
and their extrapolated drift is as small; its figures must nevertheless lie within the accuracy the package
states for them, ``LIMIT_ACCURACY`` (2e-5 analytic, 3e-4 MuJoCo, relative), of the limit cycle. The
reference for each design is a run of the same engine taken much closer to that limit, read with nothing but
:func:`cycles` (so that the reference does not share the extrapolation it checks): the analytic engine to a
steady tolerance of 1e-8, its last revolution raw; MuJoCo run three times as long as it took to settle, over
its last eight revolutions (MuJoCo's figures wobble from revolution to revolution by a few 1e-5, with where
its steps fall in a revolution, and the mean of eight is its limit to well within that).
"""

from __future__ import annotations

import functools
import math

import pytest

from ipir_mujoco import registry
from ipir_mujoco.core.cycles import LIMIT_ACCURACY, STEADY_TOL, Cycle, cycles, limit_motion
from ipir_mujoco.core.params import RobotParams

DESIGNS = {  # across the motor, incline and compliant-clutch ranges, and a slow approach
    "light crank, strong motor": dict(drive="motor", M_stall=0.6, omega_noload=50, F_r1=2, F_r2=0.5, J_A=0.003),
    "30 deg uphill": dict(drive="motor", incline=30, M_stall=1.0),
    "compliant 1e6 N/m, 1 mm play": dict(drive="motor", clutch_stiffness=1e6, clutch_damping=20,
                                         clutch_backlash=1e-3),
    "compliant 1e5 N/m, 20 deg uphill": dict(drive="motor", clutch_stiffness=1e5, clutch_damping=5,
                                             clutch_backlash=5e-4, incline=20, M_stall=1.0),
    "heavy flywheel": dict(drive="motor", J_A=0.03),  # rho ~0.9 per revolution: the slowest approach
}
VARIANTS = {"analytic": "analytic-unilateral", "mujoco": "mujoco-ratchet"}
FIGURES = ("steady_speed_m_s", "distance_per_rev_m", "energy_per_metre_j_m", "efficiency")
T_CAP = 60.0  # s: every design settles within 20 s


def raw_figures(revolutions: list[Cycle]) -> dict[str, float]:
    """The steady figures over ``revolutions`` straight from their totals (no transit energy taken off, no
    extrapolation: at the limit neither changes anything)."""
    time = sum(c.period_s for c in revolutions)
    distance = sum(c.distance_m for c in revolutions)
    motor = sum(c.motor_work_j for c in revolutions)
    lifted = sum(c.potential_change_j or 0.0 for c in revolutions)
    useful = sum(c.friction_work_j for c in revolutions) + max(lifted, 0.0)
    return {"steady_speed_m_s": distance / time, "distance_per_rev_m": distance / len(revolutions),
            "energy_per_metre_j_m": motor / distance, "efficiency": useful / (motor + max(-lifted, 0.0))}


def reference(engine: str, params: RobotParams, settled_at: float) -> dict[str, float]:
    variant = VARIANTS[engine]
    if engine == "analytic":
        run = registry.run(variant, params, 2 * T_CAP, dt_out=1e-3, until_steady=True, steady_tol=1e-8)
        assert run.summary["steady"]
        return raw_figures(cycles(run.series)[-1:])
    run = registry.run(variant, params, 3 * settled_at + 1.0, dt_out=1e-3)
    return raw_figures(cycles(run.series)[-8:])


@functools.cache
def design_runs(name: str) -> dict:
    """{engine: (run to its steady state, reference figures)} of design ``name``."""
    params = RobotParams(**DESIGNS[name])
    out = {}
    for engine, variant in VARIANTS.items():
        run = registry.run(variant, params, T_CAP, dt_out=1e-3, until_steady=True)
        assert run.summary["steady"], (name, engine)
        out[engine] = (run, reference(engine, params, run.summary["t_steady_s"]))
    return out


@pytest.mark.parametrize("engine", list(VARIANTS))
@pytest.mark.parametrize("name", list(DESIGNS))
@pytest.mark.slow
def test_steady_figures_lie_within_the_stated_accuracy_of_the_periodic_limit(name, engine):
    run, limit = design_runs(name)[engine]
    for key in FIGURES:
        error = run.summary[key] / limit[key] - 1
        assert abs(error) <= LIMIT_ACCURACY[engine], (name, engine, key, error)


@pytest.mark.parametrize("name", ["light crank, strong motor", "heavy flywheel"])
def test_the_stop_alone_would_miss_the_limit(name):
    """The check above can fail: on the slow approaches, the figures read over the steady window as it stands
    (its raw totals) miss the analytic limit by more than the stated accuracy; it is the extrapolation and
    the transit energy taken off that bring them within it."""
    run, limit = design_runs(name)["analytic"]
    found = cycles(run.series)
    assert found[-1].t_end == pytest.approx(run.summary["t_steady_s"], abs=1e-12)  # the run ends on its window
    window = raw_figures(found[-3:])
    for key in ("steady_speed_m_s", "energy_per_metre_j_m", "efficiency"):
        assert abs(window[key] / limit[key] - 1) > LIMIT_ACCURACY["analytic"], (name, key)


def _cycle(t0: float, period: float, distance: float) -> Cycle:
    return Cycle(t0, t0 + period, distance)


def test_limit_motion_recovers_a_geometric_approach_exactly():
    """Revolutions whose speed and distance approach their limits as c rho^k, from as far as a run the steady
    test stops can be (its last revolution within STEADY_TOL of the limit): the extrapolation returns the
    limits to rounding, for a monotone (rho 0.8) and an alternating (rho -0.5) approach."""
    for rho in (0.8, -0.5):
        u_lim, d_lim = 0.5, 0.05
        speeds = [u_lim * (1 - 1e-4 * rho ** k) for k in range(3)]
        distances = [d_lim * (1 - 2e-4 * rho ** k) for k in range(3)]
        revolutions = [_cycle(float(k), d / u, d) for k, (u, d) in enumerate(zip(speeds, distances))]
        speed, distance = limit_motion(revolutions)
        assert speed == pytest.approx(u_lim, rel=1e-12) and distance == pytest.approx(d_lim, rel=1e-12)


def test_limit_motion_averages_a_wobble():
    """No geometric approach (the changes grow: |rho| >= 1): the mean speed and distance of the revolutions,
    which the steady test's spread (at most STEADY_TOL of the mean) bounds."""
    distances = [0.050, 0.0500005, 0.0499990]
    revolutions = [_cycle(0.2 * k, 0.2, d) for k, d in enumerate(distances)]
    speed, distance = limit_motion(revolutions)
    assert distance == pytest.approx(sum(distances) / 3, rel=1e-15)
    assert speed == pytest.approx(sum(distances) / 0.6, rel=1e-15)
    assert max(abs(d / distance - 1) for d in distances) < STEADY_TOL
    assert math.isfinite(speed)


def test_no_sawtooth_across_designs():
    """Rigid one-way clutches in a horizontal pipe: in the limit cycle all the motor's work goes into the
    resistances, so energy per metre = F_r1 + F_r2 and efficiency = 1 for any flywheel, to the stated accuracy.
    The stop fires at a different point of each design's approach; read over the window's raw totals these
    figures jumped by ~1e-4 from one flywheel to the next."""
    params = RobotParams(**DESIGNS["heavy flywheel"])
    for J_A in (0.001, 0.0013, 0.0017, 0.002, 0.0025, 0.003):
        run = registry.run("analytic-unilateral", params.replace(J_A=J_A), T_CAP, dt_out=1e-3, until_steady=True)
        assert run.summary["energy_per_metre_j_m"] == pytest.approx(params.F_r1 + params.F_r2,
                                                                    rel=LIMIT_ACCURACY["analytic"]), J_A
        assert run.summary["efficiency"] == pytest.approx(1.0, abs=LIMIT_ACCURACY["analytic"]), J_A


def test_limit_motion_caps_its_correction_at_the_steady_tolerance():
    """Two nearly equal last changes (rho = 0.9999: a wobble the stop accepts because its last change is
    below a thousandth of the tolerance) would extrapolate by 9999 times that change; the correction is held
    to the steady tolerance of the speed, the distance's scaled alike."""
    u, d = 0.5, 0.05
    speeds = [u, u * (1 + 5e-8), u * (1 + 5e-8 + 0.9999 * 5e-8)]
    revolutions = [_cycle(float(k), d / u, d * s / u) for k, s in enumerate(speeds)]  # speed s, distance ~ s
    speed, distance = limit_motion(revolutions, tol=STEADY_TOL)
    assert abs(speed / speeds[2] - 1) == pytest.approx(STEADY_TOL, rel=1e-6)
    assert abs(distance / revolutions[2].distance_m - 1) <= STEADY_TOL * (1 + 1e-6)
    uncapped = speeds[2] + (speeds[2] - speeds[1]) * 0.9999 / (1 - 0.9999)
    assert abs(uncapped / speeds[2] - 1) > 4 * STEADY_TOL  # the cap acts here
