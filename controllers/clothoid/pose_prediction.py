"""A pose moved along an arc (Figure 2, step 5): where a vehicle driving a constant curvature will be after a
distance. The controller predicts its own start pose this way, and `path_feedforward.py` its reference pose."""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def along_arc(
    x_m: float, y_m: float, heading_rad: float, curvature_1pm: float, distance_m: float
) -> tuple[float, float, float]:  # pragma: no cover - compiled
    """(x, y, heading) after distance_m on an arc of curvature_1pm, by the arc's chord (exact for any curvature;
    a straight line below a half turn of 1e-9 rad). Compiled: the controller's step calls it."""
    half_turn = 0.5 * curvature_1pm * distance_m
    chord = distance_m * (math.sin(half_turn) / half_turn if abs(half_turn) > 1e-9 else 1.0)
    return (
        x_m + chord * math.cos(heading_rad + half_turn),
        y_m + chord * math.sin(heading_rad + half_turn),
        heading_rad + 2.0 * half_turn,
    )
