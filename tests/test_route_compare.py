"""Both engines along one route (ipir_mujoco/studies/comparison/route_compare.py): the window's figures on an equations' run
against its own energy audit, and the classes and confusion counts on made-up records."""

from __future__ import annotations

import pytest

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.route import route_from_tables
from ipir_mujoco.studies.comparison.route_compare import classify, confusion, engine_record, judge, window, work_difference

ROUTE = route_from_tables([dict(kind="straight", length=0.4), dict(kind="bend", radius=0.32, angle=60.0, plane=30.0),
                           dict(kind="straight", length=0.2)])


def test_a_window_is_its_runs_energy_audit_between_two_marks():
    """Over the window from the bend's start to the route's end: the time between the centre's crossings, and the
    motor's work less the kinetic and potential energy gained equal to the work the resistances and the scrub
    dissipated there (the audit closes to 1e-6 of the energy put through: test_route_runs), the scrub positive in
    this R/D 2 bend at mu_wall 0.5."""
    run = registry.run("analytic-unilateral", RobotParams(drive="motor", mu_wall=0.5), 20.0, route=ROUTE, dt_out=1e-3)
    times = run.summary["route_piece_times_s"]
    w = window(run, 1, 3)
    assert w["time_s"] == pytest.approx(times[3] - times[1], rel=1e-12)
    assert w["energy_j"] == pytest.approx(w["dissipated_j"], rel=1e-5)
    assert 0 < w["scrub_j"] < w["dissipated_j"]
    record = engine_record(run)
    assert record["time_s"] == times[3] and record["route_done"] is True
    assert record["net_work_j"] == pytest.approx(record["dissipated_j"] + record["potential_j"], rel=1e-5)
    assert window(run, 1, 3) == w and window(run, 0, 1)["time_s"] == times[1]  # mark 0 is the run's start


def _record(time_e, work_e, time_m, work_m, lift=(False, 0.0), scrub=(0.0, 0.0), done=(True, True)):
    equations = {"route_done": done[0], "time_s": time_e, "net_work_j": work_e, "dissipated_j": work_e,
                 "scrub_j": scrub[0]}
    mujoco = {"route_done": done[1], "time_s": time_m, "net_work_j": work_m, "lift_predicted": lift[0],
              "route_wheel_off_s": lift[1], "slid_m": scrub[1]}
    return judge(equations, mujoco)


def test_each_route_falls_in_one_class():
    """Within 2 % in both figures: agree, whatever else happened; beyond it a lift or scrub that was predicted and
    happened names it; a run that did not get through is stopped (which); anything else is a miss, a prediction
    that did not come true included."""
    assert _record(2.0, 4.0, 2.03, 4.07)["outcome"] == "agree"
    assert _record(2.0, 4.0, 2.03, 4.07, lift=(True, 0.2))["outcome"] == "agree"
    assert _record(2.0, 4.0, 2.1, 4.0, lift=(True, 0.2))["outcome"] == "lift"
    assert _record(2.0, 4.0, 2.0, 4.3, scrub=(0.2, 0.004))["outcome"] == "scrub"
    assert _record(2.0, 4.0, 2.0, 4.3, scrub=(0.2, 0.0005))["outcome"] == "miss"  # slid under SCRUB_FLOOR
    assert _record(2.0, 4.0, 2.1, 4.0, lift=(True, 0.0))["outcome"] == "miss"
    assert _record(2.0, 4.0, 2.1, 4.0, lift=(False, 0.3))["outcome"] == "miss"
    assert _record(2.0, 4.0, None, None, done=(True, False))["outcome"] == "stopped (MuJoCo)"
    assert _record(None, None, None, None, done=(False, False))["outcome"] == "stopped (both)"
    assert classify(_record(2.0, 4.0, 2.0, 4.0)) == "agree"


def test_work_downhill_is_judged_against_what_the_robot_dissipates():
    """Downhill the motor's net work is a small difference of large terms: MuJoCo's 0.1 J more against the
    equations' 0.5 J of work is 2.5 % of the 4 J the robot dissipated, not 20 %; uphill the work is the scale."""
    downhill = {"net_work_j": 0.5, "dissipated_j": 4.0}
    assert work_difference(downhill, {"net_work_j": 0.6}) == pytest.approx(0.025)
    assert work_difference({"net_work_j": 8.0, "dissipated_j": 4.0}, {"net_work_j": 8.4}) == pytest.approx(0.05)
    assert work_difference(downhill, {"net_work_j": None}) is None


def test_the_confusion_counts_every_route_once():
    records = [_record(2.0, 4.0, 2.0, 4.0, lift=lift) for lift in ((True, 0.1), (True, 0.0), (False, 0.1),
                                                                   (False, 0.0), (False, 0.0))]
    assert confusion(records, "lift") == {"predicted and happened": 1, "false alarm": 1, "miss": 1, "neither": 2}
