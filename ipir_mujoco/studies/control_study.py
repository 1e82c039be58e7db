"""The control study: what model-based speed control buys, and what the paper's model costs a controller
designed on it; and whether slowing the crank through the dead centres spares the modules' hand-over.

**Controllers** (:data:`CONTROLLERS`), at each crank speed of ``speeds`` [rad/s], each run to its periodic
steady state in each variant of :data:`VARIANTS` (the paper's first-order geometry with one-way clutches,
what the paper's model promises; the exact one-way equations; MuJoCo's ratchet):

* ``open-loop``: the motor at a constant voltage fraction u0, chosen so that its mean crank speed is the
  target (a secant search on the exact equations, :func:`open_loop_voltage`; the same u0 in every variant).
  A constant u0 is the motor line M_stall u0 (1 - omega / (u0 omega_noload)): it runs as ``drive = motor``
  with M_stall u0 and omega_noload u0, the same torque at every speed.
* ``pi``: ``drive = servo`` without feedforward; ``pi+paper``, ``pi+exact``: with the feedforward from the
  paper's first-order or the exact inverse kinetostatics (:func:`ipir_mujoco.registry.feedforward_table`).

**Profiles**: at ``profile_speed`` [rad/s] mean crank speed, the servo with the exact feedforward and a speed
target that dips through the dead centres by each ``dips`` value (``speed_dip``; 0 is constant speed), in
the exact equations and MuJoCo.

Per run, over the steady window (the last ``steady_cycles`` revolutions; a run that does not settle within
T_CAP is flagged ``steady`` false and read over its last STEADY_CYCLES whole revolutions): ``mean_omega_rad_s``,
``speed_ripple`` (:func:`ipir_mujoco.core.cycles.speed_figures`), ``peak_clutch_force_n`` [N],
``peak_module_accel_m_s2`` (the largest |a1|, |a2|) [m/s^2], ``energy_per_metre_j_m`` (the motor's work at the
crank per metre) [J/m], ``electrical_energy_per_metre_j_m`` [J/m] (what the motor draws: u tau omega_noload,
as V I for the DC motor with omega_noload = V / k_t, so the winding's loss tau^2 omega_noload / M_stall is
in it), ``steady_speed_m_s`` [m/s] (with ``energy_per_metre_j_m``: the run summary's periodic limit when
steady, :mod:`ipir_mujoco.core.cycles`; else the window's totals), ``peak_drive_u``, ``peak_motor_torque_n_m`` [N m], ``wall_s`` [s]. The
equations' peaks are exact (their reactions and accelerations peak at mode switches, which are samples).
MuJoCo's peak clutch force and module acceleration are left None, as the sweep leaves them
(:mod:`.sweep_metrics`): its rigid ratchet is a soft constraint that takes up each hand-over within a few steps
and overshoots by an amount set by the step, so a sampled peak measures the numerics (at 10 rad/s open loop,
11.4 N at 1 ms samples against the equations' 7.3 N); ``clutch-study`` gives the engagement loads of real,
compliant clutches in both engines.
"""

from __future__ import annotations

import functools
import math
import os
import time
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.cycles import STEADY_CYCLES, cycles, speed_figures, steady_window, travel
from ipir_mujoco.core.errors import ParameterError, SimulationError, refuse_all_failed
from ipir_mujoco.core.checks import check_numbers
from ipir_mujoco.core.params import RobotParams, check_real, check_whole, require_params

from .pool import map_unordered

CONTROLLERS = ("open-loop", "pi", "pi+paper", "pi+exact")
FEEDFORWARD = {"pi": "none", "pi+paper": "paper", "pi+exact": "exact"}
VARIANTS = ("analytic-approx-unilateral", "analytic-unilateral", "mujoco-ratchet")
PROFILE_VARIANTS = ("analytic-unilateral", "mujoco-ratchet")
SPEEDS = (5.0, 10.0)  # rad/s: the servo's torque stays inside the default motor's band at both
PROFILE_SPEED = 8.0  # rad/s
DIPS = (0.0, 0.1, 0.2, 0.3)
QUICK_SPEEDS, QUICK_DIPS = (10.0,), (0.0, 0.2)
T_CAP = 20.0  # s: each run's cap on the way to its steady state
DT_OUT = 1e-3  # s
WALL_BUDGET_S = 300.0  # s per run
SEARCH_STEPS, SEARCH_TOL = 8, 1e-4  # the open-loop voltage's secant search: at most, and its relative tolerance
TRACE_POINTS = 240  # samples of the crank speed over one steady revolution, kept for the figure


@dataclass(frozen=True)
class Task:
    """One run: ``part`` 'controllers' or 'profile', a variant, a controller, the mean crank speed [rad/s],
    the speed target's dip, and u0 (open loop only)."""

    part: str
    variant: str
    controller: str
    speed: float
    dip: float = 0.0
    u0: float | None = None


