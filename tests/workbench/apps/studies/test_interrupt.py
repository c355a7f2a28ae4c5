"""Interrupting a study: SIGINT (Ctrl-C) or SIGTERM ends `workbench sweep` and `workbench robustness` at once, exit
code 130, while their workers are in the middle of runs that take about a minute; the worker processes end with
the study, the rows of the runs that finished stay, and the same command resumes with the others. On the Dask
backend the client stops its runs and its LocalCluster, and says so."""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import psutil
import pytest
from study_helpers import NotSimulating, write_spec

from workbench.apps.cli import main
from workbench.apps.robustness import plan_robustness
from workbench.apps.studies import load_spec
from workbench.apps.studies.runner import failed_row
from workbench.apps.studies.store import RunStore

#: Generous: the goal is 2 s on the local backend (benchmarks/interrupt.py measures it); the runs in flight take
#: about a minute, so a study that waited for them would miss this by far.
STOP_BOUND_S = 10.0
#: The Dask LocalCluster closes its worker processes through their nannies: slower, still far below a run.
DASK_STOP_BOUND_S = 30.0
#: How long the fast runs may take to finish before the signal (a loaded machine, the workers' compilation).
READY_TIMEOUT_S = 300.0

#: Two fast runs (the kinematic car, compiled) then two slow ones (CommonRoad's multi-body car, pure Python: four
#: laps of the figure-8, about 70 s each on an idle CPU). With 2 workers, the fast runs finish first and both
#: workers are then busy with a slow run.
SLOW_SPEC = """
[study]
scenarios = ["figure8"]
controllers = ["pure-pursuit"]
vehicles = ["kinematic-bicycle", "commonroad-mb"]

[grid]
speed_kmh = [25, 30]
laps = 4
"""
#: A circle of this radius (m), one lap of which CommonRoad's multi-body car takes about a minute to simulate at
#: 30 km/h (3.1 km, 377 s simulated).
CIRCLE_RADIUS_M = 500.0


def _command(*args: str) -> list[str]:
    return [sys.executable, "-m", "workbench.apps.cli", *args]


def _alive(pid: int) -> bool:
    """The process is running (a zombie, killed but not yet reaped by whoever inherited it, is not)."""
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def _interrupt_when_ready(
    command: list[str], ready: Callable[[], bool], signum: int, bound_s: float
) -> tuple[float, str, list[int]]:
    """Start `command`, send it `signum` once `ready()` (and its workers have started); return the time it took to
    exit, its stderr and the pids of the processes it had started. Fails if it exits before, or takes longer than
    bound_s after the signal."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + READY_TIMEOUT_S
        while not (ready() and psutil.Process(process.pid).children()):
            if process.poll() is not None:
                pytest.fail(f"the study ended before the signal (exit {process.returncode}): {process.stderr.read()}")
            if time.monotonic() > deadline:
                pytest.fail(f"the study was not ready within {READY_TIMEOUT_S:g} s")
            time.sleep(0.05)
        time.sleep(1.0)  # the workers are into their slow runs
        descendants = [p.pid for p in psutil.Process(process.pid).children(recursive=True)]
        start = time.monotonic()
        process.send_signal(signum)
        try:
            _, stderr = process.communicate(timeout=bound_s)
        except subprocess.TimeoutExpired:
            pytest.fail(f"{signal.Signals(signum).name}: the study did not exit within {bound_s:g} s")
        return time.monotonic() - start, stderr, descendants
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()


def _row_ids(out: Path) -> set[str]:
    return {path.stem for path in (out / "runs").glob("*.json")}


def _assert_stopped(stderr: str, descendants: list[int], out: Path) -> None:
    assert "workbench: interrupted; stopped the " in stderr and f"kept in {out / 'runs'}: rerun to resume" in stderr
    assert "Traceback" not in stderr, stderr
    assert descendants, "the study started no worker process"
    time.sleep(0.5)  # a killed process of a LocalCluster's nanny may need a moment to be reaped
    assert [pid for pid in descendants if _alive(pid)] == [], "worker processes outlived the study"


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_sweep_with_busy_workers_stops_at_once_keeps_its_rows_and_resumes(
    tmp_path: Path, signum: int, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = write_spec(tmp_path / "spec", SLOW_SPEC)
    ids = [run.run_id for run in load_spec(spec).plan()]
    fast, slow = ids[:2], ids[2:]
    out = tmp_path / "out"
    args = ["sweep", str(spec), "--out", str(out), "--workers", "2", "--no-plots"]

    elapsed, stderr, descendants = _interrupt_when_ready(
        _command(*args), lambda: _row_ids(out) >= set(fast), signum, STOP_BOUND_S
    )
    print(f"{signal.Signals(signum).name}: exit after {elapsed:.2f} s")
    _assert_stopped(stderr, descendants, out)
    assert _row_ids(out) == set(fast), "the fast runs' rows are kept, the slow runs were not waited for"
    assert not (out / "results.parquet").exists()

    backend = NotSimulating()
    monkeypatch.setattr("workbench.apps.studies.make_backend", lambda *_: backend)
    capsys.readouterr()
    assert main(args) == 1  # the slow runs come back as error rows from NotSimulating
    assert backend.given == [slow]
    assert "4 runs (2 already done, 2 run now)" in capsys.readouterr().out


def _circle_csv(folder: Path) -> Path:
    points = max(8, int(2 * math.pi * CIRCLE_RADIUS_M / 2.0))  # a point every ~2 m
    rows = [
        f"{CIRCLE_RADIUS_M * math.sin(2 * math.pi * i / points)!r},"
        f"{CIRCLE_RADIUS_M * (1 - math.cos(2 * math.pi * i / points))!r}"
        for i in range(points)
    ]
    path = folder / "circle.csv"
    path.write_text("x_m,y_m\n" + "\n".join([*rows, rows[0]]) + "\n")  # the first row repeated: a closed loop
    return path


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_robustness_with_busy_workers_stops_at_once_keeps_its_rows_and_resumes(
    tmp_path: Path, signum: int, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every run of the study but the first two is already done (rows written as by an earlier, interrupted
    study); the two left take about a minute each."""
    circle = _circle_csv(tmp_path)
    out = tmp_path / "out"
    runs = plan_robustness(str(circle), ["pure-pursuit"], "commonroad-mb", base_dir=Path.cwd())  # as the CLI
    store = RunStore(out)
    for run in runs[2:]:
        store.write(failed_row(run, "done earlier"))
    done = {path.name: path.read_text() for path in store.runs_dir.iterdir()}
    args = ["robustness", str(circle), "--controllers", "pure-pursuit", "--vehicle", "commonroad-mb"]
    args += ["--out", str(out), "--workers", "2"]

    elapsed, stderr, descendants = _interrupt_when_ready(_command(*args), lambda: True, signum, STOP_BOUND_S)
    print(f"{signal.Signals(signum).name}: exit after {elapsed:.2f} s")
    _assert_stopped(stderr, descendants, out)
    assert {path.name: path.read_text() for path in store.runs_dir.iterdir()} == done, "a row was added or lost"

    backend = NotSimulating()
    monkeypatch.setattr("workbench.apps.studies.make_backend", lambda *_: backend)
    assert main(args) == 0
    assert backend.given == [[run.run_id for run in runs[:2]]]
    rows = [json.loads(p.read_text()) for p in sorted(store.runs_dir.glob("*.json"))]
    assert len(rows) == len(runs) and {row["run_id"] for row in rows} == {run.run_id for run in runs}


