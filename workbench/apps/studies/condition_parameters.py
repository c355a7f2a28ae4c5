"""The conditions of a study's runs as run parameters: `conditions` (a preset name or a conditions TOML file) and
each scalar field of its tables, named `<table>_<field>` (`actuation_dead_time_s`, `localisation_position_noise_m`,
`road_friction_scale`, ...), set on top of the named conditions, so that grids and draws can sweep them."""

from __future__ import annotations

import dataclasses
import os
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from workbench.base.typed_tables import unwrap
from workbench.simulation.conditions import CONDITIONS, Conditions, load_conditions

#: The tables of a Conditions whose scalar fields are run parameters.
TABLES = ("localisation", "inertial", "steering_sensor", "actuation", "road")


def _scalar_fields() -> dict[str, tuple[str, str, Any]]:
    """`<table>_<field>` -> (table, field, type) for every field of a number or an optional number."""
    hints = typing.get_type_hints(Conditions)
    out = {}
    for table in TABLES:
        cls = hints[table]
        for f in dataclasses.fields(cls):
            annotation = typing.get_type_hints(cls)[f.name]
            if unwrap(annotation)[0] in (float, int):
                out[f"{table}_{f.name}"] = (table, f.name, annotation)
    return out


#: Every scalar condition field as a run parameter: name -> (table, field, type).
CONDITION_FIELDS: dict[str, tuple[str, str, Any]] = _scalar_fields()
#: The condition run parameters and their types (`conditions` is a preset name or a path).
CONDITION_PARAMETERS: dict[str, Any] = {"conditions": str, **{k: t for k, (_, _, t) in CONDITION_FIELDS.items()}}


def resolve_conditions(value: str, base_dir: Path) -> str:
    """A `conditions` value as a run keeps it: a preset name, or the absolute path of a conditions file (relative to
    base_dir), read once here so that a file no run can use is refused before any run.

    Parameters
    ----------
    value : str
        A conditions preset's name or a conditions TOML file.
    base_dir : pathlib.Path
        The folder a relative file is taken from (the spec's).

    Returns
    -------
    str
        The preset's name, or the file's absolute path.

    Raises
    ------
    WorkbenchInputError
        An unknown preset, a missing file, or a file the conditions refuse.
    """
    if value in CONDITIONS:
        return value
    path = Path(value)
    path = path if path.is_absolute() else base_dir / path
    if not os.path.lexists(path):
        load_conditions(value)  # refuses an unknown preset or a missing file, named as given
    load_conditions(str(path))  # as `workbench run --conditions` reads it
    return str(path.resolve())


def run_conditions(name: str | None, fields: Mapping[str, Any]) -> Conditions:
    """The conditions of a run: the preset or file `name` (None: ideal), its fields set from `fields` (names of
    CONDITION_FIELDS); named "<name>+" when a field changed it, so reports tell them apart.

    Parameters
    ----------
    name : str or None
        A conditions preset or file (None: ideal).
    fields : mapping
        `CONDITION_FIELDS` name -> value, set over the named conditions.

    Returns
    -------
    Conditions
        The run's conditions.

    Raises
    ------
    WorkbenchInputError
        An unknown preset, a file it cannot read, or a field value the conditions refuse.

    Examples
    --------
    >>> from workbench.apps.studies.condition_parameters import run_conditions
    >>> conditions = run_conditions("automotive", {"actuation_dead_time_s": 0.2})
    >>> conditions.name, conditions.actuation.dead_time_s
    ('automotive+', 0.2)
    """
    conditions = load_conditions(name or "ideal")
    changes: dict[str, dict[str, Any]] = {}
    for key, value in fields.items():
        table, field_name, _ = CONDITION_FIELDS[key]
        changes.setdefault(table, {})[field_name] = value
    if not changes:
        return conditions
    tables = {t: dataclasses.replace(getattr(conditions, t), **c) for t, c in changes.items()}
    return dataclasses.replace(conditions, name=f"{conditions.name}+", **tables)
