"""Command line: ``ipir-mujoco`` (see ``shared/CONTRACT.md``).

Exit status: 0 success, 2 bad input (one line on stderr naming the value and
what is allowed), 1 a failure of the simulation itself (with the reason).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Sequence

from ipir_mujoco import analytic
from ipir_mujoco.analytic.errors import ParameterError, SimulationError
from ipir_mujoco.analytic.params import PARAMETER_NAMES, load_params
from ipir_mujoco.analytic.results import RunResult, write_json, write_mode_changes

from .. import __version__
from ..output import check_output_dir, staged_output
from ..report.plots import write_paper_figures

EXIT_OK, EXIT_FAILURE, EXIT_BAD_INPUT = 0, 1, 2


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error message and exit status 2."""

    def error(self, message: str):  # noqa: D102 (argparse API)
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see --help)\n")


def _add_model_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE",
                        help=f"set a parameter (SI units); names: {' '.join(PARAMETER_NAMES)}")
    parser.add_argument("--config", metavar="FILE.toml",
                        help="TOML file of parameters (top level or a [params] table); --set wins over it")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="ipir-mujoco",
                     description="Cross-check the analytic model of a two-module inchworm in-pipe robot "
                                 "against MuJoCo physics.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    sim = commands.add_parser("simulate", help="run one engine on one parameter set",
                              description="Run one engine on one parameter set and print or write its results. "
                                          "Defaults: the paper's model and case for 1 s.")
    sim.add_argument("--engine", choices=("analytic", "mujoco"), default="analytic",
                     help="analytic equations or MuJoCo physics (default: analytic)")
    sim.add_argument("--geometry", choices=("approx", "exact"), default=None,
                     help="first-order kinematics as in the paper (approx; analytic default) or the exact "
                          "slider-crank (exact; MuJoCo always models it)")
    sim.add_argument("--clutch", choices=analytic.CLUTCH_RULES, default="kinematic",
                     help="kinematic: the paper's rule, lock by the sign of S_dot (default); "
                          "unilateral: one-way clutches that can only push")
    sim.add_argument("--mujoco-clutch", choices=("ratchet", "lock"), default=None,
                     help="MuJoCo clutch implementation: joint-limit ratchet (default with --clutch unilateral) "
                          "or velocity-triggered lock (default with --clutch kinematic)")
    sim.add_argument("--timestep", type=float, default=None, metavar="SECONDS",
                     help="MuJoCo timestep (default 1e-4 s, converged for the paper's case; see mjcf/README.md)")
    sim.add_argument("--mjcf", metavar="FILE.xml", default=None,
                     help="MJCF template for --engine mujoco (default: the shipped mjcf/inchworm.xml)")
    _add_model_options(sim)
    sim.add_argument("--t-end", type=float, default=1.0, metavar="SECONDS", help="simulated time (default 1 s)")
    sim.add_argument("--dt-out", type=float, default=1e-4, metavar="SECONDS",
                     help="output sample interval (default 1e-4 s); mode switches are sampled exactly")
    sim.add_argument("--out", metavar="DIR",
                     help="write DIR/timeseries.csv, DIR/mode_changes.csv (time and crank angle of each mode "
                          "change), DIR/summary.json and the paper's figures as PNG")
    sim.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    sim.set_defaults(handler=cmd_simulate)

    kin = commands.add_parser("kinetostatics", help="torque and forces a prescribed crank motion needs",
                              description="Inverse kinetostatics: prescribe the crank's motion (a constant speed, "
                                          "or samples of phi(t)) and get the motor torque, clutch reactions and "
                                          "rod force it needs, as CSV and a plot against crank angle.")
    source = kin.add_mutually_exclusive_group(required=True)
    source.add_argument("--omega", type=float, metavar="RAD_S", help="constant crank speed [rad/s]")
    source.add_argument("--samples", metavar="FILE.csv",
                        help="CSV with columns t (s, from 0, increasing) and phi (rad); a cubic spline goes through them")
    kin.add_argument("--revolutions", type=float, default=2.0, help="turns at constant speed (default 2)")
    kin.add_argument("--geometry", choices=("approx", "exact"), default="exact", help="default: exact")
    kin.add_argument("--clutch", choices=analytic.CLUTCH_RULES, default="kinematic",
                     help="kinematic (the paper's rule, default) or unilateral (one-way clutches)")
    _add_model_options(kin)
    kin.add_argument("--out", metavar="DIR", default="kinetostatics",
                     help="writes DIR/kinetostatics.csv and DIR/kinetostatics.png (default ./kinetostatics)")
    kin.set_defaults(handler=cmd_kinetostatics)

    cmp_ = commands.add_parser("compare", help="compare two runs written by 'simulate --out'",
                               description="Compare run B against run A: summary figures, RMS and largest "
                                           "differences at matching time and at matching crank angle, mode "
                                           "switches matched one by one, and when a tolerance is first exceeded.")
    cmp_.add_argument("run_a", metavar="RUN_A", help="reference run folder")
    cmp_.add_argument("run_b", metavar="RUN_B", help="run folder compared against it")
    cmp_.add_argument("--tolerance", type=float, default=0.01,
                      help="relative tolerance for 'first exceeded' (fraction of each quantity's scale; default 0.01)")
    cmp_.add_argument("--json", action="store_true", help="print the comparison as one JSON object")
    cmp_.set_defaults(handler=cmd_compare)

    swp = commands.add_parser("sweep", help="geometry what-if studies over many designs",
                              description="Vary parameters over a grid, a list or a space-filling sample; run the "
                                          "chosen engines on every design; stream the results to DIR/results.csv "
                                          "and draw them. Ctrl-C keeps what is done; --resume completes it.")
    swp.add_argument("--vary", action="append", default=[], metavar="NAME=SPEC",
                     help="NAME=START:STOP:N[:log] (grid), NAME=A,B,C (list) or NAME=LO:HI[:log] (with --sample)")
    swp.add_argument("--sample", type=int, default=None, metavar="N", help="N space-filling (Sobol) designs")
    swp.add_argument("--seed", type=int, default=None, help="seed of the Sobol sample (default 0)")
    swp.add_argument("--engines", default=None, metavar="LIST",
                     help="comma-separated, first one is the reference for divergence; from: analytic-approx, "
                          "analytic-exact, analytic-unilateral, mujoco-lock, mujoco-ratchet "
                          "(default: mujoco-ratchet,analytic-unilateral)")
    swp.add_argument("--t-end", type=float, default=None, metavar="SECONDS", help="simulated time per design (default 1 s)")
    swp.add_argument("--study", metavar="FILE.toml", help="study file ([sweep] and [params] tables); options win over it")
    _add_model_options(swp)
    swp.add_argument("--out", metavar="DIR", default="sweep", help="results folder (default ./sweep)")
    swp.add_argument("--resume", action="store_true", help="complete an interrupted sweep in DIR")
    swp.add_argument("--workers", type=int, default=None, help="processes/threads to use (default: all cores)")
    swp.add_argument("--no-batch", action="store_true", help="run MuJoCo designs one by one, not through mujoco.batch")
    swp.add_argument("--scheduler", metavar="ADDRESS",
                     help="run on a Dask distributed scheduler (needs the 'dask' extra), e.g. tcp://host:8786")
    swp.set_defaults(handler=cmd_sweep)

    val = commands.add_parser("validate", help="the analytic-vs-physics validation report (the main job)",
                              description="Run the model ladder at the paper's case and write a report: "
                                          "DIR/index.html, DIR/report.md, DIR/metrics.json, DIR/figures/.")
    val.add_argument("--out", metavar="DIR", default="report", help="report folder (default: ./report)")
    _add_model_options(val)
    val.add_argument("--quick", action="store_true", help="reduced version for tests and CI (coarser output)")
    val.set_defaults(handler=cmd_validate)
    return parser


