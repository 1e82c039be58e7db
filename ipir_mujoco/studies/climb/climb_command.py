"""The climb study (``ipir-mujoco climb``): the steepest pipe a design climbs with its drive, and its speed against
the incline. Its runs: :mod:`.climbing`; its figure ``report/climb_figure.py``; its report sections
``report/riser_section.py`` and ``report/grip_section.py``."""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco import registry
from ipir_mujoco.core.limits import check_run_options
from ipir_mujoco.core.params import check_real

from ...labels import significant
from ...output import check_output_dir
from ..command import (add_model_options, add_variant_option, compile_first, model_params, study_progress,
                       write_study_files)
from ..contract import Declaration, Section

FILES = ("climb.csv", "climb.json", "climb.png")
KEYS = ("steady", "steady_speed_m_s", "mean_speed_m_s", "revolutions", "travel_m", "peak_clutch_force_n",
        "mean_clutch_force_n", "efficiency", "stalled", "stall_t_s", "stall_phi_rad", "t_end_s")
GRIP_KEYS = ("slip_m", "peak_grip_use")  # columns added with a finite grip (mu_wall)


def add_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument("--inclines", metavar="LIST|START:STOP:N", default="0:90:10",
                     help="pipe inclines above the horizontal [deg], -90..90: a comma-separated list or N evenly "
                          "spaced values from START to STOP (default 0:90:10)")
    add_variant_option(cmd, many=True, default=None,
                       help=f"comma-separated, from: {', '.join(registry.NAMES)} (default: "
                            "analytic-unilateral,mujoco-ratchet)")
    cmd.add_argument("--tolerance", type=float, default=None, metavar="DEG",
                     help="width of the bracket at which the bisection for the motor's steady-climb limit stops "
                          "(default 0.1 deg)")
    cmd.add_argument("--t-end", type=float, default=None, metavar="SECONDS",
                     help="cap of each run to steady state (motor; default 10 s), or the length of each run "
                          "(constant torque; default 1 s)")
    add_model_options(cmd)
    cmd.add_argument("--out", metavar="DIR", default="climb", help="results folder (default ./climb)")


def parse_inclines(text: str) -> tuple[float, ...]:
    """``--inclines`` as sorted distinct floats in -90..90 deg, or a one-line ParameterError."""
    from ..mechanism.clutch_study import parse_values

    values = parse_values("--inclines", text, log=False)
    for value in values:
        if not (math.isfinite(value) and -90.0 <= value <= 90.0):
            raise ParameterError(f"--inclines {text!r}: incline={value!r} deg is out of range; allowed: "
                                 "-90 <= incline <= 90 deg")
    return values


def parse_engines(text: str | None) -> tuple[str, ...]:
    """The variants (names of :mod:`ipir_mujoco.registry`) of ``--variants``, or the study's default."""
    from .climbing import CLIMB_VARIANTS

    if text is None:
        return CLIMB_VARIANTS
    names = tuple(dict.fromkeys(e.strip() for e in text.split(",") if e.strip()))
    unknown = [e for e in names if e not in registry.VARIANTS and e not in registry.ALIASES]
    if not names or unknown:
        raise ParameterError(f"--variants {text!r}: " + (f"unknown {', '.join(unknown)}" if unknown else "no variant")
                             + f"; allowed: a comma-separated list from: {', '.join(registry.NAMES)}")
    return names


def run(args: argparse.Namespace, figures) -> None:
    from . import climbing

    params = model_params(args)
    if params.incline != 0.0:
        raise ParameterError(f"incline={params.incline!r} in --set or --config: the study sets it; allowed: --inclines")
    inclines = parse_inclines(args.inclines)
    engines = parse_engines(args.variants)
    tolerance = climbing.TOLERANCE_DEG if args.tolerance is None else check_real(
        "--tolerance", args.tolerance, high=90.0, unit="deg")
    t_end = climbing.default_t_end(params) if args.t_end is None else args.t_end
    check_run_options(t_end, climbing.DT_OUT)
    check_output_dir(args.out, files=FILES)
    compile_first(engines)

    study = climbing.climb_study(params, inclines, engines, tolerance, t_end, study_progress("climb"))
    write_study_files(args.out, FILES, study, write_csv,
                      lambda path: write_figure(study, params, path, figures.climb_figure),
                      format_study(study, params), f"{len(inclines)} inclines x {len(engines)} engines")


