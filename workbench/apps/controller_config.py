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
float, int, bool, str, Path or `Path | None` (written "none" to clear). A file's values are TOML values, taken as they
are (`0.3`, `false`; the text `"0.3"` is refused); only override text is parsed.

A file holds tables only, each named by a registered controller: a key outside any table, or a table that names no
controller (`[stanly]`), is refused, so that options meant for a controller are never dropped unread. Tables of
other controllers are allowed (one file for several controllers); a file without the chosen controller's table is
read as its defaults, with a warning naming the tables it has (`missing_table_warning`).
"""

from __future__ import annotations

import dataclasses
import difflib
import textwrap
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.input_files import read_toml
from workbench.base.toml_text import toml_value
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
    field that holds an object read from a file named by its file option instead (`filter_file: Path | None`).

    Parameters
    ----------
    config_type : type
        A controller's config dataclass (e.g. `StanleyConfig`).

    Returns
    -------
    dict
        Option name -> its type annotation, in the config's field order.
    """
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
    """An instance of `config_type` from `values` (a TOML table, its values typed as they are) and `key=value`
    overrides (text, parsed as each option's type); its defaults otherwise. File options are read into their
    objects here (`FILE_OPTIONS`; `geometry`: the steered vehicle's, which a limits file without a rate column
    needs).

    Parameters
    ----------
    config_type : type
        A controller's config dataclass (e.g. `StanleyConfig`).
    values : mapping or None
        Option -> value, as a TOML table holds them (None: none).
    overrides : iterable of str
        ``key=value`` texts over `values`, each parsed as its option's type.
    base_dir : pathlib.Path or None
        The folder relative file paths are taken from (None: the working directory).
    geometry : VehicleGeometry or None
        The steered vehicle's geometry, which a limits file without a rate column needs (None: none).

    Returns
    -------
    object
        The config, checked by its own validation.

    Raises
    ------
    WorkbenchInputError
        An unknown option, a malformed override, a value of the wrong type or out of its range, or a file that
        cannot be read.

    Examples
    --------
    >>> from controllers.stanley import StanleyConfig
    >>> from workbench.apps.controller_config import build_config
    >>> build_config(StanleyConfig, overrides=["gain_per_s=2.5"]).gain_per_s
    2.5
    """
    types = option_types(config_type)
    merged: dict[str, Any] = {}
    items = [(key, value, False) for key, value in (values or {}).items()]  # TOML values: typed as they are
    for override in overrides:
        key, sep, text = override.partition("=")
        if not sep:
            raise WorkbenchInputError(f"an option override must look like key=value; got {override!r}")
        items.append((key.strip(), text.strip(), True))  # text: parsed
    for key, value, is_text in items:
        if key not in types:
            raise WorkbenchInputError(f"unknown option {key!r} for {config_type.__name__}; allowed: {', '.join(types)}")
        typed = typed_value(f"option {key!r}", value, types[key], base_dir, from_text=is_text)
        option = FILE_OPTIONS.get(key)
        if option is not None:
            merged[option.field] = None if typed is None else option.read(typed, geometry)
        else:
            merged[key] = typed
    return config_type(**merged)


def read_config_tables(path: str | Path) -> dict[str, dict[str, Any]]:
    """The tables of the controller-config file at `path`, by controller name. Refused (WorkbenchInputError naming
    the file): a key outside any table, and a table whose name is no registered controller (the close one
    suggested), so that no option in the file goes unread.

    Parameters
    ----------
    path : str or pathlib.Path
        A controller-config TOML file.

    Returns
    -------
    dict
        Controller name -> its table.

    Raises
    ------
    WorkbenchInputError
        The file is missing or not TOML, a key is outside any table, or a table names no registered controller.
    """
    from controllers import CONTROLLERS

    what = f"controller config file {str(path)!r}"
    document = read_toml(path, what)
    loose = [f"{key} = {value_text(value)}" for key, value in document.items() if not isinstance(value, dict)]
    if loose:
        raise WorkbenchInputError(
            f"{what}: {'; '.join(loose)} {'is' if len(loose) == 1 else 'are'} outside any table; options go in their "
            f"controller's table, [NAME] with NAME one of {', '.join(CONTROLLERS)}"
        )
    for name in document:
        if name not in CONTROLLERS:
            raise WorkbenchInputError(f"{what}: [{name}] names no controller; {_suggestion(name, CONTROLLERS)}")
    return document


def _suggestion(name: str, names: Iterable[str]) -> str:
    """"did you mean [x]? " (the closest of `names`, case aside) and the list of `names`."""
    names = list(names)
    by_lower = {n.lower(): n for n in names}
    close = difflib.get_close_matches(name.lower(), list(by_lower), n=1)
    hint = f"did you mean [{by_lower[close[0]]}]? " if close else ""
    return f"{hint}the tables a file may hold: {', '.join(f'[{n}]' for n in names)}"


def missing_table_warning(path: str | Path, controller_name: str) -> str | None:
    """A warning when the controller-config file at `path` has no table for `controller_name` (which then runs
    with its defaults), naming the tables it has; None when it has one. The file is read and checked as
    `read_config_tables` does.

    Parameters
    ----------
    path : str or pathlib.Path
        A controller-config TOML file.
    controller_name : str
        The controller the file is given for.

    Returns
    -------
    str or None
        The warning, or None when the file has the table.

    Raises
    ------
    WorkbenchInputError
        As `read_config_tables`.
    """
    return _missing_table_text(path, controller_name, read_config_tables(path))


