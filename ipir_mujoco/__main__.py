"""``python -m ipir_mujoco``: the same as the ``ipir-mujoco`` command."""

import sys

from .cli import main

sys.exit(main())