def run_simulation(args: argparse.Namespace) -> RunResult:
    """The run ``simulate`` asks for (raises ParameterError on bad input)."""
    params = load_params(args.config, args.overrides)
    if args.engine == "mujoco":
        if args.geometry == "approx":
            raise ParameterError("--geometry approx with --engine mujoco: MuJoCo always models the real "
                                 "linkage; allowed: --geometry exact (or leave it out)")
        from ..engine import simulate_mujoco
        from ..engine.model import SolverSettings

        implementation = args.mujoco_clutch or ("lock" if args.clutch == "kinematic" else "ratchet")
        settings = SolverSettings() if args.timestep is None else SolverSettings(timestep=args.timestep)
        progress = _progress_printer(args.t_end) if not args.json else None
        return simulate_mujoco(params, args.clutch, implementation, args.t_end, dt_out=args.dt_out,
                               settings=settings, mjcf=args.mjcf, progress=progress)
    for option, value in (("--mjcf", args.mjcf), ("--timestep", args.timestep)):
        if value is not None:
            raise ParameterError(f"{option} {value} applies only to --engine mujoco")
    if args.mujoco_clutch is not None:
        raise ParameterError(f"--mujoco-clutch {args.mujoco_clutch} applies only to --engine mujoco")
    return analytic.simulate(params, args.geometry or "approx", args.clutch, args.t_end, dt_out=args.dt_out)


