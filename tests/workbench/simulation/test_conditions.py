"""Sensing and actuation conditions (issue 18): the presets, their TOML round trip, and the refusal of bad values
and files naming the field, the value and the allowed range."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.simulation.conditions import (
    CONDITIONS,
    ROAD_FRICTION_RANGE,
    Actuation,
    Conditions,
    Inertial,
    Localisation,
    Road,
    SteeringSensor,
    conditions_to_toml,
    load_conditions,
)


def _write(tmp_path: Path, text: str, name: str = "cond.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# --------------------------------------------------------------------------------------------------- presets
def test_the_presets_are_named_sourced_and_only_ideal_is_ideal() -> None:
    assert list(CONDITIONS) == ["ideal", "rtk", "automotive", "degraded"]
    for name, conditions in CONDITIONS.items():
        assert conditions.name == name
        assert len(conditions.source) > 40, name  # says where the values come from
        assert conditions.is_ideal == (name == "ideal"), name
    assert Conditions().is_ideal
    assert CONDITIONS["ideal"] == dataclasses.replace(Conditions(), name="ideal", source=CONDITIONS["ideal"].source)


def test_the_presets_values_are_the_documented_ones() -> None:
    rtk, auto, degraded = CONDITIONS["rtk"], CONDITIONS["automotive"], CONDITIONS["degraded"]
    assert rtk.localisation.position_noise_m == 0.01 and rtk.localisation.update_rate_hz == 100.0
    assert rtk.localisation.heading_noise_rad == pytest.approx(math.radians(0.1), rel=1e-12)
    assert rtk.actuation.is_ideal and rtk.road.is_ideal and rtk.steering_sensor.is_ideal
    assert auto.localisation == rtk.localisation
    assert auto.actuation.dead_time_s == 0.1 and auto.actuation.max_steer_wheel_rate_rad_s is None
    assert auto.steering_sensor.quantisation_rad == pytest.approx(math.radians(0.1), rel=1e-12)
    assert auto.road.is_ideal
    assert 0.5 <= degraded.localisation.position_drift_m <= 1.0
    assert degraded.localisation.position_drift_time_s >= 100.0
    assert 1.0 <= degraded.localisation.update_rate_hz <= 10.0
    assert degraded.localisation.latency_s == pytest.approx(0.1)
    assert degraded.road.friction_scale == 0.5


def test_the_friction_range_is_the_vehicles() -> None:
    from workbench.vehicles.base import ROAD_FRICTION_RANGE as VEHICLES_RANGE

    assert ROAD_FRICTION_RANGE == VEHICLES_RANGE


@pytest.mark.parametrize("name", list(CONDITIONS))
def test_a_preset_round_trips_through_its_toml(tmp_path: Path, name: str) -> None:
    text = conditions_to_toml(CONDITIONS[name])
    assert load_conditions(_write(tmp_path, text)) == CONDITIONS[name]
    assert load_conditions(name) is CONDITIONS[name]


def test_a_profile_and_awkward_text_round_trip(tmp_path: Path) -> None:
    conditions = Conditions(
        name='wet "patch" \\ é',
        source="line one\nline two\ttab \x7f \U0001f697 \\u0041",
        road=Road(friction_scale=0.8, friction_profile=((0.0, 1.0), (50.0, 0.5), (80.5, 1.25))),
        actuation=Actuation(dead_time_s=0.0137, max_steer_wheel_rate_rad_s=2.5),
        localisation=Localisation(update_rate_hz=7.3, latency_s=1 / 3),
    )
    assert load_conditions(_write(tmp_path, conditions_to_toml(conditions))) == conditions


def test_missing_tables_and_keys_keep_their_defaults(tmp_path: Path) -> None:
    path = _write(tmp_path, "[localisation]\nlatency_s = 0.05\nupdate_rate_hz = 10\n", "gnss.toml")
    conditions = load_conditions(path)
    assert conditions.name == "gnss"  # the file's stem without a name
    assert conditions.source == f"read from {path}"
    assert conditions.localisation == Localisation(latency_s=0.05, update_rate_hz=10.0)
    assert conditions.inertial == Inertial() and conditions.road == Road() and conditions.actuation == Actuation()
    assert load_conditions(_write(tmp_path, "")).is_ideal
    none_rate = load_conditions(_write(tmp_path, '[actuation]\nmax_steer_wheel_rate_rad_s = "none"\n'))
    assert none_rate.actuation.max_steer_wheel_rate_rad_s is None


# ------------------------------------------------------------------------------------------------- the road
def test_the_friction_profile_is_interpolated_along_the_path_and_held_beyond_its_ends() -> None:
    road = Road(friction_scale=0.8, friction_profile=((10.0, 1.0), (20.0, 0.5), (40.0, 1.0)))
    assert road.friction_at(0.0) == pytest.approx(0.8, abs=1e-15)
    assert road.friction_at(15.0) == pytest.approx(0.8 * 0.75, abs=1e-15)
    assert road.friction_at(20.0) == pytest.approx(0.4, abs=1e-15)
    assert road.friction_at(30.0) == pytest.approx(0.8 * 0.75, abs=1e-15)
    assert road.friction_at(1e6) == pytest.approx(0.8, abs=1e-15)
    assert not road.is_ideal and not road.is_constant
    assert Road().friction_at(12.0) == 1.0 and Road().is_constant
    flat = Road(friction_profile=((0.0, 1.0), (5.0, 1.0)))
    assert flat.is_ideal and flat.is_constant
    assert Road(friction_profile=[[0, 1], [5, 0.5]]).friction_profile == ((0.0, 1.0), (5.0, 0.5))


# ---------------------------------------------------------------------------------------------- bad values
@pytest.mark.parametrize(
    ("build", "words"),
    [
        (lambda: Localisation(position_noise_m=-0.1), ["localisation.position_noise_m", "[0, 100] m", "-0.1"]),
        (lambda: Localisation(position_noise_m=math.nan), ["localisation.position_noise_m", "finite", "nan"]),
        (lambda: Localisation(position_drift_time_s=0.0), ["position_drift_time_s", "[0.001, 1e+06] s"]),
        (lambda: Localisation(heading_noise_rad=math.inf), ["heading_noise_rad", "inf"]),
        (lambda: Localisation(update_rate_hz=0.0), ["update_rate_hz", "[0.001, 10000]", '"none"', "got 0.0"]),
        (lambda: Localisation(latency_s=5.0), ["localisation.latency_s", "[0, 2] s", "5.0"]),
        (lambda: Localisation(latency_s="0.1"), ["localisation.latency_s", "'0.1'"]),
        (lambda: Inertial(yaw_rate_noise_rad_s=-1e-3), ["inertial.yaw_rate_noise_rad_s", "[0, 1] rad/s"]),
        (lambda: Inertial(yaw_rate_bias_rad_s=2.0), ["inertial.yaw_rate_bias_rad_s", "[-1, 1] rad/s"]),
        (lambda: Inertial(speed_noise_mps=True), ["inertial.speed_noise_mps", "True"]),
        (lambda: SteeringSensor(quantisation_rad=-0.01), ["steering_sensor.quantisation_rad", "0: none"]),
        (lambda: Actuation(dead_time_s=-0.1), ["actuation.dead_time_s", "[0, 2] s", "-0.1"]),
        (lambda: Actuation(max_steer_wheel_rate_rad_s=0.0), ["max_steer_wheel_rate_rad_s", "[0.001, 100]"]),
        (lambda: Road(friction_scale=0.0), ["road.friction_scale", "[0.05, 1.5]", "0.0"]),
        (lambda: Road(friction_scale=math.nan), ["road.friction_scale", "nan"]),
        (lambda: Road(friction_profile=((0.0, 1.0),)), ["road.friction_profile", "at least 2"]),
        (lambda: Road(friction_profile=((0.0, 1.0), (0.0, 0.5))), ["distances must increase", "entry 1"]),
        (lambda: Road(friction_profile=((0.0, 1.0), (5.0, 2.0))), ["friction_profile[1] scale", "[0.05, 1.5]"]),
        (lambda: Road(friction_profile=((0.0, 1.0), (5.0,))), ["friction_profile[1]", "pair"]),
        (lambda: Road(friction_profile=((0.0, 1.0), (5.0, math.nan))), ["friction_profile[1] scale", "nan"]),
        (lambda: Road(0.2, ((0.0, 1.0), (5.0, 0.2))), ["friction_scale x road.friction_profile[1]", "0.04"]),
        (lambda: Conditions(name=""), ["name", "non-empty"]),
        (lambda: Conditions(road=Localisation()), ["road", "Road"]),
    ],
)
def test_bad_values_are_refused_naming_the_field_and_range(build, words: list[str]) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        build()
    for word in words:
        assert word in str(info.value), (word, str(info.value))


# ----------------------------------------------------------------------------------------------- bad files
@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("[localisation]\nposition_noise = 0.1\n", ["[localisation]", "unknown key 'position_noise'", "allowed keys"]),
        ("[gnss]\nlatency_s = 0.1\n", ["top level", "unknown key 'gnss'", "localisation"]),
        ("[localisation]\nlatency_s = nan\n", ["localisation.latency_s", "finite", "[0, 2] s", "nan"]),
        ("[road]\nfriction_scale = -inf\n", ["road.friction_scale", "finite", "[0.05, 1.5]", "-inf"]),
        ("[localisation]\nlatency_s = -0.1\n", ["localisation.latency_s", "[0, 2] s", "-0.1"]),
        ('[inertial]\nspeed_noise_mps = "0.1"\n', ["'speed_noise_mps'", "number", "'0.1'"]),
        ("[inertial]\nspeed_noise_mps = true\n", ["'speed_noise_mps'", "number", "True"]),
        ("[actuation]\ndead_time_s = [0.1]\n", ["'dead_time_s'", "number"]),
        ("localisation = 3\n", ["[localisation] must be a table", "3"]),
        ("name = 3\n", ["'name'", "text"]),
        ("[road]\nfriction_profile = [[0.0, 1.0], [10.0, 0.1], [5.0, 1.0]]\n", ["distances must increase"]),
        ('[road]\nfriction_profile = "wet"\n', ["friction_profile", "pairs", "'wet'"]),
        ("[road]\nfriction_profile = [[0.0, 1.0], [10.0, true]]\n", ["friction_profile[1] scale", "True"]),
        ("[road]\nfriction_scale = 3.0\n", ["road.friction_scale", "[0.05, 1.5]", "3.0"]),
        ("[localisation\n", ["not valid TOML"]),
    ],
)
def test_bad_files_are_refused_naming_the_file_and_key(tmp_path: Path, text: str, words: list[str]) -> None:
    path = _write(tmp_path, text)
    with pytest.raises(WorkbenchInputError) as info:
        load_conditions(path)
    message = str(info.value)
    assert message.startswith(f"conditions file {str(path)!r}"), message
    for word in words:
        assert word in message, (word, message)


def test_an_unknown_name_lists_the_presets_and_the_file_form(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        load_conditions("rainy")
    message = str(info.value)
    assert "'rainy'" in message and ".toml" in message
    for name in CONDITIONS:
        assert name in message
    with pytest.raises(WorkbenchInputError, match="no such file"):
        load_conditions(str(tmp_path / "missing.toml"))
    with pytest.raises(WorkbenchInputError, match="a folder"):
        load_conditions(str(tmp_path))


def test_the_description_names_what_changes() -> None:
    assert "ideal" in CONDITIONS["ideal"].describe()
    text = CONDITIONS["degraded"].describe()
    for word in ("5 Hz", "latency 100 ms", "dead time 100 ms", "friction x 0.5"):
        assert word in text, (word, text)
