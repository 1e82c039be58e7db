"""Benchmark: the analytic engines before and after the compiled stepper, every target of issue 15.

Run on demand (not part of the test suite), from the repository root:

    python bench/analytic_speed.py [--before REV|none] [--repeats R] [--skip-long] [--smoke]

"Before" is the analytic package at git revision REV (default: 5590109, the
last main on solve_ivp, before the compiled stepper), copied
from git into a temporary folder and imported from there under another name
(nothing is committed or installed); "after" is the installed one. The old
package has fewer parameters: a case whose parameters it does not know at
their defaults runs "after" only; without git history (an installed package)
or with ``--before none`` every case runs "after" only, and the bench says so.
``--smoke`` runs each code path once in seconds (1 repeat, the 1 s cases cut
to 0.05 s, no long cases, no child processes): a check that the bench runs,
not a measurement. Both run
the same cases, interleaved in one process so machine load affects them alike;
each time is the best of R runs (10 s cases: one run before, three after). Printed:
absolute wall times, the ratio after/before, each engine's 10 s / 1 s ratio
with the ratio of crank revolutions beside it (the work an event-driven solver
must do grows with the revolutions, not with the time), and a Markdown table
for the README. Separately, in child processes: the first call's cost with an
empty numba cache and with a warm one, and the Python fallback
(IPIR_MUJOCO_JIT=0).
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.analytic import accel

ROOT = Path(__file__).resolve().parents[1]
BEFORE = "5590109"  # the last main whose analytic models integrate with solve_ivp
MOTOR = dict(drive="motor")
# name: (params, geometry, clutch, t_end, options); "motor to steady state" caps at 30 s
CASES = {
    "paper model (approx, kinematic), 1 s": (RobotParams(), "approx", "kinematic", 1.0, {}),
    "one-way model (exact, unilateral), 1 s": (RobotParams(), "exact", "unilateral", 1.0, {}),
    "paper model, 10 s": (RobotParams(), "approx", "kinematic", 10.0, {}),
    "one-way model, 10 s": (RobotParams(), "exact", "unilateral", 10.0, {}),
    "compliant clutch 1e6 N/m (exact), 1 s": (RobotParams(clutch_stiffness=1e6), "exact", "unilateral", 1.0, {}),
    "motor, paper model, to steady state": (RobotParams(**MOTOR), "approx", "kinematic", 30.0,
                                            {"until_steady": True}),
    "motor, one-way model, to steady state": (RobotParams(**MOTOR), "exact", "unilateral", 30.0,
                                              {"until_steady": True}),
    "motor, one-way model, 1 s": (RobotParams(**MOTOR), "exact", "unilateral", 1.0, {}),
    "motor, one-way model, 10 s": (RobotParams(**MOTOR), "exact", "unilateral", 10.0, {}),
    # a sweep's design: samples every 1 ms (the cases above keep the default 0.1 ms, whose per-sample
    # post-processing weighs on a 1 s one-way run: the two cases side by side show how much)
    "one-way model, 1 s, dt_out 1 ms (a sweep design)": (RobotParams(), "exact", "unilateral", 1.0, {"dt_out": 1e-3}),
    **{f"one-way model, 1 s, dt_out 1 ms, {k}={v:g}": (RobotParams(**{k: v}), "exact", "unilateral", 1.0,
                                                       {"dt_out": 1e-3})
       for k, v in (("L", 0.06), ("L", 0.5), ("m2", 3.0))},
    "motor, one-way model, 1 s, dt_out 1 ms": (RobotParams(**MOTOR), "exact", "unilateral", 1.0, {"dt_out": 1e-3}),
    "motor, one-way model, 10 s, dt_out 1 ms": (RobotParams(**MOTOR), "exact", "unilateral", 10.0, {"dt_out": 1e-3}),
    # at its steady speed (reached in the first seconds) the motor's crank turns as fast at 20 s as at 10 s
    "motor, one-way model, 20 s, dt_out 1 ms": (RobotParams(**MOTOR), "exact", "unilateral", 20.0, {"dt_out": 1e-3}),
}
LONG = {"paper model, 10 s", "one-way model, 10 s", "motor, one-way model, 10 s",
        "motor, one-way model, 10 s, dt_out 1 ms", "motor, one-way model, 20 s, dt_out 1 ms"}
PAIRS = [("paper model (approx, kinematic), 1 s", "paper model, 10 s"),
         ("one-way model (exact, unilateral), 1 s", "one-way model, 10 s"),
         ("motor, one-way model, 1 s", "motor, one-way model, 10 s"),
         ("motor, one-way model, 1 s, dt_out 1 ms", "motor, one-way model, 10 s, dt_out 1 ms"),
         ("motor, one-way model, 10 s, dt_out 1 ms", "motor, one-way model, 20 s, dt_out 1 ms")]


def load_before(rev: str, folder: Path):
    """The analytic package at ``rev`` as the module ``analytic_before`` (relative imports only), or None
    (after printing why) where ``rev`` is 'none', git or the revision is missing, or it does not import."""
    if rev == "none":
        print("before: none asked for (--before none); every case runs after only")
        return None
    target = folder / "analytic_before"
    target.mkdir()
    try:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "analytic"], capture_output=True,
                                 check=True)
        subprocess.run(["tar", "-x", "--strip-components=1", "-C", str(target)], input=archive.stdout, check=True)
        sys.path.insert(0, str(folder))
        return importlib.import_module("analytic_before")
    except (OSError, subprocess.CalledProcessError, ImportError) as error:
        reason = getattr(error, "stderr", b"") or str(error)
        reason = reason.decode(errors="replace") if isinstance(reason, bytes) else reason
        print(f"before: the analytic package at {rev} is not available here ({reason.strip().splitlines()[-1]}); "
              "every case runs after only")
        return None


def old_params(engine, params):
    """``params`` in the old package's dataclass, or None where it sets a field the old one does not have
    to other than its default (the old package cannot run that case)."""
    known = {f.name for f in dataclasses.fields(engine.RobotParams)}
    default = RobotParams()
    if any(getattr(params, k) != getattr(default, k) for k in params.as_dict() if k not in known):
        return None
    return engine.RobotParams(**{k: v for k, v in params.as_dict().items() if k in known})


def best(engine, case, repeats):
    """(best wall time [s] of ``repeats`` runs, the last run), or (None, None) if the old package at
    ``engine`` is None or cannot run the case."""
    params, geometry, clutch, t_end, options = case
    if engine is None:
        return None, None
    if engine.__name__ == "analytic_before":  # the same parameters in the old package's dataclass
        params = old_params(engine, params)
        if params is None:
            return None, None
    times, run = [], None
    for _ in range(repeats):
        started = time.perf_counter()
        run = engine.simulate(params, geometry, clutch, t_end, **options)
        times.append(time.perf_counter() - started)
    return min(times), run


def child(code: str, env: dict) -> dict:
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env={**os.environ, **env},
                          cwd=ROOT, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


FIRST_CALL = """
import json, time
t0 = time.perf_counter()
from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams
t1 = time.perf_counter()
analytic.simulate(RobotParams(), "approx", "kinematic", 1.0)
t2 = time.perf_counter()
analytic.simulate(RobotParams(), "exact", "unilateral", 1.0)
analytic.simulate(RobotParams(clutch_stiffness=1e6), "exact", "unilateral", 0.05)
t3 = time.perf_counter()
analytic.simulate(RobotParams(), "approx", "kinematic", 1.0)
t4 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "first": t2 - t1, "others": t3 - t2, "again": t4 - t3}))
"""
FALLBACK = """
import json, time
from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.analytic import accel
out = {"accelerated": accel.ACCELERATED}
for name, g, c, p in (("paper", "approx", "kinematic", RobotParams()),
                      ("one-way", "exact", "unilateral", RobotParams()),
                      ("compliant", "exact", "unilateral", RobotParams(clutch_stiffness=1e6))):
    times = []
    for _ in range(3):
        s = time.perf_counter(); analytic.simulate(p, g, c, 1.0); times.append(time.perf_counter() - s)
    out[name] = min(times)
