"""The conditions between the plant and the controller: what the sensors give (noise, drift, bias, update rate,
latency, quantisation), how the steering command reaches the plant (dead time, a tighter rate limit) and the road
(its friction). Frozen, validated dataclasses, the named presets (`CONDITIONS`) and their TOML file format.

A run's `Conditions` has one table per part:

- `Localisation`: the pose (x, y, yaw) and the velocity (vx, vy) from a GNSS/INS: white noise on x and y, a
  first-order Gauss-Markov drift on x and y, white heading noise, an update rate (the pose and the velocity
  refreshed at that rate and held in between) and a latency;
- `Inertial`: the yaw rate (white noise, a constant bias), the speed (white noise on its magnitude, drawn with
  each refresh of the velocity) and the yaw rate's own latency;
- `SteeringSensor`: the measured steering-wheel angle: white noise, quantisation, latency;
- `Actuation`: a dead time on the steering-wheel command and a rate limit tighter than the plant's own;
- `Road`: the tyres' peak-friction scale, constant or along the path's arc length.

The models are in `workbench.simulation.sensing` (`SensorModel`, `ActuatorModel`); `Conditions.is_ideal` is True
exactly when nothing changes a run, and the simulator then bypasses them.

A conditions file (`load_conditions("my.toml")`; `conditions_to_toml(CONDITIONS["rtk"])` writes one to start
from) holds the optional top-level `name` and `source` and any of the tables [localisation], [inertial],
[steering_sensor], [actuation] and [road], each with any of its fields (a missing field or table keeps its
default, which changes nothing). An optional field is "none" in a file; `friction_profile` is a list of
[distance_m, scale] pairs. Unknown keys and wrongly typed values are refused naming the key; values out of range
are refused naming the field, the value and the allowed range.
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from workbench.base.errors import WorkbenchInputError, is_number, require_in_range, value_text
from workbench.base.input_files import read_toml
from workbench.base.typed_tables import check_keys, field_types, typed_value

#: The road-friction scale a run may ask for, the range `VehicleModel.set_road_friction` accepts
#: (`workbench.vehicles.base.ROAD_FRICTION_RANGE`; kept here too so that reading conditions does not load the
#: vehicle models; a test checks that the two agree).
ROAD_FRICTION_RANGE: tuple[float, float] = (0.05, 1.5)

#: Upper bounds of the settings (generous: they catch a unit slip, e.g. degrees for radians or ms for s).
MAX_POSITION_SIGMA_M = 100.0
MAX_ANGLE_SIGMA_RAD = 0.5  # about 29 degrees
MAX_RATE_SIGMA_RAD_S = 1.0
MAX_SPEED_SIGMA_MPS = 10.0
MAX_LATENCY_S = 2.0
MAX_CORRELATION_TIME_S = 1e6
MAX_UPDATE_RATE_HZ = 10_000.0
MAX_QUANTISATION_RAD = 0.2
MAX_STEER_WHEEL_RATE_RAD_S = 100.0


def _require_text(name: str, value: object) -> None:
    if not isinstance(value, str):
        raise WorkbenchInputError(f"{name} must be text; got {value_text(value)}")


@dataclass(frozen=True)
class Localisation:
    """The pose (x, y, yaw) and the velocity (vx, vy) a GNSS/INS gives.

    The drift on x and on y starts from its stationary distribution. With an update rate, the pose and the velocity
    are refreshed at the multiples of 1 / update_rate_hz of the run's clock and held in between, the noise drawn
    with each refresh.
    """

    position_noise_m: float = 0.0  # sigma of white noise on x and on y (m), in [0, 100]
    position_drift_m: float = 0.0  # sigma of a first-order Gauss-Markov drift on x and on y (m), in [0, 100]
    position_drift_time_s: float = 60.0  # the drift's correlation time tau (s), in [0.001, 1e6]
    heading_noise_rad: float = 0.0  # sigma of white noise on the yaw (rad), in [0, 0.5]
    update_rate_hz: float | None = None  # pose and velocity refresh rate (Hz), in [0.001, 10000]; None: every step
    latency_s: float = 0.0  # the refreshed pose and velocity are those of this much earlier (s), in [0, 2]

    def __post_init__(self) -> None:
        require_in_range("localisation.position_noise_m", self.position_noise_m, 0.0, MAX_POSITION_SIGMA_M, "m")
        require_in_range("localisation.position_drift_m", self.position_drift_m, 0.0, MAX_POSITION_SIGMA_M, "m")
        require_in_range(
            "localisation.position_drift_time_s", self.position_drift_time_s, 1e-3, MAX_CORRELATION_TIME_S, "s"
        )
        require_in_range("localisation.heading_noise_rad", self.heading_noise_rad, 0.0, MAX_ANGLE_SIGMA_RAD, "rad")
        if self.update_rate_hz is not None:
            require_in_range(
                "localisation.update_rate_hz", self.update_rate_hz, 1e-3, MAX_UPDATE_RATE_HZ, 'Hz (or "none")'
            )
        require_in_range("localisation.latency_s", self.latency_s, 0.0, MAX_LATENCY_S, "s")

    @property
    def is_ideal(self) -> bool:
        """Whether the pose and velocity reach the controller unchanged: no noise, drift, update rate or latency."""
        return (
            self.position_noise_m == 0.0
            and self.position_drift_m == 0.0
            and self.heading_noise_rad == 0.0
            and self.update_rate_hz is None
            and self.latency_s == 0.0
        )


@dataclass(frozen=True)
class Inertial:
    """The yaw rate and the speed.

    The speed noise n scales the measured velocity (vx, vy) by (v + n) / v, v its magnitude, so the noise is on the
    speed and the direction of travel (the side-slip) is kept; it is drawn with each refresh of the velocity, which
    follows the localisation's update rate and latency. The yaw rate's latency is its own (e.g. a vehicle bus),
    independent of the localisation's.
    """

    yaw_rate_noise_rad_s: float = 0.0  # sigma of white noise on the yaw rate, drawn every step (rad/s), in [0, 1]
    yaw_rate_bias_rad_s: float = 0.0  # a constant bias added to the yaw rate (rad/s), in [-1, 1]
    speed_noise_mps: float = 0.0  # sigma of white noise on the speed (m/s), in [0, 10]
    latency_s: float = 0.0  # the yaw rate seen is that of this much earlier (s), in [0, 2]

    def __post_init__(self) -> None:
        require_in_range("inertial.yaw_rate_noise_rad_s", self.yaw_rate_noise_rad_s, 0.0, MAX_RATE_SIGMA_RAD_S, "rad/s")
        bias_max = MAX_RATE_SIGMA_RAD_S
        require_in_range("inertial.yaw_rate_bias_rad_s", self.yaw_rate_bias_rad_s, -bias_max, bias_max, "rad/s")
        require_in_range("inertial.speed_noise_mps", self.speed_noise_mps, 0.0, MAX_SPEED_SIGMA_MPS, "m/s")
        require_in_range("inertial.latency_s", self.latency_s, 0.0, MAX_LATENCY_S, "s")

    @property
    def is_ideal(self) -> bool:
        """Whether the yaw rate and the speed reach the controller unchanged: no noise, bias or latency."""
        return (
            self.yaw_rate_noise_rad_s == 0.0
            and self.yaw_rate_bias_rad_s == 0.0
            and self.speed_noise_mps == 0.0
            and self.latency_s == 0.0
        )


@dataclass(frozen=True)
class SteeringSensor:
    """The measured steering-wheel angle: noisy, then quantised, then late."""

    noise_rad: float = 0.0  # sigma of white noise on the angle (rad), in [0, 0.5]
    quantisation_rad: float = 0.0  # the angle rounded to a multiple of this after the noise (rad), in [0, 0.2]; 0: none
    latency_s: float = 0.0  # the angle seen is that of this much earlier (s), in [0, 2]

    def __post_init__(self) -> None:
        require_in_range("steering_sensor.noise_rad", self.noise_rad, 0.0, MAX_ANGLE_SIGMA_RAD, "rad")
        require_in_range(
            "steering_sensor.quantisation_rad", self.quantisation_rad, 0.0, MAX_QUANTISATION_RAD, "rad (0: none)"
        )
        require_in_range("steering_sensor.latency_s", self.latency_s, 0.0, MAX_LATENCY_S, "s")

    @property
    def is_ideal(self) -> bool:
        """Whether the steering-wheel angle reaches the controller unchanged: no noise, quantisation or latency."""
        return self.noise_rad == 0.0 and self.quantisation_rad == 0.0 and self.latency_s == 0.0


@dataclass(frozen=True)
class Actuation:
    """How the steering-wheel command reaches the plant, before the plant's own steering dynamics.

    The dead time is a pure delay honoured to the plant's step: the command applied from time t is the one the
    controller computed at t - dead_time_s. The rate limit acts on the delayed command.
    """

    dead_time_s: float = 0.0  # pure delay of the command (s), in [0, 2]
    max_steer_wheel_rate_rad_s: float | None = None  # steering-wheel rad/s, in [0.001, 100]; None: the plant's own

    def __post_init__(self) -> None:
        require_in_range("actuation.dead_time_s", self.dead_time_s, 0.0, MAX_LATENCY_S, "s")
        if self.max_steer_wheel_rate_rad_s is not None:
            require_in_range(
                "actuation.max_steer_wheel_rate_rad_s",
                self.max_steer_wheel_rate_rad_s,
                1e-3,
                MAX_STEER_WHEEL_RATE_RAD_S,
                'rad/s (or "none")',
            )

    @property
    def is_ideal(self) -> bool:
        """Whether the command reaches the plant unchanged: no dead time and no rate limit tighter than the plant's."""
        return self.dead_time_s == 0.0 and self.max_steer_wheel_rate_rad_s is None


