"""The compiled lookahead filter (`lookahead_filter.filtered_lookahead`) with its state held in an object, for the
tests that step it by hand with a ClothoidConfig's hysteresis and rate limits: the clothoid step keeps that state in
its own state record."""

from __future__ import annotations

import math

import numpy as np

from controllers.clothoid import ClothoidConfig
from controllers.clothoid.lookahead_filter import filtered_lookahead


class LookaheadFilter:
    """The lookahead actually used, from the search's choice step by step (`filtered_lookahead` with its state)."""

    __slots__ = ("_hysteresis_m", "_rates", "_state")

    def __init__(self, config: ClothoidConfig) -> None:
        self._hysteresis_m = config.lookahead_hysteresis_m
        growth, shrink = config.max_lookahead_growth_m_per_m, config.max_lookahead_shrink_m_per_m
        self._rates = (math.nan if growth is None else growth, math.nan if shrink is None else shrink)
        self._state = np.full(2, np.nan)

    def reset(self) -> None:
        """Forget the last lookahead and floor: the next choice is taken as it is."""
        self._state[:] = np.nan

    def step(self, choice_m: float, floor_m: float, ceiling_m: float, distance_m: float) -> float:
        """The lookahead (m) for this step: choice_m filtered, within [floor_m, ceiling_m]; distance_m: travelled
        since the last step (m)."""
        return filtered_lookahead(
            self._state, choice_m, floor_m, ceiling_m, distance_m, self._hysteresis_m, *self._rates
        )
