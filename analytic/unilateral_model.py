"""The one-way-clutch robot's modes: kinematics, accelerations, holding forces, events and the choice of the
next mode (the complementarity problem), and every series column of a mode's samples. The event-driven run
loop that integrates it is :mod:`.unilateral_run` (whose docstring states the model and its tie rules).
"""

from __future__ import annotations

import math

import numpy as np

from ipir_mujoco.core.errors import SimulationError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.results import Mode

from . import accel, dop853, kernels
from .dynamics import OneDofDynamics
from .forces import drive_torque
from .kinematics import Geometry

HELD = {Mode.CONTRACTION: (False, True), Mode.EXPANSION: (True, False),
        Mode.BOTH_MOVING: (False, False), Mode.BOTH_LOCKED: (True, True)}
# relative tolerances of the sign tests: far above the event-location and
# dense-output error (~rtol), far below any physical margin
_TOL_V, _TOL_A, _TOL_F = 1e-8, 1e-7, 1e-7
# [m/s] the absolute floor of the mode logic's rest test (|v| <= _TOL_V * v_scale + floor): a speed below it (a
# nanometre in a quarter hour) is rest to the event logic; without a floor a crank started at 1e-12 rad/s with no
# torque is neither at rest nor able to move in any mode. A numerical zero, not core.columns.REST_SPEED (1e-6 m/s,
# the series' rest, which reads MuJoCo's soft creep as rest): this model's rest is exact, so its floor sits just
# above round-off. The compliant model's floor (compliant_state._REGIME_REST_FLOOR) is higher for its hysteresis.
_MODE_REST_FLOOR = 1e-12
_TINY = np.finfo(float).tiny  # what a quiet guard reads at least (see events)
_STATES = ("phi", "omega", "x1", "x2", "state_v1", "motor_work")  # y, as series columns (v1: not in every mode)


