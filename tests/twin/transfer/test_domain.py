"""The emulated rig's target domain: the request checks shared by every target simulator."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from twin.errors import OutputPathError, ParameterError, ScenarioError
from twin.scenario import load_scenario
from twin.transfer.domain import check_target_request, make_target_domain

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"


def test_a_good_request_returns_the_archive_block_and_the_path(tmp_path):
    sc = load_scenario(SCENARIOS / "dry.yaml")
    spec, path = check_target_request(sc, tmp_path / "rig.h5", 3, 0.2)
    assert spec["stages"] == sc.archive["stages"] and Path(path).name == "rig.h5"


@pytest.mark.parametrize("records, duration, match", [(0, 0.2, "records_per_stage"), (2.5, 0.2, "records_per_stage"),
                                                      (3, 0.0, "record_duration"), (3, "long", "record_duration")])
def test_bad_sizes_are_named_before_any_simulation(tmp_path, records, duration, match):
    sc = load_scenario(SCENARIOS / "dry.yaml")
    with pytest.raises(ParameterError, match=match):
        make_target_domain(sc, tmp_path / "rig.h5", records_per_stage=records, record_duration=duration,
                           progress=False)
    assert not (tmp_path / "rig.h5").exists()


def test_no_archive_block_or_a_bad_path_fails_first(tmp_path):
    sc = load_scenario(SCENARIOS / "dry.yaml")
    with pytest.raises(ScenarioError, match="archive"):
        check_target_request(replace(sc, archive=None), tmp_path / "rig.h5", 3, 0.2)
    with pytest.raises(OutputPathError):
        check_target_request(sc, tmp_path / "missing_dir" / "rig.h5", 3, 0.2)
    with pytest.raises(OutputPathError):
        check_target_request(sc, tmp_path / "rig.csv", 3, 0.2)
