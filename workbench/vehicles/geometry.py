"""What a controller may know about the vehicle it steers: its geometry and steering limits (Ackermann
tan(phi) = L kappa)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from workbench.base.errors import require_in_range, require_positive


@dataclass(frozen=True)
class VehicleGeometry:
    """What a controller may know about the vehicle it steers: the wheelbase L of Ackermann's tan(phi) = L kappa,
    the steering ratio, the steering actuator's limits and the width."""

    wheelbase_m: float  # front axle to rear axle (group centre) of the steered unit (m), in [0.5, 15]
    steering_ratio: float  # steering-wheel angle / road-wheel angle, in [1, 60]
    max_road_wheel_angle_rad: float  # steering lock at the road wheels (rad), in [0.01, 1.5]
    max_steer_wheel_rate_rad_s: float  # steering-wheel rate limit of the actuator (rad/s), > 0
    width_m: float  # overall width, which sizes the ISO 3888 lanes (m), in [0.5, 4]

    def __post_init__(self) -> None:
        require_in_range("wheelbase_m", self.wheelbase_m, 0.5, 15.0, "m")
        require_in_range("steering_ratio", self.steering_ratio, 1.0, 60.0)
        require_in_range("max_road_wheel_angle_rad", self.max_road_wheel_angle_rad, 0.01, 1.5, "rad")
        require_positive("max_steer_wheel_rate_rad_s", self.max_steer_wheel_rate_rad_s)
        require_in_range("width_m", self.width_m, 0.5, 4.0, "m")

    @property
    def max_steer_wheel_angle_rad(self) -> float:
        """The steering-wheel angle at the road wheels' lock (rad): the road-wheel limit times the steering ratio."""
        return self.max_road_wheel_angle_rad * self.steering_ratio

    @classmethod
    def from_params(cls, params: Any, wheelbase_m: float) -> VehicleGeometry:
        """From a model's parameters with the usual fields (steering_ratio, max_road_wheel_angle_rad,
        max_road_wheel_rate_rad_s, width_m); the steering-wheel rate limit is the road-wheel one x the ratio.

        Parameters
        ----------
        params : object
            A model's params dataclass with ``steering_ratio``, ``max_road_wheel_angle_rad`` (rad),
            ``max_road_wheel_rate_rad_s`` (rad/s) and ``width_m`` (m).
        wheelbase_m : float
            Front axle to rear axle (group centre) of the steered unit (m, 0.5 to 15).

        Returns
        -------
        VehicleGeometry
            The geometry and steering limits a controller is built for.

        Raises
        ------
        WorkbenchInputError
            A value out of its range (the message names the field, the value and the range).
        """
        return cls(
            wheelbase_m=wheelbase_m,
            steering_ratio=params.steering_ratio,
            max_road_wheel_angle_rad=params.max_road_wheel_angle_rad,
            max_steer_wheel_rate_rad_s=params.max_road_wheel_rate_rad_s * params.steering_ratio,
            width_m=params.width_m,
        )

    def steer_wheel_for_curvature(self, curvature_1pm: float) -> float:
        """Steering-wheel angle (rad) that gives this path curvature kinematically: tan(phi) = L kappa.

        Parameters
        ----------
        curvature_1pm : float
            The path's curvature (1/m, left positive).

        Returns
        -------
        float
            The steering-wheel angle (rad, left positive), not limited to the lock.

        Examples
        --------
        >>> from workbench.vehicles import make_vehicle
        >>> geometry = make_vehicle("kinematic-bicycle").geometry
        >>> round(geometry.steer_wheel_for_curvature(1.0 / 30.0), 3)  # a 30 m radius, left
        1.286
        """
        return math.atan(self.wheelbase_m * curvature_1pm) * self.steering_ratio
