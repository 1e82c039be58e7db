"""The round-pipe robot's design rules: closed forms a designer checks before running anything (``design-check``).

Each rule is a figure of the design against its limit: ``{"name", "value", "limit", "margin", "unit", "holds",
"why"}`` (margin: how far the value is inside its limit, in its unit; ``limit`` and ``margin`` None where the rule
has none, e.g. unlimited grip). docs/model.md ("The round pipe: design rules") derives each. The rules:

- ``stall_push_1``, ``stall_push_2``: the rod's least push on a held module at the drive's torque at rest M0 (M,
  or M_stall), M0 / max |K| (K = dS/dphi, about r: the crank's quarter turn; more towards the dead centres),
  on top of the module's weight down the pipe, against its grip mu_wall F_ni: beyond it the module skids back at
  every crank angle, and a skidding module's wheels hold nothing across the pipe.
- ``restart``: the largest torque at rest a revolution needs (:func:`..climb.climb_limits.torque_needed`), against M0.
- ``weight_press_1``, ``weight_press_2``: the weight across the pipe its springs carry against the weight that
  lifts its least-pressed leg (n P / max_k u_k . up: F_ni with 3 legs, leg 0 down).
- ``lift_at_stall``: the least-pressed leg's press with the drive at M0 (:func:`ipir_mujoco.core.wheel_checks.check`
  on the statics of every crank angle: the rod's side force M0 / S on each module, the motor's couple on module
  1's rings, the weight, the held module's grip use; the wheels' sideways friction where they grip).
- ``side_grip_at_stall``: the largest ring load across the pipe over what its wheels hold there (> 1: the rings
  slide across the pipe, the wheels scrub).
- ``lift_at_speed`` (the motor and the servo): the same check with the crank at up to its no-load speed: the
  motor's torque M_stall (1 - omega / omega_noload) as its couple and the rod's side force (T - J_A alpha) / S,
  alpha the crank's own as it trades speed with the moving module's inertia at that speed (the effective
  inertia J_A + m K^2 at constant kinetic energy), the moving module rolling (its wheels' scrub where its rings
  slide). A constant torque has no top speed: its run's summary checks its own loads.
- ``tightest_bend``: the tightest bend (R / D) the geometry passes: the wheels' spread off the ring's plane
  (:func:`.pipe.bend_wheel_spread`) within their springs' reach (2 ``suspension_travel``), the housing
  (:func:`.pipe.bend_max_length`) and the rod (:func:`.pipe.bend_rod_clearance`); against the route's
  tightest bend with ``--route``.
- ``bend_scrub``: the least-pressed leg's press rolling through a bend with the wheels' scrub
  (:func:`.pipe.bend_lift_check`, whose :func:`.pipe.scrub_force` is the wheels' side-force law): each bend of
  ``--route``, or without one a bend turning across the crank's plane and one turning up at the tightest radius
  the geometry passes.
- ``climb_energy``: a steady climb's work per revolution, 2 r (F_r1 + F_r2 + m g sin(incline)), against the
  drive's 2 pi M0.
"""

from __future__ import annotations

import math

import numpy as np

from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.forces import drive_torque
from ipir_mujoco.core import pipe, wheel_checks
from ipir_mujoco.core.params import RobotParams

ANGLES = 360  # crank angles per revolution the stall and speed rules scan
SPEEDS = 9  # crank speeds from rest to the motor's no-load speed the speed rule scans
BEND_LIMIT = 100.0  # R / D: the widest bend the tightest-bend search considers (a straight beyond it)


def rule(name: str, value: float | None, limit: float | None, unit: str, why: str,
         higher_is_worse: bool = True) -> dict:
    """One rule's record: margin = limit - value (or value - limit where a larger value is better), holds where
    the margin is >= 0 (or where there is no limit); a value None (no such figure: no bend passes) does not
    hold."""
    if value is None:
        return {"name": name, "value": None, "limit": limit, "margin": None, "unit": unit, "holds": False, "why": why}
    margin = None if limit is None else (limit - value if higher_is_worse else value - limit)
    return {"name": name, "value": float(value), "limit": None if limit is None else float(limit),
            "margin": None if margin is None else float(margin), "unit": unit,
            "holds": True if margin is None else bool(margin >= 0), "why": why}


