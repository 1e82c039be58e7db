"""One-way clutches with stiffness, damping and backlash: the compliant clutch model.

Each module's one-way clutch has an *anchor* that ratchets forward with the
module: anchor_i = (running maximum of x_i) - clutch_backlash. Where the module
has gone back past its anchor (overlap d_i = anchor_i - x_i > 0) the clutch
pushes it forward with k d_i + c (-v_i), never pulling (the force is clipped
at 0). k = clutch_stiffness [N/m], c = clutch_damping [N s/m].

Two degrees of freedom, q = (x1, phi); x2 = x1 + S(phi) - S(phi0) through the
linkage; mass matrix of :meth:`OneDofDynamics.mass_terms` (exact geometry: with
the rod's mass and inertia). Lagrange's equations:

    M11 a1 + M12 alpha + M12' omega^2       = F1 + F2 + M11 g_x
    M12 a1 + M22 alpha + 1/2 M22' omega^2   = T(omega) + K F2 + M12 g_x

where F_i = clutch force + friction on module i, T the drive torque
(:func:`forces.drive_torque`), g_x = gravity along the pipe
(:func:`forces.gravity_along_pipe`; its generalized force is [M11, M12] g_x
because the robot's centre of mass moves with x1 and, through the linkage,
with phi exactly as the mass terms say).

Each module's resistance F_ri is Coulomb friction: -F_ri sign(v_i) while it
slides either way, and at rest whatever force in [-F_ri, F_ri] keeps it at
rest. Everything that switches is a discrete *regime*, fixed between events,
so the right-hand side is smooth in each segment:

* friction of module i: sliding forward (+1), backward (-1) or stuck (0; its
  velocity constraint v_i = 0 holds, and the friction it needs, R_i, is solved
  for with the accelerations);
* clutch of module i: TRACKING (at its running maximum: the anchor moves with
  it, no force), FREE (behind its maximum but inside the backlash, d_i <= 0),
  ENGAGED (d_i > 0 and k d_i - c v_i > 0: force k d_i - c v_i) or CLIPPED
  (d_i > 0 but k d_i - c v_i <= 0: a damper that would pull, so no force);
  with finite grip also SLIDING (the force would exceed the grip G_i: the
  anchor slides back and the force is G_i, :mod:`.compliant_grip`).

Events end a segment where a sliding module's velocity reaches zero, a stuck
module's needed friction reaches F_ri (|R_i| = F_ri), an overlap or a clipped
force crosses zero, or a module reaches its running maximum again. At a
velocity zero, stick or slip is decided by enumerating the friction states of
the modules at rest: stuck needs |R_i| <= F_ri, sliding in direction s needs
s a_i >= 0. Friction along one axis with a positive-definite mass matrix makes
the accelerations unique (they minimise a strictly convex function), so the
consistent choices differ only on the boundary; there the event that fired
decides (a margin that reached F_ri lets go, a velocity that reached zero
sticks), and on a dead centre at rest the gap's second-order motion
K' (phi - phi0)^2 / 2 decides, as for the rigid one-way clutch.

Energy: the clutch springs store 1/2 k d_i^2 (d_i > 0); what the clutch takes
from the module and does not store is dissipated, at the rate
v_i (k d_i - f_i) >= 0: c v_i^2 while ENGAGED, k d_i v_i while CLIPPED (the
spring relaxes faster than the damper lets it push).
"""

from __future__ import annotations

import math

import numpy as np

from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.params import RobotParams

from . import compliant_grip, kernels
from .compliant_state import (_DEAD_CENTRE_STEP, _HYSTERESIS_FORCE, _HYSTERESIS_OVERLAP, _HYSTERESIS_SPEED,
                               _REGIME_REST_FLOOR, _TOL_F, _TOL_V, Clutch, Motion, Regime)
from .dynamics import MassTerms, OneDofDynamics
from .forces import drive_torque, gravity_along_pipe
from .kinematics import Geometry, Transfer


