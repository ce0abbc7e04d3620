"""twin.archive: labelled records per stage, deterministic for a seed, on local processes and Dask."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from twin.archive import TOOTH_ERROR_KEYS, build_archive, interpolate_parameters, read_archive
from twin.errors import ParameterError, SimulationError
from twin.scenario import load_scenario

REPO = Path(__file__).resolve().parents[2]


def _small(seed=0, workers=1, executor=None):
    sc = load_scenario(REPO / "scenarios" / "lubricated.yaml")
    deg = dict(sc.degradation)
    deg.update({"stop": {"pitting_density": 0.07}, "load_window": 0.05, "record_duration": 0.0})
    # the shipped archive's pinions have errors of their own; these tests start from perfect ones
    arc = {k: v for k, v in sc.archive.items() if k not in TOOTH_ERROR_KEYS}
    arc.update({"stages": [0.0, 0.03, 0.06], "records_per_stage": 2, "record_duration": 0.01, "settle_time": 0.01})
    return sc.with_overrides(degradation=deg, archive=arc, seed=seed,
                             executor=executor or {"type": "local", "workers": workers})


@pytest.fixture(scope="module")
def archive_pair(gearbox_fmu, tmp_path_factory):
    out = tmp_path_factory.mktemp("arc") / "a.h5"
    a = build_archive(_small(workers=2), out, fmu_path=gearbox_fmu, progress=False)
    return a, out


def test_records_are_labelled_by_stage(archive_pair):
    a, _ = archive_pair
    assert list(a.labels) == [0, 0, 1, 1]
    assert np.all((a.damage[a.labels == 0] < 0.03) & (a.damage[a.labels == 1] >= 0.03))
    assert a.signals["accel_pinion_casing"].shape == (4, 1000)
    assert np.all(np.isfinite(a.signals["accel_pinion_casing"]))
    assert np.std(a.speed) > 0 and np.std(a.load) > 0          # operating scatter


def test_same_seed_same_archive_any_worker_count(archive_pair, gearbox_fmu):
    a, path = archive_pair
    b = build_archive(_small(workers=1), None, fmu_path=gearbox_fmu, progress=False)
    np.testing.assert_array_equal(a.signals["accel_pinion_casing"], b.signals["accel_pinion_casing"])
    np.testing.assert_array_equal(a.damage, b.damage)
    c = read_archive(path)
    np.testing.assert_array_equal(c.signals["accel_pinion_casing"], a.signals["accel_pinion_casing"])
    d = build_archive(_small(seed=1), None, fmu_path=gearbox_fmu, progress=False)
    assert not np.array_equal(d.damage, a.damage)


def test_dask_local_cluster_gives_the_same_archive(archive_pair, gearbox_fmu):
    pytest.importorskip("dask.distributed")
    a, _ = archive_pair
    b = build_archive(_small(executor={"type": "dask", "workers": 2}), None, fmu_path=gearbox_fmu, progress=False)
    np.testing.assert_array_equal(a.signals["accel_pinion_casing"], b.signals["accel_pinion_casing"])


def test_interpolation_between_updates():
    params = [{"k": 0.0}, {"k": 10.0}, {"k": 30.0}]
    assert interpolate_parameters([0.0, 1.0, 2.0], params, 1.5) == {"k": 20.0}
    with pytest.raises(SimulationError, match="outside the simulated range"):
        interpolate_parameters([0.0, 1.0], params[:2], 1.5)


def test_stage_beyond_the_degradation_run_is_refused(gearbox_fmu):
    sc = _small()
    arc = dict(sc.archive)
    arc["stages"] = [0.0, 0.03, 0.5]
    with pytest.raises(SimulationError, match="short of the last stage boundary"):
        build_archive(sc.with_overrides(archive=arc), None, fmu_path=gearbox_fmu, progress=False)


def test_snapshot_sampling_centres_records_on_their_stage():
    import numpy as np

    from twin.archive import stage_damage
    rng = np.random.default_rng(0)
    snap = np.array([stage_damage(rng, 0.1, 0.2, {"damage_sampling": "snapshot", "damage_scatter": 0.1})
                     for _ in range(2000)])
    assert np.all((snap >= 0.1) & (snap < 0.2))
    assert abs(snap.mean() - 0.15) < 1e-3 and abs(snap.std() - 0.01) < 1e-3
    uni = np.array([stage_damage(rng, 0.1, 0.2, {}) for _ in range(2000)])
    assert abs(uni.std() - 0.1 / np.sqrt(12)) < 2e-3


class _FixedDraw:
    """A generator whose draws are known: uniform -> its upper bound, normals and gammas as given."""

    def __init__(self, normals, gammas):
        self.normals, self.gammas = np.asarray(normals, float), np.asarray(gammas, float)

    def uniform(self, lo, hi):
        return hi

    def standard_normal(self, n):
        return self.normals[:n]

    def gamma(self, shape, scale, n):
        return self.gammas[:n]


def test_tooth_errors_by_hand():
    from twin.record_gears import tooth_errors
    teeth = 4
    healthy = {"k_pair[1]": 2.0, "k_pair[2]": 2.0, "profile_deviation[1]": 0.0, "profile_deviation[2]": 0.0}
    pitted = {**healthy, "k_pair[1]": 1.6, "k_pair[2]": 1.6}                           # L = 0.2
    draw = _FixedDraw([1.0, -1.0, 0.0, 2.0], [1.0, 3.0, 6.0, 0.5])
    spec = {"pitch_error": 1e-6, "runout": 0.0, "tooth_damage_scatter": 0.5}
    out = tooth_errors(draw, spec, teeth, healthy, pitted)
    # run-out 0; the uniform phase draw returns 2 pi, which does not matter at zero run-out
    offsets = [out[f"tooth_deviation_offset[{i}]"] for i in range(1, 5)]
    np.testing.assert_allclose(offsets, [2e-6, 0.0, 1e-6, 3e-6], atol=1e-18)       # pitch, shifted to min 0
    factors = [out[f"tooth_stiffness_factor[{i}]"] for i in range(1, 5)]
    # a loss the same all along the path: (1 - min(c L, 0.95)) / (1 - L); c = 6 is capped at 95 %
    np.testing.assert_allclose(factors, [1.0, 0.4 / 0.8, 0.05 / 0.8, 0.9 / 0.8])

    # a worn record needs the mesh's load sharing; under it each tooth is worn node by node: its
    # rigid part is the offset, the rest along the path the FMU's per-tooth field
    from twin.degradation.tooth_wear import ToothLoadSharing
    worn = {**healthy, "profile_deviation[1]": 10e-6, "profile_deviation[2]": 30e-6}  # mean 20 um
    with pytest.raises(ParameterError, match="20 um mean depth"):
        tooth_errors(_FixedDraw([0.0] * 4, [1.0, 1.5, 0.5, 1.0]), {"tooth_damage_scatter": 0.5}, teeth, healthy, worn)
    sharing = ToothLoadSharing(np.array([2e8, 2e8]), 1.6, 200.0, np.ones(2), np.zeros(2))   # 1 um deflection
    c = np.array([1.0, 1.1, 0.9, 1.0])
    out = tooth_errors(_FixedDraw([0.0] * 4, c), {"tooth_damage_scatter": 0.1}, teeth, healthy, worn, sharing)
    worn_offsets = np.array([out[f"tooth_deviation_offset[{i}]"] for i in range(1, 5)])
    field = np.array([out[f"tooth_pit_field[{m}]"] for m in range(1, 9)]).reshape(4, 2)
    np.testing.assert_allclose(field.mean(axis=1), 0.0, atol=1e-18)           # the rigid part is the offset
    expected = sharing.wear(np.zeros(4), c, 20e-6)
    np.testing.assert_allclose(worn_offsets[:, None] + field, expected - expected.mean(axis=1).min(), atol=1e-15)
    # the tooth of larger wear coefficient is worn deeper, by less than (c - 1) x the mean depth
    assert worn_offsets.min() == 0.0 and worn_offsets[2] == 0.0 and worn_offsets[1] == worn_offsets.max()
    assert 0.0 < worn_offsets.max() < 0.2 * 20e-6
    assert all(out[f"tooth_stiffness_factor[{i}]"] == 1.0 for i in range(1, 5))
    # no wear coefficient scatter, no pitch errors: the teeth stay alike
    alike = tooth_errors(_FixedDraw([0.0] * 4, [1.0] * 4), {"pitch_error": 1e-6}, teeth, healthy, worn, sharing)
    assert max(abs(v) for n, v in alike.items() if n.startswith(("tooth_deviation_offset", "tooth_pit_field"))) < 1e-15
    # a healthy flank with an as-manufactured profile: only the wear beyond it is wear
    made = {**healthy, "profile_deviation[1]": 4e-6, "profile_deviation[2]": 8e-6}
    on_made = {**made, "profile_deviation[1]": 14e-6, "profile_deviation[2]": 38e-6}     # mean wear 20 um
    out = tooth_errors(_FixedDraw([0.0] * 4, [1.0, 1.1, 0.9, 1.0]), {"tooth_damage_scatter": 0.1}, teeth,
                       made, on_made, sharing)
    np.testing.assert_allclose([out[f"tooth_deviation_offset[{i}]"] for i in range(1, 5)], worn_offsets, rtol=1e-9)
    out = tooth_errors(_FixedDraw([0.0] * 4, [1.0, 1.5, 0.5, 1.0]), {"tooth_damage_scatter": 0.5}, teeth,
                       made, made)
    assert all(out[f"tooth_deviation_offset[{i}]"] == 0.0 for i in range(1, 5))        # new flanks: no wear


def test_tooth_compliance_factors_keep_the_mean_deflection_by_hand():
    from twin.record_gears import tooth_compliance_factors
    # Healthy flank stiffness 1 everywhere; the uniform damage halves it at mid path, linearly
    # in between (three nodes, as the FMU interpolates): the loss is t / 2, with t running from 0
    # at either end to 1 at mid path, so mean(1 / k_damaged) = int_0^1 dt / (1 - t / 2) = 2 ln 2.
    # A tooth pitted twice as much loses min(t, 0.95): mean(1 / k) = -ln(0.05) + 0.05 / 0.05.
    f = tooth_compliance_factors(np.ones(3), np.array([1.0, 0.5, 1.0]), np.array([0.0, 1.0, 2.0]),
                                 samples_per_segment=20000)
    np.testing.assert_allclose(f, [2 * np.log(2), 1.0, 2 * np.log(2) / (1.0 - np.log(0.05))], rtol=1e-3)
    # the earlier mean-stiffness rule gave the doubly pitted tooth (1 - 2 L) / (1 - L) = 0.8
    assert f[2] < 0.4
    assert np.all(tooth_compliance_factors(np.ones(3), np.ones(3), np.array([0.5, 3.0])) == 1.0)
    # a node the uniform damage stripped bare: finite factors, the mean tooth unchanged
    bare = tooth_compliance_factors(np.ones(3), np.array([1.0, 0.0, 1.0]), np.array([0.5, 1.0, 2.0]))
    assert np.all(np.isfinite(bare)) and bare[1] == 1.0 and bare[0] > 1.0 > bare[2]


def test_tooth_errors_runout_and_identical_teeth():
    from twin.record_gears import tooth_errors
    rng = np.random.default_rng(3)
    healthy = {"k_pair[1]": 1.0}
    none = tooth_errors(rng, {}, 19, healthy, healthy)
    assert set(none.values()) <= {0.0, 1.0} and len(none) == 38
    out = tooth_errors(rng, {"runout": 8e-6}, 19, healthy, healthy)
    offsets = np.array([out[f"tooth_deviation_offset[{i}]"] for i in range(1, 20)])
    assert offsets.min() == 0.0 and 0 < np.ptp(offsets) <= 8e-6
    # a once-per-revolution sinusoid: all of its spectrum sits in the first order
    spectrum = np.abs(np.fft.rfft(offsets))
    assert spectrum[1] > 20 * spectrum[2:].max()


def test_archive_with_tooth_errors_keeps_every_other_draw(archive_pair, gearbox_fmu):
    a, _ = archive_pair
    sc = _small(workers=2)
    arc = {**sc.archive, "pitch_error": 2e-6, "runout": 10e-6, "tooth_damage_scatter": 0.5}
    b = build_archive(sc.with_overrides(archive=arc), None, fmu_path=gearbox_fmu, progress=False)
    for name in ("labels", "damage", "speed", "load"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    x, y = a.signals["accel_pinion_casing"], b.signals["accel_pinion_casing"]
    assert np.all(np.isfinite(y)) and not np.allclose(x, y, rtol=0.05)
    c = build_archive(sc.with_overrides(archive=arc, executor={"type": "local", "workers": 1}), None,
                      fmu_path=gearbox_fmu, progress=False)
    np.testing.assert_array_equal(y, c.signals["accel_pinion_casing"])
    assert a.gears is None and len(b.gears) == 4


def test_each_record_names_the_gear_it_was_simulated_with(gearbox_fmu, tmp_path):
    from twin.record_gears import draw_pinion, pinion_parameters, tooth_errors
    from twin.measurements import load_measurements
    sc = _small()
    bounds = {"pitch_error": 2e-6, "runout": 10e-6, "tooth_damage_scatter": 0.5}
    # the scenario's own per-tooth values combine with the drawn ones: factors multiply, offsets add
    own = {"tooth_stiffness_factor[3]": 0.5, "tooth_deviation_offset[3]": 1e-6}
    sc = sc.with_overrides(archive={**sc.archive, **bounds}, parameters={**sc.parameters, **own})
    path = tmp_path / "a.h5"
    a = build_archive(sc, path, fmu_path=gearbox_fmu, progress=False)
    back = read_archive(path)
    # the same draws, replayed: the stored gear is the one each record was simulated with
    seq = np.random.SeedSequence(sc.seed)
    seq.spawn(1 + 3 * 2 + 1)         # the record draws and seeds come first (twin.archive.build_archive)
    replay = np.random.default_rng(seq.spawn(1)[0])
    for g, h in zip(a.gears, back.gears):
        pinion = draw_pinion(replay, bounds, 19)
        assert 0 <= g["gear_runout"] <= 10e-6 and 0 <= g["gear_pitch_error_sd"] <= 2e-6
        assert 0 <= g["gear_tooth_damage_scatter"] <= 0.5 and 0 <= g["gear_runout_phase"] < 2 * np.pi
        assert g["gear_runout"] == pinion.runout and g["gear_runout_phase"] == pinion.runout_phase
        offsets, factors = g["gear_tooth_deviation_offset"], g["gear_tooth_stiffness_factor"]
        assert offsets.shape == factors.shape == (19,)
        assert offsets.min() == pytest.approx(0.0, abs=1e-6) and np.any(factors != 1.0)
        assert set(h) == set(g)
        for name in g:
            np.testing.assert_array_equal(h[name], g[name])
    plain = build_archive(sc.with_overrides(parameters={k: v for k, v in sc.parameters.items() if k not in own}),
                          None, fmu_path=gearbox_fmu, progress=False)
    # (not exactly: the weaker tooth also changes the degradation run, hence the mesh, slightly)
    for g, p in zip(a.gears, plain.gears):
        np.testing.assert_allclose(g["gear_tooth_stiffness_factor"][2], 0.5 * p["gear_tooth_stiffness_factor"][2],
                                   rtol=1e-3)
        np.testing.assert_allclose(g["gear_tooth_deviation_offset"][2] - g["gear_tooth_deviation_offset"][0],
                                   p["gear_tooth_deviation_offset"][2] - p["gear_tooth_deviation_offset"][0] + 1e-6,
                                   rtol=1e-3)
    # the split draw/parameters is the one-call tooth_errors
    rng1, rng2 = np.random.default_rng(5), np.random.default_rng(5)
    healthy = {"k_pair[1]": 1.0, "profile_deviation[1]": 0.0}
    pitted = {"k_pair[1]": 0.9, "profile_deviation[1]": 0.0}
    assert tooth_errors(rng1, bounds, 19, healthy, pitted) == pinion_parameters(draw_pinion(rng2, bounds, 19),
                                                                                healthy, pitted)
    # the gear reaches the measurement layout's metadata, and nothing there mistakes it for a typo
    mset = load_measurements(path)
    np.testing.assert_array_equal(mset[0].metadata["gear_tooth_stiffness_factor"],
                                  a.gears[0]["gear_tooth_stiffness_factor"])


def test_tooth_errors_need_a_model_with_per_tooth_parameters(two_mass_fmu):
    from twin.archive import pinion_teeth
    with pytest.raises(SimulationError, match="no per-tooth parameters"):
        pinion_teeth(two_mass_fmu)
    from twin.archive import wheel_teeth
    with pytest.raises(SimulationError, match="no per-gear-tooth parameters"):
        wheel_teeth(two_mass_fmu)


def test_gear_errors_need_the_variant(gearbox_fmu, wheel_fmu, tmp_path, monkeypatch):
    """Both refusals come before the degradation run, and leave an existing output alone."""
    import twin.degradation_run
    from twin.archive import wheel_teeth
    from twin.errors import ScenarioError

    def no_run(*a, **kw):
        raise AssertionError("the degradation run must not start")

    monkeypatch.setattr(twin.degradation_run, "run_degradation", no_run)
    with pytest.raises(SimulationError, match="GearTwin.Variants.Gearbox21WheelErrors"):
        wheel_teeth(gearbox_fmu)
    assert wheel_teeth(wheel_fmu) == 52
    sc = _small()
    sc = sc.with_overrides(archive={**sc.archive, "wheel_runout": 5e-6}, parameters={**sc.parameters, "z2": 53.0})
    out = tmp_path / "a.h5"
    out.write_bytes(b"kept")
    with pytest.raises(ScenarioError, match="z2 = 53.0"):
        build_archive(sc, out, fmu_path=wheel_fmu, progress=False)
    with pytest.raises(SimulationError, match="Gearbox21WheelErrors"):
        build_archive(sc, out, fmu_path=gearbox_fmu, progress=False)
    assert out.read_bytes() == b"kept"


def test_wheel_draw_by_hand():
    """The gear's teeth sit at the cumulative sum of its single pitch deviations, which closes over
    the revolution, plus the run-out; zero bounds give a perfect gear."""
    from twin.record_gears import draw_wheel, runout_deviation
    assert not np.any(draw_wheel(np.random.default_rng(0), {}, 52).deviation)
    w = draw_wheel(np.random.default_rng(4), {"wheel_pitch_error": 2e-6}, 52)
    # replay the draws: sd, the 52 single deviations, then run-out and phase
    rng = np.random.default_rng(4)
    sd = rng.uniform(0.0, 2e-6)
    single = sd * rng.standard_normal(52)
    assert w.pitch_error_sd == sd and w.runout == 0.0
    spacing = np.diff(np.r_[w.deviation, w.deviation[0]])      # tooth 53 is tooth 1 again
    np.testing.assert_allclose(spacing, np.roll(single - single.mean(), -1), atol=1e-18)
    assert w.deviation.min() == 0.0
    r = draw_wheel(np.random.default_rng(1), {"wheel_runout": 10e-6}, 52)
    np.testing.assert_allclose(r.deviation, runout_deviation(r.runout, r.runout_phase, 52) -
                               runout_deviation(r.runout, r.runout_phase, 52).min(), atol=1e-18)
    assert 0 < r.runout <= 10e-6
    assert set(r.parameters()) == {f"wheel_tooth_deviation_offset[{i}]" for i in range(1, 53)}


def test_archive_with_wheel_errors_keeps_every_other_draw(archive_pair, wheel_fmu, tmp_path):
    """A wheel of its own per record changes the signals and nothing else the archive draws; the
    records keep it, as set in the FMU, and with pinion errors too each keeps both."""
    from twin.record_gears import draw_wheel
    a, _ = archive_pair
    sc = _small(workers=2)
    bounds = {"wheel_pitch_error": 1.5e-6, "wheel_runout": 10e-6}
    path = tmp_path / "w.h5"
    b = build_archive(sc.with_overrides(archive={**sc.archive, **bounds}), path, fmu_path=wheel_fmu,
                      progress=False)
    for name in ("labels", "damage", "speed", "load"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    x, y = a.signals["accel_pinion_casing"], b.signals["accel_pinion_casing"]
    assert np.all(np.isfinite(y)) and not np.allclose(x, y, rtol=0.05)
    seq = np.random.SeedSequence(sc.seed)
    seq.spawn(1 + 3 * 2 + 1 + 1)     # record draws and seeds, then the pinions' stream
    replay = np.random.default_rng(seq.spawn(1)[0])
    back = read_archive(path)
    for g, h in zip(b.gears, back.gears):
        w = draw_wheel(replay, bounds, 52)
        assert set(g) == {"gear_wheel_pitch_error_sd", "gear_wheel_runout", "gear_wheel_runout_phase",
                          "gear_wheel_tooth_deviation_offset"}
        np.testing.assert_array_equal(g["gear_wheel_tooth_deviation_offset"], w.deviation)
        for name in g:
            np.testing.assert_array_equal(h[name], g[name])
    both = build_archive(sc.with_overrides(archive={**sc.archive, **bounds, "runout": 5e-6}), None,
                         fmu_path=wheel_fmu, progress=False)
    for g, w in zip(both.gears, b.gears):
        assert "gear_runout" in g
        np.testing.assert_array_equal(g["gear_wheel_tooth_deviation_offset"], w["gear_wheel_tooth_deviation_offset"])


@pytest.mark.parametrize("key", ["pitch_error", "runout", "tooth_damage_scatter", "wheel_pitch_error",
                                 "wheel_runout"])
def test_negative_tooth_error_bound_is_a_scenario_error(key):
    import yaml

    from twin.errors import ScenarioError
    from twin.scenario import scenario_from_dict
    raw = yaml.safe_load((REPO / "scenarios" / "lubricated.yaml").read_text())
    raw["archive"][key] = -1e-6
    with pytest.raises(ScenarioError, match=key):
        scenario_from_dict(raw)


def test_bad_tooth_error_bounds_set_in_code_are_named_before_any_simulation(tmp_path, monkeypatch, gearbox_fmu):
    import twin.degradation_run
    from twin.errors import ScenarioError

    def no_run(*a, **kw):
        raise AssertionError("the degradation run must not start")

    monkeypatch.setattr(twin.degradation_run, "run_degradation", no_run)
    sc = _small()
    arc = {**sc.archive, "runout": -1e-6, "pitch_error": "2 um", "tooth_damage_scatter": 0.3}
    out = tmp_path / "a.h5"
    out.write_bytes(b"kept")
    with pytest.raises(ScenarioError, match="archive.runout") as err:
        build_archive(sc.with_overrides(archive=arc), out, fmu_path=gearbox_fmu, progress=False)
    assert "archive.pitch_error" in str(err.value) and "tooth_damage_scatter" not in str(err.value)
    assert out.read_bytes() == b"kept"
    arc = {**sc.archive, "wheel_runout": float("nan"), "wheel_pitch_error": -1e-6}
    with pytest.raises(ScenarioError, match="archive.wheel_runout") as err:
        build_archive(sc.with_overrides(archive=arc), out, fmu_path=gearbox_fmu, progress=False)
    assert "archive.wheel_pitch_error" in str(err.value)
    assert out.read_bytes() == b"kept"


def test_a_worn_archive_records_each_tooths_own_flank(gearbox_fmu, tmp_path):
    sc = load_scenario(REPO / "scenarios" / "dry.yaml")
    deg = {**sc.degradation, "stop": {"wear_depth": 4.5e-5}, "record_duration": 0.0}
    arc = {**sc.archive, "stages": [0.0, 2e-5, 4e-5], "records_per_stage": 2, "record_duration": 0.01,
           "settle_time": 0.01, "damage_sampling": "snapshot"}
    sc = sc.with_overrides(degradation=deg, archive=arc, executor={"type": "local", "workers": 1})
    a = build_archive(sc, tmp_path / "w.h5", fmu_path=gearbox_fmu, progress=False)
    back = read_archive(tmp_path / "w.h5")
    worn = [(d, g) for d, g in zip(a.damage, a.gears) if d > 0]
    assert worn and all(g["gear_tooth_flank_field"].shape == (19, 11) for _, g in worn)
    for (_, g), h in zip(worn, [g for d, g in zip(back.damage, back.gears) if d > 0]):
        field = g["gear_tooth_flank_field"]
        np.testing.assert_allclose(field.mean(axis=1), 0.0, atol=1e-15)        # the rigid part is the offset
        assert np.ptp(field) > 0.1e-6          # drawn pitch errors and wear rates: the teeth differ along the path
        np.testing.assert_array_equal(h["gear_tooth_flank_field"], field)
    assert all("gear_tooth_flank_field" not in g for d, g in zip(a.damage, a.gears) if d == 0)
    from twin.measurements import load_measurements
    meta = [r.metadata for r in load_measurements(tmp_path / "w.h5")]
    assert any(np.shape(m.get("gear_tooth_flank_field")) == (19, 11) for m in meta)


def test_worn_teeth_refuse_a_pit_field_of_another_size():
    from twin.record_gears import tooth_field_parameters
    field = np.arange(8.0).reshape(4, 2) * 1e-6
    out = tooth_field_parameters(field, np.full(8, 1e-6))
    assert out["tooth_pit_field[1]"] == pytest.approx(-0.5e-6 + 1e-6)
    with pytest.raises(ParameterError, match="tooth_pit_field has 6 values where the worn teeth need 8"):
        tooth_field_parameters(field, np.zeros(6))
