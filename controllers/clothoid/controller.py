"""The clothoid-based lateral controller (Shaju, Southward & Ahmadian 2024, Figure 2).

Each step (Figure 2): the start pose, the rear-axle centre along its course with the curvature kappa(0) of Eq. 3,
moved ahead by an optional prediction time (step 5); the lookahead (adaptive by Fréchet distance, fixed or
proportional to speed; `lookahead.py`) and the hyper-clothoid to the target (Eq. 3; `clothoid_fit.py`); kappa' x V
integrated into the curvature command under the speed-dependent curvature and curvature-rate limits (section 4;
`curvature_limits.py`); Ackermann, tan(phi) = L kappa, and the steering ratio; the lead filter of Eq. 6 against
the steering-to-curvature lag of Eq. 5 (at the controller rate, scheduled on speed; `lead_filter.py`).

Choices the paper leaves open are options (ClothoidConfig); the defaults, and why (measurements in README.md):
kappa(0) is the curvature actually driven, yaw rate / speed (the command or the steering's kinematic curvature
differ from it by understeer and lag, and the fit then leaves a steady offset in every bend); the clothoid starts
along the rear axle's course, yaw plus sideslip, the direction the vehicle moves in; the Fréchet threshold is the
paper's absolute one (off the path the search falls back to the shortest candidate, which returns fastest).

Added to the paper so that the loop keeps its margins on the vehicle it steers (issue 15):
  - a lookahead floor per speed: `loop_analysis.py` linearises the loop (Eq. 3 on the predicted pose, Figure 2's
    integrator, the lead filter, the lags of Eq. 5, sampling) and finds the shortest lookahead from which the
    phase and gain margins hold about a straight and an arc; the loop gain goes as L^-3, so the search's choice
    is followed with hysteresis and at a limited rate, slowly against L / V (`lookahead_filter.py`); a geometric
    ceiling keeps the target within max_target_turn_deg of the path's turn (ClothoidConfig), never below the floor;
  - two degrees of freedom (`path_feedforward.py`): feedback on Eq. 3's kappa' less the path's own clothoid's,
    and the path's curvature rate fed forward, so tracking needs no short lookaheads where the loop has no margin;
  - the steered vehicle's own lead filter, curvature limits and lags (`vehicle_tuning.py`, made by `tuning
    schedule --design margins`; the config holds them); without them, no lead filter and no floor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.base import Controller, Measurement
from controllers.clothoid.curvature_limits import CurvatureLimits
from controllers.clothoid.filter_schedule import FilterSchedule
from controllers.clothoid.lead_filter import DiscreteLeadFilter, PassThroughFilter, SteeringFilter
from controllers.clothoid.lookahead import (
    MAX_CURVE_POINTS,
    adaptive_search,
    candidate_count,
    evaluate_candidate,
    turn_limited_lookahead,
)
from controllers.clothoid.lookahead_filter import LookaheadFilter, LookaheadFilterSettings, require_rate
from controllers.clothoid.loop_analysis import LoopSettings, PlantLags, lookahead_floor
from controllers.clothoid.path_feedforward import FeedforwardTiming, two_degree_of_freedom_rate
from controllers.clothoid.pose_prediction import along_arc
from controllers.clothoid.vehicle_tuning import VehicleTuning
from controllers.config_checks import (
    check_bool,
    check_choice,
    check_number,
    check_optional_instance,
    check_optional_number,
)
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.path import PathTracker, ReferencePath
from workbench.vehicles.base import VehicleGeometry

LOOKAHEAD_MODES = ("adaptive", "fixed", "speed")
INITIAL_CURVATURE = ("yaw-rate", "command", "steering")
HEADINGS = ("course", "yaw")
THRESHOLD_MODES = ("excess", "absolute")
#: Below this speed (m/s) yaw rate / speed and the course angle are too noisy to use.
MIN_SPEED_MPS = 0.5
#: The lookahead floor is computed per band of this many km/h (and at least at the band's lower speed, 5 km/h).
FLOOR_SPEED_BAND_KMH = 5.0
#: A run moves to a lower band's (shorter) floor only this far (km/h) below the band's edge, to a higher one at its
#: edge: the lookahead follows a falling floor at once (`lookahead_filter.py`), so a speed hovering at an edge (its
#: noise, the speed loop's ripple) must not switch the floor, and the loop gain with it, to and fro.
FLOOR_BAND_HYSTERESIS_KMH = 1.0
#: Longest lookahead (m) the floor search considers when the configured range has no margin at a speed.
MAX_FLOOR_LOOKAHEAD_M = 40.0
#: Lateral acceleration (g) of the arc about which the floor is checked besides the straight (the speed profile's
#: 0.3 g bound, with margin), capped by the curvature limit.
FLOOR_ARC_LATERAL_ACCEL_G = 0.4
#: The longest lookahead (m) the options allow.
MAX_LOOKAHEAD_M = 200.0
#: The controller's own diagnostics (`ctrl_*` columns), the same every step: zero until the first step.
DIAGNOSTIC_KEYS = (
    "lookahead_m",
    "searched_lookahead_m",
    "lookahead_floor_m",
    "lookahead_ceiling_m",
    "frechet_m",
    "curvature_rate_1pm2",
    "clothoid_curvature_rate_1pm2",
    "reference_curvature_rate_1pm2",
    "feedforward_curvature_rate_1pm2",
    "clothoid_length_m",
    "end_error_m",
    "fit_status",
    "evaluations",
    "initial_curvature_1pm",
    "curvature_cmd_1pm",
    "steer_unfiltered_rad",
)


@dataclass(frozen=True)
class ClothoidConfig:
    """Options of the clothoid controller (the paper's values where it gives them).

    lookahead_mode: "adaptive" (Fréchet, section 3), "fixed" (fixed_lookahead_m) or "speed" (lookahead_gain_s x
    speed, clipped to the range); min/max_lookahead_m: the range (m; the paper: 5-20 m; the analysis floor raises
    the lower end, and the upper one with it where needed); lookahead_step_m: the grid of the adaptive search (m);
    min_preview_time_s: raises the lower end of the range to this time x speed (s; 0: off); lookahead_hysteresis_m,
    max_lookahead_growth_m_per_m, max_lookahead_shrink_m_per_m: how the search's choice is followed
    (`lookahead_filter.py`; None: at once); min_phase_margin_deg, min_gain_margin_db: the margins the lookahead
    floor keeps (`loop_analysis.py`; 0 and 0: no floor); max_target_turn_deg: the lookahead's geometric ceiling, no
    target farther round a bend than the path turning this much from the foot point (deg; 0: none; never below the
    floor): an offset of the vehicle shows at a target theta round the bend as offset x cos(theta), and Eq. 3's gain
    on it falls alike (0.46 of a straight's at 60 deg, none at 90 deg), which the margins do not see;
    frechet_threshold_m: the adaptive threshold (m; the paper: 0.5 m) and threshold_mode how it applies ("excess" of
    |CTE| or "absolute"; module docstring); frechet_point_spacing_m: sampling of the curves compared (m);
    tolerance_x_m, tolerance_y_m: delta_x, delta_y of Eq. 3 (m); max_curvature_rate_1pm2: saturation of the
    clothoid's kappa' (1/m^2); initial_curvature: kappa(0)
    of Eq. 3, "yaw-rate", "command" or "steering"; heading: "course" or "yaw"; prediction_time_s: pose prediction
    (s; 0: off); known_delay_s: the loop's dead time the controller knows, measurement latency (the pose measured
    is that long old) plus actuation dead time (a command reaches the steering that much later) (s; 0: none): the
    pose is predicted over prediction_time_s + known_delay_s, the reference pose and the feed-forward point move
    ahead with it, and the lookahead floor's loop analysis has it as a pure delay (`loop_analysis.LoopSettings`);
    path_feedforward: the two-degree-of-freedom form (`path_feedforward.py`; False: Eq. 3 alone);
    feedforward_window_m: the window the path's curvature rate is averaged over (m); feedforward_time_s,
    reference_lead_s: its timings (s; None: from the vehicle's identified lags); tuning: the steered vehicle's own
    tuning (lead filter, curvature limits, identified lags; `tuning.own_tuning.tuning_for` finds it, and
    `tuned_controller` fills it in; None: untuned, no lead filter and no lookahead floor unless given below; in a
    config file, `tuning_dir` names a tuning directory); lead_filter: the lead filter's schedule (None: the
    tuning's; in a config file or `--set`, `filter_file` names a file of the `tuning design-lead` or `tuning
    schedule` format, read when the config is loaded); use_lead_filter: False switches the filter off;
    curvature_limits: the curvature limits (None: the tuning's, else limits from the geometry,
    `CurvatureLimits.default_for`; in a file, `limits_file` names a CSV of the `tuning rollover-limits` format).
    """

    lookahead_mode: str = "adaptive"
    min_lookahead_m: float = 5.0
    max_lookahead_m: float = 20.0
    lookahead_step_m: float = 0.5
    min_preview_time_s: float = 0.0
    lookahead_hysteresis_m: float = 0.5
    max_lookahead_growth_m_per_m: float | None = 0.3
    max_lookahead_shrink_m_per_m: float | None = 0.5
    min_phase_margin_deg: float = 45.0
    min_gain_margin_db: float = 6.0
    max_target_turn_deg: float = 60.0
    fixed_lookahead_m: float = 10.0
    lookahead_gain_s: float = 1.0
    frechet_threshold_m: float = 0.02
    threshold_mode: str = "absolute"
    frechet_point_spacing_m: float = 0.5
    tolerance_x_m: float = 0.5
    tolerance_y_m: float = 0.5
    max_curvature_rate_1pm2: float = 0.05
    initial_curvature: str = "yaw-rate"
    heading: str = "course"
    prediction_time_s: float = 0.2
    known_delay_s: float = 0.0
    path_feedforward: bool = True
    feedforward_window_m: float = 6.0
    feedforward_time_s: float | None = None
    reference_lead_s: float | None = None
    tuning: VehicleTuning | None = None
    lead_filter: FilterSchedule | None = None
    use_lead_filter: bool = True
    curvature_limits: CurvatureLimits | None = None

    def __post_init__(self) -> None:
        # Every field on its own first (`config_checks.py`), then what relates them.
        check_choice("lookahead_mode", self.lookahead_mode, LOOKAHEAD_MODES)
        check_choice("initial_curvature", self.initial_curvature, INITIAL_CURVATURE)
        check_choice("heading", self.heading, HEADINGS)
        check_choice("threshold_mode", self.threshold_mode, THRESHOLD_MODES)
        check_number("prediction_time_s", self.prediction_time_s, 0.0, 2.0, "s")
        check_number("known_delay_s", self.known_delay_s, 0.0, 1.0, "s", note="0: none")
        check_number("min_preview_time_s", self.min_preview_time_s, 0.0, 10.0, "s")
        check_number("lookahead_hysteresis_m", self.lookahead_hysteresis_m, 0.0, 50.0, "m")
        require_rate("max_lookahead_growth_m_per_m", self.max_lookahead_growth_m_per_m)
        require_rate("max_lookahead_shrink_m_per_m", self.max_lookahead_shrink_m_per_m)
        check_number("min_phase_margin_deg", self.min_phase_margin_deg, 0.0, 89.0, "deg")
        check_number("min_gain_margin_db", self.min_gain_margin_db, 0.0, 40.0, "dB")
        check_number("max_target_turn_deg", self.max_target_turn_deg, 0.0, 180.0, "deg", note="0: no ceiling")
        check_number("min_lookahead_m", self.min_lookahead_m, 0.5, MAX_LOOKAHEAD_M, "m")
        check_number("max_lookahead_m", self.max_lookahead_m, 0.5, MAX_LOOKAHEAD_M, "m")
        check_number("fixed_lookahead_m", self.fixed_lookahead_m, 0.5, MAX_LOOKAHEAD_M, "m")
        check_number("lookahead_gain_s", self.lookahead_gain_s, 0.0, 100.0, "s", low_open=True)
        check_number("frechet_threshold_m", self.frechet_threshold_m, 0.0, 100.0, "m", low_open=True)
        check_number("frechet_point_spacing_m", self.frechet_point_spacing_m, 0.0, 50.0, "m", low_open=True)
        check_number("tolerance_x_m", self.tolerance_x_m, 0.0, 100.0, "m", low_open=True)
        check_number("tolerance_y_m", self.tolerance_y_m, 0.0, 100.0, "m", low_open=True)
        check_number("max_curvature_rate_1pm2", self.max_curvature_rate_1pm2, 0.0, 10.0, "1/m^2", low_open=True)
        check_number("lookahead_step_m", self.lookahead_step_m, 0.05, 50.0, "m")
        check_bool("path_feedforward", self.path_feedforward)
        check_number("feedforward_window_m", self.feedforward_window_m, 0.1, 100.0, "m")
        for name in ("feedforward_time_s", "reference_lead_s"):
            check_optional_number(name, getattr(self, name), 0.0, 5.0, "s", none_means="from the vehicle's lags")
        check_optional_instance("tuning", self.tuning, VehicleTuning)
        check_optional_instance("lead_filter", self.lead_filter, FilterSchedule)
        check_bool("use_lead_filter", self.use_lead_filter)
        check_optional_instance("curvature_limits", self.curvature_limits, CurvatureLimits)
        if self.max_lookahead_m < self.min_lookahead_m:
            raise WorkbenchInputError(
                f"max_lookahead_m must be >= min_lookahead_m = {value_text(self.min_lookahead_m)} m; "
                f"got {value_text(self.max_lookahead_m)}"
            )
        steps = (self.max_lookahead_m - self.min_lookahead_m) / self.lookahead_step_m
        if steps > 1000:
            raise WorkbenchInputError(
                f"lookahead range / lookahead_step_m gives {steps:.0f} candidates; at most 1000 are allowed"
            )
        # the curves compared hold int(lookahead / spacing) + 1 points, at most MAX_CURVE_POINTS
        if self.max_lookahead_m / self.frechet_point_spacing_m >= MAX_CURVE_POINTS:
            raise WorkbenchInputError(
                f"frechet_point_spacing_m must be > max_lookahead_m / {MAX_CURVE_POINTS} = "
                f"{self.max_lookahead_m / MAX_CURVE_POINTS:g} m; got {value_text(self.frechet_point_spacing_m)}"
            )


class ClothoidController(Controller):
    """The clothoid controller (Figure 2). Build once for a vehicle and a ClothoidConfig; `reset` for each path.

    Its tuning (the lead filter, the curvature limits and the identified lags the lookahead floor and the
    feed-forward timing are computed from) is the config's (`ClothoidConfig.tuning`); a `vehicle` given without one
    is refused, so that a controller meant for a vehicle never runs untuned by mistake
    (`tuning.own_tuning.tuned_controller` builds it with the vehicle's own).
    """

    name: ClassVar[str] = "clothoid"
    config_type: ClassVar[type] = ClothoidConfig

    def __init__(
        self, geometry: VehicleGeometry, config: ClothoidConfig | None = None, vehicle: object | None = None
    ) -> None:
        super().__init__(geometry, config)
        cfg = self.config
        if vehicle is not None and cfg.tuning is None:
            raise WorkbenchInputError(
                f"the clothoid controller for vehicle {getattr(vehicle, 'name', vehicle)!r} needs that vehicle's "
                "tuning: build it with tuning.own_tuning.tuned_controller('clothoid', vehicle[, config]), or give "
                "ClothoidConfig(tuning=tuning.own_tuning.tuning_for(vehicle)); for an untuned controller pass no "
                "vehicle"
            )
        self.tuning: VehicleTuning | None = cfg.tuning
        if cfg.curvature_limits is not None:
            self.limits = cfg.curvature_limits
        elif self.tuning is not None:
            self.limits = self.tuning.limits
        else:
            self.limits = CurvatureLimits.default_for(geometry)
        self.filter_schedule: FilterSchedule | None = None
        if cfg.use_lead_filter:
            if cfg.lead_filter is not None:
                self.filter_schedule = cfg.lead_filter
            elif self.tuning is not None:
                self.filter_schedule = self.tuning.filter_schedule
        self._buffers = np.empty((4, MAX_CURVE_POINTS))
        top = max(cfg.max_lookahead_m, MAX_FLOOR_LOOKAHEAD_M)
        self._scores = np.empty(candidate_count(cfg.min_lookahead_m, top, cfg.lookahead_step_m))
        self._filters: dict[int, DiscreteLeadFilter] = {}
        self._floors: dict[int, float] = {}  # per speed band, for the sample time _floors_dt
        self._floors_dt: float | None = None
        self._choice = LookaheadFilter(
            LookaheadFilterSettings(
                cfg.lookahead_hysteresis_m, cfg.max_lookahead_growth_m_per_m, cfg.max_lookahead_shrink_m_per_m
            )
        )

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        if float(sample_time_s) != self._floors_dt:  # the floors depend on the sample time, not on the path
            self._floors, self._floors_dt = {}, float(sample_time_s)
        self._dt = float(sample_time_s)
        self._tracker: PathTracker = path.tracker(0.0)
        self._here: PathTracker = path.tracker(0.0)
        self._kappa_cmd: float | None = None
        self._filters = {}
        self._filter: SteeringFilter = PassThroughFilter()
        self._filter_speed_kmh = -1
        self._choice.reset()
        self._held_band: int | None = None  # the speed band whose floor applies (_floor_band)
        self._diag = self._declare_diagnostics(DIAGNOSTIC_KEYS)
        if path.speed_mps is not None:  # the floors of the planned speeds now, not inside a step (~0.1 s per band)
            for speed_mps in np.unique(np.round(path.speed_mps * 3.6 / FLOOR_SPEED_BAND_KMH)) * FLOOR_SPEED_BAND_KMH:
                self.lookahead_floor_m(float(speed_mps) / 3.6)

    def _lead_filter(self, speed_mps: float) -> SteeringFilter:
        """The lead filter for this speed: the schedule's filter at the nearest whole km/h (discretised once per
        km/h and cached), continuing from the previous filter's state."""
        if self.filter_schedule is None:
            return self._filter
        speed_kmh = round(speed_mps * 3.6) if len(self.filter_schedule.speeds_kmh) > 1 else 0
        if speed_kmh != self._filter_speed_kmh:
            new = self._filters.get(speed_kmh)
            if new is None:
                new = DiscreteLeadFilter(self.filter_schedule.at_speed(float(speed_kmh)), self._dt)
                self._filters[speed_kmh] = new
            if self._filter_speed_kmh >= 0:
                new.continue_from(self._filter)
            self._filter, self._filter_speed_kmh = new, speed_kmh
        return self._filter

    def plant_lags(self, speed_kmh: float) -> PlantLags | None:
        """The vehicle's identified lags at this speed (None without a tuning)."""
        if self.tuning is None:
            return None
        return PlantLags(self.tuning.lag_at(speed_kmh), self.tuning.measured_lag_at(speed_kmh))

    def loop_settings(self, speed_kmh: float) -> LoopSettings:
        """What the controller does at this speed, for `loop_analysis`."""
        lead = self.filter_schedule.at_speed(speed_kmh) if self.filter_schedule is not None else None
        return LoopSettings(self._dt, self.config.prediction_time_s, lead=lead, known_delay_s=self.config.known_delay_s)

    def lookahead_floor_m(self, speed_mps: float) -> float:
        """The shortest lookahead (m) that keeps the configured margins at this speed (per FLOOR_SPEED_BAND_KMH band,
        computed once per band and run; min_lookahead_m without a tuning or with the margins set to 0). The analysis
        is cached on all of `loop_settings`, the known delay included."""
        return self._band_floor_m(max(1, round(speed_mps * 3.6 / FLOOR_SPEED_BAND_KMH)))

    def _band_floor_m(self, band: int) -> float:
        """lookahead_floor_m of the speed band `band` (its speed band x FLOOR_SPEED_BAND_KMH)."""
        cfg = self.config
        floor = self._floors.get(band)
        if floor is None:
            speed_kmh = band * FLOOR_SPEED_BAND_KMH
            lags = self.plant_lags(speed_kmh)
            if lags is None or (cfg.min_phase_margin_deg <= 0.0 and cfg.min_gain_margin_db <= 0.0):
                floor = cfg.min_lookahead_m
            else:
                v = speed_kmh / 3.6
                kappa_max, _ = self.limits.at_speed(v)
                arc = min(kappa_max, FLOOR_ARC_LATERAL_ACCEL_G * G_MPS2 / v**2)
                floor = lookahead_floor(
                    lags, self.loop_settings(speed_kmh), v, cfg.min_lookahead_m,
                    max(cfg.max_lookahead_m, MAX_FLOOR_LOOKAHEAD_M), cfg.lookahead_step_m, (0.0, arc),
                    cfg.min_phase_margin_deg, cfg.min_gain_margin_db,
                )  # fmt: skip
            self._floors[band] = floor
        return floor

    def feedforward_timing(self, speed_mps: float) -> FeedforwardTiming:
        """The feed-forward's timing at this speed: the options, else from the identified lags (path_feedforward.py):
        feed-forward time = the low-frequency delay of lead filter and path lag; reference lead = the path lag's less
        the measured (yaw-rate) lag's, within [0, prediction time]; K of the path lag. A known delay adds to the
        feed-forward time (the steering commanded now takes effect that much later, from a pose that much older)
        and to the prediction time."""
        cfg, speed_kmh = self.config, speed_mps * 3.6
        lags = self.plant_lags(speed_kmh)
        lead = self.filter_schedule.at_speed(speed_kmh) if self.filter_schedule is not None else None
        path_delay = 0.0 if lags is None else lags.path.group_delay_s
        measured_delay = path_delay if lags is None or lags.measured is None else lags.measured.group_delay_s
        lead_delay = 0.0 if lead is None else lead.group_delay_s
        ff = cfg.feedforward_time_s if cfg.feedforward_time_s is not None else max(0.0, path_delay + lead_delay)
        ff += cfg.known_delay_s
        ref = cfg.reference_lead_s
        if ref is None:
            ref = min(max(path_delay - measured_delay, 0.0), self._prediction_horizon_s)
        gain = 1.0 if lags is None else lags.path.steady_state_gain
        return FeedforwardTiming(min(ff, 5.0), min(ref, 5.0), gain)

    def _initial_curvature(self, m: Measurement, steering_kappa: float) -> float:
        """kappa(0) of Eq. 3 (see ClothoidConfig.initial_curvature)."""
        mode = self.config.initial_curvature
        if mode == "yaw-rate" and m.speed_mps > MIN_SPEED_MPS:
            return m.yaw_rate_rad_s / m.speed_mps
        if mode == "steering":
            return steering_kappa
        return self._kappa_cmd

    @property
    def _prediction_horizon_s(self) -> float:
        """How far ahead the pose is predicted (s): prediction_time_s plus the known delay."""
        return self.config.prediction_time_s + self.config.known_delay_s

    def _start_pose(self, m: Measurement, kappa0: float) -> tuple[float, float, float]:
        """(x, y, heading) the clothoid starts from: the rear axle, heading along its course (or body yaw), moved
        ahead by prediction_time_s + known_delay_s on the current curvature (Figure 2, step 5)."""
        cfg = self.config
        heading = m.yaw_rad
        if cfg.heading == "course" and m.vx_mps > MIN_SPEED_MPS:
            heading += math.atan2(m.vy_mps, m.vx_mps)
        horizon = self._prediction_horizon_s
        if horizon > 0.0:
            return along_arc(m.x_m, m.y_m, heading, kappa0, m.speed_mps * horizon)
        return m.x_m, m.y_m, heading

    def _floor_band(self, speed_mps: float) -> int:
        """The speed band whose floor applies this step: the nearest, but a lower one only once the speed is
        FLOOR_BAND_HYSTERESIS_KMH below the held band's lower edge."""
        x = speed_mps * 3.6 / FLOOR_SPEED_BAND_KMH
        band, held = max(1, round(x)), self._held_band
        if held is not None and band < held and x > held - 0.5 - FLOOR_BAND_HYSTERESIS_KMH / FLOOR_SPEED_BAND_KMH:
            band = held
        self._held_band = band
        return band

    def _lookahead(self, path: ReferencePath, foot_index: float, cte_m: float, pose, kappa0: float, speed_mps: float):
        """(lookahead m, the adaptive search's choice m, the floor m, the ceiling m, number of candidates
        evaluated)."""
        cfg = self.config
        floor = self._band_floor_m(self._floor_band(speed_mps))
        floor = max(floor, cfg.min_lookahead_m, cfg.min_preview_time_s * speed_mps)
        top = max(cfg.max_lookahead_m, floor)
        if cfg.lookahead_mode == "fixed":
            return cfg.fixed_lookahead_m, cfg.fixed_lookahead_m, floor, top, 0
        if cfg.max_target_turn_deg > 0.0:  # the geometric ceiling (ClothoidConfig.max_target_turn_deg)
            ceiling = turn_limited_lookahead(
                path.x_m, path.y_m, path.heading_rad, path.closed, foot_index, pose[0], pose[1],
                math.radians(cfg.max_target_turn_deg), top,
            )  # fmt: skip
            top = max(floor, ceiling)
        if cfg.lookahead_mode == "speed":
            lookahead = min(max(cfg.lookahead_gain_s * speed_mps, floor), top)
            return lookahead, lookahead, floor, top, 0
        threshold = cfg.frechet_threshold_m + (abs(cte_m) if cfg.threshold_mode == "excess" else 0.0)
        x, y, heading = pose
        chosen, evaluations = adaptive_search(
            path.x_m, path.y_m, path.closed, foot_index, x, y, heading, kappa0, floor, top,
            cfg.lookahead_step_m, threshold, cfg.tolerance_x_m, cfg.tolerance_y_m, cfg.max_curvature_rate_1pm2,
            cfg.frechet_point_spacing_m, self._buffers, self._scores,
        )  # fmt: skip
        lookahead = self._choice.step(chosen, floor, top, speed_mps * self._dt)
        return lookahead, chosen, floor, top, evaluations

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        cfg, g, m = self.config, self.geometry, measurement
        steering_kappa = math.tan(m.steer_wheel_rad / g.steering_ratio) / g.wheelbase_m
        if self._kappa_cmd is None:  # first step: continue from the vehicle's current steering
            self._kappa_cmd = steering_kappa
            self._lead_filter(m.speed_mps).reset(m.steer_wheel_rad)
        kappa_max, rate_max = self.limits.at_speed(m.speed_mps)
        kappa0 = min(max(self._initial_curvature(m, steering_kappa), -kappa_max), kappa_max)

        # Sections 2 and 3: the lookahead, then the hyper-clothoid to the target (Eq. 3).
        pose = self._start_pose(m, kappa0)
        foot = self._tracker.update(pose[0], pose[1])
        foot_index = foot.s_m / path.spacing_m
        lookahead, searched, floor, ceiling, evaluations = self._lookahead(
            path, foot_index, foot.cte_m, pose, kappa0, m.speed_mps
        )
        frechet, kdot, length, tx, ty, ex, ey, status = evaluate_candidate(
            path.x_m, path.y_m, path.closed, foot_index, *pose, kappa0, lookahead, cfg.max_curvature_rate_1pm2,
            cfg.frechet_point_spacing_m, self._buffers,
        )  # fmt: skip
        clothoid_kdot = reference_kdot = feedforward_kdot = kdot
        if cfg.path_feedforward:  # path_feedforward.py: feedback relative to the path's own clothoid, plus its rate
            kdot, reference_kdot, feedforward_kdot = two_degree_of_freedom_rate(
                kdot, path, self._here.update(m.x_m, m.y_m), (tx, ty), m.speed_mps, self._prediction_horizon_s,
                self.feedforward_timing(m.speed_mps), cfg.feedforward_window_m,
            )  # fmt: skip

        # Figure 2: kappa' x V integrated to curvature, under the rate and curvature limits (section 4).
        rate = min(max(kdot * m.speed_mps, -rate_max), rate_max)
        self._kappa_cmd = min(max(self._kappa_cmd + rate * self._dt, -kappa_max), kappa_max)
        road_wheel = math.atan(g.wheelbase_m * self._kappa_cmd)  # Ackermann: tan(phi) = L kappa
        steer = road_wheel * g.steering_ratio
        command = self.saturate(self._lead_filter(m.speed_mps).step(steer))  # Eq. 6
        self._diag[:] = (  # in the order of DIAGNOSTIC_KEYS
            lookahead,
            searched,
            floor,
            ceiling,
            frechet,
            kdot,
            clothoid_kdot,
            reference_kdot,
            feedforward_kdot,
            length,
            math.hypot(ex - tx, ey - ty),
            float(status),
            float(evaluations),
            kappa0,
            self._kappa_cmd,
            steer,
        )
        return command
