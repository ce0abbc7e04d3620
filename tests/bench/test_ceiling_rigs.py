"""The rigs' ceiling benchmark: trained on the training file's labels, scored on the test file's
records only, and a test record drawn with a training record's seed is refused."""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

_spec = importlib.util.spec_from_file_location(
    "ceiling_rigs", Path(__file__).resolve().parents[2] / "bench" / "ceiling_rigs.py")
cr = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cr)

FS = 10240.0        # the wear test's assessor rate: no resampling
CHANNEL = "accel_pinion_casing"


def _write(path: Path, seeds: list[int]) -> str:
    """Two stages, alternating record by record: broadband noise, and the same with a 2 kHz tone."""
    from twin.measurements import Record, write_measurements
    t = np.arange(int(FS)) / FS
    recs, truth = [], {}
    for i, s in enumerate(seeds):
        x = np.random.default_rng(s).standard_normal(t.size) + (i % 2) * 3.0 * np.sin(2 * np.pi * 2000.0 * t)
        recs.append(Record(f"wear_{i:03d}", {CHANNEL: x}, {CHANNEL: "m/s2"}, FS, nominal_speed=10.0, load=5.0))
        truth[f"wear_{i:03d}"] = {"label": i % 2, "seed": s}
    write_measurements(recs, path)
    Path(str(path) + ".truth.json").write_text(json.dumps({"records": truth}))
    return str(path)


def test_scores_the_test_records_of_a_network_trained_on_the_training_labels(tmp_path):
    train, test = _write(tmp_path / "train.h5", list(range(6))), _write(tmp_path / "test.h5", list(range(10, 16)))
    run = cr.train_and_score("synthetic", "wear", 0, 14, train, test)
    assert run["n_train_records"] == run["n_test_records"] == 6
    assert run["n_test_windows"] == 6 * 9 and np.sum(run["confusion"]) == run["n_test_windows"]
    assert run["window_exact"] > 0.9 and run["window_within_one"] == 1.0
    row, = cr.summarise([run, {**run, "seed": 1, "window_exact": 0.5}])
    assert row["mean"]["window_exact"] == pytest.approx((run["window_exact"] + 0.5) / 2)
    assert not row["meets_exact"] and row["meets_within_one"]
    assert "| synthetic | wear (2) |" in cr.table([row])


def test_refuses_a_test_record_drawn_with_a_training_seed(tmp_path):
    train, test = _write(tmp_path / "train.h5", [0, 1, 2, 3]), _write(tmp_path / "test.h5", [3, 11, 12, 13])
    with pytest.raises(SystemExit, match="1 test record"):
        cr.train_and_score("synthetic", "wear", 0, 1, train, test)
