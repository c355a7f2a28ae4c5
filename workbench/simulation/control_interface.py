"""What the simulator and a lateral controller exchange: the `Measurement` the sensors give at a controller step,
and the `SteeringController` protocol the simulator drives (reset for a path, step to a steering-wheel command,
diagnostics to log). `controllers.base.Controller` implements it; the simulator knows only this interface, so the
simulation layer lies below the controllers."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    import numpy as np

    from workbench.base.path import ReferencePath

#: The diagnostics flags (1.0 or 0.0) a controller adds to its own signals: its last measurement was implausible,
#: or its last command was non-finite, and it held its previous command (controllers/base.py).
MEASUREMENT_REJECTED = "measurement_rejected"
COMMAND_REJECTED = "command_rejected"


@dataclass(frozen=True, slots=True)
class Measurement:
    """What the sensors give at one controller step (SI units).

    The reference point is the tractor's rear-axle centre, where the paper measures CTE. Each field is a real
    number: a float, an int or a NumPy real scalar. A controller's step (`controllers.base`) holds its last command
    on a frame with a field that is not (a bool, a complex number, a string, None, an array), as on a non-finite or
    implausible one, and says which field and value in its `rejection`.
    """

    t_s: float  # s; time of the measurement
    x_m: float  # m; x of the reference point
    y_m: float  # m; y of the reference point
    vx_mps: float  # m/s; the reference point's longitudinal velocity, in the vehicle frame
    vy_mps: float  # m/s; the reference point's lateral velocity, in the vehicle frame
    yaw_rad: float  # rad; heading, counter-clockwise from x
    yaw_rate_rad_s: float  # rad/s; heading rate, counter-clockwise positive
    steer_wheel_rad: float  # rad; measured steering-wheel angle, positive left

    @property
    def speed_mps(self) -> float:
        return math.hypot(self.vx_mps, self.vy_mps)


class SteeringController(Protocol):
    """A lateral controller as the simulator drives it (`controllers.base.Controller` is the implementation)."""

    @property
    def name(self) -> str:
        """The controller's registry name (a class constant of each implementation)."""
        ...

    def reset(self, path: ReferencePath, sample_time_s: float) -> None:
        """Forget all state; steps on `path` come every `sample_time_s` seconds."""

    def step(self, measurement: Measurement, path: ReferencePath) -> float:
        """The steering-wheel angle command (rad) for this measurement: finite, within the vehicle's limit."""
        ...

    def run_warnings(self, path: ReferencePath, sample_time_s: float) -> list[str]:
        """Optional: what to tell a person before a run on `path` (planned speeds included) with steps every
        `sample_time_s` s, one sentence each (e.g. an option that cannot act at these speeds); the simulation prints
        them before the run (`Simulation.warnings`). A controller without the method has none."""
        ...

    @property
    def diagnostic_names(self) -> tuple[str, ...]:
        """The names of `diagnostic_values`, the same every step from `reset` on."""
        ...

    @property
    def diagnostic_values(self) -> np.ndarray:
        """The last step's signals in the order of `diagnostic_names` (the controller's array: copy what you keep)."""
        ...

    @property
    def diagnostics(self) -> Mapping[str, float]:
        """The last step's signals to log (`ctrl_<name>` columns), MEASUREMENT_REJECTED and COMMAND_REJECTED
        among them."""
        ...

    @property
    def rejection(self) -> str:
        """Why the last rejected step was rejected, in words."""
        ...
