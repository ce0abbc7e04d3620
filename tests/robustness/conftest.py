"""Fixtures of the robustness suite: the deliberately failing FMUs (built once with gcc) and a
runner of the real ``twin`` command line in a fresh process."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
# the workers of the process pools unpickle the test tasks by module name
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE / "faulty"))


@pytest.fixture(scope="session")
def faulty_fmus(tmp_path_factory) -> dict[str, Path]:
    """``faulty`` (fails on request), ``wrong_guid`` (fmi2Instantiate returns NULL) and
    ``truncated`` (a cut shared library), see ``faulty/Faulty.c``."""
    from build_faulty import build_faulty
    return build_faulty(tmp_path_factory.mktemp("faulty"))
