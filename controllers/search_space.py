"""What a controller offers to be tuned: its tunable options, each with bounds, a scale and a reason.

Every controller class declares `search_space`, a tuple of `Tunable` next to its config, naming the options worth
searching (not every option: safety settings such as the clothoid controller's margin floors are the design's, not
knobs), the range a search may draw them from, on which scale, and what each trades. The range always contains
the option's shipped default, so a controller's default configuration is a point of its own space.

The studies read a tunable in their distribution form (`Tunable.distribution_table`: `{uniform = [low, high]}`,
`{log_uniform = ...}`, `{integers = ...}` or `{choice = [...]}`, `workbench.apps.studies.distributions`), and
`search_space_toml` writes a controller's space as the `[search.NAME]` table a tournament spec copies
(`workbench controllers --show NAME --search-space`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from workbench.base.errors import WorkbenchInputError, is_number, value_text
from workbench.base.toml_text import toml_key, toml_value

#: How a tunable is drawn: "linear" (uniform in [low, high]), "log" (log-uniform: for positive quantities spanning
#: decades, such as weights and thresholds), "integer" (whole numbers in [low, high], both included) or "choice"
#: (one of the listed values).
SCALES = ("linear", "log", "integer", "choice")
#: The distribution kind (`workbench.apps.studies.distributions.KINDS`) of each scale.
_KINDS = {"linear": "uniform", "log": "log_uniform", "integer": "integers", "choice": "choice"}


@dataclass(frozen=True)
class Tunable:
    """One tunable option of a controller.

    Parameters
    ----------
    name : str
        The option: a field of the controller's config, or a run parameter of its runs (the lead-filter scales
        `lead_filter_zero_scale` / `lead_filter_pole_scale` of a controller that reads a lead filter).
    scale : str
        One of SCALES.
    low, high : float or int, optional
        The bounds of a "linear", "log" or "integer" tunable (low < high; "log": low > 0; "integer": whole
        numbers, low <= high); None for a "choice".
    choices : tuple, optional
        The values of a "choice" tunable: numbers, text or booleans, none twice; empty for the others.
    reason : str
        One line: what the option trades (what a larger or smaller value buys and costs).
    """

    name: str
    scale: str
    low: float | int | None = None
    high: float | int | None = None
    choices: tuple[Any, ...] = ()
    reason: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise WorkbenchInputError(f"a tunable's name must be an option's name (an identifier); got {self.name!r}")
        where = f"tunable {self.name}"
        if self.scale not in SCALES:
            raise WorkbenchInputError(f"{where}: scale must be one of {', '.join(SCALES)}; got {self.scale!r}")
        if not isinstance(self.reason, str) or not self.reason.strip() or "\n" in self.reason or "\r" in self.reason:
            raise WorkbenchInputError(f"{where}: reason must be one non-empty line of text; got {self.reason!r}")
        if self.scale == "choice":
            self._check_choices(where)
        else:
            self._check_bounds(where)

    def _check_choices(self, where: str) -> None:
        if self.low is not None or self.high is not None:
            raise WorkbenchInputError(
                f"{where}: a choice has no bounds (low and high None); got low = {value_text(self.low)}, "
                f"high = {value_text(self.high)}"
            )
        if not isinstance(self.choices, tuple) or not self.choices:
            raise WorkbenchInputError(f"{where}: choices must be a non-empty tuple of values; got {self.choices!r}")
        for value in self.choices:
            if not isinstance(value, str | bool) and not (is_number(value) and math.isfinite(value)):
                raise WorkbenchInputError(
                    f"{where}: choices must be finite numbers, text or booleans; got {value_text(value)}"
                )
        if len({repr(v) for v in self.choices}) != len(self.choices):
            raise WorkbenchInputError(f"{where}: choices list a value twice: {list(self.choices)}")

    def _check_bounds(self, where: str) -> None:
        if self.choices != ():
            raise WorkbenchInputError(
                f"{where}: only a choice has choices; got {self.choices!r} on a {self.scale} scale"
            )
        low, high = self.low, self.high
        if self.scale == "integer":
            # whole numbers (not booleans), low <= high; one condition, so that the checker narrows the bounds
            if (
                not (isinstance(low, int) and not isinstance(low, bool))
                or not (isinstance(high, int) and not isinstance(high, bool))
                or low > high
            ):
                raise WorkbenchInputError(
                    f"{where}: an integer scale needs whole-number bounds with low <= high; got low = "
                    f"{value_text(low)}, high = {value_text(high)}"
                )
            return
        if not (is_number(low) and math.isfinite(low) and is_number(high) and math.isfinite(high)) or not low < high:
            raise WorkbenchInputError(
                f"{where}: a {self.scale} scale needs finite bounds with low < high; got low = {value_text(low)}, "
                f"high = {value_text(high)}"
            )
        if self.scale == "log" and low <= 0:
            raise WorkbenchInputError(f"{where}: a log scale needs low > 0; got low = {value_text(low)}")
        object.__setattr__(self, "low", float(low))
        object.__setattr__(self, "high", float(high))

    def distribution_table(self) -> dict[str, list[Any]]:
        """The tunable in the studies' distribution form, a one-entry table `Distribution.parse` reads:
        {"uniform": [low, high]}, {"log_uniform": [low, high]}, {"integers": [low, high]} or {"choice": [...]}."""
        values = list(self.choices) if self.scale == "choice" else [self.low, self.high]
        return {_KINDS[self.scale]: values}

    def contains(self, value: object) -> bool:
        """Whether `value` is a point of this tunable's range (a choice's value; a number within the bounds, a
        whole one on an integer scale)."""
        if self.scale == "choice":
            return any(type(value) is type(c) and value == c for c in self.choices)
        if not is_number(value) or not math.isfinite(value):
            return False
        if self.scale == "integer" and value != int(value):
            return False
        return self.low <= value <= self.high  # type: ignore[operator]  # every scale but a choice has its bounds


def controller_search_space(name: str) -> tuple[Tunable, ...]:
    """The search space the controller registered as `name` declares (`Controller.search_space`; empty when it
    declares none), checked to be a tuple of Tunable naming no option twice."""
    from controllers import CONTROLLERS

    if name not in CONTROLLERS:
        raise WorkbenchInputError(f"unknown controller {name!r}; choose one of {', '.join(CONTROLLERS)}")
    space = getattr(CONTROLLERS[name], "search_space", ())
    if not isinstance(space, tuple) or not all(isinstance(t, Tunable) for t in space):
        raise WorkbenchInputError(
            f"controller {name!r}: search_space must be a tuple of controllers.search_space.Tunable; got {space!r}"
        )
    names = [t.name for t in space]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise WorkbenchInputError(f"controller {name!r}: its search_space names {', '.join(twice)} more than once")
    return space


def search_space_toml(name: str) -> str:
    """The search space of controller `name` as the `[search.NAME]` TOML table a tournament spec copies, one line
    per tunable, `key = {log_uniform = [a, b]}  # reason`; for a controller that declares none, comment lines
    saying so and how a spec gives it one."""
    space = controller_search_space(name)
    table = f"[search.{toml_key(name)}]"
    if not space:
        return (
            f"# controller {name!r} declares no search space. A tournament spec can give it one as a {table} table,\n"
            "# one line per option (`workbench controllers --show " + name + "` lists them), e.g.\n"
            "# some_option = {uniform = [0.5, 2.0]}  (or log_uniform, integers = [low, high], choice = [...])\n"
        )
    entries = [f"{toml_key(t.name)} = {toml_value(t.distribution_table())}" for t in space]
    width = max(len(e) for e in entries)
    lines = [
        f"# the search space controller {name!r} declares (bounds contain its defaults): copy it into a tournament",
        "# spec, and narrow or widen it there",
        table,
        *(f"{entry:<{width}}  # {t.reason}" for entry, t in zip(entries, space, strict=True)),
    ]
    return "\n".join(lines) + "\n"


__all__ = ["SCALES", "Tunable", "controller_search_space", "search_space_toml"]
