"""The one-way clutches of the round-pipe model: a ratchet in every wheel's hub; MuJoCo's rows do the rest.

The model (:mod:`.wheels_model`) puts ``2 wheel_legs`` wheels on each module, each on a hub hinge whose angle grows
as the wheel rolls forward. Before every step :meth:`HubRatchet.before_step` raises each hub's lower limit to the
running maximum of its angle, one margin below it, as the slide model's ratchet does on the slides: a wheel rolls
forward freely (against its hub's ``frictionloss``, the rolling resistance) and never back. Everything else is
MuJoCo's: a held module stands on its locked wheels' contact friction, up to mu_wall times its wheels' normal
forces, and skids back on them beyond it.

Reported per module (:meth:`HubRatchet.states`): rolling while every hub's friction row slides (at its bound
-tau) and no hub's limit row pushes; otherwise held, and skidding while held and its wheels slide on the wall:
their contacts' tangential forces together at the friction cone's edge, mu_wall times their normal forces (to
SLIDING_SHARE), or, with no contact left, while it moves back faster than REST_SPEED; and, whatever its contacts
say, while it moves back faster than SKID_SPEED (its hubs hold while its body tips and slides on its legs, its
contacts inside their cone). A skidding module is not held (:mod:`ipir_mujoco.engine.loop.controller`'s one
meaning: held modules stand). The clutch's reaction is the clutch's share
(:func:`.clutches.clutch_share`) of the module's hold: the hubs' limit and friction rows [N m] over the wheel
radius. ``excursion`` [m]: the largest give of a hub below its running maximum so far, as the arc R (max - angle).

Per sample also (:meth:`HubRatchet.press`): each module's total wall press [N] (its wheels' contacts' normal
forces, MuJoCo's ``efc_force``; the housing's too) and how many of its wheels have no contact force.
"""

from __future__ import annotations

import math
from dataclasses import replace

import mujoco
import numpy as np

from ipir_mujoco.core.errors import ParameterError
from ipir_mujoco.core.params import RobotParams

from ipir_mujoco.core.results import REST_SPEED
from ipir_mujoco.core.wheel_checks import LIFT_SHARE

from ...builders.model import CRANK_HINGE, MOTOR, SLIDES, SolverSettings, dof_address, drive_torque_slope, qpos_address
from .model import HOUSINGS, contact_friction, leg_names, wheels_timestep
from ...loop.controller import SKID_SPEED, ROLLING, SKIDDING, STANDING, ControllerBase, RunningBound, held
from ...loop.native import LayoutError
from ...loop.rows import clutch_share, missing_rows
from .compiled import load_wheel_ratchet

LIMIT_JOINT = int(mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT)
SLIDING_SHARE = 1e-6  # a module's contacts slide where their tangential force is within this share of the cone
STICKS = 1 - 1e-9  # a hub's friction row sticks while above -tau STICKS (a sliding row sits at -tau, MuJoCo's bound)


