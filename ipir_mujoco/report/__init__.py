"""Figures and documents: the validation report, its sections, the studies' figures.

The paper's figures of any run, once ``report/plots.py``, are the result container's own now
(:mod:`ipir_mujoco.core.figures`, which :meth:`ipir_mujoco.core.results.RunResult.plot` draws); their older path
``ipir_mujoco.report.plots`` is the very module.
"""

from ipir_mujoco.core.older_paths import keep_older_paths

keep_older_paths({f"{__name__}.plots": "ipir_mujoco.core.figures"})
