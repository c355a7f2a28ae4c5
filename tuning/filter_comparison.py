"""Does the speed-scheduled lead filter track better than one filter for every speed? `compare_closed_loop` runs
the clothoid controller, with the vehicle's own tuning otherwise, on a scenario with each filter, and
`scheduled_against_fixed` reads the verdict off its rows (`tuning schedule --compare`)."""

from __future__ import annotations

import math
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from controllers.clothoid import ClothoidConfig, ClothoidController
from tuning.filter_file import read_filter_file, write_filter_file
from tuning.own_tuning import tuning_for
from tuning.schedule import ScheduleResult
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.scenarios import ScenarioOptions, make_scenario
from workbench.simulation.simulator import Simulation, SimulationConfig
from workbench.vehicles.base import VehicleModel


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
            config = (
                ClothoidConfig(tuning=tuning_for(vehicle), lead_filter=read_filter_file(path))
                if path is not None
                else ClothoidConfig(tuning=tuning_for(vehicle), use_lead_filter=False)
            )
            controller = ClothoidController(vehicle.geometry, config, vehicle=vehicle)
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
