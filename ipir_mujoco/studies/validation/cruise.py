"""The robot at cruise under a real motor: every rung of the model ladder run to its periodic steady state.

Each rung of the validation ladder (the paper's model; exact geometry; the rod's mass; MuJoCo with the
paper's locks; the one-way-clutch equations; MuJoCo's ratchet) is driven by the same DC gearmotor,
torque M_stall (1 - omega / omega_noload), from rest until its per-revolution mean speed settles
(``until_steady``; :mod:`ipir_mujoco.core.cycles`), and its steady state is read from the run's
summary: time to steady state, steady speed, distance per revolution, energy per metre (motor work at
the crank per metre), efficiency (work against the resistances / motor work), peak clutch reaction;
and from them the mean crank speed 2 pi v / d [rad/s] and the mean crank torque (motor work per
revolution / 2 pi) [N m], what the motor sees.

Cross-check: each MuJoCo rung against the equations of the same mechanism (locks by the paper's rule
against the exact equations with the rod; the ratchet against the one-way-clutch equations), with
:func:`ipir_mujoco.studies.compare.compare_runs`' summary comparison. Steady speed, distance per
revolution and energy per metre must agree within :data:`CROSS_CHECK_TOL` (its derivation is at its
definition). The peak clutch reaction is compared too but not held to it: see :data:`CHECKED`.

:func:`cruise_study` returns a JSON-ready dict (``sections.cruise`` of metrics.json)::

    params        the motor-driven parameter set (SI)
    quick, t_cap_s, dt_out_s (the equations'; MuJoCo's runs are sampled every step), cross_check_tol, wall_s,
    workers
    rungs         [{name, isolates, engine, geometry, clutch, mujoco_clutch, timestep, wall_s, steady,
                   stalled, stall_reason, revolutions, t_steady_s, steady_speed_m_s, distance_per_rev_m,
                   energy_per_metre_j_m, efficiency, peak_clutch_force_n, crank_speed_rad_s,
                   crank_torque_n_m, crank_speed_range_rad_s ([min, max] over the steady window),
                   change_vs_paper: {figure: (rung - paper) / |paper|},
                   history: {t, omega, speed} (every HISTORY_DT s: s, rad/s, m/s, robot = mean of the
                   modules), revolutions_end: {t, speed} (per-revolution mean speed [m/s] at each
                   revolution's end [s])} or {name, isolates, error}]
    cross_checks  [{mujoco, equations, figures: {figure: {a, b, relative}} (a = equations, b = MuJoCo),
                   worst_checked, within, halved_step: the same for MuJoCo at half its timestep (full
                   run only)}]
"""

from __future__ import annotations

import functools
import math
import os
import time
from typing import Callable

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.cycles import LIMIT_ACCURACY, cycles, travel
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import RunResult

from ...engine.loop.monitor import EXCURSION_PER_R, RESIDUAL_TOL
from ..comparison.compare import STEADY_FIGURES, compare_runs, relative_change
from .ladder import CROSS_CHECKS, LADDER, Rung
from ..pool import map_unordered

T_CAP = 10.0  # s: cap of every run; several times the default motor's settling time
DT_OUT = 1e-3  # s: the equations' output interval (each revolution's end is an exact sample whatever it is);
# MuJoCo is sampled at every step (run_rung)
HISTORY_DT = 4e-3  # s: interval of the stored time histories (dozens of points per crank revolution at cruise)
# Figures held to CROSS_CHECK_TOL. The peak clutch reaction is not: a rigid clutch's reaction jumps where
# it engages, which MuJoCo's soft constraint resolves over a few steps with an overshoot that depends on
# the step and on whether a sample falls on it.
CHECKED = ("steady_speed_m_s", "distance_per_rev_m", "energy_per_metre_j_m")
# Relative tolerance of the MuJoCo-against-equations cross-check at steady state, from the tolerances that
# hold each engine, not from the differences seen:
# - MuJoCo's accuracy monitor holds the energy residual to RESIDUAL_TOL = 1e-3 of the energy put through
#   the robot, which keeps revolutions and travel within 0.1 % of the converged mechanism (the monitor's
#   calibration, engine/loop/monitor.py); at steady state the cumulative residual ratio tends to the per-
#   revolution one, so energy per metre is held to it too;
# - the ratchet's backward excursion, at most EXCURSION_PER_R r, costs at most EXCURSION_PER_R / 2 of the
#   travel 2 r per stroke;
# - each engine's steady figures lie within its stated LIMIT_ACCURACY of its own limit cycle (2e-5 for the
#   equations, 3e-4 for MuJoCo; tests/test_steady_limit.py holds them), so the two differ by at most the sum.
# The equations' own error (rtol 1e-10) is negligible beside these.
CROSS_CHECK_TOL = RESIDUAL_TOL + EXCURSION_PER_R / 2 + LIMIT_ACCURACY["analytic"] + LIMIT_ACCURACY["mujoco"]
# = 1.42e-3

