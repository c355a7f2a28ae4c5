"""The Savitzky-Golay operator matrices against scipy.signal.savgol_filter."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from tuning.savgol import savgol_matrix
from workbench.base.errors import WorkbenchInputError


@settings(max_examples=30, deadline=None)
@given(
    n=st.integers(20, 400),
    half=st.integers(2, 9),
    deriv=st.integers(0, 2),
    dt=st.floats(1e-3, 0.5),
    seed=st.integers(0, 2**16),
)
def test_matches_savgol_filter_interp_mode(n: int, half: int, deriv: int, dt: float, seed: int) -> None:
    window = 2 * half + 1
    y = np.random.default_rng(seed).normal(size=n).cumsum()
    expected = signal.savgol_filter(y, window, 3, deriv=deriv, delta=dt, mode="interp")
    scale = max(1.0, float(np.abs(expected).max()))
    np.testing.assert_allclose(savgol_matrix(n, window, deriv, dt) @ y, expected, atol=1e-9 * scale)


def test_bad_windows() -> None:
    for window in (4, 3, 41):
        with pytest.raises(WorkbenchInputError, match="window must be odd"):
            savgol_matrix(40, window, 1, 0.01)
