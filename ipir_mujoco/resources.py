"""Where the files shipped beside the code are, installed or in a checkout."""

from __future__ import annotations

from importlib import resources
from pathlib import Path


def mjcf_dir() -> Path:
    """The folder of MJCF files: ``ipir_mujoco/mjcf`` when installed, ``mjcf/`` in a source checkout."""
    installed = Path(str(resources.files("ipir_mujoco"))) / "mjcf"
    if installed.is_dir():
        return installed
    checkout = Path(__file__).resolve().parent.parent / "mjcf"
    if checkout.is_dir():
        return checkout
    raise FileNotFoundError(f"no mjcf folder at {installed} or {checkout}: the installation is incomplete")
