"""The compiled path searches against their plain definitions: `first_beyond_kept` is `first_beyond` whatever
was kept before, `track` is what `PathTracker.update` reports, `value_at` is np.interp."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.path_search import first_beyond, first_beyond_kept, value_at

LOOP = (
    ClothoidChain()
    .straight(30.0)
    .clothoid_to(1 / 15, 10.0)
    .arc(40.0)
    .clothoid_to(0.0, 10.0)
    .straight(20.0)
    .to_path("bend")
)


@settings(max_examples=60, deadline=None)
@given(
    s=st.floats(0.0, 90.0),
    offset=st.floats(-3.0, 3.0),
    distances=st.lists(st.floats(0.1, 60.0), min_size=1, max_size=8),
)
def test_keeping_distances_changes_no_answer(s: float, offset: float, distances: list[float]) -> None:
    """Queries from one point, in any order of distance, give first_beyond's answers bit for bit."""
    heading = float(LOOP.heading(s))
    x, y = LOOP.position(s)
    px, py = float(x) - offset * math.sin(heading), float(y) + offset * math.cos(heading)
    start = s / LOOP.spacing_m
    kept = np.zeros(LOOP.x_m.size + 1)
    for d in distances:
        expected = first_beyond(LOOP.x_m, LOOP.y_m, px, py, start, d, LOOP.closed)
        assert first_beyond_kept(LOOP.x_m, LOOP.y_m, px, py, start, d, LOOP.closed, kept) == expected
    assert 0 <= kept[0] <= LOOP.x_m.size  # within the array


@settings(max_examples=60, deadline=None)
@given(s=st.floats(-10.0, 200.0))
def test_value_at_is_numpy_interpolation_within_the_path(s: float) -> None:
    expected = np.interp(min(max(s, 0.0), LOOP.length_m), LOOP.s_m, LOOP.curvature_1pm)
    got = value_at(LOOP.curvature_1pm, s, LOOP.spacing_m, LOOP.length_m, LOOP.closed)
    assert abs(got - expected) <= 1e-12
