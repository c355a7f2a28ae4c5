"""The vehicle log: what `tuning generate-data` writes and `tuning fit-lag` / `design-lead --validate` read.

A CSV file with a header row, one row per sample, SI units with the unit in the column name (names are
case-insensitive, each column at most once, other columns are ignored):

    t_s              time (s), strictly increasing; uniform sampling is best, jitter is resampled (see below)
    steer_wheel_deg  steering-wheel angle (deg), the steering sensor
    speed_mps        speed over ground (m/s)
    x_m, y_m         position of the rear-axle centre (of the tractor) in a local metric frame (m), e.g. GPS
                     converted to east/north
    yaw_rad          heading (rad), optional for the lag fit
    yaw_rate_rad_s   yaw rate (rad/s), from an IMU; optional

Required: t_s, steer_wheel_deg, speed_mps, and either x_m and y_m (the realised path curvature, as in the paper)
or yaw_rate_rad_s (curvature = yaw rate / speed). A user's own log (GPS/IMU plus steering sensor) in these columns
is used exactly like a generated one.

Sampling: logs whose sample interval varies by more than 1% of its median are resampled (linear interpolation)
onto a uniform grid at the median interval; a gap over GAP_FACTOR median intervals, or a median rate under
MIN_SAMPLE_RATE_HZ, is refused.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from tuning.csv_columns import column_key, require_unique_columns
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.input_files import check_input_file

#: Columns `generate-data` writes, in this order.
LOG_COLUMNS = ("t_s", "steer_wheel_deg", "speed_mps", "x_m", "y_m", "yaw_rad", "yaw_rate_rad_s")
REQUIRED_COLUMNS = ("t_s", "steer_wheel_deg", "speed_mps")
POSITION_COLUMNS = ("x_m", "y_m")
YAW_RATE_COLUMN = "yaw_rate_rad_s"
OPTIONAL_COLUMNS = ("yaw_rad",)
MIN_SAMPLE_RATE_HZ = 5.0
#: A time step longer than this many median steps is a gap in the log, not jitter.
GAP_FACTOR = 5.0
#: Relative spread of the time step up to which a log counts as uniformly sampled.
UNIFORM_TOLERANCE = 0.01


@dataclass(frozen=True)
class VehicleLog:
    """One log, uniformly sampled every dt_s (s). Arrays in SI units; x_m, y_m, yaw_rad, yaw_rate_rad_s are None
    when the log does not have them. `name` names the log in messages (the file name)."""

    name: str
    t_s: np.ndarray
    steer_wheel_rad: np.ndarray
    speed_mps: np.ndarray
    x_m: np.ndarray | None = None
    y_m: np.ndarray | None = None
    yaw_rad: np.ndarray | None = None
    yaw_rate_rad_s: np.ndarray | None = None
    resampled: bool = False

    @property
    def dt_s(self) -> float:
        return float(self.t_s[1] - self.t_s[0])

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1] - self.t_s[0])

    @property
    def has_positions(self) -> bool:
        return self.x_m is not None and self.y_m is not None

    @property
    def has_yaw_rate(self) -> bool:
        return self.yaw_rate_rad_s is not None

    def __len__(self) -> int:
        return int(self.t_s.size)

    def sideslip_rad(self) -> np.ndarray:
        """The rear-axle sideslip (rad) at each sample: the course of the positions (their central differences'
        direction) less the yaw, wrapped to (-pi, pi]; a left turn's rear axle slides out, negative.

        Raises
        ------
        WorkbenchInputError
            The log has no x_m, y_m or yaw_rad.
        """
        if self.x_m is None or self.y_m is None or self.yaw_rad is None:
            raise WorkbenchInputError(
                f"{self.name}: the sideslip needs x_m, y_m (rear-axle position) and yaw_rad; the log lacks some"
            )
        course = np.arctan2(np.gradient(self.y_m, self.t_s), np.gradient(self.x_m, self.t_s))
        return np.angle(np.exp(1j * (course - self.yaw_rad)))

    @classmethod
    def from_frame(cls, frame: pd.DataFrame, name: str = "log") -> VehicleLog:
        """Validate a table in the log format (columns above) and return it, uniformly sampled. A column named twice
        is refused (`csv_columns.require_unique_columns`)."""
        require_unique_columns(frame.columns, name)
        columns = {column_key(c): c for c in frame.columns}
        missing = [c for c in REQUIRED_COLUMNS if c not in columns]
        has_xy = all(c in columns for c in POSITION_COLUMNS)
        if not has_xy and YAW_RATE_COLUMN not in columns:
            missing.append("x_m and y_m, or yaw_rate_rad_s")
        if missing:
            found = ", ".join(str(c) for c in frame.columns) or "none"
            raise WorkbenchInputError(
                f"{name}: missing column(s) {', '.join(missing)}; found {found}; a vehicle log needs "
                f"{', '.join(REQUIRED_COLUMNS)} and x_m, y_m (rear-axle position) or yaw_rate_rad_s"
            )
        wanted = [*REQUIRED_COLUMNS, *(POSITION_COLUMNS if has_xy else ())]
        wanted += [c for c in (*OPTIONAL_COLUMNS, YAW_RATE_COLUMN) if c in columns]
        values: dict[str, np.ndarray] = {}
        for col in wanted:
            raw = frame[columns[col]]
            numeric = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float)
            bad = ~np.isfinite(numeric)
            if bad.any():
                row = int(np.flatnonzero(bad)[0])
                raise WorkbenchInputError(
                    f"{name}: column {col} row {row + 1} is {value_text(raw.iloc[row])}; every value must be a finite "
                    "number (NaN, inf and text are refused: drop or fill such rows first)"
                )
            values[col] = numeric
        t = values["t_s"]
        if t.size < 2:
            raise WorkbenchInputError(f"{name}: the log has {t.size} row(s); a vehicle log needs many samples")
        steps = np.diff(t)
        if np.any(steps <= 0):
            row = int(np.flatnonzero(steps <= 0)[0]) + 1
            raise WorkbenchInputError(
                f"{name}: t_s must increase strictly; row {row + 1} has t_s = {value_text(t[row])} after "
                f"{value_text(t[row - 1])}"
            )
        dt = float(np.median(steps))
        if 1.0 / dt < MIN_SAMPLE_RATE_HZ:
            raise WorkbenchInputError(
                f"{name}: sampled at {1.0 / dt:.3g} Hz; at least {MIN_SAMPLE_RATE_HZ:g} Hz is needed to see the lag"
            )
        if steps.max() > GAP_FACTOR * dt:
            row = int(np.argmax(steps)) + 1
            raise WorkbenchInputError(
                f"{name}: a gap of {steps.max():.3g} s before row {row + 1} (t_s = {t[row]:.6g}), over "
                f"{GAP_FACTOR:g} times the median step {dt:.3g} s; split the log at the gap"
            )
        resampled = bool(np.abs(steps - dt).max() > UNIFORM_TOLERANCE * dt)
        if resampled:
            n = math.floor((t[-1] - t[0]) / dt + 1e-9) + 1
            grid = t[0] + dt * np.arange(n)
            values = {k: (grid if k == "t_s" else np.interp(grid, t, v)) for k, v in values.items()}
        elif np.abs(steps - dt).max() > 0.0:  # tiny float jitter: use the exact uniform grid
            values["t_s"] = t[0] + dt * np.arange(t.size)
        return cls(
            name=name,
            t_s=values["t_s"],
            steer_wheel_rad=np.radians(values["steer_wheel_deg"]),
            speed_mps=values["speed_mps"],
            x_m=values.get("x_m"),
            y_m=values.get("y_m"),
            yaw_rad=values.get("yaw_rad"),
            yaw_rate_rad_s=values.get(YAW_RATE_COLUMN),
            resampled=resampled,
        )


def read_log(path: str | Path) -> VehicleLog:
    """Read and validate a vehicle log CSV; WorkbenchInputError naming the file and the problem otherwise."""
    path = Path(path)
    label = f"vehicle log {str(path)!r}"
    if not os.path.lexists(path):
        raise WorkbenchInputError(f"{label} does not exist")
    check_input_file(path, label)  # a folder, a parent that is a file, not readable
    try:
        frame = pd.read_csv(path, comment="#", skipinitialspace=True)
    except OSError as exc:
        raise WorkbenchInputError(f"{label}: not readable ({exc.strerror or exc})") from None
    except (ValueError, UnicodeDecodeError) as exc:  # pandas' EmptyDataError and ParserError are ValueErrors
        raise WorkbenchInputError(f"{path.name}: not a readable CSV file ({exc})") from None
    return VehicleLog.from_frame(frame, name=path.name)
