"""The clothoid controller's whole step (Figure 2, `controller.py`) as one compiled call.

Python only copies the measurement into its record, calls `clothoid_step`, and fills in what the step asks for and
Python alone can make: a speed node's lookahead floor (`loop_analysis.py`, python-control) or a km/h's discretised
lead filter (scipy). The step asks before it changes any state (`NEED_FLOOR`, `NEED_FILTER`; the node or km/h in
the state's `need`), so the caller fills the state's table and calls again with the same arguments.

The step reads the path in its compiled form (`workbench.base.path_search.CompiledPath`), its parameters from one
named record (PARAMS, made by `parameters`), and keeps what it holds between calls in another (STATE, made by
`initial_state`: the integrator, the filters, both path trackers' states, the floors and lead filters made so far);
the tables it reads against speed (limits, lags, lead-filter schedule) are arrays of their own. The order of
every floating-point operation is the Python step's, so the two agree to rounding; the replayed traces in
tests/controllers/clothoid/replay hold it to 1e-12.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from controllers.clothoid import delay_predictor as dp
from controllers.clothoid.lead_filter import lead_step
from controllers.clothoid.lookahead import (
    MAX_CURVE_POINTS,
    adaptive_search,
    evaluate_candidate,
    evaluated,
    turn_limited_lookahead,
)
from controllers.clothoid.lookahead_filter import filtered_lookahead
from controllers.clothoid.path_feedforward import lag_inverse_curvature, previewed_curvature, two_degree_of_freedom_rate
from controllers.clothoid.pose_prediction import along_arc
from controllers.clothoid.preview_model import HANDLING_GRID_G, preview_curvature, preview_curvatures
from controllers.clothoid.sideslip_release import RELEASE_MIN_ACCEL_MPS2, planned_acceleration, steady_sideslip
from controllers.clothoid.speed_tables import table_row
from controllers.clothoid.vehicle_tuning import LAG_COLUMNS as LAG_PARAMETERS
from workbench.base.path_search import TRACK_OUT_SIZE, TRACK_PROGRESS, TRACK_S, TRACK_STATE_SIZE, track

# Option codes (ClothoidConfig's strings).
MODE_ADAPTIVE, MODE_FIXED, MODE_SPEED = 0, 1, 2
KAPPA0_YAW_RATE, KAPPA0_COMMAND, KAPPA0_STEERING = 0, 1, 2
#: How many columns of a row of the lag tables hold the lag (`vehicle_tuning.LAG_COLUMNS`: wn, zeta, delay, K); the
#: preview response's taps (and, after the steering taps, the handling gain) follow them when the feed-forward uses
#: them.
LAG_COLUMNS = len(LAG_PARAMETERS)

#: The step's parameters (`params`, one record, made by `parameters`): the vehicle's geometry (wheelbase m,
#: steering ratio, steering-wheel limit rad), the period (s) and ClothoidConfig's numbers; NaN stands for an option's
#: None; lookahead_mode and initial_curvature are the option codes MODE_* and KAPPA0_*, the flags booleans. Its
#: lookahead_step, tolerance_x, tolerance_y, kdot_max and point_spacing are the adaptive search's settings
#: (`lookahead.SEARCH_SETTINGS`), so the step hands its parameters to the search as they are.
PARAMS = np.dtype(
    [(name, np.float64) for name in (
        "wheelbase", "steering_ratio", "max_steer", "dt", "horizon", "known_delay", "yaw_rate_age", "min_lookahead",
        "max_lookahead", "lookahead_step", "min_preview", "fixed_lookahead", "lookahead_gain", "max_turn",
        "frechet_threshold",
        "point_spacing", "tolerance_x", "tolerance_y", "kdot_max", "feedforward_window", "feedforward_time",
        "reference_lead", "hysteresis", "max_growth", "max_shrink", "min_speed", "floor_step_kmh", "floor_min_kmh",
        "preview_first_tap", "preview_spacing",
    )]
    + [(name, np.int64) for name in ("lookahead_mode", "initial_curvature")]
    + [(name, np.bool_) for name in (
        "course", "excess", "feedforward", "warm_search", "delay_model", "feedforward_inversion",
        "lag_model_reference", "sideslip_release",
    )]
)  # fmt: skip


def parameters(**fields: float | int | bool | None) -> np.ndarray:
    """The step's parameters as one record (PARAMS, a structured array of one element), every field given by name
    (None: NaN, an option left out); a field missing or unknown is refused."""
    known = set(PARAMS.names or ())  # a structured dtype always has names (numpy types them Optional)
    missing, unknown = known - set(fields), set(fields) - known
    if missing or unknown:
        raise ValueError(f"clothoid step parameters: missing {sorted(missing)}, unknown {sorted(unknown)}")
    params = np.zeros(1, PARAMS)
    for name, value in fields.items():
        params[name] = math.nan if value is None else value
    return params


# `clothoid_step`'s status.# `clothoid_step`'s status.
STEP_DONE, NEED_FLOOR, NEED_FILTER = 0, 1, 2
#: km/h rows of the lead-filter table: every whole km/h up to the plausible measurement's top speed (540 km/h).
FILTER_ROWS = 541
#: Rows of the floor table: a speed node every `floor_step_kmh` (2.5 km/h) up to 540 km/h, and the one above.
FLOOR_ROWS = 218
#: Size of `clothoid_step`'s scratch array: a table row, a projection, the two lags' rows at this speed, then the
#: release table's row (`VehicleTuning.release_table`).
LAG_ROWS = 4 + TRACK_OUT_SIZE
RELEASE_ROW = LAG_ROWS + 8
SCRATCH_SIZE = RELEASE_ROW + 1 + len(HANDLING_GRID_G)

#: What the step holds between calls (`state`, one record, made by `initial_state`): the integrator's curvature
#: command (1/m; NaN before the first step; with the lag-inverting feed-forward the feedback's alone); the
#: lookahead filter's lookahead and floor (m); the lead filter's three states (rad, shared by the filters of every
#: km/h: a bumpless switch); what a NEED_* return asks for (the floor's speed node or the km/h); the adaptive
#: search's last choice (m, where the next one starts); the delay
#: predictor's model (`delay_predictor.MODEL_SIZE`); the lag-inverting feed-forward's curvature sent last step
#: (1/m); the path trackers' states of the start pose and of the measured position (`path_search.track`); the
#: floors per speed node (m) and the lead filters per km/h (`DiscreteLeadFilter.coefficients`), NaN where Python
#: has not made them yet; the search's sampled curves (`lookahead.evaluate_candidate`) and scratch. NaN where
#: nothing is known yet.
STATE = np.dtype(
    [
        ("kappa_cmd", np.float64),
        ("lookahead", np.float64, (2,)),
        ("filter_x", np.float64, (3,)),
        ("need", np.int64),
        ("searched", np.float64),
        ("model", np.float64, (dp.MODEL_SIZE,)),
        ("feedforward_kappa", np.float64),
        ("tracker", np.float64, (TRACK_STATE_SIZE,)),
        ("here", np.float64, (TRACK_STATE_SIZE,)),
        ("floors", np.float64, (FLOOR_ROWS,)),
        ("filters", np.float64, (FILTER_ROWS, 9)),
        ("buffers", np.float64, (4, MAX_CURVE_POINTS)),
        ("scratch", np.float64, (SCRATCH_SIZE,)),
    ]
)
#: The step's measurement (`measurement`, one record): `controllers.base.Measurement`'s fields in its order.
MEASUREMENT = np.dtype([(name, np.float64) for name in ("t", "x", "y", "vx", "vy", "yaw", "yaw_rate", "steer_wheel")])


@njit(cache=True)
def floor_node(speed_mps: float, step_kmh: float, min_kmh: float) -> tuple[int, float]:
    """(node, weight): the lookahead floor at this speed is the floor of speed node `node` (node x step_kmh km/h)
    and weight of the way to the next one's, linear in the speed; below min_kmh, min_kmh's (weight 0); the top
    node's beyond FLOOR_ROWS."""
    x = max(speed_mps * 3.6, min_kmh) / step_kmh
    node = min(int(x), FLOOR_ROWS - 2)
    weight = min(x - node, 1.0)
    return node, weight if weight > 1e-9 else 0.0  # a node's own speed, to the rounding of a km/h conversion


