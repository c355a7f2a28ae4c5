"""Stanley (Thrun et al. 2006, the DARPA Grand Challenge winner): heading error plus a front-axle cross-track term.

The law: phi = (psi_path - psi) + atan(k e / (k_soft + v)), with e the front axle's signed CTE.

The front-axle position is the measured rear-axle position moved one wheelbase along the heading. A path-curvature
feedforward, atan(L kappa), is optional (off by default, as in the original law).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from controllers.base import Controller, Measurement
from controllers.config_checks import Flag, Number, check_options, option
from workbench.base.path import PathTracker, ReferencePath, wrap_angle


@dataclass(frozen=True)
class StanleyConfig:
    """Options of the Stanley law (module docstring); each field's unit, range and meaning are in its metadata
    (`config_checks.option`), which `workbench controllers --show stanley` prints."""

    gain_per_s: float = option(
        1.5,
        "k, the cross-track gain: how hard the front axle's offset is steered out (atan(k e / (k_soft + v)))",
        Number(0.0, 100.0, "1/s", low_open=True),
    )
    softening_mps: float = option(
        1.0,
        "k_soft, added to the speed in the cross-track term: keeps the law finite and calm at low speed",
        Number(0.0, 100.0, "m/s", low_open=True),
    )
    curvature_feedforward: bool = option(
        False,
        "add the feed-forward that holds the path's curvature in a steady turn (module docstring; off in the original "
        "law)",
        Flag(),
    )

    def __post_init__(self) -> None:
        check_options(self)


class Stanley(Controller):
    name: ClassVar[str] = "stanley"
    config_type: ClassVar[type] = StanleyConfig

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        self._tracker: PathTracker = path.tracker(0.0)
        self._diag = self._declare_diagnostics(("front_cte_m", "heading_term_rad", "cross_track_term_rad"))

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        cfg, m, wheelbase = self.config, measurement, self.geometry.wheelbase_m
        front_x = m.x_m + wheelbase * math.cos(m.yaw_rad)
        front_y = m.y_m + wheelbase * math.sin(m.yaw_rad)
        foot = self._tracker.update(front_x, front_y)
        heading_term = wrap_angle(foot.heading_rad - m.yaw_rad)
        cross_track_term = math.atan2(-cfg.gain_per_s * foot.cte_m, cfg.softening_mps + m.speed_mps)
        road_wheel = heading_term + cross_track_term
        if cfg.curvature_feedforward:
            road_wheel += math.atan(wheelbase * foot.curvature_1pm)
        self._diag[:] = (foot.cte_m, heading_term, cross_track_term)
        limit = self.geometry.max_road_wheel_angle_rad
        return self.saturate(min(max(road_wheel, -limit), limit) * self.geometry.steering_ratio)
