"""Benchmark: the analytic and MuJoCo engines where the wheels' grip binds.

Run on demand (not part of the test suite):

    python bench/grip_agreement.py [--smoke]

``--smoke`` runs the riser over 0.05 s only (a check that it runs, not a measurement).

Two cases, each run through the registry as the studies run them:

- the default motor's cruise (drive = motor) on mu_wall = 0.5, F_n1 = F_n2 = 10 N (5 N of grip against
  ~12 N of demand), both engines to their steady state (10 s cap, output every 1 ms): the steady speed, and
  the skid per revolution over the last three revolutions MuJoCo ran (the same crank revolutions in both
  runs), with MuJoCo's own error estimate from the same run at half its step (Richardson, first order:
  2 |s(dt) - s(dt/2)|) and the tolerance tests/test_mujoco_grip.py allows (1.5 times that plus the
  carriage's inertia share);
- a vertical riser on too little grip (incline 90, mu_wall = 0.3, F_n = 20 N: 6 N per module against the
  robot's 19.7 N weight) with a motor that turns the crank (M_stall = 1 N m), 1 s: the travel of both
  modules, which slide back.
"""

from __future__ import annotations

import argparse

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.core.cycles import _at, cycle_boundaries
from ipir_mujoco.engine import SolverSettings, simulate_mujoco
from ipir_mujoco.engine.builders.grip_model import CARRIAGE_SHARE

CRUISE = RobotParams(drive="motor", mu_wall=0.5, F_n1=10.0, F_n2=10.0)
RISER = RobotParams(drive="motor", M_stall=1.0, incline=90.0, mu_wall=0.3, F_n1=20.0, F_n2=20.0)


def skid_per_rev(run, first: int, last: int) -> list[float]:
    """Each module's skid [m] per revolution over the crank's whole revolutions first..last."""
    s = run.series
    ends, _ = cycle_boundaries(s["t"], s["phi"])
    edges = np.concatenate([[s["t"][0]], ends])[[first, last]]
    return [float(np.diff(_at(s["t"], s[f"slip{k}"], edges))[0]) / (last - first) for k in (1, 2)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--smoke", action="store_true", help="the riser over 0.05 s only, in seconds (not a "
                                                             "measurement)")
    if parser.parse_args().smoke:
        riser(0.05)
        return
    analytic = registry.run("analytic-unilateral", CRUISE, 10.0, dt_out=1e-3, until_steady=True)
    mujoco_ = registry.run("mujoco-ratchet", CRUISE, 10.0, dt_out=1e-3, until_steady=True)
    a, m = analytic.summary, mujoco_.summary
    print("cruise on 5 N of grip (default motor, mu_wall 0.5, F_n 10 N), to the steady state:")
    for name, s in (("analytic-unilateral", a), ("mujoco-ratchet", m)):
        print(f"  {name:20s} steady {s['steady']} after {s['cycles']} rev, speed {s['steady_speed_m_s']:.7f} m/s, "
              f"slip {1e3 * s['slip1_m']:.3f} / {1e3 * s['slip2_m']:.3f} mm, peak grip use {s['peak_grip_use']:.5f}")
    print(f"  steady speed: MuJoCo {m['steady_speed_m_s'] / a['steady_speed_m_s'] - 1:+.2e} (allowed 0.5 %)")
    last = m["cycles"]
    dt = mujoco_.settings["timestep"]
    half = simulate_mujoco(CRUISE, "unilateral", "ratchet", mujoco_.t_end, dt_out=1e-3,
                           settings=SolverSettings(timestep=dt / 2))
    for k, (s_an, s_mj, s_half) in enumerate(zip(skid_per_rev(analytic, last - 3, last),
                                                  skid_per_rev(mujoco_, last - 3, last),
                                                  skid_per_rev(half, last - 3, last)), start=1):
        richardson = 2 * abs(s_mj - s_half) / s_an
        print(f"  module {k} skid per revolution (revolutions {last - 3}..{last}): analytic {1e3 * s_an:.5f} mm, "
              f"MuJoCo {1e3 * s_mj:.5f} mm ({s_mj / s_an - 1:+.2e}; at dt/2 {s_half / s_an - 1:+.2e}); "
              f"Richardson {richardson:.2e}, allowed {1.5 * richardson + CARRIAGE_SHARE:.2e}")
    riser(1.0)


def riser(t_end: float) -> None:
    print(f"riser on 6 N of grip per module (incline 90, mu_wall 0.3, F_n 20 N, M_stall 1 N m), {t_end:g} s:")
    # --smoke's 0.05 s: MuJoCo's skid-accuracy check would ask a finer step than the smoke needs: warn only
    warn = {"accuracy": "warn"} if t_end < 1.0 else {}
    runs = [registry.run(v, RISER, t_end, dt_out=1e-3, **(warn if v.startswith("mujoco") else {}))
            for v in ("analytic-unilateral", "mujoco-ratchet")]
    for name, run in zip(("analytic-unilateral", "mujoco-ratchet"), runs):
        s = run.summary
        print(f"  {name:20s} x1 {s['x1_final']:+.5f} m, x2 {s['x2_final']:+.5f} m, slip {s['slip1_m']:.5f} / "
              f"{s['slip2_m']:.5f} m, {s['revolutions']:.4f} rev")
    for key in ("x1_final", "x2_final"):
        print(f"  {key}: MuJoCo {runs[1].summary[key] / runs[0].summary[key] - 1:+.2e} (allowed 2 %)")


if __name__ == "__main__":
    main()
