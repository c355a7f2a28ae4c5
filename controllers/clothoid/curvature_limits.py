"""Speed-dependent curvature and curvature-rate limits of the clothoid controller's integrator (paper, section 4).

The controller integrates dkappa/dt = kappa' V (Figure 2) and saturates both the rate and the curvature. The
limits come from a table, one row per speed, linearly interpolated (clamped beyond the ends):

    speed_kmh,max_curvature_1pm,max_curvature_rate_1pm_s
    10,0.15,0.20
    ...

`tuning rollover-limits` writes this file from step-steer tests (the curvature at which LTR reaches 1, Figure 6);
the third column is optional. Until a vehicle has been tuned, `CurvatureLimits.default_for` gives a documented
default from the vehicle's geometry: the curvature at the steering lock, a lateral-acceleration bound a/v^2, and
the curvature rate the steering-wheel rate limit allows at small angles, (rate / steering ratio) / wheelbase.
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np
from scipy.constants import g as G_MPS2  # standard gravity, 9.80665 m/s^2

from controllers.clothoid.speed_tables import table_row
from workbench.base.errors import WorkbenchInputError, require_positive, value_text
from workbench.vehicles.geometry import VehicleGeometry

REQUIRED_COLUMNS = ("speed_kmh", "max_curvature_1pm")
RATE_COLUMN = "max_curvature_rate_1pm_s"
#: Lateral acceleration bound (g) of the default limits: above the paper's 0.3 g speed-planning bound and below
#: the loaded truck preset's static rollover threshold (0.45 g) and dynamic thresholds ~25% lower (SAE 2003-01-3385).
DEFAULT_LIMIT_LATERAL_ACCEL_G = 0.4


@dataclass(frozen=True)
class CurvatureLimits:
    """Tables of the curvature limit and the curvature-rate limit against speed, one entry of each per speed,
    linearly interpolated in speed and clamped beyond the table's ends."""

    speeds_kmh: tuple[float, ...]  # the table's speeds (km/h), finite, >= 0 and strictly increasing
    max_curvature_1pm: tuple[float, ...]  # the curvature limit at each speed (1/m), finite and > 0
    max_curvature_rate_1pm_s: tuple[float, ...]  # the curvature-rate limit at each speed (1/(m s)), finite and > 0
    source: str = "table"  # where the table comes from, which starts every message (any text)

    def __post_init__(self) -> None:
        n = len(self.speeds_kmh)
        if n == 0 or len(self.max_curvature_1pm) != n or len(self.max_curvature_rate_1pm_s) != n:
            raise WorkbenchInputError(
                f"{self.source}: the limit table needs one curvature and one rate per speed; got {n} speeds, "
                f"{len(self.max_curvature_1pm)} curvatures, {len(self.max_curvature_rate_1pm_s)} rates"
            )
        for name, values in (
            ("speed_kmh", self.speeds_kmh),
            ("max_curvature_1pm", self.max_curvature_1pm),
            ("max_curvature_rate_1pm_s", self.max_curvature_rate_1pm_s),
        ):
            for i, value in enumerate(values):
                if not (math.isfinite(value) and (value > 0 or (name == "speed_kmh" and value == 0))):
                    raise WorkbenchInputError(
                        f"{self.source}: {name} must be finite and > 0; row {i} has {value_text(value)}"
                    )
        if any(b <= a for a, b in itertools.pairwise(self.speeds_kmh)):
            speeds = ", ".join(value_text(v) for v in self.speeds_kmh)
            raise WorkbenchInputError(f"{self.source}: speed_kmh must increase strictly; got [{speeds}]")

    def at_speed(self, speed_mps: float) -> tuple[float, float]:
        """(max curvature 1/m, max curvature rate 1/(m s)) at this speed (m/s), interpolated.

        Parameters
        ----------
        speed_mps : float, m/s
            The speed, finite; below the table's first speed or above its last, that row's limits hold.

        Returns
        -------
        max_curvature_1pm : float, 1/m
            The curvature limit, linearly interpolated in speed.
        max_curvature_rate_1pm_s : float, 1/(m s)
            The curvature-rate limit, linearly interpolated in speed.

        Examples
        --------
        >>> from controllers.clothoid import CurvatureLimits
        >>> limits = CurvatureLimits((10.0, 50.0), (0.15, 0.02), (0.2, 0.1))
        >>> [round(value, 4) for value in limits.at_speed(30.0 / 3.6)]
        [0.085, 0.15]
        """
        speeds, rows = self.table
        out = np.empty(2)
        table_row(speeds, rows, speed_mps * 3.6, False, out)
        kappa, rate = out.tolist()
        return kappa, rate

    @functools.cached_property
    def table(self) -> tuple[np.ndarray, np.ndarray]:
        """(speeds km/h (n,), rows (n, 2): max curvature, max curvature rate): the table as
        `speed_tables.table_row` reads it (the compiled step too)."""
        rows = np.column_stack([self.max_curvature_1pm, self.max_curvature_rate_1pm_s]).astype(float)
        return np.array(self.speeds_kmh, dtype=float), rows

    @classmethod
    def default_for(
        cls, geometry: VehicleGeometry, max_lateral_accel_g: float = DEFAULT_LIMIT_LATERAL_ACCEL_G
    ) -> CurvatureLimits:
        """Limits from the vehicle's geometry (see the module docstring), tabulated from 0 to 150 km/h.

        Parameters
        ----------
        geometry : VehicleGeometry
            The vehicle's wheelbase, steering ratio, largest road-wheel angle and steering-wheel rate limit.
        max_lateral_accel_g : float, g
            The lateral-acceleration bound a / v^2 of the curvature limit, > 0.

        Returns
        -------
        CurvatureLimits
            Rows every 5 km/h from 0 to 150 km/h: the curvature limit min(lock, a / v^2) and the constant rate
            limit (steering-wheel rate / steering ratio) / wheelbase.

        Raises
        ------
        WorkbenchInputError
            max_lateral_accel_g is not a finite number > 0.
        """
        require_positive("max_lateral_accel_g", max_lateral_accel_g)
        speeds = np.arange(0.0, 151.0, 5.0)
        lock = math.tan(geometry.max_road_wheel_angle_rad) / geometry.wheelbase_m
        v = np.maximum(speeds / 3.6, 1e-6)
        kappa = np.minimum(lock, max_lateral_accel_g * G_MPS2 / v**2)
        rate = geometry.max_steer_wheel_rate_rad_s / geometry.steering_ratio / geometry.wheelbase_m
        return cls(
            tuple(speeds.tolist()),
            tuple(kappa.tolist()),
            tuple([rate] * speeds.size),
            source=f"default limits (steering lock, {max_lateral_accel_g:g} g, steering-rate limit)",
        )
