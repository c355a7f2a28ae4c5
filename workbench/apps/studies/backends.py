"""Where a study's runs execute: a local process pool (default) or a Dask cluster.

Both take PlannedRuns and yield their rows as they finish (completion order; the caller stores them and orders
the table by the study's order). Every run is independent and deterministic, so the backend and the number of
workers change how fast a study runs, never its rows (but for the wall-clock TIMING_COLUMNS).

- `LocalBackend(workers)`: a `concurrent.futures.ProcessPoolExecutor` of `workers` processes (default: the CPUs
  this process may use), forked from this process when it runs a single thread, else started from a fork server
  that has imported the workbench once (`start_context`), so a worker starts in milliseconds. Each worker ignores
  SIGINT and SIGTERM: the study's process owns its workers. Closing the pool while runs are in progress (an
  interrupted study) cancels the queued runs and kills the workers (SIGKILL: a worker holds nothing worth saving,
  the rows are written by the study's process), so the study stops within a fraction of a second rather than when
  its longest run ends; a worker also leaves by itself within ORPHAN_CHECK_S when the study's process is gone.
- `DaskBackend(scheduler, workers)`: `dask.distributed`; with no scheduler address a `LocalCluster` of `workers`
  single-threaded worker processes, else the cluster at that address, `tcp://HOST:PORT` (its workers must have this
  package installed and see the files the spec names); a scheduler that does not answer within
  SCHEDULER_TIMEOUT_S is refused. Closing it cancels the runs in progress and stops the LocalCluster, whose
  workers keep SIGINT blocked (Ctrl-C reaches only the study's process) and log only critical failures
  (CLUSTER_LOG_LEVEL). Workers of either backend are prepared alike (`worker_setup.prepare_worker_process`: BLAS
  and OpenMP on one thread each; a Dask worker plugin). A run whose worker dies each time it runs it (Dask's
  `KilledWorker`) is recorded as an error row; any other failure of the machinery stops the study, keeping the
  rows already written.

Use a backend as a context manager (it starts its pool or client on entry and stops it on exit) and call
`map_runs(runs)`; one backend serves many batches (the optimiser's trials).
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import queue
import re
import signal
import threading
import time
from collections.abc import Iterable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from types import TracebackType
from typing import Any, Protocol, Self

from workbench.apps.studies.runner import execute_run, failed_row
from workbench.apps.studies.spec import PlannedRun
from workbench.apps.studies.worker_setup import prepare_worker_process
from workbench.base.errors import WorkbenchInputError, value_text
from workbench.simulation.plot_worker import usable_cpus

#: The names `make_backend` accepts: "local" (worker processes on this machine) or "dask" (a Dask cluster).
BACKENDS = ("local", "dask")


class BackendError(RuntimeError):
    """The machinery failed (a worker process died, a cluster could not run a task): the study stops; the rows
    already written stay, and the same command resumes."""


#: How often (s) a local worker checks that the process which started it is still there.
ORPHAN_CHECK_S = 1.0
#: How long (s) closing an interrupted local pool waits for its killed workers to be reaped, and again for its
#: manager thread to end.
KILLED_WORKER_JOIN_S = 2.0
#: How long (s) a study waiting for its runs may take to act on a stop signal that another of its threads received.
SIGNAL_CHECK_S = 0.5
#: How long (s) connecting to a dask scheduler may take before it is refused as unreachable.
SCHEDULER_TIMEOUT_S = 10.0
#: What a LocalCluster's scheduler, nannies and workers log: critical failures only. Its other errors reach the
#: study as its runs' errors (a run's exception, a worker that died: KilledWorker, the cluster unable to run a task);
#: logged, they are tracebacks of the workers' connections when an interrupted study stops its busy workers.
CLUSTER_LOG_LEVEL = logging.CRITICAL
#: The most workers per usable CPU. A run is single-threaded and CPU-bound, so workers beyond the CPUs only share
#: them (no run ends sooner) while each holds its own copy of the workbench in memory (~0.2-0.3 GB with numba's
#: kernels loaded); a few per CPU still leaves room to measure that.
MAX_WORKERS_PER_CPU = 4
#: The signals a local worker ignores (the study's process stops it) and blocks while it starts.
_STOP_SIGNALS = frozenset({signal.SIGINT, signal.SIGTERM})
#: A dask scheduler's address: tcp://HOST:PORT (HOST a name, an IPv4 address or a bracketed IPv6 address).
_SCHEDULER_ADDRESS = re.compile(r"tcp://(?P<host>[A-Za-z0-9._-]+|\[[0-9A-Fa-f:.]+\]):(?P<port>[0-9]{1,5})")


class Backend(Protocol):
    """What a study needs of a backend (`LocalBackend`, `DaskBackend`): a name and worker count, start and close
    (or a ``with`` block), `map_runs` and `describe`."""

    @property
    def name(self) -> str: ...

    @property
    def workers(self) -> int | None: ...

    @property
    def started(self) -> bool: ...

    def start(self) -> None: ...

    def close(self) -> None: ...

    def __enter__(self) -> Self: ...

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None: ...

    def map_runs(self, runs: Sequence[PlannedRun]) -> Iterator[dict[str, Any]]:
        """Run `runs`, yielding each run's row as it finishes (in completion order).

        Parameters
        ----------
        runs : sequence of PlannedRun
            The runs to execute, each independent of the others.

        Yields
        ------
        dict
            A run's row (`runner.execute_run`).
        """
        ...

    def describe(self) -> str:
        """The backend in words, for a study's progress line and report.

        Returns
        -------
        str
            The kind of backend and its workers.
        """
        ...


def default_workers() -> int:
    """The CPUs this process may run on (`plot_worker.usable_cpus`).

    Returns
    -------
    int
        At least 1.
    """
    return usable_cpus()


def max_workers() -> int:
    """The most workers a backend starts here: MAX_WORKERS_PER_CPU per usable CPU.

    Returns
    -------
    int
        MAX_WORKERS_PER_CPU times `default_workers`.
    """
    return MAX_WORKERS_PER_CPU * default_workers()


def _require_workers(workers: int | None) -> None:
    """None (the default) or a whole number from 1 to max_workers()."""
    if workers is None:
        return
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise WorkbenchInputError(f"workers must be a whole number >= 1; got {value_text(workers)}")
    if workers > max_workers():
        raise WorkbenchInputError(
            f"workers must be at most {max_workers()} ({MAX_WORKERS_PER_CPU} per usable CPU, {default_workers()} "
            f"here: a run is single-threaded, so more workers only share the CPUs, each holding its own copy of the "
            f"workbench in memory); got {workers}"
        )


def _require_scheduler(scheduler: object) -> None:
    """A dask scheduler address, tcp://HOST:PORT with a port from 1 to 65535."""
    match = _SCHEDULER_ADDRESS.fullmatch(scheduler) if isinstance(scheduler, str) else None
    if match is None or not 1 <= int(match["port"]) <= 65535:
        raise WorkbenchInputError(
            f"scheduler must be a dask scheduler's address, tcp://HOST:PORT with a port from 1 to 65535 (e.g. "
            f"tcp://10.0.0.5:8786); got {scheduler!r}"
        )


