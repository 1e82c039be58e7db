"""The round pipe's wheel legs (the wheeled MuJoCo model): their geometry and masses, a ring's sideways grip and
the side force its wheels carry rolling through a bend.

Shared by both closed-form checks of a wheeled run, the lift-off check (:mod:`.pipe`) and the sideways-grip
check (:mod:`.side_check`), and by the wheeled model's builder (the legs' directions, masses and whether its
wheels are rigid); and a module's frame (:func:`in_module_frame`, :func:`module_gravity`: the run's loads and
gravity as its rings feel them). Statics of one ring on the robot's parameters; no dynamics of the robot.
"""

from __future__ import annotations

import math

import numpy as np


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


def spread_unload(params, preload, along, spread: float):
    """The press [N] a leg of preload ``preload`` [N] loses to the pipe's spread off its ring's plane in a bend,
    ``spread`` [m] (:func:`ipir_mujoco.core.pipe.bend_wheel_spread`), the leg's direction's cosine ``along`` with the
    way the bend turns (a float or an array): P along^2 spread / (2 suspension_travel), the ring's plane cutting the
    bend obliquely so the wall is farther by half the spread along the turn."""
    return preload * along ** 2 * 0.5 * spread / params.suspension_travel


def module_gravity(params, rotation) -> np.ndarray:
    """Gravity's components across the pipe [m/s^2] in a module's frame, shape (..., 2) (y, z): ``rotation``
    (..., 3) the module's rotation vector [rad] (the run's roll, pitch and yaw columns: axis times angle, its frame
    in the world's). The world's up is (sin(incline), 0, cos(incline)): a straight pipe's, and a route's (its
    first straight's incline, :attr:`.route.Route.up`, which a run along it takes as ``incline``)."""
    angle = math.radians(params.incline)
    up = np.array([math.sin(angle), 0.0, math.cos(angle)])
    return in_module_frame(rotation, -params.g * up)[..., 1:]


def in_module_frame(rotation, vector) -> np.ndarray:
    """World vectors ``vector`` ((..., 3) or (3,)) in a module's frame, shape (..., 3): R^T v, R the rotation of
    rotation vector ``rotation`` (..., 3) [rad] (axis times angle; Rodrigues' formula turned by -angle)."""
    rot = np.asarray(rotation, dtype=float)
    v = np.asarray(vector, dtype=float)
    theta = np.linalg.norm(rot, axis=-1, keepdims=True)
    axis = rot / np.where(theta > 1e-12, theta, 1.0)
    c, s = np.cos(theta), np.sin(theta)
    return v * c - np.cross(axis, v) * s + axis * np.sum(axis * v, axis=-1, keepdims=True) * (1.0 - c)
