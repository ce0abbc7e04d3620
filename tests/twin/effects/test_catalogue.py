from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from twin.effects import BASE_MODELS, CATALOGUE, candidates_source, effect, variant_source, write_variant
from twin.errors import OutputPathError, ParameterError

REPO = Path(__file__).resolve().parents[3]
EFFECTS_DIR = REPO / "modelica" / "GearTwin" / "Effects"
ISSUE_IDS = {"pinion_eccentricity", "gear_eccentricity", "motor_torque_ripple", "load_torque_fluctuation",
             "housing_mode", "local_tooth_damage", "backlash", "tooth_friction", "distributed_wear"}


def test_catalogue_has_the_documented_ids():
    assert set(CATALOGUE) == ISSUE_IDS


@pytest.mark.parametrize("effect_id", sorted(ISSUE_IDS))
def test_each_effect_is_a_bounded_modelica_component_with_a_readme(effect_id):
    e = CATALOGUE[effect_id]
    short = e.component.rsplit(".", 1)[1]
    src = (EFFECTS_DIR / f"{short}.mo").read_text()
    for p in e.fit:
        decl = re.search(rf"parameter Real {p.name}\((.*?)\)\s*=", src)
        assert decl, p.name
        assert "min =" in decl.group(1) and "max =" in decl.group(1), f"{p.name} needs Modelica bounds"
    readme = (EFFECTS_DIR / "README.md").read_text()
    assert f"`{effect_id}`" in readme and short in readme


@pytest.mark.parametrize("base", BASE_MODELS)
def test_committed_candidate_models_are_the_generated_ones(base):
    from twin.effects import candidates_model
    short = candidates_model(base).rsplit(".", 1)[1]
    committed = (REPO / "modelica" / "GearTwin" / "Variants" / f"{short}.mo").read_text()
    assert committed == candidates_source(base), "regenerate with `twin effects --write-candidates`"
    assert f"extends {base}(" in committed


def test_variants_extend_the_base_model_they_are_built_on():
    from twin.effects import base_of
    from twin.errors import ParameterError
    src = variant_source(["housing_mode"], {"housing_mode.frequency": 3000.0}, base="GearTwin.Gearbox21Measured")
    assert "extends GearTwin.Gearbox21Measured(" in src and "model Gearbox21Measured_housing_mode_" in src
    assert base_of(["sensor_pinion.gain", "kt35"]) == "GearTwin.Gearbox21Measured"
    assert base_of(["kt35"]) == "GearTwin.Gearbox21"
    # the casing family by the parameter each model adds, the most derived first
    assert base_of(["sensor_pinion.gain", "m_casing"]) == "GearTwin.Gearbox21Casing"
    assert base_of(["m_casing", "d_shaft_input"]) == "GearTwin.Gearbox21Shafts"
    assert base_of(["m_casing", "d_shaft_input", "wall_thickness"]) == "GearTwin.Gearbox21Walls"
    assert base_of(["d_shaft_input", "wall_thickness", "housing_height"]) == "GearTwin.Gearbox21TiltingWalls"
    assert base_of(["m_casing", "d_shaft_input", "end_mass4"]) == "GearTwin.Gearbox21Overhangs"
    with pytest.raises(ParameterError, match="GearTwin.Gearbox21Other"):
        variant_source(["housing_mode"], base="GearTwin.Gearbox21Other")


def test_variant_sums_hooks_shared_by_two_effects():
    src = variant_source(["gear_eccentricity", "pinion_eccentricity"], {"pinion_eccentricity.eccentricity": 2e-5})
    assert "model Gearbox21_pinion_eccentricity_gear_eccentricity" in src
    assert ("effect_mesh_displacement = pinion_eccentricity.mesh_displacement + "
            "gear_eccentricity.mesh_displacement") in src
    assert "eccentricity = 2e-05" in src
    assert src.count("extends GearTwin.Gearbox21(") == 1


