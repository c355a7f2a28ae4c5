"""Smart velocity waypoint generation (Shaju, Southward & Ahmadian 2024, section 6).

The paper's reference paths carry a speed at every waypoint, computed from the (x, y) waypoints alone: local
quadratic polynomials give curvature, heading and path distance at each waypoint, the speed is capped so the
lateral acceleration stays below 0.3 g (their rollover threshold for a semi-tractor trailer), and the speeds
are then adjusted so the longitudinal acceleration and deceleration limits hold between waypoints.

Closed loops follow the convention of `workbench.base.waypoints.Waypoints`: the last point is *not* a repeat of the
first; the path returns from the last point to the first.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, ClassVar

import numpy as np
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from workbench.base.errors import WorkbenchInputError, require_finite, require_in_range, require_positive

if TYPE_CHECKING:
    import pandas as pd


@dataclass(frozen=True)
class SpeedLimits:
    """Limits the planned speed profile respects.

    max_speed_mps: top speed (m/s); max_lateral_accel_mps2: |v^2 kappa| bound (m/s^2, default 0.3 g as in the
    paper's section 6); max_accel_mps2 / max_decel_mps2: longitudinal acceleration / braking bounds (m/s^2,
    both positive); min_speed_mps: the profile never plans below this speed (m/s), not even where the lateral
    limit would ask for less.
    """

    max_speed_mps: float
    max_lateral_accel_mps2: float = 0.3 * G_MPS2
    max_accel_mps2: float = 1.0
    max_decel_mps2: float = 2.0
    min_speed_mps: float = 1.0

    def __post_init__(self) -> None:
        for field in fields(self):
            value = getattr(self, field.name)
            require_positive(f"SpeedLimits.{field.name}", value)
            object.__setattr__(self, field.name, float(value))
        if self.min_speed_mps > self.max_speed_mps:
            raise WorkbenchInputError(
                f"SpeedLimits.min_speed_mps must be <= max_speed_mps ({self.max_speed_mps!r} m/s); "
                f"got {self.min_speed_mps!r}"
            )


def _as_path(x_m: object, y_m: object) -> tuple[np.ndarray, np.ndarray]:
    """Validate waypoint coordinates: equal lengths, at least 3 points, finite."""
    x = np.asarray(x_m, dtype=float).ravel()
    y = np.asarray(y_m, dtype=float).ravel()
    if x.shape != y.shape:
        raise WorkbenchInputError(f"x_m has {x.size} points but y_m has {y.size}; they must match")
    if x.size < 3:
        raise WorkbenchInputError(f"a path needs at least 3 waypoints; got {x.size}")
    require_finite("x_m", x)
    require_finite("y_m", y)
    return x, y


def _segment_lengths(x: np.ndarray, y: np.ndarray, closed: bool) -> np.ndarray:
    """Chord length from waypoint i to i+1 (m); for closed loops the last entry is the closing segment."""
    if closed:
        x, y = np.append(x, x[0]), np.append(y, y[0])
    ds = np.hypot(np.diff(x), np.diff(y))
    repeated = np.flatnonzero(ds <= 0.0)
    if repeated.size:
        i = int(repeated[0])
        j = (i + 1) % ds.size
        raise WorkbenchInputError(
            f"waypoints {i} and {j} repeat the same point ({float(x[i])!r}, {float(y[i])!r}); "
            "consecutive waypoints must differ"
        )
    return ds


def _quadratic_fit(dx: np.ndarray, dy: np.ndarray, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares w = a u^2 + b u + c per row, in the frame rotated by theta (u forward, w to the left).

    dx, dy: offsets of the window points from the waypoint, one row per waypoint; returns (a, b) at u = 0.
    pinv keeps degenerate windows (fewer than 3 distinct u) finite.
    """
    cos_t, sin_t = np.cos(theta)[:, None], np.sin(theta)[:, None]
    u = cos_t * dx + sin_t * dy
    w = -sin_t * dx + cos_t * dy
    design = np.stack((u**2, u, np.ones_like(u)), axis=-1)
    a, b, _ = np.einsum("nij,nj->ni", np.linalg.pinv(design), w).T
    return a, b


