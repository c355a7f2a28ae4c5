"""Pure pursuit (Coulter 1992): steer onto the circular arc through the rear axle and a lookahead point.

The lookahead distance grows with speed, l_d = clip(k v, l_min, l_max). The target is the first path point ahead
of the foot point at Euclidean distance l_d from the rear-axle centre; when the vehicle is farther than that
from the path, l_d is raised to |CTE| + l_min so that a target ahead always exists and the approach is at most
about 45 degrees. Curvature kappa = 2 sin(alpha) / l_d, road-wheel angle tan(phi) = L kappa.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from controllers.base import Controller, Measurement
from controllers.config_checks import Number, check_options, option
from controllers.search_space import Tunable
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.path import PathTracker, ReferencePath
from workbench.base.path_search import PATH_X, PATH_Y, first_beyond, track, value_at

#: The longest lookahead (m) the options allow.
MAX_LOOKAHEAD_M = 1000.0


@dataclass(frozen=True)
class PurePursuitConfig:
    """Options of pure pursuit (module docstring); each field's unit, range and meaning are in its metadata
    (`config_checks.option`), which `workbench controllers --show pure-pursuit` prints."""

    lookahead_gain_s: float = option(
        0.8,
        "k, the lookahead per unit speed: l_d = clip(k v, min_lookahead_m, max_lookahead_m); longer is calmer, "
        "shorter cuts corners less",
        Number(0.0, 100.0, "s", low_open=True),
    )
    min_lookahead_m: float = option(
        4.0, "the shortest lookahead l_d, at low speed", Number(0.0, MAX_LOOKAHEAD_M, "m", low_open=True)
    )
    max_lookahead_m: float = option(
        30.0,
        "the longest lookahead l_d, at high speed (at least min_lookahead_m)",
        Number(0.0, MAX_LOOKAHEAD_M, "m", low_open=True),
    )

    def __post_init__(self) -> None:
        check_options(self)
        if self.max_lookahead_m < self.min_lookahead_m:
            raise WorkbenchInputError(
                f"max_lookahead_m must be >= min_lookahead_m = {value_text(self.min_lookahead_m)} m; "
                f"got {value_text(self.max_lookahead_m)}"
            )


class PurePursuit(Controller[PurePursuitConfig]):
    """Pure pursuit, registered as "pure-pursuit": steers onto the arc through the rear axle and the lookahead
    point (module docstring for the law), with the options of `PurePursuitConfig`."""

    name: ClassVar[str] = "pure-pursuit"
    config_type: ClassVar[type] = PurePursuitConfig
    search_space: ClassVar[tuple[Tunable, ...]] = (
        Tunable("lookahead_gain_s", "log", 0.3, 3.0, reason="longer lookahead per unit speed is calmer and more "
                "stable at speed, and cuts the corners more"),
        Tunable("min_lookahead_m", "linear", 3.0, 12.0, reason="a shorter lookahead at low speed tracks tighter and "
                "oscillates sooner"),
        Tunable("max_lookahead_m", "linear", 15.0, 60.0, reason="caps the lookahead at high speed: shorter cuts less "
                "on fast bends, longer keeps high speed stable"),
    )  # fmt: skip

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        self._tracker: PathTracker = path.tracker(0.0)
        self._diag = self._declare_diagnostics(("lookahead_m", "target_s_m", "curvature_cmd_1pm"))

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        cfg, m, tracker = self.config, measurement, self._tracker
        compiled = tracker.compiled
        curvature, lookahead, target_s = pure_pursuit_step(
            m.x_m, m.y_m, m.yaw_rad, m.speed_mps, cfg.lookahead_gain_s, cfg.min_lookahead_m, cfg.max_lookahead_m,
            compiled.table, compiled.record, tracker.state, tracker.out,
        )  # fmt: skip
        self._diag[:] = (lookahead, target_s, curvature)
        return self.saturate(self.geometry.steer_wheel_for_curvature(curvature))


@njit(cache=True)
def pure_pursuit_step(
    x_m: float,
    y_m: float,
    yaw_rad: float,
    speed_mps: float,
    gain_s: float,
    min_lookahead_m: float,
    max_lookahead_m: float,
    table: np.ndarray,
    record: np.ndarray,
    tracker: np.ndarray,
    foot: np.ndarray,
) -> tuple[float, float, float]:  # pragma: no cover - compiled
    """(curvature 1/m, lookahead l_d m, target arc length m) of one step (module docstring), compiled: the foot
    point on the compiled path (`path_search.CompiledPath`'s table and record; `path_search.track`, the tracker's
    state and output arrays), l_d, the target at l_d ahead (`ReferencePath.s_at_euclidean_distance`) and the arc
    to it."""
    track(table, record, tracker, x_m, y_m, foot)
    path_x, path_y = table[PATH_X], table[PATH_Y]
    shape = record[0]
    spacing, length, closed = shape.spacing, shape.length, shape.closed
    foot_s, foot_curvature, cte = foot[0], foot[5], foot[6]
    lookahead = min(max(gain_s * speed_mps, min_lookahead_m), max_lookahead_m)
    lookahead = max(lookahead, abs(cte) + min_lookahead_m)
    s_from = foot_s % length if closed else min(max(foot_s, 0.0), length)
    index = first_beyond(path_x, path_y, x_m, y_m, s_from / spacing, lookahead, closed, shape.max_segment)
    if index < 0.0:  # no point ahead is that far: the end of an open path
        target_s = length if not closed else s_from
    else:
        target_s = min(index * spacing, length)
    dx = value_at(path_x, target_s, spacing, length, closed) - x_m
    dy = value_at(path_y, target_s, spacing, length, closed) - y_m
    distance = math.hypot(dx, dy)
    if distance < 1e-6:  # at the very end of an open path: hold the path's curvature
        return foot_curvature, lookahead, target_s
    return 2.0 * math.sin(math.atan2(dy, dx) - yaw_rad) / distance, lookahead, target_s


__all__ = ["PurePursuit", "PurePursuitConfig"]
