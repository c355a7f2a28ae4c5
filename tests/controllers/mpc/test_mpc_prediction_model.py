"""The MPC prediction model: parameters from the presets, the truck's equivalent single track, the model kinds."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.signal
from hypothesis import given, settings
from hypothesis import strategies as st

from controllers.mpc.prediction_model import (
    PredictionModel,
    PredictionParams,
    matching_preset,
    params_from_geometry,
    prediction_params_for,
)
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import (
    VEHICLES,
    DynamicBicycleParams,
    TractorSemitrailerParams,
    make_vehicle,
    preset_text,
)
from workbench.vehicles.steering_lag import SteeringLag
from workbench.vehicles.tractor_semitrailer import derive

G = 9.81


def test_dynamic_bicycle_parameters_come_from_the_preset() -> None:
    p = DynamicBicycleParams()
    prm = prediction_params_for(make_vehicle("dynamic-bicycle"))
    st = prm.single_track
    assert st is not None
    assert st.mass_kg == p.mass_kg and st.yaw_inertia_kgm2 == p.yaw_inertia_kgm2
    assert (st.cg_to_front_axle_m, st.cg_to_rear_axle_m) == (p.cg_to_front_axle_m, p.cg_to_rear_axle_m)
    static_front = p.mass_kg * G * p.cg_to_rear_axle_m / p.wheelbase_m
    assert st.front_cornering_stiffness_n_per_rad == pytest.approx(p.front_cornering_coeff_per_rad * static_front)
    assert st.front_peak_force_n == pytest.approx(p.tyre_friction * static_front)
    assert prm.steering_time_constant_s == p.steering_time_constant_s
    assert prm.steering_ratio == p.steering_ratio and prm.wheelbase_m == pytest.approx(p.wheelbase_m)
    assert prm.default_kind() == "dynamic"
    # the same from the params dataclass, the preset name and a TOML file
    assert prediction_params_for(p).single_track == st
    assert prediction_params_for("dynamic-bicycle").single_track == st


def test_a_vehicle_file_is_read(tmp_path) -> None:
    text = preset_text("dynamic-bicycle").replace("mass_kg = 1093.3", "mass_kg = 1500.0")
    path = tmp_path / "heavy.toml"
    path.write_text(text)
    prm = prediction_params_for(path)
    assert prm.single_track is not None and prm.single_track.mass_kg == 1500.0


def test_kinematic_vehicle_and_geometry_give_the_kinematic_model() -> None:
    kinematic = prediction_params_for(make_vehicle("kinematic-bicycle"))
    assert kinematic.single_track is None and kinematic.default_kind() == "kinematic"
    geometry = make_vehicle("tractor-semitrailer").geometry
    only = params_from_geometry(geometry)
    assert only.single_track is None and "geometry" in only.source
    assert only.max_road_wheel_rate_rad_s == pytest.approx(geometry.max_steer_wheel_rate_rad_s / 22.0)
    assert prediction_params_for(geometry) == only


def test_commonroad_mb_uses_commonroads_car() -> None:
    prm = prediction_params_for(make_vehicle("commonroad-mb"))
    assert prm.single_track is not None
    assert prm.single_track.mass_kg == pytest.approx(1093.3, abs=0.1)


def test_unusable_vehicle_descriptions_are_rejected() -> None:
    with pytest.raises(WorkbenchInputError, match="cannot build an MPC prediction model from a int"):
        prediction_params_for(3)
    with pytest.raises(WorkbenchInputError, match="unknown vehicle 'bus'"):
        prediction_params_for("bus")
    with pytest.raises(WorkbenchInputError, match="wheelbase_m must be a finite number in"):
        PredictionParams(
            wheelbase_m=40.0, steering_ratio=15.0, max_road_wheel_angle_rad=0.5, max_road_wheel_rate_rad_s=1
        )
    with pytest.raises(WorkbenchInputError, match="needs mass, inertia and tyres"):
        PredictionModel(prediction_params_for("kinematic-bicycle"), "dynamic")
    with pytest.raises(WorkbenchInputError, match="needs an identified lag"):
        PredictionModel(prediction_params_for("dynamic-bicycle"), "kinematic-lag")
    with pytest.raises(WorkbenchInputError, match="model kind must be one of"):
        PredictionModel(prediction_params_for("dynamic-bicycle"), "bicycle")


@pytest.mark.parametrize("name", sorted(VEHICLES))
def test_each_preset_geometry_matches_its_preset(name: str) -> None:
    assert matching_preset(make_vehicle(name).geometry) == name


def test_truck_equivalent_single_track_carries_the_kingpin_share() -> None:
    p = TractorSemitrailerParams()
    d = derive(p)
    st = prediction_params_for(p).single_track
    assert st is not None
    king = d.m2 * (p.hitch_to_trailer_axle_m - d.e) / p.hitch_to_trailer_axle_m
    assert st.mass_kg == pytest.approx(d.m1 + king)
    # the equivalent CG carries the static axle-group loads of the articulated model
    assert st.mass_kg * G * st.cg_to_rear_axle_m / st.wheelbase_m == pytest.approx(d.loads_n[0])
    assert st.rear_cornering_stiffness_n_per_rad == pytest.approx(p.drive_cornering_coeff_per_rad * d.loads_n[1])


def _steady_curvature_plant(name: str, steer_wheel_rad: float, speed_mps: float) -> tuple[float, float]:
    vehicle = make_vehicle(name)
    state = vehicle.initial_state(0.0, 0.0, 0.0, speed_mps)
    for _ in range(25 * 50):
        state = vehicle.advance(state, steer_wheel_rad, 0.0, 0.02, 20)
    out = dict(zip(vehicle.output_names, vehicle.outputs(state, steer_wheel_rad, 0.0), strict=True))
    return out["yaw_rate_rad_s"] / out["vx_mps"], out["vx_mps"]


def _steady_curvature_model(model: PredictionModel, road_wheel_rad: float, speed_mps: float) -> float:
    step = model.discrete(0.02, 2)
    x = np.zeros(model.nx)
    x[model.i_cmd] = road_wheel_rad
    for _ in range(25 * 50):
        x = np.asarray(step(x, 0.0, [0.0, speed_mps])).ravel()
    return float(x[model.state_names.index("yaw_rate_rad_s")]) / speed_mps


@pytest.mark.parametrize(
    ("name", "steer_wheel_deg", "speed_mps", "tolerance"),
    [
        ("tractor-semitrailer", 40.0, 8.33, 0.002),
        ("tractor-semitrailer", 120.0, 8.33, 0.002),
        ("tractor-semitrailer", 40.0, 16.7, 0.005),
        ("dynamic-bicycle", 60.0, 16.7, 1e-4),
    ],
)
def test_steady_cornering_matches_the_plant(name: str, steer_wheel_deg: float, speed_mps: float, tolerance: float):
    """The single track (the truck's equivalent one included) turns on the same steady circle as the plant."""
    steer = math.radians(steer_wheel_deg)
    plant, speed = _steady_curvature_plant(name, steer, speed_mps)
    prm = prediction_params_for(name)
    model = _steady_curvature_model(PredictionModel(prm), steer / prm.steering_ratio, speed)
    assert model == pytest.approx(plant, rel=tolerance)


@pytest.mark.parametrize("kind", ["dynamic", "kinematic", "kinematic-lag"])
def test_driving_straight_along_a_straight_is_an_equilibrium(kind: str) -> None:
    prm = prediction_params_for("dynamic-bicycle").with_lag(SteeringLag(4.0, 0.8, 0.05))
    model = PredictionModel(prm, kind)
    xdot = np.asarray(model.ode(np.zeros(model.nx), 0.0, [0.0, 8.0])).ravel()
    assert np.all(xdot == 0.0)


@pytest.mark.parametrize(
    ("kind", "gain"), [("dynamic", 1.0), ("kinematic", 1.0), ("kinematic-lag", 1.0), ("kinematic-lag", 0.8)]
)
def test_reference_states_are_steady_cornering(kind: str, gain: float) -> None:
    """The LTV-MPC's linearisation points: steady cornering with no cross-track error (the dynamic one up to the
    magic formula's curvature factor E, which its inversion ignores; kinematic-lag with an understeer gain K)."""
    prm = prediction_params_for("dynamic-bicycle").with_lag(SteeringLag(4.0, 0.8, 0.05, steady_state_gain=gain))
    model = PredictionModel(prm, kind)
    kappa, speed = np.array([0.0, 0.01, -0.02, 1 / 30]), np.array([5.0, 8.0, 8.0, 8.33])
    refs = model.reference_states(kappa, speed)
    for x, k, v in zip(refs, kappa, speed, strict=True):
        xdot = np.asarray(model.ode(x, 0.0, [k, v])).ravel()
        lateral = v * v * abs(k)
        scale = np.array([v, v * abs(k), lateral, lateral, 1.0, 1.0, 1.0])[: model.nx] + 1e-3
        assert np.all(np.abs(xdot) / scale < (1e-4 if kind == "dynamic" else 1e-12)), (k, xdot)


@pytest.mark.parametrize("gain", [1.0, 0.85])
def test_identified_lag_is_the_transfer_function_of_eq5(gain: float) -> None:
    """kinematic-lag: the curvature's response to a step of the kinematic curvature is the second-order lag of
    Eq. 5 with its delay as a first-order Pade approximant and its steady-state gain K (reference: scipy.signal)."""
    lag = SteeringLag(omega_n_rad_s=3.0, zeta=0.7, delay_s=0.1, steady_state_gain=gain)
    prm = prediction_params_for("tractor-semitrailer").with_lag(lag)
    model = PredictionModel(prm, "kinematic-lag")
    h = 0.01
    step = model.discrete(h, 1)
    road_wheel = 0.05
    x = np.zeros(model.nx)
    x[model.i_cmd] = road_wheel
    x[model.state_names.index("delayed_wheelbase_x_curvature")] = 0.0
    samples = []
    for _ in range(400):
        samples.append(x[model.state_names.index("wheelbase_x_curvature")])
        x = np.asarray(step(x, 0.0, [0.0, 8.0])).ravel()
    wn, zeta, delay = lag.omega_n_rad_s, lag.zeta, lag.delay_s
    num = np.polymul([gain * wn * wn], [-delay / 2, 1.0])
    den = np.polymul([1.0, 2 * zeta * wn, wn * wn], [delay / 2, 1.0])
    t = h * np.arange(400)
    _, expected = scipy.signal.step((num, den), T=t)
    np.testing.assert_allclose(np.array(samples) / math.tan(road_wheel), expected, atol=2e-4)


@settings(max_examples=20, deadline=None)
@given(min_speed=st.floats(0.5, 20.0), step=st.floats(0.01, 0.2))
def test_rk4_substeps_keep_the_fast_modes_stable(min_speed: float, step: float) -> None:
    """Property: the sub-step count keeps h |lambda| within RK4's stability margin at the lowest speed."""
    model = PredictionModel(prediction_params_for("dynamic-bicycle"))
    n = model.substeps_for(step, min_speed)
    st_ = model.params.single_track
    assert st_ is not None
    fastest = max(st_.fastest_lateral_mode_per_s(min_speed), 1.0 / model.params.steering_time_constant_s)
    assert step / n * fastest <= 2.0 + 1e-9
    assert n == 1 or step / (n - 1) * fastest > 2.0


@pytest.mark.parametrize("kind", ["dynamic", "kinematic", "kinematic-lag"])
def test_compiled_progress_is_the_trapezoidal_integral_of_the_casadi_rate(kind: str) -> None:
    params = prediction_params_for("dynamic-bicycle")
    if kind == "kinematic-lag":
        params = params.with_lag(SteeringLag(omega_n_rad_s=6.0, zeta=0.8, delay_s=0.05))
    model = PredictionModel(params, kind)
    rng = np.random.default_rng(1)
    n, step = 7, 0.05
    states = rng.normal(0.0, 0.3, size=(n + 1, model.nx))
    states[2, 0] = 30.0  # 1 - kappa e_y below the floor: s' is held finite, as in the CasADi model
    kappa, speed = rng.normal(0.0, 0.05, n), rng.uniform(2.0, 20.0, n)
    kappa[2] = 0.5
    node_params = np.vstack((np.append(kappa, kappa[-1]), np.append(speed, speed[-1]))).T  # node N: last interval
    rate = np.array([float(model.progress_rate(x, p)) for x, p in zip(states, node_params, strict=True)])
    expected = np.concatenate(([0.0], np.cumsum(0.5 * step * (rate[1:] + rate[:-1]))))
    np.testing.assert_allclose(model.progress(states, kappa, speed, step), expected, rtol=1e-12, atol=1e-12)


def test_prediction_params_are_frozen() -> None:
    prm = prediction_params_for("dynamic-bicycle")
    with pytest.raises(dataclasses.FrozenInstanceError):
        prm.wheelbase_m = 3.0  # type: ignore[misc]
