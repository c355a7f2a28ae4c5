"""How a closed-loop run is simulated: speeds, rates, laps and when a run stops early (`SimulationConfig`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

from workbench.base.errors import WorkbenchInputError, require_in_range, require_positive, value_text
from workbench.simulation.conditions import CONDITIONS, Conditions
from workbench.simulation.known_delays import KnownDelays

#: The longest time-out a run may be given (s; about 32 years): beyond it a number of steps no longer fits a
#: machine integer, and `run_size` refuses far shorter runs anyway.
MAX_TIME_S = 1e9


@dataclass(frozen=True)
class SimulationConfig:
    """How a run is simulated.

    speed_kmh: the speed asked for (km/h), the maximum of the planned profile; max_lateral_accel_g: the profile's
    lateral acceleration bound (the paper: 0.3 g); max_accel_mps2, max_decel_mps2: its longitudinal bounds;
    controller_rate_hz, plant_rate_hz: step rates (the plant rate must be a whole multiple); laps: laps of a
    closed path; max_time_s: time-out (None: three times the planned lap time plus 30 s); max_abs_cte_m: a run
    whose |CTE| exceeds this has left the path and stops; max_past_end_m: so has a run whose reference point goes
    this far beyond either end of an open path (along the end's tangent); speed_feedforward: the speed controller
    feeds the planned speed's rate of change forward (speed x dv_ref/ds) besides its PI action (False: PI only);
    conditions: what lies between the plant and the controller (sensing, actuation, road; `conditions.py`; the
    default, `ideal`, changes nothing); seed: the seed of the conditions' noise (the same seed, the same run);
    inform_delays: whether the run's controller is told the conditions' nominal delays and pose noise
    (`known_delays.KnownDelays`, `Controller.informed_config`). Whoever builds the controller applies it (`workbench
    run`, compare, fig17, the study runner; `known_delays` says what to tell); the simulator steps the controller it
    is given, and metrics.json records the choice with the conditions. perfect_prediction: the controller is handed
    the plant's true state one actuation dead time ahead (the steering commands already sent applied, the
    acceleration command held), before the sensing conditions act on it: a perfect compensation of the dead time,
    the bound any delay predictor is measured against (an analysis; the dead time is then not told).
    """

    speed_kmh: float = 30.0
    max_lateral_accel_g: float = 0.3
    max_accel_mps2: float = 1.0
    max_decel_mps2: float = 2.0
    controller_rate_hz: float = 50.0
    plant_rate_hz: float = 1000.0
    laps: int = 1
    max_time_s: float | None = None
    max_abs_cte_m: float = 30.0
    max_past_end_m: float = 5.0
    speed_feedforward: bool = True
    conditions: Conditions = CONDITIONS["ideal"]
    seed: int = 0
    inform_delays: bool = False
    perfect_prediction: bool = False

    def __post_init__(self) -> None:
        require_in_range("speed_kmh", self.speed_kmh, 1e-3, 400.0, "km/h (must be > 0)")
        require_in_range("max_lateral_accel_g", self.max_lateral_accel_g, 0.01, 2.0, "g")
        require_positive("max_accel_mps2", self.max_accel_mps2)
        require_positive("max_decel_mps2", self.max_decel_mps2)
        require_in_range("controller_rate_hz", self.controller_rate_hz, 1.0, 10_000.0, "Hz")
        require_in_range("plant_rate_hz", self.plant_rate_hz, 1.0, 100_000.0, "Hz")
        ratio = self.plant_rate_hz / self.controller_rate_hz
        if ratio < 1 or abs(ratio - round(ratio)) > 1e-9:
            raise WorkbenchInputError(
                f"plant_rate_hz ({self.plant_rate_hz}) must be a whole multiple of controller_rate_hz "
                f"({self.controller_rate_hz}); the ratio is {ratio:g}"
            )
        if isinstance(self.laps, bool) or not isinstance(self.laps, int) or self.laps < 1:
            raise WorkbenchInputError(f"laps must be a whole number >= 1; got {self.laps!r}")
        if self.max_time_s is not None:
            period_s = 1.0 / self.controller_rate_hz
            require_in_range("max_time_s", self.max_time_s, period_s, MAX_TIME_S, "s (one controller period at least)")
        require_positive("max_abs_cte_m", self.max_abs_cte_m)
        require_positive("max_past_end_m", self.max_past_end_m)
        if not isinstance(self.speed_feedforward, bool):
            raise WorkbenchInputError(f"speed_feedforward must be True or False; got {self.speed_feedforward!r}")
        if not isinstance(self.conditions, Conditions):
            raise WorkbenchInputError(
                f"conditions must be a Conditions (a preset of {', '.join(CONDITIONS)} or a file, "
                f"`load_conditions`); got {value_text(self.conditions)}"
            )
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or not 0 <= self.seed < 2**63:
            raise WorkbenchInputError(f"seed must be a whole number in [0, 2**63); got {value_text(self.seed)}")
        if not isinstance(self.inform_delays, bool):
            raise WorkbenchInputError(f"inform_delays must be True or False; got {value_text(self.inform_delays)}")
        if not isinstance(self.perfect_prediction, bool):
            value = value_text(self.perfect_prediction)
            raise WorkbenchInputError(f"perfect_prediction must be True or False; got {value}")
        if self.perfect_prediction and self.conditions.actuation.dead_time_s == 0.0:
            raise WorkbenchInputError(
                f"perfect_prediction hands the controller the state one actuation dead time ahead; the conditions "
                f"{self.conditions.name!r} have no dead time (actuation.dead_time_s = 0)"
            )

    @property
    def known_delays(self) -> KnownDelays | None:
        """What the run's controller is told (`Controller.informed_config`): None unless inform_delays; else the
        conditions' nominal delays and pose noise, without the actuation dead time when perfect_prediction hands the
        controller the state past it."""
        if not self.inform_delays:
            return None
        delays = KnownDelays.from_conditions(self.conditions)
        return replace(delays, dead_time_s=0.0) if self.perfect_prediction else delays

    @property
    def substeps(self) -> int:
        return round(self.plant_rate_hz / self.controller_rate_hz)

    @property
    def speed_mps(self) -> float:
        return self.speed_kmh / 3.6
