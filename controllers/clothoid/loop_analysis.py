"""Linear analysis of the clothoid controller's loop: loop transfer function, gain and phase margins, closed-loop
poles, and the limit cycle the curvature-rate limit sustains where a margin is gone.

The loop (Figure 2), linearised about a straight path or a constant-curvature arc (curvature kappa_r) at speed V,
in deviations from it: lateral offset y, heading error psi, curvature kappa.

- Plant: the steering sent (as kinematic curvature u) -> the identified lag of Eq. 5 (K wn^2 / (s^2 + 2 zeta wn s +
  wn^2), with its pure delay) -> path curvature kappa; psi' = V kappa - V kappa_r^2 y, y' = V psi (Frenet);
  discretised with a zero-order hold at the controller period, plus any delay (whole periods; `LoopSettings`).
- Controller, exactly as `controller.py` steps it: the start pose predicted over the prediction time and the known
  delay on kappa(0) (the measured curvature, yaw rate / speed, or the integrator's command); kappa' of Eq. 3 at
  that pose as feedback on (y, psi, kappa), its gains taken by finite differences of the compiled hyper-clothoid
  fit to a target on the path at the lookahead (so the arc's geometry is in them); kappa' V integrated by forward
  Euler; the lead filter of Eq. 6 (Tustin). The controller's state-space is read off its own linear step function
  by unit probes.
- The sideslip's release (`sideslip_release.py`), where `LoopSettings.release` puts it in the loop (as while the
  speed plan brakes or drives; at a held speed the controller releases nothing): the plant's sideslip, a fourth
  output, is the lags' own (speed x K_m x the integral of the path lag's output less the measured lag's, in closed
  form from their states and the commands between their delays: no integrator), and the controller releases its
  deviation from the steady turn's (the release's slope about the operating lateral acceleration) and from the
  model's transient over the known delay, turning the predicted course, as `delay_predictor.py` does in whole
  periods. Where the release's steady sideslip is the lags' own and the delay is as told the deviation is zero and
  the loop is the one without; with the vehicle's own steady sideslip and a dead time off it is a feedback of its
  own, and the floor keeps the delayed margins with it as without (`lookahead_floor`).
- The feed-forward (`path_feedforward.py`) is not in the loop: it is computed from the path and the speed alone,
  an input added to the loop, not a feedback. By default (`ClothoidConfig.feedforward_inversion`) the lag's inverse
  is added to the steering after the lead filter and the integrator holds the feedback alone; without it, its
  curvature rate is integrated with the feedback's and passes through the lead filter. Either way L(z), its margins
  and the lookahead floor are the same; what the feed-forward changes is how far the path's curvature is already
  steered when the feedback acts (the curvature and rate limits, which bound the sum, are not in the linear loop).
- The loop is broken at the steering sent: L(z) = -C(z) P(z), negative-feedback convention.

Margins: phase margin at every gain crossover (the least reported); gain margin (how much the loop gain may rise,
at phase crossovers where |L| < 1) and gain-reduction margin (how much it may fall, where |L| > 1: the loop is of
type 3, integrator and double integrator, so it always has one at low frequency). The curvature-rate limit
saturates kappa' V before the integrator: its describing function N(A) = (2 / pi) (asin(1 / a) + sqrt(1 - 1 / a^2)
/ a), a = A / limit, a real gain in (0, 1]. Where the linear loop is unstable (|L| > 1 at a phase crossover above
the crossover), the saturated loop oscillates at that frequency with N(A) = 1 / |L|: the limit cycle this module
predicts. On loops that cycle in simulation (a lead filter at 5 m and 30 km/h, no floor) it predicts 1.4 Hz on the
loaded truck and 2.4 Hz on the dynamic bicycle, where the simulations show about 1 Hz and 2 Hz; its amplitudes are
about twice those seen (the actuator's own rate limit and lag, which also bound the cycle, are not in it).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import control
import numpy as np
from scipy import signal

from controllers.clothoid.clothoid_fit import fit_kernel
from controllers.clothoid.lead_filter import DiscreteLeadFilter, LeadFilterParams
from controllers.clothoid.loop_requirements import (
    DELAY_COMPENSATIONS,
    DELAY_UNCERTAINTY_S,
    REQUIRED_DELAYED_GAIN_MARGIN_DB,
    REQUIRED_DELAYED_PHASE_MARGIN_DEG,
    REQUIRED_GAIN_MARGIN_DB,
    REQUIRED_PHASE_MARGIN_DEG,
    UNCERTAIN_DELAY_MARGIN_FRACTION,
    predicts_with_model,
)
from controllers.clothoid.sideslip_release import SideslipRelease, steady_sideslip
from workbench.base.errors import (
    WorkbenchInputError,
    require_choice,
    require_in_range,
    require_positive,
    value_text,
)
from workbench.vehicles.steering_lag import SteeringLag

#: kappa(0) choices the analysis models (the controller's "steering" is not).
INITIAL_CURVATURES = ("yaw-rate", "command")
#: Finite-difference step of the clothoid-law gains (m, rad and 1/m x 1 m).
_PROBE = 1e-4
#: Spacing (m) of the check above a bisected floor.
_FLOOR_CHECK_M = 10.0
#: Frequency grid points of the margin search (log-spaced up to the Nyquist frequency).
_GRID_POINTS = 2000


@dataclass(frozen=True)
class LoopSettings:
    """What the controller does, for the analysis: sample_time_s (controller period, s), prediction_time_s (pose
    prediction, s), initial_curvature (kappa(0) of Eq. 3: "yaw-rate", the measured curvature, or "command", the
    integrator's), lead (Eq. 6 filter, None: off), measurement_delay_s (a dead time the controller does not know,
    s, rounded to whole periods), known_delay_s (the dead time it knows, measurement latency plus actuation dead
    time, s: the same pure delay in the loop; `ClothoidConfig.known_delay_s`), delay_compensation (how the pose is
    predicted over the known delay: "model", with the lags driven by the commands sent, `delay_predictor.py`, in
    whole periods here; "arc", on kappa(0) over prediction_time_s + known_delay_s), release (the sideslip's release
    at this speed, `sideslip_release.SideslipRelease`, acting in the loop as it does while the speed plan brakes or
    drives, with "model" only: the plant then has a fourth output, its sideslip; None: not in the loop, as at a held
    speed, where the controller does not release).

    Where a delay sits does not matter here: the loop is single-input (broken at the steering sent) and every
    output the controller measures (y, psi, kappa) comes out of the same plant, so a measurement latency z^-n P(z)
    and an actuation dead time P(z) z^-n give the same loop transfer; both are modelled as a delay of the plant's
    input. The controller's own state (its integrator, read as kappa(0) with "command") is delayed by neither."""

    sample_time_s: float = 0.02
    prediction_time_s: float = 0.2
    initial_curvature: str = "yaw-rate"
    lead: LeadFilterParams | None = None
    measurement_delay_s: float = 0.0
    known_delay_s: float = 0.0
    delay_compensation: str = "model"
    release: SideslipRelease | None = None

    def __post_init__(self) -> None:
        require_in_range("sample_time_s", self.sample_time_s, 1e-4, 1.0, "s")
        require_in_range("prediction_time_s", self.prediction_time_s, 0.0, 2.0, "s")
        require_in_range("measurement_delay_s", self.measurement_delay_s, -self.known_delay_s, 2.0, "s")
        require_in_range("known_delay_s", self.known_delay_s, 0.0, 2.0, "s")
        require_choice("delay_compensation", self.delay_compensation, DELAY_COMPENSATIONS)
        if self.initial_curvature not in INITIAL_CURVATURES:
            raise WorkbenchInputError(
                f"initial_curvature must be one of {', '.join(INITIAL_CURVATURES)} for the analysis; got "
                f"{self.initial_curvature!r}"
            )
        if self.release is not None and not self.predicts_with_model:
            raise WorkbenchInputError(
                "the sideslip's release acts over a known delay with delay_compensation 'model'; got "
                f"{self.delay_compensation!r} with known_delay_s {self.known_delay_s:g} s"
            )
        if self.predicts_with_model and self.initial_curvature != "yaw-rate":
            raise WorkbenchInputError(
                "delay_compensation 'model' predicts the measured kappa(0), initial_curvature 'yaw-rate'; got "
                f"{self.initial_curvature!r}"
            )

    @property
    def predicts_with_model(self) -> bool:
        """Whether the pose is predicted over a known delay with the lags' model (`loop_requirements`)."""
        return predicts_with_model(self.delay_compensation, self.known_delay_s)

    @property
    def nominal(self) -> LoopSettings:
        """The loop the delay compensation leaves when its model is the plant: with "model", the delay-free loop
        (Smith's predictor takes the delay out of the characteristic equation; without a known delay nothing is
        released); with "arc", this loop itself."""
        return dataclasses.replace(self, known_delay_s=0.0, release=None) if self.predicts_with_model else self


