"""What the paper reports for its simulation case, and how precisely.

The authors give their results as figures and rounded words
(``shared/paper/MODEL.md``). Each entry is the reported value, the interval a
faithful reproduction must land in, and why that interval: the reading
precision of the figure it comes from.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ipir_mujoco.analytic.results import RunResult


@dataclass(frozen=True)
class ReportedFigure:
    """One number the paper reports, with the interval that reproduces it."""

    key: str
    label: str
    reported: str  # as the paper words it
    low: float
    high: float
    units: str
    why: str  # where the number comes from and why the interval
    measure: Callable[[RunResult], float]

    def check(self, run: RunResult) -> dict:
        value = float(self.measure(run))
        return {"key": self.key, "label": self.label, "reported": self.reported, "value": value,
                "low": self.low, "high": self.high, "units": self.units, "why": self.why,
                "reproduced": bool(self.low <= value <= self.high)}


def _peak_speed(run: RunResult) -> float:
    return max(run.summary["v1_max"], run.summary["v2_max"])


def _peak_acceleration(run: RunResult) -> float:
    return float(max(np.abs(run.series["a1"]).max(), np.abs(run.series["a2"]).max()))


def _x2_absolute(run: RunResult) -> float:
    # the paper's x2 is the absolute position of C; it starts at S(phi0) ahead of A
    return run.summary["x2_final"] + float(run.series["S"][0])


REPORTED: tuple[ReportedFigure, ...] = (
    ReportedFigure("revolutions", "crank revolutions at 1 s", "about 8.5 (Fig. 2a)", 8.25, 8.75, "rev",
                   "read off Fig. 2a, whose axis counts whole revolutions: good to a quarter turn",
                   lambda run: run.summary["revolutions"]),
    ReportedFigure("x1_final", "module 1 displacement at 1 s", "about 0.9 m (Fig. 3a)", 0.85, 0.95, "m",
                   "quoted to 0.1 m: +-0.05 m", lambda run: run.summary["x1_final"]),
    ReportedFigure("x2_absolute", "module 2 position at 1 s (absolute, starts at L + r)",
                   "about 1.0 m (Fig. 3a)", 0.95, 1.05 + 1e-9, "m",
                   "quoted to 0.1 m: +-0.05 m; the paper plots C's absolute position", _x2_absolute),
    ReportedFigure("peak_speed", "peak module speed", "nearly 4 m/s by t = 1 s (Fig. 3b)", 3.8, 4.2, "m/s",
                   "read off Fig. 3b (1 m/s grid): a fifth of a division", _peak_speed),
    ReportedFigure("first_contraction_end_s", "first minimum of S", "about 0.23 s (Fig. 4)", 0.22, 0.24, "s",
                   "read off Fig. 4 (0.1 s grid): a tenth of a division",
                   lambda run: run.summary["first_contraction_end_s"] or float("nan")),
    ReportedFigure("S_min", "smallest gap S", "L - r = 1.5 dm (Fig. 4)", 0.1495, 0.1505, "m",
                   "read off Fig. 4 in dm: +-0.005 dm", lambda run: float(run.series["S"].min())),
    ReportedFigure("S_max", "largest gap S", "L + r = 2.5 dm (Fig. 4)", 0.2495, 0.2505, "m",
                   "read off Fig. 4 in dm: +-0.005 dm", lambda run: float(run.series["S"].max())),
    ReportedFigure("peak_acceleration", "largest module acceleration", "spikes up to 1000 m/s^2 (Fig. 3c)",
                   500.0, 2000.0, "m/s^2",
                   "a spike's plotted height depends on sampling (MODEL.md note 3): the order of magnitude",
                   _peak_acceleration),
)


def check_paper_figures(run: RunResult) -> list[dict]:
    """Each reported figure against ``run``: value, interval, and whether it lands in it."""
    return [figure.check(run) for figure in REPORTED]
