"""Whether the robot fits its pipe: the cross-field checks of ``pipe_diameter`` and ``wheel_radius``.

Kept beside :mod:`.params` (which defines the fields) because only the wheeled MuJoCo model has a pipe: the
slide model and the analytic equations never read these fields, so a design that would not fit a pipe is
still a valid slide design, and the checks run where a pipe is built (:func:`check_fit`).

A straight pipe of inside diameter D holds the planar mechanism when

- the crank pin's circle fits: the crank turns about A on the pipe's axis, its pin B sweeps |y| <= r, so
  2 r < D;
- each wheel fits between the axis and its wall: the wheel's centre sits at D / 2 - R from the axis, on an
  arm from the module's centreline, so 2 R < D / 2 (R < D / 4).

The rod length L does not enter a straight pipe's fit (the rod swings inside the crank pin's band, |y| <= r).
A bend's fit has three closed forms here, all reported beside MuJoCo's outcome of a route (``route_fit``): a
rigid box's (:func:`bend_max_length`), the spread sprung wheels need (:func:`bend_wheel_spread`) and the rod's
clearance from the inner wall (:func:`bend_rod_clearance`).
"""

from __future__ import annotations

import math

import numpy as np

from .errors import ParameterError


def check_fit(params) -> None:
    """ParameterError (one line) if the robot ``params`` (a RobotParams) does not fit its pipe (module docstring)."""
    D, R, r = params.pipe_diameter, params.wheel_radius, params.r
    if not 2 * r < D:
        raise ParameterError(f"pipe_diameter={D:g} m with r={r:g} m: the crank pin's circle does not fit the pipe; "
                             f"allowed: pipe_diameter > 2 r = {2 * r:g} m")
    if not 4 * R < D:
        raise ParameterError(f"wheel_radius={R:g} m with pipe_diameter={D:g} m: a wheel does not fit between the axis "
                             f"and its wall; allowed: wheel_radius < pipe_diameter / 4 = {D / 4:g} m")


def bend_max_length(width: float, radius: float, diameter: float) -> float:
    """The longest rigid module [m] of width ``width`` [m] (across the pipe) that passes a bend of centreline
    radius ``radius`` [m] in a pipe of inside diameter ``diameter`` [m]; 0.0 if none does (width >= D).

    Closed form, a rectangle in the annulus between the bend's inner wall (radius R - D/2) and outer wall
    (R + D/2): at its tightest the rectangle's inner side lies on the inner wall's tangent and its outer corners
    on the outer wall, so its half-length l/2 and the outer corners' distance from the bend's centre satisfy
    (R - D/2 + w)^2 + (l/2)^2 = (R + D/2)^2:

        l_max = 2 sqrt((R + D/2)^2 - (R - D/2 + w)^2)

    (for a straight pipe, R -> infinity, any length passes). A run along a route reports it for the wheeled
    model's rigid housing beside MuJoCo's outcome (``route_fit``); the housing is far from binding there, the
    wheels' springs bind first (:func:`bend_wheel_spread`).
    """
    if not (width >= 0 and radius > 0 and diameter > 0):
        raise ParameterError(f"bend fit: width={width!r} m, radius={radius!r} m, diameter={diameter!r} m; allowed: "
                             "width >= 0, radius > 0, diameter > 0")
    if radius < diameter / 2:
        raise ParameterError(f"bend radius={radius:g} m with pipe_diameter={diameter:g} m: the centreline radius "
                             f"must reach the pipe's half-width; allowed: radius >= {diameter / 2:g} m")
    if width >= diameter:
        return 0.0
    outer, inner = radius + diameter / 2, radius - diameter / 2 + width
    return 2.0 * (outer * outer - inner * inner) ** 0.5