def _init_worker(parent_pid: int) -> None:
    """A local worker is prepared as every worker is (`prepare_worker_process`), ignores SIGINT and SIGTERM (Ctrl-C
    reaches the whole process group; the study's process stops the pool) and leaves when the study's process is gone
    (killed without cleaning up). A forked worker starts with the stop signals blocked (`_stop_signals_blocked`), so
    that the study's own handlers, which it inherits, never run in it; they are unblocked once ignored."""
    for signum in _STOP_SIGNALS:
        signal.signal(signum, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOP_SIGNALS)
    prepare_worker_process()

    def watch() -> None:
        while True:
            time.sleep(ORPHAN_CHECK_S)
            try:
                os.kill(parent_pid, 0)
            except ProcessLookupError:
                os._exit(1)
            except PermissionError:  # the pid was taken by another user's process: ours is gone
                os._exit(1)

    threading.Thread(target=watch, name="workbench-orphan-watch", daemon=True).start()


def start_context() -> multiprocessing.context.BaseContext:
    """How local workers start. "fork" when this process runs one thread: a worker is a copy of it, the workbench
    already imported (and its compiled kernels loaded, if it ran a simulation), nothing of the caller's script
    re-run. Forking a process with other threads (a Dask client's, a GUI's) can deadlock the child, so then a fork
    server ("forkserver", importing the workbench once; the calling script must guard its top level with
    `if __name__ == "__main__":`, as for any non-fork start), or "spawn" where neither exists."""
    methods = multiprocessing.get_all_start_methods()
    if "fork" in methods and threading.active_count() == 1:
        return multiprocessing.get_context("fork")
    if "forkserver" in methods:
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(["workbench.apps.studies.runner"])
        return context
    return multiprocessing.get_context("spawn")


