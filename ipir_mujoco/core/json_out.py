"""JSON as every run and study writes it: no infinity or nan (strict readers read it), written through a
temporary file renamed into place. :mod:`.results` re-exports every name here."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np


def json_ready(data: Any) -> Any:
    """``data`` with every number that is not finite (inf, -inf, nan; Python or numpy floats) replaced by None, in
    nested dicts, lists and tuples: JSON has no infinity, and every figure a run or a study writes is then
    readable by strict JSON readers. What null means for each summary key that can be unbounded is in
    docs/cli.md (``side_use1``, ``side_use2``: unbounded, a side load with no grip to hold it); elsewhere it is
    "no such figure" (tests/test_json_summaries.py holds which keys of every engine's summary may be non-finite)."""
    if isinstance(data, dict):
        return {key: json_ready(value) for key, value in data.items()}
    if isinstance(data, (list, tuple)):
        return [json_ready(value) for value in data]
    if isinstance(data, (float, np.floating)) and not math.isfinite(data):
        return None
    return data


def json_text(data: Any, indent: int | None = None) -> str:
    """``data`` as JSON text (:func:`json_ready`: no inf or nan), as ``simulate --json`` prints it and
    :func:`write_json` writes it."""
    return json.dumps(json_ready(data), indent=indent, allow_nan=False)


def write_json(path: str | Path, data: dict[str, Any]) -> None:
    """Write ``data`` as indented JSON (:func:`json_text`: a number that is not finite is null), through a
    temporary file renamed into place: a failed write (a full disk) leaves the earlier file, or none, never a cut
    one."""
    import os

    text = json_text(data, indent=2) + "\n"
    path = Path(path)
    staged = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")  # umask permissions (mkstemp: 0600)
    try:
        staged.write_text(text, encoding="utf-8")
        os.replace(staged, path)
    except BaseException:
        if os.path.exists(staged):
            os.unlink(staged)
        raise
