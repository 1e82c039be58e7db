"""Writing output folders so that a failure leaves nothing half-written."""

from __future__ import annotations

import contextlib
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from ipir_mujoco.analytic.errors import ParameterError


def check_output_dir(out: str | Path) -> Path:
    """Refuse an output path that cannot become a folder, before any work is done."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out {str(out)!r} exists and is not a folder; give a folder path")
    return out


@contextlib.contextmanager
def staged_output(out: str | Path) -> Iterator[Path]:
    """Yield a staging folder; on success move its contents into ``out``.

    Files are written beside ``out`` first and moved in only when everything
    succeeded; on an exception the staging folder is removed and ``out`` is
    left as it was.
    """
    out = check_output_dir(out).resolve()
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}-partial-", dir=out.parent))
    try:
        yield staging
        out.mkdir(exist_ok=True)
        for item in sorted(staging.iterdir()):
            target = out / item.name
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
            item.replace(target)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
