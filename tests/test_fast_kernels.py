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
import time

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams, dop853, kernels
from ipir_mujoco.analytic import accel
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.analytic.forces import drive_torque
from ipir_mujoco.analytic.kinematic_clutch import mode_rhs
from ipir_mujoco.core.results import Mode
from ipir_mujoco.analytic.unilateral_model import UnilateralModel

# compiled for the whole test session where numba is installed (by default a process compiles only once its
# runs have spent accel.LOAD_COST_S in Python): every test then checks the compiled kernels, and the Python
# source is checked against them in child processes. Decided at import, compiled before the first test
# (tests/conftest.py compiles the kernels once for the session; at import a pytest-xdist worker collects while
# that compile runs)
ACCELERATED = accel.available()


@pytest.fixture(autouse=True, scope="module")
def _compiled():
    accel.accelerate()


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
    "compliant, damped, on 5 N of grip": (RobotParams(clutch_stiffness=1e6, clutch_damping=20.0, drive="motor",
                                                      mu_wall=0.5, F_n1=10.0, F_n2=10.0), "exact", "unilateral", 0.6),
}
_RUN = """
import json, sys
import numpy as np
from ipir_mujoco import analytic
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.analytic import accel
out = {}
for name, (params, geometry, clutch, t_end) in json.loads(sys.argv[1]).items():
    run = analytic.simulate(RobotParams(**params), geometry, clutch, t_end, dt_out=1e-3)
    out[name] = {c: np.asarray(v, dtype=float).tolist() for c, v in run.series.items()}
out["accelerated"] = accel.ACCELERATED
out["numba_loaded"] = "numba" in sys.modules
out["spent"] = accel._spent  # s of Python-mode integration counted towards compiling (frozen once compiled)
print(json.dumps(out))
"""


@pytest.mark.skipif(not ACCELERATED, reason="the kernels are not compiled (numba missing, or IPIR_MUJOCO_JIT=0): one path only")
@pytest.mark.slow
def test_compiled_and_python_paths_give_the_same_runs(tmp_path):
    """The same stepper source, compiled by numba here and run as Python in a child process
    (IPIR_MUJOCO_JIT=0): every series column agrees to 1e-12 of its largest value. Both paths do the
    same IEEE operations (numba without fast-math; np.dot through the same BLAS routine), so only a
    libm difference in sin/cos/sqrt of an ulp could separate them, and rtol 1e-10 integration carries
    that no further than ~1e-14."""
    spec = {name: (params.as_dict(), geometry, clutch, t_end) for name, (params, geometry, clutch, t_end)
            in CASES.items()}
    env = dict(os.environ, IPIR_MUJOCO_JIT="0")
    # the children run in an empty folder: `python -c` puts its working folder first on sys.path, and from the
    # repository's root would import the source tree, not the installed package (whose kernels this one compiled)
    done = subprocess.run([sys.executable, "-c", _RUN, json.dumps(spec)], capture_output=True, text=True, env=env,
                          check=True, cwd=tmp_path)
    python = json.loads(done.stdout)
    assert python.pop("accelerated") is False and python.pop("numba_loaded") is False
    python.pop("spent")
    for name, (params, geometry, clutch, t_end) in CASES.items():
        run = analytic.simulate(params, geometry, clutch, t_end, dt_out=1e-3)
        assert set(python[name]) == set(run.series), name
        for column, values in run.series.items():
            other = np.asarray(python[name][column])
            assert other.shape == values.shape, (name, column)
            scale = max(float(np.abs(values).max()), 1e-300)
            np.testing.assert_allclose(values, other, rtol=0, atol=1e-12 * scale, err_msg=f"{name}: {column}")
        assert math.isfinite(run.energy["residual_j"])


