"""The vehicle's identified preview responses (`PreviewResponse`, made by `tuning/preview_fit.py`) and their use
along the path (`preview_curvature`): the steering, and the measured curvature (yaw rate / speed), of a vehicle that
drives the path exactly, as weighted sums of the path's curvature around where it is.

They stand in for the lag of Eq. 5 in the two places the clothoid controller uses a model of the vehicle along the
path rather than in its loop: the feed-forward (the steering that drives the path's curvature) and the reference
pose's curvature (`path_feedforward.py`). Both depend on the path alone, so the loop and its margins are those of
Eq. 3 and the lags (`loop_analysis.py`) whichever model they use. The controller uses them when the lag of Eq. 5
does not explain the vehicle's logs (`VehicleTuning.lag_explains_logs`; `ClothoidConfig.feedforward_model`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from controllers.clothoid.speed_tables import bracket
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.path_search import PATH_CURVATURE, value_at


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
        object.__setattr__(self, "steering_taps", steering)
        object.__setattr__(self, "measured_taps", measured)

    def same_taps(self, other: PreviewResponse) -> bool:
        """Whether other's taps are at the same times (a table over speed needs one grid)."""
        return (self.first_tap_s, self.tap_spacing_s, len(self.steering_taps)) == (
            other.first_tap_s, other.tap_spacing_s, len(other.steering_taps),
        )  # fmt: skip


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
) -> float:  # pragma: no cover - compiled
    """sum_k h_k kappa_p(s_m + V (tau_k + shift_s)) (1/m): the taps (n speeds, m taps; rows at speeds_kmh,
    interpolated linearly in speed and clamped beyond the ends, `speed_tables.bracket`) on the path's curvature
    around s_m, each tap's time taken to distance at the speed now (`path_search.CompiledPath`'s table and record)."""
    shape = record[0]
    spacing, length, closed = shape.spacing, shape.length, shape.closed
    curvature = table[PATH_CURVATURE]
    low, high, t = bracket(speeds_kmh, speed_mps * 3.6)
    total = 0.0
    for k in range(taps.shape[1]):
        tap = taps[low, k] + t * (taps[high, k] - taps[low, k])
        s = s_m + speed_mps * (first_tap_s + k * tap_spacing_s + shift_s)
        total += tap * value_at(curvature, s, spacing, length, closed)
    return total
