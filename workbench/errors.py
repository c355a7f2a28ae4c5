"""The one exception type for bad input: files, names, parameters and values a user can correct.

Every message names the value received and what is allowed, so the CLI can print it as it is.
"""

from __future__ import annotations

import math

import numpy as np


class WorkbenchInputError(ValueError):
    """Input the workbench cannot use: a malformed file, an unknown name, an unphysical parameter, NaN."""


def require_finite(name: str, values: object) -> None:
    """Raise WorkbenchInputError naming `name` and the first non-finite entry of `values`."""
    arr = np.asarray(values, dtype=float)
    bad = ~np.isfinite(arr)
    if bad.any():
        index = int(np.flatnonzero(bad.ravel())[0])
        raise WorkbenchInputError(f"{name} must be finite numbers; entry {index} is {float(arr.ravel()[index])!r}")


def require_positive(name: str, value: float) -> None:
    """Raise WorkbenchInputError unless `value` is a finite number greater than zero."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value <= 0:
        raise WorkbenchInputError(f"{name} must be a finite number > 0; got {value!r}")


def require_in_range(name: str, value: float, low: float, high: float, unit: str = "") -> None:
    """Raise WorkbenchInputError unless low <= value <= high (and finite)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise WorkbenchInputError(f"{name} must be a finite number in [{low}, {high}] {unit}; got {value!r}")
    if not low <= value <= high:
        raise WorkbenchInputError(f"{name} must be in [{low}, {high}] {unit}; got {value!r}".replace("  ", " "))
