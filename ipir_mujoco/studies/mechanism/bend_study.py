"""The bend study (``ipir-mujoco bend-study``): time and energy for the wheeled robot to pass a 90-degree bend,
against the bend's R/D, beside the straight-pipe predictions over the same centreline length.

Each case is a route (:mod:`ipir_mujoco.core.route`): a lead-in straight of LEAD_IN + L / 2 (the robot reaches its
cruise before the bend: L is the rod, about the distance from the rear module's crank axis A to the front module's
C), a 90-degree bend of centreline radius R = (R/D) D, L / 2 + EXIT after it. The *passage* is the window from the
robot's centre (midway between A and C along the route) L / 2 before the bend (the front module entering it) to L /
2 after it (the rear module leaving it): a centreline length L + pi R / 2. (The centre moves more evenly than either
module, which stands half of each revolution; its crossing times still carry about r / 2 / v, 0.05 s, of the
stroke's ripple.) Its time and the motor's work over it come from the wheeled MuJoCo run (``mujoco-wheels`` with the
route, the rear module's progress along the centreline, :mod:`ipir_mujoco.engine.kinds.wheels.route_watch`), with how it ended
(done, or where and why it stopped), the closed-form fit beside it, and how long wheels were off their walls.

The references over the same length: the analytic finite-grip model's (``analytic-unilateral``) periodic
steady state in a straight pipe, speed v and energy per metre e: time length / v, energy e x length; and the
wheeled model's own straight pipe (the same route with the bend straightened: its marks at the same
distances), so that what the bend costs is told apart from what the wheels cost in any pipe.

The equations along the same route: each case's route (the bend, and its straightened twin) also runs in the
analytic route model (``analytic-unilateral`` with the route: the linkage spanning the bend's chord, gravity at
each module, the wheels' scrub in its closed form; docs/model.md, "The equations along a route"), over the same
window (:func:`ipir_mujoco.studies.comparison.route_compare.window`): its passage time, energy and scrub work (``equations``
in each case's record), and MuJoCo's difference from it in the bend (``mujoco_vs_equations``: time, and energy
over what the robot dissipated, MuJoCo's less the equations'; and the class
:func:`ipir_mujoco.studies.comparison.route_compare.judge` gives it: both within 2 %, or a lift or a scrub the closed-form
checks predicted and MuJoCo showed, or a stop, or a miss), so that a bend's cost in MuJoCo is judged against an
independent model of the same bend, not only against MuJoCo's own straight pipe.

``planes`` [deg]: the bend's plane turned about the pipe's axis (:mod:`ipir_mujoco.core.route`): 0 turns it in the
horizontal plane, across gravity (the default); 90 turns it up, in the plane of gravity, so that the route leaves
the bend as a riser. The energy over the window is the motor's work less the kinetic *and potential* energy gained
(MuJoCo's potential energy: the height, and the springs of the wheels' legs; what is left is what the robot
dissipates, comparable with its level twin's); a bend that turns up also climbs, which its time includes and the
level twin and the analytic level reference do not: the row says how much potential energy the window gained.
Each plane's bends share their straight twins (a straight has no plane).

A bend that passes faster than its straight twin (by more than TWIN_SLACK of the twin's time) gets a note that says
why with the run's numbers (``note``): wheels off their walls (a module that floats slides without turning its hubs,
so the rolling resistance does no work), or, with every wheel on its wall, the passage's timing ripple.
"""

from __future__ import annotations

import functools
import math
import sys
import time
from typing import Callable, Sequence


from ipir_mujoco import registry
from ipir_mujoco.core.checks import check_numbers
from ipir_mujoco.core.errors import ParameterError, ParameterTypeError, SimulationError, refuse_all_failed
from ipir_mujoco.core.options import progress_text
from ipir_mujoco.core.params import RobotParams, check_whole, require_params
from ipir_mujoco.core.pipe import check_fit
from ipir_mujoco.core.route import route_from_tables

from ..comparison.route_compare import judge
from ..comparison.route_compare import window as route_window
from ..pool import map_unordered

