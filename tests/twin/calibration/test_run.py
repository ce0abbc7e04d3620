"""twin calibrate end to end on a tiny budget: outputs, Table 2, bad blocks refused."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from twin.calibration.run import run_calibration
from twin.errors import ScenarioError
from twin.fmu import FMU
from twin.measurements import Record, write_measurements
from twin.scenario import read_parameter_file, scenario_from_dict


def _scenario(fmu, **cal):
    block = {"parameters": {"kt12": [1000.0, 2500.0], "I1": [3e-3, 6e-3]}, "algorithm": "nsga2", "pop_size": 4,
             "n_gen": 2, "natural_frequencies": [45.0, 115.0, 433.0], "foundation_modes": [13.0],
             "record_duration": 0.1, "settle_time": 0.05, **cal}
    return scenario_from_dict({"version": 1, "name": "cal", "fmu": str(fmu), "stop_time": 0.2,
                               "output": {"variables": ["accel_pinion_casing"]},
                               "executor": {"type": "local", "workers": 1}, "calibration": block})


@pytest.fixture(scope="module")
def rig(gearbox_fmu, tmp_path_factory):
    path = tmp_path_factory.mktemp("rig") / "rig.h5"
    p = {"kt12": 1900.0, "speed_ref_start": 2 * math.pi * 20, "load_start": 20.0}
    with FMU(gearbox_fmu) as f:
        f.setup(0.0, parameters=p, inputs={"motor_speed_ref": 2 * math.pi * 20, "load_torque": 20.0})
        x = f.capture(0.2, 1e-5, ["accel_pinion_casing"])[:, 0]
    write_measurements([Record("r1", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"}, 1e5,
                               nominal_speed=20.0, load=20.0)], path)
    return path


def test_outputs_and_table(gearbox_fmu, rig, tmp_path):
    rep = run_calibration(_scenario(gearbox_fmu, pop_size=6, n_gen=3), rig, tmp_path / "out", progress=False)
    for name in ("calibrated.json", "calibrated.ssv", "calibrated.ssp", "knee.json", "pareto.csv",
                 "checkpoint.json", "report.html", "report_psd.png"):
        assert (tmp_path / "out" / name).exists(), name
    chosen = read_parameter_file(tmp_path / "out" / "calibrated.json")
    assert read_parameter_file(tmp_path / "out" / "calibrated.ssv", fmu=gearbox_fmu) == chosen
    assert set(chosen) == {"kt12", "I1"}
    assert rep.measured_modes.size == 3 and rep.after_modes.size == 3
    assert "measured [Hz]" in rep.table()
    assert np.all(np.isfinite(rep.objectives_after))
    assert rep.result.F[:, 2].min() < rep.objectives_before[2]     # the front improves on the defaults
    assert "Table 2" in (tmp_path / "out" / "report.html").read_text()


def test_calibrated_ssp_runs_in_libcosim_with_the_calibrated_values(gearbox_fmu, rig, tmp_path):
    """The .ssp that twin calibrate writes, run by another SSP importer (OSP libcosim)."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    run_calibration(_scenario(gearbox_fmu, pop_size=4, n_gen=1, refine=False), rig, tmp_path / "out", progress=False)
    chosen = read_parameter_file(tmp_path / "out" / "calibrated.json")
    step, steps = 1e-4, 200
    execution = CosimExecution.from_ssp_file(str(tmp_path / "out" / "calibrated.ssp"))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    reals = {v.name.decode(): v.reference for v in execution.slave_variables(0)
             if v.type == CosimVariableType.REAL.value}
    theirs = []
    for _ in range(steps):
        assert execution.step(1)
        theirs.append(observer.last_real_values(0, [reals["accel_pinion_casing"], reals["mesh_force"]]))
    assert observer.last_real_values(0, [reals[k] for k in chosen]) == list(chosen.values())
    with FMU(gearbox_fmu) as f:
        f.setup(0.0, parameters=chosen)
        ours = f.run(steps * step, step, outputs=["accel_pinion_casing", "mesh_force"])
    ours = np.column_stack([ours["accel_pinion_casing"], ours["mesh_force"]])[1:]
    assert (np.abs(np.array(theirs) - ours).max(axis=0) / np.abs(ours).max(axis=0)).max() <= 1e-8


