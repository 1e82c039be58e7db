"""Per-revolution figures of a run and its periodic steady state, for every engine.

A *cycle* is one crank revolution: it ends where the crank's running maximum
angle first reaches phi(0) + 2 pi k (the running maximum, because a crank may
rock back before it turns on). Everything here reads a run's time series, the
same way for every engine, and computes no dynamics: it belongs with the result
container.

Columns used (each an ndarray of shape (n,)): ``t``, ``phi``, ``x1``, ``x2``,
and where present the cumulative energy columns every engine writes:
``motor_work`` (work done by the motor since t = 0, J), ``friction_work``
(work done against the resistances since t = 0, J, >= 0), ``kinetic`` (kinetic
energy, J) and ``potential`` (gravitational potential energy from the start,
J), with compliant clutches ``clutch_spring_energy`` (energy stored in the
clutch springs, J) and ``clutch_damper_work`` (cumulative work dissipated by the
clutch dampers, J), and with finite grip ``skid_work`` (cumulative work of the
grip against skidding wheels, J); plus ``lambda1``/``lambda2`` (clutch reactions, N), ``rod_force`` (N) and
``a1``/``a2`` (m/s^2) for the peaks. At a cycle boundary that falls between
two samples the columns are interpolated linearly; engines that can (the
analytic ones) put a sample exactly on each boundary.

Steady state: the run is at its periodic steady state at the end of cycle k
when the mean speeds of the last ``cycles`` revolutions (k - cycles + 1 .. k)
all lie within ``tol`` * |mean of them| of each other, that mean is > 0, and
the speed's remaining drift, extrapolated from the last two changes, is within
``tol`` * mean as well (see :func:`.steady_test.steady_at_end`): a heavy flywheel settles so
slowly that three revolutions can agree within ``tol`` while the speed is still
many times ``tol`` short of its final value.
The steady *window* is those revolutions. The steady figures state the periodic
limit the run converges to, not the window: the speed and distance per
revolution extrapolated from the last three revolutions (:func:`limit_motion`),
the energy per metre and efficiency over the window with the energy in transit
taken off (:func:`transit_free_energy`); to :data:`LIMIT_ACCURACY`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# LIMIT_ACCURACY's, STEADY_TOL's and the exact test's old home: studies, benchmarks and tests import them from here
from .steady_test import (LIMIT_ACCURACY, STEADY_CYCLES, STEADY_TOL, Steady, find_steady,  # noqa: F401
                          remaining_drift, speed_estimate, steady_at_end, steady_index, window_uncertainty)
from .energy import ENERGY_COLUMNS as _TABLE_COLUMNS
from . import energy as _energy
from .energy import RESIDUAL_KEY, by_role, residual, terms_of

_WHOLE_TOL = 1e-9  # revolutions: see cycle_boundaries
ENERGY_COLUMNS = _TABLE_COLUMNS  # the energy terms' columns (core.energy's table)


def travel(series: dict[str, np.ndarray]) -> np.ndarray:
    """Position of the robot [m]: the mean displacement of its two modules."""
    return 0.5 * (np.asarray(series["x1"]) + np.asarray(series["x2"]))


def cycle_boundaries(t: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Times [s] at which each whole revolution ends, and the sample index just after each.

    Returns (times (k,), indices (k,)): ``times[j]`` is where the running maximum of
    phi first reaches phi[0] + 2 pi (j + 1), linearly interpolated between samples;
    ``indices[j]`` the first sample at or after it.
    """
    reach = np.maximum.accumulate(np.asarray(phi, dtype=float)) - phi[0]
    # a turn short by less than 1e-9 of a revolution is complete: a run stopped exactly on a revolution end
    # and written to CSV with 12 significant digits reads back a few 1e-12 revolutions short of it
    whole = int(math.floor(reach[-1] / (2 * math.pi) + _WHOLE_TOL))
    if whole < 1:
        return np.zeros(0), np.zeros(0, dtype=int)
    targets = 2 * math.pi * np.arange(1, whole + 1)
    idx = np.searchsorted(reach, targets - 2 * math.pi * _WHOLE_TOL * (1 + targets), side="left")
    idx = np.minimum(idx, len(t) - 1)
    times = np.empty(whole)
    for j, i in enumerate(idx):
        if i == 0 or reach[i] <= targets[j] or reach[i] == reach[i - 1]:
            times[j] = t[i]
        else:
            w = (targets[j] - reach[i - 1]) / (reach[i] - reach[i - 1])
            times[j] = t[i - 1] + w * (t[i] - t[i - 1])
    return times, idx


