"""The clothoid controller's tuning of one vehicle (`VehicleTuning`): its lead filter against speed, its curvature
limits, the Eq. 5 lags identified at each speed, interpolated in speed, the lookahead floors the tuning's margins
design computed (`FloorDesign`: what they were computed for, so that the controller uses them only where it would
compute the same) and the preview responses identified at the lags' speeds (`preview_model.py`). The steered
vehicle's own tuning is made by the project's tuning chain and found by `tuning/tuning_dirs.py` (shipped for the
presets, cached for any other vehicle); a controller config holds it (`ClothoidConfig.tuning`), so the controller
reads no file."""

from __future__ import annotations

import bisect
import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.clothoid.curvature_limits import CurvatureLimits
from controllers.clothoid.filter_schedule import FilterSchedule
from controllers.clothoid.lead_filter import LeadFilterParams
from controllers.clothoid.loop_requirements import REQUIRED_GAIN_MARGIN_DB, REQUIRED_PHASE_MARGIN_DEG
from controllers.clothoid.preview_model import HANDLING_GRID_G, PreviewResponse
from controllers.clothoid.sideslip_release import SideslipRelease
from controllers.clothoid.speed_tables import table_row
from workbench.base.errors import WorkbenchInputError, shown_all, value_text
from workbench.vehicles.steering_lag import SteeringLag

#: The parameters of a lag the tables hold, in their order (`VehicleTuning.lag_tables`).
LAG_COLUMNS = ("omega_n_rad_s", "zeta", "delay_s", "steady_state_gain")
#: The median NRMSE (-) over the speeds within which the lag of Eq. 5 explains the vehicle's logs
#: (`VehicleTuning.lag_explains_logs`): a second-order lag explains a single-track car's to about 0.1 % and the
#: kinematic bicycle's to less; the loaded tractor-semitrailer's (0.6-2 %, zeta at its bound) and the multi-body
#: car's (1-3 %) it does not, and there the identified preview responses stand in for it.
LAG_EXPLAINS_NRMSE = 0.005
#: Relative tolerance (-) within which two inputs of a lookahead floor are one (`FloorInputs.matches`): a rounding
#: apart, far below any difference that moves a floor by a step of its grid.
FLOOR_INPUT_REL_TOL = 1e-9


@dataclass(frozen=True)
class FloorInputs:
    """What a lookahead floor at one speed is computed from (`loop_analysis.lookahead_floor`), besides the lags of
    that speed: speed_kmh (km/h), lead (the lead filter there; None: none), sample_time_s (controller period, s),
    prediction_time_s (s), known_delay_s (s), path_curvatures_1pm (the straight and the arc it is checked about,
    1/m), lookahead_grid_m (the search's shortest and longest lookahead and its step, m), phase_margin_deg and
    gain_margin_db (the margins kept). Two floors with equal inputs and lags are equal (`matches`)."""

    speed_kmh: float
    lead: LeadFilterParams | None
    sample_time_s: float
    prediction_time_s: float
    known_delay_s: float
    path_curvatures_1pm: tuple[float, ...]
    lookahead_grid_m: tuple[float, float, float]
    phase_margin_deg: float
    gain_margin_db: float

    def matches(self, other: FloorInputs) -> bool:
        """Whether other's floor is this one's: the same speed and lead filter, and every number within
        FLOOR_INPUT_REL_TOL of this one's. Tolerance, not equality, because some are computed (the arc, the period
        from a rate) and two computations of one value may differ by a rounding (v * v against v**2); such a
        difference is far below any that moves a floor on its grid. The search grid must be the same: a floor
        searched from a lower start is not the floor searched from a higher one, as `lookahead_floor`'s bisection
        visits other lookaheads and, where the margins fail in a gap above a passing lookahead, stops elsewhere."""
        if self.speed_kmh != other.speed_kmh or self.lead != other.lead:
            return False
        ours, theirs = self._numbers(), other._numbers()
        return len(ours) == len(theirs) and all(
            math.isclose(a, b, rel_tol=FLOOR_INPUT_REL_TOL) for a, b in zip(ours, theirs, strict=True)
        )

    def _numbers(self) -> tuple[float, ...]:
        return (
            self.sample_time_s, self.prediction_time_s, self.known_delay_s, *self.path_curvatures_1pm,
            *self.lookahead_grid_m, self.phase_margin_deg, self.gain_margin_db,
        )  # fmt: skip


