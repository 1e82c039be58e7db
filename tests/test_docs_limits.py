"""docs/cli.md and the code agree on every limit the page states: each is read off the page's text and compared
with the value the code uses (a constant, or what the code does at the limit). A limit changed on one side
only fails here, naming the sentence.

(The parameters' allowed ranges are the `params` listing the page shows, which tests/test_docs.py compares with
the command's output.)"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parent.parent / "docs" / "cli.md"
TEXT = " ".join(DOCS.read_text(encoding="utf-8").split())  # one line: sentences wrap anywhere


def stated(pattern: str) -> str:
    """The first group of ``pattern`` in docs/cli.md (whitespace-normalized); fails if the page does not say it."""
    match = re.search(pattern, TEXT)
    assert match, f"docs/cli.md no longer says {pattern!r}"
    return match.group(1)


WORDS = {"one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10}


def number(text: str) -> float:
    """A number as the page writes it: digits (with thousands' commas), or a small whole number in words."""
    return float(WORDS[text]) if text in WORDS else float(text.replace(",", ""))


def _constants():
    from ipir_mujoco.cli import simulate
    from ipir_mujoco.cli.common import WALL_EVERY_S
    from ipir_mujoco.core import options, pipe, results, route, steady_test
    from ipir_mujoco.engine.kinds import timestep
    from ipir_mujoco.engine.run import skid_check
    from ipir_mujoco.studies import bend_study, clutch_study, control_study, optimize, sweep_space

    return [
        # (what, the pattern whose first group is the stated number, the code's value)
        ("t_end", r"`--t-end` at most (\d+) s", options.MAX_T_END),
        ("samples per run", r"at most (1e\d+) samples per run", options.MAX_SAMPLES),
        ("samples per study run", r"a study keeps at most (\de\d+) samples per run", options.STUDY_SAMPLES),
        ("MuJoCo steps", r"at most (1e\d+) MuJoCo steps per run", options.MAX_STEPS),
        ("wall budget", r"and (\d+) s of wall time per run unless", options.DEFAULT_WALL_BUDGET_S),
        ("wall budget default", r"naming the budget \(default (\d+) s", options.DEFAULT_WALL_BUDGET_S),
        ("progress every", r"one at least every (\d+) s of wall time", WALL_EVERY_S),
        ("simulate cap", r"with `--until-steady`, the cap \(default (\d+)\)", simulate.T_END_STEADY),
        ("route cap", r"`--t-end` caps it \(default (\d+) s then\)", simulate.T_END_ROUTE),
        ("steady accuracy analytic", r"stated accuracy, ([\d.e-]+) analytic and",
         steady_test.LIMIT_ACCURACY["analytic"]),
        ("steady accuracy MuJoCo", r"analytic and ([\d.e-]+) MuJoCo, see `steady_test`",
         steady_test.LIMIT_ACCURACY["mujoco"]),
        ("stall end", r"A stalled run ends ([\d.]+) s after", results.REST_TIME),
        ("scrub floor", r"either at least (\d+) mm \(`core.side_check.SCRUB_FLOOR`", 1e3 * pipe.SCRUB_FLOOR),
        ("skid halvings", r"at half its step \(at most (\w+) halvings\)", skid_check.HALVINGS),
        ("route segments", r"(\d+) to (?:\d+) segments; any other key", 1),
        ("route segments most", r"\d+ to (\d+) segments; any other key", route.MAX_SEGMENTS),
        ("route bytes", r"at most (\d+) MB \(a route's", route.MAX_ROUTE_BYTES / 1e6),
        ("straight length", r"\| `length` \(straight\) \| [^|]* \| > 0, <= (\d+) \|", route.MAX_LENGTH),
        ("bend radius", r"\| > pipe_diameter / 2, <= (\d+) \|", route.MAX_LENGTH),
        ("sweep designs", r"the full grid \(at most ([\d,]+) designs\)", sweep_space.MAX_DESIGNS),
        ("sweep steady cap", r"`--t-end` caps it; default cap (\d+) s\)", sweep_space.T_END_STEADY),
        ("clutch cruise cap", r"periodic steady state, (\d+) s cap; `startup`", clutch_study.POINTS["cruise"].t_end),
        ("clutch startup", r"constant torque for (\d+) s from rest", clutch_study.POINTS["startup"].t_end),
        ("clutch least step", r"with a step of at least (1e-\d+) s is refused", timestep.DT_MIN),
        ("bend cap", r"Each run is capped at (\d+) s per metre of route", bend_study.T_CAP_PER_M),
        ("control cap", r"periodic steady state \(capped at (\d+) s\)", control_study.T_CAP),
        ("optimize budget", r"at most `--budget` designs in all, default (\d+)\)", optimize.DEFAULT_BUDGET),
        ("NSGA-II generation", r"NSGA-II \(pymoo, (\d+) designs per generation", optimize.POPULATION),
    ]


CASES = _constants()


@pytest.mark.parametrize("what,pattern,code", CASES, ids=[c[0] for c in CASES])
def test_a_limit_the_page_states_is_the_codes(what, pattern, code):
    text = stated(pattern)
    assert number(text) == pytest.approx(code, rel=1e-12), f"docs/cli.md says {what} {text}, the code {code}"


def test_the_routes_first_straight_is_as_long_as_the_page_says():
    """'the first segment ... at least as long as the robot: ..., X m with the defaults': a route whose first
    straight is X m runs, one a millimetre shorter is refused naming that length."""
    from ipir_mujoco.core.errors import ParameterError
    from ipir_mujoco.core.params import RobotParams
    from ipir_mujoco.core.route import route_from_tables
    from ipir_mujoco.engine.modelkinds.route_watch import check_route

    least = number(stated(r"from the rear module's A to its front ring's wheels, ([\d.]+) m with the defaults"))
    bend = {"kind": "bend", "radius": 0.8, "angle": 90}
    check_route(route_from_tables([{"kind": "straight", "length": least}, bend]), "wheels",
                RobotParams(mu_wall=0.5), False)
    with pytest.raises(ParameterError, match=f"allowed: length >= {least:g} m"):
        check_route(route_from_tables([{"kind": "straight", "length": least - 1e-3}, bend]), "wheels",
                    RobotParams(mu_wall=0.5), False)


def test_route_angles_are_the_pages():
    """The table's `angle` and `plane` ranges: -180..180 (angle not 0); just past either end is refused."""
    from ipir_mujoco.core.errors import ParameterError
    from ipir_mujoco.core.route import route_from_tables

    low, high = map(number, re.search(r"\| how far it turns \[deg\] \| (-?\d+)\.\.(\d+), not 0 \|", TEXT).groups())
    straight = {"kind": "straight", "length": 0.5}
    for angle in (low, high):
        route_from_tables([straight, {"kind": "bend", "radius": 0.8, "angle": angle}])
    for angle in (low - 1e-9 * abs(low), high + 1e-9 * high, 0.0):
        with pytest.raises(ParameterError):
            route_from_tables([straight, {"kind": "bend", "radius": 0.8, "angle": angle}])
