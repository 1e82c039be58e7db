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
# (MuJoCo rung, the equations of the same mechanism)
CROSS_CHECKS = (("MuJoCo, paper's rule", "with rod mass"), ("MuJoCo ratchet", "one-way clutches"))
