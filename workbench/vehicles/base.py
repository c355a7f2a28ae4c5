"""The plant interface every vehicle model implements, and what controllers may know about a vehicle.

A model is a set of ODEs x' = f(x, u) with named states, driven by two inputs: the steering-wheel angle command
(rad) and the longitudinal acceleration command (m/s^2). The simulator calls `advance` once per controller step;
a model integrates its own fine steps inside (RK4 at the plant rate, `workbench.vehicles.integration`, compiled
with numba where it matters), so no
Python-level ODE solver runs per step.

Conventions: SI units; x east, y north, yaw counter-clockwise from x; the reference point the controllers see is
the (tractor's) rear-axle centre, where the paper measures cross-track error.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import ClassVar, Generic, Protocol, TypeVar

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.geometry import VehicleGeometry
from workbench.vehicles.single_track import PredictionParams, params_from_geometry

#: Outputs every model provides, in this order, at the reference point (rear-axle centre).
STANDARD_OUTPUTS: tuple[str, ...] = (
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_rad_s",
    "steer_wheel_rad",
    "road_wheel_angle_rad",
    "lat_accel_mps2",
)

#: Range of the road-friction scale `VehicleModel.set_road_friction` accepts (Pacejka's lambda_mu), relative to the
#: road the tyre data describe (1.0): from about ice (0.05) to a road half as grippy again (1.5).
ROAD_FRICTION_RANGE: tuple[float, float] = (0.05, 1.5)

class VehicleParams(Protocol):
    """What the base class reads of every model's parameters (a frozen dataclass per model): the steering ratio
    and the longitudinal limits the acceleration command is clipped to."""

    @property
    def steering_ratio(self) -> float:
        """Steering-wheel angle / road-wheel angle."""
        ...

    @property
    def max_accel_mps2(self) -> float:
        """The largest acceleration command (m/s^2, > 0); larger ones are clipped to it."""
        ...

    @property
    def max_decel_mps2(self) -> float:
        """The largest braking (m/s^2, > 0); an acceleration command below minus this is clipped to it."""
        ...


#: A model's parameter dataclass (`VehicleModel[TheirParams]`).
ParamsT = TypeVar("ParamsT", bound=VehicleParams)


class PlantStepError(WorkbenchInputError):
    """A plant failed a step and cannot go on (an FMU plant's doStep returned an error): the message says when and
    why. The simulator ends the run with status `plant_failed`; any other caller shows it as an error."""


class VehicleModel(ABC, Generic[ParamsT]):
    """A plant. Subclasses (`VehicleModel[TheirParams]`) set `name`, `state_names`, `extra_output_names`, and in
    `__init__(params)` `params` (a frozen dataclass, `VehicleParams`) and `_geometry`; they implement `advance` and
    `outputs`.

    The default `initial_state` suits models whose first four states are x_m, y_m, yaw_rad and the longitudinal
    speed, with every other state zero except those in `heading_states` (yaws of trailing units, in line).

    Extra outputs with these names are picked up by the metrics: `ltr` (load transfer ratio, max over axle
    groups, |LTR| = 1 is wheel lift-off), `trailer_x_m`/`trailer_y_m` (the trailer's rear-axle centre).

    Road friction: a model with tyres (`has_tyres`) implements `_apply_road_friction`, and `set_road_friction`
    then scales its tyres' peak friction between controller steps (see there).
    """

    name: ClassVar[str]
    state_names: ClassVar[tuple[str, ...]]
    extra_output_names: ClassVar[tuple[str, ...]] = ()
    #: States that start at the heading yaw_rad (the yaw of a trailing unit: the units start in line).
    heading_states: ClassVar[tuple[str, ...]] = ()
    #: Whether the model has tyres whose friction `set_road_friction` scales (a subclass setting True implements
    #: `_apply_road_friction`).
    has_tyres: ClassVar[bool] = False
    params: ParamsT
    _geometry: VehicleGeometry
    #: The road-friction scale in force; an instance attribute once `set_road_friction` has been called.
    _road_friction: float = 1.0

    def __init__(self, params: ParamsT) -> None:
        """A model is built from its parameters alone; a subclass's `__init__` (which need not call this one) also
        sets `_geometry` and whatever it computes from them."""
        self.params = params

    @property
    def geometry(self) -> VehicleGeometry:
        """Controller-facing geometry and limits."""
        return self._geometry

    def initial_state(self, x_m: float, y_m: float, yaw_rad: float, speed_mps: float) -> np.ndarray:
        """State at rest in steering (straight wheels), reference point at (x, y), heading yaw, moving at speed.

        Parameters
        ----------
        x_m, y_m : float
            Position of the reference point, the (tractor's) rear-axle centre (m).
        yaw_rad : float
            Heading (rad, counter-clockwise from x); trailing units start in line with it.
        speed_mps : float
            Longitudinal speed (m/s).

        Returns
        -------
        numpy.ndarray
            The state, one value per name of `state_names`.
        """
        state = np.zeros(len(self.state_names))
        state[0], state[1], state[2], state[3] = x_m, y_m, yaw_rad, speed_mps
        for name in self.heading_states:
            state[self.state_names.index(name)] = yaw_rad
        return state

    def _inputs(self, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> tuple[float, float]:
        """(road-wheel angle command (rad), acceleration (m/s^2)), each clipped to the vehicle's limits.

        Each clip is min(max(value, low), high) written out as the comparisons those builtins make (the same
        result, a NaN passed through), at half their cost: this runs twice a controller step."""
        g, p = self._geometry, self.params
        high = g.max_road_wheel_angle_rad
        low = -high
        delta_cmd = steer_wheel_cmd_rad / g.steering_ratio
        delta_cmd = low if low > delta_cmd else delta_cmd
        delta_cmd = high if high < delta_cmd else delta_cmd
        low, high = -p.max_decel_mps2, p.max_accel_mps2
        accel = low if low > accel_cmd_mps2 else accel_cmd_mps2
        accel = high if high < accel else accel
        return delta_cmd, accel

    @property
    def road_friction(self) -> float:
        """The tyre-road friction scale in force (1.0, the road of the tyre data, until `set_road_friction`)."""
        return self._road_friction

    def set_road_friction(self, scale: float) -> None:
        """Scale the tyres' peak friction by `scale` for the following `advance` and `outputs` calls.

        Pacejka's friction scaling factor lambda_mu ("Tyre and Vehicle Dynamics", chapter 4): the peak force becomes
        D = scale x friction x load while the cornering stiffness (B C D, the slope at zero slip) is kept, so a
        slippery road lowers the limit, not the linear handling. The scale holds until set again (the simulator
        may set it between any two controller steps, e.g. varying along the path); 1.0 is exactly the model as
        built. `params`, `single_track()` (what a controller is told) and the model's state are unchanged: the
        road is not the vehicle. `scale` must be a finite number in ROAD_FRICTION_RANGE; a model without tyres
        accepts only 1.0.

        Parameters
        ----------
        scale : float
            The peak-friction scale lambda_mu (dimensionless, 0.05 to 1.5; 1.0 the road of the tyre data).

        Raises
        ------
        WorkbenchInputError
            A scale that is not a finite number in ROAD_FRICTION_RANGE, or other than 1.0 for a model without
            tyres (the message lists the models with tyres).
        """
        require_in_range("road_friction", scale, *ROAD_FRICTION_RANGE)
        scale = float(scale)
        if not self.has_tyres:
            if scale != 1.0:
                raise WorkbenchInputError(
                    f"road_friction {scale!r} needs tyres, and the {self.name} model has none (it does not slip: "
                    f"only 1.0 is accepted); use a model with tyres ({', '.join(models_with_tyres())})"
                )
            return
        if scale != self._road_friction:
            self._apply_road_friction(scale)
            self._road_friction = scale

    def _apply_road_friction(self, scale: float) -> None:
        """Make the tyres' peak friction `scale` times that of the parameters (scale 1.0 must restore the model as
        built bit for bit); called by `set_road_friction` with a validated scale that differs from the one in force."""
        raise NotImplementedError(f"{type(self).__name__} sets has_tyres but does not implement _apply_road_friction")

    @abstractmethod
    def advance(
        self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float, dt_s: float, substeps: int
    ) -> np.ndarray:
        """Integrate `substeps` fixed steps of dt_s / substeps with the inputs held; return the new state.

        The commands are clipped to the vehicle's limits (road-wheel angle, acceleration and braking) before they
        drive the model.

        Parameters
        ----------
        state : numpy.ndarray
            The state at the start of the step, one value per name of `state_names`.
        steer_wheel_cmd_rad : float
            Steering-wheel angle command (rad, left positive); the road wheels get it divided by the steering ratio.
        accel_cmd_mps2 : float
            Longitudinal acceleration command (m/s^2, braking negative).
        dt_s : float
            The step (s, > 0): one controller period.
        substeps : int
            Fixed integration steps within `dt_s` (>= 1): the plant rate divided by the controller rate.

        Returns
        -------
        numpy.ndarray
            The state at the end of the step.
        """

    @abstractmethod
    def outputs(self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> np.ndarray:
        """STANDARD_OUTPUTS followed by extra_output_names, as one float array.

        Parameters
        ----------
        state : numpy.ndarray
            The state, one value per name of `state_names`.
        steer_wheel_cmd_rad : float
            Steering-wheel angle command in force (rad), for the outputs that depend on the inputs.
        accel_cmd_mps2 : float
            Longitudinal acceleration command in force (m/s^2).

        Returns
        -------
        numpy.ndarray
            One value per name of `output_names`, SI units.
        """

    @property
    def output_names(self) -> tuple[str, ...]:
        """The names of `outputs`, in order: STANDARD_OUTPUTS, then `extra_output_names`."""
        return STANDARD_OUTPUTS + self.extra_output_names

    def single_track(self, source: str | None = None) -> PredictionParams:
        """The vehicle's single-track equivalent, what a model-based controller predicts with (`single_track.py`);
        this default, for a model that knows no better, is the kinematic single track of its geometry.

        Parameters
        ----------
        source : str or None
            Where the numbers come from, for messages and reports; this default names its own (the geometry only),
            a model that overrides it names its parameters when None.

        Returns
        -------
        PredictionParams
            The geometry and steering limits with an assumed actuator time constant and no tyres
            (`params_from_geometry`).
        """
        return params_from_geometry(self.geometry)

    def describe(self) -> str:
        """One line with the key parameters, for `workbench vehicles`.

        Returns
        -------
        str
            The wheelbase (m), steering ratio, maximum road-wheel angle (deg) and width (m).
        """
        g = self.geometry
        return (
            f"wheelbase {g.wheelbase_m:.3f} m, steering ratio {g.steering_ratio:g}, "
            f"max road-wheel angle {math.degrees(g.max_road_wheel_angle_rad):.0f} deg, width {g.width_m:g} m"
        )


class CompiledVehicleModel(VehicleModel[ParamsT]):
    """A model whose numerics are compiled with numba, on a parameter array `_p` built in `__init__`.

    Subclasses set `_advance_kernel = staticmethod(_advance)`, their module's cached
    `_advance(state, p, delta_cmd, accel, h, n)` (`integration.rk4` over the model's derivative), and either
    `_outputs_kernel = staticmethod(_outputs)`, a compiled `_outputs(state, p, delta_cmd, accel, steering_ratio)`,
    or their own `outputs`.
    """

    _p: np.ndarray
    _advance_kernel: ClassVar[Callable[..., np.ndarray]]
    _outputs_kernel: ClassVar[Callable[..., np.ndarray]]

    def advance(
        self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float, dt_s: float, substeps: int
    ) -> np.ndarray:
        """Integrate `substeps` fixed RK4 steps of dt_s / substeps with the inputs held, in the compiled kernel;
        return the new state.

        The commands are clipped to the vehicle's limits (road-wheel angle, acceleration and braking) before they
        drive the model.

        Parameters
        ----------
        state : numpy.ndarray
            The state at the start of the step, one value per name of `state_names`.
        steer_wheel_cmd_rad : float
            Steering-wheel angle command (rad, left positive); the road wheels get it divided by the steering ratio.
        accel_cmd_mps2 : float
            Longitudinal acceleration command (m/s^2, braking negative).
        dt_s : float
            The step (s, > 0): one controller period.
        substeps : int
            Fixed integration steps within `dt_s` (>= 1): the plant rate divided by the controller rate.

        Returns
        -------
        numpy.ndarray
            The state at the end of the step.
        """
        delta_cmd, accel = self._inputs(steer_wheel_cmd_rad, accel_cmd_mps2)
        return self._advance_kernel(state, self._p, delta_cmd, accel, dt_s / substeps, substeps)

    def outputs(self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> np.ndarray:
        """STANDARD_OUTPUTS followed by extra_output_names, as one float array, from the compiled kernel.

        Parameters
        ----------
        state : numpy.ndarray
            The state, one value per name of `state_names`.
        steer_wheel_cmd_rad : float
            Steering-wheel angle command in force (rad), for the outputs that depend on the inputs.
        accel_cmd_mps2 : float
            Longitudinal acceleration command in force (m/s^2).

        Returns
        -------
        numpy.ndarray
            One value per name of `output_names`, SI units.
        """
        delta_cmd, accel = self._inputs(steer_wheel_cmd_rad, accel_cmd_mps2)
        return self._outputs_kernel(
            np.asarray(state, dtype=float), self._p, delta_cmd, accel, self.params.steering_ratio
        )


def models_with_tyres() -> list[str]:
    """The names of the vehicle models with tyres (`VehicleModel.has_tyres`), sorted: those a road friction other
    than 1.0 needs. Read from the model classes themselves, every one of them defined once the package
    `workbench.vehicles` (its registry, which imports this module) is imported.

    Returns
    -------
    list of str
        The models' registered names, e.g. "commonroad-mb", "dynamic-bicycle" and "tractor-semitrailer".
    """
    names: set[str] = set()
    classes = VehicleModel.__subclasses__()
    while classes:
        cls = classes.pop()
        classes.extend(cls.__subclasses__())
        if cls.has_tyres and isinstance(getattr(cls, "name", None), str):
            names.add(cls.name)
    return sorted(names)


__all__ = ["CompiledVehicleModel", "PlantStepError", "VehicleModel", "VehicleParams", "models_with_tyres"]
