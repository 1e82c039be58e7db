"""The validation report's section "Speed control": what model-based control buys, and what the paper's model
costs a controller designed on it.

The speed controller of ``drive = servo`` (:mod:`ipir_mujoco.core.control`) holds the crank at
:data:`SPEED` rad/s (a third of the no-load speed where that is less; the design's ``omega_target`` where its
drive is the servo), with the PI alone and with the
feedforward from the paper's first-order model and from the exact one, each run to its steady state in the
paper's geometry (what the paper's model promises the controller), the exact one-way equations and MuJoCo:
six runs, about two seconds. The full comparison, with the open-loop motor and a dead-centre profile, is
``ipir-mujoco control-study``.
"""

from __future__ import annotations

from pathlib import Path

from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams

from .document import Heading, Image, Paragraph, Table, fmt

SPEED = 10.0  # rad/s
PROMISE, EXACT, MUJOCO = "analytic-approx-unilateral", "analytic-unilateral", "mujoco-ratchet"
RUNS = (("pi", EXACT), ("pi+paper", PROMISE), ("pi+paper", EXACT), ("pi+paper", MUJOCO),
        ("pi+exact", EXACT), ("pi+exact", MUJOCO))
QUICK_RUNS = (("pi+paper", PROMISE), ("pi+paper", EXACT), ("pi+exact", EXACT))
LABELS = {PROMISE: "paper's geometry (what it promises)", EXACT: "exact equations", MUJOCO: "MuJoCo"}


def compute(params: RobotParams, quick: bool, progress) -> dict:
    """The section's runs (module docstring), each as the control study reads it
    (:func:`ipir_mujoco.studies.control_study.run_task`: its figures over the steady window and the crank speed
    over its last revolution), or an error."""
    from ..studies.mechanism.control_study import Task, run_task

    speed = params.omega_target if params.drive == "servo" else min(SPEED, params.omega_noload / 3)
    defaults = RobotParams()
    base = params.replace(drive=defaults.drive, clutch_stiffness=None, clutch_damping=0.0, clutch_backlash=0.0,
                          mu_wall=None, F_n1=defaults.F_n1, F_n2=defaults.F_n2)  # the study's: rigid clutches
    out = {"speed_rad_s": speed, "control_rate_hz": base.control_rate, "runs": []}
    for controller, variant in (QUICK_RUNS if quick else RUNS):
        record = {"controller": controller, "variant": variant}
        try:
            record.update(run_task(base, Task("controllers", variant, controller, speed)))
        except (ParameterError, SimulationError) as exc:
            record["error"] = " ".join(str(exc).split())
        progress(f"speed control: {controller} on {variant}")
        out["runs"].append(record)
    return out


def _find(metrics: dict, controller: str, variant: str) -> dict | None:
    return next((r for r in metrics["runs"] if r["controller"] == controller and r["variant"] == variant
                 and "error" not in r), None)


def _ripple(metrics: dict, controller: str, variant: str) -> str:
    r = _find(metrics, controller, variant)
    return "n/a" if r is None or r["speed_ripple"] is None else f"{100 * r['speed_ripple']:.2g} %"


def render(metrics: dict, figures_dir) -> list:
    """The table of the runs and what they show."""
    w = metrics["speed_rad_s"]
    blocks: list = [Heading("Speed control"), Paragraph(
        f"The DC motor under a speed controller (`--drive servo`, docs/control.md): PI at "
        f"{metrics['control_rate_hz']:g} Hz with gains derived from the model, optionally plus a feedforward, the "
        f"torque inverse kinetostatics says a crank turning at exactly {w:g} rad/s needs, from the paper's "
        "first-order geometry (L >> r) or the exact slider-crank. The same controller runs in both engines; each "
        "run to its steady state. The paper's-geometry rows are what a controller designed on the paper's model "
        "expects; the exact equations and MuJoCo are what it gets on the real linkage.")]
    header = ["controller", "model", "speed ripple [%]", "mean crank speed [rad/s]", "peak clutch force [N]",
              "energy per metre [J/m]", "peak u (magnitude)"]
    rows = []
    for r in metrics["runs"]:
        if "error" in r:
            rows.append([CONTROLLERS[r["controller"]], LABELS[r["variant"]], "n/a: " + r["error"], "", "", "", ""])
            continue
        rows.append([CONTROLLERS[r["controller"]], LABELS[r["variant"]],
                     "n/a" if r["speed_ripple"] is None else fmt(100 * r["speed_ripple"], 3),
                     fmt(r["mean_omega_rad_s"], 6), fmt(r["peak_clutch_force_n"], 4),
                     fmt(r["energy_per_metre_j_m"], 4), fmt(r["peak_drive_u"], 3)])
    blocks.append(Table(header, rows))
    write_figure(metrics, Path(figures_dir) / "speed_control.png")
    blocks.append(Image("figures/speed_control.png", f"The crank speed's deviation from its {w:g} rad/s target over "
                        "one steady revolution, per controller: the exact equations (solid), MuJoCo (dotted), and as a "
                        "wide pale band what the paper's feedforward promises on the paper's own geometry."))
    blocks.append(Paragraph(
        f"The paper's feedforward promises a ripple of {_ripple(metrics, 'pi+paper', PROMISE)} on its own model and "
        f"delivers {_ripple(metrics, 'pi+paper', EXACT)} on the exact equations "
        f"({_ripple(metrics, 'pi+paper', MUJOCO)} in MuJoCo); the PI alone gives "
        f"{_ripple(metrics, 'pi', EXACT)}, the exact feedforward {_ripple(metrics, 'pi+exact', EXACT)} "
        f"({_ripple(metrics, 'pi+exact', MUJOCO)} in MuJoCo). What L >> r drops is the rod's angle: the exact "
        "gap rate K = -r sin(phi) (1 + r cos(phi) / D) makes the strokes asymmetric by up to r / L, and the inertia "
        "torque the feedforward must supply, 1/2 dJ/dphi omega^2, has another shape; the PI is left with that "
        "error. The open-loop motor's ripple at the same mean speed is over 50 % (ipir-mujoco control-study, "
        "which also compares a speed profile that slows through the dead centres). MuJoCo's peak clutch force is "
        "n/a, as in a sweep: its rigid ratchet takes up each hand-over within a few steps of a soft constraint, "
        "and a sampled peak measures the step (the section \"Real clutches\" has real clutches' loads)."))
    return blocks


