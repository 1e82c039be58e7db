"""The analytic models' fast path: scalar kernels, the DOP853 stepper, compiled against Python.

The kernels restate the equations of ``analytic.dynamics`` on floats; the stepper
restates scipy's DOP853. Each is held here to what it restates, and the compiled
(numba) path to the same source run as Python.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams, dop853, kernels
from ipir_mujoco.analytic.accel import ACCELERATED
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.forces import drive_torque
from ipir_mujoco.analytic.kinematic_clutch import mode_rhs
from ipir_mujoco.core.results import Mode
from ipir_mujoco.analytic.unilateral_clutch import UnilateralModel

RTOL, ATOL = 1e-10, 1e-12
DESIGNS = {
    "paper": RobotParams(),
    "motor uphill, heavy rod": RobotParams(drive="motor", incline=25.0, rod_mass=0.3, m2=0.4, L=0.09),
    "downhill, unequal masses": RobotParams(incline=-15.0, m1=2.5, F_r2=2.0, phi0=1.0, omega0=-4.0),
}


@pytest.mark.parametrize("name", DESIGNS)
@pytest.mark.parametrize("geometry", ["approx", "exact"])
def test_kernels_restate_the_dynamics(name, geometry):
    """Accelerations and holds of every moving mode, as the vectorized reference computes them."""
    params = DESIGNS[name]
    dyn = OneDofDynamics(params, geometry)
    model = UnilateralModel(params, geometry)
    p = kernels.pack(dyn)
    for phi in np.linspace(-3.0, 9.0, 13):
        for omega in (-7.0, 0.0, 2.5, 40.0):
            M = float(drive_torque(params, omega))
            scale = abs(M) / params.J_A + params.r * omega**2 + 9.81  # [rad/s^2 or m/s^2]: the sizes in play
            for mode in (Mode.CONTRACTION, Mode.EXPANSION):
                st = dyn.state(phi, omega, mode, M)
                alpha, hold, K, dK = kernels.one_dof(p, int(mode), phi, omega, M)
                # the same operations on the same numbers, in a slightly different order: roundoff
                assert alpha == pytest.approx(float(st.alpha), rel=1e-12, abs=1e-13 * scale)
                lam = float(st.lambda2 if mode is Mode.CONTRACTION else st.lambda1)
                moving_resistance = params.F_r1 if mode is Mode.CONTRACTION else params.F_r2
                assert hold + moving_resistance == pytest.approx(lam, rel=1e-12, abs=1e-12 * (1 + abs(lam)))
                assert K == pytest.approx(float(dyn.linkage.transfer(phi).K), rel=1e-13, abs=1e-16)
                assert mode_rhs(dyn, mode)(0.0, [phi, omega, 0, 0, 0])[1] == pytest.approx(alpha, rel=1e-12,
                                                                                            abs=1e-13 * scale)
            a1, alpha = dyn.both_moving(phi, omega, M)
            got = kernels.both_moving(p, phi, omega, M)
            assert got[0] == pytest.approx(float(a1), rel=1e-12, abs=1e-13 * scale)
            assert got[1] == pytest.approx(float(alpha), rel=1e-12, abs=1e-13 * scale)
            # the one-way model's event functions: the module velocities and the held modules' margins
            for mode in (Mode.CONTRACTION, Mode.EXPANSION, Mode.BOTH_MOVING):
                y = np.array([phi, omega, 0.0, 0.0, 0.3, 0.0])
                values = np.empty((2, 1))
                kernels.guard_table(kernels.UNILATERAL, int(mode), 2, p, np.zeros(1), y[None, :], values)
                reference = [float(e(0.0, y)) for e, _ in model.events(mode)]
                np.testing.assert_allclose(values[:, 0], reference, rtol=1e-12, atol=1e-12 * (1 + scale))


@pytest.mark.parametrize("geometry", ["approx", "exact"])
def test_the_stepper_is_scipys_dop853(geometry):
    """One contraction of the motor-driven robot uphill: the same method as solve_ivp's DOP853 (tableau, error
    norm, step control, dense output, root search). The kernels' roundoff differs from the numpy reference's
    (operations in another order), and step-size control passes such differences on to the step ends, so
    the two runs are two integrations at rtol: they agree within a few rtol of each state's size, and take
    the same number of steps."""
    dyn = OneDofDynamics(RobotParams(drive="motor", incline=10.0), geometry)
    y0 = [0.0, 0.0, 0.0, 0.0, 0.0]

    def gap_rate(_t, y):
        return dyn.linkage.transfer(y[0]).K * y[1]
    gap_rate.terminal, gap_rate.direction = True, 1.0
    ref = solve_ivp(mode_rhs(dyn, Mode.CONTRACTION), (0.0, 1.0), y0, method="DOP853", rtol=RTOL, atol=ATOL,
                    events=gap_rate, dense_output=True)
    got = dop853.solve(kernels.KINEMATIC, int(Mode.CONTRACTION), 0.0, 1.0, y0, kernels.pack(dyn), RTOL, ATOL,
                       None, [1.0])
    assert got.status == ref.status == 1 and got.t.size == ref.t.size > 10
    # the switch time: where phi reaches pi, known to rtol |phi| + atol, over omega (~30 rad/s)
    assert got.t_events[0][0] == pytest.approx(ref.t_events[0][0], abs=10 * (RTOL * math.pi + ATOL) / 30)
    times = np.linspace(0.0, got.t[-1], 301)
    scale = np.abs(ref.y).max(axis=1)  # each state's size over the segment (x2 stays 0 in contraction)
    assert np.all(np.abs(got.sol(times) - ref.sol(times)) <= 10 * (RTOL * scale[:, None] + ATOL))
    assert np.all(np.abs(got.sol(float(times[100])) - ref.sol(times[100])) <= 10 * (RTOL * scale + ATOL))


def test_pausing_for_the_wall_clock_budget_leaves_the_integration_unchanged():
    """The stepper stops every few steps for a budget check and resumes with the step size it had
    proposed: the same steps, bit for bit, as one uninterrupted call (one-way clutches, expansion)."""
    params = RobotParams(drive="motor", incline=5.0)
    model = UnilateralModel(params, "exact")
    y0 = [math.pi + 0.3, 12.0, 0.1, 0.2, 0.0, 0.5]
    whole = dop853.solve(kernels.UNILATERAL, int(Mode.EXPANSION), 0.0, 0.5, y0, model.constants, RTOL, ATOL, None,
                         [-1.0, -1.0])
    pauses = []
    paused = dop853.solve(kernels.UNILATERAL, int(Mode.EXPANSION), 0.0, 0.5, y0, model.constants, RTOL, ATOL, None,
                          [-1.0, -1.0], max_steps=3, pause=pauses.append)
    assert whole.status == paused.status == 1 and len(pauses) == (whole.t.size - 2) // 3 > 3
    assert np.array_equal(whole.t, paused.t) and np.array_equal(whole.y, paused.y)
    assert all(np.array_equal(a, b) for a, b in zip(whole.t_events, paused.t_events))
    times = np.linspace(np.pi / 100, whole.t[-1], 97)
    assert np.array_equal(whole.sol(times), paused.sol(times))


# each case: (params, geometry, clutch, t_end); kept short, the Python path integrates ~10x slower
CASES = {
    "paper": (RobotParams(), "approx", "kinematic", 0.6),
    "paper exact, motor, uphill": (RobotParams(drive="motor", incline=15.0), "exact", "kinematic", 0.6),
    "one-way, motor, downhill": (RobotParams(drive="motor", incline=-10.0, m2=0.6), "exact", "unilateral", 0.6),
    "one-way reversing start": (RobotParams(phi0=2.0, omega0=-20.0, F_r2=3.0), "approx", "unilateral", 0.4),
    "compliant, damped, backlash": (RobotParams(clutch_stiffness=1e6, clutch_damping=20.0, clutch_backlash=2e-4,
                                                drive="motor"), "exact", "unilateral", 0.3),
    "one-way on 5 N of grip": (RobotParams(drive="motor", mu_wall=0.5, F_n1=10.0, F_n2=10.0), "exact", "unilateral",
                               0.6),
}
_RUN = """
import json, sys
import numpy as np
from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.analytic.accel import ACCELERATED
out = {"accelerated": ACCELERATED}
for name, (params, geometry, clutch, t_end) in json.loads(sys.argv[1]).items():
    run = analytic.simulate(RobotParams(**params), geometry, clutch, t_end, dt_out=1e-3)
    out[name] = {c: np.asarray(v, dtype=float).tolist() for c, v in run.series.items()}