RATIOS = (0.6, 1.0, 1.5, 2.0, 3.0, 5.0, 7.5, 10.0)  # R/D, the default
RATIOS_QUICK = (2.0, 5.0)
LEAD_IN = 0.6  # m: straight before the passage's window (the default motor reaches its cruise in ~1 s)
EXIT = 0.05  # m: straight after the bend
DT_OUT = 1e-3  # s: the samples the progress is read from (the passage's times are good to this)
T_CAP_PER_M = 20.0  # s per metre of route: the run's cap (the default motor cruises at ~0.53 m/s: 1.9 s/m)
MU_WALL = 0.8  # the study's wall friction unless --set gives one: the straight-pipe acceptance case
PROGRESS_EVERY_S = 5.0  # s of wall time between a running case's progress lines (a log's interval, terminal.py)
PLANES = (0.0,)  # deg: the bends' planes, the default (0: horizontal, across gravity)
TWIN_SLACK = 0.005  # a bend faster than its twin by more than this share of the twin's time gets a note: the
# centre's crossing times carry ~0.05 s of a stroke's ripple (module docstring), ~2-7 % of a passage of 0.7-2.7 s
# at R/D 2-10, but a mean over both marks; half a percent is what the R/D >= 5 rows agree to (mjcf/README.md)


def study_params(base: RobotParams) -> RobotParams:
    """The study's parameters: ``base`` with the motor, and mu_wall MU_WALL where it is unlimited; ParameterError
    (one line) for an incline or a robot that does not fit its pipe (:func:`ipir_mujoco.core.pipe.check_fit`)."""
    if base.incline != 0.0:
        raise ParameterError(f"incline={base.incline:g} deg: the bend study's bends are horizontal; allowed: "
                             "incline=0")
    check_fit(base)  # the robot fits its pipe: refused here, before any run
    return base.replace(drive="motor", mu_wall=MU_WALL if base.mu_wall is None else base.mu_wall)


def case_route(params: RobotParams, ratio: float, plane: float = 0.0):
    """The route of one case: the lead-in, a 90-degree bend of R/D ``ratio`` in the plane ``plane`` [deg], the
    exit."""
    half = dict(kind="straight", length=params.L / 2)
    return route_from_tables([dict(kind="straight", length=LEAD_IN), half,
                              dict(kind="bend", radius=ratio * params.pipe_diameter, angle=90.0, plane=plane), half,
                              dict(kind="straight", length=EXIT)], "bend study")


def check_planes(planes: Sequence[float], params: RobotParams, ratio: float) -> None:
    """ParameterError (one line) for a plane out of -180..180 deg, or one the wheeled model cannot run (the
    model's own route check on the first case, before any run)."""
    from ipir_mujoco.engine.kinds import kind_for

    if not planes:
        raise ParameterError("--planes is empty; allowed: one or more angles, -180..180 deg")
    for plane in planes:
        if not (isinstance(plane, (int, float)) and math.isfinite(plane) and -180 <= plane <= 180):
            raise ParameterError(f"--planes {plane!r} is out of range; allowed: -180..180 deg")
        kind_for("wheels", params).check(params, "ratchet", "unilateral", case_route(params, ratio, plane))


def straight_route(params: RobotParams, length: float):
    """The straightened route: the same marks as a bend's of centreline length ``length`` [m]."""
    half = dict(kind="straight", length=params.L / 2)
    return route_from_tables([dict(kind="straight", length=LEAD_IN), half, dict(kind="straight", length=length),
                              half, dict(kind="straight", length=EXIT)], "bend study")


def check_ratios(ratios: Sequence[float], params: RobotParams) -> None:
    """ParameterError (one line) for an R/D the pipe cannot have: above 1/2 (the inner wall), at most 100."""
    ratios = check_numbers("ratios", ratios, "a list of R/D values, 0.5 < R/D <= 100")
    if not ratios:
        raise ParameterError("--ratios is empty; allowed: one or more R/D values, 0.5 < R/D <= 100")
    for r in ratios:
        if not (isinstance(r, (int, float)) and math.isfinite(r) and 0.5 < r <= 100):
            raise ParameterError(f"--ratios {r!r} is out of range; allowed: R/D > 0.5 and <= 100")
        if r * params.pipe_diameter > 100:
            raise ParameterError(f"--ratios {r:g}: radius {r * params.pipe_diameter:g} m; allowed: radius <= 100 m")


