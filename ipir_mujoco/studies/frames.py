"""A study's results as one pandas DataFrame, for notebooks: ``read_sweep(folder)``.

pandas is optional (``pip install pandas``); a ParameterError says so where it is missing.
"""

from __future__ import annotations

from pathlib import Path

from ipir_mujoco.core.checks import check_path
from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import parameter_units

from .sweep_metrics import UNITS


def read_sweep(folder: str | Path):
    """``folder``'s results.csv (a sweep's ``--out``) as a DataFrame, a row per design (columns as in
    docs/cli.md: ``design_id``, the varied parameters, ``ENGINE:METRIC``, ``divergence:ENGINE:METRIC``,
    ``notes``, ``error``; empty cells NaN); ``df.attrs["units"]`` gives each column's unit."""
    path = Path(check_path("folder", folder, "the path of a sweep's --out folder")) / "results.csv"
    try:
        import pandas
    except ImportError:
        raise ParameterError("read_sweep needs pandas: pip install pandas (or 'ipir-mujoco[notebook]')") from None
    if not path.is_file():
        raise ParameterError(f"{str(folder)!r} holds no sweep results (no results.csv); give a sweep's --out folder")
    frame = pandas.read_csv(path)
    units = {}
    for column in frame.columns:
        metric = column.rsplit(":", 1)[-1]
        if column.startswith("divergence:"):
            units[column] = "-"
        elif ":" in column:
            units[column] = UNITS.get(metric, "")
        elif column not in ("design_id", "notes", "error"):
            try:
                units[column] = parameter_units(column)
            except KeyError:
                units[column] = ""
    frame.attrs["units"] = units
    return frame
