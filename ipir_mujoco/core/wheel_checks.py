"""The round-pipe robot's rings under the linkage's loads: the closed-form lift-off and scrub checks.

Each module of the wheeled MuJoCo model rides on two rings ``ring_spacing`` = s apart, each of n =
``wheel_legs`` legs evenly spaced about the pipe's axis, leg k pressed outward along u_k by a linear spring with
preload P = F_ni / (2 n) and stiffness k = P / ``suspension_travel``; each leg's wheel rolls only along the pipe,
so across it the wheel holds by friction along its circumferential direction e_k (x cross u_k), up to mu_wall
times its press. A ring loaded across the pipe by F (y across in the crank's plane, z up in a horizontal pipe):

- **while its wheels grip** the ring of a standing module (or on rigid wheels) does not move; rolling
  steer-compliant wheels let it creep onto its springs (:func:`check`). e_1 .. e_n span the plane, so the wheels'
  friction carries F
  as long as it lies inside the zonotope sum_k [-1, 1] mu N_k e_k (N_k each leg's press). Its facets are normal to
  the generators' perpendiculars, the legs' own directions u_j, so the wheels hold F exactly when, for every leg j,
  |F . u_j| <= sum_k mu N_k |e_k . u_j| (:func:`held`). A module that skids along the pipe has its wheels'
  friction all along it (Coulomb's cone: with the share u of its grip used along the pipe, sqrt(1 - u^2) is left
  across), so it holds nothing across while it skids;
- **beyond that grip** the ring slides across the pipe until its springs take the load: it moves by 2 F / (n k)
  (sum_k u_k u_k^T = n / 2 I), which changes leg j's press by (2 / n) F . u_j; leg j lifts where
  F . u_j < -F_ni / 4, whatever n and k. The check gives the springs the whole load there (the sliding wheels'
  friction, which still holds some of it, left out), so it errs towards a lift.

The weight is on the springs from the start (the robot starts at rest sagged on them; its wheels' friction
carries only what is added later): half the sprung weight across the pipe per ring (:func:`~.wheel_legs.sprung_mass`).
The linkage's loads per ring: module 1 feels the crank's bearing force across the pipe at A, split half to each
ring (A is the rings' middle), and the drive's reaction couple -T about z as -+T / s on its aft and fore rings;
module 2 the rod's force at C, half to each ring; each module the rod's force along the pipe's normal where the
rod leaves the crank's plane (``vertical``); and the couples of its wheels' friction at the wall, off its axis
(:func:`pitch_couple` while it grips along the pipe, :func:`stuck_couple` while it rolls on wheels that cannot turn). :func:`ring_loads` builds them from any run's forces (the analytic
run's pin forces, MuJoCo's loop force); :func:`check` applies the two rules to every sample.

A wheel also slides without its ring sliding: one whose friction mu_wall N_k cannot turn its hub against its share
F_ri / (2 n) of the module's rolling resistance stays put while its module rolls, skidding along the pipe (and a
steer-compliant one swivels as it skids, sliding along its axle); and a wheel off its wall goes across the pipe
with its ring, which moved the suspension's whole travel to lift it. :func:`check` predicts a scrub for either.
"""

from __future__ import annotations

import math

import numpy as np

from .wheel_legs import leg_direction, sprung_mass
from .ring_motion import ring_response, rings_motion  # noqa: F401 (rings_motion: the tests' too)

RINGS = ("aft", "fore")
LIFT_SHARE = 0.05  # a leg is off its wall while its spring presses with less than this share of its preload (the
# runs' wheel_off_s counts it so; the check predicts a lift from the same press on)
MOVING_SPEED = 1e-3  # m/s: a module this fast along the pipe, not skidding, rolls (a held one creeps at ~3e-6 m/s)


def leg_frames(n: int) -> tuple[np.ndarray, np.ndarray]:
    """(u, e): each leg's outward direction and its wheel's circumferential direction, (y, z), shapes (n, 2)."""
    u = np.array([leg_direction(k, n)[1:] for k in range(n)])
    return u, np.stack([-u[:, 1], u[:, 0]], axis=1)


