"""What a Dask worker runs once before a study's runs: what a local pool's worker does
(`worker_setup.prepare_worker_process`: numerical libraries limited to one thread, so each run uses one CPU and
gives the same numbers however the cluster is laid out; tqdm on a thread lock). Imported only by the Dask backend
(it needs `distributed`)."""

from __future__ import annotations

from distributed.diagnostics.plugin import WorkerPlugin

from workbench.apps.studies.worker_setup import prepare_worker_process


class SingleThreadedLibraries(WorkerPlugin):
    """Prepare every worker, present and future, as a local pool's worker is."""

    name = "workbench-single-threaded-libraries"

    def setup(self, worker: object) -> None:
        """Called by Dask on each worker as it joins (`WorkerPlugin.setup`).

        Parameters
        ----------
        worker : distributed.Worker
            The worker (not used: the preparation is of its process).
        """
        prepare_worker_process()


__all__ = ["SingleThreadedLibraries"]
