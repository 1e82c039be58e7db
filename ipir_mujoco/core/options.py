"""The options of a run, checked once for every engine and interface.

:class:`RunOptions` is the one check: the simulated time and output interval, the steady-state stop, the work
budgets and the progress callback, each refused with a one-line :class:`ParameterError` naming the value and
what is allowed. Both models' entry points (:func:`ipir_mujoco.analytic.simulate`,
:func:`ipir_mujoco.engine.simulate_mujoco`) build one from their keywords; the registry
(:mod:`ipir_mujoco.registry`), the command line and the study files reach it through them. What only one
engine has (the analytic solver's tolerances, MuJoCo's solver settings and clutch choice) is that engine's
own check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .cycles import STEADY_CYCLES, STEADY_TOL
from .steady_watch import check_steady_test
from .errors import ParameterError, ParameterTypeError
from .params import as_real, check_real, check_whole

MAX_T_END = 3600.0  # s: an hour of simulated motion; a motor reaches its steady state in seconds, and a
# MuJoCo run at its 1e-4 s step already takes 3.6e7 steps for an hour
MAX_SAMPLES = 10_000_000  # samples kept per run: ~20 float64 columns -> 1.6 GB in memory, ~4 GB as CSV
SAMPLE_BYTES = 20 * 8  # bytes per kept sample (about 20 float64 columns)
MAX_STEPS = 100_000_000  # MuJoCo steps per run: ~7 min at ~4 us a step (bench/ratchet_step.py); the longest
# run the engine chooses by itself, 3600 s at its 1e-4 s step, is 3.6e7 steps, so only a tiny given timestep
# with a long t_end reaches it
# samples a study keeps per run at most (docs/cli.md, "Entry point and exit status"): a study runs many runs, each
# worker holds one at a time, and a run's figures are read with a few copies of its ~35 float64 columns: ~56 MB
# a run, ~250 MB of a worker's memory with the copies. A run that would keep more is sampled more coarsely
# (:func:`study_dt_out`); its steps stay the ones its accuracy needs
STUDY_SAMPLES = 200_000
DEFAULT_WALL_BUDGET_S = 1800.0  # s of wall time a run may take unless told otherwise: the longest default-step
# run (3600 s of MuJoCo, ~2.5 min) fits ~10 times over, and no run left alone goes on for hours


def study_dt_out(t_end: float, dt_out: float, step: float | None = None) -> float:
    """The output interval [s] of a study's run of ``t_end`` [s] wanted every ``dt_out`` [s]: ``dt_out``, or where
    that would keep more than STUDY_SAMPLES samples the interval that keeps that many, a whole number of MuJoCo's
    ``step`` [s] where given (its samples fall on steps). Bounds what every study holds in memory whatever the
    step its runs need (a finite grip's skids, a stiff clutch's spring)."""
    if t_end / dt_out + 1 <= STUDY_SAMPLES:
        return dt_out
    wanted = t_end / (STUDY_SAMPLES - 1)
    return wanted if step is None else step * math.ceil(wanted / step * (1 - 1e-12))


def check_step_count(t_end: float, timestep: float, t_end_name: str = "t_end",
                     timestep_name: str = "timestep") -> int:
    """The MuJoCo step count t_end / timestep (both [s]), or a one-line ParameterError naming both and the
    allowed maximum MAX_STEPS: bounded up front, so that a run of 1e12 steps is refused, not started."""
    steps = t_end / timestep
    if steps > MAX_STEPS:
        raise ParameterError(
            f"{t_end_name}={t_end:g} s with {timestep_name}={timestep:g} s would take {steps:.3g} MuJoCo steps "
            f"(~{steps * 4e-6 / 3600:.3g} h at ~4 us a step); allowed: at most {MAX_STEPS:.0e} steps "
            f"({timestep_name} >= {t_end / MAX_STEPS:.3g} s for this {t_end_name})")
    return int(math.ceil(steps))


def check_run_options(t_end: Any, dt_out: Any) -> tuple[float, float]:
    """(t_end [s], dt_out [s]) as floats: 0 < t_end <= MAX_T_END, 0 < dt_out <= t_end, and at most
    MAX_SAMPLES samples kept (t_end / dt_out + 1), with the size it would need named in the message."""
    t_end = check_real("t_end", t_end, high=MAX_T_END, unit="s")
    dt_out = check_real("dt_out", dt_out, unit="s")
    if dt_out > t_end:
        raise ParameterError(f"dt_out={dt_out:g} s is out of range; allowed: dt_out <= t_end ({t_end:g} s)")
    samples = t_end / dt_out + 1
    if samples > MAX_SAMPLES:
        raise ParameterError(
            f"t_end={t_end:g} s with dt_out={dt_out:g} s would keep {samples:.3g} samples "
            f"(~{samples * SAMPLE_BYTES / 1e9:.3g} GB); allowed: at most {MAX_SAMPLES:.0e} samples "
            f"(dt_out >= {t_end / (MAX_SAMPLES - 1):.3g} s for this t_end)")
    return t_end, dt_out


def refuse_steady_without_motor(drive: str, until_steady: bool) -> None:
    """A run asked to stop at its periodic steady state under the constant torque, which has none (the crank
    speeds up for ever or comes to rest): refused in one line, with what has a steady state."""
    if until_steady and drive == "torque":
        raise ParameterError("until_steady with drive=torque: a constant torque has no periodic steady state (the "
                             "crank speeds up for ever, or comes to rest); allowed: drive=motor or servo (--drive "
                             "motor), or a run of fixed length without until_steady")


@dataclass(frozen=True)
class RunOptions:
    """What every engine's run takes beside the parameter set, checked on construction.

    ``t_end`` [s]: the simulated time (with ``until_steady``, the cap); ``dt_out`` [s]: the output interval;
    ``until_steady``: stop at the end of the revolution where the periodic steady state is reached
    (:class:`.steady_watch.SteadyWatch` with ``steady_tol`` and ``steady_cycles``); ``progress(t)``: called with
    the simulated time [s] now and then (about every 0.1 s of it), or None; ``wall_budget_s`` [s]: the most
    wall-clock time a run may take (None: :data:`DEFAULT_WALL_BUDGET_S`, so that no run left alone goes on
    for hours; ``math.inf``: no limit, stored as None); ``max_switches``: the most mode switches an
    event-driven engine may make (None: the engine's default; MuJoCo has none to count).
    """

    t_end: float = 1.0
    dt_out: float = 1e-4
    until_steady: bool = False
    steady_tol: float = STEADY_TOL
    steady_cycles: int = STEADY_CYCLES
    progress: Callable[[float], None] | None = None
    wall_budget_s: float | None = None
    max_switches: int | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        t_end, dt_out = check_run_options(self.t_end, self.dt_out)
        set_(self, "t_end", t_end)
        set_(self, "dt_out", dt_out)
        if not isinstance(self.until_steady, (bool, np.bool_)):
            raise ParameterTypeError(f"until_steady={self.until_steady!r} is not a bool; allowed: True or False")
        set_(self, "until_steady", bool(self.until_steady))
        tol, cycles = check_steady_test(self.steady_tol, self.steady_cycles)
        set_(self, "steady_tol", tol)
        set_(self, "steady_cycles", cycles)
        if self.progress is not None and not callable(self.progress):
            raise ParameterTypeError(f"progress={self.progress!r} is not callable; allowed: a function of the "
                                 "simulated time [s], or None")
        if self.wall_budget_s is None:
            set_(self, "wall_budget_s", DEFAULT_WALL_BUDGET_S)
        else:
            budget = None if isinstance(self.wall_budget_s, bool) else as_real(self.wall_budget_s)
            if budget is None:
                raise ParameterTypeError(f"wall_budget_s={self.wall_budget_s!r} is not a number; allowed: a number "
                                         f"of seconds > 0, inf (no limit), or None (the default, "
                                         f"{DEFAULT_WALL_BUDGET_S:g} s)")
            if math.isnan(budget) or not budget > 0:
                raise ParameterError(f"wall_budget_s={self.wall_budget_s!r} is out of range; allowed: a number "
                                     f"of seconds > 0, inf (no limit), or None (the default, "
                                     f"{DEFAULT_WALL_BUDGET_S:g} s)")
            set_(self, "wall_budget_s", None if math.isinf(budget) else budget)
        if self.max_switches is not None:
            if isinstance(self.max_switches, bool) or not isinstance(self.max_switches, (int, np.integer)):
                raise ParameterTypeError(f"max_switches={self.max_switches!r} is out of range; allowed: a whole "
                                     "number >= 1")
            set_(self, "max_switches", check_whole("max_switches", self.max_switches, low=1))

    @classmethod
    def given(cls, t_end: Any, options: dict[str, Any]) -> "RunOptions":
        """The options of a run of ``t_end`` [s] from an engine's keywords ``options`` (the fields of this
        class but ``t_end``); a keyword that is not one of them is refused in one line, naming it."""
        unknown = [k for k in options if k not in _FIELDS]
        if unknown:
            raise ParameterError(f"option {unknown[0]!r} is unknown; allowed: {', '.join(_FIELDS)}")
        return cls(t_end, **options)

    @property
    def steady_settings(self) -> dict[str, Any]:
        """What a run records in its settings so that its summary applies the same steady-state test."""
        return {"until_steady": self.until_steady, "steady_tol": self.steady_tol,
                "steady_cycles": self.steady_cycles}


_FIELDS = tuple(name for name in RunOptions.__dataclass_fields__ if name != "t_end")


def check_type(name: str, value: Any, types: type | tuple[type, ...], allowed: str) -> Any:
    """``value`` if it is an instance of ``types`` (None passes where ``types`` holds ``type(None)``), else a
    one-line ParameterError naming the argument, what it got and ``allowed``: the public entry points check
    their arguments so that misuse is not a TypeError from deep inside."""
    if isinstance(value, bool) and bool not in (types if isinstance(types, tuple) else (types,)):
        raise ParameterTypeError(f"{name}={value!r} is not allowed; allowed: {allowed}")
    if not isinstance(value, types):
        raise ParameterTypeError(f"{name}={value!r} ({type(value).__name__}) is not allowed; allowed: {allowed}")
    return value


class RepeatProgress(float):
    """What a run's ``progress`` callable is given while the run is repeated at a finer step (an accuracy check's
    refinement, the wheeled model's skid check, which may take minutes): a float, the simulated time [s] the run
    had already reported (so that the times a callable sees never go back), carrying ``t`` [s], the repeat's own
    simulated time, ``attempt`` (2, 3, ...) and ``timestep`` [s], the repeat's step."""

    def __new__(cls, value: float, t: float, attempt: int, timestep: float):
        self = super().__new__(cls, value)
        self.t, self.attempt, self.timestep = float(t), int(attempt), float(timestep)
        return self


