"""The analytic solvers' work budget, progress reports and run options."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ipir_mujoco import analytic
from ipir_mujoco.analytic import ParameterError, RobotParams, SimulationError
from ipir_mujoco.analytic.solver_support import PROGRESS_EVERY_S

# Issue 11's slow design: a runaway crank (M / J_A ~ 1.2e5 rad/s^2) that turns ~3000 times in 1 s
RUNAWAY = RobotParams(m1=1.198, m2=0.1986, r=0.00706, L=0.01799, J_A=2.76e-5, F_r1=1.95, F_r2=14.8, M=3.25,
                      phi0=3.81, omega0=-46.6, rod_mass=0.215)
SOLVERS = [("approx", "kinematic"), ("exact", "unilateral")]


@pytest.mark.parametrize("geometry,clutch", SOLVERS)
def test_the_switch_budget_stops_a_run_with_its_name_and_remedy(geometry, clutch):
    with pytest.raises(SimulationError, match=r"max_switches=5 is spent at t=[0-9.e-]+ s of 1 s .*raise max_switches"):
        analytic.simulate(RobotParams(), geometry, clutch, 1.0, max_switches=5)


def test_switches_that_stop_advancing_time_end_the_run_long_before_the_switch_budget():
    """At r = 5e-324 m (the table's smallest crank) the paper's model switches its clutches at t = 0 without
    moving: the run stops after STUCK_SWITCHES such switches with that reason, not after MAX_SWITCHES."""
    from ipir_mujoco.analytic.solver_support import MAX_SWITCHES, STUCK_SWITCHES

    with pytest.raises(SimulationError, match=rf"stuck: {STUCK_SWITCHES} mode switches in a row within 1e-12 s "
                                              r"of t=0 s of 0.02 s"):
        analytic.simulate(RobotParams(r=5e-324), "approx", "kinematic", 0.02)
    assert STUCK_SWITCHES * 50 <= MAX_SWITCHES


@pytest.mark.parametrize("geometry,clutch", [("exact", "kinematic"), ("exact", "unilateral")])
def test_the_wall_clock_budget_stops_a_runaway_design(geometry, clutch):
    # checked between segments, each a few ms here: the run stops soon after 0.2 s of wall time,
    # far short of the ~1 min the whole second takes
    with pytest.raises(SimulationError, match=r"wall_budget_s=0.2 s is spent at t=.* raise wall_budget_s"):
        analytic.simulate(RUNAWAY, geometry, clutch, 1.0, wall_budget_s=0.2)


@pytest.mark.parametrize("geometry,clutch", SOLVERS)
def test_progress_comes_every_tenth_of_a_simulated_second_at_most(geometry, clutch):
    calls = []
    run = analytic.simulate(RobotParams(drive="motor"), geometry, clutch, 1.0, dt_out=1e-3, progress=calls.append)
    assert calls[-1] == run.series["t"][-1] == 1.0  # the end is always reported
    gaps = np.diff(calls[:-1])
    assert np.all(gaps >= PROGRESS_EVERY_S - 1e-12)  # never more often than every 0.1 s simulated
    # reported at the first mode switch past each tenth: with >= 2 switches per turn and turns
    # of < 0.4 s here, no gap exceeds 0.3 s
    assert np.all(np.diff(calls) <= 0.3) and len(calls) >= 1.0 / 0.3


@pytest.mark.parametrize("option,value,fragment", [
    ("max_switches", -1, "max_switches=-1"), ("max_switches", 2.5, "max_switches=2.5"),
    ("wall_budget_s", 0.0, "wall_budget_s=0.0"), ("wall_budget_s", math.nan, "wall_budget_s=nan"),
    ("progress", "stderr", "progress='stderr'"), ("until_steady", "yes", "until_steady='yes'"),
    ("steady_cycles", 1, "steady_cycles=1"), ("steady_tol", 0.0, "steady_tol=0.0"),
])
@pytest.mark.parametrize("clutch", ["kinematic", "unilateral"])
def test_bad_run_options_are_parameter_errors(clutch, option, value, fragment):
    with pytest.raises(ParameterError, match=f"^{fragment.replace('.', '[.]')} .*allowed"):
        analytic.simulate(RobotParams(), "exact", clutch, 0.1, **{option: value})


def test_a_long_step_says_it_is_still_running_until_it_ends():
    """core.options.heartbeat: a line through the report while the step lasts, none once it has ended (the
    thread is joined on leaving, so nothing can come later); waits on the first line, never on a clock."""
    import threading

    from ipir_mujoco.core.options import heartbeat

    lines: list[str] = []
    first = threading.Event()

    def report(message: str) -> None:
        lines.append(message)
        first.set()

    with heartbeat(report, "atlas toy (equations)", every_s=0.01):
        assert first.wait(60), "no heartbeat while the step ran"
    seen = len(lines)
    assert lines[0].startswith("atlas toy (equations): still running (") and lines[0].endswith(" s)")
    with heartbeat(report, "short", every_s=3600) as beat:
        beat.say("short: its own line")  # passed on as it is
    assert lines[seen:] == ["short: its own line"]  # and nothing else: it ended before its first beat


@pytest.mark.parametrize("t_end", [60.0, 1.0])  # a route's cap (tenths and wall lines), a short run (wall only)
def test_a_long_run_in_a_log_says_where_it_is_after_2_s_then_every_5_s(t_end, monkeypatch, capsys):
    """cli.common.progress_printer in a log file (stderr not a terminal), on a made-up clock: nothing while the
    run is younger than FIRST_WALL_S, a line at it, then one each WALL_EVERY_S (a run finished sooner is silent)."""
    import time

    from ipir_mujoco.cli import common

    clock = [100.0]
    monkeypatch.setattr(time, "monotonic", lambda: clock[0])
    report = common.progress_printer(t_end)
    printed = []
    for wall, simulated in [(1.9, 0.01), (2.0, 0.02), (6.9, 0.03), (7.0, 0.04), (10.0, 0.05)]:
        clock[0] = 100.0 + wall
        report(simulated)
        printed += capsys.readouterr().err.splitlines()
    assert common.FIRST_WALL_S == 2.0 and common.WALL_EVERY_S == 5.0  # the times above are these
    assert printed == [f"simulated 0.02 / {t_end:g} s", f"simulated 0.04 / {t_end:g} s"]


def test_a_run_repeated_at_a_finer_step_goes_on_saying_where_it_is(monkeypatch, capsys):
    """A wheeled run's skid check repeats the run at half its step, minutes on a long run: through the engine's
    PassProgress the repeat is heard every WALL_EVERY_S in a log file, its lines saying it is a repeat, at which
    step and how far it is, while the time a plain callable sees never goes back."""
    import time

    from ipir_mujoco.cli import common
    from ipir_mujoco.engine.modelkinds.common import PassProgress

    clock = [100.0]
    monkeypatch.setattr(time, "monotonic", lambda: clock[0])
    printed, plain = [], []
    report = common.progress_printer(5.0)
    passes = PassProgress(lambda t: (plain.append(float(t)), report(t)))
    passes.begin(5e-5)
    for wall, simulated in [(3.0, 2.5), (6.0, 3.07)]:  # the first attempt: stopped at 3.07 s (a stall, say)
        clock[0] = 100.0 + wall
        passes(simulated)
    passes.begin(2.5e-5)  # the skid check's repeat from t = 0
    for wall, simulated in [(9.0, 0.4), (11.5, 0.9), (14.0, 1.5), (33.0, 3.0), (38.5, 3.2)]:
        clock[0] = 100.0 + wall
        passes(simulated)
    printed = capsys.readouterr().err.splitlines()
    assert plain == sorted(plain) and plain[-1] == 3.2  # never back; past the first attempt, the repeat's own time
    again = [line for line in printed if "again" in line]
    assert printed[:2] == ["simulated 2.50 / 5 s", "simulated 3.07 / 5 s"]
    # the first attempt's tenths printed at 3 and 6 s of wall time; then wall lines only (the time reported stays
    # in its sixth tenth): at 11.5 s (5.5 s after the last line; 9 s was 3 s after), 33 and 38.5 s, none at 14 s
    assert again == ["simulated 0.90 / 5 s again, at a 2.5e-05 s step (attempt 2: the accuracy check)",
                     "simulated 3.00 / 5 s again, at a 2.5e-05 s step (attempt 2: the accuracy check)",
                     "simulated 3.20 / 5 s again, at a 2.5e-05 s step (attempt 2: the accuracy check)"]
