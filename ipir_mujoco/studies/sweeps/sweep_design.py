"""One design of a sweep, where the work runs: every engine of a design in a pool's worker, or a chunk of designs
through the batched MuJoCo engine in a process of its own.

:func:`run_design` (with its wall-time alarm) and :func:`run_batch_chunk` are the tasks :mod:`.sweep` hands its
pools (``optimize`` and ``sensitivity`` run :func:`run_design` too, :mod:`ipir_mujoco.studies.design.design_eval`);
each returns the metrics of :mod:`.sweep_metrics`, or the error that a design's row records.
"""

from __future__ import annotations

import signal
import threading

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams

from .sweep_metrics import batch_metrics, run_metrics


class DesignTimeout(Exception):
    """A design ran past the sweep's wall-time budget (raised by the worker's alarm)."""


def run_engine(engine: str, params: RobotParams, t_end: float, dt_out: float, options: dict):
    """One engine (a variant name of :mod:`ipir_mujoco.registry`) on one design; ``options``: until_steady,
    wall_budget_s (passed to the analytic engines; the pool's alarm covers MuJoCo's runs), every_step
    (MuJoCo sampled at every step)."""
    v = registry.variant(engine)
    return registry.run(v, params, t_end, dt_out=dt_out, until_steady=bool(options.get("until_steady")),
                        wall_budget_s=None if v.is_mujoco else options.get("wall_budget_s") or None,
                        every_step=bool(options.get("every_step")) and v.is_mujoco)


def engine_metrics(engine: str, params: RobotParams, t_end: float, dt_out: float, options: dict) -> dict:
    """Metrics of one engine on one design, or {"error": message}; a stall adds {"note": reason}."""
    try:
        run = run_engine(engine, params, t_end, dt_out, options)
    except (ParameterError, SimulationError) as exc:
        return {"error": f"{engine}: {exc}"}
    except DesignTimeout:
        raise
    except Exception as exc:  # noqa: BLE001 (one design's surprise must not end the sweep)
        return {"error": f"{engine}: internal error: {type(exc).__name__}: {exc}"}
    metrics = run_metrics(run)
    if run.stall:
        metrics["note"] = f"stalled: {run.stall}"
    bars = run.summary.get("figure_errors")
    if bars:  # MuJoCo's figures on finite grip: their rigid limit's error bars (figure_errors), said in the notes
        said = "rigid limit: " + ", ".join(f"{k} +-{e:.3g}" for k, e in bars.items())
        metrics["note"] = f"{metrics['note']}; {said}" if metrics.get("note") else said
    return metrics


def run_design(values: dict, base: RobotParams, engines: tuple[str, ...], t_end: float, dt_out: float = 1e-3,
               options: dict | None = None, alarm: bool = False) -> dict[str, dict]:
    """Every engine of ``engines`` on the design ``base`` with ``values``: {engine: metrics}.

    ``alarm``: enforce ``options['wall_budget_s']`` with SIGALRM (pool workers only: the main
    thread of a process of our own).
    """
    options = options or {}
    registry.prepare_for_many(engines)
    try:
        params = base.replace(**values)
    except ValueError as exc:
        return {engine: {"error": f"invalid design: {exc}"} for engine in engines}
    budget = options.get("wall_budget_s")
    results: dict[str, dict] = {}
    armed = bool(alarm and budget and hasattr(signal, "setitimer")
                 and threading.current_thread() is threading.main_thread())
    if armed:
        signal.signal(signal.SIGALRM, _raise_timeout)
    try:
        if armed:  # inside the try: a tiny budget may fire before the first engine starts
            signal.setitimer(signal.ITIMER_REAL, budget)
        for engine in engines:
            results[engine] = engine_metrics(engine, params, t_end, dt_out, options)
    except DesignTimeout:
        for engine in engines:
            if engine not in results:
                results[engine] = {"error": f"{engine}: exceeded --timeout-per-design {budget:g} s of wall time"}
    finally:
        if armed:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, signal.SIG_IGN)  # an alarm already on its way must not land later
    return results


def _raise_timeout(signum, frame):
    raise DesignTimeout()



def run_batch_chunk(values: list[dict], base: RobotParams, t_end: float, dt_out: float, nthread: int,
                    until_steady: bool = False, engine: str = "mujoco-ratchet") -> list[dict]:
    """The batched ``engine`` (:func:`ipir_mujoco.registry.batched`) on one chunk of designs: [{engine:
    metrics or {"error": ...}}] in their order.

    Runs in a process of its own (the batch pool), so that Ctrl-C can end it at once and its per-step
    Python work does not compete with the main process.
    """
    params: list[RobotParams | None] = []
    serial: dict[int, dict] = {}
    # what the batch does not model (registry.batch_models: a drive it does not declare, compliant clutches)
    # runs here one by one in the serial engine, never as a silently different robot
    for k, design in enumerate(values):
        try:
            params.append(base.replace(**design))
        except ValueError:
            params.append(None)
            continue
        p = params[-1]
        if not registry.batch_models(p):
            serial[k] = engine_metrics(engine, p, t_end, dt_out, {"until_steady": until_steady})
            params[-1] = None
    valid = [p for p in params if p is not None]
    try:
        outcomes = iter(registry.run_batch(engine, valid, t_end, dt_out, nthread=nthread, until_steady=until_steady)
                        if valid else [])
    except Exception as exc:  # noqa: BLE001 (recorded per design; the analytic side goes on)
        outcomes = iter([{"error": f"batch failed: {type(exc).__name__}: {exc}"}] * len(valid))
    results = []
    for k, p in enumerate(params):
        if p is None:
            results.append({engine: serial.get(k, {"error": "invalid design"})})
            continue
        outcome = next(outcomes)
        results.append({engine: {"error": f"{engine}: {outcome['error']}"} if "error" in outcome
                        else _batch_design_metrics(outcome)})
    return results


def _batch_design_metrics(outcome: dict) -> dict:
    metrics = batch_metrics(outcome)
    if outcome.get("stall"):
        metrics["note"] = f"stalled: {outcome['stall']}"
    return metrics
