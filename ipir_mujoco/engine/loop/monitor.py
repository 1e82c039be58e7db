"""The accuracy monitor of every MuJoCo run: three figures, each with a tolerance, never silent.

MuJoCo's constraints are soft and its step is first order, so a run can drift
from the mechanism it models without any warning from MuJoCo itself. Three
figures show it while the run goes, each measured on the run's own state:

``residual_ratio``
    The energy audit's residual (motor work - work against the resistances -
    kinetic and potential energy gained, and with compliant clutches - the
    energy their springs hold - the work their dampers dissipated: what the
    soft constraints (loop, rigid clutches, friction rows) and the time
    stepping, the clutch springs' included, created or lost) over the energy
    put through the robot so far:
    the largest of the motor work, the work against the resistances, the
    potential energy change and the initial kinetic energy, and at least one
    revolution's energy: the drive's 2 pi |torque| and the potential energy of
    a climb by one stroke 2 r (the rule near the start, where the motor work is
    still tiny, and for a robot that gravity moves). A compliant clutch's spring
    is counted as the step conserves it (:meth:`.compliant.CompliantClutches.stepped_spring_energy`),
    so an impact under way does not swing the figure by 1/2 omega dt of its
    energy. Tolerance 1e-3: over the cases of the convergence study
    (:mod:`ipir_mujoco.studies.convergence`) the relative error in revolutions
    stays below the residual ratio, whether the soft constraints dissipate (a
    light rod) or the stepping creates energy (a fast crank), so 1e-3 keeps the
    revolutions within 0.1 % of the converged mechanism.
``loop_gap_m``
    Distance between the rod's end C and module 2's pin [m]: how far the
    loop-closing constraint gives. A gap g moves the linkage's angles by about
    g / r and does not accumulate. The tolerance is 1e-3 r (5e-5 m for the paper's
    crank): in the timestep studies a gap past it came with an error in
    revolutions past the 0.1 % target, and a gap well inside it with an error
    well inside the target (the evidence is in mjcf/README.md).
``excursion_m``
    How far a module slid back below its furthest position so far [m] (the
    ratchet's give; 0 for an ideal one-way clutch). Each hold lets the module
    lose at most that much of the stroke 2 r it gains per revolution, so an
    excursion e costs at most e / (2 r) of the travel; the tolerance
    2e-4 r keeps that at 1e-4, a tenth of the 0.1 % target; 1e-5 m for the
    paper's crank. Rigid clutches only: a compliant clutch's module moving back
    is its physics (the series' ``clutch_overlap1``/``clutch_overlap2``), so
    the figure stays 0 there. On finite grip (:mod:`.grip`) it is the give of
    either one-way limit, the wheels' roll below its running maximum and the
    carriage above its running minimum (compliant clutches: the carriage's);
    a module skidding back moves its carriage's running minimum itself and is
    not a give.

Crossing a tolerance stops the run with a :class:`SimulationError` that names
the time, the figure, its value, the tolerance and the remedy
(``accuracy='stop'``, the default), or is recorded in the run's accuracy
record and the run goes on (``accuracy='warn'``).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ipir_mujoco.core import energy
from ipir_mujoco.core.energy import DISSIPATED, INPUT, KINETIC, STORED
from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams

ACCURACY_MODES = ("stop", "warn")
RESIDUAL_TOL = 1e-3  # of the energy put through the robot (see the module docstring)
LOOP_GAP_PER_R = 1e-3  # loop gap tolerance over the crank length r
EXCURSION_PER_R = 2e-4  # backward excursion tolerance over the crank length r


@dataclass(frozen=True)
class Tolerances:
    """The monitor's tolerances: residual ratio [-], loop gap [m], backward excursion [m]."""

    residual_ratio: float
    loop_gap_m: float
    excursion_m: float

    @classmethod
    def for_params(cls, params: RobotParams) -> "Tolerances":
        return cls(RESIDUAL_TOL, LOOP_GAP_PER_R * params.r, EXCURSION_PER_R * params.r)


def energy_audit(motor_j, dissipated_j, kinetic_gain_j, stored_gain_j, floor_j):
    """The energy audit's (residual [J], scale [J]) of the ``residual_ratio`` figure (module docstring).

    ``motor_j``: the drive's cumulative work; ``dissipated_j``: the work against the resistances (and the
    compliant clutches' dampers); ``kinetic_gain_j``: the kinetic energy gained since t = 0;
    ``stored_gain_j``: the potential energy gained (and the clutch springs' change); ``floor_j``: the
    smallest scale (the initial kinetic energy, one revolution's energy). Floats or arrays of one shape
    (a batch's designs). residual = motor - dissipated - kinetic - stored; scale = the largest of |motor|,
    dissipated, |stored| and the floor. Every run's monitor and energy record use this one audit.
    """
    residual = energy.residual({INPUT: motor_j, DISSIPATED: dissipated_j, KINETIC: kinetic_gain_j,
                                STORED: stored_gain_j})
    scale = np.maximum(np.maximum(np.abs(motor_j), dissipated_j), np.maximum(np.abs(stored_gain_j), floor_j))
    return residual, scale


def residual_ratio(residual_j: float, scale_j: float) -> float:
    """residual / scale, 0 for a zero scale (nothing put through the robot yet)."""
    return float(residual_j / scale_j) if scale_j > 0 else 0.0


