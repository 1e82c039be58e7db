"""Writing output folders so that a failure leaves nothing half-written.

The rule every command follows (docs/cli.md, "Output folders"): ``--out DIR`` may exist; the command writes
its own files into it, replacing earlier copies of those names, and leaves everything else there alone. A name
it writes that is taken by something of another kind (a folder where ``summary.json`` goes, a file where
``figures/`` goes, a link) is refused in one line before any work, and again before anything is moved in.
Files are staged in ``.DIR-partial-PID-*`` beside DIR; one left by a process that was killed (SIGKILL, power
loss) is removed by the next run that writes DIR. A study that streams into DIR (sweep, optimize, sensitivity)
holds it locked while it runs (:func:`study_folder`): a second run on the same folder, resumed or not, is
refused in one line rather than running every design again beside the first.
"""

from __future__ import annotations

import contextlib
import os
import re
import time
from pathlib import Path
from typing import Iterable, Iterator

from ipir_mujoco.core.errors import ParameterError


def check_output_dir(out: str | Path, option: str = "--out", files: Iterable[str] = (),
                     folders: Iterable[str] = ()) -> Path:
    """Refuse an output path that cannot become a writable folder, before any work is done.

    Checks, in one line each: ``out`` is a folder or does not exist yet; the nearest existing
    folder above it is a folder (not a file, as in ``FILE/sub``); and a file can be created
    there (tried, then removed: permission bits do not tell for root, read-only mounts or ACLs);
    and each of the ``files`` and ``folders`` the command will write there is free or of that kind
    (:func:`check_names`). Nothing is created.
    """
    if not str(out).strip():  # Path('') is '.': an empty --out "$DIR" would write into the current folder
        raise ParameterError(f"{option} {str(out)!r} names no folder; give a folder path")
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
    import tempfile  # here, with shutil below: the command line's parsers load this module (--help)

    try:
        handle, probe = tempfile.mkstemp(prefix=".ipir-write-test-", dir=existing)
        os.close(handle)
        os.unlink(probe)
    except OSError as exc:
        raise ParameterError(f"{option} {str(out)!r}: cannot write in {str(existing)!r} "
                             f"({exc.strerror or exc}); give a writable folder") from None
    if out.is_dir():
        check_names(out, {**{name: False for name in files}, **{name: True for name in folders}}, option)
    return out


def check_names(out: Path, names: dict[str, bool], option: str = "--out") -> None:
    """Each name of ``names`` ({name: is a folder}) in ``out`` is free or of that kind, so that a command
    replaces only its own earlier output; otherwise a one-line ParameterError naming the path."""
    for name, folder in names.items():
        target = out / name
        if not (target.exists() or target.is_symlink()):
            continue
        if target.is_symlink() or target.is_dir() != folder:
            kind = "a link" if target.is_symlink() else ("a folder" if target.is_dir() else "a file")
            raise ParameterError(f"{option} {str(out)!r}: {str(target)!r} is {kind}, where this command writes "
                                 f"its {'folder' if folder else 'file'} {name!r}; move it away or give another "
                                 f"{option} (a command replaces only its own earlier output)")


_PARTIAL = re.compile(r"-partial-(\d+)-")
STALE_LEGACY_S = 24 * 3600.0  # s: a staging folder of the older naming (no process id) this old is stale


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's process: alive
        return True
    return True


def remove_stale_staging(out: Path) -> list[Path]:
    """Remove the ``.OUT-partial-*`` staging folders beside ``out`` whose process is gone (killed while it
    wrote); return what was removed."""
    import shutil

    removed = []
    for candidate in out.parent.glob(f".{out.name}-partial-*"):
        match = _PARTIAL.search(candidate.name[len(out.name) + 1:])
        try:
            stale = (not _alive(int(match.group(1))) if match
                     else time.time() - candidate.stat().st_mtime > STALE_LEGACY_S)
        except OSError:
            continue
        if stale and candidate.is_dir() and not candidate.is_symlink():
            shutil.rmtree(candidate, ignore_errors=True)
            removed.append(candidate)
    return removed


@contextlib.contextmanager
def staged_output(out: str | Path) -> Iterator[Path]:
    """Yield a staging folder; on success move its contents into ``out``.

    Files are written beside ``out`` first (``.OUT-partial-PID-*``) and moved in
    only when everything succeeded and none of their names is taken by
    something of another kind; on an exception the staging folder is removed
    and ``out`` is left as it was. Staging folders of killed runs are removed
    first (:func:`remove_stale_staging`).
    """
    import shutil
    import tempfile

    out = check_output_dir(out).resolve()
    out.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_staging(out)
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}-partial-{os.getpid()}-", dir=out.parent))
    try:
        yield staging
        out.mkdir(exist_ok=True)
        items = sorted(staging.iterdir())
        check_names(out, {item.name: item.is_dir() for item in items})  # all or nothing
        for item in items:
            target = out / item.name
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
            item.replace(target)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


class FolderLock:
    """An exclusive lock on the folder ``out`` (``fcntl.flock`` on the folder itself: no file is left in it),
    held until :meth:`release` (or the object's end, or the process's); a folder another process holds is
    a one-line ParameterError naming it. Where the file system has no locks (some network mounts) or the
    platform no fcntl, nothing is locked."""

    def __init__(self, out: Path, option: str = "--out"):
        self.fd: int | None = None
        try:
            import fcntl
        except ImportError:  # pragma: no cover (Windows)
            return
        fd = os.open(out, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise ParameterError(f"{option} {str(out)!r} is in use by another run (a study writing there now); "
                                 f"wait for it to end, or give another {option}") from None
        except OSError:  # no locks on this file system
            os.close(fd)
            return
        self.fd = fd

    def release(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def __del__(self):
        self.release()


@contextlib.contextmanager
def study_folder(out: str | Path, option: str = "--out") -> Iterator[Path]:
    """The results folder of a study that streams into it: created if need be and locked for the block
    (:class:`FolderLock`); a ParameterError inside the block (a resume file refused before any design) leaves
    no folder this call created."""
    out = Path(out)
    created = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    lock = FolderLock(out, option)
    try:
        yield out
    except ParameterError:
        if created:
            with contextlib.suppress(OSError):
                out.rmdir()  # only if empty
        raise
    finally:
        lock.release()


def write_atomically(path: str | Path, write) -> None:
    """``write(temporary path)``, then the temporary renamed to ``path``: a failure (a full disk) leaves the
    earlier file, or none, never a cut one."""
    path = Path(path)
    staged = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")  # umask permissions (mkstemp: 0600)
    try:
        write(staged)
        os.replace(staged, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(staged)
        raise