def test_a_dask_sweep_stops_its_local_cluster_and_says_so(tmp_path: Path) -> None:
    spec = write_spec(tmp_path / "spec", SLOW_SPEC)
    fast = [run.run_id for run in load_spec(spec).plan()][:2]
    out = tmp_path / "out"
    command = _command("sweep", str(spec), "--out", str(out), "--backend", "dask", "--workers", "2", "--no-plots")

    _, stderr, descendants = _interrupt_when_ready(
        command, lambda: _row_ids(out) >= set(fast), signal.SIGTERM, DASK_STOP_BOUND_S
    )
    _assert_stopped(stderr, descendants, out)
    assert "stopped the dask LocalCluster, 2 single-threaded worker processes (runs in progress abandoned)" in stderr
    assert len(stderr.strip().splitlines()) == 1, stderr  # that line only: no log of the workers' connections
    assert _row_ids(out) == set(fast)


def test_local_workers_ignore_the_stop_signals_and_closing_the_busy_pool_ends_them(tmp_path: Path) -> None:
    """A worker ignores SIGINT and SIGTERM (Ctrl-C reaches the whole process group: the study's process stops the
    pool); closing the pool mid-run kills and reaps its workers at once."""
    import multiprocessing
    import threading

    from workbench.apps.studies import LocalBackend
    from workbench.apps.studies.backends import BackendError

    slow = load_spec(write_spec(tmp_path, SLOW_SPEC)).plan()[2:3]
    others = {child.pid for child in multiprocessing.active_children()}
    backend = LocalBackend(workers=1)
    outcome: list[object] = []

    def study() -> None:  # as a study's loop over the rows, here beside the test
        try:
            outcome.extend(backend.map_runs(slow))
        except BackendError as exc:  # its pool closed under it
            outcome.append(exc)

    with backend:
        loop = threading.Thread(target=study)
        loop.start()
        deadline = time.monotonic() + READY_TIMEOUT_S
        while not (workers := [c for c in multiprocessing.active_children() if c.pid not in others]):
            assert time.monotonic() < deadline, "no worker started"
            time.sleep(0.05)
        (worker,) = workers
        time.sleep(1.0)  # past its initialiser, into the run
        for signum in (signal.SIGINT, signal.SIGTERM):
            psutil.Process(worker.pid).send_signal(signum)
        time.sleep(1.0)
        assert worker.is_alive(), "a stop signal ended the worker"
        start = time.monotonic()
    assert not worker.is_alive() and time.monotonic() - start < STOP_BOUND_S / 2
    # killed, as the pool reports it: a forkserver child's status comes through the forkserver, and when that
    # status is lost multiprocessing reports 255 (multiprocessing/popen_forkserver.py, Popen.poll)
    killed = (-signal.SIGKILL, 255) if type(worker).__name__ == "ForkServerProcess" else (-signal.SIGKILL,)
    assert worker.exitcode in killed, worker.exitcode
    loop.join(STOP_BOUND_S)
    assert not loop.is_alive() and len(outcome) == 1 and isinstance(outcome[0], BackendError), outcome