def check_base(base: RobotParams) -> None:
    """The study sets the drive and the controller's parameters itself: given ones are refused (one line)."""
    require_params(base)
    defaults = RobotParams()
    for name in ("drive", "omega_target", "speed_dip", "feedforward"):
        if getattr(base, name) != getattr(defaults, name):
            raise ParameterError(f"{name}={getattr(base, name)!r} in --set or --config: the control study sets it; "
                                 "allowed: --speeds, --dips, --profile-speed")
    if base.clutch_stiffness is not None or base.mu_wall is not None:
        raise ParameterError("the control study runs on rigid clutches with unlimited grip; allowed: "
                             "clutch_stiffness=rigid and mu_wall=unlimited")


def design(base: RobotParams, task: Task) -> RobotParams:
    """The parameter set of ``task`` (ParameterError, one line, where the servo cannot hold it)."""
    if task.controller == "open-loop":
        return base.replace(drive="motor", M_stall=base.M_stall * task.u0, omega_noload=base.omega_noload * task.u0)
    return base.replace(drive="servo", omega_target=task.speed, speed_dip=task.dip,
                        feedforward=FEEDFORWARD[task.controller])


def check_speeds(base: RobotParams, speeds: Sequence[float], dips: Sequence[float], profile_speed: float) -> None:
    """Every speed and dip checked before any run: as the parameter set checks omega_target and speed_dip."""
    speeds, dips = check_numbers("speeds", speeds), check_numbers("dips", dips)
    if not speeds and not dips:
        raise ParameterError("--speeds and --dips are both empty; allowed: at least one value")
    for w in speeds:
        design(base, Task("controllers", VARIANTS[0], "pi", check_real("--speeds", w, unit="rad/s")))
    for a in dips:
        design(base, Task("profile", VARIANTS[1], "pi+exact", check_real("--profile-speed", profile_speed,
                                                                         unit="rad/s"), a))


def window(run) -> tuple[float, float, bool]:
    """(t0, t1) [s] of the steady window of ``run`` and whether it is steady (else its last STEADY_CYCLES
    whole revolutions)."""
    tol, n = run.steady_test
    found = cycles(run.series)
    steady = steady_window(found, tol, n, run.steady_target)
    if steady is not None:
        return steady[0].t_start, steady[-1].t_end, True
    last = found[-STEADY_CYCLES:]
    if len(last) < STEADY_CYCLES:
        raise SimulationError(f"fewer than {STEADY_CYCLES} crank revolutions within {run.t_end:g} s")
    return last[0].t_start, last[-1].t_end, False


def run_metrics(run, params: RobotParams) -> dict:
    """The study's figures of one run over its steady window (module docstring)."""
    s = run.series
    t0, t1, steady = window(run)
    t = s["t"]
    inside = (t >= t0) & (t <= t1)
    out = {"steady": steady, "t_steady_s": t1 if steady else None, **speed_figures(s, t0, t1)}
    if run.engine == "mujoco":  # its rigid ratchet's peaks measure its step (module docstring)
        out["peak_clutch_force_n"] = out["peak_module_accel_m_s2"] = None
    else:
        lam = np.maximum(s["lambda1"][inside], s["lambda2"][inside])
        out["peak_clutch_force_n"] = float(lam.max())
        out["peak_module_accel_m_s2"] = float(max(np.abs(s["a1"][inside]).max(), np.abs(s["a2"][inside]).max()))
    edges = np.array([t0, t1])
    position = np.interp(edges, t, travel(s))
    distance = float(position[1] - position[0])
    if steady:  # the summary's, the periodic limit's (core.cycles: the stated accuracy)
        out["steady_speed_m_s"] = run.summary["steady_speed_m_s"]
        out["energy_per_metre_j_m"] = run.summary["energy_per_metre_j_m"]
    else:  # no steady state: the window's own totals
        work = np.diff(np.interp(edges, t, s["motor_work"]))[0]
        out["steady_speed_m_s"] = distance / (t1 - t0)
        out["energy_per_metre_j_m"] = float(work) / distance if distance > 0 else None
    tt, omega = t[inside], s["omega"][inside]
    if "drive_u" in s:
        u, torque = s["drive_u"][inside], s["motor_torque"][inside]
    else:  # the motor at its full (equivalent) voltage: the torque from the engine's own power column
        u = np.ones_like(tt)
        torque = np.divide(s["motor_power"][inside], omega, out=np.full_like(tt, np.nan), where=omega > 0)
    drawn = float(np.trapezoid(u * torque, tt)) * params.omega_noload  # [J]: u tau omega_noload over the window
    out["electrical_energy_per_metre_j_m"] = drawn / distance if distance > 0 and math.isfinite(drawn) else None
    turn = (s["phi"] >= s["phi"][inside][-1] - 2 * math.pi) & inside  # the window's last revolution
    keep = np.unique(np.linspace(0, int(turn.sum()) - 1, TRACE_POINTS).astype(int))
    out["trace"] = {"phi_rad": (s["phi"][turn][keep] - params.phi0).tolist() if turn.any() else [],
                    "omega_rad_s": s["omega"][turn][keep].tolist() if turn.any() else []}
    return out


