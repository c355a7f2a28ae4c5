"""Lookahead selection for the clothoid controller: adaptive by Fréchet distance (paper, section 3), fixed, or
proportional to speed.

For a candidate lookahead distance l: the target is the first path point ahead of the vehicle's foot point at
Euclidean distance l from the rear axle (near the end of an open path, the point at l on the path's straight
extension beyond its end: aiming at the end itself would shrink l to zero and the clothoid's kappa', which goes as
1 / l^2, would saturate in the last metres); the hyper-clothoid is fitted from the vehicle's pose and curvature to it;
both the clothoid and the reference path from the foot point to the target are sampled at the same number of
points, and their discrete Fréchet distance measures how differently they run (Figure 3b).

The adaptive mode picks the largest l in [l_min, l_max] (on a grid of `step`) whose Fréchet distance stays under
the threshold and whose clothoid ends within the tolerances (delta_x, delta_y) of the target (Eq. 3). The paper
reports that the Fréchet distance grows monotonically with l (Figure 4b), so a bisection finds it in about
log2(grid size) fits instead of one per candidate. When no candidate qualifies (the vehicle is farther off the
path than the threshold: the Fréchet distance is at least the end-point distance |CTE|), it takes the candidate
of least Fréchet distance (Figure 5b's "minimum Fréchet distance"), found by a coarse scan refined around its
best point. Everything here is compiled with numba: a step's whole search costs tens of microseconds.
`turn_limited_lookahead` is the geometric ceiling: no target farther round a bend than a given turn of the path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from controllers.clothoid.clothoid_fit import FIT_UNREACHABLE, fit_kernel, sample_kernel
from controllers.clothoid.frechet import frechet_below
from workbench.base.path import ReferencePath
from workbench.base.path_search import PATH_HEADING, PATH_X, PATH_Y, first_beyond

#: Most points per sampled curve (the Fréchet cost grows with its square).
MAX_CURVE_POINTS = 64
#: The adaptive search's settings (`adaptive_search`'s `settings`, one record): the grid's step (m), the
#: tolerances on the clothoid's end point (m, Eq. 3), the curvature rate's saturation (1/m^2) and the spacing of
#: the points the Fréchet distance compares (m). Any record with these fields serves (the clothoid step's own
#: parameters, `step_kernel.PARAMS`).
SEARCH_SETTINGS = np.dtype(
    [(name, np.float64) for name in ("lookahead_step", "tolerance_x", "tolerance_y", "kdot_max", "point_spacing")]
)


def search_settings(
    step_m: float, tolerance_x_m: float, tolerance_y_m: float, kdot_max_1pm2: float, point_spacing_m: float
) -> np.ndarray:
    """The adaptive search's settings as one record (SEARCH_SETTINGS, a structured array of one element)."""
    settings = np.zeros(1, SEARCH_SETTINGS)
    settings[0] = (step_m, tolerance_x_m, tolerance_y_m, kdot_max_1pm2, point_spacing_m)
    return settings


@njit(cache=True)
def candidate_count(min_m: float, max_m: float, step_m: float) -> int:
    """Number of candidates min_m, min_m + step_m, ... up to max_m (a rounding slack of 1e-9 steps)."""
    return int((max_m - min_m) / step_m + 1e-9) + 1


@njit(cache=True)
def _point_at_index(x: np.ndarray, y: np.ndarray, index: float, closed: bool) -> tuple[float, float]:
    """The point at a fractional sample index; on an open path an index past the end extends its last segment."""
    n_seg = x.size - 1
    if closed:
        index = index % n_seg
    i = min(int(index), n_seg - 1)
    f = index - i
    return x[i] + f * (x[i + 1] - x[i]), y[i] + f * (y[i + 1] - y[i])


@njit(cache=True)
def _beyond_end(x: np.ndarray, y: np.ndarray, px: float, py: float, distance_m: float) -> float:
    """How many last-segment lengths past the end of an open path lies the point of the path's straight extension
    at `distance_m` from (px, py) (0 when the end itself is at least that far)."""
    ux, uy = x[-1] - x[-2], y[-1] - y[-2]
    seg = np.hypot(ux, uy)
    ux, uy = ux / seg, uy / seg
    dx, dy = x[-1] - px, y[-1] - py
    along = dx * ux + dy * uy
    disc = along * along - (dx * dx + dy * dy) + distance_m * distance_m  # |d + t u| = distance, solved for t
    if disc <= 0.0:
        return 0.0
    return max(0.0, -along + np.sqrt(disc)) / seg


