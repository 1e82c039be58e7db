"""Traction: the steepest pipe a design's wheels hold on, and the press a vertical riser needs.

With finite grip (``mu_wall``; G_i = mu_wall F_ni) a held module skids back once the ground force its
clutch must give exceeds G_i (docs/model.md, "Finite grip": a standing module needs
-F_ri <= g_i <= G_i on its whole ground force g_i). Three figures, beside the restart limit and the
energy bound of :mod:`.climbing`:

* **Rest traction limit** (statics, any drive): the steepest incline at which neither module of a
  robot standing at any crank angle skids. The holds a standing robot's modules need
  (:meth:`~ipir_mujoco.analytic.dynamics.OneDofDynamics.static_holds`, exact geometry with the rod) are
  affine in s = sin(incline): R_i = A_i(phi) + s B_i(phi), B_i >= 0, R_1 + R_2 = m g s (m the robot's
  mass). *Drive off* (M = 0): A_i = 0 and each module holds its own weight share, B_2 = (m2 + the rod's
  share at phi) g, so sin(limit) = min_i G_i / (m_i,eff g) with m_i,eff the largest share over phi.
  *Drive at rest* (M0, the constant M or the motor's M_stall): the linkage also pushes one module
  back and the other forward; where the forward push exceeds that module's resistance (R_j < -F_rj)
  it rolls, its ground force is -F_rj, and the held module's demand is capped at m g s + F_rj
  (quasi-static: the crank's acceleration at the start of motion, the one-way model's P alpha term,
  is left to the run-based limit below). The demand min(R_i, m g s + F_rj) rises with s, so module i
  holds up to s_i(phi) = max((G_i - A_i) / B_i, (G_i - F_rj) / (m g)). A push above F_ri forward
  only rolls the module (a restart, not a skid), so only the upper limit G_i bounds the incline.
* **Steady traction limit** (the motor, per engine): the steepest incline at which the run from rest
  reaches its steady state with no skid in the steady window (slip1 + slip2 grows by no more than
  SLIP_TOL there; ``peak_grip_use`` < 1 where an engine has no slip columns); bisection as the
  steady-climb limit, below that limit.
* **Riser press**: the F_ni (per module, at the given mu_wall) at which a standing robot in a vertical
  pipe holds at every crank angle: max over phi of the demand above at s = 1, over mu_wall; drive off
  and at rest, the larger binds.

With unlimited grip (the default) none of these exists: :func:`traction_study` then says so and
runs nothing.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.forces import drive_torque
from ipir_mujoco.core.params import RobotParams

from . import climb_limits as climbing  # the limits and runs (climbing.py puts the study together)

UNLIMITED = "unlimited grip: no traction limit"
SLIP_TOL = 1e-9  # m: growth of slip1 + slip2 over the steady window still counted as none (roundoff of a sum)
DRIVES = ("drive_off", "drive_at_rest")
Progress = Callable[[str], None]


def _mass(params: RobotParams) -> float:
    return params.m1 + params.m2 + params.rod_mass


def _holds(params: RobotParams, phi, M: float, geometry: str = "exact") -> tuple[np.ndarray, np.ndarray]:
    """(A, B), each shape (2, len(phi)) [N]: the static holds R_i = A_i + s B_i of a robot standing at crank
    angle(s) ``phi`` [rad] with torque ``M`` [N m] at the crank (module docstring)."""
    flat = OneDofDynamics(params.replace(incline=0.0), geometry).static_holds(phi, M=M)
    vertical = OneDofDynamics(params.replace(incline=90.0), geometry).static_holds(phi, M=M)
    A = np.array(flat)
    return A, np.array(vertical) - A


def demand(params: RobotParams, phi, s: float, M: float, geometry: str = "exact") -> np.ndarray:
    """Shape (2, len(phi)) [N]: the ground force each module of a standing robot must hold, + forward, at
    s = sin(incline), torque ``M`` at rest; a module pushed forward beyond its resistance rolls and caps
    the other's at m g s + F_rj (module docstring)."""
    A, B = _holds(params, np.atleast_1d(np.asarray(phi, dtype=float)), M, geometry)
    R = A + s * B
    cap = _mass(params) * params.g * s + np.array([[params.F_r2], [params.F_r1]])
    return np.minimum(R, cap)


def _allowed(params: RobotParams, M: float, module: int, geometry: str = "exact") -> Callable:
    """s_i(phi), vectorized: the largest sin(incline) at which module ``module`` (0 or 1) holds at phi."""
    G = params.grip[module]
    other_resistance = (params.F_r2, params.F_r1)[module]
    weight = _mass(params) * params.g

    def score(phi):
        A, B = _holds(params, phi, M, geometry)
        a, b = A[module], B[module]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            held = np.where(b > 0, (G - a) / b, np.where(a <= G, np.inf, -np.inf))
            capped = (G - other_resistance) / weight if weight > 0 else (np.inf if G >= other_resistance else -np.inf)
        return held if M == 0.0 else np.maximum(held, capped)

    return score


def _incline(s: float) -> float:
    return 90.0 if s >= 1.0 else -90.0 if s <= -1.0 else math.degrees(math.asin(s))