class CompliantModel:
    """Accelerations, events and regime decisions of the robot with compliant one-way clutches.

    State y = [phi, omega, x1, v1, motor work, friction work, damper work] (rad, rad/s, m, m/s, J, J, J).
    """

    def __init__(self, params: RobotParams, geometry: Geometry | str):
        self.params = params
        self.dyn = OneDofDynamics(params, geometry)
        self.linkage = self.dyn.linkage
        self.S0 = float(self.linkage.gap(params.phi0))
        self.k = float(params.clutch_stiffness)
        self.c = params.clutch_damping
        self.delta = params.clutch_backlash
        self.g = gravity_along_pipe(params)
        self.F = (params.F_r1, params.F_r2)
        self.grip = params.grip or (math.inf, math.inf)  # [N] each clutch's anchor holds at most this
        self.base = kernels.pack(self.dyn)

    # --- dynamics in a regime ------------------------------------------------------------
    def overlaps(self, x, regime: Regime) -> tuple:
        """d_i = anchor_i - x_i [m] for positions x = (x1, x2); a TRACKING module sits at its maximum."""
        return tuple(-self.delta + 0.0 * xi if c is Clutch.TRACKING else peak - self.delta - xi
                     for xi, c, peak in zip(x, regime.clutch, regime.peak))

    def motion(self, y, regime: Regime) -> Motion:
        """Accelerations and forces at state(s) ``y`` (7,) or (7, n) in ``regime`` (vectorized)."""
        if np.ndim(y[0]) == 0:  # one state: the scalar kernels, the same equations
            m = kernels.compliant_motion(self.constants(regime), np.asarray(y, dtype=float))
            return Motion(*m[:5], m[5:7], m[7:9], m[9:11], m[11], MassTerms(*m[12:17], Transfer(*m[17:])))
        phi, omega, x1, v1 = y[0], y[1], y[2], y[3]
        mt = self.dyn.mass_terms(phi)
        K, dK = mt.transfer.K, mt.transfer.dK
        x2, v2 = x1 + mt.transfer.S - self.S0, v1 + K * omega
        d = self.overlaps((x1, x2), regime)
        f = tuple(self.k * di - self.c * vi if c is Clutch.ENGAGED else (G + 0.0 * di if c is Clutch.SLIDING else 0.0 * di)
                  for di, vi, c, G in zip(d, (v1, v2), regime.clutch, self.grip))
        sliding = tuple(-s * F + 0.0 * di for s, F, di in zip(regime.slip, self.F, d))  # 0 where stuck
        torque = drive_torque(self.params, omega)
        w2 = omega * omega
        F1, F2 = f[0] + sliding[0], f[1] + sliding[1]
        b1 = F1 + F2 + mt.m11 * self.g - mt.dm12 * w2
        b2 = torque + K * F2 + mt.m12 * self.g - 0.5 * mt.dm22 * w2
        s1, s2 = regime.slip
        if s1 and s2:
            det = mt.m11 * mt.m22 - mt.m12**2
            a1, alpha = (mt.m22 * b1 - mt.m12 * b2) / det, (mt.m11 * b2 - mt.m12 * b1) / det
            friction = sliding
        elif s2:  # module 1 stuck: a1 = 0
            a1, alpha = 0.0 * b1, b2 / mt.m22
            friction = (mt.m12 * alpha - b1, sliding[1])
        elif s1:  # module 2 stuck: x1 = x2 - S, so a1 = -K alpha - K' omega^2 (project onto N = [-K, 1])
            jeff = mt.m11 * K**2 - 2.0 * mt.m12 * K + mt.m22
            alpha = (b2 - K * b1 + (mt.m12 - K * mt.m11) * dK * w2) / jeff
            a1 = -K * alpha - dK * w2
            friction = (sliding[0], mt.m11 * a1 + mt.m12 * alpha - b1)
        else:  # both stuck: statics (the crank is at rest, K != 0: see decide)
            a1, alpha = 0.0 * b1, 0.0 * b1
            R2 = np.where(K != 0, -b2 / np.where(K != 0, K, 1.0), 0.0)  # on a dead centre only at rest, unloaded
            friction = (-b1 - R2, R2)
        a2 = a1 + dK * w2 + K * alpha
        return Motion(alpha, a1, a2, x2, v2, f, d, friction, torque, mt)

    def rhs(self, regime: Regime):
        """d/dt y in ``regime`` (the hot path of the integration)."""
        F1, F2 = self.F
        s1, s2 = regime.slip
        c, k = self.c, self.k
        clutch = regime.clutch

        def f(_t, y):
            m = self.motion(y, regime)
            v = (y[3], m.v2)
            damper = 0.0
            for i in (0, 1):
                if clutch[i] is Clutch.ENGAGED:
                    damper += c * v[i] * v[i]
                elif clutch[i] is Clutch.CLIPPED:
                    damper += k * m.overlap[i] * v[i]
            return [y[1], m.alpha, y[3], m.a1, m.torque * y[1], s1 * F1 * v[0] + s2 * F2 * v[1], damper]
        return f

    def constants(self, regime: Regime, events: list = (), t0: float = math.nan) -> np.ndarray:
        """The kernels' constants (:data:`.kernels.P_K` on) for ``regime`` and ``events`` (:meth:`events`) from t0."""
        head = [self.k, self.c, self.delta, self.S0, *regime.slip, *(int(c) for c in regime.clutch), *regime.peak, t0,
                *compliant_grip.head(self.grip, regime.slide)]
        return np.concatenate([self.base, head, [x for _, raw, _ in events for x in raw.code]])

    # --- events --------------------------------------------------------------------------
    def events(self, regime: Regime, next_revolution: float, t0: float) -> list:
        """Terminal events of ``regime`` from time ``t0``: [(function for solve_ivp, raw function, (kind, module))].

        The raw functions are vectorized (times (n,), states (7, n)) for the check of crossings that
        solve_ivp missed inside a step.

        Kinds: 'velocity' (a sliding module stops), 'margin' (a stuck module's friction reaches F_ri),
        'engage', 'release', 'clip', 'track', 'grip', 'stick' (clutch changes; the last two: the anchor
        slides, stops, :func:`.compliant_grip.add_events`) and 'revolution' (the crank's running
        maximum reaches the next whole turn; nothing changes there, the run just samples it).

        A segment starts where some function just crossed zero, so at ``t0`` one is zero or a rounding
        error from it, and near t0 it may stay there for a while (a position of 0.1 m changes in steps
        of 1.4e-17 m). solve_ivp would then take a point of that plateau as the root (brentq returns a
        point where the function is exactly zero) and end the segment at once, again and again, or
        miss a crossing that starts a hair on the wrong side. So each switch has a small hysteresis
        (_HYSTERESIS_* below: far below any physical size, far above rounding), exact zeros count as
        the safe side, and at t0 itself every function reports the safe side: the first real crossing
        after t0 is found, and a regime that is wrong from the start still ends at once.
        """
        found = []
        eps_d, eps_v = _HYSTERESIS_OVERLAP, _HYSTERESIS_SPEED

        def add(kind, i, direction, fn, code, offset=0.0):  # code, offset: the kernels' form (kernels.compliant_guard)
            def guarded(t, y):
                value = fn(t, y)
                return -direction * 1e-300 if value == 0 or (t == t0 and direction * value > 0) else value
            guarded.terminal, guarded.direction = True, direction
            fn.direction, fn.code = direction, (code, i, direction, offset)
            found.append((guarded, fn, (kind, i)))

        for i in (0, 1):
            s, c = regime.slip[i], regime.clutch[i]
            if s == 0:  # |R_i| exceeds F_ri
                eps_f = _HYSTERESIS_FORCE * max(1.0, self.F[i])
                add("margin", i, -1.0, lambda t, y, i=i, e=eps_f: self.F[i] + e - abs(self.motion(y, regime).friction[i]),
                    kernels.EV_MARGIN, self.F[i] + eps_f)
                compliant_grip.add_events(self, regime, i, add, eps_v)  # a slide goes on
                continue  # a stuck module's overlap and velocity are constant: no clutch event
            # s v falls below -eps_v: the module has stopped and turned
            add("velocity", i, -1.0, lambda t, y, i=i, s=s: s * (y[3] if i == 0 else self.velocity2(y)) + eps_v,
                kernels.EV_VELOCITY, eps_v)
            if c is Clutch.FREE:
                add("engage", i, 1.0, lambda t, y, i=i: self._overlap(y, regime, i) - eps_d, kernels.EV_OVERLAP, -eps_d)
                if self.delta > 0:
                    add("track", i, 1.0, lambda t, y, i=i: self._position(y, i) - regime.peak[i] - eps_d,
                        kernels.EV_TRACK, -eps_d)
            elif c is Clutch.ENGAGED:
                add("release", i, -1.0, lambda t, y, i=i: self._overlap(y, regime, i), kernels.EV_OVERLAP)
                if self.c > 0:
                    add("clip", i, -1.0, lambda t, y, i=i: self._push(y, regime, i), kernels.EV_PUSH)
            elif c is Clutch.CLIPPED:
                add("engage", i, 1.0, lambda t, y, i=i: self._push(y, regime, i) - self.k * eps_d, kernels.EV_PUSH,
                    -(self.k * eps_d))
                add("release", i, -1.0, lambda t, y, i=i: self._overlap(y, regime, i), kernels.EV_OVERLAP)
            compliant_grip.add_events(self, regime, i, add, eps_v)
        add("revolution", -1, 1.0, lambda t, y: y[0] - next_revolution, kernels.EV_PHI, -next_revolution)
        return found

    def velocity2(self, y):
        return y[3] + self.linkage.transfer(y[0]).K * y[1]

    def _position(self, y, i):
        return y[2] if i == 0 else y[2] + self.linkage.gap(y[0]) - self.S0

    def _overlap(self, y, regime, i):
        return regime.peak[i] - self.delta - self._position(y, i)

    def _push(self, y, regime, i):
        """k d - c v of module i: the force an ENGAGED clutch applies, before clipping."""
        v = y[3] if i == 0 else self.velocity2(y)
        return self.k * self._overlap(y, regime, i) - self.c * v

    # --- deciding the next regime --------------------------------------------------------
    def decide(self, t: float, y, regime: Regime, fired: tuple[str, int] | None) -> tuple[Regime, np.ndarray]:
        """The regime after an event (``fired``; None at the start) at state ``y``, and the state projected
        onto its constraints (stuck velocities exactly zero)."""
        y = np.array(y, dtype=float)
        r = self.linkage.r
        x = (y[2], self._position(y, 1))
        v = (y[3], self.velocity2(y))
        # running maxima: a TRACKING module's maximum is where it is now
        peak = tuple(max(pk, xi) if c is Clutch.TRACKING else pk for pk, xi, c in zip(regime.peak, x, regime.clutch))
        clutch = list(regime.clutch)
        if fired is not None and fired[0] in ("engage", "release", "clip", "track"):
            kind, i = fired
            clutch[i] = {"engage": Clutch.ENGAGED, "clip": Clutch.CLIPPED, "track": Clutch.TRACKING,
                         "release": Clutch.TRACKING if self.delta == 0 else Clutch.FREE}[kind]
            if clutch[i] is Clutch.TRACKING:
                peak = tuple(max(pk, x[j]) if j == i else pk for j, pk in enumerate(peak))
        peak, slide = list(peak), list(regime.slide)
        compliant_grip.transitions(self, t, y, fired, clutch, peak, slide)  # an anchor slides, stops
        peak = tuple(peak)
        omega = float(y[1])
        v_scale = r * abs(omega) + abs(v[0]) + abs(v[1])
        rest = [regime.slip[i] == 0 or fired == ("velocity", i) or abs(v[i]) <= _TOL_V * v_scale + _REGIME_REST_FLOOR
                for i in (0, 1)]
        for i in (0, 1):
            overlap = self.overlaps(x, Regime(regime.slip, tuple(clutch), peak))[i]
            if rest[i] and clutch[i] is Clutch.CLIPPED:
                clutch[i] = Clutch.ENGAGED  # at rest k d - c v = k d > 0
            if rest[i] and clutch[i] is Clutch.FREE and overlap > 0:
                clutch[i] = Clutch.ENGAGED
        crank_rest = abs(omega) * r <= _TOL_V * v_scale + _REGIME_REST_FLOOR
        if all(rest) and crank_rest and abs(float(self.linkage.transfer(y[0]).K)) <= 1e-9 * r:
            slip = self._dead_centre_start(t, y, tuple(clutch), peak)
        else:
            slip = self._enumerate(t, y, tuple(clutch), peak, rest, crank_rest, fired)
        peak = list(peak)
        for i in (0, 1):
            if slip[i] == -1 and clutch[i] is Clutch.TRACKING:  # leaves its maximum backward
                clutch[i] = Clutch.ENGAGED if self.delta == 0 else Clutch.FREE
                if self.delta == 0:  # engaged from the start: the hysteresis as if it had come from FREE
                    peak[i] = x[i] + _HYSTERESIS_OVERLAP
        chosen = Regime(slip, tuple(clutch), tuple(peak), tuple(slide))
        y = self.project(y, chosen)
        chosen = compliant_grip.start_slides(self, t, y, chosen, fired)  # engaged beyond the grip
        return chosen, y

    def _enumerate(self, t, y, clutch, peak, rest, crank_rest, fired) -> tuple[int, int]:
        """The consistent friction states of the modules at rest (unique but on a boundary, see the module
        docstring); the event that fired, then the largest margin, break ties."""
        v = (y[3], self.velocity2(y))
        options = [(0, 1, -1) if rest[i] else (1 if v[i] > 0 else -1,) for i in (0, 1)]
        candidates = {}
        for slip in ((a, b) for a in options[0] for b in options[1]):
            if slip == (0, 0) and not crank_rest:
                continue  # both stuck is a static hold: the crank at rest
            trial = Regime(slip, clutch, peak)
            candidates[slip] = self.motion(self.project(y, trial), trial)
        margins = self._margins(candidates, rest, y)
        consistent = [s for s, m in margins.items() if m >= -_TOL_F]
        if len(consistent) > 1 and fired is not None and fired[0] in ("margin", "velocity"):
            kind, i = fired
            keep = [s for s in consistent if (s[i] == 0) == (kind == "velocity")]
            consistent = keep or consistent
        if not consistent:
            raise SimulationError(
                f"no consistent stick/slip state at t={t:.6g} s (phi={float(y[0]):.6g} rad, "
                f"v1={v[0]:.3g}, v2={v[1]:.3g} m/s; margins {({s: f'{m:.3g}' for s, m in margins.items()})})")
        return max(consistent, key=lambda s: margins[s])

    def _dead_centre_start(self, t, y, clutch, peak) -> tuple[int, int]:
        """Friction states from rest on a dead centre (K = 0), where every motion starts with zero module
        accelerations and forces, so every candidate ties: decided where the crank is a small angle
        _DEAD_CENTRE_STEP further on, at rest (the gap's motion K' (phi - phi0)^2 / 2 is what
        loads the modules), with the clutch overlaps kept as they are."""
        free_crank = self.motion(y, Regime((0, 1), clutch, peak)).alpha  # module 1 at rest, K = 0: M22 alpha = T
        if abs(float(free_crank)) * self.linkage.r <= 1e-12:  # [m/s^2] at the crank pin: no drive at all
            # the crank stays, and only gravity and the clutches load the modules: the friction states at rest
            return self._enumerate(t, y, clutch, peak, [True, True], True, None)
        step = math.copysign(_DEAD_CENTRE_STEP, float(free_crank))
        ahead = np.array(y, dtype=float)
        ahead[0] += step
        shift = float(self.linkage.gap(ahead[0]) - self.linkage.gap(y[0]))  # x2 moves with S at fixed x1
        peak_ahead = (peak[0], peak[1] + shift)
        candidates = {}
        for slip in ((a, b) for a in (0, 1, -1) for b in (0, 1, -1)):
            trial = Regime(slip, clutch, peak_ahead)
            candidates[slip] = self.motion(ahead, trial)
        margins = self._margins(candidates, [True, True], ahead)
        best = max(margins, key=lambda s: margins[s])
        if margins[best] < 0:
            raise SimulationError(f"no consistent stick/slip state starting from rest on a dead centre at "
                                  f"t={t:.6g} s (phi={float(y[0]):.6g} rad)")
        return best

    def _margins(self, candidates: dict, rest: list, y) -> dict:
        """Smallest scaled condition of each candidate: stuck |R_i| <= F_ri, sliding s a_i >= 0 (>= 0: consistent)."""
        p, r = self.params, self.linkage.r
        motions = list(candidates.values())
        if not motions:
            return {}
        forces = max(abs(float(fi)) for m in motions for fi in m.force)
        torque = abs(float(motions[0].torque))
        alpha = max(abs(float(m.alpha)) for m in motions)
        mass = p.m1 + p.m2 + p.rod_mass
        a_scale = r * (float(y[1]) ** 2 + alpha) + (sum(self.F) + torque / r + 2 * forces + mass * abs(self.g)) \
            / min(p.m1, p.m2)
        a_scale = max(a_scale, 1e-300)  # nothing drives the robot: every test is 0 / tiny = 0
        f_scale = sum(self.F) + 2 * forces + mass * a_scale
        out = {}
        for slip, m in candidates.items():
            tests = []
            for i in (0, 1):
                if slip[i] == 0:
                    tests.append((self.F[i] - abs(float(m.friction[i]))) / f_scale)
                elif rest[i]:
                    tests.append(slip[i] * float((m.a1, m.a2)[i]) / a_scale)
            out[slip] = min(tests) if tests else math.inf
        return out

    def project(self, y, regime: Regime) -> np.ndarray:
        """The state with the stuck modules' velocities exactly zero."""
        y = np.array(y, dtype=float)
        s1, s2 = regime.slip
        if s1 == 0:
            y[3] = 0.0
        if s1 == 0 and s2 == 0:
            y[1] = 0.0
        elif s2 == 0:
            y[3] = -float(self.linkage.transfer(y[0]).K) * y[1]
        return y