@dataclass(frozen=True)
class Road:
    """The road: the scale of the tyres' peak friction (Pacejka's lambda_mu; 1.0 the road of the tyre data).

    The friction profile has at least two pairs, distances (m) increasing from 0 or more and scales in
    ROAD_FRICTION_RANGE; it is interpolated linearly along the path's arc length and held beyond its first and last
    points. The scale at s is friction_scale x the profile's, and every such product must lie in
    ROAD_FRICTION_RANGE too. The simulator sets it with `vehicle.set_road_friction(road.friction_at(s))`.
    """

    friction_scale: float = 1.0  # the scale everywhere (dimensionless), in [0.05, 1.5]
    friction_profile: tuple[tuple[float, float], ...] | None = None  # (distance m, scale) pairs; None: constant

    def __post_init__(self) -> None:
        low, high = ROAD_FRICTION_RANGE
        require_in_range("road.friction_scale", self.friction_scale, low, high)
        if self.friction_profile is None:
            return
        profile = _profile_pairs(self.friction_profile)
        object.__setattr__(self, "friction_profile", profile)
        for i, (distance, scale) in enumerate(profile):
            require_in_range(f"road.friction_profile[{i}] distance_m", distance, 0.0, 1e9, "m")
            require_in_range(f"road.friction_profile[{i}] scale", scale, low, high)
            if i and distance <= profile[i - 1][0]:
                raise WorkbenchInputError(
                    f"road.friction_profile distances must increase; entry {i} is {value_text(distance)} m after "
                    f"{value_text(profile[i - 1][0])} m"
                )
            product = self.friction_scale * scale
            if not low <= product <= high:
                raise WorkbenchInputError(
                    f"road.friction_scale x road.friction_profile[{i}] scale must be in [{low!r}, {high!r}]; got "
                    f"{value_text(self.friction_scale)} x {value_text(scale)} = {value_text(product)}"
                )

    @property
    def is_ideal(self) -> bool:
        """Whether the road is that of the tyre data everywhere: a friction scale of 1.0 all along the path."""
        profile_flat = self.friction_profile is None or all(scale == 1.0 for _, scale in self.friction_profile)
        return self.friction_scale == 1.0 and profile_flat

    @property
    def is_constant(self) -> bool:
        """Whether the scale is the same everywhere (no profile, or one of equal scales)."""
        return self.friction_profile is None or len({scale for _, scale in self.friction_profile}) == 1

    def friction_at(self, s_m: float) -> float:
        """The friction scale at arc length `s_m` (m) of the path (the caller wraps s on a closed path).

        Parameters
        ----------
        s_m : float
            Arc length along the path (m); before the profile's first distance or after its last, the scale there
            is held.

        Returns
        -------
        float
            The peak-friction scale (dimensionless, within ROAD_FRICTION_RANGE): `friction_scale` times the
            profile's scale interpolated linearly at `s_m`, or `friction_scale` alone without a profile.
        """
        profile = self.friction_profile
        if profile is None:
            return self.friction_scale
        i = bisect.bisect_right(profile, (s_m, math.inf))
        if i == 0:
            return self.friction_scale * profile[0][1]
        if i == len(profile):
            return self.friction_scale * profile[-1][1]
        (s0, f0), (s1, f1) = profile[i - 1], profile[i]
        return self.friction_scale * (f0 + (f1 - f0) * (s_m - s0) / (s1 - s0))


