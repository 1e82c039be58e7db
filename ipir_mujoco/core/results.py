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
same way for every engine: ``peak_grip_use`` from ``lambda1/2`` and
``wheels1/2`` (:func:`grip_use`, :func:`peak_grip_use`), ``slip1_m``/``slip2_m``
from ``slip1/2``, ``mode_switches`` with the changes of ``wheels1/2``:

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
grip_use1/2  -     :func:`grip_use`: 1 while the module skids, else
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

import json
import math
from dataclasses import dataclass, field
from enum import IntEnum
from pathlib import Path
from typing import Any

import numpy as np

from .cycles import STEADY_CYCLES, STEADY_TOL, cycle_summary
from .errors import ParameterError
from .params import RobotParams
from .wheel_checks import run_summary
from .steady_test import steady_target

# [m/s] a module, the crank pin or the gap slower than this is at rest: far below any motion a run resolves,
# orders of magnitude above the creep of a module MuJoCo's soft constraints hold, so every engine's series
# reads rest alike (the analytic engines' rest is an exact 0). The summary's first minimum of S and MuJoCo's
# stall test use it.
REST_SPEED = 1e-6
# [s] how long every engine runs on once the robot is at rest for good (a stall) before it ends the run: MuJoCo
# needs that long below REST_SPEED to call a rest final, and its soft constraints to settle to the statics
REST_TIME = 0.1

COLUMNS: tuple[str, ...] = (
    "t", "phi", "omega", "alpha", "x1", "x2", "v1", "v2", "a1", "a2",
    "S", "S_dot", "lambda1", "lambda2", "mode",
)


# every series column any engine writes, and its unit (a column an engine adds is listed here too)
SERIES_UNITS: dict[str, str] = {
    "t": "s", "phi": "rad", "omega": "rad/s", "alpha": "rad/s^2", "x1": "m", "x2": "m", "v1": "m/s", "v2": "m/s",
    "a1": "m/s^2", "a2": "m/s^2", "S": "m", "S_dot": "m/s", "lambda1": "N", "lambda2": "N", "mode": "-",
    "motor_work": "J", "friction_work": "J", "kinetic": "J", "potential": "J", "clutch_spring_energy": "J",
    "clutch_damper_work": "J", "skid_work": "J", "motor_torque": "N m", "motor_power": "W", "rod_force": "N",
    "crank_pin_force": "N", "resistance1": "N", "resistance2": "N", "clutch_overlap1": "m", "clutch_overlap2": "m",
    "slip1": "m", "slip2": "m", "grip_use1": "-", "grip_use2": "-", "wheels1": "-", "wheels2": "-",
    "loop_gap": "m", "momentum": "kg m/s", "drive_u": "-", "y1": "m", "y2": "m", "yaw1": "rad", "yaw2": "rad",
    "link_y1": "N", "link_y2": "N", "link_z1": "N", "link_z2": "N",
}


class Mode(IntEnum):
    """Which clutches hold their module."""

    BOTH_LOCKED = 0  # nothing moves (stall)
    CONTRACTION = 1  # front locked, rear moves forward (S_dot < 0)
    EXPANSION = 2  # rear locked, front moves forward (S_dot > 0)
    BOTH_MOVING = 3  # neither clutch engaged (one-way clutches only)

    @property
    def rear_locked(self) -> bool:
        return self in (Mode.BOTH_LOCKED, Mode.EXPANSION)

    @property
    def front_locked(self) -> bool:
        return self in (Mode.BOTH_LOCKED, Mode.CONTRACTION)


