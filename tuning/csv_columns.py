"""The header of a CSV table `tuning` reads (vehicle logs, curvature limits): every column named once.

Column names are compared as the readers use them, stripped and case-insensitively, so that `t_s` and `T_S` are
the same column. pandas renames a repeated name on reading (`t_s`, `t_s.1`, `t_s.2`); a name of that form whose
stem is also a column is therefore a repeat too. A table with a column twice is ambiguous (which of the two is the
data?), and a reader that took one of them would silently ignore the other, so it is refused, naming the column.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from workbench.base.errors import WorkbenchInputError

#: How pandas names the repeats of a column name on reading: the name, a dot and a count.
_MANGLED = re.compile(r"(?P<stem>.+)\.(?P<count>[1-9][0-9]*)")


def column_key(name: object) -> str:
    """A column name as the readers compare it: stripped of spaces, lower case."""
    return str(name).strip().lower()


def require_unique_columns(columns: Iterable[object], label: str) -> None:
    """Raise WorkbenchInputError naming `label` and the first column that appears more than once in `columns` (the
    names as read; pandas' `NAME.1` counts as a repeat of NAME when NAME is a column too)."""
    names = [str(c) for c in columns]
    keys = [column_key(c) for c in names]
    present = set(keys)
    seen: dict[str, list[str]] = {}
    for name, key in zip(names, keys, strict=True):
        mangled = _MANGLED.fullmatch(key)
        stem = mangled["stem"] if mangled is not None and mangled["stem"] in present else key
        seen.setdefault(stem, []).append(name)
    for stem, spellings in seen.items():
        if len(spellings) > 1:
            shown = ", ".join(repr(s) for s in spellings)
            raise WorkbenchInputError(
                f"{label}: column {stem!r} appears {len(spellings)} times (read as {shown}; names are compared "
                "case-insensitively, and the reader renames a repeat NAME.1); each column must appear once: remove "
                "or rename the repeats"
            )
