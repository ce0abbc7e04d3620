"""Crash-isolated FMU work: FMUs run in worker processes that may die without ending the run.

An FMU is native code loaded into the process that calls it.  A segmentation fault, an
``exit()`` or an endless loop inside ``fmi2DoStep`` would take the Python process with it, so
everything that runs many simulations (calibration, diagnosis, archives) runs them in worker
processes, and a single ``twin simulate``/``twin run`` runs its FMU in one child process:

* :class:`IsolatedPool` (on :class:`pebble.ProcessPool`): each task has a time limit; a worker
  that dies or passes the limit is replaced by the pool, and the task's slot holds a
  :class:`~twin.errors.WorkerCrashError` naming the signal or exit status (or the limit), which
  the caller scores infeasible, retries or reports.  The other tasks go on.
* :func:`run_isolated`: one call in a forked child; its result or exception comes back, and
  its death becomes a :class:`~twin.errors.WorkerCrashError`.

Each worker keeps its temporary files (the unpacked FMUs) under one directory per pool or
child, which the parent removes when the pool closes or the child ends, so a crash leaves no
``/tmp/twin_fmu_*`` behind.  Ctrl-C (see :mod:`twin._interrupt`) stops a pool between tasks
and kills its workers; a child of :func:`run_isolated` receives the SIGINT itself and stops at
its next step boundary, like an in-process run.
"""
from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import shutil
import signal
import tempfile
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, BrokenExecutor
from concurrent.futures import TimeoutError as FutureTimeout
from concurrent.futures import wait
from pathlib import Path
from typing import Any

from twin import _interrupt
from twin._atomic import _pid_alive as _alive
from twin.errors import WorkerCrashError

log = logging.getLogger(__name__)

#: Seconds a child of :func:`run_isolated` gets to finish its step and write its partial
#: output after Ctrl-C before it is killed (a second Ctrl-C kills it at once).
INTERRUPT_GRACE = 20.0


def describe_exit(exitcode: int | None) -> str:
    """``'killed by signal SIGSEGV (Segmentation fault)'`` or ``'exited with status 3'``."""
    if exitcode is None:
        return "ended without an exit status"
    if exitcode < 0:
        try:
            sig = signal.Signals(-exitcode)
            return f"killed by signal {sig.name} ({signal.strsignal(sig)})"
        except ValueError:
            return f"killed by signal {-exitcode}"
    return f"exited with status {exitcode}"


def _private_root(kind: str) -> str:
    """A new directory for the temporary files of this process's workers or child, named with
    this process's id; those of processes that are gone (a parent killed by SIGKILL cannot clean
    up) are removed first."""
    base = Path(tempfile.gettempdir())
    for old in base.glob(f"twin_{kind}_*"):
        pid = old.name.split("_")[2] if old.name.count("_") >= 3 else ""
        if pid.isdigit() and not _alive(int(pid)):
            shutil.rmtree(old, ignore_errors=True)
    return tempfile.mkdtemp(prefix=f"twin_{kind}_{os.getpid()}_")


def _use_tempdir(root: str) -> None:
    """Send this process's temporary files (the unpacked FMUs) under ``root``, and die with the
    parent: a worker must not outlive a run that was killed (and go on writing its results)."""
    tempfile.tempdir = tempfile.mkdtemp(prefix=f"worker{os.getpid()}_", dir=root)
    with contextlib.suppress(Exception):
        import ctypes
        PR_SET_PDEATHSIG = 1
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)


def _pool_worker_init(root: str) -> None:
    _interrupt.reset_in_child()
    _use_tempdir(root)


def _pool_call(fn, task):
    return fn(task)


