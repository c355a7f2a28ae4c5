"""Curvature limits of a vehicle without a roll model: steering lock, a lateral-acceleration bound, steering rate.

`tuning rollover-limits` needs a model with load transfer (the `ltr` output: the tractor-semitrailer); the cars have
none, so their limits come from the geometry, by the rule `CurvatureLimits.default_for` applies when a controller
has no limits file:

    max_curvature_1pm        = min(tan(max road-wheel angle) / wheelbase, a_max / v^2)
    max_curvature_rate_1pm_s = (max steering-wheel rate / steering ratio) / wheelbase

with a_max = max_lateral_accel_g (default 0.4 g, DEFAULT_LIMIT_LATERAL_ACCEL_G), at the speeds asked, so that the
table is the one the tuning chain writes for the vehicle (`tuning steering-limits`) rather than a default built on
the fly. The values at each speed equal `default_for`'s at the same speed (tests); only the speeds differ.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from controllers.clothoid.curvature_limits import DEFAULT_LIMIT_LATERAL_ACCEL_G, G_MPS2, CurvatureLimits
from tuning.speeds import check_speeds
from workbench.base.errors import require_in_range
from workbench.vehicles.geometry import VehicleGeometry

SPEED_RANGE_KMH = (1.0, 200.0)
LIMITED_BY = ("steering lock", "lateral acceleration")


@dataclass(frozen=True)
class SteeringLimit:
    """One speed: speed_kmh; max_curvature_1pm and what limits it (limited_by: "steering lock" or "lateral
    acceleration"); max_curvature_rate_1pm_s from the steering-wheel rate limit."""

    speed_kmh: float
    max_curvature_1pm: float
    max_curvature_rate_1pm_s: float
    limited_by: str

    @property
    def lateral_accel_g(self) -> float:
        """Curvature x speed^2 in g."""
        return self.max_curvature_1pm * (self.speed_kmh / 3.6) ** 2 / G_MPS2


def steering_limits(
    geometry: VehicleGeometry,
    speeds_kmh: Sequence[float],
    max_lateral_accel_g: float = DEFAULT_LIMIT_LATERAL_ACCEL_G,
) -> list[SteeringLimit]:
    """The limits at each speed (km/h, strictly increasing, 1-200); max_lateral_accel_g in (0, 2] g."""
    speeds = check_speeds(speeds_kmh, *SPEED_RANGE_KMH)
    require_in_range("max_lateral_accel_g", max_lateral_accel_g, 1e-3, 2.0, "g")
    lock = math.tan(geometry.max_road_wheel_angle_rad) / geometry.wheelbase_m
    rate = geometry.max_steer_wheel_rate_rad_s / geometry.steering_ratio / geometry.wheelbase_m
    out = []
    for speed in speeds:
        lateral = max_lateral_accel_g * G_MPS2 / (speed / 3.6) ** 2
        limited_by = LIMITED_BY[0] if lock <= lateral else LIMITED_BY[1]
        out.append(SteeringLimit(speed, min(lock, lateral), rate, limited_by))
    return out


def to_curvature_limits(
    limits: Sequence[SteeringLimit], vehicle_name: str, max_lateral_accel_g: float
) -> CurvatureLimits:
    """The limits table the clothoid controller reads (`limits_file`)."""
    return CurvatureLimits(
        tuple(lim.speed_kmh for lim in limits),
        tuple(lim.max_curvature_1pm for lim in limits),
        tuple(lim.max_curvature_rate_1pm_s for lim in limits),
        source=f"tuning steering-limits ({vehicle_name}: steering lock, {max_lateral_accel_g:g} g, steering rate)",
    )


def table(limits: Sequence[SteeringLimit]) -> str:
    """A text table of the limits, for the terminal."""
    lines = ["speed_kmh  max_curvature_1pm  max_curvature_rate_1pm_s  lat_accel_g  limited_by"]
    lines += [
        f"{lim.speed_kmh:9.1f}  {lim.max_curvature_1pm:17.5f}  {lim.max_curvature_rate_1pm_s:24.5f}  "
        f"{lim.lateral_accel_g:11.3f}  {lim.limited_by}"
        for lim in limits
    ]
    return "\n".join(lines)
