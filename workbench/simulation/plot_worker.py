"""A second process that draws a run's plots while the run goes on, so that a run's plots add little to its wall
time (a Zandvoort lap from the CLI, plots included, is benchmarked against a real-time factor in benchmarks/run.py).

A run's four plots take about as long as its simulation: matplotlib's import (~0.4 s) and drawing (~0.7 s). The
worker is started before the run, imports matplotlib while the simulation runs, and draws the plots from a
`plots.RunDrawing` (arrays and strings: it unpickles with numpy alone) while the run's trace and metrics are written.
It is worth it with two or more CPUs (`worthwhile`); `workbench run` uses it, `SimulationResult.save` takes it.

Whatever goes wrong in the worker (it cannot start, dies, or its drawing raises), `wait` returns None and the caller
draws the plots itself: the worker only saves time, and a plotting error then surfaces where it always did.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
from multiprocessing.connection import Connection
from pathlib import Path

from workbench.simulation.plots import PlottedRun, RunDrawing


def usable_cpus() -> int:
    """CPUs this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def worthwhile() -> bool:
    """A second process gains time only with a second CPU to run on."""
    return usable_cpus() > 1


class PlotWorker:
    """One spawned process that draws one run's plots (`plots.save_run_plots`): `submit`, then `wait`; `close` in
    any case (a daemon process: it also ends with this one)."""

    def __init__(self) -> None:
        context = multiprocessing.get_context("spawn")  # a fresh interpreter everywhere: no forked numba or locks
        self._connection, child = context.Pipe()
        self._process = context.Process(target=_serve, args=(child,), name="workbench-plots", daemon=True)
        # Ctrl-C is this process's to handle: the worker starts with SIGINT blocked (the mask survives the exec), so
        # not even its start-up prints a KeyboardInterrupt; it then ignores SIGINT and ends with this process
        masks = hasattr(signal, "pthread_sigmask")  # POSIX
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if masks else None
        try:
            self._process.start()
        finally:
            if previous is not None:
                signal.pthread_sigmask(signal.SIG_SETMASK, previous)
        child.close()
        self._submitted = self._replied = False

    def submit(self, run: PlottedRun, out_dir: Path) -> None:
        """Send a run's plots to be drawn into out_dir (the drawing's arrays are copied to the worker)."""
        try:
            self._connection.send((RunDrawing.of(run), Path(out_dir)))
            self._submitted = True
        except (OSError, ValueError):  # the worker is gone: wait() says so
            self._submitted = False

    def wait(self) -> list[Path] | None:
        """The plots' paths once drawn; None when the worker could not draw them (the caller draws them)."""
        if not self._submitted:
            return None
        try:
            outcome, value = self._connection.recv()
        except (EOFError, OSError):
            return None
        self._replied = True
        return value if outcome == "drawn" else None

    def close(self) -> None:
        """End the worker: it leaves by itself once it has replied; otherwise (a run that failed before its plots)
        it is stopped, not waited for."""
        self._connection.close()
        if self._replied:
            self._process.join(timeout=5.0)
        if self._process.is_alive():
            self._process.kill()
        self._process.join()

    def __enter__(self) -> PlotWorker:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _serve(connection: Connection) -> None:  # pragma: no cover - runs in the worker process
    """The worker: import matplotlib, draw the one run it is sent, reply, and leave without the interpreter's
    teardown (its replies are sent; nothing else to clean up)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle; the worker ends with it
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # ignored now, no longer pending
    from matplotlib.figure import Figure  # noqa: F401 - imported now, while the parent simulates

    from workbench.simulation.plots import save_run_plots

    try:
        job = connection.recv()
    except (EOFError, OSError):
        os._exit(0)
    try:
        drawing, out_dir = job
        reply: tuple[str, list[Path] | None] = ("drawn", save_run_plots(drawing, out_dir))
    except Exception:  # the parent draws again in its own process, where the error surfaces
        reply = ("failed", None)
    try:
        connection.send(reply)
    finally:
        connection.close()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(0)