def test_bad_calibration_block_lists_problems(gearbox_fmu, rig, tmp_path):
    with pytest.raises(ScenarioError) as info:
        scenario_from_dict({"version": 1, "name": "c", "fmu": "x.fmu", "stop_time": 1.0,
                            "calibration": {"parameters": {"k": [1]}, "algorithm": "pso"}})
    assert len(info.value.problems) >= 2
    with pytest.raises(ScenarioError, match="natural_frequencies"):
        _scenario(gearbox_fmu, natural_frequencies=[])
    with pytest.raises(ScenarioError, match=r"calibration\.pairing: 'nearest' is not one of \['frequency', 'shape'\]"):
        _scenario(gearbox_fmu, pairing="nearest")
    with pytest.raises(ScenarioError, match=r"calibration\.visibility: 'all' is not one of \['mesh', 'run-up', "
                                            r"'mesh\+dominant', 'run-up\+dominant'\]"):
        _scenario(gearbox_fmu, visibility="all")
    assert _scenario(gearbox_fmu, visibility="run-up+dominant").raw["calibration"]["visibility"] == "run-up+dominant"
    with pytest.raises(ScenarioError, match=r"calibration\.fit: 'global' is not one of \['follow', 'search'\]"):
        _scenario(gearbox_fmu, fit="global")
    with pytest.raises(ScenarioError, match=r"calibration\.pairing: 'nearest' is not one of"):
        run_calibration(_scenario(gearbox_fmu), rig, tmp_path / "o3", progress=False, pairing="nearest")
    bare = scenario_from_dict({"version": 1, "name": "c", "fmu": str(gearbox_fmu), "stop_time": 1.0})
    with pytest.raises(ScenarioError, match="no calibration block"):
        run_calibration(bare, rig, tmp_path / "o2", progress=False)


def _hammer(name="hammer", modes=((87.0, 0.02), (218.0, 0.015), (512.0, 0.02)), fs=8192.0, hits=6):
    """A hammer test: 6 hits 1 s apart on three modes, force [N] and acceleration [m/s2]."""
    import scipy.signal as sps
    rng = np.random.default_rng(0)
    n = int(hits * fs)
    force = np.zeros(n)
    for i in range(hits):
        k = int((i + 0.1) * fs)
        force[k:k + 8] = (1.0 + 0.2 * rng.standard_normal()) * np.hanning(8)
    t = np.arange(n) / fs
    accel = sum(sps.lsim(sps.TransferFunction([1.0, 0.0, 0.0], [1.0, 4 * math.pi * zeta * f, (2 * math.pi * f) ** 2]),
                         force, t)[1] for f, zeta in modes)
    accel = accel + 1e-3 * np.std(accel) * rng.standard_normal(n)
    return Record(name, {"hammer": force, "accel_pinion_casing": accel}, {"hammer": "N", "accel_pinion_casing": "m/s2"},
                  fs)


def test_foundation_modes_read_from_a_hammer_record(tmp_path):
    """The paper's procedure: the run-up's modes less those an impact test on the casing shows."""
    from twin.calibration.measured import measured_modes
    from twin.measurements import MeasurementSet

    steady = Record("steady", {"accel_pinion_casing": np.zeros(1000)}, {"accel_pinion_casing": "m/s2"}, 1e4)
    mset = MeasurementSet((steady, _hammer()))
    spec = {"natural_frequencies": [45.0, 87.5, 219.0, 433.0, 515.0], "foundation_modes": "hammer"}
    freqs, _, _ = measured_modes(spec, mset, "s.yaml", tmp_path)
    assert list(freqs) == [45.0, 433.0]
    assert (tmp_path / "foundation_modes.json").exists()
    with pytest.raises(ScenarioError, match="'steady' is not a hammer test"):
        measured_modes({**spec, "foundation_modes": "steady"}, mset, "s.yaml", tmp_path)
    with pytest.raises(ScenarioError, match="no record 'impact'"):
        measured_modes({**spec, "foundation_modes": "impact"}, mset, "s.yaml", tmp_path)
    # a bad hammer record is refused before the run-up is surveyed (and its modes.json written)
    with pytest.raises(ScenarioError, match="no record 'impact'"):
        measured_modes({"modes_from": "steady", "foundation_modes": "impact"}, mset, "s.yaml", tmp_path / "o")
    assert not (tmp_path / "o").exists()


