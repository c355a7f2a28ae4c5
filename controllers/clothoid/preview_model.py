"""The vehicle's identified preview responses (`PreviewResponse`, made by `tuning/preview_fit.py`) and their use
along the path (`preview_curvature`): the steering, and the measured curvature (yaw rate / speed), of a vehicle that
drives the path exactly, as weighted sums of the path's curvature around where it is.

They stand in for the lag of Eq. 5 in the two places the clothoid controller uses a model of the vehicle along the
path rather than in its loop: the feed-forward (the steering that drives the path's curvature) and the reference
pose's curvature (`path_feedforward.py`). Both depend on the path alone, so the loop and its margins are those of
Eq. 3 and the lags (`loop_analysis.py`) whichever model they use. The controller uses them when the lag of Eq. 5
does not explain the vehicle's logs (`VehicleTuning.lag_explains_logs`; `ClothoidConfig.feedforward_model`).

The taps are identified at one lateral acceleration (`tuning/schedule.py`: 0.2 g, `PreviewFitOptions.lat_accel_g`).
In a tighter or faster corner a real vehicle takes more steering per unit of curvature (its understeer grows as the
tyres and the trailer's load transfer leave their linear range; ISO 4138's steady-state circular test). The response's
handling_gain holds that growth, identified from steady turns (`tuning/handling_fit.py`): the steady-state steering
per curvature at lateral accelerations HANDLING_GRID_G, over the one at which the taps were identified. The
feed-forward scales each steering tap's term by the gain at the lateral acceleration v^2 |kappa_p| / g the vehicle
has where that tap reads the path (a static nonlinearity before the linear taps: a Hammerstein model). The measured
taps are not scaled: in a steady turn yaw rate / speed is the path's curvature at any lateral acceleration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.clothoid.speed_tables import bracket
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.path_search import PATH_CURVATURE, PATH_SPEED, value_at

#: g: the lateral accelerations (v^2 |kappa| / g) the handling gain is given at: uniform from zero, held beyond.
HANDLING_GRID_G = (0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4)
HANDLING_STEP_G = HANDLING_GRID_G[1]
#: 1/(m/s^2): grid steps per m/s^2 of lateral acceleration.
PER_GRID_STEP = 1.0 / (G_MPS2 * HANDLING_STEP_G)
#: -: the range a handling gain may take (a vehicle whose steering per curvature changes more than twofold is not
#: in a steady turn the feed-forward can model).
HANDLING_GAIN_RANGE = (0.5, 2.0)


@dataclass(frozen=True)
class PreviewResponse:
    """The preview responses at one speed: taps at tau_k = first_tap_s + k x tap_spacing_s (s, relative to the
    present; negative: the path already driven), steering_taps (h_k: the steering's kinematic curvature is
    sum_k h_k kappa_p(t + tau_k), with kappa_p the path curvature the rear axle drives) and measured_taps (g_k: yaw
    rate / speed is sum_k g_k kappa_p(t + tau_k); they sum to one)."""

    first_tap_s: float  # s, in [-30, 0]: the first tap's time
    tap_spacing_s: float  # s, in (0, 0.5]: the time between taps
    steering_taps: tuple[float, ...]  # 1/1: one per tap, finite
    measured_taps: tuple[float, ...]  # 1/1: one per tap, finite, summing to one within 1e-6
    handling_gain: tuple[float, ...] = (1.0,) * len(HANDLING_GRID_G)  # -: one per HANDLING_GRID_G, in [0.5, 2]

    def __post_init__(self) -> None:
        if not (math.isfinite(self.first_tap_s) and -30.0 <= self.first_tap_s <= 0.0):
            raise WorkbenchInputError(f"first_tap_s must be in [-30, 0] s; got {value_text(self.first_tap_s)}")
        if not (math.isfinite(self.tap_spacing_s) and 0.0 < self.tap_spacing_s <= 0.5):
            raise WorkbenchInputError(f"tap_spacing_s must be in (0, 0.5] s; got {value_text(self.tap_spacing_s)}")
        steering = tuple(float(v) for v in self.steering_taps)
        measured = tuple(float(v) for v in self.measured_taps)
        if not steering or len(steering) != len(measured):
            raise WorkbenchInputError(
                f"steering_taps and measured_taps must be as many, at least one; got {len(steering)} and "
                f"{len(measured)}"
            )
        if not all(math.isfinite(v) for v in steering + measured):
            raise WorkbenchInputError("steering_taps and measured_taps must be finite; got a NaN or infinite tap")
        if abs(sum(measured) - 1.0) > 1e-6:
            raise WorkbenchInputError(f"measured_taps must sum to one (rigid-body steady turn); got {sum(measured)!r}")
        handling = tuple(float(v) for v in self.handling_gain)
        low, high = HANDLING_GAIN_RANGE
        if len(handling) != len(HANDLING_GRID_G) or not all(low <= v <= high for v in handling):  # False for NaN
            raise WorkbenchInputError(
                f"handling_gain must be {len(HANDLING_GRID_G)} gains (at {', '.join(f'{a:g}' for a in HANDLING_GRID_G)}"
                f" g), each in [{low:g}, {high:g}]; got {list(handling)}"
            )
        object.__setattr__(self, "steering_taps", steering)
        object.__setattr__(self, "measured_taps", measured)
        object.__setattr__(self, "handling_gain", handling)

    def same_taps(self, other: PreviewResponse) -> bool:
        """Whether other's taps are at the same times (a table over speed needs one grid)."""
        return (self.first_tap_s, self.tap_spacing_s, len(self.steering_taps)) == (
            other.first_tap_s, other.tap_spacing_s, len(other.steering_taps),
        )  # fmt: skip


