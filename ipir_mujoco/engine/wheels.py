"""The one-way clutches of the wheeled MuJoCo model: a ratchet in every wheel's hub; MuJoCo's rows do the rest.

The model (:mod:`.wheels_model`) puts four wheels on each module, each on a hub hinge whose angle grows as the
wheel rolls forward (the bottom wall's hubs turn about -z for it). Before every step
:meth:`WheelRatchet.before_step` raises each hub's lower limit to the running maximum of its angle, one margin
below it, exactly as the slide model's ratchet does on the slides (:class:`.clutches.Ratchet`): a wheel rolls
forward freely (against its hub's ``frictionloss``, the rolling resistance) and never back. Everything else is
MuJoCo's: a held module stands on its locked wheels' contact friction, up to mu_wall times the wall-press
force, and skids back on them beyond it.

Reported per module (:meth:`WheelRatchet.states`): rolling while every hub's friction row slides (at its bound
-tau) and no hub's limit row pushes; otherwise held, and skidding while held and its wheels slide on the wall:
their contacts' tangential forces together at the friction cone's edge, mu_wall times their normal forces (to
SLIDING_SHARE; MuJoCo's elliptic cone puts a sliding contact's force on that edge), or, with no contact left,
while it moves back faster than REST_SPEED. (A held module's speed alone does not tell: it rocks back and
forth faster than REST_SPEED on its springs and soft contacts as the load comes on.) The clutch's reaction is the clutch's share (:func:`.clutches.clutch_share`) of the module's hold:
the hubs' limit and friction rows [N m] over the wheel radius. ``excursion`` [m]: the largest give of a hub
below its running maximum so far, as the arc R (max - angle) on the wall, checked before every step.

The work bookkeeping of the stepping loop (:func:`wheel_loop_options`): the rolling resistance's work from the
hubs' friction rows, and the contacts' work (``skid_work``: every contact row's force times its speed
J v_{n+1} of its tangential directions: the friction's work against skidding).
"""

from __future__ import annotations

import math
from dataclasses import replace

import mujoco
import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams

from ipir_mujoco.core.results import REST_SPEED

from .controller import ROLLING, SKIDDING, STANDING, ControllerBase, RunningBound, held
from .model import CRANK_HINGE, MOTOR, SLIDES, SolverSettings, dof_address, drive_torque_slope, qpos_address
from .rows import clutch_share, missing_rows
from .wheels_model import WHEEL_NAMES, contact_friction

LIMIT_JOINT = int(mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT)
SLIDING_SHARE = 1e-6  # a module's contacts slide where their tangential force is within this share of the cone


