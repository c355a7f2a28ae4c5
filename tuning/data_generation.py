"""Drive a plant open loop with a steering-wheel profile at a held speed and log what a vehicle log would hold.

The log's columns are the format `tuning fit-lag` reads (`tuning/log_file.py`), and the format a user's own
vehicle log (GPS/IMU plus steering sensor) must be given in: t_s, steer_wheel_deg, speed_mps, x_m, y_m, yaw_rad,
yaw_rate_rad_s, with x, y the rear-axle centre (the plant's reference point) in a local east/north frame.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from tuning.log_file import LOG_COLUMNS
from tuning.maneuvers import Maneuver
from workbench.base.errors import require_in_range
from workbench.simulation.speed_control import PISpeedController
from workbench.vehicles.base import VehicleModel

__all__ = ["LOG_COLUMNS", "generate_open_loop_log"]


def generate_open_loop_log(
    vehicle: VehicleModel,
    maneuver: Maneuver,
    speed_kmh: float,
    sample_rate_hz: float = 100.0,
    plant_rate_hz: float = 1000.0,
) -> pd.DataFrame:
    """Simulate the maneuver at a held speed (PI speed control) and return the log, one row per sample. The plant
    is driven at plant_rate_hz with the profile at each plant step's midpoint, so that the steering between two
    log samples is the profile's, as a real steering wheel's is (not held from one sample to the next, which would
    delay the logged steering by half a sample: the fit interpolates the logged steering linearly)."""
    require_in_range("speed_kmh", speed_kmh, 1e-3, 400.0, "km/h (must be > 0)")
    require_in_range("sample_rate_hz", sample_rate_hz, 1.0, 10_000.0, "Hz")
    substeps = max(1, round(plant_rate_hz / sample_rate_hz))
    dt = 1.0 / sample_rate_hz
    speed_ref = speed_kmh / 3.6
    t = np.arange(0.0, maneuver.duration_s + 0.5 * dt, dt)
    steer = maneuver.steer_wheel_rad(t)
    h = dt / substeps
    fine = maneuver.steer_wheel_rad(t[:, None] + h * (np.arange(substeps) + 0.5)[None, :])
    state = vehicle.initial_state(0.0, 0.0, 0.0, speed_ref)
    speed_control = PISpeedController()
    rows = np.empty((t.size, len(LOG_COLUMNS)))
    for k, (tk, sw) in enumerate(zip(t, steer, strict=True)):
        out = vehicle.outputs(state, sw, 0.0)
        x, y, yaw, vx, vy, yaw_rate = out[:6]
        speed = math.hypot(vx, vy)
        rows[k] = (tk, math.degrees(sw), speed, x, y, yaw, yaw_rate)
        accel = speed_control.step(speed_ref, speed, dt)
        for sw_fine in fine[k].tolist():
            state = vehicle.advance(state, sw_fine, accel, h, 1)
    return pd.DataFrame(rows, columns=list(LOG_COLUMNS))
