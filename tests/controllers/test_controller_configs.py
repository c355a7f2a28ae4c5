"""Every option of every controller config, fed values a user can type by mistake: each is accepted (and the
controller then builds and steps, or refuses with the project's input error) or refused with WorkbenchInputError
naming the option and the value received, never another exception (ZeroDivisionError, TypeError, OverflowError)."""

from __future__ import annotations

import dataclasses
import math
import re

import pytest

from controllers import CONTROLLERS, make_controller
from controllers.base import Measurement
from controllers.mpc import MPCConfig
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.vehicles import KinematicBicycle

CONFIGS = {cls.config_type.__name__: (name, cls.config_type) for name, cls in CONTROLLERS.items()}
CONFIGS["MPCConfig"] = (None, MPCConfig)
BAD_VALUES = {"0": 0, "-1": -1, "nan": math.nan, "inf": math.inf, "1e308": 1e308, "True": True, "x": "x"}
CASES = [
    (config_name, field.name, label)
    for config_name, (_, config_type) in CONFIGS.items()
    for field in dataclasses.fields(config_type)
    if field.init
    for label in BAD_VALUES
]
PATH = ClothoidChain().straight(40.0).to_path("straight")


@pytest.mark.parametrize(("config_name", "field", "label"), CASES)
def test_every_option_refuses_a_bad_value_by_name(config_name: str, field: str, label: str) -> None:
    controller_name, config_type = CONFIGS[config_name]
    value = BAD_VALUES[label]
    try:
        config = config_type(**{field: value})
    except WorkbenchInputError as exc:
        message = str(exc)
        assert field in message, message
        assert value_text(value) in message, message
        assert "np.float64" not in message
        return
    if controller_name is None:  # the MPCs' shared base: its own fields are checked through NMPC/LMPC too
        return
    vehicle = KinematicBicycle()
    try:
        controller = make_controller(controller_name, vehicle.geometry, config)
    except WorkbenchInputError as exc:  # e.g. a file option "x" that does not exist
        assert re.search(r"(?<![\w.])x(?!\w)", str(exc)), str(exc)
        return
    controller.reset(PATH, 0.02)
    command = controller.step(Measurement(0.0, 1.0, 0.2, 8.0, 0.0, 0.0, 0.0, 0.0), PATH)
    assert math.isfinite(command)
    assert abs(command) <= vehicle.geometry.max_steer_wheel_angle_rad


def test_every_config_is_covered() -> None:
    assert {"ClothoidConfig", "PurePursuitConfig", "StanleyConfig", "NMPCConfig", "LMPCConfig"} <= set(CONFIGS)
    assert len(CASES) > 7 * 50


def test_numbers_are_shown_as_numbers() -> None:
    import numpy as np

    assert value_text(np.float64("nan")) == "nan"
    assert value_text(np.float64(1e308)) == "1e+308"
    assert value_text(np.int64(3)) == "3"
    assert value_text(True) == "True"
    assert value_text("x") == "'x'"
    with pytest.raises(WorkbenchInputError, match=r"frechet_threshold_m must be .*; got nan$"):
        CONTROLLERS["clothoid"].config_type(frechet_threshold_m=np.float64("nan"))