class AccuracyError(SimulationError):
    """A run stopped by the accuracy monitor (a SimulationError: exit status 1)."""


def check_accuracy_mode(accuracy: str) -> str:
    if accuracy not in ACCURACY_MODES:
        raise ParameterError(f"accuracy={accuracy!r} is unknown; allowed: {', '.join(ACCURACY_MODES)}")
    return accuracy


_WHAT = {
    "residual_ratio": "the energy residual (energy the stepping created or lost) reached {value:+.2e} of the "
                      "energy put through the robot",
    "loop_gap_m": "the loop-closure gap (rod end to module 2's pin) reached {value:.3g} m",
    "excursion_m": "a module slid back {value:.3g} m below its furthest position (ratchet excursion)",
}


class AccuracyMonitor:
    """Tracks the worst of each figure and acts when one crosses its tolerance.

    ``timestep`` [s] is the run's, for the remedy in the message. Feed it with
    :meth:`residual`, :meth:`loop_gap` and :meth:`excursion`; read
    :meth:`record` at the end.
    """

    def __init__(self, tolerances: Tolerances, mode: str = "stop", timestep: float | None = None):
        self.tolerances, self.mode, self.timestep = tolerances, check_accuracy_mode(mode), timestep
        self.worst = {"residual_ratio": 0.0, "loop_gap_m": 0.0, "excursion_m": 0.0}
        self.worst_t = dict.fromkeys(self.worst, 0.0)
        self.violations: list[dict] = []
        self._crossed: set[str] = set()

    def residual(self, t: float, residual_j: float, scale_j: float) -> None:
        """The audit's residual [J] at time ``t`` [s] against the energy put through the robot [J]."""
        ratio = residual_ratio(residual_j, scale_j)
        if abs(ratio) > abs(self.worst["residual_ratio"]):
            self.worst["residual_ratio"], self.worst_t["residual_ratio"] = ratio, t
            if abs(ratio) > self.tolerances.residual_ratio:
                self._crossing("residual_ratio", t, ratio, self.tolerances.residual_ratio)

    def loop_gap(self, t: float, gap_m: float) -> None:
        if gap_m > self.worst["loop_gap_m"]:
            self.worst["loop_gap_m"], self.worst_t["loop_gap_m"] = gap_m, t
            if gap_m > self.tolerances.loop_gap_m:
                self._crossing("loop_gap_m", t, gap_m, self.tolerances.loop_gap_m)

    def excursion(self, t: float, excursion_m: float) -> None:
        if excursion_m > self.worst["excursion_m"]:
            self.worst["excursion_m"], self.worst_t["excursion_m"] = excursion_m, t
            if excursion_m > self.tolerances.excursion_m:
                self._crossing("excursion_m", t, excursion_m, self.tolerances.excursion_m)

    def _crossing(self, figure: str, t: float, value: float, tolerance: float) -> None:
        if self.mode == "stop":
            raise AccuracyError(self.message(figure, t, value, tolerance))
        if figure not in self._crossed:  # the first crossing of each figure; the worst is in record()
            self._crossed.add(figure)
            self.violations.append({"figure": figure, "t_s": float(t), "value": float(value),
                                    "tolerance": float(tolerance)})

    def message(self, figure: str, t: float, value: float, tolerance: float) -> str:
        smaller = f" (e.g. --timestep {self.timestep / 2:.3g})" if self.timestep else ""
        return (f"MuJoCo accuracy check failed at t={t:.6g} s: {_WHAT[figure].format(value=value)}, tolerance "
                f"{tolerance:.3g}; use a smaller --timestep{smaller}, or --accuracy warn to finish the run and "
                "record it")

    def record(self, final_residual_ratio: float | None = None) -> dict:
        """The run's accuracy record: worst figures, when they occurred, tolerances, violations."""
        out = {k: float(v) for k, v in self.worst.items()}
        out["worst_at_s"] = {k: float(v) for k, v in self.worst_t.items()}
        if final_residual_ratio is not None and math.isfinite(final_residual_ratio):
            out["residual_ratio_final"] = float(final_residual_ratio)
        out["tolerances"] = asdict(self.tolerances)
        out["mode"] = self.mode
        out["ok"] = not self.violations
        out["violations"] = list(self.violations)
        return out


def rising(values: np.ndarray, worst: float, tolerance: float, offset: int) -> list[int]:
    """Rows (index + ``offset``) of ``values`` the monitor must be fed to end as if fed each in turn (each
    that beats the worst so far, starting from ``worst``): the first fed one beyond ``tolerance`` (it is
    the first beyond both, and the one that stops a run or is recorded as its crossing), and the first of
    the largest, if it beats ``worst`` (NaN never does). Every other value would only be overtaken."""
    size = np.abs(values)
    largest = np.fmax.reduce(size)
    if not largest > abs(worst):  # the common case once a run is under way: nothing to feed
        return []
    rows = []
    threshold = max(abs(worst), tolerance)
    if largest > threshold:
        rows.append(int(np.argmax(size > threshold)))
    top = int(np.argmax(size == largest))
    if not rows or top != rows[0]:
        rows.append(top)
    return [row + offset for row in rows]
