"""Reference paths parameterised by arc length, and a closest-point tracker that follows the vehicle's progress.

A `ReferencePath` is immutable: uniformly spaced samples (default every 0.1 m) of position, heading and curvature
along the arc length s (and, when its waypoints gave them, the planned speed and the track's widths). It is built
either from waypoints, through an interpolating quintic spline re-parameterised by its own arc length (so heading
and curvature are continuous and accurate even when the waypoints are unevenly spaced), or from exact samples of a
known geometry (clothoid chains, see `workbench.base.clothoid_chain`).

A `PathTracker` answers "where on the path is the vehicle?" step after step. It searches only a window around the
previous foot point, grown while the distance keeps falling at the window's edge, so the projection follows the
vehicle's progress: it never jumps to the other branch where a figure-8 crosses itself, nor across the
start/finish seam of a closed loop, and it counts laps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import overload

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from workbench.base.errors import WorkbenchInputError, require_positive
from workbench.base.path_search import (
    TRACK_OUT_SIZE,
    TRACK_PROGRESS,
    TRACK_S,
    TRACK_STATE_SIZE,
    CompiledPath,
    closest_in_window,
    first_beyond,
    slope_at,
    track,
    value_at,
)
from workbench.base.waypoints import Waypoints

#: The least window a path tracker searches each way about its last foot point (m).
DEFAULT_TRACKER_WINDOW_M = 5.0
#: Default spacing of the path's samples along s (m). Linear interpolation between samples is then exact to
#: kappa * h^2 / 8, i.e. 0.06 mm at a 20 m radius.
DEFAULT_SAMPLE_SPACING_M = 0.1
#: A path sampled into more points than this is refused: 500 km at the default 0.1 m spacing, 200 MB of samples.
MAX_PATH_SAMPLES = 5_000_000
#: Gauss-Legendre nodes used to integrate the spline's speed |r'(t)| into arc length.
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(6)
#: Degree of the interpolating spline and how often it is re-parameterised by its own arc length.
_SPLINE_DEGREE = 5
_REPARAMETERISATIONS = 2
#: A fit whose arc length over some waypoint interval exceeds this multiple of the chord is rejected as
#: oscillating (a smooth curve turning by 90 degrees between two waypoints has a ratio of 1.11).
_MAX_ARC_TO_CHORD = 1.5
#: Each re-parameterisation must shrink the mismatch between the parameter and the arc length by this factor
#: (it shrinks 50-1000x on well-behaved data), unless the mismatch is already below _MISMATCH_FLOOR.
_MIN_CONTRACTION = 0.5
_MISMATCH_FLOOR = 1e-6


def _cumulative_arc_length(spline_x: BSpline, spline_y: BSpline, t: np.ndarray) -> np.ndarray:
    """Arc length of the spline curve from t[0] to each t, by Gauss-Legendre quadrature of |r'| per interval."""
    half = 0.5 * np.diff(t)
    nodes = 0.5 * (t[:-1] + t[1:])[:, None] + half[:, None] * _GL_NODES[None, :]
    speed = np.hypot(spline_x(nodes, 1), spline_y(nodes, 1))
    return np.concatenate(([0.0], np.cumsum(half * (speed @ _GL_WEIGHTS))))