def bend_wheel_spread(half_base: float, wheel_radius: float, radius: float, diameter: float) -> float:
    """How much farther apart [m] the two wheels of a station must reach in a bend than in a straight pipe: a
    module tangent to the bend's centreline (radius ``radius`` [m], pipe diameter ``diameter`` [m]) with its
    stations ``half_base`` [m] either side of its middle and wheels of radius ``wheel_radius`` [m] on both walls.

    Closed form: the wheels' centres lie on the circles R + D/2 - R_w (outer wall) and R - D/2 + R_w (inner
    wall), on the station's line across the module, a distance b = half_base from the tangent point along the
    module, so

        spread = sqrt((R + D/2 - R_w)^2 - b^2) - sqrt((R - D/2 + R_w)^2 - b^2) - (D - 2 R_w)

    about b^2 D / (2 (R - D/2) (R + D/2)) for b << R - D/2: the pipe, measured across the module off its
    middle, is wider than D. Sprung wheels keep their wall while their springs reach that far."""
    if not (half_base >= 0 and wheel_radius > 0 and diameter > 4 * wheel_radius and radius > diameter / 2):
        raise ParameterError(f"bend wheel spread: half_base={half_base!r} m, wheel_radius={wheel_radius!r} m, "
                             f"radius={radius!r} m, diameter={diameter!r} m; allowed: half_base >= 0, "
                             "0 < 4 wheel_radius < diameter < 2 radius")
    outer, inner = radius + diameter / 2 - wheel_radius, radius - diameter / 2 + wheel_radius
    if half_base >= inner:
        return math.inf
    return (outer * outer - half_base * half_base) ** 0.5 - (inner * inner - half_base * half_base) ** 0.5 \
        - (diameter - 2 * wheel_radius)


def bend_rod_clearance(length: float, rod_radius: float, radius: float, diameter: float) -> float:
    """How far [m] a rod of ``length`` [m] and radius ``rod_radius`` [m], as a chord with both ends on a bend's
    centreline (radius ``radius`` [m], pipe diameter ``diameter`` [m]), clears the bend's inner wall; negative where
    it would cross it:

        clearance = sqrt(R^2 - (L/2)^2) - (R - D/2) - rod_radius

    (the chord's middle is nearest the bend's centre). The linkage's two ends ride near the pipe's axis, so a
    negative clearance says the rod must push them outward or bind."""
    if not (length > 0 and rod_radius >= 0 and radius > diameter / 2 and diameter > 0):
        raise ParameterError(f"bend rod clearance: length={length!r} m, rod_radius={rod_radius!r} m, radius={radius!r}"
                             f" m, diameter={diameter!r} m; allowed: length > 0, rod_radius >= 0, radius > diameter / 2")
    if length / 2 >= radius:
        return -math.inf
    return (radius * radius - length * length / 4) ** 0.5 - (radius - diameter / 2) - rod_radius


# ----------------------------------------------------------------------------------------------------
# The round pipe's wheel legs (the wheeled MuJoCo model), the closed-form lift-off and sideways-grip checks

# Each leg's masses, shares of its module's mass m_i (inside m_i): its arm (the slider and axle the spring presses
# out) and its wheel. The wheel is light: a rolling module carries its wheels' spin, J / R^2 = m_w / 2 each, the
# one mass term the analytic model lacks. The arm is ten times heavier: at 1e-3 the scrubbing wheels of a bend were
# resolved only below 3e-6 s (a R/D 5 bend's revolutions fell 0.4-0.6 % a halving from 2.5e-5 s); at 1e-2 they
# converge from 5e-5 s, a bend's step (mjcf/README.md, "The round pipe: convergence"). Both ride with their module
# along the pipe, so a straight pipe's travel does not change with them (the cruise's to 5 digits).
ARM_SHARE = 1e-2
WHEEL_SHARE = 1e-3


def sprung_mass(params, module: int) -> float:
    """The mass [kg] of module ``module`` (0 rear, 1 front) that its legs' springs carry: m_i less its 2 n legs'
    arms and wheels, whose weight goes to the wall through their own wheels."""
    m = (params.m1, params.m2)[module]
    return m * (1.0 - 2 * int(params.wheel_legs) * (ARM_SHARE + WHEEL_SHARE))