def _at(t: np.ndarray, values: np.ndarray, when: np.ndarray) -> np.ndarray:
    """values(t) at the times ``when`` (linear; of duplicated instants, the later sample)."""
    keep = np.concatenate([np.diff(t) > 0, [True]])
    return np.interp(when, t[keep], np.asarray(values, dtype=float)[keep])


@dataclass(frozen=True)
class Cycle:
    """One crank revolution: its times, travel, peaks and energy audit.

    ``energy``: each energy term's change over the revolution [J] under its audit key (the terms of
    :data:`.energy.ENERGY_TERMS` whose columns the run has, in the table's order), as (key, J) pairs; read it
    with :meth:`energy_j` or :attr:`audit`. The named figures below (``motor_work_j``, ...) read it too; None
    where the run has no such column.
    """

    t_start: float  # s
    t_end: float  # s
    distance_m: float  # travel of the robot (mean of the modules) over the revolution
    peak_clutch_force_n: float | None = None
    peak_rod_force_n: float | None = None
    energy: tuple[tuple[str, float], ...] = ()

    @property
    def audit(self) -> dict[str, float]:
        """{audit key: J} over the revolution, with the residual (:func:`.energy.residual`) where the run has the
        motor's, the kinetic and the friction terms."""
        out = dict(self.energy)
        if self.residual_j is not None:
            out[RESIDUAL_KEY] = self.residual_j
        return out

    def energy_j(self, key: str) -> float | None:
        """The change over the revolution [J] of the term with audit key ``key``; None where the run has none."""
        return dict(self.energy).get(key)

    motor_work_j = property(lambda self: self.energy_j("motor_work_j"))
    friction_work_j = property(lambda self: self.energy_j("friction_j"))
    kinetic_change_j = property(lambda self: self.energy_j("kinetic_j"))
    potential_change_j = property(lambda self: self.energy_j("potential_j"))
    skid_work_j = property(lambda self: self.energy_j("skid_j"))  # the grip's work against skidding wheels
    clutch_spring_change_j = property(lambda self: self.energy_j("clutch_spring_j"))  # compliant clutches only

    @property
    def clutch_energy_change_j(self) -> float | None:
        """Spring energy stored + damper work [J], compliant clutches only."""
        spring, damper = self.energy_j("clutch_spring_j"), self.energy_j("clutch_damper_j")
        return None if spring is None and damper is None else (spring or 0.0) + (damper or 0.0)

    @property
    def period_s(self) -> float:
        return self.t_end - self.t_start

    @property
    def mean_speed_m_s(self) -> float:
        return self.distance_m / self.period_s if self.period_s > 0 else 0.0

    @property
    def residual_j(self) -> float | None:
        """Input - dissipated - kinetic - stored over the revolution (:func:`.energy.residual`, every term the run
        has): the audit's error; None without the motor's, the kinetic or the friction term."""
        present = dict(self.energy)
        if any(key not in present for key in ("motor_work_j", "kinetic_j", "friction_j")):
            return None
        return float(residual(by_role({term: present[term.audit_key] for term in _energy.all_terms()
                                       if term.audit_key in present})))


def cycles(series: dict[str, np.ndarray]) -> list[Cycle]:
    """Every whole revolution of a run (see the module docstring)."""
    t, phi = np.asarray(series["t"], dtype=float), np.asarray(series["phi"], dtype=float)
    ends, idx = cycle_boundaries(t, phi)
    if ends.size == 0:
        return []
    starts = np.concatenate([[t[0]], ends[:-1]])
    first = np.concatenate([[0], idx[:-1]])
    edges = np.concatenate([[t[0]], ends])
    pos = _at(t, travel(series), edges)
    at_edges = {term: _at(t, series[term.column], edges) for term in terms_of(series)}

    def peak(columns, lo, hi):
        present = [np.abs(series[c][lo:hi + 1]) if c == "rod_force" else series[c][lo:hi + 1]
                   for c in columns if c in series]
        return float(max(p.max() for p in present)) if present and hi >= lo else None

    out = []
    for j in range(ends.size):
        energy = tuple((term.audit_key, float(values[j + 1] - values[j])) for term, values in at_edges.items())
        out.append(Cycle(float(starts[j]), float(ends[j]), float(pos[j + 1] - pos[j]),
                         peak(("lambda1", "lambda2"), first[j], idx[j]), peak(("rod_force",), first[j], idx[j]),
                         energy))
    return out


