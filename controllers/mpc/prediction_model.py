"""The MPC prediction model: its ODE in path coordinates, from the vehicle's single-track equivalent.

`PredictionParams` (`VehicleModel.single_track`) is the vehicle as the MPC sees it; `prediction_params_for` takes
it from a vehicle model, params dataclass, preset name or TOML file, or else from the controller's
`VehicleGeometry`; `PredictionModel` turns it into CasADi expressions. Every kind is referenced at the rear-axle
centre (where the paper measures CTE) in Frenet errors e_y (left positive) and e_psi, has the commanded road-wheel
angle delta_c as a state and its rate as the input u (so steering limits are simple bounds), and takes the path
curvature kappa and the speed v per shooting interval:

  "dynamic"  nonlinear single track: v_y at the CG, yaw rate r, magic-formula axle forces, first-order actuator:
                 v_y' = (Fyf cos(delta) + Fyr) / m - v r,   r' = (a Fyf cos(delta) - b Fyr) / Iz,
                 delta' = (delta_c - delta) / tau,          delta_c' = u
             (neglects tyre relaxation, load transfer and the actuator's rate clip).
  "kinematic" the rear axle moves along its heading with curvature tan(delta) / L, same actuator; exact for the
             `kinematic-bicycle` plant, and the model when only the geometry is known.
  "kinematic-lag" the paper's "kinematic with lag" (section 5.1, Figures 8-9): the identified lag of Eq. 5 with
             its steady-state gain K, kappa_v'' = wn^2 (K kappa_kin - kappa_v) - 2 zeta wn kappa_v', a delay as a
             first-order Pade state (states L kappa_v and its rate: dimensionless, for well-scaled QPs). The lag is
             the whole steering-to-curvature response, so it replaces the lateral dynamics (stacked on them it would
             count the tyre lag twice); the clothoid controller's lead filter uses the same identified data.

Path coordinates, v_r the rear axle's lateral velocity (v_y - b r; 0 in the kinematic kinds), omega the yaw rate
(r, or v kappa_v): s' = (v cos(e_psi) - v_r sin(e_psi)) / (1 - kappa e_y), e_y' = v sin(e_psi) + v_r cos(e_psi),
e_psi' = omega - kappa s'. The tractor-semitrailer is predicted by its equivalent single track (the kingpin's share
of the trailer as a point mass at the fifth wheel), which neglects the trailer's yaw transient.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import casadi as ca
import numpy as np
from numba import njit

from workbench.base.errors import WorkbenchInputError
from workbench.vehicles.base import VehicleGeometry, VehicleModel
from workbench.vehicles.single_track import (
    PredictionParams,
    SingleTrackParams,
    params_from_geometry,
)

MODEL_KINDS = ("dynamic", "kinematic", "kinematic-lag")
#: The RK4 step of the prediction is sub-divided until h |lambda| <= this for the fastest lateral mode at the
#: lowest prediction speed (RK4's real stability limit is 2.785; 2.0 keeps the fast modes well damped).
RK4_STABILITY_MARGIN = 2.0
#: 1 - kappa e_y is kept above this in s' (the path's centre of curvature is never crossed in prediction).
_MIN_FRENET_SCALE = 0.1


# ---------------------------------------------------------------------------------------------- from vehicles
def prediction_params_for(vehicle: object) -> PredictionParams:
    """Prediction parameters for a vehicle given as a `VehicleModel` (its `single_track`), a params dataclass of
    one (the fields of a preset), a preset name or TOML file path (str/Path), a `VehicleGeometry` (kinematic
    default) or already as `PredictionParams`.

    Parameters
    ----------
    vehicle : object
        A `VehicleModel`, a vehicle params dataclass, a preset name or TOML file path (str or pathlib.Path), a
        `VehicleGeometry` or `PredictionParams`.

    Returns
    -------
    PredictionParams
        The single track's geometry, limits and (when the vehicle gives them) mass, inertia and tyres.

    Raises
    ------
    WorkbenchInputError
        A type not listed above, or an unknown preset or unreadable vehicle file.
    """
    from workbench.vehicles import load_vehicle
    from workbench.vehicles.presets import MODEL_TYPES

    if isinstance(vehicle, PredictionParams):
        return vehicle
    if isinstance(vehicle, VehicleGeometry):
        return params_from_geometry(vehicle)
    if isinstance(vehicle, str | Path):
        return load_vehicle(str(vehicle)).single_track(f"vehicle {str(vehicle)!r}")
    if isinstance(vehicle, VehicleModel):
        return vehicle.single_track(f"the {vehicle.name} model's parameters")
    for model_type, params_type in MODEL_TYPES.values():
        if type(vehicle) is params_type:
            return model_type(vehicle).single_track(f"{type(vehicle).__name__} parameters")
    raise WorkbenchInputError(
        f"cannot build an MPC prediction model from a {type(vehicle).__name__}; give a VehicleModel, a vehicle "
        "params dataclass, a preset name or TOML file, a VehicleGeometry or PredictionParams"
    )


@functools.lru_cache(maxsize=32)
def matching_preset(geometry: VehicleGeometry) -> str | None:
    """The shipped preset whose geometry equals `geometry` exactly, or None. Presets with a single-track model
    (dynamic-bicycle, tractor-semitrailer, commonroad-mb) are tried before the kinematic one."""
    from workbench.vehicles import VEHICLES

    preference = ("dynamic-bicycle", "tractor-semitrailer", "commonroad-mb", "kinematic-bicycle")
    order = sorted(VEHICLES, key=lambda name: preference.index(name) if name in preference else len(preference))
    for name in order:
        if VEHICLES[name]().geometry == geometry:
            return name
    return None


# ---------------------------------------------------------------------------------------------- the model
class PredictionModel:
    """The ODE of one model kind as CasADi expressions, and its RK4 discretisation.

    x: states (`state_names`); u: [delta_c'] (rad/s); p: [kappa (1/m), v (m/s)], held over an interval.

    Parameters
    ----------
    params : PredictionParams
        The vehicle's single-track parameters (`prediction_params_for`).
    kind : str or None
        "dynamic", "kinematic" or "kinematic-lag" (None: "kinematic-lag" with a lag, else "dynamic" when the
        single track is known, else "kinematic").

    Raises
    ------
    WorkbenchInputError
        An unknown kind, "dynamic" without mass, inertia and tyres, or "kinematic-lag" without a lag.
    """

    def __init__(self, params: PredictionParams, kind: str | None = None) -> None:
        kind = kind or params.default_kind()
        if kind not in MODEL_KINDS:
            raise WorkbenchInputError(f"model kind must be one of {', '.join(MODEL_KINDS)}; got {kind!r}")
        if kind == "dynamic" and params.single_track is None:
            raise WorkbenchInputError(
                f"the dynamic model needs mass, inertia and tyres, which {params.source or 'these parameters'} "
                "do not give; name a vehicle preset or file, or use model 'kinematic'"
            )
        if kind == "kinematic-lag" and params.lag is None:
            raise WorkbenchInputError("model 'kinematic-lag' needs an identified lag: give a lag_file")
        self.params, self.kind = params, kind
        names = ["cte_m", "heading_error_rad"]
        if kind == "dynamic":
            names += ["vy_cg_mps", "yaw_rate_rad_s", "road_wheel_rad"]
        elif kind == "kinematic":
            names += ["road_wheel_rad"]
        else:
            names += ["wheelbase_x_curvature", "wheelbase_x_curvature_rate_1ps"]
            if params.lag is not None and params.lag.delay_s > 0.0:
                names += ["delayed_wheelbase_x_curvature"]
        names += ["road_wheel_cmd_rad"]
        self.state_names: tuple[str, ...] = tuple(names)
        self.nx, self.nu, self.np = len(names), 1, 2
        self.i_cte, self.i_heading, self.i_cmd = 0, 1, len(names) - 1
        x, u, p = ca.SX.sym("x", self.nx), ca.SX.sym("u", 1), ca.SX.sym("p", 2)
        xdot, yaw_rate, progress = self._ode(x, u, p)
        self.ode = ca.Function("ode", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])
        self.lateral_accel = ca.Function("lat_accel", [x, p], [p[1] * yaw_rate], ["x", "p"], ["ay"])
        self.progress_rate = ca.Function("progress_rate", [x, p], [progress], ["x", "p"], ["sdot"])
        self.reference = ca.Function("reference", [p], [self._reference(p[0], p[1])], ["p"], ["x_ref"])

    def _ode(self, x: ca.SX, u: ca.SX, p: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX]:
        prm, kind = self.params, self.kind
        kappa, v = p[0], p[1]
        e_y, e_psi, delta_c = x[0], x[1], x[self.i_cmd]
        wheelbase = prm.wheelbase_m
        v_rear: ca.SX | float  # the rear axle's lateral speed: 0 in the kinematic kinds
        if kind == "dynamic":
            st = prm.single_track
            assert st is not None
            vy, r, delta = x[2], x[3], x[4]
            a, b = st.cg_to_front_axle_m, st.cg_to_rear_axle_m
            alpha_f = delta - ca.atan((vy + a * r) / v)
            alpha_r = -ca.atan((vy - b * r) / v)
            fyf = _magic(alpha_f, st.front_peak_force_n, st.front_cornering_stiffness_n_per_rad, st)
            fyr = _magic(alpha_r, st.rear_peak_force_n, st.rear_cornering_stiffness_n_per_rad, st)
            vy_dot = (fyf * ca.cos(delta) + fyr) / st.mass_kg - v * r
            r_dot = (a * fyf * ca.cos(delta) - b * fyr) / st.yaw_inertia_kgm2
            delta_dot = (delta_c - delta) / prm.steering_time_constant_s
            v_rear, yaw_rate = vy - b * r, r
            states_dot = [vy_dot, r_dot, delta_dot]
        elif kind == "kinematic":
            delta = x[2]
            v_rear, yaw_rate = 0.0, v * ca.tan(delta) / wheelbase
            states_dot = [(delta_c - delta) / prm.steering_time_constant_s]
        else:
            lag = prm.lag
            assert lag is not None
            # States are curvatures times the wheelbase (L kappa, dimensionless, about the road-wheel angle) so that
            # they are of the size of the other states: the QP then needs no scaling.
            # States: L kappa_v, its rate, and the delay's first-order Pade state if any (SteeringLag's ODE).
            kinematic = lag.steady_state_gain * ca.tan(delta_c)  # K tan(delta_c): the settled L kappa
            states_dot = lag.state_derivatives([x[2 + i] for i in range(lag.ode_state_count)], kinematic)
            v_rear, yaw_rate = 0.0, v * x[2] / wheelbase
        scale = ca.fmax(1.0 - kappa * e_y, _MIN_FRENET_SCALE)
        s_dot = (v * ca.cos(e_psi) - v_rear * ca.sin(e_psi)) / scale
        e_y_dot = v * ca.sin(e_psi) + v_rear * ca.cos(e_psi)
        e_psi_dot = yaw_rate - kappa * s_dot
        xdot = ca.vertcat(e_y_dot, e_psi_dot, *states_dot, u[0])
        return xdot, yaw_rate, s_dot

    def progress(self, states: np.ndarray, kappa: np.ndarray, speed: np.ndarray, step_s: float) -> np.ndarray:
        """Predicted arc length travelled along the path (m) at each node of a plan, states (N+1, nx) with
        kappa and speed per interval (N,): the trapezoidal integral of s' (`progress_rate`; node N uses the last
        interval's kappa and speed). Compiled (`_progress_kernel`); the tests check it against `progress_rate`.

        Parameters
        ----------
        states : numpy.ndarray of float
            The plan's states, shape (N+1, nx).
        kappa : numpy.ndarray of float, 1/m
            The path's curvature over each interval, shape (N,).
        speed : numpy.ndarray of float, m/s
            The speed over each interval, shape (N,).
        step_s : float, s
            The interval's duration, > 0.

        Returns
        -------
        numpy.ndarray of float, m
            The arc length travelled from node 0 to each node, shape (N+1,), starting at 0.
        """
        if self.kind == "dynamic":
            st = self.params.single_track
            assert st is not None
            i_vy, i_r, b = (
                self.state_names.index("vy_cg_mps"),
                self.state_names.index("yaw_rate_rad_s"),
                st.cg_to_rear_axle_m,
            )
        else:
            i_vy, i_r, b = -1, -1, 0.0
        return _progress_kernel(states, kappa, speed, step_s, self.i_cte, self.i_heading, i_vy, i_r, b)

    def _reference(self, kappa: ca.SX, v: ca.SX) -> ca.SX:
        """Steady cornering on the path (e_y = 0) at curvature kappa and speed v: the state the LTV-MPC linearises
        about. For the dynamic kind: r = v kappa, the axle forces that hold the turn, their slip angles (the magic
        formula inverted without its small curvature factor E), the rear axle's sideslip as the heading error and
        the steering that goes with them (as Rajamani, Vehicle Dynamics and Control, section 3.2, with linear
        tyres)."""
        prm, names = self.params, self.state_names
        x = [ca.SX(0.0)] * self.nx
        kinematic_angle = ca.atan(prm.wheelbase_m * kappa)
        if self.kind == "dynamic":
            st = prm.single_track
            assert st is not None
            a, b, m = st.cg_to_front_axle_m, st.cg_to_rear_axle_m, st.mass_kg
            r = v * kappa
            alpha_r = _inverse_magic(
                m * v * r * a / (a + b), st.rear_peak_force_n, st.rear_cornering_stiffness_n_per_rad, st
            )
            vy = b * r - v * ca.tan(alpha_r)
            front = m * v * r * b / (a + b)  # = Fyf cos(delta): one fixed-point pass for the cosine
            delta = ca.SX(0.0)
            for _ in range(2):
                alpha_f = _inverse_magic(
                    front / ca.cos(delta), st.front_peak_force_n, st.front_cornering_stiffness_n_per_rad, st
                )
                delta = alpha_f + ca.atan((vy + a * r) / v)
            x[names.index("vy_cg_mps")] = vy
            x[names.index("yaw_rate_rad_s")] = r
            x[names.index("road_wheel_rad")] = delta
            x[self.i_heading] = alpha_r
            x[self.i_cmd] = delta
        elif self.kind == "kinematic":
            x[names.index("road_wheel_rad")] = kinematic_angle
            x[self.i_cmd] = kinematic_angle
        else:
            lag = prm.lag
            assert lag is not None
            x[names.index("wheelbase_x_curvature")] = prm.wheelbase_m * kappa
            if "delayed_wheelbase_x_curvature" in names:
                x[names.index("delayed_wheelbase_x_curvature")] = prm.wheelbase_m * kappa
            x[self.i_cmd] = ca.atan(prm.wheelbase_m * kappa / lag.steady_state_gain)
        return ca.vertcat(*x)

    def reference_states(self, kappa: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """`_reference` at each (kappa, speed) pair: (n, nx).

        Parameters
        ----------
        kappa : array_like of float, 1/m
            The path's curvatures, n of them (a scalar: one).
        speed : array_like of float, m/s
            The speeds, > 0, as many as the curvatures.

        Returns
        -------
        numpy.ndarray of float
            The steady-cornering state on the path (no cross-track error) at each pair, shape (n, nx).
        """
        kappa, speed = np.atleast_1d(kappa).astype(float), np.atleast_1d(speed).astype(float)
        out = self.reference.map(kappa.size)(np.vstack((kappa, speed)))
        return np.asarray(out.full()).T

    def substeps_for(self, step_s: float, min_speed_mps: float) -> int:
        """RK4 sub-steps per prediction step so that the fastest mode stays within RK4_STABILITY_MARGIN.

        Parameters
        ----------
        step_s : float, s
            The prediction step, > 0.
        min_speed_mps : float, m/s
            The lowest speed predicted at, > 0 (the dynamic model's lateral modes are fastest there).

        Returns
        -------
        int
            The number of sub-steps, >= 1: step_s / substeps x the fastest rate (1/s) stays within 2.
        """
        prm = self.params
        fastest = 1.0 / prm.steering_time_constant_s
        if self.kind == "dynamic":
            assert prm.single_track is not None
            fastest = max(fastest, prm.single_track.fastest_lateral_mode_per_s(min_speed_mps))
        elif self.kind == "kinematic-lag":
            lag = prm.lag
            assert lag is not None
            fastest = lag.fastest_rate_per_s
        return max(1, math.ceil(step_s * fastest / RK4_STABILITY_MARGIN - 1e-9))

    def discrete(self, step_s: float, substeps: int, name: str = "F") -> ca.Function:
        """x_next = F(x, u, p): `substeps` RK4 steps over step_s with u and p held (an SX function).

        Parameters
        ----------
        step_s : float, s
            The step's duration, > 0.
        substeps : int
            The RK4 steps within it, >= 1 (`substeps_for`).
        name : str
            The CasADi function's name.

        Returns
        -------
        casadi.Function
            F(x (nx,), u (1,), p (2,)) -> x_next (nx,).
        """
        x, u, p = ca.SX.sym("x", self.nx), ca.SX.sym("u", 1), ca.SX.sym("p", 2)
        h = step_s / substeps
        xk = x
        for _ in range(substeps):
            k1 = self.ode(xk, u, p)
            k2 = self.ode(xk + 0.5 * h * k1, u, p)
            k3 = self.ode(xk + 0.5 * h * k2, u, p)
            k4 = self.ode(xk + h * k3, u, p)
            xk = xk + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        return ca.Function(name, [x, u, p], [xk], ["x", "u", "p"], ["x_next"])


def _magic(alpha: ca.SX, peak: float, stiffness: float, st: SingleTrackParams) -> ca.SX:
    shape, curv = st.tyre_shape_factor, st.tyre_curvature_factor
    bb = stiffness / (shape * peak)
    z = bb * alpha
    return peak * ca.sin(shape * ca.atan(z - curv * (z - ca.atan(z))))


def _inverse_magic(force: ca.SX, peak: float, stiffness: float, st: SingleTrackParams) -> ca.SX:
    """Slip angle giving `force` by the magic formula with E = 0 (within 99% of the peak)."""
    shape = st.tyre_shape_factor
    bb = stiffness / (shape * peak)
    ratio = ca.fmin(ca.fmax(force / peak, -0.99), 0.99)
    return ca.tan(ca.asin(ratio) / shape) / bb


@njit(cache=True)
def _progress_kernel(
    states: np.ndarray,
    kappa: np.ndarray,
    speed: np.ndarray,
    step_s: float,
    i_cte: int,
    i_heading: int,
    i_vy: int,
    i_r: int,
    cg_to_rear_axle_m: float,
) -> np.ndarray:  # pragma: no cover - compiled
    """`PredictionModel.progress`: s' = (v cos(e_psi) - v_r sin(e_psi)) / max(1 - kappa e_y, _MIN_FRENET_SCALE)
    per node, v_r = v_y - b r (i_vy >= 0, the dynamic kind) or 0, integrated by the trapezoidal rule."""
    n_nodes, last = states.shape[0], kappa.shape[0] - 1
    out = np.empty(n_nodes)
    out[0] = 0.0
    previous = 0.0
    for k in range(n_nodes):
        j = min(k, last)
        e_y, e_psi = states[k, i_cte], states[k, i_heading]
        along = speed[j] * math.cos(e_psi)
        if i_vy >= 0:
            along -= (states[k, i_vy] - cg_to_rear_axle_m * states[k, i_r]) * math.sin(e_psi)
        rate = along / max(1.0 - kappa[j] * e_y, _MIN_FRENET_SCALE)
        if k > 0:
            out[k] = out[k - 1] + 0.5 * step_s * (rate + previous)
        previous = rate
    return out
