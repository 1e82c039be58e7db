"""``python -m ipir_mujoco``: the same as the ``ipir-mujoco`` command."""

import sys

from ipir_mujoco.cli import console  # its first statement guards Ctrl-C (one line, exit 130) through every import

sys.exit(console())
