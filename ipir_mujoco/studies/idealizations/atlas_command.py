"""The idealization atlas (``ipir-mujoco atlas``): where each of the paper's idealizations can be trusted, over a
box of designs. Its runs: :mod:`.atlas`; its figures ``report/atlas_plots.py``, its report section
``report/atlas_section.py``."""

from __future__ import annotations

import argparse
import sys

from ipir_mujoco.core.errors import ParameterError

from ..command import add_model_options, compile_first, files_line, model_params, study_progress
from ..contract import Declaration, Section


def add_options(cmd: argparse.ArgumentParser) -> None:
    from .atlas_space import DEFAULT_BUDGET, DEFAULT_SAMPLES, DEFAULT_TOLERANCE, NAMES

    cmd.add_argument("--vary", action="append", default=[], metavar="NAME=LO:HI[:log]", help="a parameter range")
    cmd.add_argument("--idealization", action="append", default=[], metavar="NAME",
                     help=f"one of: {', '.join(NAMES)} (several allowed; default: every one the options allow)")
    cmd.add_argument("--metric", action="append", default=[], metavar="KEY",
                     help="revolutions, travel_m, x1_final, x2_final, v1_max, v2_max under constant torque "
                          "(default revolutions, travel_m); steady_speed_m_s, energy_per_metre_j_m, "
                          "distance_per_rev_m, efficiency, t_steady_s under --drive motor or servo (default the "
                          "first two)")
    cmd.add_argument("--threshold", action="append", type=float, default=[], metavar="REL",
                     help="relative cost below which an idealization is safe, > 0 (several allowed; default 0.01)")
    cmd.add_argument("--budget", type=int, default=None, metavar="N",
                     help=f"MuJoCo runs for the whole atlas, 2 per design (default {DEFAULT_BUDGET}; 0: the "
                          "equations only)")
    cmd.add_argument("--samples", type=int, default=None, metavar="N",
                     help=f"the equations' designs: N x (parameters + 2) (Saltelli; default {DEFAULT_SAMPLES})")
    cmd.add_argument("--boundary-tol", type=float, default=None, metavar="FRACTION",
                     help="MuJoCo stops once the designs whose side of a threshold is not known at 95 %% are less "
                          f"than this share of the box (default {DEFAULT_TOLERANCE:g})")
    cmd.add_argument("--seed", type=int, default=None, help="seed, >= 0 (default 0)")
    cmd.add_argument("--t-end", type=float, default=None, metavar="SECONDS",
                     help="simulated time per run (default 1 s; under the motor the cap of a run to its steady "
                          "state, default 10 s)")
    add_model_options(cmd)
    cmd.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    cmd.add_argument("--out", metavar="DIR", default="atlas", help="results folder (default ./atlas)")
    cmd.add_argument("--resume", action="store_true", help="complete an interrupted atlas in DIR")


def atlas_from_args(args: argparse.Namespace):
    from .atlas import DEFAULT_BUDGET, DEFAULT_SAMPLES, DEFAULT_TOLERANCE, Atlas
    from ..sweeps.sweep_space import parse_vary

    if not args.vary:
        raise ParameterError("atlas needs at least one --vary NAME=LO:HI[:log]")
    for t in args.threshold:
        if not t > 0:
            raise ParameterError(f"--threshold {t:g} is out of range; allowed: 0 < threshold <= 10 (a relative cost)")
    return Atlas(tuple(parse_vary(v) for v in args.vary), model_params(args), tuple(args.idealization),
                 tuple(args.metric), tuple(args.threshold) or (0.01,),
                 DEFAULT_BUDGET if args.budget is None else args.budget,
                 DEFAULT_SAMPLES if args.samples is None else args.samples, 0 if args.seed is None else args.seed,
                 args.t_end, DEFAULT_TOLERANCE if args.boundary_tol is None else args.boundary_tol)


