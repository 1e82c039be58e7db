"""Render the validation report as Markdown and as self-contained HTML.

The report is built once as a list of blocks (heading, paragraph, table,
figure) and rendered twice, so ``report.md`` and ``index.html`` always say the
same. The HTML embeds its figures and the animation as data URIs: one file,
readable offline, no scripts. The animation needs headless OpenGL (see
:mod:`ipir_mujoco.video`); where there is none, the report says so in its
place and is otherwise complete.

The report's own figures (the clutches' reactions, the L/r study, the pull per stroke) are drawn by
:mod:`.validation_figures`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Sequence

from ipir_mujoco.core.options import heartbeat

from ..labels import summary_label
from .overview import FIGURE as OVERVIEW
from .overview import (accuracy_flag, ladder_change, monitor_verdict, overview_caption, overview_figure,
                       place_moved, verdict_blocks)
from ..resources import shipped
from .diagram import write_mechanism_diagram
from .document import Heading, Image, Link, Paragraph, Table, fmt, pct, to_html, to_markdown
from .validation_figures import LR_CURVES, figure_clutch_reactions, figure_lr_study, figure_pull_per_stroke
from ..core.figures import write_paper_figures
from ..studies.validation.paper_reference import describe_differences
from ..studies.validation.validate import FIGURE_RUNGS, LADDER_FIGURES, LadderRun


# The report's animation: the start (t_end [s] simulated) of the ladder's last rung, MuJoCo's robot on wheels in its
# pipe (the robot the mechanism diagram draws), ten times slower than real time, at a size whose text and wheels
# read in a page (768 px wide: the text, MuJoCo's larger font, in two corners off the robot); the MuJoCo ratchet's
# run where a ladder has no wheeled rung. --quick draws fewer, smaller frames
ANIMATION = {"t_end": 0.5, "width": 768, "height": 432, "fps": 12.5, "speed": 0.1}  # 80 ms a frame
ANIMATION_QUICK = {"t_end": 0.2, "width": 640, "height": 360, "fps": 10.0, "speed": 0.1}
ANIMATION_RUNGS = ("wheels in contact", "MuJoCo ratchet")  # the first of them the ladder ran


def _paper_section(metrics: dict, figures: dict[str, str]) -> list:
    """The paper's figures against the paper's model, or, at another design, why they are not checked."""
    case = metrics["paper_case"]
    blocks: list = []
    if case["is_paper_case"]:
        blocks.append(Heading("The paper's figures, reproduced"))
        blocks.append(Paragraph(
            "The paper states its results in rounded words. Each figure is checked against the values that round "
            "to the paper's number: a number stated to 0.1 m covers +-0.05 m. A value exactly on a bound is "
            "marked 'edge': it rounds to the paper's number under one rounding rule and to the next number under "
            "another. Margin: the distance to the nearer bound, in units of the stated precision."))
        status = {"inside": "inside", "edge": "EDGE", "outside": "OUTSIDE"}
        blocks.append(Table(
            ["figure", "paper's words", "stated precision", "accepted interval", "paper's model (this package)",
             "verdict", "margin [precisions]", "why this precision"],
            [[c["label"], c["reported"], f"{c['precision']:g} {c['units']}",
              f"[{c['low']:.6g}, {c['high']:.6g}] {c['units']}", f"{c['value']:.6g} {c['units']}",
              status[c["status"]], "" if c["margin_precisions"] is None else f"{c['margin_precisions']:.3f}",
              c["why"]] for c in metrics["paper_checks"]]))
        for check in metrics["paper_checks"]:
            if check["note"]:
                blocks.append(Paragraph(f"**{check['label']}:** {check['note']}."))
    else:
        blocks.append(Heading("Not the paper's case"))
        blocks.append(Paragraph(
            "These parameters differ from the paper's simulation case: " + describe_differences(case["differences"])
            + ". The paper prints figures for its own case only, so none is checked here; the paper's model at "
              "this design (first-order kinematics, massless rod, ideal locks) is the ladder's first rung, and "
              "every other rung is compared with it."))
        first = metrics["ladder"][0]["summary"]
        blocks.append(Table(["figure", "paper's model at this design"],
                            [[summary_label(k), fmt(first[k], 6)] for k in LADDER_FIGURES]))
    blocks.append(Paragraph("Identities: the paper also states the range of the gap, which every slider-crank "
                            "has by construction; they hold for any run and are not counted as reproduced figures."))
    blocks.append(Table(["identity", "paper's words", "expected [m]", "paper's model [m]", "holds"],
                        [[i["label"], i["reported"], f"{i['expected']:.6g}", f"{i['value']:.6g}",
                          "yes" if i["holds"] else "NO"] for i in metrics["identities"]]))
    for key in ("fig2_crank.png", "fig3_modules.png", "fig4_gap.png"):
        blocks.append(Image(figures[key], {
            "fig2_crank.png": "The paper's Fig. 2: crank angle in revolutions and cos phi; the paper's model "
                              "(solid), MuJoCo with the paper's locks (dashed) and with one-way clutches (dotted).",
            "fig3_modules.png": "The paper's Fig. 3: module displacements (from the start), velocities, "
                                "accelerations. Module 2 advances in whole strokes of 2r under the paper's rule.",
            "fig4_gap.png": "The paper's Fig. 4: gap S in dm and its rate."}[key]))
    return blocks


def _mechanism_section(figures: dict[str, str], animation_note: str | None, settings: dict) -> list:
    blocks: list = [Heading("The mechanism"), Paragraph(
        "A motor turns the crank AB (length r) about A on module 1; the connecting rod BC (length L) pushes and "
        "pulls module 2 at C. The gap S = x2 - x1 between A and C swings between L - r and L + r as the crank "
        "turns (phi = 0: the crank points at C, S = L + r). Wheels with one-way clutches let each module move "
        "forward only, so the oscillation of S becomes forward motion: while S shrinks (contraction) the front "
        "clutch holds and module 1 moves; while S grows (expansion) the rear clutch holds and module 2 moves. "
        "The symbols are those of docs/model.md.")]
    blocks.append(Image(figures["mechanism.png"], "The robot, to scale for these parameters."))
    if animation_note is None:
        wheels = settings.get("model", "wheels") == "wheels"
        robot = ("MuJoCo's robot on wheels in its pipe (the ladder's last rung, a one-way ratchet in every wheel's "
                 "hub)" if wheels else "MuJoCo with one-way clutches (the ratchet)")
        blocks.append(Image(figures["robot.gif"], (
            f"{robot}, the first {settings['t_end']:g} s from rest at {settings['speed']:g}x real time, rendered by "
            "MuJoCo offscreen. A module turns green while its clutch holds it. The same video for any design: "
            f"ipir-mujoco render{' --mujoco-model wheels' if wheels else ''} --out robot.gif")))
    else:
        blocks.append(Paragraph(f"(No animation: {animation_note}. The rest of the report does not need it; "
                                "'ipir-mujoco render' writes one where headless OpenGL exists.)"))
    return blocks


def _mujoco_settings_text(settings: dict) -> str:
    """How each MuJoCo rung was integrated (its timestep was chosen from the motion)."""
    runs = settings.get("mujoco_runs") or {"every run": settings["mujoco"]}
    any_run = next(iter(runs.values()))
    steps = "; ".join(f"{name}: timestep {s['timestep']:.3g} s, constraint time constant "
                      f"{s['constraint_time_constant']:.3g} s" for name, s in runs.items())
    return (f"{any_run['integrator']}, solimp {tuple(any_run['solimp'])}; timesteps chosen from the motion "
            f"(the crank speed the drive can reach, the rod's mass ratio, the clutch stiffness): {steps}")


def _envelope_blocks(envelope: dict) -> list:
    """The automatic MuJoCo settings over the envelope's corners, against the analytic model."""
    done = [r for r in envelope["rows"] if "error" in r]
    headline = (f"With default options (the timestep chosen from the motion, the accuracy monitor on) MuJoCo "
                f"stays within {100 * envelope['worst_error']:.3f} % of the analytic model of the same mechanism "
                f"in crank revolutions and travel over {len(done)} runs at the envelope's corners (worst: "
                f"{envelope['worst_case']}; the target is {100 * envelope['tolerance']:g} %)"
                + (f"; the accuracy monitor stopped {envelope['stopped']} run(s), listed below"
                   if envelope["stopped"] else "; the accuracy monitor stopped none")
                + f". MuJoCo took {envelope['mujoco_wall_s']:.1f} s for them, the analytic model "
                  f"{envelope['analytic_wall_s']:.1f} s. The whole envelope (speed, rod mass, L/r and mass ratio, "
                  "both clutches) is tabulated in the package's mjcf/README.md.")
    rows = []
    for r in envelope["rows"]:
        if "error" not in r:
            rows.append([r["case"], f"{r['clutch']} ({r['rule']})", f"{r['t_end']:g}", "stopped", "", "", "", "",
                         r["stopped"]])
            continue
        a = r["accuracy"]
        rows.append([r["case"], f"{r['clutch']} ({r['rule']})", f"{r['t_end']:g}",
                     f"{r['timestep']:.3g}" + (f" ({r['refinements']} halvings)" if r["refinements"] else ""),
                     pct(r["error"]["revolutions"]), pct(r["error"]["travel"]), f"{a['residual_ratio']:+.1e}",
                     f"{a['loop_gap_m']:.1e}", f"{r['wall_s']:.2f}"])
    return [Paragraph(headline),
            Table(["case", "MuJoCo clutch (rule)", "t_end [s]", "automatic timestep [s]",
                   "MuJoCo vs equations: revolutions", "MuJoCo vs equations: travel",
                   "worst energy residual / energy [-]", "worst loop gap [m]", "MuJoCo wall [s]"], rows)]


