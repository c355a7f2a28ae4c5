"""The one exception type for bad input (files, names, parameters and values a user can correct) and the checks
that raise it, for every layer: numbers in a range, whole numbers, flags, choices, objects of a type.

Every message names the value received and what is allowed, so the CLI can print it as it is. Numbers in messages
are written as Python writes its own numbers (`value_text`): a numpy scalar prints as `nan` or `1e+308`, never as
`np.float64(nan)`.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable
from typing import TypeGuard

import numpy as np


class WorkbenchInputError(ValueError):
    """Input the workbench cannot use: a malformed file, an unknown name, an unphysical parameter, NaN."""


def is_number(value: object) -> TypeGuard[float]:
    """A real number, Python's or numpy's, but not a boolean (a float to the type checker: what it computes with)."""
    if type(value) is float or type(value) is int:  # the common case, without the ABC check (these run per step)
        return True
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


def value_text(value: object) -> str:
    """`value` as a message shows it: numbers (numpy scalars included) as Python's repr of the plain int or float
    (`nan`, `1e+308`, `3`), anything else by its repr."""
    if isinstance(value, bool | np.bool_):
        return repr(bool(value))
    if isinstance(value, numbers.Integral):
        return repr(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    return repr(value)


def require_finite(name: str, values: object) -> None:
    """Raise WorkbenchInputError naming `name` and the first non-finite entry of `values`."""
    arr = np.asarray(values, dtype=float)
    bad = ~np.isfinite(arr)
    if bad.any():
        index = int(np.flatnonzero(bad.ravel())[0])
        raise WorkbenchInputError(f"{name} must be finite numbers; entry {index} is {value_text(arr.ravel()[index])}")


def require_positive(name: str, value: float) -> None:
    """Raise WorkbenchInputError unless `value` is a finite number greater than zero."""
    if not is_number(value) or not math.isfinite(value) or value <= 0:
        raise WorkbenchInputError(f"{name} must be a finite number > 0; got {value_text(value)}")


def bound_text(value: float) -> str:
    """A range's bound as a message shows it: the shortest form that reads back as the same number (`5`, `0.001`,
    `1e+09`, `0.123456789`)."""
    short = f"{float(value):g}"
    return short if float(short) == float(value) else value_text(value)


def shown_all(values: Iterable[object]) -> str:
    """A sequence as a message shows it: `[5.0, 10.0]`, each entry by `value_text`."""
    return "[" + ", ".join(value_text(v) for v in values) + "]"


def range_text(low: float, high: float, unit: str = "", *, low_open: bool = False, note: str = "") -> str:
    """What `require_in_range` allows: `[low, high] unit` (`(low, high]` when `low_open`), then `(note)`."""
    interval = f"{'(' if low_open else '['}{bound_text(low)}, {bound_text(high)}]" + (f" {unit}" if unit else "")
    return interval + (f" ({note})" if note else "")


def require_in_range(
    name: str, value: object, low: float, high: float, unit: str = "", *, low_open: bool = False, note: str = ""
) -> None:
    """Raise WorkbenchInputError unless `value` is a finite number (not a boolean) in [low, high] ((low, high] when
    `low_open`). The message names `name`, the value and the range with its unit; `note` is added to what is
    allowed ("0: off", "or None: ...")."""
    if is_number(value) and math.isfinite(value) and low <= value <= high and not (low_open and value == low):
        return  # the message is built only for a value refused (parameters are checked on every controller step)
    allowed = range_text(low, high, unit, low_open=low_open, note=note)
    raise WorkbenchInputError(f"{name} must be a finite number in {allowed}; got {value_text(value)}")


def require_whole(name: str, value: object, low: int, high: int) -> None:
    """Raise WorkbenchInputError unless `value` is a whole number (not a boolean, not a float) in [low, high]."""
    if not isinstance(value, numbers.Integral) or isinstance(value, bool | np.bool_) or not low <= int(value) <= high:
        raise WorkbenchInputError(f"{name} must be a whole number in [{low}, {high}]; got {value_text(value)}")


def require_bool(name: str, value: object) -> None:
    """Raise WorkbenchInputError unless `value` is True or False."""
    if not isinstance(value, bool | np.bool_):
        raise WorkbenchInputError(f"{name} must be true or false; got {value_text(value)}")


def require_choice(name: str, value: object, allowed: Iterable[str]) -> None:
    """Raise WorkbenchInputError unless `value` is one of the names in `allowed`."""
    allowed = tuple(allowed)
    if not isinstance(value, str) or value not in allowed:
        raise WorkbenchInputError(f"{name} must be one of {', '.join(allowed)}; got {value_text(value)}")


def require_instance_or_none(name: str, value: object, cls: type) -> None:
    """Raise WorkbenchInputError unless `value` is None or an instance of `cls` (an object a file was read into at
    the boundary, never a path)."""
    if value is not None and not isinstance(value, cls):
        raise WorkbenchInputError(f"{name} must be a {cls.__name__} or None; got {value_text(value)}")
