"""The clutch study (``ipir-mujoco clutch-study``): engagement loads of real (compliant, backlashed) one-way
clutches. Its runs: :mod:`.clutch_study`; its figure and report section: ``report/clutch_section.py``."""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import check_whole

from ...labels import significant
from ...output import check_output_dir
from ..command import add_study_options, compile_first, model_params, study_progress, write_study_files
from ..contract import Declaration, Section

FILES = ("clutch_study.csv", "clutch_study.json", "clutch_study.png")


def add_options(cmd: argparse.ArgumentParser) -> None:
    cmd.add_argument("--stiffness", metavar="LIST|START:STOP:N", default=None,
                     help="clutch stiffness seen at the module [N/m]: a comma-separated list, or N log-spaced values "
                          "from START to STOP (default 1e3:1e7:9)")
    cmd.add_argument("--backlash", metavar="LIST|START:STOP:N", default=None,
                     help="clutch backlash [m]: a comma-separated list, or N values from START to STOP "
                          "(default 0,5e-4,1e-3,2e-3)")
    cmd.add_argument("--points", metavar="LIST", default="cruise,startup",
                     help="operating points, from: cruise (the default motor, to its periodic steady state), "
                          "startup (the paper's constant torque, 1 s from rest); default both")
    add_study_options(cmd, "clutch-study", "e.g. clutch_damping=50; "
                                       "the study sets drive, clutch_stiffness and clutch_backlash itself")
    cmd.add_argument("--quick", action="store_true",
                     help="a small grid (1e4,1e5,1e6 N/m x 0,1e-3 m) for a first look; --stiffness/--backlash win")


def run(args: argparse.Namespace, figures) -> None:
    from . import clutch_study as cs

    base = model_params(args)
    defaults = type(base)()
    for name, instead in (("drive", "--points"), ("clutch_stiffness", "--stiffness"), ("clutch_backlash", "--backlash")):
        if getattr(base, name) != getattr(defaults, name):
            raise ParameterError(f"{name}={getattr(base, name)!r} in --set or --config: the study sets it; "
                                 f"allowed: {instead}")
    stiffness = cs.parse_values("--stiffness", args.stiffness, log=True) if args.stiffness is not None else \
        (cs.STIFFNESS_QUICK if args.quick else cs.STIFFNESS)
    backlash = cs.parse_values("--backlash", args.backlash, log=False) if args.backlash is not None else \
        (cs.BACKLASH_QUICK if args.quick else cs.BACKLASH)
    points = cs.parse_points(args.points)
    if args.workers is not None:
        check_whole("workers", args.workers, low=1, high=1024)
    designs = [(k, b) for k in stiffness for b in backlash]
    cs.plan(base, designs, points)  # every value checked before anything is written or run
    check_output_dir(args.out, files=FILES)
    compile_first()  # before the pool: compiled once, said at once

    study = cs.run_study(base, designs=designs, points=points, workers=args.workers,
                         progress=study_progress("clutch-study"))
    write_study_files(args.out, FILES, study, write_csv, lambda path: figures.write_study_figure(study, path),
                      format_table(study), f"{len(study['rows'])} designs x 2 engines")


STUDY = Declaration(
    "clutch-study", "engagement loads of real one-way clutches: stiffness and backlash, both engines",
    "Run the analytic compliant clutch and MuJoCo's compliant ratchet over clutch stiffness and backlash at the "
    "default motor's cruise and at the paper's start-up; write DIR/clutch_study.csv, DIR/clutch_study.json and the "
    "figure DIR/clutch_study.png; print the table.",
    options=add_options, run=run, files=FILES, figures="clutch_section",
    sections=(Section("clutch_engagement", "Real clutches: engagement loads", "clutch_section", 10),))


def _columns() -> list[str]:
    from .clutch_study import METRICS

    extra = ["t_steady_s", "timestep_s", "peak_sampling_bound", "wall_s"]
    return (["point", "clutch", "clutch_stiffness_n_m", "clutch_backlash_m"]
            + [f"{e}:{m}" for m, _, _ in METRICS for e in ("analytic", "mujoco")]
            + [f"divergence:{m}" for m, _, _ in METRICS]
            + [f"{e}:{m}" for m in extra for e in ("analytic", "mujoco")] + ["error"])


