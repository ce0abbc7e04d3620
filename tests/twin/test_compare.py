"""twin.compare: headline metric and localised findings on data with a known discrepancy."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from twin.cli import main
from twin.compare import compare_signals
from twin.fmu import FMU
from twin.measurements import Record, write_measurements

SHAFT = 19.6116    # pinion speed at 20 Hz drive under 20 N.m (motor slip)


def _sim(fmu, params=None, dur=1.0):
    p = {**(params or {}), "speed_ref_start": 2 * math.pi * 20, "load_start": 20.0}
    with FMU(fmu) as f:
        f.setup(0.0, parameters=p, inputs={"motor_speed_ref": 2 * math.pi * 20, "load_torque": 20.0})
        f.capture(0.1, 1e-5, ["accel_pinion_casing"])
        return f.capture(0.1 + dur, 1e-5, ["accel_pinion_casing"])[:, 0]


@pytest.fixture(scope="module")
def base(gearbox_fmu):
    return _sim(gearbox_fmu)


def _noisy(x, seed=0):
    return x + 0.05 * np.std(x) * np.random.default_rng(seed).standard_normal(x.size)


def test_nothing_missing_raises_no_finding(base):
    c = compare_signals(base, _noisy(base), 1e5, SHAFT)
    assert c.findings == ()
    assert c.lsd_db < 1.5


def test_line_not_locked_to_any_shaft_is_found(base):
    t = np.arange(base.size) / 1e5
    c = compare_signals(base, _noisy(base + 0.3 * np.std(base) * np.sin(2 * np.pi * 247.3 * t)), 1e5, SHAFT)
    top = c.findings[0]
    assert top.kind == "unlocked_line" and top.frequency_hz == pytest.approx(247.3, abs=0.3)
    assert top.share > 0.5 and "not locked to any shaft" in top.description


def test_repeated_impacts_locked_to_neither_shaft_are_an_envelope_finding(base, tmp_path):
    """A bearing's ring-downs at a non-integer order, too weak to lift the spectrum, stand out
    in the envelope; the same impacts in the model are no finding."""
    rng = np.random.default_rng(1)
    ring = np.exp(-np.arange(300) / 40.0) * np.sin(2 * np.pi * 12000.0 * np.arange(300) / 1e5)
    hits = np.zeros(base.size)
    t = 0.0
    while (i := int((t := t + (1 + 0.01 * rng.standard_normal()) / (3.585 * SHAFT)) * 1e5)) + 300 < base.size:
        hits[i:i + 300] += 0.5 * np.std(base) * ring
    c = compare_signals(base, _noisy(base + hits), 1e5, SHAFT)
    found = [f for f in c.findings if f.kind == "envelope_line"]
    assert len(found) == 1 and found[0].order == pytest.approx(3.585, abs=0.01)
    assert "locked to neither shaft" in found[0].description and found[0].band_hz[0] <= 12000 <= found[0].band_hz[1]
    from twin.compare import _plot                 # the report draws the envelope in a panel of its own
    _plot(c, base, base + hits, 1e5, tmp_path / "compare.png")
    assert (tmp_path / "compare.png").stat().st_size > 10000
    assert not [f for f in compare_signals(base + hits, _noisy(base + hits), 1e5, SHAFT).findings
                if f.kind == "envelope_line"]

    class Baseline:                      # the gearbox had the same impacts when calibrated
        envelope_orders = (3.58,)

        @staticmethod
        def at(f):
            return np.zeros(np.size(f))
    assert not [f for f in compare_signals(base, _noisy(base + hits), 1e5, SHAFT, discrepancy=Baseline).findings
                if f.kind == "envelope_line"]


def test_weak_tooth_is_impulsive_with_sidebands(gearbox_fmu, base):
    c = compare_signals(base, _noisy(_sim(gearbox_fmu, {"tooth_stiffness_factor[5]": 0.5})), 1e5, SHAFT)
    kinds = [f.kind for f in c.findings]
    assert kinds[0] == "impulsive"
    assert "sideband" in kinds
    assert c.lsd_db > 3.0 and abs(sum(f.share for f in c.findings) - 1.0) < 0.5


def test_cli_writes_json_html_and_signals(gearbox_fmu, base, tmp_path):
    t = np.arange(base.size) / 1e5
    x = _noisy(base + 0.3 * np.std(base) * np.sin(2 * np.pi * 247.3 * t))
    write_measurements([Record("r", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"}, 1e5,
                               nominal_speed=20.0, load=20.0)], tmp_path / "m.h5")
    (tmp_path / "s.yaml").write_text(f"version: 1\nname: cmp\nfmu: {gearbox_fmu}\nstop_time: 1.0\n"
                                     "output: {variables: [accel_pinion_casing]}\n")
    assert main(["compare", str(tmp_path / "s.yaml"), "--measurements", str(tmp_path / "m.h5"),
                 "--out", str(tmp_path / "rep")]) == 0
    data = json.loads((tmp_path / "rep" / "compare.json").read_text())
    assert data["findings"][0]["kind"] == "unlocked_line"
    assert data["headline"]["log_spectral_distance_db"] > 1.0
    for name in ("compare.html", "compare.png", "simulated.h5"):
        assert (tmp_path / "rep" / name).exists()


def test_record_without_load_is_a_measurement_error_naming_it(gearbox_fmu, tmp_path):
    from twin.compare import compare
    from twin.errors import MeasurementError
    from twin.scenario import load_scenario
    x = np.random.default_rng(0).normal(size=20000)
    write_measurements([Record("r1", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"}, 1e5,
                               nominal_speed=20.0)], tmp_path / "m.h5")
    (tmp_path / "s.yaml").write_text(f"version: 1\nname: cmp\nfmu: {gearbox_fmu}\nstop_time: 1.0\n"
                                     "output: {variables: [accel_pinion_casing]}\n")
    with pytest.raises(MeasurementError, match="r1.*lacks load"):
        compare(load_scenario(tmp_path / "s.yaml"), tmp_path / "m.h5", tmp_path / "rep")
    assert not (tmp_path / "rep" / "compare.json").exists()


def test_compare_simulates_at_the_measured_speed_as_diagnose_does(gearbox_fmu, tmp_path):
    """A record taken 1 % off its nominal speed: compare and the diagnosis baseline both run the
    model at the measured speed, so they report the same operating point and the same distance."""
    from twin.compare import compare
    from twin.effects.diagnose import record_conditions, simulate
    from twin.scenario import load_scenario
    p = {"speed_ref_start": 2 * math.pi * 20.2, "load_start": 20.0, "tooth_stiffness_factor[5]": 0.7}
    with FMU(gearbox_fmu) as f:
        f.setup(0.0, parameters=p, inputs={"motor_speed_ref": 2 * math.pi * 20.2, "load_torque": 20.0})
        f.capture(0.1, 5e-5, ["accel_pinion_casing"])
        x = _noisy(f.capture(0.6, 5e-5, ["accel_pinion_casing"])[:, 0])
    write_measurements([Record("r", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"}, 2e4,
                               nominal_speed=20.0, load=20.0)], tmp_path / "m.h5")
    (tmp_path / "s.yaml").write_text(f"version: 1\nname: cmp\nfmu: {gearbox_fmu}\nstop_time: 1.0\n"
                                     "output: {variables: [accel_pinion_casing]}\n")
    comp = compare(load_scenario(tmp_path / "s.yaml"), tmp_path / "m.h5", tmp_path / "rep")
    cond = record_conditions(gearbox_fmu, x, 2e4, 20.0, 20.0, {}, duration=0.5)
    base = compare_signals(simulate(gearbox_fmu, {}, cond.operating, x.size, "accel_pinion_casing"), x, 2e4,
                           cond.operating.shaft_hz)
    data = json.loads((tmp_path / "rep" / "compare.json").read_text())
    assert data["operating"]["shaft_hz"] == pytest.approx(cond.operating.shaft_hz)
    assert comp.shaft_hz == pytest.approx(20.2 * SHAFT / 20, rel=2e-3)      # not the nominal 20 Hz
    assert comp.lsd_db == pytest.approx(base.lsd_db, abs=1e-9)
    # a record with a speed channel: its speed is the pinion's, not the mesh line's reading
    write_measurements([Record("r", {"accel_pinion_casing": x, "tacho": np.full(x.size, 20.05)},
                               {"accel_pinion_casing": "m/s2", "tacho": "Hz"}, 2e4, nominal_speed=20.0, load=20.0)],
                       tmp_path / "t.h5")
    assert compare(load_scenario(tmp_path / "s.yaml"), tmp_path / "t.h5", tmp_path / "rep_t").shaft_hz == \
        pytest.approx(20.05, rel=1e-9)
