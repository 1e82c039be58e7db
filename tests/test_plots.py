"""The paper's figures as the package draws them: they say who drew them and hide no curve."""

from __future__ import annotations

import pytest

from ipir_mujoco.analytic import RobotParams, simulate
from ipir_mujoco.report.plots import figure_crank, figure_gap, figure_modules


@pytest.fixture(scope="module")
def runs():
    return [simulate(RobotParams(), "approx", "kinematic", 0.4), simulate(RobotParams(), "exact", "kinematic", 0.4)]


@pytest.mark.parametrize("build", [figure_crank, figure_modules, figure_gap])
def test_a_figure_of_one_run_names_the_engine_that_drew_it(runs, build):
    heading = build(runs[:1])._suptitle.get_text()
    assert "analytic engine" in heading and "approx geometry" in heading and "kinematic clutches" in heading


def test_fig4_legend_sits_outside_the_axes(runs):
    """Inside the axes any corner hides part of S or S_dot (the lower left hid the first minimum of S)."""
    fig = figure_gap(runs, labels=["paper model", "exact"])
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legend = fig.legends[0].get_window_extent(renderer)
    for ax in fig.axes:
        assert not legend.overlaps(ax.get_window_extent(renderer))
    assert "paper model (solid)" in fig._suptitle.get_text()
