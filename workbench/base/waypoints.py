"""Waypoints: the raw (x, y[, speed][, track widths]) points a reference path is built from, validated once."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_finite

#: Two consecutive waypoints closer than this are "repeated" (m).
MIN_WAYPOINT_SPACING_M = 1e-6
#: Waypoints lie in a local east/north frame within this distance of its origin (m): room for UTM-sized
#: coordinates (northings reach 1e7 m), where float64 still resolves 15 nm; beyond, the spline fit overflows.
MAX_ABS_COORDINATE_M = 1e8
#: A path that turns by more than this at a single waypoint doubles back on itself (deg): the direction of
#: travel reverses there (a cusp), which no vehicle follows without stopping and reversing.
MAX_TURN_AT_WAYPOINT_DEG = 150.0
#: No vehicle follows waypoints that turn faster than this (1/m: the turn at a waypoint over the mean length of
#: the two segments beside it): a 0.5 m radius, tighter than a 1/10-scale research car's (F1TENTH: 0.33 m
#: wheelbase, 0.42 rad lock, 0.74 m). Tighter spots are zig-zags or noise in the waypoints.
MAX_WAYPOINT_CURVATURE_1PM = 2.0
#: A track edge lies at most this far from the centre line (m): far beyond any road or race track (Zandvoort's widest
#: is 8.3 m); a larger value is a unit or column mix-up (millimetres, coordinates).
MAX_TRACK_HALF_WIDTH_M = 200.0


@dataclass(frozen=True, eq=False)
class Waypoints:
    """Planar waypoints in a local east/north (x, y) frame, metres.

    x_m, y_m: positions; speed_mps: optional speed at each waypoint; closed: the path returns to its first
    point after the last (the last point is *not* repeated); source: where the points came from (a file name or a
    scenario), used in error messages and reports; width_right_m, width_left_m: optional distances (m, >= 0, both
    or neither) from each waypoint to the track's right and left edges, across the path (TUMFTM's w_tr_right_m,
    w_tr_left_m), so runs can be measured against the track and its edges drawn.
    """

    x_m: np.ndarray
    y_m: np.ndarray
    speed_mps: np.ndarray | None = None
    closed: bool = False
    source: str = "waypoints"
    width_right_m: np.ndarray | None = None
    width_left_m: np.ndarray | None = None

    def __post_init__(self) -> None:
        x = np.asarray(self.x_m, dtype=float).ravel()
        y = np.asarray(self.y_m, dtype=float).ravel()
        if x.shape != y.shape:
            raise WorkbenchInputError(f"{self.source}: x has {x.size} points but y has {y.size}; they must match")
        if x.size < 3:
            raise WorkbenchInputError(f"{self.source}: a path needs at least 3 waypoints; got {x.size}")
        for axis, values in (("x", x), ("y", y)):
            require_finite(f"{self.source}: {axis}", values)
            far = np.flatnonzero(np.abs(values) > MAX_ABS_COORDINATE_M)
            if far.size:
                i = int(far[0])
                raise WorkbenchInputError(
                    f"{self.source}: waypoint {i} has {axis} = {float(values[i]):g} m; coordinates must lie within "
                    f"+-{MAX_ABS_COORDINATE_M:g} m of the origin of a local frame (subtract an origin near the path)"
                )
        dx, dy = np.diff(x), np.diff(y)
        if self.closed:
            dx, dy = np.append(dx, x[0] - x[-1]), np.append(dy, y[0] - y[-1])
        gaps = np.hypot(dx, dy)
        repeated = np.flatnonzero(gaps < MIN_WAYPOINT_SPACING_M)
        if repeated.size:
            i = int(repeated[0])
            j = (i + 1) % x.size
            closing = self.closed and j == 0 and repeated.size == 1
            raise WorkbenchInputError(
                f"{self.source}: waypoints {i} and {j} repeat the same point ({float(x[i])!r}, {float(y[i])!r}); "
                f"consecutive waypoints must be at least {MIN_WAYPOINT_SPACING_M:g} m apart"
                + (" (a closed loop must not repeat its first point at the end)" if closing else "")
            )
        _refuse_unfollowable(dx, dy, self.closed, x, y, self.source)
        object.__setattr__(self, "x_m", x)
        object.__setattr__(self, "y_m", y)
        if self.speed_mps is not None:
            v = np.asarray(self.speed_mps, dtype=float).ravel()
            if v.shape != x.shape:
                raise WorkbenchInputError(f"{self.source}: speed has {v.size} values but there are {x.size} waypoints")
            require_finite(f"{self.source}: speed", v)
            if (v <= 0).any():
                i = int(np.flatnonzero(v <= 0)[0])
                raise WorkbenchInputError(
                    f"{self.source}: speed must be > 0 m/s at every waypoint; waypoint {i} has {float(v[i]):g} "
                    "(a run follows the path without stopping: give the speed to pass the point at, or leave the "
                    "speed column out to plan one)"
                )
            object.__setattr__(self, "speed_mps", v)
        self._check_widths(x.size)

    def _check_widths(self, n: int) -> None:
        """Both track widths or neither; each n finite values in [0, MAX_TRACK_HALF_WIDTH_M] m, stored as arrays."""
        right, left = self.width_right_m, self.width_left_m
        if (right is None) != (left is None):
            given, missing = ("right", "left") if left is None else ("left", "right")
            raise WorkbenchInputError(
                f"{self.source}: the track's {given} width is given but not its {missing} width; give both (the "
                "distances from the centre line to the right and left edges) or neither"
            )
        for side, values in (("right", right), ("left", left)):
            if values is None:
                continue
            w = np.asarray(values, dtype=float).ravel()
            if w.size != n:
                raise WorkbenchInputError(
                    f"{self.source}: the {side} track width has {w.size} values but there are {n} waypoints"
                )
            require_finite(f"{self.source}: {side} track width", w)
            bad = np.flatnonzero((w < 0.0) | (w > MAX_TRACK_HALF_WIDTH_M))
            if bad.size:
                i = int(bad[0])
                raise WorkbenchInputError(
                    f"{self.source}: the {side} track width at waypoint {i} is {float(w[i]):g} m; it must be in "
                    f"[0, {MAX_TRACK_HALF_WIDTH_M:g}] m (the distance from the centre line to that edge)"
                )
            object.__setattr__(self, f"width_{side}_m", w)

    @property
    def has_widths(self) -> bool:
        """Whether the waypoints carry the track's widths."""
        return self.width_right_m is not None

    def __len__(self) -> int:
        return int(self.x_m.size)


