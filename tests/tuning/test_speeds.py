"""--speeds lists: plain, with an ellipsis, and the errors."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tuning.speeds import MAX_SPEEDS, parse_speeds
from workbench.base.errors import WorkbenchInputError


def test_plain_and_ellipsis_lists() -> None:
    assert parse_speeds("30") == [30.0]
    assert parse_speeds("10, 20,35") == [10.0, 20.0, 35.0]
    assert parse_speeds("10,20,...,100") == [10.0 * k for k in range(1, 11)]
    assert parse_speeds("5,10,15,...,30") == [5.0, 10.0, 15.0, 20.0, 25.0, 30.0]
    assert parse_speeds("20,22.5,...,30") == [20.0, 22.5, 25.0, 27.5, 30.0]


@given(start=st.integers(1, 50), step=st.integers(1, 15), count=st.integers(1, 8))  # last <= 185 km/h
def test_ellipsis_continues_the_first_step_to_the_last(start: int, step: int, count: int) -> None:
    last = start + step * (count + 1)
    assert parse_speeds(f"{start},{start + step},...,{last}") == [float(start + step * k) for k in range(count + 2)]


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("10,abc", "'abc' is not a number"),
        ("10,...,100", "'...' must come after at least two speeds"),
        ("10,20,...", "'...' must come after at least two speeds"),
        ("10,20,...,95", "95 is not reached from 20 in steps of 10"),
        ("20,10,...,0", "must increase"),
        ("30,20", "speeds must increase strictly"),
        ("0,10", "speed 1 must be a finite number in [1, 200] km/h"),
        ("nan", "not a finite number"),
        ("", "'' is not a number"),
    ],
)
def test_bad_lists_are_explained(text: str, needle: str) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        parse_speeds(text)
    assert needle in str(info.value)


def test_a_plain_list_is_bounded_like_an_ellipsis() -> None:
    assert len(parse_speeds(",".join(f"{1 + 0.5 * i:g}" for i in range(MAX_SPEEDS)))) == MAX_SPEEDS
    with pytest.raises(WorkbenchInputError, match=f"{MAX_SPEEDS + 1} speeds given; at most {MAX_SPEEDS}"):
        parse_speeds(",".join(f"{1 + 0.5 * i:g}" for i in range(MAX_SPEEDS + 1)))