@njit(cache=True)
def evaluate_candidate(
    table: np.ndarray,
    record: np.ndarray,
    foot_index: float,
    px: float,
    py: float,
    theta: float,
    kappa0: float,
    lookahead_m: float,
    kdot_max: float,
    point_spacing_m: float,
    buffers: np.ndarray,
    limit_m: float,
) -> tuple[float, float, float, float, float, float, float, int]:  # pragma: no cover - compiled
    """Fit and score one lookahead distance on the compiled path (`path_search.CompiledPath`'s table and record).

    Returns (frechet_m, kdot, length_m, target_x, target_y, end_x, end_y, status); buffers is a (4, MAX) work
    array for the sampled clothoid (rows 0, 1) and reference (rows 2, 3); frechet_m is inf once it is known to
    exceed limit_m (`frechet.frechet_below`; inf: always the distance itself).
    """
    path_x, path_y = table[PATH_X], table[PATH_Y]
    shape = record[0]
    closed = shape.closed
    n_seg = path_x.size - 1
    target_index = first_beyond(path_x, path_y, px, py, foot_index, lookahead_m, closed, shape.max_segment)
    if target_index < 0.0:  # the open path ends nearer than the lookahead: aim beyond it, on its last tangent
        target_index = float(n_seg) + _beyond_end(path_x, path_y, px, py, lookahead_m)
    tx, ty = _point_at_index(path_x, path_y, target_index, closed)
    kdot, length, ex, ey, status = fit_kernel(px, py, theta, kappa0, tx, ty, kdot_max)

    span = target_index - foot_index
    if closed and span < 0.0:
        span += n_seg
    n = max(3, min(buffers.shape[1], int(max(lookahead_m, 1.0) / point_spacing_m) + 1))
    sample_kernel(px, py, theta, kappa0, kdot, length, n, buffers[0], buffers[1])
    for k in range(n):
        rx, ry = _point_at_index(path_x, path_y, foot_index + span * k / (n - 1), closed)
        buffers[2, k] = rx
        buffers[3, k] = ry
    frechet = frechet_below(buffers[0, :n], buffers[1, :n], buffers[2, :n], buffers[3, :n], limit_m)
    return frechet, kdot, length, tx, ty, ex, ey, status


@njit(cache=True)
def evaluated(
    scores: np.ndarray, results: np.ndarray, min_lookahead_m: float, step_m: float, lookahead_m: float
) -> int:  # pragma: no cover - compiled
    """The candidate of the last `adaptive_search` (from min_lookahead_m by step_m) that was evaluated at exactly
    lookahead_m, whose results[k] `evaluate_candidate` would return again for it; -1 if none."""
    k = round((lookahead_m - min_lookahead_m) / step_m)
    if 0 <= k < scores.size and math.isfinite(scores[k]) and min_lookahead_m + k * step_m == lookahead_m:
        return k  # evaluated in full (a score cut short is inf)
    return -1


