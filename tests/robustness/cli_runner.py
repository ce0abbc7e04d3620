"""Run the real ``twin`` command line in a fresh process, as a user does."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def run_twin(args, cwd, *, timeout=120, env=None) -> subprocess.CompletedProcess:
    """``twin ARGS`` in a new process, as a user runs it."""
    return subprocess.run([sys.executable, "-m", "twin.cli", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, "PYTHONPATH": str(REPO), **(env or {})})


def start_twin(args, cwd) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "twin.cli", *map(str, args)], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(REPO)},
                            start_new_session=True)


def one_error_line(proc: subprocess.CompletedProcess) -> str:
    """The ``twin: error:`` line of a failed run; asserts there is no traceback."""
    assert "Traceback" not in proc.stderr and "internal error" not in proc.stderr, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.startswith("twin: error:")]
    assert proc.returncode == 2 and lines, (proc.returncode, proc.stderr)
    return lines[0]
