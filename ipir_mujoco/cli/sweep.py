"""``ipir-mujoco sweep``: what-if studies over many designs."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ipir_mujoco.analytic.errors import ParameterError
from ipir_mujoco.analytic.results import write_json

from .common import EXIT_OK, add_model_options, model_params


def add_parser(commands) -> None:
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
    add_model_options(swp)
    swp.add_argument("--out", metavar="DIR", default="sweep", help="results folder (default ./sweep)")
    swp.add_argument("--resume", action="store_true", help="complete an interrupted sweep in DIR")
    swp.add_argument("--workers", type=int, default=None, help="processes/threads to use (default: all cores)")
    swp.add_argument("--no-batch", action="store_true", help="run MuJoCo designs one by one, not through mujoco.batch")
    swp.add_argument("--scheduler", metavar="ADDRESS",
                     help="run on a Dask distributed scheduler (needs the 'dask' extra), e.g. tcp://host:8786")
    swp.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ..studies.sweep import SweepInterrupted, run_sweep
    from ..report.sweep_plots import best_designs, plot_sweep, read_results
    from ..studies.sweep_space import Study, parse_vary, read_study

    base = model_params(args)
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
