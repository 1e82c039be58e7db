"""What bounds a study before and while it runs: the samples a run keeps (STUDY_SAMPLES), the ranges it will try
(checked before the first design), a study whose every run failed (exit 1, not 0), and the skid check's repeats
inside a run's wall-time budget."""

from __future__ import annotations

import re
from types import SimpleNamespace

import pytest

from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.options import STUDY_SAMPLES, study_dt_out
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.studies.sweep_space import Study, parse_vary


def test_a_study_run_keeps_at_most_study_samples_on_whole_steps():
    assert study_dt_out(1.0, 1e-3) == 1e-3  # 1001 samples: left as it is
    dt = study_dt_out(10.0, 3.125e-6, 3.125e-6)  # a 10 s cruise at a finite grip's step: 3.2e6 samples
    n = dt / 3.125e-6
    assert abs(n - round(n)) < 1e-9 and 10.0 / dt + 1 <= STUDY_SAMPLES  # a whole number of steps, under the cap
    assert 10.0 / (dt - 3.125e-6) + 1 > STUDY_SAMPLES  # the finest such interval
    free = study_dt_out(3600.0, 1e-3)
    assert 3600.0 / free + 1 == pytest.approx(STUDY_SAMPLES)


def test_clutch_study_samples_its_runs_within_the_cap_whatever_the_grip():
    """The analytic model's clutch has no carriage: its output interval follows the spring on the module whatever
    the grip (it followed MuJoCo's carriage, 2.5e7 samples at 1e6 N/m over a 10 s cruise, refused); MuJoCo's
    every step, or every n-th beyond the cap."""
    from ipir_mujoco import registry
    from ipir_mujoco.studies.clutch_study import DT_OUT_MAX, POINTS, analytic_dt_out, design, mujoco_dt_out

    cruise = POINTS["cruise"]
    for mu in (None, 0.5):
        params = design(RobotParams(mu_wall=mu), cruise, 1e6, 0.0)
        dt = analytic_dt_out(params, cruise.t_end)
        assert cruise.t_end / dt + 1 <= STUDY_SAMPLES
        assert dt == analytic_dt_out(design(RobotParams(), cruise, 1e6, 0.0), cruise.t_end)
        h = registry.timestep("mujoco-ratchet", params, cruise.t_end, DT_OUT_MAX)
        every = mujoco_dt_out(cruise.t_end, h)
        assert cruise.t_end / every + 1 <= STUDY_SAMPLES and every >= h
    assert mujoco_dt_out(1.0, 1e-4) == 1e-4  # under the cap: every step, as before


@pytest.mark.parametrize("vary,fragment", [
    ("drive=0:1", "drive is not a number"),
    ("m1=-1:1", "m1=-1.0 is out of range"),
    ("m1=0:1", "m1=0.0 is out of range"),
    ("L=0.01:0.04", "no design of the study can have L=0.01"),
    ("wheel_legs=3:8", "wheel_legs is a whole number"),
    ("omega_target=1:5", "only drive=servo"),
    ("m2=-1,1", "m2=-1.0 is out of range"),
    ("omega_target=1,5", "only drive=servo"),
])
def test_a_study_refuses_a_vary_no_design_can_use_before_the_first(vary, fragment):
    axis = parse_vary(vary)
    with pytest.raises(ParameterError, match=re.escape(fragment)):
        Study((axis,), sample=4 if axis.is_range else None)


def test_a_range_tied_to_another_varied_parameter_is_judged_at_its_ends():
    """L=0.03:0.3 is below r = 0.05 m at its low end, but not with r varied down to 0.01 m: a valid study."""
    Study((parse_vary("L=0.03:0.3"), parse_vary("r=0.01:0.02")), sample=4)
    with pytest.raises(ParameterError, match="no design of the study can have L=0.03"):
        Study((parse_vary("L=0.03:0.3"),), sample=4)
    Study((parse_vary("L=0.01,0.2"),))  # a grid keeps its invalid designs as recorded failures
    with pytest.raises(ParameterError, match="only drive=servo"):  # a --set no design takes
        Study((parse_vary("L=0.1,0.2"),), RobotParams(omega_target=5.0))
    Study((parse_vary("clutch_stiffness=1e4,1e5"),), RobotParams(clutch_damping=5.0))  # the spring is varied


def test_a_clutch_study_whose_every_run_fails_has_failed(monkeypatch):
    from ipir_mujoco.studies import clutch_study

    monkeypatch.setattr(clutch_study, "run_task", lambda base, point, task: {"error": "the run blew up at t=0"})
    with pytest.raises(SimulationError, match="every one of the 4 runs failed; the first: the run blew up"):
        clutch_study.run_study(RobotParams(), (1e4,), (0.0,), ("startup",), workers=1)


def test_a_clutch_study_refuses_a_set_its_drive_cannot_use():
    from ipir_mujoco.studies import clutch_study

    with pytest.raises(ParameterError, match="the startup point runs drive=torque .* omega_target=5.0"):
        clutch_study.run_study(RobotParams(omega_target=5.0), (1e4,), (0.0,), ("startup",), workers=1)


class _Skidding:
    """A skid rule that always sees a skid (the budget is judged before any comparison)."""

    name = "test"

    def skidded(self, result):
        return True


def _run(step: float, wall: float):
    return SimpleNamespace(settings={"timestep": step}, wall_time_s=wall, t_end=1.0,
                           accuracy={"residual_ratio": 0.0}, summary={})


@pytest.mark.parametrize("mode", ["stop", "warn"])
def test_the_skid_check_starts_no_repeat_past_the_wall_budget_and_names_the_steps(mode):
    """The first run took 10 s of a 30 s budget: the check needs two halvings, ~20 + 40 s more: none is started.
    'stop' fails naming the steps; 'warn' keeps the run with the check failed and the same line."""
    from ipir_mujoco.engine.run.skid_check import verify_skids

    def rerun(dt):
        raise AssertionError(f"a repeat at {dt} s was started past the budget")

    first = _run(1e-4, 10.0)
    if mode == "stop":
        with pytest.raises(SimulationError, match=r"would need runs at 5e-05 s and 2\.5e-05 s \(about 60 s"):
            verify_skids(first, rerun, mode, 1e-6, _Skidding(), wall_budget_s=30.0)
        return
    kept = verify_skids(first, rerun, mode, 1e-6, _Skidding(), wall_budget_s=30.0)
    assert kept is first and kept.accuracy["skid_check"] == "failed" and kept.accuracy["ok"] is False
    assert "would need runs at 5e-05 s and 2.5e-05 s" in kept.accuracy["violations"][0]["reason"]


def test_the_skid_check_runs_its_repeats_within_the_budget():
    """With room for the repeats (10 s spent, 60 s more needed, 100 s budget) the check goes on."""
    from ipir_mujoco.engine.run.skid_check import _past_budget

    assert _past_budget(_run(1e-4, 10.0), 0.0, 5e-5, 0, 100.0) is None
    assert _past_budget(_run(1e-4, 10.0), 0.0, 5e-5, 0, None) is None
    # after one halving (its run took 20 s, 30 s spent) one more is needed, ~40 s: past a 60 s budget
    assert "2.5e-05 s (about 40 s" in _past_budget(_run(5e-5, 30.0), 10.0, 2.5e-5, 1, 60.0)