def stall_torque(params: RobotParams) -> float:
    """M0 [N m]: the drive's torque at rest (M, or the motor's M_stall), its magnitude."""
    return abs(float(drive_torque(params, 0.0)))


def linkage_samples(params: RobotParams) -> dict:
    """Over a revolution (ANGLES crank angles): phi, the gap S and K = dS/dphi, shape (ANGLES,)."""
    phi = np.linspace(0.0, 2 * math.pi, ANGLES, endpoint=False)
    transfer = OneDofDynamics(params, "exact").linkage.transfer(phi)
    return {"phi": phi, "S": np.asarray(transfer.S, dtype=float), "K": np.asarray(transfer.K, dtype=float)}


def stall_pushes(params: RobotParams) -> tuple[float, float]:
    """Each module's least hold [N] while it is the held one at the drive's torque at rest: the rod's push
    M0 / max |K| and the module's weight down the pipe (``stall_push_i``)."""
    link = linkage_samples(params)
    push = stall_torque(params) / float(np.max(np.abs(link["K"])))
    down = params.g * math.sin(math.radians(params.incline))
    return push + params.m1 * down, push + params.m2 * down


def stall_check(params: RobotParams, torque: float, alpha=0.0, moving_rolls: bool = False) -> dict:
    """:func:`.wheel_checks.check` on the statics of every crank angle with the drive's ``torque`` [N m] (scalar)
    and the crank's angular acceleration ``alpha`` [rad/s^2] (per angle, or a scalar): the rod's side force
    (T - J_A alpha) / S on module 2, its opposite on module 1, the motor's couple T on module 1's rings; the held
    module (module 2 while the gap shrinks, K < 0; module 1 while it grows) uses its push over its grip, the other
    rolls where ``moving_rolls``."""
    link = linkage_samples(params)
    side = (torque - params.J_A * np.asarray(alpha, dtype=float)) / link["S"]
    loads = wheel_checks.ring_loads(params, -side, side, np.full(ANGLES, torque))
    pushes = np.abs(torque - params.J_A * np.asarray(alpha, dtype=float)) / np.maximum(np.abs(link["K"]), 1e-12)
    down = params.g * math.sin(math.radians(params.incline))
    front_held = link["K"] < 0
    grips = params.grip
    use = [np.zeros(ANGLES), np.zeros(ANGLES)]
    if grips is not None:
        use[0] = np.where(front_held, 0.0, np.minimum(1.0, (pushes + params.m1 * down) / grips[0]))
        use[1] = np.where(front_held, np.minimum(1.0, (pushes + params.m2 * down) / grips[1]), 0.0)
    rolling = (front_held & moving_rolls, ~front_held & moving_rolls)
    return wheel_checks.check(params, loads, tuple(use), rolling)


def speed_check(params: RobotParams) -> dict:
    """The worst of :func:`stall_check` over crank speeds from rest to omega_noload (``lift_at_speed``)."""
    link = linkage_samples(params)
    worst = None
    for omega in np.linspace(0.0, params.omega_noload, SPEEDS):
        torque = params.M_stall * (1.0 - omega / params.omega_noload)
        # the crank coasting at kinetic energy J omega^2 / 2, J = J_A + m K^2 the moving module's: alpha =
        # -omega^2 J' / (2 J), J' = 2 m K K'
        out = None
        for m in (params.m1, params.m2):
            J = params.J_A + m * link["K"] ** 2
            dK = np.gradient(link["K"], link["phi"])
            alpha = -omega ** 2 * m * link["K"] * dK / J
            result = stall_check(params, torque, alpha, moving_rolls=True)
            if out is None or min(result["least_press1_n"], result["least_press2_n"]) < min(
                    out["least_press1_n"], out["least_press2_n"]):
                out = result
        if worst is None or min(out["least_press1_n"], out["least_press2_n"]) < min(
                worst["least_press1_n"], worst["least_press2_n"]):
            worst = out
    return worst


