"""calibration.png: each measured column with the fitted run over it, and its residuals in noise units.

One row per measured column: left, the measurements (dots) and the fitted model on the measured times (line);
right, (model - measured) / noise against time, with the +-2 band a fit to noise alone keeps 95 % of its points
in. A drift or a pattern there is what the model (or the fitted parameters) cannot follow.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..studies.measured import UNITS


def plot_calibration(path: str | Path, result: dict, measured) -> Path:
    columns = list(measured.columns)
    fig = Figure(figsize=(11, 0.9 + 2.6 * len(columns)), layout="constrained")
    FigureCanvasAgg(fig)
    t = measured.t
    for k, c in enumerate(columns):
        ax = fig.add_subplot(len(columns), 2, 2 * k + 1)
        ax.plot(t, measured.columns[c], ".", markersize=3, color="#7f7f7f", label="measured")
        ax.plot(t, result["model"][c], "-", color="#d62728", linewidth=1.3, label=f"fitted ({result['engine']})")
        ax.set_ylabel(f"{c} [{UNITS[c]}]")
        ax.grid(True, alpha=0.3)
        if k == 0:
            ax.legend(fontsize=8, loc="best")
        if k == len(columns) - 1:
            ax.set_xlabel("t [s]")
        res = fig.add_subplot(len(columns), 2, 2 * k + 2)
        r = np.asarray(result["residuals"][c])
        res.axhspan(-2, 2, color="#2ca02c", alpha=0.12, linewidth=0)
        res.plot(t, r, ".", markersize=3, color="#1f77b4")
        res.axhline(0, color="black", linewidth=0.8)
        res.set_ylabel(f"{c}: residual / noise")
        res.set_title(f"noise {result['noise'][c]:.3g} {UNITS[c]}, residual RMS {result['residual_rms'][c]:.3g} "
                      f"{UNITS[c]}", fontsize=9)
        res.grid(True, alpha=0.3)
        if k == len(columns) - 1:
            res.set_xlabel("t [s]")
    fitted = ", ".join(f"{n} = {e['value']:.5g} [{e['interval'][0]:.5g}, {e['interval'][1]:.5g}]"
                       for n, e in result["estimates"].items())
    weak = result["not_identifiable"]
    fig.suptitle(f"Calibration to {Path(result['data']).name}: {fitted} (95 %)"
                 + (f"\nnot identifiable from these data: {', '.join(weak)}" if weak else ""), fontsize=10)
    fig.savefig(path, dpi=110)
    return Path(path)
