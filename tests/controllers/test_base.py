"""The base class's contract (`controllers/base.py`): the plausible envelope, the held command, the flags."""

from __future__ import annotations

import dataclasses
import decimal
import fractions
import math
import sys
from typing import ClassVar

import numpy as np
import pytest

from controllers import base
from controllers.base import Controller, Measurement
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import value_text
from workbench.base.path import ReferencePath
from workbench.vehicles import KinematicBicycle

PATH = ClothoidChain().straight(50.0).to_path("straight")
GEOMETRY = KinematicBicycle().geometry
LOCK = GEOMETRY.max_steer_wheel_angle_rad
GOOD = Measurement(1.0, 5.0, 0.5, 8.0, 0.0, 0.0, 0.0, 0.0)


class _Scripted(Controller):
    """Returns what it is told to, records what it saw, and reports one signal."""

    name: ClassVar[str] = "scripted"
    config_type: ClassVar[type] = dict

    def _reset(self, path: ReferencePath, sample_time_s: float) -> None:
        self.reset_with = (path, sample_time_s)
        self.seen: list[Measurement] = []
        self.next_command, self.signal = 0.1, 0.0
        self._signal = self._declare_diagnostics(("signal",))

    def _command(self, measurement: Measurement, path: ReferencePath) -> float:
        assert path is PATH
        self.seen.append(measurement)
        self._signal[0] = self.signal
        return self.next_command


def _controller() -> _Scripted:
    controller = _Scripted(GEOMETRY)
    controller.reset(PATH, 0.02)
    return controller


def test_a_plausible_measurement_reaches_the_controller_unchanged() -> None:
    controller = _controller()
    assert controller.step(GOOD, PATH) == 0.1
    assert controller.seen == [GOOD] and controller.seen[0] is GOOD
    assert controller.diagnostics == {"signal": 0.0, "measurement_rejected": 0.0, "command_rejected": 0.0}


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("steer_wheel_rad", base.STEER_SENSOR_MARGIN * LOCK),
        ("steer_wheel_rad", -base.STEER_SENSOR_MARGIN * LOCK),
        ("vx_mps", base.MAX_SPEED_MPS),
        ("vx_mps", -base.MAX_SPEED_MPS),
        ("yaw_rate_rad_s", -base.MAX_YAW_RATE_RAD_S),
        ("x_m", base.MAX_POSITION_M),
        ("y_m", -base.MAX_POSITION_M),
        ("t_s", 1.0),  # the same time again (zero dt)
        ("yaw_rad", 1e300),
        ("yaw_rad", -base.MAX_UNWRAPPED_YAW_RAD),
        ("t_s", base.MAX_TIME_S),
        ("yaw_rate_rad_s", base.MAX_YAW_RATE_RAD_S),
        ("x_m", -base.MAX_POSITION_M),
        ("y_m", base.MAX_POSITION_M),
    ],
)
def test_the_envelope_edges_are_plausible(field: str, value: float) -> None:
    controller = _controller()
    controller.step(GOOD, PATH)
    controller.next_command = 0.2
    assert controller.step(dataclasses.replace(GOOD, **{field: value}), PATH) == 0.2
    assert controller.diagnostics["measurement_rejected"] == 0.0


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("steer_wheel_rad", base.STEER_SENSOR_MARGIN * LOCK * (1 + 1e-9)),
        ("vx_mps", math.nextafter(base.MAX_SPEED_MPS, math.inf)),
        ("vy_mps", -base.MAX_SPEED_MPS - 1e-6),
        ("yaw_rate_rad_s", base.MAX_YAW_RATE_RAD_S + 1e-9),
        ("x_m", -base.MAX_POSITION_M * 1.000001),
        ("t_s", math.nextafter(1.0, 0.0)),
        ("t_s", 2 * base.MAX_TIME_S),
        ("t_s", math.nan),
        ("yaw_rad", math.inf),
        ("steer_wheel_rad", None),
        ("x_m", "5"),
    ],
)
def test_beyond_the_envelope_the_last_command_is_held(field: str, value: object) -> None:
    controller = _controller()
    controller.step(GOOD, PATH)
    controller.next_command, controller.signal = 0.2, 7.0
    assert controller.step(dataclasses.replace(GOOD, **{field: value}), PATH) == 0.1
    assert controller.seen == [GOOD]  # the controller never saw it
    assert controller.diagnostics == {"signal": 0.0, "measurement_rejected": 1.0, "command_rejected": 0.0}
    assert controller.rejection
    assert controller.held_command == 0.1


