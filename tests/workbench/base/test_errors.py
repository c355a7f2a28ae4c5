"""The input-error helpers: messages show numbers as Python writes them, numpy scalars included."""

from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.base.errors import WorkbenchInputError, require_finite, require_in_range, require_positive, value_text


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (np.float64("nan"), "nan"),
        (np.float64(1e308), "1e+308"),
        (np.float32(0.5), "0.5"),
        (np.int64(3), "3"),
        (np.bool_(True), "True"),
        (float("-inf"), "-inf"),
        ("abc", "'abc'"),
        (None, "None"),
    ],
)
def test_value_text(value: object, text: str) -> None:
    assert value_text(value) == text


def test_messages_print_numpy_numbers_as_numbers() -> None:
    with pytest.raises(WorkbenchInputError) as info:
        require_positive("speed_kmh", np.float64("nan"))
    assert str(info.value) == "speed_kmh must be a finite number > 0; got nan"
    with pytest.raises(WorkbenchInputError) as info:
        require_in_range("psi", np.float64(1e308), np.float64(0.1), 5, "-")
    assert str(info.value) == "psi must be a finite number in [0.1, 5] -; got 1e+308"
    with pytest.raises(WorkbenchInputError) as info:
        require_finite("x_m", np.array([0.0, np.inf]))
    assert str(info.value) == "x_m must be finite numbers; entry 1 is inf"
    assert "np." not in str(info.value)


def test_numpy_numbers_are_numbers() -> None:
    require_positive("laps", np.int64(2))
    require_in_range("zeta", np.float32(0.8), 0.0, 5.0)
    with pytest.raises(WorkbenchInputError, match="got True"):
        require_positive("laps", np.bool_(True))


def test_one_range_check_for_every_layer() -> None:
    """`require_in_range` is the one range check: a closed or half-open range, a note on what is allowed, the same
    message for a value outside, NaN or a boolean, its bounds in their shortest exact form."""
    from workbench.base.errors import bound_text, range_text

    require_in_range("psi", 5.0, 0.0, 5.0, low_open=True)
    for value in (0.0, 5.5, math.nan, True):
        with pytest.raises(WorkbenchInputError) as info:
            require_in_range("psi", value, 0.0, 5.0, low_open=True, note="0.7: the paper's")
        assert str(info.value) == f"psi must be a finite number in (0, 5] (0.7: the paper's); got {value_text(value)}"
    assert [bound_text(v) for v in (400.0, 1e-3, 1e9, 0.1 + 0.2, -math.inf)] == [
        "400", "0.001", "1e+09", "0.30000000000000004", "-inf",
    ]  # fmt: skip
    assert range_text(0.0, 2.0, "s", note="0: none") == "[0, 2] s (0: none)"


def test_the_config_rules_refuse_with_the_base_checks() -> None:
    """The controllers' option rules (`config_checks`) refuse a value with the base layer's own messages."""
    from controllers.config_checks import Choice, Flag, Number, Whole
    from workbench.base.errors import require_bool, require_choice, require_whole

    cases = [
        (Number(0.0, 100.0, "m", low_open=True, none_means="unlimited"), 0.0,
         lambda: require_in_range("x", 0.0, 0.0, 100.0, "m", low_open=True, note="or None: unlimited")),
        (Whole(2, 500), 1.0, lambda: require_whole("x", 1.0, 2, 500)),
        (Choice(("a", "b")), "c", lambda: require_choice("x", "c", ("a", "b"))),
        (Flag(), 1, lambda: require_bool("x", 1)),
    ]  # fmt: skip
    for rule, value, base in cases:
        with pytest.raises(WorkbenchInputError) as by_rule:
            rule.check("x", value)
        with pytest.raises(WorkbenchInputError) as by_base:
            base()
        assert str(by_rule.value) == str(by_base.value)


def test_the_other_checks_name_the_value_and_what_is_allowed() -> None:
    from workbench.base.errors import require_bool, require_choice, require_instance_or_none, require_whole, shown_all

    with pytest.raises(WorkbenchInputError, match=r"^n must be a whole number in \[2, 5\]; got 2\.0$"):
        require_whole("n", 2.0, 2, 5)
    with pytest.raises(WorkbenchInputError, match=r"^f must be true or false; got 1$"):
        require_bool("f", np.int64(1))
    with pytest.raises(WorkbenchInputError, match=r"^mode must be one of a, b; got 'c'$"):
        require_choice("mode", "c", ("a", "b"))
    with pytest.raises(WorkbenchInputError, match=r"^lags must be a tuple or None; got 3$"):
        require_instance_or_none("lags", 3, tuple)
    require_whole("n", np.int64(5), 2, 5)
    require_instance_or_none("lags", None, tuple)
    assert shown_all(np.array([5.0, 10.0])) == "[5.0, 10.0]" and shown_all(x for x in (1, 2)) == "[1, 2]"
