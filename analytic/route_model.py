"""The robot along a route: its modes, events, mode choice and series columns (the equations: :mod:`.route_kernels`;
the run loop: :mod:`.route_run`).

Modes are :class:`.grip_model.GripMode`: which modules stand, and whether each moving module rolls forward or skids
back. With the one-way clutches (``clutch='unilateral'``) the next mode solves the complementarity problem of the
finite-grip model (:meth:`.GripModel.choose`: a module at rest may roll, stand or skid; with unlimited grip it cannot
skid); with the paper's rule (``'kinematic'``) the module whose clutch locks is the one the gap's motion would
push back (:meth:`RouteModel.choose`), and its lock holds whatever the load.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from ipir_mujoco.core import energy
from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import Mode, grip_use
from ipir_mujoco.core.route import Route

from . import accel, dop853, kernels, route_kernels
from .dynamics import OneDofDynamics
from .grip_model import GripMode, GripModel
from .kinematics import Linkage
from .route_geometry import PIECE, pack_route
from .route_kernels import (EXPANSION, N_EVENTS, Q_COUNT, Q_DIR1, Q_END, Q_G1, Q_GX, Q_H, Q_IT1, Q_MU, Q_PIECES,
                            Q_RULE, ROUTE, RULE_ONE_WAY, RULE_PAPER)
from .unilateral_model import _MODE_REST_FLOOR, _TOL_V

# route_state's outputs, by name
(S1, S2, V1, V2, ALPHA, A1, A2, R1, R2, KINETIC, POTENTIAL, TORQUE, SCRUB, K2, DK2) = range(15)
_ZERO_A = 1e-9  # |a| below this fraction of r (omega^2 + |alpha_c| + |alpha_e|) is zero (as kinematic_clutch)
# [m] how far past a joint a module's event state is moved where a ring lies this close before one (past_joints):
# far above the event's location in round-off (v 1e-15 s), far below any length the model resolves
JOINT_STEP = 1e-9


def transverse_inertia(params: RobotParams, mass: float) -> float:
    """A module's inertia [kg m^2] about an axis across it through its point (A or C): a solid cylinder of its
    mass ``mass`` [kg], as long as its ring spacing, of the radius inside its wheels (pipe_diameter / 2 - 2
    wheel_radius): the module body the wheeled MuJoCo model describes (mjcf/README.md, "The wheeled model")."""
    rho = 0.5 * params.pipe_diameter - 2.0 * params.wheel_radius
    return mass * (3.0 * rho * rho + params.ring_spacing ** 2) / 12.0


def wheel_constants(params: RobotParams) -> tuple[float, ...]:
    """The wheels' constants of the scrub's closed form (:data:`.route_kernels.Q_MU` .. ``Q_RHO``): mu_wall (0 with
    unlimited grip: the equations' rails, which carry any force across the pipe, and no scrub), the cornering
    coefficient [1/rad] (inf for rigid wheels), the legs per ring n, each module's legs' preload F_ni / (2 n) [N],
    the legs' deflection at their preload [m] and the hubs' distance from the pipe's axis [m]."""
    n = int(params.wheel_legs)
    corner = math.inf if params.cornering_coefficient is None else params.cornering_coefficient
    return (params.mu_wall or 0.0, corner, float(n), params.F_n1 / (2 * n), params.F_n2 / (2 * n),
            params.suspension_travel, 0.5 * params.pipe_diameter - params.wheel_radius)


class RouteModel(GripModel):
    """The robot with ``clutch`` 'unilateral' (one-way clutches, finite grip where ``params.mu_wall`` is) or
    'kinematic' (the paper's locks) along ``route``; the interface :mod:`.route_run` drives."""

    def __init__(self, params: RobotParams, route: Route, clutch: str):
        self.params, self.route, self.rule, self.torque = params, route, clutch, None
        self.linkage = Linkage(params.r, params.L, "exact")
        self.dyn = SimpleNamespace(a_g=params.g)  # the scale of gravity's accelerations (mode choice)
        self.grip = params.grip or (math.inf, math.inf)
        self.F = (params.F_r1, params.F_r2)
        pieces = pack_route(route)
        up = route.up
        head = np.zeros(Q_PIECES - 17)
        head[Q_G1 - 17:Q_G1 - 15] = self.grip
        head[Q_RULE - 17] = RULE_PAPER if clutch == "kinematic" else RULE_ONE_WAY
        head[Q_H - 17] = 0.5 * params.ring_spacing
        head[Q_IT1 - 17:Q_IT1 - 15] = transverse_inertia(params, params.m1), transverse_inertia(params, params.m2)
        head[Q_GX - 17:Q_GX - 14] = -params.g * up
        head[Q_END - 17], head[Q_COUNT - 17] = route.length, pieces.size // PIECE
        head[Q_MU - 17:Q_PIECES - 17] = wheel_constants(params)
        base = np.concatenate([kernels.pack(OneDofDynamics(params, "exact")), head, pieces])
        # module 2's station at the start: the straight pipe's gap, then the loop closed along the route
        self.joints = [piece.s0 for piece in route.pieces[1:]] + [route.length]  # [m] where the curvature jumps
        self.s20 = float(self._state(base, EXPANSION, [params.phi0, 0.0, 0.0, float(self.linkage.gap(params.phi0)),
                                                       0.0, 0.0, 0.0])[S2])
        self.constants = {}
        for mode in GripMode:
            constants = base.copy()
            constants[Q_DIR1:Q_DIR1 + 2] = mode.states
            self.constants[mode] = constants

    @staticmethod
    def _state(p, kinematics: int, y) -> tuple:
        # through the module (as kernels.* elsewhere): compiled once the kernels are, the same floats as the guards'
        return route_kernels.route_state(p, int(kinematics), np.asarray(y, dtype=float))

    def state(self, y, mode: GripMode) -> tuple:
        """:func:`.route_kernels.route_state` at ``y`` in ``mode`` (floats; the S1, S2, ... indices above)."""
        return self._state(self.constants[mode], mode.kinematics, y)

    def start(self) -> np.ndarray:
        """The state at t = 0: module 1's A at the route's start, the crank at (phi0, omega0), module 1 at rest
        unless the gap shrinks (the straight pipe's start, :func:`.simulate_unilateral`)."""
        p = self.params
        y = np.array([p.phi0, p.omega0, 0.0, self.s20, 0.0, 0.0, 0.0])
        gap_rate = self.state(y, GripMode.EXPANSION)[K2] * p.omega0
        y[4] = max(-gap_rate, 0.0)
        return y

    def motor(self, t, phi, omega):
        return kernels.drive_torque(self.constants[GripMode.BOTH_MOVING], float(omega))

    def velocities(self, y, mode: GripMode) -> tuple[float, float]:
        m = self.state(y, mode)
        return m[V1], m[V2]

    def _transfer(self, y) -> tuple[float, float]:
        m = self.state(y, GripMode.EXPANSION)
        return m[K2], m[DK2]

    def _motion(self, y, v, mode: GripMode, M) -> dict:
        y = np.array(y, dtype=float)
        y[4] = v[0]
        m = self.state(y, mode)
        return {"alpha": m[ALPHA], "a1": m[A1], "a2": m[A2], "R1": m[R1], "R2": m[R2]}

    def choose(self, t, y, velocities, fired=None, previous=None) -> GripMode:
        """The next mode at state ``y`` (module docstring): the one-way clutches' complementarity problem
        (:meth:`.GripModel.choose`), or the paper's rule: the lock goes to the module the gap's motion pushes
        back, by the free module's speed where it moves, else by its acceleration, else (at a dead centre at rest)
        by the next order, as in the straight pipe (:func:`.kinematic_clutch.choose_mode_at_rest_gap`)."""
        if self.rule != "kinematic":  # a module at rest rolls off against its resistance and its scrub at v = 0
            m = self.state(y, GripMode.BOTH_MOVING)
            self.F = tuple(F + route_kernels.scrub_force(self.constants[GripMode.BOTH_MOVING], i, m[S1 + i], 0.0)
                           for i, F in enumerate((self.params.F_r1, self.params.F_r2)))
            return super().choose(t, y, velocities, fired, previous)
        omega, r = float(y[1]), self.linkage.r
        contraction, expansion = self.state(y, GripMode.CONTRACTION), self.state(y, GripMode.EXPANSION)
        speed = 1e-10 * r * abs(omega)
        if fired is None and contraction[V1] > speed:
            return GripMode.CONTRACTION
        if fired is None and expansion[V2] > speed:
            return GripMode.EXPANSION
        tol = _ZERO_A * r * (omega**2 + abs(contraction[ALPHA]) + abs(expansion[ALPHA]))
        ok = (contraction[A1] > tol, expansion[A2] > tol)
        if all(ok):
            raise SimulationError(f"the paper's clutch rule cannot choose a module at t={t:.6g} s, phi={y[0]:.6g} rad "
                                  f"along the route: gravity can move either module on its own, more than the "
                                  "resistances hold; use the one-way clutches (clutch='unilateral')")
        if ok[0] or ok[1]:
            return GripMode.CONTRACTION if ok[0] else GripMode.EXPANSION
        if abs(contraction[A1]) <= tol and abs(expansion[A2]) <= tol and contraction[ALPHA] != 0.0:
            return GripMode.CONTRACTION if expansion[DK2] < 0 else GripMode.EXPANSION
        return GripMode.BOTH_LOCKED

    def project(self, y, mode: GripMode, velocities) -> np.ndarray:
        """The state with the loop closed in ``mode``'s dependent coordinate, its held modules' speeds zero (and so
        a module starting from rest beside a moving one: :meth:`.GripModel.project`)."""
        y = np.array(y, dtype=float)
        v = [float(x) for x in velocities]
        if mode.kinematics is Mode.BOTH_LOCKED:
            y[1] = 0.0
        m = self.state(y, mode)
        y[2], y[3] = m[S1], m[S2]  # closed: every mode now reads this state's geometry as it is
        if mode.kinematics is not Mode.BOTH_MOVING:
            y[4] = m[V1]
            return y
        scale = self.linkage.r * abs(float(y[1])) + abs(v[0]) + abs(v[1])
        rest = [abs(x) <= _TOL_V * scale + _MODE_REST_FLOOR for x in v]
        # a module starting from rest starts at exactly 0: its guard then reads the safe side
        y[4] = 0.0 if rest[0] else (self.state(y, GripMode.CONTRACTION)[V1] if rest[1] else v[0])
        return y

    def past_joints(self, y, mode: GripMode) -> np.ndarray:
        """The event state ``y`` with each moving module's station moved on by JOINT_STEP past a joint one of its rings
        lies within JOINT_STEP before (in its direction of motion). A ring's crossing of a joint changes the
        curvature, and so the accelerations and holds, at once: an event it causes (a hold giving way) is located
        to round-off of the joint on its near side, and the next mode must be chosen with the curvature the
        motion goes on with (the loop is closed again by :meth:`project`)."""
        y = np.array(y, dtype=float)
        h = 0.5 * self.params.ring_spacing
        for i, v in enumerate(self.velocities(y, mode)):
            if v != 0.0:
                sense = math.copysign(1.0, v)
                ahead = [sense * (joint - ring) for ring in (y[2 + i] - h, y[2 + i] + h) for joint in self.joints]
                near = [d for d in ahead if 0.0 <= d < JOINT_STEP]
                if near:
                    y[2 + i] += sense * (max(near) + JOINT_STEP)
        return y

    # --- events ------------------------------------------------------------------------------
    def events(self, mode: GripMode, quiet: dict[int, float] | None = None):
        """[(event function, meaning)]: per module ('velocity'|'hold', module), then ('end', -1), each falling
        through 0 (:func:`.route_kernels.route_guards`); ``quiet`` as :meth:`.GripModel.events`."""
        quiet = quiet or {}
        p, kinematics = self.constants[mode], int(mode.kinematics)
        silent = np.array([quiet.get(k, -math.inf) for k in range(N_EVENTS)])
        found = []
        for k in range(N_EVENTS):
            def event(t, y, k=k):
                return kernels.guard(ROUTE, kinematics, k, float(t), np.asarray(y, dtype=float), p, silent)
            event.terminal, event.direction = True, -1.0
            found.append((event, ("end", -1) if k == 2 else ("velocity" if mode.states[k] else "hold", k)))
        return found

    def guards(self, t, Y, mode: GripMode) -> np.ndarray:
        """Every event function of ``mode`` at times t (n,) and states Y (7, n): array (N_EVENTS, n)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.empty((N_EVENTS, t.size))
        kernels.guard_table(ROUTE, int(mode.kinematics), N_EVENTS, self.constants[mode], t,
                            np.ascontiguousarray(np.asarray(Y, dtype=float).reshape(7, -1).T), out)
        return out

    def graze_scan(self, sol, mode: GripMode):
        if accel.ACCELERATED and isinstance(sol, dop853.Segment):
            return lambda: sol.sol.graze_scan(ROUTE, int(mode.kinematics), N_EVENTS, self.constants[mode])

    def kernel_call(self, mode: GripMode) -> tuple[int, int, np.ndarray]:
        return ROUTE, int(mode.kinematics), self.constants[mode]

    # --- the run's columns -------------------------------------------------------------------
    def columns(self, code: int, rows: dict) -> dict[str, np.ndarray]:
        """Every series column of the samples ``rows`` (all of mode ``code``), arrays (n,): along the route, x_i
        is module i's station from its start, S = s2 - s1 the gap along the centreline."""
        mode = GripMode(code)
        states = np.column_stack([rows[c] for c in ("phi", "omega", "x1", "s2", "state_v1", "motor_work",
                                                    "scrub_work")])
        table = np.empty((states.shape[0], 15))
        route_kernels.route_table(self.constants[mode], int(mode.kinematics), np.ascontiguousarray(states), table)
        m = table.T
        x1, x2 = m[S1], m[S2] - self.s20
        piece = {"t": rows["t"], "phi": rows["phi"], "omega": rows["omega"], "alpha": m[ALPHA], "x1": x1,
                 "x2": x2, "v1": m[V1], "v2": m[V2], "a1": m[A1], "a2": m[A2], "S": m[S2] - m[S1],
                 "S_dot": m[V2] - m[V1], "mode": np.full(x1.shape, int(mode.kinematics))}
        for i, state in enumerate(mode.states):
            R, F, G = m[R1 + i], (self.params.F_r1, self.params.F_r2)[i], self.grip[i]
            if mode.kinematics is Mode.BOTH_LOCKED:  # at rest: a backward hold is the resistance's, up to F
                resistance = np.maximum(np.minimum(R, 0.0), -F)
                lam = R - resistance
            elif state == 1:
                lam, resistance = np.zeros(x1.shape), np.full(x1.shape, -F)
            elif state == -1:  # locked wheels skidding: the grip, all through the clutch
                lam, resistance = np.full(x1.shape, G), np.zeros(x1.shape)
            elif self.rule == "kinematic":  # the paper's lock takes the whole hold, pulling too
                lam, resistance = R, np.zeros(x1.shape)
            else:
                lam, resistance = np.maximum(R, 0.0), np.minimum(R, 0.0)
            piece[f"lambda{i + 1}"], piece[f"resistance{i + 1}"] = lam, resistance
            if G < math.inf:
                piece[f"wheels{i + 1}"] = np.full(x1.shape, float(state))
                piece[f"grip_use{i + 1}"] = grip_use(lam, piece[f"wheels{i + 1}"], G)
        piece.update(motor_work=rows["motor_work"], scrub_work=rows["scrub_work"], kinetic=m[KINETIC],
                     potential=m[POTENTIAL], motor_power=m[TORQUE] * rows["omega"])
        return piece

    def energy_columns(self, series: dict) -> dict[str, np.ndarray]:
        """potential (from the start), friction_work and, with finite grip, slip1, slip2 and skid_work
        (:meth:`.GripModel.energy_columns`' definitions: exact, each force constant while a module rolls or
        skids); scrub_work and kinetic are the run's own columns."""
        out = {"potential": series["potential"] - series["potential"][0]}
        friction, skid = 0.0, 0.0
        for i in (0, 1):
            x = np.asarray(series[f"x{i + 1}"], dtype=float)
            slip = np.zeros(x.shape)
            if self.grip[i] < math.inf:
                back = np.zeros(x.shape)
                back[1:] = np.where(series[f"wheels{i + 1}"][1:] == -1, x[:-1] - x[1:], 0.0)
                slip = np.cumsum(back)
                out[f"slip{i + 1}"] = slip
                skid = skid + self.grip[i] * slip
            friction = friction + (self.params.F_r1, self.params.F_r2)[i] * (x + slip)
        out["friction_work"] = friction
        if self.params.grip is not None:
            out["skid_work"] = skid
        return out

    def energy_audit(self, series: dict) -> dict[str, float]:
        """Motor work = kinetic + potential energy gained + friction + skid + scrub work + residual [J]."""
        return energy.audit(series)
