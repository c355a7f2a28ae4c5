"""CommonRoad's multi-body car model (`vehiclemodels.vehicle_dynamics_mb`) as a plant: a third-party check.

The 29-state MB model (sprung mass with roll and pitch, two unsprung axles, four wheel speeds, magic-formula
combined-slip tyres; Althoff & Wuersching, "CommonRoad: Vehicle Models", 2020) is integrated as published, with
fixed-step RK4 of its pure-Python derivative function, so it is slow (two orders of magnitude slower than the
compiled models; `benchmarks/run.py` times it). Its inputs are the front road-wheel angle *rate* and the acceleration;
this adapter closes the same first-order, rate-limited steering actuator as the other models around it, and
converts its CG reference point to the rear-axle centre: p_rear = p_cg - b (cos yaw, sin yaw).

Road friction (`set_road_friction`, Pacejka's lambda_mu): CommonRoad's tyre (`vehiclemodels.utils.tire_model`) has
D = p_d1 F_z and B = K / (C D) with the slip stiffness K = p_k1 F_z independent of p_d1, longitudinally and
laterally, so multiplying the peak coefficients p_dx1 and p_dy1 by the scale scales the peaks and keeps the
cornering (and longitudinal slip) stiffness B C D = K exactly (the slope at the curve's own origin: at zero slip
ratio, the small horizontal shift p_hx1 moves the longitudinal slope by 0.5 % at 0.3). The combined-slip forces
follow (proportional to the pure-slip ones, the kappa-induced side force to mu_y). The vertical shifts (p_vx1, and
the camber thrust p_vy1, p_vy3), which Pacejka's full magic formula also scales by a friction factor, are left as
published: they act at zero slip, i.e. in the linear handling, which the scale is to keep (scaled by 0.5 they
changed the rear-axle sideslip of a 0.05 g turn at 15 m/s by 73 %; left, it changes by 2 %). The MB model runs on
a copy of CommonRoad's parameters with p_dx1 and p_dy1 scaled; at 1.0 on CommonRoad's own parameters object.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import partial
from typing import Any, ClassVar

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_in_range
from workbench.vehicles.base import VehicleGeometry, VehicleModel
from workbench.vehicles.integration import rk4_python
from workbench.vehicles.reference_point import reference_point_python
from workbench.vehicles.single_track import PredictionParams, SingleTrackParams
from workbench.vehicles.tyres import COMMONROAD_G_MPS2

#: CommonRoad's names of the MB states, in order (x/y are the CG; vx/vy of the sprung mass, body frame).
_MB_STATES: tuple[str, ...] = (
    "x_cg_m",
    "y_cg_m",
    "road_wheel_angle_rad",
    "vx_mps",
    "yaw_rad",
    "yaw_rate_rad_s",
    "roll_rad",
    "roll_rate_rad_s",
    "pitch_rad",
    "pitch_rate_rad_s",
    "vy_mps",
    "z_m",
    "vz_mps",
    "roll_front_rad",
    "roll_rate_front_rad_s",
    "vy_front_mps",
    "z_front_m",
    "vz_front_mps",
    "roll_rear_rad",
    "roll_rate_rear_rad_s",
    "vy_rear_mps",
    "z_rear_m",
    "vz_rear_mps",
    "omega_lf_rad_s",
    "omega_rf_rad_s",
    "omega_lr_rad_s",
    "omega_rr_rad_s",
    "delta_y_front_m",
    "delta_y_rear_m",
)


#: CommonRoad tyre coefficients a road-friction scale multiplies: the longitudinal and lateral peak friction (the
#: module docstring says why these and no others).
_FRICTION_SCALED_TYRE_COEFFS: tuple[str, ...] = ("p_dx1", "p_dy1")


@dataclass(frozen=True)
class CommonRoadMBParams:
    """Which CommonRoad vehicle, plus the steering system and envelope CommonRoad does not model."""

    vehicle_id: int = 2  # CommonRoad parameters_vehicle2: BMW 320i (1: Ford Escort, 3: VW Vanagon)
    steering_ratio: float = 15.0  # assumed: typical passenger-car rack (14-16:1); CommonRoad gives none
    steering_time_constant_s: float = 0.05  # assumed: electric power-steering position loop
    max_accel_mps2: float = 3.0  # assumed comfort limit (CommonRoad's 11.5 m/s^2 is the tyre limit)
    max_decel_mps2: float = 8.0  # assumed: about 0.8 g braking
    max_step_s: float = 0.001  # assumed: RK4 step bound; 5 ms fails at low speed (stiff wheel spin), 2 ms held

    def __post_init__(self) -> None:
        if isinstance(self.vehicle_id, bool) or self.vehicle_id not in (1, 2, 3):
            raise WorkbenchInputError(f"vehicle_id must be 1, 2 or 3 (CommonRoad cars); got {self.vehicle_id!r}")
        require_in_range("steering_ratio", self.steering_ratio, 1.0, 60.0)
        require_in_range("steering_time_constant_s", self.steering_time_constant_s, 1e-3, 2.0, "s")
        require_in_range("max_accel_mps2", self.max_accel_mps2, 0.01, 11.5, "m/s^2")
        require_in_range("max_decel_mps2", self.max_decel_mps2, 0.01, 11.5, "m/s^2")
        require_in_range("max_step_s", self.max_step_s, 1e-5, 0.01, "s")


def _commonroad_parameters(vehicle_id: int) -> Any:
    from vehiclemodels.parameters_vehicle1 import parameters_vehicle1
    from vehiclemodels.parameters_vehicle2 import parameters_vehicle2
    from vehiclemodels.parameters_vehicle3 import parameters_vehicle3

    return {1: parameters_vehicle1, 2: parameters_vehicle2, 3: parameters_vehicle3}[vehicle_id]()


class CommonRoadMB(VehicleModel[CommonRoadMBParams]):
    """CommonRoad's 29-state multi-body car as a plant, registered as "commonroad-mb" (module docstring): the
    published model behind this workbench's steering actuator, reported at the rear-axle centre.

    Parameters
    ----------
    params : CommonRoadMBParams or None
        The model's parameters (None: the dataclass's defaults); `make_vehicle` builds the model from its preset
        or a vehicle file instead.
    """

    name: ClassVar[str] = "commonroad-mb"
    state_names: ClassVar[tuple[str, ...]] = _MB_STATES
    extra_output_names: ClassVar[tuple[str, ...]] = ("roll_rad", "path_curvature_1pm")
    has_tyres: ClassVar[bool] = True

    def __init__(self, params: CommonRoadMBParams | None = None) -> None:
        from vehiclemodels.init_mb import init_mb
        from vehiclemodels.vehicle_dynamics_mb import vehicle_dynamics_mb

        self.params = p = params or CommonRoadMBParams()
        self._f, self._init = vehicle_dynamics_mb, init_mb
        self._cr = cr = _commonroad_parameters(p.vehicle_id)
        #: The parameters the MB derivative runs on: `_cr` itself at road friction 1.0, else a scaled copy.
        self._cr_road = cr
        self._b = float(cr.b)
        self._geometry = VehicleGeometry(
            wheelbase_m=float(cr.a + cr.b),
            steering_ratio=p.steering_ratio,
            max_road_wheel_angle_rad=float(cr.steering.max),
            max_steer_wheel_rate_rad_s=float(cr.steering.v_max) * p.steering_ratio,
            width_m=float(cr.w),
        )

    def single_track(self, source: str | None = None) -> PredictionParams:
        """CommonRoad's car parameters as a single track with CommonRoad's tyre coefficients.

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
        p, cr = self.params, self._cr
        a, b, m = float(cr.a), float(cr.b), float(cr.m)
        fzf, fzr = m * COMMONROAD_G_MPS2 * b / (a + b), m * COMMONROAD_G_MPS2 * a / (a + b)
        tyre = cr.tire
        track = SingleTrackParams(
            mass_kg=m,
            yaw_inertia_kgm2=float(cr.I_z),
            cg_to_front_axle_m=a,
            cg_to_rear_axle_m=b,
            front_cornering_stiffness_n_per_rad=-float(tyre.p_ky1) * fzf,
            rear_cornering_stiffness_n_per_rad=-float(tyre.p_ky1) * fzr,
            front_peak_force_n=float(tyre.p_dy1) * fzf,
            rear_peak_force_n=float(tyre.p_dy1) * fzr,
            tyre_shape_factor=float(tyre.p_cy1),
            tyre_curvature_factor=float(tyre.p_ey1),
        )
        source = source or f"the {self.name} model's parameters"
        return PredictionParams(
            wheelbase_m=a + b,
            steering_ratio=p.steering_ratio,
            max_road_wheel_angle_rad=float(cr.steering.max),
            max_road_wheel_rate_rad_s=float(cr.steering.v_max),
            steering_time_constant_s=p.steering_time_constant_s,
            single_track=track,
            source=source + f" (CommonRoad vehicle {p.vehicle_id} as a single track)",
        )

    def _apply_road_friction(self, scale: float) -> None:
        """Run the MB model on a copy of CommonRoad's parameters with the peak friction p_dx1 and p_dy1 multiplied
        by `scale` (the module docstring: peaks scaled, slip stiffnesses kept); at 1.0 on CommonRoad's own
        parameters object, so that the model is exactly the one built."""
        cr = self._cr
        if scale == 1.0:
            self._cr_road = cr
            return
        scaled = {name: scale * getattr(cr.tire, name) for name in _FRICTION_SCALED_TYRE_COEFFS}
        self._cr_road = dataclasses.replace(cr, tire=dataclasses.replace(cr.tire, **scaled))

    def initial_state(self, x_m: float, y_m: float, yaw_rad: float, speed_mps: float) -> np.ndarray:
        """CommonRoad's own initial state (`init_mb`: the wheels rolling at the speed) of the car whose
        rear-axle centre is at (x, y), straight wheels, heading yaw, moving at speed.

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
        xc, yc = x_m + self._b * math.cos(yaw_rad), y_m + self._b * math.sin(yaw_rad)
        return np.array(self._init([xc, yc, 0.0, speed_mps, yaw_rad, 0.0, 0.0], self._cr), dtype=float)

    def _rhs(self, x: np.ndarray, delta_cmd: float, accel: float) -> np.ndarray:
        """MB derivative; NaN where CommonRoad's code breaks down (e.g. a wheel stops rolling in a spin:
        division by zero), so the simulator reports the state as diverged instead of a stray exception."""
        steer_rate = (delta_cmd - x[2]) / self.params.steering_time_constant_s
        try:
            return np.array(self._f(x.tolist(), [steer_rate, accel], self._cr_road), dtype=float)
        except (ZeroDivisionError, OverflowError, ValueError):
            return np.full(len(_MB_STATES), np.nan)

    def advance(
        self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float, dt_s: float, substeps: int
    ) -> np.ndarray:
        """Integrate the MB model with the inputs held over `dt_s`, in `substeps` fixed RK4 steps or more, so that
        no step is longer than `max_step_s` (the model is stiff); return the new state.

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
        n = max(substeps, math.ceil(dt_s / self.params.max_step_s - 1e-9))
        h = dt_s / n
        rhs = partial(self._rhs, delta_cmd=delta_cmd, accel=accel)
        s = np.array(state, dtype=float)
        for _ in range(n):
            s = rk4_python(rhs, s, h)
            s[23:27] = np.maximum(s[23:27], 0.0)  # CommonRoad forbids negative wheel spin
        return s

    def outputs(self, state: np.ndarray, steer_wheel_cmd_rad: float, accel_cmd_mps2: float) -> np.ndarray:
        """STANDARD_OUTPUTS at the rear-axle centre (moved there from CommonRoad's centre of gravity), then the
        sprung mass's roll (rad) and the path curvature of the reference point (1/m).

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
        x = np.asarray(state, dtype=float)
        d = self._rhs(x, delta_cmd, accel)
        b, yaw, u, r = self._b, x[4], x[3], x[5]
        vref, _, ay_ref, kappa = reference_point_python(
            u, x[10], r, d[3], d[10], d[5], b, x[2], self._geometry.wheelbase_m
        )
        return np.array(
            [
                x[0] - b * math.cos(yaw),
                x[1] - b * math.sin(yaw),
                yaw,
                u,
                vref,
                r,
                x[2] * self.params.steering_ratio,
                x[2],
                ay_ref,
                x[6],
                kappa,
            ]
        )


__all__ = ["CommonRoadMB", "CommonRoadMBParams"]