MODE_NAMES: dict[int, str] = {int(m): m.name.lower() for m in Mode}


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

        A thin call of :func:`ipir_mujoco.report.plots.plot_runs` (the drawing lives in the report layer, which
        imports nothing of this module: no import cycle)."""
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


def mode_changes(series: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    """Every change of mode: time [s], crank angle [rad] and its position in the turn [deg], from, to."""
    modes = np.asarray(series["mode"], dtype=int)
    changes = []
    for i in np.flatnonzero(np.diff(modes)):
        phi = float(series["phi"][i + 1])
        changes.append({"t": float(series["t"][i + 1]), "phi": phi,
                        "phi_deg_in_turn": math.degrees(phi % (2 * math.pi)),
                        "from": MODE_NAMES[int(modes[i])], "to": MODE_NAMES[int(modes[i + 1])]})
    return changes


def write_mode_changes(path: str | Path, series: dict[str, np.ndarray]) -> None:
    """Write :func:`mode_changes` as CSV."""
    lines = ["t,phi,phi_deg_in_turn,from,to"]
    lines += [f"{c['t']:.12g},{c['phi']:.12g},{c['phi_deg_in_turn']:.6f},{c['from']},{c['to']}"
              for c in mode_changes(series)]
    Path(path).write_text("\n".join(lines) + "\n")


def first_gap_minimum(t: np.ndarray, S_dot: np.ndarray) -> float | None:
    """Time of the first minimum of S [s]: where S first stops falling, S_dot turning from below -REST_SPEED
    to -REST_SPEED or above (rising, or at rest: a robot that stalls while contracting has its minimum where
    it comes to rest, whether its series holds an exact 0 there or the soft constraints' creep).

    Arrays of shape (n,): t [s], S_dot [m/s]. The time where S_dot reaches 0, linearly interpolated between
    the two samples (the later one if S_dot stays below 0, at rest); None if S never stops falling.
    """
    falling = S_dot[:-1] < -REST_SPEED
    stopped = S_dot[1:] >= -REST_SPEED
    hits = np.flatnonzero(falling & stopped)
    if hits.size == 0:
        return None
    i = hits[0]
    s0, s1 = S_dot[i], S_dot[i + 1]
    return float(t[i] + (t[i + 1] - t[i]) * min(1.0, -s0 / (s1 - s0)))


def min_locked_reaction(series: dict[str, np.ndarray]) -> float | None:
    """Smallest reaction of a locked clutch over the run [N]; None if none locked."""
    modes = np.asarray(series["mode"], dtype=int)
    rear = np.isin(modes, [Mode.BOTH_LOCKED, Mode.EXPANSION])
    front = np.isin(modes, [Mode.BOTH_LOCKED, Mode.CONTRACTION])
    values = np.concatenate([series["lambda1"][rear], series["lambda2"][front]])
    return float(values.min()) if values.size else None


def mode_switches(series: dict[str, np.ndarray]) -> int:
    """How often the run changes mode: the ``mode`` column, and with finite grip the module states
    ``wheels1/2`` too (a module that turns from rolling forward to skidding back changes mode where the
    kinematics, which say only which modules stand, do not)."""
    changed = np.diff(np.asarray(series["mode"], dtype=int)) != 0
    for column in ("wheels1", "wheels2"):
        if column in series:
            changed |= np.diff(np.asarray(series[column], dtype=float)) != 0
    return int(np.count_nonzero(changed))


def slip(series: dict[str, np.ndarray], module: int) -> float:
    """Backward skid [m] of module ``module`` (1 or 2) over the run, >= 0: the growth of its ``slip``
    column; 0.0 where the series has none (nothing skids: unlimited grip)."""
    column = series.get(f"slip{module}")
    return 0.0 if column is None else max(float(column[-1] - column[0]), 0.0)


def grip_use(lam, wheels, G: float) -> np.ndarray:
    """One module's ``grip_use`` column [-], the one definition every engine writes: 1 where its wheels skid
    (``wheels`` == -1), else its clutch's reaction over its grip, max(lambda, 0) / G, at most 1 (a module that
    does not skid holds within its grip by the law; what a soft engine shows beyond it, a carriage's or a
    wheel's inertia force, is not the clutch's use of the grip). G = 0 [N]: 0 unless it skids. Arrays (n,):
    ``lam`` [N] the ``lambda`` column, ``wheels`` the ``wheels`` column (+1 rolling, 0 standing, -1 skidding)."""
    lam, wheels = np.asarray(lam, dtype=float), np.asarray(wheels, dtype=float)
    use = np.minimum(np.maximum(lam, 0.0) / G, 1.0) if G > 0 else np.zeros(lam.shape)
    return np.where(wheels == -1.0, 1.0, use)


def peak_grip_use(series: dict[str, np.ndarray], grip: tuple[float, float] | None = None) -> float | None:
    """Largest grip use over the run [-] (1: a module skidded), from the columns every engine writes on finite
    grip, ``lambda1/2`` and ``wheels1/2``, by :func:`grip_use` with ``grip`` (G1, G2) [N] (a series without
    them: its ``grip_use1/2`` columns). None with unlimited grip (``grip`` None: no ratio exists)."""
    if grip is None:
        return None
    if all(c in series for c in ("lambda1", "lambda2", "wheels1", "wheels2")):
        return float(max(grip_use(series[f"lambda{k}"], series[f"wheels{k}"], G).max()
                         for k, G in zip((1, 2), grip)))
    columns = [np.asarray(series[c], dtype=float) for c in ("grip_use1", "grip_use2") if c in series]
    return float(max(c.max() for c in columns)) if columns else None


def wheel_keys(series: dict[str, np.ndarray]) -> dict[str, float]:
    """The wheeled MuJoCo model's wall figures (a run with the ``press1/2`` and ``wheels_off`` columns; {} for
    others): ``press1_n``, ``press2_n`` [N], each module's mean total wall press over the run's samples;
    ``wheel_off_s`` [s], how long any wheel was off its wall (the sample intervals that start with one off)."""
    if "press1" not in series:
        return {}
    t, off = np.asarray(series["t"], dtype=float), np.asarray(series["wheels_off"], dtype=float)
    return {"press1_n": float(np.mean(series["press1"])), "press2_n": float(np.mean(series["press2"])),
            "wheel_off_s": float(np.sum(np.diff(t)[off[:-1] > 0]))}


def summarize(series: dict[str, np.ndarray], energy: dict[str, float],
              grip: tuple[float, float] | None = None) -> dict[str, Any]:
    """The summary figures of a run, computed from its time series; ``grip`` (G1, G2) [N] of finite grip
    (:attr:`.params.RobotParams.grip`), None for unlimited grip."""
    t, phi = series["t"], series["phi"]
    return {
        "revolutions": float((phi[-1] - phi[0]) / (2 * math.pi)),
        "x1_final": float(series["x1"][-1] - series["x1"][0]),
        "x2_final": float(series["x2"][-1] - series["x2"][0]),
        "v1_max": float(np.max(series["v1"])),
        "v2_max": float(np.max(series["v2"])),
        "first_contraction_end_s": first_gap_minimum(t, series["S_dot"]),
        "mode_switches": mode_switches(series),
        "min_clutch_reaction_n": min_locked_reaction(series),
        "slip1_m": slip(series, 1),
        "slip2_m": slip(series, 2),
        "peak_grip_use": peak_grip_use(series, grip),
        **wheel_keys(series),
        "energy": dict(energy),
    }


def stall_reason(t: float, phi: float, torque: float, gravity: bool) -> str:
    """RunResult.stall, in the same words for every engine: the robot at rest for good from time ``t`` [s],
    the crank at ``phi`` [rad], where the drive's torque at rest ``torque`` [N m] cannot move it;
    ``gravity``: whether gravity pulls along the pipe (an incline)."""
    against = "the resistances and gravity" if gravity else "the resistances"
    return (f"at rest from t={t:.6g} s at phi={phi:.6g} rad ({math.degrees(phi) % 360:.1f} deg in its turn): the "
            f"drive's torque at rest ({torque:.6g} N m) cannot move the linkage against {against}")


def json_ready(data: Any) -> Any:
    """``data`` with every number that is not finite (inf, -inf, nan; Python or numpy floats) replaced by None, in
    nested dicts, lists and tuples: JSON has no infinity, and every figure a run or a study writes is then
    readable by strict JSON readers. What null means for each summary key that can be unbounded is in
    docs/cli.md (``side_use1``, ``side_use2``: unbounded, a side load with no grip to hold it); elsewhere it is
    "no such figure" (tests/test_json_summaries.py holds which keys of every engine's summary may be non-finite)."""
    if isinstance(data, dict):
        return {key: json_ready(value) for key, value in data.items()}
    if isinstance(data, (list, tuple)):
        return [json_ready(value) for value in data]
    if isinstance(data, (float, np.floating)) and not math.isfinite(data):
        return None
    return data


def json_text(data: Any, indent: int | None = None) -> str:
    """``data`` as JSON text (:func:`json_ready`: no inf or nan), as ``simulate --json`` prints it and
    :func:`write_json` writes it."""
    return json.dumps(json_ready(data), indent=indent, allow_nan=False)


def write_json(path: str | Path, data: dict[str, Any]) -> None:
    """Write ``data`` as indented JSON (:func:`json_text`: a number that is not finite is null), through a
    temporary file renamed into place: a failed write (a full disk) leaves the earlier file, or none, never a cut
    one."""
    import os

    text = json_text(data, indent=2) + "\n"
    path = Path(path)
    staged = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")  # umask permissions (mkstemp: 0600)
    try:
        staged.write_text(text, encoding="utf-8")
        os.replace(staged, path)
    except BaseException:
        if os.path.exists(staged):
            os.unlink(staged)
        raise
