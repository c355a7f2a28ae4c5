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
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from workbench.errors import WorkbenchInputError, value_text
from workbench.input_files import read_toml
from workbench.typed_tables import field_types, typed_value


def build_config(
    config_type: type,
    values: Mapping[str, Any] | None = None,
    overrides: Iterable[str] = (),
    base_dir: Path | None = None,
) -> Any:
    """An instance of `config_type` from `values` (a TOML table) and `key=value` overrides; its defaults otherwise."""
    fields = field_types(config_type)
    merged: dict[str, Any] = {}
    items = list((values or {}).items())
    for override in overrides:
        key, sep, text = override.partition("=")
        if not sep:
            raise WorkbenchInputError(f"an option override must look like key=value; got {override!r}")
        items.append((key.strip(), text.strip()))
    for key, value in items:
        if key not in fields:
            raise WorkbenchInputError(
                f"unknown option {key!r} for {config_type.__name__}; allowed: {', '.join(fields)}"
            )
        merged[key] = typed_value(f"option {key!r}", value, fields[key], base_dir, from_text=True)
    return config_type(**merged)


def read_controller_config(
    path: str | Path | None, controller_name: str, config_type: type, overrides: Iterable[str] = ()
) -> Any:
    """The config of `controller_name` from the table of that name in the TOML file at `path` (None: no file),
    with `overrides` applied on top."""
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
        return build_config(config_type, table, overrides, base_dir)
    except WorkbenchInputError as exc:
        where = f"controller config file {str(path)!r}, [{controller_name}]: " if path is not None else ""
        raise WorkbenchInputError(f"{where}{exc}") from None


def config_template(controller_name: str, config_type: type) -> str:
    """A TOML table of the controller's options at their defaults, to copy and edit (`workbench controllers
    --show NAME`). Options whose default is None are written commented out."""
    defaults = config_type()
    lines = [f"# {config_type.__name__}: options and defaults; see its docstring for units and meaning.", ""]
    lines.append(f"[{controller_name}]")
    for f in dataclasses.fields(config_type):
        if not f.init:
            continue
        value = getattr(defaults, f.name)
        if value is None:
            lines.append(f'# {f.name} = "..."')
        elif isinstance(value, bool):
            lines.append(f"{f.name} = {'true' if value else 'false'}")
        elif isinstance(value, str | Path):
            lines.append(f'{f.name} = "{value}"')
        else:
            lines.append(f"{f.name} = {value_text(value)}")
    return "\n".join(lines) + "\n"