def steady_window(found: list, tol: float = STEADY_TOL, n: int = STEADY_CYCLES,
                  target: float | None = None) -> list | None:
    """The whole revolutions (of :func:`cycles`) at whose end the run first is at steady state, or None: the
    window every steady-state figure is taken over. ``target``: the statistical test's (None: the exact test
    alone, :func:`.steady_test.steady_index`'s ``n`` revolutions); see :mod:`.steady_test`."""
    found_steady = find_steady([c.mean_speed_m_s for c in found], tol, n, target, steady_at_end)
    return None if found_steady is None else found[found_steady.start:found_steady.end + 1]


def efficiency(motor_j: float, resistance_j: float, lifted_j: float = 0.0, kinetic_j: float = 0.0,
               stored_j: float = 0.0) -> float | None:
    """The share of the energy put in that goes where it is meant to, over a stretch of a run [-]; None where
    nothing was put in.

    Arguments in J over the stretch: the drive's work ``motor_j``, the work against the resistances
    ``resistance_j``, and the gains of potential (``lifted_j``), kinetic (``kinetic_j``) and clutch-spring
    (``stored_j``) energy. Useful: resistance work + potential energy gained (on a climb the lifting is the
    job, not a loss). Put in: motor work where positive (a motor driven past its no-load speed absorbs
    energy: a loss, not negative input) + any potential, kinetic or spring energy released (downhill, or a
    crank started fast and slowing down: that energy moves the robot as the motor's would). By the energy
    balance the figure is then at most 1 (to the audit's residual) in every case; kinetic or spring energy
    gained and damper work count as not useful. In a horizontal pipe at steady state: resistance work /
    motor work.
    """
    put_in = max(motor_j, 0.0) + max(-lifted_j, 0.0) + max(-kinetic_j, 0.0) + max(-stored_j, 0.0)
    return (resistance_j + max(lifted_j, 0.0)) / put_in if put_in > 0 else None


def _stretch_efficiency(series: dict[str, np.ndarray], t0: float, t1: float) -> float | None:
    """:func:`efficiency` over the times t0..t1 [s] of a run, from its cumulative energy columns (None
    without motor and friction work)."""
    if "motor_work" not in series or "friction_work" not in series:
        return None
    t = np.asarray(series["t"], dtype=float)
    gained = {c: float(np.diff(_at(t, series[c], np.array([t0, t1])))[0]) if c in series else 0.0
              for c in ("motor_work", "friction_work", "potential", "kinetic", "clutch_spring_energy")}
    return efficiency(gained["motor_work"], gained["friction_work"], gained["potential"], gained["kinetic"],
                      gained["clutch_spring_energy"])




def transit_free_energy(window: list[Cycle]) -> dict[str, float | None]:
    """Energy per metre [J/m] and efficiency [-] over revolutions ``window`` as they read in the periodic limit
    (keys ``energy_per_metre``, ``efficiency``; None without the energy columns or without travel).

    The kinetic and clutch-spring energy the revolutions gain is energy in transit, not spent (over a period
    of the limit cycle it returns to its start), so it is taken off the motor's work rather than counted as
    a loss: energy per metre = (motor work - kinetic gained - spring energy gained) / distance, efficiency =
    :func:`efficiency` of that input. While a motor still spins up, the raw motor work per metre runs about
    ten times the speed's shortfall above its limit; with the transit taken off, what is left is the
    dissipation per metre, which hardly depends on how far the speed still has to go.
    """
    out = {"energy_per_metre": None, "efficiency": None}
    if any(c.motor_work_j is None or c.kinetic_change_j is None for c in window):
        return out
    put_in = sum(c.motor_work_j - c.kinetic_change_j - (c.clutch_spring_change_j or 0.0) for c in window)
    distance = sum(c.distance_m for c in window)
    if distance > 0:
        out["energy_per_metre"] = put_in / distance
    if all(c.friction_work_j is not None for c in window):
        out["efficiency"] = efficiency(put_in, sum(c.friction_work_j for c in window),
                                       sum(c.potential_change_j or 0.0 for c in window))
    return out


