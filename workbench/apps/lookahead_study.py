"""The paper's lookahead analyses: Fréchet distance against lookahead distance (Figure 4b) and the minimum
Fréchet distance against the initial cross-track error (Figure 5b).

A vehicle is placed at arc length s on a path, offset laterally by a CTE (left positive) and turned by a heading
error, with the path's curvature there as its own; every candidate lookahead is scored exactly as the clothoid
controller scores it (`controllers.clothoid.lookahead`), over the controller's own candidates, kappa' saturation and
threshold (the `ClothoidConfig` defaults).

Where the path's curvature stays what the vehicle's is (a straight, the middle of an arc), the fitted clothoid is the
path itself and the Fréchet distance is zero at every lookahead; it grows with the lookahead where the curvature
ahead changes (a bend's entry or exit). `growing_stretch` finds the place on a path where it grows most across the
candidates while crossing the threshold among them: the stretch on which Figure 4b shows what the threshold does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from controllers.clothoid.controller import ClothoidConfig
from controllers.clothoid.lookahead import LookaheadEvaluator
from workbench.base.errors import WorkbenchInputError, require_finite, require_in_range, require_positive
from workbench.base.path import ReferencePath

if TYPE_CHECKING:
    from matplotlib.axes import Axes

#: The clothoid controller's defaults, which the analyses use unless told otherwise.
CONTROLLER_DEFAULTS = ClothoidConfig()
#: The controller's candidate lookaheads (m): its default range (the paper's 5-20 m, section 3) on its search grid.
DEFAULT_LOOKAHEADS_M = np.arange(
    CONTROLLER_DEFAULTS.min_lookahead_m,
    CONTROLLER_DEFAULTS.max_lookahead_m + 1e-9 * CONTROLLER_DEFAULTS.lookahead_step_m,
    CONTROLLER_DEFAULTS.lookahead_step_m,
)
#: The controller's default saturation of the clothoid's kappa' (1/m^2).
DEFAULT_MAX_CURVATURE_RATE_1PM2 = CONTROLLER_DEFAULTS.max_curvature_rate_1pm2
#: The controller's default Fréchet threshold (m; the paper's is 0.5 m): the largest lookahead whose Fréchet distance
#: stays within it is the one the adaptive search picks.
DEFAULT_FRECHET_THRESHOLD_M = CONTROLLER_DEFAULTS.frechet_threshold_m
#: Spacing (m) of the places `growing_stretch` tries along a path.
STRETCH_STEP_M = 1.0


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
    #: Where on the path (arc length, m).
    s_m: float = math.nan

    def to_pandas(self) -> pd.DataFrame:
        """The curve as a table.

        Returns
        -------
        pandas.DataFrame
            lookahead_m and frechet_m, one row per candidate.
        """
        return pd.DataFrame({"lookahead_m": self.lookahead_m, "frechet_m": self.frechet_m})

    def chosen_lookahead_m(self, threshold_m: float = DEFAULT_FRECHET_THRESHOLD_M) -> float:
        """The largest lookahead (m) whose Fréchet distance stays within threshold_m, as the adaptive search picks
        it (before the end-point tolerances, the floor and the filter); NaN when none does.

        Parameters
        ----------
        threshold_m : float
            The Fréchet threshold (m), positive (default: the controller's).

        Returns
        -------
        float
            The lookahead (m), or NaN.

        Examples
        --------
        >>> import numpy as np
        >>> from workbench.apps.lookahead_study import FrechetVsLookahead
        >>> curve = FrechetVsLookahead(np.array([5.0, 10.0, 15.0, 20.0]), np.array([0.0, 0.01, 0.04, 0.09]), "bend")
        >>> curve.chosen_lookahead_m(0.05), curve.crosses(0.05)
        (15.0, True)
        """
        within = np.flatnonzero(self.frechet_m <= threshold_m)
        return float(self.lookahead_m[within[-1]]) if within.size else math.nan

    def crosses(self, threshold_m: float = DEFAULT_FRECHET_THRESHOLD_M) -> bool:
        """Whether the Fréchet distance starts within threshold_m and ends above it (the threshold then picks a
        lookahead inside the range).

        Parameters
        ----------
        threshold_m : float
            The Fréchet threshold (m), positive (default: the controller's).

        Returns
        -------
        bool
            True when the first candidate is within it and the last is above.
        """
        return bool(self.frechet_m[0] <= threshold_m < self.frechet_m[-1])

    def plot(self, ax: Axes | None = None, threshold_m: float | None = DEFAULT_FRECHET_THRESHOLD_M) -> Axes:
        """The Fréchet distance against the lookahead; with threshold_m (the controller's default unless given; None:
        none), the threshold and the lookahead it picks. The axis runs from 0 to above the larger of the curve and
        the threshold, so both show.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            The axes to draw on (None: a fresh pyplot figure's).
        threshold_m : float or None
            The Fréchet threshold (m) drawn, with the lookahead it picks (None: neither).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4), layout="constrained")
        ax.plot(self.lookahead_m, self.frechet_m, "o-", ms=3, label=self.label)
        top = float(np.max(self.frechet_m))
        if threshold_m is not None:
            ax.axhline(threshold_m, color="k", ls="--", lw=0.8, label=f"threshold {threshold_m:g} m")
            chosen = self.chosen_lookahead_m(threshold_m)
            if math.isfinite(chosen) and chosen < self.lookahead_m[-1]:
                ax.axvline(chosen, color="tab:red", ls=":", lw=1.0, label=f"lookahead picked: {chosen:g} m")
            top = max(top, threshold_m)
        ax.set_ylim(0.0, 1.1 * top if top > 0.0 else 1.0)
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
    """Score every lookahead for a vehicle at s (offset by cte, turned by heading_error, on the path's curvature).

    Parameters
    ----------
    path : ReferencePath
        The reference path.
    s_m : float
        Arc length (m) of the vehicle's place on the path.
    cte_m : float
        The vehicle's lateral offset (m) from the path, left positive.
    heading_error_rad : float
        The vehicle's heading error (rad) from the path's heading.
    lookaheads_m : numpy.ndarray
        The candidate lookaheads (m), increasing (default: the controller's).
    max_curvature_rate_1pm2 : float
        The clothoid's kappa' saturation (1/m^2; default: the controller's).

    Returns
    -------
    FrechetVsLookahead
        The Fréchet distance (m) of each candidate.

    Raises
    ------
    WorkbenchInputError
        s_m outside the path, or an offset or heading error not finite.
    """
    evaluator = LookaheadEvaluator(path)
    x, y, heading = _pose(path, s_m, cte_m, heading_error_rad)
    kappa = float(path.curvature(s_m))
    fd = np.array(
        [
            evaluator.evaluate(s_m, x, y, heading, kappa, float(la), max_curvature_rate_1pm2).frechet_m
            for la in lookaheads_m
        ]
    )
    label = f"s = {s_m:.4g} m, CTE {cte_m:g} m, curvature {kappa:.3g} 1/m"
    return FrechetVsLookahead(np.asarray(lookaheads_m, dtype=float), fd, label, s_m)


def growing_stretch(
    path: ReferencePath,
    threshold_m: float = DEFAULT_FRECHET_THRESHOLD_M,
    lookaheads_m: np.ndarray = DEFAULT_LOOKAHEADS_M,
    max_curvature_rate_1pm2: float = DEFAULT_MAX_CURVATURE_RATE_1PM2,
    step_m: float = STRETCH_STEP_M,
) -> FrechetVsLookahead:
    """Figure 4b's stretch: of the places on the path every step_m (a vehicle on the path, at its curvature), the one
    whose Fréchet distance crosses threshold_m among the lookaheads and grows most across them (where the curvature
    ahead changes most within the lookahead range). Refused for a path without such a place (a straight, a circle).

    Parameters
    ----------
    path : ReferencePath
        The reference path.
    threshold_m : float
        The Fréchet threshold (m), positive.
    lookaheads_m : numpy.ndarray
        The candidate lookaheads (m), increasing.
    max_curvature_rate_1pm2 : float
        The clothoid's kappa' saturation (1/m^2).
    step_m : float
        Spacing (m) of the places tried, positive.

    Returns
    -------
    FrechetVsLookahead
        The curve at the place found.

    Raises
    ------
    WorkbenchInputError
        threshold_m or step_m not positive, or no place where the curve crosses the threshold.
    """
    require_positive("threshold_m", threshold_m)
    require_positive("step_m", step_m)
    best: FrechetVsLookahead | None = None
    for s_m in np.arange(0.0, path.length_m, step_m):
        sweep = frechet_vs_lookahead(path, float(s_m), 0.0, 0.0, lookaheads_m, max_curvature_rate_1pm2)
        growth = sweep.frechet_m[-1] - sweep.frechet_m[0]
        if sweep.crosses(threshold_m) and (best is None or growth > best.frechet_m[-1] - best.frechet_m[0]):
            best = sweep
    if best is None:
        raise WorkbenchInputError(
            f"no place on path {path.name!r} where the Fréchet distance crosses the threshold {threshold_m:g} m "
            f"between lookaheads of {lookaheads_m[0]:g} and {lookaheads_m[-1]:g} m (its curvature ahead never changes "
            "enough)"
        )
    return best


@dataclass(frozen=True, eq=False)
class MinFrechetVsCte:
    """Figure 5b: the least Fréchet distance over the candidate lookaheads (m) against the initial CTE (m)."""

    cte_m: np.ndarray
    min_frechet_m: np.ndarray
    best_lookahead_m: np.ndarray

    def to_pandas(self) -> pd.DataFrame:
        """The curve as a table.

        Returns
        -------
        pandas.DataFrame
            cte_m, min_frechet_m and best_lookahead_m, one row per initial CTE.
        """
        return pd.DataFrame(
            {"cte_m": self.cte_m, "min_frechet_m": self.min_frechet_m, "best_lookahead_m": self.best_lookahead_m}
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Figure 5b: the minimum Fréchet distance against the initial CTE.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            The axes to draw on (None: a fresh pyplot figure's).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
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
    """For each initial CTE, the least Fréchet distance over the lookaheads and the lookahead that gives it.

    Parameters
    ----------
    path : ReferencePath
        The reference path.
    s_m : float
        Arc length (m) of the vehicle's place on the path.
    ctes_m : numpy.ndarray
        The initial lateral offsets (m), left positive.
    heading_error_rad : float
        The vehicle's heading error (rad) from the path's heading.
    lookaheads_m : numpy.ndarray
        The candidate lookaheads (m), increasing (default: the controller's).
    max_curvature_rate_1pm2 : float
        The clothoid's kappa' saturation (1/m^2; default: the controller's).

    Returns
    -------
    MinFrechetVsCte
        One point per initial CTE.

    Raises
    ------
    WorkbenchInputError
        s_m outside the path, or an offset or heading error not finite.
    """
    best, where = [], []
    for cte in ctes_m:
        sweep = frechet_vs_lookahead(path, s_m, float(cte), heading_error_rad, lookaheads_m, max_curvature_rate_1pm2)
        k = int(np.argmin(sweep.frechet_m))
        best.append(sweep.frechet_m[k])
        where.append(sweep.lookahead_m[k])
    return MinFrechetVsCte(np.asarray(ctes_m, dtype=float), np.array(best), np.array(where))
