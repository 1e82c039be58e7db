"""The uncertainty study (``ipir-mujoco uncertainty``): metrics and event probabilities under uncertain parameters,
two fidelities. Its runs and statistics: :mod:`.uncertainty`; its figure: ``report/uncertainty_figure.py``."""

from __future__ import annotations

import argparse

from ..command import add_model_options, add_variant_option, compile_first, files_line, model_params
from ..contract import Declaration
from ..design_runs import add_design_run_options, design_t_end


def add_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument("--dist", action="append", default=[], metavar="NAME=KIND:...",
                     help="an uncertain parameter: NAME=normal:MEAN:SD, uniform:LO:HI, lognormal:MU:SIGMA (of "
                          "log NAME) or truncnormal:MEAN:SD:LO:HI, in the parameter's unit; inside its allowed range")
    cmd.add_argument("--dist-file", metavar="FILE.toml",
                     help="distributions as a [dist] table (NAME = \"KIND:...\") and optionally a [correlation]; "
                          "what 'calibrate' writes as posterior.toml; --dist wins for a parameter both name")
    cmd.add_argument("--metric", action="append", default=[], metavar="KEY",
                     help="a run's summary key or sweep metric (several allowed), e.g. steady_speed_m_s")
    cmd.add_argument("--event", action="append", default=[], metavar="'KEY>V'",
                     help="an event whose probability to give: KEY>V, KEY>=V, KEY<V, KEY<=V, or stall, "
                          "no-steady-state, slides-back (e.g. 'skid_m>0.01', 'peak_clutch_force_n>15')")
    cmd.add_argument("--samples", type=int, default=1000, metavar="N",
                     help="parameter draws run in the equations (default 1000)")
    cmd.add_argument("--mujoco-samples", type=int, default=0, metavar="M",
                     help="of them, how many also run in MuJoCo (default 0; 3 or more for the multi-fidelity "
                          "estimate, e.g. 20)")
    add_variant_option(cmd, many=False, default=None,
                       help="either variant of the pair (the other matches its clutch rule): analytic-unilateral "
                            "with mujoco-ratchet (default), or analytic-exact with mujoco-lock")
    add_design_run_options(cmd)
    add_model_options(cmd)
    cmd.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    cmd.add_argument("--out", metavar="DIR", default="uncertainty", help="results folder (default ./uncertainty)")


def run(args: argparse.Namespace, figures) -> None:
    from ...output import check_output_dir
    from .uncertainty import check_metric, parse_event, run_uncertainty, write_files
    from .uq_dists import combine, parse_dist, read_dist_file

    check_output_dir(args.out, files=STUDY.files)
    base = model_params(args)
    from_file, correlation = read_dist_file(args.dist_file) if args.dist_file is not None else ([], None)
    dists = combine([parse_dist(d) for d in args.dist], from_file)
    metrics = tuple(dict.fromkeys(check_metric(m) for m in args.metric))
    events = tuple(parse_event(e) for e in args.event)
    compile_first()  # before the pool: compiled once, said at once (the equations run every sample)
    result = run_uncertainty(dists, metrics, events, base=base, engine=args.variant, samples=args.samples,
                             mujoco_samples=args.mujoco_samples, t_end=design_t_end(args),
                             until_steady=bool(args.until_steady), seed=0 if args.seed is None else args.seed,
                             correlation=correlation, workers=args.workers)
    figure = write_files(args.out, result, figure=figures.plot_uncertainty)
    print(format_result(result))
    print(f"  files: {files_line(args.out, 'uncertainty.json', 'samples.csv', figure)}")


STUDY = Declaration(
    "uncertainty", "metrics and event probabilities under uncertain parameters (equations + MuJoCo)",
    "Draw --samples parameter sets from the --dist distributions, run the equations on all of them and MuJoCo on "
    "the first --mujoco-samples (the same draws), and give each metric's mean, standard deviation and 5/50/95 % "
    "quantiles with 95 % confidence intervals, and each event's probability with its interval. With MuJoCo "
    "samples the estimate is multi-fidelity (the equations as a control variate of MuJoCo), shown beside MuJoCo's "
    "plain Monte Carlo with the variance reduction. Writes DIR/uncertainty.json, DIR/samples.csv, "
    "DIR/uncertainty.png (docs/uncertainty.md).",
    options=add_options, run=run, files=("uncertainty.json", "samples.csv", "uncertainty.png"),
    figures="uncertainty_figure")


