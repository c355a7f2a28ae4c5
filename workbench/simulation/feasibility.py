"""Whether a vehicle can follow a path at the path's planned speed, checked before a run: where the path curves
tighter than the vehicle steers, changes its curvature faster than the vehicle's steering can follow, or asks for
more lateral acceleration than its rollover threshold or its tyres allow. A run through such a place ends with a
large CTE (or a wheel lifted); the check says where and why first. Every command refuses such a path before any
run, unless told to run it anyway, through one function with one text (`refuse_infeasible`): `workbench run`,
`compare` and `robustness` (`--allow-infeasible`) and the study specs (`study.allow_infeasible = true`).

Steering lock: the steady-state road-wheel angle a path of curvature kappa needs at speed v is
atan(L kappa) + K v^2 kappa (Ackermann at the rear axle, L the wheelbase, plus the understeer gradient K of the
vehicle's single track, `SingleTrackParams.understeer_gradient_rad_per_mps2`; 0 for a model without tyres); the
lock allows `max_road_wheel_angle_rad`. The loaded tractor-semitrailer turns a 9.19 m radius at lock at walking
pace and 9.36 m at 0.3 g (understeer), the car 1.43 m: kappa_max = tan(delta_max) / L at walking pace. No model
states an articulation limit (the tractor-semitrailer's hitch turns freely), so none is checked.
Steering rate: the road-wheel angle the path asks for (as above, signed) as a function of time at the planned
speed must not change by more than the steering's rate limit allows (`max_steer_wheel_rate_rad_s` over the
steering ratio) within any STEERING_RATE_WINDOW_S. A curvature that changes too fast for the speed (a circle
entered without a transition, two turns closer than the steering can reverse between) asks for that; a short
burst above the rate costs a lag a controller recovers from, a sustained one leaves the path. The wheels are
straight when a run starts, so a path that starts in a tight curve asks the same of the steering at once.
Rollover: v^2 kappa against the vehicle's static rollover threshold, for a model that states one (the
tractor-semitrailer's `Derived.rollover_threshold_g`, 0.45 g loaded; a dynamic manoeuvre lifts a wheel up to about
25% earlier, SAE 2003-01-3385, which this static check does not claim to catch).
Tyre grip: v^2 kappa against the single track's peak axle forces over its mass (about 1.05 g for the car, 0.80 g
for the truck), on the road of the tyre data (road-friction conditions lower it further).

The vehicle's parameters only: the simulation layer does not read the controllers' or the tuning's limits.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, overload

import numpy as np
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive

if TYPE_CHECKING:
    from workbench.base.path import ReferencePath
    from workbench.vehicles.base import VehicleModel

#: Why a place is infeasible, in the order the findings list them at one place.
STEERING_LOCK = "steering lock"
STEERING_RATE = "steering rate"
ROLLOVER = "rollover"
TYRE_GRIP = "tyre grip"
REASONS = (STEERING_LOCK, STEERING_RATE, ROLLOVER, TYRE_GRIP)
#: The steering-rate check's window (s): within any this long at the planned speed, the road-wheel angle the path
#: asks for may change by at most the rate limit times this. Measured with the planned speeds at 30 and 100 km/h
#: (the most the path asks over what the window allows): figure8, dlc, fig17 and Zandvoort 0.09-0.32 on the cars and
#: 0.11-0.38 on the loaded truck; a stadium whose 6.5 m hairpins start without a transition 0.72 (car, tracked within
#: 0.29 m by pure pursuit) and 0.76 (truck); a 3 m semicircle between straights 1.37 (car, the clothoid controller
#: 4.8 m off the path) and 1.19 (truck); two 90-degree turns 0.5 m apart 1.14 (car, 21 m off the path; the truck's
#: lock rules them out); a 3 m circle, from the straight wheels a run starts with, 1.19 (car; the clothoid controller
#: 5.1 m off the path, pure pursuit 2.8 m). Over a 1 s window the hairpins the car tracks would be 1.08: a shorter
#: window judges a lag the controllers recover from.
STEERING_RATE_WINDOW_S = 1.5
#: Two infeasible stretches of one reason closer than this along the path (m) are one span: a curvature that
#: dips under the limit for a few samples inside a hairpin is one place, not several.
MERGE_GAP_M = 2.0
#: A warning names at most this many places per reason, then says how many more.
MAX_PLACES_NAMED = 3
#: The command-line option that runs a path its vehicle cannot follow anyway (`refuse_infeasible`).
ALLOW_INFEASIBLE_OPTION = "--allow-infeasible"
_MPS_PER_KMH = 1.0 / 3.6


@dataclass(frozen=True)
class VehicleLimits:
    """What the check knows of a vehicle (SI units).

    name: the vehicle's name, for messages; wheelbase_m, max_road_wheel_angle_rad: as `VehicleGeometry`;
    understeer_gradient_rad_per_mps2: K in delta = L kappa + K a_y (0 for a kinematic model);
    max_lateral_accel_g: the tyres' grip (peak axle forces over the mass), None when the model has no tyres;
    rollover_threshold_g: the static rollover threshold, None when the model states none;
    max_road_wheel_rate_rad_s: how fast the steering turns the road wheels (rad/s), None: not checked.
    """

    name: str
    wheelbase_m: float
    max_road_wheel_angle_rad: float
    understeer_gradient_rad_per_mps2: float = 0.0
    max_lateral_accel_g: float | None = None
    rollover_threshold_g: float | None = None
    max_road_wheel_rate_rad_s: float | None = None

    def __post_init__(self) -> None:
        require_in_range("wheelbase_m", self.wheelbase_m, 0.5, 15.0, "m")
        require_in_range("max_road_wheel_angle_rad", self.max_road_wheel_angle_rad, 0.01, 1.5, "rad")
        require_in_range("understeer_gradient_rad_per_mps2", self.understeer_gradient_rad_per_mps2, -1.0, 1.0)
        for name in ("max_lateral_accel_g", "rollover_threshold_g", "max_road_wheel_rate_rad_s"):
            value = getattr(self, name)
            if value is not None:
                require_positive(name, value)

    @classmethod
    def of(cls, vehicle: VehicleModel) -> VehicleLimits:
        """The limits of a vehicle model: its geometry (steering lock and rate), its single track's understeer and
        grip (when it has tyres) and its static rollover threshold (the tractor-semitrailer's; a plant from an FMU's
        as its vehicle file states it)."""
        from workbench.vehicles.tractor_semitrailer import TractorSemitrailer  # loaded with any vehicle model

        geometry = vehicle.geometry
        track = vehicle.single_track().single_track
        understeer, grip = 0.0, None
        if track is not None:
            understeer = track.understeer_gradient_rad_per_mps2()
            grip = (track.front_peak_force_n + track.rear_peak_force_n) / (track.mass_kg * G_MPS2)
        from workbench.vehicles.fmu_plant import FmuPlant  # loaded with any vehicle model too

        rollover = vehicle.derived.rollover_threshold_g if isinstance(vehicle, TractorSemitrailer) else None
        if isinstance(vehicle, FmuPlant):
            rollover = vehicle.rollover_threshold_g
        rate = geometry.max_steer_wheel_rate_rad_s / geometry.steering_ratio
        return cls(
            vehicle.name, geometry.wheelbase_m, geometry.max_road_wheel_angle_rad, understeer, grip, rollover, rate
        )

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

    @overload
    def _lock_angle(self, curvature_1pm: float, speed_sq: float) -> float: ...
    @overload
    def _lock_angle(self, curvature_1pm: np.ndarray, speed_sq: float | np.ndarray) -> np.ndarray: ...
    def _lock_angle(self, curvature_1pm: float | np.ndarray, speed_sq: float | np.ndarray) -> float | np.ndarray:
        """The steady-state road-wheel angle (rad) for this curvature (1/m, >= 0) at this squared speed."""
        return np.arctan(self.wheelbase_m * curvature_1pm) + self.understeer_gradient_rad_per_mps2 * (
            speed_sq * curvature_1pm
        )

    def road_wheel_angle_rad(self, curvature_1pm: np.ndarray, speed_mps: np.ndarray) -> np.ndarray:
        """The steady-state road-wheel angle (rad, signed as the curvature) the path asks for at each sample."""
        return np.sign(curvature_1pm) * self._lock_angle(np.abs(curvature_1pm), speed_mps * speed_mps)

    def steering_rate_ratios(self, path: ReferencePath) -> tuple[np.ndarray, np.ndarray] | None:
        """What the path, at its planned speed, asks of the steering's rate over what it allows, for the window of
        STEERING_RATE_WINDOW_S starting at each sample: the most the asked road-wheel angle changes within the
        window over the rate limit times the window (> 1: infeasible); and the index of each window's last sample
        (on a closed loop counted on past the seam: index mod (n - 1)). None without a rate limit. A run starts
        with the wheels straight: the first window counts the change from a road-wheel angle of zero too (a path
        that starts in a tight curve asks the steering to wind into it at once)."""
        if self.max_road_wheel_rate_rad_s is None:
            return None
        speed = path.planned_speed_mps
        angle = self.road_wheel_angle_rad(path.curvature_1pm, speed)
        step_s = np.diff(path.s_m) / (0.5 * (speed[1:] + speed[:-1]))
        n = angle.size
        if path.closed:  # once more round the loop (its last sample repeats the first), for windows past the seam
            angle = np.concatenate((angle, angle[1:]))
            step_s = np.concatenate((step_s, step_s))
        t_s = np.concatenate(([0.0], np.cumsum(step_s)))
        last = np.searchsorted(t_s, t_s[:n] + STEERING_RATE_WINDOW_S, side="right") - 1
        first = np.arange(n)
        high, low = _range_extremes(angle, first, last)
        change = np.maximum(high - angle[:n], angle[:n] - low)
        change[0] = max(change[0], high[0], -low[0])  # a run starts with the wheels straight
        return change / (self.max_road_wheel_rate_rad_s * STEERING_RATE_WINDOW_S), last

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
    end_s_m < start_s_m); s_m: its worst point, the one that asks most over the limit (for the steering rate: the
    start of its worst window); radius_m: the path's radius there (the tightest in that window); min_radius_m: the
    smallest radius the vehicle holds there, at speed_kmh, the planned speed (None for the steering rate, which
    limits how fast the curvature changes, not how tight it is); reason: one of REASONS; demand_ratio: what the
    path asks there over what the vehicle allows (> 1), None when not known.
    """

    start_s_m: float
    end_s_m: float
    s_m: float
    radius_m: float
    min_radius_m: float | None
    speed_kmh: float
    reason: str
    demand_ratio: float | None = None

    def __post_init__(self) -> None:
        if self.reason not in REASONS:
            raise WorkbenchInputError(f"reason must be one of {', '.join(REASONS)}; got {self.reason!r}")
        for name in ("radius_m", "min_radius_m", "demand_ratio"):
            if name == "radius_m" or getattr(self, name) is not None:
                require_positive(name, getattr(self, name))

    def to_dict(self) -> dict[str, object]:
        """The span as metrics.json writes it (numbers rounded to the centimetre, 0.01 of the ratio and 0.1 km/h)."""
        row = asdict(self)
        return {
            k: round(v, 2 if k.endswith("_m") or k == "demand_ratio" else 1) if isinstance(v, float) else v
            for k, v in row.items()
        }


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
                    demand_ratio=float(ratio[index]),
                )
            )
    spans += _steering_rate_spans(path, limits)
    return tuple(sorted(spans, key=lambda span: (span.start_s_m, REASONS.index(span.reason))))