def weight_load(params, module: int, gravity=None) -> np.ndarray:
    """The load [N] of its weight on each ring of ``module`` (0 rear, 1 front) across the pipe, (y, z): half its
    sprung mass times ``gravity``, gravity's components across the pipe in the module's frame [m/s^2] ((..., 2):
    per sample along a route, :func:`.wheel_legs.module_gravity`); None: a straight pipe's, (0, -g cos(incline))."""
    if gravity is None:
        gravity = (0.0, -params.g * math.cos(math.radians(params.incline)))
    return 0.5 * sprung_mass(params, module) * np.asarray(gravity, dtype=float)


def leg_presses(params, module: int, spring_load) -> np.ndarray:
    """Each leg's press [N] with its ring's springs carrying ``spring_load`` [N] ((..., 2): y, z), shape (..., n):
    P + (2 / n) F . u_k (negative: the leg would pull, its wheel is off the wall)."""
    n = int(params.wheel_legs)
    u, _ = leg_frames(n)
    preload = (params.F_n1, params.F_n2)[module] / (2 * n)
    return preload + (2.0 / n) * np.asarray(spring_load, dtype=float) @ u.T


def side_holds(params, module: int, gravity=None) -> np.ndarray:
    """What each ring of ``module``'s wheels hold across the pipe by friction along each leg's direction u_j [N],
    shape (n,) (with ``gravity`` per sample, :func:`weight_load`: (..., n)): sum_k mu_wall N_k |e_k . u_j|, N_k
    each leg's press under the weight (module docstring); inf with unlimited grip (a finite model's friction still
    ends somewhere: MuJoCo's is 100 times the press)."""
    n = int(params.wheel_legs)
    u, e = leg_frames(n)
    press = np.maximum(leg_presses(params, module, weight_load(params, module, gravity)), 0.0)
    if params.mu_wall is None:
        return np.full(press.shape, math.inf)
    return params.mu_wall * press @ np.abs(e @ u.T)


def held(params, module: int, load, grip_use=0.0, gravity=None) -> np.ndarray:
    """Whether ``module``'s ring holds the linkage's ``load`` [N] ((..., 2): y, z) by its wheels' friction, shape
    (...): |F . u_j| <= sqrt(1 - u^2) sum_k mu N_k |e_k . u_j| for every leg j, u = ``grip_use`` the share of
    the module's grip used along the pipe (1 while it skids); ``gravity`` as :func:`weight_load` takes it."""
    n = int(params.wheel_legs)
    u, _ = leg_frames(n)
    left = np.sqrt(1.0 - np.clip(np.asarray(grip_use, dtype=float), 0.0, 1.0) ** 2)[..., None]
    across = np.abs(np.asarray(load, dtype=float) @ u.T)
    with np.errstate(invalid="ignore"):  # inf * 0 where an unlimited grip skids (it does not)
        hold = np.nan_to_num(side_holds(params, module, gravity) * left, nan=math.inf)
    return np.all(across <= hold, axis=-1)


def ring_loads(params, side1, side2, torque, vertical1=0.0, vertical2=0.0) -> dict[str, np.ndarray]:
    """The linkage's loads [N] on each ring across the pipe, shape (..., 2) (y, z), keyed '1aft', '1fore',
    '2aft', '2fore': ``side1`` the force across the pipe on module 1 at A (through the crank's bearing), ``side2``
    on module 2 at C (the rod's pin), ``torque`` [N m] the drive's torque on the crank (its reaction, -T about
    z, on module 1's rings as -+T / s), ``vertical1``, ``vertical2`` the forces along z on each module (the rod
    out of the crank's plane). Arrays of one shape (samples) or scalars."""
    s = params.ring_spacing
    side1, side2, torque = (np.asarray(v, dtype=float) for v in (side1, side2, torque))
    shape = np.broadcast(side1, side2, torque, np.asarray(vertical1), np.asarray(vertical2)).shape
    z1 = np.broadcast_to(0.5 * np.asarray(vertical1, dtype=float), shape)
    z2 = np.broadcast_to(0.5 * np.asarray(vertical2, dtype=float), shape)
    couple = torque / s

    def pair(y, z):
        return np.stack(np.broadcast_arrays(y, z), axis=-1)

    return {"1aft": pair(0.5 * side1 + couple, z1), "1fore": pair(0.5 * side1 - couple, z1),
            "2aft": pair(0.5 * side2, z2), "2fore": pair(0.5 * side2, z2)}


