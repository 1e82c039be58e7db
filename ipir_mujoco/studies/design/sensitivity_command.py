"""The sensitivity study (``ipir-mujoco sensitivity``): Sobol indices (S1, ST) of metrics over parameter ranges.
Its runs: :mod:`.sensitivity`; its figure: ``report/optimize_plots.py``."""

from __future__ import annotations

import argparse

from ipir_mujoco.core.errors import ParameterError

from ..command import add_model_options, add_variant_option, compile_first, files_line, model_params
from ..contract import Declaration
from ..design_runs import add_design_run_options, add_output_options, design_t_end, scheduler_executor


def add_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument("--vary", action="append", default=[], metavar="NAME=LO:HI", help="a parameter range")
    cmd.add_argument("--metric", action="append", default=[], metavar="KEY", help="a sweep metric (several allowed)")
    cmd.add_argument("--samples", type=int, default=None, metavar="N",
                     help="Saltelli base samples (designs: N x (parameters + 2); a power of 2; default 64)")
    add_variant_option(cmd, many=False, default=None, help="the variant run (default analytic-unilateral)")
    add_design_run_options(cmd)
    add_model_options(cmd)
    add_output_options(cmd, "sensitivity", "study")


def run(args: argparse.Namespace, figures) -> None:
    from .design_eval import check_key
    from .sensitivity import run_sensitivity
    from ..sweeps.sweep_space import parse_vary

    if not args.vary:
        raise ParameterError("sensitivity needs at least one --vary NAME=LO:HI")
    axes = tuple(parse_vary(v) for v in args.vary)
    metrics = tuple(check_key(m, f"--metric {m!r}") for m in args.metric)
    compile_first((args.variant or "analytic-unilateral",))  # before the pool: compiled once, said at once
    drawn = []
    with scheduler_executor(args.scheduler) as executor:
        indices = run_sensitivity(axes, metrics, args.out, base=model_params(args),
                                  engine="analytic-unilateral" if args.variant is None else args.variant,
                                  t_end=design_t_end(args),
                                  until_steady=bool(args.until_steady),
                                  samples=64 if args.samples is None else args.samples,
                                  seed=0 if args.seed is None else args.seed, resume=args.resume,
                                  workers=args.workers, executor=executor,
                                  figure=lambda out, found: drawn.append(
                                      figures.plot_indices(out, found, list(metrics))))
    figure = drawn[0]
    for i in indices:
        print(f"  {i['metric']:22s} {i['parameter']:12s} S1 {i['S1']:+.3f} +- {i['S1_conf']:.3f}   "
              f"ST {i['ST']:+.3f} +- {i['ST_conf']:.3f}")
    print(f"  files: {files_line(args.out, 'indices.csv', 'sensitivity.json', 'evaluations.csv', figure)}")


STUDY = Declaration(
    "sensitivity", "Sobol sensitivity indices of metrics over parameter ranges",
    "Saltelli-sample the box of --vary ranges (SALib), run every design in one engine on all cores, and give each "
    "metric's first-order (S1) and total (ST) Sobol indices with 95 % confidence intervals.",
    options=add_options, run=run, files=("evaluations.csv", "indices.csv", "sensitivity.json", "sensitivity.png"),
    figures="optimize_plots")