def _passage(run, route, first: int, last: int) -> dict:
    """The window from the robot's centre at mark ``first`` to mark ``last`` (route pieces' starts): time [s]
    and the energy the robot used [J] (the motor's work less the kinetic and potential energy gained: the window's
    ends fall at any phase of a revolution, whose kinetic energy swings by tenths of a joule;
    :func:`..comparison.route_compare.window`), or None where the run did not get there; with MuJoCo's route keys."""
    s = run.summary
    out = {"route_done": s["route_done"], "route_stop": s["route_stop"], "route_s_m": s["route_s_m"],
           "route_length_m": s["route_length_m"], "route_wall_loss": s["route_wall_loss"],
           "route_wheel_off_s": s["route_wheel_off_s"], "route_module_off_s": s["route_module_off_s"],
           "route_arm_reach": s["route_arm_reach"], "predicted": s["route_fit"]["predicted"],
           "wheels_keep_wall": all(b["wheels_keep_wall"] for b in s["route_fit"]["bends"]),
           "timestep_s": run.settings["timestep"], "residual_ratio": s["accuracy"].get("residual_ratio"),
           "skid_j": run.energy.get("skid_j"), "lift_predicted": s.get("lift_predicted"),
           "slid_m": max(float(run.series[c][-1]) for c in ("slid1", "slid2")) if "slid1" in run.series else None}
    passage = route_window(run, first, last)
    out.update(passage, passed=passage["time_s"] is not None)
    return out


def run_case(params: RobotParams, item: tuple[str, float, float]) -> dict:
    """One case in a worker: ('bend', R/D, plane [deg]) or ('straight', R/D: its bend's length straightened, 0)."""
    kind, ratio, plane = item
    started = time.perf_counter()
    arc = math.pi / 2 * ratio * params.pipe_diameter
    route = straight_route(params, arc) if kind == "straight" else case_route(params, ratio, plane)
    t_cap = T_CAP_PER_M * route.length
    what = f"R/D {ratio:g} " + (f"bend in plane {plane:g} deg" if kind == "bend" else kind)
    try:
        run = registry.run("mujoco-wheels", params, t_cap, dt_out=DT_OUT, route=route, accuracy="warn",
                           progress=_quiet_printer(what, started, t_cap))
    except SimulationError as exc:
        return {"kind": kind, "R_over_D": ratio, "error": str(exc), "passed": False,
                "wall_s": time.perf_counter() - started, "equations": equations_case(params, route)}
    out = _passage(run, route, 1, 4)
    out.update(kind=kind, R_over_D=ratio, plane_deg=plane, radius_m=ratio * params.pipe_diameter,
               window_m=params.L + arc, wall_s=time.perf_counter() - started, equations=equations_case(params, route))
    return out


def equations_case(params: RobotParams, route) -> dict:
    """The equations (``analytic-unilateral``) along ``route``: its passage's ``time_s``, ``energy_j`` and
    ``scrub_j`` (:func:`..comparison.route_compare.window`), ``passed``, its ``route_stop``, ``residual_ratio`` and ``wall_s``
    [s]; a failure's line as ``error``."""
    started = time.perf_counter()
    try:
        run = registry.run("analytic-unilateral", params, T_CAP_PER_M * route.length, dt_out=DT_OUT, route=route)
    except SimulationError as exc:
        return {"error": str(exc), "passed": False, "time_s": None, "energy_j": None, "scrub_j": None}
    out = route_window(run, 1, 4)
    out.update(passed=out["time_s"] is not None, route_stop=run.summary["route_stop"],
               residual_ratio=run.summary["accuracy"]["residual_ratio"], wall_s=time.perf_counter() - started)
    return out


def _quiet_printer(what: str, started: float, t_cap: float, every: float = PROGRESS_EVERY_S):
    """A run's progress callback (simulated time [s]) printing on stderr at most every ``every`` seconds of wall
    time, from the run's worker: a case's run takes minutes, and its end alone would leave the study silent (its
    skid check's repeats at finer steps too: they say so). ``t_cap`` [s]: the run's cap."""
    last = [started]

    def progress(t: float) -> None:
        now = time.perf_counter()
        if now - last[0] >= every:
            last[0] = now
            print(f"bend-study: {what}: {progress_text(t, t_cap)} ({now - started:.0f} s wall)", file=sys.stderr,
                  flush=True)
    return progress