class IsolatedPool:
    """Worker processes (spawned, so no lock or thread of the parent is inherited) for FMU tasks.

    Parameters
    ----------
    workers : number of worker processes.
    timeout : time limit [s] of one task; a task still running then is stopped (its worker is
        killed and replaced) and scored a :class:`WorkerCrashError`.  ``None``: no limit.
    retries : how often a task whose worker died is run again (a hang is not retried).
    """

    def __init__(self, workers: int, *, timeout: float | None = None, retries: int = 0):
        import pebble

        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        if timeout is not None and not timeout > 0:
            raise ValueError(f"timeout must be > 0 s, got {timeout!r}")
        self.workers = int(workers)
        self.timeout = timeout
        self.retries = int(retries)
        self._root = _private_root("pool")
        self._pool = pebble.ProcessPool(max_workers=self.workers, initializer=_pool_worker_init,
                                        initargs=(self._root,), context=multiprocessing.get_context("spawn"))
        self.crashes: list[WorkerCrashError] = []

    def map(self, fn: Callable[[Any], Any], tasks: Sequence[Any], *,
            on_done: Callable[[int, Any], None] | None = None) -> list[Any]:
        """Run ``fn(task)`` for every task; results in task order.

        A task that raises has its exception in its slot; a task whose worker died or hung has
        a :class:`WorkerCrashError`.  ``on_done(index, result)`` is called as tasks finish.
        Ctrl-C (with :mod:`twin._interrupt` installed) stops the pool and raises
        :class:`KeyboardInterrupt`.
        """
        tasks = list(tasks)
        results: list[Any] = [None] * len(tasks)
        attempts = [0] * len(tasks)
        pending = {self._schedule(fn, t): i for i, t in enumerate(tasks)}
        try:
            while pending:
                done, _ = wait(list(pending), timeout=0.25, return_when=FIRST_COMPLETED)
                _interrupt.check()
                for fut in done:
                    i = pending.pop(fut)
                    r = self._outcome(fut, i)
                    if isinstance(r, WorkerCrashError) and r.timeout is None and attempts[i] < self.retries:
                        attempts[i] += 1
                        log.warning("task %d: %s; running it again (attempt %d)", i, r, attempts[i] + 1)
                        pending[self._schedule(fn, tasks[i])] = i
                        continue
                    results[i] = r
                    if on_done is not None:
                        on_done(i, r)
        except BaseException:
            for fut in pending:
                fut.cancel()
            self._pool.stop()
            self._pool.join()
            raise
        return results

    def _schedule(self, fn, task):
        return self._pool.schedule(_pool_call, args=(fn, task), timeout=self.timeout)

    def _outcome(self, fut, i: int):
        import pebble
        try:
            return fut.result()
        except FutureTimeout:
            err = WorkerCrashError(f"task {i} passed its time limit of {self.timeout:g} s and was stopped "
                                   "(its worker was replaced)", timeout=self.timeout)
        except pebble.ProcessExpired as exc:
            err = WorkerCrashError(f"the worker process running task {i} {describe_exit(exc.exitcode)} "
                                   "(it was replaced)", exitcode=exc.exitcode)
        except BrokenExecutor as exc:
            # no worker could start (every one died while importing): no task ran, so the pool is
            # unusable and every result would be this error; stop instead of handing it back as
            # the task's own failure, which a caller would score as a candidate that did not fit
            raise WorkerCrashError(f"the worker processes could not start ({exc}); a script that runs twin with "
                                   "worker processes must start it under 'if __name__ == \"__main__\":' (Python's "
                                   "multiprocessing: safe importing of the main module), or run the tasks in "
                                   "this process (LocalExecutor(isolate=False))") from None
        except Exception as exc:   # raised by the task itself: the caller decides
            return exc
        self.crashes.append(err)
        log.warning("%s", err)
        return err

    def close(self) -> None:
        """Stop the workers and remove their temporary files (also those of crashed workers)."""
        with contextlib.suppress(Exception):
            self._pool.close()
            self._pool.join(timeout=10)
        with contextlib.suppress(Exception):
            self._pool.stop()
            self._pool.join()
        shutil.rmtree(self._root, ignore_errors=True)

    def __enter__(self) -> "IsolatedPool":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _child_main(root: str, fn, args, kwargs):
    _use_tempdir(root)
    # pebble's children ignore SIGINT; this one stops at its next step boundary instead, like an
    # in-process run (SIGTERM stays pebble's, which ends the child)
    _interrupt.clear()
    _interrupt.install(sigterm=False)
    return fn(*args, **kwargs)


def _kill(processes) -> None:
    for p in processes:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.kill(p.pid, signal.SIGKILL)


def run_isolated(fn: Callable[..., Any], *args, timeout: float | None = None, what: str = "the simulation",
                 **kwargs) -> Any:
    """``fn(*args, **kwargs)`` in a forked child process; its return value, or its exception.

    The child inherits the parent's state (no pickling of the arguments; the return value is
    pickled back).  Raises :class:`WorkerCrashError` naming the signal or exit status if the
    child dies, or the limit if it runs longer than ``timeout`` seconds.  On Ctrl-C the child is
    sent SIGINT and given :data:`INTERRUPT_GRACE` seconds to stop at a step boundary (an
    orchestrated run then returns its partial result); then it is killed.
    """
    import pebble

    root = _private_root("run")
    task = pebble.concurrent.process(daemon=True, context=multiprocessing.get_context("fork"))(_child_main)
    before = {p.pid for p in multiprocessing.active_children()}
    t0 = time.monotonic()
    forwarded_at = None
    future = None
    child = []
    try:
        future = task(root, fn, args, kwargs)
        child = [p for p in multiprocessing.active_children() if p.pid not in before]
        while True:
            try:
                return future.result(timeout=0.25)
            except FutureTimeout:
                pass
            now = time.monotonic()
            if _interrupt.requested() and forwarded_at is None:
                forwarded_at = now
                for p in child:
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(p.pid, signal.SIGINT)
            if forwarded_at is not None and now - forwarded_at > INTERRUPT_GRACE:
                raise KeyboardInterrupt
            if timeout is not None and now - t0 > timeout:
                raise WorkerCrashError(f"{what} passed its time limit of {timeout:g} s and was stopped",
                                       timeout=timeout)
    except pebble.ProcessExpired as exc:
        raise WorkerCrashError(f"the FMU process running {what} {describe_exit(exc.exitcode)}",
                               exitcode=exc.exitcode) from None
    finally:
        if future is not None and not future.done():
            # killed, not cancelled: pebble then completes the future itself (with ProcessExpired)
            _kill(child)
            with contextlib.suppress(BaseException):
                future.exception(timeout=10)
        shutil.rmtree(root, ignore_errors=True)
