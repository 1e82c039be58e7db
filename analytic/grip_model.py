"""One-way clutches on wheels of finite grip: each module rolls forward, stands, or skids back.

A module's wheels are pressed onto the wall with F_ni; its one-way clutch locks
them against turning backward, and locked wheels hold by friction, at most
G_i = mu_wall F_ni (static = kinetic). With g_i the whole ground force on module
i (clutch and resistance together, + forward) the wheel-wall law is

    rolling forward:  v_i > 0,  g_i = -F_ri
    standing:         v_i = 0,  -F_ri <= g_i <= G_i
    skidding back:    v_i < 0,  g_i = +G_i        (locked wheels: no rolling resistance)

the graph of g_i = -d(phi_i)/dv_i with phi_i(v) = F_ri max(v, 0) + G_i max(-v, 0)
convex, so, the mass matrix being positive definite, the accelerations at any
instant are unique (they minimise a strictly convex function); only which of two
states a module at rest is in can tie, on the boundary between them.

Modes (:class:`GripMode`): the one-way model's four kinematics (which modules
stand, :class:`.columns.Mode`) with each moving module rolling forward or
skidding back; nine in all. The equations of a mode are the one-way model's
with a skidding module's resistance F_ri replaced by -G_i (the force then pushes
it forward): :meth:`.OneDofDynamics.with_resistance`. The kernels integrate them
as :data:`.kernels.GRIP`, with their own events (:func:`.kernels.grip_guard`): a
moving module's speed in its sense of motion (it stops) and a standing module's
smaller margin min(R_i + F_ri, G_i - R_i) (its resistance or its grip gives).

At each event the next mode solves the complementarity problem by enumeration
(:meth:`GripModel.choose`): a module at rest may roll forward (a_i >= 0), stand
(within both limits) or skid back (a_i <= 0); a moving one keeps its direction.
Ties, on boundaries only, go as the physics goes: the state whose condition just
reached its limit is left in the sense it crosses (a margin at F_ri: it rolls; at
G_i: it skids; a module that stops: it stands), a robot at rest that statics
holds stays at rest, and at a dead centre at rest (K = 0), where every single-hold
mode starts with zero module acceleration, the next order decides: the gap moves
as K' (phi - phi0)^2 / 2, so the free module of contraction kinematics moves as
-K', of expansion kinematics as +K'. docs/model.md, "Finite grip", derives them.

Reported: ``mode`` the kinematics (a module counts as held while it stands, as
with rigid one-way clutches); ``wheels1/2`` each module's state (+1 rolling, 0
standing, -1 skidding); ``lambda_i`` = G_i while it skids, its clutch's share of
the hold while it stands, 0 while it rolls; ``grip_use1/2`` = lambda_i / G_i;
``slip1/2`` its backward skid so far [m]; ``skid_work`` = sum G_i slip_i [J].
"""

from __future__ import annotations

import math
from enum import IntEnum

import numpy as np

from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import Mode, grip_use

from . import accel, dop853, kernels
from .kinematics import Geometry
from .unilateral_model import _MODE_REST_FLOOR, _TINY, _TOL_A, _TOL_F, _TOL_V, UnilateralModel, _columns

_SKID1, _SKID2 = 4, 8  # GripMode bits: module 1 / 2 skids back
# |K| below this fraction of r counts as a dead centre for the next-order decision (K = 0 up to roundoff
# in sin(phi) there: 1e-16 r; a crank at rest 1e-9 rad off a dead centre loads its modules 1e-9 of a stroke's)
_DEAD_CENTRE_K = 1e-9


