"""One result container for every engine: time series, energy audit, summary.

Engines fill :class:`RunResult`; compare, report and sweep read it and never
care which engine produced a run. The summary is computed here, from the time
series, the same way for every engine.

Time series columns (each an ndarray of shape (n,)):

=========  ========  ======================================================
column     units     meaning
=========  ========  ======================================================
t          s         time; non-decreasing. An instant where the mode
                     switches appears twice, once per mode, because
                     accelerations and reactions jump there.
phi        rad       crank angle (0 = full extension)
omega      rad/s     crank speed
alpha      rad/s^2   crank angular acceleration
x1, x2     m         displacement of module 1 (rear) / 2 (front) from t = 0
v1, v2     m/s       module velocities
a1, a2     m/s^2     module accelerations
S          m         gap x2_abs - x1_abs between A and C
S_dot      m/s       gap rate
lambda1/2  N         clutch reaction on module 1 / 2, positive pushing the
                     module forward; 0 while the module rolls forward (a
                     module skidding back on finite grip: its grip G_i)
mode       -         :class:`Mode` as an integer
=========  ========  ======================================================

Engines add their own columns beside these; every engine that drives the
robot also writes the cumulative energy columns :mod:`.cycles` reads
(``motor_work``, ``friction_work``, ``kinetic``, ``potential``, all in J).

With finite grip (``mu_wall``, docs/model.md "Finite grip") every engine writes
these too (a run without them, as with unlimited grip, has slip1_m = slip2_m =
0.0 and peak_grip_use = None). The summary's grip keys are read off them the
same way for every engine (:mod:`.summary`): ``peak_grip_use`` from
``lambda1/2`` and ``wheels1/2`` (:func:`.summary.grip_use`,
:func:`.summary.peak_grip_use`), ``slip1_m``/``slip2_m`` from ``slip1/2``,
``mode_switches`` with the changes of ``wheels1/2``:

===========  ====  ====================================================
column       unit  meaning
===========  ====  ====================================================
wheels1/2    -     each module's state, +1 rolling forward, 0 standing,
                   -1 skidding back (its locked wheels slide back on the
                   wall); a module counts as held (``mode``) only while
                   it stands
lambda1/2    N     (the columns above) the clutch's share of the hold
                   while the module stands, what its clutch carries
                   while it skids (G_i), 0 while it rolls
slip1/2      m     backward skid of module 1 / 2's locked wheels on the
                   wall since t = 0 (cumulative, >= 0: their backward
                   travel over the samples where it skids; with a
                   compliant clutch its anchor's, not the module body's)
grip_use1/2  -     :func:`.summary.grip_use`: 1 while the module skids, else
                   max(lambda_i, 0) / G_i capped at 1 (0 where G_i = 0)
skid_work    J     cumulative work of the grip against skidding,
                   sum G_i slip_i; an energy audit term (``skid_j``)
===========  ====  ====================================================

MuJoCo's wheeled model (``mujoco-wheels``) also writes each module's pose in
the mechanism's plane beside its x: ``y1``, ``y2`` [m] (module 1's A, module
2's C across the first straight's axis, 0 on it) and ``yaw1``, ``yaw2`` [rad]
(its turn about the plane's normal, 0 along x, positive towards +y), so that
``render`` can replay a run along a route with bends.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .cycles import STEADY_CYCLES, STEADY_TOL, cycle_summary
from .errors import ParameterError
from .params import RobotParams
from .wall_summary import run_summary
from .steady_test import steady_target
# re-exported (their home was here): the series' vocabulary, the summary's figures, the JSON writers
from .columns import COLUMNS, MODE_NAMES, REST_SPEED, REST_TIME, SERIES_UNITS, Mode  # noqa: F401
from .json_out import json_ready, json_text, write_json  # noqa: F401
from .summary import (first_gap_minimum, grip_use, min_locked_reaction, mode_changes, mode_switches,  # noqa: F401
                      peak_grip_use, slip, stall_reason, summarize, wheel_keys, write_mode_changes)


@dataclass
class RunResult:
    """A run of one engine.

    ``series`` maps every name in :data:`COLUMNS` to an ndarray of shape (n,).
    ``energy`` holds the engine's energy audit in joules: ``motor_work_j``
    (work of the motor torque), ``kinetic_j`` (kinetic energy gained),
    ``friction_j`` (work against the resistances) and ``residual_j`` (motor
    work minus the other two; the integration or solver error), plus any
    engine-specific terms. ``settings`` records solver settings (and, when
    given, ``steady_tol`` and ``steady_cycles`` for the steady-state test).
    ``stall`` is None, or why the robot ended at rest for good (with the time).
    ``accuracy`` is the engine's own accuracy record (MuJoCo: at least
    ``residual_ratio`` and ``loop_gap_m``), or None. ``route`` is None, or a
    run along a route's summary keys (``route_done``, ``route_time_s``,
    ``route_stop``, ...: ``ipir_mujoco.engine.kinds.wheels.route_watch``).
    ``figures`` is None, or figures that stand in the summary in place of the
    series' own, with their estimated absolute errors: ``{"values": {FIGURE:
    value}, "errors": {FIGURE: error}}`` (MuJoCo's finite grip: the rigid limit
    extrapolated from runs at several constraint time constants,
    ``ipir_mujoco.engine.kinds.slides_grip.rigid_limit``); the summary then has
    ``figure_errors`` = its ``errors``.

    Parameters
    ----------
    engine : str
        'analytic' or 'mujoco'.
    geometry : str
        'approx' (the paper's first order) or 'exact'.
    clutch : str
        The clutch rule: 'kinematic', 'unilateral' (or 'none').
    params : RobotParams
        The parameter set the run used.
    t_end : float
        The last sample's time [s].
    series : dict of str to ndarray
        Every column of :data:`COLUMNS` (and engine-specific ones), each of shape (n,), in SI units
        (:data:`SERIES_UNITS`).
    energy : dict of str to float
        The energy audit [J].
    wall_time_s : float
        Wall time of the run [s].
    settings : dict
        Solver settings and what chose them.
    stall, accuracy, route, figures
        As above.

    Attributes
    ----------
    summary : dict
        Figures every engine's run gets (revolutions, speeds, peak forces, steady state, efficiency, ...).
    """

    engine: str
    geometry: str
    clutch: str
    params: RobotParams
    t_end: float
    series: dict[str, np.ndarray]
    energy: dict[str, float]
    wall_time_s: float = 0.0
    settings: dict[str, Any] = field(default_factory=dict)
    stall: str | None = None
    accuracy: dict[str, Any] | None = None
    route: dict[str, Any] | None = None
    figures: dict[str, Any] | None = None

    def __post_init__(self) -> None:
        missing = [c for c in COLUMNS if c not in self.series]
        if missing:
            raise ValueError(f"time series lacks columns {missing}")
        n = len(self.series["t"])
        bad = [c for c, v in self.series.items() if np.shape(v) != (n,)]
        if bad:
            raise ValueError(f"time series columns {bad} do not have shape ({n},)")

    @property
    def steady_test(self) -> tuple[float, int]:
        """(tol, cycles) of the steady-state test the run applied (its settings), or the defaults
        (:data:`.cycles.STEADY_TOL`, :data:`.cycles.STEADY_CYCLES`): what every figure read off its steady
        window must apply too."""
        return (self.settings.get("steady_tol", STEADY_TOL), self.settings.get("steady_cycles", STEADY_CYCLES))

    @property
    def steady_target(self) -> float:
        """The statistical steady test's target [-] of this run (:func:`.steady_test.steady_target`: the
        accuracy its engine states for steady figures, or its steady_tol where looser), as its engine's watch
        applied it."""
        return steady_target(self.engine, self.steady_test[0])

    @property
    def summary(self) -> dict[str, Any]:
        """The summary figures of the command-line contract (docs/cli.md)."""
        summary = summarize(self.series, self.energy, self.params.grip)
        if "press1" in self.series:  # the wheeled MuJoCo model: the closed-form checks beside its outcome (a
            # route's bends have theirs in route_fit); computed once per series (a long run's take a second)
            key = (id(self.series), len(self.series["t"]), id(self.route))
            cached = self.__dict__.get("_wall_summary")
            if cached is None or cached[0] != key:
                cached = (key, run_summary(self.params, self.series, (self.route or {}).get("route_fit"),
                                           straight=not self.route))
                self.__dict__["_wall_summary"] = cached
            summary.update(cached[1])
        summary.update(cycle_summary(self.series, *self.steady_test, target=self.steady_target))
        summary["stalled"] = self.stall is not None
        summary["stall_reason"] = self.stall
        if self.stall is not None:  # a robot at rest for good has no revolution to be "per": no such figures
            summary.update(distance_per_rev_m=None, energy_per_metre_j_m=None, efficiency=None)
        accuracy = dict(self.accuracy or {})
        if "residual_ratio" not in accuracy and "residual_j" in self.energy:
            # against the energy put through the robot, as the MuJoCo engine's monitor measures it (its floor:
            # the kinetic energy at the start, which the solver's rtol applies to as well): the motor's work
            # alone is no scale where the robot coasts or runs downhill (0 with the drive off)
            e = self.energy
            start = float(self.series["kinetic"][0]) if "kinetic" in self.series else 0.0
            scale = max(abs(e.get("motor_work_j", 0.0)),
                        e.get("friction_j", 0.0) + e.get("clutch_damper_j", 0.0) + e.get("skid_j", 0.0),
                        abs(e.get("potential_j", 0.0) + e.get("clutch_spring_j", 0.0)), abs(e.get("kinetic_j", 0.0)),
                        abs(start))
            if scale > 0:
                accuracy["residual_ratio"] = e["residual_j"] / scale
        summary["accuracy"] = accuracy
        if self.route is not None:  # a run along a route: route_done, route_time_s, route_stop, ...
            summary.update(self.route)
        if self.figures is not None:  # figures extrapolated beyond the series (the rigid limit), with their errors
            summary.update(self.figures["values"])
            summary["figure_errors"] = dict(self.figures["errors"])
        return summary

    def to_json_dict(self) -> dict[str, Any]:
        """The object ``simulate --json`` prints."""
        return {
            "engine": self.engine,
            "geometry": self.geometry,
            "clutch": self.clutch,
            "params": self.params.as_dict(),
            "t_end": self.t_end,
            "summary": self.summary,
            "wall_time_s": self.wall_time_s,
            "settings": self.settings,
            "mode_names": {str(k): v for k, v in MODE_NAMES.items()},
        }

    def to_pandas(self):
        """The time series as a ``pandas.DataFrame``, one column per series column (shape (n,)), indexed by
        sample; ``df.attrs`` holds ``units`` ({column: unit}), ``summary`` and ``engine``/``geometry``/
        ``clutch``. pandas is optional: ``pip install pandas`` (a ParameterError says so where it is missing)."""
        try:
            import pandas
        except ImportError:
            raise ParameterError("to_pandas needs pandas: pip install pandas (or 'ipir-mujoco[notebook]')") from None
        frame = pandas.DataFrame({c: np.asarray(v) for c, v in self.series.items()})
        frame.attrs.update(units={c: SERIES_UNITS.get(c, "") for c in self.series}, summary=self.summary,
                           engine=self.engine, geometry=self.geometry, clutch=self.clutch)
        return frame

    def plot(self, *others: "RunResult", path: str | Path | None = None):
        """The paper's figures (crank, modules, gap against time) of this run and any ``others`` drawn over it:
        a list of three matplotlib figures; with ``path`` (a folder) also written there as fig2-4 PNG.

        A thin call of :func:`ipir_mujoco.core.figures.plot_runs` (the drawing, which imports nothing of this
        module at run time: no import cycle)."""
        from ipir_mujoco.core.figures import plot_runs  # matplotlib is loaded only when a run is drawn

        return plot_runs([self, *others], path)

    def write_csv(self, path: str | Path) -> None:
        """Write the time series as CSV with a header row of :data:`COLUMNS`."""
        extra = [c for c in self.series if c not in COLUMNS]
        names = list(COLUMNS) + extra
        table = np.column_stack([np.asarray(self.series[c], dtype=float) for c in names])
        fmt = ["%d" if c == "mode" else "%.12g" for c in names]
        np.savetxt(path, table, delimiter=",", header=",".join(names), comments="", fmt=fmt)


def read_csv(path: str | Path) -> dict[str, np.ndarray]:
    """Read a time series written by :meth:`RunResult.write_csv`."""
    table = np.genfromtxt(path, delimiter=",", names=True)
    series = {name: np.atleast_1d(table[name]).astype(float) for name in table.dtype.names}
    series["mode"] = series["mode"].astype(int)
    return series
