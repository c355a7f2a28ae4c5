"""Vehicle presets: shipped TOML files, user copies, bad files, payload override, the registry."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

from workbench.base.errors import WorkbenchInputError
from workbench.vehicles import VEHICLES, list_presets, load_vehicle, make_vehicle, preset_text
from workbench.vehicles.presets import MODEL_TYPES

NAMES = ("kinematic-bicycle", "dynamic-bicycle", "tractor-semitrailer", "commonroad-mb")


def test_every_model_has_a_preset_and_a_registry_entry() -> None:
    assert set(NAMES) <= set(list_presets())
    assert set(NAMES) == set(VEHICLES)
    for name in NAMES:
        assert VEHICLES[name]().name == name


@pytest.mark.parametrize("name", NAMES)
def test_presets_load_and_equal_the_documented_defaults(name: str) -> None:
    vehicle = make_vehicle(name)
    assert vehicle.name == name
    assert vehicle.params == MODEL_TYPES[name][1]()  # the TOML and the dataclass defaults say the same
    assert load_vehicle(name).params == vehicle.params


@pytest.mark.parametrize("name", NAMES)
def test_every_preset_value_cites_a_source(name: str) -> None:
    in_parameters = False
    for line in preset_text(name).splitlines():
        if line.startswith("["):
            in_parameters = line.strip() == "[parameters]"
        elif in_parameters and "=" in line and not line.lstrip().startswith("#"):
            value, _, comment = line.partition("#")
            assert comment.strip(), f"{name}: no source for {value.strip()!r}"
            assert re.search(r"assumed|CommonRoad|\b[ABCD]\b", comment), f"{name}: {line!r}"


def _user_copy(tmp_path: Path, name: str, old: str, new: str) -> Path:
    text = preset_text(name)
    assert old in text
    path = tmp_path / f"my-{name}.toml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


def test_a_user_copy_with_one_edited_value_loads_and_the_value_takes_effect(tmp_path: Path) -> None:
    path = _user_copy(tmp_path, "tractor-semitrailer", "steering_ratio = 22.0", "steering_ratio = 18")
    truck = make_vehicle(vehicle_file=path)
    assert truck.geometry.steering_ratio == 18.0
    assert isinstance(truck.params.steering_ratio, float)
    assert make_vehicle("tractor-semitrailer", vehicle_file=str(path)).geometry.steering_ratio == 18.0
    car = make_vehicle(vehicle_file=_user_copy(tmp_path, "dynamic-bicycle", "mass_kg = 1093.3", "mass_kg = 1500.0"))
    assert car.params.mass_kg == 1500.0


def test_a_typo_in_a_key_is_rejected_naming_the_key_the_file_and_the_allowed_keys(tmp_path: Path) -> None:
    path = _user_copy(tmp_path, "tractor-semitrailer", "payload_kg =", "payload_kgs =")
    with pytest.raises(WorkbenchInputError, match="\\[parameters\\]: unknown key 'payload_kgs'") as info:
        make_vehicle(vehicle_file=path)
    assert str(path) in str(info.value) and "payload_kg, payload_cg_from_hitch_m" in str(info.value)


def test_a_missing_key_is_rejected_naming_it(tmp_path: Path) -> None:
    path = _user_copy(tmp_path, "kinematic-bicycle", "width_m = 1.61", "")
    with pytest.raises(WorkbenchInputError, match=f"{re.escape(str(path))}: \\[parameters\\]: missing key 'width_m'"):
        load_vehicle(str(path))


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("wheelbase_m = 2.579", "wheelbase_m = 0.0", r"wheelbase_m must be a finite number in \[0.5, 15\] m; got 0.0"),
        ("wheelbase_m = 2.579", 'wheelbase_m = "long"', "\\[parameters\\]: 'wheelbase_m' must be a number; got 'long'"),
        ("wheelbase_m = 2.579", "wheelbase_m = true", "\\[parameters\\]: 'wheelbase_m' must be a number; got True"),
        ('type = "kinematic-bicycle"', 'type = "bicycle"', "type must be one of kinematic-bicycle"),
        ('type = "kinematic-bicycle"', 'kind = "kinematic-bicycle"', "\\[model\\]: unknown key 'kind'"),
        ("[parameters]", "[params]", "top level: unknown key 'params', missing key 'parameters'"),
        ("wheelbase_m = 2.579", "wheelbase_m = = 2", "not valid TOML"),
    ],
)
def test_bad_files_are_rejected_naming_the_file(tmp_path: Path, old: str, new: str, message: str) -> None:
    path = _user_copy(tmp_path, "kinematic-bicycle", old, new)
    with pytest.raises(WorkbenchInputError, match=message) as info:
        make_vehicle(vehicle_file=path)
    assert str(path) in str(info.value)


def test_unknown_names_and_missing_files_are_rejected(tmp_path: Path) -> None:
    with pytest.raises(WorkbenchInputError, match="unknown vehicle 'truck'; choose one of kinematic-bicycle"):
        make_vehicle("truck")
    with pytest.raises(WorkbenchInputError, match="neither a preset"):
        make_vehicle(vehicle_file=tmp_path / "nope.toml")
    with pytest.raises(WorkbenchInputError, match="describes a 'kinematic-bicycle'"):
        make_vehicle("tractor-semitrailer", vehicle_file=_user_copy(tmp_path, "kinematic-bicycle", "", ""))


def test_payload_overrides_the_truck_preset_and_is_refused_by_cars(tmp_path: Path) -> None:
    empty = make_vehicle("tractor-semitrailer", payload_kg=0.0)
    loaded = make_vehicle("tractor-semitrailer")
    assert empty.params.payload_kg == 0.0
    assert loaded.derived.m2 - empty.derived.m2 == pytest.approx(17000.0)
    path = _user_copy(tmp_path, "tractor-semitrailer", "payload_kg = 17000.0", "payload_kg = 5000.0")
    assert make_vehicle(vehicle_file=path, payload_kg=9000).params.payload_kg == 9000.0
    with pytest.raises(WorkbenchInputError, match=r"payload_kg must be a finite number in \[0, 40000\] kg; got -5.0"):
        make_vehicle("tractor-semitrailer", payload_kg=-5.0)
    for name in ("kinematic-bicycle", "dynamic-bicycle", "commonroad-mb"):
        with pytest.raises(WorkbenchInputError, match="has no payload; a payload applies to: tractor-semitrailer"):
            make_vehicle(name, payload_kg=1000.0)


def test_params_are_frozen() -> None:
    truck = make_vehicle("tractor-semitrailer")
    with pytest.raises(dataclasses.FrozenInstanceError):
        truck.params.payload_kg = 0.0  # type: ignore[misc]
