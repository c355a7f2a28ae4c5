"""Discrete Fréchet distance: agreement with similaritymeasures, metric properties and bounds (hypothesis), hand
examples, extreme scales, the early-exit variant, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
import similaritymeasures
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from controllers.clothoid.frechet import discrete_frechet, frechet_below, frechet_kernel
from workbench.base.errors import WorkbenchInputError

# The kernel returns sqrt of one pairwise squared distance; references computed another way (hypot, scipy's
# minkowski) differ from it by a few ulps at most.
REL = 1e-12


def random_walk(seed: int, n: int, step: float = 1.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.cumsum(rng.normal(scale=step, size=(n, 2)), axis=0) + rng.uniform(-5.0, 5.0, size=2)


def columns(curve: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.ascontiguousarray(curve[:, 0]), np.ascontiguousarray(curve[:, 1])


def max_pairwise(P: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """|P_i - Q_j| for all i, j, shape (n, m)."""
    return np.hypot(P[:, None, 0] - Q[None, :, 0], P[:, None, 1] - Q[None, :, 1])


@st.composite
def curves(draw: st.DrawFn, n: int | None = None) -> np.ndarray:
    """A curve of 1..60 points: a seeded random walk, or arbitrary points (with ties, repeats and tiny values)."""
    length = draw(st.integers(1, 60)) if n is None else n
    if draw(st.booleans()):
        return random_walk(draw(st.integers(0, 2**32 - 1)), length, step=draw(st.sampled_from([0.01, 1.0, 10.0])))
    coords = st.floats(-100.0, 100.0, allow_nan=False, allow_infinity=False)
    return draw(arrays(np.float64, (length, 2), elements=coords))


# ---------------------------------------------------------------------------------------------------------------
# Against an independent implementation (similaritymeasures: full (n, m) matrix, scipy distances).


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("n", [1, 2, 3, 10, 31, 60])
@pytest.mark.parametrize("m", [1, 2, 7, 30, 60])
def test_matches_similaritymeasures_on_random_walks(seed: int, n: int, m: int) -> None:
    P, Q = random_walk(seed, n), random_walk(1000 + seed, m)
    expected = similaritymeasures.frechet_dist(P, Q)
    assert discrete_frechet(P, Q) == pytest.approx(expected, rel=REL, abs=0.0)


@settings(max_examples=150, deadline=None)
@given(curves(), curves())
def test_matches_similaritymeasures_hypothesis(P: np.ndarray, Q: np.ndarray) -> None:
    expected = similaritymeasures.frechet_dist(P, Q)
    # scipy squares the differences, which underflow to 0 below ~1e-154 m (ours falls back to hypot there:
    # see the extreme-scale tests), hence the absolute floor.
    assert discrete_frechet(P, Q) == pytest.approx(expected, rel=REL, abs=1e-150)


# ---------------------------------------------------------------------------------------------------------------
# Properties.


@settings(max_examples=100, deadline=None)
@given(curves(), curves())
def test_symmetric_and_bounded(P: np.ndarray, Q: np.ndarray) -> None:
    d = discrete_frechet(P, Q)
    # Exactly symmetric: the transposed DP sees the same cells (dx -> -dx is exact) and min is commutative.
    assert discrete_frechet(Q, P) == d
    # Every coupling holds (0, 0) and (n-1, m-1): at least the end-point distances.
    ends = max(math.hypot(*(P[0] - Q[0])), math.hypot(*(P[-1] - Q[-1])))
    assert d >= ends * (1.0 - REL)
    # ... and it pairs vertices, so at most the largest vertex-to-vertex distance.
    assert d <= max_pairwise(P, Q).max() * (1.0 + REL)


@settings(max_examples=100, deadline=None)
@given(st.integers(1, 60).flatmap(lambda n: st.tuples(curves(n), curves(n))))
def test_equal_sampling_is_bounded_by_lock_step_coupling(PQ: tuple[np.ndarray, np.ndarray]) -> None:
    P, Q = PQ
    lock_step = np.hypot(P[:, 0] - Q[:, 0], P[:, 1] - Q[:, 1]).max()
    assert discrete_frechet(P, Q) <= lock_step * (1.0 + REL)


@settings(max_examples=50, deadline=None)
@given(curves())
def test_zero_for_identical_curves(P: np.ndarray) -> None:
    assert discrete_frechet(P, P.copy()) == 0.0


@settings(max_examples=100, deadline=None)
@given(
    curves(),
    curves(),
    st.floats(-math.pi, math.pi),
    st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)),
    st.booleans(),
)
def test_invariant_under_common_rigid_motion(
    P: np.ndarray, Q: np.ndarray, angle: float, shift: tuple[float, float], mirror: bool
) -> None:
    c, s = math.cos(angle), math.sin(angle)
    R = np.array([[c, -s], [s, c]]) @ (np.diag([1.0, -1.0]) if mirror else np.eye(2))

    def move(curve: np.ndarray) -> np.ndarray:
        return curve @ R.T + np.asarray(shift)

    # Moving a point by e changes the distance by at most e (1-Lipschitz); the rounding of the motion is
    # ~1e-13 m for coordinates up to ~1e3 m.
    assert discrete_frechet(move(P), move(Q)) == pytest.approx(discrete_frechet(P, Q), rel=REL, abs=1e-9)


@settings(max_examples=100, deadline=None)
@given(curves(), curves(), curves())
def test_triangle_inequality(P: np.ndarray, Q: np.ndarray, R: np.ndarray) -> None:
    # Composing a P-Q coupling with a Q-R coupling gives a P-R coupling of no greater leash.
    assert discrete_frechet(P, R) <= (discrete_frechet(P, Q) + discrete_frechet(Q, R)) * (1.0 + REL) + 1e-300


def test_triangle_inequality_fixed_seeds() -> None:
    for seed in range(30):
        rng = np.random.default_rng(seed)
        P, Q, R = (random_walk(10 * seed + k, int(rng.integers(1, 61))) for k in range(3))
        assert discrete_frechet(P, R) <= (discrete_frechet(P, Q) + discrete_frechet(Q, R)) * (1.0 + REL)


# ---------------------------------------------------------------------------------------------------------------
# Hand examples.


def test_parallel_segments_equally_sampled() -> None:
    x = np.linspace(0.0, 10.0, 21)
    P = np.column_stack([x, np.zeros_like(x)])
    Q = np.column_stack([x, np.full_like(x, 0.5)])
    assert discrete_frechet(P, Q) == pytest.approx(0.5, rel=REL)
    # Shifted along the line by half a spacing the vertices no longer face each other: the discrete distance
    # (0.25 m offset at best) exceeds the continuous one (0.5 m), which it upper-bounds.
    Q_shifted = np.column_stack([x[:-1] + 0.25, np.full(x.size - 1, 0.5)])
    assert discrete_frechet(P, Q_shifted) == pytest.approx(math.hypot(0.5, 0.25), rel=REL)


def test_finer_sampling_of_the_same_segment_is_coupled_to_the_nearest_vertex() -> None:
    # P every 0.5 m, Q every 0.25 m on a parallel line 0.5 m away: Q's odd vertices sit 0.25 m from P's.
    P = np.column_stack([np.linspace(0.0, 10.0, 21), np.zeros(21)])
    Q = np.column_stack([np.linspace(0.0, 10.0, 41), np.full(41, 0.5)])
    assert discrete_frechet(P, Q) == pytest.approx(math.hypot(0.5, 0.25), rel=REL)


def test_single_point_against_a_curve_is_the_farthest_vertex() -> None:
    point = np.array([[1.0, 2.0]])
    curve = np.array([[0.0, 0.0], [3.0, 1.0], [1.0, 7.0], [-2.0, 2.0]])
    farthest = max(math.hypot(*(v - point[0])) for v in curve)  # (1, 7): 5
    assert farthest == 5.0
    assert discrete_frechet(point, curve) == pytest.approx(5.0, rel=REL)
    assert discrete_frechet(curve, point) == pytest.approx(5.0, rel=REL)
    assert discrete_frechet(point, [[4.0, 6.0]]) == pytest.approx(5.0, rel=REL)


def test_the_order_of_the_vertices_matters() -> None:
    # Same vertex sets, Q traversed backwards: the walkers start 10 m apart.
    P = np.array([[0.0, 0.0], [5.0, 0.0], [10.0, 0.0]])
    assert discrete_frechet(P, P[::-1]) == pytest.approx(10.0, rel=REL)


def test_accepts_lists_and_returns_a_python_float() -> None:
    d = discrete_frechet([[0, 0], [1, 0]], [(0, 1), (1, 1)])
    assert type(d) is float
    assert d == 1.0


# ---------------------------------------------------------------------------------------------------------------
# Extreme scales: squared distances would overflow / underflow; the kernel then recomputes with hypot.


@pytest.mark.parametrize("exponent", [-600, -480, -300, 300, 480, 600])
def test_scale_equivariant_far_beyond_the_range_of_squares(exponent: int) -> None:
    scale = 2.0**exponent  # a power of two: scaling the coordinates is exact
    for seed in range(5):
        P, Q = random_walk(seed, 25), random_walk(seed + 50, 17)
        d = discrete_frechet(P, Q)
        assert discrete_frechet(P * scale, Q * scale) == pytest.approx(d * scale, rel=REL, abs=0.0)


def test_subnormal_distances_are_not_lost() -> None:
    tiny = 5e-324  # the smallest subnormal: its square underflows to 0
    assert discrete_frechet([[0.0, 0.0]], [[0.0, tiny]]) == tiny
    assert discrete_frechet([[0.0, 0.0], [1.0, 0.0]], [[0.0, 3 * tiny], [1.0, 0.0]]) == 3 * tiny


def test_huge_coordinates() -> None:
    big = 1e300
    assert discrete_frechet([[-big, 0.0]], [[big, 0.0]]) == 2 * big
    assert discrete_frechet([[0.0, 0.0], [big, big]], [[0.0, 0.0], [big, -big]]) == pytest.approx(2 * big, rel=REL)


# ---------------------------------------------------------------------------------------------------------------
# The compiled kernels directly.


def within(px: np.ndarray, py: np.ndarray, qx: np.ndarray, qy: np.ndarray, threshold: float) -> bool:
    """Whether frechet_kernel(px, py, qx, qy) <= threshold by `frechet_below`'s early exit (False for a NaN or
    negative threshold or an empty curve): a threshold test built on it must agree with the full computation."""
    return threshold >= 0.0 and frechet_below(px, py, qx, qy, threshold) <= threshold


def test_kernel_contract_for_empty_curves() -> None:
    empty, one = np.empty(0), np.ones(1)
    assert math.isnan(frechet_kernel(empty, empty, one, one))
    assert math.isnan(frechet_kernel(one, one, empty, empty))
    assert not within(empty, empty, one, one, 1.0)


# ---------------------------------------------------------------------------------------------------------------
# The banded DP (cells farther apart than one coupling's largest are left out) against every cell's recursion.


def every_cell(P: np.ndarray, Q: np.ndarray) -> float:
    """Appendix A's recursion over all n x m cells on squared distances, one sqrt at the end: the unbanded DP (NaN
    where its square leaves the normal floats, and the kernel measures with hypot instead)."""
    n, m = len(P), len(Q)
    c = np.empty((n, m))
    for i in range(n):
        for j in range(m):
            dx, dy = P[i, 0] - Q[j, 0], P[i, 1] - Q[j, 1]
            d = dx * dx + dy * dy
            if i == 0 and j == 0:
                c[i, j] = d
            elif i == 0:
                c[i, j] = max(d, c[i, j - 1])
            elif j == 0:
                c[i, j] = max(d, c[i - 1, j])
            else:
                c[i, j] = max(d, min(c[i - 1, j], c[i, j - 1], c[i - 1, j - 1]))
    return math.sqrt(c[-1, -1]) if 1e-280 <= c[-1, -1] <= 1e280 else math.nan


@st.composite
def alike_curves(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    """The controller's case, where the band is narrowest: a smooth curve and a noisy copy of it resampled at
    another count (3..60 points each), the noise 1 mm to 1 m on a 0.5 m spacing."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n, m = draw(st.integers(3, 60)), draw(st.integers(3, 60))
    length, bend = 0.5 * max(n, m), rng.uniform(-0.2, 0.2)
    s = np.linspace(0.0, length, n)
    P = np.column_stack([np.sin(bend * s) / bend if bend else s, (1.0 - np.cos(bend * s)) / bend if bend else 0 * s])
    t = np.linspace(0.0, length, m)
    Q = np.column_stack([np.interp(t, s, P[:, 0]), np.interp(t, s, P[:, 1])])
    return P, Q + rng.normal(scale=draw(st.sampled_from([0.001, 0.02, 0.3, 1.0])), size=Q.shape)


