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

from controllers.base import Controller, Measurement
from controllers.config_checks import check_number
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.path import PathTracker, ReferencePath

#: The longest lookahead (m) the options allow.
MAX_LOOKAHEAD_M = 1000.0


@dataclass(frozen=True)
class PurePursuitConfig:
    """lookahead_gain_s: l_d per unit speed (s); min_lookahead_m, max_lookahead_m: bounds on l_d (m)."""

    lookahead_gain_s: float = 0.8
    min_lookahead_m: float = 4.0
    max_lookahead_m: float = 30.0

    def __post_init__(self) -> None:
        check_number("lookahead_gain_s", self.lookahead_gain_s, 0.0, 100.0, "s", low_open=True)
        check_number("min_lookahead_m", self.min_lookahead_m, 0.0, MAX_LOOKAHEAD_M, "m", low_open=True)
        check_number("max_lookahead_m", self.max_lookahead_m, 0.0, MAX_LOOKAHEAD_M, "m", low_open=True)
        if self.max_lookahead_m < self.min_lookahead_m:
            raise WorkbenchInputError(
                f"max_lookahead_m must be >= min_lookahead_m = {value_text(self.min_lookahead_m)} m; "
                f"got {value_text(self.max_lookahead_m)}"
            )


class PurePursuit(Controller):
    name: ClassVar[str] = "pure-pursuit"
    config_type: ClassVar[type] = PurePursuitConfig

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        self._tracker: PathTracker = path.tracker(0.0)
        self._diag = self._declare_diagnostics(("lookahead_m", "target_s_m", "curvature_cmd_1pm"))

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        cfg = self.config
        m = measurement
        foot = self._tracker.update(m.x_m, m.y_m)
        lookahead = min(max(cfg.lookahead_gain_s * m.speed_mps, cfg.min_lookahead_m), cfg.max_lookahead_m)
        lookahead = max(lookahead, abs(foot.cte_m) + cfg.min_lookahead_m)
        target_s = path.s_at_euclidean_distance(foot.s_m, m.x_m, m.y_m, lookahead)
        tx, ty = path.position(target_s)
        dx, dy = float(tx) - m.x_m, float(ty) - m.y_m
        distance = math.hypot(dx, dy)
        if distance < 1e-6:  # at the very end of an open path: hold the path's curvature
            curvature = foot.curvature_1pm
        else:
            alpha = math.atan2(dy, dx) - m.yaw_rad
            curvature = 2.0 * math.sin(alpha) / distance
        self._diag[:] = (lookahead, target_s, curvature)
        return self.saturate(self.geometry.steer_wheel_for_curvature(curvature))