def _profile_pairs(profile: object) -> tuple[tuple[float, float], ...]:
    """`profile` as a tuple of (distance, scale) float pairs; WorkbenchInputError naming the bad entry."""
    if isinstance(profile, str | bytes) or not hasattr(profile, "__iter__"):
        raise WorkbenchInputError(
            f"road.friction_profile must be a list of [distance_m, scale] pairs; got {value_text(profile)}"
        )
    pairs = []
    for i, entry in enumerate(profile):
        if isinstance(entry, str | bytes) or not hasattr(entry, "__len__") or len(entry) != 2:
            raise WorkbenchInputError(
                f"road.friction_profile[{i}] must be a [distance_m, scale] pair; got {value_text(entry)}"
            )
        for part, value in zip(("distance_m", "scale"), entry, strict=True):
            if not is_number(value) or not math.isfinite(value):
                raise WorkbenchInputError(
                    f"road.friction_profile[{i}] {part} must be a finite number; got {value_text(value)}"
                )
        pairs.append((float(entry[0]), float(entry[1])))
    if len(pairs) < 2:
        raise WorkbenchInputError(
            f"road.friction_profile needs at least 2 [distance_m, scale] pairs (one scale: use friction_scale); "
            f"got {len(pairs)}"
        )
    return tuple(pairs)


