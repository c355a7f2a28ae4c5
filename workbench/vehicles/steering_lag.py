"""The identified lag between steering-wheel angle and path curvature (paper, section 5.1, Eq. 5), and its file.

    G_lag(s) = K wn^2 / (s^2 + 2 zeta wn s + wn^2) x exp(-s delay)

Eq. 5 has K = 1; a real vehicle understeers or oversteers, so the realised curvature settles at K times the
kinematic (Ackermann) one. `tuning fit-lag` writes the lag; the clothoid controller's lead filter is designed from
it and the MPC's prediction model takes it as its steering dynamics, so both controllers use the same data.

This module is the lag's one home: `SteeringLag` holds it, within the bounds the fit also searches, in every form
its users need: `transfer_function` (python-control, the delay left out or as a Pade approximant),
`frequency_response` (the lead design's search), `companion_matrices` (the clothoid loop analysis's plant),
`simulate` / `simulate_lag` (first-order hold, the delay a shift of the input; the fit calls it thousands of
times), and `state_derivatives` (written with + - * / only, so that floats, numpy arrays and CasADi symbols all
work; the MPC's kinematic-lag model, the delay a first-order Pade state).

The file is JSON, {"format": "steering-lag/1", "omega_n_rad_s": ..., "zeta": ...}, optional delay_s (default 0),
steady_state_gain (K, default 1), nrmse (fit quality: RMS error over the range of the measured curvature),
speed_range_mps (the speeds the data covered) and source (free text). Any other key is an error, so that a
misspelt key is not silently ignored.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import KW_ONLY, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.base.input_files import read_json

if TYPE_CHECKING:  # python-control and scipy.signal are imported where used: they take long to import
    import control

FORMAT_TAG = "steering-lag/1"
#: Bounds of Eq. 5's parameters: what a SteeringLag (and so a steering-lag file) accepts, and what `tuning fit-lag`
#: searches within. omega_n (rad/s), zeta, the pure delay (s) and the steady-state gain K.
OMEGA_N_BOUNDS = (0.05, 200.0)
ZETA_BOUNDS = (0.05, 10.0)
DELAY_BOUNDS = (0.0, 2.0)
GAIN_BOUNDS = (0.05, 20.0)
_REQUIRED = ("format", "omega_n_rad_s", "zeta")
_OPTIONAL = ("delay_s", "steady_state_gain", "nrmse", "speed_range_mps", "source")


@dataclass(frozen=True)
class SteeringLag:
    """Eq. 5: omega_n_rad_s (natural frequency, OMEGA_N_BOUNDS: 0.05-200 rad/s), zeta (damping, ZETA_BOUNDS:
    0.05-10), delay_s (pure delay, DELAY_BOUNDS: 0-2 s), steady_state_gain (K: realised / kinematic curvature in a
    steady turn, GAIN_BOUNDS: 0.05-20; Eq. 5 has 1); nrmse and speed_range_mps describe the identification (NaN /
    None when unknown)."""

    omega_n_rad_s: float
    zeta: float
    delay_s: float = 0.0
    _: KW_ONLY
    steady_state_gain: float = 1.0
    nrmse: float = math.nan
    speed_range_mps: tuple[float, float] | None = None
    source: str = ""

    def __post_init__(self) -> None:
        require_in_range("omega_n_rad_s", self.omega_n_rad_s, *OMEGA_N_BOUNDS, "rad/s")
        require_in_range("zeta", self.zeta, *ZETA_BOUNDS)
        require_in_range("delay_s", self.delay_s, *DELAY_BOUNDS, "s")
        require_in_range("steady_state_gain", self.steady_state_gain, *GAIN_BOUNDS)
        if not (math.isnan(self.nrmse) or self.nrmse >= 0.0):
            raise WorkbenchInputError(f"nrmse must be >= 0 (or NaN when unknown); got {self.nrmse!r}")
        if self.speed_range_mps is not None:
            low, high = self.speed_range_mps
            require_in_range("speed_range_mps[0]", low, 0.0, 150.0, "m/s")
            require_in_range("speed_range_mps[1]", high, low, 150.0, "m/s")
            object.__setattr__(self, "speed_range_mps", (float(low), float(high)))
        for name in ("omega_n_rad_s", "zeta", "delay_s", "steady_state_gain", "nrmse"):
            object.__setattr__(self, name, float(getattr(self, name)))

    @property
    def group_delay_s(self) -> float:
        """The low-frequency delay of Eq. 5 (s), -d(phase)/d(omega) at omega = 0: the pure delay plus 2 zeta / wn."""
        return self.delay_s + 2.0 * self.zeta / self.omega_n_rad_s

    def transfer_function(self, *, with_gain: bool = True, pade_order: int | None = None) -> control.TransferFunction:
        """Eq. 5 as a python-control transfer function: K wn^2 / (s^2 + 2 zeta wn s + wn^2) (wn^2 / (...) with
        with_gain=False). The pure delay is left out with pade_order None (the caller accounts for it, e.g. as the
        phase -omega delay_s, as the lead design does), else it is the Pade approximant of that order (1: what the
        MPC's prediction model integrates)."""
        import control

        wn, zeta = self.omega_n_rad_s, self.zeta
        num = [self.steady_state_gain * wn**2] if with_gain else [wn**2]
        tf = control.tf(num, [1.0, 2.0 * zeta * wn, wn**2])
        if pade_order is None or self.delay_s == 0.0:
            return tf
        if not (isinstance(pade_order, int) and 1 <= pade_order <= 10):
            raise WorkbenchInputError(f"pade_order must be None or an integer in [1, 10]; got {pade_order!r}")
        return tf * control.tf(*control.pade(self.delay_s, pade_order))

    def frequency_response(
        self, omega_rad_s: np.ndarray, *, with_gain: bool = True, with_delay: bool = True
    ) -> np.ndarray:
        """G_lag(j omega) (complex, the shape of omega) evaluated directly: K wn^2 / (s^2 + 2 zeta wn s + wn^2)
        exp(-s delay), without K (with_gain=False) or the delay (with_delay=False) if asked."""
        wn, zeta = self.omega_n_rad_s, self.zeta
        s = 1j * np.asarray(omega_rad_s, dtype=float)
        response = wn**2 / (s * s + 2.0 * zeta * wn * s + wn**2)
        if with_gain:
            response = self.steady_state_gain * response
        if with_delay and self.delay_s > 0.0:
            response = response * np.exp(-s * self.delay_s)
        return response

    def companion_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """(A (2, 2), B (2,)) of Eq. 5 with unit gain and without its delay in the states [y, y']:
        y' = y', y'' = -wn^2 y - 2 zeta wn y' + wn^2 u (the output is y; K and the delay are the caller's)."""
        wn, zeta = self.omega_n_rad_s, self.zeta
        return np.array([[0.0, 1.0], [-(wn**2), -2.0 * zeta * wn]]), np.array([0.0, wn**2])

    def simulate(self, u: np.ndarray, dt_s: float, *, with_gain: bool = True) -> np.ndarray:
        """The response to u sampled every dt_s (simulate_lag), with K unless with_gain=False, and the delay."""
        gain = self.steady_state_gain if with_gain else 1.0
        return simulate_lag(u, dt_s, self.omega_n_rad_s, self.zeta, gain, self.delay_s)

    @property
    def ode_state_count(self) -> int:
        """How many states `state_derivatives` takes: y and y', and the Pade state when there is a delay."""
        return 3 if self.delay_s > 0.0 else 2

    def state_derivatives(self, states: Sequence[Any], lag_input: Any) -> list[Any]:
        """The ODE of Eq. 5 without its gain (scale lag_input by K for it): d/dt of states [y, y'] (and w, the
        state of the delay's first-order Pade approximant exp(-s T) ~ (1 - s T / 2) / (1 + s T / 2), when delay_s >
        0) driven by lag_input:
            w' = 2 / T (lag_input - w),  delayed input = 2 w - lag_input,
            y'' = wn^2 (delayed input - y) - 2 zeta wn y'.
        Only + - * / on the arguments: floats, numpy arrays and CasADi symbols all work."""
        wn, zeta = self.omega_n_rad_s, self.zeta
        output, output_rate = states[0], states[1]
        if self.delay_s > 0.0:
            w = states[2]
            delayed = 2.0 * w - lag_input
            w_dot = 2.0 / self.delay_s * (lag_input - w)
            return [output_rate, wn * wn * (delayed - output) - 2.0 * zeta * wn * output_rate, w_dot]
        return [output_rate, wn * wn * (lag_input - output) - 2.0 * zeta * wn * output_rate]

    @property
    def fastest_rate_per_s(self) -> float:
        """The fastest decay rate (1/s, -the least real part of an eigenvalue) of `state_derivatives`' ODE:
        wn (zeta + sqrt(zeta^2 - 1)) for an overdamped lag, zeta wn for an underdamped one (whose |eigenvalue| is
        wn, larger), and 2 / delay_s for the Pade state. The MPC sizes its RK4 sub-steps with it."""
        fastest = self.omega_n_rad_s * (self.zeta + math.sqrt(max(self.zeta**2 - 1.0, 0.0)))
        if self.delay_s > 0.0:
            fastest = max(fastest, 2.0 / self.delay_s)
        return fastest

    def to_dict(self) -> dict:
        out: dict = {
            "format": FORMAT_TAG,
            "omega_n_rad_s": self.omega_n_rad_s,
            "zeta": self.zeta,
            "delay_s": self.delay_s,
            "steady_state_gain": self.steady_state_gain,
        }
        if not math.isnan(self.nrmse):
            out["nrmse"] = self.nrmse
        if self.speed_range_mps is not None:
            out["speed_range_mps"] = list(self.speed_range_mps)
        if self.source:
            out["source"] = self.source
        return out


def discrete_coefficients(omega_n: float, zeta: float, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """(b, a) of Eq. 5 (unit gain, no delay) discretised with a first-order hold at dt_s: scipy's cont2discrete
    "foh" formulas, written out for the 2-state realisation x1' = x2, x2' = -wn^2 x1 - 2 zeta wn x2 + u,
    y = wn^2 x1 (the fit calls this thousands of times; cont2discrete on a transfer function takes about five
    times longer)."""
    from scipy import linalg

    a = np.array([[0.0, 1.0], [-(omega_n**2), -2.0 * zeta * omega_n]])
    em = np.zeros((4, 4))
    em[:2, :2] = a * dt_s
    em[1, 2] = dt_s
    em[2, 3] = 1.0
    ms = linalg.expm(em)
    ad, ms12, ms13 = ms[:2, :2], ms[:2, 2], ms[:2, 3]
    bd = ms12 - ms13 + ad @ ms13
    c = np.array([omega_n**2, 0.0])
    dd = float(c @ ms13)
    # transfer function C adj(zI - Ad) Bd / det(zI - Ad) + Dd, with adj(zI - Ad) = z I + [[-a22, a12], [a21, -a11]]
    trace, det = ad[0, 0] + ad[1, 1], ad[0, 0] * ad[1, 1] - ad[0, 1] * ad[1, 0]
    adj = np.array([[-ad[1, 1], ad[0, 1]], [ad[1, 0], -ad[0, 0]]])
    den = np.array([1.0, -trace, det])
    num = dd * den + np.array([0.0, float(c @ bd), float(c @ adj @ bd)])
    return num, den


def simulate_lag(
    u: np.ndarray, dt_s: float, omega_n: float, zeta: float, gain: float = 1.0, delay_s: float = 0.0
) -> np.ndarray:
    """K G_lag(s) e^(-s delay) (Eq. 5) driven by u sampled every dt_s, from the steady state of u[0] (first-order
    hold: u linear between samples, as in scipy.signal.lsim and python-control's forced_response); the delay
    shifts u by linear interpolation, holding u[0] before the start. Bare numbers (not checked against the
    bounds), as the fit calls it; `SteeringLag.simulate` is the same for a lag."""
    from scipy import signal

    u = np.asarray(u, dtype=float)
    if delay_s > 0.0:
        t = np.arange(u.size) * dt_s
        u = np.interp(t - delay_s, t, u)
    b, a = discrete_coefficients(omega_n, zeta, dt_s)
    return gain * signal.lfilter(b, a, u, zi=signal.lfilter_zi(b, a) * u[0])[0]


def write_lag_file(lag: SteeringLag, path: str | Path) -> Path:
    """Write `lag` as JSON; returns the path."""
    path = Path(path)
    path.write_text(json.dumps(lag.to_dict(), indent=2) + "\n")
    return path


def read_lag_file(path: str | Path) -> SteeringLag:
    """Read a steering-lag file, with an error naming the file and the offending key or value."""
    path = Path(path)
    data = read_json(path, f"steering-lag file {str(path)!r}")
    if not isinstance(data, dict):
        raise WorkbenchInputError(f"steering-lag file {str(path)!r} must hold a JSON object; got {type(data).__name__}")
    missing = [key for key in _REQUIRED if key not in data]
    unknown = sorted(set(data) - set(_REQUIRED) - set(_OPTIONAL))
    if missing or unknown:
        raise WorkbenchInputError(
            f"steering-lag file {str(path)!r}: missing keys {missing}, unknown keys {unknown}; "
            f"required {list(_REQUIRED)}, optional {list(_OPTIONAL)}"
        )
    if data["format"] != FORMAT_TAG:
        raise WorkbenchInputError(
            f"steering-lag file {str(path)!r}: format must be {FORMAT_TAG!r}; got {data['format']!r}"
        )
    speed_range = data.get("speed_range_mps")
    if speed_range is not None and (not isinstance(speed_range, list) or len(speed_range) != 2):
        raise WorkbenchInputError(
            f"steering-lag file {str(path)!r}: speed_range_mps must be [low, high]; got {speed_range!r}"
        )
    try:
        return SteeringLag(
            omega_n_rad_s=data["omega_n_rad_s"],
            zeta=data["zeta"],
            delay_s=data.get("delay_s", 0.0),
            steady_state_gain=data.get("steady_state_gain", 1.0),
            nrmse=data.get("nrmse", math.nan),
            speed_range_mps=tuple(speed_range) if speed_range is not None else None,
            source=str(data.get("source", "")),
        )
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"steering-lag file {str(path)!r}: {exc}") from None
