"""Compliant one-way clutches in MuJoCo: a spring and a damper from a ratcheting anchor to each module.

The mechanism. Each module i has an anchor on the pipe that ratchets forward
with it and never back: a_i = (running maximum of x_i) - clutch_backlash.
Between the anchor and the module act a spring k [N/m] and a damper c
[N s/m]: the model's clutch actuators (:func:`.model._write_clutches`), each
a position servo on the module's slide whose target (``ctrl``) is the anchor.
So the force MuJoCo computes and applies is, by construction,

    k (a_i - x_i) - c v_i,  clamped by the actuator's force range to >= 0,

i.e. max(0, k d_i - c v_i) with the overlap d_i = a_i - x_i > 0 (the module
behind its anchor), and nothing inside the play (d_i <= 0: the damper is
switched off, below, and the clamp removes the spring's negative part).

The anchor has no mass: it is the actuator's target, raised before every step
to (x_i - backlash) when the module has gone further than ever (a rigid
one-sided link to the module that nothing can push back). It is the running
maximum of the positions at the steps' starts; between two steps a module can
pass that by at most |a_i| dt^2 / 2 (near a turning point), 5e-7 m at
100 m/s^2 and 1e-4 s.

The damper. MuJoCo's affine bias -c v acts wherever the force is not clamped;
the definition applies c only while the module is behind its anchor. So the
controller writes biasprm[2] = -c while d_i > 0 at the step's start and 0
otherwise (inside the play, where a module approaching its anchor fast would
otherwise meet a force c |v| - k |d| before it touches). Where k d - c v <= 0
the force range clamps the force to 0 (the damper would pull), and MuJoCo's
implicit integrators then leave the damping out of the step
(``mjd_actuator_vel`` skips an actuator clamped by its force range), so a
clamped clutch applies exactly nothing.

Energy, per step with the velocities v_{n+1} that move the positions: the
force applied over the step is MuJoCo's ``actuator_force`` f_n plus, for the
implicit integrators, the damping's implicit part -c (v_{n+1} - v_n) (while
unclamped and damped). The clutch spring stores 1/2 k max(d, 0)^2; the damper
dissipates (k max(d_n, 0) - f_applied) v_{n+1} dt per step (c v^2 dt while
engaged, k d v dt while clamped, as the analytic definition). What the run's
energy audit leaves after these is the time discretization (the spring's
stepping included) and the soft constraints.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ipir_mujoco.core.params import RobotParams

from ...loop.controller import NO_REACTIONS, ControllerBase, follow, held_where
from ...loop.native import LayoutError
from .loop_rows import require_friction_power
from ...builders.model import FRONT_CLUTCH, REAR_CLUTCH, SLIDES, dof_address, implicit_damping, qpos_address

CLUTCHES = (REAR_CLUTCH, FRONT_CLUTCH)


def check_transmissions(model: mujoco.MjModel, act: list[int], trn, targets: list[int], names) -> None:
    """ValueError unless each clutch actuator of ``act`` acts through transmission ``trn`` (an mjtTrn) on its
    element of ``targets`` (ids; ``names`` for the message) with gear 1."""
    for u, target, name in zip(act, targets, names):
        if (model.actuator_trntype[u] != int(trn) or model.actuator_trnid[u, 0] != target
                or model.actuator_gear[u, 0] != 1.0):
            raise ValueError(f"clutch actuator {model.actuator(u).name!r} must act on {name!r} with gear 1")


def clutch_actuators(model: mujoco.MjModel, act, params: RobotParams) -> tuple[float, float]:
    """(k [N/m], c [N s/m]) of the compliant clutches' actuators ``act`` (ids), checked to be the spring k =
    clutch_stiffness with the force range [0, ...]; their dampers set as built (a model that has run may hold
    0). ValueError where the model was built from other parameters."""
    k, c = params.clutch_stiffness, params.clutch_damping
    for u in act:
        if not (k is not None and model.actuator_gainprm[u, 0] == k and model.actuator_biasprm[u, 1] == -k
                and model.actuator_forcelimited[u] and model.actuator_forcerange[u, 0] == 0.0):
            raise ValueError("the clutch actuators need the spring k = clutch_stiffness and the force range "
                             "[0, ...]: build the model from these parameters, with a finite clutch_stiffness")
        model.actuator_biasprm[u, 2] = -c
    return k, c


class CompliantClutches(ControllerBase):
    """The controller of the compliant clutches: moves the anchors, switches the dampers, counts their work.

    ``params``: the parameter set the model was built from; its
    ``clutch_backlash`` [m] and ``clutch_damping`` c [N s/m] (the controller
    switches the actuators' damping, so a model that has run holds 0 for a
    clutch that was free) are used, and the stiffness k [N/m] is read from the
    compiled model's clutch actuators and checked against it. Called before every step
    (:meth:`before_step`) and after it (:meth:`after_step`), or the same rules compiled in
    :mod:`.stepper` (held equal bit for bit by its test). ``overlap`` holds
    d_i = a_i - x_i [m] at the last step's start; ``damper_work`` [J] is the
    cumulative work the dampers dissipated; ``excursion`` is 0: a module's
    backward motion is the clutch's physics here, not a constraint's give.
    """

    name = "compliant"
    clutch_model = "compliant"
    deferred = True  # its forces are MuJoCo's at the sample's own state, a step later (the recorder reads them)

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams):
        self.model, self.data = model, data
        self.act = [model.actuator(n).id for n in CLUTCHES]
        self.qpos_adr = [qpos_address(model, n) for n in SLIDES]
        self.dof_adr = [dof_address(model, n) for n in SLIDES]
        self._qpos, self._qvel, self._force = data.qpos, data.qvel, data.actuator_force
        self.attach(model, data, params)
        k, c = clutch_actuators(model, self.act, params)
        self.k, self.c, self.backlash, self.dt = float(k), float(c), params.clutch_backlash, float(model.opt.timestep)
        # the implicit integrators integrate the damping implicitly (MuJoCo's D matrix); Euler does not
        self.implicit = implicit_damping(model)
        self._ctrl, self._biasprm = data.ctrl, model.actuator_biasprm
        self.anchor = [self.coordinate(i) - self.backlash for i in (0, 1)]  # running maximum - backlash
        for u, a in zip(self.act, self.anchor):
            data.ctrl[u] = a
        self._modules = tuple(zip((0, 1), self.act))
        self.damped = [True, True]  # as built: biasprm[2] = -c
        self.overlap = [0.0, 0.0]
        self.v_before = [0.0, 0.0]
        self.tracking = [False, False]  # whether each module was at its running maximum at the last step's start
        self.damper_work = 0.0
        self.before_step()

    # the pieces a compliant clutch on another coordinate replaces (.compliant_grip.CompliantGrip: the roll)
    def attach(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams) -> None:
        """Check that the clutch actuators act on the slides (and set up what else the coordinate needs)."""
        check_transmissions(model, self.act, mujoco.mjtTrn.mjTRN_JOINT, [model.joint(n).id for n in SLIDES], SLIDES)

    def coordinate(self, i: int) -> float:
        """Module ``i``'s coordinate the clutch acts along [m]: its slide x_i."""
        return self._qpos.item(self.qpos_adr[i])

    def speed(self, i: int) -> float:
        """Its rate [m/s]."""
        return self._qvel.item(self.dof_adr[i])

    def after_module(self, i: int) -> None:
        """What else a step's start does for module ``i`` (nothing here)."""

    def before_step(self) -> None:
        """Raise each anchor to (coordinate - backlash) if the module went further; damper on while d > 0."""
        backlash, anchor, overlap = self.backlash, self.anchor, self.overlap
        for i, act in self._modules:  # this runs before every step: plain floats only
            x = self.coordinate(i)
            anchor[i], give = follow(anchor[i], x - backlash)  # the anchor's running maximum
            self.tracking[i] = tracking = give < 0.0
            if tracking:
                self._ctrl[act] = anchor[i]
            d = anchor[i] - x
            overlap[i] = d
            self.v_before[i] = self.speed(i)
            if (d > 0.0) != self.damped[i]:
                self.damped[i] = d > 0.0
                self._biasprm[act, 2] = -self.c if d > 0.0 else 0.0
            self.after_module(i)

    def after_step(self) -> None:
        """Add the step's damper dissipation: (spring force - applied force) * speed_{n+1} * dt, both modules."""
        work = 0.0
        for i, act in self._modules:
            d, applied = self.overlap[i], self._force.item(act)
            if d <= 0.0 and applied == 0.0:
                continue  # inside the play: no force, nothing dissipated (the common case)
            speed = self.speed(i)
            if applied > 0.0 and self.damped[i] and self.implicit:
                applied -= self.c * (speed - self.v_before[i])  # the implicit integrators' damping over the step
            work += ((self.k * d if d > 0.0 else 0.0) - applied) * speed
        self.damper_work += work * self.dt

    def stepped_spring_energy(self) -> float:
        """The springs' energy [J] at the last step's start as MuJoCo's step conserves it: sum of
        1/2 k d^2 + 1/2 dt k d v over the compressed clutches (d > 0).

        The semi-implicit step (v_{n+1} from the force at x_n, then x_{n+1} = x_n + dt v_{n+1}) keeps
        1/2 m v_n^2 + 1/2 k d_n^2 + 1/2 dt k d_n v_n exactly constant on a linear spring, with v_n the
        velocity that moved the module to x_n (substitute the two updates: the change of each side is
        dt k d_n (v_n + v_{n+1}) / 2 with opposite signs). The physical 1/2 k d^2 alone swings by up to
        1/2 omega dt of an impact's energy while the impact goes on and comes back when it ends; the
        accuracy monitor counts the spring with this form so that it sees what the stepping really
        creates or loses, not that swing. The series column is the physical 1/2 k d^2.
        """
        k, dt = self.k, self.dt
        energy = 0.0
        for d, v in zip(self.overlap, self.v_before):
            if d > 0.0:
                energy += 0.5 * k * d * (d + dt * v)
        return energy

    def forces(self) -> tuple[float, float]:
        """The clutch forces [N] MuJoCo computed at the last step's start (or the last mj_forward)."""
        return self._force.item(self.act[0]), self._force.item(self.act[1])

    def load_compiled(self, loop):
        """Its block in the compiled loop (:mod:`.controller`, ``_clutch_slides.c``): the slides, the clutch
        actuators, the anchors (the compliant part: :func:`load_spring`)."""
        require_friction_power(loop)
        loop.use("compliant")
        loop.set_config(x_q0=self.qpos_adr[0], x_q1=self.qpos_adr[1], x_v0=self.dof_adr[0], x_v1=self.dof_adr[1])
        return load_spring(self, loop)

    def reactions(self) -> tuple[bool, bool, float, float]:
        """(rear held, front held, rear force [N], front force [N]): held while its clutch pushes."""
        f1, f2 = self.forces()
        return f1 > 0.0, f2 > 0.0, f1, f2

    # the recorder's part (ClutchController): a sample's clutch forces are MuJoCo's at the sample's own state, which
    # it computes at the start of the next step, from the anchor before_step has just set for that state
    def sampled_reactions(self) -> tuple[bool, bool, float, float]:
        """None at the step: its forces are deferred (:meth:`deferred_values`)."""
        return NO_REACTIONS

    def deferred_values(self) -> tuple[float, float, float, float, float]:
        """The clutch forces [N] and overlaps [m] at the start of the step, and the springs' energy as the step
        conserves it [J] (:meth:`stepped_spring_energy`)."""
        (f1, f2), (d1, d2) = self.forces(), self.overlap
        return f1, f2, d1, d2, self.stepped_spring_energy()

    def clutch_columns(self, scalars: dict, deferred: dict) -> dict:
        """Writes each sample's reaction lambda1/2 (its clutch force at its own state) and held flags (carried
        while it pushes, and not skidding: :func:`.controller.held_where`) into ``scalars``; returns the
        overlaps clutch_overlap1/2 [m], the springs' energy clutch_spring_energy [J] (the physical 1/2 k d^2 of
        the compressed clutches) and the dampers' cumulative work clutch_damper_work [J]."""
        scalars["lambda1"], scalars["lambda2"] = deferred["clutch_force1"], deferred["clutch_force2"]
        for k in ("1", "2"):
            scalars["held" + k] = held_where(deferred["clutch_force" + k] > 0, scalars["wheels" + k]).astype(float)
        d1, d2 = deferred["clutch_overlap1"], deferred["clutch_overlap2"]
        return {"clutch_overlap1": d1.copy(), "clutch_overlap2": d2.copy(),
                "clutch_spring_energy": 0.5 * self.k * (np.maximum(d1, 0.0) ** 2 + np.maximum(d2, 0.0) ** 2),
                "clutch_damper_work": scalars["clutch_damper_work"].copy()}

    def modes(self, mode, both, turning, wheels1, wheels2) -> tuple:
        """As held: a compliant clutch passes no dead centre with both modules held."""
        return mode, wheels1, wheels2

    def finish(self) -> None:
        """The anchors and dampers for the final state, whose clutch forces the last sample holds."""
        self.before_step()