def check(params, loads: dict[str, np.ndarray], grip_use=(0.0, 0.0), rolling=(False, False),
          dt: float | None = None, speed=(None, None), gravity=(None, None), press_loss=(None, None),
          slips=None) -> dict:
    """The lift-off and scrub checks on the rings' linkage ``loads`` (:func:`ring_loads`, samples along the first
    axis) with each module's ``grip_use`` share along the pipe and whether it ``rolling`` (arrays of the samples'
    shape, or scalars); ``dt`` [s] the samples' interval (None: each sample static); ``gravity`` per module,
    gravity's components across the pipe in its frame [m/s^2] (samples, 2) (:func:`.wheel_legs.module_gravity`:
    along a route, or a module that rolls about its axis), None: a straight pipe's. The weight across the pipe is
    on the springs at every sample (it changes slowly along a route's bends: a rolling module's rings creep to
    it). ``press_loss`` per module, each leg's press lost to the pipe's shape [N] (samples, n) (a bend's spread,
    :mod:`.route_loads`), None: none; ``slips``, keyed as ``loads``, the side force [N] (samples, 2) of a slip
    angle the pipe gives a ring's rolling steer-compliant wheels (a bend's), which acts through their cornering
    compliance as the heading's does (:func:`.ring_motion.rings_motion`), None: none.

    Per ring and sample: where its wheels hold the load by their sideways friction (:func:`held`) the ring stays
    where it is; where they do not, its springs carry the load, and a module that rolls meanwhile also carries
    its wheels' sideways scrub along it (:func:`_steering_scrub`: a module turned on its springs steers its rolling
    wheels across the pipe, and their friction drags its rings on until they slide). The ring
    follows the springs' load as a mass on springs, the module's sprung mass m on n k of them (translation across
    the pipe, undamped: the legs have no damper, and a load faster than its period sqrt(m / (n k)) moves it less
    than the same load held, a load held as long as it more, up to twice), solved exactly from sample to sample
    with the load held over each (:func:`ring_response`); with ``dt`` None, statically.

    Steer-compliant wheels (:func:`.wheel_legs.rigid_wheels` false) hold a ring across the pipe only while their module
    stands: a rolling wheel's side force is its cornering stiffness times its slip angle, the ring's sideways
    speed over the module's ``speed`` [m/s] along the pipe (per sample, or None: unknown) less the module's
    heading, so within their grip a rolling module's wheels are a damper across the pipe, C_r / |v| per ring (C_r
    = cornering_coefficient P n / 2), and its heading (the rings' shifts' difference over ring_spacing) steers
    both rings the way its nose points: the rings creep until their springs carry the load, the two moved
    together (:func:`.ring_motion.rings_motion`), overdamped at a walk, nearly free at speed (speed None: no
    damping, the larger response); where the wheels' force passes their friction they slide, and only that slide
    counts towards ``slid{i}_m``.

    Returns per module i: ``least_press{i}_n`` [N], its least-pressed leg's press over the samples (the weight on
    the springs and the ring's place; < 0 a lift); ``slid{i}_m`` [m], the path its rings move across the pipe (the
    longer ring's); ``side_use{i}``, its largest load over what its wheels hold across the pipe while they grip along
    it (over the samples and legs, > 1 where they slide; 0 with unlimited grip, inf with mu_wall 0 under a load;
    a module that skids along the pipe holds less across it, Coulomb's cone, and nothing while it skids:
    :func:`held`).
    ``stuck{i}``: a wheel of it that cannot turn while it rolls: its friction mu_wall N_k at the ring's place below
    its share F_ri / (2 n) of the rolling resistance (its hub's friction), so it skids along the pipe under its
    module, and a skidding steer-compliant wheel slides along its axle as it swivels (false with unlimited grip).
    ``lift_predicted``: a least press below LIFT_SHARE of the leg's preload (where the run's ``wheel_off_s``
    counts a wheel off its wall). ``scrub_predicted``: a path of SCRUB_FLOOR or more, a lift (a leg that lifts
    has moved its ring the suspension's whole travel across the pipe, and its wheel, off the wall, goes with it)
    or a stuck wheel (the summary's outcome, ``scrubbed``, is the run's most-slid wheel's path along its axle from
    the same floor)."""
    from .side_check import SCRUB_FLOOR
    from .wheel_legs import rigid_wheels

    n = int(params.wheel_legs)
    u, _ = leg_frames(n)
    compliant = not rigid_wheels(params)
    out: dict = {}
    for i in (1, 2):
        module = i - 1
        preload = (params.F_n1, params.F_n2)[module] / (2 * n)
        stiffness = preload / params.suspension_travel
        frequency = math.sqrt(n * stiffness / sprung_mass(params, module))
        along = gravity[module]
        weight = weight_load(params, module, along)
        use = np.clip(np.asarray(grip_use[module], dtype=float), 0.0, 1.0)
        holds = side_holds(params, module, along).reshape(-1, n)
        least, path, ratio, stuck = math.inf, 0.0, 0.0, False
        # a wheel turns on the wall only while its friction mu_wall N_k can turn its hub against its share of the
        # module's rolling resistance (the hub's frictionloss, F_ri R / (2 n))
        turning = (params.F_r1, params.F_r2)[module] / (2 * n)
        rings = []
        for ring, sign in zip(RINGS, (1.0, -1.0)):
            load = np.asarray(loads[f"{i}{ring}"], dtype=float).reshape(-1, 2)
            samples = load.shape[0]
            ring_use = np.broadcast_to(use, (samples,)) if use.ndim else np.full(samples, float(use))
            rolls = np.broadcast_to(np.asarray(rolling[module], dtype=bool), (samples,))
            load = (load + sign * pitch_couple(params, module, along).reshape(-1, 2) * ring_use[:, None]
                    - sign * stuck_couple(params, module, along).reshape(-1, 2) * rolls[:, None])
            grip = held(params, module, load, ring_use, along)
            creep = grip & rolls if compliant else np.zeros(samples, dtype=bool)
            still = grip & ~creep
            spring = np.where(still[:, None], 0.0, load)
            moving = ~grip & rolls
            if params.mu_wall is not None and moving.any():
                spring = spring + _steering_scrub(params, module, spring, moving)
            rings.append((load, grip, creep, still, spring, rolls))
        steer = params.cornering_coefficient * params.suspension_travel / params.ring_spacing if compliant else 0.0
        if dt is None:  # at rest on the springs; rings that creep together carry the heading's steering too
            both = (rings[0][2] & rings[1][2])[:, None]
            turn = np.where(both, steer * (rings[1][4] - rings[0][4]), 0.0)
            bent = [0.0 if slips is None else np.where(r[2][:, None], slips[f"{i}{ring}"], 0.0)
                    for ring, r in zip(RINGS, rings)]
            moves = [(r[4] + turn + b, ~r[1]) for r, b in zip(rings, bent)]
        elif rings[0][2].any() or rings[1][2].any():
            damping = creep_damping(params, module, speed[module])
            places, slides = rings_motion([r[4] for r in rings], [r[3] for r in rings],
                                          [np.where(r[2], damping, 0.0) for r in rings], frequency, dt, steer,
                                          wheel_walls(params, module, along),
                                          None if slips is None else [slips[f"{i}{ring}"] for ring in RINGS])
            moves = [(place, slid & ~r[3]) for place, slid, r in zip(places, slides, rings)]
        else:
            moves = [(ring_response(r[4], r[1], frequency * dt), ~r[1]) for r in rings]
        for (load, *_, rolls), (place, slides) in zip(rings, moves):
            presses = leg_presses(params, module, place + weight)
            if press_loss[module] is not None:
                presses = presses - press_loss[module]
            least = min(least, float(np.min(presses)))
            if params.mu_wall is not None:  # a rolling module's wheel that cannot turn its hub skids under it
                stuck = stuck or bool(np.any(rolls & (params.mu_wall * np.min(presses, axis=-1) < turning)))
            shifts = np.diff(place, axis=0) * (2.0 / (n * stiffness))
            path = max(path, float(np.sum(np.hypot(shifts[:, 0], shifts[:, 1])[slides[:-1]])))  # creep rolls
            if params.mu_wall is not None:  # against the whole grip: a skidding module's share is in held()
                across = np.abs(load @ u.T)
                with np.errstate(divide="ignore", invalid="ignore"):  # no grip: any load is beyond it (inf)
                    ratio = max(ratio, float(np.max(np.where(holds > 0, across / holds,
                                                             np.where(across > 0, math.inf, 0.0)))))
        out[f"least_press{i}_n"] = least
        out[f"slid{i}_m"] = path
        out[f"side_use{i}"] = ratio
        out[f"stuck{i}"] = stuck
    floor = [LIFT_SHARE * F / (2 * n) for F in (params.F_n1, params.F_n2)]
    out["lift_predicted"] = out["least_press1_n"] < floor[0] or out["least_press2_n"] < floor[1]
    out["scrub_predicted"] = (max(out["slid1_m"], out["slid2_m"]) >= SCRUB_FLOOR or out["lift_predicted"]
                              or out["stuck1"] or out["stuck2"])
    return out