@dataclass(frozen=True)
class DelayRobustness:
    """What a floor asks of the loop with a known delay compensated by the lags' model, broken at the steering sent
    (the nominal loop keeps the floor's own margins): phase_margin_deg and gain_margin_db (both ways) with the
    plant's dead time the known one, and UNCERTAIN_DELAY_MARGIN_FRACTION of them with it anywhere within +-
    delay_uncertainty_s of it (s; checked at +-1 and +-1/2 times it, never below no delay at all)."""

    phase_margin_deg: float = REQUIRED_DELAYED_PHASE_MARGIN_DEG
    gain_margin_db: float = REQUIRED_DELAYED_GAIN_MARGIN_DB
    delay_uncertainty_s: float = DELAY_UNCERTAINTY_S

    def __post_init__(self) -> None:
        require_in_range("phase_margin_deg", self.phase_margin_deg, 0.0, 89.0, "deg")
        require_in_range("gain_margin_db", self.gain_margin_db, 0.0, 40.0, "dB")
        require_in_range("delay_uncertainty_s", self.delay_uncertainty_s, 0.0, 1.0, "s")

    def delay_errors_s(self, known_delay_s: float) -> tuple[float, ...]:
        """The plant's dead time less the known one (s) at which the reduced margins are checked."""
        d = self.delay_uncertainty_s
        return tuple(sorted({max(e, -known_delay_s) for e in (-d, -0.5 * d, 0.5 * d, d)} - {0.0}))


@dataclass(frozen=True)
class Margins:
    """Stability margins of one loop. phase_margin_deg: least over gain crossovers (inf without one);
    gain_margin_db: how far the loop gain may rise (> 0; inf without a phase crossover below |L| = 1);
    gain_reduction_margin_db: how far it may fall (< 0; -inf without one); crossover_rad_s: the highest gain
    crossover; phase_crossover_rad_s: the frequency of the gain margin (nan without one); stable: all closed-loop
    poles inside the unit circle; spectral_radius: their largest magnitude."""

    phase_margin_deg: float
    gain_margin_db: float
    gain_reduction_margin_db: float
    crossover_rad_s: float
    phase_crossover_rad_s: float
    stable: bool
    spectral_radius: float

    def meets(
        self, phase_margin_deg: float = REQUIRED_PHASE_MARGIN_DEG, gain_margin_db: float = REQUIRED_GAIN_MARGIN_DB
    ) -> bool:
        """Stable, with at least this phase margin and this gain margin both ways."""
        return (
            self.stable
            and self.phase_margin_deg >= phase_margin_deg
            and self.gain_margin_db >= gain_margin_db
            and self.gain_reduction_margin_db <= -gain_margin_db
        )