class WheelRatchet(ControllerBase):
    """The hubs' ratchets (module docstring); ``model`` built by :func:`.wheels_model.build_wheels_model`, made after
    the initial state is set. ``bounds`` [rad]: each hub's running maximum, rear module's hubs first."""

    name = "wheel ratchet"

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, params: RobotParams):
        self.model, self.data, self.radius = model, data, params.wheel_radius
        self._states = (math.nan, None)  # (data.time, states()) of the last step read
        legs = leg_names(params)
        names = [n + "_hub" for module in legs for n in module]
        per_module = len(legs[0])
        self.joint_ids = [model.joint(n).id for n in names]
        self.module_of = {j: (0 if k < per_module else 1) for k, j in enumerate(self.joint_ids)}
        self.qpos_adr = [qpos_address(model, n) for n in names]
        self.dof_adr = [dof_address(model, n) for n in names]
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
        self.torques = [float(model.dof_frictionloss[self.dof_adr[k]]) for k in range(len(names))]
        # per module: (its hubs' friction rows after the equality rows, each hub's friction torque [N m])
        self.friction_rows = [[(with_friction.index(self.dof_adr[k]), self.torques[k]) for k in range(len(names))
                               if self.dof_adr[k] in with_friction and self.module_of[self.joint_ids[k]] == i]
                              for i in (0, 1)]
        self.resistance = [sum(self.torques[i * per_module:(i + 1) * per_module]) / self.radius for i in (0, 1)]
        self.grip = None if params.grip is None else list(params.grip)
        self.mu = contact_friction(params)
        self.cone = (1.0 - SLIDING_SHARE) * self.mu  # a module skids where its contacts' tangential force reaches it
        self.wheel_geoms = [[model.geom(n + "_wheel").id for n in module] for module in legs]
        self.geom_module = {g: i for i, ids in enumerate(self.wheel_geoms) for g in ids}
        self.geom_module.update({model.geom(h).id: i for i, h in enumerate(HOUSINGS)})
        self.wheels_per_module = per_module

    def before_step(self) -> None:
        """Raise each hub's bound to its running maximum, or note how far (on the wall) it has given."""
        q, follow = self._qpos, self.limit.follow
        for k, a in self._hubs:
            give = follow(k, q.item(a)) * self.radius
            if give > self.excursion:
                self.excursion = give

    def load_compiled(self, loop):
        """Its block in the compiled loop (:func:`.compiled_wheels.load_wheel_ratchet`), with the loop's work rates
        (:class:`WheelPower`, on this data)."""
        if not isinstance(loop.power, WheelPower) or loop.power.data is not self.data:
            raise LayoutError("the wheel ratchet's loop has not the wheels' work rates")
        return load_wheel_ratchet(self, loop, loop.power, STICKS)

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
                module = self.module_of.get(int(d.efc_id[row]))
                if module is not None:  # a hub's (an arm's stop is no clutch)
                    limits[module] += force.item(row)
        friction, sticks = [0.0, 0.0], [False, False]
        for i in (0, 1):
            for k, tau in self.friction_rows[i]:
                f = force.item(ne + k)
                friction[i] += f
                if f > -tau * STICKS:
                    sticks[i] = True
        return limits, friction, sticks

    def contacts(self) -> tuple[list[float], list[float], list[int]]:
        """Per module of the last step: its contacts' normal forces and tangential force magnitudes [N], summed
        (an elliptic contact's rows: normal, then its two tangential directions), and how many of its wheels
        press the wall with no force."""
        d, force = self.data, self.data.efc_force
        normal, tangential = [0.0, 0.0], [0.0, 0.0]
        touching = set()
        geoms, addresses = d.contact.geom, d.contact.efc_address
        for c in range(d.ncon):
            g1, g2 = int(geoms[c, 0]), int(geoms[c, 1])
            g = g1 if g1 in self.geom_module else g2
            i = self.geom_module.get(g)
            a = int(addresses[c])
            if i is None or a < 0:
                continue
            f = force.item(a)
            normal[i] += f
            t1, t2 = force.item(a + 1), force.item(a + 2)
            tangential[i] += math.sqrt(t1 * t1 + t2 * t2)  # as _clutch_wheels.c (math.hypot rounds otherwise)
            if f > 0.0:
                touching.add(g)
        off = [sum(1 for g in ids if g not in touching) for ids in self.wheel_geoms]
        return normal, tangential, off

    def states(self) -> tuple[list[int], list[float]]:
        """Per module its wheels' state (+1 rolling, 0 standing, -1 skidding) and its clutch's share of the
        hold [N], of the last step (module docstring); computed once per step."""
        if self._states[0] == self.data.time:
            return self._states[1]
        limits, friction, sticks = self._rows()
        normal, tangential, _ = self.contacts()
        states, shares = [], []
        for i in (0, 1):
            if not (limits[i] > 0.0 or sticks[i]):
                states.append(ROLLING)
                shares.append(0.0)
                continue
            hold = (limits[i] + friction[i]) / self.radius
            speed = self._qvel.item(self.x_dof[i])  # along the pipe (its slide along x)
            if normal[i] > 0.0:
                skids = tangential[i] >= self.cone * normal[i]
            else:
                skids = speed < -REST_SPEED
            skids = skids or speed < -SKID_SPEED  # held modules stand (.controller.SKID_SPEED)
            states.append(SKIDDING if skids else STANDING)
            shares.append(clutch_share(hold, self.resistance[i]))
        self._states = (self.data.time, (states, shares))
        return states, shares

    def reactions(self) -> tuple[bool, bool, float, float]:
        """(rear held, front held, rear reaction [N], front reaction [N]) of the last step: held while its clutch
        carries it and it stands (:func:`.controller.held`: neither rolling nor skidding)."""
        states, shares = self.states()
        return held(True, states[0]), held(True, states[1]), shares[0], shares[1]

    def wheels(self) -> tuple[float, float]:
        """Each module's wheels' state of the last step: +1.0 rolling, 0.0 standing, -1.0 skidding."""
        states, _ = self.states()
        return float(states[0]), float(states[1])

    def press(self) -> tuple[float, float, int]:
        """(module 1's wall press [N], module 2's, how many wheels of both carry no force) of the last step."""
        normal, _, off = self.contacts()
        return normal[0], normal[1], off[0] + off[1]




