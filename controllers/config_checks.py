"""Controller options declared with their rules: each config field's unit, allowed values and meaning in one place,
checked by the base layer's checks (`workbench.base.errors`: each refuses a value with WorkbenchInputError naming
the option, the value received, numbers as numbers, and what is allowed).

The controllers' config dataclasses check every field by its rule, one field at a time and before any value derived
from several fields is computed, so that a bad value is reported as itself (`frechet_point_spacing_m = 0` is "must
be > 0", not a ZeroDivisionError). Booleans are not numbers here (`True` is refused where a number is asked for).

Each config field is declared with `option(default, doc, rule)`: its rule (`Number`, `Whole`, `Choice`, `Flag`,
`Instance`) carries its unit and allowed values, and its doc what it does, in the field's metadata. `check_options`
checks every field by its rule, and `workbench controllers --show NAME` prints the same unit, range and meaning
(`workbench.apps.controller_config.config_template`): one home for both.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from workbench.base.errors import (
    range_text,
    require_bool,
    require_choice,
    require_in_range,
    require_instance_or_none,
    require_whole,
)

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

# ----------------------------------------------------------------------------------------------- option rules
# A config field's rule says what it allows and checks it (`workbench.base.errors`); its field's metadata holds
# the rule with the field's unit and meaning (`option`), so that what `workbench controllers --show NAME` prints as the
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
                require_in_range(name, value, self.low, self.high, unit, low_open=self.low_open, note=note)
            return
        require_in_range(name, value, self.low, self.high, unit, low_open=self.low_open, note=self.note)

    def allowed(self) -> str:
        text = range_text(self.low, self.high, low_open=self.low_open, note=self.note)
        return text + (f', or "none": {self.none_means}' if self.none_means is not None else "")


@dataclass(frozen=True)
class Whole:
    """A whole number in [low, high] (`unit`: what it counts)."""

    low: int
    high: int
    unit: str = NO_UNIT

    def check(self, name: str, value: object) -> None:
        require_whole(name, value, self.low, self.high)

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
        require_choice(name, value, self.choices())

    def allowed(self) -> str:
        return "one of " + ", ".join(f'"{n}"' for n in self.choices())


@dataclass(frozen=True)
class Flag:
    """True or False."""

    unit: str = NO_UNIT

    def check(self, name: str, value: object) -> None:
        require_bool(name, value)

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
        require_instance_or_none(name, value, self.cls)

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


def check_options(config: DataclassInstance) -> None:
    """Check every field of a config dataclass that has a rule, in declaration order (each refusal names the
    option, the value and what is allowed); relations between fields are the config's own `__post_init__`'s."""
    for f in dataclasses.fields(config):
        rule = option_rule(f)
        if rule is not None:
            rule.check(f.name, getattr(config, f.name))