def twin_note(bend: dict, straight: dict) -> str | None:
    """Why a bend passed faster than its straight twin, with the runs' numbers (module docstring), or None."""
    tb, ts = bend.get("time_s"), straight.get("time_s")
    if tb is None or ts is None or not tb < (1 - TWIN_SLACK) * ts:
        return None
    faster = f"{100 * (1 - tb / ts):.1f} % faster than its straight twin ({tb:.3f} s against {ts:.3f} s)"
    if (bend.get("route_wheel_off_s") or 0.0) > 0:
        return (f"{faster}: wheels were off their walls {bend['route_wheel_off_s']:.3f} s (a whole module "
                f"{bend['route_module_off_s']:.3f} s); a module off its walls slides without turning its hubs, so the "
                "rolling resistance does no work there")
    return f"{faster}, every wheel on its wall: within the passage's timing ripple (a stroke's, ~0.05 s)"


def reference(params: RobotParams) -> dict:
    """The analytic finite-grip model's straight-pipe steady state: speed [m/s], energy per metre [J/m]."""
    run = registry.run("analytic-unilateral", params, 30.0, dt_out=1e-3, until_steady=True)
    s = run.summary
    if not s["steady"]:
        raise SimulationError("bend study: the analytic straight-pipe reference reached no steady state in 30 s")
    return {"steady_speed_m_s": s["steady_speed_m_s"], "energy_per_metre_j_m": s["energy_per_metre_j_m"]}


def run_study(base: RobotParams, ratios: Sequence[float] = RATIOS, *, workers: int = 1,
              progress: Callable[[str], None] = lambda _m: None, planes: Sequence[float] = PLANES) -> dict:
    """The study (module docstring) as a JSON-ready dict: ``rows`` (one per plane and R/D: the bend's passage,
    its straightened twin's, the analytic reference over the same length, ``note`` where the bend was faster
    than its twin; the equations' passage of the bend and of the twin, ``equations`` and
    ``equations_straight``, and ``mujoco_vs_equations``), ``reference``, ``settings``, ``wall_s``."""
    require_params(base)
    check_whole("workers", workers, low=1, high=1024)
    if not callable(progress):
        raise ParameterTypeError(f"progress={progress!r} is not callable; allowed: a function of one message")
    started = time.perf_counter()
    params = study_params(base)
    check_ratios(ratios, params)
    check_planes(planes, params, min(ratios))
    ref = reference(params)
    items = [(kind, r, p) for r in sorted(ratios, reverse=True)  # longest first
             for kind, p in [("bend", p) for p in planes] + [("straight", 0.0)]]
    results: dict[tuple[str, float, float], dict] = {}

    def done(item, result) -> None:
        results[item] = result
        kind, r, p = item
        status = (result["error"] if "error" in result else
                  f"passage {result['time_s']:.3f} s, {result['energy_j']:.3f} J" if result["passed"] else
                  f"did not pass: {result['route_stop']}")
        what = f"bend in plane {p:g} deg" if kind == "bend" else kind
        progress(f"[{len(results)}/{len(items)}] R/D {r:g} {what}: {status} ({result['wall_s']:.1f} s wall)")

    map_unordered(functools.partial(run_case, params), items, workers, done)
    refuse_all_failed([results[item].get("error") for item in items], "runs")
    rows = []
    for p in planes:
        for r in sorted(ratios):
            bend, straight = results[("bend", r, p)], results[("straight", r, 0.0)]
            window = params.L + math.pi / 2 * r * params.pipe_diameter
            analytic = {"time_s": window / ref["steady_speed_m_s"], "energy_j": window * ref["energy_per_metre_j_m"]}
            equations = bend.get("equations") or {}
            versus = judge(equations, bend, work="energy_j", done="passed")
            rows.append({"plane_deg": p, "R_over_D": r, "radius_m": r * params.pipe_diameter, "window_m": window,
                         "bend": bend, "straight": straight, "analytic": analytic, "note": twin_note(bend, straight),
                         "equations": equations, "equations_straight": straight.get("equations") or {},
                         "mujoco_vs_equations": {"time_s": versus["time_diff"], "energy_j": versus["work_diff"],
                                                 "outcome": versus["outcome"], "lift": versus["lift"],
                                                 "scrub": versus["scrub"]}})
    return {"rows": rows, "reference": ref,
            "settings": {"lead_in_m": LEAD_IN, "exit_m": EXIT, "dt_out_s": DT_OUT, "angle_deg": 90.0,
                         "planes_deg": list(planes),
                         "params": params.as_dict(), "window": "front module entering (A at the bend's start - L) "
                                                              "to rear module leaving (A at its end)"},
            "wall_s": time.perf_counter() - started}
