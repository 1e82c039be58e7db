"""ipir-mujoco: check the published analytic model of a two-module inchworm
in-pipe robot against MuJoCo physics.

Layers, bottom up:

- :mod:`ipir_mujoco.core`: what both models share: the parameter set, the result
  container, the errors and the per-revolution figures (numpy only);
- :mod:`ipir_mujoco.analytic`: the analytic model (numpy and scipy; it never
  imports MuJoCo);
- :mod:`ipir_mujoco.engine`: the MuJoCo model of the real linkage and its runs
  (it never imports the analytic model);
- :mod:`ipir_mujoco.studies`: compare, validate, sweeps, convergence;
- :mod:`ipir_mujoco.report`: figures and the validation report;
- :mod:`ipir_mujoco.cli`: the ``ipir-mujoco`` command.

The public Python surface, importable from here::

    from ipir_mujoco import run, RobotParams, RunResult, ParameterError, SimulationError, VARIANTS

    result = run("mujoco-ratchet", RobotParams(drive="motor"), 2.0, dt_out=1e-3)

:func:`run` runs any variant (a name of :data:`VARIANTS`) on a parameter set (:class:`RobotParams`) and
returns a :class:`RunResult`; bad input is a :class:`ParameterError` (a ValueError), a run that cannot go on a
:class:`SimulationError`. Everything else is reachable through the subpackages above.
"""

import os as _os

__version__ = "0.2.0"

# Installed, the repository's analytic/ and mjcf/ folders are ipir_mujoco/analytic and
# ipir_mujoco/mjcf. In a source checkout run without installing, they sit beside this
# package: let the subpackage import find them there.
_here = _os.path.dirname(_os.path.realpath(__file__))
if (not _os.path.isdir(_os.path.join(_here, "analytic"))
        and _os.path.isfile(_os.path.join(_here, "..", "analytic", "__init__.py"))):
    __path__.append(_os.path.dirname(_here))  # noqa: F821 (a package's own __path__)

# The public names load on first use (PEP 562), so that importing the package imports neither numpy nor the
# registry: ``ipir-mujoco --help`` and ``params`` need none of them (the command line's Ctrl-C guard,
# ipir_mujoco.cli, goes in before anything heavy loads).
_PUBLIC = {"ParameterError": "core.errors", "SimulationError": "core.errors", "RobotParams": "core.params",
           "RunResult": "core.results", "VARIANTS": "registry", "run": "registry"}

__all__ = ["VARIANTS", "ParameterError", "RobotParams", "RunResult", "SimulationError", "__version__", "run"]


from .core.older_paths import lazy_names as _lazy_names  # noqa: E402 (after the analytic folder is findable)

__getattr__, __dir__ = _lazy_names(__name__, _PUBLIC)