def _steering_rate_spans(path: ReferencePath, limits: VehicleLimits) -> list[InfeasibleSpan]:
    """The spans where the path's curvature changes faster than the steering follows at the planned speed
    (`VehicleLimits.steering_rate_ratios`): from the first window over the limit to the end of the last."""
    rated = limits.steering_rate_ratios(path)
    if rated is None:
        return []
    ratio, window_end = rated
    wrap = ratio.size - 1 if path.closed else ratio.size  # a closed loop's last sample repeats the first
    spans: list[InfeasibleSpan] = []
    for first, last in _stretches(ratio > 1.0, path):
        index = _worst(ratio, first, last)
        window = np.arange(index, window_end[index] + 1) % wrap
        speed = float(path.planned_speed_mps[index])
        span = InfeasibleSpan(
            start_s_m=float(path.s_m[first]),
            end_s_m=float(path.s_m[int(window_end[last]) % wrap]),
            s_m=float(path.s_m[index]),
            radius_m=1.0 / max(float(np.max(np.abs(path.curvature_1pm[window]))), 1e-12),
            min_radius_m=None,
            speed_kmh=speed / _MPS_PER_KMH,
            reason=STEERING_RATE,
            demand_ratio=float(ratio[index]),
        )
        previous = spans[-1] if spans else None
        if previous is not None and previous.start_s_m <= span.start_s_m <= previous.end_s_m:  # windows overlap
            worst = previous if (previous.demand_ratio or 0.0) >= (span.demand_ratio or 0.0) else span
            span = dataclasses.replace(worst, start_s_m=previous.start_s_m, end_s_m=span.end_s_m)
            spans.pop()
        spans.append(span)
    return spans