def write_csv(path: Path, study: dict) -> None:
    """One row per operating point and clutch (compliant designs, then the rigid limit, stiffness 'inf')."""
    columns = _columns()
    records = [(r["point"], "compliant", r["clutch_stiffness_n_m"], r["clutch_backlash_m"], r["analytic"],
                r["mujoco"], r["divergence"]) for r in study["rows"]]
    records += [(key, "rigid", math.inf, 0.0, ref["analytic"], ref["mujoco"], {})
                for key, ref in study["rigid"].items()]
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for point, clutch, k, b, an, mj, div in records:
            row = {"point": point, "clutch": clutch, "clutch_stiffness_n_m": k, "clutch_backlash_m": b,
                   "error": "; ".join(f"{e}: {m['error']}" for e, m in (("analytic", an), ("mujoco", mj))
                                      if "error" in m)}
            for engine, metrics in (("analytic", an), ("mujoco", mj)):
                row.update({f"{engine}:{key}": value for key, value in metrics.items()})
            row.update({f"divergence:{key}": value for key, value in div.items()})
            writer.writerow(["" if row.get(c) is None else _cell(row.get(c)) for c in columns])


def _cell(value) -> str:
    return repr(value) if isinstance(value, float) else str(value)


def _pair(an: dict, mj: dict, key: str, scale: float = 1.0, digits: int = 4) -> str:
    def one(m):
        value = None if "error" in m else m.get(key)
        return "n/a" if value is None else significant(value * scale, digits)
    return f"{one(an)} / {one(mj)}"


def format_table(study: dict) -> str:
    """The study as text: per operating point, both engines side by side, units in the header."""
    shown = [("peak_clutch_force_n", "peak force [N]", 1.0), ("peak_acceleration_m_s2", "peak accel [m/s^2]", 1.0), ("lost_per_stroke_m", "lost/stroke [mm]", 1e3),
             ("steady_speed_m_s", "speed [m/s]", 1.0), ("energy_per_metre_j_m", "energy [J/m]", 1.0)]
    lines = []
    for key, point in study["points"].items():
        columns = [c for c in shown if point["until_steady"] or c[0] not in ("steady_speed_m_s", "energy_per_metre_j_m")]
        lines.append(f"\n{point['label']} (each cell: analytic / MuJoCo; lost/stroke against the same engine's "
                     "rigid clutch, < 0: gained; last column: MuJoCo's relative divergence of the peak force)")
        header = ["k [N/m]", "backlash [mm]"] + [c[1] for c in columns] + ["force divergence"]
        rows = []
        for r in (r for r in study["rows"] if r["point"] == key):
            div = r["divergence"]["peak_clutch_force_n"]
            rows.append([f"{r['clutch_stiffness_n_m']:.3g}", f"{1e3 * r['clutch_backlash_m']:g}"]
                        + [_pair(r["analytic"], r["mujoco"], c[0], c[2]) for c in columns]
                        + ["n/a" if div is None else f"{div:+.1e}"])
        ref = study["rigid"][key]
        rows.append(["rigid", "0"] + [_pair(ref["analytic"], ref["mujoco"], c[0], c[2]) for c in columns] + [""])
        widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
        for row in [header] + rows:
            lines.append("  ".join(str(x).rjust(w) for x, w in zip(row, widths)))
        failed = [(f"k={r['clutch_stiffness_n_m']:.3g} N/m, backlash {1e3 * r['clutch_backlash_m']:g} mm", r)
                  for r in study["rows"] if r["point"] == key] + [("rigid", ref)]
        for what, record in failed:
            for engine in ("analytic", "mujoco"):
                if "error" in record[engine]:
                    lines.append(f"  {what}, {engine}: n/a ({record[engine]['error']})")
    slopes = [s for s in study["scaling"] if s["slope_stiff"] is not None]
    lines.append("\nlog-log slope of the peak force against k over the stiffest decade (1/2: an impact; -> 0: a "
                 "finite limit):" + ("" if slopes else " none (a backlash needs two stiffnesses or more)"))
    for s in slopes:
        lines.append(f"  {s['point']:8s} backlash {1e3 * s['clutch_backlash_m']:g} mm, {s['engine']:8s}: "
                     f"{s['slope_stiff']:+.3f} ({s['stiff_range_n_m'][0]:.3g}..{s['stiff_range_n_m'][1]:.3g} N/m)")
    return "\n".join(lines)