class UnilateralModel:
    """Mode kinematics, accelerations and holding forces of the one-way-clutch robot."""

    def __init__(self, params: RobotParams, geometry: Geometry | str, torque=None, dyn: OneDofDynamics | None = None):
        self.params = params
        self.dyn = OneDofDynamics(params, geometry) if dyn is None else dyn  # given: another resistance (.grip)
        self.linkage = self.dyn.linkage
        self.torque = torque  # (t, phi, omega) -> N m, or None for the drive of params
        self.constants = kernels.pack(self.dyn)  # the scalar kernels' copy of the constants
        self.u = 1.0  # the motor's voltage fraction (drive = servo: the controller's, set by set_u)

    def set_u(self, u: float) -> None:
        """The speed controller's u from now on (drive = servo): the kernels' and the Python path's."""
        self.u = float(u)
        self.constants[kernels.P_U] = self.u

    def motor(self, t, phi, omega):
        """Motor torque [N m] at time t (array-friendly)."""
        if self.torque is None:
            if isinstance(phi, float):  # one state (the event loop): the same sum without a numpy call
                return drive_torque(self.params, omega, self.u) + 0.0 * phi
            return drive_torque(self.params, omega, self.u) + 0.0 * np.asarray(phi, dtype=float)
        return self.torque(t, phi, omega)

    # --- the state in each mode: y = [phi, omega, x1, x2, v1] ---------------------------
    def velocities(self, y, mode: Mode):
        """(v1, v2) [m/s] of the modules in ``mode``."""
        K = self.linkage.transfer(y[0]).K
        if mode is Mode.CONTRACTION:
            return -K * y[1], 0.0 * K
        if mode is Mode.EXPANSION:
            return 0.0 * K, K * y[1]
        if mode is Mode.BOTH_MOVING:
            return y[4], y[4] + K * y[1]
        return 0.0 * K, 0.0 * K

    def motion(self, phi, omega, v1, mode: Mode, M=None) -> dict:
        """alpha, a1, a2 and holding forces R1, R2 (nan where not held) in ``mode``; M [N m] the torque."""
        M = self.dyn.torque(omega, M)
        if (isinstance(phi, float) and isinstance(M, float) or np.ndim(phi) == 0 and np.ndim(M) == 0) \
                and mode is not Mode.BOTH_LOCKED:  # one state: the scalar kernels
            alpha, a1, a2, R1, R2 = kernels.mode_motion(self.constants, int(mode), float(phi), float(omega), float(M))
            return {"alpha": alpha, "a1": a1, "a2": a2, "R1": R1, "R2": R2}
        nan = np.nan * np.asarray(phi, dtype=float)
        if mode in (Mode.CONTRACTION, Mode.EXPANSION):
            st = self.dyn.state(phi, omega, mode, M)
            R1 = st.lambda1 if mode is Mode.EXPANSION else nan
            R2 = st.lambda2 if mode is Mode.CONTRACTION else nan
            return {"alpha": st.alpha, "a1": st.a1, "a2": st.a2, "R1": R1, "R2": R2}
        if mode is Mode.BOTH_MOVING:
            a1, alpha = self.dyn.both_moving(phi, omega, M)
            tr = self.linkage.transfer(phi)
            return {"alpha": alpha, "a1": a1, "a2": a1 + tr.dK * omega**2 + tr.K * alpha, "R1": nan, "R2": nan}
        # static stall: the holds balance the torque (through the linkage) and gravity
        R1, R2 = self.dyn.static_holds(phi, M)
        zero = np.zeros_like(nan)
        return {"alpha": zero, "a1": zero, "a2": zero, "R1": R1, "R2": R2}

    def rhs(self, mode: Mode):
        """d/dt of y = [phi, omega, x1, x2, v1, motor work]: only what integration needs (hot path)."""
        dyn, linkage, constant, params = self.dyn, self.linkage, self.torque is None, self.params

        def f(t, y):
            phi, omega, _x1, _x2, v1, _work = y
            M = drive_torque(params, omega) if constant else self.torque(t, phi, omega)
            tr = linkage.transfer(phi)
            if mode is Mode.BOTH_MOVING:
                a1, alpha = dyn.both_moving(phi, omega, M)
                return [omega, alpha, v1, v1 + tr.K * omega, a1, M * omega]
            alpha = dyn.acceleration(phi, omega, mode, M)
            if mode is Mode.CONTRACTION:  # front held: x1_dot = -K omega
                return [omega, alpha, -tr.K * omega, 0.0, -(tr.dK * omega**2 + tr.K * alpha), M * omega]
            return [omega, alpha, 0.0, tr.K * omega, 0.0, M * omega]  # expansion: rear held
        return f

    def events(self, mode: Mode, quiet: dict[int, float] | None = None):
        """Terminal events of ``mode`` and what each means: ('velocity'|'margin', module index).

        ``quiet`` {event index: time [s]}: that event reads at least +tiny until that time
        (see :func:`.solver_support.spurious_start`).
        """
        p = self.params
        quiet = quiet or {}
        found = []
        for i in (0, 1):
            until = quiet.get(len(found), -math.inf)
            if HELD[mode][i]:
                def margin(t, y, i=i, until=until):
                    m = self.motion(y[0], y[1], y[4], mode, self.motor(t, y[0], y[1]))
                    value = (m["R1"] if i == 0 else m["R2"]) + (p.F_r1 if i == 0 else p.F_r2)
                    return value if t > until else max(value, _TINY)
                margin.terminal, margin.direction = True, -1.0
                found.append((margin, ("margin", i)))
            else:
                def velocity(t, y, i=i, until=until):
                    value = self.velocities(y, mode)[i]
                    return value if t > until else max(value, _TINY)
                velocity.terminal, velocity.direction = True, -1.0
                found.append((velocity, ("velocity", i)))
        return found

    def guards(self, t, Y, mode: Mode) -> np.ndarray:
        """Every event function of ``mode`` at times t (n,) and states Y (6, n): array (n_events, n)."""
        if accel.ACCELERATED and self.torque is None and np.ndim(t) == 1:  # compiled: no numpy calls per segment
            t = np.asarray(t, dtype=float)
            out = np.empty((2, t.size))
            kernels.guard_table(kernels.UNILATERAL, int(mode), 2, self.constants, t,
                                np.ascontiguousarray(np.asarray(Y, dtype=float).T), out)
            return out
        p = self.params
        v1, v2 = self.velocities(Y, mode)
        m = None
        rows = []
        for i in (0, 1):
            if HELD[mode][i]:
                if m is None:
                    m = self.motion(Y[0], Y[1], Y[4], mode, self.motor(t, Y[0], Y[1]))
                rows.append((m["R1"] if i == 0 else m["R2"]) + (p.F_r1 if i == 0 else p.F_r2))
            else:
                rows.append(v1 if i == 0 else v2)
        return np.array([np.broadcast_to(r, np.shape(t)) for r in rows], dtype=float)

    def graze_scan(self, sol, mode: Mode):
        """missed_crossing's scan of ``sol`` compiled (a callable) where the guards are the kernels', else None."""
        if accel.ACCELERATED and self.torque is None and isinstance(sol, dop853.Segment):
            return lambda: sol.sol.graze_scan(kernels.UNILATERAL, int(mode), 2, self.constants)

    # --- choosing the next mode ----------------------------------------------------------
    def choose(self, t, y, velocities, fired: tuple[str, int] | None = None, previous: Mode | None = None) -> Mode:
        """Solve the complementarity problem at time t, state ``y``, module velocities ``velocities``."""
        p, r = self.params, self.linkage.r
        phi, omega = float(y[0]), float(y[1])
        M = float(self.motor(t, phi, omega))
        v1, v2 = (float(v) for v in velocities)
        v_scale = r * abs(omega) + abs(v1) + abs(v2)
        at_rest = [abs(v) <= _TOL_V * v_scale + _MODE_REST_FLOOR for v in (v1, v2)]
        if not at_rest[0] and v1 < 0 or not at_rest[1] and v2 < 0:
            raise SimulationError(f"a module moves backward (v1={v1:.3g}, v2={v2:.3g} m/s) at phi={phi:.6g}")
        # the static hold (alpha = 0, the 0.0 below) is computed further down, only where it is a candidate
        motions = {mode: self.motion(phi, omega, v1, mode, M) for mode in Mode if mode is not Mode.BOTH_LOCKED}
        a_scale = r * (omega**2 + max(0.0, *(abs(m["alpha"]) for m in motions.values()))) \
            + (p.F_r1 + p.F_r2 + abs(M) / r) / min(p.m1, p.m2) + abs(self.dyn.a_g)
        a_scale = max(a_scale, 1e-300)  # nothing drives the robot at all: every test is 0 / tiny = 0
        f_scale = p.F_r1 + p.F_r2 + (p.m1 + p.m2) * a_scale
        F = (p.F_r1, p.F_r2)

        margins = {}
        for mode, held in HELD.items():
            if any(h and not z for h, z in zip(held, at_rest)):
                continue  # a held module must stand still
            if mode is Mode.BOTH_LOCKED and (r * abs(omega) > _TOL_V * v_scale + _MODE_REST_FLOOR
                                             or (abs(self.linkage.transfer(phi).K) <= 1e-12 * r and M != 0)):
                continue  # a static hold needs the crank at rest, and a torque the linkage can resist
            m = motions[mode] if mode in motions else self.motion(phi, omega, v1, mode, M)
            tests = []
            for i in (0, 1):
                if held[i]:
                    tests.append(((m["R1"], m["R2"])[i] + F[i]) / f_scale)
                elif at_rest[i]:
                    tests.append((m["a1"], m["a2"])[i] / a_scale)
            margins[mode] = min(tests) if tests else math.inf
        consistent = [mode for mode, margin in margins.items() if margin >= -_TOL_F]
        if Mode.BOTH_LOCKED in consistent:
            # at rest and statics can hold it: every motion candidate then has zero
            # acceleration at best (uniqueness of the complementarity solution), so
            # nothing drives the robot out of rest
            return Mode.BOTH_LOCKED
        if len(consistent) > 1 and previous in consistent and fired is not None:
            consistent.remove(previous)
        if len(consistent) > 1 and fired is not None:
            kind, i = fired
            keep = [m for m in consistent if HELD[m][i] == (kind == "velocity")]
            consistent = keep or consistent
        if len(consistent) > 1 and {Mode.CONTRACTION, Mode.EXPANSION} <= set(consistent):
            consistent = [Mode.CONTRACTION if self.linkage.transfer(phi).dK < 0 else Mode.EXPANSION]
        if len(consistent) > 1:
            # remaining ties: every candidate holds its conditions with equality; the
            # one with the largest margin is the one the motion moves into
            consistent = [max(consistent, key=lambda mode: margins[mode])]
        if not consistent:
            raise SimulationError(
                f"no consistent clutch mode at phi={phi:.6g} rad, omega={omega:.6g} rad/s, "
                f"v1={v1:.3g}, v2={v2:.3g} m/s (margins {({m.name: f'{v:.3g}' for m, v in margins.items()})})")
        return consistent[0]

    def kernel_call(self, mode: Mode) -> tuple[int, int, np.ndarray]:
        """(kernel model, kernel mode, constants) with which :mod:`.dop853` integrates ``mode``."""
        return kernels.UNILATERAL, int(mode), self.constants

    def columns(self, mode: int, rows: dict) -> dict[str, np.ndarray]:
        """Every series column of the samples ``rows`` of one mode (see :func:`_columns`)."""
        return _columns(self, Mode(mode), rows)

    def energy_columns(self, series: dict) -> dict[str, np.ndarray]:
        """The cumulative energy columns of a run's series (:meth:`.OneDofDynamics.energy_columns`)."""
        return self.dyn.energy_columns(series)

    def energy_audit(self, series: dict) -> dict[str, float]:
        """The run's energy audit [J] (:meth:`.OneDofDynamics.energy_audit`)."""
        return self.dyn.energy_audit(series)

    def project(self, y, mode: Mode, velocities) -> np.ndarray:
        """The state with the mode's constraints exact (held velocities zero)."""
        y = np.array(y, dtype=float)
        K = float(self.linkage.transfer(y[0]).K)
        if mode is Mode.CONTRACTION:
            y[4] = -K * y[1]
        elif mode is Mode.EXPANSION:
            y[4] = 0.0
        elif mode is Mode.BOTH_MOVING:
            y[4] = float(velocities[0])
        else:
            y[1], y[4] = 0.0, 0.0
        return y


