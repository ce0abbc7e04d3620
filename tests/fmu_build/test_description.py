"""fmu_build.description: a complete modelDescription.xml and documentation/index.html.

Units with BaseUnit exponents (one spelling each), min/max/nominal from the Modelica attributes
(and enforced by the binary), ModelStructure dependencies that match the generated code,
described states, generation metadata, the DefaultExperiment and the documentation page.
"""
from __future__ import annotations

import ctypes
import math
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

import fmu_build
from twin.errors import BuildError
from twin.units import parse_unit

pytestmark = pytest.mark.needs_gcc
FMU_FIXTURES = ["gearbox_fmu", "two_mass_fmu"]


def _xml(fmu: Path) -> ET.Element:
    with zipfile.ZipFile(fmu) as zf:
        return ET.fromstring(zf.read("modelDescription.xml"))


def _variables(root: ET.Element) -> dict[str, ET.Element]:
    return {sv.get("name"): sv for sv in root.iter("ScalarVariable")}


@pytest.mark.parametrize("fixture", FMU_FIXTURES)
def test_every_unit_is_defined_once_with_its_base_units(fixture, request):
    root = _xml(request.getfixturevalue(fixture))
    units = root.find("UnitDefinitions").findall("Unit")
    names = [u.get("name") for u in units]
    assert len(names) == len(set(names))
    used = {sv.find("Real").get("unit") for sv in root.iter("ScalarVariable") if sv.find("Real") is not None} - {None}
    assert used <= set(names)
    keys = set()
    for u in units:
        base = u.find("BaseUnit")
        assert base is not None, u.get("name")
        parsed = parse_unit(u.get("name"))
        exps = tuple(int(base.get(k, "0")) for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad"))
        assert exps == parsed.exponents, u.get("name")
        assert float(base.get("factor", "1")) == parsed.factor
        keys.add(u.get("name").replace("/s/s", "/s2"))
    # one spelling per unit: the derivative of a velocity is m/s2, as the model writes accelerations
    assert not any("/s/s" in n for n in names)
    assert len(keys) == len(names)


def test_min_max_nominal_come_from_the_modelica_attributes(gearbox_fmu):
    v = _variables(_xml(gearbox_fmu))

    def real(name):
        return v[name].find("Real").attrib

    assert real("k_pair[3]")["min"] == "0.0" and float(real("k_pair[3]")["nominal"]) == 1e8
    assert float(real("alpha")["max"]) == pytest.approx(math.pi / 2)
    assert real("I10")["min"] == "0.0" and real("kt12")["min"] == "0.0"
    assert float(real("x5")["nominal"]) == 1e-6 and float(real("omega1")["nominal"]) == 100.0
    assert real("pair_force[2]")["min"] == "0.0"
    assert "min" not in real("sensor_angle_pinion") and "min" not in real("profile_deviation[1]")
    for name, sv in v.items():
        r = sv.find("Real")
        if r is None or r.get("start") is None:
            continue
        start = float(r.get("start"))
        assert float(r.get("min", "-inf")) <= start <= float(r.get("max", "inf")), name


def test_the_binary_refuses_a_parameter_outside_its_range(two_mass_fmu, unzip_fmu, capsys):
    from fmpy.fmi2 import FMU2Slave

    md, unzipped = unzip_fmu(two_mass_fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables if v.type == "Real"}
    slave = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipped), modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="bounds")
    slave.instantiate()
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setReal([vr["k12"]], [40.0])
        with pytest.raises(Exception):
            slave.setReal([vr["m2"]], [-0.5])
        assert "parameter m2 = -0.5 is outside its range [0, inf]" in capsys.readouterr().out
        assert slave.getReal([vr["m2"]]) == [0.5]      # the value before the refused call
    finally:
        slave.freeInstance()


