"""The candidate model (every catalogue effect, switched off) built once per session."""
from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def candidates_fmu(fmu_dir) -> Path:
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Variants.Gearbox21Candidates", REPO / "modelica", fmu_dir)


@pytest.fixture(scope="session")
def executor():
    from twin.executor import LocalExecutor
    ex = LocalExecutor(2)
    yield ex
    ex.close()
