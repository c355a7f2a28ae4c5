"""Adaptive lookahead (section 3): the Fréchet distance grows with the lookahead on a bend (Figure 4b), and the
search finds the same lookahead as trying every candidate, from the range's ends or from any hint."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.clothoid.lookahead import (
    MAX_CURVE_POINTS,
    LookaheadEvaluator,
    adaptive_search,
    candidate_lookaheads,
    evaluate_candidate,
    evaluated,
    search_settings,
)
from workbench.base.clothoid_chain import ClothoidChain

BEND = ClothoidChain().straight(20.0).clothoid_to(1 / 12, 8.0).arc(40.0).to_path("sharp bend")
KDOT_MAX = 0.05


def _pose(s: float, cte: float, heading_error: float) -> tuple[float, float, float]:
    x, y = BEND.position(s)
    h = float(BEND.heading(s))
    return float(x) - cte * math.sin(h), float(y) + cte * math.cos(h), h + heading_error


def _brute_force(s: float, pose, kappa: float, low: float, high: float, step: float, threshold: float):
    evaluator = LookaheadEvaluator(BEND)
    grid = candidate_lookaheads(low, high, step)
    scores = [evaluator.evaluate(s, *pose, kappa, float(la), KDOT_MAX) for la in grid]
    ok = [c.lookahead_m for c in scores if c.frechet_m <= threshold and c.status != 2]
    return (max(ok) if ok else None), grid, np.array([c.frechet_m for c in scores])


def test_frechet_distance_grows_with_lookahead_entering_a_bend() -> None:
    """Figure 4b: on the straight 8 m before a bend of radius 12 m, the Fréchet distance rises monotonically with
    the lookahead: zero while the target is on the straight, past the paper's 0.5 m threshold at 20 m."""
    s = 12.0
    *_, fd = _brute_force(s, _pose(s, 0.0, 0.0), float(BEND.curvature(s)), 5.0, 20.0, 0.5, 0.5)
    assert np.all(np.diff(fd) >= -1e-9)
    assert fd[0] < 1e-9
    assert fd[-1] > 0.5


#: A hint for the search: none (from the range's ends), or a last choice anywhere in or beyond the range.
HINTS = st.one_of(st.just(math.nan), st.floats(0.0, 30.0))


def _search(s: float, pose, kappa: float, threshold: float, hint: float, size: int):
    scores, results = np.empty(size), np.empty((size, 8))
    compiled = BEND.compiled()
    chosen, evaluations = adaptive_search(
        compiled.table, compiled.record, search_settings(0.5, 10.0, 10.0, KDOT_MAX, 0.5), s / BEND.spacing_m, *pose,
        kappa, 5.0, 20.0, threshold, hint, np.empty((4, MAX_CURVE_POINTS)), scores, results,
    )  # fmt: skip
    return chosen, evaluations, scores, results


@settings(max_examples=60, deadline=None)
@given(
    s=st.floats(0.0, 30.0),
    cte=st.floats(-0.3, 0.3),
    threshold=st.floats(0.02, 0.6),
    hint=HINTS,
)
def test_the_search_equals_brute_force_where_the_distance_is_monotone(
    s: float, cte: float, threshold: float, hint: float
) -> None:
    pose = _pose(s, cte, 0.0)
    kappa = float(BEND.curvature(s))
    expected, grid, fd = _brute_force(s, pose, kappa, 5.0, 20.0, 0.5, threshold)
    if not np.all(np.diff(fd) >= 0.0) or expected is None:
        return  # the bisection's premise does not hold here, or nothing qualifies (the fallback's case)
    chosen, evaluations, scores, results = _search(s, pose, kappa, threshold, hint, grid.size)
    assert chosen == pytest.approx(expected)
    bisection = math.ceil(math.log2(grid.size))
    assert evaluations <= (2 + bisection if math.isnan(hint) else 2 + 2 * bisection)  # galloping: twice at most
    if math.isfinite(hint) and abs(hint - expected) < 0.25:
        assert evaluations <= 2  # the hint and the candidate above it
    # what the search kept of each candidate is what evaluate_candidate gives for it
    k = evaluated(scores, results, 5.0, 0.5, chosen)
    assert k >= 0 and results[k, 0] == scores[k]
    compiled = BEND.compiled()
    again = evaluate_candidate(
        compiled.table, compiled.record, s / BEND.spacing_m, *pose, kappa, chosen, KDOT_MAX, 0.5,
        np.empty((4, MAX_CURVE_POINTS)), np.inf,
    )  # fmt: skip
    assert tuple(results[k]) == tuple(float(v) for v in again)
    assert evaluated(scores, results, 5.0, 0.5, chosen + 0.25) == -1  # off the grid: not evaluated


