"""The clothoid controller's stability margins against lookahead and speed (`tuning margins`): a table, the
lookahead floor per speed, and a plot (margins against lookahead per speed, the lookaheads the controller may use
shaded).

The analysis itself is `controllers/clothoid/loop_analysis.py` (the loop linearised about a straight and an arc,
with the identified lags of Eq. 5, the lead filter of Eq. 6, sampling and any measurement delay); this module runs
it over a grid and says where the curvature-rate limit would sustain a limit cycle (its describing function).

The arc is the one the controller checks its floor about (`controller.py`, FLOOR_ARC_LATERAL_ACCEL_G): at each
speed the curvature of a given lateral acceleration, a g / v^2, capped at the vehicle's curvature limit (its
limits table when given, else its steering lock).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.clothoid.controller import MAX_FLOOR_LOOKAHEAD_M, MAX_LOOKAHEAD_M
from controllers.clothoid.curvature_limits import CurvatureLimits
from controllers.clothoid.filter_schedule import FilterSchedule
from controllers.clothoid.loop_analysis import (
    MAX_CURVATURE_LOOKAHEAD,
    REQUIRED_GAIN_MARGIN_DB,
    REQUIRED_PHASE_MARGIN_DEG,
    LoopSettings,
    Margins,
    PlantLags,
    keeps_margins,
    lookahead_floor,
    loop_margins,
    loop_transfer,
    predicted_limit_cycle,
)
from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.geometry import VehicleGeometry

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Columns of the margins table (one row per speed, lookahead and path curvature).
COLUMNS = (
    "speed_kmh",
    "lookahead_m",
    "path_curvature_1pm",
    "phase_margin_deg",
    "gain_margin_db",
    "gain_reduction_margin_db",
    "crossover_rad_s",
    "stable",
    "meets",
    "limit_cycle_hz",
    "limit_cycle_steer_wheel_deg",
)
#: Most lookaheads a study may hold.
MAX_LOOKAHEADS = 2000
#: Most (speed, lookahead) pairs a study may analyse: each is one loop analysis per path curvature, about 20 ms
#: (20 000 pairs about a straight and an arc: some 15 minutes).
MAX_STUDY_PAIRS = 20_000


@dataclass(frozen=True)
class MarginStudy:
    """What to analyse: lags_at (speed km/h -> PlantLags), lead (a schedule, or None: no lead filter),
    speeds_kmh, lookaheads_m, path_curvatures_1pm (fixed curvatures at every speed, 0: a straight; others: arcs),
    arc_lateral_accel_g (also, at each speed, the arc of this lateral acceleration, a g / v^2, capped at the
    curvature limit; None or 0: none), sample_time_s, prediction_time_s, measurement_delay_s, the required
    margins, the vehicle geometry (for the curvature-rate limit and the steering amplitude of a predicted limit
    cycle; None: not predicted), limits (the controller's curvature and curvature-rate limits against speed; None:
    the steering lock and the steering-rate limit of the geometry) and max_lookahead_m (the controller's longest
    lookahead, m: a floor above it is said to hold the lookahead outside the range; None: not compared)."""

    lags_at: Callable[[float], PlantLags]
    lead: FilterSchedule | None
    speeds_kmh: tuple[float, ...]
    lookaheads_m: tuple[float, ...]
    path_curvatures_1pm: tuple[float, ...] = (0.0,)
    sample_time_s: float = 0.02
    prediction_time_s: float = 0.2
    measurement_delay_s: float = 0.0
    phase_margin_deg: float = REQUIRED_PHASE_MARGIN_DEG
    gain_margin_db: float = REQUIRED_GAIN_MARGIN_DB
    geometry: VehicleGeometry | None = None
    arc_lateral_accel_g: float | None = None
    limits: CurvatureLimits | None = None
    max_lookahead_m: float | None = None

    def __post_init__(self) -> None:
        if not callable(self.lags_at):
            raise WorkbenchInputError("lags_at must be a function of the speed (km/h) returning PlantLags")
        for name, values, low, high, unit in (
            ("speeds_kmh", self.speeds_kmh, 1.0, 300.0, "km/h"),
            ("lookaheads_m", self.lookaheads_m, 0.5, 200.0, "m"),
        ):
            if not values:
                raise WorkbenchInputError(f"{name} must not be empty")
            for v in values:
                require_in_range(name, v, low, high, unit)
        if len(self.lookaheads_m) > MAX_LOOKAHEADS:
            raise WorkbenchInputError(f"lookaheads_m: at most {MAX_LOOKAHEADS}; got {len(self.lookaheads_m)}")
        pairs = len(self.speeds_kmh) * len(self.lookaheads_m)
        if pairs > MAX_STUDY_PAIRS:
            raise WorkbenchInputError(
                f"{len(self.speeds_kmh)} speeds x {len(self.lookaheads_m)} lookaheads = {pairs:,} cases to analyse; "
                f"at most {MAX_STUDY_PAIRS:,} (about 20 ms each): fewer speeds (--speeds) or a larger lookahead step "
                "(--lookahead LOW:HIGH:STEP)"
            )
        for k in self.path_curvatures_1pm:
            require_in_range("path_curvatures_1pm", k, -1.0, 1.0, "1/m")
        if self.arc_lateral_accel_g is not None:
            require_in_range("arc_lateral_accel_g", self.arc_lateral_accel_g, 0.0, 2.0, "g")
        if not self.path_curvatures_1pm and not self.arc_lateral_accel_g:
            raise WorkbenchInputError("give at least one path curvature or an arc_lateral_accel_g > 0")
        require_in_range("phase_margin_deg", self.phase_margin_deg, 0.0, 180.0, "deg")
        require_in_range("gain_margin_db", self.gain_margin_db, 0.0, 60.0, "dB")
        if self.max_lookahead_m is not None:
            require_in_range("max_lookahead_m", self.max_lookahead_m, 0.5, MAX_LOOKAHEAD_M, "m")
        if self.limits is not None and not isinstance(self.limits, CurvatureLimits):
            raise WorkbenchInputError(f"limits must be CurvatureLimits or None; got {self.limits!r}")

    def settings(self, speed_kmh: float) -> LoopSettings:
        lead = self.lead.at_speed(speed_kmh) if self.lead is not None else None
        return LoopSettings(
            self.sample_time_s, self.prediction_time_s, lead=lead, measurement_delay_s=self.measurement_delay_s
        )

    def max_curvature_1pm(self, speed_kmh: float) -> float:
        """The curvature limit (1/m) at this speed: the limits table's, else the steering lock (inf without a
        geometry)."""
        if self.limits is not None:
            return self.limits.at_speed(speed_kmh / 3.6)[0]
        if self.geometry is not None:
            return math.tan(self.geometry.max_road_wheel_angle_rad) / self.geometry.wheelbase_m
        return math.inf

    def rate_limit_1pm_s(self, speed_kmh: float) -> float:
        """The curvature-rate limit (1/(m s)) at this speed: the limits table's, else the geometry's steering-rate
        limit at small angles (`CurvatureLimits.default_for`); nan without either."""
        if self.limits is not None:
            return self.limits.at_speed(speed_kmh / 3.6)[1]
        if self.geometry is not None:
            return _rate_limit(self.geometry)
        return math.nan

    def arc_curvature_1pm(self, speed_kmh: float) -> float | None:
        """The arc of arc_lateral_accel_g at this speed (1/m), capped at the curvature limit; None without one."""
        if not self.arc_lateral_accel_g:
            return None
        v = speed_kmh / 3.6
        return min(self.arc_lateral_accel_g * G_MPS2 / v**2, self.max_curvature_1pm(speed_kmh))

    def curvatures_at(self, speed_kmh: float) -> tuple[float, ...]:
        """The path curvatures analysed at this speed: path_curvatures_1pm, then the arc (without repeats)."""
        out = [float(k) for k in self.path_curvatures_1pm]
        arc = self.arc_curvature_1pm(speed_kmh)
        if arc is not None:
            out.append(float(arc))
        return tuple(dict.fromkeys(out))

    def lookahead_step_m(self) -> float:
        """The smallest spacing of the lookaheads (m; 0.5 for a single one): the floor's grid."""
        if len(self.lookaheads_m) < 2:
            return 0.5
        return float(np.min(np.diff(sorted(self.lookaheads_m))))


