"""twin.ssv and twin.ssp: SSP 1.0 parameter sets, system descriptions and packages.

Files are checked against the SSP 1.0 XML schemas that fmpy ships; foreign files (written by
hand here, as another tool would) are read with their units converted or refused by name.
"""
from __future__ import annotations

import os
import zipfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from twin.errors import ScenarioError, SSPError
from twin.ssp import read_ssp, write_ssp
from twin.ssv import ParameterSet, ParameterValue, read_ssv, resolve, write_ssv
from twin.units import parse_unit

pytestmark = pytest.mark.needs_gcc
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSM = "http://ssp-standard.org/SSP1/SystemStructureParameterMapping"


def _schema_errors(data: bytes, xsd: str) -> list[str]:
    import fmpy
    from lxml import etree

    schema = etree.XMLSchema(etree.parse(os.path.join(os.path.dirname(fmpy.__file__), "ssp", "schema", xsd)))
    ok = schema.validate(etree.fromstring(data))
    return [] if ok else [str(e) for e in schema.error_log]


def _ssv(params: str, units: str = "") -> bytes:
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<ssv:ParameterSet xmlns:ssv="{SSV}" xmlns:ssc="{SSC}" '
            f'version="1.0" name="foreign"><ssv:Parameters>{params}</ssv:Parameters>{units}</ssv:ParameterSet>').encode()


KN_M_PER_RAD = (f'<ssv:Units><ssc:Unit name="kN.m/rad"><ssc:BaseUnit kg="1" m="2" s="-2" rad="-1" factor="1000"/>'
                f'</ssc:Unit></ssv:Units>')


# ---- .ssv ----------------------------------------------------------------------------------------
def test_ssv_round_trip_of_every_type_validates_against_the_schema(tmp_path):
    values = {"k12": 55.5, "n_teeth": 19, "enabled": True, "label": "healthy <gear> & \"case\"", "tiny": 1e-300}
    path = write_ssv(values, tmp_path / "p.ssv", name="set", units={"k12": "N/m", "tiny": "kN.m/rad"})
    assert _schema_errors(path.read_bytes(), "SystemStructureParameterValues.xsd") == []
    pset = read_ssv(path)
    assert pset.as_dict() == values
    assert [(v.name, v.type, v.unit) for v in pset.values] == [
        ("k12", "Real", "N/m"), ("n_teeth", "Integer", ""), ("enabled", "Boolean", ""), ("label", "String", ""),
        ("tiny", "Real", "kN.m/rad")]
    assert (pset.units["kN.m/rad"].exponents, pset.units["kN.m/rad"].factor) == (parse_unit("N.m/rad").exponents, 1e3)


@pytest.mark.parametrize("value", [float("inf"), float("-inf"), float("nan")])
def test_non_finite_values_are_refused_and_nothing_is_written(tmp_path, value):
    target = tmp_path / "p.ssv"
    target.write_text("previous")
    with pytest.raises(SSPError, match=r"parameter 'k1': .* is not finite"):
        write_ssv({"m1": 1.0, "k1": value}, target)
    assert target.read_text() == "previous"


@pytest.mark.parametrize("text", ["INF", "-INF", "NaN"])
def test_non_finite_values_in_a_foreign_file_are_refused(text):
    with pytest.raises(SSPError, match=rf"parameter 'k1': value '{text}' is not finite"):
        read_ssv(_ssv(f'<ssv:Parameter name="k1"><ssv:Real value="{text}"/></ssv:Parameter>'), where="x.ssv")


def test_integer_and_boolean_entries_are_read_with_their_type():
    pset = read_ssv(_ssv('<ssv:Parameter name="n"><ssv:Integer value="-7"/></ssv:Parameter>'
                         '<ssv:Parameter name="b"><ssv:Boolean value="1"/></ssv:Parameter>'
                         '<ssv:Parameter name="e"><ssv:Enumeration value="fast"/></ssv:Parameter>'))
    assert [(v.name, v.type, v.value) for v in pset.values] == [("n", "Integer", -7), ("b", "Boolean", True),
                                                                ("e", "Enumeration", "fast")]
    with pytest.raises(SSPError, match=r"'n': '2147483648' is not a valid Integer"):
        read_ssv(_ssv('<ssv:Parameter name="n"><ssv:Integer value="2147483648"/></ssv:Parameter>'))
    with pytest.raises(SSPError, match="ssv:Binary values are not supported"):
        read_ssv(_ssv('<ssv:Parameter name="n"><ssv:Binary value="00ff"/></ssv:Parameter>'))


