"""Session fixtures: the FMUs are built once per test run into a temporary directory.

``make test`` runs the suite in two pytest-xdist worker processes (``-n 2 --dist loadfile``).
The workers share one FMU directory and build each FMU under a file lock, so an FMU is built
once per run, not once per worker (:func:`build_shared`).
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
MODELICA = REPO / "modelica"

if os.environ.get("PYTEST_XDIST_WORKER"):
    # Two workers on two cores: one BLAS/OpenMP/torch thread each (and in their worker
    # processes, which inherit this), instead of two each fighting over the same cores.
    # Set before numpy or torch is imported, which read these at import.
    for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")


def build_shared(model: str, out_dir: Path, **options) -> Path:
    """:func:`fmu_build.build_fmu` of ``model`` into ``out_dir`` under a file lock, so that
    xdist workers asking for the same FMU at once build it once: the first builds, the others
    wait and then find it in the builder's cache (``options`` as for ``build_fmu``)."""
    from filelock import FileLock

    from fmu_build import build_fmu
    out_dir.mkdir(parents=True, exist_ok=True)
    key = hashlib.sha256(repr((model, sorted(options.items(), key=str))).encode()).hexdigest()[:16]
    with FileLock(str(out_dir / f".build-{key}.lock")):
        return build_fmu(model, MODELICA, out_dir, **options)


@pytest.fixture(scope="session")
def shared_build():
    """:func:`build_shared`, for the FMU fixtures of other conftest and test files."""
    return build_shared


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory) -> Path:
    """Where the session FMUs are built: one directory per run, shared by the xdist workers
    (each worker's base temporary directory is a child of the run's)."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        shared = tmp_path_factory.getbasetemp().parent / "fmus"
        shared.mkdir(exist_ok=True)
        return shared
    return tmp_path_factory.mktemp("fmus")


@pytest.fixture(scope="session")
def gearbox_fmu(fmu_dir) -> Path:
    """The 21-DOF gearbox FMU built from modelica/ (GearTwin.Gearbox21)."""
    return build_shared("GearTwin.Gearbox21", fmu_dir)


@pytest.fixture(scope="session")
def measured_fmu(fmu_dir) -> Path:
    """The gearbox as its casing accelerometers measure it (GearTwin.Gearbox21Measured)."""
    return build_shared("GearTwin.Gearbox21Measured", fmu_dir)


@pytest.fixture(scope="session")
def casing_fmu(fmu_dir) -> Path:
    """The gearbox on a casing that moves on its mounts, sensors on the casing (GearTwin.Gearbox21Casing)."""
    return build_shared("GearTwin.Gearbox21Casing", fmu_dir)


@pytest.fixture(scope="session")
def shafts_fmu(fmu_dir) -> Path:
    """The casing model with shafts that bend, from their geometry (GearTwin.Gearbox21Shafts)."""
    return build_shared("GearTwin.Gearbox21Shafts", fmu_dir)


@pytest.fixture(scope="session")
def overhangs_fmu(fmu_dir) -> Path:
    """The shafts model with the parts carried on the overhung shaft ends (GearTwin.Gearbox21Overhangs)."""
    return build_shared("GearTwin.Gearbox21Overhangs", fmu_dir)


@pytest.fixture(scope="session")
def rocking_fmu(fmu_dir) -> Path:
    """The overhangs model with the gear rocking on its shaft (GearTwin.Gearbox21Rocking)."""
    return build_shared("GearTwin.Gearbox21Rocking", fmu_dir)


@pytest.fixture(scope="session")
def walls_fmu(fmu_dir) -> Path:
    """The shafts model with flexible casing walls under the housings (GearTwin.Gearbox21Walls)."""
    return build_shared("GearTwin.Gearbox21Walls", fmu_dir)


@pytest.fixture(scope="session")
def tilting_walls_fmu(fmu_dir) -> Path:
    """The shafts model on casing walls that also tilt the housings (GearTwin.Gearbox21TiltingWalls)."""
    return build_shared("GearTwin.Gearbox21TiltingWalls", fmu_dir)


@pytest.fixture(scope="session")
def wheel_fmu(fmu_dir) -> Path:
    """The variant with the gear's own tooth errors (GearTwin.Variants.Gearbox21WheelErrors)."""
    return build_shared("GearTwin.Variants.Gearbox21WheelErrors", fmu_dir)


@pytest.fixture(scope="session")
def two_mass_fmu(fmu_dir) -> Path:
    """A second, small model built by the same pipeline (GearTwin.Examples.TwoMassOscillator)."""
    return build_shared("GearTwin.Examples.TwoMassOscillator", fmu_dir)


@pytest.fixture(scope="session")
def gearbox_fmu3(fmu_dir) -> Path:
    """GearTwin.Gearbox21 built as an FMI 3.0 FMU (same code and solver as gearbox_fmu)."""
    return build_shared("GearTwin.Gearbox21", fmu_dir / "fmi3", fmi_version=3)


@pytest.fixture(scope="session")
def two_mass_fmu3(fmu_dir) -> Path:
    """GearTwin.Examples.TwoMassOscillator built as an FMI 3.0 FMU."""
    return build_shared("GearTwin.Examples.TwoMassOscillator", fmu_dir / "fmi3", fmi_version=3)


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


def pytest_collection_modifyitems(config, items):
    """Under xdist, the files with ``slow`` tests go first: each takes minutes on one worker,
    and started last they would leave the other worker idle at the end of the run."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        slow_files = {item.path for item in items if item.get_closest_marker("slow")}
        items.sort(key=lambda item: item.path not in slow_files)     # stable: order kept within files
