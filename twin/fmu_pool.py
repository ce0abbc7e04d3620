"""Opened FMUs kept for the next run of the same file in this process.

Unpacking an FMU and loading its binary costs about as much as a short run.  Work that simulates
the same FMU many times in one process (the trials of a diagnosis or a fit, each a few tenths of
a second of simulated time) opens it through :func:`reused` and pays that once per process::

    with reused(fmu_path) as fmu:         # an FMU as FMU(fmu_path) opens it
        fmu.setup(parameters=...)
        fmu.capture(...)
"""
from __future__ import annotations

import atexit
import contextlib
import multiprocessing.util
import os
import threading
from collections.abc import Iterator
from pathlib import Path

from twin.errors import SimulationError
from twin.fmu import FMU, file_sha256

__all__ = ["reused", "close_idle"]

# (process id, resolved path, SHA-256) -> FMUs not in use.  The process id keeps a forked child
# off its parent's instances (their unpacked files are the parent's to remove).
_IDLE: dict[tuple[int, str, str], list[FMU]] = {}
_LOCK = threading.Lock()


@contextlib.contextmanager
def reused(path: str | Path) -> Iterator[FMU]:
    """An :class:`~twin.fmu.FMU` of ``path`` for one caller at a time, kept open for the next one.

    It is handed out as :class:`~twin.fmu.FMU` opens it: instantiated or not, no run started,
    every parameter at its default (an FMU that was used before is reset with ``fmiReset``).
    The file is known by its path and SHA-256, so a rebuilt FMU is opened anew.  An FMU whose
    use raised, or that cannot be reset, is closed instead of kept; those kept are closed when
    the process exits (:func:`close_idle`).
    """
    path = Path(path)
    key = (os.getpid(), str(path.resolve()), file_sha256(path) if path.is_file() else "")
    with _LOCK:
        idle = _IDLE.get(key)
        fmu = idle.pop() if idle else None
    if fmu is None:
        fmu = FMU(path)
    try:
        yield fmu
    except BaseException:
        fmu.close()
        raise
    try:
        fmu.reset()
    except SimulationError:
        fmu.close()
        return
    with _LOCK:
        _IDLE.setdefault(key, []).append(fmu)


def close_idle() -> None:
    """Close the FMUs this process keeps for reuse (and remove their unpacked files)."""
    with _LOCK:
        mine = [k for k in _IDLE if k[0] == os.getpid()]
        fmus = [f for k in mine for f in _IDLE.pop(k)]
    for fmu in fmus:
        with contextlib.suppress(Exception):
            fmu.close()


# at the exit of this process: atexit in a main process; a worker process started by
# multiprocessing (a Dask worker, say) ends with os._exit after running its finalizers instead
atexit.register(close_idle)
multiprocessing.util.Finalize(None, close_idle, exitpriority=0)