@dataclass(frozen=True)
class MarginResult:
    """table: one row per (speed, lookahead, path curvature), COLUMNS (rows with |curvature| x lookahead >= 1.8
    left out); floors: speed_kmh -> the lookahead floor (m) over the study's range and curvatures (nan when no
    lookahead in the range keeps the margins)."""

    study: MarginStudy
    table: pd.DataFrame
    floors: dict[float, float]

    def to_pandas(self) -> pd.DataFrame:
        return self.table.copy()

    def margins_at_floor(self, speed_kmh: float) -> dict[float, Margins]:
        """path curvature -> the margins at this speed's floor (empty when there is no floor)."""
        floor = self.floors.get(speed_kmh, math.nan)
        if not math.isfinite(floor):
            return {}
        lags, settings, v = self.study.lags_at(speed_kmh), self.study.settings(speed_kmh), speed_kmh / 3.6
        return {
            kr: loop_margins(lags, settings, v, float(floor), kr)
            for kr in self.study.curvatures_at(speed_kmh)
            if abs(kr) * floor < MAX_CURVATURE_LOOKAHEAD
        }

    def summary(self) -> str:
        """Per speed: the floor, the margins there (straight and arc) and the limit cycles predicted below it."""
        study = self.study
        low, high = min(study.lookaheads_m), max(study.lookaheads_m)
        lines = [
            f"lookahead floor per speed: the shortest lookahead in {low:g}-{high:g} m from which every longer one "
            f"keeps phase margin >= {study.phase_margin_deg:g} deg and gain margin >= {study.gain_margin_db:g} dB "
            f"both ways, about each path curvature"
        ]
        for speed in study.speeds_kmh:
            floor = self.floors.get(speed, math.nan)
            kinds = ", ".join(_curvature_label(k) for k in study.curvatures_at(speed))
            if not math.isfinite(floor):
                lines.append(
                    f"{speed:6g} km/h: floor none (no lookahead in {low:g}-{high:g} m keeps the margins about {kinds})"
                )
                top = max(study.max_lookahead_m or 0.0, MAX_FLOOR_LOOKAHEAD_M)
                if study.max_lookahead_m is not None and high >= top:
                    lines.append(
                        f"{' ' * 13}the clothoid controller would hold its lookahead at the top of its floor search, "
                        f"{top:g} m, without these margins, and its Fréchet search would not act: use a lead filter "
                        "with more phase margin"
                    )
                elif study.max_lookahead_m is not None:
                    lines.append(
                        f"{' ' * 13}analyse up to {top:g} m (the top of the clothoid controller's floor search) to see "
                        "where it would hold its lookahead"
                    )
            else:
                parts = [
                    f"{_curvature_label(kr)}: PM {m.phase_margin_deg:.1f} deg, GM +{m.gain_margin_db:.1f} / "
                    f"{m.gain_reduction_margin_db:.1f} dB"
                    for kr, m in self.margins_at_floor(speed).items()
                ]
                lines.append(f"{speed:6g} km/h: floor {floor:g} m ({'; '.join(parts)})")
                if study.max_lookahead_m is not None and floor > study.max_lookahead_m:
                    lines.append(
                        f"{' ' * 13}floor above max_lookahead_m ({study.max_lookahead_m:g} m): the clothoid controller "
                        f"would hold its lookahead at {floor:g} m, outside its range, and its Fréchet search would "
                        f"not act: raise max_lookahead_m to at least {floor:g} m or use a lead filter with more phase "
                        "margin"
                    )
            below, where = self.table[(self.table["speed_kmh"] == speed)], "in the range"
            if math.isfinite(floor):
                below, where = below[below["lookahead_m"] < floor], "below it"
            unstable = below[~below["stable"].astype(bool)]
            cycles = below[np.isfinite(below["limit_cycle_hz"].to_numpy(dtype=float))]
            indent = " " * 13
            if below.empty:
                lines.append(f"{indent}below it: nothing (the floor is the lowest lookahead analysed)")
            elif unstable.empty:
                lines.append(
                    f"{indent}{where}: the loop is stable at every lookahead, its margins short of those asked"
                )
            else:
                text = f"{indent}{where}: unstable at {_runs(unstable['lookahead_m'], study.lookaheads_m)} m"
                if study.geometry is None and study.limits is None:
                    text += " (limit cycles not predicted: give the vehicle, for its curvature-rate limit)"
                elif cycles.empty:
                    text += ", no limit cycle predicted"
                else:
                    text += (
                        f"; limit cycle predicted at {_runs(cycles['lookahead_m'], study.lookaheads_m)} m: "
                        f"{_span(cycles['limit_cycle_hz'], '.2f')} Hz, "
                        f"+-{_span(cycles['limit_cycle_steer_wheel_deg'], '.0f')} deg steering wheel"
                    )
                lines.append(text)
        return "\n".join(lines)

    def plot(self, fig: Figure | None = None) -> Figure:
        """Phase margin and gain margin (the smaller of rise and reduction) against lookahead, one colour per speed
        (solid: straight path; dashed: the arc), where the loop is stable; crosses along the bottom where it is not;
        the required margins and, shaded, the lookaheads at and above each speed's floor."""
        import matplotlib.pyplot as plt

        fig = fig or plt.figure(figsize=(9, 7), layout="constrained")
        ax_pm, ax_gm = fig.subplots(2, 1, sharex=True)
        colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
        top = max(self.study.lookaheads_m)
        speeds = sorted(self.table["speed_kmh"].unique())
        for i, speed in enumerate(speeds):
            rows = self.table[self.table["speed_kmh"] == speed]
            c = colours[i % len(colours)]
            arcs = 0
            for kr in self.study.curvatures_at(speed):
                path_rows = rows[rows["path_curvature_1pm"] == kr].sort_values("lookahead_m")
                if path_rows.empty:
                    continue
                if kr == 0.0:
                    style, label = "-", f"{speed:g} km/h"
                else:
                    style, label = ("--", "-.", ":")[arcs % 3], f"{speed:g} km/h, arc {kr:.3g} 1/m"
                    arcs += 1
                stable = path_rows["stable"].astype(bool).to_numpy()
                x = path_rows["lookahead_m"].to_numpy()
                pm = np.where(stable, path_rows["phase_margin_deg"].clip(-90, 120), np.nan)
                gm = np.minimum(path_rows["gain_margin_db"], -path_rows["gain_reduction_margin_db"]).clip(-20, 40)
                ax_pm.plot(x, pm, color=c, ls=style, label=label)
                ax_gm.plot(x, np.where(stable, gm, np.nan), color=c, ls=style)
                if (~stable).any():
                    ax_pm.plot(x[~stable], np.full((~stable).sum(), -5.0 - 4.0 * i), "x", color=c, ms=4)
            floor = self.floors.get(speed, math.nan)
            if math.isfinite(floor):
                for ax in (ax_pm, ax_gm):
                    ax.axvspan(floor, top, color=c, alpha=0.06)
                    ax.axvline(floor, color=c, ls=":", lw=1)
        ax_pm.axhline(self.study.phase_margin_deg, color="k", ls="--", lw=1)
        ax_gm.axhline(self.study.gain_margin_db, color="k", ls="--", lw=1)
        ax_pm.set_ylabel("phase margin (deg; x: unstable)")
        ax_gm.set_ylabel("gain margin, smaller of rise / reduction (dB)")
        ax_gm.set_xlabel("lookahead (m)")
        ax_pm.set_title("clothoid loop margins (shaded: lookaheads the controller may use, from each speed's floor)")
        ax_pm.legend(fontsize="small", ncol=2)
        for ax in (ax_pm, ax_gm):
            ax.grid(True, alpha=0.3)
        return fig


