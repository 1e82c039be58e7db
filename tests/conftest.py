"""Test-suite settings.

Property-based tests run derandomized by default, so CI is repeatable: the
same examples every run. To explore new random examples (as done when the
one-way-clutch solver was developed), run with HYPOTHESIS_PROFILE=explore.
"""

import os

from hypothesis import settings

settings.register_profile("repeatable", derandomize=True, deadline=None)
settings.register_profile("explore", derandomize=False, deadline=None, max_examples=300)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


def pytest_sessionstart(session):
    """Compile the analytic kernels (numba, where installed) before any test: the first compilation on a
    machine takes about 15 s and the command line then says so on stderr, which the command-line tests
    read; every later process loads the cached code."""
    from ipir_mujoco.analytic import RobotParams, simulate

    for geometry, clutch, params in (("approx", "kinematic", RobotParams()), ("exact", "kinematic", RobotParams()),
                                     ("exact", "unilateral", RobotParams()),
                                     ("exact", "unilateral", RobotParams(clutch_stiffness=1e5))):
        simulate(params, geometry, clutch, 0.02, dt_out=1e-3)
