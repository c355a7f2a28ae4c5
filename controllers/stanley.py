"""Stanley (Thrun et al. 2006, the DARPA Grand Challenge winner): heading error plus a front-axle cross-track term.

The law: delta = (psi_path - psi) + atan(-k e / (k_soft + v)) [+ delta_ff], with e the front axle's signed CTE
(left of the path positive) and psi_path the path's heading at the front axle's foot point. The front-axle
position is the measured rear-axle position moved one wheelbase L along the heading.

The curvature feed-forward delta_ff (optional, off by default as in the original law) is what the law lacks to
hold a circle of curvature kappa at speed v with the rear axle, the reference point where the workbench measures
the CTE, on it. In a steady turn every point of the vehicle circles one centre, so the front axle's velocity is
tangent to the concentric circle through it, which is the path's tangent at its foot point: the heading term
psi_path - psi equals the direction gamma_f of the front axle's velocity in the vehicle frame, the whole
kinematic steer (atan(L kappa) when the rear axle holds the circle) included. The road wheels hold the turn at
delta_ss = gamma_f + alpha_f, alpha_f the front axle's slip angle. With the rear axle on the circle and its
velocity beta_r = -alpha_r off the heading (alpha_r the rear axle's slip angle), the front axle lies off the
circle by

    e_f = -(L^2 kappa + 2 L sin(beta_r)) / (1 + sqrt(1 + L^2 kappa^2 + 2 L kappa sin(beta_r)))

(outside it: |P - C| = sqrt(R^2 + L^2 + 2 L R sin(beta_r)) from the centre C). The law's steady command equals
delta_ss when delta_ff = alpha_f + atan(k e_f / (k_soft + v)): the front tyres' slip plus what cancels the law's
pull of the front axle back onto the path. The slip angles are the vehicle's single track's at a_y = v^2 kappa
(`SingleTrackParams.steady_slip_angles_rad`); a vehicle without tyres (or none given) has none, and then
delta_ff = atan(k e_f / (k_soft + v)) with e_f = -(sqrt(R^2 + L^2) - R). The path's curvature is taken at the
front axle's foot point (one wheelbase of preview). Adding atan(L kappa) instead would count the kinematic steer
twice: the heading term already holds it.

The two damping terms of the law's reference form (Hoffmann et al. 2007, "Autonomous automobile trajectory tracking
for off-road driving"), both off by default (0), in which case the command is the law above, bit for bit:

    delta = u - k_yaw (r - v kappa) + k_steer (delta_prev - delta)

with u the law above, r the measured yaw rate, v kappa the trajectory's yaw rate (the path's curvature at the
front axle's foot point times the speed), and delta_prev the last command returned (road-wheel angle; 0 after a
reset). The yaw-rate term damps the yaw motion the path does not ask for; the steering-damping term opposes a
change of the command, delta = (u - k_yaw (r - v kappa) + k_steer delta_prev) / (1 + k_steer): a first-order
filter on the command whose pole, k_steer / (1 + k_steer) per step, smooths a busy command at the cost of lag.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from controllers.base import Controller, Measurement
from controllers.config_checks import Flag, Number, check_options, option
from controllers.search_space import Tunable
from workbench.base.path import PathTracker, ReferencePath, wrap_angle
from workbench.vehicles.geometry import VehicleGeometry

if TYPE_CHECKING:
    from workbench.vehicles.base import VehicleModel
    from workbench.vehicles.single_track import SingleTrackParams


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
    yaw_rate_damping_s: float = option(
        0.0,
        "k_yaw, the yaw-rate damping: -k_yaw (r - v kappa) is added to the road-wheel angle (module docstring); larger "
        "damps yaw oscillation, too large lags the turn-in",
        Number(0.0, 10.0, "s", note="0: off"),
    )
    steering_damping: float = option(
        0.0,
        "k_steer, the steering damping: k_steer (delta_prev - delta) is added to the road-wheel angle (module "
        "docstring), a filter on the command; larger is smoother and slower",
        Number(0.0, 100.0, note="0: off"),
    )

    def __post_init__(self) -> None:
        check_options(self)


class Stanley(Controller[StanleyConfig]):
    """Stanley, registered as "stanley": heading error plus a front-axle cross-track term, with an optional
    curvature feed-forward (module docstring for the law), with the options of `StanleyConfig`."""

    name: ClassVar[str] = "stanley"
    config_type: ClassVar[type] = StanleyConfig
    search_space: ClassVar[tuple[Tunable, ...]] = (
        Tunable("gain_per_s", "log", 0.3, 5.0, reason="higher pulls the front axle onto the path faster; too high "
                "oscillates, most at speed and on a lagging steering"),
        Tunable("softening_mps", "log", 0.1, 10.0, reason="larger calms the cross-track term at low speed, at the "
                "cost of a weaker pull back onto the path"),
        Tunable("yaw_rate_damping_s", "linear", 0.0, 0.5, reason="damps yaw motion the path does not ask for; too "
                "much lags the turn-in and fights the steering's own lag"),
        Tunable("steering_damping", "linear", 0.0, 4.0, reason="smooths a busy command (less steering rate) at the "
                "cost of lag in every correction"),
    )  # fmt: skip

    def __init__(
        self, geometry: VehicleGeometry, config: StanleyConfig | None = None, vehicle: VehicleModel | None = None
    ) -> None:
        """As `Controller`; `vehicle` gives the curvature feed-forward its tyres' slip (none without it: the
        kinematic single track)."""
        super().__init__(geometry, config)
        self._tyres: SingleTrackParams | None = None
        if self.config.curvature_feedforward and vehicle is not None:
            self._tyres = vehicle.single_track().single_track

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        self._tracker: PathTracker = path.tracker(0.0)
        self._diag = self._declare_diagnostics(
            ("front_cte_m", "heading_term_rad", "cross_track_term_rad", "feedforward_term_rad")
        )

    def feedforward_rad(self, curvature_1pm: float, speed_mps: float) -> float:
        """delta_ff (road-wheel angle, rad): the term that makes the law's steady command on a circle of this
        curvature at this speed the one that holds the rear axle on it (module docstring).

        Parameters
        ----------
        curvature_1pm : float, 1/m
            The path's curvature at the reference point, positive turning left.
        speed_mps : float, m/s
            The vehicle's speed, >= 0.

        Returns
        -------
        float, rad
            The feed-forward road-wheel angle: the steady front slip angle (with the vehicle's tyres, else 0)
            plus the law's cross-track term, atan(gain x e / (softening + speed)), at the front cross-track error
            e of the rear axle held on the circle.
        """
        cfg, wheelbase = self.config, self.geometry.wheelbase_m
        alpha_f = alpha_r = 0.0
        if self._tyres is not None:
            alpha_f, alpha_r = self._tyres.steady_slip_angles_rad(speed_mps * speed_mps * curvature_1pm)
        lk, twice_l_sin_beta = wheelbase * curvature_1pm, -2.0 * wheelbase * math.sin(alpha_r)
        front_cte = -(wheelbase * lk + twice_l_sin_beta) / (
            1.0 + math.sqrt(1.0 + lk * lk + curvature_1pm * twice_l_sin_beta)
        )
        return alpha_f + math.atan2(cfg.gain_per_s * front_cte, cfg.softening_mps + speed_mps)

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        cfg, m, wheelbase = self.config, measurement, self.geometry.wheelbase_m
        front_x = m.x_m + wheelbase * math.cos(m.yaw_rad)
        front_y = m.y_m + wheelbase * math.sin(m.yaw_rad)
        foot = self._tracker.update(front_x, front_y)
        heading_term = wrap_angle(foot.heading_rad - m.yaw_rad)
        cross_track_term = math.atan2(-cfg.gain_per_s * foot.cte_m, cfg.softening_mps + m.speed_mps)
        feedforward = self.feedforward_rad(foot.curvature_1pm, m.speed_mps) if cfg.curvature_feedforward else 0.0
        road_wheel = heading_term + cross_track_term + feedforward
        if cfg.yaw_rate_damping_s:
            road_wheel -= cfg.yaw_rate_damping_s * (m.yaw_rate_rad_s - m.speed_mps * foot.curvature_1pm)
        if cfg.steering_damping:
            previous = self.held_command / self.geometry.steering_ratio  # the last command's road-wheel angle
            road_wheel = (road_wheel + cfg.steering_damping * previous) / (1.0 + cfg.steering_damping)
        self._diag[:] = (foot.cte_m, heading_term, cross_track_term, feedforward)
        limit = self.geometry.max_road_wheel_angle_rad
        return self.saturate(min(max(road_wheel, -limit), limit) * self.geometry.steering_ratio)


__all__ = ["Stanley", "StanleyConfig"]