def tightest_bend(params: RobotParams) -> float:
    """The smallest centreline radius [m] of a bend the geometry passes (``tightest_bend``): bisection on R
    between D / 2 and BEND_LIMIT D of: the wheels' spread within 2 suspension_travel, the housing's rigid length
    within the bend, the rod clear of the inner wall."""
    D = params.pipe_diameter
    housing = 2 * (0.5 * D - 2 * params.wheel_radius)

    def passes(R: float) -> bool:
        spread = pipe.bend_wheel_spread(0.5 * params.ring_spacing, params.wheel_radius, R, D)
        return (spread <= 2 * params.suspension_travel and pipe.bend_max_length(housing, R, D) >= params.ring_spacing
                and pipe.bend_rod_clearance(params.L, 0.004, R, D) > 0)

    low, high = 0.5 * D * (1 + 1e-9), BEND_LIMIT * D
    if not passes(high):
        return math.inf
    for _ in range(60):
        mid = 0.5 * (low + high)
        low, high = (low, mid) if passes(mid) else (mid, high)
    return high


def design_rules(params: RobotParams, route=None) -> dict:
    """Every rule of the module docstring for ``params`` (and each bend of ``route``, a
    :class:`ipir_mujoco.core.route.Route`): ``{"rules": [...], "holds": all of them}``."""
    M0, grips = stall_torque(params), params.grip
    rules = []
    for i, push in enumerate(stall_pushes(params), start=1):
        rules.append(rule(f"stall_push_{i}", push, None if grips is None else grips[i - 1], "N",
                          f"the rod pushes held module {i} back with at least M0 / max|K| = {M0:.3g} N m / "
                          f"{float(np.max(np.abs(linkage_samples(params)['K']))):.3g} m at the drive's torque at rest, "
                          "its weight down the pipe on top; beyond its grip mu_wall F_n it skids back at every crank "
                          "angle, and a skidding module's wheels hold nothing across the pipe"))
    from ..climb.climb_limits import torque_needed

    needed = torque_needed(params)
    rules.append(rule("restart", needed["torque_n_m"], M0, "N m",
                      f"the largest torque at rest a revolution needs (crank at {math.degrees(needed['phi_rad']):.0f} "
                      f"deg, the {needed['stroke']}), against the drive's {M0:.3g} N m: beyond it a robot stopped "
                      "there does not start again"))
    n = int(params.wheel_legs)
    u, _ = wheel_checks.leg_frames(n)
    for i in (1, 2):
        weight = -2.0 * float(wheel_checks.weight_load(params, i - 1)[1])
        up = float(np.max(u[:, 1])) if weight >= 0 else float(np.max(-u[:, 1]))
        lifts = (params.F_n1, params.F_n2)[i - 1] / (2 * up) if up > 0 else None
        rules.append(rule(f"weight_press_{i}", abs(weight), lifts, "N",
                          f"module {i}'s weight across the pipe on its springs against the weight that lifts its "
                          f"least-pressed leg, n P / max(u_k . up) (P = F_n{i} / 2n): above it a leg lifts at rest"))
    stall = stall_check(params, M0)
    least = min(stall["least_press1_n"], stall["least_press2_n"])
    rules.append(rule("lift_at_stall", least, 0.0, "N",
                      "the least-pressed leg with the drive at its torque at rest, over every crank angle: the rod's "
                      "side force M0 / S, the motor's couple +-M0 / ring_spacing on module 1's rings, the weight; "
                      "the wheels' sideways friction holds where the module grips (the held one uses its push over "
                      "its grip); below 0 a leg lifts", higher_is_worse=False))
    use = max(stall["side_use1"], stall["side_use2"])
    rules.append(rule("side_grip_at_stall", use, None if grips is None else 1.0, "-",
                      "the largest ring load across the pipe at the drive's torque at rest over what the ring's wheels "
                      "hold across it by friction (mu_wall times each leg's press); above 1 the rings slide across "
                      "the pipe and the wheels scrub (a loss the equations' rails lack)"))
    if params.drive in ("motor", "servo"):
        fast = speed_check(params)
        rules.append(rule("lift_at_speed", min(fast["least_press1_n"], fast["least_press2_n"]), 0.0, "N",
                          f"the least-pressed leg with the crank at up to its no-load {params.omega_noload:.3g} rad/s: "
                          "the motor's torque as its couple, the rod's side force (T - J_A alpha) / S with the "
                          "crank's alpha as it trades speed with the moving module's inertia, the moving module "
                          "rolling (its wheels' scrub where its rings slide)", higher_is_worse=False))
    radius = tightest_bend(params)
    D = params.pipe_diameter
    bends = [] if route is None else list(route.bends)
    tightest_route = min((b.radius for b in bends), default=None)
    passed = radius / D if math.isfinite(radius) else None
    rules.append(rule("tightest_bend", passed, None if tightest_route is None else tightest_route / D, "R/D",
                      f"the tightest bend the geometry passes: the wheels' spread off the ring's plane within their "
                      f"springs' reach 2 x {params.suspension_travel:.3g} m (about ring_spacing^2 D / (8 R^2) for "
                      f"ring_spacing {params.ring_spacing:.3g} m), the housing and the rod"
                      + ("" if tightest_route is None else "; against the route's tightest bend"),
                      higher_is_worse=True))
    rules.append(bend_scrub_rule(params, route, radius))
    mass = params.m1 + params.m2 + params.rod_mass
    work = 2 * params.r * (params.F_r1 + params.F_r2 + mass * params.g * math.sin(math.radians(params.incline)))
    rules.append(rule("climb_energy", work, 2 * math.pi * M0, "J",
                      "a steady revolution's work, each module a stroke 2 r against its resistance and the robot's "
                      "weight down the pipe, against the most the drive gives in a revolution, 2 pi M0"))
    return {"rules": rules, "holds": all(r["holds"] for r in rules)}