@settings(max_examples=150, deadline=None)
@given(st.one_of(alike_curves(), st.tuples(curves(), curves())))
def test_the_banded_dp_is_every_cells_recursion_bit_for_bit(PQ: tuple[np.ndarray, np.ndarray]) -> None:
    """Leaving out the cells beyond one coupling's bound changes no bit of the distance, nor where the early exit
    stops: cut short exactly when the unbanded DP would be, for limits at, around and below the distance."""
    P, Q = PQ
    d = every_cell(P, Q)
    if math.isnan(d):
        return  # beyond the squares' range: measured with hypot (tested above)
    px, py = columns(P)
    qx, qy = columns(Q)
    assert frechet_kernel(px, py, qx, qy) == d
    assert frechet_kernel(qx, qy, px, py) == d
    for limit in (d, np.nextafter(d, 0.0), 0.5 * d, 0.9 * d, 2.0 * d):
        below = frechet_below(px, py, qx, qy, float(limit))
        assert below == d or (below == math.inf and d > limit)


def check_early_exit_agrees(P: np.ndarray, Q: np.ndarray, threshold: float) -> None:
    px, py = columns(P)
    qx, qy = columns(Q)
    d = frechet_kernel(px, py, qx, qy)
    assert within(px, py, qx, qy, threshold) == (d <= threshold)
    # the distance itself, bit for bit, unless cut short where it exceeds the limit (never for a limit outside
    # [1e-140, 1e140] m, where the cut would need other arithmetic)
    below = frechet_below(px, py, qx, qy, threshold)
    assert below == d or (below == math.inf and d > threshold and 1e-140 <= threshold <= 1e140)


