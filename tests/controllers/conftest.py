"""Fixtures shared by the controller tests: made-up measurements weaving along a bend, to step controllers with
without a simulator."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from controllers.base import Measurement
from workbench.base.clothoid_chain import ClothoidChain
from workbench.base.path import ReferencePath

#: A straight, a clothoid into a 30 m arc, a clothoid out and a straight.
BEND_PATH = (
    ClothoidChain().straight(20.0).clothoid_to(1 / 30, 15.0).arc(30.0).clothoid_to(0.0, 15.0).straight(40.0)
).to_path("bend")


def weaving_measurements(
    path: ReferencePath = BEND_PATH, count: int = 60, seed: int = 7, start_s: float = 8.0, period_s: float = 0.02
) -> list[Measurement]:
    """Made-up measurements along `path` from arc length start_s at 8 m/s: a weaving offset (0.3 m, period about
    3 s), noisy speed, yaw, yaw rate and steering (seeded)."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        s = start_s + 0.16 * k
        x, y = path.position(s)
        heading = float(path.heading(s))
        offset = 0.3 * math.sin(0.1 * k)
        out.append(
            Measurement(
                period_s * k,
                float(x) - offset * math.sin(heading),
                float(y) + offset * math.cos(heading),
                8.0 + rng.normal(0.0, 0.1),
                rng.normal(0.0, 0.05),
                heading + rng.normal(0.0, 0.02),
                8.0 * float(path.curvature(s)) + rng.normal(0.0, 0.01),
                rng.normal(0.0, 0.3),
            )
        )
    return out


@pytest.fixture(scope="session")
def weaving() -> Callable[..., list[Measurement]]:
    """`weaving_measurements`, for tests that step a controller along a bend."""
    return weaving_measurements