SCRUB_BINS = 720  # directions across the pipe the steering scrub is taken at (0.5 deg apart: to cos 0.25 deg)


def _steering_scrub(params, module: int, spring: np.ndarray, moving: np.ndarray) -> np.ndarray:
    """The wheels' sideways scrub [N] along each sample's spring load (shape (n, 2)) where ``moving`` (the module
    rolls and the ring slides): the ring's whole sideways friction, :func:`.wheel_legs.ring_side_grip`, at the load's
    direction rounded to one of SCRUB_BINS (the law is called once per direction, not per sample); zero elsewhere.
    A ring slides only where its load is beyond what its wheels hold, so every wheel slides: a steer-compliant
    wheel past its slip angle's limit pushes mu_wall P sideways, as a rigid one does."""
    from .wheel_legs import ring_side_grip

    size = np.hypot(spring[:, 0], spring[:, 1])
    where = moving & (size > 0)
    out = np.zeros_like(spring)
    if not where.any():
        return out
    angle = np.arctan2(spring[where, 1], spring[where, 0])
    bins = np.round(angle / (2 * math.pi) * SCRUB_BINS).astype(int) % SCRUB_BINS
    force = np.empty(where.sum())
    for b in np.unique(bins):
        a = 2 * math.pi * b / SCRUB_BINS
        force[bins == b] = ring_side_grip(params, module, (math.cos(a), math.sin(a)))
    out[where] = force[:, None] * spring[where] / size[where, None]
    return out


