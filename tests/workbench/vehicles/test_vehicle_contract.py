"""The contract every registered vehicle meets (`workbench/vehicles/base.py`), parametrised over the registry and a
plant from an FMU (`fmu`: the example FMU of CommonRoad's single-track car, tests/conftest.py): state and output
layout, finite integration at rest and in motion, a straight line stays straight, standstill stays put, and steady
cornering at low lateral acceleration agrees with the linear single track."""

from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.vehicles import STANDARD_OUTPUTS, VEHICLES, VehicleModel, make_vehicle

#: The registry's vehicles, and a plant from an FMU (its vehicle file from the session's example FMU: FILES).
NAMES = [*sorted(VEHICLES), "fmu"]
FILES: dict[str, str] = {}
G = 9.81
DT, SUBSTEPS = 0.02, 20  # the simulator's defaults: 50 Hz controller, 1 kHz plant

_CACHE: dict[str, VehicleModel] = {}

#: Known breach: CommonRoad's MB model braked at standstill returns NaN from its derivative within two controller
#: steps (its wheel dynamics break down at zero speed; the adapter turns the exception into NaN, which the
#: simulator reports as a diverged run). A third-party model: recorded here, not patched.
MB_BRAKED_AT_REST = pytest.mark.xfail(
    strict=True, reason="CommonRoad MB braked at standstill: its derivative breaks down (NaN)"
)


def combos(speeds: tuple[float, ...], accels: tuple[float, ...]) -> list:
    """(name, speed, accel) over the registry, with the MB model braked at standstill marked as the known breach."""
    return [
        pytest.param(
            name, v, a, marks=MB_BRAKED_AT_REST if (name, v < 1e-9, a < 0.0) == ("commonroad-mb", True, True) else ()
        )
        for name in NAMES
        for v in speeds
        for a in accels
    ]


@pytest.fixture(autouse=True, scope="module")
def _fmu_vehicle_file(example_plant_fmus) -> None:
    FILES["fmu"] = str(example_plant_fmus["2"])


def vehicle(name: str) -> VehicleModel:
    if name not in _CACHE:
        _CACHE[name] = make_vehicle(vehicle_file=FILES[name]) if name in FILES else make_vehicle(name)
    return _CACHE[name]


def run(model: VehicleModel, state: np.ndarray, steer: float, accel: float, duration_s: float) -> np.ndarray:
    for _ in range(round(duration_s / DT)):
        state = model.advance(state, steer, accel, DT, SUBSTEPS)
    return state


def outputs(model: VehicleModel, state: np.ndarray, steer: float = 0.0, accel: float = 0.0) -> dict[str, float]:
    return dict(zip(model.output_names, model.outputs(state, steer, accel).tolist(), strict=True))


@pytest.mark.parametrize("name", NAMES)
def test_state_and_output_layout(name: str) -> None:
    model = vehicle(name)
    assert model.name == name
    state = model.initial_state(1.0, 2.0, 0.3, 5.0)
    assert state.shape == (len(model.state_names),)
    assert len(set(model.state_names)) == len(model.state_names)
    # The simulator reads the first seven outputs by position (x, y, yaw, vx, vy, yaw rate, steering wheel) and
    # the trace and metrics read them by name: the standard outputs come first, in order, then the extras.
    assert model.output_names[: len(STANDARD_OUTPUTS)] == STANDARD_OUTPUTS
    assert len(set(model.output_names)) == len(model.output_names)
    assert model.outputs(state, 0.0, 0.0).shape == (len(model.output_names),)


@pytest.mark.parametrize("name", NAMES)
def test_initial_state_puts_the_reference_point_where_asked(name: str) -> None:
    model = vehicle(name)
    out = outputs(model, model.initial_state(10.0, -20.0, 0.7, 5.0))
    # 1e-12 m: CommonRoad's MB states its CG, and the adapter adds and subtracts b (cos yaw, sin yaw).
    assert out["x_m"] == pytest.approx(10.0, abs=1e-12)
    assert out["y_m"] == pytest.approx(-20.0, abs=1e-12)
    assert out["yaw_rad"] == 0.7
    assert out["vx_mps"] == 5.0
    assert out["vy_mps"] == out["yaw_rate_rad_s"] == out["steer_wheel_rad"] == out["road_wheel_angle_rad"] == 0.0