def test_a_huge_yaw_is_wrapped_before_the_controller_sees_it() -> None:
    controller = _controller()
    yaw = 2 * math.pi * 1e6 + 0.25
    controller.step(dataclasses.replace(GOOD, yaw_rad=yaw), PATH)
    seen = controller.seen[-1].yaw_rad
    assert -math.pi <= seen < math.pi and math.isclose(math.sin(seen), math.sin(yaw), abs_tol=1e-6)
    controller.step(dataclasses.replace(GOOD, yaw_rad=1e300), PATH)
    assert -math.pi <= controller.seen[-1].yaw_rad < math.pi
    controller.step(dataclasses.replace(GOOD, yaw_rad=50.0), PATH)
    assert controller.seen[-1].yaw_rad == 50.0  # below MAX_UNWRAPPED_YAW_RAD: as measured


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_non_finite_command_is_not_sent(bad: float) -> None:
    controller = _controller()
    controller.step(GOOD, PATH)
    controller.next_command, controller.signal = bad, 3.0
    assert controller.step(dataclasses.replace(GOOD, t_s=1.02), PATH) == 0.1
    assert controller.diagnostics == {"signal": 0.0, "measurement_rejected": 0.0, "command_rejected": 1.0}
    controller.next_command = 0.3
    assert controller.step(dataclasses.replace(GOOD, t_s=1.04), PATH) == 0.3
    assert controller.diagnostics == {"signal": 3.0, "measurement_rejected": 0.0, "command_rejected": 0.0}


def test_non_finite_diagnostics_reject_the_command_too() -> None:
    controller = _controller()
    controller.step(GOOD, PATH)
    controller.next_command, controller.signal = 0.3, math.nan
    assert controller.step(dataclasses.replace(GOOD, t_s=1.02), PATH) == 0.1
    assert controller.diagnostics == {"signal": 0.0, "measurement_rejected": 0.0, "command_rejected": 1.0}


def test_the_command_is_saturated_and_a_reset_forgets_the_hold() -> None:
    controller = _controller()
    controller.next_command = 1e6
    assert controller.step(GOOD, PATH) == LOCK
    controller.next_command = -math.inf
    assert controller.step(dataclasses.replace(GOOD, t_s=1.02), PATH) == LOCK
    controller.reset(PATH, 0.02)
    assert controller.held_command == 0.0
    assert controller.step(dataclasses.replace(GOOD, t_s=math.nan), PATH) == 0.0
    controller.next_command = 0.5
    assert controller.step(dataclasses.replace(GOOD, t_s=0.0), PATH) == 0.5  # time starts afresh


def test_the_flags_are_there_before_the_first_step() -> None:
    controller = _controller()
    assert controller.diagnostics == {"signal": 0.0, "measurement_rejected": 0.0, "command_rejected": 0.0}


def test_a_bad_sample_time_is_refused_for_every_controller() -> None:
    from workbench.base.errors import WorkbenchInputError

    with pytest.raises(WorkbenchInputError, match=r"^sample_time_s must be a finite number > 0; got 0\.0$"):
        _Scripted(GEOMETRY).reset(PATH, 0.0)


def test_a_clock_that_stays_behind_restarts_the_controller_instead_of_locking_it_out() -> None:
    """One frame stamped far ahead, then the clock as it was: the next CLOCK_RESET_FRAMES - 1 frames are rejected
    as earlier than the last accepted one; the one after is a new time base, and the controller restarts on it."""
    controller = _controller()
    controller.step(GOOD, PATH)
    controller.next_command = 0.2
    assert controller.step(dataclasses.replace(GOOD, t_s=1e9), PATH) == 0.2  # a glitch, but plausible on its own
    controller.next_command = 0.3
    for k in range(1, base.CLOCK_RESET_FRAMES):
        assert controller.step(dataclasses.replace(GOOD, t_s=1.0 + 0.02 * k), PATH) == 0.2
        assert controller.diagnostics["measurement_rejected"] == 1.0 and "earlier than" in controller.rejection
    restart = dataclasses.replace(GOOD, t_s=1.0 + 0.02 * base.CLOCK_RESET_FRAMES)
    assert controller.step(restart, PATH) == 0.1  # the restarted controller's first command (its _reset's)
    assert controller.seen == [restart] and controller.diagnostics["measurement_rejected"] == 0.0
    later = dataclasses.replace(GOOD, t_s=restart.t_s + 0.02)
    assert controller.step(later, PATH) == 0.1 and controller.seen == [restart, later]


