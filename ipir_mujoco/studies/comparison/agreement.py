"""Do the two engines agree on random designs across the whole envelope, or say why not?

The package's promise is that every number it prints is right within a stated
tolerance or refused with a reason. This study draws random valid designs over
every effect both engines model (constant torque or the motor, inclines from
-90 to 90 degrees, rigid or compliant clutches with damping and play, the
geometry and masses over wide ranges), runs the analytic one-way model (exact
geometry) and MuJoCo's ratchet (or its compliant clutch) at their default
settings, and sorts each design into:

- ``agree``: both finished and MuJoCo is within :data:`TIGHT` (0.1 %) of the
  analytic model in revolutions and in travel (revolutions compared against
  max(|revolutions|, 1), travel against max(|travel|, 2 r), one revolution's
  stroke, so a robot that barely moves is not judged on a ratio of two small
  numbers);
- ``agree-1%``: within :data:`LOOSE` (1 %), outside 0.1 %;
- ``refused`` / ``failed``: an engine refused the design (ParameterError) or
  stopped with a SimulationError (accuracy monitor, instability, budget), each
  with its one-line reason;
- ``DISAGREE``: both finished without complaint and differ by more than 1 %:
  a silent disagreement, the case this study exists to find.

Designs (:func:`draw`, numpy's ``default_rng(seed)``): log-uniform m1, m2 in
[0.1, 10] kg, r in [0.005, 0.1] m, L / r in [1.5, 30], J_A in [2e-5, 5e-2]
kg m^2, rod_mass in [1e-3, 0.3] kg; uniform F_r1, F_r2 in [0, 20] N and phi0 in
[0, 2 pi) rad; the robot starts at rest; half the designs under a constant
torque M (log-uniform [0.05, 5] N m), half under the motor (M_stall
log-uniform [0.05, 5] N m, omega_noload [3, 100] rad/s); half in a horizontal
pipe, half at an incline uniform in [-90, 90] degrees; a third with compliant
clutches (stiffness log-uniform [1e4, 1e7] N/m, damping 0 or log-uniform
[1, 100] N s/m, backlash 0 or uniform up to 2 % of the stroke).

``python bench/agreement_random.py`` runs it over many designs in parallel
(the figures quoted in README.md and mjcf/README.md).
"""

from __future__ import annotations

import math
import time

import numpy as np

from ipir_mujoco import registry
from ipir_mujoco.analytic import ParameterError, RobotParams, SimulationError

TIGHT, LOOSE = 1e-3, 1e-2  # relative: the 0.1 % the convergence evidence promises; a clear disagreement


def draw(rng: np.random.Generator) -> RobotParams:
    """One random valid design (module docstring)."""
    log = lambda lo, hi: float(math.exp(rng.uniform(math.log(lo), math.log(hi))))  # noqa: E731
    r = log(0.005, 0.1)
    values = dict(m1=log(0.1, 10), m2=log(0.1, 10), r=r, L=r * log(1.5, 30), J_A=log(2e-5, 5e-2),
                  F_r1=float(rng.uniform(0, 20)), F_r2=float(rng.uniform(0, 20)), rod_mass=log(1e-3, 0.3),
                  phi0=float(rng.uniform(0, 2 * math.pi)), omega0=0.0)
    if rng.uniform() < 0.5:
        values.update(drive="torque", M=log(0.05, 5))
    else:
        values.update(drive="motor", M_stall=log(0.05, 5), omega_noload=log(3, 100))
    if rng.uniform() < 0.5:
        values["incline"] = float(rng.uniform(-90, 90))
    if rng.uniform() < 1 / 3:
        values["clutch_stiffness"] = log(1e4, 1e7)
        if rng.uniform() < 0.5:
            values["clutch_damping"] = log(1, 100)
        if rng.uniform() < 0.5:
            values["clutch_backlash"] = float(rng.uniform(0, 0.02 * 2 * r))
    return RobotParams(**values)


