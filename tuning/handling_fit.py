"""Identification of the vehicle's handling gain (`PreviewResponse.handling_gain`) from steady turns: how the
steering a steady turn takes per unit of its curvature grows with lateral acceleration.

Why. The preview responses (`tuning/preview_fit.py`) are fitted to logs at one lateral acceleration (0.2 g,
`PreviewFitOptions.lat_accel_g`). In tighter or faster corners a real vehicle's understeer grows:
its tyres leave their linear range and the load moves across the axles (for the loaded tractor-semitrailer, its
trailer's too), so it takes more steering per unit of curvature than the taps say, and the feed-forward falls short
by that much in exactly the corners that matter.

What. ISO 4138's constant-speed method: steering steps held at one speed (`schedule.handling_logs`), one per rung of
lateral acceleration; in each log's last STEADY_WINDOW_S the turn is steady when yaw rate / speed varies by at most
STEADY_TOLERANCE of its mean. Each steady turn gives its lateral acceleration (speed x yaw rate / g) and its
steering ratio (the steering's kinematic curvature over yaw rate / speed: the steady-state steering per curvature).
The ratios, interpolated linearly in lateral acceleration and held beyond the turns measured, divided by the ratio
at the lateral acceleration the taps were identified at, are the gain on `preview_model.HANDLING_GRID_G`. With
fewer than two steady turns the gain is one throughout: the taps alone.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.clothoid.preview_model import HANDLING_GAIN_RANGE, HANDLING_GRID_G
from tuning.lag_fit import SteeringGeometry, kinematic_curvature, yaw_rate_curvature
from tuning.log_file import VehicleLog
from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.geometry import VehicleGeometry

#: s: the end of each log over which the turn is taken as steady (the truck's trailer settles within ~10 s of a step).
STEADY_WINDOW_S = 3.0
#: -: the largest peak-to-peak of yaw rate / speed over the window, relative to its mean, of a steady turn.
STEADY_TOLERANCE = 0.005
#: g: the kinematic lateral accelerations of the steps `schedule.handling_logs` logs (ISO 4138's ladder).
HANDLING_LADDER_G = (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4)
#: g: two steady turns closer in lateral acceleration than this are one point (the first is kept).
MIN_POINT_SPACING_G = 0.01


@dataclass(frozen=True)
class SteadyTurn:
    """One steady turn of a step log."""

    lat_accel_g: float  # g, > 0: speed x yaw rate / g over the window
    steering_ratio: float  # -, > 0: the steering's kinematic curvature over yaw rate / speed
    sideslip_rad: float = math.nan  # rad: the rear-axle sideslip over the window, as of a left turn (NaN: no positions)


@dataclass(frozen=True)
class HandlingFit:
    """The steady turns found and the gain they give (module docstring)."""

    turns: tuple[SteadyTurn, ...]  # the steady turns used, by increasing lateral acceleration
    reference_g: float  # g: the lateral acceleration the gain is one at (the taps' identification)
    gain: tuple[float, ...]  # -: one per preview_model.HANDLING_GRID_G

    def summary(self) -> str:
        """One line for the tuning's progress.

        Returns
        -------
        str
            The number of steady turns, their range and the gain at the grid's last point.
        """
        if len(self.turns) < 2:
            return f"handling: {len(self.turns)} steady turn(s), gain one"
        return (
            f"handling: {len(self.turns)} steady turns {self.turns[0].lat_accel_g:.3g}-{self.turns[-1].lat_accel_g:.3g}"
            f" g, gain {self.gain[-1]:.4f} at {HANDLING_GRID_G[-1]:g} g"
        )


def steady_turn(log: VehicleLog, geometry: VehicleGeometry | SteeringGeometry) -> SteadyTurn | None:
    """The steady turn at the end of a step log (module docstring), or None when it is not steady there.

    Parameters
    ----------
    log : VehicleLog
        A log with yaw rate, longer than STEADY_WINDOW_S, its steering held over the window.
    geometry : VehicleGeometry or SteeringGeometry
        The wheelbase and steering ratio that give the steering's kinematic curvature.

    Returns
    -------
    SteadyTurn or None
        The turn's lateral acceleration and steering ratio, and its rear-axle sideslip when the log has positions
        and yaw (`VehicleLog.sideslip_rad`); None when yaw rate / speed varies by more than
        STEADY_TOLERANCE over the window, the steering varies there, or the vehicle does not turn.

    Raises
    ------
    WorkbenchInputError
        The log has no yaw rate or is not longer than STEADY_WINDOW_S.
    """
    if log.duration_s <= STEADY_WINDOW_S:
        raise WorkbenchInputError(
            f"{log.name}: a steady turn is read over the last {STEADY_WINDOW_S:g} s; the log lasts {log.duration_s:g} s"
        )
    window = log.t_s >= log.t_s[-1] - STEADY_WINDOW_S
    turn = yaw_rate_curvature(log)[window]  # refuses a log without yaw rate
    yaw_rate = np.asarray(log.yaw_rate_rad_s)[window]
    steering = kinematic_curvature(log.steer_wheel_rad[window], geometry)
    mean = float(np.mean(turn))
    if not (np.all(np.isfinite(turn)) and abs(mean) > 0.0):
        return None
    if np.ptp(turn) > STEADY_TOLERANCE * abs(mean) or np.ptp(steering) > 1e-9 * max(abs(float(steering[0])), 1.0):
        return None
    ratio = float(np.mean(steering)) / mean
    lat_accel_g = float(np.mean(log.speed_mps[window] * yaw_rate)) / G_MPS2
    if not (ratio > 0.0 and math.isfinite(ratio)):
        return None
    sideslip = math.nan
    if log.has_positions and log.yaw_rad is not None:
        sideslip = float(np.mean(log.sideslip_rad()[window])) * (1.0 if mean > 0.0 else -1.0)
    return SteadyTurn(abs(lat_accel_g), ratio, sideslip)


def fit_handling(
    logs: Sequence[VehicleLog], geometry: VehicleGeometry | SteeringGeometry, reference_g: float
) -> HandlingFit:
    """The handling gain of one speed's step logs (module docstring).

    Parameters
    ----------
    logs : sequence of VehicleLog
        Step logs at one held speed, with yaw rate, longer than STEADY_WINDOW_S (those that end unsteady are left
        out).
    geometry : VehicleGeometry or SteeringGeometry
        The wheelbase and steering ratio that give the steering's kinematic curvature.
    reference_g : float, g
        The lateral acceleration the preview taps were identified at, where the gain is one; in [0, 1].

    Returns
    -------
    HandlingFit
        The steady turns used and the gain on HANDLING_GRID_G (ones with fewer than two steady turns).

    Raises
    ------
    WorkbenchInputError
        reference_g out of range; a log without yaw rate or too short; a gain outside HANDLING_GAIN_RANGE (the
        steering per curvature changes more than the feed-forward can model: not a vehicle in steady turns).
    """
    require_in_range("reference_g", reference_g, 0.0, 1.0, "g")
    found = sorted(
        (turn for turn in (steady_turn(log, geometry) for log in logs) if turn is not None),
        key=lambda turn: turn.lat_accel_g,
    )
    turns: list[SteadyTurn] = []
    for turn in found:
        if not turns or turn.lat_accel_g - turns[-1].lat_accel_g >= MIN_POINT_SPACING_G:
            turns.append(turn)
    if len(turns) < 2:
        return HandlingFit(tuple(turns), float(reference_g), (1.0,) * len(HANDLING_GRID_G))
    accel = np.array([turn.lat_accel_g for turn in turns])
    ratio = np.array([turn.steering_ratio for turn in turns])
    gain = np.interp(HANDLING_GRID_G, accel, ratio) / float(np.interp(reference_g, accel, ratio))
    low, high = HANDLING_GAIN_RANGE
    if not np.all((gain >= low) & (gain <= high)):
        raise WorkbenchInputError(
            f"the handling gain (steady-state steering per curvature over its value at {reference_g:g} g) reaches "
            f"{gain.min():.3g}-{gain.max():.3g} between the steady turns at {accel.min():.3g}-{accel.max():.3g} g; "
            f"allowed {low:g}-{high:g}: check the step logs' steering and yaw rate"
        )
    return HandlingFit(tuple(turns), float(reference_g), tuple(float(v) for v in gain))


__all__ = [
    "HANDLING_LADDER_G",
    "STEADY_TOLERANCE",
    "STEADY_WINDOW_S",
    "HandlingFit",
    "SteadyTurn",
    "fit_handling",
    "steady_turn",
]