@dataclass(frozen=True)
class LimitCyclePrediction:
    """The describing-function prediction for the saturated curvature rate: frequency_hz, rate_amplitude_1pm_s
    (amplitude of kappa' V at the saturation's input), curvature_amplitude_1pm (of the integrated command),
    steer_wheel_amplitude_deg (of the steering sent, with the geometry given; nan without)."""

    frequency_hz: float
    rate_amplitude_1pm_s: float
    curvature_amplitude_1pm: float
    steer_wheel_amplitude_deg: float


@lru_cache(maxsize=8192)
def clothoid_law_gains(lookahead_m: float, path_curvature_1pm: float = 0.0) -> tuple[float, float, float]:
    """d kappa' / d (y, psi, kappa) (1/m^3, 1/m^2, 1/m) of Eq. 3's hyper-clothoid at a pose on an arc of curvature
    path_curvature_1pm (a straight for 0) to the path point at Euclidean distance lookahead_m, by central
    differences of the compiled fit (`clothoid_fit.fit_kernel`). About a straight they are -6 / L^3 (1, L, L^2 / 2)
    (small angles), the law the module docstring of `controller.py` derives."""
    require_positive("lookahead_m", lookahead_m)
    kr = float(path_curvature_1pm)
    if abs(kr) * lookahead_m >= 1.9:
        raise WorkbenchInputError(
            "lookahead_m x |path_curvature_1pm| must be < 1.9 (a target on the arc ahead); got "
            f"{value_text(lookahead_m)} x {value_text(kr)}"
        )

    def kdot(y: float, psi: float, kappa: float) -> float:
        # The pose: on the arc's normal at the origin, y to the left, heading psi; the arc x = sin(kr s) / kr ...
        px, py = 0.0, y
        if kr == 0.0:
            tx, ty = px + math.sqrt(max(lookahead_m**2 - py**2, 0.0)), 0.0
        else:  # the arc point at distance lookahead_m from the pose: solve on the circle's angle by bisection
            lo, hi = 0.0, 2.0 * math.asin(min(1.0, abs(kr) * lookahead_m / 2.0) + 1e-12) / abs(kr) + 1.0
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                ax, ay = math.sin(kr * mid) / kr, (1.0 - math.cos(kr * mid)) / kr
                if math.hypot(ax - px, ay - py) < lookahead_m:
                    lo = mid
                else:
                    hi = mid
            s = 0.5 * (lo + hi)
            tx, ty = math.sin(kr * s) / kr, (1.0 - math.cos(kr * s)) / kr
        value, *_ = fit_kernel(px, py, psi, kr + kappa, tx, ty, 1e6)
        return value

    h = _PROBE
    return (
        (kdot(h, 0.0, 0.0) - kdot(-h, 0.0, 0.0)) / (2 * h),
        (kdot(0.0, h, 0.0) - kdot(0.0, -h, 0.0)) / (2 * h),
        (kdot(0.0, 0.0, h * 1e-2) - kdot(0.0, 0.0, -h * 1e-2)) / (2 * h * 1e-2),
    )


def _delay_steps(seconds: float, dt: float) -> int:
    return round(seconds / dt)


@dataclass(frozen=True)
class PlantLags:
    """The vehicle as the loop sees it: path (Eq. 5 from the steering sent to the path curvature, which turns the
    course and moves the rear axle; `tuning fit-lag --curvature-from path`) and measured (to the curvature the
    controller measures, yaw rate / speed, which leads the path curvature by the sideslip's rate; `--curvature-from
    yaw-rate`; None: the path curvature itself)."""

    path: SteeringLag
    measured: SteeringLag | None = None


def _plant_continuous(
    lags: PlantLags, speed_mps: float, path_curvature_1pm: float, sideslip: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C) of the plant in continuous time, without its delays: states path lag (2), psi, y, measured lag (2),
    each lag as SteeringLag's [y, y'] realisation (its gain K here); inputs the steering reaching the path lag and
    the measured lag; outputs (y, psi, kappa measured) and with `sideslip` the lags' part of the sideslip
    (`_sideslip_line`)."""
    require_positive("speed_mps", speed_mps)
    v, kr = float(speed_mps), float(path_curvature_1pm)
    path, measured = lags.path, lags.measured or lags.path
    a_c = np.zeros((6, 6))
    b_c = np.zeros((6, 2))
    a_c[0:2, 0:2], b_c[0:2, 0] = path.companion_matrices()
    a_c[4:6, 4:6], b_c[4:6, 1] = measured.companion_matrices()
    a_c[2, 0], a_c[2, 3], a_c[3, 2] = v * path.steady_state_gain, -v * kr * kr, v
    c_c = np.zeros((4 if sideslip else 3, 6))
    c_c[0, 3], c_c[1, 2], c_c[2, 4] = 1.0, 1.0, measured.steady_state_gain
    if sideslip:
        c_c[3] = v * measured.steady_state_gain * _integral_row(lags)
    return a_c, b_c, c_c


def _steady_slope(release: SideslipRelease, lat_accel_mps2: float) -> float:
    """The slope (rad per m/s^2) of the release's steady sideslip (`sideslip_release.steady_sideslip`) at this
    lateral acceleration: a central difference over 0.001 m/s^2 (at a point of its piecewise-linear grid, the mean of
    the two sides)."""
    row = np.array(release.row())
    step = 1e-3
    return (steady_sideslip(row, lat_accel_mps2 + step) - steady_sideslip(row, lat_accel_mps2 - step)) / (2 * step)


def _integral_row(lags: PlantLags) -> np.ndarray:
    """The integral of the path lag's output less the measured lag's, over the lag states (path lag, psi, y,
    measured lag), less the inputs' part (`_sideslip_line`): for y'' + 2 zeta wn y' + wn^2 y = wn^2 u(t - d) the
    integral of u(t - d) - y is y' / wn^2 + (2 zeta / wn) y (`delay_predictor.lag_transient_sideslip`)."""
    measured = lags.measured or lags.path
    (wp, zp), (wm, zm) = (lags.path.omega_n_rad_s, lags.path.zeta), (measured.omega_n_rad_s, measured.zeta)
    return np.array([-2.0 * zp / wp, -1.0 / wp**2, 0.0, 0.0, 2.0 * zm / wm, 1.0 / wm**2])


