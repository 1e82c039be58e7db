"""The validation report's section "Where the paper's model holds": the idealization atlas around the design.

The atlas (:mod:`ipir_mujoco.studies.atlas`) on the equations only (no MuJoCo budget: the report stays quick)
over the design's neighbourhood: L, m1, m2, J_A and the drive's strength (M under constant torque, M_stall
under the motor or the servo) each from half to one and a half times the design's (L at least 1.05 r), under
the design's drive, for every idealization the equations measure at this design (unlimited grip only where
``mu_wall`` is finite; the rod only where it has mass), on the drive's default metrics at a 1 % and a 5 %
threshold. ``quick``: SAMPLES[True] Saltelli base samples, else SAMPLES[False].
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from ipir_mujoco.core.params import RobotParams

from ..studies.atlas import Atlas, run_atlas, top_drivers
from ..studies.sweep_space import Axis
from .atlas_plots import idealization_words, metric_words, plot_safe
from .document import Heading, Image, Paragraph, Table

SPAN = 0.5  # each parameter from (1 - SPAN) to (1 + SPAN) times the design's
SAMPLES = {True: 4, False: 16}  # Saltelli base samples: N (d + 2) designs, d = 5
THRESHOLDS = (0.01, 0.05)


def neighbourhood(params: RobotParams) -> tuple[Axis, ...]:
    strength = "M" if params.drive == "torque" else "M_stall"
    axes = []
    for name in ("L", "m1", "m2", "J_A", strength):
        value = getattr(params, name)
        low = max((1 - SPAN) * value, 1.05 * params.r) if name == "L" else (1 - SPAN) * value
        axes.append(Axis(name, (), low, (1 + SPAN) * value))
    return tuple(a for a in axes if a.high > a.low)


def compute(params: RobotParams, quick: bool, progress) -> dict:
    params = params.replace(drive=params.drive)  # without another drive's parameters (the sections' motor's)
    axes = neighbourhood(params)
    atlas = Atlas(axes, params, budget=0, samples=SAMPLES[quick], thresholds=THRESHOLDS)
    with tempfile.TemporaryDirectory(prefix="ipir-atlas-") as folder:
        result = run_atlas(atlas, Path(folder) / "atlas", progress=progress, show_bars=False)
    return {"axes": [{"name": a.name, "low": a.low, "high": a.high} for a in axes], "drive": params.drive,
            "metrics": list(atlas.metrics), "thresholds": list(THRESHOLDS), "samples": atlas.samples,
            "idealizations": result["idealizations"], "runs": result["runs"]["equations"], "wall_s": result["wall_s"]}


def render(metrics: dict, figures_dir: Path) -> list:
    axes = [Axis(a["name"], (), a["low"], a["high"]) for a in metrics["axes"]]
    blocks: list = [Heading("Where the paper's model holds"), Paragraph(
        "The idealization atlas (ipir-mujoco atlas) around this design: "
        + ", ".join(f"{a.name} {a.low:.3g}..{a.high:.3g}" for a in axes)
        + f" (each +-{100 * SPAN:g} % of the design's), under the design's drive ({metrics['drive']}). Each of the "
          "paper's idealizations is removed alone, as in the ladder, and its cost on a metric is (idealized - real) "
          "/ |real|, in the equations over a quasi-random sample of "
        + f"{metrics['samples'] * (len(axes) + 2)} designs ({metrics['runs']} runs). The safe share is the "
          "sample's share of designs where the cost stays within +- the threshold (Wilson's 95 % interval); what drives "
          "the cost: its largest total Sobol indices (ST, 95 % interval; '-' where no index's interval excludes 0: "
          "too few designs to tell, or a cost that hardly varies). MuJoCo's side and other ranges: "
          "ipir-mujoco atlas (docs/cli.md).")]
    rows = []
    for name, per in metrics["idealizations"].items():
        for metric, entry in per.items():
            cells = [idealization_words(name), metric_words(metric)[0]]
            for item in entry["by_threshold"]:
                lo, hi = item["safe_fraction_interval"]
                cells.append(f"{100 * item['safe_fraction']:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}]")
            rows.append(cells + [top_drivers(entry)])
    blocks.append(Table(["idealization", "metric"] + [f"safe share, cost within +-{100 * t:g} %"
                                                      for t in metrics["thresholds"]] + ["driven by"], rows))
    plot_safe(metrics["idealizations"], axes, Path(figures_dir) / "atlas_safe.png",
              title="Safe share of the design's +-50 % neighbourhood")
    blocks.append(Image("figures/atlas_safe.png", "Share of the neighbourhood where each idealization costs less "
                                                  "than each threshold, with its 95 % interval (the equations)."))
    return blocks


def verdict(metrics: dict) -> dict | None:
    parts, worst = [], None
    first = metrics["metrics"][0]
    for name, per in metrics["idealizations"].items():
        item = per[first]["by_threshold"][0]
        frac = item["safe_fraction"]
        parts.append(f"{idealization_words(name)} within {100 * item['threshold']:g} % in {100 * frac:.0f} % of it "
                     f"(driven by {top_drivers(per[first])})")
        if worst is None or frac < worst[1]:
            worst = (name, frac)
    if worst is None:
        return None
    return {"question": "Over designs near this one (+-50 %), where does each idealization hold?",
            "answer": f"In {metric_words(first)[0]} over the neighbourhood: " + "; ".join(parts) + ".",
            "evidence": "sections.model_holds", "short": f"least safe: {idealization_words(worst[0])}",
            "key": f"{100 * worst[1]:.0f} % of the neighbourhood within {100 * metrics['thresholds'][0]:g} %"}