def initial_state() -> np.ndarray:
    """The step's state before its first step (STATE, one record): nothing known (NaN), both path
    trackers at the path's start (`PathTracker.reset(0.0)`)."""
    state = np.zeros(1, STATE)
    for name in STATE.names or ():  # a structured dtype always has names
        if STATE[name].base == np.float64:
            state[name] = np.nan
    state["need"] = 0
    for tracker in ("tracker", "here"):
        state[tracker][0, TRACK_S], state[tracker][0, TRACK_PROGRESS] = 0.0, 0.0
    return state


@njit(cache=True)
def feedforward_timing(
    speed_mps: float,
    params: np.ndarray,
    lags: np.ndarray,
    measured_lags: np.ndarray,
    lag_speeds: np.ndarray,
    schedule: np.ndarray,
    schedule_speeds: np.ndarray,
    scratch: np.ndarray,
) -> tuple[float, float, float]:  # pragma: no cover - compiled
    """(feed-forward time s, reference lead s, K) at this speed (`ClothoidController.feedforward_timing`;
    params: PARAMS): lags
    (n, 4: wn, zeta, delay, K; no rows: untuned), measured_lags (the same, or no rows: the path lag's), schedule
    (m, 3: wz, psi, wp; no rows: no lead filter)."""
    speed_kmh = speed_mps * 3.6
    path_delay = measured_delay = lead_delay = 0.0
    gain = 1.0
    if lags.shape[0] > 0:
        table_row(lag_speeds, lags, speed_kmh, False, scratch[:4])
        path_delay = scratch[2] + 2.0 * scratch[1] / scratch[0]  # SteeringLag.group_delay_s
        gain = scratch[3]
        measured_delay = path_delay
        if measured_lags.shape[0] > 0:
            table_row(lag_speeds, measured_lags, speed_kmh, False, scratch[:4])
            measured_delay = scratch[2] + 2.0 * scratch[1] / scratch[0]
    if schedule.shape[0] > 0:
        table_row(schedule_speeds, schedule, speed_kmh, True, scratch[:3])
        lead_delay = 3.0 / scratch[2] - 2.0 * scratch[1] / scratch[0]  # LeadFilterParams.group_delay_s
    p = params[0]
    ff = p.feedforward_time
    if math.isnan(ff):
        ff = max(0.0, path_delay + lead_delay)
    ff += p.known_delay
    ref = p.reference_lead
    if math.isnan(ref):
        ref = min(max(path_delay - measured_delay, 0.0), p.horizon)
    return min(ff, 5.0), min(ref, 5.0), gain