def _in_completion_order(futures: Iterable[Any]) -> Iterator[Any]:
    """`futures` (concurrent.futures' or dask's) as each finishes.

    A stop signal's handler raises KeyboardInterrupt in the main thread wherever it is; inside
    `threading.Condition.wait` (which both libraries' `as_completed` block in) that can land between the
    condition's release and re-acquire and surface as "RuntimeError: release unlocked lock" instead. Here the main
    thread blocks only in `queue.SimpleQueue.get`, which is C and leaves its lock consistent when a handler raises,
    so an interrupted study always sees the KeyboardInterrupt."""
    finished: queue.SimpleQueue[Any] = queue.SimpleQueue()
    count = 0
    for future in futures:
        future.add_done_callback(finished.put)
        count += 1
    for _ in range(count):
        yield _next_finished(finished)


def _next_finished(finished: queue.SimpleQueue[Any]) -> Any:
    while True:  # with a timeout, so that a signal another thread received is acted on within it
        try:
            return finished.get(timeout=SIGNAL_CHECK_S)
        except queue.Empty:
            continue


@contextmanager
def _stop_signals_blocked(signals: frozenset[signal.Signals] = _STOP_SIGNALS) -> Iterator[None]:
    """Block `signals` (SIGINT and SIGTERM) in this thread while worker processes may be started: they and the
    threads started meanwhile inherit the mask (local workers unblock the signals in `_init_worker`, after ignoring
    them); a signal that arrives meanwhile is delivered to this thread on leaving."""
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, signals)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


class _StartedInWith:
    """`with backend:` starts it and closes it, whatever happens inside."""

    def start(self) -> None:
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError

    def __enter__(self) -> Self:
        self.start()
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()


class LocalBackend(_StartedInWith):
    """A process pool on this machine (module docstring).

    Parameters
    ----------
    workers : int or None
        The worker processes, a whole number from 1 to `max_workers` (None: one per usable CPU,
        `default_workers`).

    Raises
    ------
    WorkbenchInputError
        workers is not a whole number from 1 to `max_workers`.
    """

    name = "local"

    def __init__(self, workers: int | None = None) -> None:
        _require_workers(workers)
        self.workers = workers or default_workers()
        self._pool: ProcessPoolExecutor | None = None
        self._futures: list[Future[dict[str, Any]]] = []

    def describe(self) -> str:
        """The backend in words for a study's progress line and report.

        Returns
        -------
        str
            E.g. "local process pool, 2 workers".
        """
        return f"local process pool, {self.workers} worker{'s' if self.workers != 1 else ''}"

    @property
    def started(self) -> bool:
        """Whether the pool is running (between `start` and `close`)."""
        return self._pool is not None

    def start(self) -> None:
        """Start the pool: workers forked from this process when that is safe (POSIX, one thread), else from a
        fork server that imports the workbench once."""
        if self._pool is None:
            context = start_context()
            self._pool = ProcessPoolExecutor(
                self.workers, mp_context=context, initializer=_init_worker, initargs=(os.getpid(),)
            )

    def close(self) -> None:
        """Stop the pool. Idle, its workers leave as asked; with runs in progress (an interrupted study), the queued
        runs are cancelled and the workers killed at once (their runs' rows are not kept: rerunning the study runs
        them), and reaped."""
        pool, self._pool = self._pool, None
        futures, self._futures = self._futures, []
        if pool is None:
            return
        if all(future.done() for future in futures):
            pool.shutdown(wait=True)
            return
        workers = list((pool._processes or {}).values())  # the pool has no public way to end running tasks
        # taken now: shutdown(wait=False) drops the pool's reference (typeshed types it as the wake-up, wrongly)
        manager: threading.Thread | None = pool._executor_manager_thread  # type: ignore[assignment]
        pool.shutdown(wait=False, cancel_futures=True)
        for worker in workers:
            if worker.is_alive():
                worker.kill()
        deadline = time.monotonic() + KILLED_WORKER_JOIN_S
        for worker in workers:
            worker.join(max(0.0, deadline - time.monotonic()))
        # The pool's manager thread closes its wake-up pipe as it winds down; Python 3.11's exit handler writes to
        # that pipe unless it is closed, and a close between its check and its write prints a traceback (OSError:
        # bad file descriptor) as the interrupted command exits. Waiting for the thread (it ends once it sees its
        # workers gone) closes the race.
        if manager is not None:
            manager.join(KILLED_WORKER_JOIN_S)

    def map_runs(self, runs: Sequence[PlannedRun]) -> Iterator[dict[str, Any]]:
        """Run `runs` on the pool's workers, yielding each run's row as it finishes (in completion order, not in
        the runs' order).

        Parameters
        ----------
        runs : sequence of PlannedRun
            The runs to execute (`StudySpec.plan`), each independent of the others.

        Yields
        ------
        dict
            A run's row (`runner.execute_run`): its parameters, the metrics.json fields, status and message; a run
            that raised is an "error" row.

        Raises
        ------
        RuntimeError
            The backend is not started (use it in a ``with`` block).
        BackendError
            A worker process died (killed, out of memory, or crashed in native code); the runs left are cancelled.
        """
        if self._pool is None:
            raise RuntimeError("start the backend first: with LocalBackend(...) as backend: ...")
        with _stop_signals_blocked():  # the first submit forks the workers
            futures = {self._pool.submit(execute_run, run): run for run in runs}
        self._futures = list(futures)
        try:
            for future in _in_completion_order(futures):
                try:
                    row = future.result()  # execute_run returns rows; only the machinery raises here
                except BrokenProcessPool as exc:
                    raise BackendError(
                        f"a worker process died (killed, out of memory, or crashed in native code) while running "
                        f"{futures[future].run_id} or another run: {exc}"
                    ) from None
                yield row
        finally:
            for future in futures:
                future.cancel()


