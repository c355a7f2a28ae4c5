"""Open-loop steering-wheel profiles used to identify the steering-to-curvature lag (paper, section 5.1).

Each maneuver is a function of time returning the steering-wheel angle (rad). `dlc` is a double-lane-change
steering profile (one sine period to the left lane, a hold, one opposite period back), `step` a single step and
`step-series` the series of alternating steps of the paper's Figure 8b.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from workbench.errors import WorkbenchInputError, require_in_range, require_positive


@dataclass(frozen=True)
class Maneuver:
    """A steering-wheel profile: amplitude_deg (steering-wheel degrees), duration_s, and the profile's kind.

    step: 0 until start_s, then amplitude. step-series: steps of +amplitude, 0, -amplitude, 0 ... each held
    hold_s. dlc: amplitude * sin(2 pi (t - start) / period) for one period, a hold of hold_s, then the opposite.
    """

    kind: str
    amplitude_deg: float = 90.0
    start_s: float = 1.0
    hold_s: float = 4.0
    period_s: float = 4.0
    duration_s: float = 20.0

    KINDS = ("step", "step-series", "dlc")

    def __post_init__(self) -> None:
        if self.kind not in self.KINDS:
            raise WorkbenchInputError(f"unknown maneuver {self.kind!r}; choose one of {', '.join(self.KINDS)}")
        require_in_range("amplitude_deg", self.amplitude_deg, -1080.0, 1080.0, "deg")
        if self.amplitude_deg == 0:
            raise WorkbenchInputError("amplitude_deg must be non-zero: a zero profile cannot excite the vehicle")
        require_in_range("start_s", self.start_s, 0.0, 1e4, "s")
        require_positive("hold_s", self.hold_s)
        require_positive("period_s", self.period_s)
        require_positive("duration_s", self.duration_s)

    def steer_wheel_rad(self, t_s: np.ndarray) -> np.ndarray:
        t = np.asarray(t_s, dtype=float) - self.start_s
        a = math.radians(self.amplitude_deg)
        if self.kind == "step":
            return np.where(t >= 0.0, a, 0.0)
        if self.kind == "step-series":
            phase = np.floor(np.maximum(t, 0.0) / self.hold_s).astype(int) % 4
            return np.where(t >= 0.0, np.choose(phase, [a, 0.0, -a, 0.0]), 0.0)
        # dlc: sine out, hold, sine back
        first = (t >= 0.0) & (t < self.period_s)
        t2 = t - self.period_s - self.hold_s
        second = (t2 >= 0.0) & (t2 < self.period_s)
        return a * (
            np.where(first, np.sin(2 * np.pi * t / self.period_s), 0.0)
            - np.where(second, np.sin(2 * np.pi * t2 / self.period_s), 0.0)
        )
