"""``ipir-mujoco simulate``: one engine on one parameter set."""

from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING

from ipir_mujoco import registry
from ipir_mujoco.core import energy
from ipir_mujoco.core.energy import INPUT, RESIDUAL_KEY
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.limits import (DEFAULT_WALL_BUDGET_S, check_run_options, check_step_count,
                                     refuse_steady_without_motor)
from ipir_mujoco.core.params import check_real, check_whole

from .. import terminal
from ..labels import fixed, significant
from .common import EXIT_OK, add_model_options, check_input_file, files_line, model_params, progress_printer

if TYPE_CHECKING:  # the parser loads without numpy (``ipir-mujoco --help``); a run loads the results with it
    from ipir_mujoco.core.results import RunResult


def add_parser(commands) -> None:
    sim = commands.add_parser("simulate", help="run one engine on one parameter set",
                              description="Run one engine on one parameter set and print or write its results. "
                                          "Defaults: the paper's model and case for 1 s.")
    sim.add_argument("--engine", choices=("analytic", "mujoco"), default="analytic",
                     help="analytic equations or MuJoCo physics (default: analytic)")
    sim.add_argument("--geometry", choices=("approx", "exact"), default=None,
                     help="first-order kinematics as in the paper (approx; analytic default) or the exact "
                          "slider-crank (exact; MuJoCo always models it)")
    sim.add_argument("--clutch", choices=registry.RULES, default=None,
                     help="kinematic: the paper's rule, lock by the sign of S_dot (default); "
                          "unilateral: one-way clutches that can only push (the default and only choice with "
                          "--mujoco-model wheels)")
    sim.add_argument("--mujoco-clutch", choices=registry.MUJOCO_CLUTCHES, default=None,
                     help="MuJoCo clutch implementation: joint-limit ratchet (default with --clutch unilateral) "
                          "or velocity-triggered lock (default with --clutch kinematic)")
    sim.add_argument("--mujoco-model", choices=registry.MUJOCO_MODELS, default="slides",
                     help="MuJoCo's model of the robot: slides = the modules on slide joints, their resistance joint "
                          "friction (default); wheels = the robot in 3-D in its round pipe (pipe_diameter), each "
                          "module free to move across it and tilt, on rings of wheel legs pressed on the wall by "
                          "springs, a ratchet in every hub, friction mu_wall at the contacts (mjcf/README.md)")
    sim.add_argument("--route", metavar="FILE.toml", default=None,
                     help="a pipeline of [[segment]] tables (straights and bends, docs/cli.md), for the exact "
                          "equations (--geometry exact, its default with --route) or --mujoco-model wheels; the run "
                          f"ends at the route's end or where the robot stops (default --t-end {T_END_ROUTE:g} s then)")
    sim.add_argument("--timestep", type=float, default=None, metavar="SECONDS",
                     help="MuJoCo timestep [s] (default: chosen from the motion, by the rule in mjcf/README.md, "
                          "installed with the package: see 'ipir-mujoco --help')")
    sim.add_argument("--accuracy", choices=("stop", "warn"), default=None,
                     help="MuJoCo accuracy monitor: stop the run when the energy residual or the loop gap "
                          "exceeds its tolerance (the default on the slides), or warn, record it in the summary and "
                          "go on (the default with --mujoco-model wheels: the wheels' soft contacts take work the "
                          "audit does not count, mjcf/README.md)")
    sim.add_argument("--mjcf", metavar="FILE.xml", default=None,
                     help="MJCF template for --engine mujoco (default: the shipped inchworm.xml)")
    sim.add_argument("--save-mjcf", metavar="FILE.xml", default=None,
                     help="with --engine mujoco: write the compiled model this run uses (its timestep, its initial "
                          "state as the keyframe run_start, a header saying what the package's controllers do "
                          "between steps) before the run")
    add_model_options(sim)
    sim.add_argument("--t-end", type=float, default=None, metavar="SECONDS",
                     help="simulated time (default 1 s); with --until-steady, the cap (default 30 s)")
    sim.add_argument("--until-steady", action="store_true",
                     help="stop at the periodic steady state (per-revolution mean speed settled); --t-end caps it")
    sim.add_argument("--dt-out", type=float, default=None, metavar="SECONDS",
                     help="output sample interval (default 1e-4 s, or the --timestep if that is longer); the "
                          "analytic engines also sample every mode switch")
    sim.add_argument("--max-switches", type=int, default=None, metavar="N",
                     help="analytic engines: stop with an error after N mode switches (a work budget for designs "
                          "that chatter; default: the engine's, 100000)")
    sim.add_argument("--wall-budget", type=float, default=DEFAULT_WALL_BUDGET_S, metavar="SECONDS",
                     help=f"stop with an error after SECONDS of wall time (default {DEFAULT_WALL_BUDGET_S:g} s, so "
                          "that no run goes on for hours; 'inf' for no limit)")
    sim.add_argument("--out", metavar="DIR",
                     help="write DIR/timeseries.csv, DIR/mode_changes.csv (time and crank angle of each mode "
                          "change), DIR/summary.json and the paper's figures as PNG")
    sim.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    sim.set_defaults(handler=run)


