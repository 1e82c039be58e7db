"""The one table of energy terms (core/energy.py) reaches every reader: a new row is audited by the analytic
models, by MuJoCo's end-of-run audit and its per-sample monitor, per revolution (core.cycles.Cycle) and on the
command line's energy line, with no reader spelling the terms.

The new row here is a made-up dissipation, ``magnet`` (column ``magnet_work``, audit key ``magnet_j``), put in the
table for the test's length; its column is a made-up cumulative work added to the series of a real run."""

from __future__ import annotations

import numpy as np
import pytest

from ipir_mujoco import registry
from ipir_mujoco.analytic import RobotParams
from ipir_mujoco.analytic.dynamics import OneDofDynamics
from ipir_mujoco.cli.simulate import _energy_line
from ipir_mujoco.core import cycles, energy
from ipir_mujoco.engine.run import simulate as mujoco_simulate

MAGNET = energy.EnergyTerm("magnet", "magnet_work", "magnet_j", energy.DISSIPATED)


@pytest.fixture
def magnet(monkeypatch):
    """The table with the made-up row (every reader reads the table when it runs, not when it was imported)."""
    monkeypatch.setattr(energy, "ENERGY_TERMS", (*energy.ENERGY_TERMS, MAGNET))
    return MAGNET


@pytest.fixture(scope="module")
def run():
    """A short analytic run (its series has the table's usual columns)."""
    return registry.run("analytic-unilateral", RobotParams(), 1.0, dt_out=1e-3)


def _with_magnet(series: dict) -> dict:
    """The series with a cumulative magnet_work [J]: a tenth of the friction work (an arbitrary, growing work)."""
    return {**series, "magnet_work": 0.1 * np.asarray(series["friction_work"])}


def test_a_new_row_is_in_the_analytic_audit(magnet, run):
    series = _with_magnet(run.series)
    audit = OneDofDynamics(run.params, "exact").energy_audit(series)
    work = float(series["magnet_work"][-1] - series["magnet_work"][0])
    assert audit["magnet_j"] == work > 0
    # the residual books it as dissipated: it drops by exactly the new term (to round-off of the motor's work)
    assert audit["residual_j"] == pytest.approx(run.energy["residual_j"] - work, abs=1e-12 * run.energy["motor_work_j"])


def test_a_new_row_is_in_every_revolutions_audit(magnet, run):
    series = _with_magnet(run.series)
    before, after = cycles.cycles(run.series), cycles.cycles(series)
    assert len(after) == len(before) > 0
    for old, new in zip(before, after):
        assert new.energy_j("magnet_j") > 0 and "magnet_j" in new.audit
        assert new.residual_j == pytest.approx(old.residual_j - new.energy_j("magnet_j"),
                                               abs=1e-12 * old.motor_work_j)


def test_a_new_row_is_on_the_command_lines_energy_line(magnet):
    line = _energy_line({"motor_work_j": 1.0, "kinetic_j": 0.5, "friction_j": 0.3, "magnet_j": 0.2,
                         "residual_j": 0.0})
    assert line == "motor 1 = kinetic 0.5 + friction 0.3 + magnet 0.2 + residual 0.00e+00"


def test_a_new_row_is_in_mujocos_end_of_run_audit(magnet, run):
    """MuJoCo's audit is the table's (core.energy.changes, by_role): a series with the new column books it."""
    series = _with_magnet(run.series)
    change = energy.changes(series)
    assert MAGNET in change and energy.by_role(change)[energy.DISSIPATED] == pytest.approx(
        energy.by_role(energy.changes(run.series))[energy.DISSIPATED] + change[MAGNET], rel=1e-15)


def test_mujocos_per_sample_monitor_reads_every_row(magnet):
    """Every row of the table has its place in the recorder (a new term's column must be recorded: without one
    this fails, naming it), and the per-sample audit sums the rows the table has, by role."""
    usual = {t.column for t in energy.ENERGY_TERMS if t is not MAGNET}
    assert set(mujoco_simulate.ENERGY_SLOTS) == usual  # the new row is not recorded: the engine must add it

    class Recorder:  # three samples; every recorded energy 1 J except the motor's work, 10 J
        scalars = np.ones((3, len(mujoco_simulate.SCALARS)))
        deferred = np.ones((3, len(mujoco_simulate.DEFERRED)))

    Recorder.scalars[:, mujoco_simulate.SCALARS.index("motor_work")] = 10.0
    run = object.__new__(mujoco_simulate._Run)
    run.recorder, run.energy0 = Recorder, (0.0, 0.0)
    slots = {**mujoco_simulate.ENERGY_SLOTS, "magnet_work": (False, mujoco_simulate.SCALARS.index("wheels1"))}
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(mujoco_simulate, "ENERGY_SLOTS", slots)
        residual, _ = run._audit(0, 3, np.zeros(3))
    dissipated = sum(1 for t in energy.ENERGY_TERMS if t.role == energy.DISSIPATED)  # the magnet's among them
    stored = sum(1 for t in energy.ENERGY_TERMS if t.role == energy.STORED)
    np.testing.assert_array_equal(residual, 10.0 - dissipated - 1.0 - stored)
