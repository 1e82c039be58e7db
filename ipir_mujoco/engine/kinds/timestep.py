"""The timestep a MuJoCo run needs, chosen from the motion it will meet.

MuJoCo's first-order step creates energy on the rotating linkage: over a run
the audit's residual grows like (omega dt)^3 times the number of revolutions
(the law ``python -m ipir_mujoco.studies.convergence`` measures with the
ratchet and the locks). So the step is chosen from two bounds known before the
run, the crank speed ``omega_b`` and the revolutions ``N_b``, such that the
predicted residual ratio

    C (omega_b dt)^3 N_b

is half the accuracy monitor's tolerance (1e-3), with C fitted to the measured
residuals against these same bounds (:data:`RESIDUAL_CONSTANT`, the largest of
the fits per clutch: the locks' engagements add their own error). The step
never exceeds :data:`DT_MAX_CLUTCH` (1e-4 s, the default proven at the paper's
1 s case; 5e-5 s for the locks) and is a whole fraction of the output
interval. Further limits:

- a very light rod: MuJoCo's soft loop leaks (1 - d) of the rod end's free
  acceleration, which grows as the module-to-rod mass ratio; with the
  impedance d = 0.9999 the error it costs in revolutions grows with that ratio
  and falls as dt^2; at 1e-4 s it stays a small part of the 0.1 % target up to
  the ratio :data:`LEAK_RATIO`, so above it the step shrinks as
  sqrt(LEAK_RATIO / ratio);
- a crank servo: 0.2 / max(sqrt(kp / J_A), kv / J_A), a tenth of the explicit
  stability limit of its stiffness and damping;
- the speed controller (drive = servo): dt <= 1 / control_rate, at least one
  step per tick (ticks then fall on steps where the step divides the period);
- compliant clutches: MuJoCo steps a spring explicitly, so its period must be
  resolved: dt <= CLUTCH_SHARE / omega_c with omega_c = sqrt(k / min(m1, m2)),
  an upper bound of every clutch frequency (the robot's kinetic energy is at
  least 1/2 m1 v1^2 + 1/2 m2 v2^2, so the Rayleigh quotient of the springs,
  k (v1^2 + v2^2) / (v^T M v), is at most k / min(m1, m2)). CLUTCH_SHARE = 0.1
  (63 steps per period 2 pi / omega_c): an impact's peak force then comes out
  within (omega dt)^2 / 4 = 2.5e-3 of its converged value by the step's own
  error bound (entering the spring between two steps and sampling its
  turning point, each up to (omega dt)^2 / 8); tests/test_mujoco_compliant.py
  holds the impacts of the paper's start and the default motor's cruise to it
  against the analytic clutch, while revolutions and travel are set by the
  speed rule above;
- compliant clutches on finite grip: the spring also acts on the skidding
  carriage (:mod:`.grip_model`), an inertia m_c = COMPLIANT_CARRIAGE_SHARE m_i
  the model adds (the analytic anchor has none), whose mode is
  omega_s = sqrt(k (1 / min(m1, m2) + 1 / min(m_c1, m_c2))), about 32 omega_c:
  dt <= CARRIAGE_STEP_SHARE / omega_s. CARRIAGE_STEP_SHARE = 0.3 (21 steps per
  period): 6.7 times inside the explicit spring's stability limit
  (omega_s dt < 2; beyond it a skid runs 3.6 times too long, mjcf/README.md),
  and the mode decides only how far the clutch force overshoots G_i while the
  carriage slides (its inertia force), within the peak's stated bound
  (omega_s dt)^2 / 4; resolving it as finely as the module's own mode (0.1)
  costs several times the run's time for nothing the figures show
  (``python bench/carriage_step.py`` measures both rules against the analytic
  model; mjcf/README.md quotes it).

Bounds on the crank: for a constant torque M, the energy the drive put in
bounds the crank's kinetic energy, J_A omega^2 / 2 <= KE(0) + |M| (phi - phi0),
which integrates to omega <= omega_start + |M| t / J_A and
phi - phi0 <= omega_start t + |M| t^2 / (2 J_A), with omega_start =
sqrt(2 KE(0) / J_A) and KE(0) bounded with every mass moving at the crank pin's
largest slider speed. For the DC motor the crank cannot run faster than
omega_noload on its own (above it the motor brakes): omega_b =
max(omega_noload, omega_start). Gravity downhill is not in these bounds; the
accuracy monitor catches what they miss and the engine then halves the step.
"""

from __future__ import annotations

import math
from dataclasses import replace

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams

from ..builders.grip_model import COMPLIANT_CARRIAGE_SHARE, carriage_share
from ..builders.model import SolverSettings
from ..loop.monitor import RESIDUAL_TOL