def test_when_nothing_qualifies_the_least_frechet_distance_is_taken() -> None:
    s, cte = 30.0, 2.0  # 2 m off: every candidate's Fréchet distance is at least 2 m
    pose = _pose(s, cte, 0.0)
    kappa = float(BEND.curvature(s))
    _, grid, fd = _brute_force(s, pose, kappa, 5.0, 20.0, 0.5, 0.5)
    chosen, *_ = _search(s, pose, kappa, 0.5, math.nan, grid.size)
    assert fd.min() >= cte - 1e-9  # the curves start |CTE| apart
    k = int(np.argmin(np.abs(grid - chosen)))
    assert fd[k] <= fd.min() + 0.05  # coarse scan and local refinement: within 5 cm of the true minimum
    # From a hint: the floor where the distance does not fall from it, else the same scan.
    for hint in (5.0, 12.0, 20.0):
        warm, *_ = _search(s, pose, kappa, 0.5, hint, grid.size)
        assert warm == (5.0 if fd[1] >= fd[0] else chosen)


@pytest.mark.parametrize("hint", [5.0, 11.0, 20.0])
def test_off_the_path_a_hint_settles_on_the_floor_in_two_fits(hint: float) -> None:
    """0.3 m off a straight, every candidate's distance is at least 0.3 m and grows with the lookahead: from any hint
    the search gallops down to the floor and takes it once the candidate above is no nearer."""
    s, cte = 2.0, 0.3
    pose, kappa = _pose(s, cte, 0.0), 0.0
    _, grid, fd = _brute_force(s, pose, kappa, 5.0, 20.0, 0.5, 0.02)
    assert fd.min() >= cte - 1e-9 and fd[1] >= fd[0]
    chosen, evaluations, *_ = _search(s, pose, kappa, 0.02, hint, grid.size)
    cold, cold_evaluations, *_ = _search(s, pose, kappa, 0.02, math.nan, grid.size)
    assert chosen == cold == 5.0
    assert evaluations <= 2 + math.ceil(math.log2(grid.size)) and evaluations < cold_evaluations
    if hint == 5.0:
        assert evaluations == 2


@pytest.mark.parametrize("remaining_m", [0.0, 1.0, 3.0, 7.0])
def test_near_the_end_of_an_open_path_the_target_is_on_its_tangent_at_the_lookahead(remaining_m: float) -> None:
    # A straight 30 m open path along x: the target stays 10 m from the rear axle on the extension, so the fitted
    # clothoid stays straight (kappa' = 0) to the last metre instead of bending hard onto the end point.
    straight = ClothoidChain().straight(30.0).to_path("straight")
    evaluator = LookaheadEvaluator(straight)
    x = 30.0 - remaining_m
    offset = evaluator.evaluate(x, x, 0.5, 0.0, 0.0, 10.0, KDOT_MAX)
    on_path = evaluator.evaluate(x, x, 0.0, 0.0, 0.0, 10.0, KDOT_MAX)
    assert on_path.target_xy == pytest.approx((x + 10.0, 0.0), abs=1e-9)
    assert on_path.curvature_rate_1pm2 == pytest.approx(0.0, abs=1e-9) and on_path.frechet_m < 1e-9
    # 0.5 m off: the target at 10 m on the extension, as it would be on a longer path
    assert math.hypot(offset.target_xy[0] - x, offset.target_xy[1] - 0.5) == pytest.approx(10.0, rel=1e-9)
    assert offset.target_xy[1] == pytest.approx(0.0, abs=1e-9)
    assert abs(offset.curvature_rate_1pm2) < KDOT_MAX
