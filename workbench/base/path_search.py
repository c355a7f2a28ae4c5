"""Compiled searches on a path's uniformly spaced samples: closest point in a window, first point beyond a distance.

These run every controller step (the simulator's CTE, every controller's own projection and lookahead), so they
are plain loops compiled with numba: about a microsecond where the equivalent numpy code costs 20-30 us in call
overhead. Indices of a closed loop's segments wrap modulo the segment count.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def closest_in_window(
    x: np.ndarray, y: np.ndarray, px: float, py: float, lo: int, hi: int, closed: bool
) -> tuple[int, float, float]:  # pragma: no cover - compiled
    """Closest point to (px, py) on segments lo..hi: (segment index as given, unwrapped; t in [0, 1]; distance^2)."""
    n_seg = x.size - 1
    best_j, best_t, best_d2 = lo, 0.0, np.inf
    for j in range(lo, hi + 1):
        i = j % n_seg if closed else j
        ax, ay = x[i], y[i]
        dx, dy = x[i + 1] - ax, y[i + 1] - ay
        t = ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy)
        t = min(max(t, 0.0), 1.0)
        ex, ey = ax + t * dx - px, ay + t * dy - py
        d2 = ex * ex + ey * ey
        if d2 < best_d2:
            best_j, best_t, best_d2 = j, t, d2
    return best_j, best_t, best_d2


@njit(cache=True)
def windowed_projection(
    x: np.ndarray, y: np.ndarray, px: float, py: float, center: int, half: int, closed: bool
) -> float:  # pragma: no cover - compiled
    """Fractional sample index of the closest point within `half` segments of `center`, the window grown while
    the closest point sits on its edge (so the search follows a monotone fall in distance, never a jump)."""
    n_seg = x.size - 1
    lo, hi = center - half, center + half
    while True:
        if not closed:
            lo, hi = max(lo, 0), min(hi, n_seg - 1)
        j, t, _ = closest_in_window(x, y, px, py, lo, hi, closed)
        low_edge = j == lo and t == 0.0 and (closed or lo > 0)
        high_edge = j == hi and t == 1.0 and (closed or hi < n_seg - 1)
        if not (low_edge or high_edge) or hi - lo >= n_seg:
            index = j + t
            return index % n_seg if closed else index
        if low_edge:
            lo -= half
        if high_edge:
            hi += half


@njit(cache=True)
def first_beyond(
    x: np.ndarray, y: np.ndarray, px: float, py: float, start: float, distance: float, closed: bool
) -> float:  # pragma: no cover - compiled
    """Fractional sample index of the first point at or after index `start` at least `distance` from (px, py).

    Walks forward at most one lap; returns -1.0 when no such point exists (the end of an open path is nearer)."""
    n_seg = x.size - 1
    i0 = int(start)
    frac0 = start - i0
    # The starting point itself (interpolated).
    i0w = i0 % n_seg if closed else min(i0, n_seg - 1)
    sx = x[i0w] + frac0 * (x[i0w + 1] - x[i0w])
    sy = y[i0w] + frac0 * (y[i0w + 1] - y[i0w])
    if math.hypot(sx - px, sy - py) >= distance:
        return start
    ax, ay, index_a = sx, sy, start
    last = i0 + n_seg if closed else n_seg
    for j in range(i0 + 1, last + 1):
        i = j % n_seg if closed else j
        bx, by = x[i], y[i]
        if math.hypot(bx - px, by - py) >= distance:
            # The circle of radius `distance` crosses segment A-B: solve |A + u (B - A) - P| = distance for u.
            dx, dy = bx - ax, by - ay
            ex, ey = ax - px, ay - py
            qa = dx * dx + dy * dy
            qb = 2.0 * (ex * dx + ey * dy)
            qc = ex * ex + ey * ey - distance * distance
            u = (-qb + math.sqrt(max(qb * qb - 4.0 * qa * qc, 0.0))) / (2.0 * qa) if qa > 0.0 else 1.0
            index = index_a + min(max(u, 0.0), 1.0) * (j - index_a)
            return index % n_seg if closed else index
        ax, ay, index_a = bx, by, float(j)
    return -1.0
