"""The actuators every model shares: the steering position loop and the realised longitudinal acceleration.

Steering: the road wheels follow the commanded angle as a first-order lag with a rate limit (an electric or
hydraulic power-steering position loop; the rate limit is CommonRoad's steering.v_max, Althoff & Wuersching,
"CommonRoad: Vehicle Models", 2020, the steering constraints):
    delta' = clip((delta_cmd - delta) / tau, -rate_max, rate_max),   delta_cmd = clip(sw_cmd / i_s, +-delta_max).
Longitudinal: the acceleration command is realised without lag (the speed loop is not what this workbench
studies), except that braking at standstill does nothing: the vehicle does not reverse.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def road_wheel_rate(delta_cmd, delta, time_constant, max_rate):  # pragma: no cover - compiled
    """delta' (rad/s): first-order lag towards the command, limited to +-max_rate."""
    return min(max((delta_cmd - delta) / time_constant, -max_rate), max_rate)


@njit(cache=True)
def realised_accel(speed, accel):  # pragma: no cover - compiled
    """Longitudinal acceleration (m/s^2) the powertrain realises: the command, but no braking at standstill."""
    return 0.0 if (speed <= 0.0 and accel < 0.0) else accel
