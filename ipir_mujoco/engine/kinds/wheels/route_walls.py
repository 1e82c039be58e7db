"""The closed-form fit of a route's bends for the wheeled MuJoCo model, reported beside MuJoCo's outcome.

:func:`fit_prediction` checks each bend of a route (:mod:`ipir_mujoco.core.route`) with the round-pipe model's
geometry against the closed forms of :mod:`ipir_mujoco.core.pipe`: the rigid housing's length, the spread its
sprung wheels need, the rod's clearance from the inner wall and the legs' lift-off check while a module rolls
through the bend (:func:`~ipir_mujoco.core.pipe.bend_lift_check`, with the bend's direction and gravity from
:func:`bend_loads`). The walls themselves are :mod:`.pipe_walls`' (round and exact).
"""

from __future__ import annotations

import math

from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.pipe import bend_lift_check, bend_max_length, bend_rod_clearance, bend_wheel_spread
from ipir_mujoco.core.route import Piece, Route

HOUSING_HALF = 0.03  # m: a housing's half-size, the fit's default rigid part
ROD_RADIUS = 0.004  # m: the rod's capsule radius (inchworm_wheels.xml)


def bend_loads(route: Route, bend: Piece, g: float, samples: int = 9) -> tuple[tuple[float, float], list]:
    """A bend's (toward, across) for :func:`ipir_mujoco.core.pipe.bend_lift_check`: the unit (y, z) it turns to
    in the robot's frame (its legs keep their place about the pipe's axis as it goes: the frame the route carries
    along, parallel transport) and gravity's (``g`` [m/s^2]) components across the pipe at ``samples`` points
    along it."""
    _, n, b = bend.frame
    d = bend.toward
    toward = (float(d @ n), float(d @ b))
    across = []
    for j in range(samples):
        frame = bend.frame_at(bend.length * j / (samples - 1))
        across.append((-g * float(route.up @ frame[1]), -g * float(route.up @ frame[2])))
    return toward, across


def fit_prediction(route: Route, params: RobotParams, half_base: float, spring_travel: float,
                   housing: tuple[float, float] = (2 * HOUSING_HALF, 2 * HOUSING_HALF)) -> dict:
    """The closed-form check of each bend beside MuJoCo's outcome: the rigid housing (``housing``: its width
    across the pipe and its length [m]) against :func:`.pipe.bend_max_length`, and the spread the wheels of a station (``half_base`` [m] either side
    of the module's middle) need against their springs' reach (2 ``spring_travel`` [m] per pair: each of the
    pair's springs reaches its free length), :func:`.pipe.bend_wheel_spread`. Returns ``{"bends": [...],
    "predicted": one line}``; a figure with no finite value (the rod's clearance where it is longer than the
    centreline's diameter) is None."""
    D, Rw = params.pipe_diameter, params.wheel_radius
    bends, worst = [], None
    for k, bend in enumerate(route.bends):
        rigid = bend_max_length(housing[0], bend.radius, D)
        spread = bend_wheel_spread(half_base, Rw, bend.radius, D)
        press = 1.0 - spread / (2 * spring_travel)
        clearance = bend_rod_clearance(params.L, ROD_RADIUS, bend.radius, D)
        lift = bend_lift_check(params, bend.radius, *bend_loads(route, bend, params.g))
        bends.append({"bend": k + 1, "radius_m": bend.radius, "R_over_D": bend.radius / D,
                      "plane_deg": math.degrees(bend.plane),
                      "housing_max_length_m": rigid, "housing_fits": rigid >= housing[1],
                      "wheel_spread_m": spread, "spring_reach_m": 2 * spring_travel,
                      "wall_press_share": press, "wheels_keep_wall": press > 0 and not lift["lift_predicted"],
                      "least_press1_n": lift["least_press1_n"], "least_press2_n": lift["least_press2_n"],
                      "scrub_n": list(lift["scrub_n"]),
                      "rod_clearance_m": clearance, "rod_clears": clearance > 0})
        if worst is None or press < worst["wall_press_share"]:
            worst = bends[-1]
    tightest = min(bends, key=lambda b: b["rod_clearance_m"]) if bends else None
    lifting = [b for b in bends if b["least_press1_n"] < 0 or b["least_press2_n"] < 0]
    if worst is None:
        predicted = "no bend: the straight pipe's fit"
    elif not worst["housing_fits"]:
        predicted = f"jams: the housing does not pass bend {worst['bend']}"
    elif not tightest["rod_clears"]:
        by = ("it is longer than the centreline's diameter" if math.isinf(tightest["rod_clearance_m"]) else
              f"as a chord of the centreline it would cross the inner wall by "
              f"{-tightest['rod_clearance_m'] * 1e3:.3g} mm")
        predicted = f"the linkage may bind in bend {tightest['bend']} (R/D {tightest['R_over_D']:.3g}): the rod {by}"
    elif not worst["wheels_keep_wall"] and worst["wall_press_share"] <= 0:
        predicted = (f"a wheel leaves the wall in bend {worst['bend']} (R/D {worst['R_over_D']:.3g}): the wheels "
                     f"need {worst['wheel_spread_m'] * 1e3:.3g} mm more spread, their springs reach "
                     f"{2 * spring_travel * 1e3:.3g} mm")
    elif lifting:
        b = min(lifting, key=lambda b: min(b["least_press1_n"], b["least_press2_n"]))
        i = 1 if b["least_press1_n"] <= b["least_press2_n"] else 2
        predicted = (f"a wheel may leave the wall in bend {b['bend']} (R/D {b['R_over_D']:.3g}): module {i}'s "
                     f"least-pressed leg {b[f'least_press{i}_n']:.3g} N with its wheels' side force in the bend "
                     f"({b['scrub_n'][i - 1]:.3g} N on its fore ring) on the straight pipe's loads")
    else:
        predicted = (f"passes: in bend {worst['bend']} (R/D {worst['R_over_D']:.3g}) the wheels press with "
                     f"{100 * worst['wall_press_share']:.0f} % of their preload and no leg lifts")
    for b in bends:  # JSON has no infinity: a rod longer than the centreline's diameter has no clearance (None)
        b.update({key: None for key, value in b.items() if isinstance(value, float) and not math.isfinite(value)})
    return {"bends": bends, "predicted": predicted}