def test_unknown_effect_names_the_catalogue():
    with pytest.raises(ParameterError, match="unknown effect 'rust'.*housing_mode"):
        effect("rust")
    with pytest.raises(ParameterError, match="rust"):
        variant_source(["housing_mode", "rust"])


def test_write_variant_updates_the_package_and_refuses_a_foreign_directory(tmp_path):
    import shutil
    root = tmp_path / "modelica"
    shutil.copytree(REPO / "modelica", root, ignore=shutil.ignore_patterns("Variants"))
    model, path = write_variant(variant_source(["housing_mode"]), root)
    assert model == "GearTwin.Variants.Gearbox21_housing_mode" and path.exists()
    assert "Gearbox21_housing_mode" in (root / "GearTwin" / "Variants" / "package.order").read_text().split()
    assert "Variants" in (root / "GearTwin" / "package.order").read_text().split()
    with pytest.raises(OutputPathError, match="GearTwin"):
        write_variant(variant_source(["housing_mode"]), tmp_path / "elsewhere")
    # fitted values name the variant: another gearbox's values give another model, not an overwrite
    a, pa = write_variant(variant_source(["housing_mode"], {"housing_mode.frequency": 2500.0}), root)
    b, pb = write_variant(variant_source(["housing_mode"], {"housing_mode.frequency": 2600.0}), root)
    assert a != b and pa != pb and "frequency = 2500.0" in pa.read_text() and "frequency = 2600.0" in pb.read_text()
    assert a.startswith("GearTwin.Variants.Gearbox21_housing_mode_")


def test_neutral_candidate_model_reproduces_the_base_model(gearbox_fmu, candidates_fmu):
    """All effects off: the candidate FMU gives the base model's response to round-off."""
    import numpy as np

    from twin.operating import simulate_operating_point
    kw = dict(settle=0.02, duration=0.05, channels=["accel_pinion_casing", "mesh_force"], output_interval=1e-5)
    a = simulate_operating_point(gearbox_fmu, 20, 20, **kw)
    b = simulate_operating_point(candidates_fmu, 20, 20, **kw)
    np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-9 * np.abs(a).max())


def test_switching_an_effect_on_changes_the_response(candidates_fmu):
    import numpy as np

    from twin.operating import simulate_operating_point
    kw = dict(settle=0.02, duration=0.05, channels=["accel_pinion_casing"], output_interval=1e-5)
    off = simulate_operating_point(candidates_fmu, 20, 20, **kw)
    on = simulate_operating_point(candidates_fmu, 20, 20, parameters={"tooth_friction.friction_coefficient": 0.08},
                                  **kw)
    assert np.std(on - off) > 0.05 * np.std(off)


def test_a_twin_calibrated_on_the_casing_family_gets_its_candidates(shafts_fmu, fmu_dir, shared_build):
    """The rigs' calibrated twin (GearTwin.Gearbox21Shafts) can be diagnosed: its candidate model
    gives the same record with every effect off, and a run-out changes it."""
    from twin.effects import base_of, candidates_model
    from twin.fmu import FMU
    from twin.operating import simulate_operating_point

    with FMU(shafts_fmu) as f:
        base = base_of(f.parameter_values())
    assert base == "GearTwin.Gearbox21Shafts"
    cand = shared_build(candidates_model(base), fmu_dir)
    kw = dict(settle=0.02, duration=0.02, channels=["accel_pinion_casing"], output_interval=5e-5)
    y0 = simulate_operating_point(str(shafts_fmu), 20.0, 20.0, parameters={}, **kw)[:, 0]
    y1 = simulate_operating_point(str(cand), 20.0, 20.0, parameters={}, **kw)[:, 0]
    y2 = simulate_operating_point(str(cand), 20.0, 20.0, parameters={"pinion_eccentricity.eccentricity": 3e-5},
                                  **kw)[:, 0]
    assert np.max(np.abs(y1 - y0)) <= 1e-9 * np.max(np.abs(y0))
    assert np.sqrt(np.mean((y2 - y0) ** 2)) > 1e-3 * np.sqrt(np.mean(y0 ** 2))


