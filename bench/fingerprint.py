"""Fingerprints of runs and studies: check that a refactoring changed no number, bit for bit.

Run on demand, from the repository root, before and after a change, and compare the two outputs:

    python bench/fingerprint.py > before.txt
    ... change ...
    python bench/fingerprint.py > after.txt && diff before.txt after.txt

Each line is a case and the SHA-256 of what it produced: every series column's bytes (in name
order), the energy audit, the summary and the accuracy record as canonical JSON (wall times,
software versions and the ladder rungs' wording, ``isolates``, left out). Studies (a small sweep, the
cruise study, a climb study) are fingerprinted from their JSON or CSV output with the same
exclusions. Numbers that depend on the machine's load (wall times) never enter a fingerprint;
every other figure does.

A change that adds a summary key or a parameter changes every fingerprint that holds them. To
check that it changed nothing else, leave the new names out of the later fingerprint:

    python bench/fingerprint.py --leave-out slip1_m,slip2_m,peak_grip_use,mu_wall,F_n1,F_n2 > after.txt

(every dictionary key, series column and sweep column of those names is dropped before hashing; a name
that does not occur changes nothing, so the earlier fingerprint compares as it is).

``--smoke`` fingerprints the first two runs of each kind only, in seconds (a check that the bench runs;
compare smoke fingerprints only with smoke fingerprints).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams

MOTOR = dict(drive="motor")
SERVO_EXACT = RobotParams(drive="servo", feedforward="exact")  # the speed controller, 10 rad/s, exact feedforward
# name: (params, geometry, clutch, t_end, options)
ANALYTIC = {
    "paper model 1 s": (RobotParams(), "approx", "kinematic", 1.0, {}),
    "exact kinematic 1 s": (RobotParams(), "exact", "kinematic", 1.0, {}),
    "approx unilateral 1 s": (RobotParams(), "approx", "unilateral", 1.0, {}),
    "one-way 1 s": (RobotParams(), "exact", "unilateral", 1.0, {}),
    "one-way L=0.06 dt 1 ms": (RobotParams(L=0.06), "exact", "unilateral", 1.0, {"dt_out": 1e-3}),
    "one-way m2=3 dt 1 ms": (RobotParams(m2=3.0), "exact", "unilateral", 1.0, {"dt_out": 1e-3}),
    "motor paper to steady": (RobotParams(**MOTOR), "approx", "kinematic", 30.0, {"until_steady": True}),
    "motor one-way to steady": (RobotParams(**MOTOR), "exact", "unilateral", 30.0, {"until_steady": True}),
    "motor one-way 30 deg": (RobotParams(incline=30.0, **MOTOR), "exact", "unilateral", 2.0, {}),
    "riser stall": (RobotParams(incline=90.0, M=0.25), "exact", "unilateral", 1.0, {}),
    "compliant 1e6": (RobotParams(clutch_stiffness=1e6), "exact", "unilateral", 0.5, {}),
    "compliant motor damped play to steady": (
        RobotParams(clutch_stiffness=1e5, clutch_damping=20.0, clutch_backlash=5e-4, **MOTOR), "exact",
        "unilateral", 10.0, {"until_steady": True, "dt_out": 1e-3}),
    "compliant incline 25": (RobotParams(M=0.4, incline=25.0, clutch_stiffness=1e6, clutch_damping=20.0,
                                         clutch_backlash=5e-4, phi0=0.7), "exact", "unilateral", 0.5, {}),
    "servo PI one-way 1 s": (RobotParams(drive="servo"), "exact", "unilateral", 1.0, {"dt_out": 1e-3}),
    "servo exact ff paper rule 1 s": (SERVO_EXACT, "approx", "kinematic", 1.0, {"dt_out": 1e-3, "feedforward": True}),
}
# name: (params, clutch rule, implementation, t_end, options)
MUJOCO = {
    "mujoco ratchet 1 s": (RobotParams(), "unilateral", "ratchet", 1.0, {"dt_out": 1e-3}),
    "mujoco lock kinematic 1 s": (RobotParams(), "kinematic", "lock", 1.0, {"dt_out": 1e-3}),
    "mujoco lock unilateral 1 s": (RobotParams(), "unilateral", "lock", 0.5, {"dt_out": 1e-3}),
    "mujoco ratchet motor to steady": (RobotParams(**MOTOR), "unilateral", "ratchet", 10.0,
                                       {"dt_out": 1e-3, "until_steady": True}),
    "mujoco compliant motor incline": (RobotParams(clutch_stiffness=1e5, clutch_damping=5.0, incline=20.0, **MOTOR),
                                       "unilateral", "ratchet", 1.0, {"dt_out": 1e-3}),
    "mujoco riser stall": (RobotParams(incline=90.0), "unilateral", "ratchet", 1.0, {"dt_out": 1e-3}),
    "mujoco servo exact ff 1 s": (SERVO_EXACT, "unilateral", "ratchet", 1.0, {"dt_out": 1e-3, "feedforward": True}),
    "mujoco grip ratchet motor": (RobotParams(mu_wall=0.5, F_n1=10.0, F_n2=10.0, **MOTOR), "unilateral", "ratchet",
                                  0.3, {"dt_out": 1e-3}),
    "mujoco compliant grip motor": (RobotParams(clutch_stiffness=1e6, mu_wall=0.5, F_n1=10.0, F_n2=10.0, **MOTOR),
                                    "unilateral", "ratchet", 0.3, {"dt_out": 1e-3}),
    "mujoco wheels motor": (RobotParams(mu_wall=0.8, **MOTOR), "unilateral", "ratchet", 0.2,
                            {"dt_out": 1e-3, "model": "wheels", "settings": "1e-4"}),
}
# name: (variant, params, t_end, options): through registry.run (what it adds: every_step, the variant's kind)
REGISTRY = {
    "wheels riser skids every step": ("mujoco-wheels", RobotParams(mu_wall=0.18, incline=90.0, **MOTOR), 0.04,
                                      {"every_step": True}),
    "wheels skid 1e-4 s": ("mujoco-wheels", RobotParams(mu_wall=0.18, incline=90.0, **MOTOR), 0.1,
                           {"dt_out": 1e-3, "timestep": 1e-4}),
    "grip riser skids every step": ("mujoco-ratchet", RobotParams(M_stall=1.0, incline=90.0, mu_wall=0.3, F_n1=20.0,
                                                                  F_n2=20.0, **MOTOR), 0.1, {"every_step": True}),
}


LEFT_OUT: set[str] = set()  # names --leave-out drops from every dictionary and the sweep's columns


def _clean(value):
    """JSON-ready ``value`` without wall times and versions (machine-dependent)."""
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in sorted(value.items())
                if not (k.startswith("wall") or k.endswith("_wall")
                        or k in ("versions", "workers", "mujoco_version", "isolates"))
                and k not in LEFT_OUT}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        return value.item()
    return value


def digest_json(value) -> str:
    return hashlib.sha256(json.dumps(_clean(value), sort_keys=True, default=str).encode()).hexdigest()[:16]


def digest_run(run) -> str:
    h = hashlib.sha256()
    for name in sorted(run.series):
        if name in LEFT_OUT:
            continue
        h.update(name.encode())
        h.update(np.ascontiguousarray(run.series[name]).tobytes())
    h.update(digest_json({"energy": run.energy, "summary": run.summary, "accuracy": run.accuracy,
                          "stall": run.stall, "t_end": run.t_end}).encode())
    return h.hexdigest()[:16]


def _with_table(params, options: dict) -> dict:
    """``options`` with ``feedforward: True`` replaced by the servo's table (computed as registry.run does)."""
    if not options.get("feedforward"):
        return options
    from ipir_mujoco.registry import feedforward_table

    return {**options, "feedforward": feedforward_table(params)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-studies", action="store_true")
    parser.add_argument("--leave-out", default="", metavar="NAME,...",
                        help="summary keys and parameters to leave out (names added since the fingerprint compared)")
    parser.add_argument("--smoke", action="store_true", help="the first two runs only, in seconds (a check that "
                        "it runs; compare smoke fingerprints only with smoke fingerprints)")
    args = parser.parse_args()
    LEFT_OUT.update(name for name in args.leave_out.split(",") if name)
    from ipir_mujoco.engine import simulate_mujoco

    smoke = slice(0, 2 if args.smoke else None)
    for name, (params, geometry, clutch, t_end, options) in list(ANALYTIC.items())[smoke]:
        options = _with_table(params, options)
        print(f"{name:45s} {digest_run(analytic.simulate(params, geometry, clutch, t_end, **options))}", flush=True)
    for name, (params, rule, implementation, t_end, options) in list(MUJOCO.items())[smoke]:
        options = _with_table(params, options)
        if options.get("settings") is not None:
            from ipir_mujoco.engine import SolverSettings

            options = {**options, "settings": SolverSettings(timestep=float(options["settings"]))}
        print(f"{name:45s} {digest_run(simulate_mujoco(params, rule, implementation, t_end, **options))}", flush=True)
    from ipir_mujoco import registry

    for name, (variant, params, t_end, options) in list(REGISTRY.items())[smoke]:
        print(f"{name:45s} {digest_run(registry.run(variant, params, t_end, **options))}", flush=True)
    if args.skip_studies or args.smoke:
        return 0
    from ipir_mujoco.studies.climbing import climb_study
    from ipir_mujoco.studies.cruise import cruise_study
    from ipir_mujoco.studies.sweep import run_sweep
    from ipir_mujoco.studies.sweep_space import Study, parse_vary

    with tempfile.TemporaryDirectory() as folder:
        study = Study(base=RobotParams(), axes=(parse_vary("L=0.1,0.3"), parse_vary("m2=0.5,2")),
                      engines=("mujoco-ratchet", "analytic-unilateral", "analytic-approx", "mujoco-lock"))
        csv = run_sweep(study, Path(folder) / "sweep", progress=False, workers=1)
        rows = csv.read_text().splitlines()
        header = rows[0].split(",")
        keep = [i for i, c in enumerate(header) if "wall" not in c and c.rsplit(":", 1)[-1] not in LEFT_OUT]
        print(f"{'sweep 2 x 2, 4 engines':45s} {digest_json([[r.split(',')[i] for i in keep] for r in rows])}")
    print(f"{'cruise study quick':45s} {digest_json(cruise_study(RobotParams(), quick=True, workers=1))}", flush=True)
    climb = climb_study(RobotParams(drive="motor"), [0.0, 30.0], tolerance=10.0)
    print(f"{'climb study motor':45s} {digest_json(climb)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
