"""The preview responses along the path (`preview_model.py`): the response's checks, `preview_curvature` against
the taps summed by hand on paths whose curvature is constant and linear in arc length (and, as a property, on any
taps), interpolated in speed like the lags, the handling gain against np.interp on arcs; the controller's choice of
model (`ClothoidConfig.feedforward_model`) and the step's feed-forward (with and without the handling gain) and
reference from the truck's own responses, with the loop and its floor unchanged."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.constants import g as G_MPS2

from controllers.base import Measurement
from controllers.clothoid import ClothoidConfig, ClothoidController
from controllers.clothoid.preview_model import (
    HANDLING_GRID_G,
    MARCH_TAPS,
    PreviewResponse,
    preview_curvature,
    preview_curvatures,
)
from tuning.own_tuning import tuning_for
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError
from workbench.base.path_search import CompiledPath
from workbench.vehicles import make_vehicle

TRUCK, CAR = make_vehicle("tractor-semitrailer"), make_vehicle("dynamic-bicycle")
TRUCK_TUNING = tuning_for(TRUCK)
SPACING_M = 0.25
S_GRID = np.arange(0.0, 300.0 + SPACING_M / 2, SPACING_M)
RATE_1PM2 = 4e-4
FIRST_S, TAP_S = -1.0, 0.05


def _sum(
    curvature: np.ndarray,
    s_m: float,
    speed_mps: float,
    taps: np.ndarray,
    speeds=(30.0,),
    shift_s=0.0,
    planned=None,
    handling=None,
) -> float:
    zeros = np.zeros_like(curvature)
    samples = (zeros, zeros, zeros, curvature, planned)
    compiled = CompiledPath.of(samples, SPACING_M, float(S_GRID[-1]), False, 0.0, 5.0)
    return preview_curvature(
        compiled.table, compiled.record, s_m, speed_mps, shift_s, FIRST_S, TAP_S, np.array(speeds, dtype=float),
        np.atleast_2d(taps), np.zeros((len(speeds), 0)) if handling is None else np.atleast_2d(handling),
    )  # fmt: skip


def test_a_response_is_checked() -> None:
    with pytest.raises(WorkbenchInputError, match="first_tap_s must be in"):
        PreviewResponse(0.5, 0.05, (1.0,), (1.0,))
    with pytest.raises(WorkbenchInputError, match="tap_spacing_s must be in"):
        PreviewResponse(-1.0, 0.0, (1.0,), (1.0,))
    with pytest.raises(WorkbenchInputError, match="as many"):
        PreviewResponse(-1.0, 0.05, (1.0, 0.0), (1.0,))
    with pytest.raises(WorkbenchInputError, match="finite"):
        PreviewResponse(-1.0, 0.05, (math.nan,), (1.0,))
    with pytest.raises(WorkbenchInputError, match="sum to one"):
        PreviewResponse(-1.0, 0.05, (1.0, 0.0), (0.6, 0.6))
    ones = (1.0,) * len(HANDLING_GRID_G)
    assert PreviewResponse(-1.0, 0.05, (1.0,), (1.0,)).handling_gain == ones
    for bad in ((1.0,) * 3, (*ones[:-1], 2.5), (*ones[:-1], 0.4), (*ones[:-1], math.nan)):
        with pytest.raises(WorkbenchInputError, match=r"handling_gain must be 9 gains .* each in \[0.5, 2\]"):
            PreviewResponse(-1.0, 0.05, (1.0,), (1.0,), bad)


def test_on_an_arc_it_is_the_curvature_times_the_taps_sum() -> None:
    taps = np.linspace(-0.1, 0.3, 41)
    assert _sum(np.full(S_GRID.size, 0.02), 100.0, 8.0, taps) == pytest.approx(0.02 * taps.sum(), rel=1e-12)


@settings(max_examples=60, deadline=None)
@given(
    taps=st.lists(st.floats(-2.0, 2.0), min_size=1, max_size=60),
    gains=st.lists(st.floats(0.5, 2.0), min_size=len(HANDLING_GRID_G), max_size=len(HANDLING_GRID_G)),
    kappa=st.floats(-0.2, 0.2),
    speed=st.floats(1.0, 30.0),
)
def test_on_an_arc_the_handling_gain_scales_the_taps_at_its_lateral_acceleration(taps, gains, kappa, speed) -> None:
    """On an arc at a held speed every tap reads v^2 |kappa| / g: the sum is kappa x sum(h) x the gain there,
    np.interp on HANDLING_GRID_G (held beyond its end)."""
    h = np.array(taps)
    gain = np.interp(speed**2 * abs(kappa) / G_MPS2, HANDLING_GRID_G, gains)
    got = _sum(np.full(S_GRID.size, kappa), 150.0, speed, h, handling=gains)
    assert got == pytest.approx(kappa * h.sum() * gain, rel=1e-9, abs=1e-12)


def test_the_handling_gain_is_interpolated_in_speed_like_the_taps() -> None:
    """Two speeds, one tap of one, gains 1 and 1.2 at 0.2 g: halfway in speed, 1.1 (the arc at 0.2 g there)."""
    speed = 30.0 / 3.6
    kappa = 0.2 * G_MPS2 / speed**2
    gains = np.ones((2, len(HANDLING_GRID_G)))
    gains[1, HANDLING_GRID_G.index(0.2)] = 1.2
    rows = np.ones((2, 1))
    got = _sum(np.full(S_GRID.size, kappa), 100.0, speed, rows, (20.0, 40.0), handling=gains)
    assert got == pytest.approx(kappa * 1.1, rel=1e-12)
    assert _sum(np.full(S_GRID.size, kappa), 100.0, speed, rows, (20.0, 40.0)) == pytest.approx(kappa, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    taps=st.lists(st.floats(-2.0, 2.0), min_size=1, max_size=60),
    speed=st.floats(1.0, 30.0),
    shift=st.floats(0.0, 0.5),
)
def test_on_a_clothoid_it_is_the_taps_on_the_curvature_at_each_taps_distance(taps, speed, shift) -> None:
    """kappa = c s, linear interpolation exact: sum_k h_k c (s + V (tau_k + shift))."""
    h = np.array(taps)
    s0 = 150.0
    tau = FIRST_S + TAP_S * np.arange(h.size)
    expected = float((h * RATE_1PM2 * (s0 + speed * (tau + shift))).sum())
    got = _sum(RATE_1PM2 * S_GRID, s0, speed, h, shift_s=shift)
    assert got == pytest.approx(expected, rel=1e-9, abs=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    taps=st.lists(st.floats(-2.0, 2.0), min_size=1, max_size=60),
    speed=st.floats(1.0, 30.0),
    planned=st.floats(1.0, 30.0),
    shift=st.floats(0.0, 0.5),
)
def test_a_held_planned_speed_gives_the_taps_at_the_measured_speed(taps, speed, planned, shift) -> None:
    """The plan's shape scaled to the measured speed: a held plan, whatever its level, reads the path as the measured
    speed held would."""
    h = np.array(taps)
    curvature = RATE_1PM2 * S_GRID
    held = _sum(curvature, 150.0, speed, h, shift_s=shift, planned=np.full(S_GRID.size, planned))
    assert held == pytest.approx(_sum(curvature, 150.0, speed, h, shift_s=shift), rel=1e-9, abs=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    taps=st.lists(st.floats(-2.0, 2.0), min_size=1, max_size=60),
    gain=st.floats(0.5, 2.0),
    speed=st.floats(1.0, 30.0),
    shift=st.floats(0.0, 0.5),
    s0=st.floats(0.0, 300.0),
)
def test_one_march_gives_both_sums_exactly(taps, gain, speed, shift, s0) -> None:
    """preview_curvatures' two sums are preview_curvature's of each set of taps, to the bit (one march for both),
    on a braked plan and a path whose curvature is not linear; the unscaled sum is not scaled."""
    steering = np.atleast_2d(taps)
    measured = steering[:, ::-1] * 0.5
    handling = np.linspace(1.0, gain, len(HANDLING_GRID_G))[np.newaxis, :]
    curvature = 0.05 * np.sin(S_GRID / 17.0)
    planned = np.sqrt(np.maximum(64.0 - 0.2 * S_GRID, 1.0))
    zeros = np.zeros_like(curvature)
    compiled = CompiledPath.of((zeros, zeros, zeros, curvature, planned), SPACING_M, float(S_GRID[-1]), False, 0.0, 5.0)
    common = (compiled.table, compiled.record, s0, speed, shift, FIRST_S, TAP_S, np.array([30.0]))
    both = preview_curvatures(*common, steering, handling, measured)
    alone = preview_curvature(*common, steering, handling), preview_curvature(*common, measured, measured[:, :0])
    assert both == alone
    assert preview_curvatures(*common, steering[:, :0], handling, measured)[0] == 0.0


@pytest.mark.parametrize("accel_mps2", [-1.5, 1.0])
@pytest.mark.parametrize("tau_s", [-1.0, -0.55, 0.0, 0.35, 2.0])
def test_braking_or_accelerating_the_taps_are_where_the_vehicle_is_at_their_time(accel_mps2, tau_s) -> None:
    """A plan of constant acceleration a (v^2 = v0^2 + 2 a (s - s0)) and one unit tap at tau on kappa = c s: the sum
    is c s(tau), s(tau) = s0 + v0 tau + a tau^2 / 2, within a h^2 / 8 of a tap between two of the march's steps
    (h = MARCH_TAPS taps: the straight line in time), the trapezoidal steps' a^2 h^2 |tau| / (4 v) and 1 mm of the
    plan's sampling; held at v0 it would be off by a tau^2 / 2 (up to 2 m here)."""
    s0, v0 = 150.0, 8.0
    planned = np.sqrt(np.maximum(v0**2 + 2.0 * accel_mps2 * (S_GRID - s0), 0.0))
    unit = np.zeros(round((tau_s - FIRST_S) / TAP_S) + 1)
    unit[-1] = 1.0
    got = _sum(RATE_1PM2 * S_GRID, s0, v0, unit, planned=planned) / RATE_1PM2
    expected = s0 + v0 * tau_s + 0.5 * accel_mps2 * tau_s**2
    h, a = MARCH_TAPS * TAP_S, abs(accel_mps2)
    tolerance = a * h**2 / 8.0 + a**2 * h**2 * abs(tau_s) / (4.0 * (v0 - 2.0 * a)) + 1e-3  # v0 - 2a: the slowest
    assert got == pytest.approx(expected, abs=tolerance)
    if tau_s != 0.0:
        assert abs((s0 + v0 * tau_s) - expected) > tolerance


