"""The bend study (``ipir-mujoco bend-study``): time and energy for the wheeled robot to pass a 90-degree bend,
against R/D. Its runs: :mod:`.bend_study`; its figure: ``report/bend_figure.py``."""

from __future__ import annotations

import argparse
import csv
import os
from pathlib import Path

from ipir_mujoco.core.params import check_whole

from ...output import check_output_dir
from ..command import add_study_options, model_params, study_progress, write_study_files
from ..contract import Declaration

FILES = ("bend_study.csv", "bend_study.json", "bend_study.png")


def add_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument("--ratios", metavar="LIST", default=None,
                     help="bend radius over pipe diameter, R/D: a comma-separated list (default 0.6,1,1.5,2,3,5,7.5,10)")
    cmd.add_argument("--quick", action="store_true", help="R/D 2 and 5 only, for a first look")
    cmd.add_argument("--planes", metavar="LIST", default=None,
                     help="the bends' planes [deg], turned about the pipe's axis: a comma-separated list (default 0: "
                          "horizontal, across gravity; 90: turning up, in the plane of gravity; needs a model that "
                          "bends out of the mechanism's plane)")
    add_study_options(cmd, "bend-study", "e.g. pipe_diameter=0.2; "
                                       "the study runs the default motor and, unless given, mu_wall 0.8")


def run(args: argparse.Namespace, figures) -> None:
    from . import bend_study as bs
    from .clutch_study import parse_values

    params = bs.study_params(model_params(args))
    ratios = parse_values("--ratios", args.ratios, log=False) if args.ratios is not None else \
        (bs.RATIOS_QUICK if args.quick else bs.RATIOS)
    bs.check_ratios(ratios, params)
    planes = parse_values("--planes", args.planes, log=False) if args.planes is not None else bs.PLANES
    bs.check_planes(planes, params, min(ratios))
    workers = (os.cpu_count() or 1) if args.workers is None else check_whole("workers", args.workers, low=1, high=1024)
    check_output_dir(args.out, files=FILES)

    progress = study_progress("bend-study")
    progress(f"{len(ratios) * len(planes)} bends and {len(ratios)} straight twins on {workers} processes (a line "
             "per finished run, and every 5 s of a running one)")
    study = bs.run_study(params, ratios, workers=workers, progress=progress, planes=planes)
    write_study_files(args.out, FILES, study, write_csv, lambda path: figures.write_bend_figure(study, path),
                      format_table(study), f"{len(study['rows'])} bends")


STUDY = Declaration(
    "bend-study", "the wheeled MuJoCo robot through a 90-degree bend: time and energy against R/D",
    "Run the wheeled MuJoCo model (--mujoco-model wheels) along a route with a 90-degree bend for each R/D, and the "
    "same length of straight pipe; time and motor work from the front module entering the bend to the rear module "
    "leaving it, beside the analytic finite-grip model's straight-pipe prediction over that length and the "
    "equations along the same route (the bend and its straight twin) with MuJoCo's difference from them. Writes "
    "DIR/bend_study.csv, DIR/bend_study.json and the figure DIR/bend_study.png; prints the table.",
    options=add_options, run=run, files=FILES, figures="bend_figure")


COLUMNS = ("plane_deg", "R_over_D", "radius_m", "window_m", "analytic_time_s", "analytic_energy_j", "straight_time_s",
           "straight_energy_j", "bend_time_s", "bend_energy_j", "bend_passed", "bend_route_stop",
           "bend_wheel_off_s", "bend_module_off_s", "bend_arm_reach", "bend_residual_ratio", "bend_skid_j",
           "predicted", "bend_potential_j", "note", "equations_time_s", "equations_energy_j", "equations_scrub_j",
           "equations_route_stop", "equations_straight_time_s", "equations_straight_energy_j",
           "mujoco_vs_equations_time", "mujoco_vs_equations_energy", "mujoco_vs_equations")


