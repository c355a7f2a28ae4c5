"""Dynamic bicycle (single-track) car with magic-formula tyres and relaxation length, referenced at the rear axle.

Stands in for a CarSim C-class car. States (SI): x_m, y_m (rear-axle centre), yaw_rad, vx_mps (longitudinal
speed), vy_cg_mps (CG lateral velocity, body frame), yaw_rate_rad_s, road_wheel_angle_rad, fy_front_N,
fy_rear_N (axle lateral forces, lagging their steady-state value by the relaxation length)::

    m (dvy + vx r) = Fyf cos(delta) + Fyr,   Iz dr = a Fyf cos(delta) - b Fyr,   dvx = a_x (realised command),
    dFy = (vx / sigma) (Fy_ss(alpha) - Fy),  Fy_ss = -mu Fz sin(C atan(B alpha - E (B alpha - atan(B alpha)))),

with B = k / (C mu) so that the cornering stiffness is k Fz, and Fz the axle load including the longitudinal
load transfer m a_x h / L (as CommonRoad's ST model). Below kinematic_blend_high_mps the lateral accelerations
blend into the kinematic bicycle's, so the model is well-posed at v = 0 and equals the kinematic bicycle there.
The steering actuator is the kinematic bicycle's: first order, rate- and angle-limited. A road-friction scale
lambda (`set_road_friction`) makes mu = lambda x tyre_friction, in the peak mu Fz and in B = k / (C mu): the peak
scales, the cornering stiffness k Fz stays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from workbench.base.errors import require_in_range
from workbench.vehicles.actuator import realised_accel, road_wheel_rate
from workbench.vehicles.base import CompiledVehicleModel, VehicleGeometry
from workbench.vehicles.blend import blend, blend_weight, check_blend_speeds, pull
from workbench.vehicles.integration import rk4
from workbench.vehicles.reference_point import reference_point, world_velocity
from workbench.vehicles.single_track import PredictionParams, SingleTrackParams
from workbench.vehicles.tyres import COMMONROAD_G_MPS2, magic_formula, relaxation_rate, slip_angle, steered_slip_angle


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
        check_blend_speeds(self.kinematic_blend_low_mps, self.kinematic_blend_high_mps)

    @property
    def wheelbase_m(self) -> float:
        """The distance between the axles (m): CG to front axle plus CG to rear axle."""
        return self.cg_to_front_axle_m + self.cg_to_rear_axle_m

    @property
    def understeer_gradient_rad_per_mps2(self) -> float:
        """Linear K in delta = L kappa + K a_y: (m / L)(b / Cf - a / Cr) with C = coefficient x static load."""
        return (1.0 / self.front_cornering_coeff_per_rad - 1.0 / self.rear_cornering_coeff_per_rad) / COMMONROAD_G_MPS2


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
def _rhs(s, p, delta_cmd, accel, out):  # pragma: no cover - compiled
    yaw, u, v, r, delta, fyf, fyr = s[2], max(s[3], 0.0), s[4], s[5], s[6], s[7], s[8]  # RK4 stages may dip < 0
    a, b, m, iz = p[P_A], p[P_B], p[P_M], p[P_I]
    wb = a + b
    ax = realised_accel(u, accel)
    ddelta = road_wheel_rate(delta_cmd, delta, p[P_TAU], p[P_RATE])
    sd, cd = math.sin(delta), math.cos(delta)
    fzf = m * (COMMONROAD_G_MPS2 * b - ax * p[P_H]) / wb
    fzr = m * (COMMONROAD_G_MPS2 * a + ax * p[P_H]) / wb
    alpha_f = steered_slip_angle(v + a * r, u, sd, cd)
    alpha_r = slip_angle(v - b * r, u)
    relax = relaxation_rate(u, p[P_VLO], p[P_SIGMA])
    out[7] = relax * (magic_formula(alpha_f, p[P_MU] * max(fzf, 0.0), p[P_BF], p[P_C], p[P_E]) - fyf)
    out[8] = relax * (magic_formula(alpha_r, p[P_MU] * max(fzr, 0.0), p[P_BR], p[P_C], p[P_E]) - fyr)
    dv_d = (fyf * cd + fyr) / m - u * r
    dr_d = (a * fyf * cd - b * fyr) / iz
    r_k = u * sd / cd / wb
    dr_k = (ax * sd / cd + u * ddelta / (cd * cd)) / wb
    dv_k = b * dr_k + pull(b * r_k, v)
    dr_k += pull(r_k, r)
    w = blend_weight(u, p[P_VLO], p[P_VHI])
    out[0], out[1] = world_velocity(u, v - b * r, yaw)
    out[2] = r
    out[3] = ax
    out[4] = blend(w, dv_d, dv_k)
    out[5] = blend(w, dr_d, dr_k)
    out[6] = ddelta


@njit(cache=True)
def _advance(state, p, delta_cmd, accel, h, n):  # pragma: no cover - compiled
    return rk4(_rhs, state, p, delta_cmd, accel, h, n)


@njit(cache=True)
def _outputs(s, p, delta_cmd, accel, ratio):  # pragma: no cover - compiled
    d = np.empty(9)
    _rhs(s, p, delta_cmd, accel, d)
    u, v, r, delta, b = max(s[3], 0.0), s[4], s[5], s[6], p[P_B]
    vref, _, ay_ref, kappa = reference_point(u, v, r, d[3], d[4], d[5], b, delta, p[P_A] + b)
    out = np.empty(12)
    out[0], out[1], out[2], out[3], out[4], out[5] = s[0], s[1], s[2], u, vref, r
    out[6], out[7], out[8] = delta * ratio, delta, ay_ref
    out[9], out[10], out[11] = s[7], s[8], kappa
    return out


class DynamicBicycle(CompiledVehicleModel[DynamicBicycleParams]):
    """The dynamic single-track car with magic-formula tyres and relaxation length, registered as
    "dynamic-bicycle" (module docstring for its equations and states).

    Parameters
    ----------
    params : DynamicBicycleParams or None
        The model's parameters (None: the dataclass's defaults); `make_vehicle` builds the model from its preset
        or a vehicle file instead.
    """

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

    has_tyres: ClassVar[bool] = True

    _advance_kernel = staticmethod(_advance)
    _outputs_kernel = staticmethod(_outputs)

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
        arr[P_C], arr[P_E] = p.tyre_shape_factor, p.tyre_curvature_factor
        self._p = arr
        self._apply_road_friction(1.0)
        self._geometry = VehicleGeometry.from_params(p, p.wheelbase_m)

    def _apply_road_friction(self, scale: float) -> None:
        """Peak friction mu = scale x tyre_friction (D = mu Fz, in the kernel) and B = k / (C mu), so that the
        cornering stiffness B C D = k Fz is kept; scale 1.0 gives exactly the entries built from the parameters."""
        p, arr = self.params, self._p
        mu = scale * p.tyre_friction
        arr[P_MU] = mu
        arr[P_BF] = p.front_cornering_coeff_per_rad / (p.tyre_shape_factor * mu)
        arr[P_BR] = p.rear_cornering_coeff_per_rad / (p.tyre_shape_factor * mu)

    def single_track(self, source: str | None = None) -> PredictionParams:
        """This model as a single track: its axles, static axle loads, tyres (cornering stiffness = coefficient x
        load, peak = friction x load) and actuator.

        Parameters
        ----------
        source : str or None
            Where the numbers come from, for messages and reports (None: this model's parameters).

        Returns
        -------
        PredictionParams
            The geometry, the steering actuator and the single track's mass, yaw inertia and axle tyres: what the MPC
            controllers predict with.
        """
        p = self.params
        a, b = p.cg_to_front_axle_m, p.cg_to_rear_axle_m
        fzf, fzr = p.mass_kg * COMMONROAD_G_MPS2 * b / (a + b), p.mass_kg * COMMONROAD_G_MPS2 * a / (a + b)
        track = SingleTrackParams(
            mass_kg=p.mass_kg,
            yaw_inertia_kgm2=p.yaw_inertia_kgm2,
            cg_to_front_axle_m=a,
            cg_to_rear_axle_m=b,
            front_cornering_stiffness_n_per_rad=p.front_cornering_coeff_per_rad * fzf,
            rear_cornering_stiffness_n_per_rad=p.rear_cornering_coeff_per_rad * fzr,
            front_peak_force_n=p.tyre_friction * fzf,
            rear_peak_force_n=p.tyre_friction * fzr,
            tyre_shape_factor=p.tyre_shape_factor,
            tyre_curvature_factor=p.tyre_curvature_factor,
        )
        return PredictionParams.from_actuator(p, a + b, source or f"the {self.name} model's parameters", track)


__all__ = ["DynamicBicycle", "DynamicBicycleParams"]