class GripMode(IntEnum):
    """A finite-grip mode: the one-way kinematics (``self & 3``, a :class:`Mode`) and which moving modules
    skid back (bits 4: module 1, 8: module 2)."""

    BOTH_LOCKED = 0  # both stand (a static stall)
    CONTRACTION = 1  # module 1 rolls forward, module 2 stands
    EXPANSION = 2  # module 1 stands, module 2 rolls forward
    BOTH_MOVING = 3  # both roll forward
    REAR_SKIDS = 5  # module 1 skids back, module 2 stands (the gap grows)
    REAR_SKIDS_FRONT_ROLLS = 7
    FRONT_SKIDS = 10  # module 1 stands, module 2 skids back (the gap shrinks)
    FRONT_SKIDS_REAR_ROLLS = 11
    BOTH_SKID = 15

    @property
    def kinematics(self) -> Mode:
        return _KINEMATICS[self]

    @property
    def skids(self) -> tuple[bool, bool]:
        return _SKIDS[self]

    @property
    def states(self) -> tuple[int, int]:
        """Per module: +1 rolls forward, 0 stands, -1 skids back."""
        return _STATES_OF[self]


# the properties' values, looked up (the mode choice reads them some 40 times per event)
_KINEMATICS = {mode: Mode(mode & 3) for mode in GripMode}
_SKIDS = {mode: (bool(mode & _SKID1), bool(mode & _SKID2)) for mode in GripMode}
_STATES_OF = {mode: tuple(0 if held else (-1 if skid else 1) for held, skid in
                          zip((_KINEMATICS[mode].rear_locked, _KINEMATICS[mode].front_locked), _SKIDS[mode]))
              for mode in GripMode}


