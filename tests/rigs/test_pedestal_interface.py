"""The pedestal rig's interface: records, files, truth, determinism, scatter, bad input, CLI."""
from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import h5py
import numpy as np
import pytest

from rigs.pedestal import EFFECTS, OUTSIDE_CATALOGUE, Damage, Rig, read_truth, write
from rigs.pedestal.cli import main
from rigs.pedestal.params import SCATTERED

PACKAGE = Path(__file__).resolve().parents[2] / "rigs" / "pedestal"


def test_the_rig_shares_no_code_with_the_twin():
    for path in PACKAGE.glob("*.py"):
        text = path.read_text()
        assert "import twin" not in text and "from twin" not in text, path
        assert "modelica" not in text.lower(), path


def test_records_are_deterministic_for_a_seed():
    rig = Rig()
    a = rig.steady(duration=0.1, seed=5)
    b = rig.steady(duration=0.1, seed=5)
    c = rig.steady(duration=0.1, seed=6)
    for ch in a.channels:
        np.testing.assert_array_equal(a[ch], b[ch])
    assert not np.allclose(a["accel_pinion_casing"], c["accel_pinion_casing"])


def test_record_channels_rate_and_true_speed_offset():
    box = Rig().scattered(seed=3, scatter=0.12)
    rec = box.steady(speed=20.0, load=20.0, duration=0.2, seed=1)
    assert rec.sample_rate == 50_000.0 and rec.n_samples == 10_000
    assert set(rec.channels) == {"accel_pinion_casing", "accel_gear_casing", "encoder"}
    enc = rec["encoder"]
    assert np.all(np.abs(np.diff(enc)) < np.pi)
    measured = (enc[-1] - enc[0]) / (2 * np.pi) / ((rec.n_samples - 1) / rec.sample_rate)
    assert measured == pytest.approx(rec.truth["true_speed"][1], rel=3e-3)
    assert measured != pytest.approx(20.0, rel=1e-4)      # the true speed is not the nominal
    assert rec.attributes["nominal_speed"] == 20.0 and rec.attributes["load"] == 20.0


def test_scattered_gearboxes_differ_within_the_scatter_and_repeat():
    base = Rig()
    a, b = base.scattered(1, 0.12), base.scattered(1, 0.12)
    assert a == b and a != base.scattered(2, 0.12)
    for sec, name in SCATTERED:
        v0 = np.atleast_1d(getattr(getattr(base, sec), name))
        v1 = np.atleast_1d(getattr(getattr(a, sec), name))
        assert np.all(np.abs(v1 / v0 - 1) <= 0.12 + 1e-12), name
    assert a.identity.seed != base.identity.seed
    fa = [m.frequency for m in a.modes()]
    f0 = [m.frequency for m in base.modes()]
    assert fa != f0


def test_files_load_with_the_twin_loader_and_truth_is_separate(tmp_path):
    from twin.measurements import load_measurements

    rig = Rig()
    recs = [rig.steady(duration=0.2, seed=1, effect="pinion_runout", name="healthy_run"),
            rig.runup((2.0, 6.0), duration=0.3, seed=2, damage=Damage("pitting", 0.05))]
    out = write(tmp_path / "rig.h5", recs)
    mset = load_measurements(out)
    assert mset.names == ("healthy_run", "runup_2")
    r0 = mset["healthy_run"]
    assert r0.sample_rate == 50_000.0 and r0.tachometer == "encoder"
    assert r0.tachometer_kind == "angle" and r0.units["accel_pinion_casing"] == "m/s2"
    np.testing.assert_allclose(r0["accel_gear_casing"], recs[0]["accel_gear_casing"])
    # what only the rig knows is in the truth file, not in the measurement file
    truth = read_truth(out)
    t0 = truth["records"]["healthy_run"]
    assert t0["effect"]["name"] == "pinion_runout" and t0["effect"]["size"] > 0
    assert truth["records"]["runup_2"]["damage"] == {"kind": "pitting", "size": 0.05}
    assert len(t0["modes"]) >= 10 and "gains" in t0
    with h5py.File(out) as f:
        attrs = set(f["records/healthy_run"].attrs) | set(f.attrs)
    assert not attrs & {"effect", "damage", "gains", "true_speed", "modes", "label"}
    json.dumps(truth)


def test_every_effect_has_a_default_size_in_the_truth():
    rig = Rig()
    assert OUTSIDE_CATALOGUE and set(OUTSIDE_CATALOGUE) <= set(EFFECTS)
    for name in EFFECTS:
        rec = rig.steady(duration=0.05, effect=name, seed=0)
        assert rec.truth["effect"]["size"] > 0


def test_stage_helpers_and_stage_records():
    rig = Rig()
    pit, wear = rig.pitting_stages(), rig.wear_stages()
    assert len(pit) == 6 and len(wear) == 4
    assert all(s.speed == 20.0 and s.load == 20.0 and s.lubricated for s in pit)
    assert pit[-1].high == pytest.approx(0.20) and wear[1].low == pytest.approx(60e-6)
    recs = rig.stage_records("wear", per_stage=2, duration=0.05, seed=1)
    assert [r.truth["label"] for r in recs] == [0, 0, 1, 1, 2, 2, 3, 3]
    assert [r.name for r in recs] == [f"wear_{i:03d}" for i in range(8)]
    sizes = [r.truth["damage"]["size"] for r in recs]
    assert sizes == sorted(sizes)                      # in the order of the test
    for r in recs:
        st = wear[r.truth["label"]]
        assert st.low <= r.truth["damage"]["size"] < st.high
        assert r.attributes["nominal_speed"] == 10.0
        assert "label" not in r.attributes and "damage" not in r.attributes


def test_bad_inputs_are_typed_errors_naming_the_value(tmp_path):
    rig = Rig()
    with pytest.raises(ValueError, match="no_such_effect"):
        rig.steady(duration=0.05, effect="no_such_effect")
    with pytest.raises(ValueError, match="rust"):
        rig.steady(duration=0.05, damage=("rust", 0.1))
    with pytest.raises(ValueError, match="1.5"):
        Damage("pitting", 1.5)
    with pytest.raises(ValueError, match="-2"):
        rig.steady(speed=-2.0, duration=0.05)
    with pytest.raises(ValueError, match="scatter"):
        rig.scattered(1, scatter=0.9)
    rec = rig.steady(duration=0.05)
    with pytest.raises(ValueError, match="rig.csv"):
        write(tmp_path / "rig.csv", [rec])
    target = tmp_path / "keep.h5"
    write(target, [rec])
    before = target.read_bytes()
    with pytest.raises(ValueError, match="unique"):
        write(target, [rec, rec])
    assert target.read_bytes() == before


def test_command_line_writes_a_loadable_file_and_truth(tmp_path, capsys):
    from twin.measurements import load_measurements

    out = tmp_path / "cli.h5"
    assert main(["steady", "--duration", "0.1", "--seed", "3", "--gearbox", "2",
                 "--effect", "drive_ripple", "--out", str(out)]) == 0
    assert load_measurements(out).names == ("steady_3",)
    assert read_truth(out)["records"]["steady_3"]["gearbox_seed"] == 3
    assert main(["steady", "--damage", "pitting", "--out", str(out)]) == 2
    assert "KIND:SIZE" in capsys.readouterr().err
    assert main(["modes"]) == 0
    assert "| 1 |" in capsys.readouterr().out


def test_describe_is_plain_data():
    d = Rig().describe()
    json.dumps(d)
    assert d["gears"] == asdict(Rig().gears)
