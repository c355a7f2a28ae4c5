"""How the lookahead follows the adaptive search's choice: floor at once, hysteresis, rate limits both ways."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.clothoid.lookahead_filter import LookaheadFilter, LookaheadFilterSettings
from workbench.base.errors import WorkbenchInputError


def test_first_choice_is_taken_within_the_floor_and_ceiling() -> None:
    f = LookaheadFilter(LookaheadFilterSettings())
    assert f.step(3.0, 8.0, 20.0, 0.2) == 8.0
    f.reset()
    assert f.step(12.0, 8.0, 20.0, 0.2) == 12.0


def test_small_changes_are_ignored_and_large_ones_followed_at_the_rates() -> None:
    f = LookaheadFilter(LookaheadFilterSettings(hysteresis_m=0.5, max_growth_m_per_m=0.3, max_shrink_m_per_m=1.0))
    f.step(10.0, 5.0, 20.0, 0.2)
    assert f.step(10.4, 5.0, 20.0, 0.2) == 10.0  # inside the hysteresis band
    assert f.step(20.0, 5.0, 20.0, 0.2) == pytest.approx(10.06)  # grows 0.3 m per m travelled
    assert f.step(5.0, 5.0, 20.0, 0.2) == pytest.approx(9.86)  # shrinks 1 m per m travelled


def test_a_rising_floor_applies_at_once() -> None:
    f = LookaheadFilter(LookaheadFilterSettings(max_growth_m_per_m=0.01))
    f.step(6.0, 5.0, 20.0, 0.2)
    assert f.step(6.0, 9.0, 20.0, 0.2) == 9.0


def test_unlimited_rates_follow_at_once() -> None:
    f = LookaheadFilter(LookaheadFilterSettings(hysteresis_m=0.0, max_growth_m_per_m=None, max_shrink_m_per_m=None))
    f.step(5.0, 5.0, 20.0, 0.2)
    assert f.step(20.0, 5.0, 20.0, 0.2) == 20.0
    assert f.step(5.0, 5.0, 20.0, 0.2) == 5.0


@given(
    choices=st.lists(st.floats(0.0, 40.0), min_size=2, max_size=50),
    floor=st.floats(1.0, 10.0),
    growth=st.floats(0.01, 2.0),
    shrink=st.floats(0.01, 2.0),
)
@settings(max_examples=100, deadline=None)
def test_steps_stay_bounded_and_within_the_range(
    choices: list[float], floor: float, growth: float, shrink: float
) -> None:
    f = LookaheadFilter(LookaheadFilterSettings(0.5, growth, shrink))
    distance = 0.2
    previous = None
    for choice in choices:
        value = f.step(choice, floor, 20.0, distance)
        assert floor <= value <= 20.0
        if previous is not None:
            assert previous - shrink * distance - 1e-9 <= value <= previous + growth * distance + 1e-9
        previous = value


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [({"hysteresis_m": -1.0}, "hysteresis_m"), ({"max_growth_m_per_m": 0.0}, "max_growth_m_per_m"),
     ({"max_shrink_m_per_m": True}, "max_shrink_m_per_m")],
)  # fmt: skip
def test_bad_settings_are_refused(kwargs: dict, needle: str) -> None:
    with pytest.raises(WorkbenchInputError, match=needle):
        LookaheadFilterSettings(**kwargs)
