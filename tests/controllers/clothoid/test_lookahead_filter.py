"""How the lookahead follows the adaptive search's choice: floor at once, hysteresis, rate limits both ways (the
options ClothoidConfig.lookahead_hysteresis_m, max_lookahead_growth_m_per_m and max_lookahead_shrink_m_per_m)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lookahead_follower import LookaheadFilter

from controllers.clothoid import ClothoidConfig
from workbench.base.errors import WorkbenchInputError

#: How a refused rate limit's range reads.
RATE_RANGE = "must be a finite number in (0, 100] m per m"


def _config(hysteresis_m: float, growth: float | None, shrink: float | None) -> ClothoidConfig:
    """The clothoid controller's options with this lookahead hysteresis (m) and these rate limits (m per m)."""
    return ClothoidConfig(
        lookahead_hysteresis_m=hysteresis_m, max_lookahead_growth_m_per_m=growth, max_lookahead_shrink_m_per_m=shrink
    )


def test_first_choice_is_taken_within_the_floor_and_ceiling() -> None:
    f = LookaheadFilter(ClothoidConfig())
    assert f.step(3.0, 8.0, 20.0, 0.2) == 8.0
    f.reset()
    assert f.step(12.0, 8.0, 20.0, 0.2) == 12.0


def test_small_changes_are_ignored_and_large_ones_followed_at_the_rates() -> None:
    f = LookaheadFilter(_config(0.5, 0.3, 1.0))
    f.step(10.0, 5.0, 20.0, 0.2)
    assert f.step(10.4, 5.0, 20.0, 0.2) == 10.0  # inside the hysteresis band
    assert f.step(20.0, 5.0, 20.0, 0.2) == pytest.approx(10.06)  # grows 0.3 m per m travelled
    assert f.step(5.0, 5.0, 20.0, 0.2) == pytest.approx(9.86)  # shrinks 1 m per m travelled


def test_a_rising_floor_applies_at_once() -> None:
    f = LookaheadFilter(ClothoidConfig(max_lookahead_growth_m_per_m=0.01))
    f.step(6.0, 5.0, 20.0, 0.2)
    assert f.step(6.0, 9.0, 20.0, 0.2) == 9.0


def test_unlimited_rates_follow_at_once() -> None:
    f = LookaheadFilter(_config(0.0, None, None))
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
    f = LookaheadFilter(_config(0.5, growth, shrink))
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
    [({"lookahead_hysteresis_m": -1.0}, "lookahead_hysteresis_m"),
     ({"max_lookahead_growth_m_per_m": 0.0}, "max_lookahead_growth_m_per_m"),
     ({"max_lookahead_shrink_m_per_m": True}, "max_lookahead_shrink_m_per_m")],
)  # fmt: skip
def test_bad_settings_are_refused(kwargs: dict, needle: str) -> None:
    with pytest.raises(WorkbenchInputError, match=needle):
        ClothoidConfig(**kwargs)


# ------------------------------------------------------------------ each threshold and rate limit at its boundary
def _started(at_m: float, settings: ClothoidConfig | None = None) -> LookaheadFilter:
    f = LookaheadFilter(settings or ClothoidConfig())
    assert f.step(at_m, 5.0, 20.0, 0.2) == at_m
    return f


def test_the_default_hysteresis_is_half_a_metre_inclusive() -> None:
    f = _started(10.0)
    assert f.step(10.5, 5.0, 20.0, 10.0) == 10.0  # exactly the hysteresis: ignored
    assert f.step(9.5, 5.0, 20.0, 10.0) == 10.0
    assert f.step(10.5001, 5.0, 20.0, 10.0) == 10.5001  # just beyond: followed (the rate allows 3 m here)
    f = _started(10.0)
    assert f.step(9.4999, 5.0, 20.0, 10.0) == 9.4999