def leg_direction(k: int, n: int) -> tuple[float, float, float]:
    """Leg ``k``'s outward unit vector of ``n`` evenly spaced about the pipe's axis x, leg 0 pointing down (-z in
    a horizontal pipe): (0, cos a, sin a) with a = -90 deg + 360 deg k / n."""
    angle = -0.5 * math.pi + 2.0 * math.pi * k / n
    return (0.0, math.cos(angle), math.sin(angle))


def rod_side_force(torque: float, r: float, L: float) -> float:
    """The largest force [N] across the pipe that a crank torque ``torque`` [N m] puts through the rod on its
    ends (A on module 1, C on module 2), quasi-static, over a turn: the rod (r crank, L rod [m]) carries
    F = T / (r |sin(phi - beta)|) along itself, sin beta = -r sin(phi) / L, and its side part F |sin beta| grows
    from T / (L + r) at the outer dead centre (phi = 0) to T / (L - r) at the inner one (phi = 180 deg)."""
    return abs(torque) / (L - r)


def lift_check(params) -> dict:
    """The closed-form lift-off check of the wheeled model's legs (docs/model.md, "The round pipe").

    Each module has two rings ``ring_spacing`` = s apart of n = ``wheel_legs`` legs, each pressed on the wall by
    a linear spring with preload P_i = F_ni / (2 n). A force F across the pipe on a ring moves it by 2 F / (n k)
    (its legs' outward directions u_k: sum u_k u_k^T = n/2 I), which changes leg k's press by (2 / n) F . u_k:
    leg k lifts where F . u_k < -F_ni / 4, whatever n and k. The loads per ring, quasi-static: half the
    weight its springs carry across the pipe, :func:`sprung_mass` g cos(incline) / 2, down (each leg's own arm
    and wheel bear on the wall through its wheel); half the rod's side force at the ring pair's
    middle (:func:`rod_side_force`, the drive's largest torque: M, or M_stall for the motor); on module 1 the
    motor's reaction couple T about z as +-T / s on its two rings. The side loads are taken both ways. The
    wheels' sideways friction can carry side loads while they grip (MuJoCo's wheels do), so the check errs on
    the side of predicting a lift.

    Returns {'least_press1_n', 'least_press2_n': each module's least-pressed leg's closed-form press [N] (< 0: it
    lifts), 'lift_predicted': bool, 'weight_press_n': (module 1's, module 2's) least press under weight alone}.
    """
    n = int(params.wheel_legs)
    torque = abs(params.M) if params.drive == "torque" else params.M_stall
    side = rod_side_force(torque, params.r, params.L)
    across = math.cos(math.radians(params.incline)) * params.g
    legs = [leg_direction(k, n) for k in range(n)]
    out, weight_only = {}, []
    for i, Fn in enumerate((params.F_n1, params.F_n2), start=1):
        m = sprung_mass(params, i - 1)
        P = Fn / (2 * n)
        down = 0.5 * m * across
        couple = torque / params.ring_spacing if i == 1 else 0.0
        least = math.inf
        for lateral in (0.5 * side + couple, -(0.5 * side + couple), 0.5 * side - couple, couple - 0.5 * side):
            for (_, uy, uz) in legs:
                least = min(least, P + (2.0 / n) * (lateral * uy - down * uz))
        out[f"least_press{i}_n"] = least
        weight_only.append(min(P + (2.0 / n) * (-down * uz) for (_, _, uz) in legs))
    out["lift_predicted"] = out["least_press1_n"] < 0 or out["least_press2_n"] < 0
    out["weight_press_n"] = tuple(weight_only)
    return out


def hub_tangent(u: tuple[float, float, float]) -> tuple[float, float]:
    """(y, z) of the wall's circumferential direction x cross u at a leg of outward direction ``u``: the way its
    wheel slides across the pipe (it rolls only along x)."""
    return (-u[2], u[1])


