"""The control study (``ipir-mujoco control-study``): speed control of the crank, open loop against PI with and
without feedforward, and a crank-speed profile that slows through the dead centres, in both engines. Its runs:
:mod:`.control_study`; its figure ``report/control_figure.py``, its report section ``report/control_section.py``."""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import check_real, check_whole

from ...labels import significant
from ...output import check_output_dir
from ..command import add_study_options, compile_first, model_params, study_progress, write_study_files
from ..contract import Declaration, Section

FILES = ("control_study.csv", "control_study.json", "control_study.png")
METRICS = ("mean_omega_rad_s", "speed_ripple", "peak_clutch_force_n", "peak_module_accel_m_s2",
           "energy_per_metre_j_m", "electrical_energy_per_metre_j_m", "steady_speed_m_s", "peak_drive_u",
           "peak_motor_torque_n_m", "steady", "t_steady_s", "wall_s")


def add_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument("--speeds", metavar="LIST", default=None,
                     help="mean crank speeds [rad/s] of the controller comparison, comma-separated (default 5,10; "
                          "each below omega_noload)")
    cmd.add_argument("--dips", metavar="LIST", default=None,
                     help="the profile's speed_dip values, 0 <= dip <= 0.9, comma-separated (default 0,0.1,0.2,0.3)")
    cmd.add_argument("--profile-speed", type=float, default=None, metavar="RAD_S",
                     help="the profile comparison's mean crank speed [rad/s] (default 8)")
    cmd.add_argument("--quick", action="store_true", help="10 rad/s and dips 0, 0.2 only; --speeds/--dips win")
    add_study_options(cmd, "control-study", "e.g. control_rate=500; "
                                       "the study sets drive, omega_target, speed_dip and feedforward itself")


def parse_list(option: str, text: str, low: float, high: float, low_open: bool, unit: str = "") -> tuple[float, ...]:
    """A comma-separated list of numbers, each checked (one line naming the option and the value)."""
    items = [t.strip() for t in text.split(",") if t.strip()]
    if not items:
        raise ParameterError(f"{option} {text!r} is empty; allowed: comma-separated numbers")
    values = []
    for item in items:
        try:
            value = float(item)
        except ValueError:
            raise ParameterError(f"{option} {item!r} is not a number; allowed: comma-separated numbers") from None
        values.append(check_real(option, value, low=low, high=high, low_open=low_open, unit=unit))
    return tuple(sorted(set(values)))


def run(args: argparse.Namespace, figures) -> None:
    from . import control_study as cs

    base = model_params(args)
    cs.check_base(base)
    speeds = parse_list("--speeds", args.speeds, 0.0, 1e5, True, "rad/s") if args.speeds is not None else \
        (cs.QUICK_SPEEDS if args.quick else cs.SPEEDS)
    dips = parse_list("--dips", args.dips, 0.0, 0.9, False) if args.dips is not None else \
        (cs.QUICK_DIPS if args.quick else cs.DIPS)
    profile_speed = cs.PROFILE_SPEED if args.profile_speed is None else \
        check_real("--profile-speed", args.profile_speed, high=1e5, unit="rad/s")
    if args.workers is not None:
        check_whole("workers", args.workers, low=1, high=1024)
    cs.check_speeds(base, speeds, dips, profile_speed)  # every value checked before anything is written or run
    check_output_dir(args.out, files=FILES)
    compile_first()  # before the pool: compiled once, said at once

    study = cs.run_study(base, speeds, dips, profile_speed, workers=args.workers,
                         progress=study_progress("control-study"))
    write_study_files(args.out, FILES, study, write_csv, lambda path: figures.write_study_figure(study, path),
                      format_table(study), f"{len(study['rows']) + len(study['profile']['rows'])} runs")


