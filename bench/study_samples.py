"""What the studies' cap on samples per run (``ipir_mujoco.core.options.STUDY_SAMPLES``) costs clutch-study.

clutch-study samples MuJoCo's compliant runs at every step so that no engagement peaks between samples. With a
finite grip the step is finer (MuJoCo's skidding carriage, 1e-3 of its module's mass, on the clutch spring: ~30
times until Dec 7, ~10 times since, ``timestep.CARRIAGE_STEP_SHARE``), and a 10 s cruise at every step kept 3.2e6
samples (a 1.9 GB study at ``--quick``). The cap samples such
a run every n-th step. This bench runs each of ``clutch-study --quick``'s MuJoCo compliant runs at a finite grip
(and at unlimited grip, where the cap does not bind) twice: sampled at every step and as the study samples it,
and prints per run the samples kept, the peak clutch force both ways, their relative difference and the bound the
study states for it, ``peak_sampling_bound`` = (omega n h)^2 / 4 with omega the fastest mode the spring takes part in
(with a finite grip MuJoCo's skidding carriage's, ~30 sqrt(k / min(m1, m2))), at most 1, with the wall time and peak
memory (ru_maxrss of a child process per run) both ways.

    python bench/study_samples.py [--smoke]   # mu_wall 0.5 and unlimited, both operating points (~5 min)
    python bench/study_samples.py --smoke     # one run
"""

from __future__ import annotations

import argparse
import multiprocessing
import resource
import sys
import time
from types import SimpleNamespace


def one(args):
    """(samples, peak force [N], wall [s], max RSS [MB]) of one MuJoCo compliant run sampled every ``every_step``
    (True) or as the study samples it; in a process of its own, so that ru_maxrss is this run's."""
    mu, point_key, k, backlash, every_step = args
    from ipir_mujoco import registry
    from ipir_mujoco.core.params import RobotParams
    from ipir_mujoco.studies.clutch_study import DT_OUT_MAX, POINTS, _peak_bound, design, mujoco_dt_out

    point = POINTS[point_key]
    params = design(RobotParams(mu_wall=mu), point, k, backlash)
    h = registry.timestep("mujoco-ratchet", params, point.t_end, DT_OUT_MAX)
    dt_out = h if every_step else mujoco_dt_out(point.t_end, h)
    started = time.perf_counter()
    run = registry.run("mujoco-ratchet", params, point.t_end, dt_out=dt_out, until_steady=point.until_steady)
    wall = time.perf_counter() - started
    s = run.series
    peak = float(max(s["lambda1"].max(), s["lambda2"].max()))
    bound = _peak_bound(params, SimpleNamespace(stiffness=k, engine="mujoco"), run, dt_out)  # the study's own
    return (s["t"].size, peak, wall, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3, dt_out / h, bound)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--smoke", action="store_true", help="one run")
    args = parser.parse_args()
    from ipir_mujoco.core.options import STUDY_SAMPLES
    from ipir_mujoco.studies.clutch_study import BACKLASH_QUICK, STIFFNESS_QUICK

    cases = [(mu, point, k, b) for mu in (0.5, None) for point in ("cruise", "startup") for k in STIFFNESS_QUICK
             for b in BACKLASH_QUICK]
    if args.smoke:
        cases = [(0.5, "startup", 1e6, 0.0)]
    print(f"STUDY_SAMPLES = {STUDY_SAMPLES:g}; each run in a process of its own (maxrss is the run's)")
    print(f"{'mu_wall':>9s} {'point':8s} {'k N/m':>7s} {'play mm':>7s} {'n':>3s} {'samples all/capped':>20s} "
          f"{'peak all N':>11s} {'capped N':>10s} {'rel diff':>9s} {'bound':>9s} {'wall s all/capped':>18s} "
          f"{'MB all/capped':>14s}")
    worst = 0.0
    context = multiprocessing.get_context("spawn")
    for mu, point, k, b in cases:
        with context.Pool(1, maxtasksperchild=1) as pool:
            every = pool.apply(one, ((mu, point, k, b, True),))
        with context.Pool(1, maxtasksperchild=1) as pool:
            capped = pool.apply(one, ((mu, point, k, b, False),))
        diff = abs(capped[1] - every[1]) / abs(every[1])
        within = diff <= capped[5] + every[5]
        worst = max(worst, diff / max(capped[5] + every[5], 1e-300))
        print(f"{'unlimited' if mu is None else mu:>9} {point:8s} {k:7.0e} {1e3 * b:7.3g} {capped[4]:3.0f} "
              f"{every[0]:>9d}/{capped[0]:<10d} {every[1]:11.6g} {capped[1]:10.6g} {diff:9.2e} {capped[5]:9.2e} "
              f"{every[2]:8.2f}/{capped[2]:<9.2f} {every[3]:6.0f}/{capped[3]:<7.0f}"
              + ("" if within else "  OUTSIDE the bound"), flush=True)
    print(f"largest difference over its bound: {worst:.3g} (<= 1: every capped peak within the stated bound)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
