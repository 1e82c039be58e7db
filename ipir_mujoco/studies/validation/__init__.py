"""The validation job: the model ladder at 1 s (validate) and to steady state (cruise), the paper's reported
figures, the L/r study and MuJoCo's convergence.

``ipir-mujoco validate`` (the command line's, as it writes the report) runs the ladder here and every study's
section of the report; the cruise study has no command of its own, only its section, declared here.
"""

from ..contract import Declaration, Section

STUDY = Declaration(
    "cruise", "every rung of the model ladder under the default motor, run to its periodic steady state",
    sections=(Section("cruise", "Under a real motor", "cruise_section", 20),))