class DaskBackend(_StartedInWith):
    """dask.distributed: a LocalCluster, or the scheduler at `scheduler` (module docstring).

    Parameters
    ----------
    scheduler : str or None
        A dask scheduler's address, ``tcp://HOST:PORT`` with a port from 1 to 65535 (None: a LocalCluster started
        on this machine).
    workers : int or None
        The LocalCluster's single-threaded worker processes, a whole number from 1 to `max_workers` (None: one per
        usable CPU); not with a scheduler.

    Raises
    ------
    WorkbenchInputError
        A malformed scheduler address, both a scheduler and workers, or workers not a whole number from 1 to
        `max_workers`.
    """

    name = "dask"

    def __init__(self, scheduler: str | None = None, workers: int | None = None) -> None:
        _require_workers(workers)
        if scheduler is not None and workers is not None:
            raise WorkbenchInputError(
                f"workers ({workers}) applies to a LocalCluster; with a scheduler ({scheduler}) the cluster's own "
                "workers run the study: drop one"
            )
        if scheduler is not None:
            _require_scheduler(scheduler)
        self.scheduler = scheduler
        self.workers = None if scheduler else workers or default_workers()
        self._client: Any = None
        self._cluster: Any = None
        self._futures: list[Any] = []

    def describe(self) -> str:
        """The backend in words for a study's progress line and report.

        Returns
        -------
        str
            The scheduler's address, or the LocalCluster and its number of workers.
        """
        if self.scheduler:
            return f"dask scheduler {self.scheduler}"
        return f"dask LocalCluster, {self.workers} single-threaded worker process{'es' if self.workers != 1 else ''}"

    @property
    def started(self) -> bool:
        """Whether the client is connected (between `start` and `close`)."""
        return self._client is not None

    def start(self) -> None:
        """Connect to the scheduler, or start a LocalCluster and connect to it.

        Raises
        ------
        WorkbenchInputError
            The scheduler does not answer within `SCHEDULER_TIMEOUT_S`.
        """
        from distributed import Client, LocalCluster

        if self._client is not None:
            return
        if self.scheduler:
            try:
                self._client = Client(self.scheduler, timeout=f"{SCHEDULER_TIMEOUT_S}s")
            except (OSError, TimeoutError) as exc:
                raise WorkbenchInputError(
                    f"cannot reach the dask scheduler {self.scheduler!r} within {SCHEDULER_TIMEOUT_S:g} s: {exc}"
                ) from None
        else:
            # Ctrl-C reaches the whole process group: the cluster's worker processes (and the thread that starts
            # them) keep SIGINT blocked, so only this process receives it, and stops them through their nannies.
            with _stop_signals_blocked(frozenset({signal.SIGINT})):
                self._cluster = LocalCluster(
                    n_workers=self.workers,
                    threads_per_worker=1,
                    processes=True,
                    # a free port: dashboard_address=None still serves on 8787 and warns when a second
                    # cluster finds it taken (dask/distributed#8136)
                    dashboard_address=":0",
                    silence_logs=CLUSTER_LOG_LEVEL,
                )
            self._client = Client(self._cluster)
        from workbench.apps.studies.dask_worker import SingleThreadedLibraries

        self._client.register_plugin(SingleThreadedLibraries())

    def close(self) -> None:
        """Cancel the runs not finished (an interrupted study), disconnect, and stop the LocalCluster if this backend
        started one (its worker processes with it)."""
        client, self._client = self._client, None
        cluster, self._cluster = self._cluster, None
        futures, self._futures = self._futures, []
        if client is not None:
            pending = [future for future in futures if not future.done()]
            if pending:
                client.cancel(pending)
            client.close()
        if cluster is not None:
            cluster.close()

    def map_runs(self, runs: Sequence[PlannedRun]) -> Iterator[dict[str, Any]]:
        """Run `runs` on the cluster, yielding each run's row as it finishes (in completion order, not in the runs'
        order).

        Parameters
        ----------
        runs : sequence of PlannedRun
            The runs to execute (`StudySpec.plan`), each independent of the others.

        Yields
        ------
        dict
            A run's row (`runner.execute_run`): its parameters, the metrics.json fields, status and message; a run
            that raised is an "error" row, and so is a run whose worker died each time it ran it.

        Raises
        ------
        RuntimeError
            The backend is not started (use it in a ``with`` block).
        BackendError
            The cluster could not run a run (e.g. the workbench is missing on a worker); the runs left are
            cancelled.
        """
        from distributed.scheduler import KilledWorker

        if self._client is None:
            raise RuntimeError("start the backend first: with DaskBackend(...) as backend: ...")
        by_key = {}
        futures = []
        for run in runs:
            future = self._client.submit(execute_run, run, key=f"workbench-run-{run.run_id}", pure=False)
            by_key[future.key] = run
            futures.append(future)
        self._futures = futures
        try:
            for future in _in_completion_order(futures):
                try:
                    row = future.result()
                except KilledWorker as exc:
                    row = failed_row(by_key[future.key], f"the dask worker died each time it ran this run: {exc}")
                except Exception as exc:  # the cluster could not run it (e.g. the workbench missing on a worker)
                    raise BackendError(
                        f"the dask cluster could not run {by_key[future.key].run_id}: {type(exc).__name__}: {exc}"
                    ) from exc
                future.release()
                yield row
        finally:
            self._client.cancel([f for f in futures if not f.done()])


