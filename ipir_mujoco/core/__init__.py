"""The vocabulary both models of the robot share, and nothing that computes dynamics.

- :mod:`.params`: the one parameter set (:class:`RobotParams`: meaning, unit, default and
  range of every field), its TOML and ``NAME=VALUE`` readers, and the run-option checks;
- :mod:`.results`: the one result container (:class:`RunResult`: time series, energy audit,
  summary) and the clutch modes (:class:`Mode`);
- :mod:`.errors`: :class:`ParameterError` (bad input, a ``ValueError``) and
  :class:`SimulationError` (a run that cannot go on);
- :mod:`.cycles`: per-revolution figures read from any run's series (steady state, distance per
  revolution, energy per metre, efficiency).

The analytic model (:mod:`ipir_mujoco.analytic`), the MuJoCo model (:mod:`ipir_mujoco.engine`)
and the judge between them (:mod:`ipir_mujoco.studies`) import it; it imports neither model
(numpy only), so that sharing it shares no physics.
"""

from .errors import ParameterError, SimulationError
from .params import PARAMETER_NAMES, RobotParams, load_params, require_params
from .results import COLUMNS, MODE_NAMES, Mode, RunResult

__all__ = ["COLUMNS", "MODE_NAMES", "Mode", "PARAMETER_NAMES", "ParameterError", "RobotParams", "RunResult",
           "SimulationError", "load_params", "require_params"]
