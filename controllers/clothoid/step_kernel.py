"""The clothoid controller's whole step (Figure 2, `controller.py`) as one compiled call.

Python only unpacks the measurement, calls `clothoid_step`, and fills in what the step asks for and Python alone
can make: a speed band's lookahead floor (`loop_analysis.py`, python-control) or a km/h's discretised lead filter
(scipy). The step asks before it changes any state (`NEED_FLOOR`, `NEED_FILTER`; the band or km/h in
state[S_NEED]), so the caller fills the table and calls again with the same arguments.

What the step holds between calls lives in arrays: `state` (the S_* layout), the two path trackers' states
(`workbench.base.path_search.track`), and the tables it reads (`StepTables`). The order of every floating-point
operation is the Python step's (commit b614e88), so the two agree to rounding; the replayed traces in
tests/controllers/clothoid/replay hold it to 1e-12.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from controllers.clothoid import delay_predictor as dp
from controllers.clothoid.lead_filter import lead_step
from controllers.clothoid.lookahead import adaptive_search, evaluate_candidate, evaluated, turn_limited_lookahead
from controllers.clothoid.lookahead_filter import filtered_lookahead
from controllers.clothoid.path_feedforward import lag_inverse_curvature, previewed_curvature, two_degree_of_freedom_rate
from controllers.clothoid.pose_prediction import along_arc
from controllers.clothoid.speed_tables import table_row
from workbench.base.path_search import TRACK_OUT_SIZE, track

# Option codes (ClothoidConfig's strings).
MODE_ADAPTIVE, MODE_FIXED, MODE_SPEED = 0, 1, 2
KAPPA0_YAW_RATE, KAPPA0_COMMAND, KAPPA0_STEERING = 0, 1, 2

# The parameter vector (`params`): the vehicle's geometry, the period and ClothoidConfig's numbers; NaN stands for
# an option's None.
(
    P_WHEELBASE, P_STEERING_RATIO, P_MAX_STEER, P_DT, P_HORIZON, P_KNOWN_DELAY, P_LOOKAHEAD_MODE, P_INITIAL_CURVATURE,
    P_COURSE, P_EXCESS, P_MIN_LOOKAHEAD, P_MAX_LOOKAHEAD, P_LOOKAHEAD_STEP, P_MIN_PREVIEW, P_FIXED_LOOKAHEAD,
    P_LOOKAHEAD_GAIN, P_MAX_TURN_RAD, P_FRECHET_THRESHOLD, P_POINT_SPACING, P_TOLERANCE_X, P_TOLERANCE_Y,
    P_KDOT_MAX, P_FEEDFORWARD, P_FEEDFORWARD_WINDOW, P_FEEDFORWARD_TIME, P_REFERENCE_LEAD, P_HYSTERESIS,
    P_MAX_GROWTH, P_MAX_SHRINK, P_MIN_SPEED, P_BAND_KMH, P_BAND_HYSTERESIS_KMH, P_PATH_SPACING, P_PATH_LENGTH,
    P_PATH_EXTENT, P_TRACKER_WINDOW, P_PATH_MAX_SEGMENT, P_WARM_SEARCH, P_DELAY_MODEL, P_FEEDFORWARD_INVERSION,
    P_LAG_MODEL_REFERENCE,
) = range(41)  # fmt: skip
PARAM_COUNT = 41

# The step's own state (`state`).
S_KAPPA_CMD = 0  # the integrator's curvature command (1/m; NaN before the first step)
S_HELD_BAND = 1  # the speed band whose floor applies (-1 before the first step)
S_LOOKAHEAD = 2  # the lookahead filter's state: its lookahead and floor (m; NaN before the first step)
S_FILTER_X = 4  # the lead filter's three states (rad), shared by the filters of every km/h (a bumpless switch)
S_NEED = 7  # what a NEED_* return asks for: the speed band or the km/h
S_SEARCHED = 8  # the adaptive search's last choice (m; NaN before the first search): where the next one starts
S_MODEL = 9  # the delay predictor's model (`delay_predictor.MODEL_SIZE` values; NaN before the first step)
#: With the lag-inverting feed-forward: its kinematic curvature sent last step (1/m; NaN before the first step);
#: S_KAPPA_CMD then holds the feedback's integrated curvature alone.
S_FEEDFORWARD_KAPPA = S_MODEL + dp.MODEL_SIZE
STATE_SIZE = S_FEEDFORWARD_KAPPA + 1

# `clothoid_step`'s status.
STEP_DONE, NEED_FLOOR, NEED_FILTER = 0, 1, 2
#: km/h rows of the lead-filter table: every whole km/h up to the plausible measurement's top speed (540 km/h).
FILTER_ROWS = 541
#: Rows of the floor table: every speed band up to 540 km/h.
FLOOR_ROWS = 120
#: Size of `clothoid_step`'s scratch array: a table row, a projection, then the two lags' rows at this speed.
LAG_ROWS = 4 + TRACK_OUT_SIZE
SCRATCH_SIZE = LAG_ROWS + 8


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
    """(feed-forward time s, reference lead s, K) at this speed (`ClothoidController.feedforward_timing`): lags
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
    ff = params[P_FEEDFORWARD_TIME]
    if math.isnan(ff):
        ff = max(0.0, path_delay + lead_delay)
    ff += params[P_KNOWN_DELAY]
    ref = params[P_REFERENCE_LEAD]
    if math.isnan(ref):
        ref = min(max(path_delay - measured_delay, 0.0), params[P_HORIZON])
    return min(ff, 5.0), min(ref, 5.0), gain


