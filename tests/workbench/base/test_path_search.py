"""The compiled path searches against their plain definitions: `first_beyond` skips only what the chord bound
proves, `track` is what `PathTracker.update` reports, `value_at` is np.interp."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.path_search import first_beyond, value_at

LOOP = (
    ClothoidChain()
    .straight(30.0)
    .clothoid_to(1 / 15, 10.0)
    .arc(40.0)
    .clothoid_to(0.0, 10.0)
    .straight(20.0)
    .to_path("bend")
)
OPEN = ClothoidChain().straight(30.0).clothoid_to(1 / 15, 10.0).arc(40.0).to_path("open bend")


@settings(max_examples=60, deadline=None)
@given(
    s=st.floats(0.0, 90.0),
    offset=st.floats(-3.0, 3.0),
    distances=st.lists(st.floats(0.1, 60.0), min_size=1, max_size=8),
)
def test_skipping_the_samples_the_chord_bound_keeps_near_changes_no_answer(
    s: float, offset: float, distances: list[float]
) -> None:
    """first_beyond with the path's longest chord (skipping what it proves nearer) gives the answers of the walk
    over every sample (no chord known: inf) bit for bit, on a loop and on an open path."""
    heading = float(LOOP.heading(s))
    x, y = LOOP.position(s)
    px, py = float(x) - offset * math.sin(heading), float(y) + offset * math.cos(heading)
    start = s / LOOP.spacing_m
    for path in (LOOP, OPEN):
        for d in distances:
            walked = first_beyond(path.x_m, path.y_m, px, py, start, d, path.closed, math.inf)
            assert first_beyond(path.x_m, path.y_m, px, py, start, d, path.closed, path.max_segment_m) == walked


def test_the_longest_chord_of_a_path() -> None:
    """ReferencePath.max_segment_m: the largest distance between neighbouring samples (the samples' spacing in arc
    length bounds it from above)."""
    chords = np.hypot(np.diff(LOOP.x_m), np.diff(LOOP.y_m))
    assert LOOP.max_segment_m == chords.max()
    assert LOOP.max_segment_m <= LOOP.spacing_m * (1.0 + 1e-9)


@settings(max_examples=60, deadline=None)
@given(s=st.floats(-10.0, 200.0))
def test_value_at_is_numpy_interpolation_within_the_path(s: float) -> None:
    expected = np.interp(min(max(s, 0.0), LOOP.length_m), LOOP.s_m, LOOP.curvature_1pm)
    got = value_at(LOOP.curvature_1pm, s, LOOP.spacing_m, LOOP.length_m, LOOP.closed)
    assert abs(got - expected) <= 1e-12
