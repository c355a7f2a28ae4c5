"""Lead filters against speed (`FilterSchedule`): what the clothoid controller's lead filter (Eq. 6) is at each
speed, interpolated between the speeds it was designed for. Its file format is `tuning/filter_file.py`."""

from __future__ import annotations

import bisect
import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np

from controllers.clothoid.lead_filter import LeadFilterParams
from controllers.clothoid.speed_tables import table_row
from workbench.base.errors import WorkbenchInputError, require_in_range

PARAM_KEYS = ("omega_z_rad_s", "psi", "omega_p_rad_s")
SPEED_RANGE_KMH = (0.0, 300.0)

#: A reference filter, not the controller's default (an untuned controller runs no lead filter, a tuned one its
#: vehicle's schedule): the base the lead-filter scaling of studies scales when the run gives no filter and the
#: vehicle has no tuning (`workbench.apps.studies.lead_filter_scaling`). Eq. 6 designed by `from_lag` (zeros on the
#: lag's poles, triple pole at 3 wn = 13.32 rad/s) for a lag of omega_n = 4.44 rad/s, zeta = 0.80, a fit of Eq. 5 to
#: the loaded tractor-semitrailer preset at 30 km/h.
DEFAULT_FILTER = LeadFilterParams.from_lag(4.44, 0.80)


@dataclass(frozen=True)
class FilterSchedule:
    """Lead filters against speed, interpolated between the speeds they were designed for; a schedule of one entry
    gives the same filter at every speed."""

    speeds_kmh: tuple[float, ...]  # the design speeds (km/h), each in [0, 300], strictly increasing, at least one
    params: tuple[LeadFilterParams, ...]  # the lead filter (Eq. 6) at each speed, one per speed
    source: str = ""  # where the filters come from, in words (any text)

    def __post_init__(self) -> None:
        speeds, params = tuple(self.speeds_kmh), tuple(self.params)
        if not speeds or len(speeds) != len(params):
            raise WorkbenchInputError(
                f"a filter schedule needs one filter per speed and at least one; got {len(speeds)} speeds and "
                f"{len(params)} filters"
            )
        for i, (speed, p) in enumerate(zip(speeds, params, strict=True)):
            require_in_range(f"schedule[{i}].speed_kmh", speed, *SPEED_RANGE_KMH, "km/h")
            if not isinstance(p, LeadFilterParams):
                raise WorkbenchInputError(f"schedule[{i}] must be LeadFilterParams; got {p!r}")
        if any(b <= a for a, b in itertools.pairwise(speeds)):
            raise WorkbenchInputError(f"schedule speeds_kmh must be strictly increasing; got {list(speeds)}")
        object.__setattr__(self, "speeds_kmh", tuple(float(s) for s in speeds))
        object.__setattr__(self, "params", params)

    @classmethod
    def single(cls, params: LeadFilterParams, speed_kmh: float = 0.0, source: str = "") -> FilterSchedule:
        """One filter for every speed (speed_kmh, km/h, is only its label).

        Parameters
        ----------
        params : LeadFilterParams
            The lead filter of Eq. 6.
        speed_kmh : float, km/h
            The speed the filter is labelled with, 0-300 km/h.
        source : str
            Where the filter comes from ("": not said).

        Returns
        -------
        FilterSchedule
            A schedule of one entry, whose `at_speed` is ``params`` at every speed.

        Raises
        ------
        WorkbenchInputError
            speed_kmh outside 0-300 km/h, or params not a LeadFilterParams.
        """
        return cls((speed_kmh,), (params,), source)

    def at_speed(self, speed_kmh: float) -> LeadFilterParams:
        """The filter at speed_kmh (km/h): each parameter interpolated linearly in speed, clamped at the ends.
        (The parameter ranges and wp / wz bounds are convex, so interpolated filters are valid too.)

        Parameters
        ----------
        speed_kmh : float, km/h
            The speed, finite; below the first speed or above the last, that speed's filter holds.

        Returns
        -------
        LeadFilterParams
            The filter at that speed.

        Raises
        ------
        WorkbenchInputError
            speed_kmh is NaN or infinite.

        Examples
        --------
        >>> from controllers.clothoid import FilterSchedule, LeadFilterParams
        >>> schedule = FilterSchedule(
        ...     (30.0, 60.0), (LeadFilterParams(10.0, 0.6, 40.0), LeadFilterParams(8.0, 0.7, 30.0))
        ... )
        >>> p = schedule.at_speed(45.0)
        >>> round(p.omega_z_rad_s, 6), round(p.psi, 6), round(p.omega_p_rad_s, 6)
        (9.0, 0.65, 35.0)
        >>> schedule.at_speed(100.0) == schedule.params[-1]
        True
        """
        speeds = self.speeds_kmh
        if not math.isfinite(speed_kmh):
            raise WorkbenchInputError(f"speed_kmh must be a finite number; got {speed_kmh!r}")
        i = bisect.bisect_left(speeds, speed_kmh)
        if i < len(speeds) and speeds[i] == speed_kmh:
            return self.params[i]
        if i == 0:
            return self.params[0]
        if i == len(speeds):
            return self.params[-1]
        table_speeds, rows = self.table
        out = np.empty(len(PARAM_KEYS))
        table_row(table_speeds, rows, float(speed_kmh), True, out)  # kept between its neighbours' values
        return LeadFilterParams(*out.tolist())

    @functools.cached_property
    def table(self) -> tuple[np.ndarray, np.ndarray]:
        """(speeds km/h (n,), parameters (n, 3) in PARAM_KEYS order): the schedule as `speed_tables.table_row`
        reads it (the compiled step's feed-forward timing too)."""
        rows = [[getattr(p, k) for k in PARAM_KEYS] for p in self.params]
        return np.array(self.speeds_kmh, dtype=float), np.array(rows, dtype=float).reshape(-1, len(PARAM_KEYS))
