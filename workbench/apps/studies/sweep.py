"""Parameter sweeps: every run a study spec plans, on a backend, into DIR/runs/ and DIR/results.parquet.

`run_sweep(spec, out_dir, backend)` plans the runs, skips those whose rows DIR already holds (a restarted sweep
resumes; an extended one runs only what is new), executes the others on the backend, writing each row as it
arrives, then writes DIR/results.parquet with one row per planned run in the study's order and returns a
`SweepResult`.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tqdm import tqdm

from workbench.apps.studies.backends import Backend, LocalBackend
from workbench.apps.studies.results import SweepResult
from workbench.apps.studies.spec import PlannedRun, StudySpec
from workbench.apps.studies.store import RunStore, write_results


def execute_runs(
    runs: Sequence[PlannedRun], store: RunStore, backend: Backend, progress: bool = False, desc: str = "runs"
) -> tuple[list[dict[str, Any]], int]:
    """The rows of `runs` in their order, running on `backend` those the store does not hold yet (each written as
    it finishes); also how many ran now. The backend is started if it has runs to do and is left running (the
    caller closes it).

    Parameters
    ----------
    runs : sequence of PlannedRun
        The runs wanted, in the order of the rows returned.
    store : RunStore
        Where rows are kept, one JSON file per run.
    backend : Backend
        Where the runs left to do execute.
    progress : bool
        Show a bar on stderr counting the runs left to do.
    desc : str
        The bar's label.

    Returns
    -------
    tuple of (list of dict, int)
        One row per run in the order of `runs`, and how many ran in this call.

    Raises
    ------
    BackendError
        The backend's machinery failed; the rows already written stay.
    """
    store.clean_temporaries()
    finished = store.read(r.run_id for r in runs)
    todo = list({r.run_id: r for r in runs if r.run_id not in finished}.values())
    if todo:
        backend.start()  # before the bar: tqdm's monitor thread would make forking workers unsafe
        bar = tqdm(total=len(todo), unit="run", desc=desc, leave=True) if progress else None
        try:
            for row in backend.map_runs(todo):
                store.write(row)
                finished[row["run_id"]] = row
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
    return [finished[r.run_id] for r in runs], len(todo)


def run_sweep(
    spec: StudySpec, out_dir: str | Path, backend: Backend | None = None, progress: bool = False
) -> SweepResult:
    """Run (or resume) the sweep into out_dir; see the module docstring. backend: a LocalBackend over every CPU
    unless given (started only if some run is left to do).

    Parameters
    ----------
    spec : StudySpec
        The study (`load_spec`), its runs planned here (`StudySpec.plan`).
    out_dir : str or pathlib.Path
        The study's folder: one JSON row per run under out_dir/runs/ (the rows already there are kept, not run
        again), then out_dir/results.parquet.
    backend : Backend or None
        Where the runs execute (`make_backend`); one started by the caller is left running, one started here is
        closed on return (None: a `LocalBackend` over every usable CPU).
    progress : bool
        Show a bar on stderr counting the runs left to do.

    Returns
    -------
    SweepResult
        One row per planned run in the study's order, and `ran`, how many of them executed in this call (the
        others were already in out_dir).

    Raises
    ------
    WorkbenchInputError
        The output folder cannot be created.
    BackendError
        The backend's machinery failed (a worker process died); the rows already written stay, and the same call
        resumes.

    Examples
    --------
    >>> from workbench.apps.studies import load_spec, make_backend, run_sweep
    >>> spec = load_spec("examples/sweep_dlc.toml")
    >>> spec.run_count()
    200
    >>> with make_backend("local", workers=2) as backend:  # doctest: +SKIP
    ...     result = run_sweep(spec, "runs/sweep-dlc", backend, progress=True)
    >>> result.summary()  # doctest: +SKIP
    """
    out = Path(out_dir)
    store = RunStore(out)
    runs = spec.plan()
    backend = backend or LocalBackend()
    started_here = not backend.started
    try:
        rows, ran = execute_runs(runs, store, backend, progress, "sweep")
    finally:
        if started_here:
            backend.close()
    write_results(out, rows)
    return SweepResult.from_rows(rows, out, ran=ran)


__all__ = ["execute_runs", "run_sweep"]
