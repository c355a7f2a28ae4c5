"""The one small interface every lateral controller implements, and the contract it keeps on bad sensor frames.

A controller is built once for a vehicle (its geometry and limits) and a frozen config, `reset` for a path and
its sample time, then stepped at that rate with what GPS/IMU and the steering sensor give. It returns a
steering-wheel angle command. Whatever it wants logged about its last step (lookahead, solver status, ...) it
names once in `_reset` (`_declare_diagnostics`) and writes each step into the array that returns, in that order:
no per-step mapping on the hot path. The simulator records them as `ctrl_<name>` columns from
`diagnostic_names` / `diagnostic_values`; `diagnostics` gives them as a mapping. Controllers contain no plotting
and no I/O.

The contract, kept here once for every controller: a real steering ECU holds its last command on a
bad sensor frame, and so does every controller. `Controller.step` is a template method:

  1. it screens the measurement against a plausible envelope (the constants below: every field a real number,
     i.e. a float, an int or a NumPy real scalar of any dtype, never a bool, complex number, string, None or
     array; every field finite, the steering sensor within STEER_SENSOR_MARGIN x the mechanical lock, speed, yaw
     rate, position and time within their bounds, time not earlier than the last accepted frame's). The controller
     sees every field as a float. An implausible measurement never reaches the controller: the step returns the
     last command it returned since `reset` (0.0 before any), the diagnostics say `measurement_rejected` = 1 and
     `rejection` names the field and its value; no exception is raised. Any finite yaw is plausible; one beyond
     MAX_UNWRAPPED_YAW_RAD is wrapped to [-pi, pi) before the controller sees it.
  2. Otherwise it calls the controller's `_command`. If that returns a non-finite number, or the controller's own
     diagnostics are not all finite, the held command is returned and `command_rejected` = 1.
  3. The command is saturated to the vehicle's steering-wheel limit.

So `step` always returns a finite command within the limit, and an implausible measurement changes nothing in
the controller. On a rejected step the controller's own diagnostics are those of the last accepted one;
`diagnostics` always holds the controller's own keys plus `measurement_rejected` and `command_rejected` (1.0 or
0.0), all finite, the same keys every step. `reset` clears the held command and the last accepted time. A frame
stamped earlier than the last accepted one is rejected, unless CLOCK_RESET_FRAMES come so in a row: then the
clock was reset, and the controller restarts (as `reset`) and takes the frame, so that one frame stamped far
ahead cannot lock it out. Subclasses implement the abstract `_reset` (declaring their diagnostics, if any) and
`_command`; they do not override `step`, `reset` or the diagnostics' accessors. `rejection` says in words why the last
rejected step was rejected.
"""

from __future__ import annotations

import math
import sys
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, ClassVar, Generic, TypeVar

import numpy as np

from controllers.search_space import Tunable
from workbench.base.errors import is_number, require_positive, value_text
from workbench.base.path import ReferencePath, wrap_angle
from workbench.simulation.control_interface import COMMAND_REJECTED, MEASUREMENT_REJECTED, Measurement
from workbench.vehicles.geometry import VehicleGeometry

if TYPE_CHECKING:
    from workbench.simulation.known_delays import KnownDelays
    from workbench.vehicles.base import VehicleModel

#: A controller's config: the frozen dataclass its `config_type` names.
ConfigT = TypeVar("ConfigT")

# The plausible envelope of a measurement (`Controller.step` rejects a frame outside it). Each bound is far beyond
# what any vehicle here can do, so that no plausible run is ever touched, and near enough that what lies beyond is
# a sensor or transmission fault rather than a state to steer from.

#: A steering-wheel reading beyond this multiple of the mechanical lock (`max_steer_wheel_angle_rad`) is a sensor
#: fault: the wheel cannot get there. The margin above 1 leaves room for calibration offsets and compliance.
STEER_SENSOR_MARGIN = 1.5
#: Largest plausible speed over ground hypot(vx, vy) (m/s; 540 km/h, beyond any road vehicle).
MAX_SPEED_MPS = 150.0
#: Largest plausible |yaw rate| (rad/s; 573 deg/s: a car spinning out stays well below it).
MAX_YAW_RATE_RAD_S = 10.0
#: Largest plausible |x|, |y| (m): covers local frames as large as UTM coordinates (northings reach 1e7 m).
MAX_POSITION_M = 1e8
#: Largest plausible |t_s| (s): covers Unix and GPS epoch time stamps (about 2e9 s) while a double still resolves
#: 0.2 ms, so that a controller period is never lost in rounding.
MAX_TIME_S = 1e12
#: Any finite yaw is plausible (a yaw angle integrated over many turns is still a heading); one beyond this
#: magnitude (rad; about 1600 turns) is wrapped to [-pi, pi) before the controller sees it, so that its rounding
#: does not swallow the small angles added to it. Below it the yaw is passed unchanged.
MAX_UNWRAPPED_YAW_RAD = 1e4
#: A clock that runs backwards for this many frames in a row has been reset (a new time base), not glitched: the
#: controller restarts (as `reset`, on the same path) and takes the frame. Fewer are single bad frames, rejected;
#: without the restart one frame stamped far ahead would lock the controller out until the next `reset`.
CLOCK_RESET_FRAMES = 5
_FIELDS = ("t_s", "x_m", "y_m", "vx_mps", "vy_mps", "yaw_rad", "yaw_rate_rad_s", "steer_wheel_rad")
#: What a measurement's field may be, for the rejection of one that is not.
_REAL_NUMBERS = "a field must be a float, an int or a NumPy real scalar (not a bool, complex, string, None or array)"
#: The most characters of a refused value a rejection shows (an array's repr can be long).
_SHOWN_CHARS = 60


