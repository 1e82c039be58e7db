"""The compiled scans over a segment's dense output, held to the numpy code they replace, bit for bit.

The one-way model samples its dense output at the output grid, at every step end (revolution ends) and
at nine points a step (the graze scan of ``missed_crossing``); compiled (numba), these loops do the same
IEEE operations in the same order as the numpy reference, so they must give the same floats, not merely
close ones: the test compares with ``np.array_equal``. Also held here: the caches that spare the event
loop and the post-processing repeated kinematics, and the steady-state watch's shortcut.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ipir_mujoco.analytic import RobotParams, dop853, kernels
from ipir_mujoco.analytic import accel
from ipir_mujoco.core.steady_watch import SteadyWatch
from ipir_mujoco.analytic.dense import DenseSolution, component_at, dense_table, graze_scan
from ipir_mujoco.analytic.kinematics import Linkage
from ipir_mujoco.core.results import Mode
from ipir_mujoco.analytic.solver_support import graze_signs
from ipir_mujoco.analytic.unilateral_model import UnilateralModel

# the compiled scans, where numba is installed, against the numpy reference (compiled before the first test, not
# at import: tests/test_fast_kernels.py says why)
ACCELERATED = accel.available()


@pytest.fixture(autouse=True, scope="module")
def _compiled():
    accel.accelerate()


RTOL, ATOL = 1e-10, 1e-12
PARAMS = RobotParams(drive="motor", incline=10.0, rod_mass=0.2)


def segments():
    """One-way segments (mode, Segment) of every moving mode. The event directions are reversed (+1: only a
    guard rising through zero stops the run), so each module's velocity and each hold's margin falls below
    zero and on: every guard then has clearly negative samples for the scan to find."""
    model = UnilateralModel(PARAMS, "exact")
    starts = {Mode.CONTRACTION: [0.4, 15.0, 0.0, 0.0, 0.7, 0.0],
              Mode.EXPANSION: [math.pi + 0.4, 15.0, 0.0, 0.0, 0.0, 0.0],
              Mode.BOTH_MOVING: [0.4, 15.0, 0.0, 0.0, 0.1, 0.0]}  # v2 < 0 from the start: 'no positive before'
    out = []
    for mode, y0 in starts.items():
        seg = dop853.solve(kernels.UNILATERAL, int(mode), 0.0, 0.2, y0, model.constants, RTOL, ATOL, None, [1.0, 1.0])
        assert seg.t.size > 8
        out.append((model, mode, seg))
    return out


def reference_guards(model, mode):
    """Every guard of ``mode`` at states ``ys`` (d, n), from kernels.guard one event at a time (not guards_at)."""
    never = np.full(2, -math.inf)

    def guards(ts, ys):
        return np.array([[kernels.guard(kernels.UNILATERAL, int(mode), k, t, np.ascontiguousarray(y), model.constants,
                                        never) for t, y in zip(ts, ys.T)] for k in (0, 1)])
    return guards


def kernel_variants(function):
    """The kernel as run (compiled where numba is present) and its Python source."""
    return [function, getattr(function, "py_func", function)]


@pytest.mark.parametrize("case", range(3))
@pytest.mark.slow
def test_the_compiled_dense_output_is_numpys(case):
    """Many times at once (grid points inside steps, step ends, times before and after the segment) through the
    compiled loop, its Python source and numpy's gather: the same floats. One time through the scalar path and
    through phi_at: the same floats as well."""
    _, _, seg = segments()[case]
    sol: DenseSolution = seg.sol
    inside = np.linspace(sol.ts[0], sol.ts[-1], 257)
    times = np.concatenate([inside, sol.ts, [sol.ts[0] - 1e-3, sol.ts[-1] + 1e-3]])
    step = np.minimum(np.maximum(np.searchsorted(sol.ts, times, side="left") - 1, 0), sol.h.size - 1)
    reference = sol.evaluate(step, times).T
    for table in kernel_variants(dense_table):
        out = np.empty_like(reference)
        table(sol.ts, sol.t_old, sol.y_old, sol.F, sol._h_safe, times, out)
        assert np.array_equal(out, reference)
    assert np.array_equal(sol(times), reference)
    for t in times[::7]:
        one = sol(float(t))
        assert np.array_equal(one, sol(np.array([t]))[:, 0])  # the two Horner orders differ only in a zero's sign
        for phi_at in kernel_variants(component_at):
            assert phi_at(sol.ts, sol.t_old, sol.y_old, sol.F, sol.h, 0, float(t)) == one[0]
        assert sol.phi_at(float(t)) == one[0]


@pytest.mark.parametrize("case", range(3))
def test_the_compiled_graze_scan_is_the_reference_scan(case):
    """The scan of missed_crossing (times, first clearly negative sample, last clearly positive one before it):
    compiled and as Python source against graze_signs (numpy sampling, kernels.guard per event), identical;
    and each guard does go clearly negative here, so the indices are tested, not only the -1 of 'never'."""
    model, mode, seg = segments()[case]
    times, negative, positive = graze_signs(seg, reference_guards(model, mode))
    assert np.all(negative >= 0) and np.all(positive < negative)
    got = seg.sol.graze_scan(kernels.UNILATERAL, int(mode), 2, model.constants)
    for a, b in zip(got, (times, negative, positive)):
        assert np.array_equal(a, b)
    sol = seg.sol
    python_times = np.empty_like(times)
    python_negative, python_positive = np.empty(2, dtype=np.int64), np.empty(2, dtype=np.int64)
    getattr(graze_scan, "py_func", graze_scan)(kernels.UNILATERAL, int(mode), 2, model.constants, sol.ts, sol.t_old,
                                              sol.y_old, sol.F, sol._h_safe, python_times, python_negative,
                                              python_positive)
    assert np.array_equal(python_times, times)
    assert np.array_equal(python_negative, negative) and np.array_equal(python_positive, positive)


def test_both_guards_at_once_are_each_guard():
    """guards_at shares one evaluation of the mass terms between a mode's two guards: each value is guard's,
    bit for bit, in every moving mode, also where the state has overflowed (nan: the controller's cue), and at
    a nan or -inf time (where guard's "quiet until -inf" rule reads at least +tiny)."""
    model = UnilateralModel(PARAMS, "exact")
    never = np.full(2, -math.inf)  # guards_at's contract: no guard quiet
    rng = np.random.default_rng(7)
    states = [np.array([phi, omega, 0.01, 0.02, v1, 0.3]) for phi, omega, v1 in
              zip(rng.uniform(-4, 10, 40), rng.uniform(-30, 60, 40), rng.uniform(-0.5, 1.0, 40))]
    states += [np.array([1e301, 1.0, 0, 0, 0, 0]), np.array([0.5, math.inf, 0, 0, 0, 0])]
    for guards_at in kernel_variants(kernels.guards_at):
        for mode in (Mode.CONTRACTION, Mode.EXPANSION, Mode.BOTH_MOVING):
            for t in (0.1, math.nan, -math.inf):
                for y in states:
                    out = np.empty(2)
                    guards_at(kernels.UNILATERAL, int(mode), 2, t, y, model.constants, never, out)
                    each = [kernels.guard(kernels.UNILATERAL, int(mode), k, t, y, model.constants, never)
                            for k in (0, 1)]
                    assert np.array_equal(out, each, equal_nan=True)


def test_the_linkage_remembers_only_what_it_may():
    """The last single angle's transfer is reused for that angle only (0.0 and -0.0 give K of opposite signs);
    inside reusing(), an array's transfer and rod motion are computed once for that very array object and are
    the values a fresh computation gives; outside, nothing is kept."""
    link = Linkage(0.05, 0.2, "exact")
    fresh = Linkage(0.05, 0.2, "exact")
    for phi in (0.3, 0.3, -0.0, 0.0, -0.0, 1.1):
        got = link.transfer(phi)
        assert all(a == b and math.copysign(1, a) == math.copysign(1, b) for a, b in zip(got, fresh._transfer(phi)))
    phi = np.linspace(-3, 9, 101)
    with link.reusing():
        first = link.transfer(phi)
        assert link.transfer(phi) is first and link.rod_motion(phi) is link.rod_motion(phi)
        other = phi + 0.5  # another array: its own values
        assert np.array_equal(link.transfer(other).K, fresh.transfer(other).K)
        for a, b in zip(link.rod_motion(phi), fresh.rod_motion(phi)):
            assert np.array_equal(a, b)
    assert link._memo is None and link.transfer(phi) is not first
    assert all(np.array_equal(a, b) for a, b in zip(first, fresh.transfer(phi)))


def test_the_watch_gives_the_same_answer_fed_in_any_chunks():
    """SteadyWatch.update answers chunks in which no revolution ends from their maximum alone: fed sample by
    sample, in odd chunks or all at once (the full path), the revolution speeds, the steady time and the
    running maximum are the same floats."""
    t = np.linspace(0.0, 12.0, 6001)
    phi = 20.0 * (t - 0.5 * (1.0 - np.exp(-t / 0.5))) - 0.3 * np.exp(-t) * np.sin(7 * t)  # rocks, then settles
    position = 0.05 * phi / (2 * math.pi)
    answers = []
    for size in (1, 7, 997, t.size):
        watch = SteadyWatch(phi[0])
        for start in range(0, t.size, size):
            watch.update(t[start:start + size], phi[start:start + size], position[start:start + size])
        answers.append((watch.speeds, watch.steady_at, watch.reach, watch.turns))
    assert answers[0][1] is not None and answers[0][3] > 20
    assert all(a == answers[0] for a in answers[1:])
    watch = SteadyWatch(0.0)  # a nan sample: the running maximum is nan from there on, as numpy's maximum says
    watch.update([0.0, 0.1], [0.0, 0.2], [0.0, 0.0])
    watch.update([0.2, 0.3], [math.nan, 0.4], [0.0, 0.0])
    assert math.isnan(watch.reach) and watch.turns == 0


@pytest.mark.skipif(not ACCELERATED, reason="numba is not installed: the numpy path is the only one")
def test_the_fallback_dense_output_is_the_compiled_one(monkeypatch):
    """Without numba DenseSolution evaluates with numpy: the same floats as the compiled loop."""
    _, _, seg = segments()[0]
    times = np.linspace(seg.sol.ts[0], seg.sol.ts[-1], 101)
    compiled, phis = seg.sol(times), [seg.sol.phi_at(float(t)) for t in times]
    monkeypatch.setattr(accel, "ACCELERATED", False)
    assert np.array_equal(seg.sol(times), compiled)
    assert [seg.sol.phi_at(float(t)) for t in times] == phis


def test_the_packaged_dop853_tableau_is_scipys_bit_for_bit():
    """The stepper's tableau (analytic/dop853_tableau.py) is scipy's DOP853, read from its public class: the
    compiled method is solve_ivp's step for step only with the same floats (np.array_equal, not allclose)."""
    from scipy.integrate import DOP853

    from ipir_mujoco.analytic import dop853_tableau as tableau

    n = tableau.N_STAGES
    assert np.array_equal(tableau.A[:n, :n], DOP853.A) and np.array_equal(tableau.A[n + 1:], DOP853.A_EXTRA)
    assert np.array_equal(tableau.C[:n], DOP853.C) and np.array_equal(tableau.C[n + 1:], DOP853.C_EXTRA)
    for name in ("B", "E3", "E5", "D"):
        assert np.array_equal(getattr(tableau, name), getattr(DOP853, name)), name
