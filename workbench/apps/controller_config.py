"""Controller options from a TOML file and `key=value` overrides, checked against the controller's config dataclass.

A config file holds one table per controller name, so one file can configure several controllers:

    [clothoid]
    lookahead_mode = "adaptive"
    frechet_threshold_m = 0.5
    filter_file = "lead.json"      # relative paths are taken relative to the config file

    [pure-pursuit]
    lookahead_gain_s = 0.8

Overrides (`--set frechet_threshold_m=0.3` on the command line) apply on top. Keys are the config dataclass's field
names; a key that is not one, or a value of the wrong type, is an error that lists what is allowed. Fields may be
float, int, bool, str, Path or `Path | None` (written "none" to clear).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.input_files import read_toml
from workbench.base.typed_tables import field_types, typed_value

if TYPE_CHECKING:
    from workbench.vehicles.geometry import VehicleGeometry


@dataclass(frozen=True)
class FileOption:
    """An option a config file or `--set` gives as a file (`filter_file = "lead.json"`), read here, at the
    boundary, into the config field that holds the object: configs hold objects, controllers read no files.

    field: the config field; read(path, geometry): the reader (geometry: the steered vehicle's, or None)."""

    field: str
    read: Callable[[Path, VehicleGeometry | None], Any]


def _lead_filter(path: Path, _geometry: VehicleGeometry | None) -> Any:
    from tuning.filter_file import read_filter_file

    return read_filter_file(path)


def _curvature_limits(path: Path, geometry: VehicleGeometry | None) -> Any:
    from tuning.limits_file import read_limits_file

    return read_limits_file(path, geometry)


def _tuning(path: Path, _geometry: VehicleGeometry | None) -> Any:
    from tuning.tuning_dirs import read_vehicle_tuning

    return read_vehicle_tuning(path)


def _lag(path: Path, _geometry: VehicleGeometry | None) -> Any:
    from workbench.vehicles.steering_lag import read_lag_file

    return read_lag_file(path)


def _prediction_vehicle(path: Path, _geometry: VehicleGeometry | None) -> Any:
    from workbench.vehicles import load_vehicle

    return load_vehicle(str(path)).single_track(f"vehicle {str(path)!r}")


#: The file options, by the name a config file or `--set` uses.
FILE_OPTIONS: dict[str, FileOption] = {
    "tuning_dir": FileOption("tuning", _tuning),
    "filter_file": FileOption("lead_filter", _lead_filter),
    "limits_file": FileOption("curvature_limits", _curvature_limits),
    "lag_file": FileOption("lag", _lag),
    "vehicle_file": FileOption("prediction_vehicle", _prediction_vehicle),
}


def option_types(config_type: type) -> dict[str, Any]:
    """The options a config file or `--set` may give for `config_type`, with their types: its fields, with each
    field that holds an object read from a file named by its file option instead (`filter_file: Path | None`)."""
    by_field = {option.field: name for name, option in FILE_OPTIONS.items()}
    return {
        by_field.get(name, name): (Path | None if name in by_field else t)
        for name, t in field_types(config_type).items()
    }


def build_config(
    config_type: type,
    values: Mapping[str, Any] | None = None,
    overrides: Iterable[str] = (),
    base_dir: Path | None = None,
    geometry: VehicleGeometry | None = None,
) -> Any:
    """An instance of `config_type` from `values` (a TOML table) and `key=value` overrides; its defaults otherwise.
    File options are read into their objects here (`FILE_OPTIONS`; `geometry`: the steered vehicle's, which a
    limits file without a rate column needs)."""
    types = option_types(config_type)
    merged: dict[str, Any] = {}
    items = list((values or {}).items())
    for override in overrides:
        key, sep, text = override.partition("=")
        if not sep:
            raise WorkbenchInputError(f"an option override must look like key=value; got {override!r}")
        items.append((key.strip(), text.strip()))
    for key, value in items:
        if key not in types:
            raise WorkbenchInputError(f"unknown option {key!r} for {config_type.__name__}; allowed: {', '.join(types)}")
        typed = typed_value(f"option {key!r}", value, types[key], base_dir, from_text=True)
        option = FILE_OPTIONS.get(key)
        if option is not None:
            merged[option.field] = None if typed is None else option.read(typed, geometry)
        else:
            merged[key] = typed
    return config_type(**merged)


def read_controller_config(
    path: str | Path | None,
    controller_name: str,
    config_type: type,
    overrides: Iterable[str] = (),
    geometry: VehicleGeometry | None = None,
) -> Any:
    """The config of `controller_name` from the table of that name in the TOML file at `path` (None: no file),
    with `overrides` applied on top; file options read into objects (`build_config`)."""
    table: Mapping[str, Any] = {}
    base_dir = None
    if path is not None:
        path = Path(path)
        document = read_toml(path, f"controller config file {str(path)!r}")
        table = document.get(controller_name, {})
        if not isinstance(table, dict):
            raise WorkbenchInputError(
                f"controller config file {str(path)!r}: [{controller_name}] must be a table; got {table!r}"
            )
        base_dir = path.resolve().parent
    try:
        return build_config(config_type, table, overrides, base_dir, geometry)
    except WorkbenchInputError as exc:
        where = f"controller config file {str(path)!r}, [{controller_name}]: " if path is not None else ""
        raise WorkbenchInputError(f"{where}{exc}") from None


def config_template(controller_name: str, config_type: type) -> str:
    """A TOML table of the controller's options at their defaults, to copy and edit (`workbench controllers
    --show NAME`). Options whose default is None are written commented out."""
    defaults = config_type()
    lines = [f"# {config_type.__name__}: options and defaults; see its docstring for units and meaning.", ""]
    lines.append(f"[{controller_name}]")
    by_field = {option.field: name for name, option in FILE_OPTIONS.items()}
    for f in dataclasses.fields(config_type):
        if not f.init:
            continue
        value = getattr(defaults, f.name)
        if f.name in by_field:
            lines.append(f'# {by_field[f.name]} = "..."')
        elif value is None:
            lines.append(f'# {f.name} = "..."')
        elif isinstance(value, bool):
            lines.append(f"{f.name} = {'true' if value else 'false'}")
        elif isinstance(value, str | Path):
            lines.append(f'{f.name} = "{value}"')
        else:
            lines.append(f"{f.name} = {value_text(value)}")
    return "\n".join(lines) + "\n"
