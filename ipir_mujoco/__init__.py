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
"""

import os as _os  # loaded with the interpreter: this file imports nothing that takes time (a Ctrl-C while the
# command line starts is caught from its first statement on: ipir_mujoco.interrupts)

__version__ = "0.2.0"

# Installed, the repository's analytic/ and mjcf/ folders are ipir_mujoco/analytic and
# ipir_mujoco/mjcf. In a source checkout run without installing, they sit beside this
# package: let the subpackage import find them there.
_here = _os.path.dirname(_os.path.realpath(__file__))
if (not _os.path.isdir(_os.path.join(_here, "analytic"))
        and _os.path.isfile(_os.path.join(_here, "..", "analytic", "__init__.py"))):
    __path__.append(_os.path.dirname(_here))  # noqa: F821 (a package's own __path__)
