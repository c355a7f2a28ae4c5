"""The run store: rows written atomically and read back exactly; leftovers of an interrupted write ignored."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from workbench.apps.studies.runner import RESULT_COLUMNS
from workbench.apps.studies.store import RunStore, rows_frame, write_results


def _row(run_id: str, **extra: object) -> dict[str, object]:
    return {"run_id": run_id, "index": 0, "speed_kmh": 30.0} | dict.fromkeys(RESULT_COLUMNS) | extra


def test_rows_round_trip_bit_for_bit(tmp_path: Path) -> None:
    store = RunStore(tmp_path)
    row = _row("a", rms_cte_m=0.1 + 0.2, max_ltr=1e-310, distance_m=math.nan, status="completed", completed=True)
    store.write(row)
    back = store.read(["a", "b"])
    assert set(back) == {"a"}
    assert back["a"]["rms_cte_m"] == 0.1 + 0.2 and back["a"]["max_ltr"] == 1e-310
    assert math.isnan(back["a"]["distance_m"]) and back["a"]["completed"] is True
    assert list(back["a"]) == list(row)


def test_interrupted_and_damaged_rows_are_not_results(tmp_path: Path) -> None:
    store = RunStore(tmp_path)
    store.write(_row("good"))
    (store.runs_dir / ".half.123.tmp").write_text('{"run_id": "half"')  # a write cut short
    store.path("broken").write_text('{"run_id": "broken", "rms')  # damaged by hand
    store.path("other").write_text('{"run_id": "not-other"}')  # a row under another run's name
    assert set(store.read(["good", "half", "broken", "other"])) == {"good"}
    assert store.clean_temporaries() == 1
    assert not list(store.runs_dir.glob(".*"))


def test_the_results_table_orders_parameters_before_metrics(tmp_path: Path) -> None:
    rows = [_row("a", status="completed"), _row("b", **{"clothoid.frechet_threshold_m": 0.5, "status": "error"})]
    frame = rows_frame(rows)
    assert list(frame.columns) == ["run_id", "index", "speed_kmh", "clothoid.frechet_threshold_m", *RESULT_COLUMNS]
    assert math.isnan(frame.loc[0, "clothoid.frechet_threshold_m"])
    path = write_results(tmp_path, rows)
    pd.testing.assert_frame_equal(pd.read_parquet(path), frame)
