"""twin.archive: labelled records per stage, deterministic for a seed, on local processes and Dask."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from twin.archive import build_archive, interpolate_parameters, read_archive
from twin.errors import SimulationError
from twin.scenario import load_scenario

REPO = Path(__file__).resolve().parents[2]


def _small(seed=0, workers=1, executor=None):
    sc = load_scenario(REPO / "scenarios" / "lubricated.yaml")
    deg = dict(sc.degradation)
    deg.update({"stop": {"pitting_density": 0.07}, "load_window": 0.05, "record_duration": 0.0})
    arc = dict(sc.archive)
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