def _structure(root: ET.Element, section: str) -> dict[str, list[tuple[str, str]]]:
    order = [sv.get("name") for sv in root.iter("ScalarVariable")]
    out = {}
    for u in root.find("ModelStructure").find(section).findall("Unknown"):
        deps = [order[int(i) - 1] for i in (u.get("dependencies") or "").split()]
        kinds = (u.get("dependenciesKind") or "").split() or [None] * len(deps)
        out[order[int(u.get("index")) - 1]] = list(zip(deps, kinds))
    return out


def test_two_mass_dependencies_are_the_nonzeros_of_its_system_matrix(two_mass_fmu, two_mass):
    root = _xml(two_mass_fmu)
    ders = _structure(root, "Derivatives")
    knowns = [*two_mass.states, "force"]
    a = two_mass.matrix()
    for i, s in enumerate(two_mass.states):
        expected = {knowns[j] for j in range(5) if a[i, j] != 0.0}
        assert {d for d, _ in ders[f"der({s})"]} == expected, s
    # der(x1) = v1 enters with a constant factor; der(v1) has parameter factors
    assert ders["der(x1)"] == [("v1", "constant")]
    assert {k for _, k in ders["der(v1)"]} == {"tunable"}
    outputs = _structure(root, "Outputs")
    assert outputs["position2"] == [("x2", "constant")]
    assert {d for d, _ in outputs["a2"]} == {"x1", "x2", "force"}
    # at initialisation the states depend on nothing but their (literal) starts
    initial = _structure(root, "InitialUnknowns")
    assert initial["x1"] == [] and {d for d, _ in initial["f1"]} == {"k1", "m1"}


def test_gearbox_dependencies_cover_every_numerical_sensitivity(gearbox_fmu, unzip_fmu):
    """Finite differences of the Model Exchange derivatives: no state enters a derivative that
    the ModelStructure does not list (the declared ones may be numerically zero at one point)."""
    from fmpy.fmi2 import FMU2Model

    root = _xml(gearbox_fmu)
    ders = _structure(root, "Derivatives")
    md, unzipped = unzip_fmu(gearbox_fmu)
    states = [d.variable.derivative.name for d in md.derivatives]
    model = FMU2Model(guid=md.guid, unzipDirectory=str(unzipped), modelIdentifier=md.modelExchange.modelIdentifier,
                      instanceName="deps")
    model.instantiate()
    try:
        model.setupExperiment(startTime=0.0)
        model.enterInitializationMode()
        model.exitInitializationMode()
        model.enterContinuousTimeMode()
        n = len(states)
        x0 = np.zeros(n)
        model.getContinuousStates(x0.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n)

        def f(x):
            x = np.ascontiguousarray(x)
            dx = np.zeros(n)
            model.setContinuousStates(x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n)
            model.getDerivatives(dx.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n)
            return dx

        base = f(x0)
        missing = []
        for j in range(n):
            h = 1e-7 * max(1.0, abs(x0[j]))
            x = x0.copy()
            x[j] += h
            changed = np.nonzero(f(x) != base)[0]
            for i in changed:
                if states[j] not in {d for d, _ in ders[f"der({states[i]})"]}:
                    missing.append((states[i], states[j]))
        assert missing == []
    finally:
        model.freeInstance()
    assert ders["der(theta1)"] == [("omega1", "constant")]
    outputs = _structure(root, "Outputs")
    assert {d for d, _ in outputs["motor_torque"]} == {"omega1", "motor_speed_ref", "drive_torque"}
    assert dict(outputs["motor_torque"])["drive_torque"] == "constant"


@pytest.mark.parametrize("fixture", FMU_FIXTURES)
def test_states_are_described_and_metadata_is_set(fixture, request):
    root = _xml(request.getfixturevalue(fixture))
    v = _variables(root)
    for sv in v.values():
        real = sv.find("Real")
        if real is not None and real.get("derivative"):
            state = list(v.values())[int(real.get("derivative")) - 1]
            assert state.get("description"), state.get("name")
    assert root.get("version") == "0.1.0" and root.get("author")
    assert root.get("generationDateAndTime").endswith("Z")
    assert root.get("generationTool").startswith("gear-twin fmu_build")


