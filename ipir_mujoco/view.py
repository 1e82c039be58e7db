"""``python -m ipir_mujoco.view``: the interactive viewer (:mod:`ipir_mujoco.cli.view`), by its documented name."""

import sys

from .cli.view import ViewedRobot, main

__all__ = ["ViewedRobot", "main"]

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
