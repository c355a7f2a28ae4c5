"""Controller.informed_config: what each built-in controller is told of the conditions' nominal delays
(KnownDelays), and that the controllers without delay compensation are told nothing."""

from __future__ import annotations

import dataclasses

import pytest

from controllers import CONTROLLERS
from controllers.base import Controller
from workbench.base.errors import WorkbenchInputError
from workbench.simulation.conditions import CONDITIONS, Actuation, Conditions, Inertial, Localisation
from workbench.simulation.known_delays import KnownDelays

AUTOMOTIVE = KnownDelays.from_conditions(CONDITIONS["automotive"])
#: Late pose and actuation, no pose noise: the MPCs' pose filter stays off.
LATE_ONLY = KnownDelays.from_conditions(
    Conditions(
        localisation=Localisation(latency_s=0.05),
        inertial=Inertial(latency_s=0.03),
        actuation=Actuation(dead_time_s=0.2),
    )
)


def _changed(before: object, after: object) -> dict[str, object]:
    return {
        f.name: getattr(after, f.name)
        for f in dataclasses.fields(after)
        if getattr(after, f.name) != getattr(before, f.name)
    }


@pytest.mark.parametrize("name", ["stanley", "pure-pursuit"])
def test_controllers_without_delay_compensation_are_told_nothing(name: str) -> None:
    cls = CONTROLLERS[name]
    config = cls.config_type()
    assert cls.informed_config(config, AUTOMOTIVE) is config
    assert cls.informed_config.__func__ is Controller.informed_config.__func__  # the base class's stated no-op


def test_the_clothoid_controller_is_told_the_loops_dead_time_and_the_yaw_rates_age() -> None:
    cls = CONTROLLERS["clothoid"]
    config = dataclasses.replace(cls.config_type(), frechet_threshold_m=0.3)
    told = cls.informed_config(config, AUTOMOTIVE)
    # pose latency 10 ms + actuation dead time 100 ms; the yaw rate 20 ms late, 10 ms older than the pose
    assert _changed(config, told) == {
        "known_delay_s": pytest.approx(0.11, abs=1e-12),
        "yaw_rate_age_s": pytest.approx(0.01, abs=1e-12),
    }
    assert told.frechet_threshold_m == 0.3
    untold = cls.informed_config(config, KnownDelays())
    assert (untold.known_delay_s, untold.yaw_rate_age_s) == (0.0, 0.0)
    # a yaw rate fresher than the pose is a negative age
    assert cls.informed_config(config, LATE_ONLY).yaw_rate_age_s == pytest.approx(-0.02, abs=1e-12)


def test_the_clothoid_controller_refuses_a_delay_its_config_cannot_predict_over() -> None:
    cls = CONTROLLERS["clothoid"]
    arc_start = dataclasses.replace(cls.config_type(), initial_curvature="command")
    with pytest.raises(WorkbenchInputError, match="known_delay_s"):
        cls.informed_config(arc_start, AUTOMOTIVE)


@pytest.mark.parametrize("name", ["nmpc", "lmpc"])
def test_an_mpc_under_a_noisy_pose_is_told_its_delays_and_filters_the_pose(name: str) -> None:
    from controllers.mpc.pose_filter import INFORMED_POSE_FILTER_CUTOFF_HZ

    cls = CONTROLLERS[name]
    config = cls.config_type()
    told = cls.informed_config(config, AUTOMOTIVE)
    assert _changed(config, told) == {
        "input_delay_s": 0.1,
        "measurement_latency_s": 0.010,
        "pose_filter_cutoff_hz": INFORMED_POSE_FILTER_CUTOFF_HZ,
        "yaw_rate_latency_s": 0.020,
    }
    assert INFORMED_POSE_FILTER_CUTOFF_HZ == 0.3  # the crossover benchmarks/conditions.py measured its goals with
    # a cutoff the config already has is kept
    own = dataclasses.replace(config, pose_filter_cutoff_hz=0.5)
    assert cls.informed_config(own, AUTOMOTIVE).pose_filter_cutoff_hz == 0.5


@pytest.mark.parametrize("name", ["nmpc", "lmpc"])
def test_an_mpc_with_an_exact_pose_keeps_its_pose_filter_off(name: str) -> None:
    cls = CONTROLLERS[name]
    config = cls.config_type()
    told = cls.informed_config(config, LATE_ONLY)
    assert _changed(config, told) == {"input_delay_s": 0.2, "measurement_latency_s": 0.05}
    assert told.pose_filter_cutoff_hz == 0.0 and told.yaw_rate_latency_s is None
    assert cls.informed_config(config, KnownDelays()) == config


def test_a_delay_beyond_an_mpc_options_range_is_refused_naming_the_option() -> None:
    cls = CONTROLLERS["lmpc"]
    with pytest.raises(WorkbenchInputError, match="input_delay_s"):
        cls.informed_config(cls.config_type(), KnownDelays(dead_time_s=1.5))
