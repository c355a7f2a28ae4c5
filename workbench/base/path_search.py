"""Compiled searches on a path's uniformly spaced samples: closest point in a window, first point beyond a distance.

These run every controller step (the simulator's CTE, every controller's own projection and lookahead), so they
are plain loops compiled with numba: about a microsecond where the equivalent numpy code costs 20-30 us in call
overhead. Indices of a closed loop's segments wrap modulo the segment count.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

#: Rows of a compiled path's table (`CompiledPath.table`, shape (PATH_ROWS, n)): the samples' x, y (m), heading
#: (rad, unwrapped), curvature (1/m) and planned speed (m/s; NaN when the path carries none).
PATH_X, PATH_Y, PATH_HEADING, PATH_CURVATURE, PATH_SPEED = range(5)
PATH_ROWS = 5
#: A compiled path's scalars (`CompiledPath.record`, one record): the sample spacing (m), the length (m), whether it
#: is a closed loop, its bounding box's diagonal (m: a move longer than this searches the whole path), the least
#: window a tracker searches each way (m) and the longest chord between neighbouring samples (m, `first_beyond`).
PATH_RECORD = np.dtype(
    [(name, np.float64) for name in ("spacing", "length")]
    + [("closed", np.bool_)]
    + [(name, np.float64) for name in ("extent", "window", "max_segment")]
)


@dataclass(frozen=True, eq=False)
class CompiledPath:
    """A path as the compiled kernels read it: its samples as one table (rows PATH_*) and its scalars as one
    record (PATH_RECORD, a structured array of one element), handed together to every kernel that walks the path.
    Made by `ReferencePath.compiled`."""

    table: np.ndarray
    record: np.ndarray

    @classmethod
    def of(
        cls,
        samples: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray | None],
        spacing_m: float,
        length_m: float,
        closed: bool,
        max_segment_m: float,
        min_window_m: float,
    ) -> CompiledPath:
        """The compiled form of samples (x, y, heading, curvature, speed or None) spaced spacing_m apart over
        length_m."""
        x, y, heading, curvature, speed = samples
        table = np.empty((PATH_ROWS, x.size))
        table[PATH_X], table[PATH_Y], table[PATH_HEADING], table[PATH_CURVATURE] = x, y, heading, curvature
        table[PATH_SPEED] = np.nan if speed is None else speed
        record = np.zeros(1, PATH_RECORD)
        record["spacing"] = spacing_m
        record["length"] = length_m
        record["closed"] = closed
        record["extent"] = float(math.hypot(np.ptp(x), np.ptp(y)))
        record["window"] = min_window_m
        record["max_segment"] = max_segment_m
        return cls(table, record)

    @property
    def extent_m(self) -> float:
        """The diagonal of the path's bounding box (m)."""
        return float(self.record[0]["extent"])

    @property
    def min_window_m(self) -> float:
        """The least window a tracker searches each way (m)."""
        return float(self.record[0]["window"])


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
    x: np.ndarray, y: np.ndarray, px: float, py: float, start: float, distance: float, closed: bool, max_segment: float
) -> float:  # pragma: no cover - compiled
    """Fractional sample index of the first point at or after index `start` at least `distance` from (px, py).

    Walks forward at most one lap; returns -1.0 when no such point exists (the end of an open path is nearer).
    max_segment: the longest chord between neighbouring samples (`ReferencePath.max_segment_m`; inf: none known).
    A sample k chords past the start is at most r0 + k max_segment from (px, py), r0 the start's own distance, so
    the walk skips the samples that bound keeps nearer than `distance` and measures only from there on: the
    same answer, bit for bit, from a few samples instead of every one up to the target (a 20 m lookahead on a
    path sampled every 0.1 m: 200).
    """
    n_seg = x.size - 1
    i0 = int(start)
    frac0 = start - i0
    # The starting point itself (interpolated).
    i0w = i0 % n_seg if closed else min(i0, n_seg - 1)
    sx = x[i0w] + frac0 * (x[i0w + 1] - x[i0w])
    sy = y[i0w] + frac0 * (y[i0w + 1] - y[i0w])
    r0 = math.hypot(sx - px, sy - py)
    if r0 >= distance:
        return start
    last = i0 + n_seg if closed else n_seg
    # The first sample the bound lets reach `distance`, one before it against rounding.
    reach = start + (distance - r0) / max_segment - 1.0 if max_segment > 0.0 else start
    first = i0 + 1
    if reach > first:
        first = int(min(reach, float(last + 1)))
    ax, ay, index_a = sx, sy, start
    if first > i0 + 1:
        i = (first - 1) % n_seg if closed else first - 1
        ax, ay, index_a = x[i], y[i], float(first - 1)
    for j in range(first, last + 1):
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


#: Layout of a tracker's state array (`track`): the foot point's arc length (NaN before the first update), the
#: progress along the path (laps counted), and the last position projected (NaN before the first update).
TRACK_S, TRACK_PROGRESS, TRACK_LAST_X, TRACK_LAST_Y = 0, 1, 2, 3
TRACK_STATE_SIZE = 4
#: Layout of `track`'s output: the foot point's arc length, progress, x, y, heading, curvature, the signed CTE,
#: at_end (1.0 / 0.0), past_end_m and distance_m (`path.Projection`'s fields, in its order).
TRACK_OUT_SIZE = 10