def _interval(pair) -> str:
    lo, hi = ("-inf" if pair[0] is None else f"{pair[0]:.4g}"), ("inf" if pair[1] is None else f"{pair[1]:.4g}")
    return f"[{lo}, {hi}]"


def format_result(result: dict) -> str:
    """The study's estimates as text: per metric a line per statistic with its 95 % interval; per event its
    probability and interval; the failures."""
    from .uq_stats import BCA_MAX

    study = result["study"]
    lines = [f"{study['engine']} on {study['samples']} samples"
             + (f", {study['mujoco_engine']} on the first {study['mujoco_samples']}" if study["mujoco_samples"] else "")
             + f" ({study['wall_s']:.1f} s); 95 % confidence intervals"]
    for key, e in result["metrics"].items():
        how = ("multi-fidelity (control variate)" if e["estimator"] == "multi-fidelity"
               else f"Monte Carlo: mean Student t, SD {'BCa' if e['samples'] <= BCA_MAX else 'percentile'} bootstrap, "
                    "quantiles order statistics")
        lines.append(f"  {key}  [{how}]")
        lines.append(f"    mean {e['mean']:.6g}  {_interval(e['mean_interval'])}")
        lines.append(f"    std  {e['std']:.4g}  {_interval(e['std_interval'])}")
        for q, v in e["quantiles"].items():
            lines.append(f"    q{q:<3} {v:.6g}  {_interval(e['quantile_intervals'][q])}")
        if e["estimator"] == "multi-fidelity":
            mc = e["mujoco_mc"]
            lines.append(f"    MuJoCo alone ({mc['samples']} runs): mean {mc['mean']:.6g} "
                         f"{_interval(mc['mean_interval'])}, std {mc['std']:.4g} {_interval(mc['std_interval'])}")
            if e.get("mujoco_error_bar") is not None:
                lines.append(f"    MuJoCo's figures carry error bars (the rigid limit on finite grip), "
                             f"{e['mujoco_error_bar']:.3g} on average: the means' intervals are widened by it")
            worth = e["variance_reduction"] * mc["samples"]
            lines.append(f"    correlation {e['correlation']:.5f}, coefficient {e['coefficient']:.4g}: variance "
                         f"reduction {e['variance_reduction']:.3g}x, worth {worth:.0f} plain MuJoCo runs")
        if e.get("note"):
            lines.append(f"    note: {e['note']}")
        if e.get("missing"):
            lines.append(f"    ({e['missing']} sample runs give no value: left out)")
    for text, e in result["events"].items():
        lines.append(f"  P({text}) = {e['probability']:.4g}  {_interval(e['interval'])}  "
                     f"[{e['estimator']}, {e['count']}/{e['samples']} samples]")
        if "mujoco_mc" in e:
            eq, mj = e["equations_mc"], e["mujoco_mc"]
            lines.append(f"    equations alone {eq['count']}/{eq['samples']}: {eq['probability']:.4g} "
                         f"{_interval(eq['interval'])}; MuJoCo alone {mj['count']}/{mj['samples']}: "
                         f"{mj['probability']:.4g} {_interval(mj['interval'])}; the pairs disagree "
                         f"{e['disagreements'][0]} + {e['disagreements'][1]} times")
        if not e.get("resolved", True):
            lines.append(f"    {e['note']}")
    failures = result["failures"]
    if study["mujoco_samples"]:
        reasons = "; ".join(f"{reason}: {n}" for reason, n in failures["mujoco_reasons"].items())
        lines.append(f"  MuJoCo runs used: {failures['mujoco_used']} of {study['mujoco_samples']}"
                     + (f" (not used: {reasons})" if reasons else ""))
    if failures["equations"] or failures["mujoco"]:
        lines.append(f"  failed runs left out: {failures['equations']} equations, {failures['mujoco']} MuJoCo; the "
                     f"first: {failures['first_error']}")
    return "\n".join(lines)
