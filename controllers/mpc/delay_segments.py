"""The MPCs' known-delay compensation, compiled parts: the commands sent, as segments of constant rate over the
delay window (`delay_segments`), padded to whole chunks (`chunked`) for the compiled integrator
(`MPCController.predict_ahead`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Command knots closer than this (s) to an end of the prediction window start no segment of their own.
KNOT_MERGE_S = 1e-9


@njit(cache=True)
def chunked(
    durations: np.ndarray, rates: np.ndarray, chunk: int, speed_mps: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """Segments padded with empty ones (duration and rate 0) to whole chunks: (durations, rates, progress at
    each node estimated at speed_mps, the padding's at the last). Compiled: it runs every step."""
    k = durations.shape[0]
    size = max(1, -(-k // chunk)) * chunk
    dt, u, nodes = np.zeros(size), np.zeros(size), np.zeros(size + 1)
    for i in range(k):
        dt[i], u[i] = durations[i], rates[i]
    for i in range(size):
        nodes[i + 1] = nodes[i] + speed_mps * dt[i]
    return dt, u, nodes


@njit(cache=True)
def delay_segments(
    times: np.ndarray, commands: np.ndarray, start: float, horizon: float, max_step: float
) -> tuple[np.ndarray, np.ndarray, float]:  # pragma: no cover - compiled
    """The commanded angle over [start, start + horizon] as segments: (durations (s), rates (rad/s), the angle at
    start). The angle is the buffered commands linearly interpolated in time, held before the first and after the
    last; segments break at the buffered times and are at most max_step long. Compiled: it runs every step."""
    end = start + horizon
    breaks = np.empty(times.shape[0] + 2)
    breaks[0] = start
    count = 1
    for t in times:
        if start + KNOT_MERGE_S < t < end - KNOT_MERGE_S:
            breaks[count] = t
            count += 1
    breaks[count] = end
    count += 1
    pieces = np.empty(count - 1, dtype=np.int64)
    for i in range(count - 1):
        pieces[i] = max(1, math.ceil((breaks[i + 1] - breaks[i]) / max_step - 1e-9))
    durations = np.empty(pieces.sum())
    rates = np.empty(durations.shape[0])
    first = np.interp(start, times, commands)
    before, j = first, 0
    for i in range(count - 1):
        after = np.interp(breaks[i + 1], times, commands)
        length = breaks[i + 1] - breaks[i]
        for _ in range(pieces[i]):
            durations[j] = length / pieces[i]
            rates[j] = (after - before) / length if length > 0.0 else 0.0
            j += 1
        before = after
    return durations, rates, first