@njit(cache=True)
def reference_curvature(
    table: np.ndarray,
    record: np.ndarray,
    s_m: float,
    speed_mps: float,
    lags: np.ndarray,
    measured_lags: np.ndarray,
    lag_speeds: np.ndarray,
    window_m: float,
    rows: np.ndarray,
) -> float:  # pragma: no cover - compiled
    """The measured (yaw-rate) curvature kappa(0) of a vehicle that follows the path exactly, at the path's arc
    length s_m (`ClothoidConfig.lag_model_reference`): the measured lag driven by the steering that inverts the path
    lag, Km Gm(s) e^(-Tm s) / (Kp Gp(s) e^(-Tp s)) on the path's curvature, with Gm / Gp = (1 + a_p s + b_p s^2) /
    (1 + a_m s + b_m s^2) (a = 2 zeta / wn, b = 1 / wn^2) to second order in s: the curvature Tp - Tm ahead plus
    (a_p - a_m) and (b_p - b_m - a_m (a_p - a_m)) times its first and second time derivatives
    (`path_feedforward.previewed_curvature`). The gains' ratio Km / Kp is taken as 1: in steady turning at a held
    speed the yaw rate over speed is the path's curvature (rigid-body kinematics), so the reference must equal the
    path's curvature on an arc; the two identified gains differ by their fits' errors (about 1 % on the loaded
    truck), which would leave the feedback holding that error as a steady offset in every arc. Without a measured
    lag: the path's curvature at s_m. The path: `path_search.CompiledPath`'s table and record; rows: 8 floats of
    scratch (the two lags' rows at this speed)."""
    path_lag, measured_lag = rows[:4], rows[4:8]
    table_row(lag_speeds, lags, speed_mps * 3.6, False, path_lag)
    if measured_lags.shape[0] == 0:
        return previewed_curvature(table, record, s_m, speed_mps, 0.0, 0.0, 0.0, window_m)[0]
    table_row(lag_speeds, measured_lags, speed_mps * 3.6, False, measured_lag)
    a_p, b_p = 2.0 * path_lag[1] / path_lag[0], 1.0 / (path_lag[0] * path_lag[0])
    a_m, b_m = 2.0 * measured_lag[1] / measured_lag[0], 1.0 / (measured_lag[0] * measured_lag[0])
    first = a_p - a_m
    curvature = previewed_curvature(
        table, record, s_m, speed_mps, path_lag[2] - measured_lag[2], first, b_p - b_m - a_m * first, window_m
    )[0]
    return curvature


