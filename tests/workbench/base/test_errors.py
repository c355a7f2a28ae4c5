"""The input-error helpers: messages show numbers as Python writes them, numpy scalars included."""

from __future__ import annotations

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
    assert str(info.value) == "psi must be in [0.1, 5] -; got 1e+308"
    with pytest.raises(WorkbenchInputError) as info:
        require_finite("x_m", np.array([0.0, np.inf]))
    assert str(info.value) == "x_m must be finite numbers; entry 1 is inf"
    assert "np." not in str(info.value)


def test_numpy_numbers_are_numbers() -> None:
    require_positive("laps", np.int64(2))
    require_in_range("zeta", np.float32(0.8), 0.0, 5.0)
    with pytest.raises(WorkbenchInputError, match="got True"):
        require_positive("laps", np.bool_(True))
