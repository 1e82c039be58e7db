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

from ..studies.comparison.measured import UNITS


def estimate_text(value: float, interval, unit: str) -> str:
    """'1.3010 N [1.2996, 1.3025]': a fitted value and its interval to the decimals that give the interval's
    half-width two significant digits, the same for every number of one estimate, with its unit."""
    lo, hi = interval
    suffix = f" {unit}" if unit and unit != "-" else ""
    half = 0.5 * (hi - lo) if lo is not None and hi is not None else float("nan")
    if not (np.isfinite(half) and half > 0):
        return f"{value:.4g}{suffix}"
    decimals = max(0, 1 - int(np.floor(np.log10(half))))
    return f"{value:.{decimals}f}{suffix} [{lo:.{decimals}f}, {hi:.{decimals}f}]"


def plot_calibration(path: str | Path, result: dict, measured) -> Path:
    calibration_figure(result, measured).savefig(path, dpi=110)
    return Path(path)


def calibration_figure(result: dict, measured) -> Figure:
    """Each measured column with the fitted run over it (left) and its residuals in noise units (right); the
    fitted values with their intervals and units in the title (module docstring)."""
    from ipir_mujoco.core.params import parameter_units
    from ipir_mujoco.registry import variant

    from ..labels import series_label

    columns = list(measured.columns)
    fig = Figure(figsize=(11, 1.3 + 2.6 * len(columns)), layout="constrained")
    FigureCanvasAgg(fig)
    t = measured.t
    engine = variant(result["engine"]).label
    for k, c in enumerate(columns):
        ax = fig.add_subplot(len(columns), 2, 2 * k + 1)
        ax.plot(t, measured.columns[c], ".", markersize=3, color="#7f7f7f", label="measured")
        ax.plot(t, result["model"][c], "-", color="#d62728", linewidth=1.3, label=f"fitted ({engine})")
        ax.set_ylabel(series_label(c))
        ax.grid(True, alpha=0.3)
        if k == len(columns) - 1:
            ax.set_xlabel("time t [s]")
        res = fig.add_subplot(len(columns), 2, 2 * k + 2)
        r = np.asarray(result["residuals"][c])
        res.axhspan(-2, 2, color="#2ca02c", alpha=0.2, linewidth=0,
                    label="+-2: where a fit to noise alone keeps 95 % of its points")
        res.plot(t, r, ".", markersize=3, color="#1f77b4", label="(model - measured) / noise")
        res.axhline(0, color="black", linewidth=0.8, label="zero residual")
        res.set_ylabel(f"{c}: residual / noise [-]")
        res.set_title(f"noise {result['noise'][c]:.3g} {UNITS[c]}, residual RMS {result['residual_rms'][c]:.3g} "
                      f"{UNITS[c]}", fontsize=9)
        res.grid(True, alpha=0.3)
        if k == len(columns) - 1:
            res.set_xlabel("time t [s]")
    handles = fig.axes[0].get_legend_handles_labels()[0] + fig.axes[1].get_legend_handles_labels()[0]
    fig.legend(handles=handles, loc="outside lower center", ncols=3, fontsize=8)
    fitted = ", ".join(f"{n} = {estimate_text(e['value'], e['interval'], parameter_units(n))}"
                       for n, e in result["estimates"].items())
    weak = result["not_identifiable"]
    fig.suptitle(f"Calibration to {Path(result['data']).name}: {fitted} (95 % intervals)"
                 + (f"\nnot identifiable from these data: {', '.join(weak)}" if weak else ""), fontsize=10)
    return fig
