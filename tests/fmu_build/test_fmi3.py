"""FMI 3.0 export (fmu_build fmi_version=3): validated by fmpy, run by fmpy, equal to FMI 2.0.

The FMI 3.0 wrapper runs the same simulation core (model_core.h) and generated code as the FMI
2.0 one, so results must agree to 1e-12 (they are in fact bit-identical).
"""
from __future__ import annotations

import ctypes
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from fmu_build.build import CFLAGS

pytestmark = pytest.mark.needs_gcc
PAIRS = [("gearbox_fmu", "gearbox_fmu3", 0.02, 1e-4), ("two_mass_fmu", "two_mass_fmu3", 2.0, 1e-3)]


@pytest.fixture(scope="module")
def unzip3(tmp_path_factory):
    from fmpy import extract, read_model_description

    cache = {}

    def unzip(fmu: Path):
        if fmu not in cache:
            target = tmp_path_factory.mktemp(Path(fmu).stem.replace(".", "_") + "_fmi3")
            cache[fmu] = (read_model_description(str(fmu)), Path(extract(str(fmu), unzipdir=str(target))))
        return cache[fmu]
    return unzip


@pytest.fixture
def slave3(unzip3):
    """``open(fmu, **start_values) -> (slave, vr)``: an initialised fmpy FMU3Slave."""
    from fmpy.fmi3 import FMU3Slave

    opened = []

    def open_(fmu, **start_values):
        md, unzipped = unzip3(fmu)
        vr = {v.name: v.valueReference for v in md.modelVariables}
        slave = FMU3Slave(guid=md.instantiationToken, unzipDirectory=str(unzipped),
                          modelIdentifier=md.coSimulation.modelIdentifier, instanceName=f"t{len(opened)}")
        slave.instantiate()
        opened.append(slave)
        slave.enterInitializationMode(startTime=0.0)
        for name, value in start_values.items():
            slave.setFloat64([vr[name]], [value])
        slave.exitInitializationMode()
        return slave, vr

    yield open_
    for s in reversed(opened):
        s.terminate()
        s.freeInstance()


@pytest.mark.parametrize("fixture", ["gearbox_fmu3", "two_mass_fmu3"])
def test_fmi3_fmu_validates_with_its_build_description(fixture, request):
    import fmpy
    from fmpy.validation import validate_fmu
    from lxml import etree

    fmu = request.getfixturevalue(fixture)
    assert validate_fmu(str(fmu)) == []
    # the command line users run: `fmpy validate FMU`
    proc = subprocess.run([str(Path(sys.executable).parent / "fmpy"), "validate", str(fmu)], capture_output=True,
                          text=True)
    assert proc.returncode == 0 and "No problems found" in proc.stdout, proc.stdout + proc.stderr
    xsd = Path(fmpy.__file__).parent / "schema" / "fmi3" / "fmi3BuildDescription.xsd"
    with zipfile.ZipFile(fmu) as zf:
        names = set(zf.namelist())
        build = etree.fromstring(zf.read("sources/buildDescription.xml"))
        md = etree.fromstring(zf.read("modelDescription.xml"))
    schema = etree.XMLSchema(etree.parse(str(xsd)))
    assert schema.validate(build), schema.error_log
    listed = {f"sources/{f.get('name')}" for f in build.iter("SourceFile")}
    assert listed == {"sources/fmi3_wrapper.c", "sources/model_functions.c"} and listed <= names
    identifier = md.find("CoSimulation").get("modelIdentifier")
    assert f"binaries/x86_64-linux/{identifier}.so" in names
    assert md.get("fmiVersion") == "3.0" and md.find("DefaultExperiment") is not None
    time_var = [v for v in md.find("ModelVariables") if v.get("causality") == "independent"]
    assert [v.get("name") for v in time_var] == ["time"]
    refs = [int(v.get("valueReference")) for v in md.find("ModelVariables")]
    assert len(refs) == len(set(refs))          # unique across types in FMI 3.0


@pytest.mark.parametrize("fmi2, fmi3, stop, step", PAIRS)
def test_fmpy_runs_fmi3_like_fmi2(fmi2, fmi3, stop, step, request):
    """fmpy's own simulation of both builds: every output equal to 1e-12 (relative to its range)."""
    from fmpy import simulate_fmu

    r2 = simulate_fmu(str(request.getfixturevalue(fmi2)), stop_time=stop, output_interval=step, step_size=step)
    r3 = simulate_fmu(str(request.getfixturevalue(fmi3)), stop_time=stop, output_interval=step, step_size=step)
    assert r2.dtype.names == r3.dtype.names and len(r2) == len(r3) == round(stop / step) + 1
    for name in r2.dtype.names:
        scale = max(np.abs(r2[name]).max(), 1e-300)
        assert np.abs(r3[name] - r2[name]).max() / scale <= 1e-12, name


def test_fmi3_parameters_state_and_bounds(two_mass_fmu3, slave3, capsys):
    slave, vr = slave3(two_mass_fmu3, k12=60.0)
    assert slave.getFloat64([vr["k12"], vr["f1"]]) == [60.0, pytest.approx(np.sqrt(100.0) / (2 * np.pi))]
    slave.doStep(0.0, 0.01)
    assert slave.getFloat64([vr["time"]]) == [0.01]
    state = slave.getFMUState()
    serialized = slave.serializeFMUState(state)
    slave.doStep(0.01, 0.01)
    first = slave.getFloat64([vr["x1"], vr["a2"]])
    slave.setFMUState(slave.deserializeFMUState(serialized))
    slave.doStep(0.01, 0.01)
    assert slave.getFloat64([vr["x1"], vr["a2"]]) == first          # bit for bit
    slave.freeFMUState(state)
    with pytest.raises(Exception):
        slave.setFloat64([vr["m1"]], [-1.0])
    assert "parameter m1 = -1 is outside its range [0, inf]" in capsys.readouterr().out
    with pytest.raises(Exception):
        slave.getInt32([vr["time"]])