@njit(cache=True)
def reference_curvature(
    path_curvature: np.ndarray,
    spacing: float,
    length: float,
    closed: bool,
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
    lag: the path's curvature at s_m. rows: 8 floats of scratch (the two lags' rows at this speed)."""
    path_lag, measured_lag = rows[:4], rows[4:8]
    table_row(lag_speeds, lags, speed_mps * 3.6, False, path_lag)
    if measured_lags.shape[0] == 0:
        return previewed_curvature(path_curvature, spacing, length, closed, s_m, speed_mps, 0.0, 0.0, 0.0, window_m)[0]
    table_row(lag_speeds, measured_lags, speed_mps * 3.6, False, measured_lag)
    a_p, b_p = 2.0 * path_lag[1] / path_lag[0], 1.0 / (path_lag[0] * path_lag[0])
    a_m, b_m = 2.0 * measured_lag[1] / measured_lag[0], 1.0 / (measured_lag[0] * measured_lag[0])
    first = a_p - a_m
    curvature = previewed_curvature(
        path_curvature, spacing, length, closed, s_m, speed_mps, path_lag[2] - measured_lag[2], first,
        b_p - b_m - a_m * first, window_m,
    )[0]  # fmt: skip
    return curvature


@njit(cache=True)
def clothoid_step(
    t_s: float,
    x_m: float,
    y_m: float,
    vx_mps: float,
    vy_mps: float,
    yaw_rad: float,
    yaw_rate_rad_s: float,
    steer_wheel_rad: float,
    params: np.ndarray,
    state: np.ndarray,
    path_x: np.ndarray,
    path_y: np.ndarray,
    path_heading: np.ndarray,
    path_curvature: np.ndarray,
    closed: bool,
    tracker: np.ndarray,
    here: np.ndarray,
    limits: np.ndarray,
    limit_speeds: np.ndarray,
    lags: np.ndarray,
    measured_lags: np.ndarray,
    lag_speeds: np.ndarray,
    schedule: np.ndarray,
    schedule_speeds: np.ndarray,
    floors: np.ndarray,
    filters: np.ndarray,
    buffers: np.ndarray,
    scores: np.ndarray,
    results: np.ndarray,
    scratch: np.ndarray,
    diagnostics: np.ndarray,
    history: np.ndarray,
) -> tuple[float, int]:  # pragma: no cover - compiled
    """(steering-wheel command rad, status) of one step (`controller.py` documents what it does); diagnostics (16)
    in the order of controller.DIAGNOSTIC_KEYS. tracker, here: the states of the start pose's and the measured
    position's path trackers; floors (FLOOR_ROWS) and filters (FILTER_ROWS, 9: `DiscreteLeadFilter.coefficients`)
    NaN where not made yet; buffers, scores, results: the search's work arrays (`lookahead.py`); scratch:
    SCRATCH_SIZE floats; history: the delay predictor's commands sent (`delay_predictor.history_length` slots; any
    size without it)."""
    p = params
    speed = math.hypot(vx_mps, vy_mps)  # Measurement.speed_mps
    spacing, length = p[P_PATH_SPACING], p[P_PATH_LENGTH]
    filtered = schedule.shape[0] > 0

    # What the step needs that Python makes, asked before any state changes.
    kmh = -1
    if filtered:
        kmh = round(speed * 3.6) if schedule.shape[0] > 1 else 0
        if math.isnan(filters[kmh, 0]):
            state[S_NEED] = kmh
            return 0.0, NEED_FILTER
    x_band = speed * 3.6 / p[P_BAND_KMH]
    band, held = max(1, round(x_band)), int(state[S_HELD_BAND])
    if held >= 0 and band < held and x_band > held - 0.5 - p[P_BAND_HYSTERESIS_KMH] / p[P_BAND_KMH]:
        band = held
    if math.isnan(floors[band]):
        state[S_NEED] = band
        return 0.0, NEED_FLOOR

    wheelbase, ratio = p[P_WHEELBASE], p[P_STEERING_RATIO]
    steering_kappa = math.tan(steer_wheel_rad / ratio) / wheelbase
    inverting = p[P_FEEDFORWARD] != 0.0 and p[P_FEEDFORWARD_INVERSION] != 0.0
    first = math.isnan(state[S_KAPPA_CMD])
    if first:  # first step: continue from the vehicle's current steering
        state[S_KAPPA_CMD] = steering_kappa
        state[S_FILTER_X] = state[S_FILTER_X + 1] = state[S_FILTER_X + 2] = steer_wheel_rad
    table_row(limit_speeds, limits, speed * 3.6, False, scratch[:2])
    kappa_max, rate_max = scratch[0], scratch[1]
    mode0 = int(p[P_INITIAL_CURVATURE])
    if mode0 == KAPPA0_YAW_RATE and speed > p[P_MIN_SPEED]:
        kappa0 = yaw_rate_rad_s / speed
    elif mode0 == KAPPA0_STEERING:
        kappa0 = steering_kappa
    else:
        kappa0 = state[S_KAPPA_CMD]
        if inverting and not math.isnan(state[S_FEEDFORWARD_KAPPA]):  # the curvature sent: feedback + feed-forward
            kappa0 += state[S_FEEDFORWARD_KAPPA]
    kappa0 = min(max(kappa0, -kappa_max), kappa_max)

    # Sections 2 and 3: the start pose, the lookahead, then the hyper-clothoid to the target (Eq. 3).
    heading = yaw_rad
    if p[P_COURSE] != 0.0 and vx_mps > p[P_MIN_SPEED]:
        heading += math.atan2(vy_mps, vx_mps)
    px, py, ph = x_m, y_m, heading
    horizon = p[P_HORIZON]
    model = state[S_MODEL : S_MODEL + dp.MODEL_SIZE]
    predicting = p[P_DELAY_MODEL] != 0.0
    if predicting:  # over the known delay with the identified lags and the commands sent (`delay_predictor.py`)
        path_lag, measured_lag = scratch[LAG_ROWS : LAG_ROWS + 4], scratch[LAG_ROWS + 4 : LAG_ROWS + 8]
        table_row(lag_speeds, lags, speed * 3.6, False, path_lag)
        if measured_lags.shape[0] > 0:
            table_row(lag_speeds, measured_lags, speed * 3.6, False, measured_lag)
        else:
            measured_lag[:] = path_lag
        delay = p[P_KNOWN_DELAY]
        dp.record_and_advance(model, history, t_s, p[P_DT], path_lag, measured_lag, delay, steering_kappa)
        px, py, ph, kappa0 = dp.predicted_start(
            model, history, x_m, y_m, heading, kappa0, speed, p[P_DT], path_lag, measured_lag, delay
        )
        kappa0 = min(max(kappa0, -kappa_max), kappa_max)
        horizon -= delay
    if horizon > 0.0:
        px, py, ph = along_arc(px, py, ph, kappa0, speed * horizon)
    foot = scratch[4 : 4 + TRACK_OUT_SIZE]
    track(
        path_x, path_y, path_heading, path_curvature, spacing, length, closed, p[P_PATH_EXTENT],
        p[P_TRACKER_WINDOW], tracker, px, py, foot,
    )  # fmt: skip
    foot_index, cte = foot[0] / spacing, foot[6]
    max_segment = p[P_PATH_MAX_SEGMENT]

    state[S_HELD_BAND] = band
    floor = max(floors[band], p[P_MIN_LOOKAHEAD], p[P_MIN_PREVIEW] * speed)
    top = max(p[P_MAX_LOOKAHEAD], floor)
    mode = int(p[P_LOOKAHEAD_MODE])
    evaluations, reused = 0, -1
    if mode == MODE_FIXED:
        lookahead = searched = p[P_FIXED_LOOKAHEAD]
    else:
        if p[P_MAX_TURN_RAD] > 0.0:  # the geometric ceiling (ClothoidConfig.max_target_turn_deg)
            ceiling = turn_limited_lookahead(
                path_x, path_y, path_heading, closed, foot_index, px, py, p[P_MAX_TURN_RAD], top, max_segment
            )
            top = max(floor, ceiling)
        if mode == MODE_SPEED:
            lookahead = searched = min(max(p[P_LOOKAHEAD_GAIN] * speed, floor), top)
        else:
            threshold = p[P_FRECHET_THRESHOLD] + (abs(cte) if p[P_EXCESS] != 0.0 else 0.0)
            searched, evaluations = adaptive_search(
                path_x, path_y, closed, foot_index, px, py, ph, kappa0, floor, top, p[P_LOOKAHEAD_STEP], threshold,
                p[P_TOLERANCE_X], p[P_TOLERANCE_Y], p[P_KDOT_MAX], p[P_POINT_SPACING], buffers, scores, results,
                max_segment, state[S_SEARCHED] if p[P_WARM_SEARCH] != 0.0 else np.nan,
            )  # fmt: skip
            state[S_SEARCHED] = searched
            lookahead = filtered_lookahead(
                state[S_LOOKAHEAD : S_LOOKAHEAD + 2], searched, floor, top, speed * p[P_DT], p[P_HYSTERESIS],
                p[P_MAX_GROWTH], p[P_MAX_SHRINK],
            )  # fmt: skip
            reused = evaluated(scores, results, floor, p[P_LOOKAHEAD_STEP], lookahead)
    if reused >= 0:  # the search evaluated this very lookahead: the same fit again
        row = results[reused]
        frechet, kdot, clothoid_length, tx, ty, ex, ey = row[0], row[1], row[2], row[3], row[4], row[5], row[6]
        status = int(row[7])
    else:
        frechet, kdot, clothoid_length, tx, ty, ex, ey, status = evaluate_candidate(
            path_x, path_y, closed, foot_index, px, py, ph, kappa0, lookahead, p[P_KDOT_MAX], p[P_POINT_SPACING],
            buffers, max_segment, np.inf,
        )  # fmt: skip
    clothoid_kdot = reference_kdot = feedforward_kdot = kdot
    feedforward_kappa = 0.0
    if p[P_FEEDFORWARD] != 0.0:  # path_feedforward.py: feedback relative to the path's own clothoid, plus its rate
        track(
            path_x, path_y, path_heading, path_curvature, spacing, length, closed, p[P_PATH_EXTENT],
            p[P_TRACKER_WINDOW], here, x_m, y_m, foot,
        )  # fmt: skip
        ff_time, reference_lead, gain = feedforward_timing(
            speed, p, lags, measured_lags, lag_speeds, schedule, schedule_speeds, scratch[:4]
        )
        if inverting and p[P_LAG_MODEL_REFERENCE] != 0.0 and lags.shape[0] > 0:
            reference_kappa = reference_curvature(
                path_curvature, spacing, length, closed, foot[0] + speed * (p[P_HORIZON] - horizon), speed, lags,
                measured_lags, lag_speeds, p[P_FEEDFORWARD_WINDOW], scratch[LAG_ROWS : LAG_ROWS + 8],
            )  # fmt: skip
            kdot, reference_kdot, feedforward_kdot = two_degree_of_freedom_rate(
                kdot, path_x, path_y, path_heading, path_curvature, spacing, length, closed, foot, tx, ty, speed,
                horizon, ff_time, 0.0, gain, p[P_FEEDFORWARD_WINDOW], p[P_HORIZON] - horizon, reference_kappa,
            )  # fmt: skip
        else:
            kdot, reference_kdot, feedforward_kdot = two_degree_of_freedom_rate(
                kdot, path_x, path_y, path_heading, path_curvature, spacing, length, closed, foot, tx, ty, speed,
                horizon, ff_time, reference_lead, gain, p[P_FEEDFORWARD_WINDOW], p[P_HORIZON] - horizon,
            )  # fmt: skip
        if inverting:  # the lag inverted, added after the lead filter; the integrator holds the feedback alone
            kdot = clothoid_kdot - reference_kdot
            omega_n, zeta, dead_time = math.nan, 1.0, 0.0
            if lags.shape[0] > 0:
                table_row(lag_speeds, lags, speed * 3.6, False, scratch[:4])
                omega_n, zeta, dead_time, gain = scratch[0], scratch[1], scratch[2], scratch[3]
            feedforward_kappa, feedforward_kdot = lag_inverse_curvature(
                path_curvature, spacing, length, closed, foot[0], speed, dead_time + p[P_KNOWN_DELAY], omega_n, zeta,
                gain, p[P_FEEDFORWARD_WINDOW],
            )  # fmt: skip
            feedforward_kappa = min(max(feedforward_kappa, -kappa_max), kappa_max)
            state[S_FEEDFORWARD_KAPPA] = feedforward_kappa
            if first:  # the feedback's share of the steering now (bumpless)
                state[S_KAPPA_CMD] = steering_kappa - feedforward_kappa
                steer_feedback = math.atan(wheelbase * state[S_KAPPA_CMD]) * ratio
                state[S_FILTER_X] = state[S_FILTER_X + 1] = state[S_FILTER_X + 2] = steer_feedback

    # Figure 2: kappa' x V integrated to curvature, under the rate and curvature limits (section 4).
    rate = min(max(kdot * speed, -rate_max), rate_max)
    if inverting:  # the feedback integrated within what the feed-forward leaves of the curvature limit
        kappa_fb = state[S_KAPPA_CMD] + rate * p[P_DT]
        kappa_fb = min(max(kappa_fb, -kappa_max - feedforward_kappa), kappa_max - feedforward_kappa)
        state[S_KAPPA_CMD] = kappa_fb
        kappa_cmd = kappa_fb + feedforward_kappa
        steer_feedback = math.atan(wheelbase * kappa_fb) * ratio
        steer = math.atan(wheelbase * kappa_cmd) * ratio
        command = steer
        if filtered:  # Eq. 6 on the feedback's steering; the feed-forward's share added after it
            command = lead_step(filters[kmh], state[S_FILTER_X : S_FILTER_X + 3], steer_feedback)
            command += steer - steer_feedback
    else:
        kappa_cmd = min(max(state[S_KAPPA_CMD] + rate * p[P_DT], -kappa_max), kappa_max)
        state[S_KAPPA_CMD] = kappa_cmd
        steer = math.atan(wheelbase * kappa_cmd) * ratio  # Ackermann: tan(phi) = L kappa
        command = steer
        if filtered:  # Eq. 6: this km/h's filter, on the state the last one left (the same lag-chain signals)
            command = lead_step(filters[kmh], state[S_FILTER_X : S_FILTER_X + 3], steer)
    limit = p[P_MAX_STEER]
    command = min(max(command, -limit), limit)
    if predicting:
        dp.send(model, history, math.tan(command / ratio) / wheelbase)

    d = diagnostics
    d[0], d[1], d[2], d[3], d[4], d[5] = lookahead, searched, floor, top, frechet, kdot
    d[6], d[7], d[8], d[9] = clothoid_kdot, reference_kdot, feedforward_kdot, clothoid_length
    d[10], d[11], d[12] = math.hypot(ex - tx, ey - ty), float(status), float(evaluations)
    d[13], d[14], d[15] = kappa0, kappa_cmd, steer
    return command, STEP_DONE
