"""How the clothoid controller follows the adaptive search's choice of lookahead: never below the floor that keeps
the loop's margins, with hysteresis, and at a limited rate in both directions.

Why. The Fréchet search (section 3) re-chooses the lookahead every step and, left alone, jumps between the ends of
its range from one step to the next (on the loaded truck's Zandvoort lap between 5 and 20 m every few steps, which
drove its limit cycle). The loop's gain goes as L^-3 (`loop_analysis.py`), so each jump is a step change of the
loop; margins computed for a frozen lookahead only hold while it varies slowly against the loop's own time scale,
L / V. So:

- the floor (`loop_analysis.lookahead_floor`, per speed) is a hard lower bound, applied at once both ways: the
  lookahead rises with it and, when it falls (the vehicle slowed), falls by as much, keeping its excess over it;
- a change of choice smaller than the hysteresis is ignored (the search's grid jitter);
- the lookahead moves towards the choice by at most `max_growth_m_per_m` (longer) or `max_shrink_m_per_m`
  (shorter) metres per metre travelled, i.e. d ln L / dt at most that times V / L, the loop's crossover scale.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from controllers.config_checks import Number

#: A rate limit in metres of lookahead per metre travelled: None (unlimited) or a number in (0, 100].
RATE_LIMIT = Number(0.0, 100.0, "m per m", low_open=True, none_means="unlimited")


@njit(cache=True)
def filtered_lookahead(
    state: np.ndarray,
    choice_m: float,
    floor_m: float,
    ceiling_m: float,
    distance_m: float,
    hysteresis_m: float,
    max_growth_m_per_m: float,
    max_shrink_m_per_m: float,
) -> float:  # pragma: no cover - compiled
    """The lookahead (m) for this step (module docstring): choice_m filtered, within [floor_m, ceiling_m];
    distance_m: travelled since the last step (m); the rates NaN when unlimited; state: [the lookahead, the floor]
    of the last step (NaN before the first), updated."""
    current, last_floor = state[0], state[1]
    if not math.isnan(current) and not math.isnan(last_floor) and floor_m < last_floor:
        current = max(current - (last_floor - floor_m), floor_m)  # a falling floor takes the lookahead down
    state[1] = floor_m
    if math.isnan(current) or abs(choice_m - current) <= hysteresis_m:
        target = choice_m if math.isnan(current) else current
    else:
        target = choice_m
    if not math.isnan(current):
        if target > current and not math.isnan(max_growth_m_per_m):
            target = min(target, current + max_growth_m_per_m * distance_m)
        elif target < current and not math.isnan(max_shrink_m_per_m):
            target = max(target, current - max_shrink_m_per_m * distance_m)
    state[0] = min(max(target, floor_m), max(ceiling_m, floor_m))
    return state[0]

