"""The plant interface every vehicle model implements, and what controllers may know about a vehicle.

A model is a set of ODEs x' = f(x, u) with named states, driven by two inputs: the steering-wheel angle command
(rad) and the longitudinal acceleration command (m/s^2). The simulator calls `advance` once per controller step;
a model integrates its own fine steps inside (RK4 at the plant rate, compiled with numba where it matters), so no
Python-level ODE solver runs per step.

Conventions: SI units; x east, y north, yaw counter-clockwise from x; the reference point the controllers see is
the (tractor's) rear-axle centre, where the paper measures cross-track error.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from workbench.errors import require_in_range, require_positive

#: Outputs every model provides, in this order, at the reference point (rear-axle centre).
STANDARD_OUTPUTS: tuple[str, ...] = (
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_rad_s",
    "steer_wheel_rad",
    "road_wheel_angle_rad",
    "lat_accel_mps2",
)


@dataclass(frozen=True)
class VehicleGeometry:
    """What a controller may know about the vehicle it steers.

    wheelbase_m: front axle to rear axle (group centre) of the steered unit, for Ackermann tan(phi) = L kappa;
    steering_ratio: steering-wheel angle / road-wheel angle; max_road_wheel_angle_rad and
    max_steer_wheel_rate_rad_s: actuator limits; width_m: overall width (sizes the ISO 3888 lanes).
    """

    wheelbase_m: float
    steering_ratio: float
    max_road_wheel_angle_rad: float
    max_steer_wheel_rate_rad_s: float
    width_m: float

    def __post_init__(self) -> None:
        require_in_range("wheelbase_m", self.wheelbase_m, 0.5, 15.0, "m")
        require_in_range("steering_ratio", self.steering_ratio, 1.0, 60.0)
        require_in_range("max_road_wheel_angle_rad", self.max_road_wheel_angle_rad, 0.01, 1.5, "rad")
        require_positive("max_steer_wheel_rate_rad_s", self.max_steer_wheel_rate_rad_s)
        require_in_range("width_m", self.width_m, 0.5, 4.0, "m")

    @property
    def max_steer_wheel_angle_rad(self) -> float:
        return self.max_road_wheel_angle_rad * self.steering_ratio

    def steer_wheel_for_curvature(self, curvature_1pm: float) -> float:
        """Steering-wheel angle (rad) that gives this path curvature kinematically: tan(phi) = L kappa."""
        return math.atan(self.wheelbase_m * curvature_1pm) * self.steering_ratio


class VehicleModel(ABC):
    """A plant. Subclasses set `name`, `state_names`, `extra_output_names` and implement the abstract methods.

    Extra outputs with these names are picked up by the metrics: `ltr` (load transfer ratio, max over axle
    groups, |LTR| = 1 is wheel lift-off), `trailer_x_m`/`trailer_y_m` (the trailer's rear-axle centre).
    """

    name: ClassVar[str]
    state_names: ClassVar[tuple[str, ...]]
    extra_output_names: ClassVar[tuple[str, ...]] = ()

    @property
    @abstractmethod
    def geometry(self) -> VehicleGeometry:
        """Controller-facing geometry and limits."""

    @abstractmethod
    def initial_state(self, x_m: float, y_m: float, yaw_rad: float, speed_mps: float) -> np.ndarray:
        """State at rest in steering (straight wheels), reference point at (x, y), heading yaw, moving at speed."""

    @abstractmethod
    def advance(
        self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float, dt_s: float, substeps: int
    ) -> np.ndarray:
        """Integrate `substeps` fixed steps of dt_s / substeps with the inputs held; return the new state."""

    @abstractmethod
    def outputs(self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> np.ndarray:
        """STANDARD_OUTPUTS followed by extra_output_names, as one float array."""

    @property
    def output_names(self) -> tuple[str, ...]:
        return STANDARD_OUTPUTS + self.extra_output_names

    def describe(self) -> str:
        """One line with the key parameters, for `workbench vehicles`."""
        g = self.geometry
        return (
            f"wheelbase {g.wheelbase_m:g} m, steering ratio {g.steering_ratio:g}, "
            f"max road-wheel angle {math.degrees(g.max_road_wheel_angle_rad):.0f} deg, width {g.width_m:g} m"
        )
