"""The calibration (``ipir-mujoco calibrate``): fit parameters to a measured run (least squares, intervals,
identifiability). Its fit: :mod:`.calibrate`; its figure: ``report/calibration_figure.py``."""

from __future__ import annotations

import argparse
import sys

from ..command import (add_model_options, add_variant_option, check_input_file, compile_first, files_line,
                       model_params, study_progress)
from ..contract import Declaration


def add_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument("--data", required=True, metavar="FILE.csv",
                     help="the measured run: a header row with t [s] and any of x1 x2 [m], phi [rad], omega [rad/s], "
                          "v1 v2 [m/s]; irregular times and noise are fine")
    cmd.add_argument("--fit", action="append", default=[], metavar="NAME=LO:HI",
                     help="a parameter to fit and its range (inside its allowed range; several allowed)")
    add_variant_option(cmd, many=False, default="analytic-unilateral",
                       help="the variant fitted (default analytic-unilateral; a MuJoCo variant works, slowly)")
    add_model_options(cmd)
    cmd.add_argument("--out", metavar="DIR", default="calibration", help="results folder (default ./calibration)")


def run(args: argparse.Namespace, figures) -> None:
    from ...output import check_output_dir
    from .calibrate import calibrate, parse_fit, write_files
    from ..comparison.measured import read_measured

    check_output_dir(args.out, files=STUDY.files)
    check_input_file("--data", args.data)
    fits = [parse_fit(f) for f in args.fit]
    base = model_params(args)
    measured = read_measured(args.data)
    compile_first((args.variant,))
    result = calibrate(measured, fits, base=base, engine=args.variant, progress=study_progress("calibrate"))
    figure = write_files(args.out, result, measured, figure=figures.plot_calibration)
    print(format_result(result))
    print(f"  files: {files_line(args.out, 'calibration.json', 'posterior.toml', figure)}")
    for name in result["not_identifiable"]:
        print(f"ipir-mujoco calibrate: warning: {name} is not identifiable from these data (its interval spans its "
              "fit range, or a direction of the parameters leaves the fit unchanged); its value is not a measurement",
              file=sys.stderr)


STUDY = Declaration(
    "calibrate", "fit parameters to a measured run (CSV of t and any of x1 x2 phi omega v1 v2)",
    "Fit the --fit parameters within their ranges so that the model's run matches the measured columns (least "
    "squares, each column weighed by its noise), with 95 % confidence intervals, their correlation, and a warning "
    "for a parameter the data cannot identify. Writes DIR/calibration.json, DIR/posterior.toml (for 'uncertainty "
    "--dist-file'), DIR/calibration.png (docs/uncertainty.md).",
    options=add_options, run=run, files=("calibration.json", "posterior.toml", "calibration.png"),
    figures="calibration_figure")


def format_result(result: dict) -> str:
    lines = [f"fitted {result['engine']} to {result['data']} ({', '.join(result['columns'])}; {result['points']} "
             f"values, {result['runs']} runs, {result['wall_s']:.1f} s); 95 % confidence intervals"]
    for name, e in result["estimates"].items():
        flag = "  NOT IDENTIFIABLE" if name in result["not_identifiable"] else ""
        bound = "  (at its range's bound)" if e["at_bound"] else ""
        lines.append(f"  {name:14s} {e['value']:.6g}  [{e['interval'][0]:.6g}, {e['interval'][1]:.6g}]{bound}{flag}")
    corr = result["correlation"]
    if len(corr["names"]) > 1:
        lines.append("  correlation: " + "; ".join(
            f"{a}-{b} {corr['matrix'][i][j]:+.3f}" for i, a in enumerate(corr["names"])
            for j, b in enumerate(corr["names"]) if j > i))
    lines.append("  residual RMS: " + ", ".join(f"{c} {v:.3g}" for c, v in result["residual_rms"].items()))
    return "\n".join(lines)