Progress = Callable[[str], None]


RUNGS = LADDER  # every rung of the model ladder, each run to its steady state


def motor_params(params: RobotParams) -> RobotParams:
    """``params`` driven by its motor (M_stall, omega_noload as given; defaults 0.5 N m, 30 rad/s)."""
    return params.replace(drive="motor")


def run_rung(params: RobotParams, rung: Rung, t_cap: float = T_CAP, dt_out: float = DT_OUT,
             settings=None) -> RunResult:
    """One rung to its steady state (``t_cap`` [s] caps it); ``settings``: MuJoCo's SolverSettings, else automatic.

    The equations are sampled every ``dt_out`` [s] (and at every mode switch, where their rigid clutches'
    reactions peak); MuJoCo at every step (the step it would choose for ``dt_out``, or ``settings``'):
    its rigid clutches engage through a soft constraint within a few steps, and sampled every ``dt_out``
    the peak reaction lands on whichever step the sample hits.
    """
    p = rung.params(params)
    if not registry.variant(rung.variant).is_mujoco:
        return registry.run(rung.variant, p, t_cap, dt_out=dt_out, until_steady=True)
    return registry.run(rung.variant, p, t_cap, dt_out=dt_out, until_steady=True, settings=settings, every_step=True)


def _task(params: RobotParams, rung: Rung, t_cap: float, dt_out: float, halve: bool):
    """A pool task: the rung's run (or its one-line failure), and with ``halve`` MuJoCo at half its step."""
    started = time.perf_counter()
    try:
        run = run_rung(params, rung, t_cap, dt_out)
    except (ParameterError, SimulationError) as exc:
        return {"error": " ".join(str(exc).split())}, None, time.perf_counter() - started
    halved = None
    if halve and registry.variant(rung.variant).is_mujoco:
        try:
            halved = run_rung(params, rung, t_cap, dt_out, registry.halved_settings(run))
        except (ParameterError, SimulationError) as exc:
            halved = {"error": " ".join(str(exc).split())}
    return run, halved, time.perf_counter() - started


def _run_all(params, t_cap, dt_out, halve, workers, progress) -> dict:
    """{rung name: (run or {"error"}, halved, wall [s])}: in a process pool of ``workers`` (1: here)."""
    done: dict = {}

    def finished(rung: Rung, outcome) -> None:
        done[rung.name] = outcome
        run = outcome[0]
        status = run["error"] if isinstance(run, dict) else (
            f"steady {run.summary['steady_speed_m_s']:.4g} m/s from {run.summary['t_steady_s']:.3g} s"
            if run.summary["steady"] else (run.stall or f"not steady by {run.t_end:g} s"))
        progress(f"[{len(done)}/{len(RUNGS)}] {rung.name}: {status} ({outcome[2]:.2f} s)")

    # the MuJoCo rungs first: the longest tasks
    order = sorted(RUNGS, key=lambda r: not registry.variant(r.variant).is_mujoco)
    map_unordered(functools.partial(_rung_task, params, t_cap, dt_out, halve), order, workers, finished)
    return done


def _rung_task(params, t_cap, dt_out, halve, rung):
    return _task(params, rung, t_cap, dt_out, halve)


def _rounded(values, digits: int = 6) -> list[float]:
    return [float(f"{v:.{digits}g}") for v in np.asarray(values, dtype=float)]


