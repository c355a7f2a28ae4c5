"""Whether a vehicle can follow a path at the path's planned speed, checked before a run: where the path curves
tighter than the vehicle steers, or asks for more lateral acceleration than its rollover threshold or its tyres
allow. A run through such a place ends with a large CTE (or a wheel lifted); the check says where and why first.

Steering lock: the steady-state road-wheel angle a path of curvature kappa needs at speed v is
atan(L kappa) + K v^2 kappa (Ackermann at the rear axle, L the wheelbase, plus the understeer gradient K of the
vehicle's single track, `SingleTrackParams.understeer_gradient_rad_per_mps2`; 0 for a model without tyres); the
lock allows `max_road_wheel_angle_rad`. The loaded tractor-semitrailer turns a 9.19 m radius at lock at walking
pace and 9.36 m at 0.3 g (understeer), the car 1.43 m.
Rollover: v^2 kappa against the vehicle's static rollover threshold, for a model that states one (the
tractor-semitrailer's `Derived.rollover_threshold_g`, 0.45 g loaded; a dynamic manoeuvre lifts a wheel up to about
25% earlier, SAE 2003-01-3385, which this static check does not claim to catch).
Tyre grip: v^2 kappa against the single track's peak axle forces over its mass (about 1.05 g for the car, 0.80 g
for the truck), on the road of the tyre data (road-friction conditions lower it further).

The vehicle's parameters only: the simulation layer does not read the controllers' or the tuning's limits.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive

if TYPE_CHECKING:
    from workbench.base.path import ReferencePath
    from workbench.vehicles.base import VehicleModel

#: Why a place is infeasible, in the order the findings list them at one place.
STEERING_LOCK = "steering lock"
ROLLOVER = "rollover"
TYRE_GRIP = "tyre grip"
REASONS = (STEERING_LOCK, ROLLOVER, TYRE_GRIP)
#: Two infeasible stretches of one reason closer than this along the path (m) are one span: a curvature that
#: dips under the limit for a few samples inside a hairpin is one place, not several.
MERGE_GAP_M = 2.0
#: A warning names at most this many places per reason, then says how many more.
MAX_PLACES_NAMED = 3
_MPS_PER_KMH = 1.0 / 3.6


@dataclass(frozen=True)
class VehicleLimits:
    """What the check knows of a vehicle (SI units).

    name: the vehicle's name, for messages; wheelbase_m, max_road_wheel_angle_rad: as `VehicleGeometry`;
    understeer_gradient_rad_per_mps2: K in delta = L kappa + K a_y (0 for a kinematic model);
    max_lateral_accel_g: the tyres' grip (peak axle forces over the mass), None when the model has no tyres;
    rollover_threshold_g: the static rollover threshold, None when the model states none.
    """

    name: str
    wheelbase_m: float
    max_road_wheel_angle_rad: float
    understeer_gradient_rad_per_mps2: float = 0.0
    max_lateral_accel_g: float | None = None
    rollover_threshold_g: float | None = None

    def __post_init__(self) -> None:
        require_in_range("wheelbase_m", self.wheelbase_m, 0.5, 15.0, "m")
        require_in_range("max_road_wheel_angle_rad", self.max_road_wheel_angle_rad, 0.01, 1.5, "rad")
        require_in_range("understeer_gradient_rad_per_mps2", self.understeer_gradient_rad_per_mps2, -1.0, 1.0)
        for name in ("max_lateral_accel_g", "rollover_threshold_g"):
            value = getattr(self, name)
            if value is not None:
                require_positive(name, value)

    @classmethod
    def of(cls, vehicle: VehicleModel) -> VehicleLimits:
        """The limits of a vehicle model: its geometry, its single track's understeer and grip (when it has tyres)
        and its static rollover threshold (the tractor-semitrailer's)."""
        from workbench.vehicles.tractor_semitrailer import TractorSemitrailer  # loaded with any vehicle model

        geometry = vehicle.geometry
        track = vehicle.single_track().single_track
        understeer, grip = 0.0, None
        if track is not None:
            understeer = track.understeer_gradient_rad_per_mps2()
            grip = (track.front_peak_force_n + track.rear_peak_force_n) / (track.mass_kg * G_MPS2)
        rollover = vehicle.derived.rollover_threshold_g if isinstance(vehicle, TractorSemitrailer) else None
        return cls(vehicle.name, geometry.wheelbase_m, geometry.max_road_wheel_angle_rad, understeer, grip, rollover)

    @property
    def lock_radius_m(self) -> float:
        """The radius of the rear axle's path at full lock at walking pace (m): L / tan(max road-wheel angle)."""
        return self.wheelbase_m / math.tan(self.max_road_wheel_angle_rad)

    def min_radius_m(self, reason: str, speed_mps: float) -> float:
        """The smallest radius (m) the vehicle holds at this speed (m/s) as far as `reason` allows."""
        v2 = speed_mps * speed_mps
        if reason == ROLLOVER and self.rollover_threshold_g is not None:
            return v2 / (self.rollover_threshold_g * G_MPS2)
        if reason == TYRE_GRIP and self.max_lateral_accel_g is not None:
            return v2 / (self.max_lateral_accel_g * G_MPS2)
        if reason != STEERING_LOCK:
            raise WorkbenchInputError(f"the {self.name} has no {reason!r} limit; reasons: {', '.join(REASONS)}")
        # The curvature at which atan(L k) + K v^2 k reaches the lock, by bisection (the angle grows with k below
        # the critical speed of an oversteering vehicle; beyond it the kinematic radius is given).
        low, high = 0.0, 4.0 / self.lock_radius_m
        if self._lock_angle(high, v2) <= self.max_road_wheel_angle_rad:
            return self.lock_radius_m
        for _ in range(60):
            middle = 0.5 * (low + high)
            below = self._lock_angle(middle, v2) < self.max_road_wheel_angle_rad
            low, high = (middle, high) if below else (low, middle)
        return 1.0 / high

    def _lock_angle(self, curvature_1pm: float | np.ndarray, speed_sq: float | np.ndarray) -> float | np.ndarray:
        """The steady-state road-wheel angle (rad) for this curvature (1/m, >= 0) at this squared speed."""
        return np.arctan(self.wheelbase_m * curvature_1pm) + self.understeer_gradient_rad_per_mps2 * (
            speed_sq * curvature_1pm
        )

    def demand_ratios(self, curvature_1pm: np.ndarray, speed_mps: np.ndarray) -> dict[str, np.ndarray]:
        """For each reason the vehicle has a limit for, what the path asks of it over what it allows (> 1:
        infeasible) at each sample: road-wheel angle over the lock, lateral acceleration over the threshold."""
        kappa = np.abs(curvature_1pm)
        v2 = speed_mps * speed_mps
        lateral_g = v2 * kappa / G_MPS2
        ratios = {STEERING_LOCK: self._lock_angle(kappa, v2) / self.max_road_wheel_angle_rad}
        if self.rollover_threshold_g is not None:
            ratios[ROLLOVER] = lateral_g / self.rollover_threshold_g
        if self.max_lateral_accel_g is not None:
            ratios[TYRE_GRIP] = lateral_g / self.max_lateral_accel_g
        return ratios


@dataclass(frozen=True)
class InfeasibleSpan:
    """A stretch of the path the vehicle cannot follow at the planned speed, for one reason.

    start_s_m, end_s_m: where it starts and ends along the path (m; on a closed loop a span across the start has
    end_s_m < start_s_m); s_m: its worst point, the one that asks most over the limit; radius_m: the path's radius
    there; min_radius_m: the smallest radius the vehicle holds there, at speed_kmh, the planned speed; reason:
    one of REASONS.
    """

    start_s_m: float
    end_s_m: float
    s_m: float
    radius_m: float
    min_radius_m: float
    speed_kmh: float
    reason: str

    def __post_init__(self) -> None:
        if self.reason not in REASONS:
            raise WorkbenchInputError(f"reason must be one of {', '.join(REASONS)}; got {self.reason!r}")
        for name in ("radius_m", "min_radius_m"):
            require_positive(name, getattr(self, name))

    def to_dict(self) -> dict[str, object]:
        """The span as metrics.json writes it (numbers rounded to the centimetre and 0.1 km/h)."""
        row = asdict(self)
        return {k: round(v, 2 if k.endswith("_m") else 1) if isinstance(v, float) else v for k, v in row.items()}


def infeasible_spans(path: ReferencePath, limits: VehicleLimits) -> tuple[InfeasibleSpan, ...]:
    """Where the path, at its planned speed, asks more of the vehicle than `limits` allow: one span per merged
    stretch and reason, sorted along the path; empty when the vehicle can follow all of it."""
    if path.speed_mps is None:
        raise WorkbenchInputError(
            f"{path.name}: checking the path against a vehicle needs its planned speed; plan it first "
            "(simulator.plan_path_speed)"
        )
    spans = []
    for reason, ratio in limits.demand_ratios(path.curvature_1pm, path.speed_mps).items():
        for first, last in _stretches(ratio > 1.0, path):
            index = _worst(ratio, first, last)
            speed = float(path.speed_mps[index])
            spans.append(
                InfeasibleSpan(
                    start_s_m=float(path.s_m[first]),
                    end_s_m=float(path.s_m[last]),
                    s_m=float(path.s_m[index]),
                    radius_m=1.0 / max(abs(float(path.curvature_1pm[index])), 1e-12),
                    min_radius_m=limits.min_radius_m(reason, speed),
                    speed_kmh=speed / _MPS_PER_KMH,
                    reason=reason,
                )
            )
    return tuple(sorted(spans, key=lambda span: (span.start_s_m, REASONS.index(span.reason))))


def check_path(path: ReferencePath, vehicle: VehicleModel) -> tuple[InfeasibleSpan, ...]:
    """`infeasible_spans` of the path (carrying its planned speed) for this vehicle model's limits."""
    return infeasible_spans(path, VehicleLimits.of(vehicle))


def _stretches(over: np.ndarray, path: ReferencePath) -> list[tuple[int, int]]:
    """(first, last) sample of each run of True in `over`, runs closer than MERGE_GAP_M merged; on a closed loop a
    run through the seam (whose last sample repeats the first) is one, with last < first."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], over.astype(np.int8), [0]))))
    runs = [[int(a), int(b) - 1] for a, b in edges.reshape(-1, 2)]
    gap = max(1, round(MERGE_GAP_M / path.spacing_m))
    merged: list[list[int]] = []
    for run in runs:
        if merged and run[0] - merged[-1][1] <= gap:
            merged[-1][1] = run[1]
        else:
            merged.append(run)
    if path.closed and len(merged) > 1 and merged[-1][1] >= over.size - 1 - gap and merged[0][0] <= gap:
        across = merged.pop()  # the run into the seam continues in the first one
        merged[0][0] = across[0]
    return [(a, b) for a, b in merged]


def _worst(ratio: np.ndarray, first: int, last: int) -> int:
    """The sample of the stretch (through the seam when last < first) where the ratio is largest."""
    index = np.arange(first, last + 1) if last >= first else np.r_[first : ratio.size, 0 : last + 1]
    return int(index[np.argmax(ratio[index])])


def feasibility_warnings(path_name: str, limits: VehicleLimits, spans: tuple[InfeasibleSpan, ...]) -> list[str]:
    """One warning per reason found, naming the places (s, the path's radius, the vehicle's minimum there at the
    planned speed) and what to expect; empty when `spans` is."""
    messages = []
    for reason in REASONS:
        found = [span for span in spans if span.reason == reason]
        if not found:
            continue
        places = "; ".join(_place(span) for span in found[:MAX_PLACES_NAMED])
        more = f" and {len(found) - MAX_PLACES_NAMED} more" if len(found) > MAX_PLACES_NAMED else ""
        where = f"at {places}{more}"
        if reason == STEERING_LOCK:
            lock = math.degrees(limits.max_road_wheel_angle_rad)
            understeer = ", more at speed as it understeers" if limits.understeer_gradient_rad_per_mps2 > 1e-9 else ""
            messages.append(
                f"{path_name} curves tighter than the {limits.name} can turn at full lock ({lock:.0f} deg road-wheel "
                f"angle: a radius of {limits.lock_radius_m:.2f} m at walking pace{understeer}) {where}: expect it "
                "to run wide there"
            )
        elif reason == ROLLOVER:
            messages.append(
                f"{path_name} asks the {limits.name}, at the planned speed, for more lateral acceleration than its "
                f"static rollover threshold ({limits.rollover_threshold_g:.2f} g) {where}: expect a wheel to lift "
                "there; a lower --lat-accel-g or --speed keeps it below"
            )
        else:
            messages.append(
                f"{path_name} asks the {limits.name}, at the planned speed, for more lateral acceleration than its "
                f"tyres hold ({limits.max_lateral_accel_g:.2f} g) {where}: expect it to slide wide there; a lower "
                "--lat-accel-g or --speed keeps it below"
            )
    return messages


def _place(span: InfeasibleSpan) -> str:
    """Where a span is, what the path asks at its worst point (curvature, or lateral acceleration) and the radius
    the vehicle holds there."""
    if span.reason == STEERING_LOCK:
        peak = f"{1.0 / span.radius_m:.3g} 1/m"
    else:
        peak = f"{(span.speed_kmh * _MPS_PER_KMH) ** 2 / (span.radius_m * G_MPS2):.2f} g"
    return (
        f"s = {span.start_s_m:.1f}-{span.end_s_m:.1f} m (peak {peak}), a radius of {span.radius_m:.2f} m against "
        f"a minimum of {span.min_radius_m:.2f} m at {span.speed_kmh:.0f} km/h"
    )
