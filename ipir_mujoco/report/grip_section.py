"""The validation report's section "Finite grip": what wheels that hold by friction do to the robot.

Two cases of the design: the paper's start-up (its constant torque, 1 s from rest) and the motor's
cruise (the design's motor, run to its steady state). For each, the grip the models demand: the peak
clutch reaction of the paper's model (``analytic-approx``) and of the one-way model
(``analytic-unilateral``) on unlimited grip, i.e. what G = mu_wall F_n would have to be for no skid.
Then realistic wheels, mu_wall in MU and a stated press F_n in PRESS (both modules alike), in the
one-way model: travel, speed and how far the modules skid back, beside the unlimited-grip run; MuJoCo
beside it where it accepts a finite grip, else its refusal (one line) is shown. Last, the press per
module a vertical riser needs at mu_wall = RISER_MU (:func:`ipir_mujoco.studies.traction.riser_press`).
``quick``: one mu, so a handful of runs.
"""

from __future__ import annotations

from pathlib import Path

from ipir_mujoco.core.params import RobotParams

from ..studies.climb import climbing, traction
from .document import Heading, Image, Paragraph, Table, fmt

MU = {False: (0.3, 0.5, 0.8), True: (0.5,)}  # wheel-wall friction coefficients tried, full / quick
PRESS = (10.0, 50.0)  # N: wall press per module tried (50 N is the parameters' default)
RISER_MU = 0.5
ONE_WAY, PAPER, MUJOCO = "analytic-unilateral", "analytic-approx", "mujoco-ratchet"


def _cases(params: RobotParams) -> dict:
    base = params.replace(mu_wall=None, F_n1=50.0, F_n2=50.0, incline=0.0)
    return {"startup": base.replace(drive="torque"), "cruise": base.replace(drive="motor")}


def _speed(m: dict, drive: str) -> float | None:
    """[m/s]: the steady speed (motor), the mean speed over the run (the start-up: travel over its 1 s)."""
    if "error" in m:
        return None
    return m["steady_speed_m_s"] if drive == "motor" else m["travel_m"] / m["t_end_s"]


def compute(params: RobotParams, quick: bool, progress) -> dict:
    """The demands, the runs on finite grip and the riser press (module docstring)."""
    out = {"quick": quick, "mu": list(MU[quick]), "press_n": list(PRESS), "cases": {}}
    for name, case in _cases(params).items():
        unlimited = {engine: climbing.measure(engine, case) for engine in (PAPER, ONE_WAY)}
        rows = []
        for mu in MU[quick]:
            for press in PRESS:
                grip = case.replace(mu_wall=mu, F_n1=press, F_n2=press)
                row = {"mu": mu, "press_n": press, "grip_n": mu * press, ONE_WAY: climbing.measure(ONE_WAY, grip)}
                if not quick or not rows:  # quick: MuJoCo once per case, enough to show it accepts or refuses
                    row[MUJOCO] = climbing.measure(MUJOCO, grip)
                rows.append(row)
                progress(f"finite grip, {name}, mu {mu:g}, F_n {press:g} N: " + (
                    row[ONE_WAY].get("error") or f"travel {row[ONE_WAY]['travel_m']:.4g} m"))
        out["cases"][name] = {"drive": case.drive, "unlimited": unlimited, "rows": rows}
    riser = params.replace(mu_wall=RISER_MU, drive="motor")
    out["riser"] = {"mu": RISER_MU, **traction.riser_press(riser)}
    return out


def _demand(m: dict) -> str:
    return m["error"] if "error" in m else fmt(m["peak_clutch_force_n"])


def _mujoco(m: dict | None, drive: str) -> str:
    if m is None:
        return "-"
    if "error" in m:
        return "refused"
    return f"{fmt(m['travel_m'])} m, {fmt(_speed(m, drive))} m/s"


def _travel(m: dict) -> str:
    """'1.363 in 2.61 s': a run's travel [m] with the time it took [s]."""
    return "n/a" if "error" in m or m.get("travel_m") is None else f"{fmt(m['travel_m'])} in {fmt(m['t_end_s'], 3)} s"