@njit(cache=True)
def adaptive_search(
    table: np.ndarray,
    record: np.ndarray,
    settings: np.ndarray,
    foot_index: float,
    px: float,
    py: float,
    theta: float,
    kappa0: float,
    min_lookahead_m: float,
    max_lookahead_m: float,
    threshold_m: float,
    hint_m: float,
    buffers: np.ndarray,
    scores: np.ndarray,
    results: np.ndarray,
) -> tuple[float, int]:  # pragma: no cover - compiled
    """The chosen lookahead (m) on the compiled path (`path_search.CompiledPath`'s table and record) and the number
    of candidates evaluated; settings: the grid's step, the end point's tolerances, the curvature rate's saturation
    and the Fréchet points' spacing (a record with SEARCH_SETTINGS's fields, `search_settings`); scores[k] holds
    candidate k's Fréchet distance (NaN where not evaluated, inf where it was cut short: more than the threshold in
    the bisection, more than the least so far in the fallback's scan, so that it could not change the choice),
    with candidate k at min + k step, and results[k] (scores.size, 8) all that `evaluate_candidate` returned for
    it (`evaluated`).

    hint_m: where to start (NaN: from the range's ends). The choice moves little from one step to the next, so
    a controller passes its last one: the hint and the candidate above it settle the search in two evaluations
    when the hint still holds; otherwise it gallops (1, 2, 4, ... candidates) to where admissibility changes and
    bisects there; when nothing qualifies from the hint down, the floor is taken if the candidate above it is no
    nearer. Where admissibility falls with the lookahead and the Fréchet distance does not fall from the floor's
    (the paper's Figure 4b; the premises of the search from the ends too), both starts choose the same candidate
    (`test_lookahead.py`); elsewhere each finds one of the places where admissibility changes.
    """
    search = settings[0]
    step_m, tolerance_x_m, tolerance_y_m = search.lookahead_step, search.tolerance_x, search.tolerance_y
    kdot_max, point_spacing_m = search.kdot_max, search.point_spacing
    count = max(1, min(candidate_count(min_lookahead_m, max_lookahead_m, step_m), scores.size))
    scores[:] = np.nan
    evaluations = 0

    def admissible(k: int, limit: float) -> bool:
        fd, kdot, length, tx, ty, ex, ey, status = evaluate_candidate(
            table, record, foot_index, px, py, theta, kappa0, min_lookahead_m + k * step_m, kdot_max,
            point_spacing_m, buffers, limit,
        )  # fmt: skip
        scores[k] = fd
        row = results[k]
        row[0], row[1], row[2], row[3], row[4], row[5], row[6], row[7] = fd, kdot, length, tx, ty, ex, ey, status
        return (
            fd <= threshold_m
            and status != FIT_UNREACHABLE
            and abs(ex - tx) <= tolerance_x_m
            and abs(ey - ty) <= tolerance_y_m
        )

    top = count - 1
    lo, hi = -1, -1  # once found: lo qualifies and hi does not; the bisection below closes the gap
    if math.isfinite(hint_m):
        k = min(max(round((hint_m - min_lookahead_m) / step_m), 0), top)
        evaluations += 1
        if admissible(k, np.inf if k == 0 or k == top else threshold_m):  # the ends in full, as below
            if k == top:
                return min_lookahead_m + top * step_m, evaluations
            stride = 1  # gallop up to the first candidate that does not qualify
            while hi < 0:
                probe = min(k + stride, top)
                evaluations += 1
                if not admissible(probe, np.inf if probe == top else threshold_m):
                    lo, hi = k, probe
                elif probe == top:
                    return min_lookahead_m + top * step_m, evaluations
                else:
                    k, stride = probe, 2 * stride
        else:
            stride = 1  # gallop down to the first candidate that qualifies
            while lo < 0 and k > 0:
                probe = max(k - stride, 0)
                evaluations += 1
                if admissible(probe, np.inf if probe == 0 else threshold_m):
                    lo, hi = probe, k
                else:
                    k, stride = probe, 2 * stride
            if lo < 0:  # nothing qualifies from the hint down: the floor, unless the candidate above is nearer
                if top == 0:
                    return min_lookahead_m, evaluations
                evaluations += 1
                admissible(1, scores[0])
                if scores[1] >= scores[0]:
                    return min_lookahead_m, evaluations
                scores[:] = np.nan  # the distance falls from the floor's: the search from the ends
    if lo < 0:
        evaluations += 1
        if admissible(top, np.inf):  # the ends in full: the fallback below may need their distances
            return min_lookahead_m + top * step_m, evaluations
        evaluations += 1
        if not admissible(0, np.inf):
            # Nothing qualifies: the candidate of least Fréchet distance, coarse scan then its neighbours.
            stride = max(1, count // 6)
            best = 0
            for k in range(stride, count, stride):
                evaluations += 1
                admissible(k, scores[best])
                if scores[k] < scores[best]:
                    best = k
            for k in range(max(0, best - stride + 1), min(count, best + stride)):
                if np.isnan(scores[k]):
                    evaluations += 1
                    admissible(k, scores[best])
                if scores[k] < scores[best]:
                    best = k
            return min_lookahead_m + best * step_m, evaluations
        lo, hi = 0, top
    while hi - lo > 1:  # lo qualifies, hi does not: bisect (Fréchet distance grows with the lookahead)
        mid = (lo + hi) // 2
        evaluations += 1
        if admissible(mid, threshold_m):
            lo = mid
        else:
            hi = mid
    return min_lookahead_m + lo * step_m, evaluations


@njit(cache=True)
def turn_limited_lookahead(
    table: np.ndarray,
    record: np.ndarray,
    foot_index: float,
    px: float,
    py: float,
    max_turn_rad: float,
    max_m: float,
) -> float:  # pragma: no cover - compiled
    """The longest lookahead (m, at most max_m) whose target (`first_beyond` from (px, py)) the path reaches before
    its heading has turned by more than max_turn_rad from the heading at the foot point: the largest distance from
    (px, py) of the samples before that turn. Why (controller.py, ClothoidConfig.max_target_turn_deg): a lateral
    offset of the vehicle shows at a target a turn theta round the bend only as offset x cos(theta), and Eq. 3's
    gain on it falls with it. A closed path's unwrapped headings continue over its seam; beyond an open path's end
    the target lies on its straight extension, which turns no further (max_m).

    The walk reads headings only; a sample's distance is measured where it may reach max_m (k chords past the foot
    point it is at most r0 + k max_segment_m away, r0 the foot point's distance: `path_search.first_beyond`), and
    those before the turn are measured once the turn is found. The path: `path_search.CompiledPath`'s table and
    record."""
    path_x, path_y, path_heading = table[PATH_X], table[PATH_Y], table[PATH_HEADING]
    shape = record[0]
    closed, max_segment_m = shape.closed, shape.max_segment
    n_seg = path_x.size - 1
    lap_turn = path_heading[-1] - path_heading[0]
    i0 = int(foot_index)
    i0w = i0 % n_seg if closed else min(i0, n_seg - 1)
    f0 = foot_index - i0
    h0 = path_heading[i0w] + f0 * (path_heading[i0w + 1] - path_heading[i0w])
    fx, fy = _point_at_index(path_x, path_y, foot_index, closed)
    # Samples before `near` are nearer than max_m (one sample's slack against rounding).
    near = foot_index + (max_m - math.hypot(fx - px, fy - py)) / max_segment_m - 1.0 if max_segment_m > 0.0 else 0.0
    last = i0 + n_seg if closed else n_seg
    for j in range(i0 + 1, last + 1):
        i = j % n_seg if closed else j
        heading = path_heading[i] + (lap_turn * (j // n_seg - i0 // n_seg) if closed else 0.0)
        if abs(heading - h0) > max_turn_rad:
            longest = 0.0
            for k in range(i0 + 1, j):
                ik = k % n_seg if closed else k
                longest = max(longest, np.hypot(path_x[ik] - px, path_y[ik] - py))
            return min(longest, max_m)
        if j >= near and np.hypot(path_x[i] - px, path_y[i] - py) >= max_m:
            return max_m
    return max_m


@dataclass(frozen=True, slots=True)
class Candidate:
    """One scored lookahead: the Fréchet distance (m), the fit (curvature rate 1/m^2, length m, status), the target
    and the clothoid's end point."""

    lookahead_m: float
    frechet_m: float
    curvature_rate_1pm2: float
    length_m: float
    target_xy: tuple[float, float]
    end_xy: tuple[float, float]
    status: int


class LookaheadEvaluator:
    """Python access to the compiled evaluation, for analyses (Figures 4b and 5b) and tests."""

    def __init__(self, path: ReferencePath, point_spacing_m: float = 0.5) -> None:
        self.path = path
        self.point_spacing_m = point_spacing_m
        self._buffers = np.empty((4, MAX_CURVE_POINTS))

    def evaluate(
        self, s_foot_m: float, x_m: float, y_m: float, heading_rad: float, curvature_1pm: float,
        lookahead_m: float, max_curvature_rate_1pm2: float,
    ) -> Candidate:  # fmt: skip
        path, compiled = self.path, self.path.compiled()
        fd, kdot, length, tx, ty, ex, ey, status = evaluate_candidate(
            compiled.table, compiled.record, s_foot_m / path.spacing_m, float(x_m), float(y_m), float(heading_rad),
            float(curvature_1pm), float(lookahead_m), float(max_curvature_rate_1pm2), self.point_spacing_m,
            self._buffers, np.inf,
        )  # fmt: skip
        return Candidate(lookahead_m, fd, kdot, length, (tx, ty), (ex, ey), status)


def candidate_lookaheads(min_m: float, max_m: float, step_m: float) -> np.ndarray:
    """The grid the adaptive search chooses from."""
    return min_m + step_m * np.arange(candidate_count(min_m, max_m, step_m))
