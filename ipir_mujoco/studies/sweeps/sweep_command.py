"""The sweep study (``ipir-mujoco sweep``): what-if studies over many designs. Its runs: :mod:`.sweep`; its
figures: ``report/sweep_plots.py``."""

from __future__ import annotations

import argparse
from pathlib import Path

from ipir_mujoco.core.errors import ParameterError, SimulationError

from ... import registry
from ...labels import significant
from .sweep_metrics import METRICS, UNITS
from .sweep_space import DEFAULT_VARIANTS, T_END_STEADY
from ..command import add_model_options, add_variant_option, check_input_file, compile_first, model_params
from ..contract import Declaration
from ..design_runs import add_scheduler_option, scheduler_executor


def add_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument("--vary", action="append", default=[], metavar="NAME=SPEC",
                     help="NAME=START:STOP:N[:log] (grid), NAME=A,B,C (list) or NAME=LO:HI[:log] (with --sample)")
    cmd.add_argument("--sample", type=int, default=None, metavar="N", help="N space-filling (Sobol) designs")
    cmd.add_argument("--seed", type=int, default=None, help="seed of the Sobol sample, >= 0 (default 0)")
    add_variant_option(cmd, many=True, default=None,
                       help=f"comma-separated, first one is the reference for divergence; from: "
                            f"{', '.join(registry.NAMES)} (default: {','.join(DEFAULT_VARIANTS)})")
    cmd.add_argument("--t-end", type=float, default=None, metavar="SECONDS",
                     help="simulated time per design (default 1 s); with --until-steady, the cap (default 10 s)")
    cmd.add_argument("--until-steady", action="store_true", default=None,
                     help="run every design to its periodic steady state (--t-end caps it); rows then carry the "
                          "steady speed, time to steady state and energy per metre (use with --drive motor)")
    cmd.add_argument("--timeout-per-design", type=float, default=None, metavar="SECONDS",
                     help="wall-time budget per design (analytic engines and MuJoCo run one by one); a design past "
                          "it is recorded as failed with the reason, never a hang")
    cmd.add_argument("--study", metavar="FILE.toml", help="study file ([sweep] and [params] tables); options win over it")
    add_model_options(cmd)
    cmd.add_argument("--out", metavar="DIR", default="sweep", help="results folder (default ./sweep)")
    cmd.add_argument("--resume", action="store_true", help="complete an interrupted sweep in DIR")
    cmd.add_argument("--workers", type=int, default=None, help="processes/threads to use (default: all cores)")
    cmd.add_argument("--no-batch", action="store_true",
                     help="run MuJoCo designs one by one in the serial engine, never through mujoco.batch (the "
                          "default wherever the serial engine's compiled loop is built)")
    cmd.add_argument("--batch-size", type=int, default=None, metavar="N",
                     help="step the MuJoCo ratchet designs through mujoco.batch, N per chunk (64 where the batch "
                          "is used without this option); rows reach results.csv as chunks finish")
    cmd.add_argument("--plot-metric", default=None, metavar="METRIC",
                     help="metric the heatmap colours (default: steady_speed_m_s with --until-steady, else "
                          "mean_speed_m_s); any of: " + ", ".join(METRICS))
    add_scheduler_option(cmd)


def study_from_args(args: argparse.Namespace):
    """The Study the options describe: defaults, the study file, then the command line (which wins)."""
    from .sweep_space import Study, parse_vary, read_study

    base = model_params(args)
    options = read_study(args.study, base) if args.study else {"base": base}
    if args.vary:
        options["axes"] = tuple(parse_vary(v) for v in args.vary)
    if args.variants is not None:
        names = tuple(e.strip() for e in args.variants.split(",") if e.strip())
        if not names:
            raise ParameterError(f"--variants {args.variants!r} names no variant; allowed: a comma-separated list "
                                 f"from: {', '.join(registry.NAMES)}")
        options["engines"] = names
    for key in ("sample", "seed", "t_end", "until_steady"):  # options given on the command line win over the file
        if getattr(args, key) is not None:
            options[key] = getattr(args, key)
    options.setdefault("axes", ())
    if options.get("until_steady") and "t_end" not in options:
        options["t_end"] = T_END_STEADY  # a run to steady state needs more than the 1 s default
    return Study(**options)


def run(args: argparse.Namespace, figures) -> None:
    from ipir_mujoco.core.results import write_json

    from .sweep import check_sweep_options, run_sweep

    if args.study is not None:
        check_input_file("--study", args.study)
    study = study_from_args(args)
    metric = figures.check_plot_metric(args.plot_metric, study.until_steady)
    check_sweep_options(args.out, args.resume, args.workers, args.timeout_per_design, args.batch_size)
    if args.no_batch and args.batch_size is not None:
        raise ParameterError(f"--batch-size {args.batch_size} with --no-batch: the batch size is for mujoco.batch; "
                             "allowed: one of the two")
    compile_first(study.engines)  # before the pool: compiled once, said at once
    with scheduler_executor(args.scheduler) as executor:
        results = run_sweep(study, args.out, executor=executor, batch_mujoco=False if args.no_batch else None,
                            resume=args.resume, workers=args.workers, timeout_per_design=args.timeout_per_design,
                            batch_size=args.batch_size)
    axes = [a.name for a in study.axes]
    columns = figures.read_results(results)
    errors = [e for e in columns["error"] if e]
    if len(columns["design_id"]) and len(errors) == len(columns["design_id"]):  # nothing to draw or rank
        raise SimulationError(f"every one of the {len(errors)} designs failed, so there is nothing to draw; the "
                              f"first: {' '.join(str(errors[0]).split())} (the rows are in {results})")
    drawn = figures.plot_sweep(results, study, args.out, metric=metric)
    best = figures.best_designs(columns, axes, list(study.engines))
    write_json(Path(args.out) / "best.json",
               {"best": best, "ranking": figures.rankings(columns, axes, list(study.engines))})
    failed = sum(bool(e) for e in columns["error"])
    stalled = sum(any(columns[f"{e}:stalled"][k] == 1 for e in study.engines) for k in range(len(columns["design_id"])))
    print(f"{len(columns['design_id'])} designs, {failed} failed, {stalled} stalled; results in {results}")
    for item in best:
        where = ", ".join(f"{a}={item[a]:.4g}" for a in axes)
        order = "highest" if item["metric"] in figures.LARGER_IS_BETTER else "lowest"
        unit = "" if UNITS[item["metric"]] == "-" else f" {UNITS[item['metric']]}"
        print(f"  best {item['metric']:22s} ({order:7s}) {item['engine']:20s} {significant(item['value'], 4)}{unit} "
              f"at {where}")
    print(f"  figures: {', '.join(str(f) for f in drawn)}; best designs: {args.out}/best.json")


STUDY = Declaration(
    "sweep", "what-if studies: engines over a grid or a sample of designs",
    "Vary parameters over a grid, a list or a space-filling sample; run the chosen engines on every design; stream "
    "the results to DIR/results.csv and draw them. Ctrl-C keeps what is done; --resume completes it.",
    options=add_options, run=run, files=("results.csv", "sweep.json", "best.json"), figures="sweep_plots")