@dataclass(frozen=True)
class FloorDesign:
    """How the tuning's margins design computed its floors (`tuning schedule --design margins`): the loop at
    sample_time_s (s) with prediction_time_s (s) and no known delay, about a straight and an arc of
    arc_lateral_accel_g (g) capped at the steering lock, searched over lookahead_grid_m (shortest, longest, step;
    m), keeping phase_margin_deg and gain_margin_db (those of `loop_requirements`, which the design keeps)."""

    sample_time_s: float
    prediction_time_s: float
    arc_lateral_accel_g: float
    lookahead_grid_m: tuple[float, float, float]
    phase_margin_deg: float = REQUIRED_PHASE_MARGIN_DEG
    gain_margin_db: float = REQUIRED_GAIN_MARGIN_DB

    def inputs(
        self,
        speed_kmh: float,
        lead: LeadFilterParams,
        lock_curvature_1pm: float,
        curvature_limit_1pm: float = math.inf,
    ) -> FloorInputs:
        """The inputs of its floor at speed_kmh (km/h) with this lead filter, the arc capped at the steered
        vehicle's lock curvature (1/m), as `tuning.schedule.margins_arc_curvature_1pm` caps it, and then at
        curvature_limit_1pm (1/m; the controller's curvature limit at that speed, which caps the controller's own
        arc: at and below the lock, it bounds the arcs the controller steers, and its table's rounding must not
        make the two arcs differ)."""
        v = speed_kmh / 3.6
        arc = min(curvature_limit_1pm, lock_curvature_1pm, self.arc_lateral_accel_g * G_MPS2 / (v * v))
        return FloorInputs(
            speed_kmh, lead, self.sample_time_s, self.prediction_time_s, 0.0, (0.0, arc), self.lookahead_grid_m,
            self.phase_margin_deg, self.gain_margin_db,
        )  # fmt: skip


