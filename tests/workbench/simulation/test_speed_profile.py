"""Smart velocity waypoint generation (paper section 6): geometry and speeds against analytic references."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.base.errors import WorkbenchInputError
from workbench.simulation.speed_profile import (
    G_MPS2,
    SpeedLimits,
    SpeedProfile,
    local_quadratic_geometry,
    plan_speed_profile,
)

A_LAT = 0.3 * G_MPS2


def circle(radius_m: float, direction: int, closed: bool, seed: int = 7) -> tuple[np.ndarray, ...]:
    """Waypoints on a circle about the origin with random spacing of 0.4-0.8 m; returns (x, y, angle)."""
    rng = np.random.default_rng(seed)
    angle = np.cumsum(rng.uniform(0.4, 0.8, size=20_000) / radius_m)
    angle = angle[angle < 2 * np.pi - 0.4 / radius_m] if closed else angle[:80]
    angle = direction * angle
    return radius_m * np.cos(angle), radius_m * np.sin(angle), angle


def wrap(angle: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * angle))


def accel_along(profile: SpeedProfile) -> np.ndarray:
    """(v_{i+1}^2 - v_i^2) / (2 ds) between consecutive waypoints, across the seam for loops (m/s^2)."""
    v2 = profile.speed_mps**2
    s = profile.s_m
    if profile.closed:
        v2, s = np.append(v2, v2[0]), np.append(s, profile.length_m)
    return np.diff(v2) / (2 * np.diff(s))


def assert_within_limits(profile: SpeedProfile) -> None:
    limits, v = profile.limits, profile.speed_mps
    assert np.all(v**2 * np.abs(profile.curvature_1pm) <= limits.max_lateral_accel_mps2 * (1 + 1e-9))
    assert np.all(v <= limits.max_speed_mps * (1 + 1e-12))
    assert np.all(v >= limits.min_speed_mps * (1 - 1e-12))
    accel = accel_along(profile)
    assert accel.max() <= limits.max_accel_mps2 + 1e-8
    assert accel.min() >= -limits.max_decel_mps2 - 1e-8


# --- local_quadratic_geometry -------------------------------------------------------------------------------


@pytest.mark.parametrize("closed", [True, False])
@pytest.mark.parametrize("direction", [1, -1])
@pytest.mark.parametrize("radius_m", [20.0, 25.0, 100.0])
def test_circle_curvature_heading_and_distance(radius_m: float, direction: int, closed: bool) -> None:
    x, y, angle = circle(radius_m, direction, closed)
    s, heading, curvature = local_quadratic_geometry(x, y, closed)
    # Curvature: 1/R with the sign of the turn (CCW = left = positive), within 1 % at every waypoint.
    assert np.all(np.sign(curvature) == direction)
    np.testing.assert_allclose(np.abs(curvature), 1 / radius_m, rtol=0.01)
    assert np.all(np.abs(curvature) >= 1 / radius_m)  # the fit's bias is conservative: never too straight
    # Heading: the tangent of the circle, angle + 90 degrees towards the direction of travel.
    assert np.abs(wrap(heading - (angle + direction * np.pi / 2))).max() < 1e-2
    assert np.all((heading > -np.pi) & (heading <= np.pi))
    # Distance: the cumulative chord length.
    np.testing.assert_allclose(s, np.concatenate(([0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y))))))


def test_curvature_error_is_second_order_in_spacing() -> None:
    # A quadratic fit of a circle is biased by O((kappa * window)^2): halving the spacing quarters the error.
    radius = 20.0
    errors = []
    for spacing in (2.0, 1.0, 0.5):
        angle = np.arange(0.0, 2 * np.pi - 1e-9, spacing / radius)
        _, _, curvature = local_quadratic_geometry(radius * np.cos(angle), radius * np.sin(angle), closed=True)
        errors.append(np.abs(curvature * radius - 1).max())
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.1)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.1)


def test_straight_line_has_zero_curvature_and_constant_heading() -> None:
    rng = np.random.default_rng(3)
    direction = 2.5  # rad, pointing into the second quadrant
    t = np.cumsum(rng.uniform(0.3, 3.0, size=50))
    x, y = 100.0 + t * math.cos(direction), -40.0 + t * math.sin(direction)
    s, heading, curvature = local_quadratic_geometry(x, y, closed=False)
    assert np.abs(curvature).max() < 1e-9
    assert np.abs(wrap(heading - direction)).max() < 1e-9
    np.testing.assert_allclose(s, t - t[0], atol=1e-9)


def test_closed_loop_window_wraps_across_the_seam() -> None:
    # The same loop with its starting waypoint moved gives the same geometry, rolled: no seam artefact.
    x, y, _ = circle(25.0, 1, closed=True)
    _, heading, curvature = local_quadratic_geometry(x, y, closed=True)
    _, heading_r, curvature_r = local_quadratic_geometry(np.roll(x, 17), np.roll(y, 17), closed=True)
    np.testing.assert_allclose(np.roll(curvature, 17), curvature_r, rtol=1e-9)
    np.testing.assert_allclose(wrap(np.roll(heading, 17) - heading_r), 0.0, atol=1e-12)


# --- plan_speed_profile -------------------------------------------------------------------------------------


def test_circle_speed_is_the_lateral_limit() -> None:
    x, y, _ = circle(25.0, 1, closed=True)
    profile = plan_speed_profile(x, y, SpeedLimits(max_speed_mps=30.0), closed=True)
    np.testing.assert_allclose(profile.speed_mps, math.sqrt(A_LAT * 25.0), rtol=0.01)
    assert_within_limits(profile)


def test_straight_line_runs_at_max_speed() -> None:
    x = np.linspace(0.0, 500.0, 251)
    profile = plan_speed_profile(x, 0.5 * x, SpeedLimits(max_speed_mps=22.0))
    np.testing.assert_array_equal(profile.speed_mps, 22.0)


def test_straight_then_tight_arc_brakes_at_exactly_max_decel() -> None:
    radius, spacing, v_max = 15.0, 0.5, 20.0
    x_straight = np.arange(-150.0, 0.0, spacing)
    phi = np.arange(0.0, 40.0 / radius, spacing / radius)
    x = np.concatenate((x_straight, radius * np.sin(phi)))
    y = np.concatenate((np.zeros_like(x_straight), radius * (1 - np.cos(phi))))
    limits = SpeedLimits(max_speed_mps=v_max)
    profile = plan_speed_profile(x, y, limits)
    s, v = profile.s_m, profile.speed_mps
    junction = x_straight.size  # first arc waypoint, at s = 150 m

    v_arc = math.sqrt(A_LAT * radius)
    arc = slice(junction + 3, None)  # past the window straddling the junction
    np.testing.assert_allclose(v[arc], v_arc, rtol=0.01)
    assert_within_limits(profile)

    # Braking: v^2 + 2 a_dec s is constant from where the speed leaves v_max to the arc (uniform braking).
    braking = np.flatnonzero((v < v_max) & (np.arange(v.size) < junction - 2))
    energy = v[braking] ** 2 + 2 * limits.max_decel_mps2 * s[braking]
    np.testing.assert_allclose(energy, energy[0], rtol=1e-12)
    np.testing.assert_allclose(accel_along(profile)[braking[:-1]], -limits.max_decel_mps2, rtol=1e-9)
    # ... and it starts the analytic braking distance (v_max^2 - v_arc^2) / (2 a_dec) = 88.97 m before the
    # arc; the quadratic window blends the curvature over +-2 waypoints at the junction, hence 3 spacings
    # of slack.
    braking_start = (energy[0] - v_max**2) / (2 * limits.max_decel_mps2)
    analytic_start = s[junction] - (v_max**2 - v_arc**2) / (2 * limits.max_decel_mps2)
    assert analytic_start - 0.5 * spacing <= braking_start <= analytic_start + 3 * spacing
    np.testing.assert_array_equal(v[s < braking_start - spacing], v_max)


def test_initial_and_final_speed_caps() -> None:
    x = np.linspace(0.0, 300.0, 301)
    limits = SpeedLimits(max_speed_mps=25.0, max_accel_mps2=1.5, max_decel_mps2=2.5, min_speed_mps=2.0)
    profile = plan_speed_profile(x, np.zeros_like(x), limits, initial_speed_mps=5.0, final_speed_mps=2.0)
    s, v = profile.s_m, profile.speed_mps
    assert v[0] == 5.0
    assert v[-1] == pytest.approx(2.0, rel=1e-12)
    # Accelerates from 5 m/s at a_acc, brakes to 2 m/s at a_dec: v^2 = 25 + 3 s, v^2 = 4 + 5 (300 - s).
    np.testing.assert_allclose(v**2, np.minimum.reduce([25 + 3 * s, 4 + 5 * (300 - s), np.full_like(s, 625)]))
    assert_within_limits(profile)


def test_speed_at_interpolates_and_wraps() -> None:
    x, y, _ = circle(40.0, -1, closed=True)
    x = x * np.linspace(1.0, 1.6, x.size)  # a loop of varying curvature, so the speed varies
    profile = plan_speed_profile(x, y, SpeedLimits(max_speed_mps=30.0), closed=True)
    length = profile.length_m
    assert length == pytest.approx(profile.s_m[-1] + math.hypot(x[0] - x[-1], y[0] - y[-1]))
    np.testing.assert_allclose(profile.speed_at(profile.s_m), profile.speed_mps)
    np.testing.assert_allclose(profile.speed_at(profile.s_m + 2 * length), profile.speed_mps)
    np.testing.assert_allclose(profile.speed_at(profile.s_m - length), profile.speed_mps)
    midway_across_seam = 0.5 * (profile.s_m[-1] + length)
    assert profile.speed_at(midway_across_seam) == pytest.approx(0.5 * (profile.speed_mps[-1] + profile.speed_mps[0]))
    assert isinstance(profile.speed_at(1.0), float)

    open_profile = plan_speed_profile(x, y, SpeedLimits(max_speed_mps=30.0))
    assert open_profile.speed_at(-5.0) == open_profile.speed_mps[0]
    assert open_profile.speed_at(open_profile.length_m + 5.0) == open_profile.speed_mps[-1]
    assert open_profile.speed_at(0.5 * (open_profile.s_m[3] + open_profile.s_m[4])) == pytest.approx(
        0.5 * (open_profile.speed_mps[3] + open_profile.speed_mps[4])
    )


def test_to_pandas() -> None:
    x, y, _ = circle(25.0, 1, closed=False)
    profile = plan_speed_profile(x, y, SpeedLimits(max_speed_mps=30.0))
    frame = profile.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    assert list(frame.columns) == ["s_m", "speed_mps", "curvature_1pm"]
    np.testing.assert_array_equal(frame["speed_mps"].to_numpy(), profile.speed_mps)
    assert len(frame) == x.size


# --- property tests: the limits hold on any smooth path -----------------------------------------------------

limits_strategy = st.builds(
    SpeedLimits,
    max_speed_mps=st.floats(5.0, 40.0),
    max_lateral_accel_mps2=st.floats(1.0, 6.0),
    max_accel_mps2=st.floats(0.3, 3.0),
    max_decel_mps2=st.floats(0.5, 6.0),
    min_speed_mps=st.floats(0.5, 2.0),
)
harmonic = st.tuples(st.floats(-0.06, 0.06), st.floats(20.0, 300.0), st.floats(0.0, 2 * np.pi))


@settings(max_examples=60, deadline=None)
@given(
    harmonics=st.lists(harmonic, min_size=1, max_size=4),
    limits=limits_strategy,
    seed=st.integers(0, 2**32 - 1),
)
def test_open_clothoid_like_paths_respect_all_limits(
    harmonics: list[tuple[float, float, float]], limits: SpeedLimits, seed: int
) -> None:
    # Curvature: a sum of sinusoids in arc length (|kappa| <= 0.24 1/m), integrated over 0.3-2.5 m steps.
    rng = np.random.default_rng(seed)
    s = np.concatenate(([0.0], np.cumsum(rng.uniform(0.3, 2.5, size=400))))
    kappa = sum(a * np.sin(2 * np.pi * s / wavelength + phase) for a, wavelength, phase in harmonics)
    heading = np.concatenate(([0.0], np.cumsum(0.5 * (kappa[1:] + kappa[:-1]) * np.diff(s))))
    x = np.concatenate(([0.0], np.cumsum(np.cos(heading[:-1]) * np.diff(s))))
    y = np.concatenate(([0.0], np.cumsum(np.sin(heading[:-1]) * np.diff(s))))
    profile = plan_speed_profile(x, y, limits)
    assert_within_limits(profile)
    # Somewhere the profile is at a bound: the lateral limit, max speed, or an acceleration/braking limit.
    lateral = np.sqrt(limits.max_lateral_accel_mps2 / np.maximum(np.abs(profile.curvature_1pm), 1e-12))
    assert np.any(np.isclose(profile.speed_mps, np.minimum(limits.max_speed_mps, lateral), rtol=1e-9))


@settings(max_examples=60, deadline=None)
@given(
    radius_m=st.floats(15.0, 200.0),
    ripples=st.lists(st.tuples(st.integers(2, 5), st.floats(-0.03, 0.03), st.floats(0, 2 * np.pi)), max_size=3),
    limits=limits_strategy,
    seed=st.integers(0, 2**32 - 1),
)
def test_closed_loops_respect_all_limits_across_the_seam(
    radius_m: float, ripples: list[tuple[int, float, float]], limits: SpeedLimits, seed: int
) -> None:
    # Star-shaped loop r(theta) = R (1 + sum eps cos(k theta + phase)), unevenly sampled every 0.3-2.5 m.
    rng = np.random.default_rng(seed)
    theta = np.cumsum(rng.uniform(0.3, 2.5, size=100_000) / radius_m)
    theta = theta[theta < 2 * np.pi - 0.3 / radius_m]
    r = radius_m * (1 + sum(eps * np.cos(k * theta + phase) for k, eps, phase in ripples))
    x, y = r * np.cos(theta), r * np.sin(theta)
    profile = plan_speed_profile(x, y, limits, closed=True)
    assert_within_limits(profile)  # includes the segment from the last waypoint back to the first
    # Planning from another starting waypoint gives the same speeds: the seam leaves no trace.
    shifted = plan_speed_profile(np.roll(x, 11), np.roll(y, 11), limits, closed=True)
    np.testing.assert_allclose(shifted.speed_mps, np.roll(profile.speed_mps, 11), rtol=1e-9)


def test_min_speed_wins_over_the_lateral_limit() -> None:
    # A 0.5 m radius needs 1.2 m/s at 0.3 g; the profile never plans below min_speed (2 m/s here).
    angle = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    x, y = 0.5 * np.cos(angle), 0.5 * np.sin(angle)
    profile = plan_speed_profile(x, y, SpeedLimits(max_speed_mps=10.0, min_speed_mps=2.0), closed=True)
    np.testing.assert_allclose(profile.speed_mps, 2.0)


# --- bad input ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"max_speed_mps": 0.0}, r"SpeedLimits\.max_speed_mps must be a finite number > 0; got 0\.0"),
        ({"max_speed_mps": float("nan")}, r"max_speed_mps .*got nan"),
        ({"max_speed_mps": 10.0, "max_lateral_accel_mps2": -1.0}, r"max_lateral_accel_mps2 .*got -1\.0"),
        ({"max_speed_mps": 10.0, "max_accel_mps2": float("inf")}, r"max_accel_mps2 .*got inf"),
        ({"max_speed_mps": 10.0, "max_decel_mps2": 0}, r"max_decel_mps2 .*got 0"),
        ({"max_speed_mps": 10.0, "min_speed_mps": True}, r"min_speed_mps .*got True"),
        (
            {"max_speed_mps": 10.0, "min_speed_mps": 12.0},
            r"min_speed_mps must be <= max_speed_mps \(10\.0 m/s\); got 12",
        ),
    ],
)
def test_speed_limits_validation(kwargs: dict[str, float], match: str) -> None:
    with pytest.raises(WorkbenchInputError, match=match):
        SpeedLimits(**kwargs)


LIMITS = SpeedLimits(max_speed_mps=20.0)
GOOD = np.array([0.0, 1.0, 2.0, 3.0])


@pytest.mark.parametrize("function", ["geometry", "plan"])
@pytest.mark.parametrize(
    ("x", "y", "match"),
    [
        ([0.0, 1.0], [0.0, 1.0], r"at least 3 waypoints; got 2"),
        (GOOD, GOOD[:3], r"x_m has 4 points but y_m has 3"),
        ([0.0, np.nan, 2.0, 3.0], GOOD, r"x_m must be finite numbers; entry 1 is nan"),
        (GOOD, [0.0, 1.0, np.inf, 3.0], r"y_m must be finite numbers; entry 2 is inf"),
        (
            [0.0, 1.0, 1.0, 2.0],
            [0.0, 0.0, 0.0, 0.0],
            r"waypoints 1 and 2 repeat the same point \(1\.0, 0\.0\)",
        ),
    ],
)
def test_bad_waypoints(function: str, x: object, y: object, match: str) -> None:
    with pytest.raises(WorkbenchInputError, match=match):
        if function == "geometry":
            local_quadratic_geometry(x, y, closed=False)
        else:
            plan_speed_profile(x, y, LIMITS)


def test_closed_loop_must_not_repeat_its_first_point() -> None:
    with pytest.raises(WorkbenchInputError, match=r"waypoints 3 and 0 repeat the same point \(0\.0, 0\.0\)"):
        plan_speed_profile([0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0], LIMITS, closed=True)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"initial_speed_mps": 25.0}, r"initial_speed_mps must be a finite number in \[1, 20\] m/s; got 25\.0"),
        ({"final_speed_mps": 0.0}, r"final_speed_mps must be a finite number in \[1, 20\] m/s; got 0\.0"),
        ({"final_speed_mps": float("nan")}, r"final_speed_mps .*got nan"),
        (
            {"closed": True, "initial_speed_mps": 5.0},
            r"initial_speed_mps and final_speed_mps must be None; got 5\.0",
        ),
        (
            {"limits": {"max_speed_mps": 20.0}},
            r"limits must be a SpeedLimits; got \{'max_speed_mps': 20\.0\}",
        ),
    ],
)
def test_bad_plan_arguments(kwargs: dict[str, object], match: str) -> None:
    arguments: dict[str, object] = {"limits": LIMITS, **kwargs}
    with pytest.raises(WorkbenchInputError, match=match):
        plan_speed_profile(np.arange(10.0), np.zeros(10), **arguments)  # type: ignore[arg-type]


@pytest.mark.parametrize("half_window", [0, -1, 1.5, True])
def test_bad_half_window(half_window: object) -> None:
    with pytest.raises(WorkbenchInputError, match=rf"half_window must be an integer >= 1; got {half_window!r}"):
        local_quadratic_geometry(GOOD, GOOD**2, closed=False, half_window=half_window)  # type: ignore[arg-type]


def test_speed_at_rejects_nan() -> None:
    profile = plan_speed_profile(np.arange(10.0), np.zeros(10), LIMITS)
    with pytest.raises(WorkbenchInputError, match=r"s_m must be finite numbers; entry 1 is nan"):
        profile.speed_at([1.0, np.nan])


def test_profile_arrays_must_match() -> None:
    with pytest.raises(WorkbenchInputError, match=r"s_m: 3, speed_mps: 2, curvature_1pm: 3"):
        SpeedProfile(np.arange(3.0), np.ones(2), np.zeros(3), False, LIMITS, 2.0)
