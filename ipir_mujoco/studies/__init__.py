"""Studies that run the engines and judge them, grouped by what they are (a folder each): the validation job,
comparisons of runs, sweeps, design searches, uncertainty, the idealization atlas, climbing, the mechanism's
parts.

The modules' older paths (``ipir_mujoco.studies.sweep``, ``ipir_mujoco.studies.atlas``, ...: the studies were one
folder) keep working: :func:`ipir_mujoco.core.older_paths.keep_older_paths` imports each as the very module at its
new place.
"""

from ipir_mujoco.core.older_paths import keep_older_paths

# each module's group folder (below studies/), where its older path ``ipir_mujoco.studies.<module>`` points
GROUPS = {
    "validation": ("validate", "ladder", "paper_reference", "cruise", "lr_study", "convergence"),
    "comparison": ("compare", "agreement", "measured", "route_compare"),
    "sweeps": ("sweep", "sweep_space", "sweep_files", "sweep_metrics", "frames"),
    "design": ("design_eval", "optimize", "sensitivity", "calibrate", "design_rules"),
    "uq": ("uncertainty", "uq_dists", "uq_stats"),
    "idealizations": ("atlas", "atlas_space", "atlas_eval", "atlas_adaptive", "atlas_surrogate", "gp"),
    "climb": ("climbing", "climb_limits", "traction"),
    "mechanism": ("clutch_study", "control_study", "bend_study"),
}
keep_older_paths({f"{__name__}.{module}": f"{__name__}.{group}.{module}"
                  for group, modules in GROUPS.items() for module in modules})
