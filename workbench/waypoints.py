"""Waypoints: the raw (x, y[, speed]) points a reference path is built from, validated once."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbench.errors import WorkbenchInputError, require_finite

#: Two consecutive waypoints closer than this are "repeated" (m).
MIN_WAYPOINT_SPACING_M = 1e-6


@dataclass(frozen=True, eq=False)
class Waypoints:
    """Planar waypoints in a local east/north (x, y) frame, metres.

    x_m, y_m: positions; speed_mps: optional speed at each waypoint; closed: the path returns to its first
    point after the last (the last point is *not* repeated); source: where the points came from (a file name or a
    scenario), used in error messages and reports.
    """

    x_m: np.ndarray
    y_m: np.ndarray
    speed_mps: np.ndarray | None = None
    closed: bool = False
    source: str = "waypoints"

    def __post_init__(self) -> None:
        x = np.asarray(self.x_m, dtype=float).ravel()
        y = np.asarray(self.y_m, dtype=float).ravel()
        if x.shape != y.shape:
            raise WorkbenchInputError(f"{self.source}: x has {x.size} points but y has {y.size}; they must match")
        if x.size < 3:
            raise WorkbenchInputError(f"{self.source}: a path needs at least 3 waypoints; got {x.size}")
        require_finite(f"{self.source}: x", x)
        require_finite(f"{self.source}: y", y)
        gaps = np.hypot(np.diff(x), np.diff(y))
        if self.closed:
            gaps = np.append(gaps, np.hypot(x[0] - x[-1], y[0] - y[-1]))
        repeated = np.flatnonzero(gaps < MIN_WAYPOINT_SPACING_M)
        if repeated.size:
            i = int(repeated[0])
            j = (i + 1) % x.size
            raise WorkbenchInputError(
                f"{self.source}: waypoints {i} and {j} repeat the same point ({float(x[i])!r}, {float(y[i])!r}); "
                f"consecutive waypoints must be at least {MIN_WAYPOINT_SPACING_M} m apart"
                + (" (a closed loop must not repeat its first point at the end)" if self.closed else "")
            )
        object.__setattr__(self, "x_m", x)
        object.__setattr__(self, "y_m", y)
        if self.speed_mps is not None:
            v = np.asarray(self.speed_mps, dtype=float).ravel()
            if v.shape != x.shape:
                raise WorkbenchInputError(f"{self.source}: speed has {v.size} values but there are {x.size} waypoints")
            require_finite(f"{self.source}: speed", v)
            if (v < 0).any():
                i = int(np.flatnonzero(v < 0)[0])
                raise WorkbenchInputError(f"{self.source}: speed must be >= 0 m/s; waypoint {i} has {float(v[i])!r}")
            object.__setattr__(self, "speed_mps", v)

    def __len__(self) -> int:
        return int(self.x_m.size)
