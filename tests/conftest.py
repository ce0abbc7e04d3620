"""Session fixtures: the FMUs are built once per test session into a temporary directory."""
from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
MODELICA = REPO / "modelica"


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("fmus")


@pytest.fixture(scope="session")
def gearbox_fmu(fmu_dir) -> Path:
    """The 21-DOF gearbox FMU built from modelica/ (GearTwin.Gearbox21)."""
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Gearbox21", MODELICA, fmu_dir)


@pytest.fixture(scope="session")
def measured_fmu(fmu_dir) -> Path:
    """The gearbox as its casing accelerometers measure it (GearTwin.Gearbox21Measured)."""
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Gearbox21Measured", MODELICA, fmu_dir)


@pytest.fixture(scope="session")
def wheel_fmu(fmu_dir) -> Path:
    """The variant with the gear's own tooth errors (GearTwin.Variants.Gearbox21WheelErrors)."""
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Variants.Gearbox21WheelErrors", MODELICA, fmu_dir)


@pytest.fixture(scope="session")
def two_mass_fmu(fmu_dir) -> Path:
    """A second, small model built by the same pipeline (GearTwin.Examples.TwoMassOscillator)."""
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Examples.TwoMassOscillator", MODELICA, fmu_dir)


@pytest.fixture(scope="session")
def gearbox_fmu3(fmu_dir) -> Path:
    """GearTwin.Gearbox21 built as an FMI 3.0 FMU (same code and solver as gearbox_fmu)."""
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Gearbox21", MODELICA, fmu_dir / "fmi3", fmi_version=3)


@pytest.fixture(scope="session")
def two_mass_fmu3(fmu_dir) -> Path:
    """GearTwin.Examples.TwoMassOscillator built as an FMI 3.0 FMU."""
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Examples.TwoMassOscillator", MODELICA, fmu_dir / "fmi3", fmi_version=3)
