"""The candidate model (every catalogue effect, switched off) built once per session."""
from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def candidates_fmu(fmu_dir, shared_build) -> Path:
    return shared_build("GearTwin.Variants.Gearbox21Candidates", fmu_dir)


@pytest.fixture(scope="session")
def executor():
    from twin.executor import LocalExecutor
    ex = LocalExecutor(2)
    yield ex
    ex.close()
