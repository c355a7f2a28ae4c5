"""A study's results on disk: one JSON file per finished run under DIR/runs/, and DIR/results.parquet assembled
from them.

Each row is written as soon as its run finishes, to a temporary name then renamed into place (`os.replace`, atomic
on one file system), so a sweep killed at any moment leaves only whole rows behind. A restart reads the rows that
are there and runs only the others; files it cannot read (a half-written temporary, a damaged row) are ignored
and their runs redone. Floats survive the JSON round trip exactly (shortest repr), so a row read back equals the
row written, bit for bit.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from workbench.apps.studies.runner import RESULT_COLUMNS
from workbench.base.errors import WorkbenchInputError

RUNS_DIR = "runs"
RESULTS_FILE = "results.parquet"
_TMP_SUFFIX = ".tmp"


class RunStore:
    """The rows of a study under out_dir/runs/<run_id>.json.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The study's folder; out_dir/runs/ is made if missing.

    Raises
    ------
    WorkbenchInputError
        out_dir/runs/ cannot be created.
    """

    def __init__(self, out_dir: str | Path) -> None:
        self.out_dir = Path(out_dir)
        self.runs_dir = self.out_dir / RUNS_DIR
        try:
            self.runs_dir.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise WorkbenchInputError(f"cannot create the output folder {str(self.runs_dir)!r}: {exc}") from None

    def path(self, run_id: str) -> Path:
        """Where a run's row is kept.

        Parameters
        ----------
        run_id : str
            The run's id (`PlannedRun.run_id`).

        Returns
        -------
        pathlib.Path
            out_dir/runs/<run_id>.json.
        """
        return self.runs_dir / f"{run_id}.json"

    def read(self, run_ids: Iterable[str]) -> dict[str, dict[str, Any]]:
        """The finished rows among run_ids (run_id -> row); runs without a readable row are left out.

        Parameters
        ----------
        run_ids : iterable of str
            The runs asked for.

        Returns
        -------
        dict of str to dict
            run_id -> its row, for each run whose file holds a JSON row of that run_id (others run again).
        """
        rows = {}
        for run_id in run_ids:
            try:
                row = json.loads(self.path(run_id).read_text(encoding="utf-8"))
            except (OSError, ValueError, RecursionError):  # unreadable, not JSON, nested too deep: redo the run
                continue
            if isinstance(row, dict) and row.get("run_id") == run_id:
                rows[run_id] = row
        return rows

    def write(self, row: Mapping[str, Any]) -> Path:
        """Write one run's row atomically; return its path.

        Parameters
        ----------
        row : mapping
            The run's row (`runner.execute_run`), with its run_id; JSON-serialisable.

        Returns
        -------
        pathlib.Path
            The row's file (`path`), replaced whole: a reader never sees half a row.
        """
        run_id = str(row["run_id"])
        final = self.path(run_id)
        tmp = final.with_name(f".{run_id}.{os.getpid()}{_TMP_SUFFIX}")
        tmp.write_text(json.dumps(dict(row), indent=1) + "\n", encoding="utf-8")
        os.replace(tmp, final)
        return final

    def clean_temporaries(self) -> int:
        """Remove temporaries left by an interrupted write; return how many.

        Returns
        -------
        int
            The number of files removed.
        """
        count = 0
        for tmp in self.runs_dir.glob(f".*{_TMP_SUFFIX}"):
            tmp.unlink(missing_ok=True)
            count += 1
        return count


def rows_frame(rows: Sequence[Mapping[str, Any]]) -> pd.DataFrame:
    """Rows as a DataFrame in the given order: the parameter columns in the order they first appear, then the
    metrics, status, message, traceback and run_time_s (RESULT_COLUMNS); a key a row lacks (another controller's
    option) is null there.

    Parameters
    ----------
    rows : sequence of mapping
        The runs' rows, in the order of the table.

    Returns
    -------
    pandas.DataFrame
        One row per run.
    """
    columns: dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(k for k in row if k not in RESULT_COLUMNS))
    columns.update(dict.fromkeys(RESULT_COLUMNS))
    return pd.DataFrame([dict(row) for row in rows], columns=list(columns))


def write_results(out_dir: str | Path, rows: Sequence[Mapping[str, Any]]) -> Path:
    """Write out_dir/results.parquet from the rows (one per run, in the study's order); return its path.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The study's folder (it exists).
    rows : sequence of mapping
        The runs' rows, in the study's order (`rows_frame`).

    Returns
    -------
    pathlib.Path
        The file, replaced whole.
    """
    path = Path(out_dir) / RESULTS_FILE
    tmp = path.with_name(f".{RESULTS_FILE}.{os.getpid()}{_TMP_SUFFIX}")
    rows_frame(rows).to_parquet(tmp, index=False)
    os.replace(tmp, path)
    return path


__all__ = ["RESULTS_FILE", "RUNS_DIR", "RunStore", "rows_frame", "write_results"]
