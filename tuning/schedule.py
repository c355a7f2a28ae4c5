"""A lead filter scheduled on speed: the paper's stated future work (section 7: the filter tuned at 30 km/h is
suboptimal at higher speeds).

At each speed the plant is driven open loop (`generate_open_loop_log`) with the double-lane-change and step-series
steering profiles sized for the same kinematic lateral acceleration (default 0.1 g, small enough to stay linear and
far from rollover), the lag of Eq. 5 is fitted to both logs jointly (`fit_lag`) and the lead filter designed for it
(`design_lead`). The filters form a `FilterSchedule`, written in the lead-filter file format with a `schedule`
list; the clothoid controller interpolates it at the current speed. The file's `design` table keeps, per speed,
the identified lag and what the design achieved.

`compare_closed_loop` runs the clothoid controller on a scenario with a scheduled and with a fixed filter, to show
which tracks better (the demonstration of issue 6, item 5), and `scheduled_against_fixed` reads the verdict off
its rows. Measured on the loaded tractor-semitrailer (`tuning schedule --speeds 20,30,...,90 --compare 60,80`, the
clothoid controller's defaults, dlc at the simulator's 0.3 g speed profile): max |CTE| 0.12 m with the schedule
against 0.28-0.29 m with the 30 km/h filter at both 60 and 80 km/h (2.5 m without a filter). The profile slows the
truck to 35 km/h in the lane changes (the dlc's 30-45 m radii at 0.3 g), so "60" and "80" differ in the approach
(60 and 70 km/h) more than in the lane changes, which the schedule meets with its 30-50 km/h filters.
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from controllers.clothoid import ClothoidConfig, ClothoidController
from controllers.clothoid.filter_file import FilterSchedule, write_filter_file
from tuning.data_generation import generate_open_loop_log
from tuning.lag_fit import LagFit, LagFitOptions, fit_lag
from tuning.lead_design import DEFAULT_MAX_CASCADE_PEAK_DB, DEFAULT_MAX_LEAD_GAIN, LeadDesign, design_lead
from tuning.log_file import VehicleLog
from tuning.maneuvers import Maneuver
from tuning.speeds import check_speeds
from workbench.errors import WorkbenchInputError, require_in_range
from workbench.scenarios import ScenarioOptions, make_scenario
from workbench.simulator import Simulation, SimulationConfig
from workbench.vehicles.base import VehicleModel

G_MPS2 = 9.80665
DEFAULT_LAT_ACCEL_G = 0.1
SCHEDULE_MANEUVERS = ("dlc", "step-series")
SPEED_RANGE_KMH = (5.0, 200.0)
#: The speed the paper tuned its lead filter at: the fixed filter the schedule is compared with by default.
PAPER_SPEED_KMH = 30.0


@dataclass(frozen=True)
class ScheduleEntry:
    """One speed: the fit of the lag and the filter designed for it."""

    speed_kmh: float
    fit: LagFit
    design: LeadDesign

    def row(self) -> dict[str, float]:
        lag, d = self.fit.lag, self.design
        return {
            "speed_kmh": self.speed_kmh,
            "omega_n_rad_s": lag.omega_n_rad_s,
            "zeta": lag.zeta,
            "steady_state_gain": self.fit.gain,
            "nrmse": lag.nrmse,
            "omega_z_rad_s": d.params.omega_z_rad_s,
            "psi": d.params.psi,
            "omega_p_rad_s": d.params.omega_p_rad_s,
            "plant_bandwidth_rad_s": d.plant_bandwidth_rad_s,
            "cascade_bandwidth_rad_s": d.cascade_bandwidth_rad_s,
        }


@dataclass(frozen=True)
class ScheduleResult:
    vehicle: str
    entries: tuple[ScheduleEntry, ...]
    lat_accel_g: float

    @property
    def speeds_kmh(self) -> tuple[float, ...]:
        return tuple(e.speed_kmh for e in self.entries)

    def filter_schedule(self) -> FilterSchedule:
        return FilterSchedule(self.speeds_kmh, tuple(e.design.params for e in self.entries), source=self._source())

    def _source(self) -> str:
        return (
            f"tuning schedule: {self.vehicle}, lag of Eq. 5 fitted at each speed to open-loop "
            f"{' and '.join(SCHEDULE_MANEUVERS)} logs at {self.lat_accel_g:g} g, lead filter by design_lead"
        )

    def write(self, path: str | Path, nominal_speed_kmh: float | None = None) -> Path:
        """Write the lead-filter file (JSON, or TOML by suffix). The top-level filter and `plant` are those of the
        speed nearest nominal_speed_kmh (default: the first speed)."""
        nominal = self.entries[0]
        if nominal_speed_kmh is not None:
            nominal = min(self.entries, key=lambda e: abs(e.speed_kmh - nominal_speed_kmh))
        first = self.entries[0].design
        design = {
            "method": first.method,
            "max_lead_gain": first.max_lead_gain,
            "max_cascade_peak_db": first.max_cascade_peak_db,
            "lat_accel_g": self.lat_accel_g,
            "maneuvers": list(SCHEDULE_MANEUVERS),
            "per_speed": [e.row() for e in self.entries],
        }
        lag = nominal.fit.lag
        return write_filter_file(
            path,
            self.filter_schedule(),
            source=self._source(),
            plant={"omega_n_rad_s": lag.omega_n_rad_s, "zeta": lag.zeta},
            speed_kmh=nominal.speed_kmh,
            extra=design,
        )

    def table(self) -> str:
        lines = ["speed_kmh  omega_n  zeta   K      nrmse   omega_z  psi    omega_p  bw_plant  bw_cascade"]
        for e in self.entries:
            r = e.row()
            lines.append(
                f"{r['speed_kmh']:9.1f}  {r['omega_n_rad_s']:7.3f}  {r['zeta']:5.3f}  {r['steady_state_gain']:5.3f}  "
                f"{r['nrmse']:6.4f}  {r['omega_z_rad_s']:7.3f}  {r['psi']:5.3f}  {r['omega_p_rad_s']:7.3f}  "
                f"{r['plant_bandwidth_rad_s']:8.3f}  {r['cascade_bandwidth_rad_s']:10.3f}"
            )
        return "\n".join(lines)


def identification_logs(
    vehicle: VehicleModel,
    speed_kmh: float,
    lat_accel_g: float = DEFAULT_LAT_ACCEL_G,
    maneuvers: Sequence[str] = SCHEDULE_MANEUVERS,
    duration_s: float = 20.0,
    sample_rate_hz: float = 100.0,
) -> list[VehicleLog]:
    """Open-loop logs at speed_kmh, each profile's amplitude giving lat_accel_g of kinematic lateral acceleration."""
    require_in_range("speed_kmh", speed_kmh, *SPEED_RANGE_KMH, "km/h")
    require_in_range("lat_accel_g", lat_accel_g, 0.001, 1.0, "g")
    amplitude = steer_amplitude_deg(vehicle, speed_kmh, lat_accel_g)
    logs = []
    for kind in maneuvers:
        frame = generate_open_loop_log(
            vehicle,
            Maneuver(kind, amplitude_deg=amplitude, duration_s=duration_s),
            speed_kmh,
            sample_rate_hz=sample_rate_hz,
        )
        logs.append(VehicleLog.from_frame(frame, name=f"{kind} at {speed_kmh:g} km/h"))
    return logs


