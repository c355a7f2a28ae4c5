"""One typed loader from TOML/JSON tables (and `key=value` text) into frozen dataclasses.

Controller configs, vehicle presets, lead-filter files and study specs all read tables whose keys must be a
dataclass's fields (or a fixed set) and whose values must have each field's type. This module is the one home of
those rules: `check_keys` refuses unknown and missing keys with the allowed list; `typed_value` converts a value
strictly (an integer is taken for a float, nothing else is converted: the text `"0.1"` or `"false"` in a file is
refused, naming the key, the value and the type; non-finite numbers are refused) or, for text from a command line
(`--set`), parses it; `dataclass_from_table` does both for a dataclass. Every problem is a
WorkbenchInputError naming the key, the value and what is allowed.

Field types handled: float, int, bool, str, Path (relative to a base folder), and any of them `| None` (written
"none" in text and in TOML, which has no null).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from workbench.base.errors import WorkbenchInputError, value_text

#: How a boolean may be written as text (`--set use_lead_filter=off`).
TRUE_WORDS = ("true", "yes", "on", "1")
FALSE_WORDS = ("false", "no", "off", "0")
_TYPE_NAMES: dict[Any, str] = {float: "number", int: "whole number", bool: "boolean", str: "text", Path: "file path"}


def unwrap(annotation: Any) -> tuple[Any, bool]:
    """(the type, whether None is allowed) of `T` or `T | None`."""
    if isinstance(annotation, types.UnionType) or typing.get_origin(annotation) is typing.Union:
        members = [a for a in typing.get_args(annotation) if a is not type(None)]
        return members[0], len(members) < len(typing.get_args(annotation))
    return annotation, False


def type_name(annotation: Any) -> str:
    """What a value of this type is called in a message: "number", "whole number", ... (or "none")."""
    base, optional = unwrap(annotation)
    return _TYPE_NAMES.get(base, getattr(base, "__name__", str(base))) + (' or "none"' if optional else "")


def field_types(cls: type) -> dict[str, Any]:
    """The init fields of dataclass `cls` and their (resolved) types, in declaration order."""
    return dict(_init_field_types(cls))


@functools.cache
def _init_field_types(cls: type) -> tuple[tuple[str, Any], ...]:
    """`field_types`, resolved once per class (resolving the annotations takes milliseconds, and a study checks
    thousands of values against the same classes)."""
    hints = typing.get_type_hints(cls)
    return tuple((f.name, hints[f.name]) for f in dataclasses.fields(cls) if f.init)


def check_keys(where: str, table: object, allowed: Iterable[str], required: Iterable[str] = ()) -> dict[str, Any]:
    """`table` as a dict, if it is a table whose keys are all in `allowed` and include every one of `required`."""
    allowed, required = tuple(allowed), tuple(required)
    if not isinstance(table, Mapping):
        raise WorkbenchInputError(f"{where} must be a table; got {value_text(table)}")
    unknown = [key for key in table if key not in allowed]
    missing = [key for key in required if key not in table]
    if unknown or missing:
        problems = [f"unknown key {k!r}" for k in unknown] + [f"missing key {k!r}" for k in missing]
        raise WorkbenchInputError(f"{where}: {', '.join(problems)}; allowed keys: {', '.join(allowed)}")
    return dict(table)


def typed_value(where: str, value: Any, annotation: Any, base_dir: Path | None = None, from_text: bool = False) -> Any:
    """`value` as the type `annotation`, strictly: a finite number for a float (an integer is taken), a whole number
    for an int, a boolean for a bool, text for a str, a path (relative to `base_dir`) for a Path, "none" (or None)
    for an optional field's None. With `from_text`, a string is parsed as the type (`"0.3"`, `"off"`, `"none"`).
    WorkbenchInputError naming `where`, the value and the type otherwise."""
    base, optional = unwrap(annotation)
    text = value.strip() if isinstance(value, str) else None
    if optional and (value is None or (text is not None and text.lower() in ("none", *(("",) if from_text else ())))):
        return None
    if base not in _TYPE_NAMES:
        raise WorkbenchInputError(f"{where} has type {annotation!r}, which cannot be given in a file")
    parsed = _parsed(base, value, text if from_text else None)
    if parsed is None:
        quoted = text is not None and base in (float, int, bool) and _parsed(base, value, text) is not None
        hint = " (a file's numbers and booleans are written without quotes)" if quoted else ""
        raise WorkbenchInputError(f"{where} must be a {type_name(annotation)}; got {value_text(value)}{hint}")
    if base is float and not math.isfinite(parsed):
        raise WorkbenchInputError(f"{where} must be a finite number; got {value_text(value)}")
    if base is Path:
        parsed = parsed.expanduser()
        return parsed if parsed.is_absolute() or base_dir is None else base_dir / parsed
    return parsed


def _parsed(base: Any, value: Any, text: str | None) -> Any:
    """`value` as `base`, or None when it is not one (text parsed only when given)."""
    is_bool = isinstance(value, bool)
    if base is float:
        if isinstance(value, int | float) and not is_bool:
            return float(value)
        return _or_none(float, text)
    if base is int:
        if isinstance(value, int) and not is_bool:
            return value
        return _or_none(int, text)
    if base is bool:
        if is_bool:
            return value
        if text is not None and text.lower() in TRUE_WORDS + FALSE_WORDS:
            return text.lower() in TRUE_WORDS
        return None
    if isinstance(value, str | Path) and str(value):  # str or Path
        return str(value) if base is str else Path(value)
    return None


def _or_none(parse: type, text: str | None) -> Any:
    if text is None:
        return None
    try:
        return parse(text)
    except ValueError:
        return None


def dataclass_from_table(
    cls: type,
    table: Mapping[str, Any],
    where: str,
    base_dir: Path | None = None,
    from_text: bool = False,
    required: bool = False,
) -> Any:
    """An instance of dataclass `cls` from a table of its fields (all of them when `required`, else its defaults
    fill the rest); keys and values checked as `check_keys` and `typed_value` do, the dataclass's own validation
    after. Messages start with `where`."""
    fields = field_types(cls)
    given = check_keys(where, table, fields, fields if required else ())
    values = {
        key: typed_value(f"{where}: {key!r}", value, fields[key], base_dir, from_text) for key, value in given.items()
    }
    return cls(**values)