def _range_extremes(values: np.ndarray, first: np.ndarray, last: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The largest and the smallest of values[first[i] : last[i] + 1] for each i (first <= last), by doubling:
    at level k the extremes of every run of 2^k values, each query answered from the two runs that cover it, so
    O(n log w) time for windows of up to w values and two levels' memory."""
    length = last - first + 1
    level_of = np.frexp(length.astype(float))[1] - 1  # floor(log2(length)), exact for whole numbers
    high, low = np.empty(first.size), np.empty(first.size)
    run_max, run_min, level, width = values, values, 0, 1
    while True:
        asked = np.flatnonzero(level_of == level)
        if asked.size:
            a, b = first[asked], last[asked] - width + 1
            high[asked] = np.maximum(run_max[a], run_max[b])
            low[asked] = np.minimum(run_min[a], run_min[b])
        if 2 * width > length.max():
            return high, low
        run_max = np.maximum(run_max[:-width], run_max[width:])
        run_min = np.minimum(run_min[:-width], run_min[width:])
        level, width = level + 1, 2 * width


def check_path(path: ReferencePath, vehicle: VehicleModel) -> tuple[InfeasibleSpan, ...]:
    """`infeasible_spans` of the path (carrying its planned speed) for this vehicle model's limits."""
    return infeasible_spans(path, VehicleLimits.of(vehicle))


def path_feasibility_warnings(path: ReferencePath, vehicle: VehicleModel) -> list[str]:
    """`feasibility_warnings` of the path (carrying its planned speed) for this vehicle model: empty when the
    vehicle can follow all of it."""
    limits = VehicleLimits.of(vehicle)
    return feasibility_warnings(path.name, limits, infeasible_spans(path, limits))


def refuse_infeasible(warnings: Sequence[str], allow: str = ALLOW_INFEASIBLE_OPTION, about: str = "") -> None:
    """Refuse a run on a path its vehicle cannot follow at the planned speed, before any run starts: a
    WorkbenchInputError of one line, `about` (what is refused, e.g. a spec key, a file, a vehicle and a speed; ""
    for nothing) then each distinct warning of `feasibility_warnings` (the path, the vehicle, the places with s in m
    and the limit) joined by '; ', ending with '; `allow` runs it anyway'. Nothing when `warnings` is empty. The one
    refusal of `workbench run`, `compare`, `robustness` and the study specs, so that each says the same."""
    if not warnings:
        return
    prefix = f"{about}: " if about else ""
    raise WorkbenchInputError(f"{prefix}{'; '.join(dict.fromkeys(warnings))}; {allow} runs it anyway")


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
        elif reason == STEERING_RATE:
            rate = math.degrees(limits.max_road_wheel_rate_rad_s or 0.0)
            messages.append(
                f"{path_name} changes its curvature faster than the {limits.name}'s steering follows at the planned "
                f"speed (its road wheels turn at most {rate:.0f} deg/s: {rate * STEERING_RATE_WINDOW_S:.0f} deg in "
                f"any {STEERING_RATE_WINDOW_S:g} s) {where}: expect it to fall behind the path there; transitions "
                "into the curves, or turns further apart, keep it below"
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
    the vehicle holds there; for the steering rate, how many times the steering's turn in the window the path asks
    for."""
    if span.reason == STEERING_RATE:
        return (
            f"s = {span.start_s_m:.1f}-{span.end_s_m:.1f} m (the road-wheel angle asked for changes by "
            f"{span.demand_ratio or math.nan:.2f} times that at {span.speed_kmh:.0f} km/h, through a radius of "
            f"{span.radius_m:.2f} m)"
        )
    if span.reason == STEERING_LOCK:
        peak = f"{1.0 / span.radius_m:.3g} 1/m"
    else:
        peak = f"{(span.speed_kmh * _MPS_PER_KMH) ** 2 / (span.radius_m * G_MPS2):.2f} g"
    return (
        f"s = {span.start_s_m:.1f}-{span.end_s_m:.1f} m (peak {peak}), a radius of {span.radius_m:.2f} m against "
        f"a minimum of {span.min_radius_m:.2f} m at {span.speed_kmh:.0f} km/h"
    )