#: m/s: below this planned speed where the vehicle is, the plan's shape is not scaled to the measured speed (a plan
#: that stops there says nothing of the speed's level).
MIN_PLANNED_SPEED_MPS = 0.5
#: Taps per step of the march along the planned speed (`preview_curvature`): the march's reads of the plan are
#: sequential, so fewer steps keep the step fast; within a step of 4 taps (0.2 s) the position is off a straight
#: line in time by at most a dt^2 / 8 (under 1 cm at 2 m/s^2).
MARCH_TAPS = 4


@njit(cache=True)
def preview_curvature(
    table: np.ndarray,
    record: np.ndarray,
    s_m: float,
    speed_mps: float,
    shift_s: float,
    first_tap_s: float,
    tap_spacing_s: float,
    speeds_kmh: np.ndarray,
    taps: np.ndarray,
    handling: np.ndarray,
) -> float:  # pragma: no cover - compiled
    """sum_k h_k kappa_p(s_k) (1/m): the taps (n speeds, m taps; rows at speeds_kmh, interpolated linearly in speed
    and clamped beyond the ends, `speed_tables.bracket`) on the path's curvature where the vehicle is at each tap's
    time tau_k + shift_s from now, s_m being where it is now (`path_search.CompiledPath`'s table and record).

    The taps are times, the path's curvature a function of distance: s_k is reached from s_m, MARCH_TAPS taps at a
    time, at the path's planned speed (PATH_SPEED) scaled by the measured speed over the planned speed at s_m (the
    plan's shape, the speed's level now), so that a corner braked into or accelerated out of is read where the
    vehicle is at each tap's time, not at speed_mps x tau_k. Where the path carries no planned speed (NaN), or plans
    less than MIN_PLANNED_SPEED_MPS at s_m, the measured speed stands in for the plan, or the plan for the scaled
    plan.

    handling (n speeds, len(HANDLING_GRID_G) gains, or no columns: none) scales each tap's term by the gain at the
    lateral acceleration v_k^2 |kappa_p(s_k)| / g, v_k the march's speed at the tap (interpolated linearly on the
    grid, held beyond its end; module docstring)."""
    return preview_curvatures(
        table, record, s_m, speed_mps, shift_s, first_tap_s, tap_spacing_s, speeds_kmh, taps, handling, taps[:, :0]
    )[0]