class GripModel:
    """Mode kinematics, accelerations, events and mode choice of the one-way-clutch robot on wheels of finite
    grip; the interface of :class:`.UnilateralModel` that :func:`.simulate_unilateral` drives."""

    def __init__(self, params: RobotParams, geometry: Geometry | str, torque=None):
        if params.grip is None:
            raise ValueError("GripModel needs a finite mu_wall; unlimited grip is UnilateralModel's")
        self.params, self.torque = params, torque
        self.grip = params.grip  # (G1, G2) [N]
        self.F = (params.F_r1, params.F_r2)
        plain = UnilateralModel(params, geometry, torque)
        self.dyn, self.linkage = plain.dyn, plain.linkage
        self._inner = {(False, False): plain}  # by skids: the one-way model with -G_i as a skidding module's F_ri
        self.constants = {}
        for mode in GripMode:
            if mode.skids not in self._inner:
                resistance = tuple(-G if s else F for s, G, F in zip(mode.skids, self.grip, self.F))
                self._inner[mode.skids] = UnilateralModel(params, geometry, torque, plain.dyn.with_resistance(resistance))
            self.constants[mode] = np.concatenate([self._inner[mode.skids].constants,
                                                   [*self.grip, *(float(s) for s in mode.states)]])

    def motor(self, t, phi, omega):
        """Motor torque [N m] (:meth:`.UnilateralModel.motor`)."""
        return self._inner[(False, False)].motor(t, phi, omega)

    def velocities(self, y, mode: GripMode):
        """(v1, v2) [m/s] of the modules in ``mode`` (its kinematics'); y = [phi, omega, x1, x2, v1, work]."""
        return self._inner[(False, False)].velocities(y, mode.kinematics)

    def motion(self, phi, omega, v1, mode: GripMode, M=None) -> dict:
        """alpha, a1, a2 and the standing modules' ground forces R1, R2 [N] (nan where moving) in ``mode``."""
        return self._inner[mode.skids].motion(phi, omega, v1, mode.kinematics, M)

    def rhs(self, mode: GripMode):
        """d/dt of the state in ``mode`` (a torque profile's path: solve_ivp)."""
        return self._inner[mode.skids].rhs(mode.kinematics)

    def kernel_call(self, mode: GripMode) -> tuple[int, int, np.ndarray]:
        """(kernel model, kernel mode, constants) with which :mod:`.dop853` integrates ``mode``."""
        return kernels.GRIP, int(mode.kinematics), self.constants[mode]

    def project(self, y, mode: GripMode, velocities) -> np.ndarray:
        """The state with the standing modules' velocities exactly zero, and so the speed of a module that
        starts to move from rest (both moving): its event then starts on its safe side (exactly 0 reads
        +tiny, :func:`.kernels.grip_guard`), and a start that reverses within the first step, shorter than
        the step's graze samples resolve, is still found as a crossing (not put at the segment's start)."""
        y = self._inner[(False, False)].project(y, mode.kinematics, velocities)
        if mode.kinematics is Mode.BOTH_MOVING:
            v = [float(x) for x in velocities]
            scale = self.linkage.r * abs(float(y[1])) + abs(v[0]) + abs(v[1])
            rest = [abs(x) <= _TOL_V * scale + _MODE_REST_FLOOR for x in v]
            K = float(self.linkage.transfer(float(y[0])).K)
            if rest[0]:
                y[4] = 0.0
            elif rest[1]:
                y[4] = -K * float(y[1])  # v2 = v1 + K omega = 0 exactly
        return y

    # --- events ----------------------------------------------------------------------------
    def _hold_margin(self, R, i):
        """min(R + F_ri, G_i - R) [N]: >= 0 while standing module i holds (floats or arrays)."""
        return np.minimum(R + self.F[i], self.grip[i] - R) if isinstance(R, np.ndarray) else \
            min(R + self.F[i], self.grip[i] - R)

    def events(self, mode: GripMode, quiet: dict[int, float] | None = None):
        """Terminal events of ``mode`` (event k watches module k) and what each means: ('velocity'|'hold', k).

        ``quiet`` {event index: time [s]}: that event reads at least +tiny until then (as in
        :meth:`.UnilateralModel.events`)."""
        quiet = quiet or {}
        found = []
        for i, state in enumerate(mode.states):
            until = quiet.get(i, -math.inf)
            if state == 0:
                def hold(t, y, i=i, until=until):
                    m = self.motion(y[0], y[1], y[4], mode, self.motor(t, y[0], y[1]))
                    value = self._hold_margin(m["R1"] if i == 0 else m["R2"], i)
                    return value if t > until else max(value, _TINY)
                event, meaning = hold, ("hold", i)
            else:
                def velocity(t, y, i=i, until=until, state=state):
                    value = state * self.velocities(y, mode)[i]
                    value = _TINY if value == 0 else value  # exactly 0 (a start from rest): the safe side
                    return value if t > until else max(value, _TINY)
                event, meaning = velocity, ("velocity", i)
            event.terminal, event.direction = True, -1.0
            found.append((event, meaning))
        return found

    def guards(self, t, Y, mode: GripMode) -> np.ndarray:
        """Every event function of ``mode`` at times t (n,) and states Y (6, n): array (2, n)."""
        if accel.ACCELERATED and self.torque is None and np.ndim(t) == 1:
            t = np.asarray(t, dtype=float)
            out = np.empty((2, t.size))
            kernels.guard_table(kernels.GRIP, int(mode.kinematics), 2, self.constants[mode], t,
                                np.ascontiguousarray(np.asarray(Y, dtype=float).T), out)
            return out
        v = self.velocities(Y, mode)
        m, rows = None, []
        for i, state in enumerate(mode.states):
            if state == 0:
                m = m or self.motion(Y[0], Y[1], Y[4], mode, self.motor(t, Y[0], Y[1]))
                rows.append(self._hold_margin(m["R1"] if i == 0 else m["R2"], i))
            else:
                value = state * v[i]
                rows.append(np.where(value == 0, _TINY, value))
        return np.array([np.broadcast_to(r, np.shape(t)) for r in rows], dtype=float)

    def graze_scan(self, sol, mode: GripMode):
        """missed_crossing's scan of ``sol`` compiled (a callable) where the guards are the kernels', else None."""
        if accel.ACCELERATED and self.torque is None and isinstance(sol, dop853.Segment):
            return lambda: sol.sol.graze_scan(kernels.GRIP, int(mode.kinematics), 2, self.constants[mode])

    # --- choosing the next mode --------------------------------------------------------------
    def choose(self, t, y, velocities, fired: tuple[str, int] | None = None,
               previous: GripMode | None = None) -> GripMode:
        """Solve the complementarity problem at time t, state ``y``, module velocities ``velocities``.

        ``fired``: the event that ended the last segment, ('velocity'|'hold', module); ``previous``: its mode.
        """
        p, r = self.params, self.linkage.r
        phi, omega = float(y[0]), float(y[1])
        M = float(self.motor(t, phi, omega))
        v = tuple(float(x) for x in velocities)
        v_scale = r * abs(omega) + abs(v[0]) + abs(v[1])
        at_rest = [abs(x) <= _TOL_V * v_scale + _MODE_REST_FLOOR for x in v]
        crank_rest = r * abs(omega) <= _TOL_V * v_scale + _MODE_REST_FLOOR
        K, dK = self._transfer(y)
        dead_centre = crank_rest and all(at_rest) and abs(K) <= _DEAD_CENTRE_K * r
        # a module at rest may roll, stand or skid (not with unlimited grip: a route's one-way clutches, RouteModel)
        options = [((1, 0, -1) if self.grip[i] < math.inf else (1, 0)) if at_rest[i] else ((1,) if v[i] > 0 else (-1,))
                   for i in (0, 1)]
        candidates = [mode for mode in GripMode if all(s in options[i] for i, s in enumerate(mode.states))]
        if GripMode.BOTH_LOCKED in candidates and (not crank_rest or (abs(K) <= 1e-12 * r and M != 0)):
            candidates.remove(GripMode.BOTH_LOCKED)  # a static hold needs the crank at rest and a torque it resists
        motions = {mode: self._motion(y, v, mode, M) for mode in candidates}
        alpha_max = max([0.0] + [abs(float(m["alpha"])) for m in motions.values()])
        a_scale = r * (omega**2 + alpha_max) + (p.F_r1 + p.F_r2 + abs(M) / r) / min(p.m1, p.m2) + abs(self.dyn.a_g)
        a_scale = max(a_scale, 1e-300)  # nothing drives the robot at all: every test is 0 / tiny = 0
        f_scale = p.F_r1 + p.F_r2 + (p.m1 + p.m2) * a_scale
        margins = {mode: self._margin(mode, motions[mode], at_rest, dead_centre, dK, a_scale, f_scale)
                   for mode in candidates}
        consistent = [mode for mode, margin in margins.items() if margin >= -_TOL_F]
        if GripMode.BOTH_LOCKED in consistent:
            return GripMode.BOTH_LOCKED  # at rest and statics holds it: accelerations unique, so it stays
        if len(consistent) > 1 and previous in consistent and fired is not None:
            consistent.remove(previous)  # its own condition is crossing its limit
        if len(consistent) > 1 and fired is not None:
            kind, i = fired
            if kind == "velocity":
                want = 0  # a module that stops stands, where it can
            else:  # a standing module's margin reached a limit: it leaves through that limit
                R = float(self._motion(y, v, previous, M)["R1" if i == 0 else "R2"])
                want = 1 if R + self.F[i] <= self.grip[i] - R else -1
            consistent = [mode for mode in consistent if mode.states[i] == want] or consistent
        if not consistent:
            raise SimulationError(
                f"no consistent clutch and grip mode at t={t:.6g} s, phi={phi:.6g} rad, omega={omega:.6g} rad/s, "
                f"v1={v[0]:.3g}, v2={v[1]:.3g} m/s (margins {({m.name: f'{x:.3g}' for m, x in margins.items()})})")
        # remaining ties hold their conditions with equality: the largest margin is the one the motion enters
        return max(consistent, key=lambda mode: margins[mode])

    def _transfer(self, y) -> tuple[float, float]:
        """(K, dK/dphi) at state ``y``: the gap's rate per crank speed with module 1 held [m/rad] and its
        derivative [m/rad^2] (the dead-centre tests of :meth:`choose`)."""
        tr = self.linkage.transfer(float(y[0]))
        return float(tr.K), float(tr.dK)

    def _motion(self, y, v: tuple[float, float], mode: GripMode, M: float) -> dict:
        """:meth:`motion` at state ``y`` with module velocities ``v`` under torque M (what :meth:`choose` asks)."""
        return self.motion(float(y[0]), float(y[1]), v[0], mode, M)

    def _margin(self, mode, m, at_rest, dead_centre, dK, a_scale, f_scale) -> float:
        """Smallest scaled condition of candidate ``mode`` with motion ``m`` (>= 0: consistent)."""
        tests = []
        single = mode.kinematics in (Mode.CONTRACTION, Mode.EXPANSION)
        for i, state in enumerate(mode.states):
            if state == 0:
                R = float(m["R1"] if i == 0 else m["R2"])
                tests += [(R + self.F[i]) / f_scale, (self.grip[i] - R) / f_scale]
            elif at_rest[i] and dead_centre and single:
                # a_i = 0 at K = 0: the next order, the free module moving as -K' (module 1) or +K' (module 2),
                # once the crank turns at all
                turns = abs(float(m["alpha"])) * self.linkage.r > _TOL_A * a_scale
                sense = -math.copysign(1.0, dK) if i == 0 else math.copysign(1.0, dK)
                tests.append(1.0 if turns and state == sense else -1.0)
            elif at_rest[i]:
                tests.append(state * float(m["a1"] if i == 0 else m["a2"]) / a_scale)
        return min(tests) if tests else math.inf

    # --- the run's columns -------------------------------------------------------------------
    def columns(self, code: int, rows: dict) -> dict[str, np.ndarray]:
        """Every series column of the samples ``rows`` (all of mode ``code``), arrays (n,)."""
        mode = GripMode(code)
        piece = _columns(self._inner[mode.skids], mode.kinematics, rows)
        shape = piece["t"].shape
        piece["mode"] = np.full(shape, int(mode.kinematics))
        for i, state in enumerate(mode.states):
            G = self.grip[i]
            if state == -1:  # locked wheels skidding: the grip, all through the clutch
                piece[f"lambda{i + 1}"] = np.full(shape, G)
                piece[f"resistance{i + 1}"] = np.zeros(shape)
            piece[f"wheels{i + 1}"] = np.full(shape, float(state))
            piece[f"grip_use{i + 1}"] = grip_use(piece[f"lambda{i + 1}"], piece[f"wheels{i + 1}"], G)
        return piece

    def energy_columns(self, series: dict) -> dict[str, np.ndarray]:
        """kinetic, potential, friction_work, slip1, slip2 and skid_work of a run's series (arrays (n,)).

        slip_i [m]: module i's backward travel so far, summed over the sample intervals that end in a skid
        (a skid segment's samples telescope to its start minus its end). friction_work = sum F_ri (x_i +
        slip_i) (its forward rolling travel) and skid_work = sum G_i slip_i [J] are exact: the forces are
        constant while a module rolls or skids."""
        out = self.dyn.energy_columns(series)
        friction, skid = 0.0, 0.0
        for i in (0, 1):
            x = np.asarray(series[f"x{i + 1}"], dtype=float)
            back = np.zeros(x.shape)
            back[1:] = np.where(series[f"wheels{i + 1}"][1:] == -1, x[:-1] - x[1:], 0.0)
            slip = np.cumsum(back)
            out[f"slip{i + 1}"] = slip
            friction = friction + self.F[i] * (x + slip)
            skid = skid + self.grip[i] * slip
        out["friction_work"], out["skid_work"] = friction, skid
        return out

    def energy_audit(self, series: dict) -> dict[str, float]:
        """Motor work = kinetic + potential energy gained + friction work + skid work + residual [J]
        (:meth:`.OneDofDynamics.energy_audit`: the table's terms the series has, skid_work among them)."""
        return self.dyn.energy_audit(series)