class Controller(ABC, Generic[ConfigT]):
    """Base class: subclasses (`Controller[TheirConfig]`) set `name`, `config_type` and implement `_reset` (calling
    `_declare_diagnostics` if they log anything) and `_command` (the module docstring's contract is kept here, in
    `step`)."""

    name: ClassVar[str]
    #: The class of `config` (ConfigT; a class variable cannot name a type variable, so it is typed as a class).
    config_type: ClassVar[type]
    config: ConfigT
    _held_command: float
    _last_t_s: float
    _rewound_frames: int
    rejection: str
    #: The options worth tuning, with bounds, scale and reason (`controllers.search_space`); empty: none declared,
    #: and a tournament spec gives the controller its space as a [search.NAME] table.
    search_space: ClassVar[tuple[Tunable, ...]] = ()

    def __init__(
        self, geometry: VehicleGeometry, config: ConfigT | None = None, vehicle: VehicleModel | None = None
    ) -> None:
        """`geometry`: the steered vehicle's; `config`: an instance of `config_type` (its defaults when None);
        `vehicle`: the steered vehicle's model (a `VehicleModel`), for controllers that predict with it (the
        MPCs); geometric controllers ignore it."""
        self.geometry = geometry
        self.config = config if config is not None else self.config_type()
        if not isinstance(self.config, self.config_type):
            raise TypeError(f"{self.name} takes a {self.config_type.__name__}; got {type(self.config).__name__}")
        self._clear_hold()
        self._declare_diagnostics(())
        self._publish_declared()

    @classmethod
    def summary(cls) -> str:
        """The first line of the controller's module docstring, for `workbench controllers`.

        Returns
        -------
        str
            That line (the class's name when the module has no docstring).
        """
        doc = sys.modules[cls.__module__].__doc__ or cls.__name__
        return doc.strip().splitlines()[0]

    @classmethod
    def informed_config(cls, config: ConfigT, delays: KnownDelays) -> ConfigT:
        """`config` (a `config_type`) told the run's nominal delays and pose noise (`KnownDelays`): the options
        by which this controller compensates them set from `delays`, every other option as it is.

        Parameters
        ----------
        config : config_type
            The controller's options, a file's and the vehicle's tuning included.
        delays : KnownDelays
            The conditions' nominal latencies, dead time and pose noise (`KnownDelays.from_conditions`).

        Returns
        -------
        config_type
            This default returns `config` unchanged: a controller without delay compensation (Stanley, pure
            pursuit, a plugin that does not override it) has nothing to be told. A controller that compensates
            delays overrides it (the clothoid controller, the MPCs)."""
        return config

    # ------------------------------------------------------------------ the interface (not overridden)
    def reset(self, path: ReferencePath, sample_time_s: float) -> None:
        """Forget all state; the next step is the first on `path`; steps come every `sample_time_s` seconds.

        Parameters
        ----------
        path : ReferencePath
            The path the run follows, with its planned speeds when it has them.
        sample_time_s : float, s
            The controller's period, > 0: `step` is called once per period.

        Raises
        ------
        WorkbenchInputError
            sample_time_s is not a finite number > 0.
        """
        require_positive("sample_time_s", sample_time_s)
        self._clear_hold()
        self._sample_time_s = float(sample_time_s)
        self._declare_diagnostics(())
        self._reset(path, sample_time_s)
        self._publish_declared()

    def step(self, measurement: Measurement, path: ReferencePath) -> float:
        """Steering-wheel angle command (rad) for this step: always finite and within the vehicle's limit (the
        module docstring's contract: an implausible measurement or a non-finite result holds the last command).

        Parameters
        ----------
        measurement : Measurement
            The vehicle's state this step (pose, speed, yaw rate, time); one with a non-finite or implausible
            field, or a time earlier than the last accepted one, is rejected (see `diagnostics`).
        path : ReferencePath
            The path given to `reset`.

        Returns
        -------
        float, rad
            The steering-wheel angle command, finite and within +-max_steer_wheel_angle_rad: `held_command`
            when the step was rejected.
        """
        screened = self._screen(measurement)
        if screened is not None and screened.t_s < self._last_t_s:
            self._rewound_frames += 1
            if self._rewound_frames < CLOCK_RESET_FRAMES:
                self.rejection = f"t_s = {screened.t_s:g} s is earlier than the last accepted {self._last_t_s:g} s"
                screened = None
            else:  # the clock has been reset, not glitched: so is the controller, and it takes the frame
                self._reset(path, self._sample_time_s)
        report, n = self._report, self._own.size
        if screened is None:
            report[n], report[n + 1] = 1.0, 0.0  # the own values stay those of the last accepted step
            return self._held_command
        command = float(self._command(screened, path))
        own = self._own
        if not (math.isfinite(command) and math.isfinite(sum(own.tolist()))):  # a NaN or inf makes the sum one
            self.rejection = "the controller's command or diagnostics were not finite"
            report[n], report[n + 1] = 0.0, 1.0
            return self._held_command
        limit = self.geometry.max_steer_wheel_angle_rad
        command = min(max(command, -limit), limit)
        self._held_command, self._last_t_s, self._rewound_frames = command, screened.t_s, 0
        report[:n] = own
        report[n], report[n + 1] = 0.0, 0.0
        return command

    @property
    def diagnostic_names(self) -> tuple[str, ...]:
        """The names of `diagnostic_values`: the controller's own, then `measurement_rejected` and
        `command_rejected`; the same every step from `reset` on."""
        return self._report_names

    @property
    def diagnostic_values(self) -> np.ndarray:
        """Internal signals of the last step, to be logged, in the order of `diagnostic_names`: the controller's own
        (those of the last accepted step when this one was rejected) and the two flags (1.0 / 0.0). The array is the
        controller's and is overwritten by the next step: copy what you keep."""
        return self._report

    @property
    def diagnostics(self) -> Mapping[str, float]:
        """`diagnostic_values` by name, as a new mapping (one handed out earlier stays as it was)."""
        return dict(zip(self._report_names, self._report.tolist(), strict=True))

    @property
    def held_command(self) -> float:
        """The command a rejected step returns: the last one returned since `reset` (0.0 before any)."""
        return self._held_command

    def saturate(self, steer_wheel_rad: float) -> float:
        """Clip a steering-wheel angle to the vehicle's limit.

        Parameters
        ----------
        steer_wheel_rad : float, rad
            A steering-wheel angle.

        Returns
        -------
        float, rad
            The angle within +-max_steer_wheel_angle_rad of the vehicle's geometry.
        """
        limit = self.geometry.max_steer_wheel_angle_rad
        return min(max(steer_wheel_rad, -limit), limit)

    def run_warnings(self, path: ReferencePath, sample_time_s: float) -> list[str]:
        """What to tell a person before a run on `path` with steps every sample_time_s (s): settings that cannot act
        as configured on it (`SteeringController.run_warnings`); none unless a subclass says otherwise.

        Parameters
        ----------
        path : ReferencePath
            The path to run, with its planned speeds when it has them.
        sample_time_s : float, s
            The controller's period, > 0.

        Returns
        -------
        list of str
            One message per setting that cannot act as configured; empty when there is none.
        """
        return []

    # ------------------------------------------------------------------ what subclasses implement
    @abstractmethod
    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        """Forget all state for a new run on `path` (sample_time_s > 0 already checked); set up the controller's
        own diagnostics with every key it will ever report."""

    @abstractmethod
    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        """The steering-wheel command (rad) for a measurement that passed the screen; the base class saturates the
        result and holds the last command when it is not finite."""

    def _declare_diagnostics(self, names: Sequence[str]) -> np.ndarray:
        """For `_reset`: the names of the controller's own signals, in the order `_command` writes them into the
        array returned (kept as `self._own`; zeros until the first step). None declared: no signals."""
        self._own_names = tuple(names)
        self._own = np.zeros(len(self._own_names))
        return self._own

    # ------------------------------------------------------------------ the screen
    def _clear_hold(self) -> None:
        self._held_command = 0.0
        self._last_t_s = -math.inf
        self._rewound_frames = 0  # frames in a row stamped earlier than the last accepted one
        #: Why the last rejected step was rejected ("" until one is), for a person reading a failure.
        self.rejection = ""

    def _publish_declared(self) -> None:
        """The report (`diagnostic_values`) for the declared signals: their initial values, no flag raised."""
        self._report_names = (*self._own_names, MEASUREMENT_REJECTED, COMMAND_REJECTED)
        self._report = np.zeros(len(self._report_names))
        self._report[: self._own.size] = self._own

    def _screen(self, m: Measurement) -> Measurement | None:
        """The measurement the controller may see (every field a float, its yaw wrapped when beyond
        MAX_UNWRAPPED_YAW_RAD), or None when a field is not a real number or the frame lies outside the plausible
        envelope (then `self.rejection` says why)."""
        try:  # the simulator's fields are floats (numpy's float64 among them): one check, no conversion
            floats = (
                isinstance(m.t_s, float)
                and isinstance(m.x_m, float)
                and isinstance(m.y_m, float)
                and isinstance(m.vx_mps, float)
                and isinstance(m.vy_mps, float)
                and isinstance(m.yaw_rad, float)
                and isinstance(m.yaw_rate_rad_s, float)
                and isinstance(m.steer_wheel_rad, float)
            )
        except AttributeError:
            self.rejection = f"the measurement is a {type(m).__name__}, not a Measurement"
            return None
        if not floats:
            as_floats = self._as_floats(m)
            if as_floats is None:
                return None
            m = as_floats
        plausible = (  # one expression on the path every plausible step takes (a comparison with NaN is False)
            abs(m.steer_wheel_rad) <= STEER_SENSOR_MARGIN * self.geometry.max_steer_wheel_angle_rad
            and math.hypot(m.vx_mps, m.vy_mps) <= MAX_SPEED_MPS
            and abs(m.yaw_rate_rad_s) <= MAX_YAW_RATE_RAD_S
            and abs(m.x_m) <= MAX_POSITION_M
            and abs(m.y_m) <= MAX_POSITION_M
            and abs(m.t_s) <= MAX_TIME_S
            and math.isfinite(m.yaw_rad)
        )
        if not plausible:
            self.rejection = self._why_implausible(m)
            return None
        if abs(m.yaw_rad) > MAX_UNWRAPPED_YAW_RAD:
            m = Measurement(
                m.t_s, m.x_m, m.y_m, m.vx_mps, m.vy_mps, float(wrap_angle(float(m.yaw_rad))), m.yaw_rate_rad_s,
                m.steer_wheel_rad,
            )  # fmt: skip
        return m

    def _as_floats(self, m: Measurement) -> Measurement | None:
        """The measurement with every field a float, when each is a real number (`is_number`: Python's or a NumPy
        real scalar of any dtype, not a bool); None otherwise, `self.rejection` naming the first field that is not
        (a complex number, a string, None, an array of any shape) or that no float can hold."""
        values = []
        for name in _FIELDS:
            value = getattr(m, name)
            if not is_number(value):
                shown = value_text(value)
                shown = shown if len(shown) <= _SHOWN_CHARS else shown[: _SHOWN_CHARS - 3] + "..."
                self.rejection = f"{name} = {shown} ({type(value).__name__}) is not a real number; {_REAL_NUMBERS}"
                return None
            try:
                values.append(float(value))
            except OverflowError:  # an int (or a fraction) beyond any float: too long to show
                self.rejection = f"{name} is a {type(value).__name__} beyond any float (above 1.8e308)"
                return None
        return Measurement(*values)

    def _why_implausible(self, m: Measurement) -> str:
        """What puts the measurement (every field a float) outside the envelope, in words."""
        values = (m.t_s, m.x_m, m.y_m, m.vx_mps, m.vy_mps, m.yaw_rad, m.yaw_rate_rad_s, m.steer_wheel_rad)
        bad = [name for name, v in zip(_FIELDS, values, strict=True) if not math.isfinite(v)]
        if bad:
            return f"{', '.join(bad)} not finite"
        lock = STEER_SENSOR_MARGIN * self.geometry.max_steer_wheel_angle_rad
        if abs(m.steer_wheel_rad) > lock:
            return f"|steer_wheel_rad| = {abs(float(m.steer_wheel_rad)):g} is beyond the sensor's range {lock:g} rad"
        if math.hypot(m.vx_mps, m.vy_mps) > MAX_SPEED_MPS:
            return f"speed {math.hypot(m.vx_mps, m.vy_mps):g} m/s is above {MAX_SPEED_MPS:g} m/s"
        if abs(m.yaw_rate_rad_s) > MAX_YAW_RATE_RAD_S:
            return f"|yaw_rate_rad_s| = {abs(float(m.yaw_rate_rad_s)):g} is above {MAX_YAW_RATE_RAD_S:g} rad/s"
        if abs(m.x_m) > MAX_POSITION_M or abs(m.y_m) > MAX_POSITION_M:
            return f"position ({float(m.x_m):g}, {float(m.y_m):g}) m is beyond +-{MAX_POSITION_M:g} m"
        return f"t_s = {float(m.t_s):g} s is beyond +-{MAX_TIME_S:g} s"


__all__ = ["Controller"]
