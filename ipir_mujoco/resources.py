"""Where the files shipped beside the code are, installed or in a checkout.

The wheel installs the repository's ``mjcf/`` as ``ipir_mujoco/mjcf`` (the MJCF
template and its README, the model's evidence) and ``docs/`` as
``ipir_mujoco/docs`` (the user documentation: cli.md, model.md, citing.md), so
a user with only the installed package can open every document the program's
output names (:func:`shipped`).
"""

from __future__ import annotations

from pathlib import Path

FOLDERS = ("mjcf", "docs")  # the repository folders installed inside the package


def _folder(name: str) -> Path:
    """``ipir_mujoco/NAME`` when installed, the checkout's ``NAME/`` otherwise (the package's own folder on disk, as
    importlib.resources gives it for a package of files, without loading importlib.resources: tempfile, shutil and
    random with it, a few hundredths of a second of every command's start)."""
    installed = Path(__file__).resolve().parent / name
    if installed.is_dir():
        return installed
    checkout = Path(__file__).resolve().parent.parent / name
    if checkout.is_dir():
        return checkout
    raise FileNotFoundError(f"no {name} folder at {installed} or {checkout}: the installation is incomplete")


def mjcf_dir() -> Path:
    """The folder of MJCF files: ``ipir_mujoco/mjcf`` when installed, ``mjcf/`` in a source checkout."""
    return _folder("mjcf")


def docs_dir() -> Path:
    """The user documentation: ``ipir_mujoco/docs`` when installed, ``docs/`` in a source checkout."""
    return _folder("docs")


def shipped(name: str) -> str:
    """Where the document ``name`` (as the repository names it, e.g. 'docs/model.md') is on this machine, as
    text; the name itself if the installation lacks it (the output still says what to look for)."""
    folder, _, rest = name.partition("/")
    if folder not in FOLDERS or not rest:
        raise ValueError(f"{name!r} is not in a folder the package ships ({', '.join(FOLDERS)})")
    try:
        path = _folder(folder) / rest
    except FileNotFoundError:
        return name
    return str(path) if path.is_file() else name