DT_MAX = 1e-4  # s: the default proven at the paper's 1 s case (mjcf/README.md)
# the locks with the paper's rule stop a module within a step at every engagement: at the paper's 1 s case
# their energy residual crosses the monitor's tolerance at 1e-4 s and stays inside it at 5e-5 s
# (tests/test_mujoco_accuracy.py holds both)
DT_MAX_CLUTCH = {"ratchet": DT_MAX, "lock": 5e-5, "none": DT_MAX}
DT_MIN = 1e-6  # s: a run needing less is refused (over a million steps per simulated second)
TARGET = 0.5 * RESIDUAL_TOL  # predicted residual ratio to aim at: half the monitor's tolerance
RESIDUAL_CONSTANT = {"ratchet": 0.36, "lock": 2.4, "none": 0.36}  # C of the law above, per clutch
LEAK_RATIO = 3e4  # module-to-rod mass ratio from which a light rod shortens the step
SERVO_SHARE = 0.2  # of 1 / (servo rate)
CLUTCH_SHARE = 0.1  # of 1 / omega_c, the clutch spring's angular frequency on a module (see the module docstring)
CARRIAGE_STEP_SHARE = 0.3  # of 1 / omega_s, the spring's mode on a skidding carriage (finite grip; module docstring)
# the slide model on finite grip (rigid clutches): its grip rows' time constant over its step, in the runs of the rigid
# limit's family (ipir_mujoco.engine.kinds.slides_grip.rigid_limit; mjcf/README.md, "Finite grip: the rigid limit", says why 8)
STEPS_PER_TIME_CONSTANT = 8


def clutch_rate(params: RobotParams) -> float:
    """omega_c = sqrt(k / min(m1, m2)) [rad/s]: no clutch spring oscillates faster on the modules (0 for rigid
    clutches); the analytic model's clutch rate whatever the grip (its anchor has no mass)."""
    if params.clutch_stiffness is None:
        return 0.0
    return math.sqrt(params.clutch_stiffness / min(params.m1, params.m2))


def carriage_rate(params: RobotParams) -> float:
    """omega_s [rad/s], the clutch spring's fastest mode in MuJoCo: with finite grip the spring acts between the
    module and its carriage (:mod:`.grip_model`), whose inertia m_c = COMPLIANT_CARRIAGE_SHARE m_i moves with it
    while the carriage slides, so omega_s = sqrt(k (1 / min(m1, m2) + 1 / min(m_c1, m_c2))) (the Rayleigh
    quotient k (u - w)^2 / (m u^2 + m_c w^2) is at most k (1/m + 1/m_c)); :func:`clutch_rate` on unlimited grip,
    0 for rigid clutches."""
    if params.clutch_stiffness is None or params.grip is None:
        return clutch_rate(params)
    lightest = min(params.m1, params.m2)
    return math.sqrt(params.clutch_stiffness * (1.0 / lightest + 1.0 / (COMPLIANT_CARRIAGE_SHARE * lightest)))


def clutch_step(params: RobotParams) -> float:
    """The longest step [s] that resolves the compliant clutches (module docstring): CLUTCH_SHARE / omega_c, and
    with finite grip CARRIAGE_STEP_SHARE / omega_s too; inf for rigid clutches."""
    if params.clutch_stiffness is None:
        return math.inf
    step = CLUTCH_SHARE / clutch_rate(params)
    if params.grip is not None:
        step = min(step, CARRIAGE_STEP_SHARE / carriage_rate(params))
    return step


def crank_bounds(params: RobotParams, t_end: float) -> tuple[float, float]:
    """(omega_b [rad/s], revolutions bound N_b) over ``t_end`` [s] (see the module docstring)."""
    p = params
    lever = p.r * (1 + p.r / math.sqrt(p.L**2 - p.r**2))  # largest slider speed per crank speed [m/rad]
    rod_turn = p.r / math.sqrt(p.L**2 - p.r**2)  # largest rod angular speed per crank speed
    mass = p.m1 + p.m2 + p.rod_mass
    j_start = p.J_A + mass * lever**2 + p.rod_inertia_value * rod_turn**2
    omega_start = abs(p.omega0) * math.sqrt(j_start / p.J_A)
    if p.drive in ("motor", "servo"):  # the servo's torque stays in the motor's band (|u| <= 1)
        omega_b = max(p.omega_noload, omega_start)
        return omega_b, omega_b * t_end / (2 * math.pi)
    omega_b = omega_start + abs(p.M) * t_end / p.J_A
    return omega_b, (omega_start * t_end + abs(p.M) * t_end**2 / (2 * p.J_A)) / (2 * math.pi)


