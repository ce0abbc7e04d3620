"""fmu_build build options: structural parameters resize the model, values become defaults,
the cache key covers them, and a bad option is named before anything is compiled."""
from __future__ import annotations

import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

import fmu_build
import fmu_build.build
from twin.errors import BuildError

REPO = Path(__file__).resolve().parents[2]
MODELICA = REPO / "modelica"


def _variables(fmu: Path) -> dict[str, ET.Element]:
    with zipfile.ZipFile(fmu) as zf:
        root = ET.fromstring(zf.read("modelDescription.xml"))
    return {sv.get("name"): sv for sv in root.iter("ScalarVariable")}, root


@pytest.fixture(scope="session")
def variant_18_35(fmu_dir) -> Path:
    # a directory of its own: tests/twin/test_variants.py builds an FMU of the same name (with the
    # computed k_pair too) into fmu_dir, and the two files may run at the same time in two workers
    return fmu_build.build_fmu("GearTwin.Gearbox21", MODELICA, fmu_dir / "options", modifiers={"z1": 18, "z2": 35})


@pytest.mark.needs_gcc
def test_structural_options_size_the_per_tooth_arrays(variant_18_35):
    variables, root = _variables(variant_18_35)
    assert variant_18_35.name == "GearTwin.Gearbox21-z1_18-z2_35.fmu"
    assert int(variables["z1"].find("Integer").get("start")) == 18
    assert int(variables["z2"].find("Integer").get("start")) == 35
    for array in ("tooth_stiffness_factor", "tooth_deviation_offset", "effect_tooth_stiffness_factor",
                  "effect_tooth_offset"):
        assert f"{array}[18]" in variables and f"{array}[19]" not in variables, array
    assert "tooth_pit_field[198]" in variables and "tooth_pit_field[199]" not in variables  # 18 x 11
    assert "z1 = 18, z2 = 35" in root.get("description")
    assert root.find("CoSimulation").get("modelIdentifier") == "GearTwin_Gearbox21_z1_18_z2_35"
    # the kinematics follow: the base radius of an 18-tooth pinion
    from fmpy import simulate_fmu
    res = simulate_fmu(str(variant_18_35), stop_time=1e-3, output=["mesh_stiffness"], step_size=1e-4)
    assert res["mesh_stiffness"].max() > 0


@pytest.mark.needs_gcc
def test_real_options_become_defaults_and_stay_tunable(tmp_path):
    k = [2.0e8 + 1e6 * i for i in range(21)]
    fmu = fmu_build.build_fmu("GearTwin.Gearbox21", MODELICA, tmp_path,
                              modifiers={"n_profile": 21, "k_pair": k, "c_mesh": 1500.0})
    variables, _ = _variables(fmu)
    assert "k_pair[21]" in variables and "profile_deviation[21]" in variables and "k_pair[22]" not in variables
    assert float(variables["k_pair[21]"].find("Real").get("start")) == k[-1]
    assert variables["c_mesh"].get("variability") == "tunable"
    assert float(variables["c_mesh"].find("Real").get("start")) == 1500.0
    # arrays get a hash in the name, scalars are spelled out
    assert fmu.name.startswith("GearTwin.Gearbox21-c_mesh_1500.0-n_profile_21-") and fmu.suffix == ".fmu"


@pytest.mark.needs_gcc
def test_options_are_part_of_the_cache_key(tmp_path, monkeypatch):
    a = fmu_build.build_fmu("GearTwin.Examples.TwoMassOscillator", MODELICA, tmp_path, modifiers={"m1": 2.0})
    mtime = a.stat().st_mtime_ns

    def forbidden(*args, **kwargs):
        raise AssertionError("cached build recompiled")
    with monkeypatch.context() as m:
        m.setattr(fmu_build.build, "flatten", forbidden)
        assert fmu_build.build_fmu("GearTwin.Examples.TwoMassOscillator", MODELICA, tmp_path,
                                   modifiers={"m1": 2.0}) == a
    b = fmu_build.build_fmu("GearTwin.Examples.TwoMassOscillator", MODELICA, tmp_path, modifiers={"m1": 3.0})
    assert b != a and a.stat().st_mtime_ns == mtime
    base = fmu_build.build_fmu("GearTwin.Examples.TwoMassOscillator", MODELICA, tmp_path)
    assert base.name == "GearTwin.Examples.TwoMassOscillator.fmu"
    assert float(_variables(b)[0]["m1"].find("Real").get("start")) == 3.0


@pytest.mark.parametrize("mods, message", [
    ({"zz": 3}, "'zz' is not declared in GearTwin.Gearbox21"),
    ({"z1": 18.5}, "'z1' is a structural Integer of GearTwin.Gearbox21, got 18.5"),
    ({"theta1": 1.0}, "'theta1' is not a parameter of GearTwin.Gearbox21"),
    ({"k_pair": [1.0, 2.0]}, "'k_pair' has 11 elements in this build, got 2"),
    ({"z1": 18, "tooth_stiffness_factor": [1.0] * 19}, "'tooth_stiffness_factor' has 18 elements in this build, got 19"),
    ({"c_mesh": "x"}, "'c_mesh': needs a number"),
    ({"c_mesh": float("inf")}, "'c_mesh' needs a finite number"),
])
def test_bad_options_are_named_and_nothing_is_written(tmp_path, monkeypatch, mods, message):
    def forbidden(*args, **kwargs):
        raise AssertionError("gcc must not run")
    monkeypatch.setattr(fmu_build.build.subprocess, "run", forbidden)
    with pytest.raises(BuildError, match=message.replace("[", r"\[").replace("(", r"\(")):
        fmu_build.build_fmu("GearTwin.Gearbox21", MODELICA, tmp_path, modifiers=mods)
    assert not list(tmp_path.glob("*.fmu"))