DT_OUT = 1e-4  # s: the default output interval
FIGURES = ("fig2_crank.png", "fig3_modules.png", "fig4_gap.png")  # --out's figures (report.plots.write_paper_figures)


def output_interval(args: argparse.Namespace) -> float:
    """--dt-out, or by default 1e-4 s, a whole number of MuJoCo timesteps when --timestep is given."""
    if args.dt_out is not None:
        return args.dt_out
    if args.engine == "mujoco" and args.timestep is not None and args.timestep > 0:
        return args.timestep * max(1, round(DT_OUT / args.timestep))
    return DT_OUT


T_END, T_END_STEADY = 1.0, 30.0  # s: the default run, and the default cap of a run to steady state
T_END_ROUTE = 60.0  # s: the default cap of a run along a route


FLAGS = {"max_switches": "--max-switches", "mjcf": "--mjcf", "timestep": "--timestep", "accuracy": "--accuracy"}


def check_options(args: argparse.Namespace) -> registry.Variant:
    """Every option of ``simulate`` that the engines do not check themselves, before any work; the variant
    the flags name (:func:`ipir_mujoco.registry.from_flags`)."""
    if args.route is not None and args.until_steady:
        raise ParameterError("--until-steady with --route: a run along a route ends at the route's end; allowed: "
                             "one of them")
    if args.t_end is None:
        args.t_end = T_END_STEADY if args.until_steady else T_END_ROUTE if args.route is not None else T_END
    if args.timestep is not None:  # before the output interval is derived from it
        check_real("--timestep", args.timestep, high=1e-2, unit="s")
    args.dt_out = output_interval(args)
    check_run_options(args.t_end, args.dt_out)
    if args.engine == "mujoco" and args.timestep is not None:
        check_step_count(args.t_end, args.timestep, "--t-end", "--timestep")
    if not (args.wall_budget > 0):  # nan and <= 0; inf is no limit
        raise ParameterError(f"--wall-budget {args.wall_budget:g} is out of range; allowed: a number of seconds "
                             "> 0, or inf (no limit)")
    if args.max_switches is not None:
        check_whole("--max-switches", args.max_switches, low=1)
    if args.route is not None and args.engine == "analytic" and args.geometry is None:
        args.geometry = "exact"  # the equations along a route: the exact linkage spans a bend's chord
    variant = registry.from_flags(args.engine, args.geometry, args.clutch, args.mujoco_clutch, args.mujoco_model)
    registry.check_route_flag(args.route, variant)
    engine_options = {"max_switches": args.max_switches, "mjcf": args.mjcf, "timestep": args.timestep,
                      "accuracy": None if args.accuracy in (None, "stop") else args.accuracy}
    registry.check_options(variant, engine_options, FLAGS.get)
    if args.mjcf is not None:
        check_input_file("--mjcf", args.mjcf)
    if args.route is not None:
        from ipir_mujoco.core.route import read_route

        check_input_file("--route", args.route)
        args.route_parsed = read_route(args.route)
    return variant


