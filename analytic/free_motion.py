"""The robot with no clutches and no resistance: both modules slide freely.

Two degrees of freedom (x1, phi) with the mass matrix of
:meth:`ipir_mujoco.analytic.dynamics.OneDofDynamics.mass_terms`:

    M11 x1_ddot + M12 alpha + M12' omega^2       = M11 a_g
    M12 x1_ddot + M22 alpha + 1/2 M22' omega^2   = M(omega) + M12 a_g

The first row is the momentum balance along the pipe: nothing outside the robot
pushes along x but gravity (a_g, zero in a horizontal pipe). M(omega) is the
drive's torque. A check case for the physics engine, not a robot that walks (it
only shakes in place, or falls).
"""

from __future__ import annotations

import math
import time

import numpy as np

from ipir_mujoco.core.errors import ParameterError, SimulationError
from ipir_mujoco.core.params import RobotParams
from ipir_mujoco.core.options import check_run_options
from ipir_mujoco.core.results import Mode, RunResult

from .dynamics import OneDofDynamics
from .solver_support import check_tolerances
from .kinematics import Geometry
from .kinetostatics import add_kinetostatics


def free_accelerations(dyn: OneDofDynamics, phi, omega):
    """(x1_ddot [m/s^2], alpha [rad/s^2]) of the free mechanism (F_r1 = F_r2 = 0), under the drive and gravity."""
    return dyn.both_moving(phi, omega)


def simulate_free(params: RobotParams, geometry: Geometry | str = Geometry.EXACT, t_end: float = 1.0, *,
                  dt_out: float = 1e-4, rtol: float = 1e-10, atol: float = 1e-12) -> RunResult:
    """Simulate the clutch-free, resistance-free mechanism from (phi0, omega0).

    Initial module velocities: module 1 at rest unless the gap shrinks, as in
    the MuJoCo engine's start (the same split, so both start identically).
    """
    if params.F_r1 != 0 or params.F_r2 != 0:
        raise ParameterError(f"F_r1={params.F_r1}, F_r2={params.F_r2}: the free mechanism has no clutches, so "
                             "modules also move backward, where a forward-only resistance is undefined; "
                             "allowed: F_r1 = F_r2 = 0")
    t_end, dt_out = check_run_options(t_end, dt_out)
    rtol, atol = check_tolerances(rtol, atol)
    started = time.perf_counter()
    dyn = OneDofDynamics(params, geometry)
    link = dyn.linkage
    K0 = float(link.transfer(params.phi0).K)
    v10 = max(-K0 * params.omega0, 0.0)

    def rhs(_t, y):
        phi, omega, _x1, v1, _work = y
        x1dd, alpha = free_accelerations(dyn, phi, omega)
        return [omega, alpha, v1, x1dd, dyn.torque(omega) * omega]

    n_out = max(1, math.ceil(t_end / dt_out - 1e-9))
    times = np.linspace(0.0, t_end, n_out + 1)
    from scipy.integrate import solve_ivp

    sol = solve_ivp(rhs, (0.0, t_end), [params.phi0, params.omega0, 0.0, v10, 0.0], method="DOP853",
                    rtol=rtol, atol=atol, t_eval=times)
    if sol.status != 0:
        raise SimulationError(f"integration failed at t={sol.t[-1]:.6g} s: {sol.message}")
    phi, omega, x1, v1, work = sol.y
    tr = link.transfer(phi)
    x1dd, alpha = free_accelerations(dyn, phi, omega)
    S_dot = tr.K * omega
    zeros = np.zeros_like(phi)
    series = {
        "t": sol.t, "phi": phi, "omega": omega, "alpha": alpha, "x1": x1, "x2": x1 + tr.S - tr.S[0],
        "v1": v1, "v2": v1 + S_dot, "a1": x1dd, "a2": x1dd + tr.dK * omega**2 + tr.K * alpha,
        "S": tr.S, "S_dot": S_dot, "lambda1": zeros, "lambda2": zeros,
        "mode": np.full(phi.shape, int(Mode.BOTH_MOVING)),
        "resistance1": zeros, "resistance2": zeros, "motor_work": work, "motor_torque": dyn.torque(omega) + zeros,
    }
    series.update(dyn.energy_columns(series))  # no resistance: friction_work stays 0 though modules go back
    add_kinetostatics(series, dyn)
    del series["motor_torque"]  # folded into motor_power
    energy = dyn.energy_audit(series)
    return RunResult(engine="analytic", geometry=dyn.geometry.value, clutch="none", params=params, t_end=t_end,
                     series=series, energy=energy, wall_time_s=time.perf_counter() - started,
                     settings={"method": "DOP853", "rtol": rtol, "atol": atol, "dt_out": dt_out,
                               "rod_modelled": dyn.include_rod})