def _var(type_="Real", unit="", causality="parameter", variability="tunable"):
    return SimpleNamespace(type=type_, unit=unit, causality=causality, variability=variability)


def test_resolve_checks_types_and_settability():
    variables = {"k": _var(unit="N/m"), "n": _var("Integer", variability="fixed"), "flag": _var("Boolean"),
                 "z1": _var("Integer", causality="local", variability="constant"), "y": _var(causality="output")}
    pset = ParameterSet("s", (ParameterValue("k", "Integer", 3), ParameterValue("n", "Integer", 4),
                              ParameterValue("flag", "Boolean", False)))
    assert resolve(pset, variables) == {"k": 3.0, "n": 4, "flag": False}
    for entry, message in ((ParameterValue("n", "Real", 4.0), r"'n' is a Real but 'n' is an Integer"),
                           (ParameterValue("flag", "Integer", 1), r"'flag' is an Integer but 'flag' is a Boolean"),
                           (ParameterValue("z1", "Integer", 18), r"'z1' has causality 'local' and variability 'constant'"),
                           (ParameterValue("y", "Real", 1.0), r"'y' has causality 'output'")):
        with pytest.raises(SSPError, match=message):
            resolve(ParameterSet("s", (entry,)), variables)
    with pytest.raises(SSPError, match=r"2 parameter\(s\) match no variable of the FMU: 'kk', 'm'"):
        resolve(ParameterSet("s", (ParameterValue("kk", "Real", 1.0), ParameterValue("m", "Real", 1.0))), variables)


# ---- a foreign .ssv with units on the gearbox FMU --------------------------------------------------
def test_foreign_ssv_units_are_converted_by_their_definitions(gearbox_fmu, tmp_path):
    from twin.scenario import read_parameter_file

    path = tmp_path / "foreign.ssv"
    path.write_bytes(_ssv('<ssv:Parameter name="kt12"><ssv:Real value="1.875" unit="kN.m/rad"/></ssv:Parameter>'
                          '<ssv:Parameter name="I1"><ssv:Real value="43" unit="g.dm2"/></ssv:Parameter>'
                          '<ssv:Parameter name="c_mesh"><ssv:Real value="1100" unit="N.s/m"/></ssv:Parameter>',
                          '<ssv:Units><ssc:Unit name="kN.m/rad"><ssc:BaseUnit kg="1" m="2" s="-2" rad="-1" '
                          'factor="1000"/></ssc:Unit><ssc:Unit name="g.dm2"><ssc:BaseUnit kg="1" m="2" factor="1e-5"/>'
                          '</ssc:Unit></ssv:Units>'))
    values = read_parameter_file(path, fmu=gearbox_fmu)
    assert values["kt12"] == 1875.0                     # not 1.875 N.m/rad
    assert values["I1"] == pytest.approx(4.3e-4, rel=1e-15)
    assert values["c_mesh"] == 1100.0                  # the FMU's own unit: used as it is
    # without an FMU, a unit that needs converting is refused by name instead of being used as is
    with pytest.raises(ScenarioError, match=r"'kt12' is given in 'kN.m/rad', which needs the FMU"):
        read_parameter_file(path)


@pytest.mark.parametrize("entry, units, message", [
    ('<ssv:Real value="1.875" unit="kN.m/rad"/>', "",
     r"unit 'kN.m/rad' is not defined in the Units element of the file \(SSP 1.0\)"),
    ('<ssv:Real value="1.875" unit="kN"/>',
     '<ssv:Units><ssc:Unit name="kN"><ssc:BaseUnit kg="1" m="1" s="-2" factor="1000"/></ssc:Unit></ssv:Units>',
     r"cannot convert 'kN' \(kg\.m\.s-2\) to 'N.m/rad' \(kg\.m2\.s-2\.rad-1\): the dimensions differ"),
])
def test_foreign_ssv_units_that_cannot_be_converted_are_refused_by_name(gearbox_fmu, tmp_path, entry, units, message):
    from twin.scenario import read_parameter_file

    path = tmp_path / "foreign.ssv"
    path.write_bytes(_ssv(f'<ssv:Parameter name="kt12">{entry}</ssv:Parameter>', units))
    with pytest.raises(ScenarioError, match=message):
        read_parameter_file(path, fmu=gearbox_fmu)


