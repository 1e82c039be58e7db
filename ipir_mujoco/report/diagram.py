"""The labelled mechanism diagram: what A, B, C, r, L, phi, S, x1, x2 and the clutches are.

Drawn to scale from a parameter set (the paper's case by default) with
matplotlib, headless. ``python -m ipir_mujoco.report.diagram FILE.png`` writes
it; the validation report and docs/model.md show it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Arc, Circle, FancyArrowPatch, Rectangle

from ipir_mujoco.core.params import RobotParams

REAR, FRONT, CRANK, ROD = "0.25", "tab:red", "tab:orange", "tab:blue"


def _arrow(ax, start, end, colour="black", style="-|>", lw=1.2, **kw):
    ax.add_patch(FancyArrowPatch(start, end, arrowstyle=style, mutation_scale=12, color=colour, lw=lw,
                                 shrinkA=0, shrinkB=0, **kw))


def _module(ax, centre_x: float, width: float, height: float, colour: str, name: str, wall: float) -> None:
    """A module body with a wheel pressed on each pipe wall and a one-way clutch symbol on each wheel."""
    ax.add_patch(Rectangle((centre_x - width / 2, -height / 2), width, height, fc="white", ec=colour, lw=1.8))
    ax.text(centre_x - width / 2 + 0.003, -height / 2 + 0.003, name, ha="left", va="bottom", fontsize=8,
            color=colour)
    radius = (wall - height / 2) / 2
    for side in (1, -1):
        y = side * (wall - radius)
        ax.add_patch(Circle((centre_x, y), radius, fc="0.85", ec=colour, lw=1.2))
        # ratchet teeth: the wheel turns one way only
        angles = np.linspace(0, 2 * math.pi, 9)[:-1]
        for a in angles:
            inner = (centre_x + 0.45 * radius * math.cos(a), y + 0.45 * radius * math.sin(a))
            outer = (centre_x + 0.8 * radius * math.cos(a + 0.5), y + 0.8 * radius * math.sin(a + 0.5))
            ax.plot([inner[0], outer[0]], [inner[1], outer[1]], color=colour, lw=0.7)


def figure_mechanism(params: RobotParams | None = None, phi: float = math.radians(55.0)) -> Figure:
    """The robot at crank angle ``phi`` [rad], to scale, with every symbol the docs and report use."""
    p = params or RobotParams()
    r, L = p.r, p.L
    scale = 0.05 / r  # drawn as if r were 0.05 m, so labels keep their size for any design
    r, L = r * scale, L * scale
    wall = 0.08
    x1 = 0.09  # position of A from the origin O
    a = np.array([x1, 0.0])
    b = a + r * np.array([math.cos(phi), math.sin(phi)])
    s = r * math.cos(phi) + math.sqrt(L**2 - (r * math.sin(phi)) ** 2)
    c = np.array([x1 + s, 0.0])

    fig = Figure(figsize=(9.0, 4.6), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.set_aspect("equal")
    ax.axis("off")
    right = c[0] + 0.09
    ax.set_xlim(-0.03, right + 0.02)
    ax.set_ylim(-0.19, 0.1)

    for y in (wall, -wall):  # the pipe wall
        ax.plot([-0.03, right + 0.02], [y, y], color="0.4", lw=2)
        ax.fill_between([-0.03, right + 0.02], y, y + 0.008 * np.sign(y), color="0.85", lw=0)
    ax.text(right + 0.015, wall + 0.011, "pipe wall", ha="right", fontsize=8, color="0.3")

    _module(ax, a[0] - 0.022, 0.1, 0.1, REAR, "module 1 (rear)\nmass m1", wall)
    _module(ax, c[0] + 0.035, 0.08, 0.1, FRONT, "module 2 (front)\nmass m2", wall)

    # crank AB and rod BC
    ax.plot(*zip(a, b), color=CRANK, lw=4, solid_capstyle="round", zorder=3)
    ax.plot(*zip(b, c), color=ROD, lw=3, solid_capstyle="round", zorder=3)
    for point, name, offset in ((a, "A", (-0.012, -0.014)), (b, "B", (-0.004, 0.009)), (c, "C", (0.006, -0.014))):
        ax.add_patch(Circle(point, 0.0035, fc="white", ec="black", lw=1.2, zorder=4))
        ax.text(point[0] + offset[0], point[1] + offset[1], name, fontsize=11, fontweight="bold", zorder=5)
    mid_ab, mid_bc = (a + b) / 2, (b + c) / 2
    ax.text(mid_ab[0] - 0.008, mid_ab[1] + 0.004, "r", fontsize=11, color=CRANK, fontweight="bold", ha="right")
    ax.text(mid_ab[0] - 0.014, mid_ab[1] - 0.008, "crank", fontsize=8, color=CRANK, ha="right")
    ax.text(mid_bc[0] + 0.004, mid_bc[1] + 0.006, "L  connecting rod", fontsize=10, color=ROD)

    # phi from the +x axis, counter-clockwise; the motor torque M turns the crank the same way
    ax.plot([a[0], a[0] + 0.8 * r], [0, 0], color="0.5", lw=0.8, ls="--")
    ax.add_patch(Arc(a, 0.9 * r, 0.9 * r, theta1=0, theta2=math.degrees(phi), color="black", lw=1))
    ax.text(a[0] + 0.5 * r * math.cos(phi / 2) + 0.003, 0.5 * r * math.sin(phi / 2) - 0.003, "phi", fontsize=10)
    ax.add_patch(Arc(a, 0.45 * r, 0.45 * r, theta1=200, theta2=330, color="tab:green", lw=1.3))
    _arrow(ax, (a[0] + 0.225 * r * math.cos(math.radians(322)), 0.225 * r * math.sin(math.radians(322))),
           (a[0] + 0.225 * r * math.cos(math.radians(335)), 0.225 * r * math.sin(math.radians(335))),
           colour="tab:green")
    ax.text(a[0] - 0.026, -0.013, "M", color="tab:green", fontsize=10, fontweight="bold")

    # the gap S and the positions x1, x2 from the origin O
    y_s, y_x = -0.118, -0.15
    _arrow(ax, (a[0], y_s), (c[0], y_s), style="<|-|>")
    ax.text((a[0] + c[0]) / 2, y_s + 0.004, "S = x2 - x1", ha="center", fontsize=9)
    for x in (a[0], c[0]):
        ax.plot([x, x], [-0.004, y_s - 0.003], color="0.5", lw=0.6, ls=":")
    ax.plot([0, 0], [y_x - 0.02, y_x + 0.01], color="black", lw=1)
    ax.text(-0.008, y_x - 0.03, "O", fontsize=10, fontweight="bold")
    _arrow(ax, (0, y_x), (a[0], y_x))
    ax.text(a[0] / 2, y_x + 0.004, "x1 (A)", ha="center", fontsize=9)
    _arrow(ax, (0, y_x - 0.018), (c[0], y_x - 0.018))
    ax.text(c[0] * 0.6, y_x - 0.014, "x2 (C)", ha="center", fontsize=9)
    _arrow(ax, (right - 0.06, y_x - 0.018), (right + 0.01, y_x - 0.018), colour="0.3")
    ax.text(right - 0.025, y_x - 0.012, "+x (forward)", ha="center", fontsize=9, color="0.3")

    # resistances and clutches
    for x, name in ((a[0] - 0.03, "F_r1"), (c[0] + 0.045, "F_r2")):
        _arrow(ax, (x + 0.015, 0.03), (x - 0.015, 0.03), colour="tab:purple")
        ax.text(x, 0.036, name, fontsize=9, color="tab:purple", ha="center")
    ax.text(0.5 * (a[0] + c[0]) + 0.02, -wall - 0.02,
            "wheels on both walls, each with a one-way clutch: a module may move forward (+x), never back",
            ha="center", va="center", fontsize=8.5, color="0.2")
    ax.set_title(f"The robot (to scale for r = {p.r:g} m, L = {p.L:g} m; drawn at phi = {math.degrees(phi):.0f} deg). "
                 "phi = 0: crank points at C, S = L + r", fontsize=10)
    return fig


def write_mechanism_diagram(path: str | Path, params: RobotParams | None = None, dpi: int = 100) -> Path:
    """Save the diagram as PNG at ``path``."""
    path = Path(path)
    figure_mechanism(params).savefig(path, dpi=dpi)
    return path


if __name__ == "__main__":  # pragma: no cover
    import argparse

    parser = argparse.ArgumentParser(prog="python -m ipir_mujoco.report.diagram",
                                     description="Draw the mechanism (the paper's case) as a PNG.")
    parser.add_argument("path", nargs="?", default="mechanism.png", help="the PNG to write (default mechanism.png)")
    write_mechanism_diagram(parser.parse_args().path)