def _sideslip_line(taps: tuple[int, int], weight: float) -> tuple[range, float]:
    """The periods back (1 = the command sent a period ago) whose commands the integral of the two lags' inputs
    holds, u(t - d_path) - u(t - d_measured) integrated (the commands between the two delays, taps in periods), and
    each one's weight in the sideslip (rad per 1/m: weight x the period, signed)."""
    low, high = sorted(taps)
    return range(low + 1, high + 1), weight if taps[1] > taps[0] else -weight


def _plant_parts(
    lags: PlantLags, speed_mps: float, path_curvature_1pm: float, settings: LoopSettings
) -> tuple[control.StateSpace, tuple[int, int]]:
    """The plant without its delays (`_plant_continuous`) at the controller period, zero-order hold; and each
    input's delay in whole periods."""
    dt = settings.sample_time_s
    path, measured = lags.path, lags.measured or lags.path
    extra = settings.measurement_delay_s + settings.known_delay_s
    taps = (_delay_steps(path.delay_s + extra, dt), _delay_steps(measured.delay_s + extra, dt))
    sideslip = settings.release is not None
    return _discrete_plant(lags, float(speed_mps), float(path_curvature_1pm), dt, sideslip)[0], taps


@lru_cache(maxsize=1024)
def _discrete_plant(
    lags: PlantLags, speed_mps: float, path_curvature_1pm: float, sample_time_s: float, sideslip: bool = False
) -> tuple[control.StateSpace, np.ndarray]:
    """The plant without its delays at the controller period, and its frequency response on the margins' grid (n,
    outputs, 2): cached, as the floor search asks for the same plant against several delays and lookaheads."""
    a_c, b_c, c_c = _plant_continuous(lags, speed_mps, path_curvature_1pm, sideslip)
    d_c = np.zeros((c_c.shape[0], 2))
    a, b, c, d, _ = signal.cont2discrete((a_c, b_c, c_c, d_c), sample_time_s, method="zoh")
    system = control.ss(a, b, c, d, sample_time_s)
    return system, _batched_response(system, _frequency_grid(sample_time_s)[1])


def plant(lags: PlantLags, speed_mps: float, path_curvature_1pm: float, settings: LoopSettings) -> control.StateSpace:
    """The plant, discrete at the controller period: input the steering sent as kinematic curvature (1/m), outputs
    (y m, psi rad, kappa 1/m, and with settings.release beta rad) as the controller measures them (module
    docstring); the delays as a delay line."""
    parts, taps = _plant_parts(lags, speed_mps, path_curvature_1pm, settings)
    a, b, c = np.asarray(parts.A), np.asarray(parts.B), np.asarray(parts.C)
    m, n = a.shape[0], max(taps)
    # a delay line u -> d1 -> ... -> dn in front; input j of the lags takes tap taps[j] (0: u itself)
    a_full = np.zeros((m + n, m + n))
    a_full[:m, :m] = a
    b_full = np.zeros((m + n, 1))
    for j, tap in enumerate(taps):
        if tap:
            a_full[:m, m + tap - 1] += b[:, j]
        else:
            b_full[:m, 0] += b[:, j]
    if n:
        b_full[m, 0] = 1.0
        for i in range(1, n):
            a_full[m + i, m + i - 1] = 1.0
    outputs = c.shape[0]
    c_full = np.hstack([c, np.zeros((outputs, n))])
    if settings.release is not None:  # the sideslip's part from the commands between the two lags' delays
        back, weight = _sideslip_line(taps, _sideslip_weight(lags, speed_mps, settings))
        c_full[3, [m + k - 1 for k in back]] += weight
    return control.ss(a_full, b_full, c_full, np.zeros((outputs, 1)), parts.dt)


def _sideslip_weight(lags: PlantLags, speed_mps: float, settings: LoopSettings) -> float:
    """The sideslip (rad) per command (1/m) held a period between the two lags' delays: V K_m dt."""
    return float(speed_mps) * (lags.measured or lags.path).steady_state_gain * settings.sample_time_s


#: With the model's delay compensation, the controller's states before its line of commands sent: kappa_cmd, the
#: lead filter (3), the lags' model (4) (`_controller_step`; `_response_with_line` eliminates the line).
_MODEL_CORE_STATES = 8


