"""The clothoid-based lateral controller (Shaju, Southward & Ahmadian 2024, Figure 2).

Each step:
  1. the start pose: the rear-axle centre, heading along its course, and its curvature kappa(0) (Eq. 3), moved
     ahead by an optional prediction time on that curvature (Figure 2, step 5);
  2. the lookahead (adaptive by Fréchet distance, fixed, or proportional to speed; `lookahead.py`) and the
     hyper-clothoid from the start pose to the target (Eq. 3; `clothoid_fit.py`);
  3. kappa' x V integrated into the curvature command, under the speed-dependent curvature-rate and curvature
     limits (section 4; `curvature_limits.py`);
  4. road-wheel angle by Ackermann, tan(phi) = L kappa; steering-wheel angle by the steering ratio;
  5. the lead filter (Eq. 6, discretised at the controller rate, scheduled on speed when its file holds a
     schedule; `lead_filter.py`, `filter_file.py`) against the lag between steering wheel and path curvature
     (Eq. 5), unless switched off.

Three choices the paper leaves open, each an option (ClothoidConfig), defaulting to what tracked best on this
repository's loaded tractor-semitrailer (measurements in README.md):
  - kappa(0) is the curvature the vehicle actually drives, yaw rate / speed ("yaw-rate"). The integrator's own
    command ("command") or the kinematic curvature of the measured steering ("steering") differ from it by the
    vehicle's understeer and lag, and the fit then settles on a circle through the target with the wrong
    curvature: a steady offset in every bend (about 1 m on the figure8 at 30 km/h with the truck).
  - the clothoid starts along the rear axle's course (yaw plus its sideslip), the direction the vehicle moves in,
    not its body yaw ("course"; the truck's tandem slips up to 3 degrees at 30 km/h).
  - the Fréchet threshold applies to the distance in excess of the current |CTE| ("excess"): the Fréchet distance
    is never below |CTE| (the curves start that far apart), so with the absolute threshold of the paper
    ("absolute") no lookahead qualifies once |CTE| exceeds it, and the controller falls back to the candidate of
    least Fréchet distance, the shortest and most aggressive, which on a lagging plant grows the error further.

Two choices for speeds above the paper's 30 km/h (the paper's future work), also options:
  - the lower end of the lookahead range is a preview time, min_preview_time_s x speed, not only metres. Linearised
    about a straight path (lateral offset y, heading error psi, curvature kappa, lookahead L from the predicted pose
    D = L + V t_p ahead), the hyper-clothoid of Eq. 3 has kappa' = -(6 / L^3) (y + psi D + kappa D^2 / 2), so the
    loop closed through the integrator of Figure 2 is d kappa_cmd / dt = -(6 V / L^3) (y + psi D + kappa D^2 / 2):
    with y' = V psi and psi' = V kappa (a lag-free plant) its poles are V / L times those of a fixed polynomial (for
    a given V t_p / L): the preview time L / V sets the loop's speed. At 30 km/h the paper's 5 m floor is 0.6 s;
    held at 5 m at 60 km/h it is 0.3 s, twice as fast a loop around a plant whose lag (Eq. 5) has slowed (omega_n
    4.3 -> 3.4 rad/s on the loaded truck): the loop oscillates in the steering-rate limit whenever the adaptive
    search picks the floor (a fixed 5 m lookahead on the truck's dlc: max |CTE| 0.04-0.05 m at 30 km/h, 1.0-3.9 m
    at 60 and 80 km/h, whichever lead filter). The default floor of 0.6 s keeps the paper's 5 m at 30 km/h and
    below; it suits the truck (a plant with a faster lag, e.g. the dynamic bicycle car, tracks better at 60 km/h
    with 0: 0.11 against 0.20 m on the dlc).
  - the adaptive lookahead may shorten at once but grows by at most max_lookahead_growth_m_per_m metres per metre
    travelled. The Fréchet search alone lets it jump between the ends of its range from one step to the next (on
    the dlc at 60 km/h, by 0.4-0.7 m per 20 ms step on average): the loop's gain goes as L^-3 (above), so each jump
    is a 64-fold gain change and the curvature rate kappa' jumps with it. Shortening stays immediate (the search
    shortens when the path ahead bends away from the clothoid); growing is limited relative to distance travelled,
    i.e. relative to the loop's own time scale L / V (d ln L / dt <= growth x V / L).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np

from controllers.base import Controller, Measurement
from controllers.clothoid.curvature_limits import CurvatureLimits
from controllers.clothoid.filter_file import DEFAULT_FILTER, FilterSchedule, read_filter_file
from controllers.clothoid.lead_filter import DiscreteLeadFilter, PassThroughFilter, SteeringFilter
from controllers.clothoid.lookahead import MAX_CURVE_POINTS, adaptive_search, candidate_count, evaluate_candidate
from workbench.errors import WorkbenchInputError, require_in_range, require_positive
from workbench.path import PathTracker, ReferencePath
from workbench.vehicles.base import VehicleGeometry

LOOKAHEAD_MODES = ("adaptive", "fixed", "speed")
INITIAL_CURVATURE = ("yaw-rate", "command", "steering")
HEADINGS = ("course", "yaw")
THRESHOLD_MODES = ("excess", "absolute")
#: Below this speed (m/s) yaw rate / speed and the course angle are too noisy to use.
MIN_SPEED_MPS = 0.5
#: Largest max_lookahead_growth_m_per_m accepted (m of lookahead per m travelled).
MAX_GROWTH_M_PER_M = 100.0


@dataclass(frozen=True)
class ClothoidConfig:
    """Options of the clothoid controller (the paper's values where it gives them).

    lookahead_mode: "adaptive" (Fréchet, section 3), "fixed" (fixed_lookahead_m) or "speed" (lookahead_gain_s x
    speed, clipped to the range); min/max_lookahead_m: the range (m; the paper: 5-20 m); lookahead_step_m: the
    grid of the adaptive search (m); min_preview_time_s: raises the lower end of the range to this time x speed
    (s; 0: off, the paper's 5 m at every speed; module docstring); max_lookahead_growth_m_per_m: the most the
    lookahead grows per metre travelled (m/m, > 0; None: unlimited, as in the paper; it always shortens at once;
    module docstring); frechet_threshold_m: the adaptive threshold (m; the paper: 0.5 m) and threshold_mode how it
    applies ("excess" of |CTE| or "absolute"; module docstring); frechet_point_spacing_m: sampling of the curves
    compared (m); tolerance_x_m, tolerance_y_m: delta_x, delta_y of Eq. 3 (m); max_curvature_rate_1pm2: saturation
    of the clothoid's kappa' (1/m^2); initial_curvature: kappa(0) of Eq. 3, "yaw-rate", "command" or "steering";
    heading: "course" or "yaw"; prediction_time_s: pose prediction (s; 0: off); filter_file: lead filter
    (JSON/TOML, the `tuning design-lead` format; None: DEFAULT_FILTER); use_lead_filter: False switches the filter
    off; limits_file: curvature limits CSV (the `tuning rollover-limits` format; None: limits from the vehicle's
    geometry, `CurvatureLimits.default_for`).
    """

    lookahead_mode: str = "adaptive"
    min_lookahead_m: float = 5.0
    max_lookahead_m: float = 20.0
    lookahead_step_m: float = 0.5
    min_preview_time_s: float = 0.6
    max_lookahead_growth_m_per_m: float | None = 0.3
    fixed_lookahead_m: float = 10.0
    lookahead_gain_s: float = 1.0
    frechet_threshold_m: float = 0.02
    threshold_mode: str = "excess"
    frechet_point_spacing_m: float = 0.5
    tolerance_x_m: float = 0.5
    tolerance_y_m: float = 0.5
    max_curvature_rate_1pm2: float = 0.05
    initial_curvature: str = "yaw-rate"
    heading: str = "course"
    prediction_time_s: float = 0.2
    filter_file: Path | None = None
    use_lead_filter: bool = True
    limits_file: Path | None = None

    def __post_init__(self) -> None:
        if self.lookahead_mode not in LOOKAHEAD_MODES:
            raise WorkbenchInputError(
                f"lookahead_mode must be one of {', '.join(LOOKAHEAD_MODES)}; got {self.lookahead_mode!r}"
            )
        if self.initial_curvature not in INITIAL_CURVATURE:
            raise WorkbenchInputError(
                f"initial_curvature must be one of {', '.join(INITIAL_CURVATURE)}; got {self.initial_curvature!r}"
            )
        for name, allowed in (("heading", HEADINGS), ("threshold_mode", THRESHOLD_MODES)):
            if getattr(self, name) not in allowed:
                raise WorkbenchInputError(f"{name} must be one of {', '.join(allowed)}; got {getattr(self, name)!r}")
        require_in_range("prediction_time_s", self.prediction_time_s, 0.0, 2.0, "s")
        require_in_range("min_preview_time_s", self.min_preview_time_s, 0.0, 10.0, "s")
        growth = self.max_lookahead_growth_m_per_m
        if growth is not None and (
            isinstance(growth, bool) or not isinstance(growth, int | float) or not 0.0 < growth <= MAX_GROWTH_M_PER_M
        ):
            raise WorkbenchInputError(
                f"max_lookahead_growth_m_per_m must be None (unlimited) or a number in (0, {MAX_GROWTH_M_PER_M:g}] "
                f"m per m travelled; got {growth!r}"
            )
        require_in_range("min_lookahead_m", self.min_lookahead_m, 0.5, 200.0, "m")
        require_in_range("max_lookahead_m", self.max_lookahead_m, self.min_lookahead_m, 200.0, "m")
        require_in_range("fixed_lookahead_m", self.fixed_lookahead_m, 0.5, 200.0, "m")
        require_positive("lookahead_gain_s", self.lookahead_gain_s)
        require_positive("frechet_threshold_m", self.frechet_threshold_m)
        require_positive("tolerance_x_m", self.tolerance_x_m)
        require_positive("tolerance_y_m", self.tolerance_y_m)
        require_positive("max_curvature_rate_1pm2", self.max_curvature_rate_1pm2)
        require_in_range("lookahead_step_m", self.lookahead_step_m, 0.05, 50.0, "m")
        steps = (self.max_lookahead_m - self.min_lookahead_m) / self.lookahead_step_m
        if steps > 1000:
            raise WorkbenchInputError(
                f"lookahead range / lookahead_step_m gives {steps:.0f} candidates; at most 1000 are allowed"
            )
        spacing_ok = self.max_lookahead_m / self.frechet_point_spacing_m < MAX_CURVE_POINTS
        require_positive("frechet_point_spacing_m", self.frechet_point_spacing_m)
        if not spacing_ok:
            raise WorkbenchInputError(
                f"frechet_point_spacing_m must be >= max_lookahead_m / {MAX_CURVE_POINTS - 1} = "
                f"{self.max_lookahead_m / (MAX_CURVE_POINTS - 1):.3g} m; got {self.frechet_point_spacing_m!r}"
            )


class ClothoidController(Controller):
    """The clothoid controller (Figure 2). Build once for a vehicle and a ClothoidConfig; `reset` for each path."""

    name: ClassVar[str] = "clothoid"
    config_type: ClassVar[type] = ClothoidConfig

    def __init__(
        self, geometry: VehicleGeometry, config: ClothoidConfig | None = None, vehicle: object | None = None
    ) -> None:
        super().__init__(geometry, config)
        cfg = self.config
        self.limits = (
            CurvatureLimits.read_csv(cfg.limits_file, geometry)
            if cfg.limits_file
            else CurvatureLimits.default_for(geometry)
        )
        self.filter_schedule: FilterSchedule = (
            read_filter_file(cfg.filter_file) if cfg.filter_file else FilterSchedule.single(DEFAULT_FILTER)
        )
        self._buffers = np.empty((4, MAX_CURVE_POINTS))
        self._scores = np.empty(candidate_count(cfg.min_lookahead_m, cfg.max_lookahead_m, cfg.lookahead_step_m))
        self._filters: dict[int, DiscreteLeadFilter] = {}

    def reset(self, path: ReferencePath, sample_time_s: float) -> None:
        require_positive("sample_time_s", sample_time_s)
        self._dt = float(sample_time_s)
        self._tracker: PathTracker = path.tracker(0.0)
        self._kappa_cmd: float | None = None
        self._filters = {}
        self._filter: SteeringFilter = PassThroughFilter()
        self._filter_speed_kmh = -1
        self._lookahead_m: float | None = None
        self._diag: dict[str, float] = {}

    def _lead_filter(self, speed_mps: float) -> SteeringFilter:
        """The lead filter for this speed: the schedule's filter at the nearest whole km/h (discretised once per
        km/h and cached), continuing from the previous filter's state."""
        if not self.config.use_lead_filter:
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

    def _initial_curvature(self, m: Measurement, steering_kappa: float) -> float:
        """kappa(0) of Eq. 3 (see ClothoidConfig.initial_curvature)."""
        mode = self.config.initial_curvature
        if mode == "yaw-rate" and m.speed_mps > MIN_SPEED_MPS:
            return m.yaw_rate_rad_s / m.speed_mps
        if mode == "steering":
            return steering_kappa
        return self._kappa_cmd

    def _start_pose(self, m: Measurement, kappa0: float) -> tuple[float, float, float]:
        """(x, y, heading) the clothoid starts from: the rear axle, heading along its course (or body yaw), moved
        ahead by prediction_time_s on the current curvature (Figure 2, step 5)."""
        cfg = self.config
        heading = m.yaw_rad
        if cfg.heading == "course" and m.vx_mps > MIN_SPEED_MPS:
            heading += math.atan2(m.vy_mps, m.vx_mps)
        x, y = m.x_m, m.y_m
        if cfg.prediction_time_s > 0.0:  # an arc of curvature kappa0 and length d, by its chord
            d = m.speed_mps * cfg.prediction_time_s
            half_turn = 0.5 * kappa0 * d
            chord = d * (math.sin(half_turn) / half_turn if abs(half_turn) > 1e-9 else 1.0)
            x += chord * math.cos(heading + half_turn)
            y += chord * math.sin(heading + half_turn)
            heading += 2.0 * half_turn
        return x, y, heading

    def _lookahead(self, path: ReferencePath, foot_index: float, cte_m: float, pose, kappa0: float, speed_mps: float):
        """(lookahead m, the adaptive search's choice m, number of candidates evaluated) by the configured mode."""
        cfg = self.config
        if cfg.lookahead_mode == "fixed":
            return cfg.fixed_lookahead_m, cfg.fixed_lookahead_m, 0
        low = min(max(cfg.min_lookahead_m, cfg.min_preview_time_s * speed_mps), cfg.max_lookahead_m)
        if cfg.lookahead_mode == "speed":
            lookahead = min(max(cfg.lookahead_gain_s * speed_mps, low), cfg.max_lookahead_m)
            return lookahead, lookahead, 0
        threshold = cfg.frechet_threshold_m + (abs(cte_m) if cfg.threshold_mode == "excess" else 0.0)
        x, y, heading = pose
        chosen, evaluations = adaptive_search(
            path.x_m, path.y_m, path.closed, foot_index, x, y, heading, kappa0, low, cfg.max_lookahead_m,
            cfg.lookahead_step_m, threshold, cfg.tolerance_x_m, cfg.tolerance_y_m, cfg.max_curvature_rate_1pm2,
            cfg.frechet_point_spacing_m, self._buffers, self._scores,
        )  # fmt: skip
        lookahead = chosen
        growth = cfg.max_lookahead_growth_m_per_m
        if growth is not None and self._lookahead_m is not None:  # shorten at once, grow per metre travelled
            lookahead = max(min(chosen, self._lookahead_m + growth * speed_mps * self._dt), low)
        self._lookahead_m = lookahead
        return lookahead, chosen, evaluations

    def step(self, measurement: Measurement, path: ReferencePath) -> float:
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
        lookahead, searched, evaluations = self._lookahead(path, foot_index, foot.cte_m, pose, kappa0, m.speed_mps)
        frechet, kdot, length, tx, ty, ex, ey, status = evaluate_candidate(
            path.x_m, path.y_m, path.closed, foot_index, *pose, kappa0, lookahead, cfg.max_curvature_rate_1pm2,
            cfg.frechet_point_spacing_m, self._buffers,
        )  # fmt: skip

        # Figure 2: kappa' x V integrated to curvature, under the rate and curvature limits (section 4).
        rate = min(max(kdot * m.speed_mps, -rate_max), rate_max)
        self._kappa_cmd = min(max(self._kappa_cmd + rate * self._dt, -kappa_max), kappa_max)
        road_wheel = math.atan(g.wheelbase_m * self._kappa_cmd)  # Ackermann: tan(phi) = L kappa
        steer = road_wheel * g.steering_ratio
        command = self.saturate(self._lead_filter(m.speed_mps).step(steer))  # Eq. 6
        self._diag = {
            "lookahead_m": lookahead,
            "searched_lookahead_m": searched,
            "frechet_m": frechet,
            "curvature_rate_1pm2": kdot,
            "clothoid_length_m": length,
            "end_error_m": math.hypot(ex - tx, ey - ty),
            "fit_status": float(status),
            "evaluations": float(evaluations),
            "initial_curvature_1pm": kappa0,
            "curvature_cmd_1pm": self._kappa_cmd,
            "steer_unfiltered_rad": steer,
        }
        return command

    @property
    def diagnostics(self) -> Mapping[str, float]:
        return self._diag