print(json.dumps(out))
"""


@pytest.mark.skipif(not ACCELERATED, reason="the kernels are not compiled (numba missing, or IPIR_MUJOCO_JIT=0): one path only")
def test_compiled_and_python_paths_give_the_same_runs():
    """The same stepper source, compiled by numba here and run as Python in a child process
    (IPIR_MUJOCO_JIT=0): every series column agrees to 1e-12 of its largest value. Both paths do the
    same IEEE operations (numba without fast-math; np.dot through the same BLAS routine), so only a
    libm difference in sin/cos/sqrt of an ulp could separate them, and rtol 1e-10 integration carries
    that no further than ~1e-14."""
    spec = {name: (params.as_dict(), geometry, clutch, t_end) for name, (params, geometry, clutch, t_end)
            in CASES.items()}
    env = dict(os.environ, IPIR_MUJOCO_JIT="0")
    done = subprocess.run([sys.executable, "-c", _RUN, json.dumps(spec)], capture_output=True, text=True, env=env,
                          check=True)
    python = json.loads(done.stdout)
    assert python.pop("accelerated") is False
    for name, (params, geometry, clutch, t_end) in CASES.items():
        run = analytic.simulate(params, geometry, clutch, t_end, dt_out=1e-3)
        assert set(python[name]) == set(run.series), name
        for column, values in run.series.items():
            other = np.asarray(python[name][column])
            assert other.shape == values.shape, (name, column)
            scale = max(float(np.abs(values).max()), 1e-300)
            np.testing.assert_allclose(values, other, rtol=0, atol=1e-12 * scale, err_msg=f"{name}: {column}")
        assert math.isfinite(run.energy["residual_j"])


def test_the_command_line_says_when_it_compiles_the_kernels_first(tmp_path, monkeypatch, capsys):
    """A cold numba cache makes the first run slow: the command line says why, in one line on stderr;
    a warm one (the cached index numba writes beside its machine code) says nothing."""
    from ipir_mujoco.analytic import accel
    from ipir_mujoco.cli import main

    if not accel.ACCELERATED:
        pytest.skip("numba is not installed: nothing is compiled")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    assert accel.compilation_pending()
    assert main(["simulate", "--t-end", "0.05", "--json"]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "compiling the analytic engines' kernels" in err
    (tmp_path / "analytic_x").mkdir()
    (tmp_path / "analytic_x" / "dop853.step-1.py311.nbi").write_bytes(b"")
    assert not accel.compilation_pending()
    assert main(["simulate", "--t-end", "0.05", "--json"]) == 0
    assert capsys.readouterr().err == ""