def _controller_step(
    settings: LoopSettings,
    lags: PlantLags,
    speed_mps: float,
    path_curvature_1pm: float,
    gains: tuple[float, float, float],
) -> tuple[int, Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, float]]]:
    """(state size, step(state, [y, psi, kappa]) -> (next state, curvature sent)): the controller's step in deviation
    variables, linear, in the order `controller.py` runs it. State: [kappa_cmd, lead filter (3)], then with the
    model's delay compensation the lags' model (path, measured: 2 each) and the commands sent (newest first). With
    settings.release the measurement holds the sideslip too ([y, psi, kappa, beta]) and its deviation from the
    steady turn's and the lags' transient (`delay_predictor.lag_transient_sideslip`, in whole periods) is released
    over the known delay (`delay_predictor.predicted_start`)."""
    dt, v = settings.sample_time_s, float(speed_mps)
    g_y, g_psi, g_k = gains
    if settings.lead is not None:
        lead_a, lead_b, lead_c, d_f = DiscreteLeadFilter(settings.lead, dt).state_space
        a_f, b_f, c_f = np.array(lead_a), np.array(lead_b), np.array(lead_c)
    measured = settings.initial_curvature == "yaw-rate"
    model = settings.predicts_with_model
    dp = v * (settings.prediction_time_s + (0.0 if model else settings.known_delay_s))
    sent = 0
    if model:
        # delay_predictor.py, exactly in whole periods: the plant's own equations (lags, psi, y) at the controller
        # period, the path lag turning psi on the measured lag's gain, a third input adding a constant curvature to
        # psi' (the measured curvature less the measured lag's model now, which the prediction holds), each lag's
        # input (its delay + the known delay) late
        measured_lag = lags.measured or lags.path
        k_measured = measured_lag.steady_state_gain
        a_c, b_c, _ = _plant_continuous(lags, v, path_curvature_1pm)
        a_c[2, 0] = v * k_measured
        offset = np.zeros((6, 1))
        offset[2, 0] = v
        a_m, b_m, *_ = signal.cont2discrete((a_c, np.hstack([b_c, offset]), np.eye(6), np.zeros((6, 3))), dt)
        taps = (_delay_steps(lags.path.delay_s + settings.known_delay_s, dt),
                _delay_steps(measured_lag.delay_s + settings.known_delay_s, dt))  # fmt: skip
        ahead, sent = _delay_steps(settings.known_delay_s, dt), max(*taps, 1)
        lag_states = [0, 1, 4, 5]
        release = settings.release
        if release is not None:  # lag_transient_sideslip: the lags' integral from the model's states and the
            # commands sent between the two lags' delays, less its steady value at the measured lag's state
            integral_row = _integral_row(lags)[[0, 1, 4, 5]]
            back, weight = _sideslip_line(taps, dt)
            # its steady value per unit of y_m: the group delays' difference, 2 zeta_m / wn_m - 2 zeta_p / wn_p plus
            # the delays' (the rows' coefficients of y_m and y_p)
            steady_part = integral_row[2] + integral_row[0] + (taps[1] - taps[0]) * dt
            kept = math.exp(-release.rate_1ps * dt)  # of the deviation, over a period
            slope = _steady_slope(release, v * v * path_curvature_1pm)  # rad per m/s^2 of lateral acceleration
    core = _MODEL_CORE_STATES
    size = core + sent if model else 4

    def step(s: np.ndarray, meas: np.ndarray) -> tuple[np.ndarray, float]:
        y, psi, kappa_meas = meas[:3]
        kappa0 = kappa_meas if measured else s[0]
        if model:  # the course turned by the measured curvature plus the path lag's output less the measured
            # lag's now; kappa(0) the measured curvature plus the measured lag's change
            line = s[core:]
            z = np.array([s[4], s[5], psi, y, s[6], s[7]])
            held = kappa_meas - k_measured * s[6]
            left = 0.0
            if release is not None:  # the measured sideslip less the steady turn's (at V^2 kappa) and the lags'
                # transient
                inputs = weight * sum(line[k - 1] for k in back)
                transient = v * k_measured * (integral_row @ s[4:8] + inputs - steady_part * s[6])
                left = meas[3] - slope * v * v * kappa_meas - transient
            for j in range(ahead):  # the commands reaching each lag j periods from now (the last held beyond)
                turn = held
                if release is not None:  # the deviation released over the period turns the course by as much
                    released = left * (1.0 - kept)
                    left -= released
                    turn -= released / (v * dt)
                z = a_m @ z + b_m @ np.array([line[max(taps[0] - j - 1, 0)], line[max(taps[1] - j - 1, 0)], turn])
            psi, y = z[2], z[3]
            kappa0 = kappa_meas + k_measured * (z[4] - s[6])
        yp, psip = y + psi * dp + 0.5 * kappa0 * dp * dp, psi + kappa0 * dp  # the chord formula, linearised
        kappa_cmd = s[0] + dt * v * (g_y * yp + g_psi * psip + g_k * kappa0)
        nxt = np.zeros(size)
        nxt[0] = kappa_cmd
        u = kappa_cmd
        if settings.lead is not None:
            f = s[1:4]
            nxt[1:4] = a_f @ f + b_f * kappa_cmd
            u = float(c_f @ f + d_f * kappa_cmd)
        if model:  # the model advances a period on what reached it; the command sent joins the line
            reached = [s[core + tap - 1] if tap else u for tap in taps]
            z = np.array([s[4], s[5], 0.0, 0.0, s[6], s[7]])
            nxt[4:core] = (a_m @ z + b_m @ np.array([*reached, 0.0]))[lag_states]
            nxt[core] = u
            nxt[core + 1 :] = s[core:-1]
        return nxt, u

    return size, step


def controller(
    settings: LoopSettings, lags: PlantLags, speed_mps: float, lookahead_m: float, path_curvature_1pm: float = 0.0
) -> control.StateSpace:
    """The controller linearised (module docstring): inputs (y, psi, kappa, and with settings.release beta), output
    the steering sent as curvature; read off its linear step by unit probes."""
    gains = clothoid_law_gains(lookahead_m, path_curvature_1pm)
    size, step = _controller_step(settings, lags, speed_mps, path_curvature_1pm, gains)
    inputs = 3 if settings.release is None else 4
    a, c = np.zeros((size, size)), np.zeros((1, size))
    b, d = np.zeros((size, inputs)), np.zeros((1, inputs))
    for i in range(size):
        e = np.zeros(size)
        e[i] = 1.0
        a[:, i], c[0, i] = step(e, np.zeros(inputs))
    for j in range(inputs):
        e = np.zeros(inputs)
        e[j] = 1.0
        b[:, j], d[0, j] = step(np.zeros(size), e)
    return control.ss(a, b, c, d, settings.sample_time_s)