def local_quadratic_geometry(
    x_m: object, y_m: object, closed: bool, half_window: int = 2
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Path distance, heading and curvature at every waypoint from local quadratic fits (paper, section 6).

    Around waypoint i the 2*half_window+1 neighbouring points are expressed in a frame centred at the waypoint
    and rotated to the local chord (from the previous to the next waypoint), u forward and w to the left; a
    least-squares quadratic w = a u^2 + b u + c gives heading = chord angle + atan(b) and curvature
    kappa = 2a / (1 + b^2)^1.5 at u = 0. Closed loops wrap the window across the seam; open paths shift it
    inwards at the ends.

    Returns (s_m, heading_rad, curvature_1pm): cumulative chord distance from the first waypoint (m), heading
    in (-pi, pi] (rad, from +x towards +y) and curvature (1/m, left turns positive). A parabola is not a
    circle: on arcs |kappa| comes out too large by O((kappa * window length)^2), for a 20 m radius ~0.6 % at
    1 m spacing and 2-8 % at 2 m (worst at the ends of open paths): the planned speed errs on the slow
    side.
    """
    x, y = _as_path(x_m, y_m)
    if isinstance(half_window, bool) or not isinstance(half_window, int) or half_window < 1:
        raise WorkbenchInputError(f"half_window must be an integer >= 1; got {half_window!r}")
    n = x.size
    ds = _segment_lengths(x, y, closed)
    s = np.concatenate(([0.0], np.cumsum(ds[: n - 1])))

    # Window indices, one row per waypoint: wrapped for loops, shifted inwards at the ends of open paths.
    h = min(half_window, (n - 1) // 2)
    offsets = np.arange(-h, h + 1)
    centre = np.arange(n)
    if closed:
        window = (centre[:, None] + offsets) % n
        prev, nxt = (centre - 1) % n, (centre + 1) % n
    else:
        start = np.clip(centre - h, 0, n - offsets.size)
        window = start[:, None] + np.arange(offsets.size)
        prev, nxt = np.maximum(centre - 1, 0), np.minimum(centre + 1, n - 1)

    # Fit in a frame centred at the waypoint and rotated to the local chord (previous -> next waypoint).
    dx, dy = x[window] - x[:, None], y[window] - y[:, None]
    scale = np.hypot(dx, dy).max(axis=1)  # > 0 (consecutive waypoints differ); conditions the fit
    chord_rad = np.arctan2(y[nxt] - y[prev], x[nxt] - x[prev])
    a, b = _quadratic_fit(dx / scale[:, None], dy / scale[:, None], chord_rad)
    curvature = 2.0 * a / scale / (1.0 + b**2) ** 1.5  # w'' scales with 1/length; the slope w' is scale-free
    heading = np.angle(np.exp(1j * (chord_rad + np.arctan(b))))
    return s, heading, curvature


class TopSpeedLimit(enum.Enum):
    """What holds a planned profile's top speed where it is: the profile's top waypoint is capped by one of these."""

    #: The top speed asked for (`SpeedLimits.max_speed_mps`) is reached.
    TARGET = "target"
    #: The lateral-acceleration bound on the curvature: the path curves even where it is fastest.
    LATERAL_ACCELERATION = "lateral acceleration"
    #: The acceleration bound: the path is too short after a slower stretch (or its start) to speed up further.
    ACCELERATION = "acceleration"
    #: The braking bound: the path is too short before a slower stretch (or its end) to brake from faster.
    BRAKING = "braking"
    #: Both: the stretch between two slower ones is too short to speed up and brake again from faster.
    ACCELERATION_AND_BRAKING = "acceleration and braking"
    #: The speeds the path's own waypoints carry (a waypoint file's speed column), below the planned ones.
    PATH_SPEED = "path speed"


@dataclass(frozen=True)
class TopSpeed:
    """A planned profile's top speed and what limited it: target_mps, the top speed asked for (m/s); top_mps, the
    planned top (m/s); s_m, where along the path it is (m); limit, what holds it there; limits, the bounds it was
    planned with."""

    target_mps: float
    top_mps: float
    s_m: float
    limit: TopSpeedLimit
    limits: SpeedLimits

    #: A top within this fraction of the target counts as reaching it.
    REACHED_TOLERANCE: ClassVar[float] = 1e-3

    @property
    def reached(self) -> bool:
        """The planned top is the target (within REACHED_TOLERANCE)."""
        return self.top_mps >= self.target_mps * (1.0 - self.REACHED_TOLERANCE)

    def reason(self) -> str:
        """What limited the top speed, in words with the bounds' values."""
        lim = self.limits
        lateral = f"the lateral-acceleration bound of {lim.max_lateral_accel_mps2 / G_MPS2:.3g} g"
        if self.limit is TopSpeedLimit.TARGET:
            return "the target speed"
        if self.limit is TopSpeedLimit.LATERAL_ACCELERATION:
            return f"{lateral} on the path's curvature, which curves even where it is fastest"
        if self.limit is TopSpeedLimit.ACCELERATION:
            return f"the acceleration bound of {lim.max_accel_mps2:g} m/s^2 after the curves slowed by {lateral}"
        if self.limit is TopSpeedLimit.BRAKING:
            return f"the braking bound of {lim.max_decel_mps2:g} m/s^2 before the curves ahead, slowed by {lateral}"
        if self.limit is TopSpeedLimit.ACCELERATION_AND_BRAKING:
            return (
                f"the acceleration and braking bounds ({lim.max_accel_mps2:g} and {lim.max_decel_mps2:g} m/s^2) "
                f"between the curves slowed by {lateral}"
            )
        return "the speeds the path's waypoints carry"

    def describe(self) -> str:
        """E.g. "target 200 km/h, planned top 69.6 km/h at s = 0 m (limited by ...)"."""
        return (
            f"target {self.target_mps * 3.6:.4g} km/h, planned top {self.top_mps * 3.6:.3g} km/h at s = "
            f"{self.s_m:.0f} m (limited by {self.reason()})"
        )


@dataclass(frozen=True)
class SpeedProfile:
    """Planned speed at every waypoint.

    s_m: path distance of each waypoint (m); speed_mps: planned speed (m/s); curvature_1pm: estimated
    curvature (1/m, left positive); closed: the path is a loop; limits: the limits it was planned for;
    length_m: total path length (m), for loops including the segment from the last waypoint back to the
    first; top_limit: what holds the top speed (`TopSpeedLimit`; `top_speed()`).
    """

    s_m: np.ndarray
    speed_mps: np.ndarray
    curvature_1pm: np.ndarray
    closed: bool
    limits: SpeedLimits
    length_m: float
    top_limit: TopSpeedLimit = TopSpeedLimit.TARGET

    _ARRAYS: ClassVar[tuple[str, ...]] = ("s_m", "speed_mps", "curvature_1pm")

    def __post_init__(self) -> None:
        arrays = {name: np.asarray(getattr(self, name), dtype=float).ravel() for name in self._ARRAYS}
        sizes = {arr.size for arr in arrays.values()}
        if len(sizes) != 1:
            raise WorkbenchInputError(
                "SpeedProfile arrays must have the same length; got "
                + ", ".join(f"{name}: {arr.size}" for name, arr in arrays.items())
            )
        for name, arr in arrays.items():
            require_finite(f"SpeedProfile.{name}", arr)
            object.__setattr__(self, name, arr)
        require_in_range("SpeedProfile.length_m", self.length_m, float(arrays["s_m"][-1]), math.inf, "m")
        if not isinstance(self.top_limit, TopSpeedLimit):
            raise WorkbenchInputError(f"SpeedProfile.top_limit must be a TopSpeedLimit; got {self.top_limit!r}")

    def top_speed(self) -> TopSpeed:
        """The planned top speed, where it is and what limited it."""
        i = int(np.argmax(self.speed_mps))
        return TopSpeed(
            self.limits.max_speed_mps, float(self.speed_mps[i]), float(self.s_m[i]), self.top_limit, self.limits
        )

    def speed_at(self, s_m: float | np.ndarray) -> float | np.ndarray:
        """Planned speed (m/s) at path distance s_m (m), linearly interpolated between waypoints.

        Closed loops wrap s_m modulo length_m (interpolating across the seam); open paths hold the first and
        last speed outside [0, length_m].
        """
        s = np.asarray(s_m, dtype=float)
        require_finite("s_m", s)
        if self.closed:
            knots = np.append(self.s_m, self.length_m)
            speeds = np.append(self.speed_mps, self.speed_mps[0])
            result = np.interp(np.mod(s, self.length_m), knots, speeds)
        else:
            result = np.interp(s, self.s_m, self.speed_mps)
        return float(result) if result.ndim == 0 else result

    def to_pandas(self) -> pd.DataFrame:
        """One row per waypoint: s_m, speed_mps, curvature_1pm."""
        import pandas as pd  # not needed to plan or run a profile

        return pd.DataFrame({name: getattr(self, name) for name in self._ARRAYS})


def _forward_pass(v2_cap: np.ndarray, s: np.ndarray, accel: float) -> np.ndarray:
    """Squared speeds after w[i+1] = min(cap[i+1], w[i] + 2 a (s[i+1] - s[i])), w[0] = cap[0].

    The recurrence unrolls to w[i] = min(cap[i], min_{j<i} cap[j] + 2 a (s[i] - s[j])): a running minimum, so
    it vectorises exactly; keeping cap[i] out of the running minimum returns it bit-for-bit where it binds.
    """
    reach = np.minimum.accumulate(v2_cap - 2.0 * accel * s)
    return np.minimum(v2_cap, np.concatenate(([np.inf], 2.0 * accel * s[1:] + reach[:-1])))


def _forward_backward(v2_cap: np.ndarray, ds: np.ndarray, limits: SpeedLimits) -> tuple[np.ndarray, np.ndarray]:
    """Squared speeds under the cap after the forward (acceleration) pass, and after the backward (braking) pass
    too."""
    s = np.concatenate(([0.0], np.cumsum(ds)))
    w = _forward_pass(v2_cap, s, limits.max_accel_mps2)
    return w, _forward_pass(w[::-1], s[-1] - s[::-1], limits.max_decel_mps2)[::-1]


def _top_limit(
    v2_cap: np.ndarray, forward: np.ndarray, v2: np.ndarray, v2_max: float, closed: bool
) -> TopSpeedLimit:
    """What holds the top of a planned profile (squared speeds: the cap, after the forward pass, final) where it
    is: the target, the cap there (the lateral bound; an open path's initial or final speed asked for counts as
    that cap), or the acceleration ramp rising into it and/or the braking ramp falling from it (on waypoints the
    two ramps meet between the top and a neighbour, so the ramp into the top is looked for at it and the waypoint
    before, the ramp out of it at it and the waypoint after)."""
    i = int(np.argmax(v2))
    close = 1.0 - 1e-9
    if v2[i] >= v2_max * close:
        return TopSpeedLimit.TARGET
    if v2[i] >= v2_cap[i] * close:
        return TopSpeedLimit.LATERAL_ACCELERATION
    n = v2.size
    before, after = ((i - 1) % n, (i + 1) % n) if closed else (max(i - 1, 0), min(i + 1, n - 1))
    braking = v2 < forward * close  # the backward pass lowered these
    accelerating = (forward < v2_cap * close) & ~braking  # the forward pass holds these
    up = bool(accelerating[i] or accelerating[before])
    down = bool(braking[i] or braking[after])
    if up and down:
        return TopSpeedLimit.ACCELERATION_AND_BRAKING
    return TopSpeedLimit.BRAKING if down else TopSpeedLimit.ACCELERATION


def plan_speed_profile(
    x_m: object,
    y_m: object,
    limits: SpeedLimits,
    closed: bool = False,
    initial_speed_mps: float | None = None,
    final_speed_mps: float | None = None,
) -> SpeedProfile:
    """Smart velocity waypoints (paper, section 6): the fastest speeds within lateral and longitudinal limits.

    v_i = min(max_speed, sqrt(a_lat / |kappa_i|)), raised to min_speed where the curve is tighter than that,
    then a forward pass (v_{i+1}^2 <= v_i^2 + 2 a_acc ds) and a backward pass
    (v_i^2 <= v_{i+1}^2 + 2 a_dec ds). initial_speed_mps / final_speed_mps (m/s, within
    [min_speed, max_speed]) cap the speed at the first / last waypoint of an open path (None: no cap), e.g.
    the vehicle's current speed or a stop at min_speed. Loops are planned once around from their slowest
    waypoint, so the limits also hold across the seam.
    """
    if not isinstance(limits, SpeedLimits):
        raise WorkbenchInputError(f"limits must be a SpeedLimits; got {limits!r}")
    x, y = _as_path(x_m, y_m)
    s, _, curvature = local_quadratic_geometry(x, y, closed)
    ds = _segment_lengths(x, y, closed)
    v_min, v_max = limits.min_speed_mps, limits.max_speed_mps

    with np.errstate(divide="ignore", over="ignore"):  # straight (or nearly): no lateral limit
        v2_cap = np.minimum(v_max**2, limits.max_lateral_accel_mps2 / np.abs(curvature))
    v2_cap = np.maximum(v2_cap, v_min**2)

    if closed:
        if initial_speed_mps is not None or final_speed_mps is not None:
            raise WorkbenchInputError(
                "a closed loop has no first or last waypoint; initial_speed_mps and final_speed_mps must be "
                f"None; got {initial_speed_mps!r} and {final_speed_mps!r}"
            )
        # Neither pass can lower the slowest waypoint, so one lap starting and ending there is exact.
        order = np.roll(np.arange(x.size), -int(np.argmin(v2_cap)))
        lap_forward, lap = _forward_backward(np.append(v2_cap[order], v2_cap[order[0]]), ds[order], limits)
        v2, forward = np.empty_like(lap[:-1]), np.empty_like(lap[:-1])
        v2[order], forward[order] = lap[:-1], lap_forward[:-1]
    else:
        for name, cap, index in (
            ("initial_speed_mps", initial_speed_mps, 0),
            ("final_speed_mps", final_speed_mps, -1),
        ):
            if cap is not None:
                require_in_range(name, cap, v_min, v_max, "m/s")
                v2_cap[index] = min(v2_cap[index], float(cap) ** 2)
        forward, v2 = _forward_backward(v2_cap, ds, limits)

    length = float(s[-1] + ds[-1]) if closed else float(s[-1])
    top_limit = _top_limit(v2_cap, forward, v2, v_max**2, closed)
    return SpeedProfile(s, np.sqrt(v2), curvature, closed, limits, length, top_limit)