@settings(max_examples=100, deadline=None)
@given(curves(), curves(), st.floats(0.0, 300.0))
def test_early_exit_agrees_with_full_computation(P: np.ndarray, Q: np.ndarray, threshold: float) -> None:
    check_early_exit_agrees(P, Q, threshold)
    px, py = columns(P)
    qx, qy = columns(Q)
    d = frechet_kernel(px, py, qx, qy)
    # At and around the distance itself, where an inconsistent arithmetic would show.
    for t in (d, np.nextafter(d, 0.0), np.nextafter(d, np.inf), 0.5 * d, 0.999 * d, 1.001 * d, 2.0 * d):
        check_early_exit_agrees(P, Q, float(t))
    assert within(px, py, qx, qy, d)


def test_early_exit_agrees_on_fixed_seeds_and_scales() -> None:
    for seed in range(20):
        P, Q = random_walk(seed, 5 + 3 * seed), random_walk(seed + 100, 60 - 2 * seed)
        for scale in (2.0**-500, 1.0, 2.0**500):
            d = discrete_frechet(P * scale, Q * scale)
            for t in (0.0, 0.3 * d, d, np.nextafter(d, 0.0), 3.0 * d, np.inf, 1e-200, 1e200):
                check_early_exit_agrees(P * scale, Q * scale, float(t))


