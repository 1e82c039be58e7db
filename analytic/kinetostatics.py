"""Forces the motion needs: rod force, crank-pin force, motor power.

Given a run's accelerations and the external forces on module 2 (clutch
reaction plus resistance), the force the rod exerts on module 2 along x
follows from module 2's Newton equation; the rod's own Newton-Euler equations
then give the pin forces at C and B. Columns added to a time series:

=================  =====  ===========================================================
rod_force          N      axial force in the rod at C, tension > 0 (the pin force at
                          C along the rod; MuJoCo reports the same quantity)
crank_pin_force    N      magnitude of the force between crank and rod at B
motor_power        W      motor torque * omega (the ``motor_torque`` column if present, else M)
=================  =====  ===========================================================

Frame and symbols as in :mod:`ipir_mujoco.analytic.kinematics`: e = (C - B) / L is the
rod's unit vector, beta its angle. In the first-order geometry the rod is
massless and taken along x (L >> r), as in the paper. Gravity along the pipe
(a_g, :func:`.forces.gravity_along_pipe`) is a uniform field along x: in each
body's Newton equation it enters as the x-acceleration a_x - a_g.
"""

from __future__ import annotations

import numpy as np

from .dynamics import OneDofDynamics


def pin_forces(series: dict[str, np.ndarray], dyn: OneDofDynamics) -> tuple[np.ndarray, ...]:
    """The rod's pin forces [N] of a run, each of shape (n,): (on_rod_x, on_rod_y), the force on the rod at C (from
    module 2), and (pin_x, pin_y), the crank's force on the rod at B; x along the pipe, y across it in the crank's
    plane. Module 2 feels -on_rod_y across the pipe at C and module 1 -pin_y at A (the crank, balanced, passes the
    pin's force on to its bearing). In the first-order geometry the rod lies along x: no force across it.

    Needs the columns phi, omega, alpha, a1, a2, lambda2 and resistance2.
    """
    p, link = dyn.params, dyn.linkage
    phi, omega, alpha = series["phi"], series["omega"], series["alpha"]
    held_force = series["lambda2"] + series["resistance2"]  # external x-force on module 2 but the rod's
    a_g = dyn.a_g
    on_rod_x = held_force - p.m2 * (series["a2"] - a_g)  # force on the rod at C, x: minus the rod's pull on module 2
    if link.geometry.value == "approx":
        zeros = np.zeros_like(on_rod_x)
        return on_rod_x, zeros, -on_rod_x, zeros
    r, s = p.r, np.sin(phi)
    D = np.sqrt(p.L**2 - (r * s) ** 2)
    cb_x, cb_y = D, -r * s  # C - B
    if dyn.include_rod:
        rod = link.rod_motion(phi)
        acc_x = series["a1"] + rod.da * omega**2 + rod.a * alpha - a_g  # relative to free fall
        acc_y = rod.db * omega**2 + rod.b * alpha
        beta_acc = rod.dg * omega**2 + rod.g * alpha
        # moment about B of the rod: I_G beta_ddot + m (G - B) x a_G = (C - B) x F_C, G - B = (C - B) / 2
        moment = p.rod_inertia_value * beta_acc + p.rod_mass * 0.5 * (cb_x * acc_y - cb_y * acc_x)
        on_rod_y = (moment + cb_y * on_rod_x) / cb_x
        return on_rod_x, on_rod_y, p.rod_mass * acc_x - on_rod_x, p.rod_mass * acc_y - on_rod_y  # crank on rod at B
    on_rod_y = cb_y * on_rod_x / cb_x  # massless rod: the pin force lies along it
    return on_rod_x, on_rod_y, -on_rod_x, -on_rod_y


def add_kinetostatics(series: dict[str, np.ndarray], dyn: OneDofDynamics) -> None:
    """Add ``rod_force``, ``crank_pin_force`` and ``motor_power`` to ``series`` (in place).

    Needs the columns phi, omega, alpha, a1, a2, lambda2 and resistance2 (:func:`pin_forces`).
    """
    p, phi = dyn.params, series["phi"]
    on_rod_x, on_rod_y, pin_x, pin_y = pin_forces(series, dyn)
    if dyn.linkage.geometry.value == "approx":
        series["rod_force"] = on_rod_x
        series["crank_pin_force"] = np.abs(on_rod_x)
    else:
        cb_x, cb_y = np.sqrt(p.L**2 - (p.r * np.sin(phi)) ** 2), -p.r * np.sin(phi)  # C - B
        series["rod_force"] = (on_rod_x * cb_x + on_rod_y * cb_y) / p.L
        series["crank_pin_force"] = np.hypot(pin_x, pin_y)
    torque = series["motor_torque"]  # every solver writes the torque it applied (a motor's varies)
    series["motor_power"] = torque * series["omega"]
