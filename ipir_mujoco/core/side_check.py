"""The wheeled model's closed-form sideways-grip check and MuJoCo's scrub outcome beside it.

:func:`side_grip_check` puts a run's linkage forces on each module's rings against what their wheels hold across
the pipe (:func:`.wheel_legs.ring_side_grip`); :func:`across_paths` measures how far MuJoCo's wheels slid across
it; :func:`side_summary` gives both as a wheeled run's summary keys.
"""

from __future__ import annotations

import numpy as np

from .wheel_legs import ring_side_grip, rod_side_force


def side_grip_check(params, side1, side2, torque, grip_use=(0.0, 0.0)) -> dict:
    """The closed-form sideways-grip check of the wheeled model's modules, on a run's linkage forces.

    The analytic model holds each module on rails: whatever the linkage pushes across the pipe, the rails carry
    without moving. The wheeled model's rings carry it by their wheels' sideways friction
    (:func:`ring_side_grip`, along y: the crank's plane, where the linkage's forces lie); a ring loaded beyond it
    slides across the pipe until its legs' springs take the rest (the wheels scrub: energy lost, and a sliding
    wheel's friction points along its slip, so less of it holds the module along the pipe). The ring loads: half
    the linkage's force across the pipe on the module (``side1`` at A, through the crank's bearing; ``side2`` at
    C, the rod's pin: :func:`ipir_mujoco.analytic.kinetostatics.pin_forces`, its inertia forces included) and on
    module 1 the drive's reaction couple ``torque`` about z as +-torque / ring_spacing on its two rings (as in
    :func:`.pipe.lift_check`). A module that holds along the pipe with the share u of its grip (``grip_use``, the
    analytic run's grip_use1/2: 1 while it skids) leaves each wheel sqrt(1 - u^2) of its friction across the
    pipe (Coulomb's cone, every wheel using the same share), so a skidding module slides across under any side
    load. The arrays [N], [N m], [-] are a run's samples, shape (n,). The check leaves out the springs' part (they
    carry a side load only as the ring moves), so it errs on the side of predicting a slide.

    Returns {'side_use1', 'side_use2': each module's largest ring load over what its ring's wheels hold across
    the pipe (> 1: they slide across it; inf: a load while its wheels skid; 0 with unlimited grip),
    'scrub_predicted': bool}.
    """
    out = {}
    for i, (side, couple) in enumerate(((side1, torque), (side2, 0.0)), start=1):
        load = 0.5 * np.abs(np.asarray(side, dtype=float)) + np.abs(np.asarray(couple, dtype=float)) / params.ring_spacing
        use = np.clip(np.asarray(grip_use[i - 1], dtype=float), 0.0, 1.0)
        hold = ring_side_grip(params, i - 1, (1.0, 0.0)) * np.sqrt(1.0 - use * use)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(load > 0, load / hold, 0.0)
        out[f"side_use{i}"] = 0.0 if params.mu_wall is None else float(np.max(ratio))
    out["scrub_predicted"] = out["side_use1"] > 1 or out["side_use2"] > 1
    return out


# a ring whose wheels all grip cannot move across the pipe (their circumferential directions span its plane): only
# the contacts' softness moves it. In the wheeled model's agreement benchmark (mjcf/README.md, "The round pipe
# against the analytic finite-grip model"), designs whose sideways-grip check on the analytic run's forces stayed
# below 1 with no wheel off moved their rings at most 0.12 mm in 1-2 s, those above it 17.1 mm and more: 1 mm lies a
# factor 8 above the one and 17 below the other
SCRUB_FLOOR = 1e-3  # m


def across_paths(series: dict, params) -> tuple[float, float]:
    """How far [m] each module's wheels slid across the pipe over a wheeled run: its most-slid wheel's sideways
    slide, the series' ``slid1``, ``slid2`` where the run has them (the engine's, from MuJoCo's kinematics: a
    steer-compliant wheel rolls its ring across the pipe without sliding); else from its pose columns (``y``,
    ``z``, ``roll``, ``pitch``, ``yaw`` and 1 or 2; small turns), as rigid wheels slide: the longer of its two
    rings' paths in (y, z) (ring centres ``ring_spacing`` / 2 fore and aft of the module's point) plus its
    wheels' path round the pipe from its roll (D / 2 |d roll|), sample to sample. (module 1's, module 2's)."""
    if "slid1" in series and "slid2" in series:
        return float(series["slid1"][-1]), float(series["slid2"][-1])
    a, out = 0.5 * params.ring_spacing, []
    for k in (1, 2):
        y, z, roll, pitch, yaw = (np.asarray(series[f"{c}{k}"], dtype=float) for c in ("y", "z", "roll", "pitch", "yaw"))
        rings = [np.hypot(np.diff(y + side * a * yaw), np.diff(z - side * a * pitch)) for side in (-1.0, 1.0)]
        out.append(float(np.sum(np.maximum(*rings) + 0.5 * params.pipe_diameter * np.abs(np.diff(roll)))))
    return out[0], out[1]


def side_summary(params, series: dict) -> dict:
    """The sideways-grip keys of a wheeled run's summary: the closed-form check beside MuJoCo's outcome.

    - ``side_use1``, ``side_use2``: :func:`side_grip_check` on the drive's loads, quasi-static as
      :func:`.pipe.lift_check` takes them (the rod's largest side force :func:`rod_side_force` at the drive's largest
      torque, M or M_stall, on both modules; the motor's reaction couple on module 1), with the modules holding
      along the pipe (no skid): each module's largest ring load across the pipe over what its ring's wheels hold
      across it. Above 1 the rings slide across the pipe; a module that skids along the pipe holds nothing across
      it whatever this says (its wheels' friction is all along the pipe), nor does a lifted wheel.
    - ``scrub_predicted``: either above 1.
    - ``across1_m``, ``across2_m`` [m]: how far MuJoCo's wheels slid across the pipe (:func:`across_paths`); a
      slide from SCRUB_FLOOR on.
    - ``scrubbed``: either at least SCRUB_FLOOR: the wheels slid across the pipe, a loss the equations' rails lack.
    """
    torque = abs(params.M) if params.drive == "torque" else params.M_stall
    side = rod_side_force(torque, params.r, params.L)
    check = side_grip_check(params, [side], [side], [torque])
    across = across_paths(series, params)
    return {"side_use1": check["side_use1"], "side_use2": check["side_use2"],
            "scrub_predicted": check["scrub_predicted"], "across1_m": across[0], "across2_m": across[1],
            "scrubbed": max(across) >= SCRUB_FLOOR}
