"""A run's trace file (`result.py`): written with pyarrow alone, read back by pandas exactly as it was logged."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from workbench.simulation.result import _write_parquet


def test_the_trace_file_holds_every_signal_exactly_in_order(tmp_path: Path) -> None:
    rng = np.random.default_rng(7)
    trace = {
        "t_s": np.arange(500) * 0.02,
        "cte_m": rng.normal(size=500),
        "flag": rng.normal(size=500) > 0.0,  # not a number type: pyarrow's own conversion
        "count": np.arange(500, dtype=np.int64),
        "strided": rng.normal(size=1000)[::2],  # not contiguous
        "nan": np.full(500, np.nan),
    }
    _write_parquet(trace, tmp_path / "trace.parquet")
    table = pd.read_parquet(tmp_path / "trace.parquet")
    assert list(table.columns) == list(trace)
    for name, values in trace.items():
        np.testing.assert_array_equal(table[name].to_numpy(), values, err_msg=name)
        assert table[name].dtype == values.dtype, name