@dataclass(frozen=True)
class Conditions:
    """Everything between the plant and the controller in a run (see the module docstring); the defaults change
    nothing."""

    name: str = "custom"  # what reports call these conditions: non-empty text
    localisation: Localisation = field(default_factory=Localisation)  # the pose and velocity from a GNSS/INS
    inertial: Inertial = field(default_factory=Inertial)  # the yaw rate and the speed
    steering_sensor: SteeringSensor = field(default_factory=SteeringSensor)  # the measured steering-wheel angle
    actuation: Actuation = field(default_factory=Actuation)  # how the steering command reaches the plant
    road: Road = field(default_factory=Road)  # the tyres' peak-friction scale along the path
    source: str = ""  # where the values come from, in words (any text)

    def __post_init__(self) -> None:
        _require_text("conditions name", self.name)
        if not self.name.strip():
            raise WorkbenchInputError("conditions name must be non-empty text; got ''")
        _require_text("conditions source", self.source)
        for name, cls in _TABLES.items():
            value = getattr(self, name)
            if not isinstance(value, cls):
                raise WorkbenchInputError(f"conditions {name} must be a {cls.__name__}; got {value_text(value)}")

    @property
    def sensing_is_ideal(self) -> bool:
        """Whether the controller sees the plant's outputs unchanged (SensorModel passes them through)."""
        return self.localisation.is_ideal and self.inertial.is_ideal and self.steering_sensor.is_ideal

    @property
    def is_ideal(self) -> bool:
        """True exactly when nothing changes the run: no noise, bias, drift, update rate or latency, no dead time,
        no tighter rate limit, and the road's friction 1.0 everywhere."""
        return self.sensing_is_ideal and self.actuation.is_ideal and self.road.is_ideal

    def describe(self) -> str:
        """One line in words: what these conditions change.

        Returns
        -------
        str
            The settings of each part that changes the run, separated by semicolons, with units; for ideal
            conditions, that nothing lies between plant and controller.
        """
        loc, ine, ste, act, road = self.localisation, self.inertial, self.steering_sensor, self.actuation, self.road
        parts = []
        if not loc.is_ideal:
            rate = "every step" if loc.update_rate_hz is None else f"{loc.update_rate_hz:g} Hz"
            parts.append(
                f"pose sigma {loc.position_noise_m:g} m + drift {loc.position_drift_m:g} m (tau "
                f"{loc.position_drift_time_s:g} s), heading sigma {math.degrees(loc.heading_noise_rad):.3g} deg, "
                f"{rate}, latency {loc.latency_s * 1e3:g} ms"
            )
        if not ine.is_ideal:
            parts.append(
                f"yaw rate sigma {math.degrees(ine.yaw_rate_noise_rad_s):.3g} deg/s, bias "
                f"{math.degrees(ine.yaw_rate_bias_rad_s):.3g} deg/s, latency {ine.latency_s * 1e3:g} ms; speed "
                f"sigma {ine.speed_noise_mps:g} m/s"
            )
        if not ste.is_ideal:
            parts.append(
                f"steering sensor sigma {math.degrees(ste.noise_rad):.3g} deg, step "
                f"{math.degrees(ste.quantisation_rad):.3g} deg, latency {ste.latency_s * 1e3:g} ms"
            )
        if not act.is_ideal:
            limit = act.max_steer_wheel_rate_rad_s
            rate = "" if limit is None else f", rate <= {limit:g} rad/s"
            parts.append(f"steering dead time {act.dead_time_s * 1e3:g} ms{rate}")
        if not road.is_ideal:
            profile = "" if road.friction_profile is None else f" x a profile of {len(road.friction_profile)} points"
            parts.append(f"road friction x {road.friction_scale:g}{profile}")
        return "; ".join(parts) if parts else "ideal: nothing between plant and controller"


