"""The paper's lookahead analyses: Fréchet distance against lookahead distance (Figure 4b) and the minimum
Fréchet distance against the initial cross-track error (Figure 5b).

A vehicle is placed at arc length s on a path, offset laterally by a CTE (left positive) and turned by a heading
error, with the path's curvature there as its own; every candidate lookahead is scored exactly as the clothoid
controller scores it (`controllers.clothoid.lookahead`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from controllers.clothoid.lookahead import LookaheadEvaluator
from workbench.base.errors import require_finite, require_in_range
from workbench.base.path import ReferencePath

if TYPE_CHECKING:
    from matplotlib.axes import Axes

#: The paper's candidate range (section 3) and the clothoid controller's default kappa' saturation.
DEFAULT_LOOKAHEADS_M = np.arange(5.0, 20.0 + 1e-9, 0.5)
DEFAULT_MAX_CURVATURE_RATE_1PM2 = 0.05


def _pose(path: ReferencePath, s_m: float, cte_m: float, heading_error_rad: float) -> tuple[float, float, float]:
    require_in_range("s_m", s_m, 0.0, path.length_m, "m")
    require_finite("cte_m", cte_m)
    require_finite("heading_error_rad", heading_error_rad)
    x, y = path.position(s_m)
    heading = float(path.heading(s_m))
    return float(x) - cte_m * math.sin(heading), float(y) + cte_m * math.cos(heading), heading + heading_error_rad


@dataclass(frozen=True, eq=False)
class FrechetVsLookahead:
    """Figure 4b: the Fréchet distance (m) of each candidate lookahead (m) at one vehicle state."""

    lookahead_m: np.ndarray
    frechet_m: np.ndarray
    label: str

    def to_pandas(self) -> pd.DataFrame:
        return pd.DataFrame({"lookahead_m": self.lookahead_m, "frechet_m": self.frechet_m})

    def plot(self, ax: Axes | None = None, threshold_m: float | None = 0.5) -> Axes:
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4), layout="constrained")
        ax.plot(self.lookahead_m, self.frechet_m, "o-", ms=3, label=self.label)
        if threshold_m is not None:
            ax.axhline(threshold_m, color="k", ls="--", lw=0.8, label=f"threshold {threshold_m:g} m")
        ax.set(xlabel="lookahead distance (m)", ylabel="Fréchet distance (m)", title="Fréchet distance vs lookahead")
        ax.legend(fontsize="small")
        return ax


def frechet_vs_lookahead(
    path: ReferencePath,
    s_m: float,
    cte_m: float = 0.0,
    heading_error_rad: float = 0.0,
    lookaheads_m: np.ndarray = DEFAULT_LOOKAHEADS_M,
    max_curvature_rate_1pm2: float = DEFAULT_MAX_CURVATURE_RATE_1PM2,
) -> FrechetVsLookahead:
    """Score every lookahead for a vehicle at s (offset by cte, turned by heading_error, on the path's curvature)."""
    evaluator = LookaheadEvaluator(path)
    x, y, heading = _pose(path, s_m, cte_m, heading_error_rad)
    kappa = float(path.curvature(s_m))
    fd = np.array(
        [
            evaluator.evaluate(s_m, x, y, heading, kappa, float(la), max_curvature_rate_1pm2).frechet_m
            for la in lookaheads_m
        ]
    )
    label = f"s = {s_m:g} m, CTE {cte_m:g} m, curvature {kappa:.3g} 1/m"
    return FrechetVsLookahead(np.asarray(lookaheads_m, dtype=float), fd, label)


@dataclass(frozen=True, eq=False)
class MinFrechetVsCte:
    """Figure 5b: the least Fréchet distance over the candidate lookaheads (m) against the initial CTE (m)."""

    cte_m: np.ndarray
    min_frechet_m: np.ndarray
    best_lookahead_m: np.ndarray

    def to_pandas(self) -> pd.DataFrame:
        return pd.DataFrame(
            {"cte_m": self.cte_m, "min_frechet_m": self.min_frechet_m, "best_lookahead_m": self.best_lookahead_m}
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4), layout="constrained")
        ax.plot(self.cte_m, self.min_frechet_m, "o-", ms=3)
        ax.set(
            xlabel="initial cross-track error (m)",
            ylabel="minimum Fréchet distance (m)",
            title="Minimum Fréchet distance vs initial CTE",
        )
        return ax


def min_frechet_vs_cte(
    path: ReferencePath,
    s_m: float,
    ctes_m: np.ndarray,
    heading_error_rad: float = 0.0,
    lookaheads_m: np.ndarray = DEFAULT_LOOKAHEADS_M,
    max_curvature_rate_1pm2: float = DEFAULT_MAX_CURVATURE_RATE_1PM2,
) -> MinFrechetVsCte:
    """For each initial CTE, the least Fréchet distance over the lookaheads and the lookahead that gives it."""
    best, where = [], []
    for cte in ctes_m:
        sweep = frechet_vs_lookahead(path, s_m, float(cte), heading_error_rad, lookaheads_m, max_curvature_rate_1pm2)
        k = int(np.argmin(sweep.frechet_m))
        best.append(sweep.frechet_m[k])
        where.append(sweep.lookahead_m[k])
    return MinFrechetVsCte(np.asarray(ctes_m, dtype=float), np.array(best), np.array(where))