STUDY = Declaration(
    "climb", "climbing ability: the steepest incline a design climbs, speed and clutch loads against it",
    "For the design and its drive: the steepest incline at which the drive restarts the robot from rest at every "
    "crank angle (quasi-static), for the motor the steepest it climbs to a steady state from rest (bisection on "
    "runs), the energy bound; and at each incline of --inclines each engine's steady speed (motor) or mean speed "
    "(constant torque), clutch reactions and climbing efficiency. Writes DIR/climb.csv, DIR/climb.json and the "
    "figure DIR/climb.png.",
    options=add_options, run=run, files=FILES, figures="climb_figure",
    sections=(Section("vertical_riser", "Vertical riser", "riser_section", 30),
              Section("finite_grip", "Finite grip", "grip_section", 40)))


def write_figure(study: dict, params, path: Path, climb_figure) -> None:
    """climb.png: ``climb_figure(study, params)`` (the report's, :func:`ipir_mujoco.report.climb_figure.climb_figure`)
    with the traction's own marks (:meth:`_FiniteGripOutput.draw`)."""
    fig = climb_figure(study, params)
    _traction_output(study).draw(fig)
    fig.savefig(path, dpi=110)


def write_csv(path: Path, study: dict) -> None:
    """One row per incline: the torque needed at rest, then ENGINE:KEY for each engine, then the errors."""
    keys = KEYS + _traction_output(study).keys
    columns = ["incline_deg", "torque_needed_n_m"] + [f"{e}:{k}" for e in study["engines"] for k in keys] + ["error"]
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for row in study["rows"]:
            cells = {"incline_deg": row["incline_deg"], "torque_needed_n_m": row["torque_needed_n_m"],
                     "error": "; ".join(f"{e}: {m['error']}" for e, m in row["engines"].items() if "error" in m)}
            for engine, metrics in row["engines"].items():
                cells.update({f"{engine}:{k}": metrics.get(k) for k in keys})
            writer.writerow(["" if cells.get(c) is None else _cell(cells[c]) for c in columns])


def _cell(value) -> str:
    if isinstance(value, bool):
        return str(int(value))
    return repr(value) if isinstance(value, float) else str(value)


def _limit(record: dict) -> str:
    if record["incline_deg"] is None:
        return "none: the drive cannot restart it even in a vertical drop"
    if record["any_incline"]:
        return "any incline (90 deg)"
    text = f"up to {record['incline_deg']:.2f} deg (hardest crank angle {math.degrees(record['phi_rad']):.1f} deg, " \
           f"{record['stroke']})"
    return text + (" (it needs a downhill slope)" if record["incline_deg"] < 0 else "")


# what the MuJoCo columns are, measured at the default motor (mjcf/README.md, "Reactions and held modules")
MUJOCO_NOTE = ("MuJoCo's rigid clutch: no peak (its soft engagement overshoots by an amount the timestep sets: "
               "16.3 N at every 0.1 ms step against the equations' 12.1 N at cruise); its mean, read at every step, "
               "is within 0.05 % of the equations' with one-way clutches, 0.35 % under the paper's rule (default "
               "motor, 0-70 deg)")