@pytest.mark.parametrize("split", ["along", "normal"])
def test_a_run_out_moves_the_start_of_contact_by_hand(candidates_fmu, split):
    """A gear moved bodily along the line of action by u starts each pair's contact u earlier
    along the path; moved by w normal to it (the centre distance shrinks by w cos(alpha)) it
    starts w / tan(alpha) earlier (d(a sin(alpha'))/da = 1/sin(alpha')). The share of a mesh cycle
    in double contact grows by that shift over p_b. With u = e sin(theta), w = e cos(theta), over
    the half turn where sin(theta) > 0 against the other that is 4 e / (pi p_b); over the halves
    of cos(theta), 4 e / (pi p_b tan(alpha)); beyond what the gearbox's own tooth errors make of
    the two halves without a run-out."""
    from twin.fmu import FMU
    from twin.operating import simulate_operating_point

    with FMU(candidates_fmu) as f:
        v = f.parameter_values()
    p_b = np.pi * v["module"] * np.cos(v["alpha"])
    expected = 4 * 1e-4 / (np.pi * p_b) / (1.0 if split == "along" else np.tan(v["alpha"]))
    kw = dict(settle=0.05, duration=0.2, channels=["mesh_stiffness", "encoder_pinion_angle"], output_interval=2e-6)
    shares = {}
    for e in (0.0, 1e-4):
        y = simulate_operating_point(str(candidates_fmu), 20.0, 20.0, **kw,
                                     parameters={"pinion_eccentricity.eccentricity": e,
                                                 "pinion_eccentricity.phase": 0.0})
        k, angle = y[:, 0], y[:, 1]
        double = k > 0.5 * (np.percentile(k, 5) + np.percentile(k, 95))
        ahead = (np.sin(angle) if split == "along" else np.cos(angle)) > 0
        shares[e] = float(np.mean(double[ahead]) - np.mean(double[~ahead]))
    assert shares[1e-4] - shares[0.0] == pytest.approx(expected, rel=0.15)


def test_a_lead_mismatch_shrinks_the_face_contact_by_hand(gearbox_fmu):
    """Leads that differ by D across the face: each pair carries k (a - D/2) with the whole face
    in contact and k a^2 / (2 D) with the length a/D of it. At light load (a << D) the mean
    approach is then about sqrt(2 D F / k_mean) instead of F / k_mean; the shafts' lateral give
    under the same force is the same, so the transmission error moves by the difference."""
    from twin.operating import simulate_operating_point

    kw = dict(settle=0.1, duration=0.1, channels=["transmission_error", "mesh_force", "mesh_stiffness",
                                                  "pair_force[1]", "pair_force[2]", "pair_force[3]"],
              output_interval=1e-5)
    mean = {}
    for d in (0.0, 20e-6):
        y = simulate_operating_point(str(gearbox_fmu), 20.0, 20.0, parameters={"lead_mismatch": d}, **kw)
        assert np.all(y[:, 3:6] >= 0.0)
        mean[d] = [float(np.mean(v)) for v in (y[:, 0], y[:, 3:6].sum(axis=1), y[:, 2])]
    (te0, f0, k0), (te1, f1, k1) = mean[0.0], mean[20e-6]
    assert f1 == pytest.approx(f0, rel=0.02)              # the same torque is carried
    assert te1 - te0 == pytest.approx(np.sqrt(2 * 20e-6 * f1 / k1) - f0 / k0, rel=0.15)


