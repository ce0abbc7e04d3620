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
