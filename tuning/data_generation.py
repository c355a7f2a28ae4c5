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
from tuning.maneuvers import Braking, Maneuver
from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive, value_text
from workbench.simulation.speed_control import PISpeedController
from workbench.vehicles.base import VehicleModel

__all__ = ["LOG_COLUMNS", "MAX_LOG_SAMPLES", "MAX_PLANT_STEPS", "check_log_size", "generate_open_loop_log"]

#: Rate (Hz) the plant is integrated at while a log is generated.
PLANT_RATE_HZ = 1000.0
#: Fewest rows (samples) of a log: what `log_file.VehicleLog` reads.
MIN_LOG_SAMPLES = 2
#: Most rows (samples) a generated log may hold: 7 columns of 8 bytes, 112 MB in memory (about 5.6 h at 100 Hz).
MAX_LOG_SAMPLES = 2_000_000
#: Most plant steps (log samples x plant steps per sample) a generated log may take: the steering profile is
#: evaluated at each (8 bytes a step, 80 MB), and they are integrated one by one, about 15 us a step on the
#: truck (10 000 s of driving at 1 kHz: a few minutes).
MAX_PLANT_STEPS = 10_000_000


def _substeps(sample_rate_hz: float, plant_rate_hz: float) -> int:
    """Plant steps per log sample: the plant rate over the sample rate, rounded, at least one."""
    return max(1, round(plant_rate_hz / sample_rate_hz))


def _planned_steps(duration_s: float, sample_rate_hz: float, plant_rate_hz: float) -> tuple[float, float]:
    """(log samples, plant steps) of a log of duration_s sampled at sample_rate_hz (`generate_open_loop_log`'s
    grid: 0 to duration_s inclusive, plant_rate_hz / sample_rate_hz plant steps a sample, at least one), as floats:
    whole numbers, or inf for a duration too long to count in integers."""
    product = duration_s * sample_rate_hz
    samples = math.floor(product + 0.5) + 1.0 if math.isfinite(product) else math.inf
    return samples, samples * _substeps(sample_rate_hz, plant_rate_hz)


def _count(n: float) -> str:
    """A count as a message shows it: whole with grouped thousands, in powers of ten from 1e15 on."""
    if not math.isfinite(n):
        return "over 1e+308"
    return f"{n:,.0f}" if n < 1e15 else f"{n:.3g}"


def check_log_size(
    duration_s: float,
    sample_rate_hz: float,
    plant_rate_hz: float = PLANT_RATE_HZ,
    names: tuple[str, str] = ("duration_s", "sample_rate_hz"),
) -> None:
    """Refuse, before anything is allocated, a log longer than MAX_LOG_SAMPLES samples or MAX_PLANT_STEPS plant
    steps: the planned samples, steps and memory, the longest duration allowed at this rate, and the options
    (`names`: how the caller calls duration_s and sample_rate_hz) that shorten it."""
    duration_name, rate_name = names
    require_positive(duration_name, duration_s)
    require_in_range(rate_name, sample_rate_hz, 1.0, 10_000.0, "Hz")
    samples, steps = _planned_steps(duration_s, sample_rate_hz, plant_rate_hz)
    if samples < MIN_LOG_SAMPLES:
        raise WorkbenchInputError(
            f"{duration_name} {value_text(duration_s)} s at {rate_name} {value_text(sample_rate_hz)} Hz gives "
            f"{samples:.0f} log sample; a log needs at least {MIN_LOG_SAMPLES}: {duration_name} at least "
            f"{(MIN_LOG_SAMPLES - 1) / sample_rate_hz:g} s"
        )
    if samples <= MAX_LOG_SAMPLES and steps <= MAX_PLANT_STEPS:
        return
    per_sample = _substeps(sample_rate_hz, plant_rate_hz)
    longest_s = min((MAX_LOG_SAMPLES - 1) / sample_rate_hz, (MAX_PLANT_STEPS // per_sample - 1) / sample_rate_hz)
    memory_gb = (samples * len(LOG_COLUMNS) + steps) * 8 / 1e9
    raise WorkbenchInputError(
        f"{duration_name} {value_text(duration_s)} s at {rate_name} {value_text(sample_rate_hz)} Hz plans "
        f"{_count(samples)} log samples and {_count(steps)} plant steps at {plant_rate_hz:g} Hz ("
        f"{f'about {memory_gb:,.3g} GB' if math.isfinite(memory_gb) else 'beyond any memory'}); "
        f"at most {MAX_LOG_SAMPLES:,} samples and {MAX_PLANT_STEPS:,} plant steps, {longest_s:,.6g} s at this rate: "
        f"give a shorter {duration_name} or a lower {rate_name}"
    )


def generate_open_loop_log(
    vehicle: VehicleModel,
    maneuver: Maneuver,
    speed_kmh: float,
    sample_rate_hz: float = 100.0,
    plant_rate_hz: float = PLANT_RATE_HZ,
    braking: Braking | None = None,
) -> pd.DataFrame:
    """Simulate the maneuver at a held speed (PI speed control; with braking, the held speed falls by its pulse,
    `maneuvers.Braking`) and return the log, one row per sample. The plant
    is driven at plant_rate_hz with the profile at each plant step's midpoint, so that the steering between two
    log samples is the profile's, as a real steering wheel's is (not held from one sample to the next, which would
    delay the logged steering by half a sample: the fit interpolates the logged steering linearly). A log longer
    than `check_log_size` allows is refused before anything is allocated."""
    require_in_range("speed_kmh", speed_kmh, 1e-3, 400.0, "km/h (must be > 0)")
    require_in_range("plant_rate_hz", plant_rate_hz, 1.0, 100_000.0, "Hz")
    if braking is not None and braking.decel_mps2 * braking.duration_s >= speed_kmh / 3.6:
        raise WorkbenchInputError(
            f"braking at {braking.decel_mps2:g} m/s^2 for {braking.duration_s:g} s would stop the vehicle from "
            f"{speed_kmh:g} km/h; the pulse must end above standstill"
        )
    check_log_size(maneuver.duration_s, sample_rate_hz, plant_rate_hz)
    substeps = _substeps(sample_rate_hz, plant_rate_hz)
    dt = 1.0 / sample_rate_hz
    held = speed_kmh / 3.6
    t = np.arange(0.0, maneuver.duration_s + 0.5 * dt, dt)
    steer = maneuver.steer_wheel_rad(t)
    h = dt / substeps
    fine = maneuver.steer_wheel_rad(t[:, None] + h * (np.arange(substeps) + 0.5)[None, :])
    state = vehicle.initial_state(0.0, 0.0, 0.0, held)
    speed_control = PISpeedController()
    rows = np.empty((t.size, len(LOG_COLUMNS)))
    for k, (tk, sw) in enumerate(zip(t, steer, strict=True)):
        out = vehicle.outputs(state, sw, 0.0)
        x, y, yaw, vx, vy, yaw_rate = out[:6]
        speed = math.hypot(vx, vy)
        rows[k] = (tk, math.degrees(sw), speed, x, y, yaw, yaw_rate)
        speed_ref, rate = (held, 0.0) if braking is None else braking.speed_ref(float(tk), held)
        accel = speed_control.step(speed_ref, speed, dt, rate)
        for sw_fine in fine[k].tolist():
            state = vehicle.advance(state, sw_fine, accel, h, 1)
    return pd.DataFrame(rows, columns=list(LOG_COLUMNS))