@dataclass(frozen=True)
class VehicleTuning:
    """The clothoid controller's tuning of one vehicle: filter_schedule (the lead filter against speed), limits
    (curvature and curvature-rate limits against speed), lags ((speed_kmh, the Eq. 5 lag to the path curvature
    identified there), speeds increasing, the same speeds as the schedule), source (which files, made for which
    vehicle), measured_lags (the same for the lag to the measured curvature, yaw rate / speed, at the same speeds;
    empty when not identified), floors ((speed_kmh, the lookahead floor the margins design computed there, m), at
    some of the lags' speeds), floor_design (what they were computed for; None: no floors) and previews ((speed_kmh,
    the preview responses identified there) at the lags' speeds, all on one grid of taps; empty when not
    identified) and releases ((speed_kmh, the sideslip's steady turns and release identified there,
    `sideslip_release.py`) at the lags' speeds; empty when not identified)."""

    filter_schedule: FilterSchedule
    limits: CurvatureLimits
    lags: tuple[tuple[float, SteeringLag], ...]
    source: str
    measured_lags: tuple[tuple[float, SteeringLag], ...] = ()
    floors: tuple[tuple[float, float], ...] = ()
    floor_design: FloorDesign | None = None
    previews: tuple[tuple[float, PreviewResponse], ...] = ()
    releases: tuple[tuple[float, SideslipRelease], ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.filter_schedule, FilterSchedule):
            raise WorkbenchInputError(f"filter_schedule must be a FilterSchedule; got {self.filter_schedule!r}")
        if not isinstance(self.limits, CurvatureLimits):
            raise WorkbenchInputError(f"limits must be CurvatureLimits; got {self.limits!r}")
        lags = _checked_lags("lags", self.lags)
        if not lags:
            raise WorkbenchInputError("lags must hold at least one (speed_kmh, SteeringLag)")
        object.__setattr__(self, "lags", lags)
        measured = _checked_lags("measured_lags", self.measured_lags)
        if measured and tuple(s for s, _ in measured) != self.lag_speeds_kmh:
            raise WorkbenchInputError(
                f"measured_lags' speeds {shown_all(s for s, _ in measured)} must be the lags' "
                f"{shown_all(self.lag_speeds_kmh)}"
            )
        object.__setattr__(self, "measured_lags", measured)
        floors = tuple((float(speed), float(floor)) for speed, floor in self.floors)
        for speed, floor in floors:
            if speed not in self.lag_speeds_kmh or not (math.isfinite(floor) and floor > 0.0):
                raise WorkbenchInputError(
                    f"floors must be (one of the lags' speeds {shown_all(self.lag_speeds_kmh)}, a lookahead > 0 m); "
                    f"got ({value_text(speed)}, {value_text(floor)})"
                )
        if floors and self.floor_design is None:
            raise WorkbenchInputError("floors need their floor_design (what they were computed for)")
        object.__setattr__(self, "floors", floors)
        previews = tuple((float(speed), response) for speed, response in self.previews)
        if previews and not measured:
            raise WorkbenchInputError("previews need the measured lags (identified from the same logs); got none")
        if previews:
            if tuple(s for s, _ in previews) != self.lag_speeds_kmh or not all(
                isinstance(r, PreviewResponse) and r.same_taps(previews[0][1]) for _, r in previews
            ):
                raise WorkbenchInputError(
                    "previews must be (speed_kmh, PreviewResponse) at the lags' speeds "
                    f"{shown_all(self.lag_speeds_kmh)}, all on one grid of taps; got speeds "
                    f"{shown_all(s for s, _ in previews)}"
                )
        object.__setattr__(self, "previews", previews)
        releases = tuple((float(speed), release) for speed, release in self.releases)
        if releases and (
            tuple(s for s, _ in releases) != self.lag_speeds_kmh
            or not all(isinstance(r, SideslipRelease) for _, r in releases)
        ):
            raise WorkbenchInputError(
                f"releases must be (speed_kmh, SideslipRelease) at the lags' speeds {shown_all(self.lag_speeds_kmh)}; "
                f"got speeds {shown_all(s for s, _ in releases)}"
            )
        object.__setattr__(self, "releases", releases)

    @property
    def lag_explains_logs(self) -> bool:
        """Whether the lag of Eq. 5 explains the vehicle's logs: the median of its fits' NRMSE over the speeds at
        most LAG_EXPLAINS_NRMSE (True when the fits recorded none)."""
        errors = [lag.nrmse for _, lag in self.lags if math.isfinite(lag.nrmse)]
        return not errors or float(np.median(errors)) <= LAG_EXPLAINS_NRMSE

    @functools.cached_property
    def preview_tables(self) -> tuple[float, float, np.ndarray, np.ndarray]:
        """(first tap s, tap spacing s, steering taps (n, m), measured taps (n, m)) at the lags' speeds, as
        `preview_model.preview_curvature` reads them; (0, 1, (0, 0), (0, 0)) without previews."""
        if not self.previews:
            return 0.0, 1.0, np.zeros((0, 0)), np.zeros((0, 0))
        first = self.previews[0][1]
        steering = np.array([r.steering_taps for _, r in self.previews], dtype=float)
        measured = np.array([r.measured_taps for _, r in self.previews], dtype=float)
        return first.first_tap_s, first.tap_spacing_s, steering, measured

    @functools.cached_property
    def preview_lag_tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """`lag_tables` with each speed's preview taps after its lag's columns (the path lag's row the steering
        taps then the handling gain, the measured lag's the measured taps), as the compiled step reads them when the
        feed-forward uses the preview responses (`step_kernel.LAG_COLUMNS`); `lag_tables` itself without
        previews."""
        speeds, lags, measured = self.lag_tables
        if not self.previews:
            return speeds, lags, measured
        _, _, steering, measured_taps = self.preview_tables
        return speeds, np.hstack([lags, steering, self.handling_table]), np.hstack([measured, measured_taps])

    @functools.cached_property
    def handling_table(self) -> np.ndarray:
        """The preview responses' handling gains (n speeds, len(HANDLING_GRID_G)), as
        `preview_model.preview_curvature` reads them; (0, 0) without previews."""
        if not self.previews:
            return np.zeros((0, 0))
        return np.array([r.handling_gain for _, r in self.previews], dtype=float)

    @functools.cached_property
    def release_table(self) -> np.ndarray:
        """The sideslip's release at the lags' speeds (n, 1 + len(HANDLING_GRID_G)): each row the release rate
        (1/s; 0: none) then the steady sideslip on the grid (rad), `SideslipRelease.row`; no rows without
        releases."""
        if not self.releases:
            return np.zeros((0, 1 + len(HANDLING_GRID_G)))
        return np.array([release.row() for _, release in self.releases], dtype=float)

    def recorded_floor_m(
        self, inputs: FloorInputs, lock_curvature_1pm: float, curvature_limit_1pm: float = math.inf
    ) -> float | None:
        """The lookahead floor (m) this tuning computed at inputs.speed_kmh, when it was computed from these inputs
        (`FloorInputs.matches`; the steered vehicle's lock curvature and the controller's curvature limit there,
        1/m, cap its arc as `FloorDesign.inputs` says) and this tuning's lags there (both lags identified); None
        otherwise: then the floor is to be computed."""
        design, floor = self.floor_design, dict(self.floors).get(inputs.speed_kmh)
        if design is None or floor is None or not self.measured_lags:
            return None
        lead = self.filter_schedule.at_speed(inputs.speed_kmh)
        recorded = design.inputs(inputs.speed_kmh, lead, lock_curvature_1pm, curvature_limit_1pm)
        return floor if recorded.matches(inputs) else None

    @functools.cached_property
    def lag_tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(speeds km/h (n,), lags (n, 4), measured lags (n, 4) or (0, 4) without): each lag's LAG_COLUMNS, as
        `speed_tables.table_row` reads them (the compiled step's feed-forward timing too)."""

        def rows(lags: tuple[tuple[float, SteeringLag], ...]) -> np.ndarray:
            return np.array([[getattr(lag, k) for k in LAG_COLUMNS] for _, lag in lags], dtype=float).reshape(-1, 4)

        return np.array(self.lag_speeds_kmh, dtype=float), rows(self.lags), rows(self.measured_lags)

    @property
    def lag_speeds_kmh(self) -> tuple[float, ...]:
        return tuple(speed for speed, _ in self.lags)

    def lag_at(self, speed_kmh: float) -> SteeringLag:
        """The lag (to the path curvature) at speed_kmh (km/h): omega_n, zeta, delay and K interpolated linearly in
        speed between the identified speeds, clamped beyond the ends (the identified lag itself at an identified
        speed)."""
        speeds, lags, _ = self.lag_tables
        return _interpolated(self.lags, speed_kmh, "lags", self.source, speeds, lags)

    def release_at(self, speed_kmh: float) -> SideslipRelease | None:
        """The sideslip's release at speed_kmh (km/h), its table row (`release_table`) interpolated linearly in
        speed as the compiled step reads it, clamped beyond the ends; None without releases or where none was
        identified there (a rate of 0: nothing released)."""
        _check_speed(speed_kmh)
        if not self.releases:
            return None
        table = self.release_table
        row = np.empty(table.shape[1])
        table_row(np.array(self.lag_speeds_kmh, dtype=float), table, float(speed_kmh), False, row)
        rate, *sideslip = row.tolist()
        return SideslipRelease.from_rate(tuple(sideslip), rate) if rate > 0.0 else None

    def measured_lag_at(self, speed_kmh: float) -> SteeringLag | None:
        """The lag to the measured curvature (yaw rate / speed) at speed_kmh, interpolated as `lag_at`; None when the
        tuning has none (files made before it was recorded: the controller then uses the path lag)."""
        if not self.measured_lags:
            _check_speed(speed_kmh)
            return None
        speeds, _, measured = self.lag_tables
        return _interpolated(self.measured_lags, speed_kmh, "measured lags", self.source, speeds, measured)


def _check_speed(speed_kmh: float) -> None:
    if isinstance(speed_kmh, bool) or not isinstance(speed_kmh, int | float) or not math.isfinite(speed_kmh):
        raise WorkbenchInputError(f"speed_kmh must be a finite number; got {value_text(speed_kmh)}")


def _checked_lags(name: str, value: object) -> tuple[tuple[float, SteeringLag], ...]:
    """(speed_kmh, SteeringLag) pairs as a tuple of float speeds, speeds increasing strictly."""
    # the field as given (any object): taken as pairs here, each pair checked below
    lags = tuple((float(speed), lag) for speed, lag in value)  # type: ignore[attr-defined]
    for i, (speed, lag) in enumerate(lags):
        if not (math.isfinite(speed) and speed >= 0.0) or not isinstance(lag, SteeringLag):
            raise WorkbenchInputError(
                f"{name}[{i}] must be (speed_kmh >= 0, SteeringLag); got ({value_text(speed)}, {type(lag).__name__})"
            )
    speeds = [speed for speed, _ in lags]
    if any(b <= a for a, b in itertools.pairwise(speeds)):
        raise WorkbenchInputError(f"{name}' speeds must increase strictly; got {shown_all(speeds)}")
    return lags


def _interpolated(
    lags: tuple[tuple[float, SteeringLag], ...],
    speed_kmh: float,
    what: str,
    source: str,
    table_speeds: np.ndarray,
    rows: np.ndarray,
) -> SteeringLag:
    """The lag of `lags` at speed_kmh, each parameter interpolated linearly in speed (`speed_tables.table_row` on
    the table (table_speeds, rows) of `lags`), clamped beyond the ends: an identified lag itself at its speed."""
    _check_speed(speed_kmh)
    speeds = tuple(speed for speed, _ in lags)
    i = bisect.bisect_left(speeds, speed_kmh)
    if i < len(speeds) and speeds[i] == speed_kmh:
        return lags[i][1]
    if i == 0 or i == len(speeds):
        return lags[0 if i == 0 else -1][1]
    out = np.empty(len(LAG_COLUMNS))
    table_row(table_speeds, rows, float(speed_kmh), False, out)
    omega_n, zeta, delay, gain = out.tolist()
    return SteeringLag(
        omega_n,
        zeta,
        delay,
        steady_state_gain=gain,
        source=f"interpolated at {speed_kmh:g} km/h between the {what} at {speeds[i - 1]:g} and {speeds[i]:g} km/h "
        f"({source})",
    )