print(json.dumps(out))
"""


def smoke_cases() -> dict:
    """The 1 s cases cut to 0.05 s (the steady-state ones to a 0.05 s cap), for --smoke."""
    return {name: (params, geometry, clutch, 0.05, options) for name, (params, geometry, clutch, t_end, options)
            in CASES.items() if name not in LONG}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default=BEFORE, help="git revision of the 'before' analytic package ('none': "
                                                          "after only)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--skip-long", action="store_true", help="skip the 10 s cases before (about 40 s)")
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args()
    cases, repeats = (smoke_cases(), 1) if args.smoke else (CASES, args.repeats)
    print(f"numba compiled kernels: {accel.accelerate()}; before = {args.before}; best of {repeats}; "
          f"machine load (1 min) {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores"
          + ("; --smoke: cases cut to 0.05 s, not a measurement" if args.smoke else ""))
    with tempfile.TemporaryDirectory() as folder:
        before = load_before(args.before, Path(folder))
        best(analytic, cases["paper model (approx, kinematic), 1 s"], 1)  # load the compiled kernels once
        rows = {}
        for name, case in cases.items():
            long = name in LONG
            old = (None, None) if long and args.skip_long else best(before, case, 1 if long else repeats)
            new = best(analytic, case, 3 if long else repeats)
            rows[name] = (old, new)
            ratio = f"{new[0] / old[0]:7.3f}" if old[0] else "      -"
            print(f"{name:48s} before {old[0] or float('nan'):8.3f} s  after {new[0] * 1e3:8.1f} ms  "
                  f"after/before {ratio}  revolutions {new[1].summary['revolutions']:8.2f}  "
                  f"t_end {new[1].t_end:6.3f} s", flush=True)
            if old[1] is not None:
                check = max(abs(new[1].summary[k] - old[1].summary[k]) / max(abs(old[1].summary[k]), 1e-12)
                            for k in ("revolutions", "x1_final", "x2_final"))
                print(f"{'':48s} same run: revolutions, x1, x2 agree to {check:.1e} relative")
    pairs = [pair for pair in PAIRS if all(name in rows for name in pair)]
    if pairs:
        print("\ncost linear in the work: a longer run against a shorter one")
    for short, long in pairs:
        (old1, new1), (old10, new10) = rows[short], rows[long]
        revs = new10[1].summary["revolutions"] / new1[1].summary["revolutions"]
        before_ratio = f"{old10[0] / old1[0]:6.1f}x" if old10[0] and old1[0] else "     -"
        print(f"{long:40s} before {before_ratio}  after {new10[0] / new1[0]:6.1f}x  revolutions {revs:6.1f}x  "
              f"after per revolution: {new1[0] / new1[1].summary['revolutions'] * 1e3:.2f} ms "
              f"({new1[1].t_end:g} s), {new10[0] / new10[1].summary['revolutions'] * 1e3:.2f} ms "
              f"({new10[1].t_end:g} s)")
    if not args.smoke:  # child processes: a cold numba cache compiles for 12-15 s
        with tempfile.TemporaryDirectory() as cache:
            cold = child(FIRST_CALL, {"NUMBA_CACHE_DIR": cache, "IPIR_MUJOCO_JIT": "1"})
            warm = child(FIRST_CALL, {"NUMBA_CACHE_DIR": cache, "IPIR_MUJOCO_JIT": "1"})
        print("\nfirst call in a new process (paper model 1 s; then the one-way and compliant models' first runs):")
        for label, t in (("empty numba cache", cold), ("warm numba cache", warm)):
            print(f"  {label:18s} import {t['import']:.2f} s, first run {t['first']:.2f} s, other models' first "
                  f"runs {t['others']:.2f} s, the same run again {t['again'] * 1e3:.1f} ms")
        fallback = child(FALLBACK, {"IPIR_MUJOCO_JIT": "0"})
        old = {k: rows[n][0][0] for k, n in (("paper", "paper model (approx, kinematic), 1 s"),
                                             ("one-way", "one-way model (exact, unilateral), 1 s"),
                                             ("compliant", "compliant clutch 1e6 N/m (exact), 1 s"))}
        print("Python fallback (IPIR_MUJOCO_JIT=0), 1 s: " + ", ".join(
            f"{k} {fallback[k] * 1e3:.0f} ms" + (f" ({fallback[k] / old[k]:.2f} of before)" if old[k] else "")
            for k in old))
    print("\n| case | before | after | after/before |\n|---|---:|---:|---:|")
    for name, ((t_old, _), (t_new, _)) in rows.items():
        before_time = f"{t_old:.3f} s" if t_old else "-"
        ratio = f"{t_new / t_old:.3f}" if t_old else "-"
        print(f"| {name} | {before_time} | {t_new * 1e3:.1f} ms | {ratio} |")


if __name__ == "__main__":
    main()
