"""``python -m ipir_mujoco``: the same as the ``ipir-mujoco`` command."""

import os
import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C before the command line's own guard is in place: one line, no traceback
    os.write(2, b"ipir-mujoco: interrupted\n")
    sys.exit(130)

sys.exit(main())
