"""The report, the README and the docs tell one story: each headline figure (ipir_mujoco.report.headlines, read
from the report's metrics.json) is written in report.md as the report states it, and every place the README and
the docs quote it gives the same number to the digits quoted.

The report is the README's first command as the suite runs it (``ipir-mujoco validate --quick``, one run shared
with tests/test_validate.py): every headline figure is the same in the full report to the digits the README and
the docs quote (the L/r crossing is root-found to 0.002 whatever the grid; the climbing limit is bisected to
climb's 0.1 deg in both; the pull share, sampled 10x coarser in --quick, is 35.6 % there and 36.5 % in the full
report: the README's '36 %' covers both).

Files read: report/metrics.json and report/report.md (from the run), README.md, docs/cli.md, docs/model.md,
docs/control.md. Figures: the L/r crossing (and its L), first-order kinematics' cost at L/r = 4 (revolutions,
rear travel), the engines' agreement on one linkage, the locks' pull (share, force), the locks' cost at 1 s
(revolutions, both travels), the cruise speeds of the paper's model and of one-way clutches, the paper's model's
error at cruise, the locks' cost at cruise, the restart and steady-climb limits, the riser's torque, the speed
control's ripples (promised, delivered, exact).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NUMBER = r"([+-]?\d+(?:\.\d+)?)"
W = r"\s+"  # a line break or a space in running text
# (file, pattern with one group per key, keys): where each headline is quoted
QUOTES = (
    ("README.md", rf"below{W}L/r = {NUMBER} \(L = {NUMBER} m; at the paper's L/r = 4 it costs {NUMBER} % in{W}"
                  rf"revolutions and {NUMBER} % in rear-module travel\)",
     ("lr_crossing", "lr_crossing_L", "first_order_revolutions", "first_order_rear_travel")),
    ("README.md", rf"equations of the same linkage to {NUMBER} %", ("engines_same_linkage",)),
    ("README.md", rf"must pull during {NUMBER} % of the run \(up to {NUMBER} N\)", ("pull_share", "pull_force")),
    ("README.md", rf"cost {NUMBER} % in revolutions and {NUMBER} % \(rear\) and {NUMBER} % \(front\) in travel",
     ("locks_revolutions", "locks_rear_travel", "locks_front_travel")),
    ("README.md", rf"the paper's model cruises at {NUMBER} m/s where the robot with one-way{W}clutches does "
                  rf"{NUMBER} m/s \(the paper's model is {NUMBER} % off",
     ("cruise_paper", "cruise_one_way", "paper_error_cruise")),
    ("README.md", rf"the locks alone, on the same mechanism, cost {NUMBER} %", ("locks_cost_cruise",)),
    ("README.md", rf"below{W}L/r = {NUMBER} \(the report's L/r study finds it", ("lr_crossing",)),
    ("README.md", rf"promises {NUMBER} % speed ripple at{W}10 rad/s and delivers {NUMBER} % on the real linkage, "
                  rf"the exact one {NUMBER} %", ("ripple_promised", "ripple_delivered", "ripple_exact")),
    ("README.md", rf"restarts anywhere up to {NUMBER} deg and climbs from{W}rest up to {NUMBER}-{NUMBER} deg",
     ("restart_limit", "climb_low", "climb_high")),
    ("README.md", rf"vertical riser needs {NUMBER} N m at rest", ("riser_torque",)),
    ("docs/cli.md", rf"crossings L={NUMBER} \[", ("lr_crossing_L",)),  # the atlas's own output: the same crossing
    ("docs/cli.md", rf"below L = {NUMBER} m, L/r = {NUMBER}", ("lr_crossing_L", "lr_crossing")),
    ("docs/model.md", rf"restart limit{W}{NUMBER} deg, a steady climb from rest up to {NUMBER}-{NUMBER} deg",
     ("restart_limit", "climb_low", "climb_high")),
    ("docs/model.md", rf"a vertical riser needs {NUMBER} N m at rest", ("riser_torque",)),
    ("docs/control.md", rf"PI with the exact{W}feedforward to {NUMBER} % \(exact equations",
     ("ripple_exact",)),
    ("docs/control.md", rf"a ripple of {NUMBER} % at 10 rad/s", ("ripple_promised",)),
    ("docs/control.md", rf"On the real linkage it delivers {NUMBER} % \(exact equations", ("ripple_delivered",)),
)


def agrees(quoted: str, value: float) -> bool:
    """Whether the quoted number is ``value`` to the digits quoted (its decimals), sign included."""
    decimals = len(quoted.partition(".")[2])
    return round(value, decimals) == float(quoted) and (not quoted.startswith("+") or value > 0)


def test_a_quote_agrees_only_to_its_own_digits():
    assert agrees("5.09", 5.0858) and agrees("0.2543", 0.254324) and agrees("36", 35.6) and agrees("+1.35", 1.354)
    assert not agrees("4.6", 5.0858) and not agrees("-1.34", 1.354) and not agrees("+1.34", 1.354)
    assert not agrees("77.5", 77.5627) and agrees("77.56", 77.5627) and agrees("77.6", 77.5627)


@pytest.mark.slow
def test_the_report_readme_and_docs_quote_the_same_headline_figures(shared_command):
    from ipir_mujoco.report.headlines import headlines

    done = shared_command("ipir-mujoco validate --quick")
    assert done.returncode == 0, done.stderr[-2000:]
    metrics = json.loads((done.folder / "report" / "metrics.json").read_text())
    markdown = (done.folder / "report" / "report.md").read_text()
    found = headlines(metrics)
    # every headline is in the report as the report states it
    assert not [h.key for h in found.values() if h.text not in markdown], [
        (h.key, h.text) for h in found.values() if h.text not in markdown]
    quoted = set()
    wrong = []
    for name, pattern, keys in QUOTES:
        text = (ROOT / name).read_text()
        match = re.search(pattern, text)
        assert match, f"{name}: the quote {pattern!r} is gone (rewritten? update QUOTES with it)"
        for key, number in zip(keys, match.groups()):
            quoted.add(key)
            if not agrees(number, found[key].value):
                wrong.append(f"{name}: {key} quoted {number}, the report has {found[key].value:.6g} "
                             f"({found[key].words})")
    assert not wrong, wrong
    assert quoted == set(found), set(found) - quoted  # every headline is quoted somewhere
