"""Checks of controller options: each refuses a value with WorkbenchInputError naming the option, the value received
(numbers as numbers: `nan`, `1e+308`, never `np.float64(nan)`) and what is allowed.

The controllers' config dataclasses check every field with these, one field at a time and before any value derived
from several fields is computed, so that a bad value is reported as itself (`frechet_point_spacing_m = 0` is "must
be > 0", not a ZeroDivisionError). Booleans are not numbers here (`True` is refused where a number is asked for).
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Iterable

import numpy as np

from workbench.base.errors import WorkbenchInputError, is_number, value_text


def shown_all(values: object) -> str:
    """A sequence as a message shows it: `[5.0, 10.0]`, each entry by `value_text`."""
    return "[" + ", ".join(value_text(v) for v in values) + "]"  # type: ignore[union-attr]


def check_number(
    name: str, value: object, low: float, high: float, unit: str = "", *, low_open: bool = False, note: str = ""
) -> None:
    """A finite number in [low, high] ((low, high] when `low_open`); `note` is added to what is allowed."""
    interval = f"{'(' if low_open else '['}{low:g}, {high:g}]" + (f" {unit}" if unit else "")
    allowed = f"a finite number in {interval}" + (f" ({note})" if note else "")
    if not is_number(value) or not math.isfinite(value):
        raise WorkbenchInputError(f"{name} must be {allowed}; got {value_text(value)}")
    if value < low or (low_open and value == low) or value > high:
        raise WorkbenchInputError(f"{name} must be {allowed}; got {value_text(value)}")


def check_optional_number(
    name: str,
    value: object,
    low: float,
    high: float,
    unit: str = "",
    *,
    low_open: bool = False,
    none_means: str = "off",
) -> None:
    """None, or what `check_number` allows; `none_means` says what None does."""
    if value is not None:
        check_number(name, value, low, high, unit, low_open=low_open, note=f"or None: {none_means}")


def check_whole(name: str, value: object, low: int, high: int) -> None:
    """A whole number (not a boolean, not a float) in [low, high]."""
    if not isinstance(value, numbers.Integral) or isinstance(value, bool | np.bool_) or not low <= value <= high:
        raise WorkbenchInputError(f"{name} must be a whole number in [{low}, {high}]; got {value_text(value)}")


def check_bool(name: str, value: object) -> None:
    """True or False."""
    if not isinstance(value, bool | np.bool_):
        raise WorkbenchInputError(f"{name} must be true or false; got {value_text(value)}")


def check_choice(name: str, value: object, allowed: Iterable[str]) -> None:
    """One of the names in `allowed`."""
    allowed = tuple(allowed)
    if not isinstance(value, str) or value not in allowed:
        raise WorkbenchInputError(f"{name} must be one of {', '.join(allowed)}; got {value_text(value)}")


def check_optional_instance(name: str, value: object, cls: type) -> None:
    """None, or an instance of `cls` (an object a file was read into at the boundary, never a path)."""
    if value is not None and not isinstance(value, cls):
        raise WorkbenchInputError(f"{name} must be a {cls.__name__} or None; got {value_text(value)}")


def check_optional_path(name: str, value: object) -> None:
    """None, or a file path (text or a path object, not empty)."""
    if value is None:
        return
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str) or not value:
        raise WorkbenchInputError(f"{name} must be a file path or None; got {value_text(value)}")