def ring_side_grip(params, module: int, toward: tuple[float, float]) -> float:
    """The sideways friction [N] each ring of module ``module`` (0 rear, 1 front) gives along the unit (y, z)
    ``toward`` across the pipe before its wheels slide: each wheel rolls only along the pipe, so it carries a load
    across it by friction along its circumferential direction e_k, up to mu_wall P (its spring takes the radial
    part, and only as it deflects), and a ring gives mu_wall P sum_k |e_k . toward| (at the defaults' 3 legs
    2 mu_wall P across a horizontal pipe, 1.73 mu_wall P up or down). Coulomb, the legs at their preload P."""
    n = int(params.wheel_legs)
    P = (params.F_n1, params.F_n2)[module] / (2 * n)
    # unlimited grip: no finite coefficient to take; 1 stands for it, a lower bound (the model's wheels then grip
    # with MU_UNLIMITED, 100, and turn in a bend only as far as their springs let them: a lift whatever this says)
    mu = params.mu_wall if params.mu_wall is not None else 1.0
    return mu * P * sum(abs(e[0] * toward[0] + e[1] * toward[1])
                        for e in (hub_tangent(leg_direction(k, n)) for k in range(n)))


def rigid_wheels(params) -> bool:
    """Whether the wheeled model's wheels are fixed on their axles: ``cornering_coefficient`` rigid, or unlimited
    grip (a steer-compliant wheel held against any load along the pipe would turn off its axis: the wheeled
    model then builds rigid ones, :func:`ipir_mujoco.engine.kinds.wheels.model.steer_compliant`)."""
    return params.cornering_coefficient is None or params.mu_wall is None


def bend_slip_angle(params, radius: float) -> float:
    """Each ring's slip angle [rad] in a bend of centreline radius ``radius`` [m]: a module whose rings, b =
    ``ring_spacing`` / 2 either side of its middle, both ride on the centreline is a chord of it, and turning
    through the bend each ring moves along the centreline's tangent there, asin(b / R) off the module's axis (the
    fore ring's towards the bend's inside, the aft ring's out)."""
    return math.asin(min(1.0, 0.5 * params.ring_spacing / radius))


def ring_side_force(params, module: int, toward: tuple[float, float], slip: float) -> float:
    """The side force [N] along the unit (y, z) ``toward`` across the pipe that a ring of module ``module`` (0 rear,
    1 front) carries when it rolls at the slip angle ``slip`` [rad] towards ``toward`` (its velocity that far off
    the module's axis). Wheel k, its sideways direction e_k (:func:`hub_tangent`), slips at alpha_k = slip
    (e_k . toward) and pushes along e_k with

        F_k = min(C |alpha_k|, mu_wall P),   C = cornering_coefficient P   (P the leg's preload)

    (docs/model.md, "The wheels' side force"), so the ring carries sum_k F_k |e_k . toward|: C slip n / 2 while no
    wheel slides (n = wheel_legs evenly spaced: sum_k (e_k . toward)^2 = n / 2), :func:`ring_side_grip` when
    all do. Rigid wheels (``cornering_coefficient`` rigid, fixed on their axles; the wheeled model's wheels with
    unlimited grip too) carry :func:`ring_side_grip` at any slip angle but zero (unlimited grip counted as
    mu_wall 1, as there)."""
    if slip == 0.0:
        return 0.0
    if rigid_wheels(params):
        return math.copysign(ring_side_grip(params, module, toward), slip)
    n = int(params.wheel_legs)
    P = (params.F_n1, params.F_n2)[module] / (2 * n)
    mu = params.mu_wall
    C = params.cornering_coefficient * P
    total = 0.0
    for e in (hub_tangent(leg_direction(k, n)) for k in range(n)):
        share = abs(e[0] * toward[0] + e[1] * toward[1])
        total += min(C * abs(slip) * share, mu * P) * share
    return math.copysign(total, slip)


COCK_HALVINGS = 60  # bisections of the bend's cock (:func:`scrub_force`): its bracket halves each time, to 1e-18