def _progress_printer(t_end: float):
    """Progress on stderr for runs long enough to wait for (simulated time > 2 s)."""
    if t_end <= 2.0:
        return None

    if sys.stderr.isatty():
        def report(t: float) -> None:
            print(f"\rsimulated {t:6.2f} / {t_end:g} s", end="" if t < t_end - 0.05 else "\n",
                  file=sys.stderr, flush=True)
        return report

    milestones = iter([t_end * k / 10 for k in range(1, 11)])
    state = {"next": next(milestones)}

    def report_lines(t: float) -> None:  # a log file gets one line per tenth of the run
        if t >= state["next"] - 1e-9:
            print(f"simulated {t:.2f} / {t_end:g} s", file=sys.stderr, flush=True)
            state["next"] = next(milestones, float("inf"))

    return report_lines


def _format_summary(run: RunResult) -> str:
    s = run.summary
    e = s["energy"]
    first = s["first_contraction_end_s"]
    lines = [
        f"{run.engine} engine, {run.geometry} geometry, {run.clutch} clutches, {run.t_end:g} s "
        f"({run.wall_time_s:.2f} s wall)",
        f"  crank revolutions        {s['revolutions']:.4f}",
        f"  module 1 (rear) moved    {s['x1_final']:.4f} m   peak speed {s['v1_max']:.3f} m/s",
        f"  module 2 (front) moved   {s['x2_final']:.4f} m   peak speed {s['v2_max']:.3f} m/s",
        "  first minimum of S       " + ("none" if first is None else f"{first:.4f} s"),
        f"  mode switches            {s['mode_switches']}",
        f"  min clutch reaction      {s['min_clutch_reaction_n']:.4g} N"
        + ("   (negative: the lock would have to pull)" if (s['min_clutch_reaction_n'] or 0) < 0 else ""),
        f"  energy [J]: motor {e['motor_work_j']:.6g} = kinetic {e['kinetic_j']:.6g} "
        f"+ friction {e['friction_j']:.6g} + residual {e['residual_j']:.2e}",
    ]
    return "\n".join(lines)


def cmd_simulate(args: argparse.Namespace) -> int:
    if args.out is not None:
        check_output_dir(args.out)
    run = run_simulation(args)
    record = run.to_json_dict()
    if args.out is not None:
        with staged_output(args.out) as staging:
            run.write_csv(staging / "timeseries.csv")
            write_mode_changes(staging / "mode_changes.csv", run.series)
            write_json(staging / "summary.json", record)
            write_paper_figures([run], staging)
    if args.json:
        print(json.dumps(record, allow_nan=False))
    else:
        print(_format_summary(run))
        if args.out is not None:
            print(f"  wrote {args.out}/timeseries.csv, mode_changes.csv, summary.json and fig2-4 PNG")
    return EXIT_OK


def _read_crank_samples(path: str):
    import numpy as np

    try:
        table = np.genfromtxt(path, delimiter=",", names=True)
    except OSError:
        raise ParameterError(f"--samples {path!r} cannot be read (does it exist?)") from None
    names = table.dtype.names or ()
    if "t" not in names or "phi" not in names:
        raise ParameterError(f"--samples {path!r} needs a header row with columns t and phi; found {list(names)}")
    return np.atleast_1d(table["t"]), np.atleast_1d(table["phi"])


def cmd_kinetostatics(args: argparse.Namespace) -> int:
    from ipir_mujoco.analytic.inverse import CrankMotion, inverse_kinetostatics

    from ..report.plots import figure_kinetostatics

    check_output_dir(args.out)
    params = load_params(args.config, args.overrides)
    if args.omega is not None:
        motion = CrankMotion.constant_speed(args.omega, params.phi0, args.revolutions)
    else:
        motion = CrankMotion.from_samples(*_read_crank_samples(args.samples))
    run = inverse_kinetostatics(params, motion, args.geometry, args.clutch)
    s = run.series
    with staged_output(args.out) as staging:
        run.write_csv(staging / "kinetostatics.csv")
        write_json(staging / "summary.json", run.to_json_dict())
        figure_kinetostatics(run).savefig(staging / "kinetostatics.png", dpi=120)
    print(f"{motion.description}, {args.clutch} clutches, {args.geometry} geometry, {run.t_end:.4g} s")
    print(f"  motor torque     {s['motor_torque'].min():+.4g} .. {s['motor_torque'].max():+.4g} N m "
          f"(mean power {run.summary['energy']['motor_work_j'] / run.t_end:.4g} W)")
    print(f"  clutch reactions rear {s['lambda1'].min():+.4g} .. {s['lambda1'].max():+.4g} N, "
          f"front {s['lambda2'].min():+.4g} .. {s['lambda2'].max():+.4g} N")
    print(f"  rod force        {s['rod_force'].min():+.4g} .. {s['rod_force'].max():+.4g} N (tension > 0)")
    print(f"  wrote {args.out}/kinetostatics.csv, kinetostatics.png, summary.json")
    return EXIT_OK