@pytest.mark.parametrize(
    ("choice", "distance", "expected"),
    [(20.0, 1.0, 10.3), (5.0, 1.0, 9.5), (10.59, 2.0, 10.59), (10.61, 2.0, 10.6), (9.01, 2.0, 9.01), (8.99, 2.0, 9.0)],
)
def test_the_default_rates_are_0_3_longer_and_0_5_shorter_per_metre(
    choice: float, distance: float, expected: float
) -> None:
    """At most 0.3 m longer and 0.5 m shorter per metre travelled; a choice within the rate is taken."""
    assert _started(10.0).step(choice, 5.0, 20.0, distance) == pytest.approx(expected, abs=1e-12)


def test_the_rate_limit_scales_with_the_distance_travelled() -> None:
    assert _started(10.0).step(20.0, 5.0, 20.0, 0.0) == 10.0  # standing still: no change
    assert _started(10.0).step(20.0, 5.0, 20.0, 2.0) == pytest.approx(10.6, abs=1e-12)
    assert _started(10.0).step(5.0, 5.0, 20.0, 2.0) == pytest.approx(9.0, abs=1e-12)


def test_a_falling_floor_takes_the_lookahead_down_by_as_much() -> None:
    f = _started(12.0, ClothoidConfig(max_lookahead_growth_m_per_m=0.3))
    assert f.step(12.0, 10.0, 20.0, 0.0) == 12.0  # a floor below the lookahead changes nothing
    assert f.step(12.0, 8.0, 20.0, 0.0) == 10.0  # the floor fell by 2 m: so does the lookahead (and no growth at 0 m)
    assert f.step(12.0, 8.0, 20.0, 0.0) == 10.0  # the same floor again: no further fall
    assert f.step(10.0, 3.0, 20.0, 0.0) == 5.0  # down by 5 m with the floor; the choice waits for distance travelled


def test_a_ceiling_below_the_floor_yields_the_floor() -> None:
    assert LookaheadFilter(ClothoidConfig()).step(15.0, 10.0, 5.0, 0.2) == 10.0


@pytest.mark.parametrize(
    ("kwargs", "allowed"),
    [
        ({"lookahead_hysteresis_m": 0.0}, True),
        ({"lookahead_hysteresis_m": 50.0}, True),
        ({"lookahead_hysteresis_m": 50.000001}, False),
        ({"lookahead_hysteresis_m": -1e-9}, False),
        ({"max_lookahead_growth_m_per_m": 100.0}, True),
        ({"max_lookahead_growth_m_per_m": 100.000001}, False),
        ({"max_lookahead_growth_m_per_m": 1e-9}, True),
        ({"max_lookahead_shrink_m_per_m": 100.0}, True),
        ({"max_lookahead_shrink_m_per_m": 100.000001}, False),
        ({"max_lookahead_shrink_m_per_m": 0.0}, False),
        ({"max_lookahead_shrink_m_per_m": None}, True),
        ({"max_lookahead_growth_m_per_m": None}, True),
    ],
)
def test_settings_are_allowed_up_to_their_bounds(kwargs: dict, allowed: bool) -> None:
    if allowed:
        ClothoidConfig(**kwargs)
    else:
        with pytest.raises(WorkbenchInputError, match=next(iter(kwargs))):
            ClothoidConfig(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"lookahead_hysteresis_m": 51.0}, "lookahead_hysteresis_m must be a finite number in [0, 50] m; got 51.0"),
        ({"max_lookahead_growth_m_per_m": 0.0}, f"max_lookahead_growth_m_per_m {RATE_RANGE}"),
        ({"max_lookahead_shrink_m_per_m": 101.0}, f"max_lookahead_shrink_m_per_m {RATE_RANGE}"),
    ],
)
def test_a_refused_setting_is_named_with_its_unit_and_range(kwargs: dict, message: str) -> None:
    with pytest.raises(WorkbenchInputError) as refused:
        ClothoidConfig(**kwargs)
    assert str(refused.value).startswith(message)