def progress_text(t: float, t_end: float) -> str:
    """A run's progress as a line says it: "simulated T / T_END s", and in a repeat (:class:`RepeatProgress`)
    the repeat's own time, with its step and attempt."""
    if isinstance(t, RepeatProgress):
        return (f"simulated {t.t:.2f} / {t_end:.4g} s again, at a {t.timestep:.3g} s step (attempt {t.attempt}: "
                "the accuracy check)")
    return f"simulated {t:.2f} / {t_end:.4g} s"


def throttled(report: Callable[[float], None], every_s: float = 5.0) -> Callable[[float], None]:
    """A run's ``progress=`` callable that passes the simulated time [s] on to ``report`` at most once every
    ``every_s`` seconds of wall time (the first after ``every_s``): a heartbeat inside a long run of a study,
    silent in a short one."""
    import time

    last = [time.monotonic()]

    def progress(t: float) -> None:
        now = time.monotonic()
        if now - last[0] >= every_s:
            last[0] = now
            report(t)
    return progress


HEARTBEAT_S = 10.0  # s of wall time between two "still running" lines of one long step


class heartbeat:  # noqa: N801 (used as a context manager, like contextlib's)
    """``with heartbeat(report, what) as beat:`` a long step says ``"{what}: still running ({s} s)"`` through
    ``report`` whenever ``every_s`` seconds of wall time pass with no line; the step's own lines go through
    ``beat.say(message)`` (to ``report``), each restarting that clock, so a step that reports often adds
    nothing. Silent when it ends sooner. A daemon thread: it never holds up the process's exit."""

    def __init__(self, report: Callable[[str], None], what: str, every_s: float = HEARTBEAT_S):
        self.report, self.what, self.every_s = report, what, every_s

    def say(self, message: str) -> None:
        import time

        self._last = time.monotonic()
        self.report(message)

    def __enter__(self) -> "heartbeat":
        import threading
        import time

        self._stop = threading.Event()
        self._started = self._last = time.monotonic()

        def beat() -> None:
            while not self._stop.wait(max(0.0, self._last + self.every_s - time.monotonic())):
                if time.monotonic() - self._last >= self.every_s:
                    self.say(f"{self.what}: still running ({time.monotonic() - self._started:.0f} s)")

        self._thread = threading.Thread(target=beat, name="ipir-heartbeat", daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc) -> bool:
        self._stop.set()
        self._thread.join()
        return False