def test_the_taps_are_interpolated_in_speed_and_clamped_beyond() -> None:
    arc = np.full(S_GRID.size, 0.01)
    rows = np.array([[1.0, 0.0], [0.0, 3.0]])  # sums 1 at 20 km/h, 3 at 40 km/h
    speeds = (20.0, 40.0)
    assert _sum(arc, 50.0, 30.0 / 3.6, rows, speeds) == pytest.approx(0.01 * 2.0, rel=1e-12)
    assert _sum(arc, 50.0, 10.0 / 3.6, rows, speeds) == pytest.approx(0.01, rel=1e-12)
    assert _sum(arc, 50.0, 60.0 / 3.6, rows, speeds) == pytest.approx(0.03, rel=1e-12)
    assert _sum(arc, 50.0, 40.0 / 3.6, rows, speeds) == pytest.approx(0.03, rel=1e-12)


def test_the_model_is_chosen_by_how_well_the_lag_explains_the_logs() -> None:
    assert ClothoidConfig().feedforward_model == "auto"
    with pytest.raises(WorkbenchInputError, match="feedforward_model"):
        ClothoidConfig(feedforward_model="fir")
    truck = ClothoidController(TRUCK.geometry, ClothoidConfig(tuning=TRUCK_TUNING), vehicle=TRUCK)
    car = ClothoidController(CAR.geometry, ClothoidConfig(tuning=tuning_for(CAR)), vehicle=CAR)
    assert truck.uses_preview and not car.uses_preview
    lag = ClothoidController(TRUCK.geometry, ClothoidConfig(tuning=TRUCK_TUNING, feedforward_model="lag"))
    assert not lag.uses_preview
    forced = ClothoidController(CAR.geometry, ClothoidConfig(tuning=tuning_for(CAR), feedforward_model="preview"))
    assert forced.uses_preview
    off = ClothoidController(TRUCK.geometry, ClothoidConfig(tuning=TRUCK_TUNING, feedforward_inversion=False))
    assert not off.uses_preview
    with pytest.raises(WorkbenchInputError, match="'preview' needs a tuning with the vehicle's preview responses"):
        ClothoidController(TRUCK.geometry, ClothoidConfig(feedforward_model="preview"))


