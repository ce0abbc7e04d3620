"""Ctrl-C that is honoured every time, at a point where stopping is safe.

Python's default SIGINT handler raises :class:`KeyboardInterrupt` at whatever bytecode runs
next.  When that is a finaliser or a weakref callback (fmpy and h5py have both), the
interpreter prints "Exception ignored in ..." and the run goes on as if nothing happened.

:func:`install` replaces the handler with one that only records the request; long loops call
:func:`check` at their step boundaries (a co-simulation step, a degradation stage, a batch of
evaluations) and the :class:`KeyboardInterrupt` is raised there, in ordinary code.  A second
Ctrl-C while the first is pending raises at once, for a user who does not want to wait for the
current step.  Without :func:`install` (library use), the default behaviour is unchanged and
:func:`check` never raises.
"""
from __future__ import annotations

import signal
import threading

_requested = threading.Event()
_installed = False


def _handler(signum, frame) -> None:
    if _requested.is_set():
        raise KeyboardInterrupt
    _requested.set()


def install(*, sigterm: bool = True) -> None:
    """Record SIGINT (and SIGTERM) instead of raising at an arbitrary point (main thread only)."""
    global _installed
    if threading.current_thread() is not threading.main_thread():
        return
    signal.signal(signal.SIGINT, _handler)
    if sigterm:
        signal.signal(signal.SIGTERM, _handler)
    _installed = True


def uninstall() -> None:
    """Restore the default handlers and forget a pending request."""
    global _installed
    if _installed and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _installed = False
    _requested.clear()


def requested() -> bool:
    """True once an interrupt has been requested (and not cleared)."""
    return _requested.is_set()


def check() -> None:
    """Raise :class:`KeyboardInterrupt` here if an interrupt was requested."""
    if _requested.is_set():
        raise KeyboardInterrupt


def clear() -> None:
    _requested.clear()


def reset_in_child() -> None:
    """In a worker process: Ctrl-C at the terminal reaches the whole process group, but the
    parent decides what happens to the batch, so a worker ignores SIGINT."""
    _requested.clear()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
