"""Identification of the steering lag of Eq. 5 from vehicle logs (paper, section 5.1, Figure 8).

Input: the kinematic (Ackermann) curvature of the steering wheel, tan(steer_wheel / steering_ratio) / wheelbase,
and the realised curvature of the rear-axle path: by default from the logged rear-axle x, y, as the paper computes
it, kappa = (x' y'' - y' x'') / (x'^2 + y'^2)^1.5 with Savitzky-Golay derivatives (zero phase, so no added lag);
or from yaw rate / speed (no positions, or on request; on the articulated truck it leads the path curvature).

Model: measured = K x G_lag(s) e^(-s delay) kinematic, simulated at the log's samples (exact first-order hold)
from the steady state of the first sample. K, the steady-state gain, is fitted by default: an understeering
vehicle reaches less than the kinematic curvature, which Eq. 5 (unit DC gain) cannot express, and without K the
fit bends omega_n and zeta to mimic it. K goes into the lag file (the MPC uses it; the lead filter of Eq. 6 keeps
unit gain). `unit_gain=True` fixes K = 1; the delay is fitted only with `fit_delay=True`.

Delay and damping trade off (both add phase lag growing with frequency), so steps and a dlc cannot tell them
apart: a chirp in the logs separates them, and with a delay zeta is bounded at DELAY_FIT_MAX_ZETA = 2, where a fit
is accepted rather than refused, since a first-order lag behind a delay is an overdamped Eq. 5 whose fast pole and
the delay are interchangeable (checked in tests/tuning/test_identification_against_linearisation.py).

Fit: scipy.optimize.least_squares over (omega_n, zeta[, K][, delay]) jointly over all logs, from each of the STARTS
best points of a coarse grid, the lowest cost kept (with a delay the cost has several valleys); each log's
residuals are scaled by its curvature range and sample count so that each log counts equally. NRMSE (reported and
written to the lag file) is the RMS over the logs of RMS(error) / range(measured curvature). Refused, saying why:
logs too short, too little steering (no excitation) or too slow, speed varying over the logs by more than
max_speed_variation (the lag depends on speed: fit each speed separately), a fit at a parameter bound (but the
zeta bound of a delay fit) or with NRMSE over max_nrmse.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, signal, sparse
from threadpoolctl import threadpool_limits

from tuning.log_file import VehicleLog
from tuning.savgol import savgol_matrix
from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive
from workbench.vehicles.geometry import VehicleGeometry
from workbench.vehicles.steering_lag import (
    DELAY_BOUNDS,
    GAIN_BOUNDS,
    OMEGA_N_BOUNDS,
    ZETA_BOUNDS,
    SteeringLag,
    simulate_lag,
)

CURVATURE_SOURCES = ("auto", "path", "yaw-rate")
# The bounds of the fitted parameters are those of the steering-lag file (OMEGA_N_BOUNDS, ZETA_BOUNDS, GAIN_BOUNDS,
# DELAY_BOUNDS, imported from workbench.vehicles.steering_lag, the lag's one home, as is simulate_lag).
#: The largest zeta of a fit with a delay (LagFitOptions.max_zeta's default then; module docstring).
DELAY_FIT_MAX_ZETA = 2.0
#: The coarse grid the fit starts from: omega_n (rad/s), zeta, and (fitting a delay) the delay (s).
OMEGA_N_GRID = tuple(np.geomspace(0.3, 60.0, 16).tolist())
ZETA_GRID = (0.3, 0.5, 0.7, 1.0, 1.4, 2.0, 3.0, 5.0)
DELAY_GRID = (0.0, 0.05, 0.1, 0.2, 0.35)
#: How many of the best grid points the fit is refined from.
STARTS = 3


@dataclass(frozen=True)
class LagFitOptions:
    """How fit_lag reads and judges the data (the module docstring says what it refuses and why). With a delay and
    no max_zeta, the upper bound of zeta is DELAY_FIT_MAX_ZETA, where a fit at the bound is accepted.
    """

    curvature_from: str = "auto"  # "auto" (path from x, y when the log has them, else yaw rate), "path" or "yaw-rate"
    smooth_s: float = 0.3  # window of the Savitzky-Golay derivatives of the path (s), in [0, 10]
    fit_delay: bool = False  # also fit a pure delay (True or False)
    max_zeta: float | None = None  # the fit's upper bound of zeta, in [0.1, 10]; None: 10, or 2 with a delay
    unit_gain: bool = False  # fix the steady-state gain K = 1 instead of fitting it (True or False)
    min_duration_s: float = 5.0  # the shortest usable log (s), > 0
    min_samples: int = 50  # the fewest samples of a usable log, a whole number >= 10
    min_steer_std_deg: float = 1.0  # the least steering-wheel standard deviation of a log (deg), in [0, 360]
    min_speed_mps: float = 2.0  # the lowest speed a log may reach (m/s), in [0.1, 100]
    max_speed_variation: float = 0.15  # the most (max - min) / mean speed over all logs, in [0, 2]
    max_nrmse: float = 0.25  # the worst fit accepted (NRMSE, module docstring), in [0, 10]

    def __post_init__(self) -> None:
        if self.curvature_from not in CURVATURE_SOURCES:
            raise WorkbenchInputError(
                f"curvature_from must be one of {', '.join(CURVATURE_SOURCES)}; got {self.curvature_from!r}"
            )
        require_in_range("smooth_s", self.smooth_s, 0.0, 10.0, "s")
        if self.max_zeta is not None:
            require_in_range("max_zeta", self.max_zeta, 0.1, ZETA_BOUNDS[1])
        require_positive("min_duration_s", self.min_duration_s)
        if isinstance(self.min_samples, bool) or not isinstance(self.min_samples, int) or self.min_samples < 10:
            raise WorkbenchInputError(f"min_samples must be a whole number >= 10; got {self.min_samples!r}")
        require_in_range("min_steer_std_deg", self.min_steer_std_deg, 0.0, 360.0, "deg")
        require_in_range("min_speed_mps", self.min_speed_mps, 0.1, 100.0, "m/s")
        require_in_range("max_speed_variation", self.max_speed_variation, 0.0, 2.0)
        require_in_range("max_nrmse", self.max_nrmse, 0.0, 10.0)

    @property
    def zeta_upper_bound(self) -> float:
        """The upper bound of zeta in the fit: max_zeta, else 10 without a delay and DELAY_FIT_MAX_ZETA with one."""
        if self.max_zeta is not None:
            return float(self.max_zeta)
        return DELAY_FIT_MAX_ZETA if self.fit_delay else ZETA_BOUNDS[1]

    @property
    def accepts_zeta_at_bound(self) -> bool:
        """Whether a fit whose zeta reaches its upper bound is accepted: with a delay and a bound under 10 (the
        response is then that of a first-order lag behind a delay, module docstring)."""
        return self.fit_delay and self.zeta_upper_bound < ZETA_BOUNDS[1]


@dataclass(frozen=True)
class SteeringGeometry:
    """What the kinematic curvature needs, for a vehicle without a model here; VehicleGeometry has both too."""

    wheelbase_m: float  # front axle to rear axle (m), in [0.5, 15]
    steering_ratio: float  # steering-wheel angle / road-wheel angle, in [1, 60]

    def __post_init__(self) -> None:
        require_in_range("wheelbase_m", self.wheelbase_m, 0.5, 15.0, "m")
        require_in_range("steering_ratio", self.steering_ratio, 1.0, 60.0)


@dataclass(frozen=True)
class FittedLog:
    """One log's curves (Figure 8): the kinematic, measured and modelled curvature over time, and how well they fit.

    The curvature arrays have one sample per log sample, like `t_s`.
    """

    name: str  # the log's name
    t_s: np.ndarray  # s; time from the log's first sample
    kinematic_1pm: np.ndarray  # 1/m; kinematic curvature of the steering-wheel angle
    measured_1pm: np.ndarray  # 1/m; the measured curvature the lag was fitted to
    modelled_1pm: np.ndarray  # 1/m; the kinematic curvature through the fitted lag (Eq. 5)
    nrmse: float  # 1, >= 0; this log's normalised RMS error of the modelled against the measured curvature
    curvature_from: str  # where the measured curvature came from: "path" (x, y) or "yaw-rate"


@dataclass(frozen=True)
class LagFit:
    """The identified lag (with nrmse and speed range), the steady-state gain K, and the curves of each log."""

    lag: SteeringLag  # the identified lag of Eq. 5, with its gain K, NRMSE and the logs' speed range
    logs: tuple[FittedLog, ...] = field(repr=False)  # each log's curves, in the order given
    options: LagFitOptions = field(repr=False)  # the options it was fitted with

    @property
    def nrmse(self) -> float:
        """The fit's normalised RMS error (module docstring): 0 for a perfect fit, at most the options' max_nrmse."""
        return self.lag.nrmse

    @property
    def gain(self) -> float:
        """The steady-state gain K (1 with unit_gain)."""
        return self.lag.steady_state_gain

    def summary(self) -> str:
        """The fit in one line, for the CLI and the logs.

        Returns
        -------
        str
            omega_n (rad/s), zeta, the delay (s, when fitted), the gain K, the NRMSE, the number of logs and their
            speed range (m/s and km/h).
        """
        lag, (v0, v1) = self.lag, self.lag.speed_range_mps or (math.nan, math.nan)
        delay = f", delay {lag.delay_s:.3f} s" if self.options.fit_delay else ""
        return (
            f"omega_n {lag.omega_n_rad_s:.3f} rad/s, zeta {lag.zeta:.3f}{delay}, steady-state gain K "
            f"{self.gain:.3f}, NRMSE {lag.nrmse:.4f} over {len(self.logs)} log(s) at {v0:.2f}-{v1:.2f} m/s "
            f"({v0 * 3.6:.1f}-{v1 * 3.6:.1f} km/h)"
        )


def kinematic_curvature(steer_wheel_rad: np.ndarray, geometry: VehicleGeometry | SteeringGeometry) -> np.ndarray:
    """Ackermann curvature (1/m) of a steering-wheel angle (rad): tan(steer_wheel / steering_ratio) / wheelbase.

    Parameters
    ----------
    steer_wheel_rad : array_like of float, rad
        Steering-wheel angles, any shape; positive turns left. Finite, and under steering_ratio x pi / 2 in
        magnitude (the road-wheel angle stays inside +-90 deg).
    geometry : VehicleGeometry or SteeringGeometry
        The vehicle's wheelbase (m) and steering ratio (steering-wheel / road-wheel angle).

    Returns
    -------
    numpy.ndarray of float, 1/m
        The kinematic curvature of each angle, in the shape of ``steer_wheel_rad``.

    Examples
    --------
    >>> from tuning.lag_fit import SteeringGeometry, kinematic_curvature
    >>> geometry = SteeringGeometry(wheelbase_m=2.5, steering_ratio=15.0)
    >>> kinematic_curvature([0.0, 0.15], geometry).round(5).tolist()
    [0.0, 0.004]
    """
    return np.tan(np.asarray(steer_wheel_rad, dtype=float) / geometry.steering_ratio) / geometry.wheelbase_m


def _window(log: VehicleLog, smooth_s: float) -> int:
    """The Savitzky-Golay window in samples: odd, at least 5, at most the log."""
    window = max(5, round(smooth_s / log.dt_s) | 1)
    if window > len(log):
        raise WorkbenchInputError(
            f"{log.name}: the smoothing window ({smooth_s:g} s = {window} samples) is longer than the log"
        )
    return window


@dataclass(frozen=True)
class _PathDerivatives:
    """Savitzky-Golay (cubic) first and second time derivatives for one log's length, window and sample time."""

    first: sparse.csr_matrix
    second: sparse.csr_matrix

    @classmethod
    def of(cls, log: VehicleLog, window: int) -> _PathDerivatives:
        return cls(savgol_matrix(len(log), window, 1, log.dt_s), savgol_matrix(len(log), window, 2, log.dt_s))

    def curvature(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(curvature 1/m, speed m/s) of the sampled path x, y."""
        dx, dy, ddx, ddy = self.first @ x, self.first @ y, self.second @ x, self.second @ y
        speed = np.hypot(dx, dy)
        return (dx * ddy - dy * ddx) / np.maximum(speed, 1e-9) ** 3, speed


def path_curvature(log: VehicleLog, smooth_s: float = 0.3) -> np.ndarray:
    """Curvature (1/m) of the logged rear-axle path, from Savitzky-Golay (cubic) time derivatives of x and y.

    The derivatives are zero phase, so the curvature carries no lag of its own: the lag fitted against it is the
    vehicle's.

    Parameters
    ----------
    log : VehicleLog
        A log with rear-axle positions (x_m, y_m columns), moving throughout.
    smooth_s : float, s
        The Savitzky-Golay window (rounded to an odd number of samples, at least 5); at most the log's duration.

    Returns
    -------
    numpy.ndarray of float, 1/m
        The path curvature at each sample of the log, positive turning left.

    Raises
    ------
    WorkbenchInputError
        The log has no x_m, y_m columns, the window is longer than the log, or the rear axle stands still at some
        sample (the curvature is undefined there).
    """
    x_m, y_m = log.x_m, log.y_m
    if x_m is None or y_m is None:
        raise WorkbenchInputError(f"{log.name}: no x_m, y_m columns to compute the path curvature from")
    kappa, speed = _PathDerivatives.of(log, _window(log, smooth_s)).curvature(x_m, y_m)
    if speed.min() <= 1e-6:
        raise WorkbenchInputError(f"{log.name}: the rear axle stands still; the path curvature is undefined")
    return kappa


def _path_of(kappa: np.ndarray, speed: np.ndarray, dt_s: float, heading0: float) -> tuple[np.ndarray, np.ndarray]:
    """The path (x, y) driven at `speed` with `kappa` from heading0 (trapezoidal integration)."""

    def integral(rate: np.ndarray) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * dt_s)])

    heading = heading0 + integral(kappa * speed)
    return integral(speed * np.cos(heading)), integral(speed * np.sin(heading))


def yaw_rate_curvature(log: VehicleLog) -> np.ndarray:
    """Curvature (1/m) as yaw rate / speed.

    Parameters
    ----------
    log : VehicleLog
        A log with a yaw_rate_rad_s column (rad/s) and a speed that stays above zero.

    Returns
    -------
    numpy.ndarray of float, 1/m
        yaw rate / speed at each sample of the log, positive turning left.

    Raises
    ------
    WorkbenchInputError
        The log has no yaw_rate_rad_s column.
    """
    if not log.has_yaw_rate:
        raise WorkbenchInputError(f"{log.name}: no yaw_rate_rad_s column to compute the curvature from")
    return log.yaw_rate_rad_s / log.speed_mps


def realised_curvature(log: VehicleLog, options: LagFitOptions) -> tuple[np.ndarray, str]:
    """The measured curvature (1/m) of the log and the source used ("path" or "yaw-rate").

    Parameters
    ----------
    log : VehicleLog
        The vehicle log to measure.
    options : LagFitOptions
        Its curvature_from ("auto": the path when the log has x_m, y_m, else the yaw rate; "path"; "yaw-rate")
        and smooth_s (s, the path's Savitzky-Golay window) are used.

    Returns
    -------
    curvature : numpy.ndarray of float, 1/m
        The realised curvature at each sample of the log.
    source : str
        The source used: "path" or "yaw-rate".

    Raises
    ------
    WorkbenchInputError
        The source asked for needs columns the log does not have, or the path curvature is undefined (see
        `path_curvature`).
    """
    source = options.curvature_from
    if source == "auto":
        source = "path" if log.has_positions else "yaw-rate"
    if source == "path":
        return path_curvature(log, options.smooth_s), source
    return yaw_rate_curvature(log), source


def simulate_unit_dc(num: np.ndarray, den: np.ndarray, u: np.ndarray, dt_s: float) -> np.ndarray:
    """A proper transfer function num/den (coefficients in s, highest power first) driven by u sampled every dt_s,
    from the steady state of u[0]: the exact first-order-hold discretisation (u linear between samples, as in
    scipy.signal.lsim and python-control's forced_response), run by scipy.signal.lfilter.

    Starting from the steady state of u[0] assumes unit DC gain (hence the name): the output starts at u[0]. A log
    that starts in a held turn then needs no run-in.

    Parameters
    ----------
    num : array_like of float
        Numerator coefficients in s, highest power first.
    den : array_like of float
        Denominator coefficients in s, highest power first; at least the degree of ``num`` (proper), stable.
    u : array_like of float
        The input, one value per sample, at least one sample.
    dt_s : float, s
        The sample time, > 0.

    Returns
    -------
    numpy.ndarray of float
        The output at each sample of ``u``, in the unit of ``u``.

    Examples
    --------
    A first-order lag 1 / (s + 1) from rest, driven by a unit step from the second sample on (the first-order
    hold ramps the input over the first 0.01 s): close to 1 - e^-1 at t = 1 s.

    >>> import numpy as np
    >>> from tuning.lag_fit import simulate_unit_dc
    >>> y = simulate_unit_dc([1.0], [1.0, 1.0], np.r_[0.0, np.ones(100)], 0.01)
    >>> round(float(y[-1]), 2)
    0.63
    """
    u = np.asarray(u, dtype=float)
    b, a, _ = signal.cont2discrete((np.asarray(num, dtype=float), np.asarray(den, dtype=float)), dt_s, method="foh")
    b = np.ravel(b)
    zi = signal.lfilter_zi(b, a) * u[0]
    return signal.lfilter(b, a, u, zi=zi)[0]


def _check_log(log: VehicleLog, options: LagFitOptions) -> None:
    """Refuse a log that cannot identify a lag, saying why."""
    if len(log) < options.min_samples or log.duration_s < options.min_duration_s:
        raise WorkbenchInputError(
            f"{log.name}: too short to identify a lag: {len(log)} samples over {log.duration_s:.3g} s; at least "
            f"{options.min_samples} samples and {options.min_duration_s:g} s are needed"
        )
    steer_std = math.degrees(float(np.std(log.steer_wheel_rad)))
    if steer_std < options.min_steer_std_deg:
        raise WorkbenchInputError(
            f"{log.name}: the steering wheel hardly moves (std {steer_std:.2f} deg, under "
            f"{options.min_steer_std_deg:g} deg): constant steering does not excite the lag; log steps, a step series "
            f"or a double lane change"
        )
    low = float(log.speed_mps.min())
    if low < options.min_speed_mps:
        raise WorkbenchInputError(
            f"{log.name}: speed falls to {low:.3g} m/s, under {options.min_speed_mps:g} m/s: the curvature is "
            f"ill-defined near standstill; log at a held speed"
        )


def _check_speeds(logs: Sequence[VehicleLog], options: LagFitOptions) -> tuple[float, float]:
    low = min(float(log.speed_mps.min()) for log in logs)
    high = max(float(log.speed_mps.max()) for log in logs)
    mean = float(np.mean(np.concatenate([log.speed_mps for log in logs])))
    if (high - low) / mean > options.max_speed_variation:
        where = "the log" if len(logs) == 1 else "the logs"
        raise WorkbenchInputError(
            f"speed varies over {where} from {low:.3g} to {high:.3g} m/s ({low * 3.6:.1f}-{high * 3.6:.1f} km/h), "
            f"{(high - low) / mean:.0%} of the mean; at most {options.max_speed_variation:.0%} is allowed because "
            f"the lag depends on speed: fit each speed separately (`tuning schedule` does)"
        )
    return low, high


@dataclass(frozen=True)
class _LogData:
    """One log prepared for the fit: kinematic and measured curvature, and how the measurement was processed, so
    that the model's curvature can be processed the same way (`as_measured`)."""

    log: VehicleLog
    kinematic: np.ndarray
    measured: np.ndarray
    source: str
    span: float
    derivatives: _PathDerivatives | None
    heading0: float

    @classmethod
    def of(cls, log: VehicleLog, geometry: VehicleGeometry | SteeringGeometry, options: LagFitOptions) -> _LogData:
        measured, source = realised_curvature(log, options)
        span = float(np.ptp(measured))
        if span <= 0.0:
            raise WorkbenchInputError(f"{log.name}: the measured curvature is constant; the vehicle did not turn")
        derivatives, heading0 = None, 0.0
        if source == "path":
            derivatives = _PathDerivatives.of(log, _window(log, options.smooth_s))
            heading0 = math.atan2((derivatives.first @ log.y_m)[0], (derivatives.first @ log.x_m)[0])
        kinematic = kinematic_curvature(log.steer_wheel_rad, geometry)
        return cls(log, kinematic, measured, source, span, derivatives, heading0)

    def as_measured(self, kappa: np.ndarray) -> np.ndarray:
        """A modelled curvature as the measurement would see it: for the path source, the curvature of the path
        it drives at the logged speed, by the same Savitzky-Golay derivatives (so that their smoothing does not
        bias the fit); for the yaw rate, itself."""
        if self.derivatives is None:
            return kappa
        x, y = _path_of(kappa, self.log.speed_mps, self.log.dt_s, self.heading0)
        return self.derivatives.curvature(x, y)[0]


def _start_points(data: Sequence[_LogData], options: LagFitOptions, max_zeta: float) -> list[dict[str, float]]:
    """The STARTS best points of the coarse grid (omega_n x zeta x delay, zeta within max_zeta), the gain solved
    linearly at each, each a dict of omega_n, zeta, gain, delay; the best first."""
    zetas = sorted({min(z, max_zeta) for z in ZETA_GRID})
    delays = DELAY_GRID if options.fit_delay else (0.0,)
    weights = [1.0 / (d.span * d.span * d.measured.size) for d in data]
    scored = []
    for wn0, zeta0, delay0 in itertools.product(OMEGA_N_GRID, zetas, delays):
        sims = [d.as_measured(simulate_lag(d.kinematic, d.log.dt_s, wn0, zeta0, 1.0, delay0)) for d in data]
        num = sum(w * float(np.dot(m, d.measured)) for w, m, d in zip(weights, sims, data, strict=True))
        den = sum(w * float(np.dot(m, m)) for w, m in zip(weights, sims, strict=True))
        gain0 = 1.0 if options.unit_gain else float(np.clip(num / den if den > 0 else 1.0, *GAIN_BOUNDS))
        cost = sum(
            w * float(np.sum((gain0 * m - d.measured) ** 2)) for w, m, d in zip(weights, sims, data, strict=True)
        )
        scored.append((cost, dict(omega_n=wn0, zeta=zeta0, gain=gain0, delay=delay0)))
    scored.sort(key=lambda item: item[0])
    return [start for _, start in scored[:STARTS]]


def fit_lag(
    logs: Sequence[VehicleLog],
    geometry: VehicleGeometry | SteeringGeometry,
    options: LagFitOptions | None = None,
    source: str = "",
) -> LagFit:
    """Fit Eq. 5 (omega_n, zeta; optionally a delay) to all logs jointly; see the module docstring. BLAS runs
    single-threaded meanwhile: the fit's thousands of 4 x 4 matrix exponentials are several times slower with
    threads (two OpenBLAS pools, numpy's and scipy's, contend on a small machine).

    Parameters
    ----------
    logs : sequence of VehicleLog
        Open-loop logs at one held speed (steps, a step series, a double lane change or a chirp), at least one.
    geometry : VehicleGeometry or SteeringGeometry
        The vehicle's wheelbase and steering ratio, which turn the steering-wheel angle into kinematic curvature.
    options : LagFitOptions, optional
        What to fit (gain, delay), the curvature source and the checks of the logs (None: the defaults).
    source : str
        The text recorded as the fitted lag's source ("": one naming the logs and the curvature source).

    Returns
    -------
    LagFit
        The identified lag (natural frequency, damping, gain and delay), its fit error and each log's curves.

    Raises
    ------
    WorkbenchInputError
        No log; a log too short, with steering that hardly moves, or slower than the options' least speed; or
        logs whose speed varies more than the options allow.

    Examples
    --------
    The lag of the dynamic bicycle at 30 km/h, from the open-loop logs `tuning schedule` records (seconds):

    >>> from tuning.lag_fit import fit_lag
    >>> from tuning.schedule import identification_logs
    >>> from workbench.vehicles import make_vehicle
    >>> car = make_vehicle("dynamic-bicycle")
    >>> fit = fit_lag(identification_logs(car, 30.0), car.geometry)
    >>> round(fit.lag.omega_n_rad_s, 1), round(fit.lag.zeta, 2), round(fit.gain, 2)
    (11.0, 0.62, 1.0)
    >>> fit.nrmse < 0.02
    True
    """
    with threadpool_limits(limits=1, user_api="blas"):
        return _fit_lag(logs, geometry, options or LagFitOptions(), source)


def _fit_lag(
    logs: Sequence[VehicleLog], geometry: VehicleGeometry | SteeringGeometry, options: LagFitOptions, source: str
) -> LagFit:
    if not logs:
        raise WorkbenchInputError("fit_lag needs at least one vehicle log")
    for log in logs:
        _check_log(log, options)
    speed_range = _check_speeds(logs, options)
    data = [_LogData.of(log, geometry, options) for log in logs]
    names = ["omega_n", "zeta"] + ([] if options.unit_gain else ["gain"]) + (["delay"] if options.fit_delay else [])
    max_zeta = options.zeta_upper_bound
    bounds = dict(omega_n=OMEGA_N_BOUNDS, zeta=(ZETA_BOUNDS[0], max_zeta), gain=GAIN_BOUNDS, delay=DELAY_BOUNDS)
    lower = np.array([bounds[n][0] for n in names])
    upper = np.array([bounds[n][1] for n in names])

    def unpack(p: np.ndarray) -> dict[str, float]:
        values = dict(zip(names, (float(v) for v in p), strict=True))
        values.setdefault("gain", 1.0)
        values.setdefault("delay", 0.0)
        return values

    def residuals(p: np.ndarray) -> np.ndarray:
        v = unpack(p)
        parts = [
            (d.as_measured(simulate_lag(d.kinematic, d.log.dt_s, v["omega_n"], v["zeta"], v["gain"], v["delay"]))
             - d.measured) / (d.span * math.sqrt(d.measured.size * len(data)))
            for d in data
        ]  # fmt: skip
        return np.concatenate(parts)

    # Start from the best points of a coarse (omega_n, zeta[, delay]) grid, the gain solved linearly at each (the
    # model is linear in K), and refine the best few: a fit with a delay has more than one valley.
    starts = _start_points(data, options, max_zeta)
    best = None
    for start in starts:
        x0 = np.clip([start[n] for n in names], lower, upper)
        trial = optimize.least_squares(residuals, x0, bounds=(lower, upper), x_scale="jac")
        if best is None or trial.cost < best.cost:
            best = trial
    assert best is not None
    fitted = unpack(best.x)
    at_bound = [n for n, x, lo, hi in zip(names, best.x, lower, upper, strict=True) if n != "delay" and
                (x <= lo * (1 + 1e-6) or x >= hi * (1 - 1e-6))]  # fmt: skip
    zeta_at_upper = fitted["zeta"] >= max_zeta * (1 - 1e-6)
    if zeta_at_upper and options.accepts_zeta_at_bound:
        at_bound.remove("zeta")
    if at_bound:
        values = ", ".join(f"{n} = {fitted[n]:.4g}" for n in at_bound)
        hints = []
        if zeta_at_upper:
            hints.append(
                "a damping at its bound means the response looks first-order"
                + (", which a delay makes likelier: try without --delay (fit_delay)" if options.fit_delay else "")
                + (
                    ", or that a unit gain is forced on an understeering vehicle: drop --unit-gain (unit_gain)"
                    if options.unit_gain
                    else ""
                )
            )
        if "gain" in at_bound:
            hints.append("a gain at its bound means the measured curvature does not scale with the steering: check "
                         "the wheelbase, the steering ratio and the units of steer_wheel_deg")  # fmt: skip
        hints.append("give varied steering (steps, a double lane change, a chirp) at one held speed")
        raise WorkbenchInputError(
            f"the fit ran to the bound of {', '.join(at_bound)} ({values}; bounds omega_n {OMEGA_N_BOUNDS}, zeta "
            f"{bounds['zeta']}, gain {GAIN_BOUNDS}): these data cannot identify a second-order lag; {'; '.join(hints)}"
        )
    fitted_logs = []
    for d in data:
        model = simulate_lag(
            d.kinematic, d.log.dt_s, fitted["omega_n"], fitted["zeta"], fitted["gain"], fitted["delay"]
        )
        nrmse = float(np.sqrt(np.mean((d.as_measured(model) - d.measured) ** 2)) / d.span)
        fitted_logs.append(
            FittedLog(d.log.name, d.log.t_s - d.log.t_s[0], d.kinematic, d.measured, model, nrmse, d.source)
        )
    nrmse = float(np.sqrt(np.mean([f.nrmse**2 for f in fitted_logs])))
    if nrmse > options.max_nrmse:
        raise WorkbenchInputError(
            f"a second-order lag explains these data poorly (NRMSE {nrmse:.3g} over {options.max_nrmse:g}; "
            f"omega_n {fitted['omega_n']:.3g} rad/s, zeta {fitted['zeta']:.3g}): check the wheelbase and steering "
            f"ratio, the units of the columns, and that x_m, y_m are the rear-axle centre"
        )
    sources = sorted({f.curvature_from for f in fitted_logs})
    gain_text = "K fixed at 1" if options.unit_gain else f"steady-state gain K = {fitted['gain']:.4g}"
    text = source or (
        f"tuning fit-lag: {', '.join(log.name for log in logs)}; curvature from {' and '.join(sources)}; {gain_text}"
    )
    lag = SteeringLag(
        omega_n_rad_s=fitted["omega_n"],
        zeta=fitted["zeta"],
        delay_s=fitted["delay"],
        steady_state_gain=fitted["gain"],
        nrmse=nrmse,
        speed_range_mps=speed_range,
        source=text,
    )
    return LagFit(lag=lag, logs=tuple(fitted_logs), options=options)


__all__ = [
    "FittedLog",
    "LagFit",
    "LagFitOptions",
    "SteeringGeometry",
    "fit_lag",
    "kinematic_curvature",
    "path_curvature",
    "realised_curvature",
    "simulate_unit_dc",
    "yaw_rate_curvature",
]
