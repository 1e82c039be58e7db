"""Benchmark: a serial MuJoCo run's cost per step against MuJoCo's own step, before and after.

Run on demand (not part of the test suite):

    python bench/ratchet_step.py [--t-end 5] [--dt-out 1e-3] [--repeats 3] [--before REV|none] [--cases ...]
    python bench/ratchet_step.py --compare [--before REV]
    python bench/ratchet_step.py --smoke

The "before" engine is an old revision's, copied from git: where that is
missing (an installed package without git history) or no longer imports
against this package (its modules moved since), the bench says so in one line
and times the other variants; ``--compare`` needs it and says so. ``--smoke``
runs every case once over 0.05 s, without "before": a check that it runs, not
a measurement.

Cases (default all): 'ratchet' (the paper's case, rigid one-way clutches),
'lock' (the paper's case, locks with the paper's rule), 'lock-unilateral'
(locks that let go when they would pull), 'compliant' (the default motor with
compliant clutches, k = 1e6 N/m, 1 mm of play), each over ``--t-end`` with an
output sample every ``--dt-out`` and the timestep the engine chooses, and
'fixed-step' (the paper's ratchet, 1 s at a given 1e-4 s: 10 steps a sample,
where the per-sample work weighs most).

Per case, timed in one process, interleaved (machine load hits all alike),
best of ``--repeats``, each in microseconds per step of the run:

- plain mj_step: ``mujoco.mj_step`` alone, timed call by call along the same
  steps of the same compiled model (the run's own model, initial state and
  clutch updates; only the time inside ``mj_step`` counts, the timer's own
  cost measured and taken off);
- before: the whole ``simulate_mujoco`` call (choosing the step, building the
  model, the run, the result) of the engine at git revision ``--before``
  (default 2e6b2fe, the engine before the compiled stepper), imported from a
  temporary copy (none is kept);
- after, Python loop: this engine with ``IPIR_MUJOCO_STEPPER=python``;
- after, compiled: this engine as installed (it says if the compiled loop is
  not built).

``--compare`` times nothing: it runs the designs of
``tests/test_mujoco_stepper.py``, a crank servo and a steady-state run with the
``--before`` engine and with this one (Python loop and compiled) and says for
each whether every column, the energy audit, the accuracy record, the stall
and the settings are identical.

Calling ``mj_step`` from Python costs a little per call (the bindings' argument
checks and error guard), which the compiled engine does not pay: measured per
case as n calls against one call with ``nstep=n`` from the same state, and
taken off the plain step to give the floor, plain mj_step in a C loop. Ratios
are given to both floors; the table at the end uses the C loop (the stricter).
A run that the accuracy
monitor would stop is run with ``accuracy='warn'`` in all variants alike (the
bench times stepping, not the automatic refinement).
"""

from __future__ import annotations

import argparse
import importlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mujoco

from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine import simulate_mujoco
from ipir_mujoco.engine.loop import stepper
from ipir_mujoco.engine.clutches import clutch_controller
from ipir_mujoco.engine.builders.model import MOTOR, SolverSettings, build_model, drive_control, set_closed_loop_state
from ipir_mujoco.engine.modelkinds.timestep import choose_settings

REPOSITORY = Path(__file__).resolve().parent.parent
COMPLIANT = RobotParams(drive="motor", clutch_stiffness=1e6, clutch_backlash=1e-3)
# name: (parameters, clutch rule, MuJoCo clutch, t_end (None: --t-end), timestep (None: the engine's choice))
CASES = {
    "ratchet": (RobotParams(), "unilateral", "ratchet", None, None),
    "lock": (RobotParams(), "kinematic", "lock", None, None),
    "lock-unilateral": (RobotParams(), "unilateral", "lock", None, None),
    "compliant": (COMPLIANT, "unilateral", "ratchet", None, None),
    "fixed-step": (RobotParams(), "unilateral", "ratchet", 1.0, 1e-4),
}


