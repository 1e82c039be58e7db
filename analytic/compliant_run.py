"""Running the compliant-clutch model: the event loop, the sampled series and the energy audit.

The equations and the regime decisions are in :mod:`.compliant_model`. Here
each regime is integrated with ``solve_ivp`` until its first event, sampled on
the output grid (with every segment's ends: an instant where the regime
changes appears twice; a damped clutch's force maxima are sampled too, so a
peak force does not depend on the grid), and the next regime is decided. A whole turn of the
crank's running maximum also ends a segment, so every revolution boundary is
a sample and the steady-state test (:class:`ipir_mujoco.core.steady_watch.SteadyWatch`) stops the
run exactly at the end of a revolution.

Series columns (ndarrays of shape (n,)): the shared ``COLUMNS`` (``lambda1``/
``lambda2`` are the clutch forces [N], ``mode`` tells which modules are held,
pushed by their clutch, see :attr:`.Regime.mode`), ``resistance1``/
``resistance2`` (the friction force on each module [N]: -F_ri sign(v_i) while
it slides, the force keeping it at rest while stuck), ``clutch_overlap1``/
``clutch_overlap2`` (d_i [m]: > 0 the clutch is compressed, -backlash..0 inside
its play), the cumulative ``motor_work``, ``friction_work`` (integral of
F_r1 |v1| + F_r2 |v2|) and ``clutch_damper_work`` [J], ``kinetic``,
``potential`` (from t = 0) and ``clutch_spring_energy`` [J], and the
kinetostatic ``rod_force``, ``crank_pin_force``, ``motor_power``. With finite
grip also ``slip1``/``slip2`` [m] (each anchor's backward slide so far),
``skid_work`` [J], ``grip_use1``/``grip_use2`` and ``wheels1``/``wheels2``
(:mod:`.compliant_grip`).
"""

from __future__ import annotations

import math
import time

import numpy as np

from ipir_mujoco.core import energy
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.options import RunOptions
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import REST_TIME, RunResult, stall_reason

from . import accel, compliant_grip, dop853, kernels
from .compliant_model import CompliantModel
from .compliant_state import Clutch, Regime
from .forces import drive_torque
from .kinematics import Geometry
from .kinetostatics import add_kinetostatics
from .roots import brentq
from .solver_support import MAX_REGIME_CHANGES, RunMonitor, check_finite, check_tolerances, sample_times, truncate

# DOP853 by measurement (paper's case, 1 s): 3-5x faster than Radau at k = 1e5..1e7 N/m, also with
# near-critical damping; LSODA's event location let the stick/slip states chatter, so it is not offered
METHODS = ("DOP853", "Radau")
# more zero-length segments in a row than this is chatter, not motion
_MAX_STALLED_SEGMENTS = 50
_BUDGET_CHECK_EVERY = 2000  # right-hand-side calls between wall-clock checks