#: The tables of a conditions file: field of Conditions -> its dataclass.
_TABLES: dict[str, type] = {
    "localisation": Localisation,
    "inertial": Inertial,
    "steering_sensor": SteeringSensor,
    "actuation": Actuation,
    "road": Road,
}
_TOP_KEYS = ("name", "source", *_TABLES)

# ------------------------------------------------------------------------------------------------------ presets
# Values and why (the `source` texts say the same in short):
#
# RTK GNSS/INS (`rtk`): OxTS RT3000 (RT user manual): "1 cm RTK" position (v2 and later, 1 sigma), outputs at 100 or
# 250 Hz with 3.5 ms latency (1 ms calculation latency in the v4 manual); dual-antenna heading 0.2 deg 1 sigma per
# metre of antenna separation (0.05 deg at 4 m), single antenna about 0.1 deg under dynamic conditions. NovAtel
# SPAN (SPAN-CPT manual): INS solution at 100 Hz. Chosen: 1 cm white on x and y, 1 cm drift with tau = 60 s (the
# slowly varying part of an RTK fix, multipath and the baseline's ppm term: assumed), heading 0.1 deg, 100 Hz,
# 10 ms latency (the unit's 3.5 ms plus the link and the driver: assumed). Yaw rate: 0.05 deg/s white and a
# 0.01 deg/s bias, speed 0.014 m/s (0.05 km/h) white: the grade of a survey INS (assumed, not taken from a sheet;
# an Xsens MTi-1 MEMS gyro's noise density, 0.007 deg/s/sqrt(Hz), gives 0.035 deg/s over 25 Hz). Autoware's
# simple_planning_simulator, for comparison, adds 0.01 m position and 0.0001 rad angle noise when its
# add_measurement_noise is on (its README's defaults).
#
# Automotive (`automotive`): the RTK pose, and the vehicle's own signals over CAN: yaw rate and steering-wheel
# angle 20 ms late (a 10 ms CAN cycle, e.g. the steering-angle sensor's 100 Hz frame, plus gateway and task
# scheduling: assumed), the steering-wheel angle in steps of 0.1 deg (a usual CAN signal resolution; BMW's DSC
# sends 0.044 deg/bit at 10 ms), and a 0.1 s dead time on the steering command. Autoware's simple_planning_simulator
# declares steer_time_delay = 0.24 s and steer_time_constant = 0.27 s as its defaults (README, the node's
# declare_parameter, and the sample vehicle's simulator_model.param.yaml), but the package's own
# simple_planning_simulator_default.param.yaml uses steer_time_delay = 0.1 s, steer_time_constant = 0.1 s. The
# 0.24 s / 0.27 s pair lumps a retrofitted drive-by-wire vehicle's whole chain, command to measured tyre angle;
# here each plant already has its power steering's own lag (time constant 0.05 s) and rate limit, so only the
# transport delay (vehicle bus, EPS controller) is added: 0.1 s, Autoware's default-file value. A file may set
# 0.24 s to study the pessimistic case. No tighter rate limit: the plants' own (0.4 rad/s at the road wheels, 6
# rad/s at the steering wheel for a 15:1 ratio) is already below Autoware's steer_rate_lim of 5 rad/s (tyre angle).
#
# Degraded (`degraded`): standard GNSS without RTK, a MEMS IMU, the automotive CAN and actuator delays, a wet road.
# NovAtel SPAN-CPT: single point L1/L2 1.2 m RMS horizontal, SBAS 0.6 m, DGPS 0.4 m, GNSS position at 20 Hz;
# Trimble 5700: L1 C/A code 0.5 m (1 sigma), <20 ms latency. Chosen: a 0.75 m Gauss-Markov drift with tau =
# 300 s (atmospheric and orbit errors vary over minutes: assumed) plus 0.2 m white (receiver noise), about 1.1 m
# RMS horizontally; 5 Hz, 0.1 s latency (a mass-market receiver's rate and its solution and transport delay);
# heading 0.5 deg (a single-antenna GNSS course fused with a MEMS gyro: assumed). Yaw rate 0.1 deg/s white, 0.1
# deg/s residual bias (an automotive MEMS gyro after standstill calibration: assumed), speed 0.05 m/s (a GNSS
# Doppler speed: assumed). Road: friction x 0.5, wet asphalt: Wong, "Theory of Ground Vehicles", Table 1.1 gives
# peak friction 0.8-0.9 dry and 0.5-0.7 wet for asphalt; half the tyre data's dry peak is at the wet range's low
# end.

