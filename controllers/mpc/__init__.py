"""Model-predictive lateral controllers, the baselines of the paper's MPC comparison (section 6.6, Figure 17).

`NMPCController` ("nmpc"): CasADi nonlinear MPC on a nonlinear single-track prediction, solved by a real-time
iteration on OSQP (default) or by IPOPT. `LMPCController` ("lmpc"): linear time-varying MPC on OSQP in the manner
of Autoware's lateral MPC. Both predict with `PredictionModel`, whose parameters come from the vehicle presets
(`prediction_params_for`) and, optionally, the steering lag identified by `tuning fit-lag`.

Modules: prediction_model (parameters, model kinds, ODEs), ocp (the optimal control problem), nlp_solver (IPOPT),
rti (real-time iteration), sparse_qp (the OSQP QP), lmpc (LTV-MPC), plan (warm start and fallback), config (the
shared options), controller (the shared controller step and its delay compensation), delay_segments (its compiled
parts), pose_filter (the optional pose filter), prediction_vehicle (which vehicle is predicted with), preview (the
path along the horizon), codegen (compiled CasADi functions), status (solve status codes).
"""

from controllers.mpc.config import MPCConfig
from controllers.mpc.controller import MPCController
from controllers.mpc.lmpc import LMPCConfig, LMPCController
from controllers.mpc.nmpc import NMPCConfig, NMPCController
from controllers.mpc.prediction_model import (
    PredictionModel,
    PredictionParams,
    SingleTrackParams,
    params_from_geometry,
    prediction_params_for,
)
from controllers.mpc.status import SolveStatus

__all__ = [
    "LMPCConfig",
    "LMPCController",
    "MPCConfig",
    "MPCController",
    "NMPCConfig",
    "NMPCController",
    "PredictionModel",
    "PredictionParams",
    "SingleTrackParams",
    "SolveStatus",
    "params_from_geometry",
    "prediction_params_for",
]
