"""Discrete Fréchet distance between two polylines: the dissimilarity score of the adaptive lookahead (paper,
section 3, Eq. 4 and Appendix A; Eiter & Mannila 1994).

The Fréchet distance of Eq. 4 is the shortest leash that lets a walker on P and one on Q go from start to end
without stepping back. Its discrete form, the one Appendix A computes, restricts the walkers to the vertices: a
coupling is a sequence of index pairs from (0, 0) to (n-1, m-1), each step advancing i, j or both by one, and

    d_F(P, Q) = min over couplings of max_k |P_{i_k} - Q_{j_k}|      (Euclidean norm),

computed by Appendix A's matrix recursion, row by row from the top-left corner (absent neighbours count as +inf):

    c(0, 0) = |P_0 - Q_0|,   c(i, j) = max(|P_i - Q_j|, min(c(i-1, j), c(i, j-1), c(i-1, j-1))),   d_F = c(n-1, m-1).

It depends on the sampling: it is >= the continuous distance of the polylines and exceeds it by at most the longest
edge (Eiter & Mannila), so it converges as the sampling is refined. The controller samples clothoid and path at
the same number of points, where the lock-step max_i |P_i - Q_i| bounds it from above.

O(n m) time at worst, O(min(n, m)) memory (one rolling row, no recursion); banded by one coupling's bound
(`_coupling_dp`), curves that run alike, as the controller's do, cost about n + m cells. The hot loop compares
squared distances (sqrt is monotone, so the same cells win) and takes one sqrt at the end, recomputing with hypot
where squares would underflow or overflow (distances below 1e-140 or above 1e140 m).

`discrete_frechet` is the checked public entry point; `frechet_kernel` and `frechet_below` (cut short above a
limit) are the compiled kernels for callers inside numba code (the lookahead search), which
must pass finite float64 arrays.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from workbench.base.errors import WorkbenchInputError

# Squared distances within [_SQ_LOW, _SQ_HIGH] are normal floats whose square root is as accurate as hypot's;
# outside it (distances < 1e-140 or > 1e140) squaring may have underflowed or overflowed somewhere.
_SQ_LOW = 1e-280
_SQ_HIGH = 1e280


@njit(cache=True)
def _cell(ax: np.ndarray, ay: np.ndarray, bx: np.ndarray, by: np.ndarray, i: int, j: int, squared: bool) -> float:
    """|A_i - B_j|, squared if `squared` (every cell's one formula, so that equal cells compare equal)."""
    dx, dy = ax[i] - bx[j], ay[i] - by[j]
    return dx * dx + dy * dy if squared else math.hypot(dx, dy)


@njit(cache=True)
def _coupling_dp(
    ax: np.ndarray, ay: np.ndarray, bx: np.ndarray, by: np.ndarray, squared: bool, limit: float
) -> float:  # pragma: no cover - compiled
    """The DP's bottom-right cell with the rolling row over B (the caller passes the shorter curve as B, so
    m <= n).

    Cells hold squared distances if `squared`, else distances. Returns -1.0 as soon as the smallest cell of a
    row exceeds `limit` (compared as a distance: sqrt of the cell if squared): every coupling crosses every row
    and the cells never decrease along it, so the final value exceeds `limit` too.

    Banded: the distance is at most `bound`, the largest cell of one coupling (j = floor(i (m-1) / (n-1)), which
    advances j by 0 or 1 a row), so a cell farther apart than `bound` is on no optimal coupling and is left out
    (+inf), and so is every cell no finite cell reaches. Each row then spans only the cells reachable from the
    last row's, a few about the diagonal for curves that run alike (~n cells instead of n m). A cell that is not
    left out gets the full DP's very value (the min over its neighbours only ever skips values above `bound`,
    which the optimum does not take), so the result and the row at which the early exit stops are the full
    DP's, bit for bit.
    """
    n, m = ax.size, bx.size
    bound = 0.0
    for i in range(n):
        d = _cell(ax, ay, bx, by, i, (i * (m - 1)) // (n - 1) if n > 1 else 0, squared)
        if d > bound:
            bound = d
    row = np.empty(m)
    # Row 0: Q's walker advances while P's waits at P_0, up to the first cell beyond the bound.
    acc = 0.0
    hi = -1
    for j in range(m):
        d = _cell(ax, ay, bx, by, 0, j, squared)
        if d > bound:
            break
        if d > acc:
            acc = d
        row[j] = acc
        hi = j
    lo = 0
    row_min = row[0]  # row 0 is non-decreasing
    if (math.sqrt(row_min) if squared else row_min) > limit:
        return -1.0
    for i in range(1, n):
        # lo..hi: the last row's span (its first and last finite cell); a cell before lo is reached by nothing.
        left = diag = np.inf
        new_lo, new_hi = -1, -1
        row_min = np.inf
        for j in range(lo, m):
            up = row[j] if j <= hi else np.inf
            best = diag if diag < up else up
            if left < best:
                best = left
            if best == np.inf and j > hi:
                break  # nothing reaches this cell, or any after it
            v = np.inf
            if best < np.inf:
                d = _cell(ax, ay, bx, by, i, j, squared)
                if d <= bound:
                    v = d if d > best else best
                    if new_lo < 0:
                        new_lo = j
                    new_hi = j
                    if v < row_min:
                        row_min = v
            row[j] = v
            diag = up
            left = v
        lo, hi = new_lo, new_hi
        if (math.sqrt(row_min) if squared else row_min) > limit:
            return -1.0
    return row[m - 1]


@njit(cache=True)
def _frechet_limited(
    px: np.ndarray, py: np.ndarray, qx: np.ndarray, qy: np.ndarray, limit: float
) -> float:  # pragma: no cover - compiled
    """The discrete Fréchet distance, or -1.0 once it is known to exceed `limit` (pass inf for no early exit)."""
    if px.size == 0 or qx.size == 0:
        return np.nan
    swap = qx.size > px.size
    # Squared arithmetic is safe for the early exit only while limit**2 is a normal float: otherwise work in
    # distances throughout.
    if _SQ_LOW <= limit * limit <= _SQ_HIGH or limit == np.inf:
        r2 = _coupling_dp(qx, qy, px, py, True, limit) if swap else _coupling_dp(px, py, qx, qy, True, limit)
        if r2 < 0.0:
            return -1.0
        if _SQ_LOW <= r2 <= _SQ_HIGH:
            return math.sqrt(r2)
    return _coupling_dp(qx, qy, px, py, False, limit) if swap else _coupling_dp(px, py, qx, qy, False, limit)


@njit(cache=True)
def frechet_kernel(px: np.ndarray, py: np.ndarray, qx: np.ndarray, qy: np.ndarray) -> float:  # pragma: no cover
    """Discrete Fréchet distance between P = (px, py) and Q = (qx, qy): finite float64 1-D arrays of lengths
    n, m >= 1 (NaN if either is empty; no other checks). At most O(n m) time (banded: see `_coupling_dp`), one row
    of min(n, m) floats.
    """
    return _frechet_limited(px, py, qx, qy, np.inf)


@njit(cache=True)
def frechet_below(
    px: np.ndarray, py: np.ndarray, qx: np.ndarray, qy: np.ndarray, limit: float
) -> float:  # pragma: no cover - compiled
    """frechet_kernel(px, py, qx, qy) exactly, or inf as soon as it is known to exceed `limit` (inf: never): the
    search of a least distance or of a threshold skips the rest of a curve that cannot win. The early exit is
    taken only for limits in [1e-140, 1e140] m, where it runs the full computation's very arithmetic."""
    if not _SQ_LOW <= limit * limit <= _SQ_HIGH:
        limit = np.inf
    d = _frechet_limited(px, py, qx, qy, limit)
    return np.inf if d < 0.0 else d


def _as_curve(name: str, curve: object) -> np.ndarray:
    """`curve` as a float (n, 2) array with n >= 1 and finite entries, else WorkbenchInputError naming `name`."""
    try:
        arr = np.asarray(curve, dtype=float)
    except (TypeError, ValueError) as exc:
        raise WorkbenchInputError(f"curve {name} must be an array of (x, y) points of shape (n, 2); {exc}") from None
    if arr.size == 0:
        raise WorkbenchInputError(f"curve {name} is empty (shape {arr.shape}); it needs at least 1 (x, y) point")
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise WorkbenchInputError(f"curve {name} must have shape (n, 2) (one (x, y) row per point); got {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        point, coord = (int(k) for k in np.argwhere(bad)[0])
        raise WorkbenchInputError(
            f"curve {name} must be finite numbers; point {point} has {'xy'[coord]} = {float(arr[point, coord])!r}"
        )
    return arr


def discrete_frechet(P: object, Q: object) -> float:
    """Discrete Fréchet distance (m) between polylines P, shape (n, 2), and Q, shape (m, 2), n, m >= 1.

    The coupling distance over the given vertices (see the module docstring): symmetric, zero for identical
    curves, between max(|P_0 - Q_0|, |P_n-1 - Q_m-1|) and max_ij |P_i - Q_j|, and an upper bound of the
    continuous Fréchet distance. Raises WorkbenchInputError for a curve of the wrong shape, without points or
    with a non-finite entry.

    Parameters
    ----------
    P : array_like of float, shape (n, 2), m
        The first polyline's vertices (x, y), n >= 1, finite.
    Q : array_like of float, shape (m, 2), m
        The second polyline's vertices (x, y), m >= 1, finite.

    Returns
    -------
    float, m
        The discrete Fréchet distance, >= 0.

    Raises
    ------
    WorkbenchInputError
        A curve that is not of shape (k, 2), has no points, or has a NaN or infinite coordinate.

    Examples
    --------
    Two parallel lines 1 m apart, and a line against a zigzag about it: only the vertices count, so leaving out
    the middle vertex of a straight line changes the distance.

    >>> from controllers.clothoid import discrete_frechet
    >>> discrete_frechet([[0, 0], [1, 0], [2, 0]], [[0, 1], [1, 1], [2, 1]])
    1.0
    >>> discrete_frechet([[0, 0], [1, 0], [2, 0]], [[0, 0.5], [1, -0.5], [2, 0]])
    0.5
    >>> discrete_frechet([[0, 0], [1, 0], [2, 0]], [[0, 0], [2, 0]])
    1.0
    """
    p = _as_curve("P", P)
    q = _as_curve("Q", Q)
    return float(
        frechet_kernel(
            np.ascontiguousarray(p[:, 0]),
            np.ascontiguousarray(p[:, 1]),
            np.ascontiguousarray(q[:, 0]),
            np.ascontiguousarray(q[:, 1]),
        )
    )