@pytest.mark.slow
def test_a_short_run_never_loads_numba_and_a_long_one_goes_on_compiled_with_the_same_floats(tmp_path):
    """By default (IPIR_MUJOCO_JIT unset) a process compiles the kernels only once its runs have spent
    accel.LOAD_COST_S in Python: a default simulate (6 ms of work compiled, about 70 ms in Python on an idle
    machine) imports numba only if its Python time reached that (the rule, checked on the time the child
    measured, so that a loaded machine, where 1 s of simulation can cost more, does not fail the test); a
    run that outlasts that switches to the compiled kernels part way and gives exactly the floats of the
    Python path (the same source, the same operations)."""
    if not ACCELERATED:
        pytest.skip("numba is not installed: nothing is compiled")
    env = {k: v for k, v in os.environ.items() if k != "IPIR_MUJOCO_JIT"}
    short = {"paper": (RobotParams().as_dict(), "approx", "kinematic", 1.0)}
    done = subprocess.run([sys.executable, "-c", _RUN, json.dumps(short)], capture_output=True, text=True, env=env,
                          check=True, cwd=tmp_path)
    result = json.loads(done.stdout)
    compiled = result["spent"] >= accel.LOAD_COST_S
    assert result["accelerated"] is compiled and result["numba_loaded"] is compiled
    # a motor run for 20 s: about 15 times LOAD_COST_S of work in Python, so it switches within its first tenth
    long = {"motor": (RobotParams(drive="motor", incline=10.0).as_dict(), "exact", "unilateral", 20.0)}
    runs = {}
    for mode in ("auto", "0"):
        done = subprocess.run([sys.executable, "-c", _RUN, json.dumps(long)], capture_output=True, text=True,
                              env=dict(env, IPIR_MUJOCO_JIT=mode), check=True, cwd=tmp_path)
        runs[mode] = json.loads(done.stdout)
    assert runs["auto"]["accelerated"] is True and runs["0"]["accelerated"] is False
    assert runs["auto"]["motor"] == runs["0"]["motor"]  # every column, every float


def test_compiling_is_announced_once_in_one_line_where_it_compiles(tmp_path, monkeypatch, capsys):
    """A cold numba cache makes the first compiled run slow: accelerate() says why (logger 'ipir_mujoco'), and
    the command line shows that as one line on stderr; with the cache warm it says nothing."""
    import logging

    from ipir_mujoco.cli import main

    if not ACCELERATED:
        pytest.skip("numba is not installed: nothing is compiled")
    import numba

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(accel, "ACCELERATED", False)  # a process that has not compiled yet
    real = numba.njit

    def no_compiling(*args, **options):  # accelerate()'s njit(**options)(function) compiles nothing; numba's
        return real(*args, **options) if args else (lambda function: function)  # own calls go through
    monkeypatch.setattr(numba, "njit", no_compiling)
    records = []
    handler = logging.Handler()
    handler.emit = records.append
    accel.log.addHandler(handler)
    monkeypatch.setattr(accel.log, "level", logging.INFO)
    monkeypatch.setattr(accel, "HEARTBEAT_S", 0.01)  # the heartbeat's period, shortened
    monkeypatch.setattr(accel, "HEARTBEAT_MAX", 10**9)  # and no cap on its lines, whatever the load
    monkeypatch.setattr(accel, "QUIET_S", 0.01)  # and the quiet that says compiling has ended

    def logged(text: str) -> bool:  # wait (up to 60 s, the heartbeat thread's turn) for a line holding text
        for _ in range(6000):
            if any(text in r.getMessage() for r in records):
                return True
            time.sleep(0.01)
        return False

    try:
        assert accel.compilation_pending() and accel.accelerate()
        # while compiling it says so every HEARTBEAT_S, until the compiled stepper's cache index appears and no
        # kernel is compiling
        assert logged("still compiling the kernels")
        (tmp_path / "analytic_x").mkdir()
        # the stepper's cache index is there, but a kernel compiled later (numba compiles each at its first call)
        # is still compiling: the heartbeat goes on, whatever the timing, until that compile has ended
        from numba.core import event

        event.start_event("numba:compile")
        (tmp_path / "analytic_x" / "dop853.step-1.py311.nbi").write_bytes(b"")
        beats = sum("still compiling" in r.getMessage() for r in records)
        for _ in range(6000):  # two more beats (up to 60 s, the heartbeat thread's turn)
            if sum("still compiling" in r.getMessage() for r in records) >= beats + 2:
                break
            time.sleep(0.01)
        assert sum("still compiling" in r.getMessage() for r in records) >= beats + 2
        assert not any("kernels compiled" in r.getMessage() for r in records)
        event.end_event("numba:compile")
        assert logged("kernels compiled")
        monkeypatch.setattr(accel, "ACCELERATED", False)
        count = len(records)
        assert not accel.compilation_pending() and accel.accelerate()
    finally:
        accel.log.removeHandler(handler)
    messages = [r.getMessage() for r in records]
    assert messages[0] == FIRST_LINE and messages[-1].startswith("kernels compiled (")
    assert all(m.startswith("still compiling the kernels (") for m in messages[1:-1]) and len(messages) == count
    # the command line prints what the package logs, one line with the command's name
    monkeypatch.setattr(accel, "HEARTBEAT_S", 1e6)  # no heartbeat within this short run
    monkeypatch.setattr(accel, "MODE", "1")
    monkeypatch.setattr(accel, "ACCELERATED", False)
    (tmp_path / "analytic_x" / "dop853.step-1.py311.nbi").unlink()
    assert main(["simulate", "--t-end", "0.05", "--json"]) == 0
    err = capsys.readouterr().err
    assert err == f"ipir-mujoco simulate: {FIRST_LINE}\n"