def leg_press(model: mujoco.MjModel, params: RobotParams, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each leg's spring press [N] from the samples' joint positions ``q`` (n, nq): k (travel - arm slide), 0 at
    and beyond the spring's free length; shape (n, 2, 2 wheel_legs), rear module first, and each leg's preload
    [N], shape (2,). A leg's light arm passes its spring's force to its wheel's contact but for its inertia
    (tests/test_mujoco_wheels.py compares the two over a run), so this is the wall's press on the wheel, read
    from the state rather than the solver (a sliding wheel's contact flickers on and off by micrometres while
    its spring stays pressed: the spring's press is the wheel's hold on the wall)."""
    from .model import leg_preload, leg_stiffness

    legs = leg_names(params)
    out = np.empty((q.shape[0], 2, len(legs[0])))
    for i, names in enumerate(legs):
        k = leg_stiffness(params, i)
        for j, n in enumerate(names):
            out[:, i, j] = np.maximum(k * (params.suspension_travel - q[:, qpos_address(model, n + "_arm")]), 0.0)
    return out, np.array([leg_preload(params, 0), leg_preload(params, 1)])


def pose_columns(model: mujoco.MjModel, q: np.ndarray) -> dict[str, np.ndarray]:
    """Each module's pose across the pipe from the samples' ``q`` (n, nq): y1/2, z1/2 [m] (its slides across the
    pipe) and roll1/2, pitch1/2, yaw1/2 [rad] (its ball joint's rotation vector about x, y, z: for the small
    turns of a module in its pipe, its roll, pitch and yaw), which with x1, x2, phi pose the robot for a replay."""
    from .model import LATERALS, TILTS, VERTICALS

    cols = {}
    for k in (1, 2):
        cols[f"y{k}"] = q[:, qpos_address(model, LATERALS[k - 1])].copy()
        cols[f"z{k}"] = q[:, qpos_address(model, VERTICALS[k - 1])].copy()
        a = qpos_address(model, TILTS[k - 1])
        quat = q[:, a:a + 4]
        sign = np.where(quat[:, 0] < 0, -1.0, 1.0)[:, None]
        w, v = np.clip(sign[:, 0] * quat[:, 0], -1.0, 1.0), sign * quat[:, 1:]
        norm = np.linalg.norm(v, axis=1)
        scale = np.where(norm > 1e-12, 2.0 * np.arctan2(norm, w) / np.maximum(norm, 1e-300), 2.0)
        rot = v * scale[:, None]
        for j, axis in enumerate(("roll", "pitch", "yaw")):
            cols[f"{axis}{k}"] = rot[:, j].copy()
    return cols


def slide_columns(model: mujoco.MjModel, params: RobotParams, q: np.ndarray) -> dict[str, np.ndarray]:
    """slid1/2 [m]: how far each module's wheels have slid sideways on the wall so far, from the samples' ``q``
    (n, nq): per wheel the sum over the samples of its centre's step along its hub's axis (the mean of the axis at
    the step's two ends, as MuJoCo's kinematics place them), the module's most-slid wheel's sum at each sample.
    A wheel rolling on its wall moves along its rolling direction, across its hub's axis: a rigid wheel while its
    ring holds its place across the pipe, a steer-compliant one also while it steers its ring across the pipe
    (``cornering_coefficient``), so what moves a centre along its hub's axis is sliding (and the contact's
    softness, and a wheel off its wall). Rigid wheels: the ring's own path across the pipe, as its three wheels'
    circumferential directions span the ring's plane."""
    from .model import leg_names

    data = mujoco.MjData(model)
    legs = leg_names(params)
    bodies = np.array([[model.body(n + "_wheel").id for n in module] for module in legs])
    hubs = np.array([[model.joint(n + "_hub").id for n in module] for module in legs])
    count = q.shape[0]
    centres, axes = np.empty((count,) + bodies.shape + (3,)), np.empty((count,) + hubs.shape + (3,))
    for i in range(count):
        data.qpos[:] = q[i]
        mujoco.mj_kinematics(model, data)
        centres[i], axes[i] = data.xpos[bodies], data.xaxis[hubs]
    mid = axes[:-1] + axes[1:]
    mid /= np.linalg.norm(mid, axis=-1, keepdims=True)
    slid = np.abs(np.einsum("nmkj,nmkj->nmk", np.diff(centres, axis=0), mid))
    total = np.concatenate([np.zeros((1,) + bodies.shape), np.cumsum(slid, axis=0)]).max(axis=-1)
    return {"slid1": total[:, 0], "slid2": total[:, 1]}


