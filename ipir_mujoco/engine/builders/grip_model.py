"""The wheels' finite grip in the MuJoCo model: a light carriage per module, held on the wall by friction.

A real clutch locks its module's wheels, and locked wheels hold by friction on
the wall, with at most G_i = mu_wall F_ni (``params.grip``). The builder adds,
per module, only where the grip is finite (unlimited grip builds today's model,
element for element):

- a **carriage**: a body on its own slide along the pipe (``rear_skid``,
  ``front_skid``: the wheels' contact on the wall, x = c_i), with Coulomb
  friction G_i (the slide's ``frictionloss``: MuJoCo holds it up to G_i and lets
  it slide at exactly G_i beyond), and an upper limit the engine lowers to the
  running minimum of c_i (:mod:`.grip`): the wheels can roll forward but never
  skid forward, so a grip below F_ri cannot drag the module forward;
- a fixed **tendon** L_i = x_i - c_i (``rear_roll``, ``front_roll``): how far
  the wheels have rolled. The module slides stay absolute (x_i is still one
  qpos, the loop and every position column unchanged). With rigid clutches
  the tendon carries the rolling resistance (``frictionloss`` F_ri, the
  module slide's moved to it: none while the wheels are locked, so none while
  the module skids) and the one-way clutch (a tendon limit whose lower bound
  the engine raises to the running maximum of L_i, as the ratchet on x_i
  without grip). With compliant clutches the clutch actuators act on the
  tendon (their anchor rides on the carriage, so it slides with it), and the
  module keeps its own Coulomb resistance F_ri, as the analytic compliant
  model has it.

So a held module stands while the whole ground force g on it satisfies
-F_ri <= g <= G_i, skids back at G_i beyond, and rolls forward at F_ri: the
limits are MuJoCo's friction rows' bounds, by construction.

The carriage's inertia, :func:`carriage_share` of its module's mass
(CARRIAGE_SHARE = 3e-4 with rigid clutches, COMPLIANT_CARRIAGE_SHARE = 1e-3
with compliant ones, whose spring acts on it and whose step must resolve
that), is its slide's ``armature`` (an inertia without weight, so it adds no load in a riser and no
potential energy; its body has the nominal BODY_MASS MuJoCo requires of a
moving body). It moves only while its module skids (with it, the clutch
holding), where it adds its inertia to the module's: a relative bias of at
most that share on a skid. MuJoCo scales a row's softness with the
inverse inertia it sees at qpos0 (``dof_invweight0``, ``tendon_invweight0``),
which for a carriage row is the carriage's, 1 / share times its
module's: the held module would creep back 1e3-1e5 times faster than a module
on its resistance today. The grip acts on the module through the carriage, so
:func:`scale_grip_rows` gives the carriage's and the tendon's rows the
module slide's own inverse weight: every row then leaks as today's module
rows do. ``mjcf/README.md`` has the measurements behind both numbers.
"""

from __future__ import annotations

import mujoco

from ipir_mujoco.core.params import RobotParams

from . import RANGE_FAR  # m: a bound that never acts (the other side of each one-way limit)

CARRIAGES = ("rear_carriage", "front_carriage")  # bodies
SKIDS = ("rear_skid", "front_skid")  # the carriages' slides: c_i
ROLLS = ("rear_roll", "front_roll")  # tendons L_i = x_i - c_i
# carriage inertia over its module's mass: rigid clutches (a skid's bias of about 0.85 of it). Lighter let the
# one-way limits give: at 1e-4 a 40 deg design's limits gave 3.3e-3 m at 1e-4 s (1.2e-10 m at 3e-4 and 1e-3);
# the solver's rare unconverged steps, ~2e-4 N for one step, were as frequent at 1e-3, 1e-4 and 1e-5
CARRIAGE_SHARE = 3e-4
COMPLIANT_CARRIAGE_SHARE = 1e-3  # compliant clutches: the spring on it sets the step (timestep.carriage_rate)
BODY_MASS = 1e-12  # kg, inertia 1e-12 kg m^2: the carriage body's own (MuJoCo needs > 1e-15 on a moving body)
MARGIN = 1e-9  # m: the one-way limits' margin, as the ratchet's (clutches.Ratchet)


