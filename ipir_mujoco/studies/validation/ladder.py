"""The model ladder: from the paper's model to MuJoCo's one-way clutches, one idealization removed per rung.

Each rung is a variant of :mod:`ipir_mujoco.registry` on the design, with the rod made massless where the
rung still keeps the paper's massless rod; the change from one rung to the next is what the idealization
the rung removes costs. The validation report runs the ladder for 1 s under the design's drive
(:mod:`.validate`) and under the motor to its periodic steady state (:mod:`.cruise`); :data:`CROSS_CHECKS`
pairs each MuJoCo rung with the equations of the same mechanism.
"""

from __future__ import annotations

from dataclasses import dataclass

from ipir_mujoco.core.params import RobotParams


@dataclass(frozen=True)
class Rung:
    """One step of the ladder: its name, the idealization it removes against the rung before, the variant."""

    name: str
    isolates: str  # the assumption this rung removes, in words
    variant: str  # a name of ipir_mujoco.registry
    massless_rod: bool = False
    accuracy: str | None = None  # MuJoCo's accuracy mode for the rung's run: None (stop, the default) or 'warn'

    def params(self, params: RobotParams) -> RobotParams:
        """The rung's parameter set: ``params``, with the rod's mass and inertia set to zero where it keeps
        the paper's massless rod."""
        return params.replace(rod_mass=0.0, rod_inertia=0.0) if self.massless_rod else params

    def describe(self, params: RobotParams) -> str:
        """What the rung removes, with the design's rod mass where that is what it adds."""
        return f"{self.isolates}: rod of {params.rod_mass:g} kg" if self.name == "with rod mass" else self.isolates


LADDER = (
    Rung("paper model", "nothing: first-order kinematics (L >> r), massless rod, ideal locks", "analytic-approx",
         massless_rod=True),
    Rung("exact geometry", "L >> r: the exact slider-crank", "analytic-exact", massless_rod=True),
    Rung("with rod mass", "the massless rod", "analytic-exact"),
    Rung("MuJoCo, paper's rule", "the equations: MuJoCo physics of the same linkage, locks by the paper's rule",
         "mujoco-lock"),
    Rung("one-way clutches", "ideal locks: clutches that can only push (equations, complementarity)",
         "analytic-unilateral"),
    Rung("MuJoCo ratchet", "the equations again: MuJoCo physics with one-way clutches (joint-limit ratchet)",
         "mujoco-ratchet"),
)
# The validation report's last rung: MuJoCo's robot on wheels in a pipe (``--mujoco-model wheels``), against the
# ratchet before it. Not in the cruise study's ladder (:mod:`.cruise`): the wheeled model costs 8-10 times the
# slide model per simulated second (bench/wheels_cost.py), and a run to the motor's steady state costs seconds where the validation report's 1 s costs half
# a second (unlimited grip: MuJoCo's automatic step).
# Its accuracy monitor warns rather than stops: under the paper's constant torque the crank reaches ~90 rad/s
# and the modules 3.7 m/s, they rock on their wheels' springs and the soft contacts dissipate ~0.3 % of the
# motor's work that the energy audit (the contacts' tangential rows only) cannot attribute, whatever the step
# (mjcf/README.md, "Wheels in contact"); the report shows the figure.
CONTACT = Rung("wheels in contact", "the slides: wheels pressed on the pipe's walls by springs, a ratchet in every "
               "hub, the resistance in the hubs, contact friction (unlimited grip: mu 10)", "mujoco-wheels",
               accuracy="warn")
VALIDATION_LADDER = LADDER + (CONTACT,)
# (MuJoCo rung, the equations of the same mechanism)
CROSS_CHECKS = (("MuJoCo, paper's rule", "with rod mass"), ("MuJoCo ratchet", "one-way clutches"))