def _curvature_label(kr: float) -> str:
    return "straight" if kr == 0.0 else f"arc {kr:.4g} 1/m"


def _span(values: pd.Series, fmt: str = "g") -> str:
    lo, hi = float(values.min()), float(values.max())
    return f"{lo:{fmt}}" if f"{lo:{fmt}}" == f"{hi:{fmt}}" else f"{lo:{fmt}}-{hi:{fmt}}"


def _runs(values: pd.Series, grid: Sequence[float]) -> str:
    """The values as runs of consecutive grid points: "3-4.5, 6-8"."""
    order = sorted(grid)
    index = sorted({order.index(v) for v in values if v in order})
    runs: list[list[int]] = []
    for i in index:
        if runs and i == runs[-1][-1] + 1:
            runs[-1].append(i)
        else:
            runs.append([i])
    return ", ".join(f"{order[r[0]]:g}" if len(r) == 1 else f"{order[r[0]]:g}-{order[r[-1]]:g}" for r in runs)


def _rate_limit(geometry: VehicleGeometry) -> float:
    """The default curvature-rate limit (1/(m s)) of the controller for this vehicle (`CurvatureLimits.default_for`)."""
    return geometry.max_steer_wheel_rate_rad_s / geometry.steering_ratio / geometry.wheelbase_m