def loop_transfer(
    lags: PlantLags, settings: LoopSettings, speed_mps: float, lookahead_m: float, path_curvature_1pm: float = 0.0
) -> control.StateSpace:
    """L(z) = -C(z) P(z), broken at the steering sent (negative-feedback convention: the closed loop is
    feedback(L, 1))."""
    p = plant(lags, speed_mps, path_curvature_1pm, settings)
    c = controller(settings, lags, speed_mps, lookahead_m, path_curvature_1pm)
    return -control.series(p, c)


def _response(loop: control.StateSpace, omega: np.ndarray) -> np.ndarray:
    """L(e^{j omega dt}) = C (zI - A)^-1 B + D, by a batched linear solve per frequency (transfer-function
    polynomials of this order lose the low frequencies to rounding, where the loop's integrators sit)."""
    a, b, c, d = (np.asarray(m, dtype=float) for m in (loop.A, loop.B, loop.C, loop.D))
    z = np.exp(1j * omega * loop.dt)
    lhs = z[:, None, None] * np.eye(a.shape[0]) - a
    x = np.linalg.solve(lhs, np.broadcast_to(b[:, :1], (omega.size, a.shape[0], 1)).astype(complex))
    return (c[:1] @ x)[:, 0, 0] + d[0, 0]


def margins(loop: control.StateSpace) -> Margins:
    """Margins of a discrete SISO loop (see Margins), from its frequency response on a log grid up to the Nyquist
    frequency, crossings refined by interpolation; stability from the closed-loop poles."""
    omega, _ = _frequency_grid(float(loop.dt))
    return _margins_from(omega, _response(loop, omega), control.feedback(loop, 1).poles())


def _margins_from(omega: np.ndarray, resp: np.ndarray, poles: np.ndarray) -> Margins:
    log_mag = np.log(np.abs(resp))
    phase = np.angle(resp)
    pm, crossover = math.inf, 0.0
    for i in np.flatnonzero(np.sign(log_mag[:-1]) != np.sign(log_mag[1:])):
        f = log_mag[i] / (log_mag[i] - log_mag[i + 1])
        r = resp[i] + f * (resp[i + 1] - resp[i])
        pm = min(pm, 180.0 - abs(math.degrees(math.atan2(r.imag, r.real))))
        crossover = max(crossover, omega[i] + f * (omega[i + 1] - omega[i]))
    gm_up, gm_down, w_pc = math.inf, 0.0, math.nan
    im = resp.imag
    for i in np.flatnonzero(np.sign(im[:-1]) != np.sign(im[1:])):
        f = im[i] / (im[i] - im[i + 1])
        re = resp[i].real + f * (resp[i + 1].real - resp[i].real)
        if re >= 0.0 or not (abs(phase[i]) > math.pi / 2 and abs(phase[i + 1]) > math.pi / 2):
            continue
        g = 1.0 / abs(re)
        if g > 1.0 and g < gm_up:
            gm_up, w_pc = g, omega[i] + f * (omega[i + 1] - omega[i])
        elif g < 1.0:
            gm_down = max(gm_down, g)
    radius = float(np.max(np.abs(poles))) if poles.size else 0.0
    return Margins(
        phase_margin_deg=pm,
        gain_margin_db=20.0 * math.log10(gm_up) if math.isfinite(gm_up) else math.inf,
        gain_reduction_margin_db=20.0 * math.log10(gm_down) if gm_down > 0 else -math.inf,
        crossover_rad_s=crossover if crossover > 0 else math.nan,
        phase_crossover_rad_s=w_pc,
        stable=radius < 1.0,
        spectral_radius=radius,
    )


def saturation_describing_function(amplitude_ratio: float | np.ndarray) -> np.ndarray:
    """N(a) of a unit saturation for a sinusoid of amplitude a x the limit: 1 for a <= 1, else (2 / pi) (asin(1 /
    a) + sqrt(1 - 1 / a^2) / a)."""
    a = np.maximum(np.asarray(amplitude_ratio, dtype=float), 1.0)
    return np.minimum((2.0 / math.pi) * (np.arcsin(1.0 / a) + np.sqrt(1.0 - 1.0 / a**2) / a), 1.0)  # <= 1 exactly


def predicted_limit_cycle(
    loop: control.StateSpace,
    rate_limit_1pm_s: float,
    lead: LeadFilterParams | None = None,
    steer_per_curvature_rad_m: float = math.nan,
) -> LimitCyclePrediction | None:
    """The limit cycle the curvature-rate saturation sustains (module docstring), or None when the linear loop is
    stable or has no phase crossover with |L| > 1 (the saturation's -1 / N lies on the negative real axis left of
    -1, so only such a crossing can meet it; of several, the fastest). The amplitude solves
    N(A / limit) = 1 / |L(j w)| by bisection. steer_per_curvature_rad_m: steering-wheel angle per curvature
    (steering ratio x wheelbase) for the steering amplitude."""
    require_positive("rate_limit_1pm_s", rate_limit_1pm_s)
    if margins(loop).stable:
        return None
    nyquist = math.pi / loop.dt
    omega = np.logspace(math.log10(nyquist) - 4.0, math.log10(nyquist * (1 - 1e-6)), _GRID_POINTS)
    resp = _response(loop, omega)
    mag = np.abs(resp)
    crossings = [
        i
        for i in np.flatnonzero(np.sign(resp.imag[:-1]) != np.sign(resp.imag[1:]))
        if resp[i].real < 0.0 and mag[i] > 1.0
    ]
    if not crossings:
        return None
    best = max(crossings)  # the fastest: the oscillation the saturation holds (the slower ones it passes through)
    target = 1.0 / mag[best]
    lo, hi = 1.0, 1e9
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        if saturation_describing_function(mid) > target:
            lo = mid
        else:
            hi = mid
    w = float(omega[best])
    rate_amp = math.sqrt(lo * hi) * rate_limit_1pm_s
    curvature_amp = target * rate_amp / w
    lead_gain = float(lead.gain_at(w)) if lead is not None else 1.0
    return LimitCyclePrediction(
        frequency_hz=w / (2 * math.pi),
        rate_amplitude_1pm_s=rate_amp,
        curvature_amplitude_1pm=curvature_amp,
        steer_wheel_amplitude_deg=math.degrees(curvature_amp * lead_gain * steer_per_curvature_rad_m),
    )


