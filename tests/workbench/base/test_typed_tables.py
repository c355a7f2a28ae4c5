"""Tests for workbench.base.typed_tables: the one typed loader behind controller configs, vehicle presets, lead-filter
files and study specs."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from workbench.base.errors import WorkbenchInputError
from workbench.base.typed_tables import check_keys, dataclass_from_table, type_name, typed_value

QUOTED = " (a file's numbers and booleans are written without quotes)"


@dataclass(frozen=True)
class _Options:
    gain: float = 1.0
    steps: int = 3
    on: bool = True
    name: str = "a"
    table: Path | None = None


@pytest.mark.parametrize(
    ("value", "annotation", "expected"),
    [(2, float, 2.0), (2.5, float, 2.5), (3, int, 3), (False, bool, False), ("x", str, "x"), (None, Path | None, None)],
)
def test_values_of_the_right_type_are_taken(value: object, annotation: object, expected: object) -> None:
    result = typed_value("k", value, annotation)
    assert result == expected and type(result) is type(expected)


@pytest.mark.parametrize(
    ("value", "annotation", "message"),
    [
        ("0.5", float, f"k must be a number; got '0.5'{QUOTED}"),  # text only from a command line
        ("7", int, f"k must be a whole number; got '7'{QUOTED}"),
        ("false", bool, f"k must be a boolean; got 'false'{QUOTED}"),
        ("maybe", bool, "k must be a boolean; got 'maybe'"),  # no hint where the text is no boolean either
        (True, float, "k must be a number; got True"),
        (2.0, int, "k must be a whole number; got 2.0"),
        (1, bool, "k must be a boolean; got 1"),
        (3, str, "k must be a text; got 3"),
        (math.nan, float, "k must be a finite number; got nan"),
        (np.float64(math.inf), float, "k must be a finite number; got inf"),
        ("", Path, "k must be a file path; got ''"),
        (5, Path | None, 'k must be a file path or "none"; got 5'),
    ],
)
def test_values_of_another_type_are_refused_naming_key_value_and_type(
    value: object, annotation: object, message: str
) -> None:
    with pytest.raises(WorkbenchInputError) as info:
        typed_value("k", value, annotation)
    assert str(info.value) == message


@pytest.mark.parametrize(
    ("text", "annotation", "expected"),
    [("0.5", float, 0.5), ("7", int, 7), ("off", bool, False), ("YES", bool, True), ("none", Path | None, None)],
)
def test_text_from_a_command_line_is_parsed(text: str, annotation: object, expected: object) -> None:
    assert typed_value("k", text, annotation, from_text=True) == expected


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_a_finite_float_written_as_text_comes_back_exactly(x: float) -> None:
    assert typed_value("k", repr(x), float, from_text=True) == x


def test_relative_paths_are_taken_from_the_base_folder(tmp_path: Path) -> None:
    assert typed_value("k", "lead.json", Path, base_dir=tmp_path) == tmp_path / "lead.json"
    assert typed_value("k", "/abs/lead.json", Path, base_dir=tmp_path) == Path("/abs/lead.json")


def test_check_keys_names_unknown_and_missing_keys_and_the_allowed_ones() -> None:
    assert check_keys("t", {"a": 1}, ("a", "b")) == {"a": 1}
    with pytest.raises(WorkbenchInputError, match=r"^t: unknown key 'c', missing key 'b'; allowed keys: a, b$"):
        check_keys("t", {"a": 1, "c": 2}, ("a", "b"), required=("b",))
    with pytest.raises(WorkbenchInputError, match=r"^t must be a table; got \[1\]$"):
        check_keys("t", [1], ("a",))


def test_a_dataclass_from_a_table_uses_its_defaults_and_its_field_types(tmp_path: Path) -> None:
    options = dataclass_from_table(_Options, {"gain": 2, "table": "f.csv"}, "opts", base_dir=tmp_path)
    assert options == _Options(gain=2.0, table=tmp_path / "f.csv")
    with pytest.raises(WorkbenchInputError, match=r"^opts: 'steps' must be a whole number; got 1\.5$"):
        dataclass_from_table(_Options, {"steps": 1.5}, "opts")
    with pytest.raises(WorkbenchInputError, match=r"^opts: missing key 'gain'"):
        dataclass_from_table(_Options, {}, "opts", required=True)
    assert type_name(Path | None) == 'file path or "none"'


def test_every_toml_loader_takes_a_files_values_as_typed(tmp_path: Path) -> None:
    """Vehicle and conditions files refuse a quoted number as controller configs and study specs do
    (tests/workbench/apps/test_controller_config.py)."""
    from workbench.simulation.conditions import conditions_to_toml, load_conditions
    from workbench.vehicles.presets import load_vehicle, preset_text

    vehicle = tmp_path / "car.toml"
    vehicle.write_text(preset_text("kinematic-bicycle").replace("width_m = 1.61 ", 'width_m = "1.61" '))
    with pytest.raises(WorkbenchInputError, match=r"\[parameters\]: 'width_m' must be a number; got '1\.61'"):
        load_vehicle(str(vehicle))
    conditions = tmp_path / "conditions.toml"
    text = conditions_to_toml(load_conditions("automotive"))
    conditions.write_text(text.replace("friction_scale = 1.0", 'friction_scale = "1.0"'))
    with pytest.raises(WorkbenchInputError, match=r"\[road\]: 'friction_scale' must be a number; got '1\.0'"):
        load_conditions(conditions)
