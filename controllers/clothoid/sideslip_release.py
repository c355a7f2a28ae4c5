"""The sideslip's release over the known dead time (`SideslipRelease`, identified by `tuning/release_fit.py`): how
far the vehicle's measured sideslip is from where its lags and its steady turns put it, and how fast it returns.

Why. The delay predictor (`delay_predictor.py`) turns the course over the dead time by the sideslip rate of the
lags of Eq. 5: the steering's effect at a held speed. Braking or driving in a turn moves the sideslip too, and the
lags, identified at held speeds, know nothing of it. A vehicle's rear-axle sideslip in a steady turn grows with its
lateral acceleration (about v^2 kappa in the tyres' linear range), so braking moves the steady sideslip, and the
vehicle follows with its own dynamics: the loaded tractor-semitrailer's rear-axle sideslip, braked at 2 m/s^2 in a
0.2 g turn at 20 km/h, ends the braking 1.7 deg beyond the steady turn's at the speed it braked to, which it
reaches in 0.08 s once the braking ends; the prediction that holds it misses that turn of the course over a 0.11 s
dead time (the truck's Zandvoort hairpin exit).

What. The measured sideslip (atan2(vy, vx)) less its quasi-steady value at the lateral acceleration now (speed x
yaw rate; the rear-axle sideslip of the steady turns, `steady_sideslip_rad`) and less the lags' own transient
sideslip (`delay_predictor.lag_transient_sideslip`: what the lags' sideslip has not yet reached of its own steady
value) is the deviation the lags do not explain; in a steady turn, and wherever the lags explain the vehicle, it
is zero. It is released at the identified rate (1 / `release_time_s`) over the dead time, each part released
turning the course by as much (`delay_predictor.predicted_start`). The release moves nothing at a steady state, so
the loop analysed about a straight and an arc at a held speed (`loop_analysis.py`) is unchanged; it acts only
where the sideslip is away from its steady value for a reason the lags do not model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.clothoid.preview_model import HANDLING_GRID_G, HANDLING_STEP_G
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.path_search import PATH_SPEED, slope_at, value_at

#: s: the range an identified release time may take (below a controller period it is immediate; above, the
#: release is slower than any dead time it is predicted over).
RELEASE_TIME_RANGE_S = (1e-3, 10.0)
#: rad: the largest steady rear-axle sideslip a table may hold (20 deg: beyond, not a steady turn).
MAX_STEADY_SIDESLIP_RAD = math.radians(20.0)
#: m/s^2: the planned longitudinal acceleration, at the vehicle or one dead time on, beyond which the deviation is
#: released; where the plan holds the speed there is no push, and the deviation there is the lags' own misfit
#: (the loaded truck's lags put its steady sideslip 0.4-1 deg from its own), which the release would wrongly undo.
RELEASE_MIN_ACCEL_MPS2 = 0.3


@dataclass(frozen=True)
class SideslipRelease:
    """The sideslip's release at one speed (module docstring).

    steady_sideslip_rad: the rear-axle sideslip of a steady left turn at each lateral acceleration of
    HANDLING_GRID_G (rad, |value| <= 20 deg; zero at zero), a right turn's the opposite; release_time_s: the time
    (s, in [0.001, 10], or inf: not identified, nothing released) within which a deviation from it falls to 1/e.
    """

    steady_sideslip_rad: tuple[float, ...]  # rad: one per HANDLING_GRID_G, the first zero
    release_time_s: float = math.inf  # s: in [0.001, 10], or inf (no release)

    def __post_init__(self) -> None:
        sideslip = tuple(float(v) for v in self.steady_sideslip_rad)
        if (
            len(sideslip) != len(HANDLING_GRID_G)
            or sideslip[0] != 0.0
            or not all(abs(v) <= MAX_STEADY_SIDESLIP_RAD for v in sideslip)  # False for NaN
        ):
            raise WorkbenchInputError(
                f"steady_sideslip_rad must be {len(HANDLING_GRID_G)} sideslips (rad, at "
                f"{', '.join(f'{a:g}' for a in HANDLING_GRID_G)} g), the first 0, each within +-"
                f"{MAX_STEADY_SIDESLIP_RAD:.4g} rad (20 deg); got {list(sideslip)}"
            )
        low, high = RELEASE_TIME_RANGE_S
        time = self.release_time_s
        if isinstance(time, bool) or not isinstance(time, int | float) or not (low <= time <= high or time == math.inf):
            raise WorkbenchInputError(
                f"release_time_s must be in [{low:g}, {high:g}] s, or inf (not identified); got {value_text(time)}"
            )
        object.__setattr__(self, "steady_sideslip_rad", sideslip)
        object.__setattr__(self, "release_time_s", float(time))

    @classmethod
    def from_rate(cls, steady_sideslip_rad: tuple[float, ...], rate_1ps: object) -> SideslipRelease:
        """The release of this steady sideslip at rate_1ps (1/s, in [0.1, 1000], or 0: not identified), as a tuning
        file holds it."""
        low, high = (1.0 / t for t in RELEASE_TIME_RANGE_S[::-1])
        if (
            isinstance(rate_1ps, bool)
            or not isinstance(rate_1ps, int | float)
            or not (rate_1ps == 0.0 or low <= rate_1ps <= high)
        ):
            raise WorkbenchInputError(
                f"release_rate_1ps must be in [{low:g}, {high:g}] 1/s, or 0 (not identified); "
                f"got {value_text(rate_1ps)}"
            )
        return cls(steady_sideslip_rad, 1.0 / rate_1ps if rate_1ps else math.inf)

    @property
    def rate_1ps(self) -> float:
        """The release rate (1/s): 1 / release_time_s, 0 when not identified."""
        return 1.0 / self.release_time_s

    def row(self) -> list[float]:
        """The row of `VehicleTuning.release_table` at its speed: the release rate (1/s), then the steady sideslip
        on HANDLING_GRID_G (rad)."""
        return [self.rate_1ps, *self.steady_sideslip_rad]


@njit(cache=True)
def planned_acceleration(path: np.ndarray, record: np.ndarray, s_m: float) -> float:  # pragma: no cover - compiled
    """The path's planned longitudinal acceleration (m/s^2) at arc length s_m: speed x d(speed)/ds of its planned
    speeds (`path_search.CompiledPath`; 0 where the path plans none)."""
    shape = record[0]
    planned = path[PATH_SPEED]
    speed = value_at(planned, s_m, shape.spacing, shape.length, shape.closed)
    rate = speed * slope_at(planned, s_m, shape.spacing, shape.length, shape.closed)
    return rate if math.isfinite(rate) else 0.0


@njit(cache=True)
def steady_sideslip(row: np.ndarray, lat_accel_mps2: float) -> float:  # pragma: no cover - compiled
    """The steady rear-axle sideslip (rad) at this lateral acceleration (m/s^2; positive: a left turn) from a row of
    the release table at this speed (rate, then the sideslip on HANDLING_GRID_G): linear between the grid's points,
    in proportion beyond its last (the rear axle's sideslip grows with lateral acceleration), odd in it."""
    n = row.size - 1
    x = abs(lat_accel_mps2) / (G_MPS2 * HANDLING_STEP_G)
    if x >= n - 1:
        value = row[n] * x / (n - 1)
    else:
        i = int(x)
        value = row[1 + i] + (x - i) * (row[2 + i] - row[1 + i])
    return value if lat_accel_mps2 >= 0.0 else -value


__all__ = [
    "MAX_STEADY_SIDESLIP_RAD",
    "RELEASE_MIN_ACCEL_MPS2",
    "RELEASE_TIME_RANGE_S",
    "SideslipRelease",
    "planned_acceleration",
    "steady_sideslip",
]
