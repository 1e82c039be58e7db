"""How the wheeled MuJoCo robot's start differs from the equations': one design of the random-design benchmark.

Run on demand from the repository root (seconds):

    python bench/wheels_start.py [--seed 6] [--design 179] [--steps 1e-4,5e-5,2.5e-5] [--t-end 0.3]
                                 [--log FILE.jsonl --series DIR] [--smoke]

Design ``--design`` of ``bench/wheels_agreement.py``'s seed ``--seed`` (the same draw). Printed:

- at t = 0, with the drive's start torque held (a constant torque of M, or of the motor's M_stall), in both
  engines (``analytic-unilateral``, ``mujoco-wheels``) and again with rigid wheels (``cornering_coefficient``
  unset): the rod's force, each module's clutch reaction and acceleration along the pipe (the series' first
  sample, ``rod_force``, ``lambda1/2``, ``a1/2``);
- the design as drawn: the momentum MuJoCo's two modules have beyond the equations' (m1 (v1 - v1') + m2 (v2 -
  v2')) at 10 ms and at ``--t-end``, at each of ``--steps``.

With ``--log`` and ``--series`` (the benchmark's, its MuJoCo series kept): over every design that ran, that
momentum after 10 ms as a mean force [N] (over 0.01 s), its 5 %, 50 % and 95 % quantiles. ``--smoke``: one step
(1e-4 s) to 0.02 s (the script runs).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams

sys.path.insert(0, str(Path(__file__).resolve().parent))
from wheels_agreement import design  # noqa: E402  (the benchmark's draw)

EARLY = 0.01  # s: the start's window


def drawn(seed: int, index: int) -> RobotParams:
    """Design ``index`` of the benchmark's seed ``seed``."""
    rng = np.random.default_rng(seed)
    for _ in range(index):
        design(rng)
    return design(rng)[0]


def held_torque(params: RobotParams) -> RobotParams:
    """The design driven by its start torque held constant (M, or the motor's M_stall)."""
    torque = params.M if params.drive == "torque" else params.M_stall
    values = {k: v for k, v in params.as_dict().items() if k not in ("M_stall", "omega_noload")}
    return RobotParams(**{**values, "drive": "torque", "M": torque})


def extra_momentum(params: RobotParams, a: dict, w: dict, t: float) -> float:
    """MuJoCo's two modules' momentum beyond the equations' at time ``t`` [kg m/s] (the samples' nearest)."""
    j = int(np.argmin(np.abs(np.asarray(a["t"]) - t)))
    k = int(np.argmin(np.abs(np.asarray(w["t"]) - t)))
    return sum(m * (w[f"v{i}"][k] - a[f"v{i}"][j]) for i, m in ((1, params.m1), (2, params.m2)))


def start_line(label: str, params: RobotParams) -> str:
    a = registry.run("analytic-unilateral", params, 1e-3, dt_out=1e-4).series
    w = registry.run("mujoco-wheels", params, 1e-3, dt_out=1e-4).series
    cells = [f"{name} {a[key][0]:+.2f} / {w[key][0]:+.2f} {unit}" for name, key, unit in
             (("rod force", "rod_force", "N"), ("clutch 1", "lambda1", "N"), ("clutch 2", "lambda2", "N"),
              ("a1", "a1", "m/s^2"), ("a2", "a2", "m/s^2"))]
    return f"t = 0, {label} (equations / MuJoCo): " + ", ".join(cells)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=6)
    parser.add_argument("--design", type=int, default=179)
    parser.add_argument("--steps", default="1e-4,5e-5,2.5e-5", help="MuJoCo steps [s], comma-separated")
    parser.add_argument("--t-end", type=float, default=0.3)
    parser.add_argument("--log", default=None, metavar="FILE.jsonl")
    parser.add_argument("--series", default=None, metavar="DIR")
    parser.add_argument("--smoke", action="store_true", help="one step (1e-4 s) to 0.02 s: the script runs")
    args = parser.parse_args(argv)
    if args.smoke:
        args.steps, args.t_end = "1e-4", 0.02
    params = drawn(args.seed, args.design)
    torque = held_torque(params)
    print(f"seed {args.seed} design {args.design}: drive {params.drive}, start torque {torque.M:.3g} N m, m "
          f"{params.m1:.3g}/{params.m2:.3g} kg, incline {params.incline:+.1f} deg")
    print(start_line(f"a constant {torque.M:.3g} N m", torque))
    print(start_line("the same, rigid wheels", replace(torque, cornering_coefficient=None)))
    a = registry.run("analytic-unilateral", params, args.t_end, dt_out=1e-3).series
    for step in (float(s) for s in args.steps.split(",")):
        w = registry.run("mujoco-wheels", params, args.t_end, dt_out=1e-3, timestep=step).series
        print(f"as drawn, step {step:g} s: MuJoCo's extra momentum {extra_momentum(params, a, w, EARLY):+.4f} kg m/s "
              f"at {EARLY:g} s, {extra_momentum(params, a, w, args.t_end):+.4f} at {args.t_end:g} s")
    if args.log and args.series:
        forces = []
        for text in Path(args.log).read_text(encoding="utf-8").splitlines():
            row = json.loads(text)
            path = Path(args.series) / f"design_{row['design']}.npz"
            if "checks" not in row or not path.is_file():
                continue
            each = RobotParams(**row["params"])
            early = registry.run("analytic-unilateral", each, 2 * EARLY, dt_out=1e-3).series
            with np.load(path) as kept:
                forces.append(extra_momentum(each, early, {key: kept[key] for key in ("t", "v1", "v2")}, EARLY) / EARLY)
        q = np.quantile(forces, [0.05, 0.5, 0.95])
        print(f"over {len(forces)} designs of {args.log}: MuJoCo's extra momentum after {EARLY:g} s as a mean force "
              f"[N], 5 / 50 / 95 %: {q[0]:+.2f} / {q[1]:+.2f} / {q[2]:+.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
