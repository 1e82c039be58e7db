"""``ipir-mujoco sensitivity``: Sobol indices (S1, ST) of metrics over parameter ranges."""

from __future__ import annotations

import argparse

from ipir_mujoco.core.errors import ParameterError

from .common import EXIT_OK, add_model_options, compile_first, files_line, model_params
from .design_runs import add_design_run_options, add_output_options, design_t_end, scheduler_executor


def add_parser(commands) -> None:
    sen = commands.add_parser("sensitivity", help="Sobol sensitivity indices of metrics over parameter ranges",
                              description="Saltelli-sample the box of --vary ranges (SALib), run every design in one "
                                          "engine on all cores, and give each metric's first-order (S1) and total "
                                          "(ST) Sobol indices with 95 % confidence intervals.")
    sen.add_argument("--vary", action="append", default=[], metavar="NAME=LO:HI", help="a parameter range")
    sen.add_argument("--metric", action="append", default=[], metavar="KEY", help="a sweep metric (several allowed)")
    sen.add_argument("--samples", type=int, default=None, metavar="N",
                     help="Saltelli base samples (designs: N x (parameters + 2); a power of 2; default 64)")
    sen.add_argument("--engine", default=None, help="engine (default analytic-unilateral)")
    add_design_run_options(sen)
    add_model_options(sen)
    add_output_options(sen, "sensitivity", "study")
    sen.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ..report.optimize_plots import plot_indices
    from ..studies.design_eval import check_key
    from ..studies.sensitivity import run_sensitivity
    from ..studies.sweep_space import parse_vary

    if not args.vary:
        raise ParameterError("sensitivity needs at least one --vary NAME=LO:HI")
    axes = tuple(parse_vary(v) for v in args.vary)
    metrics = tuple(check_key(m, f"--metric {m!r}") for m in args.metric)
    compile_first((args.engine or "analytic-unilateral",))  # before the pool: compiled once, said at once
    drawn = []
    with scheduler_executor(args.scheduler) as executor:
        indices = run_sensitivity(axes, metrics, args.out, base=model_params(args),
                                  engine="analytic-unilateral" if args.engine is None else args.engine,
                                  t_end=design_t_end(args),
                                  until_steady=bool(args.until_steady),
                                  samples=64 if args.samples is None else args.samples,
                                  seed=0 if args.seed is None else args.seed, resume=args.resume,
                                  workers=args.workers, executor=executor,
                                  figure=lambda out, found: drawn.append(plot_indices(out, found, list(metrics))))
    figure = drawn[0]
    for i in indices:
        print(f"  {i['metric']:22s} {i['parameter']:12s} S1 {i['S1']:+.3f} +- {i['S1_conf']:.3f}   "
              f"ST {i['ST']:+.3f} +- {i['ST_conf']:.3f}")
    print(f"  files: {files_line(args.out, 'indices.csv', 'sensitivity.json', 'evaluations.csv', figure)}")
    return EXIT_OK