def render(metrics: dict, figures_dir: Path) -> list:
    """The demands and finite-grip tables, the figure (figures/finite_grip.png), the riser press and a verdict."""
    titles = {"startup": "the paper's start-up (constant torque, 1 s from rest)",
              "cruise": "the motor's cruise (to its steady state)"}
    blocks: list = [Heading("Finite grip"), Paragraph(
        "A held module's locked wheels hold by friction, at most G = mu_wall F_n on the wall; beyond that the "
        "module skids back (docs/model.md, \"Finite grip\"). The peak clutch reaction on unlimited grip is the "
        "grip a run needs for no skid.")]
    blocks.append(Table(["case", "paper's model: peak reaction [N]", "one-way model: peak reaction [N]"],
                        [[titles[k], _demand(c["unlimited"][PAPER]), _demand(c["unlimited"][ONE_WAY])]
                         for k, c in metrics["cases"].items()]))
    # a run to its steady state lasts as long as it needs: its travel and skid are over its own time, so
    # that time is shown beside them, and the speed is the column to compare
    header = ["case", "mu_wall", "F_n [N]", "G [N]", "speed [m/s] (steady, or mean over 1 s)",
              "travel [m] in the run's time [s]", "skid back 1 + 2 [m]", "MuJoCo (travel, speed)"]
    rows, refusals = [], set()
    for key, case in metrics["cases"].items():
        base = case["unlimited"][ONE_WAY]
        rows.append([titles[key], "unlimited", "-", "-", fmt(_speed(base, case["drive"])), _travel(base), "0", "-"])
        for row in case["rows"]:
            m = row[ONE_WAY]
            mj = row.get(MUJOCO)
            if mj is not None and "error" in mj:
                refusals.add(mj["error"])
            rows.append(["", fmt(row["mu"], 2), fmt(row["press_n"], 3), fmt(row["grip_n"], 3),
                         m.get("error") or fmt(_speed(m, case["drive"])), "n/a" if "error" in m else _travel(m),
                         "n/a" if "error" in m else fmt(m["slip_m"]), _mujoco(mj, case["drive"])])
    blocks.append(Table(header, rows))
    write_figure(metrics, Path(figures_dir) / "finite_grip.png")
    blocks.append(Image("figures/finite_grip.png", "Speed on finite grip over the speed on unlimited grip, against "
                        "the grip G = mu_wall F_n (one-way model); the dashed line is the peak clutch reaction the "
                        "run demands on unlimited grip, the grip it needs for no skid."))
    if refusals:
        blocks.append(Paragraph("MuJoCo (" + MUJOCO + ") refused the finite grip: " + "; ".join(sorted(refusals))))
    riser = metrics["riser"]
    blocks.append(Paragraph(
        f"A vertical riser at mu_wall {riser['mu']:g} needs a press per module of "
        + " / ".join(fmt(f) for f in riser["needed_n"]) + " N (modules 1 / 2) for a standing robot to hold at "
        "every crank angle with the drive's torque at rest (each module then holds the whole weight and the "
        "other's rolling resistance, m g + F_r); with the drive off, "
        + " / ".join(fmt(f) for f in riser["press_n"]["drive_off"]) + " N (each module its own weight share)."))
    blocks.append(Paragraph(verdict(metrics)["answer"]))
    return blocks


def write_figure(metrics: dict, path: Path) -> None:
    """One panel per case: relative speed [-] against the grip G [N] (log axis), with the demanded grip."""
    grip_figure(metrics).savefig(path, dpi=110)


def grip_figure(metrics: dict):
    """The figure of :func:`write_figure` (a matplotlib Figure, for tests to read)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    fig = Figure(figsize=(8.0, 3.4), layout="constrained")
    FigureCanvasAgg(fig)
    for ax, (key, case) in zip(fig.subplots(1, len(metrics["cases"]), squeeze=False)[0], metrics["cases"].items()):
        base = _speed(case["unlimited"][ONE_WAY], case["drive"])
        points = sorted((r["grip_n"], _speed(r[ONE_WAY], case["drive"])) for r in case["rows"]
                        if "error" not in r[ONE_WAY])
        if base and points:
            ax.plot([g for g, _v in points], [v / base for _g, v in points], "o-", color="tab:blue")
        need = case["unlimited"][ONE_WAY].get("peak_clutch_force_n")
        if need:
            ax.axvline(need, linestyle="--", color="gray")
        ax.set_xscale("log")
        # labelled ticks at 1, 2, 5 of each decade: a panel spanning about a decade shows several
        ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("grip per module, G [N]")
        ax.set_ylabel("speed: finite / unlimited grip [-]")
        ax.set_title("paper's start-up (1 s)" if key == "startup" else "motor's cruise (steady)", fontsize=9)
        ax.grid(alpha=0.3)
    fig.legend(handles=[Line2D([], [], color="tab:blue", marker="o", label="one-way model on finite grip"),
                        Line2D([], [], color="gray", ls="--", label="grip needed for no skid (peak clutch reaction)")],
               loc="outside lower center", ncols=2, fontsize="small")
    return fig


def verdict(metrics: dict) -> dict:
    """{question, answer, evidence}: how much grip the runs need against what realistic wheels give."""
    parts = []
    for key, case in metrics["cases"].items():
        need = case["unlimited"][ONE_WAY].get("peak_clutch_force_n")
        base = case["unlimited"][ONE_WAY]
        weakest = min((r for r in case["rows"] if "error" not in r[ONE_WAY]), key=lambda r: r["grip_n"],
                      default=None)
        if need is None or weakest is None:
            continue
        m = weakest[ONE_WAY]
        v0, v1 = _speed(base, case["drive"]), _speed(m, case["drive"])
        change = "n/a" if not v0 or v1 is None else f"{100.0 * (v1 / v0 - 1.0):+.1f} %"
        parts.append(f"{'the start-up' if key == 'startup' else 'the cruise'} needs {fmt(need, 3)} N of grip; "
                     f"on G = {fmt(weakest['grip_n'], 3)} N (mu {weakest['mu']:g}, F_n {weakest['press_n']:g} N) "
                     f"the modules skid back {fmt(m['slip_m'], 3)} m and the speed changes {change}")
    answer = ("The one-way model: " + "; ".join(parts) + ".") if parts else "No finite-grip run completed."
    needs = [case["unlimited"][ONE_WAY].get("peak_clutch_force_n") for case in metrics["cases"].values()]
    needs = [n for n in needs if n is not None]
    short = (f"up to {fmt(max(needs), 3)} N per module (the one-way model); less skids" if needs
             else "no finite-grip run completed")
    return {"question": "How much wall grip does the robot need, and what does realistic grip cost?",
            "answer": answer, "short": short,
            "key": f"riser: F_n >= {fmt(max(metrics['riser']['needed_n']), 3)} N at mu {metrics['riser']['mu']:g}",
            "evidence": f"riser press at mu {metrics['riser']['mu']:g}: "
                        + " / ".join(fmt(f) for f in metrics["riser"]["needed_n"]) + " N per module"}