STUDY = Declaration(
    "control-study", "speed control of the crank: open loop, PI, PI + feedforward, a dead-centre profile",
    "At matching mean crank speeds, run the open-loop motor (a constant voltage that cruises at the speed), the PI "
    "speed controller, and PI with the paper's and the exact feedforward, each to its steady state in the paper's "
    "geometry, the exact equations and MuJoCo; and a speed target that dips through the dead centres against "
    "constant speed at the same mean. Writes DIR/control_study.csv, DIR/control_study.json and the figure "
    "DIR/control_study.png; prints the table (docs/control.md).",
    options=add_options, run=run, files=FILES, figures="control_figure",
    sections=(Section("speed_control", "Speed control", "control_section", 50),))


def write_csv(path: Path, study: dict) -> None:
    """One row per run: the part (controllers | profile), variant, controller, speed, dip, u0, the metrics."""
    columns = ["part", "variant", "controller", "speed_rad_s", "speed_dip", "open_loop_u0"] + list(METRICS) + ["error"]
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for part, rows in (("controllers", study["rows"]), ("profile", study["profile"]["rows"])):
            for r in rows:
                cells = {"part": part, **r}
                writer.writerow(["" if cells.get(c) is None else _cell(cells[c]) for c in columns])


def _cell(value) -> str:
    if isinstance(value, bool):
        return str(int(value))
    return repr(value) if isinstance(value, float) else str(value)


def _show(row: dict, key: str, digits: int = 4) -> str:
    if "error" in row:
        return "n/a"
    value = row.get(key)
    return "n/a" if value is None or (isinstance(value, float) and not math.isfinite(value)) else significant(value,
                                                                                                              digits)


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
    return ["  ".join(str(x).rjust(w) for x, w in zip(row, widths)) for row in [header] + rows]


SHOWN = (("mean_omega_rad_s", "omega [rad/s]"), ("speed_ripple", "ripple [-]"),
         ("peak_clutch_force_n", "clutch [N]"), ("peak_module_accel_m_s2", "accel [m/s^2]"),
         ("energy_per_metre_j_m", "crank [J/m]"), ("electrical_energy_per_metre_j_m", "drawn [J/m]"),
         ("peak_drive_u", "peak |u|"))


def format_table(study: dict) -> str:
    """The study as text: the controllers by speed and variant, then the profile; units in the headers."""
    lines = ["controllers at matching mean crank speeds (steady window; open loop: the constant voltage u0 that "
             "cruises at the speed; crank: the motor's work per metre, drawn: u tau omega_noload per metre)"]
    header = ["speed", "controller", "variant"] + [h for _, h in SHOWN]
    rows = [[f"{r['speed_rad_s']:g}", r["controller"] + (f" (u0 {r['open_loop_u0']:.4f})" if r["open_loop_u0"] else ""),
             r["variant"]] + [_show(r, k) for k, _ in SHOWN] for r in study["rows"]]
    lines += _table(header, rows)
    profile = study["profile"]
    if profile["rows"]:
        lines.append(f"\ndead-centre profile at {profile['speed_rad_s']:g} rad/s mean (PI + exact feedforward; "
                     "speed_dip 0: constant speed)")
        header = ["speed_dip", "variant"] + [h for _, h in SHOWN] + ["robot [m/s]"]
        rows = [[f"{r['speed_dip']:g}", r["variant"]] + [_show(r, k) for k, _ in SHOWN] + [_show(r, "steady_speed_m_s")]
                for r in profile["rows"]]
        lines += _table(header, rows)
    for r in study["rows"] + profile["rows"]:
        if "error" in r:
            lines.append(f"  {r['variant']} {r['controller']} {r['speed_rad_s']:g} rad/s: n/a ({r['error']})")
        elif not r["steady"]:
            lines.append(f"  {r['variant']} {r['controller']} {r['speed_rad_s']:g} rad/s dip {r['speed_dip']:g}: "
                         "did not settle to the steady-state test within the cap; read over its last revolutions")
    return "\n".join(lines)
