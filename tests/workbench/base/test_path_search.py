"""The compiled path searches against their plain definitions: `first_beyond` skips only what the chord bound
proves, `track` is what `PathTracker.update` reports, `value_at` is np.interp; the compiled form of a path they read,
and the kernels' argument counts."""

from __future__ import annotations

import importlib
import inspect
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba.core.registry import CPUDispatcher as Dispatcher

from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.path import PathTracker
from workbench.base.path_search import (
    PATH_CURVATURE,
    PATH_HEADING,
    PATH_RECORD,
    PATH_ROWS,
    PATH_SPEED,
    PATH_X,
    PATH_Y,
    first_beyond,
    track_sequence,
    value_at,
)

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


def test_the_compiled_path_is_made_once_and_holds_the_paths_samples_and_scalars() -> None:
    """`ReferencePath.compiled`: one table (rows PATH_*, the planned speed NaN when the path has none) and one
    record (PATH_RECORD), made once per path and window and shared by the path's trackers."""
    compiled = LOOP.compiled()
    assert LOOP.compiled() is compiled and LOOP.tracker(0.0).compiled is compiled
    table = compiled.table
    assert table.shape == (PATH_ROWS, LOOP.x_m.size) and table.flags.c_contiguous
    for row, samples in ((PATH_X, LOOP.x_m), (PATH_Y, LOOP.y_m), (PATH_HEADING, LOOP.heading_rad)):
        assert table[row].tolist() == samples.tolist()
    assert table[PATH_CURVATURE].tolist() == LOOP.curvature_1pm.tolist()
    assert np.isnan(table[PATH_SPEED]).all()
    record = compiled.record
    assert record.dtype == PATH_RECORD and record.shape == (1,)
    extent = math.hypot(np.ptp(LOOP.x_m), np.ptp(LOOP.y_m))
    assert record[0].tolist() == (LOOP.spacing_m, LOOP.length_m, LOOP.closed, extent, 5.0, LOOP.max_segment_m)
    assert compiled.extent_m == extent and compiled.min_window_m == 5.0
    wide = PathTracker(OPEN, 0.0, min_window_m=12.0)
    assert wide.compiled is OPEN.compiled(12.0) and wide.compiled.min_window_m == 12.0
    assert wide.compiled is not OPEN.compiled()


@settings(max_examples=40, deadline=None)
@given(steps=st.lists(st.tuples(st.floats(-2.0, 2.0), st.floats(0.0, 4.0)), min_size=1, max_size=30))
def test_track_sequence_is_track_step_by_step(steps: list[tuple[float, float]]) -> None:
    """`track_sequence` on the compiled path: each position's arc length and CTE as `PathTracker.update` gives them
    one at a time, bit for bit."""
    s, xs, ys = 0.0, [], []
    for offset, advance in steps:
        s += advance
        heading = float(LOOP.heading(s))
        x, y = LOOP.position(s)
        xs.append(float(x) - offset * math.sin(heading))
        ys.append(float(y) + offset * math.cos(heading))
    one_by_one = LOOP.tracker(0.0)
    expected = [(p.s_m, p.cte_m) for p in (one_by_one.update(x, y) for x, y in zip(xs, ys, strict=True))]
    tracker = LOOP.tracker(0.0)
    s_out, cte_out = np.empty(len(xs)), np.empty(len(xs))
    compiled = tracker.compiled
    track_sequence(compiled.table, compiled.record, tracker.state, np.array(xs), np.array(ys), s_out, cte_out)
    assert list(zip(s_out.tolist(), cte_out.tolist(), strict=True)) == expected


#: The modules whose compiled kernels walk the path or make the clothoid step.
KERNEL_MODULES = (
    "workbench.base.path_search",
    "workbench.simulation.step_kernel",
    "controllers.pure_pursuit",
    "controllers.clothoid.lookahead",
    "controllers.clothoid.path_feedforward",
    "controllers.clothoid.step_kernel",
    "controllers.clothoid.delay_predictor",
    "controllers.clothoid.clothoid_fit",
    "controllers.clothoid.pose_prediction",
    "controllers.clothoid.frechet",
    "controllers.clothoid.lookahead_filter",
)
#: The most arguments a compiled kernel takes: the path travels as its compiled form, options as records.
MAX_KERNEL_ARGUMENTS = 16


def test_no_compiled_kernel_takes_more_than_sixteen_arguments() -> None:
    counts = {}
    for name in KERNEL_MODULES:
        module = importlib.import_module(name)
        for attribute, value in vars(module).items():
            if isinstance(value, Dispatcher) and value.py_func.__module__ == name:
                counts[f"{name}.{attribute}"] = len(inspect.signature(value.py_func).parameters)
    assert "controllers.clothoid.step_kernel.clothoid_step" in counts and len(counts) > 20
    assert {kernel: n for kernel, n in counts.items() if n > MAX_KERNEL_ARGUMENTS} == {}