def steer_amplitude_deg(vehicle: VehicleModel, speed_kmh: float, lat_accel_g: float) -> float:
    """Steering-wheel angle (deg) whose kinematic curvature gives lat_accel_g at speed_kmh, capped at the lock."""
    v = speed_kmh / 3.6
    geometry = vehicle.geometry
    lock = math.tan(geometry.max_road_wheel_angle_rad) / geometry.wheelbase_m
    curvature = min(lat_accel_g * G_MPS2 / (v * v), lock)
    return math.degrees(geometry.steer_wheel_for_curvature(curvature))


def identify_schedule(
    vehicle: VehicleModel,
    speeds_kmh: Sequence[float],
    lat_accel_g: float = DEFAULT_LAT_ACCEL_G,
    fit_options: LagFitOptions | None = None,
    max_lead_gain: float = DEFAULT_MAX_LEAD_GAIN,
    max_cascade_peak_db: float = DEFAULT_MAX_CASCADE_PEAK_DB,
) -> ScheduleResult:
    """Identify the lag and design the filter at each speed (km/h, strictly increasing)."""
    speeds = check_speeds(speeds_kmh, *SPEED_RANGE_KMH)
    entries = []
    for speed in speeds:
        logs = identification_logs(vehicle, speed, lat_accel_g)
        try:
            fit = fit_lag(logs, vehicle.geometry, fit_options)
        except WorkbenchInputError as exc:
            raise WorkbenchInputError(f"at {speed:g} km/h: {exc}") from None
        design = design_lead(fit.lag, max_lead_gain=max_lead_gain, max_cascade_peak_db=max_cascade_peak_db)
        entries.append(ScheduleEntry(speed, fit, design))
    return ScheduleResult(vehicle.name, tuple(entries), float(lat_accel_g))


