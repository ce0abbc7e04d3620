"""Crash-isolated FMU work: native faults of an FMU (segfault, exit, abort, endless loop, FMI
errors) end one task, never the run, and are reported with their signal or exit status."""
from __future__ import annotations

import re
import os
import tempfile
from pathlib import Path

import numpy as np
import pytest
from robustness_tasks import faulty_fmu_evaluate, python_fault, reference_evaluate, simulate_faulty

from twin.errors import FMUError, SimulationError, WorkerCrashError
from twin.executor import LocalExecutor
from twin.isolation import IsolatedPool, describe_exit, run_isolated

# fault mode of Faulty.c -> (exception type, words of its message)
FAULTS = {
    0: (None, ()),
    1: (WorkerCrashError, ("SIGSEGV",)),
    2: (WorkerCrashError, ("exited with status 3",)),
    3: (WorkerCrashError, ("time limit of 3 s",)),
    4: (WorkerCrashError, ("SIGABRT",)),
    5: (SimulationError, ("fmi2DoStep", "on purpose", "fmi2Error")),
    6: (SimulationError, ("fmi2Fatal",)),
}


@pytest.fixture(scope="module")
def pool_results(faulty_fmus):
    """Every fault mode twice, in one pool of two workers with a 3 s limit, then good tasks."""
    modes = [*FAULTS, *FAULTS, 0, 0]
    with IsolatedPool(2, timeout=3.0) as pool:
        results = pool.map(simulate_faulty, [(str(faulty_fmus["faulty"]), m) for m in modes])
        root = Path(pool._root)
        crashes = list(pool.crashes)
    return modes, results, root, crashes


@pytest.mark.parametrize("mode", list(FAULTS))
def test_each_fault_ends_its_task_only(pool_results, mode):
    modes, results, _, _ = pool_results
    kind, words = FAULTS[mode]
    for m, r in zip(modes, results):
        if m != mode:
            continue
        if kind is None:
            assert isinstance(r, float) and np.isfinite(r)
        else:
            assert isinstance(r, kind), r
            for w in words:
                assert w in str(r)


def test_the_pool_goes_on_after_the_faults(pool_results):
    modes, results, root, crashes = pool_results
    assert isinstance(results[-1], float) and results[-1] == results[0]   # same answer as before the faults
    assert len(crashes) == 2 * 4                                           # segfault, exit, hang, abort, twice
    assert not root.exists()                                               # every worker's unpacked FMUs removed


@pytest.mark.parametrize("kind, expected", [("segfault", "SIGSEGV"), ("raise", "an ordinary error"),
                                            ("fine", "fine")])
def test_executor_returns_faults_in_their_slots(kind, expected):
    with LocalExecutor(1, timeout=30) as ex:
        out = ex.map(python_fault, [kind, "fine"])
    assert expected in str(out[0]) and out[1] == "fine"


def test_retry_runs_a_crashed_task_again_and_not_a_hung_one():
    with IsolatedPool(1, timeout=2.0, retries=1) as pool:
        out = pool.map(python_fault, ["segfault", "hang", "ok"])
        assert len(pool.crashes) == 3          # segfault twice (first run and retry), hang once
    assert isinstance(out[0], WorkerCrashError) and "SIGSEGV" in str(out[0])
    assert isinstance(out[1], WorkerCrashError) and out[1].timeout == 2.0
    assert out[2] == "ok"


@pytest.mark.parametrize("mode, kind, words", [(1, WorkerCrashError, "SIGSEGV"), (2, WorkerCrashError, "status 3"),
                                               (5, SimulationError, "on purpose"), (0, None, "")])
def test_run_isolated_reports_how_the_child_ended(faulty_fmus, mode, kind, words):
    # Only this process's directories: another test worker may be mid-run beside us.
    mine = f"twin_run_{os.getpid()}_*"
    before = set(Path(tempfile.gettempdir()).glob(mine))
    if kind is None:
        assert np.isfinite(run_isolated(simulate_faulty, (str(faulty_fmus["faulty"]), mode)))
    else:
        with pytest.raises(kind, match=words):
            run_isolated(simulate_faulty, (str(faulty_fmus["faulty"]), mode))
    assert set(Path(tempfile.gettempdir()).glob(mine)) <= before


def test_run_isolated_stops_a_hang_at_its_limit(faulty_fmus):
    with pytest.raises(WorkerCrashError, match="time limit of 1 s"):
        run_isolated(simulate_faulty, (str(faulty_fmus["faulty"]), 3), timeout=1.0)