def _batched_response(system: control.StateSpace, z: np.ndarray) -> np.ndarray:
    """C (zI - A)^-1 B + D at each z, shape (len(z), outputs, inputs)."""
    a, b, c, d = (np.asarray(m, dtype=float) for m in (system.A, system.B, system.C, system.D))
    lhs = z[:, None, None] * np.eye(a.shape[0]) - a
    return c @ np.linalg.solve(lhs, np.broadcast_to(b, (z.size, *b.shape)).astype(complex)) + d


@lru_cache(maxsize=8)
def _frequency_grid(sample_time_s: float) -> tuple[np.ndarray, np.ndarray]:
    """(omega, z = e^{j omega dt}): the margins' log grid up to the Nyquist frequency."""
    nyquist = math.pi / sample_time_s
    omega = np.logspace(math.log10(nyquist) - 5.0, math.log10(nyquist * (1 - 1e-6)), _GRID_POINTS)
    return omega, np.exp(1j * omega * sample_time_s)


@lru_cache(maxsize=1024)
def _controller_with_response(
    lags: PlantLags, settings: LoopSettings, speed_mps: float, lookahead_m: float, path_curvature_1pm: float
) -> tuple[control.StateSpace, np.ndarray]:
    """The controller (`controller`) and its frequency response on the grid, (n, inputs): cached, since the floor search
    asks for the same controller against several plant delays (`DelayRobustness`), and with the model's delay
    compensation it has some 30 states. The controller does not depend on settings.measurement_delay_s."""
    ctrl = controller(settings, lags, speed_mps, lookahead_m, path_curvature_1pm)
    z = _frequency_grid(settings.sample_time_s)[1]
    if not settings.predicts_with_model:
        return ctrl, _batched_response(ctrl, z)[:, 0, :]
    return ctrl, _response_with_line(ctrl, _MODEL_CORE_STATES, z)


def _response_with_line(system: control.StateSpace, core: int, z: np.ndarray) -> np.ndarray:
    """The frequency response (n, inputs) of a single-output system whose states from `core` on are a line of its
    own past outputs, newest first (line_j = z^-(j+1) y): by block elimination, u = (C_c R B_c + D) / (1 - C_c R A_cl
    w - C_l w), R = (zI - A_cc)^-1 and w_j = z^-(j+1), one core-sized solve per frequency instead of one of the
    whole state (the same numbers as `_batched_response`, to rounding)."""
    a, b, c, d = (np.asarray(m, dtype=float) for m in (system.A, system.B, system.C, system.D))
    w = np.cumprod(np.repeat((1.0 / z)[:, None], a.shape[0] - core, axis=1), axis=1)  # (n, line): z^-(j+1)
    lhs = z[:, None, None] * np.eye(core) - a[:core, :core]
    inputs = np.broadcast_to(b[:core], (z.size, core, b.shape[1]))
    rhs = np.concatenate([(w @ a[:core, core:].T)[:, :, None], inputs], 2)
    x = np.linalg.solve(lhs, rhs.astype(complex))  # (n, core, 1 + inputs)
    loop = x[:, :, 0] @ c[0, :core] + w @ c[0, core:]
    return (np.einsum("k,nki->ni", c[0, :core], x[:, :, 1:]) + d[0]) / (1.0 - loop)[:, None]


@lru_cache(maxsize=8192)
def loop_margins(
    lags: PlantLags, settings: LoopSettings, speed_mps: float, lookahead_m: float, path_curvature_1pm: float = 0.0
) -> Margins:
    """margins(loop_transfer(...)), cached (all arguments are frozen values), with the frequency response composed
    from the delay-free plant (6 states), its delays as z^-n and the controller: the same numbers, a fraction of
    the work, for the controller's floor search."""
    _, taps = _plant_parts(lags, speed_mps, path_curvature_1pm, settings)
    sideslip = settings.release is not None
    _, p = _discrete_plant(lags, float(speed_mps), float(path_curvature_1pm), settings.sample_time_s, sideslip)
    ctrl, c = _controller_with_response(
        lags, dataclasses.replace(settings, measurement_delay_s=0.0), speed_mps, lookahead_m, path_curvature_1pm
    )
    omega, z = _frequency_grid(settings.sample_time_s)
    delays = np.stack([z ** (-tap) for tap in taps], axis=1)  # (n, 2)
    plant_response = np.einsum("nij,nj->ni", p, delays)  # (n, outputs)
    if sideslip:  # the sideslip's part from the commands between the two lags' delays (`plant`)
        back, weight = _sideslip_line(taps, _sideslip_weight(lags, speed_mps, settings))
        plant_response[:, 3] += weight * sum(z ** (-k) for k in back)
    response = -np.einsum("ni,ni->n", c, plant_response)
    poles = control.feedback(-control.series(plant(lags, speed_mps, path_curvature_1pm, settings), ctrl), 1).poles()
    return _margins_from(omega, response, poles)