@dataclass(frozen=True)
class ClosedLoopRow:
    """One closed-loop run of the comparison: speed_kmh is the speed asked for (the profile's maximum);
    min/max_speed_kmh the speeds actually driven."""

    speed_kmh: float
    filter: str
    completed: bool
    max_abs_cte_m: float
    rms_cte_m: float
    max_abs_steer_rate_deg_s: float
    min_speed_kmh: float = math.nan
    max_speed_kmh: float = math.nan


@dataclass(frozen=True)
class FilterVerdict:
    """At one speed: max |CTE| (m) with the scheduled and with the fixed filter."""

    speed_kmh: float
    scheduled_max_abs_cte_m: float
    fixed_max_abs_cte_m: float
    fixed_label: str

    def __post_init__(self) -> None:
        for name in ("scheduled_max_abs_cte_m", "fixed_max_abs_cte_m"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or not value >= 0.0:
                raise WorkbenchInputError(f"{name} must be a number >= 0 m (inf: the run failed); got {value!r}")

    @property
    def scheduled_better(self) -> bool:
        return self.scheduled_max_abs_cte_m < self.fixed_max_abs_cte_m

    @property
    def change(self) -> float:
        """Relative change of max |CTE| from the fixed filter to the schedule (negative: the schedule is better)."""
        return self.scheduled_max_abs_cte_m / self.fixed_max_abs_cte_m - 1.0

    def line(self) -> str:
        if self.scheduled_max_abs_cte_m == self.fixed_max_abs_cte_m:
            verdict = "the same (at the fixed filter's own speed the schedule is that filter)"
        else:
            verdict = "scheduled better" if self.scheduled_better else "scheduled NOT better"
        return (
            f"{self.speed_kmh:g} km/h: max |CTE| scheduled {self.scheduled_max_abs_cte_m:.3f} m, "
            f"{self.fixed_label} {self.fixed_max_abs_cte_m:.3f} m ({100 * self.change:+.0f} %): {verdict}"
        )


def scheduled_against_fixed(
    rows: Sequence[ClosedLoopRow], fixed_label: str, scheduled_label: str = "scheduled"
) -> list[FilterVerdict]:
    """The verdict at each speed of `compare_closed_loop` rows that ran both filters (a run that did not complete
    counts as an infinite error)."""

    def error(row: ClosedLoopRow) -> float:
        return row.max_abs_cte_m if row.completed and math.isfinite(row.max_abs_cte_m) else math.inf

    by_key = {(row.speed_kmh, row.filter): row for row in rows}
    speeds = dict.fromkeys(row.speed_kmh for row in rows)
    out = []
    for speed in speeds:
        scheduled, fixed = by_key.get((speed, scheduled_label)), by_key.get((speed, fixed_label))
        if scheduled is not None and fixed is not None:
            out.append(FilterVerdict(speed, error(scheduled), error(fixed), fixed_label))
    return out


def compare_closed_loop(
    vehicle_factory: Callable[[], VehicleModel],
    filters: dict[str, Path | None] | dict[str, Path],
    speeds_kmh: Sequence[float] = (60.0, 80.0),
    scenario: str = "dlc",
    max_lateral_accel_g: float | None = None,
) -> list[ClosedLoopRow]:
    """Run the clothoid controller on `scenario` at each speed with each filter file (label -> path; None: the
    lead filter switched off) and return the tracking metrics. vehicle_factory() builds a fresh vehicle per run.
    max_lateral_accel_g: the speed profile's bound (default: the simulator's 0.3 g; raise it so that the dlc is
    driven at the asked speed)."""
    rows = []
    for speed in speeds_kmh:
        for label, path in filters.items():
            vehicle = vehicle_factory()
            config = ClothoidConfig(filter_file=path) if path is not None else ClothoidConfig(use_lead_filter=False)
            controller = ClothoidController(vehicle.geometry, config)
            scen = make_scenario(scenario, ScenarioOptions(vehicle_width_m=vehicle.geometry.width_m))
            sim_config = (
                SimulationConfig(speed_kmh=speed)
                if max_lateral_accel_g is None
                else SimulationConfig(speed_kmh=speed, max_lateral_accel_g=max_lateral_accel_g)
            )
            result = Simulation(scen, vehicle, controller, sim_config).run()
            m = result.metrics
            driven = np.asarray(result.trace["speed_mps"], dtype=float) * 3.6
            rows.append(
                ClosedLoopRow(
                    float(speed),
                    label,
                    result.completed,
                    float(m.max_abs_cte_m) if m.max_abs_cte_m is not None else math.nan,
                    float(m.rms_cte_m) if m.rms_cte_m is not None else math.nan,
                    float(m.max_abs_steer_rate_deg_s) if m.max_abs_steer_rate_deg_s is not None else math.nan,
                    float(driven.min()) if driven.size else math.nan,
                    float(driven.max()) if driven.size else math.nan,
                )
            )
    return rows


def fixed_and_scheduled_filters(
    vehicle: VehicleModel, result: ScheduleResult, fixed_speed_kmh: float, directory: str | Path | None = None
) -> dict[str, Path]:
    """Write the schedule and the single filter of its entry at fixed_speed_kmh to `directory` (a temporary one by
    default) and return {"scheduled": path, "fixed <speed> km/h": path} for `compare_closed_loop`."""
    directory = Path(directory) if directory is not None else Path(tempfile.mkdtemp(prefix="tuning-"))
    matches = [e for e in result.entries if e.speed_kmh == fixed_speed_kmh]
    if not matches:
        raise WorkbenchInputError(
            f"fixed_speed_kmh {fixed_speed_kmh:g} is not a speed of the schedule {list(result.speeds_kmh)}"
        )
    entry = matches[0]
    fixed = write_filter_file(
        directory / f"lead_{fixed_speed_kmh:g}kmh.json",
        entry.design.params,
        source=f"design_lead at {fixed_speed_kmh:g} km/h ({vehicle.name})",
        plant={"omega_n_rad_s": entry.fit.lag.omega_n_rad_s, "zeta": entry.fit.lag.zeta},
        speed_kmh=fixed_speed_kmh,
        extra=entry.design.metadata(),
    )
    scheduled = result.write(directory / "schedule.json", nominal_speed_kmh=fixed_speed_kmh)
    return {"scheduled": scheduled, f"fixed {fixed_speed_kmh:g} km/h": fixed}
