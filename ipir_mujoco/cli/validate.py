"""``ipir-mujoco validate``: the analytic-vs-physics validation report (the main job)."""

from __future__ import annotations

import argparse

from ..output import check_output_dir, staged_output
from .common import EXIT_OK, add_model_options, compile_first, model_params, study_progress


def add_parser(commands) -> None:
    val = commands.add_parser("validate", help="the analytic-vs-physics validation report (the main job)",
                              description="Run the model ladder (at the paper's case unless --set or --config "
                                          "change it; the report says which) and write a report: "
                                          "DIR/index.html, DIR/report.md, DIR/metrics.json, DIR/figures/.")
    val.add_argument("--out", metavar="DIR", default="report", help="report folder (default: ./report)")
    add_model_options(val)
    val.add_argument("--quick", action="store_true", help="reduced version for tests and CI (coarser output)")
    val.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    check_output_dir(args.out, files=("metrics.json", "index.html", "report.md"), folders=("figures",))
    params = model_params(args)
    compile_first()  # before the report's imports (matplotlib): a cold cache is said within a second or two

    from ipir_mujoco.core.results import write_json

    from ..report.sections import SECTIONS
    from ..report.validation import write_report
    from ..studies.validate import validate

    progress = study_progress("validate")
    metrics, rungs = validate(params, quick=args.quick, progress=progress, sections=SECTIONS)
    with staged_output(args.out) as staging:
        write_json(staging / "metrics.json", metrics)
        write_report(staging, metrics, rungs, SECTIONS, progress=progress)
    for verdict in metrics["verdicts"]:
        print(f"{verdict['question']}\n  {verdict['answer']}")
    print(f"report: {args.out}/index.html (also report.md, metrics.json, figures/)")
    return EXIT_OK
