"""Values written as TOML text, for the files the workbench writes for people to copy and edit (controller-config
templates, vehicle presets, optimised configs, lead-filter files): one writer, so that every such file reads back
through `workbench.base.input_files.read_toml` to the values written.

None is written "none", the text the config files read as no value (TOML has no null).
"""

from __future__ import annotations

import json
import numbers
import re
from collections.abc import Iterable, Mapping
from pathlib import Path

from workbench.base.errors import value_text

#: A key TOML takes bare; any other is quoted.
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def toml_value(value: object) -> str:
    """`value` as TOML: a boolean, a number (Python's or NumPy's, as Python writes it, so that it reads back
    exactly), a string or path (a JSON string is a TOML basic string, but for DEL, which TOML wants escaped), None
    as "none", a mapping as an inline table, any other iterable as an array."""
    if value is None:
        return '"none"'
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, numbers.Real):
        return value_text(value)
    if isinstance(value, str | Path):
        return json.dumps(str(value), ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{toml_key(k)} = {toml_value(v)}" for k, v in value.items()) + "}"
    if not isinstance(value, Iterable):
        raise TypeError(f"{type(value).__name__} {value!r} has no TOML form")
    return "[" + ", ".join(toml_value(v) for v in value) + "]"


def toml_key(key: str) -> str:
    """`key` as a TOML key: bare when it may be, else quoted."""
    return key if _BARE_KEY.fullmatch(key) else toml_value(key)


__all__ = ["toml_key", "toml_value"]
