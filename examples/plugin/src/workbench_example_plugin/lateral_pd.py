"""Lateral PD: path-curvature feed-forward plus feedback on the cross-track and heading errors at the rear axle.

An example of a controller written outside the workbench. The road-wheel angle is
    tan(delta) = L (kappa_path + k_y e_y + k_psi e_psi),
with e_y the signed distance to the path (left positive, so a vehicle left of the path steers right: k_y < 0 in
effect, written below as a minus sign) and e_psi the heading error: the linearised kinematic bicycle's error
dynamics e_y'' = v^2 (-k_y e_y) - v k_psi e_y' (at speed v) are those of a damped oscillator, with natural
frequency v sqrt(k_y) and damping ratio k_psi / (2 sqrt(k_y)).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from controllers.base import Controller, Measurement
from controllers.config_checks import Number, check_options, option
from controllers.search_space import Tunable
from workbench.base.path import ReferencePath, wrap_angle


@dataclass(frozen=True)
class LateralPDConfig:
    """The feedback gains (the defaults: damping ratio 0.7 at a natural wavelength of 2 pi / sqrt(k_y) = 20 m); each
    field's unit, range and meaning in its metadata, which `workbench controllers --show lateral-pd` prints."""

    cte_gain_1pm2: float = option(
        0.1, "k_y, the feedback on the cross-track error", Number(0.0, 10.0, "1/m^2", low_open=True)
    )
    heading_gain_1pm: float = option(0.44, "k_psi, the feedback on the heading error", Number(0.0, 10.0, "1/m"))

    def __post_init__(self) -> None:
        check_options(self)


class LateralPD(Controller):
    name: ClassVar[str] = "lateral-pd"
    config_type: ClassVar[type] = LateralPDConfig
    #: What a tournament may tune (`workbench controllers --show lateral-pd --search-space`): the two gains, each
    #: range holding its default, with what it trades.
    search_space: ClassVar[tuple[Tunable, ...]] = (
        Tunable("cte_gain_1pm2", "log", 0.01, 1.0, reason="a stiffer pull onto the path (shorter natural wavelength) "
                "tracks tighter and steers harder"),
        Tunable("heading_gain_1pm", "linear", 0.1, 2.0, reason="more damping of the approach to the path; too much "
                "slows the correction of an offset"),
    )  # fmt: skip

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        self._tracker = path.tracker()
        self._diag = self._declare_diagnostics(("cte_m", "heading_error_rad"))

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        foot = self._tracker.update(measurement.x_m, measurement.y_m)
        heading_error = float(wrap_angle(measurement.yaw_rad - foot.heading_rad))
        cfg = self.config
        curvature = foot.curvature_1pm - cfg.cte_gain_1pm2 * foot.cte_m - cfg.heading_gain_1pm * heading_error
        self._diag[:] = (foot.cte_m, heading_error)
        return self.geometry.steer_wheel_for_curvature(curvature)


__all__ = ["LateralPD", "LateralPDConfig"]