#: Paths whose |curvature| x lookahead reaches this have no target on the arc that far ahead: not analysed.
MAX_CURVATURE_LOOKAHEAD = 1.8


def _margin_checks(
    settings: LoopSettings, phase_margin_deg: float, gain_margin_db: float, delayed: DelayRobustness
) -> list[tuple[LoopSettings, float, float]]:
    """(loop, phase margin, gain margin) to keep: the nominal loop, then with the model the loop itself, with its
    delay as known and as it may be (`lookahead_floor`), without and with the sideslip's release in it where it has
    one (`LoopSettings.release`)."""
    nominal = settings.nominal
    checks = [(nominal, phase_margin_deg, gain_margin_db)]
    if nominal is not settings:
        # with a release, the loop at a held speed (nothing released) and the loop while the plan brakes or drives
        loops = [settings] if settings.release is None else [dataclasses.replace(settings, release=None), settings]
        fraction = UNCERTAIN_DELAY_MARGIN_FRACTION
        for loop in loops:
            checks.append((loop, delayed.phase_margin_deg, delayed.gain_margin_db))
            for error in delayed.delay_errors_s(loop.known_delay_s + loop.measurement_delay_s):
                late = dataclasses.replace(loop, measurement_delay_s=loop.measurement_delay_s + error)
                checks.append((late, fraction * delayed.phase_margin_deg, fraction * delayed.gain_margin_db))
    return checks


def _meets(
    lags: PlantLags,
    checks: list[tuple[LoopSettings, float, float]],
    speed_mps: float,
    lookahead_m: float,
    path_curvatures_1pm: tuple[float, ...],
) -> bool:
    return all(
        loop_margins(lags, loop, speed_mps, lookahead_m, kr).meets(pm, gm)
        for kr in path_curvatures_1pm
        if abs(kr) * lookahead_m < MAX_CURVATURE_LOOKAHEAD
        for loop, pm, gm in checks
    )


def keeps_margins(
    lags: PlantLags,
    settings: LoopSettings,
    speed_mps: float,
    lookahead_m: float,
    path_curvatures_1pm: tuple[float, ...] = (0.0,),
    phase_margin_deg: float = REQUIRED_PHASE_MARGIN_DEG,
    gain_margin_db: float = REQUIRED_GAIN_MARGIN_DB,
    delayed: DelayRobustness = DelayRobustness(),
) -> bool:
    """Whether the loop at this lookahead keeps the margins `lookahead_floor` asks for, about each path curvature:
    what tells a floor at the top of its search that keeps them from one returned because no lookahead does."""
    checks = _margin_checks(settings, phase_margin_deg, gain_margin_db, delayed)
    return _meets(lags, checks, float(speed_mps), float(lookahead_m), path_curvatures_1pm)


def lookahead_floor(
    lags: PlantLags,
    settings: LoopSettings,
    speed_mps: float,
    min_lookahead_m: float,
    max_lookahead_m: float,
    step_m: float = 0.25,
    path_curvatures_1pm: tuple[float, ...] = (0.0,),
    phase_margin_deg: float = REQUIRED_PHASE_MARGIN_DEG,
    gain_margin_db: float = REQUIRED_GAIN_MARGIN_DB,
    delayed: DelayRobustness = DelayRobustness(),
) -> float:
    """The shortest lookahead (m, on a grid of step_m from min_lookahead_m) from which every lookahead up to
    max_lookahead_m keeps the required margins about each of the path curvatures; max_lookahead_m when none does
    (`keeps_margins` tells that from a floor there that keeps them). The margins are those of the nominal loop
    (`LoopSettings.nominal`: with the model's delay compensation the delay-free one, which it leaves when its model
    is the vehicle); with that compensation the loop itself keeps `delayed`'s margins at the steering sent
    (`DelayRobustness`), without and with the sideslip's release in it where settings has one. A bisection on the
    grid (margins mostly improve with the lookahead: the loop's gain falls as L^-3), then a check every
    _FLOOR_CHECK_M above the result; a failure there restarts the bisection above it. Cached: a controller's speed
    nodes are the same run after run."""
    return _lookahead_floor(
        lags, settings, float(speed_mps), float(min_lookahead_m), float(max_lookahead_m), float(step_m),
        tuple(float(k) for k in path_curvatures_1pm), float(phase_margin_deg), float(gain_margin_db), delayed,
    )  # fmt: skip


@lru_cache(maxsize=4096)
def _lookahead_floor(
    lags: PlantLags,
    settings: LoopSettings,
    speed_mps: float,
    min_lookahead_m: float,
    max_lookahead_m: float,
    step_m: float,
    path_curvatures_1pm: tuple[float, ...],
    phase_margin_deg: float,
    gain_margin_db: float,
    delayed: DelayRobustness,
) -> float:
    grid = np.arange(min_lookahead_m, max_lookahead_m + 1e-9, step_m)
    if grid.size == 0 or grid[-1] < max_lookahead_m - 1e-9:
        grid = np.append(grid, max_lookahead_m)
    checks = _margin_checks(settings, phase_margin_deg, gain_margin_db, delayed)

    def ok(i: int) -> bool:
        return _meets(lags, checks, float(speed_mps), float(grid[i]), path_curvatures_1pm)

    if not ok(grid.size - 1):
        return float(grid[-1])
    lo, hi = -1, grid.size - 1
    while True:  # bisect for the shortest ok, then check the rest coarsely; a failure above starts over above it
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if ok(mid):
                hi = mid
            else:
                lo = mid
        stride = max(1, round(_FLOOR_CHECK_M / step_m))
        failing = [i for i in range(hi + stride, grid.size - 1, stride) if not ok(i)]
        if not failing:
            return float(grid[hi])
        lo, hi = failing[-1], grid.size - 1