def limit_motion(last: list[Cycle], tol: float = STEADY_TOL) -> tuple[float, float]:
    """The periodic limit of the mean speed [m/s] and the distance per revolution [m], from the last three
    revolutions of a run at its steady state (``last``, in order; with fewer, their mean).

    The approach to a limit cycle is geometric: each revolution's figure f_k = f_lim + c rho^k, with the
    speed's ratio rho = (u_3 - u_2) / (u_2 - u_1). So f_lim = f_3 + (f_3 - f_2) rho / (1 - rho) (Aitken's
    extrapolation), the distance with the speed's rho too (the one the steady test watches). Where
    |rho| >= 1 the revolutions show no such approach (a wobble from revolution to revolution, as MuJoCo's
    steps give): then the mean over the revolutions. The speed's correction is at most ``tol`` (the steady
    test's tolerance) of it, the distance's scaled alike: the steady test stops once the speed's extrapolated
    remaining drift is below ``tol``, or once its last change is a thousandth of that whatever its trend, and
    there a rho just below 1 (two equal wobbles) would make the factor rho / (1 - rho) unbounded.
    """
    speeds = [c.mean_speed_m_s for c in last]
    distances = [c.distance_m for c in last]
    rho = math.inf
    if len(last) == 3 and speeds[1] != speeds[0]:
        rho = (speeds[2] - speeds[1]) / (speeds[1] - speeds[0])
    if abs(rho) < 1:
        factor = rho / (1.0 - rho)
        step = abs(speeds[2] - speeds[1]) * abs(factor)
        if step > tol * abs(speeds[2]):
            factor *= tol * abs(speeds[2]) / step
        return tuple(f[2] + (f[2] - f[1]) * factor for f in (speeds, distances))
    time = sum(c.period_s for c in last)
    return sum(distances) / time, sum(distances) / len(last)


def speed_figures(series: dict[str, np.ndarray], t0: float, t1: float) -> dict:
    """The crank-speed and drive figures over the times t0..t1 [s] of a run (the steady window, or the whole
    run): ``mean_omega_rad_s`` (the crank's turn over the stretch divided by its time), ``speed_ripple``
    (the samples' peak-to-peak crank speed over that mean [-]; None unless the mean is > 0),
    ``peak_motor_torque_n_m`` (largest |motor_torque|, None without that column) and ``peak_drive_u``
    (largest |drive_u|, the servo's voltage fraction; None without it). Samples on the stretch's ends count;
    a series without ``omega`` has no ripple (None)."""
    t = np.asarray(series["t"], dtype=float)
    inside = (t >= t0) & (t <= t1)
    phi = _at(t, series["phi"], np.array([t0, t1]))
    mean = float(phi[1] - phi[0]) / (t1 - t0) if t1 > t0 else None
    omega = np.asarray(series["omega"], dtype=float)[inside] if "omega" in series else np.zeros(0)
    out = {"mean_omega_rad_s": mean,
           "speed_ripple": float(omega.max() - omega.min()) / mean if mean and mean > 0 and omega.size else None}
    for key, column in (("peak_motor_torque_n_m", "motor_torque"), ("peak_drive_u", "drive_u")):
        values = np.asarray(series[column], dtype=float)[inside] if column in series else np.zeros(0)
        out[key] = float(np.abs(values).max()) if values.size else None
    return out