def test_scenario_parameter_files_are_converted_with_the_scenarios_fmu(gearbox_fmu, tmp_path):
    from twin.scenario import load_scenario

    (tmp_path / "foreign.ssv").write_bytes(
        _ssv('<ssv:Parameter name="kt12"><ssv:Real value="1.875" unit="kN.m/rad"/></ssv:Parameter>', KN_M_PER_RAD))
    (tmp_path / "s.yaml").write_text(f"version: 1\nname: s\nfmu: {gearbox_fmu}\nstop_time: 0.01\n"
                                     "parameter_files: [foreign.ssv]\n")
    assert load_scenario(tmp_path / "s.yaml").parameters["kt12"] == 1875.0


# ---- .ssp packages ---------------------------------------------------------------------------------
def test_written_ssp_validates_and_reads_back(two_mass_fmu, tmp_path):
    out = write_ssp(two_mass_fmu, {"k12": 60.0, "m2": 0.4}, tmp_path / "tm.ssp", description="two masses")
    with zipfile.ZipFile(out) as zf:
        assert sorted(zf.namelist()) == ["SystemStructure.ssd", "resources/GearTwin.Examples.TwoMassOscillator.fmu",
                                         "resources/tm.ssv"]
        ssd, ssv = zf.read("SystemStructure.ssd"), zf.read("resources/tm.ssv")
        assert zf.read("resources/GearTwin.Examples.TwoMassOscillator.fmu") == Path(two_mass_fmu).read_bytes()
    assert _schema_errors(ssd, "SystemStructureDescription.xsd") == []
    assert _schema_errors(ssv, "SystemStructureParameterValues.xsd") == []
    text = ssd.decode()
    assert '<ssd:Connector name="force" kind="input"><ssc:Real unit="N"/></ssd:Connector>' in text
    assert '<ssd:Connector name="k12" kind="parameter"><ssc:Real unit="N/m"/></ssd:Connector>' in text
    assert '<ssc:Unit name="N/m">' in text and 'baseStepSize="0.001"' in text
    system = read_ssp(out)
    assert system.parameters == {"k12": 60.0, "m2": 0.4}
    assert system.component == "GearTwin_Examples_TwoMassOscillator"
    assert system.default_experiment == {"startTime": 0.0, "stopTime": 10.0}
    assert system.fmu.read_bytes() == Path(two_mass_fmu).read_bytes()


def test_write_ssp_refuses_bad_parameters_and_writes_nothing(two_mass_fmu, tmp_path):
    out = tmp_path / "tm.ssp"
    for params, message in (({"k12": float("nan")}, "not finite"), ({"nope": 1.0}, "match no variable"),
                            ({"f1": 2.0}, "causality 'calculatedParameter'")):
        with pytest.raises(SSPError, match=message):
            write_ssp(two_mass_fmu, params, out)
        assert not out.exists()
    with pytest.raises(SSPError, match="must end in .ssp"):
        write_ssp(two_mass_fmu, {}, tmp_path / "tm.zip")


def _package(tmp_path: Path, fmu: Path, ssd_body: str, files: dict[str, bytes] | None = None, *,
             units: str = "") -> Path:
    out = tmp_path / "foreign.ssp"
    ssd = (f'<?xml version="1.0"?>\n<ssd:SystemStructureDescription xmlns:ssd="{SSD}" xmlns:ssc="{SSC}" '
           f'xmlns:ssv="{SSV}" xmlns:ssm="{SSM}" version="1.0" name="foreign">{ssd_body}{units}'
           '</ssd:SystemStructureDescription>')
    with zipfile.ZipFile(out, "w") as zf:
        zf.writestr("SystemStructure.ssd", ssd)
        zf.write(fmu, "resources/plant.fmu")
        for name, data in (files or {}).items():
            zf.writestr(name, data)
    return out


def _component(bindings: str = "", name: str = "plant", extra: str = "") -> str:
    return (f'<ssd:Component name="{name}" source="resources/plant.fmu">'
            f'<ssd:ParameterBindings>{bindings}</ssd:ParameterBindings></ssd:Component>{extra}' if bindings else
            f'<ssd:Component name="{name}" source="resources/plant.fmu"/>{extra}')