def build_blocks(metrics: dict, figures: dict[str, str], animation_note: str | None = None,
                 animation: dict | None = None, extra: Sequence = ()) -> list:
    case = metrics["paper_case"]
    where = ("at the paper's case" if case["is_paper_case"]
             else "at a design that is not the paper's case (" + describe_differences(case["differences"]) + ")")
    blocks: list = [Heading("ipir-mujoco validation report", 1),
                    Paragraph("The paper's analytic model of the two-module inchworm robot, reproduced and "
                              f"taken apart one idealization at a time {where} "
                              f"(simulated {metrics['settings']['t_end_s']:g} s from rest).")]
    if OVERVIEW in figures:  # the picture a reader grasps first (report/overview.py)
        blocks.append(Image(figures[OVERVIEW], overview_caption(metrics)))
    blocks.append(Heading("Summary"))
    blocks.append(Table(["question", "verdict", "key figure", "where"],
                        [[v["question"], v["short"], v["key"],
                          Link(v["section"], v["section"]) if v.get("section") else ""] for v in metrics["verdicts"]]))
    verdicts, moved = verdict_blocks(metrics["verdicts"])  # short; the full answers open their sections
    blocks += verdicts
    blocks += _mechanism_section(figures, animation_note, animation or ANIMATION)
    blocks += _paper_section(metrics, figures)

    blocks.append(Heading("The model ladder"))
    blocks.append(Paragraph("Each rung removes one idealization. In brackets, what that idealization costs: (the "
                            "rung before, which has it - this rung) / |this rung|, the model with it against the "
                            "model without it, the convention of every cost in this report (for a MuJoCo rung: the "
                            "equations against MuJoCo). A figure that changes sign or reaches zero is given as a "
                            "difference in its unit."))
    header = ["rung", "removes"] + [summary_label(k) for k in LADDER_FIGURES]
    rows, previous = [], None
    for rung in metrics["ladder"]:
        cells = [rung["name"], rung["isolates"]]
        for key in LADDER_FIGURES:
            # the rung before (with the idealization) against this one: value and reference swapped
            change = ladder_change(None if previous is None else previous["summary"][key], rung["summary"][key],
                                   rung["cost_vs_previous"][key] if previous is not None else None, key)
            cells.append(fmt(rung["summary"][key]) + (f" ({change})" if change else ""))
        rows.append(cells)
        previous = rung
    blocks.append(Table(header, rows))

    from ..studies.validation.lr_study import FIGURES as LR_FIGURES, describe_threshold

    study = metrics["lr_study"]
    blocks.append(Heading("Where L >> r breaks down"))
    blocks.append(Paragraph(
        f"L/r swept from {study['ratios'][0]:.3g} to {study['ratios'][-1]:.3g} ({len(study['ratios'])} ratios, "
        "log-spaced; r and everything else as in the parameters below), each with the first-order equations, the "
        "exact slider-crank equations with the same massless rod (their difference is the L >> r assumption "
        "alone) and MuJoCo's real linkage beside the exact equations of that same linkage, with its rod (MuJoCo "
        "needs a rod with mass), all under the paper's clutch rule. Summary figures diverge by "
        "(first order - exact) / |exact|; the gap S and its rate at the same crank angle by their largest "
        "difference over the run, as a share of the stroke 2r and of the largest |dS/dt|. Each threshold is "
        "bracketed by two neighbouring ratios of the sweep; the crank revolutions' thresholds are then narrowed on "
        "the equations to 0.002 in L/r by the root-finding of ipir-mujoco atlas, which finds the same crossing "
        "over L."))
    blocks.append(Image(figures["lr_study.png"], "Divergence of the first-order model from the exact linkage "
                                                 "against L/r (log axes)."))
    angle_labels = {"S_at_angle": "gap S at the same crank angle (share of 2r)",
                    "S_dot_at_angle": "gap rate dS/dt at the same crank angle (share of max |dS/dt|)"}
    blocks.append(Table(["figure", "off by more than 1 %", "off by more than 5 %"],
                        [[angle_labels.get(key) or summary_label(key),
                          describe_threshold(study["thresholds"][key]["1%"]),
                          describe_threshold(study["thresholds"][key]["5%"])]
                         for key in LR_FIGURES + ("S_at_angle", "S_dot_at_angle")]))
    blocks.append(Table(["L/r [-]"] + [f"{label}: first order vs exact" for _, label in LR_CURVES]
                        + ["MuJoCo vs exact with its rod: crank revolutions"],
                        [[f"{row['ratio']:.3g}"] + [pct(row["divergence"][key]) for key, _ in LR_CURVES]
                         + [pct(row["mujoco_vs_exact"]["revolutions"])] for row in study["rows"]]))

    pull = metrics["clutch_pull"]
    blocks.append(Heading("Clutch forces under the paper's rule"))
    blocks.append(Paragraph(
        f"A locked clutch would have to pull during {100 * pull['fraction_of_time']:.1f} % of the run, with up to "
        f"{-pull['min_reaction_n']:.0f} N. The reaction is the moving module's m a + F_r: it turns negative "
        "whenever that module brakes harder than its resistance alone would brake it."))
    blocks.append(Image(figures["clutch_reactions.png"], "Locked-clutch reactions against crank angle."))
    blocks.append(Paragraph("The faster the crank, the more of each stroke the lock must pull: the moving module "
                            "is braked by the linkage harder than by its resistance for a growing share of the stroke."))
    blocks.append(Image(figures["pull_per_stroke.png"], "Share of each stroke in which the paper's lock would have "
                                                        "to pull, against the stroke's mean crank speed (complete "
                                                        "strokes only: the last one, cut short by the end of the "
                                                        "run, is left out)."))

    blocks.append(Heading("Energy audit"))
    blocks.append(Paragraph("For the equations the residual is the integration error; for MuJoCo it is what "
                            "the soft constraints and the time stepping took."))
    blocks.append(Table(["rung", "motor work [J]", "kinetic [J]", "friction [J]", "residual [J]",
                         "residual / motor work [-]", "MuJoCo's accuracy monitor"],
                        [[r["name"], fmt(e["motor_work_j"], 8), fmt(e["kinetic_j"], 8), fmt(e["friction_j"], 8),
                          f"{e['residual_j']:.2e}", f"{e['residual_j'] / e['motor_work_j']:.1e}",
                          monitor_verdict(r["summary"].get("accuracy"))]
                         for r in metrics["ladder"] for e in [r["summary"]["energy"]]]))
    flagged = [flag for r in metrics["ladder"] if (flag := accuracy_flag(r["name"], r["summary"].get("accuracy")))]
    if flagged:
        blocks.append(Paragraph("**Flagged:** " + " ".join(flagged)))

    blocks += list(extra)

    conv = metrics["convergence"]
    auto_steps = ", ".join(f"{clutch} {step:g} s" for clutch, step in conv.get("mujoco_auto_timestep", {}).items())
    blocks.append(Heading("Numerical convergence"))
    blocks.append(Paragraph(
        f"MuJoCo at this design, halving the timestep (constraint time constant two steps): the step the engine "
        f"chooses by itself for each clutch ({auto_steps}) is within {100 * conv['mujoco_default_error']:.3f} % of "
        f"half of it and of every finer step tried. The equations (one-way clutches) against solver tolerance: the default rtol 1e-10 is "
        f"within {100 * conv['equations_default_error']:.1e} % of the tightest. Both far below the modelling "
        "differences above. The full study over three designs is in the package's mjcf/README.md."))
    blocks.append(Table(["MuJoCo clutch", "timestep [s]", summary_label("revolutions"), summary_label("x1_final"),
                         summary_label("x2_final"), "vs equations: revolutions", "energy residual / motor work [-]"],
                        [[f"{r['clutch']} ({r['rule']})", f"{r['timestep']:g}", f"{r['revolutions']:.6f}",
                          f"{r['x1_final']:.6f}", f"{r['x2_final']:.6f}",
                          pct(r["vs_analytic"]["revolutions"]) if "vs_analytic" in r else "",
                          f"{r['residual_fraction']:.1e}"] for r in conv["mujoco"]]))
    envelope = conv.get("envelope")
    if envelope is not None:
        blocks += _envelope_blocks(envelope)
    blocks.append(Table(["equations rtol [-]", summary_label("revolutions"), summary_label("x1_final"),
                         summary_label("x2_final"), "energy residual / motor work [-]"],
                        [[f"{r['rtol']:g}", f"{r['revolutions']:.10f}", f"{r['x1_final']:.10f}",
                          f"{r['x2_final']:.10f}", f"{r['residual_fraction']:.1e}"] for r in conv["equations"]]))

    blocks.append(Heading("Parameters and software"))
    blocks.append(Table(["parameter", "value", "unit", "meaning"],
                        [[row["name"], row["text"], row["units"], row["meaning"]]
                         for row in metrics["parameter_table"]]))
    settings = metrics["settings"]
    blocks.append(Paragraph(f"Analytic solver: DOP853, rtol {settings['rtol']:g}, atol {settings['atol']:g}, "
                            f"output every {settings['dt_out_s']:g} s plus every mode switch"
                            + (" (quick run)." if settings["quick"] else ".")
                            + " MuJoCo: " + _mujoco_settings_text(settings) + " (evidence: the package's mjcf/README.md)."))
    blocks.append(Table(["software", "version"], [[k, v] for k, v in metrics["versions"].items()]))
    blocks.append(Paragraph("All numbers above are in metrics.json (schema in "
                            "ipir_mujoco/studies/validation/validate.py); "
                            "the model and its conventions are in docs/model.md. The documents this report names "
                            f"are installed with the package: docs/model.md as {shipped('docs/model.md')}, "
                            f"mjcf/README.md as {shipped('mjcf/README.md')}."))
    return place_moved(blocks, moved)