def _arc_length_spline(x: np.ndarray, y: np.ndarray, closed: bool) -> tuple[BSpline, BSpline, np.ndarray]:
    """Interpolating quintic splines x(t), y(t) whose parameter t is (nearly) the arc length.

    Starts from the chord-length parameter and refits with the knots placed at the previous fit's arc lengths.
    Against circles and clothoids sampled at uneven spacing (turning 0.02-0.3 rad between waypoints) this keeps
    the curvature within 0.7% of its maximum (0.002% in the interior of a closed circle), where a chord-length
    cubic spline errs by 2-4% (measured in tests/workbench/test_path.py).

    A quintic through very unevenly spaced waypoints (say a 5-8 m step among 1 m steps) can oscillate, and the
    re-parameterisation then diverges instead of converging. A fit is rejected when its arc length over an
    interval exceeds `_MAX_ARC_TO_CHORD` times the chord, or when re-parameterising did not shrink the mismatch
    between parameter and arc length by `_MIN_CONTRACTION`. A rejected quintic is replaced by a cubic (with
    natural end conditions on an open path: a not-a-knot cubic still bulges by metres into a long last interval),
    and the cubic keeps its last accepted fit.
    """
    chord = np.hypot(np.diff(x), np.diff(y))
    t_chord = np.concatenate(([0.0], np.cumsum(chord)))
    bc = "periodic" if closed else None
    degree = _SPLINE_DEGREE if x.size > _SPLINE_DEGREE + (1 if closed else 0) else 3 if x.size > 3 else 2
    while True:
        t, accepted, mismatch_before = t_chord, None, math.inf
        for _ in range(_REPARAMETERISATIONS + 1):
            spline_x = make_interp_spline(t, x, k=degree, bc_type=bc)
            spline_y = make_interp_spline(t, y, k=degree, bc_type=bc)
            arc = _cumulative_arc_length(spline_x, spline_y, t)
            mismatch = float(np.max(np.abs(np.diff(arc) / np.diff(t) - 1.0)))
            contracting = mismatch <= max(_MIN_CONTRACTION * mismatch_before, _MISMATCH_FLOOR)
            if not (contracting and np.all(np.diff(arc) <= _MAX_ARC_TO_CHORD * chord)):
                break
            accepted, mismatch_before, t = (spline_x, spline_y, t), mismatch, arc
        else:
            if accepted is not None:  # always: no refit was rejected, and at least one ran
                return accepted
        if degree > 3:  # the quintic is unstable on these waypoints: a cubic, natural at the ends of an open path
            degree, bc = 3, bc or "natural"
        elif accepted is not None:
            return accepted
        else:  # even the chord-length cubic oscillates: nothing better to offer
            return spline_x, spline_y, t_chord


@overload
def wrap_angle(angle_rad: float) -> float: ...
@overload
def wrap_angle(angle_rad: np.ndarray) -> np.ndarray: ...
def wrap_angle(angle_rad: float | np.ndarray) -> float | np.ndarray:
    """Wrap an angle (rad) to [-pi, pi)."""
    if isinstance(angle_rad, float | int):
        return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi
    return (np.asarray(angle_rad) + np.pi) % (2.0 * np.pi) - np.pi


@dataclass(frozen=True, slots=True)
class Projection:
    """The foot point of a position on the path.

    s_m: arc length of the foot point in [0, length]; progress_m: arc length travelled since the tracker started,
    counting laps of a closed loop; x_m, y_m: foot point; heading_rad: path heading there (unwrapped along the
    path); curvature_1pm: path curvature there (left turn positive); cte_m: signed cross-track error, positive when
    the position is left of the path (past an end of an open path: the offset from that end's tangent line);
    at_end: the foot point is the end of an open path; past_end_m: how far the position lies beyond an end of an
    open path, along that end's tangent (0 when it is not beyond either end); distance_m: the distance from the
    position to the foot point, which beyond an open path's end is the distance to the end point (|CTE| is only
    its sideways part).
    """

    s_m: float
    progress_m: float
    x_m: float
    y_m: float
    heading_rad: float
    curvature_1pm: float
    cte_m: float
    at_end: bool
    past_end_m: float = 0.0
    distance_m: float = 0.0

    @property
    def signed_distance_m(self) -> float:
        """The distance from the path, signed as the CTE (left positive): the CTE that counts beyond the ends."""
        return math.copysign(self.distance_m, self.cte_m)