COLOURS = {"pi": "tab:blue", "pi+paper": "tab:orange", "pi+exact": "tab:green"}
STYLES = {EXACT: "-", MUJOCO: ":", PROMISE: "-"}
# the controllers in words (the table's and the figure's; the code names are the servo's --feedforward choices)
CONTROLLERS = {"pi": "PI alone", "pi+paper": "PI + the paper's feedforward", "pi+exact": "PI + the exact feedforward"}
PROMISE_WIDTH = 7.0  # points: what the paper's model promises, a wide pale band under the thin delivered lines


def write_figure(metrics: dict, path: Path) -> None:
    speed_figure(metrics).savefig(path, dpi=110)


def speed_figure(metrics: dict):
    """The crank speed over a steady revolution, as a deviation from the target [%], per run: the delivered runs
    as thin lines (exact equations solid, MuJoCo dotted), the paper's promise as a wide pale band beneath them, the
    target as a grey line; the legend below the panel."""
    import math

    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    w = metrics["speed_rad_s"]
    ax.axhline(0.0, color="0.45", lw=0.9, zorder=1.5, label=f"target, {w:g} rad/s")
    for r in sorted(metrics["runs"], key=lambda r: r["variant"] != PROMISE):  # the promise first, underneath
        if "error" in r or not r["trace"]["phi_rad"]:
            continue
        phi = np.degrees(np.mod(r["trace"]["phi_rad"], 2 * math.pi))
        order = np.argsort(phi)
        deviation = 100 * (np.asarray(r["trace"]["omega_rad_s"])[order] / w - 1)
        promise = r["variant"] == PROMISE
        ax.plot(phi[order], deviation, color=COLOURS[r["controller"]], ls=STYLES[r["variant"]],
                lw=PROMISE_WIDTH if promise else 1.3, alpha=0.35 if promise else 1.0, zorder=1 if promise else 2,
                solid_capstyle="butt", label=f"{CONTROLLERS[r['controller']]}, {LABELS[r['variant']]}")
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 45))
    ax.set_xlabel("crank angle phi [deg] (dead centres at 0 and 180)")
    ax.set_ylabel("crank speed - target [% of target]")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=2, frameon=False)
    return fig


def verdict(metrics: dict) -> dict | None:
    """{question, answer, evidence}: the ripples promised and delivered."""
    promised, delivered = _find(metrics, "pi+paper", PROMISE), _find(metrics, "pi+paper", EXACT)
    exact = _find(metrics, "pi+exact", EXACT)
    if promised is None or delivered is None or exact is None:
        return None
    w = metrics["speed_rad_s"]
    return {"question": "What does model-based speed control buy, and what does the paper's model cost it?",
            "answer": f"At {w:g} rad/s a PI with the exact model's feedforward holds the crank within "
                      f"{_ripple(metrics, 'pi+exact', EXACT)} peak to peak; with the paper's feedforward it is "
                      f"promised {_ripple(metrics, 'pi+paper', PROMISE)} and gets "
                      f"{_ripple(metrics, 'pi+paper', EXACT)} on the real linkage.",
            "short": f"ripple {_ripple(metrics, 'pi+exact', EXACT)} (exact ff) vs "
                     f"{_ripple(metrics, 'pi+paper', EXACT)} (paper's ff)",
            "key": f"paper's ff promises {_ripple(metrics, 'pi+paper', PROMISE)}",
            "evidence": f"speed ripple at {w:g} rad/s, exact one-way equations"}
