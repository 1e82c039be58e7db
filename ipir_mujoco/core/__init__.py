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

# The names below load on first use (PEP 562): importing one light module of the package (core.errors,
# core.params) does not load numpy with core.results.
_NAMES = {"ParameterError": "errors", "SimulationError": "errors", "PARAMETER_NAMES": "params",
          "RobotParams": "params", "load_params": "params", "require_params": "params", "COLUMNS": "results",
          "MODE_NAMES": "results", "Mode": "results", "RunResult": "results"}

__all__ = ["COLUMNS", "MODE_NAMES", "Mode", "PARAMETER_NAMES", "ParameterError", "RobotParams", "RunResult",
           "SimulationError", "load_params", "require_params"]


from .older_paths import lazy_names as _lazy_names  # noqa: E402

__getattr__, __dir__ = _lazy_names(__name__, _NAMES)
