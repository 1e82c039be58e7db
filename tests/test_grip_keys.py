"""The grip keys mean the same in every engine: one skidding design run by every variant that models finite
grip, read through the one definition in core (``ipir_mujoco.core.summary.grip_use``, ``peak_grip_use``).

A variant whose clutch cannot skid (the paper's rule, MuJoCo's locks) refuses a finite grip in one line."""

from __future__ import annotations

import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import grip_use, peak_grip_use

# the default motor's cruise on 5 N of grip per module against a demand of ~12 N: both modules skid every stroke
SKIDDING = dict(drive="motor", mu_wall=0.5, F_n1=10.0, F_n2=10.0)
COMPLIANT = dict(clutch_stiffness=1e5, clutch_damping=50.0)
T_END = 0.5  # s: three strokes, each module skids in each
# the wheeled model skids on the same 5 N of grip with its legs pressing 50 N (mu_wall 0.1): at 10 N, below a
# module's weight with the motor's couple, its wheels lift (0.42 s of the 0.5 s) and it tips on the legs left on
# the wall, where the analytic model's constant press, and with it the grip keys' common meaning, no longer
# holds (a tipping module's centre moves back while its wheels stand, and its slip counts that: docs/cli.md)
WHEELED = dict(drive="motor", mu_wall=0.1, F_n1=50.0, F_n2=50.0)
RUNS = [("analytic-unilateral", {}), ("analytic-approx-unilateral", {}), ("analytic-unilateral", COMPLIANT),
        ("mujoco-ratchet", {}), ("mujoco-ratchet", COMPLIANT),
        pytest.param("mujoco-wheels", WHEELED, marks=pytest.mark.slow)]
REFUSING = ["analytic-approx", "analytic-exact", "mujoco-lock", "mujoco-lock-unilateral"]


def backward_travel_while_skidding(x: np.ndarray, wheels: np.ndarray) -> tuple[float, float]:
    """(the module's backward travel [m] over the sample intervals that end skidding, how far [m] the intervals
    where a skid starts or ends moved in all): the slip's definition read off the positions, and how much of it
    the sampling leaves undecided (an interval in which a skid starts or ends is counted whole or not at all)."""
    back = np.maximum(x[:-1] - x[1:], 0.0)
    skid = wheels[1:] == -1.0
    edges = (wheels[1:] == -1.0) != (wheels[:-1] == -1.0)
    return float(back[skid].sum()), float(np.abs(np.diff(x))[edges].sum())


@pytest.mark.parametrize("variant,extra", RUNS)
@pytest.mark.slow
def test_every_engine_reads_its_grip_keys_by_the_one_definition(variant, extra):
    params = RobotParams(**{**SKIDDING, **extra})
    assert params.grip == (5.0, 5.0)  # every variant on the same grip
    # the wheeled model at its automatic first step, given: its skid check's reruns (to 2.5e-5 s here) refine the
    # figures, not what the keys mean
    options = {"timestep": 1e-4} if variant == "mujoco-wheels" else {}
    run = registry.run(variant, params, T_END, dt_out=1e-3, **options)
    s, summary = run.series, run.summary
    for k, G in zip((1, 2), params.grip):
        lam, wheels = s[f"lambda{k}"], s[f"wheels{k}"]
        assert set(np.unique(wheels)) <= {-1.0, 0.0, 1.0}
        assert np.any(wheels == -1.0), f"module {k} never skids: the design no longer tests the skid keys"
        # the engine's grip_use column is core's definition of its own lambda and wheels columns, exactly
        np.testing.assert_array_equal(s[f"grip_use{k}"], grip_use(lam, wheels, G))
        assert np.all(s[f"grip_use{k}"][wheels == -1.0] == 1.0) and s[f"grip_use{k}"].max() <= 1.0
        slip = summary[f"slip{k}_m"]
        assert slip == max(float(s[f"slip{k}"][-1] - s[f"slip{k}"][0]), 0.0) and slip > 0
        if "clutch_stiffness" not in extra:  # rigid clutches: the locked wheels skid with their module
            travel, undecided = backward_travel_while_skidding(s[f"x{k}"], wheels)  # (compliant: its anchor's slide)
            # a MuJoCo module stands on soft rows that creep ~1e-9 m per revolution (mjcf/README.md): 1e-8 m more
            assert abs(slip - travel) <= undecided + 1e-8
    if variant == "mujoco-wheels":  # the design keeps every wheel on its wall: the constant press holds
        assert summary["wheel_off_s"] == 0.0
    # skidded: 1, by the same definition for every engine, and the summary is read off the columns
    assert summary["peak_grip_use"] == peak_grip_use(s, params.grip) == 1.0


@pytest.mark.parametrize("variant", REFUSING)
def test_a_clutch_that_cannot_skid_refuses_a_finite_grip_in_one_line(variant):
    with pytest.raises(ParameterError) as caught:
        registry.run(variant, RobotParams(**SKIDDING), 0.05)
    assert "mu_wall" in str(caught.value) and "\n" not in str(caught.value)


def test_unlimited_grip_has_no_grip_use_and_no_skid():
    for variant in ("analytic-unilateral", "mujoco-ratchet"):
        summary = registry.run(variant, RobotParams(drive="motor"), 0.3, dt_out=1e-3).summary
        assert summary["peak_grip_use"] is None and summary["slip1_m"] == summary["slip2_m"] == 0.0


def test_the_definition_caps_a_soft_engines_excess_and_counts_a_skid_as_full_use():
    lam = np.array([0.0, 2.5, 5.0, 5.2, 5.2, -1.0])
    wheels = np.array([1.0, 0.0, 0.0, 0.0, -1.0, 0.0])
    np.testing.assert_array_equal(grip_use(lam, wheels, 5.0), [0.0, 0.5, 1.0, 1.0, 1.0, 0.0])
    np.testing.assert_array_equal(grip_use(lam, wheels, 0.0), [0.0, 0.0, 0.0, 0.0, 1.0, 0.0])
