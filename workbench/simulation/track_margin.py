"""How close a run's vehicle came to the track's edges: the plan-view outline of each unit (a rectangle around the
car or tractor, and one around the trailer) against the edges the path's widths give (`ReferencePath.track_edges`).

The least distance between a rectangle and a curve is reached at a corner of the rectangle or at a point of the
curve, so a unit's margin at a step is the least of two kinds:

- each corner's, measured across the path at the corner's own foot point on it (its arc length s and its signed
  offset d, left positive): w_left(s) - d to the left edge, w_right(s) + d to the right one, negative beyond the edge.
  That is the distance to an edge parallel to the centre line, and within 1.5% of it where the width changes
  along the track (TUMFTM Zandvoort's steepest change is 0.18 m per m). The foot points come from Newton's method
  started at the unit's own foot point (the trace's path_s_m for the car or tractor; a progress-tracked projection
  of the trailer's axle);
- each track-edge point's near the unit (the edges sampled every `EDGE_SPACING_M` along the path): its signed
  distance to the rectangle, negative inside it (where an edge cuts into a side: the inner edge of a bend reaches
  the middle of the inner side, not its corners). Beside a side the sampled edge is within kappa h^2 / 8 of the true
  one (2 cm on a 1.5 m inner-edge radius).

Where that is negative (the outline crossed an edge), it becomes how far the outline reached beyond the edge: the
least corner-style margin over its perimeter every `OFF_TRACK_SPACING_M`, the inner side's middle included.

Vectorised over the trace: about 45 ms for a 26 000-step Zandvoort lap of the car, 100 ms with a trailer.

The vehicles do not state their overall length, so the overhangs beyond the axles are assumed here (constants
below, with their sources); the width is the vehicle's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.base.path_search import track_sequence

if TYPE_CHECKING:
    from workbench.base.path import ReferencePath
    from workbench.vehicles.base import VehicleModel

#: A passenger car (every model without a trailer): front and rear overhang beyond the axles (m). CommonRoad
#: vehicle 2's length 4.508 m less its wheelbase 2.579 m is 1.93 m, split 0.44 / 0.56 as in a front-engined saloon.
CAR_FRONT_OVERHANG_M = 0.84
CAR_REAR_OVERHANG_M = 1.09
#: The tractor: bumper ahead of the steer axle (m; assumed, US conventional tractor, 0.9-1.2 m) and the frame behind
#: the drive tandem's centre (m; assumed: 0.635 m to the last axle, Auburn GAVLAB b2 - b, plus 0.4 m of frame).
TRACTOR_FRONT_OVERHANG_M = 1.0
TRACTOR_REAR_OVERHANG_M = 1.0
#: The trailer: a 53 ft (16.154 m) US van with its kingpin 36 in (0.914 m) behind its front; its rear overhang
#: behind the tandem's centre is what remains of the length with the preset's 13.768 m from kingpin to tandem (m).
TRAILER_KINGPIN_SETBACK_M = 0.914
TRAILER_REAR_OVERHANG_M = 16.154 - 0.914 - 13.768
#: The track's edges are sampled every this (m along the path) for their distances to the vehicle's sides.
EDGE_SPACING_M = 0.5
#: Edge points up to this far (m along the path) beyond the foot points of a unit's ends are measured against it.
EDGE_REACH_M = 1.0
#: Where the outline reaches beyond an edge, its perimeter is measured every this (m) for the farthest point.
OFF_TRACK_SPACING_M = 0.25
#: Newton iterations of the foot-point search from the nearest sample (each about squares the error: one leaves
#: under 1 mm at the corners of a Zandvoort lap, the second is for tighter bends).
_NEWTON_ITERATIONS = 2
#: The Newton step's denominator 1 - kappa d is kept above this: a point near a bend's centre has no clear foot.
_MIN_NEWTON_DENOMINATOR = 0.2


@dataclass(frozen=True)
class VehicleOutline:
    """The vehicle's plan-view outline: a rectangle per unit, from its reference point (m).

    width_m: overall width; front_m: from the reference point (the rear axle's centre, the tractor's drive-group
    centre) forward to the front (wheelbase plus front overhang); rear_m: back to the rear end; trailer_front_m:
    from the trailer's axle-group centre forward to the trailer's front (kingpin distance plus set-back), and
    trailer_rear_m back to its rear, both None for a vehicle without a trailer.
    """

    width_m: float
    front_m: float
    rear_m: float
    trailer_front_m: float | None = None
    trailer_rear_m: float | None = None

    def __post_init__(self) -> None:
        require_in_range("width_m", self.width_m, 0.5, 4.0, "m")
        require_in_range("front_m", self.front_m, 0.5, 20.0, "m")
        require_in_range("rear_m", self.rear_m, 0.0, 10.0, "m")
        if (self.trailer_front_m is None) != (self.trailer_rear_m is None):
            raise WorkbenchInputError(
                f"give both trailer_front_m and trailer_rear_m or neither; got {self.trailer_front_m!r} and "
                f"{self.trailer_rear_m!r}"
            )
        if self.trailer_front_m is not None and self.trailer_rear_m is not None:
            require_in_range("trailer_front_m", self.trailer_front_m, 0.5, 25.0, "m")
            require_in_range("trailer_rear_m", self.trailer_rear_m, 0.0, 10.0, "m")

    @property
    def has_trailer(self) -> bool:
        return self.trailer_front_m is not None

    @classmethod
    def of(cls, vehicle: VehicleModel) -> VehicleOutline:
        """A vehicle model's outline: its width and wheelbase, the assumed overhangs, and for a model with a trailer
        (a `trailer_x_m` output) the trailer's from its `hitch_to_trailer_axle_m` parameter."""
        geometry = vehicle.geometry
        if "trailer_x_m" not in vehicle.output_names:
            return cls(geometry.width_m, geometry.wheelbase_m + CAR_FRONT_OVERHANG_M, CAR_REAR_OVERHANG_M)
        hitch_to_axle = getattr(vehicle.params, "hitch_to_trailer_axle_m", None)
        if hitch_to_axle is None:
            raise WorkbenchInputError(
                f"the {vehicle.name} has a trailer but no hitch_to_trailer_axle_m parameter; its outline needs it"
            )
        return cls(
            geometry.width_m,
            geometry.wheelbase_m + TRACTOR_FRONT_OVERHANG_M,
            TRACTOR_REAR_OVERHANG_M,
            float(hitch_to_axle) + TRAILER_KINGPIN_SETBACK_M,
            TRAILER_REAR_OVERHANG_M,
        )