def test_lscf_in_the_block_fits_the_hammer_records_together(gearbox_fmu, tmp_path):
    """``calibration.lscf: true`` reads the modes of the hammer records named in modes_from with the
    poly-reference LSCF fit as well (its note in modes.json); a non-boolean is refused by name."""
    from twin.calibration.measured import measured_modes
    from twin.measurements import MeasurementSet

    mset = MeasurementSet((_hammer("hammer_a"), _hammer("hammer_b", hits=5)))
    spec = {"modes_from": ["hammer_a", "hammer_b"]}
    (tmp_path / "plain").mkdir()
    (tmp_path / "lscf").mkdir()
    plain, _, _ = measured_modes(spec, mset, "s.yaml", tmp_path / "plain")
    fitted, _, _ = measured_modes({**spec, "lscf": True}, mset, "s.yaml", tmp_path / "lscf")
    notes = json.loads((tmp_path / "lscf" / "modes.json").read_text())["notes"]
    assert any(n.startswith("LSCF fit of 2 hammer test(s) x 1 channel(s)") for n in notes)
    assert not any("LSCF" in n for n in json.loads((tmp_path / "plain" / "modes.json").read_text())["notes"])
    for fn in (87.0, 218.0, 512.0):
        assert np.min(np.abs(plain - fn)) < 0.02 * fn and np.min(np.abs(fitted - fn)) < 0.02 * fn
    with pytest.raises(ScenarioError, match=r"calibration\.lscf: 'yes' is not of type 'boolean'"):
        _scenario(gearbox_fmu, lscf="yes")


def test_foundation_from_overrides_the_block(gearbox_fmu):
    from twin.calibration.run import _block

    assert _block(_scenario(gearbox_fmu), {"foundation_modes": "impact"})["foundation_modes"] == "impact"
    assert _block(_scenario(gearbox_fmu))["foundation_modes"] == [13.0]


def test_modes_read_from_several_records_together(tmp_path):
    """A mode seen in any of the records is a mode of the structure (two hammer tests struck where
    each shows modes the other does not), each mode naming the records that saw it."""
    from twin.calibration.measured import measured_modes
    from twin.measurements import MeasurementSet

    a = _hammer("hammer_a", modes=((87.0, 0.02), (218.0, 0.015)))
    b = _hammer("hammer_b", modes=((218.0, 0.015), (512.0, 0.02)))
    steady = Record("steady", {"accel_pinion_casing": np.zeros(1000)}, {"accel_pinion_casing": "m/s2"}, 1e4)
    mset = MeasurementSet((steady, a, b))
    for d in ("one", "both"):
        (tmp_path / d).mkdir()
    one, _, _ = measured_modes({"modes_from": "hammer_a"}, mset, "s.yaml", tmp_path / "one")
    both, _, what = measured_modes({"modes_from": ["hammer_a", "hammer_b"]}, mset, "s.yaml", tmp_path / "both")
    assert one.size == 2 and both.size == 3
    assert np.allclose(np.sort(both), [87.0, 218.0, 512.0], rtol=0.02)
    assert "records 'hammer_a', 'hammer_b'" in what
    saved = json.loads((tmp_path / "both" / "modes.json").read_text())
    assert saved["record"] == ["hammer_a", "hammer_b"]
    seen = {round(m["frequency_hz"] / 10): m["evidence"]["records"] for m in saved["modes"] if m["confidence"] >= 0.3}
    assert seen[round(218.0 / 10)] == ["hammer_a", "hammer_b"] and seen[round(512.0 / 10)] == ["hammer_b"]
    with pytest.raises(ScenarioError, match="no record 'hammer_c'"):
        measured_modes({"modes_from": ["hammer_a", "hammer_c"]}, mset, "s.yaml", tmp_path / "bad")
    assert not (tmp_path / "bad").exists()


