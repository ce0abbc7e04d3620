"""Where batches of independent simulations run: local worker processes or a Dask cluster.

``make_executor(spec)`` reads a scenario's ``executor:`` block::

    executor: {type: local, workers: 2}                 # default: local processes, one per core
    executor: {type: dask, address: tcp://host:8786}    # an existing dask.distributed scheduler
    executor: {type: dask, workers: 2}                  # a LocalCluster started for the run

Every executor has one verb, ``map(fn, tasks, progress=...) -> list`` (results in task order).
``fn`` must be a picklable top-level function.  A task that raises does not stop the others;
its exception is returned in its slot, and the caller decides what to do with it.
"""
from __future__ import annotations

import os
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
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


class LocalExecutor(Executor):
    """Worker processes on this machine (``workers=1`` runs in-process, which is easiest to debug)."""

    def __init__(self, workers: int | None = None):
        self.workers = workers or len(os.sched_getaffinity(0))

    def _map(self, fn, tasks, progress, desc):
        bar = progress_bar(len(tasks), progress, desc, "run")
        try:
            if self.workers == 1:
                out = []
                for t in tasks:
                    out.append(_guarded(fn, t))
                    bar.update(1)
                return out
            results: list[Any] = [None] * len(tasks)
            with ProcessPoolExecutor(max_workers=self.workers) as pool:
                futures = {pool.submit(_guarded, fn, t): i for i, t in enumerate(tasks)}
                for fut in as_completed(futures):
                    results[futures[fut]] = fut.result()
                    bar.update(1)
            return results
        finally:
            bar.close()


class DaskExecutor(Executor):
    """A dask.distributed cluster: an existing scheduler (``address``) or a LocalCluster."""

    def __init__(self, address: str | None = None, workers: int | None = None):
        from dask.distributed import Client, LocalCluster
        self._cluster = None
        if address:
            self.client = Client(address)
        else:
            self._cluster = LocalCluster(n_workers=workers or len(os.sched_getaffinity(0)), threads_per_worker=1,
                                         processes=True, dashboard_address=None)
            self.client = Client(self._cluster)

    def _map(self, fn, tasks, progress, desc):
        from dask.distributed import as_completed as dask_completed
        futures = self.client.map(_guarded, [fn] * len(tasks), tasks, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        results: list[Any] = [None] * len(tasks)
        bar = progress_bar(len(tasks), progress, desc, "run")
        try:
            for fut in dask_completed(futures):
                results[index[fut.key]] = fut.result()
                bar.update(1)
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
    if kind == "local":
        return LocalExecutor(spec.get("workers"))
    if kind == "dask":
        return DaskExecutor(spec.get("address"), spec.get("workers"))
    raise ScenarioError([("<executor>", "executor.type", f"unknown executor {kind!r}; use 'local' or 'dask'")])
