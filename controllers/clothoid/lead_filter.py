"""The lead filter of Shaju, Southward & Ahmadian (2024), section 5.2, and its discretisation at the controller rate.

The lag between steering-wheel angle and path curvature is modelled by Eq. 5,

    G_lag(s) = wn^2 / (s^2 + 2 zeta wn s + wn^2),

and compensated by the feed-forward lead filter of Eq. 6, one complex zero pair and three real poles:

    G_lead(s) = wp^3 (s^2 + 2 psi wz s + wz^2) / (wz^2 (s + wp)^3),     G_lead(0) = 1.

With wz = wn and psi = zeta the zeros cancel the lag's poles and the cascade is wp^3 / (s + wp)^3.

`DiscreteLeadFilter` runs Eq. 6 once per controller step. It uses the state-space realisation "three first-order
lags wp/(s + wp) in a chain, output = the zero polynomial applied to the last one": every state settles at the input,
so the steady state is known exactly and the DC gain is 1 by structure, and the Tustin (bilinear) discretisation
of it is lower-triangular, with its poles on the diagonal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive, value_text

if TYPE_CHECKING:  # python-control and SciPy's signal and optimize are imported where used: they take ~0.9 s
    import control

#: Sane ranges of the corner frequencies (rad/s) and of the zero damping psi (exclusive of 0).
OMEGA_RANGE_RAD_S = (0.01, 1000.0)
PSI_MAX = 5.0
#: Allowed wp / wz: at least 1 for Eq. 6 to lead (advance phase); at most 100, where the peak gain, about
#: 0.385 (wp / wz)^2 for wp >> wz, already reaches 72 dB.
POLE_RATIO_RANGE = (1.0, 100.0)


@dataclass(frozen=True)
class LeadFilterParams:
    """Parameters of Eq. 6: a complex zero pair (wz, psi) and a triple real pole (wp), with wp / wz in [1, 100]:
    the poles at or above the zeros, so that the filter leads, and at most 72 dB of peak gain."""

    omega_z_rad_s: float  # wz, the zero pair's natural frequency (rad/s), in [0.01, 1000]
    psi: float  # the zero pair's damping (dimensionless), in (0, 5]
    omega_p_rad_s: float  # wp, the triple pole's frequency (rad/s), in [0.01, 1000], with wp / wz in [1, 100]

    def __post_init__(self) -> None:
        require_in_range("omega_z_rad_s", self.omega_z_rad_s, *OMEGA_RANGE_RAD_S, "rad/s")
        require_in_range("psi", self.psi, 0.0, PSI_MAX, low_open=True)
        require_in_range("omega_p_rad_s", self.omega_p_rad_s, *OMEGA_RANGE_RAD_S, "rad/s")
        ratio = self.omega_p_rad_s / self.omega_z_rad_s
        low, high = POLE_RATIO_RANGE
        if not low * (1 - 1e-12) <= ratio <= high * (1 + 1e-12):  # slack for interpolated schedules
            raise WorkbenchInputError(
                f"omega_p_rad_s / omega_z_rad_s must be in [{low}, {high}] (poles at or above the zeros, "
                f"at most 72 dB of peak gain); got {value_text(self.omega_p_rad_s)} / {value_text(self.omega_z_rad_s)} "
                f"= {ratio:.6g}"
            )
        for name in ("omega_z_rad_s", "psi", "omega_p_rad_s"):  # JSON/TOML integers become floats
            object.__setattr__(self, name, float(getattr(self, name)))

    @classmethod
    def from_lag(cls, omega_n_rad_s: float, zeta: float, pole_ratio: float = 3.0) -> LeadFilterParams:
        """The default design: the zeros cancel the poles of the lag (Eq. 5: wz = wn, psi = zeta) and the triple
        pole sits at pole_ratio x wn (pole_ratio in [1, 100]). The cascade is then wp^3 / (s + wp)^3, a lag
        pole_ratio times faster. `tuning.lead_design.design_lead` chooses the pole by loop shaping instead (the
        largest wp within bounds on the peak gain and the cascade's resonance); this is the simple starting point.

        Parameters
        ----------
        omega_n_rad_s : float, rad/s
            The lag's natural frequency wn, 0.01-1000 rad/s.
        zeta : float
            The lag's damping, in (0, 5].
        pole_ratio : float
            wp / wn, 1-100.

        Returns
        -------
        LeadFilterParams
            wz = omega_n_rad_s, psi = zeta, wp = pole_ratio x omega_n_rad_s.

        Raises
        ------
        WorkbenchInputError
            An argument out of its range, or wp above 1000 rad/s.

        Examples
        --------
        >>> from controllers.clothoid import LeadFilterParams
        >>> LeadFilterParams.from_lag(4.44, 0.8)
        LeadFilterParams(omega_z_rad_s=4.44, psi=0.8, omega_p_rad_s=13.32)
        """
        require_in_range("omega_n_rad_s", omega_n_rad_s, *OMEGA_RANGE_RAD_S, "rad/s")
        require_in_range("zeta", zeta, 0.0, PSI_MAX, low_open=True)
        require_in_range("pole_ratio", pole_ratio, *POLE_RATIO_RANGE)
        return cls(omega_n_rad_s, zeta, pole_ratio * omega_n_rad_s)

    def transfer_function(self) -> control.TransferFunction:
        """Eq. 6 as a python-control transfer function (input and output in the same unit, e.g. rad).

        Returns
        -------
        control.TransferFunction
            wp^3 (s^2 + 2 psi wz s + wz^2) / (wz^2 (s + wp)^3), continuous time.
        """
        import control

        wz, psi, wp = self.omega_z_rad_s, self.psi, self.omega_p_rad_s
        gain = wp**3 / wz**2
        return control.tf([gain, gain * 2 * psi * wz, gain * wz**2], [1.0, 3 * wp, 3 * wp**2, wp**3])

    @property
    def dc_gain(self) -> float:
        """G_lead(0), from the coefficients of Eq. 6 (1 by construction, up to rounding)."""
        tf = self.transfer_function()
        return float(tf.num[0][0][-1] / tf.den[0][0][-1])

    def gain_at(self, omega_rad_s: np.ndarray | float) -> np.ndarray:
        """|G_lead(j omega)| of Eq. 6 at the given frequencies (rad/s).

        Parameters
        ----------
        omega_rad_s : float or array_like of float, rad/s
            The frequencies, >= 0, any shape.

        Returns
        -------
        numpy.ndarray of float
            The gain (linear) at each frequency, in the shape of ``omega_rad_s``: 1 at 0 rad/s.

        Examples
        --------
        >>> from controllers.clothoid import LeadFilterParams
        >>> LeadFilterParams.from_lag(4.44, 0.8).gain_at([0.0, 4.44, 100.0]).round(3).tolist()
        [1.0, 1.366, 1.168]
        """
        w2 = np.square(np.asarray(omega_rad_s, dtype=float))
        wz, psi, wp = self.omega_z_rad_s, self.psi, self.omega_p_rad_s
        zeros = np.hypot(wz**2 - w2, 2 * psi * wz * np.sqrt(w2))
        return wp**3 * zeros / (wz**2 * (w2 + wp**2) ** 1.5)

    @property
    def peak_gain(self) -> float:
        """The largest |G_lead(j omega)| over frequency (>= 1, the DC gain), found numerically: a log grid from
        wz / 1000 to 1000 wp, refined by a bounded scalar search. (|G_lead| itself falls as wp^3 / (wz^2 omega) at
        high frequency, so the peak is the useful measure of the filter's noise amplification.)"""
        log_w = np.linspace(math.log(self.omega_z_rad_s) - 7.0, math.log(self.omega_p_rad_s) + 7.0, 1401)
        gains = self.gain_at(np.exp(log_w))
        i = int(np.argmax(gains))
        if gains[i] <= 1.0:
            return 1.0
        lo, hi = log_w[max(i - 1, 0)], log_w[min(i + 1, len(log_w) - 1)]
        from scipy import optimize

        res = optimize.minimize_scalar(
            lambda x: -float(self.gain_at(math.exp(x))), bounds=(lo, hi), method="bounded", options={"xatol": 1e-10}
        )
        return max(float(gains[i]), -float(res.fun))

    @property
    def group_delay_s(self) -> float:
        """The low-frequency delay of Eq. 6 (s), -d(phase)/d(omega) at omega = 0: 3 / wp - 2 psi / wz (negative: the
        filter advances slow signals by that much)."""
        return 3.0 / self.omega_p_rad_s - 2.0 * self.psi / self.omega_z_rad_s

    @property
    def high_frequency_gain(self) -> float:
        """Alias of `peak_gain`: the filter's largest amplification of high-frequency content."""
        return self.peak_gain


@njit(cache=True)
def lead_step(coefficients: np.ndarray, x: np.ndarray, u: float) -> float:  # pragma: no cover - compiled
    """One sample of the discretised Eq. 6 (`DiscreteLeadFilter`): advance the state x (3) with input u in place and
    return the output y[k] = C x[k] + D u[k]. coefficients: `DiscreteLeadFilter.coefficients`, the difference form
    that is exact at steady state."""
    b1, a21, b2, a31, a32, b3, c1, c2, d = (
        coefficients[0], coefficients[1], coefficients[2], coefficients[3], coefficients[4], coefficients[5],
        coefficients[6], coefficients[7], coefficients[8],
    )  # fmt: skip
    x1, x2, x3 = x[0], x[1], x[2]
    x[0] = x1 + b1 * (u - x1)
    x[1] = x2 + a21 * (x1 - x2) + b2 * (u - x2)
    x[2] = x3 + a31 * (x1 - x3) + a32 * (x2 - x3) + b3 * (u - x3)
    return x3 + c1 * (x1 - x3) + c2 * (x2 - x3) + d * (u - x3)


class DiscreteLeadFilter:
    """Eq. 6 discretised by Tustin (bilinear) at the controller's sample time dt_s (s), optionally pre-warped so
    that the response matches the continuous filter exactly at prewarp_rad_s (which must lie below the Nyquist
    frequency pi / dt_s). Start with `reset(u0)`; then `step(u)` once per sample returns the filtered value.

    The discrete system x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k] is kept as Python floats; `state_space`
    returns it as tuples, `poles` its poles.

    Parameters
    ----------
    params : LeadFilterParams
        The continuous filter of Eq. 6.
    dt_s : float, s
        The controller's sample time, > 0.
    prewarp_rad_s : float or None, rad/s
        The frequency where the discrete response matches the continuous one, in [0, pi / dt_s) (None or 0: plain
        Tustin).

    Raises
    ------
    WorkbenchInputError
        dt_s not > 0, prewarp_rad_s out of its range, or a discretisation that is unstable or inaccurate at this
        sample time.
    """

    __slots__ = ("_coeffs", "_x", "dt_s", "params", "poles", "prewarp_rad_s", "state_space")

    def __init__(self, params: LeadFilterParams, dt_s: float, prewarp_rad_s: float | None = None) -> None:
        require_positive("dt_s", dt_s)
        self.params, self.dt_s, self.prewarp_rad_s = params, float(dt_s), prewarp_rad_s
        # Tustin with pre-warping at w0 is the bilinear map with the step 2 tan(w0 dt / 2) / w0 in place of dt.
        step = self.dt_s
        if prewarp_rad_s is not None:
            nyquist = math.pi / self.dt_s
            if (
                isinstance(prewarp_rad_s, bool)
                or not isinstance(prewarp_rad_s, int | float)
                or not (0 <= prewarp_rad_s < nyquist)
            ):
                raise WorkbenchInputError(
                    f"prewarp_rad_s must be in [0, {nyquist:.6g}) rad/s (below the Nyquist frequency pi / dt_s); "
                    f"got {value_text(prewarp_rad_s)}"
                )
            if prewarp_rad_s > 0:
                step = 2.0 * math.tan(prewarp_rad_s * self.dt_s / 2.0) / prewarp_rad_s
        # Continuous realisation of Eq. 6: x1' = wp (u - x1), x2' = wp (x1 - x2), x3' = wp (x2 - x3), so
        # x3 = (wp / (s + wp))^3 u, s x3 = wp (x2 - x3), s^2 x3 = wp^2 (x1 - 2 x2 + x3); y = (s^2 + 2 psi wz s + wz^2)
        # x3 / wz^2. The output weights sum to 1 (DC gain 1) and D = 0 (Eq. 6 is strictly proper).
        wz, psi, wp = params.omega_z_rad_s, params.psi, params.omega_p_rad_s
        r = wp / wz
        a_c = wp * np.array([[-1.0, 0.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, -1.0]])
        b_c = np.array([[wp], [0.0], [0.0]])
        c_c = np.array([[r * r, -2.0 * r * r + 2.0 * psi * r, r * r - 2.0 * psi * r + 1.0]])
        from scipy import signal

        a, b, c, d, _ = signal.cont2discrete((a_c, b_c, c_c, np.zeros((1, 1))), step, method="bilinear")
        self.poles: np.ndarray = np.linalg.eigvals(a)
        if not (np.all(np.isfinite(a)) and np.all(np.abs(self.poles) < 1.0)):
            raise WorkbenchInputError(
                f"the lead filter discretised at dt_s = {value_text(dt_s)} s is unstable: pole magnitudes "
                f"{np.abs(self.poles).round(9).tolist()} (all must be < 1)"
            )
        # Steady state x = (u, u, u) and DC gain 1 mean each row of [A B] and [C D] sums to 1, and A is lower
        # triangular; step() uses that form (differences to x_i), exact at steady state and free of cancellation.
        rows = [(*a[i, :i], b[i, 0]) for i in range(3)]
        sums = np.append(a.sum(axis=1) + b[:, 0], c.sum() + d.sum())
        if a[0, 1] != 0 or a[0, 2] != 0 or a[1, 2] != 0 or np.abs(sums - 1.0).max() > 1e-9:
            raise WorkbenchInputError(
                f"the lead filter cannot be discretised accurately at dt_s = {value_text(dt_s)} s: A = {a.tolist()}, "
                f"row sums of [A B] and [C D] {sums.tolist()} (must be 1)"
            )
        self._coeffs = np.array([*rows[0], *rows[1], *rows[2], c[0, 0], c[0, 1], d[0, 0]], dtype=float)
        self._x = np.zeros(3)
        # The realisation step() implements: each diagonal entry of A and the last weight of C are what makes its
        # row sum to 1, so the steady state and the DC gain of 1 are exact, not subject to cont2discrete's rounding.
        b1, a21, b2, a31, a32, b3, c1, c2, d0 = self._coeffs.tolist()
        self.state_space: tuple[tuple[tuple[float, ...], ...], tuple[float, ...], tuple[float, ...], float] = (
            ((1.0 - b1, 0.0, 0.0), (a21, 1.0 - a21 - b2, 0.0), (a31, a32, 1.0 - a31 - a32 - b3)),
            (b1, b2, b3),
            (c1, c2, 1.0 - c1 - c2 - d0),
            d0,
        )

    @property
    def dc_gain(self) -> float:
        """Steady-state gain of the filter step() implements, C (I - A)^-1 B + D (1 up to rounding).

        I - A is formed from the difference-form coefficients directly: 1 - A_ii would lose the digits of the
        poles' distance from 1 (about wp dt), which the output weights (about (wp / wz)^2) then amplify."""
        b1, a21, b2, a31, a32, b3, c1, c2, d = self._coeffs.tolist()
        i_minus_a = np.array([[b1, 0.0, 0.0], [-a21, a21 + b2, 0.0], [-a31, -a32, a31 + a32 + b3]])
        x1, x2, x3 = np.linalg.solve(i_minus_a, np.array([b1, b2, b3]))
        return float(x3 + c1 * (x1 - x3) + c2 * (x2 - x3) + d * (1.0 - x3))

    @property
    def state(self) -> tuple[float, float, float]:
        """The three states of the lag chain (in the input's unit): all equal to the input at steady state."""
        x1, x2, x3 = self._x.tolist()
        return x1, x2, x3

    @property
    def coefficients(self) -> np.ndarray:
        """The nine numbers `lead_step` runs on (b1, a21, b2, a31, a32, b3, c1, c2, d), a copy."""
        return self._coeffs.copy()

    def reset(self, u0: float = 0.0) -> None:
        """Steady state for the constant input u0: the output is u0 until the input changes. (Every state of the
        lag chain settles at the input; the bilinear map keeps the state coordinates.)

        Parameters
        ----------
        u0 : float
            The constant input the filter has settled at, in the input's unit (e.g. rad of steering wheel).
        """
        u0 = float(u0)
        self._x[:] = u0

    def step(self, u: float) -> float:
        """Advance one sample with input u; return the output y[k] = C x[k] + D u[k] (`lead_step`).

        Parameters
        ----------
        u : float
            The input at this sample, in any unit (the output has the same).

        Returns
        -------
        float
            The filtered value, in the input's unit.

        Examples
        --------
        A unit step into the default lead filter at 50 Hz: the lead overshoots the input while it advances it.

        >>> from controllers.clothoid import DiscreteLeadFilter, LeadFilterParams
        >>> lead = DiscreteLeadFilter(LeadFilterParams.from_lag(4.44, 0.8), dt_s=0.02)
        >>> lead.reset(0.0)
        >>> [round(lead.step(1.0), 3) for _ in range(3)]
        [0.884, 2.152, 2.633]
        """
        return lead_step(self._coeffs, self._x, float(u))