def test_default_experiment_is_a_communication_step_not_the_solver_step(gearbox_fmu, two_mass_fmu):
    for fmu, step, stop in ((gearbox_fmu, 1e-4, 1.0), (two_mass_fmu, 1e-3, 10.0)):
        root = _xml(fmu)
        exp = root.find("DefaultExperiment")
        assert float(exp.get("stepSize")) == step and float(exp.get("stopTime")) == stop
        solver = _variables(root)["solver.step_size"].find("Real")
        assert float(solver.get("start")) == 5e-6 < step


@pytest.mark.parametrize("fixture", FMU_FIXTURES)
def test_documentation_page_and_no_fmi3_build_description(fixture, request):
    fmu = request.getfixturevalue(fixture)
    with zipfile.ZipFile(fmu) as zf:
        names = set(zf.namelist())
        page = zf.read("documentation/index.html").decode()
    assert "sources/buildDescription.xml" not in names     # an FMI 3.0 file; FMI 2.0 lists <SourceFiles>
    root = _xml(fmu)
    assert f"<title>{root.get('modelName')}</title>" in page
    for sv in root.iter("ScalarVariable"):
        if sv.get("causality") in ("input", "output"):
            assert f"<code>{sv.get('name')}</code>" in page
    if fixture == "gearbox_fmu":
        assert "<h2>Degrees of freedom (21, so 42 states)</h2>" in page     # from Gearbox21.readme.md


# ---- errors and annotations of a model written at test time ---------------------------------------
PLANT = """
model Plant "A test plant"
  parameter Real k(unit = "N/m", min = 0) = 10 "Spring";
  parameter Real m(unit = "kg", min = 0) = 1 "Mass";
  Real x(unit = "m", start = 1, nominal = 0.1) "Position";
  Real v(unit = "m/s", start = 0) "Velocity";
  output Real y(unit = "UNIT") = x;
equation
  der(x) = v;
  m * der(v) = -k * x;
  annotation(experiment(StartTime = 0.5, StopTime = 2.5, Interval = 0.01, Tolerance = 1e-6));
end Plant;
annotation(version = "2.1.0", __GearTwin(author = "A. Tester", license = "BSD-3-Clause", copyright = "2026 A. Tester"));
"""


def test_annotations_give_experiment_and_metadata(tmp_path, write_package):
    write_package(tmp_path / "lib", "Lab", PLANT.replace("UNIT", "mm"))
    root = _xml(fmu_build.build_fmu("Lab.Plant", tmp_path / "lib", tmp_path / "out"))
    exp = root.find("DefaultExperiment").attrib
    assert {k: float(v) for k, v in exp.items()} == {"startTime": 0.5, "stopTime": 2.5, "stepSize": 0.01,
                                                     "tolerance": 1e-6}
    assert (root.get("version"), root.get("author"), root.get("license"), root.get("copyright")) == \
        ("2.1.0", "A. Tester", "BSD-3-Clause", "2026 A. Tester")
    mm = next(u for u in root.find("UnitDefinitions") if u.get("name") == "mm")
    assert mm.find("BaseUnit").attrib == {"m": "1", "factor": "0.001"}


@pytest.mark.parametrize("change, message", [
    (('unit = "UNIT"', 'unit = "furlong"'), r"unit of y: .*unknown unit symbol 'furlong'"),
    (("min = 0) = 10", "min = 20) = 10"), r"k: default value 10.0 is below its min = 20.0"),
    (('unit = "kg", min = 0)', 'unit = "kg", min = 2, max = 1)'), r"m: min = 2.0 is above max = 1.0"),
    (("nominal = 0.1", "nominal = -0.1"), r"nominal of x must be > 0"),
    (("Interval = 0.01", "Interval = -0.01"), r"experiment stepSize of Plant must be > 0"),
])
def test_bad_attributes_are_refused_by_name(tmp_path, write_package, change, message):
    write_package(tmp_path / "lib", "Lab", PLANT.replace(*change).replace("UNIT", "m"))
    with pytest.raises(BuildError, match=message):
        fmu_build.build_fmu("Lab.Plant", tmp_path / "lib", tmp_path / "out")
