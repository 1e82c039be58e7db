"""``ipir-mujoco kinetostatics``: torque and forces a prescribed crank motion needs."""

from __future__ import annotations

import argparse

from ipir_mujoco import analytic
from ipir_mujoco.analytic.errors import ParameterError
from ipir_mujoco.analytic.results import write_json

from ..output import check_output_dir, staged_output
from .common import EXIT_OK, add_model_options, model_params


def add_parser(commands) -> None:
    kin = commands.add_parser("kinetostatics", help="torque and forces a prescribed crank motion needs",
                              description="Inverse kinetostatics: prescribe the crank's motion (a constant speed, "
                                          "or samples of phi(t)) and get the motor torque, clutch reactions and "
                                          "rod force it needs, as CSV and a plot against crank angle.")
    source = kin.add_mutually_exclusive_group(required=True)
    source.add_argument("--omega", type=float, metavar="RAD_S", help="constant crank speed [rad/s]")
    source.add_argument("--samples", metavar="FILE.csv",
                        help="CSV with columns t (s, from 0, increasing) and phi (rad); a cubic spline goes through them")
    kin.add_argument("--revolutions", type=float, default=2.0, help="turns at constant speed (default 2)")
    kin.add_argument("--geometry", choices=("approx", "exact"), default="exact", help="default: exact")
    kin.add_argument("--clutch", choices=analytic.CLUTCH_RULES, default="kinematic",
                     help="kinematic (the paper's rule, default) or unilateral (one-way clutches)")
    add_model_options(kin)
    kin.add_argument("--out", metavar="DIR", default="kinetostatics",
                     help="writes DIR/kinetostatics.csv and DIR/kinetostatics.png (default ./kinetostatics)")
    kin.set_defaults(handler=run)


def _read_crank_samples(path: str):
    import numpy as np

    try:
        table = np.genfromtxt(path, delimiter=",", names=True)
    except OSError:
        raise ParameterError(f"--samples {path!r} cannot be read (does it exist?)") from None
    names = table.dtype.names or ()
    if "t" not in names or "phi" not in names:
        raise ParameterError(f"--samples {path!r} needs a header row with columns t and phi; found {list(names)}")
    return np.atleast_1d(table["t"]), np.atleast_1d(table["phi"])



def run(args: argparse.Namespace) -> int:
    from ipir_mujoco.analytic.inverse import CrankMotion, inverse_kinetostatics

    from ..report.plots import figure_kinetostatics

    check_output_dir(args.out)
    params = model_params(args)
    if args.omega is not None:
        motion = CrankMotion.constant_speed(args.omega, params.phi0, args.revolutions)
    else:
        motion = CrankMotion.from_samples(*_read_crank_samples(args.samples))
    run = inverse_kinetostatics(params, motion, args.geometry, args.clutch)
    s = run.series
    with staged_output(args.out) as staging:
        run.write_csv(staging / "kinetostatics.csv")
        write_json(staging / "summary.json", run.to_json_dict())
        figure_kinetostatics(run).savefig(staging / "kinetostatics.png", dpi=120)
    print(f"{motion.description}, {args.clutch} clutches, {args.geometry} geometry, {run.t_end:.4g} s")
    print(f"  motor torque     {s['motor_torque'].min():+.4g} .. {s['motor_torque'].max():+.4g} N m "
          f"(mean power {run.summary['energy']['motor_work_j'] / run.t_end:.4g} W)")
    print(f"  clutch reactions rear {s['lambda1'].min():+.4g} .. {s['lambda1'].max():+.4g} N, "
          f"front {s['lambda2'].min():+.4g} .. {s['lambda2'].max():+.4g} N")
    print(f"  rod force        {s['rod_force'].min():+.4g} .. {s['rod_force'].max():+.4g} N (tension > 0)")
    print(f"  wrote {args.out}/kinetostatics.csv, kinetostatics.png, summary.json")
    return EXIT_OK