def test_early_exit_rejects_negative_and_nan_thresholds() -> None:
    px, py = columns(random_walk(1, 10))
    assert not within(px, py, px, py, -1.0)
    assert not within(px, py, px, py, math.nan)
    assert within(px, py, px, py, 0.0)  # identical curves: distance 0 <= 0


# ---------------------------------------------------------------------------------------------------------------
# Bad input.


@pytest.mark.parametrize(
    ("P", "Q", "match"),
    [
        (np.zeros((3, 3)), np.zeros((3, 2)), r"curve P must have shape \(n, 2\).*got \(3, 3\)"),
        (np.zeros((3, 2)), np.zeros((2, 3)), r"curve Q must have shape \(n, 2\).*got \(2, 3\)"),
        (np.zeros(2), np.zeros((3, 2)), r"curve P must have shape \(n, 2\).*got \(2,\)"),
        (np.zeros((3, 2)), np.zeros((2, 2, 2)), r"curve Q must have shape \(n, 2\).*got \(2, 2, 2\)"),
        (np.zeros((0, 2)), np.zeros((3, 2)), r"curve P is empty \(shape \(0, 2\)\)"),
        (np.zeros((3, 2)), [], r"curve Q is empty"),
        ([[0.0, 1.0], [2.0, math.nan]], np.zeros((3, 2)), r"curve P must be finite.*point 1 has y = nan"),
        (np.zeros((3, 2)), [[0.0, 1.0], [math.inf, 2.0]], r"curve Q must be finite.*point 1 has x = inf"),
        ([[0.0, 1.0], [2.0]], np.zeros((3, 2)), r"curve P must be an array of \(x, y\) points"),
        (np.zeros((3, 2)), [["a", "b"]], r"curve Q must be an array of \(x, y\) points"),
    ],
)
def test_bad_input_names_curve_and_problem(P: object, Q: object, match: str) -> None:
    with pytest.raises(WorkbenchInputError, match=match):
        discrete_frechet(P, Q)
