"""Studies at scale: parameter sweeps (`workbench sweep`), controller optimisation (`workbench optimise`) and the
controller tournament (`workbench tournament`).

A TOML spec (`spec.py`) names scenarios, controllers, vehicles and parameter grids or seeded random draws
(`distributions.py`); it plans independent, deterministic runs with stable ids. `runner.py` executes one run into
a row (its parameters and the metrics.json fields; an exception becomes an "error" row), `backends.py` runs them on
a local process pool or on Dask, `store.py` keeps each row as it finishes (so a restarted study resumes) and
assembles DIR/results.parquet, `results.py` and `plots.py` summarise and draw them (and write DIR/report.html),
`optimise.py` tunes a controller's options with optuna through the same machinery, and `tournament.py` tunes every
controller of a tournament spec (`tournament_spec.py`) with the same budget on training cases and judges them on
held-out test cases. Every value a spec plans is built when it loads (`value_check.py`, with `run_build.py`, how a
run's objects are built), so that a value every run would refuse stops the study before any run.

    from workbench.apps.studies import load_spec, run_sweep, make_backend
    result = run_sweep(load_spec("examples/sweep_dlc.toml"), "runs/sweep", make_backend("local", workers=2))
    result.to_pandas(); result.plot_cte_vs_speed(); result.plot_pareto()
"""

from __future__ import annotations

from workbench.apps.studies.backends import BACKENDS, BackendError, DaskBackend, LocalBackend, make_backend
from workbench.apps.studies.optimise import OptimisationResult, run_optimisation
from workbench.apps.studies.results import SweepResult
from workbench.apps.studies.runner import TIMING_COLUMNS, execute_run
from workbench.apps.studies.spec import PlannedRun, StudySpec, load_spec
from workbench.apps.studies.sweep import run_sweep
from workbench.apps.studies.tournament import TournamentResult, run_tournament
from workbench.apps.studies.tournament_spec import TournamentSpec, load_tournament

__all__ = [
    "BACKENDS",
    "TIMING_COLUMNS",
    "BackendError",
    "DaskBackend",
    "LocalBackend",
    "OptimisationResult",
    "PlannedRun",
    "StudySpec",
    "SweepResult",
    "TournamentResult",
    "TournamentSpec",
    "execute_run",
    "load_spec",
    "load_tournament",
    "make_backend",
    "run_optimisation",
    "run_sweep",
    "run_tournament",
]
