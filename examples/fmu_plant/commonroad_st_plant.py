"""CommonRoad's single-track car as a plant with the workbench's interface, in plain Python: the model inside the
example FMUs (`commonroad_st_fmi2.py`, `commonroad_st_fmi3.py`) and, stepped directly, their reference.

The dynamics are CommonRoad's own function `vehiclemodels.vehicle_dynamics_st` (Althoff & Wuersching, "CommonRoad:
Vehicle Models", 2020: a single track with linear tyres and load transfer, switching to a kinematic model below
0.1 m/s) on CommonRoad's BMW 320i parameters (`parameters_vehicle2`). Its inputs are the front road-wheel angle
*rate* and the acceleration; this plant closes a first-order steering actuator around it (road-wheel angle command
in, time constant STEERING_TIME_CONSTANT_S, CommonRoad's own rate and angle limits after it) and holds the car at
rest instead of reversing when it brakes at standstill. Integration: fixed-step RK4 of STEP_S. Outputs are at the
rear-axle centre, the workbench's reference point: p_rear = p_cg - b (cos yaw, sin yaw).
"""

from __future__ import annotations

import math

from vehiclemodels.init_st import init_st
from vehiclemodels.parameters_vehicle2 import parameters_vehicle2
from vehiclemodels.vehicle_dynamics_st import vehicle_dynamics_st

#: RK4 step (s): the workbench's plant rate, 1 kHz.
STEP_S = 0.001
#: Steering actuator time constant (s): an electric power-steering position loop (assumed; CommonRoad gives none).
STEERING_TIME_CONSTANT_S = 0.05

#: The outputs, in order: rear-axle position (m), yaw (rad), body-frame speeds at the rear axle (m/s), yaw rate
#: (rad/s), front road-wheel angle (rad), lateral acceleration at the rear axle (m/s^2).
OUTPUT_NAMES = ("x_rear", "y_rear", "psi", "vx_rear", "vy_rear", "yaw_rate", "delta", "ay_rear")


class CommonRoadSTPlant:
    """CommonRoad's single track (module docstring) with a steering actuator, started at rest in steering."""

    def __init__(self) -> None:
        self.p = parameters_vehicle2()
        self.delta_cmd = 0.0  # road-wheel angle command (rad)
        self.accel_cmd = 0.0  # longitudinal acceleration command (m/s^2)
        self.x = init_st([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])

    def start(self, speed_mps: float) -> None:
        """At the origin heading along x at `speed_mps`, wheels straight."""
        b = self.p.b
        self.x = init_st([b, 0.0, 0.0, speed_mps, 0.0, 0.0, 0.0])

    def _inputs(self, x: list[float]) -> list[float]:
        """CommonRoad's inputs (steering rate, acceleration) for state x: the actuator's rate, and no braking
        below standstill."""
        accel = 0.0 if x[3] <= 0.0 and self.accel_cmd < 0.0 else self.accel_cmd
        return [(self.delta_cmd - x[2]) / STEERING_TIME_CONSTANT_S, accel]

    def _rhs(self, x: list[float]) -> list[float]:
        return vehicle_dynamics_st(x, self._inputs(x), self.p)

    def step(self, duration_s: float) -> None:
        """Integrate `duration_s` with the commands held, in RK4 steps of at most STEP_S."""
        n = max(1, math.ceil(duration_s / STEP_S - 1e-9))
        h = duration_s / n
        x = self.x
        for _ in range(n):
            k1 = self._rhs(x)
            k2 = self._rhs([a + 0.5 * h * k for a, k in zip(x, k1, strict=True)])
            k3 = self._rhs([a + 0.5 * h * k for a, k in zip(x, k2, strict=True)])
            k4 = self._rhs([a + h * k for a, k in zip(x, k3, strict=True)])
            x = [a + h / 6.0 * (p + 2.0 * q + 2.0 * r + s) for a, p, q, r, s in zip(x, k1, k2, k3, k4, strict=True)]
            x[3] = max(x[3], 0.0)  # held at rest, never reversing
        self.x = x

    def outputs(self) -> list[float]:
        """OUTPUT_NAMES' values for the current state and commands."""
        x, b = self.x, self.p.b
        f = self._rhs(x)
        v, yaw, r, beta = x[3], x[4], x[5], x[6]
        ay = f[3] * math.sin(beta) + v * (r + f[6]) * math.cos(beta) - b * f[5]
        return [
            x[0] - b * math.cos(yaw),
            x[1] - b * math.sin(yaw),
            yaw,
            v * math.cos(beta),
            v * math.sin(beta) - b * r,
            r,
            x[2],
            ay,
        ]
