"""``ipir-mujoco compare``: two runs written by ``simulate --out``, side by side; or a measured run (a CSV of
``t`` and any of x1 x2 phi omega v1 v2) against one of them, on the columns both have."""

from __future__ import annotations

import argparse

from ipir_mujoco.core.errors import ParameterError

from .common import EXIT_OK


def add_parser(commands) -> None:
    cmp_ = commands.add_parser("compare", help="compare two runs written by 'simulate --out', or a measured run (CSV) against one",
                               description="Compare run B against run A: summary figures, RMS and largest "
                                           "differences at matching time and at matching crank angle, mode "
                                           "switches matched one by one, and when a tolerance is first exceeded.")
    cmp_.add_argument("run_a", metavar="RUN_A", help="reference run folder, or a measured run (FILE.csv)")
    cmp_.add_argument("run_b", metavar="RUN_B", help="run folder compared against it, or a measured run (FILE.csv); "
                                                     "one side at least a run folder")
    cmp_.add_argument("--tolerance", type=float, default=0.01,
                      help="relative tolerance for 'first exceeded' (fraction of each quantity's scale; default 0.01)")
    cmp_.add_argument("--json", action="store_true", help="print the comparison as one JSON object")
    cmp_.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ipir_mujoco.core.results import json_text

    from ..studies.compare import compare_runs, format_comparison, load_run
    from ..studies.measured import compare_measured, format_measured_comparison, is_measured_csv, read_measured

    measured_a, measured_b = is_measured_csv(args.run_a), is_measured_csv(args.run_b)
    if measured_a and measured_b:
        raise ParameterError(f"{args.run_a!r} and {args.run_b!r} are both files (measured runs); allowed: at most "
                             "one measured CSV, compared against a run folder written by 'simulate --out'")
    if measured_a or measured_b:
        measured = read_measured(args.run_a if measured_a else args.run_b)
        result = compare_measured(measured, load_run(args.run_b if measured_a else args.run_a),
                                  tolerance=args.tolerance, measured_is_a=measured_a)
        print(json_text(result) if args.json else format_measured_comparison(result))
        return EXIT_OK
    result = compare_runs(load_run(args.run_a), load_run(args.run_b), tolerance=args.tolerance)
    print(json_text(result) if args.json else format_comparison(result))
    return EXIT_OK
