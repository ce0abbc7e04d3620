"""twin.variants: structural build options from the CLI and from scenarios, the computed mesh
stiffness as the variant's default, the refusal of a structural parameter given at run time,
and the geometry that twin info shows."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from twin.cli import main
from twin.degradation.geometry import GearPair
from twin.degradation.stiffness import k_pair_nodes
from twin.errors import FMUCompatibilityError, ParameterError
from twin.fmu import FMU, describe
from twin.orchestrator import check_compatibility
from twin.scenario import scenario_from_dict
from twin.variants import build_options, build_variant

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def pair_18_35(fmu_dir) -> Path:
    return build_variant("GearTwin.Gearbox21", {"z1": 18, "z2": 35}, out_dir=fmu_dir)


def _scenario(**extra):
    return scenario_from_dict({"version": 1, "name": "s", "fmu": "GearTwin.Gearbox21", "stop_time": 0.01,
                               "output": {"sample_rate": 1e5}, **extra})


def test_a_changed_geometry_gets_the_computed_mesh_stiffness():
    mods = build_options({"z1": 18.0, "z2": 35.0})
    assert mods["z1"] == 18 and isinstance(mods["z1"], int)
    assert mods["k_pair"] == k_pair_nodes(GearPair(z1=18, z2=35), 11)
    finer = build_options({"z1": 18, "n_profile": 21})
    assert len(finer["k_pair"]) == 21
    # the material feeds the stiffness and, as the model's own parameters, its Hertzian contact
    soft = build_options({"z2": 35, "youngs_modulus": 103e9})
    assert "youngs_modulus" not in soft and soft["gear_youngs_modulus"] == 103e9
    assert build_options({"poisson_ratio": 0.28})["gear_poisson_ratio"] == 0.28
    assert soft["k_pair"][5] == pytest.approx(0.5 * build_options({"z2": 35})["k_pair"][5], rel=1e-9)
    # an explicit k_pair wins; options that are not geometry leave k_pair alone
    assert build_options({"z1": 18, "k_pair": [1.0] * 11})["k_pair"] == [1.0] * 11
    assert "k_pair" not in build_options({"c_mesh": 1200.0})


@pytest.mark.needs_gcc
def test_variant_builds_with_its_own_stiffness_and_geometry(pair_18_35):
    with FMU(pair_18_35) as fmu:
        assert fmu.structural_values()["z1"] == 18 and fmu.structural_values()["z2"] == 35
        k = [fmu.variable(f"k_pair[{i}]").start for i in range(1, 12)]
        assert k == pytest.approx(k_pair_nodes(GearPair(z1=18, z2=35), 11), rel=1e-12)
        assert len([v for v in fmu.parameters if v.name.startswith("tooth_stiffness_factor[")]) == 18
        # the per-tooth pit field is sized z1 x n_profile
        assert len([v for v in fmu.parameters if v.name.startswith("tooth_pit_field[")]) == 18 * 11
    text = describe(pair_18_35)
    assert "Structural (3" in text and "z1 = 18, z2 = 35" in text
    assert "Contact ratio 1.6082" in text and "ISO 6336-1" in text and "potential energy" in text
    # the Hertzian width as the model computes it (hertz_half_width at the 20 N.m start load)
    a = np.radians(20)
    rho1, rho2 = 0.5 * 3e-3 * 18 * np.sin(a), 0.5 * 3e-3 * 35 * np.sin(a)
    line_load = 20.0 / (0.5 * 3e-3 * 35 * np.cos(a)) / 0.020           # N/m: the output torque on one pair
    b = np.sqrt(4 * line_load * rho1 * rho2 / (rho1 + rho2) / (np.pi * 2.06e11 / (2 * (1 - 0.3 ** 2))))
    assert f"Hertz half-width {b * 1e6:.1f} um at load_start 20 N.m" in text


@pytest.mark.needs_gcc
def test_structural_value_given_as_a_parameter_is_refused_with_the_rebuild_command(gearbox_fmu):
    sc = _scenario(parameters={"z1": 18, "z2": 35})
    with FMU(gearbox_fmu) as fmu:
        with pytest.raises(FMUCompatibilityError) as info:
            check_compatibility(fmu, sc)
        with pytest.raises(ParameterError, match=r"rebuild with `twin build GearTwin.Gearbox21 --set z2=35`"):
            fmu.set({"z2": 35})
    msg = str(info.value)
    assert "`twin build GearTwin.Gearbox21 --set z1=18`" in msg and "`structural: {z1: 18}`" in msg
    assert "--set z2=35" in msg
    # a built FMU that does not match the scenario's structural block is refused too
    with FMU(gearbox_fmu) as fmu, pytest.raises(FMUCompatibilityError, match="built with z1 = 19"):
        check_compatibility(fmu, _scenario(structural={"z1": 18}))


def test_scenario_structural_block_builds_the_variant(monkeypatch, tmp_path):
    import twin.variants
    calls = []
    monkeypatch.setattr(twin.variants, "build_variant",
                        lambda model, sets, **kw: calls.append((model, sets)) or tmp_path / "v.fmu")
    sc = _scenario(structural={"z1": 18, "z2": 35})
    assert sc.structural == {"z1": 18, "z2": 35}
    assert sc.fmu_path() == tmp_path / "v.fmu"
    assert calls == [("GearTwin.Gearbox21", {"z1": 18, "z2": 35})]
    from twin.errors import ScenarioError
    with pytest.raises(ScenarioError, match="also in 'structural'"):
        _scenario(structural={"z1": 18}, parameters={"z1": 18})


def test_cli_build_set(monkeypatch, capsys, tmp_path):
    import twin.variants
    calls = []

    def fake(model, sets, **kw):
        calls.append((model, sets, kw["out_dir"]))
        return tmp_path / "x.fmu"
    monkeypatch.setattr(twin.variants, "build_variant", fake)
    assert main(["build", "GearTwin.Gearbox21", "--set", "z1=18", "--set", "z2=35", "--out", str(tmp_path)]) == 0
    assert calls == [("GearTwin.Gearbox21", {"z1": 18.0, "z2": 35.0}, tmp_path)]
    assert capsys.readouterr().out.strip() == str(tmp_path / "x.fmu")
    assert main(["build", "--set", "z1"]) == 2
    assert "bad --set 'z1'" in capsys.readouterr().err


def test_a_bad_geometry_option_is_named_before_building(tmp_path):
    with pytest.raises(ParameterError, match="z1 must be an integer >= 5, got 18.5"):
        build_variant("GearTwin.Gearbox21", {"z1": 18.5}, out_dir=tmp_path)
    with pytest.raises(ParameterError, match="must be a finite number"):
        build_variant("GearTwin.Gearbox21", {"z1": float("nan")}, out_dir=tmp_path)
    assert not list(tmp_path.iterdir())


def test_computed_stiffness_is_smooth_and_positive():
    k = np.array(k_pair_nodes(GearPair(z1=18, z2=35), 41))
    assert np.all(k > 1e8) and np.all(k < 5e8)
    assert np.max(np.abs(np.diff(k, 2))) < 0.02 * k.max()
