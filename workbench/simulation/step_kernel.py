"""The simulator's own work at each controller step, compiled: two calls a step around the controller's, no
per-step Python objects.

`project_pose`, before the controller: the pose projected onto the path (`path_search.track` on a
`PathTracker`'s state and output arrays, advanced in place) and whether the run ends there (PROJECTED_*).
`finish_step`, after it: the planned speed and its slope at the foot point (`speed_reference`, the interpolation
`ReferencePath.speed` and `speed_gradient` do), the PI speed controller's command (`speed_control.pi_speed_step`)
and the trace's row written into the preallocated table: the time, the plant's outputs, the simulator's signals
(SIGNALS) and the controller's diagnostics. Each computes what the Python loop computed, in the same order, so
a run's trace is the same bit for bit.

A compiled call costs about 0.1 us per array and 0.04 us per number it is handed, so the kernels take the path in
its compiled form (`path_search.CompiledPath`: the samples as one table, the scalars as one record, `compiled_path`)
and the run's constants with the speed controller's state as one array (`run_settings`).

What stays in Python: the speed over ground (`math.hypot`, whose rounding differs from the C library's that numba
calls in about one case in 500), the measurement and the controller, the conditions' models, and the messages of
a run that ends.

Numba keys a cached kernel on its own source file only, and these kernels compile `path_search.py`'s and
`speed_control.py`'s into themselves: the cache folder is therefore per version of all the compiled sources
(`workbench/base/compiled_cache.py`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from workbench.base.errors import WorkbenchInputError
from workbench.base.path import PathTracker
from workbench.base.path_search import PATH_SPEED, CompiledPath, slope_at, track, value_at
from workbench.simulation.speed_control import PI_STATE_SIZE, PISpeedGains, pi_speed_step, pi_state

#: Indices into a tracker's output (`path_search.track`, `PathTracker.out`): the foot point's arc length (m),
#: the progress (m, laps counted), its position (m), the path's heading (rad) and curvature (1/m) there, the signed
#: CTE (m), at_end (1.0 / 0.0), how far beyond an open path's end (m) and the distance to the foot point (m).
(
    FOOT_S,
    FOOT_PROGRESS,
    FOOT_X,
    FOOT_Y,
    FOOT_HEADING,
    FOOT_CURVATURE,
    FOOT_CTE,
    FOOT_AT_END,
    FOOT_PAST_END,
    FOOT_DISTANCE,
) = range(10)

#: What `project_pose` found: the step goes on; the position is not finite (the tracker's own update says so);
#: the position lies beyond an end of an open path by more than the limit; it lies further from the path than the
#: limit; the run is complete (the end of an open path, or the laps of a closed one).
PROJECTED_ON_PATH, PROJECTED_NOT_FINITE, PROJECTED_PAST_END, PROJECTED_OFF_PATH, PROJECTED_COMPLETED = range(5)

#: The simulator's signals, in the trace row after the time and the plant's outputs (then the diagnostics).
SIGNALS = (
    "steer_wheel_cmd_rad",
    "accel_cmd_mps2",
    "speed_mps",
    "speed_ref_mps",
    "path_s_m",
    "progress_m",
    "cte_m",
    "heading_error_rad",
    "path_curvature_1pm",
    "step_time_s",
)
N_SIGNALS = len(SIGNALS)

#: Layout of `run_settings`: the limits that end a run: how far past an end of an open path, how far from the path
#: (m), and the distance to cover (m, the laps of a closed path); the controller's step (s) and whether the planned
#: speed's rate is fed forward (1.0 / 0.0); then the PI speed controller's state (`speed_control.pi_state`,
#: PI_STATE_SIZE values from SET_PI).
(
    SET_MAX_PAST_END,
    SET_MAX_DISTANCE,
    SET_TOTAL_LENGTH,
    SET_DT,
    SET_FEEDFORWARD,
    SET_PI,
) = range(6)
SETTINGS_SIZE = SET_PI + PI_STATE_SIZE


def compiled_path(tracker: PathTracker) -> CompiledPath:
    """The compiled form of the tracker's path with its window (`ReferencePath.compiled`: the samples as one
    table, rows `path_search.PATH_*`, the scalars as one record); the path must carry a planned speed."""
    path = tracker.path
    if path.speed_mps is None:
        raise WorkbenchInputError(f"{path.name}: the path carries no planned speed (`plan_path_speed`)")
    return tracker.compiled


def run_settings(
    max_past_end_m: float,
    max_abs_cte_m: float,
    total_length_m: float,
    dt_s: float,
    speed_feedforward: bool,
    speed_gains: PISpeedGains,
) -> np.ndarray:
    """The settings array (layout SET_*) of a run, its speed controller's integrator at 0."""
    settings = np.empty(SETTINGS_SIZE)
    settings[SET_MAX_PAST_END], settings[SET_MAX_DISTANCE] = max_past_end_m, max_abs_cte_m
    settings[SET_TOTAL_LENGTH], settings[SET_DT] = total_length_m, dt_s
    settings[SET_FEEDFORWARD] = 1.0 if speed_feedforward else 0.0
    settings[SET_PI:] = pi_state(speed_gains)
    return settings


