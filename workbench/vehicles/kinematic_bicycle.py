"""Kinematic bicycle with a first-order, rate-limited steering actuator, referenced at the rear-axle centre.

States: x_m, y_m (rear-axle centre), yaw_rad, speed_mps, road_wheel_angle_rad::

    x' = v cos(yaw), y' = v sin(yaw), yaw' = v tan(delta) / L,
    v' = a (v stays >= 0), delta' = clip((delta_cmd - delta) / tau, +-rate_max), delta_cmd = clip(sw_cmd / i_s).

No tyre slip: the path curvature follows the road-wheel angle exactly (tan(delta) = L kappa), so this plant shows
none of the lag of the paper's section 5. It is the reference the dynamic models must approach at low speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from workbench.base.errors import require_in_range, require_positive
from workbench.vehicles.actuator import realised_accel, road_wheel_rate
from workbench.vehicles.base import CompiledVehicleModel, VehicleGeometry
from workbench.vehicles.integration import rk4
from workbench.vehicles.single_track import PredictionParams


@dataclass(frozen=True)
class KinematicBicycleParams:
    """Parameters; defaults describe a C-class car (CommonRoad vehicle 2, a BMW 320i, from
    commonroad-vehicle-models `parameters_vehicle2`: a + b = 1.156 + 1.423 m, width 1.61 m, road-wheel angle
    limit 1.066 rad, road-wheel rate limit 0.4 rad/s).
    """

    wheelbase_m: float = 2.579  # CommonRoad vehicle 2: a + b = 1.156 + 1.423
    width_m: float = 1.61  # CommonRoad vehicle 2: w
    steering_ratio: float = 15.0  # assumed: typical passenger-car rack (14-16:1); CommonRoad gives none
    max_road_wheel_angle_rad: float = 1.066  # CommonRoad vehicle 2: steering.max
    max_road_wheel_rate_rad_s: float = 0.4  # CommonRoad vehicle 2: steering.v_max
    steering_time_constant_s: float = 0.05  # assumed: electric power-steering position loop
    max_accel_mps2: float = 3.0  # assumed comfort limit (CommonRoad's 11.5 m/s^2 is the tyre limit)
    max_decel_mps2: float = 8.0  # assumed: about 0.8 g braking

    def __post_init__(self) -> None:
        require_in_range("wheelbase_m", self.wheelbase_m, 0.5, 15.0, "m")
        require_in_range("width_m", self.width_m, 0.5, 4.0, "m")
        require_in_range("steering_ratio", self.steering_ratio, 1.0, 60.0)
        require_in_range("max_road_wheel_angle_rad", self.max_road_wheel_angle_rad, 0.01, 1.5, "rad")
        require_positive("max_road_wheel_rate_rad_s", self.max_road_wheel_rate_rad_s)
        require_in_range("steering_time_constant_s", self.steering_time_constant_s, 1e-3, 2.0, "s")
        require_positive("max_accel_mps2", self.max_accel_mps2)
        require_positive("max_decel_mps2", self.max_decel_mps2)


@njit(cache=True)
def _rhs(state, p, delta_cmd, accel, out):  # pragma: no cover - compiled
    yaw, v, delta = state[2], state[3], state[4]
    out[0] = v * math.cos(yaw)
    out[1] = v * math.sin(yaw)
    out[2] = v * math.tan(delta) / p[0]
    out[3] = realised_accel(v, accel)
    out[4] = road_wheel_rate(delta_cmd, delta, p[3], p[2])


@njit(cache=True)
def _advance(state, p, delta_cmd, accel, h, n):  # pragma: no cover - compiled
    return rk4(_rhs, state, p, delta_cmd, accel, h, n)


class KinematicBicycle(CompiledVehicleModel[KinematicBicycleParams]):
    """The kinematic bicycle with a first-order, rate-limited steering actuator, registered as
    "kinematic-bicycle": no tyre slip (module docstring for its equations and states).

    Parameters
    ----------
    params : KinematicBicycleParams or None
        The model's parameters (None: the dataclass's defaults); `make_vehicle` builds the model from its preset
        or a vehicle file instead.
    """

    name: ClassVar[str] = "kinematic-bicycle"
    state_names: ClassVar[tuple[str, ...]] = ("x_m", "y_m", "yaw_rad", "speed_mps", "road_wheel_angle_rad")

    _advance_kernel = staticmethod(_advance)

    def __init__(self, params: KinematicBicycleParams | None = None) -> None:
        self.params = params or KinematicBicycleParams()
        p = self.params
        self._p = np.array(
            [p.wheelbase_m, p.max_road_wheel_angle_rad, p.max_road_wheel_rate_rad_s, p.steering_time_constant_s]
        )
        self._geometry = VehicleGeometry.from_params(p, p.wheelbase_m)

    def outputs(self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> np.ndarray:
        """STANDARD_OUTPUTS from the state alone: no slip, so the lateral speed is zero and the yaw rate is
        v tan(delta) / L.

        Parameters
        ----------
        state : numpy.ndarray
            The state, one value per name of `state_names`.
        steer_wheel_cmd_rad : float
            Steering-wheel angle command in force (rad), for the outputs that depend on the inputs.
        accel_cmd_mps2 : float
            Longitudinal acceleration command in force (m/s^2).

        Returns
        -------
        numpy.ndarray
            One value per name of `output_names`, SI units.
        """
        x, y, yaw, v, delta = state
        yaw_rate = v * math.tan(delta) / self.params.wheelbase_m
        return np.array([x, y, yaw, v, 0.0, yaw_rate, delta * self.params.steering_ratio, delta, v * yaw_rate])

    def single_track(self, source: str | None = None) -> PredictionParams:
        """The kinematic single track with this model's actuator (no tyres).

        Parameters
        ----------
        source : str or None
            Where the numbers come from, for messages and reports (None: this model's parameters).

        Returns
        -------
        PredictionParams
            The geometry, the steering actuator and no tyres (the kinematic prediction kinds only): what the MPC
            controllers predict with.
        """
        p = self.params
        return PredictionParams.from_actuator(p, p.wheelbase_m, source or f"the {self.name} model's parameters")


__all__ = ["KinematicBicycle", "KinematicBicycleParams"]