_RTK_LOCALISATION = Localisation(
    position_noise_m=0.01,
    position_drift_m=0.01,
    position_drift_time_s=60.0,
    heading_noise_rad=math.radians(0.1),
    update_rate_hz=100.0,
    latency_s=0.010,
)
_RTK_INERTIAL = Inertial(
    yaw_rate_noise_rad_s=math.radians(0.05),
    yaw_rate_bias_rad_s=math.radians(0.01),
    speed_noise_mps=0.014,
    latency_s=0.010,
)
_CAN_STEERING_SENSOR = SteeringSensor(noise_rad=0.0, quantisation_rad=math.radians(0.1), latency_s=0.020)
_CAN_ACTUATION = Actuation(dead_time_s=0.1, max_steer_wheel_rate_rad_s=None)

#: The named conditions, `ideal` the default.
CONDITIONS: dict[str, Conditions] = {
    "ideal": Conditions(
        name="ideal",
        source="nothing between plant and controller: the plant's outputs are measured exactly and at once, the "
        "command is applied at once, the road is that of the tyre data",
    ),
    "rtk": Conditions(
        name="rtk",
        localisation=_RTK_LOCALISATION,
        inertial=_RTK_INERTIAL,
        source="RTK GNSS/INS pose (OxTS RT3000 user manual: 1 cm RTK, 100/250 Hz outputs, 3.5 ms latency, heading "
        "0.2 deg per metre of antenna separation; NovAtel SPAN: 100 Hz INS solution): 1 cm white + 1 cm drift "
        "(tau 60 s), heading 0.1 deg, 100 Hz, 10 ms; survey-grade yaw rate 0.05 deg/s, bias 0.01 deg/s, speed "
        "0.014 m/s (assumed)",
    ),
    "automotive": Conditions(
        name="automotive",
        localisation=_RTK_LOCALISATION,
        inertial=dataclasses.replace(_RTK_INERTIAL, latency_s=0.020),
        steering_sensor=_CAN_STEERING_SENSOR,
        actuation=_CAN_ACTUATION,
        source="the rtk pose, with the vehicle's signals over CAN: yaw rate and steering-wheel angle 20 ms late "
        "(assumed), steering angle in 0.1 deg steps (a usual CAN resolution), 0.1 s steering dead time (Autoware "
        "simple_planning_simulator_default.param.yaml: steer_time_delay 0.1 s; its node default, 0.24 s with a "
        "0.27 s time constant, lumps a whole drive-by-wire chain whose lag the plants model themselves)",
    ),
    "degraded": Conditions(
        name="degraded",
        localisation=Localisation(
            position_noise_m=0.2,
            position_drift_m=0.75,
            position_drift_time_s=300.0,
            heading_noise_rad=math.radians(0.5),
            update_rate_hz=5.0,
            latency_s=0.1,
        ),
        inertial=Inertial(
            yaw_rate_noise_rad_s=math.radians(0.1),
            yaw_rate_bias_rad_s=math.radians(0.1),
            speed_noise_mps=0.05,
            latency_s=0.020,
        ),
        steering_sensor=_CAN_STEERING_SENSOR,
        actuation=_CAN_ACTUATION,
        road=Road(friction_scale=0.5),
        source="standard GNSS without RTK (NovAtel SPAN-CPT: single point 1.2 m RMS, SBAS 0.6 m): 0.75 m drift "
        "(tau 300 s) + 0.2 m white, 5 Hz, 0.1 s latency, heading 0.5 deg; MEMS yaw rate 0.1 deg/s, bias 0.1 "
        "deg/s, speed 0.05 m/s (assumed); the automotive CAN and actuator delays; a wet road, friction x 0.5 (Wong, "
        "Theory of Ground Vehicles, Table 1.1: asphalt 0.8-0.9 dry, 0.5-0.7 wet)",
    ),
}