def test_null_instance_reports_the_fmu_message_not_a_crash(faulty_fmus):
    # fmi2Instantiate returns NULL (GUID mismatch): no fmi2Terminate on it, the FMU's message is shown
    with pytest.raises(FMUError, match="GUID does not match"):
        run_isolated(simulate_faulty, (str(faulty_fmus["wrong_guid"]), 0))


def test_truncated_binary_is_reported_with_its_signal_or_load_error(faulty_fmus):
    with pytest.raises((WorkerCrashError, FMUError), match="SIGBUS|SIGSEGV|cannot load"):
        run_isolated(simulate_faulty, (str(faulty_fmus["truncated"]), 0))


def test_validate_loads_the_binary_and_names_a_truncated_one(faulty_fmus):
    # every XML check passes on a cut shared library; only loading it shows the fault
    from twin.fmu import validate
    problems = validate(faulty_fmus["truncated"])
    assert len(problems) == 1 and "cannot be loaded" in problems[0], problems
    assert re.search("SIGBUS|SIGSEGV|cannot load", problems[0]), problems


@pytest.mark.parametrize("code, text", [(-11, "SIGSEGV (Segmentation fault)"), (-9, "SIGKILL"), (3, "status 3"),
                                        (None, "without an exit status")])
def test_describe_exit(code, text):
    assert text in describe_exit(code)


def test_calibration_with_a_segfaulting_and_hanging_fmu(faulty_fmus):
    """One stiffness in ten segfaults inside the FMU and one in ten loops forever: the calibration
    finishes, those are infeasible, and every evaluation and the result equal a run in which the
    same evaluations fail with an ordinary error."""
    from twin.calibration.problem import CalibrationTarget, ParameterSpace, calibrate
    fmu = faulty_fmus["faulty"]
    target = CalibrationTarget(np.zeros(100), 1000.0, 20.0, 20.0, np.array([15.9]), shaft_hz=20.0)
    space = ParameterSpace.from_bounds({"k": [5e3, 2e4], "c": [0.5, 5.0]})
    runs = {}
    for label, fn in (("faults", faulty_fmu_evaluate), ("reference", reference_evaluate)):
        with LocalExecutor(2, timeout=2.0) as ex:
            runs[label] = calibrate(fmu, space, target, algorithm="nsga2", pop_size=10, n_gen=3, seed=5,
                                    executor=ex, evaluate=fn)
            if label == "faults":
                crashes = [str(c) for c in ex._pool.crashes]
    a, b = runs["faults"], runs["reference"]
    digits = [round(1000 * h["x"][0]) % 10 for h in a.history]
    assert a.n_evals == 30 and digits.count(0) >= 1 and digits.count(1) >= 1
    assert a.failed_evals == digits.count(0) + digits.count(1)
    assert sum("SIGSEGV" in c for c in crashes) == digits.count(0)
    assert sum("time limit" in c for c in crashes) == digits.count(1)
    assert [h["x"] for h in a.history] == [h["x"] for h in b.history]
    assert [h.get("f") for h in a.history] == [h.get("f") for h in b.history]
    np.testing.assert_array_equal(a.X, b.X)
    assert a.chosen == b.chosen


def test_dask_worker_that_dies_is_reported_and_replaced():
    from twin.executor import DaskExecutor
    with DaskExecutor(workers=1, timeout=60.0) as ex:
        out = ex.map(python_fault, ["segfault", "fine", "fine"])
    assert isinstance(out[0], WorkerCrashError) and "died" in str(out[0])
    assert out[1:] == ["fine", "fine"]


def test_workers_that_cannot_start_stop_the_map_with_a_typed_error(tmp_path):
    """A script without the ``__main__`` guard makes every spawned worker die while importing it:
    no task runs, and map raises one WorkerCrashError that says why, instead of handing back a
    broken-pool exception per task that a caller would take for the tasks' own failures."""
    import subprocess
    import sys

    repo = Path(__file__).resolve().parents[2]
    script = tmp_path / "unguarded.py"
    script.write_text("from twin.executor import LocalExecutor\n"
                      "from twin.errors import WorkerCrashError\n"
                      "ex = LocalExecutor(1)\n"
                      "try:\n"
                      "    print('RESULTS', ex.map(abs, [-1, -2]))\n"
                      "except WorkerCrashError as exc:\n"
                      "    print('TYPED', exc)\n"
                      "ex.close()\n")
    env = {**os.environ, "PYTHONPATH": str(repo)}
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=env,
                         cwd=tmp_path).stdout
    assert "RESULTS" not in out
    line, = [l for l in out.splitlines() if l.startswith("TYPED")]
    assert "could not start" in line and "__main__" in line