def run(args: argparse.Namespace, figures) -> None:
    atlas = atlas_from_args(args)
    if args.workers is not None and args.workers < 1:
        raise ParameterError(f"--workers {args.workers}: allowed: a whole number >= 1")
    compile_first()  # before the pool: compiled once, said at once
    from .atlas import run_atlas

    result = run_atlas(atlas, args.out, resume=args.resume, workers=args.workers, progress=study_progress("atlas"))
    drawn = figures.plot_atlas(result, atlas, args.out)
    for line in summary_lines(result, atlas):
        print(line)
    runs = result["runs"]
    print(f"  {runs['equations'] // 2} designs of the equations ({runs['equations']} runs), {runs['mujoco'] // 2} of "
          f"MuJoCo ({runs['mujoco']} runs) in {result['wall_s']:.1f} s ({result['workers']} worker"
          f"{'s' if result['workers'] != 1 else ''})")
    print(f"  files: {files_line(args.out, 'atlas.json', 'samples.csv', *drawn)}")
    sys.stdout.flush()

STUDY = Declaration(
    "atlas", "where each of the paper's idealizations costs less than a threshold, over design ranges",
    "For each idealization of the paper's model (removed one at a time, as the validation report's ladder does), "
    "the relative cost (idealized - real) / |real| of each metric over the box of --vary ranges, and the region "
    "where it stays below each --threshold: the equations sampled densely (quasi-random), MuJoCo within --budget "
    "runs placed near the boundary by a Gaussian-process surrogate, Sobol indices of each cost. Writes "
    "DIR/atlas.json, DIR/samples.csv (streamed; Ctrl-C keeps what is done, --resume completes it) and figures.",
    options=add_options, run=run, files=("atlas.json", "samples.csv"), figures="atlas_plots",
    sections=(Section("model_holds", "Where the paper's model holds", "atlas_section", 60),))


def summary_lines(result: dict, atlas) -> list[str]:
    """One line per idealization, metric and threshold: the safe fraction, its interval, crossings, runs."""
    from .atlas import top_drivers

    lines = []
    for name, per_metric in result["idealizations"].items():
        for metric, entry in per_metric.items():
            for item in entry["by_threshold"]:
                frac, interval = item["safe_fraction"], item["safe_fraction_interval"]
                where = ("no value" if frac is None else
                         f"safe in {100 * frac:.1f} % of the box [{100 * interval[0]:.1f}, {100 * interval[1]:.1f}]")
                cross = ""
                for param, values in item.get("crossings_interval", {}).items():
                    cross = "; crossings " + (", ".join(f"{param}={v:.5g} [{lo:.5g}, {hi:.5g}]" for v, lo, hi in values)
                                              or "none")
                regions = item.get("runs_by_region")
                by = "MuJoCo" if entry["measured_by"] == "mujoco" else "the equations"
                spent = (f"; {entry['runs'] // 2} designs ({entry['runs']} runs of {by}: each idealized and real)"
                         + (f" (safe {regions['safe'] // 2}, unsafe {regions['unsafe'] // 2}, boundary "
                            f"{regions['boundary'] // 2})" if regions else ""))
                if entry.get("missing"):
                    spent += f"; {entry['missing']} designs gave no value (samples.csv: notes, error)"
                if entry.get("unusable"):  # MuJoCo's pairs it could not use, by why
                    spent += "; not used: " + ", ".join(f"{why} {n}" for why, n in entry["unusable"].items())
                if entry.get("cost_error_max") is not None:
                    spent += f"; costs within error bars up to {entry['cost_error_max']:.2g} (MuJoCo's rigid limit)"
                equations = entry.get("equations")
                if equations:  # MuJoCo measured it: the equations' answer beside it
                    eq = next(i for i in equations["by_threshold"] if i["threshold"] == item["threshold"])
                    spent += f"; the equations: safe in {100 * eq['safe_fraction']:.1f} %"
                top = top_drivers(entry)
                lines.append(f"{name:24s} {metric:22s} |cost| < {item['threshold']:g}: {where}{cross}{spent}"
                             + (f"; driven by {top}" if top != "-" else ""))
    return lines
