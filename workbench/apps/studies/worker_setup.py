"""What a study's worker process, local or Dask, does before its first run (`prepare_worker_process`)."""

from __future__ import annotations

import threading

from threadpoolctl import threadpool_limits
from tqdm import tqdm


def prepare_worker_process() -> None:
    """What a worker process of either backend does before its first run: its numerical libraries run on one thread
    (a run is one CPU's work: OpenBLAS would otherwise start a thread per CPU in every worker, and the workers would
    compete for the CPUs), and tqdm (the simulator's progress bar, off in a worker) takes a thread lock, not the
    multiprocessing semaphore it creates by default, which a worker killed by an interrupted study would leave for
    the resource tracker to report as leaked."""
    threadpool_limits(1)
    tqdm.set_lock(threading.RLock())


__all__ = ["prepare_worker_process"]