def simulate_compliant(params: RobotParams, geometry: Geometry | str = Geometry.EXACT, t_end: float = 1.0, *,
                       rtol: float = 1e-10, atol: float = 1e-12, method: str = "DOP853", **run) -> RunResult:
    """Simulate the robot with compliant one-way clutches (``params.clutch_stiffness`` finite).

    ``rtol``/``atol``: the solver's tolerances on the state (phi [rad], omega [rad/s], x1 [m],
    v1 [m/s], three cumulative works [J]); ``method``: its integrator (DOP853 by default: the
    clutch springs' oscillations are undamped or lightly damped, so they must be resolved, which
    an explicit method does cheapest). ``run``: the run options every engine takes
    (:class:`ipir_mujoco.core.options.RunOptions`; ``max_switches`` counts regime changes,
    default :data:`.solver_support.MAX_REGIME_CHANGES`; the wall-time budget is checked between segments and within long
    ones), run by :class:`.solver_support.RunMonitor` as in the other analytic models. Initial
    module velocities from (phi0, omega0): module 1 at rest unless the gap shrinks, as in the
    other engines.
    """
    options = RunOptions.given(t_end, run)
    rtol, atol = check_tolerances(rtol, atol)
    t_end, dt_out = options.t_end, options.dt_out
    if params.clutch_stiffness is None:
        raise ParameterError("clutch_stiffness=rigid: the compliant clutch model needs a finite stiffness; "
                             "allowed: 0 < clutch_stiffness <= 1e12 N/m")
    if method not in METHODS:
        raise ParameterError(f"method={method!r} is unknown; allowed: {', '.join(METHODS)}")
    monitor = RunMonitor(options, params.phi0, MAX_REGIME_CHANGES)
    model = CompliantModel(params, geometry)
    budget = _Budget(monitor)
    grid = np.linspace(0.0, t_end, max(1, math.ceil(t_end / dt_out - 1e-9)) + 1)

    K0 = float(model.linkage.transfer(params.phi0).K)
    v1_0 = max(-K0 * params.omega0, 0.0)
    y = np.array([params.phi0, params.omega0, 0.0, v1_0, 0.0, 0.0, 0.0])
    start = Regime(tuple(int(np.sign(v)) for v in (v1_0, v1_0 + K0 * params.omega0)),
                   (Clutch.TRACKING, Clutch.TRACKING), (0.0, 0.0))
    regime, y = model.decide(0.0, y, start, None)
    t, pieces, switches, short_run, turns, stall = 0.0, [], 0, 0, 0, None
    while True:
        if regime.static:  # both stuck, crank at rest, every load constant: at rest for good
            stall = stall_reason(t, float(y[0]), float(drive_torque(params, 0.0)), model.dyn.a_g != 0)
            # at rest for good: the run goes on REST_TIME at rest and ends, as every engine's does
            pieces.append(_piece(model, regime, sample_times(t, min(t + REST_TIME, t_end), grid),
                                 lambda ts: np.repeat(y[:, None], np.size(ts), axis=1)))
            break
        target = params.phi0 + 2 * math.pi * (turns + 1)
        events = model.events(regime, target, t)
        if method == "DOP853":  # the compiled stepper on the scalar kernels: the same method
            constants = model.constants(regime, events, t)
            sol = dop853.solve(kernels.COMPLIANT, kernels.GUARDED, t, t_end, y, constants, rtol, atol, None,
                               [raw.direction for _, raw, _ in events], max_steps=budget.steps, pause=budget.check)
        else:
            from scipy.integrate import solve_ivp  # Radau only: not on the compiled DOP853's path

            constants = None
            sol = solve_ivp(budget.wrap(model.rhs(regime)), (t, t_end), y, method=method, rtol=rtol, atol=atol,
                            events=[e for e, _, _ in events], dense_output=True)
        if sol.status < 0:
            raise SimulationError(f"integration failed at t={sol.t[-1]:.6g} s: {sol.message}")
        t_stop = float(sol.t[-1])
        missed = _missed_crossing(events, sol, constants)
        if missed is not None:
            t_stop = missed[0]
        times = sample_times(t, t_stop, grid)
        peaks = _force_peaks(model, regime, t, t_stop, sol)
        piece = _piece(model, regime, np.union1d(times, peaks) if peaks.size else times, sol.sol)
        steady_at = monitor.observe(piece)
        pieces.append(piece if steady_at is None else truncate(piece, steady_at))
        if steady_at is not None:
            break
        monitor.report(t_stop)
        monitor.check_budget(t_stop)
        if missed is None and sol.status != 1:
            break
        if missed is None:
            hit = min((k for k in range(len(events)) if sol.t_events[k].size), key=lambda k: sol.t_events[k][0])
            t_event, y_event = float(sol.t_events[hit][0]), np.array(sol.y_events[hit][0])
        else:
            t_event, hit, y_event = missed
        fired = events[hit][2]
        short_run = short_run + 1 if t_event - t <= 1e-12 * (1.0 + t) else 0
        if short_run > _MAX_STALLED_SEGMENTS:
            raise SimulationError(f"the clutch and friction states chatter at t={t:.6g} s (phi={y[0]:.6g} rad)")
        t = t_event
        if fired[0] == "revolution":  # only a sample: the regime goes on
            turns += 1
            y = y_event
            y[0] = max(y[0], target)  # on the boundary, so the steady test sees the whole turn
        else:
            regime, y = model.decide(t, y_event, regime, fired)
            switches += 1
            monitor.after_switch(t, switches, float(y[0]))
        if t >= t_end:
            break

    series = {c: np.concatenate([piece[c] for piece in pieces]) for c in pieces[0]}
    if params.grip is not None:  # each anchor's slide and the grip's work against it
        series.update(compliant_grip.run_columns(series, params.grip))
    monitor.report(float(series["t"][-1]), final=True)
    add_kinetostatics(series, model.dyn)
    del series["motor_torque"]  # folded into motor_power
    check_finite(series)
    return RunResult(engine="analytic", geometry=model.dyn.geometry.value, clutch="unilateral", params=params,
                     t_end=float(series["t"][-1]), series=series, energy=energy_audit(series),
                     wall_time_s=time.perf_counter() - monitor.started, stall=stall,
                     settings={"method": method, "rtol": rtol, "atol": atol, "dt_out": dt_out,
                               "rod_modelled": model.dyn.include_rod, "clutch_model": "compliant",
                               **monitor.settings, "switches": switches})