def wheel_walls(params, module: int, gravity=None) -> tuple:
    """What a ring of ``module``'s wheels hold by friction, for :func:`rings_motion`: (u, e, P, weight, mu_wall),
    the legs' outward and sideways directions (n, 2), their preload [N], the ring's weight across the pipe [N]
    (2,), or per sample with ``gravity`` (:func:`weight_load`: (samples, 2)), and the friction coefficient: wheel
    k presses N_k = P + (2 / n) (X + weight) . u_k (X the springs' load
    of the ring's place, at least 0) and its friction along a way d is mu_wall N_k |e_k . d|."""
    n = int(params.wheel_legs)
    u, e = leg_frames(n)
    return u, e, (params.F_n1, params.F_n2)[module] / (2 * n), weight_load(params, module, gravity), params.mu_wall


def creep_damping(params, module: int, speed) -> np.ndarray | float:
    """The damping rate [1/s] (c / m) of a ring of ``module`` (0 rear, 1 front) across the pipe while its
    steer-compliant wheels roll at ``speed`` [m/s] (an array, or None): C_r / |v| over half the sprung mass, C_r =
    cornering_coefficient P n / 2 (sum_k C (e_k . d)^2 over the ring's wheels, C = cornering_coefficient P; a
    wheel's slip angle is the ring's sideways speed over |v|); 0 with the speed unknown (None)."""
    if speed is None:
        return 0.0
    n = int(params.wheel_legs)
    C_r = params.cornering_coefficient * (params.F_n1, params.F_n2)[module] / (2 * n) * n / 2
    with np.errstate(divide="ignore"):
        return C_r / (0.5 * sprung_mass(params, module) * np.abs(np.asarray(speed, dtype=float)))


