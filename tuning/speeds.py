"""Lists of speeds for the commands that sweep speed: `--speeds 10,20,...,100` and its checks."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

from workbench.base.errors import WorkbenchInputError, require_in_range

ELLIPSIS = "..."
#: Most speeds a command sweeps (each is a few seconds of identification or analysis).
MAX_SPEEDS = 200


def check_speeds(speeds_kmh: Sequence[float], low: float, high: float) -> list[float]:
    """The speeds (km/h) as floats: at least one and at most MAX_SPEEDS, each in [low, high], strictly
    increasing."""
    speeds = [float(s) for s in speeds_kmh]
    if not speeds:
        raise WorkbenchInputError("give at least one speed")
    if len(speeds) > MAX_SPEEDS:
        raise WorkbenchInputError(f"{len(speeds)} speeds given; at most {MAX_SPEEDS}")
    for i, s in enumerate(speeds):
        require_in_range(f"speed {i + 1}", s, low, high, "km/h")
    if any(b <= a for a, b in itertools.pairwise(speeds)):
        raise WorkbenchInputError(f"speeds must increase strictly; got {speeds}")
    return speeds


def parse_speeds(text: str, low: float = 1.0, high: float = 200.0) -> list[float]:
    """Parse "10,20,30" or "10,20,...,100" (the step of the first two, continued to the last, inclusive)."""
    items = [item.strip() for item in text.split(",")]

    def number(item: str) -> float:
        try:
            value = float(item)
        except ValueError:
            raise WorkbenchInputError(
                f"speeds: {item!r} is not a number; give e.g. 10,20,30 or 10,20,...,100 (km/h)"
            ) from None
        if not math.isfinite(value):
            raise WorkbenchInputError(f"speeds: {item!r} is not a finite number")
        return value

    if ELLIPSIS in items:
        k = items.index(ELLIPSIS)
        if k != len(items) - 2 or k < 2 or items.count(ELLIPSIS) > 1:
            raise WorkbenchInputError(
                f"speeds: {text!r}: '...' must come after at least two speeds and before the last, as in 10,20,...,100"
            )
        head = [number(i) for i in items[:k]]
        last = number(items[-1])
        step = head[-1] - head[-2]
        if step <= 0:
            raise WorkbenchInputError(f"speeds: {text!r}: the speeds before '...' must increase")
        count = (last - head[-1]) / step
        if count < 0 or abs(count - round(count)) > 1e-6:
            raise WorkbenchInputError(
                f"speeds: {text!r}: {last:g} is not reached from {head[-1]:g} in steps of {step:g}"
            )
        if len(head) + round(count) > MAX_SPEEDS:
            raise WorkbenchInputError(f"speeds: {text!r} gives over {MAX_SPEEDS} speeds")
        speeds = head + [head[-1] + step * (i + 1) for i in range(round(count))]
    else:
        speeds = [number(i) for i in items]
    return check_speeds([round(s, 9) for s in speeds], low, high)