def make_backend(name: str = "local", scheduler: str | None = None, workers: int | None = None) -> Backend:
    """A backend by name: "local" (workers processes) or "dask" (a LocalCluster, or the scheduler given).

    Parameters
    ----------
    name : str
        One of `BACKENDS`: "local" or "dask".
    scheduler : str or None
        A dask scheduler's address, ``tcp://HOST:PORT`` (the dask backend only; None: a LocalCluster).
    workers : int or None
        The worker processes, from 1 to `max_workers` (None: one per usable CPU); not with a scheduler, whose
        cluster brings its own.

    Returns
    -------
    Backend
        A `LocalBackend` or `DaskBackend`, not started: use it as a context manager (``with backend: ...``).

    Raises
    ------
    WorkbenchInputError
        An unknown name, a scheduler for the local backend, a malformed scheduler address, both a scheduler and
        workers, or workers not a whole number from 1 to `max_workers`.

    Examples
    --------
    >>> from workbench.apps.studies import make_backend
    >>> make_backend("local", workers=2).describe()
    'local process pool, 2 workers'
    >>> make_backend("dask", workers=2).describe()
    'dask LocalCluster, 2 single-threaded worker processes'
    """
    if name not in BACKENDS:
        raise WorkbenchInputError(f"unknown backend {name!r}; choose one of {', '.join(BACKENDS)}")
    if name == "local":
        if scheduler is not None:
            raise WorkbenchInputError(f"a scheduler address ({scheduler}) needs the dask backend (--backend dask)")
        return LocalBackend(workers)
    return DaskBackend(scheduler, workers)


__all__ = [
    "BACKENDS",
    "Backend",
    "BackendError",
    "DaskBackend",
    "LocalBackend",
    "default_workers",
    "make_backend",
    "max_workers",
]
