"""Curvature limits from rollover: the step-steer series of the paper's section 4 (Figure 6).

For each speed, steering-wheel steps of growing size are applied from straight running at that speed (held: no
acceleration command) for `duration_s`; the step size is bisected for the smallest step whose load transfer ratio
(the model's `ltr` output: max over axle groups of |LTR|, 1 = wheel lift-off) reaches 1. The limit is the
curvature of the rear-axle path (the model's `path_curvature_1pm` output) at the moment LTR first reaches 1 in that
step (the kinematic curvature of the step, tan(steer / ratio) / wheelbase, is also reported). Where even the
steering lock does not lift a wheel (low speed), the limit is the path curvature the lock reaches at the end of
the step, marked "steering lock".

The clothoid controller reads the result as its curvature saturation (`CurvatureLimits`, the limits CSV); the
curvature-rate column is the default one from the vehicle's steering-rate limit (`CurvatureLimits.default_for`).
Loaded truck: 0.040, 0.016, 0.0088 1/m at 40, 60, 80 km/h, lift-off at 0.44-0.50 g of path lateral acceleration
(`tests/tuning/test_rollover.py`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.clothoid.curvature_limits import CurvatureLimits
from tuning.speeds import check_speeds
from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.base import VehicleModel

LTR_OUTPUT = "ltr"
PATH_CURVATURE_OUTPUT = "path_curvature_1pm"
SPEED_RANGE_KMH = (1.0, 200.0)
LIMITED_BY = ("rollover", "steering lock")


@dataclass(frozen=True)
class RolloverLimit:
    """One speed of Figure 6: speed_kmh; path_curvature_1pm, the limit; kinematic_curvature_1pm, the step's
    kinematic curvature; steer_wheel_deg, the step; peak_ltr in that step; limited_by "rollover" or
    "steering lock"."""

    speed_kmh: float
    path_curvature_1pm: float
    kinematic_curvature_1pm: float
    steer_wheel_deg: float
    peak_ltr: float
    limited_by: str

    @property
    def lateral_accel_g(self) -> float:
        """Path curvature x speed^2 in g."""
        return self.path_curvature_1pm * (self.speed_kmh / 3.6) ** 2 / G_MPS2


def _output_index(vehicle: VehicleModel, name: str) -> int:
    try:
        return vehicle.output_names.index(name)
    except ValueError:
        raise WorkbenchInputError(
            f"vehicle {vehicle.name!r} has no {name!r} output; rollover limits need a model with roll and load "
            f"transfer (tractor-semitrailer)"
        ) from None


@dataclass(frozen=True)
class StepSteer:
    """What one step steer gave: peak LTR, the path curvature when LTR first reached 1 (NaN if never), and the
    path curvature at the end."""

    peak_ltr: float
    path_curvature_at_lift_off_1pm: float
    final_path_curvature_1pm: float


def step_steer(
    vehicle: VehicleModel,
    speed_kmh: float,
    kinematic_curvature_1pm: float,
    duration_s: float = 6.0,
    dt_s: float = 0.02,
    substeps: int = 20,
) -> StepSteer:
    """A steering-wheel step sized for `kinematic_curvature_1pm` at t = 0 from straight running at speed_kmh."""
    i_ltr, i_kappa = _output_index(vehicle, LTR_OUTPUT), _output_index(vehicle, PATH_CURVATURE_OUTPUT)
    state = vehicle.initial_state(0.0, 0.0, 0.0, speed_kmh / 3.6)
    steer = vehicle.geometry.steer_wheel_for_curvature(kinematic_curvature_1pm)
    peak, at_one, out = 0.0, math.nan, None
    for _ in range(round(duration_s / dt_s)):
        state = vehicle.advance(state, steer, 0.0, dt_s, substeps)
        out = vehicle.outputs(state, steer, 0.0)
        if out[i_ltr] >= 1.0 and math.isnan(at_one):
            at_one = float(out[i_kappa])
        peak = max(peak, float(out[i_ltr]))
    assert out is not None
    return StepSteer(peak, at_one, float(out[i_kappa]))


def rollover_limit(
    vehicle: VehicleModel, speed_kmh: float, bisections: int = 14, duration_s: float = 6.0
) -> RolloverLimit:
    """Bisect the step between straight and the steering lock for the smallest step that lifts a wheel."""
    require_in_range("speed_kmh", speed_kmh, *SPEED_RANGE_KMH, "km/h")
    geometry = vehicle.geometry
    lock = math.tan(geometry.max_road_wheel_angle_rad) / geometry.wheelbase_m
    at_lock = step_steer(vehicle, speed_kmh, lock, duration_s)
    if at_lock.peak_ltr < 1.0:
        return RolloverLimit(
            float(speed_kmh),
            abs(at_lock.final_path_curvature_1pm),
            lock,
            math.degrees(geometry.max_steer_wheel_angle_rad),
            at_lock.peak_ltr,
            "steering lock",
        )
    lo, hi, hi_result = 0.0, lock, at_lock
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        result = step_steer(vehicle, speed_kmh, mid, duration_s)
        if result.peak_ltr >= 1.0:
            hi, hi_result = mid, result
        else:
            lo = mid
    return RolloverLimit(
        float(speed_kmh),
        abs(hi_result.path_curvature_at_lift_off_1pm),
        hi,
        math.degrees(geometry.steer_wheel_for_curvature(hi)),
        hi_result.peak_ltr,
        "rollover",
    )


def rollover_limits(vehicle: VehicleModel, speeds_kmh: Sequence[float], bisections: int = 14) -> list[RolloverLimit]:
    """rollover_limit at each speed (km/h, strictly increasing)."""
    speeds = check_speeds(speeds_kmh, *SPEED_RANGE_KMH)
    _output_index(vehicle, LTR_OUTPUT)
    _output_index(vehicle, PATH_CURVATURE_OUTPUT)
    return [rollover_limit(vehicle, s, bisections) for s in speeds]


def to_curvature_limits(limits: Sequence[RolloverLimit], vehicle: VehicleModel) -> CurvatureLimits:
    """The limits table the clothoid controller reads; the rate column from the vehicle's steering-rate limit."""
    rate = CurvatureLimits.default_for(vehicle.geometry).max_curvature_rate_1pm_s[0]
    return CurvatureLimits(
        tuple(lim.speed_kmh for lim in limits),
        tuple(lim.path_curvature_1pm for lim in limits),
        tuple([rate] * len(limits)),
        source=f"tuning rollover-limits ({vehicle.name})",
    )


def table(limits: Sequence[RolloverLimit]) -> str:
    """A text table of the limits, for the terminal."""
    lines = ["speed_kmh  path_curvature_1pm  kinematic_1pm  steer_wheel_deg  lat_accel_g  limited_by"]
    lines += [
        f"{lim.speed_kmh:9.1f}  {lim.path_curvature_1pm:18.5f}  {lim.kinematic_curvature_1pm:13.5f}  "
        f"{lim.steer_wheel_deg:15.1f}  {lim.lateral_accel_g:11.3f}  {lim.limited_by}"
        for lim in limits
    ]
    return "\n".join(lines)


__all__ = ["LIMITED_BY", "RolloverLimit", "StepSteer", "rollover_limit", "rollover_limits", "step_steer", "table"]
