"""Climbing ability: the steepest pipe a design climbs with its drive, and its speed against the incline.

The pipe rises ``incline`` degrees; gravity pulls every body back along it with g sin(incline).
Three limits, in s = sin(incline):

* **Restart limit** (quasi-static, any drive): at rest at crank angle phi, the drive's torque at rest
  M0 (the constant M, or the motor's M_stall) must move the module the linkage drives forward (module
  1 while the gap shrinks, K(phi) < 0; module 2 while it grows, K > 0) against its resistance and the
  weight it carries, the other module held by its clutch. Statics
  (:meth:`~ipir_mujoco.analytic.dynamics.OneDofDynamics.static_holds`) gives that module's hold
  R_i(M), affine in M; it moves once R_i + F_ri < 0, so the torque it needs is the M with
  R_i(M) = -F_ri (zero on a dead centre, where no torque reaches a module). With first-order
  kinematics and a massless rod that is r |sin phi| (F_ri + m_i g s). The required torque is
  affine in s, M_req = A(phi) + s B(phi) with B >= 0, so the robot restarts at every crank angle as
  long as s <= min over phi of (M0 - A) / B. Above it a robot stopped at the hardest angle stays there.
* **Steady-climb limit** (the motor): from rest at phi0 the run reaches its periodic steady state with
  a positive speed (runs with ``until_steady``). The crank's kinetic energy can carry it over the
  hardest angle, so this can lie above the restart limit. Found by bisection on the incline, between
  the restart limit and the energy bound, per engine.
* **Energy bound**: over a steady revolution each module advances at least one stroke 2r (one-way
  clutches), and the drive gives at most 2 pi M0 (the motor's torque never exceeds M_stall while the
  crank turns forward), so steady climbing needs 2 pi M0 >= 2 r (F_r1 + F_r2 + m g s), m the robot's
  mass: s <= (pi M0 / r - F_r1 - F_r2) / (m g).

Efficiency on a slope: the summary's ``efficiency`` (:func:`ipir_mujoco.core.cycles.efficiency`)
counts the work against the resistances and into height as useful, over the energy put in by the
motor and by gravity where it pulls the robot forward (downhill).
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy.optimize import minimize_scalar

from ipir_mujoco import registry
from ipir_mujoco.core.cycles import cycles, travel
from ipir_mujoco.core.cycles import steady_window as settled_cycles  # its own steady_window takes a run
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.analytic.forces import drive_torque
from ipir_mujoco.core.options import study_dt_out
from ipir_mujoco.core.params import RobotParams, check_real
from ipir_mujoco.core.results import REST_SPEED, RunResult  # REST_SPEED: m/s, at rest below it

from .sweep_metrics import mean_speed
from .sweep_space import DT_OUT as SWEEP_DT_OUT, T_END_STEADY

# the variants a climb study runs by default: the exact models with one-way clutches, one per engine
CLIMB_VARIANTS = ("analytic-unilateral", "mujoco-ratchet")
OLDER_NAMES = {"ENGINES": "CLIMB_VARIANTS"}  # see __getattr__
GRID = 3600  # crank angles per revolution scanned before refining the hardest one
T_END = T_END_STEADY  # s: cap of a run to steady state
T_END_TORQUE = 1.0  # s: length of a constant-torque run (the paper's); it accelerates, so a longer one costs more
DT_OUT = SWEEP_DT_OUT  # s: output interval of the study's runs
TOLERANCE_DEG = 0.1  # width of the bracket the bisection stops at [deg]
Progress = Callable[[str], None]


# --- quasi-static: the torque needed at rest ------------------------------------------------------------------------

def required_torque(params: RobotParams, phi, geometry: str = "exact") -> np.ndarray:
    """Torque at rest [N m] that moves the robot on from crank angle(s) ``phi`` [rad] (module docstring).

    ``params.incline`` sets the slope; the drive in ``params`` does not matter. Shape of ``phi``.
    """
    dyn = OneDofDynamics(params, geometry)
    phi = np.asarray(phi, dtype=float)
    K = dyn.linkage.transfer(phi).K
    free, unit = dyn.static_holds(phi, M=0.0), dyn.static_holds(phi, M=1.0)
    contraction = K < 0  # the gap shrinks: the linkage drives module 1 forward, module 2 is held
    hold = np.where(contraction, free[0], free[1])
    slope = np.where(contraction, unit[0] - free[0], unit[1] - free[1])  # dR_i/dM = -+1/K
    resistance = np.where(contraction, params.F_r1, params.F_r2)
    with np.errstate(divide="ignore", invalid="ignore"):
        needed = -(hold + resistance) / slope
    return np.where(slope != 0, needed, 0.0)  # a dead centre: no torque reaches a module, none is needed


def _hardest(score: Callable[[np.ndarray], np.ndarray]) -> tuple[float, float]:
    """(phi [rad] in [0, 2 pi), value) where ``score`` (vectorized in phi) is smallest over a revolution:
    a scan of GRID angles, then a bounded refinement around the best one (to ~1e-12 rad)."""
    grid = np.linspace(0.0, 2 * math.pi, GRID, endpoint=False)
    values = score(grid)
    k = int(np.nanargmin(values))
    step = grid[1] - grid[0]
    found = minimize_scalar(lambda x: float(score(np.array([x]))[0]), bounds=(grid[k] - step, grid[k] + step),
                            method="bounded", options={"xatol": 1e-12})
    phi, value = (float(found.x), float(found.fun)) if found.fun <= values[k] else (float(grid[k]), float(values[k]))
    return phi % (2 * math.pi), value


def torque_needed(params: RobotParams, geometry: str = "exact", stroke: str | None = None) -> dict:
    """The largest torque at rest [N m] a revolution needs at ``params.incline``, and where.

    {"torque_n_m", "phi_rad", "stroke": "contraction" | "expansion" (which module then moves: 1 | 2)};
    ``stroke`` limits the search to one of them.
    """
    linkage = OneDofDynamics(params, geometry).linkage

    def score(p):
        K = linkage.transfer(p).K
        inside = np.ones(np.shape(p), dtype=bool) if stroke is None else (K < 0) == (stroke == "contraction")
        return np.where(inside, -required_torque(params, p, geometry), np.inf)

    phi, value = _hardest(score)
    K = float(OneDofDynamics(params, geometry).linkage.transfer(phi).K)
    return {"torque_n_m": -value, "phi_rad": phi, "stroke": "contraction" if K < 0 else "expansion"}


def restart_limit(params: RobotParams, geometry: str = "exact") -> dict:
    """The steepest incline at which the drive restarts the robot from rest at every crank angle.

    {"incline_deg": float | None (None: not even a vertical drop moves it on), "sin": s*, "phi_rad"
    (the hardest crank angle), "stroke", "torque_at_rest_n_m": M0, "any_incline": s* >= 1}. With
    s* < 0 the drive needs a downhill slope to restart everywhere.
    """
    M0 = float(drive_torque(params, 0.0))
    flat, vertical = params.replace(incline=0.0), params.replace(incline=90.0)
    A = lambda p: required_torque(flat, p, geometry)  # noqa: E731
    B = lambda p: required_torque(vertical, p, geometry) - A(p)  # noqa: E731

    def allowed(p):
        a, b = A(p), B(p)
        with np.errstate(divide="ignore", invalid="ignore"):
            # where gravity adds nothing (b = 0: a dead centre, or g = 0) only the torque decides
            return np.where(b > 0, (M0 - a) / b, np.where(a <= M0, np.inf, -np.inf))

    phi, s = _hardest(allowed)
    K = float(OneDofDynamics(params, geometry).linkage.transfer(phi).K)
    out = {"sin": s, "phi_rad": phi, "stroke": "contraction" if K < 0 else "expansion",
           "torque_at_rest_n_m": M0, "any_incline": bool(s >= 1.0)}
    out["incline_deg"] = 90.0 if s >= 1.0 else (None if s < -1.0 else math.degrees(math.asin(s)))
    return out


def energy_bound(params: RobotParams) -> dict:
    """{"sin", "incline_deg"}: the steepest incline a steady climb can hold, by energy (module docstring)."""
    mass = params.m1 + params.m2 + params.rod_mass
    M0 = float(drive_torque(params, 0.0))
    s = (math.pi * M0 / params.r - params.F_r1 - params.F_r2) / (mass * params.g) if params.g > 0 else math.inf
    return {"sin": s, "incline_deg": 90.0 if s >= 1.0 else (None if s < -1.0 else math.degrees(math.asin(s)))}


# --- runs -----------------------------------------------------------------------------------------------------------

def default_t_end(params: RobotParams) -> float:
    """[s]: the cap of a run to steady state under the motor, the length of a run under a constant torque."""
    return T_END if params.drive == "motor" else T_END_TORQUE


def run_engine(engine: str, params: RobotParams, t_end: float, dt_out: float = DT_OUT,
               every_step: bool = False) -> RunResult:
    """One run of ``engine`` (a variant name of :mod:`ipir_mujoco.registry`): to the steady state under the
    motor (``t_end`` [s] the cap), else for ``t_end``. ``every_step``: MuJoCo sampled at each of its steps
    (the timestep it chooses for ``dt_out``), so that a mean over a window is its impulse: a sample holds its
    step's force, and read every 1 ms a rigid clutch's one-step engagement peaks alias it) while the run keeps at
    most STUDY_SAMPLES samples (:func:`ipir_mujoco.core.options.study_dt_out`), else every n-th step."""
    every_step = every_step and registry.variant(engine).is_mujoco
    if every_step:
        step = registry.timestep(engine, params, t_end, dt_out)
        if study_dt_out(t_end, step, step) != step:  # a long run: every n-th step, within the cap
            dt_out, every_step = study_dt_out(t_end, step, step), False
    return registry.run(engine, params, t_end, dt_out=dt_out, until_steady=params.drive == "motor",
                        every_step=every_step)


def steady_window(run: RunResult) -> tuple[float, float, bool]:
    """(t0, t1) [s] of the steady window (the revolutions the steady test used), else the whole run; steady?"""
    window = settled_cycles(cycles(run.series), *run.steady_test, run.steady_target)
    if window is None:
        return float(run.series["t"][0]), float(run.series["t"][-1]), False
    return window[0].t_start, window[-1].t_end, True


def locked_pull_share(run: RunResult) -> float | None:
    """Share of the run's time in which a clutch the paper's rule locks would have to pull (reaction < 0)."""
    if run.clutch != "kinematic":
        return None
    from .validate import clutch_pull

    return clutch_pull(run)["fraction_of_time"]


def run_metrics(run: RunResult) -> dict:
    """What the study keeps of one run (SI units; None where a figure does not exist for the run); with finite
    grip also "slip_m", "peak_grip_use" and "steady_slip_m" (:func:`steady_skid`)."""
    s, summary = run.series, run.summary
    t0, t1, steady = steady_window(run)
    inside = (s["t"] >= t0) & (s["t"] <= t1)
    hold = s["lambda1"] + s["lambda2"]
    if run.engine == "mujoco":  # a sample holds the force of the step (the output interval) before it
        after = (s["t"] > t0 + 1e-12) & (s["t"] <= t1 + 1e-12)
        impulse = np.sum(hold[1:][after[1:]] * np.diff(s["t"])[after[1:]])
    else:
        impulse = np.trapezoid(hold[inside], s["t"][inside])
    mean_hold = float(impulse / (t1 - t0)) if steady else None
    moved = travel(s)
    peak = summary["peak_clutch_force_n"]
    if run.engine == "mujoco" and run.settings.get("clutch_model") != "compliant":
        # a rigid MuJoCo clutch is a soft constraint whose engagement overshoot is set by the step, and read
        # every DT_OUT it is whichever step a sample hits: a figure of the numerics, not of the robot, so
        # none is shown (sweep_metrics' docstring says more)
        peak = None
    out = {"revolutions": summary["revolutions"], "travel_m": float(moved[-1] - moved[0]), "t_end_s": run.t_end,
           "steady": steady, "steady_speed_m_s": summary["steady_speed_m_s"], "t_steady_s": summary["t_steady_s"],
           "mean_speed_m_s": mean_speed(s),
           "peak_clutch_force_n": peak, "mean_clutch_force_n": mean_hold,
           "efficiency": summary["efficiency"],
           "pull_share": locked_pull_share(run), "stalled": run.stall is not None, "stall_reason": run.stall,
           "timestep_s": run.settings.get("timestep"), "wall_s": run.wall_time_s}
    if run.params.grip is not None:  # finite grip: how far the modules skidded back [m] (in all, and in the
        # steady window), the peak share of G used
        out.update(slip_m=float((summary.get("slip1_m") or 0.0) + (summary.get("slip2_m") or 0.0)),
                   peak_grip_use=summary.get("peak_grip_use"), steady_slip_m=steady_skid(run))
    if run.stall is not None:  # when and where it stopped, and what the clutches hold there
        moving = np.flatnonzero((run.params.r * np.abs(s["omega"]) > REST_SPEED) | (np.abs(s["v1"]) > REST_SPEED)
                                | (np.abs(s["v2"]) > REST_SPEED))
        out.update({"stall_t_s": float(s["t"][moving[-1] + 1] if moving.size else s["t"][0]),
                    "stall_phi_rad": float(s["phi"][-1]), "lambda1_at_rest_n": float(s["lambda1"][-1]),
                    "lambda2_at_rest_n": float(s["lambda2"][-1])})
    return out


def climbs(metrics: dict, drive: str) -> bool:
    """The motor climbs where it reaches a steady state with a positive speed; a constant torque (which
    has no steady state while it climbs at all) where it has not stalled by the end of its run."""
    if "error" in metrics or metrics["stalled"]:
        return False
    return bool(metrics["steady"] and metrics["steady_speed_m_s"] > 0) if drive == "motor" else True


def measure(engine: str, params: RobotParams, t_end: float | None = None, every_step: bool = False,
            memo: dict | None = None) -> dict:
    """:func:`run_metrics` of one run, or
    {"error": one line} for a run that fails (a runaway the paper's rule cannot follow, MuJoCo's accuracy
    monitor, ...): a result of the study, not its end; {"error", "refused": True} where the engine refuses the
    parameters (MuJoCo's locks with finite grip). ``every_step``: as :func:`run_engine` (the curve's runs,
    whose mean clutch force is shown; the bisection only asks whether a run climbs). ``memo``: a dict that
    keeps each run's figures by (engine, params, t_end, every_step), so that two searches of one study (the
    steady climb and its traction limit) run an incline once."""
    t_end = default_t_end(params) if t_end is None else t_end
    key = (engine, params, t_end, every_step)
    if memo is not None and key in memo:
        return memo[key]
    try:
        run = run_engine(engine, params, t_end, every_step=every_step)
    except ParameterError as exc:
        out = {"error": " ".join(str(exc).split()), "refused": True}
    except SimulationError as exc:
        out = {"error": " ".join(str(exc).split())}
    else:
        out = run_metrics(run)
    if memo is not None:
        memo[key] = out
    return out


def steady_skid(run: RunResult) -> float | None:
    """[m] slip1 + slip2 gained over a run's steady window (its whole run if none), or None where the run has
    no slip columns (an engine without grip: unlimited grip counts as no skid, see :func:`.traction.skids`)."""
    s = run.series
    if "slip1" not in s:
        return None
    t0, t1, _steady = steady_window(run)
    inside = np.flatnonzero((s["t"] >= t0) & (s["t"] <= t1))
    total = s["slip1"] + s["slip2"]
    return float(total[inside[-1]] - total[inside[0]]) if inside.size else 0.0


def steady_climb_limit(params: RobotParams, engine: str, low: float, high: float, tolerance: float = TOLERANCE_DEG,
                       t_end: float | None = None, progress: Progress = lambda _m: None,
                       memo: dict | None = None) -> dict:
    """Bisection on the incline [deg] for the steepest one the motor climbs from rest at phi0 (``engine``).

    ``low`` should climb and ``high`` not; each end is run first. {"incline_deg": the steepest incline
    seen to climb (None if even ``low`` does not), "bracket": [climbs, does not] [deg], "runs": [{incline_deg,
    climbs, note}]}; a bracket of ``high`` twice means it climbs up to ``high``.
    """
    check_real("tolerance", tolerance, high=90.0, unit="deg")
    runs = []

    def verdict(incline: float) -> bool:
        metrics = measure(engine, params.replace(incline=incline), t_end, memo=memo)
        ok = climbs(metrics, params.drive)
        note = metrics.get("error") or metrics.get("stall_reason") or (
            "" if ok else f"no steady state by t={metrics['t_end_s']:.3g} s")
        runs.append({"incline_deg": incline, "climbs": ok, "note": note,
                     "steady_speed_m_s": metrics.get("steady_speed_m_s")})
        progress(f"{engine} at {incline:.4g} deg: {'climbs' if ok else 'does not climb'}")
        return ok

    return bisect_incline(verdict, low, high, tolerance, runs)


def bisect_incline(verdict: Callable[[float], bool], low: float, high: float, tolerance: float, runs: list) -> dict:
    """The steepest incline [deg] in [low, high] where ``verdict(incline)`` holds, by bisection to ``tolerance``
    [deg] (each end tried first): {"incline_deg" (None if not even ``low``), "bracket": [holds, does not],
    "runs": ``runs``, which ``verdict`` fills}; a bracket of ``high`` twice means it holds up to ``high``."""
    if not verdict(low):
        return {"incline_deg": None, "bracket": [None, low], "runs": runs}
    if verdict(high):
        return {"incline_deg": high, "bracket": [high, high], "runs": runs}
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        low, high = (middle, high) if verdict(middle) else (low, middle)
    return {"incline_deg": low, "bracket": [low, high], "runs": runs}


def incline_curve(params: RobotParams, inclines, engines=CLIMB_VARIANTS, t_end: float | None = None,
                  progress: Progress = lambda _m: None) -> list[dict]:
    """Per incline [deg]: the torque a revolution needs at rest there, and each engine's :func:`measure`."""
    rows = []
    for incline in inclines:
        design = params.replace(incline=float(incline))
        row = {"incline_deg": float(incline), "torque_needed_n_m": torque_needed(design)["torque_n_m"],
               "engines": {}}
        for engine in engines:
            row["engines"][engine] = measure(engine, design, t_end, every_step=True)
            m = row["engines"][engine]
            progress(f"{float(incline):g} deg, {engine}: " + (
                m["error"] if "error" in m else "stalled" if m["stalled"] else
                f"{m['steady_speed_m_s']:.4g} m/s" if m["steady"] else f"{m['revolutions']:.3g} rev"))
        rows.append(row)
    return rows


def __getattr__(name: str):
    """The older names of this module's constants: ``ENGINES`` named variants (the registry's ``ENGINES`` names
    the two engines, analytic and mujoco)."""
    if name in OLDER_NAMES:
        return globals()[OLDER_NAMES[name]]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
