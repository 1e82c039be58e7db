"""The wheeled MuJoCo model's settings, by a convergence study: cone, impratio, noslip, solref/solimp, timestep.

Run on demand from the repository root (about a minute on 2 idle cores, several on a loaded machine):

    python bench/wheels_convergence.py [--quick] [--smoke]

Three cases, each stepped by hand with the engine's own hub ratchets (``ipir_mujoco.engine.wheels``) on the
wheeled model built from the package's defaults but for the setting varied:

- ``cruise``: the default motor, mu_wall 0.8, F_n 50 N (no skid), 1 s: module 1's travel [m] and the crank's
  revolutions;
- ``skid``: a vertical riser, the default motor, mu_wall 0.18 (grip 9 N per module against a weight of
  9.81 N), 0.5 s: each module's displacement [m] (both skid down);
- ``hold``: a vertical riser with the crank's drive off (M = 0) and mu_wall 0.8: the robot hangs on its locked
  wheels, 0.3 s: the modules' mean creep speed over the last 0.2 s [m/s] (Coulomb's law: 0).

Each row prints the case, the setting, the figures, and the analytic finite-grip model's where it has one.
The table in mjcf/README.md ("Wheels in contact") is this script's output.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import mujoco

from ipir_mujoco import registry
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.engine.model import MOTOR, SolverSettings, drive_control, qpos_address
from ipir_mujoco.engine.wheels import WheelRatchet
from ipir_mujoco.engine.wheels_model import ContactSettings, build_wheels_model, set_wheels_state

CASES = {
    "cruise": (RobotParams(drive="motor", mu_wall=0.8), 1.0),
    "skid": (RobotParams(drive="motor", mu_wall=0.18, incline=90.0), 0.5),
    "hold": (RobotParams(M=0.0, mu_wall=0.8, incline=90.0), 0.3),
}
DEFAULT = dict(dt=2.5e-5, tc=None, solimp=(0.9999, 0.9999, 0.001), cone="elliptic", impratio=1.0, noslip=10)
# (label, changes from DEFAULT)
VARIANTS = [
    ("default: dt 2.5e-5, tc 2 dt, solimp 0.9999, elliptic, impratio 1, noslip 10", {}),
    ("dt 1e-4", {"dt": 1e-4}),
    ("dt 5e-5", {"dt": 5e-5}),
    ("dt 1.25e-5", {"dt": 1.25e-5}),
    ("pyramidal cone", {"cone": "pyramidal"}),
    ("impratio 10", {"impratio": 10.0}),
    ("noslip 0", {"noslip": 0}),
    ("noslip 0, impratio 10", {"noslip": 0, "impratio": 10.0}),
    ("solref time constant 0.002 s", {"tc": 0.002}),
    ("solref 0.02 s, solimp 0.9 0.95 (MuJoCo's defaults)", {"tc": 0.02, "solimp": (0.9, 0.95, 0.001)}),
]
QUICK = {"default: dt 2.5e-5, tc 2 dt, solimp 0.9999, elliptic, impratio 1, noslip 10", "dt 1e-4", "dt 5e-5",
         "noslip 0"}


def run_case(case: str, label: str, changes: dict, t_end: float | None = None) -> dict:
    """One case at one setting, over the case's time or ``t_end`` [s] (more than 0.1 s: the hold's creep is
    measured after 0.1 s)."""
    s = {**DEFAULT, **changes}
    params, case_t_end = CASES[case]
    t_end = case_t_end if t_end is None else t_end
    settings = SolverSettings(timestep=s["dt"], constraint_time_constant=s["tc"], solimp=s["solimp"])
    contact = ContactSettings(cone=s["cone"], impratio=s["impratio"], noslip_iterations=s["noslip"])
    m = build_wheels_model(params, settings, contact)
    d = mujoco.MjData(m)
    set_wheels_state(m, d, params)
    d.ctrl[m.actuator(MOTOR).id] = drive_control(params)
    mujoco.mj_forward(m, d)
    ratchet = WheelRatchet(m, d, params)
    x = [qpos_address(m, n) for n in ("rear_slide", "front_slide")]
    crank = qpos_address(m, "crank_hinge")
    n = math.floor(t_end / s["dt"] * (1 + 1e-12))
    mark = math.floor(0.1 / s["dt"])
    x_mark = None
    started = time.perf_counter()
    for k in range(n):
        ratchet.before_step()
        mujoco.mj_step(m, d)
        if k + 1 == mark:
            x_mark = [float(d.qpos[a]) for a in x]
    out = {"case": case, "setting": label, "wall_s": time.perf_counter() - started,
           "x1": float(d.qpos[x[0]]), "x2": float(d.qpos[x[1]]), "rev": float(d.qpos[crank]) / (2 * math.pi),
           "warnings": int(sum(w.number for w in d.warning))}
    if case == "hold":
        out["creep_m_s"] = max(abs(float(d.qpos[a]) - x0) for a, x0 in zip(x, x_mark)) / (t_end - 0.1)
    return out


def analytic_rows(t_end: float | None = None) -> dict:
    rows = {}
    for case in ("cruise", "skid"):
        params, case_t_end = CASES[case]
        t_end = case_t_end if t_end is None else t_end
        a = registry.run("analytic-unilateral", params, t_end, dt_out=1e-3)
        rows[case] = {"x1": a.summary["x1_final"], "x2": a.summary["x2_final"], "rev": a.summary["revolutions"]}
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the timestep and noslip rows only")
    parser.add_argument("--smoke", action="store_true", help="every code path once, in seconds (not a measurement)")
    args = parser.parse_args(argv)
    t_end = 0.11 if args.smoke else None  # --smoke: the default setting only, each case over 0.11 s
    jobs = [(case, label, changes, t_end) for label, changes in VARIANTS[:1 if args.smoke else None]
            if not args.quick or label in QUICK for case in CASES]
    with ProcessPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(run_case, *zip(*jobs)))
    reference = analytic_rows(t_end)
    print("| case | setting | module 1 [m] | module 2 [m] | revolutions | creep [m/s] | wall [s] |")
    print("|---|---|---|---|---|---|---|")
    for case in CASES:
        if case in reference:
            r = reference[case]
            print(f"| {case} | analytic finite-grip model | {r['x1']:.5f} | {r['x2']:.5f} | {r['rev']:.4f} | | |")
        for row in (r for r in results if r["case"] == case):
            creep = f"{row['creep_m_s']:.2e}" if "creep_m_s" in row else ""
            warn = " (MuJoCo warned)" if row["warnings"] else ""
            print(f"| {case} | {row['setting']}{warn} | {row['x1']:.5f} | {row['x2']:.5f} | {row['rev']:.4f} | "
                  f"{creep} | {row['wall_s']:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
