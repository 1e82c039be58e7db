"""MuJoCo's finite grip at its stated accuracy, or flagged: the three classes where its skids drifted from the
equations (skids on 30 and 60 degree inclines, a riser that climbs while skidding every stroke, a shallow
downhill on a grip below the rolling resistance), at fixed time (1e-3) and to the steady state (3e-4).

A run on finite grip whose modules skid is verified at half its step (ipir_mujoco.engine.run.skid_check); a design
the check cannot bring within the tolerance is flagged: stopped with its figure ('stop') or recorded ('warn').
"""

from __future__ import annotations

import json
import math

import pytest

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.engine.builders.grip_model import carriage_share
from ipir_mujoco.engine.loop.monitor import AccuracyError, RESIDUAL_TOL
from ipir_mujoco.engine.run.skid_check import SKID_TOL, TRAVEL_FLOOR, differences, skidded, verify_skids

# each skids every stroke (both modules); the riser climbs 0.24 m in 2 s while skidding 0.28 m per module
CLASSES = {
    "30 deg, default motor": dict(drive="motor", incline=30.0, mu_wall=0.5, F_n1=30.0, F_n2=30.0),
    "60 deg, strong motor": dict(drive="motor", M_stall=1.5, incline=60.0, mu_wall=0.5, F_n1=40.0, F_n2=40.0),
    "riser climbing while skidding": dict(drive="motor", M_stall=2.0, incline=90.0, mu_wall=0.5, F_n1=45.0,
                                          F_n2=45.0),
    "downhill, grip below F_r": dict(drive="motor", incline=-3.0, mu_wall=0.05, F_n1=15.0, F_n2=15.0),
}


def pair(params: RobotParams, t_end: float, **options):
    analytic = registry.run("analytic-unilateral", params, t_end, dt_out=1e-3, **options)
    try:
        return analytic, registry.run("mujoco-ratchet", params, t_end, dt_out=1e-3, **options)
    except AccuracyError as exc:  # flagged: stopped with the figure, in one line
        assert "\n" not in str(exc) and "skid" in str(exc)
        return analytic, None


@pytest.mark.parametrize("name", list(CLASSES))
def test_fixed_time_travel_within_the_stated_accuracy_or_flagged(name):
    params = RobotParams(**CLASSES[name])
    analytic, mujoco_ = pair(params, 1.0)
    if mujoco_ is None:
        return
    assert skidded(mujoco_) and mujoco_.accuracy["skid_check"] == "verified"
    floor = TRAVEL_FLOOR * 2 * params.r
    a, m = analytic.summary, mujoco_.summary
    # the monitor's 0.1 % on the motion, travel relative to at least a tenth of a stroke (skid_check's scale)
    assert abs(m["revolutions"] - a["revolutions"]) <= RESIDUAL_TOL * max(abs(a["revolutions"]), 0.1)
    for key in ("x1_final", "x2_final"):
        assert abs(m[key] - a[key]) <= RESIDUAL_TOL * max(abs(a[key]), floor), key


@pytest.mark.slow
@pytest.mark.parametrize("name", ["30 deg, default motor", "riser climbing while skidding"])
def test_steady_figures_within_the_stated_accuracy_or_flagged(name):
    params = RobotParams(**CLASSES[name])
    analytic, mujoco_ = pair(params, 30.0, until_steady=True)
    if mujoco_ is None:
        return
    a, m = analytic.summary, mujoco_.summary
    assert a["steady"] and m["steady"]  # MuJoCo stops while its modules skid every stroke
    if mujoco_.accuracy["skid_check"] == "failed":  # flagged with its figure (accuracy='stop' would have raised)
        pytest.fail("stop mode returned a run whose skid check failed")
    for key in ("steady_speed_m_s", "energy_per_metre_j_m"):
        assert abs(m[key] / a[key] - 1) <= SKID_TOL["steady"], key


def test_the_skid_check_is_recorded_in_warn_mode_whatever_its_outcome():
    # 'warn' returns the run with its check recorded: verified, or failed with the figure and a violation
    params = RobotParams(**CLASSES["riser climbing while skidding"])
    run = registry.run("mujoco-ratchet", params, 1.0, dt_out=1e-3, accuracy="warn")
    record = run.accuracy
    assert record["skid_check"] in ("verified", "failed")
    assert (record["skid_check"] == "failed") == (not record["ok"])
    assert record["skid_difference"] is None or math.isfinite(record["skid_difference"])  # None: not computed
    history = run.settings["skid_check"]
    assert history[-1]["half"] == run.settings["timestep"]
    assert record["skid_difference"] == history[-1]["difference"]


def test_a_given_timestep_says_its_skids_were_not_verified():
    params = RobotParams(**CLASSES["30 deg, default motor"])
    run = registry.run("mujoco-ratchet", params, 0.5, dt_out=1e-3, timestep=1e-4)
    assert run.accuracy["skid_check"] == "not verified: timestep given"


@pytest.mark.slow
def test_the_check_compares_steady_figures_with_their_own_uncertainty():
    # two runs of one design a step apart: where the finer one was found steady statistically, its figure's own
    # uncertainty is part of what the check holds to the tolerance, with the carriages' share
    params = RobotParams(**CLASSES["30 deg, default motor"])
    coarse = registry.run("mujoco-ratchet", params, 30.0, dt_out=1e-3, until_steady=True, timestep=1e-4)
    fine = registry.run("mujoco-ratchet", params, 30.0, dt_out=1e-3, until_steady=True, timestep=5e-5)
    kind, diff = differences(coarse, fine)
    assert kind == "steady"
    own = fine.summary["steady_speed_uncertainty_m_s"] if fine.summary["steady_test"] == "statistical" else 0.0
    f = fine.summary
    gap = abs(coarse.summary["steady_speed_m_s"] - f["steady_speed_m_s"])
    # and the carriages' inertia share of the skids, over the travel (no halving shows it)
    bias = carriage_share(params) * (f["slip1_m"] + f["slip2_m"]) / (abs(f["x1_final"]) + abs(f["x2_final"]))
    assert diff["steady_speed_m_s"] == pytest.approx((gap + own) / max(coarse.summary["steady_speed_m_s"],
                                                                       f["steady_speed_m_s"]) + bias)


def test_a_skid_that_cannot_be_checked_is_flagged_not_passed():
    # a run whose step cannot be halved twice above the smallest a run may take: 'stop' ends it with the reason,
    # 'warn' records a failed check whose figure (none computed) is None, so that the summary stays JSON
    params = RobotParams(**CLASSES["30 deg, default motor"])
    base = registry.run("mujoco-ratchet", params, 0.3, dt_out=1e-3, timestep=1e-4, accuracy="warn")
    rerun = lambda dt: registry.run("mujoco-ratchet", params, 0.3, dt_out=1e-3, timestep=dt)  # noqa: E731
    with pytest.raises(AccuracyError, match="cannot be halved twice"):
        verify_skids(base, rerun, "stop", dt_min=4e-5)
    run = verify_skids(base, rerun, "warn", dt_min=4e-5)
    assert run.accuracy["skid_check"] == "failed" and not run.accuracy["ok"]
    assert run.accuracy["violations"][-1]["figure"] == "skid_difference"
    json.dumps(run.to_json_dict(), allow_nan=False)
