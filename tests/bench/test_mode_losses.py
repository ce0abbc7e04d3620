"""bench/mode_losses.py: each first-six mode in one class, from the files a bench run wrote."""
from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
from mode_losses import CLASSES, loss_class, losses, main  # noqa: E402


def _mode(hz, error_pc, twin_class="casing"):
    return {"hz": hz, "error_pc": error_pc, "twin_class": twin_class}


def test_each_mode_gets_the_first_class_that_fits():
    used, paired = [500.0, 1010.0, 1500.0], [500.0, 1500.0]
    assert loss_class(_mode(500.0, 1.0), used, paired) == "met"
    assert loss_class(_mode(2400.0, -0.1, "sensor path"), used, paired) == "met (slot)"
    assert loss_class(_mode(800.0, 9.0), used, paired) == "not seen"
    assert loss_class(_mode(1000.0, 5.0), used, paired) == "seen, unpaired"      # 1010 is 1 % away
    assert loss_class(_mode(1480.0, -4.0), used, paired) == "paired, not reached"
    assert loss_class(_mode(1480.0, -3.0), used, paired) == "met"                 # 3 % is met


def test_counts_over_the_gearboxes_of_a_run(tmp_path, capsys):
    rows = [{"rig": "beam", "seed": s, "first6_explained": [_mode(500.0, 0.5), _mode(900.0, 8.0)]} for s in (1, 2)]
    (tmp_path / "results.json").write_text(json.dumps(rows))
    for s in (1, 2):
        cal = tmp_path / f"beam_{s}_cal"
        cal.mkdir()
        (cal / "modes.json").write_text(json.dumps({"modes": [
            {"frequency_hz": 500.0, "confidence": 0.9}, {"frequency_hz": 905.0, "confidence": 0.1 if s == 1 else 0.9}]}))
        (cal / "sensitivity.json").write_text(json.dumps({"measured_hz": [500.0, 905.0]}))
    c = losses(tmp_path)
    assert set(c) == set(CLASSES)
    assert (c["met"], c["not seen"], c["paired, not reached"], c["seen, unpaired"]) == (2, 1, 1, 0)
    assert main([str(tmp_path)]) == 0
    assert "| 2 | 0 | 1 | 0 | 1 |" in capsys.readouterr().out
    assert main([str(tmp_path), str(tmp_path / "missing")]) == 2
    out, err = capsys.readouterr()
    assert out == "" and "missing" in err and len(err.strip().splitlines()) == 1