def run_simulation(args: argparse.Namespace) -> RunResult:
    """The run ``simulate`` asks for (raises ParameterError on bad input)."""
    variant = check_options(args)
    params = model_params(args)
    progress = progress_printer(args.t_end) if not args.json else None
    accuracy = args.accuracy if variant.is_mujoco else None  # None: the model's own (stop; warn on wheels)
    try:
        return registry.run(variant, params, args.t_end, dt_out=args.dt_out, until_steady=args.until_steady or None,
                            progress=progress, max_switches=args.max_switches, timestep=args.timestep,
                            mjcf=args.mjcf, accuracy=accuracy, wall_budget_s=args.wall_budget,
                            route=getattr(args, "route_parsed", None))
    except SimulationError as exc:
        if "budget" in str(exc) and "wall" in str(exc):  # say which option raises it
            raise SimulationError(f"{exc} (--wall-budget {args.wall_budget:g} s; raise it, or 'inf')") from None
        raise
    finally:
        terminal.end_status()  # a run that ended before its t_end (steady, a route's end) leaves it standing


def _estimate_text(run: RunResult) -> str:
    """What a run that did not become steady still says of its speed (the summary's speed_estimate keys)."""
    s = run.summary
    if s.get("speed_estimate_m_s") is None:
        return ""
    mean, spread = s["speed_estimate_m_s"], s["speed_estimate_uncertainty_m_s"]
    return (f"; its last {s['speed_estimate_revolutions']} revolutions average {significant(mean, 5)} "
            f"+- {significant(spread, 2)} m/s ({100 * spread / mean:.2g} %; steady asks "
            f"{100 * run.steady_target:.2g} %)")


def _number(value) -> str:
    """A figure as the text summary shows it: n/a where it has no value (a check that could not run)."""
    return "n/a" if value is None else f"{value:.3g}"


def format_summary(run: RunResult, until_steady: bool = False) -> str:
    """The human-readable summary ``simulate`` prints (``until_steady``: the run was asked to stop there)."""
    s = run.summary
    e = s["energy"]
    first = s["first_contraction_end_s"]
    reaction = s["min_clutch_reaction_n"]
    along = " along the route" if "route_done" in s else ""
    lines = [
        f"{run.engine} engine, {run.geometry} geometry, {run.clutch} clutches, {run.t_end:g} s "
        f"({run.wall_time_s:.2f} s wall)",
        f"  drive                    {drive_text(run.params)}",
        f"  crank revolutions        {s['revolutions']:.4f}",
        f"  module 1 (rear) moved    {fixed(s['x1_final'], 4)} m{along}   peak speed {fixed(s['v1_max'], 3)} m/s",
        f"  module 2 (front) moved   {fixed(s['x2_final'], 4)} m{along}   peak speed {fixed(s['v2_max'], 3)} m/s",
        "  first minimum of S       " + ("none" if first is None else f"{first:.4f} s"),
        f"  mode switches            {s['mode_switches']}",
        "  min clutch reaction      " + ("none (no clutch held)" if reaction is None else f"{reaction:.4g} N"
                                       + ("   (negative: the lock would have to pull)" if reaction < 0 else "")),
        "  energy [J]: " + _energy_line(e),
    ]
    if s["steady"]:
        lines.append(f"  steady state from {s['t_steady_s']:.3f} s: {significant(s['steady_speed_m_s'], 5)} m/s, "
                     f"{significant(s['distance_per_rev_m'], 5)} m per revolution, "
                     f"{significant(s['energy_per_metre_j_m'], 5)} J/m, efficiency {significant(s['efficiency'], 5)}")
    elif until_steady:
        lines.append(f"  steady state            not reached by {run.t_end:g} s" + _estimate_text(run))
    if s["mean_omega_rad_s"] is not None:
        over = "over the steady revolutions" if s["steady"] else "over the run"
        drive = "" if s["peak_drive_u"] is None else (f", peak torque {significant(s['peak_motor_torque_n_m'], 4)} "
                                                      f"N m, peak |u| {significant(s['peak_drive_u'], 4)}")
        ripple = "n/a" if s["speed_ripple"] is None else significant(s["speed_ripple"], 4)
        lines.append(f"  crank speed {over}: mean {significant(s['mean_omega_rad_s'], 6)} rad/s, "
                     f"ripple {ripple}{drive}")
    if run.params.grip is not None:
        use = s.get("peak_grip_use")
        lines.append(f"  wheels' grip {run.params.grip[0]:.4g} N / {run.params.grip[1]:.4g} N: skidded back "
                     f"{fixed(s['slip1_m'], 4)} m (rear), {fixed(s['slip2_m'], 4)} m (front); peak clutch load "
                     + ("none" if use is None else f"{use:.3g} of the grip"))
    if "press1_n" in s:  # the wheeled model: the wall's closed-form checks beside MuJoCo's outcome
        lines += wall_lines(s, run.params)
    if s["stalled"]:
        lines.append(f"  stalled: {s['stall_reason']}")
    if "route_done" in s:
        lines += route_lines(s)
    accuracy = s.get("accuracy") or {}
    if "loop_gap_m" in accuracy:
        lines.append(accuracy_line(accuracy))
    if accuracy.get("rigid_limit") == "extrapolated":  # the slides on finite grip: each figure's rigid limit
        lines += rigid_limit_lines(run)
    if accuracy.get("skid_check") in ("verified", "failed"):  # the run kept is the skid check's finest
        last = (run.settings.get("skid_check") or [{}])[-1]
        error = accuracy.get("skid_difference")
        lines.append(f"  skid check {accuracy['skid_check']}: the run at timestep {run.settings['timestep']:.3g} s "
                     f"({sum(bool(h.get('differences')) for h in run.settings.get('skid_check') or [])} halvings); "
                     "largest estimated error "
                     f"{last.get('figure')} " + ("n/a" if error is None else f"{error:.2g}")
                     + f" of it, its accuracy {accuracy['tolerances']['skid_difference']:.2g}")
        lines += [f"  skid check failed: {v['reason']}" for v in accuracy.get("violations", [])
                  if v.get("figure") == "skid_difference" and v.get("reason")]
    return "\n".join(lines)


