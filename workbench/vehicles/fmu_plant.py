"""A plant from the user's FMU (vehicle file model type `fmu`): any co-simulation FMU, FMI 2.0 or 3.0, steered
through the mapping of its variables to the plant interface (`fmu_plant_params.FmuPlantParams`).

The FMU keeps its own state and integrates it with its own solver; the workbench's state of this plant is what it
reads back after each controller step: the standard outputs, the extras the mapping gives, and the FMU's time
(`fmu_time_s`). So `advance` continues from the state it last returned (or from `initial_state`, which restarts the
FMU): another state is refused, as the FMU cannot be put back into it. `substeps` is not used: a controller period
is split into doSteps of `communication_step_s`.

Frames: the FMU starts where its own initial values put it; the workbench moves and turns its outputs rigidly so
that the reference point starts at the pose `initial_state` asks for (the FMU's initial position and yaw are the
origin of that transform). The initial speed is written to `speed_parameter` before initialisation.

Inputs: the road-wheel command and the acceleration are clipped to the vehicle's limits (`VehicleModel._inputs`),
then written as the mapping says (steering-wheel angle = road-wheel angle x steering_ratio; throttle and brake as
fractions of the acceleration limits). Road friction: with `friction_parameter`, `set_road_friction(scale)` writes
road_friction x scale to it between controller steps; without it only 1.0 is accepted.

A plant with load transfer (`ltr_output`) also gives the rear axle's path curvature (`path_curvature_1pm`, what the
rollover limits read): vx a_y / (vx^2 + vy^2)^(3/2) from the mapped outputs (`reference_point.py`'s curvature without
its longitudinal-acceleration term, which the mapping does not carry; small at a near-constant speed), and the
kinematic tan(road-wheel angle) / wheelbase at standstill.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.base import ROAD_FRICTION_RANGE, STANDARD_OUTPUTS, VehicleModel
from workbench.vehicles.fmu_description import read_fmu_interface
from workbench.vehicles.fmu_instance import FmuInstance
from workbench.vehicles.fmu_plant_params import OPTIONAL_OUTPUTS, FmuPlantParams
from workbench.vehicles.geometry import VehicleGeometry
from workbench.vehicles.single_track import PredictionParams, SingleTrackParams

#: The extra output a plant with load transfer (an `ltr` output) gains: the rear axle's path curvature (1/m), which
#: the rollover limits of the tuning chain read (`tuning/rollover.py`).
PATH_CURVATURE = "path_curvature_1pm"
#: Below this speed (m/s) the path curvature is the kinematic tan(road-wheel angle) / wheelbase.
_STANDSTILL_MPS = 1e-3
#: The state entry holding the FMU's time (s), after the outputs.
TIME_STATE = "fmu_time_s"
#: Relative slack (of the communication step) within which a controller period counts as a multiple of it.
_STEP_SLACK = 1e-9


class FmuPlant(VehicleModel[FmuPlantParams]):
    """A plant from the user's FMU (module docstring)."""

    name: ClassVar[str] = "fmu"
    params_type: ClassVar[type] = FmuPlantParams

    def __init__(self, params: FmuPlantParams) -> None:
        self.params = p = params
        self._geometry = VehicleGeometry.from_params(p, p.wheelbase_m)
        self.interface = read_fmu_interface(p)
        # has_tyres and the names are class constants of every other model; an FMU plant's follow from its file, so
        # they are set per instance (the base class reads them through self either way)
        self.has_tyres = p.friction_parameter is not None  # type: ignore[misc]
        extras = tuple(OPTIONAL_OUTPUTS[f] for f in p.output_fields() if f in OPTIONAL_OUTPUTS)
        self._with_curvature = p.ltr_output is not None
        self.extra_output_names = extras + ((PATH_CURVATURE,) if self._with_curvature else ())  # type: ignore[misc]
        self.state_names = (*STANDARD_OUTPUTS, *self.extra_output_names, TIME_STATE)  # type: ignore[misc]
        refs = self.interface.value_references
        self._input_refs = [refs[name] for name in p.input_names()]
        self._output_fields = p.output_fields()
        self._output_refs = [refs[getattr(p, f)] for f in self._output_fields]
        self._output_scales = np.array([1.0 / getattr(p, f"{f}_scale") for f in self._output_fields])
        self._fmu = FmuInstance(self.interface)
        self._state: np.ndarray | None = None
        self._origin = (0.0, 0.0, 0.0, 0.0)  # the FMU's x, y at the start; the workbench's
        self._turn = (1.0, 0.0, 0.0)  # cos, sin of the frame rotation; the rotation (rad)

    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as its parameters (a worker process opens the FMU again), with the road friction in force."""
        return (_rebuilt, (self.params, self.road_friction))

    def describe(self) -> str:
        return f"FMU {self.params.fmu_file} (FMI {self.interface.fmi_major}.0): " + super().describe()

    def single_track(self, source: str | None = None) -> PredictionParams:
        """What the vehicle file gives: the single track (mass, inertia, axles, tyres) or the identified lag, or
        the kinematic single track of the geometry."""
        from workbench.vehicles.steering_lag import read_lag_file

        p = self.params
        track = None
        if p.has_single_track:
            # SINGLE_TRACK_FIELDS are given all together or not at all (FmuPlantParams checks): none is None here,
            # which the checker cannot follow through has_single_track, hence the ignores
            track = SingleTrackParams(
                mass_kg=float(p.mass_kg),  # type: ignore[arg-type]
                yaw_inertia_kgm2=float(p.yaw_inertia_kgm2),  # type: ignore[arg-type]
                cg_to_front_axle_m=float(p.cg_to_front_axle_m),  # type: ignore[arg-type]
                cg_to_rear_axle_m=p.wheelbase_m - float(p.cg_to_front_axle_m),  # type: ignore[arg-type]
                front_cornering_stiffness_n_per_rad=float(p.front_cornering_stiffness_n_per_rad),  # type: ignore[arg-type]
                rear_cornering_stiffness_n_per_rad=float(p.rear_cornering_stiffness_n_per_rad),  # type: ignore[arg-type]
                front_peak_force_n=float(p.front_peak_force_n),  # type: ignore[arg-type]
                rear_peak_force_n=float(p.rear_peak_force_n),  # type: ignore[arg-type]
            )
        lag = read_lag_file(p.lag_file) if p.lag_file is not None else None
        what = "single track" if track is not None else "kinematic single track"
        source = (source or f"the {self.name} vehicle file") + f" ({what}{', identified lag' if lag else ''})"
        return PredictionParams.from_actuator(p, p.wheelbase_m, source, track, lag)

    @property
    def rollover_threshold_g(self) -> float | None:
        """The static rollover threshold the vehicle file states (g), or None."""
        return self.params.rollover_threshold_g

    def set_road_friction(self, scale: float) -> None:
        """`VehicleModel.set_road_friction`: written to friction_parameter (road_friction x scale); a plant without
        one accepts only 1.0, and the refusal says how to map one."""
        if self.params.friction_parameter is None and scale != 1.0:
            require_in_range("road_friction", scale, *ROAD_FRICTION_RANGE)
            raise WorkbenchInputError(
                f"road_friction {float(scale)!r} needs a friction parameter, and this fmu plant's vehicle file maps "
                "none (friction_parameter = \"none\": only 1.0 is accepted); map a tunable FMU parameter that scales "
                "the tyres' friction with friction_parameter and road_friction"
            )
        super().set_road_friction(scale)

    def _apply_road_friction(self, scale: float) -> None:
        p = self.params
        if self._state is not None:  # a model with tyres: its friction parameter and value are given (the ignore)
            ref = self.interface.value_references[str(p.friction_parameter)]
            self._fmu.set_parameter(ref, float(p.road_friction) * scale)  # type: ignore[arg-type]

    def _start_values(self) -> dict[int, float]:
        p, refs = self.params, self.interface.value_references
        values = {}
        # a mapped parameter has its value (FmuPlantParams checks), which the checker cannot follow: the ignores
        if p.payload_parameter is not None:
            values[refs[p.payload_parameter]] = float(p.payload_kg)  # type: ignore[arg-type]
        if p.friction_parameter is not None:
            values[refs[p.friction_parameter]] = float(p.road_friction) * self.road_friction  # type: ignore[arg-type]
        return values

    def initial_state(self, x_m: float, y_m: float, yaw_rad: float, speed_mps: float) -> np.ndarray:
        """Restart the FMU at `speed_mps` (written to speed_parameter) and place its outputs' frame so that the
        reference point is at (x_m, y_m) heading yaw_rad (module docstring)."""
        p = self.params
        values = self._start_values()
        if p.speed_parameter is not None:
            values[self.interface.value_references[p.speed_parameter]] = float(speed_mps) * p.vx_output_scale
        self._fmu.start(values)
        raw = np.array(self._fmu.outputs(self._output_refs)) * self._output_scales
        turn = float(yaw_rad) - raw[2]
        self._turn = (math.cos(turn), math.sin(turn), turn)
        self._origin = (raw[0], raw[1], float(x_m), float(y_m))
        self._state = self._state_from(raw)
        return self._state.copy()

    def _state_from(self, raw: np.ndarray) -> np.ndarray:
        """The workbench state from the scaled raw outputs (REQUIRED_OUTPUTS order, then the optional ones)."""
        p = self.params
        c, s, turn = self._turn
        fx, fy, x0, y0 = self._origin
        dx, dy = raw[0] - fx, raw[1] - fy
        angle = raw[6]
        if p.steering_output_is == "road_wheel_angle":
            steer_wheel, road_wheel = angle * p.steering_ratio, angle
        else:
            steer_wheel, road_wheel = angle, angle / p.steering_ratio
        state = [x0 + c * dx - s * dy, y0 + s * dx + c * dy, raw[2] + turn, raw[3], raw[4], raw[5]]
        state += [steer_wheel, road_wheel, raw[7]]
        extras = dict(zip(self._output_fields[8:], raw[8:].tolist(), strict=True))
        for field, value in extras.items():
            if field == "trailer_x_output":
                tx, ty = value - fx, extras["trailer_y_output"] - fy
                state.append(x0 + c * tx - s * ty)
            elif field == "trailer_y_output":
                tx, ty = extras["trailer_x_output"] - fx, value - fy
                state.append(y0 + s * tx + c * ty)
            else:
                state.append(value)
        if self._with_curvature:  # a curve traced at (vx, vy) with lateral acceleration ay: a_x v_y is not known
            speed = math.hypot(raw[3], raw[4])
            standstill = speed <= _STANDSTILL_MPS
            state.append(math.tan(road_wheel) / p.wheelbase_m if standstill else raw[3] * raw[7] / speed**3)
        state.append(self._fmu.time_s)
        return np.array(state, dtype=float)

    def _command_values(self, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> list[float]:
        """The FMU's input values for these commands (clipped to the limits, then as the mapping says)."""
        p = self.params
        delta, accel = self._inputs(steer_wheel_cmd_rad, accel_cmd_mps2)
        steer = delta if p.steering_input_is == "road_wheel_angle" else delta * p.steering_ratio
        values = [steer * p.steering_input_scale]
        if p.longitudinal_input_is == "acceleration":
            values.append(accel * p.accel_input_scale)
        else:
            values.append(max(accel, 0.0) / p.max_accel_mps2 * p.throttle_input_scale)
            values.append(max(-accel, 0.0) / p.max_decel_mps2 * p.brake_input_scale)
        return values

    def advance(
        self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float, dt_s: float, substeps: int
    ) -> np.ndarray:
        """Run the FMU for dt_s with the commands held: doSteps of communication_step_s (the last one shorter when
        dt_s is not a multiple; an FMU that cannot take a variable step is refused then)."""
        current = self._state
        if current is None or (state is not current and not np.array_equal(state, current)):
            raise WorkbenchInputError(
                "an FMU plant continues only from the state it last returned (its own state lives inside the FMU); "
                "start from initial_state()"
            )
        h = self.params.communication_step_s
        steps = dt_s / h
        n = round(steps)
        last = 0.0
        if abs(steps - n) > _STEP_SLACK * max(1.0, steps):
            n = math.floor(steps)
            last = dt_s - n * h
            if not self.interface.variable_step:
                raise WorkbenchInputError(
                    f"a plant step of {dt_s:g} s is not a multiple of communication_step_s = {h:g} s, and the FMU "
                    "cannot take a variable step; choose a communication step that divides the controller period"
                )
        fmu = self._fmu
        fmu.set_inputs(self._input_refs, self._command_values(steer_wheel_cmd_rad, accel_cmd_mps2))
        step = fmu.step
        for _ in range(n):
            step(h)
        if last > 0.0:
            step(last)
        raw = np.array(fmu.outputs(self._output_refs)) * self._output_scales
        self._state = self._state_from(raw)
        return self._state

    def outputs(self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> np.ndarray:
        """The outputs read after the step that led to `state` (the state holds them)."""
        return np.array(state[:-1], dtype=float)


def _rebuilt(params: FmuPlantParams, road_friction: float) -> FmuPlant:
    """An FmuPlant from its parameters, at this road friction (unpickling)."""
    plant = FmuPlant(params)
    if road_friction != 1.0:
        plant.set_road_friction(road_friction)
    return plant
