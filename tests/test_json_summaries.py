"""Every summary a run gives is writable as the documented JSON, on the designs that push its figures to their
extremes: no grip (mu_wall 0), unlimited grip, a stall, a lift, a skid; in every engine that takes the design.

A figure that is not finite is null in the JSON (core.json_out.json_ready: one rule at the writer). Which keys
may be non-finite is held here, so that a new inf or nan in a summary is a decision documented in docs/cli.md
(what its null means) and not a bug the writer hides.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import json_ready, json_text

# the keys whose value may be unbounded, each with its null's meaning in docs/cli.md
UNBOUNDED = {"summary.side_use1", "summary.side_use2"}

DESIGNS = {
    "no grip": {"mu_wall": 0.0},
    "unlimited grip": {},
    "stall": {"drive": "motor", "M_stall": 0.01},
    "lift": {"M": 3.0, "F_n1": 5.0, "F_n2": 5.0},  # the wheels' press far below the linkage's side loads
    "skid": {"mu_wall": 0.3, "F_n1": 5.0, "F_n2": 5.0},
}
# s: long enough for the stall (the robot at rest for 0.1 s) in the cheap engines; the wheeled model steps at
# 1e-4 s and costs ~1 s of wall time per 0.05 s simulated, so it runs the first 0.05 s (its summary keys are all
# computed from any run's samples)
T_END = {"mujoco-wheels": 0.05}


def non_finite(data, path=""):
    """The dotted paths of every number in ``data`` that is not finite."""
    if isinstance(data, dict):
        return [p for k, v in data.items() for p in non_finite(v, f"{path}{k}.")]
    if isinstance(data, (list, tuple)):
        return [p for k, v in enumerate(data) for p in non_finite(v, f"{path}{k}.")]
    if isinstance(data, (float, np.floating)) and not math.isfinite(data):
        return [path.rstrip(".")]
    return []


def test_json_ready_nulls_every_number_that_is_not_finite_and_keeps_the_rest():
    data = {"a": math.inf, "b": [1.5, -math.inf, (np.float64("nan"), 2)], "c": {"d": np.float32("inf"), "e": 0.0},
            "f": "inf", "g": None, "h": True, "i": 7}
    assert json_ready(data) == {"a": None, "b": [1.5, None, [None, 2]], "c": {"d": None, "e": 0.0}, "f": "inf",
                                "g": None, "h": True, "i": 7}
    assert json.loads(json_text(data))["b"][1] is None


@pytest.mark.slow
@pytest.mark.parametrize("variant", registry.NAMES)
def test_every_engines_summary_is_strict_json_on_the_extreme_designs(variant):
    ran = 0
    for design, changes in DESIGNS.items():
        options = {"accuracy": "warn"} if registry.variant(variant).is_mujoco else {}
        try:
            run = registry.run(variant, RobotParams(**changes), T_END.get(variant, 0.5), **options)
        except ParameterError:
            continue  # a design this variant does not model (finite grip under the paper's rule): refused in one line
        ran += 1
        record = run.to_json_dict()
        assert set(non_finite(record)) <= UNBOUNDED, (design, non_finite(record))
        text = json_text(record)
        back = json.loads(text, parse_constant=lambda name: pytest.fail(f"{name} in the JSON of {design}"))
        for key in UNBOUNDED:  # null exactly where Python has inf
            section, name = key.split(".")
            if name in record[section]:
                assert (back[section][name] is None) == (not math.isfinite(record[section][name]))
        if variant == "mujoco-wheels" and design == "no grip":  # the case: unbounded, so null
            assert back["summary"]["side_use1"] is None and back["summary"]["scrub_predicted"] is True
    assert ran >= 2  # every variant takes unlimited grip and the stall at least