def cmd_compare(args: argparse.Namespace) -> int:
    from ..studies.compare import compare_runs, format_comparison, load_run

    result = compare_runs(load_run(args.run_a), load_run(args.run_b), tolerance=args.tolerance)
    print(json.dumps(result, allow_nan=False) if args.json else format_comparison(result))
    return EXIT_OK


def cmd_sweep(args: argparse.Namespace) -> int:
    from ..studies.sweep import SweepInterrupted, run_sweep
    from ..report.sweep_plots import best_designs, plot_sweep, read_results
    from ..studies.sweep_space import Study, parse_vary, read_study

    base = load_params(args.config, args.overrides)
    options = read_study(args.study, base) if args.study else {"base": base}
    if args.vary:
        options["axes"] = tuple(parse_vary(v) for v in args.vary)
    if args.engines:
        options["engines"] = tuple(e.strip() for e in args.engines.split(",") if e.strip())
    for key in ("sample", "seed", "t_end"):  # options given on the command line win over the study file
        if getattr(args, key) is not None:
            options[key] = getattr(args, key)
    options.setdefault("axes", ())
    study = Study(**options)
    if args.workers is not None and args.workers < 1:
        raise ParameterError(f"--workers {args.workers} is out of range; allowed: >= 1")
    client = None
    if args.scheduler:
        try:
            from distributed import Client
        except ImportError:
            raise ParameterError("--scheduler needs Dask: pip install 'ipir-mujoco[dask]'") from None
        try:
            client = Client(args.scheduler, timeout="20s")
        except (OSError, TimeoutError) as exc:
            raise ParameterError(f"--scheduler {args.scheduler!r} cannot be reached: {exc}") from None
    try:
        results = run_sweep(study, args.out, executor=client.get_executor() if client else None,
                            batch_mujoco=not args.no_batch, resume=args.resume, workers=args.workers)
    except SweepInterrupted as exc:
        print(f"ipir-mujoco sweep: {exc}", file=sys.stderr)
        return 130
    finally:
        if client is not None:
            client.close()
    axes = [a.name for a in study.axes]
    figures = plot_sweep(results, axes, list(study.engines), args.out)
    best = best_designs(read_results(results), axes, list(study.engines))
    write_json(Path(args.out) / "best.json", {"best": best})
    columns = read_results(results)
    failed = sum(bool(e) for e in columns["error"])
    print(f"{len(columns['design_id'])} designs, {failed} failed; results in {results}")
    for item in best:
        where = ", ".join(f"{a}={item[a]:.4g}" for a in axes)
        print(f"  best {item['metric']:24s} {item['engine']:20s} {item['value']:.4g} at {where}")
    print(f"  figures: {', '.join(str(f) for f in figures)}; best designs: {args.out}/best.json")
    return EXIT_OK


def cmd_validate(args: argparse.Namespace) -> int:
    from ..report.validation import write_report
    from ..studies.validate import validate

    check_output_dir(args.out)
    params = load_params(args.config, args.overrides)

    def progress(message: str) -> None:
        print(f"validate: {message}", file=sys.stderr, flush=True)

    metrics, rungs = validate(params, quick=args.quick, progress=progress)
    progress("writing report ...")
    with staged_output(args.out) as staging:
        write_json(staging / "metrics.json", metrics)
        write_report(staging, metrics, rungs)
    for verdict in metrics["verdicts"]:
        print(f"{verdict['question']}\n  {verdict['answer']}")
    print(f"report: {args.out}/index.html (also report.md, metrics.json, figures/)")
    return EXIT_OK


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.handler(args)
    except ParameterError as exc:
        print(f"ipir-mujoco {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except SimulationError as exc:
        print(f"ipir-mujoco {args.command}: simulation failed: {exc}", file=sys.stderr)
        return EXIT_FAILURE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
