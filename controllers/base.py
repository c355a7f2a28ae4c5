"""The one small interface every lateral controller implements.

A controller is built once for a vehicle (its geometry and limits) and a frozen config, `reset` for a path and
its sample time, then stepped at that rate with what GPS/IMU and the steering sensor give. It returns a
steering-wheel angle command. Whatever it wants logged about its last step (lookahead, solver status, ...) it
exposes as `diagnostics`, which the simulator records as `ctrl_<name>` columns. Controllers contain no plotting
and no I/O.
"""

from __future__ import annotations

import math
import sys
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar

from workbench.path import ReferencePath
from workbench.vehicles.base import VehicleGeometry

_NO_DIAGNOSTICS: Mapping[str, float] = MappingProxyType({})


@dataclass(frozen=True, slots=True)
class Measurement:
    """What the sensors give at one controller step (SI units).

    x_m, y_m: position of the reference point (the tractor's rear-axle centre, where the paper measures CTE);
    vx_mps, vy_mps: its velocity in the vehicle frame; yaw_rad, yaw_rate_rad_s: heading and its rate;
    steer_wheel_rad: measured steering-wheel angle; t_s: time.
    """

    t_s: float
    x_m: float
    y_m: float
    vx_mps: float
    vy_mps: float
    yaw_rad: float
    yaw_rate_rad_s: float
    steer_wheel_rad: float

    @property
    def speed_mps(self) -> float:
        return math.hypot(self.vx_mps, self.vy_mps)


class Controller(ABC):
    """Base class: subclasses set `name`, `config_type` and implement `reset` and `step`."""

    name: ClassVar[str]
    config_type: ClassVar[type]

    def __init__(self, geometry: VehicleGeometry, config: Any | None = None, vehicle: object | None = None) -> None:
        """`geometry`: the steered vehicle's; `config`: an instance of `config_type` (its defaults when None);
        `vehicle`: the steered vehicle's model (a `VehicleModel`), for controllers that predict with it (the
        MPCs); geometric controllers ignore it."""
        self.geometry = geometry
        self.config = config if config is not None else self.config_type()
        if not isinstance(self.config, self.config_type):
            raise TypeError(f"{self.name} takes a {self.config_type.__name__}; got {type(self.config).__name__}")

    @classmethod
    def summary(cls) -> str:
        """The first line of the controller's module docstring, for `workbench controllers`."""
        doc = sys.modules[cls.__module__].__doc__ or cls.__name__
        return doc.strip().splitlines()[0]

    @abstractmethod
    def reset(self, path: ReferencePath, sample_time_s: float) -> None:
        """Forget all state; the next step is the first on `path`; steps come every `sample_time_s` seconds."""

    @abstractmethod
    def step(self, measurement: Measurement, path: ReferencePath) -> float:
        """Steering-wheel angle command (rad) for this step; always finite and within the vehicle's limit."""

    @property
    def diagnostics(self) -> Mapping[str, float]:
        """Internal signals of the last step, to be logged (empty by default)."""
        return _NO_DIAGNOSTICS

    def saturate(self, steer_wheel_rad: float) -> float:
        """Clip a steering-wheel angle to the vehicle's limit."""
        limit = self.geometry.max_steer_wheel_angle_rad
        return min(max(steer_wheel_rad, -limit), limit)