def scrub_force(params, module: int, toward: tuple[float, float], radius: float) -> float:
    """The side force [N] on module ``module``'s (0 rear, 1 front) fore ring, the more loaded, while it rolls through
    a bend of centreline radius ``radius`` [m] turning across the pipe towards the unit (y, z) ``toward``, steady
    and quasi-static (docs/model.md, "The wheels' side force"). Its wheels roll only along the module's axis, so
    its rings slip at +-a, a = :func:`bend_slip_angle` (the fore ring's velocity turned towards the bend's
    inside, the aft ring's out); their side forces :func:`ring_side_force` push the fore ring out and the aft
    ring in, a couple that the legs' springs carry as the module cocks (its nose out) by psi, which adds psi to
    both rings' slip: the fore ring slips at a + psi and the aft at a - psi, their net push out, G(a + psi) -
    G(a - psi), is carried by both rings' springs moving out, and the couple, b (G(a + psi) + G(a - psi)), by
    the springs across the rings' spacing: psi = (G(a + psi) + G(a - psi)) / (2 k_r b), k_r = n k / 2 a ring's
    springs' stiffness across the pipe (k = P / suspension_travel), b = ring_spacing / 2. The fore ring's
    springs then carry G(a + psi). While no wheel slides G(x) = C x n / 2 and psi = C_r a / (k_r b) (C_r = C n / 2,
    C_r / k_r = cornering_coefficient suspension_travel), so the fore ring carries C_r a (1 + C_r / (k_r b)),
    falling as 1 / R; where every wheel slides, the ring's whole sideways friction :func:`ring_side_grip`
    whatever the radius (rigid wheels: at any radius). 0 for a module at rest, as each is half of every
    revolution."""
    a = bend_slip_angle(params, radius)
    if rigid_wheels(params):
        return ring_side_force(params, module, toward, a)
    return ring_side_force(params, module, toward, a + bend_cock(params, module, toward, radius))