class StepArguments(NamedTuple):
    """`clothoid_step`'s arguments by name, in its order (a controller builds them once per run and calls
    `clothoid_step(*arguments)`; the arrays are written in place)."""

    measurement: np.ndarray
    params: np.ndarray
    state: np.ndarray
    path: np.ndarray
    record: np.ndarray
    limits: np.ndarray
    limit_speeds: np.ndarray
    lags: np.ndarray
    measured_lags: np.ndarray
    lag_axis: np.ndarray
    schedule: np.ndarray
    schedule_speeds: np.ndarray
    scores: np.ndarray
    results: np.ndarray
    diagnostics: np.ndarray
    history: np.ndarray


@njit(cache=True)
def clothoid_step(
    measurement: np.ndarray,
    params: np.ndarray,
    state: np.ndarray,
    path: np.ndarray,
    record: np.ndarray,
    limits: np.ndarray,
    limit_speeds: np.ndarray,
    lags: np.ndarray,
    measured_lags: np.ndarray,
    lag_axis: np.ndarray,
    schedule: np.ndarray,
    schedule_speeds: np.ndarray,
    scores: np.ndarray,
    results: np.ndarray,
    diagnostics: np.ndarray,
    history: np.ndarray,
) -> tuple[float, int]:  # pragma: no cover - compiled
    """(steering-wheel command rad, status) of one step (`controller.py` documents what it does) of the measurement
    (MEASUREMENT), with the parameters (PARAMS) and the state (STATE, advanced) on the compiled path
    (`path_search.CompiledPath`'s table and record); diagnostics (16) in the order of controller.DIAGNOSTIC_KEYS.
    scores, results: the search's work arrays (`lookahead.py`); history: the delay predictor's commands sent
    (`delay_predictor.history_length` slots; any size without it). lag_axis: the lags' speeds (km/h) in its first
    row, then the sideslip's release table transposed (`VehicleTuning.release_table`: a row of release rates, then
    one per point of HANDLING_GRID_G; the speeds alone: none), one array because numba's dispatch costs each
    argument about 0.1 us a step. lags and measured_lags hold each speed's lag in
    their first LAG_COLUMNS columns and, when the feed-forward and the reference curvature come from the preview
    responses (`preview_model.py`), its steering and its measured taps after them (lags may then end with the
    handling gain, `VehicleTuning.preview_lag_tables`: its columns beyond measured_lags'); with four columns they
    come from the lags."""
    m, p, st = measurement[0], params[0], state[0]
    t_s, x_m, y_m, vx_mps, vy_mps = m.t, m.x, m.y, m.vx, m.vy
    yaw_rad, yaw_rate_rad_s, steer_wheel_rad = m.yaw, m.yaw_rate, m.steer_wheel
    floors, filters, buffers, scratch = st.floors, st.filters, st.buffers, st.scratch
    speed = math.hypot(vx_mps, vy_mps)  # Measurement.speed_mps
    lag_speeds = lag_axis[0]
    spacing = record[0].spacing
    filtered = schedule.shape[0] > 0

    # What the step needs that Python makes, asked before any state changes.
    kmh = -1
    if filtered:
        kmh = round(speed * 3.6) if schedule.shape[0] > 1 else 0
        if math.isnan(filters[kmh, 0]):
            st.need = kmh
            return 0.0, NEED_FILTER
    node, weight = floor_node(speed, p.floor_step_kmh, p.floor_min_kmh)
    if math.isnan(floors[node]):
        st.need = node
        return 0.0, NEED_FLOOR
    if weight > 0.0 and math.isnan(floors[node + 1]):
        st.need = node + 1
        return 0.0, NEED_FLOOR

    wheelbase, ratio = p.wheelbase, p.steering_ratio
    steering_kappa = math.tan(steer_wheel_rad / ratio) / wheelbase
    inverting = p.feedforward and p.feedforward_inversion
    first = math.isnan(st.kappa_cmd)
    if first:  # first step: continue from the vehicle's current steering
        st.kappa_cmd = steering_kappa
        st.filter_x[:] = steer_wheel_rad
    table_row(limit_speeds, limits, speed * 3.6, False, scratch[:2])
    kappa_max, rate_max = scratch[0], scratch[1]
    mode0 = int(p.initial_curvature)
    if mode0 == KAPPA0_YAW_RATE and speed > p.min_speed:
        kappa0 = yaw_rate_rad_s / speed
    elif mode0 == KAPPA0_STEERING:
        kappa0 = steering_kappa
    else:
        kappa0 = st.kappa_cmd
        if inverting and not math.isnan(st.feedforward_kappa):  # the curvature sent: feedback + feed-forward
            kappa0 += st.feedforward_kappa
    kappa0 = min(max(kappa0, -kappa_max), kappa_max)

    # Sections 2 and 3: the start pose, the lookahead, then the hyper-clothoid to the target (Eq. 3).
    heading = yaw_rad
    if p.course and vx_mps > p.min_speed:
        heading += math.atan2(vy_mps, vx_mps)
    px, py, ph = x_m, y_m, heading
    horizon = p.horizon
    model = st.model
    predicting = p.delay_model
    if predicting:  # over the known delay with the identified lags and the commands sent (`delay_predictor.py`)
        path_lag, measured_lag = scratch[LAG_ROWS : LAG_ROWS + 4], scratch[LAG_ROWS + 4 : LAG_ROWS + 8]
        table_row(lag_speeds, lags, speed * 3.6, False, path_lag)
        if measured_lags.shape[0] > 0:
            table_row(lag_speeds, measured_lags, speed * 3.6, False, measured_lag)
        else:
            measured_lag[:] = path_lag
        delay = p.known_delay
        dp.record_and_advance(model, history, t_s, p.dt, path_lag, measured_lag, delay, steering_kappa)
        deviation = rate = 0.0
        if p.sideslip_release and delay > 0.0 and lag_axis.shape[0] > 1 and p.course and vx_mps > p.min_speed:
            releases = lag_axis[1:].T  # (speeds, the rate and the grid's sideslips): `sideslip_release.py`
            release = scratch[RELEASE_ROW : RELEASE_ROW + releases.shape[1]]
            table_row(lag_speeds, releases, speed * 3.6, False, release)
            rate = release[0]
            if rate > 0.0:  # braking or driving, now or within the dead time (`sideslip_release.py`), read at the
                # last step's foot point of the measured position (the feed-forward's tracker; without the
                # feed-forward, of the start pose): a period's travel is nothing to a plan's acceleration
                s_here = st.here[TRACK_S] if p.feedforward else st.tracker[TRACK_S]
                pushing = max(
                    abs(planned_acceleration(path, record, s_here)),
                    abs(planned_acceleration(path, record, s_here + speed * delay)),
                )
                if pushing <= RELEASE_MIN_ACCEL_MPS2:
                    rate = 0.0
            if rate > 0.0:  # the measured sideslip less the steady turn's and the lags' transient
                deviation = (
                    math.atan2(vy_mps, vx_mps)
                    - steady_sideslip(release, speed * yaw_rate_rad_s)
                    - dp.lag_transient_sideslip(model, history, speed, p.dt, path_lag, measured_lag, delay)
                )
        px, py, ph, kappa0 = dp.predicted_start(
            model, history, x_m, y_m, heading, kappa0, speed, p.dt, path_lag, measured_lag, delay, p.yaw_rate_age,
            deviation, rate,
        )  # fmt: skip
        kappa0 = min(max(kappa0, -kappa_max), kappa_max)
        horizon -= delay
    if horizon > 0.0:
        px, py, ph = along_arc(px, py, ph, kappa0, speed * horizon)
    foot = scratch[4 : 4 + TRACK_OUT_SIZE]
    track(path, record, st.tracker, px, py, foot)
    foot_index, cte = foot[0] / spacing, foot[6]

    node_floor = floors[node] + weight * (floors[node + 1] - floors[node]) if weight > 0.0 else floors[node]
    floor = max(node_floor, p.min_lookahead, p.min_preview * speed)
    top = max(p.max_lookahead, floor)
    mode = int(p.lookahead_mode)
    evaluations, reused = 0, -1
    if mode == MODE_FIXED:
        lookahead = searched = p.fixed_lookahead
    else:
        if p.max_turn > 0.0:  # the geometric ceiling (ClothoidConfig.max_target_turn_deg)
            ceiling = turn_limited_lookahead(path, record, foot_index, px, py, p.max_turn, top)
            top = max(floor, ceiling)
        if mode == MODE_SPEED:
            lookahead = searched = min(max(p.lookahead_gain * speed, floor), top)
        else:
            threshold = p.frechet_threshold + (abs(cte) if p.excess else 0.0)
            searched, evaluations = adaptive_search(
                path, record, params, foot_index, px, py, ph, kappa0, floor, top, threshold,
                st.searched if p.warm_search else np.nan, buffers, scores, results,
            )  # fmt: skip
            st.searched = searched
            lookahead = filtered_lookahead(
                st.lookahead, searched, floor, top, speed * p.dt, p.hysteresis, p.max_growth, p.max_shrink
            )
            reused = evaluated(scores, results, floor, p.lookahead_step, lookahead)
    if reused >= 0:  # the search evaluated this very lookahead: the same fit again
        row = results[reused]
        frechet, kdot, clothoid_length, tx, ty, ex, ey = row[0], row[1], row[2], row[3], row[4], row[5], row[6]
        status = int(row[7])
    else:
        frechet, kdot, clothoid_length, tx, ty, ex, ey, status = evaluate_candidate(
            path, record, foot_index, px, py, ph, kappa0, lookahead, p.kdot_max, p.point_spacing, buffers, np.inf
        )
    clothoid_kdot = reference_kdot = feedforward_kdot = kdot
    feedforward_kappa = 0.0
    if p.feedforward:  # path_feedforward.py: feedback relative to the path's own clothoid, plus its rate
        track(path, record, st.here, x_m, y_m, foot)
        ff_time, reference_lead, gain = feedforward_timing(
            speed, params, lags, measured_lags, lag_speeds, schedule, schedule_speeds, scratch[:4]
        )
        previewing = inverting and lags.shape[1] > LAG_COLUMNS
        previewed = 0.0  # the preview response's steering: the feed-forward (below)
        if previewing or (inverting and p.lag_model_reference and lags.shape[0] > 0):
            s_ref = foot[0] + speed * (p.horizon - horizon)
            if previewing:  # the measured curvature of a vehicle that drives the path, from its preview response
                taps_end = measured_lags.shape[1]  # the steering taps, then the handling gain
                steering_taps, handling = lags[:, LAG_COLUMNS:taps_end], lags[:, taps_end:]
                measured_taps = measured_lags[:, LAG_COLUMNS:]
                if s_ref == foot[0] and p.known_delay == 0.0:  # both read at the same taps: one march
                    previewed, reference_kappa = preview_curvatures(
                        path, record, s_ref, speed, 0.0, p.preview_first_tap, p.preview_spacing, lag_speeds,
                        steering_taps, handling, measured_taps,
                    )  # fmt: skip
                else:
                    reference_kappa = preview_curvature(
                        path, record, s_ref, speed, 0.0, p.preview_first_tap, p.preview_spacing, lag_speeds,
                        measured_taps, measured_taps[:, :0],
                    )  # fmt: skip
                    previewed = preview_curvature(
                        path, record, foot[0], speed, p.known_delay, p.preview_first_tap, p.preview_spacing,
                        lag_speeds, steering_taps, handling,
                    )  # fmt: skip
            else:
                reference_kappa = reference_curvature(
                    path, record, s_ref, speed, lags, measured_lags, lag_speeds, p.feedforward_window,
                    scratch[LAG_ROWS : LAG_ROWS + 8],
                )  # fmt: skip
            kdot, reference_kdot, feedforward_kdot = two_degree_of_freedom_rate(
                kdot, path, record, foot, tx, ty, speed,
                horizon, ff_time, 0.0, gain, p.feedforward_window, p.horizon - horizon, reference_kappa,
            )  # fmt: skip
        else:
            kdot, reference_kdot, feedforward_kdot = two_degree_of_freedom_rate(
                kdot, path, record, foot, tx, ty, speed,
                horizon, ff_time, reference_lead, gain, p.feedforward_window, p.horizon - horizon,
            )  # fmt: skip
        if inverting:  # the lag inverted, added after the lead filter; the integrator holds the feedback alone
            kdot = clothoid_kdot - reference_kdot
            if previewing:  # the steering that drives the path, from the preview response, the known delay ahead
                feedforward_kappa = previewed
            else:
                omega_n, zeta, dead_time = math.nan, 1.0, 0.0
                if lags.shape[0] > 0:
                    table_row(lag_speeds, lags, speed * 3.6, False, scratch[:4])
                    omega_n, zeta, dead_time, gain = scratch[0], scratch[1], scratch[2], scratch[3]
                feedforward_kappa, feedforward_kdot = lag_inverse_curvature(
                    path, record, foot[0], speed, dead_time + p.known_delay, omega_n, zeta, gain,
                    p.feedforward_window,
                )  # fmt: skip
            feedforward_kappa = min(max(feedforward_kappa, -kappa_max), kappa_max)
            st.feedforward_kappa = feedforward_kappa
            if first:  # the feedback's share of the steering now (bumpless)
                st.kappa_cmd = steering_kappa - feedforward_kappa
                steer_feedback = math.atan(wheelbase * st.kappa_cmd) * ratio
                st.filter_x[:] = steer_feedback

    # Figure 2: kappa' x V integrated to curvature, under the rate and curvature limits (section 4).
    rate = min(max(kdot * speed, -rate_max), rate_max)
    if inverting:  # the feedback integrated within what the feed-forward leaves of the curvature limit
        kappa_fb = st.kappa_cmd + rate * p.dt
        kappa_fb = min(max(kappa_fb, -kappa_max - feedforward_kappa), kappa_max - feedforward_kappa)
        st.kappa_cmd = kappa_fb
        kappa_cmd = kappa_fb + feedforward_kappa
        steer_feedback = math.atan(wheelbase * kappa_fb) * ratio
        steer = math.atan(wheelbase * kappa_cmd) * ratio
        command = steer
        if filtered:  # Eq. 6 on the feedback's steering; the feed-forward's share added after it
            command = lead_step(filters[kmh], st.filter_x, steer_feedback)
            command += steer - steer_feedback
    else:
        kappa_cmd = min(max(st.kappa_cmd + rate * p.dt, -kappa_max), kappa_max)
        st.kappa_cmd = kappa_cmd
        steer = math.atan(wheelbase * kappa_cmd) * ratio  # Ackermann: tan(phi) = L kappa
        command = steer
        if filtered:  # Eq. 6: this km/h's filter, on the state the last one left (the same lag-chain signals)
            command = lead_step(filters[kmh], st.filter_x, steer)
    limit = p.max_steer
    command = min(max(command, -limit), limit)
    if predicting:
        dp.send(model, history, math.tan(command / ratio) / wheelbase)

    d = diagnostics
    d[0], d[1], d[2], d[3], d[4], d[5] = lookahead, searched, floor, top, frechet, kdot
    d[6], d[7], d[8], d[9] = clothoid_kdot, reference_kdot, feedforward_kdot, clothoid_length
    d[10], d[11], d[12] = math.hypot(ex - tx, ey - ty), float(status), float(evaluations)
    d[13], d[14], d[15] = kappa0, kappa_cmd, steer
    return command, STEP_DONE
