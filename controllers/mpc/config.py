"""The options both MPCs share (`MPCConfig`), their search space (`MPC_SEARCH_SPACE`) and the controller period
they assume before a run gives its own (`DEFAULT_PERIOD_S`)."""

from __future__ import annotations

from dataclasses import dataclass

from controllers.config_checks import Choice, Flag, Instance, Number, Whole, check_options, option
from controllers.mpc.ocp import TrackingWeights
from controllers.mpc.pose_filter import MAX_POSE_FILTER_HZ
from controllers.mpc.prediction_model import MODEL_KINDS, PredictionParams
from controllers.search_space import Tunable
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.vehicles.steering_lag import SteeringLag

#: The largest cost weight the options allow (larger ones only make the QPs ill-conditioned).
MAX_WEIGHT = 1e9
#: The controller period (s) an MPC assumes until `reset` gives the run's: the simulator's default rate, 50 Hz. The
#: solver's time budget is this period when max_solve_time_s is 0 and no run has set it.
DEFAULT_PERIOD_S = 0.02


def _vehicle_choices() -> tuple[str, ...]:
    """What MPCConfig.vehicle may name: "auto", "geometry" or a shipped preset (`workbench vehicles`)."""
    from workbench.vehicles import VEHICLES

    return ("auto", "geometry", *VEHICLES)


@dataclass(frozen=True)
class MPCConfig:
    """Options common to both MPCs (`controllers.mpc.controller` says how each acts). Each field's unit, allowed
    range and meaning are in its metadata (`config_checks.option`): `check_options` checks them and `workbench
    controllers --show nmpc` prints them. The objects a file is read into (`prediction_vehicle`, `lag`) are given
    in a config file or `--set` by their file options (`vehicle_file`, `lag_file`), read when the config is
    loaded."""

    vehicle: str = option(
        "auto",
        'where the prediction model\'s parameters come from: "auto" (the steered vehicle\'s own when the caller passes '
        "its model, else the shipped preset of the same geometry, else the geometry alone), \"geometry\" (kinematic "
        "single track from the geometry), or a preset name",
        Choice(_vehicle_choices),
    )
    prediction_vehicle: PredictionParams | None = option(  # noqa: RUF009  (option is a dataclasses.field)
        None,
        "a vehicle's single-track equivalent to predict with instead of `vehicle` (in a file, vehicle_file names a "
        "vehicle TOML file)",
        Instance(PredictionParams, "as `vehicle` says"),
    )
    lag: SteeringLag | None = option(  # noqa: RUF009  (option is a dataclasses.field)
        None,
        'an identified steering lag the prediction uses (in a file, lag_file names a "steering-lag/1" JSON from '
        "`tuning fit-lag`)",
        Instance(SteeringLag, "no identified lag"),
    )
    model: str = option(
        "auto",
        'the prediction model (`prediction_model.py`): "auto" (kinematic-lag with a lag, else dynamic when mass and '
        'tyres are known, else kinematic), "dynamic", "kinematic" or "kinematic-lag"',
        Choice(("auto", *MODEL_KINDS)),
    )
    horizon_steps: int = option(30, "N, the prediction horizon in steps of step_s", Whole(2, 500, "steps"))
    step_s: float = option(0.05, "h, the prediction step", Number(1e-3, 1.0, "s"))
    weight_cte: float = option(200.0, "the stage weight on the cross-track error", Number(0.0, MAX_WEIGHT, "1/m^2"))
    weight_heading: float = option(
        10.0, "the stage weight on the heading error", Number(0.0, MAX_WEIGHT, "1/rad^2")
    )
    weight_steer_rate: float = option(
        5.0,
        "the stage weight on the road-wheel angle's rate (the input): larger is smoother and slower",
        Number(0.0, MAX_WEIGHT, "s^2/rad^2", low_open=True),
    )
    terminal_weight_cte: float = option(
        2000.0, "the terminal weight on the cross-track error", Number(0.0, MAX_WEIGHT, "1/m^2")
    )
    terminal_weight_heading: float = option(
        100.0, "the terminal weight on the heading error", Number(0.0, MAX_WEIGHT, "1/rad^2")
    )
    max_lat_accel_mps2: float = option(
        0.0,
        "a soft limit on the predicted lateral acceleration (its slack weighted by weight_lat_accel_slack)",
        Number(0.0, 50.0, "m/s^2", note="0: no limit"),
    )
    weight_lat_accel_slack: float = option(
        100.0,
        "the weight on the lateral-acceleration limit's slack",
        Number(0.0, MAX_WEIGHT, "s^4/m^2"),
    )
    min_model_speed_mps: float = option(
        3.0, "the prediction never runs slower than this", Number(0.5, 50.0, "m/s")
    )
    max_solve_time_s: float = option(
        0.0,
        "the solver's wall-time budget; a solve cut short by it is late and not used (a machine-dependent result: "
        "raise it for reproducible runs)",
        Number(0.0, 10.0, "s", note="0: the sample time"),
    )
    codegen: bool = option(
        True,
        "compile the model's derivatives with the system C compiler where that pays (cached; ignored without a "
        "compiler)",
        Flag(),
    )
    input_delay_s: float = option(
        0.0,
        "D, the known actuation dead time (a command sent at t reaches the steering at t + D), compensated by "
        "predicting the measured state to t + D with the commands already sent",
        Number(0.0, 1.0, "s", note="0: none"),
    )
    measurement_latency_s: float = option(
        0.0,
        "L, the known measurement latency (the measurement stamped t describes t - L), compensated as input_delay_s",
        Number(0.0, 1.0, "s", note="0: none"),
    )
    pose_filter_cutoff_hz: float = option(
        0.0,
        "the crossover frequency of the complementary filter on the measured pose (`PoseFilter`): pose noise in the "
        "loop's correction band then no longer drives the steering",
        Number(0.0, MAX_POSE_FILTER_HZ, "Hz", note="0: off"),
    )
    yaw_rate_latency_s: float | None = option(
        None,
        "the known latency of the measured yaw rate when it differs from measurement_latency_s, by which the pose "
        "filter aligns the yaw rate with the pose (only with the pose filter)",
        Number(0.0, 1.0, "s", none_means="measurement_latency_s"),
    )

    def __post_init__(self) -> None:
        check_options(self)
        if self.yaw_rate_latency_s is not None and self.pose_filter_cutoff_hz == 0.0:
            raise WorkbenchInputError(
                "yaw_rate_latency_s is used by the pose filter only: set pose_filter_cutoff_hz > 0 or leave "
                f"yaw_rate_latency_s unset (none); got {value_text(self.yaw_rate_latency_s)}"
            )

    @property
    def yaw_rate_lead_s(self) -> float:
        """How much older the measured yaw rate is than the measured pose (s): yaw_rate_latency_s - L."""
        latency = self.measurement_latency_s if self.yaw_rate_latency_s is None else self.yaw_rate_latency_s
        return latency - self.measurement_latency_s

    @property
    def weights(self) -> TrackingWeights:
        return TrackingWeights(
            cte=self.weight_cte,
            heading=self.weight_heading,
            steer_rate=self.weight_steer_rate,
            terminal_cte=self.terminal_weight_cte,
            terminal_heading=self.terminal_weight_heading,
            lat_accel_slack=self.weight_lat_accel_slack,
        )