def run_task(base: RobotParams, task: Task) -> dict:
    """One run's figures, or {'error': one line} where the engine fails."""
    params = design(base, task)
    started = time.perf_counter()
    try:
        run = registry.run(task.variant, params, T_CAP, dt_out=DT_OUT, until_steady=True,
                           wall_budget_s=WALL_BUDGET_S)
        metrics = run_metrics(run, params)
    except SimulationError as exc:
        return {"error": str(exc), "wall_s": time.perf_counter() - started}
    metrics["wall_s"] = time.perf_counter() - started
    return metrics


def _run_item(base: RobotParams, task: Task) -> dict:
    try:
        return run_task(base, task)
    except (ParameterError, SimulationError):
        raise
    except Exception as exc:  # noqa: BLE001 (a surprise inside an engine: one line naming the run)
        raise SimulationError(f"{task}: {type(exc).__name__}: {' '.join(str(exc).split())[:200]}") from None


def open_loop_voltage(base: RobotParams, speed: float, variant: str = "analytic-unilateral") -> dict:
    """u0 whose constant-voltage motor cruises at mean crank speed ``speed`` [rad/s] in ``variant``: a secant
    search on the steady mean speed (at most SEARCH_STEPS runs, to SEARCH_TOL relative). Returns u0, the
    speed it reached and the runs it took."""
    def mean(u0: float) -> float:
        run = registry.run(variant, design(base, Task("controllers", variant, "open-loop", speed, u0=u0)), T_CAP,
                           dt_out=DT_OUT, until_steady=True, wall_budget_s=WALL_BUDGET_S)
        if run.stall is not None:
            return 0.0
        return float(run.summary["mean_omega_rad_s"])

    a = speed / base.omega_noload
    b = min(1.0, a + 0.2)
    fa, fb = mean(a) - speed, mean(b) - speed
    runs = 2
    while abs(fb) > SEARCH_TOL * speed and runs < SEARCH_STEPS:
        if fb == fa:
            break
        a, b, fa = b, min(1.0, max(1e-3, b - fb * (b - a) / (fb - fa))), fb
        fb = mean(b) - speed
        runs += 1
    if abs(fb) > 10 * SEARCH_TOL * speed:
        raise SimulationError(f"no constant voltage of the motor cruises at {speed:g} rad/s (best u0={b:.4g}: "
                              f"{fb + speed:.4g} rad/s after {runs} runs); allowed: a slower --speeds value")
    return {"u0": b, "mean_omega_rad_s": fb + speed, "runs": runs}


def run_study(base: RobotParams, speeds: Sequence[float] = SPEEDS, dips: Sequence[float] = DIPS,
              profile_speed: float = PROFILE_SPEED, *, workers: int | None = None,
              progress: Callable[[str], None] = lambda _m: None) -> dict:
    """Both parts of the study (module docstring) as one JSON-ready dict."""
    check_base(base)
    check_speeds(base, speeds, dips, profile_speed)
    workers = check_whole("workers", workers, low=1, high=1024) if workers is not None else (os.cpu_count() or 1)
    started = time.perf_counter()
    voltages = {}
    for w in speeds:
        voltages[w] = open_loop_voltage(base, w)
        progress(f"open loop at {w:g} rad/s: u0 = {voltages[w]['u0']:.5f} ({voltages[w]['runs']} runs)")
    tasks = [Task("controllers", v, c, w, 0.0, voltages[w]["u0"] if c == "open-loop" else None)
             for w in speeds for c in CONTROLLERS for v in VARIANTS]
    tasks += [Task("profile", v, "pi+exact", profile_speed, a) for a in dips for v in PROFILE_VARIANTS]
    results: dict[Task, dict] = {}

    def done(task: Task, result: dict) -> None:
        results[task] = result
        status = result["error"] if "error" in result else f"{result['wall_s']:.2f} s"
        progress(f"[{len(results)}/{len(tasks)}] {task.part} {task.variant} {task.controller} {task.speed:g} rad/s"
                 + (f" dip {task.dip:g}" if task.part == "profile" else "") + f": {status}")

    analytic_first = sorted(tasks, key=lambda t: (t.variant.startswith("mujoco"), -t.dip))  # the slow ones first
    map_unordered(functools.partial(_run_item, base), analytic_first, workers, done)
    refuse_all_failed([results[t].get("error") for t in tasks], "runs")

    def row(task: Task) -> dict:
        return {"variant": task.variant, "controller": task.controller, "speed_rad_s": task.speed,
                "speed_dip": task.dip, "open_loop_u0": task.u0, **results[task]}
    return {"params": base.as_dict(), "speeds_rad_s": list(speeds), "controllers": list(CONTROLLERS),
            "variants": list(VARIANTS), "open_loop": {f"{w:g}": voltages[w] for w in speeds},
            "rows": [row(t) for t in tasks if t.part == "controllers"],
            "profile": {"speed_rad_s": profile_speed, "dips": list(dips), "variants": list(PROFILE_VARIANTS),
                        "rows": [row(t) for t in tasks if t.part == "profile"]},
            "dt_out_s": DT_OUT, "t_cap_s": T_CAP, "wall_s": time.perf_counter() - started}