class _Samples:
    """The path's samples the margins read, as one (n, 7) table (x, y, cos and sin of the heading, curvature, left
    and right width), interpolated linearly at arc lengths wrapped around a loop or clipped to an open path."""

    X, Y, COS, SIN, KAPPA, LEFT, RIGHT = range(7)

    def __init__(self, path: ReferencePath) -> None:
        if path.width_left_m is None or path.width_right_m is None:
            raise WorkbenchInputError(f"{path.name}: the path has no track widths to measure a margin against")
        h = path.heading_rad
        self.table = np.column_stack(
            (path.x_m, path.y_m, np.cos(h), np.sin(h), path.curvature_1pm, path.width_left_m, path.width_right_m)
        )
        self.spacing, self.length, self.closed = path.spacing_m, path.length_m, path.closed

    def at(self, s_m: np.ndarray) -> np.ndarray:
        """The table's rows interpolated at arc lengths s (any shape; the columns last)."""
        s = np.mod(s_m, self.length) if self.closed else np.clip(s_m, 0.0, self.length)
        u = s / self.spacing
        i = np.minimum(u.astype(np.intp), self.table.shape[0] - 2)
        low = self.table[i]
        return low + (u - i)[..., None] * (self.table[i + 1] - low)

    def nearest(self, s_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(the arc length of the sample nearest each s, that sample's row): wrapped or clipped as `at`."""
        s = np.mod(s_m, self.length) if self.closed else np.clip(s_m, 0.0, self.length)
        i = np.rint(s / self.spacing).astype(np.intp)
        return i * self.spacing, self.table[i]

    def wrap_difference(self, ds_m: np.ndarray) -> np.ndarray:
        """A difference of arc lengths taken the short way round a loop (into [-length/2, length/2))."""
        if not self.closed:
            return ds_m
        return np.mod(ds_m + 0.5 * self.length, self.length) - 0.5 * self.length


def _margins(samples: _Samples, px: np.ndarray, py: np.ndarray, s_m: np.ndarray) -> np.ndarray:
    """The margin (m) of each point (px, py) to the nearer edge, its foot point found by Newton's method from s
    (each step from the path's sample nearest the last estimate; the last evaluation interpolates)."""
    s = s_m
    for _ in range(_NEWTON_ITERATIONS):
        s, row = samples.nearest(s)
        ex, ey = px - row[..., _Samples.X], py - row[..., _Samples.Y]
        cos, sin = row[..., _Samples.COS], row[..., _Samples.SIN]
        along, across = ex * cos + ey * sin, ey * cos - ex * sin
        s = s + along / np.maximum(1.0 - row[..., _Samples.KAPPA] * across, _MIN_NEWTON_DENOMINATOR)
    row = samples.at(s)
    ex, ey = px - row[..., _Samples.X], py - row[..., _Samples.Y]
    across = ey * row[..., _Samples.COS] - ex * row[..., _Samples.SIN]
    return np.minimum(row[..., _Samples.LEFT] - across, row[..., _Samples.RIGHT] + across)


class _Edges:
    """The track's left and right edges sampled every `EDGE_SPACING_M` (about) along the path, as (2, m) arrays of
    x and y, padded beyond both ends (a loop's other end; an open path's end repeated) so that a run of points
    never needs wrapping. Single precision, from an origin at the path's start: half the memory traffic of the
    distances' arithmetic, and a resolution of 1e-7 times the path's extent (0.1 mm for a 1 km circuit)."""

    #: The padding beyond each end (m along the path): the longest run of points a unit may need.
    PAD_M = 60.0

    def __init__(self, samples: _Samples) -> None:
        count = max(2, math.ceil(samples.length / EDGE_SPACING_M)) + 1
        self.spacing = samples.length / (count - 1)
        self.closed = samples.closed
        self.origin = (float(samples.table[0, _Samples.X]), float(samples.table[0, _Samples.Y]))
        row = samples.at(np.linspace(0.0, samples.length, count))
        width = np.stack((row[:, _Samples.LEFT], -row[:, _Samples.RIGHT]))  # to the left of the path
        x = row[:, _Samples.X] - self.origin[0] - width * row[:, _Samples.SIN]
        y = row[:, _Samples.Y] - self.origin[1] + width * row[:, _Samples.COS]
        self.count, self.pad = count, math.ceil(self.PAD_M / self.spacing)
        if self.closed:  # the last point repeats the first: pad with the loop's other end
            index = np.mod(np.arange(-self.pad, count - 1 + self.pad), count - 1)
        else:
            index = np.clip(np.arange(-self.pad, count + self.pad), 0, count - 1)
        self.x, self.y = x[:, index].astype(np.float32), y[:, index].astype(np.float32)  # (2, points): left, right

    def near(self, first_s_m: np.ndarray, last_s_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) from the origin, each (steps, 2 k): both edges' points from first_s to last_s (m) at each step, k
        what the steps need (at most twice the median step's and the padding: a step that needs more is cut
        short)."""
        first = np.floor(first_s_m / self.spacing).astype(np.intp)
        need = np.ceil((last_s_m - first_s_m) / self.spacing).astype(np.intp) + 2
        k = min(int(need.max()), 2 * int(np.median(need)), self.pad)
        first = np.mod(first, self.count - 1) if self.closed else np.clip(first, -self.pad, self.count)
        start = first + self.pad  # runs of k points, copied as whole rows of a sliding-window view
        x = np.lib.stride_tricks.sliding_window_view(self.x, k, axis=1)[:, start]
        y = np.lib.stride_tricks.sliding_window_view(self.y, k, axis=1)[:, start]
        return x.transpose(1, 0, 2).reshape(first.size, -1), y.transpose(1, 0, 2).reshape(first.size, -1)


def _unit_margins(
    samples: _Samples,
    edges: _Edges,
    pose: tuple[np.ndarray, np.ndarray, np.ndarray],
    box: tuple[float, float, float],
    foot: tuple[np.ndarray, np.ndarray],
) -> np.ndarray:
    """The least margin at each step of one unit's rectangle (front, rear, half width from its reference point at
    pose = (x, y, yaw)): its corners' and the nearby edge points' (module docstring), and where that is negative,
    the least over its perimeter every `OFF_TRACK_SPACING_M`. foot: (s, ds/da) per step: a point a metres ahead of
    the reference point starts its foot search at s + a ds/da."""
    x, y, yaw = pose
    front, rear, half = box
    foot_s, per_m = foot

    def points(along: np.ndarray, across: np.ndarray, steps: slice | np.ndarray) -> np.ndarray:
        """The margins (steps, k) of the points `along` ahead and `across` left of the reference point."""
        cos, sin = np.cos(yaw[steps])[:, None], np.sin(yaw[steps])[:, None]
        px = x[steps, None] + along * cos - across * sin
        py = y[steps, None] + along * sin + across * cos
        return _margins(samples, px, py, foot_s[steps, None] + along * per_m[steps, None])

    every = slice(None)
    margin = np.min(points(np.array([front, front, -rear, -rear]), np.array([half, -half, half, -half]), every), 1)
    # The edge points in the unit's frame, and their signed distance to its rectangle (centred half_length ahead of
    # the reference point less rear): outside, the length of the excess over the half sizes; inside, minus the depth.
    ends = foot_s[:, None] + np.array([-rear, front]) * per_m[:, None]
    ex, ey = edges.near(np.min(ends, axis=1) - EDGE_REACH_M, np.max(ends, axis=1) + EDGE_REACH_M)
    ex -= (x - edges.origin[0]).astype(np.float32)[:, None]
    ey -= (y - edges.origin[1]).astype(np.float32)[:, None]
    cos, sin = np.cos(yaw).astype(np.float32)[:, None], np.sin(yaw).astype(np.float32)[:, None]
    half_length = np.float32(0.5 * (front + rear))
    over_along = ex * cos
    over_along += ey * sin
    over_along -= half_length - np.float32(rear)
    np.abs(over_along, out=over_along)
    over_along -= half_length
    over_across = ey * cos
    over_across -= ex * sin
    np.abs(over_across, out=over_across)
    over_across -= np.float32(half)
    deepest = np.minimum(np.min(np.maximum(over_along, over_across, out=ex), axis=1), 0.0)
    np.maximum(over_along, 0.0, out=over_along)
    np.maximum(over_across, 0.0, out=over_across)
    outside = np.sqrt(np.min(np.square(over_along, out=over_along) + np.square(over_across, out=over_across), axis=1))
    margin = np.minimum(margin, np.where(deepest < 0.0, deepest, outside).astype(float))
    off = np.flatnonzero(margin < 0.0)
    if off.size:  # how far the outline reached beyond the edge: its perimeter's farthest point
        along = np.linspace(-rear, front, max(2, math.ceil((front + rear) / OFF_TRACK_SPACING_M) + 1))
        across = np.linspace(-half, half, max(2, math.ceil(2 * half / OFF_TRACK_SPACING_M) + 1))
        perimeter_along = np.concatenate((along, along, np.full(across.size, front), np.full(across.size, -rear)))
        perimeter_across = np.concatenate((np.full(along.size, half), np.full(along.size, -half), across, across))
        reach = np.min(points(perimeter_along[None, :], perimeter_across[None, :], off), axis=1)
        margin[off] = np.minimum(margin[off], reach)
    return margin


def trailer_feet(path: ReferencePath, x_m: np.ndarray, y_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(arc length (m, within the path), signed lateral offset (m, left positive)) of the foot point of each of a
    sequence of positions (the trailer's axle, step by step), projected with progress tracking: it never jumps to
    the other leg of a hairpin the trailer cuts across. Sideways only (`Projection.cte_m`)."""
    x_m, y_m = np.ascontiguousarray(x_m, dtype=float), np.ascontiguousarray(y_m, dtype=float)
    tracker = path.tracker(None)
    bad = np.flatnonzero(~(np.isfinite(x_m) & np.isfinite(y_m)))
    if bad.size:
        tracker.update(float(x_m[bad[0]]), float(y_m[bad[0]]))  # raises, naming the position
    s, cte = np.empty(x_m.size), np.empty(x_m.size)
    track_sequence(tracker.compiled.table, tracker.compiled.record, tracker.state, x_m, y_m, s, cte)
    return s, cte


def track_margins(
    path: ReferencePath,
    trace: dict[str, np.ndarray],
    outline: VehicleOutline,
    trailer_s_m: np.ndarray | None = None,
) -> np.ndarray:
    """The least margin (m) of the vehicle's outline to the track's edges at each step of the trace (negative:
    beyond an edge). Reads x_m, y_m, yaw_rad and path_s_m, and for a vehicle with a trailer trailer_x_m, trailer_y_m
    and trailer_yaw_rad; trailer_s_m: the trailer axle's foot points (`trailer_feet`), computed when not given."""
    samples = _Samples(path)
    edges = _Edges(samples)
    x, y, yaw, s = (np.asarray(trace[k], dtype=float) for k in ("x_m", "y_m", "yaw_rad", "path_s_m"))
    # A point's search starts at the unit's foot point moved by the point's distance along the unit projected on
    # the path's tangent there.
    row = samples.at(s)
    aligned = np.cos(yaw) * row[:, _Samples.COS] + np.sin(yaw) * row[:, _Samples.SIN]
    box = (outline.front_m, outline.rear_m, 0.5 * outline.width_m)
    margin = _unit_margins(samples, edges, (x, y, yaw), box, (s, aligned))
    if outline.trailer_front_m is None or outline.trailer_rear_m is None:
        return margin
    tx, ty, tyaw = (np.asarray(trace[k], dtype=float) for k in ("trailer_x_m", "trailer_y_m", "trailer_yaw_rad"))
    if trailer_s_m is None:
        trailer_s_m, _ = trailer_feet(path, tx, ty)
    # The trailer's points start between its axle's foot point and the hitch's (about the tractor's: the fifth
    # wheel sits over the drive group), in proportion to their distance from the axle along the trailer.
    per_m = samples.wrap_difference(s - trailer_s_m) / (outline.trailer_front_m - TRAILER_KINGPIN_SETBACK_M)
    box = (outline.trailer_front_m, outline.trailer_rear_m, 0.5 * outline.width_m)
    return np.minimum(margin, _unit_margins(samples, edges, (tx, ty, tyaw), box, (trailer_s_m, per_m)))