def test_a_housing_mode_filters_what_reaches_the_sensor(shafts_fmu, fmu_dir, shared_build):
    """On a model with a sensor (GearTwin.Gearbox21Shafts) the mode is driven by the sensor's
    reading, not by the pedestal: what it adds scales with the sensor's gain, as the rest does."""
    from twin.effects import base_of, candidates_model
    from twin.fmu import FMU
    from twin.operating import simulate_operating_point

    with FMU(shafts_fmu) as f:
        cand = shared_build(candidates_model(base_of(f.parameter_values())), fmu_dir)
    kw = dict(settle=0.02, duration=0.05, channels=["accel_pinion_casing"], output_interval=1e-5)
    mode = {"housing_mode.participation": 1.0, "housing_mode.frequency": 2000.0}
    added, offs = [], []
    for gain in (1.0, 3.0):
        off = simulate_operating_point(str(cand), 20, 20, parameters={"sensor_pinion.gain": gain}, **kw)[:, 0]
        on = simulate_operating_point(str(cand), 20, 20, parameters={"sensor_pinion.gain": gain, **mode}, **kw)[:, 0]
        added.append(on - off)
        offs.append(off)
    assert np.std(added[0]) > 0.01 * np.std(offs[0])
    assert np.allclose(added[1], 3.0 * added[0], rtol=1e-6, atol=1e-6 * np.max(np.abs(added[1])))


def _mesh_states(fmu_path, parameters, calculated):
    """One turn and more of the pinion at 20 Hz / 20 N.m after 0.05 s, stepped by 1e-5 s and read
    one sample at a time (states are no outputs): the parameter values, the ``calculated``
    parameters' values, and per sample theta5, theta10, x5, y5, x10, y10, roll[1..3],
    pair_force[1..3] (6000 x 12)."""
    from twin.fmu import FMU
    from twin.operating import operating_point

    start, inputs = operating_point(20.0, 20.0)
    names = ["theta5", "theta10", "x5", "y5", "x10", "y10"] + [f"roll[{i}]" for i in (1, 2, 3)] \
        + [f"pair_force[{i}]" for i in (1, 2, 3)]
    with FMU(fmu_path) as f:
        v = f.parameter_values()
        f.setup(0.0, parameters={**start, **parameters}, inputs=inputs)
        values = f.get(calculated)
        f.step(0.05)
        rows = []
        for _ in range(6000):              # 0.06 s, more than a turn of the pinion
            f.step(1e-5)
            rows.append(f.get(names))
    return v, values, np.array(rows)


@pytest.mark.parametrize("setting", [{"lead_mismatch": 30e-6}, {"pinion_eccentricity.wobble": 30e-6}])
def test_the_face_law_is_the_sum_of_thin_slices_by_hand(candidates_fmu, setting):
    """Thin slices across the face (the uncoupled springs of Velex & Maatar 1996 and of ISO 6336-1's
    face load factor): a pair of stiffness k is N slices of k/N, slice j set back by D (j + 1/2)/N
    along the line of action. Summed slice by slice from the FMU's own approach and roll, they give
    each pair's force, in partial contact (a < D, as here at 20 N.m: a/D about 0.2) and, where the
    wobble D = |w cos theta5| passes zero, with the whole face in contact."""
    v, (rb1, rb2, force_static), y = _mesh_states(candidates_fmu, {"pinion_eccentricity.eccentricity": 0.0, **setting},
                                                  ["rb1", "rb2", "mesh_force_static"])
    k_pair = np.array([v[f"k_pair[{n}]"] for n in range(1, 12)])
    s = v["contact_smoothing"]
    th5, th10, x5, y5, x10, y10 = y[:, :6].T
    roll, pair_force = y[:, 6:9], y[:, 9:12]
    a = (rb1 * th5 - rb2 * th10 + (x5 - x10) * np.sin(v["alpha"]) + (y5 - y10) * np.cos(v["alpha"]))
    D = np.abs(setting.get("lead_mismatch", 0.0) + setting.get("pinion_eccentricity.wobble", 0.0) * np.cos(th5))
    # away from the smoothed entry and exit of a pair: k is k_pair along the roll, or 0 outside the path
    clear = np.all((np.abs(roll) > s) & (np.abs(roll - 1) > s), axis=1)
    k = np.where((roll > 0) & (roll < 1), np.interp(np.clip(roll, 0, 1), np.linspace(0, 1, 11), k_pair), 0.0)
    n = 4000
    gaps = D[:, None] * (np.arange(n) + 0.5) / n
    per_unit = np.maximum(0.0, a[:, None] - gaps).mean(axis=1)        # force of the slices per unit k
    slices = k * per_unit[:, None]
    assert clear.mean() > 0.8
    assert np.mean(a[clear] < D[clear]) > 0.8                             # mostly partial face contact
    np.testing.assert_allclose(pair_force[clear], slices[clear], rtol=1e-4, atol=1e-5 * force_static)
    if "pinion_eccentricity.wobble" in setting:
        assert np.any(a[clear] > D[clear])                                # and the whole face near D = 0