def test_the_step_sends_the_trucks_preview_response_and_keeps_its_loop() -> None:
    """On a clothoid, the feed-forward the step keeps is the truck's steering response at its speed summed by hand
    over the path, the known delay ahead; the loop the floor is computed on is the lags' either way."""
    path = ClothoidChain().straight(20.0).clothoid_to(RATE_1PM2 * 150.0, 150.0).to_path("ramp")
    speed, known = 8.0, 0.1
    i = round(90.0 / path.spacing_m)
    config = ClothoidConfig(tuning=TRUCK_TUNING, known_delay_s=known)
    controller = ClothoidController(TRUCK.geometry, config, vehicle=TRUCK)
    controller.reset(path, 0.02)
    g = TRUCK.geometry
    kappa = float(path.curvature_1pm[i])
    steer = math.atan(g.wheelbase_m * kappa) * g.steering_ratio
    m = Measurement(
        0.0, float(path.x_m[i]), float(path.y_m[i]), speed, 0.0, float(path.heading_rad[i]), speed * kappa, steer
    )
    controller.step(m, path)
    first, spacing, steering, _ = TRUCK_TUNING.preview_tables
    speeds = np.array(TRUCK_TUNING.lag_speeds_kmh)
    row = np.array([np.interp(speed * 3.6, speeds, steering[:, k]) for k in range(steering.shape[1])])
    handling = TRUCK_TUNING.handling_table
    gains = [np.interp(speed * 3.6, speeds, handling[:, k]) for k in range(handling.shape[1])]
    s_taps = float(path.s_m[i]) + speed * (first + spacing * np.arange(row.size) + known)
    kappa_taps = np.interp(s_taps, path.s_m, path.curvature_1pm)
    gain_taps = np.interp(speed**2 * np.abs(kappa_taps) / G_MPS2, HANDLING_GRID_G, gains)
    assert np.abs(gain_taps - 1.0).max() > 0.01  # the truck's identified gain matters on this path (0-0.2 g)
    expected = float(row @ (kappa_taps * gain_taps))
    assert controller._state[0]["feedforward_kappa"] == pytest.approx(expected, rel=1e-3)
    linear = ClothoidController(
        TRUCK.geometry, ClothoidConfig(tuning=TRUCK_TUNING, known_delay_s=known, handling_gain=False), vehicle=TRUCK
    )
    linear.reset(path, 0.02)
    linear.step(m, path)
    assert linear._state[0]["feedforward_kappa"] == pytest.approx(float(row @ kappa_taps), rel=1e-3)
    lags = ClothoidController(
        TRUCK.geometry, ClothoidConfig(tuning=TRUCK_TUNING, known_delay_s=known, feedforward_model="lag")
    )
    lags.reset(path, 0.02)
    assert controller.loop_settings(30.0) == lags.loop_settings(30.0)
    assert controller.lookahead_floor_m(30.0 / 3.6) == lags.lookahead_floor_m(30.0 / 3.6)