@njit(cache=True)
def track(
    table: np.ndarray, record: np.ndarray, state: np.ndarray, px: float, py: float, out: np.ndarray
) -> None:  # pragma: no cover - compiled
    """One `path.PathTracker.update` of the finite position (px, py) on the compiled path (`CompiledPath`'s table
    and record): the foot point searched in a window about the last (sized by how far the position moved, at
    least the record's window each way; over the whole path on the first update or after a jump longer than the
    record's extent, the path's bounding-box diagonal), the progress advanced (the shortest way round a loop's
    seam) in `state`, and the projection written to `out` (TRACK_OUT_SIZE)."""
    x, y, heading, curvature = table[PATH_X], table[PATH_Y], table[PATH_HEADING], table[PATH_CURVATURE]
    shape = record[0]
    spacing, length, closed = shape.spacing, shape.length, shape.closed
    extent, min_window = shape.extent, shape.window
    n_seg = x.size - 1
    s_old = state[TRACK_S]
    moved = 0.0
    if not math.isnan(state[TRACK_LAST_X]):
        moved = math.hypot(px - state[TRACK_LAST_X], py - state[TRACK_LAST_Y])
    if math.isnan(s_old) or moved > extent:  # the first update, or a jump: search it all
        j, t, _ = closest_in_window(x, y, px, py, 0, n_seg - 1, False)
        s_new = (j + t) * spacing
        if math.isnan(s_old):
            state[TRACK_PROGRESS] = s_new
        else:
            state[TRACK_PROGRESS] += s_new - s_old
    else:
        half = min(math.ceil(max(min_window, 2.0 * moved) / spacing), n_seg)  # no window needs the whole path
        s_m = windowed_projection(x, y, px, py, int(s_old / spacing), half, closed) * spacing
        s_new = s_m % length if closed else min(s_m, length)  # [0, L) on a loop
        delta = s_new - s_old
        if closed:  # shortest way round the seam
            delta = (delta + 0.5 * length) % length - 0.5 * length
        state[TRACK_PROGRESS] += delta
    state[TRACK_S] = s_new
    state[TRACK_LAST_X] = px
    state[TRACK_LAST_Y] = py

    i = min(int(s_new / spacing), n_seg - 1)
    frac = s_new / spacing - i
    fx = x[i] + frac * (x[i + 1] - x[i])
    fy = y[i] + frac * (y[i + 1] - y[i])
    h = heading[i] + frac * (heading[i + 1] - heading[i])
    k = curvature[i] + frac * (curvature[i + 1] - curvature[i])
    # the signed CTE: the component of (position - foot) along the path's left normal
    cos_h, sin_h = math.cos(h), math.sin(h)
    cte = -(px - fx) * sin_h + (py - fy) * cos_h
    along = (px - fx) * cos_h + (py - fy) * sin_h  # 0 beside the path; beyond an end, how far beyond
    at_end, past_end = False, 0.0
    if not closed:
        at_end = s_new >= length - 1e-9
        if at_end or s_new <= 1e-9:
            past_end = max(along if at_end else -along, 0.0)
    out[0], out[1], out[2], out[3], out[4] = s_new, state[TRACK_PROGRESS], fx, fy, h
    out[5], out[6], out[7], out[8], out[9] = k, cte, 1.0 if at_end else 0.0, past_end, math.hypot(cte, along)


@njit(cache=True)
def track_sequence(
    table: np.ndarray,
    record: np.ndarray,
    state: np.ndarray,
    px: np.ndarray,
    py: np.ndarray,
    s_out: np.ndarray,
    cte_out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """`track` for each of a sequence of finite positions in turn (a trace's, step by step), writing each foot
    point's arc length and signed CTE to s_out and cte_out: one call for a whole trace instead of one per step."""
    out = np.empty(TRACK_OUT_SIZE)
    for k in range(px.size):
        track(table, record, state, px[k], py[k], out)
        s_out[k] = out[0]
        cte_out[k] = out[6]


@njit(cache=True)
def value_at(values: np.ndarray, s: float, spacing: float, length: float, closed: bool) -> float:
    """A per-sample quantity of the path (x, y, heading, curvature, ...) at arc length s (m), interpolated linearly
    between samples: s taken modulo the length on a loop, clipped to [0, length] on an open path."""
    s = s % length if closed else min(max(s, 0.0), length)
    position = s / spacing
    i = min(int(position), values.size - 2)
    return values[i] + (position - i) * (values[i + 1] - values[i])


@njit(cache=True)
def slope_at(values: np.ndarray, s: float, spacing: float, length: float, closed: bool) -> float:
    """d(values)/ds at arc length s (per m): the slope of `value_at`'s interpolation, constant between two samples,
    the segment ahead at a sample."""
    s = s % length if closed else min(max(s, 0.0), length)
    i = min(int(s / spacing), values.size - 2)
    return (values[i + 1] - values[i]) / spacing