def _too_small(limit: str, needed: float, params: RobotParams, t_end: float, omega_b: float, servo) -> str:
    """The one-line refusal of a run whose ``limit`` (a key of choose_settings' limits) needs a timestep
    ``needed`` [s] below DT_MIN: it names that limit, its value and what to change."""
    below = f"MuJoCo would need a timestep of {needed:.2g} s"
    allowed = f"allowed: runs needing a timestep >= {DT_MIN:g} s"
    if limit == "clutch_s":
        rule = f"{CLUTCH_SHARE:g} sqrt(min(m1, m2) / k)"
        if params.grip is not None:
            rule += (f", and {CARRIAGE_STEP_SHARE:g} / sqrt(k (1/m + 1/m_c)) on the skidding carriage, "
                     f"m_c = {COMPLIANT_CARRIAGE_SHARE:g} m")
        return (f"clutch_stiffness={params.clutch_stiffness:g} N/m: {below} to resolve the clutch spring "
                f"({rule}); {allowed} (a stiffness up to {params.clutch_stiffness * (needed / DT_MIN) ** 2:.3g} "
                "N/m here, or give the timestep yourself)")
    if limit == "rod_mass_s":
        ratio = max(params.m1, params.m2) / params.rod_mass
        return (f"rod_mass={params.rod_mass:g} kg: the module-to-rod mass ratio {ratio:.3g} makes MuJoCo's soft "
                f"loop leak; {below}; {allowed} (a rod_mass of at least "
                f"{max(params.m1, params.m2) / (LEAK_RATIO * (DT_MAX / DT_MIN) ** 2):.3g} kg here, or give the "
                "timestep yourself)")
    if limit == "servo_s":
        return (f"crank servo kp={servo.kp:g} N m/rad, kv={servo.kv:g} N m s/rad on J_A={params.J_A:g} kg m^2: "
                f"{below} to follow it stably; {allowed} (a softer servo, or give the timestep yourself)")
    return (f"t_end={t_end:g} s: the crank can reach {omega_b:.3g} rad/s and {below}; {allowed} (shorten "
            "t_end, use the motor drive, or give the timestep yourself)")


def choose_settings(params: RobotParams, t_end: float, dt_out: float, servo=None,
                    clutch: str = "ratchet") -> tuple[SolverSettings, dict]:
    """The settings for a run, and why: (SolverSettings, {the bounds and each limit [s]}).

    ``clutch``: the MuJoCo clutch implementation ('ratchet', 'lock', 'none').
    Raises ParameterError if the run would need a step below 1e-6 s.
    """
    omega_b, revolutions = crank_bounds(params, t_end)
    limits = {"default_s": DT_MAX_CLUTCH[clutch]}
    if omega_b > 0 and revolutions > 0:
        constant = RESIDUAL_CONSTANT[clutch]
        limits["speed_s"] = (TARGET / (constant * max(revolutions, 1.0))) ** (1 / 3) / omega_b
    ratio = max(params.m1, params.m2) / params.rod_mass
    if ratio > LEAK_RATIO:
        limits["rod_mass_s"] = DT_MAX * math.sqrt(LEAK_RATIO / ratio)
    if servo is not None:
        rate = max(math.sqrt(servo.kp / params.J_A), servo.kv / params.J_A)
        limits["servo_s"] = SERVO_SHARE / rate
    if params.drive == "servo":
        limits["control_s"] = 1.0 / params.control_rate
    if params.clutch_stiffness is not None:
        limits["clutch_s"] = clutch_step(params)
    needed = min(limits.values())
    if needed < DT_MIN:
        raise ParameterError(_too_small(min(limits, key=limits.get), needed, params, t_end, omega_b, servo))
    steps = math.ceil(dt_out / needed * (1 - 1e-12))
    why = {"omega_bound_rad_s": omega_b, "revolutions_bound": revolutions, **limits}
    return SolverSettings(timestep=dt_out / steps), why


def first_settings(settings: SolverSettings, params: RobotParams) -> SolverSettings:
    """``settings`` (an automatic step h) as the first run of the rigid limit's family on finite grip
    (:mod:`ipir_mujoco.engine.kinds.slides_grip.rigid_limit`): the grip rows' time constant STEPS_PER_TIME_CONSTANT h [s], the
    carriage at its share for ``params``' clutches (:func:`.grip_model.carriage_share`)."""
    return replace(settings, grip_time_constant=STEPS_PER_TIME_CONSTANT * settings.timestep,
                   carriage_share=carriage_share(params))


def halved(settings: SolverSettings) -> SolverSettings:
    """``settings`` at half its step, the grip rows' time constant (where set) with it: the engine's refinement
    of an automatic step the accuracy monitor stopped keeps STEPS_PER_TIME_CONSTANT steps per time constant."""
    tau = settings.grip_time_constant
    return replace(settings, timestep=settings.timestep / 2, grip_time_constant=None if tau is None else tau / 2)


def given_settings(params: RobotParams, settings: SolverSettings, automatic) -> tuple[SolverSettings, str]:
    """A given step's settings on the slide model with finite grip, and the time constant's rule in words: where
    the grip rows' time constant is not given, the automatic run's (``automatic()``: its settings; in seconds,
    so that halving the given step converges to one model), at least two given steps (MuJoCo's floor); the
    carriage at its default share where not given."""
    if settings.grip_time_constant is not None:
        tau, rule = settings.grip_time_constant, "given"
    else:
        try:
            tau, rule = automatic().grip_time_constant, "the automatic run's"
        except ParameterError:  # the automatic step would be below the smallest allowed: the given step's own
            tau, rule = STEPS_PER_TIME_CONSTANT * settings.timestep, "of the given step (no automatic step)"
        if tau < 2 * settings.timestep:
            tau, rule = 2 * settings.timestep, "two given steps (the automatic run's is shorter)"
    share = settings.carriage_share if settings.carriage_share is not None else carriage_share(params)
    return replace(settings, grip_time_constant=tau, carriage_share=share), rule