def cycle_summary(series: dict[str, np.ndarray], tol: float = STEADY_TOL, n: int = STEADY_CYCLES,
                  target: float | None = None) -> dict:
    """The summary's per-revolution keys.

    ``steady`` (bool), ``t_steady_s``, ``steady_speed_m_s`` and
    ``energy_per_metre_j_m`` (None unless steady); ``distance_per_rev_m``,
    ``efficiency`` (:func:`efficiency`) and
    ``peak_clutch_force_n``: the periodic limit's (:func:`limit_motion`,
    :func:`transit_free_energy`; the peak over the steady window) when steady,
    else over the whole run (None where the run lacks the columns); ``cycles``: whole
    revolutions; ``cycle_energy_residual_j``: the largest |audit residual| of a
    revolution (None without energy columns); the crank-speed figures of :func:`speed_figures` over the
    steady window when steady, else over the whole run. ``target``: the statistical steady test's
    (:mod:`.steady_test`; None: the exact test alone). With it, where steady: ``steady_test`` ('exact' or
    'statistical'), ``steady_revolutions`` (the window's length), ``steady_speed_uncertainty_m_s`` and
    ``energy_per_metre_uncertainty_j_m`` (:func:`steady_uncertainties`); None where not steady. Where not
    steady, with a target: ``speed_estimate_m_s``, ``speed_estimate_uncertainty_m_s`` and
    ``speed_estimate_revolutions``, the last revolutions' mean speed and its U
    (:func:`.steady_test.speed_estimate`; None where no window fits, and where steady).
    """
    found = cycles(series)
    steady = find_steady([c.mean_speed_m_s for c in found], tol, n, target, steady_at_end)
    window = None if steady is None else found[steady.start:steady.end + 1]
    out = {"steady": window is not None, "t_steady_s": None, "steady_speed_m_s": None, "energy_per_metre_j_m": None,
           "cycles": len(found)}
    if target is not None:
        out.update(steady_test=None, steady_revolutions=None, steady_speed_uncertainty_m_s=None,
                   energy_per_metre_uncertainty_j_m=None, speed_estimate_m_s=None,
                   speed_estimate_uncertainty_m_s=None, speed_estimate_revolutions=None)
        estimate = None if window is not None else speed_estimate([c.mean_speed_m_s for c in found])
        if estimate is not None:
            out.update(speed_estimate_revolutions=estimate[0], speed_estimate_m_s=estimate[1],
                       speed_estimate_uncertainty_m_s=estimate[2])
    residuals = [abs(c.residual_j) for c in found if c.residual_j is not None]
    out["cycle_energy_residual_j"] = max(residuals) if residuals else None
    if window is not None:
        out["t_steady_s"] = window[-1].t_end
        out.update(window_figures(found, steady, tol))
        if target is not None:
            out.update(steady_test=steady.test, steady_revolutions=len(window),
                       **steady_uncertainties(window, steady, out["steady_speed_m_s"], out["energy_per_metre_j_m"]))
        peaks = [c.peak_clutch_force_n for c in window if c.peak_clutch_force_n is not None]
        out["peak_clutch_force_n"] = max(peaks) if peaks else None
        out.update(speed_figures(series, window[0].t_start, window[-1].t_end))
        return out
    revolutions = float((series["phi"][-1] - series["phi"][0]) / (2 * math.pi))
    moved = float(travel(series)[-1] - travel(series)[0])
    out["distance_per_rev_m"] = moved / revolutions if revolutions > 1e-9 else None
    t = np.asarray(series["t"], dtype=float)
    out["efficiency"] = _stretch_efficiency(series, float(t[0]), float(t[-1]))
    lambdas = [series[c] for c in ("lambda1", "lambda2") if c in series]
    out["peak_clutch_force_n"] = float(max(v.max() for v in lambdas)) if lambdas else None
    out.update(speed_figures(series, float(t[0]), float(t[-1])))
    return out


def window_figures(found: list[Cycle], steady: Steady, tol: float = STEADY_TOL) -> dict:
    """The steady figures of the window ``steady`` (revolutions ``steady.start`` .. ``steady.end`` of ``found``,
    :func:`cycles`' list) as :func:`cycle_summary` reports them: ``steady_speed_m_s`` [m/s] and
    ``distance_per_rev_m`` [m] (by the exact test the periodic limit from its last three revolutions,
    :func:`limit_motion`; by the statistical one the window's totals: no approach left to extrapolate),
    ``energy_per_metre_j_m`` [J/m] and ``efficiency`` [-] (:func:`transit_free_energy`). Also what reads one
    run's steady figures over another run's window (the rigid-limit extrapolation of MuJoCo's finite grip)."""
    window = found[steady.start:steady.end + 1]
    k = steady.end
    if steady.test == "exact":
        speed, distance = limit_motion(found[max(k - 2, 0):k + 1], tol)
    else:
        time = sum(c.period_s for c in window)
        distance = sum(c.distance_m for c in window) / len(window)
        speed = sum(c.distance_m for c in window) / time
    energy = transit_free_energy(window)
    return {"steady_speed_m_s": speed, "distance_per_rev_m": distance,
            "energy_per_metre_j_m": energy["energy_per_metre"], "efficiency": energy["efficiency"]}


def steady_uncertainties(window: list[Cycle], steady: Steady, speed: float, energy: float | None) -> dict:
    """``steady_speed_uncertainty_m_s`` [m/s] and ``energy_per_metre_uncertainty_j_m`` [J/m] of a steady window:
    by the exact test, the stated accuracy times each figure; by the statistical test, the speed's U
    (:mod:`.steady_test`) and the same confidence half-width plus trend reach of the revolutions' own energy
    per metre (motor work less the kinetic and spring energy gained, over the distance; None where a
    revolution has no such figure)."""
    out = {"steady_speed_uncertainty_m_s": steady.uncertainty * abs(speed), "energy_per_metre_uncertainty_j_m": None}
    if energy is None:
        return out
    if steady.test == "exact":
        out["energy_per_metre_uncertainty_j_m"] = steady.uncertainty * abs(energy)
        return out
    per_rev = [transit_free_energy([c])["energy_per_metre"] for c in window]
    if all(e is not None for e in per_rev):
        out["energy_per_metre_uncertainty_j_m"] = window_uncertainty(per_rev)
    return out
