"""Tables against speed, each column interpolated linearly and clamped beyond the ends: the curvature limits
(`curvature_limits.py`), the lead filter's schedule (`filter_schedule.py`), the identified lags (`vehicle_tuning.py`)
and the preview responses' taps (`preview_model.py`). One compiled lookup (`bracket`) serves them all, from Python
and from the compiled step (`step_kernel.py`) alike, so that both read the same numbers.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def bracket(speeds: np.ndarray, speed: float) -> tuple[int, int, float]:
    """(low, high, t) of `speed` in `speeds` (increasing strictly): a row is rows[low] + t (rows[high] - rows[low]);
    a listed speed's row itself (low = high, t = 0), the first or last row beyond the ends."""
    n = speeds.size
    i = 0  # bisect_left: the first speed >= speed
    while i < n and speeds[i] < speed:
        i += 1
    if i < n and speeds[i] == speed:
        return i, i, 0.0
    if i == 0 or i == n:
        end = 0 if i == 0 else n - 1
        return end, end, 0.0
    return i - 1, i, (speed - speeds[i - 1]) / (speeds[i] - speeds[i - 1])


@njit(cache=True)
def table_row(speeds: np.ndarray, rows: np.ndarray, speed: float, clip: bool, out: np.ndarray) -> None:
    """Row `speed` of the table (rows[i] at speeds[i], speeds increasing strictly), its first out.size columns, into
    out: a listed speed's row as it stands, the first or last row beyond the ends, else each column a + t (b - a)
    between its neighbours (`bracket`); with clip, kept within [min(a, b), max(a, b)] against rounding (a
    schedule's ranges are then kept exactly)."""
    low, high, t = bracket(speeds, speed)
    if low == high:
        out[:] = rows[low, : out.size]
        return
    for k in range(out.size):
        a, b = rows[low, k], rows[high, k]
        value = a + t * (b - a)
        if clip:
            value = min(max(value, min(a, b)), max(a, b))
        out[k] = value
