"""``ipir-mujoco sensitivity``: Sobol indices (S1, ST) of metrics over parameter ranges."""

from __future__ import annotations

import argparse
import sys

from ipir_mujoco.core.errors import ParameterError

from ..studies.sweep_space import T_END_STEADY
from .common import EXIT_OK, add_model_options, model_params
from .optimize import add_scheduler_option, connect


def add_parser(commands) -> None:
    sen = commands.add_parser("sensitivity", help="Sobol sensitivity indices of metrics over parameter ranges",
                              description="Saltelli-sample the box of --vary ranges (SALib), run every design in one "
                                          "engine on all cores, and give each metric's first-order (S1) and total "
                                          "(ST) Sobol indices with 95 %% confidence intervals.")
    sen.add_argument("--vary", action="append", default=[], metavar="NAME=LO:HI", help="a parameter range")
    sen.add_argument("--metric", action="append", default=[], metavar="KEY", help="a sweep metric (several allowed)")
    sen.add_argument("--samples", type=int, default=None, metavar="N",
                     help="Saltelli base samples (designs: N x (parameters + 2); a power of 2; default 64)")
    sen.add_argument("--engine", default=None, help="engine (default analytic-unilateral)")
    sen.add_argument("--seed", type=int, default=None, help="seed, >= 0 (default 0)")
    sen.add_argument("--t-end", type=float, default=None, metavar="SECONDS",
                     help="simulated time per design (default 1 s; with --until-steady the cap, default 10 s)")
    sen.add_argument("--until-steady", action="store_true", help="run every design to its periodic steady state")
    add_model_options(sen)
    sen.add_argument("--out", metavar="DIR", default="sensitivity", help="results folder (default ./sensitivity)")
    sen.add_argument("--resume", action="store_true", help="complete an interrupted study in DIR")
    sen.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    add_scheduler_option(sen)
    sen.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ..report.optimize_plots import plot_indices
    from ..studies.design_eval import StudyInterrupted, check_key
    from ..studies.sensitivity import run_sensitivity
    from ..studies.sweep_space import parse_vary

    if not args.vary:
        raise ParameterError("sensitivity needs at least one --vary NAME=LO:HI")
    axes = tuple(parse_vary(v) for v in args.vary)
    metrics = tuple(check_key(m, f"--metric {m!r}") for m in args.metric)
    t_end = args.t_end if args.t_end is not None else (T_END_STEADY if args.until_steady else 1.0)
    client = None
    try:
        client = connect(args.scheduler)
        indices = run_sensitivity(axes, metrics, args.out, base=model_params(args),
                                  engine=args.engine or "analytic-unilateral", t_end=t_end,
                                  until_steady=bool(args.until_steady), samples=64 if args.samples is None
                                  else args.samples, seed=0 if args.seed is None else args.seed,
                                  resume=args.resume, workers=args.workers,
                                  executor=client.get_executor() if client else None)
    except StudyInterrupted as exc:
        print(f"ipir-mujoco sensitivity: {exc}", file=sys.stderr)
        return 130
    finally:
        if client is not None:
            client.close()
    figure = plot_indices(args.out, indices, list(metrics))
    for i in indices:
        print(f"  {i['metric']:22s} {i['parameter']:12s} S1 {i['S1']:+.3f} +- {i['S1_conf']:.3f}   "
              f"ST {i['ST']:+.3f} +- {i['ST_conf']:.3f}")
    print(f"  files: {args.out}/indices.csv, sensitivity.json, evaluations.csv, {figure}")
    return EXIT_OK
