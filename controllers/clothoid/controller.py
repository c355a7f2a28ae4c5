"""The clothoid-based lateral controller (Shaju, Southward & Ahmadian 2024, Figure 2).

Each step (Figure 2): the start pose, the rear-axle centre along its course with the curvature kappa(0) of Eq. 3,
moved ahead by an optional prediction time (step 5); the lookahead (adaptive by Fréchet distance, fixed or
proportional to speed; `lookahead.py`) and the hyper-clothoid to the target (Eq. 3; `clothoid_fit.py`); kappa' x V
integrated into the curvature command under the speed-dependent curvature and curvature-rate limits (section 4;
`curvature_limits.py`); Ackermann, tan(phi) = L kappa, and the steering ratio; the lead filter of Eq. 6 against
the steering-to-curvature lag of Eq. 5 (at the controller rate, scheduled on speed; `lead_filter.py`).

Choices the paper leaves open are options (ClothoidConfig); the defaults, and why (measurements in docs/clothoid.md):
kappa(0) is the curvature actually driven, yaw rate / speed (the command or the steering's kinematic curvature
differ from it by understeer and lag, and the fit then leaves a steady offset in every bend); the clothoid starts
along the rear axle's course, yaw plus sideslip, the direction the vehicle moves in; the Fréchet threshold is the
paper's absolute one (off the path the search falls back to the shortest candidate, which returns fastest).

Added to the paper so that the loop keeps its margins on the vehicle it steers:
  - a lookahead floor per speed: `loop_analysis.py` linearises the loop (Eq. 3 on the predicted pose, Figure 2's
    integrator, the lead filter, the lags of Eq. 5, sampling) and finds the shortest lookahead from which the
    phase and gain margins hold about a straight and an arc; the loop gain goes as L^-3, so the search's choice
    is followed with hysteresis and at a limited rate, slowly against L / V (`lookahead_filter.py`); a geometric
    ceiling keeps the target within max_target_turn_deg of the path's turn (ClothoidConfig), never below the floor;
  - two degrees of freedom (`path_feedforward.py`): feedback on Eq. 3's kappa' less the path's own clothoid's,
    and the steering that inverts the identified lag of Eq. 5 along the path fed forward (added after the lead
    filter), so tracking needs no short lookaheads where the loop has no margin; where that lag does not explain
    the vehicle's logs (the loaded truck's trailer), the vehicle's preview responses identified from the same logs
    give the feed-forward and the reference instead (`preview_model.py`);
  - the steered vehicle's own lead filter, curvature limits and lags (`vehicle_tuning.py`, made by `tuning
    schedule --design margins`; the config holds them); without them, no lead filter and no floor.

A known dead time (known_delay_s: measurement latency plus actuation dead time) is compensated by default
with the identified lags driven by the commands already sent (`delay_predictor.py`, a Smith predictor): the start
pose and kappa(0) are where the vehicle will be when the command now sent takes effect, and the loop the clothoid law
closes is the delay-free one. The floor keeps the margins on that loop, 30 deg and 3 dB on the loop with its delay,
and half those with the delay 50 ms off either way (`loop_analysis.DelayRobustness`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, ClassVar

import numpy as np
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.base import Controller, Measurement
from controllers.clothoid import loop_requirements as requirements
from controllers.clothoid import step_kernel as sk
from controllers.clothoid.curvature_limits import CurvatureLimits
from controllers.clothoid.delay_predictor import history_length
from controllers.clothoid.filter_schedule import FilterSchedule
from controllers.clothoid.lead_filter import DiscreteLeadFilter, LeadFilterParams
from controllers.clothoid.lookahead import MAX_CURVE_POINTS, candidate_count
from controllers.clothoid.lookahead_filter import RATE_LIMIT
from controllers.clothoid.path_feedforward import FeedforwardTiming
from controllers.clothoid.vehicle_tuning import FloorInputs, VehicleTuning
from controllers.config_checks import Choice, Flag, Instance, Number, check_options, option
from controllers.search_space import Tunable
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.path import ReferencePath
from workbench.vehicles.base import VehicleGeometry, VehicleModel

if TYPE_CHECKING:  # the loop analysis (python-control, ~0.9 s to import) only where floors are computed
    from controllers.clothoid.loop_analysis import DelayRobustness, LoopSettings, PlantLags
    from workbench.simulation.known_delays import KnownDelays

LOOKAHEAD_MODES = ("adaptive", "fixed", "speed")
INITIAL_CURVATURE = ("yaw-rate", "command", "steering")
HEADINGS = ("course", "yaw")
THRESHOLD_MODES = ("excess", "absolute")
SEARCH_STARTS = ("last", "ends")
#: The models of the vehicle along the path the feed-forward and the reference can use (`feedforward_model`).
FEEDFORWARD_MODELS = ("auto", "lag", "preview")
#: Below this speed (m/s) yaw rate / speed and the course angle are too noisy to use.
MIN_SPEED_MPS = 0.5
#: The lookahead floor is computed at speed nodes this many km/h apart, each with the lead filter the step uses
#: there, and interpolated linearly between the two about the speed driven (`step_kernel.floor_node`). The floor
#: needed rises by up to 0.5 m a km/h (the loaded truck at 20-35 km/h): held over a band it lets the margins fall
#: short at the band's upper end (a 5 km/h band's centre floor at its edge: the truck's phase margin 37 deg at
#: 22.4 km/h); interpolated, they hold between nodes within 3 deg and 1 dB (`test_clothoid_hairpin_delay.py`), and
#: the floor, with the loop gain, moves with the speed, not in steps to and fro as the speed hovers at an edge.
#: Nodes 1 km/h apart would hold them within 2 deg and 0.6 dB, at 2.5 times the analysis (1.5-2 s a node with a
#: known delay), which runs through every speed a run passes.
FLOOR_SPEED_STEP_KMH = 2.5
#: The lowest speed node (km/h): below it, its floor.
FLOOR_MIN_SPEED_KMH = 5.0
#: Longest lookahead (m) the floor search considers when the configured range has no margin at a speed.
MAX_FLOOR_LOOKAHEAD_M = 40.0
#: Lateral acceleration (g) of the arc about which the floor is checked besides the straight (the speed profile's
#: 0.3 g bound, with margin), capped by the curvature limit.
FLOOR_ARC_LATERAL_ACCEL_G = 0.4
#: The longest lookahead (m) the options allow.
MAX_LOOKAHEAD_M = 200.0
#: The controller's own diagnostics (`ctrl_*` columns), the same every step: zero until the first step.
DIAGNOSTIC_KEYS = (
    "lookahead_m",
    "searched_lookahead_m",
    "lookahead_floor_m",
    "lookahead_ceiling_m",
    "frechet_m",
    "curvature_rate_1pm2",
    "clothoid_curvature_rate_1pm2",
    "reference_curvature_rate_1pm2",
    "feedforward_curvature_rate_1pm2",
    "clothoid_length_m",
    "end_error_m",
    "fit_status",
    "evaluations",
    "initial_curvature_1pm",
    "curvature_cmd_1pm",
    "steer_unfiltered_rad",
)


@dataclass(frozen=True)
class ClothoidConfig:
    """Options of the clothoid controller (the paper's values where it gives them; module docstring). Each field's
    unit, allowed range and meaning are in its metadata (`config_checks.option`): `check_options` checks them and
    `workbench controllers --show clothoid` prints them. The objects a file is read into (`tuning`, `lead_filter`,
    `curvature_limits`) are given in a config file or `--set` by their file options (`tuning_dir`, `filter_file`,
    `limits_file`), read when the config is loaded."""

    lookahead_mode: str = option(
        "adaptive",
        'how the lookahead is chosen: "adaptive" (the Fréchet search, section 3), "fixed" (fixed_lookahead_m) or '
        '"speed" (lookahead_gain_s x speed, clipped to the range)',
        Choice(LOOKAHEAD_MODES),
    )
    min_lookahead_m: float = option(
        5.0,
        "the lower end of the lookahead range (the paper: 5-20 m); the lookahead floor raises it where the loop's "
        "margins need a longer one",
        Number(0.5, MAX_LOOKAHEAD_M, "m"),
    )
    max_lookahead_m: float = option(
        20.0,
        "the upper end of the lookahead range (at least min_lookahead_m); raised with the floor where needed",
        Number(0.5, MAX_LOOKAHEAD_M, "m"),
    )
    lookahead_step_m: float = option(
        0.5,
        "the spacing of the adaptive search's candidate lookaheads (at most 1000 candidates over the range)",
        Number(0.05, 50.0, "m"),
    )
    search_start: str = option(
        "last",
        'where the adaptive search starts: "last" (the last step\'s choice; few fits a step) or "ends" (bisection '
        "from the range's ends every step); the two choose alike wherever admissibility falls with the lookahead",
        Choice(SEARCH_STARTS),
    )
    min_preview_time_s: float = option(
        0.0,
        "raises the lower end of the lookahead range to this time x speed (0: off)",
        Number(0.0, 10.0, "s"),
    )
    lookahead_hysteresis_m: float = option(
        0.5,
        "changes of the search's choice smaller than this are not followed (`lookahead_filter.py`)",
        Number(0.0, 50.0, "m"),
    )
    max_lookahead_growth_m_per_m: float | None = option(
        0.3,
        "the most the followed lookahead lengthens per metre travelled (`lookahead_filter.py`)",
        RATE_LIMIT,
    )
    max_lookahead_shrink_m_per_m: float | None = option(
        0.5,
        "the most the followed lookahead shortens per metre travelled (`lookahead_filter.py`)",
        RATE_LIMIT,
    )
    min_phase_margin_deg: float = option(
        requirements.REQUIRED_PHASE_MARGIN_DEG,
        "the phase margin the lookahead floor keeps (`loop_analysis.py`; 0 here and in min_gain_margin_db: no floor; "
        "with a known delay compensated by the lags' model, the delay-free loop's)",
        Number(0.0, 89.0, "deg"),
    )
    min_gain_margin_db: float = option(
        requirements.REQUIRED_GAIN_MARGIN_DB,
        "the gain margin the lookahead floor keeps (as min_phase_margin_deg)",
        Number(0.0, 40.0, "dB"),
    )
    min_delayed_phase_margin_deg: float = option(
        requirements.REQUIRED_DELAYED_PHASE_MARGIN_DEG,
        'with delay_compensation "model" and a known delay, the phase margin the loop with its delay and the '
        "predictor keeps besides, for dead times within known_delay_uncertainty_s of the known one "
        "(`loop_analysis.DelayRobustness`)",
        Number(0.0, 89.0, "deg"),
    )
    min_delayed_gain_margin_db: float = option(
        requirements.REQUIRED_DELAYED_GAIN_MARGIN_DB,
        "the gain margin kept as min_delayed_phase_margin_deg is",
        Number(0.0, 40.0, "dB"),
    )
    known_delay_uncertainty_s: float = option(
        requirements.DELAY_UNCERTAINTY_S,
        "how far the vehicle's dead time may be from known_delay_s (either way) with the min_delayed_* margins kept",
        Number(0.0, 1.0, "s"),
    )
    max_target_turn_deg: float = option(
        60.0,
        "the lookahead's geometric ceiling: no target farther round a bend than the path turning this much from the "
        "foot point (never below the floor); an offset shows at a target theta round the bend as offset x "
        "cos(theta), which the margins do not see",
        Number(0.0, 180.0, "deg", note="0: no ceiling"),
    )
    fixed_lookahead_m: float = option(
        10.0,
        'the lookahead of lookahead_mode "fixed"',
        Number(0.5, MAX_LOOKAHEAD_M, "m"),
    )
    lookahead_gain_s: float = option(
        1.0,
        'the lookahead per unit speed of lookahead_mode "speed" (clipped to the range)',
        Number(0.0, 100.0, "s", low_open=True),
    )
    frechet_threshold_m: float = option(
        0.02,
        "the adaptive search's threshold on the Fréchet distance between the clothoid and the path (the paper: "
        "0.5 m); threshold_mode says how it applies",
        Number(0.0, 100.0, "m", low_open=True),
    )
    threshold_mode: str = option(
        "absolute",
        'how frechet_threshold_m applies: "absolute" (the paper\'s) or "excess" (over the current |CTE|)',
        Choice(THRESHOLD_MODES),
    )
    frechet_point_spacing_m: float = option(
        0.5,
        f"the sampling of the curves the Fréchet distance compares (above max_lookahead_m / {MAX_CURVE_POINTS})",
        Number(0.0, 50.0, "m", low_open=True),
    )
    tolerance_x_m: float = option(
        0.5,
        "delta_x of Eq. 3: how far along x the clothoid's end may miss the target for a lookahead to be admissible",
        Number(0.0, 100.0, "m", low_open=True),
    )
    tolerance_y_m: float = option(
        0.5,
        "delta_y of Eq. 3: how far along y the clothoid's end may miss the target for a lookahead to be admissible",
        Number(0.0, 100.0, "m", low_open=True),
    )
    max_curvature_rate_1pm2: float = option(
        0.05,
        "the saturation of the clothoid's curvature rate kappa' (per metre of arc)",
        Number(0.0, 10.0, "1/m^2", low_open=True),
    )
    initial_curvature: str = option(
        "yaw-rate",
        'kappa(0) of Eq. 3: "yaw-rate" (measured: yaw rate / speed), "command" or "steering"; the lookahead floor is '
        "the measured kappa(0)'s whichever is chosen (\"command\"'s loop has 25-36 deg of phase margin on the truck "
        'and the car at 30 km/h; "steering" is not modelled)',
        Choice(INITIAL_CURVATURE),
    )
    heading: str = option(
        "course",
        'the clothoid\'s start direction: "course" (yaw plus sideslip, the direction the vehicle moves in) or "yaw"',
        Choice(HEADINGS),
    )
    prediction_time_s: float = option(
        0.2,
        "the start pose is predicted this far ahead (Figure 2's step 5; 0: off)",
        Number(0.0, 2.0, "s"),
    )
    known_delay_s: float = option(
        0.0,
        "the loop's dead time the controller knows, measurement latency plus actuation dead time: the pose is "
        "predicted over it, the reference pose and feed-forward point move ahead with it, and the lookahead floor's "
        "loop analysis has it",
        Number(0.0, 1.0, "s", note="0: none"),
    )
    yaw_rate_age_s: float = option(
        0.0,
        "how much older the measured yaw rate is than the measured pose (the yaw rate's latency less the pose's): "
        "with delay_compensation 'model', kappa(0) is predicted over it as well as over known_delay_s "
        "(`delay_predictor.predicted_start`)",
        Number(-0.5, 0.5, "s", note="0: as old as the pose; negative: fresher"),
    )
    delay_compensation: str = option(
        "model",
        'how the pose is predicted over known_delay_s: "model" (the identified lags driven by the commands already '
        'sent, a Smith predictor, `delay_predictor.py`; needs the tuning and initial_curvature "yaw-rate") or "arc" '
        "(on kappa(0); the delay stays in the loop, and the floor is the delayed loop's)",
        Choice(requirements.DELAY_COMPENSATIONS),
    )
    path_feedforward: bool = option(
        True,
        "the two-degree-of-freedom form: the path's own clothoid taken out of the feedback and its curvature rate fed "
        "forward (`path_feedforward.py`; false: Eq. 3 alone)",
        Flag(),
    )
    feedforward_window_m: float = option(
        2.0,
        "the window of the path curvature's derivatives the feed-forward inverts the lag with (without "
        "feedforward_inversion: the window its curvature rate is averaged over; 6 m keeps the truck's steering "
        "calmer there)",
        Number(0.1, 100.0, "m"),
    )
    feedforward_time_s: float | None = option(
        None,
        "where along the path the feed-forward reads the curvature rate: speed x this time ahead of the foot point",
        Number(0.0, 5.0, "s", none_means="from the vehicle's lags"),
    )
    reference_lead_s: float | None = option(
        None,
        "how far ahead of the foot point the feedback's reference pose starts (at most the prediction time)",
        Number(0.0, 5.0, "s", none_means="from the vehicle's lags"),
    )
    feedforward_inversion: bool = option(
        True,
        "the feed-forward inverts the identified steering-to-path-curvature lag of Eq. 5 in full (the path's "
        "curvature its dead time plus known_delay_s ahead, with its first and second time derivatives weighted "
        "2 zeta / wn and 1 / wn^2, over K; `path_feedforward.lag_inverse_curvature`) and is added to the steering "
        "after the lead filter instead of integrated through it (feedforward_time_s is then unused); false: the "
        "path's curvature rate at the lags' low-frequency delay ahead, integrated with the feedback; the form of "
        "path_feedforward's feed-forward (no effect without it); without a tuning, the path's curvature at the foot "
        "point",
        Flag(),
    )
    lag_model_reference: bool = option(
        True,
        "with feedforward_inversion: the feedback's reference pose starts at the path's pose (ahead by the known "
        "delay only) on the curvature a vehicle following the path exactly would measure, the measured (yaw-rate) "
        "lag driven by the inverted path lag (`step_kernel.reference_curvature`), instead of the path's pose and "
        "curvature reference_lead_s ahead (reference_lead_s is then unused; false: that); no effect without "
        "feedforward_inversion or a tuning, or with the preview responses (feedforward_model)",
        Flag(),
    )
    feedforward_model: str = option(
        "auto",
        "with feedforward_inversion: the model of the vehicle along the path that gives the feed-forward's steering "
        "and the reference pose's curvature: 'lag' (the lags of Eq. 5, as above), 'preview' (the preview responses "
        "identified from the same logs, `preview_model.py`; the tuning must have them) or 'auto' (the preview "
        "responses where the lag does not explain the vehicle's logs, `VehicleTuning.lag_explains_logs`, else the "
        "lags); either way the loop and its margins are the same",
        Choice(FEEDFORWARD_MODELS),
    )
    handling_gain: bool = option(
        True,
        "with the preview responses (feedforward_model): the feed-forward's steering scaled by the vehicle's handling "
        "gain, the steady-state steering per curvature at the lateral acceleration where each tap reads the path over "
        "the one the taps were identified at (`preview_model.py`; a tuning made without steady turns has gains of "
        "one); false: the taps alone, linear at any lateral acceleration; the loop is the same either way",
        Flag(),
    )
    sideslip_release: bool = option(
        True,
        "with delay_compensation 'model' and heading 'course': the measured sideslip's deviation from the steady "
        "turn's and the lags' is released over known_delay_s at the rate the tuning identified, turning the predicted "
        "course (`sideslip_release.py`; no effect without an identified release); false: held; the loop about a "
        "steady state is the same either way",
        Flag(),
    )
    tuning: VehicleTuning | None = option(  # noqa: RUF009  (option is a dataclasses.field)
        None,
        "the steered vehicle's own tuning: lead filter, curvature limits, identified lags "
        "(`tuning.own_tuning.tuned_controller` fills it in; in a file, tuning_dir names a tuning directory)",
        Instance(VehicleTuning, "untuned: no lead filter and no lookahead floor unless given"),
    )
    lead_filter: FilterSchedule | None = option(  # noqa: RUF009  (option is a dataclasses.field)
        None,
        "the lead filter's schedule (in a file, filter_file names a `tuning design-lead` or `tuning schedule` file)",
        Instance(FilterSchedule, "the tuning's"),
    )
    use_lead_filter: bool = option(True, "false switches the lead filter off", Flag())
    curvature_limits: CurvatureLimits | None = option(  # noqa: RUF009  (option is a dataclasses.field)
        None,
        "the speed-dependent curvature and curvature-rate limits (in a file, limits_file names a CSV of the `tuning "
        "rollover-limits` format)",
        Instance(CurvatureLimits, "the tuning's, else limits from the geometry (`CurvatureLimits.default_for`)"),
    )

    def with_tuning(self, tuning: VehicleTuning) -> ClothoidConfig:
        """These options with the steered vehicle's own tuning (`tuning.own_tuning.with_vehicle_tuning`).

        Parameters
        ----------
        tuning : VehicleTuning
            The vehicle's identified lags, lead-filter schedule, curvature limits and lookahead floors.

        Returns
        -------
        ClothoidConfig
            A copy of these options with ``tuning`` set; every other option as it is.
        """
        return replace(self, tuning=tuning)

    @property
    def predicts_with_model(self) -> bool:
        """Whether the pose and kappa(0) are predicted over a known delay and the yaw rate's age with the identified
        lags (`delay_predictor.py`)."""
        return requirements.predicts_with_model(self.delay_compensation, self.known_delay_s, self.yaw_rate_age_s)

    def __post_init__(self) -> None:
        # Every field on its own first (its rule, `config_checks.check_options`), then what relates them.
        check_options(self)
        if self.predicts_with_model and self.initial_curvature != "yaw-rate":
            raise WorkbenchInputError(
                f"delay_compensation 'model' predicts the measured kappa(0), initial_curvature 'yaw-rate'; got "
                f"initial_curvature {self.initial_curvature!r} with known_delay_s = {value_text(self.known_delay_s)} "
                f"s, yaw_rate_age_s = {value_text(self.yaw_rate_age_s)} s: "
                "set delay_compensation = 'arc' (the pose predicted on kappa(0)) or initial_curvature = 'yaw-rate'"
            )
        if self.max_lookahead_m < self.min_lookahead_m:
            raise WorkbenchInputError(
                f"max_lookahead_m must be >= min_lookahead_m = {value_text(self.min_lookahead_m)} m; "
                f"got {value_text(self.max_lookahead_m)}"
            )
        steps = (self.max_lookahead_m - self.min_lookahead_m) / self.lookahead_step_m
        if steps > 1000:
            raise WorkbenchInputError(
                f"lookahead range / lookahead_step_m gives {steps:.0f} candidates; at most 1000 are allowed"
            )
        # the curves compared hold int(lookahead / spacing) + 1 points, at most MAX_CURVE_POINTS
        if self.max_lookahead_m / self.frechet_point_spacing_m >= MAX_CURVE_POINTS:
            raise WorkbenchInputError(
                f"frechet_point_spacing_m must be > max_lookahead_m / {MAX_CURVE_POINTS} = "
                f"{self.max_lookahead_m / MAX_CURVE_POINTS:g} m; got {value_text(self.frechet_point_spacing_m)}"
            )


class ClothoidController(Controller[ClothoidConfig]):
    """The clothoid controller (Figure 2). Build once for a vehicle and a ClothoidConfig; `reset` for each path.

    Its tuning (the lead filter, the curvature limits and the identified lags the lookahead floor and the
    feed-forward timing are computed from) is the config's (`ClothoidConfig.tuning`); a `vehicle` given without one
    is refused, so that a controller meant for a vehicle never runs untuned by mistake
    (`tuning.own_tuning.tuned_controller` builds it with the vehicle's own).

    Parameters
    ----------
    geometry : VehicleGeometry
        The steered vehicle's wheelbase, steering ratio, lock and steering-rate limit.
    config : ClothoidConfig or None
        The controller's options (None: the defaults, untuned).
    vehicle : VehicleModel or None
        The vehicle the controller is meant for; given, the config must carry a tuning (None: no check).

    Raises
    ------
    WorkbenchInputError
        A vehicle given with a config without tuning, delay_compensation "model" with a known delay and no
        tuning (the prediction needs the identified lags), or feedforward_model "preview" with a tuning without
        preview responses.
    """

    name: ClassVar[str] = "clothoid"
    config_type: ClassVar[type] = ClothoidConfig
    #: Not the margin floors (min_phase_margin_deg, min_gain_margin_db): they are the design's safety, not knobs.
    search_space: ClassVar[tuple[Tunable, ...]] = (
        Tunable("frechet_threshold_m", "log", 0.005, 0.5, reason="smaller admits only clothoids that hug the path: "
                "shorter lookaheads, tighter tracking, busier steering"),
        Tunable("prediction_time_s", "linear", 0.0, 0.6, reason="predicting the start pose further ahead anticipates "
                "the steering's lag; too far steers for a pose not yet reached"),
        Tunable("min_preview_time_s", "linear", 0.0, 1.0, reason="a lookahead of at least this time x speed is calmer "
                "at speed and cuts tight bends more"),
        Tunable("lead_filter_zero_scale", "log", 0.8, 1.25, reason="moves the lead filter's zeros: > 1 assumes a "
                "faster steering lag (less lead), < 1 a slower one"),
        Tunable("lead_filter_pole_scale", "log", 0.9, 2.0, reason="moves the lead filter's poles: > 1 more phase lead "
                "and high-frequency gain, which amplifies noise"),
        Tunable("min_lookahead_m", "linear", 2.0, 10.0, reason="the shortest lookahead the search may choose: shorter "
                "tracks tighter where the floor allows, longer is calmer"),
        Tunable("max_lookahead_m", "linear", 12.0, 30.0, reason="the longest lookahead the search may choose: longer "
                "is smoother on straights and cuts bends more"),
    )  # fmt: skip

    @classmethod
    def informed_config(cls, config: ClothoidConfig, delays: KnownDelays) -> ClothoidConfig:
        """`config` with known_delay_s = the loop's dead time, the pose latency plus the actuation dead time
        (`KnownDelays.loop_delay_s`), which the pose prediction and the lookahead floor's loop analysis then
        have, and yaw_rate_age_s = the yaw rate's latency less the pose's, which aligns kappa(0) with the pose;
        every other option as it is.

        Parameters
        ----------
        config : ClothoidConfig
            The controller's options.
        delays : KnownDelays
            The conditions' nominal delays; the pose noise is not used (the lead filter and the lookahead floor are
            the noise's answer).

        Returns
        -------
        ClothoidConfig
            The informed options (refused, naming the option, when the delay is beyond known_delay_s's range or
            the config's delay compensation cannot take it)."""
        return replace(
            config,
            known_delay_s=delays.loop_delay_s,
            yaw_rate_age_s=delays.yaw_rate_latency_s - delays.pose_latency_s,
        )

    def __init__(
        self, geometry: VehicleGeometry, config: ClothoidConfig | None = None, vehicle: VehicleModel | None = None
    ) -> None:
        super().__init__(geometry, config)
        cfg = self.config
        if vehicle is not None and cfg.tuning is None:
            raise WorkbenchInputError(
                f"the clothoid controller for vehicle {getattr(vehicle, 'name', vehicle)!r} needs that vehicle's "
                "tuning: build it with tuning.own_tuning.tuned_controller('clothoid', vehicle[, config]), or give "
                "ClothoidConfig(tuning=tuning.own_tuning.tuning_for(vehicle)); for an untuned controller pass no "
                "vehicle"
            )
        self.tuning: VehicleTuning | None = cfg.tuning
        if cfg.predicts_with_model and self.tuning is None:
            raise WorkbenchInputError(
                f"delay_compensation 'model' (known_delay_s = {value_text(cfg.known_delay_s)} s, yaw_rate_age_s = "
                f"{value_text(cfg.yaw_rate_age_s)} s) predicts with the vehicle's identified lags, and this controller "
                "has no tuning: give ClothoidConfig(tuning=...) "
                "(tuning.own_tuning.tuning_for) or set delay_compensation = 'arc'"
            )
        if cfg.feedforward_model == "preview" and (self.tuning is None or not self.tuning.previews):
            raise WorkbenchInputError(
                "feedforward_model 'preview' needs a tuning with the vehicle's preview responses (made by `tuning "
                "schedule`); this controller's tuning has none: use 'auto' or 'lag', or make the tuning again"
            )
        if cfg.curvature_limits is not None:
            self.limits = cfg.curvature_limits
        elif self.tuning is not None:
            self.limits = self.tuning.limits
        else:
            self.limits = CurvatureLimits.default_for(geometry)
        self.filter_schedule: FilterSchedule | None = None
        if cfg.use_lead_filter:
            if cfg.lead_filter is not None:
                self.filter_schedule = cfg.lead_filter
            elif self.tuning is not None:
                self.filter_schedule = self.tuning.filter_schedule
        top = self._floor_search_top_m
        self._scores = np.empty(candidate_count(cfg.min_lookahead_m, top, cfg.lookahead_step_m))
        self._results = np.empty((self._scores.size, 8))  # each candidate's evaluation (lookahead.adaptive_search)
        self._floors: dict[int, float] = {}  # per speed node, for the sample time _floors_dt
        self._floors_dt: float | None = None
        self._state = sk.initial_state()  # the compiled step's state (step_kernel.STATE)
        self._measured = np.zeros(1, sk.MEASUREMENT)  # the measurement as the compiled step reads it
        self._history = np.empty(1)  # the delay predictor's commands sent, sized by `_reset`
        self._params = self._parameters()
        self._tables()

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        if float(sample_time_s) != self._floors_dt:  # the floors depend on the sample time, not on the path
            self._floors, self._floors_dt = {}, float(sample_time_s)
        self._dt = float(sample_time_s)
        self._state = sk.initial_state()  # both path trackers at the path's start
        self._params["dt"] = self._dt
        self._diag = self._declare_diagnostics(DIAGNOSTIC_KEYS)
        if self.config.predicts_with_model:
            longest = self.config.known_delay_s + max(self.config.yaw_rate_age_s, 0.0) + float(
                max(self._lags[:, 2].max(), self._measured_lags[:, 2].max(initial=0.0))
            )
            self._history = np.empty(history_length(self._dt, longest))
        compiled = path.compiled()
        self._step_arguments = sk.StepArguments(
            self._measured, self._params, self._state, compiled.table, compiled.record, self._limits,
            self._limit_speeds, self._lags, self._measured_lags, self._lag_axis, self._schedule,
            self._schedule_speeds, self._scores, self._results, self._diag, self._history,
        )  # fmt: skip
        # The planned speeds' floors at reset, not in a step (0.1 s a node, with the delay model 1.5 s; cached).
        for node in self._planned_nodes(path):
            self._node_floor_m(node)

    def _tables(self) -> None:
        """The tables the compiled step reads (step_kernel.py): the limits, the identified lags and the lead
        filter's schedule (no rows: untuned, no lead filter), each against speed, the lags' rows followed by the
        preview responses' steering and measured taps when the feed-forward uses them, the steering taps by the
        handling gain with handling_gain (`step_kernel.LAG_COLUMNS`), and the sideslip's release
        (`VehicleTuning.release_table`; no rows: none identified);
        built once, with the controller (they depend on its config alone, not on the path or the period)."""
        self._limit_speeds, self._limits = self.limits.table
        if self.tuning is not None:
            self._lag_speeds, self._lags, self._measured_lags = self.tuning.lag_tables
            if self.uses_preview:
                self._lag_speeds, self._lags, self._measured_lags = self.tuning.preview_lag_tables
                if not self.config.handling_gain:  # the steering taps alone (step_kernel: columns past the measured)
                    self._lags = self._lags[:, : self._measured_lags.shape[1]]
                first, spacing, _, _ = self.tuning.preview_tables
                self._params["preview_first_tap"], self._params["preview_spacing"] = first, spacing
            releases = self.tuning.release_table
        else:
            self._lag_speeds, self._lags, self._measured_lags = np.zeros(0), np.zeros((0, 4)), np.zeros((0, 4))
            releases = np.zeros((0, 0))
        # the speeds, then the release table transposed (step_kernel.clothoid_step's lag_axis; only the speeds
        # without releases)
        self._lag_axis = np.vstack([self._lag_speeds, releases.T]) if releases.size else self._lag_speeds[None, :]
        if self.filter_schedule is not None:
            self._schedule_speeds, self._schedule = self.filter_schedule.table
        else:
            self._schedule_speeds, self._schedule = np.zeros(0), np.zeros((0, 3))

    def _parameters(self) -> np.ndarray:
        """The compiled step's parameters (step_kernel.PARAMS): geometry and options (the period, NaN here, is set
        by `_reset`)."""
        cfg, g = self.config, self.geometry
        return sk.parameters(
            wheelbase=g.wheelbase_m,
            steering_ratio=g.steering_ratio,
            max_steer=g.max_steer_wheel_angle_rad,
            dt=math.nan,
            horizon=self._prediction_horizon_s,
            known_delay=cfg.known_delay_s,
            yaw_rate_age=cfg.yaw_rate_age_s,
            lookahead_mode=LOOKAHEAD_MODES.index(cfg.lookahead_mode),
            initial_curvature=INITIAL_CURVATURE.index(cfg.initial_curvature),
            course=cfg.heading == "course",
            excess=cfg.threshold_mode == "excess",
            min_lookahead=cfg.min_lookahead_m,
            max_lookahead=cfg.max_lookahead_m,
            lookahead_step=cfg.lookahead_step_m,
            min_preview=cfg.min_preview_time_s,
            fixed_lookahead=cfg.fixed_lookahead_m,
            lookahead_gain=cfg.lookahead_gain_s,
            max_turn=math.radians(cfg.max_target_turn_deg),
            frechet_threshold=cfg.frechet_threshold_m,
            point_spacing=cfg.frechet_point_spacing_m,
            tolerance_x=cfg.tolerance_x_m,
            tolerance_y=cfg.tolerance_y_m,
            kdot_max=cfg.max_curvature_rate_1pm2,
            feedforward=cfg.path_feedforward,
            feedforward_window=cfg.feedforward_window_m,
            feedforward_time=cfg.feedforward_time_s,
            reference_lead=cfg.reference_lead_s,
            hysteresis=cfg.lookahead_hysteresis_m,
            max_growth=cfg.max_lookahead_growth_m_per_m,
            max_shrink=cfg.max_lookahead_shrink_m_per_m,
            min_speed=MIN_SPEED_MPS,
            floor_step_kmh=FLOOR_SPEED_STEP_KMH,
            floor_min_kmh=FLOOR_MIN_SPEED_KMH,
            warm_search=cfg.search_start == "last",
            delay_model=cfg.predicts_with_model,
            feedforward_inversion=cfg.feedforward_inversion,
            lag_model_reference=cfg.lag_model_reference,
            sideslip_release=cfg.sideslip_release,
            preview_first_tap=0.0,
            preview_spacing=1.0,
        )

    @property
    def uses_preview(self) -> bool:
        """Whether the feed-forward and the reference curvature come from the tuning's preview responses
        (`ClothoidConfig.feedforward_model`) rather than from its lags."""
        cfg, tuning = self.config, self.tuning
        if tuning is None or not (cfg.path_feedforward and cfg.feedforward_inversion):
            return False
        if cfg.feedforward_model == "preview":
            return True
        return cfg.feedforward_model == "auto" and bool(tuning.previews) and not tuning.lag_explains_logs

    def plant_lags(self, speed_kmh: float) -> PlantLags | None:
        """The vehicle's identified lags at this speed (None without a tuning).

        Parameters
        ----------
        speed_kmh : float, km/h
            The speed, finite; the lags are interpolated linearly between the identified speeds, clamped beyond.

        Returns
        -------
        PlantLags or None
            The path lag and the measured (yaw-rate) lag, or None when the controller has no tuning.

        Raises
        ------
        WorkbenchInputError
            speed_kmh is not a finite number.
        """
        from controllers.clothoid.loop_analysis import PlantLags

        if self.tuning is None:
            return None
        return PlantLags(self.tuning.lag_at(speed_kmh), self.tuning.measured_lag_at(speed_kmh))

    def loop_settings(self, speed_kmh: float) -> LoopSettings:
        """What the controller does at this speed, for `loop_analysis`.

        Available after `reset`: the settings hold the run's sample time.

        Parameters
        ----------
        speed_kmh : float, km/h
            The speed whose lead filter (from the filter schedule, at the whole km/h the step uses) the settings
            hold.

        Returns
        -------
        LoopSettings
            The sample time, the prediction time, the lead filter at this speed (None when off), the known delay,
            the delay compensation and the sideslip's release there where the controller may release it (while
            the speed plan brakes or drives: sideslip_release on, a known delay with the model's compensation, the
            course as heading and a release identified at this speed; else None).
        """
        from controllers.clothoid.loop_analysis import LoopSettings

        cfg = self.config
        release = None
        releasing = cfg.sideslip_release and cfg.heading == "course" and cfg.known_delay_s > 0.0
        if releasing and cfg.predicts_with_model and self.tuning is not None:
            release = self.tuning.release_at(speed_kmh)
        return LoopSettings(
            self._dt, cfg.prediction_time_s, lead=self._lead_at(speed_kmh), known_delay_s=cfg.known_delay_s,
            delay_compensation=cfg.delay_compensation, release=release,
        )  # fmt: skip

    def lookahead_floor_m(self, speed_mps: float) -> float:
        """The shortest lookahead (m) that keeps the configured margins at this speed: computed at the speed nodes
        FLOOR_SPEED_STEP_KMH apart about it (once per node and run), linear between them, as the compiled step reads
        it; min_lookahead_m without a tuning or with the margins set to 0. The analysis is cached on all of
        `loop_settings`, the known delay included.

        Available after `reset`: the floor depends on the run's sample time.

        Parameters
        ----------
        speed_mps : float, m/s
            The speed, >= 0 (below FLOOR_MIN_SPEED_KMH, that speed's floor).

        Returns
        -------
        float, m
            The floor; above max_lookahead_m where the margins need a longer lookahead than the range allows
            (`run_warnings` tells).
        """
        node, weight = sk.floor_node(float(speed_mps), FLOOR_SPEED_STEP_KMH, FLOOR_MIN_SPEED_KMH)
        floor = self._node_floor_m(node)
        return floor + weight * (self._node_floor_m(node + 1) - floor) if weight > 0.0 else floor

    def _node_floor_m(self, node: int) -> float:
        """The floor at speed node `node` (node x FLOOR_SPEED_STEP_KMH km/h)."""
        cfg = self.config
        floor = self._floors.get(node)
        if floor is None:
            floor = self._recorded_floor_m(node * FLOOR_SPEED_STEP_KMH)
            if floor is None:
                inputs = self._floor_inputs(node)
                if inputs is None:
                    floor = cfg.min_lookahead_m
                else:
                    from controllers.clothoid.loop_analysis import lookahead_floor  # python-control: when used

                    lags, settings, v, curvatures, delayed = inputs
                    floor = lookahead_floor(
                        lags, settings, v, cfg.min_lookahead_m, self._floor_search_top_m, cfg.lookahead_step_m,
                        curvatures, cfg.min_phase_margin_deg, cfg.min_gain_margin_db, delayed,
                    )  # fmt: skip
            self._floors[node] = floor
        return floor

    def _recorded_floor_m(self, speed_kmh: float) -> float | None:
        """The floor the tuning's margins design computed at this speed (km/h), when it is the one the analysis
        of `_floor_inputs` computes: the tuning's lags there (`plant_lags`), the same lead filter, loop settings,
        path curvatures, search grid and margins (`VehicleTuning.recorded_floor_m`); None otherwise (the floor is
        computed), and None without a floor (no tuning, the margins set to 0). Built from the config alone, without
        the loop analysis (python-control), which a reused floor does not need."""
        cfg, g = self.config, self.geometry
        if self.tuning is None or (cfg.min_phase_margin_deg <= 0.0 and cfg.min_gain_margin_db <= 0.0):
            return None
        v = speed_kmh / 3.6
        kappa_max, _ = self.limits.at_speed(v)
        inputs = FloorInputs(
            speed_kmh, self._lead_at(speed_kmh), self._dt, cfg.prediction_time_s, cfg.known_delay_s,
            (0.0, self._floor_arc_1pm(v)), (cfg.min_lookahead_m, self._floor_search_top_m, cfg.lookahead_step_m),
            cfg.min_phase_margin_deg, cfg.min_gain_margin_db,
        )  # fmt: skip
        lock_1pm = math.tan(g.max_road_wheel_angle_rad) / g.wheelbase_m
        return self.tuning.recorded_floor_m(inputs, lock_1pm, kappa_max)

    def _floor_arc_1pm(self, speed_mps: float) -> float:
        """The arc (1/m) the floor is checked about besides the straight: FLOOR_ARC_LATERAL_ACCEL_G at this speed,
        capped by the curvature limit there."""
        kappa_max, _ = self.limits.at_speed(speed_mps)
        return min(kappa_max, FLOOR_ARC_LATERAL_ACCEL_G * G_MPS2 / speed_mps**2)

    def _lead_at(self, speed_kmh: float) -> LeadFilterParams | None:
        """The lead filter's parameters the step uses at this speed (km/h): the schedule's at the nearest whole km/h
        (`step_kernel`: one filter per km/h, rounded half to even); None without a lead filter."""
        return self.filter_schedule.at_speed(float(round(speed_kmh))) if self.filter_schedule is not None else None

    @property
    def _floor_search_top_m(self) -> float:
        """The longest lookahead (m) the floor search considers: max_lookahead_m, or MAX_FLOOR_LOOKAHEAD_M when
        longer (a floor above the range raises its top with it)."""
        return max(self.config.max_lookahead_m, MAX_FLOOR_LOOKAHEAD_M)

    def _floor_inputs(
        self, node: int
    ) -> tuple[PlantLags, LoopSettings, float, tuple[float, float], DelayRobustness] | None:
        """What the floor of speed node `node` is analysed with: the lags, the loop settings, the speed (m/s), the
        path curvatures (the straight and the FLOOR_ARC_LATERAL_ACCEL_G arc, capped by the curvature limit) and the
        margins kept with the delay (`loop_analysis.DelayRobustness`); None without a tuning or with the margins
        set to 0 (no floor)."""
        cfg = self.config
        speed_kmh = node * FLOOR_SPEED_STEP_KMH
        lags = self.plant_lags(speed_kmh)
        if lags is None or (cfg.min_phase_margin_deg <= 0.0 and cfg.min_gain_margin_db <= 0.0):
            return None
        from controllers.clothoid.loop_analysis import DelayRobustness  # python-control: imported when used

        v = speed_kmh / 3.6
        delayed = DelayRobustness(
            cfg.min_delayed_phase_margin_deg, cfg.min_delayed_gain_margin_db, cfg.known_delay_uncertainty_s
        )
        return lags, self.loop_settings(speed_kmh), v, (0.0, self._floor_arc_1pm(v)), delayed

    def _node_keeps_margins(self, node: int) -> bool:
        """Whether the lookahead floor of speed node `node` keeps the configured margins (False: no lookahead up to
        the floor search's top does, and the floor is that top)."""
        floor, inputs = self._node_floor_m(node), self._floor_inputs(node)
        if inputs is None or floor < self._floor_search_top_m - 1e-9:
            return True  # the search returns a floor below its top only where the margins hold
        from controllers.clothoid.loop_analysis import keeps_margins

        lags, settings, v, curvatures, delayed = inputs
        cfg = self.config
        return keeps_margins(
            lags, settings, v, floor, curvatures, cfg.min_phase_margin_deg, cfg.min_gain_margin_db, delayed
        )

    @staticmethod
    def _planned_nodes(path: ReferencePath) -> list[int]:
        """The floor's speed nodes about the path's planned speeds (none without them): `lookahead_floor_m`'s."""
        if path.speed_mps is None:
            return []
        nodes: set[int] = set()
        for speed in np.unique(path.speed_mps):
            node, weight = sk.floor_node(float(speed), FLOOR_SPEED_STEP_KMH, FLOOR_MIN_SPEED_KMH)
            nodes.update((node, node + 1) if weight > 0.0 else (node,))
        return sorted(nodes)

    def run_warnings(self, path: ReferencePath, sample_time_s: float) -> list[str]:
        """What to tell a person before a run on `path` (at its planned speeds) with steps every sample_time_s: the
        speeds whose lookahead floor lies above max_lookahead_m. There the lookahead is held at the floor, a
        constant lookahead outside the configured range, and the Fréchet search does not act; where no lookahead
        up to the floor search's top keeps the margins, it is held at that top without them. The run is not
        refused: the floor is what keeps the loop's margins with this tuning (a study of weak lead filters must
        be able to run it), but it is not the controller the range describes, and the message says what to
        change. None in the "fixed" lookahead mode (no floor applies) or without planned speeds.

        Parameters
        ----------
        path : ReferencePath
            The path to run, with its planned speeds (none: no warning).
        sample_time_s : float, s
            The controller's sample time, > 0; the controller is `reset` for the path with it.

        Returns
        -------
        list of str
            One message naming the speeds whose floor lies above max_lookahead_m and what to change; empty
            when there is none.
        """
        cfg = self.config
        if cfg.lookahead_mode == "fixed" or path.speed_mps is None:
            return []
        self.reset(path, sample_time_s)  # the planned nodes' floors, as the run computes them (and keeps)
        above = [(node, self._node_floor_m(node)) for node in self._planned_nodes(path)]
        above = [(node, floor) for node, floor in above if floor > cfg.max_lookahead_m + 1e-9]
        if not above:
            return []
        top = self._floor_search_top_m
        keeps = {node: self._node_keeps_margins(node) for node, _ in above}
        kept = [floor for node, floor in above if keeps[node]]
        spans: list[list] = []  # [first node, last node, floors]: neighbouring nodes that both keep or both do not
        for node, floor in above:
            if spans and spans[-1][1] == node - 1 and keeps[spans[-1][0]] == keeps[node]:
                spans[-1][1] = node
                spans[-1][2].append(floor)
            else:
                spans.append([node, node, [floor]])

        def what(first: int, floors: list[float]) -> str:
            if not keeps[first]:
                return f"floor none: no lookahead up to {top:g} m keeps them"
            low, high = min(floors), max(floors)
            return f"floor {low:g} m" if low == high else f"floor {low:g}-{high:g} m"

        step = FLOOR_SPEED_STEP_KMH
        places = ", ".join(
            f"{first * step:g}{f'-{last * step:g}' if last > first else ''} km/h ({what(first, floors)})"
            for first, last, floors in spans
        )
        remedies = []
        if kept:
            remedies.append(f"raise max_lookahead_m to at least {max(kept):g} m (--set max_lookahead_m=...)")
        remedies.append(
            "use a lead filter with more phase margin (`tuning margins` shows the floors per speed; `tuning schedule "
            "--design margins` designs the shortest)"
        )
        return [
            f"the clothoid controller's lookahead floor (the shortest lookahead keeping {cfg.min_phase_margin_deg:g} "
            f"deg / {cfg.min_gain_margin_db:g} dB margins with its lead filter and lags) lies above max_lookahead_m "
            f"= {cfg.max_lookahead_m:g} m at {places}: there the lookahead is held at the floor"
            f"{'' if all(keeps.values()) else f' ({top:g} m where none)'}, a constant outside the configured "
            f"{cfg.min_lookahead_m:g}-{cfg.max_lookahead_m:g} m, and the Fréchet search does not act; "
            f"{' or '.join(remedies)}"
        ]

    def feedforward_timing(self, speed_mps: float) -> FeedforwardTiming:
        """The feed-forward's timing at this speed: the options, else from the identified lags (path_feedforward.py):
        feed-forward time = the low-frequency delay of lead filter and path lag; reference lead = the path lag's less
        the measured (yaw-rate) lag's, within [0, prediction time]; K of the path lag. A known delay adds to the
        feed-forward time (the steering commanded now takes effect that much later, from a pose that much older)
        and to the prediction time.

        Available after `reset`: the timing depends on the run's sample time.

        Parameters
        ----------
        speed_mps : float, m/s
            The speed, >= 0.

        Returns
        -------
        FeedforwardTiming
            The feed-forward time (s), the reference lead (s) and the steady-state gain K.
        """
        ff, ref, gain = sk.feedforward_timing(
            speed_mps, self._params, self._lags, self._measured_lags, self._lag_speeds, self._schedule,
            self._schedule_speeds, np.empty(4),
        )  # fmt: skip
        return FeedforwardTiming(ff, ref, gain)

    @property
    def _prediction_horizon_s(self) -> float:
        """How far ahead the pose is predicted (s): prediction_time_s plus the known delay."""
        return self.config.prediction_time_s + self.config.known_delay_s

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        m = measurement
        self._measured[0] = (m.t_s, m.x_m, m.y_m, m.vx_mps, m.vy_mps, m.yaw_rad, m.yaw_rate_rad_s, m.steer_wheel_rad)
        while True:  # once, unless the step asks for a floor or a lead filter Python makes (step_kernel.py)
            command, status = sk.clothoid_step(*self._step_arguments)
            if status == sk.STEP_DONE:
                return command
            need = int(self._state["need"][0])
            if status == sk.NEED_FLOOR:
                self._state["floors"][0, need] = self._node_floor_m(need)
            else:
                # the kernel asks for a lead filter only when there is a schedule to make it from
                params = self.filter_schedule.at_speed(float(need))  # type: ignore[union-attr]
                self._state["filters"][0, need] = DiscreteLeadFilter(params, self._dt).coefficients


__all__ = ["ClothoidConfig", "ClothoidController"]
