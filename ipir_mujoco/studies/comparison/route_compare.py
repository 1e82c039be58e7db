"""Both engines along one route: the equations (``analytic-unilateral``, the wheels' scrub in its closed form) and
the wheeled MuJoCo model (``mujoco-wheels``), their times and motor work, and MuJoCo's lifts and slides beside the
closed-form checks that predict them.

The figures are read at the robot's centre (midway along the route between module 1's A and module 2's C): the
time it reaches a mark (the route's pieces' starts and its end, ``route_piece_times_s``, interpolated between
samples) and the motor's work then. Not at module 1's A, where a run ends: A stands half of each revolution, so
the time it reaches a mark jumps by a stand's length (up to half a revolution, 2-3 % of a short route's time) as
the two engines' phases differ by a hair; the centre always moves while a module does, so its times move as the
motion does.

:func:`compare_route` runs both and returns a JSON-ready record; :func:`classify` puts it in one of the
acceptance's classes (mjcf/README.md, "MuJoCo against the equations in bends"):

- ``agree``: both reached the route's end, time and motor work within AGREE (2 %): the work net of the kinetic
  energy the robot has at the end (within a revolution it swings by tenths of a joule, so the raw work would
  compare the engines' phases), its difference over the energy put through the robot (:func:`work_difference`:
  the equations' net motor work, or what their resistances dissipated where a route downhill makes that more);
- ``lift``, ``scrub``: beyond AGREE, and a wheel left its wall (MuJoCo's ``route_wheel_off_s`` > 0) where the
  lift-off check predicted it (``lift_predicted``: the check on the run's own loads with what each bend adds,
  :func:`ipir_mujoco.core.wall_summary.run_summary`), or the wheels slid sideways on the wall (MuJoCo's ``slid1``,
  ``slid2``, from ``core.side_check.SCRUB_FLOOR`` on) where the equations' closed form has a wheel beyond its
  friction limit in a bend (their ``scrub_j`` > 0) or the same check predicted a slide (``scrub_predicted``; a
  series without the linkage's force columns: :func:`ipir_mujoco.core.side_check.side_summary`'s);
- ``stopped``: an engine did not reach the route's end, each engine's ``route_stop`` line says why (``both``
  where both stopped, else which);
- ``over budget``: a run exceeded its wall-time budget (no verdict on its physics);
- ``miss``: beyond AGREE with no such prediction that came true.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.pipe import SCRUB_FLOOR, side_summary

AGREE = 0.02  # the acceptance's bound on the two engines' time and motor work along a route
# the series' columns of work dissipated (the rolling resistance, skids, the scrub in bends; MuJoCo's contacts'
# work is its skid_work, its hubs' friction its friction_work)
DISSIPATED = ("friction_work", "skid_work", "scrub_work")
EQUATIONS, MUJOCO = "analytic-unilateral", "mujoco-wheels"
DT_OUT = 1e-3  # s: the samples the marks' times are read from (good to this, interpolated: far below 2 % of 1 s)


def window(run, first: int, last: int) -> dict:
    """The run's figures between its centre's crossings of route mark ``first`` and ``last`` (indices into
    ``route_piece_times_s``: the pieces' starts, then the route's end; 0 is the run's start, t = 0, the centre
    then already L / 2 or so into the route): ``time_s`` [s], ``work_j`` (the motor's
    work) and ``energy_j`` (the motor's work less the kinetic and potential energy gained: what the robot
    dissipated) [J], ``scrub_j`` (the wheels' sliding in the bends: the equations' ``scrub_work``; MuJoCo's
    contacts' ``skid_work``, which also holds the soft contacts' creep and any skid) [J], ``dissipated_j`` (the
    work of every resistance: DISSIPATED's columns) [J]; None where the run did not get there."""
    times = run.summary["route_piece_times_s"]
    t_a, t_b = (0.0 if first == 0 else times[first]), times[last]
    if t_a is None or t_b is None:
        return {"time_s": None, "work_j": None, "energy_j": None, "scrub_j": None, "potential_j": None,
                "dissipated_j": None}
    t, series = run.series["t"], run.series

    def gained(column) -> float:
        return float(np.diff(np.interp([t_a, t_b], t, column))[0])

    scrub = series["scrub_work"] if "scrub_work" in series else series.get("skid_work")
    work, potential = gained(series["motor_work"]), gained(series["potential"])
    return {"time_s": t_b - t_a, "work_j": work, "potential_j": potential,
            "energy_j": work - gained(series["kinetic"]) - potential,
            "scrub_j": None if scrub is None else gained(scrub),
            "dissipated_j": sum(gained(series[c]) for c in DISSIPATED if c in series)}


def engine_record(run) -> dict:
    """One engine's run along a route: its route keys, its centre's time and the motor's work from the start to
    the route's end (:func:`window`), its energy audit over the whole run and each module's backward slip [m]."""
    s = run.summary
    out = {key: s.get(key) for key in ("route_done", "route_time_s", "route_s_m", "route_stop", "route_wheel_off_s",
                                       "lift_predicted", "least_press1_n", "least_press2_n", "scrub_predicted")}
    whole = window(run, 0, len(s["route_piece_times_s"]) - 1)
    net = None if whole["work_j"] is None else whole["energy_j"] + whole["potential_j"]
    out.update(time_s=whole["time_s"], work_j=whole["work_j"], net_work_j=net, scrub_j=whole["scrub_j"],
               dissipated_j=whole["dissipated_j"], potential_j=whole["potential_j"],
               timestep_s=run.settings.get("timestep"), residual_ratio=s["accuracy"].get("residual_ratio"),
               energy={key: float(value) for key, value in run.energy.items()}, slip_m=(s.get("slip1_m"),
                                                                                      s.get("slip2_m")))
    if "slid1" in run.series:
        out["slid_m"] = max(float(run.series["slid1"][-1]), float(run.series["slid2"][-1]))
        if out["scrub_predicted"] is None:  # a series without the linkage's force columns: the straight pipe's
            # check on the drive's loads (the rod's side force and the motor's couple against the rings' sideways grip)
            out["scrub_predicted"] = bool(side_summary(run.params, run.series)["scrub_predicted"])
    return out


def run_engine(variant: str, params, route, t_cap: float, dt_out: float = DT_OUT,
               wall_budget_s: float | None = None) -> tuple[object | None, dict]:
    """(the run or None, its record :func:`engine_record` or {'error': line}) of ``variant`` along ``route`` for at
    most ``t_cap`` [s] of simulated time and ``wall_budget_s`` [s] of wall time (None: the package's default; a
    MuJoCo run's skid check keeps the step it reached within it); ``wall_s`` [s] in the record."""
    started = time.perf_counter()
    options = {"accuracy": "warn"} if variant == MUJOCO else {}
    try:
        run = registry.run(variant, params, t_cap, route=route, dt_out=dt_out, wall_budget_s=wall_budget_s,
                           **options)
    except SimulationError as exc:
        return None, {"error": str(exc), "route_done": False, "route_stop": f"failed: {exc}",
                      "over_budget": "wall-time budget" in str(exc), "wall_s": time.perf_counter() - started}
    record = engine_record(run)
    record["wall_s"] = time.perf_counter() - started
    return run, record


def compare_route(params, route, t_cap: float, dt_out: float = DT_OUT, wall_budget_s: float | None = None,
                  keep=None) -> dict:
    """Both engines along ``route`` (module docstring) with ``params``, each for at most ``t_cap`` [s] and
    ``wall_budget_s`` [s] of wall time: {'equations': record, 'mujoco': record, 'time_diff', 'work_diff' (MuJoCo's
    over the equations' less 1, None where either did not reach the end), 'lift', 'scrub' ({'predicted',
    'happened'}), 'outcome' (:func:`classify`)}; ``keep``, if given, is called with MuJoCo's run where it
    finished (a benchmark keeps its series)."""
    _, equations = run_engine(EQUATIONS, params, route, t_cap, dt_out, wall_budget_s)
    run, mujoco = run_engine(MUJOCO, params, route, t_cap, dt_out, wall_budget_s)
    if keep is not None and run is not None:
        keep(run)
    return judge(equations, mujoco)


def relative(a: float | None, b: float | None) -> float | None:
    """a / b - 1, or None where either is missing (or b is 0)."""
    return None if a is None or b is None or b == 0 else a / b - 1.0


def work_difference(equations: dict, mujoco: dict, work: str = "net_work_j") -> float | None:
    """MuJoCo's motor work less the equations' (each net of the kinetic energy the robot has at the route's end:
    ``net_work_j``) over the energy put through the robot: the equations' net motor work, or the work their
    resistances dissipated where that is more (a route downhill, where gravity does part of the work and the
    motor's share is small or negative: a difference in what the robot dissipates is judged against what it
    dissipates, not against the small difference of two large terms); None where either is missing. ``work``: the
    records' key to compare (a bend's window: ``energy_j``, what the robot dissipated there)."""
    w_eq, w_mj, lost = equations.get(work), mujoco.get(work), equations.get("dissipated_j")
    if w_eq is None or w_mj is None:
        return None
    scale = max(abs(w_eq), lost or 0.0)
    return None if scale == 0 else (w_mj - w_eq) / scale


def judge(equations: dict, mujoco: dict, work: str = "net_work_j", done: str = "route_done") -> dict:
    """The comparison of two engine records (:func:`compare_route`'s record from them); ``work``: the key of the
    work compared (:func:`work_difference`), ``done``: of whether a run got through (a bend's window: ``energy_j``
    and ``passed``)."""
    lift = {"predicted": bool(mujoco.get("lift_predicted")), "happened": (mujoco.get("route_wheel_off_s") or 0.0) > 0}
    scrub = {"predicted": (equations.get("scrub_j") or 0.0) > 0 or bool(mujoco.get("scrub_predicted")),
             "happened": (mujoco.get("slid_m") or 0.0) >= SCRUB_FLOOR}
    record = {"equations": equations, "mujoco": mujoco, "lift": lift, "scrub": scrub,
              "time_diff": relative(mujoco.get("time_s"), equations.get("time_s")),
              "work_diff": work_difference(equations, mujoco, work)}
    record["outcome"] = classify(record, done)
    return record


def classify(record: dict, done: str = "route_done") -> str:
    """The record's class (module docstring): 'agree', 'lift', 'scrub', 'stopped (both|MuJoCo|equations)' or
    'miss'; ``done``: the engine records' key of whether a run got through."""
    if record["equations"].get("over_budget") or record["mujoco"].get("over_budget"):
        return "over budget"
    done = (bool(record["equations"].get(done)), bool(record["mujoco"].get(done)))
    if not all(done):
        return "stopped (" + ("both" if not any(done) else "MuJoCo" if done[0] else "equations") + ")"
    diffs = (record["time_diff"], record["work_diff"])
    if all(d is not None and abs(d) <= AGREE for d in diffs):
        return "agree"
    for key in ("lift", "scrub"):
        if record[key]["predicted"] and record[key]["happened"]:
            return key
    return "miss"


def confusion(records, key: str) -> dict[str, int]:
    """The ``key`` ('lift' | 'scrub') check against what MuJoCo did over ``records``: counts of predicted and
    happened, false alarms (predicted, did not happen), misses (happened, not predicted) and neither."""
    out = {"predicted and happened": 0, "false alarm": 0, "miss": 0, "neither": 0}
    for r in records:
        p, h = r[key]["predicted"], r[key]["happened"]
        out["predicted and happened" if p and h else "false alarm" if p else "miss" if h else "neither"] += 1
    return out


def percent(value: float | None) -> str:
    """A relative difference in %, or '-' where it is missing."""
    return "-" if value is None or not math.isfinite(value) else f"{100 * value:+.2f} %"
