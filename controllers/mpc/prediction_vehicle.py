"""Which vehicle an MPC predicts with (`resolve_prediction_params`): the config's choice, the steered vehicle, a
preset of the same geometry or the geometry alone, checked against the steered vehicle's geometry."""

from __future__ import annotations

from controllers.mpc.config import MPCConfig
from controllers.mpc.prediction_model import (
    PredictionParams,
    matching_preset,
    params_from_geometry,
    prediction_params_for,
)
from workbench.base.errors import WorkbenchInputError
from workbench.vehicles.geometry import VehicleGeometry

#: Relative mismatch of wheelbase or steering ratio between the prediction vehicle and the steered vehicle that is
#: rejected as a configuration error (a car's model predicting a truck).
GEOMETRY_TOLERANCE = 0.02


def resolve_prediction_params(geometry: VehicleGeometry, config: MPCConfig, vehicle: object | None) -> PredictionParams:
    """The prediction parameters for a controller, in this order: the config's prediction_vehicle; its vehicle when not
    "auto"; the `vehicle` the caller passes (a VehicleModel, its params, ...: the steered vehicle itself); the
    shipped preset with the same geometry; the geometry alone. The config's lag file goes on top. The steering
    limits are always the steered vehicle's (`geometry`)."""
    from workbench.vehicles import VEHICLES

    if config.prediction_vehicle is not None:
        params = config.prediction_vehicle
    elif config.vehicle == "auto" and vehicle is not None:
        params = prediction_params_for(vehicle)
    elif config.vehicle == "auto":
        preset = matching_preset(geometry)
        params = prediction_params_for(preset) if preset else params_from_geometry(geometry)
    elif config.vehicle == "geometry":
        params = params_from_geometry(geometry)
    elif config.vehicle in VEHICLES:
        params = prediction_params_for(config.vehicle)
    else:
        raise WorkbenchInputError(
            f"vehicle must be 'auto', 'geometry' or one of the presets {', '.join(VEHICLES)}; got {config.vehicle!r}"
        )
    for name, mine, theirs in (
        ("wheelbase_m", params.wheelbase_m, geometry.wheelbase_m),
        ("steering_ratio", params.steering_ratio, geometry.steering_ratio),
    ):
        if abs(mine - theirs) > GEOMETRY_TOLERANCE * theirs:
            raise WorkbenchInputError(
                f"the prediction model ({params.source}) has {name} = {mine:g} but the steered vehicle has "
                f"{theirs:g}; choose the matching vehicle or vehicle_file (or vehicle = 'auto')"
            )
    params = PredictionParams(
        wheelbase_m=params.wheelbase_m,
        steering_ratio=geometry.steering_ratio,
        max_road_wheel_angle_rad=geometry.max_road_wheel_angle_rad,
        max_road_wheel_rate_rad_s=geometry.max_steer_wheel_rate_rad_s / geometry.steering_ratio,
        steering_time_constant_s=params.steering_time_constant_s,
        single_track=params.single_track,
        lag=params.lag,
        source=params.source,
    )
    if config.lag is not None:
        params = params.with_lag(config.lag)
    return params
