"""Run metrics: the numbers in metrics.json. Other tools read these keys, so they are stable.

CTE is measured at the reference point (the tractor's rear-axle centre), signed, left of the path positive, at
every logged (controller) step; max_abs_cte_on_path_m leaves out the approach of a run started off the path
(`approach_end`). Vehicle fields (max_ltr, max_offtracking_m) are null for vehicles that do not
output them; the track fields (min_track_margin_m, left_track) are null when the path has no track widths or the
vehicle's outline is not known (`track_margin.py`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from workbench.base.path import ReferencePath
from workbench.simulation.limit_cycle import detect_limit_cycle, oscillation
from workbench.simulation.speed_profile import G_MPS2
from workbench.simulation.track_margin import VehicleOutline, track_margins, trailer_feet

#: A run is on the path once its |CTE| is within this (m): where a run started off it has come onto it
#: (`approach_end`), and the band comparisons call converged.
CONVERGED_CTE_M = 0.1

#: The keys of metrics.json, in order.
METRIC_KEYS: tuple[str, ...] = (
    "scenario",
    "controller",
    "vehicle",
    "completed",
    "distance_m",
    "path_length_m",
    "max_abs_cte_m",
    "max_abs_cte_on_path_m",
    "rms_cte_m",
    "max_abs_heading_error_deg",
    "max_abs_steer_wheel_deg",
    "max_abs_steer_rate_deg_s",
    "rms_steer_rate_deg_s",
    "steer_oscillation_deg",
    "limit_cycle",
    "limit_cycle_hz",
    "limit_cycle_amplitude_deg",
    "max_abs_lat_accel_g",
    "max_ltr",
    "max_offtracking_m",
    "step_time_median_us",
    "step_time_p99_us",
    "min_track_margin_m",
    "left_track",
)


@dataclass(frozen=True)
class Metrics:
    """Summary of one run; None where a quantity does not apply (no samples, no trailer, no roll model).

    CTE is the signed cross-track error at the reference point (left of the path positive). The steering-wheel
    rates difference the measured steering-wheel angle at the controller rate; the oscillation is
    `limit_cycle.oscillation`'s, away from the trace's ends. max_abs_cte_on_path_m is max_abs_cte_m itself for a
    run that starts on the path; for one started off it (fig17's 1 m) it is the tracking once the run has come onto
    the path, overshoot included, without the approach every controller shares. The track fields
    (`track_margin.track_margins`) are None when the path has no track widths or the vehicle's outline is not known.
    """

    scenario: str  # the scenario's name
    controller: str  # the controller's name
    vehicle: str  # the vehicle model's name
    completed: bool  # whether the run completed (`Status.COMPLETED`)
    distance_m: float  # m, >= 0; distance travelled by the reference point
    path_length_m: float  # m; length the run was asked to cover: the path's, times the laps of a closed path
    max_abs_cte_m: float | None  # m; the largest |CTE| over the run
    max_abs_cte_on_path_m: float | None  # m; the largest |CTE| once on the path (from `approach_end`)
    rms_cte_m: float | None  # m; the RMS CTE over the run
    max_abs_heading_error_deg: float | None  # deg; the largest |heading error| to the path
    max_abs_steer_wheel_deg: float | None  # deg; the largest |measured steering-wheel angle|
    max_abs_steer_rate_deg_s: float | None  # deg/s; the largest |steering-wheel rate|
    rms_steer_rate_deg_s: float | None  # deg/s; the RMS steering-wheel rate (the steering effort)
    steer_oscillation_deg: float | None  # deg; RMS wheel angle about its centred 1 s mean (None: < ~2 s)
    limit_cycle: bool  # whether the steering wheel limit-cycles (`limit_cycle.detect_limit_cycle`)
    limit_cycle_hz: float | None  # Hz; the limit cycle's frequency (None when there is none)
    limit_cycle_amplitude_deg: float | None  # deg; the limit cycle's steering-wheel amplitude (None when none)
    max_abs_lat_accel_g: float | None  # g; the largest |lateral acceleration|
    max_ltr: float | None  # 1; the largest |load transfer ratio| (1 is wheel lift-off; None: no roll model)
    max_offtracking_m: float | None  # m; largest lateral distance of the trailer's rear-axle centre from the path
    step_time_median_us: float | None  # µs; the median wall time of one controller step
    step_time_p99_us: float | None  # µs; the 99th percentile of the wall time of one controller step
    min_track_margin_m: float | None = None  # m; outline's (trailer's too) least distance to a track edge, < 0 beyond
    left_track: bool | None = None  # whether the outline went beyond a track edge (min_track_margin_m < 0)

    def to_dict(self) -> dict[str, object]:
        """The metrics as metrics.json holds them.

        Returns
        -------
        dict
            One entry per field, keyed by `METRIC_KEYS` in that order; None where a quantity does not apply.
        """
        return asdict(self)


def approach_end(cte_m: np.ndarray, tolerance_m: float = CONVERGED_CTE_M) -> int:
    """Index of the first sample with |CTE| within tolerance_m: where a run that started off the path has come
    onto it (0 for one that started on it; also 0 when it never comes within, so that the whole run counts).

    Parameters
    ----------
    cte_m : numpy.ndarray
        The signed cross-track error (m) at each logged step, in order.
    tolerance_m : float
        The |CTE| (m, >= 0) within which the run counts as on the path (default `CONVERGED_CTE_M`, 0.1 m).

    Returns
    -------
    int
        The index into `cte_m`: the first sample with |CTE| <= `tolerance_m`, or 0 when there is none.

    Examples
    --------
    >>> import numpy as np
    >>> from workbench.simulation.metrics import approach_end
    >>> approach_end(np.array([1.0, 0.5, 0.08, -0.2, 0.01]))
    2
    """
    within = np.flatnonzero(np.abs(cte_m) <= tolerance_m)
    return int(within[0]) if within.size else 0


def _max_abs(values: np.ndarray | None, scale: float = 1.0) -> float | None:
    if values is None or values.size == 0:
        return None
    return float(np.max(np.abs(values)) * scale)


def offtracking(path: ReferencePath, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
    """Signed lateral distance (m) of a trailer point from the path, projected with progress tracking.

    Sideways only (`Projection.cte_m`): a trailer starts behind an open path's start, where the distance to the
    start point would count its length as offtracking.

    Parameters
    ----------
    path : ReferencePath
        The path the vehicle followed.
    x_m, y_m : numpy.ndarray
        The trailer point's positions (m) at each logged step, in order (progress along the path is tracked from
        one to the next).

    Returns
    -------
    numpy.ndarray
        The signed lateral distance (m, left of the path positive) at each step, of the length of `x_m`.
    """
    return trailer_feet(path, np.asarray(x_m, dtype=float), np.asarray(y_m, dtype=float))[1]


def compute_metrics(
    trace: dict[str, np.ndarray],
    path: ReferencePath,
    *,
    scenario: str,
    controller: str,
    vehicle: str,
    completed: bool,
    path_length_m: float,
    outline: VehicleOutline | None = None,
) -> Metrics:
    """Metrics of a trace (columns as the simulator logs them); outline: the vehicle's, for the track margin (None:
    the track fields are None).

    A `SimulationResult` computes its own (`SimulationResult.metrics`); this function is for a trace read back or
    cut to a stretch.

    Parameters
    ----------
    trace : dict of str to numpy.ndarray
        The logged signals, one array per column, one row per controller step: at least ``t_s``, ``cte_m``,
        ``steer_wheel_rad``, ``step_time_s``, ``speed_mps``, ``heading_error_rad`` and ``lat_accel_mps2``; ``ltr``
        and ``trailer_x_m``, ``trailer_y_m`` when the vehicle outputs them.
    path : ReferencePath
        The path the run followed (its track widths give the track margin).
    scenario, controller, vehicle : str
        The names written into the metrics.
    completed : bool
        Whether the run completed (`Status.COMPLETED`).
    path_length_m : float
        The length the run was asked to cover (m): the path's, times the laps of a closed path.
    outline : VehicleOutline or None
        The vehicle's plan-view outline, for the track margin (None: the track fields are None).

    Returns
    -------
    Metrics
        The run's summary; None where a quantity does not apply (an empty trace, no trailer, no roll model).

    Examples
    --------
    The metrics of the second half of a run (`result`, the `SimulationResult` of fig17 steered by Stanley):

    >>> from workbench.simulation.metrics import compute_metrics
    >>> half = {name: values[len(values) // 2 :] for name, values in result.trace.items()}  # doctest: +SKIP
    >>> late = compute_metrics(half, result.path, scenario="fig17", controller="stanley",
    ...                        vehicle="kinematic-bicycle", completed=True,
    ...                        path_length_m=result.path.length_m)  # doctest: +SKIP
    >>> late.rms_cte_m <= result.metrics.rms_cte_m  # doctest: +SKIP
    True
    """
    t = trace["t_s"]
    n = t.size
    cte = trace["cte_m"]
    steer = trace["steer_wheel_rad"]
    step_us = trace["step_time_s"] * 1e6
    distance = float(np.trapezoid(trace["speed_mps"], t)) if n > 1 else 0.0
    steer_rate = np.diff(steer) / np.diff(t) if n > 1 else None
    deviation = oscillation(t, steer)
    cycle = detect_limit_cycle(t, steer)
    off = trailer_s = None
    if "trailer_x_m" in trace and n:
        trailer_s, off = trailer_feet(path, trace["trailer_x_m"], trace["trailer_y_m"])
    margin = None
    if outline is not None and path.has_widths and n:
        margin = float(np.min(track_margins(path, trace, outline, trailer_s)))
    return Metrics(
        scenario=scenario,
        controller=controller,
        vehicle=vehicle,
        completed=completed,
        distance_m=distance,
        path_length_m=float(path_length_m),
        max_abs_cte_m=_max_abs(cte),
        max_abs_cte_on_path_m=_max_abs(cte[approach_end(cte) :]),
        rms_cte_m=float(math.sqrt(np.mean(cte**2))) if n else None,
        max_abs_heading_error_deg=_max_abs(trace["heading_error_rad"], 180.0 / math.pi),
        max_abs_steer_wheel_deg=_max_abs(steer, 180.0 / math.pi),
        max_abs_steer_rate_deg_s=_max_abs(steer_rate, 180.0 / math.pi),
        rms_steer_rate_deg_s=float(math.degrees(math.sqrt(np.mean(steer_rate**2)))) if steer_rate is not None else None,
        steer_oscillation_deg=math.degrees(math.sqrt(np.mean(deviation[1] ** 2))) if deviation is not None else None,
        limit_cycle=cycle.detected,
        limit_cycle_hz=cycle.frequency_hz,
        limit_cycle_amplitude_deg=cycle.amplitude_deg,
        max_abs_lat_accel_g=_max_abs(trace["lat_accel_mps2"], 1.0 / G_MPS2),
        max_ltr=_max_abs(trace.get("ltr")),
        max_offtracking_m=_max_abs(off),
        step_time_median_us=float(np.median(step_us)) if n else None,
        step_time_p99_us=float(np.percentile(step_us, 99)) if n else None,
        min_track_margin_m=margin,
        left_track=None if margin is None else margin < 0.0,
    )


__all__ = ["Metrics", "approach_end", "compute_metrics", "offtracking"]