def test_fmi3_output_buffer_holds_the_samples_of_each_step(two_mass_fmu3, slave3):
    buffered, vr = slave3(two_mass_fmu3)
    plain, _ = slave3(two_mass_fmu3)
    fn = buffered.dll.twin_fmi3GetOutputBuffer
    fn.restype = ctypes.c_size_t
    fn.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_double), ctypes.c_size_t]
    width = buffered.dll.twin_fmi3OutputBufferWidth()
    buffered.setFloat64([vr["solver.output_interval"]], [0.001])
    buffered.doStep(0.0, 0.01)
    out = np.zeros((10, width))
    assert fn(buffered.component, out.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), 10) == 10
    outputs = sorted((v for n, v in vr.items() if n in ("a2", "position2")))
    expected = []
    for k in range(10):
        plain.doStep(k * 0.001, 0.001)
        expected.append(plain.getFloat64(outputs))
    assert np.allclose(out, expected, rtol=1e-13, atol=1e-15)


def test_fmi3_model_exchange_derivatives_equal_fmi2(two_mass_fmu3, unzip3, two_mass):
    from fmpy.fmi3 import FMU3Model

    md, unzipped = unzip3(two_mass_fmu3)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    model = FMU3Model(guid=md.instantiationToken, unzipDirectory=str(unzipped),
                      modelIdentifier=md.modelExchange.modelIdentifier, instanceName="me3")
    model.instantiate()
    try:
        model.enterInitializationMode(startTime=0.0)
        model.setFloat64([vr["force"]], [0.8])
        model.exitInitializationMode()
        model.enterContinuousTimeMode()
        n = model.getNumberOfContinuousStates()
        x = np.ascontiguousarray(np.random.default_rng(1).normal(size=n))
        dx = np.zeros(n)
        model.setContinuousStates(x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n)
        model.getContinuousStateDerivatives(dx.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n)
        assert np.allclose(dx, (two_mass.matrix() @ [*x, 0.8])[:4], rtol=1e-14, atol=1e-12)
        nominal = np.zeros(n)
        model.getNominalsOfContinuousStates(nominal.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n)
        assert nominal.tolist() == [1.0] * n
    finally:
        model.freeInstance()


def test_fmi3_wrong_token_is_refused(two_mass_fmu3, unzip3, capsys):
    from fmpy.fmi3 import FMU3Slave

    md, unzipped = unzip3(two_mass_fmu3)
    slave = FMU3Slave(guid="{00000000-0000-0000-0000-000000000000}", unzipDirectory=str(unzipped),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="wrong")
    with pytest.raises(Exception, match="Failed to instantiate"):
        slave.instantiate()
    assert f"does not match this binary ({md.instantiationToken})" in capsys.readouterr().out


def test_fmi3_shipped_sources_rebuild_an_equivalent_binary(gearbox_fmu3, unzip3, slave3, tmp_path):
    md, unzipped = unzip3(gearbox_fmu3)
    sources = unzipped / "sources"
    library = unzipped / "binaries" / "x86_64-linux" / f"{md.coSimulation.modelIdentifier}.so"
    reference, vr = slave3(gearbox_fmu3)
    reference.doStep(0.0, 0.002)
    expected = reference.getFloat64([vr["mesh_force"], vr["accel_pinion_casing"]])
    original = library.read_bytes()
    proc = subprocess.run(["gcc", *CFLAGS, "-I", str(sources), "-o", str(library),
                           *sorted(str(p) for p in sources.glob("*.c")), "-lm"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    try:
        rebuilt, _ = slave3(gearbox_fmu3)
        rebuilt.doStep(0.0, 0.002)
        assert rebuilt.getFloat64([vr["mesh_force"], vr["accel_pinion_casing"]]) == expected
    finally:
        library.write_bytes(original)


def test_fmpy_compile_rebuilds_the_fmi3_fmu_from_its_build_description(two_mass_fmu3, tmp_path):
    """`fmpy compile` (CMake) reads sources/buildDescription.xml and rebuilds the binary.

    The copy has no binary: CMake's install step skips a file it finds up to date (`-- Up-to-date:`),
    and on one checkout it kept the shipped binary on every try, so the rebuild was not tested."""
    from fmpy import simulate_fmu

    copy = tmp_path / "rebuilt.fmu"
    with zipfile.ZipFile(two_mass_fmu3) as src, zipfile.ZipFile(copy, "w", zipfile.ZIP_DEFLATED) as dst:
        so = [n for n in src.namelist() if n.startswith("binaries/") and n.endswith(".so")][-1]
        for item in src.infolist():
            if not item.filename.startswith("binaries/"):
                dst.writestr(item, src.read(item))
    proc = subprocess.run([str(Path(sys.executable).parent / "fmpy"), "compile", str(copy)], capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    with zipfile.ZipFile(copy) as a:
        assert so in a.namelist()                # a binary built from the sources ...
    ours = simulate_fmu(str(copy), stop_time=1.0, output_interval=1e-3)
    reference = simulate_fmu(str(two_mass_fmu3), stop_time=1.0, output_interval=1e-3)
    for name in reference.dtype.names:          # ... that computes the same numbers
        assert np.allclose(ours[name], reference[name], rtol=1e-12, atol=1e-15), name
