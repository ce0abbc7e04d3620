"""The FMI/SSP side of the CLI, on real FMUs: twin export-ssp, twin simulate on an .ssp."""
from __future__ import annotations

import json
from pathlib import Path
import zipfile

import pytest

from twin.cli import main
from twin.results import read_csv
from twin.ssp import read_ssp

pytestmark = pytest.mark.needs_gcc
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"


def test_export_ssp_from_json_and_foreign_ssv(two_mass_fmu, tmp_path, capsys):
    (tmp_path / "p.json").write_text(json.dumps({"parameters": {"k12": 60.0, "m2": 0.4}}))
    (tmp_path / "q.ssv").write_text(
        f'<ssv:ParameterSet xmlns:ssv="{SSV}" xmlns:ssc="{SSC}" version="1.0" name="q"><ssv:Parameters>'
        '<ssv:Parameter name="k1"><ssv:Real value="0.12" unit="kN/m"/></ssv:Parameter></ssv:Parameters>'
        '<ssv:Units><ssc:Unit name="kN/m"><ssc:BaseUnit kg="1" s="-2" factor="1000"/></ssc:Unit></ssv:Units>'
        "</ssv:ParameterSet>")
    out = tmp_path / "tm.ssp"
    assert main(["export-ssp", str(two_mass_fmu), "--parameters", str(tmp_path / "p.json"),
                 "--parameters", str(tmp_path / "q.ssv"), "--param", "m2=0.45", "--out", str(out)]) == 0
    assert "bound to 3 parameter value(s)" in capsys.readouterr().out
    assert read_ssp(out).parameters == {"k12": 60.0, "m2": 0.45, "k1": 120.0}


