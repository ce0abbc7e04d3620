"""twin.transfer.settings: the assessor's settings follow from the archive's test; rig records are checked."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import h5py
import pytest

from twin.transfer.errors import AssessorError
from twin.transfer.settings import (archive_facts, check_records, class_prior_for, preprocessing_for,
                                    resampling_note)

from .conftest import rig_records, write_tiny_archive

REPO = Path(__file__).resolve().parents[3]


def test_facts_of_an_archive_and_the_settings_they_give(tmp_path):
    f = archive_facts(write_tiny_archive(tmp_path / "lub.h5"))
    assert f.damage_kind == "pitting_density" and f.n_stages == 3
    assert (f.nominal_speed, f.nominal_load) == (20.0, 20.0)
    assert f.speed_scatter == 0.03 and f.load_scatter == 0.15       # the shipped scenario's archive block
    pre = preprocessing_for(f)
    assert pre.sample_rate == pytest.approx(20480.0) and pre.window == 2048 and pre.remove_level
    assert class_prior_for(f) == "ordinal"
    w = archive_facts(write_tiny_archive(tmp_path / "dry.h5", scenario="dry.yaml"))
    assert w.damage_kind == "wear_depth" and w.nominal_speed == 10.0 and w.nominal_load == 5.0
    pre = preprocessing_for(w)
    assert pre.sample_rate == pytest.approx(10240.0) and not pre.remove_level


def test_an_archive_without_the_operating_point_gives_its_records_median(tmp_path):
    path = write_tiny_archive(tmp_path / "old.h5")
    with h5py.File(path, "a") as f:
        del f.attrs["nominal_speed"], f.attrs["nominal_load"]
        for k in f["records"]:
            f["records"][k].attrs["nominal_speed"] = 19.0
    assert archive_facts(path).nominal_speed == 19.0


def test_a_measurement_file_or_missing_file_is_not_an_archive(tmp_path):
    from twin.measurements import write_measurements
    rig = write_measurements(rig_records(), tmp_path / "rig.h5")
    with pytest.raises(AssessorError, match="not a gear-twin archive"):
        archive_facts(rig)
    with pytest.raises(AssessorError, match="does not exist"):
        archive_facts(tmp_path / "none.h5")


def test_records_of_another_test_are_refused_by_name_and_missing_speeds_noted(tmp_path):
    f = archive_facts(write_tiny_archive(tmp_path / "lub.h5"))
    recs = rig_records(per_stage=1)
    assert check_records(recs, f) == []
    wrong = [replace(recs[0], name="dry_run", nominal_speed=10.0, load=5.0), recs[1],
             replace(recs[2], name="fast", nominal_speed=23.0)]
    with pytest.raises(AssessorError) as err:
        check_records(wrong, f)
    msg = str(err.value)
    assert "'dry_run' (speed 10 Hz, load 5 N.m)" in msg and "'fast' (speed 23 Hz)" in msg and recs[1].name not in msg
    tagged = replace(recs[0], metadata={"damage_kind": "wear_depth"})
    with pytest.raises(AssessorError, match="damage kind wear_depth"):
        check_records([tagged], f)
    notes = check_records([replace(recs[0], nominal_speed=None)], f)
    assert len(notes) == 1 and "no nominal_speed" in notes[0] and "20 Hz" in notes[0]


def test_resampling_is_reported():
    assert resampling_note([20480.0, 20480.0], 20480.0) is None
    note = resampling_note([50000.0, 25000.0], 20480.0)
    assert "25000, 50000 Hz to 20480 Hz" in note and "above 8192 Hz" in note


def test_the_shipped_scenarios_build_the_benchmarks_archives():
    from twin.scenario import load_scenario
    from twin.transfer.benchmark import TASKS, task_scenario

    for task, file in TASKS.items():
        shipped = load_scenario(REPO / file).archive
        for key, value in task_scenario(task).archive.items():
            assert shipped.get(key, 0.0) == value, (task, key)      # absent = 0 in an archive block