def format_study(study: dict, params) -> str:
    """The study as text: the limits, then one line per incline with each engine's figures."""
    motor = study["drive"] == "motor"
    drive = (f"motor, M_stall {params.M_stall:g} N m, omega_noload {params.omega_noload:g} rad/s" if motor
             else f"constant torque M = {params.M:g} N m")
    bound, traction = study["energy_bound"], _traction_output(study)
    lines = [f"climbing ability ({drive}; torque at rest {study['torque_at_rest_n_m']:g} N m)",
             f"  restarts from rest at every crank angle (quasi-static): {_limit(study['restart'])}",
             f"    the paper's model (first order, massless rod):         {_limit(study['restart_paper_model'])}",
             "  energy bound (a steady climb, 2 pi M0 per revolution):   "
             + ("any incline" if bound["sin"] >= 1 else "none" if bound["incline_deg"] is None
                else f"up to {bound['incline_deg']:.2f} deg"),
             f"  a vertical riser needs a torque at rest of {study['vertical']['torque_n_m']:.4g} N m (hardest crank "
             f"angle {math.degrees(study['vertical']['phi_rad']):.1f} deg)"]
    for engine, limit in study["steady_climb"].items():
        low, high = limit["bracket"]
        lines.append(f"  steady climb from rest at phi0, {engine}: " + (
            traction.not_even(limit)
            if limit["incline_deg"] is None else
            f"up to {high:.2f} deg (climbs at all inclines tried)" if low == high else
            f"up to {low:.2f} deg (stalls at {high:.2f} deg)"))
    lines.extend(traction.lines())
    speed = "steady speed" if motor else f"mean speed over the last 3 revolutions of {study['t_end_s']:g} s"
    lines.append(f"\nincline [deg], torque needed at rest [N m]; per engine: {speed} [m/s], peak / mean clutch "
                 "reaction [N], climbing efficiency [-]")
    for row in study["rows"]:
        cells = [f"{row['incline_deg']:7.2f}", f"{row['torque_needed_n_m']:.4f}"]
        for engine, m in row["engines"].items():
            if "error" in m:
                cells.append(f"{engine}: failed ({m['error']})")
            elif m["stalled"]:
                cells.append(f"{engine}: stalled at {math.degrees(m['stall_phi_rad']) % 360:.1f} deg in the turn, "
                             f"at rest from t={m['stall_t_s']:.4g} s")
            else:
                v = m["steady_speed_m_s"] if motor else m["mean_speed_m_s"]
                cells.append(f"{engine}: " + ("no steady state" if v is None else significant(v, 4)) + " m/s, "
                             + " / ".join("n/a" if m[k] is None else significant(m[k], 4)
                                          for k in ("peak_clutch_force_n", "mean_clutch_force_n"))
                             + " N, " + ("n/a" if m["efficiency"] is None else f"{m['efficiency']:.4f}"))
        lines.append("  " + "  |  ".join(cells))
    if any(engine.startswith("mujoco") for row in study["rows"] for engine in row["engines"]):
        lines.append(MUJOCO_NOTE)
    return "\n".join(lines)


class _UnlimitedGripOutput:
    """What the climb study's text, CSV and figure show of its traction (:mod:`ipir_mujoco.studies.traction`)
    with unlimited grip: one note; :class:`_FiniteGripOutput` with a finite grip. Chosen once per study
    (:func:`_traction_output`)."""

    keys: tuple[str, ...] = ()  # the CSV's columns added per engine

    def __init__(self, traction: dict | None):
        self.traction = traction

    def lines(self) -> list[str]:
        """The traction figures as lines of the text."""
        return [] if self.traction is None else [f"  traction: {self.traction['note']}"]

    def not_even(self, limit: dict) -> str:
        """The steady-climb line of an engine that climbs at no incline tried (``limit``: its bisection)."""
        return "not even at the restart limit"

    def draw(self, fig) -> None:
        """Add the traction's marks to climb.png's figure: none."""


