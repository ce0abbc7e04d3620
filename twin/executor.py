"""Where batches of independent simulations run: local worker processes or a Dask cluster.

``make_executor(spec)`` reads a scenario's ``executor:`` block::

    executor: {type: local, workers: 2}                 # default: local processes, one per core
    executor: {type: dask, address: tcp://host:8786}    # an existing dask.distributed scheduler
    executor: {type: dask, workers: 2}                  # a LocalCluster started for the run
    executor: {type: local, timeout: 600, retries: 1}   # time limit [s] per task; re-runs after a crash

Every executor has one verb, ``map(fn, tasks, progress=...) -> list`` (results in task order).
``fn`` must be a picklable top-level function.  A task that raises does not stop the others;
its exception is returned in its slot, and the caller decides what to do with it.

FMUs are native code, so tasks always run in worker processes (:mod:`twin.isolation`), even
with one worker: a worker that segfaults, calls ``exit()`` or passes the time limit is
replaced, and its task's slot holds a :class:`~twin.errors.WorkerCrashError` naming the signal,
exit status or limit.  On Dask the nanny restarts a dead worker, the scheduler gives up on its
task at once (``allowed-failures`` 0 on a LocalCluster) and the ``KilledWorker`` becomes the
same :class:`~twin.errors.WorkerCrashError`; a task past the time limit ends its worker process,
which the nanny replaces.
"""
from __future__ import annotations

import os
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from twin._progress import progress_bar
from twin.errors import ScenarioError


class Executor(ABC):
    """Base class: validates the batch, then runs it with :meth:`_map`."""

    def map(self, fn: Callable[[Any], Any], tasks: Sequence[Any], *, progress: bool = False,
            desc: str = "simulations") -> list[Any]:
        tasks = list(tasks)
        if not callable(fn):
            raise TypeError(f"fn must be callable, got {fn!r}")
        if not tasks:
            return []
        return self._map(fn, tasks, progress, desc)

    @abstractmethod
    def _map(self, fn, tasks, progress, desc) -> list[Any]:
        """Run ``fn`` on every task; return the results (or exceptions) in task order."""

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _guarded(fn, task):
    try:
        return fn(task)
    except Exception as exc:  # returned, not raised: one failing task must not kill the batch
        return exc


#: Default time limit [s] of one task: far above any single simulation or fit of the twin,
#: so only a hung FMU reaches it.
DEFAULT_TIMEOUT = 3600.0


class LocalExecutor(Executor):
    """Worker processes on this machine, each hosting FMUs in isolation from this process.

    ``workers`` defaults to one per core; ``timeout`` [s] limits each task (``None``: no limit);
    ``retries`` re-runs a task whose worker died (not one that hung).  ``isolate=False`` runs
    the tasks in this process instead (for debugging; a crashing FMU then ends the process).
    """

    def __init__(self, workers: int | None = None, *, timeout: float | None = DEFAULT_TIMEOUT, retries: int = 0,
                 isolate: bool = True):
        self.workers = workers or len(os.sched_getaffinity(0))
        self.timeout = timeout
        self.retries = retries
        self.isolate = isolate
        self._pool = None

    def _map(self, fn, tasks, progress, desc):
        from twin import _interrupt
        bar = progress_bar(len(tasks), progress, desc, "run")
        try:
            if not self.isolate:
                out = []
                for t in tasks:
                    _interrupt.check()
                    out.append(_guarded(fn, t))
                    bar.update(1)
                return out
            if self._pool is None:
                from twin.isolation import IsolatedPool
                self._pool = IsolatedPool(self.workers, timeout=self.timeout, retries=self.retries)
            return self._pool.map(fn, tasks, on_done=lambda i, r: bar.update(1))
        except BaseException:
            self.close()
            raise
        finally:
            bar.close()

    def close(self) -> None:
        if self._pool is not None:
            self._pool.close()
            self._pool = None


def _dask_task(fn, task, timeout):
    """Run one task on a Dask worker; past ``timeout`` s the worker process ends itself so that
    its nanny replaces it (a thread cannot be stopped) and the scheduler reports the task."""
    import threading
    timer = None
    if timeout is not None:
        def _expire():
            os.write(2, f"twin: task passed its time limit of {timeout:g} s; ending this worker\n".encode())
            os._exit(70)
        timer = threading.Timer(timeout, _expire)
        timer.daemon = True
        timer.start()
    try:
        return _guarded(fn, task)
    finally:
        if timer is not None:
            timer.cancel()


class DaskExecutor(Executor):
    """A dask.distributed cluster: an existing scheduler (``address``) or a LocalCluster."""

    def __init__(self, address: str | None = None, workers: int | None = None, *,
                 timeout: float | None = DEFAULT_TIMEOUT):
        import dask
        from dask.distributed import Client, LocalCluster
        self._cluster = None
        self.timeout = timeout
        if address:
            self.client = Client(address)
        else:
            # a task whose worker died is not handed to another worker: it would kill that one too;
            # one task per worker thread at a time, so a death takes no queued task with it
            with dask.config.set({"distributed.scheduler.allowed-failures": 0,
                                  "distributed.scheduler.worker-saturation": 1.0}):
                self._cluster = LocalCluster(n_workers=workers or len(os.sched_getaffinity(0)),
                                             threads_per_worker=1, processes=True, dashboard_address=None)
            self.client = Client(self._cluster)

    def _map(self, fn, tasks, progress, desc):
        from dask.distributed import as_completed as dask_completed

        from twin import _interrupt
        from twin.errors import WorkerCrashError
        futures = self.client.map(_dask_task, [fn] * len(tasks), tasks, [self.timeout] * len(tasks), pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        results: list[Any] = [None] * len(tasks)
        bar = progress_bar(len(tasks), progress, desc, "run")
        try:
            for fut in dask_completed(futures):
                i = index[fut.key]
                try:
                    results[i] = fut.result()
                except Exception as exc:   # KilledWorker: the worker died running this task
                    limit = f" or passed the time limit of {self.timeout:g} s" if self.timeout else ""
                    results[i] = WorkerCrashError(f"the Dask worker running task {i} died{limit} "
                                                  f"({type(exc).__name__}: {exc})")
                bar.update(1)
                _interrupt.check()
        except BaseException:
            self.client.cancel(futures)
            raise
        finally:
            bar.close()
        return results

    def close(self) -> None:
        self.client.close()
        if self._cluster is not None:
            self._cluster.close()


def make_executor(spec: Mapping[str, Any] | None) -> Executor:
    """Executor for a scenario's ``executor:`` block (see the module docstring)."""
    spec = dict(spec or {})
    kind = spec.get("type", "local")
    timeout = spec.get("timeout", DEFAULT_TIMEOUT)
    if kind == "local":
        return LocalExecutor(spec.get("workers"), timeout=timeout, retries=int(spec.get("retries", 0)))
    if kind == "dask":
        return DaskExecutor(spec.get("address"), spec.get("workers"), timeout=timeout)
    raise ScenarioError([("<executor>", "executor.type", f"unknown executor {kind!r}; use 'local' or 'dask'")])
