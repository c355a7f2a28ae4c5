"""Figures 4b and 5b as functions: their shape against the paper's and against exact geometry; Figure 4b as the
paper report draws it: growing across its lookaheads through the controller's own threshold."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from controllers.clothoid.controller import ClothoidConfig
from workbench.apps.lookahead_study import (
    DEFAULT_LOOKAHEADS_M,
    frechet_vs_lookahead,
    growing_stretch,
    min_frechet_vs_cte,
)
from workbench.apps.paper import figure_4b
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.scenarios import make_scenario

BEND = ClothoidChain().straight(20.0).clothoid_to(1 / 12, 8.0).arc(40.0).to_path("sharp bend")
STRAIGHT = ClothoidChain().straight(100.0).to_path("straight")


def test_figure_4b_grows_on_a_bend_and_stays_near_zero_on_a_straight() -> None:
    bend = frechet_vs_lookahead(BEND, 12.0)  # on the straight, 8 m before a bend of radius 12 m
    assert bend.frechet_m[-1] > 0.5 > bend.frechet_m[0]  # crosses the paper's threshold inside [5, 20] m
    assert np.all(np.diff(bend.frechet_m) >= -1e-9)
    straight = frechet_vs_lookahead(STRAIGHT, 30.0)
    assert straight.frechet_m.max() < 1e-6
    frame = bend.to_pandas()
    assert list(frame.columns) == ["lookahead_m", "frechet_m"] and len(frame) == 31
    assert bend.plot().get_ylabel() == "Fréchet distance (m)"


def test_figure_5b_min_frechet_is_at_least_the_cte_and_grows_with_it() -> None:
    """The curves start |CTE| apart, so the least Fréchet distance is >= |CTE| (equal on a straight, where the
    best clothoid starts parallel to the path)."""
    ctes = np.linspace(0.0, 2.0, 9)
    on_straight = min_frechet_vs_cte(STRAIGHT, 30.0, ctes)
    np.testing.assert_allclose(on_straight.min_frechet_m, ctes, atol=0.03)
    on_bend = min_frechet_vs_cte(BEND, 12.0, ctes)
    assert np.all(on_bend.min_frechet_m >= ctes - 1e-9)
    assert np.all(np.diff(on_bend.min_frechet_m) > 0.0)
    assert set(on_bend.to_pandas().columns) == {"cte_m", "min_frechet_m", "best_lookahead_m"}
    assert on_bend.plot().get_xlabel() == "initial cross-track error (m)"


@pytest.mark.parametrize("s_m", [-50.0, 1e3, float("nan")])
def test_a_position_off_the_path_is_refused(s_m: float) -> None:
    with pytest.raises(WorkbenchInputError, match=r"s_m must be .*in \[0"):
        frechet_vs_lookahead(BEND, s_m)


def test_the_paper_report_s_figure_4b_grows_through_the_controller_s_threshold() -> None:
    """The drawn curve grows across the plotted lookaheads and crosses the drawn threshold inside them; the threshold
    is the clothoid controller's default; the axis shows both; the lookahead marked is the one the threshold picks."""
    config = ClothoidConfig()
    ax, growing, on_arc = figure_4b(make_scenario("figure8").path)
    lines = {line.get_label(): line for line in ax.get_lines()}
    curve = next(line for label, line in lines.items() if label.startswith("a bend's entry"))
    lookahead, frechet = np.asarray(curve.get_xdata(), float), np.asarray(curve.get_ydata(), float)
    np.testing.assert_allclose(lookahead, np.arange(config.min_lookahead_m, config.max_lookahead_m + 1e-9, 0.5))
    threshold = lines[f"threshold {config.frechet_threshold_m:g} m"]
    assert set(threshold.get_ydata()) == {config.frechet_threshold_m}
    assert frechet[0] <= config.frechet_threshold_m < frechet[-1]  # crosses it within the plotted range
    assert np.all(np.diff(frechet) >= -1e-9) and frechet[-1] > 5.0 * config.frechet_threshold_m  # and grows on
    low, high = ax.get_ylim()
    assert low == 0.0 and high >= frechet.max() and high < 2.0 * frechet.max()  # not a flat line on a tall axis
    picked = lines[f"lookahead picked: {growing.chosen_lookahead_m():g} m"].get_xdata()[0]
    assert frechet[lookahead == picked][0] <= config.frechet_threshold_m < frechet[lookahead == picked + 0.5][0]
    assert on_arc.frechet_m.max() < 1e-3  # on the arc of constant curvature the clothoid is the arc
    plt.close(ax.figure)


def test_the_growing_stretch_is_where_the_curvature_ahead_changes() -> None:
    stretch = growing_stretch(BEND)  # straight 0-20 m, a clothoid 20-28 m, then the arc
    assert stretch.crosses(ClothoidConfig().frechet_threshold_m)
    assert 0.0 < stretch.s_m < 28.0 and len(stretch.lookahead_m) == len(DEFAULT_LOOKAHEADS_M)
    with pytest.raises(WorkbenchInputError, match=r"no place on path 'straight' where the Fréchet distance crosses"):
        growing_stretch(STRAIGHT)
    with pytest.raises(WorkbenchInputError, match="threshold_m must be a finite number > 0; got -1"):
        growing_stretch(BEND, threshold_m=-1.0)
