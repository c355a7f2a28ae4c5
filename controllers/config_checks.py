"""Checks of controller options: each refuses a value with WorkbenchInputError naming the option, the value received
(numbers as numbers: `nan`, `1e+308`, never `np.float64(nan)`) and what is allowed.

The controllers' config dataclasses check every field with these, one field at a time and before any value derived
from several fields is computed, so that a bad value is reported as itself (`frechet_point_spacing_m = 0` is "must
be > 0", not a ZeroDivisionError). Booleans are not numbers here (`True` is refused where a number is asked for).

Each config field is declared with `option(default, doc, rule)`: its rule (`Number`, `Whole`, `Choice`, `Flag`,
`Instance`) carries its unit and allowed values, and its doc what it does, in the field's metadata. `check_options`
checks every field by its rule, and `workbench controllers --show NAME` prints the same unit, range and meaning
(`workbench.apps.controller_config.config_template`): one home for both.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

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


# ----------------------------------------------------------------------------------------------- option rules
# A config field's rule says what it allows and checks it (the messages above); its field's metadata holds the rule
# with the field's unit and meaning (`option`), so that what `workbench controllers --show NAME` prints as the
# allowed range is what the config's validation refuses outside of.

#: The unit written for an option that is no physical quantity (a choice, a switch, a ratio, a count of things).
NO_UNIT = "-"


@dataclass(frozen=True)
class Number:
    """A finite number in [low, high] ((low, high] when `low_open`), in `unit`; with `none_means`, None as well,
    which does that. `note` says what a special value does ("0: off")."""

    low: float
    high: float
    unit: str = NO_UNIT
    low_open: bool = False
    none_means: str | None = None
    note: str = ""

    def check(self, name: str, value: object) -> None:
        unit = "" if self.unit == NO_UNIT else self.unit
        if self.none_means is not None:
            if value is not None:
                note = f"{self.note}; or None: {self.none_means}" if self.note else f"or None: {self.none_means}"
                check_number(name, value, self.low, self.high, unit, low_open=self.low_open, note=note)
            return
        check_number(name, value, self.low, self.high, unit, low_open=self.low_open, note=self.note)

    def allowed(self) -> str:
        text = f"{'(' if self.low_open else '['}{self.low:g}, {self.high:g}]" + (f" ({self.note})" if self.note else "")
        return text + (f', or "none": {self.none_means}' if self.none_means is not None else "")


@dataclass(frozen=True)
class Whole:
    """A whole number in [low, high] (`unit`: what it counts)."""

    low: int
    high: int
    unit: str = NO_UNIT

    def check(self, name: str, value: object) -> None:
        check_whole(name, value, self.low, self.high)

    def allowed(self) -> str:
        return f"a whole number in [{self.low}, {self.high}]"


@dataclass(frozen=True)
class Choice:
    """One of `names` (a tuple, or a function giving it, for a list known only once other modules are loaded)."""

    names: tuple[str, ...] | Callable[[], tuple[str, ...]]
    unit: str = NO_UNIT

    def choices(self) -> tuple[str, ...]:
        return self.names() if callable(self.names) else self.names

    def check(self, name: str, value: object) -> None:
        check_choice(name, value, self.choices())

    def allowed(self) -> str:
        return "one of " + ", ".join(f'"{n}"' for n in self.choices())


@dataclass(frozen=True)
class Flag:
    """True or False."""

    unit: str = NO_UNIT

    def check(self, name: str, value: object) -> None:
        check_bool(name, value)

    def allowed(self) -> str:
        return "true or false"


@dataclass(frozen=True)
class Instance:
    """None (which does `none_means`), or an instance of `cls`: an object a file was read into at the boundary
    (`workbench.apps.controller_config.FILE_OPTIONS` names the file option that gives it)."""

    cls: type
    none_means: str
    unit: str = NO_UNIT

    def check(self, name: str, value: object) -> None:
        check_optional_instance(name, value, self.cls)

    def allowed(self) -> str:
        return f'a {self.cls.__name__}, or "none": {self.none_means}'


#: The rules a config field may have.
Rule = Number | Whole | Choice | Flag | Instance


def option(default: Any, doc: str, rule: Rule) -> Any:
    """A config dataclass field with its default, its meaning (`doc`: one sentence, what it does and why one
    would change it) and its rule (unit and allowed values), kept in the field's metadata: the one home of what
    `check_options` checks and `workbench controllers --show NAME` prints."""
    return dataclasses.field(default=default, metadata={"doc": doc, "rule": rule})


def option_rule(f: dataclasses.Field[Any]) -> Rule | None:
    """The rule of config field `f` (None: a field not made by `option`)."""
    return f.metadata.get("rule")


def check_options(config: object) -> None:
    """Check every field of a config dataclass that has a rule, in declaration order (each refusal names the
    option, the value and what is allowed); relations between fields are the config's own `__post_init__`'s."""
    for f in dataclasses.fields(config):  # type: ignore[arg-type]
        rule = option_rule(f)
        if rule is not None:
            rule.check(f.name, getattr(config, f.name))
