"""``ipir-mujoco render``: a video (GIF or MP4) of a MuJoCo run, rendered headless."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ipir_mujoco import registry, terminal
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.limits import DEFAULT_WALL_BUDGET_S

from .common import EXIT_OK, add_model_options, check_input_file, model_params, progress_printer, tenths_printer
from .simulate import T_END, T_END_ROUTE


def add_parser(commands) -> None:
    ren = commands.add_parser("render", help="a video of a MuJoCo run (GIF, or MP4 with the 'video' extra)",
                              description="Run MuJoCo on one parameter set and write a video of it, rendered "
                                          "offscreen by MuJoCo (needs EGL or OSMesa, no screen): the modules, "
                                          "crank and rod, each clutch's state by its module's colour (green: "
                                          "holds) and the time, playback speed and speeds as text.")
    ren.add_argument("--out", metavar="FILE", default="inchworm.gif",
                     help="video file, .gif (default inchworm.gif) or .mp4 (pip install 'ipir-mujoco[video]')")
    ren.add_argument("--clutch", choices=registry.RULES, default="unilateral",
                     help="unilateral: one-way clutches (default); kinematic: the paper's rule (locks)")
    ren.add_argument("--mujoco-clutch", choices=registry.MUJOCO_CLUTCHES, default=None,
                     help="ratchet (default with unilateral) or lock (default with kinematic)")
    ren.add_argument("--mujoco-model", choices=registry.MUJOCO_MODELS, default="slides",
                     help="MuJoCo's model: slides (default) or wheels (the robot on wheels in its pipe, walls and "
                          "wheels drawn)")
    ren.add_argument("--route", metavar="FILE.toml", default=None,
                     help="with --mujoco-model wheels: the robot along a route of straights and bends (docs/cli.md), "
                          "its walls drawn, seen from above; the run ends at the route's end (--t-end caps it)")
    ren.add_argument("--t-end", type=float, default=None, metavar="SECONDS",
                     help="simulated time (default 1 s; with --route the cap, default 60 s)")
    ren.add_argument("--speed", type=float, default=0.1,
                     help="playback speed, video seconds per simulated second (default 0.1: ten times slower)")
    ren.add_argument("--fps", type=float, default=25.0, help="frames per second of the video (default 25)")
    ren.add_argument("--width", type=int, default=640, help="frame width in pixels, even (default 640)")
    ren.add_argument("--height", type=int, default=360, help="frame height in pixels, even (default 360)")
    ren.add_argument("--wall-budget", type=float, default=DEFAULT_WALL_BUDGET_S, metavar="SECONDS",
                     help=f"stop the run with an error after SECONDS of wall time, its accuracy checks' repeats "
                          f"included (default {DEFAULT_WALL_BUDGET_S:g} s; 'inf' for no limit), as simulate's")
    add_model_options(ren)
    ren.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ..output import check_output_dir
    from ..video import VideoSettings, check_writer, gl_backend, write_video

    settings = VideoSettings(width=args.width, height=args.height, fps=args.fps, speed=args.speed)
    out = Path(args.out)
    # before any work, and before MuJoCo is imported (MUJOCO_GL naming a missing library breaks that import):
    # the suffix and its writer, the route, the OpenGL library, the output path, the parameters
    check_writer(out)
    route = None
    if args.route is not None:
        registry.check_route_flag(args.route, args.mujoco_model)
        from ipir_mujoco.core.route import read_route

        check_input_file("--route", args.route)
        route = read_route(args.route)
    gl_backend()
    if out.is_dir():
        raise ParameterError(f"--out {str(out)!r} is a folder; give a video file name (.gif or .mp4)")
    check_output_dir(out.parent)  # a folder that cannot be written is refused now, not after every frame
    if not args.wall_budget > 0:  # nan and <= 0; inf is no limit
        raise ParameterError(f"--wall-budget {args.wall_budget:g} is out of range; allowed: a number of seconds "
                             "> 0, or inf (no limit)")
    params = model_params(args)
    variant = registry.from_flags("mujoco", None, args.clutch, args.mujoco_clutch, args.mujoco_model)
    t_end = args.t_end if args.t_end is not None else T_END_ROUTE if route is not None else T_END
    options = {} if route is None else {"route": route}  # the wheeled model's accuracy monitor warns by default
    until = " (or to the route's end)" if route is not None else ""
    report, said = progress_printer(t_end), []

    def progress(t: float | None = None) -> None:  # the line once the run steps (every check of its input passed
        if not said:  # by then), or after a run too short to report any step
            said.append(t)
            print(f"simulating {t_end:g} s in MuJoCo{until} ...", file=sys.stderr, flush=True)
        if report is not None and t is not None:
            report(t)
    try:
        result = registry.run(variant, params, t_end, progress=progress, wall_budget_s=args.wall_budget, **options)
        progress()
    finally:
        terminal.end_status()  # a run that ended before its t_end (a route's end) leaves it standing
    title = f"MuJoCo, {'one-way clutches' if variant.rule == 'unilateral' else 'the paper' + chr(39) + 's rule'} " \
            f"({variant.mechanism_words})"
    out.parent.mkdir(parents=True, exist_ok=True)
    partial = out.with_name(f".{out.name}.partial{out.suffix}")
    try:
        count = write_video(result, partial, settings, title=title, progress=frame_printer(), route=route)
        partial.replace(out)
    finally:
        partial.unlink(missing_ok=True)
    print(f"wrote {out}: {count} frames of {settings.width} x {settings.height} px at {settings.fps:g} fps, "
          f"{result.t_end:g} s simulated shown in {count / settings.fps:.1f} s ({settings.speed:g}x real time)")
    if route is not None:
        s = result.summary
        print(f"route {'done' if s['route_done'] else 'NOT done'}: {s['route_stop']}")
    return EXIT_OK


def frame_printer():
    """Progress of the rendering on stderr, ``report(done, total)`` (:func:`.common.tenths_printer`)."""
    printers = {}

    def report(done: int, total: int) -> None:
        if total not in printers:
            printers[total] = tenths_printer(total, lambda n: f"rendered {n:.0f} / {total} frames")
        printers[total](done)
    return report