def test_a_spall_sets_back_one_tooth_over_its_span_by_hand(candidates_fmu):
    """A spall of depth d on tooth 1 from the pinion's lowest point of single-tooth contact to the
    pitch point (roll positions from the gear geometry, worked out here): each pair carries
    k(roll) max(0, a - e) with e = d while tooth 1's contact lies in that span, 0 elsewhere and on
    every other tooth (away from the spall's edges and the pairs' entry and exit)."""
    d = 2e-6
    v, (rb1, rb2, edge), y = _mesh_states(candidates_fmu, {"local_tooth_damage.spall_depth": d},
                                          ["rb1", "rb2", "local_tooth_damage.edge_width"])
    m, alpha, z1, z2, ha = v["module"], v["alpha"], 19, 52, v["addendum_coefficient"]
    r1, r2 = m * z1 / 2, m * z2 / 2
    p_b = np.pi * m * np.cos(alpha)
    approach = np.sqrt((r2 + ha * m) ** 2 - (r2 * np.cos(alpha)) ** 2) - r2 * np.sin(alpha)
    recess = np.sqrt((r1 + ha * m) ** 2 - (r1 * np.cos(alpha)) ** 2) - r1 * np.sin(alpha)
    path = approach + recess
    lo, hi = (path - p_b) / path, approach / path            # lowest point of single contact, pitch point
    assert 0.3 < lo < hi < 0.7
    th5, th10, x5, y5, x10, y10 = y[:, :6].T
    roll, pair_force = y[:, 6:9], y[:, 9:12]
    # the pinion tooth in each pair (leading, current, next) from the count of completed mesh cycles
    mesh_angle = z1 * th5 + v["mesh_phase0"]
    cycles = np.floor(mesh_angle / (2 * np.pi))
    tooth = np.mod(cycles[:, None] + np.array([-1, 0, 1]), z1) + 1
    a = rb1 * th5 - rb2 * th10 + (x5 - x10) * np.sin(alpha) + (y5 - y10) * np.cos(alpha)
    k_pair = np.array([v[f"k_pair[{n}]"] for n in range(1, 12)])
    k = v["mesh_stiffness_scale"] * np.where((roll > 0) & (roll < 1),
                                             np.interp(np.clip(roll, 0, 1), np.linspace(0, 1, 11), k_pair), 0.0)
    inside = (np.round(tooth) == 1) & (roll > lo) & (roll < hi)
    e = np.where(inside, d, 0.0)
    s = v["contact_smoothing"]
    clear = (np.abs(roll) > s) & (np.abs(roll - 1) > s) & (np.abs(roll - lo) > edge) & (np.abs(roll - hi) > edge)
    assert inside[clear].sum() > 20 and (~inside[clear]).sum() > 1000
    expected = k * np.maximum(0.0, a[:, None] - e)
    np.testing.assert_allclose(pair_force[clear], expected[clear], rtol=1e-4, atol=1e-5 * np.abs(pair_force).max())
    # in single contact the spalled tooth gives way by the spall: the approach jumps by about d
    single = inside & (roll > lo + edge) & (roll < hi - edge)
    healthy = (np.round(tooth) != 1) & (roll > lo + edge) & (roll < hi - edge)
    assert a[np.any(single, axis=1)].mean() - a[np.any(healthy, axis=1)].mean() == pytest.approx(d, rel=0.25)