@njit(cache=True)
def preview_curvatures(
    table: np.ndarray,
    record: np.ndarray,
    s_m: float,
    speed_mps: float,
    shift_s: float,
    first_tap_s: float,
    tap_spacing_s: float,
    speeds_kmh: np.ndarray,
    taps: np.ndarray,
    handling: np.ndarray,
    unscaled_taps: np.ndarray,
) -> tuple[float, float]:  # pragma: no cover - compiled
    """(`preview_curvature` of taps with handling, of unscaled_taps without) from one march along the path: both
    sums read the path's curvature at the same s_k, so the step that needs the steering's and the measured
    curvature's sums at the same taps (no known delay) reads the path once. Either taps or unscaled_taps may have no
    columns (its sum 0); both on one grid of taps and speeds."""
    shape = record[0]
    spacing, length, closed = shape.spacing, shape.length, shape.closed
    curvature, planned = table[PATH_CURVATURE], table[PATH_SPEED]
    low, high, t = bracket(speeds_kmh, speed_mps * 3.6)
    here = value_at(planned, s_m, spacing, length, closed)
    scale = speed_mps / here if here > MIN_PLANNED_SPEED_MPS else 1.0  # False for NaN
    last_past = math.floor(-(first_tap_s + shift_s) / tap_spacing_s)  # the last tap at or before now
    s_last_past = s_m + speed_mps * (first_tap_s + last_past * tap_spacing_s + shift_s)  # within one spacing
    n = max(taps.shape[1], unscaled_taps.shape[1])
    scaled, unscaled, scaling = taps.shape[1] > 0, unscaled_taps.shape[1] > 0, handling.shape[1] > 0
    total = unscaled_total = 0.0
    gains = np.empty(handling.shape[1])  # the handling gain at this speed, on HANDLING_GRID_G
    for j in range(gains.size):
        gains[j] = handling[low, j] + t * (handling[high, j] - handling[low, j])
    for direction in (1, -1):  # now and ahead, then the path already driven
        s_a, k_a = s_last_past, last_past
        v_a = _speed_at(planned, s_a, spacing, length, closed, scale, speed_mps)
        h = direction * MARCH_TAPS * tap_spacing_s
        while (k_a < n) if direction > 0 else (k_a > 0):
            # one step of the march (trapezoidal, the end's speed read where the start's speed takes it); the taps
            # within it interpolated linearly in time
            v_b = _speed_at(planned, s_a + h * v_a, spacing, length, closed, scale, speed_mps)
            s_b = s_a + 0.5 * h * (v_a + v_b)
            for i in range(MARCH_TAPS) if direction > 0 else range(1, MARCH_TAPS + 1):
                k = k_a + direction * i
                if 0 <= k < n:
                    s = s_a + (s_b - s_a) * (i / MARCH_TAPS)
                    kappa = value_at(curvature, s, spacing, length, closed)
                    if scaled:
                        term = _tap(taps, low, high, t, k) * kappa
                        if scaling:
                            v = v_a + (v_b - v_a) * (i / MARCH_TAPS)
                            term *= _handling(gains, v * v * abs(kappa) * PER_GRID_STEP)
                        total += term
                    if unscaled:
                        unscaled_total += _tap(unscaled_taps, low, high, t, k) * kappa
            s_a, v_a, k_a = s_b, v_b, k_a + direction * MARCH_TAPS
    return total, unscaled_total


@njit(cache=True)
def _speed_at(
    planned: np.ndarray, s: float, spacing: float, length: float, closed: bool, scale: float, measured_mps: float
) -> float:  # pragma: no cover - compiled
    """The speed (m/s, >= 0) the vehicle drives at arc length s: the planned speed times scale, or the measured speed
    where the plan is NaN."""
    v = value_at(planned, s, spacing, length, closed)
    return measured_mps if math.isnan(v) else max(v * scale, 0.0)


@njit(cache=True)
def _tap(taps: np.ndarray, low: int, high: int, t: float, k: int) -> float:  # pragma: no cover - compiled
    """Tap k interpolated between the rows low and high (weight t on high)."""
    return taps[low, k] + t * (taps[high, k] - taps[low, k])


@njit(cache=True)
def _handling(gains: np.ndarray, x: float) -> float:  # pragma: no cover - compiled
    """The handling gain (gains: at one speed, on HANDLING_GRID_G) at x grid steps of lateral acceleration (>= 0):
    linear on the grid, held beyond its last point."""
    i = min(int(x), gains.size - 2)
    w = min(x - i, 1.0)
    return gains[i] + w * (gains[i + 1] - gains[i])
