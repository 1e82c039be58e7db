"""Writing output folders so that a failure leaves nothing half-written."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from ipir_mujoco.core.errors import ParameterError


def check_output_dir(out: str | Path, option: str = "--out") -> Path:
    """Refuse an output path that cannot become a writable folder, before any work is done.

    Checks, in one line each: ``out`` is a folder or does not exist yet; the nearest existing
    folder above it is a folder (not a file, as in ``FILE/sub``); and a file can be created
    there (tried, then removed: permission bits do not tell for root, read-only mounts or ACLs).
    Nothing is created.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"{option} {str(out)!r} exists and is not a folder; give a folder path")
    existing = out
    while not existing.exists():
        if existing.is_symlink():  # a dangling link: mkdir would fail on it
            raise ParameterError(f"{option} {str(out)!r}: {str(existing)!r} is a broken link")
        existing = existing.parent
    if not existing.is_dir():
        raise ParameterError(f"{option} {str(out)!r}: {str(existing)!r} is a file, not a folder")
    try:
        handle, probe = tempfile.mkstemp(prefix=".ipir-write-test-", dir=existing)
        os.close(handle)
        os.unlink(probe)
    except OSError as exc:
        raise ParameterError(f"{option} {str(out)!r}: cannot write in {str(existing)!r} "
                             f"({exc.strerror or exc}); give a writable folder") from None
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