def run_pair(params: RobotParams, t_end: float, budget_s: float | None = None) -> dict:
    """Both engines on one design: {'analytic': (status, value), 'mujoco': ..., '<engine>_wall': s,
    '<engine>_summary': the run's summary dict, or None where it was refused or failed}.

    status 'ok' with (revolutions, travel [m]), or 'refused' / 'failed' with the engine's one-line reason.
    """
    row: dict = {"params": params}
    for name, variant in (("analytic", "analytic-unilateral"), ("mujoco", "mujoco-ratchet")):
        started, row[name + "_summary"] = time.perf_counter(), None
        try:
            run = registry.run(variant, params, t_end, dt_out=1e-3, wall_budget_s=budget_s)
        except ParameterError as exc:
            row[name] = ("refused", str(exc))
        except SimulationError as exc:
            row[name] = ("failed", str(exc))
        else:
            s = row[name + "_summary"] = run.summary
            row[name] = ("ok", (s["revolutions"], 0.5 * (s["x1_final"] + s["x2_final"])))
        row[name + "_wall"] = time.perf_counter() - started
    return row


def judge(row: dict) -> tuple[str, str, float | None]:
    """(verdict, one-line detail, worst relative difference or None) of a :func:`run_pair` row."""
    (sa, va), (sm, vm) = row["analytic"], row["mujoco"]
    if sa != "ok" or sm != "ok":
        why = "; ".join(f"{n}: {v}" for n, (s, v) in (("analytic", row["analytic"]), ("mujoco", row["mujoco"]))
                        if s != "ok")
        return ("refused" if "refused" in (sa, sm) else "failed"), why, None
    (rev_a, travel_a), (rev_m, travel_m) = va, vm
    d_rev = abs(rev_m - rev_a) / max(abs(rev_a), 1.0)
    d_travel = abs(travel_m - travel_a) / max(abs(travel_a), 2 * row["params"].r)
    worst = max(d_rev, d_travel)
    detail = (f"revolutions {rev_a:.5g} / {rev_m:.5g} ({d_rev:.2e}), travel {travel_a:.5g} / {travel_m:.5g} m "
              f"({d_travel:.2e})")
    return ("agree" if worst <= TIGHT else "agree-1%" if worst <= LOOSE else "DISAGREE"), detail, worst


def describe(p: RobotParams) -> str:
    """The design on one line, to reproduce it."""
    drive = (f"M={p.M:.3g}" if p.drive == "torque"
             else f"motor M_stall={p.M_stall:.3g} omega_noload={p.omega_noload:.3g}")
    clutch = "rigid" if p.clutch_stiffness is None else (
        f"k={p.clutch_stiffness:.3g} c={p.clutch_damping:.3g} backlash={p.clutch_backlash:.3g}")
    return (f"m1={p.m1:.3g} m2={p.m2:.3g} r={p.r:.3g} L={p.L:.3g} J_A={p.J_A:.3g} rod_mass={p.rod_mass:.3g} "
            f"F_r1={p.F_r1:.3g} F_r2={p.F_r2:.3g} phi0={p.phi0:.3g} {drive} incline={p.incline:.3g} {clutch}")


def judged(designs: list[RobotParams], run_one, t_end: float, budget_s: float, workers: int):
    """Each design's (row, verdict, detail) as it finishes: ``run_one(index, params, t_end, budget_s)`` (a
    module-level function returning :func:`run_pair`'s row with its ``design`` index) on a process pool of
    ``workers``, judged by :func:`judge`. The loop the random-design benchmarks share."""
    from concurrent import futures

    with futures.ProcessPoolExecutor(workers) as pool:
        jobs = [pool.submit(run_one, i, p, t_end, budget_s) for i, p in enumerate(designs)]
        for job in futures.as_completed(jobs):
            row = job.result()
            verdict, detail, _ = judge(row)
            yield row, verdict, detail
