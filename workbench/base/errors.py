"""The one exception type for bad input: files, names, parameters and values a user can correct.

Every message names the value received and what is allowed, so the CLI can print it as it is. Numbers in messages
are written as Python writes its own numbers (`value_text`): a numpy scalar prints as `nan` or `1e+308`, never as
`np.float64(nan)`.
"""

from __future__ import annotations

import math
import numbers

import numpy as np


class WorkbenchInputError(ValueError):
    """Input the workbench cannot use: a malformed file, an unknown name, an unphysical parameter, NaN."""


def is_number(value: object) -> bool:
    """A real number, Python's or numpy's, but not a boolean."""
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


def require_in_range(name: str, value: float, low: float, high: float, unit: str = "") -> None:
    """Raise WorkbenchInputError unless low <= value <= high (and finite)."""
    if is_number(value) and math.isfinite(value) and low <= value <= high:
        return  # the message is built only for a value refused (parameters are checked on every controller step)
    bounds = f"[{value_text(low)}, {value_text(high)}]" + (f" {unit}" if unit else "")
    if not is_number(value) or not math.isfinite(value):
        raise WorkbenchInputError(f"{name} must be a finite number in {bounds}; got {value_text(value)}")
    raise WorkbenchInputError(f"{name} must be in {bounds}; got {value_text(value)}".replace("  ", " "))
