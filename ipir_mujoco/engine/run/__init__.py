"""A run on top of the engine: ``simulate_mujoco``, the run setup (runs, the viewer, ``--save-mjcf``), the checks
between blocks, the skid check, batched runs, the MJCF a run compiles."""
