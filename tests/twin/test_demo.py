"""The demo's arguments are checked before anything is built or written."""
from __future__ import annotations

import pytest

from twin.demo import run_demo
from twin.errors import ParameterError


def test_hidden_effect_records_are_a_steady_and_a_runup_file_that_exist(tmp_path):
    steady = tmp_path / "steady.h5"
    steady.write_bytes(b"")
    with pytest.raises(ParameterError, match="give a steady and a run-up file, got 1"):
        run_demo(tmp_path / "out", hidden_effect_records=[steady])
    with pytest.raises(ParameterError, match="runup.h5' do not exist"):
        run_demo(tmp_path / "out", hidden_effect_records=[steady, tmp_path / "runup.h5"])
    assert not (tmp_path / "out").exists()


def test_calibration_records_are_two_to_six_files(tmp_path):
    files = [tmp_path / f"{i}.h5" for i in range(7)]
    with pytest.raises(ParameterError, match="then another healthy steady record\\), got 7"):
        run_demo(tmp_path / "out", calibration_records=files)
    assert not (tmp_path / "out").exists()


def test_step_6_says_which_shaft_each_mode_lives_on():
    import numpy as np

    from twin.demo_rig import _shaft_reading
    from twin.signals.survey import ModalSurvey, Mode

    def mode(f, pinion, gear, confidence=0.9):
        return Mode(f, 0.02, confidence, 10.0, {"struck_db": {"hammer": pinion, "hammer_gear": gear}})

    survey = ModalSurvey("hammer", (mode(500.0, 0.0, -9.0), mode(800.0, -7.0, 0.0), mode(1200.0, -2.0, 0.0),
                                    mode(1500.0, 0.0, -20.0, confidence=0.1)), (), (), (10.0, 5000.0), 1.0,
                         np.zeros(1), np.zeros(1))
    assert _shaft_reading(survey).endswith("input shaft 500 Hz; output shaft 800 Hz; both 1200 Hz")
    quiet = ModalSurvey("hammer", (Mode(500.0, 0.02, 0.9, 10.0),), (), (), (10.0, 5000.0), 1.0, np.zeros(1),
                        np.zeros(1))
    assert _shaft_reading(quiet) == "struck-point levels: no mode in both hammer records' band"