def rung_record(rung: Rung, run: RunResult, wall_s: float) -> dict:
    """The steady-state figures and the time histories of one rung's run (see the module docstring)."""
    s = run.summary
    record = {"name": rung.name, "isolates": rung.describe(run.params), "engine": run.engine,
              "geometry": run.geometry, "clutch": run.clutch, "mujoco_clutch": registry.variant(rung.variant).clutch,
              "timestep": run.settings.get("timestep"),
              "wall_s": wall_s, "steady": s["steady"], "stalled": s["stalled"], "stall_reason": s["stall_reason"],
              "revolutions": s["revolutions"], **{k: s[k] for k in STEADY_FIGURES}}
    v, d, e = s["steady_speed_m_s"], s["distance_per_rev_m"], s["energy_per_metre_j_m"]
    steady = s["steady"] and v is not None and d and e is not None
    record["crank_speed_rad_s"] = 2 * math.pi * v / d if steady else None
    record["crank_torque_n_m"] = e * d / (2 * math.pi) if steady else None
    series = run.series
    t = np.asarray(series["t"], dtype=float)
    found = cycles(series)
    window = t >= (found[-run.steady_test[1]].t_start if steady else t[-1])
    omega = np.asarray(series["omega"])[window]
    record["crank_speed_range_rad_s"] = [float(omega.min()), float(omega.max())] if steady else None
    keep = np.concatenate([np.diff(t) > 0, [True]])  # of a duplicated switch instant, the later sample
    grid = np.arange(0.0, t[-1] + 1e-12, HISTORY_DT)
    speed = 0.5 * (np.asarray(series["v1"]) + np.asarray(series["v2"]))
    record["history"] = {"t": _rounded(grid), "omega": _rounded(np.interp(grid, t[keep], series["omega"][keep])),
                         "speed": _rounded(np.interp(grid, t[keep], speed[keep]))}
    record["revolutions_end"] = {"t": _rounded([c.t_end for c in found]),
                                 "speed": _rounded([c.mean_speed_m_s for c in found])}
    record["travel_m"] = float(travel(series)[-1] - travel(series)[0])
    return record


def cross_check(equations: RunResult, mujoco: RunResult) -> dict:
    """compare_runs' summary comparison of the steady figures: a = equations, b = MuJoCo."""
    summary = compare_runs(equations, mujoco)["summary"]
    figures = {k: summary[k] for k in STEADY_FIGURES}
    checked = [figures[k]["relative"] for k in CHECKED]
    worst = None if None in checked else max(abs(x) for x in checked)
    return {"figures": figures, "worst_checked": worst, "within": worst is not None and worst <= CROSS_CHECK_TOL}


def cruise_study(params: RobotParams, quick: bool = False, progress: Progress = lambda _m: None,
                 workers: int | None = None, t_cap: float = T_CAP, dt_out: float = DT_OUT) -> dict:
    """Every rung to its steady state under ``params``' motor, and the cross-checks (module docstring).

    ``quick`` leaves out the MuJoCo runs at half their timestep. ``workers``: processes for the rungs
    (default: the cores, at most one per rung; 1 runs them here): the rungs are independent, and a pool
    pays for its start even for these short runs.
    """
    started = time.perf_counter()
    motor = motor_params(params)
    workers = min(os.cpu_count() or 1, len(RUNGS)) if workers is None else workers
    outcomes = _run_all(motor, t_cap, dt_out, not quick, workers, progress)
    rungs, runs = [], {}
    for rung in RUNGS:
        run, _, wall = outcomes[rung.name]
        if isinstance(run, dict):
            rungs.append({"name": rung.name, "isolates": rung.describe(motor), **run})
            continue
        runs[rung.name] = run
        rungs.append(rung_record(rung, run, wall))
    paper = rungs[0] if "error" not in rungs[0] else None
    for record in rungs:
        if "error" not in record:
            record["change_vs_paper"] = {k: (None if paper is None else relative_change(record[k], paper[k]))
                                         for k in STEADY_FIGURES + ("crank_speed_rad_s", "crank_torque_n_m")}
    checks = []
    for mj_name, eq_name in CROSS_CHECKS:
        entry = {"mujoco": mj_name, "equations": eq_name}
        if mj_name in runs and eq_name in runs:
            entry.update(cross_check(runs[eq_name], runs[mj_name]))
            halved = outcomes[mj_name][1]
            if isinstance(halved, RunResult):
                entry["halved_step"] = {"timestep": halved.settings["timestep"],
                                        **cross_check(runs[eq_name], halved)}
            elif isinstance(halved, dict):
                entry["halved_step"] = halved
        else:
            entry["error"] = "a run of the pair failed (see its rung)"
        checks.append(entry)
    return {"params": motor.as_dict(), "quick": quick, "t_cap_s": t_cap, "dt_out_s": dt_out,
            "cross_check_tol": CROSS_CHECK_TOL, "checked": list(CHECKED), "rungs": rungs, "cross_checks": checks,
            "workers": workers, "wall_s": time.perf_counter() - started}