def pitch_couple(params, module: int, gravity=None) -> np.ndarray:
    """The load [N] on each ring of ``module`` (0 rear, 1 front), (y, z), +- on its aft and fore rings, of the
    couple its wheels' friction along the pipe makes at the wall while it uses all its grip: each wheel's friction
    mu N_k acts at the wall, D / 2 from the axis along its leg, and the weight across the pipe presses the lower
    legs harder (sum_k N_k u_k = the ring's weight across, W / 2), so the friction's resultant lies off the axis
    by D / 2 times W / F_n of it: a couple mu (D / 2) W about the axis across the pipe and the weight, which the
    two rings carry as +- mu (D / 2) W / s along the weight. Scaled by the share of the grip in use (with the
    friction shared as the presses are: Coulomb's law while it skids, and towards it as the least-pressed wheels
    reach their limit first); zero with unlimited grip (its skid does not happen). ``gravity`` as
    :func:`weight_load` takes it (then shape (..., 2))."""
    weight = weight_load(params, module, gravity)
    if params.mu_wall is None:
        return np.zeros_like(weight)
    return params.mu_wall * 0.5 * params.pipe_diameter * 2.0 * weight / params.ring_spacing


def stuck_couple(params, module: int, gravity=None) -> np.ndarray:
    """The load [N] on each ring of ``module`` (0 rear, 1 front), (y, z), -+ on its aft and fore rings, of the couple
    its stuck wheels make while it rolls: a wheel whose friction mu_wall N_k (N_k its press under the weight, as
    :func:`pitch_couple` takes it) cannot turn its hub against its share F_ri / (2 n) of the rolling resistance
    skids along the pipe, its friction mu_wall N_k against the module's way at the wall, D / 2 from the axis along
    its leg: the rings carry sum_k mu N_k (D / 2) u_k / s over both rings' stuck wheels, as :func:`pitch_couple`
    carries the gripping wheels' (the other way: a rolling module moves forward, a held one is pushed back). A
    heavy module's upper wheels stick first: the couple presses its aft ring towards its lower legs. Zero with
    unlimited grip. ``gravity`` as :func:`weight_load` takes it (then shape (..., 2))."""
    weight = weight_load(params, module, gravity)
    if params.mu_wall is None:
        return np.zeros_like(weight)
    n = int(params.wheel_legs)
    u, _ = leg_frames(n)
    press = np.maximum(leg_presses(params, module, weight), 0.0)
    stuck = params.mu_wall * press < (params.F_r1, params.F_r2)[module] / (2 * n)
    return 2.0 * params.mu_wall * 0.5 * params.pipe_diameter * ((stuck * press) @ u) / params.ring_spacing
