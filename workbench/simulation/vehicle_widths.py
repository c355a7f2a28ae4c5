"""The vehicle widths (m) the scenarios size lanes and tracks for: `ScenarioOptions` refuses a width outside them,
and a generated circuit's clearance (`CircuitRanges.clearance_m`) makes room for the track of the widest.
"""

from __future__ import annotations

#: The vehicle widths (m) the scenarios size lanes and tracks for.
VEHICLE_WIDTH_RANGE_M = (0.5, 4.0)

__all__ = ["VEHICLE_WIDTH_RANGE_M"]
