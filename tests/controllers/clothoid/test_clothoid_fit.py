"""The hyper-clothoid fit (paper, section 2, Eq. 3) against pyclothoids' exact G1 solver, closed forms and
properties: end point on the target when not saturated, saturated lengths locally optimal, finite output always."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pyclothoids import Clothoid

from controllers.clothoid.clothoid_fit import (
    FIT_OK,
    FIT_SATURATED,
    FIT_UNREACHABLE,
    SERIES_MAX_TURN_RAD,
    ClothoidFit,
    _cis_series,
    _integrate,
    clothoid_points,
    fit_hyper_clothoid,
    fit_kernel,
    sample_kernel,
)
from workbench.base.errors import WorkbenchInputError

WIDE_RATE = 10.0  # 1/m^2: never binding for the feasible targets below


def _feasible_cases(n: int, seed: int) -> list[tuple[float, float, float, float, float, float]]:
    """Random pose and curvature, target ahead: bearing within +-60 deg, 3-30 m away, |kappa0| <= 0.1."""
    rng = np.random.default_rng(seed)
    cases = []
    for _ in range(n):
        x0, y0 = rng.uniform(-500.0, 500.0, 2)
        theta0 = rng.uniform(-math.pi, math.pi)
        kappa0 = rng.uniform(-0.1, 0.1)
        d = rng.uniform(3.0, 30.0)
        phi = rng.uniform(-math.pi / 3, math.pi / 3)
        cases.append((x0, y0, theta0, kappa0, x0 + d * math.cos(theta0 + phi), y0 + d * math.sin(theta0 + phi)))
    return cases


def _end_by_pyclothoids(
    x0: float, y0: float, theta0: float, kappa0: float, kdot: float, length: float
) -> tuple[float, float]:
    """Independent evaluation of a clothoid's end point (Bertolazzi & Frego's Fresnel-integral code)."""
    c = Clothoid.StandardParams(x0, y0, theta0, kappa0, kdot, length)
    return c.XEnd, c.YEnd


def test_matches_pyclothoids_forward_on_feasible_targets() -> None:
    checked = 0
    for case in _feasible_cases(400, seed=1):
        ref = Clothoid.Forward(*case)
        if ref.length <= 0.0:  # pyclothoids finds no clothoid (kappa0 turns away from a wide target): skip
            continue
        kdot, length, ex, ey, status = fit_kernel(*case, WIDE_RATE)
        assert status == FIT_OK
        assert kdot == pytest.approx(ref.dk, rel=1e-6, abs=1e-12)
        assert length == pytest.approx(ref.length, rel=1e-6)
        assert math.hypot(ex - case[4], ey - case[5]) < 1e-8
        assert math.hypot(ex - ref.XEnd, ey - ref.YEnd) < 1e-8
        checked += 1
    assert checked > 300  # ~16% of these targets have no solution at all


def test_saturates_exactly_when_pyclothoids_needs_more_than_the_limit() -> None:
    kdot_max = 0.05
    saturated = 0
    for case in _feasible_cases(300, seed=2):
        ref = Clothoid.Forward(*case)
        if ref.length <= 0.0:
            continue
        kdot, _, _, _, status = fit_kernel(*case, kdot_max)
        if abs(ref.dk) > kdot_max:
            assert status == FIT_SATURATED
            assert kdot == math.copysign(kdot_max, ref.dk)
            saturated += 1
        else:
            assert status == FIT_OK
            assert kdot == pytest.approx(ref.dk, rel=1e-6, abs=1e-12)
    assert saturated > 10


def test_sampled_points_match_pyclothoids() -> None:
    n = 33
    out_x = np.full(n + 5, np.nan)
    out_y = np.full(n + 5, np.nan)
    for case in _feasible_cases(60, seed=3):
        kdot, length, ex, ey, status = fit_kernel(*case, WIDE_RATE)
        if status != FIT_OK:
            continue
        ref = Clothoid.StandardParams(*case[:4], kdot, length)
        sample_kernel(*case[:4], kdot, length, n, out_x, out_y)
        s = np.linspace(0.0, length, n)
        np.testing.assert_allclose(out_x[:n], [ref.X(v) for v in s], rtol=0, atol=1e-8)
        np.testing.assert_allclose(out_y[:n], [ref.Y(v) for v in s], rtol=0, atol=1e-8)
        assert (out_x[0], out_y[0]) == (case[0], case[1])
        assert math.hypot(out_x[n - 1] - ex, out_y[n - 1] - ey) < 1e-10
        assert np.isnan(out_x[n:]).all() and np.isnan(out_y[n:]).all()  # nothing written beyond n


@settings(max_examples=200, deadline=None)
@given(st.floats(-SERIES_MAX_TURN_RAD, SERIES_MAX_TURN_RAD))
def test_the_series_is_cos_and_sin_to_rounding(d: float) -> None:
    """The quadrature's small-turn cos and sin: within 2 ulps of 1 (cos) and of |d| (sin) of libm's."""
    c, sn = _cis_series(d)
    assert abs(c - math.cos(d)) <= 2.0 * math.ulp(1.0)
    assert abs(sn - math.sin(d)) <= 2.0 * math.ulp(abs(d)) + 1e-300


@settings(max_examples=60, deadline=None)
@given(
    kappa0=st.floats(-0.2, 0.2),
    kdot=st.floats(-0.05, 0.05),
    a=st.floats(0.0, 20.0),
    span=st.floats(0.01, 20.0),
)
def test_the_quadrature_is_scipys_adaptive_integral(kappa0: float, kdot: float, a: float, span: float) -> None:
    """int_a^b (cos, sin) theta and the Jacobian's (s^2 / 2)(-sin, cos) theta against scipy.integrate.quad at its
    tightest, across panels turning from a hair (the series) to radians (cos and sin): within 1e-12 of the span."""
    from scipy.integrate import IntegrationWarning, quad

    b = a + span
    theta = lambda s: s * (kappa0 + 0.5 * kdot * s)  # noqa: E731
    integrands = (
        lambda s: math.cos(theta(s)),
        lambda s: math.sin(theta(s)),
        lambda s: -0.5 * s * s * math.sin(theta(s)),
        lambda s: 0.5 * s * s * math.cos(theta(s)),
    )
    with warnings.catch_warnings():  # quad's note that it reached rounding, at this tolerance on smooth integrands
        warnings.simplefilter("ignore", IntegrationWarning)
        expected = [quad(f, a, b, epsabs=1e-14, epsrel=1e-14, limit=1000) for f in integrands]
    got = _integrate(kappa0, kdot, a, b, True)
    scale = (span, span, span * b * b, span * b * b)
    for value, (reference, error), size in zip(got, expected, scale, strict=True):
        assert error <= 1e-13 * size  # the reference is good to well within the tolerance
        assert abs(value - reference) <= 1e-12 * size


def test_clothoid_points_wrapper() -> None:
    x, y = clothoid_points(1.0, 2.0, 0.3, 0.05, -0.01, 20.0, 5)
    ref = Clothoid.StandardParams(1.0, 2.0, 0.3, 0.05, -0.01, 20.0)
    np.testing.assert_allclose(x, [ref.X(s) for s in np.linspace(0, 20, 5)], atol=1e-10)
    np.testing.assert_allclose(y, [ref.Y(s) for s in np.linspace(0, 20, 5)], atol=1e-10)
    x, y = clothoid_points(1.0, 2.0, 0.3, 0.05, -0.01, 20.0, 1)
    assert x.tolist() == [1.0] and y.tolist() == [2.0]
    x, y = clothoid_points(1.0, 2.0, 0.3, 0.05, -0.01, 0.0, 3)
    assert (x == 1.0).all() and (y == 2.0).all()
    for bad in ({"n": 0}, {"n": 2.5}, {"length": -1.0}, {"kdot": math.nan}):
        args = {"x0": 0.0, "y0": 0.0, "theta0": 0.0, "kappa0": 0.0, "kdot": 0.0, "length": 1.0, "n": 3} | bad
        with pytest.raises(WorkbenchInputError, match=f"^{next(iter(bad))} must"):
            clothoid_points(**args)


@pytest.mark.parametrize("theta0", [0.0, 0.7, -2.5])
@pytest.mark.parametrize("d", [0.5, 12.0, 60.0, 1e5])
def test_straight_ahead_needs_no_curvature_rate(theta0: float, d: float) -> None:
    x0, y0 = 3.0, -4.0
    fit = fit_hyper_clothoid(x0, y0, theta0, 0.0, x0 + d * math.cos(theta0), y0 + d * math.sin(theta0), 0.05)
    assert fit.status == FIT_OK
    assert abs(fit.curvature_rate_1pm2) <= 1e-12
    assert fit.length_m == pytest.approx(d, rel=1e-12)


@pytest.mark.parametrize("kappa0", [0.3, 0.05, -0.02, -0.2])
@pytest.mark.parametrize("angle", [0.2, 1.5, 3.0])
def test_target_on_the_start_circle_is_reached_by_the_arc(kappa0: float, angle: float) -> None:
    """A target on the circle of curvature kappa0 tangent to the start: kdot = 0 and L = R x angle."""
    x0, y0, theta0 = -7.0, 11.0, 0.4
    r = 1.0 / kappa0
    u, v = abs(r) * math.sin(angle), r * (1.0 - math.cos(angle))  # start frame
    x1 = x0 + u * math.cos(theta0) - v * math.sin(theta0)
    y1 = y0 + u * math.sin(theta0) + v * math.cos(theta0)
    fit = fit_hyper_clothoid(x0, y0, theta0, kappa0, x1, y1, 0.05)
    if abs(math.atan2(v, u)) > math.radians(100.0):  # half the arc angle is the bearing
        assert fit.status == FIT_UNREACHABLE
        return
    assert fit.status == FIT_OK
    assert abs(fit.curvature_rate_1pm2) <= 1e-10
    assert fit.length_m == pytest.approx(abs(r) * angle, rel=1e-10)


@pytest.mark.parametrize("kappa0", [0.0, 0.08])
def test_mirrored_target_flips_the_curvature_rate(kappa0: float) -> None:
    """Reflecting the target across the start heading line mirrors the clothoid (with kappa0 mirrored too)."""
    for x0, y0, theta0, _, x1, y1 in _feasible_cases(50, seed=4):
        c, s = math.cos(theta0), math.sin(theta0)
        u, v = c * (x1 - x0) + s * (y1 - y0), -s * (x1 - x0) + c * (y1 - y0)
        mx, my = x0 + u * c + v * s, y0 + u * s - v * c
        a = fit_hyper_clothoid(x0, y0, theta0, kappa0, x1, y1, 0.05)
        b = fit_hyper_clothoid(x0, y0, theta0, -kappa0, mx, my, 0.05)
        assert a.status == b.status
        assert b.curvature_rate_1pm2 == pytest.approx(-a.curvature_rate_1pm2, rel=1e-9, abs=1e-12)
        assert b.length_m == pytest.approx(a.length_m, rel=1e-9)


def test_targets_behind_beside_or_at_the_start_get_the_bounded_fallback() -> None:
    kdot_max = 0.05
    for bearing_deg in (110.0, 180.0, -135.0, -101.0):
        phi = math.radians(bearing_deg)
        kdot, length, ex, ey, status = fit_kernel(0.0, 0.0, 0.0, 0.02, 10 * math.cos(phi), 10 * math.sin(phi), kdot_max)
        assert status == FIT_UNREACHABLE
        assert kdot == math.copysign(kdot_max, phi)
        assert length == pytest.approx(10.0)
        ref = _end_by_pyclothoids(0.0, 0.0, 0.0, 0.02, kdot, length)
        assert math.hypot(ex - ref[0], ey - ref[1]) < 1e-8  # the fallback's end point is its own, exactly
    kdot, length, ex, ey, status = fit_kernel(5.0, 6.0, 1.0, 0.1, 5.0, 6.0, kdot_max)
    assert (kdot, length, ex, ey, status) == (0.0, 0.0, 5.0, 6.0, FIT_UNREACHABLE)
    # kappa0 turning hard away from a wide target: no clothoid reaches it (pyclothoids returns length 0 too).
    assert Clothoid.Forward(0.0, 0.0, 0.0, -0.1, 15.0, 18.0).length == 0.0
    kdot, length, *_, status = fit_kernel(0.0, 0.0, 0.0, -0.1, 15.0, 18.0, kdot_max)
    assert (status, kdot, length) == (FIT_UNREACHABLE, kdot_max, pytest.approx(math.hypot(15.0, 18.0)))


def test_non_finite_kernel_input_is_unreachable_not_a_crash() -> None:
    assert fit_kernel(0.0, 0.0, 0.0, 0.0, math.nan, 1.0, 0.05)[4] == FIT_UNREACHABLE
    assert fit_kernel(0.0, 0.0, 0.0, 0.0, 10.0, 1.0, math.inf)[:2] == (0.0, 0.0)


def test_wrapper_validates_and_reports() -> None:
    fit = fit_hyper_clothoid(0.0, 0.0, 0.0, 0.0, 10.0, 8.0, 0.01)
    assert isinstance(fit, ClothoidFit)
    assert fit.saturated and fit.reachable and fit.status == FIT_SATURATED
    assert fit.end_error_m(10.0, 8.0) == pytest.approx(math.hypot(fit.end_x_m - 10.0, fit.end_y_m - 8.0))
    assert fit.end_error_m(10.0, 8.0) > 0.1
    ok = fit_hyper_clothoid(0.0, 0.0, 0.0, 0.0, 10.0, 1.0, 0.05)
    assert ok.status == FIT_OK and not ok.saturated and ok.reachable and ok.end_error_m(10.0, 1.0) < 1e-9
    assert not fit_hyper_clothoid(0.0, 0.0, 0.0, 0.0, -10.0, 1.0, 0.05).reachable
    for name, value in (("x0", math.nan), ("theta0", math.inf), ("y1", "east"), ("kappa0", None)):
        args = {"x0": 0.0, "y0": 0.0, "theta0": 0.0, "kappa0": 0.0, "x1": 5.0, "y1": 0.0} | {name: value}
        with pytest.raises(WorkbenchInputError, match=f"^{name} must"):
            fit_hyper_clothoid(**args, max_curvature_rate_1pm2=0.05)
    for rate in (0.0, -0.05, math.nan, math.inf):
        with pytest.raises(WorkbenchInputError, match="max_curvature_rate_1pm2"):
            fit_hyper_clothoid(0.0, 0.0, 0.0, 0.0, 5.0, 0.0, rate)


_coordinate = st.floats(-1e4, 1e4)
_heading = st.floats(-10.0, 10.0)
_rate = st.floats(1e-4, 10.0)


@settings(max_examples=300, deadline=None)
@given(_coordinate, _coordinate, _heading, st.floats(-1.0, 1.0), st.floats(0.0, 1e3), st.floats(-math.pi, math.pi),
       _rate)  # fmt: skip
def test_fit_ok_means_on_target_and_saturated_means_locally_closest(
    x0: float, y0: float, theta0: float, kappa0: float, d: float, bearing: float, kdot_max: float
) -> None:
    x1, y1 = x0 + d * math.cos(theta0 + bearing), y0 + d * math.sin(theta0 + bearing)
    kdot, length, ex, ey, status = fit_kernel(x0, y0, theta0, kappa0, x1, y1, kdot_max)
    assert all(map(math.isfinite, (kdot, length, ex, ey)))
    if status == FIT_OK:
        assert abs(kdot) <= kdot_max
        assert math.hypot(ex - x1, ey - y1) <= 1e-6
    elif status == FIT_SATURATED:
        assert abs(kdot) == kdot_max
        assert length > 0.0

        def miss(s: float) -> float:
            fx, fy = clothoid_points(x0, y0, theta0, kappa0, kdot, s, 2)
            return math.hypot(fx[1] - x1, fy[1] - y1)

        assert miss(length) == pytest.approx(math.hypot(ex - x1, ey - y1), abs=1e-9)
        assert miss(length) <= min(miss(0.99 * length), miss(1.01 * length)) + 1e-9
    else:
        assert status == FIT_UNREACHABLE
        assert abs(kdot) <= kdot_max and length == pytest.approx(d, rel=1e-9, abs=1e-9)


_any_distance = st.one_of(st.just(0.0), st.floats(0.0, 1e-5), st.floats(0.0, 1e9))


@settings(max_examples=300, deadline=None)
@given(st.floats(-1e6, 1e6), st.floats(-1e6, 1e6), _heading, st.floats(-1.0, 1.0), _any_distance,
       st.floats(-math.pi, math.pi), _rate)  # fmt: skip
def test_always_finite_and_bounded(
    x0: float, y0: float, theta0: float, kappa0: float, d: float, bearing: float, kdot_max: float
) -> None:
    """Any finite input, including targets behind, beside, at the start and a million km away."""
    x1, y1 = x0 + d * math.cos(theta0 + bearing), y0 + d * math.sin(theta0 + bearing)
    kdot, length, ex, ey, status = fit_kernel(x0, y0, theta0, kappa0, x1, y1, kdot_max)
    assert status in (FIT_OK, FIT_SATURATED, FIT_UNREACHABLE)
    assert all(map(math.isfinite, (kdot, length, ex, ey)))
    assert abs(kdot) <= kdot_max and length >= 0.0
    dist = math.hypot(x1 - x0, y1 - y0)
    assert math.hypot(ex - x0, ey - y0) <= length * (1 + 1e-9) + 1e-9  # a curve is no shorter than its chord
    if status == FIT_OK:
        assert math.hypot(ex - x1, ey - y1) <= max(1e-6, 1e-10 * dist)


_finite_float = st.floats(allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(_finite_float, _finite_float, _finite_float, _finite_float, _finite_float, _finite_float,
       st.floats(min_value=0.0, exclude_min=True, allow_infinity=False))  # fmt: skip
def test_any_finite_floats_give_finite_output(
    x0: float, y0: float, theta0: float, kappa0: float, x1: float, y1: float, kdot_max: float
) -> None:
    kdot, length, ex, ey, status = fit_kernel(x0, y0, theta0, kappa0, x1, y1, kdot_max)
    assert status in (FIT_OK, FIT_SATURATED, FIT_UNREACHABLE)
    assert all(map(math.isfinite, (kdot, length, ex, ey)))
    assert abs(kdot) <= kdot_max and length >= 0.0