_TWO_PI = 2.0 * math.pi


@njit(cache=True)
def project_pose(
    px: float,
    py: float,
    path: np.ndarray,
    record: np.ndarray,
    tracker_state: np.ndarray,
    foot: np.ndarray,
    settings: np.ndarray,
) -> int:  # pragma: no cover - compiled
    """`PathTracker.update` of the position (px, py) on the compiled path (`compiled_path`'s table and record)
    into `tracker_state` and `foot` (the tracker's `state` and `out`), then the simulator's checks in its order:
    past an end by more than SET_MAX_PAST_END, further than SET_MAX_DISTANCE, at the end of an open path or
    SET_TOTAL_LENGTH travelled. A PROJECTED_* code; PROJECTED_NOT_FINITE leaves the tracker as it was."""
    if not (math.isfinite(px) and math.isfinite(py)):
        return PROJECTED_NOT_FINITE
    closed = record[0].closed
    track(path, record, tracker_state, px, py, foot)
    if foot[FOOT_PAST_END] > settings[SET_MAX_PAST_END]:
        return PROJECTED_PAST_END
    if foot[FOOT_DISTANCE] > settings[SET_MAX_DISTANCE]:
        return PROJECTED_OFF_PATH
    if (foot[FOOT_AT_END] == 1.0 and not closed) or foot[FOOT_PROGRESS] >= settings[SET_TOTAL_LENGTH]:
        return PROJECTED_COMPLETED
    return PROJECTED_ON_PATH


@njit(cache=True)
def speed_reference(
    speed: np.ndarray, spacing: float, length: float, closed: bool, s: float
) -> tuple[float, float]:  # pragma: no cover - compiled
    """(v_ref (m/s), dv_ref/ds (1/s)) at arc length s of the speed sampled every `spacing` m: `ReferencePath.speed`
    and `speed_gradient` at a float s (wrapped onto a loop, clipped onto an open path)."""
    return value_at(speed, s, spacing, length, closed), slope_at(speed, s, spacing, length, closed)


@njit(cache=True)
def finish_step(
    table: np.ndarray,
    row: int,
    t: float,
    outputs: np.ndarray,
    steer_cmd: float,
    speed: float,
    step_time: float,
    diagnostics: np.ndarray,
    foot: np.ndarray,
    path: np.ndarray,
    record: np.ndarray,
    settings: np.ndarray,
) -> float:  # pragma: no cover - compiled
    """The acceleration command of this step, its trace row written: `table[row]` = (t, outputs, SIGNALS,
    diagnostics), the columns after them untouched. The speed reference at the foot point (`foot`, the tracker's
    output) on the compiled path's planned speed (`compiled_path`'s table and record), its rate speed x dv_ref/ds
    fed forward when SET_FEEDFORWARD, the PI command on the speed controller's state in `settings` (advanced).
    NaN, with nothing written and the integrator untouched, when the speed, the reference or its rate is not
    finite (the Python `PISpeedController` says why)."""
    s = foot[FOOT_S]
    shape = record[0]
    speed_ref, slope = speed_reference(path[PATH_SPEED], shape.spacing, shape.length, shape.closed, s)
    speed_ref_rate = speed * slope if settings[SET_FEEDFORWARD] == 1.0 else 0.0
    if not (math.isfinite(speed_ref) and math.isfinite(speed) and math.isfinite(speed_ref_rate)):
        return math.nan
    accel_cmd = pi_speed_step(settings[SET_PI:], speed_ref, speed, settings[SET_DT], speed_ref_rate)
    line = table[row]
    line[0] = t
    n_out = outputs.size
    for k in range(n_out):
        line[1 + k] = outputs[k]
    k = 1 + n_out
    line[k] = steer_cmd
    line[k + 1] = accel_cmd
    line[k + 2] = speed
    line[k + 3] = speed_ref
    line[k + 4] = s
    line[k + 5] = foot[FOOT_PROGRESS]
    line[k + 6] = math.copysign(foot[FOOT_DISTANCE], foot[FOOT_CTE])  # `Projection.signed_distance_m`
    line[k + 7] = (outputs[2] - foot[FOOT_HEADING] + math.pi) % _TWO_PI - math.pi  # `path.wrap_angle` of yaw - heading
    line[k + 8] = foot[FOOT_CURVATURE]
    line[k + 9] = step_time
    k += N_SIGNALS
    for m in range(diagnostics.size):
        line[k + m] = diagnostics[m]
    return accel_cmd