# the accuracy monitor's figures in words (engine/loop/monitor.py), for the summary's accuracy line
FIGURE_WORDS = {"residual_ratio": ("energy residual", "of the energy put through"),
                "loop_gap_m": ("loop gap", "m"), "excursion_m": ("ratchet excursion", "m")}


def accuracy_line(accuracy: dict) -> str:
    """The MuJoCo monitor's record in one story: each figure's largest value over the run and when (its
    tolerance beside it), and for a figure past its tolerance when it first crossed it (with 'warn' the run went
    on, and the largest is what it reached)."""
    tolerances, at = accuracy.get("tolerances", {}), accuracy.get("worst_at_s", {})
    parts = []
    for key in ("residual_ratio", "loop_gap_m"):
        name, unit = FIGURE_WORDS[key]
        tol = tolerances.get(key)
        part = f"{name} at most {abs(accuracy[key]):.2g} {unit}" + (f" (at t={at[key]:.4g} s)" if key in at else "")
        parts.append(part + (f", tolerance {tol:.2g}" if tol is not None else ""))
    line = "  accuracy: " + "; ".join(parts)
    crossed = accuracy.get("violations") or []
    if not accuracy.get("ok", True) and crossed:
        line += "\n  OUT OF TOLERANCE: " + "; ".join(
            f"{FIGURE_WORDS.get(v['figure'], (v['figure'],))[0]} first past its {v['tolerance']:.2g} at "
            f"t={v['t_s']:.4g} s ({abs(v['value']):.3g} there)" for v in crossed)
    return line


def drive_text(params) -> str:
    """What turns the crank, in words with the parameters it acts through (core.drive_fields.DRIVE_FIELDS)."""
    motor = f"M_stall {params.M_stall:g} N m, no-load {params.omega_noload:g} rad/s"
    if params.drive == "torque":
        return f"constant torque M {params.M:g} N m (the paper's)"
    if params.drive == "motor":
        return f"DC gearmotor at full voltage, {motor}"
    return f"speed controller holding {params.omega_target:g} rad/s, gearmotor {motor}"


