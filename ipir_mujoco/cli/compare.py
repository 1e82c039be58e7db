"""``ipir-mujoco compare``: two runs written by ``simulate --out``, side by side."""

from __future__ import annotations

import argparse
import json

from .common import EXIT_OK


def add_parser(commands) -> None:
    cmp_ = commands.add_parser("compare", help="compare two runs written by 'simulate --out'",
                               description="Compare run B against run A: summary figures, RMS and largest "
                                           "differences at matching time and at matching crank angle, mode "
                                           "switches matched one by one, and when a tolerance is first exceeded.")
    cmp_.add_argument("run_a", metavar="RUN_A", help="reference run folder")
    cmp_.add_argument("run_b", metavar="RUN_B", help="run folder compared against it")
    cmp_.add_argument("--tolerance", type=float, default=0.01,
                      help="relative tolerance for 'first exceeded' (fraction of each quantity's scale; default 0.01)")
    cmp_.add_argument("--json", action="store_true", help="print the comparison as one JSON object")
    cmp_.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    from ..studies.compare import compare_runs, format_comparison, load_run

    result = compare_runs(load_run(args.run_a), load_run(args.run_b), tolerance=args.tolerance)
    print(json.dumps(result, allow_nan=False) if args.json else format_comparison(result))
    return EXIT_OK
