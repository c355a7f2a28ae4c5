"""The clothoid step's named records (`step_kernel.PARAMS`, `STATE`, `MEASUREMENT`, `StepArguments`): made in one
place each, every field set, and the step's arguments named in its own order."""

from __future__ import annotations

import dataclasses
import inspect
import math

import numpy as np
import pytest

from controllers.base import Measurement
from controllers.clothoid import ClothoidConfig, ClothoidController
from controllers.clothoid import step_kernel as sk
from controllers.clothoid.lookahead import SEARCH_SETTINGS
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.path_search import TRACK_PROGRESS, TRACK_S
from workbench.vehicles import make_vehicle

CAR = make_vehicle("kinematic-bicycle")
STRAIGHT = ClothoidChain().straight(60.0).to_path("straight")


def test_the_step_arguments_are_named_in_the_steps_own_order() -> None:
    assert sk.StepArguments._fields == tuple(inspect.signature(sk.clothoid_step.py_func).parameters)


def test_the_step_reads_the_measurement_in_its_fields_order() -> None:
    controller = ClothoidController(CAR.geometry, ClothoidConfig())
    controller.reset(STRAIGHT, 0.02)
    m = Measurement(0.04, 5.0, 0.2, 8.0, 0.1, 0.01, 0.02, 0.03)
    controller.step(m, STRAIGHT)
    assert controller._measured.dtype == sk.MEASUREMENT
    assert controller._measured[0].tolist() == tuple(getattr(m, f.name) for f in dataclasses.fields(Measurement))


def test_the_parameters_are_refused_unless_every_field_is_named() -> None:
    fields = dict.fromkeys(sk.PARAMS.names, 1.0)
    params = sk.parameters(**fields)
    assert params.dtype == sk.PARAMS and params.shape == (1,)
    with pytest.raises(ValueError, match="missing \\['wheelbase'\\]"):
        sk.parameters(**{k: v for k, v in fields.items() if k != "wheelbase"})
    with pytest.raises(ValueError, match="unknown \\['wheel_base'\\]"):
        sk.parameters(**fields, wheel_base=2.0)
    assert math.isnan(sk.parameters(**(fields | {"max_growth": None}))[0]["max_growth"])


def test_the_parameters_hold_the_search_settings_by_name() -> None:
    """The step hands its parameters to the adaptive search as they are: every search setting is a parameter."""
    assert set(SEARCH_SETTINGS.names) <= set(sk.PARAMS.names)
    for name in SEARCH_SETTINGS.names:
        assert sk.PARAMS[name] == SEARCH_SETTINGS[name]


def test_the_controllers_parameters_are_its_options() -> None:
    config = ClothoidConfig(lookahead_mode="speed", max_lookahead_growth_m_per_m=None, threshold_mode="absolute")
    controller = ClothoidController(CAR.geometry, config)
    params = controller._params[0]
    assert params["lookahead_mode"] == 2 and params["excess"] == False  # noqa: E712 - a numpy bool
    assert math.isnan(params["max_growth"]) and params["max_shrink"] == config.max_lookahead_shrink_m_per_m
    assert params["wheelbase"] == CAR.geometry.wheelbase_m and params["kdot_max"] == config.max_curvature_rate_1pm2
    assert math.isnan(params["dt"])  # the period is the run's
    controller.reset(STRAIGHT, 0.02)
    assert controller._params[0]["dt"] == 0.02


def test_the_state_starts_empty_with_both_trackers_at_the_paths_start() -> None:
    state = sk.initial_state()[0]
    assert state["need"] == 0 and math.isnan(state["kappa_cmd"]) and math.isnan(state["searched"])
    assert np.isnan(state["floors"]).all() and np.isnan(state["filters"]).all()
    for tracker in ("tracker", "here"):
        assert state[tracker][TRACK_S] == 0.0 and state[tracker][TRACK_PROGRESS] == 0.0
        assert np.isnan(state[tracker][2:]).all()


def test_a_reset_starts_the_state_again() -> None:
    controller = ClothoidController(CAR.geometry, ClothoidConfig())
    controller.reset(STRAIGHT, 0.02)
    controller.step(Measurement(0.0, 5.0, 0.2, 8.0, 0.0, 0.0, 0.0, 0.0), STRAIGHT)
    stepped = controller._state[0]
    assert stepped["lookahead"][1] >= 5.0 and not math.isnan(stepped["kappa_cmd"]) and stepped["tracker"][TRACK_S] > 0.0
    controller.reset(STRAIGHT, 0.02)
    assert controller._state.tobytes() == sk.initial_state().tobytes()
