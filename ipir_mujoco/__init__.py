"""ipir-mujoco: check the published analytic model of a two-module inchworm
in-pipe robot against MuJoCo physics.

The analytic model and the shared parameter set and result container live in
the sibling package :mod:`analytic`; this package holds the MuJoCo side, the
command line, plots and reports.
"""

__version__ = "0.1.0"