def _flat(row: dict) -> dict:
    b, s, a = row["bend"], row["straight"], row["analytic"]
    e, es, versus = row.get("equations") or {}, row.get("equations_straight") or {}, row.get("mujoco_vs_equations") or {}
    return {"equations_time_s": e.get("time_s"), "equations_energy_j": e.get("energy_j"),
            "equations_scrub_j": e.get("scrub_j"), "equations_route_stop": e.get("error", e.get("route_stop")),
            "equations_straight_time_s": es.get("time_s"), "equations_straight_energy_j": es.get("energy_j"),
            "mujoco_vs_equations_time": versus.get("time_s"), "mujoco_vs_equations_energy": versus.get("energy_j"),
            "mujoco_vs_equations": versus.get("outcome"),
            "plane_deg": row.get("plane_deg", 0.0), "note": row.get("note"), "bend_potential_j": b.get("potential_j"),
            "R_over_D": row["R_over_D"], "radius_m": row["radius_m"], "window_m": row["window_m"],
            "analytic_time_s": a["time_s"], "analytic_energy_j": a["energy_j"], "straight_time_s": s.get("time_s"),
            "straight_energy_j": s.get("energy_j"), "bend_time_s": b.get("time_s"), "bend_energy_j": b.get("energy_j"),
            "bend_passed": b.get("passed"), "bend_route_stop": b.get("error", b.get("route_stop")),
            "bend_wheel_off_s": b.get("route_wheel_off_s"), "bend_module_off_s": b.get("route_module_off_s"),
            "bend_arm_reach": b.get("route_arm_reach"), "bend_residual_ratio": b.get("residual_ratio"),
            "bend_skid_j": b.get("skid_j"), "predicted": b.get("predicted")}


def write_csv(path: Path, study: dict) -> None:
    """One row per R/D, the columns of COLUMNS (units in their names)."""
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        for row in study["rows"]:
            flat = _flat(row)
            writer.writerow(["" if flat[c] is None else repr(flat[c]) if isinstance(flat[c], float) else flat[c]
                             for c in COLUMNS])


def _short(predicted: str) -> str:
    """The closed-form fit's line in a word or two."""
    for start, word in (("passes", "passes"), ("jams", "housing jams"), ("the linkage", "rod binds"),
                        ("a wheel", "wall lost")):
        if predicted.startswith(start):
            return word
    return predicted


def format_table(study: dict) -> str:
    """The study as text: per R/D the passage's time and energy, MuJoCo in the bend / in a straight / the analytic
    model's straight prediction, the equations along the same route (the bend / its straight twin) and MuJoCo's
    difference from them in the bend, and how the run ended."""
    def num(v, digits=4):
        return "n/a" if v is None else f"{v:.{digits}g}"

    def pct(v):
        return "n/a" if v is None else f"{100 * v:+.2f} %"

    header = ["plane [deg]", "R/D", "window [m]", "time [s] bend / straight / analytic",
              "energy [J] bend / straight / analytic", "equations: time [s], energy [J] bend / straight",
              "MuJoCo - equations: time, energy: class", "wheels off [s]", "closed form", "outcome"]
    rows = []
    for row in study["rows"]:
        f = _flat(row)
        rows.append([f"{f['plane_deg']:g}", f"{f['R_over_D']:g}", f"{f['window_m']:.3f}",
                     f"{num(f['bend_time_s'])} / {num(f['straight_time_s'])} / {num(f['analytic_time_s'])}",
                     f"{num(f['bend_energy_j'])} / {num(f['straight_energy_j'])} / {num(f['analytic_energy_j'])}",
                     f"{num(f['equations_time_s'])} / {num(f['equations_straight_time_s'])}, "
                     f"{num(f['equations_energy_j'])} / {num(f['equations_straight_energy_j'])}",
                     f"{pct(f['mujoco_vs_equations_time'])}, {pct(f['mujoco_vs_equations_energy'])}: "
                     f"{f['mujoco_vs_equations'] or 'n/a'}",
                     num(f["bend_wheel_off_s"], 3),
                     _short(f["predicted"] or ""),
                     "passed" if f["bend_passed"] else f"stopped: {f['bend_route_stop']}"])
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
    lines = ["  ".join(str(x).ljust(w) for x, w in zip(r, widths)) for r in [header] + rows]
    for row in study["rows"]:
        f = _flat(row)
        where = f"plane {f['plane_deg']:g} deg, R/D {f['R_over_D']:g}"
        if abs(f["bend_potential_j"] or 0.0) > 1e-3:  # J: MuJoCo's potential energy, height and springs
            lines.append(f"{where}: the robot's potential energy (its height, its legs' springs) changed by "
                         f"{f['bend_potential_j']:.3g} J over the window, taken out of the bend's energy")
        if f["note"]:
            lines.append(f"{where}: the bend passed {f['note']}")
        if f["equations_time_s"] is None:
            lines.append(f"{where}: the equations did not pass: {f['equations_route_stop']}")
    ref = study["reference"]
    lines.append(f"analytic straight pipe: {ref['steady_speed_m_s']:.5g} m/s, {ref['energy_per_metre_j_m']:.5g} J/m")
    return "\n".join(lines)
