"""Synthetic vehicle logs through a known lag, for the tuning tests (imported by them; not a test module)."""

from __future__ import annotations

import control
import numpy as np
import pandas as pd

from tuning.lag_fit import SteeringGeometry
from tuning.maneuvers import Maneuver

#: A car-like steering geometry for synthetic logs.
GEOMETRY = SteeringGeometry(wheelbase_m=5.0, steering_ratio=20.0)


def synthetic_frame(
    kind: str,
    omega_n: float,
    zeta: float,
    *,
    gain: float = 1.0,
    delay_s: float = 0.0,
    speed_mps: float = 10.0,
    yaw_rate_noise: float = 0.0,
    position_noise_m: float = 0.0,
    seed: int = 0,
    duration_s: float = 16.0,
    rate_hz: float = 100.0,
    amplitude_deg: float = 60.0,
) -> pd.DataFrame:
    """A vehicle log whose realised curvature is gain x Eq. 5 (x delay) of the kinematic curvature, computed
    independently of tuning.lag_fit: python-control's forced_response on a 1 kHz grid, the path integrated
    from it, then sampled at rate_hz with Gaussian noise on the yaw rate (rad/s) and the positions (m). The steps
    fall between samples (start 1.005 s), as a real step would."""
    fine = 0.001
    t = np.arange(0.0, duration_s + fine / 2, fine)
    steer = Maneuver(kind, amplitude_deg=amplitude_deg, duration_s=duration_s, start_s=1.005).steer_wheel_rad(t)
    kinematic = np.tan(steer / GEOMETRY.steering_ratio) / GEOMETRY.wheelbase_m
    delayed = np.interp(t - delay_s, t, kinematic)
    lag = control.tf([omega_n**2], [1.0, 2.0 * zeta * omega_n, omega_n**2])
    kappa = gain * np.asarray(control.forced_response(lag, t, delayed).outputs)

    def integral(rate: np.ndarray) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * fine)])

    yaw = integral(kappa * speed_mps)
    x, y = integral(speed_mps * np.cos(yaw)), integral(speed_mps * np.sin(yaw))
    idx = np.arange(0, t.size, round(1.0 / (rate_hz * fine)))
    rng = np.random.default_rng(seed)
    n = idx.size
    return pd.DataFrame(
        {
            "t_s": t[idx],
            "steer_wheel_deg": np.degrees(steer[idx]),
            "speed_mps": np.full(n, speed_mps),
            "x_m": x[idx] + rng.normal(0.0, position_noise_m, n) if position_noise_m else x[idx],
            "y_m": y[idx] + rng.normal(0.0, position_noise_m, n) if position_noise_m else y[idx],
            "yaw_rad": yaw[idx],
            "yaw_rate_rad_s": kappa[idx] * speed_mps + (rng.normal(0.0, yaw_rate_noise, n) if yaw_rate_noise else 0.0),
        }
    )
