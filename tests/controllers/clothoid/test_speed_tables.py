"""The tables against speed (`speed_tables.py`): `bracket` finds where a speed falls, as a property over any increasing
speeds, and `table_row` interpolates between the rows it names."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.clothoid.speed_tables import bracket, table_row

SPEEDS = st.lists(st.floats(0.0, 300.0), min_size=1, max_size=12, unique=True).map(sorted)


@settings(max_examples=200, deadline=None)
@given(speeds=SPEEDS, speed=st.floats(-50.0, 400.0))
def test_bracket_finds_the_neighbours_and_clamps_beyond_the_ends(speeds: list[float], speed: float) -> None:
    table = np.array(speeds)
    low, high, t = bracket(table, speed)
    if speed <= table[0]:
        assert (low, high) == (0, 0) and t == 0.0
    elif speed >= table[-1]:
        assert (low, high) == (table.size - 1, table.size - 1) and t == 0.0
    else:
        assert 0.0 <= t < 1.0 and (high == low + 1 or (low == high and table[low] == speed))
        assert table[low] <= speed <= table[high]
        assert table[low] + t * (table[high] - table[low]) == pytest.approx(speed, rel=1e-12, abs=1e-12)


def test_table_row_interpolates_between_the_bracketed_rows() -> None:
    speeds = np.array([10.0, 20.0, 40.0])
    rows = np.array([[1.0, 10.0], [2.0, 20.0], [4.0, 0.0]])
    out = np.empty(2)
    for speed, expected in ((5.0, (1.0, 10.0)), (20.0, (2.0, 20.0)), (30.0, (3.0, 10.0)), (50.0, (4.0, 0.0))):
        table_row(speeds, rows, speed, False, out)
        assert tuple(out) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("speed", [5.0, 20.0, 30.0, 50.0])
def test_table_row_reads_the_leading_columns_into_a_shorter_out(speed: float) -> None:
    """The step reads the lags' four leading columns of rows that carry the preview taps beyond them: at a listed
    speed and beyond the ends as between them (a truck measured at exactly an identified speed raised in its step)."""
    speeds = np.array([10.0, 20.0, 40.0])
    rows = np.array([[1.0, 10.0, 7.0], [2.0, 20.0, 7.0], [4.0, 0.0, 7.0]])
    short, whole = np.empty(2), np.empty(3)
    table_row(speeds, rows, speed, False, short)
    table_row(speeds, rows, speed, False, whole)
    assert tuple(short) == tuple(whole[:2])