def run_margins(study: MarginStudy) -> MarginResult:
    """Margins on the study's grid, the floor per speed, and the describing-function limit cycle where the loop is
    unstable."""
    rows = []
    floors: dict[float, float] = {}
    g = study.geometry
    steer_per_curvature = g.steering_ratio * g.wheelbase_m if g is not None else math.nan
    for speed in study.speeds_kmh:
        lags: PlantLags = study.lags_at(speed)
        settings = study.settings(speed)
        curvatures = study.curvatures_at(speed)
        rate_limit = study.rate_limit_1pm_s(speed)
        v = speed / 3.6
        for lookahead in study.lookaheads_m:
            for kr in curvatures:
                if abs(kr) * lookahead >= MAX_CURVATURE_LOOKAHEAD:
                    continue
                m = loop_margins(lags, settings, v, float(lookahead), float(kr))
                cycle = None
                if not m.stable and math.isfinite(rate_limit):
                    cycle = predicted_limit_cycle(
                        loop_transfer(lags, settings, v, float(lookahead), float(kr)),
                        rate_limit,
                        settings.lead,
                        steer_per_curvature,
                    )
                rows.append(
                    {
                        "speed_kmh": speed,
                        "lookahead_m": float(lookahead),
                        "path_curvature_1pm": float(kr),
                        "phase_margin_deg": m.phase_margin_deg,
                        "gain_margin_db": m.gain_margin_db,
                        "gain_reduction_margin_db": m.gain_reduction_margin_db,
                        "crossover_rad_s": m.crossover_rad_s,
                        "stable": m.stable,
                        "meets": m.meets(study.phase_margin_deg, study.gain_margin_db),
                        "limit_cycle_hz": cycle.frequency_hz if cycle else math.nan,
                        "limit_cycle_steer_wheel_deg": cycle.steer_wheel_amplitude_deg if cycle else math.nan,
                    }
                )
        low, high = min(study.lookaheads_m), max(study.lookaheads_m)
        pm, gm = study.phase_margin_deg, study.gain_margin_db
        floor = lookahead_floor(lags, settings, v, low, high, study.lookahead_step_m(), curvatures, pm, gm)
        floors[speed] = floor if keeps_margins(lags, settings, v, floor, curvatures, pm, gm) else math.nan
    return MarginResult(study, pd.DataFrame(rows, columns=list(COLUMNS)), floors)


def lookahead_grid(low_m: float, high_m: float, step_m: float) -> tuple[float, ...]:
    """low, low + step, ..., high (m)."""
    require_in_range("lookahead step", step_m, 0.05, 50.0, "m")
    require_in_range("lowest lookahead", low_m, 0.5, 200.0, "m")
    require_in_range("longest lookahead", high_m, low_m, 200.0, "m")
    count = math.floor((high_m - low_m) / step_m + 1e-9) + 1
    if count > MAX_LOOKAHEADS:
        raise WorkbenchInputError(
            f"lookaheads {low_m:g}:{high_m:g}:{step_m:g} give {count} values; at most {MAX_LOOKAHEADS} (a larger step)"
        )
    return tuple(float(low_m + i * step_m) for i in range(count))  # as lookahead_floor's grid
