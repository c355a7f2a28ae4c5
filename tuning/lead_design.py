"""Design of the lead filter of Eq. 6 for an identified lag of Eq. 5, by loop shaping (paper, section 5.2).

    G_lag(s)  = wn^2 / (s^2 + 2 zeta wn s + wn^2)                        (the plant, from `tuning fit-lag`)
    G_lead(s) = wp^3 (s^2 + 2 psi wz s + wz^2) / (wz^2 (s + wp)^3)       (one complex zero pair, three real poles)
    T(s)      = G_lead(s) G_lag(s)                                      (the cascade; DC gain 1 by structure)

`design_lead` cancels the lag's poles (wz = wn, psi = zeta; needs zeta <= 5, the range of psi, and a strongly damped
lag may have no design under a tight bound), so that T = wp^3 / (s + wp)^3 (no overshoot, -3 dB bandwidth
0.51 wp), and takes the largest wp, by bisection, within

    max_w |G_lead(jw)| <= max_lead_gain           (default 6: the most the filter may raise steering rate and noise)
    max_w |T(jw)|      <= max_cascade_peak_db     (default 1 dB: no resonance, overshoot or ringing)

(Eq. 6 is strictly proper: its peak is its high-frequency gain.) A free search over (wz, psi, wp) was rejected:
the bandwidths are first crossings of a threshold, so its optimum jumps with the frequency grid; cancellation is
unique and smooth in the lag. 6 is the smallest round bound that at least doubles the loaded truck's bandwidth at
30 km/h; in closed loop less lead tracks better, as a larger peak gain turns the controller's fast command changes
into steering rates at the actuator's limit (docs/guide/tuning.md). `design_lead_for_margins` instead picks
Eq. 6 for the shortest lookahead floor of the clothoid loop: with a delay, cancelling leaves the delay untouched.

Reported (and written to the filter file's `design` table) for plant and cascade: the -3 dB bandwidth w_B (where
|G(jw)| first falls 3 dB below its DC gain) and the tracking bandwidth w_T (where |G(jw) - 1| first reaches
1 - 10^(-3/20): phase lag counts as well as lost magnitude, since the compensated curvature should be the
kinematic one, Figure 9); the peaks; the phases at a stated frequency, with any identified delay (which no
filter of this form compensates).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace

import control
import numpy as np
from threadpoolctl import threadpool_limits

from controllers.clothoid.lead_filter import OMEGA_RANGE_RAD_S, POLE_RATIO_RANGE, PSI_MAX, LeadFilterParams
from controllers.clothoid.loop_analysis import (
    REQUIRED_GAIN_MARGIN_DB,
    REQUIRED_PHASE_MARGIN_DEG,
    LoopSettings,
    Margins,
    PlantLags,
    lookahead_floor,
    loop_margins,
)
from tuning.lag_fit import (
    LagFitOptions,
    SteeringGeometry,
    kinematic_curvature,
    realised_curvature,
    simulate_unit_dc,
)
from tuning.log_file import VehicleLog
from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.geometry import VehicleGeometry
from workbench.vehicles.steering_lag import SteeringLag

METHOD = "cancel"
DEFAULT_MAX_LEAD_GAIN = 6.0
DEFAULT_MAX_CASCADE_PEAK_DB = 1.0
#: The -3 dB of the bandwidth, as python-control's `bandwidth` defines it, and the tracking-error threshold.
BANDWIDTH_GAIN = 10 ** (-3 / 20)
TRACKING_ERROR = 1.0 - BANDWIDTH_GAIN
_BISECTIONS = 40
_OMEGA_DECADES = (-2.0, 3.5)  # frequency grid relative to wn
_OMEGA_POINTS = 551
#: |path curvature| x lookahead at or above which an arc is not analysed (no target on it that far ahead; as
#: `lookahead_floor`).
_MAX_CURVATURE_LOOKAHEAD = 1.8


@dataclass(frozen=True)
class LeadDesign:
    """A designed filter and what it achieves. Frequencies in rad/s, phases in degrees (negative: lag)."""

    params: LeadFilterParams  # the designed filter of Eq. 6
    lag: SteeringLag  # the identified lag of Eq. 5 it was designed for (the plant)
    method: str  # "cancel" (`design_lead`) or "margins" (`design_lead_for_margins`)
    max_lead_gain: float  # 1 (linear), >= 1; the bound on the filter's peak |G_lead|
    max_cascade_peak_db: float  # dB, >= 0; the bound on the cascade's peak |G_lead G_lag| (inf: none)
    lead_peak_gain: float  # 1 (linear); the filter's peak |G_lead(jw)|, its high-frequency gain
    cascade_peak_db: float  # dB, >= 0; the cascade's peak |G_lead G_lag| (0: no resonance)
    plant_bandwidth_rad_s: float  # rad/s; the plant's -3 dB bandwidth
    cascade_bandwidth_rad_s: float  # rad/s; the cascade's -3 dB bandwidth
    plant_tracking_bandwidth_rad_s: float  # rad/s; where the plant's |G(jw) - 1| first reaches TRACKING_ERROR
    cascade_tracking_bandwidth_rad_s: float  # rad/s; where the cascade's |T(jw) - 1| first reaches TRACKING_ERROR
    phase_frequency_rad_s: float  # rad/s; where the phases are stated (default: the plant's -3 dB bandwidth)
    plant_phase_deg: float  # deg, negative: lag; the plant's phase there, the lag's delay included
    cascade_phase_deg: float  # deg, negative: lag; the cascade's phase there, the lag's delay included

    @property
    def bandwidth_ratio(self) -> float:
        """The cascade's -3 dB bandwidth over the plant's: how much faster the compensated steering responds."""
        return self.cascade_bandwidth_rad_s / self.plant_bandwidth_rad_s

    @property
    def speed_kmh(self) -> float | None:
        """The design speed: the middle of the lag data's speed range (km/h, to 0.1 km/h), when known."""
        if self.lag.speed_range_mps is None:
            return None
        return round(3.6 * 0.5 * (self.lag.speed_range_mps[0] + self.lag.speed_range_mps[1]), 1)

    def transfer_functions(self) -> tuple[control.TransferFunction, control.TransferFunction, control.TransferFunction]:
        """(plant G_lag, compensator G_lead, cascade G_lead G_lag) as python-control transfer functions (without
        the lag's delay, if any: `frequency_response` includes it).

        Returns
        -------
        plant : control.TransferFunction
            The lag of Eq. 5 with unit gain, without its delay.
        compensator : control.TransferFunction
            The lead filter of Eq. 6.
        cascade : control.TransferFunction
            Their product, G_lead G_lag.
        """
        plant = self.lag.transfer_function(with_gain=False)
        lead = self.params.transfer_function()
        return plant, lead, lead * plant

    def frequency_response(self, omega_rad_s: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """{"plant", "compensator", "cascade"}: (magnitude, phase in degrees) at omega (rad/s), delay included.

        Parameters
        ----------
        omega_rad_s : numpy.ndarray of float, rad/s
            The frequencies, > 0, increasing (the phase is unwrapped along them).

        Returns
        -------
        dict of str to (numpy.ndarray, numpy.ndarray)
            For "plant", "compensator" and "cascade": the magnitude (linear) and the phase (deg, negative: lag) at
            each frequency; the plant's and the cascade's phases include the lag's delay.
        """
        out = {}
        for name, tf in zip(("plant", "compensator", "cascade"), self.transfer_functions(), strict=True):
            response = np.asarray(control.frequency_response(tf, omega_rad_s).complex).ravel()
            phase = np.degrees(np.unwrap(np.angle(response)))
            if name != "compensator":
                phase = phase - np.degrees(omega_rad_s * self.lag.delay_s)
            out[name] = (np.abs(response), phase)
        return out

    def metadata(self) -> dict[str, object]:
        """The `design` table of the filter file.

        Returns
        -------
        dict of str to object
            The method and its criterion in words, the bounds, the peaks, the bandwidths (rad/s) and their ratio,
            the phases (deg) at phase_frequency_rad_s, and when known the lag's delay (plant_delay_s), NRMSE and
            speed range (m/s).
        """
        criterion = (
            "zeros on the lag's poles (omega_z = omega_n, psi = zeta); the largest omega_p with peak |G_lead| <= "
            "max_lead_gain and peak |G_lead G_lag| <= max_cascade_peak_db"
            if self.method == METHOD
            else "the shortest lookahead floor of the clothoid loop (45 deg, 6 dB) among a grid of (omega_z, psi, "
            "omega_p) with peak |G_lead| <= max_lead_gain and peak |G_lead G_lag| <= max_cascade_peak_db"
        )
        out: dict[str, object] = {
            "method": self.method,
            "criterion": criterion,
            "max_lead_gain": self.max_lead_gain,
            "max_cascade_peak_db": self.max_cascade_peak_db,
            "lead_peak_gain": self.lead_peak_gain,
            "cascade_peak_db": self.cascade_peak_db,
            "plant_bandwidth_rad_s": self.plant_bandwidth_rad_s,
            "cascade_bandwidth_rad_s": self.cascade_bandwidth_rad_s,
            "bandwidth_ratio": self.bandwidth_ratio,
            "plant_tracking_bandwidth_rad_s": self.plant_tracking_bandwidth_rad_s,
            "cascade_tracking_bandwidth_rad_s": self.cascade_tracking_bandwidth_rad_s,
            "phase_frequency_rad_s": self.phase_frequency_rad_s,
            "plant_phase_deg": self.plant_phase_deg,
            "cascade_phase_deg": self.cascade_phase_deg,
        }
        if self.lag.delay_s > 0:
            out["plant_delay_s"] = self.lag.delay_s
        if not math.isnan(self.lag.nrmse):
            out["lag_nrmse"] = self.lag.nrmse
        if self.lag.speed_range_mps is not None:
            out["lag_speed_range_mps"] = list(self.lag.speed_range_mps)
        return out

    def summary(self) -> str:
        """The design in one line, for the CLI.

        Returns
        -------
        str
            The filter's parameters (rad/s), its DC gain and peak gain (linear and dB, with the bound), the plant's
            and the cascade's -3 dB and tracking bandwidths (rad/s) and phases (deg).
        """
        p = self.params
        return (
            f"lead filter ({self.method}): omega_z {p.omega_z_rad_s:.3f} rad/s, psi {p.psi:.3f}, omega_p "
            f"{p.omega_p_rad_s:.3f} rad/s, DC gain {p.dc_gain:.6g}; peak gain {self.lead_peak_gain:.3g} "
            f"({20 * math.log10(self.lead_peak_gain):.1f} dB, bound {self.max_lead_gain:g}); -3 dB bandwidth "
            f"{self.plant_bandwidth_rad_s:.3f} -> {self.cascade_bandwidth_rad_s:.3f} rad/s "
            f"(x{self.bandwidth_ratio:.2f}); tracking bandwidth {self.plant_tracking_bandwidth_rad_s:.3f} -> "
            f"{self.cascade_tracking_bandwidth_rad_s:.3f} rad/s; phase at {self.phase_frequency_rad_s:.3f} rad/s "
            f"{self.plant_phase_deg:.1f} -> {self.cascade_phase_deg:.1f} deg"
        )


def _first_crossing(w: np.ndarray, excess: np.ndarray) -> np.ndarray:
    """First frequency (log-interpolated) where `excess` (..., n), negative at w[0], becomes >= 0; w[-1] if never."""
    above = excess >= 0.0
    i = np.where(above.any(axis=-1), np.argmax(above, axis=-1), w.size - 1)
    i = np.maximum(i, 1)
    lo = np.take_along_axis(excess, (i - 1)[..., None], axis=-1)[..., 0]
    hi = np.take_along_axis(excess, i[..., None], axis=-1)[..., 0]
    frac = np.clip(-lo / np.where(hi - lo == 0.0, 1.0, hi - lo), 0.0, 1.0)
    logw = np.log(w)
    return np.exp(logw[i - 1] + frac * (logw[i] - logw[i - 1]))


def tracking_bandwidth(omega_rad_s: np.ndarray, response: np.ndarray) -> np.ndarray:
    """First frequency of the grid omega (increasing, starting well inside the pass band) where |G(jw) - 1| of the
    complex response (..., n) reaches TRACKING_ERROR (log-interpolated).

    Parameters
    ----------
    omega_rad_s : numpy.ndarray of float, rad/s
        The frequency grid, shape (n,), > 0 and increasing, its first frequency inside the pass band.
    response : numpy.ndarray of complex
        G(jw) at the grid, shape (..., n): one response or a stack of them.

    Returns
    -------
    numpy.ndarray of float, rad/s
        The tracking bandwidth of each response, shape (...); the grid's last frequency where the error never
        reaches TRACKING_ERROR.

    Examples
    --------
    A first-order lag 1 / (s + 1): |G - 1| = w / sqrt(1 + w^2) reaches 1 - 10^(-3/20) at 0.305 rad/s.

    >>> import numpy as np
    >>> from tuning.lead_design import tracking_bandwidth
    >>> w = np.geomspace(0.01, 100.0, 2001)
    >>> round(float(tracking_bandwidth(w, 1.0 / (1j * w + 1.0))), 3)
    0.305
    """
    return _first_crossing(omega_rad_s, np.abs(response - 1.0) - TRACKING_ERROR)


class _Problem:
    """The design problem on a frequency grid relative to wn, vectorised over candidate filters."""

    def __init__(self, lag: SteeringLag, max_lead_gain: float, max_cascade_peak_db: float) -> None:
        wn = lag.omega_n_rad_s
        self.wn = wn
        self.w = wn * np.logspace(*_OMEGA_DECADES, _OMEGA_POINTS)
        self.plant = lag.frequency_response(self.w, with_gain=False, with_delay=False)
        self.max_lead = max_lead_gain
        self.max_cascade = 10 ** (max_cascade_peak_db / 20)

    def lead(self, wz: float | np.ndarray, psi: float | np.ndarray, wp: float | np.ndarray) -> np.ndarray:
        """G_lead(jw) for parameter arrays of shape (m,) (or scalars: m = 1), as (m, n)."""
        wz, psi, wp = (np.atleast_1d(np.asarray(v, dtype=float))[:, None] for v in (wz, psi, wp))
        s = 1j * self.w
        return wp**3 * (s * s + 2.0 * psi * wz * s + wz**2) / (wz**2 * (s + wp) ** 3)

    def largest_pole(self, wz: float, psi: float) -> float | None:
        """The largest wp meeting both bounds with wp / wz in [1, 100] and wp <= 1000 rad/s (None if even wp = wz
        breaks them)."""
        lo = math.log(POLE_RATIO_RANGE[0])
        hi = math.log(min(POLE_RATIO_RANGE[1], OMEGA_RANGE_RAD_S[1] / wz)) - 1e-12

        def ok(log_ratio: float) -> bool:
            wp = wz * math.exp(log_ratio)
            cascade_peak = float(np.abs(self.lead(wz, psi, wp) * self.plant).max())
            # the lead's peak refined off the grid (LeadFilterParams.peak_gain), so the bound holds exactly
            return cascade_peak <= self.max_cascade and LeadFilterParams(wz, psi, wp).peak_gain <= self.max_lead

        if not ok(lo):
            return None
        if ok(hi):
            return wz * math.exp(hi)
        for _ in range(_BISECTIONS):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if ok(mid) else (lo, mid)
        return wz * math.exp(lo)


def _cancelling_design(problem: _Problem, lag: SteeringLag) -> tuple[float, float, float]:
    if lag.zeta > PSI_MAX:
        raise WorkbenchInputError(
            f"the lag's zeta = {lag.zeta:.4g} is over {PSI_MAX}, the largest damping of Eq. 6's zeros: a lag this "
            f"overdamped is nearly first-order; check the fit (a fitted delay trades off with the damping: refit "
            f"without --delay) or the data"
        )
    wp = problem.largest_pole(lag.omega_n_rad_s, lag.zeta)
    if wp is None:
        raise WorkbenchInputError("no lead filter meets the bounds; raise max_lead_gain or max_cascade_peak_db")
    return lag.omega_n_rad_s, lag.zeta, wp


def _phase_deg(tf: control.TransferFunction, omega: float) -> float:
    """Phase (deg) of tf at omega, unwrapped continuously from low frequency (so a cascade lagging by more than
    180 degrees reads -200, not +160)."""
    w = omega * np.logspace(-4.0, 0.0, 801)
    response = np.asarray(control.frequency_response(tf, w).complex).ravel()
    return float(np.degrees(np.unwrap(np.angle(response))[-1]))


#: The allowed bound on the peak of |G_lead| (linear) and on the cascade's peak (dB).
MAX_LEAD_GAIN_RANGE = (1.0, 1000.0)
MAX_CASCADE_PEAK_DB_RANGE = (0.0, 20.0)


def check_design_bounds(max_lead_gain: float, max_cascade_peak_db: float | None = None) -> None:
    """Refuse a design bound outside its range (MAX_LEAD_GAIN_RANGE, MAX_CASCADE_PEAK_DB_RANGE), naming it: every
    design checks its bounds here, and a schedule before it identifies anything.

    Parameters
    ----------
    max_lead_gain : float
        Bound on the peak of |G_lead| (linear), within MAX_LEAD_GAIN_RANGE (1-1000).
    max_cascade_peak_db : float or None, dB
        Bound on the peak of |G_lead G_lag|, within MAX_CASCADE_PEAK_DB_RANGE (0-20 dB); None: not checked (the
        margins design has no such bound).

    Raises
    ------
    WorkbenchInputError
        A bound outside its range, or not a finite number.
    """
    require_in_range("max_lead_gain", max_lead_gain, *MAX_LEAD_GAIN_RANGE)
    if max_cascade_peak_db is not None:
        require_in_range("max_cascade_peak_db", max_cascade_peak_db, *MAX_CASCADE_PEAK_DB_RANGE, "dB")


def design_lead(
    lag: SteeringLag,
    max_lead_gain: float = DEFAULT_MAX_LEAD_GAIN,
    max_cascade_peak_db: float = DEFAULT_MAX_CASCADE_PEAK_DB,
    phase_frequency_rad_s: float | None = None,
) -> LeadDesign:
    """Design Eq. 6 for `lag` by the criterion of the module docstring. max_lead_gain: bound on the peak of
    |G_lead| (linear, >= 1); max_cascade_peak_db: bound on the cascade's peak (dB, >= 0); phase_frequency_rad_s:
    where the phases are reported (rad/s; default: the plant's -3 dB bandwidth).

    Parameters
    ----------
    lag : SteeringLag
        The identified lag of Eq. 5 (its zeta at most PSI_MAX = 5, the largest damping of Eq. 6's zeros).
    max_lead_gain : float
        Bound on the peak of |G_lead| (linear), 1-1000.
    max_cascade_peak_db : float, dB
        Bound on the peak of the cascade G_lead G_lag, 0-20 dB.
    phase_frequency_rad_s : float or None, rad/s
        The frequency the phases are reported at, 1e-3 to 1e4 rad/s (None: the plant's -3 dB bandwidth).

    Returns
    -------
    LeadDesign
        The filter (zeros on the lag's poles, the largest pole frequency within the bounds) and what it achieves.

    Raises
    ------
    WorkbenchInputError
        A bound or the phase frequency out of its range; a lag whose zeta is over PSI_MAX; or no filter within the
        bounds (a strongly damped lag under a tight bound).

    Examples
    --------
    >>> from tuning.lead_design import design_lead
    >>> from workbench.vehicles.steering_lag import SteeringLag
    >>> design = design_lead(SteeringLag(omega_n_rad_s=8.0, zeta=0.7))
    >>> design.params.omega_z_rad_s, design.params.psi
    (8.0, 0.7)
    >>> round(design.params.omega_p_rad_s, 1), round(design.lead_peak_gain, 2)
    (31.6, 6.0)
    >>> round(design.bandwidth_ratio, 2)
    1.99
    """
    check_design_bounds(max_lead_gain, max_cascade_peak_db)
    if phase_frequency_rad_s is not None:
        require_in_range("phase_frequency_rad_s", phase_frequency_rad_s, 1e-3, 1e4, "rad/s")
    problem = _Problem(lag, max_lead_gain, max_cascade_peak_db)
    params = LeadFilterParams(*_cancelling_design(problem, lag))
    return _report(params, lag, max_lead_gain, max_cascade_peak_db, phase_frequency_rad_s)


def _report(
    params: LeadFilterParams,
    lag: SteeringLag,
    max_lead_gain: float,
    max_cascade_peak_db: float,
    phase_frequency_rad_s: float | None,
) -> LeadDesign:
    """A LeadDesign for these parameters, measured with python-control independently of any search grid."""
    plant = lag.transfer_function(with_gain=False)
    cascade = params.transfer_function() * plant
    plant_bw = float(control.bandwidth(plant))
    omega = phase_frequency_rad_s if phase_frequency_rad_s is not None else plant_bw
    delay_deg = math.degrees(omega * lag.delay_s)
    fine = lag.omega_n_rad_s * np.logspace(-3.0, 4.0, 7001)
    plant_response = np.asarray(control.frequency_response(plant, fine).complex).ravel()
    cascade_response = np.asarray(control.frequency_response(cascade, fine).complex).ravel()
    return LeadDesign(
        params=params,
        lag=lag,
        method=METHOD,
        max_lead_gain=float(max_lead_gain),
        max_cascade_peak_db=float(max_cascade_peak_db),
        lead_peak_gain=params.peak_gain,
        cascade_peak_db=float(20 * np.log10(max(np.abs(cascade_response).max(), 1.0))),
        plant_bandwidth_rad_s=plant_bw,
        cascade_bandwidth_rad_s=float(control.bandwidth(cascade)),
        plant_tracking_bandwidth_rad_s=float(tracking_bandwidth(fine, plant_response)),
        cascade_tracking_bandwidth_rad_s=float(tracking_bandwidth(fine, cascade_response)),
        phase_frequency_rad_s=float(omega),
        plant_phase_deg=_phase_deg(plant, omega) - delay_deg,
        cascade_phase_deg=_phase_deg(cascade, omega) - delay_deg,
    )


@dataclass(frozen=True)
class ValidationTrace:
    """Figure 9 for one log: the kinematic, lagged, compensated and measured curvatures over time.

    The curvature arrays have one sample per log sample, like `t_s`. The NRMSEs are RMS errors against the kinematic
    curvature, normalised by its range (peak to peak).
    """

    name: str  # the log's name
    t_s: np.ndarray  # s; time from the log's first sample
    kinematic_1pm: np.ndarray  # 1/m; kinematic curvature of the steering-wheel angle
    lagged_1pm: np.ndarray  # 1/m; the kinematic curvature through the lag (Eq. 5)
    compensated_1pm: np.ndarray  # 1/m; Eq. 6 on the steering wheel, then kinematic with lag
    measured_1pm: np.ndarray | None  # 1/m; the log's measured curvature (None: not in the log)
    nrmse_lagged: float  # 1, >= 0; NRMSE of the lagged curvature against the kinematic one
    nrmse_compensated: float  # 1, >= 0; NRMSE of the compensated curvature against the kinematic one


def validate(design: LeadDesign, log: VehicleLog, geometry: VehicleGeometry | SteeringGeometry) -> ValidationTrace:
    """Time-domain check of the design on a log (Figure 9): the compensated curvature should follow the kinematic
    curvature more closely than the lagged one does.

    Parameters
    ----------
    design : LeadDesign
        The filter and the lag it was designed for.
    log : VehicleLog
        A log of the steering-wheel angle; its measured curvature (path or yaw rate) is added when it has one.
    geometry : VehicleGeometry or SteeringGeometry
        The vehicle's wheelbase and steering ratio, which turn the steering-wheel angle into kinematic curvature.

    Returns
    -------
    ValidationTrace
        The curvatures over time and the NRMSEs of the lagged and compensated curvatures against the kinematic one.

    Raises
    ------
    WorkbenchInputError
        The log's measured curvature cannot be computed (see `realised_curvature`).
    """
    lag = design.lag
    kin = kinematic_curvature(log.steer_wheel_rad, geometry)
    lagged = lag.simulate(kin, log.dt_s, with_gain=False)
    lead = design.params.transfer_function()
    filtered_wheel = simulate_unit_dc(lead.num[0][0], lead.den[0][0], log.steer_wheel_rad, log.dt_s)
    compensated = lag.simulate(kinematic_curvature(filtered_wheel, geometry), log.dt_s, with_gain=False)
    measured = None
    if log.has_positions or log.has_yaw_rate:
        measured, _ = realised_curvature(log, LagFitOptions())
    span = float(np.ptp(kin)) or 1.0
    return ValidationTrace(
        name=log.name,
        t_s=log.t_s - log.t_s[0],
        kinematic_1pm=kin,
        lagged_1pm=lagged,
        compensated_1pm=compensated,
        measured_1pm=measured,
        nrmse_lagged=float(np.sqrt(np.mean((lagged - kin) ** 2)) / span),
        nrmse_compensated=float(np.sqrt(np.mean((compensated - kin) ** 2)) / span),
    )


#: The candidate grid of the margins design: zero frequencies (rad/s, log-spaced 1-64 rad/s: the lags identified
#: on the presets' vehicles reach from the truck's 4 rad/s to the cars' 80), zero dampings, pole / zero ratios.
MARGINS_OMEGA_Z_RAD_S = tuple(float(w) for w in np.geomspace(1.0, 64.0, 13))
MARGINS_PSI = (0.5, 0.7, 1.0, 1.4, 2.0)
MARGINS_POLE_RATIOS = (1.5, 2.0, 3.0, 4.0, 6.0)
#: The refinement about the grid's best: factors on omega_z, psi and the pole ratio, and how many rounds.
_REFINE_FACTORS = (2**-0.25, 1.0, 2**0.25)
_REFINE_ROUNDS = 2


@dataclass(frozen=True)
class MarginsDesign:
    """The margins design (`design_lead_for_margins`): the chosen filter and the lookahead floors with and without it.

    A floor is nan when no lookahead in the searched range keeps the margins; the margin_score is the chosen filter's.
    """

    design: LeadDesign  # the chosen design (method "margins")
    floor_m: float  # m; the lookahead floor with the chosen filter (nan: none in the range)
    floor_without_lead_m: float  # m; the lookahead floor without a lead filter (nan: none in the range)
    candidates: int  # >= 0; how many candidate filters met the gain bound
    margin_score: float = math.nan  # the `margin_score` at the longest lookahead (< 1) when floor_m is nan, else nan


def margin_score(margins: Margins, phase_margin_deg: float, gain_margin_db: float) -> float:
    """How well a loop meets the required margins: the least of phase margin / required, gain margin / required
    and -(gain-reduction margin) / required (1: just met; -inf: unstable). The margins design ranks candidates by it
    where none keeps the margins at any lookahead.

    Parameters
    ----------
    margins : Margins
        The loop's margins (`controllers.clothoid.loop_analysis.loop_margins`).
    phase_margin_deg : float, deg
        The required phase margin, >= 0 (0: not required).
    gain_margin_db : float, dB
        The required gain margin both ways, >= 0 (0: not required).

    Returns
    -------
    float
        The least ratio: >= 1 when the margins are met, under 1 when not, -inf for an unstable loop, inf when
        nothing is required.
    """
    if not margins.stable:
        return -math.inf
    ratios = [margins.phase_margin_deg / phase_margin_deg if phase_margin_deg > 0 else math.inf]
    if gain_margin_db > 0:
        ratios += [margins.gain_margin_db / gain_margin_db, -margins.gain_reduction_margin_db / gain_margin_db]
    return min(ratios)


def design_lead_for_margins(
    lags: PlantLags,
    speed_mps: float,
    settings: LoopSettings,
    min_lookahead_m: float = 3.0,
    max_lookahead_m: float = 40.0,
    lookahead_step_m: float = 0.5,
    path_curvatures_1pm: tuple[float, ...] = (0.0,),
    max_lead_gain: float = DEFAULT_MAX_LEAD_GAIN,
    phase_margin_deg: float = REQUIRED_PHASE_MARGIN_DEG,
    gain_margin_db: float = REQUIRED_GAIN_MARGIN_DB,
) -> MarginsDesign:
    """Eq. 6 chosen, among a grid of (omega_z, psi, omega_p) within the gain bound, for the shortest lookahead floor
    of the clothoid controller's loop (`controllers/clothoid/loop_analysis.py`, `lookahead_floor`) at this speed:
    loop shaping on the loop itself rather than on the lag alone. Cancelling the lag's poles (`design_lead`) is the
    right shape for a lag without delay; with the delay `tuning fit-lag --delay` identifies (the loaded truck: 0.25 s
    at 30 km/h), the lag's fitted poles are fast and cancelling them leaves the delay, which limits the loop,
    untouched. Ties go to the smaller peak gain. Only the peak gain is bounded: the cancellation design's bound on
    the cascade's resonance stands in for the loop's damping, which the margins measure here directly.

    The search: the grid MARGINS_OMEGA_Z_RAD_S x MARGINS_PSI x MARGINS_POLE_RATIOS (those within max_lead_gain),
    by increasing peak gain, then _REFINE_ROUNDS rounds about the best (omega_z, psi and the ratio each x
    2^(+-1/4)). A candidate is first checked where it would have to keep the margins to win (the best floor so far,
    or one step shorter if its peak gain is not smaller; 2 loop analyses, one per path curvature): if it misses them
    there, its floor is longer and it is skipped; only the others get the full floor search. 1-5 s a speed.

    Where no candidate keeps the margins at any lookahead up to max_lookahead_m (the loaded truck at 100 km/h just
    does, at 40 m), the floor is nan and the candidate with the best `margin_score` at max_lookahead_m (the least
    bad loop there) is chosen, its score reported. Refused (WorkbenchInputError) when no candidate meets
    max_lead_gain. BLAS runs single-threaded meanwhile (the loop analyses are many small matrix problems, several
    times slower threaded on a small machine).

    Parameters
    ----------
    lags : PlantLags
        The path lag (which the filter is designed for and reported against) and the measured (yaw-rate) lag.
    speed_mps : float, m/s
        The speed the loop is analysed at, 0.1-100 m/s.
    settings : LoopSettings
        The controller's sample time, pose prediction and the other loop settings; its lead filter is replaced by
        each candidate.
    min_lookahead_m : float, m
        The shortest lookahead searched, > 0.
    max_lookahead_m : float, m
        The longest lookahead searched, at least min_lookahead_m.
    lookahead_step_m : float, m
        The step of the lookahead search, > 0.
    path_curvatures_1pm : tuple of float, 1/m
        The path curvatures the margins must hold about (0: a straight); an arc is skipped at lookaheads where
        |curvature| x lookahead reaches 1.8.
    max_lead_gain : float
        Bound on the peak of |G_lead| (linear), 1-1000.
    phase_margin_deg : float, deg
        The required phase margin (default 45 deg).
    gain_margin_db : float, dB
        The required gain margin both ways (default 6 dB).

    Returns
    -------
    MarginsDesign
        The chosen filter's design, its floor and the floor without a filter (m), how many candidates met the gain
        bound, and the margin score where no floor was found.

    Raises
    ------
    WorkbenchInputError
        max_lead_gain or speed_mps out of its range, or no candidate of the grid within max_lead_gain.

    Examples
    --------
    A lag of 8 rad/s, damping 0.7 at 60 km/h, the controller at 50 Hz with 0.2 s of pose prediction (seconds):

    >>> from controllers.clothoid.loop_analysis import LoopSettings, PlantLags
    >>> from tuning.lead_design import design_lead_for_margins
    >>> from workbench.vehicles.steering_lag import SteeringLag
    >>> lag = SteeringLag(omega_n_rad_s=8.0, zeta=0.7)
    >>> settings = LoopSettings(sample_time_s=0.02, prediction_time_s=0.2)
    >>> result = design_lead_for_margins(PlantLags(lag, lag), 60 / 3.6, settings)
    >>> result.floor_m
    12.5
    """
    with threadpool_limits(limits=1, user_api="blas"):
        return _design_lead_for_margins(
            lags, speed_mps, settings, min_lookahead_m, max_lookahead_m, lookahead_step_m, path_curvatures_1pm,
            max_lead_gain, phase_margin_deg, gain_margin_db,
        )  # fmt: skip


def _design_lead_for_margins(
    lags: PlantLags,
    speed_mps: float,
    settings: LoopSettings,
    min_lookahead_m: float,
    max_lookahead_m: float,
    lookahead_step_m: float,
    path_curvatures_1pm: tuple[float, ...],
    max_lead_gain: float,
    phase_margin_deg: float,
    gain_margin_db: float,
) -> MarginsDesign:
    check_design_bounds(max_lead_gain)
    require_in_range("speed_mps", speed_mps, 0.1, 100.0, "m/s")
    floor_args = (speed_mps, min_lookahead_m, max_lookahead_m, lookahead_step_m, path_curvatures_1pm,
                  phase_margin_deg, gain_margin_db)  # fmt: skip

    def meets(params: LeadFilterParams | None, lookahead: float) -> bool:
        lead_settings = replace(settings, lead=params)
        return all(
            loop_margins(lags, lead_settings, float(speed_mps), float(lookahead), kr).meets(
                phase_margin_deg, gain_margin_db
            )
            for kr in path_curvatures_1pm
            if abs(kr) * lookahead < _MAX_CURVATURE_LOOKAHEAD
        )

    def floor_of(params: LeadFilterParams | None) -> float:
        """The floor, nan when max_lookahead_m misses the margins (then no floor in the range has them: the floor
        is the shortest lookahead from which every longer one keeps them)."""
        if not meets(params, max_lookahead_m):
            return math.nan
        return lookahead_floor(lags, replace(settings, lead=params), *floor_args)

    def score(params: LeadFilterParams) -> float:
        lead_settings = replace(settings, lead=params)
        return min(
            margin_score(
                loop_margins(lags, lead_settings, float(speed_mps), float(max_lookahead_m), kr),
                phase_margin_deg,
                gain_margin_db,
            )
            for kr in path_curvatures_1pm
            if abs(kr) * max_lookahead_m < _MAX_CURVATURE_LOOKAHEAD
        )

    best: tuple[float, float, LeadFilterParams] | None = None
    fallback: tuple[float, float, LeadFilterParams] | None = None  # (-score, peak, params) while nothing has a floor
    seen: set[tuple[float, float, float]] = set()
    count = 0

    def consider(wz: float, psi: float, ratio: float) -> None:
        nonlocal best, fallback, count
        key = (round(wz, 9), round(psi, 9), round(ratio, 9))
        if key in seen:
            return
        seen.add(key)
        try:
            params = LeadFilterParams(wz, psi, ratio * wz)
        except WorkbenchInputError:
            return  # outside Eq. 6's ranges (a refinement step past psi 5, a ratio under 1, ...)
        peak = params.peak_gain
        if peak > max_lead_gain:
            return
        count += 1
        if best is not None:
            # it wins only with a shorter floor, or the same floor and a smaller peak gain: missing the margins there
            # means a longer floor (the floor is the shortest lookahead from which every longer one keeps them)
            threshold = best[0] if peak < best[1] else best[0] - lookahead_step_m
            if threshold < min_lookahead_m - 1e-9 or not meets(params, threshold):
                return
        floor = floor_of(params)
        if math.isnan(floor):
            if best is None:
                ranked = (-score(params), peak, params)
                if fallback is None or ranked[:2] < fallback[:2]:
                    fallback = ranked
            return
        if best is None or (floor, peak) < best[:2]:
            best = (floor, peak, params)

    # the grid by increasing peak gain, so that ties are settled early and the larger gains mostly pruned
    grid = []
    for wz, psi, ratio in itertools.product(MARGINS_OMEGA_Z_RAD_S, MARGINS_PSI, MARGINS_POLE_RATIOS):
        grid.append((LeadFilterParams(wz, psi, ratio * wz).peak_gain, wz, psi, ratio))
    for _, wz, psi, ratio in sorted(grid):
        consider(wz, psi, ratio)
    for _ in range(_REFINE_ROUNDS):
        leading = best if best is not None else fallback
        if leading is None:
            break
        centre = leading[2]
        wz0, psi0 = centre.omega_z_rad_s, centre.psi
        ratio0 = centre.omega_p_rad_s / centre.omega_z_rad_s
        for fw in _REFINE_FACTORS:
            for fp in _REFINE_FACTORS:
                for fr in _REFINE_FACTORS:
                    consider(wz0 * fw, psi0 * fp, max(1.0, ratio0 * fr))
    if best is not None:
        floor, params, chosen_score = best[0], best[2], math.nan
    elif fallback is not None:
        floor, params, chosen_score = math.nan, fallback[2], -fallback[0]
    else:
        raise WorkbenchInputError(f"no lead filter of the grid meets max_lead_gain = {max_lead_gain:g}; raise it")
    without = floor_of(None)
    design = replace(_report(params, lags.path, max_lead_gain, math.inf, None), method="margins")
    return MarginsDesign(design, floor, without, count, chosen_score)


__all__ = [
    "LeadDesign",
    "MarginsDesign",
    "ValidationTrace",
    "check_design_bounds",
    "design_lead",
    "design_lead_for_margins",
    "margin_score",
    "tracking_bandwidth",
    "validate",
]