def carriage_share(params: RobotParams) -> float:
    """The carriage's inertia over its module's mass [-] for ``params``' clutches (module docstring)."""
    return CARRIAGE_SHARE if params.clutch_stiffness is None else COMPLIANT_CARRIAGE_SHARE


def write_grip(spec: mujoco.MjSpec, params: RobotParams, solref: list, solimp: list, slides: tuple[str, str],
               clutch_actuators: tuple[str, str], share: float | None = None) -> None:
    """Add the carriages, their slides and the tendons for ``params.grip`` (finite); see the module docstring.

    ``solref``, ``solimp``: the soft parameters of the carriages' and the rolls' rows (their one-way limits and
    friction); ``slides``: the modules' slide joints, rear first; ``clutch_actuators``: the compliant clutches'
    actuators, moved onto the tendons when ``params.clutch_stiffness`` is finite; ``share``: the carriage's
    inertia over its module's mass (None: :func:`carriage_share`).
    """
    grips = params.grip
    share = carriage_share(params) if share is None else share
    masses = (params.m1, params.m2)
    compliant = params.clutch_stiffness is not None
    resistances = (params.F_r1, params.F_r2)
    for i in (0, 1):
        slide = spec.joint(slides[i])
        body = spec.worldbody.add_body(name=CARRIAGES[i], pos=list(slide.parent.pos))
        body.explicitinertial = True
        body.mass, body.ipos, body.inertia = BODY_MASS, [0, 0, 0], [BODY_MASS] * 3
        skid = body.add_joint(name=SKIDS[i], type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0])
        skid.armature = share * masses[i]
        skid.frictionloss = grips[i]
        skid.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        skid.range = [-RANGE_FAR, RANGE_FAR]  # the engine sets the upper bound before the first step
        skid.margin = MARGIN
        skid.solref_limit, skid.solimp_limit = solref, solimp
        skid.solref_friction, skid.solimp_friction = solref, solimp
        roll = spec.add_tendon(name=ROLLS[i])
        roll.wrap_joint(slides[i], 1.0)
        roll.wrap_joint(SKIDS[i], -1.0)
        roll.solref_limit, roll.solimp_limit = solref, solimp
        roll.solref_friction, roll.solimp_friction = solref, solimp
        if compliant:  # the clutch spring from the carriage; the module keeps its own resistance
            act = spec.actuator(clutch_actuators[i])
            act.trntype, act.target = mujoco.mjtTrn.mjTRN_TENDON, ROLLS[i]
            roll.limited = mujoco.mjtLimited.mjLIMITED_FALSE
            roll.frictionloss = 0.0
        else:  # rolling resistance and the one-way clutch on the wheels' roll
            slide.frictionloss = 0.0
            slide.limited = mujoco.mjtLimited.mjLIMITED_FALSE
            roll.frictionloss = resistances[i]
            roll.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            roll.range = [-RANGE_FAR, RANGE_FAR]  # the engine sets the lower bound before the first step
            roll.margin = MARGIN


def scale_grip_rows(model: mujoco.MjModel, slides: tuple[str, str]) -> None:
    """Give each carriage's slide and each tendon the inverse weight of its module's slide (module
    docstring): the inertia MuJoCo scales their rows' softness with, not the carriage's."""
    for i in (0, 1):
        weight = model.dof_invweight0[model.jnt_dofadr[model.joint(slides[i]).id]]
        model.dof_invweight0[model.jnt_dofadr[model.joint(SKIDS[i]).id]] = weight
        model.tendon_invweight0[model.tendon(ROLLS[i]).id] = weight
