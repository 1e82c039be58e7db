"""The family of runs a skidding slide run's rigid limit is extrapolated from: one design at several
regularizations, each run once when first asked for, its figures read alike.

A member at ratio k of the first run's regularization has its step, its grip rows' time constant and its
carriage's share scaled by k (:func:`member_settings`); it is used where it stayed sane (:func:`clean_motion`).
:mod:`.rigid_limit` chooses the members and extrapolates their figures (its module docstring says why).
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

from ipir_mujoco.core.cycles import cycles, window_figures
from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.results import RunResult
from ipir_mujoco.core.steady_test import find_steady, steady_at_end

from ...builders.model import SolverSettings

FIGURES = {"fixed": ("revolutions", "x1_final", "x2_final"),
           "steady": ("steady_speed_m_s", "energy_per_metre_j_m")}
MEMBER_SLACK = 1.05  # a steady family's member runs to this times the first run's end, plus half a revolution


def member_settings(first: SolverSettings, ratio: float, duration: float) -> SolverSettings:
    """The settings of the family's member at ``ratio`` times the first run's regularization: a step near ratio
    times the first's, a whole fraction of ``duration`` [s] (at fixed time the first run's simulated time, so
    that every member ends where it did; to the steady state its sampling interval, so that every member's
    revolutions are cut from samples alike), and the grip rows' time constant and the carriage's share scaled
    by the same factor."""
    steps = max(1, round(duration / (ratio * first.timestep)))
    scale = duration / steps / first.timestep
    share = first.carriage_share
    return replace(first, timestep=duration / steps, grip_time_constant=scale * first.grip_rows,
                   carriage_share=None if share is None else scale * share,
                   constraint_time_constant=None if first.constraint_time_constant is None
                   else scale * first.constraint_time_constant)


def clean_motion(run: RunResult, ratio: float) -> bool:
    """Whether a member at ``ratio`` (>= 1) times the first run's regularization stayed sane: its loop gap and its
    one-way limits' give within the monitor's tolerances times the ratio (a soft row's gap and give grow with
    its time constant), its energy residual within the tolerance times ratio^3 (the motion's own error grows as
    (omega dt)^3: a coarser member's motion may leave the first-order regime, which its figures' measured order
    then shows, but not more than that; a member beyond it met a solver failure, not a coarser step)."""
    record = run.accuracy or {}
    tolerances = record.get("tolerances", {})
    allowed = {"residual_ratio": ratio ** 3, "loop_gap_m": ratio, "excursion_m": ratio}
    return all(abs(record.get(figure, 0.0)) <= scale * tolerances.get(figure, math.inf)
               for figure, scale in allowed.items())


class Family:
    """The runs of one design at several regularizations, each run once when first asked for, and each one's
    figures read alike.

    ``first``: the automatically stepped run (regularization 1); ``rerun(settings, t_end)``: the design again with
    other settings, to ``t_end`` [s] without the steady test, its accuracy monitor recording (never stopping);
    ``t_cap`` [s]: the run's own t_end (with until_steady, the cap). Fixed time: every member runs to the first
    run's end and its figures are its summary's. Steady: the figures are read over the first run's steady window
    (the same revolutions, :func:`ipir_mujoco.core.cycles.window_figures`), so that where the steady test
    happens to stop does not scatter them; each member runs MEMBER_SLACK times the first run's time and half a
    revolution more (at most to the cap). A member that fails (a SimulationError: MuJoCo unstable, a budget), or lacks the window, is kept
    as the one-line reason.
    """

    def __init__(self, first: RunResult, rerun, t_cap: float):
        self.first, self.rerun, self.t_cap = first, rerun, t_cap
        self.settings = SolverSettings(**{k: first.settings[k] for k in (
            "timestep", "integrator", "constraint_time_constant", "solimp", "grip_time_constant", "carriage_share")})
        self.kind = "steady" if first.summary["steady"] else "fixed"
        self.window = None
        if self.kind == "steady":
            tol, n = first.steady_test
            found = cycles(first.series)
            self.window = find_steady([c.mean_speed_m_s for c in found], tol, n, first.steady_target, steady_at_end)
            window = found[self.window.start:self.window.end + 1]
            period = sum(c.period_s for c in window) / len(window)
            # a member's revolutions run ahead or behind the first's by its soft error, a few per cent of the time
            self.t_member = min(t_cap, MEMBER_SLACK * first.t_end + 0.5 * period)
        else:
            self.t_member = first.t_end
        self.members: dict[float, RunResult | str] = {1.0: first}
        self.walls = {1.0: first.wall_time_s}  # each run's own wall time [s]

    def member(self, ratio: float) -> RunResult | str:
        """The run at ``ratio`` times the first run's regularization (a RunResult, or why it is not one)."""
        if ratio not in self.members:
            sampled = self.first.settings["dt_out"]
            every_step = math.isclose(sampled, self.settings.timestep, rel_tol=1e-12)
            grid = sampled if self.kind == "steady" and not every_step else self.first.t_end
            settings = member_settings(self.settings, ratio, grid)
            started = time.perf_counter()
            try:
                run = self.rerun(settings, self.t_member)
                if self.window is not None and len(cycles(run.series)) <= self.window.end:
                    run = f"it did not complete the steady window's revolutions by {self.t_member:.6g} s"
                self.members[ratio] = run
            except SimulationError as exc:
                self.members[ratio] = " ".join(str(exc).split())
            self.walls[ratio] = time.perf_counter() - started
        return self.members[ratio]

    def figures(self, ratio: float) -> dict[str, float | None]:
        """The figures of the member at ``ratio`` (:data:`FIGURES` of the family's kind)."""
        run = self.member(ratio)
        if self.window is None:
            return {key: run.summary[key] for key in FIGURES["fixed"]}
        tol, _ = self.first.steady_test
        read = window_figures(cycles(run.series), self.window, tol)
        return {key: read[key] for key in FIGURES["steady"]}

    @property
    def wall_time_s(self) -> float:
        """The wall time of every run the family made [s]."""
        return sum(self.walls.values())

    def usable(self, ratio: float) -> bool:
        """Whether the member at ``ratio`` ran and kept its motion within the first-order regime
        (:func:`clean_motion`, its tolerances scaled by max(ratio, 1))."""
        run = self.member(ratio)
        return isinstance(run, RunResult) and clean_motion(run, max(ratio, 1.0))

    def record(self) -> list[dict]:
        """Each run the family made, finest first: its regularization ratio, time constant [s], step [s], carriage
        share, wall time [s] and its accuracy record's figures (or why it is not used)."""
        out = []
        for ratio in sorted(self.members):
            run = self.members[ratio]
            entry = {"ratio": ratio, "wall_s": self.walls[ratio]}
            if isinstance(run, RunResult):
                acc = run.accuracy or {}
                entry.update(time_constant_s=run.settings["grip_time_constant"], timestep_s=run.settings["timestep"],
                             steps=round(run.t_end / run.settings["timestep"]),
                             carriage_share=run.settings["carriage_share"], residual_ratio=acc.get("residual_ratio"),
                             loop_gap_m=acc.get("loop_gap_m"), excursion_m=acc.get("excursion_m"))
            else:
                entry["failed"] = run
            out.append(entry)
        return out
