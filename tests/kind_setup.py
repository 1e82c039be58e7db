"""A started run setup for a registry variant: the MuJoCo model, its kind and its controller, as a run makes them.

Shared by the seam's contract tests (tests/test_model_kinds.py) and the compiled loop's tests
(tests/test_mujoco_stepper.py), so that both build the setup a run builds, the same way.
"""

from __future__ import annotations

from ipir_mujoco import registry
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.engine import kinds
from ipir_mujoco.engine.run.run_setup import RunSetup


def started_setup(variant: str, params: RobotParams, implementation: str | None = None) -> RunSetup:
    """The variant's run setup for PARAMS (a 0.01 s run sampled every 1e-3 s), started and ready to step.

    IMPLEMENTATION names the clutch controller (None: the variant's own); the kind checks the parameters first,
    as a run does.
    """
    v = registry.variant(variant)
    kind = kinds.kind_for(v.model, params)
    implementation = implementation or v.clutch
    params = kind.check(params, implementation, v.rule)
    settings, _ = kind.settings(params, 0.01, 1e-3, None, implementation)
    setup = RunSetup(kind, params, settings, implementation=implementation, rule=v.rule)
    setup.start()
    return setup
