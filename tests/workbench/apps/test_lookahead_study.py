"""Figures 4b and 5b as functions: their shape against the paper's and against exact geometry."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

from workbench.apps.lookahead_study import frechet_vs_lookahead, min_frechet_vs_cte
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError

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
