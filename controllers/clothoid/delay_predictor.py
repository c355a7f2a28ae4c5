"""The pose and kappa(0) predicted over a known dead time with the vehicle's identified lags and the commands
already sent: a Smith predictor (Smith 1957) in the form of a state prediction, as the MPCs compensate a known
input delay (`controllers/mpc`).

Why. With a dead time T in the loop (measurement latency plus actuation dead time, `ClothoidConfig.known_delay_s`)
the steering the controller sends now acts T later, on a vehicle T further on. Predicting the pose over T on an
arc of the curvature measured now (`delay_compensation="arc"`) leaves the delay in the loop: it costs omega_c T of
phase at the crossover, and the lookahead floor that keeps the margins grows (the loaded truck at 20 km/h: 5.5 m
without a delay, 10.5 m with 0.11 s), which leaves a hairpin's error uncorrected over twice the distance. But what
the vehicle does over those T seconds is decided already: by the commands sent in the last T plus the lag's own
delay. Driven through the identified lags of Eq. 5 (`VehicleTuning`), they tell how the curvature will change;
the start pose and kappa(0) the controller fits from are then where the vehicle will be when the command now sent
takes effect, and the loop the clothoid law closes is the delay-free one (`loop_analysis.py`).

What. A model of each lag (to the path curvature, which turns the course, and to the measured yaw-rate curvature),
run from the kinematic curvature of the steering sent, delayed by T plus the lag's own delay. Over the next T the
course turns by the yaw-rate curvature measured now plus the path lag's output less the yaw-rate lag's now, and
kappa(0) changes by the yaw-rate lag's change (the measurement anchors the prediction, so a model's steady-state
error in K does not bias it):
    kappa_path(t + tau) = kappa(0) + K_m (x_p(t + tau) - x_m(t)),   kappa(0)' = kappa(0) + K_m (x_m(t + T) - x_m(t - A))
and the pose is moved along kappa_path in substeps of at most SUBSTEP_S, each on its mean curvature. The path lag's
output less the yaw-rate lag's is the sideslip's rate (over speed) the commands sent make, so the course's change
over T includes the sideslip's; with the two lags the plant's, on one gain, the loop with the delay and this
predictor has every pole of the delay-free loop (Smith's property, `loop_analysis.py`, `test_clothoid_delay.py`),
where turning the course with the path lag's own change misses the sideslip's rate now over T. The lags are
discretised exactly (zero-order hold) at the substep, per step at the speed's interpolated lag. A is how much older
the yaw rate (kappa(0)) is than the pose (`ClothoidConfig.yaw_rate_age_s`: a vehicle bus often delivers it later
than the localisation its pose): read as the pose's age, a 10 ms older yaw rate entering a hairpin is 1 % of its
curvature behind, which the feedback takes for the vehicle's own and steers against (the dynamic car on
Zandvoort's hairpin: max |CTE| twice that with an aligned yaw rate). Where the speed plan brakes or drives, the
sideslip the lags do not explain is released over T too (`sideslip_release.py`, `lag_transient_sideslip`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from controllers.clothoid.pose_prediction import along_arc

#: Longest substep (s) of the lag models and the pose's integration.
SUBSTEP_S = 0.002
#: The model's state: path lag [y, y'], measured lag [y, y'] (y in kinematic curvature, 1/m), then the time of the
#: last step (s) and the ring buffer's next slot.
M_PATH, M_MEASURED, M_TIME, M_HEAD = 0, 2, 4, 5
MODEL_SIZE = 6


@njit(cache=True)
def substeps_per_period(period_s: float) -> int:
    """How many substeps of at most SUBSTEP_S make one controller period."""
    return max(1, math.ceil(period_s / SUBSTEP_S - 1e-9))


def history_length(period_s: float, longest_delay_s: float) -> int:
    """Slots of the ring buffer of commands sent: the commands of the last longest_delay_s (the known delay plus
    the longest lag delay, s), and three slots more (the step now, the rounding of the delays to substeps)."""
    return math.ceil(longest_delay_s / period_s) + 3


@njit(cache=True)
def lag_transition(omega_n: float, zeta: float, h: float) -> tuple[float, float, float, float, float, float]:
    """(a11, a12, a21, a22, b1, b2): Eq. 5's unit-gain lag y'' = -wn^2 y - 2 zeta wn y' + wn^2 u discretised exactly
    over h with the input held: x+ = A x + b u. exp(M), M = A h, by its eigenvalues mu +- s (Cayley-Hamilton);
    b = A^-1 (exp(A h) - I) [0, wn^2]."""
    mu = -zeta * omega_n * h
    q = (omega_n * h) ** 2 * (1.0 - zeta * zeta)  # det(M) - mu^2
    if q > 1e-12:
        s = math.sqrt(q)
        c, f = math.cos(s), math.sin(s) / s
    elif q < -1e-12:
        s = math.sqrt(-q)
        c, f = math.cosh(s), math.sinh(s) / s
    else:
        c, f = 1.0, 1.0
    e = math.exp(mu)
    m11, m12, m21, m22 = 0.0, h, -((omega_n * h) ** 2) / h, -2.0 * zeta * omega_n * h
    a11, a12 = e * (c + f * (m11 - mu)), e * f * m12
    a21, a22 = e * f * m21, e * (c + f * (m22 - mu))
    b1 = -2.0 * zeta * omega_n * a12 - (a22 - 1.0)
    b2 = omega_n * omega_n * a12
    return a11, a12, a21, a22, b1, b2


@njit(cache=True)
def _advance(
    y: float, dy: float, lag: tuple[float, float, float, float, float, float], u: float
) -> tuple[float, float]:  # pragma: no cover - compiled
    """One substep of a lag: (y, y') after it, the input u held (`lag_transition`'s matrices)."""
    a11, a12, a21, a22, b1, b2 = lag
    return a11 * y + a12 * dy + b1 * u, a21 * y + a22 * dy + b2 * u


@njit(cache=True)
def _substep_lags(
    period_s: float, path_lag: np.ndarray, measured_lag: np.ndarray, known_delay_s: float
) -> tuple[
    int, tuple[float, float, float, float, float, float], tuple[float, float, float, float, float, float], int, int
]:  # pragma: no cover - compiled
    """(substeps a period, path lag's and measured lag's `lag_transition` over a substep, each lag's input delay in
    substeps: the known delay plus its own); the lags as (wn, zeta, delay s, K)."""
    per = substeps_per_period(period_s)
    h = period_s / per
    return (
        per,
        lag_transition(path_lag[0], path_lag[1], h),
        lag_transition(measured_lag[0], measured_lag[1], h),
        round((known_delay_s + path_lag[2]) / h),
        round((known_delay_s + measured_lag[2]) / h),
    )


@njit(cache=True)
def _input(history: np.ndarray, head: int, offset: int, delay_substeps: int, per_period: int) -> float:
    """What a lag whose input is delay_substeps late gets in the substep `offset` substeps after now: the command
    sent then (each held over its period; the last one sent, before now, held on beyond it; the oldest kept before
    the buffer)."""
    back = -1 - (offset - delay_substeps) // per_period  # periods before the last command sent
    n = history.size
    return history[(head - 1 - min(max(back, 0), n - 1)) % n]


@njit(cache=True)
def record_and_advance(
    model: np.ndarray,
    history: np.ndarray,
    t_s: float,
    period_s: float,
    path_lag: np.ndarray,
    measured_lag: np.ndarray,
    known_delay_s: float,
    initial_input: float,
) -> None:  # pragma: no cover - compiled
    """Bring the model to the step at t_s (before its command is sent). On the first call (model[M_TIME] NaN) it
    starts at rest at initial_input (the kinematic curvature of the steering now), every slot of the history
    holding it; later, the periods since the last step pass with the commands then sent (a step the controller did
    not take held the last command). path_lag, measured_lag: (wn, zeta, delay s, K) at this speed."""
    if math.isnan(model[M_TIME]):
        history[:] = initial_input
        model[M_PATH], model[M_PATH + 1] = initial_input, 0.0
        model[M_MEASURED], model[M_MEASURED + 1] = initial_input, 0.0
        model[M_TIME], model[M_HEAD] = t_s, 0.0
        return
    n = history.size
    periods = min(max(round((t_s - model[M_TIME]) / period_s), 0), n)
    head = int(model[M_HEAD])
    for _ in range(periods - 1):  # steps not taken: the last command held
        history[head] = history[(head - 1) % n]
        head = (head + 1) % n
    model[M_HEAD] = head
    per, path, measured, d_path, d_measured = _substep_lags(period_s, path_lag, measured_lag, known_delay_s)
    yp, dyp, ym, dym = model[M_PATH], model[M_PATH + 1], model[M_MEASURED], model[M_MEASURED + 1]
    for offset in range(-periods * per, 0):
        yp, dyp = _advance(yp, dyp, path, _input(history, head, offset, d_path, per))
        ym, dym = _advance(ym, dym, measured, _input(history, head, offset, d_measured, per))
    model[M_PATH], model[M_PATH + 1], model[M_MEASURED], model[M_MEASURED + 1] = yp, dyp, ym, dym
    model[M_TIME] = t_s


@njit(cache=True)
def send(model: np.ndarray, history: np.ndarray, curvature_1pm: float) -> None:  # pragma: no cover - compiled
    """Record the command sent this step (as kinematic curvature, 1/m; a non-finite one, which the controller
    does not send, as the last held)."""
    head = int(model[M_HEAD])
    n = history.size
    history[head] = curvature_1pm if math.isfinite(curvature_1pm) else history[(head - 1) % n]
    model[M_HEAD] = (head + 1) % n


@njit(cache=True)
def predicted_start(
    model: np.ndarray,
    history: np.ndarray,
    x_m: float,
    y_m: float,
    heading_rad: float,
    kappa0: float,
    speed_mps: float,
    period_s: float,
    path_lag: np.ndarray,
    measured_lag: np.ndarray,
    known_delay_s: float,
    yaw_rate_age_s: float = 0.0,
    deviation_rad: float = 0.0,
    release_rate_1ps: float = 0.0,
) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """(x, y, heading, kappa(0)) known_delay_s ahead (module docstring); the model is left as it was.

    kappa0 is measured yaw_rate_age_s (s) before the pose (the yaw rate's latency less the pose's; negative: after
    it), so its prediction starts from the measured lag's model then (`_measured_at`). deviation_rad (rad): the
    measured sideslip's deviation from the steady turn's and the lags' transient (`lag_transient_sideslip`),
    released at release_rate_1ps (1/s) over the dead time, each substep's release turning the course
    (`sideslip_release.py`; 0: none)."""
    per, path, measured, d_path, d_measured = _substep_lags(period_s, path_lag, measured_lag, known_delay_s)
    h = period_s / per
    head = int(model[M_HEAD])
    yp, dyp, ym, dym = model[M_PATH], model[M_PATH + 1], model[M_MEASURED], model[M_MEASURED + 1]
    ym_pose = ym
    ym0 = _measured_at(ym, dym, measured_lag, history, head, -round(yaw_rate_age_s / h), d_measured, per, h)
    kappa_now = kappa0 + measured_lag[3] * (ym - ym0)  # kappa(0) at the pose's time
    x, y, heading = x_m, y_m, heading_rad
    kept = math.exp(-release_rate_1ps * h) if deviation_rad != 0.0 else 1.0  # of the deviation, over a substep
    left = deviation_rad
    for offset in range(round(known_delay_s / h)):
        before = yp
        yp, dyp = _advance(yp, dyp, path, _input(history, head, offset, d_path, per))
        ym, dym = _advance(ym, dym, measured, _input(history, head, offset, d_measured, per))
        kappa = kappa_now + measured_lag[3] * (0.5 * (before + yp) - ym_pose)  # the substep's mean (trapezoidal)
        if left != 0.0:  # the deviation released over the substep turns the course by as much
            released = left * (1.0 - kept)
            left -= released
            kappa -= released / (speed_mps * h)
        x, y, heading = along_arc(x, y, heading, kappa, speed_mps * h)
    return x, y, heading, kappa0 + measured_lag[3] * (ym - ym0)


@njit(cache=True)
def _measured_at(
    ym: float,
    dym: float,
    measured_lag: np.ndarray,
    history: np.ndarray,
    head: int,
    offset: int,
    d_measured: int,
    per: int,
    h: float,
) -> float:  # pragma: no cover - compiled
    """The measured lag's model output `offset` substeps of h from now (ym, dym: its state now): stepped back
    exactly (Eq. 5 discretised over -h, each substep's input held as it was sent) or on (as `predicted_start`)."""
    if offset == 0:
        return ym
    lag = lag_transition(measured_lag[0], measured_lag[1], -h if offset < 0 else h)
    for k in range(abs(offset)):
        ym, dym = _advance(ym, dym, lag, _input(history, head, -1 - k if offset < 0 else k, d_measured, per))
    return ym


@njit(cache=True)
def lag_transient_sideslip(
    model: np.ndarray,
    history: np.ndarray,
    speed_mps: float,
    period_s: float,
    path_lag: np.ndarray,
    measured_lag: np.ndarray,
    known_delay_s: float,
) -> float:  # pragma: no cover - compiled
    """The part of the lags' sideslip (rad) not yet at its steady value for the yaw-rate curvature their model has
    now (`sideslip_release.py`): speed K_m times the integral of the path lag's output less the measured lag's (the
    course's rate less the yaw's, over speed), less its steady value, in closed form from the lags' states at this
    speed's parameters. For y'' + 2 zeta wn y' + wn^2 y = wn^2 u(t - d) the integral of u(t - d) - y is
    y' / wn^2 + (2 zeta / wn) y, so

        integral (y_p - y_m) = [y'_m / wn_m^2 + (2 zeta_m / wn_m) y_m] - [y'_p / wn_p^2 + (2 zeta_p / wn_p) y_p]
                               + integral of u from t - d_m to t - d_p

    (d: the known delay plus the lag's own), whose steady value at y_m is (group delay_m - group delay_p) y_m. Zero
    in a steady turn; at a held speed its rate is the lags' sideslip rate less the steady part's."""
    per = substeps_per_period(period_s)
    h = period_s / per
    yp, dyp, ym, dym = model[M_PATH], model[M_PATH + 1], model[M_MEASURED], model[M_MEASURED + 1]
    wp, zp, wm, zm = path_lag[0], path_lag[1], measured_lag[0], measured_lag[1]
    states = (dym / (wm * wm) + 2.0 * zm / wm * ym) - (dyp / (wp * wp) + 2.0 * zp / wp * yp)
    d_path, d_measured = round((known_delay_s + path_lag[2]) / h), round((known_delay_s + measured_lag[2]) / h)
    head = int(model[M_HEAD])
    inputs = 0.0  # the commands sent between the two lags' delays, summed over their substeps
    for back in range(min(d_path, d_measured), max(d_path, d_measured)):
        inputs += _input(history, head, -1 - back, 0, per)
    inputs *= h if d_measured > d_path else -h
    steady = (2.0 * zm / wm - 2.0 * zp / wp + (d_measured - d_path) * h) * ym
    return speed_mps * measured_lag[3] * (states + inputs - steady)