def write_animation(rung: LadderRun, path: Path, quick: bool) -> tuple[str | None, dict]:
    """The report's animation of ``rung``'s run (a MuJoCo run); (None, settings) if written, else (why not,
    settings); the settings say which MuJoCo model it draws (``model``: 'slides' or 'wheels')."""
    from ..video import RenderUnavailable, VideoSettings, write_video

    settings = ANIMATION_QUICK if quick else ANIMATION
    video = VideoSettings(**{k: v for k, v in settings.items() if k != "t_end"})
    from .. import registry
    from ..studies.validation.ladder import VALIDATION_LADDER

    variant = registry.variant(next(r.variant for r in VALIDATION_LADDER if r.name == rung.name))
    model = variant.model
    try:
        write_video(rung.run, path, video, t_end=settings["t_end"],
                    title=f"MuJoCo, one-way clutches ({variant.mechanism_words})")
    except RenderUnavailable as exc:
        return str(exc), {**settings, "model": model}
    return None, {**settings, "model": model}


def write_report(folder: Path, metrics: dict, rungs: list[LadderRun], sections: Sequence = (),
                 progress: Callable[[str], None] = lambda _m: None) -> None:
    """Write figures/, report.md and index.html into ``folder`` (metrics.json is the caller's).

    ``sections`` (:class:`ipir_mujoco.report.sections.Section`) draw their parts
    from ``metrics["sections"]``, after the core and before the numerical evidence.
    ``progress`` hears a line per group of figures, and one at least every 5 s of wall time
    (the animation takes several seconds).
    """
    figures_dir = folder / "figures"
    figures_dir.mkdir(parents=True, exist_ok=True)
    with heartbeat(progress, "writing report") as beat:
        beat.say("writing report: the ladder's figures")
        drawn = [r for r in rungs if r.name in FIGURE_RUNGS]
        write_paper_figures([r.run for r in drawn], figures_dir, labels=[r.name for r in drawn])
        write_mechanism_diagram(figures_dir / "mechanism.png", rungs[0].run.params)
        figure_clutch_reactions(rungs[0], figures_dir / "clutch_reactions.png")
        figure_lr_study(metrics["lr_study"], figures_dir / "lr_study.png")
        figure_pull_per_stroke(metrics["clutch_pull"]["per_stroke"], figures_dir / "pull_per_stroke.png")
        overview_figure(metrics).savefig(figures_dir / OVERVIEW, dpi=110)
        beat.say("writing report: the animation")
        physics = next(r for name in ANIMATION_RUNGS for r in rungs if r.name == name)
        note, animation = write_animation(physics, figures_dir / "robot.gif", metrics["settings"]["quick"])
        extra = []
        for section in sections:
            beat.say(f"writing report: {section.title}")
            extra += section.render(metrics["sections"][section.key], figures_dir)
    figures = {p.name: f"figures/{p.name}" for p in figures_dir.iterdir()}
    blocks = build_blocks(metrics, figures, note, animation, extra)
    (folder / "report.md").write_text(to_markdown(blocks))
    (folder / "index.html").write_text(to_html(blocks, folder))
