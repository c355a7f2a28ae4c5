"""A go-kart: the workbench's kinematic bicycle with a kart's dimensions, registered as `example-kart`.

An example of a vehicle model written outside the workbench: a `VehicleModel` subclass naming its `params_type`,
whose defaults are its preset. Dimensions of a rental kart (wheelbase 1.05 m, track 1.2 m; direct steering,
ratio about 3:1), assumed for the example.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from workbench.vehicles.kinematic_bicycle import KinematicBicycle, KinematicBicycleParams


@dataclass(frozen=True)
class KartParams(KinematicBicycleParams):
    """A kart's parameters (assumed for the example); the checks are the kinematic bicycle's."""

    wheelbase_m: float = 1.05
    width_m: float = 1.2
    steering_ratio: float = 3.0
    max_road_wheel_angle_rad: float = 0.5
    max_road_wheel_rate_rad_s: float = 2.0
    max_accel_mps2: float = 4.0


class Kart(KinematicBicycle):
    """A go-kart (example plugin): kinematic bicycle, 1.05 m wheelbase, 3:1 steering."""

    name: ClassVar[str] = "example-kart"
    params_type: ClassVar[type] = KartParams

    def __init__(self, params: KartParams | None = None) -> None:
        super().__init__(params or KartParams())
