"""What a vehicle file of model type `fmu` says about the user's plant FMU: the file, its communication step, the
geometry and limits the workbench needs, what model-based controllers predict with, and the mapping of the FMU's
variables to the plant interface (`workbench.vehicles.base`).

Every mapped variable is named as in the FMU's modelDescription.xml and carries a scale: the FMU's value is
scale x the workbench's value in SI units with the workbench's signs (x east, y north, yaw and yaw rate
counter-clockwise, lateral speed and acceleration positive to the left, steering positive to the left). A scale
of -1 flips a sign, 57.29577951308232 reads degrees, 3.6 reads km/h. Text fields that a plant does without are
written "none" (TOML has no null). `workbench vehicles --show fmu` prints a template with every field explained.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from pathlib import Path

from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive, value_text

#: What the steering input or output of the FMU is: the front road-wheel angle or the steering-wheel angle.
STEERING_KINDS: tuple[str, ...] = ("road_wheel_angle", "steering_wheel_angle")
#: What the longitudinal input is: an acceleration (m/s^2), or a throttle and a brake (fractions of full travel,
#: the acceleration command over max_accel_mps2 or max_decel_mps2, times their scales).
LONGITUDINAL_KINDS: tuple[str, ...] = ("acceleration", "throttle_brake")
#: Bounds of the communication step (s): from 10 kHz to the workbench's slowest controller period (0.1 s).
COMMUNICATION_STEP_RANGE_S: tuple[float, float] = (1e-4, 0.1)

#: Single-track fields that are given all together or not at all (`FmuPlantParams.has_single_track`).
SINGLE_TRACK_FIELDS: tuple[str, ...] = (
    "mass_kg",
    "yaw_inertia_kgm2",
    "cg_to_front_axle_m",
    "front_cornering_stiffness_n_per_rad",
    "rear_cornering_stiffness_n_per_rad",
    "front_peak_force_n",
    "rear_peak_force_n",
)
#: The mapped outputs every plant has, in the order of `workbench.vehicles.base.STANDARD_OUTPUTS` (the steering
#: output gives both of its angles).
REQUIRED_OUTPUTS: tuple[str, ...] = (
    "x_output",
    "y_output",
    "yaw_output",
    "vx_output",
    "vy_output",
    "yaw_rate_output",
    "steering_output",
    "lat_accel_output",
)
#: Optional mapped output -> the extra output it gives (`VehicleModel.extra_output_names`; the metrics read `ltr`
#: and the trailer's rear-axle centre by these names).
OPTIONAL_OUTPUTS: dict[str, str] = {
    "ltr_output": "ltr",
    "trailer_x_output": "trailer_x_m",
    "trailer_y_output": "trailer_y_m",
    "articulation_output": "articulation_rad",
}


@dataclass(frozen=True)
class FmuPlantParams:
    """A plant FMU and its mapping (module docstring), SI units unless a field says otherwise.

    A controller period is split into doSteps of communication_step_s, the last shortened when the period is not a
    multiple, which needs an FMU that handles a variable step. What the MPCs predict with: the steering time
    constant, and either the single track (SINGLE_TRACK_FIELDS, all or none; the rear axle is wheelbase_m -
    cg_to_front_axle_m; the ranges of `SingleTrackParams` apply, checked when `FmuPlant.single_track` builds it)
    or lag_file, or neither (a kinematic single track). Outputs: REQUIRED_OUTPUTS and any of OPTIONAL_OUTPUTS, each
    at the rear-axle centre with the workbench's signs and with its `<field>_scale` (FMU value = scale x the
    workbench's value); trailer outputs need hitch_to_trailer_axle_m, which draws the trailer's outline. A start
    value goes with its parameter: both given or both None.
    """

    fmu_file: Path  # the plant's .fmu; in a vehicle file, a relative path is from the file's folder
    communication_step_s: float  # the step of each doStep (s), in [0.0001, 0.1]
    wheelbase_m: float  # front axle to rear axle (m), in [0.5, 15]
    steering_ratio: float  # steering-wheel angle / road-wheel angle, in [1, 60]
    max_road_wheel_angle_rad: float  # steering lock at the road wheels (rad), in [0.01, 1.5]
    max_road_wheel_rate_rad_s: float  # steering rate limit at the road wheels (rad/s), > 0
    width_m: float  # overall width (m), in [0.5, 4]
    max_accel_mps2: float  # the acceleration command is clipped to this (m/s^2), in [0.01, 20]
    max_decel_mps2: float  # the deceleration command is clipped to this (m/s^2, positive), in [0.01, 20]
    steering_time_constant_s: float  # the steering actuator's time constant the MPCs use (s), in [0.001, 2]
    mass_kg: float | None  # single track: mass (kg), in [100, 100000]; None: no single track
    yaw_inertia_kgm2: float | None  # single track: yaw inertia about the CG (kg m^2), in [10, 5e6]
    cg_to_front_axle_m: float | None  # single track: CG to front axle (m), in [0.05, wheelbase_m - 0.05]
    front_cornering_stiffness_n_per_rad: float | None  # single track: front axle's (N/rad), > 0
    rear_cornering_stiffness_n_per_rad: float | None  # single track: rear axle's (N/rad), > 0
    front_peak_force_n: float | None  # single track: the front axle's peak lateral force (N), > 0
    rear_peak_force_n: float | None  # single track: the rear axle's peak lateral force (N), > 0
    lag_file: Path | None  # an identified steering lag (`tuning fit-lag` writes one); None: no identified lag
    rollover_threshold_g: float | None  # the feasibility check's static rollover threshold (g), in [0.05, 2]; None: off
    hitch_to_trailer_axle_m: float | None  # hitch to the trailer's axle (m), in [0.5, 20]; needed with trailer outputs
    steering_input: str  # the FMU input variable of the steering command
    steering_input_is: str  # what it is: "road_wheel_angle" or "steering_wheel_angle" (rad, left positive)
    steering_input_scale: float  # FMU value / workbench value, finite and not 0
    longitudinal_input_is: str  # "acceleration" (accel_input) or "throttle_brake" (throttle_input and brake_input)
    accel_input: str | None  # the FMU input of the acceleration command (m/s^2); needed with "acceleration"
    accel_input_scale: float  # FMU value / workbench value, finite and not 0
    throttle_input: str | None  # the FMU input of the throttle; needed with "throttle_brake"
    throttle_input_scale: float  # FMU value / (acceleration command / max_accel_mps2), finite and not 0
    brake_input: str | None  # the FMU input of the brake; needed with "throttle_brake"
    brake_input_scale: float  # FMU value / (deceleration command / max_decel_mps2), finite and not 0
    x_output: str  # the FMU output of x, east (m)
    x_output_scale: float  # FMU value / workbench value, finite and not 0
    y_output: str  # the FMU output of y, north (m)
    y_output_scale: float  # FMU value / workbench value, finite and not 0
    yaw_output: str  # the FMU output of the yaw, counter-clockwise (rad)
    yaw_output_scale: float  # FMU value / workbench value, finite and not 0
    vx_output: str  # the FMU output of the body-frame longitudinal speed (m/s)
    vx_output_scale: float  # FMU value / workbench value, finite and not 0
    vy_output: str  # the FMU output of the body-frame lateral speed, left positive (m/s)
    vy_output_scale: float  # FMU value / workbench value, finite and not 0
    yaw_rate_output: str  # the FMU output of the yaw rate, counter-clockwise (rad/s)
    yaw_rate_output_scale: float  # FMU value / workbench value, finite and not 0
    steering_output: str  # the FMU output of the steering angle, left positive (rad)
    steering_output_is: str  # what it is: "road_wheel_angle" or "steering_wheel_angle"
    steering_output_scale: float  # FMU value / workbench value, finite and not 0
    lat_accel_output: str  # the FMU output of the lateral acceleration, left positive (m/s^2)
    lat_accel_output_scale: float  # FMU value / workbench value, finite and not 0
    ltr_output: str | None  # load transfer ratio (|LTR| = 1: a wheel lifts); None: no rollover metrics
    ltr_output_scale: float  # FMU value / workbench value, finite and not 0
    trailer_x_output: str | None  # x of the trailer's rear-axle centre (m); given with trailer_y_output or neither
    trailer_x_output_scale: float  # FMU value / workbench value, finite and not 0
    trailer_y_output: str | None  # y of the trailer's rear-axle centre (m); given with trailer_x_output or neither
    trailer_y_output_scale: float  # FMU value / workbench value, finite and not 0
    articulation_output: str | None  # the articulation angle (rad); None: not mapped
    articulation_output_scale: float  # FMU value / workbench value, finite and not 0
    speed_parameter: str | None  # the FMU parameter set to the initial speed (vx_output's units); None: the FMU's own
    payload_parameter: str | None  # the FMU parameter set to payload_kg; None: the FMU's own payload
    payload_kg: float | None  # the payload written to payload_parameter (kg), in [0, 100000]
    friction_parameter: str | None  # the FMU's tunable tyre-friction parameter; None: only road friction 1.0
    road_friction: float | None  # friction_parameter's value on the tyre data's road, > 0; a road scale multiplies it

    def __post_init__(self) -> None:
        require_in_range("communication_step_s", self.communication_step_s, *COMMUNICATION_STEP_RANGE_S, "s")
        require_in_range("wheelbase_m", self.wheelbase_m, 0.5, 15.0, "m")
        require_in_range("steering_ratio", self.steering_ratio, 1.0, 60.0)
        require_in_range("max_road_wheel_angle_rad", self.max_road_wheel_angle_rad, 0.01, 1.5, "rad")
        require_positive("max_road_wheel_rate_rad_s", self.max_road_wheel_rate_rad_s)
        require_in_range("width_m", self.width_m, 0.5, 4.0, "m")
        require_in_range("max_accel_mps2", self.max_accel_mps2, 0.01, 20.0, "m/s^2")
        require_in_range("max_decel_mps2", self.max_decel_mps2, 0.01, 20.0, "m/s^2")
        require_in_range("steering_time_constant_s", self.steering_time_constant_s, 1e-3, 2.0, "s")
        given = [name for name in SINGLE_TRACK_FIELDS if getattr(self, name) is not None]
        if given and len(given) != len(SINGLE_TRACK_FIELDS):
            missing = [name for name in SINGLE_TRACK_FIELDS if name not in given]
            raise WorkbenchInputError(
                f"the single track is given all together or not at all: {', '.join(given)} given but "
                f"{', '.join(missing)} \"none\""
            )
        if given:
            require_in_range("cg_to_front_axle_m", self.cg_to_front_axle_m, 0.05, self.wheelbase_m - 0.05, "m")
        if self.rollover_threshold_g is not None:
            require_in_range("rollover_threshold_g", self.rollover_threshold_g, 0.05, 2.0, "g")
        _require_choice("steering_input_is", self.steering_input_is, STEERING_KINDS)
        _require_choice("steering_output_is", self.steering_output_is, STEERING_KINDS)
        _require_choice("longitudinal_input_is", self.longitudinal_input_is, LONGITUDINAL_KINDS)
        needed = ("accel_input",) if self.longitudinal_input_is == "acceleration" else ("throttle_input", "brake_input")
        for name in needed:
            if getattr(self, name) is None:
                raise WorkbenchInputError(
                    f"longitudinal_input_is = {self.longitudinal_input_is!r} needs {name}; got \"none\""
                )
        for f in fields(self):
            if f.name.endswith("_scale"):
                scale = getattr(self, f.name)
                if not math.isfinite(scale) or scale == 0.0:
                    raise WorkbenchInputError(f"{f.name} must be a finite number other than 0; got {value_text(scale)}")
        trailer = [self.trailer_x_output, self.trailer_y_output]
        if (trailer[0] is None) != (trailer[1] is None):
            raise WorkbenchInputError("trailer_x_output and trailer_y_output are given together or both \"none\"")
        if trailer[0] is not None and self.hitch_to_trailer_axle_m is None:
            raise WorkbenchInputError(
                "trailer outputs need hitch_to_trailer_axle_m (the trailer's outline); got \"none\""
            )
        if self.hitch_to_trailer_axle_m is not None:
            require_in_range("hitch_to_trailer_axle_m", self.hitch_to_trailer_axle_m, 0.5, 20.0, "m")
        _require_pair("payload_parameter", self.payload_parameter, "payload_kg", self.payload_kg)
        if self.payload_kg is not None:
            require_in_range("payload_kg", self.payload_kg, 0.0, 100_000.0, "kg")
        _require_pair("friction_parameter", self.friction_parameter, "road_friction", self.road_friction)
        if self.road_friction is not None:
            require_positive("road_friction", self.road_friction)

    @property
    def has_single_track(self) -> bool:
        """Whether the single track (mass, inertia, axles and tyres) is given."""
        return self.mass_kg is not None

    def input_names(self) -> tuple[str, ...]:
        """The FMU's input variables this mapping sets, steering first.

        Returns
        -------
        tuple of str
            The steering input, then the acceleration input, or the throttle and brake inputs.
        """
        if self.longitudinal_input_is == "acceleration":
            return (self.steering_input, str(self.accel_input))
        return (self.steering_input, str(self.throttle_input), str(self.brake_input))

    def output_fields(self) -> tuple[str, ...]:
        """The mapping's output fields in use: REQUIRED_OUTPUTS, then the OPTIONAL_OUTPUTS given.

        Returns
        -------
        tuple of str
            The names of the fields of this dataclass that name an FMU output variable, in that order.
        """
        return REQUIRED_OUTPUTS + tuple(name for name in OPTIONAL_OUTPUTS if getattr(self, name) is not None)

    def parameter_names(self) -> tuple[str, ...]:
        """The FMU parameters this mapping sets before a run: speed, payload, friction (those given).

        Returns
        -------
        tuple of str
            The FMU's parameter variable names, in that order; empty when none is given.
        """
        names = (self.speed_parameter, self.payload_parameter, self.friction_parameter)
        return tuple(name for name in names if name is not None)


def _require_choice(name: str, value: str, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        raise WorkbenchInputError(f"{name} must be one of {', '.join(allowed)}; got {value_text(value)}")


def _require_pair(parameter_field: str, parameter: str | None, value_field: str, value: float | None) -> None:
    """A start value goes with the FMU parameter it is written to: both given or both "none"."""
    if (parameter is None) != (value is None):
        raise WorkbenchInputError(
            f"{parameter_field} and {value_field} are given together or both \"none\"; got {value_text(parameter)} "
            f"and {value_text(value)}"
        )


__all__ = ["FmuPlantParams"]