def engine_at(revision: str):
    """The engine package as it was at ``revision``, imported from a temporary copy under another name, or
    None (after printing why) where git, the revision or one of its imports is missing."""
    try:
        return _engine_at(revision)
    except (OSError, subprocess.CalledProcessError, ImportError) as error:
        reason = getattr(error, "stderr", "") or f"{type(error).__name__}: {error}"
        print(f"before: the engine at {revision} is not available here ({str(reason).strip().splitlines()[-1]}); "
              "it is left out", flush=True)
        return None


def _engine_at(revision: str):
    folder = Path(tempfile.mkdtemp(prefix="ipir_engine_"))
    package = folder / "ipir_before"
    (package / "engine").mkdir(parents=True)
    listing = subprocess.run(["git", "-C", str(REPOSITORY), "ls-tree", "--name-only", revision,
                              "ipir_mujoco/engine/"], check=True, capture_output=True, text=True).stdout.split()
    for path in listing:
        if path.endswith(".py"):
            text = subprocess.run(["git", "-C", str(REPOSITORY), "show", f"{revision}:{path}"], check=True,
                                  capture_output=True, text=True).stdout
            (package / "engine" / Path(path).name).write_text(text)
    (package / "__init__.py").write_text("")
    # the engine's one import from its parent package: the MJCF folder, the installed one
    (package / "resources.py").write_text("from ipir_mujoco.resources import mjcf_dir  # noqa: F401\n")
    sys.path.insert(0, str(folder))
    return importlib.import_module("ipir_before.engine")


def timer_cost(samples: int = 200_000) -> float:
    """The cost [s] a pair of perf_counter calls adds to an interval it measures."""
    clock = time.perf_counter
    total = 0.0
    for _ in range(samples):
        t0 = clock()
        total += clock() - t0
    return total / samples


def start(case, timestep: float):
    """The run's compiled model in its initial state, with its clutch controller."""
    params, rule, implementation = case[:3]
    model = build_model(params, SolverSettings(timestep=timestep), ratchet=implementation == "ratchet")
    data = mujoco.MjData(model)
    set_closed_loop_state(model, data, params)
    controller = clutch_controller(model, data, params, implementation, rule)
    data.ctrl[model.actuator(MOTOR).id] = drive_control(params)
    mujoco.mj_forward(model, data)
    return model, data, controller


def plain_step(case, t_end: float, timestep: float, overhead: float) -> float:
    """mj_step's own time per step [s] along the run's steps (the clutch updates untimed)."""
    model, data, controller = start(case, timestep)
    before, after, step, clock = controller.before_step, controller.after_step, mujoco.mj_step, time.perf_counter
    n = int(t_end / timestep * (1 + 1e-12))
    total = 0.0
    for _ in range(n):
        before()
        t0 = clock()
        step(model, data)
        total += clock() - t0
        if after is not None:
            after()
    return total / n - overhead


def call_overhead(case, timestep: float, steps: int = 20000, repeats: int = 7) -> float:
    """What calling mj_step from Python adds per call [s]: n calls against one call with nstep=n, from the
    same state with no clutch update (so the same steps); best of ``repeats`` each."""
    per_call = in_c = float("inf")
    for _ in range(repeats):
        model, data, _ = start(case, timestep)
        started = time.perf_counter()
        for _ in range(steps):
            mujoco.mj_step(model, data)
        per_call = min(per_call, time.perf_counter() - started)
        model, data, _ = start(case, timestep)
        started = time.perf_counter()
        mujoco.mj_step(model, data, nstep=steps)
        in_c = min(in_c, time.perf_counter() - started)
    return max(per_call - in_c, 0.0) / steps


def engine_step(simulate, settings_class, case, t_end: float, dt_out: float, timestep: float, given: bool,
                python: bool = False) -> float:
    """The whole simulate_mujoco call per step [s]."""
    params, rule, implementation = case[:3]
    settings = {"settings": settings_class(timestep=timestep)} if given else {}
    previous = os.environ.get(stepper.ENV)
    os.environ[stepper.ENV] = "python" if python else ""
    try:
        started = time.perf_counter()
        simulate(params, rule, implementation, t_end, dt_out=dt_out, accuracy="warn", **settings)
        return (time.perf_counter() - started) / int(t_end / timestep * (1 + 1e-12))
    finally:
        if previous is None:
            os.environ.pop(stepper.ENV, None)
        else:
            os.environ[stepper.ENV] = previous


