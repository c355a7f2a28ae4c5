"""The path as the prediction sees it: per interval k of the horizon, the path curvature and the speed at the
vehicle's own predicted progress.

For interval k, with s_0 the foot point's arc length and p_k the predicted progress at node k (from the previous
plan, so an offset or a heading error moves the samples as it should), the path is read at the interval's middle
s_k = s_0 + (p_k + p_{k+1}) / 2:

    kappa_k = kappa_path(s_k),    v_k = max(v_0 + v_plan(s_k) - v_plan(s_0), v_min),

with v_0 the measured speed: the prediction follows the speed profile's changes from where the vehicle is, not
its absolute value. The path's samples are on a uniform arc-length grid, read by linear interpolation, wrapped
on a closed loop and clipped at the ends of an open path. Compiled with numba: this runs on every MPC step, where
the same work in small numpy calls costs 30-40 us.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from workbench.base.path import ReferencePath


class PathPreview:
    """The reset path's curvature and planned speed (zero when it has none), ready for `along`."""

    def __init__(self, path: ReferencePath) -> None:
        speed = path.speed_mps if path.speed_mps is not None else np.zeros_like(path.curvature_1pm)
        self.samples = np.ascontiguousarray(np.column_stack((path.curvature_1pm, speed)), dtype=float)
        self.spacing_m, self.length_m, self.closed = float(path.spacing_m), float(path.length_m), bool(path.closed)

    def along(self, s0_m: float, progress_m: np.ndarray, v0_mps: float, min_speed_mps: float) -> np.ndarray:
        """(N, 2): kappa_k (1/m) and v_k (m/s) per interval (module docstring) for progress p (N+1,) in m."""
        return _along(self.samples, self.spacing_m, self.length_m, self.closed, s0_m, progress_m, v0_mps, min_speed_mps)


@njit(cache=True)
def _sample(
    samples: np.ndarray, spacing_m: float, length_m: float, closed: bool, s_m: float
) -> tuple[float, float]:  # pragma: no cover - compiled
    """(curvature, planned speed) at arc length s_m, linearly interpolated on the uniform grid."""
    s_m = s_m % length_m if closed else min(max(s_m, 0.0), length_m)
    position = s_m / spacing_m
    i = min(int(position), samples.shape[0] - 2)
    frac = position - i
    return (
        samples[i, 0] * (1.0 - frac) + samples[i + 1, 0] * frac,
        samples[i, 1] * (1.0 - frac) + samples[i + 1, 1] * frac,
    )


@njit(cache=True)
def _along(
    samples: np.ndarray,
    spacing_m: float,
    length_m: float,
    closed: bool,
    s0_m: float,
    progress_m: np.ndarray,
    v0_mps: float,
    min_speed_mps: float,
) -> np.ndarray:  # pragma: no cover - compiled
    """`PathPreview.along` (the module docstring's kappa_k, v_k)."""
    n = progress_m.shape[0] - 1
    out = np.empty((n, 2))
    planned_now = _sample(samples, spacing_m, length_m, closed, s0_m)[1]
    for k in range(n):
        kappa, planned = _sample(samples, spacing_m, length_m, closed, s0_m + 0.5 * (progress_m[k] + progress_m[k + 1]))
        out[k, 0] = kappa
        out[k, 1] = max(v0_mps + planned - planned_now, min_speed_mps)
    return out