class _FiniteGripOutput(_UnlimitedGripOutput):
    """The traction figures with a finite grip: the limits at rest and on the riser, the steady climb with no
    skid, the skid columns, and the figure's marks."""

    keys = GRIP_KEYS

    def not_even(self, limit):
        high, note = limit["bracket"][1], limit["runs"][0]["note"]
        return f"not even at {high:.2f} deg" + (f" ({note})" if note else "")

    def draw(self, fig):
        """The rest traction limit that binds (dash-dot, speed panel) and each module's grip G_i (dotted, force
        panel)."""
        from matplotlib.lines import Line2D

        traction = self.traction
        speed_ax, force_ax = fig.axes[:2]
        rest = traction["rest"][traction["rest"]["binds"]]
        added = {speed_ax: [], force_ax: []}
        if rest["sin"] > -1.0:
            speed_ax.axvline(rest["incline_deg"], color="darkred", ls="-.", lw=1.2, gid="traction-rest")
            added[speed_ax].append(Line2D([], [], color="darkred", ls="-.", label=(
                f"traction limit at rest ({traction['rest']['binds'].replace('_', ' ')}): "
                f"{rest['incline_deg']:.1f} deg")))
        for i, G in enumerate(traction["grip"]):
            force_ax.axhline(G, color="darkred", ls=":" if i else (0, (1, 3)), lw=1.2, gid=f"grip{i + 1}")
        added[force_ax].append(Line2D([], [], color="darkred", ls=":", label="grip G_i = mu_wall F_ni: " + " / ".join(
            f"{G:.3g}" for G in traction["grip"]) + " N"))
        for ax, extra in added.items():
            legend = ax.get_legend()
            ax.legend(handles=(list(legend.legend_handles) if legend else []) + extra, fontsize="x-small", loc="best")

    def lines(self):
        traction = self.traction
        G1, G2 = traction["grip"]
        rest, riser = traction["rest"], traction["riser"]
        names = {"drive_off": "drive off", "drive_at_rest": "drive's torque at rest"}

        def at_rest(key: str) -> str:
            r = rest[key]
            where = f"module {r['module']} skids first" + (
                f", at crank angle {math.degrees(r['phi_rad']) % 360:.1f} deg" if key == "drive_off" else
                " wherever the drive moves the other module (it then holds m g sin + F_r)")
            return "any incline (90 deg)" if r["any_incline"] else (
                f"up to {r['incline_deg']:.2f} deg ({where})" if r["sin"] > -1 else f"none ({where})")

        lines = [f"  traction (mu_wall {traction['mu_wall']:g}, F_n {traction['F_n'][0]:g} / {traction['F_n'][1]:g} N: "
                 f"grip G {G1:.4g} / {G2:.4g} N)",
                 f"    standing at any crank angle, no skid, {names['drive_off']}: {at_rest('drive_off')}",
                 f"    standing at any crank angle, no skid, {names['drive_at_rest']} "
                 f"({rest['torque_at_rest_n_m']:g} N m): {at_rest('drive_at_rest')}",
                 f"    binds: {names[rest['binds']]}",
                 "    a vertical riser needs a press per module of "
                 + " / ".join(_press(f) for f in riser["needed_n"]) + " N at this mu_wall ("
                 + "; ".join(f"{names[k]}: " + " / ".join(_press(f) for f in riser["press_n"][k]) + " N"
                             for k in ("drive_off", "drive_at_rest")) + f"; {names[riser['binds']]} binds)"]
        for engine, limit in traction["steady"].items():
            if "error" in limit:
                text = f"refused ({limit['error']})"
            elif limit["incline_deg"] is None:
                text = "skids (or stalls) even on the level"
            else:
                low, high = limit["bracket"]
                text = (f"up to {high:.2f} deg (no skid at the steady-climb limit)" if low == high
                        else f"up to {low:.2f} deg (skids or stalls at {high:.2f} deg)")
            lines.append(f"    steady climb with no skid in the steady window, {engine}: {text}")
        return lines


def _traction_output(study: dict) -> _UnlimitedGripOutput:
    """The output of ``study``'s traction figures, by its grip (the one place the climb command asks)."""
    traction = study.get("traction")
    return (_UnlimitedGripOutput if traction is None or traction["grip"] is None else _FiniteGripOutput)(traction)


def format_traction(traction: dict | None) -> list[str]:
    """The traction figures (:mod:`ipir_mujoco.studies.traction`) as lines; one line with unlimited grip."""
    return _traction_output({"traction": traction}).lines()


def _press(force) -> str:
    """A riser's press [N] as the table shows it; None: no press holds (mu_wall = 0)."""
    return "none holds" if force is None else f"{force:.4g}"