def energy_audit(series: dict[str, np.ndarray]) -> dict[str, float]:
    """Motor work = kinetic + potential energy gained + friction work + clutch spring energy gained
    + clutch damper work (+ skid work, with finite grip) + residual [J], from a run's cumulative columns
    (:func:`ipir_mujoco.core.energy.audit`: every term of the table the series has)."""
    return energy.audit(series)


class _Budget:
    """The run's wall-time budget (:meth:`.solver_support.RunMonitor.check_budget`) inside a long segment too:
    every few thousand right-hand-side calls (Radau), or a pause of the compiled stepper every
    ``steps`` steps (None: no budget, no pauses)."""

    def __init__(self, monitor: RunMonitor):
        self.check = monitor.check_budget
        # the compiled stepper pauses for a check after as many steps (15 right-hand sides each)
        self.steps = None if monitor.wall_budget_s is None else _BUDGET_CHECK_EVERY // 15

    def wrap(self, rhs):
        if self.steps is None:
            return rhs
        calls = [0]

        def f(t, y):
            calls[0] += 1
            if calls[0] % _BUDGET_CHECK_EVERY == 0:
                self.check(t)
            return rhs(t, y)
        return f


# interior points checked per accepted step for an event function that crossed and came back
_GRAZE_POINTS = 8


def _missed_crossing(events: list, sol, constants=None):
    """An event crossing that solve_ivp missed: (t, event index, state) of the first, or None.

    solve_ivp sees an event only where its function has changed sign between step ends; a clutch
    overlap or a module speed that crosses and comes back within one step (a module that passes its
    anchor and turns, inside one long step) slips through. Each step is sampled at interior points
    through the dense output; where a function went clearly past its threshold (by more than 1e-9 of
    its size over the segment), its first crossing is located with brentq.
    """
    ends = sol.t
    if ends.size < 2:
        return None
    fractions = np.arange(1, _GRAZE_POINTS + 1) / (_GRAZE_POINTS + 1)
    times = (ends[:-1, None] + np.diff(ends)[:, None] * fractions).ravel()
    states = sol.sol(times)
    if constants is not None and accel.ACCELERATED:  # every raw value in one compiled call
        values = np.empty((len(events), times.size))
        kernels.guard_table(kernels.COMPLIANT, kernels.RAW, len(events), constants, times,
                            np.ascontiguousarray(states.T), values)
    else:
        values = np.array([np.broadcast_to(raw(times, states), times.shape) for _, raw, _ in events], dtype=float)
    direction = np.array([raw.direction for _, raw, _ in events])[:, None]
    scale = np.maximum(np.abs(values).max(axis=1, keepdims=True), 1e-300)
    past = direction * values > 1e-9 * scale
    if not past.any():
        return None
    k, j = min(zip(*np.nonzero(past)), key=lambda kj: times[kj[1]])
    guarded = events[k][0]
    step = j // _GRAZE_POINTS
    points = [ends[step], *times[step * _GRAZE_POINTS: j + 1]]  # the step's start up to the first clear crossing
    signs = [direction[k, 0] * guarded(time, sol.sol(time)) for time in points]
    if signs[0] > 0 or max(signs) <= 0:  # past at a step end already, or only at the segment's start (where
        return None  # the functions report the safe side): solve_ivp's own event handling covers it
    first = next(i for i, value in enumerate(signs) if value > 0)
    t_root = brentq(lambda time: guarded(time, sol.sol(time)), points[first - 1], points[first], xtol=1e-15,
                    rtol=4 * np.finfo(float).eps)
    return t_root, k, sol.sol(t_root)


