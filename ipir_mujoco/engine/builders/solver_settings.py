"""MuJoCo's solver settings for a run: :class:`SolverSettings` (timestep, integrator, the constraint rows'
time constants and impedance), checked on construction, and how they go into a model
(:func:`write_step_options`) and act in it (:func:`implicit_damping`).

Every builder (the slide model, :mod:`.model`, and the wheeled one) writes them the same way;
:mod:`.model` re-exports every name here.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import mujoco

from ipir_mujoco.core.errors import ParameterError

# The integrators the engines allow. Not RK4: the engines read a step's energies, drive torque and
# frictionloss forces from mjData after mj_step, which under RK4 are its last stage's, not the step's, so
# the energy audit would book values the step never had.
INTEGRATORS = {"euler": mujoco.mjtIntegrator.mjINT_EULER, "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
               "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT}
# the integrators that treat an actuator's velocity term (its damping) implicitly, through MuJoCo's D matrix;
# Euler applies it explicitly, at the step's starting velocity
IMPLICIT_INTEGRATORS = (mujoco.mjtIntegrator.mjINT_IMPLICIT, mujoco.mjtIntegrator.mjINT_IMPLICITFAST)


@dataclass(frozen=True)
class SolverSettings:
    """MuJoCo settings (see ``mjcf/README.md`` for the evidence).

    ``timestep`` [s]: 1e-4 is the largest the engine chooses by itself; a run
    given no settings has its step chosen from the motion
    (:func:`ipir_mujoco.engine.kinds.timestep.choose_settings`).
    ``constraint_time_constant`` [s] (default: 2 timesteps) is the solref time
    constant of every constraint: the loop, clutch limits and locks, and the
    resistances' friction rows. ``solimp`` is MuJoCo's impedance triple, by
    default its largest impedance 0.9999 (a soft row leaks 1 - d of the free
    acceleration it resists). ``integrator``: 'implicitfast' (default),
    'implicit' or 'euler' (:data:`INTEGRATORS`); MuJoCo's 'rk4' is refused, as
    the engines' energy and work bookkeeping reads a step's values after it,
    which under RK4 are its last stage's.

    The slide model with finite grip only (:mod:`.grip_model`; other models ignore them):
    ``grip_time_constant`` [s] is the solref time constant of its one-way limits and friction rows (the
    carriages' slides and the wheels' rolls; default: the constraint time constant), and ``carriage_share``
    [-] each carriage's inertia over its module's mass (default: :func:`.grip_model.carriage_share`). Both
    are the regularization the rigid limit is extrapolated from (:mod:`ipir_mujoco.engine.kinds.slides_grip.rigid_limit`).
    Every time constant must be at least two steps: MuJoCo would use two steps in its place (unless its
    ``refsafe`` flag is disabled), so a shorter one is refused rather than silently changed.
    """

    timestep: float = 1e-4
    integrator: str = "implicitfast"
    constraint_time_constant: float | None = None
    solimp: tuple[float, float, float] = (0.9999, 0.9999, 0.001)
    grip_time_constant: float | None = None
    carriage_share: float | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.timestep) and 0 < self.timestep <= 1e-2):
            raise ParameterError(f"timestep={self.timestep} s is out of range; allowed: 0 < timestep <= 0.01 s")
        if self.integrator == "rk4":
            raise ParameterError("integrator='rk4' is not supported: the engine's energy and work bookkeeping reads "
                                 "a step's values after it, which under RK4 are its last stage's; allowed: "
                                 + ", ".join(INTEGRATORS))
        if self.integrator not in INTEGRATORS:
            raise ParameterError(f"integrator={self.integrator!r} is unknown; allowed: {', '.join(INTEGRATORS)}")
        for name, tc in (("constraint_time_constant", self.time_constant), ("grip_time_constant", self.grip_rows)):
            if not (isinstance(tc, (int, float)) and math.isfinite(tc) and tc >= 2 * self.timestep * (1 - 1e-12)):
                raise ParameterError(f"{name}={tc} s is out of range; allowed: >= 2 timesteps "
                                     f"({2 * self.timestep} s), MuJoCo's stability limit")
        share = self.carriage_share
        if share is not None and not (isinstance(share, (int, float)) and math.isfinite(share) and 0 < share <= 0.1):
            raise ParameterError(f"carriage_share={share} is out of range; allowed: 0 < carriage_share <= 0.1")
        d0, d1, width = self.solimp
        if not (0 < d0 <= d1 < 1 and width > 0):
            raise ParameterError(f"solimp={self.solimp} is out of range; allowed: 0 < d0 <= d1 < 1, width > 0")

    @property
    def time_constant(self) -> float:
        return 2 * self.timestep if self.constraint_time_constant is None else self.constraint_time_constant

    @property
    def grip_rows(self) -> float:
        """The finite-grip rows' time constant [s]: ``grip_time_constant``, or the constraint time constant."""
        return self.time_constant if self.grip_time_constant is None else self.grip_time_constant

    def as_dict(self) -> dict:
        """The settings as a run records them; the finite-grip fields only where set (a run without finite grip
        records what it always did)."""
        out = {**asdict(self), "constraint_time_constant": self.time_constant}
        for key in ("grip_time_constant", "carriage_share"):
            if out[key] is None:
                del out[key]
        return out


def implicit_damping(model: mujoco.MjModel) -> bool:
    """Whether the model's integrator applies actuator damping implicitly (with the step's final velocity)."""
    return model.opt.integrator in IMPLICIT_INTEGRATORS


def write_step_options(spec: mujoco.MjSpec, settings: SolverSettings) -> tuple[list[float], list[float]]:
    """Write the timestep and integrator of ``settings`` into ``spec``; return the (solref, solimp) every
    constraint row of the model gets (the slide and the wheeled models alike)."""
    spec.option.timestep = settings.timestep
    spec.option.integrator = INTEGRATORS[settings.integrator]
    return [settings.time_constant, 1.0], [*settings.solimp, 0.5, 2.0]