def rigid_limit_lines(run) -> list[str]:
    """The rigid limit in words: each figure with its error, accepted (within the stated accuracy) or not, the
    measured order, and the runs it was extrapolated from."""
    s, record, extrapolation = run.summary, run.accuracy, run.settings["extrapolation"]
    used = [r for r in extrapolation["runs"] if "failed" not in r and r["timestep_s"] in extrapolation["used"]]
    runs = ", ".join(f"{r['time_constant_s']:.3g} s at {r['timestep_s']:.3g} s" for r in used)
    lines = [f"  rigid limit ({extrapolation['plan']}), from runs with the grip rows' time constant and step {runs}:"]
    for key, error in s["figure_errors"].items():
        order = extrapolation["order"].get(key)
        verdict = "accepted" if record["figures_accepted"][key] else "NOT within the stated accuracy"
        lines.append(f"    {key} {significant(s[key], 7)} +- {error:.2g} ({record['figure_relative_errors'][key]:.2g} "
                     f"of it, {verdict}; measured order " + ("n/a" if order is None else f"{order:.2f}") + ")")
    return lines


def wall_lines(s: dict, params) -> list[str]:
    """The wheels on their wall in words: MuJoCo's press and the grip it makes beside the equations' mu_wall F_ni,
    wheels off and rings' slide across the pipe, each beside its closed-form check (lift-off: the least-pressed
    leg's press; sideways grip: the largest ring load over what the ring holds across the pipe, none with
    unlimited grip), and what happened with no prediction."""
    lift = "a wheel lifts" if s["lift_predicted"] else "no wheel lifts"
    grip = "" if s.get("grip1_n") is None else (
        f"; grip {s['grip1_n']:.4g} N / {s['grip2_n']:.4g} N (mu_wall x press; the equations' mu_wall F_n "
        f"{params.mu_wall * params.F_n1:.4g} N / {params.mu_wall * params.F_n2:.4g} N)")
    lines = [f"  wall press {s['press1_n']:.4g} N / {s['press2_n']:.4g} N (mean){grip}",
             f"  a wheel off its wall {s['wheel_off_s']:.3f} s; lift-off check: least-pressed leg "
             f"{s['least_press1_n']:.3g} N / {s['least_press2_n']:.3g} N ({lift})"]
    if "side_use1" in s:  # the sideways check; in a straight pipe beside the rings' slide across it
        if params.mu_wall is None:
            check = "unlimited grip: the wheels hold across the pipe"
        else:
            check = (f"sideways-grip check {_ratio(s['side_use1'])} / {_ratio(s['side_use2'])} ("
                     + ("a slide predicted" if s["scrub_predicted"] else "held")
                     + "; a module that skids or lifts a wheel holds nothing across)")
        if "across1_m" in s:
            lines.append(f"  rings moved across the pipe {1e3 * s['across1_m']:.3g} mm / "
                         f"{1e3 * s['across2_m']:.3g} mm" + (" (slid: the wheels scrubbed)" if s["scrubbed"] else "")
                         + f"; {check}")
        else:  # along a route the wheels' own slide is the outcome (route_compare's slid_m)
            lines.append(f"  {check}")
    if s.get("unpredicted"):
        lines.append(f"  not predicted: {s['unpredicted']}")
    return lines


def _ratio(value) -> str:
    """A check's ratio in the text: 'unbounded' where it is (no grip at all against a load: inf, null in JSON)."""
    return "unbounded" if value is None or value == float("inf") else f"{value:.3g}"


def route_lines(s: dict) -> list[str]:
    """A run along a route in words: done or not and why, the closed-form fit beside it."""
    done = (f"route done in {s['route_time_s']:.4f} s" if s["route_done"] else
            f"route NOT done: {s['route_s_m']:.3f} of {s['route_length_m']:.3f} m")
    lines = [f"  {done}: {s['route_stop']}"]
    if s.get("route_wall_loss") is not None:  # MuJoCo's wheels (the equations' stay on their walls)
        lines.append(f"  wheels off their walls {s['route_wheel_off_s']:.3f} s in all (a whole module "
                     f"{s['route_module_off_s']:.3f} s); first: {s['route_wall_loss']}")
    if "route_fit" in s:
        lines.append(f"  closed-form fit: {s['route_fit']['predicted']}")
    return lines


