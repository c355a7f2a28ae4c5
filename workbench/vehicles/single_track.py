"""A vehicle's single-track (bicycle) equivalent: what a model-based controller predicts with.

Every vehicle model offers one (`VehicleModel.single_track`): its geometry and steering actuator, and, when it has
tyres, the mass, yaw inertia and axle tyres of a single track. The MPC's ODE is built from it (`controllers/mpc/
prediction_model.py`), so the MPC never needs to know the vehicle classes. The tractor-semitrailer's equivalent
carries the kingpin's share of the trailer at the fifth wheel (`TractorSemitrailer.single_track`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive
from workbench.vehicles.geometry import VehicleGeometry
from workbench.vehicles.steering_lag import SteeringLag

#: Steering-actuator time constant (s) assumed when only the geometry is known: an electric or hydraulic power
#: steering position loop (the workbench presets use 0.05 s for the car and 0.1 s for the truck).
DEFAULT_STEERING_TIME_CONSTANT_S = 0.1


@dataclass(frozen=True)
class SingleTrackParams:
    """Mass, yaw inertia, axle positions and axle tyres of a single-track (bicycle) model, SI units.

    Axle lateral force F = D sin(C atan(B alpha - E (B alpha - atan(B alpha)))) with peak D, shape C, curvature E
    and B = cornering stiffness / (C D), as in the workbench plants.
    """

    mass_kg: float  # mass m (kg), in [100, 100000]
    yaw_inertia_kgm2: float  # yaw moment of inertia about the CG (kg m^2), in [10, 5e6]
    cg_to_front_axle_m: float  # CG to front axle, a (m), in [0.05, 15]
    cg_to_rear_axle_m: float  # CG to rear axle, b (m), in [0.05, 15]
    front_cornering_stiffness_n_per_rad: float  # the front axle's cornering stiffness Cf (N/rad), > 0
    rear_cornering_stiffness_n_per_rad: float  # the rear axle's cornering stiffness Cr (N/rad), > 0
    front_peak_force_n: float  # the front axle's peak lateral force D (N), > 0
    rear_peak_force_n: float  # the rear axle's peak lateral force D (N), > 0
    tyre_shape_factor: float = 1.35  # the magic formula's shape factor C of both axles, in [1, 1.9]
    tyre_curvature_factor: float = 0.0  # the magic formula's curvature factor E of both axles, in [-5, 0.99]

    def __post_init__(self) -> None:
        require_in_range("mass_kg", self.mass_kg, 100.0, 100_000.0, "kg")
        require_in_range("yaw_inertia_kgm2", self.yaw_inertia_kgm2, 10.0, 5.0e6, "kg m^2")
        require_in_range("cg_to_front_axle_m", self.cg_to_front_axle_m, 0.05, 15.0, "m")
        require_in_range("cg_to_rear_axle_m", self.cg_to_rear_axle_m, 0.05, 15.0, "m")
        for name in (
            "front_cornering_stiffness_n_per_rad",
            "rear_cornering_stiffness_n_per_rad",
            "front_peak_force_n",
            "rear_peak_force_n",
        ):
            require_positive(name, getattr(self, name))
        require_in_range("tyre_shape_factor", self.tyre_shape_factor, 1.0, 1.9)
        require_in_range("tyre_curvature_factor", self.tyre_curvature_factor, -5.0, 0.99)

    @property
    def wheelbase_m(self) -> float:
        """The distance between the axles (m): CG to front axle plus CG to rear axle."""
        return self.cg_to_front_axle_m + self.cg_to_rear_axle_m

    def understeer_gradient_rad_per_mps2(self) -> float:
        """K in delta = L kappa + K a_y (linear tyres): (m / L) (b / Cf - a / Cr).

        Returns
        -------
        float
            The understeer gradient (rad per m/s^2 of lateral acceleration): positive understeers, negative
            oversteers, zero is neutral.
        """
        a, b, m = self.cg_to_front_axle_m, self.cg_to_rear_axle_m, self.mass_kg
        cf, cr = self.front_cornering_stiffness_n_per_rad, self.rear_cornering_stiffness_n_per_rad
        return m / (a + b) * (b / cf - a / cr)

    def steady_slip_angles_rad(self, lateral_accel_mps2: float) -> tuple[float, float]:
        """Front and rear axle slip angles (rad) in steady cornering at this lateral acceleration (m/s^2, signed):
        the axle forces that hold the turn, m a_y b / L and m a_y a / L (moment balance about the CG, cos(delta)
        taken as 1), each through the magic formula inverted without its small curvature factor E (a force
        beyond 99 % of the axle's peak is taken as 99 % of it).

        Parameters
        ----------
        lateral_accel_mps2 : float
            The steady lateral acceleration (m/s^2, left positive).

        Returns
        -------
        tuple of (float, float)
            The front and rear axle slip angles (rad), of the sign of `lateral_accel_mps2`.
        """
        a, b, m = self.cg_to_front_axle_m, self.cg_to_rear_axle_m, self.mass_kg
        shape, force = self.tyre_shape_factor, m * lateral_accel_mps2 / (a + b)
        slips = []
        for axle_force, peak, stiffness in (
            (force * b, self.front_peak_force_n, self.front_cornering_stiffness_n_per_rad),
            (force * a, self.rear_peak_force_n, self.rear_cornering_stiffness_n_per_rad),
        ):
            ratio = min(max(axle_force / peak, -0.99), 0.99)
            slips.append(math.tan(math.asin(ratio) / shape) * shape * peak / stiffness)
        return slips[0], slips[1]

    def fastest_lateral_mode_per_s(self, speed_mps: float) -> float:
        """|lambda|max of the linear single track's (v_y, r) dynamics at this speed (1/s).

        What bounds the step an explicit integration of the single track may take at that speed.

        Parameters
        ----------
        speed_mps : float
            The longitudinal speed (m/s, > 0).

        Returns
        -------
        float
            The largest magnitude of the two eigenvalues of the linear lateral dynamics (1/s).
        """
        a, b, m, iz = self.cg_to_front_axle_m, self.cg_to_rear_axle_m, self.mass_kg, self.yaw_inertia_kgm2
        cf, cr = self.front_cornering_stiffness_n_per_rad, self.rear_cornering_stiffness_n_per_rad
        v = speed_mps
        mat = np.array(
            [
                [-(cf + cr) / (m * v), -(a * cf - b * cr) / (m * v) - v],
                [-(a * cf - b * cr) / (iz * v), -(a * a * cf + b * b * cr) / (iz * v)],
            ]
        )
        return float(np.max(np.abs(np.linalg.eigvals(mat))))


class SteeringActuator(Protocol):
    """The steering actuator as a model's params describe it: the steering-wheel to road-wheel ratio, the
    road-wheel angle (rad) and rate (rad/s) limits and the first-order time constant (s)."""

    @property
    def steering_ratio(self) -> float:
        """Steering-wheel angle / road-wheel angle."""
        ...

    @property
    def max_road_wheel_angle_rad(self) -> float:
        """The road wheels' lock (rad)."""
        ...

    @property
    def max_road_wheel_rate_rad_s(self) -> float:
        """The road wheels' largest steering rate (rad/s)."""
        ...

    @property
    def steering_time_constant_s(self) -> float:
        """The first-order steering actuator's time constant (s)."""
        ...


@dataclass(frozen=True)
class PredictionParams:
    """The vehicle as the MPC predicts it (SI units): its geometry as `VehicleGeometry` has it, its steering
    actuator and what is known of its dynamics. Without a single track only the MPC's kinematic kinds are
    available; with one, its axle positions must add up to wheelbase_m.
    """

    wheelbase_m: float  # front axle to rear axle (group centre) of the steered unit (m), in [0.5, 15]
    steering_ratio: float  # steering-wheel angle / road-wheel angle, in [1, 60]
    max_road_wheel_angle_rad: float  # steering lock at the road wheels (rad), in [0.01, 1.5]
    max_road_wheel_rate_rad_s: float  # steering rate limit at the road wheels (rad/s), > 0
    steering_time_constant_s: float = DEFAULT_STEERING_TIME_CONSTANT_S  # first-order actuator (s), in [0.001, 2]
    single_track: SingleTrackParams | None = None  # mass, inertia and tyres; None: unknown
    lag: SteeringLag | None = None  # the identified steering-wheel-to-curvature lag (Eq. 5); None: not identified
    source: str = ""  # where the numbers came from, for messages and reports (any text)

    def __post_init__(self) -> None:
        require_in_range("wheelbase_m", self.wheelbase_m, 0.5, 15.0, "m")
        require_in_range("steering_ratio", self.steering_ratio, 1.0, 60.0)
        require_in_range("max_road_wheel_angle_rad", self.max_road_wheel_angle_rad, 0.01, 1.5, "rad")
        require_positive("max_road_wheel_rate_rad_s", self.max_road_wheel_rate_rad_s)
        require_in_range("steering_time_constant_s", self.steering_time_constant_s, 1e-3, 2.0, "s")
        if self.single_track is not None and abs(self.single_track.wheelbase_m - self.wheelbase_m) > 1e-6:
            raise WorkbenchInputError(
                f"single_track axle positions add up to {float(self.single_track.wheelbase_m):g} m; they must "
                f"equal wheelbase_m = {float(self.wheelbase_m):g} m"
            )

    @classmethod
    def from_actuator(
        cls,
        actuator: SteeringActuator,
        wheelbase_m: float,
        source: str,
        single_track: SingleTrackParams | None = None,
        lag: SteeringLag | None = None,
    ) -> PredictionParams:
        """A model's prediction parameters: its steering actuator's (`actuator`: the steering ratio, the road-wheel
        angle and rate limits, the time constant, which every model's params hold) with the wheelbase (m), single
        track, identified lag and source the model gives.

        Parameters
        ----------
        actuator : SteeringActuator
            A model's params: the steering ratio, the road-wheel angle (rad) and rate (rad/s) limits and the
            actuator's time constant (s).
        wheelbase_m : float
            The single track's wheelbase (m, 0.5 to 15).
        source : str
            Where the numbers come from, for messages and reports.
        single_track : SingleTrackParams or None
            Mass, inertia and axle tyres (None: unknown, the kinematic kinds only).
        lag : SteeringLag or None
            The identified steering-wheel-to-curvature lag (None: none).

        Returns
        -------
        PredictionParams
            The prediction parameters.

        Raises
        ------
        WorkbenchInputError
            A value out of its range, or a single track whose axle positions do not add up to `wheelbase_m`.
        """
        return cls(
            wheelbase_m=wheelbase_m,
            steering_ratio=actuator.steering_ratio,
            max_road_wheel_angle_rad=actuator.max_road_wheel_angle_rad,
            max_road_wheel_rate_rad_s=actuator.max_road_wheel_rate_rad_s,
            steering_time_constant_s=actuator.steering_time_constant_s,
            single_track=single_track,
            lag=lag,
            source=source,
        )

    def with_lag(self, lag: SteeringLag | None) -> PredictionParams:
        """A copy with this identified lag (None removes it).

        Parameters
        ----------
        lag : SteeringLag or None
            The identified steering-wheel-to-curvature lag (Eq. 5), or None.

        Returns
        -------
        PredictionParams
            The same parameters with `lag` in place of this one's.
        """
        return dataclasses.replace(self, lag=lag)

    def default_kind(self) -> str:
        """ "kinematic-lag" with a lag, else "dynamic" when the single track is known, else "kinematic".

        Returns
        -------
        str
            The MPC's prediction-model kind these parameters support best.
        """
        if self.lag is not None:
            return "kinematic-lag"
        return "dynamic" if self.single_track is not None else "kinematic"


def params_from_geometry(geometry: VehicleGeometry) -> PredictionParams:
    """The default when nothing but the geometry is known: a kinematic single track with the geometry's limits
    and an assumed actuator time constant (DEFAULT_STEERING_TIME_CONSTANT_S).

    Parameters
    ----------
    geometry : VehicleGeometry
        The vehicle's wheelbase, steering ratio and limits; the road-wheel rate limit is its steering-wheel rate
        limit divided by the steering ratio.

    Returns
    -------
    PredictionParams
        A kinematic single track (no tyres, no lag) with DEFAULT_STEERING_TIME_CONSTANT_S.

    Raises
    ------
    WorkbenchInputError
        A geometry outside the prediction parameters' ranges (e.g. a wheelbase over 15 m).
    """
    return PredictionParams(
        wheelbase_m=geometry.wheelbase_m,
        steering_ratio=geometry.steering_ratio,
        max_road_wheel_angle_rad=geometry.max_road_wheel_angle_rad,
        max_road_wheel_rate_rad_s=geometry.max_steer_wheel_rate_rad_s / geometry.steering_ratio,
        source="geometry only (kinematic single track, assumed actuator time constant)",
    )


__all__ = ["PredictionParams", "SingleTrackParams", "SteeringActuator", "params_from_geometry"]
