"""Identification of the sideslip's release (`controllers.clothoid.sideslip_release.SideslipRelease`): the rear-axle
sideslip of steady turns against lateral acceleration, and how fast the sideslip returns to it after braking in a
turn.

Why. The delay predictor knows the sideslip the lags of Eq. 5 give at a held speed; braking in a turn moves the
steady sideslip (it grows with lateral acceleration) and the vehicle follows with dynamics of its own, fast or
slow, with or without overshoot (the controller's module docstring). What the controller releases, and how fast,
is the vehicle's: measured here, per speed, not chosen.

What. The steady sideslip: each steady turn of the handling logs (`handling_fit.steady_turn`, which records its
rear-axle sideslip from the positions and yaw) gives a point (lateral acceleration, sideslip); the sideslip per g is
interpolated linearly in lateral acceleration and held beyond the turns measured, times the lateral acceleration,
on `preview_model.HANDLING_GRID_G`. The release: a log of the turn at RELEASE_TURN_G held steady, braked at
`maneuvers.Braking`'s deceleration (the steering held), then held at the lower speed until the turn is steady again
(`schedule.release_log`). The push is the sideslip when the braking ends less the steady turn's at the speed it
ends at (the log's last STEADY_WINDOW_S); the release time is how long after the braking the sideslip takes to come
within 1/e of the push of that steady value (linear between samples). A push under MIN_PUSH_RAD is no push: there
is nothing to time, and the release is not identified (inf, nothing released).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from controllers.clothoid.preview_model import HANDLING_GRID_G
from controllers.clothoid.sideslip_release import RELEASE_TIME_RANGE_S, SideslipRelease
from tuning.handling_fit import STEADY_WINDOW_S, SteadyTurn
from tuning.log_file import VehicleLog
from tuning.maneuvers import Braking
from workbench.base.errors import WorkbenchInputError

#: g: the lateral acceleration of the braked turn (the feed-forward's operating point, `PreviewFitOptions`).
RELEASE_TURN_G = 0.2
#: m/s^2: the braking's deceleration (a firm service braking).
RELEASE_DECEL_MPS2 = 2.0
#: s: the braking's longest duration, and the largest fraction of the speed it may take off.
RELEASE_BRAKE_S = 1.0
RELEASE_SPEED_DROP = 0.25
#: s: the steady turn before the braking (the truck's trailer settles within ~10 s of a step), and the hold after it.
RELEASE_SETTLE_S = 20.0
RELEASE_HOLD_S = 10.0
#: rad: the smallest push that is timed (0.01 deg: below it the release moves the predicted course by less than a
#: millimetre over ten metres).
MIN_PUSH_RAD = math.radians(0.01)


@dataclass(frozen=True)
class ReleaseFit:
    """The release identified at one speed (module docstring)."""

    release: SideslipRelease  # the steady sideslip on the grid and the release time
    push_rad: float  # rad: the sideslip when the braking ends less the steady turn's after it, as of a left turn
    # (NaN: no braked log)

    def summary(self) -> str:
        """One line for the tuning's progress.

        Returns
        -------
        str
            The push and the release time, or why none was identified.
        """
        if not math.isfinite(self.push_rad):
            return "release: no braked turn"
        time = self.release.release_time_s
        timed = f"in {time:.3g} s" if math.isfinite(time) else "not timed"
        return f"release: push {math.degrees(self.push_rad):+.3g} deg {timed}"


def release_braking(speed_kmh: float) -> Braking:
    """The braking of the release log at speed_kmh (km/h): at RELEASE_DECEL_MPS2 after RELEASE_SETTLE_S, for
    RELEASE_BRAKE_S or until it has taken RELEASE_SPEED_DROP of the speed off, whichever is shorter."""
    duration = min(RELEASE_BRAKE_S, RELEASE_SPEED_DROP * speed_kmh / 3.6 / RELEASE_DECEL_MPS2)
    return Braking(RELEASE_SETTLE_S, duration, RELEASE_DECEL_MPS2)


def steady_sideslip_grid(turns: Sequence[SteadyTurn]) -> tuple[float, ...] | None:
    """The steady rear-axle sideslip (rad) on HANDLING_GRID_G from the steady turns with a sideslip (module
    docstring); None when none has one."""
    points = sorted((t.lat_accel_g, t.sideslip_rad) for t in turns if math.isfinite(t.sideslip_rad))
    if not points:
        return None
    accel = np.array([a for a, _ in points])
    per_g = np.array([b / a for a, b in points])
    grid = np.asarray(HANDLING_GRID_G)
    return tuple(float(v) for v in grid * np.interp(grid, accel, per_g))


def fit_release(turns: Sequence[SteadyTurn], log: VehicleLog | None, braking: Braking | None) -> ReleaseFit | None:
    """The sideslip's release at one speed (module docstring).

    Parameters
    ----------
    turns : sequence of SteadyTurn
        The steady turns at this speed (`handling_fit.fit_handling`'s), with their sideslip.
    log : VehicleLog or None
        The braked turn (`schedule.release_log`), with positions and yaw, its turn steady over its last
        STEADY_WINDOW_S; None: none could be driven (the turn is past the steering lock).
    braking : Braking or None
        The log's braking (None with no log).

    Returns
    -------
    ReleaseFit or None
        The steady sideslip and the release time (inf when the push is under MIN_PUSH_RAD, or does not fall to 1/e
        within the log); None when no steady turn has a sideslip.

    Raises
    ------
    WorkbenchInputError
        The log lacks positions or yaw, or ends before the braking's end plus STEADY_WINDOW_S.
    """
    grid = steady_sideslip_grid(turns)
    if grid is None:
        return None
    if log is None or braking is None:
        return ReleaseFit(SideslipRelease(grid), math.nan)
    t = log.t_s
    if t[-1] - braking.end_s <= STEADY_WINDOW_S:
        raise WorkbenchInputError(
            f"{log.name}: the braking ends at {braking.end_s:g} s and the log at {t[-1]:g} s; the steady turn after it "
            f"is read over the last {STEADY_WINDOW_S:g} s"
        )
    sideslip = log.sideslip_rad()
    final = float(np.mean(sideslip[t >= t[-1] - STEADY_WINDOW_S]))
    end = int(np.searchsorted(t, braking.end_s))
    deviation = sideslip[end:] - final
    push = float(deviation[0])
    time = math.inf
    if abs(push) >= MIN_PUSH_RAD:
        fraction = deviation / push
        within = np.flatnonzero(fraction <= math.exp(-1.0))
        if within.size:
            k = int(within[0])  # k >= 1: fraction[0] is one
            step = (fraction[k - 1] - math.exp(-1.0)) / (fraction[k - 1] - fraction[k])
            time = float(t[end + k - 1] - t[end] + step * (t[end + k] - t[end + k - 1]))
            time = max(time, RELEASE_TIME_RANGE_S[0])  # within a sample: as fast as the table allows
    left = log.yaw_rate_rad_s is None or float(np.mean(log.yaw_rate_rad_s[t >= t[-1] - STEADY_WINDOW_S])) >= 0.0
    return ReleaseFit(SideslipRelease(grid, time), push if left else -push)


__all__ = [
    "MIN_PUSH_RAD",
    "RELEASE_DECEL_MPS2",
    "RELEASE_TURN_G",
    "ReleaseFit",
    "fit_release",
    "release_braking",
    "steady_sideslip_grid",
]