# -------------------------------------------------------------------------------------------------------- files
def load_conditions(name_or_path: str | os.PathLike[str]) -> Conditions:
    """The conditions named `name_or_path` (a key of CONDITIONS) or read from that TOML file (see the module
    docstring); WorkbenchInputError for an unknown name, an unreadable file or anything in it the format refuses.

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A preset ("ideal", "rtk", "automotive", "degraded") or the path of a TOML conditions file.

    Returns
    -------
    Conditions
        The preset, or the file's conditions named by its top-level ``name`` (else the file's stem).

    Raises
    ------
    WorkbenchInputError
        An unknown preset (the message lists them), an unreadable or malformed file, an unknown key, a wrongly
        typed value, or a value out of its range (the message names the field, the value and the range).

    Examples
    --------
    >>> from workbench.simulation.conditions import conditions_to_toml, load_conditions
    >>> load_conditions("ideal").is_ideal
    True
    >>> text = conditions_to_toml(load_conditions("automotive"))  # a file to copy and edit
    """
    key = os.fspath(name_or_path)
    if key in CONDITIONS:
        return CONDITIONS[key]
    path = Path(key)
    if not os.path.lexists(path) and path.suffix.lower() != ".toml":
        raise WorkbenchInputError(
            f"unknown conditions {key!r}: choose a preset ({', '.join(CONDITIONS)}) or give a .toml conditions file"
        )
    label = f"conditions file {key!r}"
    return conditions_from_table(read_toml(path, label), label, path.stem, f"read from {key}")


