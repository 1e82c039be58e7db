"""The optimization study (``ipir-mujoco optimize``): the best design, or the Pareto front, within bounds and
constraints. Its search: :mod:`.optimize`; its figure: ``report/optimize_plots.py``."""

from __future__ import annotations

import argparse
import sys

from ipir_mujoco.core.errors import ParameterError

from ..command import add_model_options, add_variant_option, compile_first, files_line, model_params
from ..contract import Declaration
from ..design_runs import add_design_run_options, add_output_options, design_t_end, scheduler_executor


def add_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument("--vary", action="append", default=[], metavar="NAME=LO:HI[:log]", help="a bounded parameter")
    cmd.add_argument("--objective", action="append", default=[], metavar="min:KEY|max:KEY",
                     help="KEY: a sweep metric (e.g. steady_speed_m_s) or a parameter name; give several for a "
                          "Pareto front")
    cmd.add_argument("--constraint", action="append", default=[], metavar="KEY<=V|KEY>=V",
                     help="a constraint on a metric or parameter; a stalled or failed design is infeasible")
    cmd.add_argument("--budget", type=int, default=None, help="designs to evaluate, >= 1 (default 100)")
    add_variant_option(cmd, many=False, default=None, help="variant of the search (default analytic-unilateral)")
    cmd.add_argument("--verify", default=None, metavar="VARIANT|none",
                     help="variant re-running the optimum / front (default mujoco-ratchet; none: skip)")
    add_design_run_options(cmd)
    add_model_options(cmd)
    add_output_options(cmd, "optimize", "optimization")


def problem_from_args(args: argparse.Namespace):
    from .optimize import DEFAULT_BUDGET, DEFAULT_ENGINE, DEFAULT_VERIFY, Problem, parse_constraint, parse_objective
    from ..sweeps.sweep_space import parse_vary

    if not args.vary:
        raise ParameterError("optimize needs at least one --vary NAME=LO:HI")
    axes = tuple(parse_vary(v) for v in args.vary)
    objectives = tuple(parse_objective(o) for o in args.objective)
    constraints = tuple(parse_constraint(c) for c in args.constraint)
    if args.verify is not None and not args.verify.strip():
        raise ParameterError(f"--verify {args.verify!r} names no model; allowed: a model variant (default "
                             f"{DEFAULT_VERIFY}), or none to skip the verification")
    verify = DEFAULT_VERIFY if args.verify is None else (None if args.verify.strip() == "none" else args.verify)
    engine = DEFAULT_ENGINE if args.variant is None else args.variant  # '' is refused by name, not read as the default
    return Problem(axes, objectives, constraints, model_params(args), engine, verify,
                   design_t_end(args), bool(args.until_steady), DEFAULT_BUDGET if args.budget is None else args.budget,
                   0 if args.seed is None else args.seed)


def run(args: argparse.Namespace, figures) -> None:
    from .optimize import run_optimize

    problem = problem_from_args(args)
    if args.workers is not None and args.workers < 1:
        raise ParameterError(f"--workers {args.workers}: allowed: a whole number >= 1")
    compile_first((problem.engine,))  # before the pool: compiled once, said at once
    drawn = []
    with scheduler_executor(args.scheduler) as executor:
        record = run_optimize(problem, args.out, resume=args.resume, workers=args.workers, executor=executor,
                              figure=lambda out: drawn.append(figures.plot_pareto(out, problem)))
    figure = drawn[0]
    print(f"{record['evaluations']} evaluations ({record['reused_on_resume']} re-used), {record['feasible']} feasible"
          + ("" if not record.get("unusable") else
             "; not used: " + ", ".join(f"{why} {n}" for why, n in record["unusable"].items())))
    items = [record["best"]] if "best" in record else record["front"]
    if "best" in record and record["best"] is None:
        print("  no feasible design found")
    for item in items:
        if item is None:
            continue
        where = ", ".join(f"{n}={item[n]:.6g}" for n in problem.names)
        shown = dict.fromkeys([o.key for o in problem.objectives] + [c.key for c in problem.constraints])
        objs = ", ".join(f"{k}={_fmt(item.get(k, getattr(problem.base, k, None)))}" for k in shown
                         if k not in problem.names)
        div = ""
        if problem.verify:
            divs = {k[len("divergence:"):]: v for k, v in item["verify"].items() if k.startswith("divergence:")}
            div = "; divergence " + ", ".join(f"{k} {_fmt(v)}" for k, v in divs.items())
        print(f"  {'best' if 'best' in record else 'front'}: {where}{': ' + objs if objs else ''}{div}")
    print(f"  files: {files_line(args.out, 'evaluations.csv', 'pareto.csv', 'optimize.json', figure)}")
    for key in record["flat_objectives"]:
        print(f"ipir-mujoco optimize: note: {key} is the same in every feasible design, so the search could not "
              f"tell them apart (a run too short for a whole crank revolution? --t-end is {problem.t_end:g} s)",
              file=sys.stderr)


STUDY = Declaration(
    "optimize", "optimize designs: one objective or a Pareto front",
    "Search the box of --vary ranges for the design that minimises or maximises one objective (Sobol start + "
    "COBYQA), or for the Pareto front of several (NSGA-II, pymoo), under constraints, in the fast engine; verify "
    "the optimum or front in MuJoCo. Ctrl-C keeps what is done; --resume completes it without re-running any "
    "design.",
    options=add_options, run=run, files=("evaluations.csv", "pareto.csv", "optimize.json", "pareto.png"),
    figures="optimize_plots")


def _fmt(v) -> str:
    return "-" if v is None else f"{v:.6g}"