def test_foreign_ssp_bindings_precedence_prefix_and_mapping(two_mass_fmu, tmp_path):
    inline = (f'<ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" name="inline">'
              '<ssv:Parameters><ssv:Parameter name="k12"><ssv:Real value="70"/></ssv:Parameter>'
              '<ssv:Parameter name="d1"><ssv:Real value="0.3"/></ssv:Parameter></ssv:Parameters>'
              '</ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding>')
    later = '<ssd:ParameterBinding source="params/second.ssv"/>'
    mapped = ('<ssd:ParameterBinding source="params/system.ssv" prefix="plant.">'
              '<ssd:ParameterMapping><ssm:ParameterMapping version="1.0">'
              '<ssm:MappingEntry source="plant.spring_g" target="plant.k1">'
              '<ssc:LinearTransformation factor="9.81"/></ssm:MappingEntry>'
              '</ssm:ParameterMapping></ssd:ParameterMapping></ssd:ParameterBinding>')
    body = (f'<ssd:System name="sys"><ssd:ParameterBindings>{mapped}</ssd:ParameterBindings>'
            f'<ssd:Elements>{_component(inline + later)}</ssd:Elements></ssd:System>')
    files = {"params/second.ssv": _ssv('<ssv:Parameter name="k12"><ssv:Real value="0.08" unit="kN/m"/></ssv:Parameter>',
                                       '<ssv:Units><ssc:Unit name="kN/m"><ssc:BaseUnit kg="1" s="-2" factor="1000"/>'
                                       '</ssc:Unit></ssv:Units>'),
             "params/system.ssv": _ssv('<ssv:Parameter name="spring_g"><ssv:Real value="10"/></ssv:Parameter>'
                                       '<ssv:Parameter name="d1"><ssv:Real value="0.5"/></ssv:Parameter>')}
    system = read_ssp(_package(tmp_path, two_mass_fmu, body, files))
    # second.ssv after the inline set (80 N/m wins over 70); the system binding over the component's
    assert system.parameters == {"k12": 80.0, "d1": 0.5, "k1": pytest.approx(98.1)}
    assert len(system.parameter_sets) == 3


@pytest.mark.parametrize("body, message", [
    ('<ssd:System name="sys"><ssd:Elements>' + _component(name="a") + _component(name="b") +
     "</ssd:Elements></ssd:System>", r"exactly one FMU component; 'sys' has 2: a \(.*\), b"),
    ('<ssd:System name="sys"><ssd:Elements><ssd:System name="inner"/></ssd:Elements></ssd:System>',
     r"nested systems \(inner\) are not supported"),
    ('<ssd:System name="sys"><ssd:Elements><ssd:Component name="a" source="resources/missing.fmu"/>'
     "</ssd:Elements></ssd:System>", r"FMU of component 'a' 'resources/missing.fmu' is not in the package"),
    ('<ssd:System name="sys"><ssd:Elements>' + _component('<ssd:ParameterBinding source="none.ssv"/>') +
     "</ssd:Elements></ssd:System>", r"parameter set 'none.ssv' is not in the package"),
    ('<ssd:System name="sys"><ssd:ParameterBindings><ssd:ParameterBinding source="p.ssv"/>'
     '</ssd:ParameterBindings><ssd:Elements>' + _component() + "</ssd:Elements></ssd:System>",
     r"system-level parameter\(s\) 'k12' do not name the component \(plant.<variable>\)"),
])
def test_foreign_ssp_problems_are_named(two_mass_fmu, tmp_path, body, message):
    files = {"p.ssv": _ssv('<ssv:Parameter name="k12"><ssv:Real value="1"/></ssv:Parameter>')}
    with pytest.raises(SSPError, match=message):
        read_ssp(_package(tmp_path, two_mass_fmu, body, files))


def test_not_an_ssp_is_refused(tmp_path):
    bad = tmp_path / "x.ssp"
    bad.write_text("hello")
    with pytest.raises(SSPError, match="not an SSP package"):
        read_ssp(bad)
    with pytest.raises(SSPError, match="does not exist"):
        read_ssp(tmp_path / "missing.ssp")


def test_scenario_may_name_an_ssp_as_its_fmu(two_mass_fmu, tmp_path):
    from twin.orchestrator import run_scenario
    from twin.scenario import load_scenario

    write_ssp(two_mass_fmu, {"k12": 60.0, "m2": 0.4}, tmp_path / "tm.ssp")
    (tmp_path / "s.yaml").write_text("version: 1\nname: s\nfmu: tm.ssp\nstop_time: 0.5\ncommunication_step: 0.01\n"
                                     "output: {sample_rate: 100}\nparameters: {m2: 0.45}\n")
    scenario = load_scenario(tmp_path / "s.yaml")
    assert scenario.parameters == {"k12": 60.0, "m2": 0.45}      # the scenario's own values win
    rec = run_scenario(scenario, progress=False)
    assert rec.result.parameters["k12"] == 60.0 and rec.result.parameters["m2"] == 0.45
    (tmp_path / "bad.yaml").write_text("version: 1\nname: s\nfmu: none.ssp\nstop_time: 0.5\n")
    with pytest.raises(ScenarioError, match="SSP file .*none.ssp does not exist"):
        load_scenario(tmp_path / "bad.yaml")
    assert np.isfinite(rec.result.time).all()