_PEAK_POINTS = 4  # points per solver step at which a damped clutch's force is scanned for its maxima


def _force_peaks(model: CompliantModel, regime: Regime, t0: float, t1: float, sol) -> np.ndarray:
    """Times [s] inside (t0, t1) where an engaged, damped clutch's force k d - c v has a local maximum.

    Without damping the force peaks where its module turns (d' = -v = 0): a segment end, so a sample.
    With damping it peaks between samples, where the output grid alone reads it low by up to
    (omega_c dt_out)^2 / 8 (measured: 1.2e-3 at 1e7 N/m, 300 N s/m, dt_out 1e-4 s). Scanned at the
    solver's step ends and points between, each local maximum is located with a bounded Brent search on
    the dense output (to sqrt(eps) of the time: a relative force error of (omega_c 1.5e-8 t)^2, 2.2e-9
    at 1e7 N/m over 1 s, growing as t^2).
    """
    engaged = [i for i in (0, 1) if regime.clutch[i] is Clutch.ENGAGED]
    if model.c == 0 or not engaged or not t1 > t0:
        return np.zeros(0)
    ends = np.concatenate([[t0], sol.t[(sol.t > t0) & (sol.t < t1)], [t1]])
    fractions = np.arange(_PEAK_POINTS) / _PEAK_POINTS
    times = np.append((ends[:-1, None] + np.diff(ends)[:, None] * fractions).ravel(), t1)
    force = model.motion(sol.sol(times), regime).force
    from scipy.optimize import minimize_scalar  # damped clutches only

    found = []
    for i in engaged:
        f = np.concatenate([[-np.inf], np.asarray(force[i], dtype=float), [-np.inf]])  # an end may hold the max
        for j in np.flatnonzero((f[1:-1] > f[:-2]) & (f[1:-1] >= f[2:])):
            low, high = times[max(j - 1, 0)], times[min(j + 1, times.size - 1)]
            best = minimize_scalar(lambda s, i=i: -float(model.motion(sol.sol(s), regime).force[i]),
                                   bounds=(low, high), method="bounded", options={"xatol": 1e-15})
            found.append(float(best.x))
    return np.array(found)


def _piece(model: CompliantModel, regime: Regime, times, dense) -> dict[str, np.ndarray]:
    """The series columns of one segment at ``times`` (n,) from its dense output."""
    p, dyn = model.params, model.dyn
    y = dense(times)
    phi, omega, x1, v1 = y[0], y[1], y[2], y[3]
    m = model.motion(y, regime)
    mt = m.mass
    shape = phi.shape

    def full(value):
        return np.broadcast_to(np.asarray(value, dtype=float), shape).astype(float)

    spring = sum(0.5 * model.k * np.maximum(d, 0.0) ** 2 for d in m.overlap)
    # from the start: x1 = x2 = 0 at phi0
    potential = dyn.potential_energy(phi, x1, m.x2) - dyn.potential_energy(p.phi0, 0.0, 0.0)
    columns = {
        "t": times, "phi": phi, "omega": omega, "alpha": full(m.alpha), "x1": x1, "x2": full(m.x2),
        "v1": v1, "v2": full(m.v2), "a1": full(m.a1), "a2": full(m.a2),
        "S": full(mt.transfer.S), "S_dot": full(mt.transfer.K * omega),
        # an engaged clutch's k d - c v is >= 0 by its regime; at the event that clips it, it is 0 to within
        # the event's location error, which must not show as a pull
        "lambda1": np.maximum(full(m.force[0]), 0.0), "lambda2": np.maximum(full(m.force[1]), 0.0),
        "mode": np.full(shape, int(regime.mode)),
        "resistance1": full(m.friction[0]), "resistance2": full(m.friction[1]),
        "clutch_overlap1": full(m.overlap[0]), "clutch_overlap2": full(m.overlap[1]),
        "motor_work": y[4], "friction_work": y[5], "clutch_damper_work": y[6],
        "kinetic": full(dyn.kinetic_energy(phi, v1, omega)),
        "potential": full(potential), "clutch_spring_energy": full(spring),
        "motor_torque": full(m.torque),
    }
    compliant_grip.piece_columns(model, regime, times, columns)  # sliding anchors; grip use and wheel states
    return columns