class WheelRatchet(ControllerBase):
    """The hubs' ratchets (module docstring); ``model`` built by :func:`.wheels_model.build_wheels_model`, called
    after the initial state is set. ``bounds`` [rad]: each hub's running maximum, rear module's hubs first."""

    name = "wheel ratchet"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams):
        self.model, self.data, self.radius = model, data, params.wheel_radius
        self._states = (math.nan, None)  # (data.time, states()) of the last step read
        names = [n + "_hub" for module in WHEEL_NAMES for n in module]
        self.module_of = {}
        self.joint_ids = [model.joint(n).id for n in names]
        for k, j in enumerate(self.joint_ids):
            self.module_of[j] = 0 if k < len(WHEEL_NAMES[0]) else 1
        self.qpos_adr = [qpos_address(model, n) for n in names]
        self.dof_adr = [dof_address(model, n) for n in names]
        limited = [j for j in range(model.njnt) if model.jnt_limited[j]]
        if sorted(limited) != sorted(self.joint_ids):
            raise ValueError("the wheel ratchet needs the hubs, and only them, limited: build the wheeled model")
        self.margins = [float(model.jnt_margin[j]) for j in self.joint_ids]
        self.range = model.jnt_range
        self.limit = RunningBound(self.range, self.joint_ids, [float(data.qpos[a]) for a in self.qpos_adr],
                                  self.margins)
        self.bounds = self.limit.extremes
        self.excursion = 0.0
        self._qpos, self._qvel = data.qpos, data.qvel
        self._hubs = tuple(enumerate(self.qpos_adr))
        self.x_dof = [dof_address(model, n) for n in SLIDES]
        # the friction rows follow the equality rows, one per dof with friction, in dof order: the hubs' only
        with_friction = [int(i) for i in np.flatnonzero(model.dof_frictionloss > 0)]
        if not set(with_friction) <= set(self.dof_adr):
            raise ParameterError("the wheeled MJCF model has frictionloss off the hubs: the engine counts the "
                                 "rolling resistance on the hubs only")
        self.friction_count = len(with_friction)
        self.friction_rows = [[with_friction.index(self.dof_adr[k]) for k in range(len(names))
                               if self.dof_adr[k] in with_friction and self.module_of[self.joint_ids[k]] == i]
                              for i in (0, 1)]
        self.torques = [float(model.dof_frictionloss[self.dof_adr[k]]) for k in range(len(names))]
        per_module = len(WHEEL_NAMES[0])
        # each module's rolling resistance [N]: its hubs' friction torques over the wheel radius
        self.resistance = [sum(self.torques[i * per_module:(i + 1) * per_module]) / self.radius for i in (0, 1)]
        self.grip = None if params.grip is None else list(params.grip)
        self.mu = contact_friction(params)
        self.geom_module = {model.geom(n + "_wheel").id: i for i, module in enumerate(WHEEL_NAMES) for n in module}

    def before_step(self) -> None:
        """Raise each hub's bound to its running maximum, or note how far (on the wall) it has given."""
        q, follow = self._qpos, self.limit.follow
        for k, a in self._hubs:
            give = follow(k, q.item(a)) * self.radius
            if give > self.excursion:
                self.excursion = give

    def _rows(self) -> tuple[list[float], list[float], list[bool]]:
        """Per module of the last step: its hubs' limit rows summed [N m], their friction rows summed [N m], and
        whether any of its friction rows sticks (inside its bound)."""
        d = self.data
        if d.nf != self.friction_count:
            raise missing_rows(2, d.time)
        ne, force = d.ne, d.efc_force
        limits = [0.0, 0.0]
        start = ne + d.nf
        for row in range(start, start + d.nl):
            if d.efc_type[row] == LIMIT_JOINT:
                limits[self.module_of[int(d.efc_id[row])]] += force.item(row)
        friction, sticks = [0.0, 0.0], [False, False]
        for i in (0, 1):
            for k in self.friction_rows[i]:
                f = force.item(ne + k)
                friction[i] += f
                tau = float(self.model.dof_frictionloss[d.efc_id[ne + k]])
                if f > -tau * (1 - 1e-9):
                    sticks[i] = True
        return limits, friction, sticks

    def _contacts(self) -> tuple[list[float], list[float]]:
        """Per module of the last step: its wheels' contacts' normal forces and tangential force magnitudes
        [N], summed (an elliptic contact's rows: normal, then its two tangential directions)."""
        d, force = self.data, self.data.efc_force
        normal, tangential = [0.0, 0.0], [0.0, 0.0]
        geoms, addresses = d.contact.geom, d.contact.efc_address
        for c in range(d.ncon):
            g1, g2 = int(geoms[c, 0]), int(geoms[c, 1])
            i = self.geom_module.get(g1, self.geom_module.get(g2))
            a = int(addresses[c])
            if i is None or a < 0:
                continue
            normal[i] += force.item(a)
            tangential[i] += math.hypot(force.item(a + 1), force.item(a + 2))
        return normal, tangential

    def states(self) -> tuple[list[int], list[float]]:
        """Per module its wheels' state (+1 rolling, 0 standing, -1 skidding) and its clutch's share of the
        hold [N], of the last step (module docstring). Computed once per step: a sample reads it twice
        (:meth:`reactions`, :meth:`wheels`)."""
        if self._states[0] == self.data.time:
            return self._states[1]
        limits, friction, sticks = self._rows()
        normal, tangential = self._contacts()
        states, shares = [], []
        for i in (0, 1):
            if not (limits[i] > 0.0 or sticks[i]):
                states.append(ROLLING)
                shares.append(0.0)
                continue
            hold = (limits[i] + friction[i]) / self.radius
            if normal[i] > 0.0:
                skids = tangential[i] >= (1.0 - SLIDING_SHARE) * self.mu * normal[i]
            else:
                skids = self._qvel.item(self.x_dof[i]) < -REST_SPEED
            states.append(SKIDDING if skids else STANDING)
            shares.append(clutch_share(hold, self.resistance[i]))
        self._states = (self.data.time, (states, shares))
        return states, shares

    def reactions(self) -> tuple[bool, bool, float, float]:
        """(rear held, front held, rear reaction [N], front reaction [N]) of the last step: held while it
        stands (:func:`.controller.held`: neither rolling nor skidding)."""
        states, shares = self.states()
        return held(True, states[0]), held(True, states[1]), shares[0], shares[1]

    def wheels(self) -> tuple[float, float]:
        """Each module's wheels' state of the last step: +1.0 rolling, 0.0 standing, -1.0 skidding."""
        states, _ = self.states()
        return float(states[0]), float(states[1])


