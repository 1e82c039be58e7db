"""``ipir-mujoco kinetostatics``: torque and forces a prescribed crank motion needs."""

from __future__ import annotations

import argparse
import math

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.limits import MAX_T_END, check_run_options
from ipir_mujoco.core.params import check_real, read_text_file

from ..labels import signed
from ..output import check_output_dir, staged_output
from .common import EXIT_OK, add_model_options, check_input_file, files_line, model_params, wall_progress


def add_parser(commands) -> None:
    kin = commands.add_parser("kinetostatics", help="torque and forces a prescribed crank motion needs",
                              description="Inverse kinetostatics: prescribe the crank's motion (a constant speed, "
                                          "or samples of phi(t)) and get the motor torque, clutch reactions and "
                                          "rod force it needs, as CSV and a plot against crank angle.")
    source = kin.add_mutually_exclusive_group(required=True)
    source.add_argument("--omega", type=float, metavar="RAD_S",
                        help="constant crank speed [rad/s], 0 < |omega| <= 1e4 (the range of omega0)")
    source.add_argument("--samples", metavar="FILE.csv",
                        help="CSV with columns t (s, from 0, increasing) and phi (rad); a cubic spline goes through them")
    kin.add_argument("--revolutions", type=float, default=2.0, help="turns at constant speed (default 2)")
    kin.add_argument("--geometry", choices=("approx", "exact"), default="exact", help="default: exact")
    kin.add_argument("--clutch", choices=registry.RULES, default="kinematic",
                     help="kinematic (the paper's rule, default) or unilateral (one-way clutches)")
    add_model_options(kin)
    kin.add_argument("--out", metavar="DIR", default="kinetostatics",
                     help="writes DIR/kinetostatics.csv, DIR/kinetostatics.png and DIR/summary.json (default ./kinetostatics)")
    kin.set_defaults(handler=run)


def _read_crank_samples(path: str):
    """(t [s], phi [rad]) from a CSV file with a header row naming t and phi; one-line errors otherwise."""
    import numpy as np

    check_input_file("--samples", path)
    lines = [ln for ln in read_text_file(path, "--samples").splitlines() if ln.strip()]
    if not lines:
        raise ParameterError(f"--samples {path!r} is empty; allowed: a CSV file with a header row t,phi "
                             "and one row per sample")
    header = [name.strip() for name in lines[0].split(",")]
    if "t" not in header or "phi" not in header:
        hint = " (columns are separated by commas, not ';')" if ";" in lines[0] else ""
        raise ParameterError(f"--samples {path!r} needs a header row with columns t and phi{hint}; "
                             f"found {header}")
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        if len(cells) != len(header):
            raise ParameterError(f"--samples {path!r} line {number} has {len(cells)} values; the header "
                                 f"has {len(header)}")
        try:
            rows.append([float(c) for c in cells])
        except ValueError:
            raise ParameterError(f"--samples {path!r} line {number}: {line.strip()!r} is not a row of "
                                 "numbers") from None
    if len(rows) < MIN_SAMPLES:
        raise ParameterError(f"--samples {path!r} has {len(rows)} sample row(s); allowed: at least {MIN_SAMPLES} "
                             "rows of t,phi under the header (the spline through them needs 4)")
    table = np.array(rows, dtype=float).reshape(len(rows), len(header))
    return table[:, header.index("t")], table[:, header.index("phi")]


# |omega| at most this [rad/s] (~95,000 rpm): the same bound as the initial crank speed omega0; the
# torque a prescribed motion needs grows as omega^2, and above it the figures are meaningless
MAX_OMEGA = 1e4
MAX_REVOLUTIONS = 1e4  # turns at constant speed: two mode switches each
MIN_SAMPLES = 4  # rows of --samples: the cubic spline through them needs 4


def run(args: argparse.Namespace) -> int:
    from ipir_mujoco.analytic.inverse import CrankMotion, inverse_kinetostatics
    from ipir_mujoco.core.results import write_json

    from ..report.plots import figure_kinetostatics

    if args.omega is not None:
        if not (math.isfinite(args.omega) and 0 < abs(args.omega) <= MAX_OMEGA):
            raise ParameterError(f"omega={args.omega:g} rad/s is out of range; allowed: 0 < |omega| <= "
                                 f"{MAX_OMEGA:g} rad/s (the range of omega0)")
        check_real("--revolutions", args.revolutions, high=MAX_REVOLUTIONS)
        duration = args.revolutions * 2 * math.pi / abs(args.omega)  # s: the run this motion makes
        if duration > MAX_T_END:
            slowest = args.revolutions * 2 * math.pi / MAX_T_END
            raise ParameterError(f"--omega {args.omega:g} rad/s with --revolutions {args.revolutions:g} would run "
                                 f"{duration:.4g} s; allowed: {slowest:.4g} <= |omega| <= {MAX_OMEGA:g} rad/s for "
                                 f"these revolutions (runs of at most {MAX_T_END:g} s), or fewer --revolutions")
    params = model_params(args)
    samples = _read_crank_samples(args.samples) if args.samples is not None else None
    check_output_dir(args.out, files=("kinetostatics.csv", "summary.json", "kinetostatics.png"))
    if samples is None:
        motion = CrankMotion.constant_speed(args.omega, params.phi0, args.revolutions)
    else:
        try:
            motion = CrankMotion.from_samples(*samples)
            check_run_options(motion.t_end, motion.t_end / 2000)  # its output grid: 2000 intervals
        except ParameterError as exc:
            raise ParameterError(f"--samples {args.samples!r}: {exc}") from None
    progress = wall_progress(motion.t_end, lambda t: f"kinetostatics: prescribed motion solved to {t:.3g} / "
                                                     f"{motion.t_end:.4g} s")
    run = inverse_kinetostatics(params, motion, args.geometry, args.clutch, progress=progress)
    s = run.series
    with staged_output(args.out) as staging:
        run.write_csv(staging / "kinetostatics.csv")
        write_json(staging / "summary.json", run.to_json_dict())
        figure_kinetostatics(run).savefig(staging / "kinetostatics.png", dpi=120)
    print(f"{motion.description}, {args.clutch} clutches, {args.geometry} geometry, {run.t_end:.4g} s")
    print(f"  motor torque     {signed(s['motor_torque'].min(), 4)} .. {signed(s['motor_torque'].max(), 4)} N m "
          f"(mean power {run.summary['energy']['motor_work_j'] / run.t_end:.4g} W)")
    print(f"  clutch reactions rear {signed(s['lambda1'].min(), 4)} .. {signed(s['lambda1'].max(), 4)} N, "
          f"front {signed(s['lambda2'].min(), 4)} .. {signed(s['lambda2'].max(), 4)} N")
    print(f"  rod force        {signed(s['rod_force'].min(), 4)} .. {signed(s['rod_force'].max(), 4)} N (tension > 0)")
    print(f"  wrote {files_line(args.out, 'kinetostatics.csv', 'kinetostatics.png', 'summary.json')}")
    return EXIT_OK