@pytest.mark.parametrize("args, message", [
    (["--param", "m2=-1"], "parameter 'm2' = -1.0 is outside its range"),
    (["--param", "nope=1"], "match no variable of the FMU: 'nope'"),
    (["--param", "k12=inf"], "must be finite"),
])
def test_export_ssp_refuses_bad_values_and_writes_nothing(two_mass_fmu, tmp_path, capsys, args, message):
    out = tmp_path / "tm.ssp"
    assert main(["export-ssp", str(two_mass_fmu), *args, "--out", str(out)]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_simulate_an_ssp_applies_its_bindings(two_mass_fmu, tmp_path, capsys):
    ssp = tmp_path / "tm.ssp"
    assert main(["export-ssp", str(two_mass_fmu), "--param", "k12=60", "--param", "m2=0.4", "--out", str(ssp)]) == 0
    assert main(["simulate", str(ssp), "--stop-time", "0.1", "--output-interval", "0.01", "--param", "m2=0.42",
                 "--output", str(tmp_path / "r.csv"), "--no-progress"]) == 0
    result = read_csv(tmp_path / "r.csv")
    assert result.parameters["k12"] == 60.0 and result.parameters["m2"] == 0.42
    with zipfile.ZipFile(ssp) as zf:
        zf.testzip()
    (tmp_path / "bad.ssp").write_text("not a zip")
    assert main(["simulate", str(tmp_path / "bad.ssp"), "--stop-time", "0.1", "--output",
                 str(tmp_path / "r2.csv")]) == 2
    assert "not an SSP package" in capsys.readouterr().err


def test_build_fmi3(tmp_path, capsys, monkeypatch):
    from fmpy import read_model_description

    out = tmp_path / "fmus"
    out.mkdir()
    assert main(["build", "GearTwin.Examples.TwoMassOscillator", "--fmi", "3", "--out", str(out)]) == 0
    path = capsys.readouterr().out.strip()
    assert path == str(out / "GearTwin.Examples.TwoMassOscillator.fmu")
    assert read_model_description(path).fmiVersion == "3.0"
    # without --out, FMI 3.0 builds go to build/fmi3 and never replace the FMI 2.0 ones in build/
    calls = []
    import fmu_build

    monkeypatch.setattr(fmu_build, "build_fmu", lambda model, mdir, out_dir, **kw: calls.append((out_dir, kw))
                        or out_dir / f"{model}.fmu")
    monkeypatch.chdir(tmp_path)
    assert main(["build", "--fmi", "3"]) == 0
    assert calls == [(Path("build") / "fmi3", {"step_size": 5e-6, "force": False, "fmi_version": 3})]


def test_validate_fmu_and_ssp(two_mass_fmu, two_mass_fmu3, tmp_path, capsys):
    for fmu in (two_mass_fmu, two_mass_fmu3):
        assert main(["validate", str(fmu)]) == 0
        assert capsys.readouterr().out.strip() == "No problems found."
    # an FMU whose model description uses a unit it does not define
    broken = tmp_path / "broken.fmu"
    with zipfile.ZipFile(two_mass_fmu) as src, zipfile.ZipFile(broken, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(b'<Real unit="N/m"', b'<Real unit="N/mm"', 1)
            dst.writestr(item, data)
    assert main(["validate", str(broken)]) == 1
    out = capsys.readouterr().out
    assert out.startswith("1 problem was found:") and 'The unit "N/mm" of variable "k1"' in out
    # an .ssp: schema problems of its files, then what reading it finds
    ssp = tmp_path / "tm.ssp"
    assert main(["export-ssp", str(two_mass_fmu), "--param", "k12=60", "--out", str(ssp)]) == 0
    capsys.readouterr()
    assert main(["validate", str(ssp)]) == 0
    bad = tmp_path / "bad.ssp"
    with zipfile.ZipFile(ssp) as src, zipfile.ZipFile(bad, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename.endswith(".ssv"):
                data = data.replace(b'<ssv:Real value="60.0"', b'<ssv:Real value="sixty"')
            dst.writestr(item, data)
    assert main(["validate", str(bad)]) == 1
    out = capsys.readouterr().out
    assert "resources/tm.ssv:" in out and "'sixty' is not a valid value of the atomic type 'xs:double'" in out
    assert "parameter 'k12': 'sixty' is not a valid Real" in out


def test_run_an_ssp_as_it_is(two_mass_fmu, tmp_path, capsys):
    from twin.results import read_hdf5

    ssp = tmp_path / "tm.ssp"
    assert main(["export-ssp", str(two_mass_fmu), "--param", "k12=60", "--out", str(ssp)]) == 0
    assert main(["run", str(ssp), "--stop-time", "0.05", "--output", str(tmp_path / "r.h5"), "--no-progress"]) == 0
    result = read_hdf5(tmp_path / "r.h5")
    assert result.parameters["k12"] == 60.0 and result.time[-1] == pytest.approx(0.05)
    assert "tm: 51 samples" in capsys.readouterr().out      # at the model's default step, 1 ms


# ---- FMI 3.0 builds through twin -----------------------------------------------------------------
def _same_results(a: Path, b: Path) -> None:
    """Two result files hold the same channels, units, parameters and samples (to 1e-12)."""
    import numpy as np

    from twin.results import read_result

    ra, rb = read_result(a), read_result(b)
    assert ra.channels == rb.channels and ra.units == rb.units and ra.parameters == rb.parameters
    np.testing.assert_array_equal(ra.time, rb.time)
    for name in ra.channels:
        scale = max(float(np.max(np.abs(ra[name]))), 1e-300)
        np.testing.assert_allclose(rb[name], ra[name], rtol=0, atol=1e-12 * scale, err_msg=name)


def test_fmi3_build_simulates_and_runs_scenarios_like_the_fmi2_build(two_mass_fmu, tmp_path, capsys):
    """`twin build --fmi 3` gives an FMU that `twin simulate` (with and without the model's default
    experiment: 1 ms over 10 s, sampled as fmpy does at 16 ms) and `twin run` run to the FMI 2.0
    build's results."""
    assert main(["build", "GearTwin.Examples.TwoMassOscillator", "--fmi", "3", "--out", str(tmp_path)]) == 0
    fmu3 = Path(capsys.readouterr().out.strip())
    for version, fmu in ((2, two_mass_fmu), (3, fmu3)):
        assert main(["simulate", str(fmu), "--output", str(tmp_path / f"default{version}.h5"), "--no-progress"]) == 0
        assert main(["simulate", str(fmu), "--stop-time", "2", "--output-interval", "1e-4", "--param", "k1=150",
                     "--input", "force=0.5", "--output", str(tmp_path / f"sim{version}.csv"), "--no-progress"]) == 0
        (tmp_path / f"s{version}.yaml").write_text(
            f"version: 1\nname: s{version}\nfmu: {fmu}\nstop_time: 1.0\ncommunication_step: 0.01\n"
            "output: {sample_rate: 2000}\nparameters: {k12: 60.0}\n"
            "operating:\n  inputs:\n    force: {ramp: {from: 0, to: 2, duration: 0.5}}\n"
            "events:\n  - {time: 0.4, override: {k1: 120.0}}\n  - {time: 0.7, reset: [k1]}\n")
        assert main(["run", str(tmp_path / f"s{version}.yaml"), "--output", str(tmp_path / f"run{version}.h5"),
                     "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "626 samples x 2 channels, t=[0, 10] s" in out and out.count("2001 samples of 2 channels (complete)") == 2
    for stem in ("default", "run"):
        _same_results(tmp_path / f"{stem}2.h5", tmp_path / f"{stem}3.h5")
    _same_results(tmp_path / "sim2.csv", tmp_path / "sim3.csv")


def test_fmi3_gearbox_runs_a_scenario_and_a_degradation_run_like_fmi2(gearbox_fmu, gearbox_fmu3, tmp_path):
    """The gearbox built for FMI 3.0 through the orchestrator (events, operating profile) and the
    degradation loop (wear re-written into the FMU between records): the FMI 2.0 build's numbers."""
    import h5py
    import numpy as np

    for version, fmu in ((2, gearbox_fmu), (3, gearbox_fmu3)):
        common = (f"fmu: {fmu}\nstop_time: 0.05\ncommunication_step: 0.01\n"
                  "output: {sample_rate: 20000, variables: [accel_pinion_casing, mesh_force, transmission_error]}\n")
        (tmp_path / f"e{version}.yaml").write_text(
            f"version: 1\nname: e{version}\n{common}operating:\n  speed: {{ramp: {{from: 5, to: 10, duration: 0.05}}}}\n"
            "  load: {constant: 5}\nevents:\n  - {time: 0.02, override: {mesh_stiffness_scale: 0.8}}\n")
        (tmp_path / f"d{version}.yaml").write_text(
            f"version: 1\nname: d{version}\n{common}operating:\n  speed: {{constant: 10}}\n  load: {{constant: 5}}\n"
            "degradation: {model: wear, max_increment: 1.5e-5, stop: {wear_depth: 5.0e-6}, max_updates: 4,\n"
            "              load_window: 0.1, record_duration: 0.01}\nseed: 0\n")
        for stem in ("e", "d"):
            assert main(["run", str(tmp_path / f"{stem}{version}.yaml"), "--output",
                         str(tmp_path / f"{stem}{version}.h5"), "--no-progress"]) == 0
    _same_results(tmp_path / "e2.h5", tmp_path / "e3.h5")
    with h5py.File(tmp_path / "d2.h5") as a, h5py.File(tmp_path / "d3.h5") as b:
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert "stages/00001/vibration/mesh_force" in names
        for name in names:
            x, y = a[name][()], b[name][()]
            scale = max(float(np.max(np.abs(x))), 1e-300)
            np.testing.assert_allclose(y, x, rtol=0, atol=1e-12 * scale, err_msg=name)


# ---- parameters of every type in SSP -------------------------------------------------------------
@pytest.mark.parametrize("version", [2, 3])
def test_export_ssp_writes_every_type_and_runs_it(typecov_fmus, tmp_path, capsys, version):
    """Integer, Boolean, String and Enumeration parameters go into the .ssv as ssv:Integer,
    ssv:Boolean, ssv:String and ssv:Enumeration (the item's name), and the package runs with them."""
    from twin.results import read_result

    fmu = typecov_fmus[("AllTypes", version)]
    out = tmp_path / "a.ssp"
    assert main(["export-ssp", str(fmu), "--param", "step=2", "--param", "invert=true", "--param", "label=wheel",
                 "--param", "mode=fast", "--param", "gain=3", "--out", str(out)]) == 0
    with zipfile.ZipFile(out) as zf:
        ssv = zf.read("resources/a.ssv").decode()
    for element in ('<ssv:Integer value="2"/>', '<ssv:Boolean value="true"/>', '<ssv:String value="wheel"/>',
                    '<ssv:Enumeration value="fast"/>', '<ssv:Real value="3.0"'):
        assert element in ssv
    assert read_ssp(out).parameters == {"step": 2, "invert": True, "label": "wheel", "mode": 3, "gain": 3.0}
    assert main(["validate", str(out)]) == 0
    assert main(["simulate", str(out), "--output", str(tmp_path / "r.h5"), "--no-progress"]) == 0
    got = read_result(tmp_path / "r.h5").parameters
    assert {k: got[k] for k in ("step", "invert", "label", "mode", "gain")} == \
        {"step": 2, "invert": True, "label": "wheel", "mode": 3, "gain": 3.0}
    capsys.readouterr()
    # an item the enumeration does not have, and an integer outside an FMI 3.0 Int8, by name
    assert main(["export-ssp", str(fmu), "--param", "mode=medium", "--out", str(tmp_path / "b.ssp")]) == 2
    assert "parameter 'mode'" in capsys.readouterr().err and not (tmp_path / "b.ssp").exists()


def test_foreign_ssv_enumeration_by_value_and_integer_ranges(typecov_fmus, tmp_path):
    from twin.errors import SSPError
    from twin.fmu import FMU
    from twin.ssv import read_ssv, resolve

    def ssv(body: str) -> Path:
        path = tmp_path / "p.ssv"
        path.write_text(f'<ssv:ParameterSet xmlns:ssv="{SSV}" version="1.0" name="p"><ssv:Parameters>{body}'
                        "</ssv:Parameters></ssv:ParameterSet>")
        return path

    with FMU(typecov_fmus[("AllTypes", 3)]) as f:
        variables = dict(f.variables)
    good = ssv('<ssv:Parameter name="mode"><ssv:Integer value="1"/></ssv:Parameter>'
               '<ssv:Parameter name="Int8_parameter"><ssv:Integer value="-7"/></ssv:Parameter>')
    assert resolve(read_ssv(good), variables) == {"mode": 1, "Int8_parameter": -7}
    for body, message in [('<ssv:Parameter name="mode"><ssv:Integer value="9"/></ssv:Parameter>', "must be an item"),
                          ('<ssv:Parameter name="mode"><ssv:Enumeration value="medium"/></ssv:Parameter>',
                           "must be an item"),
                          ('<ssv:Parameter name="Int8_parameter"><ssv:Integer value="300"/></ssv:Parameter>',
                           "within [-128, 127]"),
                          ('<ssv:Parameter name="mode"><ssv:Boolean value="true"/></ssv:Parameter>',
                           "is a Boolean but 'mode' is an Enumeration")]:
        with pytest.raises(SSPError, match=message.replace("[", r"\[").replace("]", r"\]")):
            resolve(read_ssv(ssv(body)), variables)