def wheel_loop_options(model: mujoco.MjModel, data: mujoco.MjData) -> dict:
    """:func:`.stepper.make_steps`' keyword arguments for the wheeled model after ``mj_forward`` on its initial
    state: as :func:`.loop_rows.loop_options` gives them for the slide model, with ``power(v)``, the work rates
    [W] after a step (the hubs' friction rows times the hubs' speeds; the contacts' tangential rows times their
    speeds J v_{n+1}: the friction's work against skidding) in place of the slides' friction rows.

    The contacts' normal rows are left out: their force times the step's velocity is no measure of the little
    energy a stiff soft contact stores (on a skid in a riser it booked 1.4 J where MuJoCo's own energy, the
    drive's work and the tangential rows' balance to 1e-3 J without it). With a pyramidal cone (the convergence
    study only) a contact's rows mix both directions and all of them count."""
    motor = model.actuator(MOTOR).id
    hub_dofs = [int(i) for i in np.flatnonzero(model.dof_frictionloss > 0)]
    nv = model.nv
    elliptic = model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    if elliptic and set(np.unique(model.geom_condim[model.geom_contype + model.geom_conaffinity > 0])) != {3}:
        raise ParameterError("the wheeled model's contacts must have condim 3 (the work bookkeeping reads their rows "
                             "as normal, tangent, tangent)")

    def power(v) -> tuple[float, float]:
        d = data
        if d.nf != len(hub_dofs):
            raise missing_rows(2, d.time)
        ne, nf, force = d.ne, d.nf, d.efc_force
        rolling = 0.0
        for k, dof in enumerate(hub_dofs):
            rolling += force.item(ne + k) * v[dof]
        first = ne + nf + d.nl
        if d.nefc > first:
            J = d.efc_J[first * nv:d.nefc * nv].reshape(-1, nv)
            rates = force[first:d.nefc] * (J @ np.asarray(v))
            if elliptic:  # each contact's rows: its normal, then its tangential directions; the friction's only
                rates[0::3] = 0.0
            contact = float(rates.sum())
        else:
            contact = 0.0
        return rolling, contact

    return dict(motor=motor, crank_q=qpos_address(model, CRANK_HINGE), crank_v=dof_address(model, CRANK_HINGE),
                slope=drive_torque_slope(model), torque=data.actuator_force.item(motor), friction_dofs=[],
                power=power)


def wheel_slip(x: np.ndarray) -> np.ndarray:
    """A module's backward skid so far [m], shape (n,): the sum of its backward steps between samples, from
    its positions ``x`` [m], shape (n,). A one-way clutch lets a module move back only by skidding on its locked
    wheels (or by its hubs' and contacts' give, bounded by the monitor's excursion tolerance: 5e-8 m over a
    second of the default motor's cruise). Not only the samples the wheels' state calls skidding: a skidding
    wheel bounces on the wall, and while it is off the wall or momentarily inside its cone its module still
    slides back (counting only those samples missed a fifth of a skid on a 30 degree incline)."""
    back = np.maximum(-np.diff(x), 0.0)
    return np.concatenate([[0.0], np.cumsum(back)])


def refuse_clutches(params: RobotParams, implementation: str) -> None:
    """ParameterError (one line) for a clutch the wheeled model does not have: it has the hubs' rigid
    ratchets only."""
    if implementation != "ratchet":
        raise ParameterError(f"the MuJoCo {implementation!r} clutch on the wheeled model: its clutches are ratchets "
                             "in the wheels' hubs; allowed: --mujoco-clutch ratchet (--clutch unilateral)")
    if params.clutch_stiffness is not None:
        raise ParameterError(f"clutch_stiffness={params.clutch_stiffness!r} N/m with the wheeled MuJoCo model: its "
                             "hub ratchets are rigid; allowed: clutch_stiffness=rigid, or --mujoco-model slides")


# s: the wheeled model's largest automatic timestep with finite grip: a skid's length converges only there
# (mjcf/README.md, "Wheels in contact": 48 % too long at 1e-4 s, 6 % at 5e-5 s, within 1 % at 2.5e-5 s)
DT_SKID = 2.5e-5


def wheels_settings(chosen: SolverSettings, why: dict, params: RobotParams, dt_out: float):
    """The automatic settings of a wheeled run: ``chosen`` (:func:`.timestep.choose_settings`' SolverSettings
    and ``why``, its limits [s]) with the step capped at DT_SKID where the grip is finite, a whole fraction
    of ``dt_out`` [s]; returns (settings, why)."""
    if params.grip is None or chosen.timestep <= DT_SKID:
        return chosen, why
    steps = math.ceil(dt_out / DT_SKID * (1 - 1e-12))
    return replace(chosen, timestep=dt_out / steps), {**why, "skid_s": DT_SKID}
