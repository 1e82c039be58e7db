"""What every scalar kernel reads: the layout of a model's constants array ``p`` and the drive's torque.

The robot's constants come first in every kernel model's ``p`` (:func:`.kernels.pack`, the ``P_*`` indices);
each model appends its own after them (:mod:`.kernels`, :mod:`.route_kernels`). Kept apart from :mod:`.kernels`
so that the route's kernels, which :mod:`.kernels` dispatches to, read the same layout without an import cycle.
Units: rad, rad/s, m, kg, N, N m.
"""

from __future__ import annotations

import numpy as np

from .accel import jit

(P_M1, P_M2, P_R, P_L, P_JA, P_FR1, P_FR2, P_M, P_ROD_M, P_ROD_I, P_EXACT, P_ROD, P_MOTOR, P_MSTALL, P_WNL,
 P_AG, P_U) = range(17)
TINY = float(np.finfo(float).tiny)  # what a quiet guard reads at least (see unilateral_run.events)


@jit
def drive_torque(p, omega):
    """The drive's torque [N m] at crank speed omega (:func:`.forces.drive_torque`; u = p[P_U])."""
    if p[P_MOTOR] != 0.0:
        return p[P_MSTALL] * (p[P_U] - omega / p[P_WNL])
    return p[P_M]
