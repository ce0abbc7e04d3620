"""Atomic file replacement shared by every writer in the twin.

A reader (or a crashed run) must never see a half-written result, plot or FMU,
and a failed write must leave an existing file untouched. Writers therefore
produce a temporary sibling file and rename it over the target only once it is
complete and on disk.
"""
from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path

from twin.errors import OutputPathError


def check_parent(path: str | os.PathLike[str]) -> Path:
    """Return ``path`` as a :class:`Path` after checking it can be written.

    Raises
    ------
    OutputPathError
        If the parent directory does not exist (it is never created silently,
        so a typo in a directory name is reported instead of hidden) or if the
        path itself is an existing directory.
    """
    target = Path(path)
    parent = target.parent
    if not parent.is_dir():
        raise OutputPathError(f"output directory '{parent}' does not exist (for '{target}')")
    if target.is_dir():
        raise OutputPathError(f"output path '{target}' is a directory")
    return target


def check_output_dir(path: str | os.PathLike[str], what: str = "output", *, create: bool = False) -> Path:
    """Return ``path`` as a :class:`Path` after checking a directory of results can be written there
    (its parent exists, and it is a directory or does not exist yet); ``create`` makes it.

    Raises
    ------
    OutputPathError
        A missing parent (never created silently), or ``path`` is a file; ``what`` names the
        directory in the message ("assessor", "report").
    """
    d = Path(path)
    if d.exists() and not d.is_dir():
        raise OutputPathError(f"{what} directory '{d}' exists and is not a directory")
    if not d.parent.is_dir():
        raise OutputPathError(f"output directory '{d.parent}' does not exist (for '{d}')")
    if create:
        d.mkdir(exist_ok=True)
    return d


def _final_mode(target: Path) -> int:
    """Permission bits the finished file should get.

    ``NamedTemporaryFile`` creates files as 0600; keep the mode of a file being
    replaced, otherwise use what a plain ``open()`` would give under the umask.
    """
    try:
        return stat.S_IMODE(target.stat().st_mode)
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path in the target's directory; move it over ``path`` on success.

    The body writes the complete file to the yielded path (by name, e.g. with
    ``h5py.File(tmp, "w")`` or ``fig.savefig(tmp)``) and closes it. On normal
    exit the data are fsync'ed and the file is renamed onto ``path`` with
    :func:`os.replace`, which is atomic within one file system (hence the
    temporary file lives in the same directory). If the body raises, the
    temporary file is removed, ``path`` is left as it was and the exception
    propagates.

    Raises
    ------
    OutputPathError
        If the parent directory of ``path`` is missing or ``path`` is a directory.
    """
    target = check_parent(path)
    remove_stale_temporaries(target)
    try:
        with tempfile.NamedTemporaryFile(
            delete=False, dir=target.parent, prefix=f".{target.name}.{os.getpid()}.", suffix=".tmp"
        ) as handle:
            tmp = Path(handle.name)
    except OSError as exc:
        raise OutputPathError(f"cannot write '{target}': {(exc.strerror or str(exc)).lower()} "
                              f"in directory '{target.parent}'") from None
    try:
        yield tmp
        fd = os.open(tmp, os.O_RDWR)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.chmod(tmp, _final_mode(target))
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise
    # Persist the rename itself; not every platform lets a directory be opened.
    with contextlib.suppress(OSError):
        dir_fd = os.open(target.parent, os.O_RDONLY)
        try:
            os.fsync(dir_fd)
        finally:
            os.close(dir_fd)


def partial_path(path: str | os.PathLike[str]) -> Path:
    """Where an interrupted run keeps its output: ``out.h5`` -> ``out.partial.h5``."""
    p = Path(path)
    return p.with_name(f"{p.stem}.partial{p.suffix}")


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale_temporaries(target: Path) -> None:
    """Remove the temporary siblings of ``target`` left by writers that were killed (SIGKILL,
    a crash) before they could clean up: ``.<name>.<pid>.<random>.tmp`` whose process is gone."""
    try:
        siblings = list(target.parent.glob(f".{glob_escape(target.name)}.*.tmp"))
    except OSError:
        return
    for tmp in siblings:
        parts = tmp.name[len(target.name) + 2:].split(".")
        if len(parts) >= 3 and parts[0].isdigit() and not _pid_alive(int(parts[0])):
            with contextlib.suppress(OSError):
                tmp.unlink()


def glob_escape(name: str) -> str:
    import glob
    return glob.escape(name)