def bend_scrub_rule(params: RobotParams, route, radius: float) -> dict:
    """``bend_scrub``: the least-pressed leg rolling through a bend with the wheels' scrub
    (:func:`.pipe.bend_lift_check`: the straight pipe's loads at the drive's torque at rest and, on each ring,
    the wheels' side force :func:`.pipe.scrub_force`, the place the side-force law of the wheels plugs in)."""
    if route is not None and route.bends:
        from ipir_mujoco.engine.builders.route_walls import bend_loads

        least, where = math.inf, ""
        for k, bend in enumerate(route.bends, start=1):
            check = pipe.bend_lift_check(params, bend.radius, *bend_loads(route, bend, params.g))
            value = min(check["least_press1_n"], check["least_press2_n"])
            if value < least:
                least, where = value, f"bend {k} (R/D {bend.radius / params.pipe_diameter:.3g})"
        return rule("bend_scrub", least, 0.0, "N", f"the least-pressed leg rolling through the route's bends, worst "
                    f"in {where}: the straight pipe's loads and the wheels' sideways scrub as the module turns; below "
                    "0 a leg lifts", higher_is_worse=False)
    if not math.isfinite(radius):
        return rule("bend_scrub", None, 0.0, "N", "no bend passes the geometry", higher_is_worse=False)
    across = [(0.0, -params.g * math.cos(math.radians(params.incline)))]
    least = min(min(c["least_press1_n"], c["least_press2_n"]) for c in
                (pipe.bend_lift_check(params, radius, toward, across) for toward in ((1.0, 0.0), (0.0, 1.0))))
    return rule("bend_scrub", least, 0.0, "N", "the least-pressed leg rolling through a bend at the tightest radius the "
                "geometry passes, turning across the crank's plane or up: the straight pipe's loads and the wheels' "
                "sideways scrub as the module turns (whatever the radius); below 0 a leg lifts", higher_is_worse=False)