def press_columns(model: mujoco.MjModel, params: RobotParams, q: np.ndarray) -> dict[str, np.ndarray]:
    """press1/2 [N]: each module's legs' total press on the wall (:func:`leg_press`); wheels_off [-]: how many
    legs of both modules are off their wall (pressing with less than LIFT_SHARE of their preload)."""
    press, preload = leg_press(model, params, q)
    off = (press < LIFT_SHARE * preload[None, :, None]).sum(axis=(1, 2)).astype(float)
    return {"press1": press[:, 0].sum(axis=1), "press2": press[:, 1].sum(axis=1), "wheels_off": off}


def link_columns(scalars: dict, pose: dict) -> dict[str, np.ndarray]:
    """The linkage's forces on each module across the pipe [N], in the module's own frame (``pose``'s roll, pitch
    and yaw: :func:`pose_columns`, so along a route's bends too): link_y1/2 along its y (in a straight pipe the
    crank's plane), link_z1/2 along its z. Module 2 feels the loop's pin force at C (the recorder's ``loop_fx``,
    ``loop_fy``, ``loop_fz``, in the world: MuJoCo's connect rows act on the rod, module 2 takes their opposite);
    module 1 the opposite through the crank's bearing at A (the rod's and the crank's own inertia left out: they
    weigh 1 % of a module). In a bend the rod runs along the chord between the modules, so its tension has a part
    across each module's axis."""
    from ipir_mujoco.core.wheel_legs import in_module_frame

    on_rod = np.stack([scalars["loop_fx"], scalars["loop_fy"], scalars["loop_fz"]], axis=-1)
    cols = {}
    for k, sign in ((1, 1.0), (2, -1.0)):
        rotation = np.stack([pose[f"roll{k}"], pose[f"pitch{k}"], pose[f"yaw{k}"]], axis=-1)
        local = in_module_frame(rotation, sign * on_rod)
        cols[f"link_y{k}"], cols[f"link_z{k}"] = local[:, 1].copy(), local[:, 2].copy()
    return cols