def _refuse_unfollowable(
    dx: np.ndarray, dy: np.ndarray, closed: bool, x: np.ndarray, y: np.ndarray, source: str
) -> None:
    """Raise WorkbenchInputError naming the waypoints where no vehicle can follow the path: where it doubles back
    on itself, and where it turns tighter than any vehicle can.

    dx, dy: the segments between consecutive waypoints (with the closing one of a loop); the turn at a waypoint is
    the angle between the segments arriving and leaving.
    """
    incoming = np.arctan2(dy, dx)
    outgoing = np.roll(incoming, -1) if closed else incoming[1:]
    incoming = incoming if closed else incoming[:-1]
    turn = np.abs((outgoing - incoming + np.pi) % (2.0 * np.pi) - np.pi)
    lengths = np.hypot(dx, dy)
    beside = 0.5 * (lengths + np.roll(lengths, -1)) if closed else 0.5 * (lengths[:-1] + lengths[1:])
    index = (np.arange(turn.size) + 1) % x.size  # the waypoint each turn happens at

    def where(mask: np.ndarray) -> str:
        hits = index[mask]
        listed = ", ".join(f"{i} ({float(x[i]):g}, {float(y[i]):g})" for i in hits[:5])
        return listed + (f" and {hits.size - 5} more" if hits.size > 5 else "")

    reversing = np.degrees(turn) > MAX_TURN_AT_WAYPOINT_DEG
    if reversing.any():
        raise WorkbenchInputError(
            f"{source}: the path doubles back on itself (turns by {np.degrees(turn[reversing][0]):.0f} deg, more "
            f"than {MAX_TURN_AT_WAYPOINT_DEG:g} deg, at one waypoint) at waypoint {where(reversing)}; a path is "
            "followed forwards: split it where it reverses"
        )
    tight = turn / beside > MAX_WAYPOINT_CURVATURE_1PM
    if tight.any():
        raise WorkbenchInputError(
            f"{source}: the waypoints turn tighter than any vehicle can (curvature {float(np.max(turn / beside)):.3g} "
            f"1/m, more than {MAX_WAYPOINT_CURVATURE_1PM:g} 1/m, a radius under {1 / MAX_WAYPOINT_CURVATURE_1PM:g} m) "
            f"at waypoint {where(tight)}: a zig-zag or noise in the waypoints; smooth or thin them there"
        )