def compare(before, revision: str, smoke: bool = False) -> None:
    """Each design through the engine at ``revision`` and this one's two loops: identical or what differs.
    Without that engine (``before`` None) the reference is this engine's Python loop. ``smoke``: the first
    two designs over 0.05 s."""
    if before is None:
        print(f"against this engine's Python loop (no engine at {revision} here), mujoco {mujoco.__version__}")
        before = importlib.import_module("ipir_mujoco.engine")
        os.environ[stepper.ENV] = "python"
    else:
        print(f"against the engine at {revision}, mujoco {mujoco.__version__}")
    designs = {
        "ratchet, 1 s": (RobotParams(), "unilateral", "ratchet", 1.0, {}),
        "locks, paper's rule": (RobotParams(), "kinematic", "lock", 0.5, {}),
        "locks, unilateral": (RobotParams(), "unilateral", "lock", 0.5, {}),
        "compliant, motor, climb": (RobotParams(drive="motor", incline=20.0, clutch_stiffness=1e6,
                                                clutch_damping=300.0, clutch_backlash=5e-4), "unilateral", "ratchet",
                                    0.5, {}),
        "motor, 30 deg climb": (RobotParams(drive="motor", incline=30.0), "unilateral", "ratchet", 0.5, {}),
        "no clutch, downhill": (RobotParams(F_r1=0.0, F_r2=0.5, incline=-10.0), "unilateral", "none", 0.3, {}),
        "stall": (RobotParams(drive="motor", M_stall=0.02), "unilateral", "ratchet", 3.0, {}),
        "coarse step, warned": (RobotParams(), "unilateral", "ratchet", 0.5, {"timestep": 5e-4, "accuracy": "warn"}),
        "crank servo, locks": (RobotParams(), "kinematic", "lock", 0.2, {"servo": (lambda t: 10 * t, lambda t: 10.0)}),
        "motor until steady (cap 10 s)": (RobotParams(drive="motor"), "unilateral", "ratchet", 10.0,
                                          {"until_steady": True}),
    }
    if smoke:
        designs = {name: design[:3] + (0.05,) + design[4:] for name, design in list(designs.items())[:2]}
    reference_loop = os.environ.get(stepper.ENV, "")
    for name, (params, rule, implementation, t_end, options) in designs.items():
        def run(engine):
            kwargs = dict(options)
            if "servo" in kwargs:
                kwargs["servo"] = engine.CrankServo(*kwargs["servo"])
            if "timestep" in kwargs:
                step = kwargs.pop("timestep")
                kwargs.update(settings=engine.SolverSettings(timestep=step), dt_out=step)
            kwargs.setdefault("dt_out", 1e-3)
            return engine.simulate_mujoco(params, rule, implementation, t_end, **kwargs)

        os.environ[stepper.ENV] = reference_loop
        reference = run(before)
        verdicts = []
        for label, value in (("Python loop", "python"), ("compiled", "")):
            os.environ[stepper.ENV] = value
            result = run(importlib.import_module("ipir_mujoco.engine"))
            differing = [c for c in reference.series if c not in result.series
                         or not (reference.series[c] == result.series[c]).all()]
            differing += [k for k in ("energy", "accuracy", "stall", "settings", "t_end")
                          if getattr(reference, k) != getattr(result, k)]
            verdicts.append(f"{label}: {'identical' if not differing else 'differs in ' + ', '.join(differing)}")
        os.environ.pop(stepper.ENV, None)
        print(f"{name:30s} {len(reference.series['t']):6d} samples, t_end {reference.t_end:.4g} s; "
              + "; ".join(verdicts))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=5.0, help="simulated time of each run [s] (default 5)")
    parser.add_argument("--dt-out", type=float, default=1e-3, help="output interval [s] (default 1e-3)")
    parser.add_argument("--repeats", type=int, default=3, help="timings per variant; the best is kept")
    parser.add_argument("--before", default="2e6b2fe", help="git revision of the 'before' engine ('none': skip)")
    parser.add_argument("--cases", default=",".join(CASES), help=f"comma-separated, of: {', '.join(CASES)}")
    parser.add_argument("--compare", action="store_true", help="check results against --before instead of timing")
    parser.add_argument("--smoke", action="store_true", help="every case once over 0.05 s, no 'before' (a check "
                                                             "that the bench runs, not a measurement)")
    args = parser.parse_args()
    if args.smoke:
        args.t_end, args.repeats, args.before = 0.05, 1, "none"
        CASES["fixed-step"] = CASES["fixed-step"][:3] + (0.05, 1e-4)
    before = None if args.before == "none" else engine_at(args.before)
    if args.compare:
        compare(before, args.before, args.smoke)
        return
    compiled, why = stepper.compiled_status()
    overhead = timer_cost(2000 if args.smoke else 200_000)
    load = os.getloadavg()
    print(f"mujoco {mujoco.__version__}; load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} on "
          f"{os.cpu_count()} cores; best of {args.repeats}; timer cost {overhead * 1e9:.0f} ns taken off the plain "
          f"step; compiled loop: {why}")
    rows = []
    for name in args.cases.split(","):
        case = CASES[name]
        params, rule, implementation, t_end, timestep = case
        t_end = args.t_end if t_end is None else t_end
        dt_out = args.dt_out
        given = timestep is not None
        if not given:
            timestep = choose_settings(params, t_end, dt_out, None, implementation)[0].timestep
        steps = int(t_end / timestep * (1 + 1e-12))
        variants = {"plain mj_step": lambda: plain_step(case, t_end, timestep, overhead)}
        if before is not None:
            variants[f"before ({args.before})"] = lambda: engine_step(
                before.simulate_mujoco, before.SolverSettings, case, t_end, dt_out, timestep, given)
        variants["after, Python loop"] = lambda: engine_step(simulate_mujoco, SolverSettings, case, t_end, dt_out,
                                                             timestep, given, python=True)
        if compiled:
            variants["after, compiled"] = lambda: engine_step(simulate_mujoco, SolverSettings, case, t_end, dt_out,
                                                              timestep, given)
        best = dict.fromkeys(variants, float("inf"))
        for _ in range(args.repeats):
            for label, timed in variants.items():
                best[label] = min(best[label], timed())
        call = call_overhead(case, timestep, *((200, 1) if args.smoke else ()))
        floor = best["plain mj_step"] - call  # mj_step in a C loop: what the compiled engine calls
        print(f"\n{name}: {implementation} ({rule}), t_end {t_end:g} s, dt_out {dt_out:g} s, timestep "
              f"{timestep:.4g} s ({'given' if given else 'automatic'}), {steps} steps, "
              f"{round(dt_out / timestep)} a sample; calling mj_step from Python adds {call * 1e6:.3f} us a call")
        for label, seconds in best.items():
            print(f"  {label:24s} {seconds * 1e6:7.3f} us/step  {seconds / floor:5.2f} x plain in C  "
                  f"{seconds / best['plain mj_step']:5.2f} x plain from Python  {seconds * steps:7.2f} s a run")
        rows.append((name, steps, floor, best))
    labels = [k for k in rows[0][3] if k != "plain mj_step"]
    print("\nx plain mj_step in a C loop (the plain step called from Python less its call overhead):")
    print("| case | steps | plain mj_step in C [us/step] | " + " | ".join(labels) + " |")
    print("|---|---|---|" + "---|" * len(labels))
    for name, steps, floor, best in rows:
        print(f"| {name} | {steps} | {floor * 1e6:.2f} | " + " | ".join(f"{best[k] / floor:.2f}" for k in labels)
              + " |")


if __name__ == "__main__":
    main()