def _energy_line(e: dict) -> str:
    """input = each other term of core.energy's table the run has, in the table's order (kinetic, friction,
    potential, clutch springs and dampers, skid) + residual; a term within round-off of zero (1e-12 of the input:
    a horizontal run's potential, a clutch damper of zero damping) is left out."""
    inputs = [term for term in energy.all_terms() if term.role == INPUT and term.audit_key in e]
    put_in = sum(e[term.audit_key] for term in inputs)
    negligible = 1e-12 * abs(put_in)
    terms = [f"{term.name} {e[term.audit_key]:.6g}" for term in energy.all_terms()
             if term.role != INPUT and term.audit_key in e and abs(e[term.audit_key]) > negligible]
    left = " + ".join(f"{term.name} {e[term.audit_key]:.6g}" for term in inputs)
    return f"{left} = " + " + ".join([*terms, f"residual {e[RESIDUAL_KEY]:.2e}"])


def save_run_mjcf(args: argparse.Namespace) -> None:
    """--save-mjcf FILE.xml: the model the run compiles (:func:`ipir_mujoco.engine.run.export.save_mjcf`), written
    before the run; refused in one line for the equations or a name that is not an .xml file."""
    from ipir_mujoco.engine.run.export import save_mjcf

    variant = registry.from_flags(args.engine, args.geometry, args.clutch, args.mujoco_clutch, args.mujoco_model)
    if not variant.is_mujoco:
        raise ParameterError(f"--save-mjcf {args.save_mjcf}: the analytic engines have no MJCF; allowed: with "
                             "--engine mujoco")
    if not str(args.save_mjcf).endswith(".xml"):
        raise ParameterError(f"--save-mjcf {args.save_mjcf!r} is not an .xml file name; allowed: FILE.xml")
    settings = None
    if args.timestep is not None:
        from ipir_mujoco.engine import SolverSettings

        settings = SolverSettings(timestep=args.timestep)
    save_mjcf(args.save_mjcf, model_params(args), variant.rule, variant.clutch, model=variant.model,
              t_end=args.t_end, dt_out=args.dt_out, settings=settings, mjcf=args.mjcf,
              route=getattr(args, "route_parsed", None))
    if not args.json:
        print(f"  wrote {args.save_mjcf}: the compiled model of this run (its header says what runs between steps)")


def run(args: argparse.Namespace) -> int:
    from ipir_mujoco.core.results import json_text, write_json, write_mode_changes

    from ..output import check_output_dir, staged_output

    check_options(args)
    # bad parameters are reported before the output folder is looked at
    refuse_steady_without_motor(model_params(args).drive, args.until_steady)
    if args.out is not None:
        check_output_dir(args.out, files=("timeseries.csv", "mode_changes.csv", "summary.json", *FIGURES))
    if args.save_mjcf is not None:
        save_run_mjcf(args)
    result = run_simulation(args)
    record = result.to_json_dict()
    if record["summary"].get("unpredicted"):  # the round pipe's checks did not foresee what happened: one line
        print(f"ipir-mujoco simulate: note: {record['summary']['unpredicted']}", file=sys.stderr)
    if args.out is not None:
        from ..core.figures import write_paper_figures  # matplotlib: only where figures are written

        with staged_output(args.out) as staging:
            result.write_csv(staging / "timeseries.csv")
            write_mode_changes(staging / "mode_changes.csv", result.series)
            write_json(staging / "summary.json", record)
            write_paper_figures([result], staging)
    if args.json:
        print(json_text(record))
    else:
        print(format_summary(result, args.until_steady))
        if args.out is not None:
            print(f"  wrote {files_line(args.out, 'timeseries.csv', 'mode_changes.csv', 'summary.json', *FIGURES)}")
    return EXIT_OK