def wheel_loop_options(model: mujoco.MjModel, data: mujoco.MjData) -> dict:
    """:func:`.stepper.make_steps`' keyword arguments for the wheeled model after ``mj_forward`` on its initial
    state: as :func:`.loop_rows.loop_options` gives them for the slide model, with ``power`` (:class:`WheelPower`)
    in place of the slides' friction rows."""
    motor = model.actuator(MOTOR).id
    return dict(motor=motor, crank_q=qpos_address(model, CRANK_HINGE), crank_v=dof_address(model, CRANK_HINGE),
                slope=drive_torque_slope(model), torque=data.actuator_force.item(motor), friction_dofs=[],
                power=WheelPower(model, data))


class WheelPower:
    """``power(v)``: the wheeled model's work rates [W] after a step, ``v`` the velocities v_{n+1} as a list:
    (the hubs' friction rows times the hubs' speeds, the contacts' tangential rows times their speeds J v_{n+1}:
    the friction's work against skidding), each summed row by row in row order; the compiled wheel ratchet
    (``_clutch_wheels.c``) sums the same products in the same order, J v from MuJoCo's ``mj_mulJacVec`` in both.

    The contacts' normal rows are left out: their force times the step's velocity is no measure of the little
    energy a stiff soft contact stores (on a skid in a riser it booked 1.4 J where MuJoCo's own energy, the
    drive's work and the tangential rows' balance to 1e-3 J without it). With a pyramidal cone (the convergence
    study only) a contact's rows mix both directions and all of them count. ``hub_dofs``: the dofs with
    frictionloss (the hubs'), whose rows follow the equality rows in dof order; ``elliptic``: the cone."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        self.model, self.data = model, data
        self.hub_dofs = [int(i) for i in np.flatnonzero(model.dof_frictionloss > 0)]
        self.elliptic = model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
        if self.elliptic and set(np.unique(model.geom_condim[model.geom_contype + model.geom_conaffinity > 0])) != {3}:
            raise ParameterError("the wheeled model's contacts must have condim 3 (the work bookkeeping reads their "
                                 "rows as normal, tangent, tangent)")

    def __call__(self, v) -> tuple[float, float]:
        d = self.data
        if d.nf != len(self.hub_dofs):
            raise missing_rows(2, d.time)
        ne, nf, nefc, force = d.ne, d.nf, d.nefc, d.efc_force
        rolling = 0.0
        for k, dof in enumerate(self.hub_dofs):
            rolling += force.item(ne + k) * v[dof]
        first, contact = ne + nf + d.nl, 0.0
        if nefc > first:
            jv = np.empty(nefc)
            mujoco.mj_mulJacVec(self.model, d, jv, d.qvel)  # d.qvel: v
            rates = (force[first:nefc] * jv[first:]).tolist()
            if self.elliptic:  # each contact's rows: its normal, then its tangential directions; the friction's only
                del rates[0::3]
            for rate in rates:
                contact += rate
        return rolling, contact


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


def wheels_settings(chosen: SolverSettings, why: dict, dt_out: float, route=None):
    """The automatic settings of a wheeled run: ``chosen`` (:func:`.timestep.choose_settings`' SolverSettings
    and ``why``, its limits [s]) with the step at most the model's own (:func:`.wheels_model.wheels_timestep`,
    half its rows' shortest time constant, a quarter along a ``route`` with bends: mjcf/README.md, "The round
    pipe: convergence"), a whole fraction of ``dt_out`` [s]; returns (settings, why)."""
    bends = route is not None and bool(route.bends)
    cap = wheels_timestep(bends=bends)
    if chosen.timestep <= cap:
        return chosen, why
    steps = math.ceil(dt_out / cap * (1 - 1e-12))
    return replace(chosen, timestep=dt_out / steps), {**why, ("bends_s" if bends else "rows_s"): cap}