def rest_limit(params: RobotParams, geometry: str = "exact") -> dict:
    """The rest traction limit, drive off and at rest (module docstring); needs a finite grip.

    {"drive_off": {...}, "drive_at_rest": {...}, "binds": the key of the lower, "torque_at_rest_n_m"}, each
    {"sin", "incline_deg" (90: holds at any incline), "module": 1 | 2 (which skids first), "phi_rad" (where),
    "any_incline"}.
    """
    M0 = float(drive_torque(params, 0.0))
    out = {"torque_at_rest_n_m": M0}
    for key, M in zip(DRIVES, (0.0, M0)):
        best = None
        for module in (0, 1):
            phi, s = climbing._hardest(_allowed(params, M, module, geometry))
            if best is None or s < best["sin"]:
                best = {"sin": s, "module": module + 1, "phi_rad": phi}
        best.update(incline_deg=_incline(best["sin"]), any_incline=bool(best["sin"] >= 1.0))
        out[key] = best
    out["binds"] = "drive_at_rest" if out["drive_at_rest"]["sin"] < out["drive_off"]["sin"] else "drive_off"
    return out


def riser_press(params: RobotParams, geometry: str = "exact") -> dict:
    """The wall press [N] per module at which a standing robot holds in a vertical pipe at every crank angle.

    {"hold_n": {drive: [module 1, module 2]} (the largest ground force each needs over phi), "press_n": the
    same over mu_wall, "phi_rad": where, "binds": the drive key whose press is larger (per module, the larger
    of the two is the answer: "needed_n")}.
    """
    M0 = float(drive_torque(params, 0.0))
    out = {"hold_n": {}, "press_n": {}, "phi_rad": {}}
    for key, M in zip(DRIVES, (0.0, M0)):
        holds, where = [], []
        for module in (0, 1):
            phi, value = climbing._hardest(lambda p, i=module, m=M: -demand(params, p, 1.0, m, geometry)[i])
            holds.append(-value)
            where.append(phi)
        out["hold_n"][key] = holds
        # mu_wall = 0 (no grip at all): no press holds a module that needs a ground force; null in the JSON
        out["press_n"][key] = [h / params.mu_wall if params.mu_wall > 0 else (math.inf if h > 0 else 0.0)
                               for h in holds]
        out["phi_rad"][key] = where
    out["needed_n"] = [max(out["press_n"][k][i] for k in DRIVES) for i in (0, 1)]
    out["binds"] = "drive_at_rest" if sum(out["press_n"]["drive_at_rest"]) > sum(out["press_n"]["drive_off"]) \
        else "drive_off"
    for key in DRIVES:  # no press holds it (mu_wall = 0): None, JSON's null
        out["press_n"][key] = [None if math.isinf(f) else f for f in out["press_n"][key]]
    out["needed_n"] = [None if math.isinf(f) else f for f in out["needed_n"]]
    return out


def skids(metrics: dict) -> bool:
    """Whether a run skids in its steady window (slip columns), else whether its grip use reached 1."""
    if metrics.get("steady_slip_m") is not None:
        return metrics["steady_slip_m"] > SLIP_TOL
    return metrics.get("peak_grip_use") is not None and metrics["peak_grip_use"] >= 1.0


def steady_limit(params: RobotParams, engine: str, high: float, tolerance: float = climbing.TOLERANCE_DEG,
                 t_end: float | None = None, progress: Progress = lambda _m: None, memo: dict | None = None) -> dict:
    """Bisection on the incline [deg] in [0, ``high``] for the steepest one the motor climbs to a steady state
    from rest with no skid in the steady window. {"incline_deg" (None: not even on the level), "bracket",
    "runs"}, or {"error": one line} where the engine refuses the design (MuJoCo without finite grip). ``memo``:
    as :func:`.climbing.measure` (runs the steady-climb search made are read, not run again)."""
    runs = []

    def verdict(incline: float) -> bool:
        m = climbing.measure(engine, params.replace(incline=incline), t_end, memo=memo)
        if m.get("refused"):
            raise _Refused(m["error"])
        ok = climbing.climbs(m, params.drive) and not skids(m)
        runs.append({"incline_deg": incline, "holds": ok, "steady_slip_m": m.get("steady_slip_m"),
                     "climbs": climbing.climbs(m, params.drive), "note": m.get("error", "")})
        progress(f"{engine} at {incline:.4g} deg: " + ("climbs, no skid" if ok else "skids or stalls"))
        return ok

    try:
        return climbing.bisect_incline(verdict, 0.0, high, tolerance, runs)
    except _Refused as exc:
        return {"error": str(exc), "runs": runs}


class _Refused(Exception):
    """An engine refused a run of the bisection (the message is the engine's one line)."""


def traction_study(params: RobotParams, engines=climbing.CLIMB_VARIANTS, steady_climb: dict | None = None,
                   tolerance: float = climbing.TOLERANCE_DEG, t_end: float | None = None,
                   progress: Progress = lambda _m: None, memo: dict | None = None) -> dict:
    """The traction figures of ``params`` (JSON-ready): {"grip": None, "note": UNLIMITED} with unlimited grip,
    else {"grip": [G1, G2], "mu_wall", "F_n": [F_n1, F_n2], "rest": :func:`rest_limit`, "riser":
    :func:`riser_press`, "steady": {engine: :func:`steady_limit`} (motor only; ``steady_climb``, the
    study's steady-climb limits, caps each engine's bracket; ``memo``: the runs already made,
    :func:`.climbing.measure`)}."""
    if params.grip is None:
        return {"grip": None, "note": UNLIMITED}
    out = {"grip": list(params.grip), "mu_wall": params.mu_wall, "F_n": [params.F_n1, params.F_n2],
           "rest": rest_limit(params), "riser": riser_press(params), "steady": {}}
    if params.drive == "motor":
        for engine in engines:
            cap = (steady_climb or {}).get(engine, {}).get("incline_deg")
            out["steady"][engine] = steady_limit(params, engine, 90.0 if cap is None else max(cap, 0.0),
                                                 tolerance, t_end, progress, memo)
    return out