def load_spring(ctl: CompliantClutches, loop, *also: str):
    """The compliant part of ``ctl``'s block in the compiled loop ``loop`` (``_clutch_parts.h``: actuators, anchors,
    overlaps, dampers, k, c, backlash) and its damper work; returns sync(state values), which reads back also the
    STATE fields ``also`` and passes them to ``ctl.sync_also`` (a controller with more state)."""
    if ctl.dt != loop.model.opt.timestep:
        raise LayoutError("the compliant clutches' timestep is not the model's")
    loop.set_config(act0=ctl.act[0], act1=ctl.act[1], implicit=ctl.implicit)
    loop.set_state(anchor0=ctl.anchor[0], anchor1=ctl.anchor[1], overlap0=ctl.overlap[0], overlap1=ctl.overlap[1],
                   v_before0=ctl.v_before[0], v_before1=ctl.v_before[1], damped0=ctl.damped[0], damped1=ctl.damped[1],
                   tracking0=ctl.tracking[0], tracking1=ctl.tracking[1], damper_work=ctl.damper_work, k=ctl.k, c=ctl.c,
                   backlash=ctl.backlash)
    get = loop.getter("anchor0", "anchor1", "overlap0", "overlap1", "v_before0", "v_before1", "damped0", "damped1",
                      "tracking0", "tracking1", "damper_work", *also)

    def sync(state) -> None:
        a0, a1, d0, d1, v0, v1, damped0, damped1, t0, t1, ctl.damper_work, *more = get(state)
        ctl.anchor, ctl.overlap, ctl.v_before = [a0, a1], [d0, d1], [v0, v1]
        ctl.damped, ctl.tracking = [damped0 != 0.0, damped1 != 0.0], [t0 != 0.0, t1 != 0.0]
        if more:
            ctl.sync_also(*more)
    return sync