def conditions_from_table(
    document: Mapping[str, Any], label: str, default_name: str = "custom", default_source: str = ""
) -> Conditions:
    """Conditions from a parsed conditions file (`label` starts every message); without a top-level name or
    source, `default_name` and `default_source`.

    Parameters
    ----------
    document : Mapping
        The parsed TOML document: the optional top-level ``name`` and ``source`` and any of the tables
        ``localisation``, ``inertial``, ``steering_sensor``, ``actuation`` and ``road``.
    label : str
        What every error message starts with, naming where the document came from (e.g. the file).
    default_name : str
        The conditions' name when the document has none.
    default_source : str
        Where the values come from, in words, when the document does not say.

    Returns
    -------
    Conditions
        The conditions; a missing table or field keeps its default, which changes nothing.

    Raises
    ------
    WorkbenchInputError
        An unknown key, a wrongly typed value, or a value out of its range, after `label`.
    """
    doc = check_keys(f"{label}: top level", document, _TOP_KEYS)
    try:
        name = typed_value("'name'", doc.get("name", default_name), str)
        source = typed_value("'source'", doc["source"], str) if "source" in doc else default_source
        tables = {key: _table(cls, doc[key], key) for key, cls in _TABLES.items() if key in doc}
        return Conditions(name=name, source=source, **tables)
    except WorkbenchInputError as exc:
        raise WorkbenchInputError(f"{label}: {exc}") from None


def _table(cls: type, table: object, key: str) -> Any:
    """One table of a conditions file as its dataclass: keys and types checked by the typed-table rules, except
    that a non-finite number (TOML's nan, inf) goes on to the dataclass, whose message names the allowed range; the
    road's friction_profile read as [distance_m, scale] pairs."""
    types = field_types(cls)
    values = {}
    for name, value in check_keys(f"[{key}]", table, types).items():
        if name == "friction_profile":
            none = value is None or (isinstance(value, str) and value.strip().lower() == "none")
            values[name] = None if none else value  # checked by Road
        elif isinstance(value, float) and not math.isfinite(value):
            values[name] = value
        else:
            values[name] = typed_value(f"[{key}]: {name!r}", value, types[name])
    return cls(**values)


def conditions_to_toml(conditions: Conditions) -> str:
    """The TOML text of `conditions`, which `load_conditions` reads back to equal conditions (to copy and edit).

    Parameters
    ----------
    conditions : Conditions
        The conditions to write.

    Returns
    -------
    str
        The file's text: ``name``, ``source`` and every table with every field (angles in rad, times in s; an
        unset optional value as "none").
    """
    lines = [
        "# Sensing and actuation conditions (workbench/simulation/conditions.py). Angles in rad, times in s; an",
        '# optional value is "none"; a missing key or table keeps its default, which changes nothing.',
        f"name = {_toml_string(conditions.name)}",
        f"source = {_toml_string(conditions.source)}",
    ]
    for key in _TABLES:
        table = getattr(conditions, key)
        lines += ["", f"[{key}]"]
        for f in fields(table):
            value = getattr(table, f.name)
            if f.name == "friction_profile":
                if value is None:
                    lines.append("# friction_profile = [[0.0, 1.0], [100.0, 0.5]]  # [distance_m, scale] pairs")
                else:
                    pairs = ", ".join(f"[{_toml_float(d)}, {_toml_float(s)}]" for d, s in value)
                    lines.append(f"friction_profile = [{pairs}]")
            else:
                lines.append(f"{f.name} = {_NONE if value is None else _toml_float(value)}")
    return "\n".join(lines) + "\n"


_NONE = '"none"'


def _toml_float(value: float) -> str:
    """A float as TOML writes it, exactly (repr round-trips; TOML needs a digit after the point)."""
    return repr(float(value))


def _toml_string(text: str) -> str:
    """`text` as a TOML basic string: quotes, backslashes and control characters escaped, the rest as it is."""
    escaped = "".join(
        f"\\u{ord(c):04x}" if ord(c) < 0x20 or ord(c) == 0x7F else "\\" + c if c in '"\\' else c for c in text
    )
    return f'"{escaped}"'


__all__ = [
    "CONDITIONS",
    "ROAD_FRICTION_RANGE",
    "Actuation",
    "Conditions",
    "Inertial",
    "Localisation",
    "Road",
    "SteeringSensor",
    "conditions_from_table",
    "conditions_to_toml",
    "load_conditions",
]