def test_modes_from_on_the_command_line_takes_several_records(capsys):
    from twin.cli import main
    from twin.commands.calibration import _record_list

    assert _record_list("runup") == "runup"
    assert _record_list("runup, hammer_a") == ["runup", "hammer_a"]
    assert main(["calibrate", "s.yaml", "--modes-from", "runup,"]) == 2
    assert "empty record name in 'runup,'" in capsys.readouterr().err


@pytest.mark.parametrize("bad", [[], ["runup", "runup"], [3]])
def test_a_bad_list_of_modes_records_is_refused_by_the_schema(gearbox_fmu, bad):
    from twin.calibration.run import _block

    assert _block(_scenario(gearbox_fmu, modes_from=["runup", "hammer_a"]))["modes_from"] == ["runup", "hammer_a"]
    with pytest.raises(ScenarioError, match="calibration.modes_from"):
        _block(_scenario(gearbox_fmu, modes_from=bad))


def test_struck_shafts_give_each_measured_mode_its_shaft(hammer_factory, gearbox_fmu, tmp_path):
    """``calibration.struck_shafts``: two hammer records, one per shaft; the mode struck harder on the
    input shaft's record gets a positive side level, the other a negative one (the pairing reads
    them); a record outside modes_from, a shaft without a record or an unknown shaft is refused by name."""
    from twin.calibration.measured import measured_modes
    from twin.measurements import MeasurementSet

    modes = ((900.0, 0.02), (1200.0, 0.01))
    part = np.array([[1.0, 0.25], [0.3, 1.0]])      # 900 Hz answers the pinion's blows, 1200 Hz the gear's
    records = []
    for r, name in enumerate(("hammer_pinion", "hammer_gear")):
        force, ys = hammer_factory(modes, [part[:, r]], 10_000.0, 4.0, seed=r)
        records.append(Record(name, {"hammer": force, "accel_pinion_casing": ys[0]},
                              {"hammer": "N", "accel_pinion_casing": "m"}, 10_000.0))
    mset = MeasurementSet(tuple(records))
    spec = {"modes_from": ["hammer_pinion", "hammer_gear"],
            "struck_shafts": {"hammer_pinion": "input", "hammer_gear": "output"}}
    freqs, _, _, _, _, _, shapes = measured_modes(spec, mset, "s.yaml", tmp_path, with_damping=True)
    side = {round(f, -2): s for f, s in zip(freqs, shapes.side_db)}
    # within 2 dB of the participations' ratio (the other mode's tail in each hump)
    assert abs(side[900.0] - 20 * np.log10(1 / 0.3)) < 2.0 and abs(side[1200.0] - 20 * np.log10(0.25)) < 2.0
    # without the key the struck levels stay evidence only
    _, _, _, _, _, _, plain = measured_modes({"modes_from": spec["modes_from"]}, mset, "s.yaml", tmp_path,
                                             with_damping=True)
    assert plain is None
    with pytest.raises(ScenarioError, match=r"calibration\.struck_shafts\.hammer_side: 'hammer_side' is not one of "
                                            r"the records the modes are read from"):
        measured_modes({**spec, "struck_shafts": {**spec["struck_shafts"], "hammer_side": "input"}}, mset, "s.yaml",
                       tmp_path)
    with pytest.raises(ScenarioError, match=r"calibration\.struck_shafts: no record struck on the output shaft"):
        measured_modes({**spec, "struck_shafts": {"hammer_pinion": "input", "hammer_gear": "input"}}, mset,
                       "s.yaml", tmp_path)
    with pytest.raises(ScenarioError, match=r"calibration\.struck_shafts\.hammer_gear: 'gear' is not one of"):
        _scenario(gearbox_fmu, struck_shafts={"hammer_pinion": "input", "hammer_gear": "gear"})