def bend_cock(params, module: int, toward: tuple[float, float], radius: float) -> float:
    """How far [rad] module ``module`` (0 rear, 1 front) cocks, nose out, on its legs' springs while it rolls through
    a bend of centreline radius ``radius`` [m] turning towards the unit (y, z) ``toward``: psi solving
    2 k_r b psi = G(a + psi) + G(a - psi) (:func:`scrub_force`; G = :func:`ring_side_force`, a =
    :func:`bend_slip_angle`); rigid wheels (and unlimited grip): the rings' whole sideways friction over k_r b."""
    a = bend_slip_angle(params, radius)
    n = int(params.wheel_legs)
    P = (params.F_n1, params.F_n2)[module] / (2 * n)
    lever = 0.5 * params.ring_spacing * n * P / (2 * params.suspension_travel)  # k_r b [N/rad]
    if rigid_wheels(params):
        return ring_side_force(params, module, toward, a) / lever
    # 2 k_r b psi - (G(a + psi) + G(a - psi)) grows with psi (G is concave for a positive slip and odd), from
    # -2 G(a) at 0 to >= 0 where 2 k_r b psi reaches twice the rings' whole sideways friction: one root, bisected
    low, high = 0.0, ring_side_grip(params, module, toward) / lever
    for _ in range(COCK_HALVINGS):
        psi = 0.5 * (low + high)
        couple = ring_side_force(params, module, toward, a + psi) + ring_side_force(params, module, toward, a - psi)
        low, high = (psi, high) if 2.0 * lever * psi < couple else (low, psi)
    return 0.5 * (low + high)


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
    :func:`lift_check`). A module that holds along the pipe with the share u of its grip (``grip_use``, the
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


def bend_lift_check(params, radius: float, toward: tuple[float, float], across) -> dict:
    """The lift-off check (:func:`lift_check`) of each module rolling through a bend of centreline radius ``radius``
    [m] that turns towards the unit (y, z) ``toward`` across the pipe (in the robot's frame at the route's start:
    y its left, z its up), under gravity's components across the pipe ``across`` [(g_y, g_z), m/s^2] at points
    along the bend. On top of the straight pipe's loads (half the sprung weight across, here as given; the rod's
    side force, the motor's couple on module 1) each ring carries

    - the wheels' side force (:func:`scrub_force`, the fore ring's) along +-toward: the bend's own load, growing
      with the rings' slip angle b / R while the wheels roll on it, capped at the rings' sideways friction where
      they slide (rigid wheels: the cap at any radius; at the defaults' 3 legs 2 mu_wall P across a horizontal
      bend, 1.73 mu_wall P across one turning up);
    - the rod's push or pull at its angle to the module: the rod is a chord of the bend of length at most r + L,
      (r + L) / (2 R) off the module's axis, carrying the moving module's rolling resistance and weight (at most
      max(F_ri + m_i g)) while neither module skids;
    - the pipe's spread off the ring's plane: the ring's plane cuts the bend obliquely, so the wall is farther by
      half :func:`bend_wheel_spread` along toward, which unloads leg k by P (u_k . toward)^2 spread / (2 travel).

    Returns {'least_press1_n', 'least_press2_n': the least-pressed leg's press [N] (< 0: it lifts),
    'lift_predicted': bool, 'scrub_n': (module 1's, module 2's) ring load [N]}."""
    n = int(params.wheel_legs)
    torque = abs(params.M) if params.drive == "torque" else params.M_stall
    side = rod_side_force(torque, params.r, params.L)
    push = max(params.F_r1 + params.m1 * params.g, params.F_r2 + params.m2 * params.g)
    chord = push * min(1.0, (params.r + params.L) / (2 * radius))
    half_base = 0.5 * params.ring_spacing
    spread = bend_wheel_spread(half_base, params.wheel_radius, radius, params.pipe_diameter)
    legs = [leg_direction(k, n) for k in range(n)]
    ty, tz = toward
    out, scrubs = {}, []
    for i, Fn in enumerate((params.F_n1, params.F_n2), start=1):
        m = sprung_mass(params, i - 1)  # across the pipe the springs carry the module less its legs
        P = Fn / (2 * n)
        scrub = scrub_force(params, i - 1, toward, radius)
        scrubs.append(scrub)
        couple = torque / params.ring_spacing if i == 1 else 0.0
        least = math.inf
        for gy, gz in across:
            for lateral in (0.5 * side + couple, -(0.5 * side + couple), 0.5 * side - couple, couple - 0.5 * side):
                for bend_load in (scrub + 0.5 * chord, -(scrub + 0.5 * chord)):
                    fy = 0.5 * m * gy + lateral + bend_load * ty
                    fz = 0.5 * m * gz + bend_load * tz
                    for (_, uy, uz) in legs:
                        spread_loss = P * (uy * ty + uz * tz) ** 2 * 0.5 * spread / params.suspension_travel
                        least = min(least, P - spread_loss + (2.0 / n) * (fy * uy + fz * uz))
        out[f"least_press{i}_n"] = least
    out["lift_predicted"] = out["least_press1_n"] < 0 or out["least_press2_n"] < 0
    out["scrub_n"] = tuple(scrubs)
    return out


def lift_summary(params, fit: dict | None = None) -> dict:
    """The lift-off check's summary keys of a wheeled run: ``least_press1_n``, ``least_press2_n`` [N] and
    ``lift_predicted`` (:func:`lift_check`); along a route, with its ``fit`` (the run's ``route_fit``, whose bends
    carry :func:`bend_lift_check`'s least presses), the least over the straight pipe and every bend."""
    check = lift_check(params)
    out = {key: check[key] for key in ("least_press1_n", "least_press2_n", "lift_predicted")}
    for bend in (fit or {}).get("bends", ()):
        for key in ("least_press1_n", "least_press2_n"):
            if bend.get(key) is not None:
                out[key] = min(out[key], bend[key])
    out["lift_predicted"] = out["least_press1_n"] < 0 or out["least_press2_n"] < 0
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
      :func:`lift_check` takes them (the rod's largest side force :func:`rod_side_force` at the drive's largest
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