def _columns(model: UnilateralModel, mode: Mode, rows: dict) -> dict[str, np.ndarray]:
    """Every column of the samples ``rows`` (:data:`_STATES` and ``mode``) of one mode."""
    times, phi, omega = rows["t"], rows["phi"], rows["omega"]
    y = (phi, omega, rows["x1"], rows["x2"], rows["state_v1"], rows["motor_work"])  # phi itself: see reusing
    v1, v2 = model.velocities(y, mode)
    v1 = np.broadcast_to(v1, phi.shape).astype(float)
    v2 = np.broadcast_to(v2, phi.shape).astype(float)
    if "drive_u" in rows:  # drive = servo: each sample's u, held between the controller's ticks
        M = drive_torque(model.params, omega, rows["drive_u"]) + 0.0 * phi
    else:
        M = np.broadcast_to(model.motor(times, phi, omega), phi.shape).astype(float)
    m = model.motion(phi, omega, v1, mode, M)
    tr = model.linkage.transfer(phi)
    F = (model.params.F_r1, model.params.F_r2)
    held = HELD[mode]
    clutch, resistance = [], []
    for i, R in enumerate((m["R1"], m["R2"])):
        R = np.broadcast_to(R, phi.shape)
        clutch.append(np.maximum(R, 0.0) if held[i] else np.zeros(phi.shape))
        resistance.append(np.minimum(R, 0.0) if held[i] else np.full(phi.shape, -F[i]))
    piece = {
        "t": times, "phi": phi, "omega": omega, "alpha": np.broadcast_to(m["alpha"], phi.shape).astype(float),
        "x1": y[2], "x2": y[3], "v1": v1, "v2": v2,
        "a1": np.broadcast_to(m["a1"], phi.shape).astype(float), "a2": np.broadcast_to(m["a2"], phi.shape).astype(float),
        "S": tr.S, "S_dot": tr.K * omega, "lambda1": clutch[0], "lambda2": clutch[1],
        "mode": rows["mode"], "resistance1": resistance[0], "resistance2": resistance[1],
        "motor_work": y[5], "motor_torque": M,
    }
    if "drive_u" in rows:
        piece["drive_u"] = rows["drive_u"]
    return piece
