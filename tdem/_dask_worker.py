"""The Dask worker plugin of :func:`tdem.ensemble` (imports Dask: loaded only when an
ensemble runs)."""
import os
import sys

from distributed.diagnostics.plugin import WorkerPlugin

from .ensemble import PLUGIN_NAME, worker_environment


def _taichi_started():
    backend = sys.modules.get("tdem.core.backend")
    return backend is not None and backend._state["arch"] is not None


class WorkerSetup(WorkerPlugin):
    """Dask worker plugin: sets :func:`worker_environment` on each worker as it joins,
    unless its Taichi runtime has started. A worker's index is its name where that is
    a whole number (a ``LocalCluster``'s workers, ``dask worker --name 0``), else its
    place among the workers of its machine (by address)."""
    name = PLUGIN_NAME

    def __init__(self, threads=None):
        self.threads = threads

    async def setup(self, worker):
        if _taichi_started():
            return
        index, here = None, 1
        host = worker.address.rsplit(":", 1)[0]
        try:
            info = await worker.scheduler.identity()
            same = sorted(a for a, w in info.get("workers", {}).items()
                          if a.rsplit(":", 1)[0] == host)
            if worker.address not in same:
                same = sorted(same + [worker.address])
            here = len(same)
            index = same.index(worker.address)
        except Exception:                               # no scheduler answer: alone
            index = 0
        name = str(worker.name)
        if name.lstrip("-").isdigit():
            index = int(name)
        env = worker_environment(index, here)
        if self.threads is not None:
            env["TDEM_THREADS"] = str(self.threads)
        os.environ.update(env)

    def teardown(self, worker):
        pass