def _missing_table_text(path: str | Path, controller_name: str, tables: Mapping[str, Any]) -> str | None:
    if controller_name in tables:
        return None
    has = f"only {', '.join(f'[{n}]' for n in tables)}" if tables else "no tables"
    return (
        f"controller config file {str(path)!r} has no [{controller_name}] table ({has}): {controller_name} runs "
        "with its default options"
    )


def read_controller_config(
    path: str | Path | None,
    controller_name: str,
    config_type: type,
    overrides: Iterable[str] = (),
    geometry: VehicleGeometry | None = None,
    warn: Callable[[str], None] | None = None,
) -> Any:
    """The config of `controller_name` from the table of that name in the TOML file at `path` (None: no file),
    with `overrides` applied on top; file options read into objects (`build_config`). The file is checked as
    `read_config_tables` does; `warn` (None: silent) is told when it has no table for the controller
    (`missing_table_warning`).

    Parameters
    ----------
    path : str or pathlib.Path or None
        A controller-config TOML file (None: none, the defaults and overrides only).
    controller_name : str
        The registered controller whose table is read.
    config_type : type
        A controller's config dataclass (e.g. `StanleyConfig`).
    overrides : iterable of str
        ``key=value`` texts (`--set`) over the file's table.
    geometry : VehicleGeometry or None
        The steered vehicle's geometry, which a limits file without a rate column needs (None: none).
    warn : callable or None
        Called with the warning when the file has no table for the controller (None: silent).

    Returns
    -------
    object
        The controller's config.

    Raises
    ------
    WorkbenchInputError
        As `read_config_tables` and `build_config`, the message naming the file and the table.
    """
    table: Mapping[str, Any] = {}
    base_dir = None
    if path is not None:
        path = Path(path)
        tables = read_config_tables(path)
        table = tables.get(controller_name, {})
        warning = _missing_table_text(path, controller_name, tables)
        if warning is not None and warn is not None:
            warn(warning)
        base_dir = path.resolve().parent
    try:
        return build_config(config_type, table, overrides, base_dir, geometry)
    except WorkbenchInputError as exc:
        where = f"controller config file {str(path)!r}, [{controller_name}]: " if path is not None else ""
        raise WorkbenchInputError(f"{where}{exc}") from None


#: The width of the template's comment lines (characters).
TEMPLATE_WIDTH = 116


def config_template(controller_name: str, config_type: type) -> str:
    """A TOML table of the controller's options at their defaults, to copy and edit (`workbench controllers
    --show NAME`). Above each option, as comments, what it does, its unit, its default and what it allows, from its
    field's metadata (`controllers.config_checks.option`: the rule its config's validation checks); a field without
    that metadata is listed undocumented. Options whose default is an object read from a file are written commented
    out; the text reads back (`read_controller_config`) to the defaults.

    Parameters
    ----------
    controller_name : str
        The table's name.
    config_type : type
        A controller's config dataclass (e.g. `StanleyConfig`).

    Returns
    -------
    str
        The TOML text, lines of at most TEMPLATE_WIDTH characters in its comments.
    """
    defaults = config_type()
    by_field = {option.field: name for name, option in FILE_OPTIONS.items()}
    lines = [
        f"# {controller_name}: {config_type.__name__}, every option at its default. Above each: what it does, its unit",
        '# ("-": none), its default and the values allowed. Copy, edit and pass it with --controller-config.',
        "",
        f"[{controller_name}]",
    ]
    for f in dataclasses.fields(config_type):
        if not f.init:
            continue
        value = getattr(defaults, f.name)
        lines += ["", *_option_comment(f, value, by_field.get(f.name))]
        if f.name in by_field:
            lines.append(f'# {by_field[f.name]} = "..."')
        else:
            lines.append(f"{f.name} = {toml_value(value)}")
    return "\n".join(lines) + "\n"


def _option_comment(f: dataclasses.Field[Any], default: Any, file_option: str | None) -> list[str]:
    """The comment lines above option `f` in a template: its meaning, then unit, default and allowed values."""
    from controllers.config_checks import option_rule

    rule, doc = option_rule(f), f.metadata.get("doc")
    if rule is None or doc is None:
        return [f"# {f.name}: undocumented (its config field has no `option` metadata)"]
    if file_option is not None:  # the option names a file its config field's object is read from
        none_means = getattr(rule, "none_means", None) or "none"
        default_text = f'"none" ({none_means})' if default is None else "given"
        allowed, name = 'a file path, or "none"', file_option
    else:
        default_text, allowed, name = toml_value(default), rule.allowed(), f.name

    def wrapped(text: str, first: str) -> list[str]:
        return textwrap.wrap(
            text, TEMPLATE_WIDTH, initial_indent=first, subsequent_indent="#   ", break_on_hyphens=False
        )

    return wrapped(f"{name}: {doc}.", "# ") + wrapped(
        f"unit {rule.unit}; default {default_text}; allowed: {allowed}", "#   "
    )