FIRST_LINE = ("compiling the analytic engines' kernels for this machine, once (12-15 s on an idle machine, longer "
              "under load; later runs reuse them)")


def test_the_packaged_brentq_is_scipys_float_for_float():
    """analytic.roots.brentq replaces scipy.optimize.brentq on the runs' common path: the same iterates, so the
    same root to the last bit (==, not approx), on smooth, steep, flat and kinked functions and both sign
    orders; and the same refusals."""
    from scipy.optimize import brentq as scipy_brentq

    from ipir_mujoco.analytic.roots import brentq

    rng = np.random.default_rng(7)
    functions = [lambda x, c=c: math.sin(x) - c for c in rng.uniform(-0.9, 0.9, 20)]
    functions += [lambda x, c=c: (x - c) ** 3 for c in rng.uniform(0.1, 0.9, 10)]
    functions += [lambda x, c=c: math.tanh(50 * (x - c)) for c in rng.uniform(0.1, 0.9, 10)]
    functions += [lambda x, c=c: abs(x - c) - 0.05 for c in rng.uniform(0.2, 0.5, 10)]
    def outcome(solver, *args, **tolerances):  # the root, or the refusal (e.g. no convergence at a kink)
        try:
            return solver(*args, **tolerances)
        except (ValueError, RuntimeError) as exc:
            return type(exc).__name__

    checked = 0
    for f in functions:
        for a, b in ((0.0, 1.0), (1.0, 0.0), (-0.3, 0.95)):
            if (f(a) > 0) == (f(b) > 0):
                continue
            for xtol, rtol in ((2e-12, 4 * np.finfo(float).eps), (1e-15, 4 * np.finfo(float).eps), (1e-6, 1e-8)):
                ours, theirs = (outcome(g, f, a, b, xtol=xtol, rtol=rtol) for g in (brentq, scipy_brentq))
                assert ours == theirs, (a, b, xtol, rtol)
                checked += 1
    assert checked > 200
    for call in (lambda g: g(lambda x: x + 1, 0.0, 1.0), lambda g: g(lambda x: math.nan, 0.0, 1.0)):
        for g in (brentq, scipy_brentq):
            with pytest.raises(ValueError):
                call(g)


def test_a_compilation_during_a_run_is_not_charged_to_its_wall_budget(monkeypatch):
    """The kernels may compile inside a run (accel.spent, ~15 s on a fresh machine): the process's one-time
    cost, so a run with a short wall budget must not fail for it. Stand-in: the run's clock (the budget's)
    is a counter that only the first accel.spent advances, by 100 s, against a budget of 0.5 s for a 1 s
    run (16 mode switches, each a budget check): the run's own work counts 0 s, so the machine's load
    cannot decide the outcome, and the 100 s are charged to the budget unless they are kept out."""
    from ipir_mujoco.analytic import solver_support

    class Clock:  # stands in for the time module inside solver_support: perf_counter only
        now = 0.0

        def perf_counter(self):
            return self.now

    clock, calls = Clock(), []

    def slow_first(seconds):
        if not calls:
            clock.now += 100.0
        calls.append(seconds)

    monkeypatch.setattr(solver_support, "time", clock)
    monkeypatch.setattr(accel, "spent", slow_first)
    run = analytic.simulate(RobotParams(), t_end=1.0, wall_budget_s=0.5)
    assert calls, "the run never ticked the compile clock: the stand-in did not stand in"
    assert run.summary["revolutions"] > 0
