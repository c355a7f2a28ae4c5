"""What a Dask worker runs once before a study's runs: numerical libraries limited to one thread (`threadpoolctl`),
as in the local pool's workers, so each run uses one CPU and gives the same numbers however the cluster is laid
out. Imported only by the Dask backend (it needs `distributed`)."""

from __future__ import annotations

from distributed.diagnostics.plugin import WorkerPlugin
from threadpoolctl import threadpool_limits


class SingleThreadedLibraries(WorkerPlugin):
    """Limit BLAS/OpenMP thread pools to one thread on every worker, present and future."""

    name = "workbench-single-threaded-libraries"

    def setup(self, worker: object) -> None:
        threadpool_limits(1)


__all__ = ["SingleThreadedLibraries"]