#: The search space of both MPCs (`NMPCController`, `LMPCController`): the cost weights and the horizon. The
#: weights act through their ratios, over decades: a log scale each. The horizon is at least 20 steps of 0.04 s
#: (0.8 s): on the loaded truck's dlc at 30 km/h a 0.5-0.6 s horizon leaves the path.
MPC_SEARCH_SPACE = (
    Tunable("weight_cte", "log", 10.0, 5000.0, reason="a heavier cross-track weight tracks tighter for more "
            "steering effort and less damping"),
    Tunable("weight_heading", "log", 0.5, 500.0, reason="a heavier heading weight damps the approach to the path, "
            "and slows the correction of an offset"),
    Tunable("weight_steer_rate", "log", 0.1, 100.0, reason="a heavier steering-rate weight is smoother and slower: "
            "less steering effort, more cross-track error"),
    Tunable("terminal_weight_cte", "log", 100.0, 50000.0, reason="the horizon end's cross-track weight: heavier "
            "settles on the path sooner, a short horizon stabler"),
    Tunable("terminal_weight_heading", "log", 5.0, 2000.0, reason="the horizon end's heading weight: heavier "
            "arrives aligned with the path, at the cost of effort"),
    Tunable("horizon_steps", "integer", 20, 60, reason="a longer horizon sees bends earlier and is stabler, for "
            "solve time growing with the steps"),
    Tunable("step_s", "linear", 0.04, 0.1, reason="a longer prediction step sees further for the same solve time, "
            "with a coarser model of fast motion"),
)  # fmt: skip


__all__ = ["MPCConfig"]