#: Values of a type no field may have: each is refused even where its magnitude would pass (abs() accepts a
#: complex number, an array compares element-wise, a bool is an int).
NOT_REAL = [
    1.0 + 0.0j,
    complex(0.5, 1e-12),
    np.complex128(0.5),
    "0.5",
    None,
    True,
    np.bool_(False),
    np.array(0.5),
    np.array([0.5]),
    np.array([0.5, 0.5]),
    decimal.Decimal("0.5"),
]


@pytest.mark.parametrize("field", base._FIELDS)
@pytest.mark.parametrize("value", NOT_REAL, ids=repr)
def test_a_field_that_is_not_a_real_number_is_rejected_naming_field_and_value(field: str, value: object) -> None:
    controller = _controller()
    controller.step(GOOD, PATH)
    controller.next_command, controller.signal = 0.2, 7.0
    assert controller.step(dataclasses.replace(GOOD, **{field: value}), PATH) == 0.1
    assert controller.seen == [GOOD]
    assert controller.diagnostics == {"signal": 0.0, "measurement_rejected": 1.0, "command_rejected": 0.0}
    assert controller.rejection.startswith(f"{field} = {value_text(value)} ({type(value).__name__}) is not a real")


@pytest.mark.parametrize("field", base._FIELDS)
def test_an_int_beyond_any_float_is_rejected(field: str) -> None:
    controller = _controller()
    controller.step(GOOD, PATH)
    assert controller.step(dataclasses.replace(GOOD, **{field: 10**400}), PATH) == 0.1
    assert controller.rejection == f"{field} is a int beyond any float (above 1.8e308)"
    assert controller.seen == [GOOD]


def test_a_long_value_is_shown_cut_short() -> None:
    controller = _controller()
    controller.step(dataclasses.replace(GOOD, x_m=np.zeros(100)), PATH)
    shown = controller.rejection.split(" (ndarray)")[0].removeprefix("x_m = ")
    assert len(shown) == base._SHOWN_CHARS and shown.endswith("...")
    controller.step(dataclasses.replace(GOOD, x_m="x" * (base._SHOWN_CHARS - 2)), PATH)
    assert controller.rejection.startswith(f"x_m = '{'x' * (base._SHOWN_CHARS - 2)}' (str)")


def test_a_measurement_that_is_not_one_is_rejected() -> None:
    controller = _controller()
    assert controller.step((1.0, 5.0), PATH) == 0.0  # type: ignore[arg-type]
    assert controller.rejection == "the measurement is a tuple, not a Measurement"


@pytest.mark.parametrize(
    "dtype", [np.float16, np.float32, np.float64, np.longdouble, np.int8, np.int16, np.int32, np.int64, np.uint8,
              np.uint16, np.uint32, np.uint64, int, float, fractions.Fraction],
)  # fmt: skip
def test_real_numbers_of_any_type_reach_the_controller_as_floats(dtype: type) -> None:
    controller = _controller()
    typed = Measurement(*(dtype(v) for v in (1, 5, 0, 8, 0, 0, 0, 0)))
    assert controller.step(typed, PATH) == 0.1
    seen = controller.seen[-1]
    assert all(isinstance(getattr(seen, name), float) for name in base._FIELDS), seen  # float64 is a float
    assert seen == Measurement(1.0, 5.0, 0.0, 8.0, 0.0, 0.0, 0.0, 0.0)


def test_a_measurement_of_floats_reaches_the_controller_as_it_is() -> None:
    """numpy's float64 is a float: the simulator's measurements pass without a copy."""
    controller = _controller()
    measured = Measurement(*np.array([1.0, 5.0, 0.5, 8.0, 0.0, 0.0, 0.0, 0.0]))
    controller.step(measured, PATH)
    assert controller.seen[-1] is measured


SENSOR_RANGE = base.STEER_SENSOR_MARGIN * LOCK