@pytest.mark.parametrize(("name", "speed_mps", "accel"), combos((0.0, 0.5, 2.0, 15.0), (0.0, 1.0, -3.0)))
def test_advance_and_outputs_are_finite_at_rest_and_in_motion(name: str, speed_mps: float, accel: float) -> None:
    # Full lock and a hard acceleration or braking, from standstill, through the kinematic blend (1-3 m/s) and
    # above it: every state, every output and the rate of change over one step stay finite.
    model = vehicle(name)
    lock = model.geometry.max_steer_wheel_angle_rad
    state = model.initial_state(0.0, 0.0, 0.0, speed_mps)
    for _ in range(10):
        new = model.advance(state, lock, accel, DT, SUBSTEPS)
        assert new.shape == state.shape
        assert np.all(np.isfinite(new)), dict(zip(model.state_names, new.tolist(), strict=True))
        assert np.all(np.isfinite((new - state) / DT))
        assert np.all(np.isfinite(model.outputs(new, lock, accel)))
        assert new[3] >= 0.0 if name != "commonroad-mb" else True  # no reversing (MB: its own speed state)
        state = new


#: name -> bound on |y| (m), |yaw| (rad) and |yaw rate| (rad/s) after 2 s straight at 10 m/s. The compiled models
#: have no lateral excitation at all: exactly 0. CommonRoad's tyres have small offsets (p_hy1, p_vy1) that pull
#: the MB car aside: measured 0.53 mm, 2.1e-5 rad and 2.9e-4 rad/s (a slow lateral oscillation); 10x those.
STRAIGHT = {"commonroad-mb": (5e-3, 2e-4, 3e-3)}


@pytest.mark.parametrize("name", NAMES)
def test_straight_line_stays_straight(name: str) -> None:
    # No steering at constant speed: the reference point moves along x and nothing turns.
    model = vehicle(name)
    state = run(model, model.initial_state(0.0, 0.0, 0.0, 10.0), 0.0, 0.0, 2.0)
    out = outputs(model, state)
    y_max, yaw_max, rate_max = STRAIGHT.get(name, (0.0, 0.0, 0.0))
    assert abs(out["y_m"]) <= y_max
    assert abs(out["yaw_rad"]) <= yaw_max
    assert abs(out["yaw_rate_rad_s"]) <= rate_max
    # The compiled models realise a = 0 exactly; the MB model rolls with its own wheel dynamics: 0.1% of speed.
    assert out["vx_mps"] == pytest.approx(10.0, rel=1e-3)
    assert out["x_m"] == pytest.approx(20.0, rel=1e-3)


@pytest.mark.parametrize(("name", "speed_mps", "accel"), combos((0.0,), (0.0, -2.0)))
def test_standstill_stays_put(name: str, speed_mps: float, accel: float) -> None:
    # At rest, with the wheels turned (and the brake on), nothing moves: the steering actuator turns the wheels
    # but the vehicle neither creeps nor turns, and braking does not reverse it.
    model = vehicle(name)
    lock = model.geometry.max_steer_wheel_angle_rad
    state = run(model, model.initial_state(3.0, 4.0, 0.5, speed_mps), 0.5 * lock, accel, 2.0)
    out = outputs(model, state, 0.5 * lock, accel)
    assert out["x_m"] == pytest.approx(3.0, abs=1e-9)
    assert out["y_m"] == pytest.approx(4.0, abs=1e-9)
    assert out["yaw_rad"] == pytest.approx(0.5, abs=1e-9)
    assert abs(out["vx_mps"]) < 1e-9
    assert out["road_wheel_angle_rad"] == pytest.approx(0.5 * model.geometry.max_road_wheel_angle_rad, rel=1e-6)


def understeer_gradient_rad_per_mps2(model: VehicleModel) -> float:
    """K of the linear single track, delta = L kappa + K a_y, from each model's tyre coefficients."""
    p = model.params
    if model.name == "dynamic-bicycle":
        return p.understeer_gradient_rad_per_mps2  # (1 / k_f - 1 / k_r) / g; 0 for the preset (one tyre)
    if model.name == "tractor-semitrailer":  # the tractor: steer axle against drive group (kingpin load included)
        return (1.0 / p.front_cornering_coeff_per_rad - 1.0 / p.drive_cornering_coeff_per_rad) / G
    if model.name == "fmu":  # the vehicle file's single track: CommonRoad's linear-tyre single track's (0)
        return model.single_track().single_track.understeer_gradient_rad_per_mps2()
    return 0.0  # kinematic: no slip; CommonRoad MB vehicle 2: one tyre front and rear, neutral to first order


