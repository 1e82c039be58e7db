"""Many ratcheted MuJoCo designs at once, stepped by ``mujoco.batch`` on C threads.

Each design's model is compiled by the same builder as a single run
(:func:`ipir_mujoco.engine.model.build_model`); the batch runs one model with
per-simulation copies of every field in which the designs differ, so the
builder stays the only place that turns parameters into a model. Between steps
the ratchet raises each simulation's lower slide bounds to the running maximum
of its positions, in one vectorized write (the same rule as
:class:`ipir_mujoco.engine.clutches.Ratchet`).

What a batch can measure is the state: positions and speeds, so speed,
distance per revolution, efficiency (work against the resistances, F_r times
distance, over motor work M dphi), stalls and acceleration jumps; constraint
forces (clutch reactions, rod force) are not exposed per simulation and are
left empty. A simulation MuJoCo resets for instability (its clock falls
behind) is reported as failed, with the time of its last good sample.
"""

from __future__ import annotations

import math
from typing import Sequence

import mujoco
import numpy as np
from mujoco import batch as mjbatch

from ipir_mujoco.analytic.params import RobotParams

from .simulate import captured_warnings
from .model import (CRANK_HINGE, FRONT_SLIDE, MOTOR, REAR_SLIDE, SolverSettings, build_model, dof_address,
                    qpos_address, set_closed_loop_state)


def _differing_fields(models: Sequence[mujoco.MjModel]) -> list[str]:
    """Model fields (of those a batch can expand) whose values differ between the designs."""
    base = models[0]
    names = []
    for name in mjbatch.MODEL_FIELDS:
        if name.startswith("opt."):
            continue
        value = getattr(base, name, None)
        if not isinstance(value, np.ndarray) or value.dtype.kind not in "fiub":
            continue
        if any(not np.array_equal(getattr(m, name), value) for m in models[1:]):
            names.append(name)
    return names


def run_ratchet_batch(designs: Sequence[RobotParams], t_end: float, dt_out: float = 1e-3,
                      settings: SolverSettings = SolverSettings(), nthread: int = 0) -> list[dict]:
    """Run every design with the joint-limit ratchet.

    One dict per design: ``{"series": {column: ndarray (n,)}, "motor_work_j": J,
    "friction_work_j": J}`` with the columns t, phi, omega, x1, x2, v1, v2, a1, a2,
    or ``{"error": message}``.
    """
    results: list[dict | None] = [None] * len(designs)
    models, index = [], []
    for i, params in enumerate(designs):
        try:
            models.append(build_model(params, settings, ratchet=True))
            index.append(i)
        except ValueError as exc:
            results[i] = {"error": str(exc)}
    if not models:
        return results
    base = models[0]
    steps_per_sample = max(1, round(dt_out / settings.timestep))
    n_samples = max(1, math.ceil(t_end / (steps_per_sample * settings.timestep) - 1e-9))
    n = len(models)

    with captured_warnings():
        batch = mjbatch.Batch(base, nsim=n, nthread=nthread)
        for name in _differing_fields(models) + ["jnt_range"]:
            per_sim = batch.expand(name)
            for k, model in enumerate(models):
                per_sim[k] = getattr(model, name)
        qpos, qvel, ctrl, clock = batch.bind("qpos"), batch.bind("qvel"), batch.bind("ctrl"), batch.bind("time")
        for k, (model, i) in enumerate(zip(models, index)):
            data = mujoco.MjData(model)
            set_closed_loop_state(model, data, designs[i])
            qpos[k], qvel[k] = data.qpos, data.qvel
            ctrl[k, base.actuator(MOTOR).id] = designs[i].M
        batch.forward()

        slides_q = np.array([qpos_address(base, n_) for n_ in (REAR_SLIDE, FRONT_SLIDE)])
        slides_v = np.array([dof_address(base, n_) for n_ in (REAR_SLIDE, FRONT_SLIDE)])
        slide_joints = np.array([base.joint(n_).id for n_ in (REAR_SLIDE, FRONT_SLIDE)])
        crank_q, crank_v = qpos_address(base, CRANK_HINGE), dof_address(base, CRANK_HINGE)
        jnt_range = batch.expand("jnt_range")
        bounds = qpos[:, slides_q].copy()
        jnt_range[:, slide_joints, 0] = bounds
        x_start = qpos[:, slides_q].copy()

        rows = n_samples + 1
        record = {key: np.zeros((rows, n)) for key in ("t", "phi", "omega", "x1", "x2", "v1", "v2", "a1", "a2")}
        record["t"][0], record["phi"][0], record["omega"][0] = 0.0, qpos[:, crank_q], qvel[:, crank_v]
        failed_at = np.full(n, np.nan)
        last_v = qvel[:, slides_v].copy()
        for s in range(1, rows):
            for _ in range(steps_per_sample):
                last_v = qvel[:, slides_v].copy()
                np.maximum(bounds, qpos[:, slides_q], out=bounds)
                jnt_range[:, slide_joints, 0] = bounds
                batch.step()
            expected = s * steps_per_sample * settings.timestep
            bad = (np.abs(clock - expected) > 0.5 * settings.timestep) | ~np.all(np.isfinite(qpos), axis=1)
            newly = bad & np.isnan(failed_at)
            failed_at[newly] = record["t"][s - 1][0]
            v = qvel[:, slides_v]
            record["t"][s] = expected
            record["phi"][s], record["omega"][s] = qpos[:, crank_q], qvel[:, crank_v]
            record["x1"][s], record["x2"][s] = (qpos[:, slides_q] - x_start).T
            record["v1"][s], record["v2"][s] = v.T
            record["a1"][s], record["a2"][s] = ((v - last_v) / settings.timestep).T

    for k, i in enumerate(index):
        if not np.isnan(failed_at[k]):
            results[i] = {"error": f"MuJoCo became unstable after t={failed_at[k]:.6g} s"}
            continue
        p = designs[i]
        series = {key: values[:, k] for key, values in record.items()}
        motor = p.M * (series["phi"][-1] - series["phi"][0])
        friction = p.F_r1 * series["x1"][-1] + p.F_r2 * series["x2"][-1]
        results[i] = {"series": series, "motor_work_j": motor, "friction_work_j": friction}
    return results