@pytest.mark.parametrize(
    ("fields", "why"),
    [
        ({"x_m": math.nan, "yaw_rad": math.inf}, "x_m, yaw_rad not finite"),
        ({"steer_wheel_rad": -30.0}, f"|steer_wheel_rad| = 30 is beyond the sensor's range {SENSOR_RANGE:g} rad"),
        ({"vx_mps": 100.0, "vy_mps": 120.0}, "speed 156.205 m/s is above 150 m/s"),  # each alone is within it
        ({"yaw_rate_rad_s": -11.0}, "|yaw_rate_rad_s| = 11 is above 10 rad/s"),
        ({"x_m": 2e8}, "position (2e+08, 0.5) m is beyond +-1e+08 m"),
        ({"y_m": -2e8}, "position (5, -2e+08) m is beyond +-1e+08 m"),
        ({"t_s": 2e12}, "t_s = 2e+12 s is beyond +-1e+12 s"),
        # each bound itself is plausible: the reason is the one field beyond its bound
        ({"steer_wheel_rad": SENSOR_RANGE, "t_s": 2e12}, "t_s = 2e+12 s is beyond +-1e+12 s"),
        ({"vx_mps": base.MAX_SPEED_MPS, "t_s": 2e12}, "t_s = 2e+12 s is beyond +-1e+12 s"),
        ({"yaw_rate_rad_s": base.MAX_YAW_RATE_RAD_S, "t_s": 2e12}, "t_s = 2e+12 s is beyond +-1e+12 s"),
        ({"x_m": base.MAX_POSITION_M, "y_m": base.MAX_POSITION_M, "t_s": 2e12}, "t_s = 2e+12 s is beyond +-1e+12 s"),
    ],
)
def test_the_rejection_says_which_field_is_beyond_which_bound(fields: dict, why: str) -> None:
    controller = _controller()
    controller.step(GOOD, PATH)
    controller.step(dataclasses.replace(GOOD, **fields), PATH)
    assert controller.diagnostics["measurement_rejected"] == 1.0
    assert controller.rejection == why


def test_a_rejected_step_keeps_the_last_accepted_signals() -> None:
    controller = _controller()
    controller.signal = 7.0
    controller.step(GOOD, PATH)
    controller.signal = 3.0
    controller.step(dataclasses.replace(GOOD, t_s=math.nan), PATH)
    assert controller.diagnostics == {"signal": 7.0, "measurement_rejected": 1.0, "command_rejected": 0.0}


def test_a_non_finite_command_says_so_and_a_reset_clears_the_reason() -> None:
    controller = _controller()
    assert controller.rejection == ""
    controller.next_command = math.nan
    controller.step(GOOD, PATH)
    assert controller.rejection == "the controller's command or diagnostics were not finite"
    controller.reset(PATH, 0.02)
    assert controller.rejection == ""


def test_the_yaw_is_wrapped_only_beyond_the_bound_and_nothing_else_changes() -> None:
    controller = _controller()
    controller.step(dataclasses.replace(GOOD, yaw_rad=base.MAX_UNWRAPPED_YAW_RAD), PATH)
    assert controller.seen[-1].yaw_rad == base.MAX_UNWRAPPED_YAW_RAD  # at the bound: as measured
    measured = Measurement(2.0, 6.0, 0.7, 8.5, 0.3, 2 * math.pi * 1e4 + 0.25, 0.4, 0.5)
    controller.step(measured, PATH)
    seen = controller.seen[-1]
    assert seen.yaw_rad == pytest.approx(0.25, abs=1e-9)
    assert dataclasses.replace(seen, yaw_rad=measured.yaw_rad) == measured


def test_a_restart_on_a_reset_clock_keeps_the_path_and_sample_time() -> None:
    controller = _Scripted(GEOMETRY)
    controller.reset(PATH, 0.05)
    assert controller.reset_with == (PATH, 0.05)
    controller.reset_with = None
    controller.step(dataclasses.replace(GOOD, t_s=100.0), PATH)
    for k in range(base.CLOCK_RESET_FRAMES):
        controller.step(dataclasses.replace(GOOD, t_s=1.0 + k), PATH)
    assert controller.reset_with == (PATH, 0.05)
    assert controller.seen == [dataclasses.replace(GOOD, t_s=float(base.CLOCK_RESET_FRAMES))]


def test_a_config_of_another_type_is_refused_naming_both() -> None:
    with pytest.raises(TypeError, match=r"^scripted takes a dict; got list$"):
        _Scripted(GEOMETRY, [])


def test_the_summary_is_the_first_line_of_the_controllers_module_docstring() -> None:
    from controllers.stanley import Stanley

    assert Stanley.summary() == sys.modules[Stanley.__module__].__doc__.strip().splitlines()[0]
    assert _Scripted.summary() == __doc__.strip().splitlines()[0]
