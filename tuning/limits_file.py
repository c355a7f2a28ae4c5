"""The curvature-limits file: what `tuning rollover-limits` and `tuning steering-limits` write and a controller
config's `limits_file` names (CSV, one row per speed; the third column optional):

    speed_kmh,max_curvature_1pm,max_curvature_rate_1pm_s
    10,0.15,0.20
    ...
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from controllers.clothoid.curvature_limits import RATE_COLUMN, REQUIRED_COLUMNS, CurvatureLimits
from tuning.csv_columns import column_key, require_unique_columns
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.base.input_files import check_input_file
from workbench.vehicles.geometry import VehicleGeometry


def read_limits_file(path: str | Path, geometry: VehicleGeometry | None = None) -> CurvatureLimits:
    """Read a limits table; without a rate column, the rate comes from `CurvatureLimits.default_for(geometry)`."""
    path = check_input_file(path, f"curvature limits file {str(path)!r}")
    try:
        table = pd.read_csv(path, comment="#")
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        raise WorkbenchInputError(f"{path.name}: not a readable CSV file ({exc})") from None
    require_unique_columns(table.columns, path.name)
    table.columns = [column_key(c) for c in table.columns]
    missing = [c for c in REQUIRED_COLUMNS if c not in table.columns]
    if missing:
        raise WorkbenchInputError(
            f"{path.name}: missing column(s) {', '.join(missing)}; found {', '.join(table.columns)}; "
            f"expected {', '.join(REQUIRED_COLUMNS)}[, {RATE_COLUMN}]"
        )
    numeric = table.apply(pd.to_numeric, errors="coerce")
    if numeric.isna().to_numpy().any():
        row, col = np.argwhere(numeric.isna().to_numpy())[0]
        raise WorkbenchInputError(
            f"{path.name}: row {row + 1} column {table.columns[col]} is {value_text(table.iat[row, col])}, not a number"
        )
    if RATE_COLUMN in numeric.columns:
        rates = numeric[RATE_COLUMN].tolist()
    else:
        if geometry is None:
            raise WorkbenchInputError(f"{path.name}: no {RATE_COLUMN} column and no vehicle to derive it from")
        rates = [CurvatureLimits.default_for(geometry).max_curvature_rate_1pm_s[0]] * len(numeric)
    return CurvatureLimits(
        tuple(numeric["speed_kmh"].tolist()),
        tuple(numeric["max_curvature_1pm"].tolist()),
        tuple(rates),
        source=path.name,
    )


def write_limits_file(limits: CurvatureLimits, path: str | Path) -> Path:
    """Write `limits` as a limits file (all three columns) and return its path."""
    pd.DataFrame(
        {
            "speed_kmh": limits.speeds_kmh,
            "max_curvature_1pm": limits.max_curvature_1pm,
            RATE_COLUMN: limits.max_curvature_rate_1pm_s,
        }
    ).to_csv(path, index=False, float_format="%.9g")
    return Path(path)