#: name -> (settling time (s), relative tolerance of the yaw rate against the linear single track), measured at
#: 15 m/s and 0.05 g. Kinematic: the formula is the model (0 measured; 1e-12 allows rounding). Dynamic bicycle:
#: the magic formula's curvature at 0.05 g, 4e-5 measured at 10 m/s, 6e-6 at 20 m/s; 1e-3 allows a preset 25
#: times more nonlinear. Truck: the trailer's kingpin force and the tandem's lumping move it off the two-axle
#: formula, 6e-4 measured at 10 m/s, 4e-4 at 20 m/s; 2e-3 allows 3x. MB: roll, load transfer and combined slip
#: make it oversteer slightly, +0.4% at 10 m/s, +1.6% at 20 m/s; 3% allows that growth to 25 m/s, as "within a
#: few percent" of the linear model is what a third-party multi-body car can be held to. FMU (CommonRoad's single
#: track, cornering stiffness proportional to axle load: neutral, K = 0): the linear model's small-angle terms,
#: 4.2e-5 measured at 10 m/s, 1.0e-5 at 15 m/s, 3.2e-6 at 20 m/s; 2e-4 allows 5x the largest.
STEADY = {
    "kinematic-bicycle": (3.0, 1e-12),
    "dynamic-bicycle": (6.0, 1e-3),
    "tractor-semitrailer": (20.0, 2e-3),
    "commonroad-mb": (8.0, 3e-2),
    "fmu": (6.0, 2e-4),
}


@pytest.mark.parametrize("name", NAMES)
def test_steady_cornering_at_low_lateral_acceleration_matches_the_linear_single_track(name: str) -> None:
    # Steady state of the linear single track: delta = L kappa + K a_y, so r = u tan(delta) / (L + K u^2)
    # (tan: the kinematic term exactly; K u^2 is small at 0.05 g). The steering wheel is set for 0.05 g.
    assert set(STEADY) == set(NAMES), "give every registered vehicle its settling time and tolerance"
    model = vehicle(name)
    settle_s, rel = STEADY[name]
    speed, wb, k_us = 15.0, model.geometry.wheelbase_m, understeer_gradient_rad_per_mps2(model)
    kappa = 0.05 * G / speed**2
    steer = model.geometry.steer_wheel_for_curvature(kappa * (1.0 + k_us * speed**2 / wb))
    state = run(model, model.initial_state(0.0, 0.0, 0.0, speed), steer, 0.0, settle_s)
    out = outputs(model, state, steer)
    u, r, delta = out["vx_mps"], out["yaw_rate_rad_s"], out["road_wheel_angle_rad"]
    assert r == pytest.approx(u * math.tan(delta) / (wb + k_us * u**2), rel=rel)
    assert out["lat_accel_mps2"] == pytest.approx(0.05 * G, rel=0.05)  # the set-up did what it says
    if k_us > 0.0:  # an understeering model turns less than the kinematic curvature of its steered unit
        assert r < u * math.tan(delta) / wb


@pytest.mark.parametrize("name", NAMES)
def test_the_single_track_equivalent_has_the_vehicles_geometry(name: str) -> None:
    """What a model-based controller predicts with (`VehicleModel.single_track`) is this vehicle's: the same
    wheelbase, steering ratio and lock; with tyres, axle positions that add up to that wheelbase."""
    model = vehicle(name)
    equivalent = model.single_track()
    geometry = model.geometry
    assert equivalent.wheelbase_m == pytest.approx(geometry.wheelbase_m, rel=1e-12)
    assert equivalent.steering_ratio == geometry.steering_ratio
    assert equivalent.max_road_wheel_angle_rad == pytest.approx(geometry.max_road_wheel_angle_rad, rel=1e-12)
    assert model.name in equivalent.source
    if equivalent.single_track is not None:
        assert equivalent.single_track.wheelbase_m == pytest.approx(geometry.wheelbase_m, rel=1e-9)


@pytest.mark.parametrize("name", NAMES)
def test_the_inputs_are_clipped_as_min_and_max_clip_them(name: str) -> None:
    """The plant's inputs (`_inputs`, written out as comparisons for speed) are min(max(value, low), high) of the
    road-wheel command and the acceleration, to the sign of a zero and a NaN passed through."""
    model = vehicle(name)
    g, p = model.geometry, model.params
    lim = g.max_road_wheel_angle_rad
    steers = [-math.inf, -10.0, -lim * g.steering_ratio, -0.1, -0.0, 0.0, 1e-300, 0.3, lim * g.steering_ratio, math.nan]
    accels = [-math.inf, -50.0, -p.max_decel_mps2, -0.5, -0.0, 0.0, 0.7, p.max_accel_mps2, 50.0, math.inf, math.nan]

    def same(a: float, b: float) -> bool:
        return (math.isnan(a) and math.isnan(b)) or (a == b and math.copysign(1.0, a) == math.copysign(1.0, b))

    for steer in steers:
        for accel in accels:
            delta, realised = model._inputs(steer, accel)
            assert same(delta, min(max(steer / g.steering_ratio, -lim), lim)), (steer, delta)
            assert same(realised, min(max(accel, -p.max_decel_mps2), p.max_accel_mps2)), (accel, realised)
