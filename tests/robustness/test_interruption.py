"""Interrupted runs never damage an earlier result: SIGINT and SIGKILL sent to a real ``twin run``.
A complete result is replaced only by a complete one; an interrupted run keeps its partial output
beside it (``<out>.partial.h5``), which ``--resume`` continues and a foreign scenario cannot."""
from __future__ import annotations

import hashlib
import signal
import time

import h5py
import pytest
from cli_runner import one_error_line, run_twin, start_twin

PLAIN = """version: 1
name: {name}
fmu: {fmu}
stop_time: {stop}
communication_step: 0.01
output: {{sample_rate: 100000, variables: [accel_pinion_casing]}}
operating: {{speed: {{constant: 20}}, load: {{constant: 20}}}}
"""
DEGRADATION = PLAIN + """degradation: {{model: pitting, max_increment: {inc}, stop: {{pitting_density: {stop_density}}},
              max_updates: 400, load_window: 0.1, record_duration: 0.02}}
"""


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def work(tmp_path, gearbox_fmu):
    (tmp_path / "short.yaml").write_text(PLAIN.format(name="short", fmu=gearbox_fmu, stop=0.05))
    (tmp_path / "long.yaml").write_text(PLAIN.format(name="long", fmu=gearbox_fmu, stop=60.0))
    assert run_twin(["run", "short.yaml", "--output", "out.h5", "--no-progress"], tmp_path).returncode == 0
    return tmp_path


def interrupt(work, args, sig, after):
    proc = start_twin(args, work)
    time.sleep(after)
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=120)
    return proc.returncode, out, err


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_plain_run_keeps_the_earlier_result(work, sig):
    before = digest(work / "out.h5")
    code, out, err = interrupt(work, ["run", "long.yaml", "--output", "out.h5", "--no-progress"], sig, 4.0)
    assert code == 130 and "Traceback" not in err, err
    assert digest(work / "out.h5") == before
    with h5py.File(work / "out.partial.h5") as f:          # what was simulated is kept beside it
        assert not f.attrs["complete"] and 0 < f["time"].shape[0] < 6_000_001
    assert not list(work.glob(".out.h5.*.tmp"))


def test_killed_plain_run_keeps_the_earlier_result_and_leaves_no_temporary(work):
    before = digest(work / "out.h5")
    code, _, _ = interrupt(work, ["run", "long.yaml", "--output", "out.h5", "--no-progress"], signal.SIGKILL, 4.0)
    assert code == -signal.SIGKILL
    time.sleep(0.5)                                          # the orphaned FMU process dies with its parent
    assert digest(work / "out.h5") == before
    assert run_twin(["run", "short.yaml", "--output", "out.h5", "--no-progress"], work).returncode == 0
    assert not list(work.glob(".out.h5.*.tmp"))


def test_ctrl_c_is_honoured_every_time_in_a_degradation_run(work, gearbox_fmu):
    (work / "deg.yaml").write_text(DEGRADATION.format(name="deg", fmu=gearbox_fmu, stop=0.05, inc=0.002,
                                                      stop_density=0.2))
    before = digest(work / "out.h5")
    for after in (3.0, 5.0, 7.0):
        code, _, err = interrupt(work, ["run", "deg.yaml", "--output", "out.h5", "--no-progress"],
                                 signal.SIGINT, after)
        assert code == 130 and "Exception ignored" not in err and "Traceback" not in err, err
        assert digest(work / "out.h5") == before


def test_resume_continues_its_own_partial_run_and_refuses_another(work, gearbox_fmu):
    (work / "deg.yaml").write_text(DEGRADATION.format(name="deg", fmu=gearbox_fmu, stop=0.05, inc=0.01,
                                                      stop_density=0.12))
    (work / "other.yaml").write_text(DEGRADATION.format(name="other", fmu=gearbox_fmu, stop=0.05, inc=0.02,
                                                        stop_density=0.12))
    # Interrupt once the first stage is on disk, however fast the machine: a fixed delay let a fast
    # machine finish the whole run first.
    proc = start_twin(["run", "deg.yaml", "--output", "d.h5", "--no-progress"], work)
    deadline = time.monotonic() + 120
    while not (work / "d.partial.h5").exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=120)
    code = proc.returncode
    assert code == 130 and (work / "d.partial.h5").exists() and not (work / "d.h5").exists()
    with h5py.File(work / "d.partial.h5") as f:
        done = len(f["stages"])
    proc = run_twin(["run", "other.yaml", "--output", "d.h5", "--resume", "--no-progress"], work)
    assert "another scenario" in one_error_line(proc)
    proc = run_twin(["run", "deg.yaml", "--output", "d.h5", "--resume", "--no-progress"], work, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert not (work / "d.partial.h5").exists()
    with h5py.File(work / "d.h5") as f:
        assert f.attrs["complete"] and len(f["stages"]) >= done


def test_corrupt_partial_output_is_named(work, gearbox_fmu):
    (work / "deg.yaml").write_text(DEGRADATION.format(name="deg", fmu=gearbox_fmu, stop=0.05, inc=0.01,
                                                      stop_density=0.04))
    (work / "d.partial.h5").write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    proc = run_twin(["run", "deg.yaml", "--output", "d.h5", "--resume", "--no-progress"], work)
    assert "d.partial.h5" in one_error_line(proc)


def test_ctrl_c_in_calibrate_is_one_line(tmp_path, gearbox_fmu):
    import numpy as np

    from twin.measurements import Record, write_measurements
    x = np.sin(2 * np.pi * 380 * np.arange(40000) / 1e5)
    write_measurements([Record("r", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"}, 1e5,
                               nominal_speed=20.0, load=20.0)], tmp_path / "m.h5")
    # 40 generations run far longer than 8 s: the interrupt at 8 s must find the search still
    # running (with 5 the whole command took 14 s on a loaded 2-core machine: a fast one could finish first)
    (tmp_path / "c.yaml").write_text(PLAIN.format(name="c", fmu=gearbox_fmu, stop=0.05) + (
        "calibration: {parameters: {kt12: [1000, 2500]}, algorithm: nsga2, pop_size: 4, n_gen: 40, "
        "natural_frequencies: [22, 87, 218, 430], record_duration: 0.2, settle_time: 0.05}\n"
        "executor: {type: local, workers: 1}\n"))
    code, _, err = interrupt(tmp_path, ["calibrate", "c.yaml", "--measurements", "m.h5", "--out", "cal",
                                        "--no-progress"], signal.SIGINT, 8.0)
    assert code == 130 and "Traceback" not in err and "twin: interrupted" in err, err