class ReferencePath:
    """A planar path sampled uniformly in arc length.

    Arrays hold `n` samples at s = 0, ds, ..., length; for a closed loop the last sample repeats the first (with
    its heading advanced by the loop's total turning), so interpolation needs no special case at the seam.
    width_right_m, width_left_m: the track's extent to the right and left of the path at each sample (m), or None
    when the path has no track around it (both or neither).
    """

    def __init__(
        self,
        x_m: np.ndarray,
        y_m: np.ndarray,
        heading_rad: np.ndarray,
        curvature_1pm: np.ndarray,
        spacing_m: float,
        closed: bool,
        speed_mps: np.ndarray | None = None,
        name: str = "path",
        *,
        width_right_m: np.ndarray | None = None,
        width_left_m: np.ndarray | None = None,
    ) -> None:
        self.x_m = np.ascontiguousarray(x_m, dtype=float)
        self.y_m = np.ascontiguousarray(y_m, dtype=float)
        self.heading_rad = np.ascontiguousarray(heading_rad, dtype=float)
        self.curvature_1pm = np.ascontiguousarray(curvature_1pm, dtype=float)
        self.speed_mps = None if speed_mps is None else np.ascontiguousarray(speed_mps, dtype=float)
        self.width_right_m = None if width_right_m is None else np.ascontiguousarray(width_right_m, dtype=float)
        self.width_left_m = None if width_left_m is None else np.ascontiguousarray(width_left_m, dtype=float)
        self.spacing_m = float(spacing_m)
        self.closed = bool(closed)
        self.name = name
        self.s_m = np.arange(self.x_m.size) * self.spacing_m
        self.length_m = float(self.s_m[-1])
        #: The longest chord between neighbouring samples (m): what `first_beyond` may skip by.
        self.max_segment_m = float(np.hypot(np.diff(self.x_m), np.diff(self.y_m)).max()) if self.x_m.size > 1 else 0.0
        self._compiled: dict[float, CompiledPath] = {}
        for label, arr in (("heading", self.heading_rad), ("curvature", self.curvature_1pm)):
            if arr.shape != self.x_m.shape:
                raise WorkbenchInputError(f"{name}: {label} has {arr.size} samples, positions have {self.x_m.size}")
        if (self.width_right_m is None) != (self.width_left_m is None):
            raise WorkbenchInputError(f"{name}: give both track widths (right and left) or neither")
        for label, widths in (("right track width", self.width_right_m), ("left track width", self.width_left_m)):
            if widths is not None and widths.shape != self.x_m.shape:
                raise WorkbenchInputError(f"{name}: {label} has {widths.size} samples, positions have {self.x_m.size}")

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_waypoints(
        cls, waypoints: Waypoints, spacing_m: float = DEFAULT_SAMPLE_SPACING_M, name: str | None = None
    ) -> ReferencePath:
        """Fit a quintic spline through the waypoints, parameterised by arc length, and sample it every spacing_m.

        Closed loops use a periodic spline, so heading and curvature are continuous across the seam too. A speed
        and track widths given at the waypoints are interpolated linearly in arc length.
        """
        require_positive("spacing_m", spacing_m)
        x, y = waypoints.x_m, waypoints.y_m
        if waypoints.closed:
            x, y = np.append(x, x[0]), np.append(y, y[0])
        chord_length = float(np.sum(np.hypot(np.diff(x), np.diff(y))))  # a lower bound on the arc length
        if chord_length / spacing_m > MAX_PATH_SAMPLES:
            raise WorkbenchInputError(
                f"{waypoints.source}: a path of at least {chord_length:.4g} m sampled every {spacing_m:g} m needs more "
                f"than {MAX_PATH_SAMPLES:,} samples; split it or sample it more coarsely"
            )
        spline_x, spline_y, t_knots = _arc_length_spline(x, y, waypoints.closed)

        # Arc length s(t) on a fine grid (t is already close to s after the re-parameterisation).
        t_fine = np.linspace(0.0, t_knots[-1], max(16, math.ceil(2.0 * t_knots[-1] / spacing_m)) + 1)
        s_fine = _cumulative_arc_length(spline_x, spline_y, t_fine)
        length = float(s_fine[-1])
        n_intervals = max(2, math.ceil(length / spacing_m))
        s_uniform = np.linspace(0.0, length, n_intervals + 1)
        t_uniform = np.interp(s_uniform, s_fine, t_fine)
        dx, dy = spline_x(t_uniform, 1), spline_y(t_uniform, 1)
        ddx, ddy = spline_x(t_uniform, 2), spline_y(t_uniform, 2)
        heading = np.unwrap(np.arctan2(dy, dx))
        curvature = (dx * ddy - dy * ddx) / np.hypot(dx, dy) ** 3
        x_u, y_u = spline_x(t_uniform), spline_y(t_uniform)
        if waypoints.closed:  # make the seam sample exact
            x_u[-1], y_u[-1], curvature[-1] = x_u[0], y_u[0], curvature[0]

        s_knots = np.interp(t_knots, t_fine, s_fine)

        def along_path(values: np.ndarray | None) -> np.ndarray | None:
            """Values given at the waypoints, linear in arc length at the samples (the loop closed)."""
            if values is None:
                return None
            return np.interp(s_uniform, s_knots, np.append(values, values[0]) if waypoints.closed else values)

        return cls(
            x_u,
            y_u,
            heading,
            curvature,
            length / n_intervals,
            waypoints.closed,
            along_path(waypoints.speed_mps),
            name=name or waypoints.source,
            width_right_m=along_path(waypoints.width_right_m),
            width_left_m=along_path(waypoints.width_left_m),
        )

    @classmethod
    def from_xy(
        cls,
        x_m: np.ndarray,
        y_m: np.ndarray,
        speed_mps: np.ndarray | None = None,
        closed: bool = False,
        name: str = "path",
        spacing_m: float = DEFAULT_SAMPLE_SPACING_M,
    ) -> ReferencePath:
        """A path from numpy arrays of waypoints (m), optionally with speeds (m/s); see `from_waypoints`."""
        return cls.from_waypoints(Waypoints(x_m, y_m, speed_mps, closed, source=name), spacing_m, name)

    # ------------------------------------------------------------------ evaluation
    @overload
    def wrap_s(self, s_m: float) -> float: ...
    @overload
    def wrap_s(self, s_m: np.ndarray) -> np.ndarray: ...
    def wrap_s(self, s_m: float | np.ndarray) -> float | np.ndarray:
        """Map an arc length into [0, length]: modulo the length on a closed loop, clipped on an open path."""
        if isinstance(s_m, float | int):  # the per-step case: plain Python is 10x faster than numpy here
            return s_m % self.length_m if self.closed else min(max(float(s_m), 0.0), self.length_m)
        if self.closed:
            return np.mod(s_m, self.length_m)
        return np.clip(s_m, 0.0, self.length_m)

    @overload
    def _interp(self, values: np.ndarray, s_m: float) -> float: ...
    @overload
    def _interp(self, values: np.ndarray, s_m: np.ndarray) -> np.ndarray: ...
    def _interp(self, values: np.ndarray, s_m: float | np.ndarray) -> float | np.ndarray:
        if isinstance(s_m, float | int):  # the per-step case, compiled (`path_search.value_at`)
            return value_at(values, float(s_m), self.spacing_m, self.length_m, self.closed)
        return np.interp(self.wrap_s(s_m), self.s_m, values)

    @overload
    def position(self, s_m: float) -> tuple[float, float]: ...
    @overload
    def position(self, s_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...
    def position(self, s_m: float | np.ndarray) -> tuple[float | np.ndarray, float | np.ndarray]:
        """Point(s) (x, y) on the path at arc length s (m)."""
        return self._interp(self.x_m, s_m), self._interp(self.y_m, s_m)

    def heading(self, s_m: float | np.ndarray) -> float | np.ndarray:
        """Path heading (rad, unwrapped along one lap) at arc length s."""
        return self._interp(self.heading_rad, s_m)

    def curvature(self, s_m: float | np.ndarray) -> float | np.ndarray:
        """Path curvature (1/m, left turn positive) at arc length s."""
        return self._interp(self.curvature_1pm, s_m)

    @property
    def planned_speed_mps(self) -> np.ndarray:
        """`speed_mps` of a path that must carry its planned speed (a run's: `Simulation` plans it); an error naming
        the path when it carries none."""
        if self.speed_mps is None:
            raise WorkbenchInputError(f"{self.name}: the path carries no planned speed")
        return self.speed_mps

    def speed(self, s_m: float | np.ndarray) -> float | np.ndarray | None:
        """Planned speed (m/s) at arc length s, or None when the path carries no speed."""
        return None if self.speed_mps is None else self._interp(self.speed_mps, s_m)

    def speed_gradient(self, s_m: float | np.ndarray) -> float | np.ndarray | None:
        """Slope dv/ds (1/s) of the planned speed at arc length s, or None when the path carries no speed.

        The slope of the linear interpolation `speed` uses: constant between two samples, the segment ahead at a
        sample. Along the path at speed v the reference changes at v dv/ds (m/s^2).
        """
        if self.speed_mps is None:
            return None
        if isinstance(s_m, float | int):  # the per-step case, compiled (`path_search.slope_at`)
            return slope_at(self.speed_mps, float(s_m), self.spacing_m, self.length_m, self.closed)
        i = np.minimum((self.wrap_s(np.asarray(s_m, dtype=float)) / self.spacing_m).astype(int), self.s_m.size - 2)
        return np.diff(self.speed_mps)[i] / self.spacing_m

    def with_speed(self, speed_mps: np.ndarray) -> ReferencePath:
        """A copy of this path carrying the given speed at each of its samples."""
        speed = np.asarray(speed_mps, dtype=float)
        if speed.shape != self.x_m.shape:
            raise WorkbenchInputError(f"{self.name}: speed has {speed.size} samples, the path has {self.x_m.size}")
        return ReferencePath(
            self.x_m,
            self.y_m,
            self.heading_rad,
            self.curvature_1pm,
            self.spacing_m,
            self.closed,
            speed,
            self.name,
            width_right_m=self.width_right_m,
            width_left_m=self.width_left_m,
        )

    # ------------------------------------------------------------------ the track around the path
    @property
    def has_widths(self) -> bool:
        """Whether the path carries the track's widths (its edges are known)."""
        return self.width_right_m is not None

    def track_edges(self) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None:
        """((x, y) of the left edge, (x, y) of the right edge) at the path's samples (m): each sample moved across
        the path by its width; None when the path has no widths. Where a width exceeds the radius of a bend the
        inner edge loops back on itself, as the offset of a curve does."""
        if self.width_right_m is None or self.width_left_m is None:
            return None
        normal_x, normal_y = -np.sin(self.heading_rad), np.cos(self.heading_rad)  # to the left
        left = (self.x_m + self.width_left_m * normal_x, self.y_m + self.width_left_m * normal_y)
        right = (self.x_m - self.width_right_m * normal_x, self.y_m - self.width_right_m * normal_y)
        return left, right

    def s_at_arc_distance(self, s_m: float, distance_m: float) -> float:
        """The arc length `distance_m` further along the path from s (wrapped on loops, clipped at an end)."""
        return float(self.wrap_s(s_m + distance_m))

    def s_at_euclidean_distance(self, s_from_m: float, x_m: float, y_m: float, distance_m: float) -> float:
        """The first arc length at or after s_from whose point is at least `distance_m` from (x, y).

        Searches forward along the path (at most one lap of a loop); interpolates between samples. Returns the end
        of an open path when no point ahead is that far away.
        """
        s_from = float(self.wrap_s(s_from_m))
        index = first_beyond(
            self.x_m,
            self.y_m,
            float(x_m),
            float(y_m),
            s_from / self.spacing_m,
            float(distance_m),
            self.closed,
            self.max_segment_m,
        )
        if index < 0.0:  # no point ahead is that far: the end of an open path
            return self.length_m if not self.closed else s_from
        return min(index * self.spacing_m, self.length_m)

    # ------------------------------------------------------------------ projection
    def project_global(self, x_m: float, y_m: float) -> float:
        """Arc length of the closest point over the whole path (no progress tracking; ambiguous at crossings)."""
        j, t, _ = closest_in_window(self.x_m, self.y_m, float(x_m), float(y_m), 0, self.x_m.size - 2, False)
        return float((j + t) * self.spacing_m)

    def compiled(self, min_window_m: float = DEFAULT_TRACKER_WINDOW_M) -> CompiledPath:
        """The path as the compiled kernels read it (`path_search.CompiledPath`), its trackers searching at least
        min_window_m each way; made once per window and kept."""
        compiled = self._compiled.get(min_window_m)
        if compiled is None:
            samples = (self.x_m, self.y_m, self.heading_rad, self.curvature_1pm, self.speed_mps)
            compiled = CompiledPath.of(
                samples, self.spacing_m, self.length_m, self.closed, self.max_segment_m, float(min_window_m)
            )
            self._compiled[min_window_m] = compiled
        return compiled

    def tracker(self, initial_s_m: float | None = None) -> PathTracker:
        """A progress-following projector; starts at initial_s_m or, if None, at the global closest point."""
        return PathTracker(self, initial_s_m)

    def __repr__(self) -> str:
        kind = "closed" if self.closed else "open"
        return f"ReferencePath({self.name!r}, {kind}, length={self.length_m:.1f} m, {self.x_m.size} samples)"


class PathTracker:
    """Projects successive vehicle positions onto a path, following the vehicle's progress.

    Each update searches a window of the path around the previous foot point, sized by how far the vehicle moved
    (at least `min_window_m` each way), and extends it while the best point sits on the window's edge. The other
    branch of a self-crossing path, or the far side of a loop's seam, is never reached unless the vehicle's
    distance to the path falls continuously toward it.
    """

    def __init__(
        self, path: ReferencePath, initial_s_m: float | None = None, min_window_m: float = DEFAULT_TRACKER_WINDOW_M
    ) -> None:
        self.path = path
        self.min_window_m = float(min_window_m)
        #: The path as the compiled update reads it, with this tracker's window.
        self.compiled = path.compiled(self.min_window_m)
        #: The compiled update's state (`path_search.track`) and its output row.
        self.state = np.empty(TRACK_STATE_SIZE)
        self.out = np.empty(TRACK_OUT_SIZE)
        self.reset(initial_s_m)

    def reset(self, initial_s_m: float | None = None) -> None:
        """Forget the history; the next update starts from initial_s_m (global search if None)."""
        self.state[:] = np.nan
        if initial_s_m is not None:
            self.state[TRACK_S] = float(self.path.wrap_s(initial_s_m))
        self.state[TRACK_PROGRESS] = 0.0 if initial_s_m is None else float(initial_s_m)

    @property
    def extent_m(self) -> float:
        """The diagonal of the path's bounding box (m): a move longer than this searches the whole path."""
        return self.compiled.extent_m

    @property
    def progress_m(self) -> float:
        """Arc length travelled (laps counted) as of the last update."""
        return float(self.state[TRACK_PROGRESS])

    def update(self, x_m: float, y_m: float) -> Projection:
        """The foot point of (x_m, y_m), the progress advanced to it (`path_search.track`, compiled)."""
        path = self.path
        if not (math.isfinite(x_m) and math.isfinite(y_m)):
            raise WorkbenchInputError(f"position must be finite to project onto {path.name}; got ({x_m}, {y_m})")
        self.advance(float(x_m), float(y_m))
        s_m, progress, fx, fy, heading, curvature, cte, at_end, past_end, distance = self.out.tolist()
        return Projection(s_m, progress, fx, fy, heading, curvature, cte, at_end == 1.0, past_end, distance)

    def advance(self, x_m: float, y_m: float) -> None:
        """`update` without the checks and the Projection, for a hot loop: the projection is left in `out`
        (`path_search.TRACK_OUT_SIZE` values in Projection's order, at_end as 1.0 / 0.0)."""
        compiled = self.compiled
        track(compiled.table, compiled.record, self.state, x_m, y_m, self.out)
