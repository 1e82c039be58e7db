"""Reading the text and TOML files users give (configs, study files, samples): one line saying why a file
cannot be read, never a traceback."""

from __future__ import annotations

import os
import tomllib
from pathlib import Path
from typing import Any

from .errors import ParameterError, ParameterTypeError

MAX_TEXT_BYTES = 100_000_000  # bytes of a config, study or samples file: far past any real one, and a bound
# on what /dev/zero or a mistyped multi-GB file would make the command read into memory


def read_text_file(path: str | Path, what: str, max_bytes: int = MAX_TEXT_BYTES) -> str:
    """A text file's contents as UTF-8, or a ParameterError saying in one line why it cannot be read (also
    for a device or pipe, /dev/zero, and a file past ``max_bytes``, MAX_TEXT_BYTES unless a kind of file has a
    smaller bound; only max_bytes + 1 bytes are ever read). A ``path`` that is not a str or path object (None,
    bytes, a number) is a ParameterTypeError; an empty one names no file."""
    if not isinstance(path, (str, os.PathLike)) or isinstance(os.fspath(path), bytes):
        raise ParameterTypeError(f"{what} path={path!r} ({type(path).__name__}) is not a path; allowed: a str or "
                                 "pathlib.Path naming a file")
    if not str(path).strip():  # Path('') is '.', the current folder
        raise ParameterError(f"{what} {str(path)!r} names no file; give a file")
    path = Path(path)
    try:
        if path.exists() and not path.is_dir() and not path.is_file():
            raise ParameterError(f"{what} {str(path)!r} is not a regular file (a device or pipe); give a file")
        with path.open("rb") as handle:
            data = handle.read(max_bytes + 1)
        if len(data) > max_bytes:
            raise ParameterError(f"{what} {str(path)!r} is larger than {max_bytes / 1e6:g} MB; allowed: a "
                                 "text file of at most that size")
        return data.decode("utf-8")
    except FileNotFoundError:
        raise ParameterError(f"{what} {str(path)!r} does not exist") from None
    except IsADirectoryError:
        raise ParameterError(f"{what} {str(path)!r} is a folder; give a file") from None
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{what} {str(path)!r} is not UTF-8 text (byte {exc.start}); "
                             "save it as UTF-8") from None
    except OSError as exc:
        raise ParameterError(f"{what} {str(path)!r} cannot be read: {exc.strerror}") from None


def read_toml_file(path: str | Path, what: str, max_bytes: int = MAX_TEXT_BYTES) -> dict[str, Any]:
    """A TOML file as a dict, or a ParameterError naming the file and the problem in one line (``max_bytes``:
    :func:`read_text_file`'s)."""
    text = read_text_file(path, what, max_bytes)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{what} {str(path)!r} is not valid TOML: {exc}") from None
    except ValueError as exc:  # an integer past Python's 4300-digit conversion limit
        why = "an integer of more than 4300 digits" if "digits" in str(exc) else " ".join(str(exc).split())[:120]
        raise ParameterError(f"{what} {str(path)!r} holds a value that cannot be read ({why}); allowed: numbers "
                             "within the ranges 'ipir-mujoco params' lists") from None
    except RecursionError:  # arrays or tables nested thousands deep
        raise ParameterError(f"{what} {str(path)!r} nests arrays or tables too deep to read; allowed: the flat "
                             "tables of a config or study file (docs/cli.md)") from None
