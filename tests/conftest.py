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
def casing_fmu(fmu_dir) -> Path:
    """The gearbox on a casing that moves on its mounts, sensors on the casing (GearTwin.Gearbox21Casing)."""
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Gearbox21Casing", MODELICA, fmu_dir)


@pytest.fixture(scope="session")
def shafts_fmu(fmu_dir) -> Path:
    """The casing model with shafts that bend, from their geometry (GearTwin.Gearbox21Shafts)."""
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Gearbox21Shafts", MODELICA, fmu_dir)


@pytest.fixture(scope="session")
def walls_fmu(fmu_dir) -> Path:
    """The shafts model with flexible casing walls under the housings (GearTwin.Gearbox21Walls)."""
    from fmu_build import build_fmu
    return build_fmu("GearTwin.Gearbox21Walls", MODELICA, fmu_dir)


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


def _thirdparty_builder():
    import importlib.util
    spec = importlib.util.spec_from_file_location("build_thirdparty", REPO / "tests" / "thirdparty" / "build_thirdparty.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _needs_gcc() -> None:
    import shutil
    if shutil.which("gcc") is None:
        pytest.skip("gcc is not available")


@pytest.fixture(scope="session")
def vanderpol_fmu(tmp_path_factory) -> Path:
    """The hand-written Van der Pol FMU of tests/thirdparty/vanderpol (FMI 2.0), built with gcc."""
    _needs_gcc()
    return _thirdparty_builder().build_vanderpol(tmp_path_factory.mktemp("thirdparty"))


@pytest.fixture(scope="session")
def typecov_fmus(tmp_path_factory) -> dict[tuple[str, int], Path]:
    """The hand-written type-coverage FMUs of tests/thirdparty/typecov, built with gcc for FMI 2.0
    and FMI 3.0: {(model, version): path} for AllTypes, Staircase and Ball."""
    _needs_gcc()
    builder = _thirdparty_builder()
    root = tmp_path_factory.mktemp("typecov")
    return {(model, version): builder.build_typecov(model, version, root / f"fmi{version}")
            for version in (2, 3) for model in builder.TYPECOV_MODELS}
