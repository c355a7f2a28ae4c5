"""A lead filter scheduled on speed: the paper's stated future work (section 7: the filter tuned at 30 km/h is
suboptimal at higher speeds).

At each speed the plant is driven open loop (`generate_open_loop_log`) with the dlc, step-series and chirp steering
profiles (SCHEDULE_MANEUVERS), sized for a small kinematic lateral acceleration (default 0.1 g: linear, far from
rollover) at no more than half the vehicle's steering-wheel rate limit (so that the actuator stays linear). Two lags
of Eq. 5 are fitted to the logs jointly (`fit_lag`): to the path curvature (the rear axle's x, y: what moves the
rear axle) and to the measured curvature (yaw rate / speed: what the clothoid controller measures). The lead filter
is designed for them: "cancel" (`design_lead`: the paper's loop shaping of the lag alone) or "margins"
(`design_lead_for_margins`: the shortest lookahead floor of the clothoid loop, at the controller's rate and pose
prediction, with 45 deg / 6 dB margins about a straight and an arc of 0.4 g).

The filters form a `FilterSchedule`, written in the lead-filter file format with a `schedule` list, which the
clothoid controller interpolates at the current speed; the file's `design` table keeps, per speed, the identified
lags (the measured lag's keys prefixed `measured_`), the filter, and with "margins" the floor with and without it.
With a fitted delay (`tuning schedule --delay`) Eq. 5 matches the plant's frequency response where it matters for
the loop; the chirp is logged because on dlc and steps alone delay and damping trade off (`tuning/lag_fit.py`).
`drop_refused=True` (`--drop-refused`) leaves a refused speed out, recorded with the reason in the file's
`design.dropped_speeds`, instead of refusing the whole schedule.

Whether the schedule tracks better than a fixed filter in closed loop is shown by
`tuning/filter_comparison.py`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.clothoid.filter_schedule import FilterSchedule
from controllers.clothoid.loop_analysis import LoopSettings, PlantLags
from controllers.clothoid.loop_requirements import REQUIRED_GAIN_MARGIN_DB, REQUIRED_PHASE_MARGIN_DEG
from tuning.data_generation import generate_open_loop_log
from tuning.filter_file import write_filter_file
from tuning.handling_fit import HANDLING_LADDER_G, HandlingFit, fit_handling
from tuning.lag_fit import LagFit, LagFitOptions, fit_lag
from tuning.lead_design import (
    DEFAULT_MAX_CASCADE_PEAK_DB,
    DEFAULT_MAX_LEAD_GAIN,
    LeadDesign,
    MarginsDesign,
    check_design_bounds,
    design_lead,
    design_lead_for_margins,
)
from tuning.log_file import VehicleLog
from tuning.maneuvers import Braking, Maneuver
from tuning.preview_fit import PreviewFit, PreviewFitOptions, fit_preview
from tuning.release_fit import RELEASE_HOLD_S, RELEASE_TURN_G, ReleaseFit, fit_release, release_braking
from tuning.speeds import check_speeds
from workbench.base.errors import WorkbenchInputError, require_in_range, value_text
from workbench.vehicles.base import VehicleModel
from workbench.vehicles.steering_lag import SteeringLag

DEFAULT_LAT_ACCEL_G = 0.1
#: The identification maneuvers' kinematic lateral acceleration may be set within this range (g).
LAT_ACCEL_RANGE_G = (0.001, 1.0)
SCHEDULE_MANEUVERS = ("dlc", "step-series", "chirp")
#: The identification maneuvers ask at most this fraction of the vehicle's steering-wheel rate limit (their steps
#: become ramps, the chirp's amplitude falls at high frequency), so that the actuator stays linear.
IDENTIFICATION_RATE_FRACTION = 0.5
#: How the lead filter is designed at each speed: "cancel" (`design_lead`: zeros on the path lag's poles) or
#: "margins" (`design_lead_for_margins`: the shortest lookahead floor of the clothoid loop).
DESIGNS = ("cancel", "margins")
#: The margins design's loop: the controller rate (Hz) and pose prediction (s) of the clothoid controller's
#: defaults, and the arc the floor is checked about (lateral acceleration, g, capped at the steering lock).
DEFAULT_CONTROLLER_RATE_HZ = 50.0
DEFAULT_PREDICTION_TIME_S = 0.2
MARGINS_ARC_LATERAL_ACCEL_G = 0.4
#: The lookaheads the margins design searches (m): those the clothoid controller's floor may take (its
#: MAX_FLOOR_LOOKAHEAD_M), from 3 m in steps of 0.5 m.
MARGINS_LOOKAHEAD_M = (3.0, 40.0, 0.5)
SPEED_RANGE_KMH = (5.0, 200.0)
#: The speed the paper tuned its lead filter at: the fixed filter the schedule is compared with by default.
PAPER_SPEED_KMH = 30.0
#: Two speeds closer than this (km/h) are the same speed of a schedule (the --speeds and --nominal-speed texts).
SPEED_MATCH_KMH = 1e-6


@dataclass(frozen=True)
class ScheduleEntry:
    """One speed of a schedule: the lags identified there, the filter designed for the path lag, its floors."""

    speed_kmh: float  # km/h; the speed identified at
    fit: LagFit  # the fit of the path lag
    design: LeadDesign  # the filter designed for it
    measured_fit: LagFit | None = None  # the fit of the measured (yaw-rate) lag (None: not identified)
    margins: MarginsDesign | None = None  # the margins design's lookahead floors (None: the cancel design)
    preview: PreviewFit | None = None  # the preview responses fitted to the same logs (None: not identified)
    handling: HandlingFit | None = None  # the steady turns the preview's handling gain came from (None: none)
    release: ReleaseFit | None = None  # the sideslip's steady turns and release (None: no steady sideslip)

    def row(self) -> dict[str, Any]:
        """The entry as one row of the lead-filter file's ``design.per_speed`` table and of `ScheduleResult.table`.

        Returns
        -------
        dict of str to float
            speed_kmh; the path lag (omega_n_rad_s, zeta, steady_state_gain, delay_s, nrmse); the measured lag
            under the same keys prefixed ``measured_`` when it was identified; the filter (omega_z_rad_s, psi,
            omega_p_rad_s), its lead_peak_gain and the plant's and cascade's bandwidths (rad/s); with the margins
            design, lookahead_floor_m (or margin_score when no lookahead keeps the margins) and
            floor_without_lead_m when finite; with the preview responses, their first tap and spacing (s), NRMSE,
            taps and handling gain (lists of float), under keys prefixed ``preview_``; with the steady turns, their
            lateral accelerations (g), steering ratios and (when every turn has one) sideslips (rad, as of a left
            turn) as handling_lat_accel_g, handling_ratio and handling_sideslip_rad (lists); with the release, the
            steady sideslip on the handling grid (rad, list), the release rate (1/s; 0: not identified) and, after a
            braked turn, the push (rad) as release_steady_sideslip_rad, release_rate_1ps and release_push_rad.
        """
        lag, d = self.fit.lag, self.design
        out: dict[str, Any] = {
            "speed_kmh": self.speed_kmh,
            "omega_n_rad_s": lag.omega_n_rad_s,
            "zeta": lag.zeta,
            "steady_state_gain": self.fit.gain,
            "delay_s": lag.delay_s,
            "nrmse": lag.nrmse,
        }
        if self.measured_fit is not None:
            m = self.measured_fit.lag
            out.update(
                measured_omega_n_rad_s=m.omega_n_rad_s,
                measured_zeta=m.zeta,
                measured_steady_state_gain=m.steady_state_gain,
                measured_delay_s=m.delay_s,
                measured_nrmse=m.nrmse,
            )
        out.update(
            omega_z_rad_s=d.params.omega_z_rad_s,
            psi=d.params.psi,
            omega_p_rad_s=d.params.omega_p_rad_s,
            lead_peak_gain=d.lead_peak_gain,
            plant_bandwidth_rad_s=d.plant_bandwidth_rad_s,
            cascade_bandwidth_rad_s=d.cascade_bandwidth_rad_s,
        )
        if self.margins is not None:  # a floor left out: no lookahead up to MARGINS_MAX_LOOKAHEAD_M keeps the margins
            margins = self.margins
            if math.isfinite(margins.floor_m):
                out["lookahead_floor_m"] = margins.floor_m
            else:
                out["margin_score"] = margins.margin_score
            if math.isfinite(margins.floor_without_lead_m):
                out["floor_without_lead_m"] = margins.floor_without_lead_m
        if self.preview is not None:
            response = self.preview.response
            out.update(
                preview_first_tap_s=response.first_tap_s,
                preview_tap_spacing_s=response.tap_spacing_s,
                preview_steering_nrmse=self.preview.steering_nrmse,
                preview_measured_nrmse=self.preview.measured_nrmse,
                preview_steering_taps=[float(f"{v:.7g}") for v in response.steering_taps],
                preview_measured_taps=list(response.measured_taps),
                preview_handling_gain=[float(f"{v:.7g}") for v in response.handling_gain],
            )
        if self.handling is not None:
            out.update(
                handling_lat_accel_g=[float(f"{t.lat_accel_g:.5g}") for t in self.handling.turns],
                handling_ratio=[float(f"{t.steering_ratio:.7g}") for t in self.handling.turns],
            )
            if all(math.isfinite(t.sideslip_rad) for t in self.handling.turns):
                out["handling_sideslip_rad"] = [float(f"{t.sideslip_rad:.7g}") for t in self.handling.turns]
        if self.release is not None:
            release = self.release.release
            out.update(
                release_steady_sideslip_rad=[float(f"{v:.7g}") for v in release.steady_sideslip_rad],
                release_rate_1ps=float(f"{release.rate_1ps:.5g}"),
            )
            if math.isfinite(self.release.push_rad):
                out["release_push_rad"] = float(f"{self.release.push_rad:.5g}")
        return out


@dataclass(frozen=True)
class DroppedSpeed:
    """A speed left out of a schedule (`drop_refused`), why, and what was fitted there before the refusal."""

    speed_kmh: float  # km/h; the speed left out
    reason: str  # why: the refusal of the fit or of the design, in words
    lag: SteeringLag | None = None  # the fitted path lag when the design was refused (None: the fit was)
    measured_lag: SteeringLag | None = None  # the fitted measured (yaw-rate) lag, when there was one

    def row(self) -> dict[str, float | str]:
        """The dropped speed as one row of the lead-filter file's ``design.dropped_speeds`` table.

        Returns
        -------
        dict of str to float or str
            speed_kmh and reason; the path lag's omega_n_rad_s, zeta, steady_state_gain, delay_s and nrmse when it
            was fitted; the measured lag's under the same keys prefixed ``measured_`` (but nrmse) when it was.
        """
        out: dict[str, float | str] = {"speed_kmh": self.speed_kmh, "reason": self.reason}
        if self.lag is not None:
            lag = self.lag
            out.update(omega_n_rad_s=lag.omega_n_rad_s, zeta=lag.zeta, steady_state_gain=lag.steady_state_gain)
            out.update(delay_s=lag.delay_s, nrmse=lag.nrmse)
        if self.measured_lag is not None:
            m = self.measured_lag
            out.update(measured_omega_n_rad_s=m.omega_n_rad_s, measured_zeta=m.zeta)
            out.update(measured_steady_state_gain=m.steady_state_gain, measured_delay_s=m.delay_s)
        return out


@dataclass(frozen=True)
class ScheduleResult:
    """The identified lead-filter schedule of one vehicle: a lag fit and a filter per speed kept."""

    vehicle: str  # the vehicle's model name
    entries: tuple[ScheduleEntry, ...]  # one per speed kept, by increasing speed
    lat_accel_g: float  # g; the kinematic lateral acceleration of the identification maneuvers
    fit_delay: bool = False  # whether the lags were fitted with a pure delay
    dropped: tuple[DroppedSpeed, ...] = field(default=())  # the speeds left out (with `drop_refused`)
    design: str = "cancel"  # the lead design: "cancel" (`design_lead`) or "margins" (`design_lead_for_margins`)
    controller_rate_hz: float = DEFAULT_CONTROLLER_RATE_HZ  # Hz; the controller rate the margins design analysed
    prediction_time_s: float = DEFAULT_PREDICTION_TIME_S  # s; the pose prediction the margins design analysed
    preview_options: PreviewFitOptions | None = None  # how the preview responses were fitted (None: they were not)

    @property
    def speeds_kmh(self) -> tuple[float, ...]:
        """The speeds kept (km/h), strictly increasing, one per entry."""
        return tuple(e.speed_kmh for e in self.entries)

    def entry_at(self, speed_kmh: float, what: str) -> ScheduleEntry:
        """The entry identified at speed_kmh (km/h); WorkbenchInputError naming `what`, the speeds kept and, when
        it was left out (`drop_refused`), why.

        Parameters
        ----------
        speed_kmh : float, km/h
            One of the schedule's speeds (`speeds_kmh`), matched within SPEED_MATCH_KMH.
        what : str
            What the speed is, for the error message (e.g. "the nominal speed").

        Returns
        -------
        ScheduleEntry
            The lags, the filter and (margins design) the floors identified at that speed.

        Raises
        ------
        WorkbenchInputError
            speed_kmh is not one of the speeds kept; the message lists them and, for a dropped speed, the reason.
        """
        for entry in self.entries:
            if abs(entry.speed_kmh - speed_kmh) <= SPEED_MATCH_KMH:
                return entry
        kept = ", ".join(f"{s:g}" for s in self.speeds_kmh)
        dropped = [d.reason for d in self.dropped if abs(d.speed_kmh - speed_kmh) <= SPEED_MATCH_KMH]
        why = f" (it was dropped: {dropped[0]})" if dropped else ""
        raise WorkbenchInputError(
            f"{what} {value_text(speed_kmh)} km/h is not a speed of the schedule{why}; it must be one of the speeds "
            f"identified: {kept} km/h"
        )

    def filter_schedule(self) -> FilterSchedule:
        """The filters as the schedule the clothoid controller interpolates on speed.

        Returns
        -------
        FilterSchedule
            The speeds kept (km/h) and each speed's lead-filter parameters, with a source text naming the vehicle,
            the maneuvers and the design.
        """
        return FilterSchedule(self.speeds_kmh, tuple(e.design.params for e in self.entries), source=self._source())

    def _source(self) -> str:
        delay = " with a pure delay" if self.fit_delay else ""
        how = (
            "lead filter by design_lead"
            if self.design == "cancel"
            else "lead filter by design_lead_for_margins (the shortest lookahead floor of the clothoid loop)"
        )
        return (
            f"tuning schedule: {self.vehicle}, lag of Eq. 5{delay} fitted at each speed to open-loop "
            f"{', '.join(SCHEDULE_MANEUVERS)} logs at {self.lat_accel_g:g} g, {how}"
        )

    def write(self, path: str | Path, nominal_speed_kmh: float | None = None) -> Path:
        """Write the lead-filter file (JSON, or TOML by suffix). The top-level filter and `plant` are those of the
        speed nominal_speed_kmh, which must be one of the schedule's speeds (default: the first speed): a filter is
        designed only at the speeds identified, so another speed's would be a different filter under its name.

        Parameters
        ----------
        path : str or pathlib.Path
            The file to write: ``.json`` or ``.toml`` (the suffix chooses the format).
        nominal_speed_kmh : float or None, km/h
            The speed whose filter and lag are the file's top-level filter and ``plant``; one of `speeds_kmh`
            (None: the first).

        Returns
        -------
        pathlib.Path
            The path written.

        Raises
        ------
        WorkbenchInputError
            nominal_speed_kmh is not one of the schedule's speeds, or the path's suffix is neither .json nor .toml.
        """
        nominal = self.entries[0]
        if nominal_speed_kmh is not None:
            nominal = self.entry_at(nominal_speed_kmh, "the nominal speed")
        first = self.entries[0].design
        design: dict[str, object] = {"method": first.method, "max_lead_gain": first.max_lead_gain}
        if math.isfinite(first.max_cascade_peak_db):  # the margins design bounds the peak gain only
            design["max_cascade_peak_db"] = first.max_cascade_peak_db
        if self.design == "margins":
            design.update(
                controller_rate_hz=self.controller_rate_hz,
                prediction_time_s=self.prediction_time_s,
                arc_lateral_accel_g=MARGINS_ARC_LATERAL_ACCEL_G,
                lookahead_range_m=list(MARGINS_LOOKAHEAD_M),
                phase_margin_deg=REQUIRED_PHASE_MARGIN_DEG,
                gain_margin_db=REQUIRED_GAIN_MARGIN_DB,
            )
        design.update(
            lat_accel_g=self.lat_accel_g,
            maneuvers=list(SCHEDULE_MANEUVERS),
            fit_delay=self.fit_delay,
            per_speed=[e.row() for e in self.entries],
        )
        if self.preview_options is not None:
            design["preview_fit"] = dataclasses.asdict(self.preview_options)
        if self.dropped:
            design["dropped_speeds"] = [d.row() for d in self.dropped]
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
        """The schedule as a fixed-width text table, one line per speed kept and one per speed dropped.

        Returns
        -------
        str
            Columns: speed (km/h), the path lag (omega_n rad/s, zeta, K, delay s, NRMSE), the measured lag (``m_``
            columns, when identified), the filter (omega_z rad/s, psi, omega_p rad/s, peak gain), the plant's and
            cascade's bandwidths (rad/s) and, with the margins design, the lookahead floors with and without the
            lead (m; nan when none keeps the margins).
        """
        measured = any(e.measured_fit is not None for e in self.entries)
        floors = any(e.margins is not None for e in self.entries)
        head = "speed_kmh  omega_n  zeta    K      delay_s  nrmse  "
        head += " m_omega_n  m_zeta  m_K    m_delay_s" if measured else ""
        head += "  omega_z  psi    omega_p  peak_gain  bw_plant  bw_cascade"
        head += "  floor_m  floor_no_lead_m" if floors else ""
        lines = [head]
        for e in self.entries:
            r = e.row()
            line = (
                f"{r['speed_kmh']:9.1f}  {r['omega_n_rad_s']:7.3f}  {r['zeta']:6.3f}  {r['steady_state_gain']:5.3f}  "
                f"{r['delay_s']:7.3f}  {r['nrmse']:6.4f}"
            )
            if measured:
                line += (
                    f"  {r.get('measured_omega_n_rad_s', math.nan):9.3f}  {r.get('measured_zeta', math.nan):6.3f}  "
                    f"{r.get('measured_steady_state_gain', math.nan):5.3f}  {r.get('measured_delay_s', math.nan):9.3f}"
                )
            line += (
                f"  {r['omega_z_rad_s']:7.3f}  {r['psi']:5.3f}  {r['omega_p_rad_s']:7.3f}  {r['lead_peak_gain']:9.3f}  "
                f"{r['plant_bandwidth_rad_s']:8.3f}  {r['cascade_bandwidth_rad_s']:10.3f}"
            )
            if floors:
                floor, without = (r.get(k, math.nan) for k in ("lookahead_floor_m", "floor_without_lead_m"))
                line += f"  {floor:7.2f}  {without:15.2f}"
            lines.append(line)
        lines += [f"{d.speed_kmh:9.1f}  dropped: {d.reason}" for d in self.dropped]
        return "\n".join(lines)


def identification_logs(
    vehicle: VehicleModel,
    speed_kmh: float,
    lat_accel_g: float = DEFAULT_LAT_ACCEL_G,
    maneuvers: Sequence[str] = SCHEDULE_MANEUVERS,
    duration_s: float = 20.0,
    sample_rate_hz: float = 100.0,
) -> list[VehicleLog]:
    """Open-loop logs at speed_kmh, each profile's amplitude giving lat_accel_g of kinematic lateral acceleration,
    its steering-wheel rate at most IDENTIFICATION_RATE_FRACTION of the vehicle's rate limit.

    Parameters
    ----------
    vehicle : VehicleModel
        The plant driven open loop.
    speed_kmh : float, km/h
        The held speed, within SPEED_RANGE_KMH (5-200 km/h).
    lat_accel_g : float, g
        The kinematic lateral acceleration each profile's amplitude gives, within LAT_ACCEL_RANGE_G
        (0.001-1 g); the amplitude is capped at the steering lock.
    maneuvers : sequence of str
        The steering profiles, one log each: "step", "step-series", "dlc" or "chirp".
    duration_s : float, s
        Each log's duration, > 0 (a chirp needs more than its start time).
    sample_rate_hz : float, Hz
        The logs' sample rate, 1-10000 Hz.

    Returns
    -------
    list of VehicleLog
        One log per maneuver, named "<maneuver> at <speed> km/h".

    Raises
    ------
    WorkbenchInputError
        A speed, lateral acceleration, duration or sample rate out of its range, or an unknown maneuver.
    """
    require_in_range("speed_kmh", speed_kmh, *SPEED_RANGE_KMH, "km/h")
    require_in_range("lat_accel_g", lat_accel_g, *LAT_ACCEL_RANGE_G, "g")
    amplitude = steer_amplitude_deg(vehicle, speed_kmh, lat_accel_g)
    return [
        _open_loop_log(vehicle, kind, amplitude, speed_kmh, duration_s, sample_rate_hz, f"{kind} at {speed_kmh:g} km/h")
        for kind in maneuvers
    ]


def handling_logs(
    vehicle: VehicleModel, speed_kmh: float, duration_s: float = 20.0, sample_rate_hz: float = 100.0
) -> list[VehicleLog]:
    """Open-loop steering steps at speed_kmh for the handling gain (`tuning.handling_fit`, ISO 4138's constant-speed
    method): one per rung of HANDLING_LADDER_G whose kinematic curvature is short of the steering lock, at most
    IDENTIFICATION_RATE_FRACTION of the vehicle's steering-wheel rate, held to the log's end.

    Parameters
    ----------
    vehicle : VehicleModel
        The plant driven open loop.
    speed_kmh : float, km/h
        The held speed, within SPEED_RANGE_KMH (5-200 km/h).
    duration_s : float, s
        Each log's duration, > 0: long enough for the turn to settle (`handling_fit.STEADY_WINDOW_S` at its end).
    sample_rate_hz : float, Hz
        The logs' sample rate, 1-10000 Hz.

    Returns
    -------
    list of VehicleLog
        One log per rung, named "step to <g> g at <speed> km/h"; none when even the first rung reaches the lock.

    Raises
    ------
    WorkbenchInputError
        A speed, duration or sample rate out of its range.
    """
    require_in_range("speed_kmh", speed_kmh, *SPEED_RANGE_KMH, "km/h")
    v = speed_kmh / 3.6
    logs = []
    for rung in HANDLING_LADDER_G:
        if rung * G_MPS2 / (v * v) >= lock_curvature_1pm(vehicle):
            break
        amplitude = steer_amplitude_deg(vehicle, speed_kmh, rung)
        name = f"step to {rung:g} g at {speed_kmh:g} km/h"
        logs.append(_open_loop_log(vehicle, "step", amplitude, speed_kmh, duration_s, sample_rate_hz, name))
    return logs


def release_log(
    vehicle: VehicleModel, speed_kmh: float, sample_rate_hz: float = 100.0
) -> tuple[VehicleLog, Braking] | None:
    """A steering step to RELEASE_TURN_G at speed_kmh, held, braked once the turn is steady (`release_fit`'s
    `release_braking`) and held at the lower speed for RELEASE_HOLD_S: the log the sideslip's release is identified
    from (`tuning.release_fit`), and its braking.

    Parameters
    ----------
    vehicle : VehicleModel
        The plant driven open loop.
    speed_kmh : float, km/h
        The held speed before the braking, within SPEED_RANGE_KMH (5-200 km/h).
    sample_rate_hz : float, Hz
        The log's sample rate, 1-10000 Hz.

    Returns
    -------
    (VehicleLog, Braking) or None
        The log, named "braked turn at <speed> km/h", and its braking; None when the turn's kinematic curvature
        reaches the steering lock.

    Raises
    ------
    WorkbenchInputError
        A speed or sample rate out of its range.
    """
    require_in_range("speed_kmh", speed_kmh, *SPEED_RANGE_KMH, "km/h")
    v = speed_kmh / 3.6
    if RELEASE_TURN_G * G_MPS2 / (v * v) >= lock_curvature_1pm(vehicle):
        return None
    braking = release_braking(speed_kmh)
    amplitude = steer_amplitude_deg(vehicle, speed_kmh, RELEASE_TURN_G)
    name = f"braked turn at {speed_kmh:g} km/h"
    duration = braking.end_s + RELEASE_HOLD_S
    return _open_loop_log(vehicle, "step", amplitude, speed_kmh, duration, sample_rate_hz, name, braking), braking


def _open_loop_log(
    vehicle: VehicleModel,
    kind: str,
    amplitude_deg: float,
    speed_kmh: float,
    duration_s: float,
    sample_rate_hz: float,
    name: str,
    braking: Braking | None = None,
) -> VehicleLog:
    """One open-loop log of the maneuver `kind` at amplitude_deg (steering wheel), its rate at most
    IDENTIFICATION_RATE_FRACTION of the vehicle's steering-wheel rate limit (with braking: the held speed braked by
    it)."""
    max_rate = IDENTIFICATION_RATE_FRACTION * math.degrees(vehicle.geometry.max_steer_wheel_rate_rad_s)
    maneuver = Maneuver(kind, amplitude_deg=amplitude_deg, duration_s=duration_s, max_rate_deg_s=max_rate)
    frame = generate_open_loop_log(vehicle, maneuver, speed_kmh, sample_rate_hz=sample_rate_hz, braking=braking)
    return VehicleLog.from_frame(frame, name=name)


def steer_amplitude_deg(vehicle: VehicleModel, speed_kmh: float, lat_accel_g: float) -> float:
    """Steering-wheel angle (deg) whose kinematic curvature gives lat_accel_g at speed_kmh, capped at the lock.

    Parameters
    ----------
    vehicle : VehicleModel
        The vehicle whose geometry (wheelbase, steering ratio, lock) turns curvature into a steering-wheel angle.
    speed_kmh : float, km/h
        The speed, > 0.
    lat_accel_g : float, g
        The kinematic lateral acceleration v^2 x curvature, >= 0.

    Returns
    -------
    float, deg
        The steering-wheel angle, at most the one at the steering lock.
    """
    v = speed_kmh / 3.6
    geometry = vehicle.geometry
    curvature = min(lat_accel_g * G_MPS2 / (v * v), lock_curvature_1pm(vehicle))
    return math.degrees(geometry.steer_wheel_for_curvature(curvature))


def lock_curvature_1pm(vehicle: VehicleModel) -> float:
    """The kinematic curvature (1/m) at the steering lock: tan(max road-wheel angle) / wheelbase.

    Parameters
    ----------
    vehicle : VehicleModel
        The vehicle whose geometry gives the largest road-wheel angle and the wheelbase.

    Returns
    -------
    float, 1/m
        The curvature at full lock, > 0.
    """
    geometry = vehicle.geometry
    return math.tan(geometry.max_road_wheel_angle_rad) / geometry.wheelbase_m


def margins_arc_curvature_1pm(vehicle: VehicleModel, speed_kmh: float) -> float:
    """The arc the margins design checks the floor about at speed_kmh: MARGINS_ARC_LATERAL_ACCEL_G / v^2, capped at
    the steering lock (the controller's floor uses its curvature limit; the lock bounds it).

    Parameters
    ----------
    vehicle : VehicleModel
        The vehicle whose steering lock caps the curvature.
    speed_kmh : float, km/h
        The speed, > 0.

    Returns
    -------
    float, 1/m
        The arc's curvature.
    """
    v = speed_kmh / 3.6
    return min(lock_curvature_1pm(vehicle), MARGINS_ARC_LATERAL_ACCEL_G * G_MPS2 / (v * v))


def identify_schedule(
    vehicle: VehicleModel,
    speeds_kmh: Sequence[float],
    lat_accel_g: float = DEFAULT_LAT_ACCEL_G,
    fit_options: LagFitOptions | None = None,
    max_lead_gain: float = DEFAULT_MAX_LEAD_GAIN,
    max_cascade_peak_db: float = DEFAULT_MAX_CASCADE_PEAK_DB,
    drop_refused: bool = False,
    progress: Callable[[str], None] | None = None,
    design: str = "cancel",
    controller_rate_hz: float = DEFAULT_CONTROLLER_RATE_HZ,
    prediction_time_s: float = DEFAULT_PREDICTION_TIME_S,
    preview_options: PreviewFitOptions | None = None,
) -> ScheduleResult:
    """Identify the lags and design the filter at each speed (km/h, strictly increasing). fit_options: how the
    lags are fitted (LagFitOptions; fit_delay adds a pure delay); the path lag with its curvature_from (default: the
    rear-axle path), the measured lag from yaw rate / speed with the same options. design: "cancel" (`design_lead`
    on the path lag, bounded by max_lead_gain and max_cascade_peak_db) or "margins" (`design_lead_for_margins` on
    both lags, the loop at controller_rate_hz with prediction_time_s, about a straight and the arc of
    margins_arc_curvature_1pm; bounded by max_lead_gain). A speed whose fit or design is refused makes the whole
    schedule refused, naming the speed; with drop_refused=True it is left out and recorded in `dropped` instead
    (refused only when no speed is left). progress, if given, is called with one line per speed. The preview
    responses (`tuning.preview_fit`) are fitted to the same maneuvers at each speed, at preview_options.lat_accel_g
    (0.2 g by default: the feed-forward's operating range, where the lags are a linearisation at lat_accel_g), their
    handling gain (`tuning.handling_fit`, one at that lateral acceleration) to steady turns at the same speed
    (`handling_logs`).

    Parameters
    ----------
    vehicle : VehicleModel
        The plant the open-loop logs are simulated with.
    speeds_kmh : sequence of float, km/h
        The speeds to identify, 1 to 200 of them, each within SPEED_RANGE_KMH (5-200 km/h), strictly increasing.
    lat_accel_g : float, g
        The identification maneuvers' kinematic lateral acceleration, within LAT_ACCEL_RANGE_G (0.001-1 g).
    fit_options : LagFitOptions or None
        How the lags are fitted (None: the defaults; ``fit_delay=True`` adds a pure delay).
    max_lead_gain : float
        Bound on the lead filter's peak gain, 1-1000.
    max_cascade_peak_db : float, dB
        Bound on the resonance peak of lead x lag ("cancel" design), 0-20 dB.
    drop_refused : bool
        Leave a refused speed out (recorded in the result's ``dropped``) instead of refusing the schedule.
    progress : callable or None
        Called with one line of text per speed identified or dropped (None: silent).
    design : str
        "cancel" (`design_lead` on the path lag) or "margins" (`design_lead_for_margins` on both lags).
    controller_rate_hz : float, Hz
        The clothoid controller's rate the margins design analyses the loop at, 1-1000 Hz.
    prediction_time_s : float, s
        The controller's pose prediction the margins design analyses the loop with, 0-2 s.
    preview_options : PreviewFitOptions or None
        How the preview responses are fitted (None: the defaults).

    Returns
    -------
    ScheduleResult
        One entry per speed kept, the speeds dropped, and the settings; `ScheduleResult.write` writes the
        lead-filter file.

    Raises
    ------
    WorkbenchInputError
        An argument out of its range or an unknown design (before anything is identified); a speed whose fit or
        design is refused, naming the speed (without drop_refused); no speed left (with drop_refused).

    Examples
    --------
    Two speeds on the dynamic bicycle (a few seconds):

    >>> from tuning.schedule import identify_schedule
    >>> from workbench.vehicles import make_vehicle
    >>> result = identify_schedule(make_vehicle("dynamic-bicycle"), [30.0, 60.0])
    >>> result.speeds_kmh
    (30.0, 60.0)
    >>> entry = result.entry_at(60.0, "the speed")
    >>> round(entry.fit.lag.omega_n_rad_s, 1)
    7.7
    >>> path = result.write("lead_schedule.toml")  # doctest: +SKIP
    """
    speeds = check_speeds(speeds_kmh, *SPEED_RANGE_KMH)
    if design not in DESIGNS:
        raise WorkbenchInputError(f"design must be one of {', '.join(DESIGNS)}; got {design!r}")
    require_in_range("controller_rate_hz", controller_rate_hz, 1.0, 1000.0, "Hz")
    require_in_range("prediction_time_s", prediction_time_s, 0.0, 2.0, "s")
    require_in_range("lat_accel_g", lat_accel_g, *LAT_ACCEL_RANGE_G, "g")  # before any speed is identified
    check_design_bounds(max_lead_gain, max_cascade_peak_db)
    options = fit_options or LagFitOptions()
    preview_options = preview_options or PreviewFitOptions()
    measured_options = dataclasses.replace(options, curvature_from="yaw-rate")
    settings = LoopSettings(sample_time_s=1.0 / controller_rate_hz, prediction_time_s=prediction_time_s)
    entries, dropped = [], []
    for speed in speeds:
        logs = identification_logs(vehicle, speed, lat_accel_g)
        fit = measured = None
        try:
            fit = fit_lag(logs, vehicle.geometry, options)
            try:
                measured = fit_lag(logs, vehicle.geometry, measured_options)
            except WorkbenchInputError as exc:
                raise WorkbenchInputError(f"the measured (yaw-rate) lag: {exc}") from None
            preview_logs = logs
            if preview_options.lat_accel_g != lat_accel_g:  # the feed-forward's model, at its operating amplitude
                preview_logs = identification_logs(vehicle, speed, preview_options.lat_accel_g)
            preview = fit_preview(preview_logs, vehicle.geometry, preview_options)
            handling = fit_handling(handling_logs(vehicle, speed), vehicle.geometry, preview_options.lat_accel_g)
            release = fit_release(handling.turns, *(release_log(vehicle, speed) or (None, None)))
            preview = dataclasses.replace(
                preview, response=dataclasses.replace(preview.response, handling_gain=handling.gain)
            )
            margins = None
            if design == "cancel":
                lead = design_lead(fit.lag, max_lead_gain=max_lead_gain, max_cascade_peak_db=max_cascade_peak_db)
            else:
                margins = design_lead_for_margins(
                    PlantLags(fit.lag, measured.lag),
                    speed / 3.6,
                    settings,
                    *MARGINS_LOOKAHEAD_M,
                    path_curvatures_1pm=(0.0, margins_arc_curvature_1pm(vehicle, speed)),
                    max_lead_gain=max_lead_gain,
                )
                lead = margins.design
        except WorkbenchInputError as exc:
            if not drop_refused:
                raise WorkbenchInputError(f"at {speed:g} km/h: {exc}") from None
            dropped.append(
                DroppedSpeed(speed, str(exc), fit.lag if fit is not None else None, measured.lag if measured else None)
            )
            if progress is not None:
                progress(f"{speed:g} km/h: dropped: {exc}")
            continue
        entries.append(ScheduleEntry(speed, fit, lead, measured, margins, preview, handling, release))
        if progress is not None:
            floors = ""
            if margins is not None:
                floors = (
                    f"; lookahead floor {_floor_text(margins.floor_m)} with the lead, "
                    f"{_floor_text(margins.floor_without_lead_m)} without"
                )
            progress(
                f"{speed:g} km/h: path {fit.summary()}; measured {measured.summary()}; {preview.summary()}; "
                f"{handling.summary()}; {release.summary() if release else 'release: no steady sideslip'}; "
                f"{lead.summary()}{floors}"
            )
    if not entries:
        reasons = "; ".join(f"at {d.speed_kmh:g} km/h: {d.reason}" for d in dropped)
        raise WorkbenchInputError(f"no speed of {speeds} gave a lag and a lead filter: {reasons}")
    return ScheduleResult(
        vehicle.name,
        tuple(entries),
        float(lat_accel_g),
        options.fit_delay,
        tuple(dropped),
        design,
        float(controller_rate_hz),
        float(prediction_time_s),
        preview_options,
    )


def _floor_text(floor_m: float) -> str:
    return f"{floor_m:g} m" if math.isfinite(floor_m) else f"none up to {MARGINS_LOOKAHEAD_M[1]:g} m"


__all__ = [
    "DroppedSpeed",
    "ScheduleEntry",
    "ScheduleResult",
    "handling_logs",
    "identification_logs",
    "identify_schedule",
    "lock_curvature_1pm",
    "margins_arc_curvature_1pm",
    "release_log",
    "steer_amplitude_deg",
]
