"""The climb study: a design's climbing ability with its drive, every limit and its speed against the incline.

The limits and the runs behind them are in :mod:`.climb_limits` (the restart limit, the steady-climb limit,
the energy bound: its docstring has the physics) and, with finite grip, :mod:`.traction` (where the wheels
skid); :func:`climb_study` puts them together. The names of :mod:`.climb_limits` are importable from here too.
"""

from __future__ import annotations

import time

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError, refuse_all_failed
from ipir_mujoco.core.checks import check_numbers
from ipir_mujoco.core.params import RobotParams, check_real, refuse_idle_parameters, require_params

from . import climb_limits
from .climb_limits import (CLIMB_VARIANTS, DT_OUT, GRID, T_END, T_END_TORQUE, TOLERANCE_DEG, Progress, bisect_incline,
                           climbs, default_t_end, energy_bound, incline_curve, locked_pull_share, measure,
                           required_torque, restart_limit, run_engine, run_metrics, steady_climb_limit,
                           steady_skid, steady_window, torque_needed)
from .traction import traction_study

__all__ = ["CLIMB_VARIANTS", "DT_OUT", "GRID", "T_END", "T_END_TORQUE", "TOLERANCE_DEG", "Progress", "bisect_incline",
           "climb_study", "climbs", "default_t_end", "energy_bound", "incline_curve", "locked_pull_share",
           "measure", "required_torque", "restart_limit", "run_engine", "run_metrics", "steady_climb_limit",
           "steady_skid", "steady_window", "torque_needed"]


def climb_study(params: RobotParams, inclines, engines=CLIMB_VARIANTS, tolerance: float = TOLERANCE_DEG,
                t_end: float | None = None, progress: Progress = lambda _m: None) -> dict:
    """The climbing ability of ``params`` with its drive (JSON-ready).

    {"drive", "torque_at_rest_n_m", "restart": :func:`restart_limit` (exact geometry, the rod included),
    "restart_paper_model": the same for the paper's first-order, massless-rod model, "energy_bound",
    "vertical": :func:`torque_needed` at 90 deg, "steady_climb": {engine: :func:`steady_climb_limit`}
    (motor only; empty for a constant torque), "traction": :func:`.traction.traction_study` (finite grip:
    the wheels' limits; unlimited: a note), "rows": :func:`incline_curve`, "engines", "wall_s"}.
    """
    params = require_params(params)
    inclines = check_numbers("inclines", inclines, "a list of inclines [deg], -90..90")
    refuse_idle_parameters(params)  # a parameter no run of the study can use: refused here, not in every run
    if params.drive == "servo":  # its torque at rest depends on the controller's history: no restart limit
        raise ParameterError("drive='servo' in climb: the study's restart limit and steady climb are the constant "
                             "torque's and the motor's (a fixed torque at rest); allowed: --drive torque or motor "
                             "(the servo's climb: simulate --drive servo --set incline=DEG)")
    started = time.perf_counter()
    t_end = default_t_end(params) if t_end is None else t_end
    for engine in engines:
        registry.variant(engine)  # an unknown name is refused before any run
    inclines = [check_real("incline", float(i), low=-90.0, high=90.0, low_open=False, unit="deg") for i in inclines]
    restart = restart_limit(params)
    paper = restart_limit(params.replace(rod_mass=0.0, rod_inertia=0.0), "approx")
    bound = energy_bound(params)
    limits, memo = {}, {}  # memo: the runs of the steady-climb search, read again by the traction search
    if params.drive == "motor":
        low = min(max(restart["incline_deg"] if restart["incline_deg"] is not None else -90.0, 0.0), 90.0)
        if params.grip is not None:  # a finite grip may skid below the restart limit: search from the level
            low = 0.0
        high = 90.0 if bound["incline_deg"] is None or bound["sin"] >= 1 else max(bound["incline_deg"], low)
        for engine in engines:
            limits[engine] = steady_climb_limit(params, engine, low, high, tolerance, t_end, progress, memo)
    traction = traction_study(params, engines, limits, tolerance, t_end, progress, memo)
    rows = incline_curve(params, inclines, engines, t_end, progress)
    refuse_all_failed([m.get("error") for row in rows for m in row["engines"].values()], "runs of the inclines")
    return {"drive": params.drive, "torque_at_rest_n_m": restart["torque_at_rest_n_m"], "restart": restart,
            "restart_paper_model": paper, "energy_bound": bound,
            "vertical": torque_needed(params.replace(incline=90.0)), "steady_climb": limits, "traction": traction,
            "rows": rows, "engines": list(engines), "tolerance_deg": tolerance, "t_end_s": t_end,
            "wall_s": time.perf_counter() - started}


def __getattr__(name: str):
    """Older names (``ENGINES``: :data:`CLIMB_VARIANTS`), as :mod:`.climb_limits` keeps them."""
    return climb_limits.__getattr__(name)
