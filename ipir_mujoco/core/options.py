"""The options of a run, checked once for every engine and interface.

:class:`RunOptions` is the one check: the simulated time and output interval, the steady-state stop, the work
budgets and the progress callback, each refused with a one-line :class:`ParameterError` naming the value and
what is allowed. Both models' entry points (:func:`ipir_mujoco.analytic.simulate`,
:func:`ipir_mujoco.engine.simulate_mujoco`) build one from their keywords; the registry
(:mod:`ipir_mujoco.registry`), the command line and the study files reach it through them. What only one
engine has (the analytic solver's tolerances, MuJoCo's solver settings and clutch choice) is that engine's
own check. The bounds it checks against (:mod:`.limits`, numpy-free) are re-exported here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .cycles import STEADY_CYCLES, STEADY_TOL
from .steady_watch import check_steady_test
from .errors import ParameterError, ParameterTypeError
from .limits import (CLUTCH_RULES, DEFAULT_WALL_BUDGET_S, MAX_SAMPLES, MAX_STEPS, MAX_T_END, SAMPLE_BYTES,  # noqa: F401
                     STUDY_SAMPLES, check_run_options, check_step_count, refuse_steady_without_motor,
                     study_dt_out)  # (re-exported)
from .params import as_real, check_whole


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


HEARTBEAT_S = 5.0  # s of wall time between two "still running" lines of one long step (a log's: at least so often)
LIVE_HEARTBEAT_S = 1.0  # s: the same for a printer that shows them as a terminal's status line (``report.live``)


class Status(str):
    """A progress message that a printer may show as its status line, in place of the last one (a terminal's
    single line rewritten: "still running (12 s)"), rather than as a line of its own (:mod:`ipir_mujoco.terminal`)."""


class heartbeat:  # noqa: N801 (used as a context manager, like contextlib's)
    """``with heartbeat(report, what) as beat:`` a long step says ``"{what}: still running ({s} s)"`` (a
    :class:`Status`) through ``report`` whenever ``every_s`` seconds of wall time pass with no line (default
    HEARTBEAT_S, or LIVE_HEARTBEAT_S for a ``report`` whose ``live`` attribute is true: the command line's, which
    shows it in place on a terminal and every 5 s in a log); the step's own lines go through ``beat.say(message)``
    (to ``report``), each restarting that clock, so a step that reports often adds nothing. Silent when it ends
    sooner. A daemon thread: it never holds up the process's exit."""

    def __init__(self, report: Callable[[str], None], what: str, every_s: float | None = None):
        if every_s is None:
            every_s = LIVE_HEARTBEAT_S if getattr(report, "live", False) else HEARTBEAT_S
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
                    self._last = time.monotonic()  # a status: the step's own lines are what restarts the clock
                    self.report(Status(f"{self.what}: still running ({time.monotonic() - self._started:.0f} s)"))

        self._thread = threading.Thread(target=beat, name="ipir-heartbeat", daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc) -> bool:
        self._stop.set()
        self._thread.join()
        return False
