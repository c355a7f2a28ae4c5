"""Reading a user's input files safely: the one home for checking that an input file can be read and for parsing
TOML and JSON, so that every reader refuses the same problems with the same words.

Every problem is a WorkbenchInputError whose message is `<label>: <problem>`, the label naming the file (e.g.
"controller config file 'opts.toml'"), the problem one of:

- "no such file", "a folder, not a file", "no such file (... is a file, not a folder)" (a parent is a file),
  "not readable (permission denied)", "not readable (<the system's reason>)";
- "not UTF-8 text (byte N: ...)";
- "not valid TOML: ..." / "not valid JSON: ..." (the parser's message, with line and column);
- "nested deeper than 64 levels (tables and lists within each other) ...": no format here needs more than a few
  levels, and a deeply nested file would otherwise end in a RecursionError, in the parser (tomllib and json
  recurse) or in whatever walks the document afterwards.

`check_input_file` checks a path up front (before any work), `read_text` reads it, `parse_toml`/`parse_json` parse
text, and `read_toml`/`read_json` do both.
"""

from __future__ import annotations

import json
import os
import tomllib
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from workbench.base.errors import WorkbenchInputError

#: The deepest nesting of tables and lists a TOML or JSON input may have (the formats here need at most 4).
MAX_NESTING = 64


def _os_problem(exc: OSError, path: Path) -> str:
    """The problem an OSError from opening `path` for reading means, in words."""
    if isinstance(exc, FileNotFoundError):
        blocker = _file_among_parents(path)
        return f"no such file ({str(blocker)!r} is a file, not a folder)" if blocker else "no such file"
    if isinstance(exc, IsADirectoryError):
        return "a folder, not a file"
    if isinstance(exc, NotADirectoryError):
        blocker = _file_among_parents(path)
        return f"no such file ({str(blocker or path.parent)!r} is a file, not a folder)"
    if isinstance(exc, PermissionError):
        return "not readable (permission denied)"
    return f"not readable ({exc.strerror or exc})"


def _file_among_parents(path: Path) -> Path | None:
    """The first of path's parents that exists and is not a folder (None: there is none)."""
    for parent in reversed(path.parents):
        if parent.exists() and not parent.is_dir():
            return parent
    return None


def check_input_file(path: str | os.PathLike[str], label: str) -> Path:
    """`path` as a Path if it names a readable file; WorkbenchInputError `<label>: <problem>` otherwise (missing,
    a folder, a parent that is a file, not a regular file, not readable). Checks without opening the file."""
    path = Path(path)
    try:
        if not path.exists():
            raise FileNotFoundError(path)
        if path.is_dir():
            raise IsADirectoryError(path)
        if not path.is_file():
            raise WorkbenchInputError(f"{label}: not a regular file (a device, socket or pipe)")
        if not os.access(path, os.R_OK):
            raise PermissionError(path)
    except OSError as exc:
        raise WorkbenchInputError(f"{label}: {_os_problem(exc, path)}") from None
    return path


def read_text(path: str | os.PathLike[str], label: str) -> str:
    """The file's text (UTF-8); WorkbenchInputError `<label>: <problem>` when it cannot be read or decoded."""
    path = Path(path)
    try:
        if path.is_dir():  # on some systems reading a folder gives b"" or EISDIR late; say it plainly
            raise IsADirectoryError(path)
        data = path.read_bytes()
    except OSError as exc:
        raise WorkbenchInputError(f"{label}: {_os_problem(exc, path)}") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise WorkbenchInputError(f"{label}: not UTF-8 text (byte {exc.start}: {exc.reason})") from None


def nesting_depth(document: object, limit: int = MAX_NESTING) -> int:
    """How deeply tables (dicts) and lists nest in `document` (a scalar: 0), counted without recursion; stops
    counting once past `limit` (returns limit + 1)."""
    deepest = 0
    stack: list[tuple[object, int]] = [(document, 0)]
    while stack:
        node, depth = stack.pop()
        children: Iterable[object]
        if isinstance(node, dict):
            children = node.values()
        elif isinstance(node, list | tuple):
            children = node
        else:
            continue
        depth += 1
        if depth > limit:
            return limit + 1
        deepest = max(deepest, depth)
        stack.extend((child, depth) for child in children)
    return deepest


def _too_deep(label: str) -> WorkbenchInputError:
    return WorkbenchInputError(
        f"{label}: nested deeper than {MAX_NESTING} levels (tables and lists within each other); no input of the "
        "workbench needs more than a few"
    )


def _parse(text: str, label: str, kind: str, loads: Callable[[str], Any], errors: tuple[type[Exception], ...]) -> Any:
    try:
        document = loads(text)
    except RecursionError:
        raise _too_deep(label) from None
    except errors as exc:
        raise WorkbenchInputError(f"{label}: not valid {kind}: {exc}") from None
    if nesting_depth(document) > MAX_NESTING:
        raise _too_deep(label)
    return document


def parse_toml(text: str, label: str) -> dict[str, Any]:
    """TOML text as a dict; WorkbenchInputError `<label>: not valid TOML: ...` or `<label>: nested deeper ...`."""
    return _parse(text, label, "TOML", tomllib.loads, (tomllib.TOMLDecodeError,))


def _no_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number JSON allows")


def parse_json(text: str, label: str, allow_nan: bool = True) -> Any:
    """JSON text as Python values; WorkbenchInputError `<label>: not valid JSON: ...` or `<label>: nested deeper
    ...`. allow_nan=False refuses NaN and Infinity (which Python's json accepts by default)."""

    def loads(source: str) -> Any:
        return json.loads(source) if allow_nan else json.loads(source, parse_constant=_no_constant)

    return _parse(text, label, "JSON", loads, (ValueError,))  # JSONDecodeError is a ValueError


def read_toml(path: str | os.PathLike[str], label: str) -> dict[str, Any]:
    """Read and parse a TOML file; WorkbenchInputError `<label>: <problem>` for anything it cannot use."""
    return parse_toml(read_text(path, label), label)


def read_json(path: str | os.PathLike[str], label: str, allow_nan: bool = True) -> Any:
    """Read and parse a JSON file; WorkbenchInputError `<label>: <problem>` for anything it cannot use."""
    return parse_json(read_text(path, label), label, allow_nan)


__all__ = [
    "MAX_NESTING",
    "check_input_file",
    "nesting_depth",
    "parse_json",
    "parse_toml",
    "read_json",
    "read_text",
    "read_toml",
]
