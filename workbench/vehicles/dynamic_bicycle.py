"""Dynamic bicycle (single-track) car with magic-formula tyres and relaxation length, referenced at the rear axle.

Stands in for a CarSim C-class car. States (SI): x_m, y_m (rear-axle centre), yaw_rad, vx_mps (longitudinal
speed), vy_cg_mps (CG lateral velocity, body frame), yaw_rate_rad_s, road_wheel_angle_rad, fy_front_N,
fy_rear_N (axle lateral forces, lagging their steady-state value by the relaxation length).
    m (dvy + vx r) = Fyf cos(delta) + Fyr,   Iz dr = a Fyf cos(delta) - b Fyr,   dvx = a_x (realised command),
    dFy = (vx / sigma) (Fy_ss(alpha) - Fy),  Fy_ss = -mu Fz sin(C atan(B alpha - E (B alpha - atan(B alpha)))),
with B = k / (C mu) so that the cornering stiffness is k Fz, and Fz the axle load including the longitudinal
load transfer m a_x h / L (as CommonRoad's ST model). Below kinematic_blend_high_mps the lateral accelerations
blend into the kinematic bicycle's, so the model is well-posed at v = 0 and equals the kinematic bicycle there.
The steering actuator is the kinematic bicycle's: first order, rate- and angle-limited.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from workbench.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.base import VehicleGeometry, VehicleModel

G_MPS2 = 9.81
#: Time constant (s) with which the blended kinematic branch pulls the lateral states onto the no-slip values.
KINEMATIC_PULL_S = 0.02


@dataclass(frozen=True)
class DynamicBicycleParams:
    """A C-class car: CommonRoad vehicle 2 (BMW 320i, commonroad-vehicle-models `parameters_vehicle2`) with
    CommonRoad's magic-formula tyre coefficients (`parameters_tire.yaml`, from the ADAMS handbook).
    """

    mass_kg: float = 1093.3  # CommonRoad vehicle 2: m
    yaw_inertia_kgm2: float = 1791.6  # CommonRoad vehicle 2: I_z
    cg_to_front_axle_m: float = 1.156  # CommonRoad vehicle 2: a
    cg_to_rear_axle_m: float = 1.423  # CommonRoad vehicle 2: b
    cg_height_m: float = 0.575  # CommonRoad vehicle 2: h_cg
    width_m: float = 1.61  # CommonRoad vehicle 2: w
    front_cornering_coeff_per_rad: float = 21.92  # CommonRoad tyre: -p_ky1 (cornering stiffness / load)
    rear_cornering_coeff_per_rad: float = 21.92  # CommonRoad tyre: -p_ky1, as front (CommonRoad ST)
    tyre_friction: float = 1.0489  # CommonRoad tyre: p_dy1
    tyre_shape_factor: float = 1.3507  # CommonRoad tyre: p_cy1
    tyre_curvature_factor: float = -0.0074722  # CommonRoad tyre: p_ey1
    relaxation_length_m: float = 0.4  # assumed: passenger-car tyre, 0.3-0.5 m
    steering_ratio: float = 15.0  # assumed: typical passenger-car rack (14-16:1); CommonRoad gives none
    max_road_wheel_angle_rad: float = 1.066  # CommonRoad vehicle 2: steering.max
    max_road_wheel_rate_rad_s: float = 0.4  # CommonRoad vehicle 2: steering.v_max
    steering_time_constant_s: float = 0.05  # assumed: electric power-steering position loop
    max_accel_mps2: float = 3.0  # assumed comfort limit (CommonRoad's 11.5 m/s^2 is the tyre limit)
    max_decel_mps2: float = 8.0  # assumed: about 0.8 g braking
    kinematic_blend_low_mps: float = 1.0  # assumed: purely kinematic below
    kinematic_blend_high_mps: float = 3.0  # assumed: purely dynamic above

    def __post_init__(self) -> None:
        for name, low, high, unit in _RANGES:
            require_in_range(name, getattr(self, name), low, high, unit)
        if self.kinematic_blend_low_mps >= self.kinematic_blend_high_mps:
            raise WorkbenchInputError(
                f"kinematic_blend_low_mps must be < kinematic_blend_high_mps = {self.kinematic_blend_high_mps}; "
                f"got {self.kinematic_blend_low_mps!r}"
            )

    @property
    def wheelbase_m(self) -> float:
        return self.cg_to_front_axle_m + self.cg_to_rear_axle_m

    @property
    def understeer_gradient_rad_per_mps2(self) -> float:
        """Linear K in delta = L kappa + K a_y: (m / L)(b / Cf - a / Cr) with C = coefficient x static load."""
        return (1.0 / self.front_cornering_coeff_per_rad - 1.0 / self.rear_cornering_coeff_per_rad) / G_MPS2


_RANGES: tuple[tuple[str, float, float, str], ...] = (
    ("mass_kg", 100.0, 10000.0, "kg"),
    ("yaw_inertia_kgm2", 10.0, 50000.0, "kg m^2"),
    ("cg_to_front_axle_m", 0.1, 5.0, "m"),
    ("cg_to_rear_axle_m", 0.1, 5.0, "m"),
    ("cg_height_m", 0.1, 2.0, "m"),
    ("width_m", 0.5, 4.0, "m"),
    ("front_cornering_coeff_per_rad", 1.0, 60.0, "1/rad"),
    ("rear_cornering_coeff_per_rad", 1.0, 60.0, "1/rad"),
    ("tyre_friction", 0.05, 2.5, ""),
    ("tyre_shape_factor", 1.0, 1.9, ""),
    ("tyre_curvature_factor", -5.0, 0.99, ""),
    ("relaxation_length_m", 0.01, 3.0, "m"),
    ("steering_ratio", 1.0, 60.0, ""),
    ("max_road_wheel_angle_rad", 0.01, 1.5, "rad"),
    ("max_road_wheel_rate_rad_s", 0.01, 20.0, "rad/s"),
    ("steering_time_constant_s", 1e-3, 2.0, "s"),
    ("max_accel_mps2", 0.01, 30.0, "m/s^2"),
    ("max_decel_mps2", 0.01, 30.0, "m/s^2"),
    ("kinematic_blend_low_mps", 0.0, 10.0, "m/s"),
    ("kinematic_blend_high_mps", 0.1, 20.0, "m/s"),
)

(P_A, P_B, P_M, P_I, P_H, P_TAU, P_RATE, P_SIGMA, P_VLO, P_VHI, P_MU, P_BF, P_BR, P_C, P_E, P_N) = range(16)


@njit(cache=True)
def _slip(vy, vx):  # pragma: no cover - compiled
    """Slip angle (rad) of a contact moving at (vx, vy) in the wheel frame; zero for a wheel standing still."""
    return math.atan2(vy, vx) if abs(vx) + abs(vy) > 1e-9 else 0.0


@njit(cache=True)
def _magic(alpha, d, bb, c, e):  # pragma: no cover - compiled
    x = bb * alpha
    return -d * math.sin(c * math.atan(x - e * (x - math.atan(x))))


@njit(cache=True)
def _rhs(s, p, delta_cmd, accel, out):  # pragma: no cover - compiled
    yaw, u, v, r, delta, fyf, fyr = s[2], max(s[3], 0.0), s[4], s[5], s[6], s[7], s[8]  # RK4 stages may dip < 0
    a, b, m, iz = p[P_A], p[P_B], p[P_M], p[P_I]
    wb = a + b
    ax = 0.0 if (u <= 0.0 and accel < 0.0) else accel
    ddelta = min(max((delta_cmd - delta) / p[P_TAU], -p[P_RATE]), p[P_RATE])
    sd, cd = math.sin(delta), math.cos(delta)
    fzf = m * (G_MPS2 * b - ax * p[P_H]) / wb
    fzr = m * (G_MPS2 * a + ax * p[P_H]) / wb
    vf = v + a * r
    alpha_f = _slip(vf * cd - u * sd, u * cd + vf * sd)
    alpha_r = _slip(v - b * r, u)
    relax = max(u, p[P_VLO]) / p[P_SIGMA]
    out[7] = relax * (_magic(alpha_f, p[P_MU] * max(fzf, 0.0), p[P_BF], p[P_C], p[P_E]) - fyf)
    out[8] = relax * (_magic(alpha_r, p[P_MU] * max(fzr, 0.0), p[P_BR], p[P_C], p[P_E]) - fyr)
    dv_d = (fyf * cd + fyr) / m - u * r
    dr_d = (a * fyf * cd - b * fyr) / iz
    r_k = u * sd / cd / wb
    dr_k = (ax * sd / cd + u * ddelta / (cd * cd)) / wb
    dv_k = b * dr_k + (b * r_k - v) / KINEMATIC_PULL_S
    dr_k += (r_k - r) / KINEMATIC_PULL_S
    w = min(max((u - p[P_VLO]) / (p[P_VHI] - p[P_VLO]), 0.0), 1.0)
    w = w * w * (3.0 - 2.0 * w)
    vref = v - b * r
    cy, sy = math.cos(yaw), math.sin(yaw)
    out[0] = u * cy - vref * sy
    out[1] = u * sy + vref * cy
    out[2] = r
    out[3] = ax
    out[4] = w * dv_d + (1.0 - w) * dv_k
    out[5] = w * dr_d + (1.0 - w) * dr_k
    out[6] = ddelta


@njit(cache=True)
def _rk4(state, p, delta_cmd, accel, h, n):  # pragma: no cover - compiled
    s = state.copy()
    k1, k2, k3, k4, t = np.empty(9), np.empty(9), np.empty(9), np.empty(9), np.empty(9)
    for _ in range(n):
        _rhs(s, p, delta_cmd, accel, k1)
        for i in range(9):
            t[i] = s[i] + 0.5 * h * k1[i]
        _rhs(t, p, delta_cmd, accel, k2)
        for i in range(9):
            t[i] = s[i] + 0.5 * h * k2[i]
        _rhs(t, p, delta_cmd, accel, k3)
        for i in range(9):
            t[i] = s[i] + h * k3[i]
        _rhs(t, p, delta_cmd, accel, k4)
        for i in range(9):
            s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        if s[3] < 0.0:
            s[3] = 0.0
    return s


@njit(cache=True)
def _outputs(s, p, delta_cmd, accel, ratio):  # pragma: no cover - compiled
    d = np.empty(9)
    _rhs(s, p, delta_cmd, accel, d)
    u, v, r, delta, b = max(s[3], 0.0), s[4], s[5], s[6], p[P_B]
    vref = v - b * r
    ax_ref, ay_ref = d[3] - vref * r, d[4] - b * d[5] + u * r
    speed = math.hypot(u, vref)
    kappa = (u * ay_ref - vref * ax_ref) / speed**3 if speed > 1e-3 else math.tan(delta) / (p[P_A] + b)
    out = np.empty(12)
    out[0], out[1], out[2], out[3], out[4], out[5] = s[0], s[1], s[2], u, vref, r
    out[6], out[7], out[8] = delta * ratio, delta, ay_ref
    out[9], out[10], out[11] = s[7], s[8], kappa
    return out


class DynamicBicycle(VehicleModel):
    name: ClassVar[str] = "dynamic-bicycle"
    state_names: ClassVar[tuple[str, ...]] = (
        "x_m",
        "y_m",
        "yaw_rad",
        "vx_mps",
        "vy_cg_mps",
        "yaw_rate_rad_s",
        "road_wheel_angle_rad",
        "fy_front_N",
        "fy_rear_N",
    )
    extra_output_names: ClassVar[tuple[str, ...]] = ("fy_front_N", "fy_rear_N", "path_curvature_1pm")

    def __init__(self, params: DynamicBicycleParams | None = None) -> None:
        self.params = p = params or DynamicBicycleParams()
        arr = np.zeros(P_N)
        arr[P_A], arr[P_B], arr[P_M], arr[P_I], arr[P_H] = (
            p.cg_to_front_axle_m,
            p.cg_to_rear_axle_m,
            p.mass_kg,
            p.yaw_inertia_kgm2,
            p.cg_height_m,
        )
        arr[P_TAU], arr[P_RATE] = p.steering_time_constant_s, p.max_road_wheel_rate_rad_s
        arr[P_SIGMA] = p.relaxation_length_m
        arr[P_VLO], arr[P_VHI] = p.kinematic_blend_low_mps, p.kinematic_blend_high_mps
        arr[P_MU], arr[P_C], arr[P_E] = p.tyre_friction, p.tyre_shape_factor, p.tyre_curvature_factor
        arr[P_BF] = p.front_cornering_coeff_per_rad / (p.tyre_shape_factor * p.tyre_friction)
        arr[P_BR] = p.rear_cornering_coeff_per_rad / (p.tyre_shape_factor * p.tyre_friction)
        self._p = arr
        self._geometry = VehicleGeometry(
            wheelbase_m=p.wheelbase_m,
            steering_ratio=p.steering_ratio,
            max_road_wheel_angle_rad=p.max_road_wheel_angle_rad,
            max_steer_wheel_rate_rad_s=p.max_road_wheel_rate_rad_s * p.steering_ratio,
            width_m=p.width_m,
        )

    @property
    def geometry(self) -> VehicleGeometry:
        return self._geometry

    def initial_state(self, x_m: float, y_m: float, yaw_rad: float, speed_mps: float) -> np.ndarray:
        return np.array([x_m, y_m, yaw_rad, speed_mps, 0.0, 0.0, 0.0, 0.0, 0.0], dtype=float)

    def _inputs(self, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> tuple[float, float]:
        p = self.params
        lim = p.max_road_wheel_angle_rad
        delta_cmd = min(max(steer_wheel_cmd_rad / p.steering_ratio, -lim), lim)
        return delta_cmd, min(max(accel_cmd_mps2, -p.max_decel_mps2), p.max_accel_mps2)

    def advance(
        self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float, dt_s: float, substeps: int
    ) -> np.ndarray:
        delta_cmd, accel = self._inputs(steer_wheel_cmd_rad, accel_cmd_mps2)
        return _rk4(state, self._p, delta_cmd, accel, dt_s / substeps, substeps)

    def outputs(self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> np.ndarray:
        delta_cmd, accel = self._inputs(steer_wheel_cmd_rad, accel_cmd_mps2)
        return _outputs(np.asarray(state, dtype=float), self._p, delta_cmd, accel, self.params.steering_ratio)
